// Feature editing (click / Shift-click paths / sharp threshold / undo) and the
// solve controls (α_smooth, MIQ, Run, Cancel, progress, results, downloads).
import * as THREE from 'three';
import { FeatureSet } from './features';
import { definitionList } from './panels';
import type { ErrorLocation, ImportResult, SolveResult, SolveView } from './protocol';
import { buildSolveView } from './solve-view';
import { type Adjacency, shortestPath } from './topology';
import { UvView } from './uvview';
import { COLORS, type SurfaceMode, type Viewer, heat } from './viewer';
import { Cancelled, LocatedError, type MeshWorker } from './worker-client';

/** The test hooks the editor keeps up to date (part of `window.__conemap`, see main.ts). */
export interface EditorHooks {
  /** Marked feature edges (without the fixed boundary edges). */
  features: number;
  /** Figures of the last finished solve (null before one, or after a new mesh). */
  result: ResultHook | null;
  /** Message of the last failed solve (null after a successful one). */
  solveError: string | null;
  /** The `location` of the last failed solve's error (null after a success, or when it names no mesh element). */
  solveErrorLocation: ErrorLocation | null;
  /** What the 3D view highlights of that location (valid ids only); null once cleared (Run, new mesh, feature change). */
  errorHighlight: ErrorLocation | null;
  /** Increments on every finished solve (success, failure or cancel). */
  solves: number;
  /** Face highlighted in the 3D and UV views (hover sync), or null. */
  hoverFace: number | null;
}

/** Figures of a finished solve, as the tests read them. */
export interface ResultHook {
  cones: number;
  plus: number;
  minus: number;
  /** Σk over cones and over boundary corners. */
  sumConeK: number;
  sumCornerK: number;
  boundaryCorners: number;
  /** χ of the whole mesh (from the import report). */
  eulerCharacteristic: number;
  rounds: number;
  featureEdges: number;
  /** The cone count as shown in the results panel. */
  shownCones: string;
  uv: boolean;
  seams: number;
  /** `phiᵀ(alpha L + M/A) phi` of the placement. */
  energy: number;
  /** Components whose cones a helper worker placed. */
  helperComponents: number;
}

const $ = <T extends HTMLElement>(id: string): T => {
  const el = document.getElementById(id);
  if (!el) throw new Error(`#${id} missing from index.html`);
  return el as T;
};

const NO_EDGE = 0xffffffff;
/** A click further than this from every side of the hit triangle toggles nothing (CSS px). */
const PICK_TOLERANCE = 24;

const fmt = (x: number, digits = 3): string =>
  !Number.isFinite(x) ? '—' : Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(2) : x.toFixed(digits);
const fmtInt = (n: number): string => n.toLocaleString('en-US');
const alphaOf = (slider: number): number => 10 ** slider;

/** Longest wait for an animation frame while building the view (hidden pages get none). */
const FRAME_WAIT_MS = 1000;

/** Resolves in a task after the next animation frame (so after that frame was drawn), or after FRAME_WAIT_MS without one. */
function afterNextFrame(): Promise<void> {
  return new Promise((resolve) => {
    const timer = setTimeout(resolve, FRAME_WAIT_MS);
    requestAnimationFrame(() => {
      clearTimeout(timer);
      setTimeout(resolve, 0);
    });
  });
}

interface MeshState {
  label: string;
  data: ImportResult;
  edges: Uint32Array;
  features: FeatureSet | null;
  adjacency: Adjacency | null;
}

export class Editor {
  private mesh: MeshState | null = null;
  private anchor: number | null = null;
  private solving = false;
  /** The solver has answered and its result is being put on screen (over a few frames). */
  private building = false;
  /** Ends the wait for the view being built at once (set while `building`). */
  private abortBuild: (() => void) | null = null;
  /** Bumped whenever the shown result is cleared: a view build that sees it change stops. */
  private viewEpoch = 0;
  private result: SolveResult | null = null;
  /** The solve error's location highlighted in the 3D view (null: none shown). */
  private problem: ErrorLocation | null = null;
  private resultSettings: Record<string, unknown> | null = null;
  private uvView: UvView;
  private roundingStart = 0;
  private readonly el = {
    count: $('feature-count'),
    boundaryCount: $('boundary-count'),
    sharpToggle: $<HTMLInputElement>('sharp-toggle'),
    sharpAngle: $<HTMLInputElement>('sharp-angle'),
    sharpValue: $<HTMLOutputElement>('sharp-value'),
    sharpMinEdges: $<HTMLInputElement>('sharp-min-edges'),
    sharpClosed: $<HTMLInputElement>('sharp-closed'),
    sharpStats: $<HTMLElement>('sharp-stats'),
    undo: $<HTMLButtonElement>('undo-button'),
    redo: $<HTMLButtonElement>('redo-button'),
    clear: $<HTMLButtonElement>('clear-features'),
    alpha: $<HTMLInputElement>('alpha'),
    alphaValue: $<HTMLOutputElement>('alpha-value'),
    miq: $<HTMLInputElement>('miq'),
    freeBoundary: $<HTMLInputElement>('free-boundary'),
    run: $<HTMLButtonElement>('run-button'),
    cancel: $<HTMLButtonElement>('cancel-button'),
    progress: $('solve-progress'),
    stage: $('solve-stage'),
    bar: $<HTMLProgressElement>('solve-bar'),
    error: $('solve-error'),
    note: $('solve-note'),
    status: $('solve-status'),
    results: $('results'),
    resultStats: $('result-stats'),
    distortionLegend: $('distortion-legend'),
    distortionMax: $('distortion-max'),
    histogram: $<HTMLCanvasElement>('histogram'),
    glb: $<HTMLButtonElement>('download-glb'),
    obj: $<HTMLButtonElement>('download-obj'),
    json: $<HTMLButtonElement>('download-json'),
    uv: $('uv-view'),
    uvFrame: $<HTMLButtonElement>('uv-frame'),
  };

  constructor(
    private readonly viewer: Viewer,
    private readonly worker: MeshWorker,
    private readonly hooks: EditorHooks,
    private readonly setState: (s: 'ready' | 'solving' | 'solved') => void,
  ) {
    this.uvView = new UvView(this.el.uv);
    this.uvView.onHover = (face) => this.hoverSync(face);
    this.wirePicking();
    this.wireControls();
    this.updateFeatureUi();
  }

  // ---- mesh -------------------------------------------------------------

  setMesh(data: ImportResult, label: string): void {
    const edges = data.edges ?? new Uint32Array(0);
    const features = data.valid && data.edges ? new FeatureSet(edges.length / 2, data.boundary) : null;
    this.mesh = { label, data, edges, features, adjacency: data.adjacency };
    this.anchor = null;
    this.el.sharpToggle.checked = false;
    this.el.sharpAngle.disabled = true;
    this.el.sharpMinEdges.disabled = true;
    this.el.sharpClosed.disabled = true;
    this.el.sharpStats.textContent = '';
    this.clearResult();
    this.clearProblem();
    this.hooks.solveErrorLocation = null;
    this.el.error.hidden = true;
    this.el.status.hidden = true;
    if (features) this.viewer.setLines('boundary', edges, data.boundary, COLORS.boundary, 3, 0);
    this.redrawFeatures();
    this.el.note.hidden = data.valid;
    this.el.note.textContent = data.valid
      ? ''
      : 'This mesh has blocking problems (see below): features cannot be marked and Run will report why it cannot be parametrized.';
    this.updateFeatureUi();
  }

  private clearResult(): void {
    this.viewEpoch++;
    this.result = null;
    this.resultSettings = null;
    this.hooks.result = null;
    this.el.results.hidden = true;
    this.el.uv.hidden = true;
    this.uvView.clear();
    this.viewer.setCones([], []);
    this.viewer.setLines('seams', this.mesh?.edges ?? new Uint32Array(0), [], COLORS.seam);
    this.viewer.setLines('unaligned', this.mesh?.edges ?? new Uint32Array(0), [], COLORS.unaligned);
    this.viewer.setUvSurface(null);
    this.viewer.setHoverFace(null);
  }

  /** Highlights the same face in the 3D view and the UV view. */
  private hoverSync(face: number | null): void {
    this.hooks.hoverFace = face;
    this.viewer.setHoverFace(face);
    this.uvView.setHoverFace(face);
  }

  // ---- features ---------------------------------------------------------

  private redrawFeatures(): void {
    const m = this.mesh;
    const ids = m?.features?.ids() ?? new Uint32Array(0);
    this.viewer.setLines('features', m?.edges ?? new Uint32Array(0), ids, COLORS.feature, 3.5, 1);
    this.updateFeatureUi();
  }

  private updateFeatureUi(): void {
    const f = this.mesh?.features ?? null;
    const n = f?.count ?? 0;
    this.hooks.features = n;
    this.el.count.textContent = fmtInt(n);
    this.el.count.title = `${n} feature edges marked`;
    this.el.boundaryCount.textContent = f ? `(${fmtInt(f.boundaryCount)})` : '';
    this.el.undo.disabled = !f?.canUndo;
    this.el.redo.disabled = !f?.canRedo;
    this.el.clear.disabled = !f || n === 0;
    this.el.sharpToggle.disabled = !f;
    this.el.run.disabled = !this.mesh || this.solving;
    this.el.cancel.disabled = !this.solving || this.building;
  }

  private changed(did: boolean): void {
    if (!did) return;
    // A failed solve's highlight is about the features it ran with.
    this.clearProblem();
    this.redrawFeatures();
    if (this.result && !this.solving) {
      this.el.status.textContent = 'Features changed since this result: Run again to update it.';
      this.el.status.hidden = false;
    }
  }

  private edgeFromPick(x: number, y: number): number {
    const m = this.mesh;
    if (!m?.features) return -1;
    const pick = this.viewer.pick(x, y);
    if (!pick || pick.sideDistance > PICK_TOLERANCE) return -1;
    const e = m.data.faceEdges[3 * pick.face + pick.side]!;
    return e === NO_EDGE ? -1 : e;
  }

  private click(x: number, y: number, shift: boolean): void {
    const m = this.mesh;
    if (!m?.features) return;
    if (shift) {
      const pick = this.viewer.pick(x, y);
      if (!pick) return;
      if (this.anchor === null) {
        this.anchor = pick.vertex;
        this.viewer.setAnchor(pick.vertex);
        return;
      }
      const path = m.adjacency ? shortestPath(m.adjacency, m.data.positions, this.anchor, pick.vertex) : null;
      this.anchor = null;
      this.viewer.setAnchor(null);
      if (path) this.changed(m.features.addAll(path));
      return;
    }
    const e = this.edgeFromPick(x, y);
    if (e >= 0) this.changed(m.features.toggle(e));
  }

  private wirePicking(): void {
    const canvas = this.viewer.canvas;
    let down: { x: number; y: number; t: number } | null = null;
    canvas.addEventListener('pointerdown', (e) => {
      down = e.button === 0 ? { x: e.clientX, y: e.clientY, t: performance.now() } : null;
    });
    canvas.addEventListener('pointerup', (e) => {
      if (!down || e.button !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      const quick = performance.now() - down.t < 600;
      down = null;
      if (moved < 5 && quick) this.click(e.clientX, e.clientY, e.shiftKey);
    });
    // Hover sync with the UV view (only while a UV layout is shown).
    let pending: PointerEvent | null = null;
    canvas.addEventListener('pointermove', (e) => {
      if (e.buttons || this.el.uv.hidden) return;
      if (!pending) {
        requestAnimationFrame(() => {
          const ev = pending!;
          pending = null;
          this.hoverSync(this.viewer.pick(ev.clientX, ev.clientY)?.face ?? null);
        });
      }
      pending = e;
    });
    canvas.addEventListener('pointerleave', () => {
      if (!this.el.uv.hidden) this.hoverSync(null);
    });
  }

  private async applySharp(): Promise<void> {
    const f = this.mesh?.features;
    if (!f) return;
    const mesh = this.mesh;
    const deg = Number(this.el.sharpAngle.value);
    if (!this.el.sharpToggle.checked) {
      this.el.sharpStats.textContent = '';
      this.changed(f.setSharp(null));
      return;
    }
    const minEdges = Math.max(0, Math.floor(Number(this.el.sharpMinEdges.value) || 0));
    const closedOnly = this.el.sharpClosed.checked;
    try {
      const { edges, stats } = await this.worker.sharpEdges(deg, minEdges, closedOnly);
      if (this.mesh !== mesh || !this.el.sharpToggle.checked || Number(this.el.sharpAngle.value) !== deg) return;
      const n = (k: number, one: string, many: string) => `${k} ${k === 1 ? one : many}`;
      const pruned = stats.pruned_edges ? `, ${n(stats.pruned_edges, 'dangling edge', 'dangling edges')}` : '';
      this.el.sharpStats.textContent = `${n(stats.sharp_edges, 'sharp edge', 'sharp edges')}: ${n(stats.curves, 'curve', 'curves')} (${n(stats.kept_edges, 'edge', 'edges')}) kept, ${n(stats.dropped_fragments, 'fragment', 'fragments')}${pruned} dropped`;
      this.changed(f.setSharp(edges));
    } catch (e) {
      if (!(e instanceof Cancelled)) this.showError(`sharp edges: ${e instanceof Error ? e.message : String(e)}`);
    }
  }

  private wireControls(): void {
    const el = this.el;
    el.sharpToggle.addEventListener('change', () => {
      el.sharpAngle.disabled = !el.sharpToggle.checked;
      el.sharpMinEdges.disabled = !el.sharpToggle.checked;
      el.sharpClosed.disabled = !el.sharpToggle.checked;
      void this.applySharp();
    });
    el.sharpAngle.addEventListener('input', () => (el.sharpValue.textContent = `${el.sharpAngle.value}°`));
    el.sharpAngle.addEventListener('change', () => void this.applySharp());
    el.sharpMinEdges.addEventListener('change', () => void this.applySharp());
    el.sharpClosed.addEventListener('change', () => void this.applySharp());
    el.undo.addEventListener('click', () => this.changed(this.mesh?.features?.undo() ?? false));
    el.redo.addEventListener('click', () => this.changed(this.mesh?.features?.redo() ?? false));
    el.clear.addEventListener('click', () => {
      el.sharpToggle.checked = false;
      el.sharpAngle.disabled = true;
      this.changed(this.mesh?.features?.clear() ?? false);
    });
    window.addEventListener('keydown', (e) => {
      const target = e.target as HTMLElement | null;
      if (target && (target.tagName === 'INPUT' && (target as HTMLInputElement).type === 'text')) return;
      const key = e.key.toLowerCase();
      if ((e.ctrlKey || e.metaKey) && key === 'z') {
        e.preventDefault();
        this.changed((e.shiftKey ? this.mesh?.features?.redo() : this.mesh?.features?.undo()) ?? false);
      } else if ((e.ctrlKey || e.metaKey) && key === 'y') {
        e.preventDefault();
        this.changed(this.mesh?.features?.redo() ?? false);
      } else if (key === 'escape' && this.anchor !== null) {
        this.anchor = null;
        this.viewer.setAnchor(null);
      }
    });
    const showAlpha = (): void => {
      el.alphaValue.textContent = alphaText(alphaOf(Number(el.alpha.value)));
    };
    el.alpha.addEventListener('input', showAlpha);
    showAlpha();
    el.run.addEventListener('click', () => void this.run());
    el.cancel.addEventListener('click', () => this.cancelSolve());
    for (const radio of document.querySelectorAll<HTMLInputElement>('input[name=surface]')) {
      radio.addEventListener('change', () => {
        if (radio.checked) this.setSurface(radio.value as SurfaceMode);
      });
    }
    el.json.addEventListener('click', () => this.downloadJson());
    el.uvFrame.addEventListener('click', () => this.uvView.frame());
    el.glb.addEventListener('click', () => {
      const glb = this.result?.glb;
      if (glb) download(new Blob([glb as Uint8Array<ArrayBuffer>], { type: 'model/gltf-binary' }), `${this.baseName()}-uv.glb`);
    });
    el.obj.addEventListener('click', () => {
      const obj = this.result?.obj;
      if (obj) download(new Blob([obj as Uint8Array<ArrayBuffer>], { type: 'text/plain' }), `${this.baseName()}-uv.obj`);
    });
  }

  // ---- solve ------------------------------------------------------------

  /** Shows an error; with a `location` (a solve error), highlights it in 3D and says so, with a button framing it. */
  private showError(message: string, location: ErrorLocation | null = null): void {
    const text = document.createElement('div');
    text.className = 'error-text';
    text.textContent = message;
    this.el.error.replaceChildren(text);
    this.el.error.hidden = false;
    const shown = location ? this.showProblem(location) : null;
    if (!shown) return;
    const line = document.createElement('div');
    line.className = 'error-location';
    line.dataset['testid'] = 'error-location';
    const what: string[] = [];
    const v = shown.vertices;
    if (v.length === 1) what.push(`vertex v${v[0]} (marker)`);
    else if (v.length > 1) what.push(`vertices ${v.map((x) => `v${x}`).join(', ')} (markers)`);
    const n = shown.edges.length;
    if (n > 0) what.push(`${fmtInt(n)} ${n === 1 ? 'edge' : 'edges'}`);
    const swatch = document.createElement('span');
    swatch.className = 'swatch line problem';
    const label = document.createElement('span');
    label.append(swatch, `Highlighted in the 3D view: ${what.join(' and ')}.`);
    const button = document.createElement('button');
    button.type = 'button';
    button.className = 'button small';
    button.dataset['testid'] = 'show-problem';
    button.textContent = 'Show in 3D';
    button.addEventListener('click', () => this.frameProblem());
    line.append(label, button);
    this.el.error.append(line);
  }

  /** Draws `loc` (its ids that exist on this mesh) in the 3D view; returns what is drawn, or null when nothing is. */
  private showProblem(loc: ErrorLocation): ErrorLocation | null {
    const m = this.mesh;
    this.clearProblem();
    if (!m) return null;
    const vertices = loc.vertices.filter((v) => v < m.data.positions.length / 3);
    const edges = loc.edges.filter((e) => e < m.edges.length / 2);
    if (vertices.length === 0 && edges.length === 0) return null;
    this.viewer.setLines('problem', m.edges, edges, COLORS.problem, 5, 4);
    this.viewer.setProblemVertices(vertices);
    this.problem = { vertices, edges };
    this.hooks.errorHighlight = { vertices: [...vertices], edges: [...edges] };
    return this.problem;
  }

  /** Removes the highlight of a solve error (the message stays). */
  private clearProblem(): void {
    if (!this.problem) return;
    this.problem = null;
    this.hooks.errorHighlight = null;
    this.viewer.setLines('problem', this.mesh?.edges ?? new Uint32Array(0), [], COLORS.problem);
    this.viewer.setProblemVertices([]);
    this.el.error.querySelector('.error-location')?.remove();
  }

  /**
   * Points the camera at the highlighted vertices, or without any at the
   * highlighted edges (the edges around a vertex can span the whole mesh).
   */
  private frameProblem(): void {
    const m = this.mesh;
    const p = this.problem;
    if (!m || !p) return;
    const ends = p.edges.flatMap((e) => [m.edges[2 * e]!, m.edges[2 * e + 1]!]);
    this.viewer.frameOn(p.vertices.length > 0 ? p.vertices : ends);
  }

  private progressText(stage: string, step = 0, remaining = 0): [string, number | undefined] {
    switch (stage) {
      case 'starting':
        return ['Starting…', undefined];
      case 'topology':
        return [`Topology: component ${step + 1} of ${Math.max(remaining, 1)}`, remaining ? (step + 1) / remaining : undefined];
      case 'rounding': {
        if (step === 0 || remaining > this.roundingStart) this.roundingStart = remaining;
        const frac = this.roundingStart ? 1 - remaining / this.roundingStart : undefined;
        return [`Rounding: round ${step + 1} (${fmtInt(remaining)} remaining)`, frac];
      }
      case 'cone moves':
        return [`Cone moves: pass ${step + 1}`, undefined];
      case 'cut':
        return ['Cutting the mesh open', undefined];
      case 'cross-field':
        return ['Cross field', undefined];
      case 'poisson':
        return ['Poisson solve', undefined];
      case 'arap':
      case 'ARAP':
        return [`ARAP iteration ${step + 1}${remaining ? ` of ${fmtInt(remaining)}` : ''}`, remaining ? step / remaining : undefined];
      case 'repair':
        return [`Repairing flipped faces: round ${step + 1} (${fmtInt(remaining)} flipped)`, undefined];
      case 'injective':
        return [`Injective refinement: iteration ${step} of at most ${fmtInt(remaining)}`, remaining ? step / remaining : undefined];
      case 'pair cancellation':
        return [`Cancelling cone pairs (${fmtInt(step)} removed)`, undefined];
      case 'building view':
        return ['Building the view…', undefined];
      default: {
        const label = stage.charAt(0).toUpperCase() + stage.slice(1);
        const of = remaining ? ` (${fmtInt(remaining)} remaining)` : '';
        return [`${label}: iteration ${step + 1}${of}`, remaining ? step / (step + remaining) : undefined];
      }
    }
  }

  private setProgress(stage: string, step?: number, remaining?: number): void {
    const [text, frac] = this.progressText(stage, step, remaining);
    this.el.stage.textContent = text;
    if (frac === undefined) this.el.bar.removeAttribute('value');
    else this.el.bar.value = Math.max(0, Math.min(1, frac));
  }

  async run(): Promise<void> {
    const m = this.mesh;
    if (!m || this.solving) return;
    const features = m.features?.ids() ?? new Uint32Array(0);
    const alpha = alphaOf(Number(this.el.alpha.value));
    const miq = this.el.miq.checked;
    const freeBoundary = this.el.freeBoundary.checked;
    const settings = {
      alpha_smooth: alpha,
      miq,
      boundary: freeBoundary ? 'free' : 'aligned',
      sharp_threshold_degrees: this.el.sharpToggle.checked ? Number(this.el.sharpAngle.value) : null,
      feature_edges: features.length,
    };
    this.solving = true;
    this.el.status.hidden = true;
    document.body.dataset['solving'] = 'true';
    this.el.error.hidden = true;
    this.clearProblem();
    this.el.progress.hidden = false;
    this.roundingStart = 0;
    this.setProgress('starting');
    this.updateFeatureUi();
    this.setState('solving');
    const t0 = performance.now();
    try {
      const result = await this.worker.solve(features, alpha, miq, (stage, step, remaining) => {
        if (this.mesh === m) this.setProgress(stage, step, remaining);
      }, freeBoundary);
      if (this.mesh !== m) return;
      this.clearResult();
      this.result = result;
      this.resultSettings = { ...settings, wall_ms: performance.now() - t0 };
      this.building = true;
      this.updateFeatureUi();
      const aborted = new Promise<boolean>((resolve) => (this.abortBuild = () => resolve(false)));
      if (!(await Promise.race([this.showResult(m, result), aborted]))) throw new Cancelled('cancelled while building the view');
      this.hooks.solveError = null;
      this.hooks.solveErrorLocation = null;
      this.setState('solved');
    } catch (e) {
      if (this.mesh !== m) return;
      if (e instanceof Cancelled) {
        this.setState(this.result ? 'solved' : 'ready');
      } else {
        const message = e instanceof Error ? e.message : String(e);
        const location = e instanceof LocatedError ? e.location : null;
        this.hooks.solveError = message;
        this.hooks.solveErrorLocation = location;
        this.showError(message, location);
        this.setState(this.result ? 'solved' : 'ready');
      }
    } finally {
      this.building = false;
      this.abortBuild = null;
      if (this.mesh === m) {
        this.solving = false;
        delete document.body.dataset['solving'];
        this.el.progress.hidden = true;
        this.hooks.solves++;
        this.updateFeatureUi();
      }
    }
  }

  /**
   * Stops a running solve: the worker is terminated and replaced at once (the
   * mesh is re-opened in the new one); once the solver has answered, the view
   * being built is dropped instead.
   */
  cancelSolve(): void {
    if (!this.solving) return;
    if (this.building) {
      this.clearResult();
      this.abortBuild?.();
    } else {
      this.worker.cancel();
      this.el.status.textContent = 'Cancelled; the solver was stopped.';
      this.el.status.hidden = false;
    }
    this.solving = false;
    delete document.body.dataset['solving'];
    this.el.progress.hidden = true;
    this.updateFeatureUi();
  }

  /**
   * Shows a finished solve: the figures at once; with UVs, then the 3D surface
   * with seams and cones in one frame and the UV layout in the next (their
   * shaders compiled first), the stage line saying so meanwhile. Resolves true
   * once all is shown, false when the result was cleared on the way.
   */
  private async showResult(m: MeshState, r: SolveResult): Promise<boolean> {
    const epoch = this.viewEpoch;
    const live = (): boolean => this.viewEpoch === epoch;
    const plus = r.cones.filter((c) => c.k > 0).length;
    const minus = r.cones.filter((c) => c.k < 0).length;
    const sumConeK = r.cones.reduce((s, c) => s + c.k, 0);
    const sumCornerK = r.boundary_corners.reduce((s, c) => s + c.k, 0);
    const report = m.data.report;
    const genus = report?.genus?.length ? report.genus.join(', ') : '—';
    const coneText = `${fmtInt(r.cones.length)} (+${plus} / −${minus})`;
    const t = r.timings;
    const rows: Array<[string, string]> = [
      ['Vertices', fmtInt(m.data.positions.length / 3)],
      ['Faces', fmtInt(m.data.indices.length / 3)],
      ['Genus', genus],
      ['Boundary loops', report ? fmtInt(report.boundary_loops) : '—'],
      ['Features', fmtInt(r.feature_edges)],
      ['Cones', coneText],
      ['Boundary corners', fmtInt(r.boundary_corners.length)],
      r.free_boundary
        ? ['Σk (cones)', `${sumConeK} (free boundary: its curvature takes the rest of 4χ)`]
        : ['Σk (cones + corners)', `${sumConeK + sumCornerK} = 4χ = ${4 * (report?.euler_characteristic ?? NaN)}`],
      ['Energy', fmt(r.energy, 4)],
      ['φ rms', fmt(r.phi_rms, 4)],
      ['Rounding rounds', fmtInt(r.rounds)],
    ];
    const metrics = r.metrics;
    rows.push(
      ['Distortion', fmt(metrics.distortion)],
      ['Faces < 0.2 / < 0.3', `${fmt(metrics.fraction_below_0_2 * 100, 1)} % / ${fmt(metrics.fraction_below_0_3 * 100, 1)} %`],
      ['Flipped faces', fmtInt(metrics.flipped)],
      ['Seam length', fmt(metrics.seam_length)],
      ['Seam residual (angle / length)', `${fmt(metrics.seam_angle_residual)} / ${fmt(metrics.seam_length_residual)}`],
      ['Alignment residual', fmt(metrics.alignment_residual)],
    );
    // Components may be placed in parallel (a helper worker): their stage
    // times add up over components, the cone total is wall-clock.
    const summed = new Set(['topology', 'rounding', 'cone_moves']);
    for (const [k, v] of Object.entries(t)) {
      const label = k === 'total' ? 'cones total' : `${k.replace(/_/g, ' ')}${summed.has(k) ? ' (Σ components)' : ''}`;
      rows.push([`Time: ${label}`, `${(v * 1000).toFixed(0)} ms`]);
    }
    for (const [k, v] of Object.entries(r.param_timings)) {
      rows.push([`Time: ${k.replace(/_/g, ' ')} (UV)`, `${(v * 1000).toFixed(0)} ms`]);
    }
    if (r.inserted_vertices > 0) rows.push(['Inserted vertices (refinement)', fmtInt(r.inserted_vertices)]);
    const alignment = r.feature_alignment;
    if (alignment.requested > 0) {
      const off = alignment.unaligned.slice(0, 5).map((u) => `(v${u.vertices[0]}, v${u.vertices[1]}) ${u.degrees.toFixed(1)}°`).join(', ');
      rows.push(['Features on isolines', `${fmtInt(alignment.aligned)} / ${fmtInt(alignment.requested)}${off ? ` — off: ${off}` : ''}`]);
    }
    rows.push(['Time in worker', `${r.elapsed.toFixed(0)} ms`]);
    const list = definitionList(rows);
    const coneDd = list.querySelector<HTMLElement>('dd[data-stat=cones]');
    if (coneDd) coneDd.dataset['testid'] = 'cone-count';
    this.el.resultStats.replaceChildren(list);
    this.el.results.hidden = false;

    const hasUv = r.uv.length === (m.data.indices.length / 3) * 6;
    for (const radio of document.querySelectorAll<HTMLInputElement>('input[name=surface]')) {
      radio.disabled = radio.value !== 'shaded' && !hasUv;
      radio.parentElement!.title = radio.disabled ? 'the result has no UVs for every face' : '';
      if (radio.value === 'shaded') radio.checked = !hasUv;
      if (radio.value === 'checker') radio.checked = hasUv;
    }
    this.el.glb.disabled = !r.glb;
    this.el.obj.disabled = !r.obj;
    this.el.json.disabled = false;
    this.el.distortionLegend.hidden = true;
    if (hasUv) {
      this.setProgress('building view');
      const view = r.view ?? this.buildView(m, r.uv, r);
      const distortion = view.distortion;
      if (distortion) this.drawDistortionScale(distortion.max, distortion.histogram);
      const colors = distortion?.colors ?? null;
      // The 3D view: everything at once, so that it renders once (a full frame of a big mesh is costly).
      this.viewer.setCones(r.cones, r.boundary_corners);
      this.viewer.setUvSurface({ positions: view.cornerPositions, uv: view.checkerUv, colors });
      this.viewer.setSegments('seams', view.seamSegments, COLORS.seam, 2.5, 2);
      // Requested features the map left off an axis, drawn over everything.
      this.viewer.setLines('unaligned', m.edges, alignment.unaligned.map((u) => u.edge), COLORS.unaligned, 5, 3);
      this.setSurface('checker');
      await this.viewer.prepare();
      if (!live()) return false;
      await afterNextFrame();
      if (!live()) return false;
      // The UV layout, in the next frame.
      this.el.uv.hidden = false;
      this.uvView.show({
        uv: r.uv, positions: view.layoutPositions, checkerUv: view.checkerUv, colors,
        outline: view.cutSegments, bounds: view.layoutBounds, sphere: view.layoutSphere,
      });
      this.uvView.setColored(this.surfaceMode() === 'distortion');
      await this.uvView.prepare();
      if (!live()) return false;
      await afterNextFrame();
      if (!live()) return false;
    } else {
      this.viewer.setCones(r.cones, r.boundary_corners);
      this.viewer.setSurfaceMode('shaded');
    }
    this.hooks.result = {
      cones: r.cones.length,
      plus,
      minus,
      sumConeK,
      sumCornerK,
      boundaryCorners: r.boundary_corners.length,
      eulerCharacteristic: report?.euler_characteristic ?? NaN,
      rounds: r.rounds,
      featureEdges: r.feature_edges,
      shownCones: coneText,
      uv: hasUv,
      seams: r.seam_edges.length,
      energy: r.energy,
      helperComponents: r.helperComponents ?? 0,
    };
    return true;
  }

  /** The display arrays of a solve built on this thread (when the worker sent none); `uv` is `r.uv`. */
  private buildView(m: MeshState, uv: Float32Array, r: SolveResult): SolveView {
    return buildSolveView({
      positions: m.data.positions, indices: m.data.indices, edges: m.edges, boundary: m.data.boundary,
      faceEdges: m.data.faceEdges, uv, seamEdges: r.seam_edges ?? null,
      perFaceDistortion: r.metrics?.per_face_distortion ?? null,
    });
  }

  /** The distortion legend: its scale `max` and the histogram of `counts` (equal bins of value / max over 0..1). */
  private drawDistortionScale(max: number, counts: Uint32Array): void {
    this.el.distortionMax.textContent = fmt(max);
    const canvas = this.el.histogram;
    const g = canvas.getContext('2d')!;
    const bins = counts.length;
    const top = Math.max(...counts, 1);
    g.clearRect(0, 0, canvas.width, canvas.height);
    const w = canvas.width / bins;
    const col = new THREE.Color();
    for (let i = 0; i < bins; i++) {
      const h = (counts[i]! / top) * (canvas.height - 4);
      heat((i + 0.5) / bins, col);
      g.fillStyle = `#${col.getHexString()}`;
      g.fillRect(i * w + 0.5, canvas.height - h, w - 1, h);
    }
  }

  /** The surface mode of the checked radio button ('shaded' when none is). */
  private surfaceMode(): SurfaceMode {
    return (document.querySelector<HTMLInputElement>('input[name=surface]:checked')?.value as SurfaceMode | undefined) ?? 'shaded';
  }

  private setSurface(mode: SurfaceMode): void {
    for (const radio of document.querySelectorAll<HTMLInputElement>('input[name=surface]')) radio.checked = radio.value === mode;
    this.viewer.setSurfaceMode(mode);
    this.uvView.setColored(mode === 'distortion');
    this.el.distortionLegend.hidden = mode !== 'distortion' || !this.result;
  }

  private baseName(): string {
    return (this.mesh?.label ?? 'mesh').replace(/ \(\+\d+ more\)$/, '').replace(/\.[^.]+$/, '');
  }

  /** The report: settings, features, mesh figures and the solver's result (without bulky arrays). */
  report(): Record<string, unknown> | null {
    const m = this.mesh;
    const r = this.result;
    if (!m || !r) return null;
    const { uv: _uv, glb: _glb, obj: _obj, view: _view, seam_edges: seams, metrics, ...rest } = r;
    const metricsOut = { ...metrics, per_face_distortion: undefined };
    return {
      tool: 'conemap',
      file: m.label,
      mesh: m.data.report,
      settings: this.resultSettings,
      features: {
        edges: Array.from(m.features?.ids() ?? []),
        // End positions too: the same form as `conemap solve --features FILE`.
        positions: Array.from(m.features?.ids() ?? [], (e) => [m.edges[2 * e]!, m.edges[2 * e + 1]!].map((v) => Array.from(m.data.positions.subarray(3 * v, 3 * v + 3)))),
        boundary_edges: m.features?.boundaryCount ?? 0,
      },
      result: { ...rest, metrics: metricsOut, seam_edges: seams.length },
    };
  }

  private downloadJson(): void {
    const report = this.report();
    if (report) download(new Blob([`${JSON.stringify(report, null, 2)}\n`], { type: 'application/json' }), `${this.baseName()}-report.json`);
  }

  // ---- test hooks -------------------------------------------------------

  /** Position of vertex `v` of the open mesh, or null. */
  vertexPosition(v: number): [number, number, number] | null {
    const p = this.mesh?.data.positions;
    if (!p || v < 0 || 3 * v + 2 >= p.length) return null;
    return [p[3 * v]!, p[3 * v + 1]!, p[3 * v + 2]!];
  }

  /** End vertices of edge `e` of the open mesh, or null. */
  edgeEnds(e: number): [number, number] | null {
    const m = this.mesh;
    if (!m || e < 0 || 2 * e + 1 >= m.edges.length) return null;
    return [m.edges[2 * e]!, m.edges[2 * e + 1]!];
  }

  /** Page position of vertex `v` (client CSS px), or null. */
  projectVertex(v: number): { x: number; y: number } | null {
    const q = this.vertexPosition(v);
    return q ? this.viewer.projectPoint(q[0], q[1], q[2]) : null;
  }

  projectEdge(e: number): { x: number; y: number } | null {
    const m = this.mesh;
    if (!m || e < 0 || 2 * e + 1 >= m.edges.length) return null;
    const p = m.data.positions;
    const a = m.edges[2 * e]!;
    const b = m.edges[2 * e + 1]!;
    return this.viewer.projectPoint((p[3 * a]! + p[3 * b]!) / 2, (p[3 * a + 1]! + p[3 * b + 1]!) / 2, (p[3 * a + 2]! + p[3 * b + 2]!) / 2);
  }

  edgeAt(x: number, y: number): number {
    return this.edgeFromPick(x, y);
  }

  visibleEdge(): number {
    const m = this.mesh;
    if (!m?.features) return -1;
    const rect = this.viewer.canvas.getBoundingClientRect();
    const n = m.edges.length / 2;
    // Try edges spread over the mesh until one projects inside the view and picks back to itself.
    for (let i = 0; i < 400; i++) {
      const e = Math.floor(((i * 0.6180339887) % 1) * n);
      if (m.features.boundary[e] || m.features.has(e)) continue;
      const q = this.projectEdge(e);
      if (!q || q.x < rect.left + 20 || q.x > rect.right - 20 || q.y < rect.top + 20 || q.y > rect.bottom - 20) continue;
      if (this.edgeFromPick(q.x, q.y) === e) return e;
    }
    return -1;
  }
}

function alphaText(a: number): string {
  return a >= 10 ? a.toFixed(0) : a >= 1 ? a.toFixed(2) : a >= 0.01 ? a.toFixed(3) : a.toExponential(1);
}

function download(blob: Blob, name: string): void {
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}
