// The integer grid lines u = n, v = n of the UV view while it shows an
// integer-grid map (grid units, one cell = 1): the stride that keeps them
// readable at the current zoom (every cell, or every 2, 5, 10, 20 … cells when
// cells get smaller than a few pixels) and the lines over the layout's bounds,
// split into minor lines and the major ones at each power of ten above the
// stride. Pure functions without three.js.

/** Fewest CSS pixels between two grid lines drawn. */
export const GRID_MIN_PX = 4;

/** The smallest stride of 1, 2, 5, 10, 20, 50 … cells at which lines are `GRID_MIN_PX` or more apart with `pxPerCell` pixels per cell; null when the cell size is unknown (not positive or not finite). */
export function gridStride(pxPerCell: number): number | null {
  if (!(pxPerCell > 0) || !Number.isFinite(pxPerCell)) return null;
  for (let decade = 1; ; decade *= 10) {
    for (const m of [1, 2, 5]) {
      if (m * decade * pxPerCell >= GRID_MIN_PX) return m * decade;
    }
  }
}

/** The major-line stride of minor stride `stride`: the next power of ten above it (10 for 1, 2 and 5). */
export const majorStride = (stride: number): number => 10 ** (Math.floor(Math.log10(stride) + 1e-9) + 1);

/**
 * The grid lines u = n and v = n (n a multiple of `stride`) across `bounds`
 * ([min u, min v, max u, max v]), 2 xyz points per line at height `z`: the
 * multiples of `majorStride(stride)` in `major`, the others in `minor`.
 */
export function gridLines(bounds: readonly [number, number, number, number], stride: number, z: number): { minor: Float32Array; major: Float32Array } {
  const [minU, minV, maxU, maxV] = bounds;
  if (![minU, minV, maxU, maxV, stride].every(Number.isFinite) || !(stride > 0)) return { minor: new Float32Array(0), major: new Float32Array(0) };
  const major = majorStride(stride);
  const minorOut: number[] = [];
  const majorOut: number[] = [];
  for (let axis = 0; axis < 2; axis++) {
    const [lo, hi, from, to] = axis === 0 ? [minU, maxU, minV, maxV] : [minV, maxV, minU, maxU];
    for (let n = Math.ceil(lo / stride) * stride; n <= hi; n += stride) {
      const out = n % major === 0 ? majorOut : minorOut;
      if (axis === 0) out.push(n, from, z, n, to, z);
      else out.push(from, n, z, to, n, z);
    }
  }
  return { minor: Float32Array.from(minorOut), major: Float32Array.from(majorOut) };
}
