//! Triangle meshes: the raw soup from a file, welding, validation, and the
//! validated manifold [`TriMesh`] with halfedge connectivity.

mod raw;

pub use raw::RawMesh;

// OWNER: mesh-core helper. Modules to add here: weld, topology (halfedges,
// boundary loops, components, Euler characteristic, genus), validate (problems),
// report (MeshReport), trimesh (TriMesh).

/// Figures of an imported mesh, computed even when the mesh has problems.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MeshReport {
    pub vertices: usize,
    pub faces: usize,
    pub boundary_loops: usize,
    pub components: usize,
    pub euler_characteristic: i64,
    pub genus: Vec<i64>,
    pub problems: Vec<crate::Problem>,
}

/// A validated, manifold, consistently oriented triangle mesh (placeholder).
pub struct TriMesh;
