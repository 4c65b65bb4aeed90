//! NumPy arrays to and from the core's slices, without copies where the layout allows; a wrong
//! shape or order is a `ValueError` naming the argument.

use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tubesweep_core::NodeRole;

pub(crate) fn shape_array<const D: usize>(shape: &[usize]) -> PyResult<[usize; D]> {
    shape
        .try_into()
        .map_err(|_| PyValueError::new_err(format!("shape must have {D} entries")))
}

/// The data of a C-ordered (row-major) NumPy array. `as_slice` also accepts Fortran order, whose
/// data would then be read with the axes swapped: that is an error here, naming the argument.
pub(crate) fn c_slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
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
pub(crate) fn c_slice_mut<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
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
pub(crate) fn points_slice<'a>(points: &'a PyReadonlyArray2<'_, f64>, d: usize) -> PyResult<&'a [f64]> {
    if points.shape()[1] != d {
        return Err(PyValueError::new_err(format!(
            "points must have shape (M, {d}); got {:?}",
            points.shape()
        )));
    }
    c_slice(points, "points")
}

/// Node roles as the core's enum, without copying: validates that every byte is a role.
pub(crate) fn node_roles(roles: &[u8]) -> PyResult<&[NodeRole]> {
    if let Some(&bad) = roles.iter().find(|&&r| NodeRole::from_u8(r).is_none()) {
        return Err(PyValueError::new_err(format!("roles: invalid role {bad}")));
    }
    // SAFETY: NodeRole is #[repr(u8)] and every byte was just checked to be one of its values.
    Ok(unsafe { std::slice::from_raw_parts(roles.as_ptr() as *const NodeRole, roles.len()) })
}

/// A flat (n·D) array viewed as n D-vectors, without copying.
pub(crate) fn node_vectors<'a, T, const D: usize>(flat: &'a [T], n: usize, name: &str) -> PyResult<&'a [[T; D]]> {
    if flat.len() != n * D {
        return Err(PyValueError::new_err(format!("{name} must have shape ({n}, {D})")));
    }
    // SAFETY: [T; D] has the layout of D consecutive T and the alignment of T.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr() as *const [T; D], n) })
}

/// A flat (K·D·D) row-major array viewed as K D×D matrices, without copying: K = n (one per band
/// node) or K = 1 (one for all nodes).
pub(crate) fn node_matrices<'a, const D: usize>(
    flat: &'a [f64],
    n: usize,
    name: &str,
) -> PyResult<&'a [[[f64; D]; D]]> {
    if flat.len() != n * D * D && flat.len() != D * D {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({n}, {D}, {D}) (one matrix per band node) or (1, {D}, {D}) (one for all)"
        )));
    }
    // SAFETY: [[f64; D]; D] has the layout of D·D consecutive f64 and the alignment of f64.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr() as *const [[f64; D]; D], flat.len() / (D * D)) })
}

pub(crate) fn flat_2d<'py, T: numpy::Element, const D: usize>(
    py: Python<'py>,
    rows: Vec<[T; D]>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let m = rows.len();
    let flat: Vec<T> = rows.into_iter().flatten().collect();
    let a = numpy::ndarray::Array2::from_shape_vec((m, D), flat).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

pub(crate) fn coords_array<const D: usize>(v: &[f64], name: &str) -> PyResult<[f64; D]> {
    v.try_into()
        .map_err(|_| PyValueError::new_err(format!("{name} must have {D} entries")))
}

/// Block origins (M, d) as a C-ordered int64 array with no negative entry.
pub(crate) fn block_origins<'a>(origins: &'a PyReadonlyArray2<'_, i64>, d: usize, name: &str) -> PyResult<&'a [i64]> {
    if origins.shape()[1] != d {
        return Err(PyValueError::new_err(format!("{name} must have shape (M, {d})")));
    }
    let flat = c_slice(origins, name)?;
    if let Some(&bad) = flat.iter().find(|&&c| c < 0) {
        return Err(PyValueError::new_err(format!("{name}: negative grid index {bad}")));
    }
    Ok(flat)
}

pub(crate) fn blocks_of<const D: usize>(flat: &[i64]) -> Vec<[u64; D]> {
    flat.chunks_exact(D)
        .map(|c| core::array::from_fn(|k| c[k] as u64))
        .collect()
}

pub(crate) fn table_slice<'a>(table: &'a Option<PyReadonlyArray2<'_, i32>>) -> PyResult<Option<&'a [i32]>> {
    table.as_ref().map(|t| c_slice(t, "neighbours")).transpose()
}
