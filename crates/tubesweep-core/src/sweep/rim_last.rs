//! The solve in two phases when the outer rim is swept last
//! ([`SolveOptions::defer_outer_rim`]): the band without its outer rim (held at the infinity, read
//! by nobody), then the rim's values in one pass in dependency order ([`crate::sweep::rim`]).

use super::problem::*;
use crate::error::{Error, Result};
use rayon::prelude::*;

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// [`iterate`](Self::iterate) in two phases: the band without its outer rim (held at the
    /// numerical infinity, read by nobody), then the rim's values in one pass in dependency order
    /// ([`crate::sweep::rim`]). `weights` are [`Self::upwind_weights`], `rim` the
    /// [`crate::sweep::rim::outer_rim`] of them (empty without a layer).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn iterate_rim_last(
        &self,
        u: &mut [f64],
        options: &SolveOptions,
        window_width: f64,
        pool: &rayon::ThreadPool,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
        stats: &mut SolveStats,
        weights: &[[f32; D]],
        rim: &[bool],
    ) -> Result<()> {
        if !rim.iter().any(|&b| b) {
            return self
                .with_roles(self.roles, weights)
                .iterate(u, options, window_width, pool, progress, stats);
        }
        let without_rim: Vec<NodeRole> = pool.install(|| {
            self.roles
                .par_iter()
                .zip(rim.par_iter())
                .map(|(&r, &b)| if b { NodeRole::Fixed } else { r })
                .collect()
        });
        self.with_roles(&without_rim, weights)
            .iterate(u, options, window_width, pool, progress, stats)?;
        drop(without_rim);
        // The rim counts as one iteration, reported after the first phase's; its passes (one,
        // and those over its cyclic part) count as sweeps and share the budget of sweeps left
        // (at least one pass, so that it gets values even when the first phase used it all).
        let base = stats.iterations;
        let budget = options
            .max_iterations
            .saturating_sub(base)
            .max(1)
            .saturating_mul(1 << D);
        let passes = pool.install(|| super::rim::extend_into_rim(self.band, rim, weights, u, options.tol, budget));
        stats.iterations += 1;
        stats.sweeps += passes.passes;
        stats.updates += passes.updates;
        stats.converged &= passes.converged;
        stats.last_change = stats.last_change.max(passes.last_change);
        let report = IterationReport {
            iteration: stats.iterations,
            max_change: passes.first_change,
            updates: passes.updates,
        };
        if progress(&report) == Control::Stop {
            return Err(Error::Interrupted {
                iterations: stats.iterations,
            });
        }
        Ok(())
    }
}
