//! Solves the two-layer problem on a sphere of radius 0.5 in [−1,1]^3 and prints the work done.
//! Used for profiling the sweep kernel:
//!   cargo run --release --example sphere -- 101 godunov 1 [coupled|pointwise]
//!   (VERBOSE=1 prints every iteration; THR, TOL and WINDOW set the activation threshold, the
//!   tolerance and the front window, `SolveOptions::front_window`; SOURCE_AXIS=1 or 2 puts the
//!   source on the y or z axis instead of x, z being the axis of the rows; PLAIN=1 runs the
//!   paper's sweeps to the letter: no active flags (`skip_inactive: false`), pointwise update,
//!   the rim in every sweep; Python's `paper_sweeps=True` is the same but keeps the flags, and
//!   PAPER=1 runs that (pointwise, the rim in every sweep, no window, the flags kept);
//!   SPREAD=0 leaves the pool's threads where the system starts them,
//!   `SolveOptions::spread_threads`; PREFETCH_ABOVE=bytes sets `SolveOptions::row_prefetch_above`,
//!   0 prefetches the rows ahead in every iteration and "never" in none)
//!   valgrind --tool=callgrind target/release/examples/sphere 61 godunov 1
//!   (built with `--features kernel-stats` it also prints the sweeps' counters: where the
//!   parallel sweeps wait, the rows and nodes they visit, how far the updates move the values;
//!   `tubesweep_core::kernel_stats`)
#[path = "common/shell.rs"]
mod shell;
#[path = "common/sphere_source.rs"]
mod sphere_source;

use std::time::Instant;
use tubesweep_core::{Control, InnerScheme, NodeRole, SolveOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(101);
    let scheme = match args.get(2).map(|s| s.as_str()) {
        Some("lxf") => InnerScheme::LaxFriedrichs,
        _ => InnerScheme::Godunov,
    };
    let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let plain = std::env::var_os("PLAIN").is_some();
    // Python's `paper_sweeps=True`: the paper's sweeps with the active flags kept
    let paper = std::env::var_os("PAPER").is_some();
    let coupled = !plain && !paper && args.get(4).is_none_or(|s| s != "pointwise");
    let defer_outer_rim = !plain && !paper && std::env::var_os("RIM_IN_EVERY_SWEEP").is_none();
    let source_axis = sphere_source::source_axis_from_env();
    let (band, roles, dirs, h, build) = sphere_source::sphere_with_source(n, source_axis);
    let p = sphere_source::sphere_problem(&band, &roles, &dirs, h, scheme);
    let mut u = sphere_source::starting_values(&band);
    let thr: f64 = std::env::var("THR").ok().and_then(|s| s.parse().ok()).unwrap_or(1e-12);
    let tol: f64 = std::env::var("TOL").ok().and_then(|s| s.parse().ok()).unwrap_or(1e-10);
    let front_window: f64 = std::env::var("WINDOW")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(tubesweep_core::sweep::DEFAULT_FRONT_WINDOW);
    // the front window runs only with the active flags
    let front_window = if plain || paper { 0.0 } else { front_window };
    let opts = SolveOptions {
        threads,
        activation_threshold: thr,
        tol,
        coupled,
        defer_outer_rim,
        front_window,
        skip_inactive: !plain,
        // `SPREAD=0`: the pool's threads start where the system puts them
        spread_threads: std::env::var("SPREAD").map_or(true, |v| v != "0"),
        // `PREFETCH_ABOVE=bytes`: `SolveOptions::row_prefetch_above` (0 always, "never" never)
        row_prefetch_above: match std::env::var("PREFETCH_ABOVE") {
            Ok(v) if v == "never" => usize::MAX,
            Ok(v) if !v.is_empty() => v.parse().expect("PREFETCH_ABOVE: a number of bytes or \"never\""),
            _ => tubesweep_core::sweep::default_row_prefetch_above(),
        },
        ..Default::default()
    };
    let verbose = std::env::var_os("VERBOSE").is_some();
    let t0 = Instant::now();
    let st = p
        .solve(&mut u, &opts, &mut |r| {
            if verbose {
                println!(
                    "  iteration {:3} at {:9.6} s  largest change {:.3e}  updates {}",
                    r.iteration,
                    t0.elapsed().as_secs_f64(),
                    r.max_change,
                    r.updates
                );
            }
            Control::Continue
        })
        .unwrap();
    let solve_s = t0.elapsed().as_secs_f64();
    let mut antipode = [((n - 1) / 2) as i64; 3];
    antipode[source_axis] = (3 * (n - 1) / 4) as i64;
    let far = band.find(antipode).unwrap();
    println!(
        "N={n} coupled={coupled} rim_last={defer_outer_rim} window={front_window} band={} build={build:.3}s iterations={} updates={} sweeps={:.6}s {:.1} M updates/s prefetched={} u(antipode)={:.5} solve={solve_s:.3}s",
        band.len(),
        st.iterations,
        st.updates,
        st.seconds,
        st.updates as f64 / st.seconds / 1e6,
        st.prefetch_iterations,
        u[far]
    );
    let exact = std::f64::consts::PI / 4.0;
    let mut err = 0.0f64;
    for (i, idx) in band.indices().iter().enumerate() {
        // inner nodes on the plane through the centre normal to the source's axis (x = 0 by
        // default): exact distance pi/4 at the closest point
        if idx[source_axis] == (n - 1) / 2 && roles[i] == NodeRole::Inner {
            err = err.max((u[i] - exact).abs());
        }
    }
    println!(
        "  max |u - pi/4| on the inner nodes of {} = 0: {err:.3e}",
        ["x", "y", "z"][source_axis]
    );
    if tubesweep_core::kernel_stats::ENABLED {
        // 0 threads: rayon's default number (what the solve's own pool got)
        let used = if threads == 0 {
            rayon::current_num_threads()
        } else {
            threads
        };
        print_kernel_stats(used, st.seconds);
    }
}

/// The `kernel-stats` counters of the solve (see `tubesweep_core::kernel_stats`); `seconds` is
/// the solve's time, `threads` its threads.
fn print_kernel_stats(threads: usize, seconds: f64) {
    use tubesweep_core::kernel_stats::{snapshot, CHANGE_BINS};
    let s = snapshot();
    // counting slows the sweeps (see kernel_stats), so the waits are given as a share of the
    // threads' time in the solve as well
    let thread_ms = threads as f64 * seconds * 1e3;
    println!(
        "  kernel stats: the {threads} thread{} waited {:.1} ms for upstream tiles ({} waits), {:.0}% of their {:.0} ms in the solve, and {:.1} ms at barriers ({:.0}%)",
        if threads == 1 { "" } else { "s" },
        s.tile_wait_ns as f64 * 1e-6,
        s.tile_waits,
        100.0 * s.tile_wait_ns as f64 * 1e-6 / thread_ms,
        thread_ms,
        s.barrier_wait_ns as f64 * 1e-6,
        100.0 * s.barrier_wait_ns as f64 * 1e-6 / thread_ms,
    );
    println!(
        "  rows reached {}, run {}; nodes visited in them {}",
        s.rows_seen, s.rows_run, s.node_visits
    );
    for (role, name) in [(1, "inner"), (2, "layer")] {
        let h = &s.change_histogram[role];
        let total: u64 = h.iter().sum();
        let bins: Vec<String> = (2..CHANGE_BINS).map(|b| format!("{}", h[b])).collect();
        println!(
            "  {name} updates {total}: unchanged {}, change ≥ 1 {}, per decade [1e-1, 1), [1e-2, 1e-1), …: {}",
            h[0],
            h[1],
            bins.join(" ")
        );
    }
}
