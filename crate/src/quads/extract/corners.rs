//! Step 7 of extraction: quad vertices moved onto the corners of the
//! input's feature and boundary polylines. A curved feature of a mesh (a
//! cylinder's rim) is a polygon; the quad edges along it run between
//! integer points on its segments, so a quad edge that spans a corner of the
//! polygon cuts it, off the input's sharp edge by the corner's sagitta. Where
//! that matters, the quad vertex on the curve nearest to the corner is slid
//! along the curve onto it (quads stay on the surface and the curve stays a
//! chain of quad edges; no quad may flip).

use super::QuadMesh;
use crate::features::FeatureSet;
use crate::mesh::TriMesh;
use crate::quads::check::newell_normal;
use crate::quads::SurfacePoint;
use crate::vec3::{angle, cross, dot, norm, point_segment_distance, segment_parameter, sub, V3};

/// Corners closer than this (a fraction of the bounding-box diagonal) to the
/// quad edge that spans them are left alone: a quarter of the 0.2 % within
/// which a sharp edge counts as followed. Each slide skews its quads a
/// little (alligator's boundary at 3 000 quads: mean angle deviation 3.66°
/// without slides, 4.23° sliding above 1e-4, 3.80° above 5e-4).
const MIN_DEVIATION: f64 = 5e-4;

/// Corners where the polyline turns by less than this (radians, 10°) are
/// left alone: a finely tessellated curve's quad edges follow it closely,
/// and sliding their vertices would only skew the quads (fandisk at 3 000
/// quads with every corner: mean angle deviation 5.0° -> 6.0°).
const MIN_TURNING: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// Curve edges walked from a corner to the far neighbour of the vertex that
/// would slide onto it.
const MAX_WALK: usize = 64;

/// Where a quad vertex lies on the input's curves.
#[derive(Clone, Copy, Debug, PartialEq)]
enum OnCurve {
    Edge(u32),
    Vertex(u32),
}

/// A quad vertex inside a curve edge of the input.
#[derive(Clone, Copy, Debug)]
struct OnEdge {
    vertex: u32,
    /// Arc length from the edge's first end (`edge_vertices(e)[0]`).
    t: f64,
}

/// Moves quad vertices onto the corners of the feature (`features`) and
/// boundary polylines of `mesh` that quad edges would otherwise cut (see
/// the module doc); returns how many moved. A quad vertex at an input
/// vertex is never moved; each moves at most once.
pub(super) fn align_curve_corners(mesh: &TriMesh, features: &FeatureSet, quads: &mut QuadMesh) -> usize {
    let curve = |e: u32| mesh.is_boundary_edge(e) || features.contains(e);
    let diagonal = mesh.bounding_diagonal();
    // Quad vertices at input vertices, and inside curve edges.
    let mut at_vertex = vec![false; mesh.n_vertices()];
    let mut on_edge: Vec<Vec<OnEdge>> = vec![Vec::new(); mesh.n_edges()];
    let mut on_curve: Vec<Option<OnCurve>> = vec![None; quads.positions.len()];
    for (v, loc) in quads.locations.iter().enumerate() {
        let face = mesh.faces()[loc.face as usize];
        let zeros: Vec<usize> = (0..3).filter(|&k| loc.bary[k].abs() <= 1e-12).collect();
        match zeros[..] {
            [a, b] => {
                let x = face[3 - a - b];
                at_vertex[x as usize] = true;
                on_curve[v] = Some(OnCurve::Vertex(x));
            }
            [k] => {
                let h = mesh.face_halfedges(loc.face)[(k + 1) % 3];
                let e = mesh.edge(h);
                if curve(e) {
                    let [p, q] = mesh.edge_vertices(e).map(|x| mesh.position(x));
                    let t = segment_parameter(quads.positions[v], p, q) * norm(sub(q, p));
                    on_edge[e as usize].push(OnEdge { vertex: v as u32, t });
                    on_curve[v] = Some(OnCurve::Edge(e));
                }
            }
            _ => {}
        }
    }
    let incident = quads.vertex_quads();
    // Corners of the polylines, sharpest first.
    let mut corners: Vec<(f64, u32, [u32; 2])> = (0..mesh.n_vertices() as u32)
        .filter(|&c| !at_vertex[c as usize])
        .filter_map(|c| {
            let edges: Vec<u32> = mesh.outgoing(c).map(|h| mesh.edge(h)).filter(|&e| curve(e)).collect();
            let [a, b] = edges[..] else { return None };
            let (pa, pb, pc) = (mesh.position(other_end(mesh, a, c)), mesh.position(other_end(mesh, b, c)), mesh.position(c));
            let turning = std::f64::consts::PI - angle(sub(pa, pc), sub(pb, pc));
            (turning >= MIN_TURNING).then_some((turning, c, [a, b]))
        })
        .collect();
    corners.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut moved = vec![false; quads.positions.len()];
    let mut count = 0;
    for (_, c, edges) in corners {
        // Only a quad edge that spans this corner alone: one whose ends lie
        // on the corner's own two edges (where it spans several, sliding one
        // vertex onto one corner leaves the others cut and skews the quads).
        let sides = edges.map(|e| nearest_on_edge(mesh, &on_edge, c, e));
        let [Some((left, dl)), Some((right, dr))] = sides else { continue };
        let target = mesh.position(c);
        let deviation = point_segment_distance(target, quads.positions[left as usize], quads.positions[right as usize]);
        if deviation <= MIN_DEVIATION * diagonal {
            continue;
        }
        let (v, partner, e) = if dl <= dr { (left, right, edges[0]) } else { (right, left, edges[1]) };
        if moved[v as usize] || !keeps_quads_valid(quads, &incident[v as usize], v, target) {
            continue;
        }
        // The quad edge from v away from the corner must not cut the curve
        // beyond it worse than the corner was cut.
        let Some(far) = far_neighbour(quads, &incident[v as usize], &on_curve, v, partner) else { continue };
        let Some(between) = polyline_to(mesh, &curve, c, e, on_curve[far as usize]) else { continue };
        let worst = |from: V3| between.iter().map(|&p| point_segment_distance(p, from, quads.positions[far as usize])).fold(0.0, f64::max);
        if worst(target) >= deviation.max(worst(quads.positions[v as usize])) {
            continue;
        }
        quads.positions[v as usize] = target;
        quads.locations[v as usize] = vertex_location(mesh, c, quads.locations[v as usize]);
        on_curve[v as usize] = Some(OnCurve::Vertex(c));
        moved[v as usize] = true;
        count += 1;
    }
    count
}

/// The other end of edge `e` than `v`.
fn other_end(mesh: &TriMesh, e: u32, v: u32) -> u32 {
    let [a, b] = mesh.edge_vertices(e);
    if a == v { b } else { a }
}

/// The quad vertex inside curve edge `e` nearest to its end `c`, and its
/// distance from `c`.
fn nearest_on_edge(mesh: &TriMesh, on_edge: &[Vec<OnEdge>], c: u32, e: u32) -> Option<(u32, f64)> {
    let [a, _] = mesh.edge_vertices(e);
    let length = mesh.edge_length(e);
    on_edge[e as usize]
        .iter()
        .map(|o| (o.vertex, if a == c { o.t } else { length - o.t }))
        .min_by(|x, y| x.1.total_cmp(&y.1))
}

/// The quad vertex joined to `v` by a quad edge that lies on a curve too,
/// other than `partner`; `None` unless there is exactly one.
fn far_neighbour(quads: &QuadMesh, around: &[u32], on_curve: &[Option<OnCurve>], v: u32, partner: u32) -> Option<u32> {
    let mut found: Vec<u32> = around
        .iter()
        .flat_map(|&q| {
            let c = quads.quads[q as usize];
            let i = c.iter().position(|&x| x == v).expect("v is a corner of the quads around it");
            [c[(i + 1) % 4], c[(i + 3) % 4]]
        })
        .filter(|&n| n != partner && on_curve[n as usize].is_some())
        .collect();
    found.sort_unstable();
    found.dedup();
    match found[..] {
        [n] => Some(n),
        _ => None,
    }
}

/// The positions of the curve's vertices passed walking from `c` along
/// edge `first` until `to` (a curve place); `None` when the walk leaves the
/// curve's two-edge vertices or goes on past [`MAX_WALK`] edges.
fn polyline_to(mesh: &TriMesh, curve: &dyn Fn(u32) -> bool, c: u32, first: u32, to: Option<OnCurve>) -> Option<Vec<V3>> {
    let to = to?;
    let (mut from, mut e) = (c, first);
    let mut passed = Vec::new();
    for _ in 0..MAX_WALK {
        if to == OnCurve::Edge(e) {
            return Some(passed);
        }
        let x = other_end(mesh, e, from);
        if to == OnCurve::Vertex(x) {
            return Some(passed);
        }
        passed.push(mesh.position(x));
        let onward: Vec<u32> = mesh.outgoing(x).map(|h| mesh.edge(h)).filter(|&o| o != e && curve(o)).collect();
        let [next] = onward[..] else { return None };
        (from, e) = (x, next);
    }
    None
}

/// True when moving quad vertex `v` to `to` leaves every quad of `around`
/// turned as it was: each of its four corner triangles keeps a positive
/// side against the quad's normal before the move.
fn keeps_quads_valid(quads: &QuadMesh, around: &[u32], v: u32, to: V3) -> bool {
    around.iter().all(|&q| {
        let corners = quads.quads[q as usize];
        let before = corners.map(|x| quads.positions[x as usize]);
        let after = corners.map(|x| if x == v { to } else { quads.positions[x as usize] });
        let normal = newell_normal(&before);
        (0..4).all(|i| {
            let (p, c, n) = (after[(i + 3) % 4], after[i], after[(i + 1) % 4]);
            dot(cross(sub(n, c), sub(p, c)), normal) > 0.0
        })
    })
}

/// Input vertex `c` as a surface point: in the face of `near` when it has
/// `c` as a corner, else in the face around `c` whose normal is closest to
/// `near`'s face's.
fn vertex_location(mesh: &TriMesh, c: u32, near: SurfacePoint) -> SurfacePoint {
    let normals = mesh.face_normals();
    let face = if mesh.faces()[near.face as usize].contains(&c) {
        near.face
    } else {
        let n = normals[near.face as usize];
        mesh.vertex_faces(c).max_by(|&a, &b| dot(normals[a as usize], n).total_cmp(&dot(normals[b as usize], n))).unwrap_or(near.face)
    };
    let mut bary = [0.0; 3];
    let k = mesh.faces()[face as usize].iter().position(|&x| x == c).expect("the face has c as a corner");
    bary[k] = 1.0;
    SurfacePoint { face, bary }
}
