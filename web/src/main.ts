// Page entry: wires the file inputs, the samples menu, the worker and the viewer;
// the feature editor and the solve controls live in editor.ts.
import { Editor, type EditorHooks } from './editor';
import { fetchFile, orderFiles, readFiles } from './files';
import { Panels, type Sample, type Stats, fmtBytes } from './panels';
import type { Stage, WireFile } from './protocol';
import { Viewer } from './viewer';
import { MeshWorker } from './worker-client';

type State = 'idle' | 'loading' | 'ready' | 'error' | 'solving' | 'solved';

/** Test hooks (read by tests/e2e and scripts/bench.mjs); the editor keeps its part up to date. */
interface Hooks extends EditorHooks {
  state: State;
  stats: (Omit<Stats, 'report'> & Partial<NonNullable<Stats['report']>>) | null;
  lastError: string | null;
  version: string | null;
  workerRestarts: number;
  /** Increments on every finished load (success or failure). */
  loads: number;
  /** Milliseconds of the last load's phases on the main thread's clock. */
  timings: { read: number; worker: number; draw: number } | null;
}
declare global {
  interface Window {
    __conemap: Hooks;
    /** Test-only actions (tests/e2e). */
    __conemapTest: {
      importWithTrap(name: string, text: string): void;
      /** Page position of the midpoint of edge `edgeId` (client CSS px). */
      projectEdge(edgeId: number): { x: number; y: number } | null;
      /** An interior, unmarked edge whose midpoint is visible and picks back to itself; -1 if none. */
      visibleEdge(): number;
      /** Edge id a click at (x, y) would toggle; -1 when none. */
      edgeAt(x: number, y: number): number;
      /** Smallest mesh (faces) whose solves use a helper worker; `wait`: start placing once it is ready. */
      setHelper(minFaces: number, wait: boolean): void;
      /** Refinements around cones of angle 0 before a solve fails (undefined: the default; 0 shows the raw placement's error). */
      setMaxConeRefinements(n: number | undefined): void;
      /** Position of vertex `v` of the open mesh, its page position (client CSS px), the end vertices of edge `e`. */
      vertexPosition(v: number): [number, number, number] | null;
      projectVertex(v: number): { x: number; y: number } | null;
      edgeEnds(e: number): [number, number] | null;
    };
  }
}

const DEFAULT_SAMPLE = 'fandisk.obj';
const hooks: Hooks = {
  state: 'idle', stats: null, lastError: null, version: null, workerRestarts: 0, loads: 0, timings: null,
  features: 0, result: null, solveError: null, solveErrorLocation: null, errorHighlight: null, solves: 0, hoverFace: null,
};
window.__conemap = hooks;
document.body.dataset['state'] = hooks.state;

const panels = new Panels();
const viewer = new Viewer(document.getElementById('viewport')!);
const worker = new MeshWorker();
const editor = new Editor(viewer, worker, hooks, setState);

const stageText: Record<Stage, string> = {
  starting: 'Starting the importer',
  parsing: 'Parsing',
  analysing: 'Analysing',
  transferring: 'Transferring',
};

function setState(state: State): void {
  hooks.state = state;
  document.body.dataset['state'] = state;
}

let current = 0;

/** Runs one load: read bytes → import in the worker → draw. Later loads supersede earlier ones. */
async function load(
  label: string,
  read: (progress: (loaded: number, total: number) => void) => Promise<WireFile[]>,
  simulateTrap = false,
): Promise<void> {
  const token = ++current;
  const live = (): boolean => token === current;
  editor.cancelSolve(); // a new mesh supersedes a running solve
  setState('loading');
  panels.clearError();
  panels.setStatus(`Reading ${label}…`, true, 0);
  try {
    const tRead = performance.now();
    const files = await read((loaded, total) => {
      if (live()) panels.setStatus(`Reading ${label}… ${fmtBytes(loaded)} of ${fmtBytes(total)}`, true, total ? loaded / total : 0);
    });
    if (!live()) return;
    const bytes = files.reduce((s, f) => s + f.bytes.byteLength, 0);
    const t0 = performance.now();
    const result = await worker.importMesh(files, (stage) => {
      if (live()) panels.setStatus(`${stageText[stage]} ${label}…`, true);
    }, simulateTrap);
    if (!live()) return;
    const tDraw = performance.now();
    panels.setStatus(`Drawing ${label}…`, true);
    viewer.show(result);
    editor.setMesh(result, label);
    viewer.renderNow();
    hooks.timings = { read: t0 - tRead, worker: tDraw - t0, draw: performance.now() - tDraw };
    const stats: Stats = {
      file: label,
      bytes,
      vertices: result.positions.length / 3,
      faces: result.indices.length / 3,
      importMs: result.timings.import,
      report: result.report,
    };
    panels.showStats(stats);
    const { report, ...plain } = stats;
    hooks.stats = { ...plain, ...(report ?? {}) };
    hooks.version = result.version;
    hooks.lastError = null;
    document.getElementById('version')!.textContent = `v${result.version}`;
    updateWireframeToggle();
    const total = performance.now() - t0;
    panels.setStatus(`Loaded ${label}: ${stats.faces.toLocaleString('en-US')} faces in ${total.toFixed(0)} ms`, false);
    setState('ready');
  } catch (e) {
    if (!live()) return;
    const message = e instanceof Error ? e.message : String(e);
    hooks.lastError = `${label}: ${message}`;
    console.warn(`conemap: could not load ${label}: ${message}`);
    panels.showError(label, message);
    panels.setStatus(viewer.hasMesh ? 'Import failed; the previous mesh is still shown.' : 'Import failed.', false);
    setState('error');
  } finally {
    hooks.workerRestarts = worker.restarts;
    if (live()) hooks.loads++;
  }
}

function loadLocal(fileList: FileList | File[]): void {
  const files = orderFiles([...fileList]);
  if (files.length === 0) return;
  const label = files.length > 1 ? `${files[0]!.name} (+${files.length - 1} more)` : files[0]!.name;
  panels.samples.value = '';
  void load(label, (progress) => readFiles(files, progress));
}

function loadSample(file: string): void {
  void load(file, async (progress) => [await fetchFile(`samples/${encodeURIComponent(file)}`, progress)]);
}

// File picker.
const input = document.getElementById('file-input') as HTMLInputElement;
input.addEventListener('change', () => {
  if (input.files) loadLocal(input.files);
  input.value = ''; // choosing the same file again still fires `change`
});

// Drop anywhere.
const overlay = document.getElementById('drop-overlay')!;
let dragDepth = 0;
const hasFiles = (e: DragEvent): boolean => [...(e.dataTransfer?.types ?? [])].includes('Files');
window.addEventListener('dragenter', (e) => {
  if (!hasFiles(e)) return;
  e.preventDefault();
  dragDepth++;
  overlay.hidden = false;
});
window.addEventListener('dragleave', () => {
  dragDepth = Math.max(0, dragDepth - 1);
  if (dragDepth === 0) overlay.hidden = true;
});
window.addEventListener('dragover', (e) => {
  e.preventDefault();
  if (e.dataTransfer) e.dataTransfer.dropEffect = 'copy';
});
window.addEventListener('drop', (e) => {
  e.preventDefault();
  dragDepth = 0;
  overlay.hidden = true;
  if (e.dataTransfer?.files.length) loadLocal(e.dataTransfer.files);
});

// Samples menu.
panels.samples.addEventListener('change', () => {
  if (panels.samples.value) loadSample(panels.samples.value);
});
async function listSamples(): Promise<void> {
  let samples: Sample[] = [{ name: 'fandisk', file: DEFAULT_SAMPLE, bytes: 0 }];
  try {
    const res = await fetch('samples/index.json');
    if (res.ok) samples = ((await res.json()) as { samples: Sample[] }).samples;
  } catch {
    // keep the default entry
  }
  panels.setSamples(samples, DEFAULT_SAMPLE);
}

// View options.
const wireToggle = document.getElementById('wireframe-toggle') as HTMLInputElement;
wireToggle.addEventListener('change', () => viewer.setWireframe(wireToggle.checked));
function updateWireframeToggle(): void {
  wireToggle.disabled = !viewer.wireframeAvailable;
  wireToggle.parentElement!.title = viewer.wireframeAvailable ? '' : 'Edge overlay is off for very large meshes';
}
document.getElementById('frame-button')!.addEventListener('click', () => viewer.frame());

window.__conemapTest = {
  importWithTrap(name, text) {
    void load(name, async () => [{ name, bytes: new TextEncoder().encode(text).buffer as ArrayBuffer }], true);
  },
  projectEdge: (e) => editor.projectEdge(e),
  visibleEdge: () => editor.visibleEdge(),
  edgeAt: (x, y) => editor.edgeAt(x, y),
  setHelper: (minFaces, wait) => {
    MeshWorker.helperMinFaces = minFaces;
    MeshWorker.helperWait = wait;
  },
  setMaxConeRefinements: (n) => {
    MeshWorker.maxConeRefinements = n;
  },
  vertexPosition: (v) => editor.vertexPosition(v),
  projectVertex: (v) => editor.projectVertex(v),
  edgeEnds: (e) => editor.edgeEnds(e),
};

void listSamples();
loadSample(DEFAULT_SAMPLE);
