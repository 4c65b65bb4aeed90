//! Criterion micro-benchmarks of the sweeping kernel (issue 7) on a 3D sphere band.
//!
//! The band is built here, in Rust, the way the Python layer builds it: the grid nodes of
//! `[-1, 1]^3` (N per axis) with `|‖x‖ − 0.5| ≤ 4h`, inner tube `≤ 2h` (eikonal update, Eq. 3 or
//! Eq. 4), extension layer beyond (Eq. 5 applied to Eq. 8, direction = radial `sgn(φ) x/‖x‖`),
//! the node nearest `(−0.5, 0, 0)` fixed to 0.
//!
//! Two measurements per scheme (Godunov, Lax–Friedrichs) and size (N = 101, 201):
//! * `first-iteration`: one iteration = all 2^3 Gauss–Seidel sweep orders over the whole band
//!   from the initial state (values at the numerical infinity), i.e. `max_iterations = 1` with
//!   the front window off (with it, the first iteration covers only the window round the source);
//! * `to-convergence` (N = 101 only, to keep `cargo bench` short): the whole solve, tol 1e-10.
//!
//! And the kernel alone, Godunov: `plain-to-convergence` at N = 101, 201 and 401 (about 45 s of
//! the run's time at N = 401), the paper's sweeps to the letter
//! (`skip_inactive: false`: every node but the fixed ones updated in every sweep, pointwise, the
//! rim in every sweep), whose rate counts no skipped node, on one thread and on all cores; at
//! N = 201 and 401 the iterations' rows exceed a quarter of a 32 MB last-level cache and the
//! sweeps fetch their rows ahead (`row_prefetch_above`).
//!
//! Throughput is reported in elements = local updates (`SolveStats::updates` of one calibration
//! run), so criterion prints local updates per second. Run with
//! `cargo bench -p tubesweep-core --bench sweep`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use std::time::Duration;
use tubesweep_core::sweep::{Extension, MissingNeighbour, Slowness};
use tubesweep_core::{Control, InnerScheme, NarrowBand, NodeRole, SolveOptions, SweepProblem};

/// The sphere band of radius 0.5 in `[-1, 1]^3` with `n` nodes per axis.
struct SphereBand {
    band: NarrowBand<3>,
    roles: Vec<NodeRole>,
    directions: Vec<[f32; 3]>,
    h: f64,
}

fn sphere_band(n: usize) -> SphereBand {
    let h = 2.0 / (n - 1) as f64;
    let (inner, outer) = (2.0 * h, 4.0 * h);
    let mut linear = Vec::new();
    let mut roles = Vec::new();
    let mut directions = Vec::new();
    let src = [-0.5, 0.0, 0.0];
    let mut best = (f64::INFINITY, 0usize);
    for i in 0..n {
        let x = -1.0 + h * i as f64;
        for j in 0..n {
            let y = -1.0 + h * j as f64;
            for k in 0..n {
                let z = -1.0 + h * k as f64;
                let r = (x * x + y * y + z * z).sqrt();
                let phi = r - 0.5;
                if phi.abs() > outer * (1.0 + 1e-9) {
                    continue;
                }
                let d2 = (x - src[0]).powi(2) + (y - src[1]).powi(2) + (z - src[2]).powi(2);
                if d2 < best.0 && phi.abs() <= inner {
                    best = (d2, roles.len());
                }
                linear.push(((i * n + j) * n + k) as u64);
                roles.push(if phi.abs() <= inner * (1.0 + 1e-9) {
                    NodeRole::Inner
                } else {
                    NodeRole::Outer
                });
                let s = phi.signum() / r.max(1e-300);
                directions.push([(s * x) as f32, (s * y) as f32, (s * z) as f32]);
            }
        }
    }
    roles[best.1] = NodeRole::Fixed;
    let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &linear).expect("valid band");
    SphereBand {
        band,
        roles,
        directions,
        h,
    }
}

fn problem<'a>(b: &'a SphereBand, scheme: InnerScheme<'a, 3>) -> SweepProblem<'a, 3> {
    SweepProblem {
        band: &b.band,
        roles: &b.roles,
        spacing: b.h,
        slowness: Slowness::Constant(1.0),
        extension: Extension::Directions(&b.directions),
        scheme,
        missing: MissingNeighbour::Extrapolate,
    }
}

fn run(p: &SweepProblem<'_, 3>, values: &mut Vec<f64>, opts: &SolveOptions) -> u64 {
    values.iter_mut().for_each(|v| *v = 0.0);
    let stats = p.solve(values, opts, &mut |_| Control::Continue).expect("solve");
    stats.updates
}

/// The paper's sweeps to the letter (see the module doc).
fn plain() -> SolveOptions {
    SolveOptions {
        skip_inactive: false,
        coupled: false,
        defer_outer_rim: false,
        front_window: 0.0,
        ..Default::default()
    }
}

fn bench_plain_kernel(c: &mut Criterion) {
    for n in [101usize, 201, 401] {
        let b = sphere_band(n);
        let mut values = vec![0.0; b.band.len()];
        let mut group = c.benchmark_group(format!("sphere-N{n}"));
        group
            .sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(3));
        group.sampling_mode(SamplingMode::Flat);
        let p = problem(&b, InnerScheme::Godunov);
        for threads in [1, 0] {
            let opts = SolveOptions { threads, ..plain() };
            let updates = run(&p, &mut values, &opts);
            group.throughput(Throughput::Elements(updates));
            let id = BenchmarkId::new(
                "plain-to-convergence",
                if threads == 1 {
                    "godunov-1-thread"
                } else {
                    "godunov-all-cores"
                },
            );
            group.bench_function(id, |bch| bch.iter(|| run(&p, &mut values, &opts)));
        }
        group.finish();
    }
}

fn bench_kernel(c: &mut Criterion) {
    let schemes: [(&str, InnerScheme<'static, 3>); 2] =
        [("godunov", InnerScheme::Godunov), ("lxf", InnerScheme::LaxFriedrichs)];
    for &n in &[101usize, 201] {
        let b = sphere_band(n);
        let mut values = vec![0.0; b.band.len()];
        let mut group = c.benchmark_group(format!("sphere-N{n}"));
        group
            .sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(3));
        group.sampling_mode(SamplingMode::Flat);
        for (name, scheme) in schemes.iter() {
            let p = problem(&b, *scheme);
            let one = SolveOptions {
                max_iterations: 1,
                front_window: 0.0,
                ..Default::default()
            };
            let updates = run(&p, &mut values, &one);
            group.throughput(Throughput::Elements(updates));
            group.bench_function(BenchmarkId::new("first-iteration", name), |bch| {
                bch.iter(|| run(&p, &mut values, &one))
            });
            if n <= 101 {
                let full = SolveOptions::default();
                let updates = run(&p, &mut values, &full);
                group.throughput(Throughput::Elements(updates));
                group.bench_function(BenchmarkId::new("to-convergence", name), |bch| {
                    bch.iter(|| run(&p, &mut values, &full))
                });
            }
        }
        eprintln!("sphere N={n}: {} band nodes", b.band.len());
        group.finish();
    }
}

criterion_group!(benches, bench_kernel, bench_plain_kernel);
criterion_main!(benches);
