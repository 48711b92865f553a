//! How the input file numbers its vertices and faces: [`FileNumbering`], so
//! that messages about a mesh name its elements as the file does (OBJ: the
//! 1-based `v` and `f` statements; glTF: mesh, primitive and 0-based
//! accessor index).

use super::gltf::GltfSource;

/// The file's own numbering of the imported source vertices and triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum FileNumbering {
    /// Unknown format: 0-based source vertex and triangle indices.
    #[default]
    Indices,
    /// OBJ: vertex `s` is the file's `v` number `s + 1`; triangle `t` comes
    /// from the `f` statement numbered `face_of_triangle[t]` (1-based; a
    /// polygon is fan-triangulated into several triangles).
    Obj { face_of_triangle: Vec<u32> },
    /// glTF: the primitive instances, in source vertex and triangle order.
    Gltf(GltfSource),
}

impl FileNumbering {
    /// Source vertex `s` as the file numbers it: "v57" (OBJ, 1-based),
    /// "vertex 12 of mesh 0 primitive 1" (glTF accessor index), "v56" (0-based).
    pub fn vertex(&self, s: u32) -> String {
        match self {
            FileNumbering::Indices => format!("v{s}"),
            FileNumbering::Obj { .. } => format!("v{}", s as u64 + 1),
            FileNumbering::Gltf(source) => match source.span_of_vertex(s) {
                Some(span) => format!("vertex {} of mesh {} primitive {}", s - span.first_vertex, span.mesh, span.primitive),
                None => format!("vertex {s}"),
            },
        }
    }

    /// Triangle `t` as the file numbers it: "f81" (OBJ: its `f` statement,
    /// 1-based), "triangle 5 of mesh 0 primitive 1" (glTF, 0-based), "f80".
    pub fn face(&self, t: u32) -> String {
        match self {
            FileNumbering::Indices => format!("f{t}"),
            FileNumbering::Obj { face_of_triangle } => match face_of_triangle.get(t as usize) {
                Some(f) => format!("f{f}"),
                None => format!("triangle {t}"),
            },
            FileNumbering::Gltf(source) => {
                let i = source.spans.partition_point(|s| s.first_triangle + s.triangle_count <= t);
                match source.spans.get(i).filter(|s| s.first_triangle <= t) {
                    Some(span) => format!("triangle {} of mesh {} primitive {}", t - span.first_triangle, span.mesh, span.primitive),
                    None => format!("triangle {t}"),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::gltf::PrimitiveSpan;

    #[test]
    fn names_elements_as_the_file_does() {
        let obj = FileNumbering::Obj { face_of_triangle: vec![1, 2, 2] };
        assert_eq!(obj.vertex(0), "v1");
        assert_eq!(obj.face(2), "f2");
        assert_eq!(obj.face(3), "triangle 3");
        let span = |mesh, first_vertex, first_triangle| PrimitiveSpan {
            node: 0, mesh, primitive: 1, position_accessor: 0, first_vertex, vertex_count: 10, first_triangle,
            triangle_count: 4, world: [0.0; 16], mirrored: false,
        };
        let gltf = FileNumbering::Gltf(GltfSource { spans: vec![span(0, 0, 0), span(3, 10, 4)] });
        assert_eq!(gltf.vertex(12), "vertex 2 of mesh 3 primitive 1");
        assert_eq!(gltf.face(5), "triangle 1 of mesh 3 primitive 1");
        assert_eq!(gltf.face(9), "triangle 9");
        assert_eq!(FileNumbering::Indices.vertex(4), "v4");
    }
}
