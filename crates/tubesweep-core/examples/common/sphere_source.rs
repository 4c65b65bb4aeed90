//! The sphere problem of the Rust examples: the band of `shell.rs` (included by the example as
//! module `shell`) with one source on the sphere and the extension weights in place of the
//! directions, as the Python layer hands them to the solver; the sweep problem over it and its
//! starting values.
use std::time::Instant;
use tubesweep_core::sweep::{Extension, MissingNeighbour, Slowness};
use tubesweep_core::{InnerScheme, NarrowBand, NodeRole, SweepProblem};

/// The source's axis from `SOURCE_AXIS` (0, x, when unset).
pub fn source_axis_from_env() -> usize {
    std::env::var("SOURCE_AXIS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

/// The sphere band at `n`³ nodes with its source at −0.5 on axis `source_axis` (0 is x, the
/// default of the examples; 2 is the rows' axis) and 0 on the others: the band, the roles (the
/// source node fixed), the upwind extension weights, the spacing h, and the seconds the band
/// structure took to build.
pub fn sphere_with_source(n: usize, source_axis: usize) -> (NarrowBand<3>, Vec<NodeRole>, Vec<[f32; 3]>, f64, f64) {
    assert!(source_axis < 3, "the source axis is 0, 1 or 2");
    let (lin, mut roles, mut dirs, h) = super::shell::sphere_shell(n);
    let t = Instant::now();
    let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap();
    let build = t.elapsed().as_secs_f64();
    let mut at = [((n - 1) / 2) as i64; 3];
    at[source_axis] = ((n - 1) / 4) as i64;
    let src = band.find(at).unwrap();
    roles[src] = NodeRole::Fixed;
    // as the Python layer does: the upwind weights in place of the directions (no copy of a
    // band-sized array)
    tubesweep_core::sweep::extension_weights_in_place(&band, &roles, &mut dirs);
    (band, roles, dirs, h, build)
}

/// The sweep problem on that band with unit speed and `scheme` in the inner tube.
pub fn sphere_problem<'a>(
    band: &'a NarrowBand<3>,
    roles: &'a [NodeRole],
    weights: &'a [[f32; 3]],
    h: f64,
    scheme: InnerScheme<'a, 3>,
) -> SweepProblem<'a, 3> {
    SweepProblem {
        band,
        roles,
        spacing: h,
        slowness: Slowness::Constant(1.0),
        extension: Extension::Weights(weights),
        scheme,
        missing: MissingNeighbour::Extrapolate,
    }
}

/// Starting values for the solve (the solver sets them), with room for its sentinel slot so that
/// it appends it without copying a band-sized array.
pub fn starting_values(band: &NarrowBand<3>) -> Vec<f64> {
    let mut u = Vec::with_capacity(band.len() + 1);
    u.resize(band.len(), 0.0);
    u
}
