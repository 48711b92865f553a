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

/// `conemap quads` writes a pure-quad OBJ with grid UVs and a report whose
/// figures agree with the file; `solve --grid` writes grid-unit UVs.
#[test]
fn quads_writes_a_quad_obj_and_its_report() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/spot.obj");
    let dir = std::env::temp_dir().join(format!("conemap-quads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (obj, report) = (dir.join("spot-quads.obj"), dir.join("spot-quads.json"));
    let out = Command::new(env!("CARGO_BIN_EXE_conemap"))
        .arg("quads")
        .arg(spot)
        .arg("-o")
        .arg(&obj)
        .args(["--quads", "3000", "--quiet", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&obj).unwrap();
    let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
    assert!(faces.iter().all(|f| f.split_whitespace().count() == 5), "a face that is not a quad");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
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
    std::fs::remove_dir_all(&dir).ok();
}
