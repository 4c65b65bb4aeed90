//! The extension update in the outer layer (paper Eq. (8), discretised with the upwind
//! update (5)).
//!
//! In the extension layer `h_in < |φ| ≤ h_out` the solution is extended constantly along the
//! outward direction `v = sgn(φ) n` (for a closest-point surface, `v = (x − cp(x)) / |x − cp(x)|`,
//! Sect. 5.2) by solving `v · ∇u = 0`. With `v_k^± = (v_k ± |v_k|)/2`, Eq. (5) reads
//!
//! ```text
//!     u ← Σ_k ( v_k^+ u_{k−} − v_k^− u_{k+} ) / Σ_k |v_k| ,
//! ```
//!
//! a convex combination of the *upwind* neighbours (those closer to the surface).

/// Upwind extension update (Eq. (5)) with direction `v`. `minus[k]`, `plus[k]` are the neighbour
/// values along axis `k` and `present_minus[k]`, `present_plus[k]` say whether those neighbours
/// exist in the band. An absent upwind neighbour is left out and the weights renormalised; when no
/// upwind neighbour exists (or `v` vanishes, e.g. on a medial axis) the update returns `None` and
/// the node keeps its value.
#[inline(always)]
pub fn extension_update<const D: usize>(
    v: [f32; D],
    minus: [f64; D],
    plus: [f64; D],
    present_minus: [bool; D],
    present_plus: [bool; D],
) -> Option<f64> {
    let mut num = 0.0;
    let mut den = 0.0;
    for k in 0..D {
        let w = v[k] as f64;
        if w > 0.0 {
            if present_minus[k] {
                num += w * minus[k];
                den += w;
            }
        } else if w < 0.0 && present_plus[k] {
            num += -w * plus[k];
            den += -w;
        }
    }
    if den > 1e-12 {
        Some(num / den)
    } else {
        None
    }
}

/// Upwind weights of Eq. (5) for direction `v`, normalised to sum 1: `weights[k] > 0` weighs the
/// minus neighbour along axis `k`, `< 0` the plus neighbour (with weight `|weights[k]|`). Absent
/// upwind neighbours get weight 0 and the rest is renormalised; `None` when no upwind neighbour
/// exists or `v` vanishes. The band structure does not change during a solve, so the solver
/// computes these once and the update becomes [`extension_apply`].
#[inline]
pub fn extension_weights<const D: usize>(
    v: [f32; D],
    present_minus: [bool; D],
    present_plus: [bool; D],
) -> Option<[f32; D]> {
    let mut w = [0.0f64; D];
    let mut den = 0.0;
    for k in 0..D {
        let c = v[k] as f64;
        if c > 0.0 && present_minus[k] {
            w[k] = c;
            den += c;
        } else if c < 0.0 && present_plus[k] {
            w[k] = c;
            den -= c;
        }
    }
    if den > 1e-12 {
        let mut out = [0.0f32; D];
        for k in 0..D {
            out[k] = (w[k] / den) as f32;
        }
        Some(out)
    } else {
        None
    }
}

/// The extension update (5) with precomputed [`extension_weights`].
#[inline(always)]
pub fn extension_apply<const D: usize>(weights: [f32; D], minus: [f64; D], plus: [f64; D]) -> f64 {
    let mut acc = 0.0;
    for k in 0..D {
        let w = weights[k] as f64;
        // branch-free: exactly one of the two weights is non-zero (neighbour values are finite)
        let wm = if w > 0.0 { w } else { 0.0 };
        let wp = if w < 0.0 { -w } else { 0.0 };
        acc += wm * minus[k] + wp * plus[k];
    }
    acc
}

/// The extension update (5) with precomputed [`extension_weights`], reading only the upwind
/// neighbour along each axis: `neighbours[k] = [minus, plus]`, `value(i)` the value of node `i`.
/// Bit-identical to [`extension_apply`] (the terms it adds for the downwind side are exact zeros).
#[inline(always)]
pub fn extension_apply_upwind<const D: usize>(
    weights: [f32; D],
    neighbours: &[[u32; 2]; D],
    value: impl Fn(u32) -> f64,
) -> f64 {
    let mut acc = 0.0;
    for k in 0..D {
        let w = weights[k] as f64;
        acc += w.abs() * value(neighbours[k][(w < 0.0) as usize]);
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precomputed_weights_agree_with_the_direct_update() {
        let v = [0.6f32, -0.48, 0.64];
        let (minus, plus) = ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]);
        for pm in [[true, true, true], [false, true, true]] {
            let direct = extension_update(v, minus, plus, pm, [true; 3]).unwrap();
            let w = extension_weights(v, pm, [true; 3]).unwrap();
            assert!((extension_apply(w, minus, plus) - direct).abs() < 1e-6);
        }
        assert!(extension_weights([1.0f32, 0.0], [false, true], [true, true]).is_none());
    }

    #[test]
    fn follows_the_axis_direction() {
        let got = extension_update([1.0f32, 0.0], [2.0, 9.0], [7.0, 9.0], [true; 2], [true; 2]);
        assert_eq!(got, Some(2.0));
        let got = extension_update([-1.0f32, 0.0], [2.0, 9.0], [7.0, 9.0], [true; 2], [true; 2]);
        assert_eq!(got, Some(7.0));
    }

    #[test]
    fn diagonal_is_the_mean_of_upwind_values() {
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let got = extension_update([s, -s], [1.0, 5.0], [5.0, 3.0], [true; 2], [true; 2]).unwrap();
        assert!((got - 2.0).abs() < 1e-12);
    }

    #[test]
    fn missing_upwind_neighbour_is_dropped_and_vanishing_direction_skips() {
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let got = extension_update([s, s], [1.0, 5.0], [0.0, 0.0], [false, true], [true; 2]);
        assert_eq!(got, Some(5.0));
        assert_eq!(
            extension_update([0.0f32, 0.0], [1.0, 1.0], [1.0, 1.0], [true; 2], [true; 2]),
            None
        );
    }
}
