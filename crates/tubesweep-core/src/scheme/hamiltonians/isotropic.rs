//! The isotropic eikonal Hamiltonian `H(x, p) = |p| − 1/F(x)` (paper Eq. (1); Sect. 5.1 with
//! `H = |∇u| − 1/F`). `∂H/∂p_k = p_k/|p|`, so `σ_k = 1` is the exact bound, and the general
//! Lax–Friedrichs update then coincides with the eikonal update Eq. (4).

use super::{norm, slowness_at};
use crate::Hamiltonian;

/// `|p| − s(x)`, `s = 1/F`.
pub struct Isotropic<'a> {
    /// Slowness `1/F` per band node (or a single value for all nodes).
    pub slowness: &'a [f64],
    /// Constant viscosities overriding the default `σ_k = 1`.
    pub sigma: Option<&'a [f64]>,
}

impl<'a, const D: usize> Hamiltonian<D> for Isotropic<'a> {
    #[inline]
    fn value(&self, node: usize, p: [f64; D]) -> f64 {
        norm(&p) - slowness_at(self.slowness, node)
    }

    #[inline]
    fn viscosity(&self, _node: usize) -> [f64; D] {
        match self.sigma {
            Some(s) => core::array::from_fn(|k| s[k]),
            None => [1.0; D],
        }
    }

    /// `max s`: no path costs more than its length times the largest slowness.
    fn slowness_bound(&self) -> Option<f64> {
        Some(self.slowness.iter().cloned().fold(0.0, f64::max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_and_viscosity() {
        let s = [0.5];
        let h = Isotropic {
            slowness: &s,
            sigma: None,
        };
        assert!((Hamiltonian::<2>::value(&h, 7, [3.0, 4.0]) - 4.5).abs() < 1e-15);
        assert_eq!(Hamiltonian::<3>::viscosity(&h, 0), [1.0; 3]);
    }
}
