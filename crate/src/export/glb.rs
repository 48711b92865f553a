//! glTF 2.0 writer: one node (identity transform, node transforms were baked
//! into the positions at import), one mesh, one TRIANGLES primitive per
//! output group, each with its own POSITION (f32, min/max), NORMAL (f32, unit),
//! TEXCOORD_0 (f32) and indices (u16 when every index fits below 65535, else
//! u32). Every bufferView starts on a 4-byte boundary and is tightly packed.
//!
//! `asset.extras.conemap` records the UV normalisation (`uv_offset`,
//! `uv_scale`: `TEXCOORD_0 = ((u − offset_u) scale, 1 − (v − offset_v) scale)`)
//! and any notes about dropped source data.

use super::{generator, ExportInput, ExportOptions};
use base64::Engine;
use serde_json::{json, Value};

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;

/// The binary glTF (`.glb`) of `input`.
pub fn write_glb(input: &ExportInput, options: &ExportOptions) -> Vec<u8> {
    let (doc, bin) = document(input, options, false);
    let json = serde_json::to_vec(&doc).expect("glTF JSON serialises");
    pack_glb(&json, Some(&bin))
}

/// A GLB container: the 12-byte header, the JSON chunk (padded with spaces to
/// 4 bytes) and, unless `bin` is `None`, the BIN chunk (padded with zeros).
pub fn pack_glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let padded = |bytes: &[u8], fill: u8| {
        let mut v = bytes.to_vec();
        v.resize(bytes.len().next_multiple_of(4), fill);
        v
    };
    let json = padded(json, b' ');
    let bin = bin.map(|b| padded(b, 0));
    let total = 12 + 8 + json.len() + bin.as_ref().map_or(0, |b| 8 + b.len());
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if let Some(bin) = bin {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    out
}

/// The `.gltf` JSON of `input`, its single buffer embedded as a base64 data URI.
pub fn write_gltf(input: &ExportInput, options: &ExportOptions) -> String {
    let (doc, _) = document(input, options, true);
    serde_json::to_string(&doc).expect("glTF JSON serialises")
}

/// A glTF binary buffer under construction: its bytes and the bufferViews and
/// accessors that describe them (all in buffer 0).
#[derive(Default)]
pub struct GltfBuffer {
    /// The buffer's bytes.
    pub data: Vec<u8>,
    /// The `bufferViews` JSON objects, by index.
    pub views: Vec<Value>,
    /// The `accessors` JSON objects, by index.
    pub accessors: Vec<Value>,
}

impl GltfBuffer {
    /// Pads `data` with zeros to a multiple of 4 bytes.
    pub fn pad(&mut self) {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
    }

    /// Appends `bytes` at the next 4-byte boundary as a new bufferView with
    /// the given `target` and `byteStride` (each only if `Some`); returns its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>, stride: Option<usize>) -> usize {
        self.pad();
        let mut v = json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.data.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Appends the accessor JSON object `a`; returns its index.
    pub fn accessor(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// A FLOAT `VECN` (or SCALAR) accessor over `values` in a new
    /// bufferView, with `min` / `max` when `with_bounds`; returns its index.
    pub fn floats<const N: usize>(&mut self, values: &[[f32; N]], with_bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ARRAY_BUFFER), None);
        let kind = match N {
            2 => "VEC2",
            3 => "VEC3",
            4 => "VEC4",
            _ => "SCALAR",
        };
        let mut a = json!({"bufferView": view, "componentType": FLOAT, "count": values.len(), "type": kind});
        if with_bounds {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for v in values {
                for i in 0..N {
                    lo[i] = lo[i].min(v[i]);
                    hi[i] = hi[i].max(v[i]);
                }
            }
            a["min"] = json!(lo.map(f64::from).to_vec());
            a["max"] = json!(hi.map(f64::from).to_vec());
        }
        self.accessor(a)
    }
    /// A SCALAR index accessor over `indices` of `vertex_count` vertices
    /// (u16 when they fit, else u32) in a new bufferView; returns its index.
    pub fn indices(&mut self, indices: &[u32], vertex_count: usize) -> usize {
        // 65535 is the primitive restart value for u16, so it must not occur.
        let (bytes, component): (Vec<u8>, u32) = if vertex_count <= 65535 {
            (indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(), UNSIGNED_SHORT)
        } else {
            (indices.iter().flat_map(|&i| i.to_le_bytes()).collect(), UNSIGNED_INT)
        };
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER), None);
        self.accessor(json!({
            "bufferView": view, "componentType": component, "count": indices.len(), "type": "SCALAR"
        }))
    }
}

/// The glTF JSON and the (4-byte padded) binary buffer. With `embed`, the
/// buffer is written into the JSON as a data URI.
fn document(input: &ExportInput, options: &ExportOptions, embed: bool) -> (Value, Vec<u8>) {
    let layout = input.layout(&input.written_uv(options));
    let normals = input.normals();
    let norm = input.uv_normalization(options);
    let mut bin = GltfBuffer::default();

    // Materials: the source's (factors only), plus a checker material for
    // primitives without one when the checker is on.
    let mut materials: Vec<Value> = input.source.as_ref().map(|s| s.materials.clone()).unwrap_or_default();
    let mut texture_info = None;
    let mut images = Vec::new();
    if options.checker {
        let png = super::checker_png();
        let view = bin.view(&png, None, None);
        images.push(json!({"bufferView": view, "mimeType": "image/png", "name": "conemap checker"}));
        let cell = options.checker_cell.filter(|c| *c > 0.0 && c.is_finite()).unwrap_or_else(|| norm.auto_checker_cell());
        // Texture coordinate T = (u, −v) / (2 cell) in input UV units: the
        // image holds 2 × 2 squares, so one square spans `cell` units.
        let k = 1.0 / (2.0 * norm.scale * cell);
        let offset = [
            (norm.offset[0] / (2.0 * cell)).rem_euclid(1.0),
            (-k - norm.offset[1] / (2.0 * cell)).rem_euclid(1.0),
        ];
        texture_info = Some(json!({
            "index": 0,
            "extensions": {"KHR_texture_transform": {"offset": offset, "scale": [k, k]}}
        }));
        for m in &mut materials {
            m["pbrMetallicRoughness"]["baseColorTexture"] = texture_info.clone().unwrap();
        }
    }
    let mut checker_material = None;

    let mut primitives = Vec::new();
    for g in &layout.groups {
        let positions: Vec<[f32; 3]> =
            g.wedges.iter().map(|w| input.position(w.source).map(|x| x as f32)).collect();
        let normal: Vec<[f32; 3]> = g.wedges.iter().map(|w| normals[w.source as usize].map(|x| x as f32)).collect();
        let uv: Vec<[f32; 2]> = g.wedges.iter().map(|w| norm.gltf(w.uv).map(|x| x as f32)).collect();
        let p = bin.floats(&positions, true);
        let n = bin.floats(&normal, false);
        let t = bin.floats(&uv, false);
        let i = bin.indices(g.triangles.as_flattened(), g.wedges.len());
        let mut prim = json!({
            "attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t},
            "indices": i,
            "mode": 4,
        });
        let material = g.material.filter(|&m| m < materials.len()).or_else(|| {
            texture_info.as_ref().map(|info| {
                *checker_material.get_or_insert_with(|| {
                    materials.push(json!({
                        "name": "conemap checker",
                        "pbrMetallicRoughness": {"baseColorTexture": info, "metallicFactor": 0.0, "roughnessFactor": 1.0}
                    }));
                    materials.len() - 1
                })
            })
        });
        if let Some(m) = material {
            prim["material"] = json!(m);
        }
        primitives.push(prim);
    }
    bin.pad();

    let name = options.name.clone().unwrap_or_else(|| "conemap".to_string());
    let mut extras = json!({"uv_offset": norm.offset, "uv_scale": norm.scale});
    if !input.notes.is_empty() {
        extras["notes"] = json!(input.notes);
    }
    let mut buffer = json!({"byteLength": bin.data.len()});
    if embed {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin.data);
        buffer["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": generator(), "extras": {"conemap": extras}},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": primitives}],
        "buffers": [buffer],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
    });
    if !materials.is_empty() {
        doc["materials"] = json!(materials);
    }
    if !images.is_empty() {
        doc["images"] = json!(images);
        doc["samplers"] = json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
        doc["textures"] = json!([{"source": 0, "sampler": 0}]);
        doc["extensionsUsed"] = json!(["KHR_texture_transform"]);
    }
    (doc, bin.data)
}
