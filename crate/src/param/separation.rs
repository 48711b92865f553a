//! Which integers of quantization must stay apart (the collapse constraints
//! of Bommes et al. 2013, "Integer-Grid Maps for Reliable Quad Meshing", in
//! their simplest form): two singular points or isolines that are near each
//! other on the surface and side by side along a coordinate must not land
//! on the same grid line of that coordinate, or the surface between them is
//! squeezed onto it (collapsed or flipped triangles, a vertex the map winds
//! around, holes in the quad mesh).
//!
//! The pairs are of unknowns that end up integers (both coordinates of
//! every wedge of a cone or corner, isoline constants): coordinates of one
//! chart of the cut disk, so two of them compare directly. An unknown that
//! is not rounded itself (a cone's wedge on the far side of a seam) becomes
//! integer once the translations are. Two are *near* when their
//! vertices share the star of a disk vertex (at most two edges apart, never
//! across a seam), or when one is a singular point (a cone or corner: both
//! coordinates integers) and the other within a grid cell of it through the
//! triangles of its chart (on a fine mesh a cell spans several edges, and
//! two cones four edges apart could otherwise share a grid point); and
//! *side by side along `c`* when their displacement in the seamless map is
//! at least as long along `c` as along the other coordinate (a cone at the
//! end of an isoline, or two cones one above the other, may share the
//! line); or when they are the corners of one triangle
//! (which they would collapse, whatever the direction); or when one is an
//! isoline and the other lies between two of its vertices along it (a cone
//! a fraction of a cell from a feature curve: the CAD cylinder's rim).
//!
//! [`HeldApart`] is the active set of a pass that holds violated pairs as
//! rows of its solves.

use super::element::{Element, NearWedges};
use std::collections::HashSet;

/// Unknown `hi` must exceed unknown `lo` by at least one (grid units).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct Separation {
    pub lo: usize,
    pub hi: usize,
}

/// The separations among the unknowns marked `integral`, from the seamless map
/// `seamless` in grid units: pairs near in the star of a disk vertex (any
/// scale), and pairs of a singular point and a corner within `radius` grid
/// units of it through the chart (where a cell spans several edges, two
/// cones less than a cell apart are further apart than a star). A pair whose
/// order differs between two of its vertex pairs is left out (it cannot be
/// kept apart on one side).
pub(super) fn separations(elements: &[Element], integral: &[bool], seamless: &[f64], radius: f64) -> Vec<Separation> {
    let n_wedges = elements.iter().flat_map(|el| el.w).max().map_or(0, |w| w + 1);
    // Per wedge: the form corners of its star, (unknown, coordinate, seamless uv).
    let mut star: Vec<Vec<Corner>> = vec![Vec::new(); n_wedges];
    for el in elements {
        for corner in form_corners(el, integral, seamless) {
            for &w in &el.w {
                push_corner(&mut star[w], corner);
            }
        }
    }
    let mut found: HashSet<Separation> = HashSet::new();
    for corners in &star {
        side_by_side(corners, 0..corners.len(), &mut found);
    }
    // Pairs of a singular point (both coordinates integers) and the corners
    // within `radius` of it, reached through the triangles of its chart.
    let mut near = NearWedges::new(elements, n_wedges);
    let mut ball: Vec<Corner> = Vec::new();
    for el0 in elements {
        for k0 in 0..3 {
            let w0 = el0.w[k0];
            if radius <= 0.0 || near.started(w0) || !(0..2).all(|c| integral[el0.x[c][k0]]) {
                continue;
            }
            let p0 = [seamless[el0.x[0][k0]], seamless[el0.x[1][k0]]];
            ball.clear();
            ball.extend((0..2).map(|c| (el0.x[c][k0], c, p0)));
            near.walk(elements, seamless, w0, p0, radius, |f| {
                for corner in form_corners(&elements[f], integral, seamless) {
                    push_corner(&mut ball, corner);
                }
            });
            side_by_side(&ball, 0..2, &mut found);
        }
    }
    // A triangle whose corners are two forms of one coordinate collapses
    // when they are equal, whatever the direction between them.
    for el in elements {
        for c in 0..2 {
            let t = el.x[c];
            if t.iter().any(|&u| !integral[u]) {
                continue;
            }
            let Some(k) = (1..3).find(|&k| t[k] != t[0]) else { continue };
            if (1..3).any(|j| t[j] != t[0] && t[j] != t[k]) {
                continue;
            }
            let (ya, yb) = (seamless[el.x[c][0]], seamless[el.x[c][k]]);
            if ya != yb {
                let (a, b) = (t[0], t[k]);
                found.insert(if yb > ya { Separation { lo: a, hi: b } } else { Separation { lo: b, hi: a } });
            }
        }
    }
    let mut list: Vec<Separation> =
        found.iter().copied().filter(|s| !found.contains(&Separation { lo: s.hi, hi: s.lo })).collect();
    list.sort_unstable_by_key(|s| (s.lo, s.hi));
    list
}

/// A corner of an integer unknown: (unknown, coordinate, seamless uv).
type Corner = (usize, usize, [f64; 2]);

/// The corners of `el` whose unknowns are `integral`.
fn form_corners<'a>(el: &'a Element, integral: &'a [bool], seamless: &'a [f64]) -> impl Iterator<Item = Corner> + 'a {
    (0..3).flat_map(move |k| {
        let p = [seamless[el.x[0][k]], seamless[el.x[1][k]]];
        (0..2).filter(move |&c| integral[el.x[c][k]]).map(move |c| (el.x[c][k], c, p))
    })
}

/// Adds `corner` to `corners` unless it is there.
fn push_corner(corners: &mut Vec<Corner>, corner: Corner) {
    if !corners.iter().any(|e| e.0 == corner.0 && e.2 == corner.2) {
        corners.push(corner);
    }
}

/// The separations between the corners `corners[centre]` and the others of
/// `corners` (all near each other): side by side along their coordinate, or
/// one beside an isoline between its ends along it (a cone next to a feature
/// curve, between two of its vertices, however short the step to the line).
fn side_by_side(corners: &[Corner], centre: std::ops::Range<usize>, found: &mut HashSet<Separation>) {
    let ordered = |a: usize, b: usize, ya: f64, yb: f64| if yb > ya { Separation { lo: a, hi: b } } else { Separation { lo: b, hi: a } };
    for &(a, c, pa) in &corners[centre.clone()] {
        for &(b, cb, pb) in corners {
            let d = [pb[0] - pa[0], pb[1] - pa[1]];
            if a == b || c != cb || d[c].abs() < d[1 - c].abs() || d[c] == 0.0 {
                continue;
            }
            found.insert(ordered(a, b, pa[c], pb[c]));
        }
    }
    // An isoline (one unknown at several corners) is a line: a corner beside
    // it between its ends along the line is side by side with it across it.
    for &(b, c, pb) in corners {
        let along = corners.iter().filter(|e| e.0 == b).map(|e| e.2[1 - c]);
        let (lo, hi) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        if !(hi > lo) {
            continue;
        }
        for &(a, ca, pa) in &corners[centre.clone()] {
            if a == b || ca != c || !(lo..=hi).contains(&pa[1 - c]) || pa[c] == pb[c] {
                continue;
            }
            found.insert(ordered(a, b, pa[c], pb[c]));
        }
    }
}

/// The separations of one grid size, and per form the ones it is in.
pub(super) struct Separations {
    pub list: Vec<Separation>,
    of_form: Vec<Vec<usize>>,
}

impl Separations {
    /// [`separations`] of the unknowns `integral` in the seamless map `seamless`
    /// (grid units) within `radius`, indexed by `form_of` (per unknown, the form
    /// that is it alone, `usize::MAX` if none; `n_forms` forms).
    pub fn new(elements: &[Element], integral: &[bool], seamless: &[f64], radius: f64, form_of: &[usize], n_forms: usize) -> Separations {
        let list = separations(elements, integral, seamless, radius);
        let mut of_form = vec![Vec::new(); n_forms];
        for (i, s) in list.iter().enumerate() {
            for u in [s.lo, s.hi] {
                if form_of[u] != usize::MAX {
                    of_form[form_of[u]].push(i);
                }
            }
        }
        Separations { list, of_form }
    }

    /// The integers form `i` (the unknown `form_of` maps to `i`) may take to
    /// stay a grid line from every rounded form (`value` of an unknown) it is
    /// separated from: `(lower, upper)`, empty when no integer meets all.
    pub fn bounds(&self, i: usize, form_of: &[usize], value: impl Fn(usize) -> Option<i64>) -> (i64, i64) {
        let (mut lower, mut upper) = (i64::MIN, i64::MAX);
        for &k in &self.of_form[i] {
            let sep = self.list[k];
            if form_of[sep.hi] == i {
                if let Some(lo) = value(sep.lo) {
                    lower = lower.max(lo + 1);
                }
            } else if let Some(hi) = value(sep.hi) {
                upper = upper.min(hi - 1);
            }
        }
        (lower, upper)
    }

    /// Separations whose two unknowns are integers in `x` (to `near`) and less than a grid line apart.
    pub fn violated(&self, x: &[f64], near: f64) -> Vec<Separation> {
        let integer = |y: f64| (y - y.round()).abs() < near;
        self.list.iter().copied().filter(|s| integer(x[s.lo]) && integer(x[s.hi]) && x[s.hi] - x[s.lo] < 1.0 - near).collect()
    }
}

/// The separations held as rows `x_hi - x_lo = gap` of a pass's solves
/// (`gap` an integer, 1 unless widened): each joins once a solve leaves its
/// pair less than a grid line apart, integers or not, and stays (an active
/// set that only grows: a pair pushed apart to one grid line would go back
/// without its row). The rows are dropped by the solve once the rounded
/// forms determine both unknowns.
#[derive(Default)]
pub(super) struct HeldApart {
    pub list: Vec<Separation>,
    pub gaps: Vec<i64>,
    set: HashSet<Separation>,
}

impl HeldApart {
    /// Holds every separation of `separations` violated in `x` (less than a
    /// grid line apart by more than `near`, integers or not); returns how
    /// many joined.
    pub fn hold_violated(&mut self, separations: &Separations, x: &[f64], near: f64) -> usize {
        let before = self.list.len();
        for &sep in &separations.list {
            if x[sep.hi] - x[sep.lo] < 1.0 - near && self.set.insert(sep) {
                self.list.push(sep);
                self.gaps.push(1);
            }
        }
        self.list.len() - before
    }

    /// The held pairs `x` leaves less than a grid line apart (by more than
    /// `near`): the rows the solve dropped as dependent on the others.
    pub fn violated(&self, x: &[f64], near: f64) -> Vec<Separation> {
        self.list.iter().copied().filter(|s| x[s.hi] - x[s.lo] < 1.0 - near).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cone one small step above a feature isoline `v = 0`, between two of
    /// its vertices and sharing no triangle with both: every displacement
    /// from the cone to an isoline vertex is longer along u than along v,
    /// yet the cone must stay a grid line above the isoline.
    #[test]
    fn a_cone_beside_an_isoline_between_its_vertices_stays_off_it() {
        // Wedges: 0, 1 on the isoline at u = 0 and 1; 2 an interior vertex;
        // 3 the cone. Unknowns: u of wedge i is i; v of the isoline is 10,
        // of wedge 2 is 12, of the cone 11.
        let x = |w: [usize; 3]| [w, w.map(|i| [10, 10, 12, 11][i])];
        let q = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let elements: Vec<Element> = [[0, 1, 2], [0, 2, 3], [2, 1, 3]].into_iter().map(|w| Element::new(q, 0.5, w, x(w))).collect();
        let mut seamless = vec![0.0; 13];
        seamless[..4].copy_from_slice(&[0.0, 1.0, 0.5, 0.5]);
        (seamless[10], seamless[12], seamless[11]) = (0.0, 0.05, 0.1);
        let mut integral = vec![false; 13];
        for u in [3, 10, 11] {
            integral[u] = true;
        }
        assert_eq!(separations(&elements, &integral, &seamless, 0.0), vec![Separation { lo: 10, hi: 11 }]);
    }

    /// Two cones four edges apart on a strip whose cell spans five edges
    /// share no star, yet could round onto one grid line: within a radius of
    /// a cell they are kept a line apart along the coordinate they are side
    /// by side in (u), and not along the one they share (v).
    #[test]
    fn cones_within_a_cell_are_kept_apart_beyond_their_stars() {
        // Vertices (i, j), i in 0..=5, j in 0..=1; wedge = vertex; u unknown
        // = vertex, v unknown = 12 + vertex; the cones are vertices 0 and 4.
        let id = |i: usize, j: usize| j * 6 + i;
        let mut elements = Vec::new();
        for i in 0..5 {
            let (a, b, c, d) = (id(i, 0), id(i + 1, 0), id(i + 1, 1), id(i, 1));
            for w in [[a, b, c], [a, c, d]] {
                let q = w.map(|v| [(v % 6) as f64, (v / 6) as f64]);
                elements.push(Element::new(q, 0.5, w, [w, w.map(|v| 12 + v)]));
            }
        }
        let mut seamless = vec![0.0; 24];
        for v in 0..12 {
            (seamless[v], seamless[12 + v]) = (0.2 * (v % 6) as f64, 0.2 * (v / 6) as f64);
        }
        let mut integral = vec![false; 24];
        for u in [0, 4, 12, 16] {
            integral[u] = true;
        }
        assert_eq!(separations(&elements, &integral, &seamless, 0.0), vec![]);
        assert_eq!(separations(&elements, &integral, &seamless, 1.0), vec![Separation { lo: 0, hi: 4 }]);
    }
}
