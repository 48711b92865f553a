//! Quantization: the seamless map made an integer-grid map (the paper's
//! Limitations and Figures 1 and 12; Bommes et al. 2013). For a grid size `s`
//! (model units) the map is scaled to grid units (`uv / s`), and then
//! - every singular point (cone, and any boundary or feature corner whose UV
//!   angle is not straight) lands on an integer point,
//! - every feature and boundary isoline on an integer `u` or `v` (the end
//!   of a feature curve inside the surface, where the isoline runs straight
//!   on, is no singular point: on a curve shorter than a cell it stays off
//!   the grid points, [`CurveEnd`]),
//! - every seam transition's translation becomes an integer vector,
//!
//! while the seam rows of (B.2) and the isolines keep holding exactly. The
//! integer unknowns ("forms": linear forms of the wedge unknowns) are
//! rounded greedily in the spirit of Algorithm 1: closest to an integer
//! first, in batches, with the map re-solved after each batch as the
//! least-squares closest map, `min sum_f A_f |J_f - J_f^0 / s|^2` (the
//! seamless map's Jacobians `J^0`), under the rounded forms. Interior cones
//! are rounded first, then boundary and feature corners and isolines, then
//! translations: a translation across a seam that ends at a cone `p` is
//! `(I - r) p`, and the two sides of a half-turn seam from a corner `P` to a
//! cone `p` satisfy `f_g(P) + f_f(P) = 2 p`, so rounding the cone later could
//! leave it half-way between grid points. A triangle whose three corners
//! are rounded forms of one coordinate is never put onto one grid line, and
//! two integers that the surface between them keeps apart (a cone beside a
//! feature isoline, two parallel isolines less than a cell apart: see
//! [`super::separation`]) are rounded a line apart; where the other forms
//! determine them on one line anyway (through a seam's translation, say),
//! [`Quantizer::separate`] moves the integers that determine them.
//! Likewise a seam translation around a thin part of the surface (the loop
//! crossing that seam goes around a horn, a leg or a handle: [`periods`])
//! is the part's circumference in grid steps; where the rounded forms make
//! it less than three, two quads around the part would share their four
//! vertices, and [`Quantizer::widen_periods`] moves the integers that
//! determine it.
//!
//! Then the polish ([`Quantizer::stiffened`], [`Quantizer::polish_stiffened`]):
//! where the plain fit's rounded map is bad,
//! the local stiffening of Bommes et al. 2009 (MIQ; [`Quantizer::stiffen`]:
//! the fit weights near the bad faces raised by their error, re-solved a
//! few times), which spreads the spike a rounded point drags the fit along
//! as (below) before it folds; the untangler under all the integer rows
//! where the map folds (on a large mesh on patches around the folds alone:
//! [`local`]), and ARAP local/global iterations (eq. 4), each kept
//! unless it makes the map worse by [`Quantizer::badness`] (flipped or
//! collapsed triangles, wound vertices). Where the map is bad,
//! [`Quantizer::uncollapse`] moves the integers at the bad triangles by one
//! and the moved map is polished too; the better of the two is returned.
//! For the plain fit the moved map goes first, where the stiffening leaves
//! the map bad, and its badness bounds the unmoved map's untangling.
//!
//! The fit weighs every face alike first. A rounded singular point then
//! drags the fit along as a spike (the displacement of a point constraint
//! decays within a ring), which folds its ring or winds the map around a
//! neighbour when the point moves by more than the ring is wide. Where that
//! leaves the map bad after the polish, or where only the stiffening
//! mended it (on meshes with the full budgets, for less distortion), the
//! whole rounding runs again with the faces within
//! one grid unit of every singular point [`STIFF_WEIGHTS`] times stiffer, so
//! the ring moves with its point; the pass with the fewest collapsed faces
//! and narrow tube periods, then wound vertices, then the least fit distortion is kept. Where the map
//! is still bad, one more pass holds the separations as rows
//! ([`HeldApart`](super::separation::HeldApart)): every pair a solve leaves less than a grid line apart is
//! held exactly one apart in the solves that follow, the collapse
//! constraints of Bommes et al. 2013 as an active set on the relaxed map,
//! so that the rounding starts from a map that already keeps them apart
//! (where a cell is wider than a part of the surface, a plank or a box
//! thinner than a cell, the moves of [`Quantizer::separate`] one integer
//! at a time cannot undo the collapse: each breaks the neighbouring pairs).
//! Held at exactly one line, some pairs cannot all part (a box's seams add
//! the gaps of two pairs into a third, whose row is then dropped as
//! dependent); where the held pass leaves such pairs and the map bad, it
//! runs again with held rows widened to two lines where that parts them
//! ([`Quantizer::widen_held`]: the separations are inequalities), kept
//! only if it has fewer faults of both kinds ([`keep_dominant`]).
//! Where the plain fit leaves separations violated, the held passes run
//! before the stiffer ones: they are the passes made for that fault, and
//! where they end clean the stiffer ones are not run (fandisk at 1 000
//! quads: 11 s -> 4 s, the same map).
//! The spike grows as the mesh gets finer than the grid (its slope at the
//! first ring is about `d / (h log(R / h))` for a point moved by `d`, edges
//! of length `h`), and neither local stiffening nor a step in the weights
//! undoes it there: their weights jump, and the strain gathers where they
//! do. The graded fit ([`Quantizer::graded_fit`]) weighs a face at
//! distance `r` from a singular point `1 + (rho / r)^2`, under which the
//! displacement is flat at the point and its slope bounded whatever `h`.
//! On a mesh of more than [`FULL_BUDGET_FACES`] faces whose cells span
//! [`GRADED_FIRST_RINGS`] edge rings or more, it is the first pass after a
//! bad plain one; elsewhere the last of all.
//! Where it is still bad and a quad count was asked, grids a few percent
//! larger and smaller ([`RETRY_GRID_FACTORS`]).
//!
//! A mesh of several parts (components) is quantized one part at a time
//! ([`parts`]): they share no unknown, so each rounds as it would alone,
//! with its own passes, and a pass costs only the part it re-runs; natively
//! the parts are shared between two threads.
//!
//! Here: the setup ([`Quantizer::new`]), the passes and which map is kept
//! ([`Quantizer::quantize_with`]). The integer forms and curve ends are in
//! [`forms`], the tube periods in [`periods`], the fit and its KKT in [`fit`], one rounding pass in
//! [`rounding`], the polish and the measures of a bad map in [`polish`]
//! (its patches in [`local`]), the parts in [`parts`].
//!
//! Cost: one symbolic analysis and numeric factorization of the KKT per
//! batch (the rows change; about ten batches), and up to eight passes where
//! the plain fit leaves the map bad, ten where the widened pass does best
//! (the held pass: up to [`HOLD_ROUNDS`](rounding::HOLD_ROUNDS) more factorizations before its
//! first batch, and at most [`WIDEN_TRIALS`](rounding::WIDEN_TRIALS) solves widening). With that factorization:
//! one adjoint solve per violated separation and one solve per row moved
//! (its response, kept while the factorization is: a trial move is
//! `x + step * response`; solved ahead in batches, [`fit::Trials`]; at
//! most [`SEPARATION_TRIALS`](rounding::SEPARATION_TRIALS) per batch, fewer
//! on large meshes: [`FULL_BUDGET_FACES`]), and the same per narrow tube period (at most
//! [`PERIOD_TRIALS`](periods::PERIOD_TRIALS) solves per batch); after the last batch, one
//! adjoint solve per probed unknown and one response per `uncollapse` trial
//! (at most [`UNCOLLAPSE_TRIALS`](polish::UNCOLLAPSE_TRIALS), only where the map is bad), and one solve
//! per ARAP iteration; the untangler of a stiffer pass factors the KKT once
//! more, with the uniform fit that its energy has (on a mesh of more than
//! [`FULL_BUDGET_FACES`] faces: one small KKT per patch instead). The local
//! stiffening of a bad plain rounding: one symbolic analysis and at most
//! [`STIFFEN_ITERATIONS`](polish::STIFFEN_ITERATIONS) + [`RELAX_ITERATIONS`](polish::RELAX_ITERATIONS) numeric factorizations
//! with two solves each (bff-face at 1 000 quads: 1.5 s of its 4.5 s,
//! where the untangler and the moves of the passes it spares took 100 s).
//! The graded pass is one more pass where it runs (spot subdivided to 93 k
//! faces at 1 000 quads: 10.6 s of quantization, where the four passes it
//! spares took 46 s and left four wound vertices).

use super::cut_graph::cut_graph;
use super::element::{signed_uv_area, Element};
use super::field::cross_field;
use super::metrics;
use super::seamless::{elements, seam_rows, unknowns};
use super::separation::Separations;
use super::{ParamError, Parametrization};
use crate::clock::Stopwatch;
use crate::cones::ConePlacement;
use crate::linalg::LinalgError;
use crate::mesh::TriMesh;
use fit::Fit;
use forms::{
    collapse_triples, curve_ends, integer_forms, integral_unknowns, single_unknown_forms, singular_cut_vertices,
    wedge_components, CurveEnd, Form, FormKind,
};
use parts::Part;
use periods::{tube_periods, TubePeriod};
use rounding::SizeRules;
use serde::Serialize;
use std::fmt;

mod fit;
mod forms;
mod local;
mod parts;
mod periods;
mod polish;
mod rounding;

/// A form within this of an integer is rounded in the current batch
/// whatever its rank (it is usually determined by forms already rounded).
const NEAR_INTEGER: f64 = 1e-6;

/// Fit weights of the faces around singular points
/// ([`Quantizer::stiff_faces`]) tried in turn while the map stays bad: 1 is
/// the plain fit (the least distortion where it works), the others trade
/// some distortion for maps that do not fold or wind near cones.
const STIFF_WEIGHTS: [f64; 3] = [1.0, 10.0, 100.0];

/// Grid lengths (times the one a quad count asks for) tried in turn while
/// the map still has collapsed or flipped faces: the rounding is sensitive
/// to where the grid falls, and a few percent off often rounds cleanly
/// (a box with a boss, Delaunay-flipped, at 3 000 quads: 167 flipped
/// triangles; at 2 850 and 3 150 quads none).
const RETRY_GRID_FACTORS: [f64; 2] = [1.03, 0.97];

/// Edge rings per cell ([`Quantizer::rings`]) from which the graded pass
/// goes first where the plain fit's map is bad, on a mesh of more than
/// [`FULL_BUDGET_FACES`] faces (bff-face at 3 000 quads, 3 rings: 0.161 ->
/// 0.139 distortion, 12.9 -> 7.0 s).
const GRADED_FIRST_RINGS: usize = 3;

/// The stiffer passes run only where the plain fit's map has at most this
/// many collapsed faces and wound vertices: they mend a few bad places next
/// to cones; where dense features fold the map in many places they cost two
/// more roundings for little.
const STIFF_PASS_LIMIT: usize = 16;

/// With [`QuantizeOptions::plain_only_if_hopeless`], the plain fit's map
/// with more collapsed faces and wound vertices than this is given up
/// after that pass. Creases marked by angle on organic meshes left
/// 203-771 (bff-face >60 at 3 000 and 1 000 quads, cow >60 at 3 000 and
/// 1 000), and the other passes never mended them (bff-face >60 at 1 000:
/// about 400 s for 329 defect places); plain maps the other passes made
/// clean or nearly so had 10-24 (spot >40 at 1 000 and 3 000, bff-bunny
/// >40 at 3 000).
const HOPELESS_PLACES: usize = 4 * STIFF_PASS_LIMIT;

/// Meshes up to this many faces get the full budgets of extra solves
/// ([`SEPARATION_TRIALS`](rounding::SEPARATION_TRIALS), [`UNCOLLAPSE_TRIALS`](polish::UNCOLLAPSE_TRIALS), [`UNCOLLAPSE_PROBES`](polish::UNCOLLAPSE_PROBES) and
/// the untangler's default iterations); larger ones a share `FULL_BUDGET_FACES
/// / faces` of them (at least [`MIN_BUDGET_SHARE`](rounding::MIN_BUDGET_SHARE)), since each solve costs
/// in proportion: on a 114 k-face mesh with dense lone features the full
/// budgets spent 85 s of 93 on separations, untangling and moves that did
/// not mend the map.
const FULL_BUDGET_FACES: f64 = 20_000.0;

/// How the grid size is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridSize {
    /// Edge length of a grid cell, in model units.
    Length(f64),
    /// About this many grid cells (quads) over the whole map:
    /// `s = sqrt(map area / N)`.
    Quads(usize),
}

/// Settings of [`Quantizer::quantize_with`], by what the caller does with
/// the map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuantizeOptions {
    /// With [`GridSize::Quads`], round again at nearby grid sizes
    /// ([`RETRY_GRID_FACTORS`]) also where the map only winds around
    /// vertices (no flipped triangle). A UV map shows such a vertex as a
    /// singular point off the grid (cow at 3 000 cells: 2, none at 0.97 the
    /// length); the quad extractor closes its cell with quads instead, so
    /// quads do not pay for the retries (fandisk >60° at 1 000: 8 s -> 16 s).
    pub retry_wound: bool,
    /// Stop after the plain pass where its map is bad in more than
    /// [`HOPELESS_PLACES`] places, for a caller that has a better way out
    /// ([`crate::pipeline::grid_map`]: the map without the feature curves
    /// finer than the grid) and quantizes again without this where that
    /// fails. [`QuantizeReport::passes_skipped`] says when it stopped.
    pub plain_only_if_hopeless: bool,
}

/// Why quantization failed.
#[derive(Clone, Debug, PartialEq)]
pub enum QuantizeError {
    /// The grid size is not a positive finite length (or the quad count is 0).
    InvalidGridSize { value: f64 },
    /// A free boundary (`--boundary free`) lies on no isoline: it cannot be
    /// put on the grid.
    FreeBoundary,
    /// The parametrization does not belong to this mesh and placement.
    Mismatch { what: &'static str },
    /// The field, the cut or a solve failed.
    Param(ParamError),
}

impl fmt::Display for QuantizeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QuantizeError::InvalidGridSize { value } => {
                write!(f, "grid size {value} is not a positive length")
            }
            QuantizeError::FreeBoundary => {
                write!(f, "an integer-grid map needs the boundary on isolines; it was solved with a free boundary")
            }
            QuantizeError::Mismatch { what } => {
                write!(f, "the parametrization does not match the mesh ({what})")
            }
            QuantizeError::Param(e) => write!(f, "quantization: {e}"),
        }
    }
}

impl std::error::Error for QuantizeError {}

impl From<ParamError> for QuantizeError {
    fn from(e: ParamError) -> Self {
        QuantizeError::Param(e)
    }
}

impl From<LinalgError> for QuantizeError {
    fn from(e: LinalgError) -> Self {
        QuantizeError::Param(ParamError::Solve(e))
    }
}

/// Figures of one quantization.
#[derive(Clone, Debug, Default, Serialize)]
pub struct QuantizeReport {
    /// Grid cell edge length, model units.
    pub grid_size: f64,
    /// Integer forms: singular-point coordinates and isolines, translations.
    pub point_forms: usize,
    pub translation_forms: usize,
    /// Rounding batches (each one KKT analysis + factorization).
    pub batches: usize,
    /// Integers moved (by one or two) to keep separated forms a grid line
    /// apart ([`Quantizer::separate`]).
    pub separation_moves: usize,
    /// Pairs of forms to be kept a grid line apart, and those left closer
    /// (each one a collapse).
    pub separations: usize,
    pub separations_violated: usize,
    /// Seam translations around thin parts of the surface (a loop around a
    /// horn or a handle: its circumference in grid steps), the integers moved
    /// to widen them to [`periods::TUBE_STEPS`] steps or more, and those left
    /// narrower (two quads around the part on the same vertices).
    pub tube_periods: usize,
    pub period_moves: usize,
    pub periods_violated: usize,
    /// Separations held as rows in the pass kept (0 unless the held pass
    /// was run and kept: [`HeldApart`](super::separation::HeldApart)), and those of them widened to
    /// more than one line so that dependent ones part too.
    pub separations_held: usize,
    pub separations_widened: usize,
    /// Ends of feature curves inside the mesh, and those left off the grid
    /// points (their curve shorter than a cell).
    pub curve_ends: usize,
    pub free_curve_ends: usize,
    /// Integers moved by one to undo a collapse ([`Quantizer::uncollapse`]).
    pub moved_integers: usize,
    /// ARAP iterations kept after the rounding.
    pub arap_iterations: usize,
    /// Local stiffening iterations the map kept was mended by (0: none;
    /// the most of any part).
    pub stiffening: usize,
    /// Fit weight of the faces around singular points in the pass kept (1:
    /// the plain fit; more where that folded or wound the map). On a mesh of
    /// several parts, that of the part with the largest map area (counts
    /// are summed over the parts).
    pub stiff_weight: f64,
    /// The pass kept weighs the faces near singular points by `1 + (rho / r)^2`
    /// (the graded fit, tried where the plain fit's map was bad); of the
    /// largest part on a mesh of several.
    pub graded_fit: bool,
    /// The rounded map had flipped triangles and the untangler removed them all.
    pub untangled: bool,
    /// Forms that came out determined by others at a non-integer value (0 on success).
    pub conflicts: usize,
    /// Largest distance of a form from its integer after the final solve.
    pub integer_residual: f64,
    /// Distortion (eq. 19) of the seamless map and of the integer-grid map.
    pub distortion_before: f64,
    pub distortion_after: f64,
    /// Flipped or degenerate triangles of the integer-grid map.
    pub flipped: usize,
    /// Vertices around which the map winds (UV angle sum off the seamless
    /// map's by 2 pi) or at which it folds the boundary back (by a quarter
    /// turn or more on the boundary).
    pub wound_vertices: usize,
    /// Total UV area in grid cells (about the number of quads).
    pub cells: f64,
    /// Only the plain pass ran: its map was hopeless and the caller has
    /// another way out ([`QuantizeOptions::plain_only_if_hopeless`]).
    pub passes_skipped: bool,
    pub seconds: f64,
}

impl QuantizeReport {
    /// The map's folds: flipped triangles and the vertices it winds around
    /// (or folds the boundary at).
    pub fn folds(&self) -> usize {
        self.flipped + self.wound_vertices
    }
}

/// An integer-grid map: one UV per face corner (`3 f + k`) in grid units.
#[derive(Clone, Debug)]
pub struct IntegerGridMap {
    pub uv: Vec<[f64; 2]>,
    pub report: QuantizeReport,
    /// Where the map folds ([`QuantizeReport::folds`]): the flipped
    /// triangles and a triangle at each vertex it winds around, ascending.
    pub fold_faces: Vec<u32>,
}

/// The fixed part of quantization for one parametrization: unknowns,
/// elements, seam rows and integer forms (set up once; [`Quantizer::quantize`]
/// runs for any grid size).
pub struct Quantizer {
    wedge: Vec<u32>,
    elements: Vec<Element>,
    vars: [Vec<usize>; 2],
    n_unknowns: usize,
    seam_rows: Vec<Vec<(usize, i64)>>,
    forms: Vec<Form>,
    /// Per form: the triangles' triples of single-unknown forms it is one of,
    /// one coordinate each (rounding all three to one integer collapses the
    /// triangle onto a grid line).
    triples: Vec<Vec<[usize; 3]>>,
    /// Per unknown: whether the integer-grid map makes it an integer (the
    /// unknowns [`Separations`] keep apart).
    integral: Vec<bool>,
    /// The ends of feature curves inside the mesh ([`curve_ends`]).
    curve_ends: Vec<CurveEnd>,
    /// Per unknown: the form that is that unknown alone (`usize::MAX` if none).
    form_of: Vec<usize>,
    /// Translations around thin parts, kept [`periods::TUBE_STEPS`] steps or more.
    tube_periods: Vec<TubePeriod>,
    /// Per component: the pin wedge's two unknowns.
    pins: Vec<[usize; 2]>,
    /// The seamless map's unknowns (model units).
    seamless: Vec<f64>,
    /// UV area of every face in the seamless map (model units).
    seamless_areas: Vec<f64>,
    /// Faces of the mesh (corner `k` of face `f` is unknown column `k` of element `f`).
    faces: Vec<[u32; 3]>,
    /// UV angle sum of every vertex in the seamless map: quantization must
    /// keep it (a vertex off it by 2 pi winds without a flipped triangle).
    angle_sums: Vec<f64>,
    /// Per vertex: on the mesh boundary (on an isoline, so its UV angle sum
    /// can change only by quarter turns, each one a fold of the boundary).
    on_boundary: Vec<bool>,
    map_area: f64,
    distortion_before: f64,
    /// On a mesh of several components: each as a quantizer of its own
    /// (they share no unknown, and each is rounded as it would be alone:
    /// [`parts`]); empty on a mesh of one component.
    parts: Vec<Part>,
}

impl Quantizer {
    /// Sets up quantization of `param`, the parametrization of `mesh` with
    /// `placement` (recomputes the field and cut, which are deterministic).
    pub fn new(
        mesh: &TriMesh,
        placement: &ConePlacement,
        param: &Parametrization,
    ) -> Result<Quantizer, QuantizeError> {
        let nf = mesh.n_faces();
        if param.uv.len() != 3 * nf {
            return Err(QuantizeError::Mismatch {
                what: "corner count",
            });
        }
        let cm = &placement.cut.mesh;
        if (0..cm.n_vertices() as u32).any(|v| placement.cut.touches_free(v)) {
            return Err(QuantizeError::FreeBoundary);
        }
        let field = cross_field(mesh, placement)?;
        let cut = cut_graph(mesh, placement, &field)?;
        let (vars, n_unknowns) = unknowns(mesh, &field, &cut);
        let elements = elements(mesh, &cut, &vars);
        let mut seamless = vec![0.0; n_unknowns];
        for (c, &w) in cut.wedge.iter().enumerate() {
            for k in 0..2 {
                seamless[vars[k][w as usize]] = param.uv[c][k];
            }
        }
        let component = wedge_components(&cut);
        let cut_sums = corner_angle_sums(cm.faces(), cm.n_vertices(), |f| [param.uv[3 * f], param.uv[3 * f + 1], param.uv[3 * f + 2]]);
        let singular = singular_cut_vertices(cm, &cut_sums);
        let forms = integer_forms(
            mesh,
            placement,
            &field.isoline,
            &cut,
            &vars,
            &component,
            &singular,
        );
        let pins = cut
            .pins
            .iter()
            .map(|&p| [vars[0][p as usize], vars[1][p as usize]])
            .collect();
        let form_of = single_unknown_forms(&forms, n_unknowns);
        let curve_ends = curve_ends(mesh, &placement.cut, &cut_sums, &field.isoline, &cut, &vars, &form_of, &seamless);
        let triples = collapse_triples(&elements, &forms, &form_of);
        let tube_periods = tube_periods(mesh, &cut, &vars, &param.uv);
        let integral = integral_unknowns(mesh, placement, &cut, &vars, &singular, n_unknowns, &forms);
        let faces = mesh.faces().to_vec();
        let seamless_areas: Vec<f64> = (0..nf)
            .map(|f| signed_uv_area([param.uv[3 * f], param.uv[3 * f + 1], param.uv[3 * f + 2]]))
            .collect();
        let map_area = seamless_areas.iter().map(|a| a.max(0.0)).sum();
        let angle_sums = corner_angle_sums(&faces, mesh.n_vertices(), |f| {
            [param.uv[3 * f], param.uv[3 * f + 1], param.uv[3 * f + 2]]
        });
        let mut quantizer = Quantizer {
            parts: Vec::new(),
            seamless_areas,
            faces,
            angle_sums,
            on_boundary: (0..mesh.n_vertices() as u32).map(|v| mesh.is_boundary_vertex(v)).collect(),
            seam_rows: seam_rows(mesh, &cut, &vars).rows,
            wedge: cut.wedge,
            elements,
            vars,
            n_unknowns,
            forms,
            triples,
            integral,
            curve_ends,
            form_of,
            tube_periods,
            pins,
            seamless,
            map_area,
            distortion_before: metrics::distortion(mesh, &param.uv),
        };
        if mesh.n_components() > 1 {
            let face_part: Vec<usize> = mesh.face_components().iter().map(|&c| c as usize).collect();
            quantizer.parts = Part::split(&quantizer, &face_part, mesh.n_components());
        }
        Ok(quantizer)
    }

    /// The start of a rounding at grid length `s` ([`GridStart`]).
    fn grid_start(&self, s: f64) -> GridStart {
        let x0: Vec<f64> = self.seamless.iter().map(|v| v / s).collect();
        let targets: Vec<[[f64; 2]; 2]> = self.elements.iter().map(|el| el.jacobian(&x0)).collect();
        let rules = self.size_rules(&x0, s);
        GridStart { x0, targets, s, rules }
    }

    /// Grid cell length for `size` (model units).
    pub fn grid_length(&self, size: GridSize) -> Result<f64, QuantizeError> {
        let s = match size {
            GridSize::Length(s) => s,
            GridSize::Quads(0) => 0.0,
            GridSize::Quads(n) => (self.map_area / n as f64).sqrt(),
        };
        if !(s > 0.0) || !s.is_finite() {
            return Err(QuantizeError::InvalidGridSize { value: s });
        }
        Ok(s)
    }

    /// The integer-grid map for grid size `size`. Contract: on return every
    /// seam row holds to solver accuracy, every form is within
    /// `report.integer_residual` of its integer (about 1e-9 of the grid) and
    /// the singular points' and isolines' coordinates are exact integers;
    /// `report.flipped` says whether the map is still free of flips. For
    /// [`GridSize::Quads`] the grid length may be a few percent off
    /// `sqrt(area / n)` where that rounds with fewer flips
    /// ([`RETRY_GRID_FACTORS`]); `report.grid_size` is the one used (on a mesh
    /// of several parts, each may keep its own: that of the largest part).
    pub fn quantize(
        &self,
        mesh: &TriMesh,
        size: GridSize,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<IntegerGridMap, QuantizeError> {
        self.quantize_with(mesh, size, &QuantizeOptions::default(), progress)
    }

    /// [`Self::quantize`] with `options`.
    pub fn quantize_with(
        &self,
        mesh: &TriMesh,
        size: GridSize,
        options: &QuantizeOptions,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<IntegerGridMap, QuantizeError> {
        let mut clock = Stopwatch::start();
        let s = self.grid_length(size)?;
        let retry = matches!(size, GridSize::Quads(_));
        let (rounded, s) = if self.parts.is_empty() {
            self.round(s, retry, options, progress)?
        } else {
            self.round_parts(s, retry, options, progress)?
        };
        let Rounded { mut x, values, batches, separation_moves, period_moves, periods_violated, moved_integers, arap_iterations, stiffening, untangled, stiff_weight, separations, separations_held, separations_widened, separations_violated, free_curve_ends, graded, passes_skipped, .. } = rounded;
        // Singular points and isolines exactly on the grid (they are single unknowns).
        for (form, value) in self.forms.iter().zip(&values) {
            if let (FormKind::Cone | FormKind::Point, [(i, 1)], Some(v)) =
                (form.kind, form.row.as_slice(), value)
            {
                if (x[*i] - *v as f64).abs() < NEAR_INTEGER {
                    x[*i] = *v as f64;
                }
            }
        }
        let inverted = local::inverted_faces(&self.elements, &x);
        let wound = self.wound_vertices(&x);
        let mut fold_faces: Vec<u32> = inverted.iter().map(|&f| f as u32).collect();
        let mut wound_left: std::collections::HashSet<u32> = wound.iter().copied().collect();
        for (f, t) in self.faces.iter().enumerate() {
            if t.iter().any(|v| wound_left.remove(v)) {
                fold_faces.push(f as u32);
            }
        }
        fold_faces.sort_unstable();
        fold_faces.dedup();
        let mut conflicts = 0;
        let mut integer_residual = 0.0f64;
        for (form, value) in self.forms.iter().zip(&values) {
            let Some(value) = value else { continue };
            let d = (form.value(&x) - *value as f64).abs();
            integer_residual = integer_residual.max(d);
            if d > 1e-6 {
                conflicts += 1;
            }
        }
        let uv: Vec<[f64; 2]> = self
            .wedge
            .iter()
            .map(|&w| [x[self.vars[0][w as usize]], x[self.vars[1][w as usize]]])
            .collect();
        let cells = (0..mesh.n_faces())
            .map(|f| signed_uv_area([uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]]))
            .sum();
        let report = QuantizeReport {
            grid_size: s,
            point_forms: self
                .forms
                .iter()
                .filter(|f| f.kind != FormKind::Translation)
                .count(),
            translation_forms: self
                .forms
                .iter()
                .filter(|f| f.kind == FormKind::Translation)
                .count(),
            batches,
            separation_moves,
            tube_periods: self.tube_periods.len(),
            period_moves,
            periods_violated,
            separations,
            separations_held,
            separations_widened,
            separations_violated,
            curve_ends: self.curve_ends.len(),
            free_curve_ends,
            moved_integers,
            arap_iterations,
            stiffening,
            stiff_weight,
            graded_fit: graded,
            untangled,
            conflicts,
            integer_residual,
            distortion_before: self.distortion_before,
            distortion_after: metrics::distortion(mesh, &uv),
            flipped: inverted.len(),
            wound_vertices: wound.len(),
            cells,
            passes_skipped,
            seconds: clock.lap(),
        };
        Ok(IntegerGridMap { uv, report, fold_faces })
    }

    /// The rounding at grid length `s` kept of the passes, each run only
    /// while the best map so far is bad: the plain fit; the separations held
    /// ([`Self::held_passes`]) where the plain fit leaves some violated; the
    /// faces around singular points stiffer ([`STIFF_WEIGHTS`]) where it is
    /// bad in at most [`STIFF_PASS_LIMIT`] places; the held passes (if not
    /// run yet) where it is; then, with `retry` (a quad count asked, not a
    /// length), nearby grid lengths ([`RETRY_GRID_FACTORS`]), holding the
    /// separations where the best map so far is the held pass's. The graded
    /// fit ([`Self::graded_fit`]) runs right after a bad plain pass on a
    /// large mesh whose cells span [`GRADED_FIRST_RINGS`] edge rings or
    /// more, else after all of them. Returns the map kept and its grid length.
    fn round(&self, s: f64, retry: bool, options: &QuantizeOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<(Rounded, f64), QuantizeError> {
        let grid = self.grid_start(s);
        let stiff = self.stiff_faces(&grid.x0);
        let plain_fit = Fit::new(&self.elements, &stiff, 1.0);
        let mut plain = self.round_and_polish(&plain_fit, &grid, Pass::default(), None, progress)?.expect("a plain pass");
        if options.plain_only_if_hopeless && plain.faults() + plain.wound > HOPELESS_PLACES {
            plain.passes_skipped = true;
            return Ok((plain, s));
        }
        let bad = |b: &Rounded| b.faults() + b.wound > 0;
        let is_bad = |best: &Option<(Rounded, f64)>| best.as_ref().is_some_and(|(b, _)| bad(b));
        // Stiffer fits mend a few bad places next to cones; the held
        // separations mend collapses between parallel lines, and go first
        // where the plain fit leaves separations violated.
        let few = bad(&plain) && plain.faults() + plain.wound <= STIFF_PASS_LIMIT;
        // Where only the polish mended the plain rounding (local
        // stiffening), the stiffer fits may round to less distortion: tried
        // on meshes with the full budgets.
        let mended = plain.rounded_bad && !bad(&plain) && self.elements.len() as f64 <= FULL_BUDGET_FACES;
        let stiffer = (few || mended) && stiff.contains(&true);
        let plain_bad = bad(&plain);
        let held_first = plain_bad && plain.separations_violated > 0;
        let mut best = None;
        keep_better(&mut best, plain, s);
        // The graded fit keeps a rounded point's ring from following it as
        // a spike however fine the mesh. On a large mesh whose cells span
        // several edges that spike is what folds the plain fit's map, and
        // the passes cost most: the graded pass goes first. Elsewhere it is
        // the last resort, after the retries (the stiffer and held passes
        // and nearby grid lengths, where they work, keep less distortion:
        // spot >60° at 1 000 quads, 0.176 against 0.209; teapot, whose
        // small parts have fine cells, 0.166 against 0.176).
        let graded_first = self.elements.len() as f64 > FULL_BUDGET_FACES && self.rings(1.0, s) >= GRADED_FIRST_RINGS;
        let graded_pass = |best: &mut Option<(Rounded, f64)>, progress: &mut dyn FnMut(usize, usize)| -> Result<(), QuantizeError> {
            let rounded = self.round_and_polish(&self.graded_fit(&grid.x0), &grid, Pass::default(), bound(best), progress)?.expect("a graded pass");
            keep_better(best, rounded, s);
            Ok(())
        };
        if graded_first && plain_bad {
            graded_pass(&mut best, progress)?;
        }
        if held_first && is_bad(&best) {
            self.held_passes(&plain_fit, &grid, &mut best, progress)?;
        }
        for &weight in STIFF_WEIGHTS.iter().skip(1).filter(|_| stiffer) {
            if !is_bad(&best) && !mended {
                break;
            }
            let rounded = self.round_and_polish(&Fit::new(&self.elements, &stiff, weight), &grid, Pass::default(), bound(&best), progress)?.expect("a stiff pass");
            keep_better(&mut best, rounded, s);
        }
        if !held_first && few && is_bad(&best) {
            self.held_passes(&plain_fit, &grid, &mut best, progress)?;
        }
        // A quad count only asks for about so many quads: where the map
        // still folds, nearby grid lengths round differently and often
        // cleanly (holding the separations where a held pass did best; where
        // the widened one did, both held and widened: each length rounds its
        // own way).
        for factor in RETRY_GRID_FACTORS.into_iter().filter(|_| retry) {
            let Some((b, _)) = best.as_ref() else { break };
            if b.faults() == 0 && (b.wound == 0 || !options.retry_wound) {
                break;
            }
            let (held, best_pass) = (Pass { hold: b.separations_held > 0, widen: false }, b.pass);
            let retried = self.grid_start(s * factor);
            for pass in [held, best_pass].into_iter().take(if best_pass.widen { 2 } else { 1 }) {
                match self.round_and_polish(&plain_fit, &retried, pass, bound(&best), progress)? {
                    Some(rounded) if pass.widen => keep_dominant(&mut best, rounded, retried.s),
                    Some(rounded) => keep_better(&mut best, rounded, retried.s),
                    None => {}
                }
            }
        }
        if !graded_first && is_bad(&best) {
            graded_pass(&mut best, progress)?;
        }
        Ok(best.expect("at least one pass"))
    }

    /// The held pass (the plain fit `fit`, the separations held as rows),
    /// and where its held rows could not part every held pair (rows dropped
    /// as dependent) and its map is bad, the widened one: another trajectory
    /// of the rounding, kept only if it dominates ([`keep_dominant`]).
    fn held_passes(&self, fit: &Fit, grid: &GridStart, best: &mut Option<(Rounded, f64)>, progress: &mut dyn FnMut(usize, usize)) -> Result<(), QuantizeError> {
        let rounded = self.round_and_polish(fit, grid, Pass { hold: true, widen: false }, bound(best), progress)?.expect("a held pass");
        let widen = rounded.held_dropped > 0 && rounded.faults() + rounded.wound > 0;
        keep_better(best, rounded, grid.s);
        if widen {
            if let Some(rounded) = self.round_and_polish(fit, grid, Pass { hold: true, widen: true }, bound(best), progress)? {
                keep_dominant(best, rounded, grid.s);
            }
        }
        Ok(())
    }

    /// [`Self::round`] of every part on its own, joined: the unknowns and
    /// forms of each part from its rounding, the counts summed (the joined
    /// map's wound vertices and distortion are not: `quantize_with` measures
    /// the whole map). A part may
    /// keep a retried grid length of its own; the length returned is that
    /// of the part with the largest map area.
    fn round_parts(&self, s: f64, retry: bool, options: &QuantizeOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<(Rounded, f64), QuantizeError> {
        let mut joined = Rounded {
            x: vec![0.0; self.n_unknowns],
            values: vec![None; self.forms.len()],
            stiff_weight: 1.0,
            ..Rounded::default()
        };
        let (mut s_joined, mut largest) = (s, 0.0);
        for (part, rounded) in self.parts.iter().zip(self.round_each_part(s, retry, options, progress)) {
            let (q, (r, s_part)) = (&part.quantizer, rounded?);
            for (&u, &v) in part.unknown.iter().zip(&r.x) {
                joined.x[u] = v;
            }
            for (&i, &v) in part.form.iter().zip(&r.values) {
                joined.values[i] = v;
            }
            if q.map_area > largest {
                (largest, s_joined, joined.stiff_weight, joined.graded) = (q.map_area, s_part, r.stiff_weight, r.graded);
            }
            joined.batches += r.batches;
            joined.passes_skipped |= r.passes_skipped;
            joined.separation_moves += r.separation_moves;
            joined.period_moves += r.period_moves;
            joined.periods_violated += r.periods_violated;
            joined.moved_integers += r.moved_integers;
            joined.arap_iterations = joined.arap_iterations.max(r.arap_iterations);
            joined.stiffening = joined.stiffening.max(r.stiffening);
            joined.untangled |= r.untangled;
            joined.collapsed += r.collapsed;
            joined.separations += r.separations;
            joined.separations_held += r.separations_held;
            joined.separations_widened += r.separations_widened;
            joined.separations_violated += r.separations_violated;
            joined.free_curve_ends += r.free_curve_ends;
        }
        // Untangled: some part's flips were all removed and no part has any left.
        joined.untangled &= joined.collapsed == 0;
        Ok((joined, s_joined))
    }

    /// [`Self::round`] of every part, in part order. Natively the parts are
    /// shared with a helper thread (largest first, each to the thread with
    /// fewer faces so far; the helper's parts report no progress): they
    /// share nothing, so the outcome is the same as on one thread.
    fn round_each_part(
        &self,
        s: f64,
        retry: bool,
        options: &QuantizeOptions,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Vec<Result<(Rounded, f64), QuantizeError>> {
        let mut on_helper = vec![false; self.parts.len()];
        if cfg!(not(target_arch = "wasm32")) {
            let mut order: Vec<usize> = (0..self.parts.len()).collect();
            order.sort_by_key(|&i| std::cmp::Reverse(self.parts[i].quantizer.elements.len()));
            let (mut here, mut there) = (0, 0);
            for i in order {
                let faces = self.parts[i].quantizer.elements.len();
                if there < here {
                    (on_helper[i], there) = (true, there + faces);
                } else {
                    here += faces;
                }
            }
        }
        let total: usize = self.parts.iter().zip(&on_helper).filter(|(_, &h)| !h).map(|(p, _)| p.quantizer.forms.len()).sum();
        let round_some = |helper: bool, progress: &mut dyn FnMut(usize, usize)| {
            let mut rounded_forms = 0;
            let mut out = Vec::new();
            for (i, part) in self.parts.iter().enumerate().filter(|&(i, _)| on_helper[i] == helper) {
                let q = &part.quantizer;
                out.push((i, q.round(s, retry, options, &mut |done, _| progress(rounded_forms + done, total))));
                rounded_forms += q.forms.len();
            }
            out
        };
        let (mut mine, theirs) = if on_helper.contains(&true) {
            std::thread::scope(|scope| {
                let helper = scope.spawn(|| round_some(true, &mut |_, _| {}));
                let mine = round_some(false, progress);
                (mine, helper.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
            })
        } else {
            (round_some(false, progress), Vec::new())
        };
        mine.extend(theirs);
        mine.sort_by_key(|(i, _)| *i);
        mine.into_iter().map(|(_, r)| r).collect()
    }

    /// How good the rounded map `x` (grid length `s`) is: (collapsed faces,
    /// wound vertices, fit distortion, violated separations).
    fn assess(&self, x: &[f64], s: f64, targets: &[[[f64; 2]; 2]], separations: &Separations) -> (usize, usize, f64, usize) {
        let collapsed = (0..self.elements.len()).filter(|&f| self.collapsed(f, x, s)).count();
        (collapsed, self.wound_vertices(x).len(), self.fit_distortion(x, targets), separations.violated(x, NEAR_INTEGER).len())
    }

}

impl Rounded {
    /// Collapsed or flipped faces and tube periods narrower than
    /// [`periods::TUBE_STEPS`]: each leaves a hole or a non-manifold place
    /// in the quad mesh (a wound vertex only a vertex of valence 3).
    fn faults(&self) -> usize {
        self.collapsed + self.periods_violated
    }

    /// [`Quantizer::badness`] of the map, from its counts.
    fn badness(&self) -> usize {
        self.collapsed + polish::WOUND_WEIGHT * self.wound
    }
}

/// The outcome of one [`Quantizer::round_and_polish`].
#[derive(Default)]
struct Rounded {
    /// The plain pass alone, given up as hopeless ([`QuantizeOptions::plain_only_if_hopeless`]).
    passes_skipped: bool,
    x: Vec<f64>,
    values: Vec<Option<i64>>,
    batches: usize,
    separation_moves: usize,
    /// Integers moved to widen tube periods ([`Quantizer::widen_periods`]),
    /// and the periods `x` leaves narrower than [`periods::TUBE_STEPS`].
    period_moves: usize,
    periods_violated: usize,
    moved_integers: usize,
    arap_iterations: usize,
    untangled: bool,
    /// Collapsed or flipped faces ([`Quantizer::collapsed`]), wound
    /// vertices and [`Quantizer::fit_distortion`] of `x`.
    collapsed: usize,
    wound: usize,
    distortion: f64,
    stiff_weight: f64,
    /// Whether its fit is the graded one ([`Quantizer::graded_fit`]).
    graded: bool,
    /// Separations of its grid size, those held as rows ([`HeldApart`](super::separation::HeldApart))
    /// and those `x` leaves violated.
    separations: usize,
    separations_held: usize,
    separations_widened: usize,
    separations_violated: usize,
    /// Held pairs the relaxed map left violated (their rows dependent on
    /// the others) before any widening.
    held_dropped: usize,
    /// Local stiffening iterations the polish started from ([`Quantizer::stiffen`]).
    stiffening: usize,
    /// Whether the rounded map was bad before its polish.
    rounded_bad: bool,
    pass: Pass,
    /// Ends of feature curves left off the grid points at its grid size.
    free_curve_ends: usize,
}

/// How a pass of [`Quantizer::round_and_polish`] rounds: with `hold`,
/// holding the separations it leaves violated as rows ([`HeldApart`](super::separation::HeldApart));
/// with `widen` too, widening held rows so that the held pairs whose rows
/// are dependent are parted as well ([`Quantizer::widen_held`]).
#[derive(Clone, Copy, Default)]
struct Pass {
    hold: bool,
    widen: bool,
}

/// What a rounding at one grid length starts from: the seamless map in
/// units of the grid length `s` (`x0`), its Jacobians (the fit's targets)
/// and the rules of that length ([`SizeRules`]).
struct GridStart {
    x0: Vec<f64>,
    targets: Vec<[[f64; 2]; 2]>,
    s: f64,
    rules: SizeRules,
}

/// The [`Quantizer::badness`] of the best map so far where it is bad: the
/// bound of the next pass's polish ([`Quantizer::polish_stiffened`]).
fn bound(best: &Option<(Rounded, f64)>) -> Option<usize> {
    best.as_ref().map(|(b, _)| b.badness()).filter(|&b| b > 0)
}

/// Keeps the better of `best` and `candidate` (rounded at grid length
/// `s`) by (collapsed faces, wound vertices, fit distortion). Flipped or
/// collapsed faces leave holes in the quad mesh; a cell the map winds
/// around is closed with quads (an extra singular vertex): fewer of the
/// first, then of the second, count first.
fn keep_better(best: &mut Option<(Rounded, f64)>, candidate: Rounded, s: f64) {
    let key = |r: &Rounded| (r.faults(), r.wound, r.distortion);
    if best.as_ref().is_none_or(|(b, _)| key(&candidate) < key(b)) {
        *best = Some((candidate, s));
    }
}

/// Keeps `candidate` (rounded at grid length `s`) over `best` only where it
/// has no more faults ([`Rounded::faults`]) and no more wound vertices, and fewer of
/// both together: a pass that widens held rows stretches the map (more
/// cells, more distortion), so it has to mend the map, not trade one fault
/// for another.
fn keep_dominant(best: &mut Option<(Rounded, f64)>, candidate: Rounded, s: f64) {
    let dominates = best.as_ref().is_none_or(|(b, _)| {
        candidate.faults() <= b.faults() && candidate.wound <= b.wound && candidate.faults() + candidate.wound < b.faults() + b.wound
    });
    if dominates {
        *best = Some((candidate, s));
    }
}

/// Sum of the signed UV corner angles (`atan2`, so each corner of a flipped
/// triangle counts negative) at every vertex, `uv_of(f)` the UV triangle of
/// face `f`. Not `element::angle_sums(.., true)`: on a collapsed triangle
/// that one takes the straight corner as +pi where `atan2` can give -pi
/// (the sign of a zero cross product), and the wound-vertex counts differ.
fn corner_angle_sums(
    faces: &[[u32; 3]],
    n_vertices: usize,
    uv_of: impl Fn(usize) -> [[f64; 2]; 3],
) -> Vec<f64> {
    let mut sums = vec![0.0; n_vertices];
    for (f, face) in faces.iter().enumerate() {
        let uv = uv_of(f);
        for k in 0..3 {
            let (p, a, b) = (uv[k], uv[(k + 1) % 3], uv[(k + 2) % 3]);
            let (ea, eb) = ([a[0] - p[0], a[1] - p[1]], [b[0] - p[0], b[1] - p[1]]);
            sums[face[k] as usize] +=
                (ea[0] * eb[1] - ea[1] * eb[0]).atan2(ea[0] * eb[0] + ea[1] * eb[1]);
        }
    }
    sums
}
