//! The whole method in one call: refine doubly constrained triangles, place
//! cones (sections 4-5) — refining around any vertex that would need a cone
//! of angle 0 and placing them again —, then compute the seamless aligned
//! parametrization (Appendix B). A mesh of several components is solved one
//! component at a time and the solutions joined (module `parts`). The CLI
//! calls [`solve`]; the wasm API runs the same steps ([`SolveStage`]) so
//! that a helper worker can place components.
//! Errors that name mesh elements carry them in input-mesh indices
//! ([`SolveError::location`], module `location`).

use crate::clock::{now_seconds, Stopwatch};
use crate::cones::{self, ComponentPlacement, ConeError, ConeOptions, ConePlacement, ConeProblem, MismatchError, RoundingRule};
use crate::features::{refine_for_features_on, split_around, split_flipped, split_long_edges, FeatureSet, RefineCounts, Refined};
use crate::mesh::TriMesh;
use crate::param::quantize::GridSize;
use crate::param::{self, ParamError, ParamOptions, ParamProgress, Parametrization};
use std::borrow::Cow;
use std::fmt;

mod coarse;
mod grid;
mod location;
mod parts;
mod quad_stage;
pub use coarse::{corner_values_onto, Coarse, COARSE_FACES_PER_QUAD, COARSE_MAX_DISTANCE, COARSE_MIN_TURN_COS};
pub use grid::{grid_map, GridFeatures, GridMapped, GridStage, LongEdges};
pub use quad_stage::{Attempts, Decimation, QuadOptions, QuadProgress, QuadStage, QuadTimings, QuadsError, TracedQuads};
pub use location::{enclosing_features, ErrorLocation, MAX_LOCATION_EDGES};
use location::Lift;
use parts::Parts;

/// Settings of both stages.
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveOptions {
    pub cones: ConeOptions,
    pub param: ParamOptions,
    pub refine: RefineOptions,
}

/// How often the pipeline refines the mesh and solves again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineOptions {
    /// Refinements around cones of index >= 4 (angle <= 0) before the solve
    /// fails with [`crate::param::ParamError::DegenerateCone`]; 0 reports
    /// what the cone placement alone gives.
    pub max_cone_refinements: usize,
    /// Refinements around triangles a map leaves flipped ([`Placed::parametrize`]).
    pub max_flip_refinements: usize,
    /// Before the cones, split edges longer than this ([`split_long_edges`]);
    /// `None`: solve on the input's triangles. A quad mesh of a low-poly
    /// input (a CAD export) wants it; a UV map of one usually keeps its triangles.
    pub max_edge_length: Option<f64>,
}

impl Default for RefineOptions {
    fn default() -> Self {
        // 4: with 2, bff-face at --sharp 60 ended with an index-9 cone.
        RefineOptions { max_cone_refinements: 4, max_flip_refinements: 2, max_edge_length: None }
    }
}

/// The longest edge the solve behind a quad mesh keeps, as a fraction of
/// the input's bounding-box diagonal ([`RefineOptions::for_quads`]). A
/// low-poly input (a CAD export: fans and strips of long, thin triangles)
/// has too few vertices for cones where they belong and for a map that
/// bends with the surface: block with a hole, 208 faces, at 1 000 quads,
/// 661 defects and distortion 0.47 as given, none and 0.07 refined to 5 %
/// (3 %: 3 defects; finer costs seconds of rounding). Meshes with edges
/// all shorter (spot, fandisk, teapot) are not touched.
pub const QUAD_MAX_EDGE: f64 = 0.05;

/// The longest edge the solve behind a quad mesh keeps, in quads (of the
/// size asked for, or `sqrt(area / quads)`), where that is shorter than
/// [`QUAD_MAX_EDGE`]: the diagonal of a scene grows with its objects, not
/// its quads. Sixteen copies of a game asset side by side at 16 times the
/// quads kept edges of 8 quads (287 defects, Euler characteristic off), the
/// asset alone edges of 2.1 (none). 3.5 leaves every shared mesh at 3 000
/// quads as [`QUAD_MAX_EDGE`] has it (gazebo 2.1, fandisk 2.7, cow 3.3 quads).
pub const QUAD_MAX_EDGE_QUADS: f64 = 3.5;

impl RefineOptions {
    /// The default refinements plus, for a quad mesh of `mesh` with quads
    /// of `grid`, edges split down to [`QUAD_MAX_EDGE`] of its bounding-box
    /// diagonal or [`QUAD_MAX_EDGE_QUADS`] quads, whichever is shorter.
    pub fn for_quads(mesh: &TriMesh, grid: GridSize) -> RefineOptions {
        let quad = quad_length(mesh, grid);
        let (by_diagonal, by_quads) = (QUAD_MAX_EDGE * mesh.bounding_diagonal(), QUAD_MAX_EDGE_QUADS * quad);
        // (A grid size that is not a positive length is the quantization's error to report.)
        let length = if by_quads > 0.0 && by_quads.is_finite() { by_diagonal.min(by_quads) } else { by_diagonal };
        RefineOptions { max_edge_length: Some(length), ..RefineOptions::default() }
    }
}

/// The edge length of a quad of `grid` on `mesh`: the length given, or
/// `sqrt(area / quads)` (the surface's area: about the map's).
pub fn quad_length(mesh: &TriMesh, grid: GridSize) -> f64 {
    match grid {
        GridSize::Length(s) => s,
        GridSize::Quads(n) => (mesh.face_areas().iter().sum::<f64>() / n.max(1) as f64).sqrt(),
    }
}

impl SolveOptions {
    /// These settings for the map behind an integer-grid map of `grid` on
    /// `mesh`: opposite cones closer than a grid cell's diagonal cancel
    /// ([`cones::ConeOptions::min_pair_distance`]). Where they were kept,
    /// the rounding put each such pair on one grid point or folded the
    /// cells between them.
    pub fn for_quads(self, mesh: &TriMesh, grid: GridSize) -> SolveOptions {
        let min_pair_distance = cones::GRID_PAIR_CELLS * quad_length(mesh, grid);
        SolveOptions { cones: ConeOptions { min_pair_distance, ..self.cones }, ..self }
    }
}

/// The settings to solve `mesh` again with when a map solved with `refine`
/// is not fine enough (for quads of `grid`, or, with `None`, because it
/// folds on a low-poly mesh): `refine` asked for no maximum edge length and
/// `mesh` has edges longer than [`RefineOptions::for_quads`] keeps (without
/// a grid: [`QUAD_MAX_EDGE`] of its diagonal). `None`: keep the map as it is.
pub fn long_edges_refine(mesh: &TriMesh, refine: &RefineOptions, grid: Option<GridSize>) -> Option<RefineOptions> {
    let length = match grid {
        Some(grid) => RefineOptions::for_quads(mesh, grid).max_edge_length?,
        None => QUAD_MAX_EDGE * mesh.bounding_diagonal(),
    };
    let long = (0..mesh.n_edges() as u32).any(|e| mesh.edge_length(e) > length);
    (refine.max_edge_length.is_none() && long).then_some(RefineOptions { max_edge_length: Some(length), ..*refine })
}

/// Below this many faces a mesh whose map still folds after the local
/// refinements is refined everywhere and solved again ([`Placed::parametrize`]).
pub const LOW_POLY_FACES: usize = 5_000;

/// Progress of either stage.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveProgress {
    Cones(cones::ConeProgress),
    Param(ParamProgress),
}

/// What failed. Mesh elements named here are those of the mesh the stage
/// solved on (the refinement of the input, if any; for cone errors its cut):
/// [`SolveError::location`] has them in input indices.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveCause {
    Cones(ConeError),
    /// Component placements from elsewhere that do not fit the stage.
    Components(MismatchError),
    Param(ParamError),
    /// The best map after every flip refinement still folds: `flipped`
    /// triangles with UV area <= 0, `wound` folded vertices
    /// ([`param::metrics::Metrics::wound_vertices`]); `faces` are the
    /// flipped triangles and those around the folded vertices.
    Folded { flipped: usize, wound: usize, refinements: usize, faces: Vec<u32> },
}

impl fmt::Display for SolveCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveCause::Cones(e) => write!(f, "{e}"),
            SolveCause::Components(e) => write!(f, "{e}"),
            SolveCause::Param(e) => write!(f, "parametrization: {e}"),
            SolveCause::Folded { flipped, wound, refinements, .. } => write!(
                f,
                "parametrization: the map still folds after {refinements} refinements ({flipped} flipped triangles, {wound} folded vertices)"
            ),
        }
    }
}

/// Why solving failed: the cause and, when it names mesh elements, where
/// they are on the input mesh (its message then names input indices too).
#[derive(Clone, Debug, PartialEq)]
pub struct SolveError {
    pub cause: SolveCause,
    /// The location and the message in input terms.
    located: Option<(ErrorLocation, String)>,
}

impl SolveError {
    /// `cause` located through `lift` (no location when it names no mesh element).
    fn new(lift: &Lift, cause: SolveCause) -> SolveError {
        let located = location::locate(lift, &cause);
        SolveError { cause, located }
    }

    /// An error that names no mesh element (component results that do not fit).
    fn unlocated(cause: SolveCause) -> SolveError {
        SolveError { cause, located: None }
    }

    /// The input-mesh vertices and edges the error is about; `None` when it
    /// names none (e.g. a linear solve that failed).
    pub fn location(&self) -> Option<&ErrorLocation> {
        self.located.as_ref().map(|(l, _)| l)
    }
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.located {
            Some((_, message)) => f.write_str(message),
            None => write!(f, "{}", self.cause),
        }
    }
}

impl std::error::Error for SolveError {
    /// The stage's own error (cones, component results or parametrization).
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.cause {
            SolveCause::Cones(e) => Some(e),
            SolveCause::Components(e) => Some(e),
            SolveCause::Param(e) => Some(e),
            SolveCause::Folded { .. } => None,
        }
    }
}

/// The result: the mesh actually parametrized (the input, or the input with
/// doubly constrained triangles split), its features, cones and UVs.
#[derive(Clone, Debug)]
pub struct Solution<'a> {
    pub mesh: Cow<'a, TriMesh>,
    pub features: Cow<'a, FeatureSet>,
    /// Edges split before solving (0: `mesh` is the input).
    pub splits: usize,
    /// When split: solved face → input face, solved vertex → input
    /// vertex (`NONE` for inserted vertices) and solved edge → the input
    /// edge it is a piece of (`NONE` for edges inside input faces).
    pub original_face: Option<Vec<u32>>,
    pub original_vertex: Option<Vec<u32>>,
    pub original_edge: Option<Vec<u32>>,
    /// What the refinement split, by reason.
    pub refinement: RefineCounts,
    /// Times the longest edges of flipped triangles were split and everything
    /// solved again ([`Placed::parametrize`]).
    pub flip_refinements: usize,
    pub placement: ConePlacement,
    pub param: Parametrization,
    /// Seconds spent refining.
    pub refine_seconds: f64,
    /// The refinement options the solution was solved with: those asked
    /// for, or the maximum edge length of the low-poly fallback.
    pub refine_options: RefineOptions,
}

/// Largest angle (radians) between a feature edge's UV image and an axis
/// for the edge to count as aligned: solver round-off is about 1e-13 here.
pub const ALIGNED_TOLERANCE: f64 = 1e-9;

/// How the requested feature edges came out ([`Solution::feature_alignment`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FeatureAlignment {
    /// Feature edges requested (input edges).
    pub requested: usize,
    /// Of those, the edges whose UV image on every side (every piece, where
    /// the refinement split the edge) is parallel to an axis within [`ALIGNED_TOLERANCE`].
    pub aligned: usize,
    /// Largest deviation from an axis over all requested edges, radians.
    pub worst_radians: f64,
    /// The requested edges that are not aligned, worst first.
    pub unaligned: Vec<UnalignedFeature>,
}

/// A requested feature edge whose UV image is off an axis.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UnalignedFeature {
    /// Input edge id and its end vertices (input ids).
    pub edge: u32,
    pub vertices: [u32; 2],
    /// Deviation from the nearest axis, degrees.
    pub degrees: f64,
}

impl Solution<'_> {
    /// This solution owning its mesh and features (to keep it past its input).
    pub fn into_owned(self) -> Solution<'static> {
        Solution { mesh: Cow::Owned(self.mesh.into_owned()), features: Cow::Owned(self.features.into_owned()), ..self }
    }

    /// The quantization of this map ([`param::quantize`]): set up once, run
    /// for any grid size without placing cones again.
    pub fn quantizer(&self) -> Result<param::quantize::Quantizer, param::quantize::QuantizeError> {
        param::quantize::Quantizer::new(&self.mesh, &self.placement, &self.param)
    }

    /// Faces (of `mesh`) whose UV triangle is flipped or degenerate.
    pub fn flipped_faces(&self) -> Vec<u32> {
        let uv = &self.param.uv;
        (0..self.mesh.n_faces() as u32)
            .filter(|&f| !(param::element::signed_uv_area([0, 1, 2].map(|k| uv[3 * f as usize + k])) > 0.0))
            .collect()
    }

    /// Flipped faces and the faces around folded vertices (of `mesh`).
    fn folded_faces(&self) -> Vec<u32> {
        let wound = param::metrics::wound_vertices(&self.mesh, &self.placement, &self.param.uv);
        let mut faces = self.flipped_faces();
        faces.extend(wound.iter().flat_map(|&v| self.mesh.vertex_faces(v)));
        faces.sort_unstable();
        faces.dedup();
        faces
    }

    /// How the mesh solved on maps to the input `mesh` (with its `features`).
    fn lift<'s>(&'s self, input: &'s TriMesh, features: &'s FeatureSet) -> Lift<'s> {
        Lift {
            input,
            features,
            solved: &self.mesh,
            solved_features: &self.features,
            original_vertex: self.original_vertex.as_deref(),
            original_edge: self.original_edge.as_deref(),
            original_face: self.original_face.as_deref(),
        }
    }

    /// Faces (of `mesh`) around the cones the map realized with another
    /// index than placed ([`param::Parametrization::realized_cones`]): the
    /// map is locally injective there, but the placement's angle did not fit.
    pub fn realized_cone_faces(&self) -> Vec<u32> {
        let cut = &self.placement.cut;
        let mut faces: Vec<u32> =
            self.param.realized_cones.iter().flat_map(|&(cv, _)| self.mesh.vertex_faces(cut.original_vertex[cv as usize])).collect();
        faces.sort_unstable();
        faces.dedup();
        faces
    }

    /// Flipped triangles, then realized cones: what a flip refinement tries
    /// to lower, in this order.
    fn defects(&self) -> (usize, usize) {
        (self.param.metrics.flipped, self.param.realized_cones.len())
    }

    /// The refinement of the input this solution was computed on (`None`:
    /// the input itself), to refine further.
    fn refinement_of_input(&self) -> Option<Refined> {
        let (Some(original_face), Some(original_vertex), Some(original_edge)) =
            (&self.original_face, &self.original_vertex, &self.original_edge)
        else {
            return None;
        };
        Some(Refined {
            mesh: self.mesh.clone().into_owned(),
            features: self.features.clone().into_owned(),
            original_face: original_face.clone(),
            original_vertex: original_vertex.clone(),
            original_edge: original_edge.clone(),
            splits: self.splits,
            counts: self.refinement,
        })
    }

    /// The edges of the mesh solved on that are pieces of the input edges
    /// in `input_features` (a feature set of the input mesh), ascending.
    pub fn solved_edges_of(&self, input_features: &FeatureSet) -> Vec<u32> {
        (0..self.mesh.n_edges() as u32)
            .filter(|&e| {
                let orig = self.original_edge.as_ref().map_or(e, |oe| oe[e as usize]);
                orig != crate::mesh::NONE && input_features.contains(orig)
            })
            .collect()
    }

    /// Checks every requested feature edge (`requested`, on the INPUT mesh
    /// `input`) the way an outside checker does: the UV image of the edge,
    /// on both faces beside it, must be parallel to an axis.
    pub fn feature_alignment(&self, input: &TriMesh, requested: &FeatureSet) -> FeatureAlignment {
        let m = &*self.mesh;
        let mut worst = vec![f64::NAN; input.n_edges()];
        for h in 0..3 * m.n_faces() as u32 {
            let e = m.edge(h);
            let orig = self.original_edge.as_ref().map_or(e, |oe| oe[e as usize]);
            if orig == crate::mesh::NONE || !requested.contains(orig) {
                continue;
            }
            let (p, q) = (self.param.uv[h as usize], self.param.uv[m.next(h) as usize]);
            let dev = param::metrics::axis_deviation((q[1] - p[1]).atan2(q[0] - p[0]));
            let w = &mut worst[orig as usize];
            *w = if w.is_nan() { dev } else { w.max(dev) };
        }
        let mut unaligned = Vec::new();
        let mut worst_radians = 0.0f64;
        for e in requested.edges() {
            // An edge with no image at all counts as 90° off.
            let dev = if worst[e as usize].is_nan() { std::f64::consts::FRAC_PI_2 } else { worst[e as usize] };
            worst_radians = worst_radians.max(dev);
            if dev > ALIGNED_TOLERANCE {
                unaligned.push(UnalignedFeature { edge: e, vertices: input.edge_vertices(e), degrees: dev.to_degrees() });
            }
        }
        unaligned.sort_by(|a, b| b.degrees.total_cmp(&a.degrees).then(a.edge.cmp(&b.edge)));
        let requested_n = requested.len();
        FeatureAlignment { requested: requested_n, aligned: requested_n - unaligned.len(), worst_radians, unaligned }
    }

    /// The UVs per corner of the INPUT mesh (`3 f + k`): where faces were
    /// split, each input corner takes the UV of that corner in the sub-face
    /// containing it (for display; exports use the solved mesh exactly).
    pub fn input_corner_uv(&self, input: &TriMesh) -> Vec<[f64; 2]> {
        self.input_corner_values(input, &self.param.uv)
    }

    /// Per-corner values `uv` of the solved mesh (an integer-grid map, say)
    /// on the input's corners, as [`Self::input_corner_uv`].
    pub fn input_corner_values(&self, input: &TriMesh, uv: &[[f64; 2]]) -> Vec<[f64; 2]> {
        let (Some(of), Some(ov)) = (&self.original_face, &self.original_vertex) else {
            return uv.to_vec();
        };
        let mut out = vec![[0.0; 2]; 3 * input.n_faces()];
        for (r, tri) in self.mesh.faces().iter().enumerate() {
            let f = of[r] as usize;
            for (k, &v) in tri.iter().enumerate() {
                let o = ov[v as usize];
                if let Some(j) = input.faces()[f].iter().position(|&w| w == o) {
                    out[3 * f + j] = uv[3 * r + k];
                }
            }
        }
        out
    }

    /// Seam edges as ids of the INPUT mesh (seams along inserted edges are dropped).
    pub fn input_seam_edges(&self, input: &TriMesh) -> Vec<u32> {
        let Some(ov) = &self.original_vertex else {
            return self.param.seam_edges.clone();
        };
        let mut out: Vec<u32> = self
            .param
            .seam_edges
            .iter()
            .filter_map(|&e| {
                let [a, b] = self.mesh.edge_vertices(e).map(|v| ov[v as usize]);
                if a == crate::mesh::NONE || b == crate::mesh::NONE {
                    return None;
                }
                input.edge_between(a, b)
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Solves on `mesh` with `features` (see the module doc); a mesh of
/// several components one component at a time ([`Parts`]).
pub fn solve<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    match Parts::split(mesh, features) {
        Some(parts) => {
            let (solutions, wall_share) = parts.solve_each(options, progress)?;
            Ok(parts.join(mesh, features, &solutions, options, wall_share))
        }
        None => solve_one(mesh, features, options, progress),
    }
}

/// [`solve`] on `mesh` as one: cones on all its components, then one
/// parametrization with its refinements and fallbacks.
fn solve_one<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    let placed = place_cones(mesh, features, options, &mut |p| progress(SolveProgress::Cones(p)))?;
    placed.parametrize(mesh, features, progress)
}

/// [`solve`] on the refinement `refined` of `mesh` (`None`: the input
/// itself) made in `refine_seconds`: cones placed anew, then
/// [`Placed::parametrize`] with all its fallbacks.
fn solve_refined<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    refined: Option<Refined>,
    refine_seconds: f64,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    ConeStage::with_refinement(mesh, features, options, refined, 0, refine_seconds, now_seconds())
        .place(mesh, features, &mut |p| progress(SolveProgress::Cones(p)))
        .and_then(|placed| placed.parametrize(mesh, features, progress))
}

/// The cone stage of [`solve`] alone: the refinement the features need,
/// every component placed (on this thread, or two natively), and the
/// refinements around cones of angle 0.
pub fn place_cones(
    mesh: &TriMesh,
    features: &FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(cones::ConeProgress),
) -> Result<Placed, SolveError> {
    ConeStage::new(mesh, features, options).place(mesh, features, progress)
}

/// The cone stage of [`solve`] as steps, so that its components can be
/// placed anywhere (threads, other wasm instances that built the same
/// stage): build it, place every component of [`ConeStage::problem`], then
/// [`ConeStage::complete`]. Every method takes the same `mesh` and `features`.
#[derive(Clone, Debug)]
pub struct ConeStage {
    options: SolveOptions,
    /// The refinement of the input solved on (`None`: the input itself).
    refined: Option<Refined>,
    /// Refinements around cones of angle 0 made so far.
    attempt: usize,
    refine_seconds: f64,
    /// When the stage began (`clock::now_seconds`).
    started: f64,
    problem: ConeProblem,
}

/// What [`ConeStage::finish`] leads to.
#[derive(Clone, Debug)]
enum ConeStep {
    /// The cones are placed: go on to the parametrization.
    Placed(Placed),
    /// Cones of angle 0 appeared: the mesh was refined around them; place
    /// the new stage's components again.
    Again(ConeStage),
}

/// [`solve`] in steps, so that components can be placed anywhere (other
/// wasm instances that built the same stage): [`SolveStage::new`], place
/// every component of [`SolveStage::schedule`], then
/// [`SolveStage::finish`]. A mesh of several components is staged part by
/// part ([`Parts`]); its components are numbered across the parts. Every
/// method takes the same `mesh` and `features`.
pub enum SolveStage {
    One(ConeStage),
    /// Each part's stage, and the number of components before it.
    Parts { parts: Parts, stages: Vec<ConeStage>, first: Vec<usize> },
}

impl SolveStage {
    /// The stage of `mesh`: one [`ConeStage`], or one per part where it has several components.
    pub fn new(mesh: &TriMesh, features: &FeatureSet, options: &SolveOptions) -> SolveStage {
        let Some(parts) = Parts::split(mesh, features) else {
            return SolveStage::One(ConeStage::new(mesh, features, options));
        };
        let stages: Vec<ConeStage> = (0..parts.len()).map(|p| ConeStage::new(&parts.part(p).mesh, &parts.part(p).features, options)).collect();
        let first = stages
            .iter()
            .scan(0, |n, s| {
                let before = *n;
                *n += s.problem().n_components();
                Some(before)
            })
            .collect();
        SolveStage::Parts { parts, stages, first }
    }

    /// Number of components to place.
    pub fn n_components(&self) -> usize {
        match self {
            SolveStage::One(stage) => stage.problem().n_components(),
            SolveStage::Parts { stages, .. } => stages.iter().map(|s| s.problem().n_components()).sum(),
        }
    }

    /// The components in the order to place them (most faces first).
    pub fn schedule(&self) -> Vec<usize> {
        match self {
            SolveStage::One(stage) => stage.problem().schedule(),
            SolveStage::Parts { stages, first, .. } => {
                let mut all: Vec<(usize, usize)> = stages
                    .iter()
                    .zip(first)
                    .flat_map(|(s, &first)| s.problem().component_faces().into_iter().enumerate().map(move |(c, n)| (first + c, n)))
                    .collect();
                all.sort_by_key(|&(c, n)| (std::cmp::Reverse(n), c));
                all.into_iter().map(|(c, _)| c).collect()
            }
        }
    }

    /// Places component `c` (< [`Self::n_components`]); an error is located on the input.
    pub fn place_component(
        &self,
        mesh: &TriMesh,
        features: &FeatureSet,
        c: usize,
        progress: &mut dyn FnMut(cones::ConeProgress),
    ) -> Result<ComponentPlacement, SolveError> {
        if c >= self.n_components() {
            return Err(out_of_range(c));
        }
        match self {
            SolveStage::One(stage) => stage.problem().place_component(c, progress).map_err(|e| stage.cone_error(mesh, features, e)),
            SolveStage::Parts { parts, stages, first } => {
                let p = first.partition_point(|&f| f <= c) - 1;
                let part = parts.part(p);
                let mut placed = stages[p]
                    .problem()
                    .place_component(c - first[p], progress)
                    .map_err(|e| parts.lift_error(p, stages[p].cone_error(&part.mesh, &part.features, e)))?;
                placed.component = c;
                Ok(placed)
            }
        }
    }

    /// Joins the placed components (each from [`Self::place_component`],
    /// here or in another instance) and parametrizes ([`Placed::parametrize`];
    /// part by part, then [`Parts::join`]).
    pub fn finish<'a>(
        self,
        mesh: &'a TriMesh,
        features: &'a FeatureSet,
        placed: Vec<ComponentPlacement>,
        progress: &mut dyn FnMut(SolveProgress),
    ) -> Result<Solution<'a>, SolveError> {
        let total = self.n_components();
        match self {
            SolveStage::One(stage) => stage
                .complete(mesh, features, placed, &mut |p| progress(SolveProgress::Cones(p)))?
                .parametrize(mesh, features, progress),
            SolveStage::Parts { parts, stages, first } => {
                let options = stages.first().map(|s| s.options).unwrap_or_default();
                let mut of_part: Vec<Vec<ComponentPlacement>> = vec![Vec::new(); parts.len()];
                for mut r in placed {
                    if r.component >= total {
                        return Err(out_of_range(r.component));
                    }
                    let p = first.partition_point(|&f| f <= r.component) - 1;
                    r.component -= first[p];
                    of_part[p].push(r);
                }
                let mut solutions = Vec::with_capacity(parts.len());
                for (p, (stage, placed)) in stages.into_iter().zip(of_part).enumerate() {
                    let part = parts.part(p);
                    let solution = stage
                        .complete(&part.mesh, &part.features, placed, &mut |c| progress(SolveProgress::Cones(c)))
                        .and_then(|placed| placed.parametrize(&part.mesh, &part.features, progress))
                        .map_err(|e| parts.lift_error(p, e))?;
                    solutions.push(solution);
                }
                Ok(parts.join(mesh, features, &solutions, &options, 1.0))
            }
        }
    }
}

/// Component `c` is not one of the stage's.
fn out_of_range(c: usize) -> SolveError {
    SolveError::unlocated(SolveCause::Components(MismatchError(format!("component {c} is out of range"))))
}

/// A finished cone stage, ready for [`Placed::parametrize`].
#[derive(Clone, Debug)]
pub struct Placed {
    options: SolveOptions,
    refined: Option<Refined>,
    refine_seconds: f64,
    pub placement: ConePlacement,
}

impl ConeStage {
    /// Refines the mesh (edges longer than `options.refine.max_edge_length`,
    /// then where its features need it, [`refine_for_features_on`]) and prepares the cone problem.
    pub fn new(mesh: &TriMesh, features: &FeatureSet, options: &SolveOptions) -> ConeStage {
        let started = now_seconds();
        let refined = options.refine.max_edge_length.and_then(|length| split_long_edges(mesh, features, None, length));
        let refined = refine_for_features_on(mesh, features, refined);
        let refine_seconds = now_seconds() - started;
        ConeStage::with_refinement(mesh, features, options, refined, 0, refine_seconds, started)
    }

    fn with_refinement(
        mesh: &TriMesh,
        features: &FeatureSet,
        options: &SolveOptions,
        refined: Option<Refined>,
        attempt: usize,
        refine_seconds: f64,
        started: f64,
    ) -> ConeStage {
        let (m, f) = refined.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
        let problem = ConeProblem::new(m, f, &options.cones);
        ConeStage { options: *options, refined, attempt, refine_seconds, started, problem }
    }

    /// The components to place.
    pub fn problem(&self) -> &ConeProblem {
        &self.problem
    }

    /// `e`, from placing a component of [`Self::problem`], as a [`SolveError`]
    /// located on the input `mesh` (with its `features`).
    pub fn cone_error(&self, mesh: &TriMesh, features: &FeatureSet, e: ConeError) -> SolveError {
        SolveError::new(&lift(mesh, features, self.refined.as_ref()), SolveCause::Cones(e))
    }

    /// Places every component here ([`cones::place_all`]) and completes the stage.
    fn place(self, mesh: &TriMesh, features: &FeatureSet, progress: &mut dyn FnMut(cones::ConeProgress)) -> Result<Placed, SolveError> {
        let results = cones::place_all(self.problem(), progress).map_err(|e| self.cone_error(mesh, features, e))?;
        self.complete(mesh, features, results, progress)
    }

    /// Joins the placed components (one per component of [`Self::problem`])
    /// into the placement. Where cones of angle 0 appear, the mesh is refined
    /// around them and the refined stage's components are placed here
    /// ([`cones::place_all`], reporting to `progress`), while attempts remain.
    pub fn complete(
        self,
        mesh: &TriMesh,
        features: &FeatureSet,
        results: Vec<ComponentPlacement>,
        progress: &mut dyn FnMut(cones::ConeProgress),
    ) -> Result<Placed, SolveError> {
        let (mut stage, mut results) = (self, results);
        loop {
            match stage.finish(mesh, features, results)? {
                ConeStep::Placed(placed) => return Ok(placed),
                ConeStep::Again(next) => {
                    results = cones::place_all(next.problem(), progress).map_err(|e| next.cone_error(mesh, features, e))?;
                    stage = next;
                }
            }
        }
    }

    /// One step of [`Self::complete`]: joins the placed components, or
    /// refines around cones of angle 0 while attempts remain. The placement's `timings.total` is the wall-clock time of all
    /// attempts without the refinements (the per-stage timings are those of
    /// the last attempt, summed over components that may have run in parallel).
    fn finish(self, mesh: &TriMesh, features: &FeatureSet, results: Vec<ComponentPlacement>) -> Result<ConeStep, SolveError> {
        let ConeStage { options, refined, attempt, mut refine_seconds, started, problem } = self;
        let m = refined.as_ref().map_or(mesh, |r| &r.mesh);
        let mut placement = problem.assemble(m, results).map_err(|e| SolveError::unlocated(SolveCause::Components(e)))?;
        let degenerate = zero_angle_cones(&placement);
        if degenerate.is_empty() || attempt >= options.refine.max_cone_refinements {
            placement.timings.total = now_seconds() - started - refine_seconds;
            return Ok(ConeStep::Placed(Placed { options, refined, refine_seconds, placement }));
        }
        // Only vertices of `m` are named; lift the refinement one level.
        let mut clock = Stopwatch::start();
        let refined = Some(split_around(mesh, features, refined, &degenerate));
        refine_seconds += clock.lap();
        Ok(ConeStep::Again(ConeStage::with_refinement(mesh, features, &options, refined, attempt + 1, refine_seconds, started)))
    }
}

impl Placed {
    /// The mesh the cones were placed on: the refinement of `input`, or `input`.
    pub fn mesh<'a>(&'a self, input: &'a TriMesh) -> &'a TriMesh {
        self.refined.as_ref().map_or(input, |r| &r.mesh)
    }

    /// The features on [`Self::mesh`]: those of the refinement, or `input`'s.
    pub fn features<'a>(&'a self, input: &'a FeatureSet) -> &'a FeatureSet {
        self.refined.as_ref().map_or(input, |r| &r.features)
    }

    /// What the refinement inserted (all zero when `mesh` is the input).
    pub fn refinement(&self) -> (usize, RefineCounts) {
        self.refined.as_ref().map_or((0, RefineCounts::default()), |r| (r.splits, r.counts))
    }

    /// The seamless aligned parametrization (Appendix B) on the placed
    /// cones. Where the map keeps flipped triangles (else, where it realized
    /// cones with another index than placed), their longest edges are split
    /// ([`split_flipped`]) and the cones placed again, up to
    /// `options.refine.max_flip_refinements` times; the result with the fewest flipped
    /// triangles, then realized cones, is returned (a later attempt that
    /// fails is dropped).
    pub fn parametrize<'a>(
        self,
        mesh: &'a TriMesh,
        features: &'a FeatureSet,
        progress: &mut dyn FnMut(SolveProgress),
    ) -> Result<Solution<'a>, SolveError> {
        let mut options = self.options;
        let (initial, refine_seconds) = (self.refined.clone(), self.refine_seconds);
        // With features, the cone moves' proxy (the conformal scale's norm,
        // section 5.3) can disagree with the map: fewer cones lower it while
        // the isolines along the features shear the map more (spot >40°:
        // 75 -> 36 cones, distortion 0.14 -> 0.25; bunny >60° 0.135 -> 0.172;
        // a plate with five holes 0.125 -> 0.243). The placement without
        // moves is parametrized too (natively on a second thread), and the
        // map with fewer flipped triangles, then lower distortion, kept.
        let unmoved = SolveOptions { cones: ConeOptions { optimize_locations: false, ..options.cones }, ..options };
        let compare = !features.is_empty() && options.cones.optimize_locations;
        let other = |progress: &mut dyn FnMut(SolveProgress)| -> Option<Solution<'a>> {
            let stage = ConeStage::with_refinement(mesh, features, &unmoved, initial.clone(), 0, refine_seconds, now_seconds());
            let placed = stage.place(mesh, features, &mut |p| progress(SolveProgress::Cones(p))).ok()?;
            placed.parametrize_once(mesh, features, &mut |p| progress(SolveProgress::Param(p))).ok()
        };
        #[cfg(not(target_arch = "wasm32"))]
        let (first, other) = std::thread::scope(|scope| {
            let helper = compare.then(|| scope.spawn(|| other(&mut |_| {})));
            let first = self.parametrize_once(mesh, features, &mut |p| progress(SolveProgress::Param(p)));
            (first, helper.and_then(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))))
        });
        #[cfg(target_arch = "wasm32")]
        let (first, other) = {
            let first = self.parametrize_once(mesh, features, &mut |p| progress(SolveProgress::Param(p)));
            (first, if compare { other(progress) } else { None })
        };
        let key = |s: &Solution| (s.param.metrics.flipped, s.param.metrics.distortion);
        let mut best = match (first, other) {
            (Ok(first), Some(other)) if key(&other) < key(&first) => {
                options = unmoved;
                other
            }
            (Ok(first), _) => first,
            (Err(_), Some(other)) => {
                options = unmoved;
                other
            }
            (Err(e), None) => return Err(e),
        };
        for _ in 0..options.refine.max_flip_refinements {
            let mut flipped = best.flipped_faces();
            if flipped.is_empty() {
                flipped = best.realized_cone_faces();
            }
            if flipped.is_empty() {
                break;
            }
            let mut clock = Stopwatch::start();
            let refined = split_flipped(mesh, features, best.refinement_of_input(), &flipped);
            let started = now_seconds();
            let stage = ConeStage::with_refinement(mesh, features, &options, Some(refined), 0, best.refine_seconds + clock.lap(), started);
            let attempt = stage
                .place(mesh, features, &mut |p| progress(SolveProgress::Cones(p)))
                .and_then(|placed| placed.parametrize_once(mesh, features, &mut |p| progress(SolveProgress::Param(p))));
            match attempt {
                Ok(mut next) if next.defects() < best.defects() => {
                    next.flip_refinements = best.flip_refinements + 1;
                    best = next;
                }
                _ => break,
            }
        }
        // A map that folds is not a result (issue 13). Fallbacks, each placing
        // again from the input: where the placement came from coarse levels,
        // place on the component itself (cow x4 at 20-40°: the coarse
        // placements of its 1 700 feature edges folded); per-cluster rounding
        // decides in parallel what the paper's rule decides one batch at a
        // time, so where that placement folds, place once more the paper's
        // way. (The retry's own fallback then covers the last.)
        // (`best` no longer changes: every fallback below returns its own solution.)
        let m = &best.param.metrics;
        let folds = m.flipped > 0 || m.wound_vertices > 0;
        let coarse = mesh.n_vertices() > options.cones.coarse_vertices;
        if folds && (coarse || options.cones.rounding == RoundingRule::PerCluster) {
            let mut retry = options;
            if coarse {
                retry.cones.coarse_vertices = usize::MAX;
            } else {
                retry.cones.rounding = RoundingRule::Whole;
            }
            if let Ok(solution) = solve_refined(mesh, features, &retry, initial, refine_seconds, progress) {
                return Ok(solution);
            }
        }
        // A low-poly mesh (a CAD export: long, thin triangles between
        // features) may have too few vertices for any map without folds.
        // First solve again from the input with its long edges split
        // ([`long_edges_refine`]: block with a hole at --sharp 60, 2.3 s and
        // distortion 0.47 by the next fallback, 0.18 s and 0.07 this way; a
        // plate with five holes failed after 115 s, 0.37 s this way); where
        // that still folds, split the longest edge of every face and solve
        // again, until the mesh is no longer low-poly.
        if folds && best.mesh.n_faces() < LOW_POLY_FACES {
            if let Some(refine) = long_edges_refine(mesh, &options.refine, None) {
                if let Ok(solution) = solve(mesh, features, &SolveOptions { refine, ..options }, progress) {
                    return Ok(solution);
                }
            }
            let mut clock = Stopwatch::start();
            let all: Vec<u32> = (0..best.mesh.n_faces() as u32).collect();
            let refined = split_flipped(mesh, features, best.refinement_of_input(), &all);
            if let Ok(solution) = solve_refined(mesh, features, &options, Some(refined), best.refine_seconds + clock.lap(), progress) {
                return Ok(solution);
            }
        }
        if folds {
            let cause = SolveCause::Folded {
                flipped: m.flipped,
                wound: m.wound_vertices,
                refinements: best.flip_refinements,
                faces: best.folded_faces(),
            };
            return Err(SolveError::new(&best.lift(mesh, features), cause));
        }
        Ok(best)
    }

    /// One parametrization of the placed cones ([`Self::parametrize`] without the refinement).
    fn parametrize_once<'a>(
        self,
        mesh: &'a TriMesh,
        features: &'a FeatureSet,
        progress: &mut dyn FnMut(ParamProgress),
    ) -> Result<Solution<'a>, SolveError> {
        let Placed { options, refined, refine_seconds, placement } = self;
        let (input, input_features) = (mesh, features);
        let (mesh, features, splits, original_face, original_vertex, original_edge, refinement) = match refined {
            Some(Refined { mesh: m, features: f, splits, original_face, original_vertex, original_edge, counts }) => {
                (Cow::Owned(m), Cow::Owned(f), splits, Some(original_face), Some(original_vertex), Some(original_edge), counts)
            }
            None => (Cow::Borrowed(mesh), Cow::Borrowed(features), 0, None, None, None, RefineCounts::default()),
        };
        let param = param::parametrize(&mesh, &placement, &options.param, progress).map_err(|e| {
            let lift = Lift {
                input,
                features: input_features,
                solved: &mesh,
                solved_features: &features,
                original_vertex: original_vertex.as_deref(),
                original_edge: original_edge.as_deref(),
                original_face: original_face.as_deref(),
            };
            SolveError::new(&lift, SolveCause::Param(e))
        })?;
        let mut placement = placement;
        placement.realize(&mesh, &param.realized_cones);
        Ok(Solution {
            mesh,
            features,
            splits,
            original_face,
            original_vertex,
            original_edge,
            refinement,
            flip_refinements: 0,
            placement,
            param,
            refine_seconds,
            refine_options: options.refine,
        })
    }
}


/// The maps from the mesh solved on (`refined`, or `mesh` itself) back to `mesh`.
fn lift<'a>(mesh: &'a TriMesh, features: &'a FeatureSet, refined: Option<&'a Refined>) -> Lift<'a> {
    match refined {
        Some(r) => Lift {
            input: mesh,
            features,
            solved: &r.mesh,
            solved_features: &r.features,
            original_vertex: Some(&r.original_vertex),
            original_edge: Some(&r.original_edge),
            original_face: Some(&r.original_face),
        },
        None => Lift { input: mesh, features, solved: mesh, solved_features: features, original_vertex: None, original_edge: None, original_face: None },
    }
}


/// Vertices (of the mesh the placement was computed on) that carry an
/// interior cone of index `k >= 4`, i.e. a cone angle `<= 0`.
fn zero_angle_cones(placement: &ConePlacement) -> Vec<u32> {
    let cm = &placement.cut.mesh;
    let mut out: Vec<u32> = (0..cm.n_vertices() as u32)
        .filter(|&v| placement.k[v as usize] >= 4 && !cm.is_boundary_vertex(v))
        .map(|v| placement.cut.original_vertex[v as usize])
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::LinalgError;
    use std::error::Error;

    #[test]
    fn errors_chain_down_to_the_linear_solve() {
        let e = SolveError::unlocated(SolveCause::Param(ParamError::Solve(LinalgError::NotFactorized)));
        let param = e.source().expect("the stage's error");
        assert!(param.downcast_ref::<ParamError>().is_some());
        let linalg = param.source().expect("the linear solve's error");
        assert_eq!(linalg.downcast_ref::<LinalgError>(), Some(&LinalgError::NotFactorized));
        assert!(linalg.source().is_none());
        let folded = SolveError::unlocated(SolveCause::Folded { flipped: 1, wound: 0, refinements: 0, faces: vec![0] });
        assert!(folded.source().is_none());
    }
}
