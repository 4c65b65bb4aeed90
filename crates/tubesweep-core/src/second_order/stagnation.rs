//! Limit cycles of the second-order sweeps, which are not monotone: the nodes that swing in one
//! repeat their changes iteration after iteration, and the largest change of an iteration with
//! them. [`in_a_limit_cycle`] recognises the repetition within a few periods; the solver
//! ([`super::solver`]) then opens its front window, or falls back to accepting decreases only,
//! as its stagnation test (a change not below `stall_ratio` times that `stall_window` iterations
//! before) would only have done about twenty iterations later.

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

#[cfg(test)]
mod tests {
    use super::*;

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
