//! Cone placement on synthetic shapes with known answers.

use super::test_meshes::{grid, octahedron, square_annulus, torus};
use super::*;
use crate::features::FeatureSet;

fn run(mesh: &TriMesh, alpha: f64, miq: bool) -> ConePlacement {
    let options = ConeOptions { alpha_smooth: alpha, miq, ..ConeOptions::default() };
    place_cones(mesh, &FeatureSet::none(mesh), &options, &mut |_| {}).unwrap()
}

fn assert_gauss_bonnet(mesh: &TriMesh, r: &ConePlacement) {
    for c in &r.components {
        assert_eq!(c.k_sum, 4 * c.euler_characteristic, "sum of k is 4 chi per component");
        assert!(c.residual < 1e-8, "residual {}", c.residual);
    }
    let total: i32 = r.cones.iter().chain(&r.boundary_corners).map(|c| c.k).sum();
    assert_eq!(total as i64, 4 * mesh.euler_characteristic());
}

#[test]
fn flat_square_has_four_corners_and_no_cones() {
    let mesh = grid(8, 8, |x, y| [x, y, 0.0]);
    let r = run(&mesh, DEFAULT_ALPHA, false);
    assert_gauss_bonnet(&mesh, &r);
    assert!(r.cones.is_empty(), "cones: {:?}", r.cones);
    assert_eq!(r.boundary_corners.len(), 4);
    assert!(r.boundary_corners.iter().all(|c| c.k == 1));
    assert!(r.phi.iter().all(|p| p.abs() < 1e-8), "max |phi| {}", r.phi.iter().fold(0.0f64, |m, p| m.max(p.abs())));
}

#[test]
fn octahedron_gets_eight_quarter_turns() {
    let mesh = octahedron();
    let r = run(&mesh, DEFAULT_ALPHA, false);
    assert_gauss_bonnet(&mesh, &r);
    assert_eq!(r.cones.iter().map(|c| c.k).sum::<i32>(), 8);
}

#[test]
fn torus_of_revolution_at_large_alpha_has_no_cones() {
    let mesh = torus(24, 12, 2.0, 0.7);
    let r = run(&mesh, 100.0, false);
    assert_gauss_bonnet(&mesh, &r);
    assert_eq!(r.components[0].path_integers.len(), 2, "two homology loops");
    assert!(r.cones.is_empty(), "cones: {:?}", r.cones);
}

#[test]
fn axis_aligned_annulus_is_flat_without_cones() {
    let mesh = square_annulus(4, 3, 0.4, 0.0);
    let r = run(&mesh, DEFAULT_ALPHA, false);
    assert_gauss_bonnet(&mesh, &r);
    assert!(r.cones.is_empty(), "cones: {:?}", r.cones);
    assert_eq!(r.boundary_corners.iter().filter(|c| c.k == 1).count(), 4);
    assert_eq!(r.boundary_corners.iter().filter(|c| c.k == -1).count(), 4);
    assert!(r.phi.iter().all(|p| p.abs() < 1e-8));
}

#[test]
fn rotated_annulus_absorbs_the_rotation_with_cones() {
    let mesh = square_annulus(6, 4, 0.4, 30f64.to_radians());
    let r = run(&mesh, DEFAULT_ALPHA, false);
    assert_gauss_bonnet(&mesh, &r);
    assert!(!r.cones.is_empty(), "a 30 degree misalignment needs cones");
    assert_eq!(r.components[0].path_integers.len(), 1, "one alignment path between the two loops");
}

#[test]
fn ring_with_flap_gets_cones_where_miq_emulation_gets_none() {
    // Figure 10: boundary alignment forces a cone-free map to collapse the flap.
    let mesh = super::test_meshes::ring_with_flap(96);
    assert_eq!(mesh.boundary_loops().len(), 2);
    let ours = run(&mesh, DEFAULT_ALPHA, false);
    assert_gauss_bonnet(&mesh, &ours);
    let miq = run(&mesh, MIQ_ALPHA, true);
    assert_gauss_bonnet(&mesh, &miq);
    assert!(miq.cones.is_empty(), "MIQ emulation: {:?}", miq.cones);
    assert!(!ours.cones.is_empty(), "the method must place cones to avoid the collapse");
}

/// Opposite interior cones closer than `min_pair_distance` cancel (a quad
/// grid cannot keep them apart) and Gauss-Bonnet still holds; a distance
/// beyond every pair leaves a bump without cones.
#[test]
fn close_opposite_cones_cancel_for_a_coarse_grid() {
    let mesh = grid(24, 24, |x, y| [x, y, 0.5 * (-40.0 * ((x - 0.5).powi(2) + (y - 0.5).powi(2))).exp()]);
    let with = |d: f64| {
        let options = ConeOptions { min_pair_distance: d, ..ConeOptions::default() };
        place_cones(&mesh, &FeatureSet::none(&mesh), &options, &mut |_| {}).unwrap()
    };
    let kept = with(0.0);
    assert_gauss_bonnet(&mesh, &kept);
    let turns = |r: &ConePlacement| r.cones.iter().map(|c| c.k.abs()).sum::<i32>();
    let d = 0.3;
    let pairs = kept.close_pairs(d);
    assert!(!pairs.is_empty() && pairs.len() < turns(&kept) as usize / 2, "{pairs:?}");
    let cancelled = with(d);
    assert_gauss_bonnet(&mesh, &cancelled);
    assert!(cancelled.close_pairs(d).is_empty());
    assert_eq!(turns(&cancelled), turns(&kept) - 2 * pairs.len() as i32);
    let none = with(2.0);
    assert_gauss_bonnet(&mesh, &none);
    assert!(none.cones.is_empty(), "cones: {:?}", none.cones);
}

/// [`close_pairs`]: closest first, each quarter turn in one pair (a cone
/// of index -2 in two), none at or beyond the distance.
#[test]
fn close_pairs_are_greedy_by_distance() {
    let at = |x: f64, k: i64| ([x, 0.0, 0.0], k);
    let cones = [at(0.0, 1), at(0.3, -1), at(0.5, 1), at(1.0, -2), at(1.25, 1), at(5.0, -1), at(5.9, 1), at(1.6, 1)];
    assert_eq!(close_pairs(&cones, 0.9), vec![(2, 1), (4, 3), (7, 3)]);
    assert_eq!(close_pairs(&cones, 0.15), vec![]);
}
