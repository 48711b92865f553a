//! glTF 2.0 import, `.glb` and `.gltf` (OWNER: gltf helper).

use super::InputFile;
use crate::{ImportError, RawMesh};

/// Imports every triangle primitive of the default scene, node transforms applied.
pub fn import(file: &InputFile, others: &[InputFile]) -> Result<RawMesh, ImportError> {
    let _ = (file, others);
    Err(ImportError::Malformed { format: "glTF", detail: "not implemented yet".into() })
}

/// For a `.gltf` on disk, reads the external buffers its JSON names (native only).
#[cfg(not(target_arch = "wasm32"))]
pub fn sibling_buffers(path: &std::path::Path, main: &InputFile) -> Result<Vec<InputFile>, ImportError> {
    let _ = (path, main);
    Ok(Vec::new())
}
