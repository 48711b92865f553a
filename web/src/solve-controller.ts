// The solve controls: α_smooth, MIQ (which sets α to the library's MIQ
// default), free boundary, Run (off, with the reason, on a mesh that cannot
// be solved) and Cancel (also Esc); a solve through the worker with its
// progress line, handed to the result panel once the solver answers and kept
// in the run history (run-history.ts, whose rows show a run again), and one
// end for every solve (success, failure, cancel), told on the page's status
// line; the solve error box, with the mesh elements it names highlighted in
// 3D.
import { $, fmt, fmtAlpha, fmtDuration, fmtInt } from './dom';
import type { FeatureEditor } from './feature-editor';
import type { MeshProblems } from './mesh-problems';
import { COLORS } from './palette';
import type { ErrorLocation } from './protocol';
import type { ResultPanel } from './result-panel';
import { type Run, RunHistory, type RunSettings } from './run-history';
import { type PageState, type PageStore, canTransition } from './state';
import type { Hooks } from './test-hooks';
import type { Viewer } from './viewer';
import { Cancelled, LocatedError, type MeshWorker } from './worker-client';

/** How a solve ended. */
type Outcome = { kind: 'solved'; run: Run } | { kind: 'cancelled' } | { kind: 'failed'; message: string; location: ErrorLocation | null };

/** α_smooth of the slider's position (a power of ten). */
const alphaOf = (slider: number): number => 10 ** slider;

/** Plain words for the kinds of blocking problems (crate `Problem` kinds). */
const KIND_WORDS: Record<string, string> = {
  non_manifold_edge: 'edges with more than two faces',
  inconsistent_orientation: 'faces oriented inconsistently',
  zero_area_face: 'faces of zero area',
  zero_length_edge: 'edges of zero length',
  degenerate_face: 'degenerate faces',
  duplicate_face: 'duplicate faces',
  non_finite_coordinate: 'vertices with NaN coordinates',
  index_out_of_range: 'faces with bad vertex indices',
};

export class SolveController {
  /** Solves started so far; `active` is the one running (null: none). */
  private runs = 0;
  private active: number | null = null;
  /** The solve error's location highlighted in the 3D view (null: none shown). */
  private problem: ErrorLocation | null = null;
  /** Remaining count at the start of the rounding stage (for its progress fraction). */
  private roundingStart = 0;
  /** The slider's position before MIQ emulation set it to the MIQ default (restored when unticked). */
  private alphaBeforeMiq: string | null = null;
  /** The runs of the open mesh. */
  private readonly history = new RunHistory((run) => void this.showRun(run));
  private readonly el = {
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
  };

  constructor(
    private readonly viewer: Viewer,
    private readonly worker: MeshWorker,
    private readonly store: PageStore,
    private readonly features: FeatureEditor,
    private readonly problems: MeshProblems,
    private readonly results: ResultPanel,
    private readonly hooks: Pick<Hooks, 'solveError' | 'solveErrorLocation' | 'errorHighlight' | 'solves'>,
    /** Sets the page's status line (what happened last). */
    private readonly setStatus: (text: string) => void,
  ) {
    const el = this.el;
    const showAlpha = (): void => {
      el.alphaValue.textContent = fmtAlpha(alphaOf(Number(el.alpha.value)));
    };
    el.alpha.addEventListener('input', showAlpha);
    showAlpha();
    el.miq.addEventListener('change', () => {
      this.followMiq();
      showAlpha();
    });
    el.run.addEventListener('click', () => void this.start());
    el.cancel.addEventListener('click', () => this.cancel());
    window.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && this.active !== null) {
        e.preventDefault();
        this.cancel();
      }
    });
    store.subscribe((s) => this.render(s));
  }

  /**
   * With MIQ emulation ticked, α_smooth goes to the library's MIQ default
   * (the paper's "100.0*": large α without the harmonic-minimality
   * constraint, as the CLI's --miq); unticked, back to where it was.
   */
  private followMiq(): void {
    const el = this.el;
    const defaults = this.features.mesh?.data.alphaDefaults;
    if (el.miq.checked && defaults) {
      this.alphaBeforeMiq = el.alpha.value;
      el.alpha.value = String(Math.log10(defaults.miq));
    } else if (!el.miq.checked && this.alphaBeforeMiq !== null) {
      el.alpha.value = this.alphaBeforeMiq;
      this.alphaBeforeMiq = null;
    }
  }

  /** Resets the error box, status, note and run history for the mesh the feature editor has just opened; on a mesh that cannot be solved, says why Run is off. */
  meshChanged(): void {
    const valid = this.features.mesh?.data.valid ?? false;
    this.history.clear();
    this.clearProblem();
    this.hooks.solveErrorLocation = null;
    this.el.error.hidden = true;
    this.el.status.hidden = true;
    this.el.note.hidden = valid;
    this.el.note.textContent = valid ? '' : this.blockedReason();
    this.el.run.title = valid ? 'Compute cones and the seamless map' : this.el.note.textContent;
    this.render(this.store.state);
  }

  /** Why the open mesh cannot be solved, in plain words (its blocking problems by kind). */
  private blockedReason(): string {
    const kinds = new Map<string, number>();
    for (const p of this.problems.blocking) kinds.set(p.kind, (kinds.get(p.kind) ?? 0) + 1);
    const what = [...kinds].map(([k, n]) => `${fmtInt(n)} ${KIND_WORDS[k] ?? k.replace(/_/g, ' ')}`).join(', ');
    return `Run is off: this mesh cannot be parametrized (${what || 'blocking problems'}). Repair it in a mesh editor; the Problems list below shows each one in 3D.`;
  }

  /** After an edit of the features: drops the error highlight (it was about the old ones) and says when the shown result is out of date. */
  featuresChanged(): void {
    this.clearProblem();
    if (this.results.hasResult && this.store.state.phase !== 'solving') {
      this.el.status.textContent = 'Features changed since this result: Run again to update it.';
      this.el.status.hidden = false;
    }
  }

  /** Runs a solve of the open mesh with the features and settings shown; resolves once it has ended (see `end`). */
  async start(): Promise<void> {
    const m = this.features.mesh;
    if (!m?.data.valid || !canTransition(this.store.state.phase, 'solving')) return;
    const features = m.features?.ids() ?? new Uint32Array(0);
    const alpha = alphaOf(Number(this.el.alpha.value));
    const miq = this.el.miq.checked;
    const freeBoundary = this.el.freeBoundary.checked;
    const settings: Omit<RunSettings, 'wall_ms'> = {
      alpha_smooth: alpha,
      miq,
      boundary: freeBoundary ? 'free' : 'aligned',
      sharp_threshold_degrees: this.features.sharpThreshold(),
      feature_edges: features.length,
    };
    const run = ++this.runs;
    this.active = run;
    this.el.status.hidden = true;
    this.el.error.hidden = true;
    this.clearProblem();
    this.roundingStart = 0;
    this.setProgress('starting');
    this.setStatus(`Solving ${m.label} (α ${fmtAlpha(alpha)})…`);
    this.store.transition('solving');
    const t0 = performance.now();
    let outcome: Outcome;
    try {
      const result = await this.worker.solve(features, m.features?.creaseIds() ?? new Uint32Array(0), alpha, miq, (stage, step, remaining, fraction) => {
        if (this.active === run) this.setProgress(stage, step, remaining, fraction);
      }, freeBoundary, this.store.state.tuning);
      if (this.active !== run) return;
      this.store.transition('solving', { building: true });
      this.setProgress('building view');
      const solved: Run = { n: this.history.nextNumber, mesh: m, result, settings: { ...settings, wall_ms: performance.now() - t0 } };
      const shown = await this.results.show(solved);
      outcome = shown ? { kind: 'solved', run: solved } : { kind: 'cancelled' };
    } catch (e) {
      if (e instanceof Cancelled) outcome = { kind: 'cancelled' };
      else outcome = { kind: 'failed', message: e instanceof Error ? e.message : String(e), location: e instanceof LocatedError ? e.location : null };
    }
    this.end(run, outcome);
  }

  /**
   * Stops the running solve, if any, and ends it at once: the worker is
   * terminated and replaced (the mesh is re-opened in the new one); once the
   * solver has answered, the view being built is dropped instead.
   */
  cancel(): void {
    if (this.active === null) return;
    if (this.store.state.building) {
      this.results.clear();
    } else {
      this.worker.cancel();
      this.el.status.textContent = 'Cancelled; the solver was stopped.';
      this.el.status.hidden = false;
    }
    this.end(this.active, { kind: 'cancelled' });
  }

  /** The one end of solve `run` (later calls for it do nothing): records and shows `outcome`, then leaves `solving`. */
  private end(run: number, outcome: Outcome): void {
    if (this.active !== run) return;
    this.active = null;
    if (outcome.kind === 'solved') {
      this.hooks.solveError = null;
      this.hooks.solveErrorLocation = null;
      this.history.add(outcome.run);
      const { result: r, settings } = outcome.run;
      this.setStatus(`Solved in ${fmtDuration(settings.wall_ms)} (α ${fmtAlpha(settings.alpha_smooth)}): ${fmtInt(r.cones.length)} cones, distortion ${fmt(r.metrics.distortion)}`);
    } else if (outcome.kind === 'failed') {
      this.hooks.solveError = outcome.message;
      this.hooks.solveErrorLocation = outcome.location;
      this.showError(outcome.message, outcome.location);
      this.setStatus('Solve failed: see the message under Solve.');
    } else {
      // A cancel while the view was built cleared the result shown: the newest run comes back (its map left the worker).
      const latest = this.history.latest;
      if (!this.results.hasResult && latest) {
        this.history.setCurrent(latest);
        void this.results.show(latest, false);
      }
      this.setStatus(this.results.hasResult ? 'Solve cancelled; the previous result is shown.' : 'Solve cancelled.');
    }
    this.hooks.solves++;
    this.store.transition(this.results.hasResult ? 'solved' : 'ready');
    // Once the progress line is gone: the panel is as tall as it stays.
    if (outcome.kind === 'solved') this.results.revealActions();
  }

  /**
   * Shows `run` of the history again (its figures, views and downloads) and
   * says so on the status line; quads only for the newest run (the worker
   * holds its map only). Ignored while a solve runs.
   */
  private async showRun(run: Run): Promise<void> {
    if (this.store.state.phase !== 'solved') return;
    this.history.setCurrent(run);
    const newest = run === this.history.latest;
    this.setStatus(`Showing run ${run.n} of ${this.history.nextNumber - 1} (α ${fmtAlpha(run.settings.alpha_smooth)})${newest ? '' : '; quads need the newest run'}.`);
    await this.results.show(run, newest);
  }

  /** The controls as `state` and the open mesh allow: Run when a solve may start, Cancel while one runs (until its view is built); the history's rows only when solved. */
  private render(state: PageState): void {
    const solving = state.phase === 'solving';
    this.history.setEnabled(state.phase === 'solved');
    this.el.run.disabled = !this.features.mesh?.data.valid || !canTransition(state.phase, 'solving');
    this.el.cancel.disabled = !solving || state.building;
    this.el.progress.hidden = !solving;
  }

  /** Shows an error; with a `location` (a solve error), highlights it in 3D and says so, with a button framing it. */
  showError(message: string, location: ErrorLocation | null = null): void {
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

  /** Hides the error box and its highlight. */
  hideError(): void {
    this.clearProblem();
    this.el.error.hidden = true;
  }

  /** Draws `loc` (its ids that exist on this mesh) in the 3D view; returns what is drawn, or null when nothing is. */
  private showProblem(loc: ErrorLocation): ErrorLocation | null {
    const m = this.features.mesh;
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
    this.viewer.setLines('problem', new Uint32Array(0), [], COLORS.problem);
    this.viewer.setProblemVertices([]);
    this.el.error.querySelector('.error-location')?.remove();
  }

  /**
   * Points the camera at the highlighted vertices, or without any at the
   * highlighted edges (the edges around a vertex can span the whole mesh).
   */
  private frameProblem(): void {
    const m = this.features.mesh;
    const p = this.problem;
    if (!m || !p) return;
    const ends = p.edges.flatMap((e) => [m.edges[2 * e]!, m.edges[2 * e + 1]!]);
    this.viewer.frameOn(p.vertices.length > 0 ? p.vertices : ends);
  }

  /**
   * The progress line's text and bar fraction (undefined: indeterminate) for
   * a report of `stage` at `step` with `remaining` to go, `fraction` of the
   * stage done where the library knows it.
   */
  private progressText(stage: string, step = 0, remaining = 0, fraction?: number): [string, number | undefined] {
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
        return [`Cone moves: pass ${step + 1}${fraction === undefined ? '' : ` (${fmtInt(remaining)} cones to try)`}`, fraction];
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
        return [`Cancelling cone pairs (${fmtInt(step)} removed${fraction === undefined ? '' : `, ${fmtInt(remaining)} pairs to try`})`, fraction];
      case 'building view':
        return ['Building the view…', undefined];
      default: {
        const label = stage.charAt(0).toUpperCase() + stage.slice(1);
        const of = remaining ? ` (${fmtInt(remaining)} remaining)` : '';
        return [`${label}: iteration ${step + 1}${of}`, remaining ? step / (step + remaining) : undefined];
      }
    }
  }

  private setProgress(stage: string, step?: number, remaining?: number, fraction?: number): void {
    const [text, frac] = this.progressText(stage, step, remaining, fraction);
    this.el.stage.textContent = text;
    if (frac === undefined) this.el.bar.removeAttribute('value');
    else this.el.bar.value = Math.max(0, Math.min(1, frac));
  }
}
