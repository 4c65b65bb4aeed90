//! How long a cache line takes to go from one core to another and back: two threads, pinned to
//! the first two CPUs this process may use, pass a counter back and forth through one atomic
//! (each waits until the other has written, then writes). Prints the median round trip over a
//! few rounds:
//!   cargo run --release -p tubesweep-core --example core_to_core [round trips per round]
//!
//! The parallel sweeps hand values and "tile done" flags from one core to the next at every
//! tile (`sweep/strip_pipeline.rs`), so their speed-up on two cores falls as this latency grows.
//! It is the host's doing, not the program's: on a virtual machine the two virtual CPUs may sit
//! on one core complex (tens of nanoseconds) or on two (hundreds), and that can change from day
//! to day. `benches/microbench.py` prints it beside the speed-ups it measures.
//!
//! Output: `core_to_core cpus=A,B round_trip_ns=T`, or `core_to_core unavailable: why` (not Linux,
//! or fewer than two CPUs allowed).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The counter, alone on its cache line.
#[repr(align(128))]
struct Line(AtomicU64);

fn main() {
    let trips: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(200_000);
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
    let mut rounds: Vec<f64> = (0..7).map(|_| round_trip_ns(a, b, trips)).collect();
    rounds.sort_by(f64::total_cmp);
    println!("core_to_core cpus={a},{b} round_trip_ns={:.1}", rounds[rounds.len() / 2]);
}

/// Mean round trip in nanoseconds over `trips` exchanges between CPUs `a` and `b`.
fn round_trip_ns(a: usize, b: usize, trips: u64) -> f64 {
    let line = Arc::new(Line(AtomicU64::new(0)));
    let other = Arc::clone(&line);
    let echo = std::thread::spawn(move || {
        pin(b);
        for i in 0..trips {
            while other.0.load(Ordering::Acquire) != 2 * i + 1 {
                std::hint::spin_loop();
            }
            other.0.store(2 * i + 2, Ordering::Release);
        }
    });
    pin(a);
    // let the other thread reach its CPU and its loop before the clock starts
    line.0.store(1, Ordering::Release);
    while line.0.load(Ordering::Acquire) != 2 {
        std::hint::spin_loop();
    }
    let t0 = Instant::now();
    for i in 1..trips {
        line.0.store(2 * i + 1, Ordering::Release);
        while line.0.load(Ordering::Acquire) != 2 * i + 2 {
            std::hint::spin_loop();
        }
    }
    let secs = t0.elapsed().as_secs_f64();
    echo.join().expect("the echo thread does not panic");
    secs * 1e9 / (trips - 1).max(1) as f64
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
        Ok((0..libc::CPU_SETSIZE as usize).filter(|&c| libc::CPU_ISSET(c, &set)).collect())
    }
}

#[cfg(not(target_os = "linux"))]
fn allowed_cpus() -> Result<Vec<usize>, String> {
    Err("pinning threads to CPUs is implemented for Linux only".into())
}

/// Pins the calling thread to CPU `cpu`.
#[cfg(target_os = "linux")]
fn pin(cpu: usize) {
    // SAFETY: as in `allowed_cpus`
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

#[cfg(not(target_os = "linux"))]
fn pin(_cpu: usize) {}
