// The runs of the open mesh, newest first: a bounded list (at most MAX_RUNS
// and RUN_BUDGET_BYTES of result arrays; the newest run is always kept) shown
// as a compact table — run, α, cones, distortion, flipped faces, time — whose
// rows show that run again. A new mesh clears it.
import { $, fmt, fmtAlpha, fmtDuration, fmtInt } from './dom';
import type { OpenMesh } from './feature-editor';
import type { SolveResult } from './protocol';

/** The settings a solve ran with (what the JSON report records). */
export interface RunSettings {
  alpha_smooth: number;
  miq: boolean;
  boundary: 'free' | 'aligned';
  sharp_threshold_degrees: number | null;
  feature_edges: number;
  /** Milliseconds from Run to the result on screen. */
  wall_ms: number;
}

/** One finished solve: its number (1 for the first on this mesh), the mesh, the result and its settings. */
export interface Run {
  n: number;
  mesh: OpenMesh;
  result: SolveResult;
  settings: RunSettings;
}

/** Runs kept at most. */
export const MAX_RUNS = 8;
/** Bytes of result arrays (UVs, exports, per-face distortion) the kept runs may hold together. */
export const RUN_BUDGET_BYTES = 256 * 1024 ** 2;

/** Bytes of the typed arrays of result `r` (its display arrays included). */
export function runBytes(r: SolveResult): number {
  const v = r.view;
  const arrays: Array<ArrayBufferView | null | undefined> = [r.uv, r.seam_edges, r.glb, r.obj, r.metrics.per_face_distortion];
  if (v) arrays.push(v.cornerPositions, v.checkerUv, v.layoutPositions, v.cutSegments, v.seamSegments, v.distortion?.colors);
  return arrays.reduce((s, a) => s + (a?.byteLength ?? 0), 0);
}

/** The runs of `runs` (newest first) kept: the newest always, then the next ones while at most `max` and `budget` bytes (by `bytes`). */
export function keptRuns<T>(runs: readonly T[], bytes: (run: T) => number, max = MAX_RUNS, budget = RUN_BUDGET_BYTES): T[] {
  const kept: T[] = [];
  let total = 0;
  for (const run of runs) {
    total += bytes(run);
    if (kept.length > 0 && (kept.length >= max || total > budget)) break;
    kept.push(run);
  }
  return kept;
}

export class RunHistory {
  /** Newest first. */
  private runs: Run[] = [];
  /** Runs numbered so far on this mesh. */
  private count = 0;
  /** The run shown (null: none). */
  private current: Run | null = null;
  private readonly el = {
    box: $('run-history'),
    rows: $('run-history-rows'),
    note: $('run-history-note'),
  };

  /** `onSelect` is called with the run of a row clicked (not the one shown). */
  constructor(private readonly onSelect: (run: Run) => void) {}

  /** The newest run (null: none). */
  get latest(): Run | null {
    return this.runs[0] ?? null;
  }

  /** Number of runs kept. */
  get size(): number {
    return this.runs.length;
  }

  /** The number the next run added gets (1 for the first on this mesh). */
  get nextNumber(): number {
    return this.count + 1;
  }

  /** Records `run` (a finished solve, numbered `nextNumber`, on screen) as the newest, shown; drops the oldest runs beyond the bounds. */
  add(run: Run): void {
    // The display arrays are rebuilt when an older run is shown again: only the newest keeps them.
    for (const r of this.runs) delete r.result.view;
    this.count = Math.max(this.count, run.n);
    this.runs = keptRuns([run, ...this.runs], (r) => runBytes(r.result));
    this.current = run;
    this.render();
  }

  /** Marks `run` as the one shown (its row highlighted). */
  setCurrent(run: Run): void {
    this.current = run;
    this.render();
  }

  /** Forgets every run (a new mesh). */
  clear(): void {
    this.runs = [];
    this.count = 0;
    this.current = null;
    this.render();
  }

  /** Enables or disables switching (off while a solve runs). */
  setEnabled(enabled: boolean): void {
    for (const b of this.el.rows.querySelectorAll('button')) b.disabled = !enabled;
  }

  /** The table: one row per run, the shown one marked; hidden with fewer than two runs. */
  private render(): void {
    this.el.box.hidden = this.runs.length < 2;
    const rows = this.runs.map((run) => this.row(run));
    this.el.rows.replaceChildren(...rows);
    const dropped = this.count - this.runs.length;
    this.el.note.textContent = `Quads are computed for the newest run only.${dropped > 0 ? ` ${dropped} older ${dropped === 1 ? 'run was' : 'runs were'} dropped to bound memory (at most ${MAX_RUNS} kept).` : ''}`;
  }

  /** The table row of `run`: a button naming it, then its figures; a click shows it. */
  private row(run: Run): HTMLTableRowElement {
    const tr = document.createElement('tr');
    const shown = run === this.current;
    tr.className = shown ? 'current' : '';
    tr.dataset['run'] = String(run.n);
    const m = run.result.metrics;
    const button = document.createElement('button');
    button.type = 'button';
    button.className = 'run-button';
    button.textContent = `#${run.n}`;
    button.setAttribute('aria-pressed', String(shown));
    button.title = shown ? 'Shown' : `Show run ${run.n}`;
    const first = document.createElement('th');
    first.scope = 'row';
    first.append(button);
    tr.append(first);
    for (const text of [fmtAlpha(run.settings.alpha_smooth), fmtInt(run.result.cones.length), fmt(m.distortion), fmtInt(m.flipped), fmtDuration(run.settings.wall_ms)]) {
      const td = document.createElement('td');
      td.textContent = text;
      tr.append(td);
    }
    tr.addEventListener('click', () => {
      if (run !== this.current && !button.disabled) this.onSelect(run);
    });
    return tr;
  }
}
