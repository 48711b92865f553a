//! A mesh of several parts quantized one part at a time. The parts (the
//! components of the mesh: a game asset's planks, beams and boards) share
//! no unknown, so each is rounded as it would be alone: its own KKT, its own
//! budgets of extra solves, its own passes and grid-size retries. A pass
//! then re-runs only the part it may mend, and a small part's forms are
//! never rounded in one batch of the whole mesh without a solve between
//! them.

use super::{CurveEnd, Form, Quantizer, TubePeriod};
use crate::param::element::Element;

/// One component of the mesh as a quantizer of its own, and where its
/// unknowns and forms sit in the whole.
pub(super) struct Part {
    pub(super) quantizer: Quantizer,
    /// Index in the whole of each of the part's unknowns.
    pub(super) unknown: Vec<usize>,
    /// Index in the whole of each of the part's forms.
    pub(super) form: Vec<usize>,
}

/// Per entity of the whole (face, vertex, wedge, unknown, form, pin): its
/// part and its index within the part (entities keep their order).
struct Numbering {
    part: Vec<usize>,
    local: Vec<usize>,
    /// Per part: its entities, by their index in the whole.
    members: Vec<Vec<usize>>,
}

impl Numbering {
    /// Entities numbered within their parts in order of their index.
    fn new(part: Vec<usize>, n_parts: usize) -> Numbering {
        let mut members = vec![Vec::new(); n_parts];
        let local = part
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                members[c].push(i);
                members[c].len() - 1
            })
            .collect();
        Numbering { part, local, members }
    }

    /// The entities of part `c`, by their index in the whole.
    fn of(&self, c: usize) -> impl Iterator<Item = usize> + '_ {
        self.members[c].iter().copied()
    }
}

impl Part {
    /// The parts of `q`, one per component of the mesh (`face_part`: the
    /// component of every face, `n_parts` of them). Each part's quantizer
    /// holds the part's elements, seam rows, forms and pins renumbered;
    /// O(size of `q`) in all.
    pub(super) fn split(q: &Quantizer, face_part: &[usize], n_parts: usize) -> Vec<Part> {
        let n_wedges = q.vars[0].len();
        let (mut vertex_part, mut wedge_part) = (vec![0usize; q.angle_sums.len()], vec![0usize; n_wedges]);
        for (f, el) in q.elements.iter().enumerate() {
            for k in 0..3 {
                vertex_part[q.faces[f][k] as usize] = face_part[f];
                wedge_part[el.w[k]] = face_part[f];
            }
        }
        let mut unknown_part = vec![0usize; q.n_unknowns];
        for (w, &c) in wedge_part.iter().enumerate() {
            for k in 0..2 {
                unknown_part[q.vars[k][w]] = c;
            }
        }
        let first_part = |row: &[(usize, i64)]| row.first().map_or(0, |&(u, _)| unknown_part[u]);
        let faces = Numbering::new(face_part.to_vec(), n_parts);
        let vertices = Numbering::new(vertex_part, n_parts);
        let wedges = Numbering::new(wedge_part, n_parts);
        let rows = Numbering::new(q.seam_rows.iter().map(|r| first_part(r)).collect(), n_parts);
        let forms = Numbering::new(q.forms.iter().map(|f| first_part(&f.row)).collect(), n_parts);
        let period_part: Vec<usize> = q.tube_periods.iter().map(|p| first_part(&p.rows[0])).collect();
        let pins = Numbering::new(q.pins.iter().map(|p| unknown_part[p[0]]).collect(), n_parts);
        let unknowns = Numbering::new(unknown_part, n_parts);
        let unknown = |u: usize| unknowns.local[u];
        let row = |r: &[(usize, i64)]| r.iter().map(|&(u, a)| (unknown(u), a)).collect::<Vec<_>>();
        (0..n_parts)
            .map(|c| {
                let face_ids: Vec<usize> = faces.of(c).collect();
                let form_ids: Vec<usize> = forms.of(c).collect();
                let unknown_ids: Vec<usize> = unknowns.of(c).collect();
                let wedge_ids: Vec<usize> = wedges.of(c).collect();
                let elements = face_ids
                    .iter()
                    .map(|&f| {
                        let el = &q.elements[f];
                        Element { w: el.w.map(|w| wedges.local[w]), x: el.x.map(|x| x.map(unknown)), g: el.g, area: el.area }
                    })
                    .collect();
                let forms_c = form_ids
                    .iter()
                    .map(|&i| {
                        let form = &q.forms[i];
                        // A response (2 p + k, a) is to the translation of pin p's component.
                        let response = form.response.iter().map(|&(t, a)| (2 * pins.local[t / 2] + t % 2, a)).collect();
                        Form { row: row(&form.row), kind: form.kind, response }
                    })
                    .collect();
                let seamless_areas: Vec<f64> = face_ids.iter().map(|&f| q.seamless_areas[f]).collect();
                let quantizer = Quantizer {
                    wedge: face_ids.iter().flat_map(|&f| &q.wedge[3 * f..3 * f + 3]).map(|&w| wedges.local[w as usize] as u32).collect(),
                    vars: [0, 1].map(|k| wedge_ids.iter().map(|&w| unknown(q.vars[k][w])).collect()),
                    n_unknowns: unknown_ids.len(),
                    seam_rows: rows.of(c).map(|r| row(&q.seam_rows[r])).collect(),
                    triples: form_ids.iter().map(|&i| q.triples[i].iter().map(|t| t.map(|j| forms.local[j])).collect()).collect(),
                    integral: unknown_ids.iter().map(|&u| q.integral[u]).collect(),
                    curve_ends: q
                        .curve_ends
                        .iter()
                        .filter(|end| forms.part[end.form] == c)
                        .map(|end| CurveEnd { form: forms.local[end.form], length: end.length })
                        .collect(),
                    form_of: unknown_ids.iter().map(|&u| q.form_of[u]).map(|i| if i == usize::MAX { i } else { forms.local[i] }).collect(),
                    tube_periods: q
                        .tube_periods
                        .iter()
                        .zip(&period_part)
                        .filter(|&(_, &part)| part == c)
                        .map(|(p, _)| p)
                        .map(|p| TubePeriod { rows: [row(&p.rows[0]), row(&p.rows[1])] })
                        .collect(),
                    pins: pins.of(c).map(|p| q.pins[p].map(unknown)).collect(),
                    seamless: unknown_ids.iter().map(|&u| q.seamless[u]).collect(),
                    map_area: seamless_areas.iter().map(|a| a.max(0.0)).sum(),
                    seamless_areas,
                    faces: face_ids.iter().map(|&f| q.faces[f].map(|v| vertices.local[v as usize] as u32)).collect(),
                    angle_sums: vertices.of(c).map(|v| q.angle_sums[v]).collect(),
                    on_boundary: vertices.of(c).map(|v| q.on_boundary[v]).collect(),
                    distortion_before: q.distortion_before,
                    elements,
                    forms: forms_c,
                    parts: Vec::new(),
                };
                Part { quantizer, unknown: unknown_ids, form: form_ids }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cones::test_meshes::three_parts;
    use crate::cones::{place_cones, ConeOptions};
    use crate::features::FeatureSet;
    use crate::param::{parametrize, ParamOptions};

    /// Every part's quantizer is the whole's restricted to the part: the
    /// same Jacobians, form values and kinds, seam rows, single-unknown
    /// forms and pins (through the part's renumbering).
    #[test]
    fn a_part_is_the_whole_restricted_to_it() {
        let mesh = three_parts();
        assert_eq!(mesh.n_components(), 3);
        let placement = place_cones(&mesh, &FeatureSet::none(&mesh), &ConeOptions::default(), &mut |_| {}).unwrap();
        let param = parametrize(&mesh, &placement, &ParamOptions::default(), &mut |_| {}).unwrap();
        let whole = Quantizer::new(&mesh, &placement, &param).unwrap();
        assert_eq!(whole.parts.len(), 3);
        let sum = |f: &dyn Fn(&Quantizer) -> usize| whole.parts.iter().map(|p| f(&p.quantizer)).sum::<usize>();
        assert_eq!(sum(&|q| q.elements.len()), whole.elements.len());
        assert_eq!(sum(&|q| q.n_unknowns), whole.n_unknowns);
        assert_eq!(sum(&|q| q.forms.len()), whole.forms.len());
        assert_eq!(sum(&|q| q.seam_rows.len()), whole.seam_rows.len());
        assert_eq!(sum(&|q| q.pins.len()), whole.pins.len());
        assert_eq!(sum(&|q| q.curve_ends.len()), whole.curve_ends.len());
        let mut whole_face = (0..mesh.n_faces()).map(|f| (mesh.face_components()[f], f)).collect::<Vec<_>>();
        whole_face.sort();
        let mut faces = whole_face.iter().map(|&(_, f)| f);
        for part in &whole.parts {
            let q = &part.quantizer;
            assert!(q.parts.is_empty() && !q.forms.is_empty());
            for (u, &g) in part.unknown.iter().enumerate() {
                assert_eq!(q.seamless[u], whole.seamless[g]);
                assert_eq!(q.integral[u], whole.integral[g]);
                let own = q.form_of[u];
                assert_eq!(if own == usize::MAX { own } else { part.form[own] }, whole.form_of[g]);
            }
            for el in &q.elements {
                let f = faces.next().unwrap();
                assert_eq!(el.jacobian(&q.seamless), whole.elements[f].jacobian(&whole.seamless));
                assert_eq!(el.area, whole.elements[f].area);
            }
            let pin_unknown = |q: &Quantizer, t: usize| q.pins[t / 2][t % 2];
            for (form, &g) in q.forms.iter().zip(&part.form) {
                let w = &whole.forms[g];
                assert_eq!((form.kind, form.value(&q.seamless)), (w.kind, w.value(&whole.seamless)));
                assert_eq!(form.response.len(), w.response.len());
                for (&(t, a), &(tw, aw)) in form.response.iter().zip(&w.response) {
                    assert_eq!((part.unknown[pin_unknown(q, t)], a), (pin_unknown(&whole, tw), aw));
                }
            }
            for row in &q.seam_rows {
                let r: f64 = row.iter().map(|&(u, a)| a as f64 * q.seamless[u]).sum();
                assert!(r.abs() < 1e-9, "seam row residual {r}");
                assert!(row.iter().all(|&(u, _)| u < q.n_unknowns));
            }
        }
    }
}
