//! The built-in upwind solvers by name, for the sweep's static dispatch: the kernel runs a row
//! loop specialised for each of them (the `specialised!` macro of `sweep/mod.rs`), so that the
//! local solve of the moving medium or the metric is inlined into the loop as the Godunov update
//! (3) is, instead of being called through the [`super::LocalSolver`] trait object at every node. Other
//! solvers (and [`crate::scheme::hamiltonians::Isotropic`] through this interface) keep the call
//! through the trait object. Either way the values are the same bits.

use crate::scheme::hamiltonians::{MovingMedium, SymmetricMetric};

/// Which built-in solver a [`super::LocalSolver`] is ([`super::LocalSolver::builtin`]).
#[derive(Clone, Copy)]
pub enum Builtin<'s, const D: usize> {
    /// The moving medium `F|p| + v·p = 1` ([`super::moving_medium`]).
    MovingMedium(&'s MovingMedium<'s, D>),
    /// The Riemannian metric `F sqrt(pᵀ M p) = 1` ([`super::metric`]).
    Metric(&'s SymmetricMetric<'s, D>),
    /// Any other solver: called through the trait object.
    Other,
}
