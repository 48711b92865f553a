//! Unit tests of the parametrization stage on synthetic meshes.

use super::*;
use crate::cones::test_meshes::{grid, octahedron, torus};
use crate::cones::{place_cones, ConeOptions};
use crate::features::FeatureSet;
use std::f64::consts::{FRAC_PI_2, PI};

fn run(mesh: &TriMesh, features: &FeatureSet) -> (ConePlacement, Parametrization) {
    let placement = place_cones(mesh, features, &ConeOptions::default(), &mut |_| {}).expect("cones");
    let p = parametrize(mesh, &placement, &ParamOptions::default(), &mut |_| {}).expect("param");
    (placement, p)
}

fn check(mesh: &TriMesh, placement: &ConePlacement, p: &Parametrization) {
    let m = &p.metrics;
    assert!(m.seam_angle_residual < 1e-6, "seam angle {}", m.seam_angle_residual);
    assert!(m.seam_length_residual < 1e-6, "seam length {}", m.seam_length_residual);
    assert!(m.alignment_residual < 1e-6, "alignment {}", m.alignment_residual);
    assert_eq!(m.flipped, 0, "flipped triangles");
    let sums = metrics::uv_angle_sums(mesh, &p.uv);
    let cut = cut_graph::cut_graph(mesh, placement, &field::cross_field(mesh, placement).unwrap()).unwrap();
    for v in 0..mesh.n_vertices() as u32 {
        let k = cut.vertex_k[v as usize] as f64;
        let expected = if mesh.is_boundary_vertex(v) { PI - k * FRAC_PI_2 } else { 2.0 * PI - k * FRAC_PI_2 };
        assert!((sums[v as usize] - expected).abs() < 1e-6, "vertex {v}: angle sum {} expected {expected}", sums[v as usize]);
    }
}

#[test]
fn field_matchings_are_integers_and_aligned() {
    for mesh in [octahedron(), torus(12, 8, 2.0, 0.7), grid(5, 5, |x, y| [x, y, 0.2 * x * y])] {
        let placement = place_cones(&mesh, &FeatureSet::none(&mesh), &ConeOptions::default(), &mut |_| {}).unwrap();
        let f = field::cross_field(&mesh, &placement).unwrap();
        assert!(f.integrality_residual < 1e-6, "residual {}", f.integrality_residual);
    }
}

#[test]
fn closest_rotation_is_the_polar_factor() {
    let r = seamless::closest_rotation([[2.0, -0.1], [0.3, 1.5]]).unwrap();
    assert!((r[0][0] * r[1][1] - r[0][1] * r[1][0] - 1.0).abs() < 1e-12);
    let (s, c) = (0.4f64).sin_cos();
    let r = seamless::closest_rotation([[3.0 * c, -3.0 * s], [3.0 * s, 3.0 * c]]).unwrap();
    assert!((r[0][0] - c).abs() < 1e-12 && (r[1][0] - s).abs() < 1e-12);
}

#[test]
fn flat_square_is_a_similarity() {
    let mesh = grid(8, 8, |x, y| [x, y, 0.0]);
    let (placement, p) = run(&mesh, &FeatureSet::none(&mesh));
    assert_eq!(placement.cones.len(), 0);
    check(&mesh, &placement, &p);
    assert!(p.metrics.distortion < 1e-6, "distortion {}", p.metrics.distortion);
}

#[test]
fn bumpy_square_and_closed_surfaces() {
    let mesh = grid(10, 10, |x, y| [x, y, 0.15 * (3.0 * x).sin() * (2.0 * y).cos()]);
    let (placement, p) = run(&mesh, &FeatureSet::none(&mesh));
    check(&mesh, &placement, &p);
    println!("bumpy square: {:?}", p.metrics);
    for mesh in [octahedron(), torus(16, 10, 2.0, 0.7)] {
        let (placement, p) = run(&mesh, &FeatureSet::none(&mesh));
        check(&mesh, &placement, &p);
        println!("closed: {:?}", p.metrics);
    }
}

#[test]
fn mismatched_placement_is_an_error() {
    let a = grid(3, 3, |x, y| [x, y, 0.0]);
    let b = grid(4, 4, |x, y| [x, y, 0.0]);
    let placement = place_cones(&a, &FeatureSet::none(&a), &ConeOptions::default(), &mut |_| {}).unwrap();
    let r = parametrize(&b, &placement, &ParamOptions::default(), &mut |_| {});
    assert!(matches!(r, Err(ParamError::MeshMismatch { .. })));
}

/// Smallest ratio of UV area to 3D area over all faces, after scaling the
/// UVs so the total areas match.
fn min_area_ratio(mesh: &TriMesh, uv: &[[f64; 2]]) -> f64 {
    let areas = crate::operators::face_areas(mesh.positions(), mesh.faces());
    let uv_areas: Vec<f64> = (0..mesh.n_faces())
        .map(|f| seamless::signed_uv_area([uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]]))
        .collect();
    let scale = areas.iter().sum::<f64>() / uv_areas.iter().sum::<f64>();
    (0..mesh.n_faces()).map(|f| uv_areas[f] * scale / areas[f]).fold(f64::INFINITY, f64::min)
}

#[test]
fn ring_with_flap_does_not_collapse_while_miq_emulation_does() {
    // Figure 10: without cones the boundary-aligned map must squeeze the flap.
    let mesh = crate::cones::test_meshes::ring_with_flap(96);
    let none = FeatureSet::none(&mesh);
    let ours = run(&mesh, &none).1;
    let ours_min = min_area_ratio(&mesh, &ours.uv);
    let options = ConeOptions { alpha_smooth: crate::cones::MIQ_ALPHA, miq: true, ..ConeOptions::default() };
    let placement = place_cones(&mesh, &none, &options, &mut |_| {}).unwrap();
    assert!(placement.cones.is_empty());
    let miq_min = match parametrize(&mesh, &placement, &ParamOptions::default(), &mut |_| {}) {
        Ok(p) => min_area_ratio(&mesh, &p.uv),
        Err(_) => 0.0, // a collapsed system is a collapse too
    };
    eprintln!("ring with flap: smallest UV/3D area ratio {ours_min:.3} (ours) vs {miq_min:.2e} (MIQ emulation)");
    assert!(ours_min > 0.05, "our map: smallest area ratio {ours_min}");
    assert!(miq_min < 0.2 * ours_min, "MIQ emulation should collapse the flap: {miq_min} vs {ours_min}");
}


#[test]
fn folded_arap_map_is_repaired_and_refined_without_flips() {
    // A square annulus with a rotated hole: ARAP leaves flipped triangles
    // (8 with the harmonic weight of session 9; the hole 0.4 / 0.5 rad
    // folded before and no longer does); the repaired map is the start of
    // the injective refinement.
    let mesh = crate::cones::test_meshes::square_annulus(8, 4, 0.5, 0.6);
    let none = FeatureSet::none(&mesh);
    let options = ConeOptions { alpha_smooth: 0.01, ..ConeOptions::default() };
    let placement = place_cones(&mesh, &none, &options, &mut |_| {}).expect("cones");
    let no_refine = ParamOptions { refine: injective::RefineOptions { max_iterations: 0, ..Default::default() }, ..Default::default() };
    let before = parametrize(&mesh, &placement, &no_refine, &mut |_| {}).expect("param");
    let after = parametrize(&mesh, &placement, &ParamOptions::default(), &mut |_| {}).expect("param");
    assert!(after.flips_before_repair > 0, "the case should start with flips");
    assert!(after.refine_iterations > 0);
    check(&mesh, &placement, &after);
    assert_eq!(after.metrics.wound_vertices, 0);
    assert!(after.metrics.distortion < before.metrics.distortion, "{} vs {}", after.metrics.distortion, before.metrics.distortion);
    eprintln!("annulus: distortion {:.4} -> {:.4}", before.metrics.distortion, after.metrics.distortion);
}

