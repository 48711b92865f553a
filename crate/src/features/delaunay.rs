//! Delaunay flips of coplanar edges: the long, thin triangles of a low-poly
//! mesh (a CAD kernel's strips and fans over flat faces) replaced by well
//! shaped ones without moving the surface. Only edges whose two triangles
//! lie in one plane are flipped, never a feature or boundary edge, so the
//! surface, its features and its boundary stay exactly as they were.

use super::refine::{refined_from, RefineCounts, Refined};
use super::FeatureSet;
use crate::mesh::TriMesh;
use crate::vec3::{angle, cross, dot, norm, point_triangle_distance, sub, V3};
use std::collections::HashMap;

/// Two triangles are coplanar when each one's far corner lies within this
/// fraction of the bounding-box diagonal of the other's plane: float32
/// coordinates (glTF) are rounded at about 6e-8 of their magnitude.
const COPLANAR: f64 = 1e-7;

/// Flips per edge of the mesh before giving up (Lawson's algorithm ends far
/// sooner on a plane; this only bounds a cycle caused by rounding).
const MAX_FLIPS_PER_EDGE: usize = 8;

/// Flips, on the refinement `current` of `mesh` (`None`: the input itself),
/// every interior edge that is neither a feature nor shared by two faces
/// that are not coplanar, where the two angles opposite it sum to more than
/// π, until none is left (Lawson's algorithm: on each plane the result is
/// its Delaunay triangulation). Returns `current` when nothing was flipped.
pub(super) fn flip_coplanar(mesh: &TriMesh, features: &FeatureSet, current: Option<Refined>) -> Option<Refined> {
    let (m, f) = current.as_ref().map_or((mesh, features), |r| (&r.mesh, &r.features));
    let mut faces = m.faces().to_vec();
    let positions = m.positions();
    let tolerance = COPLANAR * m.bounding_diagonal();
    // Unordered vertex pair -> the (one or two) faces on it.
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(m.n_edges());
    for (i, t) in faces.iter().enumerate() {
        for k in 0..3 {
            edge_faces.entry(key(t[k], t[(k + 1) % 3])).or_default().push(i as u32);
        }
    }
    let fixed: std::collections::HashSet<(u32, u32)> = f
        .edges()
        .map(|e| {
            let [a, b] = m.edge_vertices(e);
            key(a, b)
        })
        .collect();
    let mut stack: Vec<(u32, u32)> = edge_faces.keys().copied().collect();
    stack.sort_unstable();
    let mut flips = 0;
    let max_flips = MAX_FLIPS_PER_EDGE * m.n_edges();
    while let Some((a, b)) = stack.pop() {
        if flips >= max_flips {
            break;
        }
        let Some(pair) = edge_faces.get(&(a, b)).filter(|p| p.len() == 2) else {
            continue;
        };
        let (f1, f2) = (pair[0] as usize, pair[1] as usize);
        if fixed.contains(&(a, b)) {
            continue;
        }
        // Orient: f1 = (a, b, c) runs a -> b, f2 = (b, a, d).
        let (a, b) = if runs(&faces[f1], a, b) { (a, b) } else { (b, a) };
        let (c, d) = (third(&faces[f1], a, b), third(&faces[f2], b, a));
        if edge_faces.contains_key(&key(c, d)) {
            continue;
        }
        let p = |v: u32| positions[v as usize];
        let n1 = cross(sub(p(b), p(a)), sub(p(c), p(a)));
        let n2 = cross(sub(p(a), p(b)), sub(p(d), p(b)));
        let (l1, l2) = (norm(n1), norm(n2));
        if l1 == 0.0 || l2 == 0.0 || dot(n1, n2) <= 0.0 {
            continue;
        }
        let height = |n: V3, l: f64, o: u32, x: u32| (dot(sub(p(x), p(o)), n) / l).abs();
        if height(n1, l1, a, d) > tolerance || height(n2, l2, b, c) > tolerance {
            continue;
        }
        if angle(sub(p(a), p(c)), sub(p(b), p(c))) + angle(sub(p(b), p(d)), sub(p(a), p(d))) <= std::f64::consts::PI + 1e-12 {
            continue;
        }
        // The new faces (a, d, c) and (d, b, c) must keep the orientation.
        let n = crate::vec3::add(n1, n2);
        if dot(cross(sub(p(d), p(a)), sub(p(c), p(a))), n) <= 0.0 || dot(cross(sub(p(b), p(d)), sub(p(c), p(d))), n) <= 0.0 {
            continue;
        }
        faces[f1] = [a, d, c];
        faces[f2] = [d, b, c];
        edge_faces.remove(&key(a, b));
        edge_faces.insert(key(c, d), vec![f1 as u32, f2 as u32]);
        replace(&mut edge_faces, key(a, d), f2 as u32, f1 as u32);
        replace(&mut edge_faces, key(b, c), f1 as u32, f2 as u32);
        stack.extend([key(a, d), key(d, b), key(b, c), key(c, a)]);
        flips += 1;
    }
    if flips == 0 {
        return current;
    }
    Some(rebuild(m, f, current.as_ref(), faces, flips))
}

/// True when triangle `t` has the directed edge `a -> b`.
fn runs(t: &[u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
}

/// The corner of `t` other than `a` and `b`.
fn third(t: &[u32; 3], a: u32, b: u32) -> u32 {
    t.iter().copied().find(|&v| v != a && v != b).expect("a triangle has three corners")
}

/// Face `from` on edge `e` becomes face `to`.
fn replace(edge_faces: &mut HashMap<(u32, u32), Vec<u32>>, e: (u32, u32), from: u32, to: u32) {
    if let Some(fs) = edge_faces.get_mut(&e) {
        for g in fs.iter_mut().filter(|g| **g == from) {
            *g = to;
        }
    }
}

/// The refinement of the input given by `m` (its refinement `current`, if
/// any, with features `f`) with its faces replaced by `faces` (the same
/// vertices, `flips` edges flipped). A flipped face lies in the face of `m`
/// that holds its centroid; a flipped edge is inside the input's faces.
fn rebuild(m: &TriMesh, f: &FeatureSet, current: Option<&Refined>, faces: Vec<[u32; 3]>, flips: usize) -> Refined {
    let tolerance = LOCATE_TOLERANCE * m.bounding_diagonal();
    let parent: Vec<u32> = faces
        .iter()
        .enumerate()
        .map(|(g, t)| {
            if *t == m.faces()[g] {
                g as u32
            } else {
                let centroid = [0, 1, 2].map(|i| t.iter().map(|&v| m.position(v)[i]).sum::<f64>() / 3.0);
                locate(m, t[0], centroid, tolerance)
            }
        })
        .collect();
    let added = RefineCounts { coplanar_flips: flips, ..RefineCounts::default() };
    refined_from(m, f, current, m.positions().to_vec(), faces, &parent, &[], &added)
}

/// A point is in a face when within this fraction of the bounding-box
/// diagonal of it ([`locate`]).
const LOCATE_TOLERANCE: f64 = 1e-9;

/// Faces [`locate`] visits before it settles for the nearest one seen.
const MAX_LOCATE_FACES: usize = 4096;

/// The face of `m` that holds `p`, a point of `m`'s surface near vertex
/// `start`: faces are visited breadth first from those around `start` until
/// one is within `tolerance` of `p`, else the nearest of those visited.
fn locate(m: &TriMesh, start: u32, p: V3, tolerance: f64) -> u32 {
    let mut seen: std::collections::HashSet<u32> = m.vertex_faces(start).collect();
    let mut queue: std::collections::VecDeque<u32> = seen.iter().copied().collect();
    let mut nearest = (f64::INFINITY, queue[0]);
    while let Some(g) = queue.pop_front() {
        let d = distance_to_face(m, g, p);
        if d <= tolerance {
            return g;
        }
        if d < nearest.0 {
            nearest = (d, g);
        }
        if seen.len() < MAX_LOCATE_FACES {
            for h in m.face_halfedges(g) {
                if let Some(n) = m.face(m.twin(h)) {
                    if seen.insert(n) {
                        queue.push_back(n);
                    }
                }
            }
        }
    }
    nearest.1
}

/// Distance from `p` to face `face` of `m`.
fn distance_to_face(m: &TriMesh, face: u32, p: V3) -> f64 {
    point_triangle_distance(p, &m.faces()[face as usize].map(|v| m.position(v)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::NONE;

    fn min_angle(m: &TriMesh) -> f64 {
        m.corner_angles().iter().flatten().copied().fold(f64::INFINITY, f64::min)
    }

    /// A fan over `n` points of a flat 5 x 1 ellipse: slivers from vertex 0.
    fn ellipse_fan(n: u32) -> TriMesh {
        use std::f64::consts::PI;
        let positions = (0..n).map(|i| {
            let a = 2.0 * PI * i as f64 / n as f64;
            [5.0 * a.cos(), a.sin(), 0.0]
        });
        TriMesh::from_welded_arrays(positions.collect(), (1..n - 1).map(|i| [0, i, i + 1]).collect()).unwrap()
    }

    /// A fan of slivers is flipped into a Delaunay triangulation of the same
    /// polygon: same vertices, area, boundary and features (a feature
    /// diagonal stays), every face in its input face's plane, and nothing
    /// left to flip.
    #[test]
    fn a_fan_of_slivers_becomes_delaunay_and_the_surface_stays() {
        let m = ellipse_fan(24);
        let mut f = FeatureSet::none(&m);
        let diagonal = m.outgoing(0).find(|&h| m.head(h) == 12).map(|h| m.edge(h)).unwrap();
        f.set(&m, diagonal, true);
        let r = flip_coplanar(&m, &f, None).expect("the fan is not Delaunay");
        assert!(r.counts.coplanar_flips > 0);
        assert_eq!((r.mesh.n_vertices(), r.mesh.n_faces(), r.splits), (m.n_vertices(), m.n_faces(), 0));
        let area = |m: &TriMesh| m.face_areas().iter().sum::<f64>();
        assert!((area(&r.mesh) - area(&m)).abs() < 1e-12 * area(&m));
        for v in 0..r.mesh.n_vertices() as u32 {
            assert_eq!(r.mesh.position(v), m.position(r.original_vertex[v as usize]));
        }
        assert_eq!(r.features.len(), 1);
        let kept = r.features.edges().next().unwrap();
        assert_eq!(r.original_edge[kept as usize], diagonal);
        assert!(min_angle(&r.mesh) > 2.0 * min_angle(&m), "{} -> {}", min_angle(&m), min_angle(&r.mesh));
        // Each face overlaps its input face (its centroid lies in it).
        for (g, t) in r.mesh.faces().iter().enumerate() {
            let c = [0, 1, 2].map(|i| t.iter().map(|&v| r.mesh.position(v)[i]).sum::<f64>() / 3.0);
            assert!(distance_to_face(&m, r.original_face[g], c) < 1e-12, "face {g}");
        }
        assert!(flip_coplanar(&r.mesh, &r.features, None).is_none());
    }

    /// Two triangles folded along their shared edge are not flipped, however thin.
    #[test]
    fn a_fold_is_not_flipped() {
        let pair = |z: f64| {
            let positions = vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [5.0, 0.1, 0.0], [5.0, -0.1, z]];
            TriMesh::from_welded_arrays(positions, vec![[0, 1, 2], [1, 0, 3]]).unwrap()
        };
        let folded = pair(1e-3);
        assert!(flip_coplanar(&folded, &FeatureSet::none(&folded), None).is_none());
        let flat = pair(0.0);
        let r = flip_coplanar(&flat, &FeatureSet::none(&flat), None).expect("a flat sliver pair flips");
        assert_eq!(r.counts.coplanar_flips, 1);
        assert_eq!(r.original_edge.iter().filter(|&&e| e == NONE).count(), 1);
    }
}
