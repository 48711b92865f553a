//! QEx step 1, `snap`: turns the floating-point corner UVs into an exact
//! integer-grid map in fixed point, so that every later predicate is an exact
//! integer computation.

use crate::quads::QuadDefect;
use crate::TriMesh;

/// Fixed-point resolution: one grid unit is `ONE` integer steps (2^32);
/// with coordinates up to 2^28 grid units, differences fit `i64` and
/// products `i128`.
pub(super) const ONE: i64 = 1 << 32;

/// A UV point (or vector) in fixed point.
pub(super) type Point = [i64; 2];

/// Points are kept within `±LIMIT` (2^60, the fixed-point image of
/// [`MAX_UV`](super::MAX_UV)): then a transition (translation below 2^61)
/// cannot overflow `i64`, nor an orientation `i128`.
const LIMIT: i64 = 1 << 60;

/// True when `p` is within the range every predicate is exact for.
pub(super) fn in_range(p: Point) -> bool {
    p[0].abs() <= LIMIT && p[1].abs() <= LIMIT
}

/// The axis direction `dir` (0: +u, 1: +v, 2: −u, 3: −v; counter-clockwise)
/// as a vector of one grid unit.
pub(super) fn axis(dir: u8) -> Point {
    rotate([ONE, 0], dir)
}

/// `p` rotated by `r` quarter turns counter-clockwise.
pub(super) fn rotate(p: Point, r: u8) -> Point {
    match r % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    }
}

pub(super) fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

pub(super) fn add(a: Point, b: Point) -> Point {
    [a[0] + b[0], a[1] + b[1]]
}

/// Exact 2D cross product `u × v`.
pub(super) fn cross(u: Point, v: Point) -> i128 {
    u[0] as i128 * v[1] as i128 - u[1] as i128 * v[0] as i128
}

/// Exact dot product.
pub(super) fn dot(u: Point, v: Point) -> i128 {
    u[0] as i128 * v[0] as i128 + u[1] as i128 * v[1] as i128
}

/// Twice the signed area of `(a, b, c)`: positive when counter-clockwise.
pub(super) fn orient(a: Point, b: Point, c: Point) -> i128 {
    cross(sub(b, a), sub(c, a))
}

/// True when the fixed-point coordinate `x` is an integer of the grid.
pub(super) fn is_integer(x: i64) -> bool {
    x.rem_euclid(ONE) == 0
}

/// A grid automorphism `x ↦ Rʳ x + t` (R the counter-clockwise quarter turn,
/// `t` a multiple of [`ONE`]): the map from one face's chart to its
/// neighbour's across an edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Transition {
    pub r: u8,
    pub t: Point,
}

impl Transition {
    pub const IDENTITY: Transition = Transition { r: 0, t: [0, 0] };

    /// The image of point `p`.
    pub fn apply(&self, p: Point) -> Point {
        add(rotate(p, self.r), self.t)
    }

    /// The inverse map (`x ↦ R⁻ʳ (x − t)`).
    pub fn inverse(&self) -> Transition {
        let r = (4 - self.r) % 4;
        let t = rotate(self.t, r);
        Transition { r, t: [-t[0], -t[1]] }
    }
}

/// The exact map: fixed-point UV per face corner and the transition of
/// every face halfedge `h` (chart of `face(h)` → chart of `face(twin(h))`;
/// identity on boundary edges).
pub(super) struct SnappedMap {
    pub uv: Vec<Point>,
    pub transition: Vec<Transition>,
}

impl SnappedMap {
    /// The three corner UVs of face `f`.
    pub fn corners(&self, f: u32) -> [Point; 3] {
        let c = 3 * f as usize;
        [self.uv[c], self.uv[c + 1], self.uv[c + 2]]
    }
}

/// `x` in fixed point of `one` steps per grid unit, snapped to the nearest
/// integer when within `tol` of it.
fn snap_coordinate(x: f64, tol: f64, one: i64) -> i64 {
    let r = x.round();
    if (x - r).abs() <= tol {
        r as i64 * one
    } else {
        (x * one as f64).round() as i64
    }
}

/// Snaps `uv` (one finite UV per face corner, `|uv| ≤ 2^28`) to an exact
/// integer-grid map.
///
/// Per interior edge the transition is the quarter-turn rotation that best
/// matches the edge vector on both sides, with the rounded translation; a
/// translation further than `tol` from an integer is recorded as a defect.
/// Per mesh vertex the first corner of its fan (the master) is snapped
/// (coordinates within `tol` of an integer become that integer) and every
/// other corner is set from it by composing the exact transitions around
/// the fan, so that all corners agree exactly across every edge. A fan whose
/// transitions do not close up on the master (holonomy that does not fix
/// it), or a cone whose UV is not an integer point, is recorded as a defect.
pub(super) fn snap(mesh: &TriMesh, uv: &[[f64; 2]], tol: f64, defects: &mut Vec<QuadDefect>) -> SnappedMap {
    snap_at(mesh, uv, tol, ONE, defects)
}

/// [`snap`] in a fixed point of `one` steps per grid unit (a power of two
/// at most [`ONE`]); the points are then in that fixed point.
pub(super) fn snap_at(mesh: &TriMesh, uv: &[[f64; 2]], tol: f64, one: i64, defects: &mut Vec<QuadDefect>) -> SnappedMap {
    let n3 = 3 * mesh.n_faces();
    let mut transition = vec![Transition::IDENTITY; n3];
    for h in 0..n3 as u32 {
        let th = mesh.twin(h);
        if mesh.is_boundary_halfedge(th) || th < h {
            continue;
        }
        // h: corner a → b of face f; th: corner b → a of face g.
        let (a, b) = (h as usize, mesh.next(h) as usize);
        let (gb, ga) = (th as usize, mesh.next(th) as usize);
        let vf = [uv[b][0] - uv[a][0], uv[b][1] - uv[a][1]];
        let vg = [uv[gb][0] - uv[ga][0], uv[gb][1] - uv[ga][1]];
        let rot_f = |p: [f64; 2], r: u8| match r {
            0 => p,
            1 => [-p[1], p[0]],
            2 => [-p[0], -p[1]],
            _ => [p[1], -p[0]],
        };
        let mismatch = |r: u8| {
            let q = rot_f(vf, r);
            (q[0] - vg[0]).powi(2) + (q[1] - vg[1]).powi(2)
        };
        let r = (0..4u8).min_by(|&x, &y| mismatch(x).total_cmp(&mismatch(y))).unwrap_or(0);
        let (ra, rb) = (rot_f(uv[a], r), rot_f(uv[b], r));
        let mut t = [0i64; 2];
        let mut off = 0f64;
        for i in 0..2 {
            let ta = uv[ga][i] - ra[i];
            let tb = uv[gb][i] - rb[i];
            let ti = (0.5 * (ta + tb)).round();
            off = off.max((ta - ti).abs()).max((tb - ti).abs());
            t[i] = ti as i64 * one;
        }
        if off > tol {
            defects.push(QuadDefect {
                face: h / 3,
                what: format!(
                    "transition across edge {} is not a grid automorphism (off by {off:.3e}); rounded to a quarter turn and an integer translation",
                    mesh.edge(h)
                ),
            });
        }
        let tr = Transition { r, t };
        transition[h as usize] = tr;
        transition[th as usize] = tr.inverse();
    }

    let mut fixed = vec![[0i64; 2]; n3];
    for v in 0..mesh.n_vertices() as u32 {
        let h0 = mesh.vertex_halfedge(v);
        let m = uv[h0 as usize];
        let master = [snap_coordinate(m[0], tol, one), snap_coordinate(m[1], tol, one)];
        fixed[h0 as usize] = master;
        let (mut cur, mut p, mut turns) = (h0, master, 0u32);
        for _ in 0..mesh.n_halfedges() {
            let inc = mesh.prev(cur);
            let nxt = mesh.twin(inc);
            if mesh.is_boundary_halfedge(nxt) {
                break;
            }
            let tr = transition[inc as usize];
            p = tr.apply(p);
            turns += tr.r as u32;
            if !in_range(p) {
                // Inconsistent transitions drifted out of range: restart from
                // this corner's own UV (the fan is broken there anyway).
                let own = uv[nxt as usize];
                p = [snap_coordinate(own[0], tol, one), snap_coordinate(own[1], tol, one)];
                defects.push(QuadDefect {
                    face: nxt / 3,
                    what: format!("transitions around vertex {v} drift out of range; corner taken as given"),
                });
            }
            if nxt == h0 {
                if p != master {
                    defects.push(QuadDefect {
                        face: h0 / 3,
                        what: format!("transitions around vertex {v} do not close up on its UV; the last edge of its fan is inconsistent"),
                    });
                } else if turns % 4 != 0 && !(master[0].rem_euclid(one) == 0 && master[1].rem_euclid(one) == 0) {
                    defects.push(QuadDefect {
                        face: h0 / 3,
                        what: format!("cone at vertex {v} is not on an integer point"),
                    });
                }
                break;
            }
            fixed[nxt as usize] = p;
            cur = nxt;
        }
    }
    SnappedMap { uv: fixed, transition }
}
