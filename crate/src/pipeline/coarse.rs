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
use crate::mesh::{decimate_keeping, CollapseLimits, NearestFace, TriMesh, NONE};
use crate::param::quantize::GridSize;
use crate::vec3::{barycentric_point, cross, dot, sub, V3};

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
        if !Coarse::wanted(input, grid, faces_per_quad) {
            return None;
        }
        let quad = quad_length(input, grid);
        let quads = quads_on(input, quad);
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

    /// Whether `input` has more than twice `faces_per_quad` faces per quad
    /// of `grid` ([`Coarse::for_quads`] decimates it).
    pub fn wanted(input: &TriMesh, grid: GridSize, faces_per_quad: f64) -> bool {
        let quads = quads_on(input, quad_length(input, grid));
        quads.is_finite() && quads > 0.0 && (input.n_faces() as f64) > 2.0 * faces_per_quad * quads
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

/// How many quads of edge `quad` cover `mesh`'s area.
fn quads_on(mesh: &TriMesh, quad: f64) -> f64 {
    mesh.face_areas().iter().sum::<f64>() / (quad * quad)
}

/// Per face corner of `onto`, the value of the piecewise linear per-corner
/// `values` of `from` (a decimation's map, say) at that corner: each face of
/// `onto` takes the linear function of the face of `from` nearest its
/// centroid (among those facing its way), extended over the plane, so that
/// its three corners stay in one chart of a map with seams. Where `from`
/// is `onto`'s decimation, neighbours that take different faces of `from`
/// differ at their shared corners by the distance to `from` times the
/// map's change of gradient (or, across a seam, by the seam's transition).
pub fn corner_values_onto(from: &TriMesh, values: &[[f64; 2]], onto: &TriMesh) -> Vec<[f64; 2]> {
    debug_assert_eq!(values.len(), 3 * from.n_faces());
    if from.n_faces() == 0 {
        return vec![[0.0; 2]; 3 * onto.n_faces()];
    }
    let mut locator = NearestFace::new(from);
    let normals = onto.face_normals();
    let mut out = Vec::with_capacity(3 * onto.n_faces());
    for (f, t) in onto.faces().iter().enumerate() {
        let corners = t.map(|v| onto.position(v));
        let centroid = barycentric_point(&corners, [1.0 / 3.0; 3]);
        let g = locator.nearest(centroid, Some(normals[f])).expect("a mesh with faces").face as usize;
        let triangle = from.faces()[g].map(|v| from.position(v));
        for p in corners {
            let bary = plane_barycentric(p, &triangle);
            let value = |k: usize| (0..3).map(|i| bary[i] * values[3 * g + i][k]).sum::<f64>();
            out.push([value(0), value(1)]);
        }
    }
    out
}

/// The barycentric coordinates (any sign) of `p`'s projection onto the
/// plane of `t`; those of the nearest point of `t` where `t` is degenerate.
fn plane_barycentric(p: V3, t: &[V3; 3]) -> [f64; 3] {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let area2 = dot(n, n);
    if !(area2 > 0.0) {
        return crate::vec3::closest_point_barycentric(p, t);
    }
    let a = dot(cross(sub(t[2], t[1]), sub(p, t[1])), n) / area2;
    let b = dot(cross(sub(t[0], t[2]), sub(p, t[2])), n) / area2;
    [a, b, 1.0 - a - b]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A linear function of position on a decimation of a plane, carried
    /// back to the plane's triangles, is that function at their corners.
    #[test]
    fn a_linear_map_of_a_decimated_plane_comes_back_exactly() {
        let fine = TriMesh::from_raw(&shapes::grid(16, 12, |x, y| [x, y, 0.3 * x - 0.2 * y])).unwrap();
        let keep = vec![false; fine.n_vertices()];
        let limits = CollapseLimits { min_turn_cos: 0.5, max_distance: f64::INFINITY };
        let coarse = decimate_keeping(&fine, 30, &keep, limits).expect("decimates").mesh;
        assert!(coarse.n_faces() < fine.n_faces() / 2, "{} of {} faces", coarse.n_faces(), fine.n_faces());
        let map = |p: V3| [2.0 * p[0] - p[1] + 0.5, p[0] + 3.0 * p[2]];
        let values: Vec<[f64; 2]> = coarse.faces().iter().flat_map(|t| t.map(|v| map(coarse.position(v)))).collect();
        let carried = corner_values_onto(&coarse, &values, &fine);
        assert_eq!(carried.len(), 3 * fine.n_faces());
        for (c, got) in carried.iter().enumerate() {
            let want = map(fine.position(fine.faces()[c / 3][c % 3]));
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12, "corner {c}: {got:?} for {want:?}");
        }
    }
}
