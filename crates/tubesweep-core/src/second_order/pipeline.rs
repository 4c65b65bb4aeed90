//! The second-order sweeps on several threads: the first-order driver's pipelined wavefront over
//! strips of tiles ([`crate::band::schedule`], [`crate::sweep::strip_pipeline`]), with the
//! values of the sequential sweep for any thread count.
//!
//! The schedule's argument holds for the second-order stencils too: a node reads (and wakes)
//! only nodes along its own axis lines, at distance 1 and 2, and along an axis line every
//! schedule visits the nodes in the sweep's direction, so each node reads the same values as in
//! the sequential sweep; tiles that run at the same time are never on a common axis line of
//! rows. With the default thread count each iteration runs in parallel or on the calling thread,
//! whichever measures faster ([`crate::sweep::thread_choice`]); the bits are the same either way.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::strip_pipeline::{run_sweeps_in_one_broadcast, strip_worker};
use crate::sweep::sweep_state::Accumulator;
use crate::sweep::thread_choice::{threads_for_default, ThreadChoice};

/// Visits the nodes of `rows` (band rows, in this order; each walked backwards when asked) and
/// returns the totals.
pub(super) type RunRows<'f> = dyn Fn(&[u32], bool) -> Accumulator + Sync + 'f;

/// The thread pool and the tiles' done marks of one solve.
pub(super) struct Pipeline {
    /// Built only when the sweeps can run on several threads (a 3D band, more than one thread):
    /// on one thread or in 2D every iteration runs on the calling thread, and a pool there was a
    /// thread started and stopped per solve for nothing.
    pool: Option<rayon::ThreadPool>,
    tiles_done: Vec<AtomicU32>,
    sweep_id: AtomicU32,
    choice: ThreadChoice,
    parallel: bool,
    adaptive: bool,
    threads: usize,
}

impl Pipeline {
    /// `threads`: 0 for the default (the idle cores, then per iteration by measurement).
    pub(super) fn new<const D: usize>(band: &NarrowBand<D>, threads: usize) -> Result<Self> {
        let count = if threads == 0 { threads_for_default() } else { threads };
        // only a 3D band has strips of tiles that can run side by side
        let pool = if D == 3 && count > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(count)
                    .build()
                    .map_err(|e| Error::invalid("threads", format!("could not start {count} threads: {e}")))?,
            )
        } else {
            None
        };
        let count = pool.as_ref().map_or(count, |p| p.current_num_threads());
        let parallel = pool.is_some() && count > 1;
        let tiles_done = if parallel {
            let sched = band.schedule();
            let most = (0..1usize << (D - 1)).map(|o| sched.tiles(o).len()).max().unwrap_or(0);
            (0..most).map(|_| AtomicU32::new(0)).collect()
        } else {
            Vec::new()
        };
        Ok(Pipeline {
            pool,
            tiles_done,
            sweep_id: AtomicU32::new(0),
            choice: ThreadChoice::new(parallel, threads == 0, count),
            parallel,
            adaptive: threads == 0,
            threads: count,
        })
    }

    /// Forgets the timings of the last phase (an update of the other phase costs differently).
    pub(super) fn new_phase(&mut self) {
        self.choice = ThreadChoice::new(self.parallel, self.adaptive, self.threads);
    }

    /// One iteration: the 2^D sweeps in Gray-code order of the orientations (bit `D − 1`: the
    /// rows walked backwards, the others: the leading axes), each visiting every row once.
    pub(super) fn iteration<const D: usize>(&mut self, band: &NarrowBand<D>, run_rows: &RunRows<'_>) -> Accumulator {
        let orientations = 1usize << D;
        let lead_mask = (1usize << (D - 1)) - 1;
        let sched = band.schedule();
        let run_parallel = self.choice.parallel(self.parallel);
        self.choice.start(run_parallel);
        let acc = if let (true, Some(pool)) = (run_parallel, &self.pool) {
            let (tiles_done, ids) = (&self.tiles_done[..], &self.sweep_id);
            let per_sweep = |s: usize, next_strip: &AtomicUsize, abandoned: &AtomicBool| {
                let orient = s ^ (s >> 1);
                let lead = orient & lead_mask;
                let backwards = (orient >> (D - 1)) & 1 == 1;
                let (rows, tiles) = (sched.rows(lead), sched.tiles(lead));
                let run_tile = |t: usize| run_rows(&rows[tiles[t] as usize..tiles[t + 1] as usize], backwards);
                strip_worker(
                    sched.strip_tiles(lead),
                    sched.strips(lead),
                    sched.upstream(lead),
                    tiles_done,
                    ids.load(Ordering::Relaxed),
                    next_strip,
                    abandoned,
                    &run_tile,
                )
            };
            pool.install(|| run_sweeps_in_one_broadcast(orientations, ids, &per_sweep))
        } else {
            (0..orientations).fold(Accumulator::default(), |acc, s| {
                let orient = s ^ (s >> 1);
                let backwards = (orient >> (D - 1)) & 1 == 1;
                acc.merge(run_rows(band.row_order(orient & lead_mask), backwards))
            })
        };
        self.choice.finish(acc.updates);
        acc
    }
}
