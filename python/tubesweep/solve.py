"""The surface eikonal solver: the two-layer tube method (Algorithm 3) and the naive single tube
(Algorithm 2) on a sparse narrow band."""

from __future__ import annotations

import contextlib
import dataclasses
import time
import warnings
from typing import Any, Callable, List, Optional, Tuple

import numpy as np

from . import _native
from ._validate import (
    available_memory_bytes,
    check_memory,
    ACTIVATION_FRACTION,
    FRONT_WINDOW,
    check_threads as _threads,
    check_infinity as _infinity,
    as_grid,
    as_points,
    as_sources,
    check_hamiltonian,
    check_tolerance,
    check_tolerance_scale,
    checked_point_speeds,
    speed_at_points,
    progress_callback,
    real_scalar,
    speed_values,
    warn_unconverged,
)
from ._result_check import check_values
from ._interpolation import interpolate_band
from .grid import Grid
from .stats import SolveStats
from .surface import BandGeometry, Surface, as_surface, band_neighbours
from ._warn import user_stacklevel

#: The default stopping tolerance of the first-order sweeps (with ``order=2`` it stands for the
#: second-order default, ``second_order.default_tol``).
DEFAULT_TOL = 1e-10

__all__ = ["solve", "Solution", "METHODS", "SOURCE_INITS", "ROLE_RTOL", "SOURCE_RADIUS"]

METHODS = ("two-layer", "naive")
SOURCE_INITS = ("exact", "node")

#: A node belongs to the inner tube when ``|φ| ≤ inner·Δx·(1 + ROLE_RTOL)``. The relative
#: tolerance makes nodes that sit exactly on the inner radius (up to rounding, common on
#: symmetric grids) consistently inner.
ROLE_RTOL = 1e-9

#: With ``source_init="exact"``, inner-tube nodes whose closest point lies within this many grid
#: spacings of a source are fixed to the exact local distance ``|cp(x) − x_s|`` times the mean
#: slowness.
SOURCE_RADIUS = 2.0

ROLE_FIXED, ROLE_INNER, ROLE_OUTER = 0, 1, 2

_MAX_WIDENINGS = 4
# band nodes at which a solution samples its surface's φ array, to notice a later change
_PHI_SAMPLE = 4096
_ROLE_CHUNK = 1 << 18


class Solution:
    """The result of :func:`solve`: first-arrival times on the band nodes.

    Call it to interpolate (``sol(points)``); print it to see what was solved and how it went.

    Attributes
    ----------
    grid : Grid
        The grid solved on.
    surface : Surface
        The surface solved on.
    indices : numpy.ndarray
        ``(K, d)`` int64 grid indices of the band nodes.
    values : numpy.ndarray
        ``(K,)`` the solution at the band nodes (``inf`` where never reached).
    roles : numpy.ndarray
        ``(K,)`` uint8: 0 fixed (source), 1 inner tube, 2 extension layer.
    phi : numpy.ndarray
        ``(K,)`` float32: φ (level set) or ``|x − cp(x)|`` (closest point) at the band nodes.
    stats : SolveStats
        What the solve did (iterations, updates, times, convergence).
    sources : numpy.ndarray
        ``(S, d)`` the source points.
    hamiltonian : str
        ``"godunov"``, ``"lxf"``, ``"moving-medium"``, ``"metric"`` or ``"isotropic"``.
    method : str
        ``"two-layer"`` or ``"naive"``.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [s.default_source])
    >>> sol.stats.converged
    True
    >>> u = sol([(0.5, 0.0, 0.0)])  # the antipode: exact π/2
    """

    def __init__(
        self,
        grid: Grid,
        band: Any,
        values: np.ndarray,
        roles: np.ndarray,
        phi: np.ndarray,
        stats: SolveStats,
        sources: np.ndarray,
        surface: Surface,
        hamiltonian: str,
        method: str,
        inner: float,
        outer: float,
        fixed: Tuple[np.ndarray, np.ndarray],
        isotropic: bool,
        facing: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray]] = None,
        phi_sample: Optional[Tuple[np.ndarray, np.ndarray]] = None,
    ):
        self.grid = grid
        self._band = band
        self.values = values
        self.roles = roles
        self.phi = phi
        self.stats = stats
        self.sources = sources
        self.surface = surface
        self.hamiltonian = hamiltonian
        self.method = method
        self.inner = inner
        self.outer = outer
        # the nodes fixed by the sources (band positions) and the source of each
        self._fixed = fixed
        self._isotropic = isotropic
        self._labels: Optional[np.ndarray] = None
        # the pairs of band nodes across gaps narrower than the tubes (positions, positions, gaps)
        empty = np.empty(0, np.int64)
        self._facing = facing if facing is not None else (empty, empty, np.empty(0))
        # for a φ array: its values at a sample of the band's nodes (linear indices, values)
        self._phi_sample = phi_sample
        # order=2 with point sources: (u₀ per node, the sources' foot points, their slowness)
        self._factoring: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray]] = None

    def __getstate__(self) -> dict:
        # the native band does not pickle: its linear indices do, and rebuild it
        state = self.__dict__.copy()
        state["_band"] = np.asarray(self._band.linear(), dtype=np.int64)
        return state

    def __setstate__(self, state: dict) -> None:
        linear = state["_band"]
        state["_band"] = _native.Band.from_linear(
            list(state["grid"].shape), np.ascontiguousarray(linear).view(np.uint64)
        )
        self.__dict__.update(state)

    def _check_surface_unchanged(self) -> None:
        """Refuses to go on when the surface's φ array, which the solution uses in place for its
        projections, was changed after the solve (checked at a sample of the band's nodes)."""
        if self._phi_sample is None:
            return
        pick, values = self._phi_sample
        if not np.array_equal(self.surface._array.reshape(-1)[pick], values):  # type: ignore[attr-defined]
            raise ValueError(
                "the φ array of this solution's surface was changed after the solve: its projections onto the surface "
                "no longer match the solution. Solve again for the new φ (pass phi.copy() to LevelSet to keep the "
                "array free to change)"
            )

    def narrow_gaps(self) -> Tuple[np.ndarray, np.ndarray]:
        """Where the surface faces itself across a gap narrower than the tubes.

        There the front can cross the gap, and travel times beyond it can come out too short (see
        ``stats.facing_pairs`` and the user guide's surfaces page).

        Returns
        -------
        midpoints : numpy.ndarray
            ``(M, d)`` the midpoints of the pairs of neighbouring band nodes across such a gap.
        gaps : numpy.ndarray
            ``(M,)`` each gap's width ``|cp(a) − cp(b)|``. Both are empty where the grid resolves
            every gap.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source])
        >>> sol.narrow_gaps()[0].shape
        (0, 3)
        """
        node, neighbour, gap = self._facing
        lin = self.linear
        mid = 0.5 * (self.grid.node_points(lin[node]) + self.grid.node_points(lin[neighbour]))
        return mid.reshape(-1, self.grid.ndim), gap.copy()

    def __repr__(self) -> str:
        # what was solved, on what, and how it went: enough to tell two solutions apart when printed
        s = self.stats
        g = self.grid
        order = getattr(self, "order", 1)
        return (
            f"Solution(surface={self.surface!r}, grid={'×'.join(map(str, g.shape))} (spacing {g.spacing:.4g}), "
            f"band_nodes={s.band_points:,} ({s.inner_points:,} inner), sources={len(self.sources)}, "
            f"method={self.method!r}, hamiltonian={self.hamiltonian!r}, order={order}, iterations={s.iterations}, "
            f"converged={s.converged})"
        )

    @property
    def linear(self) -> np.ndarray:
        """C-order linear grid indices (K,) of the band nodes, increasing (computed from the band on
        each access: the solution does not hold them)."""
        return self._band.linear()

    @property
    def indices(self) -> np.ndarray:
        return self.grid.unravel(self.linear)

    @property
    def points(self) -> np.ndarray:
        """Coordinates (K, d) of the band nodes."""
        return self.grid.points(self.indices)

    @property
    def inner_mask(self) -> np.ndarray:
        return self.roles != ROLE_OUTER

    def __call__(self, points: Any, interpolation: str = "linear") -> np.ndarray:
        """The solution at points near the surface, by interpolation of the band values.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points (or one point ``(d,)``) on or near the surface.
        interpolation : {"linear", "cubic"}
            ``"linear"`` (the default): multilinear over the point's cell. ``"cubic"``:
            Catmull–Rom cubics over the 4^d nodes around the point where they are all in the band
            and reached, the multilinear value elsewhere (docs/box-second-order.md has the gain
            measured: it pays with second-order values, not with the first-order scheme's).

        Returns
        -------
        numpy.ndarray
            ``(M,)`` values; NaN where the cell's corners leave the band.

        Raises
        ------
        ValueError
            If the points do not have the grid's dimension or are not finite, or
            ``interpolation`` is not one of the two.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [s.default_source])
        >>> u = sol([(0.0, 0.5, 0.0), (0.5, 0.0, 0.0)])  # exact π/4 and π/2
        >>> v = sol([(0.0, 0.5, 0.0)], interpolation="cubic")
        """
        p = as_points(points, self.grid.ndim, "points")
        out = interpolate_band(self._band, self.values, self.grid, p, interpolation)
        if self._factoring is not None:
            from .second_order import factored_values

            out = factored_values(self, p, out, interpolation)
        return out

    def on_mesh(self, vertices: Any) -> np.ndarray:
        """The solution at the vertices of a mesh of the surface (for display or export).

        Multilinear interpolation (:meth:`__call__`); where its stencil leaves the band or meets an
        unreached node, the value of the nearest band node within ``outer + 1`` grid spacings (the
        band values are constant along the normals, Eq. (8), so this is first-order accurate).

        Parameters
        ----------
        vertices : array_like
            ``(M, d)`` points on the surface, e.g. ``surface.vertices`` of a mesh.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` values; NaN where no band node is near, or where the nearest one was not reached
            (a component of the surface no source reaches, or a solve stopped early).

        Raises
        ------
        ValueError
            If the vertices do not have the grid's dimension or are not finite.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> sol = ts.solve(spot, spot.grid(60), [spot.vertices[0]])  # doctest: +SKIP
        >>> u = sol.on_mesh(spot.vertices)  # doctest: +SKIP
        """
        p = as_points(vertices, self.grid.ndim, "vertices")
        out = self(p)
        bad = np.flatnonzero(~np.isfinite(out))
        if bad.size:
            pos = self._nearest_reached(p[bad])
            out[bad] = np.where(pos >= 0, self.values[np.maximum(pos, 0)], np.nan)
        return out

    def _nearest_reached(self, p: np.ndarray) -> np.ndarray:
        """Band position (M,) of the band node nearest to each point within ``outer + 1`` grid
        spacings of it, -1 where there is none or where that node was not reached (a component
        of the surface no source reaches: the nearest *reached* node would lie on another
        component's band, whose value and source the point does not have). The offsets from the
        point's nearest node are tried in increasing length, and a point is settled once no
        longer offset can hold a nearer node."""
        d = self.grid.ndim
        r = int(np.ceil(self.outer)) + 1
        best = np.full(len(p), -1, dtype=np.int64)
        ci = self.grid.continuous_index(p)
        # points beyond reach of the grid's nodes are left at -1 (and never cast to indices)
        near = np.flatnonzero(np.all((ci > -(r + 1)) & (ci < np.asarray(self.grid.shape) + r), axis=1))
        if near.size == 0:
            return best
        ci = ci[near]
        base = np.rint(ci).astype(np.int64)
        offs = np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * d), indexing="ij"), axis=-1).reshape(-1, d)
        lengths = np.sqrt((offs * offs).sum(1))
        order = np.argsort(lengths, kind="stable")
        # |ci − base| ≤ √d/2, so a node at offset o lies at least |o| − √d/2 from the point
        slack = 0.5 * np.sqrt(d)
        open_ = np.arange(len(near))
        bd = np.full(len(near), np.inf)
        bp = np.full(len(near), -1, dtype=np.int64)
        for o, length in zip(offs[order], lengths[order]):
            open_ = open_[bd[open_] > length - slack]
            if open_.size == 0:
                break
            idx = base[open_] + o
            pos = self._band.find(np.ascontiguousarray(idx))
            ok = pos >= 0
            if not np.any(ok):
                continue
            dist = np.linalg.norm(idx - ci[open_], axis=1)
            take = ok & (dist < bd[open_]) & (dist <= self.outer + 1)
            bp[open_[take]] = pos[take]
            bd[open_[take]] = dist[take]
        found = bp >= 0
        bp[found & ~np.isfinite(self.values[np.maximum(bp, 0)])] = -1
        best[near] = bp
        return best

    def nearest_source(self, points: Any = None) -> np.ndarray:
        """Which source reaches each place first: indices into :attr:`sources`.

        For speed 1 the labels partition the surface into the geodesic Voronoi cells of the sources.
        They are recovered from the solved values (each node takes the label of its smallest,
        earlier-reached neighbour) and are first-order accurate like the values: nodes within about a
        grid spacing of a cell boundary may take the neighbouring cell's label.

        Parameters
        ----------
        points : array_like, optional
            ``(M, d)`` points, e.g. the vertices of a mesh of the surface. Default: one label per band
            node, aligned with :attr:`values`.

        Returns
        -------
        numpy.ndarray
            Labels (int); -1 where no front arrives (another component of the surface) or, for points,
            where no band node lies within ``outer + 1`` grid spacings.

        Raises
        ------
        ValueError
            For a solution with several sources under an anisotropic Hamiltonian (a moving medium or
            a metric), where the smallest neighbour is not the one the front came from: solve each
            source on one :class:`Tube` and take the argmin of the values instead.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [(0.5, 0, 0), (-0.5, 0, 0)])
        >>> sol.nearest_source([(0.4, 0.3, 0.0), (-0.4, 0.0, 0.3)]).tolist()
        [0, 1]
        """
        if not self._isotropic and len(self.sources) > 1:
            raise ValueError(
                f"nearest_source needs an isotropic Hamiltonian (godunov, lxf or Isotropic()); this solution is "
                f"{self.hamiltonian!r}. Solve each source on one ts.Tube and take the argmin of the values instead"
            )
        if self._labels is None:
            positions, sources = self._fixed
            self._labels = self._band.nearest_source_labels(
                np.ascontiguousarray(self.values, dtype=float),
                np.ascontiguousarray(positions, dtype=np.int64),
                np.ascontiguousarray(sources, dtype=np.int64),
            )
        labels: np.ndarray = self._labels
        if points is None:
            return labels.copy()
        p = as_points(points, self.grid.ndim, "points")
        pos = self._nearest_reached(p)
        return np.where(pos >= 0, labels[np.maximum(pos, 0)], -1)

    def geodesic_path(self, start: Any, *, step: float = 0.5, max_steps: Optional[int] = None) -> np.ndarray:
        """The shortest path on the surface from ``start`` to the source whose front reaches it first.

        Traced backwards along the characteristics: steps of ``step`` grid spacings against the
        gradient of the solution, each projected back onto the surface (see
        :mod:`tubesweep.geodesic_paths`). For speed F(x) it is the path of least travel time. Where
        two sources lie within a few grid spacings of each other, the path ends at the one it comes
        within two spacings of first.

        Parameters
        ----------
        start : array_like
            ``(d,)`` a point on the surface (within the inner tube).
        step : float
            Step length in grid spacings (default 0.5, at least 0.01).
        max_steps : int, optional
            The most steps to take (default: enough for a path four times the largest value).

        Returns
        -------
        numpy.ndarray
            ``(P, d)`` the polyline from the start to the source.

        Raises
        ------
        ValueError
            For a start off the surface, outside the band or on a part no source reaches; for an
            anisotropic Hamiltonian (under a moving medium or a metric the fastest path does not run
            against ∇u).

        Warns
        -----
        RuntimeWarning
            If the path stopped before reaching a source (a cut locus, a region the scheme resolves
            poorly, or a gap narrower than the tubes nearby).

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [(-0.5, 0, 0)])
        >>> path = sol.geodesic_path((0.0, 0.5, 0.0))  # a quarter of a great circle, length ≈ π/4
        """
        p = as_points(start, self.grid.ndim, "start")
        if len(p) != 1:
            raise ValueError(
                f"start must be one point of shape ({self.grid.ndim},); got {len(p)} points "
                "(use geodesic_paths for several)"
            )
        return self.geodesic_paths(p, step=step, max_steps=max_steps)[0]

    def geodesic_paths(self, starts: Any, *, step: float = 0.5, max_steps: Optional[int] = None) -> List[np.ndarray]:
        """:meth:`geodesic_path` from each of several starts, traced together.

        Parameters
        ----------
        starts : array_like
            ``(M, d)`` points on the surface.
        step : float
            Step length in grid spacings (default 0.5).
        max_steps : int, optional
            The most steps per path.

        Returns
        -------
        list of numpy.ndarray
            One ``(P_i, d)`` polyline per start.

        Raises
        ------
        ValueError
            As :meth:`geodesic_path`, naming the first bad start.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [(-0.5, 0, 0)])
        >>> paths = sol.geodesic_paths([(0.0, 0.5, 0.0), (0.0, 0.0, 0.5)])
        """
        from .geodesic_paths import trace_paths

        return trace_paths(self, starts, step=step, max_steps=max_steps)

    def to_dense(self, fill: float = np.nan) -> np.ndarray:
        """The solution as an array of the grid's shape (allocates the whole box).

        Parameters
        ----------
        fill : float
            The value off the band (default NaN).

        Returns
        -------
        numpy.ndarray
            Array of ``grid.shape``.

        Raises
        ------
        TypeError
            If ``fill`` is not a real number.

        Examples
        --------
        >>> import tubesweep as ts
        >>> c = ts.surfaces.Circle(0.5)
        >>> sol = ts.solve(c, ts.Grid((-1, -1), (1, 1), (101, 101)), [c.default_source])
        >>> sol.to_dense().shape
        (101, 101)
        """
        value = real_scalar(fill, "fill", "a real number (the value outside the band, NaN by default)")
        check_memory(
            8 * self.grid.size,
            f"the dense {self.grid.shape} array",
            "keep the band's values (sol.values) or interpolate at the points you need (sol(points))",
        )
        out = np.full(self.grid.size, value, dtype=float)
        out[self.linear] = self.values
        return out.reshape(self.grid.shape)


def _tube_roles(geom: BandGeometry, inner_width: float, method: str) -> np.ndarray:
    """Roles of the band nodes: inner tube where ``|φ| ≤ inner·Δx`` (every node for the naive
    method), else extension layer; chunk by chunk, without K-sized temporaries."""
    roles = np.full(len(geom.linear), ROLE_INNER if method == "naive" else ROLE_OUTER, np.uint8)
    if method != "naive":
        limit = inner_width * (1 + ROLE_RTOL)
        for lo in range(0, len(roles), _ROLE_CHUNK):
            part = roles[lo : lo + _ROLE_CHUNK]
            part[geom.unsigned(lo, lo + _ROLE_CHUNK) <= limit] = ROLE_INNER
    return roles


def _fix_sources(
    surface: Surface,
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    sources: np.ndarray,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    source_init: str,
    inner_width: float,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions in the band and values of the nodes fixed by the point sources, and the index of
    the source each node's value comes from (the nearest, where several sources fix one node)."""
    h = grid.spacing
    d = grid.ndim
    dist, proj = surface.project(sources, grid)
    for i, (dd, s) in enumerate(zip(dist, sources)):
        if dd > inner_width * (1 + 1e-6):
            raise ValueError(
                f"sources[{i}] = {tuple(float(x) for x in s)} is {dd:.4g} from the surface, farther than the inner tube "
                f"(inner·Δx = {inner_width:.4g}); put the source on the surface or increase `inner`"
            )
    best: dict = {}
    r = int(np.ceil(SOURCE_RADIUS + inner_width / h)) + 1
    offsets = np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * d), indexing="ij"), axis=-1).reshape(-1, d)
    for i, (s, sp) in enumerate(zip(sources, proj)):
        if source_init == "node":
            idx = grid.nearest_index(s[None])
            pos = int(band.find(idx)[0])
            if pos < 0 or roles[pos] != ROLE_INNER:
                raise ValueError(
                    f"sources[{i}]: the grid node nearest to the source is not in the inner tube; "
                    "move the source onto the surface, refine the grid or increase `inner`"
                )
            if pos not in best or best[pos][0] > 0.0:
                best[pos] = (0.0, i)
            continue
        idx = np.floor(grid.continuous_index(s[None])[0]).astype(np.int64) + offsets
        pos = band.find(np.ascontiguousarray(idx))
        ok = pos >= 0
        pos = pos[ok]
        pos = pos[roles[pos] == ROLE_INNER]
        if pos.size == 0:
            raise ValueError(f"sources[{i}] has no inner-tube node near it; refine the grid or increase `inner`")
        x = grid.points(grid.unravel(linear[pos]))
        _, cp = surface.project(x, grid)
        geo = np.linalg.norm(cp - sp, axis=1)
        near = geo <= SOURCE_RADIUS * h
        if not np.any(near):
            near = geo <= geo.min()
        slow = 0.5 * (slowness_at(cp[near]) + slowness_at(sp[None])[0])
        for p, v in zip(pos[near], geo[near] * slow):
            if p not in best or v < best[p][0]:
                best[p] = (v, i)
    positions = np.fromiter(best.keys(), dtype=np.int64, count=len(best))
    values = np.fromiter((v for v, _ in best.values()), dtype=float, count=len(best))
    labels = np.fromiter((k for _, k in best.values()), dtype=np.int64, count=len(best))
    return positions, values, labels


def solve(
    surface: Any,
    grid: Grid,
    sources: Any,
    *,
    hamiltonian: Any = "godunov",
    speed: Any = 1.0,
    flow: Any = None,
    allow_supersonic: bool = False,
    inner: float = 2.0,
    outer: float = 4.0,
    method: str = "two-layer",
    source_init: str = "exact",
    tol: float = DEFAULT_TOL,
    max_iterations: int = 10000,
    progress: Optional[Callable[[int, float, int], None]] = None,
    infinity: Optional[float] = None,
    threads: int = 0,
    paper_sweeps: bool = False,
    order: int = 1,
) -> Solution:
    """First-arrival time (geodesic distance for ``speed=1``) on an implicit curve or surface.

    Solves ``|∇_Σ u| = 1/F`` on Σ by the embedding of the paper: the eikonal equation
    ``|∇u| = 1/F`` in the inner tube ``|φ| ≤ inner·Δx`` (Godunov, Eq. 3, or Lax–Friedrichs, Eq. 4)
    and, for ``method="two-layer"`` (Algorithm 3), the extension equation (8)
    ``[sgn(φ) n]·∇u = 0`` in the layer ``inner·Δx < |φ| ≤ outer·Δx`` with the upwind update (5).
    ``method="naive"`` is Algorithm 2 (one tube ``|φ| ≤ inner·Δx``, numerical infinity outside);
    it is kept as the baseline that does not converge for a tube of width O(Δx) (Sect. 3).

    Only the band nodes are stored and swept; for a callable φ the band is found coarse-to-fine,
    so memory and work are O(N^(d−1)).

    Parameters
    ----------
    surface : LevelSet, ClosestPoint, library surface, φ array of ``grid.shape`` or callable φ
    grid : Grid
        The uniform grid; the surface must lie inside it, a few grid spacings from its sides.
    sources : array-like (K, d)
        Points on the surface (within the inner tube).
    hamiltonian : {"godunov", "lxf"} or a ``ts.hamiltonians`` object
        A :class:`tubesweep.hamiltonians.Hamiltonian` (``Isotropic()``, ``MovingMedium(v)``,
        ``Metric(M)``) solves ``H(x, ∇u) = 0`` with the general Lax–Friedrichs update of Sect. 5.1.
    speed : float, ndarray of ``grid.shape``, or callable ``F(points) -> (M,)``
        The speed F > 0 (1: geodesic distance).
    flow : callable ``v(points (M, d)) -> (M, d)`` or array of ``grid.shape + (d,)``, optional
        Ambient flow of a moving medium: solves ``|∇u| = |1 − v·∇u| / F`` (Sect. 6.3) with the
        Lax–Friedrichs update of Sect. 5.1 (shorthand for ``hamiltonian=ts.hamiltonians.MovingMedium(flow)``).
        ``|v| ≥ F`` anywhere in the inner tube is a ``ValueError``; see ``allow_supersonic``.
    allow_supersonic : bool
        Compute the moving-medium solution even where ``|v| ≥ F`` (with a warning).
    inner, outer : float
        Tube half-widths in grid spacings (paper: 2 and 4; 5 for the bunny).
    method : {"two-layer", "naive"}
        Algorithm 3 (default) or Algorithm 2, the baseline that does not converge.
    source_init : {"exact", "node"}
        ``"node"`` is the paper's choice (u = 0 at the grid node nearest each source);
        ``"exact"`` fixes the inner nodes whose closest point is within ``SOURCE_RADIUS``·Δx of a
        source to the exact local distance. ``"exact"`` is the default: 2–8× more accurate with
        Lax–Friedrichs, and first order with Godunov on the sphere where ``"node"`` stagnates;
        ``"node"`` is about 25% more accurate with Godunov on a circle and on coarse spheres
        (``tubesweep reproduce source-init``, ``docs/source-initialisation.md``).
    tol, max_iterations : float, int
        Stop when no value changes by more than ``tol`` in an iteration of 2^d sweeps, or after
        ``max_iterations`` (then ``stats.converged`` is False, with a warning). ``tol`` defaults
        to 1e-10 for ``order=1`` and to ``1e-3 Δx²`` times the mean slowness for ``order=2``.
    progress : callable, optional
        Called after every iteration as ``progress(iteration, max_change, updates)``.
    threads : int
        Worker threads for the sweeps (0: all cores, 1: sequential); the result does not depend
        on it (parallel sweeps are bit-identical to sequential ones).
    infinity : float, optional
        The finite numerical infinity unknown values start at (default: derived from the band, a
        safe upper bound on every travel time); it only affects the Lax–Friedrichs iteration count.
        A user value must exceed every travel time: values within a millionth of it count as
        never reached and are returned as ``inf``.
    paper_sweeps : bool
        ``True`` runs the paper's plain sweeps: pointwise Gauss–Seidel updates over the whole band
        in every iteration (nodes none of whose neighbours changed are still skipped, which changes
        nothing); this reproduces its iteration counts (Table 2). The default solves the same
        discrete equations, to the same solution within about ``tol``, with three accelerations
        (docs/architecture.md): with Godunov, each inner-tube node is updated together with the
        extension-layer nodes that copy it (block Gauss–Seidel; sphere N=1001: 38 instead of 55
        iterations); the *outer rim* (layer nodes no inner node depends on) is left out until
        the rest has converged, then evaluated once in dependency order; and, with Godunov on surfaces,
        the sweeps run behind a *front window* (only nodes within a few front steps of the
        smallest still-changing value are updated, and the band fills from the sources outwards):
        3× fewer local updates on the sphere at N=201, 5× at N=1001, and 2–4× less time
        (``benches/sweep_variants.py``).

    order : {1, 2}
        1: the paper's first-order scheme (the default). 2: second order (docs/second-order.md):
        the metric-corrected tube equation with limited BDF2 differences and factored point
        sources, for level sets (arrays, callables, library surfaces) with the Godunov update;
        ``sol.stats.order2`` reports its phases. A surface whose curvature the tube does not
        resolve (``outer·Δx·κ ≥ 1``), a φ that is not a signed distance (without
        ``redistance=True``) and closest-point surfaces (meshes, open surfaces) are refused with
        a ``ValueError``.

    Returns
    -------
    Solution
        The values on the band nodes, with :attr:`Solution.stats`; call it to interpolate.

    Raises
    ------
    ValueError
        For input that cannot give a right answer, with the argument named and the fix: a source
        off the surface, a grid too coarse for the surface, φ far from a distance function (use
        ``ts.LevelSet(phi, redistance=True)``), a supersonic flow, bad widths or tolerances, a
        band larger than the memory available.
    TypeError
        For arguments of the wrong type (a surface that is neither φ, a callable nor a Surface).

    Warns
    -----
    RuntimeWarning
        Where the surface faces itself across gaps narrower than the tubes (the front may cross
        there; :meth:`Solution.narrow_gaps`), where the extension layer had to be widened, or when
        the sweeps have not converged within ``max_iterations``.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid(lower=(-1, -1, -1), upper=(1, 1, 1), shape=(101, 101, 101))
    >>> sphere = lambda p: np.linalg.norm(p, axis=1) - 0.5
    >>> sol = ts.solve(sphere, grid, sources=[(-0.5, 0, 0)])
    >>> sol([(0, 0.5, 0)])  # exact π/4 = 0.785  # doctest: +ELLIPSIS
    array([0.77...])
    """
    t0 = time.perf_counter()
    order = _check_order(order)
    grid = as_grid(grid)
    surf = as_surface(surface)
    surf.check_grid(grid)
    src = as_sources(sources, grid)
    general, scheme = _resolve_scheme(hamiltonian, flow, allow_supersonic)
    if order == 2:
        from . import second_order as _so

        check_tolerance(tol, max_iterations)
        cb = progress_callback(progress)
        _check_source_init(source_init)
        _so.check_supported(surf, general, scheme, method, source_init, paper_sweeps)
        tube = _prepare_tube(surf, grid, inner, outer, method, keep_geometry=True)
        return _so.solve_on_tube(tube, src, speed, None if tol == DEFAULT_TOL else tol, max_iterations, cb, threads, t0)
    check_tolerance(tol, max_iterations)
    cb = progress_callback(progress)
    _check_source_init(source_init)
    # the one call keeps nothing for later: the float64 geometry is dropped before the sweeps
    # (unless a general Hamiltonian needs it) and the directions become the extension weights
    tube = _prepare_tube(surf, grid, inner, outer, method, keep_geometry=general is not None)
    return _solve_on_tube(
        tube,
        src,
        general,
        scheme,
        speed,
        source_init,
        tol,
        max_iterations,
        cb,
        infinity,
        threads,
        paper_sweeps,
        t0,
        reuse=False,
    )


def _check_order(order: Any) -> int:
    from .second_order import check_order

    return check_order(order)


def _resolve_scheme(hamiltonian: Any, flow: Any, allow_supersonic: bool) -> Tuple[Any, str]:
    from . import hamiltonians as _hams

    general = _hams.resolve(hamiltonian, flow, allow_supersonic)
    scheme = check_hamiltonian(hamiltonian) if general is None else general.label
    return general, scheme


def _check_source_init(source_init: str) -> None:
    if source_init not in SOURCE_INITS:
        raise ValueError(f"source_init must be one of {SOURCE_INITS}; got {source_init!r}")


@dataclasses.dataclass
class _PreparedTube:
    """The band of a surface on a grid with what every solve on it needs: the sorted linear
    indices, the roles before the sources are fixed, the native band, φ in single precision, and
    either the directions the solver may overwrite (``direction``; one solve) or the whole
    geometry (``geom``, never modified; a general Hamiltonian reads it, and a :class:`Tube`
    solves many times). ``seconds``: the time the preparation took."""

    grid: Grid
    surface: Surface
    inner: float
    outer_eff: float
    method: str
    geom: Optional[BandGeometry]
    linear: np.ndarray
    roles: np.ndarray
    band: Any
    phi: np.ndarray
    direction: Optional[np.ndarray]
    seconds: float
    #: the pairs of neighbouring nodes across a gap narrower than the tubes: their band positions
    #: and their gaps (``_warn_if_tubes_touch``)
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray] = (np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0))


# The memory a solve adds per band node at its peak, for the check below: 57–58 B for `ts.solve` at
# N = 1001 and 2001 (`benches/run.py --scale`), more through `ts.Tube` and the general Hamiltonians
# (up to about 110 B at N = 301).
_BAND_BYTES_PER_NODE = 110
# Points per axis (along the box's longest side) of the coarse sample that estimates the band.
_BAND_ESTIMATE_POINTS = 17


def _check_band_memory(surf: Surface, grid: Grid, half_width: float) -> None:
    """Raises MemoryError before the band search when the band would not fit in memory. Skipped
    when even a band filling the whole box would fit (every grid up to a few hundred nodes per
    axis); otherwise the surface's area is estimated from its distance at a coarse sample of the
    box (the nodes within one coarse spacing H of it fill a shell of volume ≈ 2·H·area), and the
    band of half-width w holds about 2·w·area / h^d nodes."""
    avail = available_memory_bytes()
    if avail is None or grid.size * _BAND_BYTES_PER_NODE <= 0.9 * avail or getattr(surf, "redistance", False):
        return
    nodes = _estimated_band_nodes(surf, grid, half_width)
    check_memory(
        nodes * _BAND_BYTES_PER_NODE,
        f"the band (about {nodes:.3g} nodes at grid spacing {grid.spacing:.3g})",
        "use a coarser grid (fewer nodes per axis) or a thinner tube",
    )


def _estimated_band_nodes(surf: Surface, grid: Grid, half_width: float) -> float:
    """About how many nodes of ``grid`` lie within ``half_width`` of ``surf`` (see
    :func:`_check_band_memory`), from the surface's distance at a coarse sample of the box."""
    lower, upper = np.asarray(grid.lower, dtype=float), np.asarray(grid.upper, dtype=float)
    big_h = float(np.max(upper - lower)) / (_BAND_ESTIMATE_POINTS - 1)
    axes = [np.minimum(np.arange(lo, hi + 0.5 * big_h, big_h), hi) for lo, hi in zip(lower, upper)]
    points = np.stack([c.reshape(-1) for c in np.meshgrid(*axes, indexing="ij")], axis=1)
    try:
        dist = np.asarray(surf.project(points, grid)[0], dtype=float)
    except Exception:  # a surface undefined at some sample far from it: no estimate, the search decides
        return 0.0
    area = np.count_nonzero(np.isfinite(dist) & (dist <= big_h)) * big_h**grid.ndim / (2 * big_h)
    return 2 * half_width * area / grid.spacing**grid.ndim


def _lacking_neighbours(grid: Grid, band: Any, linear: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """The linear indices (sorted, unique) of the in-grid neighbours that the band nodes
    ``missing`` (band positions) lack in the band."""
    lacking = [np.empty(0, np.int64)]
    for moved, inside, pos in band_neighbours(grid, band, linear, missing):
        absent = moved[inside & (pos < 0)]
        lacking.append(np.ravel_multi_index(tuple(absent.T), grid.shape).astype(np.int64))
    return np.unique(np.concatenate(lacking))


def _ridge_pairs(
    grid: Grid, band: Any, linear: np.ndarray, roles: np.ndarray, phi: np.ndarray, kink: Optional[np.ndarray]
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs of neighbouring band nodes of which one straddles a kink of a level set's φ (a
    ridge between facing parts, ``BandGeometry.kink``) and one lies in the inner tube, with the
    gap ``2|φ|`` at the kink's node. There the central differences give no reliable direction,
    so the directions' tests of ``Band.facing_sheet_pairs`` can miss the pair (two spheres
    ``min(d₁, d₂)`` 5 spacings apart were crossed without a word)."""
    empty = np.empty(0, np.int64)
    if kink is None or not np.any(kink):
        return empty, empty, np.empty(0)
    at = np.flatnonzero(kink)
    nodes, neighbours = [], []
    for _, _, pos in band_neighbours(grid, band, linear, at):
        ok = pos >= 0
        a, b = at[ok], pos[ok]
        ok = (roles[a] == ROLE_INNER) | (roles[b] == ROLE_INNER)
        a, b = a[ok], b[ok]
        nodes.append(np.minimum(a, b))
        neighbours.append(np.maximum(a, b))
    node, neighbour = np.concatenate(nodes), np.concatenate(neighbours)
    gap = 2.0 * np.abs(phi[np.where(kink[node], node, neighbour)]).astype(float)
    return node, neighbour, gap


def _warn_if_tubes_touch(
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    phi: np.ndarray,
    direction: np.ndarray,
    inner: float,
    kink: Optional[np.ndarray] = None,
    noise: float = 0.0,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Warns where two parts of the surface face each other across a gap so narrow that the inner
    tube of one touches the band of the other (``_native.Band.facing_sheet_pairs``,
    ``tubesweep_core::facing_sheets``): the eikonal equation crosses the gap there and the travel
    times beyond it come out too short, a shortcut the surface does not have. Returns the pairs'
    band positions and their gaps."""
    h = grid.spacing
    node, neighbour, gap = band.facing_sheet_pairs(
        roles == ROLE_INNER,
        np.ascontiguousarray(phi, dtype=np.float32),
        np.ascontiguousarray(direction, dtype=np.float32).reshape(len(linear), grid.ndim),
        h,
    )
    if noise > 0 and node.size:
        # a noisy closest-point map (``_cp_checks``): nodes within a few times its noise of the
        # surface have directions the noise can turn around, which the facing test would read as
        # two sheets (at noise 0.01 spacings, 13 pairs on a sphere); they are left out
        clear = 4.0 * noise
        keep = (np.abs(phi[node]) > clear) & (np.abs(phi[neighbour]) > clear)
        node, neighbour, gap = node[keep], neighbour[keep], gap[keep]
    ridge = _ridge_pairs(grid, band, linear, roles, phi, kink)
    if ridge[0].size:
        node, neighbour, gap = (np.concatenate([x, y]) for x, y in zip((node, neighbour, gap), ridge))
        # a pair found both ways counts once (the smaller gap)
        order = np.lexsort((gap, neighbour, node))
        node, neighbour, gap = node[order], neighbour[order], gap[order]
        first = np.ones(node.size, bool)
        first[1:] = (node[1:] != node[:-1]) | (neighbour[1:] != neighbour[:-1])
        node, neighbour, gap = node[first], neighbour[first], gap[first]
    if node.size == 0:
        return node, neighbour, gap
    narrowest = int(np.argmin(gap))
    where = ", ".join(f"{float(v):.4g}" for v in grid.node_points(linear[node[narrowest : narrowest + 1]])[0])
    needed = float(gap[narrowest]) / (2 * inner + 2)
    # how much of the surface: the inner-tube nodes of the pairs among all inner-tube nodes
    inner_nodes = roles == ROLE_INNER
    touched = np.unique(np.concatenate([node, neighbour]))
    share = np.count_nonzero(inner_nodes[touched]) / max(int(np.count_nonzero(inner_nodes)), 1)
    warnings.warn(
        f"the surface faces itself across gaps narrower than its tubes at {node.size} node pair(s), about "
        f"{_percent(share)} of the surface (the narrowest {float(gap[narrowest]):.3g} wide, near ({where})). Distances "
        "reached across such a gap can come out too short; elsewhere the result holds. sol.narrow_gaps() shows where; "
        f"a grid spacing below {needed:.3g} (now {h:.3g}) resolves a real gap, while a crease or scan artefact stays "
        "narrower than any grid",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
    return node, neighbour, gap


def _percent(share: float) -> str:
    """A share as a short percentage: '0.1%', '12%', or '< 0.01%'."""
    if share < 1e-4:
        return "< 0.01%"
    return f"{100 * share:.2g}%" if share < 0.1 else f"{100 * share:.0f}%"


def _check_surface_spans_two_cells(
    surf: Surface, grid: Grid, linear: np.ndarray, roles: np.ndarray, inner: float
) -> None:
    """Refuses a surface that the grid cannot resolve: one whose closest points from the inner
    tube span less than two grid spacings along every axis of their bounding box (a disc or plane
    patch smaller than a cell; on a disc of radius 0.02Δx the distances came out 29% short, with
    no warning; a closed mesh or closest-point curve that small too, while a level set that small
    is refused earlier, by the distance check, its tube reaching the centre). The inner tube of a surface that small has at most ``(2·inner + 3)^d`` nodes, so the
    closest points are computed only for a band that small: nothing is added to other solves."""
    h = grid.spacing
    # counted before they are listed: the list of a large band's inner nodes (8 bytes per inner
    # node) would raise the set-up's peak memory
    n_inner = int(np.count_nonzero(roles == ROLE_INNER))
    if n_inner == 0 or n_inner > (2 * int(np.ceil(inner)) + 3) ** grid.ndim:
        return
    inner_nodes = np.flatnonzero(roles == ROLE_INNER)
    _, closest = surf.project(grid.node_points(linear[inner_nodes]), grid)
    closest = closest[np.all(np.isfinite(closest), axis=1)]
    if closest.size == 0:
        return
    extent = float(np.max(np.ptp(closest, axis=0)))
    if extent == 0.0:
        raise ValueError(
            "the surface is a single point: every node of the inner tube has the same closest point "
            f"{tuple(float(x) for x in closest[0])}, so there is no curve or surface to solve on (for a "
            "closest-point map, check that cp returns the nearest point of the surface)"
        )
    if extent < 2.0 * h:
        raise ValueError(
            f"the grid is too coarse for this surface: the surface spans only {extent:.3g} along the longest side of "
            f"its bounding box (from the inner tube's closest points), less than two grid spacings (h = {h:.4g}), so the "
            f"grid cannot resolve it; refine the grid to a spacing below {extent / 2:.3g}, or shrink the box"
        )


def _widening_message(missing: np.ndarray, phi: np.ndarray, h: float, inner: float, outer: float) -> str:
    """Why inner-tube nodes (band positions ``missing``) lack a neighbour in the band of half-width
    ``outer`` spacings. For a distance function a neighbour lies at most one spacing farther from
    the surface, so an inner node within ``outer − 1`` spacings of it whose neighbour falls
    outside says φ is not a distance function there; when every such node lies beyond that (only
    possible when ``outer − inner`` is about 1) the extension layer is merely too thin to hold the
    neighbours, rounding included, and φ is not to blame."""
    far = np.abs(phi[missing].astype(float)) > (outer - 1.0) * h * (1 - 1e-6)
    widen = f"Widening the extension layer to outer = {outer + 1}"
    if np.all(far):
        return (
            f"{missing.size} inner-tube nodes had a neighbour outside the band with outer = {outer}: the extension "
            f"layer (outer − inner = {outer - inner:g} grid spacings) is too thin to hold every neighbour of the inner "
            f"tube (a neighbour can lie a full spacing farther out, and rounding puts some just beyond). {widen}; "
            "pass outer ≥ inner + 2 to avoid this"
        )
    return (
        f"{missing.size} inner-tube nodes had a neighbour outside the band with outer = {outer}: φ is not close to a "
        f"distance function there (at {int(np.count_nonzero(~far))} of them the neighbour is more than one spacing "
        f"farther out in φ). {widen}"
    )


def _prepare_tube(
    surf: Surface, grid: Grid, inner: float, outer: float, method: str, keep_geometry: bool, reusable: bool = False
) -> _PreparedTube:
    """The band of ``surf`` (Algorithm 3's inner tube and extension layer, or Algorithm 2's
    single tube) with its roles, widened while inner nodes lack a neighbour in it. ``reusable``
    keeps the geometry unmodified for many solves (:class:`Tube`)."""
    t0 = time.perf_counter()
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    widths = []
    for name, val in (("inner", inner), ("outer", outer)):
        w = real_scalar(val, name, "a finite number of grid spacings")
        if not np.isfinite(w):
            raise ValueError(f"{name} must be a finite number of grid spacings; got {val!r}")
        widths.append(w)
    inner, outer = widths
    if inner < 1.0:
        raise ValueError(
            f"inner = {inner} grid spacings is thinner than the grid can resolve: the inner tube needs at least 1 "
            "(the paper uses 2)"
        )
    if method == "two-layer" and outer < inner + 1.0:
        raise ValueError(
            f"outer = {outer} must exceed inner = {inner} by at least 1 grid spacing so that the extension layer "
            "holds every neighbour of the inner tube (the paper uses inner=2, outer=4)"
        )
    h = grid.spacing
    inner_width = inner * h
    outer_eff = float(outer) if method == "two-layer" else float(inner)

    _check_band_memory(surf, grid, outer_eff * h)
    # a re-distanced band, and the bound on |∇φ| its candidates were found with when the user gave it
    redistanced = bool(getattr(surf, "redistance", False))
    given_bound = getattr(surf, "lipschitz", None) if redistanced else None
    previously_lacking: Optional[np.ndarray] = None
    for attempt in range(_MAX_WIDENINGS + 1):
        # (catch_warnings only where needed: entering and leaving it resets Python's record of the
        # warnings already shown, and a solve repeated in a loop would then repeat its warnings)
        with warnings.catch_warnings() if attempt > 0 else contextlib.nullcontext():
            if attempt > 0:  # a warning about the band's nodes was given at the first attempt
                warnings.filterwarnings("ignore", message=".*could not be projected onto it", category=RuntimeWarning)
            geom = surf.band(grid, outer_eff * h)
        if geom.linear.size == 0:
            raise ValueError(
                "the band is empty: no grid node lies within the tube; check that the surface passes through the grid "
                "and that φ is in the grid's units"
            )
        roles = _tube_roles(geom, inner_width, method)
        linear = geom.linear
        if attempt == 0:
            _check_surface_spans_two_cells(surf, grid, linear, roles, inner)
        band = geom.native_band  # built by the surface, or None
        # The float64 φ (and |φ| where stored) only decide the roles: from here on the solver
        # keeps φ in single precision, and the band is built without them (memory is per band
        # node: see docs/architecture.md).
        phi = geom.signed.astype(np.float32)
        kink = geom.kink
        direction: Optional[np.ndarray] = None
        if reusable:
            # kept for every solve: the solver gets copies of its directions
            geom = dataclasses.replace(geom, consumable=False)
        elif not keep_geometry:
            direction = geom.directions_for_solver()
            geom = None  # type: ignore[assignment]
        if band is None or len(band) != len(linear):
            band = _native.Band.from_linear(
                list(grid.shape), np.ascontiguousarray(linear, dtype=np.int64).view(np.uint64)
            )
        if method == "naive":
            break
        missing = band.nodes_missing_neighbours(roles == ROLE_INNER)
        if missing.size == 0:
            break
        lacking = _lacking_neighbours(grid, band, linear, missing)
        if (
            redistanced
            and given_bound is None
            and previously_lacking is not None
            and np.all(np.isin(previously_lacking, lacking))
        ):
            # A re-distanced band, its candidates found with an estimated bound on |∇φ|, holds the
            # nodes within the layer that could be projected onto the zero level set; the layer
            # was widened and none of the missing neighbours came in, so they are nodes the
            # projection cannot place (the box's |x|_∞ − r at N = 41 widened four times in 13 s
            # before ending in the error below). Going on without them gave wrong answers
            # elsewhere (a circle 3 spacings in radius came out far short at its antipode), so the
            # solve stops here. With a given bound below |∇φ| the candidates depend on the
            # layer's width and a later widening can still bring them in: widened as for any φ.
            raise ValueError(
                f"{lacking.size} nodes next to the inner tube could not be projected onto φ's zero level set, and a wider "
                "extension layer does not bring them in: the zero level set has sharp edges or corners there, or the "
                "surface is not much larger than the tube (its radius of curvature about the tube's width). Smooth φ "
                "there (round the edges over a few grid spacings), pass a signed distance function, or refine the grid"
            )
        previously_lacking = lacking
        if attempt == _MAX_WIDENINGS:
            raise ValueError(
                f"the extension layer does not enclose the inner tube even with outer = {outer_eff}: {missing.size} "
                "inner nodes lack a neighbour. "
                + (
                    ""
                    if redistanced
                    else "φ is far from a distance function (use ts.LevelSet(phi, redistance=True)), or "
                )
                + "the grid is too coarse for the surface (the tube reaches across it, e.g. a sphere not much larger "
                "than the tube: refine the grid)"
                + (
                    ""
                    if given_bound is None
                    else f", or the lipschitz bound given, {given_bound:g}, is below |∇φ| near "
                    "the surface and keeps nodes from the band's candidates (leave it out to have it estimated)"
                )
            )
        warnings.warn(
            _widening_message(missing, phi, h, inner, outer_eff), RuntimeWarning, stacklevel=user_stacklevel()
        )
        outer_eff += 1.0
    facing = _warn_if_tubes_touch(
        grid,
        band,
        linear,
        roles,
        phi,
        direction if direction is not None else geom.direction,
        inner,
        kink,
        float(getattr(surf, "_noise", 0.0)),
    )
    return _PreparedTube(
        grid,
        surf,
        float(inner),
        outer_eff,
        method,
        geom,
        linear,
        roles,
        band,
        phi,
        direction,
        time.perf_counter() - t0,
        facing,
    )


def _solve_on_tube(
    tube: _PreparedTube,
    src: np.ndarray,
    general: Any,
    scheme: str,
    speed: Any,
    source_init: str,
    tol: float,
    max_iterations: int,
    cb: Any,
    infinity: Any,
    threads: int,
    paper_sweeps: bool,
    t0: float,
    reuse: bool,
) -> "Solution":
    """Fixes the sources on the prepared tube and sweeps. With ``reuse`` the tube is left as it
    was (its roles and directions are copied); without, its arrays are consumed and dropped
    before the sweeps."""
    from . import hamiltonians as _hams

    if not isinstance(paper_sweeps, (bool, np.bool_)):
        raise TypeError(f"paper_sweeps must be True or False; got {paper_sweeps!r}")
    grid, surf, band = tube.grid, tube.surface, tube.band
    h = grid.spacing
    inner_width = tube.inner * h
    roles = tube.roles.copy() if reuse else tube.roles
    linear = tube.linear
    # node coordinates only for a speed given as a callable (an array is read at the nodes)
    x = grid.node_points(linear) if callable(speed) else np.empty((len(linear), 0))
    speed_nodes = speed_values(speed, grid, x, linear)
    slowness: Any = 1.0 / speed_nodes

    def slowness_at(p: np.ndarray) -> np.ndarray:
        if callable(speed):
            return 1.0 / speed_at_points(speed, p, "a source or the closest point of a node near it")
        if np.ndim(speed) == 0:
            return np.full(len(p), 1.0 / float(speed))
        from .euclidean import _interp_dense

        f = _interp_dense(np.asarray(speed, dtype=float), grid, p)
        return 1.0 / checked_point_speeds(f, p, "interpolated from the speed array next to a source")

    check_tolerance_scale(tol, h, float(np.mean(slowness)), max(grid.shape))
    positions, fixed_vals, fixed_sources = _fix_sources(
        surf, grid, band, linear, roles, src, slowness_at, source_init, inner_width
    )
    roles[positions] = ROLE_FIXED
    if tube.method != "naive" and len(src) == 1 and not np.any(roles == ROLE_INNER):
        raise ValueError(
            f"the grid is too coarse for this surface: every node of the inner tube lies within {SOURCE_RADIUS:g} grid "
            f"spacings (h = {h:.4g}) of a source, so its value is the source's initialisation and nothing is solved; "
            f"refine the grid"
        )
    del x
    method = tube.method
    missing_policy = "infinity" if (method == "naive" and scheme == "godunov") else "extrapolate"
    phi = tube.phi
    array = getattr(surf, "_array", None)
    phi_sample = None
    if array is not None:
        # a φ array is used in place: a sample of it at the band's nodes, for the solution to
        # notice a change before it projects points with it (geodesic paths)
        pick = linear[:: max(1, len(linear) // _PHI_SAMPLE)].copy()  # not a view: `linear` is dropped
        phi_sample = (pick, array.reshape(-1)[pick].copy())
    if general is None:
        # The linear indices are dropped before the sweeps and the fixed nodes go to the solver
        # sparsely; the directions are converted to the extension weights in place (no second
        # K×d buffer).
        if reuse:
            directions = tube.geom.directions_for_solver()  # a copy: the tube's stay as they are
        else:
            directions = tube.direction  # overwritten by the solver (a copy unless the geometry is consumable)
            tube.direction = tube.linear = tube.roles = None  # type: ignore[assignment]
        del linear
        setup = time.perf_counter() - t0
        values, st = band.solve(
            roles,
            positions,
            fixed_vals,
            h,
            slowness,
            directions,
            scheme,
            missing_policy,
            float(tol),
            int(max_iterations),
            _infinity(infinity),
            cb,
            _threads(threads),
            True,
            ACTIVATION_FRACTION * float(tol),
            not paper_sweeps,
            not paper_sweeps,
            0.0 if paper_sweeps else FRONT_WINDOW,
        )
        del directions
    else:
        setup = time.perf_counter() - t0
        values, st = _hams.solve_band(
            general,
            surf,
            grid,
            tube.geom,
            band,
            roles,
            positions,
            fixed_vals,
            src,
            speed_nodes,
            source_init == "exact",
            SOURCE_RADIUS,
            tol,
            max_iterations,
            _infinity(infinity),
            cb,
            _threads(threads),
            ACTIVATION_FRACTION * float(tol),
            not paper_sweeps,
        )
    warn_unconverged(st, tol, max_iterations)
    values[values >= st["infinity"]] = np.inf  # never reached (another component of the surface)
    # no NaN, and no inf next to a reached node in a solve reported converged
    check_values(
        grid,
        band,
        values,
        roles != ROLE_OUTER,
        st,
        _infinity(infinity),
        reachability=general is None or general.label == "isotropic",
    )
    n_outer = int(np.count_nonzero(roles == ROLE_OUTER))
    # held per node during the sweeps: values (f64), role, active flag and coupling mask, φ (f32),
    # extension weights (d × f32), per-node slowness (f64) when the speed varies; per row a lower
    # bound of its values (8 bytes, for the front window), and with the window a byte per node
    # marking the layer nodes in upwind 2-cycles; the fixed values are sparse. (With the rim
    # left to the end the core also holds a role copy and a rim mask, then the rim mask and a
    # byte of dependency counts, 2 bytes per node.)
    windowed = grid.ndim == 3 and scheme == "godunov" and not paper_sweeps and FRONT_WINDOW > 0
    per_node = 8 + 1 + 1 + 1 + 4 + 4 * grid.ndim + (8 if np.ndim(slowness) else 0) + (1 if windowed else 0)
    stats = SolveStats(
        iterations=st["iterations"],
        sweeps=st["sweeps"],
        updates=st["updates"],
        converged=st["converged"],
        last_change=st["last_change"],
        seconds=st["seconds"],
        band_points=len(roles),
        inner_points=len(roles) - n_outer,
        outer_points=n_outer,
        fixed_points=len(positions),
        setup_seconds=setup,
        band_bytes=band.nbytes + per_node * len(roles) + 8 * band.n_rows,
        window_edge=st["window_edge"],
        facing_pairs=int(tube.facing[0].size),
        narrowest_gap=float(np.min(tube.facing[2])) if tube.facing[2].size else float("inf"),
        thin_strip_iterations=(int(st["thin_strip_iterations"][0]), int(st["thin_strip_iterations"][1])),
        prefetch_iterations=int(st["prefetch_iterations"]),
    )
    return Solution(
        grid,
        band,
        values,
        roles,
        phi,
        stats,
        src,
        surf,
        scheme,
        method,
        tube.inner,
        tube.outer_eff,
        (positions, fixed_sources),
        general is None or general.label == "isotropic",
        tube.facing,
        phi_sample,
    )
