//! QEx step 4: the quads, as the cycles of traced half-edges that turn left
//! at every quad vertex.

use super::snap::{add, axis, Point, SnappedMap, ONE};
use super::vertices::QuadVertices;
use crate::mesh::NONE;
use crate::quads::QuadDefect;
use crate::TriMesh;

/// Longest cycle followed before it is declared broken.
const MAX_CYCLE: usize = 64;

/// The quads and their corner UVs, and the faces of more than four sides
/// that the extractor closes with quads ([`super::close_polygons`]).
pub(super) struct Cells {
    pub quads: Vec<[u32; 4]>,
    pub uv: Vec<[f64; 2]>,
    pub polygons: Vec<Polygon>,
}

/// A closed face of the traced isolines with an even number (> 4) of
/// distinct corners, counter-clockwise: where the map winds twice around a
/// point inside a cell (a vertex of UV angle 4 pi) the cell's isolines close
/// only after going around twice.
pub(super) struct Polygon {
    pub corners: Vec<u32>,
    /// Grid coordinates of the corners (each in the chart of its slot's face).
    pub uv: Vec<[f64; 2]>,
}

impl Cells {
    /// Adds the quad of the four half-edges `cycle`, its corner UVs the unit
    /// square in the chart of the first slot's face.
    fn push_quad(&mut self, mesh: &TriMesh, map: &SnappedMap, qv: &QuadVertices, cycle: &[u32]) {
        self.quads.push([0, 1, 2, 3].map(|i| qv.slot_owner[cycle[i] as usize]));
        let dir = qv.slots[cycle[0] as usize].dir;
        let p = qv.slot_origin(mesh, map, cycle[0]);
        let (a, b) = (axis(dir), axis((dir + 1) % 4));
        let corners: [Point; 4] = [p, add(p, a), add(add(p, a), b), add(p, b)];
        self.uv.extend(corners.iter().map(|&c| grid_uv(c)));
    }
}

/// A fixed-point point in grid units.
fn grid_uv(p: Point) -> [f64; 2] {
    p.map(|x| x as f64 / ONE as f64)
}

/// Whether the half-edges of `cycle` leave distinct quad vertices.
fn distinct_owners(qv: &QuadVertices, cycle: &[u32]) -> bool {
    let owner = |i: usize| qv.slot_owner[cycle[i] as usize];
    (0..cycle.len()).all(|i| (i + 1..cycle.len()).all(|j| owner(i) != owner(j)))
}

/// `cycle` cut into closed sub-cycles at every vertex it passes twice
/// (each piece through distinct vertices, in order).
fn split_at_repeats(qv: &QuadVertices, cycle: &[u32]) -> Vec<Vec<u32>> {
    let mut pieces = Vec::new();
    let mut stack: Vec<u32> = Vec::with_capacity(cycle.len());
    for &c in cycle {
        let owner = qv.slot_owner[c as usize];
        if let Some(i) = stack.iter().position(|&d| qv.slot_owner[d as usize] == owner) {
            pieces.push(stack.split_off(i));
        }
        stack.push(c);
    }
    pieces.push(stack);
    pieces
}

/// The half-edge after `x` around its face (the face on its left): it
/// leaves the end vertex at the slot clockwise-next to the arrival slot;
/// `None` when `x` has no trace or the face on its left is outside the
/// surface (arrival at the first slot of an open fan).
fn next(qv: &QuadVertices, target: &[u32], x: u32) -> Option<u32> {
    let y = *target.get(x as usize)?;
    if y == NONE {
        return None;
    }
    let b = qv.slot_owner[y as usize] as usize;
    let (first, end) = (qv.slot_start[b], qv.slot_start[b + 1]);
    if y > first {
        Some(y - 1)
    } else if qv.open[b] {
        None
    } else {
        Some(end - 1)
    }
}

/// Builds the quads from the traced half-edges (`target[s]`: the slot where
/// the trace from slot `s` arrives, or `NONE`). Every cycle of `next` is a
/// face; cycles of four become quads (counter-clockwise, corner UVs the unit
/// square in the chart of the first slot's face); cycles of an even length
/// above four through distinct vertices become [`Polygon`]s to be closed
/// with quads. Half-edges whose traces do not pair up, other cycles, and
/// chains that break off are recorded as defects and skipped.
pub(super) fn build_quads(
    mesh: &TriMesh,
    map: &SnappedMap,
    qv: &QuadVertices,
    target: &[u32],
    defects: &mut Vec<QuadDefect>,
) -> Cells {
    let n = target.len();
    for x in 0..n {
        let y = target[x];
        if y != NONE && target[y as usize] != x as u32 {
            defects.push(QuadDefect {
                face: qv.slots[x].face,
                what: "isoline traced one way does not come back the other way".into(),
            });
        }
    }
    let mut visited = vec![false; n];
    let mut cells = Cells { quads: Vec::new(), uv: Vec::new(), polygons: Vec::new() };
    let mut cycle = Vec::with_capacity(8);
    for x in 0..n as u32 {
        if visited[x as usize] || next(qv, target, x).is_none() {
            visited[x as usize] = true;
            continue;
        }
        cycle.clear();
        cycle.push(x);
        let mut cur = x;
        let closed = loop {
            match next(qv, target, cur) {
                Some(y) if y == x => break true,
                Some(y) if !visited[y as usize] && !cycle.contains(&y) && cycle.len() < MAX_CYCLE => {
                    cycle.push(y);
                    cur = y;
                }
                _ => break false,
            }
        };
        for &c in &cycle {
            visited[c as usize] = true;
        }
        let face = qv.slots[x as usize].face;
        if !closed {
            defects.push(QuadDefect { face, what: "grid cell is not closed; skipped".into() });
            continue;
        }
        if cycle.len() == 4 && distinct_owners(qv, &cycle) {
            cells.push_quad(mesh, map, qv, &cycle);
            continue;
        }
        // Around a point the map winds twice around, the cell's isolines close
        // only after going around twice, through one vertex twice when the
        // point is a grid point: split there; digons (out and back along one
        // isoline) are glued to themselves and leave no hole.
        let pieces = split_at_repeats(qv, &cycle);
        let mut done = Vec::new();
        for piece in pieces {
            match piece.len() {
                2 => done.push("dropped an isoline traced out and back".to_string()),
                4 => {
                    cells.push_quad(mesh, map, qv, &piece);
                    done.push("kept a quad".into());
                }
                n if n % 2 == 0 => {
                    let corners = piece.iter().map(|&c| qv.slot_owner[c as usize]).collect();
                    let uv = piece.iter().map(|&c| grid_uv(qv.slot_origin(mesh, map, c))).collect();
                    cells.polygons.push(Polygon { corners, uv });
                    done.push(format!("closed {n} sides with {} quads around a vertex inside", n / 2));
                }
                n => done.push(format!("skipped {n} sides")),
            }
        }
        defects.push(QuadDefect {
            face,
            what: format!("grid cell has {} sides (the map winds around a point in it): {}", cycle.len(), done.join(", ")),
        });
    }
    cells
}
