//! Vertices by position, for feature lists given as end points.

use std::collections::HashMap;

/// Finds mesh vertices by position with a uniform hash grid.
pub(super) struct VertexLocator<'a> {
    positions: &'a [[f64; 3]],
    cell: f64,
    origin: [f64; 3],
    grid: HashMap<[i64; 3], Vec<u32>>,
    tolerance: f64,
}

impl<'a> VertexLocator<'a> {
    pub(super) fn new(positions: &'a [[f64; 3]]) -> Self {
        let (lo, hi) = crate::vec3::bounds(positions);
        let diag = ((0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>()).sqrt().max(f64::MIN_POSITIVE);
        let tolerance = 1e-6 * diag;
        let cell = 4.0 * tolerance;
        let mut locator = VertexLocator { positions, cell, origin: lo, grid: HashMap::new(), tolerance };
        for (v, p) in positions.iter().enumerate() {
            let key = locator.key(p);
            locator.grid.entry(key).or_default().push(v as u32);
        }
        locator
    }

    fn key(&self, p: &[f64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|i| ((p[i] - self.origin[i]) / self.cell).floor() as i64)
    }

    /// Every vertex within the tolerance, nearest first (a mesh can hold
    /// several vertices at one position: open cracks, touching components).
    pub(super) fn find_all(&self, p: &[f64; 3]) -> Vec<u32> {
        let k = self.key(p);
        let mut near: Vec<(f64, u32)> = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &v in self.grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]).into_iter().flatten() {
                        let q = self.positions[v as usize];
                        let d = ((0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>()).sqrt();
                        if d <= self.tolerance {
                            near.push((d, v));
                        }
                    }
                }
            }
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        near.into_iter().map(|(_, v)| v).collect()
    }
}
