//! Triangle meshes: the raw soup from a file, welding, validation, the
//! validated manifold [`TriMesh`] with halfedge connectivity, and its
//! geometry (angles, areas, frames, the cotangent Laplacian: `geometry`).
//!
//! Pipeline: [`RawMesh`] → [`weld()`] (connectivity from positions) →
//! [`analyze()`] (figures and [`crate::Problem`]s, never fails) →
//! [`TriMesh::from_raw`] (fails with the blocking problems) → the geometry
//! accessors on [`TriMesh`] (each computed once, on first use).

pub(crate) mod box_grid;
mod decimate;
mod geometry;
mod nearest;
mod problem;
mod raw;
pub mod shapes;
mod subdivide;
mod topology;
mod trimesh;
mod validate;
mod weld;

#[cfg(test)]
mod tests;

pub use decimate::{decimate_interior, decimate_keeping, CollapseLimits, Decimated};
pub use geometry::{wrap_angle, FaceFrames};
pub use nearest::{Nearest, NearestFace};
pub use problem::{ElementNames, FileNames, LocatedProblem, Problem};
pub use raw::RawMesh;
pub use subdivide::subdivide_midpoint;
pub use trimesh::{Outgoing, TriMesh, NONE};
pub use validate::{analyze, analyze_by_index, analyze_located, Located, ZERO_AREA_REL};
pub use weld::{weld, Welded, NO_VERTEX};
pub(crate) use topology::UnionFind;

/// Figures of an imported mesh, computed even when the mesh has problems.
///
/// Vertices are welded vertices referenced by faces. Edges are keyed by welded
/// vertex pair. Components are edge-connected (see [`analyze()`]). A face with
/// an out-of-range index counts in `faces` but is left out of every other figure.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MeshReport {
    /// Welded vertices referenced by faces.
    pub vertices: usize,
    /// Triangles as imported (all of them).
    pub faces: usize,
    /// Boundary loops: boundary edges joined at shared vertices within a component.
    pub boundary_loops: usize,
    /// Edge-connected components.
    pub components: usize,
    /// Components when faces sharing only a vertex also count as connected.
    pub vertex_connected_components: usize,
    /// V − E + F over the whole mesh.
    pub euler_characteristic: i64,
    /// Per component, `(2 − χ − b) / 2` (integer division); meaningful only
    /// where `component_is_manifold`.
    pub genus: Vec<i64>,
    /// Every defect found, grouped by kind in a fixed order (index range,
    /// coordinates, unreferenced, degenerate, zero-length, zero-area, duplicate,
    /// non-manifold edge, non-manifold vertex, orientation), ascending within a kind.
    pub problems: Vec<crate::Problem>,
    /// Source vertices in the file, referenced or not.
    pub source_vertices: usize,
    /// Referenced source vertices merged into another by welding.
    pub merged_vertices: usize,
    /// Undirected edges.
    pub edges: usize,
    /// Edges with exactly one incident face.
    pub boundary_edges: usize,
    /// Edges with more than two incident faces (counting every face).
    pub non_manifold_edges: usize,
    /// Vertices whose faces form more than one fan.
    pub non_manifold_vertices: usize,
    /// V − E + F per component (a non-manifold vertex counts in each component it touches).
    pub euler_characteristic_per_component: Vec<i64>,
    /// Boundary loops per component.
    pub boundary_loops_per_component: Vec<usize>,
    /// Faces per component.
    pub faces_per_component: Vec<usize>,
    /// Per component: no non-manifold edge or vertex, no degenerate or
    /// duplicate face, consistent orientation.
    pub component_is_manifold: Vec<bool>,
}

impl MeshReport {
    /// True when no problem blocks building a [`TriMesh`].
    pub fn is_clean(&self) -> bool {
        !self.problems.iter().any(|p| p.is_blocking())
    }
}
