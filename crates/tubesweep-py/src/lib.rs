//! Thin PyO3 bindings of `tubesweep-core`: array conversion, releasing the GIL around solves,
//! progress and Ctrl-C, and error mapping. All validation a user sees with a helpful message
//! happens in the Python package; the core re-checks what could break it.
//!
//! The files mirror the core's folders:
//!
//! | file | binds |
//! |---|---|
//! | `surface.rs` | `tubesweep_core::surface`: analytic φ, mesh closest points (`TriangleTree`), open surfaces, re-distancing |
//! | `band_search.rs` | `tubesweep_core::band::{discovery, sampled, normals}`: finding a band and its directions |
//! | `band.rs` | `Band` (`tubesweep_core::band::NarrowBand`) and its methods, `interpolate` and labels (`solution`) |
//! | `sweep.rs` | solves (`tubesweep_core::sweep`), the GIL released, progress and Ctrl-C |
//! | `box_order2.rs` | the second-order solve in the box (`tubesweep_core::sweep::factored_box`) |
//! | `second_order.rs` | order=2 on surfaces (`tubesweep_core::second_order`) |
//! | `mesh_smooth.rs` | the smooth closest-point map of a mesh (`tubesweep_core::surface::mesh_smooth`) |
//! | `point_cloud.rs` | point clouds' closest points (`tubesweep_core::surface::point_cloud`) |
//! | `many_sources.rs` | many solves on one band (`tubesweep_core::sweep::many_sources`) |
//! | `moving.rs` | warm starts on a moved surface (`tubesweep_core::second_order::warm`) |
//! | `convert.rs` | NumPy arrays to and from slices |
//! | `errors.rs` | the one place where core errors become Python exceptions |
//!
//! New bindings go in a new file with a `register` function, called from one line below.

mod band;
mod band_search;
mod box_order2;
mod convert;
mod creases;
mod errors;
mod geometry_report;
mod many_sources;
mod mesh_smooth;
mod moving;
mod point_cloud;
mod progress;
mod second_order;
mod surface;
mod sweep;

use pyo3::prelude::*;

/// The compiled core of tubesweep. Use the `tubesweep` package, not this module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    band::register(m)?;
    band_search::register(m)?;
    box_order2::register(m)?;
    many_sources::register(m)?;
    moving::register(m)?;
    mesh_smooth::register(m)?;
    point_cloud::register(m)?;
    second_order::register(m)?;
    surface::register(m)?;
    sweep::register(m)?;
    m.add("DEFAULT_INFINITY", tubesweep_core::DEFAULT_INFINITY)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
