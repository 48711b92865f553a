// The display arrays of a solve with UVs (the unwelded surface, checker UVs,
// distortion colours and histogram, seam lines, the 2D layout and its chart
// outlines), built with tight loops over typed arrays. Pure functions without
// three.js: the worker builds a `SolveView` right after the solve and transfers
// it, so the page only uploads; the page can build one itself as a fallback.
import { interpolateViridis } from 'd3-scale-chromatic';
import type { SolveView } from './protocol';

/** Bins of the distortion histogram: HISTOGRAM_BINS − 1 equal bins over [0, max), the last one every face at or above max. */
export const HISTOGRAM_BINS = 40;

/** Entries of the distortion ramp's table (`rampRgb` picks the nearest). */
const RAMP_SIZE = 256;
let rampTable: Float32Array | null = null;

/** An sRGB channel (0..1) in linear light, as WebGL vertex colours are read. */
const srgbToLinear = (c: number): number => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);

/**
 * Distortion colour ramp (0 = none … 1 = at or above the scale, clamped):
 * viridis, sequential and perceptually ordered (dark purple → teal →
 * yellow, see `rampCss`), in linear light for vertex colours; writes r, g,
 * b to out[o..o+2].
 */
export function rampRgb(t: number, out: { [i: number]: number }, o: number): void {
  if (!rampTable) {
    rampTable = new Float32Array(RAMP_SIZE * 3);
    for (let i = 0; i < RAMP_SIZE; i++) {
      const hex = Number.parseInt(interpolateViridis(i / (RAMP_SIZE - 1)).slice(1), 16);
      rampTable[3 * i] = srgbToLinear(((hex >> 16) & 255) / 255);
      rampTable[3 * i + 1] = srgbToLinear(((hex >> 8) & 255) / 255);
      rampTable[3 * i + 2] = srgbToLinear((hex & 255) / 255);
    }
  }
  const x = t > 0 ? (t < 1 ? t : 1) : 0; // NaN → 0
  const i = 3 * Math.round(x * (RAMP_SIZE - 1));
  out[o] = rampTable[i]!;
  out[o + 1] = rampTable[i + 1]!;
  out[o + 2] = rampTable[i + 2]!;
}

/** The ramp's colour at `t` (0..1, clamped) as CSS (sRGB hex), for the legend and the histogram. */
export const rampCss = (t: number): string => interpolateViridis(Math.max(0, Math.min(1, t)));

/** UVs scaled for the checker texture: 20 squares across the layout's larger side (a new array). */
export function checkerUv(uv: Float32Array): Float32Array {
  const scaled = new Float32Array(uv.length);
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = 0; i < uv.length; i++) {
    const x = uv[i]!;
    if (x < lo) lo = x;
    if (x > hi) hi = x;
  }
  const scale = hi > lo ? 2.5 / (hi - lo) : 1;
  for (let i = 0; i < uv.length; i++) scaled[i] = uv[i]! * scale;
  return scaled;
}

/** Positions per face corner (xyz of vertex indices[c] at 3c), i.e. the mesh unwelded. */
export function cornerPositions(positions: Float32Array, indices: Uint32Array): Float32Array {
  const out = new Float32Array(indices.length * 3);
  for (let c = 0; c < indices.length; c++) {
    const v = 3 * indices[c]!;
    out[3 * c] = positions[v]!;
    out[3 * c + 1] = positions[v + 1]!;
    out[3 * c + 2] = positions[v + 2]!;
  }
  return out;
}

/** The auto scale of per-face distortion `perFace`: its 99th percentile, at least 1e-6 (1 when empty). */
export function autoScale(perFace: Float32Array): number {
  if (perFace.length === 0) return 1;
  const sorted = Float32Array.from(perFace).sort();
  return Math.max(sorted[Math.min(sorted.length - 1, Math.floor(sorted.length * 0.99))]!, 1e-6);
}

/**
 * Per-face distortion `perFace` as colours against `scale` (the value shown
 * as the ramp's top; default: `autoScale`): the scale, rgb per face corner,
 * and the histogram (see HISTOGRAM_BINS; NaN in no bin).
 */
export function distortionView(perFace: Float32Array, scale?: number): NonNullable<SolveView['distortion']> {
  const max = scale !== undefined && scale > 0 ? scale : autoScale(perFace);
  const colors = new Float32Array(perFace.length * 9);
  const rgb = [0, 0, 0];
  const histogram = new Uint32Array(HISTOGRAM_BINS);
  const top = HISTOGRAM_BINS - 1;
  for (let f = 0; f < perFace.length; f++) {
    const v = perFace[f]!;
    rampRgb(v / max, rgb, 0);
    for (let k = 0; k < 9; k += 3) {
      colors[9 * f + k] = rgb[0]!;
      colors[9 * f + k + 1] = rgb[1]!;
      colors[9 * f + k + 2] = rgb[2]!;
    }
    if (v >= max) histogram[top]!++;
    else if (v >= 0) histogram[Math.floor((v / max) * top)]!++;
  }
  return { colors, max, histogram };
}

/** [min u, min v, max u, max v] of `uv` (2 per corner); infinite when it is empty. */
export function uvBounds(uv: Float32Array): [number, number, number, number] {
  let minX = Infinity;
  let minY = Infinity;
  let maxX = -Infinity;
  let maxY = -Infinity;
  for (let i = 0; i + 1 < uv.length; i += 2) {
    const x = uv[i]!;
    const y = uv[i + 1]!;
    if (x < minX) minX = x;
    if (x > maxX) maxX = x;
    if (y < minY) minY = y;
    if (y > maxY) maxY = y;
  }
  return [minX, minY, maxX, maxY];
}

/** The UV layout as xyz per corner (z = 0) with its bounds and bounding sphere (as three.js computes them). */
export function layoutGeometry(uv: Float32Array): Pick<SolveView, 'layoutPositions' | 'layoutBounds' | 'layoutSphere'> {
  const corners = uv.length / 2;
  const pos = new Float32Array(corners * 3);
  for (let c = 0; c < corners; c++) {
    pos[3 * c] = uv[2 * c]!;
    pos[3 * c + 1] = uv[2 * c + 1]!;
  }
  const [minX, minY, maxX, maxY] = uvBounds(uv);
  const cx = (minX + maxX) / 2;
  const cy = (minY + maxY) / 2;
  let r2 = 0;
  for (let c = 0; c < corners; c++) {
    const dx = pos[3 * c]! - cx;
    const dy = pos[3 * c + 1]! - cy;
    const d = dx * dx + dy * dy;
    if (d > r2) r2 = d;
  }
  return { layoutPositions: pos, layoutBounds: [minX, minY, maxX, maxY], layoutSphere: [cx, cy, Math.sqrt(r2)] };
}

/**
 * Chart outlines of the layout: one segment (two xyz points at z = 0.005, in
 * raw UVs) per face side 3f+k (corner k → k+1) whose edge is a seam or on the
 * boundary. `faceEdges` gives each side's edge id (≥ edgeCount: none).
 */
export function cutSegments(uv: Float32Array, faceEdges: Uint32Array, edgeCount: number, seams: Uint32Array, boundary: Uint32Array): Float32Array {
  const cut = new Uint8Array(edgeCount);
  for (let i = 0; i < seams.length; i++) cut[seams[i]!] = 1;
  for (let i = 0; i < boundary.length; i++) cut[boundary[i]!] = 1;
  let n = 0;
  for (let s = 0; s < faceEdges.length; s++) if (faceEdges[s]! < edgeCount && cut[faceEdges[s]!]) n++;
  const seg = new Float32Array(n * 6);
  let j = 0;
  for (let s = 0; s < faceEdges.length; s++) {
    if (!(faceEdges[s]! < edgeCount && cut[faceEdges[s]!])) continue;
    const k = s % 3;
    const b = s - k + ((k + 1) % 3); // the side runs from corner s to corner b
    seg[j] = uv[2 * s]!;
    seg[j + 1] = uv[2 * s + 1]!;
    seg[j + 2] = 0.005;
    seg[j + 3] = uv[2 * b]!;
    seg[j + 4] = uv[2 * b + 1]!;
    seg[j + 5] = 0.005;
    j += 6;
  }
  return seg;
}

/** Line segments (two xyz points each) of the edges `ids` of `edges` (2 vertex ids per edge). */
export function edgeSegments(positions: Float32Array, edges: Uint32Array, ids: ArrayLike<number>): Float32Array {
  const seg = new Float32Array(ids.length * 6);
  for (let i = 0; i < ids.length; i++) {
    const e = ids[i]!;
    const a = 3 * edges[2 * e]!;
    const b = 3 * edges[2 * e + 1]!;
    seg[6 * i] = positions[a]!;
    seg[6 * i + 1] = positions[a + 1]!;
    seg[6 * i + 2] = positions[a + 2]!;
    seg[6 * i + 3] = positions[b]!;
    seg[6 * i + 4] = positions[b + 1]!;
    seg[6 * i + 5] = positions[b + 2]!;
  }
  return seg;
}

/** The mesh and solve arrays a `SolveView` is built from. */
export interface SolveViewInput {
  positions: Float32Array;
  indices: Uint32Array;
  edges: Uint32Array;
  boundary: Uint32Array;
  faceEdges: Uint32Array;
  uv: Float32Array;
  seamEdges: Uint32Array | null;
  perFaceDistortion: Float32Array | null;
}

/** Builds every display array of a solve with UVs (2 per face corner), see `SolveView`. */
export function buildSolveView(m: SolveViewInput): SolveView {
  const seams = m.seamEdges ?? new Uint32Array(0);
  return {
    cornerPositions: cornerPositions(m.positions, m.indices),
    checkerUv: checkerUv(m.uv),
    ...layoutGeometry(m.uv),
    cutSegments: cutSegments(m.uv, m.faceEdges, m.edges.length / 2, seams, m.boundary),
    seamSegments: edgeSegments(m.positions, m.edges, seams),
    distortion: m.perFaceDistortion ? distortionView(m.perFaceDistortion) : null,
  };
}

/** The distinct buffers of a view's arrays (to transfer it). */
export function viewBuffers(v: SolveView): ArrayBuffer[] {
  const arrays: ArrayBufferView[] = [v.cornerPositions, v.checkerUv, v.layoutPositions, v.cutSegments, v.seamSegments];
  if (v.distortion) arrays.push(v.distortion.colors, v.distortion.histogram);
  const out: ArrayBuffer[] = [];
  for (const a of arrays) if (a.buffer instanceof ArrayBuffer && !out.includes(a.buffer)) out.push(a.buffer);
  return out;
}
