//! Seamless parametrization (Appendix B.2): linear elements with (u, v) per
//! wedge of the cut disk; the Poisson problem (23) `min sum_f A_f |grad f - R_f|^2`
//! under the seam, isoline and pin constraints, enforced exactly through one
//! KKT system; ARAP local/global iterations (eq. 4, Liu et al. 2008) that
//! reuse its factorization; then, when ARAP folds, a repair by local
//! reweighting that finds a fold-free map, and finally the injective
//! refinement of [`super::injective`] (ARAP + barrier, same constraints)
//! from the best fold-free map, which pulls the distortion back down.

use super::cut_graph::CutGraph;
use super::field::{CrossField, NO_ISOLINE};
use super::injective::{RefineOptions, Refiner};
use super::untangle::untangle;
use super::element::{angle_sums, local_triangle, signed_uv_area, Element};
use super::metrics::{self, interior_cone_angles};
use super::{ParamCounts, ParamError, ParamOptions, ParamProgress, ParamTimings};
use crate::clock::Stopwatch;
use crate::cones::ConePlacement;
use crate::linalg::{constraint_values, independent_rows, Kkt, LdltSolver, NullSpaceProjector, LinalgError, FactorOptions, Triplet};
use crate::mesh::{TriMesh, UnionFind};

/// Repair rounds tried without lowering the number of folds before giving up.
const REPAIR_PATIENCE: usize = 16;

/// The repair has diverged (it spreads folds instead of removing them) once a
/// round leaves more than this many times the fewest folds seen (at least
/// [`REPAIR_DIVERGENCE_FLOOR`] of them); its later rounds only grow costlier
/// as the weights grow (a 100 k-face torus knot: 224 -> 589 -> 1 862 ->
/// 29 624 folds over 16 rounds and 110 s before this stop).
const REPAIR_DIVERGENCE: usize = 4;
const REPAIR_DIVERGENCE_FLOOR: usize = 25;

/// Relative residual of the Poisson solve (23).
const POISSON_TOLERANCE: f64 = 1e-12;

/// Relative residual of an ARAP global step: a local/global iteration is
/// itself approximate, and the first solve with the factor usually reaches
/// this (one solve instead of two with refinement to 1e-12).
const ARAP_TOLERANCE: f64 = 1e-5;

/// `max |C x| / max |x|` every solve is projected down to.
const CONSTRAINT_TOLERANCE: f64 = 1e-14;

/// Result of [`seamless_map`]: UV per wedge.
#[derive(Clone, Debug)]
pub struct SeamlessResult {
    pub uv: Vec<[f64; 2]>,
    /// Iterations and folds of ARAP, the repair, the untangling and the refinement.
    pub counts: ParamCounts,
    /// Cones the map realizes with another index than placed: `(cut
    /// vertex, k)` ([`ConePlacement::realize`]).
    pub realized: Vec<(u32, i32)>,
    /// Final ARAP energy `sum_f A_f |J_f - R_f|^2`.
    pub energy: f64,
}

/// The constrained system on the shared unknowns of [`unknowns`].
struct System {
    elements: Vec<Element>,
    n_wedges: usize,
    n_unknowns: usize,
    vars: [Vec<usize>; 2],
    constraints: Vec<Triplet>,
    n_rows: usize,
    kkt: Kkt,
    /// The factorization; released (`None`) before the injective refinement,
    /// which factors a system of its own.
    solver: Option<LdltSolver>,
    /// Puts inexact solves back onto the constraints; `None` when `C Cᵀ`
    /// could not be factored (every solve is then refined to full accuracy).
    projector: Option<NullSpaceProjector>,
}

impl System {
    /// The factorization ([`LinalgError::NotFactorized`] once released).
    fn solver(&self) -> Result<&LdltSolver, ParamError> {
        self.solver.as_ref().ok_or(ParamError::Solve(LinalgError::NotFactorized))
    }

    /// Global step: solves (23) for the target rotations `r` (rows in the
    /// face frame) to the relative residual `tolerance`, then projects onto
    /// the constraints (to [`CONSTRAINT_TOLERANCE`] of the largest unknown).
    fn global_step(&self, weights: &[f64], r: &[[[f64; 2]; 2]], tolerance: f64) -> Result<Vec<[f64; 2]>, ParamError> {
        let mut rhs = vec![0.0; self.n_unknowns + self.n_rows];
        for ((el, &wt), rf) in self.elements.iter().zip(weights).zip(r) {
            for k in 0..3 {
                let g = el.g[k];
                for c in 0..2 {
                    rhs[el.x[c][k]] += wt * el.area * (g[0] * rf[c][0] + g[1] * rf[c][1]);
                }
            }
        }
        let tolerance = if self.projector.is_some() { tolerance } else { POISSON_TOLERANCE };
        let mut x = self.solver()?.solve_many_to(&rhs, 1, tolerance)?.0;
        // The constraints must hold exactly. An inexact solve of a badly
        // conditioned system (large repair weights) can be far off them:
        // then it is refined to full accuracy first.
        let scale = |x: &[f64]| x[..self.n_unknowns].iter().fold(1.0f64, |m, v| m.max(v.abs()));
        if tolerance > POISSON_TOLERANCE && self.constraint_residual(&x) > 1e-7 * scale(&x) {
            x = self.solver()?.solve_many_to(&rhs, 1, POISSON_TOLERANCE)?.0;
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(ParamError::NotFinite { what: "global solve" });
        }
        // An inexact solve is off the constraints by about its residual:
        // project back. The projector works on `C Cᵀ`, which does not depend
        // on the weights, so it stays exact where heavy repair weights make
        // the KKT badly scaled.
        if let Some(projector) = &self.projector {
            projector.project(&mut x[..self.n_unknowns], CONSTRAINT_TOLERANCE, 3);
        }
        let (worst, scale) = (self.constraint_residual(&x), scale(&x));
        if worst > 1e-7 * scale {
            return Err(ParamError::ConstraintViolation { residual: worst / scale });
        }
        Ok((0..self.n_wedges).map(|w| [x[self.vars[0][w]], x[self.vars[1][w]]]).collect())
    }

    /// `q <- Z (Zᵀ A Z)⁻¹ Zᵀ q` with the factored KKT (`A` its current
    /// stiffness, `Z` a basis of `C x = 0`): the KKT solve for right-hand
    /// side `(q, 0)`, to a relative residual of 1e-8, projected onto the
    /// constraints. Leaves `q` at 0 when the solve fails.
    fn precondition(&self, q: &mut [f64]) {
        let mut rhs = vec![0.0; self.n_unknowns + self.n_rows];
        rhs[..self.n_unknowns].copy_from_slice(q);
        let solved = self.solver().ok().and_then(|s| s.solve_many_to(&rhs, 1, 1e-8).ok());
        match solved {
            Some((x, ..)) => q.copy_from_slice(&x[..self.n_unknowns]),
            None => q.iter_mut().for_each(|v| *v = 0.0),
        }
        if let Some(projector) = &self.projector {
            projector.project(q, CONSTRAINT_TOLERANCE, 3);
        }
    }

    fn refactor(&mut self, weights: &[f64]) -> Result<(), ParamError> {
        let a = stiffness_triplets(&self.elements, weights);
        self.kkt.refill(&a, &self.constraints)?;
        let solver = self.solver.as_mut().ok_or(ParamError::Solve(LinalgError::NotFactorized))?;
        solver.factorize(&self.kkt.values)?;
        Ok(())
    }

    /// The unknown vector of wedge UVs `uv` (which must agree on shared unknowns).
    fn unknowns_of(&self, uv: &[[f64; 2]]) -> Vec<f64> {
        let mut x = vec![0.0; self.n_unknowns];
        for (w, p) in uv.iter().enumerate() {
            x[self.vars[0][w]] = p[0];
            x[self.vars[1][w]] = p[1];
        }
        x
    }

    /// Wedge UVs of the unknown vector `x`.
    fn wedges_of(&self, x: &[f64]) -> Vec<[f64; 2]> {
        (0..self.n_wedges).map(|w| [x[self.vars[0][w]], x[self.vars[1][w]]]).collect()
    }

    /// Largest `|C x|` over the constraint rows (all homogeneous).
    fn constraint_residual(&self, x: &[f64]) -> f64 {
        constraint_values(&self.constraints, self.n_rows, x).iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// Jacobian of face `f` for UV per wedge.
    fn jacobian(&self, f: usize, uv: &[[f64; 2]]) -> [[f64; 2]; 2] {
        self.elements[f].wedge_jacobian(uv)
    }
}

/// Upper triangle of the stiffness of (23) with per-face weights.
pub(super) fn stiffness_triplets(elements: &[Element], weights: &[f64]) -> Vec<Triplet> {
    let mut t = Vec::with_capacity(elements.len() * 18);
    for (el, &wt) in elements.iter().zip(weights) {
        for a in 0..3 {
            for b in 0..3 {
                // Stiffness of (23): A_f grad(phi_a) . grad(phi_b) (full
                // matrix given; the strictly lower half is ignored).
                let v = wt * el.area * (el.g[a][0] * el.g[b][0] + el.g[a][1] * el.g[b][1]);
                for c in 0..2 {
                    let (i, j) = (el.x[c][a], el.x[c][b]);
                    if i <= j {
                        t.push((i, j, v));
                    }
                }
            }
        }
    }
    t
}

/// The LDLᵀ of a seamless-map KKT, analysed and factorized. Small
/// regularization: the constraint pivots are exact zeros before their primal
/// neighbours are eliminated; a smaller delta refines faster here.
pub(super) fn factored(kkt: &Kkt) -> Result<LdltSolver, LinalgError> {
    let options = FactorOptions { delta: 1e-11, max_refinement_steps: 30, accept_residual: 1e-4, ..FactorOptions::default() };
    let mut solver = LdltSolver::with_options(&kkt.pattern, &kkt.signs, options)?;
    solver.factorize(&kkt.values)?;
    Ok(solver)
}

/// One linear element per face on the wedges of `cut` and unknowns `vars`.
pub(super) fn elements(mesh: &TriMesh, cut: &CutGraph, vars: &[Vec<usize>; 2]) -> Vec<Element> {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            let (q, area) = local_triangle(mesh, f);
            let c = 3 * f as usize;
            let w = [0, 1, 2].map(|k| cut.wedge[c + k] as usize);
            Element::new(q, area, w, [w.map(|i| vars[0][i]), w.map(|i| vars[1][i])])
        })
        .collect()
}

/// Closest rotation to `j` (Appendix B.2, local step): `B = ½[[a+d, b-c], [c-b, a+d]]`,
/// `R = B / sqrt(det B)`; `None` when `B` vanishes.
pub fn closest_rotation(j: [[f64; 2]; 2]) -> Option<[[f64; 2]; 2]> {
    let (a, b, c, d) = (j[0][0], j[0][1], j[1][0], j[1][1]);
    let (p, q) = (0.5 * (a + d), 0.5 * (b - c));
    let n = (p * p + q * q).sqrt();
    if n <= f64::MIN_POSITIVE || !n.is_finite() {
        return None;
    }
    Some([[p / n, q / n], [-q / n, p / n]])
}

fn frob2(j: [[f64; 2]; 2], r: [[f64; 2]; 2]) -> f64 {
    (0..2).flat_map(|a| (0..2).map(move |b| (a, b))).map(|(a, b)| (j[a][b] - r[a][b]).powi(2)).sum()
}

/// Faces whose UV triangle (per wedge) is flipped or degenerate.
fn flipped_faces(sys: &System, uv: &[[f64; 2]]) -> Vec<usize> {
    (0..sys.elements.len()).filter(|&f| !(signed_uv_area(sys.elements[f].uv(uv)) > 0.0)).collect()
}

/// The cones and boundary corners of a map with every triangle positive
/// whose angle sum differs from the placement's (`2 pi - k pi/2` inside,
/// `pi - k pi/2` on the cut mesh's boundary, i.e. features and boundaries):
/// `(cut vertex, k)` with the index the sum realizes. Inside, seam
/// transitions fix the angle up to multiples of 2 pi; on the boundary the
/// edges are only held on isolines, so the angle may differ by multiples
/// of pi/2 of the right parity (e.g. pi realized as 2 pi). Updates the
/// interior `cone_angle` (per mesh vertex) to match. With every triangle
/// positive the angle sums add up to `pi` per face, so the realized indices
/// keep the placement's sum (`4 chi` of the cut mesh).
fn realized_cones(placement: &ConePlacement, sys: &System, uv: &[[f64; 2]], cone_angle: &mut [f64]) -> Vec<(u32, i32)> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let cm = &placement.cut.mesh;
    let sums = angle_sums(cm.faces(), cm.n_vertices(), |f| sys.elements[f].uv(uv), false);
    let mut out = Vec::new();
    for (cv, &sum) in sums.iter().enumerate() {
        if placement.cut.touches_free(cv as u32) {
            continue; // a free boundary vertex has no prescribed angle
        }
        let boundary = cm.is_boundary_vertex(cv as u32);
        let full = if boundary { PI } else { 2.0 * PI };
        let k = ((full - sum) / FRAC_PI_2).round() as i32;
        if k != placement.k[cv] {
            out.push((cv as u32, k));
            if !boundary {
                cone_angle[placement.cut.original_vertex[cv] as usize] = full - k as f64 * FRAC_PI_2;
            }
        }
    }
    out
}

/// Flipped faces plus the faces around interior vertices whose UV angle sum
/// is off their cone angle by more than pi: the map winds around such a
/// vertex more than once although no triangle is flipped.
fn folded_faces(mesh: &TriMesh, sys: &System, uv: &[[f64; 2]], cone_angle: &[f64]) -> Vec<usize> {
    let mut bad = flipped_faces(sys, uv);
    let sums = angle_sums(mesh.faces(), mesh.n_vertices(), |f| sys.elements[f].uv(uv), false);
    for v in 0..mesh.n_vertices() as u32 {
        let expected = cone_angle[v as usize];
        if expected.is_finite() && (sums[v as usize] - expected).abs() > std::f64::consts::PI {
            bad.extend(mesh.vertex_faces(v).map(|f| f as usize));
        }
    }
    bad.sort_unstable();
    bad.dedup();
    bad
}

impl System {
    /// Sets up the shared unknowns of `cut` ([`unknowns`]), one element per
    /// face, the constraint rows, and factors the KKT with unit weights (the
    /// system of Poisson (23) and ARAP).
    fn new(mesh: &TriMesh, field: &CrossField, cut: &CutGraph) -> Result<System, ParamError> {
        let nf = mesh.n_faces();
        let nw = cut.n_wedges;
        let (vars, n_unknowns) = unknowns(mesh, field, cut);
        let elements = elements(mesh, cut, &vars);

        let (constraints, n_rows) = constraint_rows(mesh, cut, &vars, n_unknowns);
        let a = stiffness_triplets(&elements, &vec![1.0; nf]);
        let kkt = Kkt::assemble(&a, n_unknowns, &constraints, n_rows)?;
        let solver = factored(&kkt)?;
        let projector = NullSpaceProjector::new(&constraints, n_unknowns, n_rows).ok();
        Ok(System { elements, n_wedges: nw, n_unknowns, vars, constraints, n_rows, kkt, solver: Some(solver), projector })
    }
}

/// Builds the constrained system, runs Poisson (23), ARAP, the repair (only
/// when ARAP folds) and the injective refinement.
///
/// Contract: returns UV per wedge of `cut` satisfying every constraint row
/// (seam transitions along each [`super::cut_graph::SeamCurve`], isolines,
/// one pin per disk component) to solver accuracy. The KKT matrix is
/// factored once for Poisson + ARAP; the repair refactors (same pattern);
/// the refinement has its own pattern, analysed once. When a
/// fold-free map (no flipped triangle, no wound vertex) is found the result
/// is fold-free and no worse by eq. (19) than that map.
#[allow(clippy::too_many_arguments)]
pub fn seamless_map(
    mesh: &TriMesh,
    placement: &ConePlacement,
    field: &CrossField,
    cut: &CutGraph,
    options: &ParamOptions,
    progress: &mut dyn FnMut(ParamProgress),
    clock: &mut Stopwatch,
    timings: &mut ParamTimings,
) -> Result<SeamlessResult, ParamError> {
    progress(ParamProgress::Poisson);
    let nf = mesh.n_faces();
    let mut sys = System::new(mesh, field, cut)?;
    let weights = vec![1.0; nf];

    // Poisson (23) with the field's target Jacobians (B.1).
    let mut r: Vec<[[f64; 2]; 2]> = (0..nf).map(|f| field.target(f)).collect();
    let mut uv = sys.global_step(&weights, &r, POISSON_TOLERANCE)?;
    let poisson_uv = uv.clone();
    timings.poisson = clock.lap();

    let fixed: Vec<bool> = (0..nf)
        .map(|f| options.fix_feature_rotations && (0..3).any(|k| field.isoline[3 * f + k] != NO_ISOLINE))
        .collect();
    let (iterations, energy) = arap(&sys, &weights, &fixed, &mut r, &mut uv, options, 0, progress)?;
    timings.arap = clock.lap();

    // Fold-over repair (only when ARAP folds), then relaxation.
    let mut cone_angle = interior_cone_angles(mesh, placement);
    let mut state = ArapState { weights, pinned: fixed, r, uv, energy };
    let Repaired { mut best_uv, mut best_flips, rounds, flips_before } =
        repair_folds(mesh, &mut sys, field, &mut state, &cone_angle, options, progress)?;
    let ArapState { mut weights, mut energy, .. } = state;
    timings.repair = clock.lap();

    // Untangling of what the repair left folded, from its best map.
    let mut untangle_iterations = 0;
    let mut realized = Vec::new();
    if best_flips > 0 && options.untangle.max_outer > 0 && sys.projector.is_some() {
        let untangled;
        (untangle_iterations, untangled) = untangle_folds(&mut sys, &mut weights, mesh.face_components(), placement, &best_uv, &mut cone_angle, options)?;
        if let Some(u) = untangled {
            realized = u.realized;
            best_flips = 0;
            energy = arap_energy(&sys, &u.uv);
            best_uv = u.uv;
        }
        // A partly untangled map is not kept: the flip refinement splits
        // the faces the repair left flipped, and fewer of them there (a
        // single one on teapot at `--sharp 20`) refine too little.
    }
    timings.untangle = clock.lap();

    // Injective refinement from a fold-free start: ARAP's map, else the
    // repaired one, else the Poisson map when that one is fold-free.
    if best_flips > 0 && folded_faces(mesh, &sys, &poisson_uv, &cone_angle).is_empty() {
        best_uv = poisson_uv;
        best_flips = 0;
        energy = arap_energy(&sys, &best_uv);
    }
    let mut refine_iterations = 0;
    if best_flips == 0 && options.refine.max_iterations > 0 {
        // Free the ARAP factorization first: the refinement factors its own
        // (larger) system, and peak memory matters in the browser.
        sys.solver = None;
        if let Some((x, iterations)) = refine(&sys, &sys.unknowns_of(&best_uv), &options.refine, progress) {
            let refined = sys.wedges_of(&x);
            // The refinement minimises a surrogate (ARAP + barrier): keep its
            // map unless it is worse by the paper's measure, eq. (19).
            let corners = |uv: &[[f64; 2]]| -> Vec<[f64; 2]> { cut.wedge.iter().map(|&w| uv[w as usize]).collect() };
            if folded_faces(mesh, &sys, &refined, &cone_angle).is_empty()
                && metrics::distortion(mesh, &corners(&refined)) <= metrics::distortion(mesh, &corners(&best_uv))
            {
                refine_iterations = iterations;
                energy = arap_energy(&sys, &refined);
                best_uv = refined;
            }
        }
    }
    timings.injective = clock.lap();
    Ok(SeamlessResult {
        uv: best_uv,
        counts: ParamCounts {
            arap_iterations: iterations,
            flips_before_repair: flips_before,
            flips_fixed: flips_before - best_flips,
            repair_rounds: rounds,
            refine_iterations,
            untangle_iterations,
        },
        realized,
        energy,
    })
}

/// ARAP's state between runs: per-face weights, the faces whose rotation
/// is held, the target rotations, the map (per wedge) and its energy.
struct ArapState {
    weights: Vec<f64>,
    pinned: Vec<bool>,
    r: Vec<[[f64; 2]; 2]>,
    uv: Vec<[f64; 2]>,
    energy: f64,
}

/// What [`repair_folds`] found: the map with the fewest folds and its count,
/// the rounds run and the folds before the first.
struct Repaired {
    best_uv: Vec<[f64; 2]>,
    best_flips: usize,
    rounds: usize,
    flips_before: usize,
}

/// Fold-over repair of the ARAP map in `state`: raises the weight of the
/// folded triangles and their neighbours (only A changes: every constraint
/// holds) and re-runs ARAP, while the rounds make progress; then, without
/// the injective refinement and once fold-free, decays the weights back
/// towards 1 while the map stays fold-free. Refactors `sys` per round.
fn repair_folds(
    mesh: &TriMesh,
    sys: &mut System,
    field: &CrossField,
    state: &mut ArapState,
    cone_angle: &[f64],
    options: &ParamOptions,
    progress: &mut dyn FnMut(ParamProgress),
) -> Result<Repaired, ParamError> {
    let mut flips = folded_faces(mesh, sys, &state.uv, cone_angle);
    let flips_before = flips.len();
    let (mut best_uv, mut best_flips) = (state.uv.clone(), flips.len());
    let mut round = 0;
    // Rounds go on while they make progress: finer meshes need more of them
    // (the 52 k-face fandisk needed 13-24).
    let mut stalled = 0;
    while !flips.is_empty() && round < options.repair_rounds && stalled < REPAIR_PATIENCE {
        round += 1;
        progress(ParamProgress::Repair { round, flips: flips.len() });
        for &f in &flips {
            // Hold a flipped triangle's target at the field frame (an
            // orientation-preserving rotation) instead of the closest rotation
            // to its flipped Jacobian, and weight it up.
            state.r[f] = field.target(f);
            state.pinned[f] = true;
            state.weights[f] = (state.weights[f] * 10.0).min(1e6);
            for k in 0..3 {
                let t = mesh.twin(3 * f as u32 + k);
                if let Some(g) = mesh.face(t) {
                    state.weights[g as usize] = (state.weights[g as usize] * 3.0).min(1e6);
                }
            }
        }
        sys.refactor(&state.weights)?;
        let (_, e) = arap(sys, &state.weights, &state.pinned, &mut state.r, &mut state.uv, options, 10, &mut |_| {})?;
        state.energy = e;
        flips = folded_faces(mesh, sys, &state.uv, cone_angle);
        if flips.len() < best_flips {
            best_flips = flips.len();
            best_uv = state.uv.clone();
            stalled = 0;
        } else {
            stalled += 1;
        }
        if flips.len() > REPAIR_DIVERGENCE * best_flips.max(REPAIR_DIVERGENCE_FLOOR) {
            break;
        }
    }
    // Relaxation (only without the injective refinement).
    let relax = options.refine.max_iterations == 0;
    if relax && best_flips == 0 && round > 0 {
        state.uv = best_uv.clone();
        for _ in 0..16 {
            for w in state.weights.iter_mut() {
                *w = 1.0 + (*w - 1.0) * 0.85;
            }
            sys.refactor(&state.weights)?;
            let mut trial = state.uv.clone();
            let mut r_trial = state.r.clone();
            let (_, e) = arap(sys, &state.weights, &state.pinned, &mut r_trial, &mut trial, options, 10, &mut |_| {})?;
            if !folded_faces(mesh, sys, &trial, cone_angle).is_empty() {
                break;
            }
            state.uv = trial;
            state.r = r_trial;
            state.energy = e;
            best_uv = state.uv.clone();
        }
    }
    Ok(Repaired { best_uv, best_flips, rounds: round, flips_before })
}

/// Untangles the folded map `start` (sec. [`super::untangle`]), preconditioned
/// by the unweighted KKT (`weights` reset to 1, one factorization), on the
/// components of the mesh (`face_part`: per face) that hold an inverted
/// triangle: no constraint couples two components, so the others keep
/// their map, and each iteration costs their energy only. Returns
/// the iterations, and the map when it satisfies the constraints with every
/// triangle positive, with the cones it realizes otherwise than placed
/// (`cone_angle` updated to match).
fn untangle_folds(
    sys: &mut System,
    weights: &mut [f64],
    face_part: &[u32],
    placement: &ConePlacement,
    start: &[[f64; 2]],
    cone_angle: &mut [f64],
    options: &ParamOptions,
) -> Result<(usize, Option<Untangled>), ParamError> {
    weights.iter_mut().for_each(|w| *w = 1.0);
    sys.refactor(weights)?;
    let precondition = |q: &mut [f64]| sys.precondition(q);
    let mut x = sys.unknowns_of(start);
    let mut tangled = vec![false; face_part.iter().map(|&c| c as usize + 1).max().unwrap_or(0)];
    for (el, &c) in sys.elements.iter().zip(face_part) {
        tangled[c as usize] |= !(signed_uv_area(el.unknowns_uv(&x)) > 0.0);
    }
    let active: Vec<Element> = sys.elements.iter().zip(face_part).filter(|(_, &c)| tangled[c as usize]).map(|(el, _)| *el).collect();
    let stats = untangle(&active, &precondition, &mut x, &options.untangle);
    if let Some(projector) = &sys.projector {
        projector.project(&mut x, CONSTRAINT_TOLERANCE, 3);
    }
    let uv = sys.wedges_of(&x);
    let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let feasible = sys.constraint_residual(&x) <= 1e-12 * scale;
    if !(feasible && stats.inverted == 0 && flipped_faces(sys, &uv).is_empty()) {
        return Ok((stats.iterations, None));
    }
    // Every triangle positive: locally injective away from the cones and
    // corners, some of which the map may realize with another angle than
    // placed (see `realized_cones`).
    let realized = realized_cones(placement, sys, &uv, cone_angle);
    Ok((stats.iterations, Some(Untangled { uv, realized })))
}

/// A fold-free map found by [`untangle_folds`].
struct Untangled {
    uv: Vec<[f64; 2]>,
    /// `(cut vertex, k)` of the cones realized otherwise than placed.
    realized: Vec<(u32, i32)>,
}

/// Injective refinement ([`super::injective`]) of the feasible, fold-free
/// unknowns `start`; `None` when it made no progress, failed numerically or
/// drifted off the constraints (then `start` stands).
fn refine(sys: &System, start: &[f64], options: &RefineOptions, progress: &mut dyn FnMut(ParamProgress)) -> Option<(Vec<f64>, usize)> {
    let projector = sys.projector.as_ref()?;
    let mut refiner = Refiner::new(&sys.elements, sys.n_unknowns, &sys.constraints, sys.n_rows, projector).ok()?;
    let mut x = start.to_vec();
    let max = options.max_iterations;
    let stats = refiner.refine(&mut x, options, &mut |iteration| progress(ParamProgress::Injective { iteration: iteration + 1, max }));
    let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let drift = sys.constraint_residual(&x) - sys.constraint_residual(start);
    (stats.iterations > 0 && drift <= 1e-12 * scale).then_some((x, stats.iterations))
}

/// ARAP energy (4) `sum_f A_f min_R |J_f - R|^2` of the wedge UVs `uv`.
fn arap_energy(sys: &System, uv: &[[f64; 2]]) -> f64 {
    (0..sys.elements.len())
        .map(|f| {
            let j = sys.jacobian(f, uv);
            closest_rotation(j).map_or(f64::INFINITY, |r| sys.elements[f].area * frob2(j, r))
        })
        .sum()
}

/// ARAP local/global iterations (eq. 4) from `uv`; `cap` overrides the
/// iteration limit when non-zero. Returns (iterations, energy).
#[allow(clippy::too_many_arguments)]
fn arap(
    sys: &System,
    weights: &[f64],
    fixed: &[bool],
    r: &mut [[[f64; 2]; 2]],
    uv: &mut Vec<[f64; 2]>,
    options: &ParamOptions,
    cap: usize,
    progress: &mut dyn FnMut(ParamProgress),
) -> Result<(usize, f64), ParamError> {
    let max = if cap > 0 { cap.min(options.max_arap_iterations.max(cap)) } else { options.max_arap_iterations };
    let energy = |r: &[[[f64; 2]; 2]], uv: &[[f64; 2]]| -> f64 {
        (0..sys.elements.len()).map(|f| weights[f] * sys.elements[f].area * frob2(sys.jacobian(f, uv), r[f])).sum()
    };
    let mut prev = f64::INFINITY;
    let mut e = energy(r, uv);
    let mut it = 0;
    while it < max {
        it += 1;
        progress(ParamProgress::Arap { iteration: it, max });
        // Local step: closest rotation (B.2), kept fixed next to features.
        for f in 0..sys.elements.len() {
            if !fixed[f] {
                if let Some(rot) = closest_rotation(sys.jacobian(f, uv)) {
                    r[f] = rot;
                }
            }
        }
        // Global step: (23) with the new R, same factorization.
        *uv = sys.global_step(weights, r, ARAP_TOLERANCE)?;
        prev = prev.min(e);
        e = energy(r, uv);
        if prev.is_finite() && (prev - e) <= options.arap_tolerance * prev.max(f64::MIN_POSITIVE) {
            break;
        }
    }
    Ok((it, e))
}

/// Unknown index of every wedge's u and v: isolines (`u_a = u_b` or
/// `v_a = v_b` along every feature and boundary edge, both sides) are
/// enforced by sharing one unknown per class of equal coordinates, which
/// also removes the rows they would make redundant.
pub(super) fn unknowns(mesh: &TriMesh, field: &CrossField, cut: &CutGraph) -> ([Vec<usize>; 2], usize) {
    let nw = cut.n_wedges;
    let mut uf = [UnionFind::new(nw), UnionFind::new(nw)];
    for h in 0..3 * mesh.n_faces() as u32 {
        let c = field.isoline[h as usize];
        if c == NO_ISOLINE {
            continue;
        }
        let c = c as usize;
        let (a, b) = (cut.wedge[h as usize], cut.wedge[mesh.next(h) as usize]);
        uf[c].union(a, b);
    }
    let mut n = 0;
    let mut var: [Vec<usize>; 2] = [vec![usize::MAX; nw], vec![usize::MAX; nw]];
    for c in 0..2 {
        let mut id = vec![usize::MAX; nw];
        for w in 0..nw as u32 {
            let r = uf[c].find(w) as usize;
            if id[r] == usize::MAX {
                id[r] = n;
                n += 1;
            }
            var[c][w as usize] = id[r];
        }
    }
    (var, n)
}

/// Integer rows `sum_i c_i x_i = 0`, each stored once: merged, without
/// zero entries, first coefficient positive.
#[derive(Default)]
pub(super) struct RowSet {
    pub(super) rows: Vec<Vec<(usize, i64)>>,
    seen: std::collections::HashSet<Vec<(usize, i64)>>,
}

impl RowSet {
    /// Adds the row of `entries` (duplicates summed) unless it vanishes or
    /// is already there (then returns false); clears `entries`.
    pub(super) fn push(&mut self, entries: &mut Vec<(usize, i64)>) -> bool {
        entries.sort_unstable_by_key(|e| e.0);
        let mut merged: Vec<(usize, i64)> = Vec::new();
        for &(i, v) in entries.iter() {
            match merged.last_mut() {
                Some(l) if l.0 == i => l.1 += v,
                _ => merged.push((i, v)),
            }
        }
        merged.retain(|e| e.1 != 0);
        entries.clear();
        if merged.is_empty() {
            return false;
        }
        if merged[0].1 < 0 {
            for e in merged.iter_mut() {
                e.1 = -e.1;
            }
        }
        let added = self.seen.insert(merged.clone());
        if added {
            self.rows.push(merged);
        }
        added
    }
}

/// Rotation `Rot(-m pi/2)` of a seam curve with matching `m`: `f_g = r f_f + t`.
pub(super) fn curve_rotation(matching: i64) -> [[i64; 2]; 2] {
    match matching.rem_euclid(4) {
        0 => [[1, 0], [0, 1]],
        1 => [[0, 1], [-1, 0]],
        2 => [[-1, 0], [0, -1]],
        _ => [[0, -1], [1, 0]],
    }
}

/// Wedge pairs `(f side, g side)` at the vertices of a seam curve, head to
/// tail (a closed curve's first vertex once).
pub(super) fn curve_wedge_pairs(mesh: &TriMesh, cut: &CutGraph, curve: &super::cut_graph::SeamCurve) -> Vec<(u32, u32)> {
    let hs = &curve.halfedges;
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(hs.len() + 1);
    let t0 = mesh.twin(hs[0]);
    pairs.push((cut.wedge[hs[0] as usize], cut.wedge[mesh.next(t0) as usize]));
    for &h in hs {
        let t = mesh.twin(h);
        pairs.push((cut.wedge[mesh.next(h) as usize], cut.wedge[t as usize]));
    }
    if curve.closed && pairs.first() == pairs.last() {
        pairs.pop();
    }
    pairs
}

/// The seam transition rows (B.2, translation eliminated) on the unknowns
/// of [`unknowns`], without pins.
pub(super) fn seam_rows(mesh: &TriMesh, cut: &CutGraph, vars: &[Vec<usize>; 2]) -> RowSet {
    let var = |w: u32, c: usize| vars[c][w as usize];
    let mut set = RowSet::default();
    let mut entries = Vec::new();
    for curve in &cut.curves {
        let rot = curve_rotation(curve.matching);
        for win in curve_wedge_pairs(mesh, cut, curve).windows(2) {
            let ((fa, ga), (fb, gb)) = (win[0], win[1]);
            for c in 0..2 {
                // f_g(b) - f_g(a) = r (f_f(b) - f_f(a))   (B.2, t eliminated).
                entries.push((var(gb, c), 1));
                entries.push((var(ga, c), -1));
                for d in 0..2 {
                    if rot[c][d] != 0 {
                        entries.push((var(fb, d), -rot[c][d]));
                        entries.push((var(fa, d), rot[c][d]));
                    }
                }
                set.push(&mut entries);
            }
        }
    }
    set
}

/// Constraint rows on the unknowns of [`unknowns`]: seam transitions (B.2)
/// and pins; rows that vanish or repeat are dropped.
fn constraint_rows(mesh: &TriMesh, cut: &CutGraph, vars: &[Vec<usize>; 2], n_unknowns: usize) -> (Vec<Triplet>, usize) {
    let mut set = seam_rows(mesh, cut, vars);
    let mut entries = Vec::new();
    for &p in &cut.pins {
        for c in 0..2 {
            entries.push((vars[c][p as usize], 1));
            set.push(&mut entries);
        }
    }
    let rows = set.rows;
    // Drop rows that are combinations of earlier ones (exact redundancy
    // makes the KKT singular); pins come last and are never redundant.
    let keep = independent_rows(&rows, n_unknowns);
    let mut triplets = Vec::new();
    let mut m = 0;
    for (row, k) in rows.iter().zip(keep) {
        if k {
            triplets.extend(row.iter().map(|&(i, v)| (m, i, v as f64)));
            m += 1;
        }
    }
    (triplets, m)
}

