//! Where a solve failed, in the indices of the INPUT mesh (the ones the CLI's
//! user and the page know). The stages name elements of the mesh they solve
//! on: the refinement of the input ([`crate::features::Refined`], vertices
//! renumbered, some inserted) and, for cone errors, its cut. [`Lift`] maps
//! them back; [`locate`] turns an error into an [`ErrorLocation`] and a
//! message in input terms.

use super::SolveCause;
use crate::cones::ConeError;
use crate::features::{cut_open, FeatureSet};
use crate::mesh::{TriMesh, NONE};
use crate::param::ParamError;
use serde::Serialize;
use std::fmt;

/// Input-mesh vertices and edges a solve error is about (what the page highlights).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ErrorLocation {
    /// Input vertex ids: the vertex named, or for a vertex the refinement
    /// inserted, the corners of the input edge or face it lies in.
    pub vertices: Vec<u32>,
    /// Input edge ids: the edge named, or the feature edges the user can change.
    pub edges: Vec<u32>,
}

/// Most feature edges a location lists ([`enclosing_features`]): enough to
/// show a region's outline, few enough for a message and a highlight.
pub const MAX_LOCATION_EDGES: usize = 500;

/// Feature edges met by walking the faces of `mesh` from `seeds` without
/// crossing a feature (or boundary) edge, nearest first, at most `cap`; the
/// flag is false when the cap cut the list short.
pub fn enclosing_features(mesh: &TriMesh, features: &FeatureSet, seeds: &[u32], cap: usize) -> (Vec<u32>, bool) {
    let mut visited = vec![false; mesh.n_faces()];
    let mut met = vec![false; mesh.n_edges()];
    let mut queue = std::collections::VecDeque::new();
    for &f in seeds {
        if !std::mem::replace(&mut visited[f as usize], true) {
            queue.push_back(f);
        }
    }
    let mut out = Vec::new();
    while let Some(f) = queue.pop_front() {
        for h in mesh.face_halfedges(f) {
            let e = mesh.edge(h);
            if features.contains(e) {
                if !std::mem::replace(&mut met[e as usize], true) {
                    if out.len() == cap {
                        return (out, false);
                    }
                    out.push(e);
                }
                continue;
            }
            if let Some(g) = mesh.face(mesh.twin(h)) {
                if !std::mem::replace(&mut visited[g as usize], true) {
                    queue.push_back(g);
                }
            }
        }
    }
    (out, true)
}

/// The mesh a stage solved on (`solved`, with `solved_features`) and its
/// maps to the input (`None`: `solved` is the input itself).
pub(super) struct Lift<'a> {
    pub input: &'a TriMesh,
    pub features: &'a FeatureSet,
    pub solved: &'a TriMesh,
    pub solved_features: &'a FeatureSet,
    pub original_vertex: Option<&'a [u32]>,
    pub original_edge: Option<&'a [u32]>,
    pub original_face: Option<&'a [u32]>,
}

/// Where a solved-mesh vertex lies on the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Site {
    /// It is input vertex `v`.
    Vertex(u32),
    /// The refinement inserted it on input edge `e` (a midpoint).
    OnEdge(u32),
    /// The refinement inserted it inside input face `f`.
    InFace(u32),
}

/// Where a solved-mesh edge lies on the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum EdgeSite {
    /// It is (a piece of) input edge `e`.
    Edge(u32),
    /// The refinement drew it inside input face `f`.
    InFace(u32),
}

impl Lift<'_> {
    /// The input face that solved face `f` lies in.
    fn input_face(&self, f: u32) -> u32 {
        self.original_face.map_or(f, |of| of[f as usize])
    }

    /// The input edge that solved edge `e` is (a piece of), if any.
    fn input_edge(&self, e: u32) -> Option<u32> {
        let o = self.original_edge.map_or(e, |oe| oe[e as usize]);
        (o != NONE).then_some(o)
    }

    /// Where solved vertex `v` lies: an input vertex, or where it was inserted.
    pub fn site(&self, v: u32) -> Site {
        let o = self.original_vertex.map_or(v, |ov| ov[v as usize]);
        if o != NONE {
            return Site::Vertex(o);
        }
        // A midpoint has the two halves of its input edge among its edges; a
        // centroid only edges inside the face.
        let s = self.solved;
        if let Some(e) = s.outgoing(v).find_map(|h| self.input_edge(s.edge(h))) {
            return Site::OnEdge(e);
        }
        let f = s.vertex_faces(v).next().expect("a vertex of a valid mesh has a face");
        Site::InFace(self.input_face(f))
    }

    /// Where solved edge `e` lies: an input edge, or the input face it was drawn in.
    pub fn edge_site(&self, e: u32) -> EdgeSite {
        if let Some(o) = self.input_edge(e) {
            return EdgeSite::Edge(o);
        }
        let h = self.solved.edge_halfedges(e)[0];
        EdgeSite::InFace(self.input_face(self.solved.face(h).expect("edge_halfedges starts with a face halfedge")))
    }
}

impl Site {
    /// The input vertices to show for it.
    pub fn vertices(self, input: &TriMesh) -> Vec<u32> {
        match self {
            Site::Vertex(v) => vec![v],
            Site::OnEdge(e) => input.edge_vertices(e).to_vec(),
            Site::InFace(f) => input.faces()[f as usize].to_vec(),
        }
    }

    /// The input faces it touches (where a walk around it starts).
    pub fn faces(self, input: &TriMesh) -> Vec<u32> {
        match self {
            Site::Vertex(v) => input.vertex_faces(v).collect(),
            Site::OnEdge(e) => input.edge_halfedges(e).iter().filter_map(|&h| input.face(h)).collect(),
            Site::InFace(f) => vec![f],
        }
    }

    /// "vertex v3", "a vertex inserted on edge (v1, v2)", "… in triangle (v1, v2, v3)".
    pub fn describe(self, input: &TriMesh) -> String {
        match self {
            Site::Vertex(v) => format!("vertex v{v}"),
            Site::OnEdge(e) => format!("a vertex inserted on edge {}", Pair(input.edge_vertices(e))),
            Site::InFace(f) => format!("a vertex inserted in {}", Triangle(input.faces()[f as usize])),
        }
    }
}

impl EdgeSite {
    /// Its location: the input edge, or the corners of the face it lies in.
    fn location(self, input: &TriMesh) -> ErrorLocation {
        match self {
            EdgeSite::Edge(e) => ErrorLocation { vertices: Vec::new(), edges: vec![e] },
            EdgeSite::InFace(f) => ErrorLocation { vertices: input.faces()[f as usize].to_vec(), edges: Vec::new() },
        }
    }

    /// "edge (v1, v2)" or "an edge inserted in triangle (v1, v2, v3)".
    fn describe(self, input: &TriMesh) -> String {
        match self {
            EdgeSite::Edge(e) => format!("edge {}", Pair(input.edge_vertices(e))),
            EdgeSite::InFace(f) => format!("an edge inserted in {}", Triangle(input.faces()[f as usize])),
        }
    }
}

struct Pair([u32; 2]);
impl fmt::Display for Pair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "(v{}, v{})", self.0[0], self.0[1])
    }
}

struct Triangle([u32; 3]);
impl fmt::Display for Triangle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "triangle (v{}, v{}, v{})", self.0[0], self.0[1], self.0[2])
    }
}

/// Feature edges listed in a message before "and N more".
const LISTED_EDGES: usize = 4;

/// "the 12 feature edges around it ((v1, v2), …, and 8 more)" for `edges`
/// of `input` (`complete`: false when the list was capped).
fn edge_list(input: &TriMesh, edges: &[u32], complete: bool) -> String {
    let mut listed: Vec<String> = edges.iter().take(LISTED_EDGES).map(|&e| Pair(input.edge_vertices(e)).to_string()).collect();
    if !complete {
        listed.push("…".into());
        return format!("the feature edges around it (over {}: {})", edges.len(), listed.join(", "));
    }
    if edges.len() > LISTED_EDGES {
        listed.push(format!("and {} more", edges.len() - LISTED_EDGES));
    }
    let noun = if edges.len() == 1 { "feature edge" } else { "feature edges" };
    format!("the {} {noun} around it ({})", edges.len(), listed.join(", "))
}

/// The input location of `cause` and its message in input terms, when it
/// names mesh elements (of `lift.solved`, or of its cut for cone errors);
/// `None` for errors that name none (a failed linear solve, a mismatch).
pub(super) fn locate(lift: &Lift, cause: &SolveCause) -> Option<(ErrorLocation, String)> {
    let input = lift.input;
    match cause {
        SolveCause::Param(ParamError::DegenerateCone { vertex, k }) => {
            let site = lift.site(*vertex);
            let (edges, complete) = enclosing_features(input, lift.features, &site.faces(input), MAX_LOCATION_EDGES);
            let angle = 360 - 90 * k;
            let what = site.describe(input);
            // k >= 4 is where the cone placement could not spread the
            // curvature the features enclose: often a small region around a
            // sharp vertex, sometimes a large one it rounded badly.
            let head = format!(
                "parametrization: the cone at {what} would need index {k} (a cone angle of {angle}°, which no seamless map can have)"
            );
            let message = if edges.is_empty() {
                format!("{head}: the cone placement found no way to spread the curvature around it over more vertices; subdivide the mesh there")
            } else {
                format!(
                    "{head}: the cone placement found no way to spread the curvature enclosed by {} over more vertices; \
                     unmark some of them or subdivide the mesh there",
                    edge_list(input, &edges, complete)
                )
            };
            Some((ErrorLocation { vertices: site.vertices(input), edges }, message))
        }
        SolveCause::Param(ParamError::Misaligned { edge, value }) => {
            let site = lift.edge_site(*edge);
            let kind = match site {
                EdgeSite::Edge(e) if input.is_boundary_edge(e) => "boundary ",
                EdgeSite::Edge(_) => "feature ",
                EdgeSite::InFace(_) => "",
            };
            let message = format!("parametrization: cross-field is not aligned with {kind}{} ({value} quarter turns)", site.describe(input));
            Some((site.location(input), message))
        }
        SolveCause::Param(ParamError::NonIntegerMatching { edge, value }) => {
            let site = lift.edge_site(*edge);
            let message = format!("parametrization: cross-field matching across {} is {value} quarter turns, not an integer", site.describe(input));
            Some((site.location(input), message))
        }
        SolveCause::Param(ParamError::UncutSingularity { edge, matching }) => {
            let site = lift.edge_site(*edge);
            let message = format!("parametrization: {} is not cut but has matching {matching} (not a multiple of 4)", site.describe(input));
            Some((site.location(input), message))
        }
        SolveCause::Cones(ConeError::InconsistentBoundary { vertex }) => {
            // The cut is deterministic: cutting again numbers its vertices as the stage did.
            let cut = cut_open(lift.solved, lift.solved_features);
            let v = *cut.original_vertex.get(*vertex as usize)?;
            let site = lift.site(v);
            let edges = match site {
                Site::Vertex(iv) => input.outgoing(iv).map(|h| input.edge(h)).filter(|&e| lift.features.contains(e)).collect(),
                _ => Vec::new(),
            };
            let message = format!("cone placement: boundary turning at {} is inconsistent", site.describe(input));
            Some((ErrorLocation { vertices: site.vertices(input), edges }, message))
        }
        SolveCause::Folded { flipped, wound, faces, .. } => {
            let input_faces: Vec<u32> = match lift.original_face {
                Some(of) => faces.iter().map(|&f| of[f as usize]).collect(),
                None => faces.clone(),
            };
            let mut edges: Vec<u32> = input_faces.iter().flat_map(|&f| (0..3).map(move |k| input.edge(3 * f + k))).collect();
            edges.sort_unstable();
            edges.dedup();
            edges.truncate(MAX_LOCATION_EDGES);
            let message = format!(
                "parametrization: the map still folds ({flipped} flipped triangles, {wound} folded vertices; their edges are highlighted): \
                 unmark or mark features near them, change alpha, or subdivide the mesh there"
            );
            Some((ErrorLocation { vertices: Vec::new(), edges }, message))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::test_grid;
    use crate::pipeline::{RefineOptions, SolveOptions};

    /// The edge of `m` between grid points `a` and `b`.
    fn edge(m: &TriMesh, a: (u32, u32), b: (u32, u32)) -> u32 {
        let at = |(i, j): (u32, u32)| (0..m.n_vertices() as u32).find(|&v| m.position(v) == [i as f64, j as f64, 0.0]).unwrap();
        let (a, b) = (at(a), at(b));
        m.edge(m.outgoing(a).find(|&h| m.head(h) == b).unwrap())
    }

    fn ring(m: &TriMesh, corners: &[(u32, u32)]) -> Vec<u32> {
        (0..corners.len()).map(|i| edge(m, corners[i], corners[(i + 1) % corners.len()])).collect()
    }

    #[test]
    fn the_walk_stops_at_the_feature_ring_and_collects_it() {
        // A 6 × 6 grid; a ring of 8 feature edges around the 2 × 2 block at (2..4, 2..4).
        let m = test_grid(6, |_, _| 0.0);
        let outer = ring(&m, &[(2, 2), (3, 2), (4, 2), (4, 3), (4, 4), (3, 4), (2, 4), (2, 3)]);
        // A feature outside the ring that the walk must not reach.
        let far = edge(&m, (0, 0), (1, 1));
        let mut f = FeatureSet::none(&m);
        for &e in outer.iter().chain([&far]) {
            f.set(&m, e, true);
        }
        let centre = (0..m.n_vertices() as u32).find(|&v| m.position(v) == [3.0, 3.0, 0.0]).unwrap();
        let seeds: Vec<u32> = m.vertex_faces(centre).collect();
        let (mut got, complete) = enclosing_features(&m, &f, &seeds, MAX_LOCATION_EDGES);
        assert!(complete);
        got.sort_unstable();
        let mut want = outer.clone();
        want.sort_unstable();
        assert_eq!(got, want);
        // From outside the ring: everything else, the ring seen from outside and the far edge.
        let (outside, _) = enclosing_features(&m, &f, &[0], MAX_LOCATION_EDGES);
        assert_eq!(outside.len(), 9);
        // The cap.
        let (capped, complete) = enclosing_features(&m, &f, &seeds, 3);
        assert_eq!((capped.len(), complete), (3, false));
    }

    #[test]
    fn refined_vertices_and_edges_map_to_the_input() {
        // The central square of a 3 × 3 grid ringed by features gets refined
        // (its doubly constrained triangles split at edge midpoints), then the
        // faces around a corner of the ring at their centroids (as around a
        // cone of angle 0): vertices are renumbered, some inserted.
        let m = test_grid(3, |_, _| 0.0);
        let mut f = FeatureSet::none(&m);
        for e in ring(&m, &[(1, 1), (2, 1), (2, 2), (1, 2)]) {
            f.set(&m, e, true);
        }
        let first = crate::features::refine_for_features(&m, &f).expect("the ring needs refinement");
        let corner = (0..first.mesh.n_vertices() as u32).find(|&v| first.mesh.position(v) == [1.0, 1.0, 0.0]).unwrap();
        let r = crate::features::split_around(&m, &f, Some(first), &[corner]);
        assert!(r.mesh.n_vertices() > m.n_vertices());
        let lift = Lift {
            input: &m,
            features: &f,
            solved: &r.mesh,
            solved_features: &r.features,
            original_vertex: Some(&r.original_vertex),
            original_edge: Some(&r.original_edge),
            original_face: Some(&r.original_face),
        };
        let (mut renumbered, mut on_edge, mut in_face) = (0, 0, 0);
        for v in 0..r.mesh.n_vertices() as u32 {
            let p = r.mesh.position(v);
            match lift.site(v) {
                Site::Vertex(o) => {
                    assert_eq!(m.position(o), p, "refined v{v} is input v{o}");
                    renumbered += usize::from(o != v);
                }
                Site::OnEdge(e) => {
                    on_edge += 1;
                    let [a, b] = m.edge_vertices(e).map(|x| m.position(x));
                    assert_eq!(p, crate::vec3::midpoint(a, b), "refined v{v} is the midpoint of input edge {e}");
                }
                Site::InFace(face) => {
                    in_face += 1;
                    let c = m.faces()[face as usize].map(|x| m.position(x));
                    // Counter-clockwise in the xy plane: left of every side.
                    let inside = (0..3).all(|i| {
                        let (a, b) = (c[i], c[(i + 1) % 3]);
                        (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 1e-12
                    });
                    assert!(inside, "refined v{v} lies in input face {face}");
                }
            }
        }
        assert!(renumbered > 0, "the test needs a refinement that renumbers input vertices");
        assert!(on_edge > 0 && in_face > 0, "{on_edge} midpoints, {in_face} centroids");
        // A DegenerateCone at each refined vertex names the input vertex at
        // the same place, or the input triangle / edge it was inserted in.
        for v in 0..r.mesh.n_vertices() as u32 {
            let cause = SolveCause::Param(ParamError::DegenerateCone { vertex: v, k: 5 });
            let (loc, msg) = locate(&lift, &cause).unwrap();
            match lift.site(v) {
                Site::Vertex(o) => {
                    assert_eq!(loc.vertices, vec![o]);
                    assert!(msg.contains(&format!("vertex v{o} ")), "{msg}");
                }
                Site::OnEdge(e) => {
                    assert_eq!(loc.vertices, m.edge_vertices(e).to_vec());
                    assert!(msg.contains("a vertex inserted on edge (v"), "{msg}");
                }
                Site::InFace(face) => {
                    assert_eq!(loc.vertices, m.faces()[face as usize].to_vec());
                    assert!(msg.contains("a vertex inserted in triangle (v"), "{msg}");
                }
            }
            assert!(msg.contains("cone angle of -90°"), "{msg}");
        }
        // Edges the refinement drew inside input faces name their face.
        let inner = (0..r.mesh.n_edges() as u32).find(|&e| r.original_edge[e as usize] == NONE).unwrap();
        let cause = SolveCause::Param(ParamError::UncutSingularity { edge: inner, matching: 1 });
        let (loc, msg) = locate(&lift, &cause).unwrap();
        assert!(loc.edges.is_empty() && loc.vertices.len() == 3, "{msg}");
        assert!(msg.starts_with("parametrization: an edge inserted in triangle (v"), "{msg}");
        // Every refined feature edge maps to the input feature it is a piece of.
        for e in r.features.edges() {
            let cause = SolveCause::Param(ParamError::Misaligned { edge: e, value: 0.5 });
            let (loc, msg) = locate(&lift, &cause).unwrap();
            assert_eq!(loc.edges.len(), 1);
            assert!(f.contains(loc.edges[0]));
            let [a, b] = r.mesh.edge_vertices(e).map(|x| r.mesh.position(x));
            let [c, d] = m.edge_vertices(loc.edges[0]).map(|x| m.position(x));
            let on = |p: [f64; 3]| {
                let (u, w) = (crate::vec3::sub(p, c), crate::vec3::sub(d, c));
                crate::vec3::cross(u, w).iter().all(|x| x.abs() < 1e-12)
            };
            assert!(on(a) && on(b), "refined edge {e} lies on input edge {}", loc.edges[0]);
            assert!(msg.contains("feature edge (v"), "{msg}");
        }
    }

    /// A needle: a hexagonal pyramid of height `h` over a unit hexagon,
    /// the base fanned from its centre.
    fn needle(h: f64) -> TriMesh {
        let mut p = vec![[0.0, 0.0, h]];
        p.extend((0..6).map(|i| {
            let a = std::f64::consts::PI * i as f64 / 3.0;
            [a.cos(), a.sin(), 0.0]
        }));
        p.push([0.0; 3]);
        // Side faces start at the rim, so that splitting them renumbers the apex.
        let t = (0..6u32).flat_map(|i| [[1 + i, 1 + (i + 1) % 6, 0], [7, 1 + (i + 1) % 6, 1 + i]]).collect();
        TriMesh::from_welded_arrays(p, t).unwrap()
    }

    /// The needle and its rim (the six base edges, dihedral angle ~92°; the
    /// sides meet at ~60°), which encloses nearly 2 pi of curvature at the apex.
    fn needle_with_rim(h: f64) -> (TriMesh, FeatureSet, u32, Vec<u32>) {
        let m = needle(h);
        let f = FeatureSet::sharp_edges(&m, 75.0);
        let apex = (0..m.n_vertices() as u32).find(|&v| m.position(v) == [0.0, 0.0, h]).unwrap();
        let is_rim = |e: u32| m.edge_vertices(e).iter().all(|&v| v != apex && m.position(v) != [0.0; 3]);
        let rim: Vec<u32> = (0..m.n_edges() as u32).filter(|&e| is_rim(e)).collect();
        assert_eq!(f.edges().collect::<Vec<_>>(), rim, "the rim is the feature set");
        (m, f, apex, rim)
    }

    #[test]
    fn a_needle_solves_by_spreading_its_apex_cone() {
        // The cone placement alone puts index 4 at the apex, whose neighbours
        // are all on the rim; the refinement around it gives interior
        // vertices the quarter turns spread onto.
        let (m, f, _, _) = needle_with_rim(30.0);
        let s = crate::pipeline::solve(&m, &f, &Default::default(), &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.refinement.zero_angle_faces > 0, "the apex needed the refinement");
        assert!(s.placement.cones.iter().all(|c| c.k <= 3), "{:?}", s.placement.cones);
        assert_eq!(s.param.metrics.flipped, 0);
        let a = s.feature_alignment(&m, &f);
        assert_eq!(a.aligned, a.requested);
    }

    #[test]
    fn a_needle_without_refinement_fails_with_its_apex_and_rim_in_input_indices() {
        let (m, f, apex, rim) = needle_with_rim(30.0);
        let options = SolveOptions { refine: RefineOptions { max_cone_refinements: 0, ..Default::default() }, ..Default::default() };
        let e = crate::pipeline::solve(&m, &f, &options, &mut |_| {}).expect_err("the apex needs index 4");
        let SolveCause::Param(ParamError::DegenerateCone { k: 4, .. }) = e.cause else { panic!("{e}") };
        let loc = e.location().expect("a degenerate cone has a location");
        assert_eq!(loc.vertices, vec![apex], "{e}");
        let mut edges = loc.edges.clone();
        edges.sort_unstable();
        assert_eq!(edges, rim, "{e}");
        let msg = e.to_string();
        assert!(msg.contains(&format!("the cone at vertex v{apex} would need index 4 (a cone angle of 0°, ")), "{msg}");
        assert!(msg.contains("the 6 feature edges around it ((v"), "{msg}");
    }

    #[test]
    fn a_degenerate_cone_inside_a_ring_names_the_ring() {
        // No refinement: the solved mesh is the input.
        let m = test_grid(6, |_, _| 0.0);
        let outer = ring(&m, &[(2, 2), (3, 2), (4, 2), (4, 3), (4, 4), (3, 4), (2, 4), (2, 3)]);
        let mut f = FeatureSet::none(&m);
        for &e in &outer {
            f.set(&m, e, true);
        }
        let centre = (0..m.n_vertices() as u32).find(|&v| m.position(v) == [3.0, 3.0, 0.0]).unwrap();
        let lift = Lift { input: &m, features: &f, solved: &m, solved_features: &f, original_vertex: None, original_edge: None, original_face: None };
        let (loc, msg) = locate(&lift, &SolveCause::Param(ParamError::DegenerateCone { vertex: centre, k: 4 })).unwrap();
        assert_eq!(loc.vertices, vec![centre]);
        let mut got = loc.edges.clone();
        got.sort_unstable();
        let mut want = outer;
        want.sort_unstable();
        assert_eq!(got, want);
        assert!(msg.contains(&format!("the cone at vertex v{centre} would need index 4 (a cone angle of 0°, ")), "{msg}");
        assert!(msg.contains("the 8 feature edges around it ((v"), "{msg}");
        assert!(msg.contains("and 4 more"), "{msg}");
        assert!(msg.contains("unmark some of them"), "{msg}");
        // Errors that name no element have no location.
        let solve = SolveCause::Param(ParamError::ConstraintViolation { residual: 1.0 });
        assert!(locate(&lift, &solve).is_none());
    }
}
