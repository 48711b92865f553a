//! Untangling of a seamless map that the fold-over repair left with flipped
//! triangles: the regularized barrier of Garanzha, Kaporin, Kudryavtseva,
//! Protais, Ray and Sokolov 2021 ("Foldover-free maps in 50 lines of code"),
//! minimised under the same exact linear constraints (seam transitions,
//! isolines, pins) as the rest of [`super::seamless`].
//!
//! Per triangle, with `J` its Jacobian in the face frame, `D = det J` and
//! `chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2` (positive for every `D`,
//! `-> max(D, 0)` as `eps -> 0`):
//!
//! `F_eps = sum_f A_f [ (1 - theta) |J|^2 / chi + theta (D^2 + 1) / chi ]`
//!
//! (shape plus area term). It is finite on inverted triangles, so it can
//! start from a folded map; `eps` is lowered between minimisations by the
//! paper's rule until every `D > 0`, after which the barrier is the one of
//! [`super::injective`]. Each minimisation is L-BFGS on the null space of
//! the constraints, its initial inverse Hessian the constrained Poisson
//! inverse `Z (Zᵀ A Z)⁻¹ Zᵀ` (`Z` a basis of `C x = 0`; one solve with the
//! factored KKT): every direction, a combination of such solves and past
//! steps, keeps the iterate feasible, and the Poisson part scales the steps
//! to the mesh (with projected gradients alone L-BFGS made little progress
//! on the cow).

use super::element::Element;

/// Weight `theta` of the area term. The paper's 1/128 is for maps with a
/// fixed boundary; here nothing is fixed but one pin per component, and
/// with 1/128 the map shrinks towards a point while `eps` is large (the
/// cow at `--sharp 60`: 39 inverted triangles became 5 600). 1/2 keeps the scale.
const AREA_WEIGHT: f64 = 0.5;

/// Past steps kept by L-BFGS.
const HISTORY: usize = 8;

/// Settings of [`untangle`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UntangleOptions {
    /// Cap on the `eps` updates (outer iterations); 0 disables untangling.
    pub max_outer: usize,
    /// Cap on L-BFGS iterations per `eps`.
    pub max_inner: usize,
    /// Cap on L-BFGS iterations in all.
    pub max_total: usize,
    /// `eps` updates without fewer inverted triangles before giving up.
    pub patience: usize,
}

impl Default for UntangleOptions {
    fn default() -> Self {
        UntangleOptions { max_outer: 60, max_inner: 200, max_total: 3000, patience: 10 }
    }
}

/// What [`untangle`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UntangleStats {
    pub outer: usize,
    pub iterations: usize,
    /// Triangles with `det J <= 0` at the start and at the end.
    pub inverted_start: usize,
    pub inverted: usize,
}

fn det(j: &[[f64; 2]; 2]) -> f64 {
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

fn chi(d: f64, eps: f64) -> f64 {
    // Written to keep accuracy for d << 0: (d + sqrt(e^2 + d^2)) / 2 = e^2 / (2 (sqrt(e^2 + d^2) - d)).
    let s = (eps * eps + d * d).sqrt();
    if d >= 0.0 {
        0.5 * (d + s)
    } else {
        0.5 * eps * eps / (s - d)
    }
}

fn chi_derivative(d: f64, eps: f64) -> f64 {
    0.5 + 0.5 * d / (eps * eps + d * d).sqrt()
}

/// The barrier energy of one triangle's Jacobian (without its area) and,
/// when `grad` is given, its derivative in `J` added to `grad` times `scale`.
fn energy(j: &[[f64; 2]; 2], eps: f64, grad: Option<(&mut [[f64; 2]; 2], f64)>) -> f64 {
    let d = det(j);
    let t = j[0][0] * j[0][0] + j[0][1] * j[0][1] + j[1][0] * j[1][0] + j[1][1] * j[1][1];
    let c = chi(d, eps);
    let e = (1.0 - AREA_WEIGHT) * t / c + AREA_WEIGHT * (d * d + 1.0) / c;
    if let Some((g, scale)) = grad {
        let dc = chi_derivative(d, eps);
        // dE/dD, and dD/dJ = cofactor(J).
        let de_dd = -(1.0 - AREA_WEIGHT) * t * dc / (c * c) + AREA_WEIGHT * (2.0 * d / c - (d * d + 1.0) * dc / (c * c));
        let cof = [[j[1][1], -j[1][0]], [-j[0][1], j[0][0]]];
        for a in 0..2 {
            for b in 0..2 {
                g[a][b] += scale * (2.0 * (1.0 - AREA_WEIGHT) * j[a][b] / c + de_dd * cof[a][b]);
            }
        }
    }
    e
}

/// `F_eps(x)` and, with `grad`, its gradient (overwritten, length of `x`).
fn total(elements: &[Element], x: &[f64], eps: f64, mut grad: Option<&mut [f64]>) -> f64 {
    if let Some(g) = grad.as_deref_mut() {
        g.iter_mut().for_each(|v| *v = 0.0);
    }
    let mut sum = 0.0;
    for el in elements {
        let j = el.jacobian(x);
        match grad.as_deref_mut() {
            None => sum += el.area * energy(&j, eps, None),
            Some(g) => {
                let mut dj = [[0.0; 2]; 2];
                sum += el.area * energy(&j, eps, Some((&mut dj, el.area)));
                for k in 0..3 {
                    for c in 0..2 {
                        g[el.x[c][k]] += dj[c][0] * el.g[k][0] + dj[c][1] * el.g[k][1];
                    }
                }
            }
        }
    }
    sum
}

fn min_det(elements: &[Element], x: &[f64]) -> (f64, usize) {
    elements.iter().fold((f64::INFINITY, 0), |(m, n), el| {
        let d = det(&el.jacobian(x));
        (m.min(d), n + usize::from(!(d > 0.0)))
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Minimises `F_eps` from `x` by L-BFGS on `C x = 0` (at most `max`
/// iterations, stopping when a step lowers `F` by less than 1e-9 of it);
/// returns the iterations taken. `precondition` is the initial inverse
/// Hessian of the two-loop recursion: it maps a vector to one on `C x = 0`.
fn minimise(elements: &[Element], precondition: &dyn Fn(&mut [f64]), x: &mut [f64], eps: f64, max: usize) -> usize {
    let n = x.len();
    let mut g = vec![0.0; n];
    let mut f = total(elements, x, eps, Some(&mut g));
    let (mut s_hist, mut y_hist): (Vec<Vec<f64>>, Vec<Vec<f64>>) = (Vec::new(), Vec::new());
    let mut g_new = vec![0.0; n];
    let mut trial = vec![0.0; n];
    for it in 0..max {
        // Two-loop recursion: d = -H g.
        let mut d: Vec<f64> = g.iter().map(|v| -v).collect();
        let mut alphas = Vec::with_capacity(s_hist.len());
        for (s, y) in s_hist.iter().zip(&y_hist).rev() {
            let a = dot(s, &d) / dot(y, s);
            d.iter_mut().zip(y).for_each(|(di, yi)| *di -= a * yi);
            alphas.push(a);
        }
        precondition(&mut d);
        for ((s, y), a) in s_hist.iter().zip(&y_hist).zip(alphas.iter().rev()) {
            let b = dot(y, &d) / dot(y, s);
            d.iter_mut().zip(s).for_each(|(di, si)| *di += (a - b) * si);
        }
        // No step moves a point by more than a tenth of the map's size:
        // near a nearly degenerate triangle the gradient is huge.
        let size = x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        let longest = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if longest > 0.1 * size {
            d.iter_mut().for_each(|v| *v *= 0.1 * size / longest);
        }
        let slope = dot(&g, &d);
        if !(slope < 0.0) {
            if s_hist.is_empty() {
                return it;
            }
            s_hist.clear();
            y_hist.clear();
            continue;
        }
        // Backtracking (Armijo).
        let mut step = 1.0;
        let mut accepted = None;
        for _ in 0..60 {
            trial.iter_mut().zip(x.iter()).zip(&d).for_each(|((t, xi), di)| *t = xi + step * di);
            let ft = total(elements, &trial, eps, None);
            if ft.is_finite() && ft <= f + 1e-4 * step * slope {
                accepted = Some(ft);
                break;
            }
            step *= 0.5;
        }
        let Some(ft) = accepted else { return it };
        total(elements, &trial, eps, Some(&mut g_new));
        let s: Vec<f64> = d.iter().map(|v| step * v).collect();
        let y: Vec<f64> = g_new.iter().zip(&g).map(|(a, b)| a - b).collect();
        x.copy_from_slice(&trial);
        std::mem::swap(&mut g, &mut g_new);
        let decrease = f - ft;
        f = ft;
        if dot(&s, &y) > 1e-16 * dot(&y, &y).sqrt() * dot(&s, &s).sqrt() {
            if s_hist.len() == HISTORY {
                s_hist.remove(0);
                y_hist.remove(0);
            }
            s_hist.push(s);
            y_hist.push(y);
        }
        if decrease <= 1e-9 * f.abs() {
            return it + 1;
        }
    }
    max
}

/// Untangles the feasible unknowns `x` (`C x = 0`) in place: on return
/// every triangle has `det J > 0` when [`UntangleStats::inverted`] is 0.
/// `precondition` maps a vector `q` to `Z (Zᵀ A Z)⁻¹ Zᵀ q` for an SPD `A`
/// (the Poisson stiffness) and a basis `Z` of `C x = 0`, so `x` stays on
/// the constraints up to the accuracy of that solve.
pub(super) fn untangle(elements: &[Element], precondition: &dyn Fn(&mut [f64]), x: &mut [f64], options: &UntangleOptions) -> UntangleStats {
    let (mut d_min, inverted_start) = min_det(elements, x);
    let mut stats = UntangleStats { inverted_start, inverted: inverted_start, ..UntangleStats::default() };
    if inverted_start == 0 {
        return stats;
    }
    // The paper's start and update of eps.
    let mut eps = (1e-12 + 0.04 * d_min.min(0.0).powi(2)).sqrt();
    let (mut fewest, mut stalled) = (inverted_start, 0);
    for outer in 0..options.max_outer {
        if stats.iterations >= options.max_total {
            break;
        }
        let before = total(elements, x, eps, None);
        let budget = options.max_inner.min(options.max_total - stats.iterations);
        stats.iterations += minimise(elements, precondition, x, eps, budget);
        stats.outer = outer + 1;
        let after = total(elements, x, eps, None);
        let (d, inverted) = min_det(elements, x);
        d_min = d;
        stats.inverted = inverted;
        if inverted == 0 {
            // From here on the injective refinement's barrier takes over.
            break;
        }
        if inverted < fewest {
            (fewest, stalled) = (inverted, 0);
        } else {
            stalled += 1;
            if stalled >= options.patience {
                break;
            }
        }
        let sigma = (1.0 - after / before).max(0.1);
        let mu = (1.0 - sigma) * chi(d_min, eps);
        eps = if d_min < mu { 2.0 * (mu * (mu - d_min)).sqrt() } else { 1e-10 };
    }
    stats
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A `n × n`-vertex grid on the unit square as elements of the identity
    /// map (u unknowns `0..n²`, v unknowns `n²..2n²`), and its boundary flags.
    pub(in crate::param) fn grid(n: usize) -> (Vec<Element>, Vec<[f64; 2]>, Vec<bool>) {
        let id = |i: usize, j: usize| i * n + j;
        let p: Vec<[f64; 2]> = (0..n * n).map(|k| [(k / n) as f64 / (n - 1) as f64, (k % n) as f64 / (n - 1) as f64]).collect();
        let boundary = (0..n * n).map(|k| k / n == 0 || k / n == n - 1 || k % n == 0 || k % n == n - 1).collect();
        let mut elements = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                for w in [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]] {
                    let q = w.map(|k| p[k]);
                    let area = 0.5 * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
                    elements.push(Element::new(q, area, w, [w, w.map(|k| k + n * n)]));
                }
            }
        }
        (elements, p, boundary)
    }

    #[test]
    fn a_folded_grid_with_a_fixed_boundary_is_untangled() {
        let n = 7;
        let (elements, p, boundary) = grid(n);
        let nv = n * n;
        // Identity map, then interior vertices pushed across their neighbours.
        let mut x: Vec<f64> = p.iter().map(|q| q[0]).chain(p.iter().map(|q| q[1])).collect();
        for (k, shift) in [(2 * n + 2, [0.45, 0.3]), (4 * n + 3, [-0.4, 0.35]), (3 * n + 4, [0.1, -0.5])] {
            x[k] += shift[0];
            x[nv + k] += shift[1];
        }
        let start = min_det(&elements, &x).1;
        assert!(start >= 6, "the start must be folded ({start} inverted)");
        // C pins the boundary: its projection zeroes boundary components.
        let precondition = |q: &mut [f64]| {
            for k in 0..nv {
                if boundary[k] {
                    q[k] = 0.0;
                    q[nv + k] = 0.0;
                }
            }
        };
        let fixed = x.clone();
        let stats = untangle(&elements, &precondition, &mut x, &UntangleOptions::default());
        assert_eq!(stats.inverted_start, start);
        assert_eq!(stats.inverted, 0, "{stats:?}");
        assert_eq!(min_det(&elements, &x).1, 0);
        for k in (0..nv).filter(|&k| boundary[k]) {
            assert_eq!((x[k], x[nv + k]), (fixed[k], fixed[nv + k]), "boundary vertex {k} moved");
        }
    }

    #[test]
    fn the_energy_gradient_matches_finite_differences() {
        let (elements, p, _) = grid(4);
        let nv = p.len();
        let mut x: Vec<f64> = p.iter().map(|q| q[0]).chain(p.iter().map(|q| q[1])).collect();
        x[5] += 0.6; // inverts some triangles
        x[nv + 6] -= 0.4;
        let eps = 0.05;
        let mut g = vec![0.0; x.len()];
        total(&elements, &x, eps, Some(&mut g));
        for k in [5, 6, nv + 5, nv + 6, 9] {
            let h = 1e-6;
            let (mut a, mut b) = (x.clone(), x.clone());
            a[k] += h;
            b[k] -= h;
            let fd = (total(&elements, &a, eps, None) - total(&elements, &b, eps, None)) / (2.0 * h);
            assert!((fd - g[k]).abs() <= 1e-5 * (1.0 + fd.abs()), "unknown {k}: {} vs {fd}", g[k]);
        }
    }
}
