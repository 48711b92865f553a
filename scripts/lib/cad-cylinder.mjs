// A closed cylinder as a CAD kernel exports it, as OBJ text: the low-poly
// input the quad solve refines first (crate `pipeline::QUAD_MAX_EDGE`).
// Used by the bench, the node tests and the page tests.

/**
 * Radius 1, height 2 around the z axis, `n` rim vertices at each end: the
 * side one band of long triangles (two per segment), each cap a fan from
 * its first rim vertex (4 n - 4 faces; the rims are the only edges > 60°).
 */
export function cadCylinderObj(n) {
  const lines = [];
  for (const z of [0, 2]) {
    for (let i = 0; i < n; i++) lines.push(`v ${Math.cos((2 * Math.PI * i) / n)} ${Math.sin((2 * Math.PI * i) / n)} ${z}`);
  }
  for (let i = 1; i <= n; i++) {
    const j = (i % n) + 1;
    lines.push(`f ${i} ${j} ${n + j}`, `f ${i} ${n + j} ${n + i}`);
  }
  for (let i = 2; i < n; i++) lines.push(`f 1 ${i + 1} ${i}`, `f ${n + 1} ${n + i} ${n + i + 1}`);
  return lines.join('\n') + '\n';
}
