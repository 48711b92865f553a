//! Welding: source vertices at exactly the same position become one vertex.
//!
//! Connectivity of an imported mesh comes from positions, not from the file's
//! vertex indices (files routinely split vertices along UV or normal seams).

use super::topology::UnionFind;
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

/// Distance, relative to the bounding-box diagonal, below which two
/// boundary vertices are one point: exporters that evaluate a seam point
/// twice in floating point (e.g. angle 0 and 2 pi) leave such cracks.
pub const CRACK_TOLERANCE: f64 = 1e-7;

/// Closes floating-point cracks: merges each vertex of `boundary` (vertices
/// on an edge used by one face) into a lower-numbered boundary vertex within
/// [`CRACK_TOLERANCE`] of the diagonal, unless `joined(u, w)` says an edge
/// already joins them. Returns `None` when nothing merges.
pub fn close_cracks(w: &Welded, boundary: &[u32], joined: impl Fn(u32, u32) -> bool) -> Option<Welded> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &w.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let tol = CRACK_TOLERANCE * diag;
    if !(tol > 0.0 && tol.is_finite()) {
        return None;
    }
    let cell = |p: [f64; 3]| p.map(|x| (x / tol).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>, BuildHasherDefault<FxHasher>> = HashMap::default();
    let mut sorted = boundary.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let mut rep: Vec<u32> = (0..w.positions.len() as u32).collect();
    let mut merged = false;
    for &v in &sorted {
        let p = w.positions[v as usize];
        let c = cell(p);
        let mut target = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &u in grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]).into_iter().flatten() {
                        let q = w.positions[u as usize];
                        let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                        if d2 <= tol * tol && !joined(u, v) {
                            target = Some(rep[u as usize]);
                            break 'search;
                        }
                    }
                }
            }
        }
        match target {
            Some(t) => {
                rep[v as usize] = t;
                merged = true;
            }
            None => grid.entry(c).or_default().push(v),
        }
    }
    if !merged {
        return None;
    }
    // Renumber by first use, as `weld` does, and compose the source maps.
    let raw = RawMesh {
        positions: w.positions.clone(),
        triangles: w.triangles.iter().map(|t| t.map(|v| if v == NO_VERTEX { v } else { rep[v as usize] })).collect(),
    };
    let re = weld_impl(&raw, false);
    let source_to_welded =
        w.source_to_welded.iter().map(|&x| if x == NO_VERTEX { x } else { re.source_to_welded[rep[x as usize] as usize] }).collect();
    let welded_to_source = re.welded_to_source.iter().map(|&x| w.welded_to_source[x as usize]).collect();
    Some(Welded { positions: re.positions, triangles: re.triangles, source_to_welded, welded_to_source })
}

/// Splits each vertex of `pinches` whose faces form several fans (faces
/// around it joined through shared edges) into one vertex per fan: the
/// first fan in face order keeps the vertex, the others get copies at the
/// same position (same source vertex). Faces keep their order.
pub fn split_pinches(w: &Welded, pinches: &[u32]) -> Welded {
    let mut out = w.clone();
    let mut is_pinch = vec![false; w.positions.len()];
    for &v in pinches {
        is_pinch[v as usize] = true;
    }
    let mut incident: HashMap<u32, Vec<usize>, BuildHasherDefault<FxHasher>> = HashMap::default();
    for (f, t) in w.triangles.iter().enumerate() {
        for &v in t {
            if v != NO_VERTEX && is_pinch[v as usize] {
                incident.entry(v).or_default().push(f);
            }
        }
    }
    let mut keys: Vec<u32> = incident.keys().copied().collect();
    keys.sort_unstable();
    for v in keys {
        let faces = &incident[&v];
        // Union faces sharing an edge (v, x).
        let mut fans = UnionFind::new(faces.len());
        let mut by_other: HashMap<u32, u32, BuildHasherDefault<FxHasher>> = HashMap::default();
        for (i, &f) in faces.iter().enumerate() {
            for &x in w.triangles[f].iter().filter(|&&x| x != v) {
                match by_other.get(&x) {
                    Some(&j) => fans.union(i as u32, j),
                    None => {
                        by_other.insert(x, i as u32);
                    }
                }
            }
        }
        let mut copy_of_root: HashMap<u32, u32, BuildHasherDefault<FxHasher>> = HashMap::default();
        for (i, &f) in faces.iter().enumerate() {
            let root = fans.find(i as u32);
            let next = copy_of_root.len();
            let id = *copy_of_root.entry(root).or_insert_with(|| {
                if next == 0 {
                    v
                } else {
                    out.positions.push(w.positions[v as usize]);
                    out.welded_to_source.push(w.welded_to_source[v as usize]);
                    (out.positions.len() - 1) as u32
                }
            });
            for c in out.triangles[f].iter_mut() {
                if *c == v {
                    *c = id;
                }
            }
        }
    }
    out
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

    /// Two triangles whose shared edge was written twice with a 1e-12 crack
    /// (the way `sin(2 pi)` differs from `sin(0)`): the analysis closes it.
    #[test]
    fn floating_point_cracks_close_but_real_gaps_stay() {
        let crack = |gap: f64| RawMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0 + gap, 0.0, 0.0], [gap, 1.0, 0.0], [1.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2], [3, 5, 4]],
        };
        let closed = crate::mesh::analyze(&crack(1e-12));
        assert_eq!((closed.vertices, closed.boundary_edges), (4, 4), "the crack is closed");
        let open = crate::mesh::analyze(&crack(1e-3));
        assert_eq!((open.vertices, open.boundary_edges), (6, 6), "a real gap stays open");
        let mesh = crate::mesh::TriMesh::from_raw(&crack(1e-12)).unwrap();
        assert_eq!(mesh.n_vertices(), 4);
        assert_eq!(mesh.source_to_welded()[3], mesh.source_to_welded()[1]);
    }
}
