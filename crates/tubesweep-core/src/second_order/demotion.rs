//! A runaway's nodes at first order. Where the factored update is not causal — the chord u₀ of
//! [`super::factoring`] read through closest points that do not follow one smooth surface (a
//! point cloud's fits bridging a hole in its samples: the Stanford bunny's vertices at N = 101
//! crept down by 0.3Δx every iteration over the largest hole in its base), or a region far faster
//! than the sources — the second-order sweeps run away and the first-order factored restart can
//! creep after them. Those nodes are found from the iterates ([`Demotion::of`]), and the solve is
//! done again from the sources with only them at first order: the paper's update on u itself
//! (Eq. (3), unfactored, B = I), which is monotone and causal, as at any node whose geometry is
//! not resolved ([`super::geometry::Unresolved::Runaway`]); everywhere else second order.

use crate::error::Result;
use crate::sweep::{Control, IterationReport, NodeRole};

use super::attempt::{from_the_sources, Attempts};
use super::geometry::{NodeGeometry, Unresolved};
use super::solver::{SecondOrderOptions, SecondOrderStats};

/// The solve is done again only where second order keeps more than a third of the inner tube
/// (`benches/experiments/runaway_demotion.py`): with the fast half of a circle or a sphere at
/// first order (50–58% of the tube) the largest errors were 10–200 times smaller than the paper's
/// scheme's, which the solve returned before; with a source beside the fast half (70–75%: the
/// chord from the source no estimate of the travel times on most of the circle) 15–50% larger;
/// with a source inside a small region 100 times slower than the rest of the sphere, 99%. Beyond
/// this share the first attempt's result stands (the paper's scheme where its restart ran away).
pub(super) const DEMOTED_SHARE: f64 = 0.65;

/// The first-order restart's iterations run after it crept, to see which nodes still fall.
pub(super) const CREEP_PROBE: usize = 2;

/// A fall in the probe's iterations larger than this fraction of the runaway floor (σ̄Δx) marks
/// a creeping node (a converging first-order iterate falls by less than the stopping tolerance,
/// ≪ Δx², by then).
const CREEP_FALL: f64 = 1e-3;

/// The nodes a runaway found.
#[derive(Debug, Default)]
pub(super) struct Demotion {
    nodes: Vec<bool>,
    pub(super) count: usize,
    /// The node that fell farthest (band index).
    pub(super) deepest: Option<usize>,
}

impl Demotion {
    /// The nodes (not fixed) where the first-order restart's iterate `values` (w = u − u₀) lies
    /// more than `floor` below zero — u more than σ̄Δx below the chord u₀ from the sources, which
    /// a solution only does where the front went faster than at the sources (the chord is then
    /// no estimate of the travel time, and its gradient drives the factored update the wrong way)
    /// — and, where the restart crept (`crept`, its iterate before the probe iterations), those
    /// that fell by more than [`CREEP_FALL`]·`floor` in the probe.
    pub(super) fn of(values: &[f64], crept: Option<&[f64]>, roles: &[NodeRole], floor: f64) -> Self {
        let restart = crept.unwrap_or(values);
        let mut nodes = vec![false; values.len()];
        let (mut count, mut deepest, mut fell_most) = (0, None, 0.0);
        for (i, &role) in roles.iter().enumerate() {
            if role == NodeRole::Fixed {
                continue;
            }
            let mut fell = 0.0f64;
            if restart[i] < -floor {
                fell = -restart[i];
            }
            if let Some(before) = crept {
                let probe = before[i] - values[i];
                if before[i].is_finite() && values[i].is_finite() && probe > CREEP_FALL * floor {
                    fell = fell.max(probe);
                }
            }
            if fell > 0.0 {
                nodes[i] = true;
                count += 1;
                if fell > fell_most {
                    (fell_most, deepest) = (fell, Some(i));
                }
            }
        }
        Demotion { nodes, count, deepest }
    }

    /// Per band node, whether it was found (an extension node found extends u instead of w).
    pub(super) fn nodes(&self) -> &[bool] {
        &self.nodes
    }

    /// `geometry` (one entry per node not in the extension layer, in band order) with the found
    /// nodes at first order; `positions` gets the band positions of those whose update was second
    /// order.
    pub(super) fn demoted<const D: usize>(
        &self,
        geometry: &[NodeGeometry],
        roles: &[NodeRole],
        positions: &mut Vec<u32>,
    ) -> Vec<NodeGeometry> {
        positions.clear();
        let mut out = geometry.to_vec();
        let inner = roles.iter().enumerate().filter(|(_, &r)| r != NodeRole::Outer);
        for ((i, _), g) in inner.zip(out.iter_mut()) {
            if self.nodes[i] && g.first_order() == 0 {
                *g = g.at_first_order::<D>(Unresolved::Runaway);
                positions.push(i as u32);
            }
        }
        out
    }
}

/// The two phases on `values` (see [`super::solver::sweep_second_order_from`]) and, where they
/// run away, once more from the sources with the runaway's nodes at first order
/// ([`Demotion::of`]), phase 1 included, within the iterations left, the progress counting on;
/// `demoted` gets the band positions of the inner-tube nodes so put. The first attempt's result
/// stands (`demoted` empty) when no node was found, when its restart stopped at the iteration
/// limit, when more than [`DEMOTED_SHARE`] of the inner tube would be put at first order, or when
/// the second attempt runs away too.
pub(super) fn solve_demoting<const D: usize>(
    run: &Attempts<'_, '_, D>,
    values: &mut [f64],
    changed: Option<&[bool]>,
    control: &mut dyn FnMut(&IterationReport) -> Control,
    demoted: &mut Vec<u32>,
) -> Result<SecondOrderStats> {
    let options = run.options;
    let mut found = Demotion::default();
    let first = run.run(None, values, options, changed, control, (&[], Some(&mut found)))?;
    demoted.clear();
    // (a restart stopped by max_iterations found its nodes from a partial iterate, and leaves
    // fewer iterations than it had for a second attempt)
    let stopped = !first.converged && !first.restart_failed;
    if first.runaway_iteration.is_none() || found.count == 0 || stopped {
        return Ok(first);
    }
    let (factoring, _, _) = run.sw;
    let geometry = found.demoted::<D>(run.tube.0, &factoring.roles, demoted);
    if demoted.len() as f64 > DEMOTED_SHARE * geometry.len() as f64 {
        demoted.clear();
        return Ok(first);
    }
    // the first attempt's values, returned as they are if the second runs away too
    let first_values = values.to_vec();
    from_the_sources(values, &factoring.roles);
    let used = first.first_order_iterations + first.second_order_iterations;
    let again = SecondOrderOptions {
        max_iterations: options.max_iterations.saturating_sub(used),
        own_first_phase: true,
        ..*options
    };
    let mut shifted = |r: &IterationReport| {
        control(&IterationReport {
            iteration: r.iteration + used,
            ..*r
        })
    };
    let mut stats = run.run(
        Some(&geometry),
        values,
        &again,
        None,
        &mut shifted,
        (found.nodes(), None),
    )?;
    if stats.runaway_iteration.is_some() {
        values.copy_from_slice(&first_values);
        demoted.clear();
        return Ok(SecondOrderStats {
            updates: first.updates + stats.updates,
            seconds: first.seconds + stats.seconds,
            ..first
        });
    }
    stats.first_order_iterations += first.first_order_iterations;
    stats.second_order_iterations += first.second_order_iterations;
    stats.updates += first.updates;
    stats.seconds += first.seconds;
    stats.demoted_nodes = demoted.len();
    stats.demoted_at = found.deepest;
    stats.demoted_runaway_iteration = first.runaway_iteration;
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    const I: NodeRole = NodeRole::Inner;
    const O: NodeRole = NodeRole::Outer;
    const F: NodeRole = NodeRole::Fixed;

    #[test]
    fn the_nodes_below_the_chord_or_still_falling_are_found_and_no_fixed_node() {
        let roles = [F, I, I, O, I, I];
        let floor = 1.0;
        // the restart's w: node 2 more than the floor below the chord; node 0 farther but fixed,
        // node 4 just above the floor, node 5 unreached; no creep
        let values = [-5.0, 0.3, -1.5, -0.2, -0.99, f64::INFINITY];
        let d = Demotion::of(&values, None, &roles, floor);
        assert_eq!(d.nodes(), &[false, false, true, false, false, false]);
        assert_eq!((d.count, d.deepest), (1, Some(2)));
        // where it crept: the nodes that fell by more than CREEP_FALL·floor in the probe (the
        // extension layer's node 3 too; node 1 by half that)
        let before = [-5.0, 0.3, -1.5, 0.0, -0.5, 2.0];
        let after = [-9.0, 0.3 - 0.5 * CREEP_FALL, -1.5, -0.4, -0.5, 1.0];
        let d = Demotion::of(&after, Some(&before), &roles, floor);
        assert_eq!(d.nodes(), &[false, false, true, true, false, true]);
        assert_eq!((d.count, d.deepest), (3, Some(2)));
    }

    #[test]
    fn the_found_inner_nodes_run_first_order_and_are_listed() {
        let roles = [I, O, I, F];
        let resolved = NodeGeometry::resolved_for_tests();
        // one geometry per node not in the extension layer: nodes 0, 2 and 3
        let geometry = [resolved.at_first_order::<3>(Unresolved::Curvature), resolved, resolved];
        let d = Demotion {
            nodes: vec![true, true, true, false],
            count: 3,
            deepest: Some(2),
        };
        let mut positions = Vec::new();
        let out = d.demoted::<3>(&geometry, &roles, &mut positions);
        // node 0 was first order already (its reason kept), node 2 is put at first order, node 3
        // (not found) keeps its geometry
        assert_eq!(positions, vec![2]);
        assert_eq!(out[0].first_order(), Unresolved::Curvature as u8);
        assert_eq!(out[1].first_order(), Unresolved::Runaway as u8);
        assert_eq!(out[1].normal, geometry[1].normal);
        assert_eq!((out[1].b(0), out[1].b(1), out[1].b(3)), (1.0, 0.0, 1.0));
        assert_eq!(out[2], geometry[2]);
    }
}
