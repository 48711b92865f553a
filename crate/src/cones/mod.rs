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
pub mod frames;
pub mod harmonic;
pub mod system;
#[cfg(test)]
pub(crate) mod test_meshes;

use crate::clock::Stopwatch;
use crate::features::{cut_open, CutMesh, FeatureSet};
use crate::mesh::TriMesh;
use frames::{Frames, Visit};
use serde::Serialize;
use std::f64::consts::FRAC_PI_2;
pub use system::ConeError;
use system::{ComponentSystem, Weights};

/// Default `alpha_smooth` (paper: 0.01 in most figures).
pub const DEFAULT_ALPHA: f64 = 0.01;
/// `alpha_smooth` used by MIQ emulation when none is given ("100.0*" in Table 1).
pub const MIQ_ALPHA: f64 = 100.0;
/// Accepted range of `alpha_smooth`.
pub const ALPHA_RANGE: (f64, f64) = (1e-4, 1e3);

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
        }
    }
}

/// Progress reports, in order.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// Building the path basis and harmonic forms of component `component`.
    Topology { component: usize, components: usize },
    /// Rounding round `round`: `free` integers still unrounded.
    Rounding { component: usize, round: usize, free: usize },
    /// Cone-location pass `pass`.
    ConeMoves { component: usize, pass: usize },
    /// Pair cancellation: `removed` pairs so far.
    PairCancellation { component: usize, removed: usize },
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

/// Seconds per stage.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ConeTimings {
    pub cut: f64,
    pub topology: f64,
    pub rounding: f64,
    pub cone_moves: f64,
    pub total: f64,
}

/// Per-component figures.
#[derive(Clone, Debug, Serialize)]
pub struct ComponentCones {
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
    /// Opposite cone pairs cancelled by the close-pair clean-up and by descent.
    pub merged_pairs: usize,
    pub cancelled_pairs: usize,
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
    pub components: Vec<ComponentCones>,
    /// `phiᵀ(alpha L + M/A) phi` summed over components.
    pub energy: f64,
    /// Area-weighted RMS of `phi`.
    pub phi_rms: f64,
    pub rounds: usize,
    pub timings: ConeTimings,
}

/// Places cones on `mesh` with features `features` cut open (section 5).
pub fn place_cones(
    mesh: &TriMesh,
    features: &FeatureSet,
    options: &ConeOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<ConePlacement, ConeError> {
    let mut clock = Stopwatch::start();
    let mut timings = ConeTimings::default();
    let cut = cut_open(mesh, features);
    timings.cut = clock.lap();
    let cm = &cut.mesh;
    let frames = Frames::new(cm);
    let boundary_k = boundary_turning(cm);
    let weights = Weights { alpha_smooth: options.alpha_smooth, miq: options.miq };

    let nv = cm.n_vertices();
    let mut k = vec![0i32; nv];
    let mut phi = vec![0.0; nv];
    let mut omega = vec![0.0; 3 * cm.n_faces()];
    let mut components = Vec::new();
    let (mut energy, mut phi2_area, mut total_area, mut rounds) = (0.0, 0.0, 0.0, 0);
    let n_comp = cm.n_components();
    let mut seeds = vec![u32::MAX; n_comp];
    for (f, &c) in cm.face_components().iter().enumerate() {
        if seeds[c as usize] == u32::MAX {
            seeds[c as usize] = f as u32;
        }
    }
    for (c, &seed) in seeds.iter().enumerate() {
        progress(Progress::Topology { component: c, components: n_comp });
        let mut sys = ComponentSystem::new(cm, &frames, seed, &boundary_k, weights)?;
        timings.topology += clock.lap();
        sys.round_all(&mut |round, free| progress(Progress::Rounding { component: c, round, free }))?;
        timings.rounding += clock.lap();
        let moves = if options.optimize_locations {
            sys.optimize_locations(options.max_move_passes, &mut |pass| {
                progress(Progress::ConeMoves { component: c, pass })
            })?
        } else {
            0
        };
        let merged = if options.merge_close_pairs { sys.merge_close_pairs()? } else { 0 };
        let cancelled = if options.cancel_pairs_nearest > 0 {
            sys.cancel_pairs(options.cancel_pairs_nearest, &mut |n| progress(Progress::PairCancellation { component: c, removed: n }))?
        } else {
            0
        };
        timings.cone_moves += clock.lap();

        let kv = sys.vertex_k();
        let local_phi = sys.phi().to_vec();
        let h = sys.h();
        for (i, &v) in sys.tree.vertices.iter().enumerate() {
            k[v as usize] = kv[i] as i32;
            phi[v as usize] = local_phi[i];
        }
        for &f in &sys.tree.faces {
            let hs = cm.face_halfedges(f);
            let tri = cm.faces()[f as usize];
            for i in 0..3 {
                let visit = Visit { h_in: hs[i], h_out: hs[(i + 1) % 3] };
                let coef = frames.segment_phi_coefficients(cm, visit);
                let mut w: f64 = (0..3).map(|j| coef[j] * phi[tri[j] as usize]).sum();
                for (j, hj) in h.iter().enumerate() {
                    w += hj * sys.basis.segment(j, visit);
                }
                omega[3 * f as usize + i] = w;
            }
        }
        let area: f64 = sys.tree.faces.iter().map(|&f| frames.area(f)).sum();
        energy += sys.energy(options.alpha_smooth);
        phi2_area += sys.phi_norm2() * area;
        total_area += area;
        rounds += sys.rounds;
        let comp_index = c;
        components.push(ComponentCones {
            euler_characteristic: cm.component_euler_characteristic(comp_index),
            boundary_loops: cm.component_boundary_loops(comp_index),
            genus: cm.genus(comp_index),
            k_sum: kv.iter().sum(),
            path_integers: sys.tree.leftovers.iter().map(|&e| sys.fixed[sys.tree.g_index[e as usize] as usize].unwrap_or(0)).collect(),
            h,
            rounds: sys.rounds,
            moves,
            merged_pairs: merged,
            cancelled_pairs: cancelled,
            residual: sys.residual,
            refinement_steps: sys.refinement_steps,
        });
    }
    let (cones, boundary_corners) = original_cones(mesh, &cut, &k);
    timings.total = timings.cut + timings.topology + timings.rounding + timings.cone_moves;
    Ok(ConePlacement {
        cut,
        k,
        phi,
        omega,
        cones,
        boundary_corners,
        components,
        energy,
        phi_rms: (phi2_area / total_area.max(f64::MIN_POSITIVE)).sqrt(),
        rounds,
        timings,
    })
}

/// Turning integer of every boundary vertex, rounded from the geometry:
/// `round((pi - angle sum) / (pi/2))`, at most 1 so every boundary corner
/// keeps a parametric angle of at least 90° (a sector sharper than 45°
/// would otherwise round to a zero angle and collapse); 0 elsewhere.
pub fn boundary_turning(mesh: &TriMesh) -> Vec<i32> {
    let sums = crate::operators::angle_sums(mesh.positions(), mesh.faces());
    (0..mesh.n_vertices() as u32)
        .map(|v| {
            if mesh.is_boundary_vertex(v) {
                (((std::f64::consts::PI - sums[v as usize]) / FRAC_PI_2).round() as i32).min(1)
            } else {
                0
            }
        })
        .collect()
}

/// Cone indices on the input mesh from the cut-vertex integers: a vertex cut
/// into `n` boundary sectors has cone angle `sum (pi - k_s pi/2)`, so
/// `k = sum k_s + 2 (2 - n)` inside and `sum k_s + 2 (1 - n)` on the boundary.
fn original_cones(mesh: &TriMesh, cut: &CutMesh, k: &[i32]) -> (Vec<Cone>, Vec<Cone>) {
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
    for v in 0..n as u32 {
        let i = v as usize;
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
