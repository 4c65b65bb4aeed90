//! The cost of the sub-cell re-distancing alone (`tubesweep_core::surface::redistance_band`, what
//! `LevelSet(phi_array, redistance=True).band(grid, 4Δx)` runs), for the sphere R = 0.5 in
//! [−1, 1]³ sampled as `|x|² − R²`, as a voxel mask (`−0.5` inside, `0.5` outside) and as that mask
//! smoothed (σ = 1.5 voxels, as `LevelSet.from_mask(mask, smooth=1.5)`): the CPU time
//! of the process (all threads; medians of the repeats), the band's size and a hash of its linear
//! indices, signed distances and directions (equal hashes: the same bits).
//!
//!     cargo run --release -p tubesweep-core --example redistance_cost -- [N] [repeats] [tol]   # 201 3 1e-12
//!
//! `CASE=<start of a case's name>` runs that case alone. For instruction counts, which a busy
//! machine does not change:
//! `RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no target/release/examples/redistance_cost 101 1`.
use tubesweep_core::surface::redistance::SampledField;
use tubesweep_core::surface::redistance_band::{redistanced_band_of_samples, RedistanceOptions};

fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes the timespec it is given
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("N, repeats and tol"))
        .collect();
    let n = args.first().map_or(201, |&v| v as usize);
    let repeats = args.get(1).map_or(3, |&v| v as usize).max(1);
    let tol = args.get(2).copied().unwrap_or(1e-12);
    let h = 2.0 / (n - 1) as f64;
    let r2 = |l: usize| {
        let (i, j, k) = (l / (n * n), l / n % n, l % n);
        [i, j, k].iter().map(|&m| (-1.0 + h * m as f64).powi(2)).sum::<f64>()
    };
    let mask: Vec<f64> = (0..n * n * n).map(|l| if r2(l) < 0.25 { -0.5 } else { 0.5 }).collect();
    let cases: [(&str, Vec<f64>); 3] = [
        ("|x|²−R²", (0..n * n * n).map(|l| r2(l) - 0.25).collect()),
        ("sphere mask σ=1.5", smoothed(&mask, n, 1.5)),
        ("sphere mask", mask),
    ];
    for (name, samples) in &cases {
        if std::env::var("CASE").is_ok_and(|c| !name.starts_with(&c)) {
            continue;
        }
        let field = SampledField::<3>::new(samples, [n; 3], [-1.0; 3], h).expect("a valid grid");
        let options = RedistanceOptions {
            half_width: 4.0 * h,
            eps: 0.5 * h,
            max_steps: 40,
            tol,
        };
        let mut times = Vec::new();
        let mut band = None;
        for _ in 0..repeats {
            let start = cpu_seconds();
            band = Some(redistanced_band_of_samples(&field, options).expect("a sign change"));
            times.push(cpu_seconds() - start);
        }
        times.sort_by(f64::total_cmp);
        let band = band.expect("one repeat at least");
        // the largest error against the sphere's exact signed distance |x| − R
        let worst = band
            .linear
            .iter()
            .zip(&band.signed)
            .map(|(&l, &s)| (s - (r2(l as usize).sqrt() - 0.5)).abs())
            .fold(0.0f64, f64::max);
        let mut hash = 0xcbf29ce484222325u64;
        let mut mix = |v: u64| hash = (hash ^ v).wrapping_mul(0x100000001b3);
        for (&l, &s) in band.linear.iter().zip(&band.signed) {
            mix(l);
            mix(s.to_bits());
        }
        for &d in &band.direction {
            mix(u64::from(d.to_bits()));
        }
        println!(
            "N={n} {name:18} band nodes {:8} (unsettled {:6}): CPU {:.3} s, {:.2} µs per band node; largest error {:.3e} Δx; hash {hash:016x}",
            band.linear.len(),
            band.unsettled,
            times[repeats / 2],
            times[repeats / 2] * 1e6 / band.linear.len() as f64,
            worst / h,
        );
    }
}

/// The mask smoothed as `LevelSet.from_mask(mask, smooth=sigma)` does (`scipy.ndimage.gaussian_filter`
/// with `mode="nearest"`, truncated at 4σ), along each axis in turn: the mask's −0.5/0.5 here, so
/// 0.5 − the smoothed 0/1 mask.
fn smoothed(mask: &[f64], n: usize, sigma: f64) -> Vec<f64> {
    let radius = (4.0 * sigma + 0.5) as isize;
    let weights: Vec<f64> = (-radius..=radius)
        .map(|m| (-0.5 * (m as f64 / sigma).powi(2)).exp())
        .collect();
    let total: f64 = weights.iter().sum();
    let mut out = mask.to_vec();
    for stride in [n * n, n, 1] {
        let src = out.clone();
        for (l, v) in out.iter_mut().enumerate() {
            let at = (l / stride % n) as isize;
            let mut sum = 0.0;
            for (w, m) in weights.iter().zip(-radius..=radius) {
                let c = (at + m).clamp(0, n as isize - 1);
                sum += w * src[(l as isize + (c - at) * stride as isize) as usize];
            }
            *v = sum / total;
        }
    }
    out
}
