//! Limit cycles of the second-order sweeps, which are not monotone: the nodes that swing in one
//! repeat their changes iteration after iteration, and the largest change of an iteration with
//! them. [`in_a_limit_cycle`] recognises the repetition within a few periods; the solver
//! ([`super::solver`]) then opens its front window, or falls back to accepting decreases only,
//! as its stagnation test ([`stalled`]) would only have done about twenty iterations later.

/// A limit cycle of the second-order sweeps: the largest changes of the iterations repeat, with a
/// period of at most [`CYCLE_PERIOD`] iterations, each equal to [`CYCLE_SPREAD`] (relative) to the
/// one a period before, [`CYCLE_MATCHES`] more times than the period in a row.
const CYCLE_PERIOD: usize = 8;

/// See [`CYCLE_PERIOD`].
const CYCLE_MATCHES: usize = 2;

/// See [`CYCLE_PERIOD`]: the smoothed sphere mask at N = 191 cycled (before the margin of the
/// inner update's side rule, `solver.rs`) with a period of 1 iteration whose change repeated to 8
/// digits (5.5876847e-7); where the second-order sweeps converge slowly (the six-fold star at
/// N = 1601), successive changes differ in the third digit or before.
const CYCLE_SPREAD: f64 = 1e-6;

/// Whether the largest changes of the iterations so far, `changes` (the newest last), end in a
/// limit cycle ([`CYCLE_PERIOD`]): the nodes that swing in it repeat their changes iteration after
/// iteration (nil over a period), which the stagnation test would only catch `stall_window`
/// iterations later.
pub(super) fn in_a_limit_cycle(changes: &[f64]) -> bool {
    let m = changes.len();
    (1..=CYCLE_PERIOD).any(|period| {
        let matches = period + CYCLE_MATCHES;
        m >= period + matches
            && (m - matches..m).all(|k| {
                let (c, before) = (changes[k], changes[k - period]);
                c.is_finite() && c > 0.0 && (c - before).abs() <= CYCLE_SPREAD * c.max(before)
            })
    })
}

/// The default `ratio` of [`stalled`] (`SecondOrderOptions::stall_ratio`): less than 2% of
/// progress over the stretch is a stall.
pub const STALL_RATIO: f64 = 0.98;

/// The stagnation test of the second-order sweeps: the largest changes of the iterations so far,
/// `changes` (the newest last), made no progress over the last w = max(`window`, half of them)
/// iterations: none of those below `ratio` times the smallest change before them.
///
/// Where the sweeps converge slowly the changes can rise for a while and fall again, so the test
/// compares the smallest changes, over a stretch that grows with the iterations. On the circle at
/// N = 4001 (2D, no front window) the change fell by 1–3% per iteration and rose from 3.68e-6 to
/// 4.15e-6 over iterations 29–41 of phase 2 before falling on to the tolerance (146 iterations);
/// the earlier test (the change above 0.9 times the change twenty iterations before) took that for
/// a stall at iteration 39, and decreases only from there on left the largest error at 3.8e-6
/// instead of 1.7e-7, with no warning. A limit cycle, or a plateau, makes no progress at all and
/// is still caught, after at most as many iterations again as it took to begin.
pub(super) fn stalled(changes: &[f64], window: usize, ratio: f64) -> bool {
    let m = changes.len();
    let w = window.max(m / 2);
    if m <= w {
        return false;
    }
    let before = changes[..m - w].iter().copied().fold(f64::INFINITY, f64::min);
    let recent = changes[m - w..].iter().copied().fold(f64::INFINITY, f64::min);
    recent > ratio * before
}

/// The creep of iterations that accept decreases only ([`super::phase`]'s runaway test): the
/// largest changes `changes` stalled ([`stalled`]) with every change of the stretch above `floor`.
pub(super) fn creeping(changes: &[f64], window: usize, ratio: f64, floor: f64) -> bool {
    let m = changes.len();
    let w = window.max(m / 2).min(m);
    changes[m - w..].iter().all(|&c| c > floor) && stalled(changes, window, ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slow_descent_with_a_bump_is_not_a_stall_and_a_plateau_is() {
        // phase 2's largest changes on the circle at N = 4001 (iterations 1–39, in units of
        // 1e-6): a slow descent that rises for ten iterations before falling again
        let c: Vec<f64> = [
            38.39, 22.94, 11.74, 8.563, 7.650, 7.068, 6.659, 6.349, 6.100, 5.892, 5.711, 5.548, 5.398, 5.254, 5.114,
            4.977, 4.840, 4.704, 4.568, 4.435, 4.306, 4.183, 4.069, 3.965, 3.874, 3.799, 3.741, 3.701, 3.682, 3.683,
            3.702, 3.739, 3.790, 3.850, 3.915, 3.981, 4.040, 4.090, 4.126,
        ]
        .iter()
        .map(|v| v * 1e-6)
        .collect();
        for m in 21..=c.len() {
            assert!(
                !stalled(&c[..m], 20, STALL_RATIO),
                "a bump in a slow descent ({m} iterations)"
            );
        }
        // the earlier test fired there: the change above 0.9 times the change twenty before
        assert!(c[38] > 0.9 * c[18]);
        // a plateau (or a cycle) after 30 iterations of progress: a stall within 30 more
        let mut plateau: Vec<f64> = (0..30).map(|k| 1e-5 * 0.9f64.powi(k)).collect();
        let level = plateau[29];
        plateau.extend((0..30).map(|k| level * (1.0 + 0.1 * ((k % 3) as f64))));
        assert!(stalled(&plateau, 20, STALL_RATIO));
        assert!(!stalled(&plateau[..20], 20, STALL_RATIO), "not before a whole window");
    }

    #[test]
    fn cycles_of_one_to_eight_iterations_are_recognised_and_slow_convergence_is_not() {
        // the smoothed sphere mask at N = 191: period 1; then a cycle of period 5
        let one: Vec<f64> = [7.7930146, 3.366462, 6.65504, 1.415579, 5.154589]
            .iter()
            .map(|d| 5.5876847e-7 + d * 1e-16)
            .collect();
        assert!(!in_a_limit_cycle(&one[..3]) && in_a_limit_cycle(&one[..4]));
        let five = [6.0038e-7, 9.3578e-7, 6.5323e-7, 6.0029e-7, 9.3609e-7];
        let cycle: Vec<f64> = (0..12).map(|k| five[k % 5] * (1.0 + 1e-9 * k as f64)).collect();
        assert!(!in_a_limit_cycle(&cycle[..11]) && in_a_limit_cycle(&cycle));
        // the six-fold star at N = 1601 (a plateau of the BDF3 ramp), a steady fall, new values
        let star = [
            4.534619e-06,
            4.533226e-06,
            4.552137e-06,
            4.547350e-06,
            4.515372e-06,
            4.467342e-06,
        ];
        let fall: Vec<f64> = (0..40).map(|k| 1e-3 * 0.8f64.powi(k)).collect();
        let reached = [f64::INFINITY; 20];
        for changes in [&star[..], &fall, &reached] {
            assert!(!(1..=changes.len()).any(|m| in_a_limit_cycle(&changes[..m])));
        }
        // a nine-iteration period is beyond the test
        let nine: Vec<f64> = (0..40).map(|k| 1e-6 * (1.0 + (k % 9) as f64)).collect();
        assert!(!in_a_limit_cycle(&nine));
    }
}
