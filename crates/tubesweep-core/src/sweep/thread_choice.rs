//! The default thread count on a busy machine: iteration by iteration, the parallel sweeps or the
//! sequential sweep on the calling thread, whichever the measurements say is faster.
//!
//! The parallel sweeps are a pipelined wavefront over tiles (`strip_worker`): a thread waits at
//! each tile for its upwind tiles, so when another process takes one of the cores, the thread
//! descheduled there holds up the others, and two threads on one and a half cores ran slower than
//! one (the sphere at N = 201, one of two cores kept busy: 138 ms against 86 ms with `threads = 1`).
//! Every iteration gives the same bits whichever way it runs ([`crate::band::schedule`]), so
//! the choice can change between iterations without changing the solution.
//!
//! With the default thread count (`threads = 0`), no iteration runs in parallel before the parallel
//! sweeps have been timed once while the machine has fewer idle cores than the pool has threads
//! (after that the timings alone decide: a reading is a snapshot, and another task's instant on a
//! core must not keep a quiet machine's solve on one thread): on Linux, the runnable tasks of
//! `/proc/loadavg` that are not this process's threads (read before each iteration, tens of
//! microseconds), against the cores. That alone decides under a steady load: one parallel iteration timed as a probe cost
//! 80–170 ms where a sequential one took 2–4 ms (the sphere at N = 201, one of two cores kept
//! busy), more than the whole sequential solve. Otherwise the iterations run sequentially until one has
//! been timed (the first iterations behind the front window are small, and waking the pool costs
//! more than their work), then one runs in parallel, each timed per local update; from then on the
//! faster of the two runs, and the other is timed again every [`PROBE_EVERY`] iterations times
//! the ratio of their times (rarely when it is much slower: the load of a machine changes, but
//! each probe of the slower mode costs that ratio), each estimate an exponential average over its
//! runs. The pool itself is sized the same way when the solve starts
//! ([`threads_for_default`]): its preparation (the grid-path search, the rim, the activity flags)
//! runs on it in parallel too, and with one idle core the whole solve runs on one thread. An
//! explicit thread count is run as asked.

use std::time::Instant;

/// Iterations between two runs of the mode that is not the faster one (to notice a change of load).
pub const PROBE_EVERY: usize = 6;

/// Weight of the newest measurement in a mode's average time per update.
const SMOOTHING: f64 = 0.5;

/// Iterations with fewer local updates than this are not timed (their time is the threads'
/// wake-up and barriers, not the sweeps').
const MIN_UPDATES: u64 = 2048;

/// The choice between the parallel and the sequential sweeps (see the module's documentation).
pub(crate) struct ThreadChoice {
    adaptive: bool,
    threads: usize,
    /// Average seconds per local update: [sequential, parallel].
    per_update: [Option<f64>; 2],
    /// Iterations run in the faster mode since the other was last timed.
    since_probe: usize,
    started: Option<(Instant, bool)>,
    /// Iterations run sequentially (for the statistics).
    pub sequential_iterations: usize,
}

impl ThreadChoice {
    /// `parallel`: the band can be swept in parallel with more than one thread; `adaptive`: the
    /// thread count is the default one (choose by the load and by measurement); `threads`: the
    /// pool's threads.
    pub fn new(parallel: bool, adaptive: bool, threads: usize) -> Self {
        ThreadChoice {
            adaptive: parallel && adaptive,
            threads,
            per_update: [None, if parallel { None } else { Some(0.0) }],
            since_probe: 0,
            started: None,
            sequential_iterations: 0,
        }
    }

    /// Whether the coming iteration runs in parallel (`parallel_possible`: the band can).
    pub fn parallel(&self, parallel_possible: bool) -> bool {
        if !parallel_possible {
            return false;
        }
        if !self.adaptive {
            return true;
        }
        // The load reading only keeps the first parallel iteration (the probe) off a busy
        // machine; once both modes are timed, the timings decide: a reading is a snapshot, and
        // another task's instant on a core must not send a quiet machine's solve to one thread.
        if self.per_update[1].is_none() {
            if let Some(idle) = idle_cores() {
                if idle < self.threads {
                    return false;
                }
            }
        }
        match self.per_update {
            [None, _] => false,
            [_, None] => true,
            [Some(seq), Some(par)] => {
                let faster_is_parallel = par <= seq;
                let ratio = if faster_is_parallel { seq / par } else { par / seq };
                let every = (PROBE_EVERY as f64 * ratio.clamp(1.0, 8.0)).round() as usize;
                if self.since_probe + 1 >= every {
                    !faster_is_parallel
                } else {
                    faster_is_parallel
                }
            }
        }
    }

    /// Marks the start of an iteration run in `parallel` (or not).
    pub fn start(&mut self, parallel: bool) {
        self.started = Some((Instant::now(), parallel));
        if !parallel {
            self.sequential_iterations += 1;
        }
    }

    /// Records the end of the iteration started last, which made `updates` local updates.
    pub fn finish(&mut self, updates: u64) {
        if let Some((t0, parallel)) = self.started.take() {
            if !self.adaptive {
                return;
            }
            // the faster mode before this iteration's measurement (None until both are timed)
            let faster = match self.per_update {
                [Some(seq), Some(par)] => Some(par <= seq),
                _ => None,
            };
            if updates >= MIN_UPDATES {
                let per = t0.elapsed().as_secs_f64() / updates as f64;
                let slot = &mut self.per_update[parallel as usize];
                *slot = Some(match *slot {
                    Some(old) => (1.0 - SMOOTHING) * old + SMOOTHING * per,
                    None => per,
                });
            }
            if faster == Some(parallel) {
                self.since_probe += 1;
            } else {
                self.since_probe = 0;
            }
        }
    }
}

/// The cores not taken by other processes' runnable tasks: the cores (`available_parallelism`)
/// minus the runnable tasks of `/proc/loadavg` (its fourth field, `running/total`) that are not
/// this process's own (its threads in state R in `/proc/self/task/*/stat`: the reading thread,
/// and pool threads still spinning after an iteration). None where it cannot tell (not Linux).
pub fn idle_cores() -> Option<usize> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let running: usize = text.split_whitespace().nth(3)?.split('/').next()?.parse().ok()?;
    let cores = std::thread::available_parallelism().ok()?.get();
    Some(cores.saturating_sub(running.saturating_sub(own_runnable()?)))
}

/// This process's threads in state R (running or runnable), at least 1 (the caller).
fn own_runnable() -> Option<usize> {
    let mut n = 0;
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let Ok(entry) = entry else { continue };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // "tid (comm) S ...": the state follows the last ')' (comm may hold spaces and ')')
        if let Some(i) = stat.rfind(')') {
            if stat[i + 1..].trim_start().starts_with('R') {
                n += 1;
            }
        }
    }
    Some(n.max(1))
}

/// The pool's size for the default thread count: rayon's default number (the cores, or
/// `RAYON_NUM_THREADS`), but no more than the idle cores ([`idle_cores`]), and at least one.
/// The count is a snapshot: when it finds fewer idle cores than that, it is read again up to four
/// times 0.25 ms apart and the most idle taken, so that a task running for an instant does not
/// put a whole solve on one thread (a process that keeps a core busy is there at every read).
pub fn threads_for_default() -> usize {
    let n = rayon::current_num_threads().max(1);
    let Some(mut idle) = idle_cores() else {
        return n;
    };
    for _ in 0..4 {
        if idle >= n {
            break;
        }
        std::thread::sleep(std::time::Duration::from_micros(250));
        idle = idle.max(idle_cores().unwrap_or(0));
    }
    n.min(idle).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_explicit_thread_count_always_runs_in_parallel() {
        let mut c = ThreadChoice::new(true, false, 2);
        for _ in 0..20 {
            assert!(c.parallel(true));
            c.start(true);
            c.finish(1 << 20);
        }
        assert_eq!(c.sequential_iterations, 0);
        assert!(!ThreadChoice::new(true, false, 2).parallel(false));
    }

    #[test]
    fn the_default_measures_both_then_runs_the_faster_and_probes_the_other() {
        let mut c = ThreadChoice::new(true, true, 0); // (a pool of 0 threads: never sequential for the load)
        let mut runs = Vec::new();
        for _ in 0..30 {
            let p = c.parallel(true);
            runs.push(p);
            c.start(p);
            c.finish(1 << 20);
            // the parallel sweeps measured slower (as on a busy machine)
            if p {
                c.per_update[1] = Some(2e-8);
            } else {
                c.per_update[0] = Some(1e-8);
            }
        }
        assert!(!runs[0] && runs[1], "first sequential, then parallel: {runs:?}");
        // afterwards sequential, with a parallel probe every 2·PROBE_EVERY iterations (the
        // parallel sweeps measured twice as slow)
        let parallel_later = runs[2..].iter().filter(|&&p| p).count();
        assert!((1..=28 / (2 * PROBE_EVERY) + 1).contains(&parallel_later), "{runs:?}");
        assert!(c.sequential_iterations >= 24);
    }

    #[test]
    fn idle_cores_are_at_most_the_cores() {
        if let Some(idle) = idle_cores() {
            assert!(idle <= std::thread::available_parallelism().unwrap().get());
        }
    }

    #[test]
    fn small_iterations_are_not_timed() {
        let mut c = ThreadChoice::new(true, true, 0); // (a pool of 0 threads: never sequential for the load)
        assert!(!c.parallel(true), "small iterations first run on one thread");
        c.start(false);
        c.finish(10);
        assert_eq!(c.per_update, [None, None]);
        assert!(!c.parallel(true), "still to be timed sequentially");
        c.start(false);
        c.finish(1 << 20);
        assert!(c.parallel(true), "then timed in parallel");
    }
}
