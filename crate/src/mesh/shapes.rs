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
    assert!(n_around >= 4 && n_around.is_multiple_of(2), "cad_cylinder: an even number of segments, at least 4");
    let n = n_around as u32;
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
    // counter-clockwise.
    cylinder_with_caps(n_around, height, strip.into_iter().map(|mut t| {
        t.sort_unstable();
        t
    }))
}

/// [`cad_cylinder`] with each cap a fan of triangles from its first rim
/// vertex instead of a zigzag strip, as many exporters write a polygon
/// (the page tests' OBJ, `scripts/lib/cad-cylinder.mjs`); `n_around` at
/// least 3.
pub fn fan_capped_cylinder(n_around: usize, height: f64) -> RawMesh {
    assert!(n_around >= 3, "fan_capped_cylinder: at least 3 segments");
    cylinder_with_caps(n_around, height, (1..n_around as u32 - 1).map(|i| [0, i, i + 1]))
}

/// The closed cylinder of [`cad_cylinder`] with caps triangulated by `cap`:
/// triangles over rim indices `0..n_around`, counter-clockwise seen from +z
/// (the top cap as given, the bottom one reversed).
fn cylinder_with_caps(n_around: usize, height: f64, cap: impl Iterator<Item = [u32; 3]>) -> RawMesh {
    use std::f64::consts::PI;
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
    for t in cap {
        triangles.push([t[2], t[1], t[0]]);
        triangles.push(t.map(|v| v + n));
    }
    RawMesh { positions, triangles }
}

/// The closed surface of an `nx` × `ny` × `nz` block of unit cubes with the
/// columns `holes` (cube `(i, j)`, all `k`) removed: a block with through
/// holes of genus `holes.len()` (when no two touch each other or the sides),
/// every cube face two triangles, as a voxel or CAD export gives it.
pub fn voxel_block(nx: usize, ny: usize, nz: usize, holes: &[(usize, usize)]) -> RawMesh {
    let filled = |c: [i64; 3]| {
        let inside = c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < nx as i64 && c[1] < ny as i64 && c[2] < nz as i64;
        inside && !holes.contains(&(c[0] as usize, c[1] as usize))
    };
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |p: [i64; 3]| {
        *index.entry(p).or_insert_with(|| {
            positions.push(p.map(|c| c as f64));
            (positions.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for (i, j, k) in (0..nx).flat_map(|i| (0..ny).flat_map(move |j| (0..nz).map(move |k| (i, j, k)))) {
        let cube = [i as i64, j as i64, k as i64];
        if !filled(cube) {
            continue;
        }
        for axis in 0..3 {
            for side in [-1i64, 1] {
                let mut next = cube;
                next[axis] += side;
                if filled(next) {
                    continue;
                }
                // The face's corners counter-clockwise seen from outside.
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut origin = cube;
                origin[axis] += (side + 1) / 2;
                let mut corners = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(du, dv)| {
                    let mut p = origin;
                    p[u] += du;
                    p[v] += dv;
                    vertex(p)
                });
                if side < 0 {
                    corners.reverse();
                }
                triangles.extend([[corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]]);
            }
        }
    }
    RawMesh { positions, triangles }
}
