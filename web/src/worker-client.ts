// Page side of the worker protocol: promises for results, progress callbacks,
// automatic replacement of a worker that crashed or died, and cancellation
// (terminate + fresh worker). The worker keeps the open mesh as a session; after
// any replacement the client re-opens the last mesh in the new worker from a
// kept copy of its file bytes, so later requests keep working.
//
// Solves run in steps (see protocol.ts): on large meshes a short-lived helper
// worker opens the same mesh and places some of the cut mesh's components
// (they are independent), which halves the cone stage on two cores. Quads are
// asked of the worker that finished the solve (its session keeps the map).
import type { CreaseResult, ErrorLocation, ImportResult, QuadsResult, Request, Response, SharpResult, SolveBegun, SolveResult, Stage, WireFile } from './protocol';
import type { SolveTuning } from './state';

export class WorkerCrashed extends Error {
  override name = 'WorkerCrashed';
}

export class Cancelled extends Error {
  override name = 'Cancelled';
}

/** A solve error that names mesh elements: `location` has their ids (see protocol.ts). */
export class LocatedError extends Error {
  override name = 'LocatedError';
  constructor(
    message: string,
    readonly location: ErrorLocation,
  ) {
    super(message);
  }
}

/** A progress report: the stage, two counters, and the share of the stage done (0..1) where the library knows it. */
export type ProgressFn = (stage: string, step?: number, remaining?: number, fraction?: number) => void;

interface Pending {
  resolve: (value: unknown) => void;
  reject: (e: Error) => void;
  onProgress: ProgressFn;
}

type Body = Request extends infer R ? (R extends { id: number } ? Omit<R, 'id'> : never) : never;

const copyFiles = (files: WireFile[]): WireFile[] => files.map((f) => ({ name: f.name, bytes: f.bytes.slice(0) }));

/** A helper worker taking part in one solve. */
interface Helper {
  worker: MeshWorker;
  /** Resolves once it has opened the mesh and begun the same solve. */
  ready: Promise<void>;
}

export class MeshWorker {
  private worker: Worker;
  private nextId = 1;
  private pending = new Map<number, Pending>();
  /** Copy of the files of the mesh open in the worker (for re-opening in a new worker). */
  private openFiles: WireFile[] | null = null;
  private openFaces = 0;
  /** The helper of the solve in progress. */
  private helper: MeshWorker | null = null;
  /** Terminated for good (helpers are never replaced). */
  private disposed = false;
  /** `restarts` when the last solve finished in this worker (null: no solve since the mesh was opened). */
  private solvedIn: number | null = null;
  /** How many times a dead worker was replaced (for the test hooks). */
  restarts = 0;

  /** `replaceOnFailure`: spawn a fresh worker (re-opening the mesh) when this one dies or is cancelled. */
  constructor(private readonly replaceOnFailure = true) {
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
    if (!this.replaceOnFailure) {
      this.disposed = true;
      for (const p of owed) p.reject(reason);
      return;
    }
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
    this.dropHelper();
    this.replace(new Cancelled('cancelled'));
  }

  private dropHelper(): void {
    this.helper?.replace(new Cancelled('the solve ended'));
    this.helper = null;
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
        p.onProgress(msg.stage, msg.step, msg.remaining, msg.fraction);
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
          p.reject(msg.location ? new LocatedError(msg.message, msg.location) : new Error(msg.message));
        }
        break;
    }
  }

  private send<T>(body: Body, transfer: Transferable[] = [], onProgress: ProgressFn = () => {}): Promise<T> {
    const id = this.nextId++;
    const request = { ...body, id } as Request;
    if (this.disposed) return Promise.reject(new Cancelled('this worker was stopped'));
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
    this.openFaces = result.indices.length / 3;
    this.solvedIn = null;
    return result;
  }

  /**
   * Ids of the interior edges of the open mesh sharper than `degrees`,
   * without curves of fewer than `minEdges` edges (0: all) and, when
   * `closedOnly`, without dangling ends; with the detection's counts.
   */
  sharpEdges(degrees: number, minEdges = 0, closedOnly = false): Promise<SharpResult> {
    return this.send<SharpResult>({ type: 'sharp', degrees, minEdges, closedOnly });
  }

  /** The creases `conemap quads` follows by default on the open mesh, with the detection's counts and settings. */
  creaseEdges(): Promise<CreaseResult> {
    return this.send<CreaseResult>({ type: 'creases' });
  }

  /** Edge ids of the open mesh that a features file or JSON report (`text`) names by position; rejects saying what does not match. */
  featuresFromJson(text: string): Promise<Uint32Array> {
    return this.send<Uint32Array>({ type: 'features-from-json', text });
  }

  /**
   * Cones and UVs for the open mesh, in steps: begin, place every component
   * (some in a helper worker on large meshes), finish. Progress comes from this
   * worker (and from the helper once this one has nothing left to place).
   * `tuning` says when a helper is used and how hard the cone placement tries.
   * `creases`: those of `features` that the creases preset found (see
   * `creaseEdges`): the quads drop them where they fold the map.
   */
  async solve(features: Uint32Array, creases: Uint32Array, alphaSmooth: number, miq: boolean, onProgress: ProgressFn, freeBoundary: boolean, tuning: Readonly<SolveTuning>): Promise<SolveResult> {
    const generation = this.restarts;
    this.solvedIn = null; // a solve begun drops the session's last map, whatever its outcome
    /** Throws `Cancelled` once this worker was replaced (cancel or crash) since the solve began. */
    const alive = (): void => {
      if (this.restarts !== generation) throw new Cancelled('cancelled');
    };
    const { schedule } = await this.send<SolveBegun>({ type: 'solve-begin', features, creases, alphaSmooth, miq, freeBoundary, maxConeRefinements: tuning.maxConeRefinements }, [], onProgress);
    const queue = Array.from(schedule);
    const total = schedule.length;
    const helper = this.startHelper(features, alphaSmooth, miq, freeBoundary, schedule, tuning.helperMinFaces);
    let ownDone = false;
    let helperBusy = false;
    let placed = 0;
    let helped = 0;
    const leftover: number[] = [];
    // Every request opens with a 'starting' report: not news in the middle of
    // a solve. Components go largest first, to two workers: 'topology'
    // reports count the components placed so far rather than naming one.
    const placing: ProgressFn = (stage, step, remaining, fraction) => {
      if (stage === 'starting') return;
      if (stage === 'topology') onProgress(stage, Math.min(placed, total - 1), total);
      else onProgress(stage, step, remaining, fraction);
    };
    const own = async (): Promise<void> => {
      if (helper && tuning.helperWait) await helper.ready.catch(() => {});
      alive();
      for (let c = queue.shift(); c !== undefined; c = queue.shift()) {
        await this.send({ type: 'solve-place', component: c, share: false }, [], placing);
        placed++;
      }
      ownDone = true;
      // A helper still starting up would only make the solve wait for it.
      if (helper && !helperBusy && this.helper === helper.worker) this.dropHelper();
    };
    const help = async (h: Helper): Promise<void> => {
      const progress: ProgressFn = (...a) => ownDone && placing(...a);
      try {
        await h.ready;
        for (let c = queue.shift(); c !== undefined; c = queue.shift()) {
          helperBusy = true;
          try {
            const { bytes } = await h.worker.send<{ bytes: Uint8Array }>({ type: 'solve-place', component: c, share: true }, [], progress);
            await this.send({ type: 'solve-add', bytes }, [bytes.buffer]);
            helped++;
            placed++;
          } catch (e) {
            leftover.push(c);
            throw e;
          } finally {
            helperBusy = false;
          }
        }
      } catch (e) {
        if (!(e instanceof Cancelled)) {
          console.warn(`conemap: the helper worker stopped (${e instanceof Error ? e.message : String(e)}); the main worker places the rest`);
        }
      } finally {
        if (this.helper === h.worker) this.dropHelper();
      }
    };
    try {
      await Promise.all([own(), helper ? help(helper) : null]);
      for (const c of leftover) {
        alive();
        await this.send({ type: 'solve-place', component: c, share: false }, [], placing);
      }
      alive();
      const result = await this.send<SolveResult>({ type: 'solve-finish' }, [], placing);
      this.solvedIn = this.restarts;
      return { ...result, helperComponents: helped };
    } finally {
      if (helper && this.helper === helper.worker) this.dropHelper();
    }
  }

  /**
   * The integer-grid map and quad mesh of the last solve for about `quads`
   * grid cells, from the worker whose session finished it (only quantization
   * and extraction run, or, on a mesh much finer than its quads, a decimation
   * and its solve). Rejects when the last solve did not succeed, or the
   * worker was replaced since (its session, and the map, are gone), and with the
   * library's error when quantization fails; `onProgress` gets the stages
   * 'decimation', the solve's, 'quantization' (forms rounded, forms) and
   * 'quad extraction'.
   */
  quads(quads: number, onProgress: ProgressFn = () => {}): Promise<QuadsResult> {
    if (this.solvedIn !== this.restarts) {
      return Promise.reject(new Error('the solver holds no solved map (a solve since failed, was cancelled, or the worker was restarted): Run again to get quads'));
    }
    return this.send<QuadsResult>({ type: 'quads', quads }, [], onProgress);
  }

  /** A helper for a solve of `schedule`'s components, or null when one would not pay (fewer than `minFaces` faces, one component, one core). */
  private startHelper(features: Uint32Array, alphaSmooth: number, miq: boolean, freeBoundary: boolean, schedule: Uint32Array, minFaces: number): Helper | null {
    const cores = typeof navigator === 'undefined' ? 2 : (navigator.hardwareConcurrency ?? 2);
    if (schedule.length < 2 || this.openFaces < minFaces || !this.openFiles || cores < 2) return null;
    this.dropHelper();
    const worker = new MeshWorker(false);
    const files = copyFiles(this.openFiles);
    const ready = (async () => {
      await worker.send({ type: 'import', files, quiet: true }, files.map((f) => f.bytes));
      const begun = await worker.send<SolveBegun>({ type: 'solve-begin', features, alphaSmooth, miq, freeBoundary });
      if (begun.schedule.length !== schedule.length || begun.schedule.some((c, i) => c !== schedule[i])) {
        throw new Error('the helper sees a different mesh');
      }
    })();
    this.helper = worker;
    return { worker, ready };
  }
}
