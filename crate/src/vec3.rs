//! Small 3-vector helpers on `[f64; 3]`, shared by every geometric module.

/// A point or vector in R³.
pub type V3 = [f64; 3];

/// `a − b`.
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// `a + b`.
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `s · a`.
#[inline]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// `a · b`.
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// `a × b`.
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
/// `|a|`.
#[inline]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// `(a + b) / 2`.
#[inline]
pub fn midpoint(a: V3, b: V3) -> V3 {
    scale(add(a, b), 0.5)
}

/// Corners `(lo, hi)` of the axis-aligned box around `points` (infinite,
/// inverted, for none); points of any dimension (3D positions, 2D UVs).
pub fn bounds<const N: usize>(points: &[[f64; N]]) -> ([f64; N], [f64; N]) {
    let mut lo = [f64::INFINITY; N];
    let mut hi = [f64::NEG_INFINITY; N];
    for p in points {
        for i in 0..N {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
}

/// Parameter `t ∈ [0, 1]` of the point of the segment `[a, b]` closest to
/// `p` (0 when `a == b`).
pub fn segment_parameter(p: V3, a: V3, b: V3) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The angle between `u` and `w`, in `[0, π]`.
pub fn angle(u: V3, w: V3) -> f64 {
    norm(cross(u, w)).atan2(dot(u, w))
}

/// Distance from `p` to the segment `[a, b]` (a point when `a == b`).
pub fn point_segment_distance(p: V3, a: V3, b: V3) -> f64 {
    let t = segment_parameter(p, a, b);
    norm(sub(p, add(a, scale(sub(b, a), t))))
}

/// Distance from `p` to the triangle `t` (see [`closest_point_barycentric`]).
pub fn point_triangle_distance(p: V3, t: &[V3; 3]) -> f64 {
    norm(sub(p, barycentric_point(t, closest_point_barycentric(p, t))))
}

/// The point `Σ bary[k] · t[k]`.
pub fn barycentric_point(t: &[V3; 3], bary: [f64; 3]) -> V3 {
    [0, 1, 2].map(|i| bary[0] * t[0][i] + bary[1] * t[1][i] + bary[2] * t[2][i])
}

/// Barycentric coordinates (each in `[0, 1]`, summing to 1) of the point of
/// the triangle `t` closest to `p`, by the closest-point regions of Ericson,
/// Real-Time Collision Detection §5.1.5; a zero-area triangle is treated as
/// its three edges.
pub fn closest_point_barycentric(p: V3, t: &[V3; 3]) -> [f64; 3] {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let n = cross(ab, ac);
    if !(dot(n, n) > 0.0) {
        let on_edge = |i: usize| {
            let j = (i + 1) % 3;
            let s = segment_parameter(p, t[i], t[j]);
            let mut bary = [0.0; 3];
            bary[i] = 1.0 - s;
            bary[j] = s;
            bary
        };
        let distance = |bary: &[f64; 3]| norm(sub(p, barycentric_point(t, *bary)));
        let candidates = [on_edge(0), on_edge(1), on_edge(2)];
        return candidates.into_iter().min_by(|x, y| distance(x).total_cmp(&distance(y))).unwrap_or([1.0, 0.0, 0.0]);
    }
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    // Inside: the projection onto the plane.
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}
