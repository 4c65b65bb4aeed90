//! The Lax–Friedrichs local solver (paper Eq. (4) for the eikonal equation and the general form of
//! Sect. 5.1, after Kao, Osher and Qian 2004).
//!
//! For a Hamiltonian `H(x, p)` with artificial viscosities `σ_k ≥ max |∂H/∂p_k|`, the sweeping
//! update at a node is
//!
//! ```text
//!     u ← [Σ_k σ_k / h]^{-1} · [ Σ_k σ_k (u_{k+} + u_{k−}) / (2h) − H(x, p̄) ],
//!     p̄_k = (u_{k+} − u_{k−}) / (2h)                                    (Sect. 5.1)
//! ```
//!
//! For the eikonal Hamiltonian `H = |p| − 1/F` with `σ_k = 1` this is Eq. (4):
//! `u ← mean(u_{k±}) + (h/d) (1/F − |p̄|)`.
//!
//! The update is not monotone in the neighbour values, so the sweeping driver applies the paper's
//! acceptance rule (proof of Corollary 1): a value is only ever replaced by a smaller one.

/// Eikonal Lax–Friedrichs update, Eq. (4), for `D` axes. `minus[k]`, `plus[k]` are the neighbour
/// values along axis `k`; `f = h / F` at the node.
#[inline(always)]
pub fn lxf_eikonal_update<const D: usize>(minus: [f64; D], plus: [f64; D], f: f64) -> f64 {
    let mut mean2 = 0.0; // Σ (u+ + u−)/2
    let mut grad2 = 0.0; // Σ ((u+ − u−)/2)^2  = h^2 |p̄|^2
    for k in 0..D {
        mean2 += 0.5 * (plus[k] + minus[k]);
        let d = 0.5 * (plus[k] - minus[k]);
        grad2 += d * d;
    }
    (mean2 + f - grad2.sqrt()) / D as f64
}

/// General Lax–Friedrichs update of Sect. 5.1. `hamiltonian_value` is `H(x, p̄)` evaluated by the
/// caller at the central-difference gradient `p̄`; `sigma[k]` the viscosities; `h` the spacing.
#[inline(always)]
pub fn lxf_general_update<const D: usize>(
    minus: [f64; D],
    plus: [f64; D],
    sigma: [f64; D],
    hamiltonian_value: f64,
    h: f64,
) -> f64 {
    let mut num = -hamiltonian_value;
    let mut den = 0.0;
    for k in 0..D {
        num += sigma[k] * (plus[k] + minus[k]) / (2.0 * h);
        den += sigma[k] / h;
    }
    num / den
}

/// Central-difference gradient `p̄_k = (u_{k+} − u_{k−}) / (2h)`.
#[inline(always)]
pub fn central_gradient<const D: usize>(minus: [f64; D], plus: [f64; D], h: f64) -> [f64; D] {
    let mut p = [0.0; D];
    for k in 0..D {
        p[k] = (plus[k] - minus[k]) / (2.0 * h);
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_eq4_in_2d() {
        let (ue, uw, un, us, h) = (1.0_f64, 0.8_f64, 0.95_f64, 0.85_f64, 0.1_f64);
        let expect = (ue + uw + un + us) / 4.0
            + h / 2.0 * (1.0 - (((ue - uw) / (2.0 * h)).powi(2) + ((un - us) / (2.0 * h)).powi(2)).sqrt());
        let got = lxf_eikonal_update([uw, us], [ue, un], h);
        assert!((got - expect).abs() < 1e-14);
    }

    #[test]
    fn exact_for_a_plane_wave() {
        // u = x: neighbours u ± h along x, equal along y: LxF reproduces u exactly
        let (u, h) = (0.7, 0.05);
        let got = lxf_eikonal_update([u - h, u], [u + h, u], h);
        assert!((got - u).abs() < 1e-14);
    }

    #[test]
    fn general_form_reduces_to_eikonal() {
        let (minus, plus, h) = ([0.2, 0.3, 0.25], [0.4, 0.31, 0.27], 0.1);
        let p = central_gradient(minus, plus, h);
        let hval = (p.iter().map(|x| x * x).sum::<f64>()).sqrt() - 1.0;
        let a = lxf_general_update(minus, plus, [1.0; 3], hval, h);
        let b = lxf_eikonal_update(minus, plus, h);
        assert!((a - b).abs() < 1e-14);
    }
}
