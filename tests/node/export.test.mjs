// `conemap solve`: exports to .glb / .gltf / .obj, checked with the Khronos
// glTF-Validator (zero errors) and re-imported with `conemap info`.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { before, describe, it } from 'node:test';
import validator from 'gltf-validator';
import { makeGltfFixtures } from './make-gltf.mjs';
import { committedFandisk, root, sharedMesh } from './wasm.mjs';
import { checkUv, parseObj } from './uvcheck.mjs';

const exe = path.join(root, 'target/release/conemap');

/** Newest modification time (ms) of the files under `dir`. */
function newest(dir) {
  let t = 0;
  for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
    const p = path.join(dir, e.name);
    t = Math.max(t, e.isDirectory() ? newest(p) : fs.statSync(p).mtimeMs);
  }
  return t;
}

/** Uses target/release/conemap when newer than the crate sources, else builds it. */
function ensureCli() {
  const sources = Math.max(newest(path.join(root, 'crate/src')), fs.statSync(path.join(root, 'crate/Cargo.toml')).mtimeMs);
  if (fs.existsSync(exe) && fs.statSync(exe).mtimeMs >= sources) return;
  const r = spawnSync('cargo', ['build', '--release', '-p', 'conemap', '--bin', 'conemap'], {
    cwd: root,
    stdio: ['ignore', 'inherit', 'inherit'],
  });
  assert.equal(r.status, 0, 'cargo build --release -p conemap --bin conemap');
}

function conemap(...args) {
  const r = spawnSync(exe, args, { cwd: root, encoding: 'utf8', maxBuffer: 64 << 20 });
  return { status: r.status, stdout: r.stdout, stderr: r.stderr };
}

function info(file) {
  const r = conemap('info', file, '--json');
  assert.equal(r.status, 0, `conemap info ${file}: ${r.stderr}`);
  return JSON.parse(r.stdout);
}

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 0 });
  const errors = report.issues.messages.filter((m) => m.severity === 0);
  assert.equal(
    report.issues.numErrors,
    0,
    `${path.basename(file)}: validator errors:\n${errors.map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`).join('\n')}`,
  );
  return report;
}

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-export-'));
const woodyObj = sharedMesh('woody');

// Inputs: the committed fandisk.obj, and woody as a one-primitive .glb and a
// two-mesh .gltf made by make-gltf.mjs.
// The fixtures are written at load time so each (input, format) pair can be
// its own test.
const inputs = [{ label: 'fandisk.obj', file: committedFandisk }];
for (const w of await makeGltfFixtures(woodyObj, path.join(tmp, 'fixtures'))) {
  if (w.name === 'woody.glb' || w.name === 'woody-two-nodes.gltf') inputs.push({ label: w.name, file: w.path, faces: w.faces });
}

describe('conemap solve', () => {
  before(() => ensureCli());

  it('has the woody fixtures', () => {
    assert.ok(inputs.some((i) => i.label === 'woody.glb'));
  });

  const cases = [];
  for (const input of inputs.filter((i) => i.label !== 'woody-two-nodes.gltf')) {
    for (const format of ['glb', 'gltf', 'obj']) cases.push({ input, format });
  }
  for (const { input, format } of cases) {
    it(`${input.label} → .${format}`, async () => {
      const source = info(input.file);
      if (input.faces !== undefined) assert.equal(source.faces, input.faces, `${input.label}: fixture faces`);
      const stem = path.basename(input.label).replace(/\.[^.]+$/, '');
      const out = path.join(tmp, `${stem}-out.${format}`);
      const report = path.join(tmp, `${stem}-${format}.json`);
      const args = ['solve', input.file, '-o', out, '--report', report];
      if (format !== 'obj') args.push('--checker');
      const r = conemap(...args);
      assert.equal(r.status, 0, `conemap ${args.join(' ')}:\n${r.stderr}`);
      assert.match(r.stdout, /cones/);
      assert.match(r.stdout, /distortion/);
      assert.ok(fs.existsSync(out), `${out} written`);

      const rep = JSON.parse(fs.readFileSync(report, 'utf8'));
      assert.equal(rep.faces, source.faces);
      assert.ok(Array.isArray(rep.cones), 'report.cones');
      assert.ok(rep.metrics && Number.isFinite(rep.metrics.distortion), 'report.metrics.distortion');
      for (const k of ['import', 'cones', 'param', 'export', 'total']) assert.ok(k in rep.timings, `report.timings.${k}`);
      assert.ok(rep.output.vertices >= source.vertices, 'output vertices ≥ welded vertices');

      if (format === 'obj') {
        const text = fs.readFileSync(out, 'utf8');
        const count = (prefix) => text.split('\n').filter((l) => l.startsWith(prefix)).length;
        assert.equal(count('f '), source.faces, `${input.label}: f lines`);
        assert.ok(count('vt ') >= source.vertices, `${input.label}: vt ${count('vt ')} ≥ ${source.vertices} vertices`);
        assert.equal(count('vt '), rep.output.vertices);
        assert.equal(count('v '), source.vertices);
        // Independent check from the file alone (OBJ keeps full precision).
        const c = checkUv(parseObj(text));
        assert.equal(c.flipped, 0, `${input.label}: flipped triangles`);
        assert.ok(c.seams > 0, `${input.label}: a closed or cut surface has seams`);
        assert.ok(c.maxSeamAngle < 1e-6, `${input.label}: seam transition off a quarter turn by ${c.maxSeamAngle} rad`);
        assert.ok(c.maxSeamLength < 1e-6, `${input.label}: seam length mismatch ${c.maxSeamLength}`);
        assert.ok(c.maxBoundaryAxis < 1e-6, `${input.label}: boundary edge off axis by ${c.maxBoundaryAxis} rad`);
      } else {
        const v = await validate(out);
        assert.equal(v.info.totalTriangleCount ?? source.faces, source.faces);
        assert.equal(v.info.version, '2.0');
        assert.match(v.info.generator, /^conemap \d+\.\d+\.\d+/);
        if (v.info.totalVertexCount !== undefined) assert.equal(v.info.totalVertexCount, rep.output.vertices);
      }
      // Re-import through conemap: same faces; welding gives back the input's mesh.
      const back = info(out);
      assert.equal(back.faces, source.faces, `${input.label} → .${format}: faces`);
      assert.equal(back.vertices, source.vertices, `${input.label} → .${format}: welded vertices`);
      assert.equal(back.euler_characteristic, source.euler_characteristic);
    });
  }

  it('keeps the primitives of a two-mesh glTF', async () => {
    const input = inputs.find((i) => i.label === 'woody-two-nodes.gltf');
    const out = path.join(tmp, 'two-nodes-out.glb');
    const r = conemap('solve', input.file, '-o', out);
    assert.equal(r.status, 0, r.stderr);
    const v = await validate(out);
    assert.equal(v.info.drawCallCount ?? 2, 2);
    // The JSON chunk names two primitives.
    const glb = fs.readFileSync(out);
    const json = JSON.parse(glb.subarray(20, 20 + glb.readUInt32LE(12)).toString('utf8'));
    assert.equal(json.meshes.length, 1);
    assert.equal(json.meshes[0].primitives.length, 2);
    assert.equal(json.nodes.length, 1);
    assert.equal(json.nodes[0].matrix, undefined);
  });

  it('rejects an unknown output extension with usage status 2', () => {
    const r = conemap('solve', committedFandisk, '-o', path.join(tmp, 'x.stl'));
    assert.equal(r.status, 2);
    assert.match(r.stderr, /\.glb|unknown output format/);
    assert.equal(r.stderr.trim().split('\n').length, 1);
  });

  it('fails with status 1 for an unwritable output path', () => {
    const r = conemap('solve', committedFandisk, '-o', path.join(tmp, 'no/such/dir/out.glb'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /cannot write/);
    assert.equal(r.stderr.trim().split('\n').length, 1);
  });

  it('fails with status 1 for a non-manifold mesh', () => {
    const bad = path.join(tmp, 'fin.obj');
    // Three triangles on one edge.
    fs.writeFileSync(bad, 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n');
    const r = conemap('solve', bad, '-o', path.join(tmp, 'fin.glb'));
    assert.equal(r.status, 1);
    assert.match(r.stderr, /cannot be parametrized/);
    assert.equal(r.stderr.trim().split('\n').length, 1);
  });

  it('needs -o', () => {
    const r = conemap('solve', committedFandisk);
    assert.equal(r.status, 2);
  });
});
