//! The command-line tool as a user runs it.

use std::process::{Command, Stdio};

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
