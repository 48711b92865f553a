//! Meshes of several components, solved one component at a time. No
//! constraint of either stage couples two components, so each part gets
//! the whole pipeline of its own ([`super::solve_one`]: its refinements, its
//! cones, the comparison with the unmoved placement, its flip refinements
//! and fallbacks), natively two parts at a time, and the solutions are
//! joined into one on the input ([`Parts::join`]). Solved whole, one part
//! that folds made every part be placed and parametrized again (a game
//! asset of 896 parts: 34 s, against 1.3 s for a quarter of it).

use super::location::ErrorLocation;
use super::{Solution, SolveError, SolveOptions, SolveProgress};
use crate::clock::now_seconds;
use crate::cones::{original_cones, BoundaryMode, ConePlacement, ConeTimings};
use crate::features::{cut_open, FeatureSet, RefineCounts};
use crate::mesh::{TriMesh, NONE};
use crate::param::metrics::Metrics;
use crate::param::{ParamCounts, ParamTimings, Parametrization};
use std::borrow::Cow;

/// One component of the input as a mesh of its own, with its features.
pub struct Part {
    pub mesh: TriMesh,
    pub features: FeatureSet,
    /// Part vertex / face / edge → input vertex / face / edge. Faces keep
    /// their corners in order: halfedge `3 r + i` of the part is halfedge
    /// `3 face[r] + i` of the input.
    vertex: Vec<u32>,
    face: Vec<u32>,
    edge: Vec<u32>,
}

/// The components of a mesh as [`Part`]s, in the order of `face_components`.
pub struct Parts {
    parts: Vec<Part>,
}

/// A halfedge of edge `e` that has a face (`3 f + i`).
fn face_halfedge(mesh: &TriMesh, e: u32) -> u32 {
    let [h, t] = mesh.edge_halfedges(e);
    if mesh.face(h).is_some() {
        h
    } else {
        t
    }
}

impl Parts {
    /// `mesh` split into its components, each with the `features` on it;
    /// `None` for a mesh of one component.
    pub fn split(mesh: &TriMesh, features: &FeatureSet) -> Option<Parts> {
        let n = mesh.n_components();
        if n < 2 {
            return None;
        }
        let mut faces_of = vec![Vec::new(); n];
        for (f, &c) in mesh.face_components().iter().enumerate() {
            faces_of[c as usize].push(f as u32);
        }
        // Every vertex is in one component: one table serves all parts.
        let mut local = vec![NONE; mesh.n_vertices()];
        let parts = faces_of
            .into_iter()
            .map(|face| {
                // A component of a valid mesh is valid.
                let (part, vertex) = mesh.submesh(&face, &mut local)?;
                let edge: Vec<u32> = (0..part.n_edges() as u32)
                    .map(|e| {
                        let h = face_halfedge(&part, e);
                        mesh.edge(3 * face[(h / 3) as usize] + h % 3)
                    })
                    .collect();
                let mut part_features = FeatureSet::none(&part);
                for (e, &o) in edge.iter().enumerate() {
                    if features.contains(o) {
                        part_features.set(&part, e as u32, true);
                    }
                }
                Some(Part { mesh: part, features: part_features, vertex, face, edge })
            })
            .collect::<Option<Vec<Part>>>()?;
        Some(Parts { parts })
    }

    pub fn len(&self) -> usize {
        self.parts.len()
    }

    pub fn part(&self, p: usize) -> &Part {
        &self.parts[p]
    }

    /// Part indices, most faces first.
    fn largest_first(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.parts.len()).collect();
        order.sort_by_key(|&p| std::cmp::Reverse(self.parts[p].mesh.n_faces()));
        order
    }

    /// [`super::solve_one`] on every part: natively on this thread and a
    /// helper (largest parts first; the helper reports no progress), in
    /// wasm one after another. A part's error is returned located on the
    /// input ([`Self::lift_error`]).
    ///
    /// Also returns the wall-clock time over the parts' own times summed,
    /// for [`Self::join`] (below 1 where two parts ran at once).
    pub fn solve_each(&self, options: &SolveOptions, progress: &mut dyn FnMut(SolveProgress)) -> Result<(Vec<Solution<'_>>, f64), SolveError> {
        let started = now_seconds();
        let order = self.largest_first();
        let solve = |p: usize, progress: &mut dyn FnMut(SolveProgress)| {
            let part = &self.parts[p];
            let started = now_seconds();
            let solution = super::solve_one(&part.mesh, &part.features, options, progress);
            (solution, now_seconds() - started)
        };
        let mut results = crate::parallel::share_jobs(&order, |p| solve(p, &mut |_| {}), |p| solve(p, progress), |_| false);
        results.sort_by_key(|r| r.0);
        let summed: f64 = results.iter().map(|r| r.1 .1).sum();
        let wall_share = ((now_seconds() - started) / summed.max(f64::MIN_POSITIVE)).min(1.0);
        let solutions = results.into_iter().map(|(p, (r, _))| r.map_err(|e| self.lift_error(p, e))).collect::<Result<_, _>>()?;
        Ok((solutions, wall_share))
    }

    /// `e`, from solving part `p`, located on the input: its location's
    /// vertices and edges, and the vertices its message names (`v12`),
    /// become input ids. (The cause keeps the part's own elements.)
    pub fn lift_error(&self, p: usize, e: SolveError) -> SolveError {
        let part = &self.parts[p];
        let located = e.located.map(|(location, message)| {
            let location = ErrorLocation {
                vertices: location.vertices.iter().map(|&v| part.vertex[v as usize]).collect(),
                edges: location.edges.iter().map(|&e| part.edge[e as usize]).collect(),
            };
            (location, relabel_vertices(&message, &part.vertex))
        });
        SolveError { cause: e.cause, located }
    }

    /// The solutions of the parts (one per part, in order) joined into one
    /// solution of `mesh` with `features`. Where no part was refined, the
    /// solved mesh is `mesh` itself; else the parts' solved meshes side by
    /// side, with maps to the input composed through the parts'.
    /// `options`: those the parts were solved with (the cut's boundary mode).
    /// The refinement and cone-stage seconds are the parts' summed, times
    /// `wall_share` (wall-clock over summed time, from [`Self::solve_each`];
    /// 1 where the parts ran one after another), so that with the
    /// parametrization's they add up to the wall-clock time.
    pub fn join<'a>(
        &self,
        mesh: &'a TriMesh,
        features: &'a FeatureSet,
        solutions: &[Solution<'_>],
        options: &SolveOptions,
        wall_share: f64,
    ) -> Solution<'a> {
        assert_eq!(solutions.len(), self.parts.len(), "one solution per part");
        let refined = solutions.iter().any(|s| s.original_face.is_some());
        // Joined face -> (part, face of the part's solved mesh).
        let at: Vec<(usize, u32)> = if refined {
            solutions.iter().enumerate().flat_map(|(p, s)| (0..s.mesh.n_faces() as u32).map(move |r| (p, r))).collect()
        } else {
            let mut at = vec![(0, 0); mesh.n_faces()];
            for (p, part) in self.parts.iter().enumerate() {
                for (r, &f) in part.face.iter().enumerate() {
                    at[f as usize] = (p, r as u32);
                }
            }
            at
        };
        let mut joined_face: Vec<Vec<u32>> = solutions.iter().map(|s| vec![NONE; s.mesh.n_faces()]).collect();
        for (f, &(p, r)) in at.iter().enumerate() {
            joined_face[p][r as usize] = f as u32;
        }
        let (solved, solved_features, original_face, original_vertex, original_edge) = if refined {
            let (m, f, of, ov, oe) = self.join_meshes(solutions, &at);
            (Cow::Owned(m), Cow::Owned(f), Some(of), Some(ov), Some(oe))
        } else {
            (Cow::Borrowed(mesh), Cow::Borrowed(features), None, None, None)
        };
        let m: &TriMesh = &solved;
        // Joined edge -> (part, edge of the part's solved mesh).
        let edge_at = |e: u32| {
            let h = face_halfedge(m, e);
            let (p, r) = at[(h / 3) as usize];
            (p, solutions[p].mesh.edge(3 * r + h % 3))
        };
        let mut placement = join_placements(m, &solved_features, solutions, &at, options);
        placement.timings.total *= wall_share;
        let cut = &placement.cut.mesh;
        // Part cut vertex -> joined cut vertex, and the per-corner values.
        let mut cut_vertex: Vec<Vec<u32>> = solutions.iter().map(|s| vec![NONE; s.placement.cut.mesh.n_vertices()]).collect();
        let mut uv = vec![[0.0; 2]; 3 * m.n_faces()];
        for (f, &(p, r)) in at.iter().enumerate() {
            let part_cut = &solutions[p].placement.cut.mesh;
            for i in 0..3 {
                cut_vertex[p][part_cut.faces()[r as usize][i] as usize] = cut.faces()[f][i];
                uv[3 * f + i] = solutions[p].param.uv[3 * r as usize + i];
            }
        }
        let mut seam_edges: Vec<u32> = solutions
            .iter()
            .enumerate()
            .flat_map(|(p, s)| {
                let joined_face = &joined_face[p];
                s.param.seam_edges.iter().map(move |&e| {
                    let h = face_halfedge(&s.mesh, e);
                    m.edge(3 * joined_face[(h / 3) as usize] + h % 3)
                })
            })
            .collect();
        seam_edges.sort_unstable();
        let realized_cones = solutions
            .iter()
            .enumerate()
            .flat_map(|(p, s)| s.param.realized_cones.iter().map(|&(v, k)| (cut_vertex[p][v as usize], k)).collect::<Vec<_>>())
            .collect();
        let parts_metrics: Vec<Metrics> = solutions.iter().map(|s| s.param.metrics.clone()).collect();
        let param = Parametrization {
            metrics: Metrics::join(&parts_metrics, m, &uv),
            uv,
            seam_edges,
            counts: summed!(
                ParamCounts,
                solutions.iter().map(|s| &s.param.counts),
                arap_iterations,
                flips_before_repair,
                flips_fixed,
                repair_rounds,
                refine_iterations,
                untangle_iterations
            ),
            realized_cones,
            timings: summed!(ParamTimings, solutions.iter().map(|s| &s.param.timings), cut, field, poisson, arap, repair, untangle, injective, metrics),
        };
        debug_assert!((0..m.n_edges() as u32).all(|e| {
            let (p, pe) = edge_at(e);
            solved_features.contains(e) == solutions[p].features.contains(pe)
        }));
        let mut refinement = RefineCounts::default();
        for s in solutions {
            refinement.add(&s.refinement);
        }
        Solution {
            mesh: solved,
            features: solved_features,
            splits: solutions.iter().map(|s| s.splits).sum(),
            original_face,
            original_vertex,
            original_edge,
            refinement,
            flip_refinements: solutions.iter().map(|s| s.flip_refinements).max().unwrap_or(0),
            placement,
            param,
            refine_seconds: wall_share * solutions.iter().map(|s| s.refine_seconds).sum::<f64>(),
            // A part's low-poly fallback shows here (as solved, for the next solve).
            refine_options: solutions.iter().map(|s| s.refine_options).find(|r| *r != options.refine).unwrap_or(options.refine),
        }
    }

    /// The parts' solved meshes side by side, in the joined face order `at`,
    /// with their features and the maps to the input (face, vertex, edge).
    #[allow(clippy::type_complexity)]
    fn join_meshes(&self, solutions: &[Solution<'_>], at: &[(usize, u32)]) -> (TriMesh, FeatureSet, Vec<u32>, Vec<u32>, Vec<u32>) {
        let mut offset = Vec::with_capacity(solutions.len() + 1);
        let mut owner = Vec::new();
        let mut positions = Vec::new();
        offset.push(0u32);
        for (p, s) in solutions.iter().enumerate() {
            positions.extend_from_slice(s.mesh.positions());
            owner.extend((0..s.mesh.n_vertices() as u32).map(|v| (p, v)));
            offset.push(positions.len() as u32);
        }
        let triangles: Vec<[u32; 3]> = at.iter().map(|&(p, r)| solutions[p].mesh.faces()[r as usize].map(|v| v + offset[p])).collect();
        let joined = TriMesh::from_welded_arrays(positions, triangles.clone()).expect("components of valid meshes side by side are valid");
        let source = joined.welded_to_source();
        assert!(joined.faces().iter().zip(&triangles).all(|(t, u)| t.map(|v| source[v as usize]) == *u), "faces kept in order");
        let input_vertex = |p: usize, v: u32| {
            let v = solutions[p].original_vertex.as_ref().map_or(v, |ov| ov[v as usize]);
            if v == NONE {
                NONE
            } else {
                self.parts[p].vertex[v as usize]
            }
        };
        let original_vertex = source
            .iter()
            .map(|&s| {
                let (p, v) = owner[s as usize];
                input_vertex(p, v)
            })
            .collect();
        let original_face = at
            .iter()
            .map(|&(p, r)| self.parts[p].face[solutions[p].original_face.as_ref().map_or(r, |of| of[r as usize]) as usize])
            .collect();
        let mut features = FeatureSet::none(&joined);
        let original_edge = (0..joined.n_edges() as u32)
            .map(|e| {
                let h = face_halfedge(&joined, e);
                let (p, r) = at[(h / 3) as usize];
                let s = &solutions[p];
                let pe = s.mesh.edge(3 * r + h % 3);
                if s.features.contains(pe) {
                    features.set(&joined, e, true);
                }
                let pe = s.original_edge.as_ref().map_or(pe, |oe| oe[pe as usize]);
                if pe == NONE {
                    NONE
                } else {
                    self.parts[p].edge[pe as usize]
                }
            })
            .collect();
        (joined, features, original_face, original_vertex, original_edge)
    }
}

/// The parts' placements joined on the joined mesh `m` (faces from the
/// parts as `at` says): the cut made again on `m` (deterministic, the same
/// per component), `k` and `phi` carried over corner by corner, `omega`
/// face by face, cones listed again; figures concatenated, energies and
/// timings summed.
fn join_placements(m: &TriMesh, features: &FeatureSet, solutions: &[Solution<'_>], at: &[(usize, u32)], options: &SolveOptions) -> ConePlacement {
    let mut cut = cut_open(m, features);
    if options.cones.boundary == BoundaryMode::Free {
        cut.free_original_boundary(m);
    }
    let nv = cut.mesh.n_vertices();
    let (mut k, mut phi, mut omega) = (vec![0; nv], vec![0.0; nv], vec![0.0; 3 * m.n_faces()]);
    for (f, &(p, r)) in at.iter().enumerate() {
        let pp = &solutions[p].placement;
        let r = r as usize;
        for i in 0..3 {
            let (cv, pcv) = (cut.mesh.faces()[f][i] as usize, pp.cut.mesh.faces()[r][i] as usize);
            k[cv] = pp.k[pcv];
            phi[cv] = pp.phi[pcv];
            omega[3 * f + i] = pp.omega[3 * r + i];
        }
    }
    let (cones, boundary_corners) = original_cones(m, &cut, &k);
    let areas: Vec<f64> = solutions.iter().map(|s| s.mesh.face_areas().iter().sum()).collect();
    let total_area: f64 = areas.iter().sum();
    let phi2_area: f64 = solutions.iter().zip(&areas).map(|(s, a)| s.placement.phi_rms.powi(2) * a).sum();
    let timings = summed!(ConeTimings, solutions.iter().map(|s| &s.placement.timings), cut, topology, rounding, cone_moves, total);
    ConePlacement {
        cut,
        k,
        phi,
        omega,
        cones,
        boundary_corners,
        components: solutions.iter().flat_map(|s| s.placement.components.iter().cloned()).collect(),
        energy: solutions.iter().map(|s| s.placement.energy).sum(),
        phi_rms: (phi2_area / total_area.max(f64::MIN_POSITIVE)).sqrt(),
        rounds: solutions.iter().map(|s| s.placement.rounds).sum(),
        timings,
    }
}

/// A `$ty` whose every named field is the sum of that field over `$items`
/// (an expression evaluated once per field).
macro_rules! summed {
    ($ty:ident, $items:expr, $($field:ident),+) => {
        $ty { $($field: $items.map(|x| x.$field).sum(),)+ }
    };
}
use summed;

/// `message` with every vertex it names (`v` and digits, after a
/// non-alphanumeric character) renamed through `vertex`.
fn relabel_vertices(message: &str, vertex: &[u32]) -> String {
    let mut out = String::with_capacity(message.len());
    let bytes = message.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i] == b'v' && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric());
        let digits = bytes[i + 1..].iter().take_while(|b| b.is_ascii_digit()).count();
        if starts && digits > 0 {
            let id: Option<u32> = message[i + 1..i + 1 + digits].parse().ok();
            if let Some(&v) = id.and_then(|id| vertex.get(id as usize)) {
                out.push_str(&format!("v{v}"));
                i += 1 + digits;
                continue;
            }
        }
        let c = message[i..].chars().next().expect("inside the string");
        out.push(c);
        i += c.len_utf8();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::three_parts;
    use crate::pipeline::SolveCause;

    /// Each part is its component of the input: positions, faces corner by
    /// corner, edges and features through its maps; a part's error names
    /// input elements.
    #[test]
    fn parts_are_the_components_of_the_input() {
        let mesh = three_parts();
        let mut features = FeatureSet::none(&mesh);
        for e in (0..mesh.n_edges() as u32).step_by(7) {
            features.set(&mesh, e, true);
        }
        let parts = Parts::split(&mesh, &features).expect("three components");
        assert_eq!(parts.len(), 3);
        let mut seen = vec![0; mesh.n_faces()];
        for part in &parts.parts {
            let m = &part.mesh;
            assert_eq!(m.n_components(), 1);
            for (v, &o) in part.vertex.iter().enumerate() {
                assert_eq!(m.position(v as u32), mesh.position(o));
            }
            for (r, &f) in part.face.iter().enumerate() {
                assert_eq!(m.faces()[r].map(|v| part.vertex[v as usize]), mesh.faces()[f as usize]);
                seen[f as usize] += 1;
            }
            for (e, &o) in part.edge.iter().enumerate() {
                let [a, b] = m.edge_vertices(e as u32).map(|v| part.vertex[v as usize]);
                let [c, d] = mesh.edge_vertices(o);
                assert!([a, b] == [c, d] || [a, b] == [d, c]);
                assert_eq!(part.features.contains(e as u32), features.contains(o));
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "every face in one part");
        let e = SolveError {
            cause: SolveCause::Folded { flipped: 1, wound: 0, refinements: 0, faces: vec![0] },
            located: Some((ErrorLocation { vertices: vec![0, 2], edges: vec![1] }, "folds at v0 and v2".into())),
        };
        let lifted = parts.lift_error(1, e);
        let p = &parts.parts[1];
        assert_eq!(lifted.location().unwrap().vertices, vec![p.vertex[0], p.vertex[2]]);
        assert_eq!(lifted.location().unwrap().edges, vec![p.edge[1]]);
        assert_eq!(lifted.to_string(), format!("folds at v{} and v{}", p.vertex[0], p.vertex[2]));
    }

    #[test]
    fn messages_name_input_vertices() {
        let vertex = [7, 8, 9, 40];
        assert_eq!(relabel_vertices("the cone at vertex v3 near (v0, v2), over v12", &vertex), "the cone at vertex v40 near (v7, v9), over v12");
        assert_eq!(relabel_vertices("v1v2 ēv0", &vertex), "v8v2 ēv7");
    }
}
