//! The whole method in one call: refine doubly constrained triangles, place
//! cones (sections 4-5), then compute the seamless aligned parametrization
//! (Appendix B). The CLI and the wasm API call this.

use crate::clock::Stopwatch;
use crate::cones::{self, ConeError, ConeOptions, ConePlacement};
use crate::features::{split_doubly_constrained, FeatureSet};
use crate::mesh::TriMesh;
use crate::param::{self, ParamError, ParamOptions, ParamProgress, Parametrization};
use std::borrow::Cow;
use std::fmt;

/// Settings of both stages.
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveOptions {
    pub cones: ConeOptions,
    pub param: ParamOptions,
}

/// Progress of either stage.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveProgress {
    Cones(cones::Progress),
    Param(ParamProgress),
}

/// Why solving failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveError {
    Cones(ConeError),
    Param(ParamError),
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::Cones(e) => write!(f, "{e}"),
            SolveError::Param(e) => write!(f, "parametrization: {e}"),
        }
    }
}

impl std::error::Error for SolveError {}

/// The result: the mesh actually parametrized (the input, or the input with
/// doubly constrained triangles split), its features, cones and UVs.
#[derive(Clone, Debug)]
pub struct Solution<'a> {
    pub mesh: Cow<'a, TriMesh>,
    pub features: Cow<'a, FeatureSet>,
    /// Edges split before solving (0: `mesh` is the input).
    pub splits: usize,
    pub placement: ConePlacement,
    pub param: Parametrization,
    /// Seconds spent refining.
    pub refine_seconds: f64,
}

/// Solves on `mesh` with `features` (see the module doc).
pub fn solve<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    let mut clock = Stopwatch::start();
    let (mesh, features, splits) = match split_doubly_constrained(mesh, features) {
        Some(r) => (Cow::Owned(r.mesh), Cow::Owned(r.features), r.splits),
        None => (Cow::Borrowed(mesh), Cow::Borrowed(features), 0),
    };
    let refine_seconds = clock.lap();
    let placement = cones::place_cones(&mesh, &features, &options.cones, &mut |p| progress(SolveProgress::Cones(p)))
        .map_err(SolveError::Cones)?;
    let param = param::parametrize(&mesh, &placement, &options.param, &mut |p| progress(SolveProgress::Param(p)))
        .map_err(SolveError::Param)?;
    Ok(Solution { mesh, features, splits, placement, param, refine_seconds })
}
