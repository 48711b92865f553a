// End-to-end test of the quad mode of the built page (dist/) in headless
// Chromium via playwright-core: the fandisk with its sharp edges solved, then
// the quads of the map at a count set on the slider, their figures, legend,
// overlay, the grid map in the UV view and the downloads; a low-poly CAD
// cylinder; the fandisk's creases marked with the Creases button followed by
// the quads. Run after `npm run build`.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import validator from 'gltf-validator';
import { cadCylinderObj } from '../../scripts/lib/cad-cylinder.mjs';
import { closePage, openPage, output } from './harness.mjs';

const LOAD_TIMEOUT = 90_000;
const SOLVE_TIMEOUT = 120_000;
const QUADS_TIMEOUT = 60_000;

let ctx;
let server;
let page;
let consoleErrors = [];

const hooks = () => page.evaluate(() => window.__conemap);

/** Waits until the answer after `runs` answers is on the page; returns the hooks. */
async function waitForQuads(runs) {
  await page.waitForFunction((n) => window.__conemap.quadRuns > n && document.body.dataset.quads !== 'running', runs, { timeout: QUADS_TIMEOUT });
  return hooks();
}

/** The larger side of bounds [min u, min v, max u, max v]. */
const extent = (b) => Math.max(b[2] - b[0], b[3] - b[1]);

/** Asserts that the UV view draws the integer-grid map of the quads in hooks `h` (their bounds, grid units, with grid lines). */
function assertGridLayout(h) {
  const uv = h.uvView;
  assert.equal(uv?.map, 'grid', 'the UV view draws the grid map');
  assert.deepEqual(uv.bounds, h.quads.uvBounds, 'the UV view is fit to the grid UVs');
  assert.ok(extent(uv.bounds) > 10, `grid map extent ${extent(uv.bounds)} cells`);
  assert.ok(Number.isInteger(uv.gridStride) && uv.gridStride >= 1, `grid stride ${uv.gridStride}`);
}

/**
 * Moves the pointer from off the views onto the centroid of face `f` in the UV
 * view: some face is highlighted (hover sync) and the pointer lies within its
 * triangle as drawn, so no farther from its centroid than its farthest corner
 * (the grid map has degenerate triangles: not always `f` itself).
 */
async function hoverUvFace(f) {
  await page.mouse.move(5, 5);
  await page.waitForFunction(() => window.__conemap.hoverFace === null, null, { timeout: 5_000 });
  const p = await page.evaluate((face) => window.__conemapTest.projectUvFace(face), f);
  assert.ok(p, 'no UV layout');
  await page.mouse.move(p.x, p.y);
  await page.waitForFunction(() => window.__conemap.hoverFace !== null, null, { timeout: 5_000 });
  const g = (await hooks()).hoverFace;
  const q = await page.evaluate((face) => window.__conemapTest.projectUvFace(face), g);
  const d = Math.hypot(q.x - p.x, q.y - p.y);
  assert.ok(d <= q.radius + 1, `hovered face ${g} (for ${f}) is ${d.toFixed(1)} px from the pointer, radius ${q.radius.toFixed(1)} px`);
}

/** The `f` lines of an OBJ text, each as its vertex references. */
const faces = (text) => text.split('\n').filter((l) => l.startsWith('f ')).map((l) => l.trim().split(/\s+/).slice(1));

describe('quad mode', () => {
  before(async () => {
    ctx = await openPage();
    ({ server, page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('solves the fandisk with its sharp edges; the quad control appears, off', async () => {
    await page.goto(server.url);
    await page.waitForFunction(() => window.__conemap && window.__conemap.loads > 0 && window.__conemap.state === 'ready', null, { timeout: LOAD_TIMEOUT });
    assert.equal(await page.getByTestId('quads').isVisible(), false, 'no quad control before a solve');
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction(() => window.__conemap.features > 300, null, { timeout: 10_000 });
    await page.getByTestId('alpha').fill('0');
    await page.getByTestId('run').click();
    await page.waitForFunction(() => window.__conemap.solves > 0, null, { timeout: SOLVE_TIMEOUT });
    const h = await hooks();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(await page.getByTestId('quads').isVisible(), true);
    assert.equal(await page.getByTestId('quad-mode').isChecked(), false);
    assert.equal(await page.getByTestId('quad-count').isEnabled(), false, 'the slider waits for quad mode');
    assert.equal(await page.getByTestId('quad-target').innerText(), '3,000');
    assert.equal(h.quads, null);
    assert.equal(h.uvView?.map, 'seamless');
    assert.deepEqual(h.uvView.bounds, h.result.uvBounds);
    assert.equal(h.uvView.gridStride, null, 'no grid lines on the seamless map');
  });

  it('computes about 2000 quads from the slider; a newer count supersedes an older one', async () => {
    const runs = (await hooks()).quadRuns;
    await page.getByTestId('quad-mode').check();
    // Quad mode asks for the slider's 3000 at once; 500 then 2000 supersede it.
    await page.evaluate(() => window.__conemapTest.setQuadCount(500));
    await page.evaluate(() => window.__conemapTest.setQuadCount(2000));
    await page.waitForFunction(() => document.body.dataset.quads === 'running', null, { timeout: 5_000 });
    const frame = await page.evaluate(() => new Promise((res) => { const t = performance.now(); requestAnimationFrame(() => res(performance.now() - t)); }));
    assert.ok(frame < 1000, `a frame took ${frame} ms while quads were computed`);
    const h = await waitForQuads(runs);
    assert.equal(h.quadsError, null);
    assert.equal(h.quadRuns, runs + 1, 'only the newest request was shown');
    const q = h.quads;
    assert.equal(q.target, 2000);
    assert.ok(Math.abs(q.quads - 2000) <= 0.15 * 2000, `${q.quads} quads for 2000`);
    assert.equal(q.quadIndices, 4 * q.quads);
    assert.equal(q.uvCorners, 3 * h.stats.faces, 'grid UVs for every face corner');
    assert.equal(q.gridChecker, true, 'the checker is drawn from the grid UVs');
    assertGridLayout(h);
    // Hover sync on the grid layout: the face under the pointer in the UV view is highlighted.
    for (const f of [0, 100, Math.floor(h.stats.faces / 2)]) await hoverUvFace(f);
    assert.ok(q.gridSize > 0);
    assert.ok(q.singular.three + q.singular.five + q.singular.other > 0, 'the fandisk has singular vertices');
    assert.equal(await page.getByTestId('quad-target').innerText(), '2,000');
    // The figures, the edge length and the valence legend.
    const stats = page.getByTestId('quad-stats');
    assert.equal(await stats.isVisible(), true);
    assert.match(await stats.locator('dd[data-stat=quads]').innerText(), new RegExp(`^${q.quads.toLocaleString('en-US')} \\(asked 2,000\\)$`));
    assert.match(await stats.locator('dd[data-stat=singular-vertices]').innerText(), new RegExp(`^${q.singular.three} × 3, ${q.singular.five} × 5, ${q.singular.other} other$`));
    assert.match(await stats.locator('dd[data-stat=corner-angle-deviation-mean-max]').innerText(), /^\d+\.\d° \/ \d+\.\d°$/);
    assert.match(await stats.locator('dd[data-stat=distortion-seamless-grid]').innerText(), /^\d\.\d{3} → \d\.\d{3}$/);
    assert.match(await page.getByTestId('quad-size').innerText(), /^Quad edge \d\.\d{4} \(model units\) · [\d,]+ quads$/);
    assert.equal(await page.getByTestId('quad-defects').isVisible(), q.defects > 0);
    const legend = page.getByTestId('quad-legend');
    assert.equal(await legend.isVisible(), true);
    assert.match(await legend.innerText(), new RegExp(`valence 3 \\(${q.singular.three}\\).*valence 5 \\(${q.singular.five}\\).*other \\(${q.singular.other}\\)`, 's'));
    assert.equal(await page.getByTestId('solve-error').isVisible(), false);
    await page.getByTestId('quads').scrollIntoViewIfNeeded();
    await page.screenshot({ path: path.join(output, 'quads-fandisk.png') });
    // "Show quads" hides the edges only; the figures stay.
    await page.getByTestId('show-quads').uncheck();
    await page.screenshot({ path: path.join(output, 'quads-fandisk-grid-checker.png') });
    await page.getByTestId('show-quads').check();
  });

  it('switching the quad count redraws the UV view with the new grid map (at 500 quads traced on a decimation)', async () => {
    let h = await hooks();
    assert.equal(h.quads.decimatedFaces, null, '6.5 faces per quad at 2 000: traced on the mesh solved');
    const before = h.uvView.bounds;
    await page.evaluate(() => window.__conemapTest.setQuadCount(500));
    h = await waitForQuads(h.quadRuns);
    assert.equal(h.quads?.target, 500, h.quadsError ?? '');
    assertGridLayout(h);
    // 26 faces per quad: traced on a decimation, the grid map carried back to every face corner.
    assert.ok(h.quads.decimatedFaces > 4 * 500 && h.quads.decimatedFaces < h.stats.faces / 2, `decimation of ${h.quads.decimatedFaces} faces`);
    assert.equal(h.quads.uvCorners, 3 * h.stats.faces);
    assert.equal(h.quads.defects, 0);
    assert.ok(h.quads.distance < 0.02, `distance ${h.quads.distance}`);
    assert.match(await page.getByTestId('quad-stats').innerText(), /Traced on\s+a decimation to [\d,]+ triangles/);
    // A quarter of the cells: about half the extent.
    const ratio = extent(h.uvView.bounds) / extent(before);
    assert.ok(ratio > 0.3 && ratio < 0.7, `extent ratio ${ratio} for 500 / 2000 quads`);
    await page.evaluate(() => window.__conemapTest.setQuadCount(2000));
    h = await waitForQuads(h.quadRuns);
    assert.equal(h.quads?.target, 2000, h.quadsError ?? '');
    assertGridLayout(h);
  });

  it('downloads the quad mesh as .obj (quads only, the count shown) and .glb, and the grid-UV .glb', async () => {
    const q = (await hooks()).quads;
    const [obj] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-quads-obj').click()]);
    assert.equal(obj.suggestedFilename(), 'fandisk-quads.obj');
    const f = faces(fs.readFileSync(await obj.path(), 'utf8'));
    assert.equal(f.length, q.quads, 'one f line per quad shown');
    assert.ok(f.every((refs) => refs.length === 4), 'every f line has 4 vertices');
    for (const [testid, name] of [['download-quads-glb', 'fandisk-quads.glb'], ['download-grid-glb', 'fandisk-grid-uv.glb']]) {
      const [glb] = await Promise.all([page.waitForEvent('download'), page.getByTestId(testid).click()]);
      assert.equal(glb.suggestedFilename(), name);
      const bytes = new Uint8Array(fs.readFileSync(await glb.path()));
      const validation = await validator.validateBytes(bytes, { uri: name, maxIssues: 0 });
      assert.equal(validation.issues.numErrors, 0, `${name}: ${JSON.stringify(validation.issues.messages.slice(0, 3))}`);
    }
  });

  it('turns quad mode off back to the seamless checker and UV layout, and a new solve drops the quads', async () => {
    await page.getByTestId('quad-mode').uncheck();
    let h = await hooks();
    assert.equal(h.quads, null);
    assert.equal(h.uvView?.map, 'seamless', 'the UV view is back to the seamless map');
    assert.deepEqual(h.uvView.bounds, h.result.uvBounds);
    assert.equal(h.uvView.gridStride, null);
    assert.equal(await page.evaluate(() => document.body.dataset.quads), undefined);
    assert.equal(await page.getByTestId('quad-legend').isVisible(), false);
    assert.equal(await page.getByTestId('download-quads-obj').isEnabled(), false);
    // With quad mode on, a new solve asks for its own quads once it is shown.
    await page.getByTestId('quad-mode').check();
    h = await waitForQuads(h.quadRuns);
    assert.ok(h.quads, h.quadsError ?? '');
    const { solves, quadRuns } = h;
    await page.getByTestId('run').click();
    await page.waitForFunction((n) => window.__conemap.solves > n, solves, { timeout: SOLVE_TIMEOUT });
    h = await waitForQuads(quadRuns);
    assert.equal(h.state, 'solved');
    assert.equal(h.quads?.target, 2000, h.quadsError ?? '');
    assertGridLayout(h);
  });

  it('traces the quads of a low-poly CAD cylinder on a map solved again on its refinement', async () => {
    const n = 20;
    const loads = (await hooks()).loads;
    await page.getByTestId('file-input').setInputFiles({ name: 'cylinder.obj', mimeType: 'text/plain', buffer: Buffer.from(cadCylinderObj(n)) });
    await page.waitForFunction((k) => window.__conemap.loads > k && window.__conemap.state !== 'loading', loads, { timeout: LOAD_TIMEOUT });
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction((k) => window.__conemap.features === k, 2 * n, { timeout: 10_000 });
    let h = await hooks();
    const { solves, quadRuns } = h;
    await page.getByTestId('run').click();
    await page.waitForFunction((k) => window.__conemap.solves > k, solves, { timeout: SOLVE_TIMEOUT });
    await page.evaluate(() => window.__conemapTest.setQuadCount(1000));
    await page.waitForFunction((k) => window.__conemap.quadRuns > k && window.__conemap.quads?.target === 1000
      && document.body.dataset.quads !== 'running', quadRuns, { timeout: QUADS_TIMEOUT });
    h = await hooks();
    assert.ok(h.quads, h.quadsError ?? '');
    assert.ok(h.quads.solvedFaces > 10 * (4 * n - 4), `solved on ${h.quads.solvedFaces} faces`);
    assert.equal(h.quads.defects, 0);
    assert.equal(h.quads.uvCorners, 3 * (4 * n - 4), 'grid UVs on the input corners');
    assert.match(await page.getByTestId('quad-stats').innerText(), /Solved on\s+[\d,]+ triangles \(long edges split for quads\)/);
  });

  it('follows the creases of the fandisk marked with the Creases button, as conemap quads does', async () => {
    await page.goto(server.url);
    await page.waitForFunction(() => window.__conemap && window.__conemap.loads > 0 && window.__conemap.state === 'ready', null, { timeout: LOAD_TIMEOUT });
    await page.getByTestId('creases-button').click();
    await page.waitForFunction(() => window.__conemap.features === 693, null, { timeout: 10_000 });
    await page.getByTestId('run').click();
    await page.waitForFunction(() => window.__conemap.solves > 0, null, { timeout: SOLVE_TIMEOUT });
    await page.getByTestId('quad-mode').check();
    const h = await waitForQuads(0);
    const q = h.quads;
    assert.ok(q, h.quadsError ?? '');
    assert.equal(q.target, 3000);
    assert.equal(q.droppedCreases, 0, 'the creases are followed at 3 000 quads');
    assert.equal(q.defects, 0);
    assert.ok(q.sharpWithin > 0.99, `${q.sharpWithin} of the sharp edges near a quad edge`);
    assert.ok(q.distance < 0.01, `distance ${q.distance} of the diagonal`);
    // The JSON report says which features were creases.
    const [json] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-json').click()]);
    const report = JSON.parse(fs.readFileSync(await json.path(), 'utf8'));
    assert.equal(report.features.edges.length, 693);
    assert.deepEqual(report.features.creases, report.features.edges, 'every feature came from the Creases button');
    // With the quads shown: their figures, as `conemap quads --report` writes them.
    assert.equal(report.quads.target, 3000);
    assert.equal(report.quads.report.quads, q.quads);
    assert.equal(report.quads.dropped_crease_edges, 0);
    assert.equal(typeof report.quads.quantization.distortion_after, 'number');
    assert.equal(report.quads.obj, undefined, 'no meshes in the report');
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
