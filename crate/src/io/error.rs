//! What can go wrong reading a file: [`ImportError`]; its `Display` is the
//! one-line message shown by the CLI and the page.

use std::fmt;

/// Why a file could not be turned into a triangle soup.
#[derive(Clone, Debug, PartialEq)]
pub enum ImportError {
    /// The file name's extension and its first bytes match no supported format.
    UnknownFormat { name: String },
    /// The file holds no bytes.
    Empty { name: String },
    /// The file parsed but holds no triangle geometry.
    NoTriangles { name: String },
    /// The file needs an extension this importer does not support.
    UnsupportedExtension { extension: String },
    /// A glTF buffer is missing, e.g. an external `.bin` that was not supplied.
    MissingBuffer { uri: String },
    /// The file is malformed or truncated; `detail` says where.
    Malformed { format: &'static str, detail: String },
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImportError::UnknownFormat { name } => {
                write!(f, "{name}: not a recognised mesh file (expected .glb, .gltf or .obj)")
            }
            ImportError::Empty { name } => write!(f, "{name}: the file is empty"),
            ImportError::NoTriangles { name } => write!(f, "{name}: the file contains no triangle geometry"),
            ImportError::UnsupportedExtension { extension } => {
                write!(f, "unsupported glTF extension {extension}: decompress the file first (e.g. gltf-transform)")
            }
            ImportError::MissingBuffer { uri } => {
                write!(f, "glTF buffer \"{uri}\" was not supplied: drop the .gltf together with its .bin")
            }
            ImportError::Malformed { format, detail } => write!(f, "malformed {format} file: {detail}"),
        }
    }
}

impl std::error::Error for ImportError {}
