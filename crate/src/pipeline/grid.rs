//! The integer-grid map of a solved map ([`crate::param::quantize`]), solved again
//! on a finer mesh where the input's long edges leave the grid map folded.

use super::{long_edges_refine, Solution, SolveOptions, SolveProgress};
use crate::features::FeatureSet;
use crate::mesh::TriMesh;
use crate::param::quantize::{GridSize, IntegerGridMap, QuantizeError, QuantizeOptions, QuantizeReport};

/// An integer-grid map and the solution it quantizes (the one given to
/// [`grid_map`], or the one solved again on the refinement of the input).
pub struct GridMapped<'a> {
    pub solution: Solution<'a>,
    pub map: IntegerGridMap,
}

/// The integer-grid map of `solution` (solved on `mesh` with `features` and
/// `options`) for `size`. Where it folds (flipped triangles or vertices it
/// winds around) and `mesh` has edges longer than a quad mesh of `size`
/// keeps ([`long_edges_refine`]: a low-poly CAD export), the map is solved
/// again on that refinement and the grid map that folds less is kept (an
/// extruded 12-point star with a bore, 288 faces, at 2 000-4 000 cells: 2-3
/// flipped triangles on the input's, none on the refinement's). A failure
/// of that second solve or quantization keeps the first map.
/// `solve_progress` reports the second solve, `progress` each quantization.
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
    let faults = |r: &QuantizeReport| r.flipped + r.wound_vertices;
    let map = solution.quantizer()?.quantize_with(&solution.mesh, size, quantize, progress)?;
    let first = GridMapped { solution, map };
    if faults(&first.map.report) == 0 {
        return Ok(first);
    }
    let Some(refine) = long_edges_refine(mesh, &options.refine, Some(size)) else {
        return Ok(first);
    };
    let again = super::solve(mesh, features, &SolveOptions { refine, ..*options }, solve_progress).ok().and_then(|solution| {
        let map = solution.quantizer().ok()?.quantize_with(&solution.mesh, size, quantize, progress).ok()?;
        Some(GridMapped { solution, map })
    });
    Ok(match again {
        Some(again) if faults(&again.map.report) < faults(&first.map.report) => again,
        _ => first,
    })
}
