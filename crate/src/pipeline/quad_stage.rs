//! The quad mesh of an input for a grid, as every front door makes it:
//! the integer-grid map ([`GridStage`]), the quads traced on it
//! ([`extract_quads_along`]) and their figures against the input
//! ([`check_quads`]). A mesh much finer than its quads is traced on a
//! decimation ([`Coarse`]) and the quads moved onto the input
//! ([`project_onto`]); where those quads fold, or their Euler
//! characteristic or boundary loops are not the input's, they are traced
//! again on a decimation twice as fine (on the input below twice that),
//! and the better quads are kept (the input's topology first, then fewer
//! folds, then nearer the input; measured in `docs/STATUS.md`, sessions
//! 43 and 44). [`QuadStage`] keeps its solves for the next grid
//! (the page's quad-count slider re-runs only the quantization where the
//! mesh is solved whole, and the decimation's solve where it is not).

use super::{solve, Coarse, GridFeatures, GridMapped, GridStage, LongEdges, RefineOptions, Solution, SolveError, SolveOptions, SolveProgress, COARSE_FACES_PER_QUAD};
use crate::clock::Stopwatch;
use crate::features::FeatureSet;
use crate::mesh::TriMesh;
use crate::param::quantize::{GridSize, IntegerGridMap, QuantizeError, QuantizeOptions};
use crate::quads::{check_quads, extract_quads_along, project_onto, CheckOptions, ExtractError, ExtractOptions, QuadMesh, QuadReport};

/// Settings of [`QuadStage`].
#[derive(Clone, Copy, Debug, Default)]
pub struct QuadOptions {
    /// The solve's settings. `refine.max_edge_length` `None`: that of
    /// [`RefineOptions::for_quads`] on the mesh solved (the input or its
    /// decimation) for the grid asked for.
    pub solve: SolveOptions,
    pub quantize: QuantizeOptions,
    /// Trace on the input only, never on a decimation.
    pub full_mesh: bool,
}

/// Where a [`QuadStage`] is in a request.
#[derive(Clone, Debug, PartialEq)]
pub enum QuadProgress {
    /// Decimating the input (faces per quad asked for).
    Decimate { faces_per_quad: f64 },
    Solve(SolveProgress),
    /// A quantization's rounding: integers rounded of those to round.
    Quantize { done: usize, total: usize },
    Extract,
}

/// Why a request gave no quads: the solve of the input (a decimation's
/// failing solve falls back to the input's), the quantization of its map,
/// or the extraction.
#[derive(Clone, Debug)]
pub enum QuadsError {
    Solve(SolveError),
    Quantize(QuantizeError),
    Extract(ExtractError),
}

impl std::fmt::Display for QuadsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QuadsError::Solve(e) => e.fmt(f),
            QuadsError::Quantize(e) => e.fmt(f),
            QuadsError::Extract(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for QuadsError {}

/// Seconds a request spent per stage, summed over its attempts.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct QuadTimings {
    pub decimate: f64,
    /// Cones and the seamless map (of the first solve; the grid stage's
    /// solves again count as quantization).
    pub solve: f64,
    pub quantize: f64,
    pub extract: f64,
    pub check: f64,
}

/// The decimation quads were traced on.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Decimation {
    pub faces: usize,
    pub vertices: usize,
    /// The largest distance a quad vertex moved onto the input.
    pub largest_projection: f64,
}

/// How a request's attempts went, beside the quads kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attempts {
    /// One attempt, on the input or a decimation.
    Once,
    /// The decimation's map could not be solved: traced on the input.
    DecimationUnsolved,
    /// The decimation's quads folded: traced again on a decimation twice
    /// as fine (`on_input`: on the input), the better kept.
    Retried { on_input: bool },
}

/// The quads of a request and what they were traced from.
pub struct TracedQuads {
    /// The map quantized: of the input, its refinement, or the decimation.
    pub solution: Solution<'static>,
    pub map: IntegerGridMap,
    /// The input's feature edges the map was solved without.
    pub dropped_features: FeatureSet,
    /// Opposite cone pairs cancelled for the grid ([`GridMapped`]).
    pub cancelled_pairs: usize,
    pub quads: QuadMesh,
    /// The quads' figures against the input (where the map was solved on
    /// the input's refinement, against that).
    pub report: QuadReport,
    pub decimation: Option<Decimation>,
    pub attempts: Attempts,
    /// Attempts made (each a solve, its quantization and extraction).
    pub traced: usize,
    pub timings: QuadTimings,
}

impl TracedQuads {
    /// Defect places, flipped and degenerate quads.
    pub fn folds(&self) -> usize {
        self.report.defects + self.report.flipped_quads + self.report.degenerate_quads
    }

    /// The larger of the two one-sided distances (relative), 0 where unmeasured.
    fn distance(&self) -> f64 {
        let r = &self.report;
        r.distance_input_to_quads_relative.unwrap_or(0.0).max(r.distance_quads_to_input_relative.unwrap_or(0.0))
    }

    /// Whether the quads' Euler characteristic or boundary loops differ
    /// from `input`'s (a piece pinched off, a hole left open).
    fn topology_differs(&self, input: &TriMesh) -> bool {
        (self.report.euler_characteristic, self.report.boundary_loops) != (input.euler_characteristic(), input.boundary_loops().len())
    }

    /// The one with the input's topology, then fewer folds, then nearer
    /// the input (ties: `a`), with the timings and attempts of both. (A
    /// retry of cow x16 at 1 000 quads on a coarser decimation had one
    /// fold fewer and Euler characteristic 4.)
    fn better(input: &TriMesh, a: TracedQuads, b: TracedQuads) -> TracedQuads {
        let (ta, tb) = (a.timings, b.timings);
        let timings = QuadTimings {
            decimate: ta.decimate + tb.decimate,
            solve: ta.solve + tb.solve,
            quantize: ta.quantize + tb.quantize,
            extract: ta.extract + tb.extract,
            check: ta.check + tb.check,
        };
        let traced = a.traced + b.traced;
        let key = |t: &TracedQuads| (t.topology_differs(input), t.folds(), t.distance());
        let mut kept = if key(&b) < key(&a) { b } else { a };
        (kept.timings, kept.traced) = (timings, traced);
        kept
    }
}

/// A decimation solved for a grid, kept for the same request.
struct CoarseSolve {
    key: (GridSize, u64, FeatureSet),
    coarse: Coarse,
    /// Its grid stage; `None` where its solve failed.
    stage: Option<GridStage>,
}

/// The quads of one input for any grid, with its solves kept: those of the
/// input (by the features solved with) and the last decimations.
pub struct QuadStage {
    features: GridFeatures,
    options: QuadOptions,
    /// Grid stages of the input: the first solved with `features` or
    /// given, then at most one with the features a retry kept.
    full: Vec<GridStage>,
    coarse: Vec<CoarseSolve>,
}

/// Decimations a [`QuadStage`] keeps (a request makes at most two), and
/// solves of the whole input (each holds a map of every face).
const KEPT_DECIMATIONS: usize = 2;
const KEPT_FULL: usize = 2;

impl QuadStage {
    /// The stage of an input with `features`.
    pub fn new(features: GridFeatures, options: QuadOptions) -> QuadStage {
        QuadStage { features, options, full: Vec::new(), coarse: Vec::new() }
    }

    /// The stage of an input whose map with `stage.features()` was solved
    /// already (the page's solve, kept for its quads).
    pub fn with_solved(stage: GridStage, features: GridFeatures, options: QuadOptions) -> QuadStage {
        QuadStage { features, options, full: vec![stage], coarse: Vec::new() }
    }

    /// The input's features the stage solves with.
    pub fn features(&self) -> &GridFeatures {
        &self.features
    }

    /// The quads of `input` (the mesh the stage's features are of) for
    /// `grid`: on a decimation where `input` has more than twice
    /// [`COARSE_FACES_PER_QUAD`] faces per quad, with the fallbacks of the
    /// module doc (a retry where those quads fold or have another topology
    /// than `input`); on `input` otherwise.
    pub fn quads(&mut self, input: &TriMesh, grid: GridSize, progress: &mut dyn FnMut(QuadProgress)) -> Result<TracedQuads, QuadsError> {
        let all = self.features.clone();
        let first = match self.trace_coarse(input, &all, grid, COARSE_FACES_PER_QUAD, progress) {
            Some(Ok(traced)) => traced,
            Some(Err(decimate)) => {
                let mut traced = self.trace_full(input, &all, grid, progress)?;
                traced.attempts = Attempts::DecimationUnsolved;
                traced.timings.decimate += decimate;
                return Ok(traced);
            }
            None => return self.trace_full(input, &all, grid, progress),
        };
        if first.folds() == 0 && !first.topology_differs(input) {
            return Ok(first);
        }
        // With the features the first kept, none dropped again: one solve
        // and rounding (the creases of an organic part folding the map
        // cost several: cow subdivided twice at 3 000 quads, 400 s).
        let kept = GridFeatures::asked(input, all.all.without(&first.dropped_features));
        let (again, on_input) = match self.trace_coarse(input, &kept, grid, 2.0 * COARSE_FACES_PER_QUAD, progress) {
            Some(Ok(again)) => (Some(again), false),
            Some(Err(_)) => (None, false),
            None => (self.trace_full(input, &kept, grid, progress).ok(), true),
        };
        let mut kept = match again {
            Some(mut again) => {
                again.dropped_features.union(&first.dropped_features);
                TracedQuads::better(input, first, again)
            }
            None => first,
        };
        kept.attempts = Attempts::Retried { on_input };
        Ok(kept)
    }

    /// The quads traced on a decimation of `input` to `faces_per_quad`
    /// faces per quad of `grid`, keeping the vertices of every feature of
    /// the stage; `None` where the input is not fine enough to decimate
    /// (or the stage traces on the full mesh only), `Some(Err(seconds))`
    /// where the decimation's map could not be solved or quantized.
    fn trace_coarse(
        &mut self,
        input: &TriMesh,
        features: &GridFeatures,
        grid: GridSize,
        faces_per_quad: f64,
        progress: &mut dyn FnMut(QuadProgress),
    ) -> Option<Result<TracedQuads, f64>> {
        if self.options.full_mesh || !Coarse::wanted(input, grid, faces_per_quad) {
            return None;
        }
        let key = (grid, faces_per_quad.to_bits(), features.all.clone());
        let mut timings = QuadTimings::default();
        if !self.coarse.iter().any(|c| c.key == key) {
            let mut clock = Stopwatch::start();
            progress(QuadProgress::Decimate { faces_per_quad });
            let coarse = Coarse::for_quads(input, &self.features.all, grid, faces_per_quad)?;
            timings.decimate = clock.lap();
            let solved = coarse.grid_features(input, features);
            let options = self.solve_options(&coarse.mesh, grid);
            let solution = solve(&coarse.mesh, &solved.all, &options, &mut |p| progress(QuadProgress::Solve(p))).map(Solution::into_owned);
            let stage = solution.ok().map(|s| GridStage::new(s, solved, options, LongEdges::RefineFirst));
            timings.solve = clock.lap();
            if self.coarse.len() == KEPT_DECIMATIONS {
                self.coarse.remove(0);
            }
            self.coarse.push(CoarseSolve { key: key.clone(), coarse, stage });
        }
        let (quantize, sharp) = (self.options.quantize, &self.features.all);
        let CoarseSolve { coarse, stage, .. } = self.coarse.iter_mut().find(|c| c.key == key).expect("kept above");
        let spent = timings.decimate + timings.solve;
        let Some(stage) = stage else { return Some(Err(spent)) };
        let traced = trace(input, Some(coarse), stage, sharp, grid, &quantize, progress);
        Some(traced.map(|t| TracedQuads { timings: QuadTimings { decimate: timings.decimate, solve: timings.solve, ..t.timings }, ..t }).map_err(|_| spent))
    }

    /// The quads traced on `input` solved with `features` (a stage kept
    /// for them, or solved now).
    fn trace_full(&mut self, input: &TriMesh, features: &GridFeatures, grid: GridSize, progress: &mut dyn FnMut(QuadProgress)) -> Result<TracedQuads, QuadsError> {
        let mut clock = Stopwatch::start();
        let at = match self.full.iter().position(|s| s.features() == &features.all) {
            Some(at) => at,
            None => {
                let options = self.solve_options(input, grid);
                let solution = solve(input, &features.all, &options, &mut |p| progress(QuadProgress::Solve(p))).map_err(QuadsError::Solve)?;
                if self.full.len() == KEPT_FULL {
                    self.full.pop();
                }
                self.full.push(GridStage::new(solution, features.clone(), options, LongEdges::RefineFirst));
                self.full.len() - 1
            }
        };
        let solve = clock.lap();
        let quantize = self.options.quantize;
        let mut traced = trace(input, None, &mut self.full[at], &self.features.all, grid, &quantize, progress)?;
        traced.timings.solve = solve;
        Ok(traced)
    }

    /// The stage's settings for a solve of `mesh` for quads of `grid`.
    fn solve_options(&self, mesh: &TriMesh, grid: GridSize) -> SolveOptions {
        let refine = self.options.solve.refine;
        let max_edge_length = refine.max_edge_length.or(RefineOptions::for_quads(mesh, grid).max_edge_length);
        SolveOptions { refine: RefineOptions { max_edge_length, ..refine }, ..self.options.solve }.for_quads(mesh, grid)
    }
}

/// The quads of `stage`'s map for `grid`, traced on `coarse` (a decimation
/// of `input`) and moved onto `input`, or traced on `input` where `coarse`
/// is `None`; their figures against `input` with its feature edges `sharp`.
fn trace(
    input: &TriMesh,
    coarse: Option<&Coarse>,
    stage: &mut GridStage,
    sharp: &FeatureSet,
    grid: GridSize,
    quantize: &QuantizeOptions,
    progress: &mut dyn FnMut(QuadProgress),
) -> Result<TracedQuads, QuadsError> {
    let mut clock = Stopwatch::start();
    let mesh = coarse.map_or(input, |c| &c.mesh);
    let mapped = {
        let progress = std::cell::RefCell::new(&mut *progress);
        let solving = &mut |p| (progress.borrow_mut())(QuadProgress::Solve(p));
        let quantizing = &mut |done, total| (progress.borrow_mut())(QuadProgress::Quantize { done, total });
        stage.map(mesh, grid, quantize, solving, quantizing)
    };
    let GridMapped { solution, map, dropped_features, cancelled_pairs } = mapped.map_err(QuadsError::Quantize)?;
    let quantize_seconds = clock.lap();
    progress(QuadProgress::Extract);
    // On a decimation, the quads are untangled once they are on the input.
    let extract_options = ExtractOptions { untangle: coarse.is_none(), ..ExtractOptions::default() };
    let mut quads = extract_quads_along(&solution.mesh, &solution.features, &map.uv, &extract_options).map_err(QuadsError::Extract)?;
    let (dropped_features, decimation) = match coarse {
        Some(c) => {
            let largest_projection = project_onto(&mut quads, &solution.mesh, input, sharp);
            let decimation = Decimation { faces: c.mesh.n_faces(), vertices: c.mesh.n_vertices(), largest_projection };
            (c.input_features(input, &dropped_features), Some(decimation))
        }
        None => (dropped_features, None),
    };
    let extract = clock.lap();
    // Every feature solved for (detected creases too), the dropped ones too,
    // on the input (or where it was solved on a refinement, on that).
    let (checked_mesh, sharp) = match coarse {
        Some(_) => (input, sharp.edges().collect()),
        None => (&*solution.mesh, solution.solved_edges_of(sharp)),
    };
    let report = check_quads(checked_mesh, &quads, &CheckOptions { sharp_edges: &sharp, ..CheckOptions::default() });
    let check = clock.lap();
    Ok(TracedQuads {
        solution: solution.clone(),
        map,
        dropped_features,
        cancelled_pairs,
        quads,
        report,
        decimation,
        attempts: Attempts::Once,
        traced: 1,
        timings: QuadTimings { decimate: 0.0, solve: 0.0, quantize: quantize_seconds, extract, check },
    })
}
