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
