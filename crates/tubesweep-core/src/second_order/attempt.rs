//! One attempt of the second-order solve ([`super::solver`]): phase 1 and phase 2 behind their
//! front windows, and after a runaway the first-order restart from the sources; with a
//! [`Demotion`] to fill, where the runaway was ([`super::demotion`]).

use std::sync::atomic::AtomicU8;
use std::time::Instant;

use crate::band::NarrowBand;
use crate::error::Result;
use crate::sweep::{Control, IterationReport, NodeRole, Slowness};

use super::demotion::{Demotion, CREEP_PROBE};
use super::factoring::Factoring;
use super::geometry::NodeGeometry;
use super::phase::{run_phase, RunPhase};
use super::pipeline::Pipeline;
use super::solver::{Limits, SecondOrderOptions, SecondOrderStats, Sweeper, RUNAWAY_FLOOR};

/// Every node that is not fixed back to +∞ (the fixed nodes keep their values): a start from the
/// sources.
pub(super) fn from_the_sources(values: &mut [f64], roles: &[NodeRole]) {
    for (v, &r) in values.iter_mut().zip(roles) {
        if r != NodeRole::Fixed {
            *v = f64::INFINITY;
        }
    }
}

/// What each attempt of [`super::demotion::solve_demoting`] reads besides the values.
pub(super) struct Attempts<'r, 'a, const D: usize> {
    pub(super) band: &'r NarrowBand<D>,
    pub(super) tube: (&'r [NodeGeometry], &'r [f32]),
    pub(super) sw: (&'r Factoring<D>, &'r [[f32; D]], Slowness<'a>),
    pub(super) spacing: f64,
    pub(super) options: &'r SecondOrderOptions,
}

impl<const D: usize> Attempts<'_, '_, D> {
    /// [`attempt`] with `geometry` in place of the tube's (None: the tube's).
    pub(super) fn run(
        &self,
        geometry: Option<&[NodeGeometry]>,
        values: &mut [f64],
        options: &SecondOrderOptions,
        changed: Option<&[bool]>,
        control: &mut dyn FnMut(&IterationReport) -> Control,
        demotion: (&[bool], Option<&mut Demotion>),
    ) -> Result<SecondOrderStats> {
        let tube = (geometry.unwrap_or(self.tube.0), self.tube.1);
        attempt(
            self.band,
            tube,
            self.sw,
            self.spacing,
            values,
            options,
            changed,
            control,
            demotion,
        )
    }
}

/// One attempt of the two phases on `values` with the nodes' `geometry` (the tube's, or with a
/// runaway's nodes at first order, [`super::demotion`], whose extension nodes `extends_u` marks);
/// with `found`, where a runaway was is found there.
#[allow(clippy::too_many_arguments)]
fn attempt<const D: usize>(
    band: &NarrowBand<D>,
    (geometry, abs_phi): (&[NodeGeometry], &[f32]),
    (factoring, directions, slowness): (&Factoring<D>, &[[f32; D]], Slowness<'_>),
    spacing: f64,
    values: &mut [f64],
    options: &SecondOrderOptions,
    mut changed: Option<&[bool]>,
    control: &mut dyn FnMut(&IterationReport) -> Control,
    (extends_u, mut found): (&[bool], Option<&mut Demotion>),
) -> Result<SecondOrderStats> {
    let start = Instant::now();
    let n = band.len();
    let sw = Sweeper::new(
        band,
        (geometry, abs_phi),
        (factoring, directions, slowness),
        spacing,
        options,
        extends_u,
    );
    let roles = sw.roles;
    // per row, the nodes before it that are not in the extension layer (the rows cover the band
    // in order): the index of a node's geometry, counted along the row as the sweeps walk it
    let mut row_inner = Vec::with_capacity(band.n_rows() + 1);
    let mut count = 0u32;
    for r in 0..band.n_rows() {
        let (s, e) = band.row_range(r);
        row_inner.push(count);
        count += roles[s..e].iter().filter(|&&r| r != NodeRole::Outer).count() as u32;
    }
    row_inner.push(count);
    let sigma_mean = match slowness {
        Slowness::Constant(s) => s,
        Slowness::PerNode(s) => s.iter().sum::<f64>() / n.max(1) as f64,
    };
    // a value this far below zero is a runaway (phase 2 and the restart after it)
    let floor = RUNAWAY_FLOOR * sigma_mean * spacing;
    let unit = if options.window_first > 0.0 || options.window_second > 0.0 {
        let fixed = roles
            .iter()
            .enumerate()
            .filter(|(_, &r)| r == NodeRole::Fixed)
            .map(|(i, _)| i);
        let hops = crate::sweep::grid_hops::max_grid_hops(band, fixed);
        spacing * sigma_mean * (hops as f64).sqrt()
    } else {
        0.0
    };
    // one flag per node, and a sink for the sentinel ([`Sweeper::activate`])
    let active: Vec<AtomicU8> = (0..=n).map(|_| AtomicU8::new(0)).collect();
    // the sweeps hold w = u − u₀ (the extension update reads no u₀, the inner one only to form u
    // for its ramps and the metric); the fixed nodes' given values are put back as they were
    let fixed_values: Vec<(usize, f64)> = roles
        .iter()
        .enumerate()
        .filter(|(_, &r)| r == NodeRole::Fixed)
        .map(|(i, _)| (i, values[i]))
        .collect();
    let mut pipeline = Pipeline::new(band, options.threads)?;
    for (v, &u0) in values.iter_mut().zip(sw.u0) {
        *v -= u0;
    }
    let mut stats = SecondOrderStats {
        last_change: f64::INFINITY,
        ..Default::default()
    };
    let mut iteration = 0;
    // one phase: the active flags from its start ([`Sweeper::start_flags`]), the thread choice's
    // timings forgotten after an earlier phase (an update of the other phase costs differently)
    let mut phase = |values: &mut [f64],
                     lim: Limits,
                     width: f64,
                     iteration: &mut usize,
                     stats: &mut SecondOrderStats,
                     options: &SecondOrderOptions| {
        if *iteration > 0 {
            pipeline.new_phase();
        }
        let first = match changed.take() {
            Some(c) => Some(sw.start_flags_changed(&active, values, c)),
            None => {
                sw.start_flags(&active, values);
                None
            }
        };
        let (run, state) = (
            RunPhase {
                sw: &sw,
                band,
                active: &active,
                row_inner: &row_inner,
                options,
            },
            &mut pipeline,
        );
        run_phase(&run, values, state, lim, width, first, iteration, stats, &mut *control)
    };
    // the phases; w back to u whatever their outcome (an interrupted solve's values included)
    let mut phases = || -> Result<()> {
        if options.own_first_phase && options.tol_first.is_finite() {
            let lim = Limits::first_order(options.tol_first);
            phase(
                values,
                lim,
                options.window_first * unit,
                &mut iteration,
                &mut stats,
                options,
            )?;
            stats.first_order_iterations = iteration;
        }
        let lim = Limits {
            second: true,
            decreases_only: false,
            threshold: options.tol,
            window: f64::INFINITY,
            settled: options.tol,
            floor: -floor,
        };
        let before = iteration;
        stats.converged = phase(
            values,
            lim,
            options.window_second * unit,
            &mut iteration,
            &mut stats,
            options,
        )?;
        stats.second_order_iterations = iteration - before;
        if stats.runaway_iteration.is_some() {
            // the second-order iterate is lost: the first phase again, from the sources (monotone,
            // so it converges), to the second phase's tolerance: its first-order values are the result
            from_the_sources(values, roles);
            // guarded as phase 2 is: where the factored update is not causal (a region far faster
            // than the sources) these sweeps creep down too; the caller then has no values
            let lim = Limits {
                floor: -floor,
                ..Limits::first_order(options.tol.min(options.tol_first))
            };
            let runaway = stats.runaway_iteration;
            let before = iteration;
            stats.converged = phase(
                values,
                lim,
                options.window_first * unit,
                &mut iteration,
                &mut stats,
                options,
            )?;
            stats.first_order_iterations += iteration - before;
            let restart_failed = stats.runaway_iteration != runaway;
            if restart_failed {
                // the first-order restart ran away as well: no values to return
                stats.runaway_iteration = runaway;
                stats.restart_failed = true;
                stats.converged = false;
            }
            if let Some(found) = found.as_deref_mut() {
                // where: the first-order restart's values far below the chord from the sources,
                // and where it crept, the nodes that still fall in a few more of its iterations
                // (behind no window)
                let crept = if restart_failed {
                    let before = values.to_vec();
                    let probe = SecondOrderOptions {
                        max_iterations: iteration + CREEP_PROBE,
                        ..*options
                    };
                    let lim = Limits::first_order(options.tol.min(options.tol_first));
                    let before_probe = iteration;
                    phase(values, lim, 0.0, &mut iteration, &mut stats, &probe)?;
                    stats.first_order_iterations += iteration - before_probe;
                    Some(before)
                } else {
                    None
                };
                *found = Demotion::of(values, crept.as_deref(), roles, floor);
            }
        }
        Ok(())
    };
    let outcome = phases();
    for (v, &u0) in values.iter_mut().zip(sw.u0) {
        *v += u0;
    }
    for (i, v) in fixed_values {
        values[i] = v;
    }
    outcome?;
    stats.unreached = values
        .iter()
        .zip(roles)
        .filter(|(v, &r)| r != NodeRole::Fixed && !v.is_finite())
        .count();
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(stats)
}
