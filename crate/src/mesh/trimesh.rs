//! The validated halfedge mesh every later stage works on.
//!
//! Layout (flat arrays, struct of arrays):
//! * face `f` has corners `faces[f]`, counter-clockwise as in the file;
//! * halfedge `h = 3 f + k` (`k = 0, 1, 2`) of face `f` runs from corner `k`
//!   to corner `(k + 1) % 3`; `next`/`prev` are implicit for these;
//! * boundary halfedges (no face) are numbered `3 F ..`, one per boundary
//!   edge, running opposite to that edge's face halfedge; their `next`
//!   follows the boundary loop (the hole is on their left);
//! * every halfedge has a twin; edge `e` is `{h, twin(h)}` with
//!   `h = edge_halfedges(e)[0]` a face halfedge.

use super::validate::{analyze_raw, analyze_welded, Analysis};
use super::weld::{split_pinches, Welded};
use super::{MeshReport, RawMesh};
use crate::Problem;

/// Sentinel for "no element" in index arrays.
pub const NONE: u32 = u32::MAX;

/// A validated, manifold, consistently oriented triangle mesh with halfedge
/// connectivity. Vertices are welded; only vertices used by faces exist.
#[derive(Clone, Debug)]
pub struct TriMesh {
    positions: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    he_tail: Vec<u32>,
    he_twin: Vec<u32>,
    he_edge: Vec<u32>,
    /// `next` / `prev` of boundary halfedge `3F + i` at index `i`.
    bnd_next: Vec<u32>,
    bnd_prev: Vec<u32>,
    edge_he: Vec<u32>,
    vertex_he: Vec<u32>,
    boundary_loops: Vec<Vec<u32>>,
    face_component: Vec<u32>,
    component_boundary_loops: Vec<usize>,
    report: MeshReport,
    source_to_welded: Vec<u32>,
    welded_to_source: Vec<u32>,
    /// Derived quantities, filled on first use (see [`super::geometry`]).
    pub(super) geometry: super::geometry::GeometryCache,
}

impl TriMesh {
    /// Welds `raw` by position, validates it and builds the halfedge mesh.
    /// Errs with every blocking problem ([`Problem::is_blocking`]);
    /// unreferenced vertices are dropped silently.
    pub fn from_raw(raw: &RawMesh) -> Result<TriMesh, Vec<Problem>> {
        let a = analyze_raw(raw);
        let vertices: Vec<u32> = a
            .report
            .problems
            .iter()
            .filter_map(|p| if let Problem::NonManifoldVertex { vertex, .. } = p { Some(*vertex) } else { None })
            .collect();
        if vertices.is_empty() || a.report.problems.iter().any(Problem::is_blocking) {
            return Self::from_analysis(a);
        }
        // Repair: one vertex per fan; the report keeps naming the pinches.
        let pinches: Vec<Problem> =
            a.report.problems.iter().filter(|p| matches!(p, Problem::NonManifoldVertex { .. })).cloned().collect();
        let mut split = analyze_welded(raw, split_pinches(&a.welded, &vertices));
        split.report.non_manifold_vertices = pinches.len();
        split.report.problems.extend(pinches);
        Self::from_analysis(split)
    }

    /// Builds from arrays whose indices already define connectivity (no
    /// welding by position; unused vertices are dropped and the rest
    /// renumbered in order of first use). Convenient for tests.
    pub fn from_welded_arrays(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<TriMesh, Vec<Problem>> {
        let raw = RawMesh { positions, triangles };
        Self::from_analysis(analyze_welded(&raw, Welded::by_index(&raw)))
    }

    /// The faces `faces` of this mesh as a mesh of their own (a component,
    /// say): vertices numbered in order of first use, faces and their
    /// corners kept in order (halfedge `3 r + i` of it is halfedge
    /// `3 faces[r] + i` here), and its vertex → this mesh's vertex. `local`
    /// (one entry per vertex here) must hold [`NONE`] for the vertices of
    /// `faces`; on return it holds their numbers in the new mesh. `None`
    /// where the faces do not form a valid mesh on their own.
    pub fn submesh(&self, faces: &[u32], local: &mut [u32]) -> Option<(TriMesh, Vec<u32>)> {
        let mut vertex = Vec::new();
        let triangles: Vec<[u32; 3]> = faces
            .iter()
            .map(|&f| {
                self.faces[f as usize].map(|v| {
                    if local[v as usize] == NONE {
                        local[v as usize] = vertex.len() as u32;
                        vertex.push(v);
                    }
                    local[v as usize]
                })
            })
            .collect();
        let positions = vertex.iter().map(|&v| self.positions[v as usize]).collect();
        let sub = TriMesh::from_welded_arrays(positions, triangles).ok()?;
        // Numbered as given (first use), unless the validation dropped something.
        let same = sub.n_vertices() == vertex.len()
            && sub.n_faces() == faces.len()
            && sub.welded_to_source().iter().enumerate().all(|(i, &s)| s as usize == i)
            && sub.faces().iter().zip(faces).all(|(t, &f)| t.map(|v| vertex[v as usize]) == self.faces[f as usize]);
        same.then_some((sub, vertex))
    }

    fn from_analysis(a: Analysis) -> Result<TriMesh, Vec<Problem>> {
        let blocking: Vec<Problem> = a.report.problems.iter().filter(|p| p.is_blocking()).cloned().collect();
        if !blocking.is_empty() {
            return Err(blocking);
        }
        let Analysis { welded, edges, face_component, report } = a;
        let Welded { positions, triangles: faces, source_to_welded, welded_to_source } = welded;
        let nf = faces.len();
        let nv = positions.len();
        let ne = edges.n_edges();
        let nb = report.boundary_edges;
        let nh = 3 * nf + nb;

        let mut he_tail = Vec::with_capacity(nh);
        for t in &faces {
            he_tail.extend_from_slice(t);
        }
        let mut he_twin = vec![NONE; nh];
        let mut he_edge = edges.he_edge;
        he_edge.resize(nh, NONE);
        let mut edge_he = Vec::with_capacity(ne);
        for e in 0..ne {
            let hs = &edges.he[edges.start[e] as usize..edges.start[e + 1] as usize];
            let h = hs[0];
            edge_he.push(h);
            let t = if hs.len() == 2 {
                hs[1]
            } else {
                // New boundary halfedge, opposite to h.
                let g = he_tail.len() as u32;
                let head = faces[(h / 3) as usize][((h % 3 + 1) % 3) as usize];
                he_tail.push(head);
                he_edge[g as usize] = e as u32;
                g
            };
            he_twin[h as usize] = t;
            he_twin[t as usize] = h;
        }
        debug_assert_eq!(he_tail.len(), nh);

        // Boundary loop links: the boundary halfedge leaving each boundary vertex.
        let first_b = 3 * nf as u32;
        let mut out_b = vec![NONE; nv];
        for g in first_b..nh as u32 {
            out_b[he_tail[g as usize] as usize] = g;
        }
        let mut bnd_next = vec![NONE; nb];
        let mut bnd_prev = vec![NONE; nb];
        for g in first_b..nh as u32 {
            let head = he_tail[he_twin[g as usize] as usize];
            let n = out_b[head as usize];
            bnd_next[(g - first_b) as usize] = n;
            bnd_prev[(n - first_b) as usize] = g;
        }

        // Outgoing halfedge per vertex: for boundary vertices the face
        // halfedge along the boundary, so the fan starts at the boundary.
        let mut vertex_he = vec![NONE; nv];
        for h in (0..first_b).rev() {
            vertex_he[he_tail[h as usize] as usize] = h;
        }
        for g in first_b..nh as u32 {
            let h = he_twin[g as usize];
            vertex_he[he_tail[h as usize] as usize] = h;
        }

        let mut boundary_loops = Vec::new();
        let mut seen = vec![false; nb];
        let mut component_boundary_loops = vec![0usize; report.components];
        for g0 in first_b..nh as u32 {
            if seen[(g0 - first_b) as usize] {
                continue;
            }
            let mut lp = Vec::new();
            let mut g = g0;
            loop {
                seen[(g - first_b) as usize] = true;
                lp.push(g);
                g = bnd_next[(g - first_b) as usize];
                if g == g0 || lp.len() > nb {
                    break;
                }
            }
            let f = he_twin[g0 as usize] / 3;
            component_boundary_loops[face_component[f as usize] as usize] += 1;
            boundary_loops.push(lp);
        }

        Ok(TriMesh {
            positions,
            faces,
            he_tail,
            he_twin,
            he_edge,
            bnd_next,
            bnd_prev,
            edge_he,
            vertex_he,
            boundary_loops,
            face_component,
            component_boundary_loops,
            report,
            source_to_welded,
            welded_to_source,
            geometry: Default::default(),
        })
    }

    // ----- sizes -----

    /// Number of (welded, referenced) vertices.
    #[inline]
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }
    /// Number of faces (triangles).
    #[inline]
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }
    /// Number of undirected edges.
    #[inline]
    pub fn n_edges(&self) -> usize {
        self.edge_he.len()
    }
    /// Number of halfedges: `3 F` face halfedges plus one per boundary edge.
    #[inline]
    pub fn n_halfedges(&self) -> usize {
        self.he_tail.len()
    }
    /// Number of boundary halfedges (= boundary edges).
    #[inline]
    pub fn n_boundary_halfedges(&self) -> usize {
        self.bnd_next.len()
    }

    // ----- geometry -----

    /// Welded vertex positions.
    #[inline]
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }
    /// Position of vertex `v`.
    #[inline]
    pub fn position(&self, v: u32) -> [f64; 3] {
        self.positions[v as usize]
    }
    /// Corners of every face, counter-clockwise.
    #[inline]
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }
    /// The vector from tail to head of halfedge `h`.
    #[inline]
    pub fn halfedge_vector(&self, h: u32) -> [f64; 3] {
        let (a, b) = (self.position(self.tail(h)), self.position(self.head(h)));
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
    }

    // ----- halfedges -----

    /// Vertex halfedge `h` leaves.
    #[inline]
    pub fn tail(&self, h: u32) -> u32 {
        self.he_tail[h as usize]
    }
    /// Vertex halfedge `h` points to.
    #[inline]
    pub fn head(&self, h: u32) -> u32 {
        self.he_tail[self.he_twin[h as usize] as usize]
    }
    /// Face on the left of `h`; `None` for boundary halfedges.
    #[inline]
    pub fn face(&self, h: u32) -> Option<u32> {
        if (h as usize) < 3 * self.faces.len() {
            Some(h / 3)
        } else {
            None
        }
    }
    /// True for halfedges with no face (they run along boundary loops).
    #[inline]
    pub fn is_boundary_halfedge(&self, h: u32) -> bool {
        h as usize >= 3 * self.faces.len()
    }
    /// Next halfedge around the same face (or boundary loop).
    #[inline]
    pub fn next(&self, h: u32) -> u32 {
        let nf3 = 3 * self.faces.len() as u32;
        if h < nf3 {
            h - h % 3 + (h % 3 + 1) % 3
        } else {
            self.bnd_next[(h - nf3) as usize]
        }
    }
    /// Previous halfedge around the same face (or boundary loop).
    #[inline]
    pub fn prev(&self, h: u32) -> u32 {
        let nf3 = 3 * self.faces.len() as u32;
        if h < nf3 {
            h - h % 3 + (h % 3 + 2) % 3
        } else {
            self.bnd_prev[(h - nf3) as usize]
        }
    }
    /// The opposite halfedge of the same edge.
    #[inline]
    pub fn twin(&self, h: u32) -> u32 {
        self.he_twin[h as usize]
    }
    /// Edge of halfedge `h`.
    #[inline]
    pub fn edge(&self, h: u32) -> u32 {
        self.he_edge[h as usize]
    }
    /// The three halfedges of face `f`, `3f, 3f+1, 3f+2` (corner k → k+1).
    #[inline]
    pub fn face_halfedges(&self, f: u32) -> [u32; 3] {
        [3 * f, 3 * f + 1, 3 * f + 2]
    }

    // ----- edges -----

    /// `[face halfedge, its twin]` of edge `e` (the twin is the boundary
    /// halfedge on a boundary edge).
    #[inline]
    pub fn edge_halfedges(&self, e: u32) -> [u32; 2] {
        let h = self.edge_he[e as usize];
        [h, self.he_twin[h as usize]]
    }
    /// `[tail, head]` of `edge_halfedges(e)[0]`.
    #[inline]
    pub fn edge_vertices(&self, e: u32) -> [u32; 2] {
        let h = self.edge_he[e as usize];
        [self.tail(h), self.head(h)]
    }
    /// The edge joining vertices `a` and `b`, if any.
    pub fn edge_between(&self, a: u32, b: u32) -> Option<u32> {
        self.outgoing(a).find(|&h| self.head(h) == b).map(|h| self.edge(h))
    }
    /// True when edge `e` has only one face.
    #[inline]
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.is_boundary_halfedge(self.he_twin[self.edge_he[e as usize] as usize])
    }

    // ----- vertices -----

    /// An outgoing halfedge of `v`; for a boundary vertex, the face halfedge
    /// whose edge is the boundary edge where the fan starts.
    #[inline]
    pub fn vertex_halfedge(&self, v: u32) -> u32 {
        self.vertex_he[v as usize]
    }
    /// True when `v` lies on a boundary loop.
    #[inline]
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.is_boundary_halfedge(self.he_twin[self.vertex_he[v as usize] as usize])
    }
    /// Outgoing halfedges of `v` in counter-clockwise order (`h → twin(prev(h))`),
    /// starting at [`Self::vertex_halfedge`]; for a boundary vertex the last
    /// one is the boundary halfedge leaving `v`.
    #[inline]
    pub fn outgoing(&self, v: u32) -> Outgoing<'_> {
        let start = self.vertex_he[v as usize];
        Outgoing { mesh: self, start, cur: start, done: false }
    }
    /// The one-ring neighbours of `v`, ordered as [`Self::outgoing`]
    /// (a boundary vertex's ring starts and ends at its two boundary neighbours).
    pub fn one_ring(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v).map(move |h| self.head(h))
    }
    /// Faces around `v`, counter-clockwise (the fan, boundary to boundary).
    pub fn vertex_faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v).filter_map(move |h| self.face(h))
    }
    /// Number of edges at `v`.
    pub fn valence(&self, v: u32) -> usize {
        self.outgoing(v).count()
    }

    // ----- boundary, components, topology -----

    /// Boundary loops, each the ordered list of its boundary halfedges
    /// (following `next`).
    pub fn boundary_loops(&self) -> &[Vec<u32>] {
        &self.boundary_loops
    }
    /// Vertices of boundary loop `i`, in loop order (tails of its halfedges).
    pub fn boundary_loop_vertices(&self, i: usize) -> Vec<u32> {
        self.boundary_loops[i].iter().map(|&h| self.tail(h)).collect()
    }
    /// Number of edge-connected components.
    pub fn n_components(&self) -> usize {
        self.report.components
    }
    /// Component id of each face (components numbered by their first face).
    pub fn face_components(&self) -> &[u32] {
        &self.face_component
    }
    /// Component id of vertex `v` (every vertex of a `TriMesh` has a face).
    pub fn vertex_component(&self, v: u32) -> usize {
        let f = self.vertex_faces(v).next().expect("every vertex of a TriMesh lies on a face");
        self.face_component[f as usize] as usize
    }
    /// V − E + F of the whole mesh.
    pub fn euler_characteristic(&self) -> i64 {
        self.report.euler_characteristic
    }
    /// V − E + F of component `c`.
    pub fn component_euler_characteristic(&self, c: usize) -> i64 {
        self.report.euler_characteristic_per_component[c]
    }
    /// Boundary loops of component `c`.
    pub fn component_boundary_loops(&self, c: usize) -> usize {
        self.component_boundary_loops[c]
    }
    /// Genus of component `c`: `(2 − χ − b) / 2`.
    pub fn genus(&self, c: usize) -> i64 {
        self.report.genus[c]
    }
    /// The analysis this mesh was built from (only non-blocking problems).
    pub fn report(&self) -> &MeshReport {
        &self.report
    }
    /// Source vertex → welded vertex ([`NONE`] for unreferenced source vertices).
    pub fn source_to_welded(&self) -> &[u32] {
        &self.source_to_welded
    }
    /// Welded vertex → one representative source vertex.
    pub fn welded_to_source(&self) -> &[u32] {
        &self.welded_to_source
    }
}

/// Iterator over the outgoing halfedges of a vertex; see [`TriMesh::outgoing`].
pub struct Outgoing<'a> {
    mesh: &'a TriMesh,
    start: u32,
    cur: u32,
    done: bool,
}

impl Iterator for Outgoing<'_> {
    type Item = u32;
    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.done {
            return None;
        }
        let h = self.cur;
        self.cur = self.mesh.twin(self.mesh.prev(h));
        self.done = self.cur == self.start;
        Some(h)
    }
}
