//! The mesh cut open along its features (section 4), and the turning
//! integers its boundary corners get.

use super::FeatureSet;
use crate::mesh::{TriMesh, UnionFind, NONE};
use crate::vec3::{dot, sub, V3};
use std::collections::HashMap;
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
/// proportion to the turning its own corners' rounding lost ([`spread_along_loops`]),
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
            let order = closest_order(mesh, &corners[c], step, &turning, &k);
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
/// its own corners' rounding lost in the direction of `step` (largest
/// remainders, at most that turning rounded), and moves its own corners in
/// the order of [`boundary_turning`] ([`spread_ties`]). A circle's lost
/// turning goes back to that circle: a plate with three round holes gets
/// four corners on each, where the component-wide order put six on the two
/// that turned most per vertex and none on the third. Returns the moves made.
///
/// A loop's own corners are those whose position it passes once
/// ([`own_corners`]): where a feature curve ends inside the surface, the cut
/// runs up one side of it and back down the other in one loop, and the two
/// sides' turning adds up to the Gaussian curvature along the curve, which
/// the cones may carry anywhere near, not turning of a curve around a
/// region (a 114 k bunny's convex crease of 2.4 quarter turns took two
/// corners of 90° where the crease bends 26°: seamless distortion 0.10 ->
/// 0.14, 9 places in its quads at 3 000 after 4 min of rounding).
fn spread_along_loops(mesh: &TriMesh, loops: &[Vec<u32>], step: i32, need: usize, turning: &[f64], k: &mut [i32]) -> usize {
    let own: Vec<Vec<u32>> = loops.iter().map(|l| own_corners(mesh, l)).collect();
    let lost: Vec<f64> = own.iter().map(|l| l.iter().map(|&v| closeness(v, step, turning, k)).sum::<f64>().max(0.0)).collect();
    let all: f64 = lost.iter().sum();
    if !(all > 0.0) {
        return 0;
    }
    let exact: Vec<f64> = lost.iter().map(|d| need as f64 * d / all).collect();
    let mut share: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let mut by_remainder: Vec<usize> = (0..loops.len()).collect();
    // Equal remainders (alike loops) by a key of their positions, not their numbering.
    let key: Vec<V3> = own.iter().map(|l| l.iter().map(|&v| mesh.position(v)).min_by(lexicographic).unwrap_or_default()).collect();
    by_remainder.sort_by(|&a, &b| (exact[b] - exact[b].floor()).total_cmp(&(exact[a] - exact[a].floor())).then(lexicographic(&key[a], &key[b])));
    let left = need.saturating_sub(share.iter().sum::<usize>()); // < loops.len(): the remainders add to less
    for &l in by_remainder.iter().take(left) {
        share[l] += 1;
    }
    let mut moved = 0;
    for (l, vertices) in own.iter().enumerate() {
        let n = share[l].min(lost[l].round() as usize);
        let mut order = closest_order(mesh, vertices, step, turning, k);
        order.retain(|c| c.0 > 0.0);
        for v in spread_ties(mesh, &order, n.min(order.len())) {
            k[v as usize] += step;
            moved += 1;
        }
    }
    moved
}

/// The vertices of boundary loop `vertices` whose position no other vertex
/// of the loop shares (the sides of a cut along a feature curve that ends
/// inside the surface are one loop, each position on it twice).
fn own_corners(mesh: &TriMesh, vertices: &[u32]) -> Vec<u32> {
    let key = |v: u32| mesh.position(v).map(f64::to_bits);
    let mut count: HashMap<[u64; 3], usize> = HashMap::with_capacity(vertices.len());
    for &v in vertices {
        *count.entry(key(v)).or_default() += 1;
    }
    vertices.iter().copied().filter(|&v| count[&key(v)] == 1).collect()
}

/// How close corner `v`'s rounding was to going the other way, in the
/// direction of `step`: `step (t_v - k_v)` quarter turns.
fn closeness(v: u32, step: i32, turning: &[f64], k: &[i32]) -> f64 {
    step as f64 * (turning[v as usize] - k[v as usize] as f64)
}

/// The `corners` that may move by `step` (none above 1), sorted by
/// [`closest_first`].
fn closest_order(mesh: &TriMesh, corners: &[u32], step: i32, turning: &[f64], k: &[i32]) -> Vec<Corner> {
    let mut order: Vec<Corner> = corners
        .iter()
        .filter(|&&v| step < 0 || k[v as usize] < 1)
        .map(|&v| (closeness(v, step, turning, k), mesh.position(v), v))
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
fn spread_ties(mesh: &TriMesh, order: &[Corner], count: usize) -> Vec<u32> {
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

/// A boundary corner for [`boundary_turning`]: `(closeness, position, vertex)`.
type Corner = (f64, V3, u32);

/// Order of corners for [`boundary_turning`]: closest to going the other
/// way first, closeness in buckets of 1e-9, ties by position
/// ([`lexicographic`]). (A tolerance comparison is not a total order, and
/// the sort panicked on it: a jittered bff-face x4.)
fn closest_first(a: &Corner, b: &Corner) -> std::cmp::Ordering {
    let bucket = |x: f64| (x * 1e9).round();
    bucket(b.0).total_cmp(&bucket(a.0)).then(lexicographic(&a.1, &b.1))
}

/// Positions by x, then y, then z: how exact ties between corners are
/// broken. It does not depend on the numbering (a part's corners are the
/// same whatever else its file holds, and in whatever order), and alike
/// loops in parallel planes start at matching points (the two caps of a
/// cylinder get their corners at the same angles, so its side maps without
/// a twist).
fn lexicographic(a: &V3, b: &V3) -> std::cmp::Ordering {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])).then(a[2].total_cmp(&b[2]))
}

/// Difference (quarter turns) between what a component's interior must
/// carry after independent corner rounding and its own curvature from which
/// [`boundary_turning`] rounds the corners as a whole.
pub const MAX_ROUNDING_DRIFT: i64 = 2;

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

    /// The corners a round hole's drift puts on its rim are chosen by
    /// position, not numbering: the same mesh with its faces in reverse
    /// order (so every vertex renumbered) gets corners at the same points.
    /// (By vertex id the ties fell elsewhere, and a part's cones changed
    /// with what came before it in its file.)
    #[test]
    fn corners_do_not_depend_on_the_numbering() {
        use crate::mesh::{RawMesh, TriMesh};
        let mesh = square_with_round_hole(12, 4, 0.4);
        let reversed = RawMesh { positions: mesh.positions().to_vec(), triangles: mesh.faces().iter().rev().copied().collect() };
        let renumbered = TriMesh::from_raw(&reversed).unwrap();
        assert_ne!(renumbered.positions(), mesh.positions(), "the vertices are renumbered");
        let corners = |m: &TriMesh| {
            let k = boundary_turning(m);
            let mut at: Vec<([u64; 3], i32)> = (0..m.n_vertices()).filter(|&v| k[v] != 0).map(|v| (m.position(v as u32).map(f64::to_bits), k[v])).collect();
            at.sort_unstable();
            at
        };
        let before = corners(&mesh);
        assert_eq!(before.len(), 8, "four corners on the square, four on the hole");
        assert_eq!(corners(&renumbered), before);
    }

    /// A double cone with three quarters of its rim marked and a meridian
    /// from its upper apex down to its third ring: two feature curves that
    /// end inside the surface, each cut into one loop up one side and back
    /// down the other. The rim's two sides turn alike, together the Gaussian
    /// curvature along the crease (5.6 quarter turns), which is no turning
    /// of a curve around a region, so it gives the rim loop no share of the
    /// drift correction: the corner closest to rounding the other way goes
    /// first, the meridian's tip at the apex (turning -1.71: a cone of 90°
    /// there), not one of the rim's vertices that turn 0.08. (Given back by
    /// loop, a 114 k bunny's crease took two 90° corners where it bends 26°,
    /// not a tip at 0.34: seamless distortion 0.10 -> 0.14.)
    #[test]
    fn an_open_crease_takes_no_share_for_the_curvature_along_it() {
        use crate::features::{cut_open, FeatureSet};
        use crate::mesh::{RawMesh, TriMesh};
        use std::f64::consts::PI;
        let (n, rings, height) = (48, 6, 0.4);
        // Ring 0 is the rim (z = 0); ring j of each side at radius 1 - j / rings, then the apex.
        let at = |j: usize, i: usize, side: f64| {
            let (r, a) = (1.0 - j as f64 / rings as f64, 2.0 * PI * i as f64 / n as f64);
            [r * a.cos(), r * a.sin(), side * height * j as f64 / rings as f64]
        };
        let mut raw = RawMesh { positions: (0..n).map(|i| at(0, i, 1.0)).collect(), triangles: Vec::new() };
        for side in [1.0, -1.0] {
            let mut previous: Vec<u32> = (0..n as u32).collect();
            for j in 1..=rings {
                let ids: Vec<u32> = if j < rings {
                    raw.positions.extend((0..n).map(|i| at(j, i, side)));
                    (raw.positions.len() - n..raw.positions.len()).map(|v| v as u32).collect()
                } else {
                    raw.positions.push(at(rings, 0, side));
                    vec![raw.positions.len() as u32 - 1; n]
                };
                for i in 0..n {
                    let (a, b, c, d) = (previous[i], previous[(i + 1) % n], ids[(i + 1) % n], ids[i]);
                    let mut pair = [[a, b, c], [a, c, d]];
                    if side < 0.0 {
                        pair = pair.map(|[x, y, z]| [x, z, y]);
                    }
                    raw.triangles.extend(pair.into_iter().filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]));
                }
                previous = ids;
            }
        }
        let mesh = TriMesh::from_raw(&raw).unwrap();
        let mut features: Vec<[[f64; 3]; 2]> = (0..3 * n / 4).map(|i| [at(0, i, 1.0), at(0, i + 1, 1.0)]).collect();
        features.extend((3..rings).map(|j| [at(j, n / 8, 1.0), at(j + 1, n / 8, 1.0)]));
        let cut = cut_open(&mesh, &FeatureSet::from_positions(&mesh, &features).unwrap());
        let k = boundary_turning(&cut.mesh);
        let apex = (0..cut.mesh.n_vertices()).find(|&v| cut.mesh.position(v as u32) == at(rings, 0, 1.0)).unwrap();
        assert_eq!(k[apex], -1, "the meridian's tip at the apex");
    }

    /// Corners whose closeness differs by less than the old 1e-9 tolerance in
    /// a chain (a ~ b, b ~ c, a !~ c) are still ordered consistently:
    /// transitive, antisymmetric, and a sort of them does not panic.
    #[test]
    fn corner_order_is_a_total_order() {
        let values: Vec<super::Corner> = (0..200u32).map(|i| (0.3 + i as f64 * 0.6e-9, [((i * 7919) % 97) as f64, 0.0, 0.0], i)).collect();
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
