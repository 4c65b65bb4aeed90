//! A sweep problem and what a solve returns: the nodes' roles ([`NodeRole`]: fixed, inner tube,
//! extension layer), the slowness, the extension layer's data, the options ([`SolveOptions`]),
//! the statistics ([`SolveStats`]) and the progress callback's types; the checks of a problem's
//! input.

use super::front_window::*;
use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::scheme::extension::extension_weights;
use crate::scheme::hamiltonian::InnerScheme;
use rayon::prelude::*;

/// What the sweep does at a node.
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeRole {
    /// Source value, kept as given.
    Fixed = 0,
    /// Inner tube: eikonal / HJ local solver.
    Inner = 1,
    /// Extension layer: upwind extension along the outward direction.
    Outer = 2,
}

impl NodeRole {
    pub fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(NodeRole::Fixed),
            1 => Some(NodeRole::Inner),
            2 => Some(NodeRole::Outer),
            _ => None,
        }
    }
}

/// How an inner node reads a neighbour that is not in the band.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MissingNeighbour {
    /// The neighbour holds the numerical infinity (Algorithm 2; harmless for Godunov, which takes
    /// the smaller neighbour per axis).
    Infinity,
    /// The neighbour is linearly extrapolated from the node and its opposite neighbour,
    /// `u_missing = 2 u − u_opposite` (a one-sided difference for Lax–Friedrichs at the grid
    /// boundary or a cut tube end, after Kao, Osher and Qian 2004).
    Extrapolate,
}

/// Slowness `1/F` at the nodes.
#[derive(Clone, Copy)]
pub enum Slowness<'a> {
    Constant(f64),
    PerNode(&'a [f64]),
}

/// The extension layer's data, per node (read only at [`NodeRole::Outer`] nodes).
#[derive(Clone, Copy)]
pub enum Extension<'a, const D: usize> {
    /// No extension layer (Algorithms 1 and 2).
    None,
    /// The outward unit direction `sgn(φ) n` per node; the solver derives the upwind weights of
    /// Eq. (5) from it, in a buffer of `D` f32 per node.
    Directions(&'a [[f32; D]]),
    /// Upwind weights already derived by [`extension_weights_in_place`] (no extra buffer).
    Weights(&'a [[f32; D]]),
}

/// Replaces the outward directions of the [`NodeRole::Outer`] nodes by the upwind weights of
/// Eq. (5) ([`extension_weights`], absent neighbours dropped); the other nodes' entries are zeroed
/// and an outer node without an upwind neighbour gets NaN (it keeps its value). The band does not
/// change during a solve, so the weights are computed once; doing it in place saves `4 D` bytes
/// per band node.
pub fn extension_weights_in_place<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    directions: &mut [[f32; D]],
) {
    let sentinel = band.sentinel();
    directions
        .par_iter_mut()
        .zip(roles.par_iter())
        .enumerate()
        .for_each(|(n, (v, &r))| {
            if r != NodeRole::Outer {
                *v = [0.0; D];
                return;
            }
            let nb = band.neighbours_of(n);
            let mut pm = [true; D];
            let mut pp = [true; D];
            for k in 0..D {
                pm[k] = nb[k][0] != sentinel;
                pp[k] = nb[k][1] != sentinel;
            }
            *v = extension_weights(*v, pm, pp).unwrap_or([f32::NAN; D]);
        });
}

/// Everything the driver needs about one problem.
pub struct SweepProblem<'a, const D: usize> {
    pub band: &'a NarrowBand<D>,
    pub roles: &'a [NodeRole],
    /// Grid spacing `h`.
    pub spacing: f64,
    pub slowness: Slowness<'a>,
    /// What the extension update (5) reads at the [`NodeRole::Outer`] nodes.
    pub extension: Extension<'a, D>,
    pub scheme: InnerScheme<'a, D>,
    pub missing: MissingNeighbour,
}

/// Stopping rule and numerical infinity.
#[derive(Debug, Clone, Copy)]
pub struct SolveOptions {
    /// Stop when the largest change in one iteration is below this.
    pub tol: f64,
    /// Give up (with `converged = false`) after this many iterations.
    pub max_iterations: usize,
    /// The finite "numerical infinity" that non-fixed nodes start at; `None` derives a safe,
    /// tight one from the band (see [`SweepProblem::auto_infinity`]).
    pub infinity: Option<f64>,
    /// Worker threads for the solve (the sweeps and their preparation), in a pool of its own: 0 =
    /// rayon's default (all cores, or `RAYON_NUM_THREADS`), 1 = sequential. The result does not depend on it (see
    /// [`crate::band::schedule`]).
    pub threads: usize,
    /// Skip nodes none of whose neighbours changed since their last update (default true). The
    /// result is bit-identical either way for the pointwise updates, and identical to rounding
    /// (an ulp here and there) with the coupled Godunov update. Off, every node but the fixed
    /// ones is updated in every sweep, in row loops that touch no flag: the paper's sweeps to the
    /// letter, for measuring what the flags save. (Python's `paper_sweeps=True` keeps the flags:
    /// the same bits from fewer updates.)
    pub skip_inactive: bool,
    /// A node whose value changes by at most this much does not re-activate its neighbours.
    /// 0 (the default) keeps the result bit-identical to plain sweeps; a value below `tol` trades
    /// a deviation of that order for fewer updates in the last iterations.
    pub activation_threshold: f64,
    /// Godunov only: update each inner-tube node together with the extension-layer neighbours
    /// whose update (5) reads it ([`crate::scheme::godunov::godunov_update_coupled`], a block
    /// Gauss–Seidel step). The discrete equations and so the solution (to about `tol`) are the
    /// same; the pointwise node ↔ layer cycle that contracts only by the extension weight per
    /// pass is solved at once: on the sphere 22% fewer updates at N = 201, 36% at N = 1001
    /// (`benches/experiments/sweep_variants.py`). `false` runs the
    /// paper's pointwise sweeps (its Table 2 iteration counts).
    pub coupled: bool,
    /// Leave the *outer rim* to the end: the extension-layer nodes that no inner-tube node
    /// depends on (not read by an inner node, nor by a layer node that one reads, and so on)
    /// cannot change the inner tube, so the sweeps first converge the rest of the band with the
    /// rim held still, then the converged values are extended into the rim in one pass in
    /// dependency order ([`crate::sweep::rim`]). The same equations and fixed point; the rim (about a
    /// third of the layer with the paper's widths) is evaluated about once per node instead of
    /// being swept in every iteration.
    pub defer_outer_rim: bool,
    /// Godunov on 3D bands only, with `skip_inactive`: sweep behind a moving *front window*. The sweeps
    /// converge from the sources outwards: a region settles only once the region upwind of it
    /// has, and on the sphere the settled region grows by a roughly fixed step per iteration
    /// (the value changes binned by distance from the source show it). Updates far ahead of
    /// that front are redone later anyway. So only the nodes whose value is at most the window's
    /// edge `front + w` are updated, from the first iteration on: `front` is the smallest source
    /// value at the start, then the smallest value that changed by more than `tol` in the
    /// previous iteration, and `w = front_window · h s̄ · sqrt(H)` (`h` the spacing, `s̄` the mean
    /// slowness, `H` the longest grid path from a source in steps, so that `H h s̄` estimates
    /// the range of the values; the front's step shrinks like the square root of the spacing). A
    /// node still at the numerical infinity is updated but takes the new value only if it lies
    /// within the window; so every value set lies within it, and the band fills from the sources
    /// outwards like a wave, without the first iterations' long detours round the surface. Nodes
    /// beyond it stay active for later, and rows entirely beyond it are skipped whole. The window
    /// only widens: to `front + w` when something in it moved, else past the nearest node waiting
    /// beyond it (by at least `w`); it opens fully when no node waits beyond it. Extension-layer
    /// nodes in an upwind 2-cycle (two layer nodes that read each other, where the directions from
    /// two sheets of the surface meet: edges of open surfaces, the Möbius band's twist) are not
    /// held back: they would wait until the window passed the numerical infinity mixed into
    /// their values. The stopping test only counts iterations over the whole band, so the fixed
    /// point is the same to about `tol`. A solve stopped earlier (`max_iterations`, interrupted)
    /// leaves the nodes beyond the window unreached ([`SolveStats::window_edge`]). On the sphere at
    /// N = 1001, 5× fewer local updates than without it (`benches/experiments/sweep_variants.py`). 0 switches
    /// it off. Lax–Friedrichs has no such front (its values near the sources keep moving, and a
    /// window there multiplied the iterations); on curves (2D bands, a few ms) it saved little on a
    /// circle and cost 1–3× the time on the six-fold star, whose front stalls at the arms.
    pub front_window: f64,
    /// On Linux, with more than one thread: before the sweeps, move each of the pool's threads
    /// once to a CPU of its own, then let it run anywhere again (`sweep/spread_threads.rs`):
    /// fresh threads often start on one core. The same values either way.
    pub spread_threads: bool,
    /// The sweeps prefetch the data of the rows a few places ahead in their order when the rows
    /// the previous iteration visited held more than this many bytes of the arrays the kernel
    /// reads (before the first iteration every row counts as visited, or none with the front
    /// window): with the band's data beyond the last-level cache the tiles' short runs through
    /// memory would wait on it; within, the hints only cost instructions
    /// (`sweep/row_prefetch.rs`; an upwind solver's sweeps count their bytes twice). Default
    /// [`default_row_prefetch_above`], a share of the last-level cache; 0 prefetches in every iteration that follows one that visited a row
    /// (and in the first unless the window is on), `usize::MAX` never; x86-64 only. The same
    /// values either way.
    pub row_prefetch_above: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tol: 1e-10,
            max_iterations: 10_000,
            infinity: None,
            threads: 0,
            skip_inactive: true,
            activation_threshold: 0.0,
            coupled: true,
            defer_outer_rim: true,
            front_window: DEFAULT_FRONT_WINDOW,
            spread_threads: true,
            row_prefetch_above: super::row_prefetch::default_row_prefetch_above(),
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveStats {
    /// Full passes of the 2^d sweep orders; with [`SolveOptions::defer_outer_rim`], one more
    /// for the rim (its values set from the converged rest of the band, [`crate::sweep::rim`]).
    pub iterations: usize,
    /// Single directional sweeps (2^d per iteration), and the rim's passes (one in dependency
    /// order, more where rim nodes read each other in a cycle).
    pub sweeps: usize,
    /// Local updates performed (one per visited non-fixed node and sweep).
    pub updates: u64,
    /// Whether the stopping test was met.
    pub converged: bool,
    /// Largest change during the last iteration.
    pub last_change: f64,
    /// Wall-clock seconds of [`SweepProblem::solve`]: the preparation (the grid-path search, the
    /// outer rim, the flags) and the sweeps.
    pub seconds: f64,
    /// The numerical infinity used; nodes never reached hold exactly this value.
    pub infinity: f64,
    /// Where the front window ([`SolveOptions::front_window`]) stood when the solve ended:
    /// infinite when it was off or had opened (always so for a converged solve). When the solve
    /// stopped earlier (`max_iterations`, or interrupted), the nodes above it are reported
    /// unreached (they hold the numerical infinity), and the values just below it are not
    /// converged yet.
    pub window_edge: f64,
    /// Parallel iterations (3D, more than one thread) whose sweeps ran strips thin across the
    /// first and the second leading axis (`SweepProblem::thin_strip_axis`); the others ran
    /// square tiles. The values are the same bits either way.
    pub thin_strip_iterations: [usize; 2],
    /// Iterations whose sweeps prefetched the rows ahead ([`SolveOptions::row_prefetch_above`]).
    /// The values are the same bits either way.
    pub prefetch_iterations: usize,
}

/// Reported to the progress callback after every iteration.
#[derive(Debug, Clone, Copy)]
pub struct IterationReport {
    pub iteration: usize,
    pub max_change: f64,
    pub updates: u64,
}

/// The progress callback's answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    Continue,
    Stop,
}

impl<'a, const D: usize> SweepProblem<'a, D> {
    pub(super) fn check(&self, values: &[f64]) -> Result<()> {
        let n = self.band.len();
        if self.roles.len() != n {
            return Err(Error::invalid(
                "roles",
                format!("expected {n} roles, got {}", self.roles.len()),
            ));
        }
        if values.len() != n {
            return Err(Error::invalid(
                "values",
                format!("expected {n} values, got {}", values.len()),
            ));
        }
        if let Slowness::PerNode(s) = self.slowness {
            if s.len() != n {
                return Err(Error::invalid("speed", format!("expected {n} values, got {}", s.len())));
            }
        }
        if self.roles.contains(&NodeRole::Outer) {
            match self.extension {
                Extension::None => {
                    return Err(Error::invalid(
                        "directions",
                        "the band has extension-layer nodes but no directions",
                    ));
                }
                Extension::Directions(d) | Extension::Weights(d) if d.len() != n => {
                    return Err(Error::invalid(
                        "directions",
                        format!("expected {n} directions, got {}", d.len()),
                    ));
                }
                _ => {}
            }
        }
        if !(self.spacing > 0.0 && self.spacing.is_finite()) {
            return Err(Error::invalid("spacing", "must be positive and finite"));
        }
        Ok(())
    }

    /// The upwind weights of Eq. (5), per node: empty without an extension layer, borrowed when
    /// handed in as [`Extension::Weights`], derived from [`Extension::Directions`] (a copy)
    /// otherwise.
    pub(super) fn upwind_weights(&self) -> std::borrow::Cow<'a, [[f32; D]]> {
        use std::borrow::Cow;
        match self.extension {
            _ if !self.roles.contains(&NodeRole::Outer) => Cow::Borrowed(&[]),
            Extension::None => Cow::Borrowed(&[]),
            Extension::Weights(w) => Cow::Borrowed(w),
            Extension::Directions(d) => {
                let mut w = d.to_vec();
                extension_weights_in_place(self.band, self.roles, &mut w);
                Cow::Owned(w)
            }
        }
    }

    /// The mean slowness over the band (the constant one, or the mean of the per-node ones).
    pub(super) fn mean_slowness(&self) -> f64 {
        match self.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(s) if !s.is_empty() => s.iter().sum::<f64>() / s.len() as f64,
            Slowness::PerNode(_) => 1.0,
        }
    }

    /// The largest slowness of a general Hamiltonian, which bounds the extrapolation of absent
    /// neighbours (see `fill_missing`); computed once per solve, it may scan every node.
    pub(super) fn general_slowness(&self) -> f64 {
        match self.scheme {
            InnerScheme::General(ham) => ham.slowness_bound().unwrap_or(f64::INFINITY),
            _ => f64::INFINITY,
        }
    }

    /// This problem with other roles and the extension weights already derived.
    pub(super) fn with_roles<'b>(&self, roles: &'b [NodeRole], weights: &'b [[f32; D]]) -> SweepProblem<'b, D>
    where
        'a: 'b,
    {
        SweepProblem {
            band: self.band,
            roles,
            spacing: self.spacing,
            slowness: self.slowness,
            extension: if weights.is_empty() {
                Extension::None
            } else {
                Extension::Weights(weights)
            },
            scheme: self.scheme,
            missing: self.missing,
        }
    }
}
