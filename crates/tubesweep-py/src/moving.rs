//! Bindings of the warm starts on a moved surface (`tubesweep_core::second_order::warm`); the
//! warm solve itself is `second_order_solve(..., warm=...)` (`second_order.rs`).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use tubesweep_core::second_order::warm::{carry_values, inner_components};

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

/// The number of connected components (along the axes) of the band nodes flagged in `select`.
#[pyfunction]
pub fn band_components(py: Python<'_>, band: PyRef<'_, PyBand>, select: PyReadonlyArray1<'_, bool>) -> PyResult<usize> {
    let s = c_slice(&select, "select")?;
    let b = &band.band;
    py.detach(|| match b {
        AnyBand::D2(b) => inner_components(b, s),
        AnyBand::D3(b) => inner_components(b, s),
    })
    .map_err(to_pyerr)
}

/// Registers the functions of this file in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(carry_band_values, m)?)?;
    m.add_function(wrap_pyfunction!(band_components, m)?)
}
