// The quads of a solved map: the quad-mode switch and the target-count slider
// (log scale), one quads request at a time to the worker that solved the map
// (a newer request supersedes the ones not yet answered), its progress line,
// the figures (quad edge length, counts, singular vertices by valence, corner
// angles, distortion before → after quantization, defects), the valence
// legend and the downloads; the 3D overlay is quad-view.ts, and the UV view
// (result-panel.ts) is told to draw the grid map while quads are shown. Errors
// go to the page's solve error box; the solved map stays shown.
import { $, definitionList, fmt, fmtInt, fmtMs } from './dom';
import { downloadBytes, fileStem } from './downloads';
import type { OpenMesh } from './feature-editor';
import type { QuadsResult } from './protocol';
import { QuadView, valenceCounts } from './quad-view';
import { uvBounds } from './solve-view';
import type { PageState, PageStore } from './state';
import type { Hooks, QuadsHook } from './test-hooks';
import type { Viewer } from './viewer';
import type { MeshWorker } from './worker-client';

/** Slider range and default (log10 of the quad count) and how long the slider rests before a request. */
export const QUAD_SLIDER = { min: 2, max: Math.log10(30_000), initial: Math.log10(3_000) } as const;
const DEBOUNCE_MS = 250;

/** The target quad count of slider position `s` (log10), to two significant digits. */
export function quadsOf(s: number): number {
  const n = 10 ** s;
  const unit = 10 ** Math.max(0, Math.floor(Math.log10(n)) - 1);
  return Math.round(n / unit) * unit;
}

/** What the quad panel tells the rest of the page. */
export interface QuadPanelEvents {
  /** Shows a failed request's message (the page's error box). */
  onError: (message: string) => void;
  /** Hides that message again after a success. */
  clearError: () => void;
  /** The grid UVs of the quads shown (grid units, 2 per input face corner) for the UV view; null: none are shown, back to the seamless map. */
  onGridUv: (uv: Float32Array | null) => void;
}

/** The quads shown, the count they were asked for and the milliseconds the request took. */
interface Shown {
  result: QuadsResult;
  target: number;
  ms: number;
}

export class QuadPanel {
  private readonly view: QuadView;
  /** The mesh of the solved map (null: no map shown). */
  private mesh: OpenMesh | null = null;
  private shown: Shown | null = null;
  /** Bumped when the map changes or leaves the screen: answers to older requests are dropped. */
  private epoch = 0;
  /** The newest count asked for and not yet sent (null: none); `sending` while a request is in flight. */
  private wanted: number | null = null;
  private sending = false;
  private debounce: ReturnType<typeof setTimeout> | undefined;
  private phase: PageState['phase'] = 'idle';
  private readonly el = {
    panel: $('quads'),
    mode: $<HTMLInputElement>('quad-mode'),
    count: $<HTMLInputElement>('quad-count'),
    target: $<HTMLOutputElement>('quad-target'),
    size: $('quad-size'),
    showEdges: $<HTMLInputElement>('show-quads'),
    progress: $('quad-progress'),
    stage: $('quad-stage'),
    bar: $<HTMLProgressElement>('quad-bar'),
    stats: $('quad-stats'),
    defects: $('quad-defects'),
    legend: $('quad-legend'),
    obj: $<HTMLButtonElement>('download-quads-obj'),
    glb: $<HTMLButtonElement>('download-quads-glb'),
    gridGlb: $<HTMLButtonElement>('download-grid-glb'),
  };

  /** Wires the controls; `events` are told of errors and of the grid UVs shown (see `QuadPanelEvents`). */
  constructor(
    private readonly viewer: Viewer,
    private readonly worker: MeshWorker,
    private readonly store: PageStore,
    private readonly hooks: Pick<Hooks, 'quads' | 'quadsError' | 'quadRuns'>,
    private readonly events: QuadPanelEvents,
  ) {
    this.view = new QuadView(viewer);
    const el = this.el;
    el.count.min = String(QUAD_SLIDER.min);
    el.count.max = String(QUAD_SLIDER.max);
    el.count.value = String(QUAD_SLIDER.initial);
    this.showTarget();
    el.count.addEventListener('input', () => {
      this.showTarget();
      clearTimeout(this.debounce);
      this.debounce = setTimeout(() => this.requestShown(), DEBOUNCE_MS);
    });
    el.count.addEventListener('change', () => this.requestShown());
    el.mode.addEventListener('change', () => {
      if (el.mode.checked) this.requestShown();
      else this.reset();
      this.render();
    });
    el.showEdges.addEventListener('change', () => this.view.setEdgesVisible(el.showEdges.checked));
    el.obj.addEventListener('click', () => this.save('obj', 'text/plain', 'quads.obj'));
    el.glb.addEventListener('click', () => this.save('glb', 'model/gltf-binary', 'quads.glb'));
    el.gridGlb.addEventListener('click', () => this.save('grid_glb', 'model/gltf-binary', 'grid-uv.glb'));
    store.subscribe((s) => this.stateChanged(s));
  }

  /**
   * A solved map of mesh `m` is on screen (null: none is): drops the quads of
   * the one before; with quad mode on, asks for the new map's once the page
   * is in phase `solved`.
   */
  setMap(m: OpenMesh | null): void {
    this.reset();
    this.mesh = m;
    if (m && this.el.mode.checked && this.store.state.phase === 'solved') this.requestShown();
    this.render();
  }

  /** Sets the slider to the position of about `n` quads and asks for them at once (as a release of the slider does). */
  setCount(n: number): void {
    this.el.count.value = String(Math.log10(Math.max(1, n)));
    this.showTarget();
    this.requestShown();
  }

  /**
   * The quads shown for the JSON report: the count asked for, the request's
   * milliseconds and the result's figures (the quantization's and the
   * quad mesh's, as `conemap quads --report` writes them), without the
   * meshes and exports; null when none are shown.
   */
  reportSection(): Record<string, unknown> | null {
    if (!this.shown) return null;
    const { result, target, ms } = this.shown;
    const { uv: _uv, positions: _positions, quads: _quads, edges: _edges, singular: _singular, obj: _obj, glb: _glb, grid_glb: _gridGlb, ...figures } = result;
    return { target, ms, ...figures };
  }

  /** The target count of the slider as it stands. */
  private get target(): number {
    return quadsOf(Number(this.el.count.value));
  }

  private showTarget(): void {
    this.el.target.textContent = fmtInt(this.target);
  }

  /** Asks for the slider's count when quad mode is on and a map is solved; supersedes any request not yet answered. */
  private requestShown(): void {
    clearTimeout(this.debounce);
    if (!this.el.mode.checked || !this.mesh || this.store.state.phase !== 'solved') return;
    if (this.shown?.target === this.target && this.wanted === null && !this.sending) return;
    this.wanted = this.target;
    if (!this.sending) void this.pump();
  }

  /**
   * Sends the wanted counts one at a time; an answer is shown only when no
   * newer count is wanted and the map is the one it was asked for (the store
   * says 'running' meanwhile, then 'shown' or 'failed').
   */
  private async pump(): Promise<void> {
    this.sending = true;
    try {
      while (this.wanted !== null) {
        const target = this.wanted;
        this.wanted = null;
        const epoch = this.epoch;
        if (this.store.state.phase !== 'solved') return;
        this.store.setQuads('running');
        this.setProgress('starting');
        this.el.progress.hidden = false;
        const t0 = performance.now();
        let outcome: { result: QuadsResult } | { error: string };
        try {
          outcome = { result: await this.worker.quads(target, (stage, step, remaining) => {
            if (this.epoch === epoch && this.wanted === null) this.setProgress(stage, step, remaining);
          }) };
        } catch (e) {
          outcome = { error: e instanceof Error ? e.message : String(e) };
        }
        if (this.epoch !== epoch || this.wanted !== null) continue; // superseded
        this.el.progress.hidden = true;
        this.hooks.quadRuns++;
        if ('result' in outcome) {
          this.show({ result: outcome.result, target, ms: performance.now() - t0 });
        } else {
          this.dropShown();
          this.hooks.quadsError = outcome.error;
          this.events.onError(`Quads: ${outcome.error}`);
          this.store.setQuads('failed');
          this.render();
        }
      }
    } finally {
      this.sending = false;
      this.el.progress.hidden = this.wanted === null;
    }
  }

  /** Puts `s` on screen: the overlay, the grid map in the UV view, the figures, the legend, the downloads. */
  private show(s: Shown): void {
    const r = s.result;
    this.shown = s;
    this.view.show(r);
    this.view.setEdgesVisible(this.el.showEdges.checked);
    this.events.onGridUv(r.uv);
    const counts = valenceCounts(r.singular);
    this.el.size.textContent = `Quad edge ${fmt(r.quantization.grid_size, 4)} (model units) · ${fmtInt(r.report.quads)} quads`;
    this.el.stats.replaceChildren(quadTable(s, counts));
    this.el.defects.hidden = r.defects === 0;
    this.el.defects.textContent = r.defects === 0 ? ''
      : `The extractor repaired ${fmtInt(r.defects)} ${r.defects === 1 ? 'place' : 'places'} where the grid map was not valid: the quad mesh may have holes or irregular quads there.`;
    for (const [key, n] of Object.entries(counts)) {
      const label = this.el.legend.querySelector(`[data-valence=${key}]`);
      if (label) label.textContent = fmtInt(n);
    }
    this.hooks.quadsError = null;
    this.hooks.quads = quadsHook(s, counts, this.viewer.showsGridUv);
    this.events.clearError();
    this.store.setQuads('shown');
    this.render();
  }

  /** Drops the quads shown and any request not yet answered; the store says 'off'. */
  private reset(): void {
    this.epoch++;
    this.wanted = null;
    clearTimeout(this.debounce);
    this.el.progress.hidden = true;
    this.dropShown();
    this.store.setQuads('off');
  }

  /** Removes the quads shown (overlay, figures): the 3D and UV views go back to the seamless map's. */
  private dropShown(): void {
    if (this.shown) this.events.onGridUv(null);
    this.shown = null;
    this.view.clear();
    this.el.size.textContent = '';
    this.el.stats.replaceChildren();
    this.el.defects.hidden = true;
    this.hooks.quads = null;
  }

  /** Leaving phase `solved` drops the quads (a solve or load is under way); coming back asks again when quad mode is on. */
  private stateChanged(s: PageState): void {
    const was = this.phase;
    this.phase = s.phase;
    if (was === 'solved' && s.phase !== 'solved') this.reset();
    else if (was !== 'solved' && s.phase === 'solved') this.requestShown();
    this.render();
  }

  /** The controls as the map and quad mode allow. */
  private render(): void {
    const el = this.el;
    const solved = this.mesh !== null && this.phase === 'solved';
    el.panel.hidden = this.mesh === null;
    el.mode.disabled = !solved;
    el.count.disabled = !solved || !el.mode.checked;
    el.showEdges.disabled = !this.shown;
    el.legend.hidden = !this.shown;
    for (const b of [el.obj, el.glb, el.gridGlb]) b.disabled = !this.shown;
  }

  /** Downloads field `key` of the quads shown as `<mesh>-<suffix>`. */
  private save(key: 'obj' | 'glb' | 'grid_glb', type: string, suffix: string): void {
    const bytes = this.shown?.result[key];
    if (bytes) downloadBytes(bytes, type, `${fileStem(this.mesh?.label)}-${suffix}`);
  }

  /** The progress line for a report of `stage` (quantization: `step` of `remaining` forms rounded; any other: a stage of the map solved again for the quad size). */
  private setProgress(stage: string, step = 0, remaining = 0): void {
    let text = 'Starting…';
    let frac: number | undefined;
    if (stage === 'quantization') {
      text = remaining ? `Quantization: ${fmtInt(step)} of ${fmtInt(remaining)} integers fixed` : 'Quantization';
      frac = remaining ? step / remaining : undefined;
    } else if (stage === 'quad extraction') {
      text = 'Quad extraction';
    } else if (stage === 'decimation') {
      text = 'Decimating the mesh for the quads';
    } else if (stage !== 'starting') {
      // The map solved again for this quad size (edges split, or cone pairs cancelled).
      text = `Map for this quad size: ${stage}`;
    }
    this.el.stage.textContent = text;
    if (frac === undefined) this.el.bar.removeAttribute('value');
    else this.el.bar.value = Math.max(0, Math.min(1, frac));
  }
}

/** The figures table of quads `s` with its interior singular vertices counted by valence. */
function quadTable(s: Shown, counts: ReturnType<typeof valenceCounts>): HTMLDListElement {
  const { quantization: q, report: r } = s.result;
  const boundarySingular = r.singular_vertices.filter((v) => v.boundary).length;
  const rows: Array<[string, string]> = [
    ['Quads', `${fmtInt(r.quads)} (asked ${fmtInt(s.target)})`],
    ['Quad edge length', fmt(q.grid_size, 4)],
    ['Quad vertices', fmtInt(r.vertices)],
    ['Singular vertices', `${fmtInt(counts.three)} × 3, ${fmtInt(counts.five)} × 5, ${fmtInt(counts.other)} other`],
    ['Cones', s.result.cancelled_pairs > 0
      ? `${fmtInt(s.result.cones)} (${fmtInt(s.result.cancelled_pairs)} pairs closer than a quad's diagonal cancelled)`
      : fmtInt(s.result.cones)],
  ];
  if (boundarySingular > 0) rows.push(['Irregular boundary vertices', fmtInt(boundarySingular)]);
  const creases = s.result.dropped_crease_edges;
  const marked = s.result.dropped_feature_edges - creases;
  if (marked > 0) {
    rows.push(['Features not followed', `${fmtInt(marked)} edges (short branches and small loops the quads are too large for; the map with them folded)`]);
  }
  if (creases > 0) {
    rows.push(['Creases not followed', `${fmtInt(creases)} edges (the map with them folded on their part of the mesh)`]);
  }
  rows.push(
    ['Corner angle deviation (mean / max)', `${fmt(r.angle_mean_deviation, 1)}° / ${fmt(r.angle_max_deviation, 1)}°`],
    ['Quads with corners in 45°–135°', `${fmt(r.fraction_corners_45_135 * 100, 1)} %`],
    ['Distortion (seamless → grid)', `${fmt(q.distortion_before)} → ${fmt(q.distortion_after)}`],
    ['Flipped (grid triangles / quads)', `${fmtInt(q.flipped)} / ${fmtInt(r.flipped_quads)}`],
  );
  if (r.distance_quads_to_input_relative !== undefined) {
    rows.push(['Distance to input (of bbox diagonal)', `${fmt(r.distance_quads_to_input_relative * 100, 2)} %`]);
  }
  const decimated = s.result.decimated;
  if (decimated) {
    rows.push(['Traced on', `a decimation to ${fmtInt(decimated.faces)} triangles, moved onto the mesh (checkerboard: its grid map carried back)`]);
  } else if (s.result.refinement.long_edges > 0) {
    rows.push(['Solved on', `${fmtInt(s.result.solved_faces)} triangles (long edges split for quads)`]);
  }
  rows.push(['Defects (repaired)', fmtInt(s.result.defects)]);
  if (decimated) {
    const t = s.result.timings;
    rows.push(['Time: decimation and its solve', fmtMs((t.decimate + t.solve) * 1000)]);
  }
  rows.push(
    ['Time: quantization', fmtMs(q.seconds * 1000)],
    ['Time: quads request', fmtMs(s.ms)],
  );
  return definitionList(rows);
}

/** The test hooks' figures of quads `s` (`gridChecker`: the 3D checker is drawn from the grid UVs). */
function quadsHook(s: Shown, counts: ReturnType<typeof valenceCounts>, gridChecker: boolean): QuadsHook {
  const r = s.result;
  return {
    target: s.target,
    quads: r.report.quads,
    quadIndices: r.quads.length,
    vertices: r.report.vertices,
    gridSize: r.quantization.grid_size,
    singular: counts,
    angleMeanDeviation: r.report.angle_mean_deviation,
    distortionBefore: r.quantization.distortion_before,
    distortionAfter: r.quantization.distortion_after,
    defects: r.defects,
    distance: r.report.distance_quads_to_input_relative === undefined || r.report.distance_input_to_quads_relative === undefined
      ? null
      : Math.max(r.report.distance_quads_to_input_relative, r.report.distance_input_to_quads_relative),
    sharpWithin: r.report.fraction_sharp_within_tolerance ?? null,
    droppedFeatures: s.result.dropped_feature_edges,
    droppedCreases: s.result.dropped_crease_edges,
    solvedFaces: r.solved_faces,
    decimatedFaces: r.decimated?.faces ?? null,
    insertedVertices: r.inserted_vertices,
    uvCorners: r.uv.length / 2,
    gridChecker,
    uvBounds: uvBounds(r.uv),
  };
}
