// End-to-end test of the feature editor and the solve controls of the built page
// (dist/) in headless Chromium via playwright-core. Run after `npm run build`.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { closePage, openPage, output, root } from './harness.mjs';
import validator from 'gltf-validator';
import { checkUv, edgeAlignment, parseObj } from '../node/uvcheck.mjs';

const LOAD_TIMEOUT = 90_000;
const SOLVE_TIMEOUT = 120_000;

let ctx;
let server;
let page;
let consoleErrors = [];

const hooks = () => page.evaluate(() => window.__conemap);
const featureCountText = async () => Number((await page.getByTestId('feature-count').innerText()).replace(/,/g, ''));

async function waitForLoad(afterCount) {
  await page.waitForFunction((n) => window.__conemap && window.__conemap.loads > n
    && window.__conemap.state !== 'loading', afterCount, { timeout: LOAD_TIMEOUT });
  return hooks();
}

async function loadSample(file) {
  const n = (await hooks()).loads;
  await page.selectOption('[data-testid=samples]', file);
  const h = await waitForLoad(n);
  assert.equal(h.state, 'ready', h.lastError ?? '');
  return h;
}

/** Presses Run and waits until the solve finished (solved, or failed back to ready). */
async function runSolve() {
  const n = (await hooks()).solves;
  await page.getByTestId('run').click();
  await page.waitForFunction((k) => window.__conemap.solves > k, n, { timeout: SOLVE_TIMEOUT });
  return hooks();
}

async function screenshot(name) {
  await page.screenshot({ path: path.join(output, `${name}.png`) });
}

/** Clicks the projected midpoint of a visible edge; returns its id. */
async function clickVisibleEdge(modifiers = []) {
  const edge = await page.evaluate(() => window.__conemapTest.visibleEdge());
  assert.ok(edge >= 0, 'no visible interior edge found');
  const p = await page.evaluate((e) => window.__conemapTest.projectEdge(e), edge);
  for (const m of modifiers) await page.keyboard.down(m);
  await page.mouse.click(p.x, p.y);
  for (const m of modifiers) await page.keyboard.up(m);
  return { edge, p };
}

async function sampleOptions() {
  return page.locator('[data-testid=samples] option').evaluateAll((els) => els.map((e) => e.value));
}

describe('feature editing and solving', () => {
  before(async () => {
    ctx = await openPage();
    ({ server, page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('opens with the fandisk and no features', async () => {
    await page.goto(server.url);
    const h = await waitForLoad(0);
    assert.equal(h.state, 'ready', h.lastError ?? '');
    assert.equal(h.stats.faces, 12946);
    assert.equal(h.features, 0);
    assert.equal(await featureCountText(), 0);
    assert.equal(await page.getByTestId('run').isEnabled(), true);
    assert.equal(await page.getByTestId('cancel').isEnabled(), false);
  });

  it('toggles an edge clicked at its projected position, with undo and redo', async () => {
    const { edge, p } = await clickVisibleEdge();
    assert.equal(await page.evaluate(({ x, y }) => window.__conemapTest.edgeAt(x, y), p), edge);
    await page.waitForFunction(() => window.__conemap.features === 1);
    assert.equal(await featureCountText(), 1);
    await screenshot('features-one-edge');
    await page.keyboard.press('Control+z');
    assert.equal((await hooks()).features, 0);
    await page.keyboard.press('Control+Shift+z');
    assert.equal((await hooks()).features, 1);
    await page.getByTestId('undo').click();
    assert.equal(await featureCountText(), 0);
    await page.getByTestId('redo').click();
    assert.equal(await featureCountText(), 1);
    // Clicking the same edge again removes it.
    await page.mouse.click(p.x, p.y);
    assert.equal(await featureCountText(), 0);
  });

  it('marks the shortest edge path between two Shift-clicked vertices', async () => {
    const pts = await page.evaluate(() => {
      const t = window.__conemapTest;
      const rect = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      // Two points on the mesh, well apart: scan a grid for positions that hit it.
      const hits = [];
      for (let i = 1; i < 8 && hits.length < 2; i++) {
        const x = rect.left + rect.width * (0.3 + 0.06 * i);
        const y = rect.top + rect.height * (0.35 + 0.04 * i);
        if (t.pick(x, y) && (hits.length === 0 || Math.hypot(x - hits[0].x, y - hits[0].y) > 120)) hits.push({ x, y });
      }
      return hits;
    });
    assert.equal(pts.length, 2, 'no two points on the mesh');
    for (const q of pts) {
      await page.keyboard.down('Shift');
      await page.mouse.click(q.x, q.y);
      await page.keyboard.up('Shift');
    }
    const n = (await hooks()).features;
    assert.ok(n >= 3, `path marked only ${n} edges`);
    assert.equal(await featureCountText(), n);
    await screenshot('features-path');
    await page.getByTestId('clear-features').click();
    assert.equal(await featureCountText(), 0);
  });

  it('marks sharp edges from the dihedral-angle slider, editable afterwards', async () => {
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction(() => window.__conemap.features > 300, null, { timeout: 10_000 });
    const sharp = (await hooks()).features;
    assert.equal(await page.getByTestId('sharp-value').innerText(), '60°');
    const { edge } = await clickVisibleEdge();
    assert.ok(edge >= 0);
    assert.equal((await hooks()).features, sharp + 1);
    await page.keyboard.press('Control+z');
    assert.equal((await hooks()).features, sharp);
    await screenshot('features-sharp-60');
    // The detection's counts, and the curve-length filter: a minimum longer
    // than every curve drops them all, 0 brings them back.
    const stats = await page.getByTestId('sharp-stats').innerText();
    assert.match(stats, new RegExp(`^${sharp} sharp edges: \\d+ curves? \\(${sharp} edges\\) kept, 0 fragments dropped$`));
    await page.getByTestId('sharp-min-edges').fill('100000');
    await page.getByTestId('sharp-min-edges').dispatchEvent('change');
    await page.waitForFunction(() => window.__conemap.features === 0, null, { timeout: 10_000 });
    assert.match(await page.getByTestId('sharp-stats').innerText(), /: 0 curves \(0 edges\) kept, [1-9]\d* fragments? dropped$/);
    await page.getByTestId('sharp-min-edges').fill('0');
    await page.getByTestId('sharp-min-edges').dispatchEvent('change');
    await page.waitForFunction((n) => window.__conemap.features === n, sharp, { timeout: 10_000 });
  });

  it('runs cone placement from the α slider and shows a consistent result', async () => {
    await page.getByTestId('alpha').fill('0'); // 10^0 = 1
    assert.equal(await page.getByTestId('alpha-value').innerText(), '1.00');
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    const r = h.result;
    assert.ok(r.cones > 0, 'no cones');
    assert.equal(r.featureEdges, h.features);
    const shown = await page.getByTestId('cone-count').innerText();
    assert.equal(shown, r.shownCones);
    assert.equal(Number(shown.split(' ')[0].replace(/,/g, '')), r.cones);
    assert.equal(r.plus + r.minus <= r.cones, true);
    assert.equal(r.sumConeK + r.sumCornerK, 4 * r.eulerCharacteristic, 'Σk over cones and corners = 4χ');
    assert.equal(await page.getByTestId('solve-error').isVisible(), false);
    assert.equal(await page.getByTestId('results').isVisible(), true);
    await page.getByTestId('results').scrollIntoViewIfNeeded();
    await screenshot('solved-fandisk-cones');
    // The JSON report downloads with the settings, the features and the cones.
    const [download] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-json').click()]);
    const report = JSON.parse(fs.readFileSync(await download.path(), 'utf8'));
    assert.equal(report.file, 'fandisk.obj');
    assert.equal(report.settings.alpha_smooth, 1);
    assert.equal(report.features.edges.length, h.features);
    assert.deepEqual(report.features.creases, [], 'the slider marks no creases');
    assert.equal(report.quads, undefined, 'no quads shown');
    assert.equal(report.result.cones.length, r.cones);
    assert.equal(r.uv, true, 'the solve gives UVs');
    // With the parametrization: the .glb and .obj exports download.
    const [glb] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-glb').click()]);
    const bytes = fs.readFileSync(await glb.path());
    assert.equal(bytes.subarray(0, 4).toString('latin1'), 'glTF');
    assert.match(glb.suggestedFilename(), /^fandisk-uv\.glb$/);
    const validation = await validator.validateBytes(new Uint8Array(bytes), { uri: 'fandisk-uv.glb', maxIssues: 0 });
    assert.equal(validation.issues.numErrors, 0, JSON.stringify(validation.issues.messages.slice(0, 3)));
    const [obj] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-obj').click()]);
    const text = fs.readFileSync(await obj.path(), 'utf8');
    assert.match(text, /^vt /m);
    // Re-import the download and check it from the file alone: seamless, no
    // fold-overs, and every marked feature edge on a u or v isoline.
    const parsed = parseObj(text);
    const check = checkUv(parsed);
    assert.equal(check.flipped, 0, 'flipped triangles in the download');
    assert.ok(check.maxSeamAngle < 1e-6 && check.maxSeamLength < 1e-6, `seams: ${JSON.stringify(check)}`);
    const aligned = edgeAlignment(parsed, report.features.positions, 1e-4);
    assert.equal(aligned.missing, 0, 'every marked edge is in the download');
    assert.ok(aligned.worst < 1e-6, `a marked edge is ${aligned.worst} rad off the nearest axis`);
    assert.ok(report.result.metrics && typeof report.result.metrics.distortion === 'number', 'metrics in the report');
  });

  it('shows UVs: checkerboard, distortion heat map with histogram, UV layout with hover sync', async () => {
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.result.uv, true);
    assert.ok(h.result.seams > 0, 'no seams');
    assert.equal(await page.getByTestId('uv-view').isVisible(), true);
    assert.equal(await page.getByTestId('surface-checker').isChecked(), true);
    await page.getByTestId('results').scrollIntoViewIfNeeded();
    await screenshot('uv-checker');
    await page.getByTestId('surface-distortion').check();
    assert.equal(await page.getByTestId('histogram').isVisible(), true);
    // Hover sync: the face under the pointer in 3D is highlighted in the UV view.
    const q = await page.evaluate(() => {
      const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      return { x: r.left + r.width * 0.5, y: r.top + r.height * 0.45 };
    });
    await page.mouse.move(q.x, q.y);
    await page.mouse.move(q.x + 2, q.y + 1);
    await page.waitForFunction(() => window.__conemap.hoverFace !== null, null, { timeout: 5_000 });
    const face3d = (await hooks()).hoverFace;
    // …and the other way round: hovering the UV layout highlights the face in 3D.
    const uvBox = await page.getByTestId('uv-canvas').boundingBox();
    await page.mouse.move(uvBox.x + uvBox.width / 2, uvBox.y + uvBox.height / 2);
    await page.mouse.move(uvBox.x + uvBox.width / 2 + 1, uvBox.y + uvBox.height / 2 + 1);
    await page.waitForFunction((f) => window.__conemap.hoverFace !== null && window.__conemap.hoverFace !== f, face3d, { timeout: 5_000 });
    await page.getByTestId('results').scrollIntoViewIfNeeded();
    await screenshot('uv-distortion');
    const uvPixels = await page.evaluate(() => {
      const src = document.querySelector('[data-testid=uv-canvas]');
      const c = document.createElement('canvas');
      c.width = c.height = 64;
      const g = c.getContext('2d');
      g.drawImage(src, 0, 0, 64, 64);
      const d = g.getImageData(0, 0, 64, 64).data;
      const colours = new Set();
      for (let i = 0; i < d.length; i += 4) colours.add((d[i] >> 4) << 8 | (d[i + 1] >> 4) << 4 | d[i + 2] >> 4);
      return colours.size;
    });
    assert.ok(uvPixels >= 8, `UV view looks blank (${uvPixels} colours)`);
    await page.locator('input[name=surface][value=shaded]').check();
  });

  it('places some components in a helper worker with the same result', async () => {
    const alone = (await runSolve()).result;
    assert.equal(alone.helperComponents, 0, 'the fandisk is below the helper threshold');
    assert.ok(alone.cones > 0);
    await page.evaluate(() => window.__conemapTest.setHelper(0, true));
    try {
      const h = await runSolve();
      assert.equal(h.state, 'solved', h.solveError ?? '');
      assert.ok(h.result.helperComponents > 0, 'the helper placed no component');
      for (const key of ['cones', 'plus', 'minus', 'sumConeK', 'sumCornerK', 'rounds', 'seams', 'energy']) {
        assert.equal(h.result[key], alone[key], key);
      }
      // Cancelled while both workers run: no error shows up (then or late), and the next solve works.
      const before = await hooks();
      await page.getByTestId('run').click();
      await page.waitForFunction(() => window.__conemap.state === 'solving');
      await page.waitForTimeout(150);
      await page.getByTestId('cancel').click();
      await page.waitForFunction((n) => window.__conemap.solves > n, before.solves, { timeout: 10_000 });
      await page.waitForTimeout(1_000);
      assert.equal(await page.getByTestId('solve-error').isVisible(), false);
      assert.equal((await hooks()).solveError, null);
      const again = await runSolve();
      assert.equal(again.state, 'solved', again.solveError ?? '');
      assert.equal(again.result.energy, alone.energy);
    } finally {
      await page.evaluate(() => window.__conemapTest.setHelper(50_000, false));
    }
  });

  it('cancels a running solve at once and solves again afterwards', async () => {
    const options = await sampleOptions();
    // A large sample: the solve must still be running after 400 ms.
    const big = 'bff-bunny.obj';
    assert.ok(options.includes(big), `${big} not among the samples (../shared/meshes absent at build time?)`);
    await loadSample(big);
    assert.equal((await hooks()).result, null, 'a new mesh clears the result');
    await page.getByTestId('alpha').fill('-2');
    const before = await hooks();
    await page.getByTestId('run').click();
    await page.waitForFunction(() => window.__conemap.state === 'solving');
    await page.getByTestId('solve-stage').waitFor({ state: 'visible' });
    await page.waitForTimeout(400); // let it get into the solver
    await screenshot(`solving-${big.replace(/\.obj$/, '')}`);
    const t0 = Date.now();
    await page.getByTestId('cancel').click();
    await page.waitForFunction((n) => window.__conemap.solves > n, before.solves, { timeout: 5_000 });
    const cancelled = await hooks();
    assert.ok(Date.now() - t0 < 5_000, 'cancel took too long');
    assert.equal(cancelled.state, 'ready');
    assert.equal(cancelled.result, null);
    assert.equal(await page.getByTestId('solve-error').isVisible(), false);
    assert.match(await page.getByTestId('solve-status').innerText(), /cancelled/i);
    assert.equal(await page.getByTestId('run').isEnabled(), true);
    // The page is responsive right away.
    const ms = await page.evaluate(() => new Promise((res) => { const t = performance.now(); requestAnimationFrame(() => res(performance.now() - t)); }));
    assert.ok(ms < 1000, `frame took ${ms} ms after cancel`);
    // The new worker re-opened the mesh: a solve on it works (α = 1: quicker).
    await page.getByTestId('alpha').fill('0');
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.stats.file, big);
    assert.ok(h.result.cones > 0);
    assert.equal(h.result.sumConeK + h.result.sumCornerK, 4 * h.result.eulerCharacteristic);
    await page.getByTestId('results').scrollIntoViewIfNeeded();
    await screenshot(`solved-${big.replace(/\.obj$/, '')}`);
  });

  it('turns Run off, saying why, on a mesh that cannot be solved, and on again for the next', async () => {
    const options = await sampleOptions();
    assert.ok(options.includes('beetle.obj'), 'beetle.obj not among the samples');
    await loadSample('beetle.obj');
    const run = page.getByTestId('run');
    assert.equal(await run.isEnabled(), false, 'Run is off on a non-manifold mesh');
    const note = page.getByTestId('solve-note');
    assert.ok(await note.isVisible());
    assert.match(await note.innerText(), /^Run is off: this mesh cannot be parametrized \(\d+ edges with more than two faces/);
    assert.equal(await run.getAttribute('title'), await note.innerText(), 'the reason is the button\'s tooltip too');
    assert.equal(await run.getAttribute('aria-describedby'), 'solve-note');
    await screenshot('solve-blocked-beetle');
    await loadSample('fandisk.obj');
    assert.equal(await run.isEnabled(), true);
    assert.equal(await note.isVisible(), false);
  });

  it('leaves the boundary free with the toggle: woody (flat) gets no corners and no cones', async () => {
    assert.ok((await sampleOptions()).includes('woody.obj'), 'woody.obj among the samples (../shared/meshes at build time)');
    await loadSample('woody.obj');
    const toggle = page.getByTestId('free-boundary');
    await toggle.uncheck();
    const aligned = (await runSolve()).result;
    assert.ok(aligned.boundaryCorners > 0, 'aligned: corners');
    await toggle.check();
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.result.boundaryCorners, 0);
    assert.equal(h.result.cones, 0, 'a flat disk with a free boundary needs no cone');
    assert.equal(h.result.uv, true);
    await toggle.uncheck();
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
