//! Topology and validation tests on small hand-made meshes.

use super::*;
use crate::Problem;

fn raw(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> RawMesh {
    RawMesh { positions: positions.to_vec(), triangles: triangles.to_vec() }
}

fn tetrahedron() -> RawMesh {
    raw(
        &[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        &[[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
    )
}

fn square() -> RawMesh {
    raw(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2], [0, 2, 3]])
}

/// An n × m grid on a torus of radii 2 and 1.
fn torus(n: u32, m: u32) -> RawMesh {
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (i as f64 / n as f64 * std::f64::consts::TAU, j as f64 / m as f64 * std::f64::consts::TAU);
            positions.push([(2.0 + v.cos()) * u.cos(), (2.0 + v.cos()) * u.sin(), v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    RawMesh { positions, triangles }
}

/// Checks every halfedge invariant of a built mesh.
fn check_invariants(m: &TriMesh) {
    let nh = m.n_halfedges() as u32;
    assert_eq!(m.n_halfedges(), 3 * m.n_faces() + m.n_boundary_halfedges());
    for h in 0..nh {
        assert_eq!(m.twin(m.twin(h)), h);
        assert_ne!(m.twin(h), h);
        assert_eq!(m.next(m.prev(h)), h);
        assert_eq!(m.prev(m.next(h)), h);
        assert_eq!(m.tail(m.next(h)), m.head(h));
        assert_eq!(m.head(h), m.tail(m.twin(h)));
        assert_eq!(m.edge(h), m.edge(m.twin(h)));
        assert_eq!(m.face(h).is_none(), m.is_boundary_halfedge(h));
        assert!(!(m.is_boundary_halfedge(h) && m.is_boundary_halfedge(m.twin(h))));
        if let Some(f) = m.face(h) {
            assert_eq!(m.faces()[f as usize][(h % 3) as usize], m.tail(h));
        }
    }
    for e in 0..m.n_edges() as u32 {
        let [h, t] = m.edge_halfedges(e);
        assert_eq!(m.edge(h), e);
        assert!(m.face(h).is_some());
        assert_eq!(m.twin(h), t);
        assert_eq!(m.edge_vertices(e), [m.tail(h), m.head(h)]);
        assert_eq!(m.is_boundary_edge(e), m.face(t).is_none());
    }
    let mut degree_sum = 0;
    for v in 0..m.n_vertices() as u32 {
        let out: Vec<u32> = m.outgoing(v).collect();
        assert!(out.iter().all(|&h| m.tail(h) == v));
        let boundary: Vec<u32> = out.iter().copied().filter(|&h| m.is_boundary_halfedge(h)).collect();
        if m.is_boundary_vertex(v) {
            assert_eq!(boundary, vec![*out.last().unwrap()], "boundary halfedge closes the fan");
            assert!(m.is_boundary_edge(m.edge(out[0])));
        } else {
            assert!(boundary.is_empty());
        }
        degree_sum += out.len();
    }
    assert_eq!(degree_sum, 2 * m.n_edges());
    let mut in_loops = 0;
    for (i, lp) in m.boundary_loops().iter().enumerate() {
        for (k, &h) in lp.iter().enumerate() {
            assert!(m.is_boundary_halfedge(h));
            assert_eq!(m.next(h), lp[(k + 1) % lp.len()]);
        }
        assert_eq!(m.boundary_loop_vertices(i).len(), lp.len());
        in_loops += lp.len();
    }
    assert_eq!(in_loops, m.n_boundary_halfedges());
    let loops: usize = (0..m.n_components()).map(|c| m.component_boundary_loops(c)).sum();
    assert_eq!(loops, m.boundary_loops().len());
    assert_eq!(m.euler_characteristic(), m.n_vertices() as i64 - m.n_edges() as i64 + m.n_faces() as i64);
}

#[test]
fn tetrahedron_is_a_sphere() {
    let r = analyze(&tetrahedron());
    assert_eq!((r.vertices, r.faces, r.edges, r.boundary_edges, r.boundary_loops), (4, 4, 6, 0, 0));
    assert_eq!((r.components, r.euler_characteristic, r.genus.clone()), (1, 2, vec![0]));
    assert!(r.problems.is_empty());
    let m = TriMesh::from_raw(&tetrahedron()).unwrap();
    check_invariants(&m);
    assert_eq!((m.n_vertices(), m.n_faces(), m.n_edges(), m.n_halfedges()), (4, 4, 6, 12));
    assert_eq!(m.genus(0), 0);
    let ring: Vec<u32> = m.one_ring(0).collect();
    assert_eq!(ring.len(), 3);
    assert!(m.boundary_loops().is_empty());
}

#[test]
fn square_has_one_boundary_loop() {
    let m = TriMesh::from_raw(&square()).unwrap();
    check_invariants(&m);
    assert_eq!((m.n_edges(), m.n_halfedges(), m.boundary_loops().len()), (5, 10, 1));
    assert_eq!(m.boundary_loops()[0].len(), 4);
    // The hole is on the left of boundary halfedges: the loop runs clockwise.
    let mut lv = m.boundary_loop_vertices(0);
    let start = lv.iter().position(|&v| v == 0).unwrap();
    lv.rotate_left(start);
    assert_eq!(lv, vec![0, 3, 2, 1]);
    assert!((0..4).all(|v| m.is_boundary_vertex(v)));
    // Fan of vertex 0 starts at the boundary neighbour 1, ends at 3.
    assert_eq!(m.one_ring(0).collect::<Vec<_>>(), vec![1, 2, 3]);
    assert_eq!(m.vertex_faces(0).collect::<Vec<_>>(), vec![0, 1]);
    assert_eq!((m.euler_characteristic(), m.genus(0), m.component_boundary_loops(0)), (1, 0, 1));
}

#[test]
fn torus_grid_has_genus_one() {
    let t = torus(6, 4);
    let r = analyze(&t);
    assert_eq!((r.vertices, r.faces, r.edges, r.boundary_edges), (24, 48, 72, 0));
    assert_eq!((r.euler_characteristic, r.genus.clone()), (0, vec![1]));
    assert!(r.problems.is_empty(), "{:?}", r.problems);
    let m = TriMesh::from_raw(&t).unwrap();
    check_invariants(&m);
    assert!((0..24).all(|v| m.valence(v) == 6));
    assert_eq!(m.genus(0), 1);
}

#[test]
fn bow_tie_vertex() {
    let b = raw(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]],
        &[[0, 1, 2], [0, 3, 4]],
    );
    let r = analyze(&b);
    assert_eq!(r.problems, vec![Problem::NonManifoldVertex { vertex: 0, fans: 2 }]);
    assert_eq!((r.components, r.boundary_loops, r.euler_characteristic), (2, 2, 1));
    assert_eq!(r.euler_characteristic_per_component, vec![1, 1]);
    assert_eq!(r.component_is_manifold, vec![false, false]);
    // Building repairs it: one vertex per fan, the report still names the pinch.
    let m = TriMesh::from_raw(&b).expect("a pinch is split, not refused");
    check_invariants(&m);
    assert_eq!((m.n_vertices(), m.euler_characteristic()), (6, 2));
    assert_eq!(m.position(0), m.position(5));
    assert_eq!(m.report().problems, vec![Problem::NonManifoldVertex { vertex: 0, fans: 2 }]);
}

#[test]
fn three_faces_on_an_edge() {
    let t = raw(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0]],
        &[[0, 1, 2], [1, 0, 3], [1, 0, 4]],
    );
    let r = analyze(&t);
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.problems, vec![Problem::NonManifoldEdge { edge: [0, 1], faces: vec![0, 1, 2] }]);
    assert_eq!(TriMesh::from_raw(&t).unwrap_err(), r.problems);
}

#[test]
fn flipped_face() {
    let mut t = tetrahedron();
    t.triangles[3] = [1, 2, 3];
    let r = analyze(&t);
    assert_eq!(r.euler_characteristic, 2);
    assert_eq!(
        r.problems,
        vec![
            Problem::InconsistentOrientation { edge: [1, 2], faces: [0, 3] },
            Problem::InconsistentOrientation { edge: [3, 1], faces: [2, 3] },
            Problem::InconsistentOrientation { edge: [2, 3], faces: [1, 3] },
        ]
    );
}

#[test]
fn duplicate_degenerate_zero_area_zero_length() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let r = analyze(&raw(&p, &[[0, 1, 2], [2, 1, 0], [0, 0, 2], [0, 1, 3], [0, 4, 1]]));
    assert!(r.problems.contains(&Problem::DuplicateFace { faces: [0, 1] }), "{:?}", r.problems);
    assert!(r.problems.contains(&Problem::DegenerateFace { face: 2, vertices: [0, 0, 2] }));
    assert!(r.problems.contains(&Problem::ZeroAreaFace { face: 3, area: 0.0 }));
    assert!(r.problems.contains(&Problem::ZeroLengthEdge { edge: [4, 1], face: 4 }));
}

#[test]
fn zero_area_is_relative() {
    // A thin but valid sliver far from the origin is not zero-area.
    let p = [[1e6, 0.0, 0.0], [1e6 + 1.0, 0.0, 0.0], [1e6 + 0.5, 1e-6, 0.0]];
    assert!(analyze(&raw(&p, &[[0, 1, 2]])).problems.is_empty());
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-14, 0.0]];
    assert!(matches!(analyze(&raw(&p, &[[0, 1, 2]])).problems[..], [Problem::ZeroAreaFace { face: 0, .. }]));
}

#[test]
fn bad_indices_and_coordinates_do_not_panic() {
    let r = analyze(&RawMesh::default());
    assert_eq!((r.vertices, r.faces, r.components, r.euler_characteristic), (0, 0, 0, 0));
    assert!(TriMesh::from_raw(&RawMesh::default()).is_ok());
    let p = [[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [0.0, f64::INFINITY, 0.0], [5.0, 5.0, 5.0]];
    let r = analyze(&raw(&p, &[[0, 1, 2], [0, 2, 7], [u32::MAX, 0, 1]]));
    assert_eq!(
        r.problems,
        vec![
            Problem::IndexOutOfRange { face: 1, index: 7, vertex_count: 4 },
            Problem::IndexOutOfRange { face: 2, index: u32::MAX, vertex_count: 4 },
            Problem::NonFiniteCoordinate { vertex: 1 },
            Problem::NonFiniteCoordinate { vertex: 2 },
            Problem::UnreferencedVertex { vertex: 3 },
        ]
    );
    assert_eq!((r.faces, r.vertices, r.edges, r.euler_characteristic), (3, 3, 3, 1));
}

#[test]
fn unreferenced_vertices_are_dropped() {
    let mut s = square();
    s.positions.insert(0, [7.0, 7.0, 7.0]);
    for t in &mut s.triangles {
        for i in t.iter_mut() {
            *i += 1;
        }
    }
    let m = TriMesh::from_raw(&s).unwrap();
    assert_eq!(m.n_vertices(), 4);
    assert_eq!(m.source_to_welded(), &[NONE, 0, 1, 2, 3]);
    assert_eq!(m.welded_to_source(), &[1, 2, 3, 4]);
    assert_eq!(m.report().problems, vec![Problem::UnreferencedVertex { vertex: 0 }]);
}

#[test]
fn seams_are_welded_but_not_by_index() {
    // A square whose diagonal vertices are duplicated (a UV seam).
    let s = raw(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2], [3, 4, 5]],
    );
    let r = analyze(&s);
    assert_eq!((r.vertices, r.edges, r.boundary_edges, r.components, r.merged_vertices), (4, 5, 4, 1, 2));
    let r = analyze_by_index(&s);
    assert_eq!((r.vertices, r.edges, r.boundary_edges, r.components), (6, 6, 6, 2));
    assert!(TriMesh::from_welded_arrays(s.positions.clone(), s.triangles.clone()).unwrap().n_components() == 2);
}

#[test]
fn subdivided_torus_keeps_topology() {
    let t = subdivide_midpoint(&subdivide_midpoint(&torus(5, 3)));
    let m = TriMesh::from_raw(&t).unwrap();
    check_invariants(&m);
    assert_eq!((m.n_faces(), m.euler_characteristic(), m.genus(0)), (30 * 16, 0, 1));
}

/// Random soups: analysis never panics, and whatever builds is consistent.
#[test]
fn random_soups() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move |n: u32| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n as u64) as u32
    };
    let mut built = 0;
    for round in 0..400 {
        let nv = 3 + rnd(8);
        let positions: Vec<[f64; 3]> =
            (0..nv).map(|_| [rnd(3) as f64, rnd(3) as f64, if round % 2 == 0 { 0.0 } else { rnd(2) as f64 }]).collect();
        let nf = rnd(8);
        let triangles: Vec<[u32; 3]> = (0..nf).map(|_| [rnd(nv + 1), rnd(nv), rnd(nv)]).collect();
        let r = RawMesh { positions, triangles };
        let rep = analyze(&r);
        let _ = analyze_by_index(&r);
        let _ = subdivide_midpoint(&r);
        if let Ok(m) = TriMesh::from_raw(&r) {
            check_invariants(&m);
            // Every extra fan of a pinch vertex became a vertex of its own.
            let extra: i64 = rep
                .problems
                .iter()
                .map(|p| if let Problem::NonManifoldVertex { fans, .. } = p { *fans as i64 - 1 } else { 0 })
                .sum();
            assert_eq!(m.euler_characteristic(), rep.euler_characteristic + extra);
            built += 1;
        }
    }
    assert!(built > 10, "only {built} random meshes were clean");
}
