//! Counters of what the sweeps did, for profiling the kernel: where the parallel sweeps wait,
//! how many rows and nodes they look at, and how far each local update moves a value. Compiled
//! in only with the `kernel-stats` feature; without it every recording function is empty and
//! inlined away, so the solver pays nothing.
//!
//! ```text
//! cargo run --release -p tubesweep-core --features kernel-stats --example sphere -- 201 godunov 2
//! ```
//!
//! They count the sweeps only: the one pass that sets the outer rim's values at the end
//! ([`crate::sweep::rim`], with `SolveOptions::defer_outer_rim`) is not in them, so the histogram's
//! total is `SolveStats::updates` less the rim's updates.
//!
//! Each thread counts on its own and adds its counts to process-wide totals after every sweep
//! ([`flush`]); [`snapshot`] reads the totals, [`reset`] clears them. They count every solve in
//! the process. On request ([`log_rows`]) the rows each sweep ran are also logged one by one,
//! with their visits and updates ([`take_row_log`]): the work the load-balance model of
//! `examples/schedule_balance.rs --windowed` puts through the parallel schedule.
//!
//! Counting costs time (a thread-local access per node visited), so with the feature the sweeps
//! run slower than without it, and the waits measured include that.

#[cfg(feature = "kernel-stats")]
use std::sync::atomic::{AtomicU64, Ordering};

/// Bins of [`KernelStats::change_histogram`]: 0 the updates that left the value as it was, 1 the
/// changes of at least 1, then bin `2 + j` the changes in `[10^-(j+1), 10^-j)`, the last bin
/// everything smaller.
pub const CHANGE_BINS: usize = 20;

/// A copy of the counters.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct KernelStats {
    /// Waits of a parallel sweep's strip for the tile of the previous strip it depends on (only
    /// those that found it not done yet).
    pub tile_waits: u64,
    /// The time of those waits in nanoseconds, summed over the threads.
    pub tile_wait_ns: u64,
    /// Time the threads spent at the barriers between sweeps, in nanoseconds, summed over the
    /// threads.
    pub barrier_wait_ns: u64,
    /// Rows the sweeps reached.
    pub rows_seen: u64,
    /// Rows the sweeps ran (dirty and not beyond the front window).
    pub rows_run: u64,
    /// Nodes of the rows run (each visited, whether updated or not).
    pub node_visits: u64,
    /// Per role (index 1 inner, 2 extension layer), the local updates by how far they moved the
    /// value, or would have where the front window refused the new value (see [`CHANGE_BINS`]).
    pub change_histogram: [[u64; CHANGE_BINS]; 3],
}

#[cfg(feature = "kernel-stats")]
mod counters {
    use super::*;
    use std::cell::Cell;

    /// The process-wide totals, which [`flush`](super::flush) adds each thread's own counts to.
    pub static TOTALS: [AtomicU64; 6 + 3 * CHANGE_BINS] = [const { AtomicU64::new(0) }; 6 + 3 * CHANGE_BINS];
    pub const TILE_WAITS: usize = 0;
    pub const TILE_WAIT_NS: usize = 1;
    pub const BARRIER_WAIT_NS: usize = 2;
    pub const ROWS_SEEN: usize = 3;
    pub const ROWS_RUN: usize = 4;
    pub const NODE_VISITS: usize = 5;
    pub const CHANGES: usize = 6;

    thread_local! {
        /// This thread's counts since its last flush (kept per thread, so that counting does not
        /// make the threads contend for the totals' cache lines).
        pub static LOCAL: [Cell<u64>; 6 + 3 * CHANGE_BINS] = const { [const { Cell::new(0) }; 6 + 3 * CHANGE_BINS] };
    }

    #[inline(always)]
    pub fn add(slot: usize, v: u64) {
        LOCAL.with(|l| l[slot].set(l[slot].get() + v));
    }
}

/// Whether the counters are compiled in (the `kernel-stats` feature).
pub const ENABLED: bool = cfg!(feature = "kernel-stats");

/// The bin of a change (see [`CHANGE_BINS`]).
pub fn change_bin(change: Option<f64>) -> usize {
    match change {
        None => 0,
        Some(c) if !(c > 0.0) => 0,
        Some(c) if c >= 1.0 => 1,
        // the first decade [10^-(j+1), 10^-j) that holds c (compared, not a logarithm: this runs
        // once per local update)
        Some(c) => 2 + DECADES.iter().position(|&t| c >= t).unwrap_or(CHANGE_BINS - 3),
    }
}

/// The lower ends of the decade bins: 1e-1, 1e-2, …, 1e-17 (the last bin takes the rest).
const DECADES: [f64; CHANGE_BINS - 3] = [
    1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15, 1e-16, 1e-17,
];

/// A strip waited `ns` nanoseconds for its upstream tile.
#[inline(always)]
pub fn tile_wait(ns: u64) {
    #[cfg(feature = "kernel-stats")]
    {
        counters::add(counters::TILE_WAITS, 1);
        counters::add(counters::TILE_WAIT_NS, ns);
    }
    #[cfg(not(feature = "kernel-stats"))]
    let _ = ns;
}

/// A thread waited `ns` nanoseconds at a barrier between sweeps.
#[inline(always)]
pub fn barrier_wait(ns: u64) {
    #[cfg(feature = "kernel-stats")]
    counters::add(counters::BARRIER_WAIT_NS, ns);
    #[cfg(not(feature = "kernel-stats"))]
    let _ = ns;
}

/// A sweep reached row `r`; `run`: it ran its `nodes` nodes and made `updates` local updates
/// there. `updates` is 0 in the sweeps without the active flags (`skip_inactive: false`, the
/// `sphere` example's `PLAIN=1`), which count their updates per sweep instead.
#[inline(always)]
pub fn row(r: usize, run: bool, nodes: usize, updates: u64) {
    #[cfg(feature = "kernel-stats")]
    {
        counters::add(counters::ROWS_SEEN, 1);
        if run {
            counters::add(counters::ROWS_RUN, 1);
            counters::add(counters::NODE_VISITS, nodes as u64);
            if row_log::ON.load(Ordering::Relaxed) {
                row_log::LOCAL.with(|l| {
                    l.borrow_mut().push(RowWork {
                        row: r as u32,
                        nodes: nodes as u32,
                        updates: updates as u32,
                    })
                });
            }
        }
    }
    #[cfg(not(feature = "kernel-stats"))]
    let _ = (r, run, nodes, updates);
}

/// A row a sweep ran, in the row log ([`log_rows`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowWork {
    /// The row (`NarrowBand::row_range`).
    pub row: u32,
    /// Its nodes, each visited.
    pub nodes: u32,
    /// The local updates made in it (0 in the sweeps without the active flags: see [`row`]).
    pub updates: u32,
}

#[cfg(feature = "kernel-stats")]
mod row_log {
    use super::RowWork;
    use std::cell::RefCell;
    use std::sync::atomic::AtomicBool;
    use std::sync::Mutex;

    /// Whether the rows run are logged.
    pub static ON: AtomicBool = AtomicBool::new(false);
    /// The flushed entries: each thread's rows of one sweep.
    pub static ENTRIES: Mutex<Vec<Vec<RowWork>>> = Mutex::new(Vec::new());

    thread_local! {
        /// This thread's rows since its last flush.
        pub static LOCAL: RefCell<Vec<RowWork>> = const { RefCell::new(Vec::new()) };
    }
}

/// Starts (`true`) or stops logging every row the sweeps run, with its nodes and updates, and
/// clears the log. For a work model of the sweeps (`examples/schedule_balance.rs`); the log
/// grows by 12 bytes per row run.
pub fn log_rows(on: bool) {
    #[cfg(feature = "kernel-stats")]
    {
        row_log::ON.store(on, Ordering::Relaxed);
        row_log::ENTRIES.lock().unwrap_or_else(|e| e.into_inner()).clear();
    }
    #[cfg(not(feature = "kernel-stats"))]
    let _ = on;
}

/// Takes the row log gathered since [`log_rows`] or the last call: an entry per [`flush`], that
/// is one per sweep when the sweeps run sequentially (one thread, or a 2D band) and one per
/// thread and sweep when they run in parallel, the threads' entries of a sweep together (each
/// thread flushes after the barrier that ends the sweep, before any starts the next) and the
/// sweeps in order. Empty without the feature.
pub fn take_row_log() -> Vec<Vec<RowWork>> {
    #[cfg(feature = "kernel-stats")]
    {
        std::mem::take(&mut *row_log::ENTRIES.lock().unwrap_or_else(|e| e.into_inner()))
    }
    #[cfg(not(feature = "kernel-stats"))]
    Vec::new()
}

/// A local update at a node of role `role` (1 inner, 2 layer) moved its value by `change`
/// (`None`: not at all).
#[inline(always)]
pub fn update(role: u8, change: Option<f64>) {
    #[cfg(feature = "kernel-stats")]
    counters::add(
        counters::CHANGES + (role as usize).min(2) * CHANGE_BINS + change_bin(change),
        1,
    );
    #[cfg(not(feature = "kernel-stats"))]
    let _ = (role, change);
}

/// Adds this thread's counts to the process-wide totals (the sweeps call it on every thread
/// after every sweep).
#[inline(always)]
pub fn flush() {
    #[cfg(feature = "kernel-stats")]
    {
        counters::LOCAL.with(|l| {
            for (total, v) in counters::TOTALS.iter().zip(l.iter()) {
                let v = v.take();
                if v != 0 {
                    total.fetch_add(v, Ordering::Relaxed);
                }
            }
        });
        // drained on every flush, so that rows logged just before the log was switched off do
        // not turn up in a later log
        let rows = row_log::LOCAL.with(|l| std::mem::take(&mut *l.borrow_mut()));
        if row_log::ON.load(Ordering::Relaxed) {
            row_log::ENTRIES.lock().unwrap_or_else(|e| e.into_inner()).push(rows);
        }
    }
}

/// The totals now (all zero without the feature).
pub fn snapshot() -> KernelStats {
    #[allow(unused_mut)]
    let mut s = KernelStats::default();
    #[cfg(feature = "kernel-stats")]
    {
        use counters::*;
        let t = |i: usize| TOTALS[i].load(Ordering::Relaxed);
        s.tile_waits = t(TILE_WAITS);
        s.tile_wait_ns = t(TILE_WAIT_NS);
        s.barrier_wait_ns = t(BARRIER_WAIT_NS);
        s.rows_seen = t(ROWS_SEEN);
        s.rows_run = t(ROWS_RUN);
        s.node_visits = t(NODE_VISITS);
        for r in 0..3 {
            for b in 0..CHANGE_BINS {
                s.change_histogram[r][b] = t(CHANGES + r * CHANGE_BINS + b);
            }
        }
    }
    s
}

/// Clears the totals.
pub fn reset() {
    #[cfg(feature = "kernel-stats")]
    for c in counters::TOTALS.iter() {
        c.store(0, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With the feature: the counters of a solve on the sphere, and its row log, agree with its
    /// statistics, and neither depends on the thread count (the sweeps are bit-identical). The
    /// totals are process-wide, so no other solve may run in the process meanwhile: run it on
    /// its own, as `make test` does (`cargo test -p tubesweep-core --features kernel-stats kernel_stats::`);
    /// in a run of every test with the feature, other tests' solves would add to its counts.
    #[cfg(feature = "kernel-stats")]
    #[test]
    fn the_counters_agree_with_the_solve_and_not_with_the_thread_count() {
        use crate::sweep::SolveOptions;
        use crate::test_bands::{sphere_band, sphere_problem};
        use crate::{Control, InnerScheme};
        let (band, roles, dirs, h) = sphere_band(61);
        let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
        let mut runs = Vec::new();
        // per sweep, the rows run with their work, in row order
        let mut logs: Vec<Vec<Vec<RowWork>>> = Vec::new();
        for threads in [1, 2] {
            reset();
            log_rows(true);
            let mut u = vec![0.0; band.len()];
            // the rim in the sweeps, so that every update is a sweep's
            let opts = SolveOptions {
                threads,
                defer_outer_rim: false,
                ..Default::default()
            };
            let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
            let s = snapshot();
            let log = take_row_log();
            log_rows(false);
            // an entry per thread and sweep, and together the rows run with their visits and
            // updates
            assert_eq!(log.len(), threads * st.sweeps);
            assert_eq!(log.iter().map(|e| e.len() as u64).sum::<u64>(), s.rows_run);
            assert_eq!(log.iter().flatten().map(|w| w.nodes as u64).sum::<u64>(), s.node_visits);
            assert_eq!(log.iter().flatten().map(|w| w.updates as u64).sum::<u64>(), st.updates);
            logs.push(
                log.chunks(threads)
                    .map(|sweep| {
                        let mut rows: Vec<RowWork> = sweep.concat();
                        rows.sort_unstable_by_key(|w| w.row);
                        rows
                    })
                    .collect(),
            );
            let histogram: u64 = s.change_histogram.iter().flatten().sum();
            assert_eq!(histogram, st.updates, "every local update is binned once");
            assert_eq!(s.change_histogram[0].iter().sum::<u64>(), 0, "no fixed node is updated");
            assert!(
                s.node_visits >= st.updates && s.rows_run <= s.rows_seen && s.rows_run > 0,
                "{s:?}"
            );
            // every row is reached in every sweep
            assert_eq!(s.rows_seen, (band.n_rows() * st.sweeps) as u64);
            // the first updates take nodes from the numerical infinity: changes of at least 1
            assert!(s.change_histogram[1][1] > 0 && s.change_histogram[2][1] > 0);
            if threads == 1 {
                assert_eq!((s.tile_waits, s.barrier_wait_ns), (0, 0));
            }
            runs.push(KernelStats {
                tile_waits: 0,
                tile_wait_ns: 0,
                barrier_wait_ns: 0,
                ..s
            });
        }
        assert_eq!(runs[0], runs[1]);
        // the threads' entries of a sweep together hold the rows the one thread ran, with the
        // same work
        assert_eq!(logs[0], logs[1]);
    }

    #[test]
    fn changes_fall_in_decade_bins() {
        assert_eq!(change_bin(None), 0);
        assert_eq!(change_bin(Some(0.0)), 0);
        assert_eq!(change_bin(Some(3.0)), 1);
        assert_eq!(change_bin(Some(0.5)), 2);
        assert_eq!(change_bin(Some(0.1)), 2);
        assert_eq!(change_bin(Some(0.0999)), 3);
        assert_eq!(change_bin(Some(0.05)), 3);
        assert_eq!(change_bin(Some(2e-11)), 2 + 10);
        assert_eq!(change_bin(Some(1e-300)), CHANGE_BINS - 1);
    }
}
