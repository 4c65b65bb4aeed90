//! The load-balance bound of the parallel sweep on the sphere band: the total work of a sweep
//! (band nodes) over the time the schedule needs with `threads` threads when a node costs one
//! unit and synchronisation is free. Two schedules: the strip pipeline the solver runs (threads
//! take strips in order, a tile waits for its upstream tile, see `schedule.rs`), simulated event
//! by event; and, for comparison, waves separated by barriers with the tiles of a wave spread
//! greedily, largest first. Deterministic: no timing.
//!   cargo run --release --example schedule_balance -- 101 201 401
#[path = "common/shell.rs"]
mod shell;

use tubesweep_core::{NarrowBand, NodeRole};

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
fn pipeline_time(strip_tiles: &[u32], strips: &[u32], upstream: &[u32], work: &dyn Fn(usize) -> usize, threads: usize) -> usize {
    let mut finish = vec![0usize; upstream.len()];
    let mut free = vec![0usize; threads];
    for s in 0..strips.len() - 1 {
        // the strip goes to the thread that is free first (ties: the lowest index)
        let i = (0..threads).min_by_key(|&i| free[i]).unwrap();
        let mut t_now = free[i];
        for &t in &strip_tiles[strips[s] as usize..strips[s + 1] as usize] {
            let up = upstream[t as usize];
            let ready = if up == tubesweep_core::schedule::NO_TILE { 0 } else { finish[up as usize] };
            t_now = t_now.max(ready) + work(t as usize);
            finish[t as usize] = t_now;
        }
        free[i] = t_now;
    }
    free.into_iter().max().unwrap_or(0)
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![101, 201, 401] } else { sizes };
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
                pipeline += pipeline_time(sched.strip_tiles(lead), sched.strips(lead), sched.upstream(lead), &work, threads);
            }
            println!(
                "N={n} threads={threads}: load-balance bound {:.2}x for the strip pipeline, {:.2}x for waves with barriers",
                total as f64 / pipeline as f64,
                total as f64 / waves_time as f64
            );
        }
    }
}
