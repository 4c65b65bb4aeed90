//! The kernel: one row of a sweep, node by node — skip what cannot change (inactive nodes, rows
//! beyond the front window), apply the local solver of the node's role (Godunov Eq. (3),
//! Lax–Friedrichs Eq. (4) or a general Hamiltonian, the extension update (5)), accept the value
//! and wake the neighbours. Specialised at compile time for the scheme, the slowness, the window
//! and the active flags (the `specialised!` macro of `sweep/mod.rs`).

use super::problem::*;
use super::sweep_state::{Accumulator, Limits, SharedValues, SweepContext, KEEP_ROW, WAKE_ROWS};
use crate::band::NeighbourTable;
use crate::scheme::extension::extension_apply_upwind;
use crate::scheme::godunov::{coupled_axis, fmin, godunov_update, godunov_update_coupled};
use crate::scheme::hamiltonian::InnerScheme;
use crate::scheme::lax_friedrichs::{central_gradient, lxf_eikonal_update, lxf_general_update};
use crate::scheme::upwind::{Builtin, LocalSolver};
use std::sync::atomic::{AtomicU8, Ordering};

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// The rows of one tile, in order, with the update specialised for scheme `S` and a
    /// constant (`P = false`) or per-node (`P = true`) slowness.
    pub(super) fn run_rows<const S: u8, const P: bool, const W: bool, const K: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        rows: &[u32],
        backwards: bool,
        lim: Limits,
    ) -> Accumulator {
        let mut acc = Accumulator::default();
        for (t, &r) in rows.iter().enumerate() {
            if lim.prefetch_ahead > 0 {
                if let Some(&ahead) = rows.get(t + lim.prefetch_ahead) {
                    self.prefetch_row::<K, W>(ctx, ahead as usize, lim);
                }
            }
            self.run_row::<S, P, W, K>(ctx, r as usize, backwards, lim, &mut acc);
        }
        acc
    }

    /// The dirty-row invariant, checked in the unit tests whenever a row is reached: a row whose
    /// flag is clear holds no active node (fixed nodes, which are never updated, aside).
    #[cfg(test)]
    pub(super) fn assert_clean_row_is_idle(&self, ctx: &SweepContext<'_, D>, r: usize) {
        if ctx.row_dirty[r].load(Ordering::Relaxed) != 0 {
            return;
        }
        let (s, e) = self.band.row_range(r);
        for n in s..e {
            assert!(
                ctx.active[n].load(Ordering::Relaxed) == 0 || self.roles[n] == NodeRole::Fixed,
                "row {r} is clean but its node {n} is active"
            );
        }
    }

    /// One row, in sweep order; with the flags (`K`), skipped whole when none of its nodes is
    /// active (its dirty flag is clear) or all its values lie beyond the front window.
    #[inline(always)]
    pub(super) fn run_row<const S: u8, const P: bool, const W: bool, const K: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        r: usize,
        backwards: bool,
        lim: Limits,
        acc: &mut Accumulator,
    ) {
        let run = self.claim_row::<W, K>(ctx, r, lim, acc);
        let before = acc.updates;
        if run {
            self.run_claimed_row::<S, P, W, K>(ctx, r, backwards, lim, acc);
        }
        if crate::kernel_stats::ENABLED {
            let (s, e) = self.band.row_range(r);
            crate::kernel_stats::row(r, run, e - s, acc.updates - before);
        }
    }

    /// Whether row `r` has anything to do ([`SweepContext::take_row`], which clears its dirty
    /// flag when it has); in the unit tests, also checks the dirty-row invariant.
    #[inline(always)]
    pub(super) fn claim_row<const W: bool, const K: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        r: usize,
        lim: Limits,
        acc: &mut Accumulator,
    ) -> bool {
        if !K {
            // every row runs in every sweep
            return true;
        }
        #[cfg(test)]
        self.assert_clean_row_is_idle(ctx, r);
        ctx.take_row::<W>(r, lim, acc)
    }

    /// The nodes of row `r`, which [`claim_row`](Self::claim_row) let through, in sweep order.
    #[inline(always)]
    pub(super) fn run_claimed_row<const S: u8, const P: bool, const W: bool, const K: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        r: usize,
        backwards: bool,
        lim: Limits,
        acc: &mut Accumulator,
    ) {
        let (s, e) = self.band.row_range(r);
        acc.visited += (e - s) as u64;
        let mut low = f64::INFINITY;
        let mut marks = 0u8;
        let arrays = self.node_arrays::<S>(ctx);
        if backwards {
            for n in (s..e).rev() {
                self.visit::<S, P, W, K>(ctx, &arrays, n, lim, acc, &mut low, &mut marks);
            }
        } else {
            for n in s..e {
                self.visit::<S, P, W, K>(ctx, &arrays, n, lim, acc, &mut low, &mut marks);
            }
        }
        ctx.finish_row::<W, K>(r, low, marks);
    }

    /// The arrays the kernel reads at a node, copied into locals for a row ([`NodeArrays`]), with
    /// the built-in upwind solver of scheme `S`.
    #[inline(always)]
    pub(super) fn node_arrays<'k, const S: u8>(&'k self, ctx: &SweepContext<'k, D>) -> NodeArrays<'k, D> {
        NodeArrays {
            u: *ctx.u,
            roles: self.roles,
            table: self.band.neighbour_table(),
            weights: ctx.weights,
            coupling: ctx.coupling,
            active: ctx.active,
            cyclic: ctx.cyclic,
            slowness_per_node: match self.slowness {
                Slowness::PerNode(s) => s,
                Slowness::Constant(_) => &[],
            },
            h_times_constant_slowness: match self.slowness {
                Slowness::Constant(s) => self.spacing * s,
                Slowness::PerNode(_) => f64::NAN,
            },
            spacing: self.spacing,
            upwind: match self.scheme {
                InnerScheme::Upwind(solver) if S == UPWIND_MOVING_MEDIUM || S == UPWIND_METRIC => solver.builtin(),
                _ => Builtin::Other,
            },
        }
    }

    #[inline(always)]
    /// Updates node `n` if it is active (and within the front window), re-activates its
    /// neighbours when it changed by more than the threshold, and lowers `low` to its new value.
    /// `row` collects what the row's dirty flags need: [`KEEP_ROW`] when the node stays active,
    /// [`WAKE_ROWS`] when it activated its neighbours. Without the flags (`K = false`), updates
    /// every node but the fixed ones and touches neither `low` nor `row`.
    pub(super) fn visit<const S: u8, const P: bool, const W: bool, const K: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        arr: &NodeArrays<'_, D>,
        n: usize,
        lim: Limits,
        acc: &mut Accumulator,
        low: &mut f64,
        row: &mut u8,
    ) {
        if !K {
            // no flags: every node but the fixed ones (`iterate` counts these updates per sweep,
            // `updated_per_sweep`)
            // SAFETY: n < band.len(), the length of roles (checked in `check`)
            if unsafe { *arr.roles.get_unchecked(n) } == NodeRole::Fixed {
                return;
            }
            // SAFETY: n < band.len()
            let nb = unsafe { arr.table.neighbours_of_unchecked(n) };
            let result = self.local_update::<S, P>(ctx, arr, n, &nb, lim.inf);
            if crate::kernel_stats::ENABLED {
                crate::kernel_stats::update(arr.roles[n] as u8, result.map(|u| u.change()));
            }
            if let Some(up) = result {
                let c = up.change();
                if c > acc.max_change {
                    acc.max_change = c;
                }
                arr.u.set(n, up.new);
            }
            return;
        }
        let active = arr.active;
        // SAFETY: n < band.len(); active has that length plus the sentinel slot.
        let flag = unsafe { active.get_unchecked(n) };
        // fixed nodes get activated by their neighbours too: one test for both (no short circuit)
        let fixed = unsafe { *arr.roles.get_unchecked(n) } == NodeRole::Fixed;
        let state = flag.load(Ordering::Relaxed);
        if (state == 0) | fixed {
            return;
        }
        // beyond the front window (see `Limits::window`): a node that holds a value there stays
        // active for a later iteration; an unreached one is updated, but takes the new value only
        // if it lies within the window
        let mut unreached_beyond = false;
        if W {
            let value = arr.u.get(n);
            if value > lim.window && (arr.cyclic.is_empty() || unsafe { *arr.cyclic.get_unchecked(n) } == 0) {
                if !unreached(value, lim.inf) {
                    *row |= KEEP_ROW;
                    if value < acc.waiting {
                        acc.waiting = value;
                    }
                    return;
                }
                if state == lim.refused {
                    // refused earlier in this iteration, and no neighbour has changed since (that
                    // would have set the flag to 1): the same window, the same candidate, which
                    // already lowered this iteration's `waiting`
                    *row |= KEEP_ROW;
                    return;
                }
                unreached_beyond = true;
            }
        }
        flag.store(0, Ordering::Relaxed);
        acc.updates += 1;
        // SAFETY: n < band.len()
        let nb = unsafe { arr.table.neighbours_of_unchecked(n) };
        let result = self.local_update::<S, P>(ctx, arr, n, &nb, lim.inf);
        if crate::kernel_stats::ENABLED {
            crate::kernel_stats::update(arr.roles[n] as u8, result.map(|u| u.change()));
        }
        let Some(up) = result else { return };
        if W && unreached_beyond && up.new > lim.window {
            flag.store(lim.refused, Ordering::Relaxed);
            *row |= KEEP_ROW;
            if up.new < acc.waiting {
                acc.waiting = up.new;
            }
            return;
        }
        if up.self_dependent {
            flag.store(1, Ordering::Relaxed);
            *row |= KEEP_ROW;
        }
        let c = up.change();
        if c > acc.max_change {
            acc.max_change = c;
        }
        arr.u.set(n, up.new);
        if W {
            if up.new < *low {
                *low = up.new;
            }
            if c > lim.settled && up.new < acc.front {
                acc.front = up.new;
            }
        }
        if c <= lim.threshold {
            return;
        }
        *row |= WAKE_ROWS;
        for k in 0..D {
            unsafe {
                active.get_unchecked(nb[k][0] as usize).store(1, Ordering::Relaxed);
                active.get_unchecked(nb[k][1] as usize).store(1, Ordering::Relaxed);
            }
        }
    }

    /// The local update of node `n` (not fixed) from the current neighbour values: the extension
    /// update (5) in the layer, the scheme's local solver with monotone acceptance in the inner
    /// tube. `None` when the value would not change. Nothing is written.
    #[inline(always)]
    pub(super) fn local_update<const S: u8, const P: bool>(
        &self,
        ctx: &SweepContext<'_, D>,
        arr: &NodeArrays<'_, D>,
        n: usize,
        nb: &[[u32; 2]; D],
        inf: f64,
    ) -> Option<LocalUpdate> {
        let u = arr.u;
        // SAFETY: n < band.len(); roles, weights and the neighbour table have at least that
        // length (checked in `check`); neighbour entries are ≤ len, the sentinel slot of `u`.
        let role = unsafe { *arr.roles.get_unchecked(n) };
        let old = u.get(n);
        if role == NodeRole::Outer {
            // Eq. (5) with the precomputed upwind weights, reading only the upwind neighbours.
            // Neighbours still at the numerical infinity stay in the convex combination, as in
            // the paper: the extended value then approaches the solution from above like the
            // inner values do. Dropping them would let a too-small value into the layer, which
            // the monotone Godunov update could never undo.
            let w = unsafe { *arr.weights.get_unchecked(n) };
            if w[0].is_nan() {
                // no upwind neighbour (or a vanishing normal, e.g. on a medial axis): the node
                // keeps its value even when a neighbour re-activates it
                return None;
            }
            let v = extension_apply_upwind(w, nb, |i| u.get(i as usize));
            return if v == old {
                None
            } else {
                Some(LocalUpdate {
                    old,
                    new: v,
                    self_dependent: false,
                })
            };
        }
        let mut minus = [0.0; D];
        let mut plus = [0.0; D];
        for k in 0..D {
            minus[k] = u.get(nb[k][0] as usize);
            plus[k] = u.get(nb[k][1] as usize);
        }
        let h = arr.spacing;
        // SAFETY: n < band.len()
        let f = unsafe { arr.h_times_slowness::<P>(n) };
        // NaN only for a per-node slowness dispatched with P = false, which the general
        // Hamiltonian (taking its slowness from the Hamiltonian) alone may be
        debug_assert!(
            S == GENERAL || S >= UPWIND || !f.is_nan(),
            "a per-node slowness dispatched with P = false"
        );
        let mut self_dependent = false;
        let candidate = if S == GODUNOV {
            let mut mins = [0.0; D];
            let mask = if arr.coupling.is_empty() {
                0
            } else {
                unsafe { *arr.coupling.get_unchecked(n) }
            };
            if mask == 0 {
                for k in 0..D {
                    mins[k] = fmin(minus[k], plus[k]);
                }
                godunov_update(mins, f)
            } else {
                // An extension-layer neighbour O that reads this node with weight w holds
                // u_O = w u + r. Its stored value was computed from this node's value then, which
                // was at least the current `old`, so r = u_O − w·old over-estimates its rest:
                // the coupled root stays an upper bound of the solution, like every update here.
                let mut coef = [1.0; D];
                for k in 0..D {
                    let side = (plus[k] < minus[k]) as usize;
                    let a = if side == 1 { plus[k] } else { minus[k] };
                    mins[k] = a;
                    if mask >> (2 * k + side) & 1 == 1 {
                        // SAFETY: the mask only marks neighbours in the band
                        let q = nb[k][side] as usize;
                        let w = unsafe { arr.weights.get_unchecked(q)[k] }.abs() as f64;
                        (mins[k], coef[k]) = coupled_axis(a, w, old, inf);
                    }
                }
                godunov_update_coupled(mins, coef, f)
            }
        } else if S == UPWIND {
            let InnerScheme::Upwind(solver) = self.scheme else {
                return None;
            };
            solver.update(n, minus, plus, h, old)
        } else if S == UPWIND_MOVING_MEDIUM {
            // the same solver as through the trait object, inlined (static dispatch)
            let Builtin::MovingMedium(solver) = arr.upwind else {
                return None;
            };
            solver.update(n, minus, plus, h, old)
        } else if S == UPWIND_METRIC {
            let Builtin::Metric(solver) = arr.upwind else {
                return None;
            };
            solver.update(n, minus, plus, h, old)
        } else if S == LXF {
            if self.missing == MissingNeighbour::Extrapolate {
                self_dependent = fill_missing(nb, arr.table.sentinel(), old, inf, f, &mut minus, &mut plus);
            }
            lxf_eikonal_update(minus, plus, f)
        } else {
            let InnerScheme::General(ham) = self.scheme else {
                return None;
            };
            if self.missing == MissingNeighbour::Extrapolate {
                let f = h * ctx.general_slowness;
                self_dependent = fill_missing(nb, arr.table.sentinel(), old, inf, f, &mut minus, &mut plus);
            }
            let p = central_gradient(minus, plus, h);
            lxf_general_update(minus, plus, ham.viscosity(n), ham.value(n, p), h)
        };
        // monotone acceptance: keep the smaller value (Sect. 4, proof of Corollary 1)
        if candidate < old {
            Some(LocalUpdate {
                old,
                new: candidate,
                self_dependent,
            })
        } else {
            None
        }
    }
}

/// What the kernel reads at a node, copied from the problem and the sweep context once per row.
/// The values are written through a raw pointer ([`SharedValues`]); read through the problem and
/// the context, these addresses were loaded again from memory at every node after such a write
/// (seen in the generated row loop), while held in locals they stay in registers: the same bits,
/// 0.97–0.99 of the sweep time (docs/development/performance-history.md, "The kernel's arrays in registers").
#[derive(Clone, Copy)]
pub(super) struct NodeArrays<'k, const D: usize> {
    u: SharedValues<'k>,
    roles: &'k [NodeRole],
    table: NeighbourTable<'k, D>,
    weights: &'k [[f32; D]],
    coupling: &'k [u8],
    active: &'k [AtomicU8],
    cyclic: &'k [u8],
    /// The per-node slowness; empty when it is constant.
    slowness_per_node: &'k [f64],
    /// `h / F`, the right-hand side of the local solvers, when the slowness is constant; NaN
    /// when it is given per node (then only [`Self::h_times_slowness`] with `P = true` is used,
    /// and a general Hamiltonian, which takes its slowness from the Hamiltonian, reads neither).
    h_times_constant_slowness: f64,
    spacing: f64,
    /// The built-in upwind solver when the row loop is specialised for one (`Other` otherwise).
    upwind: Builtin<'k, D>,
}

impl<const D: usize> NodeArrays<'_, D> {
    /// `h / F(x_n)` at node `n` (`P`: the slowness is given per node).
    ///
    /// # Safety
    /// `n` is a node of the band, and `P` is set exactly when the slowness is given per node (as
    /// the `specialised!` dispatch sets it; the per-node slowness has the band's length, checked
    /// in `SweepProblem::check`).
    #[inline(always)]
    unsafe fn h_times_slowness<const P: bool>(&self, n: usize) -> f64 {
        debug_assert!(
            !P || n < self.slowness_per_node.len(),
            "P = true without a per-node slowness"
        );
        if P {
            self.spacing * *self.slowness_per_node.get_unchecked(n)
        } else {
            self.h_times_constant_slowness
        }
    }
}

/// Whether `v` is the numerical infinity `inf`, up to the rounding of an extension update whose
/// upwind neighbours all hold it (its f32 weights sum to 1 only to about 1e-7). Every travel time
/// lies well below `inf` (twice the longest grid path, by default).
#[inline]
pub(super) fn unreached(v: f64, inf: f64) -> bool {
    v >= inf * (1.0 - 1e-6)
}

/// A value change proposed by [`SweepProblem::local_update`].
#[derive(Debug, Clone, Copy)]
pub(super) struct LocalUpdate {
    old: f64,
    new: f64,
    /// The update read the node's own value (Lax–Friedrichs next to an absent neighbour): it
    /// must be revisited even if no neighbour changes.
    self_dependent: bool,
}

impl LocalUpdate {
    #[inline(always)]
    fn change(&self) -> f64 {
        // |new − old| without a branch (the same bits as either subtraction's magnitude)
        (self.new - self.old).abs()
    }
}

/// Replaces the values of absent neighbours by a linear extrapolation through the node,
/// `2 u − u_opposite`, limited to `[u − f, u + f]` with `f = h · s` the largest change a solution
/// of `|∇u| = s` can have over one grid step (without the limit, an opposite neighbour that still
/// holds a value mixed with the numerical infinity extrapolates to a large negative value, which
/// the monotone acceptance would then keep). Where the node itself is still at infinity the
/// opposite value is copied. Returns whether any neighbour was absent (the update then depends on
/// the node's own value).
#[inline(always)]
fn fill_missing<const D: usize>(
    nb: &[[u32; 2]; D],
    sentinel: u32,
    centre: f64,
    inf: f64,
    f: f64,
    minus: &mut [f64; D],
    plus: &mut [f64; D],
) -> bool {
    let mut any = false;
    let extrapolate = |other: f64| -> f64 {
        if centre < inf && other < inf {
            let v = 2.0 * centre - other;
            if v < centre - f {
                centre - f
            } else if v > centre + f {
                centre + f
            } else {
                v
            }
        } else {
            other
        }
    };
    for k in 0..D {
        let m_absent = nb[k][0] == sentinel;
        let p_absent = nb[k][1] == sentinel;
        any |= m_absent | p_absent;
        if m_absent && p_absent {
            minus[k] = centre;
            plus[k] = centre;
        } else if m_absent {
            minus[k] = extrapolate(plus[k]);
        } else if p_absent {
            plus[k] = extrapolate(minus[k]);
        }
    }
    any
}

pub(super) const GODUNOV: u8 = 0;
pub(super) const LXF: u8 = 1;
pub(super) const GENERAL: u8 = 2;
pub(super) const UPWIND: u8 = 3;
/// The built-in upwind solvers, dispatched statically ([`Builtin`]).
pub(super) const UPWIND_MOVING_MEDIUM: u8 = 4;
pub(super) const UPWIND_METRIC: u8 = 5;
