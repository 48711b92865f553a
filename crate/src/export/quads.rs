//! Writers of a [`QuadMesh`]:
//!
//! * OBJ: `v` per vertex, `vt` per quad corner (the grid-unit UVs as given)
//!   and `f v/vt` with four corners per quad;
//! * binary glTF 2.0: one mesh with a TRIANGLES primitive (every quad as two
//!   triangles split along its shorter 3D diagonal; POSITION, NORMAL,
//!   TEXCOORD_0, indices) and a LINES primitive (every undirected quad edge
//!   once) over the same POSITION accessor, for a wireframe overlay.
//!
//! Quads with a vertex index out of range are left out of both. When
//! `uv` does not hold one entry per quad corner the UVs are left out too.
//!
//! glTF `TEXCOORD_0 = (u, −v)`: grid units, `t` pointing down as glTF
//! wants, so an image shows the same way as through the OBJ `vt` (the
//! convention of [`crate::export`], without its normalisation: one texture
//! repeat per grid cell).

use super::{generator, pack_glb, GltfBuffer};
use crate::quads::check::quad_edges;
use crate::quads::QuadMesh;
use crate::vec3::{add, cross, norm, sub, V3};
use serde_json::json;
use std::collections::HashMap;
use std::fmt::Write;

const MODE_LINES: u32 = 1;
const MODE_TRIANGLES: u32 = 4;

/// The OBJ text of `quads`: comment lines (the generator, then every line of
/// `header`), `v x y z` per vertex, `vt u v` per quad corner `4 q + i` (when
/// `uv` has one per corner), then `f a/ta b/tb c/tc d/td` per quad, 1-based.
/// Numbers use Rust's shortest round-trip formatting of `f64`, so parsing
/// them back gives the same values bit for bit.
pub fn write_quad_obj(quads: &QuadMesh, header: &str) -> String {
    let with_uv = has_corner_uvs(quads);
    let mut out = String::with_capacity(32 * quads.n_vertices() + 48 * quads.n_quads());
    let _ = writeln!(out, "# {} quad mesh", generator());
    for line in header.lines() {
        let _ = writeln!(out, "# {}", line.replace('\r', " "));
    }
    for p in &quads.positions {
        let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
    }
    if with_uv {
        for t in &quads.uv {
            let _ = writeln!(out, "vt {} {}", t[0], t[1]);
        }
    }
    for (q, quad) in quads.quads.iter().enumerate().filter(|(_, quad)| in_range(quads, quad)) {
        out.push('f');
        for (i, &v) in quad.iter().enumerate() {
            if with_uv {
                let _ = write!(out, " {}/{}", v + 1, 4 * q + i + 1);
            } else {
                let _ = write!(out, " {}", v + 1);
            }
        }
        out.push('\n');
    }
    out
}

/// The binary glTF of `quads` (see the module documentation). Output
/// vertices are the distinct (vertex, corner UV) pairs, so a vertex whose
/// corners carry different UVs is split; NORMAL is the unit area-weighted
/// (Newell) normal of the quads around the vertex. A mesh without quads
/// gives a valid file with no mesh.
pub fn write_quad_glb(quads: &QuadMesh) -> Vec<u8> {
    let layout = GlbLayout::new(quads);
    let mut doc = json!({"asset": {"version": "2.0", "generator": generator()}});
    if layout.triangles.is_empty() {
        return pack_glb(&serde_json::to_vec(&doc).expect("glTF JSON serialises"), None);
    }
    let normals = vertex_normals(quads);
    let mut bin = GltfBuffer::default();
    let positions: Vec<[f32; 3]> =
        layout.wedges.iter().map(|&(v, _)| quads.positions[v as usize].map(|x| x as f32)).collect();
    let normal: Vec<[f32; 3]> = layout.wedges.iter().map(|&(v, _)| normals[v as usize].map(|x| x as f32)).collect();
    let position = bin.floats(&positions, true);
    let mut attributes = json!({"POSITION": position, "NORMAL": bin.floats(&normal, false)});
    if has_corner_uvs(quads) {
        let uv: Vec<[f32; 2]> = layout.wedges.iter().map(|&(_, t)| [t[0] as f32, -t[1] as f32]).collect();
        attributes["TEXCOORD_0"] = json!(bin.floats(&uv, false));
    }
    let n = layout.wedges.len();
    let triangles: Vec<u32> = layout.triangles.iter().flatten().copied().collect();
    let mut primitives = vec![json!({
        "attributes": attributes,
        "indices": bin.indices(&triangles, n),
        "material": 0,
        "mode": MODE_TRIANGLES,
    })];
    if !layout.lines.is_empty() {
        let lines: Vec<u32> = layout.lines.iter().flatten().copied().collect();
        primitives.push(json!({
            "attributes": {"POSITION": position},
            "indices": bin.indices(&lines, n),
            "material": 1,
            "mode": MODE_LINES,
        }));
    }
    bin.pad();
    let name = "conemap quads";
    doc["scene"] = json!(0);
    doc["scenes"] = json!([{"nodes": [0]}]);
    doc["nodes"] = json!([{"mesh": 0, "name": name}]);
    doc["meshes"] = json!([{"name": name, "primitives": primitives}]);
    let matte = |grey: f64| {
        json!({"baseColorFactor": [grey, grey, grey, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0})
    };
    doc["materials"] = json!([
        {"name": "quads", "doubleSided": true, "pbrMetallicRoughness": matte(0.8)},
        {"name": "quad edges", "pbrMetallicRoughness": matte(0.05)},
    ]);
    doc["buffers"] = json!([{"byteLength": bin.data.len()}]);
    doc["bufferViews"] = json!(bin.views);
    doc["accessors"] = json!(bin.accessors);
    pack_glb(&serde_json::to_vec(&doc).expect("glTF JSON serialises"), Some(&bin.data))
}

fn has_corner_uvs(quads: &QuadMesh) -> bool {
    quads.uv.len() == 4 * quads.n_quads()
}

fn in_range(quads: &QuadMesh, quad: &[u32; 4]) -> bool {
    quad.iter().all(|&v| (v as usize) < quads.n_vertices())
}

/// Output vertices and elements of the glTF primitives.
struct GlbLayout {
    /// `(vertex, UV)` per output vertex.
    wedges: Vec<(u32, [f64; 2])>,
    /// Two per quad, over output vertices.
    triangles: Vec<[u32; 3]>,
    /// One per undirected quad edge, over output vertices.
    lines: Vec<[u32; 2]>,
}

impl GlbLayout {
    fn new(quads: &QuadMesh) -> GlbLayout {
        let with_uv = has_corner_uvs(quads);
        let mut index: HashMap<(u32, u64, u64), u32> = HashMap::new();
        let mut wedges = Vec::new();
        // An output vertex of each mesh vertex, for the lines.
        let mut first_wedge = vec![None; quads.n_vertices()];
        let mut triangles = Vec::with_capacity(2 * quads.n_quads());
        for (q, quad) in quads.quads.iter().enumerate().filter(|(_, quad)| in_range(quads, quad)) {
            let corners: [u32; 4] = std::array::from_fn(|i| {
                let v = quad[i];
                let uv = if with_uv { quads.uv[4 * q + i] } else { [0.0, 0.0] };
                // Adding 0.0 turns -0.0 into +0.0, so the two compare equal.
                let key = (v, (uv[0] + 0.0).to_bits(), (uv[1] + 0.0).to_bits());
                let w = *index.entry(key).or_insert_with(|| {
                    wedges.push((v, uv));
                    wedges.len() as u32 - 1
                });
                first_wedge[v as usize].get_or_insert(w);
                w
            });
            let p = quad.map(|v| quads.positions[v as usize]);
            let [a, b, c, d] = if norm(sub(p[2], p[0])) <= norm(sub(p[3], p[1])) {
                corners
            } else {
                [corners[1], corners[2], corners[3], corners[0]]
            };
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
        let lines = quad_edges(quads)
            .iter()
            .filter_map(|e| Some([first_wedge[e.vertices[0] as usize]?, first_wedge[e.vertices[1] as usize]?]))
            .collect();
        GlbLayout { wedges, triangles, lines }
    }
}

/// Unit area-weighted vertex normals: the sum of the Newell normals (twice
/// the area) of the quads (indices in range) around each vertex; `[0, 0, 1]`
/// where they cancel or the vertex has no quad.
fn vertex_normals(quads: &QuadMesh) -> Vec<V3> {
    let mut n = vec![[0.0; 3]; quads.n_vertices()];
    for quad in quads.quads.iter().filter(|quad| in_range(quads, quad)) {
        let p = quad.map(|v| quads.positions[v as usize]);
        let newell = (0..4).fold([0.0; 3], |s, i| add(s, cross(p[i], p[(i + 1) % 4])));
        for &v in quad {
            n[v as usize] = add(n[v as usize], newell);
        }
    }
    n.into_iter()
        .map(|v| {
            let len = norm(v);
            if len > 0.0 && len.is_finite() {
                v.map(|x| x / len)
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use gltf::mesh::Mode;

    /// An `nx × ny` grid of unit quads in the plane z = 0 (vertex `(i, j)` =
    /// `j (nx + 1) + i`), corner UVs the grid coordinates.
    fn grid(nx: u32, ny: u32) -> QuadMesh {
        let id = |i: u32, j: u32| j * (nx + 1) + i;
        let mut mesh = QuadMesh::default();
        for j in 0..=ny {
            for i in 0..=nx {
                // Irrational offsets: f32 text would not round-trip these.
                mesh.positions.push([i as f64 + 2f64.sqrt() * 1e-7, j as f64 / 3.0, 0.0]);
            }
        }
        for j in 0..ny {
            for i in 0..nx {
                mesh.quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                let (u, v) = (i as f64, j as f64);
                mesh.uv.extend([[u, v], [u + 1.0, v], [u + 1.0, v + 1.0], [u, v + 1.0]]);
            }
        }
        mesh
    }

    /// The numbers after the keyword of every line starting with `keyword `.
    fn records<'a>(obj: &'a str, keyword: &'a str) -> impl Iterator<Item = Vec<&'a str>> + 'a {
        obj.lines().filter_map(move |l| l.strip_prefix(keyword)?.strip_prefix(' ').map(|r| r.split(' ').collect()))
    }

    #[test]
    fn obj_round_trips_positions_uvs_and_quads() {
        let mesh = grid(3, 2);
        let obj = write_quad_obj(&mesh, "first line\nsecond line");
        assert!(obj.lines().take(3).all(|l| l.starts_with("# ")));
        assert!(obj.lines().nth(2).is_some_and(|l| l == "# second line"));
        let number = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN);
        let v: Vec<V3> = records(&obj, "v").map(|r| std::array::from_fn(|i| number(r[i]))).collect();
        assert_eq!(v, mesh.positions);
        let vt: Vec<[f64; 2]> = records(&obj, "vt").map(|r| [number(r[0]), number(r[1])]).collect();
        assert_eq!(vt, mesh.uv);
        let faces: Vec<Vec<&str>> = records(&obj, "f").collect();
        assert_eq!(faces.len(), 6);
        for (q, f) in faces.iter().enumerate() {
            assert_eq!(f.len(), 4);
            for (i, corner) in f.iter().enumerate() {
                assert_eq!(*corner, format!("{}/{}", mesh.quads[q][i] + 1, 4 * q + i + 1));
            }
        }
    }

    #[test]
    fn obj_without_corner_uvs_has_plain_faces_and_skips_broken_quads() {
        let mut mesh = grid(2, 1);
        mesh.uv.clear();
        mesh.quads.push([0, 1, 2, 100]);
        let obj = write_quad_obj(&mesh, "");
        assert_eq!(records(&obj, "vt").count(), 0);
        let faces: Vec<Vec<&str>> = records(&obj, "f").collect();
        assert_eq!(faces, vec![vec!["1", "2", "5", "4"], vec!["2", "3", "6", "5"]]);
    }

    /// The parsed document and its binary chunk.
    fn parse(bytes: &[u8]) -> (gltf::Document, Vec<u8>) {
        let g = gltf::Gltf::from_slice(bytes).expect("the writer's GLB is valid glTF");
        let blob = g.blob.clone().unwrap_or_default();
        (g.document, blob)
    }

    #[test]
    fn glb_has_two_triangles_per_quad_and_one_line_per_edge() {
        let mesh = grid(3, 2);
        let bytes = write_quad_glb(&mesh);
        assert_eq!(u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, bytes.len());
        let (doc, blob) = parse(&bytes);
        let m = doc.meshes().next().expect("one mesh");
        let prims: Vec<gltf::Primitive> = m.primitives().collect();
        assert_eq!(prims.len(), 2);
        let (tri, lines) = (&prims[0], &prims[1]);
        assert_eq!((tri.mode(), lines.mode()), (Mode::Triangles, Mode::Lines));
        let pos = tri.get(&gltf::Semantic::Positions).expect("POSITION");
        assert_eq!(lines.get(&gltf::Semantic::Positions).map(|a| a.index()), Some(pos.index()));
        assert!(pos.min().is_some() && pos.max().is_some());
        // The grid has one UV per vertex, so no vertex is split.
        assert_eq!(pos.count(), mesh.n_vertices());
        assert_eq!(tri.indices().map(|a| a.count()), Some(3 * 2 * 6));
        // 3 × 2 grid: 3·3 horizontal + 4·2 vertical edges.
        assert_eq!(lines.indices().map(|a| a.count()), Some(2 * 17));
        let reader = tri.reader(|_| Some(&blob[..]));
        let normals: Vec<[f32; 3]> = reader.read_normals().map(|n| n.collect()).unwrap_or_default();
        assert_eq!(normals.len(), mesh.n_vertices());
        assert!(normals.iter().all(|n| *n == [0.0, 0.0, 1.0]));
        let uv: Vec<[f32; 2]> = reader.read_tex_coords(0).map(|t| t.into_f32().collect()).unwrap_or_default();
        let positions: Vec<[f32; 3]> = reader.read_positions().map(|p| p.collect()).unwrap_or_default();
        for (t, p) in uv.iter().zip(&positions) {
            // Vertex (i, j) has UV (i, j): stored as (i, −j).
            assert_eq!(t[0], p[0].round());
            assert_eq!(t[1], -(3.0 * p[1]).round());
        }
    }

    #[test]
    fn glb_splits_vertices_at_uv_seams_and_quads_along_the_shorter_diagonal() {
        // Two quads sharing an edge, the second one's UVs shifted: the two
        // shared vertices are split. The top row is sheared by +1 in x, so
        // each quad is a parallelogram with the short diagonal 1–3.
        let mut mesh = grid(2, 1);
        for p in &mut mesh.positions[3..] {
            p[0] += 1.0;
        }
        for t in &mut mesh.uv[4..] {
            t[0] += 10.0;
        }
        let (doc, blob) = parse(&write_quad_glb(&mesh));
        let m = doc.meshes().next().expect("one mesh");
        let tri = m.primitives().next().expect("triangles");
        assert_eq!(tri.get(&gltf::Semantic::Positions).map(|a| a.count()), Some(8));
        let reader = tri.reader(|_| Some(&blob[..]));
        let indices: Vec<u32> = reader.read_indices().map(|i| i.into_u32().collect()).unwrap_or_default();
        // Output vertices 0..4 are the first quad's corners in order.
        assert_eq!(&indices[..6], &[1, 2, 3, 1, 3, 0]);
        let lines = m.primitives().nth(1).expect("lines");
        assert_eq!(lines.indices().map(|a| a.count()), Some(2 * 7));
    }

    #[test]
    fn glb_of_no_quads_is_valid_and_empty() {
        let (doc, _) = parse(&write_quad_glb(&QuadMesh::default()));
        assert_eq!(doc.meshes().count(), 0);
    }
}
