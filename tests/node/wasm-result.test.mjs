// The wasm results against the TypeScript types that mirror them
// (web/src/protocol.ts): the same keys, the typed arrays the worker transfers,
// and figures that agree with each other.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { before, test } from 'node:test';
import { cadCylinderObj } from '../../scripts/lib/cad-cylinder.mjs';
import { committedFandisk, loadPageModule, loadWasm, sharedMesh } from './wasm.mjs';

const wasm = loadWasm();
let protocol;
before(async () => {
  protocol = await loadPageModule('protocol');
});

const open = (file) => wasm.MeshSession.open([{ name: path.basename(file), bytes: new Uint8Array(fs.readFileSync(file)) }]);
const sorted = (o) => Object.keys(o).sort();

test('place_cones returns exactly the fields of ConeResult', () => {
  const r = open(sharedMesh('woody')).place_cones(new Uint32Array(), 0.01, false, () => {});
  assert.deepEqual(sorted(r), sorted(protocol.CONE_RESULT_KEYS));
  assert.equal(Object.getPrototypeOf(r), Object.prototype, 'a plain object, not a Map');
  assert.equal(r.free_boundary, false);
  assert.equal(r.inserted_vertices, 0);
});

test('solve returns exactly the fields of WasmSolveResult, arrays typed and sized', () => {
  const session = open(sharedMesh('woody'));
  const faces = session.indices().length / 3;
  const r = session.solve(new Uint32Array(), 0.01, false, () => {});
  assert.deepEqual(sorted(r), sorted(protocol.WASM_SOLVE_RESULT_KEYS));
  assert.deepEqual(sorted(r.metrics), sorted(protocol.SOLVE_METRICS_KEYS));
  assert.ok(r.uv instanceof Float32Array && r.uv.length === 6 * faces, 'uv: 2 per face corner');
  assert.ok(r.seam_edges instanceof Uint32Array && r.seam_edges.length === r.metrics.seam_edges);
  assert.ok(r.metrics.per_face_distortion instanceof Float32Array && r.metrics.per_face_distortion.length === faces);
  assert.ok(r.glb instanceof Uint8Array && new TextDecoder().decode(r.glb.subarray(0, 4)) === 'glTF');
  assert.ok(r.obj instanceof Uint8Array && /^v /m.test(new TextDecoder().decode(r.obj)));
  assert.equal(r.metrics.cones, r.cones.length);
  assert.equal(r.metrics.boundary_corners, r.boundary_corners.length);
  assert.equal(r.metrics.faces, faces);
  assert.equal(r.metrics.flipped, 0);
  assert.equal(r.feature_alignment.requested, 0);
  assert.ok(r.param_timings.arap >= 0 && r.timings.total > 0);
});

test('quads returns exactly the fields of QuadsResult: a valid quad mesh, grid UVs, a quad-only OBJ', () => {
  const session = open(committedFandisk);
  assert.throws(() => session.quads(1000, () => {}), /solve/, 'quads need a solve first');
  const faces = session.indices().length / 3;
  session.solve(session.sharp_edges(60), 1, false, () => {});
  const stages = new Set();
  const r = session.quads(1000, (stage) => stages.add(stage));
  assert.deepEqual([...stages], ['quantization', 'quad extraction']);
  assert.deepEqual(sorted(r), sorted(protocol.QUADS_RESULT_KEYS));
  assert.deepEqual(sorted(r.quantization), sorted(protocol.QUANTIZE_REPORT_KEYS));
  assert.deepEqual(sorted(r.report), sorted(protocol.QUAD_REPORT_KEYS));
  assert.equal(Object.getPrototypeOf(r.report.valence_histogram.interior), Object.prototype, 'a plain object, not a Map');
  for (const key of ['uv', 'positions']) assert.ok(r[key] instanceof Float32Array, key);
  for (const key of ['quads', 'edges', 'singular']) assert.ok(r[key] instanceof Uint32Array, key);
  for (const key of ['obj', 'glb', 'grid_glb']) assert.ok(r[key] instanceof Uint8Array, key);
  assert.equal(r.uv.length, 6 * faces, 'uv: 2 per input face corner');
  assert.ok(r.uv.every(Number.isFinite));
  const n = r.quads.length / 4;
  assert.equal(r.report.quads, n);
  assert.ok(Math.abs(n - 1000) < 150, `${n} quads for 1000`);
  const vertices = r.positions.length / 3;
  assert.equal(r.report.vertices, vertices);
  for (let q = 0; q < n; q++) {
    const ids = Array.from(r.quads.subarray(4 * q, 4 * q + 4));
    assert.ok(ids.every((v) => v < vertices), `quad ${q} has a vertex out of range`);
    assert.equal(new Set(ids).size, 4, `quad ${q} repeats a vertex`);
  }
  assert.equal(r.edges.length / 2, r.report.edges);
  assert.ok(r.edges.every((v) => v < vertices));
  assert.equal(r.singular.length % 2, 0);
  assert.equal(r.singular.length / 2, r.report.singular_vertices.filter((v) => !v.boundary).length);
  assert.equal(r.defects, r.report.defects);
  assert.ok(r.quantization.grid_size > 0 && r.quantization.cells > 0);
  const obj = new TextDecoder().decode(r.obj);
  const faceLines = obj.split('\n').filter((l) => l.startsWith('f '));
  assert.equal(faceLines.length, n, 'one f line per quad');
  for (const l of faceLines) assert.equal(l.trim().split(/\s+/).length, 5, `not a quad: ${l}`);
  for (const glb of [r.glb, r.grid_glb]) assert.equal(new TextDecoder().decode(glb.subarray(0, 4)), 'glTF');
});

test('quads of a low-poly mesh are traced on a map solved again on its refinement, once', () => {
  // 12 segments: the UV map keeps the input triangles (its caps' corners,
  // spread 90° apart, fold none of the fans of thin triangles; at 16, 20 and
  // from 28 segments they do, and solve splits long edges too; bunched, the
  // corners gave maps of distortion 0.44-0.66).
  const n = 12;
  const session = wasm.MeshSession.open([{ name: 'cylinder.obj', bytes: new TextEncoder().encode(cadCylinderObj(n)) }]);
  const faces = session.indices().length / 3;
  assert.equal(faces, 4 * n - 4);
  const solved = session.solve(session.sharp_edges(60), undefined, false, () => {});
  assert.equal(solved.refinement.long_edges, 0, 'the UV map keeps the input triangles');
  assert.ok(solved.metrics.distortion < 0.25, `distortion ${solved.metrics.distortion}`);
  const stages = new Set();
  const r = session.quads(1000, (stage) => stages.add(stage));
  assert.ok(stages.has('rounding') && stages.has('quantization'), [...stages].join(', '));
  assert.ok(r.refinement.long_edges > 0 && r.inserted_vertices > 0, JSON.stringify(r.refinement));
  assert.ok(r.solved_faces > 10 * faces, `${r.solved_faces} faces`);
  assert.equal(r.uv.length, 6 * faces, 'grid UVs still on the input corners');
  assert.equal(r.defects, 0);
  assert.equal(r.report.euler_characteristic, 2);
  assert.equal(r.report.flipped_quads, 0);
  assert.ok(r.report.angle_mean_deviation < 8, `${r.report.angle_mean_deviation}°`);
  assert.ok(r.report.singular_vertices.every((v) => v.valence === 3 || v.valence === 5), 'valences 3 and 5 only');
  const again = new Set();
  const r2 = session.quads(600, (stage) => again.add(stage));
  assert.deepEqual([...again], ['quantization', 'quad extraction'], 'another count re-runs only quantization and extraction');
  assert.equal(r2.solved_faces, r.solved_faces);
});

test('quads of a mesh much finer than its quads are traced on a decimation, moved onto the mesh, the grid map carried back', () => {
  // 30 faces per quad at 1 000 quads: decimated to about 8.
  const session = open(sharedMesh('bff-cowhead'));
  const faces = session.indices().length / 3;
  session.solve(new Uint32Array(), undefined, false, () => {});
  const stages = new Set();
  const r = session.quads(1000, (stage) => stages.add(stage));
  assert.ok(stages.has('decimation') && stages.has('rounding') && stages.has('quantization'), [...stages].join(', '));
  assert.ok(r.decimated && r.decimated.faces < faces / 2 && r.decimated.faces > 4 * 1000, JSON.stringify(r.decimated));
  assert.equal(r.solved_faces, r.decimated.faces, 'the map solved on the decimation');
  assert.ok(r.timings.decimate > 0 && r.timings.solve > 0 && r.timings.quantize > 0, JSON.stringify(r.timings));
  // The quads against the input: the figures the CLI's quads checks.
  assert.equal(r.defects, 0);
  assert.equal(r.report.euler_characteristic, 1);
  assert.equal(r.report.boundary_loops, 1);
  assert.equal(r.report.flipped_quads + r.report.degenerate_quads, 0);
  const distance = Math.max(r.report.distance_quads_to_input_relative, r.report.distance_input_to_quads_relative);
  assert.ok(distance < 0.015, `distance ${distance}`);
  assert.ok(r.decimated.largest_projection > 0);
  // The grid map on every input corner, no input triangle turned over in it.
  assert.equal(r.uv.length, 6 * faces);
  let turned = 0;
  for (let f = 0; f < faces; f++) {
    const u = r.uv.subarray(6 * f, 6 * f + 6);
    if ((u[2] - u[0]) * (u[5] - u[1]) - (u[3] - u[1]) * (u[4] - u[0]) <= 0) turned++;
  }
  assert.equal(turned, 0, `${turned} input triangles turned over in the carried map`);
  const again = new Set();
  const r2 = session.quads(1000, (stage) => again.add(stage));
  assert.deepEqual([...again], ['quantization', 'quad extraction'], 'the same count: the decimation and its solve kept');
  assert.equal(r2.report.quads, r.report.quads);
});

test('quads cancel the opposite cones a coarse grid cannot keep apart, solving again only when those pairs change', () => {
  const session = open(sharedMesh('cow'));
  const solved = session.solve(new Uint32Array(), undefined, false, () => {});
  const stages = new Set();
  const r = session.quads(1000, (stage) => stages.add(stage));
  assert.ok(r.cancelled_pairs > 0, 'the cow has opposite cones closer than a quad diagonal at 1 000 quads');
  assert.ok(stages.has('rounding') && stages.has('quantization'), [...stages].join(', '));
  assert.ok(r.cones < solved.cones.length && r.cones >= solved.cones.length - 2 * r.cancelled_pairs, `${solved.cones.length} -> ${r.cones}`);
  const singular = r.report.singular_vertices.filter((v) => !v.boundary);
  if (r.defects === 0) assert.equal(singular.length, r.cones, 'one singular vertex per cone');
  const again = new Set();
  const r2 = session.quads(1000, (stage) => again.add(stage));
  assert.deepEqual([...again], ['quantization', 'quad extraction'], 'the same pairs: only quantization and extraction again');
  assert.equal(r2.cones, r.cones);
  const fine = session.quads(10000, () => {});
  assert.ok(fine.cancelled_pairs < r.cancelled_pairs && fine.cones > r.cones, `${fine.cancelled_pairs} pairs at 10 000 quads`);
});

test('quads drop the feature curves finer than the grid where the map with them folds, and say so', () => {
  // The teapot's one crease above 60° is the spout's lip: 4 edges, under two quads at 3 000.
  const session = open(sharedMesh('teapot'));
  const sharp = session.sharp_edges(60);
  assert.equal(sharp.length, 4);
  session.solve(sharp, undefined, false, () => {});
  const r = session.quads(3000, () => {});
  assert.equal(r.dropped_feature_edges, 4, 'solved without the lip');
  assert.equal(r.quantization.flipped + r.quantization.wound_vertices, 0, 'the map without the lip does not fold');
  assert.equal(r.defects, 0);
  assert.ok(r.report.sharp_edges_checked >= 4, 'the check still measures the dropped edges');
  const again = new Set();
  const r2 = session.quads(3000, (stage) => again.add(stage));
  assert.deepEqual([...again], ['quantization', 'quad extraction'], 'the same edges dropped: no solve again');
  assert.equal(r2.dropped_feature_edges, 4);
  assert.equal(r2.report.quads, r.report.quads);
});

test('crease_edges are the creases conemap quads follows; quads drop them where they fold the map, unlike marked edges', () => {
  const fandisk = open(committedFandisk).crease_edges();
  assert.equal(fandisk.degrees, 75);
  assert.equal(fandisk.min_length_fraction, 0.1);
  assert.ok(fandisk.edges instanceof Uint32Array);
  assert.equal(fandisk.edges.length, 693, 'the 693 crease edges conemap quads reports for the fandisk');
  assert.deepEqual(fandisk.stats, { sharp_edges: 693, curves: 1, kept_edges: 693, dropped_fragments: 0, pruned_edges: 0 });
  // The cow's 32 crease edges fold its map at 1 000 quads: passed as
  // creases they all go (as in the CLI); passed only as features, only
  // curves finer than the grid would (1 edge), and the map folds.
  const session = open(sharedMesh('cow'));
  const creases = session.crease_edges().edges;
  assert.equal(creases.length, 32);
  const edges = session.edges().length / 2;
  assert.throws(() => session.solve_begin(creases, undefined, false, Uint32Array.of(edges)), /feature edge id \d+ is out of range/);
  // (`solve` takes the creases as its last argument; the page passes them to `solve_begin`.)
  session.solve(creases, undefined, false, () => {}, creases);
  const r = session.quads(1000, () => {});
  assert.equal(r.dropped_crease_edges, 32);
  assert.equal(r.dropped_feature_edges, 32);
  assert.equal(r.quantization.flipped + r.quantization.wound_vertices, 0, 'the map without the creases does not fold');
  assert.equal(r.defects, 0);
});

test('quads of a game asset of 56 parts: every part rounded on its own, the quad mesh closed', () => {
  const session = open(sharedMesh('xatlas-gazebo'));
  session.solve(new Uint32Array(), undefined, false, () => {});
  const r = session.quads(3000, () => {});
  assert.equal(r.defects, 0);
  assert.equal(r.quantization.flipped, 0);
  assert.equal(r.quantization.wound_vertices, 0);
  assert.equal(r.quantization.conflicts, 0);
  assert.equal(r.report.euler_characteristic, 111, 'the input has 56 parts: V - E + F = 111');
  assert.ok(Math.abs(r.report.quads - 3000) < 900, `${r.report.quads} quads for 3000`);
  const singular = r.report.singular_vertices.filter((v) => !v.boundary);
  assert.ok(singular.every((v) => v.valence >= 2 && v.valence !== 4), 'singular vertices have valence 4 - k, k != 0');
});
