//! Thin PyO3 bindings of `tubesweep-core`: array conversion, releasing the GIL around solves,
//! progress and Ctrl-C, and error mapping (in `errors.rs`). All validation a user sees with a
//! helpful message happens in the Python package; the core re-checks what could break it.

mod box_order2;
mod errors;
mod many_sources;
mod second_order;

use errors::to_pyerr;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyReadonlyArrayDyn,
    PyReadwriteArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::scheme::hamiltonians::{Isotropic, Metric, MovingMedium};
use tubesweep_core::solution::interpolate::interpolate;
use tubesweep_core::solution::nearest_source::nearest_source_labels;
use tubesweep_core::sweep::{
    default_row_prefetch_above, extension_weights_in_place, Extension, MissingNeighbour, Slowness,
};
use tubesweep_core::{
    Control, Hamiltonian, InnerScheme, IterationReport, LocalSolver, NodeRole, SolveOptions, SolveStats, SweepProblem,
};

enum AnyBand {
    D2(NarrowBand<2>),
    D3(NarrowBand<3>),
}

/// A narrow band of grid nodes with its neighbour table (see `tubesweep_core::band`).
#[pyclass(module = "tubesweep._native", name = "Band", frozen)]
struct PyBand {
    band: AnyBand,
}

fn shape_array<const D: usize>(shape: &[usize]) -> PyResult<[usize; D]> {
    shape
        .try_into()
        .map_err(|_| PyValueError::new_err(format!("shape must have {D} entries")))
}

fn parse_scheme(name: &str) -> PyResult<u8> {
    match name {
        "godunov" => Ok(0),
        "lxf" => Ok(1),
        _ => Err(PyValueError::new_err(format!(
            "hamiltonian: unknown scheme {name:?}; use 'godunov' or 'lxf'"
        ))),
    }
}

fn parse_missing(name: &str) -> PyResult<MissingNeighbour> {
    match name {
        "infinity" => Ok(MissingNeighbour::Infinity),
        "extrapolate" => Ok(MissingNeighbour::Extrapolate),
        _ => Err(PyValueError::new_err(format!("missing: unknown policy {name:?}"))),
    }
}

fn stats_dict<'py>(py: Python<'py>, s: &SolveStats) -> PyResult<Bound<'py, PyDict>> {
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

/// The data of a C-ordered (row-major) NumPy array. `as_slice` also accepts Fortran order, whose
/// data would then be read with the axes swapped: that is an error here, naming the argument.
fn c_slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: &'a numpy::PyReadonlyArray<'_, T, D>,
    name: &str,
) -> PyResult<&'a [T]> {
    if !a.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{name} must be a C-ordered array; pass np.ascontiguousarray({name})"
        )));
    }
    Ok(a.as_slice()?)
}

/// [`c_slice`] for an array the solver writes.
fn c_slice_mut<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: &'a mut numpy::PyReadwriteArray<'_, T, D>,
    name: &str,
) -> PyResult<&'a mut [T]> {
    if !a.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{name} must be a C-ordered array; pass np.ascontiguousarray({name})"
        )));
    }
    Ok(a.as_slice_mut()?)
}

/// The points (M, `d`) of a query as a C-ordered slice; a wrong shape names the one it needs.
fn points_slice<'a>(points: &'a PyReadonlyArray2<'_, f64>, d: usize) -> PyResult<&'a [f64]> {
    if points.shape()[1] != d {
        return Err(PyValueError::new_err(format!(
            "points must have shape (M, {d}); got {:?}",
            points.shape()
        )));
    }
    c_slice(points, "points")
}

/// φ of a library surface at the points (M, `d`): one value per point, computed by `phi` (a
/// function of `tubesweep_core::surface::analytic`) without the GIL.
fn phi_at_points<'py>(
    py: Python<'py>,
    points: &PyReadonlyArray2<'py, f64>,
    d: usize,
    phi: impl FnOnce(&[f64], &mut [f64]) -> tubesweep_core::Result<()> + Send,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let p = points_slice(points, d)?;
    let mut out = vec![0.0; points.shape()[0]];
    py.detach(|| phi(p, &mut out)).map_err(to_pyerr)?;
    Ok(out.into_pyarray(py))
}

/// Node roles as the core's enum, without copying: validates that every byte is a role.
fn node_roles(roles: &[u8]) -> PyResult<&[NodeRole]> {
    if let Some(&bad) = roles.iter().find(|&&r| NodeRole::from_u8(r).is_none()) {
        return Err(PyValueError::new_err(format!("roles: invalid role {bad}")));
    }
    // SAFETY: NodeRole is #[repr(u8)] and every byte was just checked to be one of its values.
    Ok(unsafe { std::slice::from_raw_parts(roles.as_ptr() as *const NodeRole, roles.len()) })
}

/// A flat (n·D) array viewed as n D-vectors, without copying.
fn node_vectors<'a, T, const D: usize>(flat: &'a [T], n: usize, name: &str) -> PyResult<&'a [[T; D]]> {
    if flat.len() != n * D {
        return Err(PyValueError::new_err(format!("{name} must have shape ({n}, {D})")));
    }
    // SAFETY: [T; D] has the layout of D consecutive T and the alignment of T.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr() as *const [T; D], n) })
}

/// The per-node outward directions (K, D), borrowed mutably from NumPy and overwritten with the
/// upwind weights of the extension update (Eq. (5)): the solve then needs no second K×D buffer.
fn extension_in_place<'a, const D: usize>(
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
fn starting_values(n: usize, fixed: &FixedNodes<'_>) -> PyResult<Vec<f64>> {
    check_fixed(n, fixed)?;
    let mut values = Vec::with_capacity(n + 1);
    values.resize(n, 0.0);
    for (&p, &v) in fixed.positions.iter().zip(fixed.values) {
        values[p as usize] = v;
    }
    Ok(values)
}

/// The fixed nodes are as many positions as values, each a position in the band of `n` nodes.
fn check_fixed(n: usize, fixed: &FixedNodes<'_>) -> PyResult<()> {
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
fn check_before_consuming(
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
struct FixedNodes<'s> {
    positions: &'s [i64],
    values: &'s [f64],
}

/// Runs `problem` with the GIL released; after every iteration re-acquires it to honour Ctrl-C
/// and call the Python progress callback. Returns the solution and the statistics dict.
fn run_sweeps<'py, const D: usize>(
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
            Python::attach(|py| {
                if let Err(e) = py.check_signals() {
                    py_error = Some(e);
                    return Control::Stop;
                }
                if let Some(cb) = &progress_ref {
                    if let Err(e) = cb.call1(py, (r.iteration, r.max_change, r.updates)) {
                        py_error = Some(e);
                        return Control::Stop;
                    }
                }
                Control::Continue
            })
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
fn solve_generic<'py, const D: usize>(
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
struct GeneralInputs<'s> {
    kind: String,
    slowness: &'s [f64],
    flow: Option<&'s [f64]>,
    metric: Option<&'s [f64]>,
    sigma: Option<&'s [f64]>,
}

/// Per axis, the largest over the band's nodes of the Hamiltonian's own viscosity `σ_k` (the exact
/// bound of `|∂H/∂p_k|` it uses without a user's `sigma`): the smallest constant `sigma` that keeps
/// the Lax–Friedrichs update monotone everywhere.
fn required_sigma<const D: usize>(
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
fn solve_general_generic<'py, const D: usize>(
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
    let metric: Vec<[[f64; D]; D]> = match inputs.metric {
        Some(m) if m.len() == n * D * D => m
            .chunks_exact(D * D)
            .map(|c| core::array::from_fn(|i| core::array::from_fn(|j| c[i * D + j])))
            .collect(),
        Some(_) => return Err(PyValueError::new_err(format!("metric must have shape ({n}, {D}, {D})"))),
        None => Vec::new(),
    };
    // the smallest admissible constant viscosities: the default (exact) σ of every node, per axis
    if let Some(sig) = inputs.sigma {
        let needed = required_sigma::<D>(&inputs, flow, &metric, n);
        if let Some(k) = (0..D).find(|&k| sig[k] < needed[k]) {
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
    let (ham, solver): (&dyn Hamiltonian<D>, &dyn LocalSolver<D>) = match inputs.kind.as_str() {
        "isotropic" => {
            iso = Isotropic {
                slowness: inputs.slowness,
                sigma: inputs.sigma,
            };
            (&iso, &iso)
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
            (&mm, &mm)
        }
        "metric" => {
            if metric.is_empty() && n > 0 {
                return Err(PyValueError::new_err("hamiltonian 'metric' needs metric (K, d, d)"));
            }
            met = Metric {
                slowness: inputs.slowness,
                metric: &metric,
                sigma: inputs.sigma,
            };
            (&met, &met)
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
        // the upwind local solver of `tubesweep_core::upwind`, or the Lax–Friedrichs update of Sect. 5.1
        scheme: if upwind {
            InnerScheme::Upwind(solver)
        } else {
            InnerScheme::General(ham)
        },
        missing,
    };
    run_sweeps(py, &problem, fixed, &options, progress)
}

macro_rules! with_band {
    ($self:expr, $b:ident, $body:expr) => {
        match &$self.band {
            AnyBand::D2($b) => $body,
            AnyBand::D3($b) => $body,
        }
    };
}

#[pymethods]
impl PyBand {
    /// Band from sorted C-order linear node indices of a grid of `shape`.
    #[staticmethod]
    fn from_linear(py: Python<'_>, shape: Vec<usize>, linear: PyReadonlyArray1<'_, u64>) -> PyResult<Self> {
        let lin = linear.as_slice()?;
        let band = py
            .detach(|| match shape.len() {
                2 => NarrowBand::<2>::from_sorted_linear(shape[..].try_into().unwrap(), lin).map(AnyBand::D2),
                3 => NarrowBand::<3>::from_sorted_linear(shape[..].try_into().unwrap(), lin).map(AnyBand::D3),
                d => Err(tubesweep_core::Error::invalid(
                    "grid",
                    format!("only 2D and 3D grids are supported, got {d}D"),
                )),
            })
            .map_err(to_pyerr)?;
        Ok(PyBand { band })
    }

    /// The whole box as a band.
    #[staticmethod]
    fn full_box(py: Python<'_>, shape: Vec<usize>) -> PyResult<Self> {
        let band = py
            .detach(|| match shape.len() {
                2 => shape_array::<2>(&shape)
                    .ok()
                    .map(|s| NarrowBand::<2>::full_box(s).map(AnyBand::D2)),
                3 => shape_array::<3>(&shape)
                    .ok()
                    .map(|s| NarrowBand::<3>::full_box(s).map(AnyBand::D3)),
                _ => None,
            })
            .ok_or_else(|| PyValueError::new_err("grid: only 2D and 3D grids are supported"))?
            .map_err(to_pyerr)?;
        Ok(PyBand { band })
    }

    fn __len__(&self) -> usize {
        with_band!(self, b, b.len())
    }

    #[getter]
    fn ndim(&self) -> usize {
        match &self.band {
            AnyBand::D2(_) => 2,
            AnyBand::D3(_) => 3,
        }
    }

    #[getter]
    fn n_rows(&self) -> usize {
        with_band!(self, b, b.n_rows())
    }

    /// Bytes held by the band structure (nodes, rows, neighbour table, sweep orders).
    #[getter]
    fn nbytes(&self) -> usize {
        with_band!(self, b, b.heap_bytes())
    }

    /// C-order linear grid indices of the band nodes, shape (K,), in band order (increasing).
    fn linear<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let v: Vec<i64> = with_band!(self, b, b.linear_indices().into_iter().map(|x| x as i64).collect());
        v.into_pyarray(py)
    }

    /// Grid indices of the band nodes, shape (K, d), in band order.
    fn indices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let (flat, d): (Vec<i64>, usize) = with_band!(self, b, {
            let idx = b.indices();
            let d = idx.first().map(|i| i.len()).unwrap_or(self.ndim());
            (idx.iter().flat_map(|i| i.iter().map(|&c| c as i64)).collect(), d)
        });
        let k = flat.len() / d.max(1);
        Ok(numpy::ndarray::Array2::from_shape_vec((k, d), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?
            .into_pyarray(py))
    }

    /// Neighbour table, shape (K, d, 2): band position of the minus/plus neighbour along each
    /// axis, or K when that neighbour is not in the band.
    fn neighbours<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<i64>>> {
        let (flat, k, d): (Vec<i64>, usize, usize) = with_band!(self, b, {
            let d = self.ndim();
            let flat = (0..b.len())
                .flat_map(|n| b.neighbours_of(n).into_iter().flat_map(|p| [p[0] as i64, p[1] as i64]))
                .collect();
            (flat, b.len(), d)
        });
        Ok(numpy::ndarray::Array3::from_shape_vec((k, d, 2), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?
            .into_pyarray(py))
    }

    /// The places where central differences of φ at band nodes `start..stop` need φ off the
    /// band, as the module function `rim_nodes` gives them, read off this band's own neighbours
    /// (it must be the band of those linear indices). See
    /// `tubesweep_core::band::normals::rim_nodes_in_band`.
    fn rim_nodes<'py>(
        &self,
        py: Python<'py>,
        start: usize,
        stop: usize,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Vec<usize>)> {
        let (nodes, counts) = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::normals::rim_nodes_in_band(b, start..stop)
                )
            })
            .map_err(to_pyerr)?;
        let nodes: Vec<i64> = nodes.into_iter().map(|n| n as i64).collect();
        Ok((nodes.into_pyarray(py), counts))
    }

    /// The outward directions sgn(φ)∇φ/|∇φ| at band nodes `start..stop`, as the module function
    /// `outward_directions` computes them (the same bits), with the neighbours read off this
    /// band; `rim_phi` in the order of [`rim_nodes`](Self::rim_nodes). Returns |∇φ|. See
    /// `tubesweep_core::band::normals::outward_directions_in_band`.
    fn outward_directions<'py>(
        &self,
        py: Python<'py>,
        spacing: f64,
        phi: PyReadonlyArray1<'py, f64>,
        start: usize,
        stop: usize,
        rim_phi: PyReadonlyArray1<'py, f64>,
        mut direction: PyReadwriteArray2<'py, f32>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (ph, rim) = (phi.as_slice()?, rim_phi.as_slice()?);
        let dir = c_slice_mut(&mut direction, "direction")?;
        let norms = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::normals::outward_directions_in_band(b, spacing, ph, start..stop, rim, dir)
                )
            })
            .map_err(to_pyerr)?;
        Ok(norms.into_pyarray(py))
    }

    /// Band positions of grid indices (M, d); -1 where the node is not in the band.
    fn find<'py>(&self, py: Python<'py>, indices: PyReadonlyArray2<'py, i64>) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let d = self.ndim();
        if indices.shape()[1] != d {
            return Err(PyValueError::new_err(format!("indices must have shape (M, {d})")));
        }
        let s = c_slice(&indices, "indices")?;
        let out: Vec<i64> = with_band!(self, b, {
            s.chunks_exact(d)
                .map(|c| {
                    let idx = c.try_into().unwrap();
                    b.find(idx).map(|p| p as i64).unwrap_or(-1)
                })
                .collect()
        });
        Ok(out.into_pyarray(py))
    }

    /// Band positions of the selected nodes that lack an in-grid neighbour in the band.
    fn nodes_missing_neighbours<'py>(
        &self,
        py: Python<'py>,
        select: PyReadonlyArray1<'py, bool>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let sel = select.as_slice()?;
        if sel.len() != self.__len__() {
            return Err(PyValueError::new_err("select must have one entry per band node"));
        }
        let out: Vec<i64> = with_band!(
            self,
            b,
            b.nodes_missing_neighbours(sel).into_iter().map(|n| n as i64).collect()
        );
        Ok(out.into_pyarray(py))
    }

    /// The pairs of neighbouring band nodes that straddle a gap between two parts of the surface
    /// facing each other (see `tubesweep_core::band::facing_sheets`): `inner` per node, `phi` its
    /// signed or unsigned distance, `direction` (K, d) its outward direction. Returns the pairs'
    /// band positions and their gaps `|cp(a) − cp(b)|`.
    #[allow(clippy::type_complexity)]
    fn facing_sheet_pairs<'py>(
        &self,
        py: Python<'py>,
        inner: PyReadonlyArray1<'py, bool>,
        phi: PyReadonlyArray1<'py, f32>,
        direction: PyReadonlyArray2<'py, f32>,
        spacing: f64,
    ) -> PyResult<(
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let d = self.ndim();
        if direction.shape()[1] != d {
            return Err(PyValueError::new_err(format!("direction must have shape (K, {d})")));
        }
        let (inn, ph, dir) = (inner.as_slice()?, phi.as_slice()?, c_slice(&direction, "direction")?);
        let pairs = py
            .detach(|| match &self.band {
                AnyBand::D2(b) => tubesweep_core::band::facing_sheets::facing_sheet_pairs(b, inn, ph, dir, spacing),
                AnyBand::D3(b) => tubesweep_core::band::facing_sheets::facing_sheet_pairs(b, inn, ph, dir, spacing),
            })
            .map_err(to_pyerr)?;
        let node: Vec<i64> = pairs.iter().map(|p| p.node as i64).collect();
        let neighbour: Vec<i64> = pairs.iter().map(|p| p.neighbour as i64).collect();
        let gap: Vec<f64> = pairs.iter().map(|p| p.gap).collect();
        Ok((node.into_pyarray(py), neighbour.into_pyarray(py), gap.into_pyarray(py)))
    }

    /// Multilinear interpolation of `values` at `points` (M, d); NaN where the stencil leaves
    /// the band.
    fn interpolate<'py>(
        &self,
        py: Python<'py>,
        values: PyReadonlyArray1<'py, f64>,
        lower: Vec<f64>,
        spacing: f64,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.ndim();
        if points.shape()[1] != d || lower.len() != d {
            return Err(PyValueError::new_err(format!("points must have shape (M, {d})")));
        }
        let vals = values.as_slice()?;
        if vals.len() != self.__len__() {
            return Err(PyValueError::new_err("values must have one entry per band node"));
        }
        let pts = c_slice(&points, "points")?;
        let out = py.detach(|| match &self.band {
            AnyBand::D2(b) => interpolate(b, vals, [lower[0], lower[1]], spacing, pts),
            AnyBand::D3(b) => interpolate(b, vals, [lower[0], lower[1], lower[2]], spacing, pts),
        });
        Ok(out.into_pyarray(py))
    }

    /// The label of the source whose front reaches each band node first (see
    /// `tubesweep_core::solution::nearest_source`): `values` one per band node, the fixed nodes' band
    /// positions and the source each was fixed from; -1 where no front arrives.
    fn nearest_source_labels<'py>(
        &self,
        py: Python<'py>,
        values: PyReadonlyArray1<'py, f64>,
        fixed_positions: PyReadonlyArray1<'py, i64>,
        fixed_labels: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let vals = c_slice(&values, "values")?;
        let to_u32 = |a: &PyReadonlyArray1<'py, i64>, name: &str| -> PyResult<Vec<u32>> {
            c_slice(a, name)?
                .iter()
                .map(|&v| {
                    u32::try_from(v).map_err(|_| PyValueError::new_err(format!("{name}: {v} is not a valid index")))
                })
                .collect()
        };
        let fixed = to_u32(&fixed_positions, "fixed_positions")?;
        let labels = to_u32(&fixed_labels, "fixed_labels")?;
        let out = py
            .detach(|| match &self.band {
                AnyBand::D2(b) => nearest_source_labels(b, vals, &fixed, &labels),
                AnyBand::D3(b) => nearest_source_labels(b, vals, &fixed, &labels),
            })
            .map_err(to_pyerr)?;
        Ok(out.into_pyarray(py))
    }

    /// Runs the sweeps. See `tubesweep_core::sweep`. The fixed nodes (role 0) start from
    /// `fixed_values` at the band positions `fixed_positions` (both (F,); a fixed node not listed
    /// starts from 0).
    #[pyo3(signature = (roles, fixed_positions, fixed_values, spacing, slowness, directions, scheme, missing, tol, max_iterations, infinity, progress=None, threads=0, skip_inactive=true, activation_threshold=0.0, coupled=true, defer_outer_rim=true, front_window=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        roles: PyReadonlyArray1<'py, u8>,
        fixed_positions: PyReadonlyArray1<'py, i64>,
        fixed_values: PyReadonlyArray1<'py, f64>,
        spacing: f64,
        slowness: Bound<'py, PyAny>,
        directions: Option<PyReadwriteArray2<'py, f32>>,
        scheme: &str,
        missing: &str,
        tol: f64,
        max_iterations: usize,
        infinity: Option<f64>,
        progress: Option<Bound<'py, PyAny>>,
        threads: usize,
        skip_inactive: bool,
        activation_threshold: f64,
        coupled: bool,
        defer_outer_rim: bool,
        front_window: f64,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
        let scheme = parse_scheme(scheme)?;
        let missing = parse_missing(missing)?;
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
            threads,
            skip_inactive,
            activation_threshold,
            coupled,
            defer_outer_rim,
            front_window,
            spread_threads: true,
            row_prefetch_above: default_row_prefetch_above(),
        };
        let roles = roles.as_slice()?;
        let fixed = FixedNodes {
            positions: fixed_positions.as_slice()?,
            values: fixed_values.as_slice()?,
        };
        match &self.band {
            AnyBand::D2(b) => solve_generic(
                py, b, roles, &fixed, spacing, &slowness, directions, scheme, missing, options, progress,
            ),
            AnyBand::D3(b) => solve_generic(
                py, b, roles, &fixed, spacing, &slowness, directions, scheme, missing, options, progress,
            ),
        }
    }

    /// Runs the sweeps with the general Lax–Friedrichs update of Sect. 5.1 and a built-in
    /// Hamiltonian: `"isotropic"` (`|p| − s`), `"moving_medium"` (`|p| − s|1 − v·p|`, needs
    /// `flow` (K, d)) or `"metric"` (`sqrt(pᵀMp) − s`, needs `metric` (K, d, d)). `slowness` has
    /// 1 or K entries; `sigma` (d,) overrides the automatic per-node viscosities. Fixed nodes as in
    /// `solve`.
    #[pyo3(signature = (roles, fixed_positions, fixed_values, spacing, hamiltonian, slowness, directions, missing, tol, max_iterations, infinity, flow=None, metric=None, sigma=None, progress=None, threads=0, skip_inactive=true, activation_threshold=0.0, defer_outer_rim=true, scheme="lxf"))]
    #[allow(clippy::too_many_arguments)]
    fn solve_general<'py>(
        &self,
        py: Python<'py>,
        roles: PyReadonlyArray1<'py, u8>,
        fixed_positions: PyReadonlyArray1<'py, i64>,
        fixed_values: PyReadonlyArray1<'py, f64>,
        spacing: f64,
        hamiltonian: &str,
        slowness: PyReadonlyArray1<'py, f64>,
        directions: Option<PyReadwriteArray2<'py, f32>>,
        missing: &str,
        tol: f64,
        max_iterations: usize,
        infinity: Option<f64>,
        flow: Option<PyReadonlyArray2<'py, f64>>,
        metric: Option<PyReadonlyArray3<'py, f64>>,
        sigma: Option<PyReadonlyArray1<'py, f64>>,
        progress: Option<Bound<'py, PyAny>>,
        threads: usize,
        skip_inactive: bool,
        activation_threshold: f64,
        defer_outer_rim: bool,
        scheme: &str,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
        let missing = parse_missing(missing)?;
        if !(activation_threshold >= 0.0) {
            return Err(PyValueError::new_err("activation_threshold must be non-negative"));
        }
        let upwind = match scheme {
            "godunov" => true,
            "lxf" => false,
            other => {
                return Err(PyValueError::new_err(format!(
                    "scheme must be 'godunov' (upwind) or 'lxf'; got {other:?}"
                )))
            }
        };
        if upwind && sigma.is_some() {
            return Err(PyValueError::new_err(
                "sigma (the Lax–Friedrichs viscosities) does not apply to scheme='godunov'",
            ));
        }
        // the coupled update is the eikonal Godunov one's; the general Hamiltonians use their own
        let options = SolveOptions {
            tol,
            max_iterations,
            infinity,
            threads,
            skip_inactive,
            activation_threshold,
            coupled: false,
            defer_outer_rim,
            front_window: 0.0,
            spread_threads: true,
            row_prefetch_above: default_row_prefetch_above(),
        };
        let inputs = GeneralInputs {
            kind: hamiltonian.to_string(),
            slowness: slowness.as_slice()?,
            flow: match &flow {
                Some(f) => Some(c_slice(f, "flow")?),
                None => None,
            },
            metric: match &metric {
                Some(m) => Some(c_slice(m, "metric")?),
                None => None,
            },
            sigma: match &sigma {
                Some(s) => Some(s.as_slice()?),
                None => None,
            },
        };
        let roles = roles.as_slice()?;
        let fixed = FixedNodes {
            positions: fixed_positions.as_slice()?,
            values: fixed_values.as_slice()?,
        };
        match &self.band {
            AnyBand::D2(b) => solve_general_generic(
                py, b, roles, &fixed, spacing, inputs, directions, missing, options, progress, upwind,
            ),
            AnyBand::D3(b) => solve_general_generic(
                py, b, roles, &fixed, spacing, inputs, directions, missing, options, progress, upwind,
            ),
        }
    }
}

/// The compiled core of tubesweep. Use the `tubesweep` package, not this module.
/// Exact closest points on a triangle mesh (AABB tree, see `tubesweep_core::surface::mesh`).
#[pyclass(module = "tubesweep._native", name = "TriangleTree", frozen)]
struct PyTriangleTree {
    tree: tubesweep_core::surface::mesh::TriangleTree,
}

#[pymethods]
impl PyTriangleTree {
    /// Builds the tree over triangles `faces` (m, 3) of `vertices` (n, 3).
    #[new]
    fn new(vertices: PyReadonlyArray2<'_, f64>, faces: PyReadonlyArray2<'_, i64>) -> PyResult<Self> {
        if vertices.shape()[1] != 3 || faces.shape()[1] != 3 {
            return Err(PyValueError::new_err(
                "vertices and faces must have shape (n, 3) and (m, 3)",
            ));
        }
        let v = c_slice(&vertices, "vertices")?;
        let f = c_slice(&faces, "faces")?;
        let n = v.len() / 3;
        if f.is_empty() {
            return Err(PyValueError::new_err("faces is empty"));
        }
        let mut tris = Vec::with_capacity(f.len() / 3);
        for t in f.chunks_exact(3) {
            let mut tri = [[0.0; 3]; 3];
            for (k, &i) in t.iter().enumerate() {
                if i < 0 || i as usize >= n {
                    return Err(PyValueError::new_err(format!(
                        "faces: vertex index {i} out of range 0..{n}"
                    )));
                }
                let i = i as usize;
                tri[k] = [v[3 * i], v[3 * i + 1], v[3 * i + 2]];
            }
            tris.push(tri);
        }
        Ok(PyTriangleTree {
            tree: tubesweep_core::surface::mesh::TriangleTree::new(tris),
        })
    }

    fn __len__(&self) -> usize {
        self.tree.len()
    }

    #[getter]
    fn nbytes(&self) -> usize {
        self.tree.heap_bytes()
    }

    /// Whether some triangle lies within `thresholds[i]` of `points[i]` ((M, 3) and (M,)): the
    /// answer of `closest(points, inf)[0] <= thresholds` without finding the closest triangles.
    /// See `tubesweep_core::surface::mesh::TriangleTree::any_within_many`.
    fn any_within<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        thresholds: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        if points.shape()[1] != 3 || points.shape()[0] != thresholds.len() {
            return Err(PyValueError::new_err(
                "points must have shape (M, 3) and thresholds shape (M,)",
            ));
        }
        let (p, t) = (c_slice(&points, "points")?, c_slice(&thresholds, "thresholds")?);
        let found = py.detach(|| self.tree.any_within_many(p, t));
        Ok(found.into_pyarray(py))
    }

    /// The band among the candidate nodes `points` (M, 3): the positions of those within
    /// `half_width` of the mesh, their distances, signed distances (with `pseudo_normals`
    /// (T, 7, 3), else the distances) and extension directions (K, 3) float32, `face_normals`
    /// (T, 3) where a node lies within `on_surface` of the mesh. T is the tree's number of
    /// triangles. See `tubesweep_core::band::mesh_band`.
    #[allow(clippy::type_complexity)]
    fn band<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        half_width: f64,
        on_surface: f64,
        face_normals: PyReadonlyArray2<'py, f64>,
        pseudo_normals: Option<PyReadonlyArray3<'py, f64>>,
    ) -> PyResult<(
        Bound<'py, PyArray1<u32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f32>>,
    )> {
        let t = self.tree.len();
        if points.shape()[1] != 3 {
            return Err(PyValueError::new_err("points must have shape (M, 3)"));
        }
        if face_normals.shape() != [t, 3] {
            return Err(PyValueError::new_err(format!(
                "face_normals must have shape ({t}, 3), one per triangle of the tree"
            )));
        }
        if let Some(pn) = &pseudo_normals {
            if pn.shape() != [t, 7, 3] {
                return Err(PyValueError::new_err(format!(
                    "pseudo_normals must have shape ({t}, 7, 3)"
                )));
            }
        }
        let p = c_slice(&points, "points")?;
        let face: Vec<[f64; 3]> = c_slice(&face_normals, "face_normals")?
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let pseudo: Option<Vec<[[f64; 3]; 7]>> = match &pseudo_normals {
            Some(pn) => Some(
                pn.as_slice()
                    .map_err(|_| PyValueError::new_err("pseudo_normals must be C-contiguous"))?
                    .chunks_exact(21)
                    .map(|c| core::array::from_fn(|f| [c[3 * f], c[3 * f + 1], c[3 * f + 2]]))
                    .collect(),
            ),
            None => None,
        };
        let band = py
            .detach(|| {
                let normals = tubesweep_core::band::mesh_band::MeshNormals {
                    face: &face,
                    pseudo: pseudo.as_deref(),
                };
                tubesweep_core::band::mesh_band::mesh_band(&self.tree, p, half_width, on_surface, &normals)
            })
            .map_err(to_pyerr)?;
        let k = band.kept.len();
        let direction = numpy::ndarray::Array2::from_shape_vec((k, 3), band.direction)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok((
            band.kept.into_pyarray(py),
            band.distance.into_pyarray(py),
            band.signed.into_pyarray(py),
            direction.into_pyarray(py),
        ))
    }

    /// Closest points of `points` (M, 3) searched within `max_distance`: returns distance (M,)
    /// (inf where nothing is that close), closest point (M, 3), triangle (M,) (-1 where none) and
    /// feature code (M,) (0 face, 1-3 vertex a/b/c, 4 edge ab, 5 ac, 6 bc).
    #[allow(clippy::type_complexity)]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        max_distance: f64,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<u8>>,
    )> {
        if points.shape()[1] != 3 {
            return Err(PyValueError::new_err("points must have shape (M, 3)"));
        }
        let p = c_slice(&points, "points")?;
        let res = py.detach(|| self.tree.closest_many(p, max_distance));
        let m = res.len();
        let mut dist = Vec::with_capacity(m);
        let mut cp = Vec::with_capacity(3 * m);
        let mut tri = Vec::with_capacity(m);
        let mut feat = Vec::with_capacity(m);
        for r in res {
            match r {
                Some(c) => {
                    dist.push(c.distance);
                    cp.extend_from_slice(&c.point);
                    tri.push(c.triangle as i64);
                    feat.push(c.feature as u8);
                }
                None => {
                    dist.push(f64::INFINITY);
                    cp.extend_from_slice(&[f64::NAN; 3]);
                    tri.push(-1);
                    feat.push(0);
                }
            }
        }
        let cp =
            numpy::ndarray::Array2::from_shape_vec((m, 3), cp).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok((
            dist.into_pyarray(py),
            cp.into_pyarray(py),
            tri.into_pyarray(py),
            feat.into_pyarray(py),
        ))
    }
}

/// The last split of the coarse-to-fine band search: the C-order linear indices (sorted) of the
/// nodes of the 2 × … × 2 blocks with lowest corners `origins` (M, d) (even grid indices, no
/// repeats, any order), cut to the grid of `shape`. See `tubesweep_core::band::discovery`.
#[pyfunction]
fn split_pair_blocks<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    origins: PyReadonlyArray2<'py, i64>,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    let d = shape.len();
    if origins.shape()[1] != d {
        return Err(PyValueError::new_err(format!("origins must have shape (M, {d})")));
    }
    let flat = c_slice(&origins, "origins")?;
    if let Some(&bad) = flat.iter().find(|&&c| c < 0) {
        return Err(PyValueError::new_err(format!("origins: negative grid index {bad}")));
    }
    fn blocks<const D: usize>(flat: &[i64]) -> Vec<[u64; D]> {
        flat.chunks_exact(D)
            .map(|c| core::array::from_fn(|k| c[k] as u64))
            .collect()
    }
    let out = py
        .detach(|| match d {
            2 => tubesweep_core::band::discovery::split_pair_blocks::<2>(
                shape_array(&shape).unwrap(),
                &blocks::<2>(flat),
            ),
            3 => tubesweep_core::band::discovery::split_pair_blocks::<3>(
                shape_array(&shape).unwrap(),
                &blocks::<3>(flat),
            ),
            _ => Err(tubesweep_core::Error::invalid(
                "grid",
                format!("only 2D and 3D grids are supported, got {d}D"),
            )),
        })
        .map_err(to_pyerr)?;
    Ok(out.into_pyarray(py))
}

fn blocks_of<const D: usize>(flat: &[i64]) -> Vec<[u64; D]> {
    flat.chunks_exact(D)
        .map(|c| core::array::from_fn(|k| c[k] as u64))
        .collect()
}

/// Block origins (M, d) as a C-ordered int64 array with no negative entry.
fn block_origins<'a>(origins: &'a PyReadonlyArray2<'_, i64>, d: usize, name: &str) -> PyResult<&'a [i64]> {
    if origins.shape()[1] != d {
        return Err(PyValueError::new_err(format!("{name} must have shape (M, {d})")));
    }
    let flat = c_slice(origins, name)?;
    if let Some(&bad) = flat.iter().find(|&&c| c < 0) {
        return Err(PyValueError::new_err(format!("{name}: negative grid index {bad}")));
    }
    Ok(flat)
}

fn flat_2d<'py, T: numpy::Element, const D: usize>(
    py: Python<'py>,
    rows: Vec<[T; D]>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let m = rows.len();
    let flat: Vec<T> = rows.into_iter().flatten().collect();
    let a = numpy::ndarray::Array2::from_shape_vec((m, D), flat).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

fn coords_array<const D: usize>(v: &[f64], name: &str) -> PyResult<[f64; D]> {
    v.try_into()
        .map_err(|_| PyValueError::new_err(format!("{name} must have {D} entries")))
}

/// The largest `|last − o|` (grid spacings) over the children of blocks of `2·block` nodes per
/// axis with lowest corners `parents` (M, d). See `tubesweep_core::band::discovery::children_radius_max`.
#[pyfunction]
fn children_radius_max(
    py: Python<'_>,
    shape: Vec<usize>,
    parents: PyReadonlyArray2<'_, i64>,
    block: u64,
) -> PyResult<f64> {
    let flat = block_origins(&parents, shape.len(), "parents")?;
    py.detach(|| match shape.len() {
        2 => tubesweep_core::band::discovery::children_radius_max::<2>(
            shape_array(&shape).unwrap(),
            &blocks_of::<2>(flat),
            block,
        ),
        3 => tubesweep_core::band::discovery::children_radius_max::<3>(
            shape_array(&shape).unwrap(),
            &blocks_of::<3>(flat),
            block,
        ),
        d => Err(tubesweep_core::Error::invalid(
            "grid",
            format!("only 2D and 3D grids are supported, got {d}D"),
        )),
    })
    .map_err(to_pyerr)
}

type Children<'py> = (
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The children (blocks of `block` nodes per axis) of the blocks of `2·block` with lowest corners
/// `parents` (M, d): `(origins (C, d) int64, centres (C, d), radii (C,))`, centres in world
/// coordinates. See `tubesweep_core::band::discovery::block_children`.
#[pyfunction]
fn block_children<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    parents: PyReadonlyArray2<'py, i64>,
    block: u64,
    lower: Vec<f64>,
    spacing: f64,
) -> PyResult<Children<'py>> {
    let flat = block_origins(&parents, shape.len(), "parents")?;
    fn run<'py, const D: usize>(
        py: Python<'py>,
        shape: &[usize],
        flat: &[i64],
        block: u64,
        lower: &[f64],
        spacing: f64,
    ) -> PyResult<Children<'py>> {
        let (shape, lower) = (shape_array::<D>(shape)?, coords_array::<D>(lower, "lower")?);
        let (o, c, r) = py
            .detach(|| {
                tubesweep_core::band::discovery::block_children::<D>(
                    shape,
                    &blocks_of::<D>(flat),
                    block,
                    lower,
                    spacing,
                )
            })
            .map_err(to_pyerr)?;
        let o: Vec<[i64; D]> = o.into_iter().map(|b| b.map(|x| x as i64)).collect();
        Ok((flat_2d(py, o)?, flat_2d(py, c)?, r.into_pyarray(py)))
    }
    match shape.len() {
        2 => run::<2>(py, &shape, flat, block, &lower, spacing),
        3 => run::<3>(py, &shape, flat, block, &lower, spacing),
        d => Err(PyValueError::new_err(format!(
            "only 2D and 3D grids are supported, got {d}D"
        ))),
    }
}

/// Copies the candidates with |values| ≤ half_width to the fronts of `linear_out` and
/// `values_out` (C-contiguous, at least as long as the candidates) and returns their number. See
/// `tubesweep_core::band::discovery::keep_within`.
#[pyfunction]
fn keep_within<'py>(
    py: Python<'py>,
    linear: PyReadonlyArray1<'py, u64>,
    values: PyReadonlyArray1<'py, f64>,
    half_width: f64,
    mut linear_out: numpy::PyReadwriteArray1<'py, u64>,
    mut values_out: numpy::PyReadwriteArray1<'py, f64>,
) -> PyResult<usize> {
    let (lin, val) = (c_slice(&linear, "linear")?, c_slice(&values, "values")?);
    let (lo, vo) = (
        c_slice_mut(&mut linear_out, "linear_out")?,
        c_slice_mut(&mut values_out, "values_out")?,
    );
    py.detach(|| tubesweep_core::band::discovery::keep_within(lin, val, half_width, lo, vo))
        .map_err(to_pyerr)
}

/// World coordinates (M, d) of the nodes with C-order linear indices `linear` (the arithmetic of
/// `Grid.points`). See `tubesweep_core::band::discovery::node_points`.
#[pyfunction]
fn node_points<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    linear: PyReadonlyArray1<'py, u64>,
    lower: Vec<f64>,
    spacing: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let lin = c_slice(&linear, "linear")?;
    fn run<'py, const D: usize>(
        py: Python<'py>,
        shape: &[usize],
        lin: &[u64],
        lower: &[f64],
        spacing: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (shape, lower) = (shape_array::<D>(shape)?, coords_array::<D>(lower, "lower")?);
        let p = py
            .detach(|| tubesweep_core::band::discovery::node_points::<D>(shape, lin, lower, spacing))
            .map_err(to_pyerr)?;
        let a = numpy::ndarray::Array2::from_shape_vec((lin.len(), D), p)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }
    match shape.len() {
        2 => run::<2>(py, &shape, lin, &lower, spacing),
        3 => run::<3>(py, &shape, lin, &lower, spacing),
        d => Err(PyValueError::new_err(format!(
            "only 2D and 3D grids are supported, got {d}D"
        ))),
    }
}

/// The neighbour table of band nodes `start..stop`: (2·(d − 1), stop − start) int32, for each
/// group (axis k = 0, …, d − 2; side +1 then −1) the band position of each node's neighbour less
/// the node's, or −2^31 where φ there must be supplied (off the band or outside the grid). See
/// `tubesweep_core::band::normals::neighbour_table`.
#[pyfunction]
fn neighbour_table<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    linear: PyReadonlyArray1<'py, u64>,
    start: usize,
    stop: usize,
) -> PyResult<Bound<'py, PyArray2<i32>>> {
    let lin = linear.as_slice()?;
    let table = py
        .detach(|| tubesweep_core::band::normals::neighbour_table(&shape, lin, start..stop))
        .map_err(to_pyerr)?;
    let a = numpy::ndarray::Array2::from_shape_vec((2 * shape.len().saturating_sub(1), stop - start), table)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// `|x − c| − r` at the points (M, d) with d = len(centre) (2 or 3): the exact signed distance
/// to a circle or sphere. See `tubesweep_core::surface::analytic::sphere_signed_distance`.
#[pyfunction]
fn sphere_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    centre: Vec<f64>,
    radius: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    if points.shape()[1] != centre.len() {
        return Err(PyValueError::new_err(format!(
            "points must have shape (M, {}) like the centre; got {:?}",
            centre.len(),
            points.shape()
        )));
    }
    phi_at_points(py, &points, centre.len(), |p, out| {
        tubesweep_core::surface::analytic::sphere_signed_distance(p, &centre, radius, out)
    })
}

/// `hypot(hypot(q_x, q_y) − R, q_z) − r` with `q = x − c` at the points (M, 3): the exact signed
/// distance to a torus about the z axis. See `tubesweep_core::surface::analytic::torus_signed_distance`.
#[pyfunction]
fn torus_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    centre: Vec<f64>,
    major: f64,
    minor: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let c = coords_array::<3>(&centre, "centre")?;
    phi_at_points(py, &points, 3, |p, out| {
        tubesweep_core::surface::analytic::torus_signed_distance(p, c, major, minor, out)
    })
}

/// The exact signed distance to the ellipsoid with semi-axes `axes` about `centre` at the points
/// (M, 3). See `tubesweep_core::surface::analytic::ellipsoid_signed_distance`.
#[pyfunction]
fn ellipsoid_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    centre: Vec<f64>,
    axes: Vec<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (c, a) = (coords_array::<3>(&centre, "centre")?, coords_array::<3>(&axes, "axes")?);
    phi_at_points(py, &points, 3, |p, out| {
        tubesweep_core::surface::analytic::ellipsoid_signed_distance(p, c, a, out)
    })
}

/// The parameters (θ, s) of the closest point on the Möbius band (centre radius `r`, half-width
/// `w`) of the points (M, 3), at most `iterations` Newton steps per candidate. See
/// `tubesweep_core::surface::mobius::mobius_closest_parameters`.
#[pyfunction]
fn mobius_closest_parameters<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    r: f64,
    w: f64,
    iterations: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let p = points_slice(&points, 3)?;
    let m = points.shape()[0];
    let (mut theta, mut s) = (vec![0.0; m], vec![0.0; m]);
    py.detach(|| tubesweep_core::surface::mobius::mobius_closest_parameters(p, r, w, iterations, &mut theta, &mut s))
        .map_err(to_pyerr)?;
    Ok((theta.into_pyarray(py), s.into_pyarray(py)))
}

/// The closest points (M, 3) on one of the library's open surfaces (`kind`: "hemisphere" or
/// "disc" of radius `size`, "plane-patch" of half-side `size`) about `centre` of the points
/// (M, 3). See `tubesweep_core::surface::open_surfaces`.
#[pyfunction]
fn open_surface_closest_points<'py>(
    py: Python<'py>,
    kind: &str,
    points: PyReadonlyArray2<'py, f64>,
    centre: Vec<f64>,
    size: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    use tubesweep_core::surface::open_surfaces::{
        disc_closest_points, hemisphere_closest_points, plane_patch_closest_points,
    };
    let cp = match kind {
        "hemisphere" => hemisphere_closest_points,
        "disc" => disc_closest_points,
        "plane-patch" => plane_patch_closest_points,
        _ => {
            return Err(PyValueError::new_err(format!(
                "kind must be 'hemisphere', 'disc' or 'plane-patch'; got {kind:?}"
            )))
        }
    };
    let c = coords_array::<3>(&centre, "centre")?;
    let p = points_slice(&points, 3)?;
    let m = points.shape()[0];
    let mut out = vec![0.0; 3 * m];
    py.detach(|| cp(p, c, size, &mut out)).map_err(to_pyerr)?;
    use numpy::PyArrayMethods;
    numpy::PyArray1::from_vec(py, out).reshape([m, 3])
}

/// The exact signed distance to the rounded cube (half-side `half_size`, edges and corners rounded
/// to `radius`) about `centre` at the points (M, 3). See
/// `tubesweep_core::surface::analytic::rounded_cube_signed_distance`.
#[pyfunction]
fn rounded_cube_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    centre: Vec<f64>,
    half_size: f64,
    radius: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let c = coords_array::<3>(&centre, "centre")?;
    phi_at_points(py, &points, 3, |p, out| {
        tubesweep_core::surface::analytic::rounded_cube_signed_distance(p, c, half_size, radius, out)
    })
}

/// φ = min of the two torus distances of the double torus at the points (M, 3). See
/// `tubesweep_core::surface::analytic::double_torus_signed_distance`.
#[pyfunction]
fn double_torus_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    major: f64,
    minor: f64,
    offset: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    phi_at_points(py, &points, 3, |p, out| {
        tubesweep_core::surface::analytic::double_torus_signed_distance(p, major, minor, offset, out)
    })
}

/// The exact signed distance to the six-fold star r(θ) = r0 + eps sin²(3θ) at the points (M, 2).
/// See `tubesweep_core::surface::analytic::star_signed_distance`.
#[pyfunction]
fn star_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    r0: f64,
    eps: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    phi_at_points(py, &points, 2, |p, out| {
        tubesweep_core::surface::analytic::star_signed_distance(p, r0, eps, out)
    })
}

fn table_slice<'a>(table: &'a Option<PyReadonlyArray2<'_, i32>>) -> PyResult<Option<&'a [i32]>> {
    table.as_ref().map(|t| c_slice(t, "neighbours")).transpose()
}

/// The places where central differences of φ at band nodes `start..stop` need φ off the band:
/// `(positions, counts)`, the band positions for each group (axis k = 0, 1, …; side +1 then −1)
/// concatenated, and the size of each group (2·d). From `neighbours` (their `neighbour_table`)
/// when given. See `tubesweep_core::band::normals::rim_nodes`.
#[pyfunction]
#[pyo3(signature = (shape, linear, start, stop, neighbours=None))]
fn rim_nodes<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    linear: PyReadonlyArray1<'py, u64>,
    start: usize,
    stop: usize,
    neighbours: Option<PyReadonlyArray2<'py, i32>>,
) -> PyResult<(Bound<'py, PyArray1<i64>>, Vec<usize>)> {
    let lin = linear.as_slice()?;
    let table = table_slice(&neighbours)?;
    let (nodes, counts) = py
        .detach(|| match table {
            Some(t) => tubesweep_core::band::normals::rim_nodes_of(&shape, lin, start..stop, t),
            None => tubesweep_core::band::normals::rim_nodes(&shape, lin, start..stop),
        })
        .map_err(to_pyerr)?;
    let nodes: Vec<i64> = nodes.into_iter().map(|n| n as i64).collect();
    Ok((nodes.into_pyarray(py), counts))
}

/// The outward directions sgn(φ)∇φ/|∇φ| at band nodes `start..stop` by central differences,
/// written to `direction` ((stop − start, d) float32, C-contiguous); φ at band nodes from `phi`,
/// off the band from `rim_phi` (in the order of `rim_nodes`); the neighbours from `neighbours`
/// (their `neighbour_table`) when given. Returns |∇φ| there. See
/// `tubesweep_core::band::normals::outward_directions`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (shape, spacing, linear, phi, start, stop, rim_phi, direction, neighbours=None))]
fn outward_directions<'py>(
    py: Python<'py>,
    shape: Vec<usize>,
    spacing: f64,
    linear: PyReadonlyArray1<'py, u64>,
    phi: PyReadonlyArray1<'py, f64>,
    start: usize,
    stop: usize,
    rim_phi: PyReadonlyArray1<'py, f64>,
    mut direction: PyReadwriteArray2<'py, f32>,
    neighbours: Option<PyReadonlyArray2<'py, i32>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (lin, ph, rim) = (linear.as_slice()?, phi.as_slice()?, rim_phi.as_slice()?);
    let table = table_slice(&neighbours)?;
    let dir = c_slice_mut(&mut direction, "direction")?;
    let norms = py
        .detach(|| match table {
            Some(t) => tubesweep_core::band::normals::outward_directions_with(
                &shape,
                spacing,
                lin,
                ph,
                start..stop,
                t,
                rim,
                dir,
            ),
            None => tubesweep_core::band::normals::outward_directions(&shape, spacing, lin, ph, start..stop, rim, dir),
        })
        .map_err(to_pyerr)?;
    Ok(norms.into_pyarray(py))
}

/// The position (in C order) of the first NaN or infinite sample of `phi`, or None. See
/// `tubesweep_core::band::sampled::first_non_finite`.
#[pyfunction]
fn first_non_finite(py: Python<'_>, phi: PyReadonlyArrayDyn<'_, f64>) -> PyResult<Option<usize>> {
    let s = c_slice(&phi, "phi")?;
    Ok(py.detach(|| tubesweep_core::band::sampled::first_non_finite(s)))
}

/// Sorted linear node indices and a value at each, as NumPy arrays.
type LinearAndValues<'py> = (Bound<'py, PyArray1<u64>>, Bound<'py, PyArray1<f64>>);

/// The band `|φ| ≤ half_width` of a φ sampled on the whole grid (`phi` has the grid's shape):
/// sorted C-order linear indices and φ there. See `tubesweep_core::band::sampled::band_of_samples`.
#[pyfunction]
fn band_of_samples<'py>(
    py: Python<'py>,
    phi: PyReadonlyArrayDyn<'py, f64>,
    half_width: f64,
) -> PyResult<LinearAndValues<'py>> {
    let shape = phi.shape().to_vec();
    let s = c_slice(&phi, "phi")?;
    let (linear, values) = py
        .detach(|| tubesweep_core::band::sampled::band_of_samples(&shape, s, half_width))
        .map_err(to_pyerr)?;
    Ok((linear.into_pyarray(py), values.into_pyarray(py)))
}

/// The outward directions sgn(φ)∇φ/|∇φ| of a φ sampled on the whole grid at the band nodes
/// `linear`, written to `direction` ((len(linear), d) float32, C-contiguous); returns |∇φ|. See
/// `tubesweep_core::band::sampled::outward_directions_of_samples`.
#[pyfunction]
fn outward_directions_of_samples<'py>(
    py: Python<'py>,
    phi: PyReadonlyArrayDyn<'py, f64>,
    spacing: f64,
    linear: PyReadonlyArray1<'py, u64>,
    mut direction: PyReadwriteArray2<'py, f32>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let shape = phi.shape().to_vec();
    let (s, lin) = (c_slice(&phi, "phi")?, c_slice(&linear, "linear")?);
    let dir = c_slice_mut(&mut direction, "direction")?;
    let norms = py
        .detach(|| tubesweep_core::band::sampled::outward_directions_of_samples(&shape, spacing, s, lin, dir))
        .map_err(to_pyerr)?;
    Ok(norms.into_pyarray(py))
}

/// The largest |∇φ| over the nodes of a φ sampled on the whole grid (the differences of
/// `numpy.gradient`). See `tubesweep_core::band::sampled::max_gradient_norm_of_samples`.
#[pyfunction]
fn max_gradient_norm_of_samples(py: Python<'_>, phi: PyReadonlyArrayDyn<'_, f64>, spacing: f64) -> PyResult<f64> {
    let shape = phi.shape().to_vec();
    let s = c_slice(&phi, "phi")?;
    py.detach(|| tubesweep_core::band::sampled::max_gradient_norm_of_samples(&shape, spacing, s))
        .map_err(to_pyerr)
}

/// The candidates for the re-distanced band of a φ sampled on the whole grid: the nodes with
/// `|φ| ≤ half_width · G`, `G` a bound on the gradient of φ's interpolant within reach of the
/// node (sorted C-order linear indices and φ there). See
/// `tubesweep_core::band::sampled::redistance_candidates_of_samples`.
#[pyfunction]
fn redistance_candidates_of_samples<'py>(
    py: Python<'py>,
    phi: PyReadonlyArrayDyn<'py, f64>,
    spacing: f64,
    half_width: f64,
) -> PyResult<LinearAndValues<'py>> {
    let shape = phi.shape().to_vec();
    let s = c_slice(&phi, "phi")?;
    let (linear, values) = py
        .detach(|| tubesweep_core::band::sampled::redistance_candidates_of_samples(&shape, spacing, s, half_width))
        .map_err(to_pyerr)?;
    Ok((linear.into_pyarray(py), values.into_pyarray(py)))
}

/// Closest points, signed distances and convergence flags.
type ProjectionArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
);

/// Closest points of `points` (M, d) on the zero level set of the multilinear interpolant of a
/// φ sampled on the whole grid (`phi` has the grid's shape; `lower` and `spacing` place it):
/// Newton projection and orthogonality iterations, the algorithm of `tubesweep.redistance`.
/// Returns (closest points (M, d), signed distances (M,), converged (M,)). See
/// `tubesweep_core::surface::redistance::project_to_zero_level_set`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn project_to_sampled_level_set<'py>(
    py: Python<'py>,
    phi: PyReadonlyArrayDyn<'py, f64>,
    lower: Vec<f64>,
    spacing: f64,
    points: PyReadonlyArray2<'py, f64>,
    eps: f64,
    newton_steps: usize,
    orthogonality_steps: usize,
    tol: f64,
) -> PyResult<ProjectionArrays<'py>> {
    use tubesweep_core::surface::redistance::{project_to_zero_level_set, ProjectionOptions, SampledField};
    let shape = phi.shape().to_vec();
    let d = shape.len();
    if points.shape()[1] != d {
        return Err(PyValueError::new_err(format!(
            "points must have shape (M, {d}) like the grid; got {:?}",
            points.shape()
        )));
    }
    let (s, p) = (c_slice(&phi, "phi")?, c_slice(&points, "points")?);
    let options = ProjectionOptions {
        eps,
        newton_steps,
        orthogonality_steps,
        tol,
    };
    fn run<const D: usize>(
        s: &[f64],
        shape: &[usize],
        lower: &[f64],
        spacing: f64,
        p: &[f64],
        options: ProjectionOptions,
    ) -> PyResult<tubesweep_core::surface::redistance::Projection> {
        let field = SampledField::<D>::new(s, shape_array::<D>(shape)?, coords_array::<D>(lower, "lower")?, spacing)
            .map_err(to_pyerr)?;
        project_to_zero_level_set(&field, p, options).map_err(to_pyerr)
    }
    let out = py.detach(|| match d {
        2 => run::<2>(s, &shape, &lower, spacing, p, options),
        3 => run::<3>(s, &shape, &lower, spacing, p, options),
        _ => Err(PyValueError::new_err(format!(
            "only 2D and 3D grids are supported, got {d}D"
        ))),
    })?;
    let m = out.signed.len();
    let closest = numpy::ndarray::Array2::from_shape_vec((m, d), out.closest)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((
        closest.into_pyarray(py),
        out.signed.into_pyarray(py),
        out.converged.into_pyarray(py),
    ))
}

/// The band, its structure and its outward directions, of a library surface whose φ is evaluated
/// in Rust.
type AnalyticBand<'py> = (
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<f64>>,
    Option<PyBand>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<f32>>,
);

/// The band of a library surface with a Rust φ (`kind` "sphere", "torus", "ellipsoid", "star",
/// "rounded-cube" or "double-torus", `parameters` as `tubesweep_core::surface::analytic::AnalyticSurface::from_parameters` takes
/// them), without calling back into Python: the coarse-to-fine search
/// (`tubesweep_core::band::discovery::discover_band`), the band structure, φ at its rim and the
/// outward directions, the same nodes and bits as the callable route. Returns (sorted linear
/// indices, φ there, the band or None when empty, directions (K, d) float32, |∇φ| (K,) float32).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn analytic_level_set_band<'py>(
    py: Python<'py>,
    kind: &str,
    parameters: Vec<f64>,
    shape: Vec<usize>,
    lower: Vec<f64>,
    spacing: f64,
    half_width: f64,
    lipschitz: f64,
) -> PyResult<AnalyticBand<'py>> {
    use tubesweep_core::surface::analytic::AnalyticSurface;
    let surface = AnalyticSurface::from_parameters(kind, &parameters).map_err(to_pyerr)?;
    if surface.ndim() != shape.len() {
        return Err(PyValueError::new_err(format!(
            "surface: a {kind} in {}D on a {}D grid",
            surface.ndim(),
            shape.len()
        )));
    }
    type Found = (Vec<u64>, Vec<f64>, Option<AnyBand>, Vec<f32>, Vec<f32>);
    #[allow(clippy::too_many_arguments)]
    fn run<const D: usize>(
        surface: &AnalyticSurface,
        shape: &[usize],
        lower: &[f64],
        spacing: f64,
        half_width: f64,
        lipschitz: f64,
        wrap: fn(NarrowBand<D>) -> AnyBand,
    ) -> PyResult<Found> {
        let (shape, lower) = (shape_array::<D>(shape)?, coords_array::<D>(lower, "lower")?);
        let phi = |p: &[f64], out: &mut [f64]| surface.signed_distance(p, out);
        let (linear, values) =
            tubesweep_core::band::discovery::discover_band::<D>(shape, lower, spacing, half_width, lipschitz, &phi)
                .map_err(to_pyerr)?;
        if linear.is_empty() {
            return Ok((linear, values, None, Vec::new(), Vec::new()));
        }
        let band = NarrowBand::<D>::from_sorted_linear(shape, &linear).map_err(to_pyerr)?;
        let mut direction = vec![0.0f32; linear.len() * D];
        let norms = tubesweep_core::band::normals::outward_directions_of_function_in_band(
            &band,
            &linear,
            &values,
            lower,
            spacing,
            &phi,
            &mut direction,
        )
        .map_err(to_pyerr)?;
        Ok((linear, values, Some(wrap(band)), direction, norms))
    }
    let (linear, values, band, direction, norms) = py.detach(|| match shape.len() {
        2 => run::<2>(&surface, &shape, &lower, spacing, half_width, lipschitz, AnyBand::D2),
        3 => run::<3>(&surface, &shape, &lower, spacing, half_width, lipschitz, AnyBand::D3),
        d => Err(PyValueError::new_err(format!(
            "only 2D and 3D grids are supported, got {d}D"
        ))),
    })?;
    let d = shape.len();
    let direction = numpy::ndarray::Array2::from_shape_vec((linear.len(), d), direction)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((
        linear.into_pyarray(py),
        values.into_pyarray(py),
        band.map(|band| PyBand { band }),
        direction.into_pyarray(py),
        norms.into_pyarray(py),
    ))
}

/// The bytes of the sweeps' arrays that the rows of an iteration must hold for the next
/// iteration to prefetch its rows: `SolveOptions::row_prefetch_above`'s default, a share of the
/// last-level cache (`tubesweep_core::sweep::default_row_prefetch_above`).
#[pyfunction]
fn row_prefetch_above() -> usize {
    default_row_prefetch_above()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBand>()?;
    m.add_class::<PyTriangleTree>()?;
    many_sources::register(m)?;
    box_order2::register(m)?;
    m.add_function(wrap_pyfunction!(split_pair_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(children_radius_max, m)?)?;
    m.add_function(wrap_pyfunction!(block_children, m)?)?;
    m.add_function(wrap_pyfunction!(node_points, m)?)?;
    m.add_function(wrap_pyfunction!(keep_within, m)?)?;
    m.add_function(wrap_pyfunction!(row_prefetch_above, m)?)?;
    m.add_function(wrap_pyfunction!(first_non_finite, m)?)?;
    m.add_function(wrap_pyfunction!(band_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(outward_directions_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(max_gradient_norm_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(redistance_candidates_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(project_to_sampled_level_set, m)?)?;
    m.add_function(wrap_pyfunction!(analytic_level_set_band, m)?)?;
    m.add_function(wrap_pyfunction!(neighbour_table, m)?)?;
    m.add_function(wrap_pyfunction!(rim_nodes, m)?)?;
    m.add_function(wrap_pyfunction!(outward_directions, m)?)?;
    m.add_function(wrap_pyfunction!(sphere_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(torus_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(ellipsoid_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(rounded_cube_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(double_torus_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(mobius_closest_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(open_surface_closest_points, m)?)?;
    m.add_function(wrap_pyfunction!(star_signed_distance, m)?)?;
    second_order::register(m)?;
    m.add("DEFAULT_INFINITY", tubesweep_core::DEFAULT_INFINITY)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
