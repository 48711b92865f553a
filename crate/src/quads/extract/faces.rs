//! QEx step 4: the quads, as the cycles of traced half-edges that turn left
//! at every quad vertex.

use super::snap::{add, axis, Point, SnappedMap, ONE};
use super::vertices::QuadVertices;
use crate::mesh::NONE;
use crate::quads::QuadDefect;
use crate::TriMesh;

/// Longest cycle followed before it is declared broken.
const MAX_CYCLE: usize = 64;

/// The quads and their corner UVs.
pub(super) struct Cells {
    pub quads: Vec<[u32; 4]>,
    pub uv: Vec<[f64; 2]>,
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
/// square in the chart of the first slot's face). Half-edges whose traces do
/// not pair up, cycles of another length, and chains that break off are
/// recorded as defects and skipped.
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
    let mut cells = Cells { quads: Vec::new(), uv: Vec::new() };
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
        if cycle.len() != 4 {
            defects.push(QuadDefect { face, what: format!("grid cell has {} sides; skipped", cycle.len()) });
            continue;
        }
        let quad = [0, 1, 2, 3].map(|i| qv.slot_owner[cycle[i] as usize]);
        if (0..4).any(|i| (i + 1..4).any(|j| quad[i] == quad[j])) {
            defects.push(QuadDefect { face, what: "grid cell repeats a vertex (the map winds around it there); skipped".into() });
        } else {
            cells.quads.push(quad);
            let dir = qv.slots[x as usize].dir;
            let p = qv.slot_origin(mesh, map, x);
            let (a, b) = (axis(dir), axis((dir + 1) % 4));
            let corners: [Point; 4] = [p, add(p, a), add(add(p, a), b), add(p, b)];
            cells.uv.extend(corners.iter().map(|c| [c[0] as f64 / ONE as f64, c[1] as f64 / ONE as f64]));
        }
    }
    cells
}
