//! The closest point on the Möbius band of the paper's Sect. 5.2 (an open, non-orientable
//! surface given by its closest-point function):
//!
//! ```text
//!     X(θ, s) = ((R + s cos(θ/2)) cos θ, (R + s cos(θ/2)) sin θ, s sin(θ/2)),   |s| ≤ w.
//! ```
//!
//! The algorithm of the Python `MobiusBand._closest_parameters_numpy`, point by point on all
//! threads instead of vectorised: the interior critical point of `½|X(θ, s) − x|²` by Newton's
//! method in `(θ, s)`, and the nearest point of each boundary curve `s = ±w` by Newton's method in
//! `θ`, all from `θ₀ = atan2(y, x)`; the nearest admissible candidate wins (a minimum over the
//! closed band is an interior critical point or lies on the boundary). The sines and cosines come
//! from another library than NumPy's, so the parameters agree with the NumPy version to rounding,
//! and at the few points equidistant from two candidates either may win.

use crate::error::{Error, Result};
use crate::surface::mesh::{dot, sub};
use rayon::prelude::*;

/// Points per parallel task.
const CHUNK: usize = 1 << 10;

/// Newton steps are clipped to this length in `θ` and `s`.
const MAX_STEP: f64 = 0.2;

/// A point stops iterating once its step falls to this.
const STEP_TOL: f64 = 1e-13;

/// The band's parametrisation and the derivatives the Newton steps need at `(θ, s)`:
/// `X, X_θ, X_s, X_θθ, X_θs` (`X_ss = 0`: the band is ruled).
#[inline]
fn derivatives(r: f64, th: f64, s: f64) -> [[f64; 3]; 5] {
    let (s2, c2) = (0.5 * th).sin_cos();
    let (si, c) = th.sin_cos();
    let rho = r + s * c2;
    [
        [rho * c, rho * si, s * s2],
        [-0.5 * s * s2 * c - rho * si, -0.5 * s * s2 * si + rho * c, 0.5 * s * c2],
        [c2 * c, c2 * si, s2],
        [
            -0.25 * s * c2 * c + s * s2 * si - rho * c,
            -0.25 * s * c2 * si - s * s2 * c - rho * si,
            -0.25 * s * s2,
        ],
        [-0.5 * s2 * c - c2 * si, -0.5 * s2 * si + c2 * c, 0.5 * c2],
    ]
}

/// The band's point `X(θ, s)`.
#[inline]
pub fn mobius_point(r: f64, th: f64, s: f64) -> [f64; 3] {
    let (s2, c2) = (0.5 * th).sin_cos();
    let (si, c) = th.sin_cos();
    let rho = r + s * c2;
    [rho * c, rho * si, s * s2]
}

/// The interior critical point of `½|X(θ, s) − x|²` from `θ₀`: Newton's method in `(θ, s)` where
/// the Hessian is positive definite, a gradient step elsewhere, steps clipped to [`MAX_STEP`], at
/// most `iterations` steps.
fn interior(r: f64, x: [f64; 3], th0: f64, iterations: usize) -> (f64, f64) {
    let d0 = derivatives(r, th0, 0.0);
    let mut th = th0;
    let mut s = dot(sub(x, d0[0]), d0[2]);
    for _ in 0..iterations {
        let [p, pt, ps, ptt, pts] = derivatives(r, th, s);
        let d = sub(p, x);
        let (g1, g2) = (dot(d, pt), dot(d, ps));
        let tt = dot(pt, pt);
        let h11 = tt + dot(d, ptt);
        let h12 = dot(pt, ps) + dot(d, pts);
        let h22 = dot(ps, ps);
        let det = h11 * h22 - h12 * h12;
        let (dth, ds) = if det > 1e-14 && h11 > 0.0 {
            ((h22 * g1 - h12 * g2) / det, (h11 * g2 - h12 * g1) / det)
        } else {
            (g1 / tt.max(1e-14), g2)
        };
        let (dth, ds) = (dth.clamp(-MAX_STEP, MAX_STEP), ds.clamp(-MAX_STEP, MAX_STEP));
        th -= dth;
        s -= ds;
        if !(dth.abs().max(ds.abs()) > STEP_TOL) {
            break;
        }
    }
    (th, s)
}

/// The nearest point of the boundary curve `s = sb` from `θ₀`: Newton's method in `θ` (a gradient
/// step where the second derivative is not positive), steps clipped, at most `iterations` steps.
fn boundary(r: f64, x: [f64; 3], th0: f64, sb: f64, iterations: usize) -> f64 {
    let mut th = th0;
    for _ in 0..iterations {
        let [p, pt, _, ptt, _] = derivatives(r, th, sb);
        let d = sub(p, x);
        let g = dot(d, pt);
        let tt = dot(pt, pt);
        let h = tt + dot(d, ptt);
        let step = if h > 1e-14 { g / h } else { g / tt.max(1e-14) };
        let step = step.clamp(-MAX_STEP, MAX_STEP);
        th -= step;
        if !(step.abs() > STEP_TOL) {
            break;
        }
    }
    th
}

/// The parameters `(θ, s)` of the closest point on the Möbius band (centre radius `r`,
/// half-width `w`) of each point (`M` rows of 3 coordinates), into `theta` and `s`, with at most
/// `iterations` Newton steps per candidate (module notes).
pub fn mobius_closest_parameters(
    points: &[f64],
    r: f64,
    w: f64,
    iterations: usize,
    theta: &mut [f64],
    s: &mut [f64],
) -> Result<()> {
    if !points.len().is_multiple_of(3) {
        return Err(Error::invalid("points", "expected an (M, 3) array"));
    }
    let m = points.len() / 3;
    if theta.len() != m || s.len() != m {
        return Err(Error::invalid("out", format!("expected {m} values (one per point)")));
    }
    if !(w > 0.0 && w < r && r.is_finite()) {
        return Err(Error::invalid("w", format!("need 0 < w < R, got R = {r}, w = {w}")));
    }
    theta
        .par_chunks_mut(CHUNK)
        .zip(s.par_chunks_mut(CHUNK))
        .zip(points.par_chunks(3 * CHUNK))
        .for_each(|((theta, s), p)| {
            for ((t_out, s_out), x) in theta.iter_mut().zip(s.iter_mut()).zip(p.chunks_exact(3)) {
                let x = [x[0], x[1], x[2]];
                let th0 = x[1].atan2(x[0]);
                let (ti, si) = interior(r, x, th0, iterations);
                let mut best = (f64::INFINITY, th0, 0.0);
                // the interior candidate counts only inside the band; then the boundaries, in order
                let candidates = [
                    (ti, si, si.abs() <= w),
                    (boundary(r, x, th0, -w, iterations), -w, true),
                    (boundary(r, x, th0, w, iterations), w, true),
                ];
                for (th, sv, ok) in candidates {
                    let q = sub(mobius_point(r, th, sv), x);
                    let d = dot(q, q).sqrt();
                    if ok && d < best.0 {
                        best = (d, th, sv);
                    }
                }
                *t_out = best.1;
                *s_out = best.2;
            }
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance from `x` to the band by brute force: the nearest of a fine parameter grid,
    /// then refined by a local grid search.
    fn brute_force_distance(r: f64, w: f64, x: [f64; 3]) -> f64 {
        let (nt, ns) = (2000, 200);
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in 0..nt {
            let th = 2.0 * std::f64::consts::PI * i as f64 / nt as f64;
            for j in 0..=ns {
                let s = -w + 2.0 * w * j as f64 / ns as f64;
                let q = sub(mobius_point(r, th, s), x);
                let d = dot(q, q);
                if d < best.0 {
                    best = (d, th, s);
                }
            }
        }
        let (mut dt, mut ds) = (2.0 * std::f64::consts::PI / nt as f64, 2.0 * w / ns as f64);
        for _ in 0..40 {
            let (d0, t0, s0) = best;
            let mut b = (d0, t0, s0);
            for a in -2..=2 {
                for c in -2..=2 {
                    let (th, s) = (t0 + 0.5 * a as f64 * dt, (s0 + 0.5 * c as f64 * ds).clamp(-w, w));
                    let q = sub(mobius_point(r, th, s), x);
                    let d = dot(q, q);
                    if d < b.0 {
                        b = (d, th, s);
                    }
                }
            }
            best = b;
            dt *= 0.6;
            ds *= 0.6;
        }
        best.0.sqrt()
    }

    #[test]
    fn closest_points_are_the_nearest_points_of_the_band() {
        // points near the band (within the tubes the solver uses), near its boundary and past it,
        // and on the z axis far from it; against a brute-force search over the parameters
        let (r, w) = (0.6, 0.3);
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut points = Vec::new();
        for _ in 0..300 {
            let (th, s) = (2.0 * std::f64::consts::PI * uniform(), -1.3 * w + 2.6 * w * uniform());
            let p = mobius_point(r, th, s);
            let off = [0.2 * uniform() - 0.1, 0.2 * uniform() - 0.1, 0.2 * uniform() - 0.1];
            points.extend_from_slice(&[p[0] + off[0], p[1] + off[1], p[2] + off[2]]);
        }
        points.extend_from_slice(&[0.0, 0.0, 0.5, 0.6, 0.0, 0.0, -0.6, 0.0, 0.1]);
        let m = points.len() / 3;
        let (mut th, mut s) = (vec![0.0; m], vec![0.0; m]);
        mobius_closest_parameters(&points, r, w, 60, &mut th, &mut s).unwrap();
        for i in 0..m {
            let x = [points[3 * i], points[3 * i + 1], points[3 * i + 2]];
            assert!(s[i].abs() <= w, "point {x:?}: s = {} outside the band", s[i]);
            let q = sub(mobius_point(r, th[i], s[i]), x);
            let d = dot(q, q).sqrt();
            let exact = brute_force_distance(r, w, x);
            assert!(
                (d - exact).abs() < 1e-9,
                "point {x:?}: distance {d} against {exact} by brute force"
            );
        }
    }

    #[test]
    fn rejects_bad_shapes_and_widths() {
        let (mut th, mut s) = (vec![0.0; 1], vec![0.0; 1]);
        assert!(mobius_closest_parameters(&[0.0, 0.0], 0.6, 0.3, 60, &mut th, &mut s).is_err());
        assert!(mobius_closest_parameters(&[0.0, 0.0, 0.0], 0.6, 0.7, 60, &mut th, &mut s).is_err());
        assert!(mobius_closest_parameters(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0], 0.6, 0.3, 60, &mut th, &mut s).is_err());
    }
}
