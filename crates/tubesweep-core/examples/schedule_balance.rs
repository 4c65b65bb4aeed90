//! The load-balance bound of the parallel sweep schedule on the sphere band: the total work of a
//! sweep (band nodes) over its critical path when the tiles of every wave are spread over
//! `threads` threads, greedily largest first, as single tiles and as the sweep runs them (pairs
//! of tiles only in waves with at least 4 tiles per thread). Deterministic: no timing.
//!   cargo run --release --example schedule_balance -- 101 201 401
use tubesweep_core::NarrowBand;

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

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![101, 201, 401] } else { sizes };
    for n in sizes {
        let h = 2.0 / (n - 1) as f64;
        let mut lin = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let x = [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
                    let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                    if (r - 0.5).abs() <= 4.0 * h {
                        lin.push(((i * n + j) * n + k) as u64);
                    }
                }
            }
        }
        let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap();
        let sched = band.schedule();
        for threads in [2usize, 4] {
            let (mut total, mut single, mut scheduled) = (0usize, 0usize, 0usize);
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
                    single += critical_path(&per_tile, threads);
                    let tasks: Vec<usize> = if t1 - t0 >= 4 * threads {
                        per_tile.chunks(2).map(|c| c.iter().sum()).collect()
                    } else {
                        per_tile
                    };
                    scheduled += critical_path(&tasks, threads);
                }
            }
            println!(
                "N={n} threads={threads}: load-balance bound {:.2}x with single tiles, {:.2}x as scheduled",
                total as f64 / single as f64,
                total as f64 / scheduled as f64
            );
        }
    }
}
