//! What is carried over from a glTF source: the primitive grouping, the
//! materials (factors only) and the normals. Best effort: anything that cannot
//! be read is left out with a note, never an error.

use crate::io::gltf::GltfSource;
use crate::io::InputFile;
use crate::RawMesh;
use base64::Engine;
use serde_json::{json, Map, Value};

/// One output primitive: a run of triangles and its material index (into
/// `SourceData::materials`).
pub(super) struct SourceGroup {
    pub triangles: std::ops::Range<usize>,
    pub material: Option<usize>,
}

pub(super) struct SourceData {
    pub groups: Vec<SourceGroup>,
    /// glTF material JSON, in source order (sanitised).
    pub materials: Vec<Value>,
    /// Per source vertex, the transformed unit source normal if there is one.
    pub normals: Vec<Option<[f64; 3]>>,
}

impl SourceData {
    pub fn read(
        source: &GltfSource,
        document: &InputFile,
        companions: &[InputFile],
        raw: &RawMesh,
        notes: &mut Vec<String>,
    ) -> SourceData {
        let mut data = SourceData { groups: Vec::new(), materials: Vec::new(), normals: Vec::new() };
        // The spans must tile the triangles in order, else keep one primitive.
        let mut next = 0usize;
        let mut tiles = true;
        for s in &source.spans {
            if s.first_triangle as usize != next {
                tiles = false;
                break;
            }
            next += s.triangle_count as usize;
        }
        if !tiles || next != raw.triangles.len() {
            notes.push("the glTF source spans do not match the mesh; written as one primitive".into());
            return data;
        }
        let gltf = match gltf::Gltf::from_slice(&document.bytes) {
            Ok(g) => g,
            Err(e) => {
                notes.push(format!("{}: materials and normals not kept ({e})", document.name));
                data.groups = source
                    .spans
                    .iter()
                    .map(|s| SourceGroup { triangles: span_range(s), material: None })
                    .collect();
                return data;
            }
        };
        let buffers = resolve_buffers(&gltf, companions);

        let mut dropped_textures = false;
        for m in gltf.materials() {
            let (value, had_textures) = material_json(&m);
            dropped_textures |= had_textures;
            data.materials.push(value);
        }
        if dropped_textures {
            notes.push("material textures were dropped (factors kept)".into());
        }

        data.normals = vec![None; raw.positions.len()];
        let mut missing_normals = false;
        for s in &source.spans {
            let prim = gltf.meshes().nth(s.mesh as usize).and_then(|m| m.primitives().nth(s.primitive as usize));
            let material = prim.as_ref().and_then(|p| p.material().index());
            data.groups.push(SourceGroup { triangles: span_range(s), material });
            let Some(prim) = prim else { continue };
            let normal_acc = prim.get(&gltf::Semantic::Normals);
            let read = normal_acc.as_ref().and_then(|a| read_vec3_f32(a, &buffers));
            match read {
                Some(ns) if ns.len() == s.vertex_count as usize => {
                    let m = normal_matrix(&s.world);
                    for (k, n) in ns.iter().enumerate() {
                        let n = n.map(f64::from);
                        let t = [
                            m[0] * n[0] + m[3] * n[1] + m[6] * n[2],
                            m[1] * n[0] + m[4] * n[1] + m[7] * n[2],
                            m[2] * n[0] + m[5] * n[1] + m[8] * n[2],
                        ];
                        if let Some(slot) = data.normals.get_mut(s.first_vertex as usize + k) {
                            *slot = super::normalize(t);
                        }
                    }
                }
                _ => missing_normals |= normal_acc.is_some(),
            }
        }
        if missing_normals {
            notes.push("some source normals could not be read; computed normals used there".into());
        }
        data
    }
}

fn span_range(s: &crate::io::gltf::PrimitiveSpan) -> std::ops::Range<usize> {
    s.first_triangle as usize..(s.first_triangle + s.triangle_count) as usize
}

/// Buffer data by buffer index (None when unavailable).
fn resolve_buffers(gltf: &gltf::Gltf, companions: &[InputFile]) -> Vec<Option<Vec<u8>>> {
    gltf.buffers()
        .map(|b| {
            let data = match b.source() {
                gltf::buffer::Source::Bin => gltf.blob.clone(),
                gltf::buffer::Source::Uri(uri) => {
                    if let Some(rest) = uri.strip_prefix("data:") {
                        rest.split_once(";base64,")
                            .and_then(|(_, b64)| base64::engine::general_purpose::STANDARD.decode(b64).ok())
                    } else {
                        let name = percent_decode(uri);
                        companions.iter().find(|f| f.name == name || f.name == uri).map(|f| f.bytes.clone())
                    }
                }
            };
            data.filter(|d| d.len() >= b.length())
        })
        .collect()
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push(h * 16 + l);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A non-sparse FLOAT VEC3 accessor, every byte range checked.
fn read_vec3_f32(acc: &gltf::Accessor, buffers: &[Option<Vec<u8>>]) -> Option<Vec<[f32; 3]>> {
    if acc.data_type() != gltf::accessor::DataType::F32
        || acc.dimensions() != gltf::accessor::Dimensions::Vec3
        || acc.sparse().is_some()
    {
        return None;
    }
    let view = acc.view()?;
    let data = buffers.get(view.buffer().index())?.as_deref()?;
    let view_start = view.offset();
    let view_end = view_start.checked_add(view.length())?;
    let view_bytes = data.get(view_start..view_end)?;
    let stride = view.stride().unwrap_or(12).max(12);
    let count = acc.count();
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let at = acc.offset().checked_add(i.checked_mul(stride)?)?;
        let b = view_bytes.get(at..at.checked_add(12)?)?;
        let f = |j: usize| f32::from_le_bytes([b[4 * j], b[4 * j + 1], b[4 * j + 2], b[4 * j + 3]]);
        out.push([f(0), f(1), f(2)]);
    }
    Some(out)
}

/// The 3×3 normal matrix (column-major) of a column-major 4×4 world matrix:
/// the cofactor matrix, sign-corrected for mirroring, i.e. a positive
/// multiple of the inverse transpose.
fn normal_matrix(w: &[f64; 16]) -> [f64; 9] {
    let a = |c: usize, r: usize| w[c * 4 + r];
    // Cofactor C(r, c) of the 3×3 block; column-major output.
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(c1, r1) * a(c2, r2) - a(c2, r1) * a(c1, r2)
    };
    let det = a(0, 0) * cof(0, 0) + a(1, 0) * cof(0, 1) + a(2, 0) * cof(0, 2);
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    let mut m = [0.0; 9];
    for c in 0..3 {
        for r in 0..3 {
            m[c * 3 + r] = sign * cof(r, c);
        }
    }
    m
}

/// The material as output JSON (name and factors) and whether it had textures.
fn material_json(m: &gltf::Material) -> (Value, bool) {
    let pbr = m.pbr_metallic_roughness();
    let had_textures = pbr.base_color_texture().is_some()
        || pbr.metallic_roughness_texture().is_some()
        || m.normal_texture().is_some()
        || m.occlusion_texture().is_some()
        || m.emissive_texture().is_some();
    let mut out = Map::new();
    if let Some(name) = m.name() {
        out.insert("name".into(), json!(name));
    }
    let finite = |x: f32, lo: f32, hi: f32, default: f32| if x.is_finite() { x.clamp(lo, hi) } else { default };
    let base = pbr.base_color_factor().map(|c| finite(c, 0.0, 1.0, 1.0));
    out.insert(
        "pbrMetallicRoughness".into(),
        json!({
            "baseColorFactor": base.map(f64::from),
            "metallicFactor": f64::from(finite(pbr.metallic_factor(), 0.0, 1.0, 1.0)),
            "roughnessFactor": f64::from(finite(pbr.roughness_factor(), 0.0, 1.0, 1.0)),
        }),
    );
    let emissive = m.emissive_factor().map(|c| finite(c, 0.0, 1.0, 0.0));
    if emissive != [0.0; 3] {
        out.insert("emissiveFactor".into(), json!(emissive.map(f64::from)));
    }
    match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => {}
        gltf::material::AlphaMode::Blend => {
            out.insert("alphaMode".into(), json!("BLEND"));
        }
        gltf::material::AlphaMode::Mask => {
            out.insert("alphaMode".into(), json!("MASK"));
            let cutoff = m.alpha_cutoff().filter(|c| c.is_finite() && *c >= 0.0).unwrap_or(0.5);
            out.insert("alphaCutoff".into(), json!(f64::from(cutoff)));
        }
    }
    if m.double_sided() {
        out.insert("doubleSided".into(), json!(true));
    }
    (Value::Object(out), had_textures)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_matrix_of_scale_and_mirror() {
        // Non-uniform scale diag(2, 1, 1): normals scale by diag(1/2, 1, 1) up to a factor.
        let mut w = [0.0; 16];
        w[0] = 2.0;
        w[5] = 1.0;
        w[10] = 1.0;
        w[15] = 1.0;
        let m = normal_matrix(&w);
        assert_eq!(m, [1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
        // Mirror x: the normal's x flips, the others stay (positive multiple of M^-T).
        w[0] = -1.0;
        let m = normal_matrix(&w);
        assert_eq!(m, [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("bad%2"), "bad%2");
        assert_eq!(percent_decode("x%"), "x%");
    }
}
