//! The Gauss–Seidel sweeping driver: Algorithm 1 (the Euclidean fast sweeping method),
//! Algorithm 2 (the naive single tube) and Algorithm 3 (the two-layer tube) of the paper are all
//! this one loop over a [`NarrowBand`], differing only in the role of each node:
//!
//! * [`NodeRole::Fixed`]: a source value, never updated;
//! * [`NodeRole::Inner`]: the eikonal (or general HJ) local solver — Eq. (3), (4) or Sect. 5.1;
//! * [`NodeRole::Outer`]: the extension update, Eq. (5) applied to Eq. (8).
//!
//! One *iteration* is one pass of all 2^d sweep orders (Gray-code order, so consecutive sweeps
//! differ in one axis). The solver stops when the largest change of any node value during an
//! iteration is below `tol`. Values start at a finite numerical infinity; inner-tube values are
//! only ever replaced by smaller ones (this is automatic for Godunov and is the paper's explicit
//! acceptance rule for Lax–Friedrichs, proof of Corollary 1).

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::extension::extension_update;
use crate::godunov::godunov_update;
use crate::hamiltonian::InnerScheme;
use crate::lax_friedrichs::{central_gradient, lxf_eikonal_update, lxf_general_update};
use std::time::Instant;

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

/// Everything the driver needs about one problem.
pub struct SweepProblem<'a, const D: usize> {
    pub band: &'a NarrowBand<D>,
    pub roles: &'a [NodeRole],
    /// Grid spacing `h`.
    pub spacing: f64,
    pub slowness: Slowness<'a>,
    /// Outward unit direction `sgn(φ) n` per node; read only at [`NodeRole::Outer`] nodes and may be
    /// empty if there are none.
    pub directions: &'a [[f32; D]],
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
    /// The finite "numerical infinity" that non-fixed nodes start at.
    pub infinity: f64,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions { tol: 1e-10, max_iterations: 10_000, infinity: crate::DEFAULT_INFINITY }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveStats {
    /// Full passes of the 2^d sweep orders.
    pub iterations: usize,
    /// Single directional sweeps (2^d per iteration).
    pub sweeps: usize,
    /// Local updates performed (one per visited non-fixed node and sweep).
    pub updates: u64,
    /// Whether the stopping test was met.
    pub converged: bool,
    /// Largest change during the last iteration.
    pub last_change: f64,
    /// Wall-clock seconds in the sweeps.
    pub seconds: f64,
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
    fn check(&self, values: &[f64]) -> Result<()> {
        let n = self.band.len();
        if self.roles.len() != n {
            return Err(Error::invalid("roles", format!("expected {n} roles, got {}", self.roles.len())));
        }
        if values.len() != n {
            return Err(Error::invalid("values", format!("expected {n} values, got {}", values.len())));
        }
        if let Slowness::PerNode(s) = self.slowness {
            if s.len() != n {
                return Err(Error::invalid("speed", format!("expected {n} values, got {}", s.len())));
            }
        }
        if self.roles.iter().any(|&r| r == NodeRole::Outer) && self.directions.len() != n {
            return Err(Error::invalid("directions", format!("expected {n} directions, got {}", self.directions.len())));
        }
        if !(self.spacing > 0.0 && self.spacing.is_finite()) {
            return Err(Error::invalid("spacing", "must be positive and finite"));
        }
        Ok(())
    }

    /// Runs the sweeps. `values` holds the fixed nodes' values on entry (other entries are
    /// overwritten with the numerical infinity) and the solution on return. `progress` is called
    /// after every iteration; returning [`Control::Stop`] ends the solve with
    /// [`Error::Interrupted`].
    pub fn solve(
        &self,
        values: &mut Vec<f64>,
        options: &SolveOptions,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
    ) -> Result<SolveStats> {
        self.check(values)?;
        if !(options.infinity.is_finite() && options.infinity > 0.0) {
            return Err(Error::invalid("infinity", "must be positive and finite"));
        }
        if !(options.tol >= 0.0) {
            return Err(Error::invalid("tol", "must be non-negative"));
        }
        let start = Instant::now();
        let inf = options.infinity;
        for (v, &r) in values.iter_mut().zip(self.roles) {
            if r != NodeRole::Fixed {
                *v = inf;
            }
        }
        values.push(inf); // the sentinel slot read for absent neighbours
        let mut stats = SolveStats::default();
        let result = self.iterate(values, options, progress, &mut stats);
        values.pop();
        stats.seconds = start.elapsed().as_secs_f64();
        result.map(|_| stats)
    }

    fn iterate(
        &self,
        u: &mut [f64],
        options: &SolveOptions,
        progress: &mut dyn FnMut(&IterationReport) -> Control,
        stats: &mut SolveStats,
    ) -> Result<()> {
        let n_orient = 1usize << D;
        while stats.iterations < options.max_iterations {
            let mut max_change = 0.0f64;
            let mut updates = 0u64;
            for s in 0..n_orient {
                let dir = s ^ (s >> 1); // Gray code
                let (c, n) = self.sweep(u, dir, options.infinity);
                max_change = max_change.max(c);
                updates += n;
                stats.sweeps += 1;
            }
            stats.iterations += 1;
            stats.updates += updates;
            stats.last_change = max_change;
            if progress(&IterationReport { iteration: stats.iterations, max_change, updates }) == Control::Stop {
                return Err(Error::Interrupted { iterations: stats.iterations });
            }
            if max_change < options.tol {
                stats.converged = true;
                break;
            }
        }
        Ok(())
    }

    /// One Gauss–Seidel sweep in orientation `dir` (bit `k` set = axis `k` walked backwards).
    /// Returns the largest change and the number of local updates.
    fn sweep(&self, u: &mut [f64], dir: usize, inf: f64) -> (f64, u64) {
        let band = self.band;
        let lead_mask = (1usize << (D - 1)) - 1;
        let backwards = dir >> (D - 1) & 1 == 1;
        let mut max_change = 0.0f64;
        let mut updates = 0u64;
        for &r in band.row_order(dir & lead_mask) {
            let (s, e) = band.row_range(r as usize);
            if backwards {
                for n in (s..e).rev() {
                    self.visit(u, n, inf, &mut max_change, &mut updates);
                }
            } else {
                for n in s..e {
                    self.visit(u, n, inf, &mut max_change, &mut updates);
                }
            }
        }
        (max_change, updates)
    }

    #[inline(always)]
    fn visit(&self, u: &mut [f64], n: usize, inf: f64, max_change: &mut f64, updates: &mut u64) {
        let role = self.roles[n];
        if role == NodeRole::Fixed {
            return;
        }
        let nb = &self.band.neighbours()[n];
        let sentinel = self.band.sentinel();
        let mut minus = [0.0; D];
        let mut plus = [0.0; D];
        for k in 0..D {
            minus[k] = u[nb[k][0] as usize];
            plus[k] = u[nb[k][1] as usize];
        }
        *updates += 1;
        let old = u[n];
        if role == NodeRole::Outer {
            // Neighbours still at the numerical infinity stay in the convex combination, as in
            // the paper: the extended value then approaches the solution from above like the
            // inner values do. Dropping them would let a too-small value into the layer, which
            // the monotone Godunov update could never undo.
            let mut pm = [true; D];
            let mut pp = [true; D];
            for k in 0..D {
                pm[k] = nb[k][0] != sentinel;
                pp[k] = nb[k][1] != sentinel;
            }
            if let Some(new) = extension_update(self.directions[n], minus, plus, pm, pp) {
                let c = (new - old).abs();
                if c > *max_change {
                    *max_change = c;
                }
                u[n] = new;
            }
            return;
        }
        let h = self.spacing;
        let slow = match self.slowness {
            Slowness::Constant(s) => s,
            Slowness::PerNode(s) => s[n],
        };
        let candidate = match self.scheme {
            InnerScheme::Godunov => {
                let mut mins = [0.0; D];
                for k in 0..D {
                    mins[k] = minus[k].min(plus[k]);
                }
                godunov_update(mins, h * slow)
            }
            InnerScheme::LaxFriedrichs => {
                if self.missing == MissingNeighbour::Extrapolate {
                    fill_missing(nb, sentinel, old, inf, &mut minus, &mut plus);
                }
                lxf_eikonal_update(minus, plus, h * slow)
            }
            InnerScheme::General(ham) => {
                if self.missing == MissingNeighbour::Extrapolate {
                    fill_missing(nb, sentinel, old, inf, &mut minus, &mut plus);
                }
                let p = central_gradient(minus, plus, h);
                lxf_general_update(minus, plus, ham.viscosity(n), ham.value(n, p), h)
            }
        };
        // monotone acceptance: keep the smaller value (Sect. 4, proof of Corollary 1)
        if candidate < old {
            let c = old - candidate;
            if c > *max_change {
                *max_change = c;
            }
            u[n] = candidate;
        }
    }
}

/// Replaces the values of absent neighbours by a linear extrapolation through the node
/// (`2 u − u_opposite`), or by the opposite value when the node is still at infinity.
#[inline(always)]
fn fill_missing<const D: usize>(
    nb: &[[u32; 2]; D],
    sentinel: u32,
    centre: f64,
    inf: f64,
    minus: &mut [f64; D],
    plus: &mut [f64; D],
) {
    for k in 0..D {
        let m_absent = nb[k][0] == sentinel;
        let p_absent = nb[k][1] == sentinel;
        if m_absent && p_absent {
            minus[k] = centre;
            plus[k] = centre;
        } else if m_absent {
            minus[k] = if centre < inf && plus[k] < inf { 2.0 * centre - plus[k] } else { plus[k] };
        } else if p_absent {
            plus[k] = if centre < inf && minus[k] < inf { 2.0 * centre - minus[k] } else { minus[k] };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hamiltonian::IsotropicEikonal;

    fn box_problem<'a>(band: &'a NarrowBand<2>, roles: &'a [NodeRole], scheme: InnerScheme<'a, 2>, h: f64) -> SweepProblem<'a, 2> {
        SweepProblem {
            band,
            roles,
            spacing: h,
            slowness: Slowness::Constant(1.0),
            directions: &[],
            scheme,
            missing: MissingNeighbour::Extrapolate,
        }
    }

    #[test]
    fn godunov_from_a_corner_is_exact_on_the_axes_and_converges_in_two_iterations() {
        let n = 41;
        let h = 1.0 / (n - 1) as f64;
        let band = NarrowBand::<2>::full_box([n, n]).unwrap();
        let mut roles = vec![NodeRole::Inner; band.len()];
        roles[0] = NodeRole::Fixed;
        let mut u = vec![0.0; band.len()];
        let p = box_problem(&band, &roles, InnerScheme::Godunov, h);
        let stats = p.solve(&mut u, &SolveOptions::default(), &mut |_| Control::Continue).unwrap();
        assert!(stats.converged);
        assert_eq!(stats.iterations, 2);
        // along the axes the Godunov solution is exact
        assert!((u[n - 1] - 1.0).abs() < 1e-12);
        assert!((u[(n - 1) * n] - 1.0).abs() < 1e-12);
        // the diagonal has the known first-order error, below h
        let diag = u[band.len() - 1];
        assert!((diag - 2f64.sqrt()).abs() < 0.1 && diag > 2f64.sqrt());
    }

    #[test]
    fn general_hamiltonian_agrees_with_the_specialised_lax_friedrichs() {
        let n = 21;
        let h = 1.0 / (n - 1) as f64;
        let band = NarrowBand::<2>::full_box([n, n]).unwrap();
        let mut roles = vec![NodeRole::Inner; band.len()];
        let centre = band.find([10, 10]).unwrap();
        roles[centre] = NodeRole::Fixed;
        let slowness = vec![1.0; band.len()];
        let ham = IsotropicEikonal { slowness: &slowness };
        let opts = SolveOptions { tol: 1e-12, ..Default::default() };
        let mut a = vec![0.0; band.len()];
        let mut b = vec![0.0; band.len()];
        let sa = box_problem(&band, &roles, InnerScheme::LaxFriedrichs, h).solve(&mut a, &opts, &mut |_| Control::Continue).unwrap();
        let sb = box_problem(&band, &roles, InnerScheme::General(&ham), h).solve(&mut b, &opts, &mut |_| Control::Continue).unwrap();
        assert!(sa.converged && sb.converged);
        let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-9, "diff {diff}");
    }

    #[test]
    fn progress_can_stop_the_solve() {
        let band = NarrowBand::<2>::full_box([11, 11]).unwrap();
        let mut roles = vec![NodeRole::Inner; band.len()];
        roles[0] = NodeRole::Fixed;
        let mut u = vec![0.0; band.len()];
        let p = box_problem(&band, &roles, InnerScheme::LaxFriedrichs, 0.1);
        let err = p.solve(&mut u, &SolveOptions::default(), &mut |_| Control::Stop).unwrap_err();
        assert_eq!(err, Error::Interrupted { iterations: 1 });
        assert_eq!(u.len(), band.len());
    }
}
