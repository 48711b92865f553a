//! Solves after fixing more variables without refactorizing: a bordered
//! (Schur-complement) update on top of a stale LDLᵀ factorization.
//!
//! The factorized matrix `K0` holds, for each variable that may later be
//! fixed, a constraint row `fix_i` that is *decoupled* while inactive
//! (coupling 0, diagonal −1). Activating it (coupling 1 to variable `p_i`,
//! diagonal 0) gives the true matrix
//! `K = [[K0', B], [Bᵀ, 0]]` with `B = [e_{p_1} … e_{p_k}]`. With
//! `Z = K0⁻¹ B` (one solve per activation, cached) and `S = Bᵀ Z`, a solve
//! `K [z; λ] = [r; c]` is `y = K0⁻¹ r`, `λ = S⁻¹ (Bᵀ y − c)`, `z = y − Z λ`.
//! This costs one solve plus `O(n k)` per right-hand side, against one
//! factorization, so it pays while `k` is small. When only the fixed values
//! `c` change between solves (Algorithm 1's rounds), `r` (the right-hand side
//! with the held fix rows zeroed) stays the same, and a `y` given by the
//! caller ([`FixBorder::set_base`]) saves even that solve. All solves use the
//! factor alone ([`LdltSolver::solve_unrefined`]): the caller refines against
//! the true matrix.

use super::cholesky::LdltSolver;
use super::LinalgError;
use nalgebra::{DMatrix, DVector};

/// The variables activated since the last factorization and their columns `Z`.
#[derive(Default)]
pub struct FixBorder {
    /// `(variable p_i, fix row fix_i)` in activation order (indices into `K`).
    fixes: Vec<(usize, usize)>,
    /// `Z_i = K0⁻¹ e_{p_i}`.
    columns: Vec<Vec<f64>>,
    /// LU of `S = Bᵀ Z`, rebuilt on every activation.
    schur: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// `y = K0⁻¹ r` for the right-hand side `r` of [`Self::set_base`].
    base: Option<(Vec<f64>, Vec<f64>)>,
}

impl FixBorder {
    /// Number of activations held.
    pub fn len(&self) -> usize {
        self.fixes.len()
    }

    /// True when no activation is held (solves are plain `K0` solves).
    pub fn is_empty(&self) -> bool {
        self.fixes.is_empty()
    }

    /// Forgets every activation (after a refactorization that includes them).
    pub fn clear(&mut self) {
        self.fixes.clear();
        self.columns.clear();
        self.schur = None;
        self.base = None;
    }

    /// Records `y = K0⁻¹ r` (e.g. the solution right after factorizing, when
    /// no fix is held): later solves whose right-hand side equals `r` outside
    /// the held fix rows reuse it instead of solving. Cleared by [`Self::clear`].
    pub fn set_base(&mut self, r: Vec<f64>, y: Vec<f64>) {
        self.base = Some((r, y));
    }

    /// Activates the fix rows of `fixes` (`(variable, fix row)` pairs): one
    /// blocked solve with `K0` for all their columns.
    pub fn push(&mut self, solver: &LdltSolver, fixes: &[(usize, usize)]) -> Result<(), LinalgError> {
        if fixes.is_empty() {
            return Ok(());
        }
        let n = solver.pattern().dim();
        let mut e = vec![0.0; n * fixes.len()];
        for (j, &(var, _)) in fixes.iter().enumerate() {
            e[j * n + var] = 1.0;
        }
        let z = solver.solve_unrefined_many(&e, fixes.len())?;
        self.columns.extend(z.chunks(n).map(<[f64]>::to_vec));
        self.fixes.extend_from_slice(fixes);
        let k = self.fixes.len();
        let s = DMatrix::from_fn(k, k, |i, j| self.columns[j][self.fixes[i].0]);
        self.schur = Some(s.lu());
        Ok(())
    }

    /// Solves the bordered system for the full right-hand side `b` (length
    /// of `K`; the entries at the held fix rows are the fixed values).
    pub fn solve(&self, solver: &LdltSolver, b: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let Some(schur) = &self.schur else {
            return solver.solve_unrefined(b);
        };
        let mut r = b.to_vec();
        for &(_, row) in &self.fixes {
            r[row] = 0.0;
        }
        let mut x = match &self.base {
            Some((base_r, y)) if *base_r == r => y.clone(),
            _ => solver.solve_unrefined(&r)?,
        };
        let rhs = DVector::from_iterator(self.fixes.len(), self.fixes.iter().map(|&(var, row)| x[var] - b[row]));
        let lambda = schur.solve(&rhs).ok_or(LinalgError::NotFinite { what: "bordered Schur complement" })?;
        for (z, &l) in self.columns.iter().zip(lambda.iter()) {
            for (xi, zi) in x.iter_mut().zip(z) {
                *xi -= zi * l;
            }
        }
        for (&(_, row), &l) in self.fixes.iter().zip(lambda.iter()) {
            x[row] = l;
        }
        Ok(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::{Kkt, Triplet};

    /// `A` tridiagonal SPD on 6 unknowns; fix rows for unknowns 1 and 4,
    /// active (coupling 1, diagonal 0) or decoupled (coupling 0, diagonal −1).
    fn kkt(active: [bool; 2]) -> Kkt {
        let n = 6;
        let mut a: Vec<Triplet> = (0..n).map(|i| (i, i, 2.5 + i as f64 * 0.1)).collect();
        a.extend((0..n - 1).map(|i| (i, i + 1, -1.0)));
        let c: Vec<Triplet> = vec![(0, 1, 1.0), (1, 4, 1.0)];
        let mut k = Kkt::assemble(&a, n, &c, 2).unwrap();
        for (r, (&on, var)) in active.iter().zip([1usize, 4]).enumerate() {
            let slot = k.pattern.slot(var, n + r).unwrap();
            k.values[slot] = if on { 1.0 } else { 0.0 };
            let d = k.pattern.diag_slot(n + r);
            k.values[d] = if on { 0.0 } else { -1.0 };
        }
        k
    }

    #[test]
    fn bordered_solve_matches_a_fresh_factorization() {
        let b = [1.0, -2.0, 0.5, 3.0, -1.0, 0.25, 0.7, -0.3];
        let exact = kkt([true, true]).solver().unwrap().solve(&b).unwrap();
        // Factor with both fix rows decoupled, then activate them by bordering.
        let k0 = kkt([false, false]);
        let solver = k0.solver().unwrap();
        let mut border = FixBorder::default();
        border.push(&solver, &[(1, 6)]).unwrap();
        border.push(&solver, &[(4, 7)]).unwrap();
        let x = border.solve(&solver, &b).unwrap();
        for (xi, ei) in x.iter().zip(&exact) {
            assert!((xi - ei).abs() < 1e-12, "{x:?} vs {exact:?}");
        }
        assert!((x[1] - 0.7).abs() < 1e-12 && (x[4] + 0.3).abs() < 1e-12, "fixed values hold");
    }

    #[test]
    fn a_recorded_base_solution_is_reused_only_for_its_right_hand_side() {
        let k0 = kkt([false, false]);
        let solver = k0.solver().unwrap();
        // Base: the right-hand side with both (inactive) fix rows at 0.
        let r = [1.0, -2.0, 0.5, 3.0, -1.0, 0.25, 0.0, 0.0];
        let y = solver.solve(&r).unwrap();
        let mut border = FixBorder::default();
        border.set_base(r.to_vec(), y);
        border.push(&solver, &[(1, 6), (4, 7)]).unwrap();
        // Same outside the held fix rows: the base is used; the result must
        // still be the exact bordered solution.
        let b = [1.0, -2.0, 0.5, 3.0, -1.0, 0.25, 0.7, -0.3];
        let exact = kkt([true, true]).solver().unwrap().solve(&b).unwrap();
        let x = border.solve(&solver, &b).unwrap();
        assert!(x.iter().zip(&exact).all(|(a, e)| (a - e).abs() < 1e-12), "{x:?} vs {exact:?}");
        // A different right-hand side elsewhere must not reuse it.
        let b2 = [0.0, 1.0, 0.5, 3.0, -1.0, 0.25, 0.7, -0.3];
        let exact2 = kkt([true, true]).solver().unwrap().solve(&b2).unwrap();
        let x2 = border.solve(&solver, &b2).unwrap();
        assert!(x2.iter().zip(&exact2).all(|(a, e)| (a - e).abs() < 1e-12), "{x2:?} vs {exact2:?}");
    }
}
