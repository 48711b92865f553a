// The solve side of the page put together: the mesh's problems, the feature
// editor, the solve controller, the result panel and its quads, told of a new
// mesh and of each other's news.
import { FeatureEditor } from './feature-editor';
import { MeshProblems } from './mesh-problems';
import type { ImportResult } from './protocol';
import { QuadPanel } from './quad-panel';
import { ResultPanel } from './result-panel';
import { SolveController } from './solve-controller';
import type { PageStore } from './state';
import type { Hooks } from './test-hooks';
import type { Viewer } from './viewer';
import type { MeshWorker } from './worker-client';

export class Editor {
  readonly problems: MeshProblems;
  readonly features: FeatureEditor;
  readonly results: ResultPanel;
  readonly quads: QuadPanel;
  readonly solve: SolveController;

  /** Wires the five parts to `viewer`, `worker`, the page's `store`, the test `hooks` they keep up to date and the page's status line (`setStatus`). */
  constructor(viewer: Viewer, worker: MeshWorker, store: PageStore, hooks: Hooks, setStatus: (text: string) => void) {
    this.problems = new MeshProblems(viewer, hooks);
    this.features = new FeatureEditor(viewer, worker, hooks, {
      onChange: () => this.solve.featuresChanged(),
      onError: (message) => this.solve.showError(message),
    });
    this.quads = new QuadPanel(viewer, worker, store, hooks, {
      onError: (message) => this.solve.showError(message),
      clearError: () => this.solve.hideError(),
      onGridUv: (uv) => this.results.showGridUv(uv),
    });
    this.results = new ResultPanel(viewer, hooks, this.quads);
    this.solve = new SolveController(viewer, worker, store, this.features, this.problems, this.results, hooks, setStatus);
  }

  /** Opens a freshly imported mesh (`data`, shown by the viewer, named `label`): its problems listed and drawn, no features, no result, no solve error. */
  setMesh(data: ImportResult, label: string): void {
    this.results.clear();
    this.problems.show(data);
    this.features.setMesh(data, label);
    this.solve.meshChanged();
  }
}
