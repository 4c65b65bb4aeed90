//! Prefetching a sweep's rows ahead of it, when the data the sweeps read do not fit in the cache.
//!
//! The sweeps visit the rows in tiles of 8 × 8 rows ([`crate::schedule`]): eight rows that are
//! neighbours along the second leading axis lie next to each other in memory, but the next eight
//! lie a plane of the band away. Every array the kernel reads at a node (its value, role,
//! neighbour table, upwind weights, flags) is thus read in runs of a few cache lines, too short
//! for the processor's own prefetcher to pick up. While the rows an iteration visits fit in the
//! last-level cache this does not matter; beyond it each run starts with misses. So the sweeps
//! ask for the lines of the row [`ROW_PREFETCH_AHEAD`] places ahead in the visiting order (and
//! only for a row that will run: dirty, inside the front window), but only in an iteration that
//! follows one whose visited rows held more than [`SolveOptions::row_prefetch_above`] bytes of
//! those arrays (the default is [`DEFAULT_CACHE_SHARE`] of the last-level cache). Below that the
//! hints only cost instructions; docs/architecture.md ("Rows fetched ahead") has the measurements.
//!
//! [`SolveOptions::row_prefetch_above`]: super::SolveOptions::row_prefetch_above

use super::sweep_state::{Limits, SweepContext};
use super::{Slowness, SweepProblem};
use crate::prefetch::prefetch_range;
use std::sync::atomic::Ordering;
use std::sync::OnceLock;

/// How many rows ahead in the visiting order the sweeps prefetch (1, 2, 4 and 8 measured within
/// a few percent of each other on the sphere at N = 401).
pub(super) const ROW_PREFETCH_AHEAD: usize = 2;

/// The share of the last-level cache above which the sweeps prefetch (see the module doc).
pub const DEFAULT_CACHE_SHARE: f64 = 0.5;

/// The last-level cache assumed where the system does not say (Linux's sysfs): 32 MiB.
const ASSUMED_LAST_LEVEL_CACHE: usize = 32 << 20;

/// The size in bytes of the largest-level data or unified cache of CPU 0 as Linux reports it
/// (`/sys/devices/system/cpu/cpu0/cache`), read once; 32 MiB where it cannot be read.
pub fn last_level_cache_bytes() -> usize {
    static SIZE: OnceLock<usize> = OnceLock::new();
    *SIZE.get_or_init(|| read_last_level_cache().unwrap_or(ASSUMED_LAST_LEVEL_CACHE))
}

fn read_last_level_cache() -> Option<usize> {
    let dir = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache").ok()?;
    let mut best: Option<(u32, usize)> = None;
    for entry in dir.flatten() {
        let path = entry.path();
        let read = |f: &str| std::fs::read_to_string(path.join(f)).ok().map(|s| s.trim().to_string());
        if read("type").as_deref() == Some("Instruction") {
            continue;
        }
        let (Some(level), Some(size)) = (read("level").and_then(|l| l.parse::<u32>().ok()), read("size").and_then(|s| parse_cache_size(&s))) else {
            continue;
        };
        if best.map_or(true, |(l, _)| level > l) {
            best = Some((level, size));
        }
    }
    best.map(|(_, size)| size).filter(|&s| s > 0)
}

/// Parses sysfs's cache sizes: "32768K", "1M", "512" (bytes).
fn parse_cache_size(s: &str) -> Option<usize> {
    let (digits, unit) = match s.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((i, _)) => s.split_at(i),
        None => (s, ""),
    };
    let n: usize = digits.parse().ok()?;
    let scale = match unit.trim() {
        "" => 1,
        "K" | "k" | "KiB" => 1 << 10,
        "M" | "MiB" => 1 << 20,
        "G" | "GiB" => 1 << 30,
        _ => return None,
    };
    n.checked_mul(scale)
}

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
        let mut bytes = 8 + 1 + (8 * (D - 1) + 1) + 4 * D;
        if ctx.skip_inactive {
            bytes += 1;
        }
        if !ctx.coupling.is_empty() {
            bytes += 1;
        }
        if let Slowness::PerNode(_) = self.slowness {
            bytes += 8;
        }
        bytes
    }

    /// Whether the iteration after one that visited rows holding `visited_per_sweep` nodes per
    /// sweep prefetches its rows: [`ROW_PREFETCH_AHEAD`] or 0 for [`Limits::prefetch_ahead`].
    pub(super) fn row_prefetch_ahead(&self, ctx: &SweepContext<'_, D>, visited_per_sweep: u64, above_bytes: usize) -> usize {
        let bytes = visited_per_sweep.saturating_mul(self.swept_bytes_per_node(ctx) as u64);
        if bytes > above_bytes as u64 {
            ROW_PREFETCH_AHEAD
        } else {
            0
        }
    }

    /// Asks for the cache lines that the sweep will read at the nodes of row `r`, unless the row
    /// will not run (with the flags `K`, its dirty flag is clear; with the window `W`, its lower
    /// bound lies beyond it: [`SweepContext::take_row`]'s tests, which this one only reads).
    #[inline(always)]
    pub(super) fn prefetch_row<const K: bool, const W: bool>(&self, ctx: &SweepContext<'_, D>, r: usize, lim: Limits) {
        // SAFETY: r < n_rows; row_dirty and row_low have n_rows + 1 entries
        if K && unsafe { ctx.row_dirty.get_unchecked(r) }.load(Ordering::Relaxed) == 0 {
            return;
        }
        if W && unsafe { ctx.row_low.get_unchecked(r) }.load(Ordering::Relaxed) > lim.window_key {
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_sizes_parse_as_sysfs_writes_them() {
        assert_eq!(parse_cache_size("32768K"), Some(32 << 20));
        assert_eq!(parse_cache_size("1M"), Some(1 << 20));
        assert_eq!(parse_cache_size("512"), Some(512));
        assert_eq!(parse_cache_size("12 MiB"), Some(12 << 20));
        assert_eq!(parse_cache_size("lots"), None);
        assert_eq!(parse_cache_size("3X"), None);
        assert!(last_level_cache_bytes() > 0);
        assert_eq!(default_row_prefetch_above(), (last_level_cache_bytes() as f64 * DEFAULT_CACHE_SHARE) as usize);
    }
}
