//! A fixed sparsity pattern for a symmetric matrix, stored as the upper
//! triangle in compressed sparse column (CSC) form with sorted row indices.
//!
//! The pattern is built once from triplets; values are then carried as plain
//! `Vec<f64>` slices in *slot order* (one slot per stored upper-triangular
//! entry) so that a factorization can reuse its symbolic analysis whenever
//! only the values change.

use super::LinalgError;

/// Triplet convention used throughout [`crate::linalg`]: `(row, col, value)`.
pub type Triplet = (usize, usize, f64);

/// Marker stored in a slot map for a triplet that does not contribute
/// (a strictly-lower entry, which is implied by symmetry).
pub const IGNORED_SLOT: usize = usize::MAX;

/// Sparsity pattern of an `n × n` symmetric matrix (upper triangle, CSC,
/// sorted rows, every diagonal entry present).
///
/// Triplet input convention (all builders and refill functions): give the
/// upper triangle (`row <= col`) or the full symmetric matrix; strictly-lower
/// triplets (`row > col`) are ignored because they are implied by symmetry.
/// Duplicates are summed.  Never give the lower triangle alone.
#[derive(Clone, Debug)]
pub struct SymmetricPattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl SymmetricPattern {
    /// Builds the pattern of the `n × n` symmetric matrix whose entries are the
    /// positions of `triplets` (values are ignored; explicit zeros are kept).
    /// The diagonal is always included.  Errors on an index `>= n`.
    pub fn from_triplets(n: usize, triplets: &[Triplet]) -> Result<Self, LinalgError> {
        Self::from_positions(n, triplets.iter().map(|&(r, c, _)| (r, c)))
    }

    /// Same as [`Self::from_triplets`] for bare `(row, col)` positions.
    pub fn from_positions(
        n: usize,
        positions: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, LinalgError> {
        // Collect upper-triangular (row, col) pairs per column, plus the diagonal.
        let mut entries: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
        for (r, c) in positions {
            if r >= n || c >= n {
                return Err(LinalgError::IndexOutOfBounds { row: r, col: c, n });
            }
            if r <= c {
                entries.push((r, c));
            }
        }
        // Sort by (col, row) and deduplicate.
        entries.sort_unstable_by_key(|&(r, c)| (c, r));
        entries.dedup();
        let mut col_ptr = vec![0usize; n + 1];
        for &(_, c) in &entries {
            col_ptr[c + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let row_idx = entries.iter().map(|&(r, _)| r).collect();
        Ok(Self { n, col_ptr, row_idx })
    }

    /// Builds the pattern and the matching values (duplicates summed) in one go.
    pub fn with_values(n: usize, triplets: &[Triplet]) -> Result<(Self, Vec<f64>), LinalgError> {
        let pattern = Self::from_triplets(n, triplets)?;
        let values = pattern.values_from_triplets(triplets)?;
        Ok((pattern, values))
    }

    /// Matrix dimension `n`.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of stored upper-triangular entries (= length of a value slice).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// CSC column pointers of the upper triangle (length `n + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// CSC row indices of the upper triangle (sorted within each column).
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Slot of entry `(row, col)` or `(col, row)` (symmetric lookup), if stored.
    pub fn slot(&self, row: usize, col: usize) -> Option<usize> {
        let (r, c) = if row <= col { (row, col) } else { (col, row) };
        if c >= self.n {
            return None;
        }
        let (start, end) = (self.col_ptr[c], self.col_ptr[c + 1]);
        self.row_idx[start..end].binary_search(&r).ok().map(|k| start + k)
    }

    /// Slot of the diagonal entry `(i, i)` (always stored). Panics only if `i >= n`.
    pub fn diag_slot(&self, i: usize) -> usize {
        // The diagonal is the last entry of column i in the upper triangle.
        self.col_ptr[i + 1] - 1
    }

    /// For each triplet, the slot it is summed into ([`IGNORED_SLOT`] for a
    /// strictly-lower triplet).  Compute once, then refill values cheaply with
    /// [`Self::fill_values_with_slots`].  Errors if an entry is not in the pattern.
    pub fn slot_map(&self, triplets: &[Triplet]) -> Result<Vec<usize>, LinalgError> {
        triplets
            .iter()
            .map(|&(r, c, _)| self.triplet_slot(r, c))
            .collect()
    }

    fn triplet_slot(&self, r: usize, c: usize) -> Result<usize, LinalgError> {
        if r >= self.n || c >= self.n {
            return Err(LinalgError::IndexOutOfBounds { row: r, col: c, n: self.n });
        }
        if r > c {
            return Ok(IGNORED_SLOT);
        }
        self.slot(r, c).ok_or(LinalgError::NotInPattern { row: r, col: c })
    }

    /// Values in slot order for `triplets` on this pattern (duplicates summed,
    /// strictly-lower ignored, absent entries zero).  Errors if a triplet lies
    /// outside the pattern.
    pub fn values_from_triplets(&self, triplets: &[Triplet]) -> Result<Vec<f64>, LinalgError> {
        let mut out = vec![0.0; self.nnz()];
        self.fill_values(triplets, &mut out)?;
        Ok(out)
    }

    /// Overwrites `out` (length [`Self::nnz`]) with the values of `triplets`,
    /// like [`Self::values_from_triplets`] without allocating.
    pub fn fill_values(&self, triplets: &[Triplet], out: &mut [f64]) -> Result<(), LinalgError> {
        self.check_len(out.len())?;
        out.iter_mut().for_each(|v| *v = 0.0);
        for &(r, c, v) in triplets {
            let s = self.triplet_slot(r, c)?;
            if s != IGNORED_SLOT {
                out[s] += v;
            }
        }
        Ok(())
    }

    /// Overwrites `out` with `Σ values[k]` into `slots[k]` (a map from
    /// [`Self::slot_map`]); `values` are the triplet values in the same order.
    pub fn fill_values_with_slots(
        &self,
        slots: &[usize],
        values: &[f64],
        out: &mut [f64],
    ) -> Result<(), LinalgError> {
        self.check_len(out.len())?;
        if slots.len() != values.len() {
            return Err(LinalgError::DimensionMismatch {
                what: "slot map vs triplet values",
                expected: slots.len(),
                found: values.len(),
            });
        }
        out.iter_mut().for_each(|v| *v = 0.0);
        for (&s, &v) in slots.iter().zip(values) {
            if s != IGNORED_SLOT {
                if s >= out.len() {
                    return Err(LinalgError::DimensionMismatch {
                        what: "slot index",
                        expected: out.len(),
                        found: s,
                    });
                }
                out[s] += v;
            }
        }
        Ok(())
    }

    /// `y = K x` for the symmetric matrix `K` with upper-triangle `values`
    /// (slot order).  Lengths must be `nnz`, `n`, `n`.
    pub fn mul_vec(&self, values: &[f64], x: &[f64], y: &mut [f64]) -> Result<(), LinalgError> {
        self.check_len(values.len())?;
        for (what, len) in [("x", x.len()), ("y", y.len())] {
            if len != self.n {
                return Err(LinalgError::DimensionMismatch { what, expected: self.n, found: len });
            }
        }
        self.mul_vec_unchecked(values, x, y);
        Ok(())
    }

    #[allow(clippy::needless_range_loop)]
    pub(crate) fn mul_vec_unchecked(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.n {
            let xj = x[j];
            let mut acc = 0.0;
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[k];
                let a = values[k];
                if i == j {
                    acc += a * xj;
                } else {
                    acc += a * x[i];
                    y[i] += a * xj;
                }
            }
            y[j] += acc;
        }
    }

    /// Largest absolute value among `values` (0 if empty).
    pub(crate) fn max_abs(values: &[f64]) -> f64 {
        values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    pub(crate) fn check_len(&self, len: usize) -> Result<(), LinalgError> {
        if len != self.nnz() {
            return Err(LinalgError::DimensionMismatch {
                what: "value slice (pattern nnz)",
                expected: self.nnz(),
                found: len,
            });
        }
        Ok(())
    }
}
