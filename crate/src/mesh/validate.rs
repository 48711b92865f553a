//! Analysis of an imported triangle soup: figures and every [`Problem`], with
//! the offending elements. Never panics, whatever the input.
//!
//! Conventions (see also [`MeshReport`]):
//! * vertices are welded ([`weld`]) unless a problem's doc says "source";
//! * a face with an out-of-range index is reported and left out of all
//!   topology (its in-range corners still count as referenced vertices);
//! * figures (edges, boundary/non-manifold edges, χ) count every other face,
//!   degenerate ones included, edges keyed by welded vertex pair — the way the
//!   test-mesh README counts them by index. Problems about edges
//!   (non-manifold, orientation, duplicates) ignore degenerate faces, which
//!   already have their own problem;
//! * connected components are **edge-connected**: two faces are in the same
//!   component when a chain of faces sharing edges joins them (faces touching
//!   only at a vertex are separate components; such a vertex is a
//!   non-manifold vertex and counts towards each component's V).

use super::topology::{he_head, he_tail, EdgeTable, UnionFind};
use super::weld::{close_cracks, weld, Welded, NO_VERTEX};
use super::problem::{FileNames, LocatedProblem};
use super::{MeshReport, RawMesh};
use crate::io::FileNumbering;
use crate::Problem;

/// Relative tolerance of the zero-area test: a face is flagged when
/// `|e1 × e2| <= ZERO_AREA_REL * (longest edge)²` (or is exactly zero).
pub const ZERO_AREA_REL: f64 = 1e-12;

/// Figures and problems of `raw` (connectivity from welded positions).
/// Never panics: out-of-range indices, NaN coordinates and empty meshes are
/// reported, not fatal.
pub fn analyze(raw: &RawMesh) -> MeshReport {
    analyze_raw(raw).report
}

/// What [`analyze_located`] finds: the report, the welding the problems'
/// ids refer to, and every problem located and named as the file does.
pub struct Located {
    pub report: MeshReport,
    pub welded: Welded,
    pub problems: Vec<LocatedProblem>,
}

/// Like [`analyze`], with the welding and each problem as a
/// [`LocatedProblem`] whose message follows the file's `numbering`.
pub fn analyze_located(raw: &RawMesh, numbering: &FileNumbering) -> Located {
    let Analysis { welded, report, .. } = analyze_raw(raw);
    let names = FileNames { raw, welded: &welded, numbering };
    let problems = report.problems.iter().map(|p| LocatedProblem::new(p, &names)).collect();
    Located { report, welded, problems }
}

/// Welds `raw` by position, closes floating-point cracks along open
/// boundaries ([`super::weld::close_cracks`]) and analyses the result.
pub(crate) fn analyze_raw(raw: &RawMesh) -> Analysis {
    let a = analyze_welded(raw, weld(raw));
    if a.report.boundary_edges == 0 {
        return a;
    }
    let boundary_edges: Vec<[u32; 2]> = (0..a.edges.n_edges())
        .filter(|&e| a.edges.start[e + 1] - a.edges.start[e] == 1)
        .map(|e| a.edges.verts[e])
        .collect();
    let mut on_boundary = vec![false; a.welded.positions.len()];
    for e in &boundary_edges {
        on_boundary[e[0] as usize] = true;
        on_boundary[e[1] as usize] = true;
    }
    let boundary: Vec<u32> = boundary_edges.iter().flatten().copied().collect();
    let joined: std::collections::HashSet<[u32; 2]> =
        a.edges.verts.iter().filter(|e| on_boundary[e[0] as usize] && on_boundary[e[1] as usize]).copied().collect();
    match close_cracks(&a.welded, &boundary, |u, v| joined.contains(&[u.min(v), u.max(v)])) {
        Some(closed) => analyze_welded(raw, closed),
        None => a,
    }
}

/// Like [`analyze`], but connectivity comes from the file's indices as given
/// (no welding by position): the figures the test-mesh README lists.
pub fn analyze_by_index(raw: &RawMesh) -> MeshReport {
    analyze_welded(raw, Welded::by_index(raw)).report
}

/// Everything the analysis computes; [`super::TriMesh`] builds on it.
pub(crate) struct Analysis {
    pub welded: Welded,
    pub edges: EdgeTable,
    /// Component of each face (`u32::MAX` for faces left out).
    pub face_component: Vec<u32>,
    pub report: MeshReport,
}

/// Analyses `raw` given its welding (`weld(raw)` or `Welded::by_index(raw)`):
/// one phase per kind of check, each returning its problems and figures.
pub(crate) fn analyze_welded(raw: &RawMesh, welded: Welded) -> Analysis {
    let n_src = raw.positions.len();
    let nf = raw.triangles.len();
    let nv = welded.positions.len();
    let tris = &welded.triangles;

    let src = SourceChecks::run(raw, &welded);
    let use_face = &src.use_face;
    let deg = FaceChecks::run(raw, &welded, use_face);
    let edges = EdgeTable::build(nv, tris, use_face);
    let ne = edges.n_edges();
    let ec = EdgeChecks::run(&edges, tris, &deg.degenerate);
    let (face_component, nc) = edge_components(&edges, use_face);
    let fans = vertex_fans(&edges, tris, use_face, nv);
    let mut p_nm_vertex = Vec::new();
    for (v, &n) in fans.iter().enumerate() {
        if n > 1 {
            p_nm_vertex.push(Problem::NonManifoldVertex { vertex: v as u32, fans: n });
        }
    }
    let (n_loops, loops_per_comp) = boundary_loops(&edges, &ec.boundary_edges, &face_component, nc);
    let (f_c, chi_c) = component_euler_characteristics(&edges, tris, use_face, &face_component, nc, nv);
    let genus: Vec<i64> = (0..nc).map(|c| (2 - chi_c[c] - loops_per_comp[c] as i64) / 2).collect();
    let (p_degen, p_zero_len, p_zero_area) = (deg.degen, deg.zero_len, deg.zero_area);
    let (p_dup, p_nm_edge, p_orient) = (ec.dup, ec.nm_edge, ec.orient);

    let mut manifold = vec![true; nc];
    {
        let mut bad_face = |f: u32| {
            if let Some(&c) = face_component.get(f as usize) {
                if c != u32::MAX {
                    manifold[c as usize] = false;
                }
            }
        };
        for p in p_degen.iter().chain(&p_zero_len).chain(&p_dup).chain(&p_nm_edge).chain(&p_orient) {
            match p {
                Problem::DegenerateFace { face, .. } | Problem::ZeroLengthEdge { face, .. } => bad_face(*face),
                Problem::DuplicateFace { faces } | Problem::InconsistentOrientation { faces, .. } => {
                    faces.iter().for_each(|&f| bad_face(f))
                }
                Problem::NonManifoldEdge { faces, .. } => faces.iter().for_each(|&f| bad_face(f)),
                _ => {}
            }
        }
        if !p_nm_vertex.is_empty() {
            for f in 0..nf {
                if use_face[f] && tris[f].iter().any(|&v| fans[v as usize] > 1) {
                    bad_face(f as u32);
                }
            }
        }
    }
    let vertex_components = vertex_connected_components(tris, use_face, nv);
    let faces_used = use_face.iter().filter(|&&u| u).count() as i64;

    let non_manifold_vertices = p_nm_vertex.len();
    let mut problems = src.range;
    for group in [src.finite, src.unref, p_degen, p_zero_len, p_zero_area, p_dup, p_nm_edge, p_nm_vertex, p_orient] {
        problems.extend(group);
    }
    let report = MeshReport {
        vertices: nv,
        faces: nf,
        boundary_loops: n_loops,
        components: nc,
        vertex_connected_components: vertex_components,
        euler_characteristic: nv as i64 - ne as i64 + faces_used,
        genus,
        problems,
        source_vertices: n_src,
        // A split pinch vertex adds a vertex without a source of its own.
        merged_vertices: src.referenced_sources.saturating_sub(nv),
        edges: ne,
        boundary_edges: ec.boundary_edges.len(),
        non_manifold_edges: ec.non_manifold_edges,
        non_manifold_vertices,
        euler_characteristic_per_component: chi_c,
        boundary_loops_per_component: loops_per_comp,
        faces_per_component: f_c.iter().map(|&x| x as usize).collect(),
        component_is_manifold: manifold,
    };
    Analysis { welded, edges, face_component, report }
}


/// Index range, coordinates and references, in source indices.
struct SourceChecks {
    range: Vec<Problem>,
    finite: Vec<Problem>,
    unref: Vec<Problem>,
    /// Per face: all its indices are in range (the other phases skip it otherwise).
    use_face: Vec<bool>,
    referenced_sources: usize,
}

impl SourceChecks {
    fn run(raw: &RawMesh, welded: &Welded) -> SourceChecks {
        let n_src = raw.positions.len();
        let nf = raw.triangles.len();
        let mut p_range = Vec::new();
        let mut use_face = vec![true; nf];
        for (f, t) in raw.triangles.iter().enumerate() {
            for &i in t {
                if i as usize >= n_src {
                    p_range.push(Problem::IndexOutOfRange {
                        face: f as u32,
                        index: i,
                        vertex_count: n_src.min(u32::MAX as usize) as u32,
                    });
                    use_face[f] = false;
                }
            }
        }
        let mut p_finite = Vec::new();
        let mut p_unref = Vec::new();
        let mut referenced_sources = 0usize;
        for (s, p) in raw.positions.iter().enumerate() {
            if welded.source_to_welded.get(s).copied().unwrap_or(NO_VERTEX) == NO_VERTEX {
                p_unref.push(Problem::UnreferencedVertex { vertex: s as u32 });
            } else {
                referenced_sources += 1;
                if !p.iter().all(|c| c.is_finite()) {
                    p_finite.push(Problem::NonFiniteCoordinate { vertex: s as u32 });
                }
            }
        }
        SourceChecks { range: p_range, finite: p_finite, unref: p_unref, use_face, referenced_sources }
    }
}

/// Degenerate faces (a repeated source index), zero-length edges (welded
/// together) and zero-area faces (relative to the longest edge, [`ZERO_AREA_REL`]).
struct FaceChecks {
    degen: Vec<Problem>,
    zero_len: Vec<Problem>,
    zero_area: Vec<Problem>,
    /// Per face: degenerate or with a zero-length edge (left out of the edge checks).
    degenerate: Vec<bool>,
}

impl FaceChecks {
    fn run(raw: &RawMesh, welded: &Welded, use_face: &[bool]) -> FaceChecks {
        let nf = raw.triangles.len();
        let tris = &welded.triangles;
        let mut p_degen = Vec::new();
        let mut p_zero_len = Vec::new();
        let mut p_zero_area = Vec::new();
        let mut degenerate = vec![false; nf];
        for f in 0..nf {
            if !use_face[f] {
                continue;
            }
            let s = raw.triangles[f];
            let w = tris[f];
            if s[0] == s[1] || s[1] == s[2] || s[0] == s[2] {
                p_degen.push(Problem::DegenerateFace { face: f as u32, vertices: w });
                degenerate[f] = true;
            } else if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
                let (i, j) = if w[0] == w[1] {
                    (0, 1)
                } else if w[1] == w[2] {
                    (1, 2)
                } else {
                    (2, 0)
                };
                p_zero_len.push(Problem::ZeroLengthEdge { edge: [s[i], s[j]], face: f as u32 });
                degenerate[f] = true;
            } else {
                let p = [
                    welded.positions[w[0] as usize],
                    welded.positions[w[1] as usize],
                    welded.positions[w[2] as usize],
                ];
                if p.iter().all(|q| q.iter().all(|c| c.is_finite())) {
                    let e0 = sub(p[1], p[0]);
                    let e1 = sub(p[2], p[0]);
                    let e2 = sub(p[2], p[1]);
                    let c = cross(e0, e1);
                    let c2 = dot(c, c);
                    let m = dot(e0, e0).max(dot(e1, e1)).max(dot(e2, e2));
                    let tol = ZERO_AREA_REL * m;
                    if c2 <= tol * tol {
                        p_zero_area.push(Problem::ZeroAreaFace { face: f as u32, area: 0.5 * c2.sqrt() });
                    }
                }
            }
        }
        FaceChecks { degen: p_degen, zero_len: p_zero_len, zero_area: p_zero_area, degenerate }
    }
}

/// Boundary and non-manifold edges, inconsistent orientation and duplicate faces.
struct EdgeChecks {
    boundary_edges: Vec<u32>,
    /// Edges with more than two faces, counting every face.
    non_manifold_edges: usize,
    nm_edge: Vec<Problem>,
    orient: Vec<Problem>,
    dup: Vec<Problem>,
}

impl EdgeChecks {
    fn run(edges: &EdgeTable, tris: &[[u32; 3]], degenerate: &[bool]) -> EdgeChecks {
        let ne = edges.n_edges();
        let mut boundary_edges = Vec::new();
        let mut non_manifold_edges = 0usize;
        let mut p_nm_edge = Vec::new();
        let mut p_orient = Vec::new();
        let mut p_dup: Vec<(u32, u32)> = Vec::new();
        let mut nd: Vec<u32> = Vec::new();
        let mut key_faces: Vec<(u32, [u32; 3])> = Vec::new();
        for e in 0..ne {
            let hs = edges.halfedges(e);
            let [lo, hi] = edges.verts[e];
            match hs.len() {
                1 => boundary_edges.push(e as u32),
                2 => {}
                _ => non_manifold_edges += 1,
            }
            if hs.len() < 2 {
                continue;
            }
            nd.clear();
            nd.extend(hs.iter().copied().filter(|&h| !degenerate[(h / 3) as usize]));
            if lo != hi {
                if nd.len() > 2 {
                    p_nm_edge.push(Problem::NonManifoldEdge { edge: [lo, hi], faces: nd.iter().map(|h| h / 3).collect() });
                } else if nd.len() == 2 && he_tail(tris, nd[0]) == he_tail(tris, nd[1]) {
                    p_orient.push(Problem::InconsistentOrientation {
                        edge: [he_tail(tris, nd[0]), he_head(tris, nd[0])],
                        faces: [nd[0] / 3, nd[1] / 3],
                    });
                }
            }
            // Duplicate faces: checked once per face, on the edge of its two
            // smallest vertex ids.
            key_faces.clear();
            for &h in &nd {
                let f = h / 3;
                let mut s = tris[f as usize];
                s.sort_unstable();
                if s[0] == lo && s[1] == hi && key_faces.last().map(|k| k.0) != Some(f) {
                    key_faces.push((f, s));
                }
            }
            for j in 1..key_faces.len() {
                if let Some(i) = (0..j).find(|&i| key_faces[i].1 == key_faces[j].1) {
                    p_dup.push((key_faces[i].0, key_faces[j].0));
                }
            }
        }
        p_dup.sort_unstable_by_key(|&(a, b)| (b, a));
        let p_dup: Vec<Problem> = p_dup.into_iter().map(|(a, b)| Problem::DuplicateFace { faces: [a, b] }).collect();
        EdgeChecks { boundary_edges, non_manifold_edges, nm_edge: p_nm_edge, orient: p_orient, dup: p_dup }
    }
}

/// Edge-connected components: per face its component (`u32::MAX` for faces
/// left out), numbered by smallest face; and their number.
fn edge_components(edges: &EdgeTable, use_face: &[bool]) -> (Vec<u32>, usize) {
    let nf = use_face.len();
    let ne = edges.n_edges();
    let mut uf = UnionFind::new(nf);
    for e in 0..ne {
        let hs = edges.halfedges(e);
        for w in hs.windows(2) {
            uf.union(w[0] / 3, w[1] / 3);
        }
    }
    let mut face_component = vec![u32::MAX; nf];
    let mut n_comp = 0u32;
    for f in 0..nf {
        if !use_face[f] {
            continue;
        }
        let r = uf.find(f as u32) as usize;
        // Roots are the smallest face of their set, so they are met first.
        if r == f {
            face_component[f] = n_comp;
            n_comp += 1;
        } else {
            face_component[f] = face_component[r];
        }
    }
    drop(uf);
    let nc = n_comp as usize;
    (face_component, nc)
}

/// Per welded vertex, the number of fans of faces around it (corners joined
/// across the edges they share); more than one is a non-manifold vertex.
fn vertex_fans(edges: &EdgeTable, tris: &[[u32; 3]], use_face: &[bool], nv: usize) -> Vec<u32> {
    let nf = use_face.len();
    let ne = edges.n_edges();
    let mut cuf = UnionFind::new(3 * nf);
    for e in 0..ne {
        let hs = edges.halfedges(e);
        let [lo, hi] = edges.verts[e];
        let mut first_lo = u32::MAX;
        let mut first_hi = u32::MAX;
        for &h in hs {
            let f = h / 3;
            let k = h % 3;
            let ct = h;
            let ch = 3 * f + (k + 1) % 3;
            if lo == hi {
                cuf.union(ct, ch);
                continue;
            }
            let (c_lo, c_hi) = if he_tail(tris, h) == lo { (ct, ch) } else { (ch, ct) };
            if first_lo == u32::MAX {
                first_lo = c_lo;
                first_hi = c_hi;
            } else {
                cuf.union(first_lo, c_lo);
                cuf.union(first_hi, c_hi);
            }
        }
    }
    let mut fans = vec![0u32; nv];
    for f in 0..nf {
        if !use_face[f] {
            continue;
        }
        for k in 0..3 {
            let c = (3 * f + k) as u32;
            if cuf.find(c) == c {
                fans[tris[f][k] as usize] += 1;
            }
        }
    }
    drop(cuf);
    fans
}

/// Boundary loops (boundary edges joined at a vertex within a component):
/// their number, and their number per component.
fn boundary_loops(edges: &EdgeTable, boundary_edges: &[u32], face_component: &[u32], nc: usize) -> (usize, Vec<usize>) {
    let nb = boundary_edges.len();
    let mut ends: Vec<(u32, u32, u32)> = Vec::with_capacity(2 * nb);
    for (bi, &e) in boundary_edges.iter().enumerate() {
        let h = edges.halfedges(e as usize)[0];
        let c = face_component[(h / 3) as usize];
        let [lo, hi] = edges.verts[e as usize];
        ends.push((lo, c, bi as u32));
        ends.push((hi, c, bi as u32));
    }
    ends.sort_unstable();
    let mut buf = UnionFind::new(nb);
    for w in ends.windows(2) {
        if w[0].0 == w[1].0 && w[0].1 == w[1].1 {
            buf.union(w[0].2, w[1].2);
        }
    }
    let mut loops_per_comp = vec![0usize; nc];
    let mut n_loops = 0usize;
    for (bi, &e) in boundary_edges.iter().enumerate() {
        if buf.find(bi as u32) == bi as u32 {
            n_loops += 1;
            let h = edges.halfedges(e as usize)[0];
            loops_per_comp[face_component[(h / 3) as usize] as usize] += 1;
        }
    }
    (n_loops, loops_per_comp)
}

/// Per component: its faces and its Euler characteristic V − E + F.
fn component_euler_characteristics(
    edges: &EdgeTable,
    tris: &[[u32; 3]],
    use_face: &[bool],
    face_component: &[u32],
    nc: usize,
    nv: usize,
) -> (Vec<i64>, Vec<i64>) {
    let nf = use_face.len();
    let ne = edges.n_edges();
    let mut f_c = vec![0i64; nc];
    let mut e_c = vec![0i64; nc];
    let mut v_c = vec![0i64; nc];
    for f in 0..nf {
        if use_face[f] {
            f_c[face_component[f] as usize] += 1;
        }
    }
    for e in 0..ne {
        let h = edges.halfedges(e)[0];
        e_c[face_component[(h / 3) as usize] as usize] += 1;
    }
    // faces ordered by component (counting sort), then mark vertices per component
    let mut order_start = vec![0usize; nc + 1];
    for c in 0..nc {
        order_start[c + 1] = order_start[c] + f_c[c] as usize;
    }
    let mut order = vec![0u32; order_start[nc]];
    let mut fill = order_start.clone();
    for f in 0..nf {
        if use_face[f] {
            let c = face_component[f] as usize;
            order[fill[c]] = f as u32;
            fill[c] += 1;
        }
    }
    let mut mark = vec![u32::MAX; nv];
    for c in 0..nc {
        for &f in &order[order_start[c]..order_start[c + 1]] {
            for &v in &tris[f as usize] {
                if mark[v as usize] != c as u32 {
                    mark[v as usize] = c as u32;
                    v_c[c] += 1;
                }
            }
        }
    }
    let chi_c: Vec<i64> = (0..nc).map(|c| v_c[c] - e_c[c] + f_c[c]).collect();
    (f_c, chi_c)
}

/// Components when faces sharing only a vertex also count as connected.
fn vertex_connected_components(tris: &[[u32; 3]], use_face: &[bool], nv: usize) -> usize {
    let nf = use_face.len();
    let mut vuf = UnionFind::new(nv);
    for f in 0..nf {
        if use_face[f] {
            let t = tris[f];
            vuf.union(t[0], t[1]);
            vuf.union(t[0], t[2]);
        }
    }
    let mut vertex_components = 0usize;
    let mut root_seen = vec![false; nv];
    for f in 0..nf {
        if use_face[f] {
            let r = vuf.find(tris[f][0]) as usize;
            if !root_seen[r] {
                root_seen[r] = true;
                vertex_components += 1;
            }
        }
    }
    drop(vuf);
    vertex_components
}

pub(crate) use crate::vec3::{cross, dot, sub};
