//! A bounds-checked accessor reader. Every range (accessor within its
//! bufferView, bufferView within its buffer, stride versus element size,
//! sparse indices versus the accessor count) is validated before a byte is
//! read, so a truncated or lying file yields [`ImportError::Malformed`]
//! naming the accessor or bufferView instead of a panic.

use super::container::{malformed, Buffers};
use crate::ImportError;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use gltf::json::{self, Index};

/// Largest element count accepted for an accessor that has no bufferView
/// (its contents are zeros, so its count is not bounded by any data).
const MAX_ZERO_ELEMENTS: u64 = 1 << 24;

fn component_size(ct: ComponentType) -> usize {
    match ct {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn component_count(ty: Type) -> usize {
    match ty {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

fn type_name(ty: Type) -> &'static str {
    match ty {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

/// Copies `count` elements of `elem_size` bytes out of bufferView `view`
/// (starting `byte_offset` bytes into it, honouring its byteStride) into a
/// tightly packed vector, after checking every range.
fn packed_bytes(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    view_index: usize,
    byte_offset: u64,
    count: u64,
    elem_size: usize,
    who: &str,
) -> Result<Vec<u8>, ImportError> {
    let view = root.buffer_views.get(view_index).ok_or_else(|| {
        malformed(format!(
            "{who}: bufferView {view_index} does not exist ({} bufferViews)",
            root.buffer_views.len()
        ))
    })?;
    let buffer_index = view.buffer.value();
    let buffer = root.buffers.get(buffer_index).ok_or_else(|| {
        malformed(format!(
            "bufferView {view_index}: buffer {buffer_index} does not exist ({} buffers)",
            root.buffers.len()
        ))
    })?;
    let view_offset = view.byte_offset.map_or(0, |o| o.0);
    let view_len = view.byte_length.0;
    let view_end = view_offset.checked_add(view_len);
    if view_end.is_none_or(|e| e > buffer.byte_length.0) {
        return Err(malformed(format!(
            "bufferView {view_index}: bytes {view_offset}..{} lie beyond buffer {buffer_index} (byteLength {})",
            view_offset as u128 + view_len as u128,
            buffer.byte_length.0
        )));
    }
    let stride = view.byte_stride.map_or(elem_size, |s| s.0);
    if stride < elem_size {
        return Err(malformed(format!(
            "bufferView {view_index}: byteStride {stride} is smaller than the {elem_size}-byte elements of {who}"
        )));
    }
    let needed = if count == 0 {
        Some(0)
    } else {
        (count - 1)
            .checked_mul(stride as u64)
            .and_then(|n| n.checked_add(elem_size as u64))
            .and_then(|n| n.checked_add(byte_offset))
    };
    match needed {
        Some(n) if n <= view_len => {}
        _ => {
            return Err(malformed(format!(
                "{who}: {count} elements of {elem_size} bytes (stride {stride}) from byteOffset {byte_offset} \
                 do not fit in bufferView {view_index} (byteLength {view_len})"
            )))
        }
    }
    let data = buffers.get(buffer_index)?;
    // The buffer is at least byteLength long (checked by `Buffers::get`) and the
    // view and element ranges lie within it (checked above), so these slices hold.
    let view_bytes = &data[view_offset as usize..(view_offset + view_len) as usize];
    let start = byte_offset as usize;
    let count = count as usize;
    if stride == elem_size {
        return Ok(view_bytes[start..start + count * elem_size].to_vec());
    }
    let mut out = Vec::with_capacity(count * elem_size);
    for i in 0..count {
        let at = start + i * stride;
        out.extend_from_slice(&view_bytes[at..at + elem_size]);
    }
    Ok(out)
}

/// Decodes packed little-endian components to f64, applying the glTF
/// normalisation rules when `normalized` is set.
fn decode(bytes: &[u8], ct: ComponentType, normalized: bool, out: &mut Vec<f64>) {
    match ct {
        ComponentType::F32 => out.extend(
            bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64),
        ),
        ComponentType::U32 => {
            let scale = if normalized {
                1.0 / u32::MAX as f64
            } else {
                1.0
            };
            out.extend(
                bytes
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64 * scale),
            )
        }
        ComponentType::U16 => {
            let scale = if normalized { 1.0 / 65535.0 } else { 1.0 };
            out.extend(
                bytes
                    .chunks_exact(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64 * scale),
            )
        }
        ComponentType::I16 => out.extend(bytes.chunks_exact(2).map(|c| {
            let v = i16::from_le_bytes([c[0], c[1]]) as f64;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        })),
        ComponentType::U8 => {
            let scale = if normalized { 1.0 / 255.0 } else { 1.0 };
            out.extend(bytes.iter().map(|&b| b as f64 * scale))
        }
        ComponentType::I8 => out.extend(bytes.iter().map(|&b| {
            let v = b as i8 as f64;
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        })),
    }
}

/// Reads accessor `index` as `count × components` f64 values, checking its
/// type against `expect`. Sparse accessors are supported.
fn read_f64(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    index: usize,
    expect: Type,
    role: &str,
) -> Result<(Vec<f64>, ComponentType), ImportError> {
    let who = format!("accessor {index} ({role})");
    let acc = root.accessors.get(index).ok_or_else(|| {
        malformed(format!(
            "{who} does not exist ({} accessors)",
            root.accessors.len()
        ))
    })?;
    let ty = match acc.type_ {
        Checked::Valid(t) => t,
        Checked::Invalid => return Err(malformed(format!("{who}: invalid type"))),
    };
    if ty != expect {
        return Err(malformed(format!(
            "{who}: type is {}, expected {}",
            type_name(ty),
            type_name(expect)
        )));
    }
    let ct = match acc.component_type {
        Checked::Valid(c) => c.0,
        Checked::Invalid => return Err(malformed(format!("{who}: invalid componentType"))),
    };
    let comps = component_count(ty);
    let elem_size = comps * component_size(ct);
    let count = acc.count.0;
    let mut values = Vec::new();
    match acc.buffer_view {
        Some(view) => {
            let bytes = packed_bytes(
                root,
                buffers,
                view.value(),
                acc.byte_offset.map_or(0, |o| o.0),
                count,
                elem_size,
                &who,
            )?;
            values.reserve_exact(count as usize * comps);
            decode(&bytes, ct, acc.normalized, &mut values);
        }
        None => {
            if count > MAX_ZERO_ELEMENTS {
                return Err(malformed(format!(
                    "{who}: count {count} without a bufferView is implausibly large"
                )));
            }
            values.resize(count as usize * comps, 0.0);
        }
    }
    if let Some(sparse) = &acc.sparse {
        apply_sparse(
            root,
            buffers,
            sparse,
            &mut values,
            count,
            comps,
            ct,
            acc.normalized,
            &who,
        )?;
    }
    Ok((values, ct))
}

#[allow(clippy::too_many_arguments)]
fn apply_sparse(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    sparse: &json::accessor::sparse::Sparse,
    values: &mut [f64],
    count: u64,
    comps: usize,
    ct: ComponentType,
    normalized: bool,
    who: &str,
) -> Result<(), ImportError> {
    let n = sparse.count.0;
    if n > count {
        return Err(malformed(format!(
            "{who}: sparse count {n} exceeds the accessor count {count}"
        )));
    }
    let ict = match sparse.indices.component_type {
        Checked::Valid(c) => c.0,
        Checked::Invalid => {
            return Err(malformed(format!(
                "{who}: invalid sparse indices componentType"
            )))
        }
    };
    let swho = format!("{who} sparse indices");
    let ibytes = packed_bytes(
        root,
        buffers,
        sparse.indices.buffer_view.value(),
        sparse.indices.byte_offset.0,
        n,
        component_size(ict),
        &swho,
    )?;
    let mut indices = Vec::with_capacity(n as usize);
    decode(&ibytes, ict, false, &mut indices);
    let vwho = format!("{who} sparse values");
    let vbytes = packed_bytes(
        root,
        buffers,
        sparse.values.buffer_view.value(),
        sparse.values.byte_offset.0,
        n,
        comps * component_size(ct),
        &vwho,
    )?;
    let mut subst = Vec::with_capacity(n as usize * comps);
    decode(&vbytes, ct, normalized, &mut subst);
    for (k, &i) in indices.iter().enumerate() {
        if i >= count as f64 {
            return Err(malformed(format!(
                "{swho}: entry {k} is {i}, out of range for {count} elements"
            )));
        }
        let i = i as usize;
        values[i * comps..(i + 1) * comps].copy_from_slice(&subst[k * comps..(k + 1) * comps]);
    }
    Ok(())
}

/// Reads a POSITION accessor (VEC3; FLOAT, or the integer types of
/// KHR_mesh_quantization, normalised or not).
pub(crate) fn read_positions(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    index: Index<json::Accessor>,
) -> Result<Vec<[f64; 3]>, ImportError> {
    let (values, _) = read_f64(root, buffers, index.value(), Type::Vec3, "POSITION")?;
    Ok(values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Reads an index accessor (SCALAR; UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT).
pub(crate) fn read_indices(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    index: Index<json::Accessor>,
) -> Result<Vec<u32>, ImportError> {
    let i = index.value();
    if let Some(acc) = root.accessors.get(i) {
        match acc.component_type {
            Checked::Valid(c) if matches!(c.0, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) => {}
            _ => {
                return Err(malformed(format!(
                    "accessor {i} (indices): componentType must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT"
                )))
            }
        }
        if acc.normalized {
            return Err(malformed(format!(
                "accessor {i} (indices): indices must not be normalized"
            )));
        }
    }
    let (values, _) = read_f64(root, buffers, i, Type::Scalar, "indices")?;
    // Unsigned integers up to u32::MAX are exact in f64.
    Ok(values.into_iter().map(|v| v as u32).collect())
}
