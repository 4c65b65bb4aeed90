//! Second-order accuracy on surfaces (`order=2`, docs/second-order.md): the scheme "S2".
//!
//! The paper's tube equation, |∇u| = 1/F at every inner-tube node (its Sect. 4 with Eq. (3)),
//! is a *model* error of size φκ = O(Δx) off the surface, so no stencil makes it second order.
//! This module solves instead the metric-corrected equation |B∇u| = 1/F, B = (I − φD²φ)⁻¹,
//! whose exact solution in the tube is the normal extension of the surface solution, with:
//!
//! * [`geometry`]: n, D²φ (central differences of φ) and B per node, once per band, and the
//!   curvature the tube must resolve (h_out·κ < 1);
//! * [`factoring`]: u = u₀ + w with u₀ the chord distance to the nearest point source, the nodes
//!   within a small ball of a source fixed at u₀;
//! * [`setup`]: both in one parallel pass over the band ([`joined`]: the fixed nodes joined to
//!   their source);
//! * [`creases`]: where φ's level sets have creases or corners, and the shortcut they cost;
//! * [`many`]: many sources on one band, the geometry shared, in parallel across the sources;
//! * [`local`]: the limited BDF2/BDF3 Godunov update (continuous ramps from first to second to third
//!   order, Newton's method for the unequal steps) and the second-order extension update;
//! * [`solver`]: phase 1 (first order, monotone) then phase 2 (second order, assignment), with
//!   the stagnation safeguard ([`attempt`]), and where they run away, once more with the
//!   runaway's nodes at first order ([`demotion`]);
//! * [`warm`]: phase 2 from a moved surface's previous values (warm starts).
//!
//! The first-order solver ([`crate::sweep`]) is untouched: `order=1` is the paper's scheme.

mod active;
mod attempt;
pub mod creases;
mod demotion;
pub mod factoring;
pub mod fingerprint;
pub mod geometry;
pub mod implicit;
mod joined;
pub mod local;
mod local_fit;
pub mod many;
mod phase;
mod pipeline;
mod rows;
pub mod setup;
pub mod smoothed_creases;
pub mod solver;
mod stagnation;
pub mod start;
mod symmetric;
pub mod warm;

pub use factoring::{factor_sources, factor_sources_of, Factoring};
pub use geometry::{tube_geometry, tube_geometry_of, GeometrySummary, NodeGeometry, TubeGeometry, Unresolved};
pub use implicit::Implicit;
pub use setup::tube_setup_of;
pub use solver::{sweep_second_order, sweep_second_order_reporting, SecondOrderOptions, SecondOrderStats};
pub use stagnation::STALL_RATIO;
pub use start::first_order_start;

/// |∇φ| at an inner node must be within this of 1 for its second-order update (B uses D²φ,
/// which is the surface's curvature only for a signed distance); elsewhere the node runs first
/// order ([`geometry::Unresolved::Gradient`]).
pub const GRAD_NORM_TOLERANCE: f64 = 0.05;

/// Second order is refused for the whole tube (and `order="auto"` runs the paper's scheme) when
/// more than this fraction of the inner-tube nodes would run the first-order update: the surface
/// is then not resolved by the grid at all, and the first-order scheme is the cheaper one.
pub const MAX_FIRST_ORDER_FRACTION: f64 = 0.5;

/// A level set whose unresolved curvature covers more than this fraction of the inner tube has
/// convex creases or corners (the cube max|x| − 0.5: 18% at N = 41, 10% at N = 81; a crease
/// where φ = min(φ₁, φ₂) fails the gradient test instead, noise of 1e-3 at N = 121 0.2%): the
/// inner tube cuts them at any order, and the second-order update beside them was no better
/// than the paper's (1.53 against 1.57 at N = 41, 1.76 against 1.77 at N = 81, 2.0 exact), so
/// the tube is refused and `order="auto"` runs the paper's scheme.
pub const MAX_CREASE_FRACTION: f64 = 0.05;

/// How a refusal says that φ was found noisy (its derivatives all from least-squares fits,
/// `geometry::NOISY_FRACTION`): the first-order fallback of `order="auto"` reads it and looks for
/// the creases that the noise hides through a smoothing (python/tubesweep/_coarse_creases.py).
pub const NOISY_PHI: &str = "reads as noisy at the grid's scale";

/// Refuses a tube on which second order cannot run: when more than
/// [`MAX_FIRST_ORDER_FRACTION`] of the inner-tube nodes are unresolved (an incomplete stencil of
/// φ, φ not a signed distance, or a principal curvature κ with `outer_width`·κ ≥ 1, where B is
/// singular or the tube reaches a focal point). Fewer unresolved nodes do not refuse it: they
/// run the first-order update node by node ([`geometry::node_geometry`]).
pub fn check_geometry(summary: &GeometrySummary, outer_width: f64, spacing: f64) -> crate::Result<()> {
    check_geometry_of(summary, outer_width, spacing, false)
}

/// As [`check_geometry`], the message worded for a closest-point map when `closest_point` (there
/// an unresolved curvature also flags an open surface, beyond whose rim cp(x) lies on the
/// boundary curve, or an edge; |∇|x − cp(x)|| off 1 a map whose points are not the nearest ones).
pub fn check_geometry_of(
    summary: &GeometrySummary,
    outer_width: f64,
    spacing: f64,
    closest_point: bool,
) -> crate::Result<()> {
    use crate::error::Error;
    let total = summary.inner_nodes.max(1);
    let unresolved = summary.first_order_nodes();
    if (unresolved as f64) <= MAX_FIRST_ORDER_FRACTION * total as f64 {
        if !closest_point && summary.unresolved_curvature as f64 > MAX_CREASE_FRACTION * total as f64 {
            let share = 100.0 * summary.unresolved_curvature as f64 / total as f64;
            if summary.creases.nodes == 0 {
                return Err(Error::invalid(
                    "grid",
                    format!(
                        "order=2: {} of the {} inner-tube nodes ({share:.0}%) have a principal curvature the tube does \
                         not resolve (outer·Δx·κ ≥ 1; spacing {spacing:.4}, outer·Δx = {outer_width:.4}), where the \
                         second-order update is no better than the first-order one. Refine the grid (or use order=1)",
                        summary.unresolved_curvature, summary.inner_nodes,
                    ),
                ));
            }
            return Err(Error::invalid(
                "surface",
                format!(
                    "order=2: {} of the {} inner-tube nodes ({share:.0}%) lie at convex creases or corners of φ's level \
                     sets or next to them (a principal curvature with outer·Δx·κ ≥ 1; {} crease nodes, the normal \
                     turning by up to {:.0}°), where the inner tube lets the front cut the corner by about \
                     {:.2}·inner·Δx per crease it crosses (2·tan(θ/2); about 1.5Δx where the inner tube is thinned \
                     at them, order=\"auto\"), and the second-order update next to them came out no better. Round \
                     the edges over more than the tube's width (outer·Δx = {outer_width:.4}) for second order; use \
                     order=1 (or \"auto\")",
                    summary.unresolved_curvature,
                    summary.inner_nodes,
                    summary.creases.nodes,
                    summary.creases.angle,
                    summary.creases.shortcut_per_inner_width(),
                ),
            ));
        }
        return Ok(());
    }
    let what = if closest_point { "|x − cp(x)|" } else { "φ" };
    let mut reasons = Vec::new();
    if summary.incomplete_stencils > 0 {
        reasons.push(format!(
            "{} lack a band neighbour for the differences of {what} (the band or the box cuts the stencil)",
            summary.incomplete_stencils
        ));
    }
    if summary.off_distance > 0 {
        reasons.push(format!(
            "{} have |∇{what}| off 1 by more than {GRAD_NORM_TOLERANCE} ({})",
            summary.off_distance,
            if closest_point {
                "cp does not return the nearest points there"
            } else {
                "φ is not a signed distance there: pass redistance=True"
            }
        ));
    }
    if summary.unresolved_curvature > 0 {
        reasons.push(format!(
            "{} have a curvature the tube does not resolve (outer·Δx·κ ≥ 1: a crease, a corner, noise, {}or a grid \
             too coarse: spacing {spacing:.4}, outer·Δx = {outer_width:.4})",
            summary.unresolved_curvature,
            if closest_point { "an open surface's rim, " } else { "" }
        ));
    }
    if summary.fitted_everywhere && !closest_point {
        // (read by the first-order fallback, which then looks for creases through a smoothing)
        reasons.push(format!(
            "φ {NOISY_PHI} (its derivatives came from least-squares fits over three steps)"
        ));
    }
    let (count, _, _) = summary.gradient_moments;
    let gradient = !closest_point && 2 * summary.off_distance > unresolved;
    let advice = if gradient {
        // mostly φ's gradient: a finer grid does not change that
        if count > 0 {
            let mean = summary.gradient_mean_spread().0;
            format!(
                "|∇φ| is {mean:.3} on average near the surface: ts.LevelSet(phi, redistance=True) re-distances φ (or \
                 divide φ by {mean:.3} if it is a scaled distance), or use order=1"
            )
        } else {
            "ts.LevelSet(phi, redistance=True) re-distances φ, or use order=1".to_string()
        }
    } else {
        "the grid does not resolve the surface (curvature radii below the tube's width, or noise at the grid's \
         scale): refine the grid or smooth φ, or use order=1"
            .to_string()
    };
    Err(Error::invalid(
        if gradient { "surface" } else { "grid" },
        format!(
            "order=2: {unresolved} of the {} inner-tube nodes ({:.0}%) cannot run the second-order update: {}. Second \
             order runs node by node where the geometry is resolved, but here most of the tube is not: {advice}",
            summary.inner_nodes,
            100.0 * unresolved as f64 / total as f64,
            reasons.join("; ")
        ),
    ))
}

/// The starting values: u₀ at the fixed nodes, +∞ elsewhere.
pub fn starting_values<const D: usize>(factoring: &Factoring<D>) -> Vec<f64> {
    factoring
        .roles
        .iter()
        .zip(&factoring.u0)
        .map(|(&r, &u0)| {
            if r == crate::sweep::NodeRole::Fixed {
                u0
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{Control, NodeRole, Slowness};

    /// The sphere of radius 0.5 on n³ nodes over [−1, 1]³, source (−0.5, 0, 0): the max error
    /// at the inner nodes' foot points against the great-circle distance, away from the source
    /// and the antipode.
    fn sphere_error(n: usize, window: f64) -> (f64, f64, SecondOrderStats) {
        let (e, m, stats, _) = sphere_solve(n, window, 1);
        (e, m, stats)
    }

    /// The same, with the values, on `threads` threads.
    fn sphere_solve(n: usize, window: f64, threads: usize) -> (f64, f64, SecondOrderStats, Vec<f64>) {
        sphere_solve_with(n, window, threads, 1e-3, 2.0)
    }

    /// The same, with phase 1 stopped at `first_tol`·Δx² (+∞: none) and the extension's limit.
    fn sphere_solve_with(
        n: usize,
        window: f64,
        threads: usize,
        first_tol: f64,
        extension_limit: f64,
    ) -> (f64, f64, SecondOrderStats, Vec<f64>) {
        sphere_solve_tuned(n, window, threads, first_tol, extension_limit, &|_| {})
    }

    /// The same, the options changed by `tune` before the solve.
    fn sphere_solve_tuned(
        n: usize,
        window: f64,
        threads: usize,
        first_tol: f64,
        extension_limit: f64,
        tune: &dyn Fn(&mut SecondOrderOptions),
    ) -> (f64, f64, SecondOrderStats, Vec<f64>) {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(n, 0.5, &[0.0]);
        let idx = band.indices();
        let pts: Vec<[f64; 3]> = idx
            .iter()
            .map(|i| [-1.0 + h * i[0] as f64, -1.0 + h * i[1] as f64, -1.0 + h * i[2] as f64])
            .collect();
        let phi: Vec<f64> = pts
            .iter()
            .map(|x| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.5)
            .collect();
        let geo = tube_geometry(&band, &roles, &phi, &dirs, h, 4.0 * h).unwrap();
        let fac = factor_sources(
            &band,
            &roles,
            &phi,
            &dirs,
            [-1.0; 3],
            h,
            &[[-0.5, 0.0, 0.0]],
            &[1.0],
            2.0 * h,
        )
        .unwrap();
        let mut values = starting_values(&fac);
        let mut options = SecondOrderOptions {
            tol_first: first_tol * h * h,
            tol: 1e-3 * h * h,
            max_iterations: 500,
            stall_ratio: STALL_RATIO,
            stall_window: 20,
            own_first_phase: true,
            window_first: window,
            window_second: window,
            extension_limit,
            threads,
            ramp_length: 1.0,
        };
        tune(&mut options);
        let stats = sweep_second_order(
            &band,
            &geo,
            &fac,
            &dirs,
            Slowness::Constant(1.0),
            h,
            &mut values,
            &options,
            &mut |_| Control::Continue,
        )
        .unwrap();
        let (mut worst, mut sum, mut count): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for (i, x) in pts.iter().enumerate() {
            if roles[i] == NodeRole::Outer || phi[i].abs() > h {
                continue;
            }
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            let exact = 0.5 * (-x[0] / r).clamp(-1.0, 1.0).acos();
            if !(0.2..=0.5 * std::f64::consts::PI - 0.2).contains(&exact) {
                continue;
            }
            worst = worst.max((values[i] - exact).abs());
            sum += (values[i] - exact).abs();
            count += 1.0;
        }
        (worst, sum / count, stats, values)
    }

    #[test]
    fn sphere_converges_at_second_order() {
        let (e1, m1, s1) = sphere_error(41, 0.0);
        let (e2, m2, s2) = sphere_error(81, 0.0);
        assert!(s1.converged && s2.converged, "{s1:?} {s2:?}");
        let order = (e1 / e2).ln() / (80.0f64 / 40.0).ln();
        let mean_order = (m1 / m2).ln() / (80.0f64 / 40.0).ln();
        assert!(
            order > 1.5 && mean_order > 1.75 && m2 < 1e-4,
            "max errors {e1:.3e} {e2:.3e}, order {order:.2}; mean {m1:.3e} {m2:.3e}, order {mean_order:.2}"
        );
    }

    #[test]
    fn a_fallback_reports_how_far_from_settled_the_values_were() {
        // without the window, a stall test that fires as soon as it can (phase 2's second iteration)
        let (e, _, st, _) = sphere_solve_tuned(41, 0.0, 1, 1e-3, 2.0, &|o| {
            o.stall_window = 1;
            o.stall_ratio = 1e-300;
        });
        let h = 2.0 / 40.0;
        let (fired, change) = (
            st.fallback_iteration.expect("it fires"),
            st.fallback_change.expect("its size"),
        );
        assert!(st.converged && fired >= 2, "{st:?}");
        // the change of the iteration before it fired (phase 1's first-order values corrected to
        // second order): above the tolerance, else it had stopped, and below a spacing; accepting
        // decreases only from there still ends near the second-order values on the sphere
        assert!(change > 1e-3 * h * h && change < h, "{change:e}");
        let (e_plain, _, plain) = sphere_error(41, 0.0);
        assert!(plain.fallback_iteration.is_none() && plain.fallback_change.is_none());
        assert!(e < 2.0 * e_plain, "{e:e} against {e_plain:e}, {st:?}");
    }

    #[test]
    fn the_front_windows_keep_the_errors_and_save_updates() {
        let (e, m, plain) = sphere_error(81, 0.0);
        let (ew, mw, windowed) = sphere_error(81, 2.0);
        assert!(
            windowed.converged && windowed.fallback_iteration.is_none(),
            "{windowed:?}"
        );
        // the same up to a few stopping tolerances (1e-3Δx² = 6.3e-7): max 1.054e-4 / 1.029e-4,
        // mean 1.795e-5 / 1.773e-5 with the BDF3 ramp (whose kink test makes the fixed point
        // depend slightly on the path), within 1% with BDF2 alone
        assert!(
            (ew - e).abs() < 0.03 * e && (mw - m).abs() < 0.02 * m,
            "max {e:.4e} / {ew:.4e}, mean {m:.4e} / {mw:.4e}"
        );
        assert!(
            (windowed.updates as f64) < 0.6 * plain.updates as f64,
            "{} updates windowed, {} plain",
            windowed.updates,
            plain.updates
        );
    }

    #[test]
    fn a_runaway_second_phase_is_abandoned_for_the_first_phase() {
        // phase 1 stopped far too early (64·Δx²) and the extension's BDF2 correction unlimited:
        // the second-order sweeps from that start run away (values to −1e6 and beyond); they are
        // stopped at the first value below −σ̄Δx and the first phase's monotone values are
        // returned, converged, instead of running to max_iterations
        let (e, m, stats, values) = sphere_solve_with(101, 2.0, 1, 64.0, f64::INFINITY);
        let runaway = stats
            .runaway_iteration
            .expect("this start ran away when the guard was written");
        assert!(runaway < 100, "{stats:?}");
        assert!(stats.converged, "{stats:?}");
        assert!(values.iter().all(|&v| v >= 0.0), "a negative value was returned");
        // first-order accuracy (the second-order solve's max error is about 1e-3 here)
        assert!(e < 5e-2 && m < 2e-2 && e > 2e-3, "max {e:.3e}, mean {m:.3e}, {stats:?}");
    }

    #[test]
    fn the_limited_extension_converges_from_a_poor_start() {
        // the start above with the extension's correction limited (the default): no runaway,
        // no fallback, and the errors of the solve from a full first phase
        let (e, m, stats, _) = sphere_solve_with(101, 2.0, 1, 64.0, 2.0);
        let (e_full, m_full, full, _) = sphere_solve_with(101, 2.0, 1, 1.0, 2.0);
        for s in [&stats, &full] {
            assert!(
                s.converged && s.runaway_iteration.is_none() && s.fallback_iteration.is_none(),
                "{s:?}"
            );
        }
        assert!(
            (e - e_full).abs() < 0.01 * e_full && (m - m_full).abs() < 0.01 * m_full && e < 2e-3,
            "max {e:.4e} / {e_full:.4e}, mean {m:.4e} / {m_full:.4e}"
        );
    }

    #[test]
    fn without_a_first_phase_the_errors_stay_and_updates_fall() {
        // tol_first = ∞: the second-order sweeps start from the fixed nodes, behind the window
        let (e, m, none, _) = sphere_solve_with(81, 2.0, 1, f64::INFINITY, 2.0);
        let (e1, m1, first, _) = sphere_solve_with(81, 2.0, 1, 1.0, 2.0);
        assert!(
            none.converged && none.first_order_iterations == 0 && none.fallback_iteration.is_none(),
            "{none:?}"
        );
        assert!(
            (e - e1).abs() < 0.01 * e1 && (m - m1).abs() < 0.01 * m1 && m < 1e-4,
            "max {e:.4e} / {e1:.4e}, mean {m:.4e} / {m1:.4e}"
        );
        assert!(
            (none.updates as f64) < 0.85 * first.updates as f64,
            "{} updates without phase 1, {} with it",
            none.updates,
            first.updates
        );
    }

    #[test]
    fn the_start_wakes_only_the_readers_of_reached_nodes() {
        // every non-fixed node active at the start: the same bits, the visits that found no
        // neighbour reached more (with and without a first phase)
        for first_tol in [f64::INFINITY, 1.0] {
            let (_, _, few, a) = sphere_solve_with(61, 2.0, 1, first_tol, 2.0);
            solver::ALL_ACTIVE_START.with(|f| f.set(true));
            let (_, _, all, b) = sphere_solve_with(61, 2.0, 1, first_tol, 2.0);
            solver::ALL_ACTIVE_START.with(|f| f.set(false));
            assert!(few.updates < all.updates, "{} / {}", few.updates, all.updates);
            assert_eq!(few.second_order_iterations, all.second_order_iterations);
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x.to_bits(), y.to_bits());
            }
        }
    }

    #[test]
    fn the_x86_64_v3_walk_gives_the_baseline_bits() {
        // where the CPU has x86-64-v3 the sweeps run the walk compiled for it: the same values,
        // updates and iterations as the baseline walk (one and two threads, with and without a
        // first phase)
        for (threads, first_tol) in [(1, f64::INFINITY), (2, f64::INFINITY), (1, 1.0)] {
            let (_, _, fast, a) = sphere_solve_with(61, 2.0, threads, first_tol, 2.0);
            rows::FORCE_BASELINE.with(|f| f.set(true));
            let (_, _, base, b) = sphere_solve_with(61, 2.0, threads, first_tol, 2.0);
            rows::FORCE_BASELINE.with(|f| f.set(false));
            assert_eq!(
                (fast.updates, fast.first_order_iterations, fast.second_order_iterations),
                (base.updates, base.first_order_iterations, base.second_order_iterations)
            );
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x.to_bits(), y.to_bits());
            }
        }
    }

    #[test]
    fn any_thread_count_gives_the_same_bits() {
        let (_, _, one, a) = sphere_solve(61, 2.0, 1);
        let (_, _, two, b) = sphere_solve(61, 2.0, 2);
        let (_, _, three, c) = sphere_solve(61, 2.0, 3);
        assert_eq!(
            (one.updates, one.first_order_iterations),
            (two.updates, two.first_order_iterations)
        );
        assert_eq!(three.second_order_iterations, one.second_order_iterations);
        for ((x, y), z) in a.iter().zip(&b).zip(&c) {
            assert_eq!((x.to_bits(), x.to_bits()), (y.to_bits(), z.to_bits()));
        }
        // without a first phase too
        let (_, _, one, a) = sphere_solve_with(61, 2.0, 1, f64::INFINITY, 2.0);
        let (_, _, two, b) = sphere_solve_with(61, 2.0, 2, f64::INFINITY, 2.0);
        assert_eq!(one.updates, two.updates);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
}
