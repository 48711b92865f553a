//! Quality figures of a parametrization: the isometric distortion of eq. (19)
//! at the best global scale, flips, seamlessness and alignment residuals.

use super::cut_graph::CutGraph;
use super::element::{self, hat_gradients, local_triangle, signed_uv_area};
use crate::cones::ConePlacement;
use crate::mesh::TriMesh;
use serde::Serialize;
use std::f64::consts::FRAC_PI_2;

/// Figures of one parametrization.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Metrics {
    /// eq. (19): `(1/A) sum_f A_f min_R |s J_f - R|_F` at the best scale `s`.
    pub distortion: f64,
    /// The global UV scale `s` at which `distortion` is measured.
    pub scale: f64,
    /// Fraction of triangles (by count) with distortion below 0.2 / 0.3.
    pub fraction_below_0_2: f64,
    pub fraction_below_0_3: f64,
    /// Largest per-triangle distortion.
    pub max_distortion: f64,
    /// Triangles with signed UV area ≤ 0.
    pub flipped: usize,
    /// Interior vertices where the map folds: the *signed* UV angle sum is
    /// off the cone angle by more than pi (the map winds around them more or
    /// less than the cone needs, including vertices ringed by flipped
    /// triangles, whose sum is 0 or -2 pi).
    pub wound_vertices: usize,
    /// Largest deviation (radians) of a seam edge's transition from a multiple of 90°.
    pub seam_angle_residual: f64,
    /// Largest relative difference of the two UV lengths of a seam edge.
    pub seam_length_residual: f64,
    /// Largest angle (radians) between a feature/boundary edge's UV image and the nearest axis.
    pub alignment_residual: f64,
    /// Interior cones and boundary corners of the input mesh.
    pub cones: usize,
    pub boundary_corners: usize,
    pub seam_edges: usize,
    /// Total 3D length of the seam edges.
    pub seam_length: f64,
    pub faces: usize,
}

/// Per-triangle `min_R |s J - R|_F` from the conformal / anticonformal norms of `J`.
fn tri_distortion(conf: f64, anti: f64, s: f64) -> f64 {
    (2.0 * s * s * (conf * conf + anti * anti) - 4.0 * s * conf + 2.0).max(0.0).sqrt()
}

/// Jacobian (UV per unit length, in the face frame) and area of every face.
pub fn face_jacobians(mesh: &TriMesh, uv: &[[f64; 2]]) -> Vec<([[f64; 2]; 2], f64)> {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            let (q, area) = local_triangle(mesh, f);
            let p = [0, 1, 2].map(|k| uv[3 * f as usize + k]);
            (element::jacobian(&hat_gradients(q, area), p), area)
        })
        .collect()
}

/// Per-face distortion `min_R |s J_f - R|_F` at UV scale `s` (the
/// quantity eq. (19) averages), for heat maps and histograms.
pub fn face_distortion(mesh: &TriMesh, uv: &[[f64; 2]], s: f64) -> Vec<f64> {
    face_jacobians(mesh, uv)
        .iter()
        .map(|&(j, _)| {
            let (a, b, c, d) = (j[0][0], j[0][1], j[1][0], j[1][1]);
            let conf = (0.25 * ((a + d).powi(2) + (b - c).powi(2))).sqrt();
            let anti = (0.25 * ((a - d).powi(2) + (b + c).powi(2))).sqrt();
            tri_distortion(conf, anti, s)
        })
        .collect()
}

/// Sum of the UV corner angles around every vertex of `mesh` (all wedges):
/// `2 pi - k pi/2` at an interior vertex of cone index `k` for a seamless,
/// fold-free map.
pub fn uv_angle_sums(mesh: &TriMesh, uv: &[[f64; 2]]) -> Vec<f64> {
    angle_sums(mesh, uv, false)
}

/// UV corner angles summed per vertex (UV per corner `3 f + k`); with
/// `signed`, the angles of flipped triangles count negative.
fn angle_sums(mesh: &TriMesh, uv: &[[f64; 2]], signed: bool) -> Vec<f64> {
    element::angle_sums(mesh.faces(), mesh.n_vertices(), |f| [uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]], signed)
}

/// Cone angle `2 pi - k pi/2` of every interior vertex of `mesh` that is not
/// on a feature (NaN elsewhere), from the cone placement.
pub(crate) fn interior_cone_angles(mesh: &TriMesh, placement: &ConePlacement) -> Vec<f64> {
    let mut angle = vec![f64::NAN; mesh.n_vertices()];
    let cut = &placement.cut;
    for (cv, &v) in cut.original_vertex.iter().enumerate() {
        if !cut.mesh.is_boundary_vertex(cv as u32) {
            angle[v as usize] = 2.0 * std::f64::consts::PI - placement.k[cv] as f64 * std::f64::consts::FRAC_PI_2;
        }
    }
    angle
}

/// Interior vertices where the map folds ([`Metrics::wound_vertices`]):
/// signed UV angle sum off the vertex's cone angle by more than pi.
pub fn wound_vertices(mesh: &TriMesh, placement: &ConePlacement, uv: &[[f64; 2]]) -> Vec<u32> {
    let sums = angle_sums(mesh, uv, true);
    let cone_angle = interior_cone_angles(mesh, placement);
    (0..mesh.n_vertices() as u32)
        .filter(|&v| {
            let expected = cone_angle[v as usize];
            expected.is_finite() && (sums[v as usize] - expected).abs() > std::f64::consts::PI
        })
        .collect()
}

/// Angle (radians) from `angle` to the nearest multiple of 90°.
pub fn axis_deviation(angle: f64) -> f64 {
    (angle - (angle / FRAC_PI_2).round() * FRAC_PI_2).abs()
}

/// Conformal and anticonformal norms and area of every face with a finite Jacobian.
fn face_parts(mesh: &TriMesh, uv: &[[f64; 2]]) -> Vec<(f64, f64, f64)> {
    face_jacobians(mesh, uv)
        .iter()
        .map(|&(j, area)| {
            let (a, b, c, d) = (j[0][0], j[0][1], j[1][0], j[1][1]);
            let conf = (0.25 * ((a + d).powi(2) + (b - c).powi(2))).sqrt();
            let anti = (0.25 * ((a - d).powi(2) + (b + c).powi(2))).sqrt();
            (conf, anti, area)
        })
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect()
}

/// Eq. (19) at the best scale: `(mean, s)` minimising the area-weighted mean
/// of `min_R |s J_f - R|_F` over `s` (golden-section search on `log s`).
fn best_scale_mean(parts: &[(f64, f64, f64)]) -> (f64, f64) {
    let total: f64 = parts.iter().map(|p| p.2).sum::<f64>().max(f64::MIN_POSITIVE);
    let mean = |s: f64| parts.iter().map(|&(c, a, w)| w * tri_distortion(c, a, s)).sum::<f64>() / total;
    // Least-squares scale as a centre, then golden-section search on log s (the mean is convex in s).
    let num: f64 = parts.iter().map(|&(c, _, w)| w * c).sum();
    let den: f64 = parts.iter().map(|&(c, a, w)| w * (c * c + a * a)).sum();
    let s0 = if den > 0.0 && num > 0.0 { num / den } else { 1.0 };
    let (mut lo, mut hi) = ((s0 / 8.0).ln(), (s0 * 8.0).ln());
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (mean(x1.exp()), mean(x2.exp()));
    for _ in 0..80 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = mean(x1.exp());
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = mean(x2.exp());
        }
    }
    let scale = (0.5 * (lo + hi)).exp();
    (mean(scale), scale)
}

/// The distortion of eq. (19) at the best global scale ([`Metrics::distortion`])
/// of per-corner `uv` (index `3 f + k`).
pub fn distortion(mesh: &TriMesh, uv: &[[f64; 2]]) -> f64 {
    best_scale_mean(&face_parts(mesh, uv)).0
}

impl Metrics {
    /// The distortion figures (distortion, scale, fractions below 0.2 and
    /// 0.3, largest) of per-corner `uv` at one global scale, and `faces`;
    /// every count and residual 0.
    fn of_distortion(mesh: &TriMesh, uv: &[[f64; 2]]) -> Metrics {
        let parts = face_parts(mesh, uv);
        let (distortion, scale) = best_scale_mean(&parts);
        let per_tri: Vec<f64> = parts.iter().map(|&(c, a, _)| tri_distortion(c, a, scale)).collect();
        let n = per_tri.len().max(1) as f64;
        let below = |t: f64| per_tri.iter().filter(|&&d| d < t).count() as f64 / n;
        Metrics {
            distortion,
            scale,
            fraction_below_0_2: below(0.2),
            fraction_below_0_3: below(0.3),
            max_distortion: per_tri.iter().cloned().fold(0.0, f64::max),
            flipped: 0,
            wound_vertices: 0,
            seam_angle_residual: 0.0,
            seam_length_residual: 0.0,
            alignment_residual: 0.0,
            cones: 0,
            boundary_corners: 0,
            seam_edges: 0,
            seam_length: 0.0,
            faces: mesh.n_faces(),
        }
    }

    /// The figures of a map joined from maps of separate components, each
    /// measured on its own (`parts`): the distortion figures measured again
    /// on the joined `mesh` and per-corner `uv` (one global scale), counts
    /// and lengths summed, residuals the largest.
    pub fn join(parts: &[Metrics], mesh: &TriMesh, uv: &[[f64; 2]]) -> Metrics {
        let sum = |f: fn(&Metrics) -> usize| parts.iter().map(f).sum::<usize>();
        let max = |f: fn(&Metrics) -> f64| parts.iter().map(f).fold(0.0, f64::max);
        Metrics {
            flipped: sum(|m| m.flipped),
            wound_vertices: sum(|m| m.wound_vertices),
            seam_angle_residual: max(|m| m.seam_angle_residual),
            seam_length_residual: max(|m| m.seam_length_residual),
            alignment_residual: max(|m| m.alignment_residual),
            cones: sum(|m| m.cones),
            boundary_corners: sum(|m| m.boundary_corners),
            seam_edges: sum(|m| m.seam_edges),
            seam_length: parts.iter().map(|m| m.seam_length).sum(),
            ..Metrics::of_distortion(mesh, uv)
        }
    }
}

/// Computes every figure of [`Metrics`] for per-corner `uv` (index `3 f + k`).
pub fn compute(mesh: &TriMesh, placement: &ConePlacement, cut: &CutGraph, uv: &[[f64; 2]]) -> Metrics {
    let nf = mesh.n_faces();
    let flipped = (0..nf).filter(|&f| !(signed_uv_area([uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]]) > 0.0)).count();

    let (mut seam_angle, mut seam_len, mut seam_length) = (0.0f64, 0.0f64, 0.0);
    for &e in &cut.seam_edges {
        let [h, t] = mesh.edge_halfedges(e);
        let (Some(_), Some(_)) = (mesh.face(h), mesh.face(t)) else { continue };
        let d = |a: u32, b: u32| {
            let (p, q) = (uv[a as usize], uv[b as usize]);
            [q[0] - p[0], q[1] - p[1]]
        };
        let ef = d(h, mesh.next(h));
        let eg = d(mesh.next(t), t);
        let ang = (ef[0] * eg[1] - ef[1] * eg[0]).atan2(ef[0] * eg[0] + ef[1] * eg[1]);
        seam_angle = seam_angle.max(axis_deviation(ang));
        let (lf, lg) = (ef[0].hypot(ef[1]), eg[0].hypot(eg[1]));
        seam_len = seam_len.max((lf - lg).abs() / lf.max(lg).max(f64::MIN_POSITIVE));
        let p = mesh.edge_vertices(e).map(|v| mesh.position(v));
        seam_length += ((p[0][0] - p[1][0]).powi(2) + (p[0][1] - p[1][1]).powi(2) + (p[0][2] - p[1][2]).powi(2)).sqrt();
    }

    let mut alignment = 0.0f64;
    for h in 0..3 * nf as u32 {
        if placement.cut.is_aligned_halfedge(h) {
            let (p, q) = (uv[h as usize], uv[mesh.next(h) as usize]);
            let ang = (q[1] - p[1]).atan2(q[0] - p[0]);
            alignment = alignment.max(axis_deviation(ang));
        }
    }
    let wound_vertices = wound_vertices(mesh, placement, uv).len();
    Metrics {
        flipped,
        wound_vertices,
        seam_angle_residual: seam_angle,
        seam_length_residual: seam_len,
        alignment_residual: alignment,
        cones: placement.cones.len(),
        boundary_corners: placement.boundary_corners.len(),
        seam_edges: cut.seam_edges.len(),
        seam_length,
        ..Metrics::of_distortion(mesh, uv)
    }
}
