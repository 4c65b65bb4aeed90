//! The cost per node update of the upwind solvers (`tubesweep_core::scheme::upwind`) inside the
//! sweeps, against the isotropic Godunov update (3) on the same band, the same thread count and
//! the same sweep mode: the sphere of radius 0.5 in [−1,1]^3 (the band of the other examples), one
//! source at (−0.5, 0, 0), unit speed, and
//!
//! * the isotropic Godunov update (3) through the solver's own kernel (`InnerScheme::Godunov`), and
//!   through the upwind solvers' interface (`InnerScheme::Upwind` with `Isotropic`: the same
//!   dispatch, Eq. (3) as the local solve);
//! * the upwind moving medium with the rigid rotation `v = ω e_z × x̂ R` (ω = 1), and with v = 0;
//! * the upwind metric: a constant tilted `M` (eigenvalues 0.3–2.3), and `M = I`, both stored per
//!   node (`D(D+1)/2 = 6` numbers, 48 bytes: a surface's tangential `M` is per node, so this is the
//!   realistic cost), and the tilted `M` stored once for all nodes (a constant `M` off a surface).
//!
//! Each in two sweep modes: the plain sweeps (`skip_inactive: false`, every node in every sweep)
//! and the default sweeps of the general Hamiltonians (active flags, the rim last, no coupling,
//! no front window). Prints ns per node update (sweep seconds / updates), the updates and the
//! iterations; the fastest of `REPS` (default 5) rounds, the cases alternating. Beside it, the
//! same from the process's CPU time (user + system, `getrusage`) over the solve: on a shared,
//! busy machine the wall time also counts the time the solve waited for a core, the CPU time
//! does not.
//!
//!     cargo run --release -p tubesweep-core --example upwind_sweep -- [N=101] [threads=1]
//!   (`SOURCE_AXIS=1` or `2` puts the source on the y or z axis, as in the other examples; `CASE=text`
//!   runs only the cases whose name contains it, beside Eq. (3))
#[path = "common/shell.rs"]
mod shell;
#[path = "common/sphere_source.rs"]
mod sphere_source;

use tubesweep_core::scheme::hamiltonians::{Isotropic, MovingMedium, SymmetricMetric};
#[allow(unused_imports)]
use tubesweep_core::{Control, InnerScheme, NarrowBand, NodeRole, SolveOptions, SolveStats};

/// The CPU time of this process so far (user + system, all its threads, ended ones included).
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes into the struct it is given
    let mut r: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut r) };
    let t = |v: libc::timeval| v.tv_sec as f64 + 1e-6 * v.tv_usec as f64;
    t(r.ru_utime) + t(r.ru_stime)
}

/// The solve's statistics and the CPU seconds it took.
fn run(
    band: &NarrowBand<3>,
    p: &tubesweep_core::SweepProblem<'_, 3>,
    plain: bool,
    threads: usize,
) -> (SolveStats, f64) {
    let opts = SolveOptions {
        threads,
        skip_inactive: !plain,
        coupled: false,
        front_window: 0.0,
        defer_outer_rim: !plain,
        row_prefetch_above: std::env::var("PREFETCH_ABOVE")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(tubesweep_core::sweep::default_row_prefetch_above),
        ..Default::default()
    };
    let mut u = sphere_source::starting_values(band);
    let c0 = cpu_seconds();
    let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
    (st, cpu_seconds() - c0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(101);
    let threads: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let (band, roles, weights, h, _) = sphere_source::sphere_with_source(n, sphere_source::source_axis_from_env());
    let idx = band.indices();
    // the rotation about z at each node's closest point on the sphere (R = 0.5), tangent there
    let flow: Vec<[f64; 3]> = idx
        .iter()
        .map(|i| {
            let x: [f64; 3] = core::array::from_fn(|k| -1.0 + i[k] as f64 * h);
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt().max(1e-12);
            [-0.5 * x[1] / r, 0.5 * x[0] / r, 0.0]
        })
        .collect();
    let zero = vec![[0.0; 3]; band.len()];
    let s = [1.0];
    let m3 = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];
    let tilted = vec![m3; band.len()];
    let ident = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; band.len()];
    let rot = MovingMedium {
        slowness: &s,
        flow: &flow,
        sigma: None,
    };
    let still = MovingMedium {
        slowness: &s,
        flow: &zero,
        sigma: None,
    };
    let met = SymmetricMetric::new(&s, &tilted);
    let eye = SymmetricMetric::new(&s, &ident);
    let one = SymmetricMetric::new(&s, &[m3]);
    let iso = Isotropic {
        slowness: &s,
        sigma: None,
    };
    let cases: [(&str, InnerScheme<'_, 3>); 7] = [
        ("isotropic Godunov (3)", InnerScheme::Godunov),
        ("Eq. (3) through the upwind interface", InnerScheme::Upwind(&iso)),
        ("upwind moving medium, rotation", InnerScheme::Upwind(&rot)),
        ("upwind moving medium, v = 0", InnerScheme::Upwind(&still)),
        ("upwind metric, tilted M", InnerScheme::Upwind(&met)),
        ("upwind metric, M = I", InnerScheme::Upwind(&eye)),
        ("upwind metric, one tilted M for all", InnerScheme::Upwind(&one)),
    ];
    println!("sphere N={n}, band {} nodes, {threads} thread(s)", band.len());
    // the cases alternate, round after round, and each keeps its fastest round: the machine is
    // shared, and a load that comes and goes then falls on all of them alike
    let reps: usize = std::env::var("REPS").ok().and_then(|s| s.parse().ok()).unwrap_or(5);
    for plain in [true, false] {
        println!(
            "-- {}",
            if plain {
                "plain sweeps (every node in every sweep)"
            } else {
                "active flags, the rim last (the general Hamiltonians' default)"
            }
        );
        let mut best: Vec<Option<SolveStats>> = vec![None; cases.len()];
        let mut best_cpu = vec![f64::INFINITY; cases.len()];
        for _ in 0..reps {
            for (i, (name, scheme)) in cases.iter().enumerate() {
                // `CASE=text` runs Eq. (3) and the cases whose name contains it (for profiling)
                if i > 0 && std::env::var("CASE").is_ok_and(|c| !name.contains(c.as_str())) {
                    continue;
                }
                let p = sphere_source::sphere_problem(&band, &roles, &weights, h, *scheme);
                let (st, cpu) = run(&band, &p, plain, threads);
                best_cpu[i] = best_cpu[i].min(cpu);
                if best[i].as_ref().is_none_or(|b| st.seconds < b.seconds) {
                    best[i] = Some(st);
                }
            }
        }
        let ns = |st: &SolveStats| 1e9 * st.seconds / st.updates.max(1) as f64;
        let iso = ns(best[0].as_ref().unwrap());
        let cpu_ns = |i: usize| 1e9 * best_cpu[i] / best[i].as_ref().map_or(1, |st| st.updates.max(1)) as f64;
        let iso_cpu = cpu_ns(0);
        for (i, ((name, _), st)) in cases.iter().zip(&best).enumerate() {
            let Some(st) = st.as_ref() else { continue };
            println!(
                "{name:<38} {:6.1} ns/update ({:4.2}x), CPU {:6.1} ns ({:4.2}x)  {:>9} updates  {:3} iterations  {:.3} s",
                ns(st),
                ns(st) / iso,
                cpu_ns(i),
                cpu_ns(i) / iso_cpu,
                st.updates,
                st.iterations,
                st.seconds
            );
        }
    }
}
