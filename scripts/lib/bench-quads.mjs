// Quad-mesh rows of scripts/bench.mjs: integer-grid quantization and quad
// extraction on the fandisk (sharp edges > 60° as features) and spot (no
// features) at about 1 000, 3 000 and 10 000 quads, natively (`conemap quads
// --report`) and in wasm under node (`MeshSession.quads` after one `solve`).
//
// Every row is { stage, input, faces, ms, note } like the other benches, plus
// the figures as fields (`target`, `quads`, `quantize_s`, `extract_s`, ...)
// for bench-results/bench.json.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { cadCylinderObj } from './cad-cylinder.mjs';

/** Quads asked for (the CLI's `--quads N`, `MeshSession.quads(n)`). */
export const QUAD_TARGETS = [1000, 3000, 10000];

/**
 * The meshes: fandisk with its sharp edges (> 60°) as features, spot without
 * features (spot only where ../shared/meshes is present), and a low-poly
 * CAD cylinder (24 segments, 92 long triangles, rims > 60° as features),
 * which the quad solve refines first (`pipeline::QUAD_MAX_EDGE`).
 */
export function quadMeshes(fandisk, sharedMeshes) {
  const meshes = [{ name: 'fandisk.obj', file: fandisk, sharp: 60, label: 'fandisk.obj (sharp > 60°)' }];
  const spot = path.join(sharedMeshes, 'spot.obj');
  if (fs.existsSync(spot)) meshes.push({ name: 'spot.obj', file: spot, sharp: null, label: 'spot.obj (no features)' });
  const cylinder = path.join(os.tmpdir(), 'conemap-bench-cad-cylinder.obj');
  fs.writeFileSync(cylinder, cadCylinderObj(24));
  meshes.push({ name: 'cad-cylinder.obj', file: cylinder, sharp: 60, label: 'CAD cylinder, 24 segments (sharp > 60°)' });
  return meshes;
}

/**
 * QuadriFlow's figures on the same meshes at about 3 000 quads, for
 * comparison only: static, not run here (QuadriFlow is not installed).
 */
export const QUADRIFLOW_ANCHORS = [
  { input: 'fandisk.obj', quads: 2818, seconds: 3.4, euler: 4, singular: 50, angle: 10.1 },
  { input: 'spot.obj', quads: 2970, seconds: 3.1, euler: null, singular: 62, angle: 7.1 },
];

/** Static rows of QUADRIFLOW_ANCHORS (ms '—': nothing is measured); after the native rows. */
export function quadriflowRows() {
  return QUADRIFLOW_ANCHORS.map((a) => ({
    stage: 'QuadriFlow anchor (static, not run)',
    input: a.input,
    ms: NaN,
    static: true,
    note: `${a.quads.toLocaleString('en-US')} quads in ${a.seconds} s, `
      + `${a.euler === null ? '' : `Euler ${a.euler}, `}${a.singular} singular, mean angle deviation ${a.angle}°`,
  }));
}

/** Singular vertices of a quad report: interior ones by valence, and the boundary count. */
function singularSummary(report) {
  const all = report.singular_vertices ?? [];
  const interior = all.filter((v) => !v.boundary);
  const byValence = new Map();
  for (const v of interior) byValence.set(v.valence, (byValence.get(v.valence) ?? 0) + 1);
  const detail = [...byValence].sort((a, b) => a[0] - b[0]).map(([val, n]) => `${n}×v${val}`).join(' ');
  return { interior: interior.length, boundary: all.length - interior.length, text: `${interior.length} singular (${detail || 'none'}) + ${all.length - interior.length} on the boundary` };
}

/**
 * The figures of one quad run: `quantization` and `report` as the CLI's
 * report / `MeshSession.quads` give them, `defects` a count.
 */
function quadFigures(quantization, report, defects) {
  const s = singularSummary(report);
  return {
    quads: report.quads,
    euler: report.euler_characteristic,
    boundary_loops: report.boundary_loops,
    singular: s.interior,
    singular_boundary: s.boundary,
    angle_mean_deviation: report.angle_mean_deviation,
    flipped_quads: report.flipped_quads,
    degenerate_quads: report.degenerate_quads,
    non_manifold_edges: report.non_manifold_edges,
    sharp_within_tolerance: report.fraction_sharp_within_tolerance,
    distance_quads_to_input: report.distance_quads_to_input_relative,
    distance_input_to_quads: report.distance_input_to_quads_relative,
    defects,
    flipped_after_quantization: quantization.flipped,
    conflicts: quantization.conflicts,
    grid_size: quantization.grid_size,
    distortion_before: quantization.distortion_before,
    distortion_after: quantization.distortion_after,
    singularText: s.text,
  };
}

/** The note shared by the native and wasm rows. */
function figuresNote(f) {
  const sharp = f.sharp_within_tolerance === undefined || f.sharp_within_tolerance === null
    ? '' : `, ${(100 * f.sharp_within_tolerance).toFixed(1)} % sharp aligned`;
  return `${f.quads.toLocaleString('en-US')} quads, angle dev ${f.angle_mean_deviation.toFixed(1)}°, ${f.singularText}, `
    + `Euler ${f.euler} (${f.boundary_loops} loops), ${f.defects} defects, ${f.flipped_after_quantization} flipped tris, `
    + `distortion ${f.distortion_before.toFixed(3)} → ${f.distortion_after.toFixed(3)}, `
    + `${f.flipped_quads} flipped / ${f.degenerate_quads} degenerate quads${sharp}`;
}

/** Input face count of an OBJ (lines starting `f `; the meshes are triangles). */
function objFaces(file) {
  let n = 0;
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) if (line.startsWith('f ')) n++;
  return n;
}

/**
 * Natively: `conemap quads MESH -o OUT.obj --quads N [--sharp 60] --quiet
 * --report R.json` per mesh and N (each run solves again: the CLI has no
 * session). ms = quantize + extract; the note has the solve for scale.
 */
export function nativeQuadRows(bin, meshes) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-quads-'));
  const rows = [];
  try {
    for (const mesh of meshes) {
      const faces = objFaces(mesh.file);
      for (const n of QUAD_TARGETS) {
        const report = path.join(dir, 'report.json');
        const extra = mesh.sharp === null ? [] : ['--sharp', String(mesh.sharp)];
        const r = spawnSync(bin, ['quads', mesh.file, '-o', path.join(dir, 'out.obj'), '--quads', String(n), ...extra, '--quiet', '--report', report], { encoding: 'utf8' });
        if (r.status !== 0) return { skipped: `conemap quads ${mesh.name} --quads ${n} failed: ${(r.stderr || '').trim().split('\n').slice(-2).join(' | ')}` };
        const j = JSON.parse(fs.readFileSync(report, 'utf8'));
        const t = j.timings;
        const f = quadFigures(j.quantization, j.quads, Array.isArray(j.defects) ? j.defects.length : j.defects);
        rows.push({
          stage: `quantize + extract, N = ${n.toLocaleString('en-US')}`,
          input: mesh.label,
          faces,
          ms: (t.quantize + t.extract) * 1000,
          note: `quantize ${t.quantize.toFixed(3)} s, extract ${t.extract.toFixed(3)} s (solve ${t.solve.toFixed(2)} s, check ${t.check.toFixed(3)} s)`
            + `${j.decimated ? `, traced on a decimation to ${j.decimated.faces.toLocaleString('en-US')} faces` : ''}${j.attempts > 1 ? ` (${j.attempts} attempts)` : ''}; ${figuresNote(f)}`,
          target: n,
          quantize_s: t.quantize,
          extract_s: t.extract,
          solve_s: t.solve,
          check_s: t.check,
          ...withoutText(f),
        });
      }
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
  return [...rows, ...quadriflowRows()];
}

const withoutText = ({ singularText, ...rest }) => rest;

/**
 * In wasm under node: one `MeshSession.solve` per mesh (α = 0.01), then
 * `session.quads(n, () => {})` for each N, timed on the wall clock (what the
 * page re-runs when the quad count changes: quantization, extraction, checks
 * and the OBJ / GLB / grid-GLB exports; the first call also sets the
 * quantizer up). A second call at the first N shows the cost without that
 * set-up, on the same map: a later, larger N may re-solve the map on a
 * refinement (edges longer than its quads want), which the session keeps.
 */
export function wasmNodeQuadRows(wasm, meshes) {
  if (typeof wasm.MeshSession?.prototype?.quads !== 'function') {
    return { skipped: 'build/pkg-node has no MeshSession.quads (rebuild: node scripts/build.mjs)' };
  }
  const rows = [];
  for (const mesh of meshes) {
    const session = wasm.MeshSession.open([{ name: mesh.name, bytes: new Uint8Array(fs.readFileSync(mesh.file)) }]);
    try {
      const features = mesh.sharp === null ? new Uint32Array(0) : session.sharp_edges(mesh.sharp);
      let t0 = performance.now();
      const solved = session.solve(features, 0.01, false, () => {});
      const solveMs = performance.now() - t0;
      const faces = session.indices().length / 3;
      rows.push({
        stage: 'solve (once per mesh)',
        input: mesh.label,
        faces,
        ms: solveMs,
        note: `${solved.cones.length} cones, distortion ${solved.metrics.distortion.toFixed(3)}, ${solved.metrics.flipped} flipped`,
      });
      const targets = [QUAD_TARGETS[0], ...QUAD_TARGETS];
      targets.forEach((n, i) => {
        t0 = performance.now();
        let q;
        try {
          q = session.quads(n, () => {});
        } catch (e) {
          throw new Error(`session.quads(${n}) on ${mesh.name} threw: ${e.message ?? e}`);
        }
        const ms = performance.now() - t0;
        const f = quadFigures(q.quantization, q.report, q.defects);
        const quantS = q.quantization.seconds;
        const tag = i === 0 ? ' (first call: with quantizer set-up)' : i === 1 ? ' (again)' : '';
        rows.push({
          stage: `session.quads(${n.toLocaleString('en-US')})${tag}`,
          input: mesh.label,
          faces,
          ms,
          note: `quantize ${quantS.toFixed(3)} s, rest ${(ms / 1000 - quantS).toFixed(3)} s (extract + check + exports)`
            + `${q.decimated ? `, traced on a decimation to ${q.decimated.faces.toLocaleString('en-US')} faces (decimation and its solve ${(q.timings.decimate + q.timings.solve).toFixed(3)} s)` : ''}; ${figuresNote(f)}`,
          target: n,
          quantize_s: quantS,
          rest_s: ms / 1000 - quantS,
          bytes: { obj: q.obj.length, glb: q.glb.length, grid_glb: q.grid_glb.length },
          ...withoutText(f),
        });
      });
    } finally {
      session.free();
    }
  }
  return rows;
}
