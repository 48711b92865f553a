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
//!
//! Then [`Quantizer::polish`]: where the plain fit's rounded map is bad,
//! the local stiffening of Bommes et al. 2009 (MIQ; [`Quantizer::stiffen`]:
//! the fit weights near the bad faces raised by their error, re-solved a
//! few times), which spreads the spike a rounded point drags the fit along
//! as (below) before it folds; the untangler under all the integer rows
//! where the map folds (on a large mesh on patches around the folds alone:
//! [`local`]), and ARAP local/global iterations (eq. 4), each kept
//! unless it makes the map worse by [`Quantizer::badness`] (flipped or
//! collapsed triangles, wound vertices). Where the map is still bad,
//! [`Quantizer::uncollapse`] moves the integers at the bad triangles by one
//! and the moved map is polished too; the better of the two is returned.
//!
//! The fit weighs every face alike first. A rounded singular point then
//! drags the fit along as a spike (the displacement of a point constraint
//! decays within a ring), which folds its ring or winds the map around a
//! neighbour when the point moves by more than the ring is wide. Where that
//! leaves the map bad after the polish, or where only the stiffening
//! mended it (on meshes with the full budgets, for less distortion), the
//! whole rounding runs again with the faces within
//! one grid unit of every singular point [`STIFF_WEIGHTS`] times stiffer, so
//! the ring moves with its point; the pass with the fewest collapsed faces,
//! then wound vertices, then the least fit distortion is kept. Where the map
//! is still bad, one more pass holds the separations as rows
//! ([`HeldApart`]): every pair a solve leaves less than a grid line apart is
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
//! Cost: one symbolic analysis and numeric factorization of the KKT per
//! batch (the rows change; about ten batches), and up to eight passes where
//! the plain fit leaves the map bad, ten where the widened pass does best
//! (the held pass: up to [`HOLD_ROUNDS`] more factorizations before its
//! first batch, and at most [`WIDEN_TRIALS`] solves widening). With that factorization:
//! one adjoint solve per violated separation and one solve per move tried
//! (at most [`SEPARATION_TRIALS`] per batch, fewer on large meshes:
//! [`FULL_BUDGET_FACES`]); after the last batch, one
//! adjoint solve per probed unknown and one solve per `uncollapse` trial
//! (at most [`UNCOLLAPSE_TRIALS`], only where the map is bad), and one solve
//! per ARAP iteration; the untangler of a stiffer pass factors the KKT once
//! more, with the uniform fit that its energy has (on a mesh of more than
//! [`FULL_BUDGET_FACES`] faces: one small KKT per patch instead). The local
//! stiffening of a bad plain rounding: one symbolic analysis and at most
//! [`STIFFEN_ITERATIONS`] + [`RELAX_ITERATIONS`] numeric factorizations
//! with two solves each (bff-face at 1 000 quads: 1.5 s of its 4.5 s,
//! where the untangler and the moves of the passes it spares took 100 s).
//! The graded pass is one more pass where it runs (spot subdivided to 93 k
//! faces at 1 000 quads: 10.6 s of quantization, where the four passes it
//! spares took 46 s and left four wound vertices).

use super::cut_graph::cut_graph;
use super::element::{signed_uv_area, Element, NearWedges};
use super::field::cross_field;
use super::metrics;
use super::seamless::{
    self, closest_rotation, elements, seam_rows, stiffness_triplets, unknowns,
};
use super::separation::{HeldApart, Separation, Separations};
use super::untangle::{untangle, UntangleOptions, UntangleStats};
use super::{ParamError, Parametrization};
use crate::clock::Stopwatch;
use crate::cones::ConePlacement;
use crate::linalg::{
    constraint_values, independent_rows, FactorOptions, Kkt, LdltSolver, LinalgError, NullSpaceProjector, Triplet,
};
use crate::mesh::TriMesh;
use forms::{
    collapse_triples, curve_ends, integer_forms, integral_unknowns, single_unknown_forms, singular_cut_vertices,
    wedge_components, CurveEnd, Form, FormKind,
};
use parts::Part;
use serde::Serialize;
use std::cell::OnceCell;
use std::f64::consts::PI;
use std::fmt;

mod forms;
mod local;
mod parts;

/// Share of the remaining forms of a class rounded per batch.
const BATCH_FRACTION: f64 = 0.5;

/// A form within this of an integer is rounded in the current batch
/// whatever its rank (it is usually determined by forms already rounded).
const NEAR_INTEGER: f64 = 1e-6;

/// Times a batch is solved again with its conflicting forms moved first.
const MAX_REORDERS: usize = 8;

/// Rounded integers moved, at most per batch, so that forms the others
/// determine come out integers ([`Quantizer::restore_parity`]).
const PARITY_MOVES: usize = 64;

/// Share of its seamless-map UV area below which a triangle counts as
/// collapsed (squeezed onto a grid line: the exact snapping of the integers
/// afterwards makes it degenerate).
const COLLAPSED_SHARE: f64 = 1e-6;

/// Weight of a wound vertex in [`Quantizer::badness`].
const WOUND_WEIGHT: usize = 16;

/// Integer moves tried against flipped or collapsed triangles, at most.
const UNCOLLAPSE_TRIALS: usize = 40;

/// Radius (grid units) within which an integer of the seamless map side by
/// side with a singular point must stay a grid line from it ([`Separations`]).
const SEPARATION_RADIUS: f64 = 1.0;

/// Feature curves shorter than this many grid cells keep their inner ends
/// off the grid points ([`CurveEnd`]).
const CURVE_END_CELLS: f64 = 1.0;

/// Re-solves spent restoring separations after a batch, at most.
const SEPARATION_TRIALS: usize = 200;

/// Moves that mend one separation by breaking another, at most per batch.
const SIDEWAYS_MOVES: usize = 8;

/// Integers tried per violated separation.
const CANDIDATES_PER_SEPARATION: usize = 16;

/// Unknowns of bad triangles whose sensitivities pick the integers
/// [`Quantizer::uncollapse`] tries, at most per round.
const UNCOLLAPSE_PROBES: usize = 48;

/// Relative residual of every solve.
const SOLVE_TOLERANCE: f64 = 1e-12;
/// Relative residual at which a solve whose refinement stagnates is taken
/// as it is. These KKTs reach 4-7e-12 in floating point, about
/// [`SOLVE_TOLERANCE`]; finishing such solves by GMRES took 3-7 triangular
/// solves each where one or two do.
const STALL_ACCEPT: f64 = 1e-10;
/// Relative residual of the untangler's preconditioner solves: they only
/// shape the L-BFGS steps, and refining them to 1e-8 made a bad map's
/// quantization 2.5x slower (plate with five holes at 3 000 quads: 101 s
/// against 41 s, the same defects).
const PRECONDITION_TOLERANCE: f64 = 1e-4;

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

/// Radius (grid units) of the stiff faces around a singular point.
const STIFF_RADIUS: f64 = 1.0;

/// The graded fit ([`Quantizer::graded_fit`]): its weight `1 + (rho / r)^2`
/// at distance `r` (grid units) from a singular point, `rho` =
/// [`GRADED_RADIUS`], on the faces within [`GRADED_REACH`] of one, capped
/// at [`MAX_GRADED_WEIGHT`] (a face around the point itself, `r` ~ 0).
const GRADED_RADIUS: f64 = 1.0;
const GRADED_REACH: f64 = 3.0;
const MAX_GRADED_WEIGHT: f64 = 1e4;

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

/// Solves of the relaxed map before the held pass's first batch, each
/// holding the separations the one before left violated ([`HeldApart`]).
const HOLD_ROUNDS: usize = 3;

/// Held rows the held pass may try widened by a line before its first batch
/// ([`Quantizer::widen_held`]; a share on large meshes, [`Quantizer::budget`]).
const WIDEN_TRIALS: usize = 32;

/// Meshes up to this many faces get the full budgets of extra solves
/// ([`SEPARATION_TRIALS`], [`UNCOLLAPSE_TRIALS`], [`UNCOLLAPSE_PROBES`] and
/// the untangler's default iterations); larger ones a share `FULL_BUDGET_FACES
/// / faces` of them (at least [`MIN_BUDGET_SHARE`]), since each solve costs
/// in proportion: on a 114 k-face mesh with dense lone features the full
/// budgets spent 85 s of 93 on separations, untangling and moves that did
/// not mend the map.
const FULL_BUDGET_FACES: f64 = 20_000.0;

/// Least share of the full budgets.
const MIN_BUDGET_SHARE: f64 = 0.1;

/// Radii (grid cells) of the patches around inverted faces that the polish
/// of a mesh of more than [`FULL_BUDGET_FACES`] untangles in turn, each
/// around the faces the one before left inverted, before the whole map
/// ([`local`]); their most vertex rings, and the largest share of the faces
/// a patch may take.
const PATCH_CELLS: [f64; 2] = [3.0, 6.0];
const MAX_PATCH_RINGS: usize = 64;
const MAX_PATCH_SHARE: f64 = 0.25;

/// Stalled `eps` updates the polish's untangler waits for, at least.
const MIN_UNTANGLE_PATIENCE: usize = 3;

/// ARAP iterations after the rounding, at most.
const ARAP_ITERATIONS: usize = 20;

/// Local stiffening re-solves of a rounded map that is bad, at most
/// ([`Quantizer::stiffen`]), and the largest weight a face reaches.
const STIFFEN_ITERATIONS: usize = 10;
const MAX_STIFFENING: f64 = 1e6;

/// Stiffening iterations without a less bad map after which it stops: where
/// the rounding itself squeezed the map (dense feature curves), the
/// badness bounces instead of falling.
const STIFFEN_PATIENCE: usize = 3;

/// Radius (grid cells) around the bad faces of a map within which
/// [`Quantizer::stiffen`] raises the weights.
const STIFFEN_CELLS: f64 = 1.0;

/// Steps that relax a clean stiffened map's weights towards 1, at most,
/// and the share of each weight's excess over 1 a step keeps.
const RELAX_ITERATIONS: usize = 8;
const RELAX_FACTOR: f64 = 0.5;

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

impl From<crate::linalg::LinalgError> for QuantizeError {
    fn from(e: crate::linalg::LinalgError) -> Self {
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
    /// Separations held as rows in the pass kept (0 unless the held pass
    /// was run and kept: [`HeldApart`]), and those of them widened to
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
    /// Vertices around which the map winds (UV angle sum off the seamless map's by 2 pi).
    pub wound_vertices: usize,
    /// Total UV area in grid cells (about the number of quads).
    pub cells: f64,
    pub seconds: f64,
}

/// An integer-grid map: one UV per face corner (`3 f + k`) in grid units.
#[derive(Clone, Debug)]
pub struct IntegerGridMap {
    pub uv: Vec<[f64; 2]>,
    pub report: QuantizeReport,
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

    /// Faces within [`STIFF_RADIUS`] grid units (in the seamless map `x0`,
    /// grid units) of a singular point, reached through faces of its chart:
    /// a rounded point drags a fit of uniform weight along as a spike (a
    /// harmonic displacement from one point decays within a ring), which
    /// folds its ring or winds the map around a neighbour when the point
    /// moves by more than the ring is wide; stiffer faces around it carry
    /// the ring along and leave the distortion to the regular faces beyond.
    fn stiff_faces(&self, x0: &[f64]) -> Vec<bool> {
        let mut stiff = vec![false; self.elements.len()];
        self.walk_singular_points(x0, STIFF_RADIUS, |f, _| stiff[f] = true);
        stiff
    }

    /// Calls `visit(f, p)` for every face around the wedges reached from
    /// each singular point `p` (a wedge both of whose coordinates are
    /// forms) through wedges of its chart within `radius` grid units of it
    /// in the seamless map `x0` (grid units).
    fn walk_singular_points(&self, x0: &[f64], radius: f64, mut visit: impl FnMut(usize, [f64; 2])) {
        let n_wedges = self.vars[0].len();
        let mut near = NearWedges::new(&self.elements, n_wedges);
        for c in (0..n_wedges).filter(|&w| (0..2).all(|k| self.form_of[self.vars[k][w]] != usize::MAX)) {
            let p = [x0[self.vars[0][c]], x0[self.vars[1][c]]];
            near.walk(&self.elements, x0, c, p, radius, |f| visit(f, p));
        }
    }

    /// The graded fit for the seamless map `x0` (grid units): weight
    /// `1 + (rho / r)^2` on a face at distance `r` from the nearest
    /// singular point of its chart ([`GRADED_RADIUS`], [`GRADED_REACH`]).
    /// With uniform weights, the displacement `d` of a rounded point decays
    /// like `log r` (the fit's Green's function), and its slope at the
    /// point's first ring, `d / (h log(R / h))` for edges of length `h`,
    /// grows as the mesh gets finer than the grid until the ring folds or
    /// winds; under these weights the radial solution has slope
    /// `2 d r / ((r^2 + rho^2) log(1 + R^2 / rho^2))`, flat at the point
    /// and at most `d / (rho log(1 + R^2 / rho^2))` whatever `h` (spot
    /// subdivided to 93 k faces, 1 000 quads: the plain fit winds around 51
    /// vertices, this one around 5, mended by the local stiffening).
    fn graded_fit(&self, x0: &[f64]) -> Fit {
        let mut r = vec![f64::INFINITY; self.elements.len()];
        self.walk_singular_points(x0, GRADED_REACH * GRADED_RADIUS, |f, p| {
            let uv = self.elements[f].unknowns_uv(x0);
            let centroid = [0, 1].map(|k| (uv[0][k] + uv[1][k] + uv[2][k]) / 3.0);
            r[f] = r[f].min((centroid[0] - p[0]).hypot(centroid[1] - p[1]));
        });
        let weights: Vec<f64> = r.iter().map(|&r| 1.0 + (GRADED_RADIUS * GRADED_RADIUS / (r * r)).min(MAX_GRADED_WEIGHT)).collect();
        Fit { stiffness: stiffness_triplets(&self.elements, &weights), weights, stiff_weight: 1.0, graded: true }
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
        let Rounded { mut x, values, batches, separation_moves, moved_integers, arap_iterations, stiffening, untangled, stiff_weight, separations, separations_held, separations_widened, separations_violated, free_curve_ends, graded, .. } = rounded;
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
        let flipped = self.flipped(&x);
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
            flipped,
            wound_vertices: self.wound_vertices(&x).len(),
            cells,
            seconds: clock.lap(),
        };
        Ok(IntegerGridMap { uv, report })
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
        let plain = self.round_and_polish(&plain_fit, &grid, Pass::default(), progress)?.expect("a plain pass");
        let bad = |b: &Rounded| b.collapsed + b.wound > 0;
        let is_bad = |best: &Option<(Rounded, f64)>| best.as_ref().is_some_and(|(b, _)| bad(b));
        // Stiffer fits mend a few bad places next to cones; the held
        // separations mend collapses between parallel lines, and go first
        // where the plain fit leaves separations violated.
        let few = bad(&plain) && plain.collapsed + plain.wound <= STIFF_PASS_LIMIT;
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
            let rounded = self.round_and_polish(&self.graded_fit(&grid.x0), &grid, Pass::default(), progress)?.expect("a graded pass");
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
            let rounded = self.round_and_polish(&Fit::new(&self.elements, &stiff, weight), &grid, Pass::default(), progress)?.expect("a stiff pass");
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
            if b.collapsed == 0 && (b.wound == 0 || !options.retry_wound) {
                break;
            }
            let (held, best_pass) = (Pass { hold: b.separations_held > 0, widen: false }, b.pass);
            let retried = self.grid_start(s * factor);
            for pass in [held, best_pass].into_iter().take(if best_pass.widen { 2 } else { 1 }) {
                match self.round_and_polish(&plain_fit, &retried, pass, progress)? {
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
        let rounded = self.round_and_polish(fit, grid, Pass { hold: true, widen: false }, progress)?.expect("a held pass");
        let widen = rounded.held_dropped > 0 && rounded.collapsed + rounded.wound > 0;
        keep_better(best, rounded, grid.s);
        if widen {
            if let Some(rounded) = self.round_and_polish(fit, grid, Pass { hold: true, widen: true }, progress)? {
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
            joined.separation_moves += r.separation_moves;
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

    /// One greedy rounding of all forms with the fit `fit` (batches of
    /// [`BATCH_FRACTION`], each re-solved, separations restored), then
    /// [`Self::polish`], and where the map is still bad [`Self::uncollapse`]
    /// and polish again, keeping the better. With `pass.hold`, the relaxed
    /// map first and every batch after it hold the separations they leave
    /// violated ([`HeldApart`]); with `pass.widen` too, held rows are
    /// widened first ([`Self::widen_held`]), and the pass is not run
    /// (`None`) where that widens nothing: it would repeat the held pass.
    fn round_and_polish(&self, fit: &Fit, grid: &GridStart, pass: Pass, progress: &mut dyn FnMut(usize, usize)) -> Result<Option<Rounded>, QuantizeError> {
        let GridStart { x0, targets, s, rules } = grid;
        let s = *s;
        let separations = &rules.separations;
        let mut values: Vec<Option<i64>> = vec![None; self.forms.len()];
        let mut order: Vec<usize> = Vec::new();
        let mut x = x0.to_vec();
        let mut batches = 0;
        let mut separation_moves = 0;
        let mut system = None;
        let mut held = HeldApart::default();
        let mut held_dropped = 0;
        if pass.hold {
            let mut relaxed = None;
            for _ in 0..HOLD_ROUNDS {
                if held.hold_violated(separations, &x, NEAR_INTEGER) == 0 {
                    break;
                }
                let solved = self.solve(fit, &order, &values, &x, targets, &held)?.0;
                x = solved.x.clone();
                relaxed = Some(solved);
            }
            if relaxed.is_none() && pass.widen {
                return Ok(None);
            }
            if let Some(mut relaxed) = relaxed {
                held_dropped = held.violated(&relaxed.x, NEAR_INTEGER).len();
                // A widened pass that widens nothing would repeat the held
                // pass step for step.
                if pass.widen && self.widen_held(&mut relaxed, &mut held, x0, targets)? == 0 {
                    return Ok(None);
                }
                x = relaxed.x;
            }
        }
        for kind in [FormKind::Cone, FormKind::Point, FormKind::Translation] {
            loop {
                let mut free: Vec<(f64, usize)> = (0..self.forms.len())
                    .filter(|&i| values[i].is_none() && self.forms[i].kind == kind && !rules.free[i])
                    .map(|i| (distance_to_integer(self.forms[i].value(&x)), i))
                    .collect();
                if free.is_empty() {
                    break;
                }
                free.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                // The nearest share of the forms, and every form already near
                // an integer.
                let near = free.iter().filter(|f| f.0 < NEAR_INTEGER).count();
                let take = ((free.len() as f64 * BATCH_FRACTION).ceil() as usize).max(near).min(free.len());
                let mut batch: Vec<usize> = free[..take].iter().map(|f| f.1).collect();
                let before = order.len();
                let mut retries = 0;
                let (solved, dependent) = loop {
                    for &i in &batch {
                        values[i] = None;
                    }
                    for &i in &batch {
                        values[i] = Some(self.rounding(i, &values, &x, separations));
                    }
                    order.truncate(before);
                    order.extend(&batch);
                    let (solved, dependent) = self.solve(fit, &order, &values, &x, targets, &held)?;
                    // A candidate the others determine at a non-integer value (a
                    // dependency with coefficient 1/2 the kind order missed): round
                    // it first instead, so that it determines them.
                    let conflicting: Vec<usize> = dependent
                        .iter()
                        .copied()
                        .filter(|&i| {
                            batch.contains(&i)
                                && distance_to_integer(self.forms[i].value(&solved.x))
                                    > NEAR_INTEGER
                        })
                        .collect();
                    if conflicting.is_empty() || retries == MAX_REORDERS {
                        break (solved, dependent);
                    }
                    retries += 1;
                    batch.retain(|i| !conflicting.contains(i));
                    batch.splice(0..0, conflicting);
                };
                let mut solved = solved;
                self.restore_parity(&mut solved, &dependent, &mut values, x0, targets)?;
                separation_moves += self.separate(&mut solved, &mut values, x0, targets, separations)?;
                x = solved.x.clone();
                if pass.hold {
                    held.hold_violated(separations, &x, NEAR_INTEGER);
                }
                // A candidate the batch's other forms already determine takes the
                // value the solve gives it.
                for i in dependent {
                    values[i] = Some(self.forms[i].value(&x).round() as i64);
                }
                system = Some(solved);
                batches += 1;
                progress(
                    values.iter().filter(|v| v.is_some()).count(),
                    self.forms.len(),
                );
            }
        }
        // The rounded map polished (untangled where it folds, then ARAP);
        // where it is still bad, the same after moving integers off collapses,
        // keeping whichever ends better.
        // The stiffer fits stiffen faces around singular points already.
        let stiffen = fit.stiff_weight == 1.0;
        let mut moved_integers = 0;
        let mut polish = Polished::default();
        let mut rounded_bad = false;
        if let Some(mut moved_system) = system {
            polish = self.polish(x.clone(), &moved_system, targets, s, stiffen)?;
            rounded_bad = polish.rounded_bad > 0;
            let rounded = std::mem::replace(&mut x, std::mem::take(&mut polish.x));
            if polish.bad > 0 && UNCOLLAPSE_TRIALS > 0 {
                let (mut moved_values, mut moved_x) = (values.clone(), rounded);
                let moves = self.uncollapse(
                    &mut moved_values,
                    &mut moved_x,
                    &mut moved_system,
                    x0,
                    targets,
                    s,
                    separations,
                )?;
                if moves > 0 {
                    let mut moved = self.polish(moved_x, &moved_system, targets, s, stiffen)?;
                    if moved.bad < polish.bad {
                        (x, values, moved_integers) = (std::mem::take(&mut moved.x), moved_values, moves);
                        polish = moved;
                    }
                }
            }
        }
        let (collapsed, wound, distortion, separations_violated) = self.assess(&x, s, targets, separations);
        Ok(Some(Rounded {
            x,
            values,
            batches,
            separation_moves,
            moved_integers,
            arap_iterations: polish.arap_iterations,
            untangled: polish.untangled,
            stiffening: polish.stiffening,
            collapsed,
            wound,
            distortion,
            stiff_weight: fit.stiff_weight,
            graded: fit.graded,
            separations: separations.list.len(),
            separations_held: held.list.len(),
            separations_widened: held.gaps.iter().filter(|&&g| g > 1).count(),
            held_dropped,
            rounded_bad,
            pass,
            separations_violated,
            free_curve_ends: self.curve_ends.iter().filter(|end| end.free_at(s)).count(),
        }))
    }

    /// Area-weighted mean of `|J_f - T_f|^2` over the faces (the fit's
    /// objective with uniform weights), to compare maps of one grid size.
    fn fit_distortion(&self, x: &[f64], targets: &[[[f64; 2]; 2]]) -> f64 {
        let (mut sum, mut area) = (0.0, 0.0);
        for (el, t) in self.elements.iter().zip(targets) {
            sum += fit_error(el, x, t);
            area += el.area;
        }
        sum / area
    }

    /// The integer form `i` is rounded to: the nearest, unless that puts a
    /// triangle whose three corners lie on rounded forms of one coordinate
    /// (two feature isolines less than a cell apart, say) onto one grid
    /// line; then the next integer on `i`'s side of the others.
    fn rounding(&self, i: usize, values: &[Option<i64>], x: &[f64], separations: &Separations) -> i64 {
        let y = self.forms[i].value(x);
        let v = y.round() as i64;
        for triple in &self.triples[i] {
            let others: Vec<usize> = triple.iter().copied().filter(|&j| j != i).collect();
            if !others.iter().all(|&j| values[j] == Some(v)) {
                continue;
            }
            let (lo, hi) = others
                .iter()
                .map(|&j| self.forms[j].value(x))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                    (l.min(y), h.max(y))
                });
            if y > hi {
                return self.separated(i, v + 1, values, separations);
            } else if y < lo {
                return self.separated(i, v - 1, values, separations);
            }
        }
        self.separated(i, v, values, separations)
    }

    /// `v` moved the least so that form `i` stays a grid line apart from
    /// every rounded form it must be separated from; `v` when no integer
    /// meets all of them.
    fn separated(&self, i: usize, v: i64, values: &[Option<i64>], separations: &Separations) -> i64 {
        let value = |u: usize| self.form_of.get(u).and_then(|&f| values.get(f).copied().flatten());
        let (lower, upper) = separations.bounds(i, &self.form_of, value);
        if lower <= upper {
            v.clamp(lower, upper)
        } else {
            v
        }
    }

    /// Whether every rounded form (`values` set) is an integer in `x`.
    fn rounded_forms_integral(&self, values: &[Option<i64>], x: &[f64]) -> bool {
        values.iter().zip(&self.forms).all(|(v, f)| v.is_none() || distance_to_integer(f.value(x)) < NEAR_INTEGER)
    }

    /// Every rounded form set to its (integer) value in `x`: a move of one
    /// integer moves the forms it determines by integers too.
    fn take_determined_values(&self, values: &mut [Option<i64>], x: &[f64]) {
        for (value, form) in values.iter_mut().zip(&self.forms) {
            if value.is_some() {
                *value = Some(form.value(x).round() as i64);
            }
        }
    }

    /// The rules of grid size `s` for the seamless map `x0` (grid units):
    /// the separations within [`SEPARATION_RADIUS`], and the ends of curves
    /// shorter than [`CURVE_END_CELLS`] left free.
    fn size_rules(&self, x0: &[f64], s: f64) -> SizeRules {
        let separations = Separations::new(&self.elements, &self.integral, x0, SEPARATION_RADIUS, &self.form_of, self.forms.len());
        let mut free = vec![false; self.forms.len()];
        for end in self.curve_ends.iter().filter(|end| end.free_at(s)) {
            free[end.form] = true;
        }
        SizeRules { separations, free }
    }

    /// Restores violated separations after a batch: a form the others
    /// determine cannot be rounded apart directly, so for each violated pair
    /// the change of its gap per unit change of every rounded integer comes
    /// from one adjoint solve (`K⁻¹ [c; 0]`, the multipliers), and
    /// the integers that widen it, closest to their seamless values first,
    /// are tried moved by one (by two where the gap gains a half per unit),
    /// each re-solved with the same factorization. A
    /// move is kept when every form stays integer and fewer separations stay
    /// violated; when none does, the cheapest move that mends one pair at
    /// the price of another is taken (at most [`SIDEWAYS_MOVES`], never back
    /// to a state seen before), since the collapse often moves along a chain
    /// of isolines before it finds room. Returns the moves kept.
    fn separate(
        &self,
        system: &mut RoundedSystem,
        values: &mut [Option<i64>],
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        separations: &Separations,
    ) -> Result<usize, QuantizeError> {
        let mut violated = separations.violated(&system.x, NEAR_INTEGER);
        let (mut moves, mut trials, mut sideways) = (0, 0, 0);
        let mut seen = std::collections::HashSet::new();
        seen.insert(values.to_vec());
        let max_trials = self.budget(SEPARATION_TRIALS);
        while !violated.is_empty() && trials < max_trials {
            let mut best: Option<SeparationMove> = None;
            let mut improved = false;
            'pairs: for sep in violated.clone() {
                // The gap x_hi - x_lo is linear: one adjoint solve for it
                // (counted with the trials: each is a solve).
                if trials >= max_trials {
                    break 'pairs;
                }
                trials += 1;
                let gap_gain = system.sensitivity(&[(sep.hi, 1), (sep.lo, -1)])?;
                let mut candidates: Vec<(f64, usize, usize, i64)> = system
                    .form_rows
                    .iter()
                    .filter_map(|&(form, row)| {
                        let v = values[form]?;
                        let step = widening_step(gap_gain[row])?;
                        let cost = ((v + step) as f64 - self.forms[form].value(x0)).abs();
                        Some((cost, form, row, step))
                    })
                    .collect();
                candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
                for &(_, form, row, step) in candidates.iter().take(CANDIDATES_PER_SEPARATION) {
                    if trials >= max_trials {
                        break 'pairs;
                    }
                    let mut trial = values.to_vec();
                    trial[form] = Some(values[form].unwrap_or(0) + step);
                    if seen.contains(&trial) {
                        continue;
                    }
                    trials += 1;
                    system.b[row] += step as f64;
                    let x = system.resolve(self, targets)?;
                    system.b[row] -= step as f64;
                    if !self.rounded_forms_integral(&trial, &x) {
                        continue;
                    }
                    let after = separations.violated(&x, NEAR_INTEGER);
                    if after.len() < violated.len() {
                        best = Some(SeparationMove { row, step, x, values: trial, violated: after });
                        improved = true;
                        break 'pairs;
                    }
                    if best.is_none() && after.len() == violated.len() && !after.contains(&sep) {
                        best = Some(SeparationMove { row, step, x, values: trial, violated: after });
                    }
                }
            }
            let Some(SeparationMove { row, step, x, values: trial, violated: after }) = best else { break };
            if !improved {
                if sideways == SIDEWAYS_MOVES {
                    break;
                }
                sideways += 1;
            }
            system.b[row] += step as f64;
            system.x = x;
            values.copy_from_slice(&trial);
            self.take_determined_values(values, &system.x);
            seen.insert(values.to_vec());
            violated = after;
            moves += 1;
        }
        Ok(moves)
    }

    /// Moves rounded integers by one until every form in `dependent` (those
    /// the rounded forms determine) is an integer in `system.x` (at most
    /// [`PARITY_MOVES`]). Transitions of 90° are determined only up to a sublattice:
    /// a cone's position `c` across a seam of rotation `R` gives `(I - R) c`,
    /// of determinant 2, so a form may be determined at half an integer when
    /// the integers it depends on were rounded independently (a genus-2 block
    /// without features at 3 000 cells: 18 translations at n + 1/2). The form's
    /// dependence on every rounded row is one adjoint solve
    /// ([`RoundedSystem::sensitivity`]); of the rounded integers that a step
    /// of one makes it integral, the one whose step costs least (its new
    /// value nearest the seamless map's) moves, without a new factorization.
    fn restore_parity(
        &self,
        system: &mut RoundedSystem,
        dependent: &[usize],
        values: &mut [Option<i64>],
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
    ) -> Result<(), QuantizeError> {
        for _ in 0..PARITY_MOVES {
            let off = |i: &&usize| distance_to_integer(self.forms[**i].value(&system.x)) > NEAR_INTEGER;
            let Some(&i) = dependent.iter().find(off) else { break };
            let value = self.forms[i].value(&system.x);
            let gain = system.sensitivity(&self.forms[i].row)?;
            let best = system
                .form_rows
                .iter()
                .flat_map(|&(form, row)| [(form, row, 1), (form, row, -1)])
                .filter(|&(_, row, step)| distance_to_integer(value + gain[row] * step as f64) < NEAR_INTEGER)
                .filter_map(|(form, row, step)| {
                    let v = values[form]?;
                    Some((((v + step) as f64 - self.forms[form].value(x0)).abs(), form, row, step))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let Some((_, form, row, step)) = best else { break };
            values[form] = values[form].map(|v| v + step);
            system.b[row] += step as f64;
            system.x = system.resolve(self, targets)?;
        }
        Ok(())
    }

    /// `full` scaled by the share of the full budgets this mesh gets
    /// ([`FULL_BUDGET_FACES`]), at least 1.
    fn budget(&self, full: usize) -> usize {
        let share = (FULL_BUDGET_FACES / self.elements.len().max(1) as f64).clamp(MIN_BUDGET_SHARE, 1.0);
        ((full as f64 * share).round() as usize).max(1)
    }

    /// The untangler's options in [`Self::polish`]: the default, its total
    /// iterations and patience scaled by [`Self::budget`] (patience at
    /// least [`MIN_UNTANGLE_PATIENCE`]).
    fn polish_untangle(&self) -> UntangleOptions {
        let default = UntangleOptions::default();
        UntangleOptions {
            max_total: self.budget(default.max_total),
            patience: self.budget(default.patience).max(MIN_UNTANGLE_PATIENCE),
            ..default
        }
    }

    /// Where `x` is bad and with `stiffen`, starts from its least bad local
    /// stiffening ([`Self::stiffen`]); untangles it under `system`'s rows
    /// when it folds, then runs ARAP local/global iterations (eq. 4), each
    /// step kept unless it makes the map worse by [`Self::badness`].
    fn polish(
        &self,
        mut x: Vec<f64>,
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
        s: f64,
        stiffen: bool,
    ) -> Result<Polished, QuantizeError> {
        let rounded_bad = self.badness(&x, s);
        let mut bad = rounded_bad;
        let mut stiffening = 0;
        if bad > 0 && stiffen {
            (x, bad, stiffening) = self.stiffen(x, bad, system, targets, s)?;
        }
        let mut arap_iterations = 0;
        let mut untangled = false;
        // The untangler mends inverted triangles; a map whose only fault is a
        // vertex it winds around twice has none to mend.
        if (0..self.elements.len()).any(|f| self.collapsed(f, &x, s)) {
            // Untangle in model units (the barrier's area term wants det J ~ 1):
            // around the folds on a large mesh, else the whole map.
            let mut xm: Vec<f64> = x.iter().map(|v| v * s).collect();
            let stats = match self.untangle_locally(&mut xm, system, s)? {
                Some(stats) => stats,
                None => {
                    let projector =
                        NullSpaceProjector::new(&system.c, self.n_unknowns, system.b.len()).ok();
                    let solver = system.untangle_solver(self)?;
                    let precondition = |q: &mut [f64]| precondition(solver, system.b.len(), q, projector.as_ref());
                    untangle(&self.elements, &precondition, &mut xm, &self.polish_untangle())
                }
            };
            let candidate = system.onto_constraints(xm.iter().map(|v| v / s).collect())?;
            let f = self.badness(&candidate, s);
            if f < bad {
                x = candidate;
                bad = f;
                untangled = stats.inverted == 0 && f == 0;
            }
        }
        for _ in 0..ARAP_ITERATIONS {
            let r: Vec<[[f64; 2]; 2]> = self
                .elements
                .iter()
                .zip(targets)
                .map(|(el, t)| {
                    closest_rotation(el.jacobian(&x))
                        .map(|r| r.map(|row| row.map(|v| v / s)))
                        .unwrap_or(*t)
                })
                .collect();
            // Put back onto the rows: the graded fit's weights (up to 1e4)
            // leave an ARAP solve off them by about 1e-9.
            let next = system.onto_constraints(system.resolve(self, &r)?)?;
            let f = self.badness(&next, s);
            if f > bad {
                break;
            }
            let moved = next
                .iter()
                .zip(&x)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            x = next;
            bad = f;
            arap_iterations += 1;
            if moved < 1e-4 {
                break;
            }
        }
        Ok(Polished { x, bad, rounded_bad, arap_iterations, untangled, stiffening })
    }

    /// The local stiffening of Bommes et al. 2009 (MIQ) of the rounded map
    /// `x` (badness `bad`) under `system`'s rows: the fit weight of every
    /// face within [`STIFFEN_CELLS`] of a bad one ([`Self::flipped_faces`])
    /// is multiplied by `1 + e_f`, `e_f` its relative Jacobian error
    /// `|J_f - T_f| / |T_f|` plus one where it is collapsed, and the map
    /// solved again, at most [`STIFFEN_ITERATIONS`] times while it is bad.
    /// A rounded point drags the uniform fit along as a spike (the
    /// displacement of a point constraint decays within a ring), which
    /// folds its ring or winds the map around it; the weights grow fastest
    /// where the spike is sharpest and spread it until the ring moves with
    /// its point; a clean map's weights then relax towards 1 while it stays
    /// clean. Returns the least bad map, its badness and the iterations
    /// that led to it (0: none made the map less bad). One symbolic
    /// analysis, one numeric factorization per iteration; each solve is put
    /// back onto the rows by `system` (heavy weights leave it off them by
    /// up to 1e-9), and one that fails ends the iterations.
    fn stiffen(
        &self,
        mut x: Vec<f64>,
        mut bad: usize,
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
        s: f64,
    ) -> Result<(Vec<f64>, usize, usize), QuantizeError> {
        let mut weights = system.weights.clone();
        let mut best_weights: Option<(Vec<f64>, usize)> = None;
        let mut kkt = Kkt::assemble(&stiffness_triplets(&self.elements, &weights), self.n_unknowns, &system.c, system.b.len())?;
        let mut solver: Option<LdltSolver> = None;
        let mut current = x.clone();
        let rings = self.rings(STIFFEN_CELLS, s);
        for iteration in 1..=STIFFEN_ITERATIONS {
            let near = local::faces_around(&self.faces, &self.flipped_faces(&current, s), rings);
            for (f, (el, t)) in self.elements.iter().zip(targets).enumerate().filter(|&(f, _)| near[f]) {
                let j = el.jacobian(&current);
                let norm = |m: [[f64; 2]; 2]| m.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
                let error = norm([[j[0][0] - t[0][0], j[0][1] - t[0][1]], [j[1][0] - t[1][0], j[1][1] - t[1][1]]]) / norm(*t).max(f64::MIN_POSITIVE);
                let collapsed = if self.collapsed(f, &current, s) { 1.0 } else { 0.0 };
                weights[f] = (weights[f] * (1.0 + error + collapsed)).min(MAX_STIFFENING);
            }
            // A solve the heavy weights make fail ends the stiffening.
            let Ok(solved) = self.weighted_solve(&mut kkt, &mut solver, &weights, system, targets) else { break };
            current = solved;
            let next = self.badness(&current, s);
            if next < bad {
                (x, bad, best_weights) = (current.clone(), next, Some((weights.clone(), iteration)));
            }
            let since_best = iteration - best_weights.as_ref().map_or(0, |b| b.1);
            if bad == 0 || since_best >= STIFFEN_PATIENCE {
                break;
            }
        }
        let Some((best, iterations)) = best_weights else { return Ok((x, bad, 0)) };
        // A clean map's weights relax towards 1 while it stays clean (the
        // least distortion that does not fold).
        if bad == 0 {
            for step in 1..=RELAX_ITERATIONS {
                let keep = RELAX_FACTOR.powi(step as i32);
                weights = best.iter().map(|w| 1.0 + (w - 1.0) * keep).collect();
                let Ok(relaxed) = self.weighted_solve(&mut kkt, &mut solver, &weights, system, targets) else { break };
                if self.badness(&relaxed, s) > 0 {
                    break;
                }
                x = relaxed;
            }
        }
        Ok((x, bad, iterations))
    }

    /// The map closest to `targets` with fit weights `weights` under
    /// `system`'s rows, put back onto them by `system`: `kkt` (assembled on
    /// `system`'s rows) refilled and factored by `solver`, whose symbolic
    /// analysis is made on first use and kept.
    fn weighted_solve(
        &self,
        kkt: &mut Kkt,
        solver: &mut Option<LdltSolver>,
        weights: &[f64],
        system: &RoundedSystem,
        targets: &[[[f64; 2]; 2]],
    ) -> Result<Vec<f64>, QuantizeError> {
        kkt.refill(&stiffness_triplets(&self.elements, weights), &system.c)?;
        let solver = match solver {
            Some(solver) => {
                solver.factorize(&kkt.values)?;
                solver
            }
            None => solver.insert(factored(kkt)?),
        };
        system.onto_constraints(fit_solve(solver, self, weights, targets, &system.b)?)
    }

    /// Where the rounded map has flipped or collapsed triangles or wound
    /// vertices, moves by one the integers that move their corners (found by
    /// adjoint solves as in [`Self::separate`], so a translation whose seam
    /// passes there counts too), closest to their seamless values first,
    /// keeping each move that leaves a less bad map ([`Self::badness`]) and
    /// no more violated separations, every form still integer. One solve
    /// with `system`'s factorization per trial, at most
    /// [`UNCOLLAPSE_TRIALS`]. Returns the moves kept.
    fn uncollapse(
        &self,
        values: &mut [Option<i64>],
        x: &mut Vec<f64>,
        system: &mut RoundedSystem,
        x0: &[f64],
        targets: &[[[f64; 2]; 2]],
        s: f64,
        separations: &Separations,
    ) -> Result<usize, QuantizeError> {
        let mut badness = self.badness(x, s);
        let violated = separations.violated(x, NEAR_INTEGER).len();
        let (mut trials, mut kept) = (0, 0);
        let mut tried = std::collections::HashSet::new();
        let (max_trials, max_probes) = (self.budget(UNCOLLAPSE_TRIALS), self.budget(UNCOLLAPSE_PROBES));
        while badness > 0 && trials < max_trials {
            let mut unknowns: Vec<usize> = self
                .flipped_faces(x, s)
                .iter()
                .flat_map(|&f| self.elements[f].x.iter().flatten().copied())
                .collect();
            unknowns.sort_unstable();
            unknowns.dedup();
            unknowns.truncate(max_probes);
            let mut gain = vec![0.0f64; system.b.len()];
            let probes: Vec<[(usize, i64); 1]> = unknowns.iter().map(|&u| [(u, 1)]).collect();
            for column in system.sensitivities(&probes)? {
                for (g, d) in gain.iter_mut().zip(column) {
                    *g = g.max(d.abs());
                }
            }
            let mut candidates: Vec<(f64, usize, usize, i64)> = system
                .form_rows
                .iter()
                .filter(|&&(_, row)| gain[row] > 0.5)
                .flat_map(|&(form, row)| {
                    let v = values[form].unwrap_or(0);
                    let y = self.forms[form].value(x0);
                    [1, -1].map(|step| (((v + step) as f64 - y).abs(), form, row, step))
                })
                .collect();
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut improved = false;
            for (_, form, row, step) in candidates {
                let v = values[form].unwrap_or(0) + step;
                if trials >= max_trials || !tried.insert((form, v)) {
                    continue;
                }
                trials += 1;
                system.b[row] += step as f64;
                let moved = system.resolve(self, targets)?;
                let after = self.badness(&moved, s);
                if self.rounded_forms_integral(values, &moved) && after < badness && separations.violated(&moved, NEAR_INTEGER).len() <= violated {
                    values[form] = Some(v);
                    self.take_determined_values(values, &moved);
                    system.x = moved.clone();
                    *x = moved;
                    badness = after;
                    kept += 1;
                    improved = true;
                    break;
                }
                system.b[row] -= step as f64;
            }
            if !improved {
                break;
            }
        }
        Ok(kept)
    }

    /// [`local::Patch::untangle`] of `xm` (model units) on the faces within
    /// [`PATCH_CELLS`] grid cells of its inverted ones, under `system`'s
    /// rows, each radius around the faces the one before left inverted.
    /// `None` (the whole map is to be untangled) on meshes of at most
    /// [`FULL_BUDGET_FACES`] faces (there the whole map costs little more and
    /// spreads the distortion), when nothing is inverted, or when a patch
    /// would cover more than [`MAX_PATCH_SHARE`] of the faces (the folds are
    /// spread). Folds left by the widest patch are held by the integers:
    /// on the bunny subdivided to 114 k faces the whole-map untangler left
    /// the same 3-5 of them, at 45-70 s a pass.
    fn untangle_locally(&self, xm: &mut [f64], system: &RoundedSystem, s: f64) -> Result<Option<UntangleStats>, QuantizeError> {
        if self.elements.len() as f64 <= FULL_BUDGET_FACES {
            return Ok(None);
        }
        let mut done: Option<UntangleStats> = None;
        for cells in PATCH_CELLS {
            let seeds = local::inverted_faces(&self.elements, xm);
            if seeds.is_empty() {
                break;
            }
            let rings = self.rings(cells, s);
            let in_patch = local::faces_around(&self.faces, &seeds, rings);
            if in_patch.iter().filter(|&&inside| inside).count() as f64 > MAX_PATCH_SHARE * self.faces.len() as f64 {
                return Ok(None);
            }
            let Some(patch) = local::Patch::new(&self.elements, &in_patch, &system.c, system.b.len(), self.n_unknowns)? else {
                return Ok(None);
            };
            let stats = patch.untangle(xm, &self.polish_untangle());
            done = Some(match done {
                None => stats,
                Some(first) => UntangleStats { outer: first.outer + stats.outer, iterations: first.iterations + stats.iterations, inverted_start: first.inverted_start, inverted: stats.inverted },
            });
        }
        Ok(done)
    }

    /// Vertex rings of faces that span `cells` grid cells of length `s` (in
    /// the edge of an equilateral triangle of the mean seamless area; at
    /// least one, at most [`MAX_PATCH_RINGS`]).
    fn rings(&self, cells: f64, s: f64) -> usize {
        let mean_area = self.seamless_areas.iter().sum::<f64>() / self.seamless_areas.len().max(1) as f64;
        let edge = (mean_area * 4.0 / 3f64.sqrt()).sqrt().max(f64::MIN_POSITIVE);
        (cells * s / edge).ceil().clamp(1.0, MAX_PATCH_RINGS as f64) as usize
    }

    /// Whether face `f` of `x` (grid size `s`) is flipped or collapsed: its
    /// UV area below [`COLLAPSED_SHARE`] of its area in the seamless map.
    fn collapsed(&self, f: usize, x: &[f64], s: f64) -> bool {
        !(signed_uv_area(self.elements[f].unknowns_uv(x)) * s * s
            > COLLAPSED_SHARE * self.seamless_areas[f])
    }

    /// Faces flipped or collapsed ([`Self::collapsed`]), and the faces around
    /// [`Self::wound_vertices`].
    fn flipped_faces(&self, x: &[f64], s: f64) -> Vec<usize> {
        let mut bad: Vec<usize> = (0..self.elements.len())
            .filter(|&f| self.collapsed(f, x, s))
            .collect();
        let wound = self.wound_vertices(x);
        if !wound.is_empty() {
            bad.extend(
                (0..self.faces.len())
                    .filter(|&f| self.faces[f].iter().any(|v| wound.binary_search(v).is_ok())),
            );
            bad.sort_unstable();
            bad.dedup();
        }
        bad
    }

    /// How far `x` is from a valid map: flipped or collapsed faces, plus
    /// [`WOUND_WEIGHT`] per wound vertex (a move must not trade a few
    /// collapsed slivers for a vertex the map winds around).
    fn badness(&self, x: &[f64], s: f64) -> usize {
        let collapsed = (0..self.elements.len())
            .filter(|&f| self.collapsed(f, x, s))
            .count();
        collapsed + WOUND_WEIGHT * self.wound_vertices(x).len()
    }

    /// Vertices whose UV angle sum is off the seamless map's by more than pi
    /// (ascending).
    fn wound_vertices(&self, x: &[f64]) -> Vec<u32> {
        let sums = corner_angle_sums(&self.faces, self.angle_sums.len(), |f| {
            self.elements[f].unknowns_uv(x)
        });
        (0..sums.len() as u32)
            .filter(|&v| (sums[v as usize] - self.angle_sums[v as usize]).abs() > PI)
            .collect()
    }

    /// Triangles of `x` flipped or degenerate ([`local::inverted_faces`]).
    fn flipped(&self, x: &[f64]) -> usize {
        local::inverted_faces(&self.elements, x).len()
    }

    /// Widens held rows so that the pairs whose rows the solve dropped are
    /// parted too. On a box thinner than a cell the seams add the gaps of two
    /// held pairs into a third (`x27 - x28 = (x10 - x11) - (x0 - x2)`): at
    /// gap 1 each, the third's row is dependent and its pair left on one
    /// line, though as the inequalities they are (gap >= 1) all three can
    /// hold (one gap of 2). For each such pair of the relaxed map
    /// `system.x`, its gap's change per unit change of every held row comes
    /// from one adjoint solve ([`RoundedSystem::sensitivity`]); the held
    /// rows that widen it, least stretched first, are tried a line wider
    /// (two where it gains a half per line), each one solve with the same
    /// factorization; a trial is kept when fewer held pairs stay violated.
    /// At most [`Self::budget`]`(WIDEN_TRIALS)` solves. Returns the rows widened.
    fn widen_held(&self, system: &mut RoundedSystem, held: &mut HeldApart, x0: &[f64], targets: &[[[f64; 2]; 2]]) -> Result<usize, QuantizeError> {
        let mut violated = held.violated(&system.x, NEAR_INTEGER);
        let (mut trials, max_trials, mut widened) = (0, self.budget(WIDEN_TRIALS), 0);
        for pair in violated.clone() {
            if !violated.contains(&pair) {
                continue;
            }
            if trials >= max_trials {
                break;
            }
            trials += 1;
            let gain = system.sensitivity(&[(pair.hi, 1), (pair.lo, -1)])?;
            let mut candidates: Vec<(f64, usize, usize, i64)> = system
                .held_rows
                .iter()
                .filter(|&&(k, _)| held.list[k] != pair)
                .filter_map(|&(k, row)| {
                    // Held gaps only grow.
                    let step = widening_step(gain[row]).filter(|&step| step > 0)?;
                    let sep = held.list[k];
                    Some(((held.gaps[k] + step) as f64 - (x0[sep.hi] - x0[sep.lo]), k, row, step))
                })
                .collect();
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for (_, k, row, step) in candidates.into_iter().take(CANDIDATES_PER_SEPARATION) {
                if trials >= max_trials {
                    break;
                }
                trials += 1;
                system.b[row] += step as f64;
                let x = system.resolve(self, targets)?;
                let after = held.violated(&x, NEAR_INTEGER);
                if after.len() < violated.len() {
                    (system.x, violated) = (x, after);
                    held.gaps[k] += step;
                    widened += 1;
                    break;
                }
                system.b[row] -= step as f64;
            }
        }
        Ok(widened)
    }

    /// Factors the KKT of the seam rows, the rounded forms `order` (their
    /// values in `values`), the gauge pins each component still needs
    /// (held at `x`'s values) and the separations `held` (`x_hi - x_lo =
    /// gap`, left out where the rows before determine them), and solves for the
    /// map closest to `targets`. Also returns the forms of `order` left out
    /// because the earlier rows determine them.
    fn solve(
        &self,
        fit: &Fit,
        order: &[usize],
        values: &[Option<i64>],
        x: &[f64],
        targets: &[[[f64; 2]; 2]],
        held: &HeldApart,
    ) -> Result<(RoundedSystem, Vec<usize>), QuantizeError> {
        let mut rows = self.seam_rows.clone();
        let mut rhs_rows = vec![0.0; rows.len()];
        let mut responses = Vec::with_capacity(order.len() + 2 * self.pins.len());
        for &i in order {
            let form = &self.forms[i];
            rows.push(form.row.clone());
            rhs_rows.push(values[i].unwrap_or(0) as f64);
            responses.push(form.response.clone());
        }
        // The component translations the rounded forms do not fix are held
        // by pins: a pin is kept when its translation is independent of the
        // forms' responses and of the pins before it.
        responses.extend((0..2 * self.pins.len()).map(|t| vec![(t, 1)]));
        let free_translation = independent_rows(&responses, 2 * self.pins.len());
        for (t, _) in free_translation[order.len()..].iter().enumerate().filter(|(_, &free)| free) {
            let unknown = self.pins[t / 2][t % 2];
            rows.push(vec![(unknown, 1)]);
            rhs_rows.push(x[unknown]);
        }
        let n_held_from = rows.len();
        for (sep, &gap) in held.list.iter().zip(&held.gaps) {
            rows.push(vec![(sep.hi, 1), (sep.lo, -1)]);
            rhs_rows.push(gap as f64);
        }
        let keep = independent_rows(&rows, self.n_unknowns);
        let n_seam = self.seam_rows.len();
        let dependent = order
            .iter()
            .zip(&keep[n_seam..])
            .filter(|(_, &k)| !k)
            .map(|(&i, _)| i)
            .collect();
        let mut c = Vec::new();
        let mut b = Vec::new();
        let (mut form_rows, mut held_rows) = (Vec::new(), Vec::new());
        for (r, ((row, k), v)) in rows.iter().zip(keep).zip(rhs_rows).enumerate() {
            if k {
                if (n_seam..n_seam + order.len()).contains(&r) {
                    form_rows.push((order[r - n_seam], b.len()));
                }
                if r >= n_held_from {
                    held_rows.push((r - n_held_from, b.len()));
                }
                c.extend(row.iter().map(|&(i, a)| (b.len(), i, a as f64)));
                b.push(v);
            }
        }
        let kkt = Kkt::assemble(&fit.stiffness, self.n_unknowns, &c, b.len())?;
        let solver = factored(&kkt)?;
        let mut system = RoundedSystem {
            weights: fit.weights.clone(),
            solver,
            uniform: OnceCell::new(),
            c,
            b,
            form_rows,
            held_rows,
            n: self.n_unknowns,
            x: Vec::new(),
        };
        system.x = system.resolve(self, targets)?;
        Ok((system, dependent))
    }
}

/// The least-squares fit of the rounded map to the seamless map's
/// Jacobians, `min sum_f w_f A_f |J_f - J_f^0 / s|^2`: per-face weights and
/// the stiffness they give.
struct Fit {
    weights: Vec<f64>,
    stiffness: Vec<Triplet>,
    /// Weight of the stiff faces (1: none stiffer).
    stiff_weight: f64,
    /// Weights graded towards the singular points ([`Quantizer::graded_fit`]).
    graded: bool,
}

impl Fit {
    /// Weight `stiff_weight` on the faces `stiff`, 1 elsewhere.
    fn new(elements: &[Element], stiff: &[bool], stiff_weight: f64) -> Fit {
        let weights: Vec<f64> = stiff.iter().map(|&b| if b { stiff_weight } else { 1.0 }).collect();
        let stiffness = stiffness_triplets(elements, &weights);
        Fit { weights, stiffness, stiff_weight, graded: false }
    }
}

/// What [`Quantizer::polish`] made of a rounded map: the map, its
/// [`Quantizer::badness`] and that of the map it was given, the ARAP
/// iterations kept, whether the untangler left no fold, and the local
/// stiffening iterations it started from.
#[derive(Default)]
struct Polished {
    x: Vec<f64>,
    bad: usize,
    rounded_bad: usize,
    arap_iterations: usize,
    untangled: bool,
    stiffening: usize,
}

/// The outcome of one [`Quantizer::round_and_polish`].
#[derive(Default)]
struct Rounded {
    x: Vec<f64>,
    values: Vec<Option<i64>>,
    batches: usize,
    separation_moves: usize,
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
    /// Separations of its grid size, those held as rows ([`HeldApart`])
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
/// holding the separations it leaves violated as rows ([`HeldApart`]);
/// with `widen` too, widening held rows so that the held pairs whose rows
/// are dependent are parted as well ([`Quantizer::widen_held`]).
#[derive(Clone, Copy, Default)]
struct Pass {
    hold: bool,
    widen: bool,
}

/// What quantization at one grid size keeps to beyond the forms.
struct SizeRules {
    separations: Separations,
    /// Per form: left free (the end of a curve shorter than [`CURVE_END_CELLS`] cells).
    free: Vec<bool>,
}

/// One integer moved by [`Quantizer::separate`]: the row of `c` changed by
/// `step`, the re-solved map, the forms' values and the separations still
/// violated.
struct SeparationMove {
    row: usize,
    step: i64,
    x: Vec<f64>,
    values: Vec<Option<i64>>,
    violated: Vec<Separation>,
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

/// A factored KKT of [`Quantizer::solve`] and its constraint values.
struct RoundedSystem {
    /// Per face: the weight of its Jacobian fit ([`Fit`]).
    weights: Vec<f64>,
    solver: LdltSolver,
    /// [`Self::untangle_solver`] of a stiffer fit, once factored.
    uniform: OnceCell<LdltSolver>,
    c: Vec<Triplet>,
    b: Vec<f64>,
    /// The rows of `c` that are rounded forms: (form, row).
    form_rows: Vec<(usize, usize)>,
    /// The rows of `c` that are held separations: (index in [`HeldApart`], row).
    held_rows: Vec<(usize, usize)>,
    n: usize,
    x: Vec<f64>,
}

impl RoundedSystem {
    /// The factored KKT the untangler is preconditioned with. Its energy
    /// weighs every face alike, and so must its preconditioner: with a
    /// stiffer fit's KKT its steps near singular points came out 10-100
    /// times too short (fandisk >60 at 1 500 quads: 17 s -> 12 s, the same
    /// map). This system's own where its fit is uniform; else the same rows
    /// with uniform weights, factored on first use and kept (it depends on
    /// the rows `c`, which [`Quantizer::uncollapse`] leaves, not on `b`).
    fn untangle_solver(&self, q: &Quantizer) -> Result<&LdltSolver, QuantizeError> {
        if self.weights.iter().all(|&w| w == 1.0) {
            return Ok(&self.solver);
        }
        if self.uniform.get().is_none() {
            let stiffness = stiffness_triplets(&q.elements, &vec![1.0; q.elements.len()]);
            let solver = factored(&Kkt::assemble(&stiffness, q.n_unknowns, &self.c, self.b.len())?)?;
            let _ = self.uniform.set(solver);
        }
        Ok(self.uniform.get().expect("set above"))
    }

    /// Per row of `c`: the change of the linear form `row` of the solution
    /// per unit change of that row's value (the multipliers of `K⁻¹ [row; 0]`,
    /// `K` symmetric).
    fn sensitivity(&self, row: &[(usize, i64)]) -> Result<Vec<f64>, QuantizeError> {
        Ok(self.sensitivities(&[row])?.pop().unwrap_or_default())
    }

    /// [`Self::sensitivity`] of each of `rows`, solved together (one pass
    /// over the factor for all of them).
    fn sensitivities<R: AsRef<[(usize, i64)]>>(&self, rows: &[R]) -> Result<Vec<Vec<f64>>, QuantizeError> {
        let dim = self.n + self.b.len();
        let mut rhs = vec![0.0; dim * rows.len()];
        for (column, row) in rhs.chunks_mut(dim).zip(rows) {
            for &(i, a) in row.as_ref() {
                column[i] += a as f64;
            }
        }
        let z = self.solver.solve_many_to(&rhs, rows.len(), SOLVE_TOLERANCE)?.0;
        Ok(z.chunks(dim).map(|column| column[self.n..].to_vec()).collect())
    }

    /// `x` moved back onto the rows `C x = b` by the smallest change in the
    /// stiffness norm (one solve for `(0, b - C x)`).
    fn onto_constraints(&self, mut x: Vec<f64>) -> Result<Vec<f64>, QuantizeError> {
        let mut rhs = vec![0.0; self.n];
        let cx = constraint_values(&self.c, self.b.len(), &x);
        rhs.extend(self.b.iter().zip(&cx).map(|(b, v)| b - v));
        let dx = self.solver.solve_many_to(&rhs, 1, SOLVE_TOLERANCE)?.0;
        x.iter_mut().zip(&dx).for_each(|(v, d)| *v += d);
        Ok(x)
    }

    /// The map closest to per-face target Jacobians `targets` under this system's rows.
    fn resolve(&self, q: &Quantizer, targets: &[[[f64; 2]; 2]]) -> Result<Vec<f64>, QuantizeError> {
        fit_solve(&self.solver, q, &self.weights, targets, &self.b)
    }
}

/// The map closest to per-face target Jacobians `targets` with face weights
/// `weights`, under the rows of `solver` (a factored KKT of that fit) with
/// values `b`.
fn fit_solve(solver: &LdltSolver, q: &Quantizer, weights: &[f64], targets: &[[[f64; 2]; 2]], b: &[f64]) -> Result<Vec<f64>, QuantizeError> {
    let mut rhs = vec![0.0; q.n_unknowns];
    for ((el, t), w) in q.elements.iter().zip(targets).zip(weights) {
        for k in 0..3 {
            let g = el.g[k];
            for c in 0..2 {
                rhs[el.x[c][k]] += w * el.area * (g[0] * t[c][0] + g[1] * t[c][1]);
            }
        }
    }
    rhs.extend_from_slice(b);
    let x = solver.solve_many_to(&rhs, 1, SOLVE_TOLERANCE)?.0;
    if x.iter().any(|v| !v.is_finite()) {
        return Err(QuantizeError::Param(ParamError::NotFinite {
            what: "quantized map",
        }));
    }
    Ok(x[..q.n_unknowns].to_vec())
}

/// `q <- Z (Zᵀ A Z)⁻¹ Zᵀ q` (the untangler's preconditioner): the solve
/// for `(q, 0)` with `solver`, a factored KKT of `n_rows` rows `C` (on the
/// `q.len()` unknowns) and some SPD `A`, put back onto `C q = 0` by
/// `projector`; 0 when it fails.
fn precondition(solver: &LdltSolver, n_rows: usize, q: &mut [f64], projector: Option<&NullSpaceProjector>) {
    let n = q.len();
    let mut rhs = q.to_vec();
    rhs.resize(n + n_rows, 0.0);
    match solver.solve_many_to(&rhs, 1, PRECONDITION_TOLERANCE) {
        Ok((x, _)) => q.copy_from_slice(&x[..n]),
        Err(_) => q.iter_mut().for_each(|v| *v = 0.0),
    }
    if let Some(projector) = projector {
        projector.project(q, 1e-14, 3);
    }
}

/// [`seamless::factored`] with solves that stop where they stagnate below
/// [`STALL_ACCEPT`].
fn factored(kkt: &Kkt) -> Result<LdltSolver, LinalgError> {
    let mut solver = seamless::factored(kkt)?;
    solver.set_options(FactorOptions { stall_accept: STALL_ACCEPT, ..solver.options() });
    Ok(solver)
}

/// The change of a row's value that widens a gap by a grid line, from the
/// gap's `gain` per unit change of that row: one, or two where the gain is a
/// half (a translation across a half-turn seam: `f_g(P) + f_f(P) = 2 p`), in
/// the gain's direction; `None` where the row barely moves the gap.
fn widening_step(gain: f64) -> Option<i64> {
    let magnitude = if gain.abs() > 0.75 { 1 } else { 2 };
    (gain.abs() > 0.25).then_some(if gain > 0.0 { magnitude } else { -magnitude })
}

/// Keeps the better of `best` and `candidate` (rounded at grid length
/// `s`) by (collapsed faces, wound vertices, fit distortion). Flipped or
/// collapsed faces leave holes in the quad mesh; a cell the map winds
/// around is closed with quads (an extra singular vertex): fewer of the
/// first, then of the second, count first.
fn keep_better(best: &mut Option<(Rounded, f64)>, candidate: Rounded, s: f64) {
    let key = |r: &Rounded| (r.collapsed, r.wound, r.distortion);
    if best.as_ref().is_none_or(|(b, _)| key(&candidate) < key(b)) {
        *best = Some((candidate, s));
    }
}

/// Keeps `candidate` (rounded at grid length `s`) over `best` only where it
/// has no more collapsed faces and no more wound vertices, and fewer of
/// both together: a pass that widens held rows stretches the map (more
/// cells, more distortion), so it has to mend the map, not trade one fault
/// for another.
fn keep_dominant(best: &mut Option<(Rounded, f64)>, candidate: Rounded, s: f64) {
    let dominates = best.as_ref().is_none_or(|(b, _)| {
        candidate.collapsed <= b.collapsed && candidate.wound <= b.wound && candidate.collapsed + candidate.wound < b.collapsed + b.wound
    });
    if dominates {
        *best = Some((candidate, s));
    }
}

/// `A_f |J_f - T_f|^2`: the fit's error of element `el` in `x` against the target Jacobian `t`.
fn fit_error(el: &Element, x: &[f64], t: &[[f64; 2]; 2]) -> f64 {
    let j = el.jacobian(x);
    el.area * (0..2).flat_map(|r| (0..2).map(move |c| (r, c))).map(|(r, c)| (j[r][c] - t[r][c]).powi(2)).sum::<f64>()
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

/// `|y - round(y)|`.
fn distance_to_integer(y: f64) -> f64 {
    (y - y.round()).abs()
}
