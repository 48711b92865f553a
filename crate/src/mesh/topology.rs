//! Shared combinatorial building blocks: the undirected edge table built from
//! face halfedges, and a union-find.
//!
//! Halfedge `h = 3 f + k` of face `f` runs from corner `k` to corner `(k+1) % 3`.

/// Halfedges grouped by undirected edge `{lo, hi}` (welded indices, `lo <= hi`).
/// Edges are sorted by `(lo, hi)`; within an edge, halfedges are ascending.
pub(crate) struct EdgeTable {
    /// Halfedge ids grouped by edge: edge `e` owns `he[start[e]..start[e + 1]]`.
    pub he: Vec<u32>,
    pub start: Vec<u32>,
    /// `[lo, hi]` per edge.
    pub verts: Vec<[u32; 2]>,
    /// Edge of each face halfedge (`u32::MAX` for faces left out).
    pub he_edge: Vec<u32>,
}

impl EdgeTable {
    /// Builds the table from the faces with `use_face[f]`; their corners must be
    /// `< n_vertices`. Linear time: bucket by the lower vertex, sort tiny buckets.
    pub fn build(n_vertices: usize, tris: &[[u32; 3]], use_face: &[bool]) -> EdgeTable {
        let mut count = vec![0u32; n_vertices + 1];
        for (f, t) in tris.iter().enumerate() {
            if !use_face[f] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                count[a.min(b) as usize + 1] += 1;
            }
        }
        for i in 0..n_vertices {
            count[i + 1] += count[i];
        }
        let total = count[n_vertices] as usize;
        let mut fill = count.clone();
        // (hi << 32) | halfedge, bucketed by lo.
        let mut slots = vec![0u64; total];
        for (f, t) in tris.iter().enumerate() {
            if !use_face[f] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let lo = a.min(b) as usize;
                let hi = a.max(b) as u64;
                slots[fill[lo] as usize] = (hi << 32) | (3 * f + k) as u64;
                fill[lo] += 1;
            }
        }
        drop(fill);
        let mut he = Vec::with_capacity(total);
        let mut start = Vec::with_capacity(total / 2 + 1);
        let mut verts = Vec::with_capacity(total / 2 + 1);
        let mut he_edge = vec![u32::MAX; 3 * tris.len()];
        for lo in 0..n_vertices {
            let bucket = &mut slots[count[lo] as usize..count[lo + 1] as usize];
            if bucket.len() > 1 {
                if bucket.len() <= 16 {
                    insertion_sort(bucket);
                } else {
                    bucket.sort_unstable();
                }
            }
            let mut prev_hi = u64::MAX;
            for &s in bucket.iter() {
                let hi = s >> 32;
                let h = (s & 0xffff_ffff) as u32;
                if hi != prev_hi {
                    start.push(he.len() as u32);
                    verts.push([lo as u32, hi as u32]);
                    prev_hi = hi;
                }
                he_edge[h as usize] = (verts.len() - 1) as u32;
                he.push(h);
            }
        }
        start.push(he.len() as u32);
        EdgeTable { he, start, verts, he_edge }
    }

    pub fn n_edges(&self) -> usize {
        self.verts.len()
    }

    /// The face halfedges of edge `e`.
    #[inline]
    pub fn halfedges(&self, e: usize) -> &[u32] {
        &self.he[self.start[e] as usize..self.start[e + 1] as usize]
    }
}

fn insertion_sort(v: &mut [u64]) {
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// Tail vertex of face halfedge `h`.
#[inline]
pub(crate) fn he_tail(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[(h / 3) as usize][(h % 3) as usize]
}

/// Head vertex of face halfedge `h`.
#[inline]
pub(crate) fn he_head(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[(h / 3) as usize][((h % 3 + 1) % 3) as usize]
}

/// Disjoint sets over `0..n` (path halving; the smaller root wins a union,
/// so each set's root is its first element).
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub fn new(n: usize) -> UnionFind {
        UnionFind { parent: (0..n as u32).collect() }
    }
    #[inline]
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            let gp = self.parent[p as usize];
            self.parent[x as usize] = gp;
            x = gp;
        }
        x
    }
    #[inline]
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi as usize] = lo;
        }
    }
    /// Number of distinct sets among `members`.
    pub fn count_sets(&mut self, members: impl Iterator<Item = u32>) -> usize {
        let mut roots: Vec<u32> = members.map(|x| self.find(x)).collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len()
    }
}
