//! The constrained problem of section 5.3 on one connected component, and
//! Algorithm 1 (greedy rounding of the path integers `p`).
//!
//! Unknowns `x = [phi (V) | h~ (n_h) | p (|G|)]` with `h = h~ / sqrt(W)`.
//! Constraint rows (eq. 16, written per cycle of the augmented dual graph):
//! * vertex `v` (all but one, their sum is zero):
//!   `(L phi)_v - (pi/2) sum_e sigma_ve p_e = -transport(gamma_v)`;
//! * leftover `l` (`G_path`): `B_phi phi + B_h h - (pi/2) p_l = -transport(C_l)`;
//! * fix `e`: `t_e p_e = t_e c_e` (`t_e = 1` once `p_e` is rounded);
//! * pin: boundary vertex rows `sum_e sigma_ve p_e = k_v - 4 j_v` that
//!   peeling could not turn into fixes.
//!
//! Objective (eq. 18 with the harmonic minimality (17) as a penalty of
//! weight [`HARMONIC_WEIGHT`], see docs/cone-placement.md):
//! `phiᵀ(alpha L + M/A)phi + W hᵀ M_1 h`;
//! MIQ emulation: `alpha (phiᵀ L phi + hᵀ M_1 h) + phiᵀ M phi / A`.
//! Only values change between rounds, so the symbolic analysis is done once.

use super::dual_tree::{is_free_edge, DualTree};
use super::dual_path::{cycle_transport, segment_phi_coefficients, vertex_cycle, Visit};
use super::harmonic::HarmonicBasis;
use super::{ConeError, RoundingRule};
use crate::linalg::{FixBorder, Kkt, LdltSolver, LinalgError, FactorOptions, Triplet};
use crate::mesh::{TriMesh, NONE};
use std::f64::consts::FRAC_PI_2;
use std::f64::consts::PI;

mod curvature;
mod free_curvature;
mod indices;
mod moves;

use curvature::CurvatureSystem;
use free_curvature::FreeCurvatureSystem;

/// Weight `W` of the harmonic norm `hᵀ M_1 h` beside `phiᵀ(alpha L + M/A)phi`.
/// The paper's minimality (17) is the limit `W -> inf` (lexicographic: h
/// least first, phi at any cost). Rounded that way, Algorithm 1 diverges on
/// components with many boundary loops: once the fixed `p` leave no `h = 0`,
/// every later fix is paid for in `phi` instead of `h`, by cone pairs of
/// growing index (cow `--sharp 30`, a component of 130 loops: relaxed
/// indices -1.4 .. 1.8 at the start, -174 .. 159 twenty rounds later,
/// objective 7.9 -> 8e4, cones down to -43; the map folds). At equal weight
/// the same rounding stays within -5 .. 3 and the cow solves; W = 100 still
/// diverged, W = 10 solved the cow at 30° in 54 s with .39, W = 0.1 as W = 1.
const HARMONIC_WEIGHT: f64 = 1.0;
/// Proximal weight on the free integers (see the assembly).
const P_PROXIMAL: f64 = 1e-8;
/// Relative objective increase accepted when the clean-up cancels a close pair.
pub const MERGE_TOLERANCE: f64 = 0.01;
/// Total rounding allowed per batch and free cluster (Algorithm 1: below 0.5).
const ROUNDING_BATCH: f64 = 0.5;
/// Relative residual the solves of intermediate rounding rounds stop at.
const ROUNDING_TOLERANCE: f64 = 1e-6;
/// Memory budget (in f64s) for the cached columns of the bordered updates.
const BORDER_BUDGET: usize = 8 << 20;
/// Most fixes handled by bordered updates before the KKT is refactorized,
/// and most fixes of one round bordered rather than refactorized. Natively,
/// faer's SIMD dense kernels make a factorization cost only 10-20 bordered
/// columns; in wasm (simplicial, scalar) bordering pays much longer.
/// Measured on the fandisk subdivided to 207 k faces (rounding 20.6 s
/// natively, 40.7 s in wasm; the other target's values cost 4-5 s).
const MAX_BORDER: usize = if cfg!(target_arch = "wasm32") { 96 } else { 48 };
/// A round fixing more than this refactorizes (see [`MAX_BORDER`]).
const MAX_BORDER_BATCH: usize = if cfg!(target_arch = "wasm32") { MAX_BORDER } else { 16 };
/// Largest relative LDLᵀ regularization tried before a solve failure is reported.
const MAX_DELTA: f64 = 1e-4;

/// One vertex's cycle expressed in the path basis.
#[derive(Clone, Debug)]
struct VertexCycle {
    /// `G` indices and signs `sigma_ve`.
    g: Vec<(u32, i32)>,
    /// Geometric holonomy (transport) of the cycle.
    transport: f64,
    /// `j_v`: `(K_v - transport) / 2 pi`, an integer.
    j: i64,
    /// True when the cycle crosses a free port: the row holds for any
    /// `phi` (its continuous `p` absorbs it) and the vertex has no index.
    free: bool,
}

/// Settings of one solve.
#[derive(Clone, Copy, Debug)]
pub struct Weights {
    pub alpha_smooth: f64,
    pub miq: bool,
}

/// The KKT system of one component, its factorization and the rounding state.
pub struct ComponentSystem<'a> {
    mesh: &'a TriMesh,
    pub tree: DualTree,
    pub basis: HarmonicBasis,
    /// Mesh vertex → local index (`NONE` outside the component).
    local: Vec<u32>,
    cycles: Vec<VertexCycle>,
    /// Angle defects (2 pi or pi minus the angle sum) per local vertex.
    defect: Vec<f64>,
    /// Vertex areas per local vertex, and the component's area.
    area: Vec<f64>,
    total_area: f64,
    /// Fixed value of each `p` (`None` while free).
    pub fixed: Vec<Option<i64>>,
    /// Per `G` edge: true for a port of a free boundary edge, whose `p` is
    /// a continuous unknown, never rounded (the frame need not turn with
    /// the boundary there).
    continuous: Vec<bool>,
    n: usize,
    row_fix: usize,
    constraint_rhs: Vec<f64>,
    kkt: Kkt,
    /// The KKT's LDLᵀ, built on the first factorization: a component placed
    /// from coarse indices on an aligned boundary never needs it (every
    /// integer is given, and the curvature equation gives `phi` and `h~`).
    solver: Option<LdltSolver>,
    /// Options of the KKT solver (kept while it is not built).
    solver_options: FactorOptions,
    /// Slot of each fix row's coefficient `t_e` in the KKT values.
    fix_slots: Vec<usize>,
    /// Slot of each fix row's diagonal (`-1` while the row is inactive, so
    /// its multiplier is decoupled; `0` once active).
    fix_diag_slots: Vec<usize>,
    /// Fixes made since the last factorization, solved by bordering.
    border: FixBorder,
    h_scale: f64,
    /// Last solution.
    pub x: Vec<f64>,
    pub residual: f64,
    pub rounds: usize,
    /// Iterative-refinement steps over all solves (a conditioning diagnostic).
    pub refinement_steps: usize,
    /// Upper-triangle triplets of the objective's phi and h blocks.
    objective_terms: Vec<Triplet>,
    /// Upper-triangle triplets of `L` on the local vertices.
    laplacian: Vec<Triplet>,
    /// The path rows' entries on `[phi | h~]` (rows from 0).
    path_rows: Vec<Triplet>,
    /// The curvature equation alone, for trials once every `p` is fixed
    /// (built on first use).
    curvature: Option<CurvatureSystem>,
    /// Its counterpart on a component with a free boundary (built on first use).
    free_curvature: Option<FreeCurvatureSystem>,
    /// Set once the free one failed a solve: trials then use the KKT.
    free_curvature_failed: bool,
    /// How [`Self::round_all`] batches its fixes.
    pub rounding: RoundingRule,
}

impl<'a> ComponentSystem<'a> {
    /// Builds and factorizes the system for the component containing face
    /// `seed`; boundary vertices get the turning integers of `boundary_k`
    /// (indexed by mesh vertex), except where they end a free boundary edge
    /// (`free`, per mesh edge; empty: none free).
    pub fn new(
        mesh: &'a TriMesh,
        seed: u32,
        boundary_k: &[i32],
        free: &[bool],
        weights: Weights,
    ) -> Result<Self, ConeError> {
        let tree = DualTree::new(mesh, seed, free);
        let basis = HarmonicBasis::new(mesh, &tree)?;
        let nv = tree.vertices.len();
        let nh = basis.len();
        let ng = tree.g_edges.len();
        let mut local = vec![NONE; mesh.n_vertices()];
        for (i, &v) in tree.vertices.iter().enumerate() {
            local[v as usize] = i as u32;
        }

        let (area, defect) = vertex_geometry(mesh, &tree, &local);
        let total_area: f64 = area.iter().sum();
        let continuous: Vec<bool> = tree.g_edges.iter().map(|&e| is_free_edge(free, e)).collect();
        let cycles = vertex_cycles(mesh, &tree, &defect, &continuous);
        let BoundaryRows { fixed, pins } = peel_boundary(mesh, &tree, &cycles, boundary_k)?;

        let n = nv + nh + ng;
        let h_scale = if weights.miq { 1.0 } else { HARMONIC_WEIGHT.sqrt() };
        let l = component_laplacian(mesh, &tree);
        let laplacian: Vec<Triplet> = l
            .iter()
            .map(|&(r, c, w)| (local[r] as usize, local[c] as usize, w))
            .filter(|&(lr, lc, _)| lr <= lc)
            .collect();
        let objective_terms = objective_triplets(&laplacian, &area, total_area, &basis, weights);
        let rows = ConstraintRows::assemble(mesh, &tree, &basis, &local, &l, &cycles, &fixed, &pins, h_scale);
        let kkt = Kkt::assemble(&with_proximal(&objective_terms, nv + nh, ng), n, &rows.entries, rows.rhs.len())?;
        let (p0, row_fix) = (nv + nh, rows.row_fix);
        let fix_slots = (0..ng)
            .map(|g| kkt.pattern.slot(p0 + g, n + row_fix + g).expect("fix entry is in the pattern"))
            .collect();
        let fix_diag_slots = (0..ng).map(|g| kkt.pattern.diag_slot(n + row_fix + g)).collect();
        Ok(ComponentSystem {
            mesh,
            tree,
            basis,
            local,
            cycles,
            defect,
            area,
            total_area,
            fixed,
            continuous,
            n,
            row_fix,
            constraint_rhs: rows.rhs,
            kkt,
            solver: None,
            solver_options: FactorOptions { max_refinement_steps: 50, ..FactorOptions::default() },
            fix_slots,
            fix_diag_slots,
            border: FixBorder::default(),
            h_scale,
            x: Vec::new(),
            residual: f64::NAN,
            rounds: 0,
            refinement_steps: 0,
            objective_terms,
            laplacian,
            path_rows: rows.path_rows,
            curvature: None,
            free_curvature: None,
            free_curvature_failed: false,
            rounding: RoundingRule::PerCluster,
        })
    }

    /// True when the component has free boundary edges (continuous `p`).
    pub fn has_free_boundary(&self) -> bool {
        self.continuous.iter().any(|&c| c)
    }

    fn p0(&self) -> usize {
        self.tree.vertices.len() + self.basis.len()
    }

    /// Builds the KKT solver (its symbolic analysis) on first use.
    fn build_kkt_solver(&mut self) -> Result<(), ConeError> {
        if self.solver.is_none() {
            let mut solver = LdltSolver::new(&self.kkt.pattern, &self.kkt.signs)?;
            solver.set_options(self.solver_options);
            self.solver = Some(solver);
        }
        Ok(())
    }

    /// The KKT solver after a factorization ([`Self::refactor_and_solve`]).
    fn factored(&self) -> &LdltSolver {
        self.solver.as_ref().expect("the KKT is factorized before it solves")
    }

    /// Relative residual above which a solve is a failure.
    fn accept_residual(&self) -> f64 {
        self.solver_options.accept_residual.max(self.solver_options.tolerance)
    }

    /// Sets the KKT solver's options (now, or when it is built).
    fn set_solver_options(&mut self, options: FactorOptions) {
        self.solver_options = options;
        if let Some(solver) = &mut self.solver {
            solver.set_options(options);
        }
    }

    /// Refactors the KKT after fixes changed and solves it.
    fn refactor_and_solve(&mut self) -> Result<(), ConeError> {
        for g in 0..self.fixed.len() {
            self.write_fix_row(g);
        }
        // Escalating regularization: a pivot that overflows under the default
        // delta (seen on 200 k-face meshes) is retried with a larger one;
        // iterative refinement against the exact matrix restores accuracy.
        loop {
            self.border.clear();
            self.build_kkt_solver()?;
            let solver = self.solver.as_mut().expect("built above");
            let result = solver.factorize(&self.kkt.values).map_err(ConeError::from).and_then(|()| self.solve_kkt());
            let options = self.solver_options;
            match result {
                Err(ConeError::Solve(
                    LinalgError::ZeroPivot { .. } | LinalgError::NotFinite { .. } | LinalgError::NotConverged { .. },
                )) if options.delta < MAX_DELTA => {
                    self.set_solver_options(FactorOptions { delta: options.delta * 100.0, ..options });
                }
                Ok(()) => {
                    // Rounds until the next factorization change only held fix rows.
                    self.border.set_base(self.rhs(), self.x.clone());
                    return Ok(());
                }
                other => return other,
            }
        }
    }

    /// Refactorizes when the KKT is not factorized or fixes are bordered, so
    /// that blocked solves with the factorization alone see every fix.
    fn factorize_if_stale(&mut self) -> Result<(), ConeError> {
        if self.solver.is_some() && self.border.is_empty() {
            Ok(())
        } else {
            self.refactor_and_solve()
        }
    }

    /// The KKT right-hand side `[0; constraint values]`.
    fn rhs(&self) -> Vec<f64> {
        let mut b = vec![0.0; self.n];
        b.extend_from_slice(&self.constraint_rhs);
        b
    }

    /// True when every `p` is fixed and none is continuous (aligned
    /// boundary): the curvature equation alone then holds `phi` and `h~`.
    fn integers_fixed(&self) -> bool {
        !self.has_free_boundary() && self.fixed.iter().all(Option::is_some)
    }

    /// Solves for `x` with the current fixes: by the curvature equation once
    /// every integer is fixed ([`Self::solve_fixed`]), else by the KKT.
    pub(crate) fn solve_unknowns(&mut self) -> Result<(), ConeError> {
        if self.integers_fixed() {
            self.solve_fixed()
        } else {
            self.solve_kkt()
        }
    }

    /// The curvature equation's right-hand side for vertex indices `k`:
    /// `b_i = (pi/2)(k_i - 4 j_i) - transport_i` (see [`curvature`]).
    fn curvature_rhs(&self, k: &[i64]) -> Vec<f64> {
        k.iter().zip(&self.cycles).map(|(&ki, c)| FRAC_PI_2 * (ki - 4 * c.j) as f64 - c.transport).collect()
    }

    /// `x` with every integer fixed, from the curvature equation: `phi` of
    /// zero `M`-mean with `L phi = (pi/2) sum sigma p - transport` (the
    /// vertex rows of eq. 16), `h~` from the path rows, `p` the fixes; the
    /// multipliers are left 0. The KKT's solution has the same `phi` and
    /// `h~` (the objective only picks `phi`'s constant). `residual` is then
    /// that of the constraint rows.
    fn solve_fixed(&mut self) -> Result<(), ConeError> {
        // The fix rows as active (what a factorization made since the last
        // fixes, with its border, already holds).
        for g in 0..self.fixed.len() {
            self.write_fix_row(g);
        }
        let (nv, nh, p0) = (self.tree.vertices.len(), self.basis.len(), self.p0());
        let b = self.curvature_rhs(&self.vertex_k());
        let row_path = nv.saturating_sub(1);
        let shift: Vec<f64> = (0..nh)
            .map(|l| {
                let g = self.tree.g_index[self.tree.leftovers[l] as usize] as usize;
                self.constraint_rhs[row_path + l] + FRAC_PI_2 * self.fixed[g].expect("every p is fixed") as f64
            })
            .collect();
        let curvature = self.curvature()?;
        let phi = curvature.responses(&b, 1, 1e-12)?[..nv].to_vec();
        let h = curvature.harmonic(&phi, &shift)?;
        let dim = self.kkt.pattern.dim();
        let mut x = vec![0.0; dim];
        x[..nv].copy_from_slice(&phi);
        x[nv..nv + nh].copy_from_slice(&h);
        for (g, f) in self.fixed.iter().enumerate() {
            x[p0 + g] = f.expect("every p is fixed") as f64;
        }
        let rhs = self.rhs();
        let mut kx = vec![0.0; dim];
        self.kkt.pattern.mul_vec(&self.kkt.values, &x, &mut kx)?;
        let r2: f64 = (self.n..dim).map(|i| (rhs[i] - kx[i]).powi(2)).sum();
        let b2: f64 = rhs[self.n..].iter().map(|v| v * v).sum();
        let residual = (r2 / b2.max(f64::MIN_POSITIVE)).sqrt();
        // Integers the rows cannot all meet (e.g. a pin row the given
        // indices contradict) are an error, as the KKT's solve would be.
        if residual.is_nan() || residual > self.accept_residual() {
            return Err(LinalgError::NotConverged { relative_residual: residual, steps: 0 }.into());
        }
        self.residual = residual;
        self.x = x;
        Ok(())
    }

    /// Solves the KKT with the current factorization (and the bordered
    /// fixes made since) and right-hand side, refining against the exact
    /// matrix; factorizes first if it never was.
    pub(crate) fn solve_kkt(&mut self) -> Result<(), ConeError> {
        if self.solver.is_none() {
            return self.refactor_and_solve();
        }
        let b = self.rhs();
        if self.border.is_empty() {
            let (x, info) = self.factored().solve_with_info(&b)?;
            self.refinement_steps += info.refinement_steps;
            self.x = x;
            self.residual = info.relative_residual;
            return Ok(());
        }
        // A border whose Schur complement is singular (a new fix that the
        // held ones already determine) or that refines too little is left
        // to a fresh, regularized factorization.
        let bordered = self.bordered_solve(&b);
        if bordered.is_err() || self.residual > self.accept_residual() {
            return self.refactor_and_solve();
        }
        Ok(())
    }

    /// [`Self::solve`] with bordered fixes: iterative refinement of the
    /// bordered solve against the exact matrix, up to the solver options' limits.
    fn bordered_solve(&mut self, b: &[f64]) -> Result<(), ConeError> {
        let options = self.solver_options;
        let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::MIN_POSITIVE);
        let mut x = self.border.solve(self.factored(), b)?;
        let mut kx = vec![0.0; b.len()];
        for step in 0..=options.max_refinement_steps {
            self.kkt.pattern.mul_vec(&self.kkt.values, &x, &mut kx)?;
            let r: Vec<f64> = b.iter().zip(&kx).map(|(bi, ki)| bi - ki).collect();
            self.residual = r.iter().map(|v| v * v).sum::<f64>().sqrt() / bnorm;
            if self.residual < options.tolerance || step == options.max_refinement_steps {
                break;
            }
            let dx = self.border.solve(self.factored(), &r)?;
            x.iter_mut().zip(&dx).for_each(|(xi, di)| *xi += di);
            self.refinement_steps += 1;
        }
        self.x = x;
        Ok(())
    }

    /// Writes fix row `g` into the KKT values and right-hand side: active
    /// (`p_g = c_g`) once `p_g` is fixed, else decoupled (diagonal `-1`).
    fn write_fix_row(&mut self, g: usize) {
        let fx = self.fixed[g];
        self.kkt.values[self.fix_slots[g]] = if fx.is_some() { 1.0 } else { 0.0 };
        self.kkt.values[self.fix_diag_slots[g]] = if fx.is_some() { 0.0 } else { -1.0 };
        self.constraint_rhs[self.row_fix + g] = fx.unwrap_or(0) as f64;
    }

    /// Makes the fixes of `newly` (indices into `p`) active: by bordered
    /// updates while they are few, else by refactorizing; then solves.
    fn activate_and_solve(&mut self, newly: &[usize]) -> Result<(), ConeError> {
        for &g in newly {
            self.write_fix_row(g);
        }
        let limit = MAX_BORDER.min(BORDER_BUDGET / self.kkt.pattern.dim().max(1));
        if self.border.len() + newly.len() > limit || newly.len() > MAX_BORDER_BATCH {
            return self.refactor_and_solve();
        }
        let (p0, fix0) = (self.p0(), self.n + self.row_fix);
        let fixes: Vec<(usize, usize)> = newly.iter().map(|&g| (p0 + g, fix0 + g)).collect();
        let solver = self.solver.as_ref().expect("rounds start with a factorization");
        self.border.push(solver, &fixes)?;
        self.solve_kkt()
    }

    /// Algorithm 1: solve, fix in every free cluster the `p` nearest to
    /// integers (total rounding below 0.5 per cluster, at least one; see
    /// [`Self::round_batch`]), repeat until all are fixed.
    /// `progress(round, free_left)` is called after every solve.
    pub fn round_all(&mut self, progress: &mut dyn FnMut(usize, usize)) -> Result<(), ConeError> {
        // Rounding decisions need far less than the final accuracy: solve
        // intermediate rounds to ROUNDING_TOLERANCE, the last one exactly.
        let exact = self.solver_options;
        self.set_solver_options(FactorOptions { tolerance: ROUNDING_TOLERANCE.max(exact.tolerance), ..exact });
        let rounded = self.round_loop(progress);
        let options = self.solver_options;
        self.set_solver_options(FactorOptions { tolerance: exact.tolerance, ..options });
        rounded?;
        // Later stages change only right-hand sides: with every integer
        // fixed, the curvature equation; else (free ports) a factorization
        // of the final matrix.
        if self.integers_fixed() || self.border.is_empty() {
            self.solve_unknowns()
        } else {
            self.refactor_and_solve()
        }
    }

    /// The rounds of [`Self::round_all`].
    fn round_loop(&mut self, progress: &mut dyn FnMut(usize, usize)) -> Result<(), ConeError> {
        self.refactor_and_solve()?;
        loop {
            let p0 = self.p0();
            let mut free: Vec<(f64, usize)> = self
                .fixed
                .iter()
                .enumerate()
                .filter(|&(g, f)| f.is_none() && !self.continuous[g])
                .map(|(g, _)| {
                    let v = self.x[p0 + g];
                    ((v - v.round()).abs(), g)
                })
                .collect();
            progress(self.rounds, free.len());
            if free.is_empty() {
                return Ok(());
            }
            free.sort_by(|a, b| a.0.total_cmp(&b.0));
            let batch = self.round_batch(&free);
            for &g in &batch {
                self.fixed[g] = Some(self.x[p0 + g].round() as i64);
            }
            self.rounds += 1;
            self.activate_and_solve(&batch)?;
        }
    }

    /// Step 4 of Algorithm 1 applied per free cluster: in each cluster, the
    /// free `p` nearest to integers whose total rounding stays below 0.5
    /// (at least one). `free` holds `(distance to the nearest integer, g)`,
    /// nearest first. The fixed `p` around a cluster fix its total index, so
    /// clusters are coupled only through the smooth `phi`; rounding them in
    /// the same round takes the late rounds from one or two `p` each to one
    /// batch per cluster (spot: 450 rounds -> 24, bff-bunny: 880 -> 74).
    fn round_batch(&self, free: &[(f64, usize)]) -> Vec<usize> {
        let cluster = match self.rounding {
            RoundingRule::PerCluster => self.free_clusters(free),
            RoundingRule::Whole => vec![0; free.len()],
        };
        // Per cluster: (total rounding, p taken, closed).
        let mut state: std::collections::HashMap<usize, (f64, usize, bool)> = Default::default();
        let mut batch = Vec::new();
        for (&(d, g), &c) in free.iter().zip(&cluster) {
            let s = state.entry(c).or_insert((0.0, 0, false));
            if s.2 {
                continue;
            }
            if s.1 > 0 && s.0 + d >= ROUNDING_BATCH {
                s.2 = true;
                continue;
            }
            s.0 += d;
            s.1 += 1;
            batch.push(g);
        }
        batch
    }

    /// For each `(d, g)` of `free`, the free cluster it belongs to: vertices
    /// joined by free `G` edges or along a free boundary (a representative
    /// vertex).
    fn free_clusters(&self, free: &[(f64, usize)]) -> Vec<usize> {
        let mut clusters = crate::mesh::UnionFind::new(self.tree.vertices.len());
        let ends = |g: usize| self.mesh.edge_vertices(self.tree.g_edges[g]).map(|v| self.local[v as usize]);
        let continuous = (0..self.continuous.len()).filter(|&g| self.continuous[g]);
        for g in free.iter().map(|&(_, g)| g).chain(continuous) {
            let [a, b] = ends(g);
            clusters.union(a, b);
        }
        free.iter().map(|&(_, g)| clusters.find(ends(g)[0]) as usize).collect()
    }

    /// The cone index of every local vertex: `k_v = 4 j_v + sum sigma p`
    /// (all `p` must be fixed).
    pub fn vertex_k(&self) -> Vec<i64> {
        (0..self.cycles.len()).map(|i| self.vertex_k_at(i)).collect()
    }

    /// `phi` per local vertex from the last solve.
    pub fn phi(&self) -> &[f64] {
        &self.x[..self.tree.vertices.len()]
    }

    /// Harmonic coefficients `h` from the last solve.
    pub fn h(&self) -> Vec<f64> {
        let nv = self.tree.vertices.len();
        self.x[nv..nv + self.basis.len()].iter().map(|v| v / self.h_scale).collect()
    }

    /// Local index of mesh vertex `v`.
    pub fn local(&self, v: u32) -> u32 {
        self.local[v as usize]
    }

    /// `phiᵀ M phi / A`: the area-weighted mean of phi² (the distortion proxy).
    pub fn phi_norm2(&self) -> f64 {
        self.phi_norm2_at(&self.x, None)
    }

    /// `phiᵀ (alpha L + M/A) phi` with `alpha` as given.
    pub fn energy(&self, alpha: f64) -> f64 {
        let phi = self.phi();
        let mut e = self.phi_norm2();
        for &f in &self.tree.faces {
            let tri = self.mesh.faces()[f as usize];
            let p = |k: usize| phi[self.local[tri[k] as usize] as usize];
            let cot = self.mesh.corner_cotangents()[f as usize];
            for k in 0..3 {
                // Edge opposite corner k, weight cot(angle k) / 2.
                let (a, b) = (p((k + 1) % 3), p((k + 2) % 3));
                e += alpha * 0.5 * cot[k] * (a - b) * (a - b);
            }
        }
        e
    }

    /// Angle defects per local vertex.
    pub fn defects(&self) -> &[f64] {
        &self.defect
    }

    /// The objective of the last solve: `phiᵀ(alpha L + M/A)phi` plus the
    /// harmonic term ([`HARMONIC_WEIGHT`], or `alpha hᵀM_1h` for MIQ).
    pub fn objective(&self) -> f64 {
        self.objective_at(&self.x, None)
    }

    /// The objective at `x + delta` (`delta` of the length of `x`, if given).
    fn objective_at(&self, x: &[f64], delta: Option<&[f64]>) -> f64 {
        let v = |i: usize| x[i] + delta.map_or(0.0, |d| d[i]);
        self.objective_terms
            .iter()
            .map(|&(r, c, w)| if r == c { w * v(r) * v(c) } else { 2.0 * w * v(r) * v(c) })
            .sum()
    }

    /// `phiᵀ M phi / A` at `x + delta`.
    fn phi_norm2_at(&self, x: &[f64], delta: Option<&[f64]>) -> f64 {
        let v = |i: usize| x[i] + delta.map_or(0.0, |d| d[i]);
        (0..self.area.len()).map(|i| v(i) * v(i) * self.area[i]).sum::<f64>() / self.total_area
    }

    /// The cone index of local vertex `i` (all `p` on its cycle fixed; 0 on
    /// a free boundary).
    pub fn vertex_k_at(&self, i: usize) -> i64 {
        let c = &self.cycles[i];
        if c.free {
            return 0;
        }
        4 * c.j + c.g.iter().map(|&(g, s)| s as i64 * self.fixed[g as usize].unwrap_or(0)).sum::<i64>()
    }
}

/// The system of the component of face 0 of `mesh` at alpha 0.01, with
/// the mesh's own boundary turning (for tests).
#[cfg(test)]
pub(crate) fn test_system(mesh: &TriMesh) -> ComponentSystem<'_> {
    let boundary_k = crate::features::boundary_turning(mesh);
    ComponentSystem::new(mesh, 0, &boundary_k, &[], Weights { alpha_smooth: 0.01, miq: false }).unwrap()
}

/// [`test_system`] with the whole boundary of `mesh` free.
#[cfg(test)]
pub(crate) fn test_system_free(mesh: &TriMesh) -> ComponentSystem<'_> {
    let boundary_k = crate::features::boundary_turning(mesh);
    let free: Vec<bool> = (0..mesh.n_edges() as u32).map(|e| mesh.is_boundary_edge(e)).collect();
    ComponentSystem::new(mesh, 0, &boundary_k, &free, Weights { alpha_smooth: 0.01, miq: false }).unwrap()
}

/// The cotangent Laplacian of the component of `tree` as triplets in mesh
/// vertex indices, summed over its faces in mesh order.
fn component_laplacian(mesh: &TriMesh, tree: &DualTree) -> Vec<Triplet> {
    let mut faces = tree.faces.clone();
    faces.sort_unstable();
    mesh.cotan_laplacian_triplets(faces.iter().copied())
}

/// Upper-triangle triplets of the objective (eq. 18) on `[phi | h~]`:
/// `alpha L + M/A` on phi (`laplacian` in local indices, upper triangle),
/// the Gram matrix of the harmonic basis on `h~` (weight 1, or alpha for
/// MIQ emulation).
fn objective_triplets(laplacian: &[Triplet], area: &[f64], total_area: f64, basis: &HarmonicBasis, weights: Weights) -> Vec<Triplet> {
    let (nv, nh) = (area.len(), basis.len());
    let alpha = weights.alpha_smooth;
    let mut a: Vec<Triplet> = laplacian.iter().map(|&(r, c, w)| (r, c, alpha * w)).collect();
    a.extend(area.iter().enumerate().map(|(i, &ai)| (i, i, ai / total_area)));
    let h_weight = if weights.miq { alpha } else { 1.0 };
    for i in 0..nh {
        for j in i..nh {
            a.push((nv + i, nv + j, h_weight * basis.gram[i][j]));
        }
    }
    a
}

/// The KKT's primal block: `objective` and a tiny proximal term on the `ng`
/// integers from `p0`. It keeps the block definite (the matrix is then
/// quasi-definite and LDLᵀ without pivoting is stable); it is a constant once
/// every p is fixed, so final solutions are unaffected.
fn with_proximal(objective: &[Triplet], p0: usize, ng: usize) -> Vec<Triplet> {
    let mut a = objective.to_vec();
    a.extend((0..ng).map(|g| (p0 + g, p0 + g, P_PROXIMAL)));
    a
}

/// The constraint rows of eq. 16 in the order of the module doc (vertex,
/// path, fix, pin), on the unknowns `[phi | h~ | p]`.
struct ConstraintRows {
    /// Row, column, value.
    entries: Vec<Triplet>,
    /// One right-hand side per row.
    rhs: Vec<f64>,
    /// The path rows' entries (rows counted from 0).
    path_rows: Vec<Triplet>,
    /// First fix row (one per `G` edge, inactive while its `p` is free).
    row_fix: usize,
}

impl ConstraintRows {
    /// All rows: `l` is the component's Laplacian in mesh indices, `local`
    /// maps mesh to local vertices, `fixed` and `pins` come from
    /// [`peel_boundary`], `h_scale` is `sqrt(W)` (1 for MIQ emulation).
    #[allow(clippy::too_many_arguments)]
    fn assemble(
        mesh: &TriMesh,
        tree: &DualTree,
        basis: &HarmonicBasis,
        local: &[u32],
        l: &[Triplet],
        cycles: &[VertexCycle],
        fixed: &[Option<i64>],
        pins: &[(usize, i64)],
        h_scale: f64,
    ) -> Self {
        let mut rows = ConstraintRows { entries: Vec::new(), rhs: Vec::new(), path_rows: Vec::new(), row_fix: 0 };
        let p0 = tree.vertices.len() + basis.len();
        rows.push_vertex_rows(l, local, cycles, p0);
        let (path_start, row_path) = (rows.entries.len(), rows.rhs.len());
        rows.push_path_rows(mesh, tree, basis, local, p0, h_scale);
        rows.path_rows = rows.entries[path_start..].iter().map(|&(r, col, w)| (r - row_path, col, w)).collect();
        rows.row_fix = rows.rhs.len();
        // Fix rows: `t_e p_e = t_e c_e`, `t_e = 1` where peeling fixed `p_e`.
        for (g, f) in fixed.iter().enumerate() {
            let row = rows.rhs.len();
            rows.entries.push((row, p0 + g, if f.is_some() { 1.0 } else { 0.0 }));
            rows.rhs.push(f.unwrap_or(0) as f64);
        }
        // Pin rows: `sum_e sigma_ve p_e = k_v - 4 j_v`.
        for &(i, target) in pins {
            let row = rows.rhs.len();
            rows.entries.extend(cycles[i].g.iter().map(|&(g, s)| (row, p0 + g as usize, s as f64)));
            rows.rhs.push(target as f64);
        }
        rows
    }

    /// Vertex rows `(L phi)_v - (pi/2) sum_e sigma_ve p_e = -transport(gamma_v)`
    /// for every local vertex but the last (the rows sum to zero).
    fn push_vertex_rows(&mut self, l: &[Triplet], local: &[u32], cycles: &[VertexCycle], p0: usize) {
        let nv = cycles.len();
        for &(r, col, w) in l {
            let (lr, lc) = (local[r], local[col]);
            if lr != NONE && (lr as usize) + 1 < nv {
                self.entries.push((lr as usize, lc as usize, w));
            }
        }
        for (i, cycle) in cycles.iter().enumerate().take(nv.saturating_sub(1)) {
            self.entries.extend(cycle.g.iter().map(|&(g, s)| (i, p0 + g as usize, -FRAC_PI_2 * s as f64)));
            self.rhs.push(-cycle.transport);
        }
    }

    /// Path rows (`G_path`, one per leftover edge of the tree):
    /// `B_phi phi + B_h h - (pi/2) p_l = -transport(C_l)` with eq. 11's
    /// coefficients along the fundamental cycle and `h = h~ / h_scale`.
    fn push_path_rows(&mut self, mesh: &TriMesh, tree: &DualTree, basis: &HarmonicBasis, local: &[u32], p0: usize, h_scale: f64) {
        let h0 = tree.vertices.len();
        for &e in &tree.leftovers {
            let row = self.rhs.len();
            let cycle = tree.fundamental_cycle(mesh, e);
            for visit in &cycle {
                let coef = segment_phi_coefficients(mesh, *visit);
                let tri = mesh.faces()[(visit.h_in / 3) as usize];
                for k in 0..3 {
                    self.entries.push((row, local[tri[k] as usize] as usize, coef[k]));
                }
            }
            for j in 0..basis.len() {
                self.entries.push((row, h0 + j, basis.path_integral(j, &cycle) / h_scale));
            }
            self.entries.push((row, p0 + tree.g_index[e as usize] as usize, -FRAC_PI_2));
            self.rhs.push(-cycle_transport(mesh, &cycle));
        }
    }
}

/// Per local vertex of the component of `tree`: its barycentric area (a third
/// of each incident face's) and its angle defect (sec. 5.2: `2π − Σθ` inside,
/// `π − Σθ` on the boundary), summed over `tree.faces` in that order.
fn vertex_geometry(mesh: &TriMesh, tree: &DualTree, local: &[u32]) -> (Vec<f64>, Vec<f64>) {
    let nv = tree.vertices.len();
    let mut angle_sum = vec![0.0; nv];
    let mut area = vec![0.0; nv];
    let (angles, areas) = (mesh.corner_angles(), mesh.face_areas());
    for &f in &tree.faces {
        let tri = mesh.faces()[f as usize];
        let a = areas[f as usize];
        for k in 0..3 {
            let i = local[tri[k] as usize] as usize;
            angle_sum[i] += angles[f as usize][k];
            area[i] += a / 3.0;
        }
    }
    let defect = tree
        .vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| if mesh.is_boundary_vertex(v) { PI } else { 2.0 * PI } - angle_sum[i])
        .collect();
    (area, defect)
}

/// The dual cycle of every local vertex in the path basis of `tree`, with its
/// transport and `j_v = (K_v − transport) / 2π` (rounded: an integer up to
/// round-off); `continuous` marks the `G` edges whose `p` is free.
fn vertex_cycles(mesh: &TriMesh, tree: &DualTree, defect: &[f64], continuous: &[bool]) -> Vec<VertexCycle> {
    tree.vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let cycle = vertex_cycle(mesh, v);
            let transport = cycle_transport(mesh, &cycle);
            let j = ((defect[i] - transport) / (2.0 * PI)).round() as i64;
            let g = cycle_signs(mesh, tree, &cycle);
            let free = g.iter().any(|&(g, _)| continuous[g as usize]);
            VertexCycle { g, transport, j, free }
        })
        .collect()
}

/// Boundary turning (sec. 5): the cycle of a boundary vertex (not on a free
/// edge) must sum to its turning integer `boundary_k[v] − 4 j_v`. Rows that
/// leave a single `p` unknown fix it, repeatedly; returns those fixes (per `G`
/// edge) and the rows left over as `(local vertex, target)` pins, reduced to an
/// independent set (a repeated pin would make the KKT singular; the boundary
/// rows of a component are consistent, so the dropped ones hold too). Errs
/// when a fully known row disagrees with its target.
fn peel_boundary(
    mesh: &TriMesh,
    tree: &DualTree,
    cycles: &[VertexCycle],
    boundary_k: &[i32],
) -> Result<BoundaryRows, ConeError> {
    let ng = tree.g_edges.len();
    let mut fixed: Vec<Option<i64>> = vec![None; ng];
    let target = |i: usize| boundary_k[tree.vertices[i] as usize] as i64 - 4 * cycles[i].j;
    let mut pending: Vec<usize> =
        (0..cycles.len()).filter(|&i| mesh.is_boundary_vertex(tree.vertices[i]) && !cycles[i].free).collect();
    loop {
        let mut progress = false;
        let mut still = Vec::new();
        for &i in &pending {
            let unknown: Vec<&(u32, i32)> = cycles[i].g.iter().filter(|(g, _)| fixed[*g as usize].is_none()).collect();
            let known: i64 = cycles[i].g.iter().filter_map(|&(g, s)| fixed[g as usize].map(|p| s as i64 * p)).sum();
            match unknown.len() {
                0 => {
                    if known != target(i) {
                        return Err(ConeError::InconsistentBoundary { vertex: tree.vertices[i] });
                    }
                    progress = true;
                }
                1 => {
                    let (g, s) = *unknown[0];
                    fixed[g as usize] = Some((target(i) - known) * s as i64);
                    progress = true;
                }
                _ => still.push(i),
            }
        }
        pending = still;
        if !progress || pending.is_empty() {
            break;
        }
    }
    let mut rows: Vec<Vec<(usize, i64)>> = (0..ng).filter(|&g| fixed[g].is_some()).map(|g| vec![(g, 1)]).collect();
    let n_fixed_rows = rows.len();
    rows.extend(pending.iter().map(|&i| cycles[i].g.iter().map(|&(g, s)| (g as usize, s as i64)).collect()));
    let keep = crate::linalg::independent_rows(&rows, ng);
    let pins = pending.iter().zip(&keep[n_fixed_rows..]).filter(|(_, &k)| k).map(|(&i, _)| (i, target(i))).collect();
    Ok(BoundaryRows { fixed, pins })
}

/// What [`peel_boundary`] leaves for the KKT: the `p` it fixed and the rows to pin.
struct BoundaryRows {
    /// Per `G` edge, the value of `p` when a boundary row determines it.
    fixed: Vec<Option<i64>>,
    /// Independent boundary rows left: `(local vertex, target)`.
    pins: Vec<(usize, i64)>,
}

/// The `G` edges a cycle crosses, with the sign `+1` when the cycle crosses
/// in the orientation of the edge's fundamental cycle.
fn cycle_signs(mesh: &TriMesh, tree: &DualTree, cycle: &[Visit]) -> Vec<(u32, i32)> {
    let mut out = Vec::new();
    for (i, visit) in cycle.iter().enumerate() {
        let next = cycle[(i + 1) % cycle.len()];
        let e = mesh.edge(visit.h_out);
        if mesh.twin(visit.h_out) == next.h_in {
            let g = tree.g_index[e as usize];
            if g != NONE {
                let s = if mesh.edge_halfedges(e)[0] == visit.h_out { 1 } else { -1 };
                out.push((g, s));
            }
        } else {
            // Through the outer node: leave by a port, enter by another.
            let g_out = tree.g_index[e as usize];
            if g_out != NONE {
                out.push((g_out, -1));
            }
            let g_in = tree.g_index[mesh.edge(next.h_in) as usize];
            if g_in != NONE {
                out.push((g_in, 1));
            }
        }
    }
    out
}

