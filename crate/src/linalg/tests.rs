use super::*;
use nalgebra::{DMatrix, DVector};

/// Dense copy of the symmetric matrix given by pattern + values.
fn dense(pattern: &SymmetricPattern, values: &[f64]) -> DMatrix<f64> {
    let n = pattern.dim();
    let mut d = DMatrix::zeros(n, n);
    for j in 0..n {
        for k in pattern.col_ptr()[j]..pattern.col_ptr()[j + 1] {
            let i = pattern.row_idx()[k];
            d[(i, j)] = values[k];
            d[(j, i)] = values[k];
        }
    }
    d
}

fn dense_solve(pattern: &SymmetricPattern, values: &[f64], rhs: &[f64]) -> Vec<f64> {
    let d = dense(pattern, values);
    d.lu().solve(&DVector::from_column_slice(rhs)).expect("dense LU").as_slice().to_vec()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

fn rel_residual(pattern: &SymmetricPattern, values: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let mut y = vec![0.0; b.len()];
    pattern.mul_vec(values, x, &mut y).unwrap();
    let r: f64 = y.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt();
    r / b.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// 5-point graph Laplacian (+ optional mass shift) of an nx × ny grid, as
/// full symmetric triplets (duplicates summed by the pattern).
fn grid_laplacian(nx: usize, ny: usize, shift: f64) -> Vec<Triplet> {
    let id = |i: usize, j: usize| j * nx + i;
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let v = id(i, j);
            t.push((v, v, shift));
            let mut nb = Vec::new();
            if i + 1 < nx {
                nb.push(id(i + 1, j));
            }
            if j + 1 < ny {
                nb.push(id(i, j + 1));
            }
            for w in nb {
                t.push((v, v, 1.0));
                t.push((w, w, 1.0));
                t.push((v, w, -1.0));
                t.push((w, v, -1.0));
            }
        }
    }
    t
}

/// A small KKT: A is a 5×5 SPD-ish tridiagonal, C has 2 rows.
fn small_kkt() -> (Vec<Triplet>, Vec<Triplet>) {
    let mut a = Vec::new();
    for i in 0..5 {
        a.push((i, i, 2.0 + 0.1 * i as f64));
        if i + 1 < 5 {
            a.push((i, i + 1, -0.7));
        }
    }
    let c = vec![(0, 0, 1.0), (0, 3, -2.0), (1, 1, 0.5), (1, 2, 1.5), (1, 4, 1.0)];
    (a, c)
}

#[test]
fn pattern_sums_duplicates_ignores_lower_and_refills() {
    let t = vec![(0, 1, 1.0), (1, 0, 1.0), (0, 1, 2.0), (2, 2, 4.0), (1, 1, -1.0)];
    let (p, v) = SymmetricPattern::with_values(3, &t).unwrap();
    assert_eq!(p.nnz(), 4); // (0,0) (0,1) (1,1) (2,2): diagonal always present
    assert_eq!(v[p.slot(0, 1).unwrap()], 3.0);
    assert_eq!(v[p.slot(1, 0).unwrap()], 3.0);
    assert_eq!(v[p.diag_slot(0)], 0.0);
    assert_eq!(v[p.diag_slot(2)], 4.0);
    let slots = p.slot_map(&t).unwrap();
    assert_eq!(slots[1], IGNORED_SLOT);
    let mut out = vec![9.0; p.nnz()];
    p.fill_values_with_slots(&slots, &[1.0, 1.0, 1.0, 1.0, 1.0], &mut out).unwrap();
    assert_eq!(out[p.slot(0, 1).unwrap()], 2.0);
    assert_eq!(
        p.values_from_triplets(&[(0, 2, 1.0)]),
        Err(LinalgError::NotInPattern { row: 0, col: 2 })
    );
    assert!(matches!(
        SymmetricPattern::from_triplets(3, &[(3, 0, 1.0)]),
        Err(LinalgError::IndexOutOfBounds { .. })
    ));
}

#[test]
fn small_kkt_matches_dense_lu() {
    let (a, c) = small_kkt();
    let b = [1.0, -2.0, 0.5, 3.0, -1.0];
    let d = [0.25, -0.75];
    let sol = solve_kkt(&a, 5, &c, 2, &b, &d).unwrap();
    let kkt = Kkt::assemble(&a, 5, &c, 2).unwrap();
    let rhs = kkt.rhs(&b, &d).unwrap();
    let reference = dense_solve(&kkt.pattern, &kkt.values, &rhs);
    assert!(max_diff(&sol.x, &reference[..5]) < 1e-12, "{:?} vs {:?}", sol.x, reference);
    assert!(max_diff(&sol.lambda, &reference[5..]) < 1e-12);
    assert!(sol.info.relative_residual < 1e-12);
    // Constraints hold.
    let cx0 = sol.x[0] - 2.0 * sol.x[3];
    assert!((cx0 - 0.25).abs() < 1e-12);
}

#[test]
fn grid_laplacian_with_dirichlet_rows() {
    // Harmonic interpolation of a linear function: the 5-point Laplacian
    // reproduces it exactly, so the KKT solution must equal it everywhere.
    let (nx, ny) = (30, 25);
    let n = nx * ny;
    let a = grid_laplacian(nx, ny, 0.0); // singular alone (constants), fixed by constraints
    let lin = |v: usize| 0.3 * (v % nx) as f64 - 0.2 * (v / nx) as f64 + 1.0;
    let boundary: Vec<usize> =
        (0..n).filter(|&v| v % nx == 0 || v % nx == nx - 1 || v / nx == 0 || v / nx == ny - 1).collect();
    let c: Vec<Triplet> = boundary.iter().enumerate().map(|(r, &v)| (r, v, 1.0)).collect();
    let d: Vec<f64> = boundary.iter().map(|&v| lin(v)).collect();
    let b = vec![0.0; n];
    let sol = solve_kkt(&a, n, &c, boundary.len(), &b, &d).unwrap();
    let exact: Vec<f64> = (0..n).map(lin).collect();
    assert!(max_diff(&sol.x, &exact) < 1e-10, "max err {}", max_diff(&sol.x, &exact));
    assert!(sol.info.relative_residual < 1e-10);
    // Independent residual check against the assembled matrix.
    let kkt = Kkt::assemble(&a, n, &c, boundary.len()).unwrap();
    let rhs = kkt.rhs(&b, &d).unwrap();
    let full: Vec<f64> = sol.x.iter().chain(&sol.lambda).copied().collect();
    assert!(rel_residual(&kkt.pattern, &kkt.values, &full, &rhs) < 1e-10);

    // A non-trivial source term and a few scattered interior constraints too.
    let f: Vec<f64> = (0..n).map(|v| ((v * 37 % 11) as f64 - 5.0) * 0.1).collect();
    let mut c2 = c.clone();
    let mut d2 = d.clone();
    for (k, v) in [100usize, 333, 517].into_iter().enumerate() {
        c2.push((boundary.len() + k, v, 1.0));
        c2.push((boundary.len() + k, v + 1, -1.0));
        d2.push(0.01 * k as f64);
    }
    let sol2 = solve_kkt(&a, n, &c2, d2.len(), &f, &d2).unwrap();
    assert!(sol2.info.relative_residual < 1e-10, "{:?}", sol2.info);
}

#[test]
fn refactorize_same_pattern_new_values() {
    let (a, c) = small_kkt();
    let mut kkt = Kkt::assemble(&a, 5, &c, 2).unwrap();
    let mut solver = LdltSolver::new(&kkt.pattern, &kkt.signs).unwrap();
    let rhs = [1.0, 2.0, 3.0, 4.0, 5.0, 0.5, -0.5];
    assert_eq!(solver.solve(&rhs), Err(LinalgError::NotFactorized));
    for round in 0..4 {
        let s = 1.0 + round as f64;
        let a2: Vec<Triplet> = a.iter().map(|&(i, j, v)| (i, j, v * s)).collect();
        let c2: Vec<Triplet> = c.iter().map(|&(i, j, v)| (i, j, v / s + 0.1 * round as f64)).collect();
        kkt.refill(&a2, &c2).unwrap();
        solver.factorize(&kkt.values).unwrap();
        let (x, info) = solver.solve_with_info(&rhs).unwrap();
        let reference = dense_solve(&kkt.pattern, &kkt.values, &rhs);
        let scale = reference.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        assert!(max_diff(&x, &reference) < 1e-11 * scale, "round {round}: {} (scale {scale})", max_diff(&x, &reference));
        assert!(info.relative_residual < 1e-12);
    }
    // Larger: the grid KKT with a varying mass shift, refactorized in place;
    // also checks multiple right-hand sides against single solves.
    let (nx, ny) = (20, 20);
    let n = nx * ny;
    let cons: Vec<Triplet> = (0..nx).map(|r| (r, r, 1.0)).collect();
    let mut big = Kkt::assemble(&grid_laplacian(nx, ny, 0.0), n, &cons, nx).unwrap();
    let mut solver = LdltSolver::new(&big.pattern, &big.signs).unwrap();
    for shift in [0.0, 1e-3, 1.0] {
        big.refill(&grid_laplacian(nx, ny, shift), &cons).unwrap();
        solver.factorize(&big.values).unwrap();
        let k = 3;
        let rhs: Vec<f64> = (0..(n + nx) * k).map(|i| ((i * 13 % 7) as f64 - 3.0) * 0.5).collect();
        let (xs, infos) = solver.solve_many(&rhs, k).unwrap();
        for j in 0..k {
            let bj = &rhs[j * (n + nx)..(j + 1) * (n + nx)];
            let xj = solver.solve(bj).unwrap();
            assert!(max_diff(&xj, &xs[j * (n + nx)..(j + 1) * (n + nx)]) < 1e-9);
            assert!(infos[j].relative_residual < 1e-12, "{:?}", infos[j]);
        }
    }
}

#[test]
fn singular_cases_return_errors() {
    let (a, c) = small_kkt();
    let kkt = Kkt::assemble(&a, 5, &c, 2).unwrap();
    // 1. No regularization: the zero constraint block gives a zero pivot
    //    (faer's LDLᵀ does not pivot), reported as an error, not a panic/NaN.
    let opts = FactorOptions { delta: 0.0, ..FactorOptions::default() };
    let mut s = LdltSolver::with_options(&kkt.pattern, &kkt.signs, opts).unwrap();
    let r = s.factorize(&kkt.values);
    assert!(
        matches!(r, Err(LinalgError::ZeroPivot { .. })),
        "{r:?}"
    );
    assert_eq!(s.solve(&[0.0; 7]), Err(LinalgError::NotFactorized));

    // 2. A variable with no entries at all and a nonzero right-hand side.
    let mut t = a.clone();
    t.push((5, 5, 0.0));
    let (p, v) = SymmetricPattern::with_values(6, &t).unwrap();
    let mut s = LdltSolver::new(&p, &[1; 6]).unwrap();
    s.factorize(&v).unwrap(); // regularized: pivot replaced by +δ
    let r = s.solve(&[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    assert!(matches!(r, Err(LinalgError::NotConverged { .. })), "{r:?}");
    // …and LLᵀ refuses it outright.
    let mut spd = SparseSpd::new(&p).unwrap();
    assert!(matches!(spd.factorize(&v), Err(LinalgError::NotPositiveDefinite { .. })));
    assert!(matches!(
        SparseSpd::from_triplets(2, &[(0, 0, 1.0), (1, 1, -1.0)]),
        Err(LinalgError::NotPositiveDefinite { .. })
    ));

    // 3. Pure Neumann Laplacian (constants in the kernel): consistent rhs
    //    (zero mean) solves, inconsistent rhs is NotConverged.
    let (nx, ny) = (8, 7);
    let n = nx * ny;
    let (p, v) = SymmetricPattern::with_values(n, &grid_laplacian(nx, ny, 0.0)).unwrap();
    let mut s = LdltSolver::new(&p, &vec![1; n]).unwrap();
    s.factorize(&v).unwrap();
    let mut b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
    let mean = b.iter().sum::<f64>() / n as f64;
    b.iter_mut().for_each(|x| *x -= mean);
    let (_, info) = s.solve_with_info(&b).unwrap();
    assert!(info.relative_residual < 1e-10, "{info:?}");
    b[0] += 1.0;
    assert!(matches!(s.solve(&b), Err(LinalgError::NotConverged { .. })));

    // 4. Non-finite input and wrong lengths.
    let mut bad = kkt.values.clone();
    bad[0] = f64::NAN;
    let mut s = LdltSolver::new(&kkt.pattern, &kkt.signs).unwrap();
    assert_eq!(s.factorize(&bad), Err(LinalgError::NotFinite { what: "matrix values" }));
    assert!(matches!(s.factorize(&bad[1..]), Err(LinalgError::DimensionMismatch { .. })));
    s.factorize(&kkt.values).unwrap();
    assert!(matches!(s.solve(&[1.0; 3]), Err(LinalgError::DimensionMismatch { .. })));
    assert!(matches!(
        LdltSolver::new(&kkt.pattern, &[1, 1, 1, 1, 1, -1, 2]),
        Err(LinalgError::InvalidSign { index: 6, sign: 2 })
    ));
    assert!(matches!(solve_kkt(&a, 5, &c, 2, &[0.0; 4], &[0.0; 2]), Err(LinalgError::DimensionMismatch { .. })));
}

#[test]
fn redundant_constraint_rows() {
    // C has a duplicated row and a row that is the sum of two others
    // (rank-deficient C, as the cone problem can produce).
    let (nx, ny) = (12, 10);
    let n = nx * ny;
    let a = grid_laplacian(nx, ny, 1e-2);
    let base: Vec<Triplet> = vec![(0, 0, 1.0), (1, 5, 1.0), (1, 6, -1.0), (2, 50, 2.0), (2, 70, 1.0)];
    let d_base = vec![1.0, 0.5, -0.25];
    let mut c = base.clone();
    c.push((3, 0, 1.0)); // duplicate of row 0
    for &(r, col, v) in &base {
        if r == 1 || r == 2 {
            c.push((4, col, v)); // row 4 = row 1 + row 2
        }
    }
    let f: Vec<f64> = (0..n).map(|i| ((i * 5 % 9) as f64 - 4.0) * 0.1).collect();
    let reference = solve_kkt(&a, n, &base, 3, &f, &d_base).unwrap();

    // Consistent right-hand side: converges; primal part is unique and matches.
    let d = vec![1.0, 0.5, -0.25, 1.0, 0.25];
    let sol = solve_kkt(&a, n, &c, 5, &f, &d).unwrap();
    assert!(sol.info.relative_residual < 1e-10, "{:?}", sol.info);
    assert!(max_diff(&sol.x, &reference.x) < 1e-8, "{}", max_diff(&sol.x, &reference.x));
    // Multipliers are not unique, but Cᵀλ is.
    let mut ct_l = vec![0.0; n];
    let mut ct_l_ref = vec![0.0; n];
    for &(r, col, v) in &c {
        ct_l[col] += v * sol.lambda[r];
    }
    for &(r, col, v) in &base {
        ct_l_ref[col] += v * reference.lambda[r];
    }
    assert!(max_diff(&ct_l, &ct_l_ref) < 1e-7);

    // Inconsistent right-hand side (duplicate row asks for another value).
    let d_bad = vec![1.0, 0.5, -0.25, 2.0, 0.25];
    let r = solve_kkt(&a, n, &c, 5, &f, &d_bad);
    assert!(matches!(r, Err(LinalgError::NotConverged { .. })), "{r:?}");
}

#[test]
fn sparse_spd_matches_dense_and_solves_many() {
    let (nx, ny) = (9, 8);
    let n = nx * ny;
    let t = grid_laplacian(nx, ny, 0.05);
    let spd = SparseSpd::from_triplets(n, &t).unwrap();
    let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
    let (x, info) = spd.solve_with_info(&b).unwrap();
    let (p, v) = SymmetricPattern::with_values(n, &t).unwrap();
    assert!(max_diff(&x, &dense_solve(&p, &v, &b)) < 1e-10);
    assert!(info.relative_residual < 1e-12);
    let b2: Vec<f64> = b.iter().chain(b.iter().map(|v| v * 2.0).collect::<Vec<_>>().iter()).copied().collect();
    let (x2, _) = spd.solve_many(&b2, 2).unwrap();
    assert!(max_diff(&x2[..n], &x) < 1e-12);
    assert!(max_diff(&x2[n..], &x.iter().map(|v| v * 2.0).collect::<Vec<_>>()) < 1e-11);
    // Zero rhs gives exactly zero.
    assert!(spd.solve(&vec![0.0; n]).unwrap().iter().all(|v| *v == 0.0));
}

#[test]
fn degenerate_sizes() {
    // No constraints: LDLᵀ on an SPD matrix.
    let (a, _) = small_kkt();
    let sol = solve_kkt(&a, 5, &[], 0, &[1.0; 5], &[]).unwrap();
    assert!(sol.lambda.is_empty() && sol.info.relative_residual < 1e-12);
    // Empty system.
    let sol = solve_kkt(&[], 0, &[], 0, &[], &[]).unwrap();
    assert!(sol.x.is_empty());
    let spd = SparseSpd::from_triplets(0, &[]).unwrap();
    assert!(spd.solve(&[]).unwrap().is_empty());
}

#[test]
fn null_space_projection_is_orthogonal() {
    // Two rows on four unknowns: x0 - x1 = 0, x1 + x2 - 2 x3 = 0.
    let c = [(0, 0, 1.0), (0, 1, -1.0), (1, 1, 1.0), (1, 2, 1.0), (1, 3, -2.0)];
    let p = NullSpaceProjector::new(&c, 4, 2).unwrap();
    let y0 = [1.0, -2.0, 0.5, 3.0];
    let mut y = y0;
    assert!(p.project(&mut y, 1e-15, 3));
    assert!(p.residual(&y).iter().all(|r| r.abs() < 1e-14));
    // The removed part lies in the row space: orthogonal to every null vector.
    let d: Vec<f64> = y0.iter().zip(&y).map(|(a, b)| a - b).collect();
    for z in [[1.0, 1.0, 1.0, 1.0], [1.0, 1.0, -1.0, 0.0]] {
        assert!(d.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>().abs() < 1e-14);
    }
    // A feasible vector is left alone; a wrong length is refused.
    let mut f = [1.0, 1.0, 1.0, 1.0];
    assert!(p.project(&mut f, 1e-15, 3) && f == [1.0, 1.0, 1.0, 1.0]);
    assert!(!p.project(&mut [0.0; 3], 1e-15, 3));
    // Rank-deficient rows are refused.
    assert!(NullSpaceProjector::new(&[(0, 0, 1.0), (1, 0, 2.0)], 2, 2).is_err());
}

/// A solve whose refinement stagnates below `stall_accept` is returned as it
/// is; with `stall_accept = 0` the same solve is finished by GMRES. The
/// tolerance 0 is unreachable, so refinement always stagnates.
#[test]
fn stagnating_solves_below_stall_accept_skip_gmres() {
    let (nx, ny) = (9, 8);
    let n = nx * ny;
    let (p, v) = SymmetricPattern::with_values(n, &grid_laplacian(nx, ny, 0.5)).unwrap();
    let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
    let solve = |stall_accept: f64| {
        let opts = FactorOptions { tolerance: 0.0, stall_accept, ..FactorOptions::default() };
        let mut s = LdltSolver::with_options(&p, &vec![1; n], opts).unwrap();
        s.factorize(&v).unwrap();
        let (x, info) = s.solve_many_to(&b, 1, 0.0).unwrap();
        assert!(rel_residual(&p, &v, &x, &b) < 1e-13, "{info:?}");
        info[0]
    };
    let accepted = solve(1e-10);
    assert!(accepted.refinement_steps <= 2, "{accepted:?}");
    let finished = solve(0.0);
    assert!(finished.refinement_steps > 10, "{finished:?}");
}
