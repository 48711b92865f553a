//! wasm-bindgen API: thin conversions between JS values and the library.
//!
//! Errors cross as JS `Error`s carrying the library's one-line message.

use crate::io::{self, InputFile};
use crate::mesh;
use js_sys::{Array, Float32Array, Object, Reflect, Uint32Array, Uint8Array};
use wasm_bindgen::prelude::*;

/// Library version, for the page's about line.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Imports a mesh from `files` (an array of `{name: string, bytes: Uint8Array}`;
/// the first is the mesh, the rest companion buffers). Returns
/// `{report, positions: Float32Array, indices: Uint32Array}` with welded
/// vertices, or throws an `Error` naming the problem.
#[wasm_bindgen]
pub fn import_mesh(files: Array) -> Result<JsValue, JsError> {
    let files = input_files(&files)?;
    let (main, others) = files.split_first().ok_or_else(|| JsError::new("no file given"))?;
    let raw = io::import(main, others).map_err(|e| JsError::new(&e.to_string()))?;
    let report = mesh::analyze(&raw);
    let welded = mesh::weld(&raw);
    let positions: Vec<f32> = welded.positions.iter().flat_map(|p| p.map(|c| c as f32)).collect();
    let indices: Vec<u32> = welded.triangles.iter().flatten().copied().collect();
    let messages: Array = report.problems.iter().map(|p| JsValue::from(p.to_string())).collect();
    let out = Object::new();
    let report_js = serde_wasm_bindgen::to_value(&report).map_err(|e| JsError::new(&e.to_string()))?;
    set(&report_js.clone().into(), "problem_messages", &messages.into())?;
    set(&out, "report", &report_js)?;
    set(&out, "positions", &Float32Array::from(&positions[..]).into())?;
    set(&out, "indices", &Uint32Array::from(&indices[..]).into())?;
    Ok(out.into())
}

fn input_files(files: &Array) -> Result<Vec<InputFile>, JsError> {
    files
        .iter()
        .map(|f| {
            let name = Reflect::get(&f, &"name".into())
                .ok()
                .and_then(|n| n.as_string())
                .ok_or_else(|| JsError::new("each file needs a string `name`"))?;
            let bytes = Reflect::get(&f, &"bytes".into())
                .ok()
                .filter(|b| b.is_instance_of::<Uint8Array>())
                .ok_or_else(|| JsError::new("each file needs `bytes` as a Uint8Array"))?;
            Ok(InputFile { name, bytes: Uint8Array::from(bytes).to_vec() })
        })
        .collect()
}

fn set(obj: &Object, key: &str, value: &JsValue) -> Result<(), JsError> {
    Reflect::set(obj, &key.into(), value).map(|_| ()).map_err(|_| JsError::new("could not build the result object"))
}
