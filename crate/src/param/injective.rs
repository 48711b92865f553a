//! Injective refinement of a fold-free seamless map (after the ARAP stage of
//! Appendix B.2): SLIM-style reweighted local/global iterations (Rabinovich
//! et al. 2017) of the energy
//!
//! `E(f) = sum_f A_f psi(sigma_1, sigma_2)`,
//! `psi = sum_i (sigma_i - 1)^2 + mu (sigma_i - 1/sigma_i)^2`,
//!
//! i.e. the ARAP energy (4) plus `mu` times the symmetric Dirichlet energy
//! (minus its minimum 4), which is infinite on degenerate triangles and so a
//! barrier against flips. (Optionally the ARAP term is replaced by a
//! smoothed version of eq. (19)'s summand, [`Density`]: lower mean
//! distortion, more concentrated, fewer triangles below 0.3 on some meshes.)
//!
//! Every iteration minimises a quadratic proxy of `E`: SLIM's
//! `sum_f A_f |W_f (grad (f + d) - R_f)|^2` with `W_f^T W_f` replaced by its
//! largest eigenvalue `w_f` times the identity (the same gradient at `f`, a
//! larger Hessian, so still a descent step). That is a weighted version of
//! (23) whose u and v blocks are coupled only through the constraints: its
//! factor is half the size of SLIM's proxy's. Steps keep the same exact
//! linear constraints (seam transitions, isolines, pins); a line search then
//! starts from the largest step that keeps every triangle's signed UV area
//! positive. The constraints are homogeneous, so every iterate stays feasible.
//! Started from a fold-free map, no triangle flips and the UV angle sum at
//! every vertex (a continuous function of the iterate while no triangle
//! degenerates) keeps its value: the map never starts to wind around a cone.

use super::element::Element;
use super::ParamError;
use crate::linalg::{Kkt, LdltSolver, NullSpaceProjector, FactorOptions, Triplet};

/// Iterations over which the energy decrease is averaged for the stop test:
/// a step limited by one nearly degenerate triangle can gain little while the
/// next one gains much, so single iterations are a poor test.
pub const STALL_WINDOW: usize = 5;

/// Iterations per factorization of the proxy matrix (see [`Refiner::refine`]).
const REFACTOR_EVERY: usize = 5;

/// Most projections that push a step back onto the constraints.
const FEASIBILITY_PASSES: usize = 3;

/// `max |C d| / max |d|` a step is projected down to: over the 60 iterations
/// the iterate must stay on the constraints to ~1e-12 of its size.
const FEASIBILITY_TOLERANCE: f64 = 1e-14;

/// A 2×2 matrix, row-major.
type Mat2 = [[f64; 2]; 2];

/// Settings of [`Refiner::refine`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineOptions {
    /// Weight `mu` of the symmetric Dirichlet barrier term (> 0).
    pub barrier: f64,
    /// Smoothing `eps` of the distortion term ([`Density`]); `inf`: ARAP.
    pub smoothing: f64,
    /// Cap on the iterations (0 disables the refinement).
    pub max_iterations: usize,
    /// Stop once the last [`STALL_WINDOW`] iterations lowered the energy by
    /// less than this fraction per iteration on average.
    pub tolerance: f64,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions { barrier: 0.002, smoothing: f64::INFINITY, max_iterations: 60, tolerance: 1e-4 }
    }
}

/// What [`Refiner::refine`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RefineStats {
    /// Accepted iterations.
    pub iterations: usize,
    /// Energy `E` of the start and of the result (`inf` start: not fold-free).
    pub energy_start: f64,
    pub energy: f64,
}

/// Singular values and polar data of a 2×2 Jacobian with positive determinant.
#[derive(Clone, Copy, Debug)]
struct Svd {
    /// `sigma_1 >= sigma_2 > 0`.
    sigma: [f64; 2],
    /// Closest rotation `U V^T` (Appendix B.2, local step).
    rot: [[f64; 2]; 2],
    /// `(cos 2 phi, sin 2 phi)` of the first left singular vector `(cos phi, sin phi)`.
    dir2: [f64; 2],
}

/// Closed-form SVD of `j` (rows: u and v gradients) from its conformal and
/// anticonformal parts; `None` unless `det j > 0` and everything is finite.
fn svd(j: [[f64; 2]; 2]) -> Option<Svd> {
    let (a, b, c, d) = (j[0][0], j[0][1], j[1][0], j[1][1]);
    let (e, h) = (0.5 * (a + d), 0.5 * (c - b));
    let (f, g) = (0.5 * (a - d), 0.5 * (c + b));
    let q = e.hypot(h);
    let r = f.hypot(g);
    let s1 = q + r;
    // sigma_2 = det / sigma_1 stays accurate when q ≈ r.
    let s2 = (a * d - b * c) / s1;
    if !(s2 > 0.0) || !(q > r) || !s1.is_finite() {
        return None;
    }
    let rot = [[e / q, -h / q], [h / q, e / q]];
    let dir2 = if r > 1e-14 * q { [(e * f - h * g) / (q * r), (h * f + e * g) / (q * r)] } else { [1.0, 0.0] };
    Some(Svd { sigma: [s1, s2], rot, dir2 })
}

/// The energy density `psi` of the module doc: `mu` weighs the barrier,
/// `eps` smooths the distortion term (`inf`: the ARAP term).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Density {
    pub mu: f64,
    pub eps: f64,
}

impl Density {
    /// Distortion term `D = sum_i (sigma_i - 1)^2` → `2 eps (sqrt(eps^2 + D) - eps)`
    /// (≈ `D` for small `D`, ≈ `2 eps sqrt(D)`, eq. (19)'s summand, for large).
    fn distortion(&self, d: f64) -> f64 {
        if self.eps.is_finite() {
            2.0 * self.eps * d / ((self.eps * self.eps + d).sqrt() + self.eps)
        } else {
            d
        }
    }

    /// `psi(J)` (0 at rotations); `inf` when `det J <= 0` (flipped or degenerate).
    pub fn value(&self, j: [[f64; 2]; 2]) -> f64 {
        match svd(j) {
            Some(s) => {
                let d: f64 = s.sigma.iter().map(|&x| (x - 1.0).powi(2)).sum();
                self.distortion(d) + self.mu * s.sigma.iter().map(|&x| (x - 1.0 / x).powi(2)).sum::<f64>()
            }
            None => f64::INFINITY,
        }
    }

    /// Local step: the SPD matrix `M = W^T W = U diag(w_1^2, w_2^2) U^T`, the
    /// closest rotation `R` with `2 M (J - R) = grad psi(J)`, from the SLIM
    /// weights `w_i^2 = (d psi / d sigma_i) / (2 (sigma_i - 1))`, and the
    /// largest eigenvalue `max w_i^2` of `M`; `None` when `det J <= 0`.
    fn proxy(&self, j: Mat2) -> Option<(Mat2, Mat2, f64)> {
        let s = svd(j)?;
        let d: f64 = s.sigma.iter().map(|&x| (x - 1.0).powi(2)).sum();
        let base = if self.eps.is_finite() { self.eps / (self.eps * self.eps + d).sqrt() } else { 1.0 };
        // Barrier: (s - 1/s)^2 has derivative 2 (s - s^-3) = 2 (s - 1)(1 + s)(1 + s^2) / s^3.
        let w = s.sigma.map(|x| base + self.mu * (1.0 + x) * (1.0 + x * x) / (x * x * x));
        let (m, t) = (0.5 * (w[0] + w[1]), 0.5 * (w[0] - w[1]));
        let (c, sn) = (s.dir2[0], s.dir2[1]);
        let mm = [[m + t * c, t * sn], [t * sn, m - t * c]];
        let w_max = w[0].max(w[1]);
        (mm.iter().flatten().all(|v| v.is_finite()) && w_max.is_finite()).then_some((mm, s.rot, w_max))
    }
}

/// Total energy `E(x) = sum_f A_f psi(J_f)`; `inf` when a triangle is flipped or degenerate.
pub(super) fn energy(elements: &[Element], x: &[f64], psi: &Density) -> f64 {
    let mut e = 0.0;
    for el in elements {
        let d = psi.value(el.jacobian(x));
        if !d.is_finite() {
            return f64::INFINITY;
        }
        e += el.area * d;
    }
    e
}

/// Largest `t > 0` such that the triangle `p + s q` keeps a positive signed
/// area for every `s` in `[0, t)`: the smallest positive root of the
/// quadratic `area(p + t q) = 0` (`inf` when there is none).
pub fn max_step(p: [[f64; 2]; 3], q: [[f64; 2]; 3]) -> f64 {
    let cross = |u: [f64; 2], v: [f64; 2]| u[0] * v[1] - u[1] * v[0];
    let sub = |u: [f64; 2], v: [f64; 2]| [u[0] - v[0], u[1] - v[1]];
    let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let (f1, f2) = (sub(q[1], q[0]), sub(q[2], q[0]));
    let a = cross(e1, e2);
    let b = cross(e1, f2) + cross(f1, e2);
    let c = cross(f1, f2);
    if !(a > 0.0) {
        return 0.0;
    }
    let mut t = f64::INFINITY;
    if c == 0.0 {
        if b < 0.0 {
            t = -a / b;
        }
        return t;
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return t;
    }
    // Stable roots: q/c and a/q with q = -(b + sign(b) sqrt(disc)) / 2.
    let qq = -0.5 * (b + b.signum() * disc.sqrt());
    for root in [qq / c, if qq != 0.0 { a / qq } else { f64::INFINITY }] {
        if root > 0.0 && root < t {
            t = root;
        }
    }
    t
}

/// The reweighted global step on the constrained system: the KKT matrix
/// `[[A(w), C^T], [C, 0]]` of (23) with face weights `w_f` (module doc),
/// analysed once and refactored with new weights every few iterations.
pub(super) struct Refiner<'a> {
    elements: &'a [Element],
    n: usize,
    constraints: &'a [Triplet],
    kkt: Kkt,
    solver: LdltSolver,
    /// Slot of every triplet ([`PER_FACE`] per face, then the constraints) in `kkt.values`.
    slots: Vec<usize>,
    values: Vec<f64>,
    /// Puts every step back onto `C d = 0` (the factor's solve leaves it off by
    /// the regularization, ~1e-8 relative to the step).
    projector: &'a NullSpaceProjector,
}

impl<'a> Refiner<'a> {
    /// Builds the pattern for `elements` (unknowns `0..n`) and the `m`
    /// constraint rows `constraints` (`(row, unknown, value)`, homogeneous),
    /// whose null-space `projector` it borrows.
    pub(super) fn new(
        elements: &'a [Element],
        n: usize,
        constraints: &'a [Triplet],
        m: usize,
        projector: &'a NullSpaceProjector,
    ) -> Result<Self, ParamError> {
        let mut a = Vec::with_capacity(PER_FACE * elements.len());
        for el in elements {
            for_pairs(el, |i, j| a.push((i, j, if i == j { 1.0 } else { 0.0 })));
        }
        let kkt = Kkt::assemble(&a, n, constraints, m)?;
        let mut t = a;
        t.extend(constraints.iter().map(|&(r, c, v)| (c, n + r, v)));
        let slots = kkt.pattern.slot_map(&t)?;
        let values = t.iter().map(|e| e.2).collect();
        // The triplets are the largest temporary: free them before the
        // factor is allocated (wasm memory never shrinks).
        drop(t);
        let mut solver = LdltSolver::new(&kkt.pattern, &kkt.signs)?;
        solver.set_options(FactorOptions { delta: 1e-11, ..FactorOptions::default() });
        Ok(Refiner { elements, n, constraints, kkt, solver, slots, values, projector })
    }

    /// Minimises `E` (module doc) from the fold-free `x` (unknowns, length `n`,
    /// satisfying the constraints) in place: at most `options.max_iterations`
    /// reweighted global steps with flip-free line search, stopping at a
    /// relative decrease below `options.tolerance` or at a numerical failure
    /// (keeping the last iterate). Leaves `x` unchanged when it is not
    /// fold-free. Every iterate is fold-free and feasible. `progress(i)` is
    /// called before iteration `i` (0-based).
    pub(super) fn refine(&mut self, x: &mut [f64], options: &RefineOptions, progress: &mut dyn FnMut(usize)) -> RefineStats {
        let psi = Density { mu: options.barrier, eps: options.smoothing };
        let mut e = energy(self.elements, x, &psi);
        let mut stats = RefineStats { iterations: 0, energy_start: e, energy: e };
        if !e.is_finite() || x.len() != self.n {
            return stats;
        }
        let nf = self.elements.len();
        let mut trial = x.to_vec();
        let mut history = vec![e];
        let mut stale_failed = true;
        for iteration in 0..options.max_iterations {
            // The proxy matrix changes slowly: steps in between refactorizations
            // reuse the last factor (still a descent direction, as the matrix is
            // positive definite on the constraints' null space); a stale step
            // that brings no decrease is retried with a fresh factorization.
            let refresh = stale_failed || iteration % REFACTOR_EVERY == 0;
            progress(iteration);
            if e <= 0.0 {
                break;
            }
            // Local step: weights and rotations; assemble A(W) and -grad/2.
            let mut rhs = vec![0.0; self.n + self.kkt.m];
            let mut proxy_ok = true;
            for (f, el) in self.elements.iter().enumerate() {
                let j = el.jacobian(x);
                let Some((mm, rot, w_max)) = psi.proxy(j) else {
                    proxy_ok = false;
                    break;
                };
                if refresh {
                    // The matrix values: only a refactorization reads them.
                    let base = PER_FACE * f;
                    let mut s = 0;
                    for_pairs_full(|_, k, k2| {
                        self.values[base + s] = el.area * w_max * (el.g[k][0] * el.g[k2][0] + el.g[k][1] * el.g[k2][1]);
                        s += 1;
                    });
                }
                // r = M (R - J), per frame direction d; rhs_(c,k) += A sum_d g_k[d] r[c][d].
                let mut r = [[0.0; 2]; 2];
                for c in 0..2 {
                    for d in 0..2 {
                        r[c][d] = (0..2).map(|c2| mm[c][c2] * (rot[c2][d] - j[c2][d])).sum();
                    }
                }
                for k in 0..3 {
                    for c in 0..2 {
                        rhs[el.x[c][k]] += el.area * (el.g[k][0] * r[c][0] + el.g[k][1] * r[c][1]);
                    }
                }
            }
            if !proxy_ok {
                break;
            }
            debug_assert_eq!(self.values.len(), PER_FACE * nf + self.constraints.len());
            // Global step: the step d (C d = 0) minimising the proxy. A
            // numerical failure ends the refinement at the current iterate.
            let Some(d) = self.step(&rhs, refresh) else {
                if refresh {
                    break;
                }
                stale_failed = true;
                continue;
            };
            // Line search: largest flip-free step, halved until E decreases.
            let mut t = 1.0f64;
            for el in self.elements {
                let p = el.unknowns_uv(x);
                let q = el.unknowns_uv(&d);
                t = t.min(0.8 * max_step(p, q));
            }
            let mut accepted = None;
            for _ in 0..40 {
                if !(t > 0.0) {
                    break;
                }
                for i in 0..self.n {
                    trial[i] = x[i] + t * d[i];
                }
                let et = energy(self.elements, &trial, &psi);
                if et < e {
                    accepted = Some(et);
                    break;
                }
                t *= 0.5;
            }
            let Some(et) = accepted else {
                if refresh {
                    break;
                }
                stale_failed = true;
                continue;
            };
            stale_failed = false;
            x.copy_from_slice(&trial);
            stats.iterations += 1;
            e = et;
            history.push(e);
            if history.len() > STALL_WINDOW {
                let before = history[history.len() - 1 - STALL_WINDOW];
                if (before - e) / before < options.tolerance * STALL_WINDOW as f64 {
                    break;
                }
            }
        }
        stats.energy = e;
        stats
    }

    /// Solves for the step `d` (primal part, pushed onto `C d = 0`), after
    /// refactorizing with the current values if `refresh`; `None` on any
    /// numerical failure.
    fn step(&mut self, rhs: &[f64], refresh: bool) -> Option<Vec<f64>> {
        if refresh {
            self.kkt.pattern.fill_values_with_slots(&self.slots, &self.values, &mut self.kkt.values).ok()?;
            self.solver.factorize(&self.kkt.values).ok()?;
        }
        // A descent direction needs no refinement; only C d = 0 must hold,
        // which the projection restores (the regularized factor's solve is
        // off by ~1e-8 of the step).
        let sol = self.solver.solve_unrefined(rhs).ok()?;
        let mut d = sol[..self.n].to_vec();
        (d.iter().all(|v| v.is_finite()) && self.projector.project(&mut d, FEASIBILITY_TOLERANCE, FEASIBILITY_PASSES)).then_some(d)
    }
}

/// Matrix entries per face: the 3×3 stiffness block of u and that of v.
const PER_FACE: usize = 18;

/// Calls `f(c, k, k2)` for the [`PER_FACE`] pairs (component, corner, corner) of a face, in a fixed order.
fn for_pairs_full(mut f: impl FnMut(usize, usize, usize)) {
    for c in 0..2 {
        for k in 0..3 {
            for k2 in 0..3 {
                f(c, k, k2);
            }
        }
    }
}

/// Calls `f(i, j)` with the unknowns of the pairs of [`for_pairs_full`], same order.
fn for_pairs(el: &Element, mut f: impl FnMut(usize, usize)) {
    for_pairs_full(|c, k, k2| f(el.x[c][k], el.x[c][k2]));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::grid;
    use crate::mesh::TriMesh;

    /// A flat `n × n` grid on [0, 1]² as a constrained problem: one (u, v)
    /// unknown pair per vertex, the corner (0, 0) pinned at the origin, and
    /// the left side glued to the bottom side by a quarter-turn seam
    /// transition (B.2) as at a cone: `f(0, y) = Rot(pi/2) f(y, 0)`. The
    /// identity is feasible with `E = 0`.
    fn quarter_turn_problem(n: usize) -> (TriMesh, Vec<Element>, Vec<Triplet>, usize) {
        let mesh = grid(n, n, |x, y| [x, y, 0.0]);
        let nv = mesh.n_vertices();
        let elements = (0..mesh.n_faces() as u32)
            .map(|f| {
                let (q, area) = super::super::element::local_triangle(&mesh, f);
                let w = mesh.faces()[f as usize].map(|v| v as usize);
                Element::new(q, area, w, [w, w.map(|i| nv + i)])
            })
            .collect();
        let on = |pred: &dyn Fn([f64; 3]) -> bool, key: usize| {
            let mut v: Vec<usize> = (0..nv).filter(|&i| pred(mesh.positions()[i])).collect();
            v.sort_by(|&a, &b| mesh.positions()[a][key].total_cmp(&mesh.positions()[b][key]));
            v
        };
        let left = on(&|p| p[0].abs() < 1e-12, 1);
        let bottom = on(&|p| p[1].abs() < 1e-12, 0);
        assert_eq!(left[0], bottom[0]);
        let (u, v) = (|i: usize| i, |i: usize| nv + i);
        let mut c = vec![(0, u(left[0]), 1.0), (1, v(left[0]), 1.0)];
        let mut row = 2;
        for j in 1..left.len() {
            let (a0, a1, b0, b1) = (left[j - 1], left[j], bottom[j - 1], bottom[j]);
            // Δf(a) = Rot90 Δf(b): Δu_a = -Δv_b, Δv_a = Δu_b.
            c.extend([(row, u(a1), 1.0), (row, u(a0), -1.0), (row, v(b1), 1.0), (row, v(b0), -1.0)]);
            c.extend([(row + 1, v(a1), 1.0), (row + 1, v(a0), -1.0), (row + 1, u(b1), -1.0), (row + 1, u(b0), 1.0)]);
            row += 2;
        }
        (mesh, elements, c, row)
    }

    fn residual(c: &[Triplet], m: usize, x: &[f64]) -> f64 {
        crate::linalg::constraint_values(c, m, x).iter().fold(0.0f64, |a, b| a.max(b.abs()))
    }

    fn min_area(elements: &[Element], x: &[f64]) -> f64 {
        elements
            .iter()
            .map(|el| {
                let p = el.unknowns_uv(x);
                (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn refinement_of_a_distorted_fold_free_map() {
        let (mesh, elements, c, m) = quarter_turn_problem(8);
        let nv = mesh.n_vertices();
        // Start: p -> p / (1 + 3 (x + y)), fold-free (det > 0), feasible, badly distorted.
        let mut x = vec![0.0; 2 * nv];
        for (i, p) in mesh.positions().iter().enumerate() {
            let s = 1.0 / (1.0 + 3.0 * (p[0] + p[1]));
            x[i] = p[0] * s;
            x[nv + i] = p[1] * s;
        }
        assert!(residual(&c, m, &x) < 1e-15 && min_area(&elements, &x) > 0.0);
        let projector = NullSpaceProjector::new(&c, 2 * nv, m).unwrap();
        let mut refiner = Refiner::new(&elements, 2 * nv, &c, m, &projector).unwrap();
        let options = RefineOptions::default();
        let stats = refiner.refine(&mut x, &options, &mut |_| {});
        assert!(stats.iterations > 0 && stats.iterations <= options.max_iterations);
        assert!(stats.energy < 1e-3 * stats.energy_start, "{stats:?}");
        assert!((energy(&elements, &x, &Density { mu: options.barrier, eps: options.smoothing }) - stats.energy).abs() < 1e-12);
        assert!(min_area(&elements, &x) > 0.0, "flipped triangle");
        assert!(residual(&c, m, &x) < 1e-13, "constraint residual {}", residual(&c, m, &x));
        // Converges to the identity (the only zero-energy feasible map).
        let err = mesh.positions().iter().enumerate().map(|(i, p)| (x[i] - p[0]).hypot(x[nv + i] - p[1])).fold(0.0, f64::max);
        assert!(err < 0.05, "distance to the identity {err}");
    }

    #[test]
    fn refinement_with_a_large_barrier_and_smoothing() {
        let (mesh, elements, c, m) = quarter_turn_problem(6);
        let nv = mesh.n_vertices();
        // Start: a shear-free squash towards the pinned corner, x -> x^2-ish (fold-free).
        let mut x = vec![0.0; 2 * nv];
        for (i, p) in mesh.positions().iter().enumerate() {
            let s = 0.2 + 0.8 * (p[0] + p[1]) / 2.0;
            x[i] = p[0] * s;
            x[nv + i] = p[1] * s;
        }
        assert!(min_area(&elements, &x) > 0.0);
        for options in [
            RefineOptions { barrier: 1.0, ..RefineOptions::default() },
            RefineOptions { smoothing: 0.3, ..RefineOptions::default() },
        ] {
            let mut y = x.clone();
            let projector = NullSpaceProjector::new(&c, 2 * nv, m).unwrap();
            let mut refiner = Refiner::new(&elements, 2 * nv, &c, m, &projector).unwrap();
            let stats = refiner.refine(&mut y, &options, &mut |_| {});
            assert!(stats.energy < 0.5 * stats.energy_start, "{options:?}: {stats:?}");
            assert!(min_area(&elements, &y) > 0.0 && residual(&c, m, &y) < 1e-13);
        }
    }

    #[test]
    fn folded_start_is_left_alone() {
        let (mesh, elements, c, m) = quarter_turn_problem(4);
        let nv = mesh.n_vertices();
        // The zero map (feasible, every triangle degenerate): not a valid start.
        let mut x = vec![0.0; 2 * nv];
        let projector = NullSpaceProjector::new(&c, 2 * nv, m).unwrap();
        let mut refiner = Refiner::new(&elements, 2 * nv, &c, m, &projector).unwrap();
        let stats = refiner.refine(&mut x, &RefineOptions::default(), &mut |_| {});
        assert_eq!(stats.iterations, 0);
        assert_eq!(stats.energy_start, f64::INFINITY);
        assert!(x.iter().all(|&v| v == 0.0));
    }

    fn numeric_gradient(j: [[f64; 2]; 2], psi: &Density) -> [[f64; 2]; 2] {
        let h = 1e-6;
        let mut g = [[0.0; 2]; 2];
        for a in 0..2 {
            for b in 0..2 {
                let (mut jp, mut jm) = (j, j);
                jp[a][b] += h;
                jm[a][b] -= h;
                g[a][b] = (psi.value(jp) - psi.value(jm)) / (2.0 * h);
            }
        }
        g
    }

    #[test]
    fn proxy_gradient_matches_the_energy() {
        for (j, mu, eps) in [
            ([[1.3, 0.4], [-0.2, 0.7]], 0.1, f64::INFINITY),
            ([[0.2, -0.05], [0.1, 0.3]], 1.0, 0.1),
            ([[2.0, 0.0], [0.0, 2.0]], 0.02, f64::INFINITY),
            ([[2.0, 0.1], [0.0, 1.5]], 0.02, 0.05),
            ([[0.0, -1.5], [0.4, 0.1]], 0.5, 1.0),
        ] {
            let psi = Density { mu, eps };
            let (m, r, w_max) = psi.proxy(j).unwrap();
            // M <= w_max I, with equality along the first eigenvector.
            let tr = m[0][0] + m[1][1];
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            assert!((w_max - 0.5 * (tr + (tr * tr - 4.0 * det).max(0.0).sqrt())).abs() < 1e-9 * w_max);
            let num = numeric_gradient(j, &psi);
            for a in 0..2 {
                for b in 0..2 {
                    let g: f64 = 2.0 * (0..2).map(|c| m[a][c] * (j[c][b] - r[c][b])).sum::<f64>();
                    assert!((g - num[a][b]).abs() < 1e-5 * (1.0 + g.abs()), "{j:?}: {g} vs {}", num[a][b]);
                }
            }
        }
        let psi = Density { mu: 0.1, eps: 0.1 };
        assert_eq!(psi.value([[1.0, 0.0], [0.0, -1.0]]), f64::INFINITY);
        assert!(psi.value([[0.6, -0.8], [0.8, 0.6]]).abs() < 1e-14);
    }

    #[test]
    fn max_step_is_the_first_degeneracy() {
        let p = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // Apex moves straight down: degenerate at t = 1.
        let t = max_step(p, [[0.0, 0.0], [0.0, 0.0], [0.0, -1.0]]);
        assert!((t - 1.0).abs() < 1e-14);
        // Rigid motion never degenerates.
        assert_eq!(max_step(p, [[1.0, 2.0], [1.0, 2.0], [1.0, 2.0]]), f64::INFINITY);
        // Quadratic case: corner 1 moves to (1,0)+t(-2,1), corner 2 to (0,1)+t(1,-2).
        let q = [[0.0, 0.0], [-2.0, 1.0], [1.0, -2.0]];
        let t = max_step(p, q);
        let s = |t: f64| {
            let (a, b) = ([1.0 - 2.0 * t, t], [t, 1.0 - 2.0 * t]);
            a[0] * b[1] - a[1] * b[0]
        };
        assert!(t > 0.0 && s(t).abs() < 1e-12 && s(0.5 * t) > 0.0, "t = {t}");
    }
}
