// Feature editing on the open mesh: click an edge to toggle it, Shift-click two
// vertices to mark the shortest path between them, the sharp-edge detection
// controls, undo / redo / clear (buttons and keys); and the queries of the open
// mesh's geometry the test hooks answer with.
import { $, fmtInt } from './dom';
import { FeatureSet } from './features';
import { COLORS } from './palette';
import type { ImportResult } from './protocol';
import { onClick } from './render-loop';
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
const PICK_TOLERANCE = 24;

export class FeatureEditor {
  private open: OpenMesh | null = null;
  /** First vertex of a Shift-click path, until the second. */
  private anchor: number | null = null;
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
  };

  constructor(
    private readonly viewer: Viewer,
    private readonly worker: MeshWorker,
    private readonly hooks: Pick<Hooks, 'features'>,
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
    this.anchor = null;
    this.el.sharpToggle.checked = false;
    this.el.sharpAngle.disabled = true;
    this.el.sharpMinEdges.disabled = true;
    this.el.sharpClosed.disabled = true;
    this.el.sharpStats.textContent = '';
    if (features) this.viewer.setLines('boundary', edges, data.boundary, COLORS.boundary, 3, 0);
    this.redraw();
  }

  /** The sharp-edge threshold in use (degrees), or null when detection is off. */
  sharpThreshold(): number | null {
    return this.el.sharpToggle.checked ? Number(this.el.sharpAngle.value) : null;
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
  }

  private changed(did: boolean): void {
    if (!did) return;
    this.redraw();
    this.events.onChange();
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
    onClick(this.viewer.canvas, (e) => this.click(e.clientX, e.clientY, e.shiftKey));
  }

  private async applySharp(): Promise<void> {
    const f = this.open?.features;
    if (!f) return;
    const mesh = this.open;
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
      if (this.open !== mesh || !this.el.sharpToggle.checked || Number(this.el.sharpAngle.value) !== deg) return;
      const n = (k: number, one: string, many: string) => `${k} ${k === 1 ? one : many}`;
      const pruned = stats.pruned_edges ? `, ${n(stats.pruned_edges, 'dangling edge', 'dangling edges')}` : '';
      this.el.sharpStats.textContent = `${n(stats.sharp_edges, 'sharp edge', 'sharp edges')}: ${n(stats.curves, 'curve', 'curves')} (${n(stats.kept_edges, 'edge', 'edges')}) kept, ${n(stats.dropped_fragments, 'fragment', 'fragments')}${pruned} dropped`;
      this.changed(f.setSharp(edges));
    } catch (e) {
      if (!(e instanceof Cancelled)) this.events.onError(`sharp edges: ${e instanceof Error ? e.message : String(e)}`);
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
    el.undo.addEventListener('click', () => this.changed(this.open?.features?.undo() ?? false));
    el.redo.addEventListener('click', () => this.changed(this.open?.features?.redo() ?? false));
    el.clear.addEventListener('click', () => {
      el.sharpToggle.checked = false;
      el.sharpAngle.disabled = true;
      this.changed(this.open?.features?.clear() ?? false);
    });
    window.addEventListener('keydown', (e) => {
      const target = e.target as HTMLElement | null;
      if (target && (target.tagName === 'INPUT' && (target as HTMLInputElement).type === 'text')) return;
      const key = e.key.toLowerCase();
      if ((e.ctrlKey || e.metaKey) && key === 'z') {
        e.preventDefault();
        this.changed((e.shiftKey ? this.open?.features?.redo() : this.open?.features?.undo()) ?? false);
      } else if ((e.ctrlKey || e.metaKey) && key === 'y') {
        e.preventDefault();
        this.changed(this.open?.features?.redo() ?? false);
      } else if (key === 'escape' && this.anchor !== null) {
        this.anchor = null;
        this.viewer.setAnchor(null);
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
