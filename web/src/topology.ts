// Typed-array mesh connectivity for picking and feature paths: vertex → (neighbour,
// edge id) adjacency in CSR form, face → edge ids, and Dijkstra over edge lengths.
// Pure functions; used in the worker (building) and on the main thread (queries).

/** Vertex adjacency: the neighbours of v are nbr[offsets[v] .. offsets[v+1]], reached by edge eid[i]. */
export interface Adjacency {
  offsets: Uint32Array;
  nbr: Uint32Array;
  eid: Uint32Array;
}

/** Builds the CSR adjacency from `edges` (2 vertex ids per edge, edge id = index / 2). */
export function buildAdjacency(edges: Uint32Array, vertexCount: number): Adjacency {
  const m = edges.length / 2;
  const offsets = new Uint32Array(vertexCount + 1);
  for (let i = 0; i < edges.length; i++) offsets[edges[i]! + 1]!++;
  for (let v = 0; v < vertexCount; v++) offsets[v + 1]! += offsets[v]!;
  const fill = offsets.slice(0, vertexCount);
  const nbr = new Uint32Array(2 * m);
  const eid = new Uint32Array(2 * m);
  for (let e = 0; e < m; e++) {
    const a = edges[2 * e]!;
    const b = edges[2 * e + 1]!;
    let i = fill[a]!++;
    nbr[i] = b;
    eid[i] = e;
    i = fill[b]!++;
    nbr[i] = a;
    eid[i] = e;
  }
  return { offsets, nbr, eid };
}

/** Edge id between vertices a and b, or -1. */
export function edgeBetween(adj: Adjacency, a: number, b: number): number {
  for (let i = adj.offsets[a]!, end = adj.offsets[a + 1]!; i < end; i++) if (adj.nbr[i] === b) return adj.eid[i]!;
  return -1;
}

/**
 * Edge ids of each face's sides: out[3f + k] is the edge from corner k to corner
 * k+1; 0xffffffff where the side has no edge (invalid meshes).
 */
export function faceEdges(indices: Uint32Array, adj: Adjacency): Uint32Array {
  const out = new Uint32Array(indices.length);
  for (let t = 0; t < indices.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const e = edgeBetween(adj, indices[t + k]!, indices[t + ((k + 1) % 3)]!);
      out[t + k] = e < 0 ? 0xffffffff : e;
    }
  }
  return out;
}

/**
 * Shortest path (sum of edge lengths) from vertex `from` to `to`; returns its edge
 * ids in order, or null when `to` cannot be reached. Binary heap on typed arrays.
 */
export function shortestPath(adj: Adjacency, positions: Float32Array, from: number, to: number): Uint32Array | null {
  const n = adj.offsets.length - 1;
  if (from === to) return new Uint32Array(0);
  const dist = new Float64Array(n).fill(Infinity);
  const via = new Int32Array(n).fill(-1); // edge id used to reach the vertex
  const done = new Uint8Array(n);
  // Heap of (dist, vertex) with lazy deletion.
  let heapD = new Float64Array(1024);
  let heapV = new Uint32Array(1024);
  let size = 0;
  const push = (d: number, v: number): void => {
    if (size === heapD.length) {
      const nd = new Float64Array(size * 2);
      nd.set(heapD);
      heapD = nd;
      const nv = new Uint32Array(size * 2);
      nv.set(heapV);
      heapV = nv;
    }
    let i = size++;
    while (i > 0) {
      const p = (i - 1) >> 1;
      if (heapD[p]! <= d) break;
      heapD[i] = heapD[p]!;
      heapV[i] = heapV[p]!;
      i = p;
    }
    heapD[i] = d;
    heapV[i] = v;
  };
  const pop = (): number => {
    const top = heapV[0]!;
    const d = heapD[--size]!;
    const v = heapV[size]!;
    let i = 0;
    for (;;) {
      let c = 2 * i + 1;
      if (c >= size) break;
      if (c + 1 < size && heapD[c + 1]! < heapD[c]!) c++;
      if (heapD[c]! >= d) break;
      heapD[i] = heapD[c]!;
      heapV[i] = heapV[c]!;
      i = c;
    }
    heapD[i] = d;
    heapV[i] = v;
    return top;
  };
  dist[from] = 0;
  push(0, from);
  while (size > 0) {
    const v = pop();
    if (done[v]) continue;
    done[v] = 1;
    if (v === to) break;
    const dv = dist[v]!;
    const vx = positions[3 * v]!;
    const vy = positions[3 * v + 1]!;
    const vz = positions[3 * v + 2]!;
    for (let i = adj.offsets[v]!, end = adj.offsets[v + 1]!; i < end; i++) {
      const w = adj.nbr[i]!;
      if (done[w]) continue;
      const dx = positions[3 * w]! - vx;
      const dy = positions[3 * w + 1]! - vy;
      const dz = positions[3 * w + 2]! - vz;
      const d = dv + Math.sqrt(dx * dx + dy * dy + dz * dz);
      if (d < dist[w]!) {
        dist[w] = d;
        via[w] = adj.eid[i]!;
        push(d, w);
      }
    }
  }
  if (!done[to]) return null;
  const path: number[] = [];
  for (let v = to; v !== from; ) {
    const e = via[v]!;
    path.push(e);
    const i = adj.offsets[v]!;
    // The other end of edge e from v.
    let other = -1;
    for (let j = i, end = adj.offsets[v + 1]!; j < end; j++) if (adj.eid[j] === e) other = adj.nbr[j]!;
    v = other;
  }
  return Uint32Array.from(path.reverse());
}
