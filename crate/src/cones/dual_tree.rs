//! The path basis of section 5.2 ("Change of basis of paths", Figure 8) on
//! one connected component:
//! * `T`, a spanning tree of the augmented dual graph (faces plus one outer
//!   node for all boundary edges), grown from each boundary loop along the
//!   chain of faces around it, then breadth-first inward;
//! * `G`, the dual edges (interior edges and boundary "ports") not in `T`,
//!   one integer `p` each;
//! * `T_p`, a primal spanning tree avoiding the edges dual to `T`, and the
//!   `2g + m - 1` leftover edges in neither tree (tree-cotree): the homology
//!   loops and boundary alignment paths `G_path`.

use super::dual_path::Visit;
use crate::mesh::{TriMesh, NONE};
use std::collections::VecDeque;

/// Spanning trees and the edge classes of one component.
#[derive(Clone, Debug)]
pub struct DualTree {
    /// Faces of the component, in the order they joined `T`.
    pub faces: Vec<u32>,
    /// Vertices of the component (ascending).
    pub vertices: Vec<u32>,
    /// Per mesh face: the face halfedge through which it joined `T` (a port
    /// halfedge when its parent is the outer node; `NONE` for the root of a
    /// closed component or for faces of other components).
    pub parent_he: Vec<u32>,
    /// Per mesh face: depth in `T` (the outer node has depth 0).
    pub depth: Vec<u32>,
    /// Edges of `G` (not dual to a tree edge of `T`), ascending.
    pub g_edges: Vec<u32>,
    /// Per mesh edge: index into `g_edges`, or `NONE`.
    pub g_index: Vec<u32>,
    /// Per mesh vertex: the halfedge pointing to it from its parent in `T_p`
    /// (`NONE` at the root and outside the component).
    pub primal_parent_he: Vec<u32>,
    /// Per mesh vertex: depth in `T_p`.
    pub primal_depth: Vec<u32>,
    /// The leftover edges (`G_path`): neither in `T_p` nor dual to `T`.
    pub leftovers: Vec<u32>,
    /// True when the component has boundary (and so an outer node).
    pub has_boundary: bool,
}

impl DualTree {
    /// Builds the trees for the component with face `seed`. `free` flags
    /// the free boundary edges per mesh edge (empty: none). A free edge is
    /// still a port of the outer node, but its `p` is a continuous unknown
    /// (see `ComponentSystem`), so the tree hangs from the outer node only
    /// through aligned edges: one root port per loop that has one (its
    /// gauge aligns the frame there), or, when no boundary edge is aligned,
    /// one port of the first loop (an arbitrary gauge: every other cycle
    /// through the outer node crosses a free port).
    pub fn new(mesh: &TriMesh, seed: u32, free: &[bool]) -> DualTree {
        let t = DualSpanningTree::grow(mesh, seed, free);
        // Edges dual to T.
        let ne = mesh.n_edges();
        let mut in_t = vec![false; ne];
        for &f in &t.faces {
            if t.parent_he[f as usize] != NONE {
                in_t[mesh.edge(t.parent_he[f as usize]) as usize] = true;
            }
        }
        let mut vertices: Vec<u32> = t.faces.iter().flat_map(|&f| mesh.faces()[f as usize]).collect();
        vertices.sort_unstable();
        vertices.dedup();
        let mut comp_edges: Vec<u32> = t.faces.iter().flat_map(|&f| mesh.face_halfedges(f).map(|h| mesh.edge(h))).collect();
        comp_edges.sort_unstable();
        comp_edges.dedup();

        let tp = PrimalSpanningTree::grow(mesh, free, &in_t, &comp_edges, &vertices);

        let g_edges: Vec<u32> = comp_edges.iter().copied().filter(|&e| !in_t[e as usize]).collect();
        let mut g_index = vec![NONE; ne];
        for (i, &e) in g_edges.iter().enumerate() {
            g_index[e as usize] = i as u32;
        }
        let leftovers = g_edges.iter().copied().filter(|&e| !tp.in_tp[e as usize]).collect();
        DualTree {
            faces: t.faces,
            vertices,
            parent_he: t.parent_he,
            depth: t.depth,
            g_edges,
            g_index,
            primal_parent_he: tp.parent_he,
            primal_depth: tp.depth,
            leftovers,
            has_boundary: t.has_boundary,
        }
    }

    /// The fundamental cycle of `G` edge `e`, oriented so it crosses `e`
    /// from the face of `edge_halfedges(e)[0]` to the other side (for a port:
    /// from the outer node into the face).
    pub fn fundamental_cycle(&self, mesh: &TriMesh, e: u32) -> Vec<Visit> {
        let [h0, h1] = mesh.edge_halfedges(e);
        // Faces along the tree path, as (face, entry halfedge, exit halfedge).
        let (start_face, start_in) = if mesh.is_boundary_halfedge(h1) {
            (h0 / 3, h0) // enter from the outer node through the port
        } else {
            (h1 / 3, h1)
        };
        let end_face = if mesh.is_boundary_halfedge(h1) { None } else { Some(h0 / 3) };
        // Up-path from start to the root, and from end to the root.
        let up = |mut f: u32| {
            let mut path = vec![f];
            while self.parent_he[f as usize] != NONE {
                let p = self.parent_he[f as usize];
                let t = mesh.twin(p);
                match mesh.face(t) {
                    Some(g) => {
                        f = g;
                        path.push(f);
                    }
                    None => break, // reached the outer node
                }
            }
            path
        };
        let a = up(start_face);
        let b = end_face.map(up).unwrap_or_default();
        // Drop the common tail (shared ancestors above the lowest common one).
        let (mut ia, mut ib) = (a.len(), b.len());
        while ia > 0 && ib > 0 && a[ia - 1] == b[ib - 1] {
            ia -= 1;
            ib -= 1;
        }
        // Sequence of faces: a[..=ia] (up to the LCA face if shared) then b reversed.
        let mut seq: Vec<u32> = Vec::new();
        if end_face.is_some() && ia < a.len() {
            // The LCA is a face: include it once.
            seq.extend_from_slice(&a[..=ia]);
            seq.extend(b[..ib].iter().rev());
        } else {
            // The path goes through the outer node (or ends there for a port).
            seq.extend_from_slice(&a);
            seq.extend(b.iter().rev());
        }
        // Build visits with entry/exit halfedges.
        let mut visits: Vec<Visit> = Vec::with_capacity(seq.len());
        let mut h_in = start_in;
        for (i, &f) in seq.iter().enumerate() {
            let h_out = if i + 1 == seq.len() {
                match end_face {
                    Some(_) => h0, // back across e
                    None => self.parent_he[f as usize], // out through f's root port
                }
            } else {
                let g = seq[i + 1];
                self.step(mesh, f, g)
            };
            visits.push(Visit { h_in, h_out });
            if i + 1 < seq.len() {
                let g = seq[i + 1];
                h_in = if mesh.face(mesh.twin(h_out)) == Some(g) {
                    mesh.twin(h_out)
                } else {
                    self.parent_he[g as usize] // entered from the outer node through g's port
                };
            }
        }
        visits
    }

    /// The halfedge of `f` through which a tree path leaves `f` towards its
    /// tree neighbour `g` (or towards the outer node when they are only
    /// joined through it).
    fn step(&self, mesh: &TriMesh, f: u32, g: u32) -> u32 {
        let pf = self.parent_he[f as usize];
        if pf != NONE && mesh.face(mesh.twin(pf)) == Some(g) {
            return pf; // g is f's parent
        }
        let pg = self.parent_he[g as usize];
        if pg != NONE && mesh.face(mesh.twin(pg)) == Some(f) {
            return mesh.twin(pg); // f is g's parent
        }
        pf // both hang from the outer node: leave through f's port
    }

    /// The `G` edges on the `T_p` path from `a` to `b`, with the sign `+1`
    /// when the path runs along `edge_halfedges(e)[0]`.
    pub fn primal_path(&self, mesh: &TriMesh, mut a: u32, mut b: u32) -> Vec<(u32, i32)> {
        let (mut from_a, mut from_b) = (Vec::new(), Vec::new());
        while a != b {
            if self.primal_depth[a as usize] >= self.primal_depth[b as usize] {
                let h = self.primal_parent_he[a as usize]; // parent -> a
                from_a.push((mesh.edge(h), -orientation(mesh, h))); // walking a -> parent
                a = mesh.tail(h);
            } else {
                let h = self.primal_parent_he[b as usize];
                from_b.push((mesh.edge(h), orientation(mesh, h))); // later walked parent -> b
                b = mesh.tail(h);
            }
        }
        from_a.extend(from_b.into_iter().rev());
        from_a
    }
}

/// True when edge `e` is flagged in `free` (per mesh edge; an empty slice flags none).
pub fn is_free_edge(free: &[bool], e: u32) -> bool {
    free.get(e as usize).copied().unwrap_or(false)
}

/// `+1` when halfedge `h` runs along its edge's first halfedge, else `-1`.
pub fn orientation(mesh: &TriMesh, h: u32) -> i32 {
    if mesh.edge_halfedges(mesh.edge(h))[0] == h {
        1
    } else {
        -1
    }
}


/// `T` of [`DualTree`]: the faces of one component in the order they joined,
/// with their parent halfedges and depths (per mesh face).
struct DualSpanningTree {
    faces: Vec<u32>,
    parent_he: Vec<u32>,
    depth: Vec<u32>,
    has_boundary: bool,
}

impl DualSpanningTree {
    /// Grows `T` for the component of face `seed` as [`DualTree::new`] says:
    /// from the root ports along each rooted loop's chain of faces, then
    /// breadth-first inward (from `seed` on a closed component).
    fn grow(mesh: &TriMesh, seed: u32, free: &[bool]) -> DualSpanningTree {
        let comp = mesh.face_components()[seed as usize];
        let nf = mesh.n_faces();
        let mut parent_he = vec![NONE; nf];
        let mut depth = vec![NONE; nf];
        let mut faces = Vec::new();
        let mut queue = VecDeque::new();
        let in_comp = |f: u32| mesh.face_components()[f as usize] == comp;
        let is_free = |g: u32| is_free_edge(free, mesh.edge(g));

        let loops: Vec<&Vec<u32>> = mesh
            .boundary_loops()
            .iter()
            .filter(|lp| in_comp(mesh.twin(lp[0]) / 3))
            .collect();
        let has_boundary = !loops.is_empty();
        // (loop, its root halfedge) for the loops the tree hangs from.
        let mut rooted: Vec<(&Vec<u32>, u32)> =
            loops.iter().filter_map(|lp| lp.iter().find(|&&g| !is_free(g)).map(|&g| (*lp, g))).collect();
        if rooted.is_empty() && has_boundary {
            rooted.push((loops[0], loops[0][0]));
        }
        if has_boundary {
            for (lp, first) in rooted {
                // Root port: the face halfedge of the loop's first aligned edge.
                let root_h = mesh.twin(first);
                let root = root_h / 3;
                if depth[root as usize] == NONE {
                    parent_he[root as usize] = root_h;
                    depth[root as usize] = 1;
                    faces.push(root);
                    queue.push_back(root);
                }
                // Chain: the fans of the loop's vertices in order.
                for &g in lp.iter() {
                    let v = mesh.head(g);
                    let mut prev_face = NONE;
                    for h in mesh.outgoing(v) {
                        let Some(f) = mesh.face(h) else { break };
                        if prev_face != NONE && depth[f as usize] == NONE && depth[prev_face as usize] != NONE {
                            parent_he[f as usize] = h; // entered across edge of h from the previous fan face
                            depth[f as usize] = depth[prev_face as usize] + 1;
                            faces.push(f);
                            queue.push_back(f);
                        }
                        prev_face = f;
                    }
                }
            }
        } else {
            depth[seed as usize] = 1;
            faces.push(seed);
            queue.push_back(seed);
        }
        // Breadth-first growth inward.
        while let Some(f) = queue.pop_front() {
            for h in mesh.face_halfedges(f) {
                let t = mesh.twin(h);
                if let Some(g) = mesh.face(t) {
                    if depth[g as usize] == NONE {
                        parent_he[g as usize] = t;
                        depth[g as usize] = depth[f as usize] + 1;
                        faces.push(g);
                        queue.push_back(g);
                    }
                }
            }
        }

        DualSpanningTree { faces, parent_he, depth, has_boundary }
    }
}

/// `T_p` of [`DualTree`]: per mesh vertex its parent halfedge and depth, and
/// per mesh edge whether it is a tree edge.
struct PrimalSpanningTree {
    parent_he: Vec<u32>,
    depth: Vec<u32>,
    in_tp: Vec<bool>,
}

impl PrimalSpanningTree {
    /// Grows `T_p` over the edges of `comp_edges` not dual to `T` (`in_t`),
    /// spanning `vertices`.
    fn grow(mesh: &TriMesh, free: &[bool], in_t: &[bool], comp_edges: &[u32], vertices: &[u32]) -> PrimalSpanningTree {
        // T_p: breadth-first over primal edges not dual to T.
        let nv = mesh.n_vertices();
        let mut primal_parent_he = vec![NONE; nv];
        let mut primal_depth = vec![NONE; nv];
        let mut in_tp = vec![false; mesh.n_edges()];
        // Fewest non-free edges from the root (a 0-1 breadth-first search;
        // without free edges a plain one): with a free boundary, T_p runs
        // along the free edges wherever it can, so a free vertex's parent
        // edge is a free port (no integer) except where a loop joins the rest.
        let cost = |e: u32| u32::from(!is_free_edge(free, e));
        let root_v = match comp_edges.iter().find(|&&e| is_free_edge(free, e)) {
            Some(&e) => mesh.edge_vertices(e)[0],
            None => vertices[0],
        };
        let mut dist = vec![u32::MAX; nv];
        let mut done = vec![false; nv];
        dist[root_v as usize] = 0;
        primal_depth[root_v as usize] = 0;
        let mut vq = VecDeque::from([root_v]);
        while let Some(v) = vq.pop_front() {
            if std::mem::replace(&mut done[v as usize], true) {
                continue;
            }
            let ph = primal_parent_he[v as usize];
            if ph != NONE {
                in_tp[mesh.edge(ph) as usize] = true;
                primal_depth[v as usize] = primal_depth[mesh.tail(ph) as usize] + 1;
            }
            for h in mesh.outgoing(v) {
                let e = mesh.edge(h);
                let w = mesh.head(h);
                let d = dist[v as usize] + cost(e);
                if !in_t[e as usize] && !done[w as usize] && d < dist[w as usize] {
                    dist[w as usize] = d;
                    primal_parent_he[w as usize] = h;
                    if cost(e) == 0 {
                        vq.push_front(w);
                    } else {
                        vq.push_back(w);
                    }
                }
            }
        }
        debug_assert!(vertices.iter().all(|&v| primal_depth[v as usize] != NONE), "T_p spans the component");
        PrimalSpanningTree { parent_he: primal_parent_he, depth: primal_depth, in_tp }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::{grid, octahedron, square_annulus, torus};

    fn check_counts(mesh: &TriMesh, expected_leftovers: usize) {
        let t = DualTree::new(mesh, 0, &[]);
        assert_eq!(t.faces.len(), mesh.n_faces(), "T spans every face");
        let chi = mesh.euler_characteristic();
        let expected_g = t.vertices.len() as i64 - chi + if t.has_boundary { 0 } else { 1 };
        assert_eq!(t.g_edges.len() as i64, expected_g);
        assert_eq!(t.leftovers.len(), expected_leftovers);
        for &e in &t.g_edges {
            let cycle = t.fundamental_cycle(mesh, e);
            // Consecutive visits are joined by a crossing or pass through the outer node.
            for i in 0..cycle.len() {
                let (a, b) = (cycle[i], cycle[(i + 1) % cycle.len()]);
                assert_eq!(a.h_in / 3, a.h_out / 3);
                assert_ne!(a.h_in, a.h_out);
                let crossing = mesh.twin(a.h_out) == b.h_in;
                let ports = mesh.is_boundary_halfedge(mesh.twin(a.h_out)) && mesh.is_boundary_halfedge(mesh.twin(b.h_in));
                assert!(crossing || ports, "edge {e}: broken cycle at visit {i}");
            }
            // Exactly one crossing of a non-tree edge: e itself.
            let non_tree: Vec<u32> = cycle
                .iter()
                .map(|v| mesh.edge(v.h_out))
                .filter(|&x| t.g_index[x as usize] != NONE)
                .collect();
            let ports_in: Vec<u32> = cycle
                .iter()
                .map(|v| mesh.edge(v.h_in))
                .filter(|&x| mesh.is_boundary_edge(x) && t.g_index[x as usize] != NONE)
                .collect();
            let mut all: Vec<u32> = non_tree.iter().filter(|&&x| !mesh.is_boundary_edge(x)).copied().collect();
            all.extend(ports_in);
            assert_eq!(all, vec![e], "edge {e}: non-tree crossings");
        }
    }

    #[test]
    fn counts_on_closed_open_and_toroidal_meshes() {
        check_counts(&octahedron(), 0);
        check_counts(&grid(4, 3, |x, y| [x, y, 0.0]), 0);
        check_counts(&square_annulus(3, 2, 0.4, 0.0), 1);
        check_counts(&torus(8, 6, 2.0, 0.7), 2);
    }
}
