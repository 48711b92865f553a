//! Step 6: closing the holes the trace leaves where the map is not a valid
//! integer-grid map. The cells over flipped triangles are skipped, so the
//! traced quads stop around them; QEx keeps tracing through such fold-overs,
//! here the traced mesh is closed afterwards instead. Where the traced quads
//! are not a manifold (overlapping closings of wound cells) they are first
//! removed, which leaves a hole too. Every boundary loop of
//! the quads that does not run along the input's boundary is such a hole;
//! one with an even number of sides is filled with quads whose new vertices
//! lie on the input surface, and recorded as a defect; one that reaches the
//! input's boundary is closed with new vertices along it. Two holes that
//! cut the quads on one component of the input into two pieces are joined
//! by a strip of quads instead (`bridge`). Odd and overlong holes stay
//! open (also recorded); a loop through a vertex twice is left as it is.

mod boundary;
mod bridge;
mod patch;

use crate::quads::{QuadDefect, QuadMesh, SurfacePoint};
use crate::vec3::{norm, sub};
use crate::TriMesh;
use boundary::{boundary_path, boundary_position, path_length, point_along};
use patch::fill_polygon;
use std::collections::{HashMap, HashSet};

/// Holes longer than this are left open (the map is broken over a region
/// too large to patch plausibly).
const MAX_HOLE: usize = 64;

/// A hole at the boundary is filled only when the input's boundary between
/// its ends is at most this many times as long as its run inside.
const BOUNDARY_PATH_RATIO: f64 = 3.0;

/// Fills the holes of `quads` (see the module comment), appending vertices,
/// quads (unit-square corner UVs) and one defect per hole.
pub(super) fn fill_holes(mesh: &TriMesh, quads: &mut QuadMesh) {
    let (opened, face) = open_non_manifold(mesh, quads);
    if opened > 0 {
        let what = format!("{opened} quads where the traced mesh is not a manifold removed (the hole is filled)");
        quads.defects.push(QuadDefect { face, what });
    }
    let holes = holes(quads).0;
    let on: Vec<Vec<bool>> = holes.iter().map(|h| h.iter().map(|&v| on_input_boundary(mesh, quads.locations[v as usize])).collect()).collect();
    // Holes off the boundary whose quads are pieces cut off from the rest are joined in pairs.
    let inside: Vec<usize> = (0..holes.len()).filter(|&i| !on[i].contains(&true)).collect();
    let inside_holes: Vec<Vec<u32>> = inside.iter().map(|&i| holes[i].clone()).collect();
    let mut joined = vec![false; holes.len()];
    for (x, y) in bridge::pairs_to_join(mesh, quads, &inside_holes) {
        let (i, j) = (inside[x], inside[y]);
        let added = bridge::join(quads, &holes[i], &holes[j]);
        let what = format!(
            "holes of {} and {} quad edges on either side of a ring where the map is invalid; joined with {added} quads",
            holes[i].len(),
            holes[j].len()
        );
        quads.defects.push(QuadDefect { face: quads.locations[holes[i][0] as usize].face, what });
        joined[i] = true;
        joined[j] = true;
    }
    for (k, hole) in holes.into_iter().enumerate() {
        if joined[k] {
            continue;
        }
        let first = quads.locations[hole[0] as usize].face;
        let n = hole.len();
        let on = &on[k];
        let on_boundary = on.iter().filter(|&&b| b).count();
        if on_boundary == n {
            continue; // the input's own boundary
        }
        let what = if on_boundary > 0 {
            let at = format!("hole of {n} quad edges at the input's boundary where the map is invalid");
            match fill_boundary_runs(mesh, quads, &hole, on) {
                (added, None) => format!("{at}; closed with {added} quads"),
                (0, Some(why)) => format!("{at}; left open: {why}"),
                (added, Some(why)) => format!("{at}; partly closed with {added} quads, left open where {why}"),
            }
        } else if n % 2 == 1 {
            format!("hole of {n} quad edges where the map is invalid; left open: it has an odd number of sides")
        } else if n > MAX_HOLE {
            format!("hole of {n} quad edges where the map is invalid; left open: it is too long")
        } else {
            format!("hole of {n} quad edges where the map is invalid; closed with {} quads", fill_polygon(mesh, quads, &hole))
        };
        quads.defects.push(QuadDefect { face: first, what });
    }
}

/// Fills a hole that reaches the input's boundary (`on`: which of its
/// vertices lie on that boundary): each run of its sides
/// off the boundary, from boundary point `a` to boundary point `b`, and the
/// input's boundary from `b` back to `a` (new quad vertices spaced along it
/// so the polygon has an even number of sides) bound a polygon, filled like
/// a hole inside. The number of quads added, and why a run stays open
/// (the last reason, if any did).
fn fill_boundary_runs(mesh: &TriMesh, quads: &mut QuadMesh, hole: &[u32], on: &[bool]) -> (usize, Option<&'static str>) {
    let n = hole.len();
    let mut runs: Vec<Vec<u32>> = Vec::new();
    for i in (0..n).filter(|&i| on[i] && !on[(i + 1) % n]) {
        let mut run = vec![hole[i]];
        let mut j = (i + 1) % n;
        while !on[j] {
            run.push(hole[j]);
            j = (j + 1) % n;
        }
        run.push(hole[j]);
        runs.push(run);
    }
    let (mut added, mut open) = (0, None);
    for run in runs {
        match fill_run(mesh, quads, &run) {
            Ok(k) => added += k,
            Err(why) => open = Some(why),
        }
    }
    (added, open)
}

/// Closes the hole between the run of hole sides `run` (from boundary point
/// to boundary point) and the input's boundary back from its end to its
/// start ([`fill_boundary_runs`]).
fn fill_run(mesh: &TriMesh, quads: &mut QuadMesh, run: &[u32]) -> Result<usize, &'static str> {
    let length: f64 = run.windows(2).map(|w| norm(sub(quads.positions[w[1] as usize], quads.positions[w[0] as usize]))).sum();
    let sides = run.len() - 1;
    let (a, b) = (run[0], run[sides]);
    let path = boundary_path(mesh, quads.locations[b as usize], quads.locations[a as usize])
        .ok_or("its ends are not joined along the input's boundary")?;
    let path_length = path_length(mesh, &path);
    if !(path_length <= BOUNDARY_PATH_RATIO * length) {
        return Err("the input's boundary between its ends is too long");
    }
    // New vertices along the boundary: as many as fit at the run's
    // mean side, with the parity that makes the polygon even.
    let ideal = path_length / (length / sides as f64) - 1.0;
    let m = (0..=ideal.ceil().max(1.0) as usize + 1)
        .filter(|m| (sides + m + 1) % 2 == 0)
        .min_by(|&x, &y| (x as f64 - ideal).abs().total_cmp(&(y as f64 - ideal).abs()))
        .unwrap_or(1);
    let mut polygon = run.to_vec();
    for k in 1..=m {
        let (location, p) = point_along(mesh, &path, path_length * k as f64 / (m + 1) as f64).location(mesh);
        quads.positions.push(p);
        quads.locations.push(location);
        polygon.push((quads.n_vertices() - 1) as u32);
    }
    if polygon.len() < 4 || polygon.len() > MAX_HOLE {
        return Err("it is too short or too long to fill");
    }
    Ok(fill_polygon(mesh, quads, &polygon))
}

/// The boundary loops of `quads` as vertex cycles oriented as a face
/// filling them would be (each side `a → b` the reverse of a quad's side),
/// and the vertices where loops are not simple: loops through a vertex
/// twice, or through a side two quads share in the same direction, are
/// left out and their vertices listed.
fn holes(quads: &QuadMesh) -> (Vec<Vec<u32>>, Vec<u32>) {
    let mut side_quad: HashMap<(u32, u32), usize> = HashMap::new();
    let mut broken = vec![false; quads.n_vertices()];
    for (q, quad) in quads.quads.iter().enumerate() {
        for i in 0..4 {
            let (a, b) = (quad[i], quad[(i + 1) % 4]);
            if a == b || side_quad.insert((a, b), q).is_some() {
                broken[a as usize] = true;
                broken[b as usize] = true;
            }
        }
    }
    // The quad side entering `a` before the side `a → b` of quad `q`.
    let previous = |q: usize, a: u32| {
        let quad = quads.quads[q];
        let i = quad.iter().position(|&v| v == a).unwrap_or(0);
        quad[(i + 3) % 4]
    };
    // Hole side `a → z` after the hole side `b → a`: turn around `a` through
    // its quads, starting at the one with side `a → b`, to the far side.
    let next = |a: u32, b: u32| -> Option<u32> {
        let mut q = *side_quad.get(&(a, b))?;
        for _ in 0..64 {
            let y = previous(q, a);
            match side_quad.get(&(a, y)) {
                Some(&q2) => q = q2,
                None => return Some(y),
            }
        }
        None
    };
    let mut hole_sides: Vec<(u32, u32)> =
        side_quad.keys().filter(|&&(a, b)| !side_quad.contains_key(&(b, a))).map(|&(a, b)| (b, a)).collect();
    hole_sides.sort_unstable();
    let mut done: HashSet<(u32, u32)> = HashSet::new();
    let mut loops = Vec::new();
    let mut pinched = Vec::new();
    for &start in &hole_sides {
        if done.contains(&start) {
            continue;
        }
        let mut cycle = vec![start.0];
        let mut side = start;
        let mut valid = !broken[start.0 as usize];
        loop {
            done.insert(side);
            let (b, a) = side;
            let Some(z) = next(a, b) else {
                valid = false;
                break;
            };
            side = (a, z);
            if side == start {
                break;
            }
            if done.contains(&side) || cycle.len() > 4 * quads.n_quads() {
                valid = false;
                break;
            }
            valid &= !broken[a as usize];
            cycle.push(a);
        }
        let mut sorted = cycle.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if valid && sorted.len() == cycle.len() && cycle.len() >= 3 {
            loops.push(cycle);
        } else {
            pinched.extend(cycle);
        }
    }
    (loops, pinched)
}

/// Rounds of [`open_non_manifold`].
const REPAIR_ROUNDS: usize = 4;

/// Opens the places where the traced quads are not a manifold (two closings
/// of cells the map winds around that overlap, or a trace that does not
/// come back): removes every quad with a side another quad also has in
/// the same direction (so every edge of three or more quads loses two),
/// or through a vertex a hole's loop passes twice or two holes pass, until
/// the loops are simple and apart, so the holes left can be filled (or
/// joined, where the pieces they separate met at a vertex). The number of
/// quads removed and the input face under the first.
fn open_non_manifold(mesh: &TriMesh, quads: &mut QuadMesh) -> (usize, u32) {
    let (mut removed, mut face) = (0, 0);
    for _ in 0..REPAIR_ROUNDS {
        // An edge of three or more quads has two in the same direction.
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for q in &quads.quads {
            for i in 0..4 {
                *directed.entry((q[i], q[(i + 1) % 4])).or_default() += 1;
            }
        }
        let bad_side = |a: u32, b: u32| a == b || directed[&(a, b)] > 1;
        // A vertex two holes pass through (two fans of quads meeting at a
        // point) is opened too, so the pieces it joins can be bridged.
        let mut hole_sides_from = vec![0usize; quads.n_vertices()];
        for &(a, b) in directed.keys() {
            if !directed.contains_key(&(b, a)) {
                hole_sides_from[b as usize] += 1;
            }
        }
        let pinches = (0..quads.n_vertices() as u32).filter(|&v| hole_sides_from[v as usize] > 1);
        let mut bad_vertex = vec![false; quads.n_vertices()];
        for v in holes(quads).1.into_iter().chain(pinches) {
            // The input's own boundary may touch itself; only holes are opened.
            if !on_input_boundary(mesh, quads.locations[v as usize]) {
                bad_vertex[v as usize] = true;
            }
        }
        let remove: Vec<bool> = quads
            .quads
            .iter()
            .map(|q| (0..4).any(|i| bad_side(q[i], q[(i + 1) % 4]) || bad_vertex[q[i] as usize]))
            .collect();
        let count = remove.iter().filter(|&&r| r).count();
        if count == 0 || count == quads.n_quads() {
            break;
        }
        if removed == 0 {
            let q = remove.iter().position(|&r| r).unwrap_or(0);
            face = quads.locations[quads.quads[q][0] as usize].face;
        }
        quads.remove_quads(&remove);
        removed += count;
    }
    (removed, face)
}

/// Whether a quad vertex lies on a boundary edge or vertex of the input.
fn on_input_boundary(mesh: &TriMesh, p: SurfacePoint) -> bool {
    boundary_position(mesh, p).is_some()
}
