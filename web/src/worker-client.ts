// Page side of the worker protocol: promises for results, progress callbacks,
// automatic replacement of a worker that crashed or died, and cancellation
// (terminate + fresh worker). The worker keeps the open mesh as a session; after
// any replacement the client re-opens the last mesh in the new worker from a
// kept copy of its file bytes, so later requests keep working.
import type { ImportResult, Request, Response, SharpResult, SolveResult, Stage, WireFile } from './protocol';

export class WorkerCrashed extends Error {
  override name = 'WorkerCrashed';
}

export class Cancelled extends Error {
  override name = 'Cancelled';
}

export type ProgressFn = (stage: string, step?: number, remaining?: number) => void;

interface Pending {
  resolve: (value: unknown) => void;
  reject: (e: Error) => void;
  onProgress: ProgressFn;
}

type Body = Request extends infer R ? (R extends { id: number } ? Omit<R, 'id'> : never) : never;

const copyFiles = (files: WireFile[]): WireFile[] => files.map((f) => ({ name: f.name, bytes: f.bytes.slice(0) }));

export class MeshWorker {
  private worker: Worker;
  private nextId = 1;
  private pending = new Map<number, Pending>();
  /** Copy of the files of the mesh open in the worker (for re-opening in a new worker). */
  private openFiles: WireFile[] | null = null;
  /** How many times a dead worker was replaced (for the test hooks). */
  restarts = 0;

  constructor() {
    this.worker = this.spawn();
  }

  private spawn(): Worker {
    const w = new Worker(new URL('./worker.js', import.meta.url), { type: 'module', name: 'conemap-wasm' });
    w.onmessage = (e: MessageEvent<Response>) => this.onMessage(e.data);
    w.onerror = (e: ErrorEvent) => {
      e.preventDefault();
      this.replace(new WorkerCrashed(`the worker failed: ${e.message || 'unknown error'}`));
    };
    w.onmessageerror = () => this.replace(new WorkerCrashed('the worker sent a message that could not be read'));
    return w;
  }

  /** Terminates the current worker, fails everything it still owed, starts a fresh one with the open mesh. */
  private replace(reason: Error): void {
    this.worker.terminate();
    this.restarts++;
    const owed = [...this.pending.values()];
    this.pending.clear();
    this.worker = this.spawn();
    if (this.openFiles) {
      // Re-open the current mesh quietly; requests sent after this one wait for it in the worker.
      const files = copyFiles(this.openFiles);
      this.send({ type: 'import', files, quiet: true }, files.map((f) => f.bytes)).catch((e: unknown) => {
        console.warn(`conemap: could not re-open the mesh in the new worker: ${e instanceof Error ? e.message : String(e)}`);
        this.openFiles = null;
      });
    }
    for (const p of owed) p.reject(reason);
  }

  /** Stops whatever the worker is doing (the pending requests reject with `Cancelled`). */
  cancel(): void {
    this.replace(new Cancelled('cancelled'));
  }

  /** True while a request is in flight. */
  get busy(): boolean {
    return this.pending.size > 0;
  }

  private onMessage(msg: Response): void {
    const p = this.pending.get(msg.id);
    if (!p) return;
    switch (msg.type) {
      case 'progress':
        p.onProgress(msg.stage, msg.step, msg.remaining);
        break;
      case 'result':
        this.pending.delete(msg.id);
        p.resolve(msg.value);
        break;
      case 'error':
        this.pending.delete(msg.id);
        if (msg.fatal) {
          p.reject(new WorkerCrashed(msg.message));
          this.replace(new WorkerCrashed(msg.message));
        } else {
          p.reject(new Error(msg.message));
        }
        break;
    }
  }

  private send<T>(body: Body, transfer: Transferable[] = [], onProgress: ProgressFn = () => {}): Promise<T> {
    const id = this.nextId++;
    const request = { ...body, id } as Request;
    return new Promise<T>((resolve, reject) => {
      this.pending.set(id, { resolve: resolve as (v: unknown) => void, reject, onProgress });
      this.worker.postMessage(request, [...new Set(transfer)]);
    });
  }

  /** Imports a mesh and keeps it open in the worker. The files' buffers are transferred (detached here). */
  async importMesh(files: WireFile[], onProgress: (stage: Stage) => void = () => {}, simulateTrap = false): Promise<ImportResult> {
    const kept = copyFiles(files);
    const result = await this.send<ImportResult>(
      { type: 'import', files, ...(simulateTrap ? { simulateTrap } : {}) },
      files.map((f) => f.bytes),
      (stage) => onProgress(stage as Stage),
    );
    this.openFiles = kept;
    return result;
  }

  /** Ids of the interior edges of the open mesh sharper than `degrees`. */
  sharpEdges(degrees: number): Promise<SharpResult> {
    return this.send<SharpResult>({ type: 'sharp', degrees });
  }

  /** Cones (and UVs when the build can) for the open mesh. */
  solve(features: Uint32Array, alphaSmooth: number, miq: boolean, onProgress: ProgressFn): Promise<SolveResult> {
    return this.send<SolveResult>({ type: 'solve', features, alphaSmooth, miq }, [], onProgress);
  }
}
