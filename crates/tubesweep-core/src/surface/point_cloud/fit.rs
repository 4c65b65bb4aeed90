//! The local fit of a point cloud around a centre c: the k nearest samples weighted by Wendland's
//! function of their distance to c, their weighted principal frame (normal = the axis of least
//! spread), and the weighted least-squares quadric height function over the tangent coordinates
//! (a parabola for a curve); then the projection of a point onto the graph of that height function
//! by Newton's method.
//!
//! Continuity: the support radius R is the larger of the distance from c to the (k+1)-th nearest
//! sample (which gets weight 0) and a fixed smoothing radius ρ, so the weights, the frame and the
//! coefficients are continuous in c (a sample enters or leaves the neighbourhood with weight 0).

/// The number of basis functions of the height function: 1, a, a² (curves); 1, a, b, a², ab, b².
pub(crate) const fn basis_len(d: usize) -> usize {
    if d == 2 {
        3
    } else {
        6
    }
}

/// Wendland's C² function ψ(r) = (1 − r)⁴(4r + 1) on [0, 1], 0 beyond.
#[inline]
pub(crate) fn wendland(r: f64) -> f64 {
    if r >= 1.0 {
        0.0
    } else {
        let s = 1.0 - r;
        s * s * s * s * (4.0 * r + 1.0)
    }
}

/// A local height function: origin m, frame rows (D−1 tangents, then the normal), scale R, and the
/// coefficients of h(a) in scaled coordinates a = (x − m)·t / R, h = (x − m)·n / R.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fit<const D: usize> {
    pub origin: [f64; D],
    pub frame: [[f64; D]; D],
    pub radius: f64,
    pub coef: [f64; 6],
}

#[inline]
pub(crate) fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        s += a[k] * b[k];
    }
    s
}

#[inline]
pub(crate) fn distance<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        s += (a[k] - b[k]) * (a[k] - b[k]);
    }
    s.sqrt()
}

/// Eigenvalues (ascending) and eigenvectors (rows) of a symmetric D×D matrix, by cyclic Jacobi.
pub(crate) fn symmetric_eigen<const D: usize>(m: &[[f64; D]; D]) -> ([f64; D], [[f64; D]; D]) {
    let mut a = *m;
    let mut v = [[0.0; D]; D];
    for k in 0..D {
        v[k][k] = 1.0;
    }
    for _ in 0..50 {
        let mut off = 0.0;
        let mut diag = 0.0;
        for p in 0..D {
            diag += a[p][p] * a[p][p];
            for q in p + 1..D {
                off += a[p][q] * a[p][q];
            }
        }
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..D {
            for q in p + 1..D {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for r in 0..D {
                    let (arp, arq) = (a[r][p], a[r][q]);
                    a[r][p] = c * arp - s * arq;
                    a[r][q] = s * arp + c * arq;
                }
                for r in 0..D {
                    let (apr, aqr) = (a[p][r], a[q][r]);
                    a[p][r] = c * apr - s * aqr;
                    a[q][r] = s * apr + c * aqr;
                }
                for r in 0..D {
                    let (vp, vq) = (v[p][r], v[q][r]);
                    v[p][r] = c * vp - s * vq;
                    v[q][r] = s * vp + c * vq;
                }
            }
        }
    }
    let mut order: [usize; D] = [0; D];
    for k in 0..D {
        order[k] = k;
    }
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let mut values = [0.0; D];
    let mut vectors = [[0.0; D]; D];
    for (k, &o) in order.iter().enumerate() {
        values[k] = a[o][o];
        vectors[k] = v[o];
    }
    (values, vectors)
}

/// The basis functions at tangent coordinates `a` (D−1 of them used).
#[inline]
fn basis<const D: usize>(a: &[f64; 2]) -> [f64; 6] {
    if D == 2 {
        [1.0, a[0], a[0] * a[0], 0.0, 0.0, 0.0]
    } else {
        [1.0, a[0], a[1], a[0] * a[0], a[0] * a[1], a[1] * a[1]]
    }
}

impl<const D: usize> Fit<D> {
    /// The weighted fit to `neighbours` (the samples within `radius` of `centre`: weight
    /// ψ(|p − c| / radius)). `None` when the neighbourhood is degenerate (all its weighted samples
    /// on a line in 3D, or coincident).
    pub(crate) fn new(neighbours: &[[f64; D]], centre: &[f64; D], radius: f64) -> Option<Self> {
        let n = neighbours.len();
        if n < basis_len(D) + 1 {
            return None;
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return None;
        }
        let weight = |i: usize| wendland(distance(&neighbours[i], centre) / radius);
        let mut wsum = 0.0;
        let mut mean = [0.0; D];
        for i in 0..n {
            let w = weight(i);
            wsum += w;
            for k in 0..D {
                mean[k] += w * neighbours[i][k];
            }
        }
        if !(wsum > 0.0) {
            return None;
        }
        for k in 0..D {
            mean[k] /= wsum;
        }
        let mut cov = [[0.0; D]; D];
        for i in 0..n {
            let w = weight(i);
            for p in 0..D {
                let dp = neighbours[i][p] - mean[p];
                for q in p..D {
                    cov[p][q] += w * dp * (neighbours[i][q] - mean[q]);
                }
            }
        }
        for p in 0..D {
            for q in 0..p {
                cov[p][q] = cov[q][p];
            }
        }
        let (values, vectors) = symmetric_eigen(&cov);
        let largest = values[D - 1];
        // the tangent spread must be two-dimensional on a surface (one on a curve)
        if !(largest > 0.0) || values[1] <= 1e-10 * largest {
            return None;
        }
        let mut frame = [[0.0; D]; D];
        for k in 0..D - 1 {
            frame[k] = vectors[D - 1 - k];
        }
        frame[D - 1] = vectors[0];
        // weighted least squares for the height function, in scaled coordinates
        let nb = basis_len(D);
        let mut ata = [[0.0; 6]; 6];
        let mut atb = [0.0; 6];
        for i in 0..n {
            let w = weight(i);
            if w == 0.0 {
                continue;
            }
            let (a, h) = local(&frame, &mean, radius, &neighbours[i]);
            let phi = basis::<D>(&a);
            for p in 0..nb {
                atb[p] += w * phi[p] * h;
                for q in p..nb {
                    ata[p][q] += w * phi[p] * phi[q];
                }
            }
        }
        for p in 0..nb {
            for q in 0..p {
                ata[p][q] = ata[q][p];
            }
        }
        let coef = solve_spd(ata, atb, nb)?;
        Some(Fit {
            origin: mean,
            frame,
            radius,
            coef,
        })
    }

    /// The weighted root-mean-square distance of `neighbours` (those it was fitted to, centred at
    /// `centre` within `radius`) from the fitted graph: about the samples' noise on one sheet.
    pub(crate) fn misfit(&self, neighbours: &[[f64; D]], centre: &[f64; D], radius: f64) -> f64 {
        let (mut sum, mut wsum) = (0.0, 0.0);
        for p in neighbours {
            let w = wendland(distance(p, centre) / radius);
            let (a, h) = self.local(p);
            let off = (h - self.height(&a).0) * self.radius;
            sum += w * off * off;
            wsum += w;
        }
        if wsum > 0.0 {
            (sum / wsum).sqrt()
        } else {
            0.0
        }
    }

    /// Tangent coordinates and height of `x` in the fit's scaled frame.
    #[inline]
    pub(crate) fn local(&self, x: &[f64; D]) -> ([f64; 2], f64) {
        local(&self.frame, &self.origin, self.radius, x)
    }

    /// The fitted height g(a), its gradient and Hessian (in scaled coordinates).
    #[inline]
    pub(crate) fn height(&self, a: &[f64; 2]) -> (f64, [f64; 2], [[f64; 2]; 2]) {
        let c = &self.coef;
        if D == 2 {
            (
                c[0] + c[1] * a[0] + c[2] * a[0] * a[0],
                [c[1] + 2.0 * c[2] * a[0], 0.0],
                [[2.0 * c[2], 0.0], [0.0, 0.0]],
            )
        } else {
            let g = c[0] + c[1] * a[0] + c[2] * a[1] + c[3] * a[0] * a[0] + c[4] * a[0] * a[1] + c[5] * a[1] * a[1];
            let grad = [
                c[1] + 2.0 * c[3] * a[0] + c[4] * a[1],
                c[2] + c[4] * a[0] + 2.0 * c[5] * a[1],
            ];
            (g, grad, [[2.0 * c[3], c[4]], [c[4], 2.0 * c[5]]])
        }
    }

    /// The point of the graph at tangent coordinates `a`, in the grid's coordinates.
    pub(crate) fn lift(&self, a: &[f64; 2]) -> [f64; D] {
        let (g, _, _) = self.height(a);
        let mut y = self.origin;
        for k in 0..D {
            for j in 0..D - 1 {
                y[k] += self.radius * a[j] * self.frame[j][k];
            }
            y[k] += self.radius * g * self.frame[D - 1][k];
        }
        y
    }

    /// The tangent coordinates of the point of the graph nearest to `x` (Newton's method on
    /// f(a) = ½|a − a₀|² + ½(g(a) − h₀)², Gauss–Newton where its Hessian is not positive, each step
    /// halved until f decreases), within the fit's support (|a| ≤ 1 in units of its radius: beyond,
    /// the quadric means nothing, and the fixed point moves the centre there instead).
    pub(crate) fn project(&self, x: &[f64; D]) -> [f64; 2] {
        let (a0, h0) = self.local(x);
        let m = D - 1;
        let objective = |a: &[f64; 2]| {
            let (g, _, _) = self.height(a);
            let mut s = (g - h0) * (g - h0);
            for p in 0..m {
                s += (a[p] - a0[p]) * (a[p] - a0[p]);
            }
            0.5 * s
        };
        let mut a = inside_support(a0);
        let mut fa = objective(&a);
        for _ in 0..NEWTON_STEPS {
            let (g, dg, hg) = self.height(&a);
            let r = g - h0;
            let mut grad = [0.0; 2];
            let mut hess = [[0.0; 2]; 2];
            for p in 0..m {
                grad[p] = a[p] - a0[p] + r * dg[p];
                for q in 0..m {
                    hess[p][q] = if p == q { 1.0 } else { 0.0 } + dg[p] * dg[q] + r * hg[p][q];
                }
            }
            let mut step = solve_small(&hess, &grad, m);
            if step.is_none() {
                for p in 0..m {
                    for q in 0..m {
                        hess[p][q] = if p == q { 1.0 } else { 0.0 } + dg[p] * dg[q];
                    }
                }
                step = solve_small(&hess, &grad, m);
            }
            let Some(s) = step else { break };
            let mut t = 1.0;
            let mut moved = false;
            for _ in 0..30 {
                let trial = inside_support([a[0] - t * s[0], if m == 2 { a[1] - t * s[1] } else { 0.0 }]);
                let ft = objective(&trial);
                if ft <= fa {
                    moved = (trial[0] - a[0]).abs() + (trial[1] - a[1]).abs() > 1e-15;
                    a = trial;
                    fa = ft;
                    break;
                }
                t *= 0.5;
            }
            if !moved {
                break;
            }
        }
        a
    }
}

/// `a` moved radially into the unit disc (the fit's support in scaled coordinates).
#[inline]
fn inside_support(a: [f64; 2]) -> [f64; 2] {
    let r = (a[0] * a[0] + a[1] * a[1]).sqrt();
    if r > 1.0 {
        [a[0] / r, a[1] / r]
    } else {
        a
    }
}

/// Newton steps of [`Fit::project`].
const NEWTON_STEPS: usize = 12;

#[inline]
fn local<const D: usize>(frame: &[[f64; D]; D], origin: &[f64; D], radius: f64, x: &[f64; D]) -> ([f64; 2], f64) {
    let mut rel = [0.0; D];
    for k in 0..D {
        rel[k] = (x[k] - origin[k]) / radius;
    }
    let mut a = [0.0; 2];
    for j in 0..D - 1 {
        a[j] = dot(&frame[j], &rel);
    }
    (a, dot(&frame[D - 1], &rel))
}

/// Solves a small positive-definite system (1×1 or 2×2); `None` when it is not positive definite.
fn solve_small(h: &[[f64; 2]; 2], g: &[f64; 2], m: usize) -> Option<[f64; 2]> {
    if m == 1 {
        return (h[0][0] > 0.0).then(|| [g[0] / h[0][0], 0.0]);
    }
    let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    if !(h[0][0] > 0.0 && det > 1e-14 * h[0][0] * h[1][1]) {
        return None;
    }
    Some([
        (h[1][1] * g[0] - h[0][1] * g[1]) / det,
        (h[0][0] * g[1] - h[1][0] * g[0]) / det,
    ])
}

/// Cholesky solve of the normal equations (n ≤ 6), a tiny ridge on the diagonal for
/// neighbourhoods that barely determine the quadratic terms; `None` if not positive definite.
fn solve_spd(mut a: [[f64; 6]; 6], mut b: [f64; 6], n: usize) -> Option<[f64; 6]> {
    let scale = (0..n).map(|i| a[i][i]).fold(0.0, f64::max);
    for i in 0..n {
        a[i][i] += 1e-12 * scale;
    }
    for j in 0..n {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[j][k] * a[j][k];
        }
        if !(d > 0.0) {
            return None;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..n {
            let mut s = a[i][j];
            for k in 0..j {
                s -= a[i][k] * a[j][k];
            }
            a[i][j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i][k] * b[k];
        }
        b[i] = s / a[i][i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k][i] * b[k];
        }
        b[i] = s / a[i][i];
    }
    Some(b)
}

/// The largest angular gap (radians) between the directions from `a` to `others` in the tangent
/// plane (for a curve, D = 2: 0 when the others lie on both sides of `a`, 2π when on one side),
/// and the unit direction (tangent coordinates) that bisects it: where the samples around `a`
/// stop (for a curve, the side with no others).
pub(crate) fn gap_and_bisector<const D: usize>(a: &[f64; 2], others: &[[f64; 2]]) -> (f64, [f64; 2]) {
    if D == 2 {
        let below = others.iter().any(|o| o[0] < a[0]);
        let above = others.iter().any(|o| o[0] > a[0]);
        let side = if below { 1.0 } else { -1.0 };
        return (if below && above { 0.0 } else { std::f64::consts::TAU }, [side, 0.0]);
    }
    let mut angles: Vec<f64> = others
        .iter()
        .filter(|o| o[0] != a[0] || o[1] != a[1])
        .map(|o| (o[1] - a[1]).atan2(o[0] - a[0]))
        .collect();
    if angles.is_empty() {
        return (std::f64::consts::TAU, [1.0, 0.0]);
    }
    angles.sort_by(f64::total_cmp);
    let last = angles[angles.len() - 1];
    let (mut gap, mut from) = (angles[0] + std::f64::consts::TAU - last, last);
    for w in angles.windows(2) {
        if w[1] - w[0] > gap {
            (gap, from) = (w[1] - w[0], w[0]);
        }
    }
    let mid = from + 0.5 * gap;
    (gap, [mid.cos(), mid.sin()])
}

/// The point of the convex hull of `pts` (2D, or an interval for a curve) nearest to `a`: `a`
/// itself when inside.
pub(crate) fn clamp_to_hull<const D: usize>(a: &[f64; 2], pts: &[[f64; 2]]) -> [f64; 2] {
    if D == 2 {
        let lo = pts.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
        return [a[0].clamp(lo, hi), 0.0];
    }
    // Andrew's monotone chain, counter-clockwise
    let mut p: Vec<[f64; 2]> = pts.to_vec();
    p.sort_by(|x, y| x[0].total_cmp(&y[0]).then(x[1].total_cmp(&y[1])));
    p.dedup();
    if p.len() < 3 {
        return *a;
    }
    let cross =
        |o: &[f64; 2], x: &[f64; 2], y: &[f64; 2]| (x[0] - o[0]) * (y[1] - o[1]) - (x[1] - o[1]) * (y[0] - o[0]);
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for q in iter {
            while hull.len() >= start + 2 && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], q) <= 0.0 {
                hull.pop();
            }
            hull.push(*q);
        }
        hull.pop();
    }
    let n = hull.len();
    if n < 3 {
        return *a;
    }
    let inside = (0..n).all(|i| cross(&hull[i], &hull[(i + 1) % n], a) >= 0.0);
    if inside {
        return *a;
    }
    let mut best = *a;
    let mut best_d = f64::INFINITY;
    for i in 0..n {
        let (s, e) = (hull[i], hull[(i + 1) % n]);
        let d = [e[0] - s[0], e[1] - s[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let t = if len2 > 0.0 {
            (((a[0] - s[0]) * d[0] + (a[1] - s[1]) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [s[0] + t * d[0], s[1] + t * d[1]];
        let dq = (q[0] - a[0]).powi(2) + (q[1] - a[1]).powi(2);
        if dq < best_d {
            best_d = dq;
            best = q;
        }
    }
    best
}
