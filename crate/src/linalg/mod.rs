//! Sparse linear algebra: a reusable symmetric (indefinite) factorization on
//! top of faer.
//!
//! * [`SymmetricPattern`] — fixed upper-triangular CSC pattern built from
//!   `(row, col, value)` triplets; values travel as slot-ordered `Vec<f64>`
//!   so one symbolic analysis serves every refill.
//! * [`LdltSolver`] — KKT / saddle-point systems `[[A, Cᵀ], [C, 0]]`:
//!   LDLᵀ (faer, AMD ordering, no pivoting) with sign-based dynamic
//!   regularization (`+1` primal, `−1` constraint rows), then iterative
//!   refinement against the unregularized matrix.
//! * [`SparseSpd`] — plain sparse Cholesky LLᵀ for SPD systems. Both
//!   solvers are [`SparseCholesky`] and share its factorize/solve methods.
//! * [`Kkt`] / [`solve_kkt`] — KKT assembly and a one-off solve.
//!
//! Everything runs sequentially (`Par::Seq`) and never reads the clock, so it
//! works on `wasm32-unknown-unknown`.  Failures are [`LinalgError`]s, not panics.

mod bordered;
mod cholesky;
mod kkt;
mod krylov;
mod pattern;

#[cfg(test)]
mod tests;

pub use bordered::FixBorder;
pub use cholesky::{Ldlt, LdltSolver, Llt, SolveInfo, FactorOptions, SparseCholesky, SparseSpd};
pub use krylov::{gmres, KrylovInfo};
pub use kkt::{constraint_values, independent_rows, solve_kkt, Kkt, KktSolution, NullSpaceProjector};
pub use pattern::{SymmetricPattern, Triplet, IGNORED_SLOT};

use std::fmt;

/// Why a factorization or solve failed.
#[derive(Clone, Debug, PartialEq)]
pub enum LinalgError {
    /// A slice had the wrong length.
    DimensionMismatch { what: &'static str, expected: usize, found: usize },
    /// A triplet index was outside the matrix.
    IndexOutOfBounds { row: usize, col: usize, n: usize },
    /// A value was given for an entry that is not in the analysed pattern.
    NotInPattern { row: usize, col: usize },
    /// A pivot sign other than −1, 0, +1.
    InvalidSign { index: usize, sign: i8 },
    /// NaN or infinity in the input, the factor or the solution.
    NotFinite { what: &'static str },
    /// An exactly zero pivot (LDLᵀ with regularization disabled). `index` is
    /// as reported by faer, in the permuted elimination order.
    ZeroPivot { index: usize },
    /// A pivot ≤ 0 in LLᵀ: the matrix is not (numerically) positive
    /// definite. `index` is as reported by faer (elimination order).
    NotPositiveDefinite { index: usize },
    /// Iterative refinement ended with `relative_residual` above the accepted
    /// level (singular matrix with inconsistent right-hand side, or too
    /// ill-conditioned).
    NotConverged { relative_residual: f64, steps: usize },
    /// `solve` called before a successful `factorize`.
    NotFactorized,
    /// Allocation failed or an index overflowed inside faer.
    OutOfMemory,
}

impl fmt::Display for LinalgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinalgError::DimensionMismatch { what, expected, found } => {
                write!(f, "{what}: expected length {expected}, found {found}")
            }
            LinalgError::IndexOutOfBounds { row, col, n } => {
                write!(f, "entry ({row}, {col}) is outside the {n}×{n} matrix")
            }
            LinalgError::NotInPattern { row, col } => {
                write!(f, "entry ({row}, {col}) is not in the analysed sparsity pattern")
            }
            LinalgError::InvalidSign { index, sign } => {
                write!(f, "pivot sign {sign} at row {index} is not -1, 0 or +1")
            }
            LinalgError::NotFinite { what } => write!(f, "{what} contains NaN or infinity"),
            LinalgError::ZeroPivot { index } => write!(f, "zero pivot at elimination step {index}"),
            LinalgError::NotPositiveDefinite { index } => {
                write!(f, "matrix is not positive definite (pivot at elimination step {index})")
            }
            LinalgError::NotConverged { relative_residual, steps } => write!(
                f,
                "solve did not converge: relative residual {relative_residual:.3e} after {steps} refinement steps"
            ),
            LinalgError::NotFactorized => write!(f, "solve called before a successful factorization"),
            LinalgError::OutOfMemory => write!(f, "out of memory in sparse factorization"),
        }
    }
}

impl std::error::Error for LinalgError {}
