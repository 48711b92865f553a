//! Quads of a mesh much finer than them, traced on its decimation
//! (`pipeline::Coarse`) and moved onto it (`quads::project_onto`): the
//! fandisk subdivided once (52 k faces) with its edges above 60° as
//! features, at 2 000 quads (26 faces per quad).

use conemap::features::FeatureSet;
use conemap::mesh::{subdivide_midpoint, TriMesh};
use conemap::param::quantize::{GridSize, QuantizeOptions};
use conemap::pipeline::{grid_map, solve, Coarse, GridFeatures, LongEdges, RefineOptions, SolveOptions, COARSE_FACES_PER_QUAD};
use conemap::quads::{check_quads, extract_quads_along, project_onto, CheckOptions, ExtractOptions};
use conemap::vec3::barycentric_point;

mod common;

/// The decimation keeps every feature edge and the topology, has about
/// `COARSE_FACES_PER_QUAD` faces per quad, and the quads traced on it lie
/// on the input (each vertex where its location says), clean, with every
/// feature edge on quad edges.
#[test]
fn quads_traced_on_a_decimation_lie_on_the_input_and_follow_its_features() {
    let input = TriMesh::from_raw(&subdivide_midpoint(&common::shared_raw("fandisk.obj"))).unwrap();
    let features = FeatureSet::sharp_edges(&input, 60.0);
    let grid = GridSize::Quads(2000);
    let coarse = Coarse::for_quads(&input, &features, grid, COARSE_FACES_PER_QUAD).expect("26 faces per quad are decimated");
    let asked = COARSE_FACES_PER_QUAD * 2000.0;
    assert!((0.8 * asked..1.2 * asked).contains(&(coarse.mesh.n_faces() as f64)), "{} faces", coarse.mesh.n_faces());
    assert_eq!(coarse.mesh.euler_characteristic(), input.euler_characteristic());
    let on_coarse = coarse.features(&input, &features);
    assert_eq!(on_coarse.len(), features.len());
    assert_eq!(coarse.input_features(&input, &on_coarse), features);
    for e in on_coarse.edges() {
        let [a, b] = coarse.mesh.edge_vertices(e).map(|v| coarse.mesh.position(v));
        let [c, d] = coarse.mesh.edge_vertices(e).map(|v| input.position(coarse.vertex[v as usize]));
        assert_eq!((a, b), (c, d), "a feature edge is the input's");
    }
    // Not decimated: few faces per quad.
    assert!(Coarse::for_quads(&input, &features, GridSize::Quads(4000), COARSE_FACES_PER_QUAD).is_none());

    let options = SolveOptions { refine: RefineOptions::for_quads(&coarse.mesh, grid), ..SolveOptions::default() }.for_quads(&coarse.mesh, grid);
    let solution = solve(&coarse.mesh, &on_coarse, &options, &mut |_| {}).unwrap();
    let grid_features = GridFeatures::asked(&coarse.mesh, on_coarse.clone());
    let mapped = grid_map(&coarse.mesh, &grid_features, &options, solution, grid, &QuantizeOptions::default(), LongEdges::RefineFirst, &mut |_| {}, &mut |_, _| {}).unwrap();
    assert!(mapped.dropped_features.is_empty());
    let untangled_later = ExtractOptions { untangle: false, ..ExtractOptions::default() };
    let mut quads = extract_quads_along(&mapped.solution.mesh, &mapped.solution.features, &mapped.map.uv, &untangled_later).unwrap();
    let moved = project_onto(&mut quads, &mapped.solution.mesh, &input, &features);
    assert!(moved > 0.0 && moved < 0.01 * input.bounding_diagonal(), "moved {moved}");
    for (p, l) in quads.positions.iter().zip(&quads.locations) {
        let t = input.faces()[l.face as usize].map(|v| input.position(v));
        let at = barycentric_point(&t, l.bary);
        assert!((0..3).all(|k| (at[k] - p[k]).abs() < 1e-12), "{p:?} is not at its location {at:?}");
    }
    let sharp: Vec<u32> = features.edges().collect();
    let report = check_quads(&input, &quads, &CheckOptions { sharp_edges: &sharp, ..CheckOptions::default() });
    assert_eq!((report.euler_characteristic, report.boundary_loops, report.non_manifold_edges), (input.euler_characteristic(), 0, 0), "{report:?}");
    assert_eq!((report.flipped_quads, report.degenerate_quads, report.defects), (0, 0, 0), "{report:?}");
    assert!(report.fraction_sharp_within_tolerance.unwrap() > 0.97, "{report:?}");
    let distance = report.distance_input_to_quads_relative.unwrap().max(report.distance_quads_to_input_relative.unwrap());
    assert!(distance < 0.01, "{report:?}");
}
