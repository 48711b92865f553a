//! Wavefront OBJ import (OWNER: mesh-core helper).

use super::InputFile;
use crate::{ImportError, RawMesh};

/// Parses an OBJ file: `v` lines and `f` lines (polygons fan-triangulated,
/// negative indices, `v`, `v/vt`, `v//vn`, `v/vt/vn` forms).
pub fn import(file: &InputFile) -> Result<RawMesh, ImportError> {
    let _ = file;
    Err(ImportError::Malformed { format: "OBJ", detail: "not implemented yet".into() })
}
