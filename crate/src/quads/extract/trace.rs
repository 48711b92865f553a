//! QEx step 3, `trace_edge`: follows the unit isoline segment of one slot
//! across the triangles, exactly, to the integer point where it ends.

use super::snap::{add, axis, cross, dot, in_range, orient, sub, Point, SnappedMap, Transition};
use super::vertices::{corner_sector, Place, QuadVertices, Slot};
use crate::TriMesh;

/// Why a trace was abandoned, and in which face.
pub(super) struct TraceFailure {
    pub face: u32,
    pub what: &'static str,
}

const OUT_OF_RANGE: &str = "trace is carried out of the representable UV range by inconsistent transitions";

/// The segment being traced, in the chart of face `face`: from `p` to `q`,
/// axis direction `dir`.
#[derive(Clone, Copy)]
struct Walk {
    face: u32,
    p: Point,
    q: Point,
    dir: u8,
}

impl Walk {
    /// The same segment in the chart reached through `tr`; `None` when it
    /// lands out of the exact range (only on inconsistent maps).
    fn through(self, tr: Transition, face: u32) -> Option<Walk> {
        let w = Walk { face, p: tr.apply(self.p), q: tr.apply(self.q), dir: (self.dir + tr.r) % 4 };
        (in_range(w.p) && in_range(w.q)).then_some(w)
    }
}

/// Where the segment leaves the current face.
enum Exit {
    /// Through the interior of edge `k` (corner `k` → `k + 1`).
    Edge(usize),
    /// Through corner `k` (also when running along an edge to its end).
    Corner(usize),
}

fn sign(x: i128) -> i8 {
    x.signum() as i8
}

/// The exit of the directed line `p → q` from a positive triangle `x` that it
/// crosses, from the sides of its corners; `None` when it does not cross it
/// (it only touches a corner, or the triangle is flipped or degenerate).
fn exit(x: [Point; 3], w: &Walk) -> Option<Exit> {
    let s: [i8; 3] = [0, 1, 2].map(|i| sign(orient(w.p, w.q, x[i])));
    let at = |i: usize| s[i % 3];
    if let Some(k) = (0..3).find(|&k| at(k) < 0 && at(k + 1) > 0) {
        return Some(Exit::Edge(k));
    }
    if let Some(k) = (0..3).find(|&k| at(k) == 0 && at(k + 1) > 0 && at(k + 2) < 0) {
        return Some(Exit::Corner(k));
    }
    let k = (0..3).find(|&k| at(k) == 0 && at(k + 1) == 0 && at(k + 2) != 0)?;
    let along = sub(x[(k + 1) % 3], x[k]);
    Some(Exit::Corner(if dot(along, axis(w.dir)) > 0 { (k + 1) % 3 } else { k }))
}

/// True when axis direction `dir` lies in the closed corner sector of face
/// halfedge `h` (a positive corner).
fn in_sector(mesh: &TriMesh, map: &SnappedMap, h: u32, dir: u8) -> bool {
    let (e1, e2) = corner_sector(mesh, map, h);
    let a = axis(dir);
    cross(e1, e2) > 0 && cross(e1, a) >= 0 && cross(a, e2) >= 0
}

/// The walk continued past mesh vertex at corner `c` of the walk's face: the
/// face of the fan whose corner sector holds the direction, found by turning
/// counter-clockwise and then (at a boundary) clockwise from the current
/// face, the segment carried along through the transitions.
fn pass_vertex(mesh: &TriMesh, map: &SnappedMap, w: Walk, c: usize) -> Option<Walk> {
    let h0 = 3 * w.face + c as u32;
    let (mut h, mut cur) = (h0, w);
    loop {
        if in_sector(mesh, map, h, cur.dir) {
            return Some(cur);
        }
        let inc = mesh.prev(h);
        let t = mesh.twin(inc);
        if mesh.is_boundary_halfedge(t) {
            break;
        }
        cur = cur.through(map.transition[inc as usize], t / 3)?;
        h = t;
        if h == h0 {
            return None;
        }
    }
    let (mut h, mut cur) = (h0, w);
    loop {
        let t = mesh.twin(h);
        if mesh.is_boundary_halfedge(t) {
            return None;
        }
        cur = cur.through(map.transition[h as usize], t / 3)?;
        h = mesh.next(t);
        if h == h0 {
            return None;
        }
        if in_sector(mesh, map, h, cur.dir) {
            return Some(cur);
        }
    }
}

/// The slot (global index) by which the walk arrives at its end `q`, which
/// lies in the closed face `w.face` with edge orientations `o` (all ≥ 0, not
/// all 0): the quad vertex there and its slot pointing back along the walk.
fn arrive(mesh: &TriMesh, map: &SnappedMap, qv: &QuadVertices, w: &Walk, o: [i128; 3]) -> Result<u32, &'static str> {
    let back = (w.dir + 2) % 4;
    let zeros = (0..3).filter(|&k| o[k] == 0).fold(0u8, |m, k| m | 1 << k);
    let (q, slot) = match zeros {
        0 => {
            let q =
                qv.face_point(w.face, w.q).ok_or("trace ends at a point inside a face that is not a quad vertex")?;
            (q, Slot { face: w.face, dir: back })
        }
        1 | 2 | 4 => {
            let h = 3 * w.face + zeros.trailing_zeros();
            let e = mesh.edge(h);
            let h0 = mesh.edge_halfedges(e)[0];
            let (p, dir) = if h == h0 {
                (w.q, back)
            } else {
                let tr = map.transition[h as usize];
                (tr.apply(w.q), (back + tr.r) % 4)
            };
            let q = qv.edge_point(e, p).ok_or("trace ends at a point on an edge that is not a quad vertex")?;
            (q, Slot { face: h0 / 3, dir })
        }
        3 | 5 | 6 => {
            // On edges k and k + 1 means at corner k + 1.
            let c = match zeros {
                3 => 1,
                6 => 2,
                _ => 0,
            };
            let v = mesh.faces()[w.face as usize][c];
            let q = qv.vertex_point(v).ok_or("trace ends at a mesh vertex whose UV is not an integer point")?;
            let h = 3 * w.face + c as u32;
            let (_, e2) = corner_sector(mesh, map, h);
            let a = axis(back);
            let inc = mesh.prev(h);
            let t = mesh.twin(inc);
            let slot = if cross(a, e2) == 0 && dot(a, e2) > 0 && !mesh.is_boundary_halfedge(t) {
                // Along e2: registered in the next face counter-clockwise.
                let tr = map.transition[inc as usize];
                Slot { face: t / 3, dir: (back + tr.r) % 4 }
            } else {
                Slot { face: w.face, dir: back }
            };
            (q, slot)
        }
        _ => return Err("trace ends in a degenerate UV triangle"),
    };
    qv.find_slot(q, slot).ok_or("trace arrives at a quad vertex from a direction it has no slot for")
}

/// Traces the unit isoline segment leaving slot `s` (global index) and
/// returns the slot by which it arrives at the next integer point.
///
/// Exact: the segment's ends are integer points in fixed point, carried from
/// chart to chart by the exact transitions; the segment may pass through the
/// interior of faces, through mesh vertices and along mesh edges. Fails
/// (with the face where it gave up) when the segment leaves the surface,
/// meets a flipped or degenerate triangle, ends at no quad vertex, or crosses
/// more than `max_steps` triangles.
pub(super) fn trace_edge(
    mesh: &TriMesh,
    map: &SnappedMap,
    qv: &QuadVertices,
    s: u32,
    max_steps: usize,
) -> Result<u32, TraceFailure> {
    let slot = qv.slots[s as usize];
    let p = qv.slot_origin(mesh, map, s);
    let mut w = Walk { face: slot.face, p, q: add(p, axis(slot.dir)), dir: slot.dir };
    if let Place::Edge(e) = qv.list[qv.slot_owner[s as usize] as usize].place {
        let h0 = mesh.edge_halfedges(e)[0];
        let edge = sub(map.uv[mesh.next(h0) as usize], map.uv[h0 as usize]);
        if cross(edge, axis(w.dir)) < 0 {
            let t = mesh.twin(h0);
            if mesh.is_boundary_halfedge(t) {
                return Err(TraceFailure { face: slot.face, what: "trace leaves the surface" });
            }
            w = w
                .through(map.transition[h0 as usize], t / 3)
                .ok_or(TraceFailure { face: slot.face, what: OUT_OF_RANGE })?;
        }
    }
    let fail = |face: u32, what: &'static str| Err(TraceFailure { face, what });
    // The halfedge of the current face the walk came in through, if any.
    let mut entry = None;
    for _ in 0..max_steps {
        let x = map.corners(w.face);
        let o = [0, 1, 2].map(|k| orient(x[k], x[(k + 1) % 3], w.q));
        if o.iter().all(|&v| v >= 0) && o.iter().any(|&v| v != 0) {
            return arrive(mesh, map, qv, &w, o).map_err(|what| TraceFailure { face: w.face, what });
        }
        if orient(x[0], x[1], x[2]) <= 0 {
            return fail(w.face, "trace meets a flipped or degenerate UV triangle");
        }
        match exit(x, &w) {
            Some(Exit::Edge(k)) => {
                let h = 3 * w.face + k as u32;
                let t = mesh.twin(h);
                if mesh.is_boundary_halfedge(t) {
                    return fail(w.face, "trace leaves the surface");
                }
                if entry == Some(h) {
                    return fail(w.face, "trace turns back through the edge it came in by (inconsistent transitions)");
                }
                match w.through(map.transition[h as usize], t / 3) {
                    Some(next) => w = next,
                    None => return fail(w.face, OUT_OF_RANGE),
                }
                entry = Some(t);
            }
            Some(Exit::Corner(c)) => match pass_vertex(mesh, map, w, c) {
                Some(next) => {
                    w = next;
                    entry = None;
                }
                None => return fail(w.face, "trace finds no face to continue in past a mesh vertex"),
            },
            None => return fail(w.face, "trace does not cross the triangle it is in"),
        }
    }
    fail(w.face, "trace did not reach an integer point within the step limit")
}
