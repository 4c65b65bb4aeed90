//! Bands for the unit tests: spherical shells on a grid over [−1,1]^3, built from the node lists
//! the Rust examples use too (`examples/common/shell.rs`).

use crate::band::NarrowBand;
use crate::scheme::hamiltonian::InnerScheme;
use crate::sweep::{Extension, MissingNeighbour, NodeRole, Slowness, SweepProblem};

#[path = "../examples/common/shell.rs"]
mod shell;

/// Spheres of radius `r0` centred at `(c, 0, 0)` for each `c` in `centres`, on `n`³ nodes over
/// [−1,1]^3: the nodes within 4h of the nearest one, inner within 2h, with radial extension
/// directions. No sources. Returns the band, the roles, the directions and h.
pub(crate) fn shell_band(n: usize, r0: f64, centres: &[f64]) -> (NarrowBand<3>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let (lin, roles, dirs, h) = shell::shell_nodes(n, r0, centres);
    (
        NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap(),
        roles,
        dirs,
        h,
    )
}

/// A sphere of radius 0.5 in [−1,1]^3 (`shell_band`), source node nearest (−0.5, 0, 0).
pub(crate) fn sphere_band(n: usize) -> (NarrowBand<3>, Vec<NodeRole>, Vec<[f32; 3]>, f64) {
    let (band, mut roles, dirs, h) = shell_band(n, 0.5, &[0.0]);
    let src = band.find([(n / 4) as i64, (n / 2) as i64, (n / 2) as i64]).unwrap();
    roles[src] = NodeRole::Fixed;
    (band, roles, dirs, h)
}

/// The sphere of radius 0.5 at the nodes of a band over [−1,1]^3 with spacing `h`, as a level
/// set (φ = |x| − 0.5) and as a closest-point map (the offsets x − cp(x)).
pub(crate) fn sphere_phi_and_offsets(band: &NarrowBand<3>, h: f64) -> (Vec<f64>, Vec<[f64; 3]>) {
    let pts: Vec<[f64; 3]> = band
        .indices()
        .iter()
        .map(|i| [-1.0 + h * i[0] as f64, -1.0 + h * i[1] as f64, -1.0 + h * i[2] as f64])
        .collect();
    let norm = |x: &[f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let phi = pts.iter().map(|x| norm(x) - 0.5).collect();
    let offsets = pts
        .iter()
        .map(|x| {
            let r = norm(x);
            [x[0] - 0.5 * x[0] / r, x[1] - 0.5 * x[1] / r, x[2] - 0.5 * x[2] / r]
        })
        .collect();
    (phi, offsets)
}

/// The two-layer problem on such a band: unit speed, the outward directions, `scheme` in the
/// inner tube, absent neighbours extrapolated.
pub(crate) fn sphere_problem<'a>(
    band: &'a NarrowBand<3>,
    roles: &'a [NodeRole],
    dirs: &'a [[f32; 3]],
    h: f64,
    scheme: InnerScheme<'a, 3>,
) -> SweepProblem<'a, 3> {
    SweepProblem {
        band,
        roles,
        spacing: h,
        slowness: Slowness::Constant(1.0),
        extension: Extension::Directions(dirs),
        scheme,
        missing: MissingNeighbour::Extrapolate,
    }
}
