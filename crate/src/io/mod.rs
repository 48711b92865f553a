//! File import: bytes in, [`RawMesh`] out. The format is picked from the
//! file name's extension, falling back to the first bytes.

mod error;
pub mod gltf;
pub mod obj;

pub use error::ImportError;
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
    if main.bytes.is_empty() {
        return Err(ImportError::Empty { name: main.name.clone() });
    }
    let lower = main.name.to_ascii_lowercase();
    if main.bytes.starts_with(b"glTF") || lower.ends_with(".glb") || lower.ends_with(".gltf") {
        gltf::import(main, others)
    } else if lower.ends_with(".obj") {
        obj::import(main)
    } else {
        Err(ImportError::UnknownFormat { name: main.name.clone() })
    }
}

/// Like [`import`], also returning where each vertex came from when the
/// input is glTF (so an export can carry its normals and materials over).
pub fn import_with_source(main: &InputFile, others: &[InputFile]) -> Result<(RawMesh, Option<gltf::GltfSource>), ImportError> {
    if main.bytes.is_empty() {
        return Err(ImportError::Empty { name: main.name.clone() });
    }
    let lower = main.name.to_ascii_lowercase();
    if main.bytes.starts_with(b"glTF") || lower.ends_with(".glb") || lower.ends_with(".gltf") {
        let (raw, source) = gltf::import_with_source(main, others)?;
        Ok((raw, Some(source)))
    } else {
        Ok((import(main, others)?, None))
    }
}

/// Reads a file and its siblings from disk (native only) and imports it.
#[cfg(not(target_arch = "wasm32"))]
pub fn import_path(path: &std::path::Path) -> Result<RawMesh, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let main = InputFile { name, bytes };
    let others = gltf::sibling_buffers(path, &main)?;
    Ok(import(&main, &others)?)
}
