//! The local solvers ("schemes"): the value one node takes from its neighbours. The inner tube
//! solves the eikonal equation with the Godunov update (paper Eq. (3)) or the Lax–Friedrichs one
//! (Eq. (4), and its general form for `H(x, ∇u) = 0` of Sect. 5.1 with the built-in
//! [`hamiltonians`]), or the convex anisotropic ones with the [`upwind`] local solver (ref. [35]); the extension layer applies the upwind update (5) to Eq. (8). A new
//! Hamiltonian is one file implementing [`Hamiltonian`]; a new local solver is one file here and
//! one arm of [`InnerScheme`] dispatched in the sweep's kernel (`sweep/kernel.rs`).

pub mod extension;
pub mod godunov;
pub mod hamiltonian;
pub mod hamiltonians;
pub mod lax_friedrichs;
pub mod limited_godunov;
pub mod upwind;

pub use hamiltonian::{Hamiltonian, InnerScheme};
pub use upwind::LocalSolver;
