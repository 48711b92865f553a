//! wasm-bindgen API: thin conversions between JS values and the library.
//!
//! Errors cross as JS `Error`s carrying the library's one-line message; solve
//! errors that name mesh elements also carry `location` ([`solve_error`]).

use crate::cones::{self, BoundaryMode, ComponentFigures, ComponentPlacement, Cone, ConeOptions, ConePlacement, ConeProgress, ConeTimings};
use crate::export::{self, ExportInput, ExportOptions};
use crate::param::quantize::{GridSize, QuantizeReport};
use crate::param::{self, Metrics, ParamOptions, ParamProgress, ParamTimings};
use crate::quads::{self, QuadReport};
use crate::pipeline::{
    corner_values_onto, Decimation, FeatureAlignment, GridFeatures, GridStage, LongEdges, QuadOptions, QuadProgress, QuadStage, QuadTimings, QuadsError, RefineOptions, Solution,
    SolveError, SolveOptions, SolveProgress, SolveStage, TracedQuads,
};
use crate::features::{FeatureSet, RefineCounts};
use crate::io::gltf::GltfSource;
use crate::io::{self, InputFile};
use crate::mesh::{self, LocatedProblem, MeshReport, RawMesh, TriMesh};
use js_sys::{Array, Float32Array, Function, Object, Reflect, Uint32Array, Uint8Array};
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// Library version, for the page's about line.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// `alpha_smooth` when none is given, as the CLI's `--alpha` default: the
/// paper's 0.01, or with MIQ emulation its "100.0*" (large α, no
/// harmonic-minimality constraint).
#[wasm_bindgen]
pub fn default_alpha(miq: bool) -> f64 {
    if miq {
        cones::MIQ_ALPHA
    } else {
        cones::DEFAULT_ALPHA
    }
}

/// Imports a mesh from `files` (an array of `{name: string, bytes: Uint8Array}`;
/// the first is the mesh, the rest companion buffers). Returns
/// `{report, positions: Float32Array, indices: Uint32Array}` with welded
/// vertices, or throws an `Error` naming the problem.
#[wasm_bindgen]
pub fn import_mesh(files: Array) -> Result<JsValue, JsError> {
    let session = MeshSession::open(files)?;
    let out = Object::new();
    set(&out, "report", &session.report()?)?;
    set(&out, "positions", &session.positions().into())?;
    set(&out, "indices", &session.indices().into())?;
    Ok(out.into())
}

/// An imported mesh kept in the worker between requests: its report, its
/// welded geometry and, when it has no blocking problem, the validated
/// [`TriMesh`] that cone placement and parametrization run on.
#[wasm_bindgen]
pub struct MeshSession {
    raw: RawMesh,
    /// The input files and, for glTF, where each vertex came from: exports
    /// carry the input's normals and materials over.
    files: Vec<InputFile>,
    source: Option<GltfSource>,
    report: MeshReport,
    /// The report's problems, named as the file numbers its elements and
    /// located in the ids of `positions` / `triangles`.
    problems: Vec<LocatedProblem>,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    mesh: Option<TriMesh>,
    /// The solve in progress through the `solve_*` steps.
    job: Option<Job>,
    /// The last solve's map, kept for `quads` (and its quantizer, set up on
    /// first use), with the solves of the decimations `quads` traced on.
    grid: Option<QuadStage>,
    refine: RefineOptions,
    boundary: BoundaryMode,
}

/// A solve run in steps: its features and settings, its cone stage and the
/// components placed so far.
struct Job {
    features: FeatureSet,
    /// Those of `features` found as creases (see `solve_begin`).
    creases: FeatureSet,
    options: SolveOptions,
    stage: SolveStage,
    placed: Vec<ComponentPlacement>,
}

#[wasm_bindgen]
impl MeshSession {
    /// Imports `files` (as for [`import_mesh`]); throws on unreadable input.
    /// A mesh with problems still opens: see `report()` and `is_valid()`.
    pub fn open(files: Array) -> Result<MeshSession, JsError> {
        let files = input_files(&files)?;
        let (main, others) = files.split_first().ok_or_else(|| JsError::new("no file given"))?;
        let io::Imported { raw, gltf: source, numbering } = io::import_file(main, others).map_err(|e| JsError::new(&e.to_string()))?;
        let mesh::Located { report, welded, problems } = mesh::analyze_located(&raw, &numbering);
        let mesh = TriMesh::from_raw(&raw).ok();
        let (positions, triangles) = match &mesh {
            Some(m) => (m.positions().to_vec(), m.faces().to_vec()),
            // The analysis's welding: the ids the problems are located in.
            None => (welded.positions, welded.triangles),
        };
        Ok(MeshSession {
            raw, files, source, report, problems, positions, triangles, mesh, job: None, grid: None,
            refine: RefineOptions::default(), boundary: BoundaryMode::Aligned,
        })
    }

    /// Refinements around cones of angle <= 0 that solves try before they
    /// fail (`undefined`: the default, 4); 0 shows what the cone placement
    /// alone gives, with the error's location.
    pub fn set_max_cone_refinements(&mut self, n: Option<u32>) {
        self.refine.max_cone_refinements = n.map_or(RefineOptions::default().max_cone_refinements, |n| n as usize);
    }

    /// Whether later cone placements and solves leave the mesh's boundary
    /// free (no isolines, no corners; features stay aligned) instead of
    /// aligning it (the default).
    pub fn set_free_boundary(&mut self, free: bool) {
        self.boundary = if free { BoundaryMode::Free } else { BoundaryMode::Aligned };
    }

    /// The mesh report (`MeshReport`) plus `problem_messages` (one line
    /// each, elements numbered as the file does: OBJ 1-based, glTF by mesh,
    /// primitive and accessor index) and `located_problems`: per problem
    /// `{kind, message, blocking, vertices, edges (vertex pairs, flat), faces}`
    /// in the ids of `positions()` / `indices()`.
    pub fn report(&self) -> Result<JsValue, JsError> {
        let value = serde_wasm_bindgen::to_value(&self.report).map_err(|e| JsError::new(&e.to_string()))?;
        let messages: Array = self.problems.iter().map(|p| JsValue::from(p.message.as_str())).collect();
        set(&value.clone().into(), "problem_messages", &messages.into())?;
        set(&value.clone().into(), "located_problems", &to_js(&self.problems)?)?;
        Ok(value)
    }

    /// True when the mesh has no blocking problem (cones and UVs can be computed).
    pub fn is_valid(&self) -> bool {
        self.mesh.is_some()
    }

    /// Welded vertex positions, xyz per vertex.
    pub fn positions(&self) -> Float32Array {
        let v: Vec<f32> = self.positions.iter().flat_map(|p| p.map(|c| c as f32)).collect();
        Float32Array::from(&v[..])
    }

    /// Triangles as welded vertex indices, 3 per face.
    pub fn indices(&self) -> Uint32Array {
        let v: Vec<u32> = self.triangles.iter().flatten().copied().collect();
        Uint32Array::from(&v[..])
    }

    /// Edges of the valid mesh, 2 vertex indices per edge; edge `i` is the
    /// id used by `sharp_edges`, `boundary_edges` and `place_cones`. Empty
    /// for an invalid mesh.
    pub fn edges(&self) -> Uint32Array {
        let v: Vec<u32> = match &self.mesh {
            Some(m) => (0..m.n_edges() as u32).flat_map(|e| m.edge_vertices(e)).collect(),
            None => Vec::new(),
        };
        Uint32Array::from(&v[..])
    }

    /// Ids of the boundary edges.
    pub fn boundary_edges(&self) -> Uint32Array {
        let v: Vec<u32> = match &self.mesh {
            Some(m) => (0..m.n_edges() as u32).filter(|&e| m.is_boundary_edge(e)).collect(),
            None => Vec::new(),
        };
        Uint32Array::from(&v[..])
    }

    /// Ids of the interior edges whose dihedral angle exceeds `degrees`.
    pub fn sharp_edges(&self, degrees: f64) -> Uint32Array {
        let v: Vec<u32> = match &self.mesh {
            Some(m) => FeatureSet::sharp_edges(m, degrees).edges().collect(),
            None => Vec::new(),
        };
        Uint32Array::from(&v[..])
    }

    /// Sharp edges above `degrees` without the curves of fewer than
    /// `min_edges` edges (0: keep all) and, when `closed_only`, without
    /// dangling ends: `{ edges: Uint32Array, stats }` (`features::SharpStats`).
    pub fn sharp_curves(&self, degrees: f64, min_edges: u32, closed_only: bool) -> Result<JsValue, JsError> {
        use crate::features::{detect_sharp, MinLength, SharpOptions};
        let mesh = self.valid_mesh()?;
        let min_length = if min_edges > 0 { MinLength::Edges(min_edges as usize) } else { MinLength::None };
        let found = detect_sharp(mesh, &SharpOptions { min_length, prune_dangling: closed_only, ..SharpOptions::threshold(degrees) });
        Ok(detection_object(&found)?.into())
    }

    /// The creases `conemap quads` follows where no features are given
    /// ([`crate::features::CREASES`]): `{ edges, stats }` as `sharp_curves`
    /// plus `degrees` (the threshold) and `min_length_fraction` (the
    /// shortest curve kept, a fraction of the bounding-box diagonal). Pass
    /// them to `solve_begin` as `creases` too, so that the grid map drops
    /// them where they fold it, as the CLI does.
    pub fn crease_edges(&self) -> Result<JsValue, JsError> {
        use crate::features::{detect_sharp, MinLength, CREASES};
        let found = detect_sharp(self.valid_mesh()?, &CREASES);
        let out = detection_object(&found)?;
        set(&out, "degrees", &CREASES.threshold_degrees.into())?;
        let fraction = match CREASES.min_length {
            MinLength::DiagonalFraction(f) => f,
            MinLength::None | MinLength::Edges(_) => 0.0,
        };
        set(&out, "min_length_fraction", &fraction.into())?;
        Ok(out.into())
    }

    /// Ids of the edges a features file or JSON report (`text`, see
    /// `io::parse_feature_edges`) names by their end positions; throws
    /// saying which edge does not match this mesh, or what the file lacks.
    pub fn features_from_json(&self, text: &str) -> Result<Uint32Array, JsError> {
        let mesh = self.valid_mesh()?;
        let edges = io::parse_feature_edges(text).map_err(|e| JsError::new(&e))?;
        let set = FeatureSet::from_positions(mesh, &edges).map_err(|e| JsError::new(&format!("{e}: the file does not match this mesh")))?;
        let ids: Vec<u32> = set.edges().collect();
        Ok(Uint32Array::from(&ids[..]))
    }

    /// Places cones with `feature_edges` (edge ids) as features.
    /// `progress(stage: string, step: number, remaining: number)` is called
    /// per topology step, rounding round and cone-move pass. Returns a
    /// [`ConeResult`] (cones on the mesh refined where the features need it).
    pub fn place_cones(
        &self,
        feature_edges: &[u32],
        alpha_smooth: Option<f64>,
        miq: bool,
        progress: &Function,
    ) -> Result<JsValue, JsError> {
        let (mesh, features, cones) = self.request(feature_edges, alpha_smooth, miq)?;
        let options = SolveOptions { cones, param: ParamOptions::default(), refine: self.refine };
        let placed = crate::pipeline::place_cones(mesh, &features, &options, &mut cone_progress(progress))
            .map_err(|e| JsError::new(&e.to_string()))?;
        to_js(&ConeResult::new(&placed.placement, features.len(), placed.refinement().0))
    }
}

#[wasm_bindgen]
impl MeshSession {
    /// Places cones and computes the seamless aligned map (the whole method).
    /// Returns a [`SolveResult`]: the `place_cones` fields plus the map, its
    /// metrics and the exports of the solved mesh. Solve errors throw as
    /// `solve_finish` says. `creases` (may be left out): as in `solve_begin`.
    pub fn solve(
        &mut self,
        feature_edges: &[u32],
        alpha_smooth: Option<f64>,
        miq: bool,
        progress: &Function,
        creases: Option<Vec<u32>>,
    ) -> Result<JsValue, JsValue> {
        let schedule = self.solve_begin(feature_edges, alpha_smooth, miq, creases)?;
        for c in schedule {
            self.solve_place(c, false, progress)?;
        }
        self.solve_finish(progress)
    }

    /// `solve` in steps, so that another session with the same mesh can place
    /// some components: `solve_begin`, then `solve_place` for every
    /// component (here, or elsewhere and handed over with `solve_add`), then
    /// `solve_finish`. Starts a solve (dropping any unfinished one); returns
    /// the components in the order to place them (largest first).
    /// `alpha_smooth` undefined: [`default_alpha`] of `miq`, as the CLI.
    /// `creases` (undefined: none): those of the feature edges that
    /// `crease_edges` found rather than the user marked; `quads` drops them
    /// on each component where they fold the map ([`GridFeatures`]).
    pub fn solve_begin(&mut self, feature_edges: &[u32], alpha_smooth: Option<f64>, miq: bool, creases: Option<Vec<u32>>) -> Result<Vec<u32>, JsError> {
        self.job = None;
        self.grid = None;
        let (mesh, features, cones) = self.request(feature_edges, alpha_smooth, miq)?;
        let creases = self.features(mesh, creases.as_deref().unwrap_or_default())?;
        let options = SolveOptions { cones, param: ParamOptions::default(), refine: self.refine };
        let stage = SolveStage::new(mesh, &features, &options);
        let schedule = stage.schedule().iter().map(|&c| c as u32).collect();
        self.job = Some(Job { features, creases, options, stage, placed: Vec::new() });
        Ok(schedule)
    }

    /// Places component `component` of the started solve and keeps it;
    /// with `share`, also returns it as bytes for `solve_add` in another session.
    /// A placement error throws with a `location` where it names mesh elements.
    pub fn solve_place(&mut self, component: u32, share: bool, progress: &Function) -> Result<Option<Uint8Array>, JsValue> {
        let job = self.job.as_mut().ok_or_else(|| JsError::new("no solve was started"))?;
        let n = job.stage.n_components();
        if component as usize >= n {
            return Err(JsError::new(&format!("component {component} is out of range ({n} components)")).into());
        }
        let mesh = self.mesh.as_ref().ok_or_else(|| JsError::new("no valid mesh is open"))?;
        let placed = job
            .stage
            .place_component(mesh, &job.features, component as usize, &mut cone_progress(progress))
            .map_err(|e| solve_error(&e))?;
        let bytes = share.then(|| Uint8Array::from(&placed.to_json()[..]));
        job.placed.push(placed);
        Ok(bytes)
    }

    /// Adds a component placed by another session (`solve_place` with `share`).
    pub fn solve_add(&mut self, bytes: &[u8]) -> Result<(), JsError> {
        let job = self.job.as_mut().ok_or_else(|| JsError::new("no solve was started"))?;
        job.placed.push(ComponentPlacement::from_json(bytes).map_err(|e| JsError::new(&e.to_string()))?);
        Ok(())
    }

    /// Joins the placed components and computes the parametrization (any
    /// refinement around cones of angle 0 is placed here); returns what
    /// `solve` returns. Ends the started solve. Throws an `Error` with the
    /// solve error's message and, where it names mesh elements, `location:
    /// {vertices: number[], edges: number[]}` in input ids ([`solve_error`]).
    pub fn solve_finish(&mut self, progress: &Function) -> Result<JsValue, JsValue> {
        let Job { features, creases, options, stage, placed } = self.job.take().ok_or_else(|| JsError::new("no solve was started"))?;
        let mesh = self.valid_mesh()?;
        let fail = |e: SolveError| solve_error(&e);
        let sol = stage.finish(mesh, &features, placed, &mut solve_progress(progress)).map_err(fail)?;
        let result = self.solution_object(mesh, &features, &sol)?;
        // (The stage keeps the settings as solved: a low-poly fallback's edge length is not asked again.)
        let solved = sol.into_owned();
        let features = GridFeatures::with_creases(features, &creases);
        let solved = GridStage::new(solved, features.clone(), options, LongEdges::RefineFirst);
        self.grid = Some(QuadStage::with_solved(solved, features, QuadOptions { solve: options, ..QuadOptions::default() }));
        Ok(result)
    }

    /// The integer-grid map of the last solve for about `quads` grid cells
    /// and the quad mesh traced on it (a [`QuadsResult`]), by
    /// [`QuadStage::quads`]: on a mesh of more than twice
    /// [`crate::pipeline::COARSE_FACES_PER_QUAD`] faces per quad, traced on
    /// a decimation solved for this grid and moved onto the mesh (the
    /// grid map carried back to the mesh's triangles by
    /// [`corner_values_onto`]); otherwise on the solve's map, re-running
    /// only quantization and extraction unless this grid asks for a solve
    /// that the last calls did not (the first call on a mesh with edges
    /// longer than a quad mesh wants, opposite cones the grid puts closer
    /// than a cell's diagonal, feature curves finer than a grid that folds
    /// the map). Throws when nothing was solved yet, with the solve error
    /// as `solve_finish` does, or with the quantization error (a free
    /// boundary, say).
    pub fn quads(&mut self, quads: u32, progress: &Function) -> Result<JsValue, JsValue> {
        self.valid_mesh()?;
        // Out of the session while it runs, so that the result may borrow
        // both; back in whatever happens.
        let mut grid = self.grid.take().ok_or_else(|| JsError::new("solve the map before asking for quads"))?;
        let result = self.quads_on(&mut grid, quads, progress);
        self.grid = Some(grid);
        result
    }
}

impl MeshSession {
    /// [`MeshSession::quads`] on `grid`.
    fn quads_on(&self, grid: &mut QuadStage, quads: u32, progress: &Function) -> Result<JsValue, JsValue> {
        let input = self.valid_mesh()?;
        let creases = grid.features().detected.clone();
        let traced = grid.quads(input, GridSize::Quads(quads as usize), &mut |p| quad_progress(progress, p)).map_err(|e| match e {
            QuadsError::Solve(e) => solve_error(&e),
            e => JsError::new(&e.to_string()).into(),
        })?;
        let TracedQuads { solution: sol, map, dropped_features: dropped, cancelled_pairs, quads: quad_mesh, report, decimation, timings, .. } = traced;
        let corner_uv = match decimation {
            Some(_) => corner_values_onto(&sol.mesh, &map.uv, input),
            None => sol.input_corner_values(input, &map.uv),
        };
        let uv: Vec<f32> = corner_uv.iter().flat_map(|p| p.map(|c| c as f32)).collect();
        let positions: Vec<f32> = quad_mesh.positions.iter().flat_map(|p| p.map(|c| c as f32)).collect();
        let corners: Vec<u32> = quad_mesh.quads.iter().flatten().copied().collect();
        let edges: Vec<u32> = quads::check::quad_edges(&quad_mesh).iter().flat_map(|e| e.vertices).collect();
        let singular: Vec<u32> = report.singular_vertices.iter().filter(|v| !v.boundary).flat_map(|v| [v.vertex, v.valence]).collect();
        let grid_options = ExportOptions { grid_units: true, checker_cell: Some(1.0), ..ExportOptions::default() };
        // On a decimation, the input's triangles with the map carried back.
        let grid_glb = match decimation {
            Some(_) => self.export_corners(None, &corner_uv, |input| export::write_glb(input, &grid_options))?,
            None => self.export_solved(&sol, &map.uv, |input| export::write_glb(input, &grid_options))?,
        };
        let obj = export::quads::write_quad_obj(&quad_mesh, &format!("{} quads, grid cell {}", quad_mesh.n_quads(), map.report.grid_size));
        Ok(to_js(&QuadsResult {
            quantization: &map.report,
            report: &report,
            uv: Float32Array::from(&uv[..]),
            positions: Float32Array::from(&positions[..]),
            quads: Uint32Array::from(&corners[..]),
            edges: Uint32Array::from(&edges[..]),
            singular: Uint32Array::from(&singular[..]),
            defects: quad_mesh.defects.len(),
            cones: sol.placement.cones.len(),
            cancelled_pairs,
            dropped_feature_edges: dropped.len(),
            dropped_crease_edges: dropped.intersection(&creases).len(),
            solved_faces: sol.mesh.n_faces(),
            inserted_vertices: sol.splits,
            refinement: &sol.refinement,
            decimated: decimation,
            timings,
            obj: Uint8Array::from(obj.as_bytes()),
            glb: Uint8Array::from(&export::quads::write_quad_glb(&quad_mesh)[..]),
            grid_glb: Uint8Array::from(&grid_glb[..]),
        })?)
    }
}

/// Reports a quad request's stage on `progress` as the solve's are.
fn quad_progress(progress: &Function, p: QuadProgress) {
    match p {
        QuadProgress::Decimate { .. } => notify(progress, "decimation", 0, 0, None),
        QuadProgress::Solve(p) => solve_progress(progress)(p),
        QuadProgress::Quantize { done, total } => notify(progress, "quantization", done, total, None),
        QuadProgress::Extract => notify(progress, "quad extraction", 0, 0, None),
    }
}

/// Stage name and two counters of a parametrization progress report.
fn param_stage(p: &ParamProgress) -> (&'static str, usize, usize) {
    match *p {
        ParamProgress::Field => ("cross-field", 0, 0),
        ParamProgress::Cut => ("cut", 0, 0),
        ParamProgress::Poisson => ("poisson", 0, 0),
        ParamProgress::Arap { iteration, max } => ("arap", iteration, max),
        ParamProgress::Repair { round, flips } => ("repair", round, flips),
        ParamProgress::Injective { iteration, max } => ("injective", iteration, max),
    }
}

impl MeshSession {
    /// The result of `solve` for the solution `sol` of `mesh` (see [`SolveResult`]).
    /// `write` applied to the export input of the solved mesh with per-corner
    /// `uv`: the input's own attributes when the solve split nothing, else
    /// the refined mesh (exactly, with its split edges).
    fn export_solved<R>(&self, sol: &Solution, uv: &[[f64; 2]], write: impl FnOnce(&ExportInput) -> R) -> Result<R, JsError> {
        self.export_corners((sol.splits > 0).then_some(&*sol.mesh), uv, write)
    }

    /// `write` applied to the export input of the input mesh (with its own
    /// attributes), or of its refinement `refined`, with per-corner `uv`.
    fn export_corners<R>(&self, refined: Option<&TriMesh>, uv: &[[f64; 2]], write: impl FnOnce(&ExportInput) -> R) -> Result<R, JsError> {
        let solved_raw;
        let (raw, mesh) = match refined {
            Some(mesh) => {
                solved_raw = RawMesh { positions: mesh.positions().to_vec(), triangles: mesh.faces().to_vec() };
                (&solved_raw, mesh)
            }
            None => (&self.raw, self.valid_mesh()?),
        };
        let mut input = ExportInput::new(raw, mesh, uv).map_err(|e| JsError::new(&e.to_string()))?;
        if let (Some(source), None) = (&self.source, refined) {
            input = input.with_gltf_source(source, &self.files[0], &self.files[1..]);
        }
        Ok(write(&input))
    }

    fn solution_object(&self, mesh: &TriMesh, features: &FeatureSet, sol: &Solution) -> Result<JsValue, JsError> {
        let corner_uv = sol.input_corner_uv(mesh);
        let uv: Vec<f32> = corner_uv.iter().flat_map(|p| p.map(|c| c as f32)).collect();
        let per_face: Vec<f32> =
            param::metrics::face_distortion(mesh, &corner_uv, sol.param.metrics.scale).iter().map(|&d| d as f32).collect();
        let (glb, obj) = self.export_solved(sol, &sol.param.uv, |input| {
            (export::write_glb(input, &ExportOptions::default()), export::write_obj(input, &ExportOptions::default()))
        })?;
        to_js(&SolveResult {
            cones: ConeResult::new(&sol.placement, sol.features.len(), sol.splits),
            uv: Float32Array::from(&uv[..]),
            seam_edges: Uint32Array::from(&sol.input_seam_edges(mesh)[..]),
            metrics: SolveMetrics { figures: &sol.param.metrics, per_face_distortion: Float32Array::from(&per_face[..]) },
            param_timings: &sol.param.timings,
            refinement: &sol.refinement,
            flip_refinements: sol.flip_refinements,
            realized_cones: sol.param.realized_cones.len(),
            feature_alignment: sol.feature_alignment(mesh, features),
            glb: Uint8Array::from(&glb[..]),
            obj: Uint8Array::from(obj.as_bytes()),
        })
    }
}

impl MeshSession {
    /// Checks a cones/solve request: the valid mesh, its features from edge
    /// ids, and the cone options.
    fn request(&self, feature_edges: &[u32], alpha_smooth: Option<f64>, miq: bool) -> Result<(&TriMesh, FeatureSet, ConeOptions), JsError> {
        let mesh = self.valid_mesh()?;
        let features = self.features(mesh, feature_edges)?;
        let alpha_smooth = alpha_smooth.unwrap_or_else(|| default_alpha(miq));
        let (lo, hi) = cones::ALPHA_RANGE;
        if !(lo..=hi).contains(&alpha_smooth) {
            return Err(JsError::new(&format!("alpha_smooth {alpha_smooth} is outside {lo}..{hi}")));
        }
        Ok((mesh, features, ConeOptions { alpha_smooth, miq, boundary: self.boundary, ..ConeOptions::default() }))
    }

    fn valid_mesh(&self) -> Result<&TriMesh, JsError> {
        self.mesh.as_ref().ok_or_else(|| {
            let first = self.problems.iter().find(|p| p.blocking).map(|p| p.message.as_str()).unwrap_or_default();
            JsError::new(&format!("this mesh cannot be parametrized: {first}"))
        })
    }

    fn features(&self, mesh: &TriMesh, edges: &[u32]) -> Result<FeatureSet, JsError> {
        let mut set = FeatureSet::none(mesh);
        for &e in edges {
            if e as usize >= mesh.n_edges() {
                return Err(JsError::new(&format!("feature edge id {e} is out of range ({} edges)", mesh.n_edges())));
            }
            set.set(mesh, e, true);
        }
        Ok(set)
    }
}

/// A JS `Error` with the message of `e` and, when `e` names mesh elements,
/// a `location` property `{vertices: number[], edges: number[]}` (input ids).
fn solve_error(e: &SolveError) -> JsValue {
    let error = js_sys::Error::new(&e.to_string());
    if let Some(location) = e.location() {
        // Without its location the error still says where, in words.
        if let Ok(value) = serde_wasm_bindgen::to_value(location) {
            let _ = Reflect::set(&error, &"location".into(), &value);
        }
    }
    error.into()
}

/// Calls the page's `progress(stage, step, remaining[, fraction])` (the
/// fraction of the stage done, where the stage knows it); a throwing
/// callback must not stop the solve, so its error is ignored.
fn notify(progress: &Function, stage: &str, a: usize, b: usize, fraction: Option<f64>) {
    let (stage, a, b) = (JsValue::from(stage), JsValue::from(a as f64), JsValue::from(b as f64));
    let _ = match fraction {
        Some(f) => progress.apply(&JsValue::NULL, &Array::of4(&stage, &a, &b, &f.into())),
        None => progress.call3(&JsValue::NULL, &stage, &a, &b),
    };
}

/// Forwards the progress of both stages to the page's `progress`.
fn solve_progress(progress: &Function) -> impl FnMut(SolveProgress) + '_ {
    move |p| {
        let (stage, a, b, fraction) = match p {
            SolveProgress::Cones(c) => cone_stage(&c),
            SolveProgress::Param(p) => {
                let (stage, a, b) = param_stage(&p);
                (stage, a, b, None)
            }
        };
        notify(progress, stage, a, b, fraction);
    }
}

/// Forwards cone-placement progress to the page's `progress`.
fn cone_progress(progress: &Function) -> impl FnMut(ConeProgress) + '_ {
    move |p| {
        let (stage, a, b, fraction) = cone_stage(&p);
        notify(progress, stage, a, b, fraction);
    }
}

/// Stage name, two counters and the fraction done (where known) of a
/// cone-placement progress report: cone moves and pair cancellation give the
/// share of the current pass's candidates evaluated (`remaining`: those left).
fn cone_stage(p: &ConeProgress) -> (&'static str, usize, usize, Option<f64>) {
    let share = |done: usize, of: usize| (of > 0).then(|| done as f64 / of as f64);
    match *p {
        ConeProgress::Topology { component, components } => ("topology", component, components, None),
        ConeProgress::Rounding { round, free, .. } => ("rounding", round, free, None),
        ConeProgress::ConeMoves { pass, tried, cones, .. } => ("cone moves", pass, cones - tried, share(tried, cones)),
        ConeProgress::PairCancellation { removed, tried, trials, .. } => ("pair cancellation", removed, trials - tried, share(tried, trials)),
    }
}

/// What `place_cones` returns, and the first fields of [`SolveResult`];
/// mirrored field for field by `ConeResult` in `web/src/protocol.ts`.
#[derive(Serialize)]
struct ConeResult<'a> {
    cones: &'a [Cone],
    boundary_corners: &'a [Cone],
    components: &'a [ComponentFigures],
    rounds: usize,
    energy: f64,
    phi_rms: f64,
    timings: &'a ConeTimings,
    /// Feature edges of the request.
    feature_edges: usize,
    free_boundary: bool,
    /// Vertices the refinement inserted (around features and cones).
    inserted_vertices: usize,
}

impl<'a> ConeResult<'a> {
    fn new(r: &'a ConePlacement, feature_edges: usize, inserted_vertices: usize) -> ConeResult<'a> {
        ConeResult {
            cones: &r.cones,
            boundary_corners: &r.boundary_corners,
            components: &r.components,
            rounds: r.rounds,
            energy: r.energy,
            phi_rms: r.phi_rms,
            timings: &r.timings,
            feature_edges,
            free_boundary: r.cut.has_free_boundary(),
            inserted_vertices,
        }
    }
}

/// What `solve` / `solve_finish` return; mirrored field for field by
/// `WasmSolveResult` in `web/src/protocol.ts`. Arrays cross as typed arrays.
#[derive(Serialize)]
struct SolveResult<'a> {
    #[serde(flatten)]
    cones: ConeResult<'a>,
    /// Two per input face corner `3 f + k`.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    uv: Float32Array,
    /// Input edge ids.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    seam_edges: Uint32Array,
    metrics: SolveMetrics<'a>,
    param_timings: &'a ParamTimings,
    refinement: &'a RefineCounts,
    flip_refinements: usize,
    realized_cones: usize,
    feature_alignment: FeatureAlignment,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    glb: Uint8Array,
    /// The OBJ export, UTF-8.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    obj: Uint8Array,
}

/// What `quads` returns; mirrored field for field by `QuadsResult` in
/// `web/src/protocol.ts`.
#[derive(Serialize)]
struct QuadsResult<'a> {
    quantization: &'a QuantizeReport,
    report: &'a QuadReport,
    /// The integer-grid map, two per input face corner, in grid units.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    uv: Float32Array,
    /// Quad mesh: three per vertex, four vertex ids per quad, two per edge,
    /// and (vertex, valence) per interior singular vertex.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    positions: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    quads: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    edges: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    singular: Uint32Array,
    /// Places the extractor had to repair.
    defects: usize,
    /// Cones of the map quantized, and the pairs of opposite cones of the
    /// solve's map cancelled for this grid (closer than a cell's diagonal;
    /// 0 on a map solved without dropped features, which cancels its own).
    cones: usize,
    cancelled_pairs: usize,
    /// The input's feature edges the map was solved without, where the map
    /// with all of them folded ([`GridStage::map`]; 0: every feature kept),
    /// and how many of them were creases (`solve_begin`'s `creases`).
    dropped_feature_edges: usize,
    dropped_crease_edges: usize,
    /// The mesh the map was solved on: its faces, the vertices inserted into
    /// the input, and why ([`pipeline::long_edges_refine`] may have refined it).
    solved_faces: usize,
    inserted_vertices: usize,
    refinement: &'a RefineCounts,
    /// The decimation the quads were traced on (`null`: on the mesh solved),
    /// and the seconds per stage.
    decimated: Option<Decimation>,
    timings: QuadTimings,
    /// The quad mesh as OBJ (UTF-8) and binary glTF.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    obj: Uint8Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    glb: Uint8Array,
    /// The solved mesh with the integer-grid UVs (grid units), binary glTF.
    #[serde(with = "serde_wasm_bindgen::preserve")]
    grid_glb: Uint8Array,
}

/// The map's [`Metrics`] and the distortion of every input face.
#[derive(Serialize)]
struct SolveMetrics<'a> {
    #[serde(flatten)]
    figures: &'a Metrics,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    per_face_distortion: Float32Array,
}

/// `value` as a plain JS object (maps too, as `#[serde(flatten)]` makes them).
fn to_js<T: Serialize>(value: &T) -> Result<JsValue, JsError> {
    let serializer = serde_wasm_bindgen::Serializer::new().serialize_maps_as_objects(true);
    value.serialize(&serializer).map_err(|e| JsError::new(&e.to_string()))
}

/// `{ edges: Uint32Array, stats }` of a sharp-edge detection.
fn detection_object(found: &crate::features::SharpDetection) -> Result<Object, JsError> {
    let edges: Vec<u32> = found.features.edges().collect();
    let out = Object::new();
    set(&out, "edges", &Uint32Array::from(&edges[..]).into())?;
    set(&out, "stats", &to_js(&found.stats)?)?;
    Ok(out)
}

fn input_files(files: &Array) -> Result<Vec<InputFile>, JsError> {
    files
        .iter()
        .map(|f| {
            let name = Reflect::get(&f, &"name".into())
                .ok()
                .and_then(|n| n.as_string())
                .ok_or_else(|| JsError::new("each file needs a string `name`"))?;
            let bytes = Reflect::get(&f, &"bytes".into())
                .ok()
                .filter(|b| b.is_instance_of::<Uint8Array>())
                .ok_or_else(|| JsError::new("each file needs `bytes` as a Uint8Array"))?;
            Ok(InputFile { name, bytes: Uint8Array::from(bytes).to_vec() })
        })
        .collect()
}

fn set(obj: &Object, key: &str, value: &JsValue) -> Result<(), JsError> {
    Reflect::set(obj, &key.into(), value).map(|_| ()).map_err(|_| JsError::new("could not build the result object"))
}
