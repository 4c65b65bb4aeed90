//! The upwind metric's storage ([`SymmetricMetric`]): one matrix for all nodes gives the bits of
//! the same matrix stored per node, and a slightly asymmetric `M` the bits of `(M + Mᵀ)/2`.

use super::*;
use crate::scheme::hamiltonians::SymmetricMetric;

const M3: [[f64; 3]; 3] = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];

/// The converged values, iterations and updates of the upwind metric solve on the sphere band.
fn solve(
    band: &NarrowBand<3>,
    roles: &[NodeRole],
    dirs: &[[f32; 3]],
    h: f64,
    met: &SymmetricMetric<'_, 3>,
    threads: usize,
) -> (Vec<f64>, usize, u64) {
    let opts = SolveOptions {
        threads,
        coupled: false,
        front_window: 0.0,
        ..Default::default()
    };
    let p = sphere_problem(band, roles, dirs, h, InnerScheme::Upwind(met));
    let mut u = vec![0.0; band.len()];
    let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
    assert!(st.converged);
    // a solve that reached the band
    assert!(u.iter().filter(|v| **v < 10.0).count() > band.len() / 2);
    (u, st.iterations, st.updates)
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn one_matrix_for_all_nodes_gives_the_bits_of_the_per_node_storage() {
    let (band, roles, dirs, h) = sphere_band(33);
    let s = [1.0];
    let per_node = vec![M3; band.len()];
    let stored = SymmetricMetric::new(&s, &per_node);
    let one = SymmetricMetric::new(&s, &[M3]);
    assert_eq!((stored.matrices(), one.matrices()), (band.len(), 1));
    assert_eq!((stored.bytes(), one.bytes()), (48 * band.len(), 48));
    for threads in [1, 2] {
        assert_eq!(
            solve(&band, &roles, &dirs, h, &stored, threads),
            solve(&band, &roles, &dirs, h, &one, threads)
        );
    }
    // and the one-matrix storage is read as M, not as some other matrix: M = I gives other values
    let eye = SymmetricMetric::new(&s, &[[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]]);
    assert!(!same_bits(
        &solve(&band, &roles, &dirs, h, &eye, 1).0,
        &solve(&band, &roles, &dirs, h, &one, 1).0
    ));
}

#[test]
fn a_slightly_asymmetric_metric_is_solved_as_its_symmetric_part() {
    let (band, roles, dirs, h) = sphere_band(33);
    let s = [1.0];
    // per node an asymmetry of up to 1e-10 relative (what the Python validation lets through),
    // different at every node and entry
    let mut x = 12345u64;
    let asym: Vec<[[f64; 3]; 3]> = (0..band.len())
        .map(|_| {
            let mut m = M3;
            for row in m.iter_mut() {
                for v in row.iter_mut() {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    *v *= 1.0 + 1e-10 * ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
                }
            }
            m
        })
        .collect();
    let sym: Vec<[[f64; 3]; 3]> = asym
        .iter()
        .map(|a| core::array::from_fn(|i| core::array::from_fn(|j| (a[i][j] + a[j][i]) / 2.0)))
        .collect();
    assert!(asym.iter().any(|a| a[0][1] != a[1][0]));
    let got = solve(&band, &roles, &dirs, h, &SymmetricMetric::new(&s, &asym), 1);
    let want = solve(&band, &roles, &dirs, h, &SymmetricMetric::new(&s, &sym), 1);
    assert!(same_bits(&got.0, &want.0));
    assert_eq!((got.1, got.2), (want.1, want.2));
    // the perturbation moved the solution (the symmetric part is not just M3 again)
    let plain = solve(&band, &roles, &dirs, h, &SymmetricMetric::new(&s, &[M3]), 1);
    assert!(!same_bits(&got.0, &plain.0));
}
