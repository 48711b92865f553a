// End-to-end test of the UV pane of the built page (dist/) in headless
// Chromium via playwright-core: the split between the 3D view and the UV
// layout (no overlap at 800×600, the divider dragged and moved with the
// keyboard), the [0, 1]² frame, the overlap figures checked against coverage
// recomputed here from the downloaded OBJ, chart selection in both views
// checked against charts recomputed from the OBJ, the hover marker, and
// screenshots at 1400×900, 800×600 and 390×844. Run after `npm run build`.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { closePage, openPage, output } from './harness.mjs';
import { parseObj } from '../node/uvcheck.mjs';

/** Longest waits (ms) for a load and for a solve. */
const TIMEOUT = { load: 90_000, solve: 120_000 };

/** The server, the browser and the page with its console errors (see `openPage`); `page` for short. */
let ctx;
let page;

const hooks = () => page.evaluate(() => window.__conemap);

async function loadSample(file) {
  const n = (await hooks()).loads;
  await page.selectOption('[data-testid=samples]', file);
  await page.waitForFunction((k) => window.__conemap.loads > k && window.__conemap.state !== 'loading', n, { timeout: TIMEOUT.load });
  const h = await hooks();
  assert.equal(h.state, 'ready', h.lastError ?? '');
  return h;
}

/** Presses Run and waits until the solve and its UV layout are on the page. */
async function runSolve() {
  const n = (await hooks()).solves;
  await page.getByTestId('run').click();
  await page.waitForFunction((k) => window.__conemap.solves > k, n, { timeout: TIMEOUT.solve });
  const h = await hooks();
  assert.equal(h.state, 'solved', h.solveError ?? '');
  await page.waitForFunction(() => window.__conemap.uvView !== null, null, { timeout: 10_000 });
  return hooks();
}

/** The downloaded OBJ of the result shown, parsed. */
async function downloadObj() {
  const [obj] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-obj').click()]);
  return parseObj(fs.readFileSync(await obj.path(), 'utf8'));
}

/**
 * Coverage of the OBJ's UV triangles sampled at n × n points over their
 * bounds, independently of the page's rasterizer: how many triangles hold
 * each point strictly inside (barycentric coordinates > 1e-7, so that points
 * on shared edges count once at most), via a bucket grid.
 */
function sampledOverlap({ vt, faces }, n = 400) {
  const tris = faces.map((f) => f.map((c) => vt[c[1]]));
  let [minU, minV, maxU, maxV] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const t of tris) for (const [u, v] of t) { minU = Math.min(minU, u); maxU = Math.max(maxU, u); minV = Math.min(minV, v); maxV = Math.max(maxV, v); }
  const span = Math.max(maxU - minU, maxV - minV);
  const step = span / n;
  const buckets = new Map();
  tris.forEach((t, i) => {
    const us = t.map((p) => p[0]);
    const vs = t.map((p) => p[1]);
    for (let a = Math.floor((Math.min(...us) - minU) / step); a <= Math.floor((Math.max(...us) - minU) / step); a++) {
      for (let b = Math.floor((Math.min(...vs) - minV) / step); b <= Math.floor((Math.max(...vs) - minV) / step); b++) {
        const k = a * (n + 1) + b;
        if (!buckets.has(k)) buckets.set(k, []);
        buckets.get(k).push(i);
      }
    }
  });
  let covered = 0;
  let stacked = 0;
  let maxDepth = 0;
  for (let a = 0; a < n; a++) {
    for (let b = 0; b < n; b++) {
      const u = minU + (a + 0.5) * step;
      const v = minV + (b + 0.5) * step;
      let depth = 0;
      for (const i of buckets.get(a * (n + 1) + b) ?? []) {
        const [[x0, y0], [x1, y1], [x2, y2]] = tris[i];
        const d = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
        if (d === 0) continue;
        const l1 = ((u - x0) * (y2 - y0) - (x2 - x0) * (v - y0)) / d;
        const l2 = ((x1 - x0) * (v - y0) - (u - x0) * (y1 - y0)) / d;
        if (l1 > 1e-7 && l2 > 1e-7 && 1 - l1 - l2 > 1e-7) depth++;
      }
      if (depth > 0) covered++;
      if (depth > 1) stacked++;
      maxDepth = Math.max(maxDepth, depth);
    }
  }
  return { share: covered ? stacked / covered : 0, maxDepth };
}

/** The charts of the OBJ (faces joined across an edge whose two ends have the same UVs on both sides): their count and the chart size of each face. */
function objChartSizes({ v, vt, faces }) {
  const parent = faces.map((_, i) => i);
  const find = (i) => (parent[i] === i ? i : (parent[i] = find(parent[i])));
  const pos = (i) => v[i].join(',');
  const sides = new Map();
  faces.forEach((f, i) => {
    for (let k = 0; k < 3; k++) {
      const [a, b] = [f[k], f[(k + 1) % 3]];
      const [pa, pb] = [pos(a[0]), pos(b[0])];
      const key = pa < pb ? `${pa}|${pb}` : `${pb}|${pa}`;
      const uvs = (pa < pb ? [vt[a[1]], vt[b[1]]] : [vt[b[1]], vt[a[1]]]).flat().join(',');
      const other = sides.get(key);
      if (!other) sides.set(key, { face: i, uvs });
      else if (other.uvs === uvs) parent[find(i)] = find(other.face);
    }
  });
  const size = new Map();
  faces.forEach((_, i) => size.set(find(i), (size.get(find(i)) ?? 0) + 1));
  return { count: size.size, sizes: faces.map((_, i) => size.get(find(i))) };
}

/** Clicks the UV view at the centroid of face `f`; returns the chart hook after it. */
async function clickUvFace(f) {
  const p = await page.evaluate((face) => window.__conemapTest.projectUvFace(face), f);
  await page.mouse.click(p.x, p.y);
  return (await hooks()).chart;
}

/** The bounding box of test id `id`. */
const box = (id) => page.getByTestId(id).boundingBox();

const disjoint = (a, b) => a.x + a.width <= b.x + 0.5 || b.x + b.width <= a.x + 0.5 || a.y + a.height <= b.y + 0.5 || b.y + b.height <= a.y + 0.5;

async function screenshot(name) {
  await page.screenshot({ path: path.join(output, `${name}.png`) });
}

/** The "UV overlap" row of the result's figures as a user reads it: in "All figures and timings", opened for it and folded again. */
async function overlapFigure() {
  const details = page.getByTestId('result-details');
  await details.locator('summary').click();
  assert.equal(await details.evaluate((el) => el.open), true);
  const text = await details.locator('[data-testid=result-stats] dd[data-stat=uv-overlap]').innerText();
  await details.locator('summary').click();
  return text;
}

describe('UV pane', () => {
  before(async () => {
    ctx = await openPage();
    page = ctx.page;
    await page.setViewportSize({ width: 800, height: 600 });
    await page.goto(ctx.server.url);
    await page.waitForFunction(() => window.__conemap?.loads > 0 && window.__conemap.state === 'ready', null, { timeout: TIMEOUT.load });
  });

  after(() => closePage(ctx));

  it('shows the UV layout beside the 3D view at 800×600, resizable with the divider by pointer and keyboard', async () => {
    await loadSample('woody.obj');
    await page.getByTestId('free-boundary').check();
    const h = await runSolve();
    assert.equal(h.result.cones, 0, 'woody with a free boundary: a flat disk');
    assert.ok(await page.getByTestId('uv-view').isVisible());
    assert.ok(await page.getByTestId('uv-divider').isVisible());
    // Stacked in the tall views area of 800×600, without covering the 3D view.
    assert.equal(await page.getByTestId('views').getAttribute('data-split'), 'column');
    const canvas = await box('canvas');
    const uv = await box('uv-view');
    assert.ok(disjoint(canvas, uv), `3D ${JSON.stringify(canvas)} and UV ${JSON.stringify(uv)} overlap`);
    assert.ok(canvas.height >= 150 && uv.height >= 150, 'both panes usable');
    await screenshot('uvpane-800x600');

    // Drag the divider up by 80 px: the UV pane grows by as much, the 3D view shrinks.
    const d = await box('uv-divider');
    await page.mouse.move(d.x + d.width / 2, d.y + d.height / 2);
    await page.mouse.down();
    await page.mouse.move(d.x + d.width / 2, d.y + d.height / 2 - 40, { steps: 3 });
    await page.mouse.move(d.x + d.width / 2, d.y + d.height / 2 - 80, { steps: 3 });
    await page.mouse.up();
    const uv2 = await box('uv-view');
    const canvas2 = await box('canvas');
    assert.ok(Math.abs(uv2.height - uv.height - 80) <= 3, `UV pane ${uv.height} → ${uv2.height} px`);
    assert.ok(Math.abs(canvas.height - canvas2.height - 80) <= 3, `3D view ${canvas.height} → ${canvas2.height} px`);
    assert.ok(disjoint(canvas2, uv2));

    // Keyboard: the focused divider moves with the arrow keys, to the limits with Home / End.
    const divider = page.getByTestId('uv-divider');
    await divider.focus();
    const value = async () => Number(await divider.getAttribute('aria-valuenow'));
    const v0 = await value();
    await page.keyboard.press('ArrowDown');
    assert.equal(await value(), v0 + 5);
    const uv3 = await box('uv-view');
    assert.ok(uv3.height < uv2.height - 10, `ArrowDown: the UV pane shrinks (${uv2.height} → ${uv3.height})`);
    await page.keyboard.press('ArrowUp');
    await page.keyboard.press('ArrowUp');
    assert.equal(await value(), v0 - 5);
    await page.keyboard.press('End');
    assert.equal(await value(), Number(await divider.getAttribute('aria-valuemax')));
    assert.ok(Math.abs((await box('uv-view')).height - 140) <= 2, 'End: the UV pane at its least');
    await page.keyboard.press('Home');
    assert.ok(Math.abs((await box('canvas')).height - 140) <= 2, 'Home: the 3D view at its least');
    // A double click puts the divider back where it started (the UV pane at 42 %).
    await divider.dblclick();
    assert.equal(await value(), 58);
  });

  it('draws the [0, 1]² frame and finds no overlap on a flat disk (recomputed from the OBJ)', async () => {
    const h = await hooks();
    assert.equal(h.uvView.map, 'seamless');
    // The frame is the square the exports map to [0, 1]²: from the layout's lower-left corner, its longer side long.
    const [u0, v0, u1, v1] = h.result.uvBounds;
    const side = Math.max(u1 - u0, v1 - v0);
    assert.deepEqual(h.uvView.frame, [u0, v0, u0 + side, v0 + side]);
    const obj = await downloadObj();
    const vts = obj.vt.flat();
    assert.ok(Math.min(...vts) > -1e-6 && Math.abs(Math.max(...vts) - 1) < 1e-6, 'the OBJ spans [0, 1]² along its longer side');
    const truth = sampledOverlap(obj);
    assert.equal(truth.share, 0, 'the OBJ of woody has no stacked UVs');
    assert.equal(h.uvView.overlap.overlapped, 0);
    assert.equal(h.uvView.overlap.maxDepth, 1);
    assert.equal(await overlapFigure(), 'none');
    assert.equal(await page.getByTestId('uv-overlap-text').innerText(), 'none');
  });

  it('shows the overlap of a layout that overlaps, as recomputed from the OBJ, and tints it', async () => {
    await page.getByTestId('free-boundary').uncheck();
    await loadSample('teapot.obj');
    const h = await runSolve();
    const o = h.uvView.overlap;
    const truth = sampledOverlap(await downloadObj());
    assert.ok(truth.share > 0.01, `the OBJ stacks ${truth.share} of its area`);
    assert.ok(Math.abs(o.share - truth.share) < 0.02, `page ${o.share} vs recomputed ${truth.share}`);
    assert.equal(o.maxDepth, truth.maxDepth, 'deepest stack');
    assert.ok(o.ms < 1000, `rasterized in ${o.ms} ms`);
    assert.equal(h.uvView.overlapTint, true);
    const shown = await overlapFigure();
    assert.match(shown, new RegExp(`^${Math.round(o.share * 100)} % of area, up to ${o.maxDepth} layers$`));
    // The tint can be turned off and on.
    await page.getByTestId('uv-overlaps').locator('input').uncheck();
    assert.equal((await hooks()).uvView.overlapTint, false);
    await page.getByTestId('uv-overlaps').locator('input').check();
    assert.equal((await hooks()).uvView.overlapTint, true);
  });

  it('selects a clicked chart in both views (its face count recomputed from the OBJ); a click on empty space clears', async () => {
    // The teapot: 4 components, so 4 charts of different sizes.
    const { count, sizes } = objChartSizes(await downloadObj());
    const faces = sizes.length;
    assert.ok(count > 1, 'the teapot has several charts');
    // Faces spread over the mesh (where charts stack, a click picks the one drawn on top): until two charts were selected.
    const seen = new Set();
    for (let i = 0; i < 24 && (seen.size < 2 || i < 4); i++) {
      const chart = await clickUvFace(Math.floor((i * (faces - 1)) / 23));
      assert.ok(chart, `clicking face ${i} selected nothing`);
      assert.equal(chart.faces3d, sizes[chart.face], `3D: the chart of face ${chart.face}`);
      assert.equal(chart.facesUv, sizes[chart.face], `UV view: the chart of face ${chart.face}`);
      assert.equal(chart.charts, count);
      seen.add(chart.chart);
    }
    assert.ok(seen.size > 1, 'clicks in different charts');
    await screenshot('uvpane-chart-selected');
    // Recolouring both views at another distortion scale keeps the selection.
    const selected = (await hooks()).chart;
    await page.getByTestId('surface-distortion').check();
    await page.getByTestId('distortion-scale-mode').selectOption('fixed');
    assert.equal((await hooks()).distortion.fixed, true);
    assert.deepEqual((await hooks()).chart, selected);
    assert.equal((await hooks()).uvView.selectedFaces, selected.facesUv, 'the chart stays highlighted in the layout');
    await page.getByTestId('distortion-scale-mode').selectOption('auto');
    await page.getByTestId('surface-checker').check();
    // Escape clears the selection too.
    await page.keyboard.press('Escape');
    assert.equal((await hooks()).chart, null);
    await clickUvFace(0);
    // Empty space: beyond the layout's bounds.
    const b = (await hooks()).uvView.bounds;
    const p = await page.evaluate((bb) => window.__conemapTest.projectUvPoint(bb[2] + 0.02 * (bb[2] - bb[0]), bb[3] + 0.02 * (bb[3] - bb[1])), b);
    const pane = await box('uv-canvas');
    assert.ok(p.x < pane.x + pane.width && p.y > pane.y, 'the empty point is in the pane');
    await page.mouse.click(p.x, p.y);
    assert.equal((await hooks()).chart, null);
  });

  it('makes the hovered face visible however small it is drawn (outline and ring)', async () => {
    await page.getByTestId('uv-frame').click();
    // A face drawn a few pixels across at fit zoom.
    const faces = (await hooks()).stats.faces;
    let f = Math.floor(faces / 2);
    let p = await page.evaluate((face) => window.__conemapTest.projectUvFace(face), f);
    for (let tries = 0; p.radius > 4 && tries < 50; tries++) {
      f = (f + 97) % faces;
      p = await page.evaluate((face) => window.__conemapTest.projectUvFace(face), f);
    }
    assert.ok(p.radius <= 4, `no face under 4 px found (${p.radius})`);
    /** The uv canvas's pixels in a 48 px square around p (CSS px), as RGBA bytes. */
    const around = () => page.evaluate(({ x, y }) => {
      const src = document.querySelector('[data-testid=uv-canvas]');
      const r = src.getBoundingClientRect();
      const k = src.width / r.width;
      const c = document.createElement('canvas');
      c.width = c.height = 48;
      const g = c.getContext('2d');
      g.drawImage(src, (x - r.left - 24) * k, (y - r.top - 24) * k, 48 * k, 48 * k, 0, 0, 48, 48);
      return Array.from(g.getImageData(0, 0, 48, 48).data);
    }, p);
    const frame = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    await page.mouse.move(5, 5);
    await page.waitForFunction(() => window.__conemap.hoverFace === null);
    await frame();
    const before = await around();
    await page.mouse.move(p.x, p.y);
    await page.waitForFunction(() => window.__conemap.hoverFace !== null, null, { timeout: 5_000 });
    await frame();
    const after = await around();
    let changed = 0;
    for (let i = 0; i < before.length; i += 4) {
      if (Math.abs(before[i] - after[i]) + Math.abs(before[i + 1] - after[i + 1]) + Math.abs(before[i + 2] - after[i + 2]) > 60) changed++;
    }
    // The face itself covers at most ~50 px²; the ring around it some hundreds.
    assert.ok(changed > 150, `hovering changed only ${changed} pixels`);
    await page.mouse.move(5, 5);
  });

  it('looks right at 1400×900 (side by side) and 390×844 (stacked)', async () => {
    await page.setViewportSize({ width: 1400, height: 900 });
    await page.waitForFunction(() => document.querySelector('[data-testid=views]').dataset.split === 'row');
    const canvas = await box('canvas');
    const uv = await box('uv-view');
    assert.ok(disjoint(canvas, uv) && uv.x > canvas.x, 'side by side, the UV pane on the right');
    await screenshot('uvpane-1400x900');
    await page.setViewportSize({ width: 390, height: 844 });
    await page.waitForFunction(() => document.querySelector('[data-testid=views]').dataset.split === 'column');
    assert.ok(disjoint(await box('canvas'), await box('uv-view')));
    await screenshot('uvpane-390x844');
    await page.setViewportSize({ width: 800, height: 600 });
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(ctx.consoleErrors, []);
  });
});
