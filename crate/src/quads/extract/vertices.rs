//! QEx step 2: the quad vertices (integer points of the map) and their
//! outgoing isoline directions (`Slot`s), counter-clockwise.

use super::snap::{axis, cross, dot, is_integer, orient, sub, Point, SnappedMap, ONE};
use crate::mesh::NONE;
use crate::quads::QuadDefect;
use crate::TriMesh;

/// Where an integer point lies on the input mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Place {
    /// Strictly inside face `f`.
    Face(u32),
    /// Strictly inside edge `e`.
    Edge(u32),
    /// At mesh vertex `v`.
    Vertex(u32),
}

/// An integer point of the map. `uv` is in the chart of its home face:
/// the face itself, the face of `edge_halfedges(e)[0]` for an edge point,
/// the face of `vertex_halfedge(v)` for a vertex point.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadVertex {
    pub place: Place,
    pub uv: Point,
}

/// An outgoing isoline direction of a quad vertex: axis direction `dir`
/// (see [`axis`]) in the chart of face `face`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Slot {
    pub face: u32,
    pub dir: u8,
}

/// All quad vertices with their slots (CSR) and lookup tables.
pub(super) struct QuadVertices {
    pub list: Vec<QuadVertex>,
    /// Quad vertices `face_start[f]..face_start[f + 1]` are the points inside
    /// face `f`, sorted by `(v, u)`.
    face_start: Vec<u32>,
    /// Likewise for edges (sorted by `(u, v)` in the home chart).
    edge_start: Vec<u32>,
    /// Quad vertex at each mesh vertex, or `NONE`.
    at_vertex: Vec<u32>,
    /// Slots of quad vertex `q`: `slots[slot_start[q]..slot_start[q + 1]]`,
    /// counter-clockwise; for an open fan (boundary) from the boundary side
    /// with the surface on its left to the other boundary side.
    pub slot_start: Vec<u32>,
    pub slots: Vec<Slot>,
    /// Owner quad vertex of each slot.
    pub slot_owner: Vec<u32>,
    /// True when the fan of slots is open (the point is on the boundary).
    pub open: Vec<bool>,
}

fn div_floor(a: i64, b: i64) -> i64 {
    a.div_euclid(b)
}

/// The first axis direction counter-clockwise from `w` (inclusive), or
/// `None` for the zero vector.
fn first_axis_from(w: Point) -> Option<u8> {
    (0..4u8).find(|&d| {
        let a = axis(d);
        dot(w, a) > 0 && cross(w, a) >= 0
    })
}

/// Enumerates the integer points strictly inside triangle `x` (positive
/// orientation), row by row, appending them to `out`; gives up (false) when
/// more than `budget` rows or points would be needed.
fn face_points(x: [Point; 3], budget: usize, out: &mut Vec<Point>) -> bool {
    let ylo = x.iter().map(|p| p[1]).min().unwrap_or(0);
    let yhi = x.iter().map(|p| p[1]).max().unwrap_or(0);
    let (jlo, jhi) = (div_floor(ylo, ONE), div_floor(yhi, ONE));
    if (jhi - jlo) as u64 > budget as u64 {
        return false;
    }
    for j in jlo..=jhi {
        let yy = j * ONE;
        let (mut xlo, mut xhi) = (i64::MAX, i64::MIN);
        for i in 0..3 {
            let (a, b) = (x[i], x[(i + 1) % 3]);
            if (a[1] - yy).signum() * (b[1] - yy).signum() > 0 || a[1] == b[1] {
                continue;
            }
            let xc = a[0] as i128 + (yy - a[1]) as i128 * (b[0] - a[0]) as i128 / (b[1] - a[1]) as i128;
            xlo = xlo.min(xc as i64);
            xhi = xhi.max(xc as i64);
        }
        if xlo > xhi {
            continue;
        }
        let (ilo, ihi) = (div_floor(xlo, ONE), div_floor(xhi, ONE) + 1);
        if (ihi - ilo) as u64 > budget as u64 {
            return false;
        }
        for i in ilo..=ihi {
            let q = [i * ONE, yy];
            if (0..3).all(|k| orient(x[k], x[(k + 1) % 3], q) > 0) {
                out.push(q);
                if out.len() > budget {
                    return false;
                }
            }
        }
    }
    true
}

/// Enumerates the integer points strictly inside segment `a`–`b`, appending
/// them to `out` sorted by `(u, v)`; false when over `budget`.
fn edge_points(a: Point, b: Point, budget: usize, out: &mut Vec<Point>) -> bool {
    let d = sub(b, a);
    let start = out.len();
    if d[0] == 0 && d[1] == 0 {
        return true;
    }
    // Walk the coordinate that varies (u unless the edge is vertical).
    let k = if d[0] != 0 { 0 } else { 1 };
    let (lo, hi) = (a[k].min(b[k]), a[k].max(b[k]));
    let (ilo, ihi) = (div_floor(lo, ONE) + 1, div_floor(hi - 1, ONE));
    if ihi >= ilo && (ihi - ilo) as u64 > budget as u64 {
        return false;
    }
    for i in ilo..=ihi {
        let c = i * ONE;
        let num = (c - a[k]) as i128 * d[1 - k] as i128;
        if num % d[k] as i128 != 0 {
            continue;
        }
        let other = a[1 - k] as i128 + num / d[k] as i128;
        let Ok(other) = i64::try_from(other) else { continue };
        if !is_integer(other) {
            continue;
        }
        let mut q = [0; 2];
        q[k] = c;
        q[1 - k] = other;
        out.push(q);
    }
    out[start..].sort_unstable();
    true
}

impl QuadVertices {
    /// Enumerates the integer points of `map` (inside faces with positive UV
    /// area, inside edges, at mesh vertices; each exactly once, edge points in
    /// the chart of the edge's first halfedge) and their slots. Faces with
    /// non-positive UV area contribute no interior points and no corner slots
    /// (a defect each); a boundary edge off the integer isolines is a defect.
    /// Stops adding points past `max_vertices` (a defect).
    pub fn enumerate(
        mesh: &TriMesh,
        map: &SnappedMap,
        max_vertices: usize,
        defects: &mut Vec<QuadDefect>,
    ) -> QuadVertices {
        let nf = mesh.n_faces();
        let mut list = Vec::new();
        let mut pts = Vec::new();
        let mut over_budget = false;
        let mut face_start = Vec::with_capacity(nf + 1);
        for f in 0..nf as u32 {
            face_start.push(list.len() as u32);
            let x = map.corners(f);
            if orient(x[0], x[1], x[2]) <= 0 {
                defects.push(QuadDefect {
                    face: f,
                    what: "UV triangle is flipped or degenerate; its interior points are skipped".into(),
                });
                continue;
            }
            pts.clear();
            let budget = max_vertices.saturating_sub(list.len());
            if over_budget || !face_points(x, budget, &mut pts) {
                over_budget = true;
                continue;
            }
            list.extend(pts.iter().map(|&uv| QuadVertex { place: Place::Face(f), uv }));
        }
        face_start.push(list.len() as u32);

        let ne = mesh.n_edges();
        let mut edge_start = Vec::with_capacity(ne + 1);
        for e in 0..ne as u32 {
            edge_start.push(list.len() as u32);
            let h0 = mesh.edge_halfedges(e)[0];
            let (a, b) = (map.uv[h0 as usize], map.uv[mesh.next(h0) as usize]);
            if mesh.is_boundary_edge(e) && !(0..2).any(|k| a[k] == b[k] && is_integer(a[k])) {
                defects
                    .push(QuadDefect { face: h0 / 3, what: format!("boundary edge {e} is not on an integer isoline") });
            }
            pts.clear();
            let budget = max_vertices.saturating_sub(list.len());
            if over_budget || !edge_points(a, b, budget, &mut pts) {
                over_budget = true;
                continue;
            }
            list.extend(pts.iter().map(|&uv| QuadVertex { place: Place::Edge(e), uv }));
        }
        edge_start.push(list.len() as u32);

        let mut at_vertex = vec![NONE; mesh.n_vertices()];
        for v in 0..mesh.n_vertices() as u32 {
            let uv = map.uv[mesh.vertex_halfedge(v) as usize];
            if is_integer(uv[0]) && is_integer(uv[1]) && !over_budget {
                at_vertex[v as usize] = list.len() as u32;
                list.push(QuadVertex { place: Place::Vertex(v), uv });
            }
        }
        if over_budget {
            defects.push(QuadDefect {
                face: 0,
                what: format!("more than {max_vertices} integer points; enumeration stopped"),
            });
        }

        let mut qv = QuadVertices {
            list,
            face_start,
            edge_start,
            at_vertex,
            slot_start: Vec::new(),
            slots: Vec::new(),
            slot_owner: Vec::new(),
            open: Vec::new(),
        };
        qv.build_slots(mesh, map);
        qv
    }

    /// Fills the slots: four per face point; per edge point the axis
    /// directions counter-clockwise from the edge's first halfedge (only the
    /// face side on a boundary edge); per vertex point the axis directions in
    /// each corner sector of the fan, half-open `[e1, e2)` except closed at
    /// the end of a boundary fan.
    fn build_slots(&mut self, mesh: &TriMesh, map: &SnappedMap) {
        let n = self.list.len();
        self.slot_start.reserve(n + 1);
        self.open.reserve(n);
        let mut fan = Vec::new();
        for q in 0..n {
            self.slot_start.push(self.slots.len() as u32);
            let place = self.list[q].place;
            let open = match place {
                Place::Face(f) => {
                    self.slots.extend((0..4).map(|dir| Slot { face: f, dir }));
                    false
                }
                Place::Edge(e) => {
                    let h0 = mesh.edge_halfedges(e)[0];
                    let w = sub(map.uv[mesh.next(h0) as usize], map.uv[h0 as usize]);
                    let boundary = mesh.is_boundary_edge(e);
                    if let Some(d0) = first_axis_from(w) {
                        for i in 0..4 {
                            let dir = (d0 + i) % 4;
                            if !boundary || cross(w, axis(dir)) >= 0 {
                                self.slots.push(Slot { face: h0 / 3, dir });
                            }
                        }
                    }
                    boundary
                }
                Place::Vertex(v) => {
                    let open = mesh.is_boundary_vertex(v);
                    fan.clear();
                    fan.extend(mesh.outgoing(v).filter(|&h| !mesh.is_boundary_halfedge(h)));
                    for (i, &h) in fan.iter().enumerate() {
                        let last = open && i + 1 == fan.len();
                        let (e1, e2) = corner_sector(mesh, map, h);
                        if cross(e1, e2) <= 0 {
                            continue;
                        }
                        let Some(d0) = first_axis_from(e1) else { continue };
                        for k in 0..4 {
                            let dir = (d0 + k) % 4;
                            let a = axis(dir);
                            let c2 = cross(a, e2);
                            if cross(e1, a) >= 0 && (c2 > 0 || (last && c2 == 0 && dot(a, e2) > 0)) {
                                self.slots.push(Slot { face: h / 3, dir });
                            }
                        }
                    }
                    open
                }
            };
            self.open.push(open);
        }
        self.slot_start.push(self.slots.len() as u32);
        self.slot_owner = vec![0; self.slots.len()];
        for q in 0..n {
            for s in self.slot_start[q]..self.slot_start[q + 1] {
                self.slot_owner[s as usize] = q as u32;
            }
        }
    }

    /// The quad vertex strictly inside face `f` at `p` (chart of `f`).
    pub fn face_point(&self, f: u32, p: Point) -> Option<u32> {
        let (a, b) = (self.face_start[f as usize] as usize, self.face_start[f as usize + 1] as usize);
        let i = self.list[a..b].binary_search_by_key(&(p[1], p[0]), |q| (q.uv[1], q.uv[0])).ok()?;
        Some((a + i) as u32)
    }

    /// The quad vertex strictly inside edge `e` at `p` (home chart of `e`).
    pub fn edge_point(&self, e: u32, p: Point) -> Option<u32> {
        let (a, b) = (self.edge_start[e as usize] as usize, self.edge_start[e as usize + 1] as usize);
        let i = self.list[a..b].binary_search_by_key(&p, |q| q.uv).ok()?;
        Some((a + i) as u32)
    }

    /// The quad vertex at mesh vertex `v`, if its UV is an integer point.
    pub fn vertex_point(&self, v: u32) -> Option<u32> {
        let q = self.at_vertex[v as usize];
        (q != NONE).then_some(q)
    }

    /// Global index of the slot of quad vertex `q` equal to `slot`.
    pub fn find_slot(&self, q: u32, slot: Slot) -> Option<u32> {
        let (a, b) = (self.slot_start[q as usize], self.slot_start[q as usize + 1]);
        (a..b).find(|&s| self.slots[s as usize] == slot)
    }

    /// Where the isoline of slot `s` starts: the owner's UV in the chart of
    /// the slot's face.
    pub fn slot_origin(&self, mesh: &TriMesh, map: &SnappedMap, s: u32) -> Point {
        let q = self.list[self.slot_owner[s as usize] as usize];
        let face = self.slots[s as usize].face;
        match q.place {
            Place::Face(_) | Place::Edge(_) => q.uv,
            Place::Vertex(v) => {
                let c = mesh.faces()[face as usize].iter().position(|&w| w == v).unwrap_or(0);
                map.uv[3 * face as usize + c]
            }
        }
    }
}

/// The two edge vectors `(e1, e2)` of the corner where face halfedge `h`
/// starts (towards the next and the previous corner), in its face's chart.
pub(super) fn corner_sector(mesh: &TriMesh, map: &SnappedMap, h: u32) -> (Point, Point) {
    let x = map.uv[h as usize];
    let e1 = sub(map.uv[mesh.next(h) as usize], x);
    let e2 = sub(map.uv[mesh.prev(h) as usize], x);
    (e1, e2)
}
