//! Wavefront OBJ writer.
//!
//! * `v`: one per source vertex used by a face, in source order, printed with
//!   Rust's shortest round-trip formatting of the f64 position;
//! * `vt`: one per output vertex (distinct (source vertex, UV) wedge),
//!   normalised UVs `(u', v')`, origin bottom-left (see the module
//!   documentation of [`crate::export`]);
//! * `vn`: one per welded vertex (area-weighted normals), or one per used
//!   source vertex when the source supplied normals;
//! * `f v/vt/vn` per triangle, in input order; `g` per output group when
//!   there is more than one.

use super::{generator, ExportInput, ExportOptions};
use std::fmt::Write;

/// The OBJ text of `input`.
pub fn write_obj(input: &ExportInput, options: &ExportOptions) -> String {
    let layout = input.layout(&input.written_uv(options));
    let normals = input.normals();
    let norm = input.uv_normalization(options);
    let raw = input.raw;
    let s2w = input.mesh.source_to_welded();
    let per_source_normals = input.source.as_ref().is_some_and(|s| s.normals.iter().any(Option::is_some));

    let mut out = String::with_capacity(64 * raw.triangles.len());
    let _ = writeln!(out, "# {}", generator());
    let _ = writeln!(out, "# UVs normalised: vt = ((u - {:?}) * {:?}, (v - {:?}) * {:?})", norm.offset[0], norm.scale, norm.offset[1], norm.scale);
    for note in &input.notes {
        let _ = writeln!(out, "# note: {}", note.replace(['\n', '\r'], " "));
    }
    if let Some(name) = &options.name {
        let _ = writeln!(out, "o {}", name.replace(['\n', '\r'], " "));
    }

    // v: used source vertices, renumbered in source order (1-based).
    let mut v_index = vec![0u32; raw.positions.len()];
    for t in &raw.triangles {
        for &s in t {
            v_index[s as usize] = 1;
        }
    }
    let mut next = 0u32;
    for (s, slot) in v_index.iter_mut().enumerate() {
        if *slot != 0 {
            next += 1;
            *slot = next;
            let p = input.position(s as u32);
            let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
        }
    }

    // vn: per welded vertex, or per used source vertex.
    let n_index: Vec<u32> = if per_source_normals {
        for (s, &i) in v_index.iter().enumerate() {
            if i != 0 {
                write_normal(&mut out, normals[s]);
            }
        }
        v_index.clone()
    } else {
        let mut first_source = vec![u32::MAX; input.mesh.n_vertices()];
        for (s, &w) in s2w.iter().enumerate() {
            if (w as usize) < first_source.len() && first_source[w as usize] == u32::MAX {
                first_source[w as usize] = s as u32;
            }
        }
        for &s in &first_source {
            write_normal(&mut out, if s == u32::MAX { [0.0, 0.0, 1.0] } else { normals[s as usize] });
        }
        // Welded vertex w is vn w + 1.
        s2w.iter().map(|&w| w.wrapping_add(1)).collect()
    };

    // vt: one per wedge, group after group.
    let mut vt_base = Vec::with_capacity(layout.groups.len());
    let mut count = 0u32;
    for g in &layout.groups {
        vt_base.push(count);
        for w in &g.wedges {
            let [u, v] = norm.apply(w.uv);
            let _ = writeln!(out, "vt {u} {v}");
        }
        count += g.wedges.len() as u32;
    }

    let many = layout.groups.len() > 1;
    for (gi, g) in layout.groups.iter().enumerate() {
        if many {
            let _ = writeln!(out, "g group{gi}");
        }
        for t in &g.triangles {
            out.push('f');
            for &local in t {
                let w = g.wedges[local as usize];
                let s = w.source as usize;
                let _ = write!(out, " {}/{}/{}", v_index[s], vt_base[gi] + local + 1, n_index[s]);
            }
            out.push('\n');
        }
    }
    out
}

fn write_normal(out: &mut String, n: [f64; 3]) {
    let _ = writeln!(out, "vn {} {} {}", n[0] as f32, n[1] as f32, n[2] as f32);
}
