//! The sphere problem of the Rust examples: the band of `shell.rs` (included by the example as
//! module `shell`) with one source on the sphere and the extension weights in place of the
//! directions, as the Python layer hands them to the solver.
use std::time::Instant;
use tubesweep_core::{NarrowBand, NodeRole};

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
