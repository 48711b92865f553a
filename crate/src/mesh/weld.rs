//! Welding: source vertices at exactly the same position become one vertex.
//!
//! Connectivity of an imported mesh comes from positions, not from the file's
//! vertex indices (files routinely split vertices along UV or normal seams).

use super::RawMesh;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// Marks "no vertex": unreferenced source vertices, out-of-range corners.
pub const NO_VERTEX: u32 = u32::MAX;

/// The result of [`weld`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Welded {
    /// Welded vertex positions (those of each vertex's representative).
    pub positions: Vec<[f64; 3]>,
    /// One triangle per source triangle, same order, in welded indices; a corner
    /// whose source index is out of range holds [`NO_VERTEX`].
    pub triangles: Vec<[u32; 3]>,
    /// Source vertex → welded vertex; [`NO_VERTEX`] for source vertices no face uses.
    pub source_to_welded: Vec<u32>,
    /// Welded vertex → one representative source vertex (the first one met in face order).
    pub welded_to_source: Vec<u32>,
}

impl Welded {
    /// A "weld" that trusts the given indices: no positions are merged, only
    /// unreferenced vertices are dropped (welded order: first appearance in faces).
    pub fn by_index(raw: &RawMesh) -> Welded {
        weld_impl(raw, false)
    }
}

/// Welds `raw`: source vertices at bit-identical positions (with -0.0 == 0.0)
/// become one vertex. Only vertices referenced by an in-range face corner are
/// kept, numbered in order of first appearance in the face list. Never panics:
/// out-of-range indices become [`NO_VERTEX`] corners; NaN coordinates weld by bit
/// pattern. Runs in expected linear time (hash map with an Fx-style hasher).
pub fn weld(raw: &RawMesh) -> Welded {
    weld_impl(raw, true)
}

fn weld_impl(raw: &RawMesh, merge_positions: bool) -> Welded {
    let n_src = raw.positions.len();
    let mut source_to_welded = vec![NO_VERTEX; n_src];
    let mut welded_to_source: Vec<u32> = Vec::new();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::with_capacity(raw.triangles.len());
    let mut map: HashMap<PosKey, u32, BuildHasherDefault<FxHasher>> = HashMap::default();
    if merge_positions {
        // Typical meshes have about half as many vertices as faces.
        map.reserve(raw.triangles.len() / 2 + 16);
    }
    for tri in &raw.triangles {
        let mut out = [NO_VERTEX; 3];
        for (k, &s) in tri.iter().enumerate() {
            let su = s as usize;
            if su >= n_src {
                continue;
            }
            let w = source_to_welded[su];
            if w != NO_VERTEX {
                out[k] = w;
                continue;
            }
            let p = raw.positions[su];
            let next = positions.len() as u32;
            let w = if merge_positions {
                *map.entry(PosKey::new(p)).or_insert(next)
            } else {
                next
            };
            if w == next {
                positions.push(p);
                welded_to_source.push(s);
            }
            source_to_welded[su] = w;
            out[k] = w;
        }
        triangles.push(out);
    }
    Welded { positions, triangles, source_to_welded, welded_to_source }
}

/// Exact position key; `x + 0.0` turns -0.0 into +0.0.
#[derive(Clone, Copy, PartialEq, Eq)]
struct PosKey([u64; 3]);

impl PosKey {
    fn new(p: [f64; 3]) -> PosKey {
        PosKey([(p[0] + 0.0).to_bits(), (p[1] + 0.0).to_bits(), (p[2] + 0.0).to_bits()])
    }
}

impl Hash for PosKey {
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_u64(self.0[0]);
        state.write_u64(self.0[1]);
        state.write_u64(self.0[2]);
    }
}

/// A tiny Fx-style hasher (rotate, xor, multiply) with a mixing finaliser, so
/// keys whose low bits are all zero (short decimal floats) still spread well.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher {
    hash: u64,
}

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.hash = (self.hash.rotate_left(5) ^ x).wrapping_mul(SEED);
    }
    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        // murmur3 fmix64
        let mut h = self.hash;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welds_coincident_and_drops_unreferenced() {
        let raw = RawMesh {
            positions: vec![
                [0.0, 0.0, 0.0],  // 0
                [1.0, 0.0, 0.0],  // 1
                [0.0, 1.0, 0.0],  // 2
                [9.0, 9.0, 9.0],  // 3 unreferenced
                [1.0, -0.0, 0.0], // 4 == 1 (-0.0 == 0.0)
                [1.0, 1.0, 0.0],  // 5
            ],
            triangles: vec![[0, 1, 2], [4, 5, 2], [2, 7, 0]],
        };
        let w = weld(&raw);
        assert_eq!(w.positions.len(), 4);
        assert_eq!(w.triangles, vec![[0, 1, 2], [1, 3, 2], [2, NO_VERTEX, 0]]);
        assert_eq!(w.source_to_welded, vec![0, 1, 2, NO_VERTEX, 1, 3]);
        assert_eq!(w.welded_to_source, vec![0, 1, 2, 5]);
        let b = Welded::by_index(&raw);
        assert_eq!(b.positions.len(), 5);
        assert_eq!(b.triangles[1], [3, 4, 2]);
    }

    #[test]
    fn empty_and_nan() {
        assert_eq!(weld(&RawMesh::default()).positions.len(), 0);
        let raw = RawMesh {
            positions: vec![[f64::NAN, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [1.0, 2.0, 3.0]],
            triangles: vec![[0, 1, 2]],
        };
        let w = weld(&raw);
        assert_eq!(w.triangles, vec![[0, 0, 1]]);
    }
}
