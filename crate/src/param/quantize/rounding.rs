//! One greedy rounding pass: the forms closest to an integer first, in
//! batches, the fit re-solved after each; separations restored by moving
//! the integers that determine them ([`Quantizer::separate`]), or held as
//! rows ([`HeldApart`]) and widened ([`Quantizer::widen_held`]); tube
//! periods widened the same way ([`Quantizer::widen_periods`]); then the
//! polish ([`super::polish`]).

use super::super::separation::{HeldApart, Separations};
use super::fit::{Fit, RoundedSystem, Trials};
use super::forms::FormKind;
use super::polish::Polished;
use super::{GridStart, Pass, QuantizeError, Quantizer, Rounded, FULL_BUDGET_FACES, NEAR_INTEGER};

/// Share of the remaining forms of a class rounded per batch.
const BATCH_FRACTION: f64 = 0.5;
/// Times a batch is solved again with its conflicting forms moved first.
const MAX_REORDERS: usize = 8;
/// Rounded integers moved, at most per batch, so that forms the others
/// determine come out integers ([`Quantizer::restore_parity`]).
const PARITY_MOVES: usize = 64;
/// Radius (grid units) within which an integer of the seamless map side by
/// side with a singular point must stay a grid line from it ([`Separations`]).
const SEPARATION_RADIUS: f64 = 1.0;
/// Re-solves spent restoring separations after a batch, at most.
pub(super) const SEPARATION_TRIALS: usize = 200;
/// Moves that mend one separation by breaking another, at most per batch.
const SIDEWAYS_MOVES: usize = 8;
/// Integers tried per violated separation.
const CANDIDATES_PER_SEPARATION: usize = 16;
/// Solves of the relaxed map before the held pass's first batch, each
/// holding the separations the one before left violated ([`HeldApart`]).
pub(super) const HOLD_ROUNDS: usize = 3;
/// Held rows the held pass may try widened by a line before its first batch
/// ([`Quantizer::widen_held`]; a share on large meshes, [`Quantizer::budget`]).
pub(super) const WIDEN_TRIALS: usize = 32;
/// Least share of the full budgets.
pub(super) const MIN_BUDGET_SHARE: f64 = 0.1;

impl Quantizer {
    /// One greedy rounding of all forms with the fit `fit` (batches of
    /// [`BATCH_FRACTION`], each re-solved, separations restored), then
    /// its polish ([`Self::stiffened`], [`Self::polish_stiffened`]) and,
    /// where the map is bad, the polish of the map with integers moved off
    /// its collapses ([`Self::polish_moved`]), keeping the better. With
    /// `pass.hold`, the relaxed map first and every batch after it hold the
    /// separations they leave violated ([`HeldApart`]); with `pass.widen`
    /// too, held rows are widened first ([`Self::widen_held`]), and the pass is not run
    /// (`None`) where that widens nothing: it would repeat the held pass.
    /// `bound`: the badness of the best map of the earlier passes where it
    /// is bad; a map far worse is not untangled ([`Self::polish_stiffened`]).
    pub(super) fn round_and_polish(&self, fit: &Fit, grid: &GridStart, pass: Pass, bound: Option<usize>, progress: &mut dyn FnMut(usize, usize)) -> Result<Option<Rounded>, QuantizeError> {
        let GridStart { x0, targets, s, rules } = grid;
        let s = *s;
        let separations = &rules.separations;
        let mut values: Vec<Option<i64>> = vec![None; self.forms.len()];
        let mut order: Vec<usize> = Vec::new();
        let mut x = x0.to_vec();
        let mut batches = 0;
        let mut separation_moves = 0;
        let mut period_moves = 0;
        let mut system = None;
        let mut held = HeldApart::default();
        let mut held_dropped = 0;
        if pass.hold {
            let mut relaxed = None;
            for _ in 0..HOLD_ROUNDS {
                if held.hold_violated(separations, &x, NEAR_INTEGER) == 0 {
                    break;
                }
                let solved = self.solve(fit, &order, &values, &x, targets, &held)?.0;
                x = solved.x.clone();
                relaxed = Some(solved);
            }
            if relaxed.is_none() && pass.widen {
                return Ok(None);
            }
            if let Some(mut relaxed) = relaxed {
                held_dropped = held.violated(&relaxed.x, NEAR_INTEGER).len();
                // A widened pass that widens nothing would repeat the held
                // pass step for step.
                if pass.widen && self.widen_held(&mut relaxed, &mut held, x0, targets)? == 0 {
                    return Ok(None);
                }
                x = relaxed.x;
            }
        }
        for kind in [FormKind::Cone, FormKind::Point, FormKind::Translation] {
            loop {
                let mut free: Vec<(f64, usize)> = (0..self.forms.len())
                    .filter(|&i| values[i].is_none() && self.forms[i].kind == kind && !rules.free[i])
                    .map(|i| (distance_to_integer(self.forms[i].value(&x)), i))
                    .collect();
                if free.is_empty() {
                    break;
                }
                free.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                // The nearest share of the forms, and every form already near
                // an integer.
                let near = free.iter().filter(|f| f.0 < NEAR_INTEGER).count();
                let take = ((free.len() as f64 * BATCH_FRACTION).ceil() as usize).max(near).min(free.len());
                let mut batch: Vec<usize> = free[..take].iter().map(|f| f.1).collect();
                let before = order.len();
                let mut retries = 0;
                let (solved, dependent) = loop {
                    for &i in &batch {
                        values[i] = None;
                    }
                    for &i in &batch {
                        values[i] = Some(self.rounding(i, &values, &x, separations));
                    }
                    order.truncate(before);
                    order.extend(&batch);
                    let (solved, dependent) = self.solve(fit, &order, &values, &x, targets, &held)?;
                    // A candidate the others determine at a non-integer value (a
                    // dependency with coefficient 1/2 the kind order missed): round
                    // it first instead, so that it determines them.
                    let conflicting: Vec<usize> = dependent
                        .iter()
                        .copied()
                        .filter(|&i| {
                            batch.contains(&i)
                                && distance_to_integer(self.forms[i].value(&solved.x))
                                    > NEAR_INTEGER
                        })
                        .collect();
                    if conflicting.is_empty() || retries == MAX_REORDERS {
                        break (solved, dependent);
                    }
                    retries += 1;
                    batch.retain(|i| !conflicting.contains(i));
                    batch.splice(0..0, conflicting);
                };
                let mut solved = solved;
                self.restore_parity(&mut solved, &dependent, &mut values, x0, targets)?;
                separation_moves += self.separate(&mut solved, &mut values, x0, targets, separations)?;
                if !self.tube_periods.is_empty() {
                    period_moves += self.widen_periods(&mut solved, &mut values, x0, targets, separations)?;
                }
                x = solved.x.clone();
                if pass.hold {
                    held.hold_violated(separations, &x, NEAR_INTEGER);
                }
                // A candidate the batch's other forms already determine takes the
                // value the solve gives it.
                for i in dependent {
                    values[i] = Some(self.forms[i].value(&x).round() as i64);
                }
                system = Some(solved);
                batches += 1;
                progress(
                    values.iter().filter(|v| v.is_some()).count(),
                    self.forms.len(),
                );
            }
        }
        // The rounded map polished (untangled where it folds, then ARAP);
        // where it is bad, the same with integers moved off the collapses
        // too ([`Self::polish_moved`]), keeping whichever ends less bad
        // (ties to the unmoved map). For the plain fit's passes the moved
        // map goes first, where the local stiffening leaves the map bad: its
        // badness bounds the unmoved map's untangling, which on a coarse
        // grid often cannot mend the map (fandisk >60 at 1 000 quads: 1 173
        // bad faces, 10 s, ending at 754, against the moved map's 64 after
        // 0.5 s). The stiffer fits are polished whatever the bound (and
        // stiffen faces around singular points already): their moved map
        // comes after, only where the unmoved one stays bad.
        let stiffen = fit.stiff_weight == 1.0;
        let mut moved_integers = 0;
        let mut polish = Polished::default();
        let mut rounded_bad = false;
        if let Some(mut system) = system {
            let start = self.stiffened(x.clone(), &system, targets, s, stiffen)?;
            rounded_bad = start.rounded_bad > 0;
            let mut moved = None;
            if stiffen && start.bad > 0 {
                moved = self.polish_moved(&values, &x, &mut system, x0, targets, s, separations, stiffen, bound)?;
            }
            let unmoved_bound = match &moved {
                Some(m) if m.polish.bad > 0 => Some(bound.map_or(m.polish.bad, |b| b.min(m.polish.bad))),
                _ => bound,
            };
            let unmoved = self.polish_stiffened(start, &system, targets, s, stiffen, unmoved_bound)?;
            if !stiffen && unmoved.bad > 0 {
                moved = self.polish_moved(&values, &x, &mut system, x0, targets, s, separations, stiffen, bound)?;
            }
            polish = unmoved;
            x = std::mem::take(&mut polish.x);
            if let Some(mut m) = moved.filter(|m| m.polish.bad < polish.bad) {
                (x, values, moved_integers) = (std::mem::take(&mut m.polish.x), m.values, m.moves);
                polish = m.polish;
            }
        }
        let (collapsed, wound, distortion, separations_violated) = self.assess(&x, s, targets, separations);
        let periods_violated = self.periods_violated(&x);
        Ok(Some(Rounded {
            passes_skipped: false,
            x,
            values,
            batches,
            separation_moves,
            period_moves,
            periods_violated,
            moved_integers,
            arap_iterations: polish.arap_iterations,
            untangled: polish.untangled,
            stiffening: polish.stiffening,
            collapsed,
            wound,
            distortion,
            stiff_weight: fit.stiff_weight,
            graded: fit.graded,
            separations: separations.list.len(),
            separations_held: held.list.len(),
            separations_widened: held.gaps.iter().filter(|&&g| g > 1).count(),
            held_dropped,
            rounded_bad,
            pass,
            separations_violated,
            free_curve_ends: self.curve_ends.iter().filter(|end| end.free_at(s)).count(),
        }))
    }

    /// The integer form `i` is rounded to: the nearest, unless that puts a
    /// triangle whose three corners lie on rounded forms of one coordinate
    /// (two feature isolines less than a cell apart, say) onto one grid
    /// line; then the next integer on `i`'s side of the others.
    pub(super) fn rounding(&self, i: usize, values: &[Option<i64>], x: &[f64], separations: &Separations) -> i64 {
        let y = self.forms[i].value(x);
        let v = y.round() as i64;
        for triple in &self.triples[i] {
            let others: Vec<usize> = triple.iter().copied().filter(|&j| j != i).collect();
            if !others.iter().all(|&j| values[j] == Some(v)) {
                continue;
            }
            let (lo, hi) = others
                .iter()
                .map(|&j| self.forms[j].value(x))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                    (l.min(y), h.max(y))
                });
            if y > hi {
                return self.separated(i, v + 1, values, separations);
            } else if y < lo {
                return self.separated(i, v - 1, values, separations);
            }
        }
        self.separated(i, v, values, separations)
    }

    /// `v` moved the least so that form `i` stays a grid line apart from
    /// every rounded form it must be separated from; `v` when no integer
    /// meets all of them.
    pub(super) fn separated(&self, i: usize, v: i64, values: &[Option<i64>], separations: &Separations) -> i64 {
        let value = |u: usize| self.form_of.get(u).and_then(|&f| values.get(f).copied().flatten());
        let (lower, upper) = separations.bounds(i, &self.form_of, value);
        if lower <= upper {
            v.clamp(lower, upper)
        } else {
            v
        }
    }

    /// Whether every rounded form (`values` set) is an integer in `x`.
    pub(super) fn rounded_forms_integral(&self, values: &[Option<i64>], x: &[f64]) -> bool {
        values.iter().zip(&self.forms).all(|(v, f)| v.is_none() || distance_to_integer(f.value(x)) < NEAR_INTEGER)
    }

    /// Every rounded form set to its (integer) value in `x`: a move of one
    /// integer moves the forms it determines by integers too.
    pub(super) fn take_determined_values(&self, values: &mut [Option<i64>], x: &[f64]) {
        for (value, form) in values.iter_mut().zip(&self.forms) {
            if value.is_some() {
                *value = Some(form.value(x).round() as i64);
            }
        }
    }

    /// The rules of grid size `s` for the seamless map `x0` (grid units):
    /// the separations within [`SEPARATION_RADIUS`], and the ends of curves
    /// shorter than [`super::forms::CURVE_END_CELLS`] left free.
    pub(super) fn size_rules(&self, x0: &[f64], s: f64) -> SizeRules {
        let separations = Separations::new(&self.elements, &self.integral, x0, SEPARATION_RADIUS, &self.form_of, self.forms.len());
        let mut free = vec![false; self.forms.len()];
        for end in self.curve_ends.iter().filter(|end| end.free_at(s)) {
            free[end.form] = true;
        }
        SizeRules { separations, free }
    }

    /// Restores violated separations after a batch: a form the others
    /// determine cannot be rounded apart directly, so for each violated pair
    /// the change of its gap per unit change of every rounded integer comes
    /// from one adjoint solve (`K⁻¹ [c; 0]`, the multipliers), and
    /// the integers that widen it, closest to their seamless values first,
    /// are tried moved by one (by two where the gap gains a half per unit),
    /// each from the moved row's response ([`RoundedSystem::response`]). A
    /// move is kept when every form stays integer and fewer separations stay
    /// violated; when none does, the cheapest move that mends one pair at
    /// the price of another is taken (at most [`SIDEWAYS_MOVES`], never back
    /// to a state seen before), since the collapse often moves along a chain
    /// of isolines before it finds room. Returns the moves kept.
    pub(super) fn separate(
        &self,
        system: &mut RoundedSystem,
        values: &mut [Option<i64>],
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        separations: &Separations,
    ) -> Result<usize, QuantizeError> {
        let mut violated = separations.violated(&system.x, NEAR_INTEGER);
        let (mut moves, mut trials, mut sideways) = (0, 0, 0);
        let mut seen = std::collections::HashSet::new();
        seen.insert(values.to_vec());
        let max_trials = self.budget(SEPARATION_TRIALS);
        while !violated.is_empty() && trials < max_trials {
            let mut best: Option<SeparationMove> = None;
            let mut improved = false;
            'pairs: for sep in violated.clone() {
                // The gap x_hi - x_lo is linear: one adjoint solve for it
                // (counted with the trials: each is a solve).
                if trials >= max_trials {
                    break 'pairs;
                }
                trials += 1;
                let moved_values = |form: usize, step: i64| {
                    let mut trial = values.to_vec();
                    trial[form] = Some(values[form].unwrap_or(0) + step);
                    trial
                };
                let mut candidates = self.widening_moves(system, &[(sep.hi, 1), (sep.lo, -1)], values, x0)?;
                candidates.truncate(CANDIDATES_PER_SEPARATION);
                candidates.retain(|&(_, form, _, step)| !seen.contains(&moved_values(form, step)));
                candidates.truncate(max_trials - trials);
                let mut ahead = Trials::new(candidates.iter().map(|c| c.2));
                for (i, &(_, form, row, step)) in candidates.iter().enumerate() {
                    let trial = moved_values(form, step);
                    trials += 1;
                    let x = ahead.resolve_moved(system, i, step)?;
                    if !self.rounded_forms_integral(&trial, &x) {
                        continue;
                    }
                    let after = separations.violated(&x, NEAR_INTEGER);
                    if after.len() < violated.len() {
                        best = Some(SeparationMove { row, step, values: trial });
                        improved = true;
                        break 'pairs;
                    }
                    if best.is_none() && after.len() == violated.len() && !after.contains(&sep) {
                        best = Some(SeparationMove { row, step, values: trial });
                    }
                }
            }
            let Some(SeparationMove { row, step, values: trial }) = best else { break };
            if !improved {
                if sideways == SIDEWAYS_MOVES {
                    break;
                }
                sideways += 1;
            }
            system.take_move(self, targets, row, step)?;
            values.copy_from_slice(&trial);
            self.take_determined_values(values, &system.x);
            seen.insert(values.to_vec());
            violated = separations.violated(&system.x, NEAR_INTEGER);
            moves += 1;
        }
        Ok(moves)
    }

    /// The moves of rounded integers that widen the linear form `gap` (of the
    /// unknowns) by about a grid line, cheapest first: per rounded row, its
    /// step ([`widening_step`] of the gap's change per unit change of the
    /// row, one adjoint solve for all rows), as `(cost, form, row, step)`,
    /// the cost the moved value's distance from the seamless map's `x0`.
    pub(super) fn widening_moves(
        &self,
        system: &RoundedSystem,
        gap: &[(usize, i64)],
        values: &[Option<i64>],
        x0: &[f64],
    ) -> Result<Vec<(f64, usize, usize, i64)>, QuantizeError> {
        let gain = system.sensitivity(gap)?;
        let mut moves: Vec<(f64, usize, usize, i64)> = system
            .form_rows
            .iter()
            .filter_map(|&(form, row)| {
                let v = values[form]?;
                let step = widening_step(gain[row])?;
                Some((((v + step) as f64 - self.forms[form].value(x0)).abs(), form, row, step))
            })
            .collect();
        moves.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(moves)
    }

    /// Moves rounded integers by one until every form in `dependent` (those
    /// the rounded forms determine) is an integer in `system.x` (at most
    /// [`PARITY_MOVES`]). Transitions of 90° are determined only up to a sublattice:
    /// a cone's position `c` across a seam of rotation `R` gives `(I - R) c`,
    /// of determinant 2, so a form may be determined at half an integer when
    /// the integers it depends on were rounded independently (a genus-2 block
    /// without features at 3 000 cells: 18 translations at n + 1/2). The form's
    /// dependence on every rounded row is one adjoint solve
    /// ([`RoundedSystem::sensitivity`]); of the rounded integers that a step
    /// of one makes it integral, the one whose step costs least (its new
    /// value nearest the seamless map's) moves, without a new factorization.
    pub(super) fn restore_parity(
        &self,
        system: &mut RoundedSystem,
        dependent: &[usize],
        values: &mut [Option<i64>],
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
    ) -> Result<(), QuantizeError> {
        for _ in 0..PARITY_MOVES {
            let off = |i: &&usize| distance_to_integer(self.forms[**i].value(&system.x)) > NEAR_INTEGER;
            let Some(&i) = dependent.iter().find(off) else { break };
            let value = self.forms[i].value(&system.x);
            let gain = system.sensitivity(&self.forms[i].row)?;
            let best = system
                .form_rows
                .iter()
                .flat_map(|&(form, row)| [(form, row, 1), (form, row, -1)])
                .filter(|&(_, row, step)| distance_to_integer(value + gain[row] * step as f64) < NEAR_INTEGER)
                .filter_map(|(form, row, step)| {
                    let v = values[form]?;
                    Some((((v + step) as f64 - self.forms[form].value(x0)).abs(), form, row, step))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let Some((_, form, row, step)) = best else { break };
            values[form] = values[form].map(|v| v + step);
            system.take_move(self, targets, row, step)?;
        }
        Ok(())
    }

    /// `full` scaled by the share of the full budgets this mesh gets
    /// ([`FULL_BUDGET_FACES`]), at least 1.
    pub(super) fn budget(&self, full: usize) -> usize {
        let share = (FULL_BUDGET_FACES / self.elements.len().max(1) as f64).clamp(MIN_BUDGET_SHARE, 1.0);
        ((full as f64 * share).round() as usize).max(1)
    }

    /// Widens held rows so that the pairs whose rows the solve dropped are
    /// parted too. On a box thinner than a cell the seams add the gaps of two
    /// held pairs into a third (`x27 - x28 = (x10 - x11) - (x0 - x2)`): at
    /// gap 1 each, the third's row is dependent and its pair left on one
    /// line, though as the inequalities they are (gap >= 1) all three can
    /// hold (one gap of 2). For each such pair of the relaxed map
    /// `system.x`, its gap's change per unit change of every held row comes
    /// from one adjoint solve ([`RoundedSystem::sensitivity`]); the held
    /// rows that widen it, least stretched first, are tried a line wider
    /// (two where it gains a half per line), each from the row's response
    /// ([`RoundedSystem::response`]); a trial is kept when fewer held pairs
    /// stay violated. At most [`Self::budget`]`(WIDEN_TRIALS)` solves. Returns the rows widened.
    pub(super) fn widen_held(&self, system: &mut RoundedSystem, held: &mut HeldApart, x0: &[f64], targets: &[[[f64; 2]; 2]]) -> Result<usize, QuantizeError> {
        let mut violated = held.violated(&system.x, NEAR_INTEGER);
        let (mut trials, max_trials, mut widened) = (0, self.budget(WIDEN_TRIALS), 0);
        for pair in violated.clone() {
            if !violated.contains(&pair) {
                continue;
            }
            if trials >= max_trials {
                break;
            }
            trials += 1;
            let gain = system.sensitivity(&[(pair.hi, 1), (pair.lo, -1)])?;
            let mut candidates: Vec<(f64, usize, usize, i64)> = system
                .held_rows
                .iter()
                .filter(|&&(k, _)| held.list[k] != pair)
                .filter_map(|&(k, row)| {
                    // Held gaps only grow.
                    let step = widening_step(gain[row]).filter(|&step| step > 0)?;
                    let sep = held.list[k];
                    Some(((held.gaps[k] + step) as f64 - (x0[sep.hi] - x0[sep.lo]), k, row, step))
                })
                .collect();
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            candidates.truncate(CANDIDATES_PER_SEPARATION.min(max_trials - trials));
            let mut ahead = Trials::new(candidates.iter().map(|c| c.2));
            for (i, (_, k, row, step)) in candidates.into_iter().enumerate() {
                trials += 1;
                let x = ahead.resolve_moved(system, i, step)?;
                let after = held.violated(&x, NEAR_INTEGER);
                if after.len() < violated.len() {
                    system.take_move(self, targets, row, step)?;
                    violated = held.violated(&system.x, NEAR_INTEGER);
                    held.gaps[k] += step;
                    widened += 1;
                    break;
                }
            }
        }
        Ok(widened)
    }
}

/// What quantization at one grid size keeps to beyond the forms.
pub(super) struct SizeRules {
    pub(super) separations: Separations,
    /// Per form: left free (the end of a curve shorter than [`super::forms::CURVE_END_CELLS`] cells).
    pub(super) free: Vec<bool>,
}

/// One integer moved by [`Quantizer::separate`]: the row of `c` changed by
/// `step` and the forms' values.
pub(super) struct SeparationMove {
    pub(super) row: usize,
    pub(super) step: i64,
    pub(super) values: Vec<Option<i64>>,
}

/// The change of a row's value that widens a gap by a grid line, from the
/// gap's `gain` per unit change of that row: one, or two where the gain is a
/// half (a translation across a half-turn seam: `f_g(P) + f_f(P) = 2 p`), in
/// the gain's direction; `None` where the row barely moves the gap.
pub(super) fn widening_step(gain: f64) -> Option<i64> {
    let magnitude = if gain.abs() > 0.75 { 1 } else { 2 };
    (gain.abs() > 0.25).then_some(if gain > 0.0 { magnitude } else { -magnitude })
}

/// `|y - round(y)|`.
pub(super) fn distance_to_integer(y: f64) -> f64 {
    (y - y.round()).abs()
}
