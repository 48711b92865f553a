//! Benchmark of the KKT LDLᵀ solver on a realistic system:
//! `A = L + M/A_total` (cotangent Laplacian + barycentric mass) of a bumpy
//! triangulated grid with ~13 000 vertices, plus a few hundred constraint rows
//! (single-vertex rows, difference rows and long "path" rows).
//!
//! Run: `cargo run --release -p conemap --example bench_ldlt [nx ny]`
//! Prints one JSON line with timings in milliseconds.

use std::time::Instant;

use conemap::linalg::{Kkt, LdltSolver, SparseSpd, Triplet};
use conemap::TriMesh;

fn grid(nx: usize, ny: usize) -> TriMesh {
    let h = 1.0 / nx.max(ny) as f64;
    let raw = conemap::mesh::shapes::grid(nx, ny, |u, v| {
        let (x, y) = (u * nx as f64 * h, v * ny as f64 * h);
        [x, y, 0.08 * (7.0 * x).sin() * (5.0 * y).cos()]
    });
    TriMesh::from_raw(&raw).expect("a bumpy grid is a valid mesh")
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (nx, ny) = (args.first().copied().unwrap_or(114), args.get(1).copied().unwrap_or(113));
    let mesh = grid(nx, ny);
    let n = mesh.n_vertices();

    // A = L + M / A_total  (α_smooth = 1).
    let mut a: Vec<Triplet> = mesh.cotan_laplacian_triplets(0..mesh.n_faces() as u32);
    let m = mesh.vertex_areas();
    let area: f64 = m.iter().sum();
    a.extend(m.iter().enumerate().map(|(i, mi)| (i, i, mi / area)));

    // Constraints: 200 single-vertex rows, 60 difference rows, 40 path rows
    // (each a run of 40 vertices along a grid row, like loop/path integrals).
    let mut c: Vec<Triplet> = Vec::new();
    let mut row = 0;
    let stride = n / 200;
    for k in 0..200 {
        c.push((row, (k * stride + 17) % n, 1.0));
        row += 1;
    }
    for k in 0..60 {
        let v = (k * 211 + 5) % (n - nx - 2);
        c.push((row, v, 1.0));
        c.push((row, v + nx + 2, -1.0));
        row += 1;
    }
    for k in 0..40 {
        let j = 3 + (k * 7) % (ny - 6);
        let i0 = (k * 13) % (nx - 41);
        for s in 0..40 {
            c.push((row, j * (nx + 1) + i0 + s, if s % 2 == 0 { 0.5 } else { -0.25 }));
        }
        row += 1;
    }
    let mc = row;
    let rhs_c: Vec<f64> = (0..mc).map(|r| ((r * 7 % 13) as f64 - 6.0) * 0.01).collect();
    let rhs_p: Vec<f64> = (0..n).map(|i| ((i * 31 % 17) as f64 - 8.0) * 1e-4).collect();

    let t0 = Instant::now();
    let kkt = Kkt::assemble(&a, n, &c, mc).expect("assemble");
    let t_assemble = ms(t0);

    let t0 = Instant::now();
    let mut solver = LdltSolver::new(&kkt.pattern, &kkt.signs).expect("symbolic");
    let t_symbolic = ms(t0);

    let t0 = Instant::now();
    solver.factorize(&kkt.values).expect("numeric");
    let t_numeric = ms(t0);

    // Refactorization on the same pattern (values scaled), averaged.
    let reps = 5;
    let mut vals = kkt.values.clone();
    let t0 = Instant::now();
    for r in 0..reps {
        for v in vals.iter_mut() {
            *v *= 1.0 + 1e-3 * r as f64;
        }
        solver.factorize(&vals).expect("refactor");
    }
    let t_refactor = ms(t0) / reps as f64;
    solver.factorize(&kkt.values).expect("numeric");

    let rhs = kkt.rhs(&rhs_p, &rhs_c).expect("rhs");
    let t0 = Instant::now();
    let (_, info) = solver.solve_with_info(&rhs).expect("solve");
    let t_solve = ms(t0);

    let k = 8;
    let many: Vec<f64> = (0..k).flat_map(|j| rhs.iter().map(move |v| v * (1.0 + j as f64))).collect();
    let t0 = Instant::now();
    let (_, infos) = solver.solve_many(&many, k).expect("solve_many");
    let t_solve_many = ms(t0) / k as f64;
    let worst = infos.iter().fold(0.0f64, |m, i| m.max(i.relative_residual));

    // Plain SPD Cholesky of A alone for comparison (Poisson-like step).
    let t0 = Instant::now();
    let spd = SparseSpd::from_triplets(n, &a).expect("spd");
    let t_spd_factor = ms(t0);
    let t0 = Instant::now();
    let (_, spd_info) = spd.solve_with_info(&rhs_p).expect("spd solve");
    let t_spd_solve = ms(t0);

    println!(
        "{{\"vertices\":{n},\"faces\":{},\"constraints\":{mc},\"kkt_dim\":{},\"kkt_nnz_upper\":{},\
\"assemble_ms\":{t_assemble:.3},\"symbolic_ms\":{t_symbolic:.3},\"numeric_ms\":{t_numeric:.3},\
\"refactor_ms\":{t_refactor:.3},\"solve_ms\":{t_solve:.3},\"refinement_steps\":{},\
\"relative_residual\":{:.3e},\"solve_many_ms_per_rhs\":{t_solve_many:.3},\"solve_many_worst_residual\":{worst:.3e},\
\"spd_analyse_factor_ms\":{t_spd_factor:.3},\"spd_solve_ms\":{t_spd_solve:.3},\"spd_residual\":{:.3e}}}",
        mesh.n_faces(),
        n + mc,
        kkt.pattern.nnz(),
        info.refinement_steps,
        info.relative_residual,
        spd_info.relative_residual,
    );
}
