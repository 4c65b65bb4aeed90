"""The methods under test: tubesweep (Godunov, Lax–Friedrichs) and the peers.

Each method has ``available() -> (bool, reason)``, ``prepare(problem)`` (untimed: meshes, tube
masks) and ``run(prepared)`` (the timed work, returning values at the evaluation points plus
statistics). What is timed:

* ``tubesweep-*``: the whole public call ``ts.solve(...)`` (band discovery, source set-up and
  sweeps); ``sweep_s`` is ``sol.stats.seconds`` (the native solve: its preparation and the sweeps). ``tubesweep-godunov-tolh``
  stops at ``tol = 1e-3·Δx`` instead of the default ``1e-10``.
* ``skfmm-tube``: finding the tube |φ| ≤ 2Δx (with tubesweep's coarse-to-fine band search, so
  that φ costs both the same), building the dense N^d arrays (distance-to-source level set,
  tube mask) and ``skfmm.distance(..., order=2)``.
* ``heat``: ``potpourri3d.MeshHeatMethodDistanceSolver(V, F)`` and ``compute_distance`` (set-up +
  solve) on the marching-cubes mesh of the same grid (mesh extraction not timed).
* ``mmp``: ``pygeodesic`` exact polyhedral geodesics (MMP) on the same mesh, set-up + solve.

Mesh methods start from the mesh vertex nearest the source; their exact reference is measured
from that vertex's closest point on the surface, and their vertex values are interpolated
linearly (barycentric, on the closest triangle) at the common evaluation points.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Tuple

import numpy as np

import tubesweep as ts
from problems import Problem


@dataclass
class Outcome:
    values: np.ndarray  # at problem.eval_points (NaN where the method gives nothing)
    exact: np.ndarray  # the exact reference for this method's source
    stats: Dict[str, Any] = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# mesh helpers
# --------------------------------------------------------------------------------------------
def clean_mesh(v: np.ndarray, f: np.ndarray, tol: float) -> Tuple[np.ndarray, np.ndarray]:
    """Merges vertices closer than ``tol`` (marching cubes duplicates a vertex where φ = 0 at a
    node), drops degenerate and duplicate faces and unreferenced vertices."""
    key = np.round(v / tol).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inv = inv.reshape(-1)
    f = inv[f]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    srt = np.sort(f, axis=1)
    _, keep = np.unique(srt, axis=0, return_index=True)
    f = f[np.sort(keep)]
    v = v[first]
    used = np.unique(f)
    remap = -np.ones(len(v), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return v[used], remap[f]


def marching_cubes_mesh(problem: Problem) -> Tuple[np.ndarray, np.ndarray]:
    try:
        from skimage.measure import marching_cubes
    except ImportError as e:  # pragma: no cover
        raise ImportError("mesh peers need scikit-image: pip install scikit-image") from e
    grid = problem.grid
    phi = problem.dense_phi(grid)  # type: ignore[misc]
    h = grid.spacing
    v, f, _, _ = marching_cubes(phi, level=0.0, spacing=(h, h, h))
    v = v + np.asarray(grid.lower)[None, :]
    return clean_mesh(v, f.astype(np.int64), 1e-7 * h)


def interpolate_on_mesh(
    v: np.ndarray, f: np.ndarray, values: np.ndarray, points: np.ndarray, k: int = 12
) -> np.ndarray:
    """Linear (barycentric) interpolation of vertex ``values`` at the closest point of the mesh
    to each of ``points`` (closest among the ``k`` triangles with the nearest centroids)."""
    from scipy.spatial import cKDTree

    tri = v[f]  # (F, 3, 3)
    tree = cKDTree(tri.mean(axis=1))
    _, cand = tree.query(points, k=min(k, len(f)))
    cand = np.atleast_2d(cand)
    a, b, c = tri[cand, 0], tri[cand, 1], tri[cand, 2]  # (M, k, 3)
    p = points[:, None, :]
    ua, ub, uc = values[f[cand, 0]], values[f[cand, 1]], values[f[cand, 2]]
    best_d = np.full(cand.shape, np.inf)
    best_u = np.full(cand.shape, np.nan)
    # interior: projection onto the plane with barycentrics ≥ 0
    e0, e1, w = b - a, c - a, p - a
    d00, d01, d11 = (e0 * e0).sum(-1), (e0 * e1).sum(-1), (e1 * e1).sum(-1)
    d20, d21 = (w * e0).sum(-1), (w * e1).sum(-1)
    den = d00 * d11 - d01 * d01
    ok = den > 0
    den = np.where(ok, den, 1.0)
    lb = (d11 * d20 - d01 * d21) / den
    lc = (d00 * d21 - d01 * d20) / den
    la = 1 - lb - lc
    inside = ok & (la >= 0) & (lb >= 0) & (lc >= 0)
    q = la[..., None] * a + lb[..., None] * b + lc[..., None] * c
    dist = np.linalg.norm(p - q, axis=-1)
    sel = inside & (dist < best_d)
    best_d = np.where(sel, dist, best_d)
    best_u = np.where(sel, la * ua + lb * ub + lc * uc, best_u)
    # edges
    for x, y, ux, uy in ((a, b, ua, ub), (b, c, ub, uc), (c, a, uc, ua)):
        e = y - x
        ee = np.maximum((e * e).sum(-1), 1e-300)
        t = np.clip(((p - x) * e).sum(-1) / ee, 0.0, 1.0)
        q = x + t[..., None] * e
        dist = np.linalg.norm(p - q, axis=-1)
        sel = dist < best_d
        best_d = np.where(sel, dist, best_d)
        best_u = np.where(sel, (1 - t) * ux + t * uy, best_u)
    j = np.argmin(best_d, axis=1)
    return best_u[np.arange(len(points)), j]


def interpolate_dense(arr: np.ndarray, grid: ts.Grid, points: np.ndarray) -> np.ndarray:
    """Multilinear interpolation of a dense (masked) array; NaN where a corner is masked."""
    data = np.ma.getdata(arr).astype(float)
    mask = np.ma.getmaskarray(arr)
    data = np.where(mask, np.nan, data)
    s = (points - np.asarray(grid.lower)) / grid.spacing
    i0 = np.clip(np.floor(s).astype(np.int64), 0, np.asarray(grid.shape) - 2)
    t = s - i0
    d = grid.ndim
    out = np.zeros(len(points))
    for corner in range(1 << d):
        bits = [(corner >> k) & 1 for k in range(d)]
        idx = tuple(i0[:, k] + bits[k] for k in range(d))
        w = np.ones(len(points))
        for k in range(d):
            w *= t[:, k] if bits[k] else 1 - t[:, k]
        out += w * data[idx]
    return out


# --------------------------------------------------------------------------------------------
# methods
# --------------------------------------------------------------------------------------------
class Method:
    name = ""
    label = ""
    dims: Tuple[int, ...] = (2, 3)
    module: Optional[str] = None
    pip: str = ""

    def available(self) -> Tuple[bool, str]:
        if self.module is None:
            return True, ""
        try:
            importlib.import_module(self.module)
        except ImportError:
            return False, f"{self.name}: not installed (pip install {self.pip})"
        return True, ""

    def applies(self, problem: Problem) -> Tuple[bool, str]:
        if problem.ndim not in self.dims:
            return False, f"{self.name} works on {'/'.join(str(d) + 'D' for d in self.dims)} problems only"
        return True, ""

    def prepare(self, problem: Problem) -> Any:
        return problem

    def run(self, prepared: Any) -> Outcome:  # pragma: no cover - interface
        raise NotImplementedError


class Tubesweep(Method):
    """``ts.solve`` with the default stopping test (largest change in an iteration below
    ``tol = 1e-10``), or with ``tol = tol_h · Δx`` when ``tol_h`` is given: a tolerance tied to
    the grid, far below the first-order scheme's O(Δx) error, that stops the iteration once
    further sweeps could only move the answer by that much (the result stays within about
    ``tol`` of the converged one). ``threads=1`` runs it on one core (``-1t``): the same bits as
    on all cores, and a time to set beside the peers, which run on one core."""

    def __init__(self, hamiltonian: str, tol_h: Optional[float] = None, threads: int = 0, order: int = 1):
        self.hamiltonian = hamiltonian
        self.tol_h = tol_h
        self.threads = threads
        self.order = order
        self.name = (
            f"tubesweep-{hamiltonian}"
            + ("" if tol_h is None else "-tolh")
            + ("" if threads == 0 else f"-{threads}t")
            + ("" if order == 1 else f"-order{order}")
        )
        self.label = (
            f"tubesweep ({'Godunov' if hamiltonian == 'godunov' else 'Lax–Friedrichs'}, two-layer"
            + ("" if tol_h is None else f", tol = {tol_h:g}·Δx")
            + ("" if threads == 0 else f", {threads} thread" + ("s" if threads > 1 else ""))
            + (", order=1: the paper's scheme" if order == 1 else f", order={order}: the default's choice here")
            + ")"
        )

    def run(self, problem: Problem) -> Outcome:
        kw: Dict[str, Any] = {} if self.tol_h is None else {"tol": self.tol_h * problem.grid.spacing}
        if self.threads:
            kw["threads"] = self.threads
        kw["order"] = self.order  # explicit: "tubesweep-godunov" is the paper's first-order scheme
        t0 = time.perf_counter()
        sol = ts.solve(problem.surface, problem.grid, sources=[problem.source], hamiltonian=self.hamiltonian, **kw)
        wall = time.perf_counter() - t0
        st = sol.stats
        return Outcome(
            sol(problem.eval_points),
            problem.exact,
            dict(
                wall=wall,
                sweep_s=st.seconds,
                setup_s=st.setup_seconds,
                band_points=st.band_points,
                iterations=st.iterations,
                updates=st.updates,
                converged=st.converged,
                band_bytes=st.band_bytes,
            ),
        )


class SkfmmTube(Method):
    name = "skfmm-tube"
    label = "scikit-fmm in a tube |φ|≤2Δx (order 2)"
    module = "skfmm"
    pip = "scikit-fmm"
    TUBE = 2.0

    def run(self, prepared: Any) -> Outcome:
        import skfmm

        problem = prepared
        grid = problem.grid
        h = grid.spacing
        t0 = time.perf_counter()
        # the tube |φ| ≤ 2Δx, found with the same coarse-to-fine search tubesweep uses (cheaper
        # than evaluating φ on the whole box, which a plain scikit-fmm user would do)
        tube = problem.surface.band(grid, self.TUBE * h).linear
        t_tube = time.perf_counter() - t0
        axes = [grid.lower[k] + h * np.arange(grid.shape[k]) for k in range(grid.ndim)]
        r2 = np.zeros(grid.shape)
        for k, ax in enumerate(axes):
            shp = [1] * grid.ndim
            shp[k] = -1
            r2 = r2 + ((ax - problem.source[k]) ** 2).reshape(shp)
        r = np.sqrt(r2)
        radius = 2.0 * h  # the initial front: the sphere of radius 2Δx about the source
        mask = np.ones(grid.size, dtype=bool)
        mask[tube] = False
        psi = np.ma.MaskedArray(r - radius, mask.reshape(grid.shape))
        d = skfmm.distance(psi, dx=h, order=2)
        u = np.ma.MaskedArray(np.where(np.ma.getdata(psi) < 0, r, np.ma.getdata(d) + radius), np.ma.getmaskarray(d))
        wall = time.perf_counter() - t0
        vals = interpolate_dense(u, grid, problem.eval_points)
        return Outcome(
            vals, problem.exact, dict(wall=wall, setup_s=t_tube, band_points=int(len(tube)), dense_nodes=int(grid.size))
        )


class MeshMethod(Method):
    dims = (3,)

    def prepare(self, problem: Problem) -> Any:
        if problem.input_mesh is not None:
            v, f = problem.input_mesh
            src = int(np.argmin(np.linalg.norm(v - problem.source, axis=1)))
            exact = problem.exact
            eval_vertices = True
        else:
            t0 = time.perf_counter()
            v, f = marching_cubes_mesh(problem)
            self.mesh_seconds = time.perf_counter() - t0
            src = int(np.argmin(np.linalg.norm(v - problem.source, axis=1)))
            offset = float(np.linalg.norm(v[src] - problem.source))
            if offset < 1e-9:
                exact = problem.exact
            else:
                _, cp = problem.surface.project(v[src][None], problem.grid)
                exact = problem.exact_from(cp[0], problem.eval_points)
            eval_vertices = False
        return problem, v, f, src, exact, eval_vertices

    def values_at_eval(self, prepared: Any, dist: np.ndarray) -> np.ndarray:
        problem, v, f, src, exact, eval_vertices = prepared
        if eval_vertices:
            from scipy.spatial import cKDTree

            _, idx = cKDTree(v).query(problem.eval_points)
            return dist[idx]
        return interpolate_on_mesh(v, f, dist, problem.eval_points)


class Heat(MeshMethod):
    name = "heat"
    label = "heat method (potpourri3d), set-up + solve"
    module = "potpourri3d"
    pip = "potpourri3d"

    def run(self, prepared: Any) -> Outcome:
        import potpourri3d as pp3d

        problem, v, f, src, exact, _ = prepared
        t0 = time.perf_counter()
        solver = pp3d.MeshHeatMethodDistanceSolver(v, f)
        dist = solver.compute_distance(src)
        wall = time.perf_counter() - t0
        return Outcome(
            self.values_at_eval(prepared, np.asarray(dist)),
            exact,
            dict(wall=wall, band_points=int(len(v)), mesh_s=getattr(self, "mesh_seconds", 0.0)),
        )


class MMP(MeshMethod):
    name = "mmp"
    label = "exact polyhedral geodesics (pygeodesic, MMP)"
    module = "pygeodesic"
    pip = "pygeodesic"

    def applies(self, problem: Problem) -> Tuple[bool, str]:
        if problem.input_mesh is not None:
            return False, "mmp on the input mesh is the bunny's exact reference itself"
        return super().applies(problem)

    def run(self, prepared: Any) -> Outcome:
        import pygeodesic.geodesic as geodesic

        problem, v, f, src, exact, _ = prepared
        t0 = time.perf_counter()
        algo = geodesic.PyGeodesicAlgorithmExact(v, f.astype(np.int32))
        dist, _ = algo.geodesicDistances(np.array([src], dtype=np.int32), None)
        wall = time.perf_counter() - t0
        return Outcome(
            self.values_at_eval(prepared, np.asarray(dist, dtype=float)),
            exact,
            dict(wall=wall, band_points=int(len(v)), mesh_s=getattr(self, "mesh_seconds", 0.0)),
        )


METHODS: Dict[str, Method] = {
    m.name: m
    for m in (
        Tubesweep("godunov"),
        Tubesweep("godunov", order=2),
        Tubesweep("godunov", tol_h=1e-3),
        Tubesweep("godunov", threads=1),
        Tubesweep("lxf"),
        SkfmmTube(),
        Heat(),
        MMP(),
    )
}
