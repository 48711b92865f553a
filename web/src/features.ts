// Feature edges chosen by the user: one flag per edge, boundary edges fixed,
// undo/redo of every change (a change is the list of edges whose flag flipped,
// with the sharp-edge detection settings before and after it).

/** The sharp-edge detection settings a change was made with (null: detection off). */
export interface SharpSettings {
  degrees: number;
  minEdges: number;
  closedOnly: boolean;
  /** The creases preset (`MeshSession.crease_edges`; `degrees` is its threshold): the quads may drop these edges. */
  creases?: true;
}

/** One undoable change: the edges flipped, the sharp edges and settings before and after; `open` while a slider drag may extend it. */
interface Change {
  edges: Uint32Array;
  sharpBefore: Uint8Array;
  sharpAfter: Uint8Array;
  settingsBefore: SharpSettings | null;
  settingsAfter: SharpSettings | null;
  open: boolean;
}

export class FeatureSet {
  readonly flags: Uint8Array;
  readonly boundary: Uint8Array;
  /** Edges set by the last sharp-edge threshold (replaced when it changes). */
  private sharp: Uint8Array;
  /** The detection settings of the current marks (restored by undo and redo). */
  private settings: SharpSettings | null = null;
  private undoStack: Change[] = [];
  private redoStack: Change[] = [];
  private n = 0;
  readonly boundaryCount: number;

  constructor(readonly edgeCount: number, boundary: Uint32Array) {
    this.flags = new Uint8Array(edgeCount);
    this.boundary = new Uint8Array(edgeCount);
    this.sharp = new Uint8Array(edgeCount);
    for (const e of boundary) this.boundary[e] = 1;
    this.boundaryCount = boundary.length;
  }

  /** Number of marked (interior) feature edges. */
  get count(): number {
    return this.n;
  }

  get canUndo(): boolean {
    return this.undoStack.length > 0;
  }

  get canRedo(): boolean {
    return this.redoStack.length > 0;
  }

  has(e: number): boolean {
    return this.flags[e] === 1;
  }

  /** The sharp-edge detection settings of the current marks (null: off). */
  get sharpSettings(): SharpSettings | null {
    return this.settings;
  }

  private flip(edges: Uint32Array): void {
    for (const e of edges) {
      this.flags[e] ^= 1;
      this.n += this.flags[e] ? 1 : -1;
    }
  }

  /**
   * Applies a change (edges to flip, the sharp edges and settings after it);
   * with `extend`, merges it into the last change while that one is open (a
   * slider drag). Returns false when it changes nothing.
   */
  private commit(edges: number[], sharpAfter = this.sharp, settingsAfter = this.settings, extend = false): boolean {
    const sameSettings = JSON.stringify(settingsAfter) === JSON.stringify(this.settings);
    if (edges.length === 0 && sameSettings) return false;
    const flipped = Uint32Array.from(edges);
    this.flip(flipped);
    const last = this.undoStack[this.undoStack.length - 1];
    if (extend && last?.open && this.redoStack.length === 0) {
      // Edges flipped twice over the drag cancel out.
      const odd = new Set<number>(last.edges);
      for (const e of flipped) if (!odd.delete(e)) odd.add(e);
      last.edges = Uint32Array.from(odd);
      last.sharpAfter = sharpAfter;
      last.settingsAfter = settingsAfter;
    } else {
      this.closeChange();
      this.undoStack.push({ edges: flipped, sharpBefore: this.sharp, sharpAfter, settingsBefore: this.settings, settingsAfter, open: extend });
      this.redoStack = [];
    }
    this.sharp = sharpAfter;
    this.settings = settingsAfter;
    return true;
  }

  /** Ends the open change (a slider drag released): later changes are undone separately. */
  closeChange(): void {
    const last = this.undoStack[this.undoStack.length - 1];
    if (last) last.open = false;
  }

  /** Toggles one edge; boundary edges cannot be toggled. */
  toggle(e: number): boolean {
    if (e < 0 || e >= this.edgeCount || this.boundary[e]) return false;
    return this.commit([e]);
  }

  /** Marks all of `edges` (a shortest path) as features. */
  addAll(edges: Iterable<number>): boolean {
    const change: number[] = [];
    for (const e of edges) if (!this.boundary[e] && !this.flags[e] && !change.includes(e)) change.push(e);
    return this.commit(change);
  }

  /**
   * Replaces the edges of the previous sharp threshold by `edges` (keeps
   * edges marked by hand), found with `settings` (null: detection off);
   * `drag`: part of a slider drag, one undo step with the rest of it.
   */
  setSharp(edges: Uint32Array | null, settings: SharpSettings | null = null, drag = false): boolean {
    const next = new Uint8Array(this.edgeCount);
    if (edges) for (const e of edges) if (!this.boundary[e]) next[e] = 1;
    const change: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) {
      const want = next[e] ? 1 : this.sharp[e] ? 0 : this.flags[e]!;
      if (want !== this.flags[e]) change.push(e);
    }
    return this.commit(change, next, settings, drag);
  }

  /** Unmarks every edge and turns the detection off. */
  clear(): boolean {
    const change: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) if (this.flags[e]) change.push(e);
    return this.commit(change, new Uint8Array(this.edgeCount), null);
  }

  /** Replaces every mark by `edges` (an imported list; detection off). */
  replaceAll(edges: Uint32Array): boolean {
    const want = new Uint8Array(this.edgeCount);
    for (const e of edges) if (e < this.edgeCount && !this.boundary[e]) want[e] = 1;
    const change: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) if (want[e] !== this.flags[e]) change.push(e);
    return this.commit(change, new Uint8Array(this.edgeCount), null);
  }

  /** Undoes the last change (its marks, sharp edges and settings); false when there is none. */
  undo(): boolean {
    const change = this.undoStack.pop();
    if (!change) return false;
    change.open = false;
    this.flip(change.edges);
    this.sharp = change.sharpBefore;
    this.settings = change.settingsBefore;
    this.redoStack.push(change);
    return true;
  }

  /** Redoes the last undone change; false when there is none. */
  redo(): boolean {
    const change = this.redoStack.pop();
    if (!change) return false;
    this.flip(change.edges);
    this.sharp = change.sharpAfter;
    this.settings = change.settingsAfter;
    this.undoStack.push(change);
    return true;
  }

  /** Marked edge ids found by the creases preset (still marked and the preset in use), ascending. */
  creaseIds(): Uint32Array {
    if (!this.settings?.creases) return new Uint32Array(0);
    const out: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) if (this.sharp[e] && this.flags[e]) out.push(e);
    return Uint32Array.from(out);
  }

  /** Marked edge ids, ascending. */
  ids(): Uint32Array {
    const out = new Uint32Array(this.n);
    let j = 0;
    for (let e = 0; e < this.edgeCount; e++) if (this.flags[e]) out[j++] = e;
    return out;
  }
}
