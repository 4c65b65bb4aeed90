//! Tests of the sweeps; helpers shared by the files of this folder.

use super::problem::*;
use super::*;
use crate::band::schedule::NO_TILE;
use crate::band::NarrowBand;
use crate::error::Error;
use crate::scheme::hamiltonian::InnerScheme;
use crate::scheme::hamiltonian::IsotropicEikonal;
use crate::test_bands::{shell_band, sphere_band, sphere_problem};
use std::sync::atomic::AtomicU8;

mod bits;
mod front_window;
mod rim;
mod symmetric_metric;
mod upwind_dispatch;

fn box_problem<'a>(
    band: &'a NarrowBand<2>,
    roles: &'a [NodeRole],
    scheme: InnerScheme<'a, 2>,
    h: f64,
) -> SweepProblem<'a, 2> {
    SweepProblem {
        band,
        roles,
        spacing: h,
        slowness: Slowness::Constant(1.0),
        extension: Extension::None,
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
    let stats = p
        .solve(&mut u, &SolveOptions::default(), &mut |_| Control::Continue)
        .unwrap();
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
    let opts = SolveOptions {
        tol: 1e-12,
        ..Default::default()
    };
    let mut a = vec![0.0; band.len()];
    let mut b = vec![0.0; band.len()];
    let sa = box_problem(&band, &roles, InnerScheme::LaxFriedrichs, h)
        .solve(&mut a, &opts, &mut |_| Control::Continue)
        .unwrap();
    let sb = box_problem(&band, &roles, InnerScheme::General(&ham), h)
        .solve(&mut b, &opts, &mut |_| Control::Continue)
        .unwrap();
    assert!(sa.converged && sb.converged);
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-9, "diff {diff}");
}

/// Solves `p` to convergence with `opts` (tol 1e-13).
fn converged(p: &SweepProblem<'_, 3>, opts: SolveOptions) -> (Vec<f64>, SolveStats) {
    let mut u = vec![0.0; p.band.len()];
    let st = p
        .solve(&mut u, &SolveOptions { tol: 1e-13, ..opts }, &mut |_| Control::Continue)
        .unwrap();
    assert!(st.converged);
    (u, st)
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn coupled_update_reaches_the_pointwise_fixed_point_with_fewer_updates() {
    let (band, roles, dirs, h) = sphere_band(41);
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    let run = |coupled: bool, threads: usize| {
        converged(
            &p,
            SolveOptions {
                coupled,
                threads,
                ..Default::default()
            },
        )
    };
    let (a, sa) = run(true, 1);
    let (b, sb) = run(false, 1);
    let diff = max_difference(&a, &b);
    assert!(diff < 1e-10, "coupled and pointwise differ by {diff}");
    assert!(sa.updates < sb.updates, "{} vs {}", sa.updates, sb.updates);
    assert!(sa.iterations <= sb.iterations);
    // and the coupled sweeps are bit-identical in parallel too
    let (c, sc) = run(true, 3);
    assert_eq!(sc.iterations, sa.iterations);
    assert!(a.iter().zip(&c).all(|(x, y)| x.to_bits() == y.to_bits()));
}

#[test]
fn progress_can_stop_the_solve() {
    let band = NarrowBand::<2>::full_box([11, 11]).unwrap();
    let mut roles = vec![NodeRole::Inner; band.len()];
    roles[0] = NodeRole::Fixed;
    let mut u = vec![0.0; band.len()];
    let p = box_problem(&band, &roles, InnerScheme::LaxFriedrichs, 0.1);
    let err = p
        .solve(&mut u, &SolveOptions::default(), &mut |_| Control::Stop)
        .unwrap_err();
    assert_eq!(err, Error::Interrupted { iterations: 1 });
    assert_eq!(u.len(), band.len());
}
