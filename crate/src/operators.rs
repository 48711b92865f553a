//! Discrete differential operators on plain arrays.
//!
//! Inputs are `positions: &[[f64; 3]]` and `triangles: &[[u32; 3]]` (vertex
//! indices, counter-clockwise = outward orientation), so these functions do
//! not depend on the mesh type.  Triangles are assumed valid (indices in
//! range, non-degenerate); a zero-area triangle yields non-finite cotangents.
//!
//! Conventions (Myles & Zorin 2013, sec. 5.2–5.3):
//! * `L` is the positive semi-definite cotangent Laplacian discretizing `−∇²`:
//!   `L = Σ_edges ½(cot α + cot β)(e_i − e_j)(e_i − e_j)ᵀ`, i.e.
//!   `L_ij = −½(cot α_ij + cot β_ij)` for an edge, `L_ii = −Σ_j L_ij`.
//! * `M` is the diagonal barycentric (one-third) lumped mass matrix whose
//!   entries sum to the surface area `A`, as used in `φᵀ(αL + M/A)φ`.
//! * Angle defects: `2π − Σθ` at interior vertices (Gaussian curvature),
//!   `π − Σθ` at boundary vertices (geodesic curvature).

use std::f64::consts::PI;

use crate::vec3::{cross, dot, norm, sub, V3};

#[inline]
fn corners(positions: &[V3], t: &[u32; 3]) -> [V3; 3] {
    [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]]
}

/// For corner `k` of a triangle: the edge vectors from that corner to the
/// next and previous corners.
#[inline]
fn corner_edges(p: &[V3; 3], k: usize) -> (V3, V3) {
    (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]))
}

/// Interior angle (radians, in `[0, π]`) at each corner: `out[f][k]` is the
/// angle of face `f` at vertex `triangles[f][k]` (atan2 form, robust near 0 and π).
pub fn corner_angles(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let p = corners(positions, t);
            let mut a = [0.0; 3];
            for (k, ak) in a.iter_mut().enumerate() {
                let (u, v) = corner_edges(&p, k);
                *ak = norm(cross(u, v)).atan2(dot(u, v));
            }
            a
        })
        .collect()
}

/// Cotangent of each corner angle, laid out like [`corner_angles`]
/// (`cot θ = (u·v)/|u×v|`; infinite for a degenerate triangle).
pub fn corner_cotangents(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let p = corners(positions, t);
            let mut c = [0.0; 3];
            for (k, ck) in c.iter_mut().enumerate() {
                let (u, v) = corner_edges(&p, k);
                *ck = dot(u, v) / norm(cross(u, v));
            }
            c
        })
        .collect()
}

/// Area of each triangle (`½|(p1 − p0) × (p2 − p0)|`).
pub fn face_areas(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    triangles
        .iter()
        .map(|t| {
            let p = corners(positions, t);
            0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])))
        })
        .collect()
}

/// Unit normal of each triangle (right-hand rule on the vertex order);
/// `[0, 0, 0]` for a degenerate triangle.
pub fn face_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let p = corners(positions, t);
            let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            let l = norm(n);
            if l > 0.0 {
                [n[0] / l, n[1] / l, n[2] / l]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// Triplets `(row, col, value)` of the PSD cotangent Laplacian (full
/// symmetric, duplicates *not* summed; size `positions.len()`).  Each face
/// contributes `½ cot θ_k` to the edge opposite corner `k`.
pub fn cotan_laplacian_triplets(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<(usize, usize, f64)> {
    let cots = corner_cotangents(positions, triangles);
    let mut t = Vec::with_capacity(12 * triangles.len());
    for (tri, c) in triangles.iter().zip(&cots) {
        for k in 0..3 {
            let i = tri[(k + 1) % 3] as usize;
            let j = tri[(k + 2) % 3] as usize;
            let w = 0.5 * c[k];
            t.push((i, j, -w));
            t.push((j, i, -w));
            t.push((i, i, w));
            t.push((j, j, w));
        }
    }
    t
}

/// Barycentric lumped vertex areas (the diagonal of `M`): each vertex gets one
/// third of the area of every incident triangle.  Chosen over mixed-Voronoi
/// areas because it is always positive (obtuse triangles included), is the
/// row-sum lumping of the P1 mass matrix, and sums exactly to the surface area
/// `A` as `φᵀ(αL + M/A)φ` requires.  Unreferenced vertices get 0.
pub fn vertex_areas(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut m = vec![0.0; positions.len()];
    for (t, a) in triangles.iter().zip(face_areas(positions, triangles)) {
        for &v in t {
            m[v as usize] += a / 3.0;
        }
    }
    m
}

/// Sum of the corner angles at each vertex (`VA(v)` in the paper).
pub fn angle_sums(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut s = vec![0.0; positions.len()];
    for (t, a) in triangles.iter().zip(corner_angles(positions, triangles)) {
        for k in 0..3 {
            s[t[k] as usize] += a[k];
        }
    }
    s
}

/// Discrete curvature per vertex (paper sec. 5.2): `2π − VA(v)` (Gaussian
/// curvature) at interior vertices, `π − VA(v)` (geodesic curvature) where
/// `is_boundary_vertex[v]`.  Panics if `is_boundary_vertex.len() != positions.len()`.
/// By Gauss–Bonnet the sum over all vertices is `2πχ`.
pub fn angle_defects(positions: &[[f64; 3]], triangles: &[[u32; 3]], is_boundary_vertex: &[bool]) -> Vec<f64> {
    assert_eq!(
        is_boundary_vertex.len(),
        positions.len(),
        "angle_defects: one boundary flag per vertex"
    );
    angle_sums(positions, triangles)
        .into_iter()
        .zip(is_boundary_vertex)
        .map(|(s, &b)| if b { PI - s } else { 2.0 * PI - s })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (nx+1)×(ny+1) grid on [0, nx·h]×[0, ny·h] in the z = 0 plane, split
    /// into triangles with alternating diagonals.
    fn grid(nx: usize, ny: usize, h: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let raw = crate::mesh::shapes::grid(nx, ny, |x, y| [x * nx as f64 * h, y * ny as f64 * h, 0.0]);
        (raw.positions, raw.triangles)
    }

    fn octahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let p = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, t)
    }

    fn icosahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let p = vec![
            [-1.0, g, 0.0],
            [1.0, g, 0.0],
            [-1.0, -g, 0.0],
            [1.0, -g, 0.0],
            [0.0, -1.0, g],
            [0.0, 1.0, g],
            [0.0, -1.0, -g],
            [0.0, 1.0, -g],
            [g, 0.0, -1.0],
            [g, 0.0, 1.0],
            [-g, 0.0, -1.0],
            [-g, 0.0, 1.0],
        ];
        let t = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        (p, t)
    }

    /// `L x` from the triplets of [`cotan_laplacian_triplets`].
    fn matvec(l: &[(usize, usize, f64)], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for &(r, c, v) in l {
            y[r] += v * x[c];
        }
        y
    }

    /// `L` as a dense matrix (rows), duplicates summed.
    fn dense(l: &[(usize, usize, f64)], n: usize) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; n]; n];
        for &(r, c, v) in l {
            d[r][c] += v;
        }
        d
    }

    #[test]
    fn flat_grid_laplacian_mass_and_defects() {
        let (p, t) = grid(6, 5, 0.5);
        let n = p.len();
        let l = cotan_laplacian_triplets(&p, &t);
        // L·1 = 0 everywhere.
        let ones = vec![1.0; n];
        assert!(matvec(&l, &ones).iter().all(|v| v.abs() < 1e-12));
        // L·(linear) = 0 at interior vertices.
        let boundary: Vec<bool> = p.iter().map(|q| q[0] == 0.0 || q[1] == 0.0 || q[0] == 3.0 || q[1] == 2.5).collect();
        let lin: Vec<f64> = p.iter().map(|q| 2.0 * q[0] - 3.0 * q[1] + 0.7).collect();
        let y = matvec(&l, &lin);
        for v in 0..n {
            if !boundary[v] {
                assert!(y[v].abs() < 1e-12, "L·linear at interior vertex {v}: {}", y[v]);
            }
        }
        // PSD sign: diagonal positive, off-diagonal ≤ 0 on this (right-angled) grid.
        for (r, row) in dense(&l, n).iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                if r == c {
                    assert!(v > 0.0);
                } else {
                    assert!(v <= 1e-15);
                }
            }
        }
        // Σ M = area.
        let area = 3.0 * 2.5;
        let m: f64 = vertex_areas(&p, &t).iter().sum();
        assert!((m - area).abs() < 1e-12);
        assert!((face_areas(&p, &t).iter().sum::<f64>() - area).abs() < 1e-12);
        // Angle defects.
        let d = angle_defects(&p, &t, &boundary);
        let corners = [0, 6, n - 7, n - 1];
        for v in 0..n {
            let expect = if corners.contains(&v) { PI / 2.0 } else { 0.0 };
            assert!((d[v] - expect).abs() < 1e-12, "defect at {v} = {}", d[v]);
        }
    }

    #[test]
    fn laplacian_is_symmetric_and_matches_triplets() {
        // A slightly bumpy, non-flat grid to get generic cotangents.
        let (mut p, t) = grid(5, 4, 1.0);
        for (i, q) in p.iter_mut().enumerate() {
            q[2] = 0.3 * ((i * 7 % 5) as f64 - 2.0) / 2.0;
            q[0] += 0.1 * ((i * 3 % 4) as f64 - 1.5);
        }
        let l = cotan_laplacian_triplets(&p, &t);
        let d = dense(&l, p.len());
        for i in 0..p.len() {
            let row_sum: f64 = d[i].iter().sum();
            assert!(row_sum.abs() < 1e-12);
            for j in 0..p.len() {
                assert!((d[i][j] - d[j][i]).abs() < 1e-14);
            }
        }
        // xᵀ L x = Σ w_ij (x_i − x_j)² ≥ 0 for a test vector (sanity of sign).
        let x: Vec<f64> = (0..p.len()).map(|i| (i as f64 * 0.37).sin()).collect();
        let lx = matvec(&l, &x);
        let q: f64 = x.iter().zip(&lx).map(|(a, b)| a * b).sum();
        assert!(q > 0.0);
    }

    #[test]
    fn closed_polyhedra_gauss_bonnet() {
        for (name, (p, t)) in [("octahedron", octahedron()), ("icosahedron", icosahedron())] {
            let b = vec![false; p.len()];
            let d = angle_defects(&p, &t, &b);
            let total: f64 = d.iter().sum();
            assert!((total - 4.0 * PI).abs() < 1e-12, "{name}: Σ defects = {total}");
            let per = 4.0 * PI / p.len() as f64;
            assert!(d.iter().all(|x| (x - per).abs() < 1e-12), "{name}: regular");
            // Σ M = total area; L·1 = 0.
            let area: f64 = face_areas(&p, &t).iter().sum();
            assert!((vertex_areas(&p, &t).iter().sum::<f64>() - area).abs() < 1e-12);
            let l = cotan_laplacian_triplets(&p, &t);
            assert!(matvec(&l, &vec![1.0; p.len()]).iter().all(|v| v.abs() < 1e-12));
        }
    }
}
