//! A uniform grid over axis-aligned boxes for nearest-item queries: the
//! spatial index behind the quad check's distances (samples to triangles)
//! and sharp-edge test (samples to quad edges) and behind
//! [`super::NearestFace`], about linear in the number of queries and items.

use crate::vec3::{add, bounds, norm, sub, V3};

/// Per-query marks so an item spanning several cells is measured once.
pub(crate) struct Visited {
    mark: Vec<u32>,
    query: u32,
}

impl Visited {
    pub(crate) fn new(items: usize) -> Self {
        Visited { mark: vec![0; items], query: 0 }
    }
    fn start(&mut self) {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.mark.fill(0);
            self.query = 1;
        }
    }
    /// True the first time `item` is seen in this query.
    fn first(&mut self, item: u32) -> bool {
        let fresh = self.mark[item as usize] != self.query;
        self.mark[item as usize] = self.query;
        fresh
    }
}

/// A uniform grid of cubic cells over items' axis-aligned boxes (each item
/// listed in every cell its box overlaps), for nearest-item queries.
pub(crate) struct BoxGrid {
    origin: V3,
    cell: f64,
    dims: [usize; 3],
    /// Items of cell `c` are `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// Box of each item.
    boxes: Vec<(V3, V3)>,
}

impl BoxGrid {
    /// The grid over `boxes` (`(lo, hi)` each): cubic cells about the mean
    /// box diagonal, at most `8 n + 64` of them.
    pub(crate) fn new(boxes: &[(V3, V3)]) -> BoxGrid {
        let corners: Vec<V3> = boxes.iter().flat_map(|&(lo, hi)| [lo, hi]).collect();
        let (lo, hi) = bounds(&corners);
        // Non-finite coordinates (a broken input) all land in the border cells.
        let extent = sub(hi, lo).map(|x| if x.is_finite() { x } else { 0.0 });
        let mean_size = boxes.iter().map(|(l, h)| norm(sub(*h, *l))).sum::<f64>() / boxes.len().max(1) as f64;
        let limit = 8 * boxes.len() + 64;
        let mut cell = if mean_size > 0.0 { mean_size } else { norm(extent).max(1.0) };
        let dims_for = |cell: f64| extent.map(|x| ((x / cell).floor() as usize).saturating_add(1));
        let mut dims = dims_for(cell);
        while dims.iter().fold(1usize, |n, &d| n.saturating_mul(d)) > limit {
            cell *= 1.25;
            dims = dims_for(cell);
        }
        let origin = lo.map(|x| if x.is_finite() { x } else { 0.0 });
        let mut grid = BoxGrid { origin, cell, dims, start: Vec::new(), items: Vec::new(), boxes: boxes.to_vec() };
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut count = vec![0u32; n_cells + 1];
        for &(l, h) in boxes {
            grid.for_cells(l, h, |c| count[c + 1] += 1);
        }
        for c in 0..n_cells {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[n_cells] as usize];
        for (i, &(l, h)) in boxes.iter().enumerate() {
            grid.for_cells(l, h, |c| {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
            });
        }
        grid.start = count;
        grid.items = items;
        grid
    }

    /// Integer cell coordinates of `p`, clamped into the grid.
    fn cell_of(&self, p: V3) -> [usize; 3] {
        [0, 1, 2].map(|i| (((p[i] - self.origin[i]) / self.cell).floor().max(0.0) as usize).min(self.dims[i] - 1))
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Calls `f` with every cell the box `[lo, hi]` overlaps.
    fn for_cells(&self, lo: V3, hi: V3, mut f: impl FnMut(usize)) {
        let (a, b) = (self.cell_of(lo), self.cell_of(hi));
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    f(self.index([x, y, z]));
                }
            }
        }
    }

    /// The smallest `distance(item)` over the items, searched in shells of
    /// cells around `p`; stops once no unvisited item can be closer than the
    /// best found or than `cutoff` (the result is then only known to exceed
    /// `cutoff`). Infinite when there are no items.
    pub(crate) fn nearest(&self, p: V3, cutoff: f64, seen: &mut Visited, mut distance: impl FnMut(u32) -> f64) -> f64 {
        seen.start();
        let c = self.cell_of(p);
        let mut best = f64::INFINITY;
        for r in 0usize.. {
            // Items in shells ≥ r are at least (r − 1) cells away.
            let reach = r.saturating_sub(1) as f64 * self.cell;
            if r > 0 && (best <= reach || cutoff < reach) {
                break;
            }
            let lo = c.map(|x| x.saturating_sub(r));
            let hi = [0, 1, 2].map(|i| (c[i] + r).min(self.dims[i] - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    let on_shell = |x: usize, i: usize| x.abs_diff(c[i]) == r;
                    for x in lo[0]..=hi[0] {
                        if !(on_shell(x, 0) || on_shell(y, 1) || on_shell(z, 2)) {
                            continue;
                        }
                        // Cells and items farther than the best (or the cutoff) cannot matter.
                        let limit = best.min(cutoff);
                        let cell_lo = [x, y, z].map(|k| k as f64 * self.cell);
                        let cell_lo = add(self.origin, cell_lo);
                        if box_distance(p, cell_lo, add(cell_lo, [self.cell; 3])) > limit {
                            continue;
                        }
                        let cell = self.index([x, y, z]);
                        for &item in &self.items[self.start[cell] as usize..self.start[cell + 1] as usize] {
                            let (l, h) = self.boxes[item as usize];
                            if seen.first(item) && box_distance(p, l, h) <= best.min(cutoff) {
                                best = best.min(distance(item));
                            }
                        }
                    }
                }
            }
            if (0..3).all(|i| lo[i] == 0 && hi[i] == self.dims[i] - 1) {
                break;
            }
        }
        best
    }
}

/// Distance from `p` to the box `[lo, hi]` (0 inside).
fn box_distance(p: V3, lo: V3, hi: V3) -> f64 {
    norm([0, 1, 2].map(|i| (lo[i] - p[i]).max(p[i] - hi[i]).max(0.0)))
}
