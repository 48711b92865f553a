//! glTF import: hand-built `.glb` / `.gltf` files, malformed input that must
//! fail cleanly, and a round trip of the shared OBJ meshes through GLB.

use conemap::export::{pack_glb, GltfBuffer};
use conemap::io::gltf::{import, import_with_source};
use conemap::io::InputFile;
use conemap::{ImportError, RawMesh};
use serde_json::{json, Value};

mod common;

// ---------------------------------------------------------------------------
// A tiny glTF writer on the library's buffer builder
// ---------------------------------------------------------------------------

type Bin = GltfBuffer;

/// The accessors and documents these tests build on a [`GltfBuffer`].
trait TestGltf {
    /// An f32 VEC3 accessor of `pts` with min/max; returns its index.
    fn positions(&mut self, pts: &[[f32; 3]]) -> usize;
    /// A SCALAR u8 index accessor; returns its index.
    fn indices_u8(&mut self, idx: &[u8]) -> usize;
    /// A SCALAR u16 index accessor; returns its index.
    fn indices_u16(&mut self, idx: &[u16]) -> usize;
    /// A SCALAR u32 index accessor; returns its index.
    fn indices_u32(&mut self, idx: &[u32]) -> usize;
    /// The glTF JSON: `rest` (meshes, nodes, scenes, …) plus asset, buffer,
    /// bufferViews and accessors. `uri` is the buffer's URI (None for GLB).
    fn json(&mut self, uri: Option<&str>, rest: Value) -> Value;
    /// The GLB of [`TestGltf::json`] without a URI and the buffer's bytes.
    fn glb(&mut self, rest: Value) -> Vec<u8>;
}

impl TestGltf for GltfBuffer {
    fn positions(&mut self, pts: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = pts.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.view(&bytes, None, None);
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in pts {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        self.accessor(
            json!({"bufferView": view, "componentType": 5126, "count": pts.len(),
                             "type": "VEC3", "min": lo, "max": hi}),
        )
    }

    fn indices_u8(&mut self, idx: &[u8]) -> usize {
        let view = self.view(idx, None, None);
        self.accessor(json!({"bufferView": view, "componentType": 5121, "count": idx.len(), "type": "SCALAR"}))
    }

    fn indices_u16(&mut self, idx: &[u16]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, None, None);
        self.accessor(json!({"bufferView": view, "componentType": 5123, "count": idx.len(), "type": "SCALAR"}))
    }

    fn indices_u32(&mut self, idx: &[u32]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, None, None);
        self.accessor(json!({"bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}))
    }

    fn json(&mut self, uri: Option<&str>, rest: Value) -> Value {
        self.pad();
        let mut buffer = json!({"byteLength": self.data.len()});
        if let Some(u) = uri {
            buffer["uri"] = json!(u);
        }
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "buffers": [buffer],
            "bufferViews": self.views,
            "accessors": self.accessors,
        });
        for (k, v) in rest.as_object().expect("rest is an object") {
            doc[k] = v.clone();
        }
        doc
    }

    fn glb(&mut self, rest: Value) -> Vec<u8> {
        let doc = self.json(None, rest);
        glb(&doc.to_string(), &self.data)
    }
}

/// The library's GLB container of `json` and `bin`, without a BIN chunk when `bin` is empty.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    pack_glb(json.as_bytes(), Some(bin).filter(|b| !b.is_empty()))
}

fn file(name: &str, bytes: Vec<u8>) -> InputFile {
    InputFile {
        name: name.to_string(),
        bytes,
    }
}

fn one_mesh(prim: Value) -> Value {
    json!({"meshes": [{"primitives": [prim]}], "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})
}

fn import_glb(bytes: Vec<u8>) -> Result<RawMesh, ImportError> {
    import(&file("test.glb", bytes), &[])
}

fn malformed_detail(r: Result<RawMesh, ImportError>) -> String {
    match r {
        Err(ImportError::Malformed { format, detail }) => {
            assert_eq!(format, "glTF");
            detail
        }
        other => panic!("expected Malformed, got {other:?}"),
    }
}

const QUAD: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];

fn as_f64(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

/// A valid single-triangle-pair GLB used by the corruption tests.
fn small_glb() -> Vec<u8> {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 3]);
    b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "indices": idx}),
    ))
}

// ---------------------------------------------------------------------------
// Primitive modes and index types
// ---------------------------------------------------------------------------

#[test]
fn indexed_triangles_u8_u16_u32() {
    for kind in ["u8", "u16", "u32"] {
        let mut b = Bin::default();
        let pos = b.positions(&QUAD);
        let tri = [0u32, 1, 2, 0, 2, 3];
        let idx = match kind {
            "u8" => b.indices_u8(&tri.map(|i| i as u8)),
            "u16" => b.indices_u16(&tri.map(|i| i as u16)),
            _ => b.indices_u32(&tri),
        };
        let m = import_glb(b.glb(one_mesh(
            json!({"attributes": {"POSITION": pos}, "indices": idx, "mode": 4}),
        )))
        .unwrap();
        assert_eq!(m.positions, as_f64(&QUAD), "{kind}");
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]], "{kind}");
    }
}

#[test]
fn non_indexed_triangles() {
    let mut b = Bin::default();
    let pts = [QUAD[0], QUAD[1], QUAD[2], QUAD[0], QUAD[2], QUAD[3]];
    let pos = b.positions(&pts);
    let m = import_glb(b.glb(one_mesh(json!({"attributes": {"POSITION": pos}})))).unwrap();
    assert_eq!(m.positions, as_f64(&pts));
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
}

#[test]
fn triangle_strip_non_indexed_and_indexed() {
    // A 5-vertex strip: windings alternate so all three faces point the same way.
    let pts: Vec<[f32; 3]> = (0..5)
        .map(|i| [(i / 2) as f32, (i % 2) as f32, 0.0])
        .collect();
    let mut b = Bin::default();
    let pos = b.positions(&pts);
    let m = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "mode": 5}),
    )))
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
    // Every face has the orientation of the first (here: clockwise seen from +z).
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let nz = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert!(nz < 0.0, "face {t:?} flipped");
    }

    // Indexed: two triangles joined by degenerate repeats; the join is dropped.
    let mut b = Bin::default();
    let pos = b.positions(&[
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [5.0, 0.0, 0.0],
        [6.0, 0.0, 0.0],
        [5.0, 1.0, 0.0],
    ]);
    let idx = b.indices_u16(&[0, 1, 2, 2, 3, 3, 3, 4, 5]);
    let m = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "indices": idx, "mode": 5}),
    )))
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
}

#[test]
fn triangle_fan() {
    let mut b = Bin::default();
    let pts = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.5, 0.0],
    ];
    let pos = b.positions(&pts);
    let m = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "mode": 6}),
    )))
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);

    let mut b = Bin::default();
    let pos = b.positions(&pts);
    let idx = b.indices_u32(&[4, 0, 1, 2]);
    let m = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "indices": idx, "mode": 6}),
    )))
    .unwrap();
    assert_eq!(m.triangles, vec![[4, 0, 1], [4, 1, 2]]);
}

#[test]
fn points_and_lines_are_skipped() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let tri = b.positions(&QUAD[..3]);
    let doc = json!({
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": pos}, "mode": 0},
            {"attributes": {"POSITION": pos}, "mode": 1},
            {"attributes": {"POSITION": tri}},
            {"attributes": {"POSITION": pos}, "mode": 3},
        ]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]
    });
    let m = import_glb(b.glb(doc)).unwrap();
    assert_eq!(m.positions, as_f64(&QUAD[..3]));
    assert_eq!(m.triangles, vec![[0, 1, 2]]);

    // Only points: no triangles.
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let r = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "mode": 0}),
    )));
    assert_eq!(
        r,
        Err(ImportError::NoTriangles {
            name: "test.glb".into()
        })
    );
}

#[test]
fn no_geometry_is_no_triangles() {
    let mut b = Bin::default();
    let r = import_glb(b.glb(json!({"nodes": [{"name": "empty"}], "scenes": [{"nodes": [0]}]})));
    assert_eq!(
        r,
        Err(ImportError::NoTriangles {
            name: "test.glb".into()
        })
    );
    let r = import(
        &file("a.gltf", br#"{"asset":{"version":"2.0"}}"#.to_vec()),
        &[],
    );
    assert_eq!(
        r,
        Err(ImportError::NoTriangles {
            name: "a.gltf".into()
        })
    );
}

// ---------------------------------------------------------------------------
// Scene graph
// ---------------------------------------------------------------------------

#[test]
fn node_transforms_hierarchy_and_instancing() {
    let mut b = Bin::default();
    let tri = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let pos = b.positions(&tri);
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "nodes": [
            // 0: parent, translation only, with the mesh.
            {"mesh": 0, "translation": [10.0, 0.0, 0.0], "children": [1]},
            // 1: child: 180° about z, scale 2, translation (0, 0, 3).
            {"mesh": 0, "rotation": [0.0, 0.0, 1.0, 0.0], "scale": [2.0, 2.0, 2.0], "translation": [0.0, 0.0, 3.0],
             "children": [2]},
            // 2: grandchild, column-major matrix: translation (1, 2, 3).
            {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,2,3,1]},
            // 3: a separate root with a uniform scale.
            {"mesh": 0, "scale": [0.5, 0.5, 0.5]},
        ],
        "scenes": [{"nodes": [0, 3]}]
    });
    let (m, src) = import_with_source(&file("t.glb", b.glb(doc)), &[]).unwrap();
    assert_eq!(m.face_count(), 4);
    assert_eq!(m.vertex_count(), 12);
    let expect: Vec<[f64; 3]> = vec![
        // node 0: + (10, 0, 0)
        [11.0, 0.0, 0.0],
        [10.0, 1.0, 0.0],
        [10.0, 0.0, 1.0],
        // node 1 world: T(10,0,0) · T(0,0,3) · Rz(180°) · S(2)
        [8.0, 0.0, 3.0],
        [10.0, -2.0, 3.0],
        [10.0, 0.0, 5.0],
        // node 2 world: node 1 world · T(1,2,3): local p + (1,2,3) then node 1
        [6.0, -4.0, 9.0],
        [8.0, -6.0, 9.0],
        [8.0, -4.0, 11.0],
        // node 3: scale 0.5
        [0.5, 0.0, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.5],
    ];
    assert_eq!(m.positions, expect);
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]
    );
    // Provenance: depth-first pre-order, one span per primitive instance.
    let nodes: Vec<u32> = src.spans.iter().map(|s| s.node).collect();
    assert_eq!(nodes, vec![0, 1, 2, 3]);
    assert!(src
        .spans
        .iter()
        .all(|s| s.mesh == 0 && s.primitive == 0 && s.vertex_count == 3 && !s.mirrored));
    assert_eq!(src.span_of_vertex(7).unwrap().node, 2);
    assert_eq!(src.spans[3].first_triangle, 3);
}

#[test]
fn rotation_90_degrees() {
    let mut b = Bin::default();
    let pos = b.positions(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "nodes": [{"mesh": 0, "rotation": [0.0, 0.0, h, h]}],  // +90° about z
        "scenes": [{"nodes": [0]}]
    });
    let m = import_glb(b.glb(doc)).unwrap();
    let expect = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    for (p, e) in m.positions.iter().zip(expect) {
        for k in 0..3 {
            assert!((p[k] - e[k]).abs() < 1e-12, "{p:?} vs {e:?}");
        }
    }
}

#[test]
fn mirrored_node_flips_winding() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}],
        "nodes": [{"mesh": 0}, {"mesh": 0, "scale": [-1.0, 1.0, 1.0]}],
        "scenes": [{"nodes": [0, 1]}]
    });
    let (m, src) = import_with_source(&file("t.glb", b.glb(doc)), &[]).unwrap();
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]]
    );
    assert_eq!(m.positions[5], [-1.0, 0.0, 0.0]);
    assert!(!src.spans[0].mirrored && src.spans[1].mirrored);
    // Orientation: both copies face +z.
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let nz = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert!(nz > 0.0, "{t:?}");
    }
}

#[test]
fn scene_selection() {
    let mut b = Bin::default();
    let a = b.positions(&QUAD[..3]);
    let c = b.positions(&[[5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]]);
    let meshes = json!([{"primitives": [{"attributes": {"POSITION": a}}]},
                        {"primitives": [{"attributes": {"POSITION": c}}]}]);
    let nodes = json!([{"mesh": 0}, {"mesh": 1}]);
    // Default scene 1 → mesh 1 only.
    let m = import_glb(b.glb(json!({"meshes": meshes, "nodes": nodes, "scenes": [{"nodes": [0]}, {"nodes": [1]}], "scene": 1})))
        .unwrap();
    assert_eq!(m.positions[0], [5.0, 5.0, 5.0]);
    assert_eq!(m.vertex_count(), 3);
    // No default → scene 0.
    let m = import_glb(b.glb(
        json!({"meshes": meshes, "nodes": nodes, "scenes": [{"nodes": [0]}, {"nodes": [1]}]}),
    ))
    .unwrap();
    assert_eq!(m.positions[0], [0.0, 0.0, 0.0]);
    // No scenes → every root node (node 1 is a child of node 0 here, so it comes after it).
    let nodes2 = json!([{"mesh": 0, "children": [1]}, {"mesh": 1}]);
    let m = import_glb(b.glb(json!({"meshes": meshes, "nodes": nodes2}))).unwrap();
    assert_eq!(m.vertex_count(), 6);
    assert_eq!(m.positions[3], [5.0, 5.0, 5.0]);
    // A default scene that does not exist.
    let d = malformed_detail(import_glb(
        b.glb(json!({"meshes": meshes, "nodes": nodes, "scenes": [], "scene": 4})),
    ));
    assert!(d.contains("scene 4"), "{d}");
}

#[test]
fn node_cycle_is_malformed() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD[..3]);
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "nodes": [{"mesh": 0, "children": [1]}, {"children": [0]}],
        "scenes": [{"nodes": [0]}]
    });
    let d = malformed_detail(import_glb(b.glb(doc)));
    assert!(d.contains("cycle"), "{d}");
}

// ---------------------------------------------------------------------------
// Buffers: data URIs and companion files
// ---------------------------------------------------------------------------

fn quad_gltf(uri: &str) -> (Vec<u8>, Vec<u8>) {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let doc = b.json(
        Some(uri),
        one_mesh(json!({"attributes": {"POSITION": pos}, "indices": idx})),
    );
    (doc.to_string().into_bytes(), b.data)
}

#[test]
fn gltf_with_data_uri() {
    use base64::Engine as _;
    let (_, data) = quad_gltf("x");
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&data)
    );
    let (json, _) = quad_gltf(&uri);
    let m = import(&file("quad.gltf", json), &[]).unwrap();
    assert_eq!(m.positions, as_f64(&QUAD));
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn gltf_with_external_bin() {
    let (json, data) = quad_gltf("buffers/quad%20data.bin");
    // Matched by file name, percent-decoded, path components stripped.
    let others = [
        file("unrelated.bin", vec![0; 4]),
        file("quad data.bin", data.clone()),
    ];
    let m = import(&file("quad.gltf", json.clone()), &others).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    // Also with a path on the supplied side.
    let m = import(
        &file("quad.gltf", json.clone()),
        &[file("C:\\x\\quad data.bin", data.clone())],
    )
    .unwrap();
    assert_eq!(m.face_count(), 2);
    // Missing → MissingBuffer naming the URI.
    let r = import(&file("quad.gltf", json.clone()), &others[..1]);
    assert_eq!(
        r,
        Err(ImportError::MissingBuffer {
            uri: "buffers/quad%20data.bin".into()
        })
    );
    // Too short → Malformed naming the buffer.
    let short = [file("quad data.bin", data[..data.len() - 4].to_vec())];
    let d = malformed_detail(import(&file("quad.gltf", json), &short));
    assert!(d.contains("buffer 0"), "{d}");
}

#[test]
fn dispatch_through_io_import() {
    let m = conemap::io::import(&file("whatever.bin", small_glb()), &[]).unwrap();
    assert_eq!(m.face_count(), 2);
    let (json, data) = quad_gltf("q.bin");
    let m = conemap::io::import(&file("Q.GLTF", json), &[file("q.bin", data)]).unwrap();
    assert_eq!(m.face_count(), 2);
}

#[test]
fn import_path_reads_sibling_buffers() {
    let dir = std::env::temp_dir().join(format!("conemap-gltf-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("bin dir")).unwrap();
    let (json, data) = quad_gltf("bin%20dir/quad.bin");
    std::fs::write(dir.join("quad.gltf"), &json).unwrap();
    std::fs::write(dir.join("bin dir/quad.bin"), &data).unwrap();
    let m = conemap::io::import_path(&dir.join("quad.gltf")).unwrap();
    assert_eq!(m.face_count(), 2);
    let main = file("quad.gltf", json.clone());
    let sib = conemap::io::gltf::sibling_buffers(&dir.join("quad.gltf"), &main).unwrap();
    assert_eq!(sib.len(), 1);
    assert_eq!(sib[0].name, "bin dir/quad.bin");
    // Without the .bin on disk: the import names the missing URI.
    std::fs::remove_file(dir.join("bin dir/quad.bin")).unwrap();
    let err = conemap::io::import_path(&dir.join("quad.gltf")).unwrap_err();
    assert!(err.to_string().contains("bin%20dir/quad.bin"), "{err}");
    // Non-glTF files have no siblings.
    let obj = file("a.obj", b"v 0 0 0\n".to_vec());
    assert!(conemap::io::gltf::sibling_buffers(&dir.join("a.obj"), &obj)
        .unwrap()
        .is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// Accessor layouts
// ---------------------------------------------------------------------------

#[test]
fn interleaved_stride() {
    // POSITION and NORMAL interleaved with a 24-byte stride.
    let mut b = Bin::default();
    let mut bytes = Vec::new();
    for p in QUAD {
        for c in p.iter().chain([0.0f32, 0.0, 1.0].iter()) {
            bytes.extend(c.to_le_bytes());
        }
    }
    let view = b.view(&bytes, None, Some(24));
    let pos = b.accessor(json!({"bufferView": view, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                                "min": [0,0,0], "max": [1,1,0]}));
    let nrm = b.accessor(json!({"bufferView": view, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"}));
    let idx = b.indices_u8(&[0, 1, 2, 0, 2, 3]);
    let m = import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx}),
    )))
    .unwrap();
    assert_eq!(m.positions, as_f64(&QUAD));

    // A stride smaller than the element is malformed.
    let mut b = Bin::default();
    let view = b.view(&bytes, None, Some(8));
    let pos =
        b.accessor(json!({"bufferView": view, "componentType": 5126, "count": 4, "type": "VEC3"}));
    let d = malformed_detail(import_glb(
        b.glb(one_mesh(json!({"attributes": {"POSITION": pos}}))),
    ));
    assert!(
        d.contains("bufferView 0") && d.contains("byteStride"),
        "{d}"
    );
}

#[test]
fn quantized_positions() {
    // KHR_mesh_quantization: normalized i16 and unnormalized u8 positions.
    let mut b = Bin::default();
    let q: Vec<u8> = [[32767i16, 0, 0, 0], [0, -32767, 0, 0], [0, 0, -32768, 0]] // padded to the 8-byte stride
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let view = b.view(&q, None, Some(8));
    let pos = b.accessor(json!({"bufferView": view, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3",
                                "min": [0,-1,-1], "max": [1,0,0]}));
    let u8s = b.view(&[1, 2, 3, 0, 4, 5, 6, 0, 7, 8, 9, 0], None, Some(4));
    let pos2 =
        b.accessor(json!({"bufferView": u8s, "componentType": 5121, "count": 3, "type": "VEC3"}));
    let doc = json!({
        "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}, {"attributes": {"POSITION": pos2}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]
    });
    let m = import_glb(b.glb(doc)).unwrap();
    assert_eq!(
        m.positions,
        vec![
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
            [1.0, 2.0, 3.0],
            [4.0, 5.0, 6.0],
            [7.0, 8.0, 9.0]
        ]
    );
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
}

#[test]
fn sparse_positions() {
    let mut b = Bin::default();
    let base = b.positions(&[[0.0; 3]; 3]);
    let base_view = b.accessors[base]["bufferView"].clone();
    let si = b.view(&[2u8, 0, 0, 0], None, None);
    let vals: Vec<u8> = [[7.0f32, 8.0, 9.0]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let sv = b.view(&vals, None, None);
    let sparse = json!({"count": 1, "indices": {"bufferView": si, "componentType": 5121},
                        "values": {"bufferView": sv}});
    let with_base = b.accessor(
        json!({"bufferView": base_view, "componentType": 5126, "count": 3, "type": "VEC3",
                                      "sparse": sparse}),
    );
    let zeros =
        b.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3", "sparse": sparse}));
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": with_base}}, {"attributes": {"POSITION": zeros}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]
    });
    let m = import_glb(b.glb(doc)).unwrap();
    assert_eq!(m.positions[2], [7.0, 8.0, 9.0]);
    assert_eq!(m.positions[5], [7.0, 8.0, 9.0]);
    assert_eq!(m.positions[3], [0.0; 3]);

    // A sparse index past the accessor count.
    let mut b = Bin::default();
    let si = b.view(&[5u8, 0, 0, 0], None, None);
    let sv = b.view(&vals, None, None);
    let bad = b.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
        "sparse": {"count": 1, "indices": {"bufferView": si, "componentType": 5121}, "values": {"bufferView": sv}}}));
    let d = malformed_detail(import_glb(
        b.glb(one_mesh(json!({"attributes": {"POSITION": bad}}))),
    ));
    assert!(d.contains("accessor 0") && d.contains("sparse"), "{d}");
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

#[test]
fn compression_extensions_are_rejected() {
    for (list, ext) in [
        ("extensionsUsed", "KHR_draco_mesh_compression"),
        ("extensionsRequired", "KHR_draco_mesh_compression"),
        ("extensionsUsed", "EXT_meshopt_compression"),
        ("extensionsRequired", "EXT_meshopt_compression"),
        ("extensionsRequired", "EXT_mesh_gpu_instancing"),
        ("extensionsRequired", "VENDOR_unknown_geometry"),
    ] {
        let mut b = Bin::default();
        let pos = b.positions(&QUAD[..3]);
        let mut rest = one_mesh(json!({"attributes": {"POSITION": pos}}));
        rest[list] = json!([ext]);
        if list == "extensionsRequired" {
            rest["extensionsUsed"] = json!([ext]);
        }
        let r = import_glb(b.glb(rest));
        assert_eq!(
            r,
            Err(ImportError::UnsupportedExtension {
                extension: ext.into()
            }),
            "{list} {ext}"
        );
    }
    // Appearance-only extensions, required or not, are fine.
    let mut b = Bin::default();
    let pos = b.positions(&QUAD[..3]);
    let mut rest = one_mesh(json!({"attributes": {"POSITION": pos}}));
    rest["extensionsRequired"] = json!(["KHR_materials_unlit", "KHR_texture_transform"]);
    rest["extensionsUsed"] = json!([
        "KHR_materials_unlit",
        "KHR_texture_transform",
        "EXT_mesh_gpu_instancing"
    ]);
    assert_eq!(import_glb(b.glb(rest)).unwrap().face_count(), 1);
}

#[test]
fn zero_length_is_empty() {
    assert_eq!(
        import(&file("a.glb", vec![]), &[]),
        Err(ImportError::Empty {
            name: "a.glb".into()
        })
    );
    assert_eq!(
        import(&file("a.gltf", vec![]), &[]),
        Err(ImportError::Empty {
            name: "a.gltf".into()
        })
    );
}

#[test]
fn every_truncation_fails_cleanly() {
    let full = small_glb();
    assert!(import_glb(full.clone()).is_ok());
    for cut in 0..full.len() {
        let r = import_glb(full[..cut].to_vec());
        match r {
            Err(ImportError::Empty { .. }) => assert_eq!(cut, 0),
            Err(ImportError::Malformed { .. }) => {}
            other => panic!(
                "cut at {cut}/{}: expected an error, got {other:?}",
                full.len()
            ),
        }
    }
    // The same for a .gltf JSON file.
    let (json, data) = quad_gltf("q.bin");
    for cut in 1..json.len() {
        assert!(
            import(
                &file("q.gltf", json[..cut].to_vec()),
                &[file("q.bin", data.clone())]
            )
            .is_err(),
            "cut {cut}"
        );
    }
    for cut in 0..data.len() {
        let r = import(
            &file("q.gltf", json.clone()),
            &[file("q.bin", data[..cut].to_vec())],
        );
        assert!(
            matches!(r, Err(ImportError::Malformed { .. })),
            "bin cut {cut}: {r:?}"
        );
    }
}

/// A 64-bit LCG (Knuth's MMIX constants).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
}

#[test]
fn random_bytes_fail_cleanly() {
    let mut rng = Lcg(0x5eed);
    for round in 0..400 {
        let len = 1 + (rng.next() % 300) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        if round % 4 == 1 {
            // A plausible GLB header in front of the noise.
            let mut h = b"glTF".to_vec();
            h.extend(2u32.to_le_bytes());
            h.extend(((len + 12) as u32).to_le_bytes());
            h.append(&mut bytes);
            bytes = h;
        } else if round % 4 == 2 {
            bytes.insert(0, b'{');
        }
        for name in ["noise.glb", "noise.gltf"] {
            let r = import(&file(name, bytes.clone()), &[]);
            assert!(
                matches!(r, Err(ImportError::Malformed { .. })),
                "round {round} {name}: {r:?}"
            );
        }
    }
}

#[test]
fn corrupted_bytes_never_panic() {
    // Random byte flips in a valid GLB may still parse; they must never panic.
    let full = small_glb();
    let mut rng = Lcg(42);
    for _ in 0..3000 {
        let mut b = full.clone();
        for _ in 0..1 + rng.next() % 4 {
            let at = (rng.next() as usize) % b.len();
            b[at] = rng.next() as u8;
        }
        let _ = import_glb(b);
    }
}

#[test]
fn buffer_view_beyond_buffer() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let mut doc = b.json(
        None,
        one_mesh(json!({"attributes": {"POSITION": pos}, "mode": 6})),
    );
    doc["bufferViews"][0]["byteLength"] = json!(4096);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(d.contains("bufferView 0") && d.contains("buffer 0"), "{d}");

    // A bufferView pointing at a buffer that does not exist.
    doc["bufferViews"][0]["byteLength"] = json!(48);
    doc["bufferViews"][0]["buffer"] = json!(3);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(d.contains("bufferView 0") && d.contains("buffer 3"), "{d}");
}

#[test]
fn declared_buffer_longer_than_bin_chunk() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let mut doc = b.json(
        None,
        one_mesh(json!({"attributes": {"POSITION": pos}, "mode": 6})),
    );
    doc["buffers"][0]["byteLength"] = json!(1000);
    doc["bufferViews"][0]["byteLength"] = json!(1000);
    doc["accessors"][0]["count"] = json!(80);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(d.contains("buffer 0") && d.contains("1000"), "{d}");
}

#[test]
fn accessor_beyond_buffer_view() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let mut doc = b.json(
        None,
        one_mesh(json!({"attributes": {"POSITION": pos}, "indices": idx})),
    );
    doc["accessors"][1]["count"] = json!(7);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(
        d.contains("accessor 1") && d.contains("bufferView 1"),
        "{d}"
    );
    doc["accessors"][1]["count"] = json!(6);
    doc["accessors"][0]["byteOffset"] = json!(4);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(
        d.contains("accessor 0") && d.contains("bufferView 0"),
        "{d}"
    );
    // Huge counts must not overflow or allocate.
    doc["accessors"][0]["byteOffset"] = json!(0);
    doc["accessors"][0]["count"] = json!(u64::MAX / 2);
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(d.contains("accessor 0"), "{d}");
}

#[test]
fn index_out_of_range() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 4]);
    let d = malformed_detail(import_glb(b.glb(one_mesh(
        json!({"attributes": {"POSITION": pos}, "indices": idx}),
    ))));
    assert!(
        d.contains("accessor 1") && d.contains("element 5") && d.contains("vertex 4"),
        "{d}"
    );
}

#[test]
fn other_structural_errors() {
    let cases: Vec<(Value, &str)> = vec![
        // Indices as floats.
        (
            json!({"attributes": {"POSITION": 0}, "indices": 0}),
            "componentType",
        ),
        // POSITION accessor that does not exist.
        (json!({"attributes": {"POSITION": 9}}), "accessor 9"),
        // No POSITION at all.
        (json!({"attributes": {}}), "POSITION"),
        // An unknown mode.
        (json!({"attributes": {"POSITION": 0}, "mode": 42}), "mode"),
        // TRIANGLES with 4 vertices.
        (json!({"attributes": {"POSITION": 0}}), "multiple of 3"),
    ];
    for (prim, want) in cases {
        let mut b = Bin::default();
        let _ = b.positions(&QUAD);
        let d = malformed_detail(import_glb(b.glb(one_mesh(prim.clone()))));
        assert!(d.contains(want), "{prim}: {d}");
    }
    // POSITION that is VEC2.
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let mut doc = b.json(
        None,
        one_mesh(json!({"attributes": {"POSITION": pos}, "mode": 6})),
    );
    doc["accessors"][0]["type"] = json!("VEC2");
    let d = malformed_detail(import_glb(glb(&doc.to_string(), &b.data)));
    assert!(d.contains("VEC2"), "{d}");
    // A node naming a mesh that does not exist.
    let d = malformed_detail(import_glb(
        b.glb(json!({"nodes": [{"mesh": 3}], "scenes": [{"nodes": [0]}]})),
    ));
    assert!(d.contains("mesh 3"), "{d}");
    // A scene naming a node that does not exist.
    let d = malformed_detail(import_glb(b.glb(json!({"scenes": [{"nodes": [7]}]}))));
    assert!(d.contains("node 7"), "{d}");
    // Bad JSON.
    let d = malformed_detail(import(&file("x.gltf", b"{\"asset\": ".to_vec()), &[]));
    assert!(d.contains("JSON"), "{d}");
    // A GLB whose first chunk is not JSON.
    let mut g = small_glb();
    g[16] = b'X';
    let d = malformed_detail(import_glb(g));
    assert!(d.contains("chunk"), "{d}");
    // GLB version 1.
    let mut g = small_glb();
    g[4] = 1;
    let d = malformed_detail(import_glb(g));
    assert!(d.contains("version"), "{d}");
}

// ---------------------------------------------------------------------------
// Round trip of the shared meshes
// ---------------------------------------------------------------------------

/// Minimal OBJ reader for the test: `v` and `f` lines, polygons fan-triangulated.
fn parse_obj(text: &str) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    let mut f = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).map(|s| s.parse().unwrap()).collect();
                v.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let idx: Vec<u32> = it
                    .map(|s| {
                        let i: i64 = s.split('/').next().unwrap().parse().unwrap();
                        (if i < 0 { v.len() as i64 + i } else { i - 1 }) as u32
                    })
                    .collect();
                for k in 1..idx.len() - 1 {
                    f.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    (v, f)
}

/// Tiny GLB writer: f32 positions, u32 indices, TRIANGLES, one node.
fn write_glb(pos: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<u8> {
    let mut b = Bin::default();
    let p = b.positions(pos);
    let flat: Vec<u32> = tris.iter().flatten().copied().collect();
    let i = b.indices_u32(&flat);
    b.glb(one_mesh(
        json!({"attributes": {"POSITION": p}, "indices": i}),
    ))
}

/// The same as a TRIANGLE_STRIP: each triangle is its own 3-index strip,
/// joined by degenerate repeats; odd-placed triangles are written (a, c, b)
/// so that the strip's alternation restores (a, b, c).
fn write_strip_glb(pos: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<u8> {
    let mut strip: Vec<u32> = Vec::new();
    for t in tris {
        if let Some(&last) = strip.last() {
            strip.push(last);
            strip.push(t[0]);
        }
        if strip.len().is_multiple_of(2) {
            strip.extend([t[0], t[1], t[2]]);
        } else {
            strip.extend([t[0], t[2], t[1]]);
        }
    }
    let mut b = Bin::default();
    let p = b.positions(pos);
    let i = b.indices_u32(&strip);
    b.glb(one_mesh(
        json!({"attributes": {"POSITION": p}, "indices": i, "mode": 5}),
    ))
}

#[test]
fn round_trip_shared_meshes() {
    for name in ["fandisk", "spot", "woody", "alligator"] {
        let text = std::fs::read_to_string(common::shared_path(&format!("{name}.obj"))).unwrap();
        let (pos, tris) = parse_obj(&text);
        let expect_pos: Vec<[f64; 3]> = as_f64(&pos);
        for (variant, bytes) in [
            ("triangles", write_glb(&pos, &tris)),
            ("strip", write_strip_glb(&pos, &tris)),
        ] {
            let m = import(&file(&format!("{name}.glb"), bytes), &[]).unwrap();
            assert_eq!(m.face_count(), tris.len(), "{name} {variant}");
            assert_eq!(m.positions, expect_pos, "{name} {variant}");
            assert_eq!(m.triangles, tris, "{name} {variant}");
        }
    }
}

/// The files written by tests/node/make-gltf.mjs: each must hold exactly the
/// OBJ's triangles with bit-identical world positions. Checks the committed
/// fixtures in tests/fixtures/gltf and, if set, the directory named by
/// CONEMAP_GLTF_FIXTURES (OBJs looked up there, then in ../shared/meshes).
#[test]
fn make_gltf_fixtures_match_their_obj() {
    let committed = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/fixtures/gltf"
    ));
    let shared = std::path::PathBuf::from(common::SHARED_MESHES);
    let mut dirs = vec![committed];
    if let Some(d) = std::env::var_os("CONEMAP_GLTF_FIXTURES") {
        dirs.push(d.into());
    }
    let mut checked = 0;
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            eprintln!("note: {} is absent", dir.display());
            continue;
        };
        let mut names: Vec<String> = entries
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter_map(|n| n.strip_suffix(".glb").map(str::to_string))
            .filter(|n| !n.ends_with("-strip") && !n.ends_with("-nonindexed"))
            .collect();
        names.sort();
        for name in names {
            let obj = [
                dir.join(format!("{name}.obj")),
                shared.join(format!("{name}.obj")),
            ]
            .into_iter()
            .find(|p| p.is_file())
            .unwrap_or_else(|| panic!("no OBJ for fixture {name}"));
            let (pos, tris) = parse_obj(&std::fs::read_to_string(&obj).unwrap());
            let corners = |tris: &[[u32; 3]]| -> Vec<[f64; 3]> {
                tris.iter()
                    .flatten()
                    .map(|&v| pos[v as usize].map(f64::from))
                    .collect()
            };
            let proper: Vec<[u32; 3]> = tris
                .iter()
                .copied()
                .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
                .collect();
            let read = |f: &str| std::fs::read(dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
            let bin = format!("{name}-two-nodes.bin");
            let cases = [
                (format!("{name}.glb"), vec![], &tris),
                (
                    format!("{name}-two-nodes.gltf"),
                    vec![file(&bin, read(&bin))],
                    &tris,
                ),
                (format!("{name}-strip.glb"), vec![], &proper),
                (format!("{name}-nonindexed.glb"), vec![], &tris),
            ];
            for (main, others, expect) in cases {
                let m = import(&file(&main, read(&main)), &others)
                    .unwrap_or_else(|e| panic!("{main}: {e}"));
                assert_eq!(m.face_count(), expect.len(), "{main}");
                let got: Vec<[f64; 3]> = m
                    .triangles
                    .iter()
                    .flatten()
                    .map(|&v| m.positions[v as usize])
                    .collect();
                assert!(
                    got == corners(expect),
                    "{main}: world positions differ from the OBJ"
                );
                checked += 1;
            }
        }
    }
    eprintln!("checked {checked} fixture files");
    assert!(checked >= 4, "the committed fixtures were not found");
}

/// Sets random numeric fields of a valid document (counts, offsets, strides,
/// indices, modes, transforms) to hostile values: never a panic.
#[test]
fn hostile_json_numbers_never_panic() {
    let mut b = Bin::default();
    let pos = b.positions(&QUAD);
    let idx = b.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let si = b.view(&[1u8, 0, 0, 0], None, None);
    let sv = b.view(&[0u8; 12], None, None);
    let sparse = b.accessor(json!({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
        "sparse": {"count": 1, "indices": {"bufferView": si, "componentType": 5121}, "values": {"bufferView": sv}}}));
    let doc = b.json(None, json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "mode": 5},
                                   {"attributes": {"POSITION": sparse}, "mode": 6}]}],
        "nodes": [{"mesh": 0, "children": [1], "translation": [1, 2, 3]}, {"mesh": 0, "scale": [1, 1, 1]}],
        "scenes": [{"nodes": [0]}], "scene": 0
    }));
    fn numeric_paths(v: &Value, here: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        match v {
            Value::Number(_) => out.push(here.clone()),
            Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| {
                here.push(i.to_string());
                numeric_paths(x, here, out);
                here.pop();
            }),
            Value::Object(o) => o.iter().for_each(|(k, x)| {
                here.push(k.clone());
                numeric_paths(x, here, out);
                here.pop();
            }),
            _ => {}
        }
    }
    let mut paths = Vec::new();
    numeric_paths(&doc, &mut Vec::new(), &mut paths);
    let hostile = [
        json!(0),
        json!(1),
        json!(2),
        json!(3),
        json!(5),
        json!(7),
        json!(255),
        json!(65535),
        json!(4294967295u64),
        json!(9007199254740993u64),
        json!(-1),
        json!(1e30),
        json!(0.5),
    ];
    let mut rng = Lcg(7);
    for _ in 0..4000 {
        let mut d = doc.clone();
        for _ in 0..1 + rng.next() % 3 {
            let path = &paths[rng.next() as usize % paths.len()];
            let mut slot = &mut d;
            for key in path {
                slot = match slot {
                    Value::Array(a) => &mut a[key.parse::<usize>().unwrap()],
                    other => &mut other[key.as_str()],
                };
            }
            *slot = hostile[rng.next() as usize % hostile.len()].clone();
        }
        let _ = import_glb(glb(&d.to_string(), &b.data));
    }
}
