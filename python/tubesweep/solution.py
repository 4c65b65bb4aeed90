"""What a solve returns: :class:`Solution`, the values on the band and what is read from them
(interpolation, the solution on a mesh, nearest-source labels, geodesic paths)."""

from __future__ import annotations

import warnings
from typing import Any, List, Optional, Tuple, Union

import numpy as np

from . import _native
from ._validate import (
    check_memory,
    as_points,
    real_scalar,
)
from ._factoring import factored_values
from ._interpolation import interpolate_band
from ._sheet_readout import own_side_plan
from .grid import Grid
from .stats import SolveStats
from .surface import Surface
from ._roles import ROLE_OUTER
from ._warn import user_stacklevel


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
        The equation and scheme asked for: the eikonal scheme (``"godunov"`` or ``"lxf"``) for the
        eikonal equation, else the general Hamiltonian's label (``"moving-medium"``,
        ``"metric"`` or ``"isotropic"``). Which local solver ran is ``stats.local_solver``
        (``"godunov"``, ``"lxf"`` or ``"upwind"``).
    method : str
        ``"two-layer"`` or ``"naive"``.
    order : int
        The order of the scheme solved with: 1, or 2 for ``solve(..., order=2)``.

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
        # the surface's parts per band node where two face each other across a narrow gap
        # (``_parts.part_labels``; None otherwise): a point whose cell holds corners of two reads
        # its reached corners (``_sheet_readout``)
        self._parts: Optional[np.ndarray] = None
        # order=2 with point sources: (u₀ per node, the sources' foot points, their slowness)
        self._factoring: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray, float]] = None
        self._first_order_positions: Optional[np.ndarray] = None
        # order=2: per band node a digest of what its update reads (a warm start from this
        # solution starts the sweeps where they changed: tubesweep_core::second_order::fingerprint)
        self._digests: Optional[np.ndarray] = None
        # with the digests: the solve's tolerance and a checksum of its values (a warm start uses
        # the digests only for the converged values of a solve at least as tight, unedited); or
        # why a solve that would have kept them did not
        self._digested: Optional[Union[Tuple[float, int], str]] = None
        # with the digests: per node its value when its readers were last brought up to date (a
        # warm start wakes the readers of a node that drifted from it: moving._unpropagated_drift)
        self._anchor: Optional[np.ndarray] = None
        # the inner tube's connected components and a checksum of its flags, once a warm start
        # counted them (tubesweep.moving.inner_components)
        self._inner_components: Optional[Tuple[int, int, np.ndarray]] = None
        self.order = 1

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

    def first_order_points(self) -> np.ndarray:
        """Where the second-order solve ran the paper's first-order update (``order=2``).

        Second order is decided node by node: at inner-tube nodes whose local geometry the grid
        does not resolve (a crease, a corner, noise, the rim of an open surface, a stencil cut by
        the box) the update is first order; ``stats.order2["first_order_nodes"]`` counts them and
        ``stats.order2["first_order_reasons"]`` says why. Errors near these points, and
        downstream of them, are first order in the grid spacing.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` the grid points of those nodes; empty for an ``order=1`` solution and where
            every node ran second order.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source])
        >>> sol.first_order_points().shape
        (0, 3)
        """
        positions = self._first_order_positions
        if positions is None or len(positions) == 0:
            return np.empty((0, self.grid.ndim))
        return self.grid.node_points(self.linear[positions])

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
            ``(M,)`` values; NaN where the cell's corners leave the band (points farther from the
            surface than about the tube's outer width less a cell, or outside the grid), with a
            ``RuntimeWarning`` that counts them; +∞ on a part of the surface no source reaches
            (where the cell's reached corners carry less than half its weight; where they carry
            more, the value is theirs, renormalised).

        Raises
        ------
        ValueError
            If the points do not have the grid's dimension or are not finite, or
            ``interpolation`` is not one of the two; or if the φ array of the surface was
            changed after a second-order solve (its values near a source are read through the
            points' projections onto the surface).

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [s.default_source])
        >>> u = sol([(0.0, 0.5, 0.0), (0.5, 0.0, 0.0)])  # exact π/4 and π/2
        >>> v = sol([(0.0, 0.5, 0.0)], interpolation="cubic")
        """
        p = as_points(points, self.grid.ndim, "points")
        out = self._at(p, interpolation)
        off = np.isnan(out)
        if np.any(off):
            i = int(np.flatnonzero(off)[0])
            q = p[i]
            warnings.warn(
                f"sol(points): {int(np.count_nonzero(off))} of {len(out)} points lie where the band does not reach "
                f"(the first, points[{i}] = {tuple(round(float(c), 6) for c in q)}): NaN there. The band holds the "
                f"solution within {self.outer:g} grid spacings of the surface and a point reads the corners of its "
                f"cell, so points within about {max(self.outer - 1.0, 0.5):g} spacings read values; read points on or "
                "near the surface (surface.project(points, grid) gives their closest points), or sol.on_mesh(points), "
                "which reads the nearest node's value a little farther out",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        return out

    def _at(self, points: Any, interpolation: str = "linear") -> np.ndarray:
        """:meth:`__call__` without its warning about the points off the band (for the readers
        that handle NaN themselves: :meth:`on_mesh` and geodesic paths)."""
        p = as_points(points, self.grid.ndim, "points")
        if self._factoring is not None:  # the factored form near a source projects onto the surface
            self._check_surface_unchanged()
        out = self._read(p, interpolation)
        # a band cut across narrow gaps, or a mesh of separate pieces: each point read from its own
        # side of the gap (at second order its cell's corners read as any point: the factored form
        # near a source)
        plan = own_side_plan(
            self.grid,
            self.surface,
            self._band,
            self._facing,
            len(self.values),
            p,
            cut=bool(self.stats.cut_edges),
            labels=getattr(self, "_parts", None),  # (a solution pickled before it had parts)
        )
        if plan is not None:
            out = plan.apply(out, self._read(plan.corners, "linear"))
        return out

    def _read(self, p: np.ndarray, interpolation: str) -> np.ndarray:
        """The values interpolated at ``p``, in the factored form near a second-order solution's
        point sources (:func:`~tubesweep._factoring.factored_values`)."""
        out = interpolate_band(self._band, self.values, self.grid, p, interpolation)
        if self._factoring is not None:
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
            ``(M,)`` values; NaN where no band node is near or the point lies farther from the
            surface than the tube (with a warning); +inf where the nearest node was not reached
            (a component of the surface no source reaches, or a solve stopped early), as
            :meth:`__call__` gives there.

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
        out = self._at(p)
        bad = np.flatnonzero(~np.isfinite(out))
        if bad.size:
            pos = self._nearest_reached(p[bad])
            pos[self._beyond_tube(p[bad], pos)] = -1
            # +inf on a part of the surface no source reaches (as sol(points) and the band give),
            # NaN off the band
            out[bad] = np.where(pos >= 0, self.values[np.maximum(pos, 0)], np.where(pos == -2, np.inf, np.nan))
            self._warn_off_band(p[bad[pos == -1]], len(p), self._faceless(p, bad[pos == -1]))
        return out

    def _beyond_tube(self, p: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Where a point that :meth:`on_mesh` would give its nearest node's value (``pos`` ≥ 0)
        lies farther from the surface than the tube (``outer + 0.5`` spacings): no vertex of this
        surface, NaN rather than a value read a few spacings away (the sphere's centre, 7.5
        spacings inside, read 0.29: a helper's review). False where the surface cannot project."""
        beyond = np.zeros(len(p), dtype=bool)
        at = np.flatnonzero(pos != -1)  # (-2: the nearest node unreached, +inf if on the surface)
        if at.size == 0:
            return beyond
        try:
            distance = np.asarray(self.surface.project(p[at], self.grid)[0], dtype=float)
        except Exception:  # (a surface that cannot project there: the nearest node stands)
            return beyond
        beyond[at] = distance > (self.outer + 0.5) * self.grid.spacing
        return beyond

    def _faceless(self, vertices: np.ndarray, which: np.ndarray) -> np.ndarray:
        """Whether each of ``vertices[which]`` is a vertex of this solution's mesh that none of its
        faces uses, where ``vertices`` are the mesh's own (all False otherwise)."""
        faces, own = getattr(self.surface, "faces", None), getattr(self.surface, "vertices", None)
        if faces is None or own is None or np.shape(own) != vertices.shape or not np.array_equal(own, vertices):
            return np.zeros(len(which), dtype=bool)
        used = np.zeros(len(vertices), dtype=bool)
        used[np.asarray(faces).reshape(-1)] = True
        return ~used[which]

    def _warn_off_band(self, p: np.ndarray, total: int, faceless: Optional[np.ndarray] = None) -> None:
        """A RuntimeWarning when points that :meth:`on_mesh` leaves NaN are off the band (their
        nearest grid node is not in it, or they lie outside the box), not merely on a part of the
        surface no source reaches: they are not on this surface (a mesh's own vertices after
        ``from_mesh(..., normalize=True)`` moved it, a mesh on another scale), or they are the
        mesh's own vertices that no face uses (``faceless``, per point)."""
        if p.size == 0:
            return
        g = self.grid
        ci = g.continuous_index(p)
        inside = np.all((ci > -0.5) & (ci < np.asarray(g.shape) - 0.5), axis=1)
        off = ~inside
        if np.any(inside):
            idx = np.rint(ci[inside]).astype(np.int64)
            off[inside] = self._band.find(np.ascontiguousarray(idx)) < 0
        n = int(np.count_nonzero(off))
        unused = 0 if faceless is None else int(np.count_nonzero(off & faceless))
        if unused:
            others = f"; the other {n - unused} lie off the band too" if n > unused else ""
            warnings.warn(
                f"on_mesh: {unused} of {total} vertices are used by no face of the mesh and lie off the surface's band: "
                f"NaN there{others} (trimesh's Trimesh.remove_unreferenced_vertices() drops such vertices)",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        elif n:
            warnings.warn(
                f"on_mesh: {n} of {total} vertices lie off the band (farther from the surface than the tube, or outside "
                "the grid box): NaN there. Are they this surface's vertices? from_mesh(..., normalize=True) moves the "
                "mesh: pass surface.vertices",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )

    def _nearest_reached(self, p: np.ndarray) -> np.ndarray:
        """Band position (M,) of the band node nearest to each point within ``outer + 1`` grid
        spacings of it, -1 where there is none, -2 where that node was not reached (a component
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
        # a mesh of separate pieces: only nodes of the point's own piece (across a gap narrower
        # than the tube the nearest node is the other piece's, and a piece no source reaches
        # read its neighbour's values)
        own = self._band_pieces()
        if own is not None:
            from .surfaces._mesh_parts import point_parts

            point_piece = point_parts(self.surface, p[near])
        for o, length in zip(offs[order], lengths[order]):
            open_ = open_[bd[open_] > length - slack]
            if open_.size == 0:
                break
            idx = base[open_] + o
            pos = self._band.find(np.ascontiguousarray(idx))
            ok = pos >= 0
            if own is not None:
                ok &= own[np.maximum(pos, 0)] == point_piece[open_]
            if not np.any(ok):
                continue
            dist = np.linalg.norm(idx - ci[open_], axis=1)
            take = ok & (dist < bd[open_]) & (dist <= self.outer + 1)
            bp[open_[take]] = pos[take]
            bd[open_[take]] = dist[take]
        found = bp >= 0
        bp[found & ~np.isfinite(self.values[np.maximum(bp, 0)])] = -2
        best[near] = bp
        return best

    def _band_pieces(self) -> Optional[np.ndarray]:
        """Per band node the piece of a mesh of separate pieces its nearest face lies on (kept
        after the first call), or None on other surfaces."""
        node_parts = getattr(self.surface, "_node_parts", None)
        if node_parts is None:
            return None
        if "_pieces" not in self.__dict__:
            self._pieces = node_parts(self.grid, self.linear)
        return self._pieces

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
            Step length in grid spacings (default 0.5, from 0.01 to 1).
        max_steps : int, optional
            The most steps to take (default: 8·(the grid's points per axis, summed)/step, more than any
            path within the grid needs).

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
