// Mesh import through the wasm build, under node.
import assert from 'node:assert/strict';
import crypto from 'node:crypto';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { describe, it } from 'node:test';
import { EXPECTED, committedFandisk, importFiles, loadWasm, root, sharedMesh } from './wasm.mjs';

const wasm = loadWasm();

function checkShape(out, faces) {
  assert.ok(out.positions instanceof Float32Array, 'positions is a Float32Array');
  assert.ok(out.indices instanceof Uint32Array, 'indices is a Uint32Array');
  assert.equal(out.positions.length % 3, 0);
  assert.equal(out.indices.length, faces * 3);
  const n = out.positions.length / 3;
  let max = 0;
  for (const i of out.indices) if (i > max) max = i;
  assert.ok(max < n, `index ${max} out of range for ${n} vertices`);
  assert.ok(out.positions.every(Number.isFinite), 'all coordinates finite');
}

function checkReport(out, expected) {
  if (!out.report) return; // the report is being added to the wasm API
  const r = out.report;
  assert.equal(r.vertices, expected.vertices, 'report.vertices');
  assert.equal(r.faces, expected.faces, 'report.faces');
  assert.equal(r.euler_characteristic, expected.euler_characteristic, 'report.euler_characteristic');
  assert.ok(Array.isArray(r.problems) && Array.isArray(r.problem_messages), 'problems and problem_messages arrays');
}

describe('wasm import_mesh', () => {
  it('reports a version string', () => {
    assert.match(wasm.version(), /^\d+\.\d+\.\d+/);
  });

  it('imports the committed sample fandisk.obj', () => {
    const out = importFiles(wasm, [committedFandisk]);
    checkShape(out, 12946);
    assert.equal(out.positions.length / 3, EXPECTED.fandisk.vertices);
    checkReport(out, EXPECTED.fandisk);
  });

  for (const name of ['fandisk', 'spot', 'woody', 'alligator']) {
    const file = sharedMesh(name);
    it(`imports ../shared/meshes/${name}.obj`, () => {
      const out = importFiles(wasm, [file]);
      checkShape(out, EXPECTED[name].faces);
      checkReport(out, EXPECTED[name]);
    });
  }

  const failures = [
    { what: 'a zero-length OBJ', name: 'empty.obj', bytes: new Uint8Array(0), message: /empty/i },
    { what: 'a zero-length GLB', name: 'empty.glb', bytes: new Uint8Array(0), message: /empty/i },
    { what: 'random bytes named .glb', name: 'x.glb', bytes: crypto.randomBytes(4096), message: /malformed|glb|gltf/i },
    { what: 'an unknown extension', name: 'mesh.stl', bytes: new Uint8Array(64), message: /not a recognised|extension|\.stl/i },
    { what: 'a truncated GLB', name: 'cut.glb', bytes: truncatedGlb(), message: /malformed|truncated/i },
    { what: 'broken glTF JSON', name: 'bad.gltf', bytes: Buffer.from('{"asset": {'), message: /malformed|json|gltf/i },
  ];
  for (const f of failures) {
    it(`throws a readable Error for ${f.what}`, () => {
      assert.throws(() => importFiles(wasm, [f]), (e) => {
        assert.ok(e instanceof Error, `expected an Error, got ${typeof e}: ${e}`);
        assert.match(e.message, f.message);
        assert.ok(e.message.length < 400, 'message is one readable line');
        return true;
      });
    });
  }

  it('throws for an empty file list', () => {
    assert.throws(() => wasm.import_mesh([]), /no file/i);
  });

  it('keeps working after errors', () => {
    assert.throws(() => importFiles(wasm, [{ name: 'x.glb', bytes: crypto.randomBytes(100) }]));
    checkShape(importFiles(wasm, [committedFandisk]), 12946);
  });
});

/** Files a .gltf refers to (external buffers and images), as paths next to it. */
function companions(file) {
  if (!file.endsWith('.gltf')) return [];
  const json = JSON.parse(fs.readFileSync(file, 'utf8'));
  return [...(json.buffers ?? []), ...(json.images ?? [])]
    .map((b) => b.uri)
    .filter((uri) => typeof uri === 'string' && !uri.startsWith('data:'))
    .map((uri) => path.join(path.dirname(file), decodeURIComponent(uri)));
}

/** A GLB whose header promises more bytes than there are. */
function truncatedGlb() {
  const json = Buffer.from(JSON.stringify({ asset: { version: '2.0' } }).padEnd(32, ' '));
  const glb = Buffer.alloc(12 + 8 + json.length);
  glb.write('glTF', 0, 'latin1');
  glb.writeUInt32LE(2, 4);
  glb.writeUInt32LE(glb.length, 8);
  glb.writeUInt32LE(json.length, 12);
  glb.write('JSON', 16, 'latin1');
  json.copy(glb, 20);
  return glb.subarray(0, glb.length - 10); // cut inside the JSON chunk
}

// glTF variants written by tests/node/make-gltf.mjs must import to the same
// mesh as the OBJ they came from.
const makeGltf = path.join(root, 'tests/node/make-gltf.mjs');
describe('glTF fixtures match their OBJ', () => {
  for (const name of ['fandisk', 'spot', 'woody']) {
    const obj = name === 'fandisk' ? committedFandisk : sharedMesh(name);
    it(name, async () => {
      const { makeGltfFixtures } = await import(makeGltf);
      const dir = fs.mkdtempSync(path.join(os.tmpdir(), `conemap-gltf-${name}-`));
      try {
        const reference = importFiles(wasm, [obj]);
        const fixtures = await makeGltfFixtures(obj, dir);
        assert.ok(fixtures.length > 0, 'makeGltfFixtures returned no fixtures');
        const refFaces = reference.indices.length / 3;
        for (const fx of fixtures) {
          // `files`: main file then companions (.bin); older shapes give `path`/`file` only.
          const main = fx.files?.[0] ?? fx.path ?? fx.file;
          const mainPath = path.isAbsolute(main) ? main : path.join(dir, main);
          const rest = fx.files ? fx.files.slice(1) : companions(mainPath);
          const list = [mainPath, ...rest.map((f) => (path.isAbsolute(f) ? f : path.join(dir, f)))];
          const label = path.basename(mainPath);
          const out = importFiles(wasm, list);
          const expectedFaces = fx.faces ?? refFaces;
          assert.equal(out.indices.length / 3, expectedFaces, `${label}: faces`);
          // Fixtures that keep every OBJ face must give the OBJ's mesh (the strip
          // variant may leave out faces that repeat a vertex).
          if (expectedFaces === refFaces && out.report && reference.report) {
            assert.equal(out.report.vertices, reference.report.vertices, `${label}: welded vertices`);
            assert.equal(out.report.euler_characteristic, reference.report.euler_characteristic, `${label}: Euler characteristic`);
          }
        }
      } finally {
        fs.rmSync(dir, { recursive: true, force: true });
      }
    });
  }
});

describe('problems located and numbered as the file does', () => {
  const open = (name, text) => wasm.MeshSession.open([{ name, bytes: new TextEncoder().encode(text) }]);

  it('names beetle\'s non-manifold edges by the OBJ file\'s 1-based v and f numbers', () => {
    const file = sharedMesh('beetle');
    const text = fs.readFileSync(file, 'utf8');
    const faces = text.split('\n').filter((l) => /^f\s/.test(l)).map((l) => l.trim().split(/\s+/).slice(1).map((c) => Number(c.split('/')[0])));
    const session = wasm.MeshSession.open([{ name: 'beetle.obj', bytes: new Uint8Array(fs.readFileSync(file)) }]);
    const report = session.report();
    const located = report.located_problems;
    assert.equal(located.length, report.problems.length);
    assert.deepEqual(located.map((p) => p.message), report.problem_messages);
    assert.deepEqual(located.map((p) => p.kind), report.problems.map((p) => p.kind));
    const positions = session.positions();
    const edges = located.filter((p) => p.kind === 'non_manifold_edge');
    assert.ok(edges.length > 0);
    for (const p of edges) {
      assert.equal(p.blocking, true);
      const [, a, b, list] = p.message.match(/^edge \(v(\d+), v(\d+)\) has \d+ faces \((.*)\)$/);
      for (const f of list.split(', ').map((x) => Number(x.slice(1)))) {
        assert.ok(faces[f - 1].includes(Number(a)) && faces[f - 1].includes(Number(b)), `${p.message}: f${f} is ${faces[f - 1]}`);
      }
      // Located in the shown mesh's ids: the edge's ends are the pair drawn, the faces are triangles.
      assert.deepEqual(p.vertices, p.edges);
      assert.equal(p.edges.length, 2);
      for (const v of p.vertices) assert.ok(v < positions.length / 3);
      assert.equal(p.faces.length, list.split(', ').length);
    }
    assert.throws(() => session.place_cones(new Uint32Array(), 0.01, false, () => {}), new RegExp(`cannot be parametrized: ${edges[0].message.replace(/[()]/g, '\\$&')}`));
  });

  it('numbers the faces of polygons by their f statement', () => {
    // Three quads around one edge (v1, v2): each fan-triangulated into two triangles.
    const obj = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 -1 0\nv 1 -1 0\nv 0 0 1\nv 1 0 1\n'
      + 'f 1 2 4 3\nf 2 1 5 6\nf 1 2 8 7\n';
    const p = open('quads.obj', obj).report().located_problems.find((x) => x.kind === 'non_manifold_edge');
    assert.equal(p.message, 'edge (v1, v2) has 3 faces (f1, f2, f3)');
  });

  it('says what a features file lacks, and which edge does not match the mesh', () => {
    const session = wasm.MeshSession.open([{ name: 'fandisk.obj', bytes: new Uint8Array(fs.readFileSync(committedFandisk)) }]);
    const sharp = session.sharp_edges(60);
    const positions = session.positions();
    const edges = session.edges();
    const at = (v) => Array.from(positions.subarray(3 * v, 3 * v + 3));
    const ends = Array.from(sharp, (e) => [at(edges[2 * e]), at(edges[2 * e + 1])]);
    assert.deepEqual([...session.features_from_json(JSON.stringify({ edges: ends }))], [...sharp], 'the CLI form');
    const report = { features: { edges: Array.from(sharp), positions: ends, boundary_edges: 0 } };
    assert.deepEqual([...session.features_from_json(JSON.stringify(report))], [...sharp], 'a JSON report');
    assert.throws(() => session.features_from_json('{"edges": [[[9, 9, 9], [1, 0, 0]]]}'), /feature edge 0: no mesh vertex at \(9, 9, 9\): the file does not match this mesh/);
    assert.throws(() => session.features_from_json('hello'), /not a JSON file/);
    assert.throws(() => session.features_from_json('{"faces": []}'), /expected \{"edges"/);
  });
});
