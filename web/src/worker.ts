// Module Web Worker: the only place the wasm runs. Receives `Request`s, answers
// with `Response`s (see protocol.ts); result buffers are transferred, not copied.
import init, { import_mesh, version } from '@conemap/wasm';
import { MAX_WIREFRAME_FACES, uniqueEdges } from './edges';
import type { MeshReport, Request, Response } from './protocol';

interface WorkerScope {
  onmessage: ((event: MessageEvent<Request>) => void) | null;
  postMessage(message: Response, transfer?: Transferable[]): void;
}
const scope = self as unknown as WorkerScope;

let ready: Promise<unknown> | null = null;
const wasmReady = (): Promise<unknown> =>
  (ready ??= init({ module_or_path: new URL('./pkg/conemap_bg.wasm', import.meta.url) }));

function post(message: Response, transfer: Transferable[] = []): void {
  scope.postMessage(message, transfer);
}

function errorMessage(e: unknown): string {
  if (e instanceof Error) return e.message || e.name;
  return String(e);
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
    post({ id, type: 'progress', stage: 'parsing' });
    const files = req.files.map((f) => ({ name: f.name, bytes: new Uint8Array(f.bytes) }));
    const t0 = performance.now();
    if (req.simulateTrap) throw new WebAssembly.RuntimeError('unreachable (simulated trap)');
    const out = import_mesh(files) as { positions: Float32Array; indices: Uint32Array; report?: MeshReport };
    const t1 = performance.now();
    post({ id, type: 'progress', stage: 'analysing' });
    const faces = out.indices.length / 3;
    const edges = faces <= MAX_WIREFRAME_FACES ? uniqueEdges(out.indices, out.positions.length / 3) : null;
    const t2 = performance.now();
    post({ id, type: 'progress', stage: 'transferring' });
    const transfer: Transferable[] = [out.positions.buffer, out.indices.buffer];
    if (edges) transfer.push(edges.buffer);
    post(
      {
        id,
        type: 'result',
        positions: out.positions,
        indices: out.indices,
        edges,
        report: out.report ?? null,
        timings: { import: t1 - t0, edges: t2 - t1 },
        version: version(),
      },
      transfer,
    );
  } catch (e) {
    // A trap (a Rust panic ends in `unreachable`) leaves the instance unusable.
    const fatal = e instanceof WebAssembly.RuntimeError;
    const message = fatal ? `the importer crashed (${errorMessage(e)}); this is a bug in conemap` : errorMessage(e);
    post({ id, type: 'error', message, fatal });
  }
}

scope.onmessage = (event) => {
  void handle(event.data);
};
