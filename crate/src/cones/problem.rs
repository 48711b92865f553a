//! Cone placement split by component: the cut mesh's components are
//! independent problems (section 5: features cut the surface open, and each
//! component gets its own system). A [`ConeProblem`] is built once;
//! [`ConeProblem::place_component`] can then run for different components on
//! different threads or in different wasm instances (its result serializes),
//! and [`ConeProblem::assemble`] joins the results into a [`ConePlacement`].

use super::dual_path::{segment_phi_coefficients, Visit};
use super::system::{ComponentSystem, Weights};
use super::{original_cones, BoundaryMode, ComponentFigures, ConeError, ConeOptions, ConePlacement, ConeTimings, ConeProgress};
use crate::clock::Stopwatch;
use crate::features::{boundary_turning, cut_open, CutMesh, FeatureSet};
use crate::mesh::{decimate_interior, TriMesh, NONE};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Everything the components' placements share: the mesh cut open along the
/// features (with its geometry), boundary turning integers and the options.
#[derive(Clone, Debug)]
pub struct ConeProblem {
    cut: CutMesh,
    boundary_k: Vec<i32>,
    /// One face of every component.
    seeds: Vec<u32>,
    options: ConeOptions,
    /// Seconds spent cutting the mesh open.
    cut_seconds: f64,
}

/// The placement of one component: its vertices' integers and `phi`, its
/// faces' `omega`, figures and timings. Self-contained, so it can travel
/// between wasm instances as JSON ([`ComponentPlacement::to_json`]).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ComponentPlacement {
    pub component: usize,
    /// Cut-mesh vertices of the component, with `k` and `phi` of each.
    pub vertices: Vec<u32>,
    pub k: Vec<i32>,
    pub phi: Vec<f64>,
    /// Faces of the component, with `omega` of their 3 midline segments each.
    pub faces: Vec<u32>,
    pub omega: Vec<f64>,
    pub figures: ComponentFigures,
    /// `phiᵀ(alpha L + M/A) phi` of the component, `|phi|²` times its area, its area.
    pub energy: f64,
    pub phi2_area: f64,
    pub area: f64,
    /// Seconds: building the system, rounding, cone moves and clean-up.
    pub topology_seconds: f64,
    pub rounding_seconds: f64,
    pub moves_seconds: f64,
}

/// Each level of the coarse-to-fine placement has at most this fraction of
/// the interior vertices of the next finer one.
const COARSENING: usize = 4;

/// The steps after the integers are fixed: cone moves and the clean-ups
/// (pair merging, pair cancellation, spreading of cones above index 3).
/// Returns (moves, merged pairs, cancelled pairs, quarter turns spread).
fn improve(
    sys: &mut ComponentSystem,
    options: &ConeOptions,
    c: usize,
    progress: &mut dyn FnMut(ConeProgress),
) -> Result<(usize, usize, usize, usize), ConeError> {
    let move_cones = |sys: &mut ComponentSystem, progress: &mut dyn FnMut(ConeProgress)| {
        sys.optimize_locations(options.max_move_passes, options.max_cone_index, &mut |pass, tried, cones| {
            progress(ConeProgress::ConeMoves { component: c, pass, tried, cones })
        })
    };
    let moves = if options.optimize_locations { move_cones(sys, progress)? } else { 0 };
    let merged = if options.merge_close_pairs { sys.merge_close_pairs()? } else { 0 };
    let cancelled = if options.cancel_pairs_nearest > 0 {
        sys.cancel_pairs(options.cancel_pairs_nearest, &mut |removed, tried, trials| {
            progress(ConeProgress::PairCancellation { component: c, removed, tried, trials })
        })?
    } else {
        0
    };
    let cancelled = cancelled + if options.min_pair_distance > 0.0 { sys.cancel_close_pairs(options.min_pair_distance)? } else { 0 };
    // After the clean-ups, so that none of them gathers the quarter turns
    // again; the moves that follow keep every cone within the bound.
    let spread = sys.spread_degenerate_cones(options.max_cone_index)?;
    let settled = if spread > 0 && options.optimize_locations { move_cones(sys, progress)? } else { 0 };
    Ok((moves + settled, merged, cancelled, spread))
}

/// Component placements that do not fit the problem: a component missing or
/// twice, indices out of range, faces of another component, lengths that
/// disagree (e.g. results from an instance that opened another mesh).
#[derive(Clone, Debug, PartialEq)]
pub struct MismatchError(pub String);

impl fmt::Display for MismatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cone placement: component results do not fit this mesh: {}", self.0)
    }
}

impl std::error::Error for MismatchError {}

impl ComponentPlacement {
    /// JSON with exactly round-tripping floats.
    pub fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec(self).expect("a component placement always serializes")
    }

    /// Reads [`Self::to_json`]'s output.
    pub fn from_json(bytes: &[u8]) -> Result<ComponentPlacement, MismatchError> {
        serde_json::from_slice(bytes).map_err(|e| MismatchError(format!("unreadable component result ({e})")))
    }
}

impl ConeProblem {
    /// Cuts `mesh` open along `features` and prepares the shared data.
    pub fn new(mesh: &TriMesh, features: &FeatureSet, options: &ConeOptions) -> ConeProblem {
        let mut clock = Stopwatch::start();
        let mut cut = cut_open(mesh, features);
        if options.boundary == BoundaryMode::Free {
            cut.free_original_boundary(mesh);
        }
        let cm = &cut.mesh;
        let boundary_k = boundary_turning(cm);
        let mut seeds = vec![u32::MAX; cm.n_components()];
        for (f, &c) in cm.face_components().iter().enumerate() {
            if seeds[c as usize] == u32::MAX {
                seeds[c as usize] = f as u32;
            }
        }
        ConeProblem { cut, boundary_k, seeds, options: *options, cut_seconds: clock.lap() }
    }

    /// Number of components of the cut mesh.
    pub fn n_components(&self) -> usize {
        self.seeds.len()
    }

    /// Faces per component: a cost estimate for scheduling.
    pub fn component_faces(&self) -> Vec<usize> {
        let mut n = vec![0; self.n_components()];
        for &c in self.cut.mesh.face_components() {
            n[c as usize] += 1;
        }
        n
    }

    /// Components in the order to schedule them: largest first.
    pub fn schedule(&self) -> Vec<usize> {
        let faces = self.component_faces();
        let mut order: Vec<usize> = (0..faces.len()).collect();
        order.sort_by_key(|&c| std::cmp::Reverse(faces[c]));
        order
    }

    /// Places the cones of component `c` (< [`Self::n_components`]): system,
    /// Algorithm 1, cone moves and the optional clean-ups.
    pub fn place_component(&self, c: usize, progress: &mut dyn FnMut(ConeProgress)) -> Result<ComponentPlacement, ConeError> {
        let mut clock = Stopwatch::start();
        let (cm, options) = (&self.cut.mesh, &self.options);
        let weights = Weights { alpha_smooth: options.alpha_smooth, miq: options.miq };
        progress(ConeProgress::Topology { component: c, components: self.n_components() });
        let mut sys = ComponentSystem::new(cm, self.seeds[c], &self.boundary_k, &self.cut.free, weights)?;
        sys.rounding = options.rounding;
        let topology_seconds = clock.lap();
        let mut rounds = None;
        if let Some((k, coarse_rounds)) = self.coarse_indices(c, &sys, progress) {
            if sys.fix_indices(&k).is_ok() {
                rounds = Some(coarse_rounds);
            }
        }
        if rounds.is_none() {
            sys.round_all(&mut |round, free| progress(ConeProgress::Rounding { component: c, round, free }))?;
        }
        let rounding_seconds = clock.lap();
        // Placed coarse, the cones only move here: the clean-ups ran on the
        // coarse mesh, and their objective is not resolution-independent (the
        // Dirichlet energy of phi near a cone grows like log(1/h)), so on the
        // fine mesh they would cancel pairs the coarse solve kept.
        let fine_options = if rounds.is_some() { ConeOptions { merge_close_pairs: false, cancel_pairs_nearest: 0, ..*options } } else { *options };
        let (moves, merged, cancelled, spread) = improve(&mut sys, &fine_options, c, progress)?;

        let kv = sys.vertex_k();
        let phi = sys.phi().to_vec();
        let h = sys.h();
        let vertices = sys.tree.vertices.clone();
        let faces = sys.tree.faces.clone();
        // omega = -*dphi + h on the midline segments (section 4).
        let mut omega = Vec::with_capacity(3 * faces.len());
        for &f in &faces {
            let hs = cm.face_halfedges(f);
            let tri = cm.faces()[f as usize];
            for i in 0..3 {
                let visit = Visit { h_in: hs[i], h_out: hs[(i + 1) % 3] };
                let coef = segment_phi_coefficients(cm, visit);
                let mut w: f64 = (0..3).map(|j| coef[j] * phi[sys.local(tri[j]) as usize]).sum();
                for (j, hj) in h.iter().enumerate() {
                    w += hj * sys.basis.segment(j, visit);
                }
                omega.push(w);
            }
        }
        let area: f64 = faces.iter().map(|&f| cm.face_areas()[f as usize]).sum();
        let figures = ComponentFigures {
            euler_characteristic: cm.component_euler_characteristic(c),
            boundary_loops: cm.component_boundary_loops(c),
            genus: cm.genus(c),
            k_sum: kv.iter().sum(),
            path_integers: sys.tree.leftovers.iter().map(|&e| sys.fixed[sys.tree.g_index[e as usize] as usize].unwrap_or(0)).collect(),
            h,
            rounds: rounds.unwrap_or(sys.rounds),
            moves,
            merged_pairs: merged,
            cancelled_pairs: cancelled,
            spread_quarter_turns: spread,
            residual: sys.residual,
            refinement_steps: sys.refinement_steps,
        };
        Ok(ComponentPlacement {
            component: c,
            vertices,
            k: kv.iter().map(|&k| k as i32).collect(),
            energy: sys.energy(options.alpha_smooth),
            phi2_area: sys.phi_norm2() * area,
            phi,
            faces,
            omega,
            figures,
            area,
            topology_seconds,
            rounding_seconds,
            moves_seconds: clock.lap(),
        })
    }

    /// Cone indices per local vertex of `sys` (component `c`) placed on a
    /// decimation of the component ([`decimate_interior`]: boundary and
    /// feature curves kept, so the boundary integers are the same), and the
    /// rounds that took; `None` when the component is small enough to place
    /// directly or the coarse placement fails (the caller then rounds here).
    fn coarse_indices(&self, c: usize, sys: &ComponentSystem, progress: &mut dyn FnMut(ConeProgress)) -> Option<(Vec<i64>, usize)> {
        let (cm, options) = (&self.cut.mesh, &self.options);
        let vertices = &sys.tree.vertices;
        let interior = vertices.iter().filter(|&&v| !cm.is_boundary_vertex(v)).count();
        if interior <= options.coarse_vertices {
            return None;
        }
        // The component alone, numbered in order of first use.
        let mut sub_id = vec![NONE; cm.n_vertices()];
        let (sub, sub_vertex) = cm.submesh(&sys.tree.faces, &mut sub_id)?;
        // Levels, each a decimation of the previous to a quarter of its
        // interior (at least the coarse size): the cones settle at every scale.
        let mut levels: Vec<(TriMesh, Vec<u32>)> = Vec::new(); // (mesh, its vertices in `sub`)
        loop {
            let finer = levels.last().map_or(&sub, |l| &l.0);
            let interior = (0..finer.n_vertices() as u32).filter(|&v| !finer.is_boundary_vertex(v)).count();
            if interior <= options.coarse_vertices {
                break;
            }
            let d = decimate_interior(finer, options.coarse_vertices.max(interior / COARSENING))?;
            let to_sub: Vec<u32> = match levels.last() {
                Some((_, up)) => d.vertex.iter().map(|&v| up[v as usize]).collect(),
                None => d.vertex,
            };
            levels.push((d.mesh, to_sub));
        }
        let weights = Weights { alpha_smooth: options.alpha_smooth, miq: options.miq };
        // Per level, coarsest first: indices per `sub` vertex carried down.
        let mut k_sub: Option<Vec<i64>> = None;
        let mut rounds = 0;
        for (mesh, to_sub) in levels.iter().rev() {
            let to_cut = |v: u32| sub_vertex[to_sub[v as usize] as usize];
            let boundary_k: Vec<i32> = (0..mesh.n_vertices() as u32).map(|v| self.boundary_k[to_cut(v) as usize]).collect();
            // Boundary edges are kept by the decimation: free where the cut mesh's are.
            let free: Vec<bool> = (0..mesh.n_edges() as u32)
                .map(|e| {
                    let [a, b] = mesh.edge_vertices(e).map(to_cut);
                    mesh.is_boundary_edge(e)
                        && cm.outgoing(a).find(|&h| cm.head(h) == b).is_some_and(|h| self.cut.free[cm.edge(h) as usize])
                })
                .collect();
            let mut lsys = ComponentSystem::new(mesh, 0, &boundary_k, &free, weights).ok()?;
            lsys.rounding = options.rounding;
            match &k_sub {
                None => {
                    lsys.round_all(&mut |round, free| progress(ConeProgress::Rounding { component: c, round, free })).ok()?;
                    rounds = lsys.rounds;
                    improve(&mut lsys, options, c, &mut |_| {}).ok()?;
                }
                Some(k) => {
                    let given: Vec<i64> = lsys.tree.vertices.iter().map(|&v| k[to_sub[v as usize] as usize]).collect();
                    lsys.fix_indices(&given).ok()?;
                    if options.optimize_locations {
                        lsys.optimize_locations(options.max_move_passes, options.max_cone_index, &mut |_, _, _| {}).ok()?;
                    }
                }
            }
            let mut next: Vec<i64> = sub_vertex.iter().map(|&v| if cm.is_boundary_vertex(v) { self.boundary_k[v as usize] as i64 } else { 0 }).collect();
            for (i, ki) in lsys.vertex_k().into_iter().enumerate() {
                let v = to_sub[lsys.tree.vertices[i] as usize];
                if !sub.is_boundary_vertex(v) {
                    next[v as usize] = ki;
                }
            }
            k_sub = Some(next);
        }
        let k_sub = k_sub?;
        let k = vertices.iter().map(|&v| k_sub[sub_id[v as usize] as usize]).collect();
        Some((k, rounds))
    }

    /// Joins one placement per component (any order) into the placement of
    /// `mesh` (the mesh this problem was built from). Checks that the results
    /// fit: every component exactly once, indices in range, lengths matching.
    /// `timings.total` is the sum of the stages; a caller that knows the
    /// wall-clock time (components may run in parallel) overwrites it.
    pub fn assemble(self, mesh: &TriMesh, mut results: Vec<ComponentPlacement>) -> Result<ConePlacement, MismatchError> {
        let cm = &self.cut.mesh;
        let (nv, nf) = (cm.n_vertices(), cm.n_faces());
        results.sort_by_key(|r| r.component);
        let components: Vec<usize> = results.iter().map(|r| r.component).collect();
        if components != (0..self.n_components()).collect::<Vec<_>>() {
            return Err(MismatchError(format!("expected components 0..{}, got {components:?}", self.n_components())));
        }
        let mut k = vec![0i32; nv];
        let mut phi = vec![0.0; nv];
        let mut omega = vec![0.0; 3 * nf];
        let mut timings = ConeTimings { cut: self.cut_seconds, ..ConeTimings::default() };
        let (mut energy, mut phi2_area, mut total_area, mut rounds) = (0.0, 0.0, 0.0, 0);
        let mut figures = Vec::with_capacity(results.len());
        for r in results {
            let c = r.component;
            if r.k.len() != r.vertices.len() || r.phi.len() != r.vertices.len() || r.omega.len() != 3 * r.faces.len() {
                return Err(MismatchError(format!("component {c}: array lengths disagree")));
            }
            for (i, &v) in r.vertices.iter().enumerate() {
                if v as usize >= nv {
                    return Err(MismatchError(format!("component {c}: vertex {v} out of range ({nv} vertices)")));
                }
                k[v as usize] = r.k[i];
                phi[v as usize] = r.phi[i];
            }
            for (i, &f) in r.faces.iter().enumerate() {
                if f as usize >= nf || cm.face_components()[f as usize] as usize != c {
                    return Err(MismatchError(format!("component {c}: face {f} is not in it")));
                }
                omega[3 * f as usize..3 * f as usize + 3].copy_from_slice(&r.omega[3 * i..3 * i + 3]);
            }
            timings.topology += r.topology_seconds;
            timings.rounding += r.rounding_seconds;
            timings.cone_moves += r.moves_seconds;
            energy += r.energy;
            phi2_area += r.phi2_area;
            total_area += r.area;
            rounds += r.figures.rounds;
            figures.push(r.figures);
        }
        let (cones, boundary_corners) = original_cones(mesh, &self.cut, &k);
        timings.total = timings.cut + timings.topology + timings.rounding + timings.cone_moves;
        Ok(ConePlacement {
            cut: self.cut,
            k,
            phi,
            omega,
            cones,
            boundary_corners,
            components: figures,
            energy,
            phi_rms: (phi2_area / total_area.max(f64::MIN_POSITIVE)).sqrt(),
            rounds,
            timings,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::place_cones;
    use crate::cones::test_meshes::grid;

    #[test]
    fn components_placed_apart_assemble_to_the_whole_placement() {
        // A curved sheet cut in two by a feature line across it.
        let mesh = grid(8, 8, |x, y| [x, y, 0.2 * (3.0 * x).sin() * y]);
        let mut features = FeatureSet::none(&mesh);
        for e in 0..mesh.n_edges() as u32 {
            if mesh.edge_vertices(e).iter().all(|&v| (mesh.position(v)[1] - 0.5).abs() < 1e-12) {
                features.set(&mesh, e, true);
            }
        }
        let options = ConeOptions::default();
        let whole = place_cones(&mesh, &features, &options, &mut |_| {}).unwrap();
        let problem = ConeProblem::new(&mesh, &features, &options);
        assert_eq!(problem.n_components(), 2);
        // Placed in reverse order, each through JSON (exact floats).
        let results: Vec<ComponentPlacement> = problem
            .schedule()
            .iter()
            .rev()
            .map(|&c| {
                let r = problem.place_component(c, &mut |_| {}).unwrap();
                let back = ComponentPlacement::from_json(&r.to_json()).unwrap();
                assert_eq!(back, r);
                back
            })
            .collect();
        let joined = problem.clone().assemble(&mesh, results.clone()).unwrap();
        assert_eq!((&joined.k, &joined.phi, &joined.omega), (&whole.k, &whole.phi, &whole.omega));
        assert_eq!((&joined.cones, &joined.boundary_corners), (&whole.cones, &whole.boundary_corners));
        assert_eq!(joined.energy, whole.energy);

        // Results that do not fit are refused.
        assert!(problem.clone().assemble(&mesh, results[..1].to_vec()).is_err());
        let mut twice = results.clone();
        twice[1].component = twice[0].component;
        assert!(problem.clone().assemble(&mesh, twice).is_err());
        let mut foreign = results.clone();
        foreign[0].faces[0] = foreign[1].faces[0];
        assert!(problem.clone().assemble(&mesh, foreign).is_err());
        let mut short = results;
        short[0].phi.pop();
        assert!(problem.assemble(&mesh, short).is_err());
        assert!(ComponentPlacement::from_json(b"{\"component\": 0}").is_err());
    }
}
