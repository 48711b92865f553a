//! File import: bytes in, [`RawMesh`] out. The format is picked from the
//! file name's extension, falling back to the first bytes.

mod error;
mod features;
pub mod gltf;
mod numbering;
pub mod obj;

pub use error::ImportError;
pub use features::{parse_feature_edges, EdgeEnds};
pub use numbering::FileNumbering;
use crate::RawMesh;

/// A file handed to the importer: its name (used for the format and for
/// resolving relative URIs) and its bytes.
#[derive(Clone, Debug)]
pub struct InputFile {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// Imports the mesh in `main`; `others` are companion files dropped with it
/// (a `.gltf`'s external `.bin` buffers), looked up by URI.
pub fn import(main: &InputFile, others: &[InputFile]) -> Result<RawMesh, ImportError> {
    import_file(main, others).map(|i| i.raw)
}

/// Like [`import`], also returning where each vertex came from when the
/// input is glTF (so an export can carry its normals and materials over).
pub fn import_with_source(main: &InputFile, others: &[InputFile]) -> Result<(RawMesh, Option<gltf::GltfSource>), ImportError> {
    import_file(main, others).map(|i| (i.raw, i.gltf))
}

/// A file imported: its triangle soup, for glTF where each vertex came
/// from, and how the file numbers its vertices and faces (for messages).
#[derive(Clone, Debug)]
pub struct Imported {
    pub raw: RawMesh,
    pub gltf: Option<gltf::GltfSource>,
    pub numbering: FileNumbering,
}

/// Like [`import`], with the glTF provenance and the file's numbering ([`Imported`]).
pub fn import_file(main: &InputFile, others: &[InputFile]) -> Result<Imported, ImportError> {
    if main.bytes.is_empty() {
        return Err(ImportError::Empty { name: main.name.clone() });
    }
    let lower = main.name.to_ascii_lowercase();
    if main.bytes.starts_with(b"glTF") || lower.ends_with(".glb") || lower.ends_with(".gltf") {
        let (raw, source) = gltf::import_with_source(main, others)?;
        Ok(Imported { raw, numbering: FileNumbering::Gltf(source.clone()), gltf: Some(source) })
    } else if lower.ends_with(".obj") {
        let (raw, face_of_triangle) = obj::import_numbered(main)?;
        Ok(Imported { raw, gltf: None, numbering: FileNumbering::Obj { face_of_triangle } })
    } else {
        Err(ImportError::UnknownFormat { name: main.name.clone() })
    }
}

/// Reads a file and its siblings from disk (native only) and imports it.
#[cfg(not(target_arch = "wasm32"))]
pub fn import_path(path: &std::path::Path) -> Result<RawMesh, Box<dyn std::error::Error>> {
    Ok(import_path_numbered(path)?.raw)
}

/// [`import_path`], with the glTF provenance and the file's numbering.
#[cfg(not(target_arch = "wasm32"))]
pub fn import_path_numbered(path: &std::path::Path) -> Result<Imported, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let main = InputFile { name, bytes };
    let others = gltf::sibling_buffers(path, &main)?;
    Ok(import_file(&main, &others)?)
}
