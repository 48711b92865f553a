//! Filling one hole of the quad mesh ([`fill_polygon`]): candidate
//! fillings (one quad, a fan around a new centre, cuts into two shorter
//! holes) scored by their worst corner and the valences they leave, new
//! vertices placed on and relaxed over the input surface.

use crate::mesh::NONE;
use crate::quads::{QuadMesh, SurfacePoint};
use crate::vec3::{add, cross, dot, norm, scale, sub, V3};
use crate::TriMesh;
use std::collections::HashMap;

/// Cuts tried per hole of 6 to 16 sides (the shortest ones; longer holes
/// take the shortest cut only, which bounds the search).
const CUTS_TRIED: usize = 3;

/// Weight of a unit of valence away from 4 against the sine of the worst
/// corner angle, in [`Patch::score`].
const VALENCE_WEIGHT: f64 = 0.05;

/// Relaxation steps of the new vertices of a filled hole.
const SMOOTHING_STEPS: usize = 10;

/// Input faces searched for the surface point nearest to a new vertex.
const MAX_SEARCH_FACES: usize = 20_000;

/// Fills the even cycle `polygon` with quads ([`Patch::plan`]) and relaxes
/// the vertices it creates; the number of quads added.
pub(super) fn fill_polygon(mesh: &TriMesh, quads: &mut QuadMesh, polygon: &[u32]) -> usize {
    let before = quads.n_quads();
    let first_new = quads.n_vertices();
    let neighbours = corner_neighbours(quads, polygon);
    let mut patch = Patch { mesh, faces: search_faces(mesh, quads, polygon), quads, neighbours };
    for q in patch.plan(polygon) {
        patch.push_quad(q);
    }
    patch.smooth(before, first_new);
    quads.n_quads() - before
}

/// The vertices joined by a quad edge to each vertex of `hole`, sorted.
fn corner_neighbours(quads: &QuadMesh, hole: &[u32]) -> HashMap<u32, Vec<u32>> {
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
            (v, list)
        })
        .collect()
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
    /// The vertices joined by a quad edge to each corner of the hole
    /// before it is filled ([`corner_neighbours`]).
    neighbours: HashMap<u32, Vec<u32>>,
}

impl Patch<'_> {
    fn position(&self, v: u32) -> V3 {
        self.quads.positions[v as usize]
    }

    /// The point of the searched input faces nearest to `x`.
    fn nearest(&self, x: V3) -> (SurfacePoint, V3) {
        SurfacePoint::nearest(self.mesh, self.faces.iter().copied(), x)
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
        let scored: Vec<(f64, Vec<[u32; 4]>)> = candidates.into_iter().map(|c| (self.score(hole, &c), c)).collect();
        scored.into_iter().max_by(|a, b| a.0.total_cmp(&b.0)).map(|(_, c)| c).unwrap_or_default()
    }

    /// How good a filling of `hole` by `quads` is: its worst corner (the
    /// sine of the corner angle, negative where a quad folds), less a
    /// penalty for vertices whose valence it takes away from 4; minus
    /// infinity where it joins two corners the quads already join (that
    /// edge would have three quads: a quad hanging into the hole by three
    /// sides, cut off as a quad over the same four vertices, seen on a
    /// jittered fandisk stretched 3 x 1 x 0.5, creases above 60°, 3 000
    /// quads).
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
                if self.neighbours.get(&a).is_some_and(|joined| joined.binary_search(&b).is_ok()) {
                    return f64::NEG_INFINITY;
                }
                *degree.entry(a).or_default() += 1;
                *degree.entry(b).or_default() += 1;
            }
        }
        let valence_cost: f64 = degree
            .iter()
            .map(|(v, &added)| {
                let before = self.neighbours.get(v).map_or(0, Vec::len) as f64;
                (before + added as f64 - 4.0).abs() - if self.neighbours.contains_key(v) { (before - 4.0).abs() } else { 0.0 }
            })
            .sum();
        worst - VALENCE_WEIGHT * valence_cost
    }
}


#[cfg(test)]
mod tests {
    use super::fill_polygon;
    use crate::quads::{QuadMesh, SurfacePoint};
    use crate::TriMesh;

    /// A 2 x 1 hole whose best filling, two unit squares split by the edge
    /// from `b` to `e`, would repeat an edge a quad hanging into it already
    /// has: the filling goes around that edge instead.
    #[test]
    fn a_filling_never_joins_two_corners_the_quads_already_join() {
        let rectangle = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mesh = TriMesh::from_welded_arrays(rectangle, vec![[0, 1, 2], [0, 2, 3]]).expect("a valid rectangle");
        // a b c d e f around the hole, then the hanging quad's far corners x y.
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.5, 0.5, 0.0],
            [1.5, 0.4, 0.0],
        ];
        let at = SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] };
        let (b, e) = (1, 4);
        let hanging = [b, e, 6, 7];
        let mut quads = QuadMesh {
            locations: vec![at; positions.len()],
            positions,
            quads: vec![hanging],
            uv: [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].to_vec(),
            defects: Vec::new(),
        };
        let added = fill_polygon(&mesh, &mut quads, &[0, 1, 2, 3, 4, 5]);
        assert!(added > 0);
        let joins = |q: &[u32; 4], a: u32, b: u32| (0..4).any(|i| [q[i], q[(i + 1) % 4]] == [a, b] || [q[i], q[(i + 1) % 4]] == [b, a]);
        for q in &quads.quads[1..] {
            assert!(!joins(q, b, e), "the filling {:?} joins b and e again", &quads.quads[1..]);
        }
    }
}
