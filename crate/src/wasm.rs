//! wasm-bindgen API: thin conversions around the library.
use wasm_bindgen::prelude::*;

/// Library version, for the page's about line.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}
