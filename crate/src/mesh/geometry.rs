//! The geometry of a [`TriMesh`]: every per-mesh quantity later stages read
//! (corner angles and cotangents, face areas, normals and tangent frames,
//! vertex areas, angle sums and defects, dihedral angles, the cotangent
//! Laplacian), each computed on first use and cached with the mesh, as
//! geometry-central's `requireX()` does. Connectivity is [`TriMesh`]'s; the
//! formulas on positions live here and nowhere else.
//!
//! Conventions (Myles & Zorin 2013, sec. 5.2–5.3):
//! * `L` is the positive semi-definite cotangent Laplacian discretizing `−∇²`:
//!   `L = Σ_edges ½(cot α + cot β)(e_i − e_j)(e_i − e_j)ᵀ`, i.e.
//!   `L_ij = −½(cot α_ij + cot β_ij)` for an edge, `L_ii = −Σ_j L_ij`.
//! * `M` is the diagonal barycentric (one-third) lumped mass matrix whose
//!   entries sum to the surface area `A`, as used in `φᵀ(αL + M/A)φ`.
//! * Angle defects: `2π − Σθ` at interior vertices (Gaussian curvature),
//!   `π − Σθ` at boundary vertices (geodesic curvature).
//! * Face `f`'s tangent frame: x along its first halfedge, y = n × x.
//!
//! A `TriMesh` is immutable, so a cached value never goes stale; the cache
//! is `Sync` (`OnceLock`), so a mesh can be shared between threads.

use std::f64::consts::PI;
use std::sync::OnceLock;

use super::TriMesh;
use crate::vec3::{cross, dot, norm, scale, sub, V3};

/// The lazily filled quantities of one mesh (see the accessors on [`TriMesh`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct GeometryCache {
    corner_angles: OnceLock<Vec<[f64; 3]>>,
    corner_cotangents: OnceLock<Vec<[f64; 3]>>,
    face_areas: OnceLock<Vec<f64>>,
    face_normals: OnceLock<Vec<V3>>,
    face_frames: OnceLock<FaceFrames>,
    vertex_areas: OnceLock<Vec<f64>>,
    angle_sums: OnceLock<Vec<f64>>,
    angle_defects: OnceLock<Vec<f64>>,
    dihedral_angles: OnceLock<Vec<f64>>,
}

/// Orthonormal tangent frame of every face: x along the face's first
/// halfedge, y = n × x (n the unit normal of the face's vertex order).
#[derive(Clone, Debug)]
pub struct FaceFrames {
    x: Vec<V3>,
    y: Vec<V3>,
}

impl FaceFrames {
    fn new(mesh: &TriMesh) -> FaceFrames {
        let nf = mesh.n_faces();
        let (mut x, mut y) = (Vec::with_capacity(nf), Vec::with_capacity(nf));
        for f in 0..nf as u32 {
            let (e0, e1) = first_edges(mesh, f);
            let n = cross(e0, e1);
            let xa = scale(e0, 1.0 / norm(e0));
            let na = scale(n, 1.0 / norm(n));
            x.push(xa);
            y.push(cross(na, xa));
        }
        FaceFrames { x, y }
    }

    /// Angle of tangent vector `d` in the frame of face `f`.
    #[inline]
    pub fn angle(&self, f: u32, d: V3) -> f64 {
        let (x, y) = (self.x[f as usize], self.y[f as usize]);
        dot(d, y).atan2(dot(d, x))
    }
}

/// Wraps an angle to (-π, π].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let mut r = a % (2.0 * PI);
    if r <= -PI {
        r += 2.0 * PI;
    } else if r > PI {
        r -= 2.0 * PI;
    }
    r
}

/// The vectors of face `f`'s halfedges 0 and 1 (corner 0 → 1, corner 1 → 2).
#[inline]
fn first_edges(mesh: &TriMesh, f: u32) -> (V3, V3) {
    let [h0, h1, _] = mesh.face_halfedges(f);
    (mesh.halfedge_vector(h0), mesh.halfedge_vector(h1))
}

/// For corner `k` of face `f`: the edge vectors from that corner to the
/// next and previous corners.
#[inline]
fn corner_edges(mesh: &TriMesh, f: u32, k: usize) -> (V3, V3) {
    let t = mesh.faces()[f as usize];
    let p = mesh.position(t[k]);
    (sub(mesh.position(t[(k + 1) % 3]), p), sub(mesh.position(t[(k + 2) % 3]), p))
}

fn per_corner(mesh: &TriMesh, value: impl Fn(V3, V3) -> f64) -> Vec<[f64; 3]> {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            [0, 1, 2].map(|k| {
                let (u, v) = corner_edges(mesh, f, k);
                value(u, v)
            })
        })
        .collect()
}

impl TriMesh {
    /// Interior angle (radians, in `[0, π]`) at each corner: `[f][k]` is the
    /// angle of face `f` at vertex `faces()[f][k]` (atan2 form, robust near 0 and π).
    pub fn corner_angles(&self) -> &[[f64; 3]] {
        self.geometry.corner_angles.get_or_init(|| per_corner(self, crate::vec3::angle))
    }

    /// Cotangent of each corner angle, laid out like [`TriMesh::corner_angles`]
    /// (`cot θ = (u·v)/|u×v|`).
    pub fn corner_cotangents(&self) -> &[[f64; 3]] {
        self.geometry.corner_cotangents.get_or_init(|| per_corner(self, |u, v| dot(u, v) / norm(cross(u, v))))
    }

    /// Area of each face, `½|e0 × e1|` for its first two halfedges (positive:
    /// a `TriMesh` has no zero-area face).
    pub fn face_areas(&self) -> &[f64] {
        self.geometry.face_areas.get_or_init(|| {
            (0..self.n_faces() as u32)
                .map(|f| {
                    let (e0, e1) = first_edges(self, f);
                    0.5 * norm(cross(e0, e1))
                })
                .collect()
        })
    }

    /// Unit normal of each face (right-hand rule on its vertex order).
    pub fn face_normals(&self) -> &[V3] {
        self.geometry.face_normals.get_or_init(|| {
            self.faces()
                .iter()
                .map(|t| {
                    let p0 = self.position(t[0]);
                    let n = cross(sub(self.position(t[1]), p0), sub(self.position(t[2]), p0));
                    let l = norm(n);
                    [n[0] / l, n[1] / l, n[2] / l]
                })
                .collect()
        })
    }

    /// The tangent frame of every face (see [`FaceFrames`]).
    pub fn face_frames(&self) -> &FaceFrames {
        self.geometry.face_frames.get_or_init(|| FaceFrames::new(self))
    }

    /// Length of edge `e`.
    pub fn edge_length(&self, e: u32) -> f64 {
        let [a, b] = self.edge_vertices(e);
        norm(sub(self.position(a), self.position(b)))
    }

    /// Length of the diagonal of the axis-aligned bounding box (0 for an empty mesh).
    pub fn bounding_diagonal(&self) -> f64 {
        if self.n_vertices() == 0 {
            return 0.0;
        }
        let (lo, hi) = crate::vec3::bounds(self.positions());
        norm(sub(hi, lo))
    }

    /// Angle of halfedge `h`'s direction in the frame of face `h / 3`
    /// (`h` a face halfedge).
    #[inline]
    pub fn halfedge_angle(&self, h: u32) -> f64 {
        self.face_frames().angle(h / 3, self.halfedge_vector(h))
    }

    /// Frame rotation `kappa` crossing the edge of face halfedge `h` from its
    /// face to the twin's face: `angle_g(d) − angle_f(d)` for the edge
    /// direction `d`, wrapped to (-π, π]. Requires an interior edge.
    #[inline]
    pub fn kappa(&self, h: u32) -> f64 {
        let [h0, h1] = self.edge_halfedges(self.edge(h));
        // The twin runs the other way: its angle is the edge's plus π.
        // Computed once per edge so kappa(twin) = −kappa exactly, even at ±π.
        let k = wrap_angle(self.halfedge_angle(h1) - PI - self.halfedge_angle(h0));
        if h == h0 {
            k
        } else {
            -k
        }
    }

    /// Barycentric lumped vertex areas (the diagonal of `M`): each vertex gets
    /// one third of the area of every incident face. Chosen over
    /// mixed-Voronoi areas because it is always positive (obtuse triangles
    /// included), is the row-sum lumping of the P1 mass matrix, and sums
    /// exactly to the surface area `A` as `φᵀ(αL + M/A)φ` requires.
    pub fn vertex_areas(&self) -> &[f64] {
        self.geometry.vertex_areas.get_or_init(|| {
            let mut m = vec![0.0; self.n_vertices()];
            for (t, a) in self.faces().iter().zip(self.face_areas()) {
                for &v in t {
                    m[v as usize] += a / 3.0;
                }
            }
            m
        })
    }

    /// Sum of the corner angles at each vertex (`VA(v)` in the paper), summed
    /// in face order.
    pub fn angle_sums(&self) -> &[f64] {
        self.geometry.angle_sums.get_or_init(|| {
            let mut s = vec![0.0; self.n_vertices()];
            for (t, a) in self.faces().iter().zip(self.corner_angles()) {
                for k in 0..3 {
                    s[t[k] as usize] += a[k];
                }
            }
            s
        })
    }

    /// Discrete curvature per vertex (paper sec. 5.2): `2π − VA(v)` (Gaussian
    /// curvature) at interior vertices, `π − VA(v)` (geodesic curvature) at
    /// boundary vertices. By Gauss–Bonnet the sum is `2πχ`.
    pub fn angle_defects(&self) -> &[f64] {
        self.geometry.angle_defects.get_or_init(|| {
            let sums = self.angle_sums();
            (0..self.n_vertices() as u32)
                .map(|v| if self.is_boundary_vertex(v) { PI } else { 2.0 * PI } - sums[v as usize])
                .collect()
        })
    }

    /// Angle between the normals of the two faces of each edge, in `[0, π]`
    /// (0 for a flat edge); 0 on boundary edges.
    pub fn dihedral_angles(&self) -> &[f64] {
        self.geometry.dihedral_angles.get_or_init(|| {
            let normals = self.face_normals();
            (0..self.n_edges() as u32)
                .map(|e| {
                    let [h, t] = self.edge_halfedges(e);
                    match (self.face(h), self.face(t)) {
                        (Some(f), Some(g)) => dot(normals[f as usize], normals[g as usize]).clamp(-1.0, 1.0).acos(),
                        _ => 0.0,
                    }
                })
                .collect()
        })
    }

    /// Triplets `(row, col, value)` of the PSD cotangent Laplacian on `faces`
    /// (full symmetric, duplicates *not* summed, vertex indices of the whole
    /// mesh), in the order of `faces`: each face adds `½ cot θ_k` to the edge
    /// opposite its corner `k`.
    pub fn cotan_laplacian_triplets(&self, faces: impl IntoIterator<Item = u32>) -> Vec<(usize, usize, f64)> {
        let cots = self.corner_cotangents();
        let mut out = Vec::new();
        for f in faces {
            let (tri, c) = (self.faces()[f as usize], cots[f as usize]);
            for k in 0..3 {
                let i = tri[(k + 1) % 3] as usize;
                let j = tri[(k + 2) % 3] as usize;
                let w = 0.5 * c[k];
                out.extend([(i, j, -w), (j, i, -w), (i, i, w), (j, j, w)]);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::mesh::shapes;
    use crate::TriMesh;
    use std::f64::consts::PI;

    fn mesh(p: Vec<[f64; 3]>, t: Vec<[u32; 3]>) -> TriMesh {
        TriMesh::from_welded_arrays(p, t).unwrap()
    }

    /// (nx+1)×(ny+1) grid on [0, nx·h]×[0, ny·h] in the z = 0 plane, split
    /// into triangles with alternating diagonals; `bump` moves each vertex.
    fn grid(nx: usize, ny: usize, h: f64, bump: impl Fn(usize, [f64; 3]) -> [f64; 3]) -> TriMesh {
        let raw = shapes::grid(nx, ny, |x, y| [x * nx as f64 * h, y * ny as f64 * h, 0.0]);
        let p = raw.positions.iter().enumerate().map(|(i, &q)| bump(i, q)).collect();
        mesh(p, raw.triangles)
    }

    fn octahedron() -> TriMesh {
        let p = vec![[1., 0., 0.], [-1., 0., 0.], [0., 1., 0.], [0., -1., 0.], [0., 0., 1.], [0., 0., -1.]];
        let t = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        mesh(p, t)
    }

    fn icosahedron() -> TriMesh {
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
        mesh(p, t)
    }

    fn laplacian(m: &TriMesh) -> Vec<(usize, usize, f64)> {
        m.cotan_laplacian_triplets(0..m.n_faces() as u32)
    }

    /// `L x` from triplets.
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
        let m = grid(6, 5, 0.5, |_, q| q);
        let n = m.n_vertices();
        let l = laplacian(&m);
        assert!(matvec(&l, &vec![1.0; n]).iter().all(|v| v.abs() < 1e-12), "L·1 = 0");
        let lin: Vec<f64> = m.positions().iter().map(|q| 2.0 * q[0] - 3.0 * q[1] + 0.7).collect();
        let y = matvec(&l, &lin);
        for v in 0..n as u32 {
            if !m.is_boundary_vertex(v) {
                assert!(y[v as usize].abs() < 1e-12, "L·linear at interior vertex {v}: {}", y[v as usize]);
            }
        }
        // PSD sign: diagonal positive, off-diagonal ≤ 0 on this (right-angled) grid.
        for (r, row) in dense(&l, n).iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                assert!(if r == c { v > 0.0 } else { v <= 1e-15 });
            }
        }
        let area = 3.0 * 2.5;
        assert!((m.vertex_areas().iter().sum::<f64>() - area).abs() < 1e-12);
        assert!((m.face_areas().iter().sum::<f64>() - area).abs() < 1e-12);
        // The four corners turn by π/2; every other boundary vertex is straight.
        for v in 0..n {
            let q = m.position(v as u32);
            let corner = (q[0] == 0.0 || q[0] == 3.0) && (q[1] == 0.0 || q[1] == 2.5);
            let expect = if corner { PI / 2.0 } else { 0.0 };
            assert!((m.angle_defects()[v] - expect).abs() < 1e-12, "defect at {v} = {}", m.angle_defects()[v]);
        }
        assert!(m.dihedral_angles().iter().all(|&d| d.abs() < 1e-7), "a plane has no creases");
    }

    #[test]
    fn laplacian_is_symmetric_with_zero_row_sums() {
        // A bumpy, non-flat grid for generic cotangents.
        let m = grid(5, 4, 1.0, |i, q| [q[0] + 0.1 * ((i * 3 % 4) as f64 - 1.5), q[1], 0.3 * ((i * 7 % 5) as f64 - 2.0) / 2.0]);
        let n = m.n_vertices();
        let d = dense(&laplacian(&m), n);
        for i in 0..n {
            assert!(d[i].iter().sum::<f64>().abs() < 1e-12);
            for j in 0..n {
                assert!((d[i][j] - d[j][i]).abs() < 1e-14);
            }
        }
        // xᵀ L x = Σ w_ij (x_i − x_j)² > 0 for a non-constant vector.
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let q: f64 = x.iter().zip(matvec(&laplacian(&m), &x)).map(|(a, b)| a * b).sum();
        assert!(q > 0.0);
    }

    #[test]
    fn closed_polyhedra_gauss_bonnet() {
        for (name, m) in [("octahedron", octahedron()), ("icosahedron", icosahedron())] {
            let d = m.angle_defects();
            let total: f64 = d.iter().sum();
            assert!((total - 4.0 * PI).abs() < 1e-12, "{name}: Σ defects = {total}");
            let per = 4.0 * PI / m.n_vertices() as f64;
            assert!(d.iter().all(|x| (x - per).abs() < 1e-12), "{name}: regular");
            let area: f64 = m.face_areas().iter().sum();
            assert!((m.vertex_areas().iter().sum::<f64>() - area).abs() < 1e-12);
            assert!(matvec(&laplacian(&m), &vec![1.0; m.n_vertices()]).iter().all(|v| v.abs() < 1e-12));
        }
        // The octahedron's faces meet at the supplement of acos(-1/3).
        let expect = PI - (-1.0f64 / 3.0).acos();
        assert!(octahedron().dihedral_angles().iter().all(|&d| (d - expect).abs() < 1e-12));
    }

    #[test]
    fn frames_are_orthonormal_and_kappa_is_antisymmetric() {
        let m = icosahedron();
        for f in 0..m.n_faces() as u32 {
            let [h0, h1, _] = m.face_halfedges(f);
            assert!(m.halfedge_angle(h0).abs() < 1e-15, "x runs along the first halfedge");
            // y = n × x: the second halfedge turns left by the exterior angle at corner 1.
            let turn = m.halfedge_angle(h1) - (PI - m.corner_angles()[f as usize][1]);
            assert!(turn.abs() < 1e-12, "face {f}: second halfedge off by {turn}");
        }
        for h in 0..m.n_halfedges() as u32 {
            assert_eq!(m.kappa(h), -m.kappa(m.twin(h)));
        }
    }
}
