//! The command-line tool as a user runs it.

use std::process::{Command, Stdio};

mod common;

const FANDISK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../web/public/samples/fandisk.obj");

#[test]
fn info_counts_the_fandisk() {
    let out = Command::new(env!("CARGO_BIN_EXE_conemap")).args(["info", FANDISK, "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((report["vertices"].as_u64(), report["faces"].as_u64()), (Some(6475), Some(12946)));
}

#[test]
fn a_closed_standard_output_ends_the_tool_quietly() {
    // The reader goes away before anything is written (as `conemap info | head -0`).
    let mut child = Command::new(env!("CARGO_BIN_EXE_conemap"))
        .args(["info", FANDISK])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !stderr.contains("panicked"), "status {:?}, stderr: {stderr}", out.status);
}

#[test]
fn cones_refines_where_the_features_need_it_as_solve_does() {
    // At 20°, spot's creases include lone edges and doubly constrained
    // triangles: `cones` places on the same refined mesh as `solve`.
    let spot = common::shared_path("spot.obj");
    let out = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("cones").arg(&spot).args(["--sharp", "20", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let inserted = report["inserted_vertices"].as_u64().expect("inserted_vertices");
    assert!(inserted > 0, "spot at 20° needs refinement");
    assert_eq!(report["vertices"].as_u64(), Some(2930 + inserted), "cones are reported on the refined mesh");
    let k: i64 = ["cones", "boundary_corners"]
        .iter()
        .flat_map(|key| report[key].as_array().unwrap().iter().map(|c| c["k"].as_i64().unwrap()))
        .sum();
    assert_eq!(k, 4 * report["euler_characteristic"].as_i64().unwrap(), "Gauss-Bonnet on the refined mesh");
}

/// A `conemap quads` run on a shared mesh that succeeded: its scratch
/// directory (remove it when done), the quad OBJ, stdout and the report.
struct QuadsRun {
    dir: std::path::PathBuf,
    obj: std::path::PathBuf,
    stdout: String,
    report: serde_json::Value,
}

/// Runs `conemap quads` on `../shared/meshes/{mesh}.obj` with `args` (and
/// `--quiet --report`) into a scratch directory named after `tag`.
fn run_quads(mesh: &str, tag: &str, args: &[&str]) -> QuadsRun {
    let input = format!("{}/../../shared/meshes/{mesh}.obj", env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("conemap-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (obj, report) = (dir.join(format!("{mesh}-quads.obj")), dir.join(format!("{mesh}-quads.json")));
    let out = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("quads").arg(input).arg("-o").arg(&obj).args(args).args(["--quiet", "--report"]).arg(&report).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    QuadsRun { dir, obj, stdout: String::from_utf8_lossy(&out.stdout).into_owned(), report }
}

/// `conemap quads` writes a pure-quad OBJ with grid UVs and a report whose
/// figures agree with the file; `solve --grid` writes grid-unit UVs.
#[test]
fn quads_writes_a_quad_obj_and_its_report() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/spot.obj");
    let QuadsRun { dir, obj, report: json, .. } = run_quads("spot", "quads", &["--quads", "3000"]);
    let text = std::fs::read_to_string(&obj).unwrap();
    let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
    assert!(faces.iter().all(|f| f.split_whitespace().count() == 5), "a face that is not a quad");
    assert_eq!(json["quads"]["quads"].as_u64().unwrap() as usize, faces.len());
    assert_eq!(json["quads"]["euler_characteristic"], 2);
    assert!((faces.len() as f64 / 3000.0 - 1.0).abs() < 0.1, "{} quads", faces.len());

    let glb = dir.join("spot-grid.obj");
    let out = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("solve").arg(spot).arg("-o").arg(&glb).args(["--grid", "0.05", "--quiet"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&glb).unwrap();
    let vt: Vec<f64> = text.lines().filter(|l| l.starts_with("vt ")).flat_map(|l| l.split_whitespace().skip(1).map(|v| v.parse::<f64>().unwrap())).collect();
    assert!(vt.iter().any(|v| v.abs() > 2.0), "UVs look normalised, not in grid units");

    let bad = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("quads").arg(spot).arg("-o").arg(&obj).args(["--quads", "10", "--quad-size", "0.1"]).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
    // A maximum edge length far below the mesh's size is refused up front,
    // not refined until memory runs out.
    let tiny = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("quads").arg(spot).arg("-o").arg(&obj).args(["--max-edge", "0.01%"]).output().unwrap();
    assert_eq!(tiny.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&tiny.stderr).contains("would split the mesh into about"), "{}", String::from_utf8_lossy(&tiny.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// `conemap quads --sharp 60` on the teapot: the map with the spout's lip
/// (4 edges, under two quads) folds, so it is solved without it; stdout
/// says so, the report counts the 4 edges, and the sharp-edge figures still
/// measure them.
#[test]
fn quads_say_which_features_the_grid_could_not_follow() {
    let QuadsRun { dir, stdout, report: json, .. } = run_quads("teapot", "dropped", &["--sharp", "60"]);
    assert!(stdout.contains("solved without 4 feature edges"), "{stdout}");
    assert_eq!(json["dropped_feature_edges"], 4);
    assert_eq!(json["defects"].as_array().map(Vec::len), Some(0));
    assert!(json["quads"]["sharp_edges_checked"].as_u64().unwrap() >= 4);
    std::fs::remove_dir_all(&dir).ok();
}

/// `conemap quads` given no features follows a CAD part's creases
/// (`features::CREASES`: fandisk's 693 edges above 75°): the quads stay
/// within 1 % of the diagonal and have those edges on quad edges, and the
/// report and stdout say so; `--sharp none` cuts across them (over 1 %).
#[test]
fn quads_follow_a_cad_parts_creases_unless_told_not_to() {
    let distance = |q: &serde_json::Value| q["distance_input_to_quads_relative"].as_f64().unwrap().max(q["distance_quads_to_input_relative"].as_f64().unwrap());
    let auto = run_quads("fandisk", "creases", &[]);
    assert_eq!((&auto.report["detected_feature_edges"], &auto.report["dropped_feature_edges"]), (&693.into(), &0.into()));
    assert!(auto.stdout.contains("693 of 693 crease edges followed"), "{}", auto.stdout);
    let q = &auto.report["quads"];
    assert_eq!(auto.report["defects"].as_array().map(Vec::len), Some(0));
    assert!(distance(q) < 0.01, "{q}");
    assert!(q["fraction_sharp_within_tolerance"].as_f64().unwrap() > 0.99, "{q}");
    let none = run_quads("fandisk", "no-creases", &["--sharp", "none"]);
    assert_eq!(none.report["detected_feature_edges"], 0);
    assert!(distance(&none.report["quads"]) > 0.01, "creases cut across: {}", none.report["quads"]);
    for dir in [auto.dir, none.dir] {
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// `conemap quads` on a mesh much finer than its quads (bff-cowhead, 30 k
/// faces, at 1 000 quads) traces them on a decimation of about
/// `COARSE_FACES_PER_QUAD` faces per quad and moves them onto the input:
/// every vertex of the OBJ lies on an input triangle, the quads are clean
/// (the input's Euler characteristic and boundary loops, no flipped or
/// degenerate quad, the singular vertices the cones), and `--full-mesh`
/// solves on every face.
#[test]
fn quads_of_a_mesh_much_finer_than_its_quads_are_traced_on_a_decimation() {
    let input = common::shared_mesh("bff-cowhead.obj");
    let run = run_quads("bff-cowhead", "decimated", &["--quads", "1000"]);
    let faces = run.report["decimated"]["faces"].as_u64().expect("a decimation") as f64;
    let asked = conemap::pipeline::COARSE_FACES_PER_QUAD * 1000.0;
    assert!((0.7 * asked..1.3 * asked).contains(&faces), "{faces} faces for {asked}");
    assert!(run.stdout.contains("traced on a decimation"), "{}", run.stdout);
    let triangles: Vec<[[f64; 3]; 3]> = input.faces().iter().map(|t| t.map(|v| input.position(v))).collect();
    let diagonal = input.bounding_diagonal();
    let text = std::fs::read_to_string(&run.obj).unwrap();
    let vertices: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [x[0], x[1], x[2]]
        })
        .collect();
    let q = &run.report["quads"];
    assert_eq!(vertices.len() as u64, q["vertices"].as_u64().unwrap());
    for p in &vertices {
        let d = triangles.iter().map(|t| conemap::vec3::point_triangle_distance(*p, t)).fold(f64::INFINITY, f64::min);
        // The OBJ's decimal digits.
        assert!(d < 1e-6 * diagonal, "a quad vertex {d} off the input");
    }
    assert_eq!(q["euler_characteristic"].as_i64(), Some(input.euler_characteristic()));
    assert_eq!(q["boundary_loops"].as_u64(), Some(input.boundary_loops().len() as u64));
    assert_eq!((q["flipped_quads"].as_u64(), q["degenerate_quads"].as_u64(), q["non_manifold_edges"].as_u64()), (Some(0), Some(0), Some(0)));
    assert_eq!(run.report["defects"].as_array().map(Vec::len), Some(0));
    let singular: u64 = q["valence_histogram"]["interior"].as_object().unwrap().iter().filter(|(k, _)| *k != "4").map(|(_, n)| n.as_u64().unwrap()).sum();
    assert_eq!(Some(singular), run.report["cones"].as_u64(), "singular vertices are the cones: {q}");
    let full = run_quads("bff-cowhead", "full-mesh", &["--quads", "1000", "--full-mesh"]);
    assert!(full.report["decimated"].is_null());
    for dir in [run.dir, full.dir] {
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// `solve --quads` into a `.glb`: read back as the file's f32, every seam
/// transition is a quarter turn plus an integer translation to the last bit
/// and every cone an integer point, with coordinates of up to about 64 grid
/// units (where a plain f32 rounding is off by ~4e-6).
#[test]
fn a_grid_glb_is_an_integer_grid_map_in_f32() {
    let spot = common::shared_path("spot.obj");
    let dir = std::env::temp_dir().join(format!("conemap-grid-glb-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let glb = dir.join("spot-grid.glb");
    let out = Command::new(env!("CARGO_BIN_EXE_conemap")).arg("solve").arg(&spot).arg("-o").arg(&glb).args(["--quads", "10000", "--quiet"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&glb).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let g = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = g.blob.clone().unwrap();
    // Triangles as (welded position id, uv) corners; positions welded by their f32 bits.
    let mut ids = std::collections::HashMap::new();
    let mut corners: Vec<(usize, [f64; 2])> = Vec::new();
    for mesh in g.meshes() {
        for prim in mesh.primitives() {
            let r = prim.reader(|_| Some(&blob[..]));
            let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
            let tex: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
            for i in r.read_indices().unwrap().into_u32() {
                let key = pos[i as usize].map(f32::to_bits);
                let n = ids.len();
                let id = *ids.entry(key).or_insert(n);
                // TEXCOORD_0 = (u, 1 − v) in grid units.
                let t = tex[i as usize];
                corners.push((id, [t[0] as f64, 1.0 - t[1] as f64]));
            }
        }
    }
    let extent = corners.iter().map(|c| c.1[0].abs().max(c.1[1].abs())).fold(0.0, f64::max);
    assert!(extent > 32.0, "coordinates up to {extent}: too small to test f32 exactness");
    // Each undirected edge with its two sides: (corner a, corner b) per face.
    let mut sides: std::collections::HashMap<(usize, usize), Vec<(usize, usize)>> = std::collections::HashMap::new();
    for f in 0..corners.len() / 3 {
        for k in 0..3 {
            let (a, b) = (3 * f + k, 3 * f + (k + 1) % 3);
            let key = (corners[a].0.min(corners[b].0), corners[a].0.max(corners[b].0));
            sides.entry(key).or_default().push(if corners[a].0 < corners[b].0 { (a, b) } else { (b, a) });
        }
    }
    let rot = |p: [f64; 2], r: u8| match r {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    };
    let (mut seams, mut worst) = (0, 0f64);
    for pair in sides.values().filter(|s| s.len() == 2) {
        let [(a0, b0), (a1, b1)] = [pair[0], pair[1]];
        let (ua, ub, va, vb) = (corners[a0].1, corners[b0].1, corners[a1].1, corners[b1].1);
        if ua == va && ub == vb {
            continue;
        }
        seams += 1;
        let d0 = [ub[0] - ua[0], ub[1] - ua[1]];
        let d1 = [vb[0] - va[0], vb[1] - va[1]];
        let r = (0..4u8).min_by(|&x, &y| {
            let (p, q) = (rot(d0, x), rot(d0, y));
            let e = |p: [f64; 2]| (p[0] - d1[0]).powi(2) + (p[1] - d1[1]).powi(2);
            e(p).total_cmp(&e(q))
        });
        let r = r.unwrap();
        for (u, v) in [(ua, va), (ub, vb)] {
            let ru = rot(u, r);
            for i in 0..2 {
                let t = v[i] - ru[i];
                worst = worst.max((t - t.round()).abs());
            }
        }
    }
    assert!(seams > 100, "{seams} seam edges");
    assert_eq!(worst, 0.0, "a seam translation is off an integer by {worst:.2e} in the file");
}
