//! The tube geometry's part of the second-order reports (`second_order`'s single solve and
//! `many_sources`' batch, whose sources share one geometry).

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The tube geometry's part of a second-order report (one solve's, or a batch's, whose sources
/// share it): the largest curvature, the range of |∇φ|, the inner-tube nodes that run the
/// first-order update and why, and the creases. `runaway`: a solve's nodes that a runaway left at
/// first order (`tubesweep_core::second_order::demotion`), counted among them as their own reason
/// (0 for a batch, whose rows report theirs).
pub(crate) fn geometry_report(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    summary: &tubesweep_core::second_order::GeometrySummary,
    runaway: usize,
) -> PyResult<()> {
    d.set_item("max_curvature", summary.max_curvature)?;
    d.set_item("grad_norm_range", (summary.grad_norm_min, summary.grad_norm_max))?;
    d.set_item("first_order_nodes", summary.first_order_nodes() + runaway)?;
    d.set_item("inner_nodes", summary.inner_nodes)?;
    let reasons = PyDict::new(py);
    reasons.set_item("stencil", summary.incomplete_stencils)?;
    reasons.set_item("gradient", summary.off_distance)?;
    reasons.set_item("curvature", summary.unresolved_curvature)?;
    reasons.set_item("runaway", runaway)?;
    d.set_item("first_order_reasons", reasons)?;
    d.set_item("creases", crate::creases::creases_dict(py, &summary.creases)?)
}
