//! Quantities measured along dual paths: frame transport between
//! consecutive faces (`kappa`, boundary port angles), the conformal part of
//! the connection on midline segments (eq. 11) and the total geodesic
//! curvature of a dual path (eq. 14). The face frames themselves are mesh
//! geometry ([`crate::mesh::FaceFrames`]).
//!
//! A dual path is a list of [`Visit`]s: in face `h_in / 3` it runs along the
//! midline segment from the midpoint of halfedge `h_in` to that of `h_out`.
//! Between two visits it either crosses an interior edge (`twin(h_out) ==
//! next.h_in`) or passes through the outer node through two boundary edges.

use crate::mesh::{wrap_angle, TriMesh};
use crate::vec3::{self, dot, sub, V3};

/// One face of a dual path: enters through the edge of face halfedge `h_in`,
/// leaves through the edge of face halfedge `h_out` (same face).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Visit {
    pub h_in: u32,
    pub h_out: u32,
}

/// Transport term between two consecutive visits: `kappa` across an
/// interior edge, or the two port terms through the outer node (`-angle` of
/// the edge left, `+angle` of the edge entered).
pub fn transition(mesh: &TriMesh, from: Visit, to: Visit) -> f64 {
    if mesh.twin(from.h_out) == to.h_in {
        mesh.kappa(from.h_out)
    } else {
        debug_assert!(mesh.is_boundary_halfedge(mesh.twin(from.h_out)));
        debug_assert!(mesh.is_boundary_halfedge(mesh.twin(to.h_in)));
        mesh.halfedge_angle(to.h_in) - mesh.halfedge_angle(from.h_out)
    }
}

/// Geometric part of the holonomy of a closed dual cycle: the sum of the
/// transitions between its consecutive visits (cyclically).
pub fn cycle_transport(mesh: &TriMesh, cycle: &[Visit]) -> f64 {
    (0..cycle.len()).map(|i| transition(mesh, cycle[i], cycle[(i + 1) % cycle.len()])).sum()
}

/// Coefficients of the conformal connection `-*dphi` on the midline segment
/// of `visit` (eq. 11): the segment value is `sum_k c[k] * phi[corner k of
/// the face]`. With this sign the values around a vertex sum to `(L phi)_v`
/// for the positive semi-definite cotangent Laplacian `L`.
pub fn segment_phi_coefficients(mesh: &TriMesh, visit: Visit) -> [f64; 3] {
    let f = visit.h_in / 3;
    let t = segment(mesh, visit);
    let two_area = 2.0 * mesh.face_areas()[f as usize];
    // Edge opposite corner k runs from corner k+1 to corner k+2: halfedge 3f + (k+1)%3.
    [0, 1, 2].map(|k| dot(mesh.halfedge_vector(3 * f + (k + 1) % 3), t) / two_area)
}

/// Total geodesic curvature of an open dual path (eq. 14): the sum of the
/// turning angles between consecutive midline segments, the second triangle
/// unfolded about the shared edge.
pub fn path_geodesic_curvature(mesh: &TriMesh, path: &[Visit]) -> f64 {
    let frames = mesh.face_frames();
    path.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            debug_assert_eq!(mesh.twin(a.h_out), b.h_in);
            let da = frames.angle(a.h_in / 3, segment(mesh, a));
            let db = frames.angle(b.h_in / 3, segment(mesh, b));
            wrap_angle(db - (da + mesh.kappa(a.h_out)))
        })
        .sum()
}

/// The visits of the dual cycle around vertex `v`, counter-clockwise: for an
/// interior vertex a closed loop, for a boundary vertex the fan from one
/// boundary edge to the other (closed through the outer node).
pub fn vertex_cycle(mesh: &TriMesh, v: u32) -> Vec<Visit> {
    mesh.outgoing(v)
        .filter(|&h| !mesh.is_boundary_halfedge(h))
        .map(|h| Visit { h_in: h, h_out: mesh.prev(h) })
        .collect()
}

/// The midline segment of `visit`: from the midpoint of `h_in` to that of `h_out`.
fn segment(mesh: &TriMesh, visit: Visit) -> V3 {
    sub(midpoint(mesh, visit.h_out), midpoint(mesh, visit.h_in))
}

fn midpoint(mesh: &TriMesh, h: u32) -> V3 {
    vec3::midpoint(mesh.position(mesh.tail(h)), mesh.position(mesh.head(h)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::{grid, octahedron};
    use std::f64::consts::PI;

    /// The holonomy constant of every vertex cycle is the angle defect modulo 2 pi.
    fn check_vertex_transport(mesh: &TriMesh) {
        let defects = mesh.angle_defects();
        for v in 0..mesh.n_vertices() as u32 {
            let g = cycle_transport(mesh, &vertex_cycle(mesh, v));
            let j = (defects[v as usize] - g) / (2.0 * PI);
            assert!((j - j.round()).abs() < 1e-9, "vertex {v}: transport {g}, defect {}", defects[v as usize]);
        }
    }

    #[test]
    fn vertex_transport_matches_angle_defects() {
        check_vertex_transport(&octahedron());
        check_vertex_transport(&grid(5, 4, |x, y| [x, y, 0.3 * (x * y).sin()]));
    }

    #[test]
    fn segment_values_around_a_vertex_sum_to_the_laplacian() {
        let mesh = grid(6, 5, |x, y| [x, y, 0.2 * (2.0 * x).cos() * y]);
        let phi: Vec<f64> = (0..mesh.n_vertices()).map(|i| ((i * 7919) % 13) as f64 * 0.1).collect();
        let mut lphi = vec![0.0; mesh.n_vertices()];
        for (i, j, w) in mesh.cotan_laplacian_triplets(0..mesh.n_faces() as u32) {
            lphi[i] += w * phi[j];
        }
        for v in 0..mesh.n_vertices() as u32 {
            let mut sum = 0.0;
            for visit in vertex_cycle(&mesh, v) {
                let c = segment_phi_coefficients(&mesh, visit);
                let tri = mesh.faces()[(visit.h_in / 3) as usize];
                sum += (0..3).map(|k| c[k] * phi[tri[k] as usize]).sum::<f64>();
            }
            let lv = lphi[v as usize];
            assert!((sum - lv).abs() < 1e-12, "vertex {v}: {sum} vs {lv}");
        }
    }

    #[test]
    fn segments_of_one_face_close() {
        let mesh = octahedron();
        let [a, b, c] = mesh.face_halfedges(0);
        let total: [f64; 3] = [Visit { h_in: a, h_out: b }, Visit { h_in: b, h_out: c }, Visit { h_in: c, h_out: a }]
            .iter()
            .map(|&v| segment_phi_coefficients(&mesh, v))
            .fold([0.0; 3], |s, x| [s[0] + x[0], s[1] + x[1], s[2] + x[2]]);
        assert!(total.iter().all(|t| t.abs() < 1e-14));
    }

    #[test]
    fn geodesic_curvature_of_the_midline_loop_is_the_angle_sum() {
        // Around a cone of angle sum S the unfolded midline polygon turns by S (eq. 14).
        let mesh = octahedron();
        let mut cycle = vertex_cycle(&mesh, 0);
        cycle.push(cycle[0]);
        let turning = path_geodesic_curvature(&mesh, &cycle);
        assert!((turning - 4.0 * PI / 3.0).abs() < 1e-12, "turning {turning}"); // four 60° corners
    }
}
