//! The linear (P1) triangle element, shared by the seamless solve
//! ([`super::seamless`]), the injective refinement ([`super::injective`]), the
//! untangling ([`super::untangle`]) and the metrics ([`super::metrics`]): a
//! face's local frame, the gradients of its hat functions, the Jacobian of a
//! piecewise-linear map, and UV areas and angles.
//!
//! Conventions: a face's frame has corner 0 at the origin and its first edge
//! along x (as [`crate::mesh::FaceFrames`]); a Jacobian's rows are the gradients
//! of u and v in that frame; UV triangles are counter-clockwise when the map
//! preserves orientation.

use crate::mesh::TriMesh;
use crate::vec3::{cross, dot, sub};

/// Local 2D coordinates of the corners of face `f` in its frame (x along the
/// first edge, y = n × x), corner 0 at the origin, and the face area.
pub(crate) fn local_triangle(mesh: &TriMesh, f: u32) -> ([[f64; 2]; 3], f64) {
    let t = mesh.faces()[f as usize];
    let p = t.map(|v| mesh.position(v));
    let e0 = sub(p[1], p[0]);
    let e2 = sub(p[2], p[0]);
    let l0 = dot(e0, e0).sqrt();
    let x = [e0[0] / l0, e0[1] / l0, e0[2] / l0];
    let n = cross(e0, e2);
    let nn = dot(n, n).sqrt();
    let nu = [n[0] / nn, n[1] / nn, n[2] / nn];
    let y = cross(nu, x);
    ([[0.0, 0.0], [l0, 0.0], [dot(e2, x), dot(e2, y)]], 0.5 * nn)
}

/// Gradients of the three hat functions of the triangle `q` (area `area`):
/// `grad phi_k = rot90(q_{k+2} - q_{k+1}) / (2 A)`.
pub(super) fn hat_gradients(q: [[f64; 2]; 3], area: f64) -> [[f64; 2]; 3] {
    [0, 1, 2].map(|k| {
        let (a, b) = (q[(k + 1) % 3], q[(k + 2) % 3]);
        [-(b[1] - a[1]) / (2.0 * area), (b[0] - a[0]) / (2.0 * area)]
    })
}

/// Jacobian of the linear map taking the corners with hat gradients `g` to
/// the UV points `p` (rows: the gradients of u and of v).
#[inline]
pub(super) fn jacobian(g: &[[f64; 2]; 3], p: [[f64; 2]; 3]) -> [[f64; 2]; 2] {
    let mut j = [[0.0; 2]; 2];
    for k in 0..3 {
        for c in 0..2 {
            j[c][0] += p[k][c] * g[k][0];
            j[c][1] += p[k][c] * g[k][1];
        }
    }
    j
}

/// Signed UV area of a triangle relative to its orientation (≤ 0: flipped or degenerate).
pub fn signed_uv_area(uv: [[f64; 2]; 3]) -> f64 {
    0.5 * ((uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]))
}

/// Unsigned UV angle at corner `p` of the triangle `(p, a, b)`.
pub(super) fn corner_angle(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (x, y) = ([a[0] - p[0], a[1] - p[1]], [b[0] - p[0], b[1] - p[1]]);
    (x[0] * y[1] - x[1] * y[0]).atan2(x[0] * y[0] + x[1] * y[1]).abs()
}

/// UV corner angles summed per vertex of `faces` (`n_vertices` of them), the
/// UV triangle of face `f` given by `uv_of(f)`; with `signed`, the angles of
/// flipped triangles (UV area < 0) count negative.
pub(super) fn angle_sums(faces: &[[u32; 3]], n_vertices: usize, uv_of: impl Fn(usize) -> [[f64; 2]; 3], signed: bool) -> Vec<f64> {
    let mut sums = vec![0.0; n_vertices];
    for (f, t) in faces.iter().enumerate() {
        let uv = uv_of(f);
        let flipped = signed && signed_uv_area(uv) < 0.0;
        for k in 0..3 {
            let angle = corner_angle(uv[k], uv[(k + 1) % 3], uv[(k + 2) % 3]);
            sums[t[k] as usize] += if flipped { -angle } else { angle };
        }
    }
    sums
}

/// A face of a linear system on shared unknowns: its corners' wedges and
/// unknowns, its hat gradients and its area.
#[derive(Clone, Copy)]
pub(super) struct Element {
    /// Wedges of the three corners.
    pub(super) w: [usize; 3],
    /// Unknowns of the corners' u and v.
    pub(super) x: [[usize; 3]; 2],
    /// Gradients of the three hat functions in the face frame.
    pub(super) g: [[f64; 2]; 3],
    pub(super) area: f64,
}

impl Element {
    /// The element of the triangle `q` (area `area`) with corner wedges `w`
    /// and unknowns `x`.
    pub(super) fn new(q: [[f64; 2]; 3], area: f64, w: [usize; 3], x: [[usize; 3]; 2]) -> Element {
        Element { w, x, g: hat_gradients(q, area), area }
    }

    /// The UV triangle of the unknown vector `x`.
    #[inline]
    pub(super) fn unknowns_uv(&self, x: &[f64]) -> [[f64; 2]; 3] {
        // Written out: `array::map` here was left a call in the untangler's
        // inner loop (a fifth of its time on fandisk).
        let corner = |k: usize| [x[self.x[0][k]], x[self.x[1][k]]];
        [corner(0), corner(1), corner(2)]
    }

    /// Jacobian for the unknown vector `x`.
    #[inline]
    pub(super) fn jacobian(&self, x: &[f64]) -> [[f64; 2]; 2] {
        jacobian(&self.g, self.unknowns_uv(x))
    }

    /// Jacobian for UV per wedge.
    #[inline]
    pub(super) fn wedge_jacobian(&self, uv: &[[f64; 2]]) -> [[f64; 2]; 2] {
        jacobian(&self.g, self.w.map(|w| uv[w]))
    }

    /// The UV triangle of UV per wedge.
    #[inline]
    pub(super) fn uv(&self, uv: &[[f64; 2]]) -> [[f64; 2]; 3] {
        self.w.map(|w| uv[w])
    }
}

/// Walks of a cut disk's elements near a wedge (the elements around the
/// wedges whose UV lies within a radius of the start), through wedges, so
/// never across a seam: per wedge the elements around it, and per wedge the
/// walk that reached it last.
pub(super) struct NearWedges {
    elements_of: Vec<Vec<usize>>,
    seen: Vec<usize>,
}

impl NearWedges {
    /// For `elements` on `n_wedges` wedges.
    pub(super) fn new(elements: &[Element], n_wedges: usize) -> NearWedges {
        let mut elements_of = vec![Vec::new(); n_wedges];
        for (f, el) in elements.iter().enumerate() {
            for &w in &el.w {
                elements_of[w].push(f);
            }
        }
        NearWedges { elements_of, seen: vec![usize::MAX; n_wedges] }
    }

    /// Whether a walk started at wedge `w` already.
    pub(super) fn started(&self, w: usize) -> bool {
        self.seen[w] == w
    }

    /// Calls `visit(f)` for every element around each wedge reached from
    /// `w0` (UV `p0` in the unknowns `x`) through wedges within `radius` of
    /// `p0` (an element around two reached wedges comes twice).
    pub(super) fn walk(&mut self, elements: &[Element], x: &[f64], w0: usize, p0: [f64; 2], radius: f64, mut visit: impl FnMut(usize)) {
        self.seen[w0] = w0;
        let mut stack = vec![w0];
        while let Some(w) = stack.pop() {
            for &f in &self.elements_of[w] {
                visit(f);
                let el = &elements[f];
                for k in 0..3 {
                    let (u, p) = (el.w[k], [x[el.x[0][k]], x[el.x[1][k]]]);
                    if self.seen[u] != w0 && (p[0] - p0[0]).hypot(p[1] - p0[1]) < radius {
                        self.seen[u] = w0;
                        stack.push(u);
                    }
                }
            }
        }
    }
}
