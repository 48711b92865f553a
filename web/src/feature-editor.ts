// Feature editing on the open mesh: the edge under the pointer highlighted and
// a click toggling it, Shift-click two vertices to mark the shortest path
// between them, the sharp-edge detection controls (a slider drag is one undo
// step) and the creases preset, undo / redo / clear (buttons and keys, the
// detection settings with the edges), features import and export as JSON;
// and the queries of the open mesh's geometry the test hooks answer with.
import { $, fmtInt } from './dom';
import { download, fileStem } from './downloads';
import { FeatureSet, type SharpSettings } from './features';
import { COLORS } from './palette';
import type { CreaseResult, ImportResult, SharpResult } from './protocol';
import { latestPerFrame, onClick } from './render-loop';
import type { Hooks } from './test-hooks';
import { type Adjacency, shortestPath } from './topology';
import type { Viewer } from './viewer';
import { Cancelled, type MeshWorker } from './worker-client';

/** The mesh open in the page, with its marked features (null when it cannot be parametrized). */
export interface OpenMesh {
  label: string;
  data: ImportResult;
  edges: Uint32Array;
  features: FeatureSet | null;
  adjacency: Adjacency | null;
}

/** What the feature editor tells the rest of the page. */
export interface FeatureEvents {
  /** The marked features changed (by the user). */
  onChange(): void;
  /** Sharp-edge detection failed with `message`. */
  onError(message: string): void;
}

const NO_EDGE = 0xffffffff;
/** A click further than this from every side of the hit triangle toggles nothing (CSS px). */
const PICK_TOLERANCE = 6;
const HINT = 'Click an edge to toggle it; Shift-click two vertices to mark the shortest path between them.';

export class FeatureEditor {
  private open: OpenMesh | null = null;
  /** First vertex of a Shift-click path, until the second. */
  private anchor: number | null = null;
  /** The edge highlighted under the pointer (-1: none). */
  private hovered = -1;
  /** Sharp-edge requests run one after the other, in order. */
  private sharpQueue: Promise<void> = Promise.resolve();
  /** The settings the detection controls were last set to (a preset's stay in use until a control changes). */
  private shown: SharpSettings | null = null;
  private readonly el = {
    count: $('feature-count'),
    boundaryCount: $('boundary-count'),
    sharpToggle: $<HTMLInputElement>('sharp-toggle'),
    sharpAngle: $<HTMLInputElement>('sharp-angle'),
    sharpValue: $<HTMLOutputElement>('sharp-value'),
    sharpMinEdges: $<HTMLInputElement>('sharp-min-edges'),
    sharpClosed: $<HTMLInputElement>('sharp-closed'),
    sharpStats: $<HTMLElement>('sharp-stats'),
    creases: $<HTMLButtonElement>('creases-button'),
    hint: $<HTMLElement>('feature-hint'),
    importInput: $<HTMLInputElement>('features-file'),
    exportButton: $<HTMLButtonElement>('export-features'),
    undo: $<HTMLButtonElement>('undo-button'),
    redo: $<HTMLButtonElement>('redo-button'),
    clear: $<HTMLButtonElement>('clear-features'),
  };

  constructor(
    private readonly viewer: Viewer,
    private readonly worker: MeshWorker,
    private readonly hooks: Pick<Hooks, 'features' | 'hoverEdge'>,
    private readonly events: FeatureEvents,
  ) {
    this.wirePicking();
    this.wireControls();
    this.updateUi();
  }

  /** The open mesh, or null before the first. */
  get mesh(): OpenMesh | null {
    return this.open;
  }

  /** Takes a freshly imported mesh (shown by the viewer) and its label; starts with no features marked. */
  setMesh(data: ImportResult, label: string): void {
    const edges = data.edges ?? new Uint32Array(0);
    const features = data.valid && data.edges ? new FeatureSet(edges.length / 2, data.boundary) : null;
    this.open = { label, data, edges, features, adjacency: data.adjacency };
    this.setAnchor(null);
    this.hover(-1);
    this.showSharpSettings(null);
    this.el.sharpStats.textContent = '';
    if (features) this.viewer.setLines('boundary', edges, data.boundary, COLORS.boundary, 3, 0);
    this.redraw();
  }

  /** The sharp-edge threshold in use (degrees), or null when detection is off. */
  sharpThreshold(): number | null {
    return this.el.sharpToggle.checked ? Number(this.el.sharpAngle.value) : null;
  }

  /** Shows detection `settings` in the controls (null: off, the other controls disabled). */
  private showSharpSettings(settings: SharpSettings | null): void {
    const el = this.el;
    this.shown = settings;
    el.sharpToggle.checked = settings !== null;
    if (settings) {
      el.sharpAngle.value = String(settings.degrees);
      el.sharpMinEdges.value = String(settings.minEdges);
      el.sharpClosed.checked = settings.closedOnly;
    }
    this.showAngle();
    for (const c of [el.sharpAngle, el.sharpMinEdges, el.sharpClosed]) c.disabled = settings === null;
  }

  /** The angle beside the slider, and the slider's spoken value. */
  private showAngle(): void {
    this.el.sharpValue.textContent = `${this.el.sharpAngle.value}°`;
    this.el.sharpAngle.setAttribute('aria-valuetext', `${this.el.sharpAngle.value} degrees`);
  }

  /** The detection settings the controls show (null: detection off); the creases preset's while no control changed since it was chosen. */
  private controlSettings(): SharpSettings | null {
    const el = this.el;
    if (!el.sharpToggle.checked) return null;
    const minEdges = Math.max(0, Math.floor(Number(el.sharpMinEdges.value) || 0));
    const settings: SharpSettings = { degrees: Number(el.sharpAngle.value), minEdges, closedOnly: el.sharpClosed.checked };
    const preset = this.shown;
    const unchanged = preset?.creases && preset.degrees === settings.degrees && preset.minEdges === settings.minEdges && preset.closedOnly === settings.closedOnly;
    return unchanged ? preset : settings;
  }

  /** Says what a detection with `settings` found. */
  private showStats(settings: SharpSettings, found: SharpResult | CreaseResult): void {
    const n = (k: number, one: string, many: string) => `${k} ${k === 1 ? one : many}`;
    const { stats } = found;
    if (settings.creases && 'min_length_fraction' in found) {
      const percent = Math.round(100 * found.min_length_fraction);
      this.el.sharpStats.textContent = `Creases: ${n(stats.kept_edges, 'edge', 'edges')} on ${n(stats.curves, 'curve', 'curves')} (> ${found.degrees}°, at least ${percent} % of the diagonal long), ${n(stats.dropped_fragments, 'shorter curve', 'shorter curves')} dropped; the quads drop them where they fold the map`;
      return;
    }
    const pruned = stats.pruned_edges ? `, ${n(stats.pruned_edges, 'dangling edge', 'dangling edges')}` : '';
    this.el.sharpStats.textContent = `${n(stats.sharp_edges, 'sharp edge', 'sharp edges')}: ${n(stats.curves, 'curve', 'curves')} (${n(stats.kept_edges, 'edge', 'edges')}) kept, ${n(stats.dropped_fragments, 'fragment', 'fragments')}${pruned} dropped`;
  }

  private redraw(): void {
    const m = this.open;
    const ids = m?.features?.ids() ?? new Uint32Array(0);
    this.viewer.setLines('features', m?.edges ?? new Uint32Array(0), ids, COLORS.feature, 3.5, 1);
    this.updateUi();
  }

  private updateUi(): void {
    const f = this.open?.features ?? null;
    const n = f?.count ?? 0;
    this.hooks.features = n;
    this.el.count.textContent = fmtInt(n);
    this.el.count.title = `${n} feature edges marked`;
    this.el.boundaryCount.textContent = f ? `(${fmtInt(f.boundaryCount)})` : '';
    this.el.undo.disabled = !f?.canUndo;
    this.el.redo.disabled = !f?.canRedo;
    this.el.clear.disabled = !f || n === 0;
    this.el.sharpToggle.disabled = !f;
    this.el.creases.disabled = !f;
    this.el.exportButton.disabled = !f || n === 0;
    const importLabel = this.el.importInput.labels?.[0];
    this.el.importInput.disabled = !f;
    importLabel?.classList.toggle('disabled', !f);
  }

  private changed(did: boolean): void {
    if (!did) return;
    this.redraw();
    this.events.onChange();
  }

  /** After an undo or redo (`did`): the edges, and the detection controls as the change left them (the counts only while they still hold). */
  private stepped(did: boolean): void {
    if (!did) return;
    const settings = this.open?.features?.sharpSettings ?? null;
    if (JSON.stringify(settings) !== JSON.stringify(this.controlSettings())) this.el.sharpStats.textContent = '';
    this.showSharpSettings(settings);
    this.changed(true);
  }

  /** The first vertex of a Shift-click path (null: none), its marker and the hint saying what comes next. */
  private setAnchor(vertex: number | null): void {
    this.anchor = vertex;
    this.viewer.setAnchor(vertex);
    this.el.hint.textContent = vertex === null ? HINT : 'Shift-click the second vertex to mark the path; Esc cancels.';
    this.el.hint.classList.toggle('active', vertex !== null);
  }

  /** Highlights edge `e` under the pointer (-1: none). */
  private hover(e: number): void {
    if (e === this.hovered) return;
    this.hovered = e;
    this.hooks.hoverEdge = e >= 0 ? e : null;
    const m = this.open;
    this.viewer.setLines('hover-edge', m?.edges ?? new Uint32Array(0), e >= 0 ? [e] : [], COLORS.hover, 6, 3);
    this.viewer.canvas.style.cursor = e >= 0 ? 'pointer' : '';
  }

  private edgeFromPick(x: number, y: number): number {
    const m = this.open;
    if (!m?.features) return -1;
    const pick = this.viewer.pick(x, y);
    if (!pick || pick.sideDistance > PICK_TOLERANCE) return -1;
    const e = m.data.faceEdges[3 * pick.face + pick.side]!;
    return e === NO_EDGE ? -1 : e;
  }

  private click(x: number, y: number, shift: boolean): void {
    const m = this.open;
    if (!m?.features) return;
    if (shift) {
      const pick = this.viewer.pick(x, y);
      if (!pick) return;
      if (this.anchor === null) {
        this.setAnchor(pick.vertex);
        return;
      }
      const path = m.adjacency ? shortestPath(m.adjacency, m.data.positions, this.anchor, pick.vertex) : null;
      this.setAnchor(null);
      if (path) this.changed(m.features.addAll(path));
      return;
    }
    const e = this.edgeFromPick(x, y);
    if (e >= 0) this.changed(m.features.toggle(e));
  }

  private wirePicking(): void {
    const canvas = this.viewer.canvas;
    const hoverAt = latestPerFrame((e: PointerEvent) => this.hover(e.buttons === 0 && !e.shiftKey ? this.edgeFromPick(e.clientX, e.clientY) : -1));
    canvas.addEventListener('pointermove', hoverAt);
    canvas.addEventListener('pointerleave', () => requestAnimationFrame(() => this.hover(-1)));
    onClick(canvas, (e) => this.click(e.clientX, e.clientY, e.shiftKey));
  }

  /**
   * Queues a detection with the settings the controls show when its turn
   * comes (the detection of an unchanged setting is skipped); `drag`: part
   * of a slider drag (one undo step with the rest of it), `release` ends it.
   */
  private requestSharp(drag: boolean, release = false): void {
    this.sharpQueue = this.sharpQueue.then(async () => {
      await this.applySharp(drag);
      if (release) this.open?.features?.closeChange();
    });
  }

  /** Runs the detection the controls ask for on the open mesh and marks its edges (see `requestSharp`). */
  private async applySharp(drag: boolean): Promise<void> {
    const f = this.open?.features;
    if (!f) return;
    const settings = this.controlSettings();
    if (JSON.stringify(settings) === JSON.stringify(f.sharpSettings)) return;
    if (!settings) {
      this.el.sharpStats.textContent = '';
      this.changed(f.setSharp(null, null));
      return;
    }
    await this.detect(settings, drag);
  }

  /**
   * Marks the creases `conemap quads` follows by default instead of the
   * last detection's edges (one undo step; edges marked by hand stay), and
   * shows the preset's settings in the controls.
   */
  private requestCreases(): void {
    this.sharpQueue = this.sharpQueue.then(() => this.detect('creases', false));
  }

  /**
   * Runs a detection on the open mesh and marks its edges in place of the
   * last detection's (`drag`: part of a slider drag): with `wanted`, or the
   * creases preset, whose settings come with its answer and are shown in
   * the controls.
   */
  private async detect(wanted: SharpSettings | 'creases', drag: boolean): Promise<void> {
    const mesh = this.open;
    const f = mesh?.features;
    if (!f) return;
    try {
      let found: SharpResult | CreaseResult;
      let settings: SharpSettings;
      if (wanted === 'creases' || wanted.creases) {
        const creases = await this.worker.creaseEdges();
        [found, settings] = [creases, { degrees: creases.degrees, minEdges: 0, closedOnly: false, creases: true }];
      } else {
        [found, settings] = [await this.worker.sharpEdges(wanted.degrees, wanted.minEdges, wanted.closedOnly), wanted];
      }
      if (this.open !== mesh) return;
      if (settings.creases) this.showSharpSettings(settings);
      this.showStats(settings, found);
      this.changed(f.setSharp(found.edges, settings, drag));
    } catch (e) {
      const what = wanted === 'creases' ? 'creases' : 'sharp edges';
      if (!(e instanceof Cancelled)) this.events.onError(`${what}: ${e instanceof Error ? e.message : String(e)}`);
    }
  }

  /** Reads a features file or JSON report and marks the edges it names instead of the current ones (one undo step). */
  private async importFeatures(file: File): Promise<void> {
    const mesh = this.open;
    const f = mesh?.features;
    if (!f) return;
    try {
      const ids = await this.worker.featuresFromJson(await file.text());
      if (this.open !== mesh) return;
      this.showSharpSettings(null);
      this.changed(f.replaceAll(ids));
      this.el.sharpStats.textContent = `Imported ${fmtInt(ids.length)} feature ${ids.length === 1 ? 'edge' : 'edges'} from ${file.name}.`;
    } catch (e) {
      if (!(e instanceof Cancelled)) this.events.onError(`Could not import features from ${file.name}: ${e instanceof Error ? e.message : String(e)}`);
    }
  }

  /** Saves the marked edges as `{edges: [[[x, y, z], [x, y, z]], …]}`, the form `conemap solve --features` reads. */
  private exportFeatures(): void {
    const m = this.open;
    if (!m?.features) return;
    const p = m.data.positions;
    const at = (v: number): number[] => Array.from(p.subarray(3 * v, 3 * v + 3));
    const edges = Array.from(m.features.ids(), (e) => [at(m.edges[2 * e]!), at(m.edges[2 * e + 1]!)]);
    download(new Blob([JSON.stringify({ file: m.label, edges })], { type: 'application/json' }), `${fileStem(m.label)}-features.json`);
  }

  private wireControls(): void {
    const el = this.el;
    el.sharpToggle.addEventListener('change', () => {
      for (const c of [el.sharpAngle, el.sharpMinEdges, el.sharpClosed]) c.disabled = !el.sharpToggle.checked;
      this.requestSharp(false);
    });
    // Dragging the slider updates the marks as it goes: one undo step, ended on release.
    el.sharpAngle.addEventListener('input', () => {
      this.showAngle();
      this.requestSharp(true);
    });
    el.sharpAngle.addEventListener('change', () => this.requestSharp(true, true));
    el.sharpMinEdges.addEventListener('change', () => this.requestSharp(false));
    el.sharpClosed.addEventListener('change', () => this.requestSharp(false));
    el.creases.addEventListener('click', () => this.requestCreases());
    el.undo.addEventListener('click', () => this.stepped(this.open?.features?.undo() ?? false));
    el.redo.addEventListener('click', () => this.stepped(this.open?.features?.redo() ?? false));
    el.clear.addEventListener('click', () => {
      const did = this.open?.features?.clear() ?? false;
      this.showSharpSettings(null);
      this.el.sharpStats.textContent = '';
      this.changed(did);
    });
    el.importInput.addEventListener('change', () => {
      const file = el.importInput.files?.[0];
      el.importInput.value = ''; // choosing the same file again still fires `change`
      if (file) void this.importFeatures(file);
    });
    el.exportButton.addEventListener('click', () => this.exportFeatures());
    window.addEventListener('keydown', (e) => {
      const target = e.target as HTMLElement | null;
      if (target && (target.tagName === 'INPUT' && (target as HTMLInputElement).type === 'text')) return;
      const key = e.key.toLowerCase();
      if ((e.ctrlKey || e.metaKey) && key === 'z') {
        e.preventDefault();
        this.stepped((e.shiftKey ? this.open?.features?.redo() : this.open?.features?.undo()) ?? false);
      } else if ((e.ctrlKey || e.metaKey) && key === 'y') {
        e.preventDefault();
        this.stepped(this.open?.features?.redo() ?? false);
      } else if (key === 'escape' && this.anchor !== null) {
        this.setAnchor(null);
      }
    });
  }

  // ---- queries for the test hooks ----------------------------------------

  /** Position of vertex `v` of the open mesh, or null. */
  vertexPosition(v: number): [number, number, number] | null {
    const p = this.open?.data.positions;
    if (!p || v < 0 || 3 * v + 2 >= p.length) return null;
    return [p[3 * v]!, p[3 * v + 1]!, p[3 * v + 2]!];
  }

  /** End vertices of edge `e` of the open mesh, or null. */
  edgeEnds(e: number): [number, number] | null {
    const m = this.open;
    if (!m || e < 0 || 2 * e + 1 >= m.edges.length) return null;
    return [m.edges[2 * e]!, m.edges[2 * e + 1]!];
  }

  /** Page position of vertex `v` (client CSS px), or null. */
  projectVertex(v: number): { x: number; y: number } | null {
    const q = this.vertexPosition(v);
    return q ? this.viewer.projectPoint(q[0], q[1], q[2]) : null;
  }

  /** Page position of the midpoint of edge `e` (client CSS px), or null. */
  projectEdge(e: number): { x: number; y: number } | null {
    const ends = this.edgeEnds(e);
    const a = ends && this.vertexPosition(ends[0]);
    const b = ends && this.vertexPosition(ends[1]);
    return a && b ? this.viewer.projectPoint((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2) : null;
  }

  /** Edge id a click at page position (x, y) would toggle; -1 when none. */
  edgeAt(x: number, y: number): number {
    return this.edgeFromPick(x, y);
  }

  /** An interior, unmarked edge whose midpoint is visible and picks back to itself; -1 if none. */
  visibleEdge(): number {
    const m = this.open;
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
