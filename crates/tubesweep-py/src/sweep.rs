//! Solves (`tubesweep_core::sweep`): the fixed nodes and extension weights from NumPy, the sweeps
//! with the GIL released, progress and Ctrl-C between iterations, and the statistics as a dict.

use crate::convert::*;
use crate::errors::to_pyerr;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadwriteArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::scheme::hamiltonians::{Isotropic, Metric, MovingMedium, SymmetricMetric};
use tubesweep_core::sweep::{
    default_row_prefetch_above, extension_weights_in_place, Extension, MissingNeighbour, Slowness,
};
use tubesweep_core::{
    Control, Hamiltonian, InnerScheme, IterationReport, NodeRole, SolveOptions, SolveStats, SweepProblem,
};

pub(crate) fn parse_scheme(name: &str) -> PyResult<u8> {
    match name {
        "godunov" => Ok(0),
        "lxf" => Ok(1),
        _ => Err(PyValueError::new_err(format!(
            "hamiltonian: unknown scheme {name:?}; use 'godunov' or 'lxf'"
        ))),
    }
}

pub(crate) fn parse_missing(name: &str) -> PyResult<MissingNeighbour> {
    match name {
        "infinity" => Ok(MissingNeighbour::Infinity),
        "extrapolate" => Ok(MissingNeighbour::Extrapolate),
        _ => Err(PyValueError::new_err(format!("missing: unknown policy {name:?}"))),
    }
}

pub(crate) fn stats_dict<'py>(py: Python<'py>, s: &SolveStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iterations", s.iterations)?;
    d.set_item("sweeps", s.sweeps)?;
    d.set_item("updates", s.updates)?;
    d.set_item("converged", s.converged)?;
    d.set_item("last_change", s.last_change)?;
    d.set_item("seconds", s.seconds)?;
    d.set_item("infinity", s.infinity)?;
    d.set_item("window_edge", s.window_edge)?;
    d.set_item(
        "thin_strip_iterations",
        (s.thin_strip_iterations[0], s.thin_strip_iterations[1]),
    )?;
    d.set_item("prefetch_iterations", s.prefetch_iterations)?;
    Ok(d)
}

/// The per-node outward directions (K, D), borrowed mutably from NumPy and overwritten with the
/// upwind weights of the extension update (Eq. (5)): the solve then needs no second K×D buffer.
pub(crate) fn extension_in_place<'a, const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    directions: &'a mut Option<PyReadwriteArray2<'_, f32>>,
    n: usize,
) -> PyResult<Extension<'a, D>> {
    match directions {
        Some(d) => {
            let flat = c_slice_mut(d, "directions")?;
            if flat.len() != n * D {
                return Err(PyValueError::new_err(format!("directions must have shape ({n}, {D})")));
            }
            // SAFETY: [f32; D] has the layout of D consecutive f32 and the alignment of f32.
            let v: &mut [[f32; D]] = unsafe { std::slice::from_raw_parts_mut(flat.as_mut_ptr() as *mut [f32; D], n) };
            extension_weights_in_place(band, roles, v);
            Ok(Extension::Weights(v))
        }
        None => Ok(Extension::None),
    }
}

/// The fixed nodes' values as the solver's starting vector: zero everywhere, `fixed.values[i]` at
/// band position `fixed.positions[i]` (the solver overwrites the non-fixed nodes with the numerical
/// infinity). One spare slot for the sentinel the solver appends, so that push does not reallocate.
pub(crate) fn starting_values(n: usize, fixed: &FixedNodes<'_>) -> PyResult<Vec<f64>> {
    check_fixed(n, fixed)?;
    let mut values = Vec::with_capacity(n + 1);
    values.resize(n, 0.0);
    for (&p, &v) in fixed.positions.iter().zip(fixed.values) {
        values[p as usize] = v;
    }
    Ok(values)
}

/// The fixed nodes are as many positions as values, each a position in the band of `n` nodes.
pub(crate) fn check_fixed(n: usize, fixed: &FixedNodes<'_>) -> PyResult<()> {
    if fixed.positions.len() != fixed.values.len() {
        return Err(PyValueError::new_err(format!(
            "fixed_positions and fixed_values must have the same length, got {} and {}",
            fixed.positions.len(),
            fixed.values.len()
        )));
    }
    if let Some(&p) = fixed.positions.iter().find(|&&p| p < 0 || p as usize >= n) {
        return Err(PyValueError::new_err(format!(
            "fixed_positions: {p} is not a position in the band of {n} nodes"
        )));
    }
    Ok(())
}

/// Everything the solve would reject, checked before `directions` is overwritten with the
/// extension weights: a call that fails leaves the caller's array as it was.
pub(crate) fn check_before_consuming(
    n: usize,
    spacing: f64,
    options: &SolveOptions,
    slowness_len: Option<usize>,
    fixed: &FixedNodes<'_>,
) -> PyResult<()> {
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "spacing must be positive and finite, got {spacing}"
        )));
    }
    if !(options.tol >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "tol must be non-negative, got {}",
            options.tol
        )));
    }
    if let Some(v) = options.infinity {
        if !(v.is_finite() && v > 0.0) {
            return Err(PyValueError::new_err(format!(
                "infinity must be positive and finite, got {v}"
            )));
        }
    }
    if let Some(len) = slowness_len {
        if len != n {
            return Err(PyValueError::new_err(format!(
                "speed: the slowness must have one entry per band node ({n}), got {len}"
            )));
        }
    }
    check_fixed(n, fixed)
}

/// The nodes fixed by the sources, given sparsely: band positions and their values.
pub(crate) struct FixedNodes<'s> {
    pub(crate) positions: &'s [i64],
    pub(crate) values: &'s [f64],
}

/// Runs `problem` with the GIL released; after every iteration re-acquires it to honour Ctrl-C
/// and call the Python progress callback. Returns the solution and the statistics dict.
pub(crate) fn run_sweeps<'py, const D: usize>(
    py: Python<'py>,
    problem: &SweepProblem<'_, D>,
    fixed: &FixedNodes<'_>,
    options: &SolveOptions,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
    let mut values = starting_values(problem.band.len(), fixed)?;
    let mut py_error: Option<PyErr> = None;
    let progress_ref = progress.as_ref().map(|p| p.clone().unbind());
    let result = py.detach(|| {
        let mut callback = |r: &IterationReport| -> Control {
            crate::progress::check_in(&progress_ref, &mut py_error, (r.iteration, r.max_change, r.updates))
        };
        problem.solve(&mut values, options, &mut callback)
    });
    if let Some(e) = py_error {
        return Err(e);
    }
    let stats = result.map_err(to_pyerr)?;
    Ok((values.into_pyarray(py), stats_dict(py, &stats)?))
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_generic<'py, const D: usize>(
    py: Python<'py>,
    band: &NarrowBand<D>,
    roles: &[u8],
    fixed: &FixedNodes<'_>,
    spacing: f64,
    slowness: &Bound<'py, PyAny>,
    mut directions: Option<PyReadwriteArray2<'py, f32>>,
    scheme: u8,
    missing: MissingNeighbour,
    options: SolveOptions,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
    let n = band.len();
    if roles.len() != n {
        return Err(PyValueError::new_err(format!(
            "roles must have one entry per band node ({n})"
        )));
    }
    let roles = node_roles(roles)?;
    let slowness_arr: Option<PyReadonlyArray1<'py, f64>>;
    let constant_slowness: Option<f64>;
    if let Ok(s) = slowness.extract::<f64>() {
        constant_slowness = Some(s);
        slowness_arr = None;
    } else {
        slowness_arr = Some(slowness.extract()?);
        constant_slowness = None;
    }
    let slow_slice = match &slowness_arr {
        Some(a) => Some(a.as_slice()?),
        None => None,
    };
    check_before_consuming(n, spacing, &options, slow_slice.map(|s| s.len()), fixed)?;
    let problem = SweepProblem {
        band,
        roles,
        spacing,
        slowness: match (constant_slowness, slow_slice) {
            (Some(s), _) => Slowness::Constant(s),
            (None, Some(s)) => Slowness::PerNode(s),
            (None, None) => Slowness::Constant(1.0),
        },
        extension: extension_in_place::<D>(band, roles, &mut directions, n)?,
        scheme: if scheme == 0 {
            InnerScheme::Godunov
        } else {
            InnerScheme::LaxFriedrichs
        },
        missing,
    };
    run_sweeps(py, &problem, fixed, &options, progress)
}

/// Per-node data of a built-in general Hamiltonian (Sect. 5.1), borrowed from NumPy arrays.
pub(crate) struct GeneralInputs<'s> {
    pub(crate) kind: String,
    pub(crate) slowness: &'s [f64],
    pub(crate) flow: Option<&'s [f64]>,
    pub(crate) metric: Option<&'s [f64]>,
    pub(crate) sigma: Option<&'s [f64]>,
}

/// Per axis, the largest over the band's nodes of the Hamiltonian's own viscosity `σ_k` (the exact
/// bound of `|∂H/∂p_k|` it uses without a user's `sigma`): the smallest constant `sigma` that keeps
/// the Lax–Friedrichs update monotone everywhere.
pub(crate) fn required_sigma<const D: usize>(
    inputs: &GeneralInputs<'_>,
    flow: &[[f64; D]],
    metric: &[[[f64; D]; D]],
    n: usize,
) -> [f64; D] {
    let ham: Box<dyn Hamiltonian<D> + '_> = match inputs.kind.as_str() {
        // a flow or metric missing or of the wrong length is refused after this, by the caller
        "moving_medium" if flow.len() == n => Box::new(MovingMedium {
            slowness: inputs.slowness,
            flow,
            sigma: None,
        }),
        "metric" if metric.len() == n => Box::new(Metric {
            slowness: inputs.slowness,
            metric,
            sigma: None,
        }),
        "moving_medium" | "metric" => return [0.0; D],
        _ => Box::new(Isotropic {
            slowness: inputs.slowness,
            sigma: None,
        }),
    };
    let mut needed = [0.0f64; D];
    for node in 0..n {
        let v = ham.viscosity(node);
        for k in 0..D {
            needed[k] = needed[k].max(v[k]);
        }
    }
    needed
}

/// Sweeps with the general Lax–Friedrichs update of Sect. 5.1 and a built-in Hamiltonian.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_general_generic<'py, const D: usize>(
    py: Python<'py>,
    band: &NarrowBand<D>,
    roles: &[u8],
    fixed: &FixedNodes<'_>,
    spacing: f64,
    inputs: GeneralInputs<'_>,
    mut directions: Option<PyReadwriteArray2<'py, f32>>,
    missing: MissingNeighbour,
    options: SolveOptions,
    progress: Option<Bound<'py, PyAny>>,
    upwind: bool,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
    let n = band.len();
    if roles.len() != n {
        return Err(PyValueError::new_err(format!(
            "roles must have one entry per band node ({n})"
        )));
    }
    if inputs.slowness.len() != n && inputs.slowness.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "slowness must have 1 or {n} entries, got {}",
            inputs.slowness.len()
        )));
    }
    if let Some(s) = inputs.sigma {
        if s.len() != D || !s.iter().all(|x| x.is_finite() && *x > 0.0) {
            return Err(PyValueError::new_err(format!(
                "sigma must hold {D} positive finite numbers"
            )));
        }
    }
    let roles = node_roles(roles)?;
    check_before_consuming(n, spacing, &options, None, fixed)?;
    let flow: &[[f64; D]] = match inputs.flow {
        Some(f) => node_vectors::<f64, D>(f, n, "flow")?,
        None => &[],
    };
    // M per node, or one for all nodes: the upwind solver packs its symmetric part (one matrix stays
    // one); the Lax–Friedrichs update reads it as given, per node, borrowed from NumPy (one matrix
    // repeated for all nodes)
    let metric: &[[[f64; D]; D]] = match inputs.metric {
        Some(m) => node_matrices::<D>(m, n, "metric")?,
        None => &[],
    };
    let lxf_metric: Cow<'_, [[[f64; D]; D]]> = if !upwind && metric.len() == 1 && n > 1 {
        Cow::Owned(vec![metric[0]; n])
    } else {
        Cow::Borrowed(metric)
    };
    // the smallest admissible constant viscosities: the default (exact) σ of every node, per axis
    // (reported back: a σ far above it adds viscosity, and error, in proportion)
    let mut sigma_needed: Option<[f64; D]> = None;
    if let Some(sig) = inputs.sigma {
        let needed = required_sigma::<D>(&inputs, flow, &lxf_metric, n);
        sigma_needed = Some(needed);
        // (a relative slack of 1e-6: the identity metric's bound reads 1.00000006 from its f32 copy,
        // and σ = 1, its exact bound, was refused)
        if let Some(k) = (0..D).find(|&k| sig[k] < needed[k] * (1.0 - 1e-6)) {
            return Err(PyValueError::new_err(format!(
                "sigma[{k}] = {} is below max |∂H/∂p_{k}| = {} over the band (Sect. 5.1): the Lax–Friedrichs update would \
                 not be monotone and the values would blow up; pass sigma of at least {:?}, or leave sigma out for the \
                 exact per-node bound",
                sig[k], needed[k], needed
            )));
        }
    }
    let iso;
    let mm;
    let met;
    let sym;
    // the upwind local solver of `tubesweep_core::scheme::upwind`, or the Lax–Friedrichs update of Sect. 5.1
    let scheme: InnerScheme<'_, D> = match inputs.kind.as_str() {
        "isotropic" => {
            iso = Isotropic {
                slowness: inputs.slowness,
                sigma: inputs.sigma,
            };
            if upwind {
                InnerScheme::Upwind(&iso)
            } else {
                InnerScheme::General(&iso)
            }
        }
        "moving_medium" => {
            if flow.is_empty() && n > 0 {
                return Err(PyValueError::new_err("hamiltonian 'moving_medium' needs flow (K, d)"));
            }
            mm = MovingMedium {
                slowness: inputs.slowness,
                flow,
                sigma: inputs.sigma,
            };
            if upwind {
                InnerScheme::Upwind(&mm)
            } else {
                InnerScheme::General(&mm)
            }
        }
        "metric" => {
            if metric.is_empty() && n > 0 {
                return Err(PyValueError::new_err("hamiltonian 'metric' needs metric (K, d, d)"));
            }
            if upwind {
                sym = SymmetricMetric::new(inputs.slowness, metric);
                InnerScheme::Upwind(&sym)
            } else {
                met = Metric {
                    slowness: inputs.slowness,
                    metric: &lxf_metric,
                    sigma: inputs.sigma,
                };
                InnerScheme::General(&met)
            }
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "hamiltonian: unknown built-in {other:?}; use 'isotropic', 'moving_medium' or 'metric'"
            )))
        }
    };
    // every input checked: now the directions may be overwritten with the extension weights
    let extension = extension_in_place::<D>(band, roles, &mut directions, n)?;
    let problem = SweepProblem {
        band,
        roles,
        spacing,
        slowness: Slowness::Constant(1.0), // unused by InnerScheme::General and ::Upwind
        extension,
        scheme,
        missing,
    };
    let (values, stats) = run_sweeps(py, &problem, fixed, &options, progress)?;
    if let Some(needed) = sigma_needed {
        stats.set_item("sigma_needed", needed.to_vec())?;
    }
    Ok((values, stats))
}

/// The bytes of the sweeps' arrays that the rows of an iteration must hold for the next
/// iteration to prefetch its rows: `SolveOptions::row_prefetch_above`'s default, a share of the
/// last-level cache (`tubesweep_core::sweep::default_row_prefetch_above`).
#[pyfunction]
pub(crate) fn row_prefetch_above() -> usize {
    default_row_prefetch_above()
}

/// Adds this file's classes and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(row_prefetch_above, m)?)?;
    Ok(())
}
