#!/usr/bin/env node
// Benchmark harness: prints a table and writes bench-results/bench.json.
//
//   npm run bench                     (setup + build + this script)
//   node scripts/bench.mjs [--no-native] [--no-browser] [--quick] [--big] [--only ENV:STAGE,...]
//   (--big adds spot subdivided three times, 375 k faces, to native:scaling)
//   browser:solve-big / browser:solve-single: Run in the page on 207 k faces with
//   features, and on spot ×16 / fandisk ×16 without (issue 13's page targets)
//   native:parts: a game asset of 56 parts copied 1, 4 and 16 times (64 with --big),
//   solved with --quads: each part on its own, growth with the number of parts
//   native:quads / wasm-node:quads: integer-grid quantization and quad extraction
//   on fandisk (sharp > 60°) and spot at about 1 000, 3 000 and 10 000 quads
//   (scripts/lib/bench-quads.mjs), with QuadriFlow's figures as static rows
//   native:quads-scaling, wasm-node:quads-scaling: the same on spot subdivided 0-2 times (0-3 with --big):
//   one surface, finer meshes; the growth exponent at each quad count
//
// Each entry of BENCHES is { env, stage, run(ctx) } and returns rows
// { input, faces?, ms, runs?, note? } (env/stage are filled in). Later pipeline
// stages (cones, solve) add entries here; a bench that cannot run returns
// { skipped: 'reason' } and appears as a note instead of failing the harness.
//
// Inputs: fandisk.obj (committed sample) and a ≥1 M-face OBJ made by 1-to-4
// midpoint subdivision of fandisk, cached in the temp directory.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { QUAD_TARGETS, nativeQuadRows, quadMeshes, wasmNodeQuadRows } from './lib/bench-quads.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const args = new Set(process.argv.slice(2));
const quick = args.has('--quick');
// --only native:solve,browser:solve-big runs just those benches.
const onlyAt = process.argv.indexOf('--only');
const only = onlyAt > 0 ? new Set((process.argv[onlyAt + 1] ?? '').split(',')) : null;
const MIN_BIG_FACES = 1_000_000;
const env = { ...process.env, PATH: [path.join(os.homedir(), '.cargo/bin'), process.env.PATH].join(path.delimiter) };

// ---------------------------------------------------------------- inputs

/** Reads an OBJ's vertices and triangles (polygons fan-triangulated). */
function readObj(file) {
  const pos = [];
  const tri = [];
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
    if (line.startsWith('v ')) {
      const [, x, y, z] = line.trim().split(/\s+/);
      pos.push(+x, +y, +z);
    } else if (line.startsWith('f ')) {
      const idx = line.trim().split(/\s+/).slice(1).map((t) => {
        const i = parseInt(t, 10);
        return i < 0 ? pos.length / 3 + i : i - 1;
      });
      for (let k = 1; k + 1 < idx.length; k++) tri.push(idx[0], idx[k], idx[k + 1]);
    }
  }
  return { positions: Float64Array.from(pos), triangles: Uint32Array.from(tri) };
}

/** One level of 1-to-4 midpoint subdivision (shared edge midpoints). */
function subdivide({ positions, triangles }) {
  const nv = positions.length / 3;
  const mids = new Map();
  const pos = Array.from(positions);
  const mid = (a, b) => {
    const key = a < b ? a * nv + b : b * nv + a;
    let m = mids.get(key);
    if (m === undefined) {
      m = pos.length / 3;
      pos.push((pos[3 * a] + pos[3 * b]) / 2, (pos[3 * a + 1] + pos[3 * b + 1]) / 2, (pos[3 * a + 2] + pos[3 * b + 2]) / 2);
      mids.set(key, m);
    }
    return m;
  };
  const out = new Uint32Array(triangles.length * 4);
  let j = 0;
  for (let t = 0; t < triangles.length; t += 3) {
    const [a, b, c] = [triangles[t], triangles[t + 1], triangles[t + 2]];
    const [ab, bc, ca] = [mid(a, b), mid(b, c), mid(c, a)];
    out.set([a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca], j);
    j += 12;
  }
  return { positions: Float64Array.from(pos), triangles: out };
}

function writeObj(mesh, file) {
  const fd = fs.openSync(file, 'w');
  const chunk = [];
  const flush = () => { fs.writeSync(fd, chunk.join('')); chunk.length = 0; };
  const p = mesh.positions;
  for (let i = 0; i < p.length; i += 3) {
    chunk.push(`v ${p[i].toFixed(6)} ${p[i + 1].toFixed(6)} ${p[i + 2].toFixed(6)}\n`);
    if (chunk.length >= 65536) flush();
  }
  const t = mesh.triangles;
  for (let i = 0; i < t.length; i += 3) {
    chunk.push(`f ${t[i] + 1} ${t[i + 1] + 1} ${t[i + 2] + 1}\n`);
    if (chunk.length >= 65536) flush();
  }
  flush();
  fs.closeSync(fd);
}

/** The subdivided fandisk with at least MIN_BIG_FACES faces (cached in the temp dir). */
function bigObj(source) {
  let mesh = readObj(source);
  let levels = 0;
  let faces = mesh.triangles.length / 3;
  while (faces < MIN_BIG_FACES) { faces *= 4; levels++; }
  const dir = path.join(os.tmpdir(), 'conemap-bench');
  const file = path.join(dir, `fandisk-sub${levels}.obj`);
  if (fs.existsSync(file) && fs.statSync(file).mtimeMs >= fs.statSync(source).mtimeMs) return { file, faces };
  fs.mkdirSync(dir, { recursive: true });
  process.stdout.write(`bench: writing ${file} (${levels} subdivision levels, ${faces.toLocaleString('en-US')} faces)… `);
  for (let i = 0; i < levels; i++) mesh = subdivide(mesh);
  writeObj(mesh, `${file}.tmp`);
  fs.renameSync(`${file}.tmp`, file);
  console.log(`${(fs.statSync(file).size / 2 ** 20).toFixed(0)} MB`);
  return { file, faces };
}

const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];

// ---------------------------------------------------------------- benches

/**
 * Runs a cargo example that prints one JSON line of timings; each timing field
 * becomes a row. `unit` is the unit of the printed numbers ('s' or 'ms');
 * `isTime(key)` picks the timing fields (counts such as faces are not times).
 */
function cargoExample(example, exampleArgs, input, { unit = 'ms', isTime = (k) => /_ms$/.test(k) } = {}) {
  const src = path.join(root, 'crate/examples', `${example}.rs`);
  if (!fs.existsSync(src)) return { skipped: `crate/examples/${example}.rs does not exist yet` };
  const r = spawnSync('cargo', ['run', '--quiet', '--release', '-p', 'conemap', '--example', example, '--', ...exampleArgs], {
    cwd: root, env, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 64 * 2 ** 20,
  });
  if (r.status !== 0) return { skipped: `cargo run --example ${example} failed: ${(r.stderr || '').trim().split('\n').slice(-3).join(' | ')}` };
  const line = r.stdout.trim().split('\n').reverse().find((l) => l.trim().startsWith('{'));
  if (!line) return { skipped: `${example} printed no JSON line` };
  const json = JSON.parse(line);
  const faces = json.faces ?? json.triangles;
  const rows = Object.entries(json)
    .filter(([k, v]) => typeof v === 'number' && isTime(k))
    .map(([k, v]) => ({ input, faces, stage: k, ms: unit === 's' ? v * 1000 : v }));
  if (rows.length === 0) return { skipped: `no timing fields in ${line.slice(0, 160)}` };
  return rows;
}

/** crate/examples/bench_import.rs [MESH.obj] [MIN_FACES]: subdivides to ≥ MIN_FACES, prints seconds. */
function nativeImport(ctx) {
  const out = [];
  for (const { file, faces } of ctx.inputs) {
    const minFaces = faces >= MIN_BIG_FACES ? MIN_BIG_FACES : 0;
    const label = faces >= MIN_BIG_FACES ? `${path.basename(ctx.inputs[0].file)} subdivided` : path.basename(file);
    const rows = cargoExample('bench_import', [ctx.inputs[0].file, String(minFaces)], label, {
      unit: 's',
      isTime: (k) => !/faces|vertices|bytes|count/i.test(k),
    });
    if (rows.skipped) return rows;
    out.push(...rows);
  }
  return out;
}

function wasmNodeImport(ctx) {
  const pkg = path.join(root, 'build/pkg-node/conemap.js');
  if (!fs.existsSync(pkg)) return { skipped: 'build/pkg-node missing (run npm run build)' };
  const wasm = createRequire(import.meta.url)(pkg);
  const rows = [];
  for (const { file } of ctx.inputs) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const runs = bytes.length > 50 * 2 ** 20 ? 2 : 7;
    const times = [];
    let faces = 0;
    for (let i = 0; i < runs; i++) {
      const t0 = performance.now();
      const out = wasm.import_mesh([{ name: path.basename(file), bytes }]);
      times.push(performance.now() - t0);
      faces = out.indices.length / 3;
    }
    rows.push({ input: path.basename(file), faces, ms: median(times), runs, note: `min ${Math.min(...times).toFixed(1)} ms` });
  }
  return rows;
}

/** `source` subdivided `levels` times (cached in the temp dir), e.g. fandisk 2 → 207 k faces. */
function subObj(source, levels) {
  const dir = path.join(os.tmpdir(), 'conemap-bench');
  const file = path.join(dir, `${path.basename(source, '.obj')}-sub${levels}.obj`);
  let mesh = readObj(source);
  const faces = (mesh.triangles.length / 3) * 4 ** levels;
  if (fs.existsSync(file) && fs.statSync(file).mtimeMs >= fs.statSync(source).mtimeMs) return { file, faces };
  fs.mkdirSync(dir, { recursive: true });
  for (let i = 0; i < levels; i++) mesh = subdivide(mesh);
  writeObj(mesh, `${file}.tmp`);
  fs.renameSync(`${file}.tmp`, file);
  return { file, faces };
}

/**
 * The whole method natively (`conemap solve --report`): fandisk with its sharp
 * edges (> 60°) as features and without features, α = 0.01; one row per stage.
 */
function nativeSolve(ctx) {
  const bin = releaseCli();
  if (bin.skipped) return bin;
  const file = ctx.inputs[0].file;
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-solve-'));
  const rows = [];
  for (const [label, extra] of [['sharp > 60°', ['--sharp', '60']], ['no features', []]]) {
    const report = path.join(dir, 'report.json');
    const r = spawnSync(bin, ['solve', file, ...extra, '-o', path.join(dir, 'out.glb'), '--report', report], { encoding: 'utf8' });
    if (r.status !== 0) return { skipped: `conemap solve failed: ${(r.stderr || '').trim()}` };
    const j = JSON.parse(fs.readFileSync(report, 'utf8'));
    const t = j.timings;
    const input = `${path.basename(file)} (${label})`;
    const note = `${j.cones.length} cones, ${j.rounds} rounds, distortion ${j.metrics.distortion.toFixed(3)}, ${j.metrics.flipped} flipped`;
    for (const [stage, sec] of [
      ['import', t.import],
      ['cones: topology', t.cones.topology],
      ['cones: rounding', t.cones.rounding],
      ['cones: moves + clean-up', t.cones.cone_moves],
      ['param: field + cut', t.param.field + t.param.cut],
      ['param: Poisson + ARAP', t.param.poisson + t.param.arap],
      ['param: repair', t.param.repair],
      ['export', t.export],
      ['file → UVs total', t.total],
    ]) rows.push({ stage, input, faces: j.output.faces, ms: sec * 1000, note: stage.endsWith('total') ? note : '' });
  }
  fs.rmSync(dir, { recursive: true, force: true });
  return rows;
}

/** Builds the release CLI; returns its path, or `{ skipped }`. */
function releaseCli() {
  const build = spawnSync('cargo', ['build', '--quiet', '--release', '-p', 'conemap', '--bin', 'conemap'], { cwd: root, env, encoding: 'utf8' });
  if (build.status !== 0) return { skipped: `cargo build failed: ${(build.stderr || '').trim().split('\n').slice(-2).join(' | ')}` };
  return path.join(root, 'target/release/conemap');
}

/** `conemap solve FILE --report` (α = 0.01, no features): the report, or `{ skipped }`. */
function solveReport(bin, file, extra = []) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-solve-'));
  try {
    const report = path.join(dir, 'report.json');
    const r = spawnSync(bin, ['solve', file, ...extra, '-o', path.join(dir, 'out.glb'), '--report', report, '--quiet'], { encoding: 'utf8' });
    if (r.status !== 0) return { skipped: `conemap solve ${path.basename(file)} failed: ${(r.stderr || '').trim()}` };
    return JSON.parse(fs.readFileSync(report, 'utf8'));
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

/** One row per solve: faces, cones, distortion, flips, rounds and seconds per stage in the note. */
function solveRow(stage, input, j) {
  const t = j.timings;
  const wound = j.metrics.wound_vertices;
  const note = `${j.cones.length} cones, distortion ${j.metrics.distortion.toFixed(3)}, ${j.metrics.flipped} flipped, ${wound} wound, `
    + `${j.rounds} rounds; s: cones ${t.cones_total.toFixed(2)} (rounding ${t.cones.rounding.toFixed(2)}, moves ${t.cones.cone_moves.toFixed(2)}), param ${t.param_total.toFixed(2)}`;
  return { stage, input, faces: j.faces, ms: t.total * 1000, note };
}

const sharedMeshes = path.join(root, '..', 'shared', 'meshes');
/** The clean shared samples of 4 k-35 k faces (file → UV targets of issue 13). */
const SAMPLES = ['bff-hemisphere', 'spot', 'cow', 'alligator', 'teapot', 'bff-punctured-torus', 'bff-maze', 'fandisk', 'bff-bunny', 'bff-cowhead', 'bff-face'];

/** Every clean shared sample natively, α = 0.01, no features (`../shared/meshes`). */
function nativeSamples() {
  if (!fs.existsSync(sharedMeshes)) return { skipped: `${sharedMeshes} not found` };
  const bin = releaseCli();
  if (bin.skipped) return bin;
  const rows = [];
  for (const name of SAMPLES) {
    const j = solveReport(bin, path.join(sharedMeshes, `${name}.obj`));
    if (j.skipped) return j;
    rows.push(solveRow('file → UVs', `${name}.obj`, j));
  }
  return rows;
}

/** The shared samples with a boundary, for `--boundary free` against the aligned default. */
const OPEN_SAMPLES = ['bff-hemisphere', 'alligator', 'bff-punctured-torus', 'bff-maze', 'bff-cowhead', 'bff-face'];

/** Open samples natively with the boundary aligned and free (α = 0.01, no features); `--big` adds bff-face ×4. */
function nativeFreeBoundary() {
  if (!fs.existsSync(sharedMeshes)) return { skipped: `${sharedMeshes} not found` };
  const bin = releaseCli();
  if (bin.skipped) return bin;
  const rows = [];
  const inputs = OPEN_SAMPLES.map((name) => ({ name: `${name}.obj`, file: path.join(sharedMeshes, `${name}.obj`) }));
  if (args.has('--big')) inputs.push({ name: 'bff-face.obj ×4', file: subObj(path.join(sharedMeshes, 'bff-face.obj'), 1).file });
  for (const { name, file } of inputs) {
    for (const mode of ['aligned', 'free']) {
      const j = solveReport(bin, file, ['--boundary', mode]);
      if (j.skipped) return j;
      rows.push(solveRow(`file → UVs, boundary ${mode}`, name, j));
    }
  }
  return rows;
}

/**
 * spot.obj and its midpoint subdivisions, 1-2 times (1-3 with --big): the
 * same surface at 4x the faces each time, as [{ levels, file }], or
 * `{ skipped }` where the shared meshes are absent.
 */
function spotFamily() {
  const spot = path.join(sharedMeshes, 'spot.obj');
  if (!fs.existsSync(spot)) return { skipped: `${spot} not found` };
  const family = [];
  for (let levels = 0; levels <= (args.has('--big') ? 3 : 2); levels++) {
    family.push({ levels, file: levels ? subObj(spot, levels).file : spot });
  }
  return family;
}

/**
 * Growth with mesh size: the spot family (`spotFamily`), α = 0.01; a row
 * per size and the fitted exponent e of time ∝ faces^e.
 */
function nativeScaling() {
  const family = spotFamily();
  if (family.skipped) return family;
  const bin = releaseCli();
  if (bin.skipped) return bin;
  const rows = [];
  const points = [];
  for (const { levels, file } of family) {
    const j = solveReport(bin, file);
    if (j.skipped) return j;
    rows.push(solveRow('file → UVs', `spot.obj ×4^${levels}`, j));
    points.push([Math.log(j.faces), Math.log(j.timings.total)]);
  }
  rows.push(growthRow('spot.obj family', points));
  return rows;
}

/** The row of the exponent e of time ∝ faces^e fitted (least squares) to `points` ([log faces, log seconds]). */
function growthRow(input, points) {
  const n = points.length;
  const mx = points.reduce((a, p) => a + p[0], 0) / n;
  const my = points.reduce((a, p) => a + p[1], 0) / n;
  const e = points.reduce((a, p) => a + (p[0] - mx) * (p[1] - my), 0) / points.reduce((a, p) => a + (p[0] - mx) ** 2, 0);
  return { stage: 'growth exponent', input, ms: NaN, note: `time ∝ faces^${e.toFixed(2)} (least squares over ${n} sizes)` };
}

/** `k` copies of `source` side by side (a grid of them, 1.2 widths apart) as one OBJ, cached like `subObj`. */
function copiesObj(source, k) {
  const dir = path.join(os.tmpdir(), 'conemap-bench');
  const file = path.join(dir, `${path.basename(source, '.obj')}-x${k}.obj`);
  if (fs.existsSync(file) && fs.statSync(file).mtimeMs >= fs.statSync(source).mtimeMs) return { file };
  const { positions, triangles } = readObj(source);
  let [lo, hi] = [Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) [lo, hi] = [Math.min(lo, positions[i]), Math.max(hi, positions[i])];
  const side = Math.ceil(Math.sqrt(k));
  const step = 1.2 * (hi - lo);
  const out = { positions: [], triangles: [] };
  for (let c = 0; c < k; c++) {
    const base = out.positions.length / 3;
    for (let i = 0; i < positions.length; i += 3) {
      out.positions.push(positions[i] + (c % side) * step, positions[i + 1], positions[i + 2] + Math.floor(c / side) * step);
    }
    for (const v of triangles) out.triangles.push(v + base);
  }
  fs.mkdirSync(dir, { recursive: true });
  writeObj(out, `${file}.tmp`);
  fs.renameSync(`${file}.tmp`, file);
  return { file };
}

/**
 * Many parts (a game asset: xatlas-gazebo, 56 components, 1, 4 and 16 copies
 * side by side; 64 with --big): `solve --quads 3000·k --sharp 60`, each part
 * solved and quantized on its own; a row per size and the growth exponent.
 */
function nativeParts() {
  const gazebo = path.join(sharedMeshes, 'xatlas-gazebo.obj');
  if (!fs.existsSync(gazebo)) return { skipped: `${gazebo} not found` };
  const bin = releaseCli();
  if (bin.skipped) return bin;
  const rows = [];
  const points = [];
  for (const k of args.has('--big') ? [1, 4, 16, 64] : [1, 4, 16]) {
    const { file } = k > 1 ? copiesObj(gazebo, k) : { file: gazebo };
    const j = solveReport(bin, file, ['--sharp', '60', '--quads', String(3000 * k)]);
    if (j.skipped) return j;
    const row = solveRow('file → grid UVs', `xatlas-gazebo.obj ×${k} (${56 * k} parts)`, j);
    const q = j.quantization;
    row.note += `, quantize ${j.timings.quantize.toFixed(2)}; grid: ${q.flipped} flipped, ${q.wound_vertices} wound`;
    rows.push(row);
    points.push([Math.log(j.faces), Math.log(j.timings.total)]);
  }
  rows.push(growthRow('xatlas-gazebo.obj copies', points));
  return rows;
}

/**
 * Quantization and quad extraction natively (`conemap quads --report`): fandisk
 * with sharp edges > 60°, spot without features, about 1 000 / 3 000 / 10 000
 * quads; ms = quantize + extract.
 */
function nativeQuads(ctx) {
  const bin = releaseCli();
  if (bin.skipped) return bin;
  return nativeQuadRows(bin, quadMeshes(ctx.inputs[0].file, sharedMeshes));
}

/**
 * Quantization and extraction against mesh size: the spot family
 * (`spotFamily`) at about 1 000, 3 000 and 10 000 quads (the rows of
 * `nativeQuadRows`), and the exponent e of (quantize + extract) time ∝
 * faces^e at each quad count.
 */
function nativeQuadScaling() {
  const bin = releaseCli();
  if (bin.skipped) return bin;
  return quadScalingRows((meshes) => nativeQuadRows(bin, meshes));
}

/**
 * The page's quads against mesh size, in wasm under node: the spot family
 * solved once each, then `session.quads(n)` (wall clock: on the larger
 * meshes the decimation and its solve included), and the exponents.
 */
function wasmNodeQuadScaling() {
  const pkg = path.join(root, 'build/pkg-node/conemap.js');
  if (!fs.existsSync(pkg)) return { skipped: 'build/pkg-node missing (run npm run build)' };
  const wasm = createRequire(import.meta.url)(pkg);
  // Each count once, as a first request (a repeated one reuses the decimation's solve).
  const firstCalls = (rows) => (Array.isArray(rows) ? rows.filter((r) => !/\(again\)/.test(r.stage)) : rows);
  return quadScalingRows((meshes) => firstCalls(wasmNodeQuadRows(wasm, meshes)));
}

/** `quadRows` of the spot family and, per quad count, the growth of ms with faces. */
function quadScalingRows(quadRows) {
  const family = spotFamily();
  if (family.skipped) return family;
  const meshes = family.map(({ levels, file }) => ({ name: path.basename(file), file, sharp: null, label: `spot.obj ×4^${levels} (no features)` }));
  const all = quadRows(meshes);
  if (!Array.isArray(all)) return all;
  const rows = all.filter((r) => !r.static);
  for (const n of QUAD_TARGETS) {
    const at = rows.filter((r) => r.target === n);
    rows.push(growthRow(`spot.obj family, N = ${n.toLocaleString('en-US')}`, at.map((r) => [Math.log(r.faces), Math.log(r.ms)])));
  }
  return rows;
}

/** The same in wasm under node: one `MeshSession.solve` per mesh, then `session.quads(n)` per N (wall clock). */
function wasmNodeQuads(ctx) {
  const pkg = path.join(root, 'build/pkg-node/conemap.js');
  if (!fs.existsSync(pkg)) return { skipped: 'build/pkg-node missing (run npm run build)' };
  return wasmNodeQuadRows(createRequire(import.meta.url)(pkg), quadMeshes(ctx.inputs[0].file, sharedMeshes));
}

/** The whole method in wasm under node: fandisk, sharp edges > 60° as features, α = 0.01. */
function wasmNodeSolve(ctx) {
  const pkg = path.join(root, 'build/pkg-node/conemap.js');
  if (!fs.existsSync(pkg)) return { skipped: 'build/pkg-node missing (run npm run build)' };
  const wasm = createRequire(import.meta.url)(pkg);
  const file = ctx.inputs[0].file;
  const t0 = performance.now();
  const session = wasm.MeshSession.open([{ name: path.basename(file), bytes: new Uint8Array(fs.readFileSync(file)) }]);
  try {
    const r = session.solve(session.sharp_edges(60), 0.01, false, () => {});
    const ms = performance.now() - t0;
    const t = r.timings;
    const p = r.param_timings;
    const input = path.basename(file);
    return [
      { stage: 'cones (rounding)', input, ms: t.rounding * 1000, note: `${r.rounds} rounds` },
      { stage: 'cones total', input, ms: t.total * 1000, note: `${r.cones.length} cones` },
      { stage: 'param (Poisson + ARAP + repair)', input, ms: (p.poisson + p.arap + p.repair) * 1000, note: '' },
      { stage: 'file → UVs + GLB total', input, ms, note: `distortion ${r.metrics.distortion.toFixed(3)}, ${r.metrics.flipped} flipped` },
    ];
  } finally {
    session.free();
  }
}

/** Cone placement in wasm under node: fandisk with its sharp edges (> 60°) as features, α = 1. */
function wasmNodeCones(ctx) {
  const pkg = path.join(root, 'build/pkg-node/conemap.js');
  if (!fs.existsSync(pkg)) return { skipped: 'build/pkg-node missing (run npm run build)' };
  const wasm = createRequire(import.meta.url)(pkg);
  const file = ctx.inputs[0].file;
  const session = wasm.MeshSession.open([{ name: path.basename(file), bytes: new Uint8Array(fs.readFileSync(file)) }]);
  try {
    let t0 = performance.now();
    const sharp = session.sharp_edges(60);
    const sharpMs = performance.now() - t0;
    t0 = performance.now();
    const r = session.place_cones(sharp, 1, false, () => {});
    const conesMs = performance.now() - t0;
    const input = path.basename(file);
    return [
      { stage: 'sharp_edges(60°)', input, ms: sharpMs, note: `${sharp.length} edges` },
      { stage: 'place_cones', input, ms: conesMs, note: `${sharp.length} features, α=1: ${r.cones.length} cones, ${r.rounds} rounds` },
    ];
  } finally {
    session.free();
  }
}

/** The built page served from dist/ in headless Chromium, the default mesh loaded. */
async function openBenchPage() {
  const { findChromium, launchChromium } = await import('./lib/chromium.mjs');
  if (!findChromium()) return { skipped: 'no Chromium (set CHROMIUM_PATH or apt-get install chromium)' };
  const { startServer } = await import('./serve.mjs');
  const server = await startServer({ root: path.join(root, 'dist'), port: 0 });
  const browser = await launchChromium();
  const page = await browser.context.newPage();
  await page.goto(server.url);
  await page.waitForFunction(() => window.__conemap?.state === 'ready', null, { timeout: 120_000 });
  return { server, browser, page };
}

/**
 * The page's feature editor and solve on the main thread's clock: edge picking
 * (raycast without BVH + nearest side in screen space) and a sharp-edge pass on a
 * 207 k-face mesh, and Run (cone placement) on the fandisk.
 */
async function browserFeatures(ctx) {
  const opened = await openBenchPage();
  if (opened.skipped) return opened;
  const { server, browser, page } = opened;
  try {
    const rows = [];
    // Run on the fandisk: sharp edges > 60° as features, α = 1.
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction(() => window.__conemap.features > 0, null, { timeout: 60_000 });
    await page.getByTestId('alpha').fill('0');
    let t0 = Date.now();
    await page.getByTestId('run').click();
    await page.waitForFunction(() => window.__conemap.solves > 0, null, { timeout: 300_000 });
    const h = await page.evaluate(() => window.__conemap);
    rows.push({ stage: 'Run → result shown', input: 'fandisk.obj', faces: 12946, ms: Date.now() - t0, note: h.result ? `${h.result.cones} cones${h.result.uv ? ', with UVs (solve)' : ' (place_cones only)'}` : `failed: ${h.solveError}` });
    // Picking and sharp edges on the 207 k-face mesh.
    const mid = subObj(ctx.inputs[0].file, 2);
    const n = h.loads;
    await page.getByTestId('file-input').setInputFiles(mid.file);
    await page.waitForFunction((k) => window.__conemap.loads > k && window.__conemap.state !== 'loading', n, { timeout: 300_000 });
    const input = path.basename(mid.file);
    const pick = await page.evaluate(() => {
      const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      const times = [];
      let hits = 0;
      for (let i = 0; i < 15; i++) {
        const t = performance.now();
        if (window.__conemapTest.edgeAt(r.left + r.width * (0.35 + 0.02 * i), r.top + r.height * (0.4 + 0.01 * i)) >= 0) hits++;
        times.push(performance.now() - t);
      }
      times.sort((a, b) => a - b);
      return { median: times[7], max: times[14], hits };
    });
    rows.push({ stage: 'pick an edge (click)', input, faces: mid.faces, ms: pick.median, note: `max ${pick.max.toFixed(1)} ms, ${pick.hits}/15 hits` });
    t0 = Date.now();
    await page.getByTestId('sharp-toggle').check();
    await page.waitForFunction(() => window.__conemap.features > 0, null, { timeout: 120_000 });
    rows.push({ stage: 'sharp edges > 60° marked', input, faces: mid.faces, ms: Date.now() - t0, note: 'worker + feature lines' });
    return rows;
  } finally {
    await browser.close();
    await server.close();
  }
}

/**
 * Sum of the proportional set sizes (PSS, MB) of the Chromium processes this
 * script started (descendants of this node process: a Chromium of someone
 * else's tests on the same machine does not count).
 */
function chromiumPssMb() {
  const parent = new Map();
  const comm = new Map();
  for (const pid of fs.readdirSync('/proc').filter((d) => /^\d+$/.test(d))) {
    try {
      // /proc/PID/stat: "pid (comm) state ppid ..."; comm may hold spaces.
      const stat = fs.readFileSync(`/proc/${pid}/stat`, 'utf8');
      const close = stat.lastIndexOf(')');
      comm.set(pid, stat.slice(stat.indexOf('(') + 1, close));
      parent.set(pid, stat.slice(close + 2).split(' ')[1]);
    } catch { /* the process ended */ }
  }
  const ours = (pid) => {
    for (let p = parent.get(pid); p && p !== '0'; p = parent.get(p)) if (p === String(process.pid)) return true;
    return false;
  };
  let kb = 0;
  for (const [pid, name] of comm) {
    if (!/chrom/.test(name) || !ours(pid)) continue;
    try {
      const m = /^Pss:\s+(\d+) kB/m.exec(fs.readFileSync(`/proc/${pid}/smaps_rollup`, 'utf8'));
      if (m) kb += Number(m[1]);
    } catch { /* the process ended */ }
  }
  return kb / 1024;
}

/**
 * The whole method in the page's worker, as a user runs it: a fresh page,
 * `file` through the file input, `prepare(page)` (features, α; nothing: the
 * defaults), Run, and the wait for the result shown. Measures the wall time
 * from Run to the result shown, the longest main-thread frame gap meanwhile
 * and the peak memory of Chromium (PSS of its processes, sampled every 250 ms
 * over the load and the solve); reads the figures the results panel shows.
 * `after(page)` runs on the solved page before it closes; what it returns is
 * passed on as `after`.
 */
async function solveInPage(file, { prepare = async () => {}, after = async () => null } = {}) {
  const opened = await openBenchPage();
  if (opened.skipped) return opened;
  const { server, browser, page } = opened;
  let peak = chromiumPssMb();
  const sampler = setInterval(() => { peak = Math.max(peak, chromiumPssMb()); }, 250);
  try {
    const loads = await page.evaluate(() => window.__conemap.loads);
    await page.getByTestId('file-input').setInputFiles(file);
    await page.waitForFunction((k) => window.__conemap.loads > k && window.__conemap.state !== 'loading', loads, { timeout: 300_000 });
    const loaded = await page.evaluate(() => ({ state: window.__conemap.state, error: window.__conemap.lastError, faces: window.__conemap.stats?.faces }));
    if (loaded.state !== 'ready') return { skipped: `page did not load ${path.basename(file)}: ${loaded.error}` };
    await prepare(page);
    await page.evaluate(() => {
      const m = { maxGap: 0, running: true };
      window.__bench = m;
      let last = performance.now();
      const tick = (t) => { m.maxGap = Math.max(m.maxGap, t - last); last = t; if (m.running) requestAnimationFrame(tick); };
      requestAnimationFrame(tick);
    });
    const solves = await page.evaluate(() => window.__conemap.solves);
    const t0 = Date.now();
    await page.getByTestId('run').click();
    await page.waitForFunction((k) => window.__conemap.solves > k, solves, { timeout: 1_800_000, polling: 500 });
    const ms = Date.now() - t0;
    const h = await page.evaluate(() => {
      window.__bench.running = false;
      const c = window.__conemap;
      const shown = (stat) => document.querySelector(`[data-testid=result-stats] dd[data-stat=${stat}]`)?.textContent ?? null;
      return {
        result: c.result, error: c.solveError, gap: window.__bench.maxGap, restarts: c.workerRestarts,
        distortion: shown('distortion'), flipped: shown('flipped-faces'),
      };
    });
    return { faces: loaded.faces, ms, ...h, after: await after(page), peak };
  } finally {
    clearInterval(sampler);
    await browser.close();
    await server.close();
  }
}

/** The note of a page solve: cones, distortion and flips as the results panel shows them, or why it failed. */
const pageSolveNote = (s) => (s.result
  ? `${s.result.cones} cones, distortion ${s.distortion ?? '—'}, ${s.flipped ?? '—'} flipped, ${s.result.uv ? 'UVs' : 'no UVs'}, `
    + `${s.result.helperComponents} components placed by the helper worker`
  : `failed: ${s.error}`) + (s.restarts ? `; worker restarted ${s.restarts}×` : '');

/** The frame-gap and memory rows of a page solve. */
const pageSolveRows = (input, s) => [
  { stage: 'longest frame gap during the solve', input, ms: s.gap, note: 'includes drawing the solved view (SwiftShader in headless Chromium)' },
  { stage: 'peak Chromium memory (PSS, MB)', input, ms: NaN, note: `${s.peak.toFixed(0)} MB over the load and solve` },
];

/**
 * The fandisk subdivided to 207 k faces with its sharp edges (> 60°) as
 * features, α = 0.01 (`solveInPage`), plus one plain redraw of the solved view
 * for scale (in headless Chromium both it and the frame gap are mostly
 * SwiftShader rasterising the frame).
 */
async function browserSolveBig(ctx) {
  const mid = subObj(ctx.inputs[0].file, 2);
  const input = path.basename(mid.file);
  const s = await solveInPage(mid.file, {
    async prepare(page) {
      await page.getByTestId('sharp-toggle').check();
      await page.getByTestId('sharp-angle').fill('60');
      await page.waitForFunction(() => window.__conemap.features > 0, null, { timeout: 120_000 });
      // α slider is log10 α in [-3, 2].
      await page.getByTestId('alpha').fill('-2');
    },
    // For scale: one plain redraw of the solved 3D view (the Frame button), median of 3.
    async after(page) {
      const redraws = [];
      for (let i = 0; i < 3; i++) {
        redraws.push(await page.evaluate(() => new Promise((resolve) => {
          document.getElementById('frame-button').click();
          const t = performance.now();
          requestAnimationFrame(() => requestAnimationFrame(() => resolve(performance.now() - t)));
        })));
      }
      return redraws.sort((a, b) => a - b)[1];
    },
  });
  if (s.skipped) return s;
  const [gap, memory] = pageSolveRows(input, s);
  return [
    { stage: 'Run → result shown (207 k faces, worker)', input, faces: mid.faces, ms: s.ms, note: pageSolveNote(s) },
    gap,
    { stage: 'one redraw of the solved 3D view', input, ms: s.after, note: 'Frame button, 2 frames; mostly SwiftShader rasterisation' },
    memory,
  ];
}

/**
 * Issue 13's page figures on single-component meshes, no features, the page's
 * defaults (α slider, boundary fixed): spot subdivided twice (93 696 faces,
 * target under 25 s) and the fandisk subdivided twice (207 136 faces, closed,
 * one component; target under 60 s and 1.5 GB), each in a fresh page.
 */
async function browserSolveSingle(ctx) {
  const spot = path.join(sharedMeshes, 'spot.obj');
  if (!fs.existsSync(spot)) return { skipped: `${spot} not found` };
  const rows = [];
  for (const [mesh, target] of [[subObj(spot, 2), 'target < 25 s'], [subObj(ctx.inputs[0].file, 2), 'target < 60 s, 1.5 GB']]) {
    const input = `${path.basename(mesh.file)} (no features)`;
    const s = await solveInPage(mesh.file);
    if (s.skipped) return s;
    rows.push({ stage: 'Run → result shown (worker)', input, faces: s.faces, ms: s.ms, note: `${target}; ${pageSolveNote(s)}` }, ...pageSolveRows(input, s));
  }
  return rows;
}

async function browserLoad(ctx) {
  const big = ctx.inputs.find((i) => i.faces >= MIN_BIG_FACES);
  if (!big) return { skipped: 'no ≥1 M-face input (--quick)' };
  const opened = await openBenchPage();
  if (opened.skipped) return opened;
  const { server, browser, page } = opened;
  try {
    // Two loads of the big file: first with the canvas hidden, so the frame gaps
    // measure the page's own main-thread work (read, worker round trip, geometry
    // upload); then visible, which adds software-GL (SwiftShader) rasterisation of
    // every triangle: seconds in headless Chromium, milliseconds on a real GPU.
    const input = path.basename(big.file);
    const rows = [];
    for (const hidden of [true, false]) {
      const m = await measureLoad(page, big.file, hidden);
      if (m.state !== 'ready') return { skipped: `page did not load the file: ${m.lastError}` };
      const tag = hidden ? 'canvas hidden' : 'canvas visible';
      if (hidden) {
        rows.push(
          { stage: 'read file', input, ms: m.timings.read, note: 'FileReader, main thread clock' },
          { stage: 'worker round trip', input, faces: m.faces, ms: m.timings.worker, note: `wasm import ${m.importMs.toFixed(0)} ms + edges + transfer` },
          { stage: 'build + draw call', input, ms: m.timings.draw },
        );
      }
      rows.push(
        { stage: `file input → ready (${tag})`, input, faces: m.faces, ms: m.wall, note: 'wall clock' },
        { stage: `longest frame gap (${tag})`, input, ms: m.maxGap, note: hidden ? "the page's own main-thread work" : 'includes SwiftShader rasterisation' },
        { stage: `longest long task (${tag})`, input, ms: m.maxLongTask, note: m.maxLongTask ? '' : 'none observed (> 50 ms)' },
      );
    }
    return rows;
  } finally {
    await browser.close();
    await server.close();
  }
}

/** Loads `file` through the page's file input while watching animation frames and long tasks. */
async function measureLoad(page, file, hideCanvas) {
  await page.evaluate((hide) => {
    document.querySelector('[data-testid=canvas]').style.visibility = hide ? 'hidden' : '';
    const m = { maxGap: 0, maxLongTask: 0, running: true };
    window.__bench = m;
    let last = performance.now();
    const tick = (t) => {
      m.maxGap = Math.max(m.maxGap, t - last);
      last = t;
      if (m.running) requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
    try {
      m.observer = new PerformanceObserver((list) => {
        for (const e of list.getEntries()) m.maxLongTask = Math.max(m.maxLongTask, e.duration);
      });
      m.observer.observe({ type: 'longtask', buffered: false });
    } catch { /* longtask entries not supported */ }
  }, hideCanvas);
  const loadsBefore = await page.evaluate(() => window.__conemap.loads);
  const t0 = performance.now();
  await page.getByTestId('file-input').setInputFiles(file);
  await page.waitForFunction((n) => window.__conemap.loads > n && window.__conemap.state !== 'loading', loadsBefore, { timeout: 600_000, polling: 50 });
  const wall = performance.now() - t0;
  // Let the frame that shows the mesh (and any work it triggers) happen.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(r, 200)))));
  return page.evaluate((w) => {
    const c = window.__conemap;
    const m = window.__bench;
    m.running = false;
    m.observer?.disconnect();
    return { wall: w, state: c.state, lastError: c.lastError, faces: c.stats?.faces, importMs: c.stats?.importMs ?? NaN, timings: c.timings, maxGap: m.maxGap, maxLongTask: m.maxLongTask };
  }, wall);
}

const BENCHES = [
  { env: 'native', stage: 'import', run: nativeImport, enabled: !args.has('--no-native') },
  { env: 'native', stage: 'ldlt', run: () => cargoExample('bench_ldlt', [], 'bumpy grid'), enabled: !args.has('--no-native') && !quick },
  { env: 'wasm-node', stage: 'import', run: wasmNodeImport, enabled: true },
  { env: 'wasm-node', stage: 'cones', run: wasmNodeCones, enabled: true },
  { env: 'native', stage: 'solve', run: nativeSolve, enabled: !args.has('--no-native') },
  { env: 'native', stage: 'samples', run: nativeSamples, enabled: !args.has('--no-native') },
  { env: 'native', stage: 'scaling', run: nativeScaling, enabled: !args.has('--no-native') && !quick },
  { env: 'native', stage: 'parts', run: nativeParts, enabled: !args.has('--no-native') && !quick },
  { env: 'native', stage: 'free-boundary', run: nativeFreeBoundary, enabled: !args.has('--no-native') && !quick },
  { env: 'wasm-node', stage: 'solve', run: wasmNodeSolve, enabled: true },
  { env: 'native', stage: 'quads', run: nativeQuads, enabled: !args.has('--no-native') },
  { env: 'native', stage: 'quads-scaling', run: nativeQuadScaling, enabled: !args.has('--no-native') && !quick },
  { env: 'wasm-node', stage: 'quads', run: wasmNodeQuads, enabled: true },
  { env: 'wasm-node', stage: 'quads-scaling', run: wasmNodeQuadScaling, enabled: !quick },
  { env: 'browser', stage: 'load', run: browserLoad, enabled: !args.has('--no-browser') && !quick },
  { env: 'browser', stage: 'features', run: browserFeatures, enabled: !args.has('--no-browser') },
  { env: 'browser', stage: 'solve-big', run: browserSolveBig, enabled: !args.has('--no-browser') && !quick },
  { env: 'browser', stage: 'solve-single', run: browserSolveSingle, enabled: !args.has('--no-browser') && !quick },
];

// ---------------------------------------------------------------- main

const fandisk = path.join(root, 'web/public/samples/fandisk.obj');
const inputs = [{ file: fandisk, faces: 12946 }];
if (!quick) inputs.push(bigObj(fandisk));

const rows = [];
const notes = [];
for (const b of BENCHES.filter((x) => x.enabled && (!only || only.has(`${x.env}:${x.stage}`)))) {
  process.stdout.write(`bench: ${b.env} ${b.stage}… `);
  const t0 = performance.now();
  let result;
  try {
    result = await b.run({ inputs });
  } catch (e) {
    result = { skipped: `error: ${e.message.split('\n')[0]}` };
  }
  if (result.skipped) {
    notes.push(`${b.env} ${b.stage}: ${result.skipped}`);
    console.log(`skipped (${result.skipped})`);
    continue;
  }
  console.log(`${((performance.now() - t0) / 1000).toFixed(1)} s`);
  for (const r of result) rows.push({ ...r, env: b.env, stage: r.stage ? `${b.stage}: ${r.stage}` : b.stage });
}

const fmt = (v) => (typeof v === 'number' ? (Number.isNaN(v) ? '—' : v >= 100 ? v.toFixed(0) : v.toFixed(1)) : v ?? '');
const cols = [
  ['env', (r) => r.env],
  ['stage', (r) => r.stage],
  ['input', (r) => r.input],
  ['faces', (r) => (r.faces ? r.faces.toLocaleString('en-US') : '')],
  ['ms', (r) => fmt(r.ms)],
  ['note', (r) => [r.runs ? `median of ${r.runs}` : '', r.note ?? ''].filter(Boolean).join('; ')],
];
const cells = rows.map((r) => cols.map(([, f]) => String(f(r))));
const widths = cols.map(([h], i) => Math.max(h.length, ...cells.map((c) => c[i].length)));
const line = (c) => c.map((s, i) => (i === 3 || i === 4 ? s.padStart(widths[i]) : s.padEnd(widths[i]))).join('  ');
console.log();
console.log(line(cols.map(([h]) => h)));
console.log(line(widths.map((w) => '-'.repeat(w))));
for (const c of cells) console.log(line(c));
for (const n of notes) console.log(`note: ${n}`);

const outDir = path.join(root, 'bench-results');
fs.mkdirSync(outDir, { recursive: true });
const report = {
  date: new Date().toISOString(),
  machine: { platform: `${os.platform()} ${os.arch()}`, cpus: os.cpus().length, cpu: os.cpus()[0]?.model, node: process.version },
  inputs: inputs.map((i) => ({ file: path.relative(root, i.file).startsWith('..') ? i.file : path.relative(root, i.file), faces: i.faces })),
  rows,
  notes,
};
fs.writeFileSync(path.join(outDir, 'bench.json'), `${JSON.stringify(report, null, 2)}\n`);
console.log(`\nbench: wrote ${path.relative(root, path.join(outDir, 'bench.json'))}`);
