//! What the threads of a sweep share, and the bookkeeping per row that lets them skip work:
//! the rows' dirty flags (a row none of whose nodes is active is skipped whole), the rows' lower
//! bounds behind the front window (a row whose bound lies beyond the window waits), the
//! per-iteration limits and the per-sweep totals (docs/architecture.md, "Invariants").
//! The sweep loop itself is in [`super`].

use std::sync::atomic::{AtomicU32, AtomicU64, AtomicU8, Ordering};

/// What the threads of a sweep share.
pub(super) struct SweepContext<'a, const D: usize> {
    pub(super) u: &'a SharedValues<'a>,
    pub(super) active: &'a [AtomicU8],
    pub(super) weights: &'a [[f32; D]],
    /// Per inner node, bit `2k + side` set when the neighbour `nb[k][side]` is an extension-layer
    /// node whose update (5) reads this node (see [`SweepProblem::coupling_mask`](super::SweepProblem)); empty when
    /// the coupled Godunov update is not used.
    pub(super) coupling: &'a [u8],
    pub(super) general_slowness: f64,
    /// Per tile, the id of the last parallel sweep that finished it (empty when sequential).
    pub(super) tiles_done: &'a [AtomicU32],
    /// The id of the last parallel sweep (ids start at 1, the flags at 0).
    pub(super) sweep_id: AtomicU32,
    /// Per row (and a last slot for "no row"), a lower bound of its values and of the values its
    /// nodes can take next, as an [`order_key`]: the smallest value it held at the start, was
    /// given since, or that a row next to it held at the start or gave when it woke this row (a
    /// Godunov or extension update never falls below all the values it reads). Never raised, so
    /// a bound even where an extension update raises a value. A row above the front window is
    /// skipped whole. Lowered by the thread that runs the row or a row next to it; two rows next
    /// to the same row can run at once, hence the atomic minimum ([`SweepContext::lower_row`]).
    pub(super) row_low: &'a [AtomicU64],
    /// Per node, 1 for the extension-layer nodes in an upwind 2-cycle, which the front window
    /// does not hold back (empty without the window).
    pub(super) cyclic: &'a [u8],
    /// Per row (and a last slot for "no row"), set while a node of the row may be active: a row
    /// whose flag is clear is skipped whole. Set for every row at the start; cleared when the row
    /// is run; set again for the row when a node stays active, and for the row and the rows next
    /// to it along the leading axes ([`NarrowBand::row_neighbours`](crate::band::NarrowBand::row_neighbours)) when a node activates its
    /// neighbours. Those rows are never run at the same time as the row (see
    /// [`crate::band::schedule`]), so no activation is missed.
    pub(super) row_dirty: &'a [AtomicU8],
    /// [`NarrowBand::row_neighbours`](crate::band::NarrowBand::row_neighbours).
    pub(super) row_neighbours: &'a [u32],
    /// The solve runs a front window: the sweeps track the row bounds, the front and the nodes
    /// waiting beyond the window; otherwise they skip that bookkeeping.
    pub(super) windowed: bool,
    /// Active flags are kept ([`SolveOptions::skip_inactive`](super::SolveOptions::skip_inactive)): a node is updated only when a
    /// neighbour changed. Without them every node is updated in every sweep (the paper's plain
    /// sweeps) and the sweeps touch neither the flags nor the rows' dirty flags.
    pub(super) skip_inactive: bool,
}

/// The smallest active-flag value that marks a node refused by the front window (0: inactive,
/// 1: active; see [`Limits::refused`]).
pub(super) const REFUSED: u8 = 2;

/// A node of the row stays active: the row stays dirty.
pub(super) const KEEP_ROW: u8 = 1;
/// A node of the row activated its neighbours: the row and the rows next to it become dirty.
pub(super) const WAKE_ROWS: u8 = 2;

impl<const D: usize> SweepContext<'_, D> {
    /// Whether row `r` would run now: its dirty flag is set and, with the window (`W`), its
    /// lower bound lies within it ([`take_row`](Self::take_row)'s tests, read without acting on
    /// them; with the window off its key is that of infinity, so `W = true` is right there too,
    /// only slower). For predicting the work ahead.
    #[inline(always)]
    pub(super) fn row_may_run<const W: bool>(&self, r: usize, lim: Limits) -> bool {
        // SAFETY: r < n_rows; row_dirty and row_low have n_rows + 1 entries
        unsafe {
            self.row_dirty.get_unchecked(r).load(Ordering::Relaxed) != 0
                && (!W || self.row_low.get_unchecked(r).load(Ordering::Relaxed) <= lim.window_key)
        }
    }

    /// Whether row `r` has anything to do: a node may be active and not all its values lie
    /// beyond the front window (a dirty row that does lie beyond it lowers `acc.waiting` to its
    /// bound). Clears the row's dirty flag when it has.
    #[inline(always)]
    pub(super) fn take_row<const W: bool>(&self, r: usize, lim: Limits, acc: &mut Accumulator) -> bool {
        // SAFETY: r < n_rows; row_dirty has n_rows + 1 entries
        let dirty = unsafe { self.row_dirty.get_unchecked(r) };
        if dirty.load(Ordering::Relaxed) == 0 {
            return false;
        }
        if W {
            // SAFETY: r < n_rows; row_low has n_rows + 1 entries
            let key = unsafe { self.row_low.get_unchecked(r) }.load(Ordering::Relaxed);
            if key > lim.window_key {
                let low = from_order_key(key);
                if low < acc.waiting {
                    acc.waiting = low;
                }
                return false;
            }
        }
        dirty.store(0, Ordering::Relaxed);
        true
    }

    /// After row `r` ran: lowers its bound to `low` and sets the dirty flags `marks` asks for.
    #[inline(always)]
    pub(super) fn finish_row<const W: bool, const K: bool>(&self, r: usize, low: f64, marks: u8) {
        if !K {
            return;
        }
        let key = order_key(low);
        if W {
            self.lower_row(r, key);
        }
        if marks != 0 {
            unsafe { self.row_dirty.get_unchecked(r) }.store(1, Ordering::Relaxed);
        }
        if marks & WAKE_ROWS != 0 {
            let per = 2 * (D - 1);
            for &q in &self.row_neighbours[r * per..(r + 1) * per] {
                // SAFETY: entries are < n_rows or the last slot n_rows
                unsafe { self.row_dirty.get_unchecked(q as usize) }.store(1, Ordering::Relaxed);
                // the nodes this row woke take values of at least the smallest value it gave
                // (a Godunov or extension update never falls below all the values it reads)
                if W {
                    self.lower_row(q as usize, key);
                }
            }
        }
    }

    /// Lowers the bound of row `r` (or the "no row" slot) to the value with [`order_key`] `key`.
    /// Rows next to each other may finish at the same time on different threads, so this is an
    /// atomic minimum.
    #[inline(always)]
    pub(super) fn lower_row(&self, r: usize, key: u64) {
        // SAFETY: r ≤ n_rows; row_low has n_rows + 1 entries
        let slot = unsafe { self.row_low.get_unchecked(r) };
        if slot.load(Ordering::Relaxed) > key {
            slot.fetch_min(key, Ordering::Relaxed);
        }
    }
}

/// A key for `v` whose unsigned order is the order of the values (for every non-NaN `v`; −0.0
/// comes just below +0.0), so that an [`AtomicU64`] holds a lower bound that threads can lower
/// with `fetch_min`.
#[inline(always)]
pub(super) fn order_key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | 1 << 63
    }
}

/// The value whose [`order_key`] is `k`.
#[inline(always)]
pub(super) fn from_order_key(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k })
}

/// Per-sweep totals.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Accumulator {
    pub(crate) max_change: f64,
    pub(crate) updates: u64,
    /// The smallest new value of a node that changed by more than `Limits::settled` (infinite
    /// when none did): where the unconverged part of the band begins.
    pub(crate) front: f64,
    /// A lower bound of the values of the active nodes left beyond the front window (infinite
    /// when none were): where the window goes next when nothing in it moved.
    pub(crate) waiting: f64,
    /// The nodes of the rows that ran (all nodes of every row without the flags): what the
    /// sweep read, for the next iteration's [`Limits::prefetch_ahead`].
    pub(crate) visited: u64,
}

impl Default for Accumulator {
    fn default() -> Self {
        Accumulator {
            max_change: 0.0,
            updates: 0,
            front: f64::INFINITY,
            waiting: f64::INFINITY,
            visited: 0,
        }
    }
}

impl Accumulator {
    pub(crate) fn merge(self, o: Accumulator) -> Accumulator {
        Accumulator {
            max_change: self.max_change.max(o.max_change),
            updates: self.updates + o.updates,
            front: self.front.min(o.front),
            waiting: self.waiting.min(o.waiting),
            visited: self.visited + o.visited,
        }
    }
}

/// The per-iteration constants of a sweep.
#[derive(Debug, Clone, Copy)]
pub(super) struct Limits {
    /// The numerical infinity.
    pub(super) inf: f64,
    /// A change at most this large does not re-activate the neighbours
    /// ([`SolveOptions::activation_threshold`](super::SolveOptions::activation_threshold)).
    pub(super) threshold: f64,
    /// Nodes holding more than this are left for a later iteration (and stay active); infinite
    /// unless [`SolveOptions::front_window`](super::SolveOptions::front_window) is on.
    pub(super) window: f64,
    /// [`order_key`] of `window`.
    pub(super) window_key: u64,
    /// The active-flag value of an unreached node whose new value lay beyond the window in this
    /// iteration ([`REFUSED`] plus the iteration number modulo 250): it stays active, but is
    /// not updated again in this iteration unless a neighbour changes (which sets its flag to 1).
    pub(super) refused: u8,
    /// A change larger than this (the tolerance) counts towards [`Accumulator::front`].
    pub(super) settled: f64,
    /// How many rows ahead in the visiting order the sweeps prefetch the rows' data; 0 for none
    /// (see `row_prefetch.rs`).
    pub(super) prefetch_ahead: usize,
}

/// The node values, shared by the threads of a parallel sweep. The schedule guarantees that the
/// tiles processed at the same time write disjoint nodes and read no node another tile writes
/// (see [`crate::band::schedule`]), so unsynchronised access is race-free.
/// Copies (held in registers by the row loop) borrow the values for `'a`, like the slice they
/// were made from.
#[derive(Clone, Copy)]
pub(crate) struct SharedValues<'a> {
    ptr: *mut f64,
    len: usize,
    borrowed: std::marker::PhantomData<&'a [std::cell::Cell<f64>]>,
}

unsafe impl Sync for SharedValues<'_> {}
unsafe impl Send for SharedValues<'_> {}

impl<'a> SharedValues<'a> {
    /// The values of `u`, borrowed mutably for as long as any copy lives.
    pub(crate) fn new(u: &'a mut [f64]) -> Self {
        SharedValues {
            ptr: u.as_mut_ptr(),
            len: u.len(),
            borrowed: std::marker::PhantomData,
        }
    }

    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> f64 {
        debug_assert!(i < self.len);
        unsafe { *self.ptr.add(i) }
    }
    /// Prefetch hint for the values `start..end` ([`crate::prefetch`]).
    #[inline(always)]
    pub(super) fn prefetch(&self, start: usize, end: usize) {
        crate::prefetch::prefetch_raw_range(self.ptr as *const f64, self.len, start, end);
    }
    #[inline(always)]
    pub(crate) fn set(&self, i: usize, v: f64) {
        debug_assert!(i < self.len);
        unsafe { *self.ptr.add(i) = v }
    }
}
