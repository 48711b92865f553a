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
//! across a seam), and *side by side along `c`* when their displacement in
//! the seamless map is at least as long along `c` as along the other
//! coordinate (a cone at the end of an isoline, or two cones one above the
//! other, may share the line); or when they are the corners of one triangle
//! (which they would collapse, whatever the direction); or when one is an
//! isoline and the other lies between two of its vertices along it (a cone
//! a fraction of a cell from a feature curve: the CAD cylinder's rim).

use super::element::Element;
use std::collections::HashSet;

/// Unknown `hi` must exceed unknown `lo` by at least one (grid units).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct Separation {
    pub lo: usize,
    pub hi: usize,
}

/// The separations among the unknowns marked `integral`, from the seamless map
/// `seamless` (any scale: only directions and signs are used). A pair whose
/// order differs between two of its vertex pairs is left out (it cannot be
/// kept apart on one side).
pub(super) fn separations(elements: &[Element], integral: &[bool], seamless: &[f64]) -> Vec<Separation> {
    let n_wedges = elements.iter().flat_map(|el| el.w).max().map_or(0, |w| w + 1);
    // Per wedge: the form corners of its star, (unknown, coordinate, seamless uv).
    let mut star: Vec<Vec<(usize, usize, [f64; 2])>> = vec![Vec::new(); n_wedges];
    for el in elements {
        for k in 0..3 {
            let p = [seamless[el.x[0][k]], seamless[el.x[1][k]]];
            for c in 0..2 {
                let form = el.x[c][k];
                if !integral[form] {
                    continue;
                }
                for &w in &el.w {
                    if !star[w].iter().any(|e| e.0 == form && e.2 == p) {
                        star[w].push((form, c, p));
                    }
                }
            }
        }
    }
    let mut found: HashSet<Separation> = HashSet::new();
    for corners in &star {
        for (i, &(a, c, pa)) in corners.iter().enumerate() {
            for &(b, cb, pb) in &corners[i + 1..] {
                if a == b || c != cb {
                    continue;
                }
                let d = [pb[0] - pa[0], pb[1] - pa[1]];
                if d[c].abs() < d[1 - c].abs() || d[c] == 0.0 {
                    continue;
                }
                found.insert(if d[c] > 0.0 { Separation { lo: a, hi: b } } else { Separation { lo: b, hi: a } });
            }
        }
        // An isoline (one unknown at several corners of the star) is a line:
        // a corner beside it, between its ends along the line, is side by
        // side with it across the line however short the step to the line
        // (a cone next to a feature curve, between two of its vertices).
        for &(b, c, pb) in corners {
            let along = corners.iter().filter(|e| e.0 == b).map(|e| e.2[1 - c]);
            let (lo, hi) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
            if !(hi > lo) {
                continue;
            }
            for &(a, ca, pa) in corners {
                if a == b || ca != c || !(lo..=hi).contains(&pa[1 - c]) || pa[c] == pb[c] {
                    continue;
                }
                found.insert(if pb[c] > pa[c] { Separation { lo: a, hi: b } } else { Separation { lo: b, hi: a } });
            }
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

/// Per form: the separations it takes part in (indices into `list`), with
/// `form_of` the form of each unknown that is one (`usize::MAX` if none).
pub(super) fn by_form(list: &[Separation], form_of: &[usize], n_forms: usize) -> Vec<Vec<usize>> {
    let mut of = vec![Vec::new(); n_forms];
    for (i, s) in list.iter().enumerate() {
        for u in [s.lo, s.hi] {
            if form_of[u] != usize::MAX {
                of[form_of[u]].push(i);
            }
        }
    }
    of
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
        assert_eq!(separations(&elements, &integral, &seamless), vec![Separation { lo: 10, hi: 11 }]);
    }
}
