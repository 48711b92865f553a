// The charts of a UV map: connected UV islands, i.e. the faces connected
// across edges that are not seams (a seamless map of a closed mesh is one
// chart per component). Union-find over the faces, then compact ids and the
// faces of each chart in CSR form. Pure typed-array code without three.js.

/** The charts of a map: the chart of each face, and each chart's faces (`faces[offsets[c] .. offsets[c + 1]]`). */
export interface Charts {
  chartOf: Uint32Array;
  offsets: Uint32Array;
  faces: Uint32Array;
}

/**
 * The charts of the faces whose sides have the edges `faceEdges` (3 per face;
 * ≥ `edgeCount`: no edge) when the edges `seams` are cut: faces sharing an
 * edge that is not a seam are in the same chart. Charts are numbered in the
 * order of their first face.
 */
export function faceCharts(faceEdges: Uint32Array, edgeCount: number, seams: ArrayLike<number>): Charts {
  const n = Math.floor(faceEdges.length / 3);
  const cut = new Uint8Array(edgeCount);
  for (let i = 0; i < seams.length; i++) if (seams[i]! < edgeCount) cut[seams[i]!] = 1;
  const parent = new Uint32Array(n);
  for (let f = 0; f < n; f++) parent[f] = f;
  const find = (f: number): number => {
    let r = f;
    while (parent[r] !== r) r = parent[r]!;
    while (parent[f] !== r) {
      const next = parent[f]!;
      parent[f] = r;
      f = next;
    }
    return r;
  };
  // The first face seen on each edge; every later one joins it.
  const first = new Int32Array(edgeCount).fill(-1);
  for (let s = 0; s < 3 * n; s++) {
    const e = faceEdges[s]!;
    if (e >= edgeCount || cut[e]) continue;
    const f = (s / 3) | 0;
    const g = first[e]!;
    if (g < 0) {
      first[e] = f;
      continue;
    }
    const a = find(f);
    const b = find(g);
    if (a !== b) parent[Math.max(a, b)] = Math.min(a, b);
  }
  const chartOf = new Uint32Array(n);
  const idOfRoot = new Int32Array(n).fill(-1);
  let count = 0;
  for (let f = 0; f < n; f++) {
    const r = find(f);
    if (idOfRoot[r]! < 0) idOfRoot[r] = count++;
    chartOf[f] = idOfRoot[r]!;
  }
  const offsets = new Uint32Array(count + 1);
  for (let f = 0; f < n; f++) offsets[chartOf[f]! + 1]!++;
  for (let c = 0; c < count; c++) offsets[c + 1]! += offsets[c]!;
  const faces = new Uint32Array(n);
  const next = offsets.slice(0, count);
  for (let f = 0; f < n; f++) faces[next[chartOf[f]!]!++] = f;
  return { chartOf, offsets, faces };
}

/** The faces of chart `chart` of `charts` (a view, not a copy); empty for an unknown chart. */
export function chartFaces(charts: Charts, chart: number): Uint32Array {
  if (!(chart >= 0 && chart + 1 < charts.offsets.length)) return new Uint32Array(0);
  return charts.faces.subarray(charts.offsets[chart]!, charts.offsets[chart + 1]!);
}
