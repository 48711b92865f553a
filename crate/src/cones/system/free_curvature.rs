//! `phi` and `h` once every integer is fixed, on a component with a free
//! boundary: the KKT of eq. 18 with the fixed `p` eliminated.
//!
//! A free port's `p` is a continuous unknown, so a free vertex's row does
//! not hold `phi` there and the curvature equation alone
//! ([`super::curvature`]) no longer determines it: `phi` on the free
//! boundary is an unknown of the objective. With the integer `p` fixed the
//! problem keeps `[phi | h~ | q]` (`q`: the free ports' `p`) and the vertex
//! and path rows; its KKT has half the dimension of the component's (no
//! integer unknowns, no fix rows) and one factorization serves every trial.
//! A transfer changes the right-hand sides of two vertex rows only (as in
//! [`super::curvature`]), so its response is one column of a blocked solve.

use crate::linalg::{Kkt, LdltSolver, LinalgError, FactorOptions, Triplet};
use std::f64::consts::FRAC_PI_2;

/// Proximal weight on the free ports' `p` (the component system's, so the
/// responses are those of its KKT).
const Q_PROXIMAL: f64 = super::P_PROXIMAL;

pub(super) struct FreeCurvatureSystem {
    kkt: Kkt,
    solver: LdltSolver,
    /// Unknowns `phi` and `h~`: the width of a response column.
    nv: usize,
    nh: usize,
    /// Vertex areas over the component's area (`M/A`).
    mass: Vec<f64>,
}

impl FreeCurvatureSystem {
    /// Assembles and factorizes. `objective` holds the upper-triangle
    /// triplets of the objective on `[phi | h~]`, `laplacian` those of `L`,
    /// `vertex_q[i]` the free ports `(q, sigma)` vertex `i`'s cycle crosses
    /// (`nq` in all), `path_rows` the path rows' entries on `[phi | h~ | q]`
    /// (fixed integers left out).
    pub fn new(
        objective: &[Triplet],
        laplacian: &[Triplet],
        mass: Vec<f64>,
        vertex_q: &[Vec<(usize, i32)>],
        nq: usize,
        path_rows: &[Triplet],
        nh: usize,
    ) -> Result<Self, LinalgError> {
        let nv = mass.len();
        let n = nv + nh + nq;
        let mut a: Vec<Triplet> = objective.to_vec();
        a.extend((0..nq).map(|j| (nv + nh + j, nv + nh + j, Q_PROXIMAL)));
        // Vertex rows (all but the last: their sum is zero), then the path rows.
        let n_vertex_rows = nv.saturating_sub(1);
        let mut c: Vec<Triplet> = Vec::new();
        for &(r, col, w) in laplacian {
            if r < n_vertex_rows {
                c.push((r, col, w));
            }
            if r != col && col < n_vertex_rows {
                c.push((col, r, w));
            }
        }
        for (i, ports) in vertex_q.iter().enumerate().take(n_vertex_rows) {
            c.extend(ports.iter().map(|&(q, s)| (i, nv + nh + q, -FRAC_PI_2 * s as f64)));
        }
        c.extend(path_rows.iter().map(|&(r, col, w)| (n_vertex_rows + r, col, w)));
        let kkt = Kkt::assemble(&a, n, &c, n_vertex_rows + nh)?;
        let mut solver = LdltSolver::new(&kkt.pattern, &kkt.signs)?;
        solver.set_options(FactorOptions { max_refinement_steps: 50, ..FactorOptions::default() });
        solver.factorize(&kkt.values)?;
        Ok(Self { kkt, solver, nv, nh, mass })
    }

    /// Responses to `k` changes of the vertex right-hand side (`db`, `nv`
    /// values per column; the last vertex's entry is implied and ignored):
    /// `[d phi; d h~]` per column.
    pub fn responses(&self, db: &[f64], k: usize, tolerance: f64) -> Result<Vec<f64>, LinalgError> {
        let (dim, n, nv) = (self.kkt.pattern.dim(), self.kkt.n, self.nv);
        let mut rhs = vec![0.0; dim * k];
        for (c, col) in db.chunks(nv).enumerate() {
            rhs[c * dim + n..c * dim + n + nv.saturating_sub(1)].copy_from_slice(&col[..nv.saturating_sub(1)]);
        }
        let (x, _) = self.solver.solve_many_to(&rhs, k, tolerance)?;
        Ok(x.chunks(dim).flat_map(|c| c[..nv + self.nh].iter().copied()).collect())
    }

    /// First-order sensitivity of `phiᵀ M phi / A` (see
    /// `CurvatureSystem::move_potential`): with `y = K⁻¹ [M phi / A; 0]`,
    /// a change `Δb` of the vertex rows changes it by about `2 yᵀ Δb`, so
    /// `Phi = (pi/2) y` on the vertex rows (0 at the last vertex).
    pub fn move_potential(&self, phi: &[f64], tolerance: f64) -> Result<Vec<f64>, LinalgError> {
        let (dim, n, nv) = (self.kkt.pattern.dim(), self.kkt.n, self.nv);
        let mut rhs = vec![0.0; dim];
        for i in 0..nv {
            rhs[i] = phi[i] * self.mass[i];
        }
        let (y, _) = self.solver.solve_many_to(&rhs, 1, tolerance)?;
        let mut potential: Vec<f64> = y[n..n + nv.saturating_sub(1)].iter().map(|v| FRAC_PI_2 * v).collect();
        potential.resize(nv, 0.0);
        Ok(potential)
    }
}
