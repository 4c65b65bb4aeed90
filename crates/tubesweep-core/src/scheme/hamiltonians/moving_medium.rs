//! The anisotropic eikonal equation in a moving medium (paper Sect. 6.3, after [25]):
//!
//! ```text
//!     |∇u| = |1 − v(x)·∇u| / F(x),   i.e.   H(x, p) = |p| − s(x) |1 − v(x)·p|,   s = 1/F.
//! ```
//!
//! `u` is the first-arrival time of a wave that moves with speed `F` relative to a medium that
//! itself moves with velocity `v`: a front with unit normal `n` advances with normal speed
//! `F + v·n`. Where `|v| < F` the zero set of `H` is the same as that of the convex Hamiltonian
//! `|p| − s (1 − v·p)` (on `{H = 0}` one has `1 − v·p > 0`), so both give the same viscosity
//! solution; the absolute value is kept as the paper writes it, which only matters where the
//! flow is supersonic (`|v| ≥ F`).
//!
//! Viscosity: `∂H/∂p_k = p_k/|p| ± s v_k`, whose supremum over `p` is `σ_k = 1 + s |v_k|`, per node.

use super::{norm, slowness_at};
use crate::Hamiltonian;

/// `|p| − s(x) |1 − v(x)·p|`.
pub struct MovingMedium<'a, const D: usize> {
    /// Slowness `1/F` per band node (or a single value for all nodes).
    pub slowness: &'a [f64],
    /// Flow velocity `v` per band node (tangent to the surface; the Python layer projects it).
    pub flow: &'a [[f64; D]],
    /// Constant viscosities overriding the per-node default `1 + s |v_k|`.
    pub sigma: Option<&'a [f64]>,
}

impl<'a, const D: usize> Hamiltonian<D> for MovingMedium<'a, D> {
    #[inline]
    fn value(&self, node: usize, p: [f64; D]) -> f64 {
        let v = &self.flow[node];
        let mut vp = 0.0;
        for k in 0..D {
            vp += v[k] * p[k];
        }
        norm(&p) - slowness_at(self.slowness, node) * (1.0 - vp).abs()
    }

    #[inline]
    fn viscosity(&self, node: usize) -> [f64; D] {
        match self.sigma {
            Some(s) => core::array::from_fn(|k| s[k]),
            None => {
                let s = slowness_at(self.slowness, node);
                let v = &self.flow[node];
                core::array::from_fn(|k| 1.0 + s * v[k].abs())
            }
        }
    }

    /// `max 1/(F − |v|)`: a front never moves slower than `F − |v|` along any direction. `None`
    /// (the fixed default infinity) when the flow is supersonic somewhere.
    fn slowness_bound(&self) -> Option<f64> {
        let mut bound = 0.0f64;
        for (n, v) in self.flow.iter().enumerate() {
            let s = slowness_at(self.slowness, n);
            let sv = s * norm(v);
            if !(sv < 1.0) {
                return None;
            }
            bound = bound.max(s / (1.0 - sv));
        }
        Some(bound)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_flow_is_isotropic() {
        let s = [1.0 / 3.0];
        let flow = [[0.0; 3]];
        let h = MovingMedium {
            slowness: &s,
            flow: &flow,
            sigma: None,
        };
        assert!((h.value(0, [0.0, 3.0, 4.0]) - (5.0 - 1.0 / 3.0)).abs() < 1e-15);
        assert_eq!(h.viscosity(0), [1.0; 3]);
    }

    #[test]
    fn effective_speed_along_and_against_the_flow() {
        // u = x / (F + v) solves the equation for a flow v along +x: p = 1/(F+v)
        let (f, v) = (3.0, 1.0);
        let s = [1.0 / f];
        let flow = [[v, 0.0]];
        let h = MovingMedium {
            slowness: &s,
            flow: &flow,
            sigma: None,
        };
        assert!(h.value(0, [1.0 / (f + v), 0.0]).abs() < 1e-15);
        assert!(h.value(0, [-1.0 / (f - v), 0.0]).abs() < 1e-15);
        assert_eq!(h.viscosity(0), [1.0 + v / f, 1.0]);
        assert!((h.slowness_bound().unwrap() - 1.0 / (f - v)).abs() < 1e-15);
        let fast = [[4.0, 0.0]];
        assert!(MovingMedium {
            slowness: &s,
            flow: &fast,
            sigma: None
        }
        .slowness_bound()
        .is_none());
    }

    #[test]
    fn viscosity_bounds_the_derivative() {
        let s = [0.4];
        let flow = [[0.7, -1.3]];
        let h = MovingMedium {
            slowness: &s,
            flow: &flow,
            sigma: None,
        };
        let sig = h.viscosity(0);
        let eps = 1e-7;
        for i in 0..64 {
            let a = i as f64 * 0.1;
            let p = [2.0 * a.cos(), 2.0 * a.sin()];
            for k in 0..2 {
                let mut q = p;
                q[k] += eps;
                let d = (h.value(0, q) - h.value(0, p)) / eps;
                assert!(d.abs() <= sig[k] + 1e-6);
            }
        }
    }
}
