//! The whole method in one call: refine doubly constrained triangles, place
//! cones (sections 4-5) — refining around any vertex that would need a cone
//! of angle 0 and placing them again —, then compute the seamless aligned
//! parametrization (Appendix B). The CLI and the wasm API call this.

use crate::clock::Stopwatch;
use crate::cones::{self, ConeError, ConeOptions, ConePlacement};
use crate::features::{split_around, split_doubly_constrained, FeatureSet, Refined};
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
    /// When split: solved face → input face and solved vertex → input
    /// vertex (`NONE` for inserted midpoints).
    pub original_face: Option<Vec<u32>>,
    pub original_vertex: Option<Vec<u32>>,
    pub placement: ConePlacement,
    pub param: Parametrization,
    /// Seconds spent refining.
    pub refine_seconds: f64,
}

impl Solution<'_> {
    /// The UVs per corner of the INPUT mesh (`3 f + k`): where faces were
    /// split, each input corner takes the UV of that corner in the sub-face
    /// containing it (for display; exports use the solved mesh exactly).
    pub fn input_corner_uv(&self, input: &TriMesh) -> Vec<[f64; 2]> {
        let (Some(of), Some(ov)) = (&self.original_face, &self.original_vertex) else {
            return self.param.uv.clone();
        };
        let mut uv = vec![[0.0; 2]; 3 * input.n_faces()];
        for (r, tri) in self.mesh.faces().iter().enumerate() {
            let f = of[r] as usize;
            for (k, &v) in tri.iter().enumerate() {
                let o = ov[v as usize];
                if let Some(j) = input.faces()[f].iter().position(|&w| w == o) {
                    uv[3 * f + j] = self.param.uv[3 * r + k];
                }
            }
        }
        uv
    }

    /// Seam edges as ids of the INPUT mesh (seams along inserted edges are dropped).
    pub fn input_seam_edges(&self, input: &TriMesh) -> Vec<u32> {
        let Some(ov) = &self.original_vertex else {
            return self.param.seam_edges.clone();
        };
        let mut out: Vec<u32> = self
            .param
            .seam_edges
            .iter()
            .filter_map(|&e| {
                let [a, b] = self.mesh.edge_vertices(e).map(|v| ov[v as usize]);
                if a == crate::mesh::NONE || b == crate::mesh::NONE {
                    return None;
                }
                input.outgoing(a).find(|&h| input.head(h) == b).map(|h| input.edge(h))
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Solves on `mesh` with `features` (see the module doc).
pub fn solve<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    progress: &mut dyn FnMut(SolveProgress),
) -> Result<Solution<'a>, SolveError> {
    let mut clock = Stopwatch::start();
    let mut refined = split_doubly_constrained(mesh, features);
    let mut refine_seconds = clock.lap();
    let mut attempt = 0;
    let placement = loop {
        let (m, f) = refined.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
        let placement = cones::place_cones(m, f, &options.cones, &mut |p| progress(SolveProgress::Cones(p)))
            .map_err(SolveError::Cones)?;
        let degenerate = zero_angle_cones(&placement);
        if degenerate.is_empty() || attempt == MAX_CONE_REFINEMENTS {
            break placement;
        }
        // Only vertices of `m` are named; lift the refinement one level.
        clock.lap();
        refined = Some(split_around(mesh, features, refined.take(), &degenerate));
        refine_seconds += clock.lap();
        attempt += 1;
    };
    let (mesh, features, splits, original_face, original_vertex) = match refined {
        Some(Refined { mesh: m, features: f, splits, original_face, original_vertex }) => {
            (Cow::Owned(m), Cow::Owned(f), splits, Some(original_face), Some(original_vertex))
        }
        None => (Cow::Borrowed(mesh), Cow::Borrowed(features), 0, None, None),
    };
    let param = param::parametrize(&mesh, &placement, &options.param, &mut |p| progress(SolveProgress::Param(p)))
        .map_err(SolveError::Param)?;
    Ok(Solution { mesh, features, splits, original_face, original_vertex, placement, param, refine_seconds })
}

/// Rounds of local refinement tried when cones of angle 0 appear.
const MAX_CONE_REFINEMENTS: usize = 2;

/// Vertices (of the mesh the placement was computed on) that carry an
/// interior cone of index `k >= 4`, i.e. a cone angle `<= 0`.
fn zero_angle_cones(placement: &ConePlacement) -> Vec<u32> {
    let cm = &placement.cut.mesh;
    let mut out: Vec<u32> = (0..cm.n_vertices() as u32)
        .filter(|&v| placement.k[v as usize] >= 4 && !cm.is_boundary_vertex(v))
        .map(|v| placement.cut.original_vertex[v as usize])
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}
