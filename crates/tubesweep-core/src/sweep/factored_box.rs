//! Second-order fast sweeping in the whole box: the factored eikonal equation `|∇u| = s(x)`
//! with the limited second-order Godunov update ([`crate::scheme::limited_godunov`]), the box's
//! counterpart of the paper's Algorithm 1 (Sect. 2) at `order = 2`.
//!
//! **Factoring.** Every node is assigned the source `j` that minimises `sⱼ |x − xⱼ|` (`sⱼ` the
//! slowness at the source) and written `u = u₀ + w` with `u₀ = sⱼ |x − xⱼ|`, which removes the
//! source's cone singularity from `w` (without it the order falls to about 1). Each local update
//! factors its neighbours by the *node's* source, so the one-sided differences stay consistent
//! where neighbouring nodes belong to different sources. Nodes near a source are fixed by the
//! caller (the exact local travel time).
//!
//! **Iteration** (design note, Sect. 2). Phase 1: the first-order update (`t = 0`), monotone
//! (a node keeps the smaller of its old and new value), in the 2^d alternating sweep orders, until
//! the largest change in an iteration is below `tol`. Phase 2: the limited second-order update with
//! plain assignment, from the phase-1 values, until the change is below `tol` (which should be
//! ≪ Δx²). The second-order update is not monotone: if the change stops shrinking (it exceeds
//! `stagnation_ratio` times the change `stagnation_window` iterations earlier), the sweeps go on
//! accepting decreases only, which ends any limit cycle; [`FactoredStats::safeguard_iteration`]
//! records it.
//!
//! **Runaway guard.** The factored first-order update is not causal everywhere: where the local
//! slowness is far below the source's (a fast region next to a source in a slow one, contrasts of
//! about 30× in 3D and 100× in 2D), the factor's curvature term `sⱼΔx²/r` outweighs the local
//! `sΔx`, two neighbours each lower the other, and the monotone phase 1 (or phase 2) falls without
//! bound. Travel times are never negative, so a value below [`RUNAWAY_FLOOR`]`·s_min·Δx` ends the
//! factored solve, and so does a monotone iteration (phase 1, or phase 2 after the safeguard)
//! whose change stops shrinking ([`DRIFT_WINDOW`], [`DRIFT_RATIO`]: a slow fall, long before it
//! reaches the floor): the sweeps start again from the fixed nodes with the plain first-order
//! update (no factor: the paper's Eq. (3), monotone and causal, so it converges) and its values
//! are returned; [`FactoredStats::runaway_iteration`] records it.
//!
//! **Parallel sweeps, same bits.** A sweep visits the grid's rows (the last axis) in the order of
//! the sweep's orientation. A node reads only its axis neighbours at distances 1 and 2, so in 3D
//! the rows whose first two oriented indices have the same sum read none of each other and are
//! updated in parallel, level after level; each node then reads exactly what the sequential
//! lexicographic sweep would give it, and the result does not depend on the number of threads.

use crate::error::{Error, Result};
use crate::scheme::godunov::godunov_update;
use crate::scheme::limited_godunov::{limited_root_from, ramp, Side};
use crate::sweep::{Control, IterationReport, Slowness};
use rayon::prelude::*;
use std::time::Instant;

/// A point-source problem in the whole box `lower + h·[0, shape)`.
pub struct FactoredBox<'a, const D: usize> {
    pub shape: [usize; D],
    pub lower: [f64; D],
    pub h: f64,
    /// The slowness `1/F`, constant or one per node (C order).
    pub slowness: Slowness<'a>,
    /// The source points and the slowness at each.
    pub sources: &'a [[f64; D]],
    pub source_slowness: &'a [f64],
    /// Nodes held at given values (the exact local travel time near the sources).
    pub fixed_nodes: &'a [usize],
    pub fixed_values: &'a [f64],
}

/// How [`FactoredBox::solve`] iterates.
#[derive(Clone, Debug)]
pub struct FactoredOptions {
    /// Stop a phase when the largest change in one iteration (2^d sweeps) is below this.
    pub tol: f64,
    /// Iterations of both phases together.
    pub max_iterations: usize,
    /// Run phase 2 (the second-order update); `false` stops after the first-order phase 1.
    pub second_order: bool,
    /// The ramp's width is `ε = s·Δx² / ramp_length` (a length, e.g. the box's largest extent),
    /// so that `t` does not depend on the units of length or time.
    pub ramp_length: f64,
    pub stagnation_window: usize,
    pub stagnation_ratio: f64,
    /// Worker threads (0: rayon's default pool, 1: sequential). The result does not depend on it.
    pub threads: usize,
    /// 3D levels with fewer nodes than this run on one thread (a level is too small to share).
    pub parallel_min_nodes: usize,
    /// A node is updated again only when a value of its stencil (the neighbours at distances 1
    /// and 2) changed by more than this since its last update, in the current phase; 0 skips
    /// only exact repeats (the same bits as updating every node).
    pub activation_threshold: f64,
}

impl Default for FactoredOptions {
    fn default() -> Self {
        FactoredOptions {
            tol: 1e-9,
            max_iterations: 1000,
            second_order: true,
            ramp_length: 1.0,
            stagnation_window: 10,
            stagnation_ratio: 0.9,
            threads: 0,
            parallel_min_nodes: 4096,
            activation_threshold: 0.0,
        }
    }
}

/// What [`FactoredBox::solve`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FactoredStats {
    /// Iterations of both phases (each 2^d sweeps).
    pub iterations: usize,
    pub first_order_iterations: usize,
    pub second_order_iterations: usize,
    pub sweeps: usize,
    pub updates: u64,
    pub converged: bool,
    /// Largest change of any value during the last iteration.
    pub last_change: f64,
    /// The iteration after which phase 2 fell back to accepting decreases only (the stagnation
    /// safeguard), if it did.
    pub safeguard_iteration: Option<usize>,
    /// The largest change of the `stagnation_window` + 1 iterations that made it fire: about how
    /// far from settled the values were.
    pub safeguard_change: Option<f64>,
    /// The iteration (phases 1 and 2 counted together) after which a value fell below
    /// [`RUNAWAY_FLOOR`]`·s_min·Δx`, or the monotone sweeps drifted ([`DRIFT_WINDOW`]), and the
    /// factored sweeps were abandoned for the plain first-order ones (the module's note); None
    /// when they were not.
    pub runaway_iteration: Option<usize>,
    /// Iterations of the plain first-order sweeps after a runaway (0 without one).
    pub plain_iterations: usize,
    pub seconds: f64,
}

/// A value below `-RUNAWAY_FLOOR·s_min·Δx` (`s_min` the smallest slowness) is a runaway: travel
/// times are never negative, and the nodes next to a source are fixed at positive values, so no
/// converging iterate comes near it.
pub const RUNAWAY_FLOOR: f64 = 1.0;

/// The monotone sweeps (phase 1, or phase 2 after the stagnation safeguard) drift, which is a
/// runaway too, when an iteration's change exceeds `DRIFT_RATIO` times that of `DRIFT_WINDOW`
/// iterations earlier (both finite and at least `tol`): a monotone causal iteration's changes
/// shrink, a drift's stay (a cycle of nodes lowering each other loses the same amount every
/// iteration, slower than the floor can catch: 1.5e-4 per iteration at 81² with a 50× contrast).
pub const DRIFT_WINDOW: usize = 10;
pub const DRIFT_RATIO: f64 = 0.9;

/// What a row, a sweep or an iteration did: the largest change, the number of updates and the
/// smallest value it changed a node to.
#[derive(Clone, Copy)]
struct Outcome {
    change: f64,
    updates: u64,
    lowest: f64,
}

impl Outcome {
    const NONE: Outcome = Outcome {
        change: 0.0,
        updates: 0,
        lowest: f64::INFINITY,
    };
    #[inline(always)]
    fn and(self, o: Outcome) -> Outcome {
        Outcome {
            change: self.change.max(o.change),
            updates: self.updates + o.updates,
            lowest: self.lowest.min(o.lowest),
        }
    }
}

/// The node values, written by one row's worker and read by the others (see the module's note
/// on parallel sweeps: no two workers touch a value one of them writes in the same level).
#[derive(Clone, Copy)]
struct Shared {
    ptr: *mut f64,
    len: usize,
}
unsafe impl Sync for Shared {}
unsafe impl Send for Shared {}
impl Shared {
    #[inline(always)]
    fn get(&self, i: usize) -> f64 {
        debug_assert!(i < self.len);
        unsafe { *self.ptr.add(i) }
    }
    #[inline(always)]
    fn set(&self, i: usize, v: f64) {
        debug_assert!(i < self.len);
        unsafe { *self.ptr.add(i) = v }
    }
}

/// The per-node sweep stamps (the sweep that last updated a node, the last that changed it),
/// written like the values: each by the worker of its node's row only.
#[derive(Clone, Copy)]
struct Stamps {
    visited: *mut u32,
    changed: *mut u32,
}
unsafe impl Sync for Stamps {}
unsafe impl Send for Stamps {}

/// One sweep: its index (from 1), the first sweep of the current phase, and the update used.
#[derive(Clone, Copy)]
struct Sweep {
    index: u32,
    phase_start: u32,
    second: bool,
    monotone: bool,
}

/// The per-node data the sweeps read.
struct Sweeper<'p, 'a, const D: usize> {
    p: &'p FactoredBox<'a, D>,
    stride: [usize; D],
    u0: Vec<f64>,
    source_of: Vec<u32>,
    fixed: Vec<bool>,
    ramp_length: f64,
    parallel_min_nodes: usize,
    activation_threshold: f64,
    /// `false` after a runaway: `u₀ = 0` and no factor gradient (the plain Eq. (3)).
    factored: bool,
}

impl<'a, const D: usize> FactoredBox<'a, D> {
    fn len(&self) -> usize {
        self.shape.iter().product()
    }

    fn check(&self, options: &FactoredOptions) -> Result<()> {
        if !(D == 2 || D == 3) {
            return Err(Error::invalid("grid", "the factored box solver runs in 2D and 3D"));
        }
        if self.shape.iter().any(|&n| n < 3) {
            return Err(Error::invalid("grid", "needs at least 3 nodes per axis"));
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(Error::invalid("grid", "the spacing must be finite and positive"));
        }
        let n = self.len();
        match self.slowness {
            Slowness::Constant(s) if !(s.is_finite() && s > 0.0) => {
                return Err(Error::invalid("speed", "must be finite and positive"))
            }
            Slowness::PerNode(v) if v.len() != n => {
                return Err(Error::invalid(
                    "speed",
                    format!("needs one value per node ({n}), got {}", v.len()),
                ))
            }
            Slowness::PerNode(v) if v.iter().any(|s| !(s.is_finite() && *s > 0.0)) => {
                return Err(Error::invalid("speed", "must be finite and positive at every node"))
            }
            _ => {}
        }
        if self.sources.is_empty() || self.sources.len() != self.source_slowness.len() {
            return Err(Error::invalid(
                "sources",
                "needs at least one source, and one slowness per source",
            ));
        }
        if self.sources.len() > u32::MAX as usize {
            return Err(Error::invalid("sources", "too many sources"));
        }
        if self.sources.iter().flatten().any(|c| !c.is_finite())
            || self.source_slowness.iter().any(|s| !(s.is_finite() && *s > 0.0))
        {
            return Err(Error::invalid(
                "sources",
                "source points and their slowness must be finite (slowness > 0)",
            ));
        }
        if options.max_iterations.saturating_mul(1 << D) >= u32::MAX as usize {
            return Err(Error::invalid("max_iterations", "too large"));
        }
        if !(options.activation_threshold >= 0.0) {
            return Err(Error::invalid("activation_threshold", "must be ≥ 0"));
        }
        if self.fixed_nodes.len() != self.fixed_values.len() || self.fixed_nodes.iter().any(|&i| i >= n) {
            return Err(Error::invalid(
                "fixed_nodes",
                "one value per fixed node, each a node of the box",
            ));
        }
        if self.fixed_values.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid("fixed_values", "must be finite"));
        }
        if !(options.tol.is_finite() && options.tol > 0.0) {
            return Err(Error::invalid("tol", "must be finite and positive"));
        }
        if !(options.ramp_length.is_finite() && options.ramp_length > 0.0) {
            return Err(Error::invalid("ramp_length", "must be finite and positive"));
        }
        if options.stagnation_window == 0 || !(options.stagnation_ratio > 0.0) {
            return Err(Error::invalid(
                "stagnation_window",
                "the window must be ≥ 1 and the ratio > 0",
            ));
        }
        Ok(())
    }

    /// The factor `u₀` and the source index of every node (the source minimising `sⱼ|x − xⱼ|`).
    pub fn factor(&self) -> (Vec<f64>, Vec<u32>) {
        let n = self.len();
        let last = self.shape[D - 1];
        let mut u0 = vec![0.0; n];
        let mut src = vec![0u32; n];
        u0.par_chunks_mut(last)
            .zip(src.par_chunks_mut(last))
            .enumerate()
            .for_each(|(row, (u0r, srcr))| {
                let mut idx = [0usize; D];
                let mut r = row;
                for k in (0..D - 1).rev() {
                    idx[k] = r % self.shape[k];
                    r /= self.shape[k];
                }
                for c in 0..last {
                    idx[D - 1] = c;
                    let x: [f64; D] = std::array::from_fn(|k| self.lower[k] + self.h * idx[k] as f64);
                    let (mut best, mut which) = (f64::INFINITY, 0u32);
                    for (j, (xs, ss)) in self.sources.iter().zip(self.source_slowness).enumerate() {
                        let d = ss * dist(&x, xs);
                        if d < best {
                            best = d;
                            which = j as u32;
                        }
                    }
                    u0r[c] = best;
                    srcr[c] = which;
                }
            });
        (u0, src)
    }

    /// Solves; returns the values (C order) and what the solve did. `progress` is called after
    /// every iteration; [`Control::Stop`] ends the solve with [`Error::Interrupted`].
    pub fn solve(
        &self,
        options: &FactoredOptions,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
    ) -> Result<(Vec<f64>, FactoredStats)> {
        self.check(options)?;
        let start = Instant::now();
        let (u0, source_of) = self.factor();
        let n = self.len();
        let mut fixed = vec![false; n];
        let mut u = vec![f64::INFINITY; n];
        for (&i, &v) in self.fixed_nodes.iter().zip(self.fixed_values) {
            fixed[i] = true;
            u[i] = u[i].min(v);
        }
        let mut stride = [1usize; D];
        for k in (0..D - 1).rev() {
            stride[k] = stride[k + 1] * self.shape[k + 1];
        }
        let mut sw = Sweeper {
            p: self,
            stride,
            u0,
            source_of,
            fixed,
            ramp_length: options.ramp_length,
            parallel_min_nodes: options.parallel_min_nodes,
            activation_threshold: options.activation_threshold,
            factored: true,
        };
        let min_slowness = match self.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(v) => v.iter().copied().fold(f64::INFINITY, f64::min),
        };
        let floor = -RUNAWAY_FLOOR * min_slowness * self.h;
        let pool = if options.threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(options.threads)
                    .build()
                    .map_err(|e| Error::invalid("threads", e.to_string()))?,
            )
        } else {
            None
        };
        let parallel = options.threads != 1;
        let mut stats = FactoredStats::default();
        let mut second = false;
        let mut monotone = true;
        let mut history: Vec<f64> = Vec::new();
        // the finite changes of the current monotone mode's iterations
        let mut drift: Vec<f64> = Vec::new();
        let shared = Shared {
            ptr: u.as_mut_ptr(),
            len: u.len(),
        };
        // per node: the sweep that last updated it, and the last that changed it by more than the
        // activation threshold (sweeps counted from 1 over the whole solve)
        let mut visited = vec![0u32; n];
        let mut changed = vec![0u32; n];
        let stamps = Stamps {
            visited: visited.as_mut_ptr(),
            changed: changed.as_mut_ptr(),
        };
        // the first sweep of the current phase (or mode): every node is updated in it
        let mut phase_start = 1u32;
        while stats.iterations < options.max_iterations {
            let mut out = Outcome::NONE;
            for orientation in 0..(1usize << D) {
                let sweep = Sweep {
                    index: stats.sweeps as u32 + 1 + orientation as u32,
                    phase_start,
                    second,
                    monotone,
                };
                let run = || sw.sweep(shared, stamps, orientation, sweep, parallel);
                out = out.and(match &pool {
                    Some(pool) => pool.install(run),
                    None => run(),
                });
            }
            let (change, updates) = (out.change, out.updates);
            stats.iterations += 1;
            stats.sweeps += 1 << D;
            stats.updates += updates;
            stats.last_change = change;
            if !sw.factored {
                stats.plain_iterations += 1;
            } else if second {
                stats.second_order_iterations += 1;
            } else {
                stats.first_order_iterations += 1;
            }
            if progress(&IterationReport {
                iteration: stats.iterations,
                max_change: change,
                updates,
            }) == Control::Stop
            {
                return Err(Error::Interrupted {
                    iterations: stats.iterations,
                });
            }
            // the monotone sweeps (phase 1, or phase 2 after the safeguard) converge unless they
            // drift: a change that stops shrinking there is a runaway too
            let drifting = monotone
                && change.is_finite()
                && change >= options.tol
                && drift.len() >= DRIFT_WINDOW
                && change > DRIFT_RATIO * drift[drift.len() - DRIFT_WINDOW];
            if monotone && change.is_finite() {
                drift.push(change);
            }
            if sw.factored && (out.lowest < floor || drifting) {
                // a runaway: the plain first-order sweeps from the fixed nodes again
                stats.runaway_iteration = Some(stats.iterations);
                drift.clear();
                sw.factored = false;
                sw.u0.iter_mut().for_each(|v| *v = 0.0);
                for (i, f) in sw.fixed.iter().enumerate() {
                    if !f {
                        shared.set(i, f64::INFINITY);
                    }
                }
                second = false;
                monotone = true;
                phase_start = stats.sweeps as u32 + 1;
                continue;
            }
            if !second {
                if change < options.tol {
                    if !options.second_order || !sw.factored {
                        stats.converged = true;
                        break;
                    }
                    second = true;
                    monotone = false;
                    drift.clear();
                    phase_start = stats.sweeps as u32 + 1;
                }
                continue;
            }
            if change < options.tol {
                stats.converged = true;
                break;
            }
            history.push(change);
            let w = options.stagnation_window;
            if !monotone && history.len() > w && change > options.stagnation_ratio * history[history.len() - 1 - w] {
                monotone = true;
                drift.clear();
                phase_start = stats.sweeps as u32 + 1;
                stats.safeguard_iteration = Some(stats.iterations);
                stats.safeguard_change = Some(history[history.len() - 1 - w..].iter().copied().fold(0.0, f64::max));
            }
        }
        stats.seconds = start.elapsed().as_secs_f64();
        Ok((u, stats))
    }
}

#[inline(always)]
fn dist<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        let d = a[k] - b[k];
        s += d * d;
    }
    s.sqrt()
}

impl<const D: usize> Sweeper<'_, '_, D> {
    /// One sweep in the orientation whose bit `k` reverses axis `k`; the largest change and the
    /// number of updates.
    fn sweep(&self, u: Shared, stamps: Stamps, orientation: usize, sweep: Sweep, parallel: bool) -> Outcome {
        let shape = self.p.shape;
        let oriented = |k: usize, c: usize| if orientation >> k & 1 == 1 { shape[k] - 1 - c } else { c };
        if D == 2 {
            let mut out = Outcome::NONE;
            for c0 in 0..shape[0] {
                let mut prefix = [0usize; D];
                prefix[0] = oriented(0, c0);
                out = out.and(self.row(u, stamps, prefix, orientation, sweep));
            }
            return out;
        }
        // D == 3: levels of c0 + c1, the rows of a level in parallel
        let (n0, n1) = (shape[0], shape[1]);
        let mut out = Outcome::NONE;
        for level in 0..(n0 + n1 - 1) {
            let lo = level.saturating_sub(n1 - 1);
            let hi = level.min(n0 - 1);
            let one = |c0: usize| {
                let c1 = level - c0;
                let mut prefix = [0usize; D];
                prefix[0] = oriented(0, c0);
                prefix[1] = oriented(1, c1);
                self.row(u, stamps, prefix, orientation, sweep)
            };
            let r = if parallel && hi > lo && shape[2] * (hi - lo + 1) >= self.parallel_min_nodes {
                (lo..=hi)
                    .into_par_iter()
                    .map(one)
                    .reduce(|| Outcome::NONE, Outcome::and)
            } else {
                (lo..=hi).map(one).fold(Outcome::NONE, Outcome::and)
            };
            out = out.and(r);
        }
        out
    }

    /// Whether a value of node `n`'s stencil changed (beyond the activation threshold) at or
    /// after its last update in this phase.
    #[inline(always)]
    fn stale(&self, stamps: Stamps, n: usize, idx: [usize; D], sweep: Sweep) -> bool {
        let visited = unsafe { *stamps.visited.add(n) };
        if visited < sweep.phase_start {
            return true;
        }
        let changed = |m: usize| unsafe { *stamps.changed.add(m) } >= visited;
        for k in 0..D {
            let st = self.stride[k];
            let i = idx[k];
            let nk = self.p.shape[k];
            if (i >= 1 && changed(n - st)) || (i + 1 < nk && changed(n + st)) {
                return true;
            }
            if sweep.second && ((i >= 2 && changed(n - 2 * st)) || (i + 2 < nk && changed(n + 2 * st))) {
                return true;
            }
        }
        false
    }

    /// Updates the row (the last axis) whose other indices are `prefix[..D-1]`.
    fn row(&self, u: Shared, stamps: Stamps, prefix: [usize; D], orientation: usize, sweep: Sweep) -> Outcome {
        let last = self.p.shape[D - 1];
        let reversed = orientation >> (D - 1) & 1 == 1;
        let mut base = 0;
        for k in 0..D - 1 {
            base += prefix[k] * self.stride[k];
        }
        let mut idx = prefix;
        let mut change = 0.0f64;
        let mut updates = 0u64;
        let mut lowest = f64::INFINITY;
        for c in 0..last {
            let i = if reversed { last - 1 - c } else { c };
            let n = base + i;
            if self.fixed[n] {
                continue;
            }
            idx[D - 1] = i;
            if !self.stale(stamps, n, idx, sweep) {
                continue;
            }
            let old = u.get(n);
            let cand = self.update(u, n, idx, sweep.second, old);
            updates += 1;
            unsafe { *stamps.visited.add(n) = sweep.index };
            let new = if sweep.monotone {
                if cand < old {
                    cand
                } else {
                    old
                }
            } else if cand.is_finite() {
                cand
            } else {
                old
            };
            if new != old {
                u.set(n, new);
                let d = (new - old).abs();
                change = change.max(d);
                lowest = lowest.min(new);
                if !(d <= self.activation_threshold) {
                    unsafe { *stamps.changed.add(n) = sweep.index };
                }
            }
        }
        Outcome {
            change,
            updates,
            lowest,
        }
    }

    /// The local update at node `n` (grid index `idx`): `u₀ + w`, `w` the root of the limited
    /// Godunov equation ([`limited_root`]); `+∞` when no neighbour is reached yet.
    #[inline(always)]
    fn update(&self, u: Shared, n: usize, idx: [usize; D], second: bool, old: f64) -> f64 {
        let p = self.p;
        let src = self.source_of[n];
        let xs = &p.sources[src as usize];
        let ss = p.source_slowness[src as usize];
        let x: [f64; D] = std::array::from_fn(|k| p.lower[k] + p.h * idx[k] as f64);
        let r = dist(&x, xs);
        let g: [f64; D] = std::array::from_fn(|k| {
            if self.factored && r > 0.0 {
                ss * (x[k] - xs[k]) / r
            } else {
                0.0
            }
        });
        let s = match p.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(v) => v[n],
        };
        let eps = s * p.h * p.h / self.ramp_length;
        // the factor at node m = n + off·e_k, by the node's own source
        let factor = |m: usize, k: usize, off: f64| -> f64 {
            if !self.factored {
                0.0
            } else if self.source_of[m] == src {
                self.u0[m]
            } else {
                let mut y = x;
                y[k] += off * p.h;
                ss * dist(&y, xs)
            }
        };
        let sides: [[Side; 2]; D] = std::array::from_fn(|k| {
            std::array::from_fn(|j| {
                let up = j == 1;
                let sigma = if up { 1.0 } else { -1.0 };
                let has1 = if up { idx[k] + 1 < p.shape[k] } else { idx[k] >= 1 };
                if !has1 {
                    return Side::MISSING;
                }
                let n1 = if up { n + self.stride[k] } else { n - self.stride[k] };
                let u1 = u.get(n1);
                if !u1.is_finite() {
                    return Side::MISSING;
                }
                let w1 = u1 - factor(n1, k, sigma);
                let mut t = 0.0;
                let mut w2 = f64::NAN;
                if second && (if up { idx[k] + 2 < p.shape[k] } else { idx[k] >= 2 }) {
                    let n2 = if up { n1 + self.stride[k] } else { n1 - self.stride[k] };
                    let u2 = u.get(n2);
                    t = ramp(u1, u2, eps);
                    if t > 0.0 {
                        w2 = u2 - factor(n2, k, 2.0 * sigma);
                    }
                }
                Side::limited(w1, w2, t, p.h, sigma * g[k])
            })
        });
        let w = if second {
            limited_root_from(&sides, s, old - self.u0[n])
        } else {
            // first order: every side has h = Δx, the classical closed form (Eq. (3))
            let mins: [f64; D] = std::array::from_fn(|k| sides[k][0].a.min(sides[k][1].a));
            if mins.iter().all(|m| !m.is_finite()) {
                f64::INFINITY
            } else {
                godunov_update(mins, p.h * s)
            }
        };
        self.u0[n] + w
    }
}

#[cfg(test)]
#[path = "factored_box_tests.rs"]
mod tests;
