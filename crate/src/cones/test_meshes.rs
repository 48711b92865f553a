//! Small synthetic meshes for the cone-placement tests.

use crate::mesh::TriMesh;

/// A regular octahedron (six degree-4 vertices, each a cone of angle 2pi - pi/2).
pub fn octahedron() -> TriMesh {
    let p = vec![[1., 0., 0.], [-1., 0., 0.], [0., 1., 0.], [0., -1., 0.], [0., 0., 1.], [0., 0., -1.]];
    let t = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    TriMesh::from_welded_arrays(p, t).unwrap()
}

/// An `nx` × `ny` grid of squares on [0, 1]² mapped through `embed`.
pub fn grid(nx: usize, ny: usize, embed: impl Fn(f64, f64) -> [f64; 3]) -> TriMesh {
    let raw = crate::mesh::shapes::grid(nx, ny, embed);
    TriMesh::from_welded_arrays(raw.positions, raw.triangles).unwrap()
}

/// A torus of revolution with `nu` × `nv` quads split in two.
pub fn torus(nu: usize, nv: usize, big_r: f64, small_r: f64) -> TriMesh {
    use std::f64::consts::PI;
    let mut p = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = (2.0 * PI * i as f64 / nu as f64, 2.0 * PI * j as f64 / nv as f64);
            let r = big_r + small_r * v.cos();
            p.push([r * u.cos(), r * u.sin(), small_r * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((j % nv) * nu + (i % nu)) as u32;
    let mut t = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    TriMesh::from_welded_arrays(p, t).unwrap()
}

/// A flat square annulus: the square [-1, 1]² minus the square of half-side
/// `inner` rotated by `angle`, triangulated by a polar-like grid of
/// `n` segments per side and `rings` rings.
pub fn square_annulus(n: usize, rings: usize, inner: f64, angle: f64) -> TriMesh {
    annulus(n, rings, |s| square_point(s, inner, angle))
}

/// The square [-1, 1]² minus the disk of `radius` about its centre, on the
/// grid of [`square_annulus`] (the hole a polygon of `4 n` sides).
pub fn square_with_round_hole(n: usize, rings: usize, radius: f64) -> TriMesh {
    use std::f64::consts::PI;
    annulus(n, rings, |s| {
        let a = 2.0 * PI * s - 0.75 * PI; // s = 0 faces the corner (-1, -1)
        [radius * a.cos(), radius * a.sin()]
    })
}

/// Point at arclength fraction `s` in [0, 1) around a square of half-side
/// `half` rotated by `rot`, from its corner (-half, -half) counterclockwise.
fn square_point(s: f64, half: f64, rot: f64) -> [f64; 2] {
    let side = (s * 4.0).floor() as usize % 4;
    let f = s * 4.0 - (s * 4.0).floor();
    let (x, y) = match side {
        0 => (-half + 2.0 * half * f, -half),
        1 => (half, -half + 2.0 * half * f),
        2 => (half - 2.0 * half * f, half),
        _ => (-half, half - 2.0 * half * f),
    };
    [x * rot.cos() - y * rot.sin(), x * rot.sin() + y * rot.cos()]
}

/// The square [-1, 1]² minus the region inside the closed curve `inner`
/// (arclength fraction in [0, 1) to a point), triangulated by `rings` rings
/// of `4 n` quads between the two, each split in two.
fn annulus(n: usize, rings: usize, inner: impl Fn(f64) -> [f64; 2]) -> TriMesh {
    let m = 4 * n;
    let mut p = Vec::new();
    for r in 0..=rings {
        let t = r as f64 / rings as f64;
        for i in 0..m {
            let s = i as f64 / m as f64;
            let a = square_point(s, 1.0, 0.0);
            let b = inner(s);
            p.push([a[0] * (1.0 - t) + b[0] * t, a[1] * (1.0 - t) + b[1] * t, 0.0]);
        }
    }
    let id = |r: usize, i: usize| (r * m + i % m) as u32;
    let mut t = Vec::new();
    for r in 0..rings {
        for i in 0..m {
            let (a, b, c, d) = (id(r, i), id(r, i + 1), id(r + 1, i + 1), id(r + 1, i));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    TriMesh::from_welded_arrays(p, t).unwrap()
}

/// The ring-with-flap shape of the paper's Figure 10: a circular strip ring
/// (radii 1 to 1.5, `n` columns around) whose outer side widens smoothly
/// over the first quarter turn (out to radius 2) and then splits: the outer
/// half continues as a flap, separated from the ring by a slit, and ends
/// with two right-angle corners at half a turn. A cone-free aligned map must
/// give the ring one parametric width everywhere, so the flap collapses.
pub fn ring_with_flap(n: usize) -> TriMesh {
    use std::collections::HashMap;
    use std::f64::consts::PI;
    assert!(n.is_multiple_of(4));
    let (quarter, half) = (n / 4, n / 2);
    let theta = |i: usize| 2.0 * PI * i as f64 / n as f64;
    let outer = |i: usize| if i <= quarter { 1.5 + 0.5 * theta(i).sin() } else { 2.0 };
    #[derive(Clone, Copy, PartialEq, Eq, Hash)]
    enum Key {
        Ring(usize, usize),
        Outer(usize, usize), // rows 8..=12 of the widened part and the flap
    }
    let mut id: HashMap<Key, u32> = HashMap::new();
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut vert = |key: Key, p: &mut Vec<[f64; 3]>| {
        *id.entry(key).or_insert_with(|| {
            let (i, r) = match key {
                Key::Ring(i, j) => (i, 1.0 + 0.5 * j as f64 / 8.0),
                Key::Outer(i, j) => (i, 1.5 + (outer(i) - 1.5) * (j - 8) as f64 / 4.0),
            };
            let a = theta(i);
            p.push([r * a.cos(), r * a.sin(), 0.0]);
            (p.len() - 1) as u32
        })
    };
    // Vertex of the outer part at column i, row j (8..=12): row 8 is the
    // ring's outer row up to the split, the flap's own row after it.
    let outer_key = |i: usize, j: usize| {
        if j == 8 && i <= quarter {
            Key::Ring(i % n, 8)
        } else {
            Key::Outer(i, j)
        }
    };
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..8 {
            let a = vert(Key::Ring(i, j), &mut p);
            let b = vert(Key::Ring((i + 1) % n, j), &mut p);
            let c = vert(Key::Ring((i + 1) % n, j + 1), &mut p);
            let d = vert(Key::Ring(i, j + 1), &mut p);
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    for i in 0..half {
        for j in 8..12 {
            let b = vert(outer_key(i + 1, j), &mut p);
            let c = vert(outer_key(i + 1, j + 1), &mut p);
            if i == 0 {
                // The widening starts from the single ring vertex at angle 0.
                let a = vert(Key::Ring(0, 8), &mut p);
                t.push([a, b, c]);
                continue;
            }
            let a = vert(outer_key(i, j), &mut p);
            let d = vert(outer_key(i, j + 1), &mut p);
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    TriMesh::from_welded_arrays(p, t).unwrap()
}

/// A torus, an octahedron and a bent square side by side: three components.
pub fn three_parts() -> TriMesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for (k, part) in [torus(16, 10, 2.0, 0.7), octahedron(), grid(6, 6, |x, y| [x, y, 0.3 * x * y])].iter().enumerate() {
        let base = positions.len() as u32;
        positions.extend(part.positions().iter().map(|p| [p[0] + 5.0 * k as f64, p[1], p[2]]));
        triangles.extend(part.faces().iter().map(|t| t.map(|v| v + base)));
    }
    TriMesh::from_welded_arrays(positions, triangles).unwrap()
}
