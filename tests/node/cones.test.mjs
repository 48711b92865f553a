// Cone placement through the wasm build (the page's worker calls the same API).
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { committedFandisk, loadWasm, sharedMesh } from './wasm.mjs';

const wasm = loadWasm();
const open = (file) =>
  wasm.MeshSession.open([{ name: path.basename(file), bytes: new Uint8Array(fs.readFileSync(file)) }]);
const sumK = (r) => [...r.cones, ...r.boundary_corners].reduce((s, c) => s + c.k, 0);

test('fandisk with sharp features: Gauss-Bonnet, progress by round, exact constraints', () => {
  const session = open(committedFandisk);
  assert.equal(session.is_valid(), true);
  const edges = session.edges();
  const sharp = session.sharp_edges(60);
  assert.ok(sharp.length > 0 && sharp.length < edges.length / 2);
  const stages = new Set();
  let roundingCalls = 0;
  const fractions = [];
  const r = session.place_cones(sharp, 0.01, false, (stage, step, remaining, fraction) => {
    stages.add(stage);
    if (stage === 'rounding') roundingCalls += 1;
    if (fraction !== undefined) fractions.push([stage, fraction]);
  });
  for (const stage of ['topology', 'rounding', 'cone moves']) assert.ok(stages.has(stage), `no ${stage} report`);
  // Cone moves and pair cancellation tell the share of their pass done.
  assert.ok(fractions.some(([stage]) => stage === 'cone moves'), 'cone moves report no fraction');
  for (const [stage, f] of fractions) {
    assert.ok(['cone moves', 'pair cancellation'].includes(stage), `a fraction for ${stage}`);
    assert.ok(f >= 0 && f < 1, `${stage}: fraction ${f}`);
  }
  assert.equal(r.feature_edges, sharp.length);
  assert.equal(sumK(r), 4 * 2, 'sum of k = 4 chi');
  for (const c of r.components) {
    assert.equal(c.k_sum, 4 * c.euler_characteristic);
    assert.ok(c.residual < 1e-8, `residual ${c.residual}`);
  }
  // One report after every solve: the first one and one per rounding round, per component.
  assert.equal(roundingCalls, r.rounds + r.components.length);
  assert.ok(r.cones.length > 10 && r.cones.length < 200, `${r.cones.length} cones`);
  for (const c of r.cones) assert.ok(Number.isInteger(c.k) && c.k !== 0 && c.position.length === 3);
});

test('woody (open surface): boundary corners and cones add up to 4 chi', () => {
  const file = sharedMesh('woody');
  const r = open(file).place_cones(new Uint32Array(), 0.01, false, () => {});
  assert.equal(sumK(r), 4);
  assert.ok(r.boundary_corners.length > 0);
});

test('MIQ emulation runs on the same mesh; without an α it takes the CLI\'s --miq default', () => {
  assert.equal(wasm.default_alpha(false), 0.01);
  assert.equal(wasm.default_alpha(true), 100);
  const session = open(committedFandisk);
  const sharp = session.sharp_edges(60);
  const r = session.place_cones(sharp, 100, true, () => {});
  assert.equal(sumK(r), 8);
  const byDefault = session.place_cones(sharp, undefined, true, () => {});
  assert.equal(byDefault.energy, r.energy, 'undefined α with MIQ is α = 100');
  const plain = session.place_cones(sharp, undefined, false, () => {});
  assert.equal(plain.energy, session.place_cones(sharp, 0.01, false, () => {}).energy, 'undefined α without MIQ is 0.01');
});

test('bad requests give readable errors, not crashes', () => {
  const session = open(committedFandisk);
  assert.throws(() => session.place_cones(new Uint32Array(), 1e9, false, () => {}), /alpha_smooth .* outside/);
  assert.throws(() => session.place_cones(new Uint32Array([4e9]), 0.01, false, () => {}), /feature edge id .* out of range/);
  const beetle = sharedMesh('beetle');
  const bad = open(beetle);
  assert.equal(bad.is_valid(), false);
  assert.throws(() => bad.place_cones(new Uint32Array(), 0.01, false, () => {}), /cannot be parametrized: edge \(v\d+, v\d+\) has \d faces/);
  // The session still answers after an error.
  assert.equal(sumK(session.place_cones(session.sharp_edges(60), 0.01, false, () => {})), 8);
});

/** Solves `bytes` in steps across two sessions (every other component placed
 * in the second and handed over as bytes); checks it equals the one-call
 * solve; returns the first session (its solve finished) and the features. */
function solveAcrossSessions(bytes, minComponents) {
  const a = open(bytes);
  const b = open(bytes);
  const sharp = a.sharp_edges(60);
  const schedule = a.solve_begin(sharp, 0.01, false);
  assert.deepEqual([...b.solve_begin(sharp, 0.01, false)], [...schedule]);
  assert.ok(schedule.length >= minComponents, `${schedule.length} components`);
  assert.deepEqual([...schedule].sort((x, y) => x - y), [...schedule.keys()], 'every component once');
  schedule.forEach((c, i) => {
    if (i % 2) a.solve_add(b.solve_place(c, true, () => {}));
    else assert.equal(a.solve_place(c, false, () => {}), undefined);
  });
  const split = a.solve_finish(() => {});
  const whole = open(bytes).solve(sharp, 0.01, false, () => {});
  assert.equal(split.energy, whole.energy);
  assert.deepEqual(split.cones, whole.cones);
  assert.ok(split.uv.length === whole.uv.length && split.uv.every((v, i) => v === whole.uv[i]), 'same UVs to the bit');
  assert.equal(split.metrics.flipped, 0);
  return { a, sharp, schedule, whole };
}

test('a mesh of 56 parts solved in steps across two sessions equals the one-call solve', () => {
  // Components are numbered across the parts, each solved on its own.
  solveAcrossSessions(sharedMesh('xatlas-gazebo'), 56);
});

test('a solve in steps across two sessions equals the one-call solve', () => {
  const { a, sharp, schedule, whole } = solveAcrossSessions(committedFandisk, 3);
  // Misuse gets clear errors and leaves the session usable.
  assert.throws(() => a.solve_finish(() => {}), /no solve was started/);
  a.solve_begin(sharp, 0.01, false);
  assert.throws(() => a.solve_place(schedule.length, false, () => {}), /out of range/);
  assert.throws(() => a.solve_add(new TextEncoder().encode('{"component": 1}')), /unreadable component result/);
  assert.throws(() => a.solve_finish(() => {}), /do not fit this mesh/);
  assert.equal(a.solve(sharp, 0.01, false, () => {}).energy, whole.energy);
});

test('sharp curves: filters by curve length and dangling ends, with counts', () => {
  const session = open(committedFandisk);
  const all = session.sharp_edges(60);
  const plain = session.sharp_curves(60, 0, false);
  assert.deepEqual([...plain.edges], [...all]);
  assert.equal(plain.stats.sharp_edges, all.length);
  assert.equal(plain.stats.kept_edges, all.length);
  assert.equal(plain.stats.dropped_fragments, 0);
  assert.ok(plain.stats.curves >= 1);
  // A minimum longer than the longest curve drops every curve.
  const none = session.sharp_curves(60, all.length + 1, false);
  assert.equal(none.edges.length, 0);
  assert.equal(none.stats.dropped_fragments, plain.stats.curves);
  // Pruning keeps a subset, and never more edges than detected.
  const closed = session.sharp_curves(60, 0, true);
  const kept = new Set(all);
  assert.ok([...closed.edges].every((e) => kept.has(e)));
  assert.equal(closed.edges.length + closed.stats.pruned_edges, all.length);
});

test('free boundary: woody (flat, one loop) maps without cones, corners or distortion', () => {
  const file = sharedMesh('woody');
  const session = open(file);
  const aligned = session.solve(new Uint32Array(), 0.01, false, () => {});
  assert.ok(aligned.boundary_corners.length > 0 && aligned.metrics.distortion > 1e-3);
  session.set_free_boundary(true);
  const free = session.solve(new Uint32Array(), 0.01, false, () => {});
  assert.equal(free.boundary_corners.length, 0);
  assert.equal(free.cones.length, 0);
  assert.ok(free.metrics.distortion < 1e-6, `distortion ${free.metrics.distortion}`);
  assert.equal(free.metrics.flipped, 0);
  session.set_free_boundary(false);
  assert.ok(session.place_cones(new Uint32Array(), 0.01, false, () => {}).boundary_corners.length > 0, 'the setting can be undone');
});
