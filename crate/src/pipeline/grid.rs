//! The integer-grid map of a solved map ([`crate::param::quantize`]) and
//! the solves it may need again: on a finer mesh where the input's long
//! edges are too coarse for the grid, with the grid's close opposite cones
//! cancelled, and without the feature curves the grid is too coarse to
//! follow where they fold it. [`GridStage`] keeps those solves for the next
//! grid size (the page's quad-count slider); [`grid_map`] is one request.

use super::{long_edges_refine, quad_length, solve, RefineOptions, Solution, SolveOptions, SolveProgress};
use crate::cones;
use crate::features::{chains_near, finer_than_grid, FeatureSet};
use crate::mesh::TriMesh;
use crate::param::quantize::{GridSize, IntegerGridMap, QuantizeError, QuantizeOptions, Quantizer};

/// An integer-grid map and the solution it quantizes: the one solved first,
/// or one solved again (on the refinement of the input, with
/// `cancelled_pairs` cone pairs cancelled, or without `dropped_features`).
/// `S` is the solution or a reference to it.
pub struct GridMapped<S> {
    pub solution: S,
    pub map: IntegerGridMap,
    /// The input's feature edges the map was solved without
    /// ([`finer_than_grid`]); empty where every feature was kept.
    pub dropped_features: FeatureSet,
    /// Opposite cone pairs of the first solve cancelled for this grid
    /// ([`SolveOptions::for_quads`]); 0 where the map solved without
    /// `dropped_features` is used (that solve cancels its own, uncounted).
    pub cancelled_pairs: usize,
}

/// When a map solved on a mesh with edges longer than the grid wants
/// ([`long_edges_refine`]: a low-poly CAD export) is solved again on its
/// refinement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LongEdges {
    /// Before the first quantization: a quad mesh wants vertices where its
    /// quads bend.
    RefineFirst,
    /// Only where the grid map folds, keeping the map that folds less: a
    /// UV map keeps the input's triangles where it can (an extruded
    /// 12-point star with a bore, 288 faces, at 2 000-4 000 cells: 2-3
    /// flipped triangles on the input's, none on the refinement's).
    RefineWhereFolded,
}

/// The feature edges of a grid map's solve: every one (`all`), and those
/// of them found for the caller rather than asked for (`detected`: the
/// creases of [`crate::features::CREASES`] where no features were given),
/// which the stage drops on each component where the map folds.
#[derive(Clone, Debug)]
pub struct GridFeatures {
    pub all: FeatureSet,
    pub detected: FeatureSet,
}

impl GridFeatures {
    /// Only features asked for, of `mesh`'s edges.
    pub fn asked(mesh: &TriMesh, features: FeatureSet) -> GridFeatures {
        GridFeatures { all: features, detected: FeatureSet::none(mesh) }
    }

    /// Only creases found for the caller (every one droppable).
    pub fn detected(creases: FeatureSet) -> GridFeatures {
        GridFeatures { all: creases.clone(), detected: creases }
    }

    /// Features `all`, of which those also in `creases` were found for the
    /// caller (the page's "Creases" button) and are droppable.
    pub fn with_creases(all: FeatureSet, creases: &FeatureSet) -> GridFeatures {
        let detected = all.intersection(creases);
        GridFeatures { all, detected }
    }
}

/// A solved map kept for integer-grid maps of any size, with the maps
/// solved again for earlier sizes (each kept while later sizes ask for the
/// same thing, so that moving a quad-count slider re-runs only the
/// quantization).
pub struct GridStage {
    /// The map solved first (or on the refinement of the input, see [`LongEdges`]).
    base: Solved,
    /// The solve's features and settings, as solved (the low-poly
    /// fallback's maximum edge length included), to solve again with.
    features: GridFeatures,
    options: SolveOptions,
    long_edges: LongEdges,
    /// The map solved again with these cut-vertex pairs of `base` cancelled.
    paired: Option<Resolved<Vec<(u32, u32)>>>,
    /// The maps solved again without these feature edges (steps 3 and 4
    /// of [`GridStage::map`]), by [`Without`].
    without: [Option<Resolved<FeatureSet>>; 4],
}

/// A map and its quantizer (set up on first use).
struct Solved {
    solution: Solution<'static>,
    quantizer: Option<Quantizer>,
}

/// A map solved again for `key`; `None` where that solve failed (not tried
/// again for the same key).
struct Resolved<K> {
    key: K,
    solved: Option<Solved>,
}

/// Which of a stage's maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    Base,
    Paired,
    Without(Without),
}

/// Which feature curves a map solved again without features dropped
/// ([`GridStage::map`], steps 3 and 4), besides the curves finer than the
/// grid: the detected creases' chains next to the folds, every detected
/// crease of the folding components, then the same of the asked features.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Without {
    DetectedNear = 0,
    Detected = 1,
    AskedNear = 2,
    Asked = 3,
}

impl Solved {
    fn new(solution: Solution<'static>) -> Solved {
        Solved { solution, quantizer: None }
    }

    /// `solution`'s integer-grid map for `size`, its quantizer set up first if need be.
    fn quantize(&mut self, size: GridSize, options: &QuantizeOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<IntegerGridMap, QuantizeError> {
        if self.quantizer.is_none() {
            self.quantizer = Some(self.solution.quantizer()?);
        }
        let quantizer = self.quantizer.as_ref().expect("set up above");
        quantizer.quantize_with(&self.solution.mesh, size, options, progress)
    }
}

/// A candidate map: where it came from, the map, the features it dropped.
struct Candidate {
    source: Source,
    map: IntegerGridMap,
    dropped: FeatureSet,
}

impl GridStage {
    /// The stage of `solution`, solved with `features.all` and `options`.
    pub fn new(solution: Solution<'_>, features: GridFeatures, options: SolveOptions, long_edges: LongEdges) -> GridStage {
        // As solved: a low-poly fallback's edge length is not asked again.
        let options = SolveOptions { refine: solution.refine_options, ..options };
        GridStage { base: Solved::new(solution.into_owned()), features, options, long_edges, paired: None, without: Default::default() }
    }

    /// The features solved for (every one, the dropped ones too).
    pub fn features(&self) -> &FeatureSet {
        &self.features.all
    }

    /// Those of [`GridStage::features`] found rather than asked for
    /// ([`GridFeatures::detected`]).
    pub fn detected_features(&self) -> &FeatureSet {
        &self.features.detected
    }

    /// The integer-grid map for `size` of the stage's map, solved on `input`
    /// (the mesh the stage's solve was given), and what it was solved again
    /// for:
    /// 1. a mesh with edges longer than the grid wants is solved again on
    ///    its refinement ([`LongEdges`]; where that solve fails, the map
    ///    solved first is used and the refinement not asked again);
    /// 2. where the grid puts opposite cones closer than
    ///    [`cones::GRID_PAIR_CELLS`] cells and the map was not solved for
    ///    them, it is solved again with those pairs cancelled
    ///    ([`SolveOptions::for_quads`]; where the rounding kept such a pair
    ///    it put it on one grid point or folded the cells between);
    /// 3. where the map still folds (flipped triangles or vertices it winds
    ///    around) and some feature curves are finer than the grid
    ///    ([`finer_than_grid`]: short dangling branches and small loops,
    ///    whose corner cones the rounding must put on grid points a cell
    ///    apart) or were detected rather than asked for
    ///    ([`GridFeatures::detected`]), it is solved again without them and
    ///    kept if it folds less: first without only the detected creases'
    ///    chains within a ring of the folds ([`chains_near`]; kept where
    ///    that map does not fold), else without every detected crease on a
    ///    component where the map folds
    ///    (teapot with creases above 60° at 3 000 quads: the map winds
    ///    around 6 vertices with the spout's lip, none without it). A map
    ///    that follows every feature wins ties. With such curves the first
    ///    rounding stops after its plain pass where that leaves a hopeless
    ///    map ([`QuantizeOptions::plain_only_if_hopeless`]: bff-face with
    ///    creases above 60° at 1 000 quads, about 500 -> 67 s for the same
    ///    quads), and runs its other passes only where the map without them
    ///    folds no less;
    /// 4. where it still folds, solved again without the asked features'
    ///    chains next to the folds too, then without every feature of the
    ///    components where it folds, each kept if it folds less: a folded
    ///    map follows no curve cleanly, and its quads have holes and
    ///    overlaps (cow with creases above 60° at 1 000 quads: 151 defects
    ///    and 59 flipped triangles with the 114 of its 302 edges that step
    ///    3 keeps).
    ///
    /// A failed solve in 2, 3 or 4 keeps the map without it. Errors: the
    /// quantization's, of the map solved first. `solve_progress` reports
    /// the solves, `progress` each quantization.
    pub fn map(
        &mut self,
        input: &TriMesh,
        size: GridSize,
        quantize: &QuantizeOptions,
        solve_progress: &mut dyn FnMut(SolveProgress),
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<GridMapped<&Solution<'static>>, QuantizeError> {
        // 1. The refinement, before any rounding.
        if self.long_edges == LongEdges::RefineFirst {
            if let Some(refine) = long_edges_refine(input, &self.options.refine, Some(size)) {
                if let Some(solved) = self.solve_again(input, &self.features.all, refine, None, solve_progress) {
                    self.replace_base(solved);
                }
                self.options.refine = refine;
            }
        }
        // 2. Close cone pairs cancelled; with curves to drop, a hopeless
        // rounding stops after its plain pass where a later step may drop
        // more (the first, and those of 3 and 4 that asked features may
        // follow).
        let source = self.pair_cancelled(input, size, solve_progress);
        let mut dropped = finer_than_grid(input, &self.features.all, quad_length(input, size));
        let droppable = !self.features.all.is_empty();
        let first = QuantizeOptions { plain_only_if_hopeless: droppable, ..*quantize };
        let map = self.quantize(source, size, &first, progress)?;
        let mut best = Candidate { source, map, dropped: FeatureSet::none(input) };
        // 1. The refinement, where the map folds.
        if best.map.report.folds() > 0 && self.long_edges == LongEdges::RefineWhereFolded {
            if let Some(refine) = long_edges_refine(input, &self.options.refine, Some(size)) {
                self.options.refine = refine;
                let again = self.solve_again(input, &self.features.all, refine, Some(size), solve_progress);
                if let Some(mut solved) = again {
                    if let Ok(map) = solved.quantize(size, quantize, progress) {
                        if map.report.folds() < best.map.report.folds() {
                            self.replace_base(solved);
                            best = Candidate { source: Source::Base, map, dropped: FeatureSet::none(input) };
                        }
                    }
                }
            }
        }
        // 3. Without the curves finer than the grid and the detected creases
        // of the components where the map folds.
        if best.map.report.folds() > 0 {
            // First only the detected creases' chains next to the folds,
            // kept where that map does not fold.
            let mut local = dropped.clone();
            local.union(&self.near_folds(input, &best, &self.features.detected));
            dropped.union(&self.where_folded(input, &best, &self.features.detected));
            if !local.is_empty() && local != dropped {
                self.try_without(Without::DetectedNear, local, &mut best, true, input, size, quantize, solve_progress, progress);
            }
        }
        let asked = self.features.all != self.features.detected;
        if best.map.report.folds() > 0 && !dropped.is_empty() {
            let options = if asked { &first } else { quantize };
            self.try_without(Without::Detected, dropped.clone(), &mut best, false, input, size, options, solve_progress, progress);
        }
        // 4. Where it still folds, the asked features next to the folds, then
        // every feature of the folding components, go too: a folded map
        // follows no curve cleanly, and its quads have holes and overlaps
        // (cow with creases above 60° at 1 000 quads: 151 defects with
        // the 114 edges left of 302).
        if best.map.report.folds() > 0 && asked {
            let mut local = dropped.clone();
            local.union(&self.near_folds(input, &best, &self.features.all));
            if local != best.dropped {
                self.try_without(Without::AskedNear, local, &mut best, false, input, size, &first, solve_progress, progress);
            }
        }
        // A stopped map kept so far is rounded in full before every feature
        // of the folding parts goes: its other passes may mend it (spot with
        // creases above 40° at 1 000 quads: step 3's map, clean in full).
        if asked {
            self.complete_stopped(&mut best, size, quantize, progress)?;
        }
        if best.map.report.folds() > 0 && asked {
            let mut all = dropped;
            all.union(&self.where_folded(input, &best, &self.features.all));
            if all != best.dropped {
                self.try_without(Without::Asked, all, &mut best, false, input, size, quantize, solve_progress, progress);
            }
        }
        self.complete_stopped(&mut best, size, quantize, progress)?;
        let cancelled_pairs = match (best.source, &self.paired) {
            (Source::Paired, Some(p)) => p.key.len(),
            _ => 0,
        };
        let solution = &self.solved(best.source).expect("a candidate's map exists").solution;
        Ok(GridMapped { solution, map: best.map, dropped_features: best.dropped, cancelled_pairs })
    }

    /// Where `best`'s rounding stopped after its plain pass
    /// ([`QuantizeOptions::plain_only_if_hopeless`]), rounds its map again
    /// with every pass and keeps that (every pass includes the plain one:
    /// no worse, and complete).
    fn complete_stopped(&mut self, best: &mut Candidate, size: GridSize, quantize: &QuantizeOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<(), QuantizeError> {
        if best.map.report.passes_skipped {
            let map = self.quantize(best.source, size, quantize, progress)?;
            if map.report.folds() <= best.map.report.folds() {
                best.map = map;
            }
        }
        Ok(())
    }

    /// The edges of `features` on the components of `input` where
    /// `candidate`'s map folds.
    fn where_folded(&self, input: &TriMesh, candidate: &Candidate, features: &FeatureSet) -> FeatureSet {
        on_components_of(input, self.input_fold_faces(candidate).into_iter(), features)
    }

    /// The map solved again without the feature edges `dropped` (into slot
    /// `without`) and quantized for `size`, made `best` where it folds less
    /// (with `only_clean`, only where it does not fold at all).
    #[allow(clippy::too_many_arguments)]
    fn try_without(
        &mut self,
        without: Without,
        dropped: FeatureSet,
        best: &mut Candidate,
        only_clean: bool,
        input: &TriMesh,
        size: GridSize,
        quantize: &QuantizeOptions,
        solve_progress: &mut dyn FnMut(SolveProgress),
        progress: &mut dyn FnMut(usize, usize),
    ) {
        self.solve_without(without, &dropped, input, size, solve_progress);
        let source = Source::Without(without);
        if let Ok(map) = self.quantize(source, size, quantize, progress) {
            let folds = map.report.folds();
            if folds == 0 || (!only_clean && folds < best.map.report.folds()) {
                *best = Candidate { source, map, dropped };
            }
        }
    }

    /// The faces of the input where `candidate`'s map folds (its solve's
    /// fold faces, mapped back where that solve refined the input).
    fn input_fold_faces(&self, candidate: &Candidate) -> Vec<u32> {
        let solution = &self.solved(candidate.source).expect("a candidate's map exists").solution;
        candidate.map.fold_faces.iter().map(|&f| solution.original_face.as_ref().map_or(f, |original| original[f as usize])).collect()
    }

    /// The chains of `features` ([`chains_near`]) within a ring of the
    /// faces where `candidate`'s map folds.
    fn near_folds(&self, input: &TriMesh, candidate: &Candidate, features: &FeatureSet) -> FeatureSet {
        let mut near = vec![false; input.n_vertices()];
        for f in self.input_fold_faces(candidate) {
            for v in input.faces()[f as usize] {
                near[v as usize] = true;
                for w in input.one_ring(v) {
                    near[w as usize] = true;
                }
            }
        }
        chains_near(input, features, &near)
    }

    /// The map to round for `size` (step 2 of [`Self::map`]): the map solved
    /// again with the grid's close opposite cone pairs cancelled (solved
    /// now unless the last such request had the same pairs), or the base
    /// map where there are none, the base was solved for them, or that
    /// solve failed.
    fn pair_cancelled(&mut self, input: &TriMesh, size: GridSize, solve_progress: &mut dyn FnMut(SolveProgress)) -> Source {
        let distance = cones::GRID_PAIR_CELLS * quad_length(input, size);
        if self.options.cones.min_pair_distance >= distance {
            return Source::Base;
        }
        let pairs = self.base.solution.placement.close_pairs(distance);
        if pairs.is_empty() {
            return Source::Base;
        }
        if self.paired.as_ref().is_none_or(|p| p.key != pairs) {
            let solved = self.solve_again(input, &self.features.all, self.options.refine, Some(size), solve_progress);
            self.paired = Some(Resolved { key: pairs, solved });
        }
        match &self.paired {
            Some(Resolved { solved: Some(_), .. }) => Source::Paired,
            _ => Source::Base,
        }
    }

    /// Fills slot `without` with the map solved again for `size` without
    /// the feature edges `dropped`, unless it holds that map (or its failed
    /// solve) already.
    fn solve_without(&mut self, without: Without, dropped: &FeatureSet, input: &TriMesh, size: GridSize, solve_progress: &mut dyn FnMut(SolveProgress)) {
        if self.without[without as usize].as_ref().is_none_or(|r| &r.key != dropped) {
            let solved = self.solve_again(input, &self.features.all.without(dropped), self.options.refine, Some(size), solve_progress);
            self.without[without as usize] = Some(Resolved { key: dropped.clone(), solved });
        }
    }

    /// `input` solved again with `features`, the stage's settings with
    /// `refine`, and (for a grid) its close cone pairs cancelled; `None`
    /// where that fails.
    fn solve_again(
        &self,
        input: &TriMesh,
        features: &FeatureSet,
        refine: RefineOptions,
        grid: Option<GridSize>,
        solve_progress: &mut dyn FnMut(SolveProgress),
    ) -> Option<Solved> {
        let mut options = SolveOptions { refine, ..self.options };
        if let Some(grid) = grid {
            options = options.for_quads(input, grid);
        }
        let solution = solve(input, features, &options, solve_progress).ok()?;
        Some(Solved::new(solution.into_owned()))
    }

    /// `solved` as the base map; the maps solved again from the old one go.
    fn replace_base(&mut self, solved: Solved) {
        self.base = solved;
        self.paired = None;
        self.without = Default::default();
    }

    fn solved(&self, source: Source) -> Option<&Solved> {
        match source {
            Source::Base => Some(&self.base),
            Source::Paired => self.paired.as_ref()?.solved.as_ref(),
            Source::Without(w) => self.without[w as usize].as_ref()?.solved.as_ref(),
        }
    }

    /// The integer-grid map of the map `source` (an error where it was not solved).
    fn quantize(&mut self, source: Source, size: GridSize, options: &QuantizeOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<IntegerGridMap, QuantizeError> {
        let solved = match source {
            Source::Base => Some(&mut self.base),
            Source::Paired => self.paired.as_mut().and_then(|p| p.solved.as_mut()),
            Source::Without(w) => self.without[w as usize].as_mut().and_then(|u| u.solved.as_mut()),
        };
        let solved = solved.ok_or(QuantizeError::Mismatch { what: "a map that was not solved" })?;
        solved.quantize(size, options, progress)
    }
}

/// The edges of `features` on the components of `mesh` that hold one of `faces`.
fn on_components_of(mesh: &TriMesh, faces: impl Iterator<Item = u32>, features: &FeatureSet) -> FeatureSet {
    let mut marked = vec![false; mesh.n_components()];
    for f in faces {
        marked[mesh.face_components()[f as usize] as usize] = true;
    }
    let mut on = FeatureSet::none(mesh);
    for e in features.edges() {
        on.set(mesh, e, marked[mesh.vertex_component(mesh.edge_vertices(e)[0])]);
    }
    on
}

/// The integer-grid map of `solution` (solved on `mesh` with `features.all`
/// and `options`) for `size`, as [`GridStage::map`] with `long_edges`, for
/// a caller that asks once.
#[allow(clippy::too_many_arguments)]
pub fn grid_map(
    mesh: &TriMesh,
    features: &GridFeatures,
    options: &SolveOptions,
    solution: Solution<'_>,
    size: GridSize,
    quantize: &QuantizeOptions,
    long_edges: LongEdges,
    solve_progress: &mut dyn FnMut(SolveProgress),
    progress: &mut dyn FnMut(usize, usize),
) -> Result<GridMapped<Solution<'static>>, QuantizeError> {
    let mut stage = GridStage::new(solution, features.clone(), *options, long_edges);
    let GridMapped { solution, map, dropped_features, cancelled_pairs } = stage.map(mesh, size, quantize, solve_progress, progress)?;
    // (A copy of the mesh and map: milliseconds beside the solve.)
    Ok(GridMapped { solution: solution.clone(), map, dropped_features, cancelled_pairs })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two blocks side by side: a fold on one of them marks its edges only.
    #[test]
    fn folds_mark_the_features_of_their_own_component() {
        let mut raw = crate::mesh::shapes::voxel_block(2, 1, 1, &[]);
        let n = raw.positions.len() as u32;
        let moved: Vec<[f64; 3]> = raw.positions.iter().map(|p| [p[0] + 5.0, p[1], p[2]]).collect();
        let faces: Vec<[u32; 3]> = raw.triangles.iter().map(|t| t.map(|v| v + n)).collect();
        raw.positions.extend(moved);
        raw.triangles.extend(faces);
        let mesh = TriMesh::from_raw(&raw).unwrap();
        let edges = FeatureSet::sharp_edges(&mesh, 60.0);
        assert_eq!((mesh.n_components(), edges.len()), (2, 2 * 16));
        let first = mesh.face_components()[0];
        let on_first = |f: u32| mesh.face_components()[f as usize] == first;
        let (a, b) = ((0..mesh.n_faces() as u32).find(|&f| on_first(f)).unwrap(), (0..mesh.n_faces() as u32).find(|&f| !on_first(f)).unwrap());
        let marked = on_components_of(&mesh, [a, a].into_iter(), &edges);
        assert_eq!(marked.len(), 16);
        assert!(marked.edges().all(|e| mesh.vertex_component(mesh.edge_vertices(e)[0]) == first as usize));
        assert_eq!(on_components_of(&mesh, [a, b].into_iter(), &edges), edges);
        assert!(on_components_of(&mesh, std::iter::empty(), &edges).is_empty());
    }
}
