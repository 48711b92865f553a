//! Small synthetic meshes for the cone-placement tests.

use crate::mesh::TriMesh;

/// A regular octahedron (six degree-4 vertices, each a cone of angle 2pi - pi/2).
pub fn octahedron() -> TriMesh {
    let p = vec![[1., 0., 0.], [-1., 0., 0.], [0., 1., 0.], [0., -1., 0.], [0., 0., 1.], [0., 0., -1.]];
    let t = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    TriMesh::from_welded_arrays(p, t).unwrap()
}

/// An `nx` × `ny` grid of squares on [0, 1]², each split into two
/// triangles, mapped through `embed`.
pub fn grid(nx: usize, ny: usize, embed: impl Fn(f64, f64) -> [f64; 3]) -> TriMesh {
    let mut p = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            p.push(embed(i as f64 / nx as f64, j as f64 / ny as f64));
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
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
    TriMesh::from_welded_arrays(p, t).unwrap()
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
    let square = |s: f64, half: f64, rot: f64| -> [f64; 2] {
        // Point at arclength fraction s in [0, 1) around a square of half-side `half`.
        let side = (s * 4.0).floor() as usize % 4;
        let f = s * 4.0 - (s * 4.0).floor();
        let (x, y) = match side {
            0 => (-half + 2.0 * half * f, -half),
            1 => (half, -half + 2.0 * half * f),
            2 => (half - 2.0 * half * f, half),
            _ => (-half, half - 2.0 * half * f),
        };
        [x * rot.cos() - y * rot.sin(), x * rot.sin() + y * rot.cos()]
    };
    let m = 4 * n;
    let mut p = Vec::new();
    for r in 0..=rings {
        let t = r as f64 / rings as f64;
        for i in 0..m {
            let s = i as f64 / m as f64;
            let a = square(s, 1.0, 0.0);
            let b = square(s, inner, angle);
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
/// (radii 1 to 1.5) with a radial flap (out to radius 2.5, about 0.35 wide)
/// protruding from its outer side; `n` cells around the ring.
pub fn ring_with_flap(n: usize) -> TriMesh {
    use std::collections::HashMap;
    use std::f64::consts::PI;
    let radii = [1.0, 1.125, 1.25, 1.375, 1.5, 1.75, 2.0, 2.25, 2.5];
    let ring_rows = 4; // rows 0..4 are the ring, rows 4..8 the flap
    let flap_cells = 2; // cells on each side of angle 0
    let mut id: HashMap<(usize, usize), u32> = HashMap::new();
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut vert = |i: usize, j: usize, p: &mut Vec<[f64; 3]>| {
        let i = i % n;
        *id.entry((i, j)).or_insert_with(|| {
            let a = 2.0 * PI * i as f64 / n as f64;
            p.push([radii[j] * a.cos(), radii[j] * a.sin(), 0.0]);
            (p.len() - 1) as u32
        })
    };
    let mut t = Vec::new();
    for j in 0..radii.len() - 1 {
        for i in 0..n {
            let in_flap = i < flap_cells || i >= n - flap_cells;
            if j >= ring_rows && !in_flap {
                continue;
            }
            let (a, b) = (vert(i, j, &mut p), vert(i + 1, j, &mut p));
            let (c, d) = (vert(i + 1, j + 1, &mut p), vert(i, j + 1, &mut p));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    TriMesh::from_welded_arrays(p, t).unwrap()
}
