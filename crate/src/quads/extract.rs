//! Quad extraction from an integer-grid map, after QEx (Ebke, Bommes,
//! Chaine, Kobbelt 2013, "QEx: Robust Quad Mesh Extraction"):
//!
//! 1. `snap::snap`: the corner UVs become an exact fixed-point integer-grid
//!    map (exact transitions, exactly consistent corners);
//! 2. `vertices::QuadVertices`: the integer points (inside faces, inside
//!    edges, at mesh vertices) with their outgoing isoline directions;
//! 3. `trace::trace_edge`: each direction's unit isoline segment followed
//!    exactly to the next integer point;
//! 4. `faces::build_quads`: the cycles of traced half-edges are the quads;
//! 5. `close_polygons`: a cycle of more sides (the map winds twice around a
//!    point in the cell) is closed with quads around an input vertex there;
//! 6. `fill::fill_holes`: the holes left where cells were skipped (flipped
//!    triangles) are filled with quads on the input surface;
//! 7. `corners::align_curve_corners`: quad vertices slid along feature and
//!    boundary polylines onto the corners quad edges would cut;
//! 8. `untangle::untangle`: quad vertices off the curves moved along the
//!    surface where their quads fold in 3D (a cell over a tip tighter than
//!    itself), unless that takes the quads further from the input.
//!
//! Every predicate after step 1 is exact integer arithmetic. Where the map is
//! not a valid integer-grid map the extractor closes or skips what it cannot
//! trace as a quad and records a [`QuadDefect`].

mod corners;
mod faces;
mod fill;
mod snap;
mod trace;
mod untangle;
pub(crate) use untangle::untangle;
mod vertices;

#[cfg(test)]
#[path = "extract_tests.rs"]
mod extract_tests;

use super::{QuadDefect, QuadMesh, SurfacePoint};
use crate::features::FeatureSet;
use crate::mesh::NONE;
use crate::TriMesh;
use snap::{dot, orient, sub};
use vertices::{Place, QuadVertices};

/// Largest accepted UV coordinate magnitude (grid units); keeps the exact
/// fixed-point predicates within `i128`.
pub const MAX_UV: f64 = (1u64 << 28) as f64;

/// Knobs of [`extract_quads`].
#[derive(Clone, Copy, Debug)]
pub struct ExtractOptions {
    /// UV coordinates within this distance of an integer are snapped to it;
    /// a transition whose translation is further than this from an integer
    /// vector is reported as a defect.
    pub snap_tolerance: f64,
    /// A trace crossing more triangles than this is abandoned (a defect).
    pub max_trace_steps: usize,
    /// At most this many quad vertices are enumerated (a defect beyond).
    pub max_vertices: usize,
    /// Step 8: move the vertices of quads that fold in 3D along the surface.
    pub untangle: bool,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions { snap_tolerance: 1e-6, max_trace_steps: 1_000, max_vertices: 10_000_000, untangle: true }
    }
}

/// Input that [`extract_quads`] cannot work with at all.
#[derive(Clone, Debug, PartialEq)]
pub enum ExtractError {
    /// `uv` does not have one entry per face corner.
    CornerCount { expected: usize, found: usize },
    /// A UV is NaN or infinite.
    NotFinite { corner: usize },
    /// A UV coordinate exceeds [`MAX_UV`] in magnitude.
    OutOfRange { corner: usize },
}

impl std::fmt::Display for ExtractError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExtractError::CornerCount { expected, found } => {
                write!(f, "expected {expected} corner UVs (3 per face), found {found}")
            }
            ExtractError::NotFinite { corner } => write!(f, "UV of corner {corner} is not finite"),
            ExtractError::OutOfRange { corner } => write!(f, "UV of corner {corner} exceeds {MAX_UV} grid units"),
        }
    }
}

impl std::error::Error for ExtractError {}

/// Extracts the quad mesh of the integer-grid map `uv` (one UV per face
/// corner `3 f + k`, grid units) on `mesh`.
///
/// Vertices are the integer points of the map, each exactly on the input
/// surface (barycentric in its face); quads are the unit grid cells,
/// counter-clockwise like the input, with their corner UVs in the chart of
/// one face. On a valid map the result is a pure, manifold quad mesh with
/// the input's Euler characteristic and boundary loops, valence 4 except
/// `4 − k` at a cone of index `k`, and every input edge on an integer isoline
/// covered by quad edges. Where the map winds twice around a point, the
/// cell there closes only after going around twice: it is split at repeated
/// vertices, out-and-back isolines are dropped and the rest closed with
/// quads around an input vertex ([`close_polygons`]), so the mesh has no
/// hole there. Where the map is otherwise invalid (flips, non-integer
/// transitions or cones) the affected cells are skipped and the hole they
/// leave is filled with quads whose new vertices lie on the input surface
/// (even holes away from the input's boundary; others stay open). All of
/// these are listed in [`QuadMesh::defects`]. Errs only on a wrong number of UVs or a UV that is
/// not finite or beyond [`MAX_UV`]; never panics.
pub fn extract_quads(mesh: &TriMesh, uv: &[[f64; 2]], options: &ExtractOptions) -> Result<QuadMesh, ExtractError> {
    extract_quads_along(mesh, &FeatureSet::none(mesh), uv, options)
}

/// [`extract_quads`] on a map whose isolines follow the feature edges
/// `features` of `mesh`: their polylines' corners (and the boundary's) get
/// quad vertices where quad edges would cut them (step 7).
pub fn extract_quads_along(mesh: &TriMesh, features: &FeatureSet, uv: &[[f64; 2]], options: &ExtractOptions) -> Result<QuadMesh, ExtractError> {
    let expected = 3 * mesh.n_faces();
    if uv.len() != expected {
        return Err(ExtractError::CornerCount { expected, found: uv.len() });
    }
    for (corner, p) in uv.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ExtractError::NotFinite { corner });
        }
        if p[0].abs() > MAX_UV || p[1].abs() > MAX_UV {
            return Err(ExtractError::OutOfRange { corner });
        }
    }
    let mut defects: Vec<QuadDefect> = Vec::new();
    let map = snap::snap(mesh, uv, options.snap_tolerance, &mut defects);
    let qv = QuadVertices::enumerate(mesh, &map, options.max_vertices, &mut defects);
    let target: Vec<u32> = (0..qv.slots.len() as u32)
        .map(|s| match trace::trace_edge(mesh, &map, &qv, s, options.max_trace_steps) {
            Ok(t) => t,
            Err(failure) => {
                defects.push(QuadDefect { face: failure.face, what: failure.what.into() });
                NONE
            }
        })
        .collect();
    let cells = faces::build_quads(mesh, &map, &qv, &target, &mut defects);

    let mut positions = Vec::with_capacity(qv.list.len());
    let mut locations = Vec::with_capacity(qv.list.len());
    for q in &qv.list {
        let loc = surface_point(mesh, &map, q.place, q.uv);
        let corners = mesh.faces()[loc.face as usize];
        let mut x = [0.0; 3];
        for (k, &c) in corners.iter().enumerate() {
            let p = mesh.position(c);
            for i in 0..3 {
                x[i] += loc.bary[k] * p[i];
            }
        }
        positions.push(x);
        locations.push(loc);
    }
    let mut quads = QuadMesh { positions, locations, quads: cells.quads, uv: cells.uv, defects };
    close_polygons(mesh, &cells.polygons, &mut quads);
    fill::fill_holes(mesh, &mut quads);
    drop_pillows(&mut quads);
    drop_unreferenced(&mut quads);
    corners::align_curve_corners(mesh, features, &mut quads);
    if options.untangle {
        untangle::untangle(mesh, features, &mut quads);
    }
    Ok(quads)
}

/// Removes every pair of quads over the same four vertices in opposite
/// orders (a pillow: two faces closed on each other) and says where. Each
/// of their edges loses two faces, so an edge a pillow made non-manifold
/// gets its two others back, and no edge becomes a boundary that was not
/// one. The hole filling ([`fill::fill_holes`]) made them where a quad
/// hung into a hole by three sides, until it stopped joining corners the
/// quads already join (a jittered fandisk stretched 3 x 1 x 0.5 with
/// creases above 60° at 3 000 quads had two pillows, Euler characteristic
/// 4 for 2, two non-manifold edges); no step is known to make them now,
/// and this check stays as the last guard of a manifold result.
fn drop_pillows(quads: &mut QuadMesh) {
    let cycle = |q: &[u32; 4]| {
        let first = (0..4).min_by_key(|&k| q[k]).expect("four corners");
        [0, 1, 2, 3].map(|k| q[(first + k) % 4])
    };
    let mut by_cycle: std::collections::HashMap<[u32; 4], Vec<usize>> = std::collections::HashMap::new();
    for (i, q) in quads.quads.iter().enumerate() {
        by_cycle.entry(cycle(q)).or_default().push(i);
    }
    let mut dropped = vec![false; quads.quads.len()];
    for (i, q) in quads.quads.iter().enumerate() {
        if dropped[i] {
            continue;
        }
        let reversed = cycle(&[q[3], q[2], q[1], q[0]]);
        let partner = by_cycle.get(&reversed).and_then(|others| others.iter().copied().find(|&j| j != i && !dropped[j]));
        if let Some(j) = partner {
            dropped[i] = true;
            dropped[j] = true;
            let face = quads.locations[q[0] as usize].face;
            quads.defects.push(QuadDefect { face, what: "two quads over the same four vertices closed on each other; both removed".into() });
        }
    }
    quads.remove_quads(&dropped);
}

/// Removes the vertices no quad uses (the tip of an isoline traced out and
/// back inside a cell the map winds around, a hole filling's candidate
/// vertices not chosen), renumbering the rest in order.
fn drop_unreferenced(quads: &mut QuadMesh) {
    let mut new_index = vec![u32::MAX; quads.positions.len()];
    for q in &quads.quads {
        for &v in q {
            new_index[v as usize] = 0;
        }
    }
    if !new_index.contains(&u32::MAX) {
        return;
    }
    let mut kept = 0;
    for (v, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = kept;
            quads.positions[kept as usize] = quads.positions[v];
            quads.locations[kept as usize] = quads.locations[v];
            kept += 1;
        }
    }
    quads.positions.truncate(kept as usize);
    quads.locations.truncate(kept as usize);
    for q in &mut quads.quads {
        *q = q.map(|v| new_index[v as usize]);
    }
}

/// Closes every polygon of `2 m` corners with `m` quads around a new
/// vertex: the input vertex nearest to the corners' centroid among those
/// within two rings of the corners' faces (the point the map winds around
/// lies there). Corner `2 i` of each quad is a polygon corner, so the
/// corners alternate valence 5 and 4 and the new vertex has valence `m`.
fn close_polygons(mesh: &TriMesh, polygons: &[faces::Polygon], quads: &mut QuadMesh) {
    if polygons.is_empty() {
        return;
    }
    for polygon in polygons {
        let n = polygon.corners.len();
        let centroid = polygon
            .corners
            .iter()
            .fold([0.0; 3], |c, &q| crate::vec3::add(c, quads.positions[q as usize]))
            .map(|x| x / n as f64);
        let mut near: Vec<u32> = polygon
            .corners
            .iter()
            .flat_map(|&q| mesh.faces()[quads.locations[q as usize].face as usize])
            .collect();
        for _ in 0..2 {
            let grown: Vec<u32> =
                near.iter().flat_map(|&v| mesh.vertex_faces(v).flat_map(|f| mesh.faces()[f as usize])).collect();
            near.extend(grown);
            near.sort_unstable();
            near.dedup();
        }
        let distance = |v: u32| {
            let p = mesh.position(v);
            (0..3).map(|i| (p[i] - centroid[i]).powi(2)).sum::<f64>()
        };
        let Some(centre) = near.iter().copied().min_by(|&a, &b| distance(a).total_cmp(&distance(b))) else {
            continue;
        };
        let h0 = mesh.vertex_halfedge(centre);
        let mut bary = [0.0; 3];
        bary[(h0 % 3) as usize] = 1.0;
        let m = quads.positions.len() as u32;
        quads.positions.push(mesh.position(centre));
        quads.locations.push(SurfacePoint { face: h0 / 3, bary });
        let uv_mean = polygon.uv.iter().fold([0.0; 2], |c, p| [c[0] + p[0], c[1] + p[1]]).map(|x| x / n as f64);
        for i in (0..n).step_by(2) {
            let k = [i, i + 1, (i + 2) % n];
            quads.quads.push([polygon.corners[k[0]], polygon.corners[k[1]], polygon.corners[k[2]], m]);
            quads.uv.extend(k.iter().map(|&j| polygon.uv[j]));
            quads.uv.push(uv_mean);
        }
    }
}

/// The integer-grid map `uv` (one UV per face corner, grid units) made exact
/// in binary floating point: every coordinate a multiple of `2^-bits`
/// (`bits ≤ 32`), integers within `tol` snapped to them, and the corners
/// set so that across every interior edge the two sides differ exactly by
/// a quarter-turn rotation and an integer translation. Any float type whose
/// mantissa holds `|coordinate|·2^bits` keeps those relations exactly (an
/// f32 when it is below 2^24). `None` when `uv` is not an integer-grid map
/// within `tol` (the snap would move corners) or not finite and within
/// [`MAX_UV`].
pub fn exact_grid_uv(mesh: &TriMesh, uv: &[[f64; 2]], tol: f64, bits: u32) -> Option<Vec<[f64; 2]>> {
    let valid = uv.len() == 3 * mesh.n_faces()
        && uv.iter().all(|p| p.iter().all(|x| x.is_finite() && x.abs() <= MAX_UV))
        && bits <= 32;
    if !valid {
        return None;
    }
    let one = 1i64 << bits;
    let mut defects = Vec::new();
    let map = snap::snap_at(mesh, uv, tol, one, &mut defects);
    defects.is_empty().then(|| map.uv.iter().map(|p| p.map(|x| x as f64 / one as f64)).collect())
}

/// The input face and barycentric coordinates of the integer point `uv`
/// (home chart of `place`, see [`vertices::QuadVertex`]).
fn surface_point(mesh: &TriMesh, map: &snap::SnappedMap, place: Place, uv: snap::Point) -> SurfacePoint {
    match place {
        Place::Face(f) => {
            let x = map.corners(f);
            let area = orient(x[0], x[1], x[2]) as f64;
            let bary = [0, 1, 2].map(|k| orient(x[(k + 1) % 3], x[(k + 2) % 3], uv) as f64 / area);
            SurfacePoint { face: f, bary }
        }
        Place::Edge(e) => {
            let h0 = mesh.edge_halfedges(e)[0];
            let (a, b) = (map.uv[h0 as usize], map.uv[mesh.next(h0) as usize]);
            let w = sub(b, a);
            let t = dot(sub(uv, a), w) as f64 / dot(w, w) as f64;
            let mut bary = [0.0; 3];
            bary[(h0 % 3) as usize] = 1.0 - t;
            bary[((h0 + 1) % 3) as usize] = t;
            SurfacePoint { face: h0 / 3, bary }
        }
        Place::Vertex(v) => {
            let h0 = mesh.vertex_halfedge(v);
            let mut bary = [0.0; 3];
            bary[(h0 % 3) as usize] = 1.0;
            SurfacePoint { face: h0 / 3, bary }
        }
    }
}
