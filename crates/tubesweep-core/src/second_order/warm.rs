//! Warm starts on a surface that moved (issue 47, docs/moving-surfaces.md): the second-order
//! sweeps of the moved surface's tube start from the previous solution's values instead of +∞.
//!
//! * [`carry_values`]: the previous values carried onto the new band. The solution in the tube is
//!   the normal extension of the surface solution (constant along the normals, the corrected
//!   equation |B∇u| = 1/F of [`super`]), so a node that lies in both bands keeps its value: the
//!   carried value differs from the new solution by the change of the surface solution at its foot
//!   point, O(the distance moved) — an initial guess, never taken as a result. A node new to the band
//!   starts at +∞ and the sweeps reach it from its neighbours.
//! * [`inner_components`]: the connected components of the inner tube (6- or 4-connected), to
//!   refuse a warm start across a change of topology (a component pinched off keeps finite carried
//!   values that no source supports).
//! * [`sweep_warm`]: the second-order phase (plain assignment, values may rise and fall) from the
//!   carried values, behind the cold solve's front window, and a cold solve instead when that
//!   phase leaves the path that the fixed-point argument covers.
//!
//! What a warm start saves is small with this scheme. A surface that moves by δ changes the
//! surface solution by O(δ) everywhere (a sphere grown by δ: every distance by the factor
//! 1 + δ/r), far above the stopping tolerance (≈ 5e-4Δx²), and phase 2 contracts such an error by
//! a factor of about 2.5 per iteration (the sphere → ellipsoid steps of 0.3Δx at N = 121: 4.7e-3,
//! 1.7e-3, 7.7e-4, ... 3.2e-7 in ten iterations). Without the window every node is then updated in
//! every sweep of those iterations: 2.5 times the cold solve's updates; behind the window, as many
//! as the cold solve's (the window, not the start, sets the cost), and from a start extrapolated
//! in time (two previous solutions, error O(δ²)) about three quarters of them.
//!
//! How close could a start be? `benches/experiments/warm_predictors.py` predicts each cold solution
//! of that sequence from the *cold* solutions of the steps before (the best a warm start could
//! have): carried, 44k tolerances off at the worst node (median 14k); extrapolated linearly, 5.6k–12k
//! (median 220); quadratically (three steps), 1.3k–6.5k (median 12–25), the worst at the
//! antipode, where the geodesics meet, and 60–75 % of the nodes common to the bands still more
//! than 10 tolerances off. So even that start needs about 8 iterations over the whole band (cold:
//! 19, 18 updates per band node): the sweeps alone would still cost about half of a cold solve.
//! The sweeps already visit only the nodes one of whose stencil's values changed by more than the
//! tolerance (the active flags of [`super::solver`]); from such a start they skip little.
//!
//! Where the surface moved only in part, a warm start does pay: given the previous solve's
//! digests ([`WarmStart::previous`], [`super::fingerprint`]), the sweeps start from the nodes
//! whose update changed and the nodes that read them, and the window from the smallest of their
//! values ([`super::active`]); every other node keeps the previous fixed point of its unchanged
//! update until a node it reads moves by more than the tolerance. Only what lies downstream of
//! the change is swept. Measured (`benches/moving_surfaces.py --local`, the sphere at N = 121, a
//! bump of 0.3Δx and radius 0.15 changing 2.6 % of the band's updates, the source at the north
//! pole): at the antipode 0.02 of the cold solve's updates, at the equator 0.06, next to the
//! source 0.20; `moved` and the solve together 0.23, 0.28 and 0.43 of a cold solve's time (the
//! rest is the tube and its geometry, built anew: some ten O(band) passes of 1–4 ms each at
//! N = 121, where reading a node's old and new φ to see whether it changed costs over half of
//! computing its direction), the values within 2.1, 3.0 and 11.0 tolerances of the cold solve's. The solves of a `ts.Tube` and warm solves compute and keep the
//! digests (a one-off `ts.solve` does not: 8 bytes per node would break issue 31's memory target):
//! one pass over the band, O(band).
//!
//! Tried and not kept: Gauss–Seidel passes in increasing order of the carried values before phase
//! 2 (a counting sort by value in buckets of σ̄Δx/20, then the phase-2 update node by node, like
//! fast marching with a known order), in the hope that one pass in a nearly causal order is
//! nearly final. The scheme is not causal in value order: the extension update averages the
//! neighbours of smaller |φ| whatever their values, the inner nodes at the tube's edge read
//! those extension nodes, and along the normals the values tie (the solution is constant along
//! them), so a stale neighbour across a tie feeds a node strongly. Even from the cold solution
//! itself raised by 0.5Δx (an upper start, the exact order) one pass left the inner nodes' median
//! error at 0.043Δx and the extension layer's largest at 0.81Δx (sphere → ellipsoid at N = 61).
//! From the carried values (step 2 of 5) the median error went 0.23Δx → 0.092, 0.045, 0.015Δx
//! after 1, 2, 3 passes — 2–2.5 times per pass, as per iteration of 2^D sweeps — and the largest
//! 0.81Δx → 0.74, 0.97, 0.51Δx. Warm solves with 1 to 16 such passes before phase 2 took 1.2 to
//! 1.8 times a cold solve (1.1 without them, same runs): the passes are sequential and walk the
//! memory out of order, and phase 2 still needs several iterations after them. Refreshing the
//! extension nodes right after each node they read, or ordering by u + c|φ|, did worse.
//!
//! Why the warm start reaches the cold solve's fixed point (to the path dependence that the
//! second-order fixed point has anyway: the kink tests of the BDF2 and BDF3 ramps read the
//! node's own value, so two cold solves that differ only in their window differ by a few stopping
//! tolerances, see
//! [`super::solver`]'s tests). The cold solve's phase 1 (when it runs)
//! is monotone — a value is only replaced by a smaller one — so a start below the solution would stick
//! there; phase 2 is plain assignment u_i ← S_i(u), S_i the limited update, which reads the node's
//! own value only to choose which sides are upwind and in the kink tests, none of which moves
//! the fixed point (see [`super::solver`]'s `Sweeper::inner`). The warm solve runs phase 2 alone.
//! A value too *high* comes down as soon as an upwind neighbour is right (the Godunov update is
//! the smallest root over the upwind sides); a value too *low* cannot hold itself up: the
//! smallest of a set of values below the solution is updated from neighbours no smaller than
//! itself and rises by at least σΔx/√D per visit (the first-order part of every update), so the
//! set empties in finitely many sweeps, unless a component carries no source (its values then
//! rise without end — refused by [`inner_components`]). Two safeguards of phase 2 leave that
//! argument: the stagnation test switches to decreases only, which would freeze a value still
//! too low, and the runaway guard; when either fires, [`sweep_warm`] solves again cold, so the
//! result is always a cold fixed point. Measured (benches/moving_surfaces.py): warm and cold
//! values agree to within the stopping tolerance's order (docs/moving-surfaces.md has the figures).

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::{Control, IterationReport, NodeRole, Slowness};
use crate::union_find::SmallestRoot;

use super::factoring::Factoring;
use super::fingerprint::changed_nodes;
use super::geometry::TubeGeometry;
use super::solver::{sweep_second_order_from, sweep_second_order_reporting, SecondOrderOptions, SecondOrderStats};

/// The previous values on the new band: node `new_linear[i]` takes `old_values[j]` where
/// `old_linear[j]` is the same grid node, +∞ where the node is new to the band. Both index lists
/// are sorted (the bands' order); one merge, O(both bands).
pub fn carry_values(old_linear: &[u64], old_values: &[f64], new_linear: &[u64]) -> Result<Vec<f64>> {
    if old_linear.len() != old_values.len() {
        return Err(Error::invalid(
            "warm",
            format!(
                "one previous value per previous band node is needed ({} nodes, {} values)",
                old_linear.len(),
                old_values.len()
            ),
        ));
    }
    if old_linear.windows(2).any(|w| w[0] >= w[1]) || new_linear.windows(2).any(|w| w[0] >= w[1]) {
        return Err(Error::invalid("warm", "band indices must be sorted and distinct"));
    }
    let mut out = Vec::with_capacity(new_linear.len());
    let mut j = 0;
    for &l in new_linear {
        while j < old_linear.len() && old_linear[j] < l {
            j += 1;
        }
        out.push(if j < old_linear.len() && old_linear[j] == l {
            old_values[j]
        } else {
            f64::INFINITY
        });
    }
    Ok(out)
}

/// The number of connected components of the nodes with `select` (neighbours along the axes), by
/// union–find over the band's neighbour table: O(band).
pub fn inner_components<const D: usize>(band: &NarrowBand<D>, select: &[bool]) -> Result<usize> {
    let labels = component_labels(band, select)?;
    Ok((0..labels.len())
        .filter(|&i| select[i] && labels[i] == i as u32)
        .count())
}

/// The connected component of each node with `select` (neighbours along the axes): the smallest
/// band position in it, `u32::MAX` for the nodes not selected. Union–find over the band's
/// neighbour table, O(band); a cut edge (`crate::band::cut_edges`) joins nothing.
pub fn component_labels<const D: usize>(band: &NarrowBand<D>, select: &[bool]) -> Result<Vec<u32>> {
    let n = band.len();
    if select.len() != n {
        return Err(Error::invalid(
            "select",
            format!("one flag per band node ({n}) is needed"),
        ));
    }
    let mut sets = SmallestRoot::new(n);
    let sentinel = band.sentinel();
    for i in 0..n {
        if !select[i] {
            continue;
        }
        // the neighbours at +e_k suffice: each pair is met once from its lower node
        for nb in band.neighbours_of(i) {
            let j = nb[1];
            if j == sentinel || !select[j as usize] {
                continue;
            }
            // the smaller root stays: a component's root is its smallest position
            sets.join(i as u32, j);
        }
    }
    Ok((0..n)
        .map(|i| if select[i] { sets.root(i as u32) } else { u32::MAX })
        .collect())
}

/// Why a warm solve was solved again cold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WarmRestart {
    /// The stagnation safeguard fired (decreases only could freeze a value below the solution).
    Stagnation,
    /// The runaway guard fired.
    Runaway,
}

/// What [`sweep_warm`] did.
#[derive(Debug, Clone)]
pub struct WarmStats {
    pub stats: SecondOrderStats,
    /// Nodes that started from a carried value (the others: +∞, or u₀ at the fixed nodes).
    pub carried: usize,
    /// Set when the warm sweeps were abandoned for a cold solve.
    pub restarted: Option<WarmRestart>,
    /// Nodes whose update differs from the previous solve's ([`super::fingerprint`]), when the
    /// previous digests were given: the sweeps started from them and the nodes that read them.
    pub changed: Option<usize>,
    /// Nodes whose start was extrapolated in time from two previous solutions.
    pub extrapolated: usize,
    /// The inner-tube nodes that a runaway of the cold solve left at first order (band
    /// positions, [`super::demotion`]; the warm sweeps themselves start again cold instead).
    pub demoted: Vec<u32>,
}

/// Where a warm solve starts ([`sweep_warm`]).
#[derive(Debug, Clone, Copy)]
pub struct WarmStart<'a> {
    /// The previous values on this band ([`carry_values`]).
    pub carried: &'a [f64],
    /// The values of the solve before that on this band: the start is then extrapolated in time,
    /// 2·carried − older, where both have a value (at the changed nodes only, when `previous` is
    /// given: the others keep their fixed point).
    pub older: Option<&'a [f64]>,
    /// The previous band's grid positions and digests, and this band's digests
    /// ([`super::fingerprint::node_fingerprints`]): the sweeps then start from the nodes whose update
    /// changed ([`super::fingerprint::changed_nodes`]) instead of from every node.
    pub previous: Option<(&'a [u64], &'a [u64], &'a [u64])>,
}

impl<'a> WarmStart<'a> {
    /// A start from `carried` alone: every node active.
    pub fn carried(carried: &'a [f64]) -> Self {
        WarmStart {
            carried,
            older: None,
            previous: None,
        }
    }
}

/// The second-order solve from `start` ([`carry_values`] on this band): the fixed nodes at u₀,
/// the others at their carried (or extrapolated) value, then phase 2 alone behind the cold solve's
/// window (`cold_options.window_second`), from every node or, given the previous digests, from
/// the nodes whose update changed and their readers (the window from the smallest of their
/// values); when a safeguard fires, the cold solve of `cold_options` from the fixed nodes (see
/// the module documentation). `values` gets the result.
#[allow(clippy::too_many_arguments)]
pub fn sweep_warm<const D: usize>(
    band: &NarrowBand<D>,
    geometry: &TubeGeometry,
    factoring: &Factoring<D>,
    directions: &[[f32; D]],
    slowness: Slowness<'_>,
    spacing: f64,
    start: &WarmStart<'_>,
    values: &mut Vec<f64>,
    cold_options: &SecondOrderOptions,
    control: &mut dyn FnMut(&IterationReport) -> Control,
) -> Result<WarmStats> {
    let n = band.len();
    let carried = start.carried;
    if carried.len() != n || start.older.is_some_and(|o| o.len() != n) {
        return Err(Error::invalid(
            "warm",
            format!("one carried value per band node ({n}) is needed, got {}", carried.len()),
        ));
    }
    let changed = match start.previous {
        Some((old_linear, old_digests, digests)) => {
            if digests.len() != n {
                return Err(Error::invalid(
                    "warm",
                    format!("one digest per band node ({n}) is needed"),
                ));
            }
            Some(changed_nodes(old_linear, old_digests, &band.linear_indices(), digests)?)
        }
        None => None,
    };
    let (mut count, mut extrapolated) = (0, 0);
    values.clear();
    for i in 0..n {
        let c = carried[i];
        values.push(if factoring.roles[i] == NodeRole::Fixed {
            factoring.u0[i]
        } else if c.is_finite() {
            count += 1;
            let moved = changed.as_ref().is_none_or(|(flags, _)| flags[i]);
            let c = match start.older.map(|o| o[i]) {
                Some(o) if moved && o.is_finite() => {
                    extrapolated += 1;
                    2.0 * c - o
                }
                _ => c,
            };
            // never below the factored part's share at a node next to a source
            c.max(0.0)
        } else {
            f64::INFINITY
        });
    }
    let warm_options = SecondOrderOptions {
        tol_first: f64::INFINITY,
        window_first: 0.0,
        ..*cold_options
    };
    let stats = sweep_second_order_from(
        band,
        (geometry, factoring, directions, slowness),
        spacing,
        values,
        &warm_options,
        changed.as_ref().map(|(flags, _)| &flags[..]),
        control,
        None,
    )?;
    let restarted = if stats.runaway_iteration.is_some() {
        Some(WarmRestart::Runaway)
    } else if stats.fallback_iteration.is_some() {
        Some(WarmRestart::Stagnation)
    } else {
        None
    };
    let changed = changed.map(|(_, c)| c);
    if restarted.is_none() {
        return Ok(WarmStats {
            stats,
            carried: count,
            restarted,
            changed,
            extrapolated,
            demoted: Vec::new(),
        });
    }
    *values = super::starting_values(factoring);
    let (mut cold, demoted) = sweep_second_order_reporting(
        (band, geometry, factoring, directions, slowness),
        spacing,
        values,
        cold_options,
        control,
    )?;
    cold.updates += stats.updates;
    cold.seconds += stats.seconds;
    cold.second_order_iterations += stats.second_order_iterations;
    Ok(WarmStats {
        stats: cold,
        carried: count,
        restarted,
        changed,
        extrapolated,
        demoted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::second_order::sweep_second_order;

    #[test]
    fn carried_values_follow_the_grid_nodes() {
        let old = [2u64, 5, 7, 9];
        let vals = [0.2, 0.5, 0.7, 0.9];
        let got = carry_values(&old, &vals, &[1, 5, 6, 9, 10]).unwrap();
        assert_eq!(got[1], 0.5);
        assert_eq!(got[3], 0.9);
        assert!(got[0].is_infinite() && got[2].is_infinite() && got[4].is_infinite());
        assert!(carry_values(&[3, 2], &[0.0, 0.0], &[1]).is_err());
        assert!(carry_values(&[2], &[0.0, 0.0], &[1]).is_err());
    }

    #[test]
    fn components_of_two_shells_are_two() {
        let (band, roles, _, _) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let select: Vec<bool> = roles.iter().map(|&r| r != NodeRole::Outer).collect();
        assert_eq!(inner_components(&band, &select).unwrap(), 1);
        // split the band by a slab of unselected nodes: the shell's inner tube cut at |z| small
        let idx = band.indices();
        let cut: Vec<bool> = select
            .iter()
            .zip(&idx)
            .map(|(&s, i)| s && (i[2] as i64 - 20).abs() > 1)
            .collect();
        assert_eq!(inner_components(&band, &cut).unwrap(), 2);
        // each node's label is the smallest position of its component, u32::MAX off the selection
        let labels = component_labels(&band, &cut).unwrap();
        let north: Vec<usize> = (0..idx.len()).filter(|&i| cut[i] && idx[i][2] > 20).collect();
        let south: Vec<usize> = (0..idx.len()).filter(|&i| cut[i] && idx[i][2] < 20).collect();
        assert!(south.iter().all(|&i| labels[i] == south[0] as u32));
        assert!(north.iter().all(|&i| labels[i] == north[0] as u32));
        assert!((0..idx.len()).all(|i| cut[i] || labels[i] == u32::MAX));
        assert!(component_labels(&band, &cut[1..]).is_err());
    }

    /// A cold solve on the sphere of radius `r` (n³ nodes over [−1, 1]³, source on the −x axis):
    /// the band's linear indices, its values, and what a warm solve on it needs.
    struct Sphere {
        band: NarrowBand<3>,
        geo: TubeGeometry,
        fac: Factoring<3>,
        dirs: Vec<[f32; 3]>,
        h: f64,
        options: SecondOrderOptions,
    }

    fn sphere(n: usize, r: f64) -> Sphere {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(n, r, &[0.0]);
        let phi: Vec<f64> = band
            .indices()
            .iter()
            .map(|i| {
                let x = [-1.0 + h * i[0] as f64, -1.0 + h * i[1] as f64, -1.0 + h * i[2] as f64];
                (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - r
            })
            .collect();
        let geo = super::super::tube_geometry(&band, &roles, &phi, &dirs, h, 4.0 * h).unwrap();
        let fac = super::super::factor_sources(
            &band,
            &roles,
            &phi,
            &dirs,
            [-1.0; 3],
            h,
            &[[-r, 0.0, 0.0]],
            &[1.0],
            2.0 * h,
        )
        .unwrap();
        let options = SecondOrderOptions {
            tol_first: f64::INFINITY,
            tol: 5e-4 * h * h,
            max_iterations: 500,
            stall_ratio: crate::second_order::STALL_RATIO,
            stall_window: 20,
            own_first_phase: true,
            window_first: 2.0,
            window_second: 2.0,
            extension_limit: 2.0,
            threads: 1,
            ramp_length: 1.0,
        };
        Sphere {
            band,
            geo,
            fac,
            dirs,
            h,
            options,
        }
    }

    fn cold(s: &Sphere) -> (Vec<f64>, SecondOrderStats) {
        let mut v = super::super::starting_values(&s.fac);
        let st = sweep_second_order(
            &s.band,
            &s.geo,
            &s.fac,
            &s.dirs,
            Slowness::Constant(1.0),
            s.h,
            &mut v,
            &s.options,
            &mut |_| Control::Continue,
        )
        .unwrap();
        (v, st)
    }

    #[test]
    fn a_warm_solve_on_a_grown_sphere_reaches_the_cold_values() {
        // the sphere of radius 0.5 grown by 0.4Δx: the warm solve from the old values equals the
        // cold solve on the new band to a few stopping tolerances
        let n = 61;
        let old = sphere(n, 0.5);
        let (old_values, _) = cold(&old);
        let new = sphere(n, 0.5 + 0.4 * old.h);
        let (cold_values, cold_stats) = cold(&new);
        let carried = carry_values(&old.band.linear_indices(), &old_values, &new.band.linear_indices()).unwrap();
        let mut warm_values = Vec::new();
        let warm = sweep_warm(
            &new.band,
            &new.geo,
            &new.fac,
            &new.dirs,
            Slowness::Constant(1.0),
            new.h,
            &WarmStart::carried(&carried),
            &mut warm_values,
            &new.options,
            &mut |_| Control::Continue,
        )
        .unwrap();
        assert!(warm.restarted.is_none() && warm.stats.converged, "{warm:?}");
        assert!(
            warm.carried > 9 * new.band.len() / 10,
            "{} of {}",
            warm.carried,
            new.band.len()
        );
        let tol = new.options.tol;
        let worst = warm_values
            .iter()
            .zip(&cold_values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 10.0 * tol, "warm − cold max {worst:.3e}, tol {tol:.3e}");
        // behind the window the warm start costs about what the cold solve does (module docs)
        assert!(
            (warm.stats.updates as f64) < 1.3 * cold_stats.updates as f64,
            "{} warm updates, {} cold",
            warm.stats.updates,
            cold_stats.updates
        );
    }

    #[test]
    fn values_carried_too_low_rise_to_the_cold_values() {
        // the fixed-point argument's hard case: every carried value 3Δx below the solution (the
        // monotone first phase would keep them); phase 2 alone brings them up
        let s = sphere(41, 0.5);
        let (cold_values, _) = cold(&s);
        let low: Vec<f64> = cold_values.iter().map(|v| (v - 3.0 * s.h).max(0.0)).collect();
        let mut warm_values = Vec::new();
        let warm = sweep_warm(
            &s.band,
            &s.geo,
            &s.fac,
            &s.dirs,
            Slowness::Constant(1.0),
            s.h,
            &WarmStart::carried(&low),
            &mut warm_values,
            &s.options,
            &mut |_| Control::Continue,
        )
        .unwrap();
        // converged on the assignment path, without a restart from the sources
        assert!(warm.stats.converged && warm.restarted.is_none(), "{warm:?}");
        let worst = warm_values
            .iter()
            .zip(&cold_values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 10.0 * s.options.tol,
            "max {worst:.3e}, tol {:.3e}, {warm:?}",
            s.options.tol
        );
    }

    #[test]
    fn a_warm_solve_on_an_unchanged_tube_keeps_the_values_bit_for_bit() {
        // the same surface again: every digest agrees, no node starts active, and the previous
        // values are the result without an update
        let s = sphere(41, 0.5);
        let (values, _) = cold(&s);
        let digests = crate::second_order::fingerprint::node_fingerprints(
            &s.band,
            &s.geo,
            &s.fac,
            &s.dirs,
            Slowness::Constant(1.0),
        )
        .unwrap();
        let again = sphere(41, 0.5);
        let digests_again = crate::second_order::fingerprint::node_fingerprints(
            &again.band,
            &again.geo,
            &again.fac,
            &again.dirs,
            Slowness::Constant(1.0),
        )
        .unwrap();
        assert_eq!(digests, digests_again);
        let linear = s.band.linear_indices();
        let mut out = Vec::new();
        let start = WarmStart {
            carried: &values,
            older: Some(&values),
            previous: Some((&linear, &digests, &digests_again)),
        };
        let warm = sweep_warm(
            &again.band,
            &again.geo,
            &again.fac,
            &again.dirs,
            Slowness::Constant(1.0),
            again.h,
            &start,
            &mut out,
            &again.options,
            &mut |_| Control::Continue,
        )
        .unwrap();
        assert_eq!(warm.changed, Some(0));
        assert_eq!(warm.extrapolated, 0);
        assert_eq!(warm.stats.updates, 0);
        assert!(warm.stats.converged);
        assert!(out.iter().zip(&values).all(|(a, b)| a.to_bits() == b.to_bits()));
        // a grown sphere changes every node's digest
        let grown = sphere(41, 0.5 + 0.3 * s.h);
        let d = crate::second_order::fingerprint::node_fingerprints(
            &grown.band,
            &grown.geo,
            &grown.fac,
            &grown.dirs,
            Slowness::Constant(1.0),
        )
        .unwrap();
        let (_, count) =
            crate::second_order::fingerprint::changed_nodes(&linear, &digests, &grown.band.linear_indices(), &d)
                .unwrap();
        assert_eq!(count, grown.band.len());
    }
}
