//! Exact signed distances of the library's analytic surfaces, evaluated on all threads: the
//! Python package's `Circle`, `Sphere`, `Torus`, `Ellipsoid`, `Star`, `RoundedCube` and
//! `DoubleTorus` call these instead of NumPy expressions, with the same arithmetic (so the same
//! bits; the star's to rounding), because the band search evaluates φ at every candidate node and
//! the outward directions at every rim place.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Points per parallel task.
const CHUNK: usize = 1 << 13;

fn check_points(points: &[f64], d: usize, out: &[f64]) -> Result<()> {
    if d == 0 || !points.len().is_multiple_of(d) {
        return Err(Error::invalid("points", format!("expected an (M, {d}) array")));
    }
    if out.len() != points.len() / d {
        return Err(Error::invalid(
            "out",
            format!(
                "expected {} values (one per point), got {}",
                points.len() / d,
                out.len()
            ),
        ));
    }
    Ok(())
}

/// `φ(x) = |x − c| − r`, the signed distance to the circle (d = 2) or sphere (d = 3) of radius
/// `r` about `c`, at the points (`M` rows of `d = centre.len()` coordinates) into `out`. `|x − c|`
/// is `sqrt(Σ_k (x_k − c_k)²)` summed in axis order.
pub fn sphere_signed_distance(points: &[f64], centre: &[f64], radius: f64, out: &mut [f64]) -> Result<()> {
    let d = centre.len();
    check_points(points, d, out)?;
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * d))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(d)) {
                let mut sq = (x[0] - centre[0]) * (x[0] - centre[0]);
                for k in 1..d {
                    sq += (x[k] - centre[k]) * (x[k] - centre[k]);
                }
                *o = sq.sqrt() - radius;
            }
        });
    Ok(())
}

/// `φ(x) = hypot(hypot(q_x, q_y) − R, q_z) − r` with `q = x − c`: the signed distance to the
/// torus about the z axis through `c` with centre-circle radius `R` and tube radius `r`, at the
/// points (`M` rows of 3 coordinates) into `out`.
pub fn torus_signed_distance(points: &[f64], centre: [f64; 3], major: f64, minor: f64, out: &mut [f64]) -> Result<()> {
    check_points(points, 3, out)?;
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 3))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(3)) {
                let q = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
                *o = (q[0].hypot(q[1]) - major).hypot(q[2]) - minor;
            }
        });
    Ok(())
}

/// The signed distance to the cube of half-side `half_size` about `centre` with its edges and
/// corners rounded to `radius`, `|max(q, 0)| + min(max_k q_k, 0) − radius` with
/// `q = |x − c| − (half_size − radius)` componentwise (exact), at the points (`M` rows of 3
/// coordinates) into `out`, with the arithmetic (and bits) of the Python
/// `RoundedCube._signed_distance_numpy`.
pub fn rounded_cube_signed_distance(
    points: &[f64],
    centre: [f64; 3],
    half_size: f64,
    radius: f64,
    out: &mut [f64],
) -> Result<()> {
    check_points(points, 3, out)?;
    if !(radius > 0.0 && radius <= half_size && half_size.is_finite()) {
        return Err(Error::invalid(
            "radius",
            format!("need 0 < radius <= half_size, got radius = {radius}, half_size = {half_size}"),
        ));
    }
    let inner = half_size - radius;
    // NumPy's maximum and minimum: NaN wins (f64::max and min would drop it)
    let max = |a: f64, b: f64| if a.is_nan() || a > b { a } else { b };
    let min = |a: f64, b: f64| if a.is_nan() || a < b { a } else { b };
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 3))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(3)) {
                let q = [
                    (x[0] - centre[0]).abs() - inner,
                    (x[1] - centre[1]).abs() - inner,
                    (x[2] - centre[2]).abs() - inner,
                ];
                let m = [max(q[0], 0.0), max(q[1], 0.0), max(q[2], 0.0)];
                let outside = ((m[0] * m[0] + m[1] * m[1]) + m[2] * m[2]).sqrt();
                let inside = min(max(max(q[0], q[1]), q[2]), 0.0);
                *o = outside + inside - radius;
            }
        });
    Ok(())
}

/// `φ = min(φ₁, φ₂)` of the two ring tori (centre-circle radius `major`, tube radius `minor`)
/// about the z axis through `(∓offset, 0, 0)`: the genus-2 surface of the Python `DoubleTorus`,
/// with the arithmetic (and bits) of its `_signed_distance_numpy`, at the points (`M` rows of 3
/// coordinates) into `out`.
pub fn double_torus_signed_distance(
    points: &[f64],
    major: f64,
    minor: f64,
    offset: f64,
    out: &mut [f64],
) -> Result<()> {
    check_points(points, 3, out)?;
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 3))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(3)) {
                let torus = |cx: f64| ((x[0] - cx).hypot(x[1]) - major).hypot(x[2]) - minor;
                *o = torus(-offset).min(torus(offset));
            }
        });
    Ok(())
}

/// The signed distance to the ellipsoid `Σ ((x_i − c_i)/a_i)² = 1` (semi-axes `axes`, centre
/// `centre`) at the points (`M` rows of 3 coordinates) into `out`, with the arithmetic of the
/// Python `Ellipsoid._signed_distance_numpy` (the same bits): the closest point is
/// `y_i = a_i² x_i / (a_i² + t)` with `t` the root in `(−min a_i², ∞)` of
/// `F(t) = Σ (a_i x_i / (a_i² + t))² − 1`, found by [`ellipsoid_root`]; interior points on the
/// plane of the shortest axis far from the surface (where `a_min² + t` vanishes) have their
/// closest point straight above or below them along that axis.
pub fn ellipsoid_signed_distance(points: &[f64], centre: [f64; 3], axes: [f64; 3], out: &mut [f64]) -> Result<()> {
    check_points(points, 3, out)?;
    if !axes.iter().all(|&a| a > 0.0 && a.is_finite()) {
        return Err(Error::invalid(
            "axes",
            format!("semi-axes must be positive and finite, got {axes:?}"),
        ));
    }
    let a2 = [axes[0] * axes[0], axes[1] * axes[1], axes[2] * axes[2]];
    // the first shortest axis, as np.argmin
    let kmin = (0..3).fold(0, |m, k| if axes[k] < axes[m] { k } else { m });
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 3))
        .for_each(|(out, p)| {
            for (o, p) in out.iter_mut().zip(p.chunks_exact(3)) {
                let x = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
                let t = ellipsoid_root(x, axes, a2, kmin);
                let den = [a2[0] + t, a2[1] + t, a2[2] + t];
                let mut y = [0.0f64; 3];
                if den[kmin] <= 1e-12 * a2[kmin] {
                    let mut sum = 0.0;
                    for k in (0..3).filter(|&k| k != kmin) {
                        y[k] = if a2[k] > a2[kmin] {
                            a2[k] * x[k] / (a2[k] - a2[kmin])
                        } else {
                            0.0
                        };
                        let v = y[k] / axes[k];
                        sum += v * v;
                    }
                    let rest = 1.0 - sum;
                    let sign = if x[kmin] >= 0.0 { 1.0 } else { -1.0 };
                    y[kmin] = sign * axes[kmin] * rest.max(0.0).sqrt();
                } else {
                    for k in 0..3 {
                        y[k] = a2[k] * x[k] / den[k];
                    }
                }
                let d = [
                    p[0] - (y[0] + centre[0]),
                    p[1] - (y[1] + centre[1]),
                    p[2] - (y[2] + centre[2]),
                ];
                let dist = ((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]).sqrt();
                let s = |k: usize| {
                    let v = x[k] / axes[k];
                    v * v
                };
                let inside = (s(0) + s(1)) + s(2) < 1.0;
                *o = if inside { -dist } else { dist };
            }
        });
    Ok(())
}

/// Most Newton steps [`ellipsoid_root`] takes; it stops far earlier, the convergence being
/// quadratic once near the root.
/// The Python `Ellipsoid._newton_root` takes as many (keep the two equal: the same bits).
pub const ELLIPSOID_NEWTON_STEPS: usize = 100;

/// The root `t` of the ellipsoid's `F(t) = Σ (a_i x_i / (a_i² + t))² − 1` for the point `x`
/// (relative to the centre; `a2` the squared semi-axes, `kmin` the first shortest axis), or
/// `−a_kmin²` where `F` has no root above it (interior points on the plane `x_kmin = 0` far from
/// the surface). `F` is convex and decreasing on `t > −a_kmin²`, and at
/// `t₀ = max_i (a_i |x_i| − a_i²)` the largest term is 1, so `F(t₀) ≥ 0`: Newton's method from
/// `t₀` moves right and never passes the root, and stops once `F ≤ 0` or a step no longer
/// advances `t` (the root to the last bits), or after [`ELLIPSOID_NEWTON_STEPS`]. A term with
/// `x_i = 0` is 0 (its limit). So is a term whose `a_i² + t` is exactly 0: when `a_kmin |x_kmin|`
/// is below rounding against `a_kmin²` (`|x_kmin|` about 1e-17 or less), `t₀` rounds onto the
/// pole `−a_kmin²`, and the point is treated as lying on the plane `x_kmin = 0`, which it does to
/// within rounding (without this the first step divides by 0 and the search stops at the pole,
/// far from the root). The arithmetic is that of `Ellipsoid._newton_root` in Python, operation for
/// operation.
#[inline]
pub fn ellipsoid_root(x: [f64; 3], axes: [f64; 3], a2: [f64; 3], kmin: usize) -> f64 {
    let ax_x = [axes[0] * x[0], axes[1] * x[1], axes[2] * x[2]];
    let mut t = -a2[kmin];
    for k in 0..3 {
        t = t.max(axes[k] * x[k].abs() - a2[k]);
    }
    for _ in 0..ELLIPSOID_NEWTON_STEPS {
        let den = [a2[0] + t, a2[1] + t, a2[2] + t];
        let mut q = [0.0f64; 3];
        let mut slope = [0.0f64; 3];
        for k in 0..3 {
            if ax_x[k] != 0.0 && den[k] != 0.0 {
                let r = ax_x[k] / den[k];
                q[k] = r * r;
                slope[k] = q[k] / den[k];
            }
        }
        let f = (q[0] + q[1]) + q[2] - 1.0;
        if !(f > 0.0) {
            break;
        }
        // F'(t) = −2 Σ q_k / (a_k² + t)
        let next = t + f / (2.0 * ((slope[0] + slope[1]) + slope[2]));
        if !(next > t) {
            break;
        }
        t = next;
    }
    t
}

/// The signed distance to the six-fold star `r(θ) = r0 + ε sin²(3θ)` of the paper's Sect. 6.1 at
/// the points (`M` rows of 2 coordinates) into `out`, by the algorithm of the Python
/// `Star.signed_distance`: the closest point's polar angle is first searched on 129 angles
/// within ±0.8 of the point's own (points with `| |x| − r(θ_x) | ≤ min(0.2, 0.9 r0)`) or on 4096
/// angles round the whole curve (the others), then refined by 8 clipped Newton steps on
/// `(γ(t) − x)·γ'(t) = 0`; inside (`|x| < r(θ_x)`) the distance is negative. Equal to the NumPy
/// version to rounding (the sines and cosines come from a different library, and the window's
/// candidates are evaluated by the angle-addition formulas).
pub fn star_signed_distance(points: &[f64], r0: f64, eps: f64, out: &mut [f64]) -> Result<()> {
    star_signed_distance_with(points, r0, eps, out, false)
}

/// [`star_signed_distance`], with `whole_window` searching every candidate of the window (the
/// tests compare the two).
fn star_signed_distance_with(points: &[f64], r0: f64, eps: f64, out: &mut [f64], whole_window: bool) -> Result<()> {
    check_points(points, 2, out)?;
    if !(r0 > 0.0 && eps >= 0.0 && r0.is_finite() && eps.is_finite()) {
        return Err(Error::invalid(
            "r0",
            format!("need r0 > 0 and eps >= 0, got r0 = {r0}, eps = {eps}"),
        ));
    }
    let r = |t: f64| {
        let s = (3.0 * t).sin();
        r0 + eps * (s * s)
    };
    let curve = |t: f64| {
        let rt = r(t);
        [rt * t.cos(), rt * t.sin()]
    };
    const DENSE: usize = 4096;
    let dense_step = 2.0 * std::f64::consts::PI / DENSE as f64;
    // the whole curve's samples, made only if a point far from the curve needs them (a band's
    // points are nearly all near it, and the 4096 samples' sines and cosines cost more than a
    // few hundred points' distances)
    let dense: std::sync::OnceLock<Vec<[f64; 2]>> = std::sync::OnceLock::new();
    let near_limit = 0.2f64.min(0.9 * r0);
    const WINDOW: usize = 129;
    let window_step = 1.6 / (WINDOW - 1) as f64;
    // the window's angle offsets δ with cos δ, sin δ, cos 3δ and sin 3δ
    struct Offset {
        delta: f64,
        c: f64,
        s: f64,
        c3: f64,
        s3: f64,
    }
    let window: Vec<Offset> = (0..WINDOW)
        .map(|k| {
            let delta = if k + 1 == WINDOW {
                0.8
            } else {
                -0.8 + k as f64 * window_step
            };
            let (s, c) = delta.sin_cos();
            let (s3, c3) = (3.0 * delta).sin_cos();
            Offset { delta, c, s, c3, s3 }
        })
        .collect();
    // The window's candidates that can be nearest: the point of the curve at the point's own
    // angle is |ρ − r(θ)| away, so the closest point is no farther and its angle lies within
    // asin(|ρ − r(θ)| / ρ) of the point's. Every candidate beyond that, and WINDOW_MARGIN
    // candidates more, is farther than one within it (a candidate's spacing along the curve is
    // below that margin's sweep at radius ρ), so the first nearest of these is the first nearest
    // of the whole window: the same start for Newton, the same bits.
    const WINDOW_MARGIN: f64 = 3.0;
    let window_span = |rho: f64, radial: f64| -> std::ops::Range<usize> {
        if whole_window || !(rho > radial) {
            return 0..WINDOW;
        }
        let half = (radial / rho).asin() + WINDOW_MARGIN * window_step;
        let lo = ((0.8 - half) / window_step).floor().max(0.0) as usize;
        let hi = (((0.8 + half) / window_step).ceil() as usize + 1).min(WINDOW);
        lo..hi
    };
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 2))
        .for_each(|(out, p)| {
            for (o, q) in out.iter_mut().zip(p.chunks_exact(2)) {
                let (x, y) = (q[0], q[1]);
                let polar = y.atan2(x);
                let inside_radius = r(polar);
                let d2 = |c: [f64; 2]| (c[0] - x) * (c[0] - x) + (c[1] - y) * (c[1] - y);
                let mut t;
                let rho = x.hypot(y);
                let radial = (rho - inside_radius).abs();
                if radial <= near_limit {
                    // γ(polar + δ) by the angle-addition formulas from the window's precomputed
                    // sines and cosines: no trigonometric call per candidate
                    let (sp, cp) = polar.sin_cos();
                    let (s3p, c3p) = (3.0 * polar).sin_cos();
                    t = polar - 0.8;
                    let mut best = f64::INFINITY;
                    for w in &window[window_span(rho, radial)] {
                        let s3 = s3p * w.c3 + c3p * w.s3;
                        let rt = r0 + eps * (s3 * s3);
                        let c = [rt * (cp * w.c - sp * w.s), rt * (sp * w.c + cp * w.s)];
                        let dd = d2(c);
                        if dd < best {
                            best = dd;
                            t = polar + w.delta;
                        }
                    }
                } else {
                    let dense = dense.get_or_init(|| (0..DENSE).map(|j| curve(j as f64 * dense_step)).collect());
                    t = nearest_sample(dense, dense_step, x, y, polar, r0, r0 + eps) as f64 * dense_step;
                }
                // Newton on g(t) = (γ(t) − q)·γ'(t) = 0, each step clipped to ±0.01
                for _ in 0..8 {
                    let (s3, c, si) = ((3.0 * t).sin(), t.cos(), t.sin());
                    let rt = r0 + eps * (s3 * s3);
                    let dr = 3.0 * eps * (6.0 * t).sin();
                    let d2r = 18.0 * eps * (6.0 * t).cos();
                    let g1 = [dr * c - rt * si, dr * si + rt * c];
                    let g2 = [d2r * c - 2.0 * dr * si - rt * c, d2r * si + 2.0 * dr * c - rt * si];
                    let diff = [rt * c - x, rt * si - y];
                    let f = diff[0] * g1[0] + diff[1] * g1[1];
                    let fp = (g1[0] * g1[0] + g1[1] * g1[1]) + (diff[0] * g2[0] + diff[1] * g2[1]);
                    let step = if fp.abs() > 1e-14 { f / fp } else { 0.0 };
                    t -= step.clamp(-0.01, 0.01);
                }
                let c = curve(t);
                let dist = ((x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1])).sqrt();
                *o = if rho < inside_radius { -dist } else { dist };
            }
        });
    Ok(())
}

/// The index of the sample of `dense` (the points `γ(j·step)` of a curve star-shaped about the
/// origin with `r_min ≤ |γ| ≤ r_max`, `step = 2π / dense.len()`) nearest to `(x, y)`, whose polar
/// angle is `polar`: the first nearest in index order, as a scan of all of them would give. The
/// scan starts at the sample nearest in angle and walks outwards both ways, and stops once no
/// sample further round can be nearer: a sample at angle `polar ± Δ` lies on that ray between
/// radii `r_min` and `r_max`, and the distance from the point to that segment grows with `Δ`.
fn nearest_sample(dense: &[[f64; 2]], step: f64, x: f64, y: f64, polar: f64, r_min: f64, r_max: f64) -> usize {
    let m = dense.len();
    let rho = x.hypot(y);
    // the squared distance from the point to the segment of radii [r_min, r_max] at angle offset Δ
    let bound = |delta: f64| {
        let c = delta.cos();
        let t = (rho * c).clamp(r_min, r_max);
        rho * rho + t * t - 2.0 * rho * t * c
    };
    let d2 = |j: usize| {
        let c = dense[j];
        (c[0] - x) * (c[0] - x) + (c[1] - y) * (c[1] - y)
    };
    let start = ((polar.rem_euclid(2.0 * std::f64::consts::PI) / step).round() as usize) % m;
    let (mut best, mut jbest) = (d2(start), start);
    let consider = |j: usize, best: &mut f64, jbest: &mut usize| {
        let dd = d2(j);
        if dd < *best || (dd == *best && j < *jbest) {
            *best = dd;
            *jbest = j;
        }
    };
    for k in 1..=m / 2 {
        // the samples k steps round either way are at least |Δ| ≥ (k − 1/2)·step off the point's
        // angle (the start is within step/2 of it): none nearer once that bound exceeds the best
        let delta = (k as f64 - 0.5) * step;
        if bound(delta.min(std::f64::consts::PI)) * (1.0 - 1e-12) > best {
            break;
        }
        consider((start + k) % m, &mut best, &mut jbest);
        consider((start + m - k) % m, &mut best, &mut jbest);
    }
    jbest
}

/// One of the library's surfaces whose signed distance is evaluated here: what the Python package
/// hands the core so that the band of such a surface is found without calling back into Python
/// ([`crate::band::discovery::discover_band`]).
#[derive(Debug, Clone, PartialEq)]
pub enum AnalyticSurface {
    /// [`sphere_signed_distance`]: a circle (2 centre coordinates) or a sphere (3).
    Sphere { centre: Vec<f64>, radius: f64 },
    /// [`torus_signed_distance`].
    Torus { centre: [f64; 3], major: f64, minor: f64 },
    /// [`ellipsoid_signed_distance`].
    Ellipsoid { centre: [f64; 3], axes: [f64; 3] },
    /// [`star_signed_distance`] (2D).
    Star { r0: f64, eps: f64 },
    /// [`rounded_cube_signed_distance`].
    RoundedCube {
        centre: [f64; 3],
        half_size: f64,
        radius: f64,
    },
    /// [`double_torus_signed_distance`].
    DoubleTorus { major: f64, minor: f64, offset: f64 },
}

impl AnalyticSurface {
    /// The surface named `kind` ("sphere", "torus", "ellipsoid", "star", "rounded-cube" or
    /// "double-torus") with the parameters in the order of the variant's fields (a sphere's centre
    /// has 2 or 3 coordinates).
    pub fn from_parameters(kind: &str, p: &[f64]) -> Result<Self> {
        let bad = || Error::invalid("parameters", format!("{p:?} are not the parameters of a {kind}"));
        Ok(match (kind, p.len()) {
            ("sphere", 3 | 4) => AnalyticSurface::Sphere { centre: p[..p.len() - 1].to_vec(), radius: p[p.len() - 1] },
            ("torus", 5) => AnalyticSurface::Torus { centre: [p[0], p[1], p[2]], major: p[3], minor: p[4] },
            ("ellipsoid", 6) => AnalyticSurface::Ellipsoid { centre: [p[0], p[1], p[2]], axes: [p[3], p[4], p[5]] },
            ("star", 2) => AnalyticSurface::Star { r0: p[0], eps: p[1] },
            ("rounded-cube", 5) => AnalyticSurface::RoundedCube { centre: [p[0], p[1], p[2]], half_size: p[3], radius: p[4] },
            ("double-torus", 3) => AnalyticSurface::DoubleTorus { major: p[0], minor: p[1], offset: p[2] },
            ("sphere" | "torus" | "ellipsoid" | "star" | "rounded-cube" | "double-torus", _) => return Err(bad()),
            _ => {
                return Err(Error::invalid(
                    "kind",
                    format!("unknown analytic surface {kind:?}; use sphere, torus, ellipsoid, star, rounded-cube or double-torus"),
                ))
            }
        })
    }

    /// The dimension of the space the surface lies in.
    pub fn ndim(&self) -> usize {
        match self {
            AnalyticSurface::Sphere { centre, .. } => centre.len(),
            AnalyticSurface::Torus { .. } | AnalyticSurface::Ellipsoid { .. } => 3,
            AnalyticSurface::RoundedCube { .. } | AnalyticSurface::DoubleTorus { .. } => 3,
            AnalyticSurface::Star { .. } => 2,
        }
    }

    /// The signed distance at the points (`ndim` coordinates each) into `out`.
    pub fn signed_distance(&self, points: &[f64], out: &mut [f64]) -> Result<()> {
        match self {
            AnalyticSurface::Sphere { centre, radius } => sphere_signed_distance(points, centre, *radius, out),
            AnalyticSurface::Torus { centre, major, minor } => {
                torus_signed_distance(points, *centre, *major, *minor, out)
            }
            AnalyticSurface::Ellipsoid { centre, axes } => ellipsoid_signed_distance(points, *centre, *axes, out),
            AnalyticSurface::Star { r0, eps } => star_signed_distance(points, *r0, *eps, out),
            AnalyticSurface::RoundedCube {
                centre,
                half_size,
                radius,
            } => rounded_cube_signed_distance(points, *centre, *half_size, *radius, out),
            AnalyticSurface::DoubleTorus { major, minor, offset } => {
                double_torus_signed_distance(points, *major, *minor, *offset, out)
            }
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn analytic_surfaces_from_their_parameters() {
        let s = AnalyticSurface::from_parameters("sphere", &[0.0, 0.0, 1.0]).unwrap();
        assert_eq!(s.ndim(), 2);
        let mut out = [0.0; 2];
        s.signed_distance(&[3.0, 0.0, 0.0, 0.5], &mut out).unwrap();
        assert_eq!(out, [2.0, -0.5]);
        assert_eq!(
            AnalyticSurface::from_parameters("torus", &[0.0, 0.0, 0.0, 0.5, 0.2])
                .unwrap()
                .ndim(),
            3
        );
        assert_eq!(
            AnalyticSurface::from_parameters("ellipsoid", &[0.0, 0.0, 0.0, 0.6, 0.45, 0.3])
                .unwrap()
                .ndim(),
            3
        );
        assert_eq!(AnalyticSurface::from_parameters("star", &[0.5, 0.2]).unwrap().ndim(), 2);
        assert!(AnalyticSurface::from_parameters("torus", &[0.5, 0.2]).is_err());
        assert!(AnalyticSurface::from_parameters("cube", &[1.0]).is_err());
    }
    use super::*;

    #[test]
    fn sphere_and_circle_distances() {
        let p = [0.0, 0.0, 0.0, 3.0, 4.0, 0.0, 1.0, 2.0, 2.0];
        let mut out = [0.0; 3];
        sphere_signed_distance(&p, &[0.0, 0.0, 0.0], 2.0, &mut out).unwrap();
        assert_eq!(out, [-2.0, 3.0, 1.0]);
        let mut out2 = [0.0; 2];
        sphere_signed_distance(&[4.0, 5.0, 1.0, 1.0], &[1.0, 1.0], 1.0, &mut out2).unwrap();
        assert_eq!(out2, [4.0, -1.0]);
        assert!(sphere_signed_distance(&p[..8], &[0.0; 3], 1.0, &mut out).is_err());
        assert!(sphere_signed_distance(&p, &[0.0; 3], 1.0, &mut out2).is_err());
    }

    #[test]
    fn torus_distances() {
        // on the outer equator, the inner equator, the top circle and the centre
        let p = [0.7, 0.0, 0.0, 0.0, -0.3, 0.0, 0.5, 0.0, 0.2, 0.0, 0.0, 0.0];
        let mut out = [0.0; 4];
        torus_signed_distance(&p, [0.0; 3], 0.5, 0.2, &mut out).unwrap();
        for (v, e) in out.iter().zip([0.0, 0.0, 0.0, 0.3]) {
            assert!((v - e).abs() < 1e-15, "{v} vs {e}");
        }
    }

    /// The root by 100 bisections of `[−a_kmin², a_max |x|]` (the algorithm before Newton's).
    fn bisected_root(x: [f64; 3], axes: [f64; 3], a2: [f64; 3], kmin: usize) -> f64 {
        let norm = ((x[0] * x[0] + x[1] * x[1]) + x[2] * x[2]).sqrt();
        let amax = axes.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let (mut lo, mut hi) = (-a2[kmin], (amax * norm + 1e-300).max(0.0));
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            let g: f64 = (0..3).map(|k| (axes[k] * x[k] / (a2[k] + mid)).powi(2)).sum::<f64>() - 1.0;
            if g > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn ellipsoid_newton_root_agrees_with_bisection_and_stays_left_of_the_root() {
        // random points in the box, points near the surface, on the coordinate planes and axes,
        // interior points on and next to the plane of the shortest axis (where the root tends to
        // −a_kmin² or does not exist), for a triaxial ellipsoid and an oblate spheroid
        let mut state = 0x2545f4914f6cdd1du64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for axes in [[0.6, 0.45, 0.3], [0.5, 0.5, 0.4], [0.3, 0.7, 0.5]] {
            let a2 = [axes[0] * axes[0], axes[1] * axes[1], axes[2] * axes[2]];
            let kmin = (0..3).fold(0, |m, k| if axes[k] < axes[m] { k } else { m });
            let mut points = Vec::new();
            for i in 0..40_000 {
                let mut x = [uniform(), uniform(), uniform()];
                match i % 8 {
                    // near the surface: scaled onto it, then moved off by up to 0.05
                    0 | 1 => {
                        let s = ((x[0] / axes[0]).powi(2) + (x[1] / axes[1]).powi(2) + (x[2] / axes[2]).powi(2)).sqrt();
                        let off = 1.0 + 0.1 * uniform();
                        x = [x[0] / s * off, x[1] / s * off, x[2] / s * off];
                    }
                    // on the plane of the shortest axis, deep inside, anywhere, or a hair off it
                    2 => x = [0.2 * x[0], 0.2 * x[1], 0.2 * x[2]],
                    3 => x[kmin] = 0.0,
                    4 => x[kmin] = 1e-12 * uniform(),
                    // a hair off the plane, below rounding against a_kmin² (t₀ on the pole)
                    6 => x[kmin] = 1e-20 * uniform(),
                    5 => x[(kmin + 1) % 3] = 0.0,
                    _ => {}
                }
                if i % 8 == 2 {
                    x[kmin] = 0.0;
                }
                points.push(x);
            }
            points.push([0.0; 3]);
            points.push([axes[0], 0.0, 0.0]);
            points.push([0.0, 0.0, 2.0]);
            for x in points {
                let t = ellipsoid_root(x, axes, a2, kmin);
                let b = bisected_root(x, axes, a2, kmin);
                let scale = 1.0f64.max(b.abs());
                assert!(
                    (t - b).abs() <= 1e-14 * scale,
                    "axes {axes:?}, x {x:?}: Newton {t}, bisection {b}"
                );
                // never right of the root: F(t) ≥ 0 up to rounding, where the root is well
                // conditioned (next to t = −a_kmin² one ulp of t moves F by far more)
                if a2[kmin] + t > 1e-6 {
                    let f: f64 = (0..3).map(|k| (axes[k] * x[k] / (a2[k] + t)).powi(2)).sum::<f64>() - 1.0;
                    assert!(f >= -1e-12, "axes {axes:?}, x {x:?}: F(t) = {f}");
                }
            }
        }
    }

    #[test]
    fn rounded_cube_and_double_torus_distances() {
        // the rounded cube: on a face, at a rounded edge and corner, inside
        let mut out = [0.0; 4];
        let p = [0.7, 0.0, 0.0, 0.6, 0.6, 0.0, 0.6, 0.6, 0.6, 0.1, 0.0, 0.0];
        rounded_cube_signed_distance(&p, [0.0; 3], 0.5, 0.1, &mut out).unwrap();
        let e = [0.2, 0.2 * 2f64.sqrt() - 0.1, 0.2 * 3f64.sqrt() - 0.1, -0.4];
        for (v, e) in out.iter().zip(e) {
            assert!((v - e).abs() < 1e-12, "{v} vs {e}");
        }
        assert!(rounded_cube_signed_distance(&p, [0.0; 3], 0.5, 0.6, &mut out).is_err());
        // the double torus: on the outer equator of either torus, at the centre of a tube
        let p = [-(0.36 + 0.35 + 0.12), 0.0, 0.0, 0.36 + 0.35, 0.0, 0.0, 0.0, 0.0, 1.0];
        let mut out = [0.0; 3];
        double_torus_signed_distance(&p, 0.35, 0.12, 0.36, &mut out).unwrap();
        let far = ((0.36f64.hypot(0.0) - 0.35).hypot(1.0)) - 0.12;
        for (v, e) in out.iter().zip([0.0, -0.12, far]) {
            assert!((v - e).abs() < 1e-12, "{v} vs {e}");
        }
        assert_eq!(
            AnalyticSurface::from_parameters("rounded-cube", &[0.0, 0.0, 0.0, 0.5, 0.1])
                .unwrap()
                .ndim(),
            3
        );
        assert!(AnalyticSurface::from_parameters("double-torus", &[0.35, 0.12]).is_err());
    }

    #[test]
    fn ellipsoid_distances() {
        // on the axes: outside, on the surface, inside; and the degenerate interior case (the
        // centre of an oblate spheroid: the closest points are the poles)
        let axes = [0.5, 0.5, 0.4];
        let p = [0.9, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.0];
        let mut out = [0.0; 4];
        ellipsoid_signed_distance(&p, [0.0; 3], axes, &mut out).unwrap();
        for (v, e) in out.iter().zip([0.4, 0.0, -0.3, -0.4]) {
            assert!((v - e).abs() < 1e-12, "{v} vs {e}");
        }
        assert!(ellipsoid_signed_distance(&p, [0.0; 3], [0.5, 0.0, 0.4], &mut out).is_err());
    }

    #[test]
    fn star_distances() {
        // against a brute-force search over 400,000 points of r(θ) = 0.5 + 0.2 sin²(3θ), at points
        // near the curve (Newton's case), far from it (the whole-curve search) and inside it
        let (r0, eps) = (0.5, 0.2);
        let p = [
            0.8, 0.0, 0.3, 0.0, 0.55, 0.33, -0.2, 0.61, 0.05, -0.02, -0.9, -0.7, 0.0, 0.0, 0.42, -0.1,
        ];
        let mut out = [0.0; 8];
        star_signed_distance(&p, r0, eps, &mut out).unwrap();
        let m = 400_000;
        let curve: Vec<(f64, f64)> = (0..m)
            .map(|j| {
                let t = 2.0 * std::f64::consts::PI * j as f64 / m as f64;
                let r = r0 + eps * (3.0 * t).sin().powi(2);
                (r * t.cos(), r * t.sin())
            })
            .collect();
        for (q, &v) in p.chunks_exact(2).zip(&out) {
            let d = curve
                .iter()
                .map(|c| (c.0 - q[0]).hypot(c.1 - q[1]))
                .fold(f64::INFINITY, f64::min);
            let th = q[1].atan2(q[0]);
            let inside = q[0].hypot(q[1]) < r0 + eps * (3.0 * th).sin().powi(2);
            let want = if inside { -d } else { d };
            assert!((v - want).abs() < 1e-6, "at {q:?}: {v} vs {want}");
        }
        assert!(star_signed_distance(&p, 0.0, eps, &mut out).is_err());
    }

    #[test]
    fn the_star_window_narrowed_to_reach_gives_the_whole_window_bits() {
        // points up to the window's limit (0.2) from the curve, for the paper's star and a
        // spikier one: the narrowed window starts Newton where the whole one does
        let mut next = crate::test_random::uniform(99);
        for (r0, eps) in [(0.5, 0.2), (0.3, 0.5), (1.0, 0.05)] {
            let mut p = Vec::new();
            for _ in 0..100_000 {
                let th = 2.0 * std::f64::consts::PI * next();
                let off = 0.4 * next() - 0.2;
                let r = r0 + eps * (3.0 * th).sin().powi(2) + off;
                p.extend_from_slice(&[r * th.cos(), r * th.sin()]);
            }
            let (mut a, mut b) = (vec![0.0; p.len() / 2], vec![0.0; p.len() / 2]);
            star_signed_distance_with(&p, r0, eps, &mut a, false).unwrap();
            star_signed_distance_with(&p, r0, eps, &mut b, true).unwrap();
            for i in 0..a.len() {
                assert_eq!(
                    a[i].to_bits(),
                    b[i].to_bits(),
                    "r0 {r0}, eps {eps}, point {:?}",
                    &p[2 * i..2 * i + 2]
                );
            }
        }
    }

    #[test]
    fn the_pruned_search_finds_the_sample_a_full_scan_finds() {
        let (r0, eps) = (0.5, 0.2);
        let m = 4096;
        let step = 2.0 * std::f64::consts::PI / m as f64;
        let dense: Vec<[f64; 2]> = (0..m)
            .map(|j| {
                let t = j as f64 * step;
                let r = r0 + eps * (3.0 * t).sin().powi(2);
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let mut uniform = crate::test_random::uniform(12345);
        let mut next = || uniform() * 2.0 - 1.0;
        for _ in 0..20_000 {
            let (x, y) = (next() * 1.2, next() * 1.2);
            let full = (0..m)
                .min_by(|&a, &b| {
                    let da = (dense[a][0] - x).powi(2) + (dense[a][1] - y).powi(2);
                    let db = (dense[b][0] - x).powi(2) + (dense[b][1] - y).powi(2);
                    da.partial_cmp(&db).unwrap().then(a.cmp(&b))
                })
                .unwrap();
            let pruned = nearest_sample(&dense, step, x, y, y.atan2(x), r0, r0 + eps);
            assert_eq!(pruned, full, "at ({x}, {y})");
        }
    }
}
