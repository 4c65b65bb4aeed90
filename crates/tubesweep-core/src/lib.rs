//! # tubesweep-core
//!
//! Fast sweeping solvers for the eikonal equation on curves and surfaces that are given
//! implicitly, after T. Wong and S. Leung, *A Fast Sweeping Method for Eikonal Equations on
//! Implicit Surfaces*, J. Sci. Comput. 67 (2016) 837–859 ("the paper"). Pure Rust (no Python).
//!
//! The map, in the order data flows through a solve:
//!
//! | folder | what lives there | paper |
//! |---|---|---|
//! | [`surface`] | evaluating Σ: analytic signed distances, closest points on meshes and open surfaces, re-distancing | Sect. 4, 5.2 |
//! | [`band`] | the narrow band (inner tube + extension layer), its discovery, directions, facing sheets, row schedule | Fig. 4, Eq. (8) |
//! | [`scheme`] | the local solvers: Godunov, Lax–Friedrichs, the extension update, Hamiltonians, the upwind solvers of general Hamiltonians, the limited second-order Godunov | Eqs. (3), (4), (5), Sect. 5.1 |
//! | [`sweep`] | the Gauss–Seidel sweeps over the band (Algorithms 1–3), in parallel, the rim, the front window, many sources on one band, the second-order factored box | Algorithms 1–3 |
//! | [`second_order`] | `order=2`: the metric-corrected tube equation, its geometry, factored sources, BDF2 local solvers and sweeps | beyond the paper (docs/second-order.md) |
//! | [`solution`] | interpolation in the band (multilinear, cubic), nearest-source labels | — |
//! | [`error`], [`kernel_stats`] | the error type; profiling counters (feature `kernel-stats`, empty without it) | — |
//!
//! Grids are uniform with spacing `h` in every axis; node `(i, j[, k])` sits at
//! `lower + h * (i, j[, k])`, and nodes are numbered in C order (the last axis varies fastest),
//! like a NumPy array of the grid's shape.

pub mod band;
pub mod error;
pub mod kernel_stats;
mod prefetch;
pub mod scheme;
pub mod second_order;
pub mod solution;
pub mod surface;
pub mod sweep;
#[cfg(test)]
mod test_bands;
#[cfg(test)]
mod test_random;
mod union_find;

pub use band::NarrowBand;
pub use error::{Error, Result};
pub use scheme::{Hamiltonian, InnerScheme, LocalSolver};
pub use sweep::{Control, IterationReport, NodeRole, SolveOptions, SolveStats, SweepProblem};

/// The default "numerical infinity": large enough to dominate any travel time a user will meet
/// in a unit-sized box, small enough that the Lax–Friedrichs update (which averages neighbours)
/// never overflows or produces NaN. See [`SolveOptions::infinity`].
pub const DEFAULT_INFINITY: f64 = 1.0e6;
