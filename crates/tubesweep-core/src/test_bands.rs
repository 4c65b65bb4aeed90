//! Bands for the unit tests: spherical shells on a grid over [−1,1]^3.

use crate::band::NarrowBand;
use crate::sweep::NodeRole;

/// Spheres of radius `r0` centred at `(c, 0, 0)` for each `c` in `centres`, on `n`³ nodes over
/// [−1,1]^3: the nodes within 4h of the nearest one, inner within 2h, with radial extension
/// directions. No sources. Returns the band, the roles, the directions and h.
pub(crate) fn shell_band(n: usize, r0: f64, centres: &[f64]) -> (NarrowBand<3>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let h = 2.0 / (n - 1) as f64;
    let mut lin = Vec::new();
    let mut roles = Vec::new();
    let mut dirs = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let x = [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
                let c = centres.iter().copied().min_by(|a, b| (x[0] - a).abs().total_cmp(&(x[0] - b).abs())).unwrap();
                let d = [x[0] - c, x[1], x[2]];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let phi = r - r0;
                if phi.abs() <= 4.0 * h {
                    lin.push(((i * n + j) * n + k) as u64);
                    roles.push(if phi.abs() <= 2.0 * h { NodeRole::Inner } else { NodeRole::Outer });
                    let s = phi.signum() / r;
                    dirs.push([(d[0] * s) as f32, (d[1] * s) as f32, (d[2] * s) as f32]);
                }
            }
        }
    }
    (NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap(), roles, dirs, h)
}
