//! The integer forms of quantization: the linear forms of the wedge
//! unknowns that the integer-grid map makes integers (singular points,
//! isolines, seam translations), the ends of feature curves inside the
//! mesh, and the per-unknown and per-form tables the rounding looks them up
//! in. Set up once per parametrization by [`super::Quantizer::new`].

use crate::cones::ConePlacement;
use crate::features::CutMesh;
use crate::mesh::{TriMesh, UnionFind};
use crate::param::cut_graph::CutGraph;
use crate::param::element::Element;
use crate::param::seamless::{curve_rotation, curve_wedge_pairs, RowSet};
use serde::Serialize;
use std::f64::consts::{FRAC_PI_4, PI};

/// Feature curves shorter than this many grid cells keep their inner ends
/// off the grid points ([`CurveEnd`]).
pub(super) const CURVE_END_CELLS: f64 = 1.0;

/// What an integer form pins down.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub(super) enum FormKind {
    /// A coordinate of an interior cone's wedge.
    Cone,
    /// A coordinate of a singular boundary or feature point's wedge, or an isoline's constant.
    Point,
    /// A component of a seam curve's translation `t = f_g(a) - r f_f(a)`.
    Translation,
}

/// The end of a feature curve inside the mesh: the form of its coordinate
/// along the curve, and the curve's length (model units). Where the curve
/// is shorter than [`CURVE_END_CELLS`] cells the form is left free: only
/// the isoline is an integer (its two ends on grid points would squeeze
/// it to a point or stretch it to a cell).
#[derive(Clone, Copy, Debug)]
pub(super) struct CurveEnd {
    pub(super) form: usize,
    pub(super) length: f64,
}

impl CurveEnd {
    /// Whether the end is left free at grid size `s`.
    #[inline]
    pub(super) fn free_at(&self, s: f64) -> bool {
        self.length < CURVE_END_CELLS * s
    }
}

/// A linear form of the unknowns that must take an integer value.
#[derive(Clone, Debug)]
pub(super) struct Form {
    pub(super) row: Vec<(usize, i64)>,
    pub(super) kind: FormKind,
    /// Change of the form under translations `d_c` of the disk components
    /// (indices into the pins): `sum (2 c + k, a) a d_c[k]`. A seam
    /// translation between two components responds to both.
    pub(super) response: Vec<(usize, i64)>,
}

impl Form {
    #[inline]
    pub(super) fn value(&self, x: &[f64]) -> f64 {
        self.row.iter().map(|&(i, c)| c as f64 * x[i]).sum()
    }
}

/// Per unknown: whether the integer-grid map makes it an integer: both
/// coordinates of every wedge of a `singular` cut vertex
/// ([`singular_cut_vertices`]) and every form of a single unknown.
pub(super) fn integral_unknowns(
    mesh: &TriMesh,
    placement: &ConePlacement,
    cut: &CutGraph,
    vars: &[Vec<usize>; 2],
    singular: &[bool],
    n_unknowns: usize,
    forms: &[Form],
) -> Vec<bool> {
    let cm = &placement.cut.mesh;
    let mut integral = vec![false; n_unknowns];
    for f in 0..mesh.n_faces() {
        for k in 0..3 {
            if singular[cm.faces()[f][k] as usize] {
                let w = cut.wedge[3 * f + k] as usize;
                integral[vars[0][w]] = true;
                integral[vars[1][w]] = true;
            }
        }
    }
    for form in forms {
        if let [(u, 1)] = form.row.as_slice() {
            integral[*u] = true;
        }
    }
    integral
}

/// Per cut vertex: whether its UV angle sum (`sums`) is off the straight
/// angle (2 pi inside, pi on the boundary) by more than pi / 4.
pub(super) fn singular_cut_vertices(cm: &TriMesh, sums: &[f64]) -> Vec<bool> {
    (0..cm.n_vertices() as u32)
        .map(|v| {
            let straight = if cm.is_boundary_vertex(v) { PI } else { 2.0 * PI };
            (sums[v as usize] - straight).abs() > FRAC_PI_4
        })
        .collect()
}

/// The ends of feature curves inside the mesh (a cut boundary vertex of an
/// interior vertex, UV angle sum in `sums` 2 pi: the isoline runs straight
/// on through it), each as the form of its coordinate along the curve and the curve's
/// length in the seamless map `seamless` (the extent of its isoline's
/// wedges along it).
pub(super) fn curve_ends(
    mesh: &TriMesh,
    cut_mesh: &CutMesh,
    sums: &[f64],
    isoline: &[u8],
    cut: &CutGraph,
    vars: &[Vec<usize>; 2],
    form_of: &[usize],
    seamless: &[f64],
) -> Vec<CurveEnd> {
    let cm = &cut_mesh.mesh;
    let is_end = |v: u32| {
        cm.is_boundary_vertex(v)
            && !mesh.is_boundary_vertex(cut_mesh.original_vertex[v as usize])
            && (sums[v as usize] - 2.0 * PI).abs() < FRAC_PI_4
    };
    // Per isoline unknown: the extent of its wedges along the other coordinate.
    let mut extent: std::collections::HashMap<usize, (f64, f64)> = Default::default();
    for w in 0..vars[0].len() {
        for c in 0..2 {
            if form_of[vars[c][w]] != usize::MAX {
                let y = seamless[vars[1 - c][w]];
                let e = extent.entry(vars[c][w]).or_insert((y, y));
                *e = (e.0.min(y), e.1.max(y));
            }
        }
    }
    let mut ends = Vec::new();
    let mut seen = vec![false; cm.n_vertices()];
    for (f, face) in cm.faces().iter().enumerate() {
        for k in 0..3 {
            let v = face[k];
            // The isoline's coordinate: that of a feature halfedge at this corner.
            let Some(c) = [3 * f + k, 3 * f + (k + 2) % 3].iter().map(|&h| isoline[h] as usize).find(|&c| c < 2) else { continue };
            if seen[v as usize] || !is_end(v) {
                continue;
            }
            seen[v as usize] = true;
            let w = cut.wedge[3 * f + k] as usize;
            let Some(&(lo, hi)) = extent.get(&vars[c][w]) else { continue };
            let form = form_of[vars[1 - c][w]];
            if form != usize::MAX {
                ends.push(CurveEnd { form, length: hi - lo });
            }
        }
    }
    ends
}

/// Per unknown: the form that is that unknown alone (a singular point's
/// coordinate or an isoline constant), `usize::MAX` where there is none.
pub(super) fn single_unknown_forms(forms: &[Form], n_unknowns: usize) -> Vec<usize> {
    let mut form_of = vec![usize::MAX; n_unknowns];
    for (i, f) in forms.iter().enumerate() {
        if let (FormKind::Cone | FormKind::Point, [(u, 1)]) = (f.kind, f.row.as_slice()) {
            form_of[*u] = i;
        }
    }
    form_of
}

/// Per form: the triples of distinct-enough single-unknown forms that hold
/// the same coordinate of the three corners of some triangle.
pub(super) fn collapse_triples(elements: &[Element], forms: &[Form], form_of: &[usize]) -> Vec<Vec<[usize; 3]>> {
    let mut triples = vec![Vec::new(); forms.len()];
    for el in elements {
        for c in 0..2 {
            let t = el.x[c].map(|u| form_of[u]);
            if t.contains(&usize::MAX) || (t[0] == t[1] && t[1] == t[2]) {
                continue;
            }
            for &i in &t {
                if !triples[i].contains(&t) {
                    triples[i].push(t);
                }
            }
        }
    }
    triples
}

/// Disk component (index of its pin in `cut.pins`) of every wedge.
pub(super) fn wedge_components(cut: &CutGraph) -> Vec<usize> {
    let mut uf = UnionFind::new(cut.n_wedges);
    for f in cut.wedge.chunks(3) {
        uf.union(f[0], f[1]);
        uf.union(f[0], f[2]);
    }
    let mut of_root = vec![usize::MAX; cut.n_wedges];
    for (i, &p) in cut.pins.iter().enumerate() {
        let r = uf.find(p) as usize;
        of_root[r] = i;
    }
    (0..cut.n_wedges as u32)
        .map(|w| of_root[uf.find(w) as usize])
        .collect()
}

/// The integer forms: both coordinates of one wedge of every singular point
/// (a cut-mesh vertex whose UV angle is off straight by more than pi/4), the
/// constant of every isoline class, and both components of every seam
/// curve's translation. Duplicates (the same row) are listed once.
///
/// One wedge per point: its other wedges follow from it through seam
/// translations with unit coefficients, whereas two wedges of points
/// rounded first can determine a third point with coefficient 1/2 (a
/// half-turn seam between cones: `f_g(b) + f_f(b) = 2 p_a`).
pub(super) fn integer_forms(
    mesh: &TriMesh,
    placement: &ConePlacement,
    isoline: &[u8],
    cut: &CutGraph,
    vars: &[Vec<usize>; 2],
    component: &[usize],
    singular: &[bool],
) -> Vec<Form> {
    let cm = &placement.cut.mesh;
    let mut set = RowSet::default();
    let mut forms = Vec::new();
    let mut push = |mut row: Vec<(usize, i64)>, kind: FormKind, response: Vec<(usize, i64)>, forms: &mut Vec<Form>| {
        if set.push(&mut row) {
            forms.push(Form { row: set.rows[set.rows.len() - 1].clone(), kind, response });
        }
    };
    let mut represented = vec![false; cm.n_vertices()];
    for (f, face) in cm.faces().iter().enumerate() {
        for k in 0..3 {
            let cv = face[k] as usize;
            if singular[cv] && !std::mem::replace(&mut represented[cv], true)
            {
                let w = cut.wedge[3 * f + k] as usize;
                let kind = if cm.is_boundary_vertex(face[k]) {
                    FormKind::Point
                } else {
                    FormKind::Cone
                };
                for c in 0..2 {
                    push(vec![(vars[c][w], 1)], kind, vec![(2 * component[w] + c, 1)], &mut forms);
                }
            }
        }
    }
    for h in 0..3 * mesh.n_faces() {
        let c = isoline[h] as usize;
        if c < 2 {
            let w = cut.wedge[h] as usize;
            push(vec![(vars[c][w], 1)], FormKind::Point, vec![(2 * component[w] + c, 1)], &mut forms);
        }
    }
    for curve in &cut.curves {
        let r = curve_rotation(curve.matching);
        let (fa, ga) = curve_wedge_pairs(mesh, cut, curve)[0];
        for c in 0..2 {
            // t_c = f_g(a)_c - sum_d r[c][d] f_f(a)_d; a translation d of the disk moves it by ((I - r) d)_c.
            let mut row: Vec<(usize, i64)> = vec![(vars[c][ga as usize], 1)];
            row.extend(
                (0..2)
                    .filter(|&d| r[c][d] != 0)
                    .map(|d| (vars[d][fa as usize], -r[c][d])),
            );
            // Translations d_g, d_f of the two sides' components move it by
            // (d_g - r d_f)_c (the sides may lie in different components).
            let (cg, cf) = (component[ga as usize], component[fa as usize]);
            let mut response = vec![(2 * cg + c, 1)];
            for d in (0..2).filter(|&d| r[c][d] != 0) {
                match response.iter_mut().find(|(t, _)| *t == 2 * cf + d) {
                    Some(entry) => entry.1 -= r[c][d],
                    None => response.push((2 * cf + d, -r[c][d])),
                }
            }
            response.retain(|&(_, a)| a != 0);
            push(row, FormKind::Translation, response, &mut forms);
        }
    }
    forms
}
