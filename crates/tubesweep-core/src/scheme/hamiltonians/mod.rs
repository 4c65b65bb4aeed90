//! Built-in Hamiltonians `H(x, p)` for the general Lax–Friedrichs sweeping update of Sect. 5.1.
//!
//! Each type is one small, self-contained implementation of [`crate::Hamiltonian`]: the value
//! `H(x_n, p)` at a band node and artificial viscosities `σ_k ≥ max_p |∂H/∂p_k|` at that node.
//! All of them are written as `H(x, p) = (something homogeneous of degree one in p) − s(x)`
//! with the slowness `s = 1/F`, so `H = 0` is an eikonal-type equation whose solution is a
//! first-arrival time.
//!
//! | type | equation | paper |
//! |---|---|---|
//! | [`Isotropic`] | `|∇u| = 1/F` | Eq. (1), Sect. 5.1 |
//! | [`MovingMedium`] | `|∇u| = |1 − v·∇u| / F` | Sect. 6.3 |
//! | [`Metric`] | `sqrt(∇uᵀ M ∇u) = 1/F` | Sect. 5.1 (anisotropic) |
//!
//! [`SymmetricMetric`] is the metric as the upwind local solver ([`crate::scheme::upwind`]) reads
//! it: `(M + Mᵀ)/2` packed, `D(D+1)/2` numbers per node, or one matrix for all nodes.
//!
//! Viscosities are the exact per-node suprema of `|∂H/∂p_k|` over all `p` (so the local
//! Lax–Friedrichs update is monotone at every node); each type accepts a constant override
//! `sigma`, which must be at least as large to keep the scheme monotone.

pub mod isotropic;
pub mod metric;
pub mod moving_medium;
pub mod symmetric_metric;

pub use isotropic::Isotropic;
pub use metric::Metric;
pub use moving_medium::MovingMedium;
pub use symmetric_metric::SymmetricMetric;

/// Slowness `1/F` at a node from a per-node slice, or a constant when the slice has length 1.
#[inline(always)]
pub(crate) fn slowness_at(s: &[f64], node: usize) -> f64 {
    if s.len() == 1 {
        s[0]
    } else {
        s[node]
    }
}

/// Euclidean norm of `p`.
#[inline(always)]
pub(crate) fn norm<const D: usize>(p: &[f64; D]) -> f64 {
    p.iter().map(|x| x * x).sum::<f64>().sqrt()
}
