// Page entry: wires the file inputs, the samples menu, the worker and the viewer
// to the page's state (state.ts); the feature editor, the solve controls and
// the results are put together in editor.ts.
import { $, fmtBytes, fmtInt, fmtMs } from './dom';
import { Editor } from './editor';
import { fetchFile, orderFiles, readFiles } from './files';
import { Panels, type Sample, type Stats } from './panels';
import type { Stage, WireFile } from './protocol';
import { SplitPane } from './split';
import { PageStore, mirrorToDataset } from './state';
import { installHooks } from './test-hooks';
import { wireViewKeys } from './view-keys';
import { Viewer } from './viewer';
import { MeshWorker } from './worker-client';

const DEFAULT_SAMPLE = 'fandisk.obj';
const store = new PageStore();
const hooks = installHooks(store);
mirrorToDataset(store, document.body.dataset);

const panels = new Panels();
new SplitPane($('views'), $('uv-divider'), $('uv-view'));
const viewer = new Viewer($('viewport'));
wireViewKeys(viewer);
const worker = new MeshWorker();
const editor = new Editor(viewer, worker, store, hooks, (text) => panels.setStatus(text, false));

const stageText: Record<Stage, string> = {
  starting: 'Starting the importer',
  parsing: 'Parsing',
  analysing: 'Analysing',
  transferring: 'Transferring',
};

/** Runs one load: read bytes → import in the worker → draw. Later loads supersede earlier ones. */
async function load(
  label: string,
  read: (progress: (loaded: number, total: number) => void) => Promise<WireFile[]>,
  simulateTrap = false,
): Promise<void> {
  editor.solve.cancel(); // a new mesh supersedes a running solve
  const token = store.beginLoad();
  const live = (): boolean => store.isCurrentLoad(token);
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
    viewer.loop.renderNow(); // drawn before "ready" (and before screenshots)
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
    $('version').textContent = `v${result.version}`;
    updateWireframeToggle();
    const total = performance.now() - t0;
    panels.setStatus(`Loaded ${label}: ${fmtInt(stats.faces)} faces in ${fmtMs(total)}`, false);
    store.transition('ready');
  } catch (e) {
    if (!live()) return;
    const message = e instanceof Error ? e.message : String(e);
    hooks.lastError = `${label}: ${message}`;
    console.warn(`conemap: could not load ${label}: ${message}`);
    panels.showError(label, message);
    panels.setStatus(viewer.hasMesh ? 'Import failed; the previous mesh is still shown.' : 'Import failed.', false);
    store.transition('error');
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
const input = $<HTMLInputElement>('file-input');
input.addEventListener('change', () => {
  if (input.files) loadLocal(input.files);
  input.value = ''; // choosing the same file again still fires `change`
});

// Drop anywhere.
const overlay = $('drop-overlay');
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
const wireToggle = $<HTMLInputElement>('wireframe-toggle');
wireToggle.addEventListener('change', () => viewer.setWireframe(wireToggle.checked));
function updateWireframeToggle(): void {
  wireToggle.disabled = !viewer.wireframeAvailable;
  wireToggle.parentElement!.title = viewer.wireframeAvailable ? '' : 'Edge overlay is off for very large meshes';
}
$('frame-button').addEventListener('click', () => viewer.frame());

window.__conemapTest = {
  importWithTrap(name, text) {
    void load(name, async () => [{ name, bytes: new TextEncoder().encode(text).buffer as ArrayBuffer }], true);
  },
  projectEdge: (e) => editor.features.projectEdge(e),
  visibleEdge: () => editor.features.visibleEdge(),
  edgeAt: (x, y) => editor.features.edgeAt(x, y),
  pick: (x, y) => {
    const p = viewer.pick(x, y);
    return p ? { face: p.face, sideDistance: p.sideDistance } : null;
  },
  featureIds: () => Array.from(editor.features.mesh?.features?.ids() ?? []),
  setHelper: (minFaces, wait) => store.setTuning({ helperMinFaces: minFaces, helperWait: wait }),
  setMaxConeRefinements: (n) => store.setTuning({ maxConeRefinements: n }),
  vertexPosition: (v) => editor.features.vertexPosition(v),
  projectVertex: (v) => editor.features.projectVertex(v),
  edgeEnds: (e) => editor.features.edgeEnds(e),
  setQuadCount: (n) => editor.quads.setCount(n),
  cameraTarget: () => viewer.target.toArray(),
  projectUvFace: (f) => editor.results.projectUvFace(f),
  projectUvPoint: (u, v) => editor.results.projectUvPoint(u, v),
};

void listSamples();
loadSample(DEFAULT_SAMPLE);
