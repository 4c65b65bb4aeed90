//! The strip pipeline that runs a sweep on several threads (paper Sect. 2's Gauss–Seidel sweeps,
//! in parallel with the values of the sequential sweep): each thread takes the next strip of
//! tiles of [`crate::band::schedule`] and runs its tiles in order, each once the tile of the previous
//! strip it reads is done in the same sweep; the sweeps of one call run in one rayon broadcast
//! with a spinning barrier between them. A panic on one thread raises a flag that makes the others
//! leave their waits, so it reaches the caller instead of leaving a thread spinning.

use super::sweep_state::Accumulator;
use crate::band::schedule::NO_TILE;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};
use std::time::Instant;

/// One thread's share of a pipelined sweep: take the next strip (`next_strip`) until none is
/// left, run its tiles in order (`run_tile`), each once its upstream tile is done in sweep `id`,
/// and mark it done. Gives up (returns early) when `abandoned` is raised, so that a panic on
/// another thread reaches the caller instead of leaving this one spinning.
#[allow(clippy::too_many_arguments)]
pub(crate) fn strip_worker(
    strip_tiles: &[u32],
    strips: &[u32],
    upstream: &[u32],
    tiles_done: &[AtomicU32],
    id: u32,
    next_strip: &AtomicUsize,
    abandoned: &AtomicBool,
    run_tile: &dyn Fn(usize) -> Accumulator,
) -> Accumulator {
    let mut acc = Accumulator::default();
    let n_strips = strips.len().saturating_sub(1);
    loop {
        let s = next_strip.fetch_add(1, Ordering::Relaxed);
        if s >= n_strips {
            break;
        }
        for &t in &strip_tiles[strips[s] as usize..strips[s + 1] as usize] {
            let up = upstream[t as usize];
            if up != NO_TILE {
                // the previous strip was taken earlier by a running thread
                let done = &tiles_done[up as usize];
                let ready = || done.load(Ordering::Acquire) == id;
                // counted (with the kernel-stats feature) only when the tile is not done yet
                let waiting = (crate::kernel_stats::ENABLED && !ready()).then(Instant::now);
                let ok = spin_until(ready, abandoned);
                if let Some(t) = waiting {
                    crate::kernel_stats::tile_wait(t.elapsed().as_nanos() as u64);
                }
                if !ok {
                    return acc;
                }
            }
            acc = acc.merge(run_tile(t as usize));
            tiles_done[t as usize].store(id, Ordering::Release);
        }
    }
    acc
}

/// Spins until `ready()` (briefly, then yielding the core: the thread it waits for may have been
/// descheduled); `false` if `abandoned` is raised first.
#[inline]
fn spin_until(ready: impl Fn() -> bool, abandoned: &AtomicBool) -> bool {
    let mut spins = 0u32;
    while !ready() {
        if abandoned.load(Ordering::Acquire) {
            return false;
        }
        spins += 1;
        if spins < 2048 {
            std::hint::spin_loop();
        } else {
            std::thread::yield_now();
        }
    }
    true
}

/// `n_sweeps` pipelined sweeps on every thread of the current rayon pool in one broadcast: sweep
/// `s` is `per_sweep(s, next_strip, abandoned)` on every thread, with its own strip counter and
/// sweep id (one thread takes the next id from `ids`, then all meet at a barrier), and a barrier
/// after it. A panic on one thread raises `abandoned`, which makes the others leave their waits,
/// so the panic reaches the caller.
pub(crate) fn run_sweeps_in_one_broadcast(
    n_sweeps: usize,
    ids: &AtomicU32,
    per_sweep: &(dyn Fn(usize, &AtomicUsize, &AtomicBool) -> Accumulator + Sync),
) -> Accumulator {
    /// Raises `abandoned` when dropped by a panic.
    struct RaiseOnPanic<'a>(&'a AtomicBool);
    impl Drop for RaiseOnPanic<'_> {
        fn drop(&mut self) {
            if std::thread::panicking() {
                self.0.store(true, Ordering::Release);
            }
        }
    }
    let threads = rayon::current_num_threads();
    let next_strip: Vec<AtomicUsize> = (0..n_sweeps).map(|_| AtomicUsize::new(0)).collect();
    let abandoned = AtomicBool::new(false);
    let barrier = SpinBarrier::new(threads);
    rayon::broadcast(|b| {
        let _raise = RaiseOnPanic(&abandoned);
        let mut acc = Accumulator::default();
        for s in 0..n_sweeps {
            if b.index() == 0 {
                // the sweep's id: one past the last (ids start at 1, the done flags at 0)
                ids.fetch_add(1, Ordering::Relaxed);
            }
            if !barrier.wait(&abandoned) {
                return acc;
            }
            acc = acc.merge(per_sweep(s, &next_strip[s], &abandoned));
            // every tile of this sweep is done before any of the next starts
            let passed = barrier.wait(&abandoned);
            // this thread's counts, the wait at that barrier included (the pool ends with the
            // solve)
            crate::kernel_stats::flush();
            if !passed {
                return acc;
            }
        }
        acc
    })
    .into_iter()
    .fold(Accumulator::default(), Accumulator::merge)
}

/// A barrier for the threads of one broadcast that spins instead of sleeping.
struct SpinBarrier {
    threads: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
}

impl SpinBarrier {
    fn new(threads: usize) -> Self {
        SpinBarrier {
            threads,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
        }
    }

    /// Waits until all threads arrived; what each did before is visible to all after.
    /// `false` if `abandoned` is raised first.
    fn wait(&self, abandoned: &AtomicBool) -> bool {
        let generation = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.threads {
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::AcqRel);
            return true;
        }
        let t = crate::kernel_stats::ENABLED.then(Instant::now);
        let ok = spin_until(|| self.generation.load(Ordering::Acquire) != generation, abandoned);
        if let Some(t) = t {
            crate::kernel_stats::barrier_wait(t.elapsed().as_nanos() as u64);
        }
        ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_in_a_tile_of_the_strip_pipeline_reaches_the_caller_instead_of_hanging() {
        // two strips of three tiles, each tile of the second waiting for the one above it; three
        // sweeps in one broadcast, with the ids the sweeps hand out
        let strip_tiles = [0u32, 1, 2, 3, 4, 5];
        let strips = [0u32, 3, 6];
        let upstream = [NO_TILE, NO_TILE, NO_TILE, 0, 1, 2];
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let run = move |panic_in: Option<(usize, usize)>| -> (Accumulator, Vec<u32>) {
            let done: Vec<AtomicU32> = (0..6).map(|_| AtomicU32::new(0)).collect();
            let ids = AtomicU32::new(0);
            let acc = pool.install(|| {
                run_sweeps_in_one_broadcast(3, &ids, &|s, next, abandoned| {
                    let id = ids.load(Ordering::Relaxed);
                    strip_worker(&strip_tiles, &strips, &upstream, &done, id, next, abandoned, &|t| {
                        if panic_in == Some((s, t)) {
                            panic!("sweep {s}, tile {t}");
                        }
                        Accumulator {
                            updates: 1,
                            ..Accumulator::default()
                        }
                    })
                })
            });
            (acc, done.iter().map(|d| d.load(Ordering::Relaxed)).collect())
        };
        // a clean run visits every tile once per sweep, the last sweep's id is 3
        let (acc, done) = run(None);
        assert_eq!(acc.updates, 18);
        assert!(done.iter().all(|&d| d == 3), "{done:?}");
        // a tile of the second sweep panics: the threads waiting for it (at the tile or the
        // barrier) must give up, and the panic come out
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(Some((1, 1)))));
            tx.send(r.is_err()).unwrap();
        });
        let panicked = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("the pipeline hung");
        assert!(panicked);
    }
}
