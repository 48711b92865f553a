//! Feature curves: which edges the parametrization must align with, and the
//! mesh cut open along them so every feature becomes a boundary curve
//! (paper section 4: "we cut the mesh along feature curves converting each
//! curve into two boundary curves").
//!
//! [`FeatureSet`] holds the edges; [`detect`] finds sharp creases and
//! filters short fragments; [`grid`] finds the curves a quad grid is too
//! coarse to follow; [`cut`] opens the mesh along them; [`refine`]
//! inserts the vertices some configurations need before an aligned map exists.

mod cut;
mod delaunay;
pub mod detect;
pub mod grid;
mod locate;
mod refine;

pub use cut::{boundary_turning, cut_open, CutMesh};
pub use detect::{detect_sharp, MinLength, SharpDetection, SharpOptions, SharpStats, CREASES};
pub use grid::{chains_near, finer_than_grid};
pub use refine::{
    faces_for_length, refine_for_features, refine_for_features_on, split_around, split_flipped, split_long_edges, RefineCounts, Refined,
    MAX_REFINED_FACES,
};

use crate::mesh::TriMesh;
use locate::VertexLocator;
use std::fmt;

/// Feature edges of a [`TriMesh`], one flag per edge (boundary edges are
/// never flagged: they are aligned anyway).
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureSet {
    is_feature: Vec<bool>,
}

/// Why a feature list could not be applied to a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum FeatureError {
    /// An end point of feature edge `index` matches no mesh vertex.
    NoVertexAt { index: usize, position: [f64; 3] },
    /// Both end points of feature edge `index` match vertices that share no edge.
    NotAnEdge { index: usize, vertices: [u32; 2] },
}

impl fmt::Display for FeatureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeatureError::NoVertexAt { index, position: p } => {
                write!(f, "feature edge {index}: no mesh vertex at ({}, {}, {})", p[0], p[1], p[2])
            }
            FeatureError::NotAnEdge { index, vertices: v } => {
                write!(f, "feature edge {index}: vertices v{} and v{} are not joined by an edge", v[0], v[1])
            }
        }
    }
}

impl std::error::Error for FeatureError {}

impl FeatureSet {
    /// No features.
    pub fn none(mesh: &TriMesh) -> FeatureSet {
        FeatureSet { is_feature: vec![false; mesh.n_edges()] }
    }

    /// Interior edges whose dihedral angle (angle between the two face
    /// normals) exceeds `threshold_degrees` ([`detect::sharp_edges`]).
    pub fn sharp_edges(mesh: &TriMesh, threshold_degrees: f64) -> FeatureSet {
        detect::sharp_edges(mesh, threshold_degrees)
    }

    /// Edges given by the positions of their end points (so the list does not
    /// depend on vertex numbering); a position matches the nearest vertex
    /// within `1e-6` of the bounding-box diagonal.
    pub fn from_positions(mesh: &TriMesh, edges: &[[[f64; 3]; 2]]) -> Result<FeatureSet, FeatureError> {
        let locator = VertexLocator::new(mesh.positions());
        let mut set = FeatureSet::none(mesh);
        for (index, [p, q]) in edges.iter().enumerate() {
            let find = |x: &[f64; 3]| {
                let near = locator.find_all(x);
                if near.is_empty() { Err(FeatureError::NoVertexAt { index, position: *x }) } else { Ok(near) }
            };
            let (ends_p, ends_q) = (find(p)?, find(q)?);
            // Of the vertices at each end, the (nearest) pair joined by an edge.
            let e = ends_p
                .iter()
                .flat_map(|&a| ends_q.iter().map(move |&b| (a, b)))
                .find_map(|(a, b)| mesh.edge_between(a, b))
                .ok_or(FeatureError::NotAnEdge { index, vertices: [ends_p[0], ends_q[0]] })?;
            set.set(mesh, e, true);
        }
        Ok(set)
    }

    /// Marks (or unmarks) edge `e`; boundary edges stay unmarked.
    pub fn set(&mut self, mesh: &TriMesh, e: u32, on: bool) {
        self.is_feature[e as usize] = on && !mesh.is_boundary_edge(e);
    }

    /// Adds every feature of `other` (same mesh).
    pub fn union(&mut self, other: &FeatureSet) {
        for (a, b) in self.is_feature.iter_mut().zip(&other.is_feature) {
            *a |= *b;
        }
    }

    /// These features less those of `other` (same mesh).
    pub fn without(&self, other: &FeatureSet) -> FeatureSet {
        FeatureSet { is_feature: self.is_feature.iter().zip(&other.is_feature).map(|(&a, &b)| a && !b).collect() }
    }

    /// The features also in `other` (same mesh).
    pub fn intersection(&self, other: &FeatureSet) -> FeatureSet {
        FeatureSet { is_feature: self.is_feature.iter().zip(&other.is_feature).map(|(&a, &b)| a && b).collect() }
    }

    /// True when edge `e` is a feature.
    pub fn contains(&self, e: u32) -> bool {
        self.is_feature[e as usize]
    }

    /// Number of feature edges.
    pub fn len(&self) -> usize {
        self.is_feature.iter().filter(|&&f| f).count()
    }

    /// True when there is no feature edge.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of feature edges at each vertex of `mesh`.
    pub fn degrees(&self, mesh: &TriMesh) -> Vec<u32> {
        let mut degree = vec![0u32; mesh.n_vertices()];
        for e in self.edges() {
            for v in mesh.edge_vertices(e) {
                degree[v as usize] += 1;
            }
        }
        degree
    }

    /// The feature edges, ascending.
    pub fn edges(&self) -> impl Iterator<Item = u32> + '_ {
        self.is_feature.iter().enumerate().filter(|(_, &f)| f).map(|(e, _)| e as u32)
    }
}

/// A grid of `n` × `n` unit squares in the xy plane, each split along its
/// diagonal, with height `z(i, j)` at grid point `(i, j)` (tests).
#[cfg(test)]
pub(crate) fn test_grid(n: u32, z: impl Fn(u32, u32) -> f64) -> TriMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            p.push([i as f64, j as f64, z(i, j)]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::from_welded_arrays(p, t).expect("a grid is a valid mesh")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of 12 triangles: every edge between two cube faces is sharp.
    fn cube() -> TriMesh {
        let p = [
            [0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.],
            [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.],
        ];
        let quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
        let tris = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        TriMesh::from_welded_arrays(p.to_vec(), tris).unwrap()
    }

    #[test]
    fn cube_sharp_edges_are_the_twelve_cube_edges() {
        let m = cube();
        let s = FeatureSet::sharp_edges(&m, 60.0);
        assert_eq!(s.len(), 12);
        assert_eq!(FeatureSet::sharp_edges(&m, 95.0).len(), 0);
    }

    #[test]
    fn cutting_the_cube_along_its_edges_gives_six_squares() {
        let m = cube();
        let cut = cut_open(&m, &FeatureSet::sharp_edges(&m, 60.0));
        assert_eq!(cut.mesh.n_components(), 6);
        assert_eq!(cut.mesh.n_vertices(), 24);
        assert_eq!(cut.mesh.boundary_loops().len(), 6);
        for c in 0..6 {
            assert_eq!(cut.mesh.component_euler_characteristic(c), 1);
        }
        for (v, &o) in cut.original_vertex.iter().enumerate() {
            assert_eq!(cut.mesh.position(v as u32), m.position(o));
        }
        for e in 0..cut.mesh.n_edges() as u32 {
            let [a, b] = cut.mesh.edge_vertices(e);
            let mut orig = m.edge_vertices(cut.original_edge[e as usize]);
            let mut mapped = [cut.original_vertex[a as usize], cut.original_vertex[b as usize]];
            orig.sort();
            mapped.sort();
            assert_eq!(orig, mapped);
        }
    }

    #[test]
    fn a_feature_chain_opens_a_slit_and_a_lone_edge_stays_closed() {
        let m = cube();
        let mut lone = FeatureSet::none(&m);
        lone.set(&m, 0, true);
        let cut = cut_open(&m, &lone);
        assert_eq!(cut.mesh.n_vertices(), 8);
        assert!(cut.mesh.boundary_loops().is_empty(), "a lone interior edge cannot be opened");
        // Two cube edges meeting at vertex 0: (0, 1) and (0, 3).
        let chain = FeatureSet::from_positions(&m, &[[[1., 0., 0.], [0., 0., 0.]], [[0., 0., 0.], [0., 1., 0.]]]).unwrap();
        let cut = cut_open(&m, &chain);
        assert_eq!(cut.mesh.n_vertices(), 9, "the middle vertex of the chain splits in two");
        assert_eq!(cut.mesh.boundary_loops().len(), 1);
        assert_eq!(cut.mesh.euler_characteristic(), 1);
    }

    #[test]
    fn features_by_position_match_vertices_and_reject_strangers() {
        let m = cube();
        let s = FeatureSet::from_positions(&m, &[[[0., 0., 0.], [1., 0., 0.]]]).unwrap();
        assert_eq!(s.len(), 1);
        let far = FeatureSet::from_positions(&m, &[[[0.5, 0.5, 0.5], [1., 0., 0.]]]);
        assert!(matches!(far, Err(FeatureError::NoVertexAt { index: 0, .. })));
        let diagonal = FeatureSet::from_positions(&m, &[[[0., 0., 0.], [1., 1., 1.]]]);
        assert!(matches!(diagonal, Err(FeatureError::NotAnEdge { index: 0, .. })));
    }

    #[test]
    fn features_by_position_find_the_edge_among_coincident_vertices() {
        // A cube and a closed tetrahedron touching it at the cube's corner
        // (0, 0, 0) with a vertex of its own there (vertices 0 and 8).
        let c = cube();
        let mut p = c.positions().to_vec();
        p.extend([[0., 0., 0.], [-1., 0., 0.], [0., -1., 0.], [0., 0., -1.]]);
        let mut tris = c.faces().to_vec();
        tris.extend([[8, 10, 9], [8, 9, 11], [8, 11, 10], [9, 10, 11]]);
        let m = TriMesh::from_welded_arrays(p, tris).unwrap();
        for edge in [[[0., 0., 0.], [-1., 0., 0.]], [[1., 0., 0.], [0., 0., 0.]]] {
            let s = FeatureSet::from_positions(&m, &[edge]).expect("the edge exists at one of the coincident vertices");
            assert_eq!(s.len(), 1);
        }
    }
}
