//! Fixtures shared by the integration tests: the meshes of `../shared/meshes`
//! beside the checkout (`meshes/README.md` there tabulates them). A missing
//! fixture fails the test that needs it, naming the path: a checkout without
//! them must not pass. (Each test binary uses only some of these helpers.)
#![allow(dead_code)]

use conemap::io::import_path;
use conemap::mesh::{RawMesh, TriMesh};
use std::path::{Path, PathBuf};

/// The folder of the shared meshes.
pub const SHARED_MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes");

/// Path of shared mesh `name` (file name with extension); panics when absent.
pub fn shared_path(name: &str) -> PathBuf {
    let path = Path::new(SHARED_MESHES).join(name);
    assert!(path.is_file(), "fixture {} not found: the shared meshes must sit beside the checkout", path.display());
    path
}

/// Shared mesh `name`, imported (not validated).
pub fn shared_raw(name: &str) -> RawMesh {
    let path = shared_path(name);
    import_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Shared mesh `name`, imported and validated (panics on the first problem).
pub fn shared_mesh(name: &str) -> TriMesh {
    TriMesh::from_raw(&shared_raw(name)).unwrap_or_else(|p| panic!("{name}: {}", p[0]))
}

/// The committed fixture `tests/fixtures/NAME` (`cad/gear.obj`, say), imported and validated.
pub fn fixture_mesh(name: &str) -> TriMesh {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/fixtures")).join(name);
    let raw = import_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    TriMesh::from_raw(&raw).unwrap_or_else(|p| panic!("{name}: {}", p[0]))
}

/// The shared meshes `names` side by side as one mesh, each moved clear of
/// the ones before along x (a name may come again: copies).
pub fn side_by_side(names: &[&str]) -> TriMesh {
    let mut raw = RawMesh { positions: Vec::new(), triangles: Vec::new() };
    let mut x = 0.0;
    for name in names {
        let r = shared_raw(name);
        let (lo, hi) = r.positions.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
        let base = raw.positions.len() as u32;
        raw.positions.extend(r.positions.iter().map(|p| [p[0] - lo + x, p[1], p[2]]));
        raw.triangles.extend(r.triangles.iter().map(|t| t.map(|v| v + base)));
        x += 1.1 * (hi - lo);
    }
    TriMesh::from_raw(&raw).unwrap()
}

/// Every mesh file (.obj, .gltf, .glb) of the shared folder, sorted by name;
/// panics when the folder is absent or holds none.
pub fn shared_files() -> Vec<PathBuf> {
    let dir = Path::new(SHARED_MESHES);
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("fixtures {}: {e}: the shared meshes must sit beside the checkout", dir.display()));
    let mut paths: Vec<PathBuf> = entries
        .map(|e| e.expect("directory entry").path())
        .filter(|p| {
            let lower = p.to_string_lossy().to_ascii_lowercase();
            lower.ends_with(".obj") || lower.ends_with(".gltf") || lower.ends_with(".glb")
        })
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no meshes in {}", dir.display());
    paths
}
