//! The whole method in one call: refine doubly constrained triangles, place
//! cones (sections 4-5) — refining around any vertex that would need a cone
//! of angle 0 and placing them again —, then compute the seamless aligned
//! parametrization (Appendix B). The CLI calls [`solve`]; the wasm API runs
//! the same steps ([`ConeStage`]) so that a helper worker can place components.

use crate::clock::{now_seconds, Stopwatch};
use crate::cones::{self, ComponentPlacement, ConeError, ConeOptions, ConePlacement, ConeProblem, MismatchError};
use crate::features::{split_around, split_doubly_constrained, FeatureSet, Refined};
use crate::mesh::TriMesh;
use crate::param::{self, ParamError, ParamOptions, ParamProgress, Parametrization};
use std::borrow::Cow;
use std::fmt;

/// Settings of both stages.
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveOptions {
    pub cones: ConeOptions,
    pub param: ParamOptions,
}

/// Progress of either stage.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveProgress {
    Cones(cones::Progress),
    Param(ParamProgress),
}

/// Why solving failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveError {
    Cones(ConeError),
    /// Component placements from elsewhere that do not fit the stage.
    Components(MismatchError),
    Param(ParamError),
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::Cones(e) => write!(f, "{e}"),
            SolveError::Components(e) => write!(f, "{e}"),
            SolveError::Param(e) => write!(f, "parametrization: {e}"),
        }
    }
}

impl std::error::Error for SolveError {}

/// The result: the mesh actually parametrized (the input, or the input with
/// doubly constrained triangles split), its features, cones and UVs.
#[derive(Clone, Debug)]
pub struct Solution<'a> {
    pub mesh: Cow<'a, TriMesh>,
    pub features: Cow<'a, FeatureSet>,
    /// Edges split before solving (0: `mesh` is the input).
    pub splits: usize,
    /// When split: solved face → input face and solved vertex → input
    /// vertex (`NONE` for inserted midpoints).
    pub original_face: Option<Vec<u32>>,
    pub original_vertex: Option<Vec<u32>>,
    pub placement: ConePlacement,
    pub param: Parametrization,
    /// Seconds spent refining.
    pub refine_seconds: f64,
}

impl Solution<'_> {
    /// The UVs per corner of the INPUT mesh (`3 f + k`): where faces were
    /// split, each input corner takes the UV of that corner in the sub-face
    /// containing it (for display; exports use the solved mesh exactly).
    pub fn input_corner_uv(&self, input: &TriMesh) -> Vec<[f64; 2]> {
        let (Some(of), Some(ov)) = (&self.original_face, &self.original_vertex) else {
            return self.param.uv.clone();
        };
        let mut uv = vec![[0.0; 2]; 3 * input.n_faces()];
        for (r, tri) in self.mesh.faces().iter().enumerate() {
            let f = of[r] as usize;
            for (k, &v) in tri.iter().enumerate() {
                let o = ov[v as usize];
                if let Some(j) = input.faces()[f].iter().position(|&w| w == o) {
                    uv[3 * f + j] = self.param.uv[3 * r + k];
                }
            }
        }
        uv
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
                input.outgoing(a).find(|&h| input.head(h) == b).map(|h| input.edge(h))
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Solves on `mesh` with `features` (see the module doc).
pub fn solve<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    let placed = {
        let mut cone_progress = |p| progress(SolveProgress::Cones(p));
        let stage = ConeStage::new(mesh, features, options);
        let results = cones::place_all(stage.problem(), &mut cone_progress).map_err(SolveError::Cones)?;
        stage.complete(mesh, features, results, &mut cone_progress)?
    };
    placed.parametrize(mesh, features, &mut |p| progress(SolveProgress::Param(p)))
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

/// A finished cone stage, ready for [`Placed::parametrize`].
#[derive(Clone, Debug)]
pub struct Placed {
    options: SolveOptions,
    refined: Option<Refined>,
    refine_seconds: f64,
    pub placement: ConePlacement,
}

impl ConeStage {
    /// Splits doubly constrained triangles and prepares the cone problem.
    pub fn new(mesh: &TriMesh, features: &FeatureSet, options: &SolveOptions) -> ConeStage {
        let started = now_seconds();
        let refined = split_doubly_constrained(mesh, features);
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

    /// Joins the placed components (one per component of [`Self::problem`])
    /// into the placement. Where cones of angle 0 appear, the mesh is refined
    /// around them and the refined stage's components are placed here
    /// ([`cones::place_all`], reporting to `progress`), while attempts remain.
    pub fn complete(
        self,
        mesh: &TriMesh,
        features: &FeatureSet,
        results: Vec<ComponentPlacement>,
        progress: &mut dyn FnMut(cones::Progress),
    ) -> Result<Placed, SolveError> {
        let (mut stage, mut results) = (self, results);
        loop {
            match stage.finish(mesh, features, results)? {
                ConeStep::Placed(placed) => return Ok(placed),
                ConeStep::Again(next) => {
                    results = cones::place_all(next.problem(), progress).map_err(SolveError::Cones)?;
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
        let mut placement = problem.assemble(m, results).map_err(SolveError::Components)?;
        let degenerate = zero_angle_cones(&placement);
        if degenerate.is_empty() || attempt == MAX_CONE_REFINEMENTS {
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
    /// The seamless aligned parametrization (Appendix B) on the placed cones.
    pub fn parametrize<'a>(
        self,
        mesh: &'a TriMesh,
        features: &'a FeatureSet,
        progress: &mut dyn FnMut(ParamProgress),
    ) -> Result<Solution<'a>, SolveError> {
        let Placed { options, refined, refine_seconds, placement } = self;
        let (mesh, features, splits, original_face, original_vertex) = match refined {
            Some(Refined { mesh: m, features: f, splits, original_face, original_vertex }) => {
                (Cow::Owned(m), Cow::Owned(f), splits, Some(original_face), Some(original_vertex))
            }
            None => (Cow::Borrowed(mesh), Cow::Borrowed(features), 0, None, None),
        };
        let param = param::parametrize(&mesh, &placement, &options.param, progress).map_err(SolveError::Param)?;
        Ok(Solution { mesh, features, splits, original_face, original_vertex, placement, param, refine_seconds })
    }
}

/// Rounds of local refinement tried when cones of angle 0 appear.
const MAX_CONE_REFINEMENTS: usize = 2;

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
