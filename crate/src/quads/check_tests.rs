//! Tests of [`check_quads`] on hand-built quad meshes.

use super::*;
use crate::quads::{QuadDefect, SurfacePoint};
use std::collections::HashMap;

/// An `n × n` grid of quads, vertex `(i, j)` = `j (n + 1) + i` at
/// `embed(i, j)`, quads counter-clockwise seen from +z for the identity
/// embedding; corner UVs are the grid coordinates.
fn grid_quads(n: u32, embed: impl Fn(u32, u32) -> V3) -> QuadMesh {
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut mesh = QuadMesh::default();
    for j in 0..=n {
        for i in 0..=n {
            mesh.positions.push(embed(i, j));
        }
    }
    for j in 0..n {
        for i in 0..n {
            mesh.quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            let (u, v) = (i as f64, j as f64);
            mesh.uv.extend([[u, v], [u + 1.0, v], [u + 1.0, v + 1.0], [u, v + 1.0]]);
        }
    }
    mesh
}

fn flat(n: u32) -> impl Fn(u32, u32) -> V3 {
    move |i, j| [i as f64 / n as f64, j as f64 / n as f64, 0.0]
}

/// The input surface of `quads`: each quad split into `(0, 1, 2), (0, 2, 3)`;
/// sets `quads.locations` to a corner of the first triangle at each vertex.
fn triangulate(quads: &mut QuadMesh) -> TriMesh {
    let triangles: Vec<[u32; 3]> = quads.quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    let mut locations = vec![None; quads.n_vertices()];
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let mut bary = [0.0; 3];
            bary[k] = 1.0;
            locations[v as usize].get_or_insert(SurfacePoint { face: t as u32, bary });
        }
    }
    quads.locations = locations.into_iter().map(|l| l.expect("every test vertex is on a quad")).collect();
    TriMesh::from_welded_arrays(quads.positions.clone(), triangles).expect("test input is a valid mesh")
}

/// The surface of `[0, 1]³` as `6 n²` quads, counter-clockwise seen from outside.
fn cube_quads(n: u32) -> QuadMesh {
    // (origin, u axis, v axis) per side, u × v pointing out.
    let sides: [([u32; 3], usize, usize); 6] = [
        ([0, 0, 0], 1, 0),
        ([0, 0, n], 0, 1),
        ([0, 0, 0], 0, 2),
        ([0, n, 0], 2, 0),
        ([0, 0, 0], 2, 1),
        ([n, 0, 0], 1, 2),
    ];
    let mut mesh = QuadMesh::default();
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut vertex = |mesh: &mut QuadMesh, origin: [u32; 3], u: usize, v: usize, i: u32, j: u32| {
        let mut c = origin;
        c[u] += i;
        c[v] += j;
        *index.entry(c).or_insert_with(|| {
            mesh.positions.push(c.map(|x| x as f64 / n as f64));
            mesh.positions.len() as u32 - 1
        })
    };
    for (origin, u, v) in sides {
        for j in 0..n {
            for i in 0..n {
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let q = corners.map(|(a, b)| vertex(&mut mesh, origin, u, v, a, b));
                mesh.quads.push(q);
                let (a, b) = (i as f64, j as f64);
                mesh.uv.extend([[a, b], [a + 1.0, b], [a + 1.0, b + 1.0], [a, b + 1.0]]);
            }
        }
    }
    mesh
}

fn check(input: &TriMesh, quads: &QuadMesh) -> QuadReport {
    check_quads(input, quads, &CheckOptions::default())
}

#[test]
fn a_flat_grid_is_a_regular_disk_on_its_input() {
    let n = 4;
    let mut quads = grid_quads(n, flat(n));
    let input = triangulate(&mut quads);
    let r = check(&input, &quads);
    assert_eq!((r.quads, r.vertices, r.edges), (16, 25, 40));
    assert_eq!((r.euler_characteristic, r.boundary_loops, r.components), (1, 1, 1));
    assert_eq!((r.non_manifold_edges, r.non_manifold_vertices), (0, 0));
    assert_eq!((r.degenerate_quads, r.unreferenced_vertices), (0, 0));
    // Only the four corners (valence 2 on the boundary) are singular.
    assert_eq!(r.singular_vertices.len(), 4);
    assert!(r.singular_vertices.iter().all(|s| s.boundary && s.valence == 2));
    assert_eq!(r.valence_histogram.interior, BTreeMap::from([(4, 9)]));
    assert_eq!(r.valence_histogram.boundary, BTreeMap::from([(2, 4), (3, 12)]));
    assert!(r.angle_max_deviation < 1e-12 && r.angle_mean_deviation < 1e-12);
    assert_eq!(r.fraction_corners_45_135, 1.0);
    assert_eq!(r.flipped_quads, 0);
    assert!(r.distance_quads_to_input.is_some_and(|d| d < 1e-12));
    assert!(r.distance_input_to_quads.is_some_and(|d| d < 1e-12));
    assert_eq!(r.defects, 0);
}

#[test]
fn distances_are_skipped_unless_asked_for() {
    let mut quads = grid_quads(2, flat(2));
    let input = triangulate(&mut quads);
    let r = check_quads(&input, &quads, &CheckOptions { distances: false, ..CheckOptions::default() });
    assert_eq!((r.distance_quads_to_input, r.distance_input_to_quads_relative), (None, None));
}

#[test]
fn a_cube_has_eight_valence_three_corners_and_euler_characteristic_two() {
    let n = 3;
    let mut quads = cube_quads(n);
    let input = triangulate(&mut quads);
    let r = check(&input, &quads);
    assert_eq!((r.quads, r.vertices, r.edges), (54, 56, 108));
    assert_eq!((r.euler_characteristic, r.boundary_loops, r.components), (2, 0, 1));
    assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.degenerate_quads), (0, 0, 0));
    assert_eq!(r.singular_vertices.len(), 8);
    assert!(r.singular_vertices.iter().all(|s| !s.boundary && s.valence == 3));
    assert!(r.valence_histogram.boundary.is_empty());
    assert_eq!(r.flipped_quads, 0);
    assert!(r.angle_max_deviation < 1e-9);
    assert!(r.distance_quads_to_input.is_some_and(|d| d < 1e-12));
    assert!(r.distance_input_to_quads.is_some_and(|d| d < 1e-12));
}

#[test]
fn a_reversed_quad_is_flipped_and_breaks_its_four_edges() {
    let n = 3;
    let mut quads = grid_quads(n, flat(n));
    let input = triangulate(&mut quads);
    let [a, b, c, d] = quads.quads[4];
    quads.quads[4] = [a, d, c, b];
    let r = check(&input, &quads);
    assert_eq!(r.flipped_quads, 1);
    assert_eq!(r.non_manifold_edges, 4);
    assert_eq!((r.non_manifold_vertices, r.degenerate_quads), (0, 0));
}

/// A slab whose top slopes up towards its end (`z` from 0 to `0.2 + 0.3 x`):
/// the quad of its end face has its corners on the end's creases, each
/// located in a top or bottom triangle, whose normals add up to point away
/// from the end's. It is not flipped (each corner's admissible normals
/// include the end face's); the same quad reversed is.
#[test]
fn a_quad_with_its_corners_on_creases_is_judged_by_the_faces_around_them() {
    let mut quads = cube_quads(1);
    for p in &mut quads.positions {
        p[2] *= 0.2 + 0.3 * p[0];
    }
    let input = triangulate(&mut quads);
    let end = (0..quads.n_quads()).find(|&q| quads.quads[q].iter().all(|&v| quads.positions[v as usize][0] == 1.0)).unwrap();
    // Each end corner located in a triangle of the top (z > 0) or bottom side.
    for &v in &quads.quads[end] {
        let top = quads.positions[v as usize][2] > 0.0;
        let side = (0..input.n_faces() as u32)
            .find(|&f| {
                let zs = input.faces()[f as usize].map(|c| input.position(c)[2]);
                input.faces()[f as usize].contains(&v) && if top { zs.iter().all(|&z| z > 0.0) } else { zs.iter().all(|&z| z == 0.0) }
            })
            .unwrap();
        let mut bary = [0.0; 3];
        bary[input.faces()[side as usize].iter().position(|&c| c == v).unwrap()] = 1.0;
        quads.locations[v as usize] = SurfacePoint { face: side, bary };
    }
    assert_eq!(check(&input, &quads).flipped_quads, 0);
    let [a, b, c, d] = quads.quads[end];
    quads.quads[end] = [a, d, c, b];
    assert_eq!(check(&input, &quads).flipped_quads, 1);
}

#[test]
fn a_vertex_pushed_off_the_surface_is_measured_both_ways() {
    let (n, d) = (4, 0.01);
    let mut quads = grid_quads(n, flat(n));
    let input = triangulate(&mut quads);
    let centre = 2 * (n + 1) + 2;
    quads.positions[centre as usize][2] = d;
    let r = check(&input, &quads);
    let to_input = r.distance_quads_to_input.unwrap_or(f64::NAN);
    assert!((to_input - d).abs() < 1e-12, "{to_input}");
    // The input vertex under it sees the tent's slanted faces, slightly nearer.
    let to_quads = r.distance_input_to_quads.unwrap_or(f64::NAN);
    assert!(to_quads > 0.9 * d && to_quads <= d + 1e-12, "{to_quads}");
    let relative = r.distance_quads_to_input_relative.unwrap_or(f64::NAN);
    assert!((relative - d / 2f64.sqrt()).abs() < 1e-12);
    assert_eq!(r.flipped_quads, 0);
}

#[test]
fn bow_ties_repeats_and_zero_areas_are_degenerate_but_darts_are_not() {
    let mut quads = grid_quads(1, flat(1));
    let input = triangulate(&mut quads);
    let polygons: [[[f64; 2]; 4]; 5] = [
        [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]], // symmetric bow-tie: zero area
        [[0.0, 0.0], [3.0, 1.0], [3.0, 0.0], [0.0, 2.0]], // bow-tie with area
        [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]], // collinear
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], // square
        [[0.0, 0.0], [2.0, 1.0], [0.0, 2.0], [0.5, 1.0]], // dart (one reflex corner)
    ];
    let mut mesh = QuadMesh::default();
    for p in polygons {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(p.map(|[x, y]| [x, y, 0.0]));
        mesh.quads.push([base, base + 1, base + 2, base + 3]);
    }
    mesh.quads.push([0, 1, 1, 2]); // repeated vertex
    mesh.quads.push([0, 1, 2, 99]); // index out of range
    let r = check(&input, &mesh);
    assert_eq!(r.degenerate_quads, 5);
    assert_eq!(r.quads, 7);
}

#[test]
fn quads_sharing_only_a_vertex_make_it_non_manifold() {
    let mut quads = grid_quads(1, flat(1));
    let input = triangulate(&mut quads);
    let mesh = QuadMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ],
        quads: vec![[0, 1, 2, 3], [2, 4, 5, 6]],
        ..QuadMesh::default()
    };
    let r = check(&input, &mesh);
    assert_eq!((r.non_manifold_vertices, r.non_manifold_edges, r.components), (1, 0, 2));
    assert_eq!(r.euler_characteristic, 1);
}

#[test]
fn three_quads_on_one_edge_make_it_non_manifold() {
    let mut quads = grid_quads(1, flat(1));
    let input = triangulate(&mut quads);
    let mesh = QuadMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ],
        quads: vec![[0, 1, 2, 3], [1, 0, 5, 4], [1, 0, 7, 6]],
        ..QuadMesh::default()
    };
    let r = check(&input, &mesh);
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.non_manifold_vertices, 2);
    assert_eq!(r.components, 1);
}

#[test]
fn unreferenced_vertices_and_defects_are_counted_but_leave_euler_alone() {
    let mut quads = grid_quads(2, flat(2));
    let input = triangulate(&mut quads);
    quads.positions.push([5.0, 5.0, 5.0]);
    quads.defects.push(QuadDefect { face: 0, what: "test".to_string() });
    let r = check(&input, &quads);
    assert_eq!((r.unreferenced_vertices, r.vertices, r.euler_characteristic, r.defects), (1, 10, 1, 1));
}

#[test]
fn sheared_quads_have_the_angles_of_their_shear() {
    // x' = x + y: every corner is 45° or 135°.
    let n = 2;
    let mut quads = grid_quads(n, |i, j| [(i + j) as f64, j as f64, 0.0]);
    let input = triangulate(&mut quads);
    let r = check(&input, &quads);
    assert!((r.angle_mean_deviation - 45.0).abs() < 1e-9 && (r.angle_max_deviation - 45.0).abs() < 1e-9);
    assert_eq!(r.fraction_corners_45_135, 1.0);
    // x' = x + 2 y: corners of 26.6° and 153.4°, out of range.
    let mut steep = grid_quads(n, |i, j| [(i + 2 * j) as f64, j as f64, 0.0]);
    let input = triangulate(&mut steep);
    assert_eq!(check(&input, &steep).fraction_corners_45_135, 0.0);
}

#[test]
fn cube_edges_are_followed_and_face_diagonals_are_not() {
    let n = 3;
    let mut quads = cube_quads(n);
    let input = triangulate(&mut quads);
    // Input edges on two cube sides (both coordinates 0 or 1 in two axes).
    let on_rim = |p: V3| p.iter().filter(|&&x| x == 0.0 || x == 1.0).count() >= 2;
    let (rim, diagonals): (Vec<u32>, Vec<u32>) = (0..input.n_edges() as u32).partition(|&e| {
        let [a, b] = input.edge_vertices(e).map(|v| input.position(v));
        on_rim(a) && on_rim(b) && (0..3).filter(|&i| a[i] == b[i]).count() == 2
    });
    assert_eq!(rim.len(), 12 * n as usize);
    let followed = check_quads(&input, &quads, &CheckOptions { sharp_edges: &rim, ..CheckOptions::default() });
    assert_eq!((followed.sharp_edges_checked, followed.fraction_sharp_within_tolerance), (36, Some(1.0)));
    let diagonals: Vec<u32> = diagonals
        .into_iter()
        .filter(|&e| {
            let [a, b] = input.edge_vertices(e).map(|v| input.position(v));
            (0..3).filter(|&i| a[i] == b[i]).count() == 1
        })
        .chain([u32::MAX])
        .collect();
    let missed = check_quads(&input, &quads, &CheckOptions { sharp_edges: &diagonals, ..CheckOptions::default() });
    assert_eq!(missed.sharp_edges_checked, 54);
    assert_eq!(missed.fraction_sharp_within_tolerance, Some(0.0));
}

#[test]
fn the_report_serialises_with_snake_case_keys() {
    let mut quads = grid_quads(1, flat(1));
    let input = triangulate(&mut quads);
    let json = serde_json::to_value(check(&input, &quads)).unwrap_or_default();
    assert_eq!(json["valence_histogram"]["boundary"]["2"], 4);
    assert_eq!(json["fraction_corners_45_135"], 1.0);
    assert!(json["fraction_sharp_within_tolerance"].is_null());
}

/// Deterministic pseudo-random numbers in [−1, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[test]
fn point_triangle_distance_matches_dense_sampling() {
    let mut s = 7u64;
    for _ in 0..200 {
        let t: [V3; 3] = std::array::from_fn(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)]);
        let p = [2.0 * lcg(&mut s), 2.0 * lcg(&mut s), 2.0 * lcg(&mut s)];
        let m = 100;
        let mut sampled = f64::INFINITY;
        for i in 0..=m {
            for j in 0..=m - i {
                let (u, v) = (i as f64 / m as f64, j as f64 / m as f64);
                let q = add(t[0], add(scale(sub(t[1], t[0]), u), scale(sub(t[2], t[0]), v)));
                sampled = sampled.min(norm(sub(p, q)));
            }
        }
        let exact = point_triangle_distance(p, &t);
        // The sampling is 1/100 of an edge (≤ 0.035) coarse, never below the exact value.
        assert!(exact <= sampled + 1e-12 && sampled - exact < 0.03, "{exact} vs {sampled}");
    }
    // Zero-area triangles are measured as segments.
    let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    assert!((point_triangle_distance([1.0, 1.0, 0.0], &line) - 1.0).abs() < 1e-15);
    let point = [[1.0, 1.0, 1.0]; 3];
    assert!((point_triangle_distance([1.0, 1.0, 3.0], &point) - 2.0).abs() < 1e-15);
}

#[test]
fn the_grid_finds_the_same_nearest_triangle_as_brute_force() {
    let mut s = 11u64;
    let triangles: Vec<[V3; 3]> = (0..300)
        .map(|_| {
            let c = [5.0 * lcg(&mut s), 5.0 * lcg(&mut s), 0.5 * lcg(&mut s)];
            std::array::from_fn(|_| add(c, [0.3 * lcg(&mut s), 0.3 * lcg(&mut s), 0.3 * lcg(&mut s)]))
        })
        .collect();
    let boxes: Vec<(V3, V3)> = triangles.iter().map(|t| bounds(t)).collect();
    let grid = BoxGrid::new(&boxes);
    let mut seen = Visited::new(triangles.len());
    for _ in 0..300 {
        // Points inside and well outside the grid.
        let p = [8.0 * lcg(&mut s), 8.0 * lcg(&mut s), 3.0 * lcg(&mut s)];
        let brute = triangles.iter().map(|t| point_triangle_distance(p, t)).fold(f64::INFINITY, f64::min);
        let found = grid.nearest(p, f64::INFINITY, &mut seen, |i| point_triangle_distance(p, &triangles[i as usize]));
        assert_eq!(found, brute);
    }
}

/// Timing on the brief's size (100k input triangles, 30k quads); run with
/// `cargo test --release -p conemap --lib check_is_fast -- --ignored`.
#[test]
#[ignore]
fn check_is_fast_on_100k_triangles_and_30k_quads() {
    let wave = |x: f64, y: f64| [x, y, 0.05 * (6.0 * x).sin() * (5.0 * y).cos()];
    let fine = 224;
    let mut dense = grid_quads(fine, |i, j| wave(i as f64 / fine as f64, j as f64 / fine as f64));
    let input = triangulate(&mut dense);
    let coarse = 173;
    let mut quads = grid_quads(coarse, |i, j| wave(i as f64 / coarse as f64, j as f64 / coarse as f64));
    quads.locations = vec![SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] }; quads.n_vertices()];
    let boundary: Vec<u32> = (0..input.n_edges() as u32).filter(|&e| input.is_boundary_edge(e)).collect();
    let start = std::time::Instant::now();
    let r = check_quads(&input, &quads, &CheckOptions { sharp_edges: &boundary, ..CheckOptions::default() });
    let seconds = start.elapsed().as_secs_f64();
    assert!(input.n_faces() >= 100_000 && r.quads >= 29_000);
    assert!(r.distance_input_to_quads_relative.is_some_and(|d| d < 1e-3));
    assert!(seconds < 1.0, "{seconds} s");
}
