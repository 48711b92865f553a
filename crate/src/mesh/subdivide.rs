//! Midpoint subdivision (for benchmarks and tests).

use super::weld::FxHasher;
use super::RawMesh;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// 1-to-4 midpoint split: each triangle `(a, b, c)` becomes `(a, ab, ca)`,
/// `(ab, b, bc)`, `(ca, bc, c)`, `(ab, bc, ca)`, with one new vertex per
/// undirected edge (keyed by source index pair) appended after the old ones.
/// Orientation is kept. Faces with out-of-range indices are dropped.
pub fn subdivide_midpoint(raw: &RawMesh) -> RawMesh {
    let n = raw.positions.len();
    let mut positions = raw.positions.clone();
    positions.reserve(raw.triangles.len() * 3 / 2);
    let mut triangles = Vec::with_capacity(raw.triangles.len() * 4);
    let mut mids: HashMap<u64, u32, BuildHasherDefault<FxHasher>> = HashMap::default();
    mids.reserve(raw.triangles.len() * 3 / 2);
    let mut mid = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| -> u32 {
        let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
        *mids.entry(key).or_insert_with(|| {
            let (p, q) = (positions[a as usize], positions[b as usize]);
            positions.push([(p[0] + q[0]) * 0.5, (p[1] + q[1]) * 0.5, (p[2] + q[2]) * 0.5]);
            (positions.len() - 1) as u32
        })
    };
    for &[a, b, c] in &raw.triangles {
        if [a, b, c].iter().any(|&i| i as usize >= n) {
            continue;
        }
        let ab = mid(a, b, &mut positions);
        let bc = mid(b, c, &mut positions);
        let ca = mid(c, a, &mut positions);
        triangles.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    RawMesh { positions, triangles }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_tetrahedron() {
        let raw = RawMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        let s = subdivide_midpoint(&raw);
        assert_eq!(s.triangles.len(), 16);
        assert_eq!(s.positions.len(), 4 + 6);
        let r = crate::mesh::analyze(&s);
        assert_eq!((r.euler_characteristic, r.boundary_edges, r.problems.len()), (2, 0, 0));
    }
}
