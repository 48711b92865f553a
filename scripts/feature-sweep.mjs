#!/usr/bin/env node
// Sweeps the sharp-edge threshold over meshes with the release CLI and checks
// every result independently, from the files alone: the input's sharp edges
// (dihedral angle above the threshold, computed here) must be axis-aligned in
// the output's UVs, no triangle may be flipped, and every seam must be a
// rotation by k·90° (with equal lengths on both sides).
//
//   node scripts/feature-sweep.mjs [--angles 20,30,...] [--out DIR] MESH.obj ...
//   node scripts/feature-sweep.mjs --random N [--seed S] MESH.obj ...
// (CONEMAP_BIN=path runs another build of the CLI.) With --random, each mesh
// gets N random feature sets instead of thresholds, sent with --features:
// lone edges, random walks along edges and loops around a vertex's fan.
//
// Prints one line per run and a summary; exits 1 when any run fails or is off.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { checkUv, parseObj } from '../tests/node/uvcheck.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const argv = process.argv.slice(2);
const take = (name, dflt) => {
  const i = argv.indexOf(name);
  if (i < 0) return dflt;
  const [v] = argv.splice(i, 2).slice(1);
  return v;
};
const angles = take('--angles', '20,30,40,50,60,70,80,90,100,110,120,130,140,150').split(',').map(Number);
const outDir = take('--out', fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-sweep-')));
const extra = take('--args', '').split(' ').filter(Boolean);
const randomSets = Number(take('--random', '0'));
let seed = Number(take('--seed', '1')) >>> 0;
const bin = process.env.CONEMAP_BIN || path.join(root, 'target/release/conemap');
fs.mkdirSync(outDir, { recursive: true });

/** Interior edges of `mesh` (welded by exact position) with dihedral angle above `deg`, as position pairs. */
function sharpEdges({ v, faces }, deg) {
  const key = (i) => v[i].join(',');
  const normal = (f) => {
    const [a, b, c] = f.map((c) => v[c[0]]);
    const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
    const l = Math.hypot(...n) || 1;
    return n.map((x) => x / l);
  };
  const sides = new Map();
  faces.forEach((f, fi) => {
    for (let k = 0; k < 3; k++) {
      const [a, b] = [key(f[k][0]), key(f[(k + 1) % 3][0])];
      const e = a < b ? `${a}|${b}` : `${b}|${a}`;
      if (!sides.has(e)) sides.set(e, []);
      sides.get(e).push(fi);
    }
  });
  const out = new Set();
  const limit = (deg * Math.PI) / 180;
  for (const [e, fs2] of sides) {
    if (fs2.length !== 2) continue;
    const [n, m] = fs2.map((fi) => normal(faces[fi]));
    const cos = Math.max(-1, Math.min(1, n[0] * m[0] + n[1] * m[1] + n[2] * m[2]));
    if (Math.acos(cos) > limit) out.add(e);
  }
  return out;
}

const angleTo90 = (a) => Math.abs(a - Math.round(a / (Math.PI / 2)) * (Math.PI / 2));

/**
 * Worst axis deviation (rad) over the output face sides of the edges in
 * `edges` (position-pair keys), how many are off by more than 1e-9 rad and
 * how many have no image. An input edge the solver split (vertices inserted
 * on it) is followed as a chain of collinear output edges.
 */
function featureAlignment(out, edges) {
  const key = (i) => out.v[i].join(',');
  const pos = new Map();
  const sides = new Map(); // output edge key -> worst deviation over its face sides
  const nbrs = new Map();
  for (const f of out.faces) {
    for (let k = 0; k < 3; k++) {
      const [c, d] = [f[k], f[(k + 1) % 3]];
      const [a, b] = [key(c[0]), key(d[0])];
      pos.set(a, out.v[c[0]]);
      const e = a < b ? `${a}|${b}` : `${b}|${a}`;
      const [s, t] = [out.vt[c[1]], out.vt[d[1]]];
      const dev = angleTo90(Math.atan2(t[1] - s[1], t[0] - s[0]));
      sides.set(e, Math.max(sides.get(e) ?? 0, dev));
      for (const [x, y] of [[a, b], [b, a]]) {
        if (!nbrs.has(x)) nbrs.set(x, new Set());
        nbrs.get(x).add(y);
      }
    }
  }
  const onSegment = (p, a, b) => {
    const ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    const l2 = ab[0] ** 2 + ab[1] ** 2 + ab[2] ** 2;
    const t = (ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / l2;
    const r = ap.map((x, i) => x - t * ab[i]);
    return t > 1e-12 && t < 1 + 1e-12 && Math.hypot(...r) <= 1e-9 * Math.sqrt(l2);
  };
  let worst = 0;
  let off = 0;
  let missing = 0;
  for (const e of edges) {
    const [a, b] = e.split('|');
    let dev = sides.get(e);
    if (dev === undefined && pos.has(a) && pos.has(b)) {
      // Follow the chain of pieces from a to b.
      const [pa, pb] = [pos.get(a), pos.get(b)];
      let at = a;
      dev = 0;
      for (let steps = 0; at !== b && steps < 64; steps++) {
        const next = [...(nbrs.get(at) ?? [])].find((x) => x === b || (x !== at && onSegment(pos.get(x), pos.get(at), pb) && onSegment(pos.get(x), pa, pb)));
        if (next === undefined) break;
        const piece = at < next ? `${at}|${next}` : `${next}|${at}`;
        dev = Math.max(dev, sides.get(piece));
        at = next;
      }
      if (at !== b) dev = undefined;
    }
    if (dev === undefined) {
      missing += 1;
      continue;
    }
    worst = Math.max(worst, dev);
    if (dev > 1e-9) off += 1;
  }
  return { worst, off, missing };
}

/** Deterministic uniform [0, 1) (mulberry32). */
function random() {
  seed = (seed + 0x6d2b79f5) >>> 0;
  let t = seed;
  t = Math.imul(t ^ (t >>> 15), t | 1);
  t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
  return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
}

/**
 * A random feature set of `mesh` as position-pair keys: 1-6 picks, each a
 * lone interior edge, a random walk of 2-30 edges or the loop of edges
 * around a vertex's fan (the edges opposite it).
 */
function randomFeatures({ v, faces }) {
  const key = (i) => v[i].join(',');
  const nbrs = new Map();
  const opposite = new Map();
  const edgeKey = (a, b) => (a < b ? `${a}|${b}` : `${b}|${a}`);
  for (const f of faces) {
    for (let k = 0; k < 3; k++) {
      const [a, b, c] = [key(f[k][0]), key(f[(k + 1) % 3][0]), key(f[(k + 2) % 3][0])];
      if (!nbrs.has(a)) nbrs.set(a, new Set());
      nbrs.get(a).add(b);
      if (!nbrs.has(b)) nbrs.set(b, new Set());
      nbrs.get(b).add(a);
      if (!opposite.has(a)) opposite.set(a, []);
      opposite.get(a).push(edgeKey(b, c));
    }
  }
  const vertices = [...nbrs.keys()];
  const pickVertex = () => vertices[Math.floor(random() * vertices.length)];
  const out = new Set();
  const picks = 1 + Math.floor(random() * 6);
  for (let p = 0; p < picks; p++) {
    const kind = Math.floor(random() * 3);
    let at = pickVertex();
    if (kind === 2) {
      for (const e of opposite.get(at)) out.add(e);
      continue;
    }
    const steps = kind === 0 ? 1 : 2 + Math.floor(random() * 29);
    for (let s = 0; s < steps; s++) {
      const next = [...nbrs.get(at)];
      const to = next[Math.floor(random() * next.length)];
      out.add(edgeKey(at, to));
      at = to;
    }
  }
  return out;
}

let failures = 0;
const rows = [];
for (const mesh of argv) {
  const input = parseObj(fs.readFileSync(mesh, 'utf8'));
  const name = path.basename(mesh, '.obj');
  const runs = randomSets > 0 ? [...Array(randomSets).keys()].map((i) => `#${i}`) : angles;
  for (const deg of runs) {
    const obj = path.join(outDir, `${name}-${deg}.obj`);
    const report = path.join(outDir, `${name}-${deg}.json`);
    let sharp;
    let args;
    if (randomSets > 0) {
      sharp = randomFeatures(input);
      const file = path.join(outDir, `${name}-${deg}.features.json`);
      const edges = [...sharp].map((e) => e.split('|').map((p) => p.split(',').map(Number)));
      fs.writeFileSync(file, JSON.stringify({ edges }));
      args = ['--features', file];
    } else {
      sharp = sharpEdges(input, deg);
      args = ['--sharp', String(deg)];
    }
    const t0 = Date.now();
    const run = spawnSync(bin, ['solve', mesh, '-o', obj, ...args, '--report', report, ...extra], { encoding: 'utf8' });
    const secs = ((Date.now() - t0) / 1000).toFixed(1);
    if (run.status !== 0) {
      failures += 1;
      const msg = run.stderr.trim().split('\n').pop();
      console.log(`${name} ${deg}${randomSets ? '' : '°'}: FAILED (${secs} s) ${msg}`);
      rows.push({ name, deg, ok: false, msg });
      continue;
    }
    const out = parseObj(fs.readFileSync(obj, 'utf8'));
    const uv = checkUv(out);
    const al = featureAlignment(out, sharp);
    const rep = JSON.parse(fs.readFileSync(report, 'utf8'));
    const bad = uv.flipped > 0 || uv.maxSeamAngle > 1e-9 || uv.maxSeamLength > 1e-6 || al.worst > 1e-9 || al.missing > 0;
    const unaligned = rep.unaligned_features?.length ?? 0;
    if (bad && !(al.off <= unaligned && uv.flipped === 0)) failures += 1;
    const line = `${name} ${deg}${randomSets ? '' : '°'}: ${bad ? 'OFF' : 'ok'} (${secs} s) features ${sharp.size}, cones ${rep.cones.length}, flipped ${uv.flipped}, seam ${uv.maxSeamAngle.toExponential(1)} rad / ${uv.maxSeamLength.toExponential(1)}, features off ${al.off} (worst ${al.worst.toExponential(1)} rad, reported ${unaligned}), missing ${al.missing}, distortion ${rep.metrics.distortion.toFixed(4)}, inserted ${rep.inserted_vertices}`;
    console.log(line);
    rows.push({ name, deg, ok: !bad, secs: +secs, features: sharp.size, flipped: uv.flipped, seam: uv.maxSeamAngle, off: al.off, worst: al.worst, distortion: rep.metrics.distortion });
  }
}
fs.writeFileSync(path.join(outDir, 'sweep.json'), JSON.stringify(rows, null, 1));
console.log(`${rows.length} runs, ${failures} failed or off; outputs in ${outDir}`);
process.exit(failures ? 1 : 0);
