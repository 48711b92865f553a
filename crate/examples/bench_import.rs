//! Import benchmark: `cargo run --release --example bench_import [MESH.obj] [MIN_FACES]`.
//!
//! Loads a mesh (default: shared/meshes/fandisk.obj), subdivides it 1-to-4
//! until it has at least MIN_FACES (default 1 000 000) faces, writes it as an
//! OBJ (6 decimals, like common exporters) to a temporary file, then times
//! each import stage separately and prints one JSON line (seconds).

use conemap::io::{import, InputFile};
use conemap::mesh::{analyze, subdivide_midpoint, weld};
use conemap::{RawMesh, TriMesh};
use std::io::Write;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/fandisk.obj").to_string());
    let min_faces: usize = args.next().map(|s| s.parse().expect("MIN_FACES must be a number")).unwrap_or(1_000_000);

    let mut mesh = conemap::io::import_path(std::path::Path::new(&path)).expect("cannot read the input mesh");
    while mesh.face_count() < min_faces {
        mesh = subdivide_midpoint(&mesh);
    }
    let tmp = std::env::temp_dir().join(format!("conemap-bench-{}.obj", std::process::id()));
    write_obj(&mesh, &tmp);
    let bytes_len = std::fs::metadata(&tmp).map(|m| m.len()).unwrap_or(0);

    let t = Instant::now();
    let bytes = std::fs::read(&tmp).expect("cannot read back the temporary file");
    let read = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let raw = import(&InputFile { name: "bench.obj".into(), bytes }, &[]).expect("parse failed");
    let parse = t.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&tmp);

    let t = Instant::now();
    let welded = weld(&raw);
    let weld_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let report = analyze(&raw);
    let analyze_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let tri = TriMesh::from_raw(&raw);
    let trimesh_s = t.elapsed().as_secs_f64();
    let tri = match tri {
        Ok(m) => m,
        Err(p) => panic!("subdivided mesh has {} problems, first: {}", p.len(), p[0]),
    };
    assert_eq!(welded.positions.len(), tri.n_vertices());
    assert_eq!(report.vertices, tri.n_vertices());
    println!(
        "{{\"read\": {read:.4}, \"parse\": {parse:.4}, \"read_parse\": {:.4}, \"weld\": {weld_s:.4}, \
         \"analyze\": {analyze_s:.4}, \"trimesh_from_raw\": {trimesh_s:.4}, \"import_total\": {:.4}, \
         \"faces\": {}, \"vertices\": {}, \"obj_bytes\": {bytes_len}}}",
        read + parse,
        read + parse + trimesh_s,
        tri.n_faces(),
        tri.n_vertices()
    );
}

fn write_obj(mesh: &RawMesh, path: &std::path::Path) {
    let file = std::fs::File::create(path).expect("cannot create the temporary file");
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    writeln!(w, "# conemap bench_import").unwrap();
    for p in &mesh.positions {
        writeln!(w, "v {:.6} {:.6} {:.6}", p[0], p[1], p[2]).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    w.flush().unwrap();
}
