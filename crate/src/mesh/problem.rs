//! What can be wrong with a mesh: [`Problem`], found by validation.
//!
//! Every variant names the offending element so a user can find it; `Display`
//! gives the one-line message shown by the CLI and the page.

use serde::Serialize;
use std::fmt;

/// A defect found in a mesh. Vertex indices refer to welded vertices unless a
/// field says otherwise; face indices refer to the imported triangles in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Problem {
    /// An edge shared by more than two faces.
    NonManifoldEdge { edge: [u32; 2], faces: Vec<u32> },
    /// A vertex whose faces form more than one fan (a "bow-tie").
    NonManifoldVertex { vertex: u32, fans: u32 },
    /// Two faces share an edge but traverse it in the same direction.
    InconsistentOrientation { edge: [u32; 2], faces: [u32; 2] },
    /// A face with (numerically) zero area but three distinct vertices.
    ZeroAreaFace { face: u32, area: f64 },
    /// An edge whose two distinct end vertices lie at the same point. `edge`
    /// holds SOURCE vertex indices: welding has made both ends one vertex.
    ZeroLengthEdge { edge: [u32; 2], face: u32 },
    /// A face that uses the same vertex twice (a collapsed edge).
    DegenerateFace { face: u32, vertices: [u32; 3] },
    /// Two faces over the same three vertices.
    DuplicateFace { faces: [u32; 2] },
    /// A source vertex that no face uses.
    UnreferencedVertex { vertex: u32 },
    /// A vertex coordinate that is NaN or infinite (source vertex index).
    NonFiniteCoordinate { vertex: u32 },
    /// A face index that points past the vertex list (source indices).
    IndexOutOfRange { face: u32, index: u32, vertex_count: u32 },
}

impl Problem {
    /// True for defects that make the mesh unusable for parametrization;
    /// false for those that are only reported and repaired when the mesh is
    /// built (unreferenced vertices are dropped, a non-manifold vertex is
    /// split into one vertex per fan).
    pub fn is_blocking(&self) -> bool {
        !matches!(self, Problem::UnreferencedVertex { .. } | Problem::NonManifoldVertex { .. })
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::NonManifoldEdge { edge, faces } => write!(
                f,
                "edge (v{}, v{}) has {} faces ({})",
                edge[0],
                edge[1],
                faces.len(),
                list("f", faces)
            ),
            Problem::NonManifoldVertex { vertex, fans } => {
                write!(f, "vertex v{vertex} is non-manifold: its faces form {fans} separate fans (split into {fans} vertices)")
            }
            Problem::InconsistentOrientation { edge, faces } => write!(
                f,
                "faces f{} and f{} are oriented inconsistently across edge (v{}, v{})",
                faces[0], faces[1], edge[0], edge[1]
            ),
            Problem::ZeroAreaFace { face, area } => write!(f, "face f{face} has zero area ({area:e})"),
            Problem::ZeroLengthEdge { edge, face } => {
                write!(f, "edge (v{}, v{}) of face f{face} has zero length", edge[0], edge[1])
            }
            Problem::DegenerateFace { face, vertices } => write!(
                f,
                "face f{face} is degenerate: it uses a vertex twice (v{}, v{}, v{})",
                vertices[0], vertices[1], vertices[2]
            ),
            Problem::DuplicateFace { faces } => {
                write!(f, "faces f{} and f{} are duplicates over the same three vertices", faces[0], faces[1])
            }
            Problem::UnreferencedVertex { vertex } => write!(f, "vertex v{vertex} is not used by any face"),
            Problem::NonFiniteCoordinate { vertex } => {
                write!(f, "vertex v{vertex} has a NaN or infinite coordinate")
            }
            Problem::IndexOutOfRange { face, index, vertex_count } => write!(
                f,
                "face f{face} refers to vertex {index}, but there are only {vertex_count} vertices"
            ),
        }
    }
}

fn list(prefix: &str, items: &[u32]) -> String {
    items.iter().map(|i| format!("{prefix}{i}")).collect::<Vec<_>>().join(", ")
}
