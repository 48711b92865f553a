//! Feature curves: which edges the parametrization must align with, and the
//! mesh cut open along them so every feature becomes a boundary curve
//! (paper section 4: "we cut the mesh along feature curves converting each
//! curve into two boundary curves").

use crate::mesh::{TriMesh, UnionFind, NONE};
use crate::operators;
use std::collections::HashMap;
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
    /// normals) exceeds `threshold_degrees`.
    pub fn sharp_edges(mesh: &TriMesh, threshold_degrees: f64) -> FeatureSet {
        let threshold = threshold_degrees.to_radians();
        let mut set = FeatureSet::none(mesh);
        let normals = operators::face_normals(mesh.positions(), mesh.faces());
        for e in 0..mesh.n_edges() as u32 {
            let [h, t] = mesh.edge_halfedges(e);
            if let (Some(f), Some(g)) = (mesh.face(h), mesh.face(t)) {
                let (a, b) = (normals[f as usize], normals[g as usize]);
                let cos = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0);
                set.is_feature[e as usize] = cos.acos() > threshold;
            }
        }
        set
    }

    /// Edges given by the positions of their end points (so the list does not
    /// depend on vertex numbering); a position matches the nearest vertex
    /// within `1e-6` of the bounding-box diagonal.
    pub fn from_positions(mesh: &TriMesh, edges: &[[[f64; 3]; 2]]) -> Result<FeatureSet, FeatureError> {
        let locator = VertexLocator::new(mesh.positions());
        let mut set = FeatureSet::none(mesh);
        for (index, [p, q]) in edges.iter().enumerate() {
            let find = |x: &[f64; 3]| locator.find(x).ok_or(FeatureError::NoVertexAt { index, position: *x });
            let (a, b) = (find(p)?, find(q)?);
            let e = mesh
                .outgoing(a)
                .find(|&h| mesh.head(h) == b)
                .map(|h| mesh.edge(h))
                .ok_or(FeatureError::NotAnEdge { index, vertices: [a, b] })?;
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

    /// The feature edges, ascending.
    pub fn edges(&self) -> impl Iterator<Item = u32> + '_ {
        self.is_feature.iter().enumerate().filter(|(_, &f)| f).map(|(e, _)| e as u32)
    }
}

/// A mesh cut open along its feature edges.
#[derive(Clone, Debug)]
pub struct CutMesh {
    /// The cut mesh: each feature edge became two boundary edges.
    pub mesh: TriMesh,
    /// Cut vertex → vertex of the original mesh.
    pub original_vertex: Vec<u32>,
    /// Cut edge → edge of the original mesh.
    pub original_edge: Vec<u32>,
}

impl CutMesh {
    /// True when boundary edge `e` of the cut mesh comes from a feature
    /// (rather than from a boundary of the original mesh).
    pub fn is_feature_edge(&self, original: &TriMesh, e: u32) -> bool {
        self.mesh.is_boundary_edge(e) && !original.is_boundary_edge(self.original_edge[e as usize])
    }
}

/// Cuts `mesh` open along `features`: the corners around each vertex are
/// split into the sectors separated by feature edges, one new vertex per
/// sector. Faces keep their indices. An isolated feature edge whose two ends
/// are interior and touch no other feature cannot be opened (it would become
/// two edges between the same two vertices) and is left closed.
pub fn cut_open(mesh: &TriMesh, features: &FeatureSet) -> CutMesh {
    let mut degree = vec![0u32; mesh.n_vertices()];
    for e in features.edges() {
        for v in mesh.edge_vertices(e) {
            degree[v as usize] += 1;
        }
    }
    let splits = |v: u32| degree[v as usize] >= 2 || mesh.is_boundary_vertex(v);
    let is_cut = |e: u32| features.contains(e) && mesh.edge_vertices(e).iter().any(|&v| splits(v));
    // Union corners (3 f + k) across every interior non-feature edge.
    let n_corners = 3 * mesh.n_faces();
    let mut corners = UnionFind::new(n_corners);
    for e in 0..mesh.n_edges() as u32 {
        if is_cut(e) || mesh.is_boundary_edge(e) {
            continue;
        }
        let [h, t] = mesh.edge_halfedges(e);
        // Halfedge h = 3f + k runs corner k -> k + 1; its twin runs the other way.
        let (ht, hh) = (h, 3 * (h / 3) + (h % 3 + 1) % 3);
        let (tt, th) = (t, 3 * (t / 3) + (t % 3 + 1) % 3);
        for (a, b) in [(ht, th), (hh, tt)] {
            corners.union(a, b);
        }
    }
    let mut new_id = vec![NONE; n_corners];
    let mut original_vertex = Vec::new();
    let mut faces = Vec::with_capacity(mesh.n_faces());
    for (f, tri) in mesh.faces().iter().enumerate() {
        let mut out = [0u32; 3];
        for k in 0..3 {
            let r = corners.find((3 * f + k) as u32) as usize;
            if new_id[r] == NONE {
                new_id[r] = original_vertex.len() as u32;
                original_vertex.push(tri[k]);
            }
            out[k] = new_id[r];
        }
        faces.push(out);
    }
    let positions = original_vertex.iter().map(|&v| mesh.position(v)).collect();
    let cut = TriMesh::from_welded_arrays(positions, faces)
        .expect("cutting a valid mesh along edges keeps it manifold and oriented");
    // The builder renumbers vertices by first use; follow its numbering.
    let original_vertex = cut.welded_to_source().iter().map(|&s| original_vertex[s as usize]).collect();
    let original_edge = (0..cut.n_edges() as u32)
        .map(|e| {
            let h = cut.edge_halfedges(e)[0];
            mesh.edge(h) // face halfedge numbering is shared (3 f + k)
        })
        .collect();
    CutMesh { mesh: cut, original_vertex, original_edge }
}

/// A mesh refined so that no triangle has two constrained (feature or
/// boundary) edges, with its features carried over.
#[derive(Clone, Debug)]
pub struct Refined {
    pub mesh: TriMesh,
    pub features: FeatureSet,
    /// Refined face → the input face it lies in.
    pub original_face: Vec<u32>,
    /// Refined vertex → input vertex (`NONE` for inserted midpoints).
    pub original_vertex: Vec<u32>,
    /// Vertices inserted (edge midpoints and face centroids).
    pub splits: usize,
}

/// Splits, at its midpoint, the free edge of every triangle whose other two
/// edges are both constrained: an aligned map puts such a triangle's three
/// corners on isolines, and where both lie on one isoline the triangle
/// would have zero UV area. Returns `None` when no triangle needs it.
pub fn split_doubly_constrained(mesh: &TriMesh, features: &FeatureSet) -> Option<Refined> {
    let constrained = |m: &TriMesh, f: &FeatureSet, e: u32| m.is_boundary_edge(e) || f.contains(e);
    let mut current: Option<Refined> = None;
    for _pass in 0..4 {
        let (m, f) = match &current {
            Some(r) => (&r.mesh, &r.features),
            None => (mesh, features),
        };
        // Edges to split: the free edge of faces with two constrained edges,
        // at most one per face and pass (a face next to two chosen edges
        // waits for the next pass).
        let mut split = vec![false; m.n_edges()];
        let mut claimed = vec![false; m.n_faces()];
        let mut any = false;
        for face in 0..m.n_faces() as u32 {
            let hs = m.face_halfedges(face);
            let c: Vec<bool> = hs.iter().map(|&h| constrained(m, f, m.edge(h))).collect();
            if c.iter().filter(|&&x| x).count() != 2 {
                continue;
            }
            let free = hs[c.iter().position(|&x| !x).unwrap()];
            let e = m.edge(free);
            let other = m.face(m.twin(free)).expect("the free edge is interior");
            if split[e as usize] || claimed[face as usize] || claimed[other as usize] {
                continue;
            }
            split[e as usize] = true;
            claimed[face as usize] = true;
            claimed[other as usize] = true;
            any = true;
        }
        if !any {
            break;
        }
        // Rebuild the triangle list with a midpoint on every split edge.
        let mut positions = m.positions().to_vec();
        let mut mid = vec![NONE; m.n_edges()];
        for e in 0..m.n_edges() {
            if split[e] {
                let [a, b] = m.edge_vertices(e as u32);
                mid[e] = positions.len() as u32;
                positions.push(crate::vec3::midpoint(m.position(a), m.position(b)));
            }
        }
        let mut triangles = Vec::with_capacity(m.n_faces() + 2 * split.iter().filter(|&&x| x).count());
        let mut parent_face = Vec::with_capacity(triangles.capacity());
        let face_origin = |face: u32| current.as_ref().map_or(face, |r| r.original_face[face as usize]);
        for face in 0..m.n_faces() as u32 {
            let hs = m.face_halfedges(face);
            let v = m.faces()[face as usize];
            // Halfedge k runs corner k -> k+1; claims allow one split edge per face.
            match (0..3).find(|&k| mid[m.edge(hs[k]) as usize] != NONE) {
                Some(k) => {
                    let x = mid[m.edge(hs[k]) as usize];
                    let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                    triangles.push([a, x, c]);
                    triangles.push([x, b, c]);
                    parent_face.extend([face_origin(face); 2]);
                }
                None => {
                    triangles.push(v);
                    parent_face.push(face_origin(face));
                }
            }
        }
        let inserted = split.iter().filter(|&&x| x).count();
        current = Some(rebuild(m, f, current.as_ref(), positions, triangles, parent_face, inserted));
    }
    current.map(own_source)
}

/// Splits every face around each vertex of `vertices` at its centroid
/// (1 → 3), on top of the refinement `current` of `mesh` (if any): the
/// inserted interior vertices can carry curvature a lone vertex cannot
/// (a cone of index 4 has angle 0). Features are kept.
pub fn split_around(mesh: &TriMesh, features: &FeatureSet, current: Option<Refined>, vertices: &[u32]) -> Refined {
    let (m, f) = match &current {
        Some(r) => (&r.mesh, &r.features),
        None => (mesh, features),
    };
    let mut marked = vec![false; m.n_faces()];
    for &v in vertices {
        for h in m.outgoing(v) {
            if let Some(face) = m.face(h) {
                marked[face as usize] = true;
            }
        }
    }
    let face_origin = |face: u32| current.as_ref().map_or(face, |r| r.original_face[face as usize]);
    let mut positions = m.positions().to_vec();
    let mut triangles = Vec::with_capacity(m.n_faces() + 2 * marked.iter().filter(|&&x| x).count());
    let mut parent_face = Vec::with_capacity(triangles.capacity());
    let mut inserted = 0;
    for face in 0..m.n_faces() as u32 {
        let [a, b, c] = m.faces()[face as usize];
        if marked[face as usize] {
            let p = [a, b, c].map(|v| m.position(v));
            let x = positions.len() as u32;
            positions.push([0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0));
            triangles.extend([[a, b, x], [b, c, x], [c, a, x]]);
            parent_face.extend([face_origin(face); 3]);
            inserted += 1;
        } else {
            triangles.push([a, b, c]);
            parent_face.push(face_origin(face));
        }
    }
    own_source(rebuild(m, f, current.as_ref(), positions, triangles, parent_face, inserted))
}

/// The refined mesh from new arrays over `m` (whose vertices keep their
/// indices; new ones follow), with `m`'s features carried over (feature
/// edges are never split) and the maps to the input composed with `current`.
fn rebuild(
    m: &TriMesh,
    f: &FeatureSet,
    current: Option<&Refined>,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    original_face: Vec<u32>,
    inserted: usize,
) -> Refined {
    let refined = TriMesh::from_welded_arrays(positions, triangles).expect("inserting vertices inside faces or edges keeps the mesh valid");
    let mut features = FeatureSet::none(&refined);
    let old = |v: u32| refined.welded_to_source()[v as usize];
    for e in 0..refined.n_edges() as u32 {
        let [a, b] = refined.edge_vertices(e).map(old);
        if (a as usize) < m.n_vertices() && (b as usize) < m.n_vertices() {
            if let Some(h) = m.outgoing(a).find(|&h| m.head(h) == b) {
                if f.contains(m.edge(h)) {
                    features.set(&refined, e, true);
                }
            }
        }
    }
    let splits = current.map_or(0, |r| r.splits) + inserted;
    let original_vertex = refined
        .welded_to_source()
        .iter()
        .map(|&src| if (src as usize) >= m.n_vertices() { NONE } else { current.map_or(src, |r| r.original_vertex[src as usize]) })
        .collect();
    Refined { mesh: refined, features, splits, original_face, original_vertex }
}

/// Rebuilds a refinement from its own arrays so the mesh is its own source
/// (`source_to_welded` is the identity; edge ids are unchanged).
fn own_source(r: Refined) -> Refined {
    let mesh = TriMesh::from_welded_arrays(r.mesh.positions().to_vec(), r.mesh.faces().to_vec())
        .expect("rebuilding a valid mesh from its own arrays");
    debug_assert!((0..mesh.n_edges() as u32).all(|e| mesh.edge_vertices(e) == r.mesh.edge_vertices(e)));
    Refined { mesh, ..r }
}

/// Finds mesh vertices by position with a uniform hash grid.
struct VertexLocator<'a> {
    positions: &'a [[f64; 3]],
    cell: f64,
    origin: [f64; 3],
    grid: HashMap<[i64; 3], Vec<u32>>,
    tolerance: f64,
}

impl<'a> VertexLocator<'a> {
    fn new(positions: &'a [[f64; 3]]) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in positions {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        let diag = ((0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>()).sqrt().max(f64::MIN_POSITIVE);
        let tolerance = 1e-6 * diag;
        let cell = 4.0 * tolerance;
        let mut locator = VertexLocator { positions, cell, origin: lo, grid: HashMap::new(), tolerance };
        for (v, p) in positions.iter().enumerate() {
            let key = locator.key(p);
            locator.grid.entry(key).or_default().push(v as u32);
        }
        locator
    }

    fn key(&self, p: &[f64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|i| ((p[i] - self.origin[i]) / self.cell).floor() as i64)
    }

    /// The nearest vertex within the tolerance, if any.
    fn find(&self, p: &[f64; 3]) -> Option<u32> {
        let k = self.key(p);
        let mut best: Option<(f64, u32)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &v in self.grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]).into_iter().flatten() {
                        let q = self.positions[v as usize];
                        let d = ((0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>()).sqrt();
                        if d <= self.tolerance && best.is_none_or(|(bd, _)| d < bd) {
                            best = Some((d, v));
                        }
                    }
                }
            }
        }
        best.map(|(_, v)| v)
    }
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
}
