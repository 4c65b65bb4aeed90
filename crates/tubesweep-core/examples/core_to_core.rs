//! How long a cache line takes to go from one core to another and back: two threads, pinned to
//! the first two CPUs this process may use, pass a counter back and forth through one atomic
//! (each waits until the other has written, then writes). Prints the median round trip over a
//! few rounds:
//!   cargo run --release -p tubesweep-core --example core_to_core [round trips per round]
//!
//! The parallel sweeps hand values and "tile done" flags from one core to the next at every
//! tile (`sweep/strip_pipeline.rs`), so their speed-up on two cores falls as this latency grows.
//! It is the host's doing, not the program's: on a virtual machine the two virtual CPUs may sit
//! on one core complex (tens of nanoseconds) or on two (hundreds); the 2-core machine of
//! docs/benchmarks.md showed about 42 ns and 360–440 ns, switching within minutes.
//! `benches/microbench.py` prints it beside the speed-ups it measures. On a machine with more
//! CPUs, the first two allowed may be one core's two hardware threads, or not the pair a
//! solve's threads run on.
//!
//! A round stops after a quarter of a second even if its trips are not done, and a waiting
//! thread yields its CPU now and then, so that two threads that cannot run at once (a CPU quota
//! below two) slow the measurement down instead of hanging it.
//!
//! Output: `core_to_core cpus=A,B round_trip_ns=T`, or `core_to_core unavailable: why` (not Linux,
//! fewer than two CPUs allowed, or a thread that could not be pinned).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The counter, alone on its cache line.
#[repr(align(128))]
struct Line(AtomicU64);

/// The counter's value that tells the echo thread to stop (a round ended by its time budget).
const STOP: u64 = u64::MAX;

/// A round ends after this long even if its trips are not done (two threads that cannot run at
/// once, e.g. under a CPU quota below two, take a scheduler slice per trip).
const ROUND_BUDGET_S: f64 = 0.25;

/// Spins before a waiting thread yields its CPU once.
const SPINS_BEFORE_YIELD: u32 = 1 << 16;

fn main() {
    let trips: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(200_000)
        .max(2);
    let cpus = match allowed_cpus() {
        Ok(c) if c.len() >= 2 => c,
        Ok(_) => {
            println!("core_to_core unavailable: fewer than two CPUs allowed");
            return;
        }
        Err(why) => {
            println!("core_to_core unavailable: {why}");
            return;
        }
    };
    let (a, b) = (cpus[0], cpus[1]);
    let mut rounds = Vec::new();
    for _ in 0..7 {
        match round_trip_ns(a, b, trips) {
            Ok(ns) => rounds.push(ns),
            Err(why) => {
                println!("core_to_core unavailable: {why}");
                return;
            }
        }
    }
    rounds.sort_by(f64::total_cmp);
    println!(
        "core_to_core cpus={a},{b} round_trip_ns={:.1}",
        rounds[rounds.len() / 2]
    );
}

/// Waits until `line` holds `want` (or [`STOP`]); false on `STOP`.
fn wait_for(line: &AtomicU64, want: u64) -> bool {
    let mut spins = 0u32;
    loop {
        let v = line.load(Ordering::Acquire);
        if v == want {
            return true;
        }
        if v == STOP {
            return false;
        }
        spins += 1;
        if spins == SPINS_BEFORE_YIELD {
            spins = 0;
            std::thread::yield_now();
        }
        std::hint::spin_loop();
    }
}

/// Mean round trip in nanoseconds over up to `trips` exchanges between CPUs `a` and `b` (fewer
/// when [`ROUND_BUDGET_S`] runs out); an error when a thread cannot be pinned.
fn round_trip_ns(a: usize, b: usize, trips: u64) -> Result<f64, String> {
    let line = Arc::new(Line(AtomicU64::new(0)));
    let other = Arc::clone(&line);
    let echo = std::thread::spawn(move || -> Result<(), String> {
        let pinned = pin(b);
        if pinned.is_err() {
            other.0.store(STOP, Ordering::Release);
            return pinned;
        }
        for i in 0..trips {
            if !wait_for(&other.0, 2 * i + 1) {
                return Ok(());
            }
            other.0.store(2 * i + 2, Ordering::Release);
        }
        Ok(())
    });
    let result = (|| {
        pin(a)?;
        // let the other thread reach its CPU and its loop before the clock starts
        line.0.store(1, Ordering::Release);
        if !wait_for(&line.0, 2) {
            return Err("the echo thread stopped".to_string());
        }
        let t0 = Instant::now();
        let mut done = 0u64;
        for i in 1..trips {
            line.0.store(2 * i + 1, Ordering::Release);
            if !wait_for(&line.0, 2 * i + 2) {
                return Err("the echo thread stopped".to_string());
            }
            done += 1;
            if done.is_multiple_of(1024) && t0.elapsed().as_secs_f64() > ROUND_BUDGET_S {
                break;
            }
        }
        Ok(t0.elapsed().as_secs_f64() * 1e9 / done as f64)
    })();
    // release the echo thread if the round ended early or failed
    line.0.store(STOP, Ordering::Release);
    let echoed = echo.join().map_err(|_| "the echo thread panicked".to_string())?;
    echoed?;
    result
}

#[cfg(target_os = "linux")]
fn allowed_cpus() -> Result<Vec<usize>, String> {
    // SAFETY: cpu_set_t is plain data (zeroed: the empty set); the call writes only the set
    // passed, of the size passed
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Err("sched_getaffinity failed".into());
        }
        Ok((0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect())
    }
}

#[cfg(not(target_os = "linux"))]
fn allowed_cpus() -> Result<Vec<usize>, String> {
    Err("pinning threads to CPUs is implemented for Linux only".into())
}

/// Pins the calling thread to CPU `cpu`.
#[cfg(target_os = "linux")]
fn pin(cpu: usize) -> Result<(), String> {
    // SAFETY: as in `allowed_cpus`
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(format!(
                "sched_setaffinity to CPU {cpu} failed: {}",
                std::io::Error::last_os_error()
            ));
        }
    }
    Ok(())
}

#[cfg(not(target_os = "linux"))]
fn pin(_cpu: usize) -> Result<(), String> {
    Err("pinning threads to CPUs is implemented for Linux only".into())
}
