//! Which nodes the second-order sweeps visit: the active flags at the start of a phase, the
//! readers a changed value wakes, and the start of a warm solve on a surface that moved only in
//! part ([`Sweeper::start_flags_changed`], issue 47): the nodes whose update changed and the
//! nodes that read them, the others left at the previous fixed point until a neighbour wakes them.

use std::sync::atomic::{AtomicU8, Ordering};

use crate::sweep::NodeRole;

use super::solver::Sweeper;

impl<const D: usize> Sweeper<'_, D> {
    /// The active flags at the start of a phase: the nodes that are not fixed and have a value,
    /// and those that read a node with a value ([`Self::activate`]). Any other node would be
    /// visited only to find no neighbour reached (`inner` and `outer` give None) and be set
    /// inactive until a neighbour wakes it: the same values without those visits (from the fixed
    /// nodes alone, on the sphere at N = 201, 0.25 million of the 5.6 million updates).
    pub(super) fn start_flags(&self, active: &[AtomicU8], values: &[f64]) {
        #[cfg(test)]
        if super::solver::ALL_ACTIVE_START.with(|a| a.get()) {
            for (a, &r) in active.iter().zip(self.roles) {
                a.store((r != NodeRole::Fixed) as u8, Ordering::Relaxed);
            }
            return;
        }
        for a in active {
            a.store(0, Ordering::Relaxed);
        }
        for (i, v) in values.iter().enumerate() {
            if v.is_finite() {
                self.activate(active, i);
            }
        }
        for ((a, v), &r) in active.iter().zip(values).zip(self.roles) {
            if r == NodeRole::Fixed {
                a.store(0, Ordering::Relaxed);
            } else if v.is_finite() {
                a.store(1, Ordering::Relaxed);
            }
        }
    }

    /// Marks the nodes that read node `i`: its neighbours at distance 1 and 2 along each axis.
    /// Without branches: a missing neighbour is the sentinel, whose flag is the sink at the end
    /// of `active`, and a missing first neighbour's own neighbour is taken from `i` (the same
    /// sentinel), so that the twelve stores cost no mispredicted jumps.
    #[inline(always)]
    pub(super) fn activate(&self, active: &[AtomicU8], i: usize) {
        let table = self.table;
        let sentinel = table.sentinel();
        debug_assert_eq!(active.len(), sentinel as usize + 1);
        for k in 0..D {
            for side in 0..2 {
                // SAFETY: `i` and `from` are band nodes; `active` has one flag per band node and
                // one for the sentinel
                let j = unsafe { table.neighbour_unchecked(i, k, side) };
                let from = if j == sentinel { i } else { j as usize };
                let j2 = unsafe { table.neighbour_unchecked(from, k, side) };
                unsafe { active.get_unchecked(j as usize) }.store(1, Ordering::Relaxed);
                unsafe { active.get_unchecked(j2 as usize) }.store(1, Ordering::Relaxed);
            }
        }
    }

    /// The active flags at the start of a warm phase on a surface that moved in part: the nodes
    /// not fixed whose update reads something else than in the previous solve (`changed`, from
    /// [`super::fingerprint::changed_nodes`]) and the nodes that read them, up to distance 3
    /// along the axes (their values, |φ| or u₀ may have changed). Every other node holds the previous solve's fixed point of an
    /// unchanged update and is visited again only once a node it reads changes by more than the
    /// tolerance, as in any iteration. Returns where the front window starts: the smallest value
    /// among the active nodes and the changed fixed nodes (+∞ when nothing changed).
    pub(super) fn start_flags_changed(&self, active: &[AtomicU8], values: &[f64], changed: &[bool]) -> f64 {
        for a in active {
            a.store(0, Ordering::Relaxed);
        }
        let table = self.table;
        let sentinel = table.sentinel();
        for (i, &c) in changed.iter().enumerate() {
            if c {
                active[i].store(1, Ordering::Relaxed);
                self.activate(active, i);
                // and the readers at distance 3 (the BDF3 ramp's third neighbour): during the
                // sweeps a change reaches them through the nodes between, but a changed input
                // there (u₀, a node entering the band) need not move those nodes
                for k in 0..D {
                    for side in 0..2 {
                        let mut j = i as u32;
                        for _ in 0..3 {
                            if j == sentinel {
                                break;
                            }
                            // SAFETY: `j` is a band node (not the sentinel), k < D, side < 2
                            j = unsafe { table.neighbour_unchecked(j as usize, k, side) };
                        }
                        if j != sentinel {
                            active[j as usize].store(1, Ordering::Relaxed);
                        }
                    }
                }
            }
        }
        let mut first = f64::INFINITY;
        for (i, (a, &r)) in active.iter().zip(self.roles).enumerate() {
            if r == NodeRole::Fixed {
                a.store(0, Ordering::Relaxed);
                if changed[i] {
                    // a source that moved: the window starts where a cold solve's does
                    first = first.min(values[i] + self.u0[i]);
                }
            } else if a.load(Ordering::Relaxed) != 0 {
                first = first.min(values[i] + self.u0[i]);
            }
        }
        // the sentinel's sink stays as the activations left it: it is never visited
        first
    }
}
