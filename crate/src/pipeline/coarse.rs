//! Quads of a mesh much finer than their cells are traced on a decimation
//! of it. The cones, the seamless map and above all its rounding cost in
//! proportion to the faces, while the quads need only a few faces per
//! cell: cow subdivided twice (93 k faces) at 3 000 quads spent 95 s in
//! quantization, and its every pass rounded the same few places of a
//! surface a cell spans 30 faces of. The decimation ([`decimate_keeping`]:
//! half-edge collapses ordered by quadric error, so its vertices are the
//! input's) keeps the boundary and every vertex of a feature curve, so the
//! curves are the input's edges, and leaves about [`COARSE_FACES_PER_QUAD`]
//! faces per quad; the quads are then moved onto the input
//! ([`crate::quads::project_onto`]). The CLI's `quads` traces them again
//! on a decimation twice as fine where they fold: the cones of a
//! decimation differ from the input's, and a few land where the quads
//! fold in 3D (measured in `docs/STATUS.md`, session 43).

use super::{quad_length, GridFeatures};
use crate::features::FeatureSet;
use crate::mesh::{decimate_keeping, CollapseLimits, TriMesh, NONE};
use crate::param::quantize::GridSize;

/// Faces per quad a decimation for quads keeps. Cow subdivided once (23 k
/// faces, 7.7 per quad at 3 000) rounds as cleanly as the cow itself.
pub const COARSE_FACES_PER_QUAD: f64 = 8.0;

/// Smallest cosine between a face's normal before and after a collapse of
/// the decimation. The cone placement's 0.5 (60°) flattened tips: at
/// 1 000 quads spot subdivided once got two bow-ties on a horn, bff-face,
/// bff-bunny and teapot subdivided once one each, where the quads traced
/// on the input have none (the teapot one); at 0.8 (37°) only the
/// teapot's.
pub const COARSE_MIN_TURN_COS: f64 = 0.8;

/// Largest distance, in quads, of a kept vertex from the planes of the
/// input faces merged into it (root mean square, [`CollapseLimits`]): the
/// decimation wore tips down otherwise, which the quads then cut across
/// (spot subdivided twice at 1 000 quads: 2.01 % of the diagonal from the
/// input, 1.23 % with this, 1.52 % traced on the input; at 0.05: 1.44 %).
pub const COARSE_MAX_DISTANCE: f64 = 0.02;

/// A decimation of an input mesh that keeps its boundary and feature
/// curves: every input edge between two kept vertices that bounds or is a
/// feature is an edge here too.
pub struct Coarse {
    pub mesh: TriMesh,
    /// Per vertex of `mesh`, the input vertex it is.
    pub vertex: Vec<u32>,
    /// Per input vertex, its vertex in `mesh` ([`NONE`] where collapsed).
    coarse_vertex: Vec<u32>,
}

impl Coarse {
    /// The decimation of `input` to about `faces_per_quad` faces per quad
    /// of `grid` (in the CLI [`COARSE_FACES_PER_QUAD`]) where `input` has
    /// more than twice that, keeping the vertices of the feature edges
    /// `features`; `None` where it has fewer, or the decimation removes
    /// nothing or does not give a valid mesh.
    pub fn for_quads(input: &TriMesh, features: &FeatureSet, grid: GridSize, faces_per_quad: f64) -> Option<Coarse> {
        let quad = quad_length(input, grid);
        let area: f64 = input.face_areas().iter().sum();
        let quads = area / (quad * quad);
        if !(quads.is_finite() && quads > 0.0) || (input.n_faces() as f64) <= 2.0 * faces_per_quad * quads {
            return None;
        }
        let mut keep = vec![false; input.n_vertices()];
        for e in features.edges() {
            for v in input.edge_vertices(e) {
                keep[v as usize] = true;
            }
        }
        // A closed surface of F faces has about F / 2 vertices; fixed ones
        // (boundary, features) each take about one face fewer.
        let fixed = (0..input.n_vertices() as u32).filter(|&v| keep[v as usize] || input.is_boundary_vertex(v)).count();
        let target_faces = faces_per_quad * quads;
        let target_free = ((target_faces - fixed as f64) / 2.0).max(0.0) as usize;
        let limits = CollapseLimits { min_turn_cos: COARSE_MIN_TURN_COS, max_distance: COARSE_MAX_DISTANCE * quad };
        let decimated = decimate_keeping(input, target_free, &keep, limits)?;
        let mut coarse_vertex = vec![NONE; input.n_vertices()];
        for (c, &v) in decimated.vertex.iter().enumerate() {
            coarse_vertex[v as usize] = c as u32;
        }
        let coarse = Coarse { mesh: decimated.mesh, vertex: decimated.vertex, coarse_vertex };
        // Every feature edge is kept (its ends are, and a collapse only
        // removes the vertex it moves).
        features.edges().all(|e| coarse.coarse_edge(input, e).is_some()).then_some(coarse)
    }

    /// The edge of `mesh` that is input edge `e`, if both its ends are kept
    /// and joined.
    fn coarse_edge(&self, input: &TriMesh, e: u32) -> Option<u32> {
        let [a, b] = input.edge_vertices(e).map(|v| self.coarse_vertex[v as usize]);
        if a == NONE || b == NONE {
            return None;
        }
        self.mesh.edge_between(a, b)
    }

    /// The input's feature edges `features` as edges of `mesh`.
    pub fn features(&self, input: &TriMesh, features: &FeatureSet) -> FeatureSet {
        let mut out = FeatureSet::none(&self.mesh);
        for e in features.edges().filter_map(|e| self.coarse_edge(input, e)) {
            out.set(&self.mesh, e, true);
        }
        out
    }

    /// [`GridFeatures`] of the input as those of `mesh`.
    pub fn grid_features(&self, input: &TriMesh, features: &GridFeatures) -> GridFeatures {
        GridFeatures { all: self.features(input, &features.all), detected: self.features(input, &features.detected) }
    }

    /// Feature edges of `mesh` as the input's edges.
    pub fn input_features(&self, input: &TriMesh, features: &FeatureSet) -> FeatureSet {
        let mut out = FeatureSet::none(input);
        for e in features.edges() {
            let [a, b] = self.mesh.edge_vertices(e).map(|v| self.vertex[v as usize]);
            if let Some(e) = input.edge_between(a, b) {
                out.set(input, e, true);
            }
        }
        out
    }
}
