// An independent check of an exported UV map, as an outside checker would do
// it: weld by position, then measure seam transitions, boundary alignment and
// orientation from the file alone.

/** Parses an OBJ with `v`, `vt` and `f v/vt[/vn]` lines (triangles). */
export function parseObj(text) {
  const v = [];
  const vt = [];
  const faces = [];
  for (const line of text.split('\n')) {
    const t = line.trim().split(/\s+/);
    if (t[0] === 'v') v.push(t.slice(1, 4).map(Number));
    else if (t[0] === 'vt') vt.push(t.slice(1, 3).map(Number));
    else if (t[0] === 'f') faces.push(t.slice(1, 4).map((c) => c.split('/').map((x) => Number(x) - 1)));
  }
  return { v, vt, faces };
}

const angleTo90 = (a) => Math.abs(a - Math.round(a / (Math.PI / 2)) * (Math.PI / 2));

/**
 * Seamlessness, alignment and orientation of `{v, vt, faces}`:
 * - maxSeamAngle: largest deviation (rad) of a seam edge's transition from a
 *   multiple of 90°; maxSeamLength: largest relative length difference;
 * - maxBoundaryAxis: largest angle between a boundary edge's UV image and the
 *   nearest axis; flipped: triangles with UV area ≤ 0.
 */
export function checkUv({ v, vt, faces }) {
  const key = (i) => v[i].join(',');
  const weld = new Map();
  const id = (i) => {
    const k = key(i);
    if (!weld.has(k)) weld.set(k, weld.size);
    return weld.get(k);
  };
  const edges = new Map();
  let flipped = 0;
  for (const f of faces) {
    const uv = f.map((c) => vt[c[1]]);
    const area = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
    if (!(area > 0)) flipped += 1;
    for (let k = 0; k < 3; k++) {
      const [a, b] = [f[k], f[(k + 1) % 3]];
      const [wa, wb] = [id(a[0]), id(b[0])];
      const forward = wa < wb;
      const ekey = forward ? `${wa},${wb}` : `${wb},${wa}`;
      // UVs at the lower and the higher welded end.
      const ends = forward ? [vt[a[1]], vt[b[1]]] : [vt[b[1]], vt[a[1]]];
      if (!edges.has(ekey)) edges.set(ekey, []);
      edges.get(ekey).push(ends);
    }
  }
  let maxSeamAngle = 0;
  let maxSeamLength = 0;
  let maxBoundaryAxis = 0;
  let seams = 0;
  for (const sides of edges.values()) {
    if (sides.length === 1) {
      const [p, q] = sides[0];
      maxBoundaryAxis = Math.max(maxBoundaryAxis, angleTo90(Math.atan2(q[1] - p[1], q[0] - p[0])));
      continue;
    }
    const [[p1, q1], [p2, q2]] = sides;
    const same = p1[0] === p2[0] && p1[1] === p2[1] && q1[0] === q2[0] && q1[1] === q2[1];
    if (same) continue;
    seams += 1;
    const d1 = [q1[0] - p1[0], q1[1] - p1[1]];
    const d2 = [q2[0] - p2[0], q2[1] - p2[1]];
    const angle = Math.atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1]);
    maxSeamAngle = Math.max(maxSeamAngle, angleTo90(angle));
    const l1 = Math.hypot(...d1);
    const l2 = Math.hypot(...d2);
    maxSeamLength = Math.max(maxSeamLength, Math.abs(l1 - l2) / Math.max(l1, l2));
  }
  return { maxSeamAngle, maxSeamLength, maxBoundaryAxis, flipped, seams, vertices: weld.size };
}

/**
 * Largest angle between the UV image of each given edge (end positions, as
 * in a features file) and the nearest axis, over every face side of it.
 * Ends match the nearest vertex within `tolerance`; unmatched edges count.
 */
export function edgeAlignment({ v, vt, faces }, edges, tolerance) {
  const near = (p) => {
    let best = -1;
    let bd = tolerance;
    for (let i = 0; i < v.length; i++) {
      const d = Math.hypot(v[i][0] - p[0], v[i][1] - p[1], v[i][2] - p[2]);
      if (d <= bd) [best, bd] = [i, d];
    }
    return best;
  };
  const key = (i) => v[i].join(',');
  let worst = 0;
  let missing = 0;
  for (const [p, q] of edges) {
    const [a, b] = [near(p), near(q)];
    if (a < 0 || b < 0) {
      missing += 1;
      continue;
    }
    let found = false;
    for (const f of faces) {
      for (let k = 0; k < 3; k++) {
        const [c, d] = [f[k], f[(k + 1) % 3]];
        const ends = [key(c[0]), key(d[0])];
        if ((ends[0] === key(a) && ends[1] === key(b)) || (ends[0] === key(b) && ends[1] === key(a))) {
          const [s, t] = [vt[c[1]], vt[d[1]]];
          worst = Math.max(worst, angleTo90(Math.atan2(t[1] - s[1], t[0] - s[0])));
          found = true;
        }
      }
    }
    if (!found) missing += 1;
  }
  return { worst, missing };
}
