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
    pub seconds: f64,
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
        let sw = Sweeper {
            p: self,
            stride,
            u0,
            source_of,
            fixed,
            ramp_length: options.ramp_length,
            parallel_min_nodes: options.parallel_min_nodes,
            activation_threshold: options.activation_threshold,
        };
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
            let mut change = 0.0f64;
            let mut updates = 0u64;
            for orientation in 0..(1usize << D) {
                let sweep = Sweep {
                    index: stats.sweeps as u32 + 1 + orientation as u32,
                    phase_start,
                    second,
                    monotone,
                };
                let run = || sw.sweep(shared, stamps, orientation, sweep, parallel);
                let (c, m) = match &pool {
                    Some(pool) => pool.install(run),
                    None => run(),
                };
                change = change.max(c);
                updates += m;
            }
            stats.iterations += 1;
            stats.sweeps += 1 << D;
            stats.updates += updates;
            stats.last_change = change;
            if second {
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
            if !second {
                if change < options.tol {
                    if !options.second_order {
                        stats.converged = true;
                        break;
                    }
                    second = true;
                    monotone = false;
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
                phase_start = stats.sweeps as u32 + 1;
                stats.safeguard_iteration = Some(stats.iterations);
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
    fn sweep(&self, u: Shared, stamps: Stamps, orientation: usize, sweep: Sweep, parallel: bool) -> (f64, u64) {
        let shape = self.p.shape;
        let oriented = |k: usize, c: usize| if orientation >> k & 1 == 1 { shape[k] - 1 - c } else { c };
        if D == 2 {
            let mut out = (0.0f64, 0u64);
            for c0 in 0..shape[0] {
                let mut prefix = [0usize; D];
                prefix[0] = oriented(0, c0);
                let r = self.row(u, stamps, prefix, orientation, sweep);
                out = (out.0.max(r.0), out.1 + r.1);
            }
            return out;
        }
        // D == 3: levels of c0 + c1, the rows of a level in parallel
        let (n0, n1) = (shape[0], shape[1]);
        let mut out = (0.0f64, 0u64);
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
                    .reduce(|| (0.0, 0), |a, b| (a.0.max(b.0), a.1 + b.1))
            } else {
                (lo..=hi)
                    .map(one)
                    .fold((0.0f64, 0u64), |a, b| (a.0.max(b.0), a.1 + b.1))
            };
            out = (out.0.max(r.0), out.1 + r.1);
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
    fn row(&self, u: Shared, stamps: Stamps, prefix: [usize; D], orientation: usize, sweep: Sweep) -> (f64, u64) {
        let last = self.p.shape[D - 1];
        let reversed = orientation >> (D - 1) & 1 == 1;
        let mut base = 0;
        for k in 0..D - 1 {
            base += prefix[k] * self.stride[k];
        }
        let mut idx = prefix;
        let mut change = 0.0f64;
        let mut updates = 0u64;
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
                if !(d <= self.activation_threshold) {
                    unsafe { *stamps.changed.add(n) = sweep.index };
                }
            }
        }
        (change, updates)
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
        let g: [f64; D] = std::array::from_fn(|k| if r > 0.0 { ss * (x[k] - xs[k]) / r } else { 0.0 });
        let s = match p.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(v) => v[n],
        };
        let eps = s * p.h * p.h / self.ramp_length;
        // the factor at node m = n + off·e_k, by the node's own source
        let factor = |m: usize, k: usize, off: f64| -> f64 {
            if self.source_of[m] == src {
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
mod tests {
    use super::*;

    fn linear_speed_exact(x: &[f64], xs: &[f64], a: f64, g: &[f64]) -> f64 {
        // slowness 1/(a + g·x): T = arccosh(1 + |g|²|x − xs|² / (2 v(x) v(xs))) / |g|
        let v = |p: &[f64]| a + p.iter().zip(g).map(|(p, g)| p * g).sum::<f64>();
        let gn = g.iter().map(|g| g * g).sum::<f64>().sqrt();
        let r2: f64 = x.iter().zip(xs).map(|(a, b)| (a - b) * (a - b)).sum();
        (1.0 + gn * gn * r2 / (2.0 * v(x) * v(xs))).acosh() / gn
    }

    /// Solves the linear-speed problem on an n×n grid of [0, 1]², source (0.31, 0.47); the max
    /// error and the stats.
    fn linear_speed_2d(n: usize, second: bool, threads: usize) -> (f64, FactoredStats, Vec<f64>) {
        let (a, g) = (1.0, [0.5, -0.3]);
        let h = 1.0 / (n - 1) as f64;
        let xs = [0.31, 0.47];
        let slow: Vec<f64> = (0..n * n)
            .map(|m| {
                let (i, j) = (m / n, m % n);
                1.0 / (a + g[0] * i as f64 * h + g[1] * j as f64 * h)
            })
            .collect();
        let s0 = 1.0 / (a + g[0] * xs[0] + g[1] * xs[1]);
        let mut fixed = vec![];
        let mut vals = vec![];
        for m in 0..n * n {
            let x = [(m / n) as f64 * h, (m % n) as f64 * h];
            if dist(&x, &xs) <= 2.0 * h {
                fixed.push(m);
                vals.push(linear_speed_exact(&x, &xs, a, &g));
            }
        }
        let p = FactoredBox::<2> {
            shape: [n, n],
            lower: [0.0, 0.0],
            h,
            slowness: Slowness::PerNode(&slow),
            sources: &[xs],
            source_slowness: &[s0],
            fixed_nodes: &fixed,
            fixed_values: &vals,
        };
        let opts = FactoredOptions {
            tol: 1e-4 * h * h,
            second_order: second,
            threads,
            ..Default::default()
        };
        let (u, st) = p.solve(&opts, &mut |_| Control::Continue).unwrap();
        let mut err = 0.0f64;
        for m in 0..n * n {
            let x = [(m / n) as f64 * h, (m % n) as f64 * h];
            err = err.max((u[m] - linear_speed_exact(&x, &xs, a, &g)).abs());
        }
        (err, st, u)
    }

    #[test]
    fn second_order_in_a_linear_speed_medium_2d() {
        let (e1, st1, _) = linear_speed_2d(41, true, 1);
        let (e2, st2, _) = linear_speed_2d(81, true, 1);
        assert!(st1.converged && st2.converged);
        assert!(st2.first_order_iterations >= 2 && st2.second_order_iterations >= 2);
        let order = (e1 / e2).log2();
        assert!(order > 1.8, "order {order}: {e1:e} → {e2:e}");
        assert!(e2 < 2e-4, "{e2:e}");
        // phase 1 alone is first order and less accurate
        let (f2, st, _) = linear_speed_2d(81, false, 1);
        assert!(st.second_order_iterations == 0 && f2 > 3.0 * e2, "{f2:e} vs {e2:e}");
    }

    /// Constant slowness 2.5 on a 17³ grid (h = 0.1) with the given sources; the values, the
    /// exact distances and the stats.
    fn constant_speed_3d(sources: &[[f64; 3]], options: &FactoredOptions) -> (Vec<f64>, Vec<f64>, FactoredStats) {
        let (n, h, s) = (17, 0.1, 2.5);
        let point = |m: usize| [(m / (n * n)) as f64 * h, (m / n % n) as f64 * h, (m % n) as f64 * h];
        let exact: Vec<f64> = (0..n * n * n)
            .map(|m| {
                s * sources
                    .iter()
                    .map(|xs| dist(&point(m), xs))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let fixed: Vec<usize> = (0..n * n * n).filter(|&m| exact[m] <= 2.0 * h * s).collect();
        let vals: Vec<f64> = fixed.iter().map(|&m| exact[m]).collect();
        let slow = vec![s; sources.len()];
        let p = FactoredBox::<3> {
            shape: [n; 3],
            lower: [0.0; 3],
            h,
            slowness: Slowness::Constant(s),
            sources,
            source_slowness: &slow,
            fixed_nodes: &fixed,
            fixed_values: &vals,
        };
        let (u, st) = p.solve(options, &mut |_| Control::Continue).unwrap();
        (u, exact, st)
    }

    #[test]
    fn constant_speed_is_exact_for_one_source_and_away_from_where_fronts_meet() {
        let opts = FactoredOptions {
            tol: 1e-8,
            ..Default::default()
        };
        let (u, exact, st) = constant_speed_3d(&[[0.33, 0.71, 0.52]], &opts);
        assert!(st.converged && st.safeguard_iteration.is_none() && st.second_order_iterations >= 1);
        let err = u.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 1e-10, "{err:e}");
        // two sources: the nodes next to the surface where the fronts meet keep an O(Δx) error
        let sources = [[0.33, 0.71, 0.52], [1.2, 0.9, 1.37]];
        let (u, exact, st) = constant_speed_3d(&sources, &opts);
        assert!(st.converged);
        let (n, h) = (17, 0.1);
        let mut far = 0.0f64;
        let mut all = 0.0f64;
        for m in 0..n * n * n {
            let x = [(m / (n * n)) as f64 * h, (m / n % n) as f64 * h, (m % n) as f64 * h];
            let e = (u[m] - exact[m]).abs();
            all = all.max(e);
            if (dist(&x, &sources[0]) - dist(&x, &sources[1])).abs() > 3.0 * h {
                far = far.max(e);
            }
        }
        assert!(far < 1e-3 && all < 0.2 * h * 2.5, "{far:e} {all:e}");
    }

    #[test]
    fn the_stagnation_safeguard_switches_to_decreases_only_and_is_reported() {
        // a ratio no change can beat: the safeguard fires after `window` + 1 phase-2 iterations
        let opts = FactoredOptions {
            tol: 1e-13,
            stagnation_window: 1,
            stagnation_ratio: 1e-300,
            ..Default::default()
        };
        let (u, exact, st) = constant_speed_3d(&[[0.33, 0.71, 0.52], [1.2, 0.9, 1.37]], &opts);
        let fired = st.safeguard_iteration.expect("the safeguard fires");
        assert_eq!(fired, st.first_order_iterations + 2);
        assert!(st.converged);
        let err = u.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 0.2 * 0.1 * 2.5, "{err:e}");
    }

    fn linear_speed_3d(n: usize, threads: usize) -> (Vec<f64>, FactoredStats) {
        let (a, g) = (1.0, [0.4, -0.3, 0.2]);
        let h = 1.0 / (n - 1) as f64;
        let xs = [0.43, 0.52, 0.61];
        let point = |m: usize| [(m / (n * n)) as f64 * h, (m / n % n) as f64 * h, (m % n) as f64 * h];
        let slow: Vec<f64> = (0..n * n * n)
            .map(|m| {
                let x = point(m);
                1.0 / (a + g[0] * x[0] + g[1] * x[1] + g[2] * x[2])
            })
            .collect();
        let s0 = 1.0 / (a + g[0] * xs[0] + g[1] * xs[1] + g[2] * xs[2]);
        let (mut fixed, mut vals) = (vec![], vec![]);
        for m in 0..n * n * n {
            if dist(&point(m), &xs) <= 2.0 * h {
                fixed.push(m);
                vals.push(linear_speed_exact(&point(m), &xs, a, &g));
            }
        }
        let p = FactoredBox::<3> {
            shape: [n; 3],
            lower: [0.0; 3],
            h,
            slowness: Slowness::PerNode(&slow),
            sources: &[xs],
            source_slowness: &[s0],
            fixed_nodes: &fixed,
            fixed_values: &vals,
        };
        let opts = FactoredOptions {
            tol: 1e-3 * h * h,
            threads,
            parallel_min_nodes: 1,
            ..Default::default()
        };
        let (u, st) = p.solve(&opts, &mut |_| Control::Continue).unwrap();
        let err = (0..n * n * n)
            .map(|m| (u[m] - linear_speed_exact(&point(m), &xs, a, &g)).abs())
            .fold(0.0, f64::max);
        assert!(st.converged && err < 2e-3, "{err:e}");
        (u, st)
    }

    #[test]
    fn threads_do_not_change_the_bits() {
        let (u1, st1) = linear_speed_3d(19, 1);
        let (u2, st2) = linear_speed_3d(19, 2);
        assert_eq!(st1.iterations, st2.iterations);
        assert!(u1.iter().zip(&u2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn threads_do_not_change_the_bits_on_an_uneven_box() {
        // levels of c0 + c1 with n0 ≠ n1 (rows clipped at both ends), two sources, a source on a face
        let shape = [9, 14, 11];
        let h = 0.1;
        let sources = [[0.35, 0.52, 0.0], [0.71, 1.18, 0.64]];
        let point = |m: usize| {
            [
                (m / (14 * 11)) as f64 * h,
                (m / 11 % 14) as f64 * h,
                (m % 11) as f64 * h,
            ]
        };
        let n = 9 * 14 * 11;
        let slow: Vec<f64> = (0..n)
            .map(|m| 1.0 / (1.5 + 0.4 * point(m)[0] - 0.3 * point(m)[2]))
            .collect();
        let (mut fixed, mut vals) = (vec![], vec![]);
        for m in 0..n {
            let d = sources
                .iter()
                .map(|xs| dist(&point(m), xs))
                .fold(f64::INFINITY, f64::min);
            if d <= 2.0 * h {
                fixed.push(m);
                vals.push(d * slow[m]);
            }
        }
        let ss: Vec<f64> = sources.iter().map(|x| 1.0 / (1.5 + 0.4 * x[0] - 0.3 * x[2])).collect();
        let p = FactoredBox::<3> {
            shape,
            lower: [0.0; 3],
            h,
            slowness: Slowness::PerNode(&slow),
            sources: &sources,
            source_slowness: &ss,
            fixed_nodes: &fixed,
            fixed_values: &vals,
        };
        let run = |threads| {
            let opts = FactoredOptions {
                tol: 1e-7,
                threads,
                parallel_min_nodes: 1,
                activation_threshold: 1e-9,
                ..Default::default()
            };
            p.solve(&opts, &mut |_| Control::Continue).unwrap()
        };
        let (u1, st1) = run(1);
        let (u2, st2) = run(2);
        assert!(st1.converged && u1.iter().all(|v| v.is_finite()));
        assert_eq!(
            st1,
            FactoredStats {
                seconds: st1.seconds,
                ..st2
            }
        );
        assert!(u1.iter().zip(&u2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn bad_arguments_are_errors_not_panics() {
        let p = FactoredBox::<2> {
            shape: [5, 5],
            lower: [0.0; 2],
            h: 0.1,
            slowness: Slowness::Constant(1.0),
            sources: &[[0.2, 0.2]],
            source_slowness: &[1.0],
            fixed_nodes: &[99],
            fixed_values: &[0.0],
        };
        let e = p
            .solve(&FactoredOptions::default(), &mut |_| Control::Continue)
            .unwrap_err();
        assert!(matches!(
            e,
            Error::InvalidArgument {
                argument: "fixed_nodes",
                ..
            }
        ));
        let p = FactoredBox {
            fixed_nodes: &[12],
            ..p
        };
        let stop = p
            .solve(&FactoredOptions::default(), &mut |_| Control::Stop)
            .unwrap_err();
        assert_eq!(stop, Error::Interrupted { iterations: 1 });
        let e = p.solve(
            &FactoredOptions {
                tol: f64::NAN,
                ..Default::default()
            },
            &mut |_| Control::Continue,
        );
        assert!(matches!(e, Err(Error::InvalidArgument { argument: "tol", .. })));
    }
}
