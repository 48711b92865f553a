#!/usr/bin/env node
// Builds the static site in dist/ (and the node wasm package in build/pkg-node).
// Every step is skipped when its outputs are newer than its inputs, so a re-run
// with nothing changed takes about as long as a no-op `cargo build`.
//
//   cargo (wasm32, release) → wasm-bindgen --target web    → build/pkg      → dist/pkg
//                           → wasm-bindgen --target nodejs → build/pkg-node (tests, bench)
//   esbuild web/src/main.ts, web/src/worker.ts → dist/main.js, dist/worker.js
//   web/index.html, web/style.css → dist/;  samples → dist/samples (+ index.json)
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const rel = (...p) => path.join(root, ...p);
const dist = rel('dist');
const home = process.env.HOME ?? '';
const env = { ...process.env, PATH: [path.join(home, '.cargo/bin'), process.env.PATH].join(path.delimiter) };
const quiet = process.argv.includes('--quiet');

const log = (msg) => { if (!quiet) console.log(`build: ${msg}`); };

function run(cmd, args) {
  const r = spawnSync(cmd, args, { cwd: root, env, stdio: 'inherit' });
  if (r.error) throw new Error(`${cmd}: ${r.error.message}`);
  if (r.status !== 0) throw new Error(`${cmd} ${args.join(' ')} exited with ${r.status ?? r.signal}`);
}

function onPath(cmd) {
  return spawnSync('sh', ['-c', `command -v ${cmd}`], { env }).status === 0;
}

const mtime = (p) => { try { return fs.statSync(p).mtimeMs; } catch { return -1; } };

function filesUnder(dir) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true, recursive: true })
    .filter((d) => d.isFile())
    .map((d) => path.join(d.parentPath ?? d.path, d.name));
}

/** True when every output exists and is newer than every input. */
function upToDate(outputs, inputs) {
  const oldestOut = Math.min(...outputs.map(mtime));
  if (oldestOut < 0) return false;
  return inputs.every((i) => mtime(i) <= oldestOut);
}

function copyIfNewer(src, dst) {
  if (mtime(dst) >= mtime(src) && fs.statSync(dst).size === fs.statSync(src).size) return false;
  fs.mkdirSync(path.dirname(dst), { recursive: true });
  fs.copyFileSync(src, dst);
  return true;
}

function writeIfChanged(file, text) {
  if (fs.existsSync(file) && fs.readFileSync(file, 'utf8') === text) return false;
  fs.mkdirSync(path.dirname(file), { recursive: true });
  fs.writeFileSync(file, text);
  return true;
}

// 1. Rust → wasm (cargo is incremental on its own).
log('cargo build --release --target wasm32-unknown-unknown -p conemap --lib');
run('cargo', ['build', '--release', '--target', 'wasm32-unknown-unknown', '-p', 'conemap', '--lib', ...(quiet ? ['--quiet'] : [])]);
const wasm = rel('target/wasm32-unknown-unknown/release/conemap.wasm');
if (!fs.existsSync(wasm)) throw new Error(`cargo did not produce ${wasm}`);

// 2. wasm-bindgen, web and node flavours.
const bindgen = [
  { target: 'web', out: rel('build/pkg') },
  { target: 'nodejs', out: rel('build/pkg-node') },
];
for (const { target, out } of bindgen) {
  const outputs = [path.join(out, 'conemap.js'), path.join(out, 'conemap_bg.wasm'), path.join(out, 'conemap.d.ts')];
  const bindgenBin = path.join(home, '.cargo/bin/wasm-bindgen'); // a new CLI version regenerates
  if (upToDate(outputs, [wasm, bindgenBin].filter(fs.existsSync))) continue;
  log(`wasm-bindgen --target ${target} --out-dir ${path.relative(root, out)}`);
  run('wasm-bindgen', ['--target', target, '--out-dir', out, wasm]);
  if (target === 'web') {
    if (onPath('wasm-opt')) {
      log('wasm-opt -O3');
      const f = path.join(out, 'conemap_bg.wasm');
      run('wasm-opt', ['-O3', '--enable-bulk-memory', '--enable-nontrapping-float-to-int', '--enable-sign-ext', '--enable-mutable-globals', f, '-o', f]);
    } else {
      log('wasm-opt not on PATH; web wasm left unoptimised by binaryen');
    }
  } else {
    // The root package.json says "type": "module"; the nodejs glue is CommonJS.
    fs.writeFileSync(path.join(out, 'package.json'), '{ "type": "commonjs" }\n');
  }
  for (const o of outputs) fs.utimesSync(o, new Date(), new Date());
}

// 3. TypeScript → dist/main.js, dist/worker.js.
const bundleOut = [path.join(dist, 'main.js'), path.join(dist, 'worker.js')];
const bundleIn = [
  ...filesUnder(rel('web/src')),
  rel('build/pkg/conemap.js'),
  rel('tsconfig.json'),
  rel('package-lock.json'),
  fileURLToPath(import.meta.url),
];
if (!upToDate(bundleOut, bundleIn)) {
  log('esbuild web/src/main.ts web/src/worker.ts → dist/');
  const esbuild = await import('esbuild');
  await esbuild.build({
    absWorkingDir: root,
    entryPoints: { main: 'web/src/main.ts', worker: 'web/src/worker.ts' },
    outdir: dist,
    bundle: true,
    format: 'esm',
    platform: 'browser',
    target: ['es2022'],
    minify: true,
    sourcemap: 'linked',
    legalComments: 'none',
    logLevel: 'warning',
  });
}

// 4. Static files.
for (const f of ['index.html', 'style.css']) {
  if (copyIfNewer(rel('web', f), path.join(dist, f))) log(`copied web/${f}`);
}
for (const f of ['conemap.js', 'conemap_bg.wasm']) {
  if (copyIfNewer(rel('build/pkg', f), path.join(dist, 'pkg', f))) log(`copied build/pkg/${f} → dist/pkg/`);
}

// 5. Samples: the committed ones, then the clean shared meshes (if ../shared
// exists), then one bad input to show the error display.
const shared = path.resolve(root, '../shared/meshes');
const sharedClean = [
  'fandisk', 'spot', 'cow', 'woody', 'alligator', 'teapot', 'bff-bunny', 'bff-face',
  'bff-cowhead', 'bff-hemisphere', 'bff-punctured-torus', 'bff-maze', 'xatlas-gazebo',
];
const sharedBad = { beetle: 'bad input: non-manifold edges' };
const samples = [];
const seen = new Set();
const addSample = (src, note) => {
  const file = path.basename(src);
  if (seen.has(file) || !fs.existsSync(src)) return;
  seen.add(file);
  if (copyIfNewer(src, path.join(dist, 'samples', file))) log(`sample ${file}`);
  const name = file.replace(/\.[^.]+$/, '');
  samples.push({ name, file, bytes: fs.statSync(src).size, ...(note ? { note } : {}) });
};
for (const f of filesUnder(rel('web/public/samples')).sort()) addSample(f);
for (const n of sharedClean) addSample(path.join(shared, `${n}.obj`));
for (const [n, note] of Object.entries(sharedBad)) addSample(path.join(shared, `${n}.obj`), note);
// The default mesh first, then alphabetical, bad inputs last.
samples.sort((a, b) => (a.name === 'fandisk' ? -1 : b.name === 'fandisk' ? 1 : 0)
  || Number(Boolean(a.note)) - Number(Boolean(b.note)) || a.name.localeCompare(b.name));
if (writeIfChanged(path.join(dist, 'samples', 'index.json'), `${JSON.stringify({ samples }, null, 2)}\n`)) {
  log(`dist/samples/index.json (${samples.length} samples)`);
}
log('dist/ ready');
