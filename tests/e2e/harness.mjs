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
