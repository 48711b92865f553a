// Automated accessibility check of the whole page with axe-core, run in the
// page: after load, with a mesh that cannot be solved (the problems list),
// after a solve (the results), and with the run history, the open details,
// a fixed distortion scale and the checker density shown. No violation of
// contrast, labels, names of buttons, progress bars and canvases, or of the
// rest of axe's WCAG A/AA rules; and the focus ring of the file input shows
// on its button.
import assert from 'node:assert/strict';
import path from 'node:path';
import { createRequire } from 'node:module';
import { after, before, describe, it } from 'node:test';
import { closePage, openReadyPage, output } from './harness.mjs';

const axeSource = createRequire(import.meta.url).resolve('axe-core/axe.min.js');

/** The page, its context and helpers (`openReadyPage`), and the console errors it logged. */
let ctx, page, hooks, loadSample, runSolve;
let consoleErrors = [];

/** The axe violations of the page as it is (WCAG 2.x A and AA), one line each. */
async function violations() {
  if (!(await page.evaluate(() => 'axe' in window))) await page.addScriptTag({ path: axeSource });
  const result = await page.evaluate(() => window.axe.run(document, {
    runOnly: { type: 'tag', values: ['wcag2a', 'wcag2aa', 'wcag21a', 'wcag21aa', 'best-practice'] },
    resultTypes: ['violations'],
  }));
  return result.violations.map((v) => `${v.id}: ${v.nodes.slice(0, 3).map((n) => n.target.join(' ')).join(' | ')}`);
}

describe('accessibility (axe-core)', () => {
  before(async () => {
    ({ ctx, hooks, loadSample, runSolve } = await openReadyPage());
    ({ page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('has no violations after load', async () => {
    assert.deepEqual(await violations(), []);
  });

  it('shows the focus ring of the file input on its button', async () => {
    await page.getByTestId('file-input').focus();
    await page.keyboard.press('Shift+Tab');
    await page.keyboard.press('Tab');
    const outline = await page.locator('label[for=file-input]').evaluate((el) => getComputedStyle(el).outlineStyle);
    assert.equal(outline, 'solid');
  });

  it('has no violations with a mesh that cannot be solved (problems listed, Run off)', async () => {
    await loadSample('beetle.obj');
    assert.equal(await page.getByTestId('run').isEnabled(), false);
    assert.deepEqual(await violations(), []);
  });

  it('has no violations after a solve', async () => {
    await loadSample('fandisk.obj');
    assert.equal((await runSolve()).state, 'solved');
    await page.getByTestId('surface-distortion').check();
    assert.deepEqual(await violations(), []);
    // The jargon of the result has plain words as tooltips.
    const tips = await page.getByTestId('result-stats').locator('dt').evaluateAll((dts) => Object.fromEntries(dts.map((d) => [d.textContent, d.title])));
    for (const term of ['Energy', 'φ rms', 'Σk (cones + corners)', 'Faces < 0.2 / < 0.3', 'Seam residual (angle / length)', 'Seam length']) {
      assert.ok(tips[term]?.length > 20, `no plain-words tooltip for ${term}`);
    }
    assert.match(tips['Seam length'], /length units/);
    assert.match(await page.getByTestId('cone-legend').locator('span[title]').first().getAttribute('title'), /cone of index k = \+1/);
    await page.screenshot({ path: path.join(output, 'a11y-solved.png') });
  });

  it('has no violations with the run history, the details, a fixed distortion scale and the checker density shown', async () => {
    await page.getByTestId('alpha').fill('0');
    assert.equal((await runSolve()).state, 'solved');
    assert.equal(await page.getByTestId('run-history').isVisible(), true, 'two runs: the history table is shown');
    await page.getByTestId('result-details').locator('summary').click();
    await page.getByTestId('surface-distortion').check();
    await page.getByTestId('distortion-scale-mode').selectOption('fixed');
    assert.equal(await page.getByTestId('distortion-scale-value').isEnabled(), true);
    assert.deepEqual(await violations(), []);
    await page.getByTestId('surface-checker').check();
    assert.equal(await page.getByTestId('checker-density').isVisible(), true);
    assert.deepEqual(await violations(), []);
    // The headline figures explain their jargon as the tables do.
    assert.match(await page.getByTestId('result-summary').locator('dt', { hasText: 'Flipped faces' }).getAttribute('title'), /turned over/);
    await page.screenshot({ path: path.join(output, 'a11y-history.png') });
    await page.getByTestId('result-details').locator('summary').click();
  });

  it('fits the screen after a solve at 800×600 and 390×844: nothing below it is cut off', async () => {
    for (const [width, height] of [[800, 600], [390, 844]]) {
      await page.setViewportSize({ width, height });
      await page.waitForTimeout(200);
      const fit = await page.evaluate(() => ({ page: document.documentElement.scrollHeight, wide: document.documentElement.scrollWidth, screen: innerHeight, across: innerWidth }));
      assert.ok(fit.page <= fit.screen && fit.wide <= fit.across, `${width}×${height}: the page is ${fit.wide}×${fit.page}`);
    }
    await page.setViewportSize({ width: 1400, height: 900 });
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
