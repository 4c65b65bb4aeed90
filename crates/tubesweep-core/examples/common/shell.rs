//! The sphere band the Rust examples run on (included with `#[path]`): radius 0.5 in [−1,1]^3.
use tubesweep_core::NodeRole;

/// Sorted C-order linear indices of the `n`³ grid nodes within 4h of the sphere of radius 0.5,
/// their roles (inner within 2h, the rest extension layer), radial extension directions and h.
/// No sources.
pub fn sphere_shell(n: usize) -> (Vec<u64>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let h = 2.0 / (n - 1) as f64;
    let mut lin = Vec::new();
    let mut roles = Vec::new();
    let mut dirs = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let x = [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
                let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                let phi = r - 0.5;
                if phi.abs() <= 4.0 * h {
                    lin.push(((i * n + j) * n + k) as u64);
                    roles.push(if phi.abs() <= 2.0 * h { NodeRole::Inner } else { NodeRole::Outer });
                    let s = phi.signum() / r;
                    dirs.push([(x[0] * s) as f32, (x[1] * s) as f32, (x[2] * s) as f32]);
                }
            }
        }
    }
    (lin, roles, dirs, h)
}
