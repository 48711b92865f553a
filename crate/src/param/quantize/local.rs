//! Untangling near the folds only. A rounded map folds in a few places
//! (next to cones, between close feature lines), yet the untangler of
//! [`super::super::untangle`] moves every unknown and preconditions every
//! step with the whole mesh's KKT: on a 52 k-face mesh 566 iterations and
//! 7 s for 41 inverted triangles. Here the unknowns of the faces a few grid
//! cells around the inverted ones are untangled, everything else held:
//! the rows of the system restricted to those unknowns (the rest of each
//! row is a constant, which the map satisfies), a KKT of the patch's
//! Poisson stiffness on them, and the patch's elements. Where the patch
//! would take much of the mesh (folds spread all over), the caller
//! untangles the whole map instead ([`super::Quantizer::untangle_locally`]).

use super::super::element::{signed_uv_area, Element};
use super::super::seamless::stiffness_triplets;
use super::super::untangle::{untangle, UntangleOptions, UntangleStats};
use super::fit::{factored, precondition};
use crate::linalg::{independent_rows, Kkt, LdltSolver, LinalgError, NullSpaceProjector, Triplet};

/// The unknowns of a patch of faces (free), the unknowns of its faces'
/// other corners (held), its elements renumbered onto them, and the
/// factored KKT of its constrained Poisson problem.
pub(super) struct Patch {
    /// Global unknown of each local one: the free ones first, then the held.
    global: Vec<usize>,
    n_free: usize,
    elements: Vec<Element>,
    solver: LdltSolver,
    projector: Option<NullSpaceProjector>,
    n_rows: usize,
}

/// Faces with `det J <= 0` in `x`.
pub(super) fn inverted_faces(elements: &[Element], x: &[f64]) -> Vec<usize> {
    (0..elements.len()).filter(|&f| !(signed_uv_area(elements[f].unknowns_uv(x)) > 0.0)).collect()
}

/// Per face of `faces`: whether it lies within `rings` vertex rings of the
/// faces `seeds`.
pub(super) fn faces_around(faces: &[[u32; 3]], seeds: &[usize], rings: usize) -> Vec<bool> {
    let n_vertices = faces.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
    let mut vertex_faces: Vec<Vec<usize>> = vec![Vec::new(); n_vertices];
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            vertex_faces[v as usize].push(f);
        }
    }
    let mut in_patch = vec![false; faces.len()];
    let mut front: Vec<usize> = seeds.to_vec();
    front.iter().for_each(|&f| in_patch[f] = true);
    for _ in 0..rings {
        let mut next = Vec::new();
        for &f in &front {
            for &v in &faces[f] {
                for &g in &vertex_faces[v as usize] {
                    if !in_patch[g] {
                        in_patch[g] = true;
                        next.push(g);
                    }
                }
            }
        }
        front = next;
    }
    in_patch
}

impl Patch {
    /// The patch of the faces `in_patch` (face `f` is `elements[f]`): their
    /// unknowns are free unless a face outside uses them too. `c` (rows `<
    /// m`) are the system's rows on all `n` unknowns. `None` when the patch
    /// has no free unknown.
    pub(super) fn new(elements: &[Element], in_patch: &[bool], c: &[Triplet], m: usize, n: usize) -> Result<Option<Patch>, LinalgError> {
        // Unknowns of faces outside are held; the patch's others are free.
        let mut held = vec![false; n];
        let mut used = vec![false; n];
        for (f, el) in elements.iter().enumerate() {
            for &u in el.x.iter().flatten() {
                if in_patch[f] {
                    used[u] = true;
                } else {
                    held[u] = true;
                }
            }
        }
        let mut local = vec![usize::MAX; n];
        let mut global: Vec<usize> = Vec::new();
        for u in (0..n).filter(|&u| used[u] && !held[u]) {
            local[u] = global.len();
            global.push(u);
        }
        let n_free = global.len();
        if n_free == 0 {
            return Ok(None);
        }
        for u in (0..n).filter(|&u| used[u] && held[u]) {
            local[u] = global.len();
            global.push(u);
        }
        let patch_elements: Vec<Element> = elements
            .iter()
            .zip(in_patch)
            .filter(|(_, &inside)| inside)
            .map(|(el, _)| Element { x: el.x.map(|row| row.map(|u| local[u])), ..*el })
            .collect();
        // The rows on free unknowns, their held part a constant.
        let mut rows: Vec<Vec<(usize, i64)>> = vec![Vec::new(); m];
        for &(r, u, a) in c {
            if local[u] < n_free {
                rows[r].push((local[u], a.round() as i64));
            }
        }
        rows.retain(|row| !row.is_empty());
        let keep = independent_rows(&rows, n_free);
        let mut c_local = Vec::new();
        let mut n_rows = 0;
        for row in rows.iter().zip(&keep).filter(|(_, &k)| k).map(|(row, _)| row) {
            c_local.extend(row.iter().map(|&(u, a)| (n_rows, u, a as f64)));
            n_rows += 1;
        }
        let stiffness: Vec<Triplet> = stiffness_triplets(&patch_elements, &vec![1.0; patch_elements.len()])
            .into_iter()
            .filter(|&(i, j, _)| i < n_free && j < n_free)
            .collect();
        let solver = factored(&Kkt::assemble(&stiffness, n_free, &c_local, n_rows)?)?;
        let projector = NullSpaceProjector::new(&c_local, n_free, n_rows).ok();
        Ok(Some(Patch { global, n_free, elements: patch_elements, solver, projector, n_rows }))
    }

    /// Untangles `x` (all unknowns, model units) on the patch's free
    /// unknowns, the others held; `x` is changed only there.
    pub(super) fn untangle(&self, x: &mut [f64], options: &UntangleOptions) -> UntangleStats {
        let mut xl: Vec<f64> = self.global.iter().map(|&u| x[u]).collect();
        // Held unknowns do not move.
        let precondition = |q: &mut [f64]| {
            let (free, held) = q.split_at_mut(self.n_free);
            precondition(&self.solver, self.n_rows, free, self.projector.as_ref());
            held.iter_mut().for_each(|v| *v = 0.0);
        };
        let stats = untangle(&self.elements, &precondition, &mut xl, options);
        for (&u, &v) in self.global[..self.n_free].iter().zip(&xl) {
            x[u] = v;
        }
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The identity map of an `n × n`-vertex grid on the unit square (u
    /// unknowns `0..n²`, v unknowns `n²..2n²`, one per vertex), its
    /// elements and faces.
    fn grid(n: usize) -> (Vec<Element>, Vec<[u32; 3]>, Vec<f64>) {
        let (elements, p, _) = crate::param::untangle::tests::grid(n);
        let faces = elements.iter().map(|el| el.x[0].map(|u| u as u32)).collect();
        let x = p.iter().map(|q| q[0]).chain(p.iter().map(|q| q[1])).collect();
        (elements, faces, x)
    }

    /// A fold of two vertices in one corner of a grid whose boundary is
    /// pinned and whose two middle columns are tied (`u_a - u_b` fixed): the
    /// patch untangles it, moves nothing outside itself and keeps every row.
    #[test]
    fn a_fold_is_untangled_on_its_patch_alone() {
        let n = 12;
        let nv = n * n;
        let (elements, faces, mut x) = grid(n);
        let boundary = |k: usize| k / n == 0 || k / n == n - 1 || k % n == 0 || k % n == n - 1;
        let mut rows: Vec<Vec<(usize, f64)>> = (0..nv).filter(|&k| boundary(k)).flat_map(|k| [vec![(k, 1.0)], vec![(nv + k, 1.0)]]).collect();
        rows.extend((1..n - 1).map(|j| vec![(5 * n + j, 1.0), (6 * n + j, -1.0)]));
        let c: Vec<Triplet> = rows.iter().enumerate().flat_map(|(r, row)| row.iter().map(move |&(u, a)| (r, u, a))).collect();
        let value = |x: &[f64], row: &[(usize, f64)]| row.iter().map(|&(u, a)| a * x[u]).sum::<f64>();
        let b: Vec<f64> = rows.iter().map(|row| value(&x, row)).collect();
        for (k, shift) in [(2 * n + 2, [0.2, 0.15]), (3 * n + 2, [-0.1, 0.2])] {
            x[k] += shift[0];
            x[nv + k] += shift[1];
        }
        let seeds = inverted_faces(&elements, &x);
        assert!(seeds.len() >= 2, "the start must be folded");
        let patch = Patch::new(&elements, &faces_around(&faces, &seeds, 2), &c, rows.len(), 2 * nv).unwrap().expect("free unknowns");
        let before = x.clone();
        let stats = patch.untangle(&mut x, &UntangleOptions::default());
        assert_eq!(stats.inverted, 0, "{stats:?}");
        assert!(inverted_faces(&elements, &x).is_empty());
        let moved: Vec<usize> = (0..2 * nv).filter(|&u| x[u] != before[u]).collect();
        assert!(!moved.is_empty());
        for u in moved {
            let k = u % nv;
            assert!(!boundary(k) && k / n <= 6 && k % n <= 5, "vertex {k} outside the patch moved");
        }
        for (row, b) in rows.iter().zip(&b) {
            assert!((value(&x, row) - b).abs() < 1e-9, "row {row:?} broken");
        }
    }
}
