//! Prefetching a sweep's rows ahead of it, when the data the sweeps read do not fit in the cache.
//!
//! The sweeps visit the rows in tiles of 8 × 8 rows ([`crate::band::schedule`]): eight rows that are
//! neighbours along the second leading axis lie next to each other in memory, but the next eight
//! lie a plane of the band away. Every array the kernel reads at a node (its value, role,
//! neighbour table, upwind weights, flags) is thus read in runs of a few cache lines, too short
//! for the processor's own prefetcher to pick up. While the rows an iteration visits fit in the
//! last-level cache this does not matter; beyond it each run starts with misses. So the sweeps
//! ask for the lines of the row [`ROW_PREFETCH_AHEAD`] places ahead in the rows they are given
//! (the whole sweep on one thread, a tile on several: a tile's first rows are not fetched), but
//! only in an iteration that follows one whose visited rows held more than
//! [`SolveOptions::row_prefetch_above`] bytes of those arrays (the default is
//! [`DEFAULT_CACHE_SHARE`] of the last-level cache, [`crate::sweep::cache_size`]). Below that the hints
//! only cost instructions; docs/development/performance-history.md ("Rows fetched ahead") has the measurements.
//!
//! A row is fetched only if it looks as if it will run when the hint is issued: its dirty flag
//! set (with the active flags) and its lower bound inside the front window. A row that the rows
//! just before it wake is then missed; fetching the clean rows too (two rows ahead) made the default
//! sweeps at N = 1001 on two threads 1.47× slower (6 alternating rounds) and Python's paper sweeps at
//! N = 401 no faster (1.009×). The built-in upwind solvers' own per-node data (the metric, the
//! flow, a per-node slowness) are counted and fetched with the rest
//! ([`crate::LocalSolver::bytes_per_node`], [`crate::LocalSolver::prefetch_nodes`]; other solvers,
//! `Isotropic` through the upwind interface among them, report none); a Lax–Friedrichs general
//! Hamiltonian's are neither.
//! On other architectures than x86-64 the sweeps never prefetch.
//!
//! [`SolveOptions::row_prefetch_above`]: super::SolveOptions::row_prefetch_above

use super::problem::{Slowness, SweepProblem};
use super::sweep_state::{Limits, SweepContext};
use crate::prefetch::prefetch_range;
use crate::scheme::hamiltonian::InnerScheme;
use crate::sweep::cache_size::last_level_cache_bytes;

/// How many rows ahead in the visiting order the sweeps prefetch. Against 2, with the `sphere`
/// example's paper sweeps alternately (docs/development/performance-history.md, "Rows fetched ahead"): 8 took 0.924
/// of the time at N = 401 on one thread, 0.939 on two and 0.893 at N = 301; 12 and 16 gained
/// 1–4% more than 8 on one thread, and 16 lost 5% on two (a tile's first rows go unfetched).
pub(super) const ROW_PREFETCH_AHEAD: usize = 8;

/// How many times its bytes an upwind solver's sweep counts against the threshold: it fetches
/// ahead from half the bytes Eq. (3)'s does. Its update (25 ns against 8) is one long chain of
/// dependent operations, so the processor overlaps less of a miss with the loads of the next
/// nodes. Measured with `upwind_sweep` (one thread, fastest of 5–7 rounds, three runs; the
/// metric and the moving medium's bytes counted, the arrays about 94 bytes a node):
/// - with the default threshold Eq. (3) gains from fetching only from N = 161 (7.4 MB),
///   and loses 5–11% at N = 101–141;
/// - the upwind solvers lose 5–8% at N = 41–81 (up to 3.8 MB);
/// - they gain 17–23% at N = 101 (5.9 MB) and 25–30% at N = 161.
pub(super) const UPWIND_PREFETCH_WEIGHT: u64 = 2;

/// The share of the last-level cache above which the sweeps prefetch (see the module doc).
pub const DEFAULT_CACHE_SHARE: f64 = 0.25;

/// The default [`SolveOptions::row_prefetch_above`](super::SolveOptions::row_prefetch_above):
/// [`DEFAULT_CACHE_SHARE`] of [`last_level_cache_bytes`].
pub fn default_row_prefetch_above() -> usize {
    (last_level_cache_bytes() as f64 * DEFAULT_CACHE_SHARE) as usize
}

impl<const D: usize> SweepProblem<'_, D> {
    /// The bytes the kernel reads at a visited node, over the arrays [`Self::prefetch_row`]
    /// fetches: value, role, neighbour table (two `u32` per leading axis and a byte), upwind
    /// weights, and where the solve has them the active flag, the coupling mask and a per-node
    /// slowness.
    pub(super) fn swept_bytes_per_node(&self, ctx: &SweepContext<'_, D>) -> usize {
        use std::mem::size_of;
        let mut bytes =
            size_of::<f64>() + size_of::<super::problem::NodeRole>() + self.band.neighbour_table_bytes_per_node();
        if !ctx.weights.is_empty() {
            bytes += size_of::<[f32; D]>();
        }
        if ctx.skip_inactive {
            bytes += size_of::<std::sync::atomic::AtomicU8>();
        }
        if !ctx.coupling.is_empty() {
            bytes += size_of::<u8>();
        }
        if let Slowness::PerNode(_) = self.slowness {
            bytes += size_of::<f64>();
        }
        if let InnerScheme::Upwind(solver) = self.scheme {
            bytes += solver.bytes_per_node();
        }
        bytes
    }

    /// Whether the iteration after one that visited rows holding `visited_per_sweep` nodes per
    /// sweep prefetches its rows: [`ROW_PREFETCH_AHEAD`] or 0 for [`Limits::prefetch_ahead`].
    pub(super) fn row_prefetch_ahead(
        &self,
        ctx: &SweepContext<'_, D>,
        visited_per_sweep: u64,
        above_bytes: usize,
    ) -> usize {
        let mut bytes = visited_per_sweep.saturating_mul(self.swept_bytes_per_node(ctx) as u64);
        if let InnerScheme::Upwind(_) = self.scheme {
            bytes = bytes.saturating_mul(UPWIND_PREFETCH_WEIGHT);
        }
        if cfg!(target_arch = "x86_64") && bytes > above_bytes as u64 {
            ROW_PREFETCH_AHEAD
        } else {
            0
        }
    }

    /// Asks for the cache lines that the sweep will read at the nodes of row `r`, unless, with
    /// the flags (`K`), the row looks as if it will not run ([`SweepContext::row_may_run`], the
    /// window's test with `W`; without the flags every row runs).
    #[inline(always)]
    pub(super) fn prefetch_row<const K: bool, const W: bool>(&self, ctx: &SweepContext<'_, D>, r: usize, lim: Limits) {
        if K && !ctx.row_may_run::<W>(r, lim) {
            return;
        }
        let (s, e) = self.band.row_range(r);
        ctx.u.prefetch(s, e);
        prefetch_range(self.roles, s, e);
        self.band.prefetch_neighbour_range(s, e);
        prefetch_range(ctx.weights, s, e);
        if K {
            prefetch_range(ctx.active, s, e);
        }
        prefetch_range(ctx.coupling, s, e);
        if let Slowness::PerNode(slow) = self.slowness {
            prefetch_range(slow, s, e);
        }
        if let InnerScheme::Upwind(solver) = self.scheme {
            solver.prefetch_nodes(s, e);
        }
    }
}
