//! Synthetic meshes for tests and benchmarks.

use super::RawMesh;

/// An `nx` × `ny` grid of squares over [0, 1]² (vertex `(i, j)` at
/// `embed(i / nx, j / ny)`, index `j (nx + 1) + i`), each square split into
/// two counter-clockwise triangles with alternating diagonals.
pub fn grid(nx: usize, ny: usize, embed: impl Fn(f64, f64) -> [f64; 3]) -> RawMesh {
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            positions.push(embed(i as f64 / nx as f64, j as f64 / ny as f64));
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    RawMesh { positions, triangles }
}

/// A closed cylinder of radius 1 and height `height` around the z axis as a
/// CAD kernel exports it: `n_around` rim vertices at each end (even, at
/// least 4), the side one band of long triangles, each flat cap a zigzag
/// strip of long, thin triangles across the disk (no interior vertex). The
/// rims are the only sharp edges (90°).
pub fn cad_cylinder(n_around: usize, height: f64) -> RawMesh {
    use std::f64::consts::PI;
    assert!(n_around >= 4 && n_around.is_multiple_of(2), "cad_cylinder: an even number of segments, at least 4");
    let n = n_around as u32;
    let positions = [0.0, height]
        .iter()
        .flat_map(|&z| {
            (0..n_around).map(move |i| {
                let a = 2.0 * PI * i as f64 / n_around as f64;
                [a.cos(), a.sin(), z]
            })
        })
        .collect();
    let mut triangles = Vec::new();
    for i in 0..n {
        let (a, b, c, d) = (i, (i + 1) % n, n + (i + 1) % n, n + i);
        triangles.extend([[a, b, c], [a, c, d]]);
    }
    // The strip grows from rim vertex n/2 to either side until it closes at 0.
    let (mut left, mut right) = (n / 2 - 1, n / 2 + 1);
    let mut strip = vec![[left, n / 2, right]];
    while strip.len() < n_around - 2 {
        if strip.len() % 2 == 1 {
            strip.push([left - 1, left, right]);
            left -= 1;
        } else {
            strip.push([left, right, (right + 1) % n]);
            right = (right + 1) % n;
        }
    }
    // On a convex polygon a triangle listed in increasing index order is
    // counter-clockwise: seen from +z on the top cap, from -z reversed.
    for mut t in strip {
        t.sort_unstable();
        triangles.push([t[2], t[1], t[0]]);
        triangles.push(t.map(|v| v + n));
    }
    RawMesh { positions, triangles }
}
