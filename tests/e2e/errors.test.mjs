// End-to-end test of solve errors that point at the mesh: a needle whose sharp
// rim encloses nearly 2 pi of curvature needs a cone of angle 0 at the apex.
// The solve refines around it and spreads the cone; with that refinement
// turned off (test hook) the cone placement's own failure shows. Sweeping the
// sharp slider, each Run succeeds or names the apex and the rim, which the 3D
// view highlights until the features change.
import assert from 'node:assert/strict';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { canvasRgba, closePage, openPage, output } from './harness.mjs';
import { needleObj } from '../node/wasm.mjs';

const LOAD_TIMEOUT = 90_000;
const SOLVE_TIMEOUT = 60_000;
const H = 30;

let ctx;
let page;
let consoleErrors = [];

const hooks = () => page.evaluate(() => window.__conemap);
const nextFrame = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

async function waitForLoad(afterCount) {
  await page.waitForFunction((n) => window.__conemap && window.__conemap.loads > n
    && window.__conemap.state !== 'loading', afterCount, { timeout: LOAD_TIMEOUT });
  return hooks();
}

async function runSolve() {
  const n = (await hooks()).solves;
  await page.getByTestId('run').click();
  await page.waitForFunction((k) => window.__conemap.solves > k, n, { timeout: SOLVE_TIMEOUT });
  return hooks();
}

/** Sets the sharp slider to `deg` (sharp edges on) and waits for `count` marked edges. */
async function sharp(deg, count) {
  await page.getByTestId('sharp-toggle').check();
  await page.getByTestId('sharp-angle').fill(String(deg));
  await page.waitForFunction((n) => window.__conemap.features === n, count, { timeout: 10_000 });
}

/** Pixels of the 3D view in the highlight colour (COLORS.problem, #b6ff00). */
async function highlightPixels() {
  await nextFrame();
  const { data: d } = await canvasRgba(page, 'canvas');
  let n = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i] > 140 && d[i] < 225 && d[i + 1] > 215 && d[i + 2] < 90) n++;
  return n;
}

/** True when vertex `v` projects inside the 3D view. */
async function inView(v) {
  return page.evaluate((vertex) => {
    const q = window.__conemapTest.projectVertex(vertex);
    const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    return q !== null && q.x > r.left && q.x < r.right && q.y > r.top && q.y < r.bottom;
  }, v);
}

describe('solve errors that point at the mesh', () => {
  let apex;
  let rim;

  before(async () => {
    ctx = await openPage();
    ({ page, consoleErrors } = ctx);
    await page.goto(ctx.server.url);
    await waitForLoad(0);
    const n = (await hooks()).loads;
    await page.getByTestId('file-input').setInputFiles({ name: 'needle.obj', mimeType: 'text/plain', buffer: Buffer.from(needleObj(H)) });
    const h = await waitForLoad(n);
    assert.equal(h.state, 'ready', h.lastError ?? '');
    assert.equal(h.stats.file, 'needle.obj');
    // The apex and the rim (hexagon sides) in the page's own ids.
    ({ apex, rim } = await page.evaluate((height) => {
      const t = window.__conemapTest;
      const at = (v) => t.vertexPosition(v);
      const vertices = [...Array(8).keys()];
      const top = vertices.find((v) => at(v)[2] === height);
      const centre = vertices.find((v) => at(v).every((x) => x === 0));
      const edges = [];
      for (let e = 0; t.edgeEnds(e); e++) if (!t.edgeEnds(e).some((v) => v === top || v === centre)) edges.push(e);
      return { apex: top, rim: edges };
    }, H));
    assert.equal(rim.length, 6);
  });

  after(() => closePage(ctx));

  it('solves the needle at 75° with the default refinement', async () => {
    await sharp(75, 6);
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.errorHighlight, null);
  });

  it('sweeps the sharp slider: each Run succeeds or points at the rim', async () => {
    await page.evaluate(() => window.__conemapTest.setMaxConeRefinements(0));
    // 30°: the sides and the rim (12 edges) are features; solves.
    await sharp(30, 12);
    let h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.errorHighlight, null);
    assert.equal(await highlightPixels(), 0, 'nothing is highlighted before an error');

    // 75°: the rim alone encloses the apex's curvature; fails with a location.
    await sharp(75, 6);
    h = await runSolve();
    assert.match(h.solveError, new RegExp(`the cone at vertex v${apex} would need index 4 \\(a cone angle of 0°, `));
    assert.match(h.solveError, /the 6 feature edges around it/);
    assert.deepEqual(h.solveErrorLocation.vertices, [apex]);
    assert.deepEqual([...h.solveErrorLocation.edges].sort((a, b) => a - b), rim);
    assert.deepEqual(h.errorHighlight, h.solveErrorLocation, 'the page highlights what the error names');
    assert.equal(h.features, 6, 'the feature marks are kept');
    assert.equal(await page.getByTestId('run').isEnabled(), true, 'Run stays enabled');
    const panel = page.getByTestId('solve-error');
    assert.ok(await panel.isVisible());
    assert.match(await panel.innerText(), /would need index 4/);
    assert.match(await page.getByTestId('error-location').innerText(), new RegExp(`Highlighted in the 3D view: vertex v${apex} \\(marker\\) and 6 edges\\.`));
    const lit = await highlightPixels();
    assert.ok(lit > 50, `only ${lit} highlighted pixels`);

    // "Show in 3D" brings the apex back into view after zooming away from it.
    const box = await page.getByTestId('canvas').boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    for (let i = 0; i < 12 && (await inView(apex)); i++) await page.mouse.wheel(0, -600);
    assert.equal(await inView(apex), false, 'zooming in did not leave the apex out of view');
    await page.getByTestId('show-problem').click();
    await nextFrame();
    assert.equal(await inView(apex), true, 'Show in 3D frames the apex');
    await page.screenshot({ path: path.join(output, 'solve-error-needle.png') });

    // A feature change clears the highlight (the message stays).
    await page.getByTestId('sharp-toggle').uncheck();
    await page.waitForFunction(() => window.__conemap.features === 0);
    h = await hooks();
    assert.equal(h.errorHighlight, null);
    assert.equal(await page.getByTestId('error-location').count(), 0);
    assert.equal(await highlightPixels(), 0, 'the highlight is gone');

    // 75° again fails again; 120° (no sharp edge) solves and clears the error.
    await sharp(75, 6);
    h = await runSolve();
    assert.deepEqual(h.errorHighlight?.vertices, [apex]);
    await sharp(120, 0);
    h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.equal(h.solveError, null);
    assert.equal(h.solveErrorLocation, null);
    assert.equal(await page.getByTestId('solve-error').isVisible(), false);
  });

  it('a new run and a new mesh clear the highlight', async () => {
    await sharp(75, 6);
    let h = await runSolve();
    assert.ok(h.errorHighlight, 'the needle fails at 75°');
    // Run again: the same error, highlighted once (not drawn over the last one).
    const lit = await highlightPixels();
    h = await runSolve();
    assert.deepEqual(h.errorHighlight?.vertices, [apex]);
    assert.equal(await page.getByTestId('error-location').count(), 1);
    assert.equal(await highlightPixels(), lit);
    const n = h.loads;
    await page.selectOption('[data-testid=samples]', 'fandisk.obj');
    h = await waitForLoad(n);
    assert.equal(h.errorHighlight, null);
    assert.equal(h.solveErrorLocation, null);
    assert.equal(await page.getByTestId('solve-error').isVisible(), false);
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
