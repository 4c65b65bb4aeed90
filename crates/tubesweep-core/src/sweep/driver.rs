//! The entry point of a solve, [`SweepProblem::solve`]: checks the input, picks the numerical
//! infinity (from the longest grid path, [`crate::sweep::grid_hops`]) and the front window's width,
//! builds the thread pool, runs the sweeps ([`crate::sweep::iterate`]), with the outer rim last
//! when asked ([`crate::sweep::rim_last`]), and snaps unreached nodes to the infinity.

use super::kernel::*;
use super::problem::*;
use crate::error::{Error, Result};
use crate::scheme::hamiltonian::InnerScheme;
use std::time::Instant;

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// A numerical infinity that is safe and tight: `2 (H + 2) h s_max + max fixed value`, where
    /// `H` is the largest number of grid steps from a fixed node to any band node it can reach
    /// ([`Self::grid_hops_from_sources`]) and `s_max` the largest slowness. Every value the
    /// Godunov update produces is at most the cost of such a grid path, so real values stay
    /// below it; Lax–Friedrichs, whose update averages neighbours, then spends far fewer
    /// iterations draining the initial "infinity" out of the tube than with a fixed 1e6. For a
    /// general Hamiltonian without a slowness bound the fixed [`crate::DEFAULT_INFINITY`] is used.
    pub fn auto_infinity(&self, fixed_values: &[f64]) -> f64 {
        self.infinity_from_hops(&|| self.grid_hops_from_sources(), fixed_values)
    }

    /// [`Self::auto_infinity`] with the breadth-first search `hops` (called only when needed).
    pub(super) fn infinity_from_hops(&self, hops: &dyn Fn() -> u32, fixed_values: &[f64]) -> f64 {
        let s_max = match (self.scheme, self.slowness) {
            (InnerScheme::General(ham), _) => match ham.slowness_bound() {
                Some(s) => s,
                None => return crate::DEFAULT_INFINITY,
            },
            (InnerScheme::Upwind(solver), _) => match solver.slowness_bound() {
                Some(s) => s,
                None => return crate::DEFAULT_INFINITY,
            },
            (_, Slowness::Constant(s)) => s,
            (_, Slowness::PerNode(s)) => s.iter().cloned().fold(0.0, f64::max),
        };
        let max_fixed = self
            .roles
            .iter()
            .zip(fixed_values)
            .filter(|(&r, _)| r == NodeRole::Fixed)
            .fold(0.0f64, |m, (_, &v)| m.max(v));
        let bound = 2.0 * (hops() as f64 + 2.0) * self.spacing * s_max + max_fixed;
        if bound.is_finite() && bound > 0.0 {
            bound.max(1e-300)
        } else {
            crate::DEFAULT_INFINITY
        }
    }

    /// The largest number of grid steps from a fixed node to any band node it reaches
    /// (breadth-first search over the neighbour table; 0 without fixed nodes).
    pub fn grid_hops_from_sources(&self) -> u32 {
        let sources = self
            .roles
            .iter()
            .enumerate()
            .filter(|(_, &r)| r == NodeRole::Fixed)
            .map(|(i, _)| i);
        super::grid_hops::max_grid_hops(self.band, sources)
    }

    /// Runs the sweeps. `values` holds the fixed nodes' values on entry (other entries are
    /// overwritten with the numerical infinity) and the solution on return. `progress` is called
    /// after every iteration; returning [`Control::Stop`] ends the solve with
    /// [`Error::Interrupted`].
    pub fn solve(
        &self,
        values: &mut Vec<f64>,
        options: &SolveOptions,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
    ) -> Result<SolveStats> {
        self.check(values)?;
        if let Some(v) = options.infinity {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid("infinity", "must be positive and finite"));
            }
        }
        if !(options.tol >= 0.0) {
            return Err(Error::invalid("tol", "must be non-negative"));
        }
        let start = Instant::now();
        // Every parallel step of the solve (the preparation, the sweeps and the rim) runs on a
        // pool of `threads` threads of its own (rayon's default number for 0), never on the
        // caller's: the sweeps hold all the pool's threads at their barriers, which a caller's
        // pool busy with other work (or with another solve) could not give. The progress
        // callback runs on the caller's thread.
        // The default thread count (0) takes only the cores other tasks leave idle: on a busy
        // machine the preparation's parallel steps and the pipelined sweeps wait on descheduled
        // threads (`thread_choice`); the same values for any count.
        let threads = if options.threads == 0 {
            super::thread_choice::threads_for_default()
        } else {
            options.threads
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| Error::invalid("threads", format!("could not start {} threads: {e}", options.threads)))?;
        let pool = &pool;
        // The grid-path search, shared by the infinity and the window's width, is sequential (see
        // `grid_hops`): it runs beside the search for the outer rim when the rim is swept last.
        // (also run for a general Hamiltonian without a slowness bound, whose infinity does not
        // use it: asking for the bound here would be a pass over every node of its own)
        let hops_needed = self.windowed(options) || options.infinity.is_none();
        let weights = if options.defer_outer_rim {
            self.upwind_weights()
        } else {
            std::borrow::Cow::Borrowed(&[][..])
        };
        let weights: &[[f32; D]] = &weights;
        let rim_last = !weights.is_empty();
        let (hop_count, rim) = pool.install(|| {
            rayon::join(
                || hops_needed.then(|| self.grid_hops_from_sources()),
                || {
                    if rim_last {
                        super::rim::outer_rim(self.band, self.roles, weights)
                    } else {
                        Vec::new()
                    }
                },
            )
        });
        let hops = || hop_count.unwrap_or_else(|| self.grid_hops_from_sources());
        let inf = match options.infinity {
            Some(v) => v,
            None => self.infinity_from_hops(&hops, values),
        };
        // the front window's width: `front_window · sqrt(range · h · s̄)` with the range of the
        // values taken as the cost `H h s̄` of the longest grid path (an estimate: per-node
        // slowness and source values of their own spread it further)
        let window_width = if self.windowed(options) {
            let hs = self.spacing * self.mean_slowness();
            options.front_window * hs * (hops() as f64).sqrt()
        } else {
            0.0
        };
        let options = &SolveOptions {
            infinity: Some(inf),
            ..*options
        };
        for (v, &r) in values.iter_mut().zip(self.roles) {
            if r != NodeRole::Fixed {
                *v = inf;
            }
        }
        values.push(inf); // the sentinel slot read for absent neighbours
        let mut stats = SolveStats {
            infinity: inf,
            ..Default::default()
        };
        let result = if options.defer_outer_rim {
            self.iterate_rim_last(values, options, window_width, pool, progress, &mut stats, weights, &rim)
        } else {
            self.iterate(values, options, window_width, pool, progress, &mut stats)
        };
        values.pop();
        if stats.window_edge < f64::INFINITY {
            // Stopped before the front window opened: the values set lie within it, except those
            // of layer nodes that read a node not reached yet (the rim, swept last, and the nodes
            // in upwind 2-cycles), which hold a mixture with the infinity. They are not reached
            // either.
            for (v, &r) in values.iter_mut().zip(self.roles) {
                if r != NodeRole::Fixed && *v > stats.window_edge {
                    *v = inf;
                }
            }
        }
        // Extension-layer nodes of a component no source reaches hold convex combinations of the
        // infinity, which f32 weights can round a hair off it: snap them back, so that every
        // unreached node holds exactly `inf`.
        for v in values.iter_mut() {
            if unreached(*v, inf) {
                *v = inf;
            }
        }
        stats.seconds = start.elapsed().as_secs_f64();
        result.map(|_| stats)
    }
}
