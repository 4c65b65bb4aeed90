//! The iterations: 2^d Gauss–Seidel sweeps each (paper Sect. 2, Gray-code order), sequential or
//! in parallel (a pipelined wavefront over strips of tiles, [`crate::sweep::strip_pipeline`], the
//! strips' orientation picked per iteration from where the work lies), until the largest change
//! falls below `tol`; the active flags, the rows' lower bounds and the front window's edge are
//! kept here between sweeps.

use super::kernel::*;
use super::problem::*;
use super::strip_pipeline::{run_sweeps_in_one_broadcast, strip_worker};
use super::sweep_state::{order_key, Accumulator, Limits, SharedValues, SweepContext, REFUSED};
use crate::band::schedule::{SweepSchedule, TILE};
use crate::error::{Error, Result};
use crate::scheme::hamiltonian::InnerScheme;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicU8, AtomicUsize, Ordering};

/// How many times more of an iteration's work the fullest slab along one leading axis must hold
/// than the fullest along the other before the parallel sweeps run strips thin across that axis
/// (`SweepProblem::thin_strip_axis`); below it they keep the square tiles.
const THIN_STRIP_RATIO: f64 = 2.0;

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// The sweeps to convergence; `window_width` > 0 runs the front window
    /// ([`SolveOptions::front_window`]) with that width.
    pub(super) fn iterate(
        &self,
        u: &mut [f64],
        options: &SolveOptions,
        window_width: f64,
        pool: &rayon::ThreadPool,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
        stats: &mut SolveStats,
    ) -> Result<()> {
        // Active flags ("locking"): a node is updated only if a neighbour changed since its last
        // update. An update is a function of the neighbour values (and of the node's own value for
        // Lax–Friedrichs next to an absent neighbour, which re-activates itself), so the skipped
        // updates could not have changed anything: the result is bit-identical to the plain sweep.
        // The coupled Godunov update also reads the node's own value; re-evaluated with unchanged
        // neighbours it can only return its value again, up to the last bit of rounding. One extra slot for the sentinel keeps the activation branch-free.
        // Upwind weights of the extension update, once per solve (the band does not change).
        // Outer nodes without an upwind neighbour keep their value: they are never activated.
        let weights = self.upwind_weights();
        let weights: &[[f32; D]] = &weights;
        let n = self.roles.len();
        let values: &[f64] = u;
        let (active, start_low, coupling, first_front) = pool.install(|| {
            let active: Vec<AtomicU8> = (0..=n)
                .into_par_iter()
                .map(|i| {
                    let updated =
                        i < n && self.roles[i] != NodeRole::Fixed && weights.get(i).is_none_or(|w| !w[0].is_nan());
                    AtomicU8::new(updated as u8)
                })
                .collect();
            // per row, the smallest value it holds (the fixed values and the infinity at the start)
            let start_low: Vec<f64> = (0..self.band.n_rows())
                .into_par_iter()
                .map(|r| {
                    let (s, e) = self.band.row_range(r);
                    values[s..e].iter().fold(f64::INFINITY, |m, &v| m.min(v))
                })
                .collect();
            let coupling = self.coupling_mask(weights, options.coupled);
            // the front window starts at the smallest source value (none without a source)
            let first_front = self
                .roles
                .par_iter()
                .zip(values[..n].par_iter())
                .filter(|(&r, _)| r == NodeRole::Fixed)
                .map(|(_, &v)| v)
                .reduce(|| f64::INFINITY, f64::min);
            (active, start_low, coupling, first_front)
        });
        let row_low: Vec<AtomicU64> = start_low
            .iter()
            .chain(std::iter::once(&f64::INFINITY))
            .map(|&v| AtomicU64::new(order_key(v)))
            .collect();
        let row_neighbours = self.band.row_neighbours();
        // the rows next to a row with fixed nodes read them, like the rows a row wakes (see
        // `finish_row`): their bound is at most the smallest value that row starts with
        let per = 2 * (D - 1);
        for (r, &low) in start_low.iter().enumerate() {
            for &q in &row_neighbours[r * per..(r + 1) * per] {
                row_low[q as usize].fetch_min(order_key(low), Ordering::Relaxed);
            }
        }
        // per row: may a node be active (all at the start; the last slot stands for "no row")
        let row_dirty: Vec<AtomicU8> = (0..=self.band.n_rows()).map(|_| AtomicU8::new(1)).collect();
        let shared = SharedValues::new(u);
        let all_active = !options.skip_inactive;
        debug_assert!(
            !(all_active && window_width > 0.0),
            "the front window runs only with the active flags"
        );
        // the plain sweeps update every node that starts active (all but the fixed nodes and the
        // layer nodes without an upwind neighbour) in every sweep, and count them here
        let updated_per_sweep = if all_active {
            active[..n].iter().filter(|a| a.load(Ordering::Relaxed) != 0).count() as u64
        } else {
            0
        };

        // the largest slowness of a general Hamiltonian bounds the extrapolation of absent
        // neighbours (see `fill_missing`); computed once, it may scan every node
        let general_slowness = self.general_slowness();
        // per tile, the last parallel sweep that finished it (see `strip_worker`)
        let threads = pool.current_num_threads();
        let tiles_done: Vec<AtomicU32> = if threads == 1 || D < 3 {
            Vec::new()
        } else {
            let most = [
                self.band.schedule(),
                self.band.strip_schedule(0),
                self.band.strip_schedule(1),
            ]
            .into_iter()
            .flat_map(|sched| (0..1usize << (D - 1)).map(move |o| sched.tiles(o).len()))
            .max()
            .unwrap_or(0);
            (0..most).map(|_| AtomicU32::new(0)).collect()
        };
        let windowed = window_width > 0.0 && window_width.is_finite() && first_front < f64::INFINITY;
        let cyclic = if windowed {
            pool.install(|| self.upwind_two_cycles(weights))
        } else {
            Vec::new()
        };
        let ctx = SweepContext {
            cyclic: &cyclic,
            row_low: &row_low,
            row_dirty: &row_dirty,
            row_neighbours: &row_neighbours,
            windowed,
            skip_inactive: !all_active,
            u: &shared,
            active: &active,
            weights,
            coupling: &coupling,
            general_slowness,
            tiles_done: &tiles_done,
            sweep_id: AtomicU32::new(0),
        };
        let n_orient = 1usize << D;
        let inf = options.infinity.unwrap_or(crate::DEFAULT_INFINITY);
        // only a 3D band has independent tiles (a 2D band's waves hold one tile each); one
        // thread runs the sequential sweep
        let parallel = !ctx.tiles_done.is_empty();
        if parallel && options.spread_threads {
            super::spread_threads::over_cpus(pool);
        }
        // the rows the first iteration visits: every row, or with the window the few near the
        // sources (then the next iterations decide from what the sweeps visited)
        let mut visited_per_sweep = if windowed { 0 } else { n as u64 };
        let mut window = if windowed {
            first_front + window_width
        } else {
            f64::INFINITY
        };
        stats.window_edge = f64::INFINITY;
        // with the default thread count, each iteration in parallel or on this thread, whichever
        // measures faster (a busy machine: `thread_choice`); the same bits either way
        let mut choice = super::thread_choice::ThreadChoice::new(parallel, options.threads == 0, threads);
        while stats.iterations < options.max_iterations {
            let lim = Limits {
                inf,
                threshold: options.activation_threshold,
                window,
                window_key: order_key(window),
                settled: options.tol,
                refused: REFUSED + (stats.iterations % 250) as u8,
                prefetch_ahead: self.row_prefetch_ahead(&ctx, visited_per_sweep, options.row_prefetch_above),
            };
            let mut max_change = 0.0f64;
            let mut front = f64::INFINITY;
            let mut waiting = f64::INFINITY;
            let mut updates = 0u64;
            let mut visited = 0u64;
            let run_parallel = choice.parallel(parallel);
            choice.start(run_parallel);
            if run_parallel {
                // all 2^d sweeps of the iteration in one visit to the pool's threads, with a
                // barrier between sweeps (waking the threads once per sweep costs more than a
                // small sweep's work)
                let (acc, thin) = pool.install(|| {
                    // strips thin across the front of this iteration's work, or square tiles
                    // (decided here, on the pool's threads, which then stay awake for the sweeps)
                    let thin = self.thin_strip_axis(&ctx, lim);
                    let sched = thin.map_or(self.band.schedule(), |axis| self.band.strip_schedule(axis));
                    let per_sweep = |s: usize, next_strip: &AtomicUsize, abandoned: &AtomicBool| {
                        let dir = s ^ (s >> 1); // Gray code
                        self.strip_worker(&ctx, sched, dir, next_strip, abandoned, lim)
                    };
                    (run_sweeps_in_one_broadcast(n_orient, &ctx.sweep_id, &per_sweep), thin)
                });
                if let Some(axis) = thin {
                    stats.thin_strip_iterations[axis] += 1;
                }
                max_change = acc.max_change;
                front = acc.front;
                waiting = acc.waiting;
                updates = acc.updates;
                visited = acc.visited;
                stats.sweeps += n_orient;
            } else {
                for s in 0..n_orient {
                    let dir = s ^ (s >> 1); // Gray code
                    let acc = self.sweep(&ctx, dir, lim);
                    crate::kernel_stats::flush();
                    max_change = max_change.max(acc.max_change);
                    front = front.min(acc.front);
                    waiting = waiting.min(acc.waiting);
                    updates += acc.updates;
                    visited += acc.visited;
                    stats.sweeps += 1;
                }
            }
            if all_active {
                updates = updated_per_sweep * n_orient as u64;
            }
            choice.finish(updates);
            visited_per_sweep = visited / n_orient as u64;
            if lim.prefetch_ahead > 0 {
                stats.prefetch_iterations += 1;
            }
            stats.iterations += 1;
            stats.updates += updates;
            stats.last_change = max_change;
            // the window this iteration ran with (what a solve stopped here leaves behind)
            stats.window_edge = lim.window;
            if progress(&IterationReport {
                iteration: stats.iterations,
                max_change,
                updates,
            }) == Control::Stop
            {
                return Err(Error::Interrupted {
                    iterations: stats.iterations,
                });
            }
            // converged only when no node was left out by the window (then `front` is infinite
            // and the window opens fully for the next iteration)
            if max_change < options.tol && window == f64::INFINITY {
                stats.converged = true;
                break;
            }
            if window < f64::INFINITY {
                window = if waiting == f64::INFINITY {
                    // no node waits beyond the window: the rest of the solve runs over the whole band
                    f64::INFINITY
                } else if front < f64::INFINITY {
                    window.max(front + window_width)
                } else {
                    // nothing in the window moved: everything up to its edge has settled, and the
                    // window moves on to the nearest node still waiting beyond it
                    (window + window_width).max(waiting + window_width)
                };
            }
        }
        Ok(())
    }

    /// The leading axis (0 or 1) across which the parallel sweeps' strips should be thin in the
    /// coming iteration, or `None` for square tiles. The work is predicted from the rows that
    /// will run (dirty, with a lower bound inside the window), each weighted by its nodes and
    /// binned in slabs of [`TILE`] rows along each axis. When the fullest slab along one axis
    /// holds more than [`THIN_STRIP_RATIO`] times the work of the fullest along the other, a
    /// front crosses that axis (a ring about a source on it), and strips thin across it spread
    /// the front's rows over more strips, which the threads run side by side; with square tiles
    /// they would fall in one or two strips. Otherwise (a front across the rows' own axis, or
    /// none in particular) the square tiles' fewer waits pay more. Any choice gives the values
    /// of the sequential sweep; this one only decides how well the threads share the work.
    pub(super) fn thin_strip_axis(&self, ctx: &SweepContext<'_, D>, lim: Limits) -> Option<usize> {
        let shape = self.band.shape();
        let empty = || [vec![0u64; shape[0] / TILE + 1], vec![0u64; shape[1] / TILE + 1]];
        let slabs = (0..self.band.n_rows())
            .into_par_iter()
            .with_min_len(1024)
            .fold(empty, |mut slabs, r| {
                if ctx.row_may_run::<true>(r, lim) {
                    let (s, e) = self.band.row_range(r);
                    let ab = self.band.row_leading_indices(r);
                    for k in 0..2 {
                        slabs[k][ab[k] / TILE] += (e - s) as u64;
                    }
                }
                slabs
            })
            .reduce(empty, |mut a, b| {
                for k in 0..2 {
                    a[k].iter_mut().zip(&b[k]).for_each(|(x, y)| *x += y);
                }
                a
            });
        let fullest = |k: usize| slabs[k].iter().copied().max().unwrap_or(0);
        let (f0, f1) = (fullest(0) as f64, fullest(1) as f64);
        if f0 > THIN_STRIP_RATIO * f1 {
            Some(0)
        } else if f1 > THIN_STRIP_RATIO * f0 {
            Some(1)
        } else {
            None
        }
    }

    /// One sequential Gauss–Seidel sweep in orientation `dir` (bit `k` set = axis `k` walked
    /// backwards): the waves in order, the tiles of a wave one after the other, the rows of a
    /// tile in order. (In parallel, the threads run [`Self::strip_worker`].)
    pub(super) fn sweep(&self, ctx: &SweepContext<'_, D>, dir: usize, lim: Limits) -> Accumulator {
        let lead = dir & ((1usize << (D - 1)) - 1);
        let backwards = dir >> (D - 1) & 1 == 1;
        let rows = self.band.schedule().rows(lead);
        // Sequentially, the rows in the schedule's order (the waves in order, the tiles of a wave
        // one after the other): the order the parallel sweep's values are those of. (Interleaving
        // two tiles of a wave node by node, two independent Gauss–Seidel chains, was slower with
        // the active flags and no faster without them: docs/architecture.md.)
        specialised!(self, ctx, run_rows(ctx, rows, backwards, lim))
    }

    /// This thread's share of the parallel sweep in orientation `dir`, a pipelined wavefront over
    /// strips of tiles (see [`crate::band::schedule`]): it takes the next strip (`next_strip`) and runs
    /// its tiles in order, each once the tile of the previous strip it depends on is done in this
    /// sweep (id `ctx.sweep_id`). The values are those of the sequential sweep.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn strip_worker(
        &self,
        ctx: &SweepContext<'_, D>,
        sched: &SweepSchedule,
        dir: usize,
        next_strip: &AtomicUsize,
        abandoned: &AtomicBool,
        lim: Limits,
    ) -> Accumulator {
        let lead = dir & ((1usize << (D - 1)) - 1);
        let backwards = dir >> (D - 1) & 1 == 1;
        let (rows, tiles) = (sched.rows(lead), sched.tiles(lead));
        let run_tile = |t: usize| -> Accumulator {
            let a = &rows[tiles[t] as usize..tiles[t + 1] as usize];
            specialised!(self, ctx, run_rows(ctx, a, backwards, lim))
        };
        let id = ctx.sweep_id.load(Ordering::Relaxed);
        strip_worker(
            sched.strip_tiles(lead),
            sched.strips(lead),
            sched.upstream(lead),
            ctx.tiles_done,
            id,
            next_strip,
            abandoned,
            &run_tile,
        )
    }
}
