//! Cone placement (paper sections 4-5): the connection 1-form
//! `omega = -*dphi + h` minimizing `phiᵀ(alpha_smooth L + M/A)phi` under the
//! alignment constraints, with greedy rounding of the path integers
//! (Algorithm 1) and cone-location optimization. Conventions are in
//! `docs/cone-placement.md`.
//!
//! Pipeline: cut the mesh open along features ([`crate::features`]) →
//! per component: path basis ([`dual_tree`]) → harmonic forms
//! ([`harmonic`]) → KKT system and rounding ([`system`]) → cone moves.

pub mod dual_tree;
pub mod dual_path;
pub mod harmonic;
pub mod problem;
pub mod system;
#[cfg(test)]
pub(crate) mod test_meshes;

use crate::clock::Stopwatch;
use crate::linalg::LinalgError;
use crate::features::{CutMesh, FeatureSet};
use crate::mesh::TriMesh;
pub use problem::{ComponentPlacement, ConeProblem, MismatchError};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Default `alpha_smooth` (paper: 0.01 in most figures).
pub const DEFAULT_ALPHA: f64 = 0.01;
/// `alpha_smooth` used by MIQ emulation when none is given ("100.0*" in Table 1).
pub const MIQ_ALPHA: f64 = 100.0;
/// Accepted range of `alpha_smooth`.
pub const ALPHA_RANGE: (f64, f64) = (1e-4, 1e3);

/// Default of [`ConeOptions::coarse_vertices`]. Measured over eleven
/// samples: 2 000 against 4 000 gave equal or lower distortion on all but
/// spot x16 (.098 against .090), e.g. fandisk .066 / .105, bff-bunny .097 /
/// .115, spot .091 / .113, cow .105 / .129; 1 500 was worse again on five.
pub const COARSE_VERTICES: usize = 2000;

/// Settings of the cone placement.
#[derive(Clone, Copy, Debug)]
pub struct ConeOptions {
    /// Smoothness weight: small gives more cones and less distortion.
    pub alpha_smooth: f64,
    /// Emulate MIQ: drop the harmonic-minimality constraint.
    pub miq: bool,
    /// Run the cone-location optimization after rounding.
    pub optimize_locations: bool,
    /// Cap on cone-move passes.
    pub max_move_passes: usize,
    /// Cancel opposite cones one or two edges apart (the paper's optional clean-up).
    pub merge_close_pairs: bool,
    /// Cancel distant opposite pairs while the objective decreases (0 = off):
    /// each cone is tried against this many nearest opposite cones.
    pub cancel_pairs_nearest: usize,
    /// Components with more interior vertices than this are placed coarse
    /// to fine (`usize::MAX`: never): the cones are placed on a decimation
    /// to this many interior vertices, then moved on the component itself.
    pub coarse_vertices: usize,
    /// How Algorithm 1 batches its fixes.
    pub rounding: RoundingRule,
    /// Whether the mesh's own boundary is held on isolines.
    pub boundary: BoundaryMode,
    /// Largest index of an interior cone (1..=3; above 3 a cone has no
    /// angle). 1, the default, keeps every cone's quad valence `4 - k` at 3
    /// or more: a cone of index 2 or 3 becomes a valence-2 or valence-1
    /// vertex, whose quads fold (cow's horn tips at 3 000 quads); the
    /// excess quarter turns are spread onto nearby vertices.
    pub max_cone_index: i64,
    /// Opposite interior cones closer than this (model units) cancel, after
    /// the moves and clean-ups (0: none). A quad grid of cell `s` cannot
    /// keep apart two cones closer than a cell's diagonal: each is rounded
    /// to a grid point up to half a diagonal away, so the pair lands on one
    /// point or on two that fold the cells between them; a quad mesh wants
    /// [`GRID_PAIR_CELLS`] `* s` ([`crate::pipeline::SolveOptions::for_quads`]).
    pub min_pair_distance: f64,
}

/// [`ConeOptions::min_pair_distance`] for a quad grid, in grid cells: a cell's diagonal.
pub const GRID_PAIR_CELLS: f64 = std::f64::consts::SQRT_2;

/// Pairs of opposite cones among `cones` (position, index) closer than
/// `distance`, closest first, one quarter turn each: `(a, b)` with
/// `cones[a]` positive and `cones[b]` negative; a cone of index ±2 may be
/// in two pairs. Greedy on distances alone, so the pairs do not depend on
/// the order in which they cancel.
pub fn close_pairs(cones: &[([f64; 3], i64)], distance: f64) -> Vec<(usize, usize)> {
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for (a, &(p, ka)) in cones.iter().enumerate().filter(|c| c.1 .1 > 0) {
        for (b, &(q, _)) in cones.iter().enumerate().filter(|c| c.1 .1 < 0) {
            let d = crate::vec3::norm(crate::vec3::sub(p, q));
            if d < distance {
                candidates.extend(std::iter::repeat_n((d, a, b), ka as usize));
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut left: Vec<i64> = cones.iter().map(|c| c.1.abs()).collect();
    let mut pairs = Vec::new();
    for (_, a, b) in candidates {
        if left[a] > 0 && left[b] > 0 {
            left[a] -= 1;
            left[b] -= 1;
            pairs.push((a, b));
        }
    }
    pairs
}

/// What the boundary of the input mesh must do (features are always aligned).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoundaryMode {
    /// Every boundary edge on a u or v isoline, with corners of k·90° (the
    /// paper's setting: CAD parts, deliberate cuts).
    #[default]
    Aligned,
    /// The boundary is left free: no isoline, no corners, its geodesic
    /// curvature outside the constraints (scans with holes, atlases). The
    /// holonomy around each hole is still a multiple of 90° (seamless).
    Free,
}

/// How each round of Algorithm 1 picks the `p` to fix (see
/// docs/cone-placement.md, "Algorithm 1 and cone moves").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoundingRule {
    /// The paper's batch (total rounding below 0.5) in every free cluster
    /// at once: a few dozen rounds.
    PerCluster,
    /// The paper's batch over the whole component: hundreds of rounds; the
    /// pipeline falls back to it when a per-cluster placement gives a map
    /// that folds.
    Whole,
}

impl Default for ConeOptions {
    fn default() -> Self {
        ConeOptions {
            alpha_smooth: DEFAULT_ALPHA,
            miq: false,
            optimize_locations: true,
            max_move_passes: 20,
            merge_close_pairs: true,
            cancel_pairs_nearest: 3,
            coarse_vertices: COARSE_VERTICES,
            rounding: RoundingRule::PerCluster,
            boundary: BoundaryMode::Aligned,
            max_cone_index: 1,
            min_pair_distance: 0.0,
        }
    }
}

/// What went wrong while placing cones.
#[derive(Clone, Debug, PartialEq)]
pub enum ConeError {
    Solve(LinalgError),
    /// The boundary turning integers admit no integer path values (an internal inconsistency).
    InconsistentBoundary { vertex: u32 },
}

impl From<LinalgError> for ConeError {
    fn from(e: LinalgError) -> Self {
        ConeError::Solve(e)
    }
}

impl fmt::Display for ConeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConeError::Solve(e) => write!(f, "cone placement: linear solve failed: {e}"),
            ConeError::InconsistentBoundary { vertex } => {
                write!(f, "cone placement: boundary turning at vertex v{vertex} is inconsistent")
            }
        }
    }
}

impl std::error::Error for ConeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ConeError::Solve(e) => Some(e),
            ConeError::InconsistentBoundary { .. } => None,
        }
    }
}

/// Progress reports, in order.
#[derive(Clone, Debug, PartialEq)]
pub enum ConeProgress {
    /// Building the path basis and harmonic forms of component `component`.
    Topology { component: usize, components: usize },
    /// Rounding round `round`: `free` integers still unrounded.
    Rounding { component: usize, round: usize, free: usize },
    /// Cone-location pass `pass`: `tried` of the pass's `cones` candidate
    /// cones evaluated so far.
    ConeMoves { component: usize, pass: usize, tried: usize, cones: usize },
    /// Pair cancellation: `removed` pairs so far; in the current round,
    /// `tried` of its `trials` candidate pairs evaluated.
    PairCancellation { component: usize, removed: usize, tried: usize, trials: usize },
}

/// A cone or boundary corner: `k` quarter turns of curvature (cone angle
/// `2 pi - k pi / 2` inside, turning `k pi / 2` on the boundary).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Cone {
    /// Vertex of the input mesh.
    pub vertex: u32,
    pub k: i32,
    pub position: [f64; 3],
}

/// Seconds per stage. Components can be placed in parallel: `topology`,
/// `rounding` and `cone_moves` add up over components, `total` is wall-clock.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ConeTimings {
    pub cut: f64,
    pub topology: f64,
    pub rounding: f64,
    pub cone_moves: f64,
    pub total: f64,
}

/// Per-component figures.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ComponentFigures {
    pub euler_characteristic: i64,
    pub boundary_loops: usize,
    pub genus: i64,
    /// Sum of all `k` of the cut component (equals `4 chi`).
    pub k_sum: i64,
    /// Integers of the homology loops and boundary alignment paths (`k_path`).
    pub path_integers: Vec<i64>,
    /// Coefficients of the harmonic part.
    pub h: Vec<f64>,
    pub rounds: usize,
    pub moves: usize,
    /// Opposite cone pairs cancelled by the close-pair clean-up, and by
    /// descent and for a quad grid ([`ConeOptions::min_pair_distance`]).
    pub merged_pairs: usize,
    pub cancelled_pairs: usize,
    /// Quarter turns moved off cones of index above 3 (`spread_degenerate_cones`).
    pub spread_quarter_turns: usize,
    /// Relative residual of the final KKT solve.
    pub residual: f64,
    /// Iterative-refinement steps over all solves.
    pub refinement_steps: usize,
}

/// The result of cone placement.
#[derive(Clone, Debug)]
pub struct ConePlacement {
    /// The mesh cut open along the features.
    pub cut: CutMesh,
    /// Per cut vertex: cone index (interior) or turning integer (boundary).
    pub k: Vec<i32>,
    /// `phi` (log conformal scale) per cut vertex.
    pub phi: Vec<f64>,
    /// `omega` per midline segment: `omega[3 f + i]` runs from the midpoint of
    /// halfedge `3 f + i` to that of `3 f + (i + 1) % 3`.
    pub omega: Vec<f64>,
    /// Interior cones of the input mesh (feature vertices included).
    pub cones: Vec<Cone>,
    /// Corners of the input mesh's boundary.
    pub boundary_corners: Vec<Cone>,
    pub components: Vec<ComponentFigures>,
    /// `phiᵀ(alpha L + M/A) phi` summed over components.
    pub energy: f64,
    /// Area-weighted RMS of `phi`.
    pub phi_rms: f64,
    pub rounds: usize,
    pub timings: ConeTimings,
}

impl ConePlacement {
    /// The pairs of opposite interior cones (cut-mesh vertices, positive
    /// first) closer than `distance` ([`close_pairs`], within each
    /// component): those that [`ConeOptions::min_pair_distance`] `=
    /// distance` cancels.
    pub fn close_pairs(&self, distance: f64) -> Vec<(u32, u32)> {
        let cm = &self.cut.mesh;
        let mut by_component = vec![Vec::new(); cm.n_components()];
        for v in (0..cm.n_vertices() as u32).filter(|&v| self.k[v as usize] != 0 && !cm.is_boundary_vertex(v)) {
            by_component[cm.vertex_component(v)].push(v);
        }
        let mut pairs = Vec::new();
        for cones in by_component {
            let located: Vec<([f64; 3], i64)> = cones.iter().map(|&v| (cm.position(v), self.k[v as usize] as i64)).collect();
            pairs.extend(close_pairs(&located, distance).into_iter().map(|(a, b)| (cones[a], cones[b])));
        }
        pairs
    }

    /// Sets the index of cut vertices to what a map realized (`(cut
    /// vertex, k)` pairs, inside or on the cut mesh's boundary) and lists
    /// the cones and corners again. A map realizes each angle up to
    /// multiples of 2 pi (its angle sum at the vertex), so the indices change
    /// by multiples of 4; with every triangle positive the angle sums add up
    /// to pi per face, so the sum of the indices does not change
    /// (Gauss-Bonnet, asserted in debug builds).
    pub fn realize(&mut self, mesh: &TriMesh, realized: &[(u32, i32)]) {
        if realized.is_empty() {
            return;
        }
        let before: i64 = self.k.iter().map(|&k| k as i64).sum();
        for &(v, k) in realized {
            self.k[v as usize] = k;
        }
        debug_assert_eq!(before, self.k.iter().map(|&k| k as i64).sum::<i64>(), "realized cones must keep the index sum");
        (self.cones, self.boundary_corners) = original_cones(mesh, &self.cut, &self.k);
    }
}

/// Places cones on `mesh` with features `features` cut open (section 5).
/// Natively the components are placed on two threads (they are independent);
/// `progress` hears about the components placed on the calling thread.
pub fn place_cones(
    mesh: &TriMesh,
    features: &FeatureSet,
    options: &ConeOptions,
    progress: &mut dyn FnMut(ConeProgress),
) -> Result<ConePlacement, ConeError> {
    let mut clock = Stopwatch::start();
    let problem = ConeProblem::new(mesh, features, options);
    let results = place_all(&problem, progress)?;
    let mut placement = problem.assemble(mesh, results).expect("components placed here fit their problem");
    placement.timings.total = clock.lap();
    Ok(placement)
}

/// Places every component of `problem`, largest first; natively on two
/// threads pulling from one queue, in wasm32 one after the other.
pub fn place_all(problem: &ConeProblem, progress: &mut dyn FnMut(ConeProgress)) -> Result<Vec<ComponentPlacement>, ConeError> {
    let placed = crate::parallel::share_jobs(
        &problem.schedule(),
        |c| problem.place_component(c, &mut |_| {}),
        |c| problem.place_component(c, progress),
        Result::is_err,
    );
    placed.into_iter().map(|(_, r)| r).collect()
}

/// Cone indices on the input mesh from the cut-vertex integers: a vertex cut
/// into `n` boundary sectors has cone angle `sum (pi - k_s pi/2)`, so
/// `k = sum k_s + 2 (2 - n)` inside and `sum k_s + 2 (1 - n)` on the boundary.
pub(crate) fn original_cones(mesh: &TriMesh, cut: &CutMesh, k: &[i32]) -> (Vec<Cone>, Vec<Cone>) {
    let n = mesh.n_vertices();
    let mut sum = vec![0i32; n];
    let mut sectors = vec![0i32; n];
    let mut cut_interior = vec![false; n];
    for (cv, &o) in cut.original_vertex.iter().enumerate() {
        sum[o as usize] += k[cv];
        sectors[o as usize] += 1;
        if !cut.mesh.is_boundary_vertex(cv as u32) {
            cut_interior[o as usize] = true;
        }
    }
    let (mut cones, mut corners) = (Vec::new(), Vec::new());
    let free_boundary = cut.has_free_boundary();
    for v in 0..n as u32 {
        let i = v as usize;
        if free_boundary && mesh.is_boundary_vertex(v) {
            continue; // a free boundary has no corners
        }
        let total = if cut_interior[i] {
            sum[i]
        } else if mesh.is_boundary_vertex(v) {
            sum[i] + 2 * (1 - sectors[i])
        } else {
            sum[i] + 2 * (2 - sectors[i])
        };
        if total != 0 {
            let c = Cone { vertex: v, k: total, position: mesh.position(v) };
            if mesh.is_boundary_vertex(v) {
                corners.push(c);
            } else {
                cones.push(c);
            }
        }
    }
    (cones, corners)
}

#[cfg(test)]
mod tests;
