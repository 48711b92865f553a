//! The nearest point of a mesh's surface to a point, optionally only on
//! faces that face a given way: how quads traced on a decimation move onto
//! the input ([`crate::quads::project_onto`]), and how the decimation's map
//! is carried back to the input's triangles. A face facing the other way
//! is on the far side of a part thinner than the distance (an ear, a fin).

use super::box_grid::{BoxGrid, Visited};
use super::TriMesh;
use crate::vec3::{barycentric_point, bounds, closest_point_barycentric, dot, norm, sub, V3};

/// A point of a [`NearestFace`] mesh's surface and its distance from the query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    pub face: u32,
    pub bary: [f64; 3],
    pub point: V3,
    pub distance: f64,
}

/// Nearest-point queries on one mesh's faces (a uniform grid over their boxes).
pub struct NearestFace {
    triangles: Vec<[V3; 3]>,
    normals: Vec<V3>,
    grid: BoxGrid,
    seen: Visited,
}

impl NearestFace {
    pub fn new(mesh: &TriMesh) -> NearestFace {
        let triangles: Vec<[V3; 3]> = mesh.faces().iter().map(|t| t.map(|v| mesh.position(v))).collect();
        let boxes: Vec<(V3, V3)> = triangles.iter().map(|t| bounds(t)).collect();
        let (grid, seen) = (BoxGrid::new(&boxes), Visited::new(triangles.len()));
        NearestFace { triangles, normals: mesh.face_normals().to_vec(), grid, seen }
    }

    /// The nearest point to `p` on a face whose normal is within 90° of
    /// `facing` (on any face where `facing` is `None` or no face is);
    /// `None` on a mesh without faces.
    pub fn nearest(&mut self, p: V3, facing: Option<V3>) -> Option<Nearest> {
        let mut best: Option<Nearest> = None;
        for only_facing in [true, false] {
            if best.is_some() {
                break;
            }
            let (triangles, normals) = (&self.triangles, &self.normals);
            self.grid.nearest(p, f64::INFINITY, &mut self.seen, |f| {
                if only_facing && facing.is_some_and(|n| dot(n, normals[f as usize]) <= 0.0) {
                    return f64::INFINITY;
                }
                let t = &triangles[f as usize];
                let bary = closest_point_barycentric(p, t);
                let point = barycentric_point(t, bary);
                let distance = norm(sub(point, p));
                if best.is_none_or(|b| distance < b.distance) {
                    best = Some(Nearest { face: f, bary, point, distance });
                }
                distance
            });
        }
        best
    }
}
