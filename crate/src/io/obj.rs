//! Wavefront OBJ import: hand-rolled byte parsing, no allocation per line.
//!
//! Read: `v x y z [w | r g b]` (extra components ignored) and `f` lines
//! (`v`, `v/vt`, `v//vn`, `v/vt/vn` corners, negative = relative indices,
//! polygons fan-triangulated from their first corner). Everything else (`vt`,
//! `vn`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, comments, unknown statements)
//! is skipped. A line ending in `\` continues on the next line.
//!
//! Indices past the vertex list are kept (a positive index `i` is stored as
//! `i - 1`, a relative index before the first vertex as `u32::MAX`):
//! [`crate::mesh::analyze`] reports them as `IndexOutOfRange`.

use super::InputFile;
use crate::{ImportError, RawMesh};

/// Parses an OBJ file: `v` lines and `f` lines (polygons fan-triangulated,
/// negative indices, `v`, `v/vt`, `v//vn`, `v/vt/vn` forms).
pub fn import(file: &InputFile) -> Result<RawMesh, ImportError> {
    import_numbered(file).map(|(mesh, _)| mesh)
}

/// Like [`import`], also returning the 1-based `f` statement each triangle
/// came from (see [`super::FileNumbering::Obj`]).
pub fn import_numbered(file: &InputFile) -> Result<(RawMesh, Vec<u32>), ImportError> {
    let (mesh, faces) = parse_numbered(&file.bytes)?;
    if mesh.triangles.is_empty() {
        return Err(ImportError::NoTriangles { name: file.name.clone() });
    }
    Ok((mesh, faces))
}

/// Parses OBJ bytes (any encoding: only ASCII statements are interpreted).
/// An empty result is not an error here; [`import`] turns it into `NoTriangles`.
pub fn parse(bytes: &[u8]) -> Result<RawMesh, ImportError> {
    parse_numbered(bytes).map(|(mesh, _)| mesh)
}

/// [`parse`], with the 1-based `f` statement of each triangle.
fn parse_numbered(bytes: &[u8]) -> Result<(RawMesh, Vec<u32>), ImportError> {
    let mut st = State {
        positions: Vec::with_capacity(bytes.len() / 80),
        triangles: Vec::with_capacity(bytes.len() / 40),
        poly: Vec::with_capacity(8),
        faces: 0,
        face_of_triangle: Vec::with_capacity(bytes.len() / 40),
    };
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut joined: Vec<u8> = Vec::new();
    while pos < bytes.len() {
        let end = memchr_nl(bytes, pos);
        line_no += 1;
        let first_line = line_no;
        let mut line = trim_cr(&bytes[pos..end]);
        pos = end + 1;
        if line.last() == Some(&b'\\') {
            // Line continuation: glue the pieces with a space.
            joined.clear();
            joined.extend_from_slice(&line[..line.len() - 1]);
            while pos < bytes.len() {
                let end = memchr_nl(bytes, pos);
                line_no += 1;
                let next = trim_cr(&bytes[pos..end]);
                pos = end + 1;
                joined.push(b' ');
                if next.last() == Some(&b'\\') {
                    joined.extend_from_slice(&next[..next.len() - 1]);
                } else {
                    joined.extend_from_slice(next);
                    break;
                }
            }
            line = &joined;
            st.line(line).map_err(|d| malformed(first_line, d))?;
            continue;
        }
        st.line(line).map_err(|d| malformed(first_line, d))?;
    }
    Ok((RawMesh { positions: st.positions, triangles: st.triangles }, st.face_of_triangle))
}

fn malformed(line: usize, detail: String) -> ImportError {
    ImportError::Malformed { format: "OBJ", detail: format!("line {line}: {detail}") }
}

#[inline]
fn memchr_nl(bytes: &[u8], from: usize) -> usize {
    match bytes[from..].iter().position(|&b| b == b'\n') {
        Some(i) => from + i,
        None => bytes.len(),
    }
}

#[inline]
fn trim_cr(line: &[u8]) -> &[u8] {
    match line.last() {
        Some(b'\r') => &line[..line.len() - 1],
        _ => line,
    }
}

#[inline]
fn is_ws(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == 0x0b || b == 0x0c
}

struct State {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    poly: Vec<u32>,
    /// `f` statements read so far, and the (1-based) one of each triangle.
    faces: u32,
    face_of_triangle: Vec<u32>,
}

/// Splits off the next whitespace-separated token at or after `*p`.
#[inline]
fn token<'a>(line: &'a [u8], p: &mut usize) -> Option<&'a [u8]> {
    let mut i = *p;
    while i < line.len() && is_ws(line[i]) {
        i += 1;
    }
    if i >= line.len() {
        *p = i;
        return None;
    }
    let start = i;
    while i < line.len() && !is_ws(line[i]) {
        i += 1;
    }
    *p = i;
    Some(&line[start..i])
}

impl State {
    fn line(&mut self, line: &[u8]) -> Result<(), String> {
        let mut p = 0;
        let Some(keyword) = token(line, &mut p) else { return Ok(()) };
        match keyword {
            b"v" => {
                let mut xyz = [0.0f64; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let t = token(line, &mut p).ok_or_else(|| format!("vertex has {k} coordinates, needs 3"))?;
                    *c = parse_f64(t).ok_or_else(|| format!("bad number \"{}\"", show(t)))?;
                }
                self.positions.push(xyz);
            }
            b"f" => {
                self.poly.clear();
                let nv = self.positions.len() as i64;
                while let Some(t) = token(line, &mut p) {
                    if t[0] == b'#' {
                        break;
                    }
                    let idx = t.split(|&b| b == b'/').next().unwrap_or(t);
                    let i = parse_i64(idx).ok_or_else(|| format!("bad face index \"{}\"", show(t)))?;
                    let resolved = if i > 0 {
                        i - 1
                    } else if i < 0 {
                        nv + i
                    } else {
                        return Err("face index 0 (OBJ indices start at 1)".into());
                    };
                    let v = if (0..u32::MAX as i64).contains(&resolved) { resolved as u32 } else { u32::MAX };
                    self.poly.push(v);
                }
                if self.poly.len() < 3 {
                    return Err(format!("face has {} vertices, needs at least 3", self.poly.len()));
                }
                let v0 = self.poly[0];
                self.faces += 1;
                for w in self.poly[1..].windows(2) {
                    self.triangles.push([v0, w[0], w[1]]);
                    self.face_of_triangle.push(self.faces);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// A token for an error message (lossy, shortened).
fn show(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(t);
    if s.chars().count() > 40 {
        s.chars().take(40).collect::<String>() + "…"
    } else {
        s.into_owned()
    }
}

fn parse_i64(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &b in digits {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (b - b'0') as i64;
    }
    Some(if neg { -v } else { v })
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19,
    1e20, 1e21, 1e22,
];

/// Parses a decimal number. Fast path for `[+-]digits[.digits]` with at most
/// 19 digits whose value fits 2^53 (then `mantissa / 10^k` is exactly the
/// correctly rounded result, as with `str::parse`); anything else (exponents,
/// `inf`, `nan`, long mantissas) goes to `str::parse::<f64>`.
fn parse_f64(t: &[u8]) -> Option<f64> {
    let (neg, body) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    let mut i = 0;
    let mut mant: u64 = 0;
    let mut ndig = 0usize;
    while i < body.len() && body[i].is_ascii_digit() {
        mant = mant.wrapping_mul(10).wrapping_add((body[i] - b'0') as u64);
        ndig += 1;
        i += 1;
    }
    let mut frac = 0usize;
    if i < body.len() && body[i] == b'.' {
        i += 1;
        while i < body.len() && body[i].is_ascii_digit() {
            mant = mant.wrapping_mul(10).wrapping_add((body[i] - b'0') as u64);
            ndig += 1;
            frac += 1;
            i += 1;
        }
    }
    if i == body.len() && ndig > 0 && ndig <= 19 && mant <= (1u64 << 53) && frac <= 22 {
        let v = mant as f64 / POW10[frac];
        return Some(if neg { -v } else { v });
    }
    std::str::from_utf8(t).ok()?.parse::<f64>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obj(s: &[u8]) -> Result<RawMesh, ImportError> {
        import(&InputFile { name: "t.obj".into(), bytes: s.to_vec() })
    }

    #[test]
    fn forms_polygons_and_relative_indices() {
        let m = obj(b"# c\r\nv 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
            o a\ng b\ns 1\nusemtl m\nf 1/1/1 2/1/1 3//1 4\r\nf -4 -3 -2\nl 1 2\n")
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
        let (_, faces) = parse_numbered(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3\n").unwrap();
        assert_eq!(faces, vec![1, 1, 2], "a quad's two triangles come from f statement 1");
    }

    #[test]
    fn continuation_and_out_of_range() {
        let m = obj(b"v 0 0 0\nv 1 0 \\\n 0\nv 0 1 0\nf 1 2 \\\n 3\nf 1 2 9\nf -9 1 2\n").unwrap();
        assert_eq!(m.positions.len(), 3);
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 8], [u32::MAX, 0, 1]]);
    }

    #[test]
    fn errors_with_line_numbers() {
        let e = obj(b"v 0 0 0\nv 1 x 0\n").unwrap_err();
        assert_eq!(e.to_string(), "malformed OBJ file: line 2: bad number \"x\"");
        let e = obj(b"v 0 0 0\n\nf 0 1 2\n").unwrap_err();
        assert!(e.to_string().contains("line 3: face index 0"), "{e}");
        let e = obj(b"v 0 0 0\nf 1 1\n").unwrap_err();
        assert!(e.to_string().contains("line 2: face has 2 vertices"), "{e}");
        let e = obj(b"v 0 0\n").unwrap_err();
        assert!(e.to_string().contains("line 1: vertex has 2 coordinates"), "{e}");
        assert!(matches!(obj(b"v 0 0 0\n"), Err(ImportError::NoTriangles { .. })));
        let e = obj(b"v 0 0 0\nf 1 2 a\n").unwrap_err();
        assert!(e.to_string().contains("line 2: bad face index \"a\""), "{e}");
    }

    #[test]
    fn non_utf8_does_not_panic() {
        let m = obj(b"# \xff\xfe\nv 0 0 0\nv 1 0 0\nv 0 1 0\ng \xc3\x28\nf 1 2 3\n").unwrap();
        assert_eq!(m.triangles.len(), 1);
        assert!(obj(b"v \xff 0 0\nf 1 1 1\n").is_err());
    }

    #[test]
    fn numbers_match_std_parse() {
        for s in ["0", "-0.0", "1.5", "0.1", "-2.292449", "123456789.123456789", "1e-3", "1E5", "nan", "inf",
            ".5", "5.", "+3.25", "0.30000000000000004", "9007199254740993", "1234567890123456789012"]
        {
            let a = parse_f64(s.as_bytes()).unwrap();
            let b: f64 = s.parse().unwrap();
            assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "{s}: {a} vs {b}");
        }
        for s in ["", "-", ".", "1.2.3", "abc", "1,5"] {
            assert!(parse_f64(s.as_bytes()).is_none(), "{s}");
        }
    }
}
