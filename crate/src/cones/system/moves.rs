//! After Algorithm 1: cone-location optimization and the clean-up of close
//! pairs (section 5.3), by transfers of cone index along the primal tree.
//!
//! A transfer changes only fixed `p`, i.e. right-hand-side entries of the fix
//! rows, so its effect on the solution is `K⁻¹ Δb` whatever the current `x`
//! is. Trials therefore cost one column of a blocked solve with the final
//! factorization (no refactorization, no re-solve of `x`), and many trials
//! share one blocked solve.

use super::{ComponentSystem, ConeError, CurvatureSystem, FreeCurvatureSystem, BORDER_BUDGET};
use std::f64::consts::FRAC_PI_2;

/// A transfer of cone index: `(from, to, amount)` in local vertices and
/// quarter turns.
pub(crate) type Transfer = (usize, usize, i64);

/// Relative residual of the trial solves (energy comparisons need far less
/// than the final accuracy; the accepted state is re-solved exactly).
const TRIAL_TOLERANCE: f64 = 1e-9;
/// Most trial columns per blocked solve (also bounded by the memory budget).
const MAX_TRIAL_COLUMNS: usize = 16;
/// Relative decrease a move or cancellation must bring to be kept.
const MIN_DECREASE: f64 = 1e-9;
/// Largest interior cone index with a positive cone angle (`2 pi - k pi/2 > 0`).
pub(crate) const MAX_CONE_INDEX: i64 = 3;

impl ComponentSystem<'_> {
    /// `sigma_ig`: the sign with which local vertex `i`'s cycle crosses `G`
    /// edge `g` (`None` if it does not).
    fn sigma(&self, i: usize, g: u32) -> Option<i32> {
        self.cycles[i].g.iter().find(|(gg, _)| *gg == g).map(|&(_, s)| s)
    }

    /// The changes `(g, Δp_g)` of the fixed `p` that move `amount` quarter
    /// turns of cone index from local vertex `from` to `to` along `T_p`
    /// (leftovers are never on it; a free port on the way is a continuous
    /// unknown, which takes the index in and gives it back unchanged).
    fn transfer_changes(&self, (from, to, amount): Transfer) -> Vec<(usize, i64)> {
        let (a, b) = (self.tree.vertices[from], self.tree.vertices[to]);
        let mut x = a;
        let mut out = Vec::new();
        for (e, _) in self.tree.primal_path(self.mesh, a, b) {
            let [u, w] = self.mesh.edge_vertices(e);
            let g = self.tree.g_index[e as usize];
            if !self.continuous[g as usize] {
                let s = self.sigma(self.local[x as usize] as usize, g).expect("T_p edges are G edges of both end vertices") as i64;
                out.push((g as usize, -amount * s));
            }
            x = if u == x { w } else { u };
        }
        out
    }

    /// Makes a transfer: changes the fixed `p` and the fix rows' right-hand
    /// side (the solution `x` is left to the caller).
    pub(crate) fn transfer(&mut self, t: Transfer) {
        for (g, dp) in self.transfer_changes(t) {
            let p = self.fixed[g].as_mut().expect("all p fixed before cone moves");
            *p += dp;
            self.constraint_rhs[self.row_fix + g] = *p as f64;
        }
    }

    /// The curvature system of the final integers (factorized on first use).
    pub(super) fn curvature(&mut self) -> Result<&CurvatureSystem, ConeError> {
        if self.curvature.is_none() {
            let mass: Vec<f64> = self.area.iter().map(|a| a / self.total_area).collect();
            let nh = self.basis.len();
            self.curvature = Some(CurvatureSystem::new(&self.laplacian, mass, &self.path_rows, nh)?);
        }
        Ok(self.curvature.as_ref().expect("built above"))
    }

    /// The free-boundary counterpart of [`Self::curvature`] (built on first use).
    fn free_curvature(&mut self) -> Result<&FreeCurvatureSystem, ConeError> {
        if self.free_curvature.is_none() {
            let mass: Vec<f64> = self.area.iter().map(|a| a / self.total_area).collect();
            let mut q_index = vec![usize::MAX; self.continuous.len()];
            let mut nq = 0;
            for (g, _) in self.continuous.iter().enumerate().filter(|(_, &c)| c) {
                q_index[g] = nq;
                nq += 1;
            }
            let vertex_q: Vec<Vec<(usize, i32)>> = self
                .cycles
                .iter()
                .map(|c| c.g.iter().filter(|(g, _)| self.continuous[*g as usize]).map(|&(g, s)| (q_index[g as usize], s)).collect())
                .collect();
            // A path row's `p_l` is a free port's continuous `p` when the
            // leftover is one (each loop off the root keeps one out of `T_p`).
            let (nv, nh, p0) = (self.tree.vertices.len(), self.basis.len(), self.p0());
            let path_rows: Vec<_> = self
                .path_rows
                .iter()
                .filter_map(|&(r, col, w)| match col.checked_sub(p0) {
                    None => Some((r, col, w)),
                    Some(g) if self.continuous[g] => Some((r, nv + nh + q_index[g], w)),
                    Some(_) => None,
                })
                .collect();
            let system = FreeCurvatureSystem::new(&self.objective_terms, &self.laplacian, mass, &vertex_q, nq, &path_rows, nh)?;
            self.free_curvature = Some(system);
        }
        Ok(self.free_curvature.as_ref().expect("built above"))
    }

    /// Width of a response column: `phi` then `h~` (the objective's unknowns).
    fn response_width(&self) -> usize {
        self.tree.vertices.len() + self.basis.len()
    }

    /// For each set of transfers, the change of `[phi; h~]` that making them
    /// all would bring (column-major, [`Self::response_width`] per set).
    fn responses(&mut self, sets: &[Vec<Transfer>]) -> Result<Vec<f64>, ConeError> {
        let nv = self.tree.vertices.len();
        let mut db = vec![0.0; nv * sets.len()];
        for (col, set) in sets.iter().enumerate() {
            for &(from, to, amount) in set {
                db[col * nv + to] += FRAC_PI_2 * amount as f64;
                db[col * nv + from] -= FRAC_PI_2 * amount as f64;
            }
        }
        if self.has_free_boundary() {
            return self.free_trial(|f| f.responses(&db, sets.len(), TRIAL_TOLERANCE), |s| s.kkt_responses(sets));
        }
        Ok(self.curvature()?.responses(&db, sets.len(), TRIAL_TOLERANCE)?)
    }

    /// Trial columns per blocked solve within the memory budget.
    fn trial_columns(&self) -> usize {
        MAX_TRIAL_COLUMNS.min(BORDER_BUDGET / self.response_width().max(1)).max(1)
    }

    /// Makes the transfers and moves `[phi; h~]` by their response `dx`;
    /// the rest of `x` is stale until the next [`Self::solve`].
    fn accept(&mut self, transfers: &[Transfer], dx: &[f64]) {
        for &t in transfers {
            self.transfer(t);
        }
        self.x.iter_mut().zip(dx).for_each(|(x, d)| *x += d);
    }

    /// First-order sensitivity of `phiᵀ M phi / A` to moving cone index:
    /// returns `Phi` per local vertex such that moving `a` quarter turns from
    /// `u` to `w` (along `T_p`, as [`Self::transfer`] does) changes the
    /// energy by about `2 a (Phi[w] - Phi[u])` (one curvature solve).
    fn move_potential(&mut self) -> Result<Vec<f64>, ConeError> {
        let phi = self.x[..self.tree.vertices.len()].to_vec();
        // A ranking needs no more than the trials' accuracy.
        if self.has_free_boundary() {
            return self.free_trial(|f| f.move_potential(&phi, TRIAL_TOLERANCE), Self::kkt_move_potential);
        }
        Ok(self.curvature()?.move_potential(&phi, TRIAL_TOLERANCE)?)
    }

    /// A trial quantity on a free-boundary component: from the reduced
    /// system, or from the component's KKT once the reduced one failed (its
    /// small proximal block can defeat the unpivoted LDLᵀ: a teapot tube).
    fn free_trial<T>(
        &mut self,
        reduced: impl FnOnce(&FreeCurvatureSystem) -> Result<T, crate::linalg::LinalgError>,
        kkt: impl FnOnce(&mut Self) -> Result<T, ConeError>,
    ) -> Result<T, ConeError> {
        if !self.free_curvature_failed {
            match self.free_curvature().and_then(|f| Ok(reduced(f)?)) {
                Ok(value) => return Ok(value),
                Err(_) => self.free_curvature_failed = true,
            }
        }
        kkt(self)
    }

    /// [`Self::responses`] through the component's KKT (the check of the
    /// reduced systems, and the fallback where the free one fails): a
    /// transfer changes fix rows' right-hand sides only, so its response is
    /// `K⁻¹ Δb` with the factorization of the final integers.
    fn kkt_responses(&mut self, sets: &[Vec<Transfer>]) -> Result<Vec<f64>, ConeError> {
        self.factorize_if_stale()?;
        let (dim, width, fix0) = (self.kkt.pattern.dim(), self.response_width(), self.n + self.row_fix);
        let mut rhs = vec![0.0; dim * sets.len()];
        for (col, set) in sets.iter().enumerate() {
            for &t in set {
                for (g, dp) in self.transfer_changes(t) {
                    rhs[col * dim + fix0 + g] += dp as f64;
                }
            }
        }
        let (x, _) = self.factored().solve_many_to(&rhs, sets.len(), TRIAL_TOLERANCE)?;
        Ok(x.chunks(dim).flat_map(|c| c[..width].iter().copied()).collect())
    }

    /// [`Self::move_potential`] through the full KKT: with
    /// `y = K⁻¹ [M phi / A; 0]`, changing fixed `p_g` by `Δ` changes
    /// `phiᵀ M phi / A` by about `2 y_g Δ` (`y_g` at `p_g`'s fix row), and
    /// the potential accumulates these along `T_p` from its root.
    fn kkt_move_potential(&mut self) -> Result<Vec<f64>, ConeError> {
        self.factorize_if_stale()?;
        let nv = self.tree.vertices.len();
        let dim = self.kkt.pattern.dim();
        let mut rhs = vec![0.0; dim];
        for i in 0..nv {
            rhs[i] = self.x[i] * self.area[i] / self.total_area;
        }
        let (y, _) = self.factored().solve_many_to(&rhs, 1, TRIAL_TOLERANCE)?;
        let fix0 = self.n + self.row_fix;
        let mut order: Vec<usize> = (0..nv).collect();
        order.sort_by_key(|&i| self.tree.primal_depth[self.tree.vertices[i] as usize]);
        let mut potential = vec![0.0; nv];
        for i in order {
            let h = self.tree.primal_parent_he[self.tree.vertices[i] as usize];
            if h == crate::mesh::NONE {
                continue;
            }
            let parent = self.local[self.mesh.tail(h) as usize] as usize;
            let g = self.tree.g_index[self.mesh.edge(h) as usize];
            potential[i] = potential[parent];
            if !self.continuous[g as usize] {
                // A unit transfer parent -> i changes p_g by -sigma(parent, g).
                let s = self.sigma(parent, g).expect("T_p edges are G edges of both end vertices");
                potential[i] -= s as f64 * y[fix0 + g as usize];
            }
        }
        Ok(potential)
    }

    /// Cone-location optimization (section 5.3): moves an interior cone to
    /// a neighbouring interior vertex when that lowers `phiᵀ M phi / A`,
    /// until no move helps or `max_passes` passes. Candidates are ranked by
    /// the first-order change ([`Self::move_potential`]) and the two most
    /// promising per cone are evaluated exactly; after the first pass only
    /// cones within two rings of a moved cone are reconsidered. No move
    /// makes a cone's index exceed `max_index` or its own index. Returns the
    /// moves made; `progress(pass, tried, cones)` hears of each batch of
    /// candidate cones evaluated.
    pub fn optimize_locations(&mut self, max_passes: usize, max_index: i64, progress: &mut dyn FnMut(usize, usize, usize)) -> Result<usize, ConeError> {
        const EXACT_TRIES: usize = 2;
        let mut moves = 0;
        let mut current = self.phi_norm2();
        let nv = self.tree.vertices.len();
        // Cones to (re)consider: all at first, then those near a moved cone.
        let mut dirty = vec![true; nv];
        for pass in 0..max_passes {
            progress(pass, 0, 0);
            let potential = self.move_potential()?;
            // Per dirty interior cone: its index and its best candidates.
            let mut plans: Vec<(usize, i64, Vec<usize>)> = Vec::new();
            for i in 0..nv {
                let ki = self.vertex_k_at(i);
                let v = self.tree.vertices[i];
                if ki == 0 || !dirty[i] || self.mesh.is_boundary_vertex(v) {
                    continue;
                }
                let mut candidates: Vec<(f64, usize)> = self
                    .mesh
                    .one_ring(v)
                    .filter(|&w| !self.mesh.is_boundary_vertex(w))
                    .map(|w| self.local[w as usize] as usize)
                    .filter(|&j| self.vertex_k_at(j) + ki <= max_index.max(ki))
                    .map(|j| (2.0 * ki as f64 * (potential[j] - potential[i]), j))
                    .filter(|&(estimate, _)| estimate < -MIN_DECREASE * current)
                    .collect();
                candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
                candidates.truncate(EXACT_TRIES);
                if !candidates.is_empty() {
                    plans.push((i, ki, candidates.into_iter().map(|c| c.1).collect()));
                }
            }
            dirty.iter_mut().for_each(|d| *d = false);
            let mut moved = 0;
            let per_solve = (self.trial_columns() / EXACT_TRIES).max(1);
            for (n, chunk) in plans.chunks(per_solve).enumerate() {
                progress(pass, n * per_solve, plans.len());
                let sets: Vec<Vec<Transfer>> =
                    chunk.iter().flat_map(|(i, ki, js)| js.iter().map(move |&j| vec![(*i, j, *ki)])).collect();
                let dx = self.responses(&sets)?;
                let dim = self.response_width();
                let mut first = 0;
                for (i, ki, js) in chunk {
                    let (i, start) = (*i, first);
                    first += js.len();
                    // An earlier move of this pass may have changed this cone
                    // or its candidates.
                    let k_now = self.vertex_k_at(i);
                    if k_now == 0 || js.iter().any(|&j| self.vertex_k_at(j) + k_now > max_index.max(k_now)) {
                        continue;
                    }
                    let own;
                    let (source, start) = if k_now == *ki {
                        (&dx, start)
                    } else {
                        own = self.responses(&js.iter().map(|&j| vec![(i, j, k_now)]).collect::<Vec<_>>())?;
                        (&own, 0)
                    };
                    let column = |c: usize| &source[(start + c) * dim..(start + c + 1) * dim];
                    let mut best: Option<(f64, usize)> = None;
                    for c in 0..js.len() {
                        let e = self.phi_norm2_at(&self.x, Some(column(c)));
                        if e < current * (1.0 - MIN_DECREASE) && best.is_none_or(|b| e < b.0) {
                            best = Some((e, c));
                        }
                    }
                    if let Some((e, c)) = best {
                        let j = js[c];
                        let d = column(c).to_vec();
                        self.accept(&[(i, j, k_now)], &d);
                        current = e;
                        moves += 1;
                        moved += 1;
                        let w = self.tree.vertices[j];
                        dirty[j] = true;
                        for a in self.mesh.one_ring(w) {
                            dirty[self.local[a as usize] as usize] = true;
                            for b in self.mesh.one_ring(a) {
                                dirty[self.local[b as usize] as usize] = true;
                            }
                        }
                    }
                }
            }
            if moved == 0 {
                break;
            }
        }
        self.solve_unknowns()?;
        Ok(moves)
    }

    /// Splits interior cones of index above `max_index` (clamped to
    /// [`MAX_CONE_INDEX`]: above it a cone has angle <= 0 and no seamless map
    /// has it), one quarter turn at a time, onto the interior vertex within
    /// two rings that keeps its index within the bound and gives the lowest
    /// `phiᵀ M phi / A`. A cone with no such vertex is left (above 3 the
    /// pipeline then refines around it). Returns the quarter turns moved.
    pub fn spread_degenerate_cones(&mut self, max_index: i64) -> Result<usize, ConeError> {
        let max_index = max_index.clamp(1, MAX_CONE_INDEX);
        let mut moved = 0;
        let dim = self.response_width();
        let mut stuck: Vec<usize> = Vec::new();
        while let Some((i, _)) = self.interior_cones().into_iter().find(|&(i, k)| k > max_index && !stuck.contains(&i)) {
            let v = self.tree.vertices[i];
            let mut near: Vec<u32> = self.mesh.one_ring(v).flat_map(|a| self.mesh.one_ring(a).chain([a])).collect();
            near.sort_unstable();
            near.dedup();
            let candidates: Vec<usize> = near
                .into_iter()
                .filter(|&w| w != v && !self.mesh.is_boundary_vertex(w))
                .map(|w| self.local[w as usize] as usize)
                .filter(|&j| self.vertex_k_at(j) < max_index)
                .collect();
            let mut best: Option<(f64, usize, Vec<f64>)> = None;
            for chunk in candidates.chunks(self.trial_columns()) {
                let sets: Vec<Vec<Transfer>> = chunk.iter().map(|&j| vec![(i, j, 1)]).collect();
                let dx = self.responses(&sets)?;
                for (c, &j) in chunk.iter().enumerate() {
                    let d = &dx[c * dim..(c + 1) * dim];
                    let e = self.phi_norm2_at(&self.x, Some(d));
                    if best.as_ref().is_none_or(|b| e < b.0) {
                        best = Some((e, j, d.to_vec()));
                    }
                }
            }
            let Some((_, j, d)) = best else {
                stuck.push(i);
                continue;
            };
            self.accept(&[(i, j, 1)], &d);
            moved += 1;
        }
        if moved > 0 {
            self.solve_unknowns()?;
        }
        Ok(moved)
    }

    /// Unit transfers that cancel every interior cone: each quarter turn of a
    /// positive cone goes to the nearest negative cone with index left.
    fn pairing(&self, cones: &[(usize, i64)]) -> Vec<Transfer> {
        let pos = |i: usize| self.mesh.position(self.tree.vertices[i]);
        let mut left: Vec<(usize, i64)> = cones.iter().filter(|c| c.1 < 0).copied().collect();
        let mut moves = Vec::new();
        for &(i, ki) in cones.iter().filter(|c| c.1 > 0) {
            for _ in 0..ki {
                let Some(best) = (0..left.len()).filter(|&n| left[n].1 < 0).min_by(|&a, &b| {
                    let d = |n: usize| crate::vec3::norm(crate::vec3::sub(pos(i), pos(left[n].0)));
                    d(a).total_cmp(&d(b))
                }) else {
                    break;
                };
                moves.push((i, left[best].0, 1));
                left[best].1 += 1;
            }
        }
        moves
    }

    /// Interior cones as (local vertex, k).
    fn interior_cones(&self) -> Vec<(usize, i64)> {
        (0..self.cycles.len())
            .map(|i| (i, self.vertex_k_at(i)))
            .filter(|&(i, k)| k != 0 && !self.mesh.is_boundary_vertex(self.tree.vertices[i]))
            .collect()
    }

    /// Clean-up of section 5.3 (after Myles & Zorin 2012): cancels pairs of
    /// interior cones of opposite index one or two edges apart, unless that
    /// raises the objective by more than [`super::MERGE_TOLERANCE`] (on coarse
    /// meshes a close pair can carry a real rotation). Returns the pairs removed.
    pub fn merge_close_pairs(&mut self) -> Result<usize, ConeError> {
        let mut merged = 0;
        let mut rejected: std::collections::HashSet<(usize, usize)> = Default::default();
        let mut current = self.objective();
        loop {
            let cones = self.interior_cones();
            let index: std::collections::HashMap<usize, i64> = cones.iter().copied().collect();
            let mut pair = None;
            'search: for &(i, ki) in &cones {
                let v = self.tree.vertices[i];
                for w in self.mesh.one_ring(v) {
                    for x in std::iter::once(w).chain(self.mesh.one_ring(w)) {
                        let j = self.local[x as usize] as usize;
                        if j != i && index.get(&j) == Some(&-ki) && !rejected.contains(&(i, j)) {
                            pair = Some((i, j, ki));
                            break 'search;
                        }
                    }
                }
            }
            let Some(t) = pair else { break };
            let dx = self.responses(&[vec![t]])?;
            let e = self.objective_at(&self.x, Some(&dx));
            if e <= current * (1.0 + super::MERGE_TOLERANCE) {
                self.accept(&[t], &dx);
                current = e;
                merged += 1;
            } else {
                rejected.insert((t.0, t.1));
                rejected.insert((t.1, t.0));
            }
        }
        self.solve_unknowns()?;
        Ok(merged)
    }

    /// Cancels the pairs of opposite interior cones closer than `distance`
    /// ([`crate::cones::close_pairs`]) whatever the objective says: a grid
    /// that cannot keep them apart asks for it
    /// ([`crate::cones::ConeOptions::min_pair_distance`]). Returns the
    /// pairs cancelled.
    pub fn cancel_close_pairs(&mut self, distance: f64) -> Result<usize, ConeError> {
        let cones = self.interior_cones();
        let located: Vec<([f64; 3], i64)> = cones.iter().map(|&(i, k)| (self.mesh.position(self.tree.vertices[i]), k)).collect();
        let pairs = crate::cones::close_pairs(&located, distance);
        if pairs.is_empty() {
            return Ok(0);
        }
        // One exact solve for all of them (no trial to rank).
        for &(a, b) in &pairs {
            self.transfer((cones[a].0, cones[b].0, 1));
        }
        self.solve_unknowns()?;
        Ok(pairs.len())
    }

    /// Pair cancellation by descent on the objective (an extension of the
    /// paper's clean-up to distant pairs): for each interior cone, tries
    /// cancelling it against each of its `nearest` closest cones of opposite
    /// index and keeps the best cancellation while the objective decreases.
    /// Returns the number of pairs removed; `progress(removed, tried,
    /// trials)` hears of each batch of candidate pairs evaluated.
    pub fn cancel_pairs(&mut self, nearest: usize, progress: &mut dyn FnMut(usize, usize, usize)) -> Result<usize, ConeError> {
        let mut removed = 0;
        let mut current = self.objective();
        // Global candidate: when the interior indices sum to zero, all cones
        // may cancel at once (a single pair's removal can cost energy while
        // removing all of them lowers it, e.g. on a torus of revolution).
        let cones = self.interior_cones();
        if !cones.is_empty() && cones.iter().map(|c| c.1).sum::<i64>() == 0 {
            let moves = self.pairing(&cones);
            let dx = self.responses(std::slice::from_ref(&moves))?;
            let e = self.objective_at(&self.x, Some(&dx));
            if e < current * (1.0 - MIN_DECREASE) {
                self.accept(&moves, &dx);
                current = e;
                removed += moves.len();
            }
        }
        loop {
            progress(removed, 0, 0);
            let cones = self.interior_cones();
            let pos = |i: usize| self.mesh.position(self.tree.vertices[i]);
            // Each pair is tried once, from its positive cone.
            let mut trials: Vec<Transfer> = Vec::new();
            for &(i, ki) in cones.iter().filter(|c| c.1 > 0) {
                let mut partners: Vec<(f64, usize)> = cones
                    .iter()
                    .filter(|&&(j, kj)| kj == -ki && j != i)
                    .map(|&(j, _)| (crate::vec3::norm(crate::vec3::sub(pos(i), pos(j))), j))
                    .collect();
                partners.sort_by(|a, b| a.0.total_cmp(&b.0));
                trials.extend(partners.iter().take(nearest).map(|&(_, j)| (i, j, ki)));
            }
            let mut best: Option<(f64, Transfer, Vec<f64>)> = None;
            let dim = self.response_width();
            let per_solve = self.trial_columns();
            for (n, chunk) in trials.chunks(per_solve).enumerate() {
                progress(removed, n * per_solve, trials.len());
                let sets: Vec<Vec<Transfer>> = chunk.iter().map(|&t| vec![t]).collect();
                let dx = self.responses(&sets)?;
                for (c, &t) in chunk.iter().enumerate() {
                    let d = &dx[c * dim..(c + 1) * dim];
                    let e = self.objective_at(&self.x, Some(d));
                    if e < current * (1.0 - MIN_DECREASE) && best.as_ref().is_none_or(|b| e < b.0) {
                        best = Some((e, t, d.to_vec()));
                    }
                }
            }
            match best {
                Some((e, t, d)) => {
                    self.accept(&[t], &d);
                    current = e;
                    removed += 1;
                }
                None => break,
            }
        }
        self.solve_unknowns()?;
        Ok(removed)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{test_system, test_system_free};
    use crate::cones::test_meshes::{square_annulus, torus};
    use crate::mesh::TriMesh;

    /// A trial's response from the curvature system must be the change the
    /// full KKT gives when the transfer is made and everything is re-solved,
    /// `phi` and `h~` alike (the annulus has an alignment path, the torus
    /// two homology loops).
    fn responses_match_the_kkt(mesh: &TriMesh) {
        let mut sys = test_system(mesh);
        sys.round_all(&mut |_, _| {}).unwrap();
        let nv = sys.tree.vertices.len();
        let interior: Vec<usize> = (0..nv).filter(|&i| !mesh.is_boundary_vertex(sys.tree.vertices[i])).collect();
        let transfer = (interior[interior.len() / 3], interior[2 * interior.len() / 3], 1);
        let dx = sys.responses(&[vec![transfer]]).unwrap();
        let before = sys.x.clone();
        sys.transfer(transfer);
        sys.solve_kkt().unwrap();
        let width = sys.response_width();
        let scale = dx.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(scale > 1e-6, "the transfer changes phi");
        for i in 0..width {
            let exact = sys.x[i] - before[i];
            assert!((exact - dx[i]).abs() < 1e-7 * scale, "unknown {i}: KKT {exact} vs curvature {}", dx[i]);
        }
    }

    /// The reduced systems' trial responses and move potential are the
    /// component KKT's: the curvature equation on an aligned annulus, its
    /// free-boundary counterpart on the same annulus with both loops free.
    #[test]
    fn trial_responses_and_potential_match_the_kkt() {
        let mesh = square_annulus(6, 4, 0.4, 30f64.to_radians());
        check_trials_against_the_kkt(&mesh, test_system(&mesh));
        let free = test_system_free(&mesh);
        assert!(free.has_free_boundary());
        check_trials_against_the_kkt(&mesh, free);
    }

    fn check_trials_against_the_kkt(mesh: &TriMesh, mut sys: super::super::ComponentSystem<'_>) {
        sys.round_all(&mut |_, _| {}).unwrap();
        let nv = sys.tree.vertices.len();
        let interior: Vec<usize> = (0..nv).filter(|&i| !mesh.is_boundary_vertex(sys.tree.vertices[i])).collect();
        let sets = vec![vec![(interior[1], interior[interior.len() - 2], 1)], vec![(interior[interior.len() / 2], interior[0], -2)]];
        let reduced = sys.responses(&sets).unwrap();
        assert!(!sys.free_curvature_failed, "the reduced system answered (not the KKT fallback)");
        let kkt = sys.kkt_responses(&sets).unwrap();
        let scale = reduced.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(scale > 1e-6);
        for (i, (a, b)) in reduced.iter().zip(&kkt).enumerate() {
            // Trials need ranking accuracy; the free ports' block is held by the
            // 1e-8 proximal term only, so its solves agree to about 1e-6.
            let tolerance = if sys.has_free_boundary() { 1e-5 } else { 1e-7 };
            assert!((a - b).abs() < tolerance * scale, "free {}: entry {i}: reduced {a} vs KKT {b}", sys.has_free_boundary());
        }
        let (p1, p2) = (sys.move_potential().unwrap(), sys.kkt_move_potential().unwrap());
        assert!(!sys.free_curvature_failed);
        // Potentials agree up to a constant (only differences are used).
        let (d1, d2) = (p1[interior[0]] - p1[interior[3]], p2[interior[0]] - p2[interior[3]]);
        let pscale = p1.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(d1.abs() > 1e-9 * pscale);
        for &i in &interior {
            let (a, b) = (p1[i] - p1[interior[0]], p2[i] - p2[interior[0]]);
            // A ranking heuristic: its multipliers are solved less tightly than x.
            assert!((a - b).abs() < 1e-4 * pscale, "vertex {i}: potential {a} vs {b} ({d1} {d2})");
        }
    }

    #[test]
    fn curvature_responses_match_the_kkt_on_an_annulus() {
        responses_match_the_kkt(&square_annulus(6, 4, 0.4, 30f64.to_radians()));
    }

    #[test]
    fn curvature_responses_match_the_kkt_on_a_torus() {
        responses_match_the_kkt(&torus(16, 8, 2.0, 0.7));
    }
}
