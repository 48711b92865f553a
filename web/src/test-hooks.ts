// The page's test hooks: `window.__conemap`, figures the browser tests and
// scripts/bench.mjs read (its `state` is the store's phase), and the shape of
// `window.__conemapTest`, the actions they call (installed by main.ts).
import type { Stats } from './panels';
import type { ErrorLocation } from './protocol';
import type { PageStore, Phase } from './state';
import type { UvDrawn } from './uvview';

/** Figures of a finished solve, as the tests read them. */
export interface ResultHook {
  cones: number;
  plus: number;
  minus: number;
  /** Σk over cones and over boundary corners. */
  sumConeK: number;
  sumCornerK: number;
  boundaryCorners: number;
  /** χ of the whole mesh (from the import report). */
  eulerCharacteristic: number;
  rounds: number;
  featureEdges: number;
  /** The cone count as shown in the results panel. */
  shownCones: string;
  uv: boolean;
  seams: number;
  /** `phiᵀ(alpha L + M/A) phi` of the placement. */
  energy: number;
  /** Components whose cones a helper worker placed. */
  helperComponents: number;
  /** [min u, min v, max u, max v] of the seamless map (null without UVs). */
  uvBounds: [number, number, number, number] | null;
}

/** The distortion colours of the result shown, as the tests read them. */
export interface DistortionHook {
  /** The value at the ramp's top (the auto 99th percentile or the fixed scale). */
  scale: number;
  fixed: boolean;
  /** Faces per histogram bin (the last: at or above the scale). */
  histogram: number[];
  /** Mean vertex colour (linear rgb) over the faces. */
  meanColor: [number, number, number];
}

/** Figures of the quads shown, as the tests read them. */
export interface QuadsHook {
  /** The count asked for (the slider's) and the one the extractor made. */
  target: number;
  quads: number;
  /** Length of the `quads` array (4 per quad). */
  quadIndices: number;
  vertices: number;
  /** Quad edge length (grid cell), model units. */
  gridSize: number;
  /** Interior singular vertices by valence. */
  singular: { three: number; five: number; other: number };
  angleMeanDeviation: number;
  distortionBefore: number;
  distortionAfter: number;
  defects: number;
  /** Two-sided distance between the quads and the input (fraction of the diagonal, the larger side; null: not measured). */
  distance: number | null;
  /** Share of the sharp input edges' points near a quad edge (null: no sharp edge checked). */
  sharpWithin: number | null;
  /** Feature edges the map was solved without, and how many of them were marked as creases. */
  droppedFeatures: number;
  droppedCreases: number;
  /** Faces of the mesh the map was solved on, and the vertices inserted into the input for it. */
  solvedFaces: number;
  insertedVertices: number;
  /** Faces of the decimation the quads were traced on (null: traced on the mesh solved). */
  decimatedFaces: number | null;
  /** Face corners the grid UVs cover (2 numbers each). */
  uvCorners: number;
  /** The 3D checker is drawn from the grid UVs. */
  gridChecker: boolean;
  /** [min u, min v, max u, max v] of the grid UVs (grid units). */
  uvBounds: [number, number, number, number];
}

/** `window.__conemap`: each part of the page keeps its fields up to date. */
export interface Hooks {
  /** The page's phase (read from the store). */
  readonly state: Phase;
  stats: (Omit<Stats, 'report'> & Partial<NonNullable<Stats['report']>>) | null;
  lastError: string | null;
  version: string | null;
  workerRestarts: number;
  /** Increments on every finished load (success or failure). */
  loads: number;
  /** Milliseconds of the last load's phases on the main thread's clock. */
  timings: { read: number; worker: number; draw: number } | null;
  /** Marked feature edges (without the fixed boundary edges). */
  features: number;
  /** The edge highlighted under the pointer (a click would toggle it), or null. */
  hoverEdge: number | null;
  /** The mesh problem last clicked in the Problems list: its index there and the vertices the view framed; null when none. */
  problemFocus: { index: number; vertices: number[] } | null;
  /** Figures of the last finished solve (null before one, or after a new mesh). */
  result: ResultHook | null;
  /** The distortion colours of the result shown (null without one, or without per-face distortion). */
  distortion: DistortionHook | null;
  /** Checker squares across the seamless layout's larger side (null while the grid map's checker is drawn). */
  checkerSquares: number | null;
  /** Message of the last failed solve (null after a successful one). */
  solveError: string | null;
  /** The `location` of the last failed solve's error (null after a success, or when it names no mesh element). */
  solveErrorLocation: ErrorLocation | null;
  /** What the 3D view highlights of that location (valid ids only); null once cleared (Run, new mesh, feature change). */
  errorHighlight: ErrorLocation | null;
  /** Increments on every finished solve (success, failure or cancel). */
  solves: number;
  /** Face highlighted in the 3D and UV views (hover sync), or null. */
  hoverFace: number | null;
  /** What the UV view draws: which map, the bounds of its triangles, the grid-line stride (null when no layout is shown). */
  uvView: UvDrawn | null;
  /** The chart selected by a click in the UV view: the face clicked, its chart, the chart count, the faces highlighted in 3D and in the layout (null: none). */
  chart: { face: number; chart: number; charts: number; faces3d: number; facesUv: number } | null;
  /** Figures of the quads shown (null when none are). */
  quads: QuadsHook | null;
  /** Message of the last failed quads request (null after a success). */
  quadsError: string | null;
  /** Increments whenever the answer to a quads request (quads or error) is put on the page; superseded ones do not count. */
  quadRuns: number;
}

/** Test-only actions (tests/e2e). */
export interface TestActions {
  importWithTrap(name: string, text: string): void;
  /** Page position of the midpoint of edge `edgeId` (client CSS px). */
  projectEdge(edgeId: number): { x: number; y: number } | null;
  /** An interior, unmarked edge whose midpoint is visible and picks back to itself; -1 if none. */
  visibleEdge(): number;
  /** Edge id a click at (x, y) would toggle; -1 when none. */
  edgeAt(x: number, y: number): number;
  /** The face under (x, y) and the distance (CSS px) from there to its nearest side; null off the mesh. */
  pick(x: number, y: number): { face: number; sideDistance: number } | null;
  /** Ids of the marked feature edges, ascending. */
  featureIds(): number[];
  /** Smallest mesh (faces) whose solves use a helper worker; `wait`: start placing once it is ready. */
  setHelper(minFaces: number, wait: boolean): void;
  /** Refinements around cones of angle 0 before a solve fails (undefined: the default; 0 shows the raw placement's error). */
  setMaxConeRefinements(n: number | undefined): void;
  /** Position of vertex `v` of the open mesh, its page position (client CSS px), the end vertices of edge `e`. */
  vertexPosition(v: number): [number, number, number] | null;
  projectVertex(v: number): { x: number; y: number } | null;
  edgeEnds(e: number): [number, number] | null;
  /** Sets the quad-count slider to about `n` quads and asks for them at once (quad mode must be on). */
  setQuadCount(n: number): void;
  /** Where the 3D view's camera looks (the orbit centre), mesh coordinates. */
  cameraTarget(): [number, number, number];
  /** Page position (client CSS px) of the centroid of face `face` in the UV view, and the distance from it to the farthest corner; null when no layout is shown. */
  projectUvFace(face: number): { x: number; y: number; radius: number } | null;
  /** Page position (client CSS px) of the layout point (u, v) in the UV view. */
  projectUvPoint(u: number, v: number): { x: number; y: number };
}

declare global {
  interface Window {
    __conemap: Hooks;
    __conemapTest: TestActions;
  }
}

/** Takes the page's store and returns fresh hooks (nothing loaded or solved yet) whose `state` reads it, set as `window.__conemap`. */
export function installHooks(store: PageStore): Hooks {
  const hooks: Hooks = {
    // A getter of the literal is enumerable: `page.evaluate(() => window.__conemap)` copies it with the rest.
    get state() {
      return store.state.phase;
    },
    stats: null, lastError: null, version: null, workerRestarts: 0, loads: 0, timings: null,
    features: 0, hoverEdge: null, problemFocus: null, result: null, distortion: null, checkerSquares: null,
    solveError: null, solveErrorLocation: null, errorHighlight: null, solves: 0, hoverFace: null,
    uvView: null, chart: null, quads: null, quadsError: null, quadRuns: 0,
  };
  window.__conemap = hooks;
  return hooks;
}
