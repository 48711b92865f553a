// Messages between the page and the wasm worker. Every request carries an id;
// the worker answers with any number of `progress` messages, then exactly one
// `result` or `error` with the same id.

/** One input file: the mesh first, companion files (.bin, textures) after it. */
export interface WireFile {
  name: string;
  bytes: ArrayBuffer;
}

export type Request = {
  id: number;
  type: 'import';
  files: WireFile[];
  /** Test hook: behave as if the wasm trapped (a Rust panic) during this import. */
  simulateTrap?: boolean;
};

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
  /** Unique edges as vertex-index pairs for the wireframe overlay; null when skipped (huge meshes). */
  edges: Uint32Array | null;
  report: MeshReport | null;
  /** Milliseconds spent in the wasm import and in the edge extraction. */
  timings: { import: number; edges: number };
  version: string;
}

export type Response =
  | { id: number; type: 'progress'; stage: Stage }
  | ({ id: number; type: 'result' } & ImportResult)
  | {
      id: number;
      type: 'error';
      message: string;
      /** The wasm instance is unusable (trap/panic): the page must replace the worker. */
      fatal: boolean;
    };
