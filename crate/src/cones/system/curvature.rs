//! `phi` and `h` once every integer is fixed: the curvature equation alone.
//!
//! With all `p` fixed, the vertex rows of eq. 16 read
//! `(L phi)_v = b_v`, `b_v = (pi/2) sum_e sigma_ve p_e - transport(gamma_v)`
//! (every vertex but the last; their sum is zero), and the path rows give
//! `B_h h~ = -transport(C_l) + (pi/2) p_l - B_phi phi`. Unknowns and
//! independent constraints then differ by one (the constant of `phi`), so the
//! objective of eq. 18 only picks that constant: `phi` has zero mean under
//! `M` (`alpha L` does not see constants and `B_phi 1 = 0`).
//!
//! Cone moves and the clean-ups change `b` only (a transfer of `a` quarter
//! turns from `u` to `w` adds `(pi/2) a (e_w - e_u)`), so their trials are
//! solves with the grounded cotangent Laplacian: a quarter of the KKT's
//! dimension and definite. One factorization serves every trial.

use crate::linalg::{LdltSolver, LinalgError, FactorOptions, SymmetricPattern, Triplet};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::FRAC_PI_2;

/// The grounded Laplacian's factorization and the path rows, for responses
/// of `phi` and `h~` to changes of the vertex right-hand side.
pub(super) struct CurvatureSystem {
    /// `L` without the row and column of the last local vertex (`phi` there
    /// is 0 before the mean is removed).
    /// (`None` on a single vertex).
    solver: Option<LdltSolver>,
    /// Vertex areas over the component's area (`M/A`).
    mass: Vec<f64>,
    /// `B_phi` per path row: `(vertex, coefficient)`.
    path_phi: Vec<Vec<(usize, f64)>>,
    /// LU of `B_h` (in the scaled unknowns `h~`), `None` without paths.
    path_h: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
}

impl CurvatureSystem {
    /// Factorizes the grounded Laplacian. `laplacian` holds upper-triangle
    /// triplets of `L` on the local vertices, `mass` is `M/A`, `path_rows`
    /// the path rows' `(row, column, value)` entries on `[phi | h~]`
    /// (columns `< nv` are `phi`, the next `nh` are `h~`; others ignored).
    pub fn new(laplacian: &[Triplet], mass: Vec<f64>, path_rows: &[Triplet], nh: usize) -> Result<Self, LinalgError> {
        let nv = mass.len();
        let ng = nv.saturating_sub(1);
        let solver = if ng > 0 {
            let grounded: Vec<Triplet> = laplacian.iter().copied().filter(|&(r, c, _)| r < ng && c < ng).collect();
            let (pattern, values) = SymmetricPattern::with_values(ng, &grounded)?;
            let mut solver = LdltSolver::new(&pattern, &vec![1; ng])?;
            solver.set_options(FactorOptions { max_refinement_steps: 50, ..FactorOptions::default() });
            solver.factorize(&values)?;
            Some(solver)
        } else {
            None
        };
        let mut path_phi = vec![Vec::new(); nh];
        let mut b_h = DMatrix::zeros(nh, nh);
        for &(r, c, w) in path_rows {
            if c < nv {
                path_phi[r].push((c, w));
            } else if c < nv + nh {
                b_h[(r, c - nv)] += w;
            }
        }
        let path_h = (nh > 0).then(|| b_h.lu());
        Ok(Self { solver, mass, path_phi, path_h })
    }

    /// Width of a response column: `nv` values of `phi`, then `nh` of `h~`.
    pub fn width(&self) -> usize {
        self.mass.len() + self.path_phi.len()
    }

    /// Responses to `k` changes of the vertex right-hand side (`db`, `nv`
    /// values per column, column-major; the last vertex's entry is implied
    /// and ignored): `[d phi; d h~]` per column, `phi` of zero `M`-mean.
    pub fn responses(&self, db: &[f64], k: usize, tolerance: f64) -> Result<Vec<f64>, LinalgError> {
        let nv = self.mass.len();
        let ng = nv.saturating_sub(1);
        let mut rhs = Vec::with_capacity(ng * k);
        for col in db.chunks(nv) {
            rhs.extend_from_slice(&col[..ng]);
        }
        let y = match &self.solver {
            Some(solver) => solver.solve_many_to(&rhs, k, tolerance)?.0,
            None => Vec::new(),
        };
        let width = self.width();
        let mut out = vec![0.0; width * k];
        for c in 0..k {
            let column = &mut out[c * width..(c + 1) * width];
            column[..ng].copy_from_slice(&y[c * ng..(c + 1) * ng]);
            let mean: f64 = column[..nv].iter().zip(&self.mass).map(|(p, m)| p * m).sum();
            column[..nv].iter_mut().for_each(|p| *p -= mean);
            self.h_response(column)?;
        }
        Ok(out)
    }

    /// Fills the `h~` part of `column` from its `phi` part: `B_h dh = -B_phi dphi`.
    fn h_response(&self, column: &mut [f64]) -> Result<(), LinalgError> {
        let Some(lu) = &self.path_h else { return Ok(()) };
        let nv = self.mass.len();
        let rhs = DVector::from_iterator(
            self.path_phi.len(),
            self.path_phi.iter().map(|row| -row.iter().map(|&(v, w)| w * column[v]).sum::<f64>()),
        );
        let dh = lu.solve(&rhs).ok_or(LinalgError::NotFinite { what: "path rows' harmonic block" })?;
        column[nv..].copy_from_slice(dh.as_slice());
        Ok(())
    }

    /// `h~ = B_h⁻¹ (shift - B_phi phi)`: the path rows solved for the
    /// harmonic part (`shift`: their right-hand side plus `(pi/2) p_l`).
    pub fn harmonic(&self, phi: &[f64], shift: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let Some(lu) = &self.path_h else { return Ok(Vec::new()) };
        let rhs = DVector::from_iterator(
            self.path_phi.len(),
            self.path_phi.iter().zip(shift).map(|(row, s)| s - row.iter().map(|&(v, w)| w * phi[v]).sum::<f64>()),
        );
        let h = lu.solve(&rhs).ok_or(LinalgError::NotFinite { what: "path rows' harmonic block" })?;
        Ok(h.as_slice().to_vec())
    }

    /// First-order sensitivity of `phiᵀ M phi / A` at `phi` (of zero
    /// `M`-mean) to moving cone index: `Phi` with a transfer of `a` quarter
    /// turns from `u` to `w` changing it by about `2 a (Phi[w] - Phi[u])`.
    /// `Phi = (pi/2) L_g⁻¹ (M phi / A)`, one solve.
    pub fn move_potential(&self, phi: &[f64], tolerance: f64) -> Result<Vec<f64>, LinalgError> {
        let nv = self.mass.len();
        let ng = nv.saturating_sub(1);
        let r: Vec<f64> = phi[..ng].iter().zip(&self.mass).map(|(p, m)| p * m).collect();
        let mut potential = match &self.solver {
            Some(solver) => solver.solve_many_to(&r, 1, tolerance)?.0,
            None => Vec::new(),
        };
        potential.iter_mut().for_each(|y| *y *= FRAC_PI_2);
        potential.resize(nv, 0.0);
        Ok(potential)
    }
}
