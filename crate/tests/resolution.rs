//! Resolution-stable cone placement (issue 13): the same surface at 4x and
//! 16x the faces (midpoint subdivision, and at 4x also with its vertices
//! moved within their tangent planes) is placed coarse to fine and gets about
//! the same cones and no worse a map. (Placed directly, spot x16 lost a
//! quarter of its cones and 38 % in distortion: 32 cones, 0.155.)

use conemap::features::FeatureSet;
use conemap::mesh::{subdivide_midpoint, RawMesh, TriMesh};
use conemap::pipeline::{solve, SolveOptions};
use conemap::vec3;

mod common;
use common::shared_raw as raw;

/// Moves every vertex by up to `amount` of its shortest incident edge along
/// a deterministic direction projected onto its tangent plane.
fn jitter(raw: &RawMesh, amount: f64) -> RawMesh {
    let n = raw.positions.len();
    let mut normal = vec![[0.0; 3]; n];
    let mut shortest = vec![f64::INFINITY; n];
    for t in &raw.triangles {
        let p = t.map(|v| raw.positions[v as usize]);
        let face_normal = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
        for k in 0..3 {
            let v = t[k] as usize;
            normal[v] = vec3::add(normal[v], face_normal);
            shortest[v] = shortest[v].min(vec3::norm(vec3::sub(p[(k + 1) % 3], p[k])));
        }
    }
    let mut out = raw.clone();
    for v in 0..n {
        let nn = vec3::scale(normal[v], 1.0 / vec3::norm(normal[v]).max(f64::MIN_POSITIVE));
        let s = v as f64 * 0.618_033_988_75;
        let d = [(s * 12.9898).sin(), (s * 78.233).sin(), (s * 37.719).sin()];
        let tangent = vec3::sub(d, vec3::scale(nn, vec3::dot(d, nn)));
        out.positions[v] = vec3::add(raw.positions[v], vec3::scale(tangent, amount * shortest[v]));
    }
    out
}

/// (cones, distortion) of a default solve, checking the map is fold-free.
fn place(label: &str, raw: &RawMesh) -> (usize, f64) {
    let mesh = TriMesh::from_raw(raw).expect("valid mesh");
    let none = FeatureSet::none(&mesh);
    let solution = solve(&mesh, &none, &SolveOptions::default(), &mut |_| {}).unwrap_or_else(|e| panic!("{label}: {e}"));
    let m = &solution.param.metrics;
    assert_eq!((m.flipped, m.wound_vertices), (0, 0), "{label}: folds");
    assert!(m.seam_angle_residual < 1e-9, "{label}: seam residual {}", m.seam_angle_residual);
    eprintln!("{label}: {} faces, {} cones, distortion {:.4}", mesh.n_faces(), m.cones, m.distortion);
    (m.cones, m.distortion)
}

#[test]
fn spot_at_4_and_16_times_the_faces_gets_about_the_same_cones_and_no_worse_map() {
    let coarse = raw("spot.obj");
    let (cones, distortion) = place("spot", &coarse);
    let fine = subdivide_midpoint(&coarse);
    let finer = subdivide_midpoint(&fine);
    for (label, mesh) in [("spot x4", fine.clone()), ("spot x4 jittered", jitter(&fine, 0.25)), ("spot x16", finer)] {
        let (c, d) = place(label, &mesh);
        assert!((c as f64 - cones as f64).abs() <= 0.25 * cones as f64, "{label}: {c} cones against {cones}");
        assert!(d <= 1.1 * distortion, "{label}: distortion {d} against {distortion}");
    }
}
