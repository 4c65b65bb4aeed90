//! The cost of one local update of the upwind solvers (`tubesweep_core::scheme::upwind`) against the
//! isotropic Godunov update (3), on the neighbour values of plane waves in 3D (directions
//! turning slowly along the sequence as along a row of the sweep, with a small perturbation), for a first visit (`old` = the numerical infinity) and
//! a revisit that changes nothing (`old` = the solution): ns per update, the same data for all.
//!
//!     cargo run --release -p tubesweep-core --example upwind_cost
use std::hint::black_box;
use std::time::Instant;
use tubesweep_core::scheme::godunov::godunov_update;
use tubesweep_core::scheme::hamiltonians::{MovingMedium, SymmetricMetric};
use tubesweep_core::LocalSolver;

const N: usize = 4096;

fn lcg(x: &mut u64) -> f64 {
    *x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*x >> 11) as f64 / (1u64 << 53) as f64
}

/// Neighbour values of `u = q·x` at nodes spread along a row, perturbed by `1e-3 h`.
fn cases(q: impl Fn(usize, [f64; 3]) -> [f64; 3], h: f64) -> Vec<([f64; 3], [f64; 3], f64)> {
    let mut s = 7u64;
    (0..N)
        .map(|i| {
            // the direction turns slowly along the sequence, as along a row of the sweep
            let (a, b) = (i as f64 * 0.02, 0.5 + 0.4 * (i as f64 * 0.003).sin());
            let n = [a.cos() * b.sin(), a.sin() * b.sin(), b.cos()];
            let q = q(i, n);
            let u0 = 1.0 + lcg(&mut s);
            let mut r = || 1e-3 * h * (lcg(&mut s) - 0.5);
            let minus = core::array::from_fn(|k| u0 - q[k] * h + r());
            let plus = core::array::from_fn(|k| u0 + q[k] * h + r());
            (minus, plus, u0)
        })
        .collect()
}

fn time(label: &str, reps: usize, mut f: impl FnMut() -> f64) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        black_box(f());
        best = best.min(t.elapsed().as_secs_f64() * 1e9 / N as f64);
    }
    println!("{label:<48} {best:7.1} ns/update");
    best
}

fn main() {
    let h = 0.01;
    let reps = 200;
    let flow: Vec<[f64; 3]> = (0..N)
        .map(|i| {
            let a = i as f64 * 0.37;
            [0.5 * a.cos(), 0.5 * a.sin(), 0.2]
        })
        .collect();
    let s = [1.0];
    let mm = MovingMedium {
        slowness: &s,
        flow: &flow,
        sigma: None,
    };
    let m3 = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];
    let metric = vec![m3; N];
    let met = SymmetricMetric::new(&s, &metric);
    let iso = cases(|_, n| n, h);
    let rand = cases(
        |i, n| {
            let v = flow[i];
            let c = 1.0 + v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
            core::array::from_fn(|k| n[k] / c)
        },
        h,
    );
    let riem = cases(
        |_, n| {
            let mut q2 = 0.0;
            for r in 0..3 {
                for c in 0..3 {
                    q2 += n[r] * m3[r][c] * n[c];
                }
            }
            core::array::from_fn(|k| n[k] / q2.sqrt())
        },
        h,
    );
    for (visit, first) in [("first visit", true), ("revisit", false)] {
        println!("-- {visit}");
        let old = |u0: f64| if first { 1e6 } else { u0 };
        let g = time("isotropic Godunov (3)", reps, || {
            iso.iter()
                .map(|(m, p, u0)| godunov_update::<3>(core::array::from_fn(|k| m[k].min(p[k])), h).min(old(*u0)))
                .sum()
        });
        let a = time("upwind moving medium |v| = 0.5-0.54, F = 1", reps, || {
            rand.iter()
                .enumerate()
                .map(|(i, (m, p, u0))| mm.update(i, *m, *p, h, old(*u0)))
                .sum()
        });
        let b = time("upwind metric (tilted, eigenvalues 0.3-2.3)", reps, || {
            riem.iter()
                .enumerate()
                .map(|(i, (m, p, u0))| met.update(i, *m, *p, h, old(*u0)))
                .sum()
        });
        println!("ratios: moving medium {:.2}, metric {:.2}", a / g, b / g);
    }
}
