//! Sharp-edge detection for the "Sharp edges >" slider and `--sharp`: the
//! edges whose dihedral angle exceeds a threshold, then, for organic meshes
//! (where a threshold marks many short, noisy creases), without the
//! fragments that are too short and, optionally, without dangling ends.

use super::FeatureSet;
use crate::mesh::TriMesh;
use serde::Serialize;

/// Smallest feature curve kept by [`detect_sharp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MinLength {
    /// Keep every curve.
    None,
    /// Drop curves of fewer edges.
    Edges(usize),
    /// Drop curves shorter than this fraction of the bounding-box diagonal.
    DiagonalFraction(f64),
}

/// Settings of [`detect_sharp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SharpOptions {
    /// Interior edges whose face normals differ by more than this are sharp.
    pub threshold_degrees: f64,
    /// Curves (connected sets of sharp edges) shorter than this are dropped.
    pub min_length: MinLength,
    /// Drop dangling ends: repeatedly remove sharp edges that end at an
    /// interior vertex touching no other sharp edge, so only closed curves
    /// and curves between other features or boundaries remain.
    pub prune_dangling: bool,
}

impl SharpOptions {
    /// Only the dihedral threshold (no filtering).
    pub fn threshold(degrees: f64) -> SharpOptions {
        SharpOptions { threshold_degrees: degrees, min_length: MinLength::None, prune_dangling: false }
    }
}

/// The creases a grid map follows where the caller gives no features
/// (`quads`, `solve --grid`): edges sharper than 75° on curves at least
/// 10 % of the bounding-box diagonal long, dropped on the components where
/// they fold the map ([`crate::pipeline::GridFeatures`]). A crease of
/// angle θ that a cell of size `s` crosses is cut off by up to about
/// s·sin(θ/2) (0.6 s at 75°): at 3 000 quads a cell is about 2 % of a
/// part's diagonal, so a CAD part's 90° creases cut across put the quads
/// 1.0-1.9 % of the diagonal from it (fandisk 1.36 %; followed, 0.72 %). Lower thresholds and shorter curves
/// catch the curvature of coarse organic meshes (above 60° on curves this
/// long: cow 97 edges, whose map then folds at 3 000 quads, and bff-face
/// 32, whose quads then lie 1.49 % of the diagonal from it against 0.75 %;
/// above 75°: cow 32 edges on 3 of its 47 curves, bff-face, spot, teapot
/// and bff-bunny none). Where a crease fades below 75° its curve ends
/// there (fandisk: 7 edges of 60-75° on two fading tails).
pub const CREASES: SharpOptions = SharpOptions {
    threshold_degrees: 75.0,
    min_length: MinLength::DiagonalFraction(0.10),
    prune_dangling: false,
};

/// What [`detect_sharp`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct SharpDetection {
    pub features: FeatureSet,
    pub stats: SharpStats,
}

/// Counts of [`detect_sharp`], for the page's slider and the CLI.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SharpStats {
    /// Edges above the threshold.
    pub sharp_edges: usize,
    /// Curves (connected sets of feature edges) kept, and their edges.
    pub curves: usize,
    pub kept_edges: usize,
    /// Curves dropped for being too short, and edges removed as dangling ends.
    pub dropped_fragments: usize,
    pub pruned_edges: usize,
}

/// Interior edges whose dihedral angle (between the two face normals)
/// exceeds `threshold_degrees`.
pub fn sharp_edges(mesh: &TriMesh, threshold_degrees: f64) -> FeatureSet {
    let threshold = threshold_degrees.to_radians();
    let mut set = FeatureSet::none(mesh);
    let dihedral = mesh.dihedral_angles();
    for e in 0..mesh.n_edges() as u32 {
        if !mesh.is_boundary_edge(e) {
            set.set(mesh, e, dihedral[e as usize] > threshold);
        }
    }
    set
}

/// Sharp edges filtered as `options` say (see [`SharpOptions`]).
pub fn detect_sharp(mesh: &TriMesh, options: &SharpOptions) -> SharpDetection {
    let mut features = sharp_edges(mesh, options.threshold_degrees);
    let mut stats = SharpStats { sharp_edges: features.len(), ..SharpStats::default() };
    if options.prune_dangling {
        stats.pruned_edges = prune_dangling(mesh, &mut features);
    }
    let curves = curves(mesh, &features);
    let diagonal = mesh.bounding_diagonal();
    for curve in &curves {
        let length: f64 = curve.iter().map(|&e| mesh.edge_length(e)).sum();
        let short = match options.min_length {
            MinLength::None => false,
            MinLength::Edges(n) => curve.len() < n,
            MinLength::DiagonalFraction(f) => length < f * diagonal,
        };
        if short {
            stats.dropped_fragments += 1;
            for &e in curve {
                features.set(mesh, e, false);
            }
        } else {
            stats.curves += 1;
        }
    }
    stats.kept_edges = features.len();
    SharpDetection { features, stats }
}

/// Connected sets of feature edges (joined at shared vertices), each as its edges.
pub fn curves(mesh: &TriMesh, features: &FeatureSet) -> Vec<Vec<u32>> {
    let mut seen = vec![false; mesh.n_edges()];
    let mut out = Vec::new();
    for start in features.edges() {
        if seen[start as usize] {
            continue;
        }
        seen[start as usize] = true;
        let mut curve = Vec::new();
        let mut stack = vec![start];
        while let Some(e) = stack.pop() {
            curve.push(e);
            for v in mesh.edge_vertices(e) {
                for h in mesh.outgoing(v) {
                    let g = mesh.edge(h);
                    if features.contains(g) && !seen[g as usize] {
                        seen[g as usize] = true;
                        stack.push(g);
                    }
                }
            }
        }
        out.push(curve);
    }
    out
}

/// Removes, until none is left, feature edges with an end at an interior
/// vertex that touches no other feature edge. Returns how many were removed.
fn prune_dangling(mesh: &TriMesh, features: &mut FeatureSet) -> usize {
    let degree = |features: &FeatureSet, v: u32| mesh.outgoing(v).filter(|&h| features.contains(mesh.edge(h))).count();
    let dangling = |features: &FeatureSet, v: u32| !mesh.is_boundary_vertex(v) && degree(features, v) == 1;
    let mut stack: Vec<u32> = (0..mesh.n_vertices() as u32).filter(|&v| dangling(features, v)).collect();
    let mut removed = 0;
    while let Some(v) = stack.pop() {
        if !dangling(features, v) {
            continue;
        }
        let h = mesh.outgoing(v).find(|&h| features.contains(mesh.edge(h))).expect("a dangling vertex has one feature edge");
        features.set(mesh, mesh.edge(h), false);
        removed += 1;
        let w = mesh.head(h);
        if dangling(features, w) {
            stack.push(w);
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `n` × `n` grid whose column `x = n / 2` is lifted by 1: the edges
    /// on that line are a ridge of 90°.
    fn creased(n: u32) -> TriMesh {
        crate::features::test_grid(n, |i, _| if i == n / 2 { 1.0 } else { 0.0 })
    }

    #[test]
    fn a_ridge_is_one_curve_that_length_filters_keep_or_drop() {
        let m = creased(4);
        let all = detect_sharp(&m, &SharpOptions::threshold(60.0));
        // The ridge line x = 2 has 4 edges; its two boundary ends are not features.
        assert_eq!(all.stats.curves, 1);
        assert_eq!(all.features.len(), all.stats.sharp_edges);
        let ridge = all.features.len();
        assert!(ridge >= 2);
        let long = detect_sharp(&m, &SharpOptions { min_length: MinLength::Edges(ridge + 1), ..SharpOptions::threshold(60.0) });
        assert_eq!((long.stats.curves, long.stats.dropped_fragments, long.features.len()), (0, 1, 0));
        let keep = detect_sharp(&m, &SharpOptions { min_length: MinLength::DiagonalFraction(1e-3), ..SharpOptions::threshold(60.0) });
        assert_eq!(keep.features, all.features);
    }

    #[test]
    fn pruning_removes_a_dangling_curve_but_keeps_one_between_boundaries() {
        let m = creased(4);
        let through = detect_sharp(&m, &SharpOptions { prune_dangling: true, ..SharpOptions::threshold(60.0) });
        let plain = detect_sharp(&m, &SharpOptions::threshold(60.0));
        // Every sharp edge of the ridge lies on a path from boundary to boundary.
        let boundary_to_boundary = plain.features.edges().all(|e| {
            let c = curves(&m, &plain.features);
            c.len() == 1 && c[0].contains(&e)
        });
        assert!(boundary_to_boundary);
        // A lone interior edge dangles at both ends and is pruned.
        let mut lone = FeatureSet::none(&m);
        let interior = (0..m.n_edges() as u32).find(|&e| m.edge_vertices(e).iter().all(|&v| !m.is_boundary_vertex(v))).unwrap();
        lone.set(&m, interior, true);
        assert_eq!(prune_dangling(&m, &mut lone), 1);
        assert!(lone.is_empty());
        assert_eq!((through.features, through.stats.pruned_edges), (plain.features, 0));
    }
}
