//! Tube periods: the translation across a seam curve without rotation
//! whose dual loop (a loop crossing the cut once, at that curve) goes around
//! a thin part of the surface (a horn, a leg, a handle) instead of around a
//! disk. Such a loop develops into a straight segment: the translation is
//! the part's circumference in grid steps, and a circumference of one or
//! two steps (`|t_u| + |t_v| < 3`) puts two quads around the part on the
//! same four vertices (or one quad onto itself), which no quad mesh can
//! close. Where the loop goes around a disk instead (a dipole of cones, a
//! square hole) it turns once as it develops, and the translation is a
//! Burgers vector, a closing gap that may rightly be 0, 1 or 2 steps.
//!
//! Which is which comes from the seamless map: walking the disk's boundary
//! from one side of the curve's first edge to the other, the dual loop
//! turns by `T = pi + sum (theta_w - pi)` over the boundary wedges passed
//! (`theta_w` the wedge's UV angle; a lone cone of angle `theta` gives
//! `T = theta`); `T = ±2 pi` is a loop around a disk, any other multiple of
//! `2 pi` (0 around a tube) a period. Only loops that cross one curve are
//! seen: a tube with two seam curves along it (their half-turns composing
//! to a translation) is not.
//!
//! The rule acts like a separation ([`super::super::separation`]): once the
//! rounded forms determine a tube period at fewer than [`TUBE_STEPS`] steps,
//! [`Quantizer::widen_periods`] moves the integers that determine it.

use super::fit::{RoundedSystem, Trials};
use super::rounding::distance_to_integer;
use super::super::separation::Separations;
use super::{corner_angle_sums, QuantizeError, Quantizer, NEAR_INTEGER};
use crate::mesh::TriMesh;
use crate::param::cut_graph::CutGraph;
use crate::param::seamless::curve_wedge_pairs;
use std::f64::consts::PI;

/// Least circumference of a tube, in grid steps (`|t_u| + |t_v|`).
pub(super) const TUBE_STEPS: i64 = 3;
/// Solves spent widening tube periods after a batch, at most.
pub(super) const PERIOD_TRIALS: usize = 48;
/// Integers tried per step of a tube period.
const CANDIDATES_PER_PERIOD: usize = 16;

/// The translation `t = f_g - f_f` (no rotation) of a seam curve around a
/// tube: per coordinate, its row of unknowns.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TubePeriod {
    pub(super) rows: [Vec<(usize, i64)>; 2],
}

impl TubePeriod {
    /// `t` in `x`.
    pub(super) fn value(&self, x: &[f64]) -> [f64; 2] {
        [0, 1].map(|c| self.rows[c].iter().map(|&(u, a)| a as f64 * x[u]).sum())
    }

    /// Whether `x` determines the period (both components integers) at
    /// fewer than [`TUBE_STEPS`] steps.
    pub(super) fn violated(&self, x: &[f64]) -> bool {
        let t = self.value(x);
        t.iter().all(|&y| distance_to_integer(y) < NEAR_INTEGER) && steps(t) < TUBE_STEPS
    }

    /// The row that widens the period: its component largest in the seamless
    /// map `x0`, signed to grow the way it points there.
    fn widening_row(&self, x0: &[f64]) -> Vec<(usize, i64)> {
        let t0 = self.value(x0);
        let c = if t0[1].abs() > t0[0].abs() { 1 } else { 0 };
        let sign = if t0[c] < 0.0 { -1 } else { 1 };
        self.rows[c].iter().map(|&(u, a)| (u, sign * a)).collect()
    }
}

/// `|t_u| + |t_v|`, rounded.
fn steps(t: [f64; 2]) -> i64 {
    (t[0].abs() + t[1].abs()).round() as i64
}

/// The tube periods of the cut `cut` of `mesh` with unknowns `vars` in the
/// seamless map `uv` (per face corner): every seam curve without rotation
/// whose dual loop turns by other than `±2 pi` (module doc). O(cut length).
pub(super) fn tube_periods(mesh: &TriMesh, cut: &CutGraph, vars: &[Vec<usize>; 2], uv: &[[f64; 2]]) -> Vec<TubePeriod> {
    let on_cut = |h: u32| {
        let e = mesh.edge(h);
        cut.is_seam[e as usize] || mesh.is_boundary_halfedge(mesh.twin(h))
    };
    let wedge_faces: Vec<[u32; 3]> = cut.wedge.chunks(3).map(|w| [w[0], w[1], w[2]]).collect();
    let theta = corner_angle_sums(&wedge_faces, cut.n_wedges, |f| [uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]]);
    // The disk's boundary walks: per face halfedge on the cut, its walk, its
    // place on it and the sum of (theta - pi) over the wedges before it.
    const NOT_ON_CUT: usize = usize::MAX;
    let n_face_halfedges = 3 * mesh.n_faces();
    let mut walk_of = vec![NOT_ON_CUT; n_face_halfedges];
    let mut place = vec![0usize; n_face_halfedges];
    let mut before = vec![0.0; n_face_halfedges];
    let mut walk_turning: Vec<f64> = Vec::new();
    for start in 0..n_face_halfedges as u32 {
        if walk_of[start as usize] != NOT_ON_CUT || !on_cut(start) {
            continue;
        }
        let (id, mut h, mut sum) = (walk_turning.len(), start, 0.0);
        for i in 0.. {
            walk_of[h as usize] = id;
            place[h as usize] = i;
            before[h as usize] = sum;
            // Around the head, through the faces of its wedge, to the next cut edge.
            let mut next = mesh.next(h);
            while !on_cut(next) {
                next = mesh.next(mesh.twin(next));
            }
            sum += theta[cut.wedge[mesh.next(h) as usize] as usize] - PI;
            h = next;
            if h == start {
                break;
            }
        }
        walk_turning.push(sum);
    }
    let mut periods = Vec::new();
    for curve in cut.curves.iter().filter(|c| c.matching.rem_euclid(4) == 0) {
        let (f_side, g_side) = (curve.halfedges[0], mesh.twin(curve.halfedges[0]));
        let id = walk_of[f_side as usize];
        if id != walk_of[g_side as usize] {
            continue; // the sides lie in different disks: no loop crosses this curve alone
        }
        let (f, g) = (f_side as usize, g_side as usize);
        let arc = before[g] - before[f] + if place[g] < place[f] { walk_turning[id] } else { 0.0 };
        let turns = ((PI + arc) / (2.0 * PI)).round() as i64;
        if turns.abs() == 1 {
            continue;
        }
        let (fa, ga) = curve_wedge_pairs(mesh, cut, curve)[0];
        periods.push(TubePeriod { rows: [0, 1].map(|c| vec![(vars[c][ga as usize], 1), (vars[c][fa as usize], -1)]) });
    }
    periods
}

impl Quantizer {
    /// Widens the tube periods the rounded forms leave at fewer than
    /// [`TUBE_STEPS`] steps: as [`Self::separate`] does for separations, the
    /// period's change per unit change of every rounded integer from one
    /// adjoint solve, then the integers that widen it, closest to their
    /// seamless values first, tried moved (each from the moved row's
    /// response, [`RoundedSystem::response`]); a move is kept when every
    /// form stays integer, the period gains and no more separations are
    /// violated. At most
    /// [`Self::budget`]`(PERIOD_TRIALS)` solves. Returns the moves kept.
    pub(super) fn widen_periods(
        &self,
        system: &mut RoundedSystem,
        values: &mut [Option<i64>],
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        separations: &Separations,
    ) -> Result<usize, QuantizeError> {
        let (mut moves, mut trials, max_trials) = (0, 0, self.budget(PERIOD_TRIALS));
        for period in &self.tube_periods {
            while period.violated(&system.x) && trials < max_trials {
                let mut candidates = self.widening_moves(system, &period.widening_row(x0), values, x0)?;
                trials += 1;
                let (steps_before, violated_before) = (steps(period.value(&system.x)), separations.violated(&system.x, NEAR_INTEGER).len());
                let mut kept = false;
                candidates.truncate(CANDIDATES_PER_PERIOD.min(max_trials.saturating_sub(trials)));
                let mut ahead = Trials::new(candidates.iter().map(|c| c.2));
                for (i, (_, form, row, step)) in candidates.into_iter().enumerate() {
                    trials += 1;
                    let x = ahead.resolve_moved(system, i, step)?;
                    let mut trial = values.to_vec();
                    trial[form] = values[form].map(|v| v + step);
                    if self.rounded_forms_integral(&trial, &x)
                        && steps(period.value(&x)) > steps_before
                        && separations.violated(&x, NEAR_INTEGER).len() <= violated_before
                    {
                        system.take_move(self, targets, row, step)?;
                        values.copy_from_slice(&trial);
                        self.take_determined_values(values, &system.x);
                        (moves, kept) = (moves + 1, true);
                        break;
                    }
                }
                if !kept {
                    break;
                }
            }
        }
        Ok(moves)
    }

    /// The tube periods `x` leaves at fewer than [`TUBE_STEPS`] steps.
    pub(super) fn periods_violated(&self, x: &[f64]) -> usize {
        self.tube_periods.iter().filter(|p| p.violated(x)).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::square_annulus;
    use crate::cones::{place_cones, ConeOptions};
    use crate::features::FeatureSet;
    use crate::mesh::shapes;
    use crate::param::field::cross_field;
    use crate::param::seamless::unknowns;
    use crate::param::{cut_graph::cut_graph, parametrize, ParamOptions};

    /// The seam curves without rotation of `mesh`'s cut, and its tube periods.
    fn periods_of(mesh: &TriMesh) -> (usize, Vec<TubePeriod>) {
        let placement = place_cones(mesh, &FeatureSet::none(mesh), &ConeOptions::default(), &mut |_| {}).unwrap();
        let param = parametrize(mesh, &placement, &ParamOptions::default(), &mut |_| {}).unwrap();
        let field = cross_field(mesh, &placement).unwrap();
        let cut = cut_graph(mesh, &placement, &field).unwrap();
        let (vars, _) = unknowns(mesh, &field, &cut);
        let straight = cut.curves.iter().filter(|c| c.matching.rem_euclid(4) == 0).count();
        (straight, tube_periods(mesh, &cut, &vars, &param.uv))
    }

    /// An open tube's seam, joining its two rims, is crossed by the loop
    /// around the tube: a period (its circumference). A flat square
    /// annulus's seam, joining the hole to the outer square, is crossed by
    /// the loop around the hole, which turns once as it develops (the hole's
    /// corners square it off): a Burgers vector, no period.
    #[test]
    fn the_loop_around_a_tube_is_a_period_and_around_a_square_hole_is_not() {
        let tube = TriMesh::from_raw(&shapes::grid(24, 40, |u, v| {
            let a = if u == 1.0 { 0.0 } else { 2.0 * PI * u };
            [a.cos(), a.sin(), 6.0 * v]
        }))
        .unwrap();
        let (straight, periods) = periods_of(&tube);
        assert_eq!((straight, periods.len()), (1, 1));
        let (straight, periods) = periods_of(&square_annulus(4, 4, 0.4, 0.0));
        assert!(straight >= 1, "no seam without rotation: the case this tests is gone");
        assert_eq!(periods, vec![]);
    }
}
