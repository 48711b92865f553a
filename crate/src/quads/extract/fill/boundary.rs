//! Paths along the input's boundary between two of its points, and points
//! at a given arc length on them: where a hole that reaches the boundary
//! gets its new quad vertices ([`super::fill_run`]).

use crate::quads::SurfacePoint;
use crate::vec3::{barycentric_point, norm, sub, V3};
use crate::TriMesh;

/// A point of the input's boundary: on the boundary edge of the interior
/// half-edge `h`, at parameter `s` from its tail.
#[derive(Clone, Copy, Debug)]
pub(super) struct BoundaryPoint {
    h: u32,
    s: f64,
}

impl BoundaryPoint {
    /// Where it lies (exactly on the edge: 0 at the face's third corner).
    pub(super) fn location(self, mesh: &TriMesh) -> (SurfacePoint, V3) {
        let k = (self.h % 3) as usize;
        let mut bary = [0.0; 3];
        bary[k] = 1.0 - self.s;
        bary[(k + 1) % 3] = self.s;
        let t = mesh.faces()[(self.h / 3) as usize].map(|v| mesh.position(v));
        (SurfacePoint { face: self.h / 3, bary }, barycentric_point(&t, bary))
    }
}

/// The input's boundary from the boundary point `from` to `to`, walked with
/// the surface on the left (along the faces' half-edges): its ends and the
/// vertices between, each as the end of the edge that reaches it. `None`
/// when they are not on one boundary loop.
pub(super) fn boundary_path(mesh: &TriMesh, from: SurfacePoint, to: SurfacePoint) -> Option<Vec<BoundaryPoint>> {
    let start = boundary_position(mesh, from)?;
    let end = boundary_position(mesh, to)?;
    let mut path = vec![start];
    let mut h = start.h;
    if h == end.h && end.s >= start.s {
        path.push(end);
        return Some(path);
    }
    for _ in 0..mesh.n_boundary_halfedges() {
        path.push(BoundaryPoint { h, s: 1.0 });
        // The next boundary edge in the faces' direction starts at head(h).
        h = mesh.twin(mesh.prev(mesh.twin(h)));
        if h == end.h {
            path.push(end);
            return Some(path);
        }
    }
    None
}

/// Length of a boundary path.
pub(super) fn path_length(mesh: &TriMesh, path: &[BoundaryPoint]) -> f64 {
    path.windows(2).map(|w| norm(sub(w[1].location(mesh).1, w[0].location(mesh).1))).sum()
}

/// The point at arc length `t` along `path`: each step runs along the edge
/// of its second point, from the first point's parameter on that edge (0
/// where the first ends the previous edge).
pub(super) fn point_along(mesh: &TriMesh, path: &[BoundaryPoint], t: f64) -> BoundaryPoint {
    let mut left = t;
    for w in path.windows(2) {
        let l = norm(sub(w[1].location(mesh).1, w[0].location(mesh).1));
        if left <= l && l > 0.0 {
            let s0 = if w[0].h == w[1].h { w[0].s } else { 0.0 };
            return BoundaryPoint { h: w[1].h, s: s0 + (w[1].s - s0) * (left / l) };
        }
        left -= l;
    }
    *path.last().expect("a path has points")
}

/// A boundary point as the interior half-edge of its boundary edge (the
/// one leaving it when it is a vertex) and the parameter along it; `None`
/// for a point off the input's boundary.
pub(super) fn boundary_position(mesh: &TriMesh, p: SurfacePoint) -> Option<BoundaryPoint> {
    let zeros: Vec<usize> = (0..3).filter(|&k| p.bary[k] == 0.0).collect();
    match zeros.as_slice() {
        [k] => {
            let h = 3 * p.face + ((*k as u32 + 1) % 3);
            mesh.is_boundary_halfedge(mesh.twin(h)).then(|| BoundaryPoint { h, s: p.bary[(*k + 2) % 3] })
        }
        [i, j] => {
            let v = mesh.faces()[p.face as usize][3 - i - j];
            mesh.outgoing(v)
                .find(|&h| !mesh.is_boundary_halfedge(h) && mesh.is_boundary_halfedge(mesh.twin(h)))
                .map(|h| BoundaryPoint { h, s: 0.0 })
        }
        _ => None,
    }
}

