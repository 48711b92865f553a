//! The polish of a rounded map: local stiffening where the plain fit's
//! rounding folds, the untangler under the integer rows (on patches around
//! the folds of a large mesh: [`super::local`]), ARAP iterations, and where
//! the stiffened map is still bad one-integer moves at the bad triangles
//! ([`Quantizer::uncollapse`]); and the measures of how bad a map is
//! ([`Quantizer::badness`]).

use super::super::element::signed_uv_area;
use super::super::seamless::{closest_rotation, stiffness_triplets};
use super::super::separation::Separations;
use super::super::untangle::{untangle, UntangleOptions, UntangleStats};
use super::fit::{precondition, RoundedSystem, Trials};
use super::{corner_angle_sums, local, QuantizeError, Quantizer, FULL_BUDGET_FACES, NEAR_INTEGER};
use crate::linalg::{Kkt, LdltSolver, NullSpaceProjector};
use std::f64::consts::{FRAC_PI_4, PI};

/// Share of its seamless-map UV area below which a triangle counts as
/// collapsed (squeezed onto a grid line: the exact snapping of the integers
/// afterwards makes it degenerate).
const COLLAPSED_SHARE: f64 = 1e-6;
/// Weight of a wound vertex in [`Quantizer::badness`].
pub(super) const WOUND_WEIGHT: usize = 16;
/// How many times worse ([`Quantizer::badness`]) than the best map of the
/// rounding so far, or than the same rounding with its integers moved off
/// the collapses ([`Quantizer::uncollapse`], polished first), a map may be
/// after its local stiffening for [`Quantizer::polish_stiffened`] to
/// untangle it; worse ones hold their folds with their integers. On the
/// fandisk with creases over 60° at 700 quads: the held and widened passes'
/// 1 900 bad faces against the plain pass's 51 ended at 1 800-1 900, after
/// 3-5 s of untangling each; cow at 700: the held, widened and graded
/// passes' 980-1 900 against 32 ended at 64-650. The most a kept map was
/// worse (spot >40° at 1 000 quads): 4.2 times, 293 to 64 against 70. The
/// stiffer fits' maps are not stiffened locally and their untangling gains
/// more (cow at 700, weight 100: 1 102 to 32 against 128): always run.
pub(super) const HOPELESS_POLISH_FACTOR: usize = 6;
/// Integer moves tried against flipped or collapsed triangles, at most.
pub(super) const UNCOLLAPSE_TRIALS: usize = 40;
/// Unknowns of bad triangles whose sensitivities pick the integers
/// [`Quantizer::uncollapse`] tries, at most per round.
pub(super) const UNCOLLAPSE_PROBES: usize = 48;
/// Radii (grid cells) of the patches around inverted faces that the polish
/// of a mesh of more than [`FULL_BUDGET_FACES`] untangles in turn, each
/// around the faces the one before left inverted, before the whole map
/// ([`local`]); their most vertex rings, and the largest share of the faces
/// a patch may take.
const PATCH_CELLS: [f64; 2] = [3.0, 6.0];
const MAX_PATCH_RINGS: usize = 64;
const MAX_PATCH_SHARE: f64 = 0.25;
/// Stalled `eps` updates the polish's untangler waits for, at least.
const MIN_UNTANGLE_PATIENCE: usize = 3;
/// ARAP iterations after the rounding, at most.
const ARAP_ITERATIONS: usize = 20;
/// Local stiffening re-solves of a rounded map that is bad, at most
/// ([`Quantizer::stiffen`]), and the largest weight a face reaches.
pub(super) const STIFFEN_ITERATIONS: usize = 10;
const MAX_STIFFENING: f64 = 1e6;
/// Stiffening iterations without a less bad map after which it stops: where
/// the rounding itself squeezed the map (dense feature curves), the
/// badness bounces instead of falling.
const STIFFEN_PATIENCE: usize = 3;
/// Radius (grid cells) around the bad faces of a map within which
/// [`Quantizer::stiffen`] raises the weights.
const STIFFEN_CELLS: f64 = 1.0;
/// Steps that relax a clean stiffened map's weights towards 1, at most,
/// and the share of each weight's excess over 1 a step keeps.
pub(super) const RELAX_ITERATIONS: usize = 8;
const RELAX_FACTOR: f64 = 0.5;

impl Quantizer {
    /// The untangler's options in [`Self::polish_stiffened`]: the default,
    /// its total iterations and patience scaled by [`Self::budget`]
    /// (patience at least [`MIN_UNTANGLE_PATIENCE`]).
    pub(super) fn polish_untangle(&self) -> UntangleOptions {
        let default = UntangleOptions::default();
        UntangleOptions {
            max_total: self.budget(default.max_total),
            patience: self.budget(default.patience).max(MIN_UNTANGLE_PATIENCE),
            ..default
        }
    }

    /// The rounded map `x` as its polish starts: where it is bad and with
    /// `stiffen`, its least bad local stiffening ([`Self::stiffen`]) under
    /// `system`'s rows.
    pub(super) fn stiffened(
        &self,
        x: Vec<f64>,
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
        s: f64,
        stiffen: bool,
    ) -> Result<Polished, QuantizeError> {
        let rounded_bad = self.badness(&x, s);
        let (mut x, mut bad, mut stiffening) = (x, rounded_bad, 0);
        if bad > 0 && stiffen {
            (x, bad, stiffening) = self.stiffen(x, bad, system, targets, s)?;
        }
        Ok(Polished { x, bad, rounded_bad, arap_iterations: 0, untangled: false, stiffening })
    }

    /// The rest of the polish of `start` ([`Self::stiffened`] with the same
    /// `stiffen`): untangles it under `system`'s rows when it folds, then
    /// runs ARAP local/global iterations (eq. 4), each step kept unless it
    /// makes the map worse by [`Self::badness`]. `bound`: the badness of the
    /// best map so far where that is bad; with `stiffen`, a map more than
    /// [`HOPELESS_POLISH_FACTOR`] times worse is returned as it is.
    pub(super) fn polish_stiffened(
        &self,
        start: Polished,
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
        s: f64,
        stiffen: bool,
        bound: Option<usize>,
    ) -> Result<Polished, QuantizeError> {
        let Polished { mut x, mut bad, rounded_bad, stiffening, .. } = start;
        let mut arap_iterations = 0;
        let mut untangled = false;
        if stiffen && bound.is_some_and(|b| bad > HOPELESS_POLISH_FACTOR * b) {
            return Ok(Polished { x, bad, rounded_bad, arap_iterations, untangled, stiffening });
        }
        // The untangler mends inverted triangles; a map whose only fault is a
        // vertex it winds around twice has none to mend.
        if (0..self.elements.len()).any(|f| self.collapsed(f, &x, s)) {
            // Untangle in model units (the barrier's area term wants det J ~ 1):
            // around the folds on a large mesh, else the whole map.
            let mut xm: Vec<f64> = x.iter().map(|v| v * s).collect();
            let stats = match self.untangle_locally(&mut xm, system, s)? {
                Some(stats) => stats,
                None => {
                    let projector =
                        NullSpaceProjector::new(&system.c, self.n_unknowns, system.b.len()).ok();
                    let solver = system.untangle_solver(self)?;
                    let precondition = |q: &mut [f64]| precondition(solver, system.b.len(), q, projector.as_ref());
                    untangle(&self.elements, &precondition, &mut xm, &self.polish_untangle())
                }
            };
            let candidate = system.onto_constraints(xm.iter().map(|v| v / s).collect())?;
            let f = self.badness(&candidate, s);
            if f < bad {
                x = candidate;
                bad = f;
                untangled = stats.inverted == 0 && f == 0;
            }
        }
        for _ in 0..ARAP_ITERATIONS {
            let r: Vec<[[f64; 2]; 2]> = self
                .elements
                .iter()
                .zip(targets)
                .map(|(el, t)| {
                    closest_rotation(el.jacobian(&x))
                        .map(|r| r.map(|row| row.map(|v| v / s)))
                        .unwrap_or(*t)
                })
                .collect();
            // Put back onto the rows: the graded fit's weights (up to 1e4)
            // leave an ARAP solve off them by about 1e-9.
            let next = system.onto_constraints(system.resolve(self, &r)?)?;
            let f = self.badness(&next, s);
            if f > bad {
                break;
            }
            let moved = next
                .iter()
                .zip(&x)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            x = next;
            bad = f;
            arap_iterations += 1;
            if moved < 1e-4 {
                break;
            }
        }
        Ok(Polished { x, bad, rounded_bad, arap_iterations, untangled, stiffening })
    }

    /// The local stiffening of Bommes et al. 2009 (MIQ) of the rounded map
    /// `x` (badness `bad`) under `system`'s rows: the fit weight of every
    /// face within [`STIFFEN_CELLS`] of a bad one ([`Self::flipped_faces`])
    /// is multiplied by `1 + e_f`, `e_f` its relative Jacobian error
    /// `|J_f - T_f| / |T_f|` plus one where it is collapsed, and the map
    /// solved again, at most [`STIFFEN_ITERATIONS`] times while it is bad.
    /// A rounded point drags the uniform fit along as a spike (the
    /// displacement of a point constraint decays within a ring), which
    /// folds its ring or winds the map around it; the weights grow fastest
    /// where the spike is sharpest and spread it until the ring moves with
    /// its point; a clean map's weights then relax towards 1 while it stays
    /// clean. Returns the least bad map, its badness and the iterations
    /// that led to it (0: none made the map less bad). One symbolic
    /// analysis, one numeric factorization per iteration; each solve is put
    /// back onto the rows by `system` (heavy weights leave it off them by
    /// up to 1e-9), and one that fails ends the iterations.
    pub(super) fn stiffen(
        &self,
        mut x: Vec<f64>,
        mut bad: usize,
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
        s: f64,
    ) -> Result<(Vec<f64>, usize, usize), QuantizeError> {
        let mut weights = system.weights.clone();
        let mut best_weights: Option<(Vec<f64>, usize)> = None;
        let mut kkt = Kkt::assemble(&stiffness_triplets(&self.elements, &weights), self.n_unknowns, &system.c, system.b.len())?;
        let mut solver: Option<LdltSolver> = None;
        let mut current = x.clone();
        let rings = self.rings(STIFFEN_CELLS, s);
        for iteration in 1..=STIFFEN_ITERATIONS {
            let near = local::faces_around(&self.faces, &self.flipped_faces(&current, s), rings);
            for (f, (el, t)) in self.elements.iter().zip(targets).enumerate().filter(|&(f, _)| near[f]) {
                let j = el.jacobian(&current);
                let norm = |m: [[f64; 2]; 2]| m.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
                let error = norm([[j[0][0] - t[0][0], j[0][1] - t[0][1]], [j[1][0] - t[1][0], j[1][1] - t[1][1]]]) / norm(*t).max(f64::MIN_POSITIVE);
                let collapsed = if self.collapsed(f, &current, s) { 1.0 } else { 0.0 };
                weights[f] = (weights[f] * (1.0 + error + collapsed)).min(MAX_STIFFENING);
            }
            // A solve the heavy weights make fail ends the stiffening.
            let Ok(solved) = self.weighted_solve(&mut kkt, &mut solver, &weights, system, targets) else { break };
            current = solved;
            let next = self.badness(&current, s);
            if next < bad {
                (x, bad, best_weights) = (current.clone(), next, Some((weights.clone(), iteration)));
            }
            let since_best = iteration - best_weights.as_ref().map_or(0, |b| b.1);
            if bad == 0 || since_best >= STIFFEN_PATIENCE {
                break;
            }
        }
        let Some((best, iterations)) = best_weights else { return Ok((x, bad, 0)) };
        // A clean map's weights relax towards 1 while it stays clean (the
        // least distortion that does not fold).
        if bad == 0 {
            for step in 1..=RELAX_ITERATIONS {
                let keep = RELAX_FACTOR.powi(step as i32);
                weights = best.iter().map(|w| 1.0 + (w - 1.0) * keep).collect();
                let Ok(relaxed) = self.weighted_solve(&mut kkt, &mut solver, &weights, system, targets) else { break };
                if self.badness(&relaxed, s) > 0 {
                    break;
                }
                x = relaxed;
            }
        }
        Ok((x, bad, iterations))
    }

    /// The rounded map `rounded` (integers `values`) with integers moved off
    /// its collapses ([`Self::uncollapse`]) and polished ([`Self::stiffened`],
    /// [`Self::polish_stiffened`] with `stiffen` and `bound`); `None` where
    /// no move was kept. `system`'s rows are as given on return.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn polish_moved(
        &self,
        values: &[Option<i64>],
        rounded: &[f64],
        system: &mut RoundedSystem,
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        s: f64,
        separations: &Separations,
        stiffen: bool,
        bound: Option<usize>,
    ) -> Result<Option<Moved>, QuantizeError> {
        let (rows, solution) = (system.b.clone(), system.x.clone());
        let (mut values, mut x) = (values.to_vec(), rounded.to_vec());
        let moves = self.uncollapse(&mut values, &mut x, system, x0, targets, s, separations)?;
        let mut moved = None;
        if moves > 0 {
            let start = self.stiffened(x, system, targets, s, stiffen)?;
            moved = Some(Moved { polish: self.polish_stiffened(start, system, targets, s, stiffen, bound)?, values, moves });
        }
        (system.b, system.x) = (rows, solution);
        Ok(moved)
    }

    /// Where the rounded map has flipped or collapsed triangles or wound
    /// vertices, moves by one the integers that move their corners (found by
    /// adjoint solves as in [`Self::separate`], so a translation whose seam
    /// passes there counts too), closest to their seamless values first,
    /// keeping each move that leaves a less bad map ([`Self::badness`]) and
    /// no more violated separations, every form still integer. Each trial
    /// from the moved row's response ([`RoundedSystem::response`]), at most
    /// [`UNCOLLAPSE_TRIALS`]. Returns the moves kept.
    pub(super) fn uncollapse(
        &self,
        values: &mut [Option<i64>],
        x: &mut Vec<f64>,
        system: &mut RoundedSystem,
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        s: f64,
        separations: &Separations,
    ) -> Result<usize, QuantizeError> {
        let mut badness = self.badness(x, s);
        let violated = separations.violated(x, NEAR_INTEGER).len();
        let (mut trials, mut kept) = (0, 0);
        let mut tried = std::collections::HashSet::new();
        let (max_trials, max_probes) = (self.budget(UNCOLLAPSE_TRIALS), self.budget(UNCOLLAPSE_PROBES));
        while badness > 0 && trials < max_trials {
            let mut unknowns: Vec<usize> = self
                .flipped_faces(x, s)
                .iter()
                .flat_map(|&f| self.elements[f].x.iter().flatten().copied())
                .collect();
            unknowns.sort_unstable();
            unknowns.dedup();
            unknowns.truncate(max_probes);
            let mut gain = vec![0.0f64; system.b.len()];
            let probes: Vec<[(usize, i64); 1]> = unknowns.iter().map(|&u| [(u, 1)]).collect();
            for column in system.sensitivities(&probes)? {
                for (g, d) in gain.iter_mut().zip(column) {
                    *g = g.max(d.abs());
                }
            }
            let mut candidates: Vec<(f64, usize, usize, i64)> = system
                .form_rows
                .iter()
                .filter(|&&(_, row)| gain[row] > 0.5)
                .flat_map(|&(form, row)| {
                    let v = values[form].unwrap_or(0);
                    let y = self.forms[form].value(x0);
                    [1, -1].map(|step| (((v + step) as f64 - y).abs(), form, row, step))
                })
                .collect();
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
            candidates.retain(|&(_, form, _, step)| !tried.contains(&(form, values[form].unwrap_or(0) + step)));
            candidates.truncate(max_trials - trials);
            let mut ahead = Trials::new(candidates.iter().map(|c| c.2));
            let mut improved = false;
            for (i, (_, form, row, step)) in candidates.into_iter().enumerate() {
                let v = values[form].unwrap_or(0) + step;
                tried.insert((form, v));
                trials += 1;
                let moved = ahead.resolve_moved(system, i, step)?;
                let after = self.badness(&moved, s);
                if self.rounded_forms_integral(values, &moved) && after < badness && separations.violated(&moved, NEAR_INTEGER).len() <= violated {
                    values[form] = Some(v);
                    system.take_move(self, targets, row, step)?;
                    self.take_determined_values(values, &system.x);
                    x.clone_from(&system.x);
                    badness = self.badness(x, s);
                    kept += 1;
                    improved = true;
                    break;
                }
            }
            if !improved {
                break;
            }
        }
        Ok(kept)
    }

    /// [`local::Patch::untangle`] of `xm` (model units) on the faces within
    /// [`PATCH_CELLS`] grid cells of its inverted ones, under `system`'s
    /// rows, each radius around the faces the one before left inverted.
    /// `None` (the whole map is to be untangled) on meshes of at most
    /// [`FULL_BUDGET_FACES`] faces (there the whole map costs little more and
    /// spreads the distortion), when nothing is inverted, or when a patch
    /// would cover more than [`MAX_PATCH_SHARE`] of the faces (the folds are
    /// spread). Folds left by the widest patch are held by the integers:
    /// on the bunny subdivided to 114 k faces the whole-map untangler left
    /// the same 3-5 of them, at 45-70 s a pass.
    pub(super) fn untangle_locally(&self, xm: &mut [f64], system: &RoundedSystem, s: f64) -> Result<Option<UntangleStats>, QuantizeError> {
        if self.elements.len() as f64 <= FULL_BUDGET_FACES {
            return Ok(None);
        }
        let mut done: Option<UntangleStats> = None;
        for cells in PATCH_CELLS {
            let seeds = local::inverted_faces(&self.elements, xm);
            if seeds.is_empty() {
                break;
            }
            let rings = self.rings(cells, s);
            let in_patch = local::faces_around(&self.faces, &seeds, rings);
            if in_patch.iter().filter(|&&inside| inside).count() as f64 > MAX_PATCH_SHARE * self.faces.len() as f64 {
                return Ok(None);
            }
            let Some(patch) = local::Patch::new(&self.elements, &in_patch, &system.c, system.b.len(), self.n_unknowns)? else {
                return Ok(None);
            };
            let stats = patch.untangle(xm, &self.polish_untangle());
            done = Some(match done {
                None => stats,
                Some(first) => UntangleStats { outer: first.outer + stats.outer, iterations: first.iterations + stats.iterations, inverted_start: first.inverted_start, inverted: stats.inverted },
            });
        }
        Ok(done)
    }

    /// Vertex rings of faces that span `cells` grid cells of length `s` (in
    /// the edge of an equilateral triangle of the mean seamless area; at
    /// least one, at most [`MAX_PATCH_RINGS`]).
    pub(super) fn rings(&self, cells: f64, s: f64) -> usize {
        let mean_area = self.seamless_areas.iter().sum::<f64>() / self.seamless_areas.len().max(1) as f64;
        let edge = (mean_area * 4.0 / 3f64.sqrt()).sqrt().max(f64::MIN_POSITIVE);
        (cells * s / edge).ceil().clamp(1.0, MAX_PATCH_RINGS as f64) as usize
    }

    /// Whether face `f` of `x` (grid size `s`) is flipped or collapsed: its
    /// UV area below [`COLLAPSED_SHARE`] of its area in the seamless map.
    pub(super) fn collapsed(&self, f: usize, x: &[f64], s: f64) -> bool {
        !(signed_uv_area(self.elements[f].unknowns_uv(x)) * s * s
            > COLLAPSED_SHARE * self.seamless_areas[f])
    }

    /// Faces flipped or collapsed ([`Self::collapsed`]), and the faces around
    /// [`Self::wound_vertices`].
    pub(super) fn flipped_faces(&self, x: &[f64], s: f64) -> Vec<usize> {
        let mut bad: Vec<usize> = (0..self.elements.len())
            .filter(|&f| self.collapsed(f, x, s))
            .collect();
        let wound = self.wound_vertices(x);
        if !wound.is_empty() {
            bad.extend(
                (0..self.faces.len())
                    .filter(|&f| self.faces[f].iter().any(|v| wound.binary_search(v).is_ok())),
            );
            bad.sort_unstable();
            bad.dedup();
        }
        bad
    }

    /// How far `x` is from a valid map: flipped or collapsed faces, plus
    /// [`WOUND_WEIGHT`] per wound vertex (a move must not trade a few
    /// collapsed slivers for a vertex the map winds around).
    pub(super) fn badness(&self, x: &[f64], s: f64) -> usize {
        let collapsed = (0..self.elements.len())
            .filter(|&f| self.collapsed(f, x, s))
            .count();
        collapsed + WOUND_WEIGHT * self.wound_vertices(x).len()
    }

    /// Vertices whose UV angle sum is off the seamless map's by more than pi
    /// inside, by more than an eighth of a turn on the boundary (ascending).
    /// A boundary vertex lies on an isoline, and its angle changes by
    /// quarter turns: a straight one turned to a full turn is a hairpin of
    /// the boundary, whose two sides overlap on the isoline (bff's
    /// punctured torus at 1 000 quads: two quad vertices at one grid point,
    /// traces that do not come back).
    pub(super) fn wound_vertices(&self, x: &[f64]) -> Vec<u32> {
        let sums = corner_angle_sums(&self.faces, self.angle_sums.len(), |f| {
            self.elements[f].unknowns_uv(x)
        });
        (0..sums.len() as u32)
            .filter(|&v| {
                let limit = if self.on_boundary[v as usize] { FRAC_PI_4 } else { PI };
                (sums[v as usize] - self.angle_sums[v as usize]).abs() > limit
            })
            .collect()
    }
}

/// A rounded map with integers moved off its collapses, polished
/// ([`Quantizer::polish_moved`]).
pub(super) struct Moved {
    pub(super) polish: Polished,
    pub(super) values: Vec<Option<i64>>,
    /// Integers moved.
    pub(super) moves: usize,
}

/// What the polish ([`Quantizer::stiffened`], [`Quantizer::polish_stiffened`])
/// made of a rounded map: the map, its
/// [`Quantizer::badness`] and that of the map it was given, the ARAP
/// iterations kept, whether the untangler left no fold, and the local
/// stiffening iterations it started from.
#[derive(Default)]
pub(super) struct Polished {
    pub(super) x: Vec<f64>,
    pub(super) bad: usize,
    pub(super) rounded_bad: usize,
    pub(super) arap_iterations: usize,
    pub(super) untangled: bool,
    pub(super) stiffening: usize,
}
