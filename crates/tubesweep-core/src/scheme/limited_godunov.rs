//! The limited second-order Godunov local solver for the factored eikonal equation
//! (design note `second-order-tube.md`, Sect. 2; a second-order form of the paper's Eq. (3)).
//!
//! The unknown is split as `u = u₀ + w` with a known factor `u₀` (the source's slowness times the
//! distance to it), so that `w` is smooth at the source. Along axis `k`, on side `σ = ±1`, with the
//! neighbour values `u₁`, `u₂` at distances 1 and 2 (and `wⱼ = uⱼ − u₀(xⱼ)`):
//!
//! ```text
//!     t = clip((u₁ − u₂) / ε, 0, 1)        (0 if u₂ is missing)
//!     c = 1 + t/2,   a = (w₁ + (t/2)(2w₁ − w₂)) / c,   H = Δx / c
//!     A = a + σ H ∂ₖu₀(xᵢ)
//! ```
//!
//! `t = 1` is the BDF2 one-sided difference (`a = (4w₁ − w₂)/3`, `H = 2Δx/3`), `t = 0` the
//! first-order one; the ramp `t` makes the update a continuous function of the neighbours (a hard
//! switch between the two made the sweeps fall into limit cycles). The new `w` is the root of
//!
//! ```text
//!     Σₖ max(0, (w − A⁻ₖ)/H⁻ₖ, (w − A⁺ₖ)/H⁺ₖ)² = s²,
//! ```
//!
//! `s` the slowness at the node: Eq. (3) with one-sided differences of either order. The left side
//! is convex and increasing where positive, so Newton's method from `w₀ = minₖσ (A + sH)` (at or
//! above the root) decreases monotonically to it.

/// One side of one axis, as the root finder sees it: `w ≥ a` makes the side upwind, with the
/// difference `(w − a)/h`. A missing side (no neighbour, or one not reached yet) has `a = +∞`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Side {
    pub a: f64,
    pub h: f64,
}

impl Side {
    pub const MISSING: Side = Side {
        a: f64::INFINITY,
        h: 1.0,
    };

    /// The side built from the neighbours' factored values `w1`, `w2` (`w2` is read only when
    /// `t > 0`), the ramp `t ∈ [0, 1]`, the spacing `dx` and `sigma_g = σ ∂ₖu₀(xᵢ)`.
    #[inline(always)]
    pub fn limited(w1: f64, w2: f64, t: f64, dx: f64, sigma_g: f64) -> Side {
        if t > 0.0 {
            let c = 1.0 + 0.5 * t;
            let h = dx / c;
            let a = (w1 + 0.5 * t * (2.0 * w1 - w2)) / c;
            Side { a: a + sigma_g * h, h }
        } else {
            Side {
                a: w1 + sigma_g * dx,
                h: dx,
            }
        }
    }
}

/// The ramp `t = clip((u1 − u2)/eps, 0, 1)`; 0 when `u2` is not finite (missing or not reached).
#[inline(always)]
pub fn ramp(u1: f64, u2: f64, eps: f64) -> f64 {
    if !u2.is_finite() {
        return 0.0;
    }
    let t = (u1 - u2) / eps;
    if t >= 1.0 {
        1.0
    } else if t > 0.0 {
        t
    } else {
        0.0
    }
}

/// The root `w` of `Σₖ max(0, maxσ (w − a)/h)² = s²` over the sides of `D` axes; `+∞` when every
/// side is missing. Newton's method from above, to a relative step of 1e-13 (3–6 steps).
#[inline]
pub fn limited_root<const D: usize>(sides: &[[Side; 2]; D], s: f64) -> f64 {
    limited_root_from(sides, s, f64::NAN)
}

/// The left side `Σₖ max(0, maxσ (w − a)/h)²` and its derivative.
#[inline(always)]
fn residual<const D: usize>(sides: &[[Side; 2]; D], w: f64) -> (f64, f64) {
    let mut f = 0.0;
    let mut fp = 0.0;
    for axis in sides {
        // the larger of the two sides' differences (each an increasing function of w)
        let d0 = (w - axis[0].a) / axis[0].h;
        let d1 = (w - axis[1].a) / axis[1].h;
        let (d, h) = if d0 >= d1 { (d0, axis[0].h) } else { (d1, axis[1].h) };
        if d > 0.0 {
            f += d * d;
            fp += 2.0 * d / h;
        }
    }
    (f, fp)
}

/// [`limited_root`] with a guess `hint` (e.g. the node's current value): Newton starts there
/// instead when it lies at or above the root and below the usual start, which saves most of
/// the steps once the sweeps have nearly converged. The root is the same (to the stopping
/// test's 1e-13).
#[inline]
pub fn limited_root_from<const D: usize>(sides: &[[Side; 2]; D], s: f64, hint: f64) -> f64 {
    let mut w = f64::INFINITY;
    for axis in sides {
        for side in axis {
            w = w.min(side.a + s * side.h);
        }
    }
    if !w.is_finite() {
        return w;
    }
    let s2 = s * s;
    if hint < w && residual(sides, hint).0 >= s2 {
        w = hint;
    }
    for _ in 0..60 {
        let (f, fp) = residual(sides, w);
        let r = f - s2;
        if r <= 0.0 || fp <= 0.0 {
            return w;
        }
        let step = r / fp;
        w -= step;
        if step <= 1e-13 * (w.abs() + s * sides[0][0].h.min(sides[0][1].h)) {
            return w;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::godunov::godunov_update;

    #[test]
    fn first_order_sides_give_the_classical_godunov_update() {
        // t = 0 everywhere, no factor: Eq. (3) with the smaller neighbour per axis
        let dx = 0.1;
        let cases: [([f64; 6], f64); 4] = [
            ([1.0, 1.2, 0.95, f64::INFINITY, 1.3, 1.01], 2.0),
            ([0.0, 0.5, 0.0, 0.7, 0.0, 0.9], 1.0),
            ([3.0, 3.0, f64::INFINITY, 2.0, 5.0, 9.0], 0.3),
            ([1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 1.0),
        ];
        for (n, s) in cases {
            let sides: [[Side; 2]; 3] = std::array::from_fn(|k| {
                std::array::from_fn(|j| {
                    let v = n[2 * k + j];
                    if v.is_finite() {
                        Side::limited(v, f64::NAN, 0.0, dx, 0.0)
                    } else {
                        Side::MISSING
                    }
                })
            });
            let mins: [f64; 3] = std::array::from_fn(|k| n[2 * k].min(n[2 * k + 1]));
            let expect = godunov_update(mins, dx * s);
            let got = limited_root(&sides, s);
            assert!((got - expect).abs() < 1e-13, "{got} vs {expect}");
        }
    }

    #[test]
    fn bdf2_is_exact_for_a_quadratic_plane_wave() {
        // u(x, y) = x·cos θ + y·sin θ solves |∇u| = 1; BDF2 differences are exact on it
        let (c, s) = (0.6f64, 0.8f64);
        let dx = 0.05;
        let u = |i: f64, j: f64| dx * (i * c + j * s);
        let sides: [[Side; 2]; 2] = [
            [
                Side::limited(
                    u(-1.0, 0.0),
                    u(-2.0, 0.0),
                    ramp(u(-1.0, 0.0), u(-2.0, 0.0), dx * dx),
                    dx,
                    0.0,
                ),
                Side::MISSING,
            ],
            [Side::limited(u(0.0, -1.0), u(0.0, -2.0), 1.0, dx, 0.0), Side::MISSING],
        ];
        assert_eq!(ramp(u(-1.0, 0.0), u(-2.0, 0.0), dx * dx), 1.0);
        let w = limited_root(&sides, 1.0);
        assert!((w - u(0.0, 0.0)).abs() < 1e-14, "{w}");
    }

    #[test]
    fn the_factor_gradient_makes_a_cone_exact() {
        // u = u₀ (w ≡ 0) with any ∂u₀ of unit length: the root is w = 0 whatever t
        let g = [0.28f64, -0.96];
        for t in [0.0, 0.3, 1.0] {
            let sides: [[Side; 2]; 2] = std::array::from_fn(|k| {
                [
                    Side::limited(0.0, 0.0, t, 0.1, -g[k]),
                    Side::limited(0.0, 0.0, t, 0.1, g[k]),
                ]
            });
            let w = limited_root(&sides, 1.0);
            assert!(w.abs() < 1e-14, "t = {t}: {w}");
        }
    }

    #[test]
    fn a_hint_gives_the_same_root() {
        let sides = [
            [
                Side::limited(0.3, 0.1, 1.0, 0.1, -0.2),
                Side::limited(0.5, 0.9, 0.0, 0.1, 0.2),
            ],
            [Side::limited(0.35, 0.3, 0.4, 0.1, 0.1), Side::MISSING],
            [
                Side::limited(0.2, 0.0, 1.0, 0.1, 0.05),
                Side::limited(0.6, 0.7, 0.0, 0.1, -0.05),
            ],
        ];
        let root = limited_root(&sides, 1.5);
        for hint in [
            root - 0.01,
            root,
            root + 1e-9,
            root + 0.01,
            f64::NAN,
            f64::INFINITY,
            -1e300,
        ] {
            let w = limited_root_from(&sides, 1.5, hint);
            assert!((w - root).abs() < 1e-13, "{hint}: {w} vs {root}");
        }
    }

    #[test]
    fn ramp_is_continuous_and_clipped() {
        assert_eq!(ramp(1.0, 2.0, 0.01), 0.0);
        assert_eq!(ramp(1.0, 0.0, 0.01), 1.0);
        assert!((ramp(1.0, 0.995, 0.01) - 0.5).abs() < 1e-9);
        assert_eq!(ramp(1.0, f64::INFINITY, 0.01), 0.0);
        assert_eq!(ramp(1.0, f64::NAN, 0.01), 0.0);
        assert_eq!(limited_root(&[[Side::MISSING; 2]; 3], 1.0), f64::INFINITY);
    }
}
