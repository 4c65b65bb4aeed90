//! Spherical-shell bands on a grid over [−1,1]^3, shared by the Rust examples and the unit tests
//! (`src/test_bands.rs`), each of which includes this file with `#[path]`. The including module
//! brings `NodeRole` into scope (from `tubesweep_core` or, inside the crate, `crate::sweep`).
use super::NodeRole;

/// Spheres of radius `r0` centred at `(c, 0, 0)` for each `c` in `centres`, on `n`³ nodes over
/// [−1,1]^3: the sorted C-order linear indices of the nodes within 4h of the nearest sphere,
/// their roles (inner within 2h, the rest extension layer), radial extension directions and h.
/// No sources.
#[allow(dead_code)] // each includer uses one of the two entry points
pub fn shell_nodes(n: usize, r0: f64, centres: &[f64]) -> (Vec<u64>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let h = 2.0 / (n - 1) as f64;
    let mut lin = Vec::new();
    let mut roles = Vec::new();
    let mut dirs = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let x = [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
                let c = centres
                    .iter()
                    .copied()
                    .min_by(|a, b| (x[0] - a).abs().total_cmp(&(x[0] - b).abs()))
                    .unwrap();
                let d = [x[0] - c, x[1], x[2]];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let phi = r - r0;
                if phi.abs() <= 4.0 * h {
                    lin.push(((i * n + j) * n + k) as u64);
                    roles.push(if phi.abs() <= 2.0 * h {
                        NodeRole::Inner
                    } else {
                        NodeRole::Outer
                    });
                    let s = phi.signum() / r;
                    dirs.push([(d[0] * s) as f32, (d[1] * s) as f32, (d[2] * s) as f32]);
                }
            }
        }
    }
    (lin, roles, dirs, h)
}

/// The sphere the examples run on: radius 0.5 about the origin ([`shell_nodes`]).
#[allow(dead_code)]
pub fn sphere_shell(n: usize) -> (Vec<u64>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    shell_nodes(n, 0.5, &[0.0])
}
