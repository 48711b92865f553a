//! Figures of a quad mesh against the triangle mesh it was traced on:
//! topology (Euler characteristic, boundary loops, components,
//! manifoldness), valences, 3D corner angles, flipped quads, the two
//! one-sided distances between the surfaces and how closely the quad edges
//! follow given sharp input edges.
//!
//! The check never fails on a broken quad mesh: a quad with a vertex index
//! out of range counts as degenerate and is otherwise ignored, and a corner
//! whose [`SurfacePoint`](super::SurfacePoint) names no input face only
//! drops out of the flip test.
//!
//! Distances are exact point-to-triangle (or point-to-segment) distances,
//! found with a uniform grid over the primitives' bounding boxes
//! ([`crate::mesh::box_grid`]), so the cost is about linear in the number of samples and
//! primitives.

use super::{OnFace, QuadMesh, SurfacePoint};
use crate::mesh::box_grid::{BoxGrid, Visited};
use crate::mesh::UnionFind;
use crate::vec3::{add, angle, bounds, cross, dot, midpoint, norm, point_segment_distance, point_triangle_distance, scale, sub, V3};
use crate::TriMesh;
use serde::Serialize;
use std::collections::BTreeMap;

/// What [`check_quads`] measures beyond the figures it always computes.
#[derive(Clone, Copy, Debug)]
pub struct CheckOptions<'a> {
    /// Input edges (edge ids of the input [`TriMesh`]) the quad edges should
    /// follow; ids out of range are skipped.
    pub sharp_edges: &'a [u32],
    /// Distance, as a fraction of the input bounding-box diagonal, within
    /// which a sample of a sharp edge counts as followed (default 0.002).
    pub sharp_tolerance: f64,
    /// Compute the two one-sided distances between the surfaces (default true).
    pub distances: bool,
}

impl Default for CheckOptions<'_> {
    fn default() -> Self {
        CheckOptions { sharp_edges: &[], sharp_tolerance: 2e-3, distances: true }
    }
}

/// Figures of a quad mesh, as written into a JSON report.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub struct QuadReport {
    /// Number of quads (all of them, degenerate ones included).
    pub quads: usize,
    /// Number of vertices (all positions, unreferenced ones included).
    pub vertices: usize,
    /// Number of undirected edges ([`quad_edges`]).
    pub edges: usize,
    /// V − E + F over referenced vertices, edges and quads with valid indices.
    pub euler_characteristic: i64,
    /// Connected components of the boundary edges (edges of one quad).
    pub boundary_loops: usize,
    /// Edge-connected components of the quads.
    pub components: usize,
    /// Edges used by more than two quads, or by two running the same way.
    pub non_manifold_edges: usize,
    /// Referenced vertices whose quads do not form a single disk or half-disk.
    pub non_manifold_vertices: usize,
    /// Quads with an index out of range, a repeated vertex, (near) zero area,
    /// or folded along both diagonals (a bow-tie).
    pub degenerate_quads: usize,
    /// Vertices no quad with valid indices uses.
    pub unreferenced_vertices: usize,
    /// Interior vertices of valence ≠ 4 and boundary vertices of valence ≠ 3,
    /// by vertex id.
    pub singular_vertices: Vec<SingularVertex>,
    /// Valence counts of the referenced vertices.
    pub valence_histogram: ValenceHistogram,
    /// Mean |angle − 90°| over the quad corners whose two edges have length.
    pub angle_mean_deviation: f64,
    /// Max |angle − 90°| over the same corners (0 when there are none).
    pub angle_max_deviation: f64,
    /// Fraction of quads with every corner angle in [45°, 135°] (0 for no quads).
    pub fraction_corners_45_135: f64,
    /// Quads whose Newell normal points against the mean input face normal
    /// at their corners' locations.
    pub flipped_quads: usize,
    /// Max distance from the quads (vertices, edge midpoints, quad centres)
    /// to the input surface; `None` when not computed or there are no quads.
    pub distance_quads_to_input: Option<f64>,
    /// [`Self::distance_quads_to_input`] over the input bounding-box diagonal.
    pub distance_quads_to_input_relative: Option<f64>,
    /// Max distance from the input (vertices, edge midpoints) to the quad
    /// surface, each quad split into two triangles; `None` when not
    /// computed or there are no quads.
    pub distance_input_to_quads: Option<f64>,
    /// [`Self::distance_input_to_quads`] over the input bounding-box diagonal.
    pub distance_input_to_quads_relative: Option<f64>,
    /// Sharp input edges sampled ([`CheckOptions::sharp_edges`] in range).
    pub sharp_edges_checked: usize,
    /// Fraction of the sharp-edge samples (5 per edge) within
    /// [`CheckOptions::sharp_tolerance`] of a quad edge; `None` for no samples.
    pub fraction_sharp_within_tolerance: Option<f64>,
    /// Number of repairs the extractor reported (`quads.defects.len()`).
    pub defects: usize,
}

/// A vertex whose valence differs from the regular one (4 inside, 3 on a
/// straight boundary).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct SingularVertex {
    pub vertex: u32,
    pub valence: u32,
    pub boundary: bool,
}

/// Number of vertices per valence, interior and boundary separately.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ValenceHistogram {
    #[serde(serialize_with = "string_keys")]
    pub interior: BTreeMap<u32, usize>,
    #[serde(serialize_with = "string_keys")]
    pub boundary: BTreeMap<u32, usize>,
}

/// A valence map with its keys as strings (JSON and JS objects need them).
fn string_keys<S: serde::Serializer>(map: &BTreeMap<u32, usize>, s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(map.iter().map(|(k, v)| (k.to_string(), v)))
}

/// One undirected edge of a quad mesh and how its quads use it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QuadEdge {
    /// Endpoints, the smaller id first.
    pub vertices: [u32; 2],
    /// Number of quad sides on the edge.
    pub uses: u32,
    /// How many of them run from `vertices[0]` to `vertices[1]`.
    pub forward: u32,
}

impl QuadEdge {
    /// True for an edge of exactly one quad.
    pub fn is_boundary(&self) -> bool {
        self.uses == 1
    }
    /// True for a boundary edge or an edge of two quads running opposite ways.
    pub fn is_manifold(&self) -> bool {
        self.uses == 1 || (self.uses == 2 && self.forward == 1)
    }
}

/// Corner angles (degrees) in this closed range count as good.
const GOOD_ANGLES: (f64, f64) = (45.0, 135.0);
/// Samples per sharp edge, at parameters `(k + ½) / 5`.
const SHARP_SAMPLES: usize = 5;

/// Measures `quads` against the `input` it was traced on.
///
/// Contract: never panics, whatever `quads` holds. A vertex without a
/// location, or whose location names no face of `input`, only drops out of
/// the flip test; distances are computed only with
/// [`CheckOptions::distances`], the sharp-edge figures only for the
/// [`CheckOptions::sharp_edges`] in range. Deterministic.
pub fn check_quads(input: &TriMesh, quads: &QuadMesh, options: &CheckOptions) -> QuadReport {
    let nv = quads.n_vertices();
    let valid: Vec<bool> = quads.quads.iter().map(|q| q.iter().all(|&v| (v as usize) < nv)).collect();
    let edges = quad_edges(quads);
    let fans = vertex_fans(quads, &valid, &edges);
    let angles = corner_angles(quads, &valid);
    let diagonal = input.bounding_diagonal();
    let relative = |d: Option<f64>| d.filter(|_| diagonal > 0.0).map(|d| d / diagonal);

    let mut report = QuadReport {
        quads: quads.n_quads(),
        vertices: nv,
        edges: edges.len(),
        boundary_loops: boundary_loops(nv, &edges),
        components: components(quads, &valid),
        non_manifold_edges: edges.iter().filter(|e| !e.is_manifold()).count(),
        non_manifold_vertices: fans.non_manifold,
        degenerate_quads: (0..quads.n_quads()).filter(|&q| !valid[q] || is_degenerate(quads, q)).count(),
        unreferenced_vertices: fans.valence.iter().filter(|v| v.is_none()).count(),
        angle_mean_deviation: angles.mean_deviation,
        angle_max_deviation: angles.max_deviation,
        fraction_corners_45_135: angles.fraction_good_quads,
        flipped_quads: flipped_quads(input, quads, &valid),
        defects: quads.defects.len(),
        ..QuadReport::default()
    };
    let referenced = nv - report.unreferenced_vertices;
    let faces = valid.iter().filter(|&&ok| ok).count();
    report.euler_characteristic = referenced as i64 - edges.len() as i64 + faces as i64;
    for (v, slot) in fans.valence.iter().enumerate() {
        let Some((valence, boundary)) = *slot else { continue };
        let histogram =
            if boundary { &mut report.valence_histogram.boundary } else { &mut report.valence_histogram.interior };
        *histogram.entry(valence).or_default() += 1;
        if valence != if boundary { 3 } else { 4 } {
            report.singular_vertices.push(SingularVertex { vertex: v as u32, valence, boundary });
        }
    }
    if options.distances {
        let (to_input, to_quads) = distances(input, quads, &valid, &edges);
        report.distance_quads_to_input = to_input;
        report.distance_quads_to_input_relative = relative(to_input);
        report.distance_input_to_quads = to_quads;
        report.distance_input_to_quads_relative = relative(to_quads);
    }
    let (checked, fraction) = sharp_alignment(input, quads, &edges, options, diagonal);
    report.sharp_edges_checked = checked;
    report.fraction_sharp_within_tolerance = fraction;
    report
}

/// The undirected edges of `quads`, sorted by endpoints: one per distinct
/// pair joined by a side `(q[i], q[i+1 mod 4])` of a quad whose indices are
/// all in range; sides from a vertex to itself are no edges.
pub fn quad_edges(quads: &QuadMesh) -> Vec<QuadEdge> {
    let mut edges: Vec<QuadEdge> = Vec::new();
    for side in sorted_sides(quads) {
        match edges.last_mut() {
            Some(e) if e.vertices == side.vertices => {
                e.uses += 1;
                e.forward += u32::from(side.forward);
            }
            _ => edges.push(QuadEdge { vertices: side.vertices, uses: 1, forward: u32::from(side.forward) }),
        }
    }
    edges
}

/// One side of one quad.
#[derive(Clone, Copy)]
struct Side {
    /// Endpoints, the smaller first.
    vertices: [u32; 2],
    quad: u32,
    /// True when the quad runs from `vertices[0]` to `vertices[1]`.
    forward: bool,
}

/// The sides of the quads with indices in range (no side from a vertex to
/// itself), sorted by endpoints, then quad.
fn sorted_sides(quads: &QuadMesh) -> Vec<Side> {
    let nv = quads.n_vertices();
    let mut sides = Vec::with_capacity(4 * quads.n_quads());
    for (q, quad) in quads.quads.iter().enumerate() {
        if quad.iter().any(|&v| v as usize >= nv) {
            continue;
        }
        for i in 0..4 {
            let (a, b) = (quad[i], quad[(i + 1) % 4]);
            if a != b {
                sides.push(Side { vertices: [a.min(b), a.max(b)], quad: q as u32, forward: a < b });
            }
        }
    }
    sides.sort_unstable_by_key(|s| (s.vertices, s.quad));
    sides
}

/// Connected components of the boundary edges.
fn boundary_loops(nv: usize, edges: &[QuadEdge]) -> usize {
    let mut sets = UnionFind::new(nv);
    for e in edges.iter().filter(|e| e.is_boundary()) {
        sets.union(e.vertices[0], e.vertices[1]);
    }
    sets.count_sets(edges.iter().filter(|e| e.is_boundary()).map(|e| e.vertices[0]))
}

/// Edge-connected components of the quads with indices in range.
fn components(quads: &QuadMesh, valid: &[bool]) -> usize {
    let mut sets = UnionFind::new(quads.n_quads());
    let sides = sorted_sides(quads);
    for pair in sides.windows(2) {
        if pair[0].vertices == pair[1].vertices {
            sets.union(pair[0].quad, pair[1].quad);
        }
    }
    sets.count_sets((0..quads.n_quads() as u32).filter(|&q| valid[q as usize]))
}

/// Per-vertex figures from the fans of quads around each vertex.
struct Fans {
    /// `(valence, on the boundary)` per vertex; `None` when unreferenced.
    valence: Vec<Option<(u32, bool)>>,
    /// Referenced vertices whose fan is not one disk or half-disk.
    non_manifold: usize,
}

/// Valence (number of edges), boundary flag and fan shape of each vertex.
/// The fan of `v` is the graph whose nodes are its neighbours and whose
/// links are its quad corners (previous → next neighbour): a single cycle
/// (interior) or a single path (boundary) makes `v` manifold.
fn vertex_fans(quads: &QuadMesh, valid: &[bool], edges: &[QuadEdge]) -> Fans {
    let nv = quads.n_vertices();
    let mut valence: Vec<Option<(u32, bool)>> = vec![None; nv];
    for (q, quad) in quads.quads.iter().enumerate() {
        if valid[q] {
            for &v in quad {
                valence[v as usize] = Some((0, false));
            }
        }
    }
    for e in edges {
        for &v in &e.vertices {
            if let Some((n, boundary)) = &mut valence[v as usize] {
                *n += 1;
                *boundary |= e.is_boundary();
            }
        }
    }

    // Corner wedges (previous, next) per vertex, of quads without repeats.
    let mut wedges: Vec<(u32, u32, u32)> = Vec::new();
    for (q, quad) in quads.quads.iter().enumerate() {
        if valid[q] && !has_repeated_vertex(quad) {
            for i in 0..4 {
                wedges.push((quad[i], quad[(i + 3) % 4], quad[(i + 1) % 4]));
            }
        }
    }
    wedges.sort_unstable();
    let non_manifold = wedges
        .chunk_by(|a, b| a.0 == b.0)
        .filter(|fan| !is_disk_fan(&fan.iter().map(|&(_, a, b)| [a, b]).collect::<Vec<_>>()))
        .count();
    Fans { valence, non_manifold }
}

/// True when the links `wedges` (pairs of neighbours) form one path or one
/// cycle: connected, no node of degree above 2.
fn is_disk_fan(wedges: &[[u32; 2]]) -> bool {
    let mut nodes: Vec<u32> = wedges.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    let local = |x: u32| nodes.partition_point(|&y| y < x) as u32;
    let mut degree = vec![0u32; nodes.len()];
    let mut sets = UnionFind::new(nodes.len());
    for &[a, b] in wedges {
        let (a, b) = (local(a), local(b));
        degree[a as usize] += 1;
        degree[b as usize] += 1;
        sets.union(a, b);
    }
    degree.iter().all(|&d| d <= 2) && sets.count_sets(0..nodes.len() as u32) == 1
}

fn has_repeated_vertex(q: &[u32; 4]) -> bool {
    (0..4).any(|i| (i + 1..4).any(|j| q[i] == q[j]))
}

/// Corners of quad `q` (indices in range).
fn quad_points(quads: &QuadMesh, q: usize) -> [V3; 4] {
    quads.quads[q].map(|v| quads.positions[v as usize])
}

/// Newell normal of a polygon: its length is twice the (projected) area.
pub(crate) fn newell_normal(p: &[V3; 4]) -> V3 {
    (0..4).fold([0.0; 3], |n, i| add(n, cross(p[i], p[(i + 1) % 4])))
}

/// True for a quad (indices in range) with a repeated vertex, an area below
/// `1e-12` of its squared perimeter scale, or folded along both diagonals
/// (the two triangles of either split face opposite ways: a bow-tie).
pub(crate) fn is_degenerate(quads: &QuadMesh, q: usize) -> bool {
    if has_repeated_vertex(&quads.quads[q]) {
        return true;
    }
    let p = quad_points(quads, q);
    let scale2: f64 = (0..4).map(|i| dot(sub(p[(i + 1) % 4], p[i]), sub(p[(i + 1) % 4], p[i]))).sum();
    if !(norm(newell_normal(&p)) > 1e-12 * scale2) {
        return true;
    }
    let normal = |a: V3, b: V3, c: V3| cross(sub(b, a), sub(c, a));
    let folded = |i: usize| {
        let [a, b, c, d] = [p[i], p[(i + 1) % 4], p[(i + 2) % 4], p[(i + 3) % 4]];
        dot(normal(a, b, c), normal(a, c, d)) < 0.0
    };
    folded(0) && folded(1)
}

/// Corner-angle figures.
struct AngleStats {
    mean_deviation: f64,
    max_deviation: f64,
    fraction_good_quads: f64,
}

/// Angles (degrees) between the two edges at every corner of the quads with
/// indices in range; a corner with a zero-length edge has no angle and
/// keeps its quad out of the good fraction.
fn corner_angles(quads: &QuadMesh, valid: &[bool]) -> AngleStats {
    let (mut sum, mut max, mut corners, mut good) = (0.0f64, 0.0f64, 0usize, 0usize);
    for q in (0..quads.n_quads()).filter(|&q| valid[q]) {
        let p = quad_points(quads, q);
        let mut all_good = true;
        for i in 0..4 {
            let (u, w) = (sub(p[(i + 3) % 4], p[i]), sub(p[(i + 1) % 4], p[i]));
            if !(norm(u) > 0.0 && norm(w) > 0.0) {
                all_good = false;
                continue;
            }
            let angle = angle(u, w).to_degrees();
            let deviation = (angle - 90.0).abs();
            sum += deviation;
            max = max.max(deviation);
            corners += 1;
            all_good &= (GOOD_ANGLES.0..=GOOD_ANGLES.1).contains(&angle);
        }
        good += usize::from(all_good);
    }
    let n = quads.n_quads();
    AngleStats {
        mean_deviation: if corners > 0 { sum / corners as f64 } else { 0.0 },
        max_deviation: max,
        fraction_good_quads: if n > 0 { good as f64 / n as f64 } else { 0.0 },
    }
}

/// Quads (indices in range) whose Newell normal has a negative dot product
/// with the sum of the input's normals at their corners: at a corner inside
/// an input face, that face's normal; on an input edge or vertex (a crease,
/// say), the normal of the face around it nearest the quad's centre, the
/// face the quad lies on there (a quad across a strip narrower than a cell
/// has its corners on the strip's creases, where the location's own face
/// may be a neighbour's: 86 of a game asset's 3 784 quads were counted
/// flipped that way).
fn flipped_quads(input: &TriMesh, quads: &QuadMesh, valid: &[bool]) -> usize {
    let normals = input.face_normals();
    (0..quads.n_quads()).filter(|&q| valid[q] && is_flipped(input, normals, quads, q)).count()
}

/// True when quad `q` (indices in range) faces against the input as
/// [`flipped_quads`] counts it (`normals`: the input's face normals).
pub(crate) fn is_flipped(input: &TriMesh, normals: &[V3], quads: &QuadMesh, q: usize) -> bool {
    let triangle = |f: u32| input.faces()[f as usize].map(|v| input.position(v));
    let points = quad_points(quads, q);
    let centre = scale(add(add(points[0], points[1]), add(points[2], points[3])), 0.25);
    let reference = quads.quads[q]
        .iter()
        .filter_map(|&v| quads.locations.get(v as usize))
        .filter(|l| (l.face as usize) < normals.len())
        .map(|l| {
            let distance = |f: &u32| point_triangle_distance(centre, &triangle(*f));
            let nearest = faces_at(input, l).into_iter().min_by(|a, b| distance(a).total_cmp(&distance(b)));
            normals[nearest.unwrap_or(l.face) as usize]
        })
        .fold([0.0; 3], add);
    dot(newell_normal(&points), reference) < 0.0
}

/// The input faces that hold surface point `l`: its face, and where it lies
/// on an edge or at a vertex of it, the faces around that edge or vertex.
fn faces_at(input: &TriMesh, l: &SurfacePoint) -> Vec<u32> {
    match l.on_face(input) {
        OnFace::Corner(v) => input.vertex_faces(v).collect(),
        OnFace::Side(h) => [input.face(h), input.face(input.twin(h))].into_iter().flatten().collect(),
        OnFace::Inside => vec![l.face],
    }
}

/// `(quads → input, input → quads)`: the max distance from samples of the
/// quads (referenced vertices, edge midpoints, quad centres) to the input
/// triangles, and from samples of the input (vertices, edge midpoints) to
/// the quads split into triangles `(0, 1, 2), (0, 2, 3)`. `None` each when
/// either side has nothing to sample or measure against.
fn distances(input: &TriMesh, quads: &QuadMesh, valid: &[bool], edges: &[QuadEdge]) -> (Option<f64>, Option<f64>) {
    let input_triangles: Vec<[V3; 3]> = input.faces().iter().map(|t| t.map(|v| input.position(v))).collect();
    let mut quad_triangles = Vec::with_capacity(2 * quads.n_quads());
    let mut quad_samples = Vec::with_capacity(quads.n_vertices() + edges.len() + quads.n_quads());
    let mut referenced = vec![false; quads.n_vertices()];
    for q in (0..quads.n_quads()).filter(|&q| valid[q]) {
        let p = quad_points(quads, q);
        quad_triangles.push([p[0], p[1], p[2]]);
        quad_triangles.push([p[0], p[2], p[3]]);
        quad_samples.push(scale(add(add(p[0], p[1]), add(p[2], p[3])), 0.25));
        for &v in &quads.quads[q] {
            referenced[v as usize] = true;
        }
    }
    quad_samples.extend((0..quads.n_vertices()).filter(|&v| referenced[v]).map(|v| quads.positions[v]));
    quad_samples.extend(edges.iter().map(|e| {
        let [a, b] = e.vertices.map(|v| quads.positions[v as usize]);
        midpoint(a, b)
    }));
    let input_samples: Vec<V3> = input
        .positions()
        .iter()
        .copied()
        .chain((0..input.n_edges() as u32).map(|e| {
            let [a, b] = input.edge_vertices(e);
            midpoint(input.position(a), input.position(b))
        }))
        .collect();
    (max_distance(&quad_samples, &input_triangles), max_distance(&input_samples, &quad_triangles))
}

/// Max over `samples` of the distance to the nearest of `triangles`; `None`
/// when either is empty.
fn max_distance(samples: &[V3], triangles: &[[V3; 3]]) -> Option<f64> {
    if samples.is_empty() || triangles.is_empty() {
        return None;
    }
    let boxes: Vec<(V3, V3)> = triangles.iter().map(|t| bounds(t)).collect();
    let grid = BoxGrid::new(&boxes);
    let mut seen = Visited::new(triangles.len());
    let nearest = |p: V3, seen: &mut Visited| {
        grid.nearest(p, f64::INFINITY, seen, |i| point_triangle_distance(p, &triangles[i as usize]))
    };
    Some(samples.iter().fold(0.0f64, |m, &p| m.max(nearest(p, &mut seen))))
}

/// `(edges sampled, fraction of samples within tolerance)` for the sharp
/// input edges in range: 5 samples per edge at `(k + ½) / 5`, each tested
/// against the quad edges as segments, tolerance relative to `diagonal`.
fn sharp_alignment(
    input: &TriMesh,
    quads: &QuadMesh,
    edges: &[QuadEdge],
    options: &CheckOptions,
    diagonal: f64,
) -> (usize, Option<f64>) {
    let sharp: Vec<u32> = options.sharp_edges.iter().copied().filter(|&e| (e as usize) < input.n_edges()).collect();
    if sharp.is_empty() {
        return (0, None);
    }
    let segments: Vec<[V3; 2]> = edges.iter().map(|e| e.vertices.map(|v| quads.positions[v as usize])).collect();
    let boxes: Vec<(V3, V3)> = segments.iter().map(|s| bounds(s)).collect();
    let grid = BoxGrid::new(&boxes);
    let mut seen = Visited::new(segments.len());
    let tolerance = options.sharp_tolerance * diagonal;
    let mut within = 0usize;
    for &e in &sharp {
        let [a, b] = input.edge_vertices(e).map(|v| input.position(v));
        for k in 0..SHARP_SAMPLES {
            let t = (k as f64 + 0.5) / SHARP_SAMPLES as f64;
            let p = add(a, scale(sub(b, a), t));
            let d = grid.nearest(p, tolerance, &mut seen, |i| {
                let [s0, s1] = segments[i as usize];
                point_segment_distance(p, s0, s1)
            });
            within += usize::from(d <= tolerance);
        }
    }
    (sharp.len(), Some(within as f64 / (SHARP_SAMPLES * sharp.len()) as f64))
}

#[cfg(test)]
#[path = "check_tests.rs"]
mod tests;
