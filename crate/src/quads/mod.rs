//! Quad meshes from integer-grid maps (paper Figures 1 and 12; the
//! extraction follows QEx, Ebke et al. 2013): the integer points of the map
//! become the quad vertices, the integer isolines between them the quad
//! edges, and the grid cells the quads ([`extract`]). [`check`] measures
//! the result (topology, valences, corner angles, flips, distance to the
//! input surface); [`project_onto`] moves quads traced on a decimation of
//! the input onto the input.
//!
//! Input: a [`TriMesh`](crate::TriMesh) and one UV per face corner
//! (`3 f + k`) in grid units that form an integer-grid map: across every
//! interior edge the two sides' UVs differ by a rotation of `k·90°` plus an
//! integer translation, every cone lies on an integer point, and every
//! boundary edge on an integer isoline.

pub mod check;
pub mod extract;
mod project;

pub use check::{check_quads, CheckOptions, QuadReport};
pub use extract::{exact_grid_uv, extract_quads, extract_quads_along, ExtractError, ExtractOptions};
pub use project::project_onto;

use crate::mesh::TriMesh;
use crate::vec3::{barycentric_point, closest_point_barycentric, norm, sub, V3};
use serde::Serialize;

/// A quad mesh traced on a triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct QuadMesh {
    /// Vertex positions, each exactly on the input surface.
    pub positions: Vec<[f64; 3]>,
    /// Where each vertex lies on the input: its face and barycentric coordinates.
    pub locations: Vec<SurfacePoint>,
    /// Quads, counter-clockwise seen from the input surface's outside (the
    /// input's face orientation).
    pub quads: Vec<[u32; 4]>,
    /// Grid coordinates of each quad corner (`4 q + i`), in the chart of the
    /// input face the quad was traced in: the corners of a quad are an
    /// integer unit square up to a `k·90°` rotation and translation.
    pub uv: Vec<[f64; 2]>,
    /// Where the extractor had to repair the map (empty when it is a valid
    /// integer-grid map).
    pub defects: Vec<QuadDefect>,
}

/// A point of the input surface: face `face` and barycentric coordinates
/// with respect to its corners.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SurfacePoint {
    pub face: u32,
    pub bary: [f64; 3],
}

/// Barycentric coordinate below which a surface point lies on the edge
/// opposite that corner.
const ON_EDGE: f64 = 1e-9;

/// Where a [`SurfacePoint`] lies on its input face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnFace {
    /// Inside the face.
    Inside,
    /// On the face's side `h` (a halfedge of the face).
    Side(u32),
    /// At the face's corner vertex `v`.
    Corner(u32),
}

impl SurfacePoint {
    /// Where the point lies on its face: at a corner where two barycentric
    /// coordinates are below `1e-9`, on a side where one is.
    pub fn on_face(&self, mesh: &TriMesh) -> OnFace {
        let off: Vec<usize> = (0..3).filter(|&i| self.bary[i] < ON_EDGE).collect();
        match off.as_slice() {
            // At the corner whose coordinate is not ~0.
            [a, b] => OnFace::Corner(mesh.faces()[self.face as usize][3 - a - b]),
            // On the side opposite corner `a`: face halfedge `a + 1` (corner `a + 1` → `a + 2`).
            [a] => OnFace::Side(mesh.face_halfedges(self.face)[(a + 1) % 3]),
            _ => OnFace::Inside,
        }
    }

    /// The point of `faces` (of `mesh`) nearest to `x`, and its position;
    /// `x` itself in face 0 when `faces` is empty.
    pub fn nearest(mesh: &TriMesh, faces: impl IntoIterator<Item = u32>, x: V3) -> (SurfacePoint, V3) {
        let mut best = (f64::INFINITY, SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] }, x);
        for f in faces {
            let t = mesh.faces()[f as usize].map(|v| mesh.position(v));
            let bary = closest_point_barycentric(x, &t);
            let p = barycentric_point(&t, bary);
            let d = norm(sub(p, x));
            if d < best.0 {
                best = (d, SurfacePoint { face: f, bary }, p);
            }
        }
        (best.1, best.2)
    }
}

/// A place where the map is not a valid integer-grid map and what the
/// extractor did there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct QuadDefect {
    /// Input face where it was found.
    pub face: u32,
    /// What went wrong and what was done, in a sentence.
    pub what: String,
}

impl QuadMesh {
    /// Removes the quads `q` with `remove[q]` and their corner UVs, keeping
    /// the others in order (the vertices stay).
    pub(crate) fn remove_quads(&mut self, remove: &[bool]) {
        let mut kept = 0;
        for q in 0..self.quads.len() {
            if !remove[q] {
                self.quads[kept] = self.quads[q];
                for k in 0..4 {
                    self.uv[4 * kept + k] = self.uv[4 * q + k];
                }
                kept += 1;
            }
        }
        self.quads.truncate(kept);
        self.uv.truncate(4 * kept);
    }

    /// The quads at each vertex (a quad twice where it repeats the vertex).
    pub(crate) fn vertex_quads(&self) -> Vec<Vec<u32>> {
        let mut out = vec![Vec::new(); self.positions.len()];
        for (q, corners) in self.quads.iter().enumerate() {
            for &v in corners {
                out[v as usize].push(q as u32);
            }
        }
        out
    }

    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    pub fn n_quads(&self) -> usize {
        self.quads.len()
    }
}
