//! # tubesweep-core
//!
//! Fast sweeping solvers for the eikonal equation on curves and surfaces that are given
//! implicitly, after T. Wong and S. Leung, *A Fast Sweeping Method for Eikonal Equations on
//! Implicit Surfaces*, J. Sci. Comput. 67 (2016) 837–859 ("the paper").
//!
//! The crate is pure Rust (no Python). Its pieces follow the paper's vocabulary:
//!
//! | concept | module | paper |
//! |---|---|---|
//! | the Godunov local solver | [`godunov`] | Eq. (3) and its 3D form |
//! | the Lax–Friedrichs local solver | [`lax_friedrichs`] | Eq. (4), Sect. 5.1 |
//! | built-in Hamiltonians (isotropic, moving medium, metric) | [`hamiltonians`] | Sect. 5.1, 6.3 |
//! | the upwind extension update | [`extension`] | Eq. (5) applied to Eq. (8) |
//! | exact signed distances of the analytic surfaces (sphere, torus) | [`analytic`] | Sect. 6 |
//! | the narrow band (inner tube + extension layer) | [`band`] | Fig. 4 |
//! | where the tubes of two facing parts of the surface touch (shortcuts) | [`facing_sheets`] | Sect. 3–4 |
//! | the last split of the coarse-to-fine band search | [`discovery`] | — |
//! | the band and directions of a φ sampled on the whole grid | [`sampled`] | Eq. (8), Sect. 4 |
//! | closest points on the zero level set of a sampled φ (re-distancing) | [`redistance`] | Eq. (8), Sect. 5.2 |
//! | extension directions sgn(φ)∇φ/|∇φ| by central differences | [`normals`] | Eq. (8), Sect. 4 |
//! | the outer rim of the layer, extended into last in one pass | [`rim`] | Eq. (5) |
//! | the longest grid path from the sources (numerical infinity, front window) | [`grid_hops`] | — |
//! | the Gauss–Seidel sweeping driver | [`sweep`] | Algorithms 1, 2 and 3 |
//! | multilinear interpolation in the band | [`interpolate`] | — |
//! | which source reaches each node first (nearest-source labels) | [`nearest_source`] | — |
//! | exact closest points on triangle meshes (AABB tree) | [`mesh`] | Sect. 5.2 |
//! | closest points on the hemisphere, disc and plane patch | [`open_surfaces`] | Sect. 5.2, Fig. 9 |
//! | closest points on the Möbius band | [`mobius`] | Sect. 5.2, Fig. 9 |
//!
//! Grids are uniform with spacing `h` in every axis; node `(i, j[, k])` sits at
//! `lower + h * (i, j[, k])`, and nodes are numbered in C order (the last axis varies fastest),
//! like a NumPy array of the grid's shape.

pub mod analytic;
pub mod band;
pub mod cache_size;
pub mod discovery;
pub mod error;
pub mod extension;
pub mod facing_sheets;
pub mod godunov;
pub mod grid_hops;
pub mod hamiltonian;
pub mod hamiltonians;
pub mod interpolate;
pub mod kernel_stats;
pub mod lax_friedrichs;
pub mod many_sources;
pub mod mesh;
pub mod mesh_band;
pub mod mobius;
pub mod nearest_source;
pub mod normals;
pub mod open_surfaces;
mod prefetch;
pub mod redistance;
pub mod rim;
pub mod sampled;
pub mod schedule;
pub mod sweep;
#[cfg(test)]
mod test_bands;

pub use band::NarrowBand;
pub use error::{Error, Result};
pub use hamiltonian::{Hamiltonian, InnerScheme};
pub use sweep::{Control, IterationReport, NodeRole, SolveOptions, SolveStats, SweepProblem};

/// The default "numerical infinity": large enough to dominate any travel time a user will meet
/// in a unit-sized box, small enough that the Lax–Friedrichs update (which averages neighbours)
/// never overflows or produces NaN. See [`SolveOptions::infinity`].
pub const DEFAULT_INFINITY: f64 = 1.0e6;
