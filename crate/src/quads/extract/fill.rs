//! Step 6: closing the holes the trace leaves where the map is not a valid
//! integer-grid map. The cells over flipped triangles are skipped, so the
//! traced quads stop around them; QEx keeps tracing through such fold-overs,
//! here the traced mesh is closed afterwards instead. Where the traced quads
//! are not a manifold (overlapping closings of wound cells) they are first
//! removed, which leaves a hole too. Every boundary loop of
//! the quads that does not run along the input's boundary is such a hole;
//! one with an even number of sides is filled with quads whose new vertices
//! lie on the input surface, and recorded as a defect; one that reaches the
//! input's boundary is closed with new vertices along it. Odd and overlong
//! holes stay open (also recorded); a loop through a vertex twice is left
//! as it is.

use crate::mesh::NONE;
use crate::quads::{QuadDefect, QuadMesh, SurfacePoint};
use crate::vec3::{add, barycentric_point, closest_point_barycentric, cross, dot, norm, scale, sub, V3};
use crate::TriMesh;
use std::collections::HashMap;

/// Holes longer than this are left open (the map is broken over a region
/// too large to patch plausibly).
const MAX_HOLE: usize = 64;

/// Cuts tried per hole of 6 to 16 sides (the shortest ones; longer holes
/// take the shortest cut only, which bounds the search).
const CUTS_TRIED: usize = 3;

/// Weight of a unit of valence away from 4 against the sine of the worst
/// corner angle, in [`Patch::score`].
const VALENCE_WEIGHT: f64 = 0.05;

/// Relaxation steps of the new vertices of a filled hole.
const SMOOTHING_STEPS: usize = 10;

/// A hole at the boundary is filled only when the input's boundary between
/// its ends is at most this many times as long as its run inside.
const BOUNDARY_PATH_RATIO: f64 = 3.0;

/// Input faces searched for the surface point nearest to a new vertex.
const MAX_SEARCH_FACES: usize = 20_000;

/// Fills the holes of `quads` (see the module comment), appending vertices,
/// quads (unit-square corner UVs) and one defect per hole.
pub(super) fn fill_holes(mesh: &TriMesh, quads: &mut QuadMesh) {
    let (opened, face) = open_non_manifold(mesh, quads);
    if opened > 0 {
        let what = format!("{opened} quads where the traced mesh is not a manifold removed (the hole is filled)");
        quads.defects.push(QuadDefect { face, what });
    }
    for hole in holes(quads).0 {
        let first = quads.locations[hole[0] as usize].face;
        let n = hole.len();
        let on_boundary = hole.iter().filter(|&&v| on_input_boundary(mesh, quads.locations[v as usize])).count();
        if on_boundary == n {
            continue; // the input's own boundary
        }
        let what = if on_boundary > 0 {
            let at = format!("hole of {n} quad edges at the input's boundary where the map is invalid");
            match fill_boundary_runs(mesh, quads, &hole) {
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

/// Fills the even cycle `polygon` with quads ([`Patch::plan`]) and relaxes
/// the vertices it creates; the number of quads added.
fn fill_polygon(mesh: &TriMesh, quads: &mut QuadMesh, polygon: &[u32]) -> usize {
    let before = quads.n_quads();
    let first_new = quads.n_vertices();
    let degree = corner_degrees(quads, polygon);
    let mut patch = Patch { mesh, faces: search_faces(mesh, quads, polygon), quads, degree };
    for q in patch.plan(polygon) {
        patch.push_quad(q);
    }
    patch.smooth(before, first_new);
    quads.n_quads() - before
}

/// Fills a hole that reaches the input's boundary: each run of its sides
/// off the boundary, from boundary point `a` to boundary point `b`, and the
/// input's boundary from `b` back to `a` (new quad vertices spaced along it
/// so the polygon has an even number of sides) bound a polygon, filled like
/// a hole inside. The number of quads added, and why a run stays open
/// (the last reason, if any did).
fn fill_boundary_runs(mesh: &TriMesh, quads: &mut QuadMesh, hole: &[u32]) -> (usize, Option<&'static str>) {
    let n = hole.len();
    let on: Vec<bool> = hole.iter().map(|&v| on_input_boundary(mesh, quads.locations[v as usize])).collect();
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

/// A point of the input's boundary: on the boundary edge of the interior
/// half-edge `h`, at parameter `s` from its tail.
#[derive(Clone, Copy, Debug)]
struct BoundaryPoint {
    h: u32,
    s: f64,
}

impl BoundaryPoint {
    /// Where it lies (exactly on the edge: 0 at the face's third corner).
    fn location(self, mesh: &TriMesh) -> (SurfacePoint, V3) {
        let k = (self.h % 3) as usize;
        let mut bary = [0.0; 3];
        bary[k] = 1.0 - self.s;
        bary[(k + 1) % 3] = self.s;
        let t = mesh.faces()[(self.h / 3) as usize].map(|v| mesh.position(v));
        (SurfacePoint { face: self.h / 3, bary }, barycentric_point(&t, bary))
    }
}

/// The input's boundary from the boundary point `from` to `to`, walked with
/// the surface on the left (along the faces' half-edges): its ends and the
/// vertices between, each as the end of the edge that reaches it. `None`
/// when they are not on one boundary loop.
fn boundary_path(mesh: &TriMesh, from: SurfacePoint, to: SurfacePoint) -> Option<Vec<BoundaryPoint>> {
    let start = boundary_position(mesh, from)?;
    let end = boundary_position(mesh, to)?;
    let mut path = vec![start];
    let mut h = start.h;
    if h == end.h && end.s >= start.s {
        path.push(end);
        return Some(path);
    }
    for _ in 0..mesh.n_boundary_halfedges() {
        path.push(BoundaryPoint { h, s: 1.0 });
        // The next boundary edge in the faces' direction starts at head(h).
        h = mesh.twin(mesh.prev(mesh.twin(h)));
        if h == end.h {
            path.push(end);
            return Some(path);
        }
    }
    None
}

/// Length of a boundary path.
fn path_length(mesh: &TriMesh, path: &[BoundaryPoint]) -> f64 {
    path.windows(2).map(|w| norm(sub(w[1].location(mesh).1, w[0].location(mesh).1))).sum()
}

/// The point at arc length `t` along `path`: each step runs along the edge
/// of its second point, from the first point's parameter on that edge (0
/// where the first ends the previous edge).
fn point_along(mesh: &TriMesh, path: &[BoundaryPoint], t: f64) -> BoundaryPoint {
    let mut left = t;
    for w in path.windows(2) {
        let l = norm(sub(w[1].location(mesh).1, w[0].location(mesh).1));
        if left <= l && l > 0.0 {
            let s0 = if w[0].h == w[1].h { w[0].s } else { 0.0 };
            return BoundaryPoint { h: w[1].h, s: s0 + (w[1].s - s0) * (left / l) };
        }
        left -= l;
    }
    *path.last().expect("a path has points")
}

/// A boundary point as the interior half-edge of its boundary edge (the
/// one leaving it when it is a vertex) and the parameter along it.
fn boundary_position(mesh: &TriMesh, p: SurfacePoint) -> Option<BoundaryPoint> {
    let zeros: Vec<usize> = (0..3).filter(|&k| p.bary[k] == 0.0).collect();
    match zeros.as_slice() {
        [k] => {
            let h = 3 * p.face + ((*k as u32 + 1) % 3);
            mesh.is_boundary_halfedge(mesh.twin(h)).then(|| BoundaryPoint { h, s: p.bary[(*k + 2) % 3] })
        }
        [i, j] => {
            let v = mesh.faces()[p.face as usize][3 - i - j];
            mesh.outgoing(v)
                .find(|&h| !mesh.is_boundary_halfedge(h) && mesh.is_boundary_halfedge(mesh.twin(h)))
                .map(|h| BoundaryPoint { h, s: 0.0 })
        }
        _ => None,
    }
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
    let mut done: HashMap<(u32, u32), bool> = HashMap::new();
    let mut loops = Vec::new();
    let mut pinched = Vec::new();
    for &start in &hole_sides {
        if done.contains_key(&start) {
            continue;
        }
        let mut cycle = vec![start.0];
        let mut side = start;
        let mut valid = !broken[start.0 as usize];
        loop {
            done.insert(side, true);
            let (b, a) = side;
            let Some(z) = next(a, b) else {
                valid = false;
                break;
            };
            side = (a, z);
            if side == start {
                break;
            }
            if done.contains_key(&side) || cycle.len() > 4 * quads.n_quads() {
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
/// or through a vertex a hole's loop passes twice, until the loops are
/// simple, so the holes left can be filled. The number of quads removed
/// and the input face under the first.
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
        let mut bad_vertex = vec![false; quads.n_vertices()];
        for v in holes(quads).1 {
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
        let mut k = 0;
        for q in 0..quads.n_quads() {
            if !remove[q] {
                quads.quads[k] = quads.quads[q];
                for i in 0..4 {
                    quads.uv[4 * k + i] = quads.uv[4 * q + i];
                }
                k += 1;
            }
        }
        quads.quads.truncate(k);
        quads.uv.truncate(4 * k);
        removed += count;
    }
    (removed, face)
}

/// Number of quad edges at each vertex of `hole`.
fn corner_degrees(quads: &QuadMesh, hole: &[u32]) -> HashMap<u32, usize> {
    let mut neighbours: HashMap<u32, Vec<u32>> = hole.iter().map(|&v| (v, Vec::new())).collect();
    for q in &quads.quads {
        for i in 0..4 {
            for (a, b) in [(q[i], q[(i + 1) % 4]), (q[(i + 1) % 4], q[i])] {
                if let Some(list) = neighbours.get_mut(&a) {
                    list.push(b);
                }
            }
        }
    }
    neighbours
        .into_iter()
        .map(|(v, mut list)| {
            list.sort_unstable();
            list.dedup();
            (v, list.len())
        })
        .collect()
}

/// Whether a quad vertex lies on a boundary edge or vertex of the input.
fn on_input_boundary(mesh: &TriMesh, p: SurfacePoint) -> bool {
    let zeros: Vec<usize> = (0..3).filter(|&k| p.bary[k] == 0.0).collect();
    let corners = mesh.faces()[p.face as usize];
    match zeros.as_slice() {
        [k] => {
            // The edge opposite corner k: its half-edge runs from corner k + 1.
            let h = 3 * p.face + ((*k as u32 + 1) % 3);
            mesh.is_boundary_halfedge(mesh.twin(h))
        }
        [i, j] => mesh.is_boundary_vertex(corners[3 - i - j]),
        _ => false,
    }
}

/// The input faces near a hole: rings grown from the faces of its
/// vertices' locations, as many rings as the hole has sides (the hole's
/// interior lies within), at most [`MAX_SEARCH_FACES`].
fn search_faces(mesh: &TriMesh, quads: &QuadMesh, hole: &[u32]) -> Vec<u32> {
    let mut seen = vec![false; mesh.n_faces()];
    let mut faces: Vec<u32> = Vec::new();
    for &v in hole {
        let f = quads.locations[v as usize].face;
        if !std::mem::replace(&mut seen[f as usize], true) {
            faces.push(f);
        }
    }
    let mut start = 0;
    for _ in 0..hole.len() {
        let end = faces.len();
        for i in start..end {
            for v in mesh.faces()[faces[i] as usize] {
                for g in mesh.vertex_faces(v) {
                    if g != NONE && !std::mem::replace(&mut seen[g as usize], true) {
                        faces.push(g);
                    }
                }
            }
        }
        start = end;
        if start == faces.len() || faces.len() > MAX_SEARCH_FACES {
            break;
        }
    }
    faces
}

/// A hole being filled: the quads it adds to and the input faces its new
/// vertices are placed on.
struct Patch<'a> {
    mesh: &'a TriMesh,
    faces: Vec<u32>,
    quads: &'a mut QuadMesh,
    /// Quad edges at each corner of the hole before it is filled.
    degree: HashMap<u32, usize>,
}

impl Patch<'_> {
    fn position(&self, v: u32) -> V3 {
        self.quads.positions[v as usize]
    }

    /// The point of the searched input faces nearest to `x`.
    fn nearest(&self, x: V3) -> (SurfacePoint, V3) {
        let mut best = (f64::INFINITY, SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] }, x);
        for &f in &self.faces {
            let t = self.mesh.faces()[f as usize].map(|v| self.mesh.position(v));
            let bary = closest_point_barycentric(x, &t);
            let p = barycentric_point(&t, bary);
            let d = norm(sub(p, x));
            if d < best.0 {
                best = (d, SurfacePoint { face: f, bary }, p);
            }
        }
        (best.1, best.2)
    }

    /// A new quad vertex at the point of the input nearest to `x`.
    fn vertex_near(&mut self, x: V3) -> u32 {
        let (location, p) = self.nearest(x);
        self.quads.positions.push(p);
        self.quads.locations.push(location);
        (self.quads.positions.len() - 1) as u32
    }

    /// Relaxes the new vertices (`first_new..`) of the quads `first_quad..`:
    /// each moves to the mean of its quad-edge neighbours, then back onto
    /// the input surface, [`SMOOTHING_STEPS`] times.
    fn smooth(&mut self, first_quad: usize, first_new: usize) {
        let n_new = self.quads.n_vertices() - first_new;
        if n_new == 0 {
            return;
        }
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n_new];
        for q in &self.quads.quads[first_quad..] {
            for i in 0..4 {
                let (a, b) = (q[i] as usize, q[(i + 1) % 4]);
                if a >= first_new {
                    neighbours[a - first_new].push(b);
                }
                let (a, b) = (q[(i + 1) % 4] as usize, q[i]);
                if a >= first_new {
                    neighbours[a - first_new].push(b);
                }
            }
        }
        for _ in 0..SMOOTHING_STEPS {
            for (i, nb) in neighbours.iter().enumerate() {
                if nb.is_empty() {
                    continue;
                }
                let mean = scale(nb.iter().fold([0.0; 3], |s, &v| add(s, self.position(v))), 1.0 / nb.len() as f64);
                let (location, p) = self.nearest(mean);
                self.quads.positions[first_new + i] = p;
                self.quads.locations[first_new + i] = location;
            }
        }
    }

    fn push_quad(&mut self, q: [u32; 4]) {
        self.quads.quads.push(q);
        self.quads.uv.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    }

    /// The quads filling the even cycle `hole` (oriented as its filling
    /// faces): the best-scored ([`Patch::score`]) of one quad (4 sides), a
    /// fan around a new centre vertex (6 and 8 sides), and cuts into two
    /// shorter holes by a diagonal or a chain of new vertices between two
    /// corners, each filled in turn. Candidate vertices not used stay
    /// unreferenced (dropped after all holes are filled).
    fn plan(&mut self, hole: &[u32]) -> Vec<[u32; 4]> {
        let n = hole.len();
        if n == 4 {
            return vec![[hole[0], hole[1], hole[2], hole[3]]];
        }
        let x: Vec<V3> = hole.iter().map(|&v| self.position(v)).collect();
        let dist = |i: usize, j: usize| norm(sub(x[i % n], x[j % n]));
        let mean_side = (0..n).map(|i| dist(i, i + 1)).sum::<f64>() / n as f64;
        let mut candidates: Vec<Vec<[u32; 4]>> = Vec::new();
        if n <= 8 {
            let centre = scale(x.iter().fold([0.0; 3], |s, &p| add(s, p)), 1.0 / n as f64);
            let m = self.vertex_near(centre);
            for offset in 0..2 {
                let c = |d: usize| hole[(offset + d) % n];
                candidates.push((0..n).step_by(2).map(|k| [c(k), c(k + 1), c(k + 2), m]).collect());
            }
        }
        // Cuts from corner i to corner i + k by a chain of p sides: holes of
        // k + p and n − k + p sides, both even and shorter than n; the
        // shortest few (chain length near the corners' distance) are tried.
        let mut cuts: Vec<(f64, usize, usize, usize)> = Vec::new();
        for i in 0..n {
            for k in (n / 2).saturating_sub(1).max(2)..=(n / 2 + 1).min(n - 2) {
                let ideal = dist(i, i + k) / mean_side.max(f64::MIN_POSITIVE);
                let limit = k.min(n - k) - 1;
                let p = (1..=limit)
                    .filter(|p| (k + p) % 2 == 0)
                    .min_by(|&a, &b| (a as f64 - ideal).abs().total_cmp(&(b as f64 - ideal).abs()));
                if let Some(p) = p {
                    cuts.push((dist(i, i + k) + mean_side * (p as f64 - ideal).abs(), i, k, p));
                }
            }
        }
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let tried = if n <= 16 { CUTS_TRIED } else { 1 };
        for &(_, i, k, p) in cuts.iter().take(tried) {
            let (a, b) = (x[i], x[(i + k) % n]);
            let chain: Vec<u32> =
                (1..p).map(|s| self.vertex_near(add(a, scale(sub(b, a), s as f64 / p as f64)))).collect();
            let c = |d: usize| hole[(i + d) % n];
            let first: Vec<u32> = (0..=k).map(c).chain(chain.iter().rev().copied()).collect();
            let second: Vec<u32> = (k..=n).map(c).chain(chain.iter().copied()).collect();
            let mut quads = self.plan(&first);
            quads.extend(self.plan(&second));
            candidates.push(quads);
        }
        candidates.into_iter().max_by(|a, b| self.score(hole, a).total_cmp(&self.score(hole, b))).unwrap_or_default()
    }

    /// How good a filling of `hole` by `quads` is: its worst corner (the
    /// sine of the corner angle, negative where a quad folds), less a
    /// penalty for vertices whose valence it takes away from 4.
    fn score(&self, hole: &[u32], quads: &[[u32; 4]]) -> f64 {
        let mut worst = f64::INFINITY;
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for q in quads {
            let p = q.map(|v| self.position(v));
            let normal = (0..4).fold([0.0; 3], |s, i| add(s, cross(p[i], p[(i + 1) % 4])));
            let ln = norm(normal);
            for i in 0..4 {
                let (e0, e1) = (sub(p[i], p[(i + 3) % 4]), sub(p[(i + 1) % 4], p[i]));
                let l = norm(e0) * norm(e1) * ln;
                let sine = if l > 0.0 { dot(cross(e0, e1), normal) / l } else { -1.0 };
                worst = worst.min(sine);
                let (a, b) = (q[i], q[(i + 1) % 4]);
                edges.push((a.min(b), a.max(b)));
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let mut degree: HashMap<u32, usize> = HashMap::new();
        let n = hole.len();
        for &(a, b) in &edges {
            let side = (0..n).any(|i| (hole[i], hole[(i + 1) % n]) == (a, b) || (hole[i], hole[(i + 1) % n]) == (b, a));
            if !side {
                *degree.entry(a).or_default() += 1;
                *degree.entry(b).or_default() += 1;
            }
        }
        let valence_cost: f64 = degree
            .iter()
            .map(|(v, &added)| {
                let before = self.degree.get(v).copied().unwrap_or(0) as f64;
                (before + added as f64 - 4.0).abs() - if self.degree.contains_key(v) { (before - 4.0).abs() } else { 0.0 }
            })
            .sum();
        worst - VALENCE_WEIGHT * valence_cost
    }
}

