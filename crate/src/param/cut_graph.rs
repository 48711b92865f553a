//! Cut to a topological disk (Appendix B, step 1; Eppstein 2003).
//!
//! The features are already open in the cut mesh `Mc` of the placement. On
//! `Mc`, the edges not crossed by a breadth-first dual spanning tree form a
//! cut graph (tree–cotree: it closes every homology loop and joins every
//! boundary loop); branches ending at no cone and no boundary are pruned.
//! Seams are the remaining interior edges of `Mc` plus every opened feature
//! edge (a feature seam carries the same transition constraint as any other).
//! Wedges (UV vertices) are the corners around each vertex not separated by
//! a seam or a boundary.

use super::field::CrossField;
use super::ParamError;
use crate::cones::ConePlacement;
use crate::mesh::{TriMesh, UnionFind};

/// A maximal chain of seam edges with one transition
/// `f_g = Rot(-m pi/2) f_f + t` (B.2), `f` the face of each halfedge
/// (left of the walk) and `g` the face of its twin.
#[derive(Clone, Debug)]
pub struct SeamCurve {
    /// Face halfedges of the original mesh, head to tail along the curve.
    pub halfedges: Vec<u32>,
    /// Matching `m` of every halfedge of the curve (eq. 21), modulo 4.
    pub matching: i64,
    /// True when the curve is a closed loop through no branch point.
    pub closed: bool,
}

/// The cut graph and the wedges of the cut disk.
#[derive(Clone, Debug)]
pub struct CutGraph {
    /// Per face corner `3 f + k`: its wedge (UV vertex).
    pub wedge: Vec<u32>,
    pub n_wedges: usize,
    /// Per original edge: true when it is a seam.
    pub is_seam: Vec<bool>,
    /// Seam edges (original ids), ascending.
    pub seam_edges: Vec<u32>,
    pub curves: Vec<SeamCurve>,
    /// One wedge per component of the disk (pinned at the origin).
    pub pins: Vec<u32>,
    /// Per original vertex: total cone index `k` (interior cones and boundary corners).
    pub vertex_k: Vec<i32>,
}

/// Builds the cut graph for `placement` (see the module doc). Contract: every
/// interior cut-mesh vertex with `k != 0` lies on the cut, every component of
/// the result is a topological disk, and every non-seam interior edge has a
/// matching `≡ 0 (mod 4)` (else [`ParamError::UncutSingularity`]).
pub fn cut_graph(mesh: &TriMesh, placement: &ConePlacement, field: &CrossField) -> Result<CutGraph, ParamError> {
    let cm = &placement.cut.mesh;
    let nf = mesh.n_faces();
    let ne_c = cm.n_edges();

    // The dual spanning tree of the field propagation (matching 0 on it).
    let in_tree = &field.tree_edge;
    let pins_faces = &field.roots;
    // Cotree edges, then prune dangling branches (leaf at an interior non-cone vertex).
    let mut cut = vec![false; ne_c];
    let mut degree = vec![0u32; cm.n_vertices()];
    for e in 0..ne_c as u32 {
        if cm.is_boundary_edge(e) || !in_tree[e as usize] {
            cut[e as usize] = !cm.is_boundary_edge(e);
            for v in cm.edge_vertices(e) {
                degree[v as usize] += 1;
            }
        }
    }
    let prunable = |v: u32, degree: &[u32]| degree[v as usize] == 1 && !cm.is_boundary_vertex(v) && placement.k[v as usize] == 0;
    let mut stack: Vec<u32> = (0..cm.n_vertices() as u32).filter(|&v| prunable(v, &degree)).collect();
    while let Some(v) = stack.pop() {
        if !prunable(v, &degree) {
            continue;
        }
        let Some(h) = cm.outgoing(v).find(|&h| cut[cm.edge(h) as usize]) else { continue };
        cut[cm.edge(h) as usize] = false;
        degree[v as usize] -= 1;
        let w = cm.head(h);
        degree[w as usize] -= 1;
        if prunable(w, &degree) {
            stack.push(w);
        }
    }

    // Seams on the original mesh.
    let mut is_seam = vec![false; mesh.n_edges()];
    for h in 0..3 * nf as u32 {
        let ct = cm.twin(h);
        let opened = cm.is_boundary_halfedge(ct) && !mesh.is_boundary_halfedge(mesh.twin(h));
        if opened || (!cm.is_boundary_halfedge(ct) && cut[cm.edge(h) as usize]) {
            is_seam[mesh.edge(h) as usize] = true;
        }
    }
    let seam_edges: Vec<u32> = (0..mesh.n_edges() as u32).filter(|&e| is_seam[e as usize]).collect();

    // Wedges: union corners across interior non-seam edges.
    let mut corners = UnionFind::new(3 * nf);
    for e in 0..mesh.n_edges() as u32 {
        if is_seam[e as usize] || mesh.is_boundary_edge(e) {
            continue;
        }
        let [h, t] = mesh.edge_halfedges(e);
        let m = field.matching[h as usize];
        if m.rem_euclid(4) != 0 {
            return Err(ParamError::UncutSingularity { edge: e, matching: m });
        }
        for (a, b) in [(h, mesh.next(t)), (mesh.next(h), t)] {
            corners.union(a, b);
        }
    }
    let mut id = vec![u32::MAX; 3 * nf];
    let mut wedge = vec![0u32; 3 * nf];
    let mut n_wedges = 0usize;
    for c in 0..3 * nf {
        let r = corners.find(c as u32) as usize;
        if id[r] == u32::MAX {
            id[r] = n_wedges as u32;
            n_wedges += 1;
        }
        wedge[c] = id[r];
    }
    let pins = pins_faces.iter().map(|&f| wedge[3 * f as usize]).collect();

    // Total cone index per original vertex.
    let mut vertex_k = vec![0i32; mesh.n_vertices()];
    for c in placement.cones.iter().chain(&placement.boundary_corners) {
        if let Some(k) = vertex_k.get_mut(c.vertex as usize) {
            *k = c.k;
        }
    }
    let curves = seam_curves(mesh, &is_seam, &vertex_k, field);
    Ok(CutGraph { wedge, n_wedges, is_seam, seam_edges, curves, pins, vertex_k })
}

/// Splits the seam graph into maximal chains between branch points, cones
/// and boundary vertices; a chain is also split where the matching changes.
fn seam_curves(mesh: &TriMesh, is_seam: &[bool], vertex_k: &[i32], field: &CrossField) -> Vec<SeamCurve> {
    let seam_out = |v: u32| {
        mesh.outgoing(v).filter(move |&h| !mesh.is_boundary_halfedge(h) && is_seam[mesh.edge(h) as usize])
    };
    let node = |v: u32| seam_out(v).count() != 2 || vertex_k[v as usize] != 0 || mesh.is_boundary_vertex(v);
    let mut visited = vec![false; mesh.n_edges()];
    let mut chains: Vec<(Vec<u32>, bool)> = Vec::new();
    let walk = |h0: u32, visited: &mut Vec<bool>| -> (Vec<u32>, bool) {
        let mut hs = Vec::new();
        let mut cur = h0;
        loop {
            visited[mesh.edge(cur) as usize] = true;
            hs.push(cur);
            let w = mesh.head(cur);
            if node(w) {
                return (hs, false);
            }
            let Some(next) = seam_out(w).find(|&g| mesh.edge(g) != mesh.edge(cur)) else { return (hs, false) };
            if visited[mesh.edge(next) as usize] {
                return (hs, mesh.head(cur) == mesh.tail(h0));
            }
            cur = next;
        }
    };
    for v in 0..mesh.n_vertices() as u32 {
        if !node(v) {
            continue;
        }
        let outs: Vec<u32> = seam_out(v).collect();
        for h in outs {
            if !visited[mesh.edge(h) as usize] {
                chains.push(walk(h, &mut visited));
            }
        }
    }
    for e in 0..mesh.n_edges() as u32 {
        if is_seam[e as usize] && !visited[e as usize] {
            let h = mesh.edge_halfedges(e)[0];
            chains.push(walk(h, &mut visited));
        }
    }
    // Split where the matching (mod 4) changes.
    let mut curves = Vec::new();
    for (hs, closed) in chains {
        let mut start = 0;
        let m_of = |h: u32| field.matching[h as usize].rem_euclid(4);
        let uniform = hs.iter().all(|&h| m_of(h) == m_of(hs[0]));
        for i in 1..=hs.len() {
            if i == hs.len() || m_of(hs[i]) != m_of(hs[start]) {
                curves.push(SeamCurve {
                    halfedges: hs[start..i].to_vec(),
                    matching: m_of(hs[start]),
                    closed: closed && uniform,
                });
                start = i;
            }
        }
    }
    curves
}
