//! glTF 2.0 import, `.glb` and `.gltf`.
//!
//! The JSON is deserialised with `gltf::json`; everything else (the GLB
//! container, buffer resolution, accessor reading, the scene walk) is done
//! here with explicit range checks, so malformed input gives an
//! [`ImportError`] and never a panic. No filesystem access is needed:
//! external buffers are looked up among the companion files handed in, which
//! keeps the module usable from wasm32.
//!
//! # Vertex order
//!
//! The [`RawMesh`] holds, in this order, the vertices of every triangle
//! primitive reached by the scene walk:
//!
//! * the scene is the default one (`scene`), else scene 0, else (no scenes)
//!   every root node in node-index order;
//! * nodes are walked depth-first, pre-order: a node's own mesh comes before
//!   its children, children in the order listed;
//! * a mesh's primitives come in array order; each contributes *all* the
//!   elements of its POSITION accessor, in accessor order, transformed by the
//!   node's world matrix (so a mesh used by two nodes appears twice);
//! * POINTS and LINE* primitives are skipped and contribute nothing.
//!
//! [`import_with_source`] reports these runs as [`PrimitiveSpan`]s so an
//! exporter can map source vertices back to (node, mesh, primitive, element).
//! Skins and morph targets are ignored: positions are the base positions
//! under the node's world transform.

mod accessor;
mod container;

use super::InputFile;
use crate::{ImportError, RawMesh};
use gltf::json::{self, mesh::Mode, validation::Checked};

pub(crate) const FORMAT: &str = "glTF";

/// Upper bounds on the output, so that a small file instancing a mesh a
/// million times is rejected instead of exhausting memory.
const MAX_VERTICES: usize = 1 << 26;
const MAX_TRIANGLES: usize = 1 << 27;
/// Upper bound on node visits during the scene walk.
const MAX_NODE_VISITS: usize = 1 << 20;

/// One primitive instance of the scene walk: which source it came from and
/// which vertices and triangles of the [`RawMesh`] it produced.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveSpan {
    /// Index of the node in the glTF `nodes` array.
    pub node: u32,
    /// Index of the mesh in the glTF `meshes` array.
    pub mesh: u32,
    /// Index of the primitive in the mesh's `primitives` array.
    pub primitive: u32,
    /// The POSITION accessor; vertex `first_vertex + k` is its element `k`.
    pub position_accessor: u32,
    pub first_vertex: u32,
    pub vertex_count: u32,
    pub first_triangle: u32,
    pub triangle_count: u32,
    /// The node's world matrix, column-major (glTF convention).
    pub world: [f64; 16],
    /// True when the world matrix has a negative determinant, in which case
    /// every triangle's winding was reversed (second and third index swapped).
    pub mirrored: bool,
}

/// Provenance of an imported glTF mesh: the primitive instances in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfSource {
    pub spans: Vec<PrimitiveSpan>,
}

impl GltfSource {
    /// The span holding source vertex `v`, if any.
    pub fn span_of_vertex(&self, v: u32) -> Option<&PrimitiveSpan> {
        let i = self
            .spans
            .partition_point(|s| s.first_vertex + s.vertex_count <= v);
        self.spans
            .get(i)
            .filter(|s| s.first_vertex <= v && v < s.first_vertex + s.vertex_count)
    }
}

/// Imports every triangle primitive of the default scene, node transforms
/// applied (see the module documentation for the vertex order).
pub fn import(file: &InputFile, others: &[InputFile]) -> Result<RawMesh, ImportError> {
    import_with_source(file, others).map(|(mesh, _)| mesh)
}

/// Like [`import`], also returning where each run of vertices came from.
pub fn import_with_source(
    file: &InputFile,
    others: &[InputFile],
) -> Result<(RawMesh, GltfSource), ImportError> {
    let doc = container::parse(file)?;
    let mut buffers = container::Buffers::new(&doc, others);
    let mut walk = Walk {
        root: &doc.root,
        buffers: &mut buffers,
        mesh: RawMesh::default(),
        source: GltfSource::default(),
    };
    for (node, world) in scene_nodes(&doc.root)? {
        walk.node_geometry(node, &world)?;
    }
    let Walk { mesh, source, .. } = walk;
    if mesh.triangles.is_empty() {
        return Err(ImportError::NoTriangles {
            name: file.name.clone(),
        });
    }
    Ok((mesh, source))
}

/// For a `.gltf` (or `.glb`) on disk, reads the external buffers its JSON
/// names, relative to the file's directory (native only). Each returned
/// [`InputFile`] is named by the percent-decoded URI. Buffers whose file
/// cannot be read are left out, so [`import`] reports
/// [`ImportError::MissingBuffer`] only if the geometry actually needs them.
/// Files that are not glTF give an empty list.
#[cfg(not(target_arch = "wasm32"))]
pub fn sibling_buffers(
    path: &std::path::Path,
    main: &InputFile,
) -> Result<Vec<InputFile>, ImportError> {
    let lower = main.name.to_ascii_lowercase();
    if !(container::is_glb(&main.bytes) || lower.ends_with(".gltf")) || main.bytes.is_empty() {
        return Ok(Vec::new());
    }
    let doc = container::parse(main)?;
    let dir = path.parent().unwrap_or_else(|| std::path::Path::new(""));
    let mut out: Vec<InputFile> = Vec::new();
    for buffer in &doc.root.buffers {
        let Some(uri) = buffer.uri.as_deref() else {
            continue;
        };
        if container::is_data_uri(uri) || uri.contains("://") {
            continue;
        }
        let rel = container::percent_decode(uri);
        if out.iter().any(|f| f.name == rel) {
            continue;
        }
        if let Ok(bytes) = std::fs::read(dir.join(&rel)) {
            out.push(InputFile { name: rel, bytes });
        }
    }
    Ok(out)
}

type Mat4 = [f64; 16];

const IDENTITY: Mat4 = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

/// Column-major product `a * b`.
fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    if *a == IDENTITY {
        return *b;
    }
    if *b == IDENTITY {
        return *a;
    }
    let mut m = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            m[c * 4 + r] = (0..4).map(|k| a[k * 4 + r] * b[c * 4 + k]).sum();
        }
    }
    m
}

/// The node's local matrix: `matrix` if given, else `T * R * S`, in f64.
fn local_matrix(node: &json::Node) -> Mat4 {
    if let Some(m) = node.matrix {
        return m.map(f64::from);
    }
    let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
    let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
    let q = node
        .rotation
        .map_or([0.0, 0.0, 0.0, 1.0], |r| r.0)
        .map(f64::from);
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [x, y, z, w] = if norm > 0.0 && norm.is_finite() {
        q.map(|c| c / norm)
    } else {
        [0.0, 0.0, 0.0, 1.0]
    };
    let r = if [x, y, z] == [0.0; 3] {
        [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    } else {
        // Columns of the rotation matrix.
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + z * w),
            2.0 * (x * z - y * w),
            2.0 * (x * y - z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + x * w),
            2.0 * (x * z + y * w),
            2.0 * (y * z - x * w),
            1.0 - 2.0 * (x * x + y * y),
        ]
    };
    let mut m = [0.0; 16];
    for c in 0..3 {
        for row in 0..3 {
            m[c * 4 + row] = r[c * 3 + row] * s[c];
        }
    }
    m[12] = t[0];
    m[13] = t[1];
    m[14] = t[2];
    m[15] = 1.0;
    m
}

fn determinant3(m: &Mat4) -> f64 {
    let a = |c: usize, r: usize| m[c * 4 + r];
    a(0, 0) * (a(1, 1) * a(2, 2) - a(2, 1) * a(1, 2))
        - a(1, 0) * (a(0, 1) * a(2, 2) - a(2, 1) * a(0, 2))
        + a(2, 0) * (a(0, 1) * a(1, 2) - a(1, 1) * a(0, 2))
}

fn transform_point(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    if *m == IDENTITY {
        return p;
    }
    let mut out = [0.0; 3];
    for (r, o) in out.iter_mut().enumerate() {
        *o = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    }
    out
}

/// Every node of the scene to import, with its world matrix, in depth-first
/// pre-order.
fn scene_nodes(root: &json::Root) -> Result<Vec<(usize, Mat4)>, ImportError> {
    let roots: Vec<usize> = if let Some(scene) = root.scene {
        let s = root.scenes.get(scene.value()).ok_or_else(|| {
            container::malformed(format!(
                "default scene {} does not exist ({} scenes)",
                scene.value(),
                root.scenes.len()
            ))
        })?;
        s.nodes.iter().map(|n| n.value()).collect()
    } else if let Some(s) = root.scenes.first() {
        s.nodes.iter().map(|n| n.value()).collect()
    } else {
        let mut is_child = vec![false; root.nodes.len()];
        for node in &root.nodes {
            for c in node.children.iter().flatten() {
                if let Some(flag) = is_child.get_mut(c.value()) {
                    *flag = true;
                }
            }
        }
        (0..root.nodes.len()).filter(|&i| !is_child[i]).collect()
    };
    let mut out = Vec::new();
    // (node, parent world matrix, depth); processed in reverse push order.
    let mut stack: Vec<(usize, Mat4, usize)> =
        roots.iter().rev().map(|&n| (n, IDENTITY, 0)).collect();
    while let Some((n, parent, depth)) = stack.pop() {
        let node = root.nodes.get(n).ok_or_else(|| {
            container::malformed(format!(
                "node {n} does not exist ({} nodes)",
                root.nodes.len()
            ))
        })?;
        // A path longer than the node count must repeat a node.
        if depth > root.nodes.len() {
            return Err(container::malformed(format!(
                "node {n} is part of a cycle in the node hierarchy"
            )));
        }
        if out.len() >= MAX_NODE_VISITS {
            return Err(container::malformed(
                "the node hierarchy is too large (more than 2^20 node visits)",
            ));
        }
        let world = mul(&parent, &local_matrix(node));
        out.push((n, world));
        for c in node.children.iter().flatten().rev() {
            stack.push((c.value(), world, depth + 1));
        }
    }
    Ok(out)
}

struct Walk<'r, 'b, 'a> {
    root: &'r json::Root,
    buffers: &'b mut container::Buffers<'a>,
    mesh: RawMesh,
    source: GltfSource,
}

impl Walk<'_, '_, '_> {
    fn node_geometry(&mut self, node_index: usize, world: &Mat4) -> Result<(), ImportError> {
        let root = self.root;
        let Some(mesh_index) = root.nodes[node_index].mesh.map(|m| m.value()) else {
            return Ok(());
        };
        let mesh = root.meshes.get(mesh_index).ok_or_else(|| {
            container::malformed(format!(
                "node {node_index}: mesh {mesh_index} does not exist ({} meshes)",
                root.meshes.len()
            ))
        })?;
        let mirrored = determinant3(world) < 0.0;
        for (prim_index, prim) in mesh.primitives.iter().enumerate() {
            let here = format!("mesh {mesh_index} primitive {prim_index}");
            let mode = match prim.mode {
                Checked::Valid(m) => m,
                Checked::Invalid => {
                    return Err(container::malformed(format!("{here}: invalid mode")))
                }
            };
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                continue;
            }
            let pos_acc = *prim
                .attributes
                .get(&Checked::Valid(json::mesh::Semantic::Positions))
                .ok_or_else(|| container::malformed(format!("{here}: no POSITION attribute")))?;
            let positions = accessor::read_positions(root, self.buffers, pos_acc)?;
            let n = positions.len();
            let indices = match prim.indices {
                Some(acc) => {
                    let idx = accessor::read_indices(root, self.buffers, acc)?;
                    if let Some((k, &v)) = idx.iter().enumerate().find(|(_, &v)| v as usize >= n) {
                        return Err(container::malformed(format!(
                            "accessor {} (indices of {here}): element {k} is vertex {v}, out of range of \
                             POSITION accessor {} with {n} vertices",
                            acc.value(),
                            pos_acc.value()
                        )));
                    }
                    idx
                }
                None => (0..n as u32).collect(),
            };
            let tris = assemble(mode, &indices).map_err(|count| {
                let what = match prim.indices {
                    Some(acc) => format!(
                        "accessor {} (indices of {here}) has {count} elements",
                        acc.value()
                    ),
                    None => format!(
                        "POSITION accessor {} of non-indexed {here} has {count} vertices",
                        pos_acc.value()
                    ),
                };
                container::malformed(format!("{what}, not a multiple of 3 for TRIANGLES"))
            })?;
            let base = self.mesh.positions.len();
            if base + n > MAX_VERTICES || self.mesh.triangles.len() + tris.len() > MAX_TRIANGLES {
                return Err(container::malformed(format!(
                    "the scene is too large (over {MAX_VERTICES} vertices or {MAX_TRIANGLES} triangles)"
                )));
            }
            let first_triangle = self.mesh.triangles.len();
            self.mesh
                .positions
                .extend(positions.into_iter().map(|p| transform_point(world, p)));
            let b = base as u32;
            self.mesh
                .triangles
                .extend(tris.into_iter().map(|[i, j, k]| {
                    if mirrored {
                        [b + i, b + k, b + j]
                    } else {
                        [b + i, b + j, b + k]
                    }
                }));
            self.source.spans.push(PrimitiveSpan {
                node: node_index as u32,
                mesh: mesh_index as u32,
                primitive: prim_index as u32,
                position_accessor: pos_acc.value() as u32,
                first_vertex: b,
                vertex_count: n as u32,
                first_triangle: first_triangle as u32,
                triangle_count: (self.mesh.triangles.len() - first_triangle) as u32,
                world: *world,
                mirrored,
            });
        }
        Ok(())
    }
}

/// Turns an index list into triangles for a triangle `mode`. TRIANGLES needs
/// a multiple of 3 indices (else `Err(count)`); strips alternate winding so
/// every triangle has the orientation of the first, and strip triangles that
/// repeat an index (the degenerate joins between strips) are dropped; fans
/// yield `(v0, v[i+1], v[i+2])`.
fn assemble(mode: Mode, idx: &[u32]) -> Result<Vec<[u32; 3]>, usize> {
    match mode {
        Mode::Triangles => {
            if !idx.len().is_multiple_of(3) {
                return Err(idx.len());
            }
            Ok(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        }
        Mode::TriangleStrip => Ok((0..idx.len().saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i], idx[i + 2], idx[i + 1]]
                }
            })
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect()),
        Mode::TriangleFan => Ok((1..idx.len().saturating_sub(1))
            .map(|i| [idx[0], idx[i], idx[i + 1]])
            .collect()),
        _ => Ok(Vec::new()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strip_alternates_and_drops_degenerates() {
        let t = assemble(Mode::TriangleStrip, &[0, 1, 2, 3, 4]).unwrap();
        assert_eq!(t, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
        // Two strips joined by repeating 2 and 3: only real triangles survive;
        // the second starts at an odd position, so its winding is reversed.
        let t = assemble(Mode::TriangleStrip, &[0, 1, 2, 2, 3, 3, 4, 5]).unwrap();
        assert_eq!(t, vec![[0, 1, 2], [3, 5, 4]]);
        // With one more repeat the second strip starts at an even position.
        let t = assemble(Mode::TriangleStrip, &[0, 1, 2, 2, 3, 3, 3, 4, 5]).unwrap();
        assert_eq!(t, vec![[0, 1, 2], [3, 4, 5]]);
        assert!(assemble(Mode::TriangleStrip, &[0, 1]).unwrap().is_empty());
    }

    #[test]
    fn fan_and_triangles() {
        assert_eq!(
            assemble(Mode::TriangleFan, &[0, 1, 2, 3]).unwrap(),
            vec![[0, 1, 2], [0, 2, 3]]
        );
        assert_eq!(
            assemble(Mode::Triangles, &[0, 1, 2, 2, 1, 3]).unwrap(),
            vec![[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(assemble(Mode::Triangles, &[0, 1, 2, 3]), Err(4));
        assert!(assemble(Mode::Lines, &[0, 1]).unwrap().is_empty());
    }

    #[test]
    fn trs_composition() {
        let node: json::Node = json::deserialize::from_str(
            r#"{"translation":[1,2,3],"rotation":[0,0,1,0],"scale":[2,2,2]}"#,
        )
        .unwrap();
        let m = local_matrix(&node);
        // 180° about z, scale 2, then translate.
        assert_eq!(transform_point(&m, [1.0, 0.0, 0.0]), [-1.0, 2.0, 3.0]);
        assert_eq!(transform_point(&m, [0.0, 1.0, 1.0]), [1.0, 0.0, 5.0]);
        assert!(determinant3(&m) > 0.0);
        let mirror: json::Node = json::deserialize::from_str(r#"{"scale":[-1,1,1]}"#).unwrap();
        assert!(determinant3(&local_matrix(&mirror)) < 0.0);
        let mat: json::Node =
            json::deserialize::from_str(r#"{"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 5,6,7,1]}"#)
                .unwrap();
        assert_eq!(
            transform_point(&local_matrix(&mat), [1.0, 1.0, 1.0]),
            [6.0, 7.0, 8.0]
        );
    }

    #[test]
    fn span_lookup() {
        let span = |first_vertex, vertex_count| PrimitiveSpan {
            node: 0,
            mesh: 0,
            primitive: 0,
            position_accessor: 0,
            first_vertex,
            vertex_count,
            first_triangle: 0,
            triangle_count: 0,
            world: IDENTITY,
            mirrored: false,
        };
        let src = GltfSource {
            spans: vec![span(0, 3), span(3, 0), span(3, 4)],
        };
        assert_eq!(src.span_of_vertex(2).unwrap().first_vertex, 0);
        assert_eq!(src.span_of_vertex(3).unwrap().vertex_count, 4);
        assert!(src.span_of_vertex(7).is_none());
    }
}
