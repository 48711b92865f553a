//! Export of a parametrized mesh: glTF 2.0 (`.glb`, `.gltf`) and Wavefront OBJ.
//!
//! The writers take the mesh *as imported* (the [`RawMesh`], so source vertices
//! and their order survive), the validated [`TriMesh`] built from it (welded
//! vertex ids, used for normals) and one UV per face corner: `uv[3 f + k]` is
//! the UV of corner `k` of face `f`, in the corner order of both
//! `TriMesh::faces()[f]` and `RawMesh::triangles[f]`.
//!
//! # Vertex splitting
//!
//! An output vertex is a *wedge*: a distinct pair (source vertex, UV), the UV
//! compared exactly (bit for bit, `-0.0 == 0.0`). Corners sharing a source
//! vertex and a UV share an output vertex; anything else is split. On a welded
//! input (an OBJ with shared vertices) the split happens exactly along the UV
//! discontinuities, the seams of the parametrization, and nowhere else.
//!
//! # UV convention
//!
//! The UVs are first normalised into the unit square preserving aspect ratio
//! ([`UvNormalization`]): `u' = (u − u_min) s`, `v' = (v − v_min) s` with
//! `s = 1 / max(u_max − u_min, v_max − v_min)`. Then
//!
//! * glTF (`TEXCOORD_0`, origin top-left, `t` pointing down) stores
//!   `(u', 1 − v')`;
//! * OBJ (`vt`, origin bottom-left) stores `(u', v')`.
//!
//! Both therefore put the same image at the same place on the surface, with
//! the parametrization's `v` axis pointing up in the image.
//!
//! # Normals
//!
//! Per source vertex: the source's own `NORMAL` when the input was glTF and
//! had one (transformed by the node's normal matrix), else the area-weighted
//! average of the face normals around the welded vertex.
//!
//! # Checkerboard
//!
//! [`ExportOptions::checker`] embeds a small checkerboard PNG and a material
//! using it. The texture is mapped with `KHR_texture_transform` so that one
//! checker square spans [`ExportOptions::checker_cell`] units of the *input*
//! UVs. By default that is `2^-k` for the smallest `k ≥ 0` giving at least 16
//! squares along the longer side of the UV bounding box: a unit fraction, so
//! the squares follow the integer grid of a seamless parametrization and line
//! up across seams whose transitions are integer translations and quarter
//! turns. Viewers without the extension show one 2 × 2 checker period over
//! the normalised unit square instead.

mod glb;
pub mod quads;
mod obj;
mod png;
mod source;

pub use glb::{pack_glb, write_glb, write_gltf, GltfBuffer};
pub use obj::write_obj;
pub use png::checker_png;

use crate::io::gltf::GltfSource;
use crate::io::InputFile;
use crate::quads::exact_grid_uv;
use crate::{RawMesh, TriMesh};
use std::borrow::Cow;
use std::collections::HashMap;

/// Grid-unit UVs within this distance of an integer (and seam translations
/// within it of an integer vector) are written as exactly integer.
const GRID_SNAP_TOLERANCE: f64 = 1e-6;

/// Output formats, picked from a file name's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Binary glTF 2.0.
    Glb,
    /// glTF 2.0 JSON with the buffer embedded as a data URI.
    Gltf,
    /// Wavefront OBJ.
    Obj,
}

impl Format {
    /// The format for a path ending in `.glb`, `.gltf` or `.obj` (any case).
    pub fn from_path(path: &str) -> Option<Format> {
        let lower = path.to_ascii_lowercase();
        if lower.ends_with(".glb") {
            Some(Format::Glb)
        } else if lower.ends_with(".gltf") {
            Some(Format::Gltf)
        } else if lower.ends_with(".obj") {
            Some(Format::Obj)
        } else {
            None
        }
    }
}

/// Writer options.
#[derive(Clone, Debug, Default)]
pub struct ExportOptions {
    /// Embed a checkerboard texture and a material using it (glTF only).
    pub checker: bool,
    /// Side of one checker square in input UV units; `None` (default): the
    /// automatic unit fraction described in the module documentation.
    pub checker_cell: Option<f64>,
    /// Name of the output mesh and node (glTF) or object (OBJ).
    pub name: Option<String>,
    /// Write the UVs in grid units (an integer-grid map: one grid cell is
    /// 1.0), shifted by an integer vector only, instead of normalised to the
    /// unit square; the checker square is then one cell.
    pub grid_units: bool,
}

/// Input that cannot be exported.
#[derive(Clone, Debug, PartialEq)]
pub enum ExportError {
    /// The TriMesh does not have one face per RawMesh triangle.
    FaceCount { raw: usize, mesh: usize },
    /// `uv` does not have `3 × faces` entries.
    UvCount { expected: usize, got: usize },
    /// A UV coordinate is NaN or infinite.
    NonFiniteUv { corner: usize },
    /// Corner `k` of face `f` of the TriMesh is not the welded vertex of the
    /// RawMesh's corner: the two were not built from each other.
    CornerMismatch { face: usize, corner: usize },
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExportError::FaceCount { raw, mesh } => {
                write!(f, "export: the mesh has {mesh} faces but the imported file {raw} triangles")
            }
            ExportError::UvCount { expected, got } => {
                write!(f, "export: {got} UVs given, expected one per face corner ({expected})")
            }
            ExportError::NonFiniteUv { corner } => write!(f, "export: the UV of corner {corner} is not finite"),
            ExportError::CornerMismatch { face, corner } => write!(
                f,
                "export: corner {corner} of face {face} differs between the imported and the validated mesh"
            ),
        }
    }
}

impl std::error::Error for ExportError {}

/// The affine map taking input UVs into the unit square, aspect preserved:
/// `normalized(uv) = (uv − offset) · scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvNormalization {
    /// `(u_min, v_min)` of the input UVs.
    pub offset: [f64; 2],
    /// `1 / max(width, height)` of the UV bounding box (1 when that is 0).
    pub scale: f64,
}

impl UvNormalization {
    /// The normalisation of a UV set (identity for an empty one).
    pub fn of(uv: &[[f64; 2]]) -> UvNormalization {
        if uv.is_empty() {
            return UvNormalization { offset: [0.0, 0.0], scale: 1.0 };
        }
        let (lo, hi) = crate::vec3::bounds(uv);
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let scale = if extent > 0.0 && extent.is_finite() { 1.0 / extent } else { 1.0 };
        UvNormalization { offset: lo, scale }
    }
    /// The automatic checker square: `2^-k` for the smallest `k ≥ 0` (at
    /// most 30) with at least 16 squares along the longer side.
    pub fn auto_checker_cell(&self) -> f64 {
        let extent = 1.0 / self.scale;
        let mut cell = 1.0;
        for _ in 0..30 {
            if extent / cell >= 16.0 {
                break;
            }
            cell /= 2.0;
        }
        cell
    }
    /// The integer shift that centres a grid-unit UV set near the origin
    /// (scale 1): integer translations keep an integer-grid map one, and
    /// small coordinates keep the f32 of glTF exact to about 1e-6.
    pub fn grid(uv: &[[f64; 2]]) -> UvNormalization {
        if uv.is_empty() {
            return UvNormalization { offset: [0.0, 0.0], scale: 1.0 };
        }
        let (lo, hi) = crate::vec3::bounds(uv);
        let centre = [0, 1].map(|k| (0.5 * (lo[k] + hi[k])).round());
        UvNormalization { offset: if centre.iter().all(|c| c.is_finite()) { centre } else { [0.0, 0.0] }, scale: 1.0 }
    }
    /// `(u', v')` in `[0, 1]²`, origin bottom-left (the OBJ `vt`).
    pub fn apply(&self, uv: [f64; 2]) -> [f64; 2] {
        [(uv[0] - self.offset[0]) * self.scale, (uv[1] - self.offset[1]) * self.scale]
    }
    /// `(u', 1 − v')`, origin top-left (glTF `TEXCOORD_0`).
    pub fn gltf(&self, uv: [f64; 2]) -> [f64; 2] {
        let [u, v] = self.apply(uv);
        [u, 1.0 - v]
    }
}

/// Everything the writers need, checked for consistency once.
pub struct ExportInput<'a> {
    raw: &'a RawMesh,
    mesh: &'a TriMesh,
    uv: &'a [[f64; 2]],
    source: Option<source::SourceData>,
    notes: Vec<String>,
}

impl<'a> ExportInput<'a> {
    /// Checks that `mesh` was built from `raw` (same faces, corner for
    /// corner) and that `uv` has one finite entry per face corner.
    pub fn new(raw: &'a RawMesh, mesh: &'a TriMesh, uv: &'a [[f64; 2]]) -> Result<ExportInput<'a>, ExportError> {
        let nf = mesh.n_faces();
        if raw.triangles.len() != nf {
            return Err(ExportError::FaceCount { raw: raw.triangles.len(), mesh: nf });
        }
        if uv.len() != 3 * nf {
            return Err(ExportError::UvCount { expected: 3 * nf, got: uv.len() });
        }
        if let Some(corner) = uv.iter().position(|p| !(p[0].is_finite() && p[1].is_finite())) {
            return Err(ExportError::NonFiniteUv { corner });
        }
        let s2w = mesh.source_to_welded();
        for (f, (t, w)) in raw.triangles.iter().zip(mesh.faces()).enumerate() {
            for k in 0..3 {
                // A split non-manifold vertex: a copy at the same position.
                let same = |v: u32| v == w[k] || mesh.position(v) == mesh.position(w[k]);
                if !s2w.get(t[k] as usize).is_some_and(|&v| same(v)) {
                    return Err(ExportError::CornerMismatch { face: f, corner: k });
                }
            }
        }
        Ok(ExportInput { raw, mesh, uv, source: None, notes: Vec::new() })
    }

    /// Adds the glTF provenance: one output primitive per source primitive
    /// instance, the source materials (factors kept, textures dropped) and the
    /// source normals. `document` is the imported `.glb`/`.gltf` and
    /// `companions` its external buffers. Whatever cannot be read is skipped
    /// with a note ([`ExportInput::notes`]); this never fails.
    pub fn with_gltf_source(mut self, source: &GltfSource, document: &InputFile, companions: &[InputFile]) -> Self {
        let data = source::SourceData::read(source, document, companions, self.raw, &mut self.notes);
        self.source = Some(data);
        self
    }

    /// Remarks about source data that was not carried over.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// Number of output vertices (distinct (source vertex, UV) wedges) when
    /// written with `options`.
    pub fn output_vertex_count(&self, options: &ExportOptions) -> usize {
        self.layout(&self.written_uv(options)).groups.iter().map(|g| g.wedges.len()).sum()
    }

    /// The corner UVs the writers store with `options`: as given, or, in
    /// grid units, made exact for f32 ([`exact_grid_uv`]) with as many
    /// fractional bits as the centred coordinates leave in a 24-bit
    /// mantissa, so that the file's seam translations are integers and its
    /// cones integer points to the last bit (as given when `uv` is not an
    /// integer-grid map).
    fn written_uv(&self, options: &ExportOptions) -> Cow<'a, [[f64; 2]]> {
        if !options.grid_units || self.uv.is_empty() {
            return Cow::Borrowed(self.uv);
        }
        let centre = UvNormalization::grid(self.uv).offset;
        let extent = self.uv.iter().map(|p| (p[0] - centre[0]).abs().max((p[1] - centre[1]).abs())).fold(0.0, f64::max);
        // (|x| + 2)·2^bits ≤ 2^24 keeps x and the glTF 1 − x exact in f32.
        let bits = (24.0 - (extent + 2.0).log2()).floor().clamp(0.0, 32.0) as u32;
        match exact_grid_uv(self.mesh, self.uv, GRID_SNAP_TOLERANCE, bits) {
            Some(exact) => Cow::Owned(exact),
            None => Cow::Borrowed(self.uv),
        }
    }

    /// The UV normalisation the writers apply with `options`.
    pub fn uv_normalization(&self, options: &ExportOptions) -> UvNormalization {
        if options.grid_units {
            UvNormalization::grid(self.uv)
        } else {
            UvNormalization::of(self.uv)
        }
    }

    /// Output position of source vertex `s`: that of its welded vertex, so
    /// vertices merged across a floating-point crack coincide exactly in the
    /// file (the raw position when `s` is not in the mesh).
    fn position(&self, s: u32) -> [f64; 3] {
        match self.mesh.source_to_welded().get(s as usize) {
            Some(&w) if (w as usize) < self.mesh.n_vertices() => self.mesh.position(w),
            _ => self.raw.positions[s as usize],
        }
    }

    /// Unit normal per source vertex (index = source vertex; unreferenced
    /// vertices get a normal too), see the module documentation.
    fn normals(&self) -> Vec<[f64; 3]> {
        let welded = area_weighted_normals(self.mesh);
        let s2w = self.mesh.source_to_welded();
        let from_source = self.source.as_ref().map(|s| &s.normals);
        (0..self.raw.positions.len())
            .map(|s| {
                if let Some(Some(n)) = from_source.and_then(|ns| ns.get(s)) {
                    return *n;
                }
                match s2w.get(s) {
                    Some(&w) if (w as usize) < welded.len() => welded[w as usize],
                    _ => [0.0, 0.0, 1.0],
                }
            })
            .collect()
    }

    /// Output primitives with their wedges and local triangles.
    fn layout(&self, uv: &[[f64; 2]]) -> Layout {
        let nf = self.raw.triangles.len();
        let ranges: Vec<(std::ops::Range<usize>, Option<usize>)> = match &self.source {
            Some(s) if !s.groups.is_empty() => s.groups.iter().map(|g| (g.triangles.clone(), g.material)).collect(),
            _ => vec![(0..nf, None)],
        };
        let mut groups = Vec::with_capacity(ranges.len());
        for (range, material) in ranges {
            if range.is_empty() {
                continue;
            }
            let mut map: HashMap<(u32, u64, u64), u32> = HashMap::new();
            let mut wedges = Vec::new();
            let mut triangles = Vec::with_capacity(range.len());
            for f in range {
                let mut tri = [0u32; 3];
                for (k, slot) in tri.iter_mut().enumerate() {
                    let s = self.raw.triangles[f][k];
                    let uv = uv[3 * f + k];
                    // Adding 0.0 turns -0.0 into +0.0, so the two compare equal.
                    let key = (s, (uv[0] + 0.0).to_bits(), (uv[1] + 0.0).to_bits());
                    *slot = *map.entry(key).or_insert_with(|| {
                        wedges.push(Wedge { source: s, uv });
                        (wedges.len() - 1) as u32
                    });
                }
                triangles.push(tri);
            }
            groups.push(Group { material, wedges, triangles });
        }
        Layout { groups }
    }
}

/// One output vertex.
#[derive(Clone, Copy, Debug)]
struct Wedge {
    source: u32,
    uv: [f64; 2],
}

/// One output primitive: its vertices and triangles (local indices).
struct Group {
    material: Option<usize>,
    wedges: Vec<Wedge>,
    triangles: Vec<[u32; 3]>,
}

struct Layout {
    groups: Vec<Group>,
}

/// Unit area-weighted vertex normals of a TriMesh (per welded vertex);
/// `[0, 0, 1]` where the faces around a vertex cancel out.
pub fn area_weighted_normals(mesh: &TriMesh) -> Vec<[f64; 3]> {
    let p = mesh.positions();
    let mut n = vec![[0.0f64; 3]; p.len()];
    for f in mesh.faces() {
        let [a, b, c] = f.map(|v| p[v as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        // Length = twice the area, so the sum is area weighted.
        let cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        for &v in f {
            for i in 0..3 {
                n[v as usize][i] += cr[i];
            }
        }
    }
    n.into_iter().map(|v| normalize(v).unwrap_or([0.0, 0.0, 1.0])).collect()
}

/// `v / |v|`, or None for a zero or non-finite vector.
fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| [v[0] / len, v[1] / len, v[2] / len])
}

/// Writes `input` in `format` (the bytes of the file).
pub fn export(input: &ExportInput, format: Format, options: &ExportOptions) -> Vec<u8> {
    match format {
        Format::Glb => write_glb(input, options),
        Format::Gltf => write_gltf(input, options).into_bytes(),
        Format::Obj => write_obj(input, options).into_bytes(),
    }
}

/// The `asset.generator` string.
pub fn generator() -> String {
    format!("conemap {}", env!("CARGO_PKG_VERSION"))
}
