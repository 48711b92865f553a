//! Tests of [`extract_quads`] on synthetic integer-grid maps: planar squares,
//! cubes (cones, seams with quarter-turn transitions), flat tori, several
//! components, and invalid maps.

use super::{extract_quads, ExtractError, ExtractOptions};
use crate::quads::{QuadDefect, QuadMesh, SurfacePoint};
use crate::TriMesh;
use std::collections::HashMap;

/// Positions, triangles and corner UVs of a test map.
type TestMap = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 2]>);

/// Deterministic pseudo-random numbers in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Two counter-clockwise triangles per grid cell, alternating diagonals;
/// `id(i, j)` numbers the grid vertices.
fn grid_triangles(m: usize, id: impl Fn(usize, usize) -> u32) -> Vec<[u32; 3]> {
    let mut t = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                t.push([a, b, c]);
                t.push([a, c, d]);
            } else {
                t.push([a, b, d]);
                t.push([b, c, d]);
            }
        }
    }
    t
}

/// The square [0, n]² as an m × m grid (interior vertices jittered by up to
/// `jitter` cells, boundary vertices along the boundary), uv = position.
fn square(n: usize, m: usize, jitter: f64, seed: u64) -> TestMap {
    let mut rng = Lcg(seed);
    let h = n as f64 / m as f64;
    let mut pos = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            let (mut dx, mut dy) = ((rng.next() - 0.5) * 2.0 * jitter * h, (rng.next() - 0.5) * 2.0 * jitter * h);
            if i == 0 || i == m {
                dx = 0.0;
            }
            if j == 0 || j == m {
                dy = 0.0;
            }
            pos.push([i as f64 * h + dx, j as f64 * h + dy, 0.0]);
        }
    }
    let tris = grid_triangles(m, |i, j| (j * (m + 1) + i) as u32);
    let uv = tris.iter().flat_map(|t| t.map(|v| [pos[v as usize][0], pos[v as usize][1]])).collect();
    (pos, tris, uv)
}

/// `p` rotated by `r` quarter turns.
fn rot(p: [f64; 2], r: usize) -> [f64; 2] {
    match r % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    }
}

/// The unit cube's surface, each face an m × m grid; the chart of face `f`
/// is its grid coordinates times `s`, rotated by `f` quarter turns and moved
/// by an integer offset (plus `extra_offset` on face 3, to break the map).
/// `jitter`: move interior grid vertices (in 3D and uv alike): unmoved, by
/// half a cell (onto the grid when `s` is even), or randomly.
fn cube(m: usize, s: f64, jitter: bool, extra_offset: f64) -> TestMap {
    let frames: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    let mut rng = Lcg(7);
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut key_to_id: HashMap<[i64; 3], u32> = HashMap::new();
    let (mut tris, mut uv) = (Vec::new(), Vec::new());
    for (f, &(o, u, v)) in frames.iter().enumerate() {
        // Grid coordinates of each vertex of this face (jittered inside).
        let mut coords = vec![[0.0f64; 2]; (m + 1) * (m + 1)];
        let mut ids = vec![0u32; (m + 1) * (m + 1)];
        for j in 0..=m {
            for i in 0..=m {
                let mut c = [i as f64, j as f64];
                if jitter && i > 0 && j > 0 && i < m && j < m {
                    match (rng.next() * 3.0) as usize {
                        0 => {}
                        1 => c[0] += 0.5,
                        _ => {
                            c[0] += (rng.next() - 0.5) * 0.4;
                            c[1] += (rng.next() - 0.5) * 0.4;
                        }
                    }
                }
                let (a, b) = (c[0] / m as f64, c[1] / m as f64);
                let p = [0, 1, 2].map(|k| o[k] + a * u[k] + b * v[k]);
                let key = if i == 0 || j == 0 || i == m || j == m {
                    [0, 1, 2].map(|k| (p[k] * m as f64).round() as i64)
                } else {
                    [f as i64 + 100, i as i64, j as i64]
                };
                let id = *key_to_id.entry(key).or_insert_with(|| {
                    pos.push(p);
                    (pos.len() - 1) as u32
                });
                coords[j * (m + 1) + i] = c;
                ids[j * (m + 1) + i] = id;
            }
        }
        let off = [(f * 7 % 5) as f64 + if f == 3 { extra_offset } else { 0.0 }, (f * 3 % 4) as f64 - 2.0];
        let local = grid_triangles(m, |i, j| (j * (m + 1) + i) as u32);
        for t in local {
            tris.push(t.map(|l| ids[l as usize]));
            for l in t {
                let c = coords[l as usize];
                let r = rot([c[0] * s, c[1] * s], f);
                uv.push([r[0] + off[0], r[1] + off[1]]);
            }
        }
    }
    (pos, tris, uv)
}

/// A torus in 3D as an m × m grid whose map is the flat torus [0, n]²:
/// uv = grid coordinates · n / m, unwrapped per triangle.
fn torus(n: usize, m: usize) -> TestMap {
    let mut pos = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (th, ph) = (std::f64::consts::TAU * i as f64 / m as f64, std::f64::consts::TAU * j as f64 / m as f64);
            let r = 2.0 + ph.cos();
            pos.push([r * th.cos(), r * th.sin(), ph.sin()]);
        }
    }
    let mut tris = Vec::new();
    let mut uv = Vec::new();
    let h = n as f64 / m as f64;
    for j in 0..m {
        for i in 0..m {
            let cell = grid_triangles(1, |a, b| (b * 2 + a) as u32);
            let parity = (i + j) % 2 == 1;
            for t in cell {
                // grid_triangles(1) uses the even diagonal; mirror for odd cells.
                let t = if parity { odd_cell(t) } else { t };
                tris.push(t.map(|l| {
                    let (a, b) = (l as usize % 2, l as usize / 2);
                    (((j + b) % m) * m + (i + a) % m) as u32
                }));
                for l in t {
                    let (a, b) = (l as usize % 2, l as usize / 2);
                    uv.push([(i + a) as f64 * h, (j + b) as f64 * h]);
                }
            }
        }
    }
    (pos, tris, uv)
}

/// The other diagonal of a unit cell (corners 0 1 / 2 3 numbered `b * 2 + a`).
fn odd_cell(t: [u32; 3]) -> [u32; 3] {
    match t {
        [0, 1, 3] => [0, 1, 2],
        _ => [1, 3, 2],
    }
}

/// Sets the UV of every corner at vertex `v` to `to` (a fold when `to` lies
/// outside the vertex's one-ring).
fn move_uv(tris: &[[u32; 3]], uv: &mut [[f64; 2]], v: u32, to: [f64; 2]) {
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            if t[k] == v {
                uv[3 * f + k] = to;
            }
        }
    }
}

fn mesh(pos: Vec<[f64; 3]>, tris: Vec<[u32; 3]>) -> TriMesh {
    TriMesh::from_welded_arrays(pos, tris).expect("test mesh is valid")
}

/// Topological figures of a quad mesh.
#[derive(Debug)]
struct Topology {
    euler: i64,
    boundary_loops: usize,
    /// Number of vertices of each valence, keyed by (valence, on boundary).
    valences: HashMap<(usize, bool), usize>,
    manifold: bool,
    unused_vertices: usize,
}

fn topology(q: &QuadMesh) -> Topology {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    let mut manifold = true;
    for quad in &q.quads {
        for i in 0..4 {
            let e = (quad[i], quad[(i + 1) % 4]);
            if e.0 == e.1 || directed.insert(e, 1).is_some() {
                manifold = false;
            }
        }
    }
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); q.n_vertices()];
    let mut boundary_next: HashMap<u32, u32> = HashMap::new();
    let mut on_boundary = vec![false; q.n_vertices()];
    let mut edges = 0;
    for &(a, b) in directed.keys() {
        if !directed.contains_key(&(b, a)) {
            edges += 1;
            if boundary_next.insert(a, b).is_some() {
                manifold = false;
            }
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        } else if a < b {
            edges += 1;
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    let mut seen: HashMap<u32, bool> = HashMap::new();
    let mut boundary_loops = 0;
    for &start in boundary_next.keys() {
        if seen.contains_key(&start) {
            continue;
        }
        boundary_loops += 1;
        let mut v = start;
        while seen.insert(v, true).is_none() {
            match boundary_next.get(&v) {
                Some(&w) => v = w,
                None => {
                    manifold = false;
                    break;
                }
            }
        }
    }
    let mut valences = HashMap::new();
    let mut unused_vertices = 0;
    for (v, nb) in neighbours.iter().enumerate() {
        if nb.is_empty() {
            unused_vertices += 1;
            continue;
        }
        *valences.entry((nb.len(), on_boundary[v])).or_insert(0) += 1;
    }
    let used = (q.n_vertices() - unused_vertices) as i64;
    Topology { euler: used - edges as i64 + q.n_quads() as i64, boundary_loops, valences, manifold, unused_vertices }
}

/// Corner UVs of every quad form a counter-clockwise unit square.
fn assert_unit_squares(q: &QuadMesh) {
    assert_eq!(q.uv.len(), 4 * q.n_quads());
    for c in q.uv.chunks(4) {
        let mut area = 0.0;
        for i in 0..4 {
            let (a, b) = (c[i], c[(i + 1) % 4]);
            area += a[0] * b[1] - a[1] * b[0];
            let d = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            assert!((d - 1.0).abs() < 1e-12, "quad side {d}");
            assert!(a.iter().all(|x| (x - x.round()).abs() < 1e-12));
        }
        assert!((area / 2.0 - 1.0).abs() < 1e-12, "quad area {}", area / 2.0);
    }
}

/// Every quad vertex lies at its barycentric point of its face.
fn assert_on_surface(m: &TriMesh, q: &QuadMesh) {
    for (p, loc) in q.positions.iter().zip(&q.locations) {
        assert!(loc.bary.iter().all(|&b| (-1e-12..=1.0 + 1e-12).contains(&b)), "{loc:?}");
        assert!((loc.bary.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let c = m.faces()[loc.face as usize];
        for k in 0..3 {
            let x: f64 = (0..3).map(|i| loc.bary[i] * m.position(c[i])[k]).sum();
            assert!((x - p[k]).abs() < 1e-12);
        }
    }
}

fn extract(m: &TriMesh, uv: &[[f64; 2]]) -> QuadMesh {
    extract_quads(m, uv, &ExtractOptions::default()).expect("extraction runs")
}

/// Checks the planar square [0, n]² with uv = position.
fn check_square(n: usize, mm: usize, jitter: f64, seed: u64) {
    let (pos, tris, uv) = square(n, mm, jitter, seed);
    let m = mesh(pos, tris);
    let q = extract(&m, &uv);
    assert!(q.defects.is_empty(), "{:?}", q.defects);
    assert_eq!(q.n_quads(), n * n);
    assert_eq!(q.n_vertices(), (n + 1) * (n + 1));
    let t = topology(&q);
    assert!(t.manifold && t.unused_vertices == 0, "{t:?}");
    assert_eq!(t.euler, 1);
    assert_eq!(t.boundary_loops, 1);
    let expected: HashMap<(usize, bool), usize> =
        [((4, false), (n - 1) * (n - 1)), ((3, true), 4 * (n - 1)), ((2, true), 4)]
            .into_iter()
            .filter(|&(_, c)| c > 0)
            .collect();
    assert_eq!(t.valences, expected);
    assert_unit_squares(&q);
    assert_on_surface(&m, &q);
    // uv = position: every vertex is an integer point, every quad corner UV
    // is its vertex's position (the chart is the identity), area +1.
    for p in &q.positions {
        assert!(p[0].fract().abs().min(1.0 - p[0].fract().abs()) < 1e-9 && p[2] == 0.0, "{p:?}");
        assert!(p[1].fract().abs().min(1.0 - p[1].fract().abs()) < 1e-9, "{p:?}");
    }
    for (i, quad) in q.quads.iter().enumerate() {
        for k in 0..4 {
            let p = q.positions[quad[k] as usize];
            let c = q.uv[4 * i + k];
            assert!((p[0] - c[0]).abs() < 1e-9 && (p[1] - c[1]).abs() < 1e-9);
        }
    }
}

#[test]
fn square_with_vertices_on_integer_points() {
    // Isolines along mesh edges and through every mesh vertex.
    check_square(4, 4, 0.0, 1);
}

#[test]
fn a_long_input_boundary_is_not_a_hole() {
    // 84 boundary quad edges: longer than any hole the extractor fills.
    check_square(21, 14, 0.2, 4);
}

#[test]
fn square_with_half_integer_vertices() {
    // Vertices on isolines between integer points; diagonals through them.
    check_square(3, 6, 0.0, 1);
}

#[test]
fn square_with_generic_irregular_triangulation() {
    // Isolines cut edges generically; the boundary still lies on isolines.
    check_square(5, 7, 0.2, 3);
    check_square(6, 4, 0.2, 11);
    check_square(3, 13, 0.2, 5);
}

#[test]
fn square_edges_on_isolines_are_quad_edges() {
    let (pos, tris, uv) = square(4, 4, 0.0, 1);
    let m = mesh(pos, tris);
    let q = extract(&m, &uv);
    let at: HashMap<[i64; 2], u32> =
        q.positions.iter().enumerate().map(|(i, p)| ([p[0].round() as i64, p[1].round() as i64], i as u32)).collect();
    let quad_edges: std::collections::HashSet<(u32, u32)> = q
        .quads
        .iter()
        .flat_map(|c| (0..4).map(move |i| (c[i].min(c[(i + 1) % 4]), c[i].max(c[(i + 1) % 4]))))
        .collect();
    let mut axis_edges = 0;
    for e in 0..m.n_edges() as u32 {
        let [a, b] = m.edge_vertices(e);
        let (pa, pb) = (m.position(a), m.position(b));
        if pa[0] == pb[0] || pa[1] == pb[1] {
            axis_edges += 1;
            let (qa, qb) = (at[&[pa[0] as i64, pa[1] as i64]], at[&[pb[0] as i64, pb[1] as i64]]);
            assert!(quad_edges.contains(&(qa.min(qb), qa.max(qb))), "edge {e} not covered");
        }
    }
    assert_eq!(axis_edges, 2 * 4 * 5);
}

#[test]
fn l_shape_has_a_concave_boundary_corner() {
    // [0, 2n]² without [n, 2n]²; the corner (n, n) has UV angle 3π/2, so
    // boundary valence 4.
    for (n, cells) in [(2usize, 4usize), (2, 8)] {
        let (pos, tris, _) = square(2 * n, cells, 0.0, 1);
        let half = n as f64;
        let tris: Vec<[u32; 3]> = tris
            .into_iter()
            .filter(|t| {
                let c = t.iter().fold([0.0; 2], |a, &v| [a[0] + pos[v as usize][0], a[1] + pos[v as usize][1]]);
                !(c[0] / 3.0 > half && c[1] / 3.0 > half)
            })
            .collect();
        let uv: Vec<[f64; 2]> = tris.iter().flat_map(|t| t.map(|v| [pos[v as usize][0], pos[v as usize][1]])).collect();
        let m = mesh(pos, tris);
        let q = extract(&m, &uv);
        assert!(q.defects.is_empty(), "{:?}", q.defects);
        assert_eq!(q.n_quads(), 3 * n * n);
        let t = topology(&q);
        assert!(t.manifold && t.unused_vertices == 0);
        assert_eq!((t.euler, t.boundary_loops), (1, 1));
        assert_eq!((t.valences[&(2, true)], t.valences[&(4, true)]), (5, 1));
        assert_unit_squares(&q);
    }
}

/// Checks the cube with m × m faces and chart scale s.
fn check_cube(m: usize, s: usize, jitter: bool) -> QuadMesh {
    let (pos, tris, uv) = cube(m, s as f64, jitter, 0.0);
    let tm = mesh(pos, tris);
    assert_eq!(tm.euler_characteristic(), 2);
    let q = extract(&tm, &uv);
    assert!(q.defects.is_empty(), "{:?}", &q.defects[..q.defects.len().min(5)]);
    let k = m * s;
    assert_eq!(q.n_quads(), 6 * k * k);
    let t = topology(&q);
    assert!(t.manifold && t.unused_vertices == 0, "{t:?}");
    assert_eq!(t.euler, 2);
    assert_eq!(t.boundary_loops, 0);
    let expected: HashMap<(usize, bool), usize> =
        [((3, false), 8), ((4, false), 6 * k * k + 2 - 8)].into_iter().collect();
    assert_eq!(t.valences, expected);
    assert_unit_squares(&q);
    assert_on_surface(&tm, &q);
    // Counter-clockwise seen from outside, and of the lattice's size.
    for c in &q.quads {
        let p = c.map(|v| q.positions[v as usize]);
        let d1 = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
        let d2 = [0, 1, 2].map(|k| p[3][k] - p[1][k]);
        let n = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]];
        let centre = [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k] + p[3][k]) / 4.0 - 0.5);
        let outward: f64 = (0..3).map(|k| n[k] * centre[k]).sum();
        assert!(outward > 0.0, "quad {c:?} is clockwise");
        let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((area * (k * k) as f64 - 1.0).abs() < 1e-6, "quad area {area}");
    }
    for p in &q.positions {
        let on_face = p.iter().any(|&x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12);
        let inside = p.iter().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x));
        assert!(on_face && inside, "{p:?} off the cube");
        // Quad vertices are on the 1 / k lattice of the cube.
        assert!(p.iter().all(|&x| (x * k as f64 - (x * k as f64).round()).abs() < 1e-9), "{p:?}");
    }
    q
}

#[test]
fn cube_with_quarter_turn_seams() {
    check_cube(3, 1, false);
    check_cube(2, 3, false);
}

#[test]
fn cube_with_jittered_triangles() {
    check_cube(4, 2, true);
    check_cube(5, 1, true);
}

#[test]
fn cube_edges_are_quad_edges() {
    // With s = 1 every mesh vertex is an integer point and every cube edge
    // (a feature on an isoline) is a chain of quad edges.
    let q = check_cube(3, 1, false);
    let lattice = |p: [f64; 3]| p.map(|x| (x * 3.0).round() as i64);
    let at: HashMap<[i64; 3], u32> = q.positions.iter().enumerate().map(|(i, &p)| (lattice(p), i as u32)).collect();
    let quad_edges: std::collections::HashSet<(u32, u32)> = q
        .quads
        .iter()
        .flat_map(|c| (0..4).map(move |i| (c[i].min(c[(i + 1) % 4]), c[i].max(c[(i + 1) % 4]))))
        .collect();
    let mut cube_edges = 0;
    for a in 0..=3i64 {
        for (x, y) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
            for axis in 0..3 {
                if a == 3 {
                    continue;
                }
                let mut p = [0i64; 3];
                let others: Vec<usize> = (0..3).filter(|&k| k != axis).collect();
                p[others[0]] = x;
                p[others[1]] = y;
                p[axis] = a;
                let mut r = p;
                r[axis] = a + 1;
                let (qa, qb) = (at[&p], at[&r]);
                assert!(quad_edges.contains(&(qa.min(qb), qa.max(qb))), "cube edge {p:?}-{r:?} not covered");
                cube_edges += 1;
            }
        }
    }
    assert_eq!(cube_edges, 12 * 3);
}

#[test]
fn flat_torus() {
    for (n, m) in [(4, 6), (5, 5), (3, 4)] {
        let (pos, tris, uv) = torus(n, m);
        let tm = mesh(pos, tris);
        assert_eq!(tm.euler_characteristic(), 0);
        let q = extract(&tm, &uv);
        assert!(q.defects.is_empty(), "{:?}", q.defects);
        assert_eq!(q.n_quads(), n * n);
        let t = topology(&q);
        assert!(t.manifold && t.unused_vertices == 0, "{t:?}");
        assert_eq!((t.euler, t.boundary_loops), (0, 0));
        assert_eq!(t.valences, [((4, false), n * n)].into_iter().collect());
        assert_unit_squares(&q);
        assert_on_surface(&tm, &q);
    }
}

/// Five quarter-planes [0, n]² glued cyclically around a vertex (a cone of
/// index −1, UV angle 5π/2), embedded flat by z ↦ z^(4/5); each an m × m
/// grid with uv = grid coordinates · n / m.
fn five_squares(n: usize, m: usize) -> TestMap {
    let mut pos = Vec::new();
    let mut ids: HashMap<(usize, usize, usize), u32> = HashMap::new();
    let mut id = |s: usize, p: usize, q: usize, pos: &mut Vec<[f64; 3]>| {
        // (s, 0, t) is (s + 1, t, 0); the centre is one vertex.
        let key = if p == 0 && q == 0 {
            (0, 0, 0)
        } else if p == 0 {
            ((s + 1) % 5, q, 0)
        } else {
            (s, p, q)
        };
        *ids.entry(key).or_insert_with(|| {
            let (a, b) = (key.1 as f64 / m as f64, key.2 as f64 / m as f64);
            let (r, th) =
                ((a * a + b * b).sqrt().powf(0.8), b.atan2(a) * 0.8 + std::f64::consts::TAU * key.0 as f64 / 5.0);
            pos.push([r * th.cos(), r * th.sin(), 0.0]);
            (pos.len() - 1) as u32
        })
    };
    let (mut tris, mut uv) = (Vec::new(), Vec::new());
    let h = n as f64 / m as f64;
    for s in 0..5 {
        for t in grid_triangles(m, |p, q| (q * (m + 1) + p) as u32) {
            tris.push(t.map(|l| id(s, l as usize % (m + 1), l as usize / (m + 1), &mut pos)));
            uv.extend(t.map(|l| [(l as usize % (m + 1)) as f64 * h, (l as usize / (m + 1)) as f64 * h]));
        }
    }
    (pos, tris, uv)
}

#[test]
fn valence_five_cone() {
    for (n, m) in [(2, 2), (2, 3), (3, 4)] {
        let (pos, tris, uv) = five_squares(n, m);
        let tm = mesh(pos, tris);
        let q = extract(&tm, &uv);
        assert!(q.defects.is_empty(), "{:?}", q.defects);
        assert_eq!(q.n_quads(), 5 * n * n);
        let t = topology(&q);
        assert!(t.manifold && t.unused_vertices == 0, "{t:?}");
        assert_eq!((t.euler, t.boundary_loops), (1, 1));
        let expected: HashMap<(usize, bool), usize> = [
            ((5, false), 1),
            ((4, false), 5 * (n - 1) * (n - 1) + 5 * (n - 1)),
            ((3, true), 5 * (2 * n - 1)),
            ((2, true), 5),
        ]
        .into_iter()
        .collect();
        assert_eq!(t.valences, expected);
        assert_on_surface(&tm, &q);
    }
}

#[test]
fn two_components() {
    let (mut pos, mut tris, mut uv) = square(3, 5, 0.2, 9);
    let (cpos, ctris, cuv) = cube(2, 2.0, true, 0.0);
    let base = pos.len() as u32;
    pos.extend(cpos.iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
    tris.extend(ctris.iter().map(|t| t.map(|v| v + base)));
    uv.extend(cuv);
    let tm = mesh(pos, tris);
    assert_eq!(tm.n_components(), 2);
    let q = extract(&tm, &uv);
    assert!(q.defects.is_empty(), "{:?}", q.defects);
    assert_eq!(q.n_quads(), 9 + 6 * 16);
    let t = topology(&q);
    assert!(t.manifold && t.unused_vertices == 0);
    assert_eq!((t.euler, t.boundary_loops), (3, 1));
    assert_eq!(t.valences[&(3, false)], 8);
    assert_on_surface(&tm, &q);
}

#[test]
fn flipped_triangles_are_defects_not_panics() {
    let (pos, tris, mut uv) = square(4, 4, 0.0, 1);
    let m = mesh(pos.clone(), tris.clone());
    // Move vertex (2, 2) far outside its one-ring in every corner.
    let v = 2 * 5 + 2;
    move_uv(&tris, &mut uv, v, [3.7, 2.4]);
    let q = extract(&m, &uv);
    assert!(q.defects.iter().any(|d| d.what.contains("flipped")), "{:?}", q.defects);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
}

/// The square [0, 8]² (16 × 16 grid) with the grid vertex at `at` moved
/// to `to` in the map, and its extracted quads.
fn folded_square(at: [f64; 2], to: [f64; 2]) -> (TriMesh, QuadMesh) {
    let (pos, tris, mut uv) = square(8, 16, 0.0, 3);
    let m = mesh(pos.clone(), tris.clone());
    let v = pos.iter().position(|p| p[0] == at[0] && p[1] == at[1]).expect("grid vertex");
    move_uv(&tris, &mut uv, v as u32, to);
    let q = extract(&m, &uv);
    (m, q)
}

/// Filled quads are not folded: each has a positive area in the plane.
fn assert_positive_areas(q: &QuadMesh) {
    for quad in &q.quads {
        let p = quad.map(|v| q.positions[v as usize]);
        let area: f64 = (0..4).map(|i| p[i][0] * p[(i + 1) % 4][1] - p[(i + 1) % 4][0] * p[i][1]).sum();
        assert!(area > 0.0, "{quad:?} {p:?}");
    }
}

/// A square map whose middle folds: the cells over the flipped triangles are
/// skipped, and the hole they leave is filled with quads on the surface, so
/// the quad mesh is still one watertight disk.
#[test]
fn holes_over_flipped_triangles_are_filled() {
    // Push the vertex at (4, 4) across its neighbours.
    let (m, q) = folded_square([4.0, 4.0], [5.3, 4.6]);
    assert!(q.defects.iter().any(|d| d.what.contains("flipped")), "{:?}", q.defects);
    let filled: Vec<&QuadDefect> = q.defects.iter().filter(|d| d.what.contains("closed with")).collect();
    assert!(!filled.is_empty(), "{:?}", q.defects);
    assert!(!q.defects.iter().any(|d| d.what.contains("left open")), "{:?}", q.defects);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
    assert_eq!((t.euler, t.boundary_loops, t.unused_vertices), (1, 1, 0), "{t:?}");
    assert_on_surface(&m, &q);
    assert_unit_squares(&q);
    assert_positive_areas(&q);
}

#[test]
fn non_integer_translation_is_a_defect() {
    let (pos, tris, uv) = cube(2, 2.0, false, 0.37);
    let tm = mesh(pos, tris);
    let q = extract(&tm, &uv);
    assert!(q.defects.iter().any(|d| d.what.contains("transition")), "{:?}", q.defects);
    assert!(topology(&q).manifold);
}

#[test]
fn boundary_off_the_isolines_is_a_defect() {
    let (pos, tris, uv) = square(3, 4, 0.1, 8);
    let m = mesh(pos, tris);
    let uv: Vec<[f64; 2]> = uv.iter().map(|p| [p[0] + 0.3, p[1]]).collect();
    let q = extract(&m, &uv);
    assert!(q.defects.iter().any(|d| d.what.contains("boundary edge")), "{:?}", q.defects);
    assert!(topology(&q).manifold);
}

#[test]
fn non_integer_cone_is_a_defect() {
    // Scaling a cube map by 1.5 moves its cones off the integer points.
    let (pos, tris, uv) = cube(2, 2.0, false, 0.0);
    let tm = mesh(pos, tris);
    let uv: Vec<[f64; 2]> = uv.iter().map(|p| [1.5 * p[0] + 0.25, 1.5 * p[1]]).collect();
    let q = extract(&tm, &uv);
    assert!(!q.defects.is_empty());
}

#[test]
fn random_maps_never_panic() {
    let mut rng = Lcg(42);
    let meshes = [square(3, 4, 0.2, 2), cube(2, 1.0, true, 0.0), torus(3, 4)];
    for (pos, tris, uv) in meshes {
        let tm = mesh(pos, tris);
        for trial in 0..40 {
            let noisy: Vec<[f64; 2]> = uv
                .iter()
                .map(|p| {
                    if trial < 20 {
                        // Local damage to a valid map.
                        if rng.next() < 0.1 {
                            [p[0] + rng.next() - 0.5, p[1] + rng.next() - 0.5]
                        } else {
                            *p
                        }
                    } else {
                        [rng.next() * 8.0 - 4.0, rng.next() * 8.0 - 4.0]
                    }
                })
                .collect();
            let q = extract(&tm, &noisy);
            assert_eq!(q.uv.len(), 4 * q.n_quads());
            assert!(q.quads.iter().flatten().all(|&v| (v as usize) < q.n_vertices()));
        }
    }
}

#[test]
fn huge_inconsistent_maps_stay_in_range_and_budget() {
    let mut rng = Lcg(5);
    let (pos, tris, _) = cube(2, 1.0, false, 0.0);
    let tm = mesh(pos, tris);
    let o = ExtractOptions { max_vertices: 10_000, ..ExtractOptions::default() };
    for _ in 0..10 {
        let big = super::MAX_UV;
        let uv: Vec<[f64; 2]> =
            (0..3 * tm.n_faces()).map(|_| [(rng.next() * 2.0 - 1.0) * big, (rng.next() * 2.0 - 1.0) * big]).collect();
        let q = extract_quads(&tm, &uv, &o).expect("in range");
        assert!(q.n_vertices() <= 10_001);
        assert!(q.defects.iter().any(|d| d.what.contains("enumeration stopped")), "{:?}", q.defects);
    }
}

#[test]
fn single_triangles_never_panic() {
    let m = mesh(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
    for uv in [
        [[0.0, 0.0]; 3],
        [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
        [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]],
        [[0.5, 0.5], [0.5, 0.5], [3.0, 3.0]],
    ] {
        let q = extract(&m, &uv);
        assert!(!q.defects.is_empty());
        assert!(q.quads.is_empty() || q.n_quads() <= 16);
    }
}

#[test]
fn bad_input_is_an_error() {
    let (pos, tris, mut uv) = square(2, 2, 0.0, 1);
    let m = mesh(pos, tris);
    let o = ExtractOptions::default();
    assert_eq!(extract_quads(&m, &uv[1..], &o).unwrap_err(), ExtractError::CornerCount { expected: 24, found: 23 });
    uv[5][1] = f64::NAN;
    assert_eq!(extract_quads(&m, &uv, &o).unwrap_err(), ExtractError::NotFinite { corner: 5 });
    uv[5][1] = 1e12;
    assert_eq!(extract_quads(&m, &uv, &o).unwrap_err(), ExtractError::OutOfRange { corner: 5 });
}

/// Release-mode figures: `cargo test --release -p conemap --lib
/// quads::extract -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_large_cube() {
    for (m, scale) in [(91, 1.0), (90, 2.0 / 3.0), (90, 0.5)] {
        let (pos, tris, uv) = cube(m, scale, true, 0.0);
        let tm = mesh(pos, tris);
        let t0 = std::time::Instant::now();
        let q = extract(&tm, &uv);
        let dt = t0.elapsed();
        let k = (m as f64 * scale).round() as usize;
        assert!(q.defects.is_empty());
        assert_eq!(q.n_quads(), 6 * k * k);
        println!("{} faces -> {} quads in {:?}", tm.n_faces(), q.n_quads(), dt);
    }
    // A damaged map: 5% of the corners moved by up to half a cell.
    let (pos, tris, uv) = cube(91, 1.0, true, 0.0);
    let tm = mesh(pos, tris);
    let mut rng = Lcg(3);
    let uv: Vec<[f64; 2]> = uv
        .iter()
        .map(|p| if rng.next() < 0.05 { [p[0] + rng.next() - 0.5, p[1] + rng.next() - 0.5] } else { *p })
        .collect();
    let t0 = std::time::Instant::now();
    let q = extract(&tm, &uv);
    println!(
        "damaged: {} faces -> {} quads, {} defects in {:?}",
        tm.n_faces(),
        q.n_quads(),
        q.defects.len(),
        t0.elapsed()
    );
}

/// Quads that overlap (here a traced quad repeated, as two closings of
/// wound cells can overlap) are removed and the hole they leave filled:
/// the mesh is a manifold disk again, and the repair is reported.
#[test]
fn overlapping_quads_are_removed_and_the_hole_filled() {
    let (pos, tris, uv) = square(4, 8, 0.0, 6);
    let m = mesh(pos, tris);
    let mut q = extract(&m, &uv);
    assert!(q.defects.is_empty(), "{:?}", q.defects);
    let inside = |v: u32| q.positions[v as usize].iter().take(2).all(|&x| x > 0.0 && x < 4.0);
    let k = q.quads.iter().position(|quad| quad.iter().all(|&v| inside(v))).expect("an interior quad");
    let copy = q.quads[k];
    q.quads.push(copy);
    q.uv.extend_from_within(4 * k..4 * k + 4);
    assert!(!topology(&q).manifold);
    super::fill::fill_holes(&m, &mut q);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
    assert_eq!((t.euler, t.boundary_loops, q.n_quads()), (1, 1, 16), "{t:?}");
    assert!(q.defects.iter().any(|d| d.what.contains("not a manifold")), "{:?}", q.defects);
    assert!(q.defects.iter().any(|d| d.what.contains("closed with 1 quads")), "{:?}", q.defects);
    assert_on_surface(&m, &q);
}

/// A fold next to the boundary: the hole it leaves reaches the input's
/// boundary, and is closed with new quad vertices along that boundary, so
/// the quad mesh is one disk with one boundary loop, every vertex on the
/// surface and the boundary's vertices on the input's boundary.
#[test]
fn holes_at_the_boundary_are_filled_along_it() {
    let n = 8.0;
    let (m, q) = folded_square([4.0, 0.5], [5.2, -0.3]);
    assert!(q.defects.iter().any(|d| d.what.contains("at the input's boundary") && d.what.contains("closed with")), "{:?}", q.defects);
    assert!(!q.defects.iter().any(|d| d.what.contains("left open")), "{:?}", q.defects);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
    assert_eq!((t.euler, t.boundary_loops, t.unused_vertices), (1, 1, 0), "{t:?}");
    assert_on_surface(&m, &q);
    // Boundary vertices of the quad mesh lie on the square's boundary.
    let mut directed = std::collections::HashSet::new();
    for quad in &q.quads {
        for i in 0..4 {
            directed.insert((quad[i], quad[(i + 1) % 4]));
        }
    }
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            for w in [a, b] {
                let p = q.positions[w as usize];
                assert!(p[0] == 0.0 || p[0] == n || p[1] == 0.0 || p[1] == n, "boundary vertex {w} at {p:?}");
            }
        }
    }
    assert_positive_areas(&q);
}

/// A unit cube of 4 x 4 squares per side and its traced quads (no defect).
fn cube_quads() -> (TriMesh, QuadMesh) {
    let (pos, tris, uv) = cube(4, 1.0, false, 0.0);
    let m = mesh(pos, tris);
    let q = extract(&m, &uv);
    assert!(q.defects.is_empty(), "{:?}", q.defects);
    (m, q)
}

/// The quads of a cube with the band of quads around its middle (no quad
/// vertex with z in (0.3, 0.7)) taken out fall into two pieces, each with
/// one hole: filling both would give two closed surfaces; the holes are
/// joined by a strip of quads instead, into one closed manifold sphere.
#[test]
fn holes_that_cut_the_quads_in_two_are_joined() {
    let (m, mut q) = cube_quads();
    let n = q.n_quads();
    let middle = |v: &u32| (0.3..0.7).contains(&q.positions[*v as usize][2]);
    let band: Vec<bool> = q.quads.iter().map(|quad| quad.iter().any(middle)).collect();
    assert_eq!(band.iter().filter(|&&b| b).count(), 4 * 4 * 2, "two rows of quads around");
    q.remove_quads(&band);
    super::fill::fill_holes(&m, &mut q);
    let joined: Vec<&QuadDefect> = q.defects.iter().filter(|d| d.what.contains("joined with 16 quads")).collect();
    assert_eq!(joined.len(), 1, "{:?}", q.defects);
    assert_eq!(q.n_quads(), n - 16);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
    assert_eq!((t.euler, t.boundary_loops), (2, 0), "{t:?}");
    // The strip's quads run straight across the gap: each joins a vertex
    // at z = 0.25 to the one at z = 0.75 above it.
    for quad in &q.quads[n - 32..] {
        let z: Vec<f64> = quad.iter().map(|&v| q.positions[v as usize][2]).collect();
        assert!(z.iter().filter(|&&z| z == 0.25).count() == 2 && z.iter().filter(|&&z| z == 0.75).count() == 2, "{z:?}");
    }
}

/// A cube of six quads with a pillow (two quads over the same four
/// vertices, in opposite orders) glued along one of its edges: removing
/// the pillow leaves the closed, manifold cube with its own corners and
/// unit squares, and one defect saying where.
#[test]
fn pillows_glued_to_the_mesh_are_removed() {
    let cube = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
    let pillow = [[0, 1, 9, 8], [8, 9, 1, 0]];
    let quads: Vec<[u32; 4]> = cube.iter().chain(&pillow).copied().collect();
    let unit = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let at = SurfacePoint { face: 7, bary: [1.0, 0.0, 0.0] };
    let mut q = QuadMesh { positions: vec![[0.0; 3]; 10], locations: vec![at; 10], uv: unit.repeat(quads.len()), quads, defects: Vec::new() };
    let before = topology(&q);
    assert!(!before.manifold, "the pillow's edge (0, 1) has four quads");
    super::drop_pillows(&mut q);
    super::drop_unreferenced(&mut q);
    assert_eq!(q.quads, cube.to_vec());
    let after = topology(&q);
    assert!(after.manifold);
    assert_eq!((after.euler, after.boundary_loops, after.unused_vertices, q.n_vertices()), (2, 0, 0, 8));
    assert_unit_squares(&q);
    assert_eq!(q.defects.len(), 1);
    assert_eq!(q.defects[0].face, 7);
}

/// The cube's quads with the band around its middle taken out except two
/// quads that touch at one corner: the two pieces meet at that vertex
/// only, each with one hole through it. Filling both holes would leave two
/// spheres joined at a point; the vertex is opened and the holes joined
/// instead, into one closed manifold sphere.
#[test]
fn pieces_that_meet_at_a_vertex_are_joined() {
    let (m, mut q) = cube_quads();
    let p = |v: u32| q.positions[v as usize];
    // The pinch: a vertex at mid-height inside the face y = 0.
    let pinch = (0..q.n_vertices() as u32).find(|&v| p(v) == [0.5, 0.0, 0.5]).expect("a vertex at (0.5, 0, 0.5)");
    let band = |quad: &[u32; 4]| quad.iter().any(|&v| (0.3..0.7).contains(&p(v)[2]));
    // Of the four band quads at the pinch keep the one below and left and the one above and right.
    let keep = |quad: &[u32; 4]| {
        let c = quad.iter().fold([0.0; 3], |c, &v| crate::vec3::add(c, crate::vec3::scale(p(v), 0.25)));
        quad.contains(&pinch) && ((c[0] < 0.5 && c[2] < 0.5) || (c[0] > 0.5 && c[2] > 0.5))
    };
    let remove: Vec<bool> = q.quads.iter().map(|quad| band(quad) && !keep(quad)).collect();
    assert_eq!(remove.iter().filter(|&&r| r).count(), 32 - 2);
    q.remove_quads(&remove);
    assert_eq!(topology(&q).euler, 1, "two disks' worth of quads joined at one vertex");
    super::fill::fill_holes(&m, &mut q);
    assert!(q.defects.iter().any(|d| d.what.contains("joined with")), "{:?}", q.defects);
    let t = topology(&q);
    assert!(t.manifold, "{t:?}");
    assert_eq!((t.euler, t.boundary_loops), (2, 0), "{t:?}");
    assert!(q.quads.iter().all(|quad| !quad.contains(&pinch)), "the pinch is opened");
    assert_on_surface(&m, &q);
}
