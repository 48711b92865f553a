//! Feature curves finer than a quad grid. A feature on an integer-grid map
//! lies on an isoline and its corners on grid points, so a short branch
//! that dangles into the surface, or a small closed loop, puts its corner
//! cones within a cell of each other: the rounding must stretch them a
//! cell apart or fold the cells between (teapot with creases above 60° at
//! 3 000 quads: the spout's lip, a 4-edge arc of 1.9 cells turning half a
//! turn, carries three +1 cones within half a cell, and the map winds
//! around 6 vertices). [`finer_than_grid`] finds such curves; the grid map
//! is solved without them where the map with them folds
//! ([`crate::pipeline::grid_map`]).

use super::FeatureSet;
use crate::mesh::TriMesh;

/// Shortest dangling branch or closed loop a quad grid follows, in grid
/// cells: two quad edges.
pub const MIN_CURVE_CELLS: f64 = 2.0;

/// The feature edges of `features` that a quad grid of cell length `s`
/// cannot follow: every chain (a run of feature edges between junctions,
/// ends and the mesh boundary) shorter than [`MIN_CURVE_CELLS`]` * s` that
/// dangles (one of its ends is an interior vertex on no other feature
/// edge) or is a closed loop, removed again and again until none is left
/// (a removed branch can leave its junction a plain point of a chain that
/// now dangles). Chains between junctions or boundaries stay, whatever
/// their length.
pub fn finer_than_grid(mesh: &TriMesh, features: &FeatureSet, s: f64) -> FeatureSet {
    let min_length = MIN_CURVE_CELLS * s;
    let mut kept = features.clone();
    let mut dropped = FeatureSet::none(mesh);
    if !(min_length > 0.0) {
        return dropped;
    }
    loop {
        let degree = kept.degrees(mesh);
        let dangling = |v: u32| degree[v as usize] == 1 && !mesh.is_boundary_vertex(v);
        let short: Vec<Chain> = chains(mesh, &kept, &degree)
            .into_iter()
            .filter(|c| c.length < min_length && c.ends.is_none_or(|[a, b]| dangling(a) || dangling(b)))
            .collect();
        if short.is_empty() {
            return dropped;
        }
        for e in short.iter().flat_map(|c| &c.edges) {
            kept.set(mesh, *e, false);
            dropped.set(mesh, *e, true);
        }
    }
}

/// The chains of `features` (runs between junctions, ends and the
/// boundary) with a vertex where `near` is true, as one set.
pub fn chains_near(mesh: &TriMesh, features: &FeatureSet, near: &[bool]) -> FeatureSet {
    let degree = features.degrees(mesh);
    let mut out = FeatureSet::none(mesh);
    for chain in chains(mesh, features, &degree) {
        if chain.edges.iter().any(|&e| mesh.edge_vertices(e).iter().any(|&v| near[v as usize])) {
            for e in chain.edges {
                out.set(mesh, e, true);
            }
        }
    }
    out
}

/// A run of feature edges whose inner vertices lie on exactly two feature
/// edges and off the boundary: its edges, its length, and its two end
/// vertices (`None` for a closed loop).
struct Chain {
    edges: Vec<u32>,
    length: f64,
    ends: Option<[u32; 2]>,
}

/// The chains of `features` (`degree`: feature edges per vertex), each
/// edge in exactly one.
fn chains(mesh: &TriMesh, features: &FeatureSet, degree: &[u32]) -> Vec<Chain> {
    let node = |v: u32| degree[v as usize] != 2 || mesh.is_boundary_vertex(v);
    let mut seen = vec![false; mesh.n_edges()];
    // From vertex `v` along feature edge `e`, to the next node (or back to
    // the start of a loop).
    let walk = |v: u32, e: u32, seen: &mut [bool]| {
        let (mut chain, mut at, mut edge) = (Chain { edges: Vec::new(), length: 0.0, ends: None }, v, e);
        loop {
            seen[edge as usize] = true;
            chain.edges.push(edge);
            chain.length += mesh.edge_length(edge);
            let [a, b] = mesh.edge_vertices(edge);
            at = if a == at { b } else { a };
            if node(at) {
                chain.ends = Some([v, at]);
                return chain;
            }
            match mesh.outgoing(at).map(|h| mesh.edge(h)).find(|&g| features.contains(g) && !seen[g as usize]) {
                Some(g) => edge = g,
                None => return chain,
            }
        }
    };
    let mut out = Vec::new();
    for v in (0..mesh.n_vertices() as u32).filter(|&v| degree[v as usize] > 0 && node(v)) {
        let starts: Vec<u32> = mesh.outgoing(v).map(|h| mesh.edge(h)).filter(|&e| features.contains(e)).collect();
        for e in starts {
            if !seen[e as usize] {
                out.push(walk(v, e, &mut seen));
            }
        }
    }
    // What is left are loops through plain points only.
    for e in features.edges() {
        if !seen[e as usize] {
            out.push(walk(mesh.edge_vertices(e)[0], e, &mut seen));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The features of `mesh` along the grid-point paths `paths` (each a
    /// list of `(i, j)` points of a flat [`crate::features::test_grid`]).
    fn along(mesh: &TriMesh, paths: &[&[(u32, u32)]]) -> FeatureSet {
        let mut set = FeatureSet::none(mesh);
        // (The mesh numbers its vertices in order of first use.)
        let id = |(i, j): (u32, u32)| (0..mesh.n_vertices() as u32).find(|&v| mesh.position(v) == [i as f64, j as f64, 0.0]).expect("a grid point");
        for path in paths {
            for w in path.windows(2) {
                let (a, b) = (id(w[0]), id(w[1]));
                let e = (0..mesh.n_edges() as u32).find(|&e| [[a, b], [b, a]].contains(&mesh.edge_vertices(e)));
                set.set(mesh, e.unwrap_or_else(|| panic!("no edge between {:?} and {:?}", w[0], w[1])), true);
            }
        }
        set
    }

    #[test]
    fn short_branches_and_loops_go_and_curves_between_boundaries_stay() {
        let n = 12;
        let mesh = crate::features::test_grid(n, |_, _| 0.0);
        // A line across the grid from boundary to boundary (row 6), a spur of
        // one edge off it and one of five, a lone edge, a loop around one
        // square and one around a 3 x 3 block.
        let across: Vec<(u32, u32)> = (0..=n).map(|i| (i, 6)).collect();
        let spur = [(3, 6), (3, 7)];
        let long_spur: Vec<(u32, u32)> = (6..=11).map(|j| (9, j)).collect();
        let lone = [(1, 1), (2, 1)];
        let small_loop = [(5, 2), (6, 2), (6, 3), (5, 3), (5, 2)];
        let block_loop = [(8, 1), (9, 1), (10, 1), (11, 1), (11, 2), (11, 3), (11, 4), (10, 4), (9, 4), (8, 4), (8, 3), (8, 2), (8, 1)];
        let features = along(&mesh, &[&across, &spur, &long_spur, &lone, &small_loop, &block_loop]);
        // Cells of 1: a chain needs two unit edges.
        assert_eq!(finer_than_grid(&mesh, &features, 1.0), along(&mesh, &[&spur, &lone]));
        // Cells of 2.5: five edges; the 4-edge loop goes, the 5-edge spur stays.
        assert_eq!(finer_than_grid(&mesh, &features, 2.5), along(&mesh, &[&spur, &lone, &small_loop]));
        // Cells of 3: the 5-edge spur goes, the 12-edge loop stays and the
        // line between boundaries always does.
        assert_eq!(finer_than_grid(&mesh, &features, 3.0), along(&mesh, &[&spur, &lone, &small_loop, &long_spur]));
        assert!(finer_than_grid(&mesh, &features, 0.0).is_empty());
    }

    #[test]
    fn a_branch_left_dangling_by_a_removed_one_goes_too() {
        let n = 8;
        let mesh = crate::features::test_grid(n, |_, _| 0.0);
        // A "T" inside: two one-edge twigs off the end of a two-edge stem.
        let stem = [(4, 2), (4, 3), (4, 4)];
        let twigs = [(3, 4), (4, 4), (5, 4)];
        let features = along(&mesh, &[&stem, &twigs]);
        // Cells of 1.2 (chains of 2.4): all three chains dangle and are short.
        assert_eq!(finer_than_grid(&mesh, &features, 1.2), features);
        // Cells of 0.8 (chains of 1.6): the twigs go; the stem, dangling at
        // both ends now, is long enough.
        assert_eq!(finer_than_grid(&mesh, &features, 0.8), along(&mesh, &[&twigs]));
        // Cells of 0.4: nothing is that short.
        assert!(finer_than_grid(&mesh, &features, 0.4).is_empty());
    }

    #[test]
    fn chains_near_a_vertex_are_those_through_it_up_to_their_junctions() {
        let n = 8;
        let mesh = crate::features::test_grid(n, |_, _| 0.0);
        // A line across the grid (row 4) with a branch up from (2, 4).
        let left = [(0, 4), (1, 4), (2, 4)];
        let right = [(2, 4), (3, 4), (4, 4), (5, 4), (6, 4), (7, 4), (8, 4)];
        let branch = [(2, 4), (2, 5), (2, 6)];
        let features = along(&mesh, &[&left, &right, &branch]);
        let id = |(i, j): (u32, u32)| (0..mesh.n_vertices()).find(|&v| mesh.position(v as u32) == [i as f64, j as f64, 0.0]).expect("a grid point");
        let mut near = vec![false; mesh.n_vertices()];
        near[id((6, 4))] = true;
        assert_eq!(chains_near(&mesh, &features, &near), along(&mesh, &[&right]));
        // At the junction: all three chains.
        near[id((2, 4))] = true;
        assert_eq!(chains_near(&mesh, &features, &near), features);
        // Off the features: none.
        let mut off = vec![false; mesh.n_vertices()];
        off[id((5, 1))] = true;
        assert!(chains_near(&mesh, &features, &off).is_empty());
    }
}
