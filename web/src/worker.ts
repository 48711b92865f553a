// Module Web Worker: the only place the wasm runs. Receives `Request`s, answers
// with `Response`s (see protocol.ts); result buffers are transferred, not copied.
// Keeps the last opened mesh as a `MeshSession` so that sharp-edge queries and
// solves do not re-import it, and quads re-use the session's last solve.
import init, { MeshSession, default_alpha, version } from '@conemap/wasm';
import { MAX_WIREFRAME_FACES, uniqueEdges } from './edges';
import type { CreaseResult, ErrorLocation, ImportResult, MeshReport, QuadsResult, Request, Response, SharpResult, SolveResult, SolveView, WasmSolveResult } from './protocol';
import { buildSolveView, viewBuffers } from './solve-view';
import { buildAdjacency, faceEdges } from './topology';

interface WorkerScope {
  onmessage: ((event: MessageEvent<Request>) => void) | null;
  postMessage(message: Response, transfer?: Transferable[]): void;
}
const scope = self as unknown as WorkerScope;

let ready: Promise<unknown> | null = null;
const wasmReady = (): Promise<unknown> =>
  (ready ??= init({ module_or_path: new URL('./pkg/conemap_bg.wasm', import.meta.url) }));

/** A progress report: the stage, two counters, and the share of the stage done where the library knows it. */
type Progress = (stage: string, step: number, remaining: number, fraction?: number) => void;
/** The session API as the page uses it. */
interface Session {
  report(): MeshReport;
  is_valid(): boolean;
  positions(): Float32Array;
  indices(): Uint32Array;
  edges(): Uint32Array;
  boundary_edges(): Uint32Array;
  sharp_edges(degrees: number): Uint32Array;
  sharp_curves(degrees: number, minEdges: number, closedOnly: boolean): SharpResult;
  crease_edges(): CreaseResult;
  features_from_json(text: string): Uint32Array;
  /** `alpha` undefined: the library's default for `miq` (`default_alpha`). */
  solve_begin(features: Uint32Array, alpha: number | undefined, miq: boolean, creases: Uint32Array | undefined): Uint32Array;
  set_max_cone_refinements(n: number | undefined): void;
  set_free_boundary(free: boolean): void;
  solve_place(component: number, share: boolean, progress: Progress): Uint8Array | undefined;
  solve_add(bytes: Uint8Array): void;
  solve_finish(progress: Progress): WasmSolveResult;
  /** The integer-grid map and quad mesh of the last solve for about `quads` cells; throws before a solve. */
  quads(quads: number, progress: Progress): QuadsResult;
  free(): void;
}
let session: Session | null = null;

/** A request's result and the buffers to transfer with it. */
type Answer = { value: unknown; transfer: Transferable[] };

function post(message: Response, transfer: Transferable[] = []): void {
  scope.postMessage(message, transfer);
}

function errorMessage(e: unknown): string {
  if (e instanceof Error) return e.message || e.name;
  return String(e);
}

/** The `location` a solve error of the wasm carries (`{vertices, edges}`, see protocol.ts), or null. */
function errorLocation(e: unknown): ErrorLocation | null {
  const loc = (e as { location?: unknown } | null)?.location as Partial<ErrorLocation> | undefined;
  const ids = (a: unknown): a is number[] => Array.isArray(a) && a.every((x) => Number.isInteger(x) && x >= 0);
  if (!loc || !ids(loc.vertices) || !ids(loc.edges)) return null;
  return { vertices: loc.vertices, edges: loc.edges };
}

function openMesh(req: Extract<Request, { type: 'import' }>): Answer {
  const { id } = req;
  post({ id, type: 'progress', stage: 'parsing' });
  const files = req.files.map((f) => ({ name: f.name, bytes: new Uint8Array(f.bytes) }));
  const t0 = performance.now();
  if (req.simulateTrap) throw new WebAssembly.RuntimeError('unreachable (simulated trap)');
  const next = MeshSession.open(files) as unknown as Session;
  session?.free();
  session = next;
  if (req.quiet) return { value: null, transfer: [] };
  const positions = next.positions();
  const indices = next.indices();
  const report = next.report();
  const valid = next.is_valid();
  const t1 = performance.now();
  post({ id, type: 'progress', stage: 'analysing' });
  const faces = indices.length / 3;
  const vertexCount = positions.length / 3;
  let edges: Uint32Array | null = null;
  let boundary: Uint32Array = new Uint32Array(0);
  let faceEdgeIds: Uint32Array = new Uint32Array(0);
  let adjacency: ImportResult['adjacency'] = null;
  if (valid) {
    edges = next.edges();
    boundary = next.boundary_edges();
    adjacency = buildAdjacency(edges, vertexCount);
    faceEdgeIds = faceEdges(indices, adjacency);
  } else if (faces <= MAX_WIREFRAME_FACES) {
    edges = uniqueEdges(indices, vertexCount);
  }
  const t2 = performance.now();
  post({ id, type: 'progress', stage: 'transferring' });
  const result: ImportResult = {
    positions,
    indices,
    edges,
    report,
    valid,
    boundary,
    faceEdges: faceEdgeIds,
    adjacency,
    timings: { import: t1 - t0, edges: t2 - t1 },
    version: version(),
    alphaDefaults: { plain: default_alpha(false), miq: default_alpha(true) },
  };
  const transfer: Transferable[] = [positions.buffer, indices.buffer, boundary.buffer, faceEdgeIds.buffer];
  if (edges) transfer.push(edges.buffer);
  if (adjacency) transfer.push(adjacency.offsets.buffer, adjacency.nbr.buffer, adjacency.eid.buffer);
  return { value: result, transfer };
}

function requireSession(): Session {
  if (!session) throw new Error('no mesh is open');
  return session;
}

/** A progress callback that posts at most every 30 ms within a stage (rounding can call it thousands of times), and every change of stage. */
function throttledProgress(id: number): Progress {
  let lastPost = 0;
  let lastStage = '';
  return (stage, step, remaining, fraction) => {
    const now = performance.now();
    if (stage === lastStage && now - lastPost < 30) return;
    lastPost = now;
    lastStage = stage;
    post({ id, type: 'progress', stage, step, remaining, ...(fraction === undefined ? {} : { fraction }) });
  };
}

/** When the current stepwise solve began (`elapsed` of its result counts from there). */
let stepsStart = 0;

function solveStep(req: Extract<Request, { type: 'solve-begin' | 'solve-place' | 'solve-add' | 'solve-finish' }>): Answer {
  const s = requireSession();
  switch (req.type) {
    case 'solve-begin': {
      stepsStart = performance.now();
      s.set_max_cone_refinements(req.maxConeRefinements);
      s.set_free_boundary(req.freeBoundary ?? false);
      const schedule = s.solve_begin(req.features, req.alphaSmooth, req.miq, req.creases);
      return { value: { schedule }, transfer: [schedule.buffer] };
    }
    case 'solve-place': {
      const bytes = s.solve_place(req.component, req.share, throttledProgress(req.id)) ?? null;
      return { value: { bytes }, transfer: bytes ? [bytes.buffer] : [] };
    }
    case 'solve-add':
      s.solve_add(req.bytes);
      return { value: null, transfer: [] };
    case 'solve-finish':
      return solveAnswer(s, s.solve_finish(throttledProgress(req.id)), stepsStart);
  }
}

/** The `SolveResult` of the wasm result `solved`, with its view; `t0`: when the solve began. */
function solveAnswer(s: Session, solved: WasmSolveResult, t0: number): Answer {
  const view = solveView(s, solved);
  const value: SolveResult = { ...solved, ...(view ? { view } : {}), elapsed: performance.now() - t0 };
  const transfer: Transferable[] = view ? viewBuffers(view) : [];
  for (const v of [value.uv, value.seam_edges, value.glb, value.obj, value.metrics.per_face_distortion]) {
    if (v.buffer instanceof ArrayBuffer && !transfer.includes(v.buffer)) transfer.push(v.buffer);
  }
  return { value, transfer };
}

/** A `QuadsResult` with its arrays to transfer. */
function quadsAnswer(r: QuadsResult): Answer {
  const transfer: Transferable[] = [];
  for (const v of [r.uv, r.positions, r.quads, r.edges, r.singular, r.obj, r.glb, r.grid_glb]) {
    if (v.buffer instanceof ArrayBuffer && !transfer.includes(v.buffer)) transfer.push(v.buffer);
  }
  return { value: r, transfer };
}

/**
 * The display arrays of a solve result (see solve-view.ts), built here so the
 * page only uploads them; null when the result has no UVs for every corner or
 * building them fails (the page then builds them itself).
 */
function solveView(s: Session, r: WasmSolveResult): SolveView | null {
  try {
    const indices = s.indices();
    if (!(r.uv instanceof Float32Array) || r.uv.length !== indices.length * 2) return null;
    const positions = s.positions();
    const edges = s.edges();
    const fe = faceEdges(indices, buildAdjacency(edges, positions.length / 3));
    return buildSolveView({
      positions, indices, edges, boundary: s.boundary_edges(), faceEdges: fe, uv: r.uv,
      seamEdges: r.seam_edges, perFaceDistortion: r.metrics.per_face_distortion,
    });
  } catch (e) {
    console.warn(`conemap: building the solve view in the worker failed: ${errorMessage(e)}`);
    return null;
  }
}

async function handle(req: Request): Promise<void> {
  const { id } = req;
  try {
    post({ id, type: 'progress', stage: 'starting' });
    try {
      await wasmReady();
    } catch (e) {
      post({ id, type: 'error', message: `could not load the wasm module: ${errorMessage(e)}`, fatal: true });
      return;
    }
    let out: Answer;
    switch (req.type) {
      case 'import':
        out = openMesh(req);
        break;
      case 'sharp': {
        const found = requireSession().sharp_curves(req.degrees, req.minEdges, req.closedOnly);
        out = { value: found, transfer: [found.edges.buffer] };
        break;
      }
      case 'creases': {
        const found = requireSession().crease_edges();
        out = { value: found, transfer: [found.edges.buffer] };
        break;
      }
      case 'features-from-json': {
        const ids = requireSession().features_from_json(req.text);
        out = { value: ids, transfer: [ids.buffer] };
        break;
      }
      case 'solve-begin':
      case 'solve-place':
      case 'solve-add':
      case 'solve-finish':
        out = solveStep(req);
        break;
      case 'quads':
        out = quadsAnswer(requireSession().quads(req.quads, throttledProgress(id)));
        break;
    }
    post({ id, type: 'result', value: out.value }, out.transfer);
  } catch (e) {
    // A trap (a Rust panic ends in `unreachable`) leaves the instance unusable.
    const fatal = e instanceof WebAssembly.RuntimeError;
    const what = req.type === 'import' ? 'the importer' : 'the solver';
    const message = fatal ? `${what} crashed (${errorMessage(e)}); this is a bug in conemap` : errorMessage(e);
    if (fatal) session = null;
    const location = fatal ? null : errorLocation(e);
    post({ id, type: 'error', message, fatal, ...(location ? { location } : {}) });
  }
}

// Requests run one after the other, in arrival order.
let queue: Promise<void> = Promise.resolve();
scope.onmessage = (event) => {
  const req = event.data;
  queue = queue.then(() => handle(req));
};
