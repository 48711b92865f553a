// Unit tests of the UV pane's pure modules: the overlap rasterizer
// (web/src/uv-overlap.ts), the charts of a map (charts.ts), the marker sizes
// (marker-size.ts) and the split's limits (split.ts), each bundled by esbuild
// and imported (see loadPageModule).
import { before, describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { loadPageModule as load } from './wasm.mjs';

/** The axis-aligned square [x0, x1] × [y0, y1] as two triangles (2 UVs per corner), split along the diagonal. */
const square = (x0, y0, x1, y1) => [x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1];

/** An n × n grid of unit squares over [0, 1]², two triangles each: every inner edge shared by two triangles. */
function gridLayout(n, flip = false) {
  const out = [];
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      const [x0, y0, x1, y1] = [i / n, j / n, (i + 1) / n, (j + 1) / n];
      // Alternate diagonals; `flip` reverses every other triangle's orientation (still no overlap).
      const tris = (i + j) % 2 ? square(x0, y0, x1, y1) : [x0, y0, x1, y0, x0, y1, x1, y0, x1, y1, x0, y1];
      if (flip && (i + j) % 2) out.push(...tris.slice(0, 2), ...tris.slice(4, 6), ...tris.slice(2, 4), ...tris.slice(6));
      else out.push(...tris);
    }
  }
  return Float32Array.from(out);
}

describe('uv-overlap.ts', () => {
  let m;
  before(async () => { m = await load('uv-overlap'); });

  it('finds a third of two half-overlapping unit squares stacked two deep', () => {
    // Union 1.5, overlap 0.5: share 1/3.
    const o = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), ...square(0.5, 0, 1.5, 1)]));
    assert.ok(Math.abs(o.share - 1 / 3) < 0.002, `share ${o.share}`);
    assert.equal(o.maxDepth, 2);
    assert.equal(o.width, 1024);
    assert.ok(Math.abs(o.height - 1024 / 1.5) <= 1);
    // Three squares over the same spot: depth 3, all of it stacked.
    const three = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), ...square(0, 0, 1, 1), ...square(0, 0, 1, 1)]));
    assert.equal(three.maxDepth, 3);
    assert.equal(three.share, 1);
    assert.equal(m.overlapText(o), '33 % of area, up to 2 layers');
  });

  it('finds no overlap for disjoint or edge-sharing squares and fine grids', () => {
    const apart = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), ...square(2, 0, 3, 1)]));
    assert.equal(apart.overlapped, 0);
    assert.equal(apart.share, 0);
    assert.equal(apart.maxDepth, 1);
    assert.equal(m.overlapText(apart), 'none');
    // Touching along an edge, and a grid whose shared edges and vertices fall on cell centres: nothing counted twice, no gaps.
    const touching = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), ...square(1, 0, 2, 1)]));
    assert.equal(touching.overlapped, 0);
    assert.equal(touching.covered, touching.width * touching.height);
    for (const n of [4, 64, 128, 300]) {
      for (const flip of [false, true]) {
        const o = m.uvOverlap(gridLayout(n, flip));
        assert.equal(o.overlapped, 0, `${n}×${n} grid (flip ${flip})`);
        assert.equal(o.covered, o.width * o.height, `${n}×${n} grid covers every cell (flip ${flip})`);
      }
    }
  });

  it('counts a fold-over and skips degenerate and non-finite faces', () => {
    // A triangle folded back over its neighbour: both cover the overlap.
    const folded = m.uvOverlap(Float32Array.from([0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.5, 0.2]));
    assert.ok(folded.overlapped > 0);
    assert.equal(folded.maxDepth, 2);
    const skipped = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), 0, 0, 1, 1, 0.5, 0.5, NaN, 0, 1, 0, 0, 1]));
    assert.equal(skipped.overlapped, 0);
    const empty = m.uvOverlap(new Float32Array(0));
    assert.equal(empty.covered, 0);
    assert.equal(empty.share, 0);
  });

  it('tints only the stacked cells, more opaque the deeper', () => {
    const o = m.uvOverlap(Float32Array.from([...square(0, 0, 1, 1), ...square(0.5, 0, 1.5, 1), ...square(0.75, 0, 1.5, 1)]), 64);
    const rgba = m.overlapTint(o, [10, 20, 30]);
    assert.equal(rgba.length, o.width * o.height * 4);
    const alphaAt = (u) => rgba[4 * Math.floor(u * o.width / 1.5) + 3];
    assert.equal(alphaAt(0.25), 0, 'one layer: clear');
    assert.ok(alphaAt(0.6) > 0, 'two layers: tinted');
    assert.ok(alphaAt(1) > alphaAt(0.6), 'three layers: more opaque');
  });

  it('rasterizes 200k faces quickly', () => {
    const faces = 200_000;
    const uv = new Float32Array(faces * 6);
    let seed = 7;
    const rand = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 2 ** 32);
    for (let f = 0; f < faces; f++) {
      const x = rand();
      const y = rand();
      for (let k = 0; k < 3; k++) {
        uv[6 * f + 2 * k] = x + rand() * 0.004;
        uv[6 * f + 2 * k + 1] = y + rand() * 0.004;
      }
    }
    m.uvOverlap(uv); // warm-up
    const t0 = performance.now();
    const o = m.uvOverlap(uv);
    const ms = performance.now() - t0;
    assert.ok(o.overlapped > 0);
    assert.ok(ms < 400, `${ms.toFixed(0)} ms for 200k faces`);
  });
});

describe('charts.ts', () => {
  let m;
  before(async () => { m = await load('charts'); });

  // A strip of 4 faces: face f has edges f (left), f + 1 (right) and 10 + f (its own outer side).
  const faceEdges = Uint32Array.from([0, 1, 10, 1, 2, 11, 2, 3, 12, 3, 4, 13]);

  it('joins faces across edges that are not seams', () => {
    const c = m.faceCharts(faceEdges, 14, []);
    assert.deepEqual([...c.chartOf], [0, 0, 0, 0]);
    assert.deepEqual([...m.chartFaces(c, 0)], [0, 1, 2, 3]);
  });

  it('cuts along seams into charts numbered by first face', () => {
    const c = m.faceCharts(faceEdges, 14, [2]);
    assert.deepEqual([...c.chartOf], [0, 0, 1, 1]);
    assert.deepEqual([...m.chartFaces(c, 1)], [2, 3]);
    const all = m.faceCharts(faceEdges, 14, [1, 2, 3]);
    assert.equal(all.offsets.length - 1, 4);
    assert.equal(m.chartFaces(all, 4).length, 0, 'an unknown chart has no faces');
    // A side without an edge (≥ edgeCount) joins nothing.
    const none = m.faceCharts(Uint32Array.from([0, 99, 99, 99, 0, 99]), 1, []);
    assert.deepEqual([...none.chartOf], [0, 0]);
  });
});

describe('marker-size.ts', () => {
  let m;
  before(async () => { m = await load('marker-size'); });

  it('averages the edges at a vertex and sizes markers by it, within the limits', () => {
    // A fan of 2 triangles around vertex 0 with sides 1 and 2 long.
    const positions = Float32Array.from([0, 0, 0, 1, 0, 0, 0, 2, 0, -1, 0, 0]);
    const indices = Uint32Array.from([0, 1, 2, 0, 2, 3]);
    const [at0, at1, missing] = m.localEdgeLengths(positions, indices, [0, 1, 42]);
    assert.ok(Math.abs(at0 - (1 + 2 + 2 + 1) / 4) < 1e-6, `at 0: ${at0}`);
    assert.ok(Math.abs(at1 - (1 + Math.hypot(1, 2)) / 2) < 1e-6, `at 1: ${at1}`);
    assert.ok(Number.isNaN(missing));
    const diagonal = 10;
    assert.equal(m.markerRadius(NaN, diagonal), diagonal * m.MARKER_MAX);
    assert.equal(m.markerRadius(1, diagonal), diagonal * m.MARKER_MAX, 'coarse: capped');
    assert.ok(Math.abs(m.markerRadius(0.1, diagonal) - 0.04) < 1e-9, 'fine: 0.4 of the edge');
    assert.equal(m.markerRadius(1e-6, diagonal), diagonal * m.MARKER_MIN, 'tiny edges: the floor');
  });
});

describe('split.ts', () => {
  let m;
  before(async () => { m = await load('split'); });

  it('lays out side by side when wide, stacked when tall, and keeps both panes usable', () => {
    assert.equal(m.splitAxis(1080, 900), 'row');
    assert.equal(m.splitAxis(480, 600), 'column');
    assert.equal(m.clampShare(0.99, 1000), 1 - m.MIN_PANE_PX / 1000);
    assert.equal(m.clampShare(0, 1000), m.MIN_PANE_PX / 1000);
    assert.equal(m.clampShare(0.3, 1000), 0.3);
    assert.equal(m.clampShare(0.9, 200), 0.5, 'too small for both: even');
  });
});
