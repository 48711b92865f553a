// Messages between the page and the wasm worker. Every request carries an id;
// the worker answers with any number of `progress` messages, then exactly one
// `result` or `error` with the same id. The worker keeps one `MeshSession`
// (the last mesh opened); later requests (`sharp`, `solve-*`) refer to it.

/** One input file: the mesh first, companion files (.bin, textures) after it. */
export interface WireFile {
  name: string;
  bytes: ArrayBuffer;
}

export type Request =
  | {
      id: number;
      type: 'import';
      files: WireFile[];
      /** Re-open only (after a worker replacement): keep the session, send no geometry back. */
      quiet?: boolean;
      /** Test hook: behave as if the wasm trapped (a Rust panic) during this import. */
      simulateTrap?: boolean;
    }
  | { id: number; type: 'sharp'; degrees: number; minEdges: number; closedOnly: boolean }
  // A solve in steps (so that a helper worker can place some components):
  // begin → place every component (here, or in a helper and then add) → finish.
  | { id: number; type: 'solve-begin'; features: Uint32Array; alphaSmooth: number; miq: boolean; freeBoundary?: boolean; maxConeRefinements?: number | undefined }
  /** Places one component; with `share` the result answers `{ bytes }` for `solve-add` elsewhere. */
  | { id: number; type: 'solve-place'; component: number; share: boolean }
  | { id: number; type: 'solve-add'; bytes: Uint8Array }
  /** Answers a `SolveResult`. */
  | { id: number; type: 'solve-finish' };

/** Answer to `solve-begin`: the components in the order to place them. */
export interface SolveBegun {
  schedule: Uint32Array;
}

export type Stage = 'starting' | 'parsing' | 'analysing' | 'transferring';

/** Mesh report from the library (crate `MeshReport`); optional while it is being built. */
export interface MeshReport {
  vertices: number;
  faces: number;
  boundary_loops: number;
  components: number;
  euler_characteristic: number;
  genus: number[];
  problems: Array<{ kind: string; [index: string]: unknown }>;
  problem_messages: string[];
  /** Further figures the library may add; shown when present. */
  edges?: number;
  boundary_edges?: number;
  non_manifold_edges?: number;
  merged_vertices?: number;
  /** Per component: whether `genus` is meaningful there. */
  component_is_manifold?: boolean[];
}

export interface ImportResult {
  positions: Float32Array;
  indices: Uint32Array;
  /** Edges as vertex-index pairs (edge id = index / 2: the library's ids when `valid`); null when skipped (huge meshes). */
  edges: Uint32Array | null;
  report: MeshReport | null;
  /** The mesh can be parametrized (no blocking problem): feature edges and solving are available. */
  valid: boolean;
  /** Boundary edge ids (valid meshes). */
  boundary: Uint32Array;
  /** Per face the ids of its 3 sides (3f+k: corner k → k+1), for picking; empty for invalid meshes. */
  faceEdges: Uint32Array;
  /** Vertex adjacency in CSR form (see topology.ts), for shortest edge paths. */
  adjacency: { offsets: Uint32Array; nbr: Uint32Array; eid: Uint32Array } | null;
  /** Milliseconds spent in the wasm import and in the edge extraction. */
  timings: { import: number; edges: number };
  version: string;
}

export interface Cone {
  vertex: number;
  k: number;
  position: [number, number, number];
}

export interface ComponentResult {
  euler_characteristic: number;
  boundary_loops: number;
  genus: number;
  k_sum: number;
  path_integers?: number[];
  h?: number[];
  rounds: number;
  moves: number;
  residual: number;
  [key: string]: unknown;
}

export interface SolveMetrics {
  distortion: number;
  below_0_2: number;
  below_0_3: number;
  flipped: number;
  seam_angle_residual: number;
  seam_length_residual: number;
  alignment_residual: number;
  cones: number;
  seam_length: number;
  per_face_distortion?: Float32Array;
  [key: string]: unknown;
}

/** The result of a solve: cones (as `place_cones` reports them), UVs, metrics and exports. */
export interface SolveResult {
  cones: Cone[];
  boundary_corners: Cone[];
  components: ComponentResult[];
  rounds: number;
  energy: number;
  phi_rms: number;
  timings: Record<string, number>;
  feature_edges: number;
  /** Milliseconds in the main worker from `solve-begin` to the end of `solve-finish`. */
  elapsed: number;
  uv?: Float32Array;
  seam_edges?: Uint32Array;
  metrics?: SolveMetrics;
  /** Exports, produced in the worker right after the solve. */
  glb?: Uint8Array;
  /** The OBJ export as UTF-8 bytes (encoded in the worker, so that it is transferred rather than copied). */
  obj?: Uint8Array;
  /** Display arrays built in the worker from `uv` (present with `uv`; see solve-view.ts). */
  view?: SolveView;
  /** Components whose cones a second (helper) worker placed; set by the page. */
  helperComponents?: number;
}

/**
 * What the page shows of a solve with UVs, ready to upload (typed arrays,
 * transferred from the worker). Corners are 3f+k (face f, corner k).
 */
export interface SolveView {
  /** xyz per corner: the mesh positions unwelded (the UV-textured surface). */
  cornerPositions: Float32Array;
  /** The UVs scaled for the checker texture, 2 per corner (shared by the 3D and the 2D view). */
  checkerUv: Float32Array;
  /** The UV layout as xyz per corner (z = 0), for the 2D view. */
  layoutPositions: Float32Array;
  /** [min u, min v, max u, max v] of the layout. */
  layoutBounds: [number, number, number, number];
  /** Bounding sphere of `layoutPositions`: [centre u, centre v, radius]. */
  layoutSphere: [number, number, number];
  /** Chart outlines (seam and boundary sides) in the layout: 2 xyz points per segment, raw UVs, z = 0.005. */
  cutSegments: Float32Array;
  /** Seam edges in 3D: 2 xyz points per segment, in `seam_edges` order. */
  seamSegments: Float32Array;
  /** Per-face distortion shown as colours: scale (99th percentile), rgb per corner, 40-bin histogram of value / max. */
  distortion: { max: number; colors: Float32Array; histogram: Uint32Array } | null;
}

export interface SharpResult {
  edges: Uint32Array;
  /** Counts of the detection (`features::SharpStats`). */
  stats: { sharp_edges: number; curves: number; kept_edges: number; dropped_fragments: number; pruned_edges: number };
}

/**
 * Where a solve error is on the mesh (crate `pipeline::ErrorLocation`), in the
 * ids of the open mesh: the vertex named (or the corners of the edge / face a
 * vertex was inserted in) and the edges named or to change (capped at 500).
 */
export interface ErrorLocation {
  vertices: number[];
  edges: number[];
}

export type Response =
  | { id: number; type: 'progress'; stage: string; step?: number; remaining?: number }
  | { id: number; type: 'result'; value: unknown }
  | {
      id: number;
      type: 'error';
      message: string;
      /** The wasm instance is unusable (trap/panic): the page must replace the worker. */
      fatal: boolean;
      /** Where on the mesh, for solve errors that name mesh elements. */
      location?: ErrorLocation;
    };
