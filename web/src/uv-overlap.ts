// Overlaps of a UV layout: every triangle rasterized into a coverage-count grid
// (square cells over the layout's bounds, at most `resolution` cells along the
// longer side), how much of the covered area lies under two or more layers
// and how deep they stack, and an RGBA tint of the stacked cells for the UV
// view. Vertices are snapped to 1/16 of a cell and the edge functions are exact
// integers with a top-left fill rule, so that triangles sharing an edge or a
// vertex never both cover a cell centre: only real overlaps (stacked charts,
// fold-overs) count. Pure typed-array loops without three.js.
import { uvBounds } from './solve-view';

/** Coverage of a layout (see `uvOverlap`). */
export interface UvOverlap {
  /** Cells per row and rows of the grid. */
  width: number;
  height: number;
  /** [min u, min v, max u, max v] of the grid (square cells; covers the layout). */
  bounds: [number, number, number, number];
  /** Faces covering each cell centre, row-major from min u, min v. */
  counts: Uint16Array;
  /** Cells covered by one face or more, and by two or more. */
  covered: number;
  overlapped: number;
  /** `overlapped / covered`: the share of the layout's area stacked two or more deep (0 when nothing is covered). */
  share: number;
  /** Most faces over one cell (0 when nothing is covered). */
  maxDepth: number;
}

/** Default cells along the longer side of the grid: 1024² cells, a 0.1 % area resolution. */
export const OVERLAP_RESOLUTION = 1024;

/** Sub-cell steps a vertex is snapped to. */
const SUB = 16;

/** Most cells along a side: the edge functions (products of two coordinates up to SUB × 1024) stay within int32. */
const MAX_RESOLUTION = 1024;

/**
 * Rasterizes the triangles of `uv` (2 per face corner 3f+k) into a grid of at
 * most `resolution` (≤ 1024) square cells along the longer side of the layout's bounds,
 * counting the faces over each cell centre (flipped faces count as well,
 * degenerate or non-finite ones do not).
 */
export function uvOverlap(uv: Float32Array, resolution = OVERLAP_RESOLUTION): UvOverlap {
  const res = Math.max(1, Math.min(MAX_RESOLUTION, Math.floor(resolution)));
  const [minU, minV, maxU, maxV] = uvBounds(uv);
  const finite = [minU, minV, maxU, maxV].every(Number.isFinite);
  const span = finite ? Math.max(maxU - minU, maxV - minV) : 0;
  const cell = span > 0 ? span / res : 1;
  const width = finite ? Math.max(1, Math.min(res, Math.ceil((maxU - minU) / cell))) : 1;
  const height = finite ? Math.max(1, Math.min(res, Math.ceil((maxV - minV) / cell))) : 1;
  const counts = new Uint16Array(width * height);
  const bounds: [number, number, number, number] = finite ? [minU, minV, minU + width * cell, minV + height * cell] : [0, 0, 1, 1];
  const scale = SUB / cell;
  const half = SUB / 2;
  const faces = Math.floor(uv.length / 6);
  for (let f = 0; f < faces; f++) {
    const o = 6 * f;
    const ax = Math.round((uv[o]! - minU) * scale);
    const ay = Math.round((uv[o + 1]! - minV) * scale);
    let bx = Math.round((uv[o + 2]! - minU) * scale);
    let by = Math.round((uv[o + 3]! - minV) * scale);
    let cx = Math.round((uv[o + 4]! - minU) * scale);
    let cy = Math.round((uv[o + 5]! - minV) * scale);
    const area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    if (!(area !== 0)) continue; // degenerate or NaN
    if (area < 0) [bx, by, cx, cy] = [cx, cy, bx, by]; // counter-clockwise from here on
    // Cells whose centres (SUB * i + half) lie in the triangle's bounding box.
    const i0 = Math.max(0, Math.ceil((Math.min(ax, bx, cx) - half) / SUB));
    const i1 = Math.min(width - 1, Math.floor((Math.max(ax, bx, cx) - half) / SUB));
    const j0 = Math.max(0, Math.ceil((Math.min(ay, by, cy) - half) / SUB));
    const j1 = Math.min(height - 1, Math.floor((Math.max(ay, by, cy) - half) / SUB));
    if (i0 > i1 || j0 > j1) continue;
    const px = SUB * i0 + half;
    const py = SUB * j0 + half;
    // Edge functions (> 0 inside) at the first centre, minus 1 on edges that do not own their points (top-left rule).
    let r0 = edgeAt(bx, by, cx, cy, px, py);
    let r1 = edgeAt(cx, cy, ax, ay, px, py);
    let r2 = edgeAt(ax, ay, bx, by, px, py);
    const dx0 = -(cy - by) * SUB, dy0 = (cx - bx) * SUB;
    const dx1 = -(ay - cy) * SUB, dy1 = (ax - cx) * SUB;
    const dx2 = -(by - ay) * SUB, dy2 = (bx - ax) * SUB;
    for (let j = j0; j <= j1; j++) {
      let w0 = r0, w1 = r1, w2 = r2;
      const row = j * width;
      for (let i = i0; i <= i1; i++) {
        if ((w0 | w1 | w2) >= 0) counts[row + i]!++;
        w0 += dx0;
        w1 += dx1;
        w2 += dx2;
      }
      r0 += dy0;
      r1 += dy1;
      r2 += dy2;
    }
  }
  let covered = 0;
  let overlapped = 0;
  let maxDepth = 0;
  for (let k = 0; k < counts.length; k++) {
    const c = counts[k]!;
    if (c === 0) continue;
    covered++;
    if (c > 1) overlapped++;
    if (c > maxDepth) maxDepth = c;
  }
  return { width, height, bounds, counts, covered, overlapped, share: covered ? overlapped / covered : 0, maxDepth };
}

/**
 * The edge function of the directed edge a → b at p (twice the signed area of
 * a, b, p: > 0 left of the edge), minus 1 unless the edge owns the points on
 * it: of the two directions of an edge exactly one does, so a point on an
 * edge shared by two counter-clockwise triangles counts for one of them.
 */
function edgeAt(ax: number, ay: number, bx: number, by: number, px: number, py: number): number {
  const owns = by - ay < 0 || (by === ay && bx - ax > 0);
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax) - (owns ? 0 : 1);
}

/** The overlap figures as shown in the results: "none", or "32 % of area, up to 5 layers". */
export function overlapText(o: Pick<UvOverlap, 'share' | 'maxDepth' | 'overlapped'>): string {
  if (o.overlapped === 0) return 'none';
  const pct = o.share * 100;
  return `${pct < 1 ? pct.toFixed(2) : pct < 10 ? pct.toFixed(1) : pct.toFixed(0)} % of area, up to ${o.maxDepth} layers`;
}

/**
 * The tint of the stacked cells of `o` as RGBA bytes (`width` × `height`,
 * rows from min v): colour `rgb` (0..255 each) over cells two or more deep,
 * more opaque the deeper they stack; other cells fully transparent.
 */
export function overlapTint(o: UvOverlap, rgb: readonly [number, number, number]): Uint8Array {
  const out = new Uint8Array(o.counts.length * 4);
  for (let k = 0; k < o.counts.length; k++) {
    const c = o.counts[k]!;
    if (c < 2) continue;
    out[4 * k] = rgb[0];
    out[4 * k + 1] = rgb[1];
    out[4 * k + 2] = rgb[2];
    out[4 * k + 3] = Math.min(235, 120 + 40 * (c - 2));
  }
  return out;
}
