// Test-only stand-in for the parametrization while the wasm build has no
// `MeshSession.solve`: a 3-chart axis projection with its seams and an area
// distortion per face, in the shapes `solve` returns. Lets the browser tests
// exercise the UV display (checkerboard, heat map, histogram, UV view, hover).
// Never used unless a test asks for it (`simulateUv` on the solve request).
import type { SolveMetrics } from './protocol';

export function fakeUv(positions: Float32Array, indices: Uint32Array, faceEdges: Uint32Array, edgeCount: number): {
  uv: Float32Array;
  seam_edges: Uint32Array;
  metrics: SolveMetrics;
} {
  const faces = indices.length / 3;
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i++) {
    const c = i % 3;
    lo[c] = Math.min(lo[c]!, positions[i]!);
    hi[c] = Math.max(hi[c]!, positions[i]!);
  }
  const size = Math.max(hi[0]! - lo[0]!, hi[1]! - lo[1]!, hi[2]! - lo[2]!) || 1;
  const uv = new Float32Array(faces * 6);
  const axisOf = new Uint8Array(faces);
  const perFace = new Float32Array(faces);
  const p = (v: number, c: number): number => positions[3 * v + c]!;
  let sum = 0;
  let below2 = 0;
  let below3 = 0;
  for (let f = 0; f < faces; f++) {
    const [a, b, c] = [indices[3 * f]!, indices[3 * f + 1]!, indices[3 * f + 2]!];
    const e1 = [p(b, 0) - p(a, 0), p(b, 1) - p(a, 1), p(b, 2) - p(a, 2)];
    const e2 = [p(c, 0) - p(a, 0), p(c, 1) - p(a, 1), p(c, 2) - p(a, 2)];
    const n = [e1[1]! * e2[2]! - e1[2]! * e2[1]!, e1[2]! * e2[0]! - e1[0]! * e2[2]!, e1[0]! * e2[1]! - e1[1]! * e2[0]!];
    const an = n.map(Math.abs);
    const axis = an[0]! >= an[1]! && an[0]! >= an[2]! ? 0 : an[1]! >= an[2]! ? 1 : 2;
    axisOf[f] = axis;
    const [u, w] = axis === 0 ? [1, 2] : axis === 1 ? [0, 2] : [0, 1];
    for (let k = 0; k < 3; k++) {
      const v = indices[3 * f + k]!;
      uv[6 * f + 2 * k] = (p(v, u) - lo[u]!) / size + axis * 1.1;
      uv[6 * f + 2 * k + 1] = (p(v, w) - lo[w]!) / size;
    }
    const area3 = Math.hypot(n[0]!, n[1]!, n[2]!);
    const d = area3 > 0 ? Math.min(2, Math.abs(Math.log(an[axis]! / area3))) : 0;
    perFace[f] = d;
    sum += d;
    if (d < 0.2) below2++;
    if (d < 0.3) below3++;
  }
  const firstAxis = new Int8Array(edgeCount).fill(-1);
  const seam = new Uint8Array(edgeCount);
  for (let f = 0; f < faces; f++) {
    for (let k = 0; k < 3; k++) {
      const e = faceEdges[3 * f + k]!;
      if (e >= edgeCount) continue;
      if (firstAxis[e] === -1) firstAxis[e] = axisOf[f]!;
      else if (firstAxis[e] !== axisOf[f]) seam[e] = 1;
    }
  }
  const seams: number[] = [];
  for (let e = 0; e < edgeCount; e++) if (seam[e]) seams.push(e);
  return {
    uv,
    seam_edges: Uint32Array.from(seams),
    metrics: {
      distortion: sum / Math.max(faces, 1),
      below_0_2: below2 / Math.max(faces, 1),
      below_0_3: below3 / Math.max(faces, 1),
      flipped: 0,
      seam_angle_residual: 0,
      seam_length_residual: 0,
      alignment_residual: 0,
      cones: 0,
      seam_length: 0,
      per_face_distortion: perFace,
    },
  };
}
