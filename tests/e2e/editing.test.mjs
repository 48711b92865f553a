// End-to-end test of feature editing without accidents and of the keyboard:
// the edge under the pointer is highlighted before a click toggles it, a click
// away from every edge toggles nothing, the Shift-click path says what comes
// next, undo restores the sharp-edge controls with the edges, a slider drag
// is one undo step, the creases preset marks the CLI's creases, features round-trip through a JSON file, MIQ emulation
// sets α to 100, and Escape cancels a running solve.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { after, before, describe, it } from 'node:test';
import { closePage, openReadyPage, output } from './harness.mjs';

/** The page, its context and helpers (`openReadyPage`), and the console errors it logged. */
let ctx, page, hooks, loadSample, runSolve, nextFrame, colourPixels;
let consoleErrors = [];

const test = (name, ...args) => page.evaluate(([n, a]) => window.__conemapTest[n](...a), [name, args]);
const waitFeatures = (n) => page.waitForFunction((k) => window.__conemap.features === k, n, { timeout: 10_000 });
/** Pixels of the 3D view in the hover colour (COLORS.hover, #fff275). */
const hoverPixels = () => colourPixels([230, 256], [220, 256], [90, 150]);

/** The sharp-edge controls as shown: ticked, slider value, its label, slider enabled. */
async function sharpControls() {
  return {
    on: await page.getByTestId('sharp-toggle').isChecked(),
    angle: await page.getByTestId('sharp-angle').inputValue(),
    shown: await page.getByTestId('sharp-value').innerText(),
    enabled: await page.getByTestId('sharp-angle').isEnabled(),
  };
}

describe('feature editing and the keyboard', () => {
  before(async () => {
    ({ ctx, hooks, loadSample, runSolve, nextFrame, colourPixels } = await openReadyPage());
    ({ page, consoleErrors } = ctx);
  });

  after(() => closePage(ctx));

  it('highlights the edge under the pointer before a click, and a click away from every edge toggles nothing', async () => {
    const box = await page.getByTestId('canvas').boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    for (let i = 0; i < 4; i++) await page.mouse.wheel(0, -250); // larger triangles on screen
    await nextFrame();
    // A point 10 to 20 px inside a face (off every edge: the old 24 px reach would toggle one), and a visible edge.
    let far = null;
    for (let tries = 0; tries < 4 && !far; tries++) {
      far = await page.evaluate((r) => {
        for (let y = r.y + r.height * 0.2; y < r.y + r.height * 0.8; y += 7) {
          for (let x = r.x + r.width * 0.2; x < r.x + r.width * 0.8; x += 7) {
            const p = window.__conemapTest.pick(x, y);
            if (p && p.sideDistance > 10 && p.sideDistance < 20) return { x, y, distance: p.sideDistance };
          }
        }
        return null;
      }, box);
      if (!far) await page.mouse.wheel(0, -250);
    }
    assert.ok(far, 'no point 10-20 px from the edges of a face');
    const edge = await test('visibleEdge');
    assert.ok(edge >= 0, 'no visible edge');
    const found = { edge, mid: await test('projectEdge', edge), q: far, distance: far.distance };
    const before = (await hooks()).features;
    await page.mouse.move(found.q.x, found.q.y);
    await nextFrame();
    assert.equal((await hooks()).hoverEdge, null, `nothing is highlighted ${found.distance.toFixed(1)} px from the edges`);
    await page.mouse.click(found.q.x, found.q.y);
    assert.equal((await hooks()).features, before, `a click ${found.distance.toFixed(1)} px from the nearest edge toggled one`);
    // On the edge: highlighted first (in the hover colour), toggled by the click.
    const lit = await hoverPixels();
    await page.mouse.move(found.mid.x, found.mid.y);
    await nextFrame();
    assert.equal((await hooks()).hoverEdge, found.edge);
    assert.ok((await hoverPixels()) > lit + 10, 'the hovered edge is drawn');
    assert.equal((await hooks()).features, before, 'hovering toggles nothing');
    await page.screenshot({ path: path.join(output, 'editing-hover.png') });
    await page.mouse.click(found.mid.x, found.mid.y);
    assert.equal((await hooks()).features, before + 1);
    assert.ok((await test('featureIds')).includes(found.edge));
    await page.mouse.move(box.x + 2, box.y + 2);
    await page.getByTestId('clear-features').click();
    await page.getByTestId('frame-button').click();
  });

  it('says what comes after the first Shift-click; Escape cancels the path', async () => {
    const hint = page.getByTestId('feature-hint');
    const idle = await hint.innerText();
    const box = await page.getByTestId('canvas').boundingBox();
    const q = { x: box.x + box.width / 2, y: box.y + box.height / 2 };
    assert.ok(await test('pick', q.x, q.y), 'the view centre is on the mesh');
    await page.keyboard.down('Shift');
    await page.mouse.click(q.x, q.y);
    await page.keyboard.up('Shift');
    assert.match(await hint.innerText(), /second vertex.*Esc cancels/);
    await page.keyboard.press('Escape');
    assert.equal(await hint.innerText(), idle);
    assert.equal((await hooks()).features, 0);
  });

  it('undo restores the sharp-edge checkbox and slider with the edges', async () => {
    await page.getByTestId('sharp-toggle').check();
    await page.waitForFunction(() => window.__conemap.features > 0, null, { timeout: 10_000 });
    const at90 = (await hooks()).features;
    await page.getByTestId('sharp-angle').fill('40');
    await page.waitForFunction((n) => window.__conemap.features > n, at90, { timeout: 10_000 });
    const at40 = (await hooks()).features;
    assert.deepEqual(await sharpControls(), { on: true, angle: '40', shown: '40°', enabled: true });
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, at90);
    assert.deepEqual(await sharpControls(), { on: true, angle: '90', shown: '90°', enabled: true });
    await page.keyboard.press('Control+z');
    assert.equal((await hooks()).features, 0);
    assert.deepEqual(await sharpControls(), { on: false, angle: '90', shown: '90°', enabled: false }, 'undoing everything unticks the box');
    await page.getByTestId('redo').click();
    await page.getByTestId('redo').click();
    assert.equal((await hooks()).features, at40);
    assert.deepEqual(await sharpControls(), { on: true, angle: '40', shown: '40°', enabled: true });
    await page.getByTestId('clear-features').click();
    assert.deepEqual(await sharpControls(), { on: false, angle: '40', shown: '40°', enabled: false });
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, at40);
    assert.equal((await sharpControls()).on, true);
    await page.getByTestId('clear-features').click();
  });

  it('marks sharp edges while the slider is dragged, and undoes the drag in one step', async () => {
    // The slider is where the last test left it (40°): back to 90° first.
    await page.getByTestId('sharp-toggle').check();
    await page.waitForFunction(() => window.__conemap.features > 0, null, { timeout: 10_000 });
    const at40 = (await hooks()).features;
    await page.getByTestId('sharp-angle').fill('90');
    await page.waitForFunction((n) => window.__conemap.features !== n, at40, { timeout: 10_000 });
    const at90 = (await hooks()).features;
    const slider = await page.getByTestId('sharp-angle').boundingBox();
    const x = (deg) => slider.x + 8 + ((slider.width - 16) * deg) / 180;
    const y = slider.y + slider.height / 2;
    await page.mouse.move(x(90), y);
    await page.mouse.down();
    for (const deg of [80, 70, 60, 50, 40, 30]) {
      await page.mouse.move(x(deg), y, { steps: 3 });
      await page.waitForTimeout(60);
    }
    // Still held: the marks follow the slider.
    await page.waitForFunction((n) => window.__conemap.features > n, at90, { timeout: 10_000 });
    await page.mouse.up();
    const angle = Number(await page.getByTestId('sharp-angle').inputValue());
    assert.ok(angle < 45, `the slider is at ${angle}°`);
    await page.waitForFunction(() => !document.querySelector('[data-testid=undo]').disabled);
    await nextFrame();
    assert.ok((await hooks()).features > at90);
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, at90, 'one undo takes back the whole drag');
    assert.deepEqual(await sharpControls(), { on: true, angle: '90', shown: '90°', enabled: true });
    await page.getByTestId('clear-features').click();
    assert.equal((await hooks()).features, 0);
  });

  it('marks the creases conemap quads follows in one undo step, shown as the sharp-edge controls; a hand toggle keeps the rest', async () => {
    await page.getByTestId('creases-button').click();
    await waitFeatures(693);
    assert.deepEqual(await sharpControls(), { on: true, angle: '75', shown: '75°', enabled: true });
    assert.match(await page.getByTestId('sharp-stats').innerText(), /^Creases: 693 edges on 1 curve \(> 75°, at least 10 % of the diagonal long\), 0 shorter curves dropped/);
    // Again: nothing changes, no second undo step.
    await page.getByTestId('creases-button').click();
    await page.evaluate(() => new Promise((res) => setTimeout(res, 300)));
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, 0, 'one undo takes the creases back');
    assert.equal((await sharpControls()).on, false);
    assert.equal(await page.getByTestId('sharp-stats').innerText(), '');
    await page.getByTestId('redo').click();
    assert.equal((await hooks()).features, 693);
    assert.deepEqual(await sharpControls(), { on: true, angle: '75', shown: '75°', enabled: true });
    // Moving the slider replaces the creases by the plain threshold's edges.
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction(() => window.__conemap.features > 693, null, { timeout: 10_000 });
    assert.match(await page.getByTestId('sharp-stats').innerText(), /^\d+ sharp edges: /);
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, 693);
    await page.getByTestId('clear-features').click();
    assert.equal((await hooks()).features, 0);
  });

  it('exports the features as JSON and imports them back; a file of another mesh is refused', async () => {
    await page.getByTestId('sharp-toggle').check();
    await page.getByTestId('sharp-angle').fill('60');
    await page.waitForFunction(() => window.__conemap.features > 300, null, { timeout: 10_000 });
    const ids = await test('featureIds');
    const [download] = await Promise.all([page.waitForEvent('download'), page.getByTestId('export-features').click()]);
    assert.equal(download.suggestedFilename(), 'fandisk-features.json');
    const file = await download.path();
    assert.equal(JSON.parse(fs.readFileSync(file, 'utf8')).edges.length, ids.length);
    await page.getByTestId('clear-features').click();
    assert.equal((await hooks()).features, 0);
    await page.getByTestId('features-file').setInputFiles({ name: 'fandisk-features.json', mimeType: 'application/json', buffer: fs.readFileSync(file) });
    await waitFeatures(ids.length);
    assert.deepEqual(await test('featureIds'), ids, 'the same edges come back');
    assert.match(await page.getByTestId('sharp-stats').innerText(), new RegExp(`^Imported ${ids.length} feature edges from fandisk-features\\.json\\.$`));
    assert.equal((await sharpControls()).on, false);
    await page.getByTestId('undo').click();
    assert.equal((await hooks()).features, 0, 'the import is one undo step');
    // A file made for another mesh, and a file that is no features file.
    const other = JSON.stringify({ edges: [[[100, 100, 100], [101, 100, 100]]] });
    await page.getByTestId('features-file').setInputFiles({ name: 'other.json', mimeType: 'application/json', buffer: Buffer.from(other) });
    const error = page.getByTestId('solve-error');
    await error.waitFor({ state: 'visible' });
    assert.match(await error.innerText(), /Could not import features from other\.json: feature edge 0: no mesh vertex at \(100, 100, 100\): the file does not match this mesh/);
    await page.getByTestId('features-file').setInputFiles({ name: 'notes.json', mimeType: 'application/json', buffer: Buffer.from('hello') });
    await page.waitForFunction(() => /notes\.json: not a JSON file/.test(document.querySelector('[data-testid=solve-error]').innerText));
    assert.equal((await hooks()).features, 0, 'a refused file changes nothing');
  });

  it('MIQ emulation sets α to 100 (the paper\'s "100.0*"), with a different result than α = 0.01', async () => {
    assert.equal(await page.getByTestId('alpha-value').innerText(), '0.010');
    const plain = (await runSolve()).result;
    const miq = page.getByTestId('miq');
    assert.match(await miq.locator('xpath=..').getAttribute('title'), /α is set to 100.*harmonic-minimality/);
    await miq.check();
    assert.equal(await page.getByTestId('alpha-value').innerText(), '100');
    const h = await runSolve();
    assert.equal(h.state, 'solved', h.solveError ?? '');
    assert.ok(h.result.cones < plain.cones, `MIQ at α = 100: ${h.result.cones} cones, plain at 0.01: ${plain.cones}`);
    assert.notEqual(h.result.energy, plain.energy);
    await miq.uncheck();
    assert.equal(await page.getByTestId('alpha-value').innerText(), '0.010', 'unticking restores α');
  });

  it('Escape cancels a running solve', async () => {
    await loadSample('bff-bunny.obj');
    const before = await hooks();
    await page.getByTestId('run').click();
    await page.waitForFunction(() => window.__conemap.state === 'solving');
    await page.waitForTimeout(400);
    await page.keyboard.press('Escape');
    await page.waitForFunction((n) => window.__conemap.solves > n, before.solves, { timeout: 3_000 });
    const h = await hooks();
    assert.equal(h.state, 'ready');
    assert.equal(h.result, null);
    assert.match(await page.getByTestId('solve-status').innerText(), /cancelled/i);
  });

  it('the 3D view takes focus and orbits with the arrow keys', async () => {
    const canvas = page.getByTestId('canvas');
    assert.equal(await canvas.getAttribute('tabindex'), '0');
    assert.match(await canvas.getAttribute('aria-label'), /arrow keys/);
    await canvas.focus();
    const from = await page.evaluate(() => window.__conemapTest.projectVertex(0));
    await page.keyboard.press('ArrowLeft');
    await nextFrame();
    const to = await page.evaluate(() => window.__conemapTest.projectVertex(0));
    assert.ok(Math.hypot(to.x - from.x, to.y - from.y) > 1, 'the view turned');
  });

  it('logged no unexpected console errors', () => {
    assert.deepEqual(consoleErrors, []);
  });
});
