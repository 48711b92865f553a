//! Cross-field from the connection (Appendix B.1).
//!
//! `beta[h]` is the field angle at the midpoint of face halfedge `h`'s edge,
//! in the frame of face `h / 3` (frames as [`crate::mesh::FaceFrames`]). Inside a
//! face `beta_{f,b} = beta_{f,a} + omega(a -> b)` (eq. 22); across an edge
//! `beta_{g,e} = beta_{f,e} + kappa + m_e pi/2` (eq. 21) with `m_e = 0` on
//! the edges of a dual spanning tree of the cut mesh (Bommes et al. 2009).

use super::ParamError;
use crate::cones::ConePlacement;
use crate::mesh::TriMesh;
use std::collections::VecDeque;
use std::f64::consts::FRAC_PI_2;

/// Tolerance on the integrality of matchings and boundary alignment, in quarter turns.
pub const INTEGER_TOLERANCE: f64 = 1e-6;

/// Marker in [`CrossField::isoline`] for edges that need no isoline.
pub const NO_ISOLINE: u8 = u8::MAX;

/// A cross-field on the faces of the original mesh.
#[derive(Clone, Debug)]
pub struct CrossField {
    /// Field angle per face halfedge (edge midpoint, face frame).
    pub beta: Vec<f64>,
    /// Per face: `theta_f = (beta_a + beta_b + beta_c) / 3` (B.1).
    pub theta: Vec<f64>,
    /// Per face halfedge `h` of an interior edge of the original mesh:
    /// `m` with `beta[twin h] = beta[h] + kappa(h) + m pi/2` (eq. 21); 0 on boundary.
    pub matching: Vec<i64>,
    /// Per face halfedge whose edge is an aligned boundary of the cut mesh
    /// (feature, or boundary unless free): the UV coordinate that is constant along it (0 = u, 1 = v);
    /// [`NO_ISOLINE`] elsewhere.
    pub isoline: Vec<u8>,
    /// Largest deviation from an integer seen among matchings and alignments (quarter turns).
    pub integrality_residual: f64,
    /// Per edge of the CUT mesh: true when it is an edge of the dual spanning
    /// tree used for the propagation (matching 0 there). The cut graph is the
    /// complement of this same tree.
    pub tree_edge: Vec<bool>,
    /// Per component of the cut mesh, the face the propagation started from.
    pub roots: Vec<u32>,
}

impl CrossField {
    /// Target Jacobian of face `f` in its local frame (B.1): rows `e_f` and
    /// `e_f^perp`, i.e. the rotation by `-theta_f`.
    pub fn target(&self, f: usize) -> [[f64; 2]; 2] {
        let (s, c) = self.theta[f].sin_cos();
        [[c, s], [-s, c]]
    }
}

/// Propagates `beta` over a breadth-first dual spanning tree of every
/// component of the cut mesh (starting at an aligned boundary edge of the
/// cut mesh with `beta` = the edge angle, or at the component's first edge
/// when none is aligned), then measures the matchings on every interior
/// edge of the ORIGINAL mesh and the alignment on every aligned boundary
/// edge (features, and the boundary unless it is free).
///
/// Errors: [`ParamError::NonIntegerMatching`] / [`ParamError::Misaligned`]
/// when a value is more than [`INTEGER_TOLERANCE`] from an integer.
pub fn cross_field(mesh: &TriMesh, placement: &ConePlacement) -> Result<CrossField, ParamError> {
    let cm = &placement.cut.mesh;
    let omega = &placement.omega;
    let nf = mesh.n_faces();
    let mut beta = vec![f64::NAN; 3 * nf];
    let mut visited = vec![false; nf];
    let mut tree_edge = vec![false; cm.n_edges()];
    let mut roots = Vec::new();
    let mut queue = VecDeque::new();

    // Seeds: one per component of the cut mesh, preferring an aligned edge.
    let comps = cm.face_components();
    let n_comp = cm.n_components();
    let mut seed: Vec<Option<u32>> = vec![None; n_comp];
    let aligned = |s: u32| placement.cut.is_aligned_halfedge(s);
    for h in 0..3 * nf as u32 {
        let c = comps[(h / 3) as usize] as usize;
        if seed[c].is_none_or(|s| aligned(h) && !aligned(s)) {
            seed[c] = Some(h);
        }
    }
    for s in seed.into_iter().flatten() {
        let f = (s / 3) as usize;
        if visited[f] {
            continue;
        }
        // Aligned with the edge when it must be; any value where no edge is aligned.
        beta[s as usize] = if aligned(s) { mesh.halfedge_angle(s) } else { 0.0 };
        visited[f] = true;
        roots.push(f as u32);
        queue.push_back(s);
        while let Some(h_in) = queue.pop_front() {
            let f = h_in / 3;
            let i = h_in % 3;
            // eq. (22): beta_{f,b} = beta_{f,a} + omega(a -> b).
            let h1 = 3 * f + (i + 1) % 3;
            let h2 = 3 * f + (i + 2) % 3;
            beta[h1 as usize] = beta[h_in as usize] + omega[h_in as usize];
            beta[h2 as usize] = beta[h1 as usize] + omega[h1 as usize];
            for h in [h_in, h1, h2] {
                let t = cm.twin(h);
                if cm.is_boundary_halfedge(t) {
                    continue;
                }
                let g = (t / 3) as usize;
                if !visited[g] {
                    visited[g] = true;
                    tree_edge[cm.edge(h) as usize] = true;
                    // eq. (21) with m = 0 on the dual tree.
                    beta[t as usize] = beta[h as usize] + mesh.kappa(h);
                    queue.push_back(t);
                }
            }
        }
    }
    if beta.iter().any(|b| !b.is_finite()) {
        return Err(ParamError::NotFinite { what: "cross-field angle" });
    }

    let mut residual: f64 = 0.0;
    let mut matching = vec![0i64; 3 * nf];
    for h in 0..3 * nf as u32 {
        let t = mesh.twin(h);
        if mesh.is_boundary_halfedge(t) {
            continue;
        }
        // eq. (21): m_e = (beta_g - beta_f - kappa) / (pi/2).
        let m = (beta[t as usize] - beta[h as usize] - mesh.kappa(h)) / FRAC_PI_2;
        let d = (m - m.round()).abs();
        residual = residual.max(d);
        if d > INTEGER_TOLERANCE || !m.is_finite() {
            return Err(ParamError::NonIntegerMatching { edge: mesh.edge(h), value: m });
        }
        matching[h as usize] = m.round() as i64;
    }
    let mut isoline = vec![NO_ISOLINE; 3 * nf];
    for h in 0..3 * nf as u32 {
        if !aligned(h) {
            continue;
        }
        let n = (beta[h as usize] - mesh.halfedge_angle(h)) / FRAC_PI_2;
        let d = (n - n.round()).abs();
        residual = residual.max(d);
        if d > INTEGER_TOLERANCE || !n.is_finite() {
            return Err(ParamError::Misaligned { edge: mesh.edge(h), value: n });
        }
        // The edge runs at -n quarter turns from the field's first direction,
        // which maps to the u axis: even n -> along u (v constant), odd -> u constant.
        isoline[h as usize] = if (n.round() as i64).rem_euclid(2) == 0 { 1 } else { 0 };
    }
    let theta = (0..nf).map(|f| (beta[3 * f] + beta[3 * f + 1] + beta[3 * f + 2]) / 3.0).collect();
    Ok(CrossField { beta, theta, matching, isoline, integrality_residual: residual, tree_edge, roots })
}
