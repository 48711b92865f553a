//! Local refinement that makes a feature set solvable. An aligned seamless
//! map puts every feature and boundary edge on an isoline; some
//! configurations admit no such map on the mesh as given, but do after a
//! few vertices are inserted:
//! * a lone interior feature edge (both ends interior, touching no other
//!   feature) cannot be cut open ([`super::cut_open`] would make two edges
//!   between the same vertices): its midpoint is inserted, and the two
//!   halves open into a slit;
//! * a triangle with three constrained (feature or boundary) edges cannot
//!   have all three on isolines without collapsing: it is split at its centroid;
//! * a triangle with two constrained edges has all three corners on
//!   isolines, and collapses where two of them lie on one: its free edge is
//!   split at its midpoint;
//! * a region enclosed by features with no interior vertex has no room for
//!   a cone: where its rounded boundary corners do not sum to `4 chi`
//!   (Gauss-Bonnet, section 4), no aligned map exists; its largest face is
//!   split at its centroid, which gives it an interior vertex;
//! * a vertex that would need a cone of angle 0 ([`split_around`], on
//!   request of the cone stage): the faces around it are split at their centroids.
//!
//! Two refinements serve the map rather than the features: triangles a map
//! left flipped ([`split_flipped`]), and edges longer than a length
//! ([`split_long_edges`]: a low-poly mesh has too few vertices for a map
//! fine enough to trace quads on).
//!
//! Feature edges are only ever split along themselves, so the refined
//! features are exactly the pieces of the input features.

use super::cut::{boundary_turning, cut_open};
use super::delaunay::flip_coplanar;
use super::FeatureSet;
use crate::mesh::{TriMesh, NONE};
use serde::Serialize;

/// Splits made by the refinement, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RefineCounts {
    /// Lone interior feature edges split at their midpoint (they open into a slit).
    pub lone_edges: usize,
    /// Triangles with three constrained edges split at their centroid.
    pub triply_constrained: usize,
    /// Free edges of triangles with two constrained edges split at their midpoint.
    pub doubly_constrained: usize,
    /// Regions enclosed by features without an interior vertex and with
    /// inconsistent corners, given one (largest face split at its centroid).
    pub enclosed_regions: usize,
    /// Faces split at their centroid around vertices that needed a cone of angle 0.
    pub zero_angle_faces: usize,
    /// Longest edges of triangles a map left flipped, split at their midpoint.
    pub flipped_edges: usize,
    /// Edges longer than the asked maximum, split at their midpoint ([`split_long_edges`]).
    pub long_edges: usize,
    /// Edges between coplanar triangles flipped to make them Delaunay ([`split_long_edges`]).
    pub coplanar_flips: usize,
}

impl RefineCounts {
    pub(crate) fn add(&mut self, o: &RefineCounts) {
        self.lone_edges += o.lone_edges;
        self.triply_constrained += o.triply_constrained;
        self.doubly_constrained += o.doubly_constrained;
        self.enclosed_regions += o.enclosed_regions;
        self.zero_angle_faces += o.zero_angle_faces;
        self.flipped_edges += o.flipped_edges;
        self.long_edges += o.long_edges;
        self.coplanar_flips += o.coplanar_flips;
    }
}

/// A refinement of an input mesh, with its features carried over.
#[derive(Clone, Debug)]
pub struct Refined {
    pub mesh: TriMesh,
    pub features: FeatureSet,
    /// Refined face → the input face it lies in.
    pub original_face: Vec<u32>,
    /// Refined vertex → input vertex (`NONE` for inserted vertices).
    pub original_vertex: Vec<u32>,
    /// Refined edge → the input edge it is (a piece of), `NONE` for edges
    /// inside input faces.
    pub original_edge: Vec<u32>,
    /// Vertices inserted (edge midpoints and face centroids).
    pub splits: usize,
    pub counts: RefineCounts,
}

/// Passes of [`refine_for_features`]; each resolves every configuration it
/// finds unless two claim the same face, which then waits for the next.
const MAX_PASSES: usize = 16;

/// Refines `mesh` until none of the configurations of the module doc is
/// left (or [`MAX_PASSES`] passes ran). Returns `None` when nothing needs it.
pub fn refine_for_features(mesh: &TriMesh, features: &FeatureSet) -> Option<Refined> {
    refine_for_features_on(mesh, features, None)
}

/// [`refine_for_features`] on top of the refinement `current` of `mesh`
/// (`None`: the input itself); `current` when nothing more needs it.
pub fn refine_for_features_on(
    mesh: &TriMesh,
    features: &FeatureSet,
    mut current: Option<Refined>,
) -> Option<Refined> {
    for _ in 0..MAX_PASSES {
        let (m, f) = current.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
        let mut plan = Splits::new(m);
        plan_local(m, f, &mut plan);
        if plan.is_empty() {
            plan_enclosed(m, f, &mut plan);
        }
        if plan.is_empty() {
            break;
        }
        current = Some(plan.apply(m, f, current.as_ref()));
    }
    current
}

/// Splits every face around each vertex of `vertices` at its centroid
/// (1 → 3), on top of the refinement `current` of `mesh` (if any): the
/// inserted interior vertices can carry curvature a lone vertex cannot
/// (a cone of index 4 has angle 0). Features are kept.
pub fn split_around(mesh: &TriMesh, features: &FeatureSet, current: Option<Refined>, vertices: &[u32]) -> Refined {
    let (m, f) = current.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
    let mut plan = Splits::new(m);
    for &v in vertices {
        for face in m.vertex_faces(v) {
            if plan.centroid(face) {
                plan.counts.zero_angle_faces += 1;
            }
        }
    }
    plan.apply(m, f, current.as_ref())
}

/// Splits the longest edge of each face of `faces` (a map left them
/// flipped) at its midpoint, on top of the refinement `current` of `mesh`:
/// a long edge between far-apart constrained vertices is what a coarse map
/// cannot bend (a centroid keeps it). Faces beside an edge split in the same
/// call are skipped. Features are kept (a split feature edge gives two).
pub fn split_flipped(mesh: &TriMesh, features: &FeatureSet, current: Option<Refined>, faces: &[u32]) -> Refined {
    let (m, f) = current.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
    let mut plan = Splits::new(m);
    let lengths = edge_lengths(m);
    for &face in faces {
        if plan.edge(m, longest_edge(m, &lengths, face)) {
            plan.counts.flipped_edges += 1;
        }
    }
    plan.apply(m, f, current.as_ref())
}

/// [`split_long_edges`] stops splitting once the mesh has more faces than
/// this, however long its edges still are (a length far below the mesh's
/// size would otherwise fill memory): use [`faces_for_length`] to check a
/// length first.
pub const MAX_REFINED_FACES: usize = 1_000_000;

/// About how many faces `mesh` has once split down to edges of `length`:
/// its area over that of an equilateral triangle of that edge.
pub fn faces_for_length(mesh: &TriMesh, length: f64) -> f64 {
    mesh.face_areas().iter().sum::<f64>() / (3f64.sqrt() / 4.0 * length * length)
}

/// Passes of [`split_long_edges`]: each halves the longest edge of every
/// face it may; 48 passes take an edge down by far more than any mesh
/// needs (a face may wait for a neighbour's split).
const MAX_LENGTH_PASSES: usize = 48;

/// Splits edges of `mesh` (on top of its refinement `current`, if any)
/// longer than `max_length` at their midpoints, longest first, until none
/// is left; between passes, edges between coplanar triangles are flipped to
/// make them Delaunay ([`flip_coplanar`]), so that a flat region's long thin
/// triangles give well-shaped small ones instead of thinner strips. The
/// surface, its features and its boundary are unchanged. `current` when no
/// edge is that long; splitting stops past [`MAX_REFINED_FACES`] faces.
pub fn split_long_edges(mesh: &TriMesh, features: &FeatureSet, mut current: Option<Refined>, max_length: f64) -> Option<Refined> {
    if long_edges(current.as_ref().map_or(mesh, |r| &r.mesh), max_length).is_empty() {
        return current;
    }
    current = flip_coplanar(mesh, features, current);
    for _ in 0..MAX_LENGTH_PASSES {
        let (m, f) = current.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
        let long = long_edges(m, max_length);
        if long.is_empty() || m.n_faces() > MAX_REFINED_FACES {
            break;
        }
        let mut plan = Splits::new(m);
        for e in long {
            if plan.edge(m, e) {
                plan.counts.long_edges += 1;
            }
        }
        current = flip_coplanar(mesh, features, Some(plan.apply(m, f, current.as_ref())));
    }
    current
}

/// The longest edge of every face of `m` that is longer than `max_length`, longest first.
fn long_edges(m: &TriMesh, max_length: f64) -> Vec<u32> {
    let lengths = edge_lengths(m);
    let mut long: Vec<u32> =
        (0..m.n_faces() as u32).map(|face| longest_edge(m, &lengths, face)).filter(|&e| lengths[e as usize] > max_length).collect();
    long.sort_unstable_by(|&a, &b| lengths[b as usize].total_cmp(&lengths[a as usize]).then(a.cmp(&b)));
    long.dedup();
    long
}

/// The length of every edge of `m`.
fn edge_lengths(m: &TriMesh) -> Vec<f64> {
    (0..m.n_edges() as u32).map(|e| m.edge_length(e)).collect()
}

/// The longest edge of `face` by `lengths` (the last of its halfedges' among equals).
fn longest_edge(m: &TriMesh, lengths: &[f64], face: u32) -> u32 {
    let edges = m.face_halfedges(face).map(|h| m.edge(h));
    edges.into_iter().max_by(|&a, &b| lengths[a as usize].total_cmp(&lengths[b as usize])).expect("a face has three edges")
}

/// True when edge `e` of `m` is a feature or boundary edge.
fn constrained(m: &TriMesh, f: &FeatureSet, e: u32) -> bool {
    m.is_boundary_edge(e) || f.contains(e)
}

/// Plans the splits for lone feature edges and for triangles with two or
/// three constrained edges.
fn plan_local(m: &TriMesh, f: &FeatureSet, plan: &mut Splits) {
    let degree = f.degrees(m);
    let lone = |v: u32| degree[v as usize] == 1 && !m.is_boundary_vertex(v);
    for e in f.edges() {
        if m.edge_vertices(e).into_iter().all(lone) && plan.edge(m, e) {
            plan.counts.lone_edges += 1;
        }
    }
    for face in 0..m.n_faces() as u32 {
        let hs = m.face_halfedges(face);
        let c = hs.map(|h| constrained(m, f, m.edge(h)));
        match c.iter().filter(|&&x| x).count() {
            3 => plan.counts.triply_constrained += usize::from(plan.centroid(face)),
            2 => {
                let free = m.edge(hs[c.iter().position(|&x| !x).expect("one edge is free")]);
                if plan.edge(m, free) {
                    plan.counts.doubly_constrained += 1;
                }
            }
            _ => {}
        }
    }
}

/// Plans a centroid split in every region enclosed by features (component
/// of the cut mesh) that has no interior vertex and whose rounded boundary
/// turning does not sum to `4 chi`.
fn plan_enclosed(m: &TriMesh, f: &FeatureSet, plan: &mut Splits) {
    let cut = cut_open(m, f);
    let cm = &cut.mesh;
    let k = boundary_turning(cm);
    let nc = cm.n_components();
    let mut has_interior = vec![false; nc];
    let mut k_sum = vec![0i64; nc];
    for v in 0..cm.n_vertices() as u32 {
        let c = cm.vertex_component(v);
        has_interior[c] |= !cm.is_boundary_vertex(v);
        k_sum[c] += k[v as usize] as i64;
    }
    // Largest face of each region that needs a vertex (faces keep their ids in the cut).
    let mut largest: Vec<Option<(f64, u32)>> = vec![None; nc];
    let areas = m.face_areas();
    for face in 0..m.n_faces() as u32 {
        let c = cm.face_components()[face as usize] as usize;
        if has_interior[c] || k_sum[c] == 4 * cm.component_euler_characteristic(c) {
            continue;
        }
        if largest[c].is_none_or(|(a, _)| areas[face as usize] > a) {
            largest[c] = Some((areas[face as usize], face));
        }
    }
    for (_, face) in largest.into_iter().flatten() {
        if plan.centroid(face) {
            plan.counts.enclosed_regions += 1;
        }
    }
}

/// One pass of splits on a mesh: edges split at their midpoint, faces at
/// their centroid. A face is claimed by at most one split (so a face has at
/// most one split edge, and a centroid face none).
struct Splits {
    edge: Vec<bool>,
    centroid: Vec<bool>,
    claimed: Vec<bool>,
    counts: RefineCounts,
}

impl Splits {
    fn new(m: &TriMesh) -> Splits {
        Splits { edge: vec![false; m.n_edges()], centroid: vec![false; m.n_faces()], claimed: vec![false; m.n_faces()], counts: RefineCounts::default() }
    }

    fn is_empty(&self) -> bool {
        !self.claimed.iter().any(|&c| c)
    }

    /// Plans splitting edge `e`; false when a face next to it is claimed
    /// by another split (or `e` is already planned).
    fn edge(&mut self, m: &TriMesh, e: u32) -> bool {
        if self.edge[e as usize] {
            return false;
        }
        let faces: Vec<u32> = m.edge_halfedges(e).iter().filter_map(|&h| m.face(h)).collect();
        if faces.iter().any(|&g| self.claimed[g as usize]) {
            return false;
        }
        for g in faces {
            self.claimed[g as usize] = true;
        }
        self.edge[e as usize] = true;
        true
    }

    /// Plans splitting face `face` at its centroid; false when it is claimed.
    fn centroid(&mut self, face: u32) -> bool {
        if self.claimed[face as usize] {
            return false;
        }
        self.claimed[face as usize] = true;
        self.centroid[face as usize] = true;
        true
    }

    /// The refinement of `m` (with features `f`, itself the refinement
    /// `current` of the input, if any) by these splits. Vertices of `m` keep
    /// their indices; inserted ones follow.
    fn apply(self, m: &TriMesh, f: &FeatureSet, current: Option<&Refined>) -> Refined {
        let mut positions = m.positions().to_vec();
        // Midpoint vertex of each split edge, and the edge each midpoint splits.
        let mut mid = vec![NONE; m.n_edges()];
        let mut mid_of = Vec::new();
        for e in 0..m.n_edges() {
            if self.edge[e] {
                let [a, b] = m.edge_vertices(e as u32);
                mid[e] = positions.len() as u32;
                mid_of.push(e as u32);
                positions.push(crate::vec3::midpoint(m.position(a), m.position(b)));
            }
        }
        let mut triangles = Vec::with_capacity(m.n_faces() + 2 * self.claimed.iter().filter(|&&c| c).count());
        let mut parent = Vec::with_capacity(triangles.capacity());
        for face in 0..m.n_faces() as u32 {
            let v = m.faces()[face as usize];
            let hs = m.face_halfedges(face);
            if self.centroid[face as usize] {
                let p = v.map(|x| m.position(x));
                let x = positions.len() as u32;
                positions.push([0, 1, 2].map(|i| (p[0][i] + p[1][i] + p[2][i]) / 3.0));
                triangles.extend([[v[0], v[1], x], [v[1], v[2], x], [v[2], v[0], x]]);
                parent.extend([face; 3]);
            } else if let Some(k) = (0..3).find(|&k| mid[m.edge(hs[k]) as usize] != NONE) {
                // Halfedge k runs corner k -> k + 1.
                let x = mid[m.edge(hs[k]) as usize];
                let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                triangles.extend([[a, x, c], [x, b, c]]);
                parent.extend([face; 2]);
            } else {
                triangles.push(v);
                parent.push(face);
            }
        }
        refined_from(m, f, current, positions, triangles, &parent, &mid_of, &self.counts)
    }
}

/// The refinement of the input whose mesh is `m` (itself the refinement
/// `current` of the input, if any, with features `f`) remade as
/// `triangles` over `positions`: the vertices of `m` first, then the
/// midpoints of the edges `mid_of` of `m` in that order, then any others
/// (centroids); `parent` the face of `m` each triangle lies in; `added`
/// what was done. Refined vertices are renumbered by first use; edges of
/// `m` and halves of split edges carry their input edge and feature flag.
pub(super) fn refined_from(
    m: &TriMesh,
    f: &FeatureSet,
    current: Option<&Refined>,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    parent: &[u32],
    mid_of: &[u32],
    added: &RefineCounts,
) -> Refined {
    let nv = m.n_vertices();
    let n_mid = mid_of.len();
    let inserted = positions.len() - nv;
    let built = TriMesh::from_welded_arrays(positions, triangles).expect("inserting vertices inside faces or edges, or flipping coplanar edges, keeps the mesh valid");
    // The builder numbers vertices by first use; rebuild from its own
    // arrays so that the refined mesh is its own source.
    let old: Vec<u32> = built.welded_to_source().to_vec();
    let mesh = TriMesh::from_welded_arrays(built.positions().to_vec(), built.faces().to_vec())
        .expect("rebuilding a valid mesh from its own arrays");
    // Each refined edge is an edge of m, half of a split edge, or new.
    let parent_edge = |e: u32| -> Option<u32> {
        let [a, b] = mesh.edge_vertices(e).map(|v| old[v as usize]);
        let (lo, hi) = (a.min(b) as usize, a.max(b) as usize);
        if hi < nv {
            m.edge_between(lo as u32, hi as u32)
        } else if lo < nv && hi < nv + n_mid {
            let split = mid_of[hi - nv];
            m.edge_vertices(split).contains(&(lo as u32)).then_some(split)
        } else {
            None
        }
    };
    let mut features = FeatureSet::none(&mesh);
    let mut original_edge = vec![NONE; mesh.n_edges()];
    for e in 0..mesh.n_edges() as u32 {
        if let Some(pe) = parent_edge(e) {
            if f.contains(pe) {
                features.set(&mesh, e, true);
            }
            original_edge[e as usize] = current.map_or(pe, |r| r.original_edge[pe as usize]);
        }
    }
    let original_vertex = old
        .iter()
        .map(|&s| if (s as usize) >= nv { NONE } else { current.map_or(s, |r| r.original_vertex[s as usize]) })
        .collect();
    let original_face = parent.iter().map(|&g| current.map_or(g, |r| r.original_face[g as usize])).collect();
    let mut counts = current.map_or(RefineCounts::default(), |r| r.counts);
    counts.add(added);
    let splits = current.map_or(0, |r| r.splits) + inserted;
    Refined { mesh, features, original_face, original_vertex, original_edge, splits, counts }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32) -> TriMesh {
        crate::features::test_grid(n, |_, _| 0.0)
    }

    /// The edge between the grid points `a` and `b` (as `(i, j)`).
    fn edge(m: &TriMesh, a: (u32, u32), b: (u32, u32)) -> u32 {
        let at = |(i, j): (u32, u32)| (0..m.n_vertices() as u32).find(|&v| m.position(v) == [i as f64, j as f64, 0.0]).unwrap();
        let (a, b) = (at(a), at(b));
        m.edge(m.outgoing(a).find(|&h| m.head(h) == b).unwrap())
    }

    #[test]
    fn a_lone_edge_is_split_and_both_halves_stay_features() {
        let m = grid(4);
        let mut f = FeatureSet::none(&m);
        let e = edge(&m, (1, 1), (2, 1));
        f.set(&m, e, true);
        let r = refine_for_features(&m, &f).expect("a lone edge needs a split");
        assert_eq!(r.counts.lone_edges, 1);
        // The two grid corners whose one triangle has two boundary edges.
        assert_eq!(r.counts.doubly_constrained, 2);
        assert_eq!(r.splits, 3);
        assert_eq!(r.features.len(), 2);
        for fe in r.features.edges() {
            assert_eq!(r.original_edge[fe as usize], e);
        }
        let cut = cut_open(&r.mesh, &r.features);
        assert_eq!(cut.mesh.boundary_loops().len(), 2, "the outer boundary and the slit");
    }

    #[test]
    fn a_triangle_with_three_feature_edges_is_split_at_its_centroid() {
        let m = grid(4);
        let mut f = FeatureSet::none(&m);
        for (a, b) in [((1, 1), (2, 1)), ((2, 1), (2, 2)), ((2, 2), (1, 1))] {
            f.set(&m, edge(&m, a, b), true);
        }
        let r = refine_for_features(&m, &f).unwrap();
        assert_eq!(r.counts.triply_constrained, 1);
        for face in 0..r.mesh.n_faces() as u32 {
            let n = r.mesh.face_halfedges(face).iter().filter(|&&h| constrained(&r.mesh, &r.features, r.mesh.edge(h))).count();
            assert!(n <= 1, "face {face} keeps {n} constrained edges");
        }
        assert!(refine_for_features(&r.mesh, &r.features).is_none(), "nothing left to refine");
    }

    #[test]
    fn an_enclosed_region_with_bad_corners_gets_an_interior_vertex() {
        // A feature ring around the central square of a 3 × 3 grid: the
        // square's two triangles have two constrained edges each.
        let m = grid(3);
        let mut f = FeatureSet::none(&m);
        for (a, b) in [((1, 1), (2, 1)), ((2, 1), (2, 2)), ((2, 2), (1, 2)), ((1, 2), (1, 1))] {
            f.set(&m, edge(&m, a, b), true);
        }
        let r = refine_for_features(&m, &f).unwrap();
        // The central square's two triangles share their free edge; the two
        // grid corners have one triangle with two boundary edges each.
        assert_eq!(r.counts.doubly_constrained, 3);
        let cut = cut_open(&r.mesh, &r.features);
        let k = boundary_turning(&cut.mesh);
        for c in 0..cut.mesh.n_components() {
            let sum: i64 = (0..cut.mesh.n_vertices() as u32)
                .filter(|&v| cut.mesh.vertex_component(v) == c)
                .map(|v| k[v as usize] as i64)
                .sum();
            let interior = (0..cut.mesh.n_vertices() as u32)
                .any(|v| !cut.mesh.is_boundary_vertex(v) && cut.mesh.vertex_component(v) == c);
            assert!(interior || sum == 4 * cut.mesh.component_euler_characteristic(c), "component {c}: corners sum to {sum}");
        }
    }

    /// A CAD cylinder (bands of long triangles, caps of slivers) split to a
    /// length: every edge is that short after, the rims are the same curves
    /// in pieces, every vertex lies on the input surface, and splits and
    /// flips are counted.
    #[test]
    fn long_edges_are_split_down_to_the_length_on_the_surface() {
        let m = TriMesh::from_raw(&crate::mesh::shapes::cad_cylinder(16, 3.0)).unwrap();
        let f = FeatureSet::sharp_edges(&m, 60.0);
        let length = 0.3;
        let r = split_long_edges(&m, &f, None, length).expect("the cylinder has long edges");
        assert!((0..r.mesh.n_edges() as u32).all(|e| r.mesh.edge_length(e) <= length));
        assert!(r.counts.long_edges > 0 && r.counts.coplanar_flips > 0, "{:?}", r.counts);
        assert_eq!(r.splits, r.mesh.n_vertices() - m.n_vertices());
        assert_eq!(r.mesh.euler_characteristic(), m.euler_characteristic());
        let total = |m: &TriMesh, f: &FeatureSet| f.edges().map(|e| m.edge_length(e)).sum::<f64>();
        assert!((total(&r.mesh, &r.features) - total(&m, &f)).abs() < 1e-9);
        let area = |m: &TriMesh| m.face_areas().iter().sum::<f64>();
        assert!((area(&r.mesh) - area(&m)).abs() < 1e-9 * area(&m));
        for v in 0..r.mesh.n_vertices() as u32 {
            let p = r.mesh.position(v);
            let on = (0..m.n_faces() as u32)
                .any(|g| crate::vec3::point_triangle_distance(p, &m.faces()[g as usize].map(|x| m.position(x))) < 1e-12);
            assert!(on, "vertex {v} is off the input");
        }
        assert!(split_long_edges(&r.mesh, &r.features, None, length).is_none());
    }

    /// A length far below the mesh's size stops at [`MAX_REFINED_FACES`]
    /// faces instead of filling memory; [`faces_for_length`] tells it first.
    #[test]
    fn splitting_stops_past_the_face_limit() {
        let m = TriMesh::from_raw(&crate::mesh::shapes::cad_cylinder(16, 3.0)).unwrap();
        let f = FeatureSet::none(&m);
        let length = 1e-4;
        assert!(faces_for_length(&m, length) > 100.0 * MAX_REFINED_FACES as f64);
        let r = split_long_edges(&m, &f, None, length).expect("the cylinder has long edges");
        assert!(r.mesh.n_faces() > MAX_REFINED_FACES && r.mesh.n_faces() < 4 * MAX_REFINED_FACES, "{} faces", r.mesh.n_faces());
    }
}
