// Messages between the page and the wasm worker. Every request carries an id;
// the worker answers with any number of `progress` messages, then exactly one
// `result` or `error` with the same id. The worker keeps one `MeshSession`
// (the last mesh opened); later requests (`sharp`, `solve-*`, `quads`) refer to it.

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
  /** The creases `conemap quads` follows where no features are given; answers a `CreaseResult`. */
  | { id: number; type: 'creases' }
  /** Edge ids of the open mesh named by a features file or JSON report (`text`); answers a `Uint32Array`. */
  | { id: number; type: 'features-from-json'; text: string }
  // A solve in steps (so that a helper worker can place some components):
  // begin → place every component (here, or in a helper and then add) → finish.
  /** `creases`: those of `features` found by `creases` rather than marked (the quads drop them where they fold the map). */
  | { id: number; type: 'solve-begin'; features: Uint32Array; creases?: Uint32Array; alphaSmooth: number; miq: boolean; freeBoundary?: boolean; maxConeRefinements?: number | undefined }
  /** Places one component; with `share` the result answers `{ bytes }` for `solve-add` elsewhere. */
  | { id: number; type: 'solve-place'; component: number; share: boolean }
  | { id: number; type: 'solve-add'; bytes: Uint8Array }
  /** Answers a `SolveResult`. */
  | { id: number; type: 'solve-finish' }
  /** The integer-grid map and quad mesh of the session's last solve for about `quads` grid cells; answers a `QuadsResult`. */
  | { id: number; type: 'quads'; quads: number };

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
  /** One line per problem, elements numbered as the file does (OBJ 1-based; glTF mesh, primitive, accessor index). */
  problem_messages: string[];
  /** The problems located on the mesh as shown (crate `mesh::LocatedProblem`). */
  located_problems: LocatedProblem[];
  /** Further figures the library may add; shown when present. */
  edges?: number;
  boundary_edges?: number;
  non_manifold_edges?: number;
  merged_vertices?: number;
  /** Per component: whether `genus` is meaningful there. */
  component_is_manifold?: boolean[];
}

/**
 * A mesh problem (crate `mesh::LocatedProblem`): its kind, its message in the
 * file's numbering, whether it blocks solving, and the elements it names in
 * the ids of the shown mesh (edges as vertex pairs, flat; faces as triangles).
 */
export interface LocatedProblem {
  kind: string;
  message: string;
  blocking: boolean;
  vertices: number[];
  edges: number[];
  faces: number[];
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
  /** The library's α_smooth defaults (wasm `default_alpha`): plain, and with MIQ emulation. */
  alphaDefaults: { plain: number; miq: number };
}

export interface Cone {
  vertex: number;
  k: number;
  position: [number, number, number];
}

/** Per-component figures (crate `cones::ComponentFigures`). */
export interface ComponentResult {
  euler_characteristic: number;
  boundary_loops: number;
  genus: number;
  k_sum: number;
  path_integers: number[];
  h: number[];
  rounds: number;
  moves: number;
  merged_pairs: number;
  cancelled_pairs: number;
  spread_quarter_turns: number;
  residual: number;
  refinement_steps: number;
}

/** Seconds per cone stage (crate `cones::ConeTimings`). */
export interface ConeTimings {
  cut: number;
  topology: number;
  rounding: number;
  cone_moves: number;
  total: number;
}

/** Seconds per parametrization stage (crate `param::ParamTimings`). */
export interface ParamTimings {
  cut: number;
  field: number;
  poisson: number;
  arap: number;
  repair: number;
  untangle: number;
  injective: number;
  metrics: number;
}

/** Splits made by the refinement, by reason (crate `features::RefineCounts`). */
export interface RefineCounts {
  lone_edges: number;
  triply_constrained: number;
  doubly_constrained: number;
  enclosed_regions: number;
  zero_angle_faces: number;
  flipped_edges: number;
  long_edges: number;
  coplanar_flips: number;
}

/** How the requested feature edges came out (crate `pipeline::FeatureAlignment`). */
export interface FeatureAlignment {
  requested: number;
  aligned: number;
  worst_radians: number;
  unaligned: Array<{ edge: number; vertices: [number, number]; degrees: number }>;
}

/** The map's figures (crate `param::Metrics`) and the distortion of every input face. */
export interface SolveMetrics {
  distortion: number;
  scale: number;
  fraction_below_0_2: number;
  fraction_below_0_3: number;
  max_distortion: number;
  flipped: number;
  wound_vertices: number;
  seam_angle_residual: number;
  seam_length_residual: number;
  alignment_residual: number;
  cones: number;
  boundary_corners: number;
  seam_edges: number;
  seam_length: number;
  faces: number;
  per_face_distortion: Float32Array;
}

/** What the wasm `place_cones` returns (crate `wasm::ConeResult`, field for field). */
export interface ConeResult {
  cones: Cone[];
  boundary_corners: Cone[];
  components: ComponentResult[];
  rounds: number;
  energy: number;
  phi_rms: number;
  timings: ConeTimings;
  feature_edges: number;
  free_boundary: boolean;
  inserted_vertices: number;
}

/** What the wasm `solve` / `solve_finish` return (crate `wasm::SolveResult`, field for field). */
export interface WasmSolveResult extends ConeResult {
  /** Two per input face corner 3f+k. */
  uv: Float32Array;
  /** Input edge ids. */
  seam_edges: Uint32Array;
  metrics: SolveMetrics;
  param_timings: ParamTimings;
  refinement: RefineCounts;
  flip_refinements: number;
  realized_cones: number;
  feature_alignment: FeatureAlignment;
  glb: Uint8Array;
  /** The OBJ export, UTF-8. */
  obj: Uint8Array;
}

// Every key of the wasm results, checked both ways by the compiler (a key
// missing here, or one the type lacks, fails `tsc`); the node tests compare
// them with the keys the wasm returns, so the two sides cannot drift apart.
type Keys<T> = Record<keyof T, true>;
export const CONE_RESULT_KEYS = {
  cones: true, boundary_corners: true, components: true, rounds: true, energy: true, phi_rms: true, timings: true,
  feature_edges: true, free_boundary: true, inserted_vertices: true,
} as const satisfies Keys<ConeResult>;
export const SOLVE_METRICS_KEYS = {
  distortion: true, scale: true, fraction_below_0_2: true, fraction_below_0_3: true, max_distortion: true,
  flipped: true, wound_vertices: true, seam_angle_residual: true, seam_length_residual: true,
  alignment_residual: true, cones: true, boundary_corners: true, seam_edges: true, seam_length: true, faces: true,
  per_face_distortion: true,
} as const satisfies Keys<SolveMetrics>;
export const WASM_SOLVE_RESULT_KEYS = {
  ...CONE_RESULT_KEYS, uv: true, seam_edges: true, metrics: true, param_timings: true, refinement: true,
  flip_refinements: true, realized_cones: true, feature_alignment: true, glb: true, obj: true,
} as const satisfies Keys<WasmSolveResult>;

/** Figures of one quantization (crate `param::quantize::QuantizeReport`). */
export interface QuantizeReport {
  /** Grid cell edge length, model units. */
  grid_size: number;
  point_forms: number;
  translation_forms: number;
  batches: number;
  /** Integers moved by one to keep separated integers a grid line apart. */
  separation_moves: number;
  /** Pairs of integers (cones, corners, isolines side by side) to be kept a grid line apart, and those left closer. */
  separations: number;
  separations_violated: number;
  /** Seam translations around thin parts (a loop around a horn or a handle), integers moved to widen them to 3 grid steps or more, and those left narrower. */
  tube_periods: number;
  period_moves: number;
  periods_violated: number;
  /** Separations held as rows of the solves in the pass kept (0 unless the map was still bad after the plain and stiffer passes). */
  separations_held: number;
  /** Of those, rows widened to more than one grid line so that the pairs the seams make them determine are parted too. */
  separations_widened: number;
  /** Ends of feature curves inside the mesh, and those left off the grid points (their curve shorter than a cell). */
  curve_ends: number;
  free_curve_ends: number;
  /** Integers moved by one to undo a collapse. */
  moved_integers: number;
  arap_iterations: number;
  /** Local stiffening iterations (MIQ's) the map kept was mended by (0: none). */
  stiffening: number;
  /** Fit weight of the faces around singular points in the pass kept (1: the plain fit; more where that folded the map). */
  stiff_weight: number;
  /** The pass kept weighs faces near singular points by 1 + (rho / r)^2 (the graded fit, tried where the plain fit's map was bad). */
  graded_fit: boolean;
  /** The rounded map had flipped triangles and the untangler removed them all. */
  untangled: boolean;
  /** Forms left at a non-integer value (0 on success). */
  conflicts: number;
  integer_residual: number;
  /** Distortion (eq. 19) of the seamless map and of the integer-grid map. */
  distortion_before: number;
  distortion_after: number;
  /** Flipped or degenerate triangles of the integer-grid map. */
  flipped: number;
  /** Vertices around which the map winds (UV angle sum off the seamless map's by 2π) or at which it folds the boundary back (off by a quarter turn or more). */
  wound_vertices: number;
  /** Total UV area in grid cells (about the number of quads). */
  cells: number;
  /** Only the first pass ran: its map was hopeless and a map without the feature curves finer than the grid was tried instead. */
  passes_skipped: boolean;
  seconds: number;
}

/** A vertex of valence other than 4 inside (3 on the boundary). */
export interface SingularVertex {
  vertex: number;
  valence: number;
  boundary: boolean;
}

/** Figures of a quad mesh (crate `quads::check::QuadReport`); angles in degrees; distances absent when not computed. */
export interface QuadReport {
  quads: number;
  vertices: number;
  edges: number;
  euler_characteristic: number;
  boundary_loops: number;
  components: number;
  non_manifold_edges: number;
  non_manifold_vertices: number;
  degenerate_quads: number;
  unreferenced_vertices: number;
  singular_vertices: SingularVertex[];
  /** Vertex counts by valence (keys are valences). */
  valence_histogram: { interior: Record<string, number>; boundary: Record<string, number> };
  angle_mean_deviation: number;
  angle_max_deviation: number;
  fraction_corners_45_135: number;
  flipped_quads: number;
  distance_quads_to_input: number | undefined;
  distance_quads_to_input_relative: number | undefined;
  distance_input_to_quads: number | undefined;
  distance_input_to_quads_relative: number | undefined;
  sharp_edges_checked: number;
  fraction_sharp_within_tolerance: number | undefined;
  defects: number;
}

/** A decimation quads were traced on (crate `pipeline::Decimation`). */
export interface QuadDecimation {
  faces: number;
  vertices: number;
  /** The farthest a quad vertex moved onto the input (model units). */
  largest_projection: number;
}

/** Seconds per stage of a quads request (crate `pipeline::QuadTimings`). */
export interface QuadTimings {
  decimate: number;
  solve: number;
  quantize: number;
  extract: number;
  check: number;
}

/** What the wasm `quads` returns (crate `wasm::QuadsResult`, field for field). */
export interface QuadsResult {
  quantization: QuantizeReport;
  report: QuadReport;
  /** The integer-grid map in grid units (one cell = 1), two per input face corner 3f+k (on a decimation: its map carried back to the input's triangles). */
  uv: Float32Array;
  /** The quad mesh: xyz per vertex, 4 vertex ids per quad (CCW), 2 per edge. */
  positions: Float32Array;
  quads: Uint32Array;
  edges: Uint32Array;
  /** (vertex id, valence) per interior singular vertex. */
  singular: Uint32Array;
  /** Places the extractor repaired (0 on a valid map). */
  defects: number;
  /** Cones of the map quantized, and the pairs of opposite cones of the solve cancelled for this grid (closer than a cell's diagonal; 0 on a map solved without dropped features, which cancels its own). */
  cones: number;
  cancelled_pairs: number;
  /** Input feature edges the map was solved without: the map with them folded, and the grid is too coarse to follow them or they ran next to the folds (0: every feature kept). */
  dropped_feature_edges: number;
  /** Of those, the edges marked as creases (the map with them folded on their part of the mesh). */
  dropped_crease_edges: number;
  /** The mesh the map was solved on: its faces and the vertices inserted into the input (a low-poly mesh is refined for quads). */
  solved_faces: number;
  inserted_vertices: number;
  refinement: RefineCounts;
  /** The decimation of the input the quads were traced on and moved from (null: traced on the mesh solved). */
  decimated: QuadDecimation | null;
  /** Seconds per stage of the request (decimation, its solve, quantization, extraction, checks). */
  timings: QuadTimings;
  /** The quad mesh as OBJ (UTF-8) and as binary glTF; the input mesh with the grid UVs as binary glTF. */
  obj: Uint8Array;
  glb: Uint8Array;
  grid_glb: Uint8Array;
}

export const QUANTIZE_REPORT_KEYS = {
  grid_size: true, point_forms: true, translation_forms: true, batches: true, separation_moves: true, separations: true,
  tube_periods: true, period_moves: true, periods_violated: true,
  separations_violated: true, separations_held: true, separations_widened: true, curve_ends: true, free_curve_ends: true, moved_integers: true, arap_iterations: true, stiffening: true, stiff_weight: true, graded_fit: true,
  untangled: true, conflicts: true, integer_residual: true, distortion_before: true, distortion_after: true, flipped: true,
  wound_vertices: true, cells: true, passes_skipped: true, seconds: true,
} as const satisfies Keys<QuantizeReport>;
export const QUAD_REPORT_KEYS = {
  quads: true, vertices: true, edges: true, euler_characteristic: true, boundary_loops: true, components: true,
  non_manifold_edges: true, non_manifold_vertices: true, degenerate_quads: true, unreferenced_vertices: true,
  singular_vertices: true, valence_histogram: true, angle_mean_deviation: true, angle_max_deviation: true,
  fraction_corners_45_135: true, flipped_quads: true, distance_quads_to_input: true, distance_quads_to_input_relative: true,
  distance_input_to_quads: true, distance_input_to_quads_relative: true, sharp_edges_checked: true,
  fraction_sharp_within_tolerance: true, defects: true,
} as const satisfies Keys<QuadReport>;
export const QUADS_RESULT_KEYS = {
  quantization: true, report: true, uv: true, positions: true, quads: true, edges: true, singular: true, defects: true,
  cones: true, cancelled_pairs: true, dropped_feature_edges: true, dropped_crease_edges: true, solved_faces: true, inserted_vertices: true, refinement: true,
  decimated: true, timings: true, obj: true, glb: true, grid_glb: true,
} as const satisfies Keys<QuadsResult>;

/** A solve as the page receives it: the wasm result and what the worker adds. */
export interface SolveResult extends WasmSolveResult {
  /** Milliseconds in the main worker from `solve-begin` to the end of `solve-finish`. */
  elapsed: number;
  /** Display arrays built in the worker from `uv` (see solve-view.ts); absent when that failed. */
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

/** The creases of `MeshSession.crease_edges` (crate `features::CREASES`): a detection and its settings. */
export interface CreaseResult extends SharpResult {
  /** Dihedral threshold, and the shortest curve kept as a fraction of the bounding-box diagonal. */
  degrees: number;
  min_length_fraction: number;
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
  | { id: number; type: 'progress'; stage: string; step?: number; remaining?: number; fraction?: number }
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
