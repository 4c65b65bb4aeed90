//! Bindings of the second-order surface solver (`tubesweep_core::second_order`, `order=2`).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::second_order::fingerprint::node_fingerprints;
use tubesweep_core::second_order::warm::WarmStart;
use tubesweep_core::second_order::{
    check_geometry_of, first_order_start, starting_values, sweep_second_order_reporting, tube_setup_of, Implicit,
    SecondOrderOptions,
};
use tubesweep_core::sweep::{NodeRole, Slowness};
use tubesweep_core::{Control, IterationReport};

use crate::band::{AnyBand, PyBand};
use crate::convert::{c_slice, node_roles, node_vectors};
use crate::errors::to_pyerr;

type Solved<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyDict>,
);

/// Everything the solve reads, borrowed from NumPy.
struct Inputs<'s> {
    roles: &'s [u8],
    phi: &'s [f64],
    /// x − cp(x) per band node for a closest-point surface (then `phi` is |x − cp(x)|)
    offsets: Option<&'s [f64]>,
    directions: &'s [f32],
    lower: Vec<f64>,
    spacing: f64,
    sources: &'s [f64],
    source_slowness: &'s [f64],
    slowness: Option<&'s [f64]>,
    constant_slowness: f64,
    fix_radius: f64,
    outer_width: f64,
    options: SecondOrderOptions,
    threads: usize,
    front_window: f64,
    /// the previous values carried onto this band (`moving.rs`): a warm start
    warm: Option<&'s [f64]>,
    /// the values of the solve before the previous one on this band (a start extrapolated in time)
    warm_older: Option<&'s [f64]>,
    /// the previous band's grid positions and its nodes' digests (the sweeps start from the nodes
    /// whose update changed)
    warm_previous: Option<(&'s [u64], &'s [u64])>,
    /// return this solve's digests (for a warm start from it; 8 bytes per node)
    keep_digests: bool,
}

fn run<'py, const D: usize>(
    py: Python<'py>,
    band: &NarrowBand<D>,
    inp: &Inputs<'_>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Solved<'py>> {
    let n = band.len();
    let roles = node_roles(inp.roles)?;
    if roles.len() != n || inp.phi.len() != n {
        return Err(PyValueError::new_err(format!(
            "roles and phi need one entry per band node ({n})"
        )));
    }
    let directions = node_vectors::<f32, D>(inp.directions, n, "directions")?;
    let surface = match inp.offsets {
        Some(o) => Implicit::ClosestPoint(node_vectors::<f64, D>(o, n, "offsets")?),
        None => Implicit::LevelSet(inp.phi),
    };
    let sources = node_vectors::<f64, D>(inp.sources, inp.sources.len() / D, "sources")?;
    let lower: [f64; D] = inp
        .lower
        .as_slice()
        .try_into()
        .map_err(|_| PyValueError::new_err(format!("lower must have {D} entries")))?;
    let slowness = match inp.slowness {
        Some(s) => Slowness::PerNode(s),
        None => Slowness::Constant(inp.constant_slowness),
    };
    let mut py_error: Option<PyErr> = None;
    let progress_ref = progress.as_ref().map(|p| p.clone().unbind());
    let result = py.detach(|| {
        let (geometry, factoring) = tube_setup_of(
            band,
            roles,
            &surface,
            directions,
            lower,
            inp.spacing,
            inp.outer_width,
            sources,
            inp.source_slowness,
            inp.fix_radius,
            inp.threads,
        )?;
        check_geometry_of(
            &geometry.summary,
            inp.outer_width,
            inp.spacing,
            surface.is_closest_point(),
        )?;
        let factoring = factoring?;
        let mut values = starting_values(&factoring);
        let mut callback = |r: &IterationReport| -> Control {
            crate::progress::check_in(&progress_ref, &mut py_error, (r.iteration, r.max_change, r.updates))
        };
        let mut warm_report = None;
        // what each node's update reads of its own, for a warm start from this solve (or this one's
        // from the previous solve's)
        let digests = if inp.keep_digests || inp.warm_previous.is_some() {
            node_fingerprints(band, &geometry, &factoring, directions, slowness)?
        } else {
            Vec::new()
        };
        let (stats, demoted) = if let Some(carried) = inp.warm {
            // a warm start (tubesweep_core::second_order::warm): phase 2 from the carried values
            let start = WarmStart {
                carried,
                older: inp.warm_older,
                previous: inp.warm_previous.map(|(l, d)| (l, d, &digests[..])),
            };
            let w = tubesweep_core::second_order::warm::sweep_warm(
                band,
                &geometry,
                &factoring,
                directions,
                slowness,
                inp.spacing,
                &start,
                &mut values,
                &inp.options,
                &mut callback,
            )?;
            let stats = w.stats;
            let demoted = w.demoted.clone();
            warm_report = Some(w);
            (stats, demoted)
        } else {
            let mut first_seconds = 0.0;
            let mut first_iterations = 0;
            if !inp.options.own_first_phase {
                let st = first_order_start(
                    band,
                    &geometry.nodes,
                    &factoring,
                    directions,
                    slowness,
                    inp.spacing,
                    inp.options.tol_first,
                    inp.options.max_iterations,
                    inp.threads,
                    inp.front_window,
                    &mut values,
                    &mut callback,
                )?;
                first_seconds = st.seconds;
                first_iterations = st.iterations;
            }
            // max_iterations bounds both phases together
            let options = tubesweep_core::second_order::SecondOrderOptions {
                max_iterations: inp.options.max_iterations.saturating_sub(first_iterations),
                ..inp.options
            };
            let (mut stats, demoted) = sweep_second_order_reporting(
                (band, &geometry, &factoring, directions, slowness),
                inp.spacing,
                &mut values,
                &options,
                &mut callback,
            )?;
            if !inp.options.own_first_phase {
                stats.first_order_iterations += first_iterations;
                stats.seconds += first_seconds;
            }
            (stats, demoted)
        };
        // what the solve holds besides the band and the arrays it borrows from the tube (φ,
        // the directions, the roles given): the inner nodes' geometry and ∂u₀, u₀, |φ|, the
        // roles with the fixed nodes, the values, the active flags, per row an offset
        let bytes = geometry.nodes.capacity() * std::mem::size_of::<tubesweep_core::second_order::NodeGeometry>()
            + factoring.grad_u0.capacity() * 4 * D
            + factoring.u0.capacity() * 8
            + geometry.abs_phi.capacity() * 4
            + factoring.roles.capacity()
            + values.capacity() * 8
            + n
            + 4 * (band.n_rows() + 1)
            + if inp.keep_digests { digests.capacity() * 8 } else { 0 };
        let roles_out: Vec<u8> = factoring.roles.iter().map(|&r| r as u8).collect();
        // where the update ran first order (band positions), node by node: the geometry's, and
        // where the sweeps ran away (tubesweep_core::second_order::demotion)
        let mut first_order: Vec<u32> = (0..n)
            .filter(|&i| roles[i] != NodeRole::Outer)
            .zip(&geometry.nodes)
            .filter(|(_, g)| g.first_order() != 0)
            .map(|(i, _)| i as u32)
            .chain(demoted.iter().copied())
            .collect();
        first_order.sort_unstable();
        Ok::<_, tubesweep_core::Error>((
            values,
            factoring.u0,
            roles_out,
            stats,
            geometry.summary,
            bytes,
            first_order,
            warm_report,
            digests,
        ))
    });
    if let Some(e) = py_error {
        return Err(e);
    }
    let (values, u0, roles_out, stats, summary, bytes, first_order, warm_report, digests) = result.map_err(to_pyerr)?;
    let d = PyDict::new(py);
    d.set_item(
        "iterations",
        stats.first_order_iterations + stats.second_order_iterations,
    )?;
    d.set_item("first_order_iterations", stats.first_order_iterations)?;
    d.set_item("second_order_iterations", stats.second_order_iterations)?;
    d.set_item("updates", stats.updates)?;
    d.set_item("converged", stats.converged)?;
    d.set_item("last_change", stats.last_change)?;
    d.set_item("seconds", stats.seconds)?;
    d.set_item("fallback_iteration", stats.fallback_iteration)?;
    d.set_item("fallback_change", stats.fallback_change)?;
    d.set_item("runaway_iteration", stats.runaway_iteration)?;
    d.set_item("restart_failed", stats.restart_failed)?;
    d.set_item("unreached", stats.unreached)?;
    d.set_item("solver_bytes", bytes)?;
    crate::geometry_report::geometry_report(py, &d, &summary, stats.demoted_nodes)?;
    // where and when the sweeps ran away, when they were solved again with those nodes at first order
    d.set_item("runaway_at", stats.demoted_at)?;
    d.set_item("runaway_first_iteration", stats.demoted_runaway_iteration)?;
    d.set_item("geometry_fitted", summary.fitted_everywhere)?;
    d.set_item("first_order_positions", first_order.into_pyarray(py))?;
    if inp.keep_digests {
        d.set_item("digests", digests.into_pyarray(py))?;
    }
    if let Some(w) = warm_report {
        d.set_item("warm_carried", w.carried)?;
        d.set_item("warm_restarted", w.restarted.map(|r| format!("{r:?}").to_lowercase()))?;
        d.set_item("warm_changed", w.changed)?;
        d.set_item("warm_extrapolated", w.extrapolated)?;
    }
    Ok((
        values.into_pyarray(py),
        u0.into_pyarray(py),
        roles_out.into_pyarray(py),
        d,
    ))
}

/// The second-order solve on `band` (see `tubesweep_core::second_order`): returns the values u,
/// the factored part u₀, the roles with the fixed nodes marked (0) and a statistics dict.
#[pyfunction]
#[pyo3(signature = (band, roles, phi, directions, lower, spacing, sources, source_slowness, slowness, fix_radius, outer_width, tol_first, tol, max_iterations, progress=None, stall_ratio=tubesweep_core::second_order::STALL_RATIO, stall_window=20, threads=0, front_window=2.0, own_first_phase=false, offsets=None, window_first=0.0, window_second=0.0, ramp_length=1.0, extension_limit=f64::INFINITY, warm=None, warm_older=None, warm_previous_linear=None, warm_previous_digests=None, keep_digests=false))]
#[allow(clippy::too_many_arguments)]
pub fn second_order_solve<'py>(
    py: Python<'py>,
    band: PyRef<'py, PyBand>,
    roles: PyReadonlyArray1<'py, u8>,
    phi: PyReadonlyArray1<'py, f64>,
    directions: PyReadonlyArray2<'py, f32>,
    lower: Vec<f64>,
    spacing: f64,
    sources: PyReadonlyArray2<'py, f64>,
    source_slowness: PyReadonlyArray1<'py, f64>,
    slowness: Bound<'py, PyAny>,
    fix_radius: f64,
    outer_width: f64,
    tol_first: f64,
    tol: f64,
    max_iterations: usize,
    progress: Option<Bound<'py, PyAny>>,
    stall_ratio: f64,
    stall_window: usize,
    threads: usize,
    front_window: f64,
    own_first_phase: bool,
    offsets: Option<PyReadonlyArray2<'py, f64>>,
    window_first: f64,
    window_second: f64,
    ramp_length: f64,
    extension_limit: f64,
    warm: Option<PyReadonlyArray1<'py, f64>>,
    warm_older: Option<PyReadonlyArray1<'py, f64>>,
    warm_previous_linear: Option<PyReadonlyArray1<'py, u64>>,
    warm_previous_digests: Option<PyReadonlyArray1<'py, u64>>,
    keep_digests: bool,
) -> PyResult<Solved<'py>> {
    if !(tol > 0.0 && tol_first > 0.0) {
        return Err(PyValueError::new_err("tol must be positive"));
    }
    let per_node: Option<PyReadonlyArray1<'py, f64>> = if slowness.is_instance_of::<pyo3::types::PyFloat>() {
        None
    } else {
        Some(slowness.extract()?)
    };
    let constant_slowness: f64 = if per_node.is_none() { slowness.extract()? } else { 1.0 };
    if sources.shape()[1] != band.ndim() {
        return Err(PyValueError::new_err(format!(
            "sources must have shape (S, {})",
            band.ndim()
        )));
    }
    let inputs = Inputs {
        roles: c_slice(&roles, "roles")?,
        phi: c_slice(&phi, "phi")?,
        offsets: match &offsets {
            Some(a) => Some(c_slice(a, "offsets")?),
            None => None,
        },
        directions: c_slice(&directions, "directions")?,
        lower,
        spacing,
        sources: c_slice(&sources, "sources")?,
        source_slowness: c_slice(&source_slowness, "source_slowness")?,
        slowness: match &per_node {
            Some(a) => Some(c_slice(a, "slowness")?),
            None => None,
        },
        constant_slowness,
        fix_radius,
        outer_width,
        options: SecondOrderOptions {
            tol_first,
            tol,
            max_iterations,
            stall_ratio,
            stall_window,
            own_first_phase,
            window_first,
            window_second,
            extension_limit,
            threads,
            ramp_length,
        },
        threads,
        front_window,
        warm: match &warm {
            Some(a) => Some(c_slice(a, "warm")?),
            None => None,
        },
        warm_older: match &warm_older {
            Some(a) => Some(c_slice(a, "warm_older")?),
            None => None,
        },
        warm_previous: match (&warm_previous_linear, &warm_previous_digests) {
            (Some(l), Some(d)) => Some((
                c_slice(l, "warm_previous_linear")?,
                c_slice(d, "warm_previous_digests")?,
            )),
            (None, None) => None,
            _ => {
                return Err(PyValueError::new_err(
                    "warm_previous_linear and warm_previous_digests go together",
                ))
            }
        },
        keep_digests,
    };
    match &band.band {
        AnyBand::D2(b) => run(py, b, &inputs, progress),
        AnyBand::D3(b) => run(py, b, &inputs, progress),
    }
}

fn feet_query<'py>(
    py: Python<'py>,
    feet: &PyReadonlyArray2<'py, f64>,
    slowness: &PyReadonlyArray1<'py, f64>,
    points: &PyReadonlyArray2<'py, f64>,
    reach: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    use tubesweep_core::solution::source_feet::SourceFeet;
    let d = feet.shape()[1];
    if points.shape()[1] != d || slowness.len() != feet.shape()[0] || feet.shape()[0] == 0 {
        return Err(PyValueError::new_err(
            "feet (S, d) with S ≥ 1, slowness (S,) and points (M, d) must match",
        ));
    }
    let (f, s, p) = (
        c_slice(feet, "feet")?,
        c_slice(slowness, "slowness")?,
        c_slice(points, "points")?,
    );
    fn go<const D: usize>(f: &[f64], s: &[f64], p: &[f64], reach: Option<f64>) -> PyResult<(Vec<bool>, Vec<f64>)> {
        let feet = node_vectors::<f64, D>(f, f.len() / D, "feet")?;
        let pts = node_vectors::<f64, D>(p, p.len() / D, "points")?;
        let tree = SourceFeet::new(feet, s);
        Ok(match reach {
            Some(r) => (pts.iter().map(|x| tree.within(x, r)).collect(), Vec::new()),
            None => (Vec::new(), pts.iter().map(|x| tree.chord_min(x)).collect()),
        })
    }
    let (within, chords) = py.detach(|| match d {
        2 => go::<2>(f, s, p, reach),
        3 => go::<3>(f, s, p, reach),
        _ => Err(PyValueError::new_err("points must be 2D or 3D")),
    })?;
    Ok(if reach.is_some() {
        within.into_pyarray(py).into_any()
    } else {
        chords.into_pyarray(py).into_any()
    })
}

/// Whether each of `points` (M, d) lies within `reach` of one of the sources' `feet` (S, d)
/// (`tubesweep_core::solution::source_feet`, a kd-tree when S is large): bool (M,).
#[pyfunction]
pub fn source_feet_within<'py>(
    py: Python<'py>,
    feet: PyReadonlyArray2<'py, f64>,
    slowness: PyReadonlyArray1<'py, f64>,
    points: PyReadonlyArray2<'py, f64>,
    reach: f64,
) -> PyResult<Bound<'py, PyAny>> {
    feet_query(py, &feet, &slowness, &points, Some(reach))
}

/// The smallest σ_s·|p − x_s| over the sources' `feet` (S, d) with their `slowness` (S,), for
/// each of `points` (M, d): float (M,).
#[pyfunction]
pub fn source_feet_chords<'py>(
    py: Python<'py>,
    feet: PyReadonlyArray2<'py, f64>,
    slowness: PyReadonlyArray1<'py, f64>,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    feet_query(py, &feet, &slowness, &points, None)
}

/// The index of the nearest of `feet` (S, d) to each of `points` (M, d) (a kd-tree in the core):
/// int64 (M,).
#[pyfunction]
pub fn nearest_feet<'py>(
    py: Python<'py>,
    feet: PyReadonlyArray2<'py, f64>,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let d = feet.shape()[1];
    if points.shape()[1] != d || feet.shape()[0] == 0 {
        return Err(PyValueError::new_err(
            "feet (S, d) with S ≥ 1 and points (M, d) must match",
        ));
    }
    let (f, p) = (c_slice(&feet, "feet")?, c_slice(&points, "points")?);
    fn go<const D: usize>(f: &[f64], p: &[f64]) -> PyResult<Vec<i64>> {
        let feet = node_vectors::<f64, D>(f, f.len() / D, "feet")?;
        let pts = node_vectors::<f64, D>(p, p.len() / D, "points")?;
        Ok(tubesweep_core::solution::source_feet::nearest_feet(feet, pts)
            .into_iter()
            .map(|i| i as i64)
            .collect())
    }
    let out = py.detach(|| match d {
        2 => go::<2>(f, p),
        3 => go::<3>(f, p),
        _ => Err(PyValueError::new_err("points must be 2D or 3D")),
    })?;
    Ok(out.into_pyarray(py))
}

/// Registers the functions of this file in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(second_order_solve, m)?)?;
    m.add_function(wrap_pyfunction!(source_feet_within, m)?)?;
    m.add_function(wrap_pyfunction!(source_feet_chords, m)?)?;
    m.add_function(wrap_pyfunction!(nearest_feet, m)?)?;
    m.add_function(wrap_pyfunction!(crate::many_sources::second_order_solve_many, m)?)
}
