//! The built-in upwind solvers inlined into the row loop (static dispatch, `specialised!`) give
//! the bits of the same solvers called through the trait object.

use super::*;
use crate::scheme::hamiltonians::{MovingMedium, SymmetricMetric};
use crate::scheme::upwind::LocalSolver;

/// A solver that forwards to another through the trait, hiding which built-in it is (so the
/// kernel calls it through the trait object).
struct Hidden<'a>(&'a dyn LocalSolver<3>);

impl LocalSolver<3> for Hidden<'_> {
    fn update(&self, node: usize, minus: [f64; 3], plus: [f64; 3], h: f64, old: f64) -> f64 {
        self.0.update(node, minus, plus, h, old)
    }
    fn slowness_bound(&self) -> Option<f64> {
        self.0.slowness_bound()
    }
}

#[test]
fn the_inlined_upwind_solvers_give_the_bits_of_the_trait_object() {
    let (band, roles, dirs, h) = sphere_band(33);
    let idx = band.indices();
    // the rigid rotation about z at each node (tangent to the sphere at its closest point)
    let flow: Vec<[f64; 3]> = idx
        .iter()
        .map(|i| {
            let x: [f64; 3] = core::array::from_fn(|k| -1.0 + i[k] as f64 * h);
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt().max(1e-12);
            [-0.5 * x[1] / r, 0.5 * x[0] / r, 0.0]
        })
        .collect();
    let s = [1.0];
    let rot = MovingMedium {
        slowness: &s,
        flow: &flow,
        sigma: None,
    };
    let m = vec![[[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]]; band.len()];
    let met = SymmetricMetric::new(&s, &m);
    let solvers: [&dyn LocalSolver<3>; 2] = [&rot, &met];
    for solver in solvers {
        let hidden = Hidden(solver);
        for (skip_inactive, threads) in [(false, 1), (true, 1), (true, 2)] {
            let opts = SolveOptions {
                threads,
                skip_inactive,
                coupled: false,
                front_window: 0.0,
                defer_outer_rim: skip_inactive,
                ..Default::default()
            };
            let run = |scheme| {
                let p = sphere_problem(&band, &roles, &dirs, h, scheme);
                let mut u = vec![0.0; band.len()];
                let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
                assert!(st.converged);
                (u, st.iterations, st.updates)
            };
            let (a, ia, ua) = run(InnerScheme::Upwind(solver));
            let (b, ib, ub) = run(InnerScheme::Upwind(&hidden));
            assert_eq!((ia, ua), (ib, ub));
            assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
            // a solve that reached the band
            assert!(a.iter().filter(|v| **v < 10.0).count() > band.len() / 2);
        }
    }
}

/// An upwind solver's own per-node data (the packed metric's 48 bytes a node) count, and its
/// bytes twice, when the sweeps decide whether to fetch rows ahead; fetching them (and the rows)
/// changes no bit. (Only
/// x86-64 prefetches.)
#[test]
#[cfg(target_arch = "x86_64")]
fn the_upwind_solvers_data_count_for_prefetching_and_change_no_bit() {
    let (band, roles, dirs, h) = sphere_band(33);
    let s = [1.0];
    let m = vec![[[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]]; band.len()];
    let met = SymmetricMetric::new(&s, &m);
    assert_eq!(LocalSolver::<3>::bytes_per_node(&met), 48);
    assert_eq!(LocalSolver::<3>::bytes_per_node(&SymmetricMetric::new(&s, &m[..1])), 0);
    let run = |scheme, above: usize| {
        let opts = SolveOptions {
            threads: 1,
            skip_inactive: false,
            row_prefetch_above: above,
            ..Default::default()
        };
        let p = sphere_problem(&band, &roles, &dirs, h, scheme);
        let mut u = vec![0.0; band.len()];
        let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
        assert!(st.converged);
        (u, st)
    };
    // above the kernel's own arrays (under 60 bytes a node) and those with the metric (about
    // 95), below the latter counted twice (an upwind solver's, `UPWIND_PREFETCH_WEIGHT`): the
    // metric's solve fetches ahead (from its second iteration on), Eq. (3)'s does not
    let above = 150 * band.len();
    let (_, god) = run(InnerScheme::Godunov, above);
    assert_eq!(god.prefetch_iterations, 0);
    let (a, st) = run(InnerScheme::Upwind(&met), above);
    assert_eq!(st.prefetch_iterations, st.iterations - 1);
    let (b, never) = run(InnerScheme::Upwind(&met), usize::MAX);
    assert_eq!(never.prefetch_iterations, 0);
    assert_eq!((st.iterations, st.updates), (never.iterations, never.updates));
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
}
