// Page side of the worker protocol: one request at a time per call, promises
// for results, automatic replacement of a worker that crashed or died.
import type { ImportResult, Request, Response, Stage, WireFile } from './protocol';

export class WorkerCrashed extends Error {
  override name = 'WorkerCrashed';
}

interface Pending {
  resolve: (r: ImportResult) => void;
  reject: (e: Error) => void;
  onProgress: (stage: Stage) => void;
}

export class MeshWorker {
  private worker: Worker;
  private nextId = 1;
  private pending = new Map<number, Pending>();
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
      this.replace(`the worker failed: ${e.message || 'unknown error'}`);
    };
    w.onmessageerror = () => this.replace('the worker sent a message that could not be read');
    return w;
  }

  /** Terminates the current worker, fails everything it still owed, starts a fresh one. */
  private replace(reason: string): void {
    this.worker.terminate();
    this.restarts++;
    const owed = [...this.pending.values()];
    this.pending.clear();
    this.worker = this.spawn();
    for (const p of owed) p.reject(new WorkerCrashed(reason));
  }

  private onMessage(msg: Response): void {
    const p = this.pending.get(msg.id);
    if (!p) return;
    switch (msg.type) {
      case 'progress':
        p.onProgress(msg.stage);
        break;
      case 'result': {
        this.pending.delete(msg.id);
        const { id: _id, type: _type, ...result } = msg;
        p.resolve(result);
        break;
      }
      case 'error':
        this.pending.delete(msg.id);
        if (msg.fatal) {
          p.reject(new WorkerCrashed(msg.message));
          this.replace(msg.message);
        } else {
          p.reject(new Error(msg.message));
        }
        break;
    }
  }

  /** Imports a mesh. The files' buffers are transferred to the worker (they become detached here). */
  importMesh(files: WireFile[], onProgress: (stage: Stage) => void = () => {}, simulateTrap = false): Promise<ImportResult> {
    const id = this.nextId++;
    const request: Request = { id, type: 'import', files, ...(simulateTrap ? { simulateTrap } : {}) };
    return new Promise<ImportResult>((resolve, reject) => {
      this.pending.set(id, { resolve, reject, onProgress });
      this.worker.postMessage(request, [...new Set(files.map((f) => f.bytes))]);
    });
  }
}
