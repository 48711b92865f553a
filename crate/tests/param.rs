//! Seamless parametrization (Appendix B) on the shared meshes: every seam
//! transition is a k·90° rotation plus a translation, every feature and
//! boundary edge is an isoline, no triangle is flipped, and the UV angle sum
//! at every interior vertex is its cone angle `2 pi - k pi/2`.

use conemap::cones::ConeOptions;
use conemap::features::FeatureSet;
use conemap::pipeline::{solve, SolveOptions};
use conemap::mesh::TriMesh;
use conemap::param::{metrics::uv_angle_sums, ParamOptions};
use std::f64::consts::{FRAC_PI_2, PI};

mod common;
use common::{shared_mesh as load, side_by_side};

/// Solves `name` and checks the map; `max_flip_fraction` is the share of
/// flipped triangles tolerated (0 except where a known shortfall is stated).
/// The callers' distortion bounds are about 15 % above today's figures (in
/// the comments, also in docs/STATUS.md): a regression of the placement or
/// the map fails them.
fn run(name: &str, sharp: Option<f64>, max_distortion: f64, max_flip_fraction: f64) {
    run_on(name, &load(name), sharp, max_distortion, max_flip_fraction);
}

/// [`run`] on `input`; also: the UVs agree on both sides of every interior
/// edge that is not a seam, and every feature edge asked for is aligned
/// (on the input, through the refinement's maps).
fn run_on(name: &str, input: &TriMesh, sharp: Option<f64>, max_distortion: f64, max_flip_fraction: f64) {
    let features = match sharp {
        Some(deg) => FeatureSet::sharp_edges(input, deg),
        None => FeatureSet::none(input),
    };
    let options = SolveOptions {
        cones: ConeOptions { alpha_smooth: 0.01, ..ConeOptions::default() },
        ..SolveOptions::default()
    };
    let solution = solve(input, &features, &options, &mut |_| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (mesh, placement, p) = (&*solution.mesh, &solution.placement, &solution.param);
    let m = &p.metrics;
    let t = &p.timings;
    println!(
        "| {name} | {} | {} (+{} corners) | {:.4} | {:.3} | {} -> {} | {:.1e} / {:.1e} | {:.1e} | cut {:.3} field {:.3} poisson {:.3} arap {:.3} ({} it) repair {:.3} | cones stage {:.2} |",
        m.faces,
        m.cones,
        m.boundary_corners,
        m.distortion,
        m.fraction_below_0_3,
        p.counts.flips_before_repair,
        m.flipped,
        m.seam_angle_residual,
        m.seam_length_residual,
        m.alignment_residual,
        t.cut,
        t.field,
        t.poisson,
        t.arap,
        p.counts.arap_iterations,
        t.repair,
        placement.timings.total,
    );
    assert_eq!(p.uv.len(), 3 * mesh.n_faces());
    assert!(m.seam_angle_residual < 1e-6, "{name}: seam angle residual {}", m.seam_angle_residual);
    assert!(m.seam_length_residual < 1e-6, "{name}: seam length residual {}", m.seam_length_residual);
    assert!(m.alignment_residual < 1e-6, "{name}: alignment residual {}", m.alignment_residual);
    let allowed = (max_flip_fraction * m.faces as f64).floor() as usize;
    assert!(m.flipped <= allowed, "{name}: {} flipped triangles (allowed {allowed})", m.flipped);
    assert_eq!(m.wound_vertices, 0, "{name}: the map winds more than once around a vertex");
    assert!(m.distortion < max_distortion, "{name}: distortion {}", m.distortion);
    let mut seam = vec![false; mesh.n_edges()];
    p.seam_edges.iter().for_each(|&e| seam[e as usize] = true);
    for e in (0..mesh.n_edges() as u32).filter(|&e| !seam[e as usize] && !mesh.is_boundary_edge(e)) {
        let [h, t] = mesh.edge_halfedges(e);
        let same = |a: u32, b: u32| p.uv[a as usize] == p.uv[b as usize];
        assert!(same(h, mesh.next(t)) && same(mesh.next(h), t), "{name}: the map is cut along edge {e}, not a seam");
    }
    let alignment = solution.feature_alignment(input, &features);
    assert_eq!(alignment.aligned, alignment.requested, "{name}: {:?}", alignment.unaligned.first());

    // UV angle sums at interior vertices: 2 pi - k pi/2.
    let mut k = vec![0i32; mesh.n_vertices()];
    for c in &placement.cones {
        k[c.vertex as usize] = c.k;
    }
    let sums = uv_angle_sums(mesh, &p.uv);
    // Vertices of the tolerated flipped triangles are left out.
    let mut next_to_flip = vec![false; mesh.n_vertices()];
    for (f, tri) in mesh.faces().iter().enumerate() {
        let uv = [p.uv[3 * f], p.uv[3 * f + 1], p.uv[3 * f + 2]];
        let area = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
        if area <= 0.0 {
            tri.iter().for_each(|&v| next_to_flip[v as usize] = true);
        }
    }
    assert!(next_to_flip.iter().filter(|&&x| x).count() <= 3 * allowed);
    for v in 0..mesh.n_vertices() as u32 {
        if mesh.is_boundary_vertex(v) || next_to_flip[v as usize] {
            continue;
        }
        let expected = 2.0 * PI - k[v as usize] as f64 * FRAC_PI_2;
        assert!(
            (sums[v as usize] - expected).abs() < 1e-6,
            "{name}: vertex {v} (k = {}) UV angle sum {} expected {expected}",
            k[v as usize],
            sums[v as usize]
        );
    }
}

/// A mesh of several components is solved one component at a time and the
/// solutions joined: the joined map passes every check of [`run_on`] (cone
/// angle sums, seams, continuity, alignment), with fandisk refined for its
/// features and the hemisphere not.
#[test]
fn components_are_solved_apart_and_joined() {
    let input = side_by_side(&["fandisk.obj", "bff-hemisphere.obj", "fandisk.obj"]);
    assert_eq!(input.n_components(), 3);
    run_on("fandisk, hemisphere and fandisk", &input, Some(60.0), 0.185, 0.0);
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    assert!(solution.original_face.is_none(), "without features nothing is refined: the mesh solved is the input");
    // Gauss-Bonnet on each component: its cones and corners add up to 4 chi.
    let mut k_sum = vec![0i64; input.n_components()];
    for c in solution.placement.cones.iter().chain(&solution.placement.boundary_corners) {
        k_sum[input.vertex_component(c.vertex)] += c.k as i64;
    }
    let expected: Vec<i64> = (0..input.n_components()).map(|c| 4 * input.component_euler_characteristic(c)).collect();
    assert_eq!(k_sum, expected);
}

#[test]
fn fandisk_with_sharp_features() {
    run("fandisk.obj", Some(60.0), 0.185, 0.0); // .159
}

/// The bar for fandisk with features > 60° at alpha 0.01: at least
/// 85 % of the triangles below 0.3 (paper: 0.226 mean distortion).
#[test]
fn fandisk_with_sharp_features_has_85_percent_below_0_3() {
    let input = load("fandisk.obj");
    let features = FeatureSet::sharp_edges(&input, 60.0);
    let options = SolveOptions { cones: ConeOptions { alpha_smooth: 0.01, ..ConeOptions::default() }, param: ParamOptions::default(), ..SolveOptions::default() };
    let solution = solve(&input, &features, &options, &mut |_| {}).unwrap();
    let m = &solution.param.metrics;
    assert!(m.fraction_below_0_3 >= 0.85, "fraction below 0.3: {}", m.fraction_below_0_3);
}

/// cow.obj and teapot.obj have a pinch vertex each; it is split and they solve.
#[test]
fn meshes_with_a_pinch_vertex() {
    run("cow.obj", None, 0.12, 0.0); // .104
    run("teapot.obj", None, 0.145, 0.0); // .125
}

#[test]
fn spot() {
    run("spot.obj", None, 0.105, 0.0); // .091
}

#[test]
fn woody() {
    run("woody.obj", None, 0.175, 0.0); // .150
}

#[test]
fn alligator() {
    run("alligator.obj", None, 0.135, 0.0); // .116
}

#[test]
fn bff_punctured_torus() {
    run("bff-punctured-torus.obj", None, 0.10, 0.0); // .088
}

#[test]
fn bff_hemisphere() {
    run("bff-hemisphere.obj", None, 0.12, 0.0); // .104
}

/// A closed cylinder whose caps are triangle fans: with the rims as features
/// each cap's only interior vertex would need a cone of index 4 (angle 0).
fn fan_capped_cylinder(n: usize) -> TriMesh {
    let mut positions = Vec::new();
    for y in [-1.0, 1.0] {
        for i in 0..n {
            let t = 2.0 * PI * i as f64 / n as f64;
            positions.push([t.cos(), y, t.sin()]);
        }
    }
    positions.push([0.0, -1.0, 0.0]);
    positions.push([0.0, 1.0, 0.0]);
    let (bottom, top) = ((2 * n) as u32, (2 * n + 1) as u32);
    let mut triangles = Vec::new();
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        let (a, b, c, d) = (i, j, n as u32 + j, n as u32 + i);
        triangles.push([a, c, b]);
        triangles.push([a, d, c]);
        triangles.push([a, b, bottom]);
        triangles.push([d, top, c]);
    }
    TriMesh::from_welded_arrays(positions, triangles).expect("valid cylinder")
}

#[test]
fn a_fan_capped_cylinder_with_feature_rims_solves_without_zero_angle_cones() {
    let mesh = fan_capped_cylinder(32);
    assert_eq!(mesh.euler_characteristic(), 2);
    let options = SolveOptions { cones: ConeOptions::default(), param: ParamOptions::default(), ..SolveOptions::default() };
    let rims = FeatureSet::sharp_edges(&mesh, 40.0);
    assert_eq!(rims.len(), 64);
    // Rounded corner by corner, each cap's rim turns by 0 and its centre
    // alone would need index 4 (angle 0): the cap's corners are rounded as a
    // whole instead (four corners of 90°), or the faces around the centre split.
    let solution = solve(&mesh, &rims, &options, &mut |_| {}).expect("solved");
    let m = &solution.param.metrics;
    let cut = &solution.placement.cut.mesh;
    let corners: i32 = (0..cut.n_vertices() as u32).filter(|&v| cut.is_boundary_vertex(v)).map(|v| solution.placement.k[v as usize]).sum();
    assert!(solution.splits > 0 || corners > 0, "neither refined nor cornered");
    println!("cylinder: {} splits, corner k sum {corners}, distortion {}", solution.splits, m.distortion);
    assert!(solution.placement.k.iter().all(|&k| k < 4), "no cone of angle 0 is left");
    assert_eq!((m.flipped, m.wound_vertices), (0, 0));
    assert!(m.alignment_residual < 1e-6 && m.seam_angle_residual < 1e-6);
    let none = FeatureSet::none(&mesh);
    let solution = solve(&mesh, &none, &options, &mut |_| {}).expect("solves without features");
    assert_eq!(solution.param.metrics.flipped, 0);
}
