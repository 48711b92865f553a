//! conemap: seamless, feature-aligned UV parametrization with automatic cone
//! placement, after Myles & Zorin 2013, "Controlled-Distortion Constrained
//! Global Parametrization".
//!
//! Data flows one way:
//! file bytes → [`io`] (a [`RawMesh`]) → [`mesh`] (a validated [`TriMesh`]
//! and its geometry) → [`features`] → [`cones`] (cone placement) → [`param`]
//! (cut, field, parametrization, quantization to an integer-grid map) →
//! [`quads`] (quad extraction and checks) → [`export`]; [`pipeline`] runs
//! them in order.

// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values;
// index loops read like the formulas they implement.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod clock;
pub mod cones;
pub mod export;
pub mod features;
pub mod io;
pub mod linalg;
pub mod mesh;
pub mod parallel;
pub mod pipeline;
pub mod vec3;
pub mod param;
pub mod quads;

#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use io::ImportError;
pub use mesh::Problem;
pub use mesh::{MeshReport, RawMesh, TriMesh};
