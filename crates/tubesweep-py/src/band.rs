//! `Band`: the narrow band (`tubesweep_core::band`) as a Python object — built from sorted node
//! indices, queried (neighbours, rim, directions, facing sheets), solved on (`solve`, `solve_general`,
//! through `crate::sweep`) and read back (`interpolate`, `nearest_source_labels`:
//! `tubesweep_core::solution`).

use crate::convert::*;
use crate::errors::to_pyerr;
use crate::sweep::*;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyReadwriteArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubesweep_core::band::NarrowBand;
use tubesweep_core::solution::interpolate::interpolate;
use tubesweep_core::solution::nearest_source::nearest_source_labels;
use tubesweep_core::sweep::default_row_prefetch_above;
use tubesweep_core::sweep::NodeRole;
use tubesweep_core::SolveOptions;

pub(crate) enum AnyBand {
    D2(NarrowBand<2>),
    D3(NarrowBand<3>),
}

/// A narrow band of grid nodes with its neighbour table (see `tubesweep_core::band`).
#[pyclass(module = "tubesweep._native", name = "Band", frozen)]
pub(crate) struct PyBand {
    pub(crate) band: AnyBand,
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

    pub(crate) fn __len__(&self) -> usize {
        with_band!(self, b, b.len())
    }

    #[getter]
    pub(crate) fn ndim(&self) -> usize {
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

    /// The rows of the neighbour table ([`neighbours`](Self::neighbours)) of the band nodes at
    /// `positions` only, shape (M, d, 2), K where a neighbour is not in the band (or its edge was
    /// cut).
    fn neighbours_of_nodes<'py>(
        &self,
        py: Python<'py>,
        positions: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, numpy::PyArray3<i64>>> {
        let pos = positions.as_slice()?;
        let k = self.__len__();
        if let Some(bad) = pos.iter().find(|&&p| p < 0 || p as usize >= k) {
            return Err(PyValueError::new_err(format!(
                "positions: {bad} is not a band position (the band has {k} nodes)"
            )));
        }
        let d = self.ndim();
        let flat: Vec<i64> = with_band!(
            self,
            b,
            pos.iter()
                .flat_map(|&n| b
                    .neighbours_of(n as usize)
                    .into_iter()
                    .flat_map(|p| [p[0] as i64, p[1] as i64]))
                .collect()
        );
        Ok(numpy::ndarray::Array3::from_shape_vec((pos.len(), d, 2), flat)
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
        let (inn, ph, dir) = self.node_fields(&inner, &phi, &direction)?;
        let pairs = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::facing_sheets::facing_sheet_pairs(b, inn, ph, dir, spacing)
                )
            })
            .map_err(to_pyerr)?;
        let node: Vec<i64> = pairs.iter().map(|p| p.node as i64).collect();
        let neighbour: Vec<i64> = pairs.iter().map(|p| p.neighbour as i64).collect();
        let gap: Vec<f64> = pairs.iter().map(|p| p.gap).collect();
        Ok((node.into_pyarray(py), neighbour.into_pyarray(py), gap.into_pyarray(py)))
    }

    /// The band positions whose φ's sign the *across* test of `facing_sheet_pairs` can read
    /// (`tubesweep_core::band::facing_sheets::across_candidates`; `phi` unsigned).
    fn across_candidates<'py>(
        &self,
        py: Python<'py>,
        inner: PyReadonlyArray1<'py, bool>,
        phi: PyReadonlyArray1<'py, f32>,
        direction: PyReadonlyArray2<'py, f32>,
        spacing: f64,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let (inn, ph, dir) = self.node_fields(&inner, &phi, &direction)?;
        let nodes = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::facing_sheets::across_candidates(b, inn, ph, dir, spacing)
                )
            })
            .map_err(to_pyerr)?;
        Ok(nodes.into_iter().map(|n| n as i64).collect::<Vec<_>>().into_pyarray(py))
    }

    /// The inner-tube nodes on the overlap side of a crease that become extension nodes (see
    /// `tubesweep_core::band::crease_ridges`): `inner` per node, `phi` φ (signed), `direction`
    /// (K, d) the outward directions. Returns their band positions.
    fn crease_ridge_nodes<'py>(
        &self,
        py: Python<'py>,
        inner: PyReadonlyArray1<'py, bool>,
        phi: PyReadonlyArray1<'py, f32>,
        direction: PyReadonlyArray2<'py, f32>,
        spacing: f64,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let (inn, ph, dir) = self.node_fields(&inner, &phi, &direction)?;
        let nodes = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::crease_ridges::crease_ridge_nodes(b, inn, ph, dir, spacing)
                )
            })
            .map_err(to_pyerr)?;
        let out: Vec<i64> = nodes.iter().map(|&n| n as i64).collect();
        Ok(out.into_pyarray(py))
    }

    /// The turns of φ's normals read through a smoothing
    /// (`tubesweep_core::second_order::smoothed_creases`): `phi` per node, `passes` of the 3-node
    /// mean, normals compared up to `reach` nodes away at the nodes with |φ| ≤ `near`·`spacing`.
    /// Returns those nodes' band positions and their turns in degrees.
    #[allow(clippy::type_complexity)]
    fn smoothed_turning<'py>(
        &self,
        py: Python<'py>,
        phi: PyReadonlyArray1<'py, f64>,
        spacing: f64,
        passes: usize,
        reach: usize,
        near: f64,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>)> {
        let ph = phi.as_slice()?;
        let (at, turns) = py
            .detach(|| {
                with_band!(self, b, {
                    tubesweep_core::second_order::smoothed_creases::smoothed_normals(b, ph, spacing, passes, near).map(
                        |normals| {
                            let turns = normals.turning_all(b, reach);
                            (normals.at.iter().map(|&i| i as i64).collect::<Vec<i64>>(), turns)
                        },
                    )
                })
            })
            .map_err(to_pyerr)?;
        Ok((at.into_pyarray(py), turns.into_pyarray(py)))
    }

    /// The crease nodes found through a smoothing, their turn in degrees and the share of them
    /// beside a convex edge
    /// (`tubesweep_core::second_order::smoothed_creases::smoothed_creases`, the thresholds as its
    /// `SmoothedCreaseTest`'s).
    #[allow(clippy::too_many_arguments)]
    fn smoothed_creases(
        &self,
        py: Python<'_>,
        phi: PyReadonlyArray1<'_, f64>,
        spacing: f64,
        passes: usize,
        reach: usize,
        near: f64,
        turn: f64,
        turn_concave: f64,
        min_concave_nodes: usize,
        face: f64,
        sheets: f64,
        percentile: f64,
    ) -> PyResult<(usize, f64, f64)> {
        let ph = phi.as_slice()?;
        let test = tubesweep_core::second_order::smoothed_creases::SmoothedCreaseTest {
            passes,
            reach,
            near,
            turn,
            turn_concave,
            min_concave_nodes,
            face,
            sheets,
            percentile,
        };
        py.detach(|| {
            with_band!(
                self,
                b,
                tubesweep_core::second_order::smoothed_creases::smoothed_creases(b, ph, spacing, &test)
            )
        })
        .map(|c| (c.nodes, c.turn, c.convex))
        .map_err(to_pyerr)
    }

    /// The creases of a level set in the paper's tube (`order=1`, see
    /// `tubesweep_core::second_order::creases::creases_of_level_set`): `inner` per node, `phi` φ
    /// (signed), `direction` (K, d) the outward directions. Returns the crease nodes' count and the
    /// largest turn of the normal there, in degrees.
    fn creases_of_level_set(
        &self,
        py: Python<'_>,
        inner: PyReadonlyArray1<'_, bool>,
        phi: PyReadonlyArray1<'_, f32>,
        direction: PyReadonlyArray2<'_, f32>,
        spacing: f64,
    ) -> PyResult<(usize, f64)> {
        let (inn, ph, dir) = self.node_fields(&inner, &phi, &direction)?;
        let c = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::second_order::creases::creases_of_level_set(b, inn, ph, dir, spacing)
                )
            })
            .map_err(to_pyerr)?;
        Ok((c.nodes, c.angle))
    }

    /// The creases of a re-distanced level set in the paper's tube (`order=1`, see
    /// `tubesweep_core::second_order::creases::creases_of_redistanced`: the second-order
    /// geometry's test): `roles` per node (the paper's tube), `phi` φ (signed), `direction` (K, d)
    /// the outward directions, `outer_width` the tube's half-width. Returns the crease nodes'
    /// count, the faces' largest angle there in degrees, whether φ was found noisy (then no crease
    /// is looked for: 0, 0.0 and 0.0), and the largest turn between neighbours there in degrees.
    fn creases_of_redistanced(
        &self,
        py: Python<'_>,
        roles: PyReadonlyArray1<'_, u8>,
        phi: PyReadonlyArray1<'_, f64>,
        direction: PyReadonlyArray2<'_, f32>,
        spacing: f64,
        outer_width: f64,
    ) -> PyResult<(usize, f64, bool, f64)> {
        let d = self.ndim();
        if direction.shape()[1] != d {
            return Err(PyValueError::new_err(format!("direction must have shape (K, {d})")));
        }
        let (roles, phi, dir) = (
            node_roles(roles.as_slice()?)?,
            phi.as_slice()?,
            c_slice(&direction, "direction")?,
        );
        let c = match &self.band {
            AnyBand::D2(b) => redistanced_creases(py, b, roles, phi, dir, spacing, outer_width),
            AnyBand::D3(b) => redistanced_creases(py, b, roles, phi, dir, spacing, outer_width),
        }?;
        Ok(c.map_or((0, 0.0, true, 0.0), |c| (c.nodes, c.faces_angle, false, c.angle)))
    }

    /// The edges between neighbours whose closest points lie more than `jump` grid spacings
    /// apart, one of them in the inner tube (`tubesweep_core::band::medial_edges`): `inner` per
    /// node, `phi` its signed or unsigned distance, `direction` (K, d) its outward direction.
    /// Returns the edges' band positions (node, its plus neighbour).
    #[allow(clippy::type_complexity)]
    fn medial_edges<'py>(
        &self,
        py: Python<'py>,
        inner: PyReadonlyArray1<'py, bool>,
        phi: PyReadonlyArray1<'py, f32>,
        direction: PyReadonlyArray2<'py, f32>,
        spacing: f64,
        jump: f64,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>)> {
        let (inn, ph, dir) = self.node_fields(&inner, &phi, &direction)?;
        let edges = py
            .detach(|| {
                with_band!(
                    self,
                    b,
                    tubesweep_core::band::medial_edges::medial_edges(b, inn, ph, dir, spacing, jump)
                )
            })
            .map_err(to_pyerr)?;
        let node: Vec<i64> = edges.iter().map(|e| e.0 as i64).collect();
        let neighbour: Vec<i64> = edges.iter().map(|e| e.1 as i64).collect();
        Ok((node.into_pyarray(py), neighbour.into_pyarray(py)))
    }

    /// A copy of the band whose neighbour table no longer joins the pairs `(node[i],
    /// neighbour[i])` (band positions of grid neighbours: the pairs across a narrow gap of
    /// `facing_sheet_pairs`), so that the front cannot cross between them
    /// (`tubesweep_core::band::NarrowBand::cut_edges`). Returns the band and the edges removed.
    fn with_edges_cut(
        &self,
        py: Python<'_>,
        node: PyReadonlyArray1<'_, i64>,
        neighbour: PyReadonlyArray1<'_, i64>,
    ) -> PyResult<(PyBand, usize)> {
        let (a, b) = (node.as_slice()?, neighbour.as_slice()?);
        if a.len() != b.len() {
            return Err(PyValueError::new_err(format!(
                "node and neighbour must have the same length, got {} and {}",
                a.len(),
                b.len()
            )));
        }
        if a.iter().chain(b).any(|&p| p < 0) {
            return Err(PyValueError::new_err("node and neighbour must be band positions (≥ 0)"));
        }
        let pairs: Vec<(usize, usize)> = a.iter().zip(b).map(|(&x, &y)| (x as usize, y as usize)).collect();
        py.detach(|| match &self.band {
            AnyBand::D2(band) => {
                let mut cut = band.clone();
                cut.cut_edges(&pairs).map(|n| (AnyBand::D2(cut), n))
            }
            AnyBand::D3(band) => {
                let mut cut = band.clone();
                cut.cut_edges(&pairs).map(|n| (AnyBand::D3(cut), n))
            }
        })
        .map(|(band, n)| (PyBand { band }, n))
        .map_err(to_pyerr)
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

/// Adds this file's classes and functions to the module.
impl PyBand {
    /// The per-node fields of the band's surface tests (`facing_sheet_pairs`, `crease_ridge_nodes`,
    /// `creases_of_level_set`, `medial_edges`) as slices: `inner` and `phi` per node, `direction` (K, d) C-ordered. Their
    /// lengths are checked against the band in the core (`check_node_fields`).
    fn node_fields<'a>(
        &self,
        inner: &'a PyReadonlyArray1<'_, bool>,
        phi: &'a PyReadonlyArray1<'_, f32>,
        direction: &'a PyReadonlyArray2<'_, f32>,
    ) -> PyResult<(&'a [bool], &'a [f32], &'a [f32])> {
        let d = self.ndim();
        if direction.shape()[1] != d {
            return Err(PyValueError::new_err(format!("direction must have shape (K, {d})")));
        }
        Ok((inner.as_slice()?, phi.as_slice()?, c_slice(direction, "direction")?))
    }
}

/// [`PyBand::creases_of_redistanced`] on a band of dimension D.
fn redistanced_creases<const D: usize>(
    py: Python<'_>,
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    phi: &[f64],
    direction: &[f32],
    spacing: f64,
    outer_width: f64,
) -> PyResult<Option<tubesweep_core::second_order::creases::Creases>> {
    // (roles and phi per node: checked by the core)
    let dirs = node_vectors::<f32, D>(direction, band.len(), "direction")?;
    py.detach(|| {
        tubesweep_core::second_order::creases::creases_of_redistanced(band, roles, phi, dirs, spacing, outer_width)
    })
    .map_err(to_pyerr)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBand>()?;
    Ok(())
}
