//! The fit of a rounding: the least-squares closest map to the seamless
//! map's Jacobians under the rounded forms, `min sum_f w_f A_f |J_f - J_f^0 / s|^2`,
//! its weights (uniform, stiffer around singular points, graded), and the
//! KKT system it is solved on with one factorization per batch of forms
//! ([`RoundedSystem`]).

use super::super::element::{Element, NearWedges};
use super::super::seamless::{self, stiffness_triplets};
use super::super::separation::HeldApart;
use super::super::ParamError;
use super::{QuantizeError, Quantizer};
use crate::linalg::{constraint_values, independent_rows, FactorOptions, Kkt, LdltSolver, LinalgError, NullSpaceProjector, Triplet};
use std::cell::{OnceCell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

/// Radius (grid units) of the stiff faces around a singular point.
const STIFF_RADIUS: f64 = 1.0;
/// The graded fit ([`Quantizer::graded_fit`]): its weight `1 + (rho / r)^2`
/// at distance `r` (grid units) from a singular point, `rho` =
/// [`GRADED_RADIUS`], on the faces within [`GRADED_REACH`] of one, capped
/// at [`MAX_GRADED_WEIGHT`] (a face around the point itself, `r` ~ 0).
const GRADED_RADIUS: f64 = 1.0;
const GRADED_REACH: f64 = 3.0;
const MAX_GRADED_WEIGHT: f64 = 1e4;
/// Relative residual of every solve.
const SOLVE_TOLERANCE: f64 = 1e-12;
/// Relative residual at which a solve whose refinement stagnates is taken
/// as it is. These KKTs reach 4-7e-12 in floating point, about
/// [`SOLVE_TOLERANCE`]; finishing such solves by GMRES took 3-7 triangular
/// solves each where one or two do.
const STALL_ACCEPT: f64 = 1e-10;
/// Relative residual of the untangler's preconditioner solves: they only
/// shape the L-BFGS steps, and refining them to 1e-8 made a bad map's
/// quantization 2.5x slower (plate with five holes at 3 000 quads: 101 s
/// against 41 s, the same defects).
const PRECONDITION_TOLERANCE: f64 = 1e-4;
/// Most responses ([`RoundedSystem::response`]) solved in one batch
/// ([`Trials`]): in a batch a column costs about half what it costs alone
/// (cow at 1 000 quads: 1.2 ms alone, 0.63 ms each in a batch of 4, 0.56
/// in one of 16).
const MAX_RESPONSE_BATCH: usize = 8;
/// Most floats of responses a system keeps (64 MB); past it they are
/// dropped and solved again when asked for.
const MAX_KEPT_RESPONSE_FLOATS: usize = 1 << 23;

impl Quantizer {
    /// Faces within [`STIFF_RADIUS`] grid units (in the seamless map `x0`,
    /// grid units) of a singular point, reached through faces of its chart:
    /// a rounded point drags a fit of uniform weight along as a spike (a
    /// harmonic displacement from one point decays within a ring), which
    /// folds its ring or winds the map around a neighbour when the point
    /// moves by more than the ring is wide; stiffer faces around it carry
    /// the ring along and leave the distortion to the regular faces beyond.
    pub(super) fn stiff_faces(&self, x0: &[f64]) -> Vec<bool> {
        let mut stiff = vec![false; self.elements.len()];
        self.walk_singular_points(x0, STIFF_RADIUS, |f, _| stiff[f] = true);
        stiff
    }

    /// Calls `visit(f, p)` for every face around the wedges reached from
    /// each singular point `p` (a wedge both of whose coordinates are
    /// forms) through wedges of its chart within `radius` grid units of it
    /// in the seamless map `x0` (grid units).
    pub(super) fn walk_singular_points(&self, x0: &[f64], radius: f64, mut visit: impl FnMut(usize, [f64; 2])) {
        let n_wedges = self.vars[0].len();
        let mut near = NearWedges::new(&self.elements, n_wedges);
        for c in (0..n_wedges).filter(|&w| (0..2).all(|k| self.form_of[self.vars[k][w]] != usize::MAX)) {
            let p = [x0[self.vars[0][c]], x0[self.vars[1][c]]];
            near.walk(&self.elements, x0, c, p, radius, |f| visit(f, p));
        }
    }

    /// The graded fit for the seamless map `x0` (grid units): weight
    /// `1 + (rho / r)^2` on a face at distance `r` from the nearest
    /// singular point of its chart ([`GRADED_RADIUS`], [`GRADED_REACH`]).
    /// With uniform weights, the displacement `d` of a rounded point decays
    /// like `log r` (the fit's Green's function), and its slope at the
    /// point's first ring, `d / (h log(R / h))` for edges of length `h`,
    /// grows as the mesh gets finer than the grid until the ring folds or
    /// winds; under these weights the radial solution has slope
    /// `2 d r / ((r^2 + rho^2) log(1 + R^2 / rho^2))`, flat at the point
    /// and at most `d / (rho log(1 + R^2 / rho^2))` whatever `h` (spot
    /// subdivided to 93 k faces, 1 000 quads: the plain fit winds around 51
    /// vertices, this one around 5, mended by the local stiffening).
    pub(super) fn graded_fit(&self, x0: &[f64]) -> Fit {
        let mut r = vec![f64::INFINITY; self.elements.len()];
        self.walk_singular_points(x0, GRADED_REACH * GRADED_RADIUS, |f, p| {
            let uv = self.elements[f].unknowns_uv(x0);
            let centroid = [0, 1].map(|k| (uv[0][k] + uv[1][k] + uv[2][k]) / 3.0);
            r[f] = r[f].min((centroid[0] - p[0]).hypot(centroid[1] - p[1]));
        });
        let weights: Vec<f64> = r.iter().map(|&r| 1.0 + (GRADED_RADIUS * GRADED_RADIUS / (r * r)).min(MAX_GRADED_WEIGHT)).collect();
        Fit { stiffness: stiffness_triplets(&self.elements, &weights), weights, stiff_weight: 1.0, graded: true }
    }

    /// The map closest to `targets` with fit weights `weights` under
    /// `system`'s rows, put back onto them by `system`: `kkt` (assembled on
    /// `system`'s rows) refilled and factored by `solver`, whose symbolic
    /// analysis is made on first use and kept.
    pub(super) fn weighted_solve(
        &self,
        kkt: &mut Kkt,
        solver: &mut Option<LdltSolver>,
        weights: &[f64],
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
    ) -> Result<Vec<f64>, QuantizeError> {
        kkt.refill(&stiffness_triplets(&self.elements, weights), &system.c)?;
        let solver = match solver {
            Some(solver) => {
                solver.factorize(&kkt.values)?;
                solver
            }
            None => solver.insert(factored(kkt)?),
        };
        system.onto_constraints(fit_solve(solver, self, weights, targets, &system.b)?)
    }

    /// Factors the KKT of the seam rows, the rounded forms `order` (their
    /// values in `values`), the gauge pins each component still needs
    /// (held at `x`'s values) and the separations `held` (`x_hi - x_lo =
    /// gap`, left out where the rows before determine them), and solves for the
    /// map closest to `targets`. Also returns the forms of `order` left out
    /// because the earlier rows determine them.
    pub(super) fn solve(
        &self,
        fit: &Fit,
        order: &[usize],
        values: &[Option<i64>],
        x: &[f64],
        targets: &[[[f64; 2]; 2]],
        held: &HeldApart,
    ) -> Result<(RoundedSystem, Vec<usize>), QuantizeError> {
        let mut rows = self.seam_rows.clone();
        let mut rhs_rows = vec![0.0; rows.len()];
        let mut responses = Vec::with_capacity(order.len() + 2 * self.pins.len());
        for &i in order {
            let form = &self.forms[i];
            rows.push(form.row.clone());
            rhs_rows.push(values[i].unwrap_or(0) as f64);
            responses.push(form.response.clone());
        }
        // The component translations the rounded forms do not fix are held
        // by pins: a pin is kept when its translation is independent of the
        // forms' responses and of the pins before it.
        responses.extend((0..2 * self.pins.len()).map(|t| vec![(t, 1)]));
        let free_translation = independent_rows(&responses, 2 * self.pins.len());
        for (t, _) in free_translation[order.len()..].iter().enumerate().filter(|(_, &free)| free) {
            let unknown = self.pins[t / 2][t % 2];
            rows.push(vec![(unknown, 1)]);
            rhs_rows.push(x[unknown]);
        }
        let n_held_from = rows.len();
        for (sep, &gap) in held.list.iter().zip(&held.gaps) {
            rows.push(vec![(sep.hi, 1), (sep.lo, -1)]);
            rhs_rows.push(gap as f64);
        }
        let keep = independent_rows(&rows, self.n_unknowns);
        let n_seam = self.seam_rows.len();
        let dependent = order
            .iter()
            .zip(&keep[n_seam..])
            .filter(|(_, &k)| !k)
            .map(|(&i, _)| i)
            .collect();
        let mut c = Vec::new();
        let mut b = Vec::new();
        let (mut form_rows, mut held_rows) = (Vec::new(), Vec::new());
        for (r, ((row, k), v)) in rows.iter().zip(keep).zip(rhs_rows).enumerate() {
            if k {
                if (n_seam..n_seam + order.len()).contains(&r) {
                    form_rows.push((order[r - n_seam], b.len()));
                }
                if r >= n_held_from {
                    held_rows.push((r - n_held_from, b.len()));
                }
                c.extend(row.iter().map(|&(i, a)| (b.len(), i, a as f64)));
                b.push(v);
            }
        }
        let kkt = Kkt::assemble(&fit.stiffness, self.n_unknowns, &c, b.len())?;
        let solver = factored(&kkt)?;
        let mut system = RoundedSystem {
            weights: fit.weights.clone(),
            solver,
            uniform: OnceCell::new(),
            c,
            b,
            form_rows,
            held_rows,
            n: self.n_unknowns,
            x: Vec::new(),
            responses: RefCell::default(),
        };
        system.x = system.resolve(self, targets)?;
        Ok((system, dependent))
    }

    /// Area-weighted mean of `|J_f - T_f|^2` over the faces (the fit's
    /// objective with uniform weights), to compare maps of one grid size.
    pub(super) fn fit_distortion(&self, x: &[f64], targets: &[[[f64; 2]; 2]]) -> f64 {
        let (mut sum, mut area) = (0.0, 0.0);
        for (el, t) in self.elements.iter().zip(targets) {
            sum += fit_error(el, x, t);
            area += el.area;
        }
        sum / area
    }
}

/// The least-squares fit of the rounded map to the seamless map's
/// Jacobians, `min sum_f w_f A_f |J_f - J_f^0 / s|^2`: per-face weights and
/// the stiffness they give.
pub(super) struct Fit {
    pub(super) weights: Vec<f64>,
    pub(super) stiffness: Vec<Triplet>,
    /// Weight of the stiff faces (1: none stiffer).
    pub(super) stiff_weight: f64,
    /// Weights graded towards the singular points ([`Quantizer::graded_fit`]).
    pub(super) graded: bool,
}

impl Fit {
    /// Weight `stiff_weight` on the faces `stiff`, 1 elsewhere.
    pub(super) fn new(elements: &[Element], stiff: &[bool], stiff_weight: f64) -> Fit {
        let weights: Vec<f64> = stiff.iter().map(|&b| if b { stiff_weight } else { 1.0 }).collect();
        let stiffness = stiffness_triplets(elements, &weights);
        Fit { weights, stiffness, stiff_weight, graded: false }
    }
}

/// A factored KKT of [`Quantizer::solve`] and its constraint values.
pub(super) struct RoundedSystem {
    /// Per face: the weight of its Jacobian fit ([`Fit`]).
    pub(super) weights: Vec<f64>,
    pub(super) solver: LdltSolver,
    /// [`Self::untangle_solver`] of a stiffer fit, once factored.
    pub(super) uniform: OnceCell<LdltSolver>,
    pub(super) c: Vec<Triplet>,
    pub(super) b: Vec<f64>,
    /// The rows of `c` that are rounded forms: (form, row).
    pub(super) form_rows: Vec<(usize, usize)>,
    /// The rows of `c` that are held separations: (index in [`HeldApart`], row).
    pub(super) held_rows: Vec<(usize, usize)>,
    pub(super) n: usize,
    pub(super) x: Vec<f64>,
    /// The responses solved so far, by row ([`Self::response`]).
    responses: RefCell<HashMap<usize, Rc<[f64]>>>,
}

impl RoundedSystem {
    /// The factored KKT the untangler is preconditioned with. Its energy
    /// weighs every face alike, and so must its preconditioner: with a
    /// stiffer fit's KKT its steps near singular points came out 10-100
    /// times too short (fandisk >60 at 1 500 quads: 17 s -> 12 s, the same
    /// map). This system's own where its fit is uniform; else the same rows
    /// with uniform weights, factored on first use and kept (it depends on
    /// the rows `c`, which [`Quantizer::uncollapse`] leaves, not on `b`).
    pub(super) fn untangle_solver(&self, q: &Quantizer) -> Result<&LdltSolver, QuantizeError> {
        if self.weights.iter().all(|&w| w == 1.0) {
            return Ok(&self.solver);
        }
        if self.uniform.get().is_none() {
            let stiffness = stiffness_triplets(&q.elements, &vec![1.0; q.elements.len()]);
            let solver = factored(&Kkt::assemble(&stiffness, q.n_unknowns, &self.c, self.b.len())?)?;
            let _ = self.uniform.set(solver);
        }
        Ok(self.uniform.get().expect("set above"))
    }

    /// Per row of `c`: the change of the linear form `row` of the solution
    /// per unit change of that row's value (the multipliers of `K⁻¹ [row; 0]`,
    /// `K` symmetric).
    pub(super) fn sensitivity(&self, row: &[(usize, i64)]) -> Result<Vec<f64>, QuantizeError> {
        Ok(self.sensitivities(&[row])?.pop().unwrap_or_default())
    }

    /// [`Self::sensitivity`] of each of `rows`, solved together (one pass
    /// over the factor for all of them).
    pub(super) fn sensitivities<R: AsRef<[(usize, i64)]>>(&self, rows: &[R]) -> Result<Vec<Vec<f64>>, QuantizeError> {
        let dim = self.n + self.b.len();
        let mut rhs = vec![0.0; dim * rows.len()];
        for (column, row) in rhs.chunks_mut(dim).zip(rows) {
            for &(i, a) in row.as_ref() {
                column[i] += a as f64;
            }
        }
        let z = self.solver.solve_many_to(&rhs, rows.len(), SOLVE_TOLERANCE)?.0;
        Ok(z.chunks(dim).map(|column| column[self.n..].to_vec()).collect())
    }

    /// `x` moved back onto the rows `C x = b` by the smallest change in the
    /// stiffness norm (one solve for `(0, b - C x)`).
    pub(super) fn onto_constraints(&self, mut x: Vec<f64>) -> Result<Vec<f64>, QuantizeError> {
        let mut rhs = vec![0.0; self.n];
        let cx = constraint_values(&self.c, self.b.len(), &x);
        rhs.extend(self.b.iter().zip(&cx).map(|(b, v)| b - v));
        let dx = self.solver.solve_many_to(&rhs, 1, SOLVE_TOLERANCE)?.0;
        x.iter_mut().zip(&dx).for_each(|(v, d)| *v += d);
        Ok(x)
    }

    /// The map closest to per-face target Jacobians `targets` under this system's rows.
    pub(super) fn resolve(&self, q: &Quantizer, targets: &[[[f64; 2]; 2]]) -> Result<Vec<f64>, QuantizeError> {
        fit_solve(&self.solver, q, &self.weights, targets, &self.b)
    }

    /// The map with the value of row `row` moved by `step` (a trial move;
    /// the system is unchanged): the fit is linear in `b`, so it is
    /// `x + step * response(row)`, no solve where the response is kept.
    pub(super) fn resolve_moved(&self, row: usize, step: i64) -> Result<Vec<f64>, QuantizeError> {
        let response = self.response(row)?;
        Ok(self.x.iter().zip(response.iter()).map(|(x, d)| x + step as f64 * d).collect())
    }

    /// The map's change per unit change of row `row`'s value, the first `n`
    /// entries of `K⁻¹ e_(n + row)`: solved on first use and kept (it
    /// depends on the factorization, not on `b`).
    pub(super) fn response(&self, row: usize) -> Result<Rc<[f64]>, QuantizeError> {
        self.solve_responses(&[row])?;
        Ok(self.responses.borrow()[&row].clone())
    }

    /// Solves the responses of those of `rows` not kept yet, in one
    /// multi-column solve, and keeps them.
    fn solve_responses(&self, rows: &[usize]) -> Result<(), QuantizeError> {
        let mut missing: Vec<usize> = rows.iter().copied().filter(|r| !self.responses.borrow().contains_key(r)).collect();
        missing.sort_unstable();
        missing.dedup();
        if missing.is_empty() {
            return Ok(());
        }
        let dim = self.n + self.b.len();
        let mut rhs = vec![0.0; dim * missing.len()];
        for (column, &row) in rhs.chunks_mut(dim).zip(&missing) {
            column[self.n + row] = 1.0;
        }
        let z = self.solver.solve_many_to(&rhs, missing.len(), SOLVE_TOLERANCE)?.0;
        let mut responses = self.responses.borrow_mut();
        if (responses.len() + missing.len()) * self.n > MAX_KEPT_RESPONSE_FLOATS {
            responses.clear();
        }
        for (column, row) in z.chunks(dim).zip(missing) {
            responses.insert(row, column[..self.n].into());
        }
        Ok(())
    }

    /// Keeps a trial move: row `row`'s value moved by `step`, and the map
    /// solved afresh for `targets` (one solve; a kept map is never the sum
    /// of a trial's, whose rounding errors would pile up move after move).
    pub(super) fn take_move(&mut self, q: &Quantizer, targets: &[[[f64; 2]; 2]], row: usize, step: i64) -> Result<(), QuantizeError> {
        self.b[row] += step as f64;
        self.x = self.resolve(q, targets)?;
        Ok(())
    }
}

/// The trial moves of one search, in the order they may be tried: the rows
/// they move, whose responses ([`RoundedSystem::response`]) are solved
/// ahead in batches that grow from one (the first trial is often kept) to
/// [`MAX_RESPONSE_BATCH`].
pub(super) struct Trials {
    rows: Vec<usize>,
    batch: usize,
}

impl Trials {
    /// Trials of moves of `rows`, in this order.
    pub(super) fn new(rows: impl IntoIterator<Item = usize>) -> Trials {
        Trials { rows: rows.into_iter().collect(), batch: 1 }
    }

    /// [`RoundedSystem::resolve_moved`] of the `i`-th trial's row moved by
    /// `step`; where its response is not kept, it is solved with those of
    /// the next rows, the batch twice as large as the one before.
    pub(super) fn resolve_moved(&mut self, system: &RoundedSystem, i: usize, step: i64) -> Result<Vec<f64>, QuantizeError> {
        let row = self.rows[i];
        if !system.responses.borrow().contains_key(&row) {
            let mut ahead: Vec<usize> = Vec::with_capacity(self.batch);
            for &r in &self.rows[i..] {
                if ahead.len() == self.batch {
                    break;
                }
                if !ahead.contains(&r) && !system.responses.borrow().contains_key(&r) {
                    ahead.push(r);
                }
            }
            system.solve_responses(&ahead)?;
            self.batch = (2 * self.batch).min(MAX_RESPONSE_BATCH);
        }
        system.resolve_moved(row, step)
    }
}

/// The map closest to per-face target Jacobians `targets` with face weights
/// `weights`, under the rows of `solver` (a factored KKT of that fit) with
/// values `b`.
pub(super) fn fit_solve(solver: &LdltSolver, q: &Quantizer, weights: &[f64], targets: &[[[f64; 2]; 2]], b: &[f64]) -> Result<Vec<f64>, QuantizeError> {
    let mut rhs = vec![0.0; q.n_unknowns];
    for ((el, t), w) in q.elements.iter().zip(targets).zip(weights) {
        for k in 0..3 {
            let g = el.g[k];
            for c in 0..2 {
                rhs[el.x[c][k]] += w * el.area * (g[0] * t[c][0] + g[1] * t[c][1]);
            }
        }
    }
    rhs.extend_from_slice(b);
    let x = solver.solve_many_to(&rhs, 1, SOLVE_TOLERANCE)?.0;
    if x.iter().any(|v| !v.is_finite()) {
        return Err(QuantizeError::Param(ParamError::NotFinite {
            what: "quantized map",
        }));
    }
    Ok(x[..q.n_unknowns].to_vec())
}

/// `q <- Z (Zᵀ A Z)⁻¹ Zᵀ q` (the untangler's preconditioner): the solve
/// for `(q, 0)` with `solver`, a factored KKT of `n_rows` rows `C` (on the
/// `q.len()` unknowns) and some SPD `A`, put back onto `C q = 0` by
/// `projector`; 0 when it fails.
pub(super) fn precondition(solver: &LdltSolver, n_rows: usize, q: &mut [f64], projector: Option<&NullSpaceProjector>) {
    let n = q.len();
    let mut rhs = q.to_vec();
    rhs.resize(n + n_rows, 0.0);
    match solver.solve_many_to(&rhs, 1, PRECONDITION_TOLERANCE) {
        Ok((x, _)) => q.copy_from_slice(&x[..n]),
        Err(_) => q.iter_mut().for_each(|v| *v = 0.0),
    }
    if let Some(projector) = projector {
        projector.project(q, 1e-14, 3);
    }
}

/// [`seamless::factored`] with solves that stop where they stagnate below
/// [`STALL_ACCEPT`].
pub(super) fn factored(kkt: &Kkt) -> Result<LdltSolver, LinalgError> {
    let mut solver = seamless::factored(kkt)?;
    solver.set_options(FactorOptions { stall_accept: STALL_ACCEPT, ..solver.options() });
    Ok(solver)
}

/// `A_f |J_f - T_f|^2`: the fit's error of element `el` in `x` against the target Jacobian `t`.
pub(super) fn fit_error(el: &Element, x: &[f64], t: &[[f64; 2]; 2]) -> f64 {
    let j = el.jacobian(x);
    el.area * (0..2).flat_map(|r| (0..2).map(move |c| (r, c))).map(|(r, c)| (j[r][c] - t[r][c]).powi(2)).sum::<f64>()
}
