// Unique undirected edges of a triangle list, for the wireframe overlay.

/** Meshes above this many triangles get no overlay (memory and draw time). */
export const MAX_WIREFRAME_FACES = 2_000_000;

/** Returns each undirected edge once as a pair of vertex indices. */
export function uniqueEdges(indices: Uint32Array, vertexCount: number): Uint32Array {
  const n = indices.length;
  const keys = new Float64Array(n);
  for (let t = 0; t < n; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = indices[t + k]!;
      const b = indices[t + ((k + 1) % 3)]!;
      keys[t + k] = a < b ? a * vertexCount + b : b * vertexCount + a;
    }
  }
  keys.sort();
  let unique = 0;
  for (let i = 0; i < n; i++) if (i === 0 || keys[i] !== keys[i - 1]) unique++;
  const out = new Uint32Array(unique * 2);
  let j = 0;
  for (let i = 0; i < n; i++) {
    const key = keys[i]!;
    if (i > 0 && key === keys[i - 1]) continue;
    const a = Math.floor(key / vertexCount);
    out[j++] = a;
    out[j++] = key - a * vertexCount;
  }
  return out;
}
