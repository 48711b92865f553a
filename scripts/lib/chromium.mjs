// Finding and launching the system Chromium for tests and benchmarks
// (playwright-core only; no browser downloads).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

export const CHROMIUM_CANDIDATES = ['/usr/bin/chromium', '/usr/bin/chromium-browser'];

/** Path of a Chromium binary: $CHROMIUM_PATH, then the Debian locations; null if none. */
export function findChromium() {
  const list = [process.env.CHROMIUM_PATH, ...CHROMIUM_CANDIDATES].filter(Boolean);
  return list.find((p) => fs.existsSync(p)) ?? null;
}

export const CHROMIUM_ARGS = [
  '--no-sandbox',
  '--disable-gpu',
  '--use-angle=swiftshader', // software WebGL, works without a GPU or display
  '--enable-unsafe-swiftshader',
  '--disable-quic',
  '--no-first-run',
  '--no-default-browser-check',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--disable-extensions',
  '--disable-dev-shm-usage',
];

/**
 * Launches headless Chromium with a fresh profile directory.
 * Returns { context, close() }; close() also removes the profile.
 */
export async function launchChromium({ viewport = { width: 1280, height: 800 } } = {}) {
  const executablePath = findChromium();
  if (!executablePath) {
    throw new Error(`no Chromium found (set CHROMIUM_PATH or install the Debian package: apt-get install chromium); looked at ${CHROMIUM_CANDIDATES.join(', ')}`);
  }
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport,
  });
  return {
    context,
    async close() {
      await context.close().catch(() => {});
      fs.rmSync(profile, { recursive: true, force: true });
    },
  };
}
