//! Export: GLB / glTF / OBJ writers on small meshes with synthetic seams,
//! read back through conemap's own importers and the `gltf` crate.

use conemap::export::{self, ExportError, ExportInput, ExportOptions, Format, UvNormalization};
use conemap::io::gltf::{import, import_with_source};
use conemap::io::{obj, InputFile};
use conemap::{RawMesh, TriMesh};
use serde_json::{json, Value};
use std::collections::HashSet;

/// A unit cube with shared corners, 12 outward triangles.
fn cube() -> RawMesh {
    let mut positions = Vec::new();
    for i in 0..8u32 {
        positions.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    }
    // Quads (counter-clockwise seen from outside), split along their first diagonal.
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let mut triangles = Vec::new();
    for q in quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    RawMesh { positions, triangles }
}

/// Per-corner UVs: each side projected on its plane, sides placed side by
/// side along u (offset 2 per side), so every side is its own chart.
fn cube_uv(raw: &RawMesh) -> Vec<[f64; 2]> {
    let mut uv = Vec::new();
    for (f, t) in raw.triangles.iter().enumerate() {
        let side = f / 2;
        let axis = side / 2; // 0,1: z  2,3: y  4,5: x
        for &v in t {
            let p = raw.positions[v as usize];
            let (a, b) = match axis {
                0 => (p[0], p[1]),
                1 => (p[0], p[2]),
                _ => (p[1], p[2]),
            };
            uv.push([a + 2.0 * side as f64, 0.5 * b - 3.0]);
        }
    }
    uv
}

/// A flat n × n grid of quads with planar UVs (no seam at all).
fn grid(n: u32) -> (RawMesh, Vec<[f64; 2]>) {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f64 * 0.1, j as f64 * 0.1, (i * j) as f64 * 0.01]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let raw = RawMesh { positions, triangles };
    let uv = raw
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| [raw.positions[v as usize][0], raw.positions[v as usize][1]]))
        .collect();
    (raw, uv)
}

/// Distinct (welded vertex, uv) pairs, computed independently of the writer.
fn distinct_wedges(mesh: &TriMesh, uv: &[[f64; 2]]) -> usize {
    let mut set = HashSet::new();
    for (f, t) in mesh.faces().iter().enumerate() {
        for k in 0..3 {
            let p = uv[3 * f + k];
            set.insert((t[k], p[0].to_bits(), p[1].to_bits()));
        }
    }
    set.len()
}

/// Per output corner: (position, TEXCOORD_0, NORMAL) read with the `gltf` crate;
/// also the primitive count and the vertex count summed over primitives.
struct Read {
    corners: Vec<([f32; 3], [f32; 2], [f32; 3])>,
    primitives: usize,
    vertices: usize,
    json: Value,
}

fn read_gltf(bytes: &[u8]) -> Read {
    let g = gltf::Gltf::from_slice(bytes).expect("the gltf crate parses and validates the output");
    let buffers: Vec<Vec<u8>> = g
        .buffers()
        .map(|b| match b.source() {
            gltf::buffer::Source::Bin => g.blob.clone().expect("GLB has a BIN chunk"),
            gltf::buffer::Source::Uri(uri) => {
                use base64::Engine;
                let b64 = uri.split_once(";base64,").expect("data URI").1;
                base64::engine::general_purpose::STANDARD.decode(b64).unwrap()
            }
        })
        .collect();
    let mut out = Read { corners: Vec::new(), primitives: 0, vertices: 0, json: Value::Null };
    for mesh in g.meshes() {
        for prim in mesh.primitives() {
            out.primitives += 1;
            let r = prim.reader(|b| Some(&buffers[b.index()][..]));
            let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
            let nor: Vec<[f32; 3]> = r.read_normals().unwrap().collect();
            let tex: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
            assert_eq!(pos.len(), nor.len());
            assert_eq!(pos.len(), tex.len());
            out.vertices += pos.len();
            for i in r.read_indices().unwrap().into_u32() {
                let i = i as usize;
                out.corners.push((pos[i], tex[i], nor[i]));
            }
        }
    }
    let json_bytes = if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        bytes[20..20 + len].to_vec()
    } else {
        bytes.to_vec()
    };
    out.json = serde_json::from_slice(&json_bytes).unwrap();
    out
}

fn f32s<const N: usize>(a: [f64; N]) -> [f32; N] {
    a.map(|x| x as f32)
}

#[test]
fn glb_round_trip_splits_exactly_at_seams() {
    let raw = cube();
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let uv = cube_uv(&raw);
    let input = ExportInput::new(&raw, &mesh, &uv).unwrap();
    let glb = export::write_glb(&input, &ExportOptions::default());
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(glb.len() % 4, 0);

    // conemap's own importer: same triangle count, same positions (f32).
    let back = import(&InputFile { name: "cube.glb".into(), bytes: glb.clone() }, &[]).unwrap();
    assert_eq!(back.triangles.len(), raw.triangles.len());
    for (t_out, t_in) in back.triangles.iter().zip(&raw.triangles) {
        for k in 0..3 {
            let p_in = f32s(raw.positions[t_in[k] as usize]).map(f64::from);
            assert_eq!(back.positions[t_out[k] as usize], p_in);
        }
    }
    // 6 sides × 4 corners: split along every cube edge (all are seams here).
    assert_eq!(distinct_wedges(&mesh, &uv), 24);
    assert_eq!(back.positions.len(), 24);
    assert_eq!(input.output_vertex_count(&ExportOptions::default()), 24);

    // TEXCOORD_0 = (u', 1 − v') with the documented normalisation.
    let norm = UvNormalization::of(&uv);
    assert_eq!(norm.offset, [0.0, -3.0]);
    assert_eq!(norm.scale, 1.0 / 11.0);
    let read = read_gltf(&glb);
    assert_eq!(read.primitives, 1);
    assert_eq!(read.vertices, 24);
    assert_eq!(read.corners.len(), 3 * raw.triangles.len());
    for (c, (p, t, n)) in read.corners.iter().enumerate() {
        let (f, k) = (c / 3, c % 3);
        assert_eq!(*p, f32s(raw.positions[raw.triangles[f][k] as usize]));
        let [u, v] = uv[c];
        let expected = [(u - 0.0) / 11.0, 1.0 - (v + 3.0) / 11.0];
        assert_eq!(*t, f32s(expected), "corner {c}");
        assert!(t.iter().all(|x| (0.0..=1.0).contains(x)));
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-6, "unit normal");
    }
    // Area-weighted normal at a cube corner points along the diagonal, outward.
    let (p, _, n) = read.corners[0];
    let outward = [p[0] - 0.5, p[1] - 0.5, p[2] - 0.5];
    assert!(n[0] * outward[0] + n[1] * outward[1] + n[2] * outward[2] > 0.0);

    // POSITION min/max, generator, identity node.
    let j = &read.json;
    assert_eq!(j["asset"]["generator"], json!(format!("conemap {}", env!("CARGO_PKG_VERSION"))));
    let pos_acc = &j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize];
    assert_eq!(pos_acc["min"], json!([0.0, 0.0, 0.0]));
    assert_eq!(pos_acc["max"], json!([1.0, 1.0, 1.0]));
    assert!(j["nodes"][0].get("matrix").is_none() && j["nodes"][0].get("translation").is_none());
    for v in j["bufferViews"].as_array().unwrap() {
        assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0);
    }
}

#[test]
fn no_seam_means_no_split() {
    let (raw, uv) = grid(6);
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let input = ExportInput::new(&raw, &mesh, &uv).unwrap();
    assert_eq!(input.output_vertex_count(&ExportOptions::default()), mesh.n_vertices());
    let glb = export::write_glb(&input, &ExportOptions::default());
    let read = read_gltf(&glb);
    assert_eq!(read.vertices, 49);
    let obj_text = export::write_obj(&input, &ExportOptions::default());
    assert_eq!(obj_text.lines().filter(|l| l.starts_with("vt ")).count(), 49);

    // One synthetic seam: shift the UVs of the faces right of column 3 by a
    // unit translation. The 7 vertices on the column line split, nothing else.
    let mut seamed = uv.clone();
    for (f, t) in raw.triangles.iter().enumerate() {
        let right = t.iter().all(|&v| raw.positions[v as usize][0] >= 0.3 - 1e-12);
        if right {
            for k in 0..3 {
                seamed[3 * f + k][1] += 1.0;
            }
        }
    }
    let input = ExportInput::new(&raw, &mesh, &seamed).unwrap();
    assert_eq!(distinct_wedges(&mesh, &seamed), 49 + 7);
    assert_eq!(input.output_vertex_count(&ExportOptions::default()), 49 + 7);
}

#[test]
fn gltf_with_data_uri_and_checker() {
    let raw = cube();
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let uv = cube_uv(&raw);
    let input = ExportInput::new(&raw, &mesh, &uv).unwrap();
    let options = ExportOptions { checker: true, checker_cell: Some(1.0), name: Some("cube".into()), ..ExportOptions::default() };
    let text = export::write_gltf(&input, &options);
    assert!(text.contains("data:application/octet-stream;base64,"));
    let back = import(&InputFile { name: "cube.gltf".into(), bytes: text.clone().into_bytes() }, &[]).unwrap();
    assert_eq!(back.triangles.len(), 12);
    assert_eq!(back.positions.len(), 24);

    let read = read_gltf(text.as_bytes());
    let j = &read.json;
    assert_eq!(j["images"][0]["mimeType"], "image/png");
    assert_eq!(j["materials"][0]["name"], "conemap checker");
    assert_eq!(j["meshes"][0]["primitives"][0]["material"], 0);
    assert_eq!(j["extensionsUsed"], json!(["KHR_texture_transform"]));
    // The transform maps TEXCOORD_0 back to (u, −v) / 2 (cell = 1 input unit), mod 1.
    let tt = &j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"];
    let s = tt["scale"][0].as_f64().unwrap();
    let o = [tt["offset"][0].as_f64().unwrap(), tt["offset"][1].as_f64().unwrap()];
    for (c, (_, t, _)) in read.corners.iter().enumerate() {
        let got = [f64::from(t[0]) * s + o[0], f64::from(t[1]) * s + o[1]];
        let want = [uv[c][0] / 2.0, -uv[c][1] / 2.0];
        for i in 0..2 {
            let d = (got[i] - want[i]).rem_euclid(1.0);
            assert!(d.min(1.0 - d) < 1e-5, "corner {c}: {got:?} vs {want:?}");
        }
    }
    // Default cell: the UV box is 11 units wide, so 1/2 gives 22 ≥ 16 squares.
    assert_eq!(UvNormalization::of(&uv).auto_checker_cell(), 0.5);
    assert_eq!(UvNormalization { offset: [0.0; 2], scale: 1.0 / 40.0 }.auto_checker_cell(), 1.0);
    // The PNG in the buffer is the encoder's checker.
    let png = export::checker_png();
    let g = gltf::Gltf::from_slice(text.as_bytes()).unwrap();
    let view = g.images().next().map(|i| match i.source() {
        gltf::image::Source::View { view, .. } => view,
        _ => panic!("image from a bufferView"),
    });
    assert_eq!(view.unwrap().length(), png.len());
}

#[test]
fn obj_round_trip() {
    let raw = cube();
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let uv = cube_uv(&raw);
    let input = ExportInput::new(&raw, &mesh, &uv).unwrap();
    let text = export::write_obj(&input, &ExportOptions::default());
    let back = obj::parse(text.as_bytes()).unwrap();
    assert_eq!(back.triangles.len(), raw.triangles.len());
    assert_eq!(back.positions, raw.positions, "positions round-trip exactly");
    assert_eq!(back.triangles, raw.triangles);
    let vt: Vec<[f64; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1]]
        })
        .collect();
    assert_eq!(vt.len(), distinct_wedges(&mesh, &uv));
    let vn = text.lines().filter(|l| l.starts_with("vn ")).count();
    assert_eq!(vn, mesh.n_vertices(), "one normal per welded vertex");
    // Each f corner's vt is the corner's normalised UV (origin bottom-left).
    let norm = UvNormalization::of(&uv);
    let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
    assert_eq!(faces.len(), 12);
    for (f, line) in faces.iter().enumerate() {
        for (k, corner) in line.split_whitespace().skip(1).enumerate() {
            let idx: Vec<usize> = corner.split('/').map(|x| x.parse().unwrap()).collect();
            assert_eq!(vt[idx[1] - 1], norm.apply(uv[3 * f + k]));
        }
    }
    // Seams are splits in vt only; an unseamed grid keeps one vt per vertex.
    let (graw, guv) = grid(3);
    let gmesh = TriMesh::from_raw(&graw).unwrap();
    let gtext = export::write_obj(&ExportInput::new(&graw, &gmesh, &guv).unwrap(), &ExportOptions::default());
    assert_eq!(gtext.lines().filter(|l| l.starts_with("vt ")).count(), 16);
}

#[test]
fn bad_input_is_rejected() {
    let raw = cube();
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let uv = cube_uv(&raw);
    assert_eq!(
        ExportInput::new(&raw, &mesh, &uv[..30]).err(),
        Some(ExportError::UvCount { expected: 36, got: 30 })
    );
    let mut nan = uv.clone();
    nan[7][1] = f64::NAN;
    assert_eq!(ExportInput::new(&raw, &mesh, &nan).err(), Some(ExportError::NonFiniteUv { corner: 7 }));
    let (graw, _) = grid(2);
    let gmesh = TriMesh::from_raw(&graw).unwrap();
    assert!(matches!(ExportInput::new(&raw, &gmesh, &uv), Err(ExportError::FaceCount { .. })));
    let mut swapped = raw.clone();
    swapped.triangles[3] = [raw.triangles[3][1], raw.triangles[3][2], raw.triangles[3][0]];
    assert_eq!(
        ExportInput::new(&swapped, &mesh, &uv).err(),
        Some(ExportError::CornerMismatch { face: 3, corner: 0 })
    );
    assert_eq!(Format::from_path("a/b.GLB"), Some(Format::Glb));
    assert_eq!(Format::from_path("x.gltf"), Some(Format::Gltf));
    assert_eq!(Format::from_path("x.obj"), Some(Format::Obj));
    assert_eq!(Format::from_path("x.stl"), None);
}

/// Packs a GLB container from JSON and a BIN chunk.
fn pack_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

#[test]
fn gltf_source_keeps_primitives_materials_and_normals() {
    // Source: the cube exported once, then edited into two primitives (sides
    // 0-2 and 3-5) with two materials, and a node with a mirroring scale.
    let raw = cube();
    let mesh = TriMesh::from_raw(&raw).unwrap();
    let uv = cube_uv(&raw);
    let glb = export::write_glb(&ExportInput::new(&raw, &mesh, &uv).unwrap(), &ExportOptions::default());
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let mut bin = glb[20 + json_len + 8..].to_vec();
    // Split the index accessor (u16, 36 indices) into two of 18.
    let idx = doc["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
    let view = doc["accessors"][idx]["bufferView"].as_u64().unwrap() as usize;
    let start = doc["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
    let second: Vec<u8> = bin[start + 36..start + 72].to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let off2 = bin.len();
    bin.extend(&second);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    doc["bufferViews"].as_array_mut().unwrap().push(json!({"buffer": 0, "byteOffset": off2, "byteLength": 36}));
    let view2 = doc["bufferViews"].as_array().unwrap().len() - 1;
    doc["accessors"][idx]["count"] = json!(18);
    doc["accessors"].as_array_mut().unwrap().push(json!({"bufferView": view2, "componentType": 5123, "count": 18, "type": "SCALAR"}));
    let idx2 = doc["accessors"].as_array().unwrap().len() - 1;
    let mut p2 = doc["meshes"][0]["primitives"][0].clone();
    p2["indices"] = json!(idx2);
    p2["material"] = json!(1);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    doc["meshes"][0]["primitives"].as_array_mut().unwrap().push(p2);
    doc["materials"] = json!([
        {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 0.0, 1.0], "metallicFactor": 0.25, "roughnessFactor": 0.5}},
        {"name": "textured", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "doubleSided": true}
    ]);
    doc["textures"] = json!([{"source": 0}]);
    doc["images"] = json!([{"uri": "missing.png"}]);
    doc["nodes"][0]["scale"] = json!([-2.0, 1.0, 1.0]);
    let source_glb = pack_glb(&doc, &bin);

    let file = InputFile { name: "two.glb".into(), bytes: source_glb };
    let (raw2, source) = import_with_source(&file, &[]).unwrap();
    assert_eq!(source.spans.len(), 2);
    assert!(source.spans[0].mirrored);
    let mesh2 = TriMesh::from_raw(&raw2).unwrap();
    // UVs: the source's, one per corner (so the split stays the same).
    let uv2: Vec<[f64; 2]> = raw2.triangles.iter().flat_map(|t| t.map(|v| [raw2.positions[v as usize][1], v as f64])).collect();
    let input = ExportInput::new(&raw2, &mesh2, &uv2).unwrap().with_gltf_source(&source, &file, &[]);
    assert!(input.notes().iter().any(|n| n.contains("textures")), "{:?}", input.notes());
    let out = export::write_glb(&input, &ExportOptions::default());
    let read = read_gltf(&out);
    assert_eq!(read.primitives, 2);
    let j = &read.json;
    assert_eq!(j["materials"][0]["name"], "red");
    assert_eq!(j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"], json!([1.0, 0.0, 0.0, 1.0]));
    assert_eq!(j["materials"][0]["pbrMetallicRoughness"]["metallicFactor"], json!(0.25));
    assert_eq!(j["materials"][1]["doubleSided"], json!(true));
    assert!(j["materials"][1]["pbrMetallicRoughness"].get("baseColorTexture").is_none());
    assert_eq!(j["meshes"][0]["primitives"][1]["material"], 1);
    // Source normals, transformed by the mirroring node's normal matrix
    // (inverse transpose of diag(−2, 1, 1), up to a positive factor:
    // diag(−1/2, 1, 1)), renormalised. Triangles come in the same order,
    // corners 1 and 2 swapped by the importer since the node mirrors.
    let src = read_gltf(&file.bytes);
    assert_eq!(src.corners.len(), read.corners.len());
    for (c, (p, _, n)) in read.corners.iter().enumerate() {
        let (q, _, m) = src.corners[3 * (c / 3) + [0, 2, 1][c % 3]];
        assert_eq!(*p, [-2.0 * q[0], q[1], q[2]]);
        let d = [-0.5 * m[0], m[1], m[2]];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        for i in 0..3 {
            assert!((n[i] - d[i] / len).abs() < 1e-6, "normal {n:?} at {p:?}");
        }
        // Still outward after the mirror: the cube's centre is (−1, 0.5, 0.5).
        let out = [p[0] + 1.0, p[1] - 0.5, p[2] - 0.5];
        assert!(n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0.0);
    }
    // glTF output of the same input also parses.
    let text = export::write_gltf(&input, &ExportOptions { checker: true, ..ExportOptions::default() });
    let read = read_gltf(text.as_bytes());
    assert_eq!(read.primitives, 2);
    // The checker goes onto both kept materials.
    assert!(read.json["materials"][0]["pbrMetallicRoughness"].get("baseColorTexture").is_some());
    assert_eq!(read.json["materials"].as_array().unwrap().len(), 2);
}

/// Vertices merged across a floating-point crack are written at one
/// position, so a checker that welds by exact position sees the same mesh.
#[test]
fn crack_closed_vertices_are_written_at_one_position() {
    let gap = 1e-13;
    let raw = RawMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0 + gap, 0.0, 0.0], [gap, 1.0, 0.0], [1.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [3, 5, 4]],
    };
    let mesh = TriMesh::from_raw(&raw).unwrap();
    assert_eq!(mesh.n_vertices(), 4);
    let uv: Vec<[f64; 2]> = raw.triangles.iter().flatten().map(|&s| [raw.positions[s as usize][0], raw.positions[s as usize][1]]).collect();
    let text = export::write_obj(&ExportInput::new(&raw, &mesh, &uv).unwrap(), &ExportOptions::default());
    let positions: HashSet<String> = text.lines().filter(|l| l.starts_with("v ")).map(str::to_string).collect();
    assert_eq!(positions.len(), 4, "{text}");
}
