//! Which equation the inner tube solves, and the interface for general static Hamilton–Jacobi
//! equations `H(x, ∇u) = 0` solved with the Lax–Friedrichs sweeping update of Sect. 5.1.

/// A static Hamiltonian `H(x, p)` evaluated at band nodes, for the Lax–Friedrichs scheme of
/// Sect. 5.1. Implementations are small, self-contained types; the sweeping driver only calls
/// these two methods.
pub trait Hamiltonian<const D: usize>: Sync {
    /// `H(x_n, p)` at band node `node`.
    fn value(&self, node: usize, p: [f64; D]) -> f64;
    /// Artificial viscosities `σ_k ≥ max |∂H/∂p_k|` at band node `node` (Sect. 5.1).
    fn viscosity(&self, node: usize) -> [f64; D];
    /// An upper bound on the travel time per unit length (the largest `|∇u|` a solution can
    /// have), used to choose a tight numerical infinity. `None` (the default) falls back to
    /// [`crate::DEFAULT_INFINITY`].
    fn slowness_bound(&self) -> Option<f64> {
        None
    }
}

/// The local solver used in the inner tube (or the whole box for the Euclidean solver).
#[derive(Clone, Copy)]
pub enum InnerScheme<'a, const D: usize> {
    /// Godunov update, Eq. (3): upwind, monotone; converges in few iterations.
    Godunov,
    /// Lax–Friedrichs update for the eikonal equation, Eq. (4), with monotone acceptance.
    LaxFriedrichs,
    /// Lax–Friedrichs update of Sect. 5.1 for a general Hamiltonian, with monotone acceptance.
    General(&'a dyn Hamiltonian<D>),
    /// An upwind (Godunov-type) local solver for a convex Hamiltonian ([`crate::scheme::upwind`]):
    /// monotone, so no acceptance rule is needed beyond keeping the smaller value.
    Upwind(&'a dyn crate::scheme::upwind::LocalSolver<D>),
}

/// The isotropic eikonal Hamiltonian `H(x, p) = |p| − s(x)` with slowness `s = 1/F`. With
/// `σ_k = 1` the general Lax–Friedrichs update reduces to Eq. (4); it exists so the general code
/// path can be checked against the specialised one.
pub struct IsotropicEikonal<'a> {
    pub slowness: &'a [f64],
}

impl<'a, const D: usize> Hamiltonian<D> for IsotropicEikonal<'a> {
    #[inline]
    fn value(&self, node: usize, p: [f64; D]) -> f64 {
        p.iter().map(|x| x * x).sum::<f64>().sqrt() - self.slowness[node]
    }
    #[inline]
    fn viscosity(&self, _node: usize) -> [f64; D] {
        [1.0; D]
    }
    fn slowness_bound(&self) -> Option<f64> {
        Some(self.slowness.iter().cloned().fold(0.0, f64::max))
    }
}
