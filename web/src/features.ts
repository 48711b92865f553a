// Feature edges chosen by the user: one flag per edge, boundary edges fixed,
// undo/redo of every change (a change is the list of edges whose flag flipped).

export class FeatureSet {
  readonly flags: Uint8Array;
  readonly boundary: Uint8Array;
  /** Edges set by the last sharp-edge threshold (replaced when it changes). */
  private sharp: Uint8Array;
  private undoStack: Uint32Array[] = [];
  private redoStack: Uint32Array[] = [];
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

  private flip(edges: Uint32Array): void {
    for (const e of edges) {
      this.flags[e] ^= 1;
      this.n += this.flags[e] ? 1 : -1;
    }
  }

  /** Applies a change (edges to flip); returns false when it changes nothing. */
  private commit(edges: number[]): boolean {
    if (edges.length === 0) return false;
    const change = Uint32Array.from(edges);
    this.flip(change);
    this.undoStack.push(change);
    this.redoStack = [];
    return true;
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

  /** Replaces the edges of the previous sharp threshold by `edges` (keeps edges marked by hand). */
  setSharp(edges: Uint32Array | null): boolean {
    const next = new Uint8Array(this.edgeCount);
    if (edges) for (const e of edges) if (!this.boundary[e]) next[e] = 1;
    const change: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) {
      const want = next[e] ? 1 : this.sharp[e] ? 0 : this.flags[e]!;
      if (want !== this.flags[e]) change.push(e);
    }
    this.sharp = next;
    return this.commit(change);
  }

  clear(): boolean {
    const change: number[] = [];
    for (let e = 0; e < this.edgeCount; e++) if (this.flags[e]) change.push(e);
    this.sharp.fill(0);
    return this.commit(change);
  }

  undo(): boolean {
    const change = this.undoStack.pop();
    if (!change) return false;
    this.flip(change);
    this.redoStack.push(change);
    return true;
  }

  redo(): boolean {
    const change = this.redoStack.pop();
    if (!change) return false;
    this.flip(change);
    this.undoStack.push(change);
    return true;
  }

  /** Marked edge ids, ascending. */
  ids(): Uint32Array {
    const out = new Uint32Array(this.n);
    let j = 0;
    for (let e = 0; e < this.edgeCount; e++) if (this.flags[e]) out[j++] = e;
    return out;
  }
}
