//! Interior decimation: a coarser mesh of the same surface whose vertices
//! are a subset of the input's, for a coarse-to-fine cone placement and for
//! the quads of a mesh much finer than them ([`crate::pipeline::Coarse`]:
//! feature-curve vertices kept too, [`decimate_keeping`]).
//!
//! Half-edge collapses `u -> v` of interior vertices `u` (Garland & Heckbert
//! 1997 quadric error at `v`'s position, since `v` stays where it is), in
//! order of cost, while the link condition holds and no face turns by more
//! than [`MAX_TURN`]. Boundary vertices and edges are never touched, so the
//! boundary polylines (and, on a cut mesh, every feature curve) are exactly
//! the input's, and the Euler characteristic is kept.

use super::TriMesh;
use crate::vec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Smallest cosine between a face's normal before and after a collapse
/// ([`decimate_interior`]).
const MAX_TURN: f64 = 0.5;
/// Smallest ratio of twice a face's area to its longest edge squared after
/// a collapse (rejects needles; an equilateral triangle has 0.87).
const MIN_SHAPE: f64 = 0.05;

/// A coarse mesh and, per coarse vertex, the input vertex it is.
pub struct Decimated {
    pub mesh: TriMesh,
    pub vertex: Vec<u32>,
}

/// A symmetric 4x4 quadric (upper triangle, 10 values).
#[derive(Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    /// The plane through `p` with unit normal `n`, weighted by `w`.
    fn plane(n: [f64; 3], p: [f64; 3], w: f64) -> Quadric {
        let d = -vec3::dot(n, p);
        let q = [n[0], n[1], n[2], d];
        let mut out = [0.0; 10];
        let mut k = 0;
        for i in 0..4 {
            for j in i..4 {
                out[k] = w * q[i] * q[j];
                k += 1;
            }
        }
        Quadric(out)
    }

    fn add(&mut self, o: &Quadric) {
        self.0.iter_mut().zip(&o.0).for_each(|(a, b)| *a += b);
    }

    /// The weighted mean of the squared distances from `p` to the planes:
    /// [`Self::error`] over the summed weights (the trace of the normal part).
    fn mean_squared_distance(&self, p: [f64; 3]) -> f64 {
        let weight = self.0[0] + self.0[4] + self.0[7];
        if weight > 0.0 {
            self.error(p) / weight
        } else {
            0.0
        }
    }

    /// `[p 1] Q [p 1]ᵀ`.
    fn error(&self, p: [f64; 3]) -> f64 {
        let x = [p[0], p[1], p[2], 1.0];
        let mut e = 0.0;
        let mut k = 0;
        for i in 0..4 {
            for j in i..4 {
                e += if i == j { 1.0 } else { 2.0 } * self.0[k] * x[i] * x[j];
                k += 1;
            }
        }
        e.max(0.0)
    }
}

/// A collapse candidate, cheapest first in the heap.
struct Candidate {
    cost: f64,
    from: u32,
    to: u32,
    stamp: (u32, u32),
}

impl PartialEq for Candidate {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap. Ties by vertex ids, so the
        // result does not depend on the heap's internals.
        o.cost.total_cmp(&self.cost).then_with(|| o.from.cmp(&self.from)).then_with(|| o.to.cmp(&self.to))
    }
}

/// Decimates `mesh` until at most `target_interior` interior vertices remain
/// (or no collapse is valid). `None` if nothing could be removed or the
/// result does not validate as a mesh.
pub fn decimate_interior(mesh: &TriMesh, target_interior: usize) -> Option<Decimated> {
    let limits = CollapseLimits { min_turn_cos: MAX_TURN, max_distance: f64::INFINITY };
    decimate_keeping(mesh, target_interior, &vec![false; mesh.n_vertices()], limits)
}

/// What a collapse of [`decimate_keeping`] may do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollapseLimits {
    /// Smallest cosine between a face's normal before and after.
    pub min_turn_cos: f64,
    /// Largest root-mean-square distance (area-weighted) from the kept
    /// vertex to the planes of the input faces merged into it (the quadric
    /// of Garland & Heckbert over its weight): a tip worn down by repeated
    /// collapses moves away from its input faces' planes.
    pub max_distance: f64,
}

/// [`decimate_interior`] that also keeps the vertices marked in `keep`
/// (and so every edge between two of them: a collapse removes only the
/// vertex it moves), until at most `target_free` vertices neither on the
/// boundary nor kept remain or no collapse within `limits` is left.
pub fn decimate_keeping(mesh: &TriMesh, target_free: usize, keep: &[bool], limits: CollapseLimits) -> Option<Decimated> {
    let min_turn_cos = limits.min_turn_cos;
    let nv = mesh.n_vertices();
    let pos = mesh.positions();
    let mut faces: Vec<[u32; 3]> = mesh.faces().to_vec();
    let mut alive_face = vec![true; faces.len()];
    let mut incident: Vec<Vec<u32>> = (0..nv as u32).map(|v| mesh.vertex_faces(v).collect()).collect();
    // Vertices never removed: the boundary and the kept ones.
    let fixed: Vec<bool> = (0..nv as u32).map(|v| mesh.is_boundary_vertex(v) || keep.get(v as usize).copied().unwrap_or(false)).collect();
    let mut stamp = vec![0u32; nv];
    let mut alive = vec![true; nv];

    let normal = |t: [u32; 3]| {
        let p = t.map(|v| pos[v as usize]);
        vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]))
    };
    let mut quadric = vec![Quadric::default(); nv];
    for t in &faces {
        let n = normal(*t);
        let a = vec3::norm(n);
        if a > 0.0 {
            let q = Quadric::plane(vec3::scale(n, 1.0 / a), pos[t[0] as usize], a);
            for &v in t {
                quadric[v as usize].add(&q);
            }
        }
    }
    let cost = |quadric: &[Quadric], u: u32, v: u32| {
        let mut q = quadric[u as usize];
        q.add(&quadric[v as usize]);
        // A little edge length keeps the coarse triangles from stretching on flat parts.
        q.error(pos[v as usize]) + 1e-3 * { let d = vec3::sub(pos[u as usize], pos[v as usize]); vec3::dot(d, d) }
    };
    let mut heap = BinaryHeap::new();
    // Scratch rings, reused across collapses (this loop is most of the cost).
    let (mut ring_u, mut ring_v, mut ring_w) = (Vec::new(), Vec::new(), Vec::new());
    for u in 0..nv as u32 {
        if !fixed[u as usize] {
            neighbours_into(&incident, &faces, u, &mut ring_u);
            for &v in &ring_u {
                heap.push(Candidate { cost: cost(&quadric, u, v), from: u, to: v, stamp: (0, 0) });
            }
        }
    }

    let mut free = fixed.iter().filter(|b| !**b).count();
    let mut removed = 0usize;
    // Stale candidates are dropped once they would make up most of the heap,
    // so that it stays cache-sized (its pops were most of the decimation).
    let mut compact_at = 2 * heap.len().max(1024);
    while free > target_free {
        if heap.len() > compact_at {
            heap.retain(|c| alive[c.from as usize] && alive[c.to as usize] && c.stamp == (stamp[c.from as usize], stamp[c.to as usize]));
            compact_at = 2 * heap.len().max(1024);
        }
        let Some(c) = heap.pop() else { break };
        let (u, v) = (c.from, c.to);
        if !alive[u as usize] || !alive[v as usize] || c.stamp != (stamp[u as usize], stamp[v as usize]) {
            continue;
        }
        neighbours_into(&incident, &faces, u, &mut ring_u);
        neighbours_into(&incident, &faces, v, &mut ring_v);
        if !collapse_is_valid(pos, &faces, &incident, u, v, &ring_u, &ring_v, min_turn_cos) {
            continue;
        }
        if limits.max_distance.is_finite() {
            let mut merged = quadric[u as usize];
            merged.add(&quadric[v as usize]);
            if merged.mean_squared_distance(pos[v as usize]) > limits.max_distance * limits.max_distance {
                continue;
            }
        }
        // Collapse: drop the faces on edge uv, move u's other faces to v.
        for f in std::mem::take(&mut incident[u as usize]) {
            let t = faces[f as usize];
            if t.contains(&v) {
                alive_face[f as usize] = false;
                for &w in &t {
                    incident[w as usize].retain(|&g| g != f);
                }
            } else {
                faces[f as usize] = t.map(|w| if w == u { v } else { w });
                incident[v as usize].push(f);
            }
        }
        alive[u as usize] = false;
        let qu = quadric[u as usize];
        quadric[v as usize].add(&qu);
        free -= 1;
        removed += 1;
        stamp[v as usize] += 1;
        neighbours_into(&incident, &faces, v, &mut ring_v);
        for &w in &ring_v {
            stamp[w as usize] += 1;
        }
        for &w in &ring_v {
            for (a, b) in [(w, v), (v, w)] {
                if !fixed[a as usize] {
                    heap.push(Candidate { cost: cost(&quadric, a, b), from: a, to: b, stamp: (stamp[a as usize], stamp[b as usize]) });
                }
            }
            // Edges of w to its other neighbours changed cost through w's stamp.
            if !fixed[w as usize] {
                neighbours_into(&incident, &faces, w, &mut ring_w);
                for &x in &ring_w {
                    if x != v {
                        heap.push(Candidate { cost: cost(&quadric, w, x), from: w, to: x, stamp: (stamp[w as usize], stamp[x as usize]) });
                    }
                }
            }
        }
    }
    if removed == 0 {
        return None;
    }
    // Compact, numbering vertices in order of first use (as the mesh builder does).
    let mut new_id = vec![u32::MAX; nv];
    let mut vertex = Vec::new();
    let mut triangles = Vec::new();
    for (f, t) in faces.iter().enumerate() {
        if alive_face[f] {
            triangles.push(t.map(|w| {
                if new_id[w as usize] == u32::MAX {
                    new_id[w as usize] = vertex.len() as u32;
                    vertex.push(w);
                }
                new_id[w as usize]
            }));
        }
    }
    let positions = vertex.iter().map(|&w| pos[w as usize]).collect();
    let coarse = TriMesh::from_welded_arrays(positions, triangles).ok()?;
    (coarse.n_vertices() == vertex.len()).then_some(Decimated { mesh: coarse, vertex })
}

/// The vertices sharing a face with `v`, sorted, into `out` (cleared first).
fn neighbours_into(incident: &[Vec<u32>], faces: &[[u32; 3]], v: u32, out: &mut Vec<u32>) {
    out.clear();
    out.extend(incident[v as usize].iter().flat_map(|&f| faces[f as usize]).filter(|&w| w != v));
    out.sort_unstable();
    out.dedup();
}

/// The link condition (the common neighbours of `u` and `v` are the two
/// vertices opposite edge uv) and the shape of the faces `u` moves to `v`
/// (none turns by more than the angle of cosine `min_turn_cos`).
/// `nu`, `nvv`: the sorted [`neighbours_into`] of `u` and `v`.
#[allow(clippy::too_many_arguments)]
fn collapse_is_valid(
    pos: &[[f64; 3]],
    faces: &[[u32; 3]],
    incident: &[Vec<u32>],
    u: u32,
    v: u32,
    nu: &[u32],
    nvv: &[u32],
    min_turn_cos: f64,
) -> bool {
    if !nvv.contains(&u) {
        return false;
    }
    let common = nu.iter().filter(|w| nvv.binary_search(w).is_ok()).count();
    let on_edge = incident[u as usize].iter().filter(|&&f| faces[f as usize].contains(&v)).count();
    if on_edge != 2 || common != 2 {
        return false;
    }
    for &f in &incident[u as usize] {
        let t = faces[f as usize];
        if t.contains(&v) {
            continue;
        }
        let p = t.map(|w| pos[w as usize]);
        let q = t.map(|w| pos[if w == u { v } else { w } as usize]);
        let n0 = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
        let n1 = vec3::cross(vec3::sub(q[1], q[0]), vec3::sub(q[2], q[0]));
        let (a0, a1) = (vec3::norm(n0), vec3::norm(n1));
        if a0 == 0.0 || a1 == 0.0 || vec3::dot(n0, n1) < min_turn_cos * a0 * a1 {
            return false;
        }
        let longest = (0..3).map(|k| { let d = vec3::sub(q[k], q[(k + 1) % 3]); vec3::dot(d, d) }).fold(0.0, f64::max);
        if a1 < MIN_SHAPE * longest {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{shapes, subdivide_midpoint, RawMesh};

    /// An octahedron subdivided `levels` times, projected onto the unit sphere.
    fn sphere(levels: usize) -> TriMesh {
        let mut raw = RawMesh {
            positions: vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]],
            triangles: vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
        };
        for _ in 0..levels {
            raw = subdivide_midpoint(&raw);
        }
        raw.positions.iter_mut().for_each(|p| *p = vec3::scale(*p, 1.0 / vec3::norm(*p)));
        TriMesh::from_raw(&raw).unwrap()
    }

    #[test]
    fn a_decimated_sphere_keeps_its_topology_and_uses_input_vertices() {
        let fine = sphere(4);
        let target = fine.n_vertices() / 8;
        let d = decimate_interior(&fine, target).expect("decimates");
        assert!(d.mesh.n_vertices() <= target, "{} vertices", d.mesh.n_vertices());
        assert_eq!(d.mesh.euler_characteristic(), 2);
        for (cv, &v) in d.vertex.iter().enumerate() {
            assert_eq!(d.mesh.position(cv as u32), fine.position(v), "coarse vertices are input vertices");
        }
    }

    #[test]
    fn boundary_vertices_and_edges_are_kept() {
        let fine = TriMesh::from_raw(&shapes::grid(12, 12, |x, y| [x, y, 0.1 * (x * y).sin()])).unwrap();
        let d = decimate_interior(&fine, 10).expect("decimates");
        let boundary = |m: &TriMesh| (0..m.n_vertices() as u32).filter(|&v| m.is_boundary_vertex(v)).count();
        assert_eq!(boundary(&d.mesh), boundary(&fine));
        assert!(d.mesh.n_vertices() - boundary(&d.mesh) <= 10);
        assert_eq!(d.mesh.boundary_loops().len(), 1);
        assert_eq!(d.mesh.euler_characteristic(), 1);
    }

    /// A plate with a thin spike in its middle and a kept diagonal: the
    /// kept vertices all stay; without a distance limit the spike's tip
    /// is worn down to the target count, with one the tip stays.
    #[test]
    fn kept_vertices_stay_and_a_distance_limit_keeps_a_tip() {
        let spike = |x: f64, y: f64| [x, y, 0.5 * (-((x - 0.5).powi(2) + (y - 0.5).powi(2)) / 0.002).exp()];
        let fine = TriMesh::from_raw(&shapes::grid(24, 24, spike)).unwrap();
        let tip = (0..fine.n_vertices() as u32).max_by(|&a, &b| fine.position(a)[2].total_cmp(&fine.position(b)[2])).unwrap();
        let keep: Vec<bool> = (0..fine.n_vertices() as u32).map(|v| { let p = fine.position(v); (p[0] - p[1]).abs() < 1e-9 && v != tip }).collect();
        assert!(keep.iter().filter(|&&k| k).count() >= 20);
        let loose = CollapseLimits { min_turn_cos: -1.0, max_distance: f64::INFINITY };
        let d = decimate_keeping(&fine, 4, &keep, loose).expect("decimates");
        for v in (0..fine.n_vertices()).filter(|&v| keep[v]) {
            assert!(d.vertex.contains(&(v as u32)), "kept vertex {v} removed");
        }
        assert!(!d.vertex.contains(&tip), "the tip worn down");
        let limited = decimate_keeping(&fine, 4, &keep, CollapseLimits { max_distance: 0.01, ..loose }).expect("decimates");
        assert!(limited.vertex.contains(&tip), "the tip kept");
        assert!(limited.mesh.n_vertices() > d.mesh.n_vertices());
    }
}
