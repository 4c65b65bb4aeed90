//! A Riemannian (anisotropic) eikonal equation
//!
//! ```text
//!     sqrt(∇uᵀ M(x) ∇u) = 1/F(x),   i.e.   H(x, p) = sqrt(pᵀ M(x) p) − s(x),   s = 1/F,
//! ```
//!
//! with `M(x)` symmetric positive definite (Sect. 5.1 with an anisotropic `H`). `M` acts on
//! covectors: for a constant `M` the solution from a point source `x_s` is
//! `u(x) = s · sqrt((x − x_s)ᵀ M⁻¹ (x − x_s))`, the distance in the metric `M⁻¹`, whose geodesics
//! are straight lines.
//!
//! Viscosity: `∂H/∂p = M p / sqrt(pᵀ M p)`. With `p = M^{-1/2} q`, `(M p)_k / |q| =
//! (M^{1/2} q)_k / |q| ≤ |row_k(M^{1/2})| = sqrt(M_kk)`, with equality for `q ∥ row_k`; so
//! `σ_k = sqrt(M_kk)` per node is the exact supremum.

use super::slowness_at;
use crate::Hamiltonian;

/// `sqrt(pᵀ M(x) p) − s(x)`, for the Lax–Friedrichs update of Sect. 5.1 (`M` read as given, a full
/// matrix per node). The upwind local solver takes [`super::SymmetricMetric`] (the symmetric part, packed).
pub struct Metric<'a, const D: usize> {
    /// Slowness `1/F` per band node (or a single value for all nodes).
    pub slowness: &'a [f64],
    /// Symmetric positive definite `M` per band node, row-major.
    pub metric: &'a [[[f64; D]; D]],
    /// Constant viscosities overriding the per-node default `sqrt(M_kk)`.
    pub sigma: Option<&'a [f64]>,
}

impl<'a, const D: usize> Hamiltonian<D> for Metric<'a, D> {
    #[inline]
    fn value(&self, node: usize, p: [f64; D]) -> f64 {
        let m = &self.metric[node];
        let mut q = 0.0;
        for i in 0..D {
            let mut row = 0.0;
            for j in 0..D {
                row += m[i][j] * p[j];
            }
            q += p[i] * row;
        }
        q.max(0.0).sqrt() - slowness_at(self.slowness, node)
    }

    #[inline]
    fn viscosity(&self, node: usize) -> [f64; D] {
        match self.sigma {
            Some(s) => core::array::from_fn(|k| s[k]),
            None => {
                let m = &self.metric[node];
                core::array::from_fn(|k| m[k][k].max(0.0).sqrt())
            }
        }
    }

    /// `max s / sqrt(λ_min(M))` (a path in direction `e` costs `s sqrt(eᵀM⁻¹e) ≤ s/sqrt(λ_min)` per
    /// unit length), with the safe lower bound `λ_min ≥ det M / (tr M)^(D−1)`. `None` if some `M`
    /// is not positive definite.
    fn slowness_bound(&self) -> Option<f64> {
        let mut bound = 0.0f64;
        for (n, m) in self.metric.iter().enumerate() {
            let tr: f64 = (0..D).map(|k| m[k][k]).sum();
            let det = determinant(*m);
            if !(det > 0.0 && tr > 0.0) {
                return None;
            }
            let lam_min = det / tr.powi(D as i32 - 1);
            bound = bound.max(slowness_at(self.slowness, n) / lam_min.sqrt());
        }
        bound.is_finite().then_some(bound)
    }
}

/// Determinant by Gaussian elimination with partial pivoting.
pub(super) fn determinant<const D: usize>(mut a: [[f64; D]; D]) -> f64 {
    let mut det = 1.0;
    for c in 0..D {
        let p = (c..D)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        if a[p][c] == 0.0 {
            return 0.0;
        }
        if p != c {
            a.swap(p, c);
            det = -det;
        }
        det *= a[c][c];
        for r in c + 1..D {
            let f = a[r][c] / a[c][c];
            for k in c..D {
                a[r][k] -= f * a[c][k];
            }
        }
    }
    det
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_metric_is_isotropic() {
        let s = [1.0];
        let m = [[[1.0, 0.0], [0.0, 1.0]]];
        let h = Metric {
            slowness: &s,
            metric: &m,
            sigma: None,
        };
        assert!((h.value(0, [3.0, 4.0]) - 4.0).abs() < 1e-14);
        assert_eq!(h.viscosity(0), [1.0, 1.0]);
        // λ_min ≥ det/tr = 1/2: a safe (here loose by √2) bound on the true value 1
        assert!((h.slowness_bound().unwrap() - 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn slowness_bound_covers_the_slowest_direction() {
        let s = [0.5];
        let m = [[[2.0, 0.6], [0.6, 0.5]]];
        let h = Metric {
            slowness: &s,
            metric: &m,
            sigma: None,
        };
        let lam_min = (2.5 - ((1.5f64).powi(2) + 4.0 * 0.36).sqrt()) / 2.0;
        assert!(h.slowness_bound().unwrap() >= 0.5 / lam_min.sqrt());
        assert!((determinant([[2.0, 0.6, 0.0], [0.6, 0.5, 0.0], [0.0, 0.0, 3.0]]) - 3.0 * 0.64).abs() < 1e-14);
    }

    #[test]
    fn viscosity_is_the_supremum_of_the_derivative() {
        let s = [1.0];
        let m = [[[2.0, 0.6], [0.6, 0.5]]];
        let h = Metric {
            slowness: &s,
            metric: &m,
            sigma: None,
        };
        let sig = h.viscosity(0);
        let mut best = [0.0f64; 2];
        for i in 0..3600 {
            let a = i as f64 * std::f64::consts::PI / 1800.0;
            let p = [a.cos(), a.sin()];
            let mp = [
                m[0][0][0] * p[0] + m[0][0][1] * p[1],
                m[0][1][0] * p[0] + m[0][1][1] * p[1],
            ];
            let n = (p[0] * mp[0] + p[1] * mp[1]).sqrt();
            for k in 0..2 {
                best[k] = best[k].max((mp[k] / n).abs());
            }
        }
        for k in 0..2 {
            assert!(best[k] <= sig[k] + 1e-12 && best[k] > sig[k] - 1e-4, "{best:?} {sig:?}");
        }
    }

    #[test]
    fn exact_for_the_linear_solution_of_a_constant_metric() {
        // u = s sqrt(xᵀ M⁻¹ x) has p = s M⁻¹ x / sqrt(xᵀ M⁻¹ x): H(p) = 0
        let s = [0.5];
        let m = [[[2.0, 0.6], [0.6, 0.5]]];
        let det: f64 = 2.0 * 0.5 - 0.36;
        let inv = [[0.5 / det, -0.6 / det], [-0.6 / det, 2.0 / det]];
        let x: [f64; 2] = [0.3, -0.8];
        let mx: [f64; 2] = [inv[0][0] * x[0] + inv[0][1] * x[1], inv[1][0] * x[0] + inv[1][1] * x[1]];
        let n = (x[0] * mx[0] + x[1] * mx[1]).sqrt();
        let h = Metric {
            slowness: &s,
            metric: &m,
            sigma: None,
        };
        assert!(h.value(0, [0.5 * mx[0] / n, 0.5 * mx[1] / n]).abs() < 1e-14);
    }
}
