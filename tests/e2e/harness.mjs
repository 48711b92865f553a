// Shared set-up of the browser tests: the built site served from dist/ on a
// free port, headless Chromium, one page that records console errors.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchChromium } from '../../scripts/lib/chromium.mjs';
import { startServer } from '../../scripts/serve.mjs';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const dist = path.join(root, 'dist');
export const output = path.join(root, 'tests/output');

/** Starts the server and the browser; `consoleErrors` collects the page's errors. */
export async function openPage() {
  assert.ok(fs.existsSync(path.join(dist, 'index.html')), 'dist/ is missing: run `npm run build` first');
  fs.mkdirSync(output, { recursive: true });
  const server = await startServer({ root: dist, port: 0 });
  const browser = await launchChromium();
  const page = await browser.context.newPage();
  const consoleErrors = [];
  page.on('console', (msg) => {
    if (msg.type() === 'error') consoleErrors.push(`console.error: ${msg.text()}`);
  });
  page.on('pageerror', (err) => consoleErrors.push(`pageerror: ${err.message}`));
  return { server, browser, page, consoleErrors };
}

/** Closes what `openPage` opened (any part may be missing after a failed start). */
export async function closePage(ctx) {
  await ctx?.browser?.close();
  await ctx?.server?.close();
}

/** The pixels of the canvas with test id `testid` on `page` as drawn now: { width, height, data } (RGBA bytes). */
export async function canvasRgba(page, testid) {
  const { width, height, base64 } = await page.evaluate((id) => {
    const src = document.querySelector(`[data-testid=${id}]`);
    const c = document.createElement('canvas');
    c.width = src.width;
    c.height = src.height;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0);
    const bytes = g.getImageData(0, 0, c.width, c.height).data;
    let s = '';
    for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
    return { width: c.width, height: c.height, base64: btoa(s) };
  }, testid);
  return { width, height, data: new Uint8Array(Buffer.from(base64, 'base64')) };
}

/**
 * The helpers the tests of one page share: its test hooks, waiting for a load
 * (after `loads` loads) or a sample, a solve from Run, the next two frames,
 * and counting the 3D view's pixels whose r, g, b lie in the given ranges.
 */
export function pageHelpers(page, { loadTimeout = 90_000, solveTimeout = 120_000 } = {}) {
  const hooks = () => page.evaluate(() => window.__conemap);
  const waitForLoad = async (loads) => {
    await page.waitForFunction((n) => window.__conemap && window.__conemap.loads > n
      && window.__conemap.state !== 'loading', loads, { timeout: loadTimeout });
    return hooks();
  };
  const nextFrame = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  return {
    hooks,
    waitForLoad,
    nextFrame,
    async loadSample(file) {
      const n = (await hooks()).loads;
      await page.selectOption('[data-testid=samples]', file);
      const h = await waitForLoad(n);
      assert.equal(h.state, 'ready', h.lastError ?? '');
      return h;
    },
    async runSolve() {
      const n = (await hooks()).solves;
      await page.getByTestId('run').click();
      await page.waitForFunction((k) => window.__conemap.solves > k, n, { timeout: solveTimeout });
      return hooks();
    },
    async colourPixels([r0, r1], [g0, g1], [b0, b1]) {
      await nextFrame();
      const { data: d } = await canvasRgba(page, 'canvas');
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (d[i] > r0 && d[i] < r1 && d[i + 1] > g0 && d[i + 1] < g1 && d[i + 2] > b0 && d[i + 2] < b1) n++;
      }
      return n;
    },
  };
}

/** `openPage`, then the site at 1400×900 with its first mesh ready: the context and `pageHelpers` of its page. */
export async function openReadyPage() {
  const ctx = await openPage();
  const helpers = pageHelpers(ctx.page);
  await ctx.page.setViewportSize({ width: 1400, height: 900 });
  await ctx.page.goto(ctx.server.url);
  const h = await helpers.waitForLoad(0);
  assert.equal(h.state, 'ready', h.lastError ?? '');
  return { ctx, ...helpers };
}
