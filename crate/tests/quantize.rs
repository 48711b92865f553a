//! Integer-grid maps (param::quantize) on the shared meshes, checked from the
//! output UVs alone: across every interior edge the two sides differ by a
//! k·90° rotation plus an integer translation (grid units), every cone and
//! singular corner is an integer point, every feature and boundary edge lies
//! on an integer isoline, and no triangle is flipped.

use conemap::features::FeatureSet;
use conemap::mesh::TriMesh;
use conemap::param::{metrics::uv_angle_sums, quantize::{GridSize, QuantizeOptions}};
use conemap::pipeline::{solve, SolveOptions};
use std::f64::consts::PI;

mod common;
use common::shared_mesh as load;

/// Largest distance from an integer among `values`.
fn off_integer(values: impl IntoIterator<Item = f64>) -> f64 {
    values.into_iter().fold(0.0f64, |m, v| m.max((v - v.round()).abs()))
}

/// Checks the integer-grid properties of per-corner `uv` on `mesh` with
/// `features` (seams, isolines); returns the numbers of flipped triangles
/// and of singular vertices (UV angle sum off 2 pi, away from flips) off
/// an integer point.
fn check_integer_grid(name: &str, mesh: &TriMesh, features: &FeatureSet, uv: &[[f64; 2]]) -> (usize, usize) {
    let (flipped, off_grid, cones) = check_integer_grid_counting_cones(name, mesh, features, uv);
    assert!(cones > 0, "{name}: no cone found");
    (flipped, off_grid)
}

/// [`check_integer_grid`], for a map that may have no interior cone: also
/// returns the number of singular interior vertices.
fn check_integer_grid_counting_cones(name: &str, mesh: &TriMesh, features: &FeatureSet, uv: &[[f64; 2]]) -> (usize, usize, usize) {
    let rotate = |k: usize, p: [f64; 2]| match k % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    };
    let mut worst_translation = 0.0f64;
    let mut worst_rotation = 0.0f64;
    for e in 0..mesh.n_edges() as u32 {
        if mesh.is_boundary_edge(e) {
            continue;
        }
        let [h, t] = mesh.edge_halfedges(e);
        // Side f: h from a to b; side g: t from b to a.
        let (fa, fb) = (uv[h as usize], uv[mesh.next(h) as usize]);
        let (gb, ga) = (uv[t as usize], uv[mesh.next(t) as usize]);
        let df = [fb[0] - fa[0], fb[1] - fa[1]];
        let dg = [gb[0] - ga[0], gb[1] - ga[1]];
        let k = (0..4)
            .min_by(|&i, &j| {
                let d = |k: usize| {
                    let r = rotate(k, df);
                    (r[0] - dg[0]).hypot(r[1] - dg[1])
                };
                d(i).total_cmp(&d(j))
            })
            .unwrap();
        let r = rotate(k, df);
        worst_rotation = worst_rotation.max((r[0] - dg[0]).hypot(r[1] - dg[1]));
        let ra = rotate(k, fa);
        worst_translation = worst_translation.max(off_integer([ga[0] - ra[0], ga[1] - ra[1]]));
    }
    assert!(worst_rotation < 1e-6, "{name}: seam not a k·90° rotation ({worst_rotation:.2e})");
    assert!(worst_translation < 1e-6, "{name}: seam translation off an integer by {worst_translation:.2e}");

    // Singular vertices (UV angle sum off 2 pi inside) at integer points.
    let sums = uv_angle_sums(mesh, uv);
    let flipped: Vec<usize> = (0..mesh.n_faces())
        .filter(|&f| {
            let [p, q, r] = [uv[3 * f], uv[3 * f + 1], uv[3 * f + 2]];
            ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        })
        .collect();
    // (A flipped triangle's corners have no meaningful angle sum.)
    let near_flip = |v: u32| mesh.vertex_faces(v).any(|f| flipped.contains(&(f as usize)));
    let (mut cones, mut off_grid) = (0, 0);
    for (v, &sum) in sums.iter().enumerate() {
        if mesh.is_boundary_vertex(v as u32) || near_flip(v as u32) {
            continue;
        }
        if (sum - 2.0 * PI).abs() > 0.25 * PI {
            cones += 1;
            for f in mesh.vertex_faces(v as u32) {
                let k = mesh.faces()[f as usize].iter().position(|&w| w as usize == v).unwrap();
                let p = uv[3 * f as usize + k];
                if off_integer(p) > 1e-9 {
                    println!("{name}: singular vertex v{v} (angle {sum}) at {p:?}, not an integer point");
                    off_grid += 1;
                    break;
                }
            }
        }
    }

    // Features and boundary on integer isolines.
    let mut worst_isoline = 0.0f64;
    for e in 0..mesh.n_edges() as u32 {
        if !(features.contains(e) || mesh.is_boundary_edge(e)) {
            continue;
        }
        for h in mesh.edge_halfedges(e) {
            if mesh.is_boundary_halfedge(h) {
                continue;
            }
            let (a, b) = (uv[h as usize], uv[mesh.next(h) as usize]);
            let c = if (a[0] - b[0]).abs() < (a[1] - b[1]).abs() { 0 } else { 1 };
            worst_isoline = worst_isoline.max(off_integer([a[c], b[c]]));
        }
    }
    assert!(worst_isoline < 1e-9, "{name}: feature edge off an integer isoline by {worst_isoline:.2e}");
    (flipped.len(), off_grid, cones)
}

/// Quantizes `name` and checks the integer-grid properties; returns the
/// flipped triangles and off-grid singular vertices (asserted 0 by the
/// callers that meet it).
fn run(name: &str, sharp: Option<f64>, quads: usize) -> (usize, usize) {
    run_on(name, &load(name), sharp, quads, &SolveOptions::default())
}

/// [`run`] on a given mesh, solved with `options`.
fn run_on(name: &str, input: &TriMesh, sharp: Option<f64>, quads: usize, options: &SolveOptions) -> (usize, usize) {
    let input = input.clone();
    let features = match sharp {
        Some(deg) => FeatureSet::sharp_edges(&input, deg),
        None => FeatureSet::none(&input),
    };
    let solution = solve(&input, &features, options, &mut |_| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
    let quantizer = solution.quantizer().unwrap_or_else(|e| panic!("{name}: {e}"));
    let map = quantizer.quantize(&solution.mesh, GridSize::Quads(quads), &mut |_, _| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
    let r = &map.report;
    println!("{name} {quads}: {r:?}");
    assert_eq!(r.conflicts, 0, "{name}: integers not met");
    assert!((r.cells / quads as f64 - 1.0).abs() < 0.1, "{name}: {} cells for {quads} asked", r.cells);
    assert!(r.distortion_after >= r.distortion_before * 0.99 && r.distortion_after < 1.5 * r.distortion_before, "{name}: distortion {r:?}");
    let (flipped, off_grid) = check_integer_grid(name, &solution.mesh, &solution.features, &map.uv);
    assert_eq!(flipped, r.flipped, "{name}: flip count");
    (flipped, off_grid)
}

/// A fan-capped cylinder of `n` segments (caps fanned from the first rim
/// vertex), midpoint-subdivided `levels` times: vertices and faces in the
/// order that reproduces the cut below.
fn fan_cylinder(n: u32, levels: usize) -> TriMesh {
    use std::collections::HashMap;
    let mut p: Vec<[f64; 3]> = Vec::new();
    for z in [0.0, 2.0] {
        for i in 0..n {
            let a = 2.0 * PI * i as f64 / n as f64;
            p.push([a.cos(), a.sin(), z]);
        }
    }
    let mut t: Vec<[u32; 3]> = Vec::new();
    for i in 0..n {
        let (a, b, c, d) = (i, (i + 1) % n, n + (i + 1) % n, n + i);
        t.extend([[a, b, c], [a, c, d]]);
    }
    for i in 1..n - 1 {
        t.extend([[0, i + 1, i], [n, n + i, n + i + 1]]);
    }
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(4 * t.len());
        for [a, b, c] in t {
            let mut m = |u: u32, w: u32| {
                *mid.entry((u.min(w), u.max(w))).or_insert_with(|| {
                    let (x, y) = (p[u as usize], p[w as usize]);
                    p.push([0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1]), 0.5 * (x[2] + y[2])]);
                    p.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        t = next;
    }
    TriMesh::from_raw(&conemap::mesh::RawMesh { positions: p, triangles: t }).unwrap()
}

/// A CAD-style cylinder with its rims as features is cut into disks joined
/// by rotating seams. A seam translation between two disks responds to both
/// disks' translations: with only one side's response counted, a disk lost
/// its gauge pin once the translations were rounded, and the rounded system
/// was singular ("solve did not converge" on this mesh at 3 000 quads).
/// Solved as `solve --quads 3000` solves it (without the cancellation of
/// close cone pairs, the map behind it now winds around two vertices: the
/// rounding is chaotic, and spreading the caps' corners changed its path).
#[test]
fn seams_between_disks_fix_both_translations() {
    let cylinder = fan_cylinder(24, 3);
    let options = SolveOptions::default().for_quads(&cylinder, GridSize::Quads(3000));
    let (flipped, off_grid) = run_on("fan cylinder", &cylinder, Some(60.0), 3000, &options);
    assert_eq!((flipped, off_grid), (0, 0));
}

/// A cone's position `c` across a seam of 90° gives `(I - R) c` (determinant
/// 2), so a form can be determined at half an integer by integers rounded
/// one by one: blocks of unit cubes with through holes (genus 2 and 3, no
/// features) had 8-10 seam translations at n + 1/2 at these cell counts.
#[test]
fn forms_determined_at_half_integers_are_made_integers() {
    for (holes, nx, counts) in [(vec![(1, 1), (3, 1)], 5, [300, 1000]), (vec![(1, 1), (3, 1), (5, 1)], 7, [100, 1000])] {
        let block = TriMesh::from_raw(&conemap::mesh::shapes::voxel_block(nx, 3, 1, &holes)).unwrap();
        assert_eq!(block.euler_characteristic(), 2 - 2 * holes.len() as i64);
        let features = FeatureSet::none(&block);
        let solution = solve(&block, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
        let quantizer = solution.quantizer().unwrap();
        for quads in counts {
            let name = format!("genus-{} block at {quads}", holes.len());
            // (The cubes' faces are not whole cells: distortion from 0 to about 0.3.)
            let map = quantizer.quantize(&solution.mesh, GridSize::Quads(quads), &mut |_, _| {}).unwrap();
            assert_eq!(map.report.conflicts, 0, "{name}: {:?}", map.report);
            assert!(map.report.integer_residual < 1e-9, "{name}: {:?}", map.report);
            assert_eq!(check_integer_grid(&name, &solution.mesh, &features, &map.uv), (0, 0), "{name}");
        }
    }
}

/// A UV map's integer-grid map that winds around a vertex (no flipped
/// triangle) shows a singular point off the grid; with `retry_wound` it is
/// rounded again at nearby grid sizes and the map with fewer faults kept.
/// The cow at 3 000 cells wound around 2 vertices at the asked length and
/// none at 0.97 of it until the held pass widened its rows; it is now clean
/// at the asked length. At 1 000 cells it winds around 4 vertices at the
/// asked length (at 1 500 cells, 2 at all three lengths, until tube periods
/// were kept three steps around): the map kept is no worse than the plain
/// one and still an integer-grid map away from those vertices.
#[test]
fn uv_grid_maps_round_again_where_they_wind_around_vertices() {
    let cow = load("cow.obj");
    let features = FeatureSet::none(&cow);
    let solution = solve(&cow, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let quantizer = solution.quantizer().unwrap();
    let clean = quantizer.quantize(&solution.mesh, GridSize::Quads(3000), &mut |_, _| {}).unwrap();
    assert_eq!((clean.report.flipped, clean.report.wound_vertices), (0, 0), "{:?}", clean.report);
    let plain = quantizer.quantize(&solution.mesh, GridSize::Quads(1000), &mut |_, _| {}).unwrap();
    assert!(plain.report.flipped == 0 && plain.report.wound_vertices > 0, "the case this test is about: {:?}", plain.report);
    let options = QuantizeOptions { retry_wound: true, ..QuantizeOptions::default() };
    let map = quantizer.quantize_with(&solution.mesh, GridSize::Quads(1000), &options, &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert!((r.flipped, r.wound_vertices) <= (plain.report.flipped, plain.report.wound_vertices), "{r:?}");
    assert!((r.grid_size / plain.report.grid_size - 1.0).abs() <= 0.031 && r.conflicts == 0, "{r:?}");
    // A vertex the map winds around is a singular point off the grid: no other is.
    let (flipped, off_grid) = check_integer_grid("cow", &solution.mesh, &solution.features, &map.uv);
    assert!(flipped == 0 && off_grid <= r.wound_vertices, "{flipped} flipped, {off_grid} off the grid: {r:?}");
}

#[test]
fn spot_3000_quads() {
    assert_eq!(run("spot.obj", None, 3000), (0, 0));
}

/// Cones beside feature isolines less than a cell away, and isolines
/// determined through seams, are kept a grid line apart (param::separation);
/// the plain fit winds the map around two vertices next to a cone, the fit
/// with stiffer faces around singular points does not: nothing flips or
/// winds, every cone on its grid point.
#[test]
fn fandisk_sharp_60_3000_quads() {
    assert_eq!(run("fandisk.obj", Some(60.0), 3000), (0, 0));
}

/// At a coarse grid the moves of `separate` and `uncollapse` run (spot at
/// 1 000 quads): the forms they move others by stay at their integers.
#[test]
fn spot_1000_quads_keep_their_integers() {
    let input = load("spot.obj");
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(1000), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert!(r.moved_integers + r.separation_moves > 0, "no move ran: {r:?}");
    assert_eq!((r.conflicts, r.flipped), (0, 0), "{r:?}");
    assert!(r.integer_residual < 1e-9, "{r:?}");
    let (flipped, _) = check_integer_grid("spot.obj", &solution.mesh, &features, &map.uv);
    assert_eq!(flipped, 0);
}

/// A scan much finer than its cells (bff-face, 34 k faces, at 1 000 quads:
/// a cell spans about four edges): each rounded cone drags the uniform fit
/// along as a spike, which folds its ring or winds the map around it (63
/// wound vertices after the plain rounding). The polish's local stiffening
/// spreads the spikes; without it, seven passes over 100 s still left six
/// wound vertices.
#[test]
fn a_fine_scan_at_coarse_quads_is_stiffened_where_its_cones_spike() {
    let input = load("bff-face.obj");
    let features = FeatureSet::none(&input);
    let options = SolveOptions::default().for_quads(&input, GridSize::Quads(1000));
    let solution = solve(&input, &features, &options, &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(1000), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert!(r.stiffening > 0, "the case this tests is gone: {r:?}");
    assert_eq!((r.flipped, r.wound_vertices, r.conflicts), (0, 0, 0), "{r:?}");
    assert!(r.integer_residual < 1e-9 && r.distortion_after < 1.5 * r.distortion_before, "{r:?}");
    assert_eq!(check_integer_grid("bff-face", &solution.mesh, &features, &map.uv), (0, 0));
}

/// Spot subdivided twice (93 k faces, a cell spanning about six edges) at
/// 1 300 quads: the plain fit's rounded points drag their rings along as
/// spikes that wind the map around them, which its local stiffening does
/// not mend; the graded fit keeps them flat and the map is clean.
#[test]
fn a_mesh_much_finer_than_its_cells_is_rounded_with_the_graded_fit() {
    use conemap::mesh::subdivide_midpoint;
    let raw = subdivide_midpoint(&subdivide_midpoint(&common::shared_raw("spot.obj")));
    let input = TriMesh::from_raw(&raw).unwrap();
    let features = FeatureSet::none(&input);
    let options = SolveOptions::default().for_quads(&input, GridSize::Quads(1300));
    let solution = solve(&input, &features, &options, &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(1300), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert!(r.graded_fit, "the case this tests is gone: {r:?}");
    assert_eq!((r.flipped, r.wound_vertices, r.conflicts), (0, 0, 0), "{r:?}");
    assert!(r.integer_residual < 1e-9 && r.distortion_after < 1.8 * r.distortion_before, "{r:?}");
    assert_eq!(check_integer_grid("spot x16", &solution.mesh, &features, &map.uv), (0, 0));
}

#[test]
fn bunny_1000_quads() {
    assert_eq!(run("bff-bunny.obj", None, 1000), (0, 0));
}

/// Extracts and checks the quad mesh of `name`'s integer-grid map at about
/// `n` quads: no defect, the input's Euler characteristic, boundary loops
/// and one component, pure valid quads as many as the map's cells, within
/// 1 % of the input both ways, every sharp edge on quad edges, at most
/// `max_degenerate` degenerate quads (a bow-tie in 3D). Returns the
/// report and the solution's cones by valence `4 - k`.
fn quad_mesh(name: &str, sharp: Option<f64>, n: usize, max_degenerate: usize) -> (conemap::quads::QuadReport, std::collections::BTreeMap<u32, usize>) {
    use conemap::quads::{check_quads, extract_quads, CheckOptions, ExtractOptions};
    let input = load(name);
    let features = sharp.map_or_else(|| FeatureSet::none(&input), |deg| FeatureSet::sharp_edges(&input, deg));
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(n), &mut |_, _| {}).unwrap();
    let quads = extract_quads(&solution.mesh, &map.uv, &ExtractOptions::default()).unwrap();
    assert!(quads.defects.is_empty(), "{name}: {:?}", &quads.defects[..quads.defects.len().min(5)]);
    let sharp_edges: Vec<u32> = solution.features.edges().collect();
    let r = check_quads(&solution.mesh, &quads, &CheckOptions { sharp_edges: &sharp_edges, ..CheckOptions::default() });
    let chi = solution.mesh.n_vertices() as i64 - solution.mesh.n_edges() as i64 + solution.mesh.n_faces() as i64;
    let loops = solution.mesh.boundary_loops().len();
    assert_eq!((r.euler_characteristic, r.boundary_loops, r.components), (chi, loops, 1), "{name}");
    assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.flipped_quads), (0, 0, 0), "{name}");
    assert!(r.degenerate_quads <= max_degenerate, "{name}: {} degenerate quads", r.degenerate_quads);
    assert!((r.quads as f64 - map.report.cells).abs() < 1.0, "{name}: {} quads, {} cells", r.quads, map.report.cells);
    assert!(r.distance_quads_to_input_relative.unwrap() < 0.01 && r.distance_input_to_quads_relative.unwrap() < 0.01, "{name}: {r:?}");
    if !sharp_edges.is_empty() {
        assert_eq!(r.fraction_sharp_within_tolerance, Some(1.0), "{name}: sharp edges off the quad edges");
    }
    let mut cones = std::collections::BTreeMap::new();
    for c in &solution.placement.cones {
        *cones.entry((4 - c.k) as u32).or_default() += 1;
    }
    (r, cones)
}

/// The quad mesh of spot's integer-grid map: closed, Euler characteristic
/// 2, pure valid quads, singular vertices exactly the cones with valence
/// `4 - k`, on the surface.
#[test]
fn spot_quad_mesh() {
    let (r, cones) = quad_mesh("spot.obj", None, 3000, 0);
    let found: std::collections::BTreeMap<u32, usize> = r.valence_histogram.interior.iter().filter(|(&v, _)| v != 4).map(|(&v, &n)| (v, n)).collect();
    assert_eq!(found, cones);
    assert!(r.angle_mean_deviation < 7.1, "mean corner-angle deviation {}", r.angle_mean_deviation);
}

/// Fandisk with its creases (> 60°) at 10 000 quads and alligator with its
/// boundary at 3 000 give closed-up
/// quad meshes with the input's topology (known shortfall, docs/STATUS.md:
/// fandisk at 3 000 still winds around two vertices, and at 10 000 one quad
/// is a bow-tie in 3D).
#[test]
fn feature_and_boundary_quad_meshes() {
    let (r, _) = quad_mesh("fandisk.obj", Some(60.0), 10000, 1);
    assert!(r.angle_mean_deviation < 10.1, "fandisk: mean corner-angle deviation {}", r.angle_mean_deviation);
    quad_mesh("alligator.obj", None, 3000, 0);
}

/// Where the plain fit folds or winds the map next to cones (fandisk > 60°
/// at 3 000 quads, spot at 1 000), the stiffer fit around singular points
/// gives a valid map: nothing flips or winds, and fandisk's quad mesh has
/// no defect and its singular vertices are exactly the interior cones.
#[test]
fn stiffer_fit_around_cones_mends_coarse_grids() {
    assert_eq!(run("spot.obj", None, 1000), (0, 0));
    let (r, _) = quad_mesh("fandisk.obj", Some(60.0), 3000, 0);
    assert!(r.angle_mean_deviation < 7.0, "fandisk: mean corner-angle deviation {}", r.angle_mean_deviation);
}

/// Where the map winds twice around a point with no flipped triangle (the
/// cow at 1 400 quads, at 1 500 until tube periods were kept three steps
/// around; spot > 40° at 3 000 until the rounding's local
/// stiffening, fandisk > 60° at 1 000 until the held pass widened its
/// rows), the extractor
/// closes the mesh instead of leaving holes: each cell traced around twice
/// becomes quads around an input vertex, and the quad mesh is closed,
/// manifold, one piece, with the input's Euler characteristic; the report
/// says where.
#[test]
fn cells_the_map_winds_around_are_closed_with_quads() {
    use conemap::quads::{check_quads, extract_quads, CheckOptions, ExtractOptions};
    let input = load("cow.obj");
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(1400), &mut |_, _| {}).unwrap();
    assert_eq!(map.report.flipped, 0, "{:?}", map.report);
    assert!(map.report.wound_vertices > 0, "the case this tests is gone: {:?}", map.report);
    let quads = extract_quads(&solution.mesh, &map.uv, &ExtractOptions::default()).unwrap();
    assert!(!quads.defects.is_empty());
    for d in &quads.defects {
        assert!(d.what.contains("winds around") && !d.what.contains("skipped"), "{d:?}");
    }
    let r = check_quads(&solution.mesh, &quads, &CheckOptions::default());
    assert_eq!((r.euler_characteristic, r.boundary_loops, r.components), (solution.mesh.euler_characteristic(), 0, 1), "{r:?}");
    assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.unreferenced_vertices), (0, 0, 0), "{r:?}");
    assert_eq!(quads.uv.len(), 4 * quads.quads.len());
    // Half the quads the 1 % target is set for (3 000): under 1.5 % here.
    assert!(r.distance_input_to_quads_relative.unwrap() < 0.015, "{r:?}");
}

/// The same quantizer serves a second grid size (the page re-runs only this
/// stage when the quad count changes).
#[test]
fn quantizer_reruns_for_another_size() {
    let input = load("spot.obj");
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let quantizer = solution.quantizer().unwrap();
    for n in [2000, 10000] {
        let map = quantizer.quantize(&solution.mesh, GridSize::Quads(n), &mut |_, _| {}).unwrap();
        assert_eq!(map.report.conflicts, 0);
        assert_eq!(check_integer_grid("spot.obj", &solution.mesh, &features, &map.uv), (0, 0));
    }
    assert!(quantizer.quantize(&solution.mesh, GridSize::Length(-1.0), &mut |_, _| {}).is_err());
}


/// The cow without features at 1 200 quads: the rounding at the asked grid
/// length folds the map; with a quad count the quantizer also rounds at
/// grid lengths a few percent off and keeps the map with fewer flips (here
/// none; it still winds around a few vertices), while an explicit length is
/// kept exactly. (Its quad mesh is not clean: a thin part the rule of
/// tube periods does not see, docs/STATUS.md, splits it in two. The cow
/// at 2 000 quads was the case until tube periods were kept three steps
/// around: now clean at the asked length; spot at `--sharp 40`, 1 500
/// quads, until the held pass widened its rows.)
#[test]
fn nearby_grid_sizes_mend_a_folding_rounding() {
    let input = load("cow.obj");
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let quantizer = solution.quantizer().unwrap();
    let s = quantizer.grid_length(GridSize::Quads(1200)).unwrap();
    let exact = quantizer.quantize(&solution.mesh, GridSize::Length(s), &mut |_, _| {}).unwrap();
    assert_eq!(exact.report.grid_size, s);
    assert!(exact.report.flipped > 0, "the case this tests is gone: {:?}", exact.report);
    let count = quantizer.quantize(&solution.mesh, GridSize::Quads(1200), &mut |_, _| {}).unwrap();
    let r = &count.report;
    assert!(r.flipped < exact.report.flipped, "{} flipped, {} at the asked length", r.flipped, exact.report.flipped);
    assert!(r.grid_size != s && (r.grid_size / s - 1.0).abs() <= 0.031, "grid {} against {s}", r.grid_size);
    assert_eq!((r.conflicts, r.flipped, r.periods_violated), (0, 0, 0), "{r:?}");
    let (flipped, off_grid) = check_integer_grid("cow", &solution.mesh, &solution.features, &count.uv);
    assert!(flipped == 0 && off_grid <= r.wound_vertices, "{flipped} flipped, {off_grid} off the grid: {r:?}");
}

/// A CAD kernel's cylinder (one band of long triangles around, caps of
/// long, thin strips): solved as given, its quads had far skewed corners
/// and singular vertices of valence 2 and 7 while the caps' corners were
/// bunched (now spread around the circles: clean, mean deviation 6°);
/// solved on the refinement a quad mesh asks for (`RefineOptions::for_quads`:
/// edges split to 5 % of the diagonal, coplanar triangles flipped to
/// Delaunay), they are clean and close to square too, and still on the
/// surface (the refinement does not move it) and its features, rim corners
/// included.
#[test]
fn a_low_poly_cad_cylinder_is_refined_for_quads() {
    use conemap::pipeline::RefineOptions;
    use conemap::quads::{check_quads, extract_quads, extract_quads_along, CheckOptions, ExtractOptions};
    let input = TriMesh::from_raw(&conemap::mesh::shapes::cad_cylinder(24, 2.0)).unwrap();
    let features = FeatureSet::sharp_edges(&input, 60.0);
    let solve_with = |refine: RefineOptions| {
        let solution = solve(&input, &features, &SolveOptions { refine, ..SolveOptions::default() }, &mut |_| {}).unwrap();
        let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(1000), &mut |_, _| {}).unwrap();
        (solution, map.uv)
    };
    let report = |solution: &conemap::pipeline::Solution, quads: &conemap::quads::QuadMesh| {
        let sharp: Vec<u32> = solution.features.edges().collect();
        check_quads(&solution.mesh, quads, &CheckOptions { sharp_edges: &sharp, ..CheckOptions::default() })
    };
    let (plain, uv) = solve_with(RefineOptions::default());
    let before = report(&plain, &extract_quads_along(&plain.mesh, &plain.features, &uv, &ExtractOptions::default()).unwrap());
    let far_singular = |r: &conemap::quads::QuadReport| r.singular_vertices.iter().filter(|v| !(3..=5).contains(&v.valence)).count();
    assert!(before.angle_mean_deviation < 8.0 && far_singular(&before) == 0, "{before:?}");
    let (refined, uv) = solve_with(RefineOptions::for_quads(&input, GridSize::Quads(1000)));
    let counts = refined.refinement;
    assert!(counts.long_edges > 0 && counts.coplanar_flips > 0, "{counts:?}");
    assert!(refined.mesh.n_faces() < 40 * input.n_faces(), "{} faces", refined.mesh.n_faces());
    let quads = extract_quads_along(&refined.mesh, &refined.features, &uv, &ExtractOptions::default()).unwrap();
    let after = report(&refined, &quads);
    assert_eq!((quads.defects.len(), after.flipped_quads, after.degenerate_quads, after.non_manifold_edges), (0, 0, 0, 0), "{after:?}");
    assert_eq!((after.euler_characteristic, after.boundary_loops), (2, 0));
    assert!(after.angle_mean_deviation < 8.0 && far_singular(&after) == 0, "{after:?}");
    let (split, plain) = (refined.param.metrics.distortion, plain.param.metrics.distortion);
    assert!(split < plain, "distortion {split} refined, {plain} as given");
    assert!(after.distance_quads_to_input_relative.unwrap() < 0.01 && after.distance_input_to_quads_relative.unwrap() < 0.01, "{after:?}");
    assert_eq!(after.fraction_sharp_within_tolerance, Some(1.0), "{after:?}");
    // Without the slide onto the rims' polygon corners the quads are the
    // same. (Their edges cut the rims' corners while the caps' corners were
    // bunched; with them spread, the plain extraction follows the rims here
    // too, so this mesh no longer shows what the slide mends.)
    let uncornered = report(&refined, &extract_quads(&refined.mesh, &uv, &ExtractOptions::default()).unwrap());
    assert_eq!((uncornered.quads, uncornered.euler_characteristic), (after.quads, 2));
}

/// A CAD kernel's gear (`tests/fixtures/cad/gear.obj`: 288 long, thin
/// triangles) solved for an integer-grid map as `solve --quads` solves it:
/// where the grid map of the input's triangles folds, `pipeline::grid_map`
/// solves again on the refinement a quad mesh of that grid keeps, and its
/// map has no flipped triangle, winds around no vertex and is an integer
/// grid.
#[test]
fn a_low_poly_cad_grid_map_is_solved_again_where_it_folds() {
    use conemap::pipeline::{grid_map, GridFeatures, LongEdges};
    let input = common::fixture_mesh("cad/gear.obj");
    let features = FeatureSet::sharp_edges(&input, 60.0);
    let quantize = QuantizeOptions { retry_wound: true, ..QuantizeOptions::default() };
    let mut folded_on_input = 0;
    for quads in [2000, 3000, 4000] {
        let name = format!("gear at {quads} quads");
        let options = SolveOptions::default().for_quads(&input, GridSize::Quads(quads));
        let solution = solve(&input, &features, &options, &mut |_| {}).unwrap();
        let first = solution.quantizer().unwrap().quantize_with(&solution.mesh, GridSize::Quads(quads), &quantize, &mut |_, _| {}).unwrap();
        let input_faults = first.report.flipped + first.report.wound_vertices;
        folded_on_input += usize::from(input_faults > 0);
        let mapped = grid_map(&input, &GridFeatures::asked(&input, features.clone()), &options, solution, GridSize::Quads(quads), &quantize, LongEdges::RefineWhereFolded, &mut |_| {}, &mut |_, _| {}).unwrap();
        let (r, mesh) = (&mapped.map.report, &mapped.solution.mesh);
        assert_eq!((r.flipped, r.wound_vertices), (0, 0), "{name}: {r:?}");
        assert_eq!(mesh.n_faces() > input.n_faces(), input_faults > 0, "{name}: solved again exactly where the input's map folds");
        let (flipped, off_grid) = check_integer_grid(&name, mesh, &mapped.solution.features, &mapped.map.uv);
        assert_eq!((flipped, off_grid), (0, 0), "{name}");
    }
    assert!(folded_on_input > 0, "the input's own grid map no longer folds at any count: this test no longer exercises the second solve");
}

/// The teapot with its creases above 60° at 3 000 quads, solved as `quads`
/// solves it: its one crease, the spout's lip (4 edges, 1.9 cells, half a
/// turn), puts three +1 cones within half a cell and the grid map winds
/// around vertices. `pipeline::grid_map` solves again without the curves
/// finer than the grid (`features::finer_than_grid`) and keeps that map:
/// no fold, an integer grid, the lip no feature of it.
#[test]
fn feature_curves_finer_than_the_grid_are_dropped_where_they_fold_the_map() {
    use conemap::features::finer_than_grid;
    use conemap::pipeline::{quad_length, GridFeatures, GridStage, LongEdges};
    let (input, features, size, options, solution) = solved_with_sharp_features("teapot.obj", 60.0, 3000);
    let first = solution.quantizer().unwrap().quantize(&solution.mesh, size, &mut |_, _| {}).unwrap();
    assert!(first.report.folds() > 0, "the map with the lip no longer folds: this test no longer exercises the fallback");
    let finer = finer_than_grid(&input, &features, quad_length(&input, size));
    assert_eq!((features.len(), finer.len()), (4, 4), "the lip is the one crease, and finer than the grid");
    let mut stage = GridStage::new(solution, GridFeatures::asked(&input, features.clone()), options, LongEdges::RefineFirst);
    let mut solves = 0;
    let mapped = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| solves += 1, &mut |_, _| {}).unwrap();
    assert!(solves > 0, "solved again without the lip");
    assert_eq!(mapped.dropped_features, finer);
    let (r, sol) = (&mapped.map.report, mapped.solution);
    assert_eq!((r.flipped, r.wound_vertices), (0, 0), "{r:?}");
    assert!(sol.features.is_empty() && sol.solved_edges_of(&finer).len() >= 4, "solved without the lip, which is still found on the solved mesh");
    assert_eq!(check_integer_grid("teapot >60° without its lip", &sol.mesh, &sol.features, &mapped.map.uv), (0, 0));
    // The page's slider back at this count: the map without the lip is kept, not solved again.
    let uv = mapped.map.uv.clone();
    let mut solves = 0;
    let again = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| solves += 1, &mut |_, _| {}).unwrap();
    assert_eq!((solves, &again.dropped_features, &again.map.uv), (0, &finer, &uv));
}

/// Shared mesh `name`, its edges above `degrees` as asked features, the
/// grid of about `quads` quads, and the settings and map `quads` solves
/// them with.
fn solved_with_sharp_features(name: &str, degrees: f64, quads: usize) -> (TriMesh, FeatureSet, GridSize, SolveOptions, conemap::pipeline::Solution<'static>) {
    use conemap::pipeline::RefineOptions;
    let input = load(name);
    let features = FeatureSet::sharp_edges(&input, degrees);
    let size = GridSize::Quads(quads);
    let options = SolveOptions { refine: RefineOptions::for_quads(&input, size), ..SolveOptions::default() }.for_quads(&input, size);
    let solution = solve(&input, &features, &options, &mut |_| {}).unwrap().into_owned();
    (input, features, size, options, solution)
}

/// The grid stage of shared mesh `name` solved with the creases
/// `conemap quads` finds (`features::CREASES`, as detected creases) for
/// about `quads` quads, whose map with them folds (asserted).
fn stage_with_folding_creases(name: &str, quads: usize) -> (TriMesh, FeatureSet, conemap::pipeline::GridStage, GridSize) {
    use conemap::features::{detect_sharp, CREASES};
    use conemap::pipeline::{GridFeatures, GridStage, LongEdges, RefineOptions};
    let input = load(name);
    let creases = detect_sharp(&input, &CREASES).features;
    let size = GridSize::Quads(quads);
    let options = SolveOptions { refine: RefineOptions::for_quads(&input, size), ..SolveOptions::default() }.for_quads(&input, size);
    let solution = solve(&input, &creases, &options, &mut |_| {}).unwrap();
    let first = solution.quantizer().unwrap().quantize(&solution.mesh, size, &mut |_, _| {}).unwrap();
    assert!(first.report.folds() > 0, "{name}: the map with the creases no longer folds: the test no longer exercises the fallback");
    let stage = GridStage::new(solution, GridFeatures::detected(creases.clone()), options, LongEdges::RefineFirst);
    (input, creases, stage, size)
}

/// Creases found for a caller that gave no features (`features::CREASES`,
/// as `quads` finds them) are dropped on the components where they fold
/// the map: cow's 32 edges above 75° on long curves (ears, horns) fold its
/// map at 1 000 quads, and so does the map without only the chains next to
/// its folds, so it is solved again without any of them, with no fold.
/// (`pipeline::grid`'s unit test: a fold marks its own component's.)
#[test]
fn detected_creases_are_dropped_where_they_fold_the_map() {
    let (input, creases, mut stage, size) = stage_with_folding_creases("cow.obj", 1000);
    assert_eq!(creases.len(), 32);
    let mapped = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    assert_eq!(mapped.dropped_features, creases, "every detected crease goes");
    let (r, sol) = (&mapped.map.report, mapped.solution);
    assert_eq!((r.flipped, r.wound_vertices), (0, 0), "{r:?}");
    assert!(sol.features.is_empty());
    assert_eq!(check_integer_grid("cow without its creases", &sol.mesh, &sol.features, &mapped.map.uv), (0, 0));
    // The page's slider back at this count: both maps solved again (without
    // the creases by the folds, and without all) are kept, none solved again.
    let uv = mapped.map.uv.clone();
    let mut solves = 0;
    let again = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| solves += 1, &mut |_, _| {}).unwrap();
    assert_eq!((solves, &again.dropped_features, &again.map.uv), (0, &creases, &uv));
}

/// Where a CAD part's creases fold the map only in places, only their
/// chains next to the folds go: fandisk's 693 crease edges fold its map at
/// 1 000 quads; without the 42 next to the folds it does not (before, all
/// 693 went and the quads lay 2.19 % of the diagonal from the input; now
/// 1.02 %, 92.8 % of the crease samples within 0.2 %).
#[test]
fn detected_creases_go_only_next_to_the_folds_where_that_unfolds_the_map() {
    let (input, creases, mut stage, size) = stage_with_folding_creases("fandisk.obj", 1000);
    assert_eq!(creases.len(), 693);
    let mapped = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    let dropped = &mapped.dropped_features;
    assert!(!dropped.is_empty() && dropped.len() < creases.len() / 4, "{} of {} creases dropped", dropped.len(), creases.len());
    assert!(dropped.edges().all(|e| creases.contains(e)));
    let (r, sol) = (&mapped.map.report, mapped.solution);
    assert_eq!((r.flipped, r.wound_vertices), (0, 0), "{r:?}");
    assert_eq!(sol.solved_edges_of(&creases.without(dropped)).len(), sol.features.len(), "the map follows the other creases");
    assert_eq!(check_integer_grid("fandisk without the creases by its folds", &sol.mesh, &sol.features, &mapped.map.uv), (0, 0));
}

/// Asked features go too where the map still folds without the curves
/// finer than the grid: cow with its 302 edges above 60° (noise on an
/// organic surface) at 3 000 quads folds with the 194 left after those
/// (190 faults after the plain pass; 18 defect places in the quads before);
/// without their chains next to the folds as well it does not, and it
/// follows the rest.
#[test]
fn asked_features_go_next_to_the_folds_where_the_map_still_folds() {
    use conemap::features::finer_than_grid;
    use conemap::pipeline::{quad_length, GridFeatures, GridStage, LongEdges};
    let (input, features, size, options, solution) = solved_with_sharp_features("cow.obj", 60.0, 3000);
    let mut stage = GridStage::new(solution, GridFeatures::asked(&input, features.clone()), options, LongEdges::RefineFirst);
    let mapped = stage.map(&input, size, &QuantizeOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    let finer = finer_than_grid(&input, &features, quad_length(&input, size));
    let dropped = &mapped.dropped_features;
    assert_eq!(features.len(), 302);
    assert!(dropped.len() > finer.len() && dropped.len() < features.len(), "{} dropped: more than the {} finer than the grid, not all", dropped.len(), finer.len());
    assert!(finer.edges().all(|e| dropped.contains(e)));
    let (r, sol) = (&mapped.map.report, mapped.solution);
    assert_eq!((r.flipped, r.wound_vertices), (0, 0), "{r:?}");
    assert_eq!(sol.solved_edges_of(&features.without(dropped)).len(), sol.features.len(), "the map follows the other features");
    assert_eq!(check_integer_grid("cow >60° without the features by its folds", &sol.mesh, &sol.features, &mapped.map.uv), (0, 0));
}

/// A feature curve that ends inside the surface is an isoline running on
/// through its end, so only its constant is an integer: with the end's
/// other coordinate an integer too, a curve shorter than a cell had its
/// two ends squeezed onto one grid point or stretched a cell apart (on this
/// sheet with creases of one and two edges, a fifth of a cell and less, the
/// distortion rose from 0.018 to 0.068 at 300 quads; it is 0.028 now).
#[test]
fn feature_curves_that_end_inside_a_cell_are_not_stretched_to_it() {
    let n = 96;
    let raw = conemap::mesh::shapes::grid(n, n, |x, y| [x, y, 0.15 * (3.0 * x).sin() * (2.0 * y).cos()]);
    let sheet = TriMesh::from_raw(&raw).unwrap();
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut creases = Vec::new();
    for (i, j, di, dj, length) in [(21, 25, 1, 0, 2), (61, 41, 0, 1, 1), (41, 69, 1, 0, 1), (73, 73, 0, 1, 2), (29, 57, 1, 0, 1), (50, 50, 1, 1, 1)] {
        for k in 0..length {
            let (a, b) = (id(i + di * k, j + dj * k), id(i + di * (k + 1), j + dj * (k + 1)));
            creases.push([raw.positions[a], raw.positions[b]]);
        }
    }
    let features = FeatureSet::from_positions(&sheet, &creases).unwrap();
    assert_eq!(features.len(), 8);
    let solution = solve(&sheet, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(300), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert_eq!((r.conflicts, r.flipped, r.wound_vertices), (0, 0, 0), "{r:?}");
    assert!(r.distortion_after < 2.0 * r.distortion_before, "{r:?}");
    assert_eq!(check_integer_grid_counting_cones("creased sheet", &solution.mesh, &solution.features, &map.uv), (0, 0, 0));
}

/// A game asset of 56 parts (xatlas's gazebo sample), each quantized on its
/// own: many parts are planks and boxes thinner than a cell, whose eight
/// corner cones the rounding put on one grid line across the thin side;
/// moving one integer at a time could not part them (each move broke the
/// neighbouring pairs). With its edges sharper than 60° as features, at
/// 3 000 quads, several boxes are clean only in the pass that holds the
/// violated separations as rows of the relaxed map; without features, at
/// 3 000 and 1 000 quads, every part rounds cleanly.
#[test]
fn parts_thinner_than_a_cell_are_held_apart() {
    let input = load("xatlas-gazebo.obj");
    for (sharp, quads) in [(Some(60.0), 3000), (None, 3000), (None, 1000)] {
        let features = sharp.map_or_else(|| FeatureSet::none(&input), |deg| FeatureSet::sharp_edges(&input, deg));
        let solution = solve(&input, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
        let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(quads), &mut |_, _| {}).unwrap();
        let r = &map.report;
        assert!(sharp.is_none() || r.separations_held > 0, "the case this tests is gone: {r:?}");
        assert_eq!((r.conflicts, r.flipped, r.wound_vertices), (0, 0, 0), "{quads}: {r:?}");
        let (flipped, off_grid, _) = check_integer_grid_counting_cones("xatlas-gazebo", &solution.mesh, &solution.features, &map.uv);
        assert_eq!((flipped, off_grid), (0, 0), "{sharp:?} {quads}");
    }
}

/// An open tube 2.3 cells around and 8 cells long: the seam translation
/// around it is its circumference, and rounded to the nearest integer (2)
/// it put two quads around the tube on the same four vertices (Euler
/// characteristic 9 instead of 0, 7 non-manifold edges). Kept at three
/// steps or more, the quad mesh is an open tube of 3 by 8 quads.
#[test]
fn a_tube_is_kept_three_grid_steps_around() {
    use conemap::quads::{check_quads, extract_quads, CheckOptions, ExtractOptions};
    let s = 2.0 * PI / 2.3;
    let raw = conemap::mesh::shapes::grid(24, 84, |u, v| {
        let a = if u == 1.0 { 0.0 } else { 2.0 * PI * u };
        [a.cos(), a.sin(), 8.0 * s * v]
    });
    let tube = TriMesh::from_raw(&raw).unwrap();
    let features = FeatureSet::none(&tube);
    let solution = solve(&tube, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Length(s), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert_eq!((r.tube_periods, r.periods_violated, r.flipped, r.conflicts), (1, 0, 0, 0), "{r:?}");
    assert!(r.period_moves > 0, "the case this tests is gone: {r:?}");
    let quads = extract_quads(&solution.mesh, &map.uv, &ExtractOptions::default()).unwrap();
    assert!(quads.defects.is_empty(), "{:?}", quads.defects);
    let q = check_quads(&solution.mesh, &quads, &CheckOptions::default());
    assert_eq!((q.quads, q.euler_characteristic, q.boundary_loops, q.non_manifold_edges, q.flipped_quads), (24, 0, 2, 0, 0), "{q:?}");
}

/// A boundary vertex lies on an isoline, so its UV angle changes only by
/// quarter turns; bff's punctured torus at 1 000 quads (solved as `quads`
/// solves it) rounded a straight boundary vertex to a full turn, a hairpin
/// whose two sides overlap on the isoline, and the next boundary vertex to
/// a corner: two quad vertices at one grid point, traces that did not come
/// back, 9 defect places. Counted as a vertex the map winds around, the
/// fold sends the rounding on to the passes that mend it: no defect.
#[test]
fn a_boundary_folded_back_on_its_isoline_is_a_fault() {
    use conemap::pipeline::RefineOptions;
    use conemap::quads::{check_quads, extract_quads, CheckOptions, ExtractOptions};
    let input = load("bff-punctured-torus.obj");
    let grid = GridSize::Quads(1000);
    let mut options = SolveOptions::default();
    options.refine.max_edge_length = RefineOptions::for_quads(&input, grid).max_edge_length;
    let options = options.for_quads(&input, grid);
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &options, &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, grid, &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert_eq!((r.flipped, r.wound_vertices, r.conflicts), (0, 0, 0), "{r:?}");
    let quads = extract_quads(&solution.mesh, &map.uv, &ExtractOptions::default()).unwrap();
    assert!(quads.defects.is_empty(), "{:?}", quads.defects);
    let q = check_quads(&solution.mesh, &quads, &CheckOptions::default());
    assert_eq!((q.euler_characteristic, q.boundary_loops, q.non_manifold_edges, q.flipped_quads), (-1, 1, 0, 0), "{q:?}");
}

/// One of the asset's braces alone (a slanted box 0.22 by 0.9 by 0.7, its
/// edges sharper than 60° as features), turned and moved to twelve places,
/// at grid lengths 0.20 to 0.29: the box is thinner than a cell, and its
/// seams add the gaps of two held pairs into a third, so with every held
/// row at one line the third's row is dependent and its pair lands on one
/// grid line (4 of the 120 maps folded). Widening a held row by a line
/// parts all three.
#[test]
fn held_rows_widen_where_seams_add_their_gaps() {
    let brace: [[f64; 3]; 8] = [
        [13.425371, 0.112689, -0.746624],
        [13.582747, 1.00861, -0.057324],
        [13.401802, 1.00861, -0.057324],
        [13.622736, 0.336135, -0.765051],
        [13.582747, 1.00861, -0.23827],
        [13.425371, 0.336135, -0.746624],
        [13.401802, 1.00861, -0.23827],
        [13.622736, 0.112689, -0.765051],
    ];
    let triangles: Vec<[u32; 3]> = [[1, 2, 3], [2, 4, 5], [5, 6, 7], [6, 3, 7], [6, 8, 1], [3, 5, 7], [1, 8, 2], [2, 8, 4], [5, 4, 6], [6, 1, 3], [6, 4, 8], [3, 2, 5]]
        .iter()
        .map(|t| t.map(|i| i - 1))
        .collect();
    let mut widened = 0;
    for place in 0..12 {
        let a = [0.7 * place as f64, 1.3 * place as f64 + 0.4, 2.1 * place as f64 + 0.9];
        let turn = |p: [f64; 3]| {
            let (c, s) = (a[0].cos(), a[0].sin());
            let p = [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]];
            let (c, s) = (a[1].cos(), a[1].sin());
            let p = [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]];
            let (c, s) = (a[2].cos(), a[2].sin());
            [c * p[0] - s * p[1] + 3.0 * place as f64, s * p[0] + c * p[1] - 1.7 * place as f64, p[2] + 0.37]
        };
        let mesh = TriMesh::from_welded_arrays(brace.iter().map(|&p| turn(p)).collect(), triangles.clone()).unwrap();
        let features = FeatureSet::sharp_edges(&mesh, 60.0);
        let solution = solve(&mesh, &features, &SolveOptions::default(), &mut |_| {}).unwrap();
        let quantizer = solution.quantizer().unwrap();
        for step in 0..10 {
            let grid = 0.20 + 0.01 * step as f64;
            let map = quantizer.quantize(&solution.mesh, GridSize::Length(grid), &mut |_, _| {}).unwrap();
            let r = &map.report;
            assert_eq!((r.conflicts, r.flipped, r.separations_violated), (0, 0, 0), "place {place}, grid {grid}: {r:?}");
            let (flipped, off_grid, _) = check_integer_grid_counting_cones("brace", &solution.mesh, &solution.features, &map.uv);
            assert_eq!((flipped, off_grid), (0, 0), "place {place}, grid {grid}");
            widened += (r.separations_widened > 0) as usize;
        }
    }
    assert!(widened > 0, "the case this tests is gone");
}

/// A scene of sixteen copies of the asset in a row: its diagonal is 16
/// times the asset's, its quads too, so 5 % of the diagonal kept edges of
/// 8 quads (287 defects, Euler characteristic off by 14); the refinement
/// for quads also splits edges longer than `QUAD_MAX_EDGE_QUADS` quads,
/// and the quad mesh is closed with every copy's topology.
#[test]
fn a_scene_of_copies_is_refined_by_its_quads() {
    use conemap::pipeline::{RefineOptions, QUAD_MAX_EDGE, QUAD_MAX_EDGE_QUADS};
    use conemap::quads::{check_quads, extract_quads_along, CheckOptions, ExtractOptions};
    let input = common::side_by_side(&["xatlas-gazebo.obj"; 16]);
    let grid = GridSize::Quads(16 * 3000);
    let refine = RefineOptions::for_quads(&input, grid);
    let area: f64 = input.face_areas().iter().sum();
    let quad = (area / 48_000.0).sqrt();
    assert_eq!(refine.max_edge_length, Some(QUAD_MAX_EDGE_QUADS * quad));
    assert!(QUAD_MAX_EDGE * input.bounding_diagonal() > 2.0 * QUAD_MAX_EDGE_QUADS * quad, "the case this tests is gone");
    let features = FeatureSet::sharp_edges(&input, 60.0);
    let solution = solve(&input, &features, &SolveOptions { refine, ..SolveOptions::default() }, &mut |_| {}).unwrap();
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, grid, &mut |_, _| {}).unwrap();
    let quads = extract_quads_along(&solution.mesh, &solution.features, &map.uv, &ExtractOptions::default()).unwrap();
    assert!(quads.defects.is_empty(), "{} defects: {:?}", quads.defects.len(), &quads.defects[..quads.defects.len().min(3)]);
    let r = check_quads(&solution.mesh, &quads, &CheckOptions::default());
    assert_eq!((r.euler_characteristic, r.boundary_loops), (16 * 111, 16), "{r:?}");
}

/// The same asset on the refinement the quads ask for (edges split to 5 %
/// of the diagonal): three beams 0.58 cells thick kept a collapsed triangle
/// in every pass over the whole mesh, though each beam alone rounds cleanly
/// (a small part's forms fell into one batch of the whole and were rounded
/// without a solve between them). Each part is now rounded on its own.
#[test]
fn parts_round_as_they_would_alone() {
    use conemap::pipeline::RefineOptions;
    let input = load("xatlas-gazebo.obj");
    let features = FeatureSet::none(&input);
    let solution = solve(&input, &features, &SolveOptions { refine: RefineOptions::for_quads(&input, GridSize::Quads(3000)), ..SolveOptions::default() }, &mut |_| {}).unwrap();
    assert!(solution.mesh.n_faces() > 4 * input.n_faces(), "{} faces", solution.mesh.n_faces());
    let map = solution.quantizer().unwrap().quantize(&solution.mesh, GridSize::Quads(3000), &mut |_, _| {}).unwrap();
    let r = &map.report;
    assert_eq!((r.conflicts, r.flipped, r.wound_vertices), (0, 0, 0), "{r:?}");
    let (flipped, off_grid, _) = check_integer_grid_counting_cones("xatlas-gazebo refined", &solution.mesh, &solution.features, &map.uv);
    assert_eq!((flipped, off_grid), (0, 0));
}
