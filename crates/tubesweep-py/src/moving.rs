//! Bindings of the warm starts on a moved surface (`tubesweep_core::second_order::warm`); the
//! warm solve itself is `second_order_solve(..., warm=...)` (`second_order.rs`).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use tubesweep_core::second_order::warm::{carry_values, component_labels};

use crate::band::{AnyBand, PyBand};
use crate::convert::c_slice;
use crate::errors::to_pyerr;

/// The previous values `old_values` (on the band of sorted linear indices `old_linear`) carried
/// onto the band `new_linear`: a node in both bands keeps its value, a new node gets +∞.
#[pyfunction]
pub fn carry_band_values<'py>(
    py: Python<'py>,
    old_linear: PyReadonlyArray1<'py, u64>,
    old_values: PyReadonlyArray1<'py, f64>,
    new_linear: PyReadonlyArray1<'py, u64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (a, v, b) = (
        c_slice(&old_linear, "old_linear")?,
        c_slice(&old_values, "old_values")?,
        c_slice(&new_linear, "new_linear")?,
    );
    let out = py.detach(|| carry_values(a, v, b)).map_err(to_pyerr)?;
    Ok(out.into_pyarray(py))
}

/// The connected component (along the axes) of each band node flagged in `select`: the smallest
/// band position in it, `u32::MAX` for the nodes not flagged.
#[pyfunction]
pub fn band_component_labels<'py>(
    py: Python<'py>,
    band: PyRef<'py, PyBand>,
    select: PyReadonlyArray1<'py, bool>,
) -> PyResult<Bound<'py, PyArray1<u32>>> {
    let s = c_slice(&select, "select")?;
    let b = &band.band;
    let out = py
        .detach(|| match b {
            AnyBand::D2(b) => component_labels(b, s),
            AnyBand::D3(b) => component_labels(b, s),
        })
        .map_err(to_pyerr)?;
    Ok(out.into_pyarray(py))
}

/// Registers the functions of this file in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(carry_band_values, m)?)?;
    m.add_function(wrap_pyfunction!(band_component_labels, m)?)
}
