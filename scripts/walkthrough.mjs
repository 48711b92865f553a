#!/usr/bin/env node
// A scripted new-user walkthrough of the built page (dist/) in headless
// Chromium on any mesh file: open, load, mark sharp edges, run, look at the
// checkerboard and the distortion, download the .glb. Screenshots and the
// download go to OUTDIR; what the page said is printed.
//
//   node scripts/walkthrough.mjs MESH.glb OUTDIR [--sharp DEG] [--alpha A]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchChromium } from './lib/chromium.mjs';
import { startServer } from './serve.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const [file, outDir] = process.argv.slice(2);
const opt = (name, dflt) => { const i = process.argv.indexOf(name); return i > 0 ? Number(process.argv[i + 1]) : dflt; };
if (!file || !outDir) {
  console.error('usage: node scripts/walkthrough.mjs MESH OUTDIR [--sharp DEG] [--alpha A]');
  process.exit(2);
}
fs.mkdirSync(outDir, { recursive: true });
const server = await startServer({ root: path.join(root, 'dist'), port: 0 });
const browser = await launchChromium({ viewport: { width: 1400, height: 850 } });
const page = await browser.context.newPage();
const shot = async (name) => page.screenshot({ path: path.join(outDir, `${name}.png`) });
const text = async (id) => (await page.getByTestId(id).innerText().catch(() => '')).replace(/\s+/g, ' ').trim();
try {
  await page.goto(server.url);
  await page.waitForFunction(() => window.__conemap?.state === 'ready', null, { timeout: 120_000 });
  await shot('1-first-open');
  const loads = await page.evaluate(() => window.__conemap.loads);
  await page.getByTestId('file-input').setInputFiles(file);
  await page.waitForFunction((k) => window.__conemap.loads > k && window.__conemap.state !== 'loading', loads, { timeout: 300_000 });
  console.log('loaded:', await text('stats'), '| problems:', await text('problems'), '| error:', await text('error'));
  await shot('2-loaded');
  const sharp = opt('--sharp', NaN);
  if (Number.isFinite(sharp)) {
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill(String(sharp));
    await page.waitForTimeout(1500);
    console.log('features:', await text('feature-count'));
    await shot('3-features');
  }
  await page.getByTestId('alpha').fill(String(Math.log10(opt('--alpha', 0.01))));
  const solves = await page.evaluate(() => window.__conemap.solves);
  const t0 = Date.now();
  await page.getByTestId('run').click();
  await page.waitForTimeout(300);
  await shot('4-running');
  await page.waitForFunction((k) => window.__conemap.solves > k, solves, { timeout: 900_000 });
  console.log(`solved in ${((Date.now() - t0) / 1000).toFixed(1)} s:`, await text('result-stats'), '| solve error:', await text('solve-error'));
  await shot('5-checker');
  await page.getByTestId('surface-distortion').click();
  await page.waitForTimeout(500);
  await shot('6-distortion');
  const [glb] = await Promise.all([page.waitForEvent('download'), page.getByTestId('download-glb').click()]);
  const out = path.join(outDir, glb.suggestedFilename());
  await glb.saveAs(out);
  console.log('downloaded:', out, fs.statSync(out).size, 'bytes');
} finally {
  await browser.close();
  await server.close();
}
