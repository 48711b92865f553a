// The size of the markers on mesh vertices (cones, boundary corners): scaled
// with the local edge length around each vertex, so that markers on
// neighbouring vertices of a fine region do not pile up into one blob, and
// capped at a share of the mesh's size on coarse ones. Pure, without three.js.

/**
 * The mean length of the face sides that end at each vertex of `vertices`
 * (ids into `positions`, xyz each; `indices`: 3 per triangle); NaN for a
 * vertex on no face or out of range.
 */
export function localEdgeLengths(positions: Float32Array, indices: Uint32Array, vertices: ArrayLike<number>): Float32Array {
  const vertexCount = Math.floor(positions.length / 3);
  const slot = new Int32Array(vertexCount).fill(-1);
  const sum = new Float64Array(vertices.length);
  const count = new Uint32Array(vertices.length);
  for (let i = 0; i < vertices.length; i++) {
    const v = vertices[i]!;
    if (v >= 0 && v < vertexCount && slot[v]! < 0) slot[v] = i;
  }
  for (let s = 0; s < indices.length; s++) {
    const a = indices[s]!;
    const b = indices[s - (s % 3) + ((s + 1) % 3)]!;
    const sa = a < vertexCount ? slot[a]! : -1;
    const sb = b < vertexCount ? slot[b]! : -1;
    if (sa < 0 && sb < 0) continue;
    const len = Math.hypot(positions[3 * a]! - positions[3 * b]!, positions[3 * a + 1]! - positions[3 * b + 1]!, positions[3 * a + 2]! - positions[3 * b + 2]!);
    if (sa >= 0) {
      sum[sa]! += len;
      count[sa]!++;
    }
    if (sb >= 0) {
      sum[sb]! += len;
      count[sb]!++;
    }
  }
  const out = new Float32Array(vertices.length);
  for (let i = 0; i < vertices.length; i++) {
    const v = vertices[i]!;
    const s = v >= 0 && v < vertexCount ? slot[v]! : -1;
    out[i] = s >= 0 && count[s]! > 0 ? sum[s]! / count[s]! : NaN;
  }
  return out;
}

/** Largest and smallest marker radius as shares of the mesh's bounding-box diagonal. */
export const MARKER_MAX = 0.01;
export const MARKER_MIN = 0.0015;

/**
 * The radius of a marker on a vertex whose edges are `local` long (mean): 0.4
 * of it (markers on the two ends of an edge stay apart), between MARKER_MIN
 * and MARKER_MAX of `diagonal`; MARKER_MAX of it when `local` is unknown.
 */
export function markerRadius(local: number, diagonal: number): number {
  const max = diagonal * MARKER_MAX;
  if (!(local > 0)) return max;
  return Math.min(max, Math.max(diagonal * MARKER_MIN, 0.4 * local));
}
