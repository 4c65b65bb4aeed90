//! The Gauss–Seidel sweeping driver: Algorithm 1 (the Euclidean fast sweeping method),
//! Algorithm 2 (the naive single tube) and Algorithm 3 (the two-layer tube) of the paper are all
//! this one loop over a [`NarrowBand`], differing only in the role of each node:
//!
//! * [`NodeRole::Fixed`]: a source value, never updated;
//! * [`NodeRole::Inner`]: the eikonal (or general HJ) local solver — Eq. (3), (4) or Sect. 5.1;
//! * [`NodeRole::Outer`]: the extension update, Eq. (5) applied to Eq. (8).
//!
//! One *iteration* is one pass of all 2^d sweep orders (Gray-code order, so consecutive sweeps
//! differ in one axis). The solver stops when the largest change of any node value during an
//! iteration is below `tol`. Values start at a finite numerical infinity; inner-tube values are
//! only ever replaced by smaller ones (this is automatic for Godunov and is the paper's explicit
//! acceptance rule for Lax–Friedrichs, proof of Corollary 1).
//!
//! Where each piece lives:
//!
//! | file | what |
//! |---|---|
//! | `problem.rs` | [`SweepProblem`], [`NodeRole`], [`SolveOptions`], [`SolveStats`] |
//! | `driver.rs` | [`SweepProblem::solve`]: the numerical infinity, the pool, the phases |
//! | `iterate.rs` | the iterations and the 2^d sweeps, sequential or parallel |
//! | `kernel.rs` | a row of a sweep: the local updates, the active flags |
//! | `coupling.rs` | the coupled Godunov step (inner node + the layer nodes that read it) |
//! | `front_window.rs` | the front window (which values a sweep may accept yet) |
//! | `rim.rs`, `rim_last.rs` | the outer rim, extended into last in one pass |
//! | `grid_hops.rs` | the longest grid path: the numerical infinity and the window's width |
//! | `many_sources.rs` | many independent solves on one band, sources spread over threads |
//! | `factored_box.rs` | the second-order factored eikonal in the whole box (`travel_time(order=2)`) |
//! | `strip_pipeline.rs`, `sweep_state.rs`, `row_prefetch.rs`, `spread_threads.rs`, `cache_size.rs`, `thread_choice.rs` | the parallel machinery |
//!
//! Algorithms 1, 2 and 3 are the same sweeps over different bands and roles: the whole box with
//! every node inner (Algorithm 1, `tubesweep.travel_time`), one tube of inner nodes (Algorithm 2,
//! `method="naive"`), the inner tube and the extension layer (Algorithm 3, the default); the roles
//! are set by the caller (`tubesweep._roles.tube_roles`).

/// Calls `$this.$method::<S, P, W, K>($args)` with the row loop specialised for the problem:
/// the scheme `S` (the built-in upwind solvers each their own, [`crate::scheme::upwind::Builtin`]), a per-node slowness `P`, the front window `W` and the active flags `K`
/// (see [`SweepContext::skip_inactive`]), so that nothing is dispatched inside the hot loop. The
/// window runs only with the flags (see `SweepProblem::windowed`).
macro_rules! specialised {
    ($this:expr, $ctx:expr, $method:ident ( $($arg:expr),* )) => {{
        let per_node = matches!($this.slowness, Slowness::PerNode(_));
        match ($this.scheme, per_node, $ctx.windowed, $ctx.skip_inactive) {
            (InnerScheme::Godunov, false, false, true) => $this.$method::<GODUNOV, false, false, true>($($arg),*),
            (InnerScheme::Godunov, true, false, true) => $this.$method::<GODUNOV, true, false, true>($($arg),*),
            (InnerScheme::Godunov, false, true, _) => $this.$method::<GODUNOV, false, true, true>($($arg),*),
            (InnerScheme::Godunov, true, true, _) => $this.$method::<GODUNOV, true, true, true>($($arg),*),
            (InnerScheme::Godunov, false, false, false) => $this.$method::<GODUNOV, false, false, false>($($arg),*),
            (InnerScheme::Godunov, true, false, false) => $this.$method::<GODUNOV, true, false, false>($($arg),*),
            (InnerScheme::LaxFriedrichs, false, _, true) => $this.$method::<LXF, false, false, true>($($arg),*),
            (InnerScheme::LaxFriedrichs, true, _, true) => $this.$method::<LXF, true, false, true>($($arg),*),
            (InnerScheme::LaxFriedrichs, false, _, false) => $this.$method::<LXF, false, false, false>($($arg),*),
            (InnerScheme::LaxFriedrichs, true, _, false) => $this.$method::<LXF, true, false, false>($($arg),*),
            (InnerScheme::General(_), _, _, true) => $this.$method::<GENERAL, false, false, true>($($arg),*),
            (InnerScheme::General(_), _, _, false) => $this.$method::<GENERAL, false, false, false>($($arg),*),
            // the built-in upwind solvers inlined into the row loop, any other through its trait object
            (InnerScheme::Upwind(u), _, _, true) => match u.builtin() {
                $crate::scheme::upwind::Builtin::MovingMedium(_) => $this.$method::<UPWIND_MOVING_MEDIUM, false, false, true>($($arg),*),
                $crate::scheme::upwind::Builtin::Metric(_) => $this.$method::<UPWIND_METRIC, false, false, true>($($arg),*),
                $crate::scheme::upwind::Builtin::Other => $this.$method::<UPWIND, false, false, true>($($arg),*),
            },
            (InnerScheme::Upwind(u), _, _, false) => match u.builtin() {
                $crate::scheme::upwind::Builtin::MovingMedium(_) => $this.$method::<UPWIND_MOVING_MEDIUM, false, false, false>($($arg),*),
                $crate::scheme::upwind::Builtin::Metric(_) => $this.$method::<UPWIND_METRIC, false, false, false>($($arg),*),
                $crate::scheme::upwind::Builtin::Other => $this.$method::<UPWIND, false, false, false>($($arg),*),
            },
        }
    }};
}

pub mod cache_size;
mod coupling;
mod driver;
pub mod factored_box;
mod front_window;
pub mod grid_hops;
mod iterate;
mod kernel;
pub mod many_sources;
mod problem;
pub mod rim;
mod rim_last;
mod row_prefetch;
mod spread_threads;
pub(crate) mod strip_pipeline;
pub(crate) mod sweep_state;
#[cfg(test)]
mod tests;
pub(crate) mod thread_choice;

pub use front_window::DEFAULT_FRONT_WINDOW;
pub use problem::{
    extension_weights_in_place, Control, Extension, IterationReport, MissingNeighbour, NodeRole, Slowness,
    SolveOptions, SolveStats, SweepProblem,
};
pub use row_prefetch::{default_row_prefetch_above, DEFAULT_CACHE_SHARE};
