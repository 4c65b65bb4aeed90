//! The load-balance bound of the parallel sweep on the sphere band: the total work of a sweep
//! (band nodes) over the time the schedule needs with `threads` threads when a node costs one
//! unit and synchronisation is free. Two schedules: the strip pipeline of the square tiles
//! (`NarrowBand::schedule`; threads take strips in order, a tile waits for its upstream tile, see
//! `schedule.rs`), simulated event by event; and, for comparison, waves separated by barriers
//! with the tiles of a wave spread greedily, largest first. Deterministic: no timing. (The solver
//! now also runs strips thin across the front, `NarrowBand::strip_schedule`, picked per
//! iteration; the windowed mode below models tile shapes with strips along the first axis, which
//! is what it picks for the `sphere` example's source on x.)
//!   cargo run --release --example schedule_balance -- 101 201 401
//!
//! With `--windowed` (and the `kernel-stats` feature, whose row log it reads) the work is that
//! of the default solve instead, the front window's: the sphere problem of the `sphere` example
//! is solved on one thread, every row each sweep ran is logged with its nodes and updates, and
//! the pipeline is simulated sweep by sweep with that work, for several tile shapes (rows in x,
//! across the strips × rows in y, along a strip), under two cost models (see `WORK_MODELS`):
//!   cargo run --release -p tubesweep-core --features kernel-stats --example schedule_balance -- --windowed 101 201
//! (`SOURCE_AXIS=1` or `2` moves the source as in the `sphere` example.) Beside the pipeline it
//! prints the bound of a list scheduler that hands any ready tile to the thread free first (a
//! tile is ready once the tile before it in its strip and the one of the previous strip it reads
//! are done; the ready tile of the earliest wave first): what a scheduler not tied to strips could
//! reach on the same tiles.
#[path = "common/shell.rs"]
mod shell;
#[path = "common/sphere_source.rs"]
mod sphere_source;

use tubesweep_core::kernel_stats::RowWork;
use tubesweep_core::{Control, InnerScheme, NarrowBand, NodeRole, SolveOptions};

/// Largest-first assignment of `items` (work per task) to `threads`: the busiest thread's work.
fn critical_path(items: &[usize], threads: usize) -> usize {
    let mut v = items.to_vec();
    v.sort_unstable_by(|a, b| b.cmp(a));
    let mut load = vec![0usize; threads];
    for x in v {
        let i = (0..threads).min_by_key(|&i| load[i]).unwrap();
        load[i] += x;
    }
    load.into_iter().max().unwrap_or(0)
}

/// The strip pipeline of `sweep_strips`: every thread takes the next strip when it is free and
/// runs its tiles in order, each starting when the thread is free and its upstream tile is done.
/// Returns the time the last thread finishes.
fn pipeline_time(
    strip_tiles: &[u32],
    strips: &[u32],
    upstream: &[u32],
    work: &dyn Fn(usize) -> usize,
    threads: usize,
) -> usize {
    let mut finish = vec![0usize; upstream.len()];
    let mut free = vec![0usize; threads];
    for s in 0..strips.len() - 1 {
        // the strip goes to the thread that is free first (ties: the lowest index)
        let i = (0..threads).min_by_key(|&i| free[i]).unwrap();
        let mut t_now = free[i];
        for &t in &strip_tiles[strips[s] as usize..strips[s + 1] as usize] {
            let up = upstream[t as usize];
            let ready = if up == tubesweep_core::band::schedule::NO_TILE {
                0
            } else {
                finish[up as usize]
            };
            t_now = t_now.max(ready) + work(t as usize);
            finish[t as usize] = t_now;
        }
        free[i] = t_now;
    }
    free.into_iter().max().unwrap_or(0)
}

fn main() {
    let windowed = std::env::args().any(|a| a == "--windowed");
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![101, 201, 401] } else { sizes };
    if windowed {
        if !tubesweep_core::kernel_stats::ENABLED {
            eprintln!("--windowed reads the sweeps' row log: build with `--features kernel-stats`");
            std::process::exit(2);
        }
        for n in sizes {
            windowed_bounds(n);
        }
        return;
    }
    for n in sizes {
        let lin = shell::sphere_shell(n).0;
        let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap();
        let sched = band.schedule();
        for threads in [2usize, 4] {
            let (mut total, mut waves_time, mut pipeline) = (0usize, 0usize, 0usize);
            for lead in 0..4 {
                let (rows, tiles, waves) = (sched.rows(lead), sched.tiles(lead), sched.waves(lead));
                let work = |t: usize| -> usize {
                    rows[tiles[t] as usize..tiles[t + 1] as usize]
                        .iter()
                        .map(|&r| {
                            let (s, e) = band.row_range(r as usize);
                            e - s
                        })
                        .sum()
                };
                for w in 0..waves.len() - 1 {
                    let (t0, t1) = (waves[w] as usize, waves[w + 1] as usize);
                    let per_tile: Vec<usize> = (t0..t1).map(work).collect();
                    total += per_tile.iter().sum::<usize>();
                    waves_time += critical_path(&per_tile, threads);
                }
                pipeline += pipeline_time(
                    sched.strip_tiles(lead),
                    sched.strips(lead),
                    sched.upstream(lead),
                    &work,
                    threads,
                );
            }
            println!(
                "N={n} threads={threads}: load-balance bound {:.2}x for the strip pipeline, {:.2}x for waves with barriers",
                total as f64 / pipeline as f64,
                total as f64 / waves_time as f64
            );
        }
    }
}

/// Cost weights of the windowed work model: a row reached, a row run, a node visited, a local
/// update, a tile (its synchronisation). "updates" counts the local updates only; "instructions"
/// weighs each item by roughly the instructions it takes in the row loops (cachegrind, sphere
/// N = 101, one thread: a local update about 150, a node visit about 12, a row about 5 to reach
/// and 30 to run, a tile's wait and flag about 40).
const WORK_MODELS: [(&str, [u64; 5]); 2] = [("updates", [0, 0, 0, 1, 0]), ("instructions", [5, 30, 12, 150, 40])];

/// Tile shapes simulated: rows in x, the first leading axis, across the strips × rows in y, the
/// second, along a strip. The solver's is `TILE` × `TILE` = 8 × 8.
const SHAPES: [(usize, usize); 8] = [(8, 8), (4, 8), (2, 8), (2, 16), (4, 4), (16, 16), (8, 4), (1, 16)];

/// The load-balance bounds of the front window's sweeps on the sphere at `n`: the default solve's
/// work per row and sweep, logged on one thread, put through the strip pipeline (2 and 4
/// threads) for each tile shape and cost model.
fn windowed_bounds(n: usize) {
    let source_axis = sphere_source::source_axis_from_env();
    let (band, roles, weights, h, _) = sphere_source::sphere_with_source(n, source_axis);
    let p = sphere_source::sphere_problem(&band, &roles, &weights, h, InnerScheme::Godunov);
    let mut u = sphere_source::starting_values(&band);
    // the options of the `sphere` example, which are the Python layer's defaults
    let opts = SolveOptions {
        threads: 1,
        activation_threshold: 1e-12,
        tol: 1e-10,
        front_window: tubesweep_core::sweep::DEFAULT_FRONT_WINDOW,
        ..Default::default()
    };
    tubesweep_core::kernel_stats::log_rows(true);
    let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
    let log = tubesweep_core::kernel_stats::take_row_log();
    tubesweep_core::kernel_stats::log_rows(false);
    // one entry per sweep, 8 per iteration (the pass that sets the outer rim at the end, when
    // there is one, counts as an iteration and is not logged)
    let swept = log.len() / 8;
    assert!(
        log.len() == 8 * swept && (swept == st.iterations || swept + 1 == st.iterations),
        "one log entry per sweep on one thread"
    );
    let logged: u64 = log.iter().flatten().map(|w| w.updates as u64).sum();
    println!(
        "sphere N={n}, source on axis {source_axis}: {} sweeps, {} updates in them ({} with the rim pass), {} rows",
        log.len(),
        logged,
        st.updates,
        band.n_rows()
    );
    // the rows' leading coordinates (of their first nodes)
    let indices = band.indices();
    let lead: Vec<[usize; 2]> = (0..band.n_rows())
        .map(|r| {
            let idx = indices[band.row_range(r).0];
            [idx[0], idx[1]]
        })
        .collect();
    println!(
        "{:>8} {:>12} {:>10} {:>10} {:>10} {:>10}",
        "tile", "model", "2 threads", "4 threads", "2 greedy", "4 greedy"
    );
    for (ta, tb) in SHAPES {
        for (name, cost) in WORK_MODELS {
            let mut bounds = Vec::new();
            for greedy in [false, true] {
                for threads in [2usize, 4] {
                    let (mut total, mut time) = (0u64, 0u64);
                    for (k, rows_run) in log.iter().enumerate() {
                        let s = k % 8;
                        let dir = s ^ (s >> 1); // the solver's Gray code order of the orientations
                        let work = tile_work(&lead, n, dir & 3, (ta, tb), rows_run, cost);
                        let nb = (n - 1) / tb + 1;
                        let t = if greedy {
                            greedy_time(&work, nb, threads)
                        } else {
                            pipeline_time_of_tiles(&work, nb, threads)
                        };
                        total += work.iter().filter(|&&w| w != NO_ROWS).sum::<u64>();
                        time += t;
                    }
                    bounds.push(total as f64 / time as f64);
                }
            }
            println!(
                "{:>8} {:>12} {:>9.2}x {:>9.2}x {:>9.2}x {:>9.2}x",
                format!("{ta}x{tb}"),
                name,
                bounds[0],
                bounds[1],
                bounds[2],
                bounds[3]
            );
        }
    }
}

/// Marks a tile without rows in [`tile_work`].
const NO_ROWS: u64 = u64::MAX;

/// The work of every tile of one sweep in leading orientation `signs` with tiles of `shape` rows,
/// strip by strip (`a · nb + b`, `nb` tiles per strip), with `rows_run` the rows it ran and `cost`
/// the model's weights: every row is reached, every tile with a row costs the tile weight;
/// [`NO_ROWS`] for a tile without rows.
fn tile_work(
    lead: &[[usize; 2]],
    n: usize,
    signs: usize,
    shape: (usize, usize),
    rows_run: &[RowWork],
    cost: [u64; 5],
) -> Vec<u64> {
    let (na, nb) = ((n - 1) / shape.0 + 1, (n - 1) / shape.1 + 1);
    let tile_of = |r: usize| -> usize {
        let c0 = if signs & 1 != 0 { n - 1 - lead[r][0] } else { lead[r][0] };
        let c1 = if signs & 2 != 0 { n - 1 - lead[r][1] } else { lead[r][1] };
        (c0 / shape.0) * nb + c1 / shape.1
    };
    let mut work = vec![NO_ROWS; na * nb];
    for r in 0..lead.len() {
        let t = tile_of(r);
        work[t] = if work[t] == NO_ROWS {
            cost[4] + cost[0]
        } else {
            work[t] + cost[0]
        };
    }
    for w in rows_run {
        work[tile_of(w.row as usize)] += cost[1] + cost[2] * w.nodes as u64 + cost[3] * w.updates as u64;
    }
    work
}

/// The strip pipeline's time for one sweep's tile `work` (`nb` tiles per strip): the strips in
/// order, each to the thread free first; a tile waits for the one before it in its strip (the
/// same thread) and for the previous strip's tile with the same `b`.
fn pipeline_time_of_tiles(work: &[u64], nb: usize, threads: usize) -> u64 {
    let na = work.len() / nb;
    let mut finish = vec![0u64; na * nb];
    let mut free = vec![0u64; threads];
    for a in 0..na {
        if (0..nb).all(|b| work[a * nb + b] == NO_ROWS) {
            continue;
        }
        let i = (0..threads).min_by_key(|&i| free[i]).unwrap();
        let mut now = free[i];
        for b in 0..nb {
            let t = a * nb + b;
            if work[t] == NO_ROWS {
                continue;
            }
            let ready = if a > 0 && work[t - nb] != NO_ROWS {
                finish[t - nb]
            } else {
                0
            };
            now = now.max(ready) + work[t];
            finish[t] = now;
        }
        free[i] = now;
    }
    free.into_iter().max().unwrap_or(0)
}

/// A list scheduler on the same tiles and dependencies, not tied to strips: tile `(a, b)` is ready
/// once `(a − 1, b)` and `(a, b − 1)` are done, and a thread that comes free takes the ready tile
/// of the earliest wave `a + b` (then the lowest `a`). Returns the time the last tile finishes.
fn greedy_time(work: &[u64], nb: usize, threads: usize) -> u64 {
    let na = work.len() / nb;
    let cost = |t: usize| if work[t] == NO_ROWS { 0 } else { work[t] };
    let mut waiting_for: Vec<u8> = (0..na * nb).map(|t| (t >= nb) as u8 + (t % nb > 0) as u8).collect();
    let mut ready = vec![0usize];
    let mut running: Vec<(u64, usize)> = Vec::new(); // (finish time, tile)
    let (mut idle, mut now, mut done) = (threads, 0u64, 0usize);
    while done < na * nb {
        while idle > 0 && !ready.is_empty() {
            let i = (0..ready.len())
                .min_by_key(|&i| (ready[i] / nb + ready[i] % nb, ready[i] / nb))
                .unwrap();
            let t = ready.swap_remove(i);
            running.push((now + cost(t), t));
            idle -= 1;
        }
        let k = (0..running.len()).min_by_key(|&k| running[k].0).unwrap();
        let (finish, t) = running.swap_remove(k);
        (now, done, idle) = (finish, done + 1, idle + 1);
        if t / nb + 1 < na {
            waiting_for[t + nb] -= 1;
            if waiting_for[t + nb] == 0 {
                ready.push(t + nb);
            }
        }
        if t % nb + 1 < nb {
            waiting_for[t + 1] -= 1;
            if waiting_for[t + 1] == 0 {
                ready.push(t + 1);
            }
        }
    }
    now
}
