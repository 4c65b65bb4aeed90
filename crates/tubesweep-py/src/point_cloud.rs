//! Point clouds as closest-point surfaces (`tubesweep_core::surface::point_cloud`): the kd-tree,
//! the samples' analysis and the moving-least-squares closest points, the GIL released.

use crate::convert::*;
use crate::errors::to_pyerr;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tubesweep_core::surface::point_cloud::{PointCloud, SampleAnalysis};

enum Cloud {
    Two(PointCloud<2>),
    Three(PointCloud<3>),
}

/// A point cloud with its kd-tree (see `tubesweep_core::surface::point_cloud`).
#[pyclass(module = "tubesweep._native", name = "PointCloud")]
pub(crate) struct PyPointCloud {
    cloud: Cloud,
}

fn rows<const D: usize>(flat: &[f64]) -> Vec<[f64; D]> {
    flat.chunks_exact(D).map(|c| std::array::from_fn(|k| c[k])).collect()
}

fn flat<const D: usize>(rows: Vec<[f64; D]>) -> Vec<f64> {
    rows.into_iter().flatten().collect()
}

#[pymethods]
impl PyPointCloud {
    /// The cloud of `points` (M, 2) or (M, 3), distinct and finite, fitted over `neighbours`.
    #[new]
    fn new(py: Python<'_>, points: PyReadonlyArray2<'_, f64>, neighbours: usize) -> PyResult<Self> {
        let d = points.shape()[1];
        let p = c_slice(&points, "points")?;
        let cloud = match d {
            2 => {
                let r = rows::<2>(p);
                Cloud::Two(py.detach(|| PointCloud::new(r, neighbours)).map_err(to_pyerr)?)
            }
            3 => {
                let r = rows::<3>(p);
                Cloud::Three(py.detach(|| PointCloud::new(r, neighbours)).map_err(to_pyerr)?)
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "points must have shape (M, 2) or (M, 3); got {:?}",
                    points.shape()
                )))
            }
        };
        Ok(PyPointCloud { cloud })
    }

    fn __len__(&self) -> usize {
        match &self.cloud {
            Cloud::Two(c) => c.len(),
            Cloud::Three(c) => c.len(),
        }
    }

    /// An upper bound of the distance from a point of the surface to its nearest sample.
    #[getter]
    fn reach(&self) -> f64 {
        match &self.cloud {
            Cloud::Two(c) => c.reach(),
            Cloud::Three(c) => c.reach(),
        }
    }

    /// The rim flags per sample (after `mark_rim`).
    #[getter]
    fn rim<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        match &self.cloud {
            Cloud::Two(c) => c.rim().to_vec().into_pyarray(py),
            Cloud::Three(c) => c.rim().to_vec().into_pyarray(py),
        }
    }

    /// Per sample: spacing (distance to the nearest other sample), the fit's radius, the
    /// leave-one-out residual over the radius, the largest angular gap of the neighbours, the
    /// index of the nearest other sample (2³² − 1 for none). The gaps are bridged by samples up
    /// to `bridge` away (default: twice the sparsest fit's radius; `PointCloud::analyse_bridging`).
    #[allow(clippy::type_complexity)]
    #[pyo3(signature = (bridge=None))]
    fn analyse<'py>(
        &self,
        py: Python<'py>,
        bridge: Option<f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<u32>>,
    )> {
        if let Some(b) = bridge {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "bridge must be a finite distance ≥ 0; got {b}"
                )));
            }
        }
        let a: SampleAnalysis = py.detach(|| match &self.cloud {
            Cloud::Two(c) => c.analyse_bridging(bridge.unwrap_or(2.0 * c.reach())),
            Cloud::Three(c) => c.analyse_bridging(bridge.unwrap_or(2.0 * c.reach())),
        });
        Ok((
            a.spacing.into_pyarray(py),
            a.radius.into_pyarray(py),
            a.residual.into_pyarray(py),
            a.gap.into_pyarray(py),
            a.nearest.into_pyarray(py),
        ))
    }

    /// The `k` samples nearest to each of the samples `which`, nearest first, (len(which), k)
    /// (`tubesweep_core::surface::point_cloud::PointCloud::nearest_samples`).
    fn nearest_samples<'py>(
        &self,
        py: Python<'py>,
        which: PyReadonlyArray1<'_, i64>,
        k: usize,
    ) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let w = c_slice(&which, "which")?;
        if let Some(&bad) = w.iter().find(|&&i| i < 0) {
            return Err(PyValueError::new_err(format!(
                "which must hold sample indices ≥ 0; got {bad}"
            )));
        }
        let w: Vec<usize> = w.iter().map(|&i| i as usize).collect();
        let cloud = &self.cloud;
        let near = py
            .detach(|| match cloud {
                Cloud::Two(c) => c.nearest_samples(&w, k),
                Cloud::Three(c) => c.nearest_samples(&w, k),
            })
            .map_err(to_pyerr)?;
        near.into_pyarray(py).reshape([w.len(), k])
    }

    /// Sets the samples' noise (`tubesweep_core::surface::point_cloud::PointCloud::set_noise`).
    fn set_noise(&mut self, noise: f64) -> PyResult<()> {
        match &mut self.cloud {
            Cloud::Two(c) => c.set_noise(noise),
            Cloud::Three(c) => c.set_noise(noise),
        }
        .map_err(to_pyerr)
    }

    /// Marks the rim from the samples' gaps; returns how many samples lie on it.
    fn mark_rim(&mut self, py: Python<'_>, gap: PyReadonlyArray1<'_, f64>) -> PyResult<usize> {
        let g = c_slice(&gap, "gap")?;
        let cloud = &mut self.cloud;
        py.detach(|| match cloud {
            Cloud::Two(c) => c.mark_rim(g),
            Cloud::Three(c) => c.mark_rim(g),
        })
        .map_err(to_pyerr)
    }

    /// Per sample, whether it lies in a group of fewer than `min_size` samples apart from the rest
    /// (`tubesweep_core::surface::point_cloud::isolated`); `spacing` and `radius` from `analyse`.
    fn isolated<'py>(
        &self,
        py: Python<'py>,
        spacing: PyReadonlyArray1<'py, f64>,
        radius: PyReadonlyArray1<'py, f64>,
        median_radius: f64,
        min_size: usize,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let s = c_slice(&spacing, "spacing")?;
        let r = c_slice(&radius, "radius")?;
        let flags = py
            .detach(|| match &self.cloud {
                Cloud::Two(c) => c.isolated(s, r, median_radius, min_size),
                Cloud::Three(c) => c.isolated(s, r, median_radius, min_size),
            })
            .map_err(to_pyerr)?;
        Ok(flags.into_pyarray(py))
    }

    /// Closest points (M, d) of `points` and per point 0 (interior), 1 (moved to the rim) or 2
    /// (no fit: NaN), in parallel; `rho` is the smoothing radius (fits over at least the samples
    /// within it); feet found from a neighbour's foot and farther than `trust` from their point are
    /// checked against its nearest sample (0: all of them).
    #[pyo3(signature = (points, rho = 0.0, trust = 0.0))]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        rho: f64,
        trust: f64,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>)> {
        let (cp, feet, d) = match &self.cloud {
            Cloud::Two(c) => {
                let x = rows::<2>(points_slice(&points, 2)?);
                let (cp, f) = py.detach(|| c.closest_points(&x, rho, trust));
                (flat(cp), f, 2)
            }
            Cloud::Three(c) => {
                let x = rows::<3>(points_slice(&points, 3)?);
                let (cp, f) = py.detach(|| c.closest_points(&x, rho, trust));
                (flat(cp), f, 3)
            }
        };
        let m = cp.len() / d;
        let cp = cp.into_pyarray(py).reshape([m, d])?;
        let feet: Vec<u8> = feet.into_iter().map(|f| f as u8).collect();
        Ok((cp, feet.into_pyarray(py)))
    }

    /// Lower bounds of the distances from `points` to the surface (for the band search).
    fn lower_bounds<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let out = match &self.cloud {
            Cloud::Two(c) => {
                let x = rows::<2>(points_slice(&points, 2)?);
                py.detach(|| c.distance_lower_bounds(&x))
            }
            Cloud::Three(c) => {
                let x = rows::<3>(points_slice(&points, 3)?);
                py.detach(|| c.distance_lower_bounds(&x))
            }
        };
        Ok(out.into_pyarray(py))
    }
}

/// Adds this file's class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPointCloud>()
}
