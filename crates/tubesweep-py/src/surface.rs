//! Surfaces evaluated in Rust (`tubesweep_core::surface`): the analytic signed distances, closest
//! points on triangle meshes (`TriangleTree`), the Möbius band and the open surfaces, and on the
//! zero level set of a sampled φ.

use crate::convert::*;
use crate::errors::to_pyerr;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Exact closest points on a triangle mesh (AABB tree, see `tubesweep_core::surface::mesh`).
#[pyclass(module = "tubesweep._native", name = "TriangleTree", frozen)]
pub(crate) struct PyTriangleTree {
    pub(crate) tree: tubesweep_core::surface::mesh::TriangleTree,
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

/// φ of a library surface at the points (M, `d`): one value per point, computed by `phi` (a
/// function of `tubesweep_core::surface::analytic`) without the GIL.
pub(crate) fn phi_at_points<'py>(
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

/// `|x − c| − r` at the points (M, d) with d = len(centre) (2 or 3): the exact signed distance
/// to a circle or sphere. See `tubesweep_core::surface::analytic::sphere_signed_distance`.
#[pyfunction]
pub(crate) fn sphere_signed_distance<'py>(
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
pub(crate) fn torus_signed_distance<'py>(
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
pub(crate) fn ellipsoid_signed_distance<'py>(
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

/// The exact signed distance to the rounded cube (half-side `half_size`, edges and corners rounded
/// to `radius`) about `centre` at the points (M, 3). See
/// `tubesweep_core::surface::analytic::rounded_cube_signed_distance`.
#[pyfunction]
pub(crate) fn rounded_cube_signed_distance<'py>(
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
pub(crate) fn double_torus_signed_distance<'py>(
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
pub(crate) fn star_signed_distance<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    r0: f64,
    eps: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    phi_at_points(py, &points, 2, |p, out| {
        tubesweep_core::surface::analytic::star_signed_distance(p, r0, eps, out)
    })
}

/// The parameters (θ, s) of the closest point on the Möbius band (centre radius `r`, half-width
/// `w`) of the points (M, 3), at most `iterations` Newton steps per candidate. See
/// `tubesweep_core::surface::mobius::mobius_closest_parameters`.
#[pyfunction]
pub(crate) fn mobius_closest_parameters<'py>(
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
pub(crate) fn open_surface_closest_points<'py>(
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

/// Closest points, signed distances and convergence flags.
pub(crate) type ProjectionArrays<'py> = (
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
pub(crate) fn project_to_sampled_level_set<'py>(
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

/// The re-distanced band of a φ sampled on the whole grid, from any φ whose zero level set
/// crosses the grid (a mask, plateaus, φ far from a distance): sub-cell interface points on the
/// crossed cells' edges, closest points carried layer by layer and refined on the multilinear
/// interpolant (`tubesweep_core::surface::redistance_band`). Returns (linear indices (M,) uint64,
/// signed distances (M,), directions (M, d) float32, crossed cells, unsettled nodes, medial nodes).
#[pyfunction]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub(crate) fn redistanced_band_of_samples<'py>(
    py: Python<'py>,
    phi: PyReadonlyArrayDyn<'py, f64>,
    lower: Vec<f64>,
    spacing: f64,
    half_width: f64,
    eps: f64,
    max_steps: usize,
    tol: f64,
) -> PyResult<(
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f32>>,
    usize,
    usize,
    usize,
)> {
    use tubesweep_core::surface::redistance::SampledField;
    use tubesweep_core::surface::redistance_band::{
        redistanced_band_of_samples as band_of, RedistanceOptions, RedistancedBand,
    };
    let shape = phi.shape().to_vec();
    let d = shape.len();
    let s = c_slice(&phi, "phi")?;
    let options = RedistanceOptions {
        half_width,
        eps,
        max_steps,
        tol,
    };
    fn run<const D: usize>(
        s: &[f64],
        shape: &[usize],
        lower: &[f64],
        spacing: f64,
        options: RedistanceOptions,
    ) -> PyResult<RedistancedBand> {
        let field = SampledField::<D>::new(s, shape_array::<D>(shape)?, coords_array::<D>(lower, "lower")?, spacing)
            .map_err(to_pyerr)?;
        band_of(&field, options).map_err(to_pyerr)
    }
    let out = py.detach(|| match d {
        2 => run::<2>(s, &shape, &lower, spacing, options),
        3 => run::<3>(s, &shape, &lower, spacing, options),
        _ => Err(PyValueError::new_err(format!(
            "only 2D and 3D grids are supported, got {d}D"
        ))),
    })?;
    let m = out.linear.len();
    let direction = numpy::ndarray::Array2::from_shape_vec((m, d), out.direction)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((
        out.linear.into_pyarray(py),
        out.signed.into_pyarray(py),
        direction.into_pyarray(py),
        out.crossed_cells,
        out.unsettled,
        out.medial,
    ))
}

/// Per vertex the smallest vertex index of its connected part, the vertices joined by the edges
/// of the faces (m, 3). See `tubesweep_core::surface::mesh_parts::vertex_parts`.
#[pyfunction]
pub(crate) fn mesh_vertex_parts<'py>(
    py: Python<'py>,
    n_vertices: usize,
    faces: PyReadonlyArray2<'py, i64>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    if faces.shape()[1] != 3 {
        return Err(PyValueError::new_err("faces must have shape (m, 3)"));
    }
    let f = c_slice(&faces, "faces")?;
    let triangles: Vec<[i64; 3]> = f.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let labels = py
        .detach(|| tubesweep_core::surface::mesh_parts::vertex_parts(n_vertices, &triangles))
        .map_err(to_pyerr)?;
    Ok(labels.into_pyarray(py))
}

/// Adds this file's classes and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTriangleTree>()?;
    m.add_function(wrap_pyfunction!(project_to_sampled_level_set, m)?)?;
    m.add_function(wrap_pyfunction!(redistanced_band_of_samples, m)?)?;
    m.add_function(wrap_pyfunction!(sphere_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(torus_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(ellipsoid_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(rounded_cube_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(double_torus_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(mobius_closest_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(open_surface_closest_points, m)?)?;
    m.add_function(wrap_pyfunction!(star_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_vertex_parts, m)?)?;
    Ok(())
}
