//! Holes in pairs. Where the quads removed or skipped form a ring (around a
//! horn, say), the traced quads fall into two pieces, each with one hole:
//! filling both with disks would make two closed surfaces of one. While a
//! component of the input has more than one piece of quads on it, the
//! nearest two holes of different pieces on that component are joined by a
//! strip of quads instead (never two components: a lid beside its pot).

use crate::mesh::UnionFind;
use crate::quads::QuadMesh;
use crate::vec3::{norm, sub, V3};
use crate::TriMesh;

/// Two holes are joined only when their centres are at most this many times
/// the mean of their perimeters apart.
const MAX_GAP: f64 = 0.5;

/// Pairs of `holes` (indices) to join so that each component of `mesh` has
/// one piece of `quads` on it: nearest centres first, holes of different
/// pieces on the same component with an even number of sides in all.
pub(super) fn pairs_to_join(mesh: &TriMesh, quads: &QuadMesh, holes: &[Vec<u32>]) -> Vec<(usize, usize)> {
    let mut piece = pieces(quads);
    let component = |v: u32| mesh.face_components()[quads.locations[v as usize].face as usize];
    // (input component, piece) of every quad: each piece past a
    // component's first needs a join.
    let mut on_component: Vec<(u32, u32)> = quads.quads.iter().map(|q| (component(q[0]), piece.find(q[0]))).collect();
    on_component.sort_unstable();
    on_component.dedup();
    let components: std::collections::BTreeSet<u32> = on_component.iter().map(|c| c.0).collect();
    let mut excess = on_component.len() - components.len();
    let centre = |h: &[u32]| -> V3 {
        let mut c = [0.0; 3];
        for &v in h {
            let p = quads.positions[v as usize];
            for i in 0..3 {
                c[i] += p[i] / h.len() as f64;
            }
        }
        c
    };
    let perimeter = |h: &[u32]| -> f64 {
        (0..h.len()).map(|i| norm(sub(quads.positions[h[(i + 1) % h.len()] as usize], quads.positions[h[i] as usize]))).sum()
    };
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for i in 0..holes.len() {
        for j in i + 1..holes.len() {
            let (a, b) = (&holes[i], &holes[j]);
            if (a.len() + b.len()) % 2 == 1 || component(a[0]) != component(b[0]) {
                continue;
            }
            let gap = norm(sub(centre(a), centre(b)));
            if gap <= MAX_GAP * 0.5 * (perimeter(a) + perimeter(b)) {
                candidates.push((gap, i, j));
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    let mut used = vec![false; holes.len()];
    let mut out = Vec::new();
    for (_, i, j) in candidates {
        if excess == 0 {
            break;
        }
        let (pi, pj) = (piece.find(holes[i][0]), piece.find(holes[j][0]));
        if used[i] || used[j] || pi == pj {
            continue;
        }
        piece.union(pi, pj);
        used[i] = true;
        used[j] = true;
        excess -= 1;
        out.push((i, j));
    }
    out
}

/// Joins the holes `a` and `b` (each oriented as a face filling it would
/// be; together an even number of sides) by a strip of quads: from the
/// nearest pair of their vertices, around both, each quad taking a side of
/// each (or, where one is longer, two sides of it) by the shorter new
/// diagonal. The number of quads added (unit-square corner UVs).
pub(super) fn join(quads: &mut QuadMesh, a: &[u32], b: &[u32]) -> usize {
    let (n, m) = (a.len(), b.len());
    let p = |v: u32| quads.positions[v as usize];
    let d = |x: u32, y: u32| norm(sub(p(x), p(y)));
    let s = (0..m).min_by(|&x, &y| d(a[0], b[x]).total_cmp(&d(a[0], b[y]))).expect("a hole has sides");
    // Vertex of b `j` sides back from b[s], walking against b's orientation.
    let back = |j: usize| b[(s + m * 2 - j % m) % m];
    let (mut i, mut j) = (0, 0);
    let mut added = Vec::new();
    while i < n || j < m {
        let (ra, rb) = (n - i, m - j);
        let mut options: Vec<(f64, [u32; 4], usize, usize)> = Vec::new();
        if ra >= 1 && rb >= 1 {
            options.push((d(a[(i + 1) % n], back(j + 1)), [a[i % n], a[(i + 1) % n], back(j + 1), back(j)], 1, 1));
        }
        if ra >= 2 && ra >= rb + 2 {
            options.push((d(a[(i + 2) % n], back(j)), [a[i % n], a[(i + 1) % n], a[(i + 2) % n], back(j)], 2, 0));
        }
        if rb >= 2 && rb >= ra + 2 {
            options.push((d(a[i % n], back(j + 2)), [a[i % n], back(j + 2), back(j + 1), back(j)], 0, 2));
        }
        let Some(&(_, quad, di, dj)) = options.iter().min_by(|x, y| x.0.total_cmp(&y.0)) else { break };
        added.push(quad);
        (i, j) = (i + di, j + dj);
    }
    for quad in &added {
        quads.quads.push(*quad);
        quads.uv.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    }
    added.len()
}

/// The pieces of `quads`: sets of vertices joined through quads.
fn pieces(quads: &QuadMesh) -> UnionFind {
    let mut p = UnionFind::new(quads.positions.len());
    for q in &quads.quads {
        for &v in &q[1..] {
            p.union(q[0], v);
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::pairs_to_join;
    use crate::mesh::{RawMesh, TriMesh};
    use crate::quads::{QuadMesh, SurfacePoint};

    /// Three one-quad pieces, each a hole of four sides: one on the first
    /// component of the input, two on the second. The one on the first is
    /// nearest to one of the others, but only the two on the second
    /// component are joined (the pieces are one surface there; across
    /// components they are not).
    #[test]
    fn holes_are_joined_only_on_one_component() {
        let raw = RawMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let mesh = TriMesh::from_raw(&raw).unwrap();
        assert_eq!(mesh.n_components(), 2);
        let square = |x: f64| [[x, 0.0, 0.0], [x + 0.2, 0.0, 0.0], [x + 0.2, 0.2, 0.0], [x, 0.2, 0.0]];
        let on = |face: u32| SurfacePoint { face, bary: [1.0, 0.0, 0.0] };
        let (first, second) = (mesh.face_components()[0], mesh.face_components()[1]);
        assert_ne!(first, second);
        // Piece 0 on the first component at x = 0.05; pieces 1 and 2 on the
        // second at x = 0.3 and 0.6: centres 0.25 and 0.3 apart.
        let positions: Vec<[f64; 3]> = [0.05, 0.3, 0.6].iter().flat_map(|&x| square(x)).collect();
        let locations: Vec<SurfacePoint> = [0, 1, 1].iter().flat_map(|&f| [on(f); 4]).collect();
        let quads = vec![[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]];
        let q = QuadMesh { positions, locations, uv: vec![[0.0; 2]; 12], quads, defects: Vec::new() };
        let holes: Vec<Vec<u32>> = q.quads.iter().map(|c| c.iter().rev().copied().collect()).collect();
        assert_eq!(pairs_to_join(&mesh, &q, &holes), vec![(1, 2)]);
    }
}
