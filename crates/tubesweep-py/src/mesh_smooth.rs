//! The smooth closest-point map of a triangle mesh (`tubesweep_core::surface::mesh_smooth`),
//! the GIL released.

use crate::convert::*;
use crate::errors::to_pyerr;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tubesweep_core::surface::mesh_smooth::{Mode, SmoothMesh};

/// A mesh with its AABB tree, its samples' kd-tree and its boundary.
#[pyclass(module = "tubesweep._native", name = "SmoothMesh", frozen)]
pub(crate) struct PySmoothMesh {
    mesh: SmoothMesh,
}

#[pymethods]
impl PySmoothMesh {
    /// The mesh of `vertices` (n, 3) and non-degenerate `faces` (m, 3), fitted over `neighbours` samples (vertices, and
    /// points about `spacing` apart on the faces).
    #[new]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: PyReadonlyArray2<'_, i64>,
        neighbours: usize,
        spacing: f64,
    ) -> PyResult<Self> {
        if vertices.shape()[1] != 3 || faces.shape()[1] != 3 {
            return Err(PyValueError::new_err(
                "vertices and faces must have shape (n, 3) and (m, 3)",
            ));
        }
        let v: Vec<[f64; 3]> = c_slice(&vertices, "vertices")?
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let mut f = Vec::with_capacity(faces.shape()[0]);
        for t in c_slice(&faces, "faces")?.chunks_exact(3) {
            if t.iter().any(|&i| i < 0 || i as usize >= v.len()) {
                return Err(PyValueError::new_err(format!(
                    "faces: a vertex index out of range 0..{}",
                    v.len()
                )));
            }
            f.push([t[0] as u32, t[1] as u32, t[2] as u32]);
        }
        let mesh = py
            .detach(|| SmoothMesh::new(&v, &f, neighbours, spacing))
            .map_err(to_pyerr)?;
        Ok(PySmoothMesh { mesh })
    }

    /// Whether the mesh is consistently oriented.
    #[getter]
    fn oriented(&self) -> bool {
        self.mesh.oriented()
    }

    /// The number of boundary edges.
    #[getter]
    fn boundary_edges(&self) -> usize {
        self.mesh.boundary_edges()
    }

    /// Closest points (M, 3) of `points` for a grid of spacing `h` within `max_distance`, and per
    /// point the map that gave it (0 fit, 1 exact: fine mesh, 2 exact: near the boundary, 3 exact:
    /// the fit's fall-back, 4 none within `max_distance`: NaN). `mode`: "auto", "exact", "fitted".
    #[pyo3(signature = (points, h, max_distance = f64::INFINITY, mode = "auto"))]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        h: f64,
        max_distance: f64,
        mode: &str,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>)> {
        let mode = match mode {
            "auto" => Mode::Auto,
            "exact" => Mode::Exact,
            "fitted" => Mode::Fitted,
            _ => return Err(PyValueError::new_err("mode must be 'auto', 'exact' or 'fitted'")),
        };
        if !(h > 0.0 && h.is_finite()) {
            return Err(PyValueError::new_err("h must be a positive grid spacing"));
        }
        let x: Vec<[f64; 3]> = points_slice(&points, 3)?
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let (cp, kind) = py.detach(|| self.mesh.closest_points(&x, h, max_distance, mode));
        let m = cp.len();
        let cp: Vec<f64> = cp.into_iter().flatten().collect();
        let kind: Vec<u8> = kind.into_iter().map(|k| k as u8).collect();
        Ok((cp.into_pyarray(py).reshape([m, 3])?, kind.into_pyarray(py)))
    }
}

/// Adds this file's class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySmoothMesh>()
}
