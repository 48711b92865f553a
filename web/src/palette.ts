// The colours of the 3D and UV views: line and marker colours, the cone colour
// by index, the distortion ramp as a CSS gradient, and the checker texture the
// views share, with its density.
import * as THREE from 'three';
import { rampCss } from './solve-view';

export const COLORS = {
  feature: 0xff9f1c,
  boundary: 0x2ec4b6,
  seam: 0xff4fa3,
  unaligned: 0xff1f1f, // requested features the map could not align
  problem: 0xb6ff00, // where a solve failed: vertices (markers) and edges
  conePlus: 0xe63946, // k = +1 (angle deficit)
  coneMinus: 0x3a86ff, // k = −1 (angle excess)
  coneOther: 0xffd60a, // |k| > 1
  corner: 0xf1f1f1,
  anchor: 0xffffff,
  hover: 0xfff275,
  quadEdge: 0x2ad17a, // quad mesh edges (over the grid checker: apart from both of its colours)
  selection: 0x38c8ff, // the selected chart, in both views
  overlap: 0xb45cff, // UV areas stacked two or more layers deep
  uvFrame: 0xc8d0dc, // the [0, 1]² frame of the UV view
};

/** The marker colour of a singular vertex of the quad mesh by valence: 3 and 5 as the cones of index +1 and −1 that make them. */
export function valenceColor(valence: number): number {
  return valence === 3 ? COLORS.conePlus : valence === 5 ? COLORS.coneMinus : COLORS.coneOther;
}

/** Squares along each side of the checker texture: a UV span of 1 / CHECKER_SQUARES is one square. */
export const CHECKER_SQUARES = 8;

/** Grid-unit UVs `uv` scaled for the checker texture, one square per grid cell (a new array). */
export function gridCheckerUv(uv: Float32Array): Float32Array {
  const scaled = new Float32Array(uv.length);
  for (let i = 0; i < uv.length; i++) scaled[i] = uv[i]! / CHECKER_SQUARES;
  return scaled;
}

/** The marker colour of a cone of index `k`. */
export function coneColor(k: number): number {
  return k === 1 ? COLORS.conePlus : k === -1 ? COLORS.coneMinus : COLORS.coneOther;
}

/**
 * The distortion ramp (see `rampRgb`) as a CSS linear gradient from the left
 * (0) to `end` of the width (the scale); beyond, after a gap, the top colour
 * (the histogram's last bar: at or above the scale).
 */
export function rampGradient(end = 1): string {
  const pct = (x: number): string => `${(x * 100).toFixed(1)}%`;
  const stops = Array.from({ length: 9 }, (_, i) => `${rampCss(i / 8)} ${pct((i / 8) * end)}`);
  if (end < 1) stops.push(`transparent ${pct(end)}`, `transparent ${pct(end + 0.02)}`, `${rampCss(1)} ${pct(end + 0.02)}`);
  return `linear-gradient(90deg, ${stops.join(', ')})`;
}

/** Squares across the larger side of a seamless layout at checker repeat 1 (see `checkerUv` in solve-view.ts). */
export const CHECKER_BASE_SQUARES = 20;

/** The checker densities offered: squares across the larger side of the layout. */
export const CHECKER_DENSITIES = [10, 20, 40, 80] as const;

let checker: THREE.Texture | null = null;

/**
 * The CHECKER_SQUARES × CHECKER_SQUARES checkerboard texture, repeating: one
 * texture for the 3D and the UV view (each renderer uploads it once), so that
 * `setCheckerRepeat` changes both.
 */
export function checkerTexture(): THREE.Texture {
  if (checker) return checker;
  const size = 256;
  const c = document.createElement('canvas');
  c.width = c.height = size;
  const g = c.getContext('2d')!;
  const n = CHECKER_SQUARES;
  const s = size / n;
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      g.fillStyle = (i + j) % 2 ? '#f4f1ea' : '#3d4f73';
      g.fillRect(i * s, j * s, s, s);
    }
  }
  const t = new THREE.CanvasTexture(c);
  t.wrapS = t.wrapT = THREE.RepeatWrapping;
  t.colorSpace = THREE.SRGBColorSpace;
  t.anisotropy = 4;
  checker = t;
  return t;
}

/** Squares of the checker per square of its UVs (1: as the UVs were scaled); the views draw it at their next frame (a uniform, no upload). */
export function setCheckerRepeat(repeat: number): void {
  checkerTexture().repeat.set(repeat, repeat);
}
