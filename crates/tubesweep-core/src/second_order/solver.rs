//! The second-order sweeps: Gauss–Seidel over the band in the 2^D orientations (the band's row
//! orders, rows walked forwards or backwards), a node skipped while none of the values it reads
//! changed. Phase 1 is the first-order scheme (t = 0) on the corrected, factored equation, made
//! monotone (a value is only replaced by a smaller one), to convergence (here, or on the
//! first-order driver: [`super::start`]); phase 2 the limited BDF2/BDF3 scheme with plain
//! assignment, from phase 1's values (or from the fixed nodes alone when `tol_first` is +∞, the
//! Python package's choice in 3D: the window reaches every node anyway, in 20–30% fewer updates),
//! until the largest change of an iteration is below `tol` (≪ Δx²). The
//! second-order sweeps are not monotone: when the change stops shrinking (no change of the last
//! `stall_window` iterations below `stall_ratio` times the smallest before them:
//! [`super::stagnation::stalled`]), they fall back to accepting decreases only, which ends any
//! limit cycle; a limit cycle whose changes repeat
//! exactly (period of up to 8 iterations, [`super::stagnation`]) is recognised within a few
//! periods instead (the smoothed sphere mask at N = 191 cycled before the margin of
//! `Sweeper::inner`'s side rule: 38 iterations instead of 70), and behind the window opens it at
//! once (a cycle holds the window's edge).
//!
//! In 3D both phases run behind a front window like the first-order driver's
//! ([`crate::sweep::DEFAULT_FRONT_WINDOW`]; see [`run_phase`]): the sweeps leave out the nodes
//! whose value lies beyond a moving edge, so that far nodes are not updated again and again from
//! upwind values that are still changing. On the sphere at N = 201 that cut the updates from 30
//! to 10 million with the same errors (the fixed point is the same up to the stopping tolerance).
//!
//! Tried and not kept: passes in increasing order of the phase-1 values (24 passes instead of 8
//! iterations on the sphere at N = 101, half the updates but scattered in memory, and the
//! safeguard fired when nodes nearer the surface went first); waking only the neighbours above
//! the changed value (2% fewer updates); ∂u₀ by central differences of u₀ instead of its exact
//! value (first order: mean error 6.8e-4 instead of 3.4e-5 on the sphere at N = 201).

use std::sync::atomic::{AtomicU8, Ordering};

use crate::band::{NarrowBand, NeighbourTable};
use crate::error::{Error, Result};
use crate::sweep::sweep_state::{Accumulator, SharedValues};
use crate::sweep::{Control, IterationReport, NodeRole, Slowness};

use super::attempt::Attempts;
use super::factoring::Factoring;
use super::geometry::{NodeGeometry, TubeGeometry};
use super::local::{corrected_slowness_squared, godunov_closed_form, godunov_first_order, reconstruct, Side, Upwind};

/// Stopping rules of the two phases.
#[derive(Debug, Clone, Copy)]
pub struct SecondOrderOptions {
    /// Phase 1 stops when the largest change of an iteration is below this; +∞: no phase 1 (with
    /// `own_first_phase`: the second-order sweeps start from the fixed nodes, behind the window).
    pub tol_first: f64,
    /// Phase 2 stops when the largest change of an iteration is below this.
    pub tol: f64,
    /// Iterations of both phases together.
    pub max_iterations: usize,
    /// The stagnation test (see the module documentation): 0.9 and 20. With BDF3 differences
    /// ([`reconstruct`]) the change of the six-fold star at N = 801–1601 (2D) rests on a plateau
    /// for 10–20 iterations before it falls again: a 10-iteration window took that for a limit
    /// cycle and fell back to decreases only; with 20 it converges (far max 7.8e-6 at N = 1601).
    pub stall_ratio: f64,
    pub stall_window: usize,
    /// Run phase 1 here (Gauss–Seidel sweeps of the factored first-order scheme, the full
    /// anisotropic correction) instead of taking `values` as its result ([`super::start`]).
    pub own_first_phase: bool,
    /// The front window of each phase (0: none; see [`run_phase`]), as a factor c of its width
    /// c·Δx·σ̄·sqrt(H), H the longest grid path from the fixed nodes through the band and σ̄ the
    /// mean slowness (the first-order driver's width, [`crate::sweep::DEFAULT_FRONT_WINDOW`]).
    pub window_first: f64,
    pub window_second: f64,
    /// The extension layer's BDF2 correction is limited where the two neighbours' w differ by
    /// more than this many σΔx (see [`Sweeper::outer`]); +∞: never.
    pub extension_limit: f64,
    /// Threads of the sweeps (0: the default, see [`super::pipeline`]); the same values for any.
    pub threads: usize,
    /// The limiter's length ℓ: the ramp t = clip((u1 − u2)/ε, 0, 1) of [`reconstruct`] has width
    /// ε = σᵢ·Δx²/ℓ, σᵢ the node's slowness, so that t depends on the problem's shape only, not on
    /// its units or its speed's scale (the same problem in metres or millimetres, or with a speed
    /// of 1 or 100, is limited alike). The Python package passes half the grid's longest side.
    pub ramp_length: f64,
}

/// What the solve did.
#[derive(Debug, Clone, Copy, Default)]
pub struct SecondOrderStats {
    pub first_order_iterations: usize,
    pub second_order_iterations: usize,
    pub updates: u64,
    pub converged: bool,
    pub last_change: f64,
    pub seconds: f64,
    /// The phase-2 iteration at which the stagnation safeguard switched to accepting decreases
    /// only (None when it did not fire).
    pub fallback_iteration: Option<usize>,
    /// The largest change of the last `stall_window` iterations before that fallback (of the
    /// cycle, for a limit cycle): about how far from settled the values were when it fired.
    pub fallback_change: Option<f64>,
    /// Non-fixed nodes never reached (another component of the surface, or an extension-layer
    /// node with no upwind neighbour of smaller |φ|).
    pub unreached: usize,
    /// The phase-2 iteration at which the second-order sweeps ran away (a value fell below
    /// [`RUNAWAY_FLOOR`] mean slownesses times Δx: travel times are never negative) and were
    /// abandoned: the values returned are then the first phase's, recomputed from the sources
    /// (first order, monotone). None when they did not.
    pub runaway_iteration: Option<usize>,
    /// Set when the first-order restart after a runaway ran away too (a region far faster than
    /// the sources, where the factored update is not causal): the values are then not a
    /// solution, and the caller needs another scheme (the Python package: the paper's first
    /// order).
    pub restart_failed: bool,
    /// Inner-tube nodes that a runaway left at first order ([`super::demotion`]): the first
    /// attempt ran away (at phase-2 iteration `demoted_runaway_iteration`), and the solve was done
    /// again from the sources with these nodes' update the paper's (unfactored, B = I). 0 when
    /// nothing ran away.
    pub demoted_nodes: usize,
    /// The band index of the node found farthest below the chord from the sources, or falling
    /// most where the restart crept (where the runaway was), when nodes were demoted.
    pub demoted_at: Option<usize>,
    /// The first attempt's phase-2 iteration at which it ran away, when nodes were demoted.
    pub demoted_runaway_iteration: Option<usize>,
}

/// A phase-2 value below `-RUNAWAY_FLOOR·σ̄·Δx` is a runaway: the solution is non-negative and
/// the nodes next to a source are fixed, so no converging iterate comes near it.
pub const RUNAWAY_FLOOR: f64 = 1.0;

#[cfg(test)]
thread_local! {
    /// Tests: every node that is not fixed active at the start of a phase (as before
    /// [`Sweeper::start_flags`]), on this thread's solves.
    pub(crate) static ALL_ACTIVE_START: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// [`Sweeper::visit`]: the node stays active (beyond the window).
pub(super) const KEEP: u8 = 1;
/// [`Sweeper::visit`]: the node woke the nodes that read it.
pub(super) const WOKE: u8 = 2;

/// What one iteration's visits compare against.
#[derive(Clone, Copy)]
pub(super) struct Limits {
    pub(super) second: bool,
    pub(super) decreases_only: bool,
    pub(super) threshold: f64,
    pub(super) window: f64,
    pub(super) settled: f64,
    /// A value changed to below this ends the phase as a runaway (phase 2 only; −∞ otherwise).
    pub(super) floor: f64,
}

impl Limits {
    /// The first phase's: first order, monotone, to `tol`.
    pub(super) fn first_order(tol: f64) -> Self {
        Limits {
            second: false,
            decreases_only: true,
            threshold: tol,
            window: f64::INFINITY,
            settled: tol,
            floor: f64::NEG_INFINITY,
        }
    }
}

pub(super) struct Sweeper<'a, const D: usize> {
    pub(super) table: NeighbourTable<'a, D>,
    pub(super) roles: &'a [NodeRole],
    /// Per node not in the extension layer, in band order (`k` below).
    geometry: &'a [NodeGeometry],
    /// The outward unit directions sgn(φ) n per node, which the extension update follows.
    directions: &'a [[f32; D]],
    pub(super) u0: &'a [f64],
    grad_u0: &'a [[f32; D]],
    /// ∇u₀ = `grad_u0` × this ([`Factoring::grad_u0_unit`]).
    grad_u0_unit: f64,
    slowness: Slowness<'a>,
    abs_phi: &'a [f32],
    spacing: f64,
    /// ℓ/Δx² ([`SecondOrderOptions::ramp_length`]); the ramp's 1/ε is this over σᵢ.
    ramp_scale: f64,
    /// 1/ε for a constant slowness.
    ramp_constant: f64,
    /// 1/σ for a constant slowness.
    inv_sigma_constant: f64,
    /// [`UPWIND_MARGIN`]·ε for a constant slowness.
    margin_constant: f64,
    extension_limit: f64,
    /// [`UNRESOLVED_EXTENSION_FROM`] in `abs_phi`'s units.
    unresolved_extension_from: f32,
    /// More than one source: the BDF2 ramp's kink test is off ([`super::local::Upwind::w0_kink`]).
    several_sources: bool,
    /// Per band node, whether its extension update extends u instead of w ([`super::demotion`]:
    /// where u₀ is not constant along the normals, extending w lowers u by u₀'s step at every
    /// pass); empty: nowhere.
    extends_u: &'a [bool],
}

/// An inner-tube node whose geometry is not resolved and which lies this many grid spacings or
/// more off the surface takes the extension update ([`Sweeper::outer`]: its value from the
/// neighbours nearer the surface along its normal) instead of the paper's first-order update
/// with B = I. That update solves |∇u| = σ on the parallel surface through the node, which is
/// shorter than the surface by the factor 1 − κ|φ| on the concave side: where a layer of such
/// nodes ran around a sphere at |φ| = 1–2Δx (φ = (r − 0.5)³ re-distanced at N = 41, 156 of 5002
/// inner nodes flagged for their curvature) the front cut through it and every distance came out
/// short, 11% at the antipode, reported as second order. Extended instead: max error 0.0105,
/// against 0.0134 for the exact signed distance (`tests/test_order2_node_by_node.py`). Nodes nearer the
/// surface keep the first-order update, so that every part of the surface has solving nodes;
/// B = I errs there by O(κΔx) only.
pub(super) const UNRESOLVED_EXTENSION_FROM: f64 = 1.0;

/// A side of the inner update whose first neighbour lies this many ramp scales ε (σΔx²/ℓ) or
/// more above the node is reconstructed at first order only (see `Sweeper::inner`): more than
/// the O(Δx²∂²u₀) by which a side's first-order value on w differs from u1 where the chord u₀
/// curves by up to about 10/ℓ along an axis.
const UPWIND_MARGIN: f64 = 10.0;

impl<'a, const D: usize> Sweeper<'a, D> {
    /// The sweeps' view of the tube: `geometry` per inner-tube node (the tube's, or with a
    /// runaway's nodes at first order), the factoring, the options' ramp and extension limit;
    /// `extends_u`: the nodes whose extension update extends u ([`super::demotion`]).
    pub(super) fn new(
        band: &'a NarrowBand<D>,
        (geometry, abs_phi): (&'a [NodeGeometry], &'a [f32]),
        (factoring, directions, slowness): (&'a Factoring<D>, &'a [[f32; D]], Slowness<'a>),
        spacing: f64,
        options: &SecondOrderOptions,
        extends_u: &'a [bool],
    ) -> Self {
        let ramp_constant = match slowness {
            Slowness::Constant(s) => options.ramp_length / (spacing * spacing) / s,
            Slowness::PerNode(_) => f64::NAN,
        };
        Sweeper {
            table: band.neighbour_table(),
            roles: &factoring.roles,
            geometry,
            directions,
            u0: &factoring.u0,
            grad_u0: &factoring.grad_u0,
            grad_u0_unit: factoring.grad_u0_unit,
            slowness,
            spacing,
            ramp_scale: options.ramp_length / (spacing * spacing),
            ramp_constant,
            inv_sigma_constant: match slowness {
                Slowness::Constant(s) => 1.0 / s,
                Slowness::PerNode(_) => f64::NAN,
            },
            margin_constant: UPWIND_MARGIN / ramp_constant,
            abs_phi,
            extension_limit: options.extension_limit,
            unresolved_extension_from: (UNRESOLVED_EXTENSION_FROM * spacing
                / super::geometry::power_of_two_near(spacing)) as f32,
            several_sources: factoring.fixed_per_source.len() > 1,
            extends_u,
        }
    }
}

impl<const D: usize> Sweeper<'_, D> {
    #[inline(always)]
    fn sigma(&self, i: usize) -> f64 {
        match self.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(s) => s[i],
        }
    }

    /// The inner-tube update at node `i`: its new w, None when no side is known yet. The sweeps
    /// hold w = u − u₀ (see [`sweep_second_order`]); u = w + u₀ at a neighbour feeds the ramps
    /// and the metric's direction.
    ///
    /// A side is reconstructed at second order ([`reconstruct`]) unless its first neighbour lies
    /// [`UPWIND_MARGIN`] ramp scales ε or more above the node's current value (u1 ≥ uᵢ + 10ε):
    /// such a side is not taken by the Godunov update at a root ≤ uᵢ at first order nor at second,
    /// so skipping its second and third neighbours' reads (about a third of the sides on the
    /// sphere at N = 201) leaves the fixed points alone; only a value on its way up takes it at
    /// first order for one update. The margin is needed because the sweeps hold w = u − u₀: a
    /// side's first-order value is w1 ± Δx∂u₀, which differs from u1 by O(Δx²∂²u₀), so the
    /// update can take a side with u1 slightly above uᵢ. Without it (u1 < uᵢ as the test) the
    /// update jumped with the sign of uᵢ − u1 at a node whose neighbour along an axis nearly
    /// tangent to the front lay within 1e-8 of it: on a smoothed sphere mask at N = 191 and 201
    /// that held a node in a two-state cycle of 5e-7 until the limit-cycle test ended the solve
    /// at 38 and 40 iterations; with it, 29 and 30, and the sphere's, circle's and star's errors
    /// the same to four digits (`benches/experiments/limit_cycles.py`,
    /// `tubesweep reproduce second-order`).
    #[inline(always)]
    fn inner(&self, w: &SharedValues<'_>, i: usize, k_inner: usize, second: bool) -> Option<f64> {
        // SAFETY: `k_inner` counts the nodes before `i` not in the extension layer, fewer than
        // the inner geometries (checked equal to that count)
        let resolved = unsafe { self.geometry.get_unchecked(k_inner) }.first_order() == 0;
        // compiled apart for the two kinds of node, so that a resolved node's update carries no
        // test of the kind (the same arithmetic either way)
        if resolved {
            self.inner_of::<true>(w, i, k_inner, second)
        } else if unsafe { *self.abs_phi.get_unchecked(i) } >= self.unresolved_extension_from {
            // SAFETY above: |φ| has one entry per band node. Off the surface: extended, not
            // solved on a parallel surface of another length ([`UNRESOLVED_EXTENSION_FROM`])
            self.outer(w, i, false)
        } else {
            self.inner_of::<false>(w, i, k_inner, false)
        }
    }

    /// [`Self::inner`] for a node whose geometry is resolved (`RESOLVED`) or not.
    #[inline(always)]
    fn inner_of<const RESOLVED: bool>(
        &self,
        w: &SharedValues<'_>,
        i: usize,
        k_inner: usize,
        second: bool,
    ) -> Option<f64> {
        let table = self.table;
        let sentinel = table.sentinel();
        let h = self.spacing;
        let mut sides = [[Side::MISSING; 2]; D];
        let mut grad = [0.0; D];
        let wi = w.get(i);
        // SAFETY (here and below): `i` is a band node, and so is every neighbour the table gives;
        // u₀ has one value per node
        let u0 = |j: usize| unsafe { *self.u0.get_unchecked(j) };
        let ui = wi + u0(i);
        let sigma = self.sigma(i);
        let (inv_eps, inv_sigma, margin) = match self.slowness {
            Slowness::Constant(_) => (self.ramp_constant, self.inv_sigma_constant, self.margin_constant),
            Slowness::PerNode(_) => {
                let inv_eps = self.ramp_scale / sigma;
                (inv_eps, 1.0 / sigma, UPWIND_MARGIN / inv_eps)
            }
        };
        // the sides whose first neighbour lies this high or higher are taken at first order
        let skip_from = ui + margin;
        // SAFETY: `k_inner` counts the nodes before `i` not in the extension layer, fewer than
        // the inner geometries and ∇u₀'s (checked equal to that count)
        let (geometry, grad_u0) = unsafe {
            (
                self.geometry.get_unchecked(k_inner),
                self.grad_u0.get_unchecked(k_inner),
            )
        };
        // a node whose geometry is not resolved runs the paper's first-order update (B = I
        // there), on u itself: its ∂u₀ came from differences of φ across the crease, the corner
        // or the rim that made it unresolved (O(1/Δx) there: on two spheres joined by `min` the
        // factored update fell by 1.6Δx every sweep), so the sides read u₀ at the neighbours
        let resolved = RESOLVED;
        for k in 0..D {
            let du0 = if resolved {
                grad_u0[k] as f64 * self.grad_u0_unit
            } else {
                0.0
            };
            let mut near = [f64::NAN; 2];
            for side in 0..2 {
                let j1 = unsafe { table.neighbour_unchecked(i, k, side) };
                if j1 == sentinel {
                    continue;
                }
                let j1 = j1 as usize;
                let w1 = w.get(j1);
                if !w1.is_finite() {
                    continue;
                }
                let u1 = w1 + u0(j1);
                // unresolved: w at the neighbour as seen from this node's u₀, u1 − u₀(i)
                let w1 = if resolved { w1 } else { u1 - u0(i) };
                near[side] = u1;
                let mut up = Upwind {
                    w1,
                    w2: f64::NAN,
                    w3: f64::NAN,
                    w0: wi,
                    d1: f64::NAN,
                    d2: f64::NAN,
                    w0_kink: if self.several_sources { f64::NAN } else { wi },
                };
                let upwind = second && u1 < skip_from;
                if upwind {
                    let j2 = unsafe { table.neighbour_unchecked(j1, k, side) };
                    if j2 != sentinel {
                        let j2 = j2 as usize;
                        up.w2 = w.get(j2);
                        let u2 = up.w2 + u0(j2);
                        up.d1 = u1 - u2;
                        // the third neighbour only where the BDF3 ramp can open: an upwind run
                        // (u2 < u1), the node reached (the kink test needs its value)
                        if u1 > u2 && ui.is_finite() {
                            let j3 = unsafe { table.neighbour_unchecked(j2, k, side) };
                            if j3 != sentinel {
                                let j3 = j3 as usize;
                                up.w3 = w.get(j3);
                                up.d2 = u2 - (up.w3 + u0(j3));
                            }
                        }
                    }
                }
                sides[k][side] = reconstruct(&up, du0, h, inv_eps, side == 0, upwind);
            }
            // the direction of ∇u for the metric: central differences, one-sided at a gap
            grad[k] = match (near[0].is_finite(), near[1].is_finite()) {
                (true, true) => (near[1] - near[0]) / (2.0 * h),
                (true, false) if ui.is_finite() => (ui - near[0]) / h,
                (false, true) if ui.is_finite() => (near[1] - ui) / h,
                _ => 0.0,
            };
        }
        let (num, den) = corrected_slowness_squared::<D>(geometry, grad, sigma, inv_sigma);
        if second {
            godunov_closed_form(&sides, num * (h * h), den)
        } else {
            godunov_first_order(&sides, (num / den).sqrt() * h)
        }
    }

    /// The extension update at layer node `i`: per axis along which the outward direction
    /// sgn(φ) n has a component, the neighbour towards the surface, used only if it is in the band
    /// and has strictly smaller |φ| (so that no two layer nodes wait on each other); BDF2
    /// (weight 1.5|n_k|) when the next one along is there too, else first order (|n_k|).
    /// +∞ while a used neighbour is not reached, None when no neighbour qualifies. Like
    /// [`Self::inner`], on w and returning the new w.
    ///
    /// The BDF2 correction is limited like the inner sides' (`reconstruct`): with δ = w₁ − w₂ and
    /// L = `extension_limit`·σΔx, t = clip(2 − |δ|/L, 0, 1) ramps from BDF2 (t = 1, |δ| ≤ L) to
    /// first order (t = 0, |δ| ≥ 2L): weight (1 + t/2)|n_k| on w₁ + (t/2)(2w₁ − w₂). On a
    /// resolved solution |∂_k w| ≤ |∇u| + |∇u₀| ≈ 2σ, so the default L = 2σΔx leaves BDF2 alone
    /// there; what it cuts is an iterate far from smooth, from which the unlimited extrapolation
    /// (4w₁ − w₂)/3 (gain 5/3), read back by the inner nodes' distance-2 stencils, ran away:
    /// the sphere at N = 101 from a first phase stopped at 64Δx² went to −1e11.
    #[inline(always)]
    fn outer(&self, w: &SharedValues<'_>, i: usize, second: bool) -> Option<f64> {
        // compiled apart for the nodes that extend u ([`super::demotion`]; none unless a runaway
        // was found), so that the others' update carries no test of the kind
        if !self.extends_u.is_empty() && self.extends_u[i] {
            self.outer_of::<true>(w, i, second)
        } else {
            self.outer_of::<false>(w, i, second)
        }
    }

    /// [`Self::outer`] on w, or with `ON_U` on u less u₀ at this node.
    #[inline(always)]
    fn outer_of<const ON_U: bool>(&self, w: &SharedValues<'_>, i: usize, second: bool) -> Option<f64> {
        let table = self.table;
        let sentinel = table.sentinel();
        // SAFETY (here and below): `i` is a band node, and so is every neighbour the table gives;
        // the directions and |φ| have one entry per node (checked)
        let abs_phi_of = |j: usize| unsafe { *self.abs_phi.get_unchecked(j) };
        let direction = unsafe { self.directions.get_unchecked(i) };
        let abs_phi = abs_phi_of(i);
        // w at a neighbour, or u there less u₀ here where this node extends u
        let value = |j: usize| {
            let w = w.get(j);
            if ON_U {
                // SAFETY: `j` and `i` are band nodes, and u₀ has one value per node
                w + unsafe { *self.u0.get_unchecked(j) - *self.u0.get_unchecked(i) }
            } else {
                w
            }
        };
        let limit = self.extension_limit * self.sigma(i) * self.spacing;
        let (mut num, mut den) = (0.0, 0.0);
        for k in 0..D {
            let nk = direction[k];
            if nk == 0.0 {
                continue;
            }
            // outward along +e_k: the upwind neighbour is at −e_k
            let side = if nk > 0.0 { 0 } else { 1 };
            let j1 = unsafe { table.neighbour_unchecked(i, k, side) };
            if j1 == sentinel {
                continue;
            }
            let j1 = j1 as usize;
            let phi1 = abs_phi_of(j1);
            if !(phi1 < abs_phi) {
                continue;
            }
            let w1 = value(j1);
            if !w1.is_finite() {
                // not reached: nor is this node (+∞, which a start's carried value gives way to)
                return Some(f64::INFINITY);
            }
            let weight = nk.abs() as f64;
            if second {
                let j2 = unsafe { table.neighbour_unchecked(j1, k, side) };
                if j2 != sentinel {
                    let j2 = j2 as usize;
                    let w2 = value(j2);
                    if w2.is_finite() && abs_phi_of(j2) < phi1 {
                        let t = (2.0 - (w1 - w2).abs() / limit).clamp(0.0, 1.0);
                        if t >= 1.0 {
                            num += 1.5 * weight * (4.0 * w1 - w2) / 3.0;
                            den += 1.5 * weight;
                            continue;
                        }
                        if t > 0.0 {
                            let half = 0.5 * t;
                            num += weight * (w1 + half * (2.0 * w1 - w2));
                            den += weight * (1.0 + half);
                            continue;
                        }
                    }
                }
            }
            num += weight * w1;
            den += weight;
        }
        if den > 0.0 {
            Some(num / den)
        } else {
            None
        }
    }

    /// u = u₀ + w at node `i` (the window, the front and the rows' lower bounds are in u).
    #[inline(always)]
    pub(super) fn u_at(&self, w: &SharedValues<'_>, i: usize) -> f64 {
        // SAFETY: `i` is a band node, and u₀ has one value per node
        w.get(i) + unsafe { *self.u0.get_unchecked(i) }
    }

    /// Updates node `i` if it is active and its value lies within the window; records the change.
    /// `w` holds w = u − u₀; the window, `waiting` and `front` are in u. `role`: node `i`'s (the
    /// row walk has it at hand).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn visit(
        &self,
        w: &SharedValues<'_>,
        active: &[AtomicU8],
        i: usize,
        role: NodeRole,
        k_inner: usize,
        lim: Limits,
        change: &mut Accumulator,
    ) -> u8 {
        if active[i].load(Ordering::Relaxed) == 0 {
            return 0;
        }
        let old = w.get(i);
        // SAFETY: u₀ has one value per node
        let u0 = unsafe { *self.u0.get_unchecked(i) };
        if old + u0 > lim.window && old.is_finite() {
            // beyond the window: stays active for a later iteration
            change.waiting = change.waiting.min(old + u0);
            return KEEP;
        }
        active[i].store(0, Ordering::Relaxed);
        let new = match role {
            NodeRole::Fixed => return 0,
            NodeRole::Inner => self.inner(w, i, k_inner, lim.second),
            NodeRole::Outer => self.outer(w, i, lim.second),
        };
        change.updates += 1;
        let Some(new) = new else { return 0 };
        if new == old || (lim.decreases_only && !(new < old)) || new.is_nan() {
            return 0;
        }
        if new == f64::INFINITY {
            // an extension node whose upwind neighbour is not reached holds +∞ in a cold solve
            // (its values only fall); a warm start's carried value there goes back to +∞ too, or
            // it stayed finite where nothing supports it (two spheres moving apart: 24 nodes
            // between them kept 0.62–0.77 where a cold solve leaves them unreached)
            w.set(i, new);
            change.max_change = f64::INFINITY;
            self.activate(active, i);
            return WOKE;
        }
        if new + u0 > lim.window && !old.is_finite() {
            // reached, but beyond the window: not taken yet
            active[i].store(1, Ordering::Relaxed);
            change.waiting = change.waiting.min(new + u0);
            return KEEP;
        }
        w.set(i, new);
        let c = if old.is_finite() {
            (new - old).abs()
        } else {
            f64::INFINITY
        };
        change.max_change = change.max_change.max(c);
        if c > lim.settled && new + u0 < change.front {
            change.front = new + u0;
        }
        if c > lim.threshold {
            self.activate(active, i);
            return WOKE;
        }
        0
    }
}

/// Runs both phases on `values` (fixed nodes hold their values, the others +∞ or a start).
#[allow(clippy::too_many_arguments)]
pub fn sweep_second_order<const D: usize>(
    band: &NarrowBand<D>,
    geometry: &TubeGeometry,
    factoring: &Factoring<D>,
    directions: &[[f32; D]],
    slowness: Slowness<'_>,
    spacing: f64,
    values: &mut [f64],
    options: &SecondOrderOptions,
    control: &mut dyn FnMut(&IterationReport) -> Control,
) -> Result<SecondOrderStats> {
    let sw = (band, geometry, factoring, directions, slowness);
    Ok(sweep_second_order_reporting(sw, spacing, values, options, control)?.0)
}

/// [`sweep_second_order`], and the band positions of the inner-tube nodes that a runaway left at
/// first order ([`super::demotion`]; empty when nothing ran away).
#[allow(clippy::type_complexity)]
pub fn sweep_second_order_reporting<const D: usize>(
    (band, geometry, factoring, directions, slowness): (
        &NarrowBand<D>,
        &TubeGeometry,
        &Factoring<D>,
        &[[f32; D]],
        Slowness<'_>,
    ),
    spacing: f64,
    values: &mut [f64],
    options: &SecondOrderOptions,
    control: &mut dyn FnMut(&IterationReport) -> Control,
) -> Result<(SecondOrderStats, Vec<u32>)> {
    let sw = (geometry, factoring, directions, slowness);
    let mut demoted = Vec::new();
    let stats = sweep_second_order_from(band, sw, spacing, values, options, None, control, Some(&mut demoted))?;
    Ok((stats, demoted))
}

/// [`sweep_second_order`] whose first phase starts from the nodes `changed` marks and the nodes
/// that read them (a warm start on a surface that moved in part, [`super::warm::sweep_warm`]):
/// the others hold a fixed point of their unchanged update, and the window starts at the
/// smallest value among the active nodes instead of at the fixed nodes.
///
/// `demoted`: where the sweeps run away, the solve is done again from the sources with the
/// runaway's nodes at first order ([`super::demotion`]), and the band positions of the inner-tube
/// nodes so demoted go here; None: a runaway's values are the first-order restart's (a warm
/// start, which starts again cold instead).
#[allow(clippy::too_many_arguments)]
pub(super) fn sweep_second_order_from<const D: usize>(
    band: &NarrowBand<D>,
    (geometry, factoring, directions, slowness): (&TubeGeometry, &Factoring<D>, &[[f32; D]], Slowness<'_>),
    spacing: f64,
    values: &mut [f64],
    options: &SecondOrderOptions,
    changed: Option<&[bool]>,
    control: &mut dyn FnMut(&IterationReport) -> Control,
    demoted: Option<&mut Vec<u32>>,
) -> Result<SecondOrderStats> {
    let n = band.len();
    let abs_phi = &geometry.abs_phi[..];
    let n_inner = factoring.roles.iter().filter(|&&r| r != NodeRole::Outer).count();
    if values.len() != n
        || abs_phi.len() != n
        || factoring.u0.len() != n
        || directions.len() != n
        || geometry.nodes.len() != n_inner
        || factoring.grad_u0.len() != n_inner
    {
        return Err(Error::invalid(
            "values",
            format!("one value per band node ({n}) is needed"),
        ));
    }
    if !(options.ramp_length.is_finite() && options.ramp_length > 0.0) {
        return Err(Error::invalid("ramp_length", "must be finite and positive"));
    }
    if let Slowness::PerNode(s) = slowness {
        if s.len() != n {
            return Err(Error::invalid(
                "speed",
                format!("one slowness per band node ({n}) is needed"),
            ));
        }
    }
    if changed.is_some_and(|c| c.len() != n) {
        return Err(Error::invalid(
            "changed",
            format!("one flag per band node ({n}) is needed"),
        ));
    }
    let run = Attempts {
        band,
        tube: (&geometry.nodes[..], abs_phi),
        sw: (factoring, directions, slowness),
        spacing,
        options,
    };
    let Some(demoted) = demoted else {
        return run.run(None, values, options, changed, control, (&[], None));
    };
    super::demotion::solve_demoting(&run, values, changed, control, demoted)
}
