// The wasm results against the TypeScript types that mirror them
// (web/src/protocol.ts): the same keys, the typed arrays the worker transfers,
// and figures that agree with each other.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { before, test } from 'node:test';
import { loadPageModule, loadWasm, sharedMesh } from './wasm.mjs';

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
