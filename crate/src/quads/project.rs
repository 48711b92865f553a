//! A quad mesh traced on one surface (a decimation of the input, say)
//! moved onto another: each vertex to the nearest point of the other
//! surface whose face is not turned against the face it was traced on, so
//! that a vertex on one side of a part thinner than the decimation's error
//! (an ear, a fin) stays on that side. Vertices on an edge both surfaces
//! share (a feature curve the decimation kept) are 0 away and stay put.

use super::check::box_grid::{BoxGrid, Visited};
use super::extract::untangle;
use super::{QuadMesh, SurfacePoint};
use crate::features::FeatureSet;
use crate::mesh::TriMesh;
use crate::vec3::{barycentric_point, bounds, closest_point_barycentric, dot, norm, sub, V3};

/// Moves every vertex of `quads` (located on `from`) to the nearest point
/// of `onto` on a face whose normal is within 90° of its face's on `from`
/// (the nearest point of any face where none is), and relocates it there;
/// a defect's face becomes the face of `onto` nearest to its face's
/// centroid. Then the quads that fold on `onto` are untangled there
/// ([`untangle`], `features`: those of `onto`). Returns the largest
/// distance a vertex moved onto `onto`.
pub fn project_onto(quads: &mut QuadMesh, from: &TriMesh, onto: &TriMesh, features: &FeatureSet) -> f64 {
    let triangles: Vec<[V3; 3]> = onto.faces().iter().map(|t| t.map(|v| onto.position(v))).collect();
    if triangles.is_empty() {
        return 0.0;
    }
    let boxes: Vec<(V3, V3)> = triangles.iter().map(|t| bounds(t)).collect();
    let grid = BoxGrid::new(&boxes);
    let mut seen = Visited::new(triangles.len());
    let (from_normals, onto_normals) = (from.face_normals(), onto.face_normals());
    // The nearest point of `onto` to `p` on a face facing along `n` (any
    // face where `n` is None or none faces along it).
    let mut nearest = |p: V3, n: Option<V3>| -> (SurfacePoint, V3, f64) {
        let mut best = (SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] }, triangles[0][0], f64::INFINITY);
        for facing in [true, false] {
            if !facing && best.2.is_finite() {
                break;
            }
            grid.nearest(p, f64::INFINITY, &mut seen, |f| {
                if facing && n.is_some_and(|n| dot(n, onto_normals[f as usize]) <= 0.0) {
                    return f64::INFINITY;
                }
                let t = &triangles[f as usize];
                let bary = closest_point_barycentric(p, t);
                let q = barycentric_point(t, bary);
                let d = norm(sub(q, p));
                if d < best.2 {
                    best = (SurfacePoint { face: f, bary }, q, d);
                }
                d
            });
        }
        best
    };
    let mut moved = 0.0f64;
    for (v, location) in quads.locations.iter_mut().enumerate() {
        let n = from_normals.get(location.face as usize).copied();
        let (point, q, d) = nearest(quads.positions[v], n);
        quads.positions[v] = q;
        *location = point;
        moved = moved.max(d);
    }
    for defect in &mut quads.defects {
        let Some(t) = from.faces().get(defect.face as usize) else { continue };
        let centroid = barycentric_point(&t.map(|v| from.position(v)), [1.0 / 3.0; 3]);
        defect.face = nearest(centroid, from_normals.get(defect.face as usize).copied()).0.face;
    }
    untangle(onto, features, quads);
    moved
}
