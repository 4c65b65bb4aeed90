//! One phase of the second-order sweeps ([`super::solver`]): its iterations behind the front
//! window, the stagnation and limit-cycle tests once the window is open, and the runaway test.

use std::sync::atomic::AtomicU8;

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::sweep_state::{Accumulator, SharedValues};
use crate::sweep::{Control, IterationReport, NodeRole};

use super::pipeline::Pipeline;
use super::rows::{Isa, RowWalk, RowsState};
use super::solver::{Limits, SecondOrderOptions, SecondOrderStats, Sweeper};
use super::stagnation::{creeping, in_a_limit_cycle, stalled};

/// The front window opens fully when its edge has not moved for this many iterations.
const WINDOW_PATIENCE: usize = 10;

/// Iterations that accept decreases only (after the stagnation fallback, or a monotone phase)
/// whose changes stall ([`stalled`]) at more than this many stopping tolerances are a runaway
/// creeping down: values that only fall, by about the same amount iteration after iteration,
/// settle nowhere above the runaway floor (a surface with a region 70–1000 times faster than the
/// source's, where the factored update is not causal: the sphere at N = 41 crept for 10,000
/// iterations and 68 s before the floor). A stall at the values' round-off stays far below it
/// (the sphere at N = 41 with `tol = 1e-16`: 2e-14, 200 tolerances).
pub(super) const CREEP_TOLERANCES: f64 = 1e4;

/// What a phase's iterations read besides the values.
pub(super) struct RunPhase<'r, 'a, const D: usize> {
    pub(super) sw: &'r Sweeper<'a, D>,
    pub(super) band: &'r NarrowBand<D>,
    pub(super) active: &'r [AtomicU8],
    pub(super) row_inner: &'r [u32],
    pub(super) options: &'r SecondOrderOptions,
}

/// One phase's iterations (each the 2^D sweeps) until the largest change of an iteration with the
/// window fully open is below `lim.settled`; returns whether it got there. With a positive
/// `window_width` the sweeps leave out the nodes whose value lies beyond an edge that starts at
/// the smallest fixed value plus the width and moves on to the iteration's front (the smallest value that
/// still changed by more than `settled`) plus the width, or on by a width to the nearest node
/// left out when nothing in the window moved; it opens fully when no node was left out, or when
/// the edge has not moved for [`WINDOW_PATIENCE`] iterations. Once it is open, the stagnation test
/// of the second-order phase applies (see [`super::solver`]'s module documentation).
///
/// `first`: where the window starts (the smallest value among the active nodes of a warm start
/// on a surface that moved in part); None: at the smallest fixed value.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_phase<const D: usize>(
    run: &RunPhase<'_, '_, D>,
    values: &mut [f64],
    pipeline: &mut Pipeline,
    mut lim: Limits,
    window_width: f64,
    first: Option<f64>,
    iteration: &mut usize,
    stats: &mut SecondOrderStats,
    control: &mut dyn FnMut(&IterationReport) -> Control,
) -> Result<bool> {
    let RunPhase {
        sw,
        band,
        active,
        row_inner,
        options,
    } = *run;
    let tol = lim.settled;
    if window_width > 0.0 {
        let first = first.unwrap_or_else(|| {
            values
                .iter()
                .zip(sw.u0)
                .zip(sw.roles)
                .filter(|(_, &r)| r == NodeRole::Fixed)
                .map(|((&w, &u0), _)| w + u0)
                .fold(f64::INFINITY, f64::min)
        });
        lim.window = first + window_width;
    }
    let rows_state = RowsState::new(band, values, sw.u0);
    let isa = Isa::for_this_solve();
    let shared = SharedValues::new(values);
    // the largest change of each iteration since the window opened (the stagnation test's and the
    // limit cycles', `in_a_limit_cycle`)
    let mut changes: Vec<f64> = Vec::new();
    // the largest change of each iteration that accepted decreases only, the window open (the
    // creep test, [`CREEP_TOLERANCES`])
    let mut decreases: Vec<f64> = Vec::new();
    let mut unmoved = 0usize;
    while *iteration < options.max_iterations {
        *iteration += 1;
        let lim_now = lim;
        let run_rows = |rows: &[u32], backwards: bool| -> Accumulator {
            let walk = RowWalk {
                sw,
                band,
                rows_state: &rows_state,
                shared: &shared,
                active,
                row_inner,
                lim: lim_now,
            };
            walk.run(isa, rows, backwards)
        };
        let change = pipeline.iteration(band, &run_rows);
        stats.updates += change.updates;
        stats.last_change = change.max_change;
        if control(&IterationReport {
            iteration: *iteration,
            max_change: change.max_change,
            updates: change.updates,
        }) == Control::Stop
        {
            return Err(Error::Interrupted { iterations: *iteration });
        }
        // `front` is the smallest value that changed by more than `settled`: a runaway's values
        // fall by ever larger steps, so it is among them
        if change.front < lim.floor {
            stats.runaway_iteration = Some(*iteration - stats.first_order_iterations);
            return Ok(false);
        }
        changes.push(change.max_change);
        let cycling = lim.second && !lim.decreases_only && in_a_limit_cycle(&changes);
        if lim.window == f64::INFINITY {
            if change.max_change < tol {
                return Ok(true);
            }
            if lim.decreases_only {
                decreases.push(change.max_change);
                let floor = CREEP_TOLERANCES * tol;
                if creeping(&decreases, options.stall_window, options.stall_ratio, floor) {
                    stats.runaway_iteration = Some(*iteration - stats.first_order_iterations);
                    return Ok(false);
                }
            }
            if lim.second
                && !lim.decreases_only
                && (cycling || stalled(&changes, options.stall_window, options.stall_ratio))
            {
                lim.decreases_only = true;
                stats.fallback_iteration = Some(*iteration - stats.first_order_iterations);
                // how far from settled the iterate was: the largest change of the stall's window
                // (the finite ones: a node first reached in it changed from +∞, which says
                // nothing of how far the values were from settled — a coarse torus mesh at
                // N = 81 warned "up to inf")
                let w = options.stall_window.min(changes.len());
                stats.fallback_change = Some(settled_distance(&changes[changes.len() - w..]));
            }
        } else if cycling {
            // the window cannot move past a cycle: open it, for the cycle to be ended there
            lim.window = f64::INFINITY;
            changes.clear();
        } else {
            let edge = if change.waiting == f64::INFINITY {
                f64::INFINITY
            } else if change.front < f64::INFINITY {
                lim.window.max(change.front + window_width)
            } else {
                (lim.window + window_width).max(change.waiting + window_width)
            };
            unmoved = if edge > lim.window { 0 } else { unmoved + 1 };
            lim.window = if unmoved >= WINDOW_PATIENCE {
                f64::INFINITY
            } else {
                edge
            };
            if lim.window == f64::INFINITY {
                changes.clear();
            }
        }
    }
    Ok(false)
}

/// The largest finite change of `window` (a stall's iterations), +∞ when none is finite.
fn settled_distance(window: &[f64]) -> f64 {
    window
        .iter()
        .copied()
        .filter(|c| c.is_finite())
        .reduce(f64::max)
        .unwrap_or(f64::INFINITY)
}

#[cfg(test)]
mod settled_tests {
    use super::settled_distance;

    #[test]
    fn a_first_reached_node_does_not_make_the_distance_infinite() {
        assert_eq!(settled_distance(&[1e-6, f64::INFINITY, 3e-6, 2e-6]), 3e-6);
        assert_eq!(settled_distance(&[f64::INFINITY]), f64::INFINITY);
        assert_eq!(settled_distance(&[0.0, 0.0]), 0.0);
    }
}
