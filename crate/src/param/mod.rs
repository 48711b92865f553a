//! Parametrization from the connection (paper Appendix B): the cross-field
//! of B.1 ([`field`]), a cut to a topological disk through every cone
//! ([`cut_graph`], B step 1), the seamless Poisson solve of eq. (23) followed
//! by ARAP local/global iterations and a fold-over repair ([`seamless`]),
//! the untangling of what the repair left flipped ([`untangle`]), an
//! injective (flip-free) refinement under the same constraints
//! ([`injective`]), and the quality figures of section 7 ([`metrics`], eq. 19).
//! After it, [`quantize`] turns the map into an integer-grid map for a grid
//! size (the paper's Limitations), reusing the seamless system's unknowns and
//! seam rows.
//! The four share the linear triangle element of [`element`] (face frames,
//! hat gradients, Jacobians, UV areas and angles) and import no one else's
//! internals: `seamless` drives `injective` and `untangle`, and measures
//! with `metrics`.
//!
//! An untangled map has every triangle positive but may realize some
//! angles differently from the placement: inside, the placed cone angle
//! plus a multiple of 2 pi (seam transitions fix angles modulo 2 pi only);
//! on features and boundaries any multiple of pi/2 of the same parity.
//! Those cones and corners are returned in
//! [`Parametrization::realized_cones`] and the pipeline reports them
//! ([`ConePlacement::realize`]).
//!
//! Input: the original [`TriMesh`] and the [`ConePlacement`] computed on it.
//! Output: one UV per face corner (`3 f + k`), seamless across every seam
//! edge (transition `f(p2) = Rot(m pi/2) f(p1) + t`) and with every feature
//! and boundary edge on an isoline.

pub mod cut_graph;
pub mod element;
pub mod field;
pub mod injective;
pub mod metrics;
pub mod quantize;
pub mod seamless;
mod separation;
pub mod untangle;
#[cfg(test)]
mod tests;

use crate::clock::Stopwatch;
use crate::cones::ConePlacement;
use crate::linalg::LinalgError;
use crate::mesh::TriMesh;
use serde::Serialize;
use std::fmt;

pub use cut_graph::CutGraph;
pub use field::CrossField;
pub use metrics::Metrics;

/// Settings of the parametrization stage.
#[derive(Clone, Copy, Debug)]
pub struct ParamOptions {
    /// Cap on ARAP local/global iterations (0: Poisson solution only).
    pub max_arap_iterations: usize,
    /// ARAP stops once the relative energy decrease falls below this.
    pub arap_tolerance: f64,
    /// Keep the target rotation of triangles adjacent to features and
    /// boundaries fixed to the field (Appendix B.2, local step).
    pub fix_feature_rotations: bool,
    /// Rounds of the fold-over repair (local reweighting) that looks for a
    /// fold-free start of the refinement; 0 disables it. Without the
    /// refinement the repaired weights are also relaxed back towards 1.
    pub repair_rounds: usize,
    /// Injective refinement of the fold-free map ([`injective`]); 0
    /// iterations disables it.
    pub refine: injective::RefineOptions,
    /// Untangling ([`untangle`]) of a map the repair left folded.
    pub untangle: untangle::UntangleOptions,
}

impl Default for ParamOptions {
    fn default() -> Self {
        ParamOptions { max_arap_iterations: 100, arap_tolerance: 1e-5, fix_feature_rotations: true, repair_rounds: 60, refine: injective::RefineOptions::default(), untangle: untangle::UntangleOptions::default() }
    }
}

/// Progress reports, in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum ParamProgress {
    Field,
    Cut,
    Poisson,
    /// ARAP iteration `iteration` (1-based) of at most `max`.
    Arap { iteration: usize, max: usize },
    /// Fold-over repair round `round`, `flips` flipped triangles before it.
    Repair { round: usize, flips: usize },
    /// Injective refinement iteration `iteration` (1-based) of at most `max`.
    Injective { iteration: usize, max: usize },
}

/// Seconds per stage.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ParamTimings {
    pub cut: f64,
    pub field: f64,
    pub poisson: f64,
    pub arap: f64,
    pub repair: f64,
    pub untangle: f64,
    pub injective: f64,
    pub metrics: f64,
}

/// The result of [`parametrize`].
#[derive(Clone, Debug, Serialize)]
pub struct Parametrization {
    /// UV per face corner, index `3 f + k` (corner `k` of face `f`).
    pub uv: Vec<[f64; 2]>,
    /// Seam edges (ids of the original mesh): the cut graph's interior edges
    /// and every opened feature edge.
    pub seam_edges: Vec<u32>,
    pub metrics: Metrics,
    /// Iterations and folds of the solve's stages.
    #[serde(flatten)]
    pub counts: ParamCounts,
    /// Cones the map realizes with another index than `placement` gave
    /// them, `(cut vertex, k)`: apply with [`ConePlacement::realize`]. The
    /// metrics already count the realized cones.
    pub realized_cones: Vec<(u32, i32)>,
    pub timings: ParamTimings,
}

/// What the stages of the seamless solve ([`seamless::seamless_map`]) ran and repaired.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ParamCounts {
    /// ARAP iterations run (after the Poisson solve).
    pub arap_iterations: usize,
    /// Flipped or degenerate triangles right after ARAP (before repair).
    pub flips_before_repair: usize,
    /// Flipped triangles the repair removed.
    pub flips_fixed: usize,
    /// Fold-over repair rounds run.
    pub repair_rounds: usize,
    /// Iterations of the injective refinement kept (0: none ran or it was not used).
    pub refine_iterations: usize,
    /// L-BFGS iterations of the untangling (0: the repair left no fold).
    pub untangle_iterations: usize,
}

/// Why the parametrization failed.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamError {
    /// The placement does not belong to this mesh.
    MeshMismatch { what: &'static str, expected: usize, found: usize },
    /// The mesh has no faces.
    EmptyMesh,
    /// A matching `m_e` of eq. (21) is not an integer (the connection is not
    /// a cross-field connection): `value` quarter turns across edge `edge`.
    /// (Indices in these variants are those of the mesh parametrized; see
    /// `pipeline::SolveError::location` for the input mesh's.)
    NonIntegerMatching { edge: u32, value: f64 },
    /// The field is not aligned with boundary/feature edge `edge` (opened
    /// in the cut mesh): `value` quarter turns off.
    Misaligned { edge: u32, value: f64 },
    /// An edge outside the cut has a non-identity matching (bug guard).
    UncutSingularity { edge: u32, matching: i64 },
    /// The solve left a constraint row violated by `residual` (relative to the UV extent).
    ConstraintViolation { residual: f64 },
    /// A cone of index `k >= 4` (cone angle `2 pi - k pi/2 <= 0`) at vertex `vertex`:
    /// no seamless map exists with it.
    DegenerateCone { vertex: u32, k: i32 },
    /// A value became NaN or infinite.
    NotFinite { what: &'static str },
    /// The sparse KKT solve failed.
    Solve(LinalgError),
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamError::MeshMismatch { what, expected, found } => {
                write!(f, "cone placement does not match the mesh: {what} expected {expected}, found {found}")
            }
            ParamError::EmptyMesh => write!(f, "the mesh has no faces"),
            ParamError::NonIntegerMatching { edge, value } => {
                write!(f, "cross-field matching across edge {edge} is {value} quarter turns, not an integer")
            }
            ParamError::Misaligned { edge, value } => {
                write!(f, "cross-field is not aligned with boundary edge {edge} ({value} quarter turns)")
            }
            ParamError::UncutSingularity { edge, matching } => {
                write!(f, "edge {edge} is not cut but has matching {matching} (not a multiple of 4)")
            }
            ParamError::ConstraintViolation { residual } => {
                write!(f, "seam/isoline constraints violated after the solve (relative residual {residual:.2e})")
            }
            ParamError::DegenerateCone { vertex, k } => write!(
                f,
                "the cone at vertex v{vertex} would need index {k} (a cone angle of {}°): the features around it leave no other \
                 interior vertex to carry the curvature; subdivide the mesh there or mark fewer feature edges",
                360 - 90 * k
            ),
            ParamError::NotFinite { what } => write!(f, "{what} is not finite"),
            ParamError::Solve(e) => write!(f, "parametrization solve failed: {e}"),
        }
    }
}

impl std::error::Error for ParamError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ParamError::Solve(e) => Some(e),
            _ => None,
        }
    }
}

impl From<LinalgError> for ParamError {
    fn from(e: LinalgError) -> Self {
        ParamError::Solve(e)
    }
}

/// Computes a seamless, feature-aligned parametrization of `mesh` from the
/// cone placement `placement` (computed on the same `mesh`).
///
/// Contract: `placement.cut` must be the cut of `mesh` (same faces), else
/// [`ParamError::MeshMismatch`]. On success every seam edge's two UV images
/// differ by a rotation of `k·90°` and a translation, every feature and
/// boundary edge maps to an axis-parallel segment (both up to solver
/// round-off), and the metrics describe the result; `progress` is called
/// at each stage. Never panics on valid inputs; numeric failures are errors.
pub fn parametrize(
    mesh: &TriMesh,
    placement: &ConePlacement,
    options: &ParamOptions,
    progress: &mut dyn FnMut(ParamProgress),
) -> Result<Parametrization, ParamError> {
    let mut clock = Stopwatch::start();
    let mut timings = ParamTimings::default();
    check_inputs(mesh, placement)?;

    progress(ParamProgress::Field);
    let field = field::cross_field(mesh, placement)?;
    timings.field = clock.lap();

    progress(ParamProgress::Cut);
    let cut = cut_graph::cut_graph(mesh, placement, &field)?;
    timings.cut = clock.lap();

    let result = seamless::seamless_map(mesh, placement, &field, &cut, options, progress, &mut clock, &mut timings)?;
    let uv: Vec<[f64; 2]> = (0..3 * mesh.n_faces()).map(|c| result.uv[cut.wedge[c] as usize]).collect();
    if uv.iter().any(|p| !p[0].is_finite() || !p[1].is_finite()) {
        return Err(ParamError::NotFinite { what: "uv" });
    }
    let metrics = if result.realized.is_empty() {
        metrics::compute(mesh, placement, &cut, &uv)
    } else {
        let mut realized = placement.clone();
        realized.realize(mesh, &result.realized);
        metrics::compute(mesh, &realized, &cut, &uv)
    };
    timings.metrics = clock.lap();
    Ok(Parametrization {
        uv,
        seam_edges: cut.seam_edges.clone(),
        metrics,
        counts: result.counts,
        realized_cones: result.realized,
        timings,
    })
}

fn check_inputs(mesh: &TriMesh, placement: &ConePlacement) -> Result<(), ParamError> {
    let nf = mesh.n_faces();
    if nf == 0 {
        return Err(ParamError::EmptyMesh);
    }
    let cm = &placement.cut.mesh;
    let checks = [
        ("cut mesh faces", nf, cm.n_faces()),
        ("omega length", 3 * nf, placement.omega.len()),
        ("k length", cm.n_vertices(), placement.k.len()),
        ("original_vertex length", cm.n_vertices(), placement.cut.original_vertex.len()),
        ("original_edge length", cm.n_edges(), placement.cut.original_edge.len()),
    ];
    for (what, expected, found) in checks {
        if expected != found {
            return Err(ParamError::MeshMismatch { what, expected, found });
        }
    }
    if placement.cut.original_vertex.iter().any(|&v| v as usize >= mesh.n_vertices())
        || placement.cut.original_edge.iter().any(|&e| e as usize >= mesh.n_edges())
    {
        return Err(ParamError::MeshMismatch { what: "cut-to-original index", expected: mesh.n_vertices(), found: usize::MAX });
    }
    for f in 0..nf {
        let a = mesh.faces()[f];
        let b = cm.faces()[f];
        for k in 0..3 {
            if placement.cut.original_vertex[b[k] as usize] != a[k] {
                return Err(ParamError::MeshMismatch { what: "face corner", expected: a[k] as usize, found: b[k] as usize });
            }
        }
    }
    if placement.omega.iter().any(|w| !w.is_finite()) {
        return Err(ParamError::NotFinite { what: "omega" });
    }
    for (v, &k) in placement.k.iter().enumerate() {
        if k >= 4 && !cm.is_boundary_vertex(v as u32) {
            return Err(ParamError::DegenerateCone { vertex: placement.cut.original_vertex[v], k });
        }
    }
    Ok(())
}
