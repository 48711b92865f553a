//! What can be wrong with a mesh: [`Problem`], found by validation.
//!
//! Every variant names the offending element so a user can find it; `Display`
//! gives the one-line message shown by the CLI and the page.

use super::{RawMesh, Welded};
use crate::io::FileNumbering;
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

impl Problem {
    /// The variant's name as serialized (`kind`): "non_manifold_edge", ….
    pub fn kind(&self) -> &'static str {
        match self {
            Problem::NonManifoldEdge { .. } => "non_manifold_edge",
            Problem::NonManifoldVertex { .. } => "non_manifold_vertex",
            Problem::InconsistentOrientation { .. } => "inconsistent_orientation",
            Problem::ZeroAreaFace { .. } => "zero_area_face",
            Problem::ZeroLengthEdge { .. } => "zero_length_edge",
            Problem::DegenerateFace { .. } => "degenerate_face",
            Problem::DuplicateFace { .. } => "duplicate_face",
            Problem::UnreferencedVertex { .. } => "unreferenced_vertex",
            Problem::NonFiniteCoordinate { .. } => "non_finite_coordinate",
            Problem::IndexOutOfRange { .. } => "index_out_of_range",
        }
    }

    /// The one-line message with the elements named by `names` (the
    /// file's numbering, see [`FileNames`]; `Display` uses 0-based indices).
    pub fn message(&self, names: &dyn ElementNames) -> String {
        let (w, s, f) = (|v, face| names.welded_vertex(v, face), |v| names.source_vertex(v), |t| names.face(t));
        match self {
            Problem::NonManifoldEdge { edge, faces } => {
                let first = faces.first().copied();
                let listed: Vec<String> = faces.iter().map(|&t| f(t)).collect();
                format!("edge ({}, {}) has {} faces ({})", w(edge[0], first), w(edge[1], first), faces.len(), listed.join(", "))
            }
            Problem::NonManifoldVertex { vertex, fans } => {
                format!("vertex {} is non-manifold: its faces form {fans} separate fans (split into {fans} vertices)", w(*vertex, None))
            }
            Problem::InconsistentOrientation { edge, faces } => format!(
                "faces {} and {} are oriented inconsistently across edge ({}, {})",
                f(faces[0]),
                f(faces[1]),
                w(edge[0], Some(faces[0])),
                w(edge[1], Some(faces[0]))
            ),
            Problem::ZeroAreaFace { face, area } => format!("face {} has zero area ({area:e})", f(*face)),
            Problem::ZeroLengthEdge { edge, face } => {
                format!("edge ({}, {}) of face {} has zero length", s(edge[0]), s(edge[1]), f(*face))
            }
            Problem::DegenerateFace { face, vertices } => format!(
                "face {} is degenerate: it uses a vertex twice ({}, {}, {})",
                f(*face),
                w(vertices[0], Some(*face)),
                w(vertices[1], Some(*face)),
                w(vertices[2], Some(*face))
            ),
            Problem::DuplicateFace { faces } => {
                format!("faces {} and {} are duplicates over the same three vertices", f(faces[0]), f(faces[1]))
            }
            Problem::UnreferencedVertex { vertex } => format!("vertex {} is not used by any face", s(*vertex)),
            Problem::NonFiniteCoordinate { vertex } => format!("vertex {} has a NaN or infinite coordinate", s(*vertex)),
            Problem::IndexOutOfRange { face, index, vertex_count } => {
                format!("face {} refers to vertex {}, but there are only {vertex_count} vertices", f(*face), s(*index))
            }
        }
    }

    /// The elements the problem names, in the analysed mesh's ids:
    /// `(welded vertices, edges as welded vertex pairs, triangles)`;
    /// `source_to_welded` maps the source vertices some variants name.
    pub fn elements(&self, source_to_welded: &[u32]) -> (Vec<u32>, Vec<[u32; 2]>, Vec<u32>) {
        let welded = |s: u32| source_to_welded.get(s as usize).copied().filter(|&v| v != super::NO_VERTEX);
        match self {
            Problem::NonManifoldEdge { edge, faces } => (edge.to_vec(), vec![*edge], faces.clone()),
            Problem::NonManifoldVertex { vertex, .. } => (vec![*vertex], vec![], vec![]),
            Problem::InconsistentOrientation { edge, faces } => (edge.to_vec(), vec![*edge], faces.to_vec()),
            Problem::ZeroAreaFace { face, .. } => (vec![], vec![], vec![*face]),
            Problem::ZeroLengthEdge { edge, face } => (edge.iter().filter_map(|&s| welded(s)).take(1).collect(), vec![], vec![*face]),
            Problem::DegenerateFace { face, vertices } => (vertices.to_vec(), vec![], vec![*face]),
            Problem::DuplicateFace { faces } => (vec![], vec![], faces.to_vec()),
            Problem::UnreferencedVertex { .. } => (vec![], vec![], vec![]),
            Problem::NonFiniteCoordinate { vertex } => (welded(*vertex).into_iter().collect(), vec![], vec![]),
            Problem::IndexOutOfRange { face, .. } => (vec![], vec![], vec![*face]),
        }
    }
}

/// How a message names the mesh elements a [`Problem`] holds.
pub trait ElementNames {
    /// Welded vertex `v`, as a corner of triangle `face` when given (a
    /// welded vertex may stand for several source vertices).
    fn welded_vertex(&self, v: u32, face: Option<u32>) -> String;
    /// Source vertex `s`.
    fn source_vertex(&self, s: u32) -> String;
    /// Triangle `t`.
    fn face(&self, t: u32) -> String;
}

/// 0-based indices, as the problem holds them: "v56", "f80".
struct Indices;

impl ElementNames for Indices {
    fn welded_vertex(&self, v: u32, _face: Option<u32>) -> String {
        format!("v{v}")
    }
    fn source_vertex(&self, s: u32) -> String {
        format!("v{s}")
    }
    fn face(&self, t: u32) -> String {
        format!("f{t}")
    }
}

/// The file's own numbering ([`FileNumbering`]): a welded vertex is named by
/// the source vertex at that corner of the face named with it (else its
/// representative), then as the file numbers it.
pub struct FileNames<'a> {
    pub raw: &'a RawMesh,
    pub welded: &'a Welded,
    pub numbering: &'a FileNumbering,
}

impl ElementNames for FileNames<'_> {
    fn welded_vertex(&self, v: u32, face: Option<u32>) -> String {
        let corner = face.and_then(|t| {
            let (src, w) = (self.raw.triangles.get(t as usize)?, self.welded.triangles.get(t as usize)?);
            (0..3).find(|&k| w[k] == v).map(|k| src[k])
        });
        match corner.or_else(|| self.welded.welded_to_source.get(v as usize).copied()) {
            Some(s) => self.numbering.vertex(s),
            None => format!("welded vertex {v}"),
        }
    }
    fn source_vertex(&self, s: u32) -> String {
        self.numbering.vertex(s)
    }
    fn face(&self, t: u32) -> String {
        self.numbering.face(t)
    }
}

/// A problem as the page shows it: its kind, its message in the file's
/// numbering, whether it blocks parametrization, and the elements it names
/// in the analysed mesh's ids (welded vertices, edges as vertex pairs
/// flattened, triangles) for drawing them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocatedProblem {
    pub kind: &'static str,
    pub message: String,
    pub blocking: bool,
    pub vertices: Vec<u32>,
    pub edges: Vec<u32>,
    pub faces: Vec<u32>,
}

impl LocatedProblem {
    /// `p` located on the mesh `names` describes.
    pub fn new(p: &Problem, names: &FileNames) -> LocatedProblem {
        let (vertices, edges, faces) = p.elements(&names.welded.source_to_welded);
        LocatedProblem {
            kind: p.kind(),
            message: p.message(names),
            blocking: p.is_blocking(),
            vertices,
            edges: edges.into_iter().flatten().collect(),
            faces,
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(&Indices))
    }
}
