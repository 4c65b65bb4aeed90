//! The row walk of one sweep of the second-order solve ([`super::solver`]): per row, whether it
//! may hold an active node within the window ([`RowsState`]), then its nodes forwards or
//! backwards through [`Sweeper::visit`].
//!
//! The walk is compiled twice: for the baseline x86-64 target of the package, and for
//! x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT, MOVBE), which [`Isa::for_this_solve`] picks at run time
//! where the CPU has it. The source is the same and Rust never fuses a multiply and an add
//! unless told to (`mul_add`), so both give the same bits (a test checks it); the newer
//! encodings make the update about 5% faster (sphere N = 201, one thread,
//! `examples/order2_phases.rs`).

use std::sync::atomic::{AtomicU8, Ordering};

use crate::band::NarrowBand;
use crate::sweep::sweep_state::{Accumulator, SharedValues};
use crate::sweep::NodeRole;

use super::solver::{Limits, Sweeper, WOKE};

#[cfg(test)]
thread_local! {
    /// Tests: the baseline walk on this thread's solves even where the CPU has x86-64-v3.
    pub(crate) static FORCE_BASELINE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The instruction set the row walk runs with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Isa {
    Baseline,
    #[cfg(target_arch = "x86_64")]
    X86_64V3,
}

impl Isa {
    /// x86-64-v3 where the CPU has every feature of it that the walk is compiled with.
    pub(super) fn for_this_solve() -> Isa {
        #[cfg(test)]
        if FORCE_BASELINE.with(|f| f.get()) {
            return Isa::Baseline;
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("movbe")
        {
            return Isa::X86_64V3;
        }
        Isa::Baseline
    }
}

/// What one row walk reads and writes.
pub(super) struct RowWalk<'s, 'a, const D: usize> {
    pub(super) sw: &'s Sweeper<'a, D>,
    pub(super) band: &'s NarrowBand<D>,
    pub(super) rows_state: &'s RowsState,
    pub(super) shared: &'s SharedValues<'s>,
    pub(super) active: &'s [AtomicU8],
    pub(super) row_inner: &'s [u32],
    pub(super) lim: Limits,
}

impl<const D: usize> RowWalk<'_, '_, D> {
    /// Walks `rows` (backwards within each row when `backwards`) with the given instruction set.
    pub(super) fn run(&self, isa: Isa, rows: &[u32], backwards: bool) -> Accumulator {
        match isa {
            Isa::Baseline => self.walk(rows, backwards),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Isa::X86_64V3` is only chosen where the CPU has those features
            Isa::X86_64V3 => unsafe { self.walk_v3(rows, backwards) },
        }
    }

    /// [`Self::walk`] compiled for x86-64-v3.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,movbe,popcnt,sse4.1,sse4.2,ssse3")]
    unsafe fn walk_v3(&self, rows: &[u32], backwards: bool) -> Accumulator {
        self.walk(rows, backwards)
    }

    #[inline(always)]
    fn walk(&self, rows: &[u32], backwards: bool) -> Accumulator {
        let (sw, rows_state, shared, lim_now) = (self.sw, self.rows_state, self.shared, self.lim);
        let mut acc = Accumulator::default();
        for &r in rows {
            let r = r as usize;
            if rows_state.dirty[r].load(Ordering::Relaxed) == 0 {
                continue;
            }
            let low = f64::from_bits(rows_state.low[r].load(Ordering::Relaxed));
            if low > lim_now.window && low.is_finite() {
                // every value of the row lies beyond the window (a lower bound)
                acc.waiting = acc.waiting.min(low);
                continue;
            }
            rows_state.dirty[r].store(0, Ordering::Relaxed);
            let (s, e) = self.band.row_range(r);
            let roles = &sw.roles[s..e];
            let (mut status, mut low) = (0u8, f64::INFINITY);
            if backwards {
                let mut k = self.row_inner[r + 1] as usize;
                for (i, &role) in (s..e).zip(roles).rev() {
                    k -= (role != NodeRole::Outer) as usize;
                    status |= sw.visit(shared, self.active, i, role, k, lim_now, &mut acc);
                    low = low.min(sw.u_at(shared, i));
                }
            } else {
                let mut k = self.row_inner[r] as usize;
                for (i, &role) in (s..e).zip(roles) {
                    status |= sw.visit(shared, self.active, i, role, k, lim_now, &mut acc);
                    low = low.min(sw.u_at(shared, i));
                    k += (role != NodeRole::Outer) as usize;
                }
            }
            rows_state.low[r].store(low.to_bits(), Ordering::Relaxed);
            if status != 0 {
                rows_state.dirty[r].store(1, Ordering::Relaxed);
            }
            if status & WOKE != 0 {
                rows_state.wake_around(r);
            }
        }
        acc
    }
}

/// Per row: whether a node of it may be active, and a lower bound of its finite values (the
/// sweeps skip a row that has no active node, or whose values all lie beyond the window: on the
/// sphere at N = 201 the rows held 12 times as many node visits as updates).
pub(super) struct RowsState {
    dirty: Vec<AtomicU8>,
    low: Vec<std::sync::atomic::AtomicU64>,
    /// [`NarrowBand::row_neighbours`]: per row the rows next to it along each leading axis.
    neighbours: Vec<u32>,
    per: usize,
}

impl RowsState {
    /// `values`: w, and u₀, per node (the lower bounds are of u = u₀ + w).
    pub(super) fn new<const D: usize>(band: &NarrowBand<D>, values: &[f64], u0: &[f64]) -> Self {
        let rows = band.n_rows();
        let low = (0..rows)
            .map(|r| {
                let (s, e) = band.row_range(r);
                let m = values[s..e]
                    .iter()
                    .zip(&u0[s..e])
                    .fold(f64::INFINITY, |m, (&w, &u0)| m.min(w + u0));
                std::sync::atomic::AtomicU64::new(m.to_bits())
            })
            .collect();
        RowsState {
            dirty: (0..=rows).map(|_| AtomicU8::new(1)).collect(),
            low,
            neighbours: band.row_neighbours(),
            per: 2 * (D - 1),
        }
    }

    /// Marks the rows whose nodes a node of row `r` wakes: along each leading axis the rows at
    /// distance 1 and 2 (its own row is marked by the caller).
    #[inline]
    fn wake_around(&self, r: usize) {
        let sentinel = self.dirty.len() - 1;
        for d in 0..self.per {
            let q = self.neighbours[r * self.per + d] as usize;
            if q == sentinel {
                continue;
            }
            self.dirty[q].store(1, Ordering::Relaxed);
            let q2 = self.neighbours[q * self.per + d] as usize;
            if q2 != sentinel {
                self.dirty[q2].store(1, Ordering::Relaxed);
            }
        }
    }
}
