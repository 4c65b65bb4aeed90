//! Finding a band without the whole box (`tubesweep_core::band::{discovery, sampled, normals}`):
//! the coarse-to-fine search's block bookkeeping, a φ sampled on the grid, outward directions by
//! central differences, and the whole search for an analytic surface evaluated in Rust.

use crate::band::*;
use crate::convert::*;
use crate::errors::to_pyerr;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArrayDyn, PyReadwriteArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tubesweep_core::band::NarrowBand;

/// The last split of the coarse-to-fine band search: the C-order linear indices (sorted) of the
/// nodes of the 2 × … × 2 blocks with lowest corners `origins` (M, d) (even grid indices, no
/// repeats, any order), cut to the grid of `shape`. See `tubesweep_core::band::discovery`.
#[pyfunction]
pub(crate) fn split_pair_blocks<'py>(
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

/// The largest `|last − o|` (grid spacings) over the children of blocks of `2·block` nodes per
/// axis with lowest corners `parents` (M, d). See `tubesweep_core::band::discovery::children_radius_max`.
#[pyfunction]
pub(crate) fn children_radius_max(
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

pub(crate) type Children<'py> = (
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The children (blocks of `block` nodes per axis) of the blocks of `2·block` with lowest corners
/// `parents` (M, d): `(origins (C, d) int64, centres (C, d), radii (C,))`, centres in world
/// coordinates. See `tubesweep_core::band::discovery::block_children`.
#[pyfunction]
pub(crate) fn block_children<'py>(
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
pub(crate) fn keep_within<'py>(
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
pub(crate) fn node_points<'py>(
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
pub(crate) fn neighbour_table<'py>(
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

/// The places where central differences of φ at band nodes `start..stop` need φ off the band:
/// `(positions, counts)`, the band positions for each group (axis k = 0, 1, …; side +1 then −1)
/// concatenated, and the size of each group (2·d). From `neighbours` (their `neighbour_table`)
/// when given. See `tubesweep_core::band::normals::rim_nodes`.
#[pyfunction]
#[pyo3(signature = (shape, linear, start, stop, neighbours=None))]
pub(crate) fn rim_nodes<'py>(
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
pub(crate) fn outward_directions<'py>(
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
pub(crate) fn first_non_finite(py: Python<'_>, phi: PyReadonlyArrayDyn<'_, f64>) -> PyResult<Option<usize>> {
    let s = c_slice(&phi, "phi")?;
    Ok(py.detach(|| tubesweep_core::band::sampled::first_non_finite(s)))
}

/// Sorted linear node indices and a value at each, as NumPy arrays.
pub(crate) type LinearAndValues<'py> = (Bound<'py, PyArray1<u64>>, Bound<'py, PyArray1<f64>>);

/// The band `|φ| ≤ half_width` of a φ sampled on the whole grid (`phi` has the grid's shape):
/// sorted C-order linear indices and φ there. See `tubesweep_core::band::sampled::band_of_samples`.
#[pyfunction]
pub(crate) fn band_of_samples<'py>(
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
pub(crate) fn outward_directions_of_samples<'py>(
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
pub(crate) fn max_gradient_norm_of_samples(
    py: Python<'_>,
    phi: PyReadonlyArrayDyn<'_, f64>,
    spacing: f64,
) -> PyResult<f64> {
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
pub(crate) fn redistance_candidates_of_samples<'py>(
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

/// The band, its structure and its outward directions, of a library surface whose φ is evaluated
/// in Rust.
pub(crate) type AnalyticBand<'py> = (
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
pub(crate) fn analytic_level_set_band<'py>(
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

/// Adds this file's classes and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(split_pair_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(children_radius_max, m)?)?;
    m.add_function(wrap_pyfunction!(block_children, m)?)?;
    m.add_function(wrap_pyfunction!(node_points, m)?)?;
    m.add_function(wrap_pyfunction!(keep_within, m)?)?;
    m.add_function(wrap_pyfunction!(first_non_finite, m)?)?;
    m.add_function(wrap_pyfunction!(band_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(outward_directions_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(max_gradient_norm_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(redistance_candidates_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(analytic_level_set_band, m)?)?;
    m.add_function(wrap_pyfunction!(neighbour_table, m)?)?;
    m.add_function(wrap_pyfunction!(rim_nodes, m)?)?;
    m.add_function(wrap_pyfunction!(outward_directions, m)?)?;
    Ok(())
}
