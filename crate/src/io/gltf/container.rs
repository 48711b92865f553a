//! The glTF container: GLB chunk splitting, JSON parsing, the extension
//! policy, and buffer resolution (GLB blob, `data:` URIs, companion files).
//!
//! Nothing here trusts a length field: every slice is bounds-checked and a
//! bad value becomes [`ImportError::Malformed`], never a panic.

use super::FORMAT;
use crate::io::InputFile;
use crate::ImportError;
use base64::Engine as _;
use gltf::json;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

pub(super) fn malformed(detail: impl Into<String>) -> ImportError {
    ImportError::Malformed {
        format: FORMAT,
        detail: detail.into(),
    }
}

/// A parsed glTF document plus the GLB binary chunk, if any.
pub(crate) struct Document<'a> {
    pub root: json::Root,
    pub blob: Option<&'a [u8]>,
}

/// True if the bytes start with the GLB magic.
pub(crate) fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(GLB_MAGIC)
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Splits a GLB file into its JSON chunk and optional BIN chunk.
pub(crate) fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), ImportError> {
    if bytes.len() < 12 {
        return Err(malformed(format!(
            "GLB header is truncated: {} of 12 bytes",
            bytes.len()
        )));
    }
    if !is_glb(bytes) {
        return Err(malformed(
            "not a GLB file: the first four bytes are not \"glTF\"",
        ));
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(malformed(format!(
            "GLB version {version} is not supported (expected 2)"
        )));
    }
    let declared = read_u32(bytes, 8).unwrap_or(0) as usize;
    if declared > bytes.len() {
        return Err(malformed(format!(
            "GLB header declares {declared} bytes but the file has only {} (truncated?)",
            bytes.len()
        )));
    }
    if declared < 20 {
        return Err(malformed(format!(
            "GLB header declares a total length of {declared} bytes, too short for a JSON chunk"
        )));
    }
    let data = &bytes[..declared];
    let mut at = 12usize;
    let mut json_chunk: Option<&[u8]> = None;
    let mut bin_chunk: Option<&[u8]> = None;
    let mut index = 0usize;
    while at < data.len() {
        let (Some(len), Some(kind)) = (read_u32(data, at), read_u32(data, at + 4)) else {
            return Err(malformed(format!(
                "GLB chunk {index} header at byte {at} is truncated"
            )));
        };
        let start = at + 8;
        let end = start.checked_add(len as usize).filter(|&e| e <= data.len()).ok_or_else(|| {
            malformed(format!(
                "GLB chunk {index} declares {len} bytes at byte {start} but only {} remain (truncated?)",
                data.len().saturating_sub(start)
            ))
        })?;
        let body = &data[start..end];
        match (index, kind) {
            (0, CHUNK_JSON) => json_chunk = Some(body),
            (0, _) => {
                return Err(malformed(format!(
                    "GLB first chunk has type 0x{kind:08x}, expected JSON"
                )))
            }
            (_, CHUNK_BIN) if bin_chunk.is_none() => bin_chunk = Some(body),
            (_, CHUNK_JSON) => return Err(malformed("GLB has more than one JSON chunk")),
            _ => {} // unknown chunk types (and extra BIN chunks) are ignored, as the spec says
        }
        // Chunks are 4-byte aligned; tolerate a missing final padding.
        at = end
            .checked_add(3)
            .map(|e| e & !3)
            .unwrap_or(usize::MAX)
            .min(data.len())
            .max(end);
        index += 1;
    }
    let json = json_chunk.ok_or_else(|| malformed("GLB has no JSON chunk"))?;
    Ok((json, bin_chunk))
}

/// Parses the glTF JSON (after splitting a GLB if the bytes are one).
pub(crate) fn parse(file: &InputFile) -> Result<Document<'_>, ImportError> {
    let bytes = &file.bytes[..];
    if bytes.is_empty() {
        return Err(ImportError::Empty {
            name: file.name.clone(),
        });
    }
    let (json_bytes, blob) = if is_glb(bytes) {
        split_glb(bytes)?
    } else {
        let trimmed = bytes
            .strip_prefix(b"\xEF\xBB\xBF".as_slice())
            .unwrap_or(bytes);
        let first = trimmed.iter().find(|b| !b.is_ascii_whitespace());
        if first != Some(&b'{') {
            let what = if file.name.to_ascii_lowercase().ends_with(".glb") {
                "not a GLB file: the first four bytes are not \"glTF\""
            } else {
                "not glTF JSON: the file does not start with '{'"
            };
            return Err(malformed(what));
        }
        (trimmed, None)
    };
    let root: json::Root = json::deserialize::from_slice(json_bytes)
        .map_err(|e| malformed(format!("invalid glTF JSON: {e}")))?;
    check_extensions(&root)?;
    Ok(Document { root, blob })
}

/// Extensions that change how geometry is stored and that this importer
/// cannot decode: rejected when merely used, since the plain data may be a
/// placeholder.
const COMPRESSION: &[&str] = &[
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Geometry extensions this importer understands.
const SUPPORTED_GEOMETRY: &[&str] = &["KHR_mesh_quantization"];

/// Prefixes of extensions that only affect appearance (materials, textures,
/// lights, metadata); they may be required without affecting the triangles.
const APPEARANCE_PREFIXES: &[&str] = &[
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "MSFT_texture_",
    "KHR_lights_",
    "EXT_lights_",
    "KHR_xmp",
    "KHR_animation_pointer",
];

fn check_extensions(root: &json::Root) -> Result<(), ImportError> {
    let listed = root
        .extensions_required
        .iter()
        .chain(root.extensions_used.iter());
    for ext in listed {
        if COMPRESSION.contains(&ext.as_str()) {
            return Err(ImportError::UnsupportedExtension {
                extension: ext.clone(),
            });
        }
    }
    for ext in &root.extensions_required {
        let harmless = SUPPORTED_GEOMETRY.contains(&ext.as_str())
            || APPEARANCE_PREFIXES.iter().any(|p| ext.starts_with(p));
        if !harmless {
            return Err(ImportError::UnsupportedExtension {
                extension: ext.clone(),
            });
        }
    }
    Ok(())
}

/// Decodes `%XX` escapes (invalid escapes are kept verbatim).
pub(crate) fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The last path component of a name or URI (both `/` and `\` separate).
pub(crate) fn base_name(s: &str) -> &str {
    s.rsplit(['/', '\\']).next().unwrap_or(s)
}

/// True for URIs that are not references to companion files.
pub(crate) fn is_data_uri(uri: &str) -> bool {
    uri.get(..5)
        .is_some_and(|p| p.eq_ignore_ascii_case("data:"))
}

fn decode_data_uri(uri: &str, buffer: usize) -> Result<Vec<u8>, ImportError> {
    let rest = &uri[5..];
    let comma = rest
        .find(',')
        .ok_or_else(|| malformed(format!("buffer {buffer}: data URI has no ',' separator")))?;
    let (meta, payload) = (&rest[..comma], &rest[comma + 1..]);
    if meta.to_ascii_lowercase().ends_with(";base64") {
        let clean: String = payload
            .chars()
            .filter(|c| !c.is_ascii_whitespace())
            .collect();
        let engine = base64::engine::general_purpose::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        engine
            .decode(clean.as_bytes())
            .map_err(|e| malformed(format!("buffer {buffer}: invalid base64 in data URI: {e}")))
    } else {
        Ok(percent_decode(payload).into_bytes())
    }
}

/// Finds the companion file for an external buffer URI: an exact match of
/// the percent-decoded URI first, then of its file name (path components
/// stripped on both sides), then case-insensitively.
pub(crate) fn find_companion<'a>(uri: &str, others: &'a [InputFile]) -> Option<&'a InputFile> {
    let decoded = percent_decode(uri);
    let want = base_name(&decoded);
    others
        .iter()
        .find(|f| f.name == decoded || f.name == uri)
        .or_else(|| others.iter().find(|f| base_name(&f.name) == want))
        .or_else(|| {
            others
                .iter()
                .find(|f| base_name(&f.name).eq_ignore_ascii_case(want))
        })
}

/// Buffer contents, resolved lazily so that a `.gltf` whose unused buffers
/// (animation data, say) were not supplied still imports.
pub(crate) struct Buffers<'a> {
    root: &'a json::Root,
    blob: Option<&'a [u8]>,
    others: &'a [InputFile],
    cache: Vec<Option<std::borrow::Cow<'a, [u8]>>>,
}

impl<'a> Buffers<'a> {
    pub fn new(doc: &'a Document<'a>, others: &'a [InputFile]) -> Self {
        Buffers {
            root: &doc.root,
            blob: doc.blob,
            others,
            cache: vec![None; doc.root.buffers.len()],
        }
    }

    /// The bytes of buffer `index`, at least its declared `byteLength` long
    /// (and truncated to it).
    pub fn get(&mut self, index: usize) -> Result<&[u8], ImportError> {
        let buffer = self.root.buffers.get(index).ok_or_else(|| {
            malformed(format!(
                "buffer {index} does not exist ({} buffers)",
                self.root.buffers.len()
            ))
        })?;
        if self.cache[index].is_none() {
            let data: std::borrow::Cow<'a, [u8]> = match buffer.uri.as_deref() {
                None => match (index, self.blob) {
                    (0, Some(blob)) => blob.into(),
                    _ => {
                        return Err(malformed(format!(
                            "buffer {index} has no uri and is not the GLB binary chunk"
                        )))
                    }
                },
                Some(uri) if is_data_uri(uri) => decode_data_uri(uri, index)?.into(),
                Some(uri) => match find_companion(uri, self.others) {
                    Some(f) => f.bytes.as_slice().into(),
                    None => {
                        return Err(ImportError::MissingBuffer {
                            uri: uri.to_string(),
                        })
                    }
                },
            };
            let declared = buffer.byte_length.0;
            if (data.len() as u64) < declared {
                return Err(malformed(format!(
                    "buffer {index} declares byteLength {declared} but only {} bytes are present (truncated?)",
                    data.len()
                )));
            }
            let data = match data {
                std::borrow::Cow::Borrowed(b) => {
                    std::borrow::Cow::Borrowed(&b[..declared as usize])
                }
                std::borrow::Cow::Owned(mut v) => {
                    v.truncate(declared as usize);
                    std::borrow::Cow::Owned(v)
                }
            };
            self.cache[index] = Some(data);
        }
        Ok(self.cache[index].as_deref().unwrap_or(&[]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decode("a%2"), "a%2");
        assert_eq!(percent_decode("%"), "%");
        assert_eq!(percent_decode("%zz%41"), "%zzA");
        assert_eq!(percent_decode("%C3%A9"), "é");
    }

    #[test]
    fn base_names() {
        assert_eq!(base_name("dir/sub\\x.bin"), "x.bin");
        assert_eq!(base_name("x.bin"), "x.bin");
    }

    #[test]
    fn glb_header_lengths_never_panic() {
        for len in [0u32, 1, 11, 12, 19, 20, 1000, u32::MAX] {
            let mut b = b"glTF".to_vec();
            b.extend(2u32.to_le_bytes());
            b.extend(len.to_le_bytes());
            b.extend([0u8; 8]);
            assert!(split_glb(&b).is_err(), "len {len}");
        }
    }

    #[test]
    fn data_uri_variants() {
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAEC", 0).unwrap(),
            vec![0, 1, 2]
        );
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAE=", 0).unwrap(),
            vec![0, 1]
        );
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAE", 0).unwrap(),
            vec![0, 1]
        );
        assert!(decode_data_uri("data:;base64,!!!", 0).is_err());
        assert!(decode_data_uri("data:nocomma", 0).is_err());
        assert!(!is_data_uri("daté.bin"));
        assert!(!is_data_uri("dat"));
        assert!(is_data_uri("DATA:,x"));
    }
}
