//! The mesh cut open along its features (section 4), and the turning
//! integers its boundary corners get.

use super::FeatureSet;
use crate::mesh::{TriMesh, UnionFind, NONE};
use crate::vec3::{dot, sub};
use std::f64::consts::{FRAC_PI_2, PI};

/// A mesh cut open along its feature edges.
#[derive(Clone, Debug)]
pub struct CutMesh {
    /// The cut mesh: each feature edge became two boundary edges.
    pub mesh: TriMesh,
    /// Cut vertex → vertex of the original mesh.
    pub original_vertex: Vec<u32>,
    /// Cut edge → edge of the original mesh.
    pub original_edge: Vec<u32>,
    /// Per cut edge: true for a boundary edge of the original mesh left free
    /// ([`CutMesh::free_original_boundary`]): not held on an isoline, and
    /// its end vertices get no corner.
    pub free: Vec<bool>,
}

impl CutMesh {
    /// Frees the boundary of the original mesh (feature edges stay aligned).
    pub fn free_original_boundary(&mut self, original: &TriMesh) {
        self.free = (0..self.mesh.n_edges() as u32)
            .map(|e| self.mesh.is_boundary_edge(e) && original.is_boundary_edge(self.original_edge[e as usize]))
            .collect();
    }

    /// True when some edges are free.
    pub fn has_free_boundary(&self) -> bool {
        self.free.iter().any(|&f| f)
    }

    /// True when the edge of halfedge `h` is a boundary edge of the cut mesh
    /// that must lie on an isoline (a feature, or an aligned boundary).
    pub fn is_aligned_halfedge(&self, h: u32) -> bool {
        let e = self.mesh.edge(h);
        self.mesh.is_boundary_edge(e) && !self.free[e as usize]
    }

    /// True when vertex `v` of the cut mesh ends a free edge.
    pub fn touches_free(&self, v: u32) -> bool {
        self.mesh.outgoing(v).any(|h| self.free[self.mesh.edge(h) as usize])
    }
}

/// Cuts `mesh` open along `features`: the corners around each vertex are
/// split into the sectors separated by feature edges, one new vertex per
/// sector. Faces keep their indices. An isolated feature edge whose two ends
/// are interior and touch no other feature cannot be opened (it would become
/// two edges between the same two vertices) and is left closed.
pub fn cut_open(mesh: &TriMesh, features: &FeatureSet) -> CutMesh {
    let degree = features.degrees(mesh);
    let splits = |v: u32| degree[v as usize] >= 2 || mesh.is_boundary_vertex(v);
    let is_cut = |e: u32| features.contains(e) && mesh.edge_vertices(e).iter().any(|&v| splits(v));
    // Union corners (3 f + k) across every interior non-feature edge.
    let n_corners = 3 * mesh.n_faces();
    let mut corners = UnionFind::new(n_corners);
    for e in 0..mesh.n_edges() as u32 {
        if is_cut(e) || mesh.is_boundary_edge(e) {
            continue;
        }
        let [h, t] = mesh.edge_halfedges(e);
        // Halfedge h = 3f + k runs corner k -> k + 1; its twin runs the other way.
        let (ht, hh) = (h, 3 * (h / 3) + (h % 3 + 1) % 3);
        let (tt, th) = (t, 3 * (t / 3) + (t % 3 + 1) % 3);
        for (a, b) in [(ht, th), (hh, tt)] {
            corners.union(a, b);
        }
    }
    let mut new_id = vec![NONE; n_corners];
    let mut original_vertex = Vec::new();
    let mut faces = Vec::with_capacity(mesh.n_faces());
    for (f, tri) in mesh.faces().iter().enumerate() {
        let mut out = [0u32; 3];
        for k in 0..3 {
            let r = corners.find((3 * f + k) as u32) as usize;
            if new_id[r] == NONE {
                new_id[r] = original_vertex.len() as u32;
                original_vertex.push(tri[k]);
            }
            out[k] = new_id[r];
        }
        faces.push(out);
    }
    let positions = original_vertex.iter().map(|&v| mesh.position(v)).collect();
    let cut = TriMesh::from_welded_arrays(positions, faces)
        .expect("cutting a valid mesh along edges keeps it manifold and oriented");
    // The builder renumbers vertices by first use; follow its numbering.
    let original_vertex = cut.welded_to_source().iter().map(|&s| original_vertex[s as usize]).collect();
    let original_edge = (0..cut.n_edges() as u32)
        .map(|e| {
            let h = cut.edge_halfedges(e)[0];
            mesh.edge(h) // face halfedge numbering is shared (3 f + k)
        })
        .collect();
    let free = vec![false; cut.n_edges()];
    CutMesh { mesh: cut, original_vertex, original_edge, free }
}


/// Turning integer of every boundary vertex (0 elsewhere): the corner's
/// turning `t_v = (pi - angle sum) / (pi/2)` rounded, at most 1 so every
/// boundary corner keeps a parametric angle of at least 90° (a sector
/// sharper than 45° would otherwise round to a zero angle and collapse).
///
/// Each corner is rounded on its own (section 4), unless that leaves a
/// component's interior with much more to carry than its curvature: the
/// indices of a component add to `4 chi` (Gauss-Bonnet), so the interior
/// cones must sum to `4 chi - sum k`, against `round(K / (pi/2))` for the
/// angle defect `K` of the interior vertices. Along a long or jagged feature
/// loop the rounding errors add up, and a small region enclosed by it would
/// need cones of angle `<= 0`. Where the two differ by [`MAX_ROUNDING_DRIFT`]
/// or more, corners are moved by a quarter turn until the difference is gone
/// (sum-preserving rounding): first each loop gets back a share in
/// proportion to the turning its own rounding lost ([`spread_along_loops`]),
/// then the corners of the component take the rest; each time the corners
/// whose rounding was closest to going the other way move first, equally
/// close ones spread apart ([`spread_ties`]). Where
/// the 90° bound leaves no corner to move, the pipeline refines
/// ([`super::refine_for_features`], [`super::split_around`]).
pub fn boundary_turning(mesh: &TriMesh) -> Vec<i32> {
    let sums = mesh.angle_sums();
    let nv = mesh.n_vertices();
    let turning: Vec<f64> = (0..nv).map(|v| (PI - sums[v]) / FRAC_PI_2).collect();
    let mut k: Vec<i32> = (0..nv as u32)
        .map(|v| if mesh.is_boundary_vertex(v) { (turning[v as usize].round() as i32).min(1) } else { 0 })
        .collect();
    let nc = mesh.n_components();
    let mut corners: Vec<Vec<u32>> = vec![Vec::new(); nc];
    let mut sum = vec![0i64; nc];
    let mut interior_defect = vec![0.0f64; nc];
    let mut loops: Vec<Vec<Vec<u32>>> = vec![Vec::new(); nc];
    for i in 0..mesh.boundary_loops().len() {
        let vertices = mesh.boundary_loop_vertices(i);
        loops[mesh.vertex_component(vertices[0])].push(vertices);
    }
    for v in 0..nv as u32 {
        let c = mesh.vertex_component(v);
        if mesh.is_boundary_vertex(v) {
            corners[c].push(v);
            sum[c] += k[v as usize] as i64;
        } else {
            interior_defect[c] += 2.0 * PI - sums[v as usize];
        }
    }
    for c in 0..nc {
        let target = 4 * mesh.component_euler_characteristic(c) - (interior_defect[c] / FRAC_PI_2).round() as i64;
        if (target - sum[c]).abs() < MAX_ROUNDING_DRIFT {
            continue;
        }
        let step: i32 = if sum[c] < target { 1 } else { -1 };
        let mut need = (target - sum[c]).unsigned_abs() as usize;
        need -= spread_along_loops(mesh, &loops[c], step, need, &turning, &mut k);
        while need > 0 {
            let order = closest_order(&corners[c], step, &turning, &k);
            if order.is_empty() {
                break;
            }
            let moved = need.min(order.len());
            for v in spread_ties(mesh, &order, moved) {
                k[v as usize] += step;
            }
            need -= moved;
        }
    }
    k
}

/// Moves up to `need` corners of one component's boundary `loops` (vertices
/// in loop order) by `step`, loop by loop:
/// each boundary loop takes a share of `need` in proportion to the turning
/// its corners' rounding lost in the direction of `step` (largest
/// remainders, at most that turning rounded), and moves its own corners in
/// the order of [`boundary_turning`] ([`spread_ties`]). A circle's lost
/// turning goes back to that circle: a plate with three round holes gets
/// four corners on each, where the component-wide order put six on the two
/// that turned most per vertex and none on the third. Returns the moves made.
fn spread_along_loops(mesh: &TriMesh, loops: &[Vec<u32>], step: i32, need: usize, turning: &[f64], k: &mut [i32]) -> usize {
    let lost: Vec<f64> = loops.iter().map(|l| l.iter().map(|&v| closeness(v, step, turning, k)).sum::<f64>().max(0.0)).collect();
    let all: f64 = lost.iter().sum();
    if !(all > 0.0) {
        return 0;
    }
    let exact: Vec<f64> = lost.iter().map(|d| need as f64 * d / all).collect();
    let mut share: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let mut by_remainder: Vec<usize> = (0..loops.len()).collect();
    by_remainder.sort_by(|&a, &b| (exact[b] - exact[b].floor()).total_cmp(&(exact[a] - exact[a].floor())).then(a.cmp(&b)));
    let left = need.saturating_sub(share.iter().sum::<usize>()); // < loops.len(): the remainders add to less
    for &l in by_remainder.iter().take(left) {
        share[l] += 1;
    }
    let mut moved = 0;
    for (l, vertices) in loops.iter().enumerate() {
        let n = share[l].min(lost[l].round() as usize);
        let mut order = closest_order(vertices, step, turning, k);
        order.retain(|c| c.0 > 0.0);
        for v in spread_ties(mesh, &order, n.min(order.len())) {
            k[v as usize] += step;
            moved += 1;
        }
    }
    moved
}

/// How close corner `v`'s rounding was to going the other way, in the
/// direction of `step`: `step (t_v - k_v)` quarter turns.
fn closeness(v: u32, step: i32, turning: &[f64], k: &[i32]) -> f64 {
    step as f64 * (turning[v as usize] - k[v as usize] as f64)
}

/// The `corners` that may move by `step` (none above 1), as `(closeness,
/// tie hash, vertex)` sorted by [`closest_first`].
fn closest_order(corners: &[u32], step: i32, turning: &[f64], k: &[i32]) -> Vec<(f64, u64, u32)> {
    let mut order: Vec<(f64, u64, u32)> = corners
        .iter()
        .filter(|&&v| step < 0 || k[v as usize] < 1)
        .map(|&v| (closeness(v, step, turning, k), spread(v), v))
        .collect();
    order.sort_by(closest_first);
    order
}

/// Closeness (quarter turns; 0.09°) within which two corners are equally
/// sharp for [`spread_ties`]: far above an export's float noise (1e-5 on a
/// CAD circle), far below the turning of a corner.
const SAME_TURNING: f64 = 1e-3;

/// The first `count` corners of `order` (sorted by [`closest_first`]), save
/// that among corners within [`SAME_TURNING`] of the closest one left, the
/// one farthest from those picked already is picked next. A round hole,
/// whose vertices all turn alike, gets its corners evenly spaced, as a
/// square hole's; by closeness alone they follow the rounding noise of the
/// export (a CAD bracket's holes: three corners within 15°, twice).
fn spread_ties(mesh: &TriMesh, order: &[(f64, u64, u32)], count: usize) -> Vec<u32> {
    let mut picked = Vec::with_capacity(count);
    let mut taken = vec![false; order.len()];
    // Squared distance of each corner to the nearest picked one.
    let mut gap = vec![f64::INFINITY; order.len()];
    for _ in 0..count {
        let Some(first) = taken.iter().position(|t| !t) else { break };
        let equal = order[first].0 - SAME_TURNING;
        let mut best = first;
        for i in first..order.len() {
            if order[i].0 < equal {
                break;
            }
            if !taken[i] && gap[i] > gap[best] {
                best = i;
            }
        }
        taken[best] = true;
        let p = mesh.position(order[best].2);
        picked.push(order[best].2);
        for (i, g) in gap.iter_mut().enumerate() {
            let d = sub(p, mesh.position(order[i].2));
            *g = g.min(dot(d, d));
        }
    }
    picked
}

/// Order of corners `(closeness, tie hash, vertex)` for [`boundary_turning`]:
/// closest to going the other way first, closeness in buckets of 1e-9 and
/// ties by hash. (A tolerance comparison is not a total order, and the sort
/// panicked on it: a jittered bff-face x4.)
fn closest_first(a: &(f64, u64, u32), b: &(f64, u64, u32)) -> std::cmp::Ordering {
    let bucket = |x: f64| (x * 1e9).round();
    bucket(b.0).total_cmp(&bucket(a.0)).then(a.1.cmp(&b.1))
}

/// Difference (quarter turns) between what a component's interior must
/// carry after independent corner rounding and its own curvature from which
/// [`boundary_turning`] rounds the corners as a whole.
pub const MAX_ROUNDING_DRIFT: i64 = 2;

/// A fixed scramble of a vertex id (splitmix64), to break exact ties evenly.
fn spread(v: u32) -> u64 {
    let mut z = (v as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::{boundary_turning, closest_first};
    use crate::cones::test_meshes::square_with_round_hole;
    use std::cmp::Ordering;

    /// A round hole in a flat square turns a full circle in steps that each
    /// round to no corner; the four concave corners it needs (Gauss-Bonnet)
    /// are spaced evenly around it, as a square hole's, not bunched where
    /// a tie-break hash put them.
    #[test]
    fn a_round_hole_gets_four_evenly_spaced_corners() {
        let n = 12;
        let mesh = square_with_round_hole(n, 4, 0.4);
        let k = boundary_turning(&mesh);
        let hole = (0..mesh.boundary_loops().len())
            .map(|i| mesh.boundary_loop_vertices(i))
            .find(|l| mesh.position(l[0])[0].hypot(mesh.position(l[0])[1]) < 0.5)
            .expect("the hole is a boundary loop");
        let corners: Vec<usize> = (0..hole.len()).filter(|&i| k[hole[i] as usize] != 0).collect();
        assert!(corners.iter().all(|&i| k[hole[i] as usize] == -1), "{:?}", corners.iter().map(|&i| k[hole[i] as usize]).collect::<Vec<_>>());
        assert_eq!(corners.len(), 4, "corners at {corners:?}");
        for (a, b) in corners.iter().zip(corners.iter().cycle().skip(1)) {
            assert_eq!((b + hole.len() - a) % hole.len(), n, "corners at {corners:?} of {}", hole.len());
        }
        let outer: i32 = (0..mesh.n_vertices()).filter(|&v| !hole.contains(&(v as u32))).map(|v| k[v]).sum();
        assert_eq!(outer, 4, "the square keeps its four convex corners");
    }

    /// Corners whose closeness differs by less than the old 1e-9 tolerance in
    /// a chain (a ~ b, b ~ c, a !~ c) are still ordered consistently:
    /// transitive, antisymmetric, and a sort of them does not panic.
    #[test]
    fn corner_order_is_a_total_order() {
        let values: Vec<(f64, u64, u32)> = (0..200u32).map(|i| (0.3 + i as f64 * 0.6e-9, (i as u64 * 7919) % 97, i)).collect();
        for a in &values {
            for b in &values {
                assert_eq!(closest_first(a, b), closest_first(b, a).reverse());
                for c in values.iter().step_by(7) {
                    if closest_first(a, b) != Ordering::Greater && closest_first(b, c) != Ordering::Greater {
                        assert_ne!(closest_first(a, c), Ordering::Greater, "{a:?} {b:?} {c:?}");
                    }
                }
            }
        }
        let mut sorted = values.clone();
        sorted.sort_by(closest_first);
        assert!(sorted.windows(2).all(|w| closest_first(&w[0], &w[1]) != Ordering::Greater));
    }
}
