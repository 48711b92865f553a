//! `BoundaryMode::Free` on the shared meshes with holes: the map is seamless
//! and fold-free with no boundary corners, and leaving the boundary free
//! costs no distortion against aligning it, and saves much where the
//! aligned map bends around corners of a long boundary (bff-punctured-torus:
//! genus 1 and a hole, so homology loops and a free loop together;
//! bff-face: coarse to fine).

use conemap::cones::{BoundaryMode, ConeOptions};
use conemap::features::FeatureSet;
use conemap::mesh::TriMesh;
use conemap::pipeline::{solve, SolveOptions};

mod common;
use common::shared_mesh as mesh;

/// Distortion of the solve with the boundary `mode`, after checking the map.
fn distortion(name: &str, input: &TriMesh, mode: BoundaryMode) -> f64 {
    let options = SolveOptions { cones: ConeOptions { boundary: mode, ..ConeOptions::default() }, ..SolveOptions::default() };
    let features = FeatureSet::none(input);
    let s = solve(input, &features, &options, &mut |_| {}).unwrap_or_else(|e| panic!("{name} {mode:?}: {e}"));
    let m = &s.param.metrics;
    println!("{name} {mode:?}: {} cones, {} corners, distortion {:.4}", m.cones, m.boundary_corners, m.distortion);
    assert!(m.seam_angle_residual < 1e-9 && m.seam_length_residual < 1e-9, "{name}: seams {} {}", m.seam_angle_residual, m.seam_length_residual);
    assert_eq!((m.flipped, m.wound_vertices), (0, 0), "{name} {mode:?}: folds");
    if mode == BoundaryMode::Free {
        assert_eq!(m.boundary_corners, 0, "{name}: a free boundary has no corners");
    }
    m.distortion
}

#[test]
fn free_boundaries_are_seamless_and_cost_no_distortion() {
    // (mesh, largest free/aligned distortion ratio): a free boundary is a
    // relaxation, so no worse up to the greedy's noise on the torus's small
    // hole (16 edges), and clearly better on the face's long jagged one.
    // teapot: four open parts, tubes among them (its spout's reduced trial
    // system defeats the unpivoted LDLᵀ: the component KKT answers there).
    for (name, ratio) in [("bff-punctured-torus.obj", 1.02), ("bff-face.obj", 0.8), ("teapot.obj", 1.0)] {
        let input = mesh(name);
        let aligned = distortion(name, &input, BoundaryMode::Aligned);
        let free = distortion(name, &input, BoundaryMode::Free);
        assert!(free < ratio * aligned, "{name}: free {free:.4} against aligned {aligned:.4}");
    }
}
