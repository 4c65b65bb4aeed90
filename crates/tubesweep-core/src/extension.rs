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

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(extension_update([0.0f32, 0.0], [1.0, 1.0], [1.0, 1.0], [true; 2], [true; 2]), None);
    }
}
