//! The unvalidated triangle soup every importer produces.

/// Triangle soup exactly as read from a file: no welding, no validation.
///
/// `positions` are the file's vertices in file order (for glTF: every
/// primitive's vertices concatenated in scene traversal order, node transforms
/// applied); indices in `triangles` refer to them. These "source vertices" stay
/// addressable through the whole pipeline so per-vertex attributes (normals,
/// UVs, colours) can be carried to the output.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl RawMesh {
    /// Number of source vertices (referenced or not).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }
}
