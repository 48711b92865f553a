//! Every `p` from given cone indices, for a coarse-to-fine placement: the
//! cones come from a coarser mesh of the same component, the integers of
//! this system follow without rounding.
//!
//! With every vertex index `k` given, the vertex rows fix `phi` alone (see
//! [`super::curvature`]); the path integers of the free leftovers then enter
//! only the path rows, i.e. `h~ = B_h⁻¹ (rhs_l + (pi/2) p_l - B_phi phi)`, and
//! are chosen by least harmonic norm (the objective's only part that still
//! varies), rounded greedily on that small dense problem. The `p` of the
//! primal tree `T_p` follow by accumulating `k` from its leaves.

use super::{ComponentSystem, ConeError};
use crate::mesh::NONE;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::FRAC_PI_2;

impl ComponentSystem<'_> {
    /// Fixes every `p` so that local vertex `i` gets index `k[i]` (boundary
    /// vertices must carry their turning integers), then solves the curvature
    /// equation ([`ComponentSystem::solve_fixed`]; no KKT factorization).
    /// Errs with [`ConeError::InconsistentBoundary`] when `k` contradicts the
    /// boundary fixes or does not sum to `4 chi`.
    pub fn fix_indices(&mut self, k: &[i64]) -> Result<(), ConeError> {
        if self.has_free_boundary() {
            return self.fix_indices_free(k);
        }
        let nv = self.tree.vertices.len();
        let nh = self.basis.len();
        let mut p: Vec<Option<i64>> = self.fixed.clone();
        if nh > 0 {
            // The path integers see phi (from the curvature equation) only.
            let b = self.curvature_rhs(k);
            let phi = self.curvature()?.responses(&b, 1, 1e-12)?[..nv].to_vec();
            self.choose_path_integers(&phi, &mut p)?;
        }
        self.accumulate_along_tree(k, &mut p)?;
        let before = std::mem::replace(&mut self.fixed, p);
        // A factorization of earlier fixes no longer fits (the KKT is
        // factorized again where trials need it).
        self.solver = None;
        self.border.clear();
        // On failure the system is left as it was, so the caller can round instead.
        self.solve_fixed().inspect_err(|_| self.fixed = before)
    }

    /// [`Self::fix_indices`] on a component with a free boundary, where the
    /// curvature equation does not hold `phi`. The indices leave free only
    /// the integers that no vertex row holds: the leftovers and the parent
    /// edges of free vertices where a second free loop joins `T_p` (the
    /// holonomy around the homology loops and the holes), and the tree
    /// paths above them. One solve with the rest fixed gives their relaxed
    /// values; rounded, they determine the paths, and a second factorization
    /// solves with every `p` fixed (Algorithm 1 rounds anything still free).
    fn fix_indices_free(&mut self, k: &[i64]) -> Result<(), ConeError> {
        let before = self.fixed.clone();
        let mut p = before.clone();
        self.accumulate_along_tree(k, &mut p)?;
        self.fixed = p;
        if let Err(e) = self.refactor_and_solve() {
            self.fixed = before;
            return Err(e);
        }
        let p0 = self.p0();
        let leftovers = self.tree.leftovers.iter().map(|&e| self.tree.g_index[e as usize]);
        let free_parents = (0..self.tree.vertices.len()).filter(|&i| self.cycles[i].free).filter_map(|i| {
            let h = self.tree.primal_parent_he[self.tree.vertices[i] as usize];
            (h != NONE).then(|| self.tree.g_index[self.mesh.edge(h) as usize])
        });
        let mut p = before.clone();
        for g in leftovers.chain(free_parents).map(|g| g as usize) {
            if self.fixed[g].is_none() && !self.continuous[g] {
                p[g] = Some(self.x[p0 + g].round() as i64);
            }
        }
        if let Err(e) = self.accumulate_along_tree(k, &mut p) {
            self.fixed = before;
            return Err(e);
        }
        self.fixed = p;
        self.round_all(&mut |_, _| {}).inspect_err(|_| self.fixed = before)
    }

    /// The free leftovers' `p` by least `h~ᵀ G h~` (the objective's harmonic
    /// block), rounding the one nearest to an integer first.
    fn choose_path_integers(&mut self, phi: &[f64], p: &mut [Option<i64>]) -> Result<(), ConeError> {
        let nv = self.tree.vertices.len();
        let nh = self.basis.len();
        let row_path = nv.saturating_sub(1);
        let lg: Vec<usize> = self.tree.leftovers.iter().map(|&e| self.tree.g_index[e as usize] as usize).collect();
        let rhs: Vec<f64> = (0..nh).map(|l| self.constraint_rhs[row_path + l]).collect();
        let curvature = self.curvature()?;
        // h~ = c + D p_l with D = (pi/2) B_h⁻¹.
        let c = curvature.harmonic(phi, &rhs)?;
        let mut d = DMatrix::zeros(nh, nh);
        for l in 0..nh {
            let mut unit = vec![0.0; nh];
            unit[l] = FRAC_PI_2;
            let column = curvature.harmonic(&vec![0.0; nv], &unit)?;
            d.set_column(l, &DVector::from_vec(column));
        }
        let mut gram = DMatrix::zeros(nh, nh);
        for &(r, col, w) in &self.objective_terms {
            if r >= nv && col >= nv && r < nv + nh && col < nv + nh {
                gram[(r - nv, col - nv)] += w;
                if r != col {
                    gram[(col - nv, r - nv)] += w;
                }
            }
        }
        let c = DVector::from_vec(c);
        loop {
            let free: Vec<usize> = (0..nh).filter(|&l| p[lg[l]].is_none()).collect();
            if free.is_empty() {
                return Ok(());
            }
            let mut c0 = c.clone();
            for l in (0..nh).filter(|&l| p[lg[l]].is_some()) {
                c0 += d.column(l) * p[lg[l]].unwrap() as f64;
            }
            let df = DMatrix::from_fn(nh, free.len(), |r, j| d[(r, free[j])]);
            let h = df.transpose() * &gram * &df;
            let rhs = -(df.transpose() * &gram * &c0);
            let x = h.lu().solve(&rhs).ok_or(crate::linalg::LinalgError::NotFinite { what: "path integer least squares" })?;
            let (j, _) = x.iter().enumerate().map(|(j, v)| (j, (v - v.round()).abs())).min_by(|a, b| a.1.total_cmp(&b.1)).expect("free is not empty");
            p[lg[free[j]]] = Some(x[j].round() as i64);
        }
    }

    /// The `p` of `T_p` from `k`, leaves first: vertex `i`'s row
    /// `sum sigma p = k_i - 4 j_i` has its parent edge as the one unknown.
    /// On a free boundary there is no row; a `p` left unknown there leaves
    /// the rows above it unknown too (they stay free).
    fn accumulate_along_tree(&self, k: &[i64], p: &mut [Option<i64>]) -> Result<(), ConeError> {
        let nv = self.tree.vertices.len();
        let mut order: Vec<usize> = (0..nv).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(self.tree.primal_depth[self.tree.vertices[i] as usize]));
        let inconsistent = |i: usize| ConeError::InconsistentBoundary { vertex: self.tree.vertices[i] };
        let free_boundary = self.has_free_boundary();
        for &i in &order {
            let h = self.tree.primal_parent_he[self.tree.vertices[i] as usize];
            let parent_g = if h == NONE { None } else { Some(self.tree.g_index[self.mesh.edge(h) as usize]) };
            if self.cycles[i].free {
                continue;
            }
            let mut rest = 0i64;
            let mut own = None;
            let mut unknown = false;
            for &(g, s) in &self.cycles[i].g {
                if Some(g) == parent_g {
                    own = Some(s as i64);
                    continue;
                }
                match p[g as usize] {
                    Some(value) => rest += s as i64 * value,
                    None if free_boundary => unknown = true,
                    None => return Err(inconsistent(i)),
                }
            }
            if unknown {
                continue;
            }
            let target = k[i] - 4 * self.cycles[i].j - rest;
            match (parent_g, own) {
                (Some(g), Some(s)) => {
                    let value = s * target;
                    if p[g as usize].is_some_and(|fixed| fixed != value) {
                        return Err(inconsistent(i));
                    }
                    p[g as usize] = Some(value);
                }
                (Some(_), None) => return Err(inconsistent(i)),
                // The root: its row is implied by the others when sum k = 4 chi.
                (None, _) if target != 0 => return Err(inconsistent(i)),
                (None, _) => {}
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_system;
    use crate::cones::test_meshes::{square_annulus, torus};
    use crate::mesh::TriMesh;

    /// Indices rounded by one system, given to a fresh one: every `p` is
    /// fixed, each vertex gets its index, the KKT is satisfied, and the path
    /// integers reach the same harmonic norm as Algorithm 1's (they
    /// minimize it for the given indices).
    fn indices_round_trip(mesh: &TriMesh) {
        let mut rounded = test_system(mesh);
        rounded.round_all(&mut |_, _| {}).unwrap();
        let k = rounded.vertex_k();
        assert!(k.iter().any(|&ki| ki != 0));
        let mut given = test_system(mesh);
        given.fix_indices(&k).unwrap();
        assert!(given.fixed.iter().all(Option::is_some), "every p fixed");
        assert_eq!(given.vertex_k(), k);
        assert!(given.residual < 1e-9, "residual {}", given.residual);
        assert!(given.objective() <= rounded.objective() * (1.0 + 1e-9), "{} vs {}", given.objective(), rounded.objective());
    }

    /// With every integer fixed, the curvature equation's `phi` and `h~`
    /// are the KKT's (torus: two homology loops; annulus: an alignment path).
    fn fixed_solve_matches_the_kkt(mesh: &TriMesh) {
        let mut sys = test_system(mesh);
        sys.round_all(&mut |_, _| {}).unwrap();
        sys.solve_kkt().unwrap();
        let kkt = sys.x.clone();
        sys.solve_fixed().unwrap();
        let width = sys.tree.vertices.len() + sys.basis.len();
        let scale = kkt[..width].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 1e-6);
        for i in 0..width {
            assert!((sys.x[i] - kkt[i]).abs() < 1e-9 * scale, "unknown {i}: {} vs KKT {}", sys.x[i], kkt[i]);
        }
        assert!(sys.residual < 1e-12, "constraint residual {}", sys.residual);
    }

    #[test]
    fn fixed_solves_match_the_kkt() {
        fixed_solve_matches_the_kkt(&torus(16, 8, 2.0, 0.7));
        fixed_solve_matches_the_kkt(&square_annulus(6, 4, 0.4, 30f64.to_radians()));
    }

    #[test]
    fn given_indices_fix_every_integer_on_a_torus() {
        indices_round_trip(&torus(16, 8, 2.0, 0.7));
    }

    #[test]
    fn given_indices_fix_every_integer_on_a_rotated_annulus() {
        indices_round_trip(&square_annulus(6, 4, 0.4, 30f64.to_radians()));
    }

    #[test]
    fn indices_off_by_a_quarter_turn_are_refused() {
        let mesh = torus(12, 6, 2.0, 0.7);
        let mut sys = test_system(&mesh);
        let mut k = vec![0; mesh.n_vertices()];
        k[3] = 1; // sum 1, not 4 chi = 0
        assert!(sys.fix_indices(&k).is_err());
    }
}
