//! The outer rim swept last: the same fixed point, one pass, progress and interruption.

use super::*;

#[test]
fn sweeping_the_outer_rim_last_reaches_the_same_fixed_point_with_fewer_updates() {
    let (band, roles, dirs, h) = sphere_band(41);
    for scheme in [InnerScheme::Godunov, InnerScheme::LaxFriedrichs] {
        let p = sphere_problem(&band, &roles, &dirs, h, scheme);
        let run = |defer_outer_rim: bool, threads: usize| {
            converged(
                &p,
                SolveOptions {
                    defer_outer_rim,
                    threads,
                    ..Default::default()
                },
            )
        };
        let (a, sa) = run(true, 1);
        let (b, sb) = run(false, 1);
        let diff = max_difference(&a, &b);
        assert!(diff < 1e-10, "rim last and rim in every sweep differ by {diff}");
        assert!(
            (sa.updates as f64) < 0.85 * sb.updates as f64,
            "{} vs {}",
            sa.updates,
            sb.updates
        );
        let (c, _) = run(true, 3);
        assert!(a.iter().zip(&c).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}

#[test]
fn the_rim_s_one_pass_leaves_every_rim_node_at_its_fixed_point() {
    // the rim is evaluated once, in dependency order: another evaluation of Eq. (5) at any
    // rim node gives back its value to the bit
    let (band, roles, dirs, h) = sphere_band(61);
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    let w = p.upwind_weights().into_owned();
    let rim = crate::sweep::rim::outer_rim(&band, &roles, &w);
    let (u, st) = converged(&p, SolveOptions::default());
    assert!(st.converged && st.last_change == 0.0, "{st:?}");
    let mut checked = 0;
    for q in (0..band.len()).filter(|&q| rim[q] && !w[q][0].is_nan()) {
        let again = crate::scheme::extension::extension_apply_upwind(w[q], &band.neighbours_of(q), |i| {
            if i == band.sentinel() {
                st.infinity
            } else {
                u[i as usize]
            }
        });
        assert_eq!(again.to_bits(), u[q].to_bits(), "rim node {q}");
        checked += 1;
    }
    assert!(checked > 1000, "{checked} rim nodes");
}

#[test]
fn the_outer_rim_is_the_layer_that_no_inner_node_depends_on() {
    let (band, roles, dirs, h) = sphere_band(41);
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    let w = p.upwind_weights().into_owned();
    let rim = crate::sweep::rim::outer_rim(&band, &roles, &w);

    let n_rim = rim.iter().filter(|&&b| b).count();
    let n_outer = roles.iter().filter(|&&r| r == NodeRole::Outer).count();
    // with inner 2h and outer 4h a good part of the layer, but not all of it
    assert!(n_rim > n_outer / 5 && n_rim < n_outer, "{n_rim} of {n_outer}");
    for i in 0..band.len() {
        if rim[i] {
            assert_eq!(roles[i], NodeRole::Outer);
        }
        // no inner node reads a rim node
        if roles[i] == NodeRole::Inner {
            for k in 0..3 {
                for side in 0..2 {
                    let q = band.neighbours_of(i)[k][side];
                    assert!(q == band.sentinel() || !rim[q as usize]);
                }
            }
        }
        // no needed layer node reads a rim node in its update (5)
        if roles[i] == NodeRole::Outer && !rim[i] && !w[i][0].is_nan() {
            for k in 0..3 {
                let side = if w[i][k] > 0.0 {
                    0
                } else if w[i][k] < 0.0 {
                    1
                } else {
                    continue;
                };
                let q = band.neighbours_of(i)[k][side];
                assert!(q == band.sentinel() || !rim[q as usize]);
            }
        }
    }
}

#[test]
fn the_rim_phase_reports_progress_and_can_be_stopped() {
    let (band, roles, dirs, h) = sphere_band(41);
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    let opts = SolveOptions::default();
    let mut seen = Vec::new();
    let mut u = vec![0.0; band.len()];
    let st = p
        .solve(&mut u, &opts, &mut |r| {
            seen.push(r.iteration);
            Control::Continue
        })
        .unwrap();
    // one report per iteration of both phases, numbered on
    assert_eq!(seen, (1..=st.iterations).collect::<Vec<_>>());
    // stopping in the rim's last pass ends the solve there
    let mut u = vec![0.0; band.len()];
    let err = p
        .solve(&mut u, &opts, &mut |r| {
            if r.iteration == st.iterations {
                Control::Stop
            } else {
                Control::Continue
            }
        })
        .unwrap_err();
    assert_eq!(
        err,
        Error::Interrupted {
            iterations: st.iterations
        }
    );
}
