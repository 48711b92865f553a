// End-to-end test of the result panel of the built page (dist/) in headless
// Chromium at 1400×900 via playwright-core: the actions on screen after Run,
// the headline figures with the rest folded, the status line, the checker
// density, the distortion legend's fixed scale comparing two runs, and the run
// history (switching shows and exports that run; a new mesh clears it).
// Run after `npm run build`.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { canvasRgba, closePage, openReadyPage, output } from './harness.mjs';

/** The window `openReadyPage` opens at. */
const WIDE = { width: 1400, height: 900 };

/** The page, its context and helpers (`openReadyPage`), and the console errors it logged. */
let ctx, page, hooks, waitForLoad, runSolve, nextFrame;
let consoleErrors = [];

/** Sets α_smooth to 10^`log10` and presses Run; waits until the solve ended and asserts it solved; returns the hooks. */
async function solveAt(log10) {
  await page.getByTestId('alpha').fill(String(log10));
  const h = await runSolve();
  assert.equal(h.state, 'solved', h.solveError ?? '');
  return h;
}

/** Clicks download button `testid`; returns the downloaded bytes. */
async function downloadOf(testid) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.getByTestId(testid).click()]);
  return fs.readFileSync(await d.path());
}

async function screenshot(name) {
  await page.screenshot({ path: path.join(output, `${name}.png`) });
}

/** Light/dark changes along 40 rows of the UV view (the checker's square edges met), after two frames. */
async function uvCheckerTransitions() {
  await nextFrame();
  const { width, height, data: d } = await canvasRgba(page, 'uv-canvas');
  let changes = 0;
  for (let k = 1; k <= 40; k++) {
    const y = Math.floor((height * k) / 41);
    let last = null;
    for (let x = 0; x < width; x++) {
      const i = 4 * (y * width + x);
      const light = 0.3 * d[i] + 0.59 * d[i + 1] + 0.11 * d[i + 2] > 140;
      if (last !== null && light !== last) changes++;
      last = light;
    }
  }
  return changes;
}

/** The box of test id `testid` lies inside the window. */
async function assertOnScreen(testid) {
  const box = await page.getByTestId(testid).boundingBox();
  assert.ok(box, `${testid} is not rendered`);
  assert.ok(box.x >= 0 && box.y >= 0 && box.x + box.width <= WIDE.width && box.y + box.height <= WIDE.height,
    `${testid} at ${JSON.stringify(box)} is outside the ${WIDE.width}×${WIDE.height} window`);
}

describe('result panel, distortion scale and run history', () => {
  /** Figures and exports of the first run (α = 1), compared after switching back to it. */
  let first;

  before(async () => {
    ({ ctx, hooks, waitForLoad, runSolve, nextFrame } = await openReadyPage());
    ({ page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('puts the surface switch and the downloads on screen after Run, the figures that matter first, the rest folded', async () => {
    const h = await solveAt(0);
    // Without scrolling the panel: the actions are in the window.
    assert.equal(await page.getByTestId('panel').evaluate((el) => el.scrollTop), 0);
    for (const id of ['surface-checker', 'surface-distortion', 'download-glb', 'download-obj', 'download-json']) await assertOnScreen(id);
    // The headline figures: cones, distortion, flipped faces, time.
    const summary = page.getByTestId('result-summary');
    assert.equal(await page.getByTestId('cone-count').innerText(), h.result.shownCones);
    assert.match(await summary.locator('dd[data-stat=distortion]').innerText(), /^\d\.\d{3}\b/);
    assert.match(await summary.locator('dd[data-stat=flipped]').innerText(), /^\d[\d,]*$/);
    assert.match(await summary.locator('dd[data-stat=time]').innerText(), /^\d+(\.\d)? m?s$/);
    assert.equal(await page.getByTestId('result-run').innerText(), 'Run 1 · α 1.00');
    // The timings and residuals are in the details section, collapsed.
    const details = page.getByTestId('result-details');
    assert.equal(await details.evaluate((el) => el.open), false, 'details collapsed by default');
    const timings = details.locator('dd[data-stat^=time-]');
    assert.ok(await timings.count() >= 5, 'the timings are in the details');
    assert.equal(await details.locator('dd[data-stat=seam-residual-angle-length]').count(), 1, 'the residuals are in the details');
    assert.equal(await timings.first().isVisible(), false);
    assert.equal(await summary.locator('dd[data-stat^=time-]').count(), 0, 'no stage timings among the headline figures');
    await details.locator('summary').click();
    assert.equal(await timings.first().isVisible(), true, 'details open on a click');
    await details.locator('summary').click();
    // The status line tells what happened last.
    const status = await page.getByTestId('status-text').innerText();
    assert.doesNotMatch(status, /Loaded/);
    assert.match(status, /^Solved in \d+(\.\d)? m?s \(α 1\.00\): \d+ cones, distortion \d\.\d{3}$/);
    await screenshot('results-1400x900');
    first = {
      cones: h.result.cones,
      shownCones: h.result.shownCones,
      distortion: await summary.locator('dd[data-stat=distortion]').innerText(),
      obj: await downloadOf('download-obj'),
    };
  });

  it('changes the checker density from its control', async () => {
    assert.equal(await page.getByTestId('surface-checker').isChecked(), true);
    const density = page.getByTestId('checker-density');
    assert.equal(await density.isVisible(), true, 'the density control shows with the checker');
    assert.equal((await hooks()).checkerSquares, 20);
    await density.selectOption('10');
    assert.equal((await hooks()).checkerSquares, 10);
    const coarse = await uvCheckerTransitions();
    await density.selectOption('40');
    assert.equal((await hooks()).checkerSquares, 40);
    const fine = await uvCheckerTransitions();
    assert.ok(fine > 1.8 * coarse, `40 squares: ${fine} light/dark changes, 10 squares: ${coarse}`);
    await density.selectOption('20');
    await page.getByTestId('surface-distortion').check();
    assert.equal(await density.isVisible(), false, 'the density control only with the checker');
  });

  it('names the measure, and under a fixed scale two runs with different α colour differently', async () => {
    const legend = page.getByTestId('distortion-legend');
    assert.equal(await legend.isVisible(), true);
    assert.match(await legend.innerText(), /Isometric distortion per face/);
    assert.match(await legend.innerText(), /eq\. 19/);
    assert.match(await legend.innerText(), /≥ max/);
    const auto = (await hooks()).distortion;
    assert.equal(auto.fixed, false);
    assert.equal(auto.histogram.length, 40);
    assert.equal(auto.histogram.reduce((a, b) => a + b, 0), 12946, 'every face in the histogram');
    assert.ok(auto.histogram[39] > 0 && auto.histogram[39] < 0.05 * 12946, `the last bar holds the faces ≥ the 99th percentile: ${auto.histogram[39]}`);
    // Fixed: the value starts at the auto scale (two digits) and can be set.
    await page.getByTestId('distortion-scale-mode').selectOption('fixed');
    const start = Number(await page.getByTestId('distortion-scale-value').inputValue());
    assert.ok(Math.abs(start - auto.scale) <= 0.05 * auto.scale, `fixed starts at ${start}, auto was ${auto.scale}`);
    await page.getByTestId('distortion-scale-value').fill('0.5');
    await page.getByTestId('distortion-scale-value').dispatchEvent('change');
    await page.waitForFunction(() => window.__conemap.distortion?.fixed && window.__conemap.distortion.scale === 0.5);
    assert.equal(await page.getByTestId('distortion-max').innerText(), '0.500');
    const a = (await hooks()).distortion;
    await screenshot('results-distortion-fixed-alpha1');
    // A second run at α = 0.001 (more cones, less distortion) keeps the distortion view and the fixed scale.
    const h2 = await solveAt(-3);
    assert.equal(await page.getByTestId('surface-distortion').isChecked(), true, 'the distortion view stays on');
    const b = h2.distortion;
    assert.equal(b.fixed, true);
    assert.equal(b.scale, 0.5);
    const luminance = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    assert.ok(Math.abs(luminance(a.meanColor) - luminance(b.meanColor)) > 0.01,
      `mean colours α = 1 ${a.meanColor}, α = 0.001 ${b.meanColor}`);
    assert.notDeepEqual(a.histogram, b.histogram);
    await screenshot('results-distortion-fixed-alpha0.001');
    // Back to auto: each run at its own 99th percentile again.
    await page.getByTestId('distortion-scale-mode').selectOption('auto');
    await page.waitForFunction(() => window.__conemap.distortion && !window.__conemap.distortion.fixed);
    assert.notEqual((await hooks()).distortion.scale, 0.5);
  });

  it('keeps both runs; a click on the first shows its α, figures, views and exports again', async () => {
    const second = await hooks();
    const rows = page.getByTestId('run-history-rows').locator('tr');
    assert.equal(await rows.count(), 2);
    assert.equal(await page.getByTestId('run-history').isVisible(), true);
    assert.deepEqual(await rows.evaluateAll((trs) => trs.map((tr) => tr.dataset.run)), ['2', '1'], 'newest first');
    assert.match(await rows.nth(1).innerText(), /#1\s+1\.00\s/);
    assert.match(await rows.nth(0).innerText(), /#2\s+1\.0e-3\s/);
    assert.match(await rows.nth(0).getAttribute('class'), /current/);
    const secondObj = await downloadOf('download-obj');
    await page.screenshot({ path: path.join(output, 'results-history.png') });
    await rows.nth(1).click();
    await page.waitForFunction(() => window.__conemap.result !== null && document.querySelector('[data-testid=result-run]').textContent.startsWith('Run 1'));
    const h = await hooks();
    assert.equal(await page.getByTestId('result-run').innerText(), 'Run 1 · α 1.00');
    assert.equal(h.result.cones, first.cones);
    assert.equal(await page.getByTestId('cone-count').innerText(), first.shownCones);
    assert.equal(await page.getByTestId('result-summary').locator('dd[data-stat=distortion]').innerText(), first.distortion);
    assert.match(await rows.nth(1).getAttribute('class'), /current/);
    assert.equal(await page.getByTestId('uv-view').isVisible(), true, 'the UV layout of run 1');
    assert.equal(h.state, 'solved');
    assert.match(await page.getByTestId('status-text').innerText(), /^Showing run 1 of 2 \(α 1\.00\)/);
    // The download exports that run, not the newest.
    const obj = await downloadOf('download-obj');
    assert.ok(obj.equals(first.obj), 'the .obj of run 1');
    assert.ok(!obj.equals(secondObj), 'not the .obj of run 2');
    const report = JSON.parse((await downloadOf('download-json')).toString('utf8'));
    assert.equal(report.settings.alpha_smooth, 1);
    assert.equal(report.result.cones.length, first.cones);
    // And back to the newest.
    await rows.nth(0).click();
    await page.waitForFunction(() => window.__conemap.result !== null && document.querySelector('[data-testid=result-run]').textContent.startsWith('Run 2'));
    assert.equal((await hooks()).result.cones, second.result.cones);
  });

  it('looks right at 800×600 and 390×844', async () => {
    await page.getByTestId('result-details').locator('summary').click();
    for (const [w, hgt] of [[800, 600], [390, 844]]) {
      await page.setViewportSize({ width: w, height: hgt });
      await page.getByTestId('results').scrollIntoViewIfNeeded();
      await screenshot(`results-${w}x${hgt}`);
      const box = await page.getByTestId('download-glb').boundingBox();
      assert.ok(box && box.width > 20 && box.x + box.width <= w, `.glb button at ${JSON.stringify(box)} in ${w}px`);
    }
    await page.setViewportSize(WIDE);
    await page.getByTestId('result-details').locator('summary').click();
  });

  it('clears the history when a new mesh opens', async () => {
    const rows = page.getByTestId('run-history-rows').locator('tr');
    assert.equal(await rows.count(), 2, 'two runs before');
    const n = (await hooks()).loads;
    const obj = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n';
    await page.getByTestId('file-input').setInputFiles({ name: 'tetra.obj', mimeType: 'text/plain', buffer: Buffer.from(obj) });
    assert.equal((await waitForLoad(n)).state, 'ready');
    assert.equal(await rows.count(), 0);
    assert.equal(await page.getByTestId('run-history').isVisible(), false);
    assert.equal(await page.getByTestId('results').isVisible(), false);
    assert.match(await page.getByTestId('status-text').innerText(), /^Loaded tetra\.obj/);
    assert.deepEqual(consoleErrors, []);
  });
});
