// Solve errors through the wasm build. A needle whose sharp rim encloses
// nearly 2 pi of curvature needs a cone of angle 0 at its apex: by default the
// solve refines around it and spreads the cone; with the refinement turned off
// (`set_max_cone_refinements(0)`) it fails for real, and the Error carries
// `location` in input ids, as the page's worker sees it.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { loadWasm, needleObj } from './wasm.mjs';

const wasm = loadWasm();

const open = (h) => wasm.MeshSession.open([{ name: 'needle.obj', bytes: new TextEncoder().encode(needleObj(h)) }]);

/** The apex (welded id) and the rim edges (ids of the base hexagon's sides), from the session's own arrays. */
function needleParts(session, h) {
  const p = session.positions();
  const at = (v) => [p[3 * v], p[3 * v + 1], p[3 * v + 2]];
  const n = p.length / 3;
  const apex = [...Array(n).keys()].find((v) => at(v)[2] === h);
  const centre = [...Array(n).keys()].find((v) => at(v).every((x) => x === 0));
  const edges = session.edges();
  const rim = [];
  for (let e = 0; e < edges.length / 2; e++) {
    const ends = [edges[2 * e], edges[2 * e + 1]];
    if (!ends.includes(apex) && !ends.includes(centre)) rim.push(e);
  }
  return { apex, rim };
}

const sorted = (a) => [...a].sort((x, y) => x - y);

test('a needle with a sharp rim solves by default, and without refinement fails with the apex and the rim as its location', () => {
  const session = open(30);
  const { apex, rim } = needleParts(session, 30);
  const sharp = session.sharp_edges(75);
  assert.deepEqual(sorted(sharp), rim, 'the rim is the sharp set');
  const solved = session.solve(sharp, 0.01, false, () => {});
  assert.ok(solved.inserted_vertices > 0, 'the apex was refined around');
  assert.equal(solved.metrics.flipped, 0);
  assert.ok(solved.cones.every((c) => c.k <= 3));

  session.set_max_cone_refinements(0);
  let thrown;
  try {
    session.solve(sharp, 0.01, false, () => {});
  } catch (e) {
    thrown = e;
  }
  assert.ok(thrown instanceof Error, `expected an Error, got ${thrown}`);
  assert.match(thrown.message, new RegExp(`the cone at vertex v${apex} would need index 4 \\(a cone angle of 0°, `));
  assert.match(thrown.message, /the 6 feature edges around it \(\(v\d+, v\d+\), /);
  assert.match(thrown.message, /unmark some of them or subdivide the mesh there/);
  assert.deepEqual(thrown.location.vertices, [apex]);
  assert.deepEqual(sorted(thrown.location.edges), rim);
  assert.ok(Array.isArray(thrown.location.vertices) && Array.isArray(thrown.location.edges));

  // The same error through the steps the page's worker runs.
  const schedule = session.solve_begin(sharp, 0.01, false);
  for (const c of schedule) session.solve_place(c, false, () => {});
  assert.throws(() => session.solve_finish(() => {}), (e) => {
    assert.equal(e.message, thrown.message);
    assert.deepEqual(e.location, thrown.location);
    return true;
  });
  // Other errors carry no location; the session still answers.
  assert.throws(() => session.solve_finish(() => {}), (e) => /no solve was started/.test(e.message) && e.location === undefined);
  assert.deepEqual(sorted(session.sharp_edges(75)), rim);
  session.set_max_cone_refinements(undefined);
  assert.equal(session.solve(sharp, 0.01, false, () => {}).metrics.flipped, 0, 'the default again');
});
