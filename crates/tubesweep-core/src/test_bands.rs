//! Bands for the unit tests: spherical shells on a grid over [−1,1]^3, built from the node lists
//! the Rust examples use too (`examples/common/shell.rs`).

use crate::band::NarrowBand;
use crate::sweep::NodeRole;

#[path = "../examples/common/shell.rs"]
mod shell;

/// Spheres of radius `r0` centred at `(c, 0, 0)` for each `c` in `centres`, on `n`³ nodes over
/// [−1,1]^3: the nodes within 4h of the nearest one, inner within 2h, with radial extension
/// directions. No sources. Returns the band, the roles, the directions and h.
pub(crate) fn shell_band(n: usize, r0: f64, centres: &[f64]) -> (NarrowBand<3>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let (lin, roles, dirs, h) = shell::shell_nodes(n, r0, centres);
    (NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap(), roles, dirs, h)
}
