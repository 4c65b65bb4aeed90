//! The creases of a tube (`tubesweep_core::second_order::creases`) as a stats dict, for the single
//! solve's and the batch's statistics.

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `sol.stats.order2["creases"]`: the crease nodes, the largest turn of the normal there (degrees)
/// and the shortcut per crease crossed in units of inner·Δx (`second_order::creases`).
pub(crate) fn creases_dict<'py>(
    py: Python<'py>,
    creases: &tubesweep_core::second_order::creases::Creases,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("nodes", creases.nodes)?;
    d.set_item("angle_degrees", creases.angle)?;
    d.set_item("faces_angle_degrees", creases.faces_angle)?;
    d.set_item("shortcut_per_inner_width", creases.shortcut_per_inner_width())?;
    Ok(d)
}
