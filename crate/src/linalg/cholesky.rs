//! Sparse LDLᵀ (symmetric indefinite, regularized) and LLᵀ (SPD) solvers on
//! faer's low-level `sparse::linalg::cholesky` API: one symbolic analysis
//! (AMD ordering) per pattern, any number of numeric factorizations on it,
//! and solves followed by iterative refinement against the unregularized
//! matrix.

use std::marker::PhantomData;
use std::sync::Mutex;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};

use super::pattern::{SymmetricPattern, Triplet};
use super::krylov::gmres;
use super::LinalgError;

/// Refinement whose residual falls by less than this factor in a step is
/// stagnating: the column is finished by GMRES ([`super::krylov`]).
const STALL_RATIO: f64 = 0.5;
/// Preconditioner applications GMRES may spend on a stalled column (at least;
/// the options' `max_refinement_steps` if larger), and its restart length.
const KRYLOV_STEPS: usize = 60;
const KRYLOV_RESTART: usize = 30;

/// Tuning of [`LdltSolver`] / [`SparseSpd`]. `delta` and `epsilon` are
/// *relative* to the largest absolute matrix entry of the factorized values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FactorOptions {
    /// Dynamic regularization: a pivot that is below `epsilon` in magnitude or
    /// has the wrong sign is replaced by `±delta` (LDLᵀ only). `0` disables
    /// regularization (a zero pivot then gives [`LinalgError::ZeroPivot`]).
    pub delta: f64,
    /// Dynamic regularization threshold (LDLᵀ only), see `delta`.
    pub epsilon: f64,
    /// Refinement stops once `‖b − K x‖₂ / ‖b‖₂` is below this.
    pub tolerance: f64,
    /// Maximum number of refinement steps after the first solve.
    pub max_refinement_steps: usize,
    /// A solve whose final relative residual exceeds this (or `tolerance`,
    /// if larger) is reported as [`LinalgError::NotConverged`]; between
    /// `tolerance` and this it is returned (check [`SolveInfo::relative_residual`]).
    pub accept_residual: f64,
    /// A column whose refinement stagnates with its relative residual already
    /// below this is returned as it is instead of being finished by GMRES
    /// (`0`: always finished). For callers whose `tolerance` may lie below
    /// what their systems reach in floating point.
    pub stall_accept: f64,
}

impl Default for FactorOptions {
    fn default() -> Self {
        Self {
            delta: 1e-8,
            epsilon: 1e-12,
            tolerance: 1e-12,
            max_refinement_steps: 5,
            accept_residual: 1e-8,
            stall_accept: 0.0,
        }
    }
}

/// What a solve achieved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveInfo {
    /// `‖b − K x‖₂ / ‖b‖₂` against the *unregularized* matrix (0 when `b = 0`).
    pub relative_residual: f64,
    /// Refinement steps taken after the first solve.
    pub refinement_steps: usize,
}

/// Which numeric factorization faer's symbolic analysis may pick: its own
/// choice by flop density natively; simplicial on wasm32, whose dense
/// (supernodal) kernels run without SIMD. Measured on the fandisk subdivided
/// to 207 k faces, the cone KKTs and the parametrization systems factor and
/// solve 10-60 % faster there without dense fronts.
fn supernodal_threshold() -> SupernodalThreshold {
    if cfg!(target_arch = "wasm32") {
        SupernodalThreshold::FORCE_SIMPLICIAL
    } else {
        SupernodalThreshold::AUTO
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Llt,
    Ldlt,
}

/// Shared machinery: pattern, symbolic analysis, numeric factor and scratch.
struct Core {
    kind: Kind,
    pattern: SymmetricPattern,
    signs: Vec<i8>,
    options: FactorOptions,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// Unregularized matrix values (slot order) of the last factorization.
    a_values: Vec<f64>,
    factorized: bool,
    factor_mem: MemBuffer,
    /// Scratch for single right-hand-side solves; a solve that finds it busy
    /// (concurrent use through `&self`) allocates its own.
    solve_mem: Mutex<MemBuffer>,
}

fn faer_err(e: FaerError) -> LinalgError {
    match e {
        FaerError::OutOfMemory => LinalgError::OutOfMemory,
        FaerError::IndexOverflow => LinalgError::OutOfMemory,
        #[allow(unreachable_patterns)]
        _ => LinalgError::OutOfMemory,
    }
}

fn alloc(req: StackReq) -> Result<MemBuffer, LinalgError> {
    MemBuffer::try_new(req).map_err(|_| LinalgError::OutOfMemory)
}

fn norm2(v: &[f64]) -> f64 {
    // Scaled to avoid overflow/underflow on extreme inputs.
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    scale * v.iter().map(|x| (x / scale) * (x / scale)).sum::<f64>().sqrt()
}

impl Core {
    fn new(kind: Kind, pattern: &SymmetricPattern, signs: Vec<i8>) -> Result<Self, LinalgError> {
        let n = pattern.dim();
        let sym = SymbolicSparseColMatRef::new_checked(
            n,
            n,
            pattern.col_ptr(),
            None,
            pattern.row_idx(),
        );
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams { supernodal_flop_ratio_threshold: supernodal_threshold(), ..CholeskySymbolicParams::default() },
        )
        .map_err(faer_err)?;
        let factor_req = match kind {
            Kind::Ldlt => symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Spec::default()),
            Kind::Llt => symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()),
        };
        let factor_mem = alloc(factor_req)?;
        let solve_mem = Mutex::new(alloc(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))?);
        let l_values = vec![0.0; symbolic.len_val()];
        Ok(Self {
            kind,
            pattern: pattern.clone(),
            signs,
            options: FactorOptions::default(),
            symbolic,
            l_values,
            a_values: vec![0.0; pattern.nnz()],
            factorized: false,
            factor_mem,
            solve_mem,
        })
    }

    fn factorize(&mut self, values: &[f64]) -> Result<(), LinalgError> {
        self.factorized = false;
        self.pattern.check_len(values.len())?;
        if values.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::NotFinite { what: "matrix values" });
        }
        self.a_values.copy_from_slice(values);
        let n = self.pattern.dim();
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                n,
                n,
                self.pattern.col_ptr(),
                None,
                self.pattern.row_idx(),
            ),
            &self.a_values,
        );
        let stack = MemStack::new(&mut self.factor_mem);
        match self.kind {
            Kind::Ldlt => {
                let scale = SymmetricPattern::max_abs(values).max(f64::MIN_POSITIVE);
                let regularize = self.options.delta > 0.0 && self.options.epsilon > 0.0;
                let reg = if regularize {
                    LdltRegularization {
                        dynamic_regularization_signs: Some(&self.signs),
                        dynamic_regularization_delta: self.options.delta * scale,
                        dynamic_regularization_epsilon: self.options.epsilon * scale,
                    }
                } else {
                    LdltRegularization::default()
                };
                self.symbolic
                    .factorize_numeric_ldlt(
                        &mut self.l_values,
                        a,
                        Side::Upper,
                        reg,
                        Par::Seq,
                        stack,
                        Spec::default(),
                    )
                    .map_err(|e| match e {
                        LdltError::ZeroPivot { index } => LinalgError::ZeroPivot { index },
                    })?;
            }
            Kind::Llt => {
                self.symbolic
                    .factorize_numeric_llt(
                        &mut self.l_values,
                        a,
                        Side::Upper,
                        LltRegularization::default(),
                        Par::Seq,
                        stack,
                        Spec::default(),
                    )
                    .map_err(|e| match e {
                        LltError::NonPositivePivot { index } => {
                            LinalgError::NotPositiveDefinite { index }
                        }
                    })?;
            }
        }
        if self.l_values.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::NotFinite { what: "factor" });
        }
        self.factorized = true;
        Ok(())
    }

    /// Plain solve of `k` column-major right-hand sides in place with the
    /// (regularized) factor.
    fn raw_solve(&self, x: &mut [f64], k: usize) -> Result<(), LinalgError> {
        let n = self.pattern.dim();
        let mut run = |buf: &mut MemBuffer| {
            let stack = MemStack::new(buf);
            let rhs = MatMut::from_column_major_slice_mut(&mut *x, n, k);
            match self.kind {
                Kind::Ldlt => LdltRef::new(&self.symbolic, &self.l_values)
                    .solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack),
                Kind::Llt => LltRef::new(&self.symbolic, &self.l_values)
                    .solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack),
            }
        };
        if k == 1 {
            if let Ok(mut guard) = self.solve_mem.try_lock() {
                run(&mut guard);
                return Ok(());
            }
        }
        let mut own = alloc(self.symbolic.solve_in_place_scratch::<f64>(k, Par::Seq))?;
        run(&mut own);
        Ok(())
    }

    /// Solves `k` column-major right-hand sides with iterative refinement.
    fn solve_many(&self, rhs: &[f64], k: usize, tolerance: f64) -> Result<(Vec<f64>, Vec<SolveInfo>), LinalgError> {
        if !self.factorized {
            return Err(LinalgError::NotFactorized);
        }
        let n = self.pattern.dim();
        if rhs.len() != n * k {
            return Err(LinalgError::DimensionMismatch {
                what: "right-hand side",
                expected: n * k,
                found: rhs.len(),
            });
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::NotFinite { what: "right-hand side" });
        }
        let opts = FactorOptions { tolerance, ..self.options };
        let mut x = rhs.to_vec();
        if n == 0 || k == 0 {
            return Ok((x, vec![SolveInfo { relative_residual: 0.0, refinement_steps: 0 }; k]));
        }
        self.raw_solve(&mut x, k)?;
        let bnorm: Vec<f64> = rhs.chunks(n).map(norm2).collect();
        let mut info = vec![SolveInfo { relative_residual: 0.0, refinement_steps: 0 }; k];
        let mut kx = vec![0.0; n];
        let mut residuals = vec![0.0; n * k];
        let mut active: Vec<usize> = Vec::with_capacity(k);
        // Columns whose refinement stagnated, finished by GMRES below.
        let mut stalled: Vec<usize> = Vec::new();
        for step in 0..=opts.max_refinement_steps {
            active.clear();
            for j in 0..k {
                let xj = &x[j * n..(j + 1) * n];
                if bnorm[j] == 0.0 {
                    // b = 0 ⇒ x = 0 exactly (the solve is linear).
                    info[j].relative_residual = 0.0;
                    continue;
                }
                if stalled.contains(&j) {
                    continue;
                }
                if xj.iter().any(|v| !v.is_finite()) {
                    return Err(LinalgError::NotFinite { what: "solution" });
                }
                self.pattern.mul_vec_unchecked(&self.a_values, xj, &mut kx);
                let r = &mut residuals[active.len() * n..(active.len() + 1) * n];
                for i in 0..n {
                    r[i] = rhs[j * n + i] - kx[i];
                }
                let rel = norm2(r) / bnorm[j];
                let previous = info[j].relative_residual;
                info[j].relative_residual = rel;
                if rel < opts.tolerance {
                    continue;
                }
                if (step > 0 && rel > STALL_RATIO * previous) || step == opts.max_refinement_steps {
                    if rel >= opts.stall_accept {
                        stalled.push(j);
                    }
                } else if step < opts.max_refinement_steps {
                    active.push(j);
                }
            }
            if active.is_empty() {
                break;
            }
            let na = active.len();
            let corr = &mut residuals[..na * n];
            self.raw_solve(corr, na)?;
            for (a, &j) in active.iter().enumerate() {
                for i in 0..n {
                    x[j * n + i] += corr[a * n + i];
                }
                info[j].refinement_steps += 1;
            }
        }
        for &j in &stalled {
            let b = &rhs[j * n..(j + 1) * n];
            let mut apply = |v: &[f64], out: &mut [f64]| self.pattern.mul_vec_unchecked(&self.a_values, v, out);
            let mut precondition = |v: &mut [f64]| self.raw_solve(v, 1);
            let xj = &mut x[j * n..(j + 1) * n];
            let budget = KRYLOV_STEPS.max(opts.max_refinement_steps);
            let krylov = gmres(&mut apply, &mut precondition, b, xj, opts.tolerance, budget, KRYLOV_RESTART)?;
            info[j].relative_residual = krylov.relative_residual;
            info[j].refinement_steps += krylov.steps;
        }
        for inf in &info {
            if inf.relative_residual.is_nan() || inf.relative_residual > opts.accept_residual.max(opts.tolerance) {
                return Err(LinalgError::NotConverged {
                    relative_residual: inf.relative_residual,
                    steps: inf.refinement_steps,
                });
            }
        }
        Ok((x, info))
    }
}

/// A sparse symmetric solver: the symbolic analysis (AMD ordering) of one
/// pattern, the numeric factorization of its latest values, and solves with
/// iterative refinement against the unregularized matrix. `K` picks the
/// factorization; use it as [`LdltSolver`] or [`SparseSpd`].
pub struct SparseCholesky<K> {
    core: Core,
    kind: PhantomData<K>,
}

/// Marker for [`LdltSolver`]: LDLᵀ with sign-based dynamic regularization.
pub enum Ldlt {}

/// Marker for [`SparseSpd`]: LLᵀ without regularization.
pub enum Llt {}

/// Sparse symmetric *indefinite* solver for saddle-point/KKT systems
/// `[[A, Cᵀ], [C, 0]]`: LDLᵀ with sign-based dynamic regularization and
/// iterative refinement against the unregularized matrix.  Reuses one
/// symbolic analysis (AMD ordering) for every numeric factorization.
///
/// Rank-deficient constraints: a redundant constraint row produces a
/// (numerically) zero Schur-complement pivot that is regularized to `−δ`.
/// If the right-hand side is consistent the solve converges: the primal part
/// is the unique solution and the multipliers are one valid choice (the
/// multiplier null-space component is arbitrary).  If it is inconsistent the
/// residual stalls and the solve returns [`LinalgError::NotConverged`].
pub type LdltSolver = SparseCholesky<Ldlt>;

/// Sparse Cholesky (LLᵀ, no regularization) for symmetric positive definite
/// systems, e.g. a Poisson or ARAP global step: factor once, solve many.
pub type SparseSpd = SparseCholesky<Llt>;

impl SparseCholesky<Ldlt> {
    /// Symbolic analysis for `pattern`. `signs[i]` is the expected pivot sign
    /// of row `i`: `+1` for primal rows, `−1` for constraint rows (`0`: only
    /// regularize pivots below `epsilon` in magnitude). Errors on bad lengths/signs.
    pub fn new(pattern: &SymmetricPattern, signs: &[i8]) -> Result<Self, LinalgError> {
        if signs.len() != pattern.dim() {
            return Err(LinalgError::DimensionMismatch {
                what: "signs",
                expected: pattern.dim(),
                found: signs.len(),
            });
        }
        if let Some((index, &sign)) = signs.iter().enumerate().find(|(_, s)| !(-1..=1).contains(*s)) {
            return Err(LinalgError::InvalidSign { index, sign });
        }
        Ok(Self { core: Core::new(Kind::Ldlt, pattern, signs.to_vec())?, kind: PhantomData })
    }

    /// Like [`Self::new`] with non-default [`FactorOptions`].
    pub fn with_options(
        pattern: &SymmetricPattern,
        signs: &[i8],
        options: FactorOptions,
    ) -> Result<Self, LinalgError> {
        let mut s = Self::new(pattern, signs)?;
        s.core.options = options;
        Ok(s)
    }

    /// Current options.
    pub fn options(&self) -> FactorOptions {
        self.core.options
    }
}

impl SparseCholesky<Llt> {
    /// Symbolic analysis (AMD ordering) for `pattern`.
    pub fn new(pattern: &SymmetricPattern) -> Result<Self, LinalgError> {
        let n = pattern.dim();
        Ok(Self { core: Core::new(Kind::Llt, pattern, vec![1; n])?, kind: PhantomData })
    }

    /// Builds the pattern from `triplets` (upper or full), analyses and factorizes.
    pub fn from_triplets(n: usize, triplets: &[Triplet]) -> Result<Self, LinalgError> {
        let (pattern, values) = SymmetricPattern::with_values(n, triplets)?;
        let mut s = Self::new(&pattern)?;
        s.factorize(&values)?;
        Ok(s)
    }
}

impl<K> SparseCholesky<K> {
    /// The pattern the solver was analysed for.
    pub fn pattern(&self) -> &SymmetricPattern {
        &self.core.pattern
    }

    /// Replaces the options (takes effect at the next factorize/solve;
    /// `delta`/`epsilon` are unused for LLᵀ).
    pub fn set_options(&mut self, options: FactorOptions) {
        self.core.options = options;
    }

    /// Numeric factorization of the matrix with upper-triangle `values` in
    /// slot order (length `pattern.nnz()`); reuses the symbolic analysis.
    /// LLᵀ gives [`LinalgError::NotPositiveDefinite`] if a pivot is ≤ 0 (a
    /// singular PSD matrix may instead pass with a tiny pivot and then fail to
    /// converge in [`Self::solve`]).
    pub fn factorize(&mut self, values: &[f64]) -> Result<(), LinalgError> {
        self.core.factorize(values)
    }

    /// Solves with the (regularized) factor alone: no refinement and no
    /// residual, for callers that refine against a matrix of their own.
    /// Errors if not factorized, on a bad length or on non-finite values.
    pub fn solve_unrefined(&self, rhs: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.solve_unrefined_many(rhs, 1)
    }

    /// [`Self::solve_unrefined`] for `k` right-hand sides stored column-major
    /// in `rhs` (`n·k` values), in one blocked triangular solve.
    pub fn solve_unrefined_many(&self, rhs: &[f64], k: usize) -> Result<Vec<f64>, LinalgError> {
        let core = &self.core;
        if !core.factorized {
            return Err(LinalgError::NotFactorized);
        }
        let n = core.pattern.dim();
        if rhs.len() != n * k {
            return Err(LinalgError::DimensionMismatch { what: "right-hand side", expected: n * k, found: rhs.len() });
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::NotFinite { what: "right-hand side" });
        }
        let mut x = rhs.to_vec();
        if n > 0 && k > 0 {
            core.raw_solve(&mut x, k)?;
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::NotFinite { what: "solution" });
        }
        Ok(x)
    }

    /// Solves `K x = rhs` (refinement until relative residual < `tolerance` or
    /// `max_refinement_steps`); errors if not factorized or not converged.
    pub fn solve(&self, rhs: &[f64]) -> Result<Vec<f64>, LinalgError> {
        self.solve_with_info(rhs).map(|(x, _)| x)
    }

    /// [`Self::solve`] also returning the achieved residual and step count.
    pub fn solve_with_info(&self, rhs: &[f64]) -> Result<(Vec<f64>, SolveInfo), LinalgError> {
        let (x, info) = self.core.solve_many(rhs, 1, self.core.options.tolerance)?;
        Ok((x, info[0]))
    }

    /// Solves for `k` right-hand sides stored column-major in `rhs`
    /// (`n·k` values) with one blocked triangular solve per refinement step.
    pub fn solve_many(&self, rhs: &[f64], k: usize) -> Result<(Vec<f64>, Vec<SolveInfo>), LinalgError> {
        self.core.solve_many(rhs, k, self.core.options.tolerance)
    }

    /// [`Self::solve_many`] refined only to the relative residual
    /// `tolerance` (at least the options' `tolerance`), for solves that need
    /// less than the final accuracy.
    pub fn solve_many_to(&self, rhs: &[f64], k: usize, tolerance: f64) -> Result<(Vec<f64>, Vec<SolveInfo>), LinalgError> {
        self.core.solve_many(rhs, k, tolerance.max(self.core.options.tolerance))
    }
}
