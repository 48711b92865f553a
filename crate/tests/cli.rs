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
