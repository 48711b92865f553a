//! Assembly of saddle-point (KKT) systems
//! `K = [[A, Cᵀ], [C, 0]]`, `K [x; λ] = [b; d]`
//! with `A` (n × n) symmetric positive semi-definite and `C` (m × n) the
//! constraint rows, and a one-off convenience solve.

use super::cholesky::{LdltSolver, SolveInfo, SparseSpd};
use super::pattern::{SymmetricPattern, Triplet};
use super::LinalgError;

/// An assembled KKT matrix of size `n + m` (primal unknowns first, then one
/// multiplier per constraint row) on a fixed pattern.
#[derive(Clone, Debug)]
pub struct Kkt {
    /// Number of primal unknowns (size of `A`).
    pub n: usize,
    /// Number of constraint rows (rows of `C`).
    pub m: usize,
    /// Pattern of `K` (upper triangle).
    pub pattern: SymmetricPattern,
    /// Values of `K` in slot order.
    pub values: Vec<f64>,
    /// Pivot signs: `+1` for the `n` primal rows, `−1` for the `m` constraint rows.
    pub signs: Vec<i8>,
}

/// Maps the triplets of `A` (upper or full, n × n) and `C` (m × n, row =
/// constraint index) to triplets of `K` (upper triangle).
fn kkt_triplets(
    a_triplets: &[Triplet],
    n: usize,
    c_triplets: &[Triplet],
    m: usize,
) -> Result<Vec<Triplet>, LinalgError> {
    let mut t = Vec::with_capacity(a_triplets.len() + c_triplets.len());
    for &(r, c, v) in a_triplets {
        if r >= n || c >= n {
            return Err(LinalgError::IndexOutOfBounds { row: r, col: c, n });
        }
        t.push((r, c, v));
    }
    for &(r, c, v) in c_triplets {
        if r >= m || c >= n {
            return Err(LinalgError::IndexOutOfBounds { row: r, col: c, n: m.max(n) });
        }
        // C[r, c] sits at K[n + r, c]; store its upper mirror K[c, n + r].
        t.push((c, n + r, v));
    }
    Ok(t)
}

impl Kkt {
    /// Assembles `K` from the triplets of `A` (upper triangle or full
    /// symmetric, duplicates summed) and of `C` (`(constraint, unknown, value)`).
    pub fn assemble(
        a_triplets: &[Triplet],
        n: usize,
        c_triplets: &[Triplet],
        m: usize,
    ) -> Result<Self, LinalgError> {
        let t = kkt_triplets(a_triplets, n, c_triplets, m)?;
        let (pattern, values) = SymmetricPattern::with_values(n + m, &t)?;
        let signs = (0..n + m).map(|i| if i < n { 1 } else { -1 }).collect();
        Ok(Self { n, m, pattern, values, signs })
    }

    /// Refills the values on the same pattern (entries must be a subset of the
    /// assembled positions, else [`LinalgError::NotInPattern`]).
    pub fn refill(&mut self, a_triplets: &[Triplet], c_triplets: &[Triplet]) -> Result<(), LinalgError> {
        let t = kkt_triplets(a_triplets, self.n, c_triplets, self.m)?;
        self.pattern.fill_values(&t, &mut self.values)
    }

    /// A solver analysed for this pattern and factorized with the current values.
    pub fn solver(&self) -> Result<LdltSolver, LinalgError> {
        let mut s = LdltSolver::new(&self.pattern, &self.signs)?;
        s.factorize(&self.values)?;
        Ok(s)
    }

    /// Stacks `[b; d]` into one right-hand side of length `n + m`.
    pub fn rhs(&self, rhs_primal: &[f64], rhs_constraint: &[f64]) -> Result<Vec<f64>, LinalgError> {
        if rhs_primal.len() != self.n {
            return Err(LinalgError::DimensionMismatch {
                what: "primal right-hand side",
                expected: self.n,
                found: rhs_primal.len(),
            });
        }
        if rhs_constraint.len() != self.m {
            return Err(LinalgError::DimensionMismatch {
                what: "constraint right-hand side",
                expected: self.m,
                found: rhs_constraint.len(),
            });
        }
        Ok(rhs_primal.iter().chain(rhs_constraint).copied().collect())
    }
}

/// Solution of a KKT system.
#[derive(Clone, Debug)]
pub struct KktSolution {
    /// Primal unknowns (length `n`).
    pub x: Vec<f64>,
    /// Lagrange multipliers (length `m`), with the sign convention
    /// `A x + Cᵀ λ = b`.
    pub lambda: Vec<f64>,
    /// Achieved residual of the full system.
    pub info: SolveInfo,
}

/// One-off solve of `[[A, Cᵀ], [C, 0]] [x; λ] = [b; d]`: `A` from
/// `a_triplets` (n × n, upper or full), `C` from `c_triplets` (m × n).
/// For repeated solves build a [`Kkt`] and keep its [`LdltSolver`].
pub fn solve_kkt(
    a_triplets: &[Triplet],
    n: usize,
    c_triplets: &[Triplet],
    m: usize,
    rhs_primal: &[f64],
    rhs_constraint: &[f64],
) -> Result<KktSolution, LinalgError> {
    let kkt = Kkt::assemble(a_triplets, n, c_triplets, m)?;
    let rhs = kkt.rhs(rhs_primal, rhs_constraint)?;
    let solver = kkt.solver()?;
    let (mut x, info) = solver.solve_with_info(&rhs)?;
    let lambda = x.split_off(n);
    Ok(KktSolution { x, lambda, info })
}

/// `C y` per row for the constraint triplets `c` (`(row, unknown, value)`, rows `0..m`).
pub fn constraint_values(c: &[Triplet], m: usize, y: &[f64]) -> Vec<f64> {
    let mut res = vec![0.0f64; m];
    for &(row, col, v) in c {
        res[row] += v * y[col];
    }
    res
}

/// Orthogonal projection onto the null space of a full-row-rank constraint
/// matrix `C` (m × n): `y -> y - Cᵀ (C Cᵀ)⁻¹ C y`, with `C Cᵀ` factored once.
/// Cheap next to a KKT solve (`C Cᵀ` couples only rows sharing an unknown),
/// it puts an inexact KKT solution of a homogeneous system back onto `C y = 0`.
pub struct NullSpaceProjector {
    n: usize,
    m: usize,
    c: Vec<(usize, usize, f64)>,
    gram: SparseSpd,
}

impl NullSpaceProjector {
    /// Factors `C Cᵀ` for the triplets `c` (`(row, unknown, value)`, rows
    /// `0..m`, unknowns `0..n`); fails when the factorization finds `C Cᵀ` singular.
    pub fn new(c: &[Triplet], n: usize, m: usize) -> Result<Self, LinalgError> {
        let mut by_unknown: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(r, j, v) in c {
            if r >= m || j >= n {
                return Err(LinalgError::IndexOutOfBounds { row: r, col: j, n: m.max(n) });
            }
            by_unknown[j].push((r, v));
        }
        let mut t = Vec::new();
        for col in &by_unknown {
            for &(r1, v1) in col {
                t.extend(col.iter().filter(|e| r1 <= e.0).map(|&(r2, v2)| (r1, r2, v1 * v2)));
            }
        }
        Ok(Self { n, m, c: c.to_vec(), gram: SparseSpd::from_triplets(m, &t)? })
    }

    /// `C y` per row.
    pub fn residual(&self, y: &[f64]) -> Vec<f64> {
        constraint_values(&self.c, self.m, y)
    }

    /// Projects `y` (length `n`) onto `C y = 0` in place, repeating (at most
    /// `passes` times) while `max |C y| > tolerance · max |y|`; true once
    /// below it (false also on a length mismatch or a failed solve).
    pub fn project(&self, y: &mut [f64], tolerance: f64, passes: usize) -> bool {
        if y.len() != self.n {
            return false;
        }
        let max_abs = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let size = max_abs(y).max(f64::MIN_POSITIVE);
        for _ in 0..passes {
            let res = self.residual(y);
            if max_abs(&res) <= tolerance * size {
                return true;
            }
            let Ok(l) = self.gram.solve(&res) else { return false };
            for &(row, col, v) in &self.c {
                y[col] -= v * l[row];
            }
        }
        y.iter().all(|v| v.is_finite()) && max_abs(&self.residual(y)) <= tolerance * size
    }
}

/// Incremental sparse Gaussian elimination: `keep[i]` is false when row `i`
/// is a linear combination of the kept rows before it.
pub fn independent_rows(rows: &[Vec<(usize, i64)>], n_vars: usize) -> Vec<bool> {
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    let mut pivot_of = vec![usize::MAX; n_vars];
    let mut stored: Vec<(usize, Vec<(usize, f64)>)> = Vec::new();
    let mut keep = vec![false; rows.len()];
    for (ri, r) in rows.iter().enumerate() {
        let mut work: HashMap<usize, f64> = r.iter().map(|&(i, v)| (i, v as f64)).collect();
        let mut heap: BinaryHeap<Reverse<(usize, usize)>> =
            work.keys().filter(|&&v| pivot_of[v] != usize::MAX).map(|&v| Reverse((pivot_of[v], v))).collect();
        while let Some(Reverse((si, var))) = heap.pop() {
            let c = match work.get(&var) {
                Some(&c) if c.abs() > 1e-12 => c,
                _ => continue,
            };
            let srow = &stored[si].1;
            let pc = srow.iter().find(|e| e.0 == var).map_or(1.0, |e| e.1);
            let factor = c / pc;
            for &(v, a) in srow {
                *work.entry(v).or_insert(0.0) -= factor * a;
                if v != var && pivot_of[v] != usize::MAX {
                    heap.push(Reverse((pivot_of[v], v)));
                }
            }
            work.remove(&var);
        }
        work.retain(|_, c| c.abs() > 1e-9);
        let Some((&pv, _)) = work.iter().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()).then(b.0.cmp(a.0))) else {
            continue;
        };
        keep[ri] = true;
        pivot_of[pv] = stored.len();
        stored.push((pv, work.into_iter().collect()));
    }
    keep
}
