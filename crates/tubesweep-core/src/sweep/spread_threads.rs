//! The pool's threads, each moved once to a CPU of its own when a solve starts.
//!
//! A solve builds its own pool (`SweepProblem::solve`), and the operating system often starts
//! its fresh threads on the CPU of the thread that woke them, all on one core, and moves them
//! apart only some iterations later. The strip pipeline's threads wait for each other tile by
//! tile, so while they share a core a parallel iteration takes longer than the sequential one.
//! Each thread is therefore pinned for a moment to the i-th CPU it may run on, which moves it
//! there at once, and then allowed every CPU again: the scheduler stays free to move it later (to
//! make room for another process, say), and nothing is left pinned. Linux only; elsewhere the
//! threads start where the system puts them.
//!
//! It does not change the median time; it removes slow runs, which come and go with the
//! machine's state. `benches/ab_example.py S S --mode alternate --threads 2 --rounds 60
//! --env-a SPREAD=0` (one build S of the `sphere` example, the threads left where they start
//! against spread; 2-core machine of docs/benchmarks.md): at N = 201 mean 51.1 → 49.6 ms, 90th
//! percentile 61 → 51 ms, runs above 1.3 times the median 5 → 1 of 60, medians 49 and 49; at
//! N = 101 mean 17.9 → 17.2 ms, medians 15 and 16 ms (the example then printed whole milliseconds).
//! In an earlier set of 40 alternating runs of a prototype (the same spreading, switched by an
//! environment variable the solver no longer reads), in a spell where the threads often started
//! together, 12 of 40 runs at N = 101 took more than 1.3 times the median without (mean 21.1 ms,
//! 90th percentile 37) and 1 of 40 with (mean 15.4, 90th percentile 17).

/// Moves each thread of `pool` to its own CPU once (see the module docs); a pool of one thread
/// is left alone.
pub(super) fn over_cpus(pool: &rayon::ThreadPool) {
    if pool.current_num_threads() > 1 {
        pool.broadcast(|b| move_to_cpu(b.index()));
    }
}

/// Moves the calling thread to the `i`-th CPU (cyclically) of those it may run on, then lets it
/// run on all of them again.
fn move_to_cpu(i: usize) {
    #[cfg(target_os = "linux")]
    // SAFETY: cpu_set_t is plain data, zeroed is a valid (empty) set; the calls read and write
    // only the sets passed, of the size passed
    unsafe {
        let size = std::mem::size_of::<libc::cpu_set_t>();
        let mut allowed: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, size, &mut allowed) != 0 {
            return;
        }
        let cpus: Vec<usize> = (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &allowed))
            .collect();
        if cpus.len() < 2 {
            return;
        }
        let mut one: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpus[i % cpus.len()], &mut one);
        if libc::sched_setaffinity(0, size, &one) == 0 {
            libc::sched_setaffinity(0, size, &allowed);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = i;
}

#[cfg(test)]
mod tests {
    /// Spreading leaves every thread free to run on every CPU it could before.
    #[cfg(target_os = "linux")]
    #[test]
    fn spreading_the_threads_leaves_none_of_them_pinned() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        // SAFETY: as in `move_to_cpu`
        let mask = || unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            assert_eq!(
                libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set),
                0
            );
            (0..libc::CPU_SETSIZE as usize)
                .filter(|&c| libc::CPU_ISSET(c, &set))
                .collect::<Vec<_>>()
        };
        let before = pool.broadcast(|_| mask());
        super::over_cpus(&pool);
        let after = pool.broadcast(|_| mask());
        assert_eq!(before, after);
        assert!(after.iter().all(|m| !m.is_empty()));
    }
}
