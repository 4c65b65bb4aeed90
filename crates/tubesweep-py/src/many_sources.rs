//! Bindings of `tubesweep_core::sweep::many_sources`: many independent solves on one band, in parallel
//! across the sources, with the GIL released; progress and Ctrl-C on the calling thread.

use crate::band::{AnyBand, PyBand};
use crate::convert::{c_slice, node_roles};
use crate::errors::to_pyerr;
use crate::sweep::{extension_in_place, parse_missing, parse_scheme};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::sweep::many_sources::{solve_many, FixedSet, Output};
use tubesweep_core::sweep::{default_row_prefetch_above, MissingNeighbour, Slowness};
use tubesweep_core::{Control, InnerScheme, SolveOptions, SolveStats, SweepProblem};

/// Registers the functions of this file in the native module (called from `lib.rs`).
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(solve_many_on_band, m)?)
}

/// The per-source statistics as arrays (K,): iterations, updates, converged, last_change,
/// seconds, infinity, window_edge.
fn stats_arrays<'py>(py: Python<'py>, stats: &[SolveStats]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "iterations",
        stats
            .iter()
            .map(|s| s.iterations as i64)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "updates",
        stats.iter().map(|s| s.updates).collect::<Vec<_>>().into_pyarray(py),
    )?;
    d.set_item(
        "converged",
        stats.iter().map(|s| s.converged).collect::<Vec<_>>().into_pyarray(py),
    )?;
    d.set_item(
        "last_change",
        stats.iter().map(|s| s.last_change).collect::<Vec<_>>().into_pyarray(py),
    )?;
    d.set_item(
        "seconds",
        stats.iter().map(|s| s.seconds).collect::<Vec<_>>().into_pyarray(py),
    )?;
    d.set_item(
        "infinity",
        stats.iter().map(|s| s.infinity).collect::<Vec<_>>().into_pyarray(py),
    )?;
    d.set_item(
        "window_edge",
        stats.iter().map(|s| s.window_edge).collect::<Vec<_>>().into_pyarray(py),
    )?;
    Ok(d)
}

/// Everything a solve of one source needs besides its fixed nodes, as `Band.solve` takes it.
struct Common<'s> {
    roles: &'s [u8],
    spacing: f64,
    slowness: Slowness<'s>,
    scheme: u8,
    missing: MissingNeighbour,
    options: SolveOptions,
    threads: usize,
}

#[allow(clippy::too_many_arguments)]
fn run<'py, const D: usize>(
    py: Python<'py>,
    band: &NarrowBand<D>,
    common: Common<'_>,
    directions: &mut Option<PyReadwriteArray2<'py, f32>>,
    sources: &[FixedSet<'_>],
    at: Option<(&[f64], &[f64])>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>)> {
    let n = band.len();
    if common.roles.len() != n {
        return Err(PyValueError::new_err(format!(
            "roles must have one entry per band node ({n})"
        )));
    }
    let roles = node_roles(common.roles)?;
    let template = SweepProblem {
        band,
        roles,
        spacing: common.spacing,
        slowness: common.slowness,
        // the weights of Eq. (5) depend on the roles only through the layer's nodes, which no
        // source fixes: derived once for every source
        extension: extension_in_place::<D>(band, roles, directions, n)?,
        scheme: if common.scheme == 0 {
            InnerScheme::Godunov
        } else {
            InnerScheme::LaxFriedrichs
        },
        missing: common.missing,
    };
    let k = sources.len();
    let width = match at {
        Some((points, _)) => points.len() / D,
        None => n,
    };
    let lower: [f64; D] = match at {
        Some((_, lower)) => lower
            .try_into()
            .map_err(|_| PyValueError::new_err(format!("lower must have {D} entries")))?,
        None => [0.0; D],
    };
    let mut values = vec![0.0f64; k * width];
    let mut py_error: Option<PyErr> = None;
    let progress_ref = progress.as_ref().map(|p| p.clone().unbind());
    let result = py.detach(|| {
        let mut report =
            |done: usize| -> Control { crate::progress::check_in(&progress_ref, &mut py_error, (done, k)) };
        let output = match at {
            Some((points, _)) => Output::AtPoints {
                lower,
                points,
                values: &mut values,
            },
            None => Output::Band(&mut values),
        };
        solve_many(&template, sources, &common.options, common.threads, output, &mut report)
    });
    if let Some(e) = py_error {
        return Err(e);
    }
    let stats = result.map_err(to_pyerr)?;
    let array = values.into_pyarray(py).reshape([k, width])?;
    Ok((array, stats_arrays(py, &stats)?))
}

/// `K` solves on `band`, one per source, in parallel across the sources (each solve on one
/// thread): source `k` fixes the band positions `fixed_positions[offsets[k]:offsets[k+1]]` to
/// `fixed_values[...]` in a copy of `roles` (which must hold no fixed node). The other arguments
/// are `Band.solve`'s; `directions` is overwritten with the extension weights, once for all the
/// sources. Returns `(values, stats)`: values `(K, n)`, or with `at` (M, d) points and the grid's
/// `lower` corner the values interpolated there `(K, M)`; stats a dict of per-source arrays.
/// `progress(done, K)` is called on this thread about every 50 ms.
#[pyfunction]
#[pyo3(signature = (band, roles, fixed_positions, fixed_values, offsets, spacing, slowness, directions, scheme, missing, tol, max_iterations, infinity, progress=None, threads=0, activation_threshold=0.0, coupled=true, defer_outer_rim=true, front_window=0.0, at=None, lower=None))]
#[allow(clippy::too_many_arguments)]
fn solve_many_on_band<'py>(
    py: Python<'py>,
    band: &Bound<'py, PyBand>,
    roles: PyReadonlyArray1<'py, u8>,
    fixed_positions: PyReadonlyArray1<'py, i64>,
    fixed_values: PyReadonlyArray1<'py, f64>,
    offsets: PyReadonlyArray1<'py, i64>,
    spacing: f64,
    slowness: Bound<'py, PyAny>,
    mut directions: Option<PyReadwriteArray2<'py, f32>>,
    scheme: &str,
    missing: &str,
    tol: f64,
    max_iterations: usize,
    infinity: Option<f64>,
    progress: Option<Bound<'py, PyAny>>,
    threads: usize,
    activation_threshold: f64,
    coupled: bool,
    defer_outer_rim: bool,
    front_window: f64,
    at: Option<PyReadonlyArray2<'py, f64>>,
    lower: Option<Vec<f64>>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>)> {
    let scheme = parse_scheme(scheme)?;
    let missing = parse_missing(missing)?;
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "spacing must be positive and finite, got {spacing}"
        )));
    }
    if !(activation_threshold >= 0.0) {
        return Err(PyValueError::new_err("activation_threshold must be non-negative"));
    }
    if !(front_window >= 0.0 && front_window.is_finite()) {
        return Err(PyValueError::new_err(
            "front_window must be a non-negative finite number (0 switches the window off)",
        ));
    }
    let options = SolveOptions {
        tol,
        max_iterations,
        infinity,
        threads: 1,
        skip_inactive: true,
        activation_threshold,
        coupled,
        defer_outer_rim,
        front_window,
        spread_threads: true,
        row_prefetch_above: default_row_prefetch_above(),
    };
    let positions = fixed_positions.as_slice()?;
    let values = fixed_values.as_slice()?;
    let offsets = offsets.as_slice()?;
    if positions.len() != values.len() {
        return Err(PyValueError::new_err(
            "fixed_positions and fixed_values must have the same length",
        ));
    }
    if offsets.is_empty()
        || offsets[0] != 0
        || *offsets.last().unwrap_or(&0) as usize != positions.len()
        || offsets.windows(2).any(|w| w[1] < w[0])
    {
        return Err(PyValueError::new_err(
            "offsets must rise from 0 to the number of fixed positions",
        ));
    }
    if positions.iter().any(|&p| p < 0) {
        return Err(PyValueError::new_err(
            "fixed_positions must be non-negative band positions",
        ));
    }
    let positions: Vec<usize> = positions.iter().map(|&p| p as usize).collect();
    let sources: Vec<FixedSet<'_>> = offsets
        .windows(2)
        .map(|w| FixedSet {
            positions: &positions[w[0] as usize..w[1] as usize],
            values: &values[w[0] as usize..w[1] as usize],
        })
        .collect();
    let slowness_arr: Option<PyReadonlyArray1<'py, f64>> = if slowness.extract::<f64>().is_ok() {
        None
    } else {
        Some(slowness.extract()?)
    };
    let slowness = match &slowness_arr {
        Some(a) => Slowness::PerNode(a.as_slice()?),
        None => Slowness::Constant(slowness.extract::<f64>()?),
    };
    let points = match &at {
        Some(p) => Some(c_slice(p, "at")?),
        None => None,
    };
    let lower = lower.unwrap_or_default();
    let at = points.map(|p| (p, &lower[..]));
    let common = Common {
        roles: roles.as_slice()?,
        spacing,
        slowness,
        scheme,
        missing,
        options,
        threads,
    };
    let band = band.get();
    match &band.band {
        AnyBand::D2(b) => run(py, b, common, &mut directions, &sources, at, progress),
        AnyBand::D3(b) => run(py, b, common, &mut directions, &sources, at, progress),
    }
}
