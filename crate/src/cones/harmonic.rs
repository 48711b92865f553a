//! The harmonic part of the connection (eq. 12): one closed, co-closed
//! 1-form `eta_l` per leftover edge `l` of the tree-cotree decomposition.
//!
//! `eta_l = d u_l` for a Crouzeix-Raviart function `u_l` (one value per edge
//! midpoint and face side) that jumps by the cocycle `s_l` across the edges
//! of `l`'s primal fundamental loop, takes the value `-s_l` on boundary edges
//! (the outer node has value 0, so `eta_l` has no tangential part along the
//! boundary) and is harmonic for the CR Dirichlet energy. All `n_h` forms
//! share one sparse Cholesky factorization.

use super::dual_tree::{orientation, DualTree};
use super::dual_path::Visit;
use crate::linalg::{LinalgError, SparseSpd, Triplet};
use crate::mesh::{TriMesh, NONE};
use crate::vec3::{cross, dot};

/// Harmonic basis forms of one component, stored as CR values per face
/// halfedge: `u[i][h]` is the value of `u_i` at the midpoint of halfedge `h`
/// seen from `h`'s face.
#[derive(Clone, Debug)]
pub struct HarmonicBasis {
    pub u: Vec<Vec<f64>>,
    /// Gram matrix `M_1[i][j] = <eta_i, eta_j>` (L2 inner product of 1-forms).
    pub gram: Vec<Vec<f64>>,
}

impl HarmonicBasis {
    /// Computes the forms for the leftovers of `tree`.
    pub fn new(mesh: &TriMesh, tree: &DualTree) -> Result<HarmonicBasis, LinalgError> {
        let n_h = tree.leftovers.len();
        if n_h == 0 {
            return Ok(HarmonicBasis { u: Vec::new(), gram: Vec::new() });
        }
        let cot = mesh.corner_cotangents();
        // Unknowns: one per interior edge of the component (value on the side
        // of edge_halfedges(e)[0]); on a closed component the first is pinned.
        let mut unknown = vec![NONE; mesh.n_edges()];
        let mut n_unknowns = 0usize;
        let mut pinned = !tree.has_boundary;
        for &f in &tree.faces {
            for h in mesh.face_halfedges(f) {
                let e = mesh.edge(h);
                if !mesh.is_boundary_edge(e) && unknown[e as usize] == NONE {
                    if pinned {
                        pinned = false;
                        unknown[e as usize] = NONE - 1; // pinned to zero
                        continue;
                    }
                    unknown[e as usize] = n_unknowns as u32;
                    n_unknowns += 1;
                }
            }
        }
        // CR stiffness: sum over faces and pairs of halfedges (a, b) of
        // cot(angle at their shared corner) (u_a - u_b)^2.
        let pairs = |f: u32| {
            let [h0, h1, h2] = mesh.face_halfedges(f);
            let c = cot[f as usize];
            // Halfedges k and k+1 share corner k+1.
            [(h0, h1, c[1]), (h1, h2, c[2]), (h2, h0, c[0])]
        };
        let var = |h: u32| {
            let e = mesh.edge(h);
            let x = unknown[e as usize];
            if x < NONE - 1 {
                Some(x as usize)
            } else {
                None
            }
        };
        let mut triplets: Vec<Triplet> = Vec::new();
        for &f in &tree.faces {
            for (a, b, w) in pairs(f) {
                let (ia, ib) = (var(a), var(b));
                if let Some(i) = ia {
                    triplets.push((i, i, w));
                }
                if let Some(j) = ib {
                    triplets.push((j, j, w));
                }
                if let (Some(i), Some(j)) = (ia, ib) {
                    if i != j {
                        triplets.push((i.min(j), i.max(j), -w));
                    }
                }
            }
        }
        let mut u_all = Vec::with_capacity(n_h);
        if n_unknowns > 0 {
            let solver = SparseSpd::from_triplets(n_unknowns, &triplets)?;
            for &l in &tree.leftovers {
                let offset = cocycle_offsets(mesh, tree, l);
                // Side value: u[h] = x_e + offset[h] (offset holds jumps and boundary values).
                let mut rhs = vec![0.0; n_unknowns];
                for &f in &tree.faces {
                    for (a, b, w) in pairs(f) {
                        let d = offset[a as usize] - offset[b as usize];
                        if let Some(i) = var(a) {
                            rhs[i] -= w * d;
                        }
                        if let Some(j) = var(b) {
                            rhs[j] += w * d;
                        }
                    }
                }
                let x = solver.solve(&rhs)?;
                let mut u = offset;
                for &f in &tree.faces {
                    for h in mesh.face_halfedges(f) {
                        if let Some(i) = var(h) {
                            u[h as usize] += x[i];
                        }
                    }
                }
                u_all.push(u);
            }
        } else {
            for &l in &tree.leftovers {
                u_all.push(cocycle_offsets(mesh, tree, l));
            }
        }
        let gram = gram_matrix(mesh, tree, &u_all);
        Ok(HarmonicBasis { u: u_all, gram })
    }

    /// Number of basis forms.
    pub fn len(&self) -> usize {
        self.u.len()
    }

    /// True when the component has no harmonic forms (a topological disk).
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// Value of `eta_i` on the midline segment of `visit`.
    #[inline]
    pub fn segment(&self, i: usize, visit: Visit) -> f64 {
        self.u[i][visit.h_out as usize] - self.u[i][visit.h_in as usize]
    }

    /// Integral of `eta_i` along a dual path (eq. 13).
    pub fn path_integral(&self, i: usize, path: &[Visit]) -> f64 {
        path.iter().map(|&v| self.segment(i, v)).sum()
    }
}

/// Per face halfedge, the part of `u` fixed by the cocycle of leftover `l`:
/// on interior edges of the loop the jump (on the side of the edge's second
/// halfedge), on boundary edges of the loop the Dirichlet value `-s`.
fn cocycle_offsets(mesh: &TriMesh, tree: &DualTree, l: u32) -> Vec<f64> {
    let mut offset = vec![0.0; 3 * mesh.n_faces()];
    let [a, b] = mesh.edge_vertices(l);
    // Primal loop: l from a to b (sign of edge_halfedges(l)[0], which runs a -> b),
    // then the T_p path from b back to a.
    let h_l = mesh.edge_halfedges(l)[0];
    debug_assert_eq!((mesh.tail(h_l), mesh.head(h_l)), (a, b));
    let mut loop_edges = vec![(l, 1)];
    loop_edges.extend(tree.primal_path(mesh, b, a));
    for (e, s) in loop_edges {
        let [h0, h1] = mesh.edge_halfedges(e);
        if mesh.is_boundary_halfedge(h1) {
            offset[h0 as usize] = -(s as f64);
        } else {
            offset[h1 as usize] += s as f64;
        }
    }
    let _ = orientation; // sign convention shared with DualTree::primal_path
    offset
}

/// Faces per block of [`gram_matrix`] (bounds its scratch matrix).
const GRAM_BLOCK: usize = 1024;

/// `M_1[a][b] = <d u_a, d u_b>` in L2 over the component's faces, as
/// `Bᵀ B` over blocks of faces (`B`: the gradients times `sqrt(area)`, one
/// column per form), so each gradient is computed once: `n_h` gradients per
/// face and one dense product, not `n_h²` (components cut by many feature
/// loops have hundreds of forms: bff-bunny at `--sharp 30` spent minutes here).
fn gram_matrix(mesh: &TriMesh, tree: &DualTree, u: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n_h = u.len();
    let mut gram = nalgebra::DMatrix::<f64>::zeros(n_h, n_h);
    for block in tree.faces.chunks(GRAM_BLOCK) {
        let mut b = nalgebra::DMatrix::<f64>::zeros(3 * block.len(), n_h);
        for (r, &f) in block.iter().enumerate() {
            let s = mesh.face_areas()[f as usize].sqrt();
            for (j, uj) in u.iter().enumerate() {
                let g = cr_gradient(mesh, f, uj);
                for k in 0..3 {
                    b[(3 * r + k, j)] = s * g[k];
                }
            }
        }
        gram += b.tr_mul(&b);
    }
    (0..n_h).map(|i| (0..n_h).map(|j| gram[(i, j)]).collect()).collect()
}

/// Gradient in face `f` of the linear function with midpoint values `u[3f..3f+3]`.
pub fn cr_gradient(mesh: &TriMesh, f: u32, u: &[f64]) -> [f64; 3] {
    let [h0, h1, h2] = mesh.face_halfedges(f);
    let (u0, u1, u2) = (u[h0 as usize], u[h1 as usize], u[h2 as usize]);
    // Vertex values of the linear function: midpoint k lies between corners k and k+1.
    let phi = [u0 - u1 + u2, u0 + u1 - u2, -u0 + u1 + u2];
    p1_gradient(mesh, f, phi)
}

/// Gradient in face `f` of the linear function with corner values `phi`.
pub fn p1_gradient(mesh: &TriMesh, f: u32, phi: [f64; 3]) -> [f64; 3] {
    let hs = mesh.face_halfedges(f);
    let n = cross(mesh.halfedge_vector(hs[0]), mesh.halfedge_vector(hs[1]));
    let nn = dot(n, n); // (2 area)^2
    let mut g = [0.0; 3];
    for k in 0..3 {
        // grad lambda_k = n x e_k / (2A)^2 * |n| ... with e_k the edge opposite corner k.
        let e = mesh.halfedge_vector(hs[(k + 1) % 3]);
        let c = cross(n, e);
        for i in 0..3 {
            g[i] += phi[k] * c[i] / nn;
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::dual_path::vertex_cycle;
    use crate::cones::test_meshes::{square_annulus, torus};

    fn check(mesh: &TriMesh) {
        let tree = DualTree::new(mesh, 0, &[]);
        let basis = HarmonicBasis::new(mesh, &tree).unwrap();
        assert_eq!(basis.len(), tree.leftovers.len());
        // Closed: every vertex cycle integral vanishes.
        for &v in &tree.vertices {
            let cycle = vertex_cycle(mesh, v);
            for i in 0..basis.len() {
                let s = basis.path_integral(i, &cycle);
                assert!(s.abs() < 1e-12, "vertex {v}, form {i}: {s}");
            }
        }
        // Dual to the leftover cycles: B_h = ±identity.
        for (i, &l) in tree.leftovers.iter().enumerate() {
            let cycle = tree.fundamental_cycle(mesh, l);
            for j in 0..basis.len() {
                let s = basis.path_integral(j, &cycle);
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((s.abs() - expected).abs() < 1e-12, "cycle {i}, form {j}: {s}");
            }
        }
        // Co-closed: orthogonal to every conformal form *d phi, i.e. the CR
        // Laplacian residual vanishes; check through the Gram matrix being SPD.
        for i in 0..basis.len() {
            assert!(basis.gram[i][i] > 0.0);
        }
    }

    #[test]
    fn torus_forms_are_closed_and_dual_to_the_homology_loops() {
        check(&torus(10, 7, 2.0, 0.6));
    }

    #[test]
    fn annulus_form_is_closed_and_dual_to_the_alignment_path() {
        check(&square_annulus(3, 3, 0.4, 0.3));
    }
}
