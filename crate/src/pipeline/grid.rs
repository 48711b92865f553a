//! The integer-grid map of a solved map ([`crate::param::quantize`]), solved again
//! on a finer mesh where the input's long edges leave the grid map folded,
//! and without the feature curves the grid is too coarse to follow where
//! they fold it.

use super::{long_edges_refine, quad_length, Solution, SolveOptions, SolveProgress};
use crate::features::{finer_than_grid, FeatureSet};
use crate::mesh::TriMesh;
use crate::param::quantize::{GridSize, IntegerGridMap, QuantizeError, QuantizeOptions};

/// An integer-grid map and the solution it quantizes (the one given to
/// [`grid_map`], or the one solved again on the refinement of the input or
/// without the features in `dropped_features`).
pub struct GridMapped<'a> {
    pub solution: Solution<'a>,
    pub map: IntegerGridMap,
    /// The input's feature edges the map was solved without
    /// ([`finer_than_grid`]); empty where every feature was kept.
    pub dropped_features: FeatureSet,
}

/// The integer-grid map of `solution` (solved on `mesh` with `features` and
/// `options`) for `size`. Where it folds (flipped triangles or vertices it
/// winds around) and `mesh` has edges longer than a quad mesh of `size`
/// keeps ([`long_edges_refine`]: a low-poly CAD export), the map is solved
/// again on that refinement and the grid map that folds less is kept (an
/// extruded 12-point star with a bore, 288 faces, at 2 000-4 000 cells: 2-3
/// flipped triangles on the input's, none on the refinement's). A failure
/// of that second solve or quantization keeps the first map.
///
/// Where the map kept still folds and some feature curves are finer than
/// the grid ([`finer_than_grid`]: short dangling branches and small
/// loops, whose corner cones the rounding must put on grid points a cell
/// apart), the map is solved again without them and kept if it folds less
/// (teapot with creases above 60° at 3 000 quads: the map winds around 6
/// vertices with the spout's lip, none without it). A map that follows
/// every feature wins ties. With such curves, the first rounding stops
/// after its plain pass where that leaves a hopeless map
/// ([`QuantizeOptions::plain_only_if_hopeless`]: bff-face with creases
/// above 60° at 1 000 quads, about 500 -> 67 s for the same quads; cow at
/// 3 000, 103 -> 64 s), and runs its other passes only where the map
/// without them folds no less.
/// `solve_progress` reports the other solves, `progress` each quantization.
pub fn grid_map<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    solution: Solution<'a>,
    size: GridSize,
    quantize: &QuantizeOptions,
    solve_progress: &mut dyn FnMut(SolveProgress),
    progress: &mut dyn FnMut(usize, usize),
) -> Result<GridMapped<'a>, QuantizeError> {
    // With curves to drop, a hopeless first rounding stops after its plain
    // pass (and runs in full below only if dropping them does not help).
    let dropped = finer_than_grid(mesh, features, quad_length(mesh, size));
    let first = QuantizeOptions { plain_only_if_hopeless: !dropped.is_empty(), ..*quantize };
    let map = solution.quantizer()?.quantize_with(&solution.mesh, size, &first, progress)?;
    let mut best = GridMapped { solution, map, dropped_features: FeatureSet::none(mesh) };
    if best.map.report.folds() == 0 {
        return Ok(best);
    }
    let mut options = *options;
    if let Some(refine) = long_edges_refine(mesh, &options.refine, Some(size)) {
        options.refine = refine;
        if let Some(again) = solve_and_quantize(mesh, features, &options, size, quantize, solve_progress, progress) {
            keep_fewer_folds(&mut best, again);
        }
    }
    if best.map.report.folds() > 0 && !dropped.is_empty() {
        let kept = features.without(&dropped);
        if let Some(again) = solve_and_quantize(mesh, &kept, &options, size, quantize, solve_progress, progress) {
            let solution = again.solution.into_owned();
            keep_fewer_folds(&mut best, GridMapped { solution, map: again.map, dropped_features: dropped });
        }
    }
    if best.map.report.passes_skipped {
        let map = best.solution.quantizer()?.quantize_with(&best.solution.mesh, size, quantize, progress)?;
        // Every pass includes the plain one: no worse, and complete.
        if map.report.folds() <= best.map.report.folds() {
            best.map = map;
        }
    }
    Ok(best)
}

/// The grid map of `mesh` solved with `features` and `options` (`None`
/// where the solve or the quantization fails).
fn solve_and_quantize<'a>(
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &SolveOptions,
    size: GridSize,
    quantize: &QuantizeOptions,
    solve_progress: &mut dyn FnMut(SolveProgress),
    progress: &mut dyn FnMut(usize, usize),
) -> Option<GridMapped<'a>> {
    let solution = super::solve(mesh, features, options, solve_progress).ok()?;
    let map = solution.quantizer().ok()?.quantize_with(&solution.mesh, size, quantize, progress).ok()?;
    Some(GridMapped { solution, map, dropped_features: FeatureSet::none(mesh) })
}

/// `candidate` in place of `best` where its map has fewer [`crate::param::quantize::QuantizeReport::folds`].
fn keep_fewer_folds<'a>(best: &mut GridMapped<'a>, candidate: GridMapped<'a>) {
    if candidate.map.report.folds() < best.map.report.folds() {
        *best = candidate;
    }
}
