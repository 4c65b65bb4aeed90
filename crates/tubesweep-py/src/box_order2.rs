//! Bindings of the second-order box solver (`tubesweep_core::sweep::factored_box`) and of the cubic
//! interpolation in a band (`tubesweep_core::solution::interpolate_cubic`). Registered by [`register`].

use crate::band::{AnyBand, PyBand};
use crate::errors::to_pyerr;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::solution::interpolate_cubic::interpolate_cubic;
use tubesweep_core::sweep::factored_box::{FactoredBox, FactoredOptions, FactoredStats};
use tubesweep_core::sweep::Slowness;
use tubesweep_core::{Control, IterationReport};

fn stats_dict<'py>(py: Python<'py>, s: &FactoredStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iterations", s.iterations)?;
    d.set_item("first_order_iterations", s.first_order_iterations)?;
    d.set_item("second_order_iterations", s.second_order_iterations)?;
    d.set_item("sweeps", s.sweeps)?;
    d.set_item("updates", s.updates)?;
    d.set_item("converged", s.converged)?;
    d.set_item("last_change", s.last_change)?;
    d.set_item("safeguard_iteration", s.safeguard_iteration)?;
    d.set_item("safeguard_change", s.safeguard_change)?;
    d.set_item("runaway_iteration", s.runaway_iteration)?;
    d.set_item("plain_iterations", s.plain_iterations)?;
    d.set_item("seconds", s.seconds)?;
    Ok(d)
}

fn fixed_array<const D: usize>(v: &[f64], name: &str) -> PyResult<[f64; D]> {
    v.try_into()
        .map_err(|_| PyValueError::new_err(format!("{name} must have {D} entries")))
}

/// The second-order (or, with `second_order=False`, first-order factored) sweeps in the whole
/// box. `slowness` is a float or one value per node (C order); `sources` (K, d) with
/// `source_slowness` (K,); the nodes `fixed_nodes` (linear indices) held at `fixed_values`.
/// Returns the values (C order) and a stats dict.
#[pyfunction]
#[pyo3(signature = (shape, lower, spacing, slowness, sources, source_slowness, fixed_nodes, fixed_values, tol, max_iterations, second_order=true, ramp_length=1.0, threads=0, progress=None, activation_threshold=0.0))]
#[allow(clippy::too_many_arguments)]
fn factored_box_solve<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    lower: Vec<f64>,
    spacing: f64,
    slowness: Bound<'py, PyAny>,
    sources: PyReadonlyArray2<'py, f64>,
    source_slowness: PyReadonlyArray1<'py, f64>,
    fixed_nodes: PyReadonlyArray1<'py, i64>,
    fixed_values: PyReadonlyArray1<'py, f64>,
    tol: f64,
    max_iterations: usize,
    second_order: bool,
    ramp_length: f64,
    threads: usize,
    progress: Option<Bound<'py, PyAny>>,
    activation_threshold: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
    let d = shape.len();
    if sources.shape()[1] != d || lower.len() != d {
        return Err(PyValueError::new_err(format!(
            "sources must have shape (K, {d}) and lower {d} entries"
        )));
    }
    let per_node: Option<PyReadonlyArray1<'py, f64>> = if slowness.extract::<f64>().is_ok() {
        None
    } else {
        Some(slowness.extract()?)
    };
    let constant = if per_node.is_none() {
        slowness.extract::<f64>()?
    } else {
        0.0
    };
    let slow = match &per_node {
        Some(a) => Slowness::PerNode(a.as_slice()?),
        None => Slowness::Constant(constant),
    };
    let src = sources.as_slice()?;
    let src_slow = source_slowness.as_slice()?;
    let fixed: Vec<usize> = fixed_nodes
        .as_slice()?
        .iter()
        .map(|&i| usize::try_from(i).map_err(|_| PyValueError::new_err(format!("fixed_nodes: {i} is not a node"))))
        .collect::<PyResult<_>>()?;
    let fixed_vals = fixed_values.as_slice()?;
    let options = FactoredOptions {
        tol,
        max_iterations,
        second_order,
        ramp_length,
        threads,
        activation_threshold,
        ..Default::default()
    };
    let progress_ref = progress.as_ref().map(|p| p.clone().unbind());
    let mut py_error: Option<PyErr> = None;
    let result = py.detach(|| {
        let mut callback = |r: &IterationReport| -> Control {
            crate::progress::check_in(&progress_ref, &mut py_error, (r.iteration, r.max_change, r.updates))
        };
        match d {
            2 => {
                let sources: Vec<[f64; 2]> = src.chunks(2).map(|c| [c[0], c[1]]).collect();
                let p = FactoredBox::<2> {
                    shape: [shape[0], shape[1]],
                    lower: fixed_array(&lower, "lower")?,
                    h: spacing,
                    slowness: slow,
                    sources: &sources,
                    source_slowness: src_slow,
                    fixed_nodes: &fixed,
                    fixed_values: fixed_vals,
                };
                p.solve(&options, &mut callback).map_err(to_pyerr)
            }
            3 => {
                let sources: Vec<[f64; 3]> = src.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
                let p = FactoredBox::<3> {
                    shape: [shape[0], shape[1], shape[2]],
                    lower: fixed_array(&lower, "lower")?,
                    h: spacing,
                    slowness: slow,
                    sources: &sources,
                    source_slowness: src_slow,
                    fixed_nodes: &fixed,
                    fixed_values: fixed_vals,
                };
                p.solve(&options, &mut callback).map_err(to_pyerr)
            }
            _ => Err(PyValueError::new_err("the box must be 2D or 3D")),
        }
    });
    if let Some(e) = py_error {
        return Err(e);
    }
    let (values, stats) = result?;
    Ok((values.into_pyarray(py), stats_dict(py, &stats)?))
}

/// Cubic (Catmull–Rom) interpolation of `values` (one per band node) at `points` (M, d), with
/// the multilinear value where the 4^d stencil is incomplete. Returns the values and a bool per
/// point: whether it got the cubic.
#[pyfunction]
fn band_interpolate_cubic<'py>(
    py: Python<'py>,
    band: &PyBand,
    values: PyReadonlyArray1<'py, f64>,
    lower: Vec<f64>,
    spacing: f64,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<bool>>)> {
    let d = band.ndim();
    if points.shape()[1] != d || lower.len() != d {
        return Err(PyValueError::new_err(format!("points must have shape (M, {d})")));
    }
    let vals = values.as_slice()?;
    if vals.len() != band.__len__() {
        return Err(PyValueError::new_err("values must have one entry per band node"));
    }
    let pts = points.as_slice()?;
    let (out, used) = py.detach(|| match &band.band {
        AnyBand::D2(b) => interpolate_cubic(b, vals, [lower[0], lower[1]], spacing, pts),
        AnyBand::D3(b) => interpolate_cubic(b, vals, [lower[0], lower[1], lower[2]], spacing, pts),
    });
    Ok((out.into_pyarray(py), used.into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(factored_box_solve, m)?)?;
    m.add_function(wrap_pyfunction!(band_interpolate_cubic, m)?)?;
    Ok(())
}
