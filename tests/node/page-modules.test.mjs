// Unit tests of the page's pure modules (web/src/topology.ts, features.ts,
// solve-view.ts, state.ts, uv-grid.ts, dom.ts) and the pure functions of
// quad-panel.ts, quad-view.ts, run-history.ts and distortion-legend.ts: each is
// bundled by esbuild to an ES module and imported, so the tests run the page's
// code itself, without a browser.
import { before, describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { loadPageModule as load } from './wasm.mjs';

/** An (n+1)×(n+1) grid of unit squares, each split along its diagonal: positions, triangles, edges (2 ids per edge). */
function grid(n) {
  const id = (i, j) => i * (n + 1) + j;
  const positions = [];
  for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) positions.push(i, j, 0);
  const tris = [];
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) tris.push(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1));
  }
  const seen = new Map();
  const edges = [];
  for (let t = 0; t < tris.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = tris[t + k];
      const b = tris[t + ((k + 1) % 3)];
      const key = `${Math.min(a, b)},${Math.max(a, b)}`;
      if (!seen.has(key)) { seen.set(key, edges.length / 2); edges.push(Math.min(a, b), Math.max(a, b)); }
    }
  }
  return { positions: Float32Array.from(positions), indices: Uint32Array.from(tris), edges: Uint32Array.from(edges), vertexCount: (n + 1) ** 2 };
}

describe('topology.ts', () => {
  let topo;
  before(async () => { topo = await load('topology'); });

  it('builds a CSR adjacency that lists every edge from both ends', () => {
    const g = grid(3);
    const adj = topo.buildAdjacency(g.edges, g.vertexCount);
    const m = g.edges.length / 2;
    assert.equal(adj.offsets[g.vertexCount], 2 * m);
    for (let e = 0; e < m; e++) {
      const [a, b] = [g.edges[2 * e], g.edges[2 * e + 1]];
      assert.equal(topo.edgeBetween(adj, a, b), e);
      assert.equal(topo.edgeBetween(adj, b, a), e);
    }
    assert.equal(topo.edgeBetween(adj, 0, g.vertexCount - 1), -1);
  });

  it('gives each face side its edge: interior edges twice, boundary edges once', () => {
    const n = 3;
    const g = grid(n);
    const adj = topo.buildAdjacency(g.edges, g.vertexCount);
    const fe = topo.faceEdges(g.indices, adj);
    const uses = new Uint32Array(g.edges.length / 2);
    for (const e of fe) uses[e]++;
    const boundary = [...uses].filter((u) => u === 1).length;
    assert.equal(boundary, 4 * n);
    assert.ok([...uses].every((u) => u === 1 || u === 2));
    // A side with no edge (a broken mesh) is marked, not guessed.
    const bad = topo.faceEdges(Uint32Array.from([0, g.vertexCount - 1, 1]), adj);
    assert.equal(bad[0], 0xffffffff);
  });

  it('finds the shortest path: the diagonal across the grid, none to another component', () => {
    const n = 4;
    const g = grid(n);
    const adj = topo.buildAdjacency(g.edges, g.vertexCount);
    const path = topo.shortestPath(adj, g.positions, 0, g.vertexCount - 1);
    assert.equal(path.length, n, 'n diagonal edges');
    let length = 0;
    for (const e of path) {
      const [a, b] = [g.edges[2 * e], g.edges[2 * e + 1]];
      length += Math.hypot(...[0, 1, 2].map((c) => g.positions[3 * a + c] - g.positions[3 * b + c]));
    }
    assert.ok(Math.abs(length - n * Math.SQRT2) < 1e-5, `length ${length}`);
    // Consecutive edges share a vertex: a path, in order from `from`.
    let at = 0;
    for (const e of path) {
      const [a, b] = [g.edges[2 * e], g.edges[2 * e + 1]];
      assert.ok(a === at || b === at);
      at = a === at ? b : a;
    }
    assert.equal(at, g.vertexCount - 1);
    assert.equal(topo.shortestPath(adj, g.positions, 5, 5).length, 0);
    // A lone extra vertex cannot be reached.
    const lone = topo.buildAdjacency(g.edges, g.vertexCount + 1);
    const pos = Float32Array.from([...g.positions, 9, 9, 9]);
    assert.equal(topo.shortestPath(lone, pos, 0, g.vertexCount), null);
  });
});

describe('features.ts', () => {
  let FeatureSet;
  before(async () => { ({ FeatureSet } = await load('features')); });

  it('toggles interior edges only, and undoes and redoes every change', () => {
    const f = new FeatureSet(10, Uint32Array.from([0, 1]));
    assert.equal(f.toggle(0), false, 'a boundary edge stays');
    assert.equal(f.toggle(10), false, 'out of range');
    assert.ok(f.toggle(5));
    assert.ok(f.addAll([5, 6, 6, 7, 1]));
    assert.deepEqual([...f.ids()], [5, 6, 7]);
    assert.equal(f.count, 3);
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [5]);
    assert.ok(f.redo());
    assert.deepEqual([...f.ids()], [5, 6, 7]);
    assert.ok(f.toggle(6));
    assert.equal(f.canRedo, false, 'a new change drops the redo stack');
    assert.deepEqual([...f.ids()], [5, 7]);
    assert.ok(f.clear());
    assert.equal(f.count, 0);
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [5, 7]);
    assert.equal(f.addAll([5, 7]), false, 'nothing new: no change recorded');
  });

  it('replaces the previous sharp edges and keeps the ones marked by hand', () => {
    const f = new FeatureSet(8, Uint32Array.from([0]));
    f.toggle(2);
    assert.ok(f.setSharp(Uint32Array.from([0, 3, 4])));
    assert.deepEqual([...f.ids()], [2, 3, 4], 'boundary edge 0 is not a feature');
    assert.ok(f.setSharp(Uint32Array.from([4, 5])));
    assert.deepEqual([...f.ids()], [2, 4, 5]);
    assert.ok(f.setSharp(null));
    assert.deepEqual([...f.ids()], [2]);
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [2, 4, 5]);
  });

  it('undoes the sharp settings with the edges, and a slider drag as one step', () => {
    const f = new FeatureSet(8, Uint32Array.from([0]));
    const at = (degrees) => ({ degrees, minEdges: 0, closedOnly: false });
    assert.ok(f.setSharp(Uint32Array.from([3]), at(90)));
    // A drag from 90° to 30° in three moves, released: one change.
    assert.ok(f.setSharp(Uint32Array.from([3, 4]), at(60), true));
    assert.ok(f.setSharp(Uint32Array.from([3, 4, 5]), at(45), true));
    assert.ok(f.setSharp(Uint32Array.from([3, 5, 6]), at(30), true));
    f.closeChange();
    assert.deepEqual([...f.ids()], [3, 5, 6]);
    assert.deepEqual(f.sharpSettings, at(30));
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [3], 'one undo takes back the whole drag');
    assert.deepEqual(f.sharpSettings, at(90));
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], []);
    assert.equal(f.sharpSettings, null, 'undoing everything turns the detection off');
    assert.ok(f.redo() && f.redo());
    assert.deepEqual([...f.ids()], [3, 5, 6]);
    assert.deepEqual(f.sharpSettings, at(30));
    // A later change after the release is a step of its own; the sharp edges move with undo.
    assert.ok(f.setSharp(Uint32Array.from([7]), at(20), true));
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [3, 5, 6]);
    assert.ok(f.setSharp(null, null));
    assert.deepEqual([...f.ids()], [], 'the restored sharp edges are the ones replaced');
  });

  it('replaces every mark by an imported list', () => {
    const f = new FeatureSet(6, Uint32Array.from([0]));
    f.toggle(1);
    assert.ok(f.replaceAll(Uint32Array.from([0, 2, 3])));
    assert.deepEqual([...f.ids()], [2, 3]);
    assert.ok(f.undo());
    assert.deepEqual([...f.ids()], [1]);
  });
});

describe('solve-view.ts', () => {
  let sv;
  let topo;
  before(async () => { [sv, topo] = await Promise.all([load('solve-view'), load('topology')]); });

  it('colours and bins the distortion against its 99th percentile, the last bin holding everything at or above it', () => {
    const per = Float32Array.from({ length: 200 }, (_, i) => i / 100);
    const d = sv.distortionView(per);
    const sorted = [...per].sort((a, b) => a - b);
    assert.equal(d.max, sorted[Math.floor(200 * 0.99)]);
    assert.equal(sv.autoScale(per), d.max);
    assert.equal(d.histogram.length, sv.HISTOGRAM_BINS);
    assert.equal(d.histogram.reduce((a, b) => a + b, 0), per.length, 'every face in one bin');
    assert.equal(d.histogram[sv.HISTOGRAM_BINS - 1], per.filter((v) => v >= d.max).length, 'the last bin: ≥ max');
    assert.equal(d.colors.length, 9 * per.length);
  });

  it('colours against a fixed scale: faces above it saturate, the same values colour alike whatever the other faces', () => {
    const per = Float32Array.from({ length: 200 }, (_, i) => i / 100);
    const d = sv.distortionView(per, 0.5);
    assert.equal(d.max, 0.5);
    assert.equal(d.histogram[sv.HISTOGRAM_BINS - 1], 150, 'faces 0.50 … 1.99 in the last bin');
    assert.equal(d.histogram.reduce((a, b) => a + b, 0), 200);
    // The same value gets the same colour in another result under the same fixed scale, not under the auto one.
    const low = sv.distortionView(Float32Array.from([0.25, 0.01, 0.02]), 0.5);
    assert.deepEqual([...low.colors.subarray(0, 3)], [...d.colors.subarray(9 * 25, 9 * 25 + 3)]);
    const lowAuto = sv.distortionView(Float32Array.from([0.25, 0.01, 0.02]));
    assert.notDeepEqual([...lowAuto.colors.subarray(0, 3)], [...d.colors.subarray(9 * 25, 9 * 25 + 3)]);
    // A non-positive scale falls back to auto.
    assert.equal(sv.distortionView(per, 0).max, sv.autoScale(per));
  });

  it('ramps sequentially (viridis): dark purple at 0 to yellow at 1, luminance rising, clamped, in linear light', () => {
    const rgb = [0, 0, 0];
    const lin = (c) => (c / 255 <= 0.04045 ? c / 255 / 12.92 : ((c / 255 + 0.055) / 1.055) ** 2.4);
    sv.rampRgb(0, rgb, 0);
    assert.deepEqual(rgb.map((x) => +x.toFixed(4)), [0x44, 0x01, 0x54].map((c) => +lin(c).toFixed(4)), '#440154');
    sv.rampRgb(7, rgb, 0); // clamped to 1
    assert.deepEqual(rgb.map((x) => +x.toFixed(4)), [0xfd, 0xe7, 0x25].map((c) => +lin(c).toFixed(4)), '#fde725');
    sv.rampRgb(NaN, rgb, 0);
    assert.deepEqual(rgb.map((x) => +x.toFixed(4)), [0x44, 0x01, 0x54].map((c) => +lin(c).toFixed(4)), 'NaN as 0');
    let last = -1;
    for (let i = 0; i <= 20; i++) {
      sv.rampRgb(i / 20, rgb, 0);
      const y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
      assert.ok(y > last, `luminance rises at t = ${i / 20}`);
      last = y;
    }
    assert.equal(sv.rampCss(0), '#440154');
    assert.equal(sv.rampCss(2), '#fde725');
  });

  it('outlines the charts along seams and the boundary only', () => {
    const g = grid(2);
    const faceEdges = topo.faceEdges(g.indices, topo.buildAdjacency(g.edges, g.vertexCount));
    {
      const uv = new Float32Array(2 * g.indices.length);
      for (let c = 0; c < g.indices.length; c++) { uv[2 * c] = g.positions[3 * g.indices[c]]; uv[2 * c + 1] = g.positions[3 * g.indices[c] + 1]; }
      const m = g.edges.length / 2;
      const uses = new Uint32Array(m);
      for (const e of faceEdges) uses[e]++;
      const boundary = Uint32Array.from([...uses.keys()].filter((e) => uses[e] === 1));
      const seam = [...uses.keys()].find((e) => uses[e] === 2);
      const seg = sv.cutSegments(uv, faceEdges, m, Uint32Array.from([seam]), boundary);
      // One segment per boundary side, two for the seam (one per side of it).
      assert.equal(seg.length / 6, boundary.length + 2);
      for (let i = 0; i < seg.length; i += 3) assert.equal(seg[i + 2], Math.fround(0.005));
      const layout = sv.layoutGeometry(uv);
      assert.deepEqual(layout.layoutBounds, [0, 0, 2, 2]);
      assert.deepEqual(sv.uvBounds(uv), [0, 0, 2, 2]);
      assert.deepEqual(sv.uvBounds(new Float32Array(0)), [Infinity, Infinity, -Infinity, -Infinity]);
      assert.ok(Math.abs(layout.layoutSphere[2] - Math.SQRT2) < 1e-6);
      const checker = sv.checkerUv(uv);
      assert.equal(Math.max(...checker) - Math.min(...checker), 2.5);
    }
  });
});

describe('state.ts', () => {
  let st;
  before(async () => { st = await load('state'); });

  /** A store driven through `phases` from idle (a load first), and the phases its subscriber saw. */
  function driven(...phases) {
    const store = new st.PageStore();
    const seen = [];
    store.subscribe((s) => seen.push(s.phase));
    store.beginLoad();
    for (const p of phases) store.transition(p);
    return { store, seen };
  }

  it('starts idle and tells a new subscriber the state at once', () => {
    const store = new st.PageStore();
    const seen = [];
    store.subscribe((s) => seen.push(s));
    assert.equal(seen.length, 1);
    assert.equal(seen[0].phase, 'idle');
    assert.equal(seen[0].load, 0);
    assert.equal(seen[0].building, false);
  });

  it('goes through a load and solves, notifying every change with the new state', () => {
    const { store, seen } = driven('ready', 'solving', 'solved', 'solving', 'ready', 'loading', 'error', 'solving', 'solved');
    assert.deepEqual(seen, ['idle', 'loading', 'ready', 'solving', 'solved', 'solving', 'ready', 'loading', 'error', 'solving', 'solved']);
    assert.equal(store.state.phase, 'solved');
  });

  it('rejects transitions that make no sense, keeping the state and telling nobody', () => {
    // Each path starts with a load: [] is the phase loading.
    const bad = [
      [[], 'solved'], [[], 'solving'], [[], 'idle'],
      [['ready'], 'solved'], [['ready'], 'error'], [['ready'], 'idle'],
      [['ready', 'solving'], 'loading'], [['ready', 'solving'], 'error'], [['ready', 'solving'], 'idle'],
      [['error'], 'ready'], [['error'], 'solved'],
    ];
    for (const [path, to] of bad) {
      const { store, seen } = driven(...path);
      const before = store.state;
      const notified = seen.length;
      assert.throws(() => store.transition(to), st.InvalidTransition, `${[...path, to].join(' -> ')}`);
      assert.equal(store.state, before, 'state unchanged');
      assert.equal(seen.length, notified, 'no notification');
    }
    // From idle only a load may start.
    const idle = new st.PageStore();
    for (const to of ['idle', 'ready', 'solving', 'solved', 'error']) assert.throws(() => idle.transition(to), st.InvalidTransition);
    assert.equal(idle.state.phase, 'idle');
    // canTransition answers from the same table.
    assert.equal(st.canTransition('ready', 'solving'), true);
    assert.equal(st.canTransition('solved', 'solving'), true);
    assert.equal(st.canTransition('idle', 'solved'), false);
    assert.equal(st.canTransition('loading', 'solving'), false);
  });

  it('marks building only within a solve, and clears it on leaving', () => {
    const { store } = driven('ready', 'solving');
    store.transition('solving', { building: true });
    assert.equal(store.state.building, true);
    assert.equal(store.state.phase, 'solving');
    store.transition('solved');
    assert.equal(store.state.building, false);
    assert.throws(() => store.transition('loading', { building: true }), st.InvalidTransition);
    assert.equal(store.state.phase, 'solved');
  });

  it('makes earlier load tokens stale with every load', () => {
    const store = new st.PageStore();
    const first = store.beginLoad();
    assert.ok(store.isCurrentLoad(first));
    const second = store.beginLoad(); // loading -> loading: a later load supersedes
    assert.notEqual(first, second);
    assert.equal(store.isCurrentLoad(first), false);
    assert.ok(store.isCurrentLoad(second));
    store.transition('ready');
    assert.ok(store.isCurrentLoad(second), 'finishing a load keeps its token');
    // A load cannot begin in the middle of a solve (the solve is ended first).
    store.transition('solving');
    assert.throws(() => store.beginLoad(), st.InvalidTransition);
    assert.ok(store.isCurrentLoad(second), 'a rejected load takes no token');
  });

  it('keeps the solve tuning, changed field by field, in new state objects', () => {
    const store = new st.PageStore();
    const seen = [];
    store.subscribe((s) => seen.push(s));
    const initial = store.state;
    assert.deepEqual({ ...initial.tuning }, { helperMinFaces: 50_000, helperWait: false, maxConeRefinements: undefined });
    store.setTuning({ helperMinFaces: 0, helperWait: true });
    store.setTuning({ maxConeRefinements: 0 });
    assert.deepEqual({ ...store.state.tuning }, { helperMinFaces: 0, helperWait: true, maxConeRefinements: 0 });
    assert.equal(initial.tuning.helperMinFaces, 50_000, 'an earlier state is not changed');
    assert.equal(seen.length, 3);
    assert.notEqual(seen[1], seen[2]);
  });

  it('stops notifying after unsubscribe, and mirrors the phase into a dataset', () => {
    const store = new st.PageStore();
    const seen = [];
    const off = store.subscribe((s) => seen.push(s.phase));
    const dataset = {};
    st.mirrorToDataset(store, dataset);
    assert.deepEqual(dataset, { state: 'idle' });
    store.beginLoad();
    off();
    store.transition('ready');
    assert.deepEqual(seen, ['idle', 'loading']);
    assert.deepEqual(dataset, { state: 'ready' });
    store.transition('solving');
    assert.deepEqual(dataset, { state: 'solving', solving: 'true' });
    store.transition('solved');
    assert.deepEqual(dataset, { state: 'solved' }, 'solving is removed, not left false');
  });

  it('keeps the quads phase only while solved: off on leaving, rejected elsewhere, mirrored unless off', () => {
    const { store, seen } = driven('ready');
    assert.equal(store.state.quads, 'off');
    for (const q of ['running', 'shown', 'failed']) assert.throws(() => store.setQuads(q), st.InvalidTransition, `${q} while ready`);
    store.setQuads('off'); // always allowed; no change, no notification
    const notified = seen.length;
    store.setQuads('off');
    assert.equal(seen.length, notified);
    const dataset = {};
    st.mirrorToDataset(store, dataset);
    store.transition('solving');
    store.transition('solved');
    store.setQuads('running');
    assert.deepEqual(dataset, { state: 'solved', quads: 'running' });
    store.setQuads('shown');
    assert.equal(store.state.quads, 'shown');
    store.transition('solving');
    assert.equal(store.state.quads, 'off', 'a solve drops the quads');
    assert.deepEqual(dataset, { state: 'solving', solving: 'true' });
    assert.throws(() => store.setQuads('running'), st.InvalidTransition);
    store.transition('solved');
    store.setQuads('failed');
    store.beginLoad();
    assert.equal(store.state.quads, 'off', 'a load drops the quads');
    assert.deepEqual(dataset, { state: 'loading' });
  });
});

describe('quad-panel.ts and quad-view.ts', () => {
  let panel;
  let view;
  before(async () => {
    panel = await load('quad-panel');
    view = await load('quad-view');
  });

  it('maps the log slider to counts of two significant digits over 100 .. 30 000', () => {
    const { min, max, initial } = panel.QUAD_SLIDER;
    assert.equal(panel.quadsOf(min), 100);
    assert.equal(panel.quadsOf(max), 30_000);
    assert.equal(panel.quadsOf(initial), 3_000);
    assert.equal(panel.quadsOf(Math.log10(2000)), 2000);
    assert.equal(panel.quadsOf(Math.log10(1234)), 1200);
    assert.equal(panel.quadsOf(Math.log10(187)), 190);
  });

  it('draws quad edges as segments and counts singular vertices by valence', () => {
    const positions = Float32Array.from([0, 0, 0, 1, 0, 0, 1, 1, 0]);
    const seg = view.quadEdgeSegments(positions, Uint32Array.from([0, 1, 1, 2]));
    assert.deepEqual([...seg], [0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 1, 0]);
    assert.deepEqual(view.valenceCounts(Uint32Array.from([7, 3, 8, 5, 9, 3, 10, 6])), { three: 2, five: 1, other: 1 });
    assert.deepEqual(view.valenceCounts(new Uint32Array(0)), { three: 0, five: 0, other: 0 });
  });
});

describe('uv-grid.ts', () => {
  let grid;
  before(async () => { grid = await load('uv-grid'); });

  it('keeps grid lines at least GRID_MIN_PX apart at a stride of 1, 2, 5, 10, 20 … cells', () => {
    assert.equal(grid.GRID_MIN_PX, 4);
    assert.equal(grid.gridStride(6.6), 1);
    assert.equal(grid.gridStride(4), 1);
    assert.equal(grid.gridStride(3.9), 2);
    assert.equal(grid.gridStride(1), 5);
    assert.equal(grid.gridStride(0.5), 10);
    assert.equal(grid.gridStride(0.05), 100);
    assert.equal(grid.gridStride(0.03), 200);
    assert.equal(grid.gridStride(0), null);
    assert.equal(grid.gridStride(NaN), null);
    assert.deepEqual([1, 2, 5, 10, 20, 50].map(grid.majorStride), [10, 10, 10, 100, 100, 100]);
  });

  it('draws u = n and v = n across the bounds, multiples of the major stride apart', () => {
    const { minor, major } = grid.gridLines([-21, -3, 24, 24], 1, 0.5);
    // u = -21 … 24 and v = -3 … 24: 46 + 28 lines, of which u = -20, -10, 0, 10, 20 and v = 0, 10, 20 major.
    assert.equal(major.length / 6, 8);
    assert.equal(minor.length / 6, 46 + 28 - 8);
    assert.deepEqual([...major.subarray(0, 6)], [-20, -3, 0.5, -20, 24, 0.5]);
    for (let i = 0; i < major.length; i += 6) assert.ok(major[i] % 10 === 0 || major[i + 1] % 10 === 0);
    const coarse = grid.gridLines([0.5, 0.5, 9.5, 3.5], 2, 0);
    assert.deepEqual([...coarse.minor].filter((_, i) => i % 6 === 0), [2, 4, 6, 8, 0.5]);
    assert.equal(coarse.major.length, 0);
    assert.equal(grid.gridLines([Infinity, Infinity, -Infinity, -Infinity], 1, 0).minor.length, 0);
  });
});

describe('dom.ts', () => {
  let dom;
  before(async () => { dom = await load('dom'); });

  it('formats numbers with fixed decimals, exponential at the extremes, a dash when not finite', () => {
    assert.equal(dom.fmt(1.23456), '1.235');
    assert.equal(dom.fmt(1.23456, 1), '1.2');
    assert.equal(dom.fmt(0), '0.000');
    assert.equal(dom.fmt(9999.5, 0), '10000', 'below 1e4 stays fixed');
    assert.equal(dom.fmt(12345.678), '1.23e+4');
    assert.equal(dom.fmt(-0.0001234), '-1.23e-4');
    assert.equal(dom.fmt(0.001), '0.001', '1e-3 itself stays fixed');
    for (const x of [NaN, Infinity, -Infinity]) assert.equal(dom.fmt(x), '—');
  });

  it('formats counts with separators, a dash for a missing one', () => {
    assert.equal(dom.fmtInt(1234567), '1,234,567');
    assert.equal(dom.fmtInt(0), '0');
    assert.equal(dom.fmtInt(undefined), '—');
  });

  it('formats sizes in B, KB and MB, and durations in whole ms', () => {
    assert.equal(dom.fmtBytes(0), '0 B');
    assert.equal(dom.fmtBytes(1023), '1023 B');
    assert.equal(dom.fmtBytes(1024), '1.0 KB');
    assert.equal(dom.fmtBytes(1536), '1.5 KB');
    assert.equal(dom.fmtBytes(1024 ** 2 - 1), '1024.0 KB');
    assert.equal(dom.fmtBytes(5.25 * 1024 ** 2), '5.3 MB');
    assert.equal(dom.fmtMs(12.4), '12 ms');
    assert.equal(dom.fmtMs(12.6), '13 ms');
    assert.equal(dom.fmtMs(0), '0 ms');
    assert.equal(dom.fmtDuration(640.4), '640 ms');
    assert.equal(dom.fmtDuration(3240), '3.2 s');
    assert.equal(dom.fmtDuration(123_400), '123 s');
    assert.equal(dom.fmtDuration(NaN), '—');
    assert.equal(dom.fmtAlpha(1), '1.00');
    assert.equal(dom.fmtAlpha(0.01), '0.010');
    assert.equal(dom.fmtAlpha(0.001), '1.0e-3');
    assert.equal(dom.fmtAlpha(31.6), '32');
  });

  it('keys table rows in kebab case', () => {
    assert.equal(dom.statKey('Cones'), 'cones');
    assert.equal(dom.statKey('Σk (cones + corners)'), 'k-cones-corners');
    assert.equal(dom.statKey('Faces < 0.2 / < 0.3'), 'faces-0-2-0-3');
    assert.equal(dom.statKey('Time: cones total'), 'time-cones-total');
  });
});

describe('run-history.ts', () => {
  let rh;
  before(async () => { rh = await load('run-history'); });

  it('keeps the newest runs: at most MAX_RUNS, within the byte budget, the newest always', () => {
    const runs = Array.from({ length: 12 }, (_, i) => ({ n: 12 - i, bytes: 10 }));
    const size = (r) => r.bytes;
    assert.deepEqual(rh.keptRuns(runs, size).map((r) => r.n), [12, 11, 10, 9, 8, 7, 6, 5]);
    assert.equal(rh.MAX_RUNS, 8);
    assert.deepEqual(rh.keptRuns(runs, size, 8, 35).map((r) => r.n), [12, 11, 10], 'three fit 35 bytes');
    assert.deepEqual(rh.keptRuns([{ n: 1, bytes: 100 }, { n: 0, bytes: 1 }], size, 8, 35).map((r) => r.n), [1], 'the newest is kept even over the budget');
    assert.deepEqual(rh.keptRuns([], size), []);
  });

  it('counts the bytes of a result\'s arrays, display arrays included', () => {
    const r = {
      uv: new Float32Array(6), seam_edges: new Uint32Array(2), glb: new Uint8Array(100), obj: null,
      metrics: { per_face_distortion: new Float32Array(1) },
    };
    assert.equal(rh.runBytes(r), 24 + 8 + 100 + 4);
    r.view = {
      cornerPositions: new Float32Array(9), checkerUv: new Float32Array(6), layoutPositions: new Float32Array(9),
      cutSegments: new Float32Array(0), seamSegments: new Float32Array(0), distortion: { colors: new Float32Array(9) },
    };
    assert.equal(rh.runBytes(r), 136 + 4 * (9 + 6 + 9 + 9));
  });
});

describe('distortion-legend.ts', () => {
  let dl;
  before(async () => { dl = await load('distortion-legend'); });

  it('rounds a scale to two significant digits for the fixed value', () => {
    assert.equal(dl.roundScale(0.41873), 0.42);
    assert.equal(dl.roundScale(1.26), 1.3);
    assert.equal(dl.roundScale(0.000123456), 0.00012);
    assert.equal(dl.roundScale(0), 1);
    assert.equal(dl.roundScale(NaN), 1);
  });
});
