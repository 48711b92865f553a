// End-to-end test of the built page (dist/) in headless Chromium via playwright-core.
// Run after `npm run build`; `npm test` does both.
import assert from 'node:assert/strict';
import crypto from 'node:crypto';
import os from 'node:os';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { closePage, openPage, output, root } from './harness.mjs';

const fandiskObj = path.join(root, 'web/public/samples/fandisk.obj');
const LOAD_TIMEOUT = 90_000;

let ctx;
let server;
let page;
let consoleErrors = [];

/** Waits until the load counter passes `after` and returns the page's test hooks. */
async function waitForLoad(afterCount) {
  await page.waitForFunction((n) => window.__conemap && window.__conemap.loads > n
    && window.__conemap.state !== 'loading', afterCount, { timeout: LOAD_TIMEOUT });
  return page.evaluate(() => window.__conemap);
}

const loads = () => page.evaluate(() => window.__conemap.loads);

async function screenshot(name) {
  await page.screenshot({ path: path.join(output, `${name}.png`) });
}

/** Samples the WebGL canvas: distinct colours and the share of pixels that are not background. */
function canvasPixels() {
  return page.evaluate(() => {
    const src = document.querySelector('[data-testid=canvas]');
    const w = 96;
    const h = 96;
    const c = document.createElement('canvas');
    c.width = w;
    c.height = h;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0, w, h);
    const d = ctx.getImageData(0, 0, w, h).data;
    const colours = new Set();
    let covered = 0;
    const [br, bg, bb] = [d[0], d[1], d[2]]; // a corner pixel is background
    for (let i = 0; i < d.length; i += 4) {
      colours.add(((d[i] >> 3) << 10) | ((d[i + 1] >> 3) << 5) | (d[i + 2] >> 3));
      if (Math.abs(d[i] - br) + Math.abs(d[i + 1] - bg) + Math.abs(d[i + 2] - bb) > 30) covered++;
    }
    return { distinct: colours.size, coverage: covered / (w * h) };
  });
}

/** Drops files on the page with a synthetic DataTransfer, as a user drag-and-drop would. */
async function dropFiles(files) {
  const payload = files.map((f) => ({ name: f.name, bytes: [...f.bytes] }));
  const dataTransfer = await page.evaluateHandle((list) => {
    const dt = new DataTransfer();
    for (const f of list) dt.items.add(new File([new Uint8Array(f.bytes)], f.name));
    return dt;
  }, payload);
  await page.dispatchEvent('body', 'drop', { dataTransfer });
}

describe('conemap page', () => {
  before(async () => {
    ctx = await openPage();
    ({ server, page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('opens with the fandisk loaded and drawn', async () => {
    await page.goto(server.url);
    const hooks = await waitForLoad(0);
    assert.equal(hooks.state, 'ready', `state ${hooks.state}, error: ${hooks.lastError}`);
    assert.equal(hooks.stats.file, 'fandisk.obj');
    assert.equal(hooks.stats.faces, 12946);
    await page.getByTestId('stats').getByText('12,946').first().waitFor();
    assert.equal(await page.getByTestId('error').isVisible(), false);
    await screenshot('fandisk');
    const pixels = await canvasPixels();
    assert.ok(pixels.distinct >= 8, `canvas looks blank: ${JSON.stringify(pixels)}`);
    assert.ok(pixels.coverage > 0.05, `mesh covers too little of the canvas: ${JSON.stringify(pixels)}`);
  });

  it('loads another sample from the menu', async () => {
    const options = await page.locator('[data-testid=samples] option').evaluateAll((els) => els.map((e) => e.value));
    const other = 'spot.obj';
    assert.ok(options.includes(other), `${other} not among the samples ${options} (../shared/meshes absent at build time?)`);
    const n = await loads();
    await page.selectOption('[data-testid=samples]', other);
    const hooks = await waitForLoad(n);
    assert.equal(hooks.state, 'ready', hooks.lastError ?? '');
    assert.equal(hooks.stats.file, other);
    assert.notEqual(hooks.stats.faces, 12946);
    await screenshot(`sample-${other.replace(/\.obj$/, '')}`);
    assert.ok((await canvasPixels()).distinct >= 8);
  });

  it('lists the problems of a bad mesh (beetle)', async () => {
    const options = await page.locator('[data-testid=samples] option').evaluateAll((els) => els.map((e) => e.value));
    assert.ok(options.includes('beetle.obj'), 'beetle.obj not among the samples (../shared/meshes absent at build time?)');
    const n = await loads();
    await page.selectOption('[data-testid=samples]', 'beetle.obj');
    const hooks = await waitForLoad(n);
    assert.equal(hooks.stats.file, 'beetle.obj');
    assert.equal(hooks.state, 'ready');
    assert.equal(hooks.stats.euler_characteristic, -3);
    const items = page.getByTestId('problems').locator('li');
    assert.ok(await items.count() > 0, 'problems list is empty');
    assert.match(await items.first().innerText(), /edge|vertex|face/i);
    await screenshot('sample-beetle-problems');
  });

  it('numbers beetle\'s problems as the file does and frames the one clicked', async () => {
    // The file's `f` statements (1-based) with their `v` numbers (1-based, positive in beetle.obj).
    const text = fs.readFileSync(path.join(root, '../shared/meshes/beetle.obj'), 'utf8');
    const faces = text.split('\n').filter((l) => /^f\s/.test(l)).map((l) => l.trim().split(/\s+/).slice(1).map((c) => Number(c.split('/')[0])));
    const lines = page.getByTestId('problem-line');
    const messages = await lines.allInnerTexts();
    const nonManifold = messages.map((m, i) => ({ m, i, parts: m.match(/^edge \(v(\d+), v(\d+)\) has (\d+) faces \((.*)\)$/) })).filter((x) => x.parts);
    assert.ok(nonManifold.length > 0, `no non-manifold edge among ${JSON.stringify(messages.slice(0, 3))}`);
    for (const { parts } of nonManifold.slice(0, 10)) {
      const [a, b] = [Number(parts[1]), Number(parts[2])];
      const named = parts[4].split(', ').map((f) => Number(f.replace(/^f/, '')));
      assert.equal(named.length, Number(parts[3]));
      for (const f of named) {
        const corners = faces[f - 1];
        assert.ok(corners, `f${f} is not a face of the file`);
        assert.ok(corners.includes(a) && corners.includes(b), `f${f} (${corners}) of the file does not join v${a} and v${b}`);
      }
    }
    // A click on a line frames its edge: the camera then looks at the edge's end points.
    const { i } = nonManifold[nonManifold.length - 1];
    const before = await page.evaluate(() => window.__conemapTest.cameraTarget());
    await lines.nth(i).click();
    const h = await page.evaluate(() => window.__conemap);
    assert.equal(h.problemFocus.index, i);
    const target = await page.evaluate(() => window.__conemapTest.cameraTarget());
    const ends = await page.evaluate((vs) => vs.map((v) => window.__conemapTest.vertexPosition(v)), h.problemFocus.vertices);
    const mid = [0, 1, 2].map((k) => ends.reduce((s, p) => s + p[k], 0) / ends.length);
    const radius = Math.max(...ends.map((p) => Math.hypot(p[0] - mid[0], p[1] - mid[1], p[2] - mid[2])));
    assert.ok(Math.hypot(target[0] - mid[0], target[1] - mid[1], target[2] - mid[2]) <= radius + 1e-6, `camera looks at ${target}, not at the problem around ${mid}`);
    assert.ok(Math.hypot(target[0] - before[0], target[1] - before[1], target[2] - before[2]) > 0, 'the camera did not move');
    assert.match(await lines.nth(i).getAttribute('class'), /selected/);
    await screenshot('sample-beetle-problem-framed');
  });

  it('shows a readable error for a corrupt file and keeps the previous mesh', async () => {
    const before = await page.evaluate(() => window.__conemap.stats);
    const n = await loads();
    await dropFiles([{ name: 'broken.glb', bytes: crypto.randomBytes(2048) }]);
    const hooks = await waitForLoad(n);
    assert.equal(hooks.state, 'error');
    assert.match(hooks.lastError, /^broken\.glb: \S/);
    const error = page.getByTestId('error');
    assert.ok(await error.isVisible(), 'error box not visible');
    assert.match(await error.innerText(), /broken\.glb/);
    assert.deepEqual(hooks.stats, before, 'the previous mesh should stay shown');
    await screenshot('error-broken-glb');
    assert.ok((await canvasPixels()).distinct >= 8, 'previous mesh no longer drawn');
  });

  it('loads a good file through the file input afterwards', async () => {
    const n = await loads();
    await page.getByTestId('file-input').setInputFiles({
      name: 'fandisk-copy.obj',
      mimeType: 'text/plain',
      buffer: fs.readFileSync(fandiskObj),
    });
    const hooks = await waitForLoad(n);
    assert.equal(hooks.state, 'ready', hooks.lastError ?? '');
    assert.equal(hooks.stats.file, 'fandisk-copy.obj');
    assert.equal(hooks.stats.faces, 12946);
    assert.equal(await page.getByTestId('error').isVisible(), false);
    await screenshot('file-input-fandisk');
  });

  it('opens a .gltf dropped together with its .bin', async () => {
    const maker = path.join(root, 'tests/node/make-gltf.mjs');
    const { makeGltfFixtures } = await import(maker);
    const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'conemap-e2e-gltf-'));
    try {
      const fixtures = await makeGltfFixtures(fandiskObj, dir);
      const gltf = fixtures.find((f) => (f.files?.[0] ?? f.path ?? '').endsWith('.gltf') && f.files.length > 1);
      assert.ok(gltf, 'no .gltf + .bin fixture');
      const n = await loads();
      // The .bin first: the page must pick the .gltf as the main file.
      await dropFiles([...gltf.files].reverse().map((f) => ({ name: path.basename(f), bytes: fs.readFileSync(f) })));
      const hooks = await waitForLoad(n);
      assert.equal(hooks.state, 'ready', hooks.lastError ?? '');
      assert.match(hooks.stats.file, /\.gltf/);
      assert.equal(hooks.stats.faces, gltf.faces);
    } finally {
      fs.rmSync(dir, { recursive: true, force: true });
    }
  });

  it('shows an error for a zero-length file', async () => {
    const n = await loads();
    await dropFiles([{ name: 'empty.obj', bytes: Buffer.alloc(0) }]);
    const hooks = await waitForLoad(n);
    assert.equal(hooks.state, 'error');
    assert.match(hooks.lastError, /^empty\.obj: .*empty/i);
    assert.match(await page.getByTestId('error').innerText(), /empty/i);
    await screenshot('error-empty');
  });

  it('loads again after errors (the page stays usable)', async () => {
    const n = await loads();
    await dropFiles([{ name: 'again.obj', bytes: fs.readFileSync(fandiskObj) }]);
    const hooks = await waitForLoad(n);
    assert.equal(hooks.state, 'ready', hooks.lastError ?? '');
    assert.equal(hooks.stats.faces, 12946);
  });

  it('survives a crash of the wasm worker (trap) and keeps the mesh', async () => {
    const before = await page.evaluate(() => window.__conemap);
    await page.evaluate(() => window.__conemapTest.importWithTrap('trap.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'));
    const hooks = await waitForLoad(before.loads);
    assert.equal(hooks.state, 'error');
    assert.match(hooks.lastError, /^trap\.obj: .*crashed.*unreachable/i);
    assert.equal(hooks.workerRestarts, before.workerRestarts + 1, 'worker replaced');
    assert.deepEqual(hooks.stats, before.stats, 'previous mesh kept');
    assert.match(await page.getByTestId('error').innerText(), /crashed/);
    await screenshot('error-worker-crash');
    // The fresh worker imports normally.
    const n = await loads();
    await dropFiles([{ name: 'after-crash.obj', bytes: fs.readFileSync(fandiskObj) }]);
    const again = await waitForLoad(n);
    assert.equal(again.state, 'ready', again.lastError ?? '');
    assert.equal(again.stats.faces, 12946);
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
