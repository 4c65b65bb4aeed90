//! The cost of the second-order solve (`order=2`) per phase: the set-up (geometry, factoring),
//! phase 1 and phase 2, with their updates and nanoseconds per update, on inputs dumped from
//! `ts.solve(..., order=2)` by `benches/order2_dump.py` (the band's linear indices, roles, φ,
//! directions and the solve's parameters, as the Python layer hands them to the core).
//!
//! ```text
//! .venv/bin/python benches/order2_dump.py sphere 201 /tmp/sphere201
//! cargo run --release -p tubesweep-core --example order2_phases -- /tmp/sphere201 [rounds] [threads]
//! ```
//!
//! Each round prints the set-up's two passes, then each phase's time, updates and ns/update (the
//! phases are told apart by the iteration count of phase 1, from the solve's statistics; the time
//! of an iteration is taken at its progress report). The last line gives the medians.

use std::time::Instant;

use tubesweep_core::second_order::{
    check_geometry_of, factor_sources_of, starting_values, sweep_second_order, tube_geometry_of, tube_setup_of,
    Implicit, SecondOrderOptions,
};
use tubesweep_core::sweep::Slowness;
use tubesweep_core::{Control, NarrowBand, NodeRole};

fn read_bytes(dir: &str, name: &str) -> Vec<u8> {
    std::fs::read(format!("{dir}/{name}")).unwrap_or_else(|e| panic!("{dir}/{name}: {e}"))
}

fn floats(line: &str) -> Vec<f64> {
    line.split_whitespace().map(|w| w.parse().expect("a number")).collect()
}

/// The calling thread's CPU time in seconds (with one thread the solve runs on it; a shared
/// machine's load then shows less than in wall-clock time).
fn cpu_now() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid timespec to write to
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Seconds since `t0` on the clock of the run: the thread's CPU time with one thread, wall-clock
/// time with several.
fn since(t0: f64, cpu: bool) -> f64 {
    if cpu {
        cpu_now() - t0
    } else {
        WALL.with(|w| w.elapsed().as_secs_f64()) - t0
    }
}

fn now(cpu: bool) -> f64 {
    since(0.0, cpu)
}

thread_local! {
    static WALL: Instant = Instant::now();
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn least(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = args.get(1).expect("the dump's directory");
    let rounds: usize = args.get(2).map_or(5, |s| s.parse().expect("rounds"));
    let threads: usize = args.get(3).map_or(1, |s| s.parse().expect("threads"));
    let params = String::from_utf8(read_bytes(dir, "params.txt")).expect("text");
    let lines: Vec<Vec<f64>> = params.lines().map(floats).collect();
    let n = lines[0][0] as usize;
    let (h, lower) = (lines[0][1], [lines[0][2], lines[0][3], lines[0][4]]);
    let source = [lines[1][0], lines[1][1], lines[1][2]];
    let (source_slowness, slowness) = (lines[1][3], lines[1][4]);
    let (fix_radius, outer_width, tol_first, tol) = (lines[2][0], lines[2][1], lines[2][2], lines[2][3]);
    let (window_first, window_second, ramp_length) = (lines[2][4], lines[2][5], lines[2][6]);
    // the extension's limit (older dumps: none, the unlimited BDF2)
    let extension_limit = lines[2].get(7).copied().unwrap_or(f64::INFINITY);
    let linear: Vec<u64> = read_bytes(dir, "linear")
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let roles: Vec<NodeRole> = read_bytes(dir, "roles")
        .iter()
        .map(|&r| match r {
            0 => NodeRole::Fixed,
            1 => NodeRole::Inner,
            _ => NodeRole::Outer,
        })
        .collect();
    let phi: Vec<f64> = read_bytes(dir, "phi")
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let dirs: Vec<[f32; 3]> = read_bytes(dir, "dirs")
        .chunks_exact(12)
        .map(|c| std::array::from_fn(|k| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
        .collect();
    let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &linear).expect("band");
    // the set-up runs on the calling thread, and so do the sweeps on one thread
    let cpu = threads == 1 && std::env::var("WALL").is_err();
    println!(
        "{} band nodes, N = {n}, {threads} thread(s), {} time",
        band.len(),
        if cpu { "CPU" } else { "wall-clock" }
    );
    let surface = Implicit::LevelSet(&phi);
    let options = SecondOrderOptions {
        tol_first,
        tol,
        // MAX_ITERATIONS=20 on the sphere at N = 201: phase 1 alone (for profiling it)
        max_iterations: std::env::var("MAX_ITERATIONS").map_or(10000, |v| v.parse().expect("a count")),
        stall_ratio: tubesweep_core::second_order::STALL_RATIO,
        stall_window: 20,
        own_first_phase: true,
        window_first,
        window_second,
        threads,
        ramp_length,
        extension_limit,
    };
    let (mut setup, mut p1, mut p2, mut ns1, mut ns2) = (vec![], vec![], vec![], vec![], vec![]);
    for round in 0..rounds {
        // TWO_PASSES=1: the geometry and the factoring by their own functions, one after the other
        let t = now(cpu);
        let (geometry, factoring, t_geo) = if std::env::var("TWO_PASSES").is_ok() {
            let geometry = tube_geometry_of(&band, &roles, &surface, &dirs, h, outer_width).expect("geometry");
            let t_geo = since(t, cpu);
            let factoring = factor_sources_of(
                &band,
                &roles,
                &surface,
                &dirs,
                lower,
                h,
                &[source],
                &[source_slowness],
                fix_radius,
            )
            .expect("factoring");
            (geometry, factoring, t_geo)
        } else {
            let (geometry, factoring) = tube_setup_of(
                &band,
                &roles,
                &surface,
                &dirs,
                lower,
                h,
                outer_width,
                &[source],
                &[source_slowness],
                fix_radius,
                threads,
            )
            .expect("set-up");
            (geometry, factoring.expect("factoring"), since(t, cpu))
        };
        let t_fac = since(t, cpu) - t_geo;
        check_geometry_of(&geometry.summary, outer_width, h, false).expect("geometry check");
        let mut values = starting_values(&factoring);
        // per iteration: the time at its report and its updates
        let mut marks: Vec<(f64, u64)> = Vec::new();
        let t = now(cpu);
        let stats = sweep_second_order(
            &band,
            &geometry,
            &factoring,
            &dirs,
            Slowness::Constant(slowness),
            h,
            &mut values,
            &options,
            &mut |r| {
                marks.push((since(t, cpu), r.updates));
                Control::Continue
            },
        )
        .expect("solve");
        let total = since(t, cpu);
        let k = stats.first_order_iterations;
        // (no phase 1 when tol_first is +∞, the package's choice in 3D: 0 s, 0 updates)
        let t1 = if k == 0 { 0.0 } else { marks[k - 1].0 };
        let u1 = marks[..k].iter().map(|m| m.1).sum::<u64>();
        let u2: u64 = marks[k..].iter().map(|m| m.1).sum::<u64>().max(1);
        let t2 = total - t1;
        let digest = values.iter().fold(0u64, |a, v| a.rotate_left(5) ^ v.to_bits());
        println!(
            "round {round}: set-up {:.4} s (geometry {t_geo:.4}, factoring {t_fac:.4}); phase 1 {t1:.4} s, {u1} updates, \
             {:.1} ns; phase 2 {t2:.4} s, {u2} updates, {:.1} ns; {} + {} iterations, converged {}, digest {digest:016x}",
            t_geo + t_fac,
            t1 / u1.max(1) as f64 * 1e9,
            t2 / u2 as f64 * 1e9,
            stats.first_order_iterations,
            stats.second_order_iterations,
            stats.converged,
        );
        setup.push(t_geo + t_fac);
        p1.push(t1);
        p2.push(t2);
        ns1.push(t1 / u1.max(1) as f64 * 1e9);
        ns2.push(t2 / u2 as f64 * 1e9);
    }
    println!(
        "least: set-up {:.4} s, phase 1 {:.1} ns/update, phase 2 {:.1} ns/update",
        least(&setup),
        least(&ns1),
        least(&ns2)
    );
    println!(
        "median: set-up {:.4} s, phase 1 {:.4} s ({:.1} ns/update), phase 2 {:.4} s ({:.1} ns/update)",
        median(&mut setup),
        median(&mut p1),
        median(&mut ns1),
        median(&mut p2),
        median(&mut ns2)
    );
}
