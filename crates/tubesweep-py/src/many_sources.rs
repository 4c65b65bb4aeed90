//! Bindings of `tubesweep_core::sweep::many_sources`: many independent solves on one band, in parallel
//! across the sources, with the GIL released; progress and Ctrl-C on the calling thread.

use crate::band::{AnyBand, PyBand};
use crate::convert::{c_slice, node_roles};
use crate::errors::to_pyerr;
use crate::sweep::{extension_in_place, parse_missing, parse_scheme};
use numpy::{
    IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::sweep::many_sources::{solve_many, FixedSet, Output};
use tubesweep_core::sweep::{default_row_prefetch_above, MissingNeighbour, Slowness};
use tubesweep_core::{Control, InnerScheme, SolveOptions, SolveStats, SweepProblem};

/// What a batch too large for memory says (the K × n values of a batch without `at`, or K × M).
const ROWS_FIX: &str = "pass at= (the values at the points you need: sources × points) or solve fewer sources per call";

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
    let mut values = tubesweep_core::error::batch_rows(k, width, ROWS_FIX).map_err(to_pyerr)?;
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

/// What the second-order batch reads, borrowed from NumPy.
struct Order2Inputs<'s> {
    roles: &'s [u8],
    phi: &'s [f64],
    cp_offsets: Option<&'s [f64]>,
    directions: &'s [f32],
    lower: Vec<f64>,
    spacing: f64,
    feet: &'s [f64],
    source_slowness: &'s [f64],
    offsets: &'s [i64],
    slowness: Slowness<'s>,
    fix_radius: f64,
    outer_width: f64,
    options: tubesweep_core::second_order::SecondOrderOptions,
    threads: usize,
    front_window: f64,
    at: Option<(&'s [f64], &'s [f64])>,
    reach_spacings: f64,
    reach_curvature_radii: f64,
}

fn run_order2<'py, const D: usize>(
    py: Python<'py>,
    band: &NarrowBand<D>,
    inp: &Order2Inputs<'_>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>)> {
    use crate::convert::node_vectors;
    use tubesweep_core::second_order::many::{solve_many_second_order, BatchSource, BatchTube, Order2Output};
    use tubesweep_core::second_order::{check_geometry_of, setup::batch_setup_of, Implicit};
    let n = band.len();
    let roles = node_roles(inp.roles)?;
    if roles.len() != n || inp.phi.len() != n {
        return Err(PyValueError::new_err(format!(
            "roles and phi need one entry per band node ({n})"
        )));
    }
    let directions = node_vectors::<f32, D>(inp.directions, n, "directions")?;
    let surface = match inp.cp_offsets {
        Some(o) => Implicit::ClosestPoint(node_vectors::<f64, D>(o, n, "offsets")?),
        None => Implicit::LevelSet(inp.phi),
    };
    let feet = node_vectors::<f64, D>(inp.feet, inp.feet.len() / D, "feet")?;
    if feet.len() * D != inp.feet.len() || inp.source_slowness.len() != feet.len() {
        return Err(PyValueError::new_err("feet (P, d) and source_slowness (P,) must match"));
    }
    let offsets = inp.offsets;
    if offsets.len() < 2
        || offsets[0] != 0
        || *offsets.last().unwrap_or(&0) as usize != feet.len()
        || offsets.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(PyValueError::new_err(
            "offsets must rise strictly from 0 to the number of source points",
        ));
    }
    let sources: Vec<BatchSource<'_, D>> = offsets
        .windows(2)
        .map(|w| BatchSource {
            feet: &feet[w[0] as usize..w[1] as usize],
            slowness: &inp.source_slowness[w[0] as usize..w[1] as usize],
        })
        .collect();
    let lower: [f64; D] = inp
        .lower
        .as_slice()
        .try_into()
        .map_err(|_| PyValueError::new_err(format!("lower must have {D} entries")))?;
    let at = match inp.at {
        Some((p, f)) => {
            let m = p.len() / D;
            Some((
                node_vectors::<f64, D>(p, m, "at")?,
                node_vectors::<f64, D>(f, m, "at_feet")?,
            ))
        }
        None => None,
    };
    let k = sources.len();
    let width = at.map_or(n, |(p, _)| p.len());
    let mut values = tubesweep_core::error::batch_rows(k, width, ROWS_FIX).map_err(to_pyerr)?;
    let mut py_error: Option<PyErr> = None;
    let progress_ref = progress.as_ref().map(|p| p.clone().unbind());
    let result = py.detach(|| {
        // the tube's geometry and the factoring's feet once for the batch
        let (geometry, feet) = batch_setup_of(
            band,
            roles,
            &surface,
            directions,
            lower,
            inp.spacing,
            inp.outer_width,
            inp.threads,
        )?;
        check_geometry_of(
            &geometry.summary,
            inp.outer_width,
            inp.spacing,
            surface.is_closest_point(),
        )?;
        let kappa = geometry.summary.max_curvature;
        // tubesweep._factoring.factored_reach, the same operations
        let mut reach = inp.reach_spacings * inp.spacing;
        if inp.reach_curvature_radii > 0.0 && D == 3 && kappa > 0.0 && kappa.is_finite() {
            reach = reach.max(inp.reach_curvature_radii / kappa);
        }
        let tube = BatchTube {
            band,
            roles,
            directions,
            geometry: &geometry,
            feet: &feet,
            lower,
            spacing: inp.spacing,
            slowness: inp.slowness,
            fix_radius: inp.fix_radius,
            options: inp.options,
            front_window: inp.front_window,
        };
        let output = match at {
            Some((points, feet)) => Order2Output::AtPoints {
                lower,
                points,
                // the points' feet on the surface, as sol(points) reads the chord from them (from
                // the points themselves within three spacings, a point 0.005 off a sphere sampled
                // at N = 41 read 0.005 above its source, where sol(points) reads 0)
                feet,
                reach,
                values: &mut values,
            },
            None => Order2Output::Band(&mut values),
        };
        let mut report =
            |done: usize| -> Control { crate::progress::check_in(&progress_ref, &mut py_error, (done, k)) };
        let stats = solve_many_second_order(&tube, &sources, inp.threads, output, &mut report)?;
        Ok::<_, tubesweep_core::Error>((stats, geometry.summary, reach))
    });
    if let Some(e) = py_error {
        return Err(e);
    }
    let (stats, summary, reach) = result.map_err(to_pyerr)?;
    let array = values.into_pyarray(py).reshape([k, width])?;
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&tubesweep_core::second_order::SecondOrderStats) -> i64| -> Vec<i64> {
        stats.iter().map(f).collect()
    };
    d.set_item(
        "iterations",
        col(&|s| (s.first_order_iterations + s.second_order_iterations) as i64).into_pyarray(py),
    )?;
    d.set_item(
        "second_order_iterations",
        col(&|s| s.second_order_iterations as i64).into_pyarray(py),
    )?;
    d.set_item("updates", col(&|s| s.updates as i64).into_pyarray(py))?;
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
        "fallback_iteration",
        col(&|s| s.fallback_iteration.map_or(-1, |v| v as i64)).into_pyarray(py),
    )?;
    d.set_item(
        "fallback_change",
        stats
            .iter()
            .map(|s| s.fallback_change.unwrap_or(f64::NAN))
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "runaway_iteration",
        col(&|s| s.runaway_iteration.map_or(-1, |v| v as i64)).into_pyarray(py),
    )?;
    d.set_item(
        "restart_failed",
        stats
            .iter()
            .map(|s| s.restart_failed)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("unreached", col(&|s| s.unreached as i64).into_pyarray(py))?;
    // per row, the inner-tube nodes that a runaway left at first order (solved again with them so)
    d.set_item("runaway_nodes", col(&|s| s.demoted_nodes as i64).into_pyarray(py))?;
    d.set_item(
        "runaway_first_iteration",
        col(&|s| s.demoted_runaway_iteration.map_or(-1, |v| v as i64)).into_pyarray(py),
    )?;
    // the tube's geometry, shared by every source (the inner nodes that run the first-order update)
    crate::geometry_report::geometry_report(py, &d, &summary, 0)?;
    d.set_item("reach", reach)?;
    Ok((array, d))
}

/// K second-order solves on `band` (`tubesweep_core::second_order::many`), the tube's geometry
/// computed once: source `k` is the points `feet[offsets[k]:offsets[k+1]]` (on the surface) with
/// their slownesses. The other arguments are `second_order_solve`'s; with `at` (M, d) points and
/// their feet on the surface `at_feet`, the values there as `sol(points)` evaluates them (the
/// factored form within `reach_spacings` grid spacings of a source, or `reach_curvature_radii`
/// curvature radii when positive). Returns `(values, stats)`: values `(K, n)` or `(K, M)`, stats
/// per-source arrays and the scalars `max_curvature` and `reach`. Refusals of the geometry are
/// ValueErrors starting with `order=2`.
#[pyfunction]
#[pyo3(signature = (band, roles, phi, directions, lower, spacing, feet, source_slowness, offsets, slowness, fix_radius, outer_width, tol_first, tol, max_iterations, progress=None, threads=0, front_window=2.0, own_first_phase=true, cp_offsets=None, window_first=0.0, window_second=0.0, ramp_length=1.0, extension_limit=f64::INFINITY, stall_ratio=tubesweep_core::second_order::STALL_RATIO, stall_window=20, at=None, at_feet=None, reach_spacings=3.0, reach_curvature_radii=0.0))]
#[allow(clippy::too_many_arguments)]
pub fn second_order_solve_many<'py>(
    py: Python<'py>,
    band: PyRef<'py, PyBand>,
    roles: PyReadonlyArray1<'py, u8>,
    phi: PyReadonlyArray1<'py, f64>,
    directions: PyReadonlyArray2<'py, f32>,
    lower: Vec<f64>,
    spacing: f64,
    feet: PyReadonlyArray2<'py, f64>,
    source_slowness: PyReadonlyArray1<'py, f64>,
    offsets: PyReadonlyArray1<'py, i64>,
    slowness: Bound<'py, PyAny>,
    fix_radius: f64,
    outer_width: f64,
    tol_first: f64,
    tol: f64,
    max_iterations: usize,
    progress: Option<Bound<'py, PyAny>>,
    threads: usize,
    front_window: f64,
    own_first_phase: bool,
    cp_offsets: Option<PyReadonlyArray2<'py, f64>>,
    window_first: f64,
    window_second: f64,
    ramp_length: f64,
    extension_limit: f64,
    stall_ratio: f64,
    stall_window: usize,
    at: Option<PyReadonlyArray2<'py, f64>>,
    at_feet: Option<PyReadonlyArray2<'py, f64>>,
    reach_spacings: f64,
    reach_curvature_radii: f64,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>)> {
    if !(tol > 0.0 && tol_first > 0.0) {
        return Err(PyValueError::new_err("tol must be positive"));
    }
    let d = band.ndim();
    if feet.shape()[1] != d {
        return Err(PyValueError::new_err(format!("feet must have shape (P, {d})")));
    }
    let per_node: Option<PyReadonlyArray1<'py, f64>> = if slowness.is_instance_of::<pyo3::types::PyFloat>() {
        None
    } else {
        Some(slowness.extract()?)
    };
    let constant: f64 = if per_node.is_none() { slowness.extract()? } else { 1.0 };
    let at_pair = match (&at, &at_feet) {
        (Some(p), Some(f)) => {
            if p.shape() != f.shape() || p.shape()[1] != d {
                return Err(PyValueError::new_err(format!(
                    "at and at_feet must have the same shape (M, {d})"
                )));
            }
            Some((c_slice(p, "at")?, c_slice(f, "at_feet")?))
        }
        (None, None) => None,
        _ => return Err(PyValueError::new_err("at and at_feet go together")),
    };
    let inputs = Order2Inputs {
        roles: c_slice(&roles, "roles")?,
        phi: c_slice(&phi, "phi")?,
        cp_offsets: match &cp_offsets {
            Some(a) => Some(c_slice(a, "cp_offsets")?),
            None => None,
        },
        directions: c_slice(&directions, "directions")?,
        lower,
        spacing,
        feet: c_slice(&feet, "feet")?,
        source_slowness: c_slice(&source_slowness, "source_slowness")?,
        offsets: c_slice(&offsets, "offsets")?,
        slowness: match &per_node {
            Some(a) => Slowness::PerNode(c_slice(a, "slowness")?),
            None => Slowness::Constant(constant),
        },
        fix_radius,
        outer_width,
        options: tubesweep_core::second_order::SecondOrderOptions {
            tol_first,
            tol,
            max_iterations,
            stall_ratio,
            stall_window,
            own_first_phase,
            window_first,
            window_second,
            extension_limit,
            threads: 1,
            ramp_length,
        },
        threads,
        front_window,
        at: at_pair,
        reach_spacings,
        reach_curvature_radii,
    };
    match &band.band {
        AnyBand::D2(b) => run_order2(py, b, &inputs, progress),
        AnyBand::D3(b) => run_order2(py, b, &inputs, progress),
    }
}
