"""The narrow band of a surface on a grid, built once and solved on many times.

:func:`tubesweep.solve` builds the band of the surface (the inner tube and the extension layer of
Algorithm 3, with its extension directions) on every call. Where the same surface and grid are
solved for again and again (other sources, speeds or Hamiltonians: one solve per source to get
all pairwise distances, a sweep over source positions, an inverse problem), :class:`Tube` builds
it once::

    tube = ts.Tube(ts.surfaces.from_mesh("bunny.obj"), grid)
    for s in sources:
        sol = tube.solve([s])

Each :meth:`Tube.solve` gives the same values, bit for bit, as ``ts.solve`` with the same
arguments, and leaves the tube as it was. The tube holds, per band node, its linear index
(8 bytes), φ as float64 and float32 (12; the unsigned distance too, 8 more, for closest-point
and mesh surfaces), the extension direction (4·d), the role (1) and the band structure (about
22 in 3D): 55 bytes per node for the sphere at N = 201 (:attr:`Tube.nbytes`). A solve adds its
own working arrays (docs/architecture.md) and a copy of the directions.
"""

from __future__ import annotations

import time
import uuid
import warnings
from typing import Any, Callable, Optional, Union

import numpy as np

from . import second_order as _so
from ._first_order import first_order
from ._order_choice import order2_on, refuse_warm_for_order1, second_order_or_fallback
from ._request import SolveRequest, check_source_radius
from ._validate import as_grid
from .grid import Grid
from ._prepare import _prepare_tube, _PreparedTube, thinned_at_creases, unstranded
from .solution import Solution
from .surface import Surface, as_surface
from ._warn import user_stacklevel

__all__ = ["Tube"]


class Tube:
    """The band of a surface on a grid, built once for many solves.

    :func:`tubesweep.solve` without rebuilding the band each time: other sources, speeds or
    Hamiltonians on the same surface and grid (a distance matrix, a sweep over source positions,
    an inverse problem). Each :meth:`solve` gives the values of ``ts.solve`` bit for bit.

    Parameters
    ----------
    surface : LevelSet, ClosestPoint, library surface, φ array of ``grid.shape`` or callable φ
        The curve or surface.
    grid : Grid
        The uniform grid.
    inner, outer : float
        Tube half-widths in grid spacings (paper: 2 and 4). The extension layer is widened, with a
        warning, where inner nodes lack a neighbour in it, as in ``ts.solve``.
    method : {"two-layer", "naive"}
        Algorithm 3 (default) or Algorithm 2.

    Attributes
    ----------
    grid : Grid
    surface : Surface
    method : str
    inner : float
    outer : float
        The extension layer's half-width in grid spacings after any widening.
    band_points : int
        Nodes in the band.
    setup_seconds : float
        The time the band took to build.

    Raises
    ------
    ValueError
        As :func:`tubesweep.solve` for the surface and the grid (a grid too coarse for the surface,
        φ far from a distance function, bad widths, a band larger than the memory available).

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> tube = ts.Tube(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)))
    >>> a = tube.solve([(0.5, 0, 0)])
    >>> b = tube.solve([(0, 0.5, 0)], speed=2.0)
    """

    def __init__(self, surface: Any, grid: Any, *, inner: float = 2.0, outer: float = 4.0, method: str = "two-layer"):
        self._args = (inner, outer, method)
        # names this tube's band for a Dask worker's cache (tubesweep.distributed): a copy sent to a
        # worker is built there once and reused by every chunk of sources with the same token
        self._token = uuid.uuid4().hex
        self.grid: Grid = as_grid(grid)
        self.surface: Surface = as_surface(surface)
        self.surface.check_grid(self.grid)
        self._tube = _prepare_tube(
            self.surface, self.grid, inner, outer, method, keep_geometry=True, reusable=True, creases=True
        )
        # the tube of order=2 and "auto": at a level set's creases thinned (the same roles as ts.solve's)
        self._tube_order2 = thinned_at_creases(self._tube)
        # a φ array is used in place, not copied: its values at the band's nodes, kept to notice
        # a change before a later solve projects sources on the changed array (O(band) per solve)
        array = getattr(self.surface, "_array", None)
        self._phi_at_band = None if array is None else array.reshape(-1)[self._tube.linear].copy()
        # why order=2 refused this band's geometry (a crease, an unresolved curvature, ...), once found
        self._order2_refusal: Optional[str] = None
        self._first_auto: Optional[_PreparedTube] = None  # "auto"'s first-order tube, once needed

    def _check_phi_unchanged(self) -> None:
        if self._phi_at_band is not None and not np.array_equal(
            self.surface._array.reshape(-1)[self._tube.linear],  # type: ignore[attr-defined]
            self._phi_at_band,
        ):
            raise ValueError(
                "the φ array of this Tube's surface was changed after the Tube was built: its band no "
                "longer matches it. Build a new ts.Tube for the new φ (pass phi.copy() to LevelSet to keep "
                "the array free to change)"
            )

    def __getstate__(self) -> dict:
        """A tube pickles as its surface, grid and widths (and its token); unpickling builds the band
        again (the same band, bit for bit), so that a pickle does not carry band arrays."""
        return {"surface": self.surface, "grid": self.grid, "args": self._args, "token": self._token}

    def __setstate__(self, state: dict) -> None:
        inner, outer, method = state["args"]
        with warnings.catch_warnings():  # given when the tube was first built
            warnings.simplefilter("ignore", RuntimeWarning)
            self.__init__(state["surface"], state["grid"], inner=inner, outer=outer, method=method)  # type: ignore[misc]
        self._token = state["token"]

    @property
    def _tube_first_auto(self) -> _PreparedTube:
        """The tube of ``order="auto"``'s first-order scheme: thinned at creases as order 2's, with
        no piece of the inner tube cut off (``_prepare.unstranded``); computed once."""
        if self._first_auto is None:
            self._first_auto = unstranded(self._tube_order2)
        return self._first_auto

    @property
    def method(self) -> str:
        return self._tube.method

    @property
    def inner(self) -> float:
        return self._tube.inner

    @property
    def outer(self) -> float:
        return self._tube.outer_eff

    @property
    def band_points(self) -> int:
        return len(self._tube.linear)

    @property
    def setup_seconds(self) -> float:
        return self._tube.seconds

    def __repr__(self) -> str:
        return (
            f"Tube({type(self.surface).__name__}, grid shape {self.grid.shape}, {self.band_points:,} band points, "
            f"inner {self.inner:g}, outer {self.outer:g}, {self.method})"
        )

    def solve(
        self,
        sources: Any,
        *,
        hamiltonian: Any = "godunov",
        speed: Any = 1.0,
        flow: Any = None,
        allow_supersonic: bool = False,
        source_init: str = "exact",
        tol: Optional[float] = None,
        max_iterations: int = 10000,
        progress: Optional[Callable[[int, float, int], None]] = None,
        infinity: Optional[float] = None,
        threads: int = 0,
        paper_sweeps: bool = False,
        order: Union[int, str] = "auto",
        source_radius: Optional[float] = None,
        warm: Any = None,
        warm_refused: str = "raise",
    ) -> Solution:
        """First-arrival times from ``sources`` on this band, without building the band again.

        The arguments and the result are those of :func:`tubesweep.solve`;
        ``sol.stats.setup_seconds`` is the time spent on the sources and the speed.

        Parameters
        ----------
        sources : array_like
            ``(K, d)`` points on the surface.
        hamiltonian, speed, flow, allow_supersonic, source_init, tol, max_iterations, progress, infinity, threads, paper_sweeps, order, source_radius, warm, warm_refused
            As for :func:`tubesweep.solve`.

        Returns
        -------
        Solution
            The same values, bit for bit, as ``ts.solve`` with the same arguments.

        Raises
        ------
        ValueError
            As :func:`tubesweep.solve`; also if a φ array the tube was built from has been changed
            since (build a new Tube).

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> tube = ts.Tube(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)))
        >>> [round(float(tube.solve([p])([(0, 0, 0.5)])[0]), 2) for p in [(0.5, 0, 0), (0, 0.5, 0)]]
        [0.79, 0.79]
        """
        started = time.perf_counter()
        self._check_phi_unchanged()
        req = SolveRequest.checked(
            self.grid,
            sources,
            order=order,
            hamiltonian=hamiltonian,
            flow=flow,
            allow_supersonic=allow_supersonic,
            speed=speed,
            source_init=source_init,
            source_radius=source_radius,
            tol=tol,
            max_iterations=max_iterations,
            progress=progress,
            infinity=infinity,
            threads=threads,
            paper_sweeps=paper_sweeps,
            warm=warm,
            warm_refused=warm_refused,
            started=started,
        )
        sol, fallback = second_order_or_fallback(
            req, self.surface, self._tube.method, self._args[0], self._args[1], lambda: self._solve_order2(req)
        )
        if sol is not None:
            return sol
        refuse_warm_for_order1(req, fallback)
        check_source_radius(source_radius, source_init, self.grid)
        # the tube the sweeps run on: the paper's where the first-order scheme was chosen (order=1,
        # or an option only it has, which ts.solve refuses before it builds the thinned one)
        paper_tube = fallback is None or fallback.option_of_order1
        return first_order(req, self._tube if paper_tube else self._tube_first_auto, fallback, reuse=True)

    def _solve_order2(self, req: SolveRequest) -> Solution:
        """The second-order solve on this tube; a refusal of its geometry is kept and raised again
        by later solves without computing it again (a runaway depends on the speed and the
        sources: not kept)."""
        if self._order2_refusal is not None:  # this band's geometry, refused before
            raise _so.Order2NotApplicable(self._order2_refusal)
        try:
            # (the digests kept: a tube's solutions start warm solves on its moved tubes)
            return order2_on(self._tube_order2, req, keep_digests=True)
        except _so.Order2RanAway:
            raise
        except _so.Order2NotApplicable as e:
            self._order2_refusal = str(e)  # depends on the band only: not computed again
            raise

    def moved(self, surface: Any) -> "Tube":
        """The tube of this surface after it moved: the same grid, widths and method, the band of
        ``surface`` (docs/moving-surfaces.md). Solve on the new tube with ``warm=`` a solution on
        this (the previous) tube to start from the previous values instead of from the sources
        alone.

        Parameters
        ----------
        surface : LevelSet, library surface, φ array of ``grid.shape``, callable φ, mesh or point cloud
            The moved surface (φ at the new time, or the surface built from the moved vertices or
            points).

        Returns
        -------
        Tube
            The new surface's tube (this one is left as it was).

        Raises
        ------
        ValueError
            If ``surface`` is a φ array of another shape than the grid, or as :class:`Tube`.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
        >>> tube = ts.Tube(ts.surfaces.Sphere(0.5), grid)
        >>> sol = tube.solve([(0, 0, 0.5)])
        >>> grown = tube.moved(ts.surfaces.Sphere(0.51))
        >>> sol2 = grown.solve([(0, 0, 0.51)], warm=sol)
        """
        d = self.grid.ndim
        if isinstance(surface, tuple) and len(surface) == 2 and all(np.ndim(a) == 2 for a in surface):
            raise TypeError(
                "moved: got a pair of arrays, which looks like a mesh's vertices and triangles; pass the moved mesh "
                "as ts.surfaces.from_mesh((vertices, triangles))"
            )
        if (
            isinstance(surface, np.ndarray)
            and surface.ndim == 2
            and surface.shape[1] == d
            and tuple(surface.shape) != tuple(self.grid.shape)
        ):
            raise TypeError(
                f"moved: got an array of shape {surface.shape}, which looks like points, not a φ array of the grid's "
                f"shape {tuple(self.grid.shape)}; pass moved samples as ts.surfaces.from_points(points) (a mesh's moved "
                "vertices as ts.surfaces.from_mesh((vertices, triangles)))"
            )
        if isinstance(surface, np.ndarray) and tuple(surface.shape) != tuple(self.grid.shape):
            raise ValueError(
                f"moved: the φ array has shape {tuple(surface.shape)}, the tube's grid {tuple(self.grid.shape)}; a moved "
                "surface is sampled on the same grid (build a new ts.Tube for another grid)"
            )
        inner, outer, method = self._args
        return Tube(surface, self.grid, inner=inner, outer=outer, method=method)

    def solve_many(
        self,
        sources: Any,
        *,
        at: Any = None,
        hamiltonian: str = "godunov",
        speed: Any = 1.0,
        source_init: str = "exact",
        tol: Optional[float] = None,
        max_iterations: int = 10000,
        progress: Optional[Callable[[int, int], Any]] = None,
        infinity: Optional[float] = None,
        threads: int = 0,
        paper_sweeps: bool = False,
        client: Any = None,
        chunk_size: Optional[int] = None,
        return_stats: bool = False,
        order: Union[int, str] = "auto",
    ) -> Any:
        """K independent solves on this band, in parallel across the sources (docs/many-sources.md),
        each row the single :meth:`solve` of its source with the same ``order`` (default
        ``"auto"``: second order where it applies, as :meth:`solve`).

        Parameters
        ----------
        sources : array_like or list
            ``(K, d)`` K point sources, or ``(K, P, d)`` / a list of points ``(d,)`` or groups
            ``(P, d)`` (a group is one multi-source solve).
        at : array_like, optional
            ``(M, d)`` points: return the values there instead of on the whole band.
        hamiltonian : {"godunov", "lxf"}
            The scheme.
        speed, source_init, tol, max_iterations, infinity, paper_sweeps
            As for :meth:`solve`.
        progress : callable, optional
            Called as ``progress(done, total)`` about every 50 ms.
        threads : int
            Solves at once, each on one thread (0: all cores).
        client : dask.distributed.Client, optional
            Run the solves on a cluster (``pip install 'tubesweep[distributed]'``, or
            ``pip install '.[distributed]'`` in a checkout).
        chunk_size : int, optional
            Sources per cluster task.
        return_stats : bool
            Also return per-source statistics (and ``order``, ``order_fallback``: the order run, the
            lowest of any row, and why second order did not apply, as ``sol.stats``; ``orders``, each
            row's: a source whose second-order sweeps run away runs first order, as its
            :meth:`solve` does; at second order ``first_order_nodes`` and ``inner_nodes``).
        order : {"auto", 1, 2}
            As for :meth:`solve`: ``"auto"`` (the default) runs second order where it applies (the
            tube's geometry computed once for the batch) and the paper's first-order scheme
            otherwise, with the same fallback rules and reasons.

        Returns
        -------
        values : numpy.ndarray
            ``(K, band_points)`` (or ``(K, M)`` with ``at``); row k equals
            ``tube.solve(sources[k], order=order, ...).values`` (or ``sol(at)``) bit for bit.
        stats : dict
            Only with ``return_stats``: per-source arrays (iterations, converged, last_change, ...).

        Raises
        ------
        ValueError
            For sources off the surface, an unsupported Hamiltonian, an ``order`` other than 1, 2 or
            ``"auto"``, ``order=2`` where it does not apply, or as :meth:`solve`.
        KeyboardInterrupt
            On Ctrl-C, which stops every solve (no partial result).

        Notes
        -----
        ``sources`` is an array (K, d) of K point sources, or an array (K, P, d) / a list whose
        entries are points (d,) or groups (P, d) (a group is one multi-source solve). Returns a
        (K, band_points) array whose row k equals ``tube.solve(sources[k], order=order, ...).values`` bit for
        bit (``inf`` where never reached), or with ``at=points`` (M, d) the (K, M) values
        ``tube.solve(sources[k], order=order, ...)(points)`` without keeping K band arrays (memory O(band ·
        threads + K·M)). ``threads`` solves run at once, each on one thread (0: all cores), with
        the GIL released; ``progress(done, total)`` is called about every 50 ms, and Ctrl-C stops
        every solve with ``KeyboardInterrupt`` (no partial result). The other options are those of
        :meth:`solve` (``hamiltonian`` 'godunov' or 'lxf' only).

        With ``client`` (a ``dask.distributed.Client``: ``pip install 'tubesweep[distributed]'``, or
        ``pip install '.[distributed]'`` in a checkout) the sources go to the cluster's workers in
        chunks of ``chunk_size``: each worker builds this tube once and reuses it for all its
        chunks, and only the values (at ``at``) come back; the result equals the local one bit
        for bit. ``return_stats`` also returns a dict of
        per-source arrays (iterations, converged, last_change, ...).

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> tube = ts.Tube(ts.surfaces.Sphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3))
        >>> U = tube.solve_many(0.5 * np.eye(3), at=[(0.0, 0.0, -0.5)])
        >>> U.shape
        (3, 1)
        """
        if client is not None:
            from .distributed import solve_many_on_client

            out = solve_many_on_client(
                self,
                sources,
                client=client,
                at=at,
                chunk_size=chunk_size,
                progress=progress,
                options=dict(
                    hamiltonian=hamiltonian,
                    speed=speed,
                    source_init=source_init,
                    tol=tol,
                    max_iterations=max_iterations,
                    infinity=infinity,
                    paper_sweeps=paper_sweeps,
                    order=_so.check_order(order),
                ),
                threads=threads,
                return_stats=return_stats,
            )
            return _warn_nan_columns(out, at, return_stats)
        if chunk_size is not None:
            raise ValueError(
                "chunk_size is for a Dask client (client=...): a local solve_many runs every source at once"
            )
        from .many import solve_many

        out = solve_many(
            self,
            sources,
            at=at,
            hamiltonian=hamiltonian,
            speed=speed,
            source_init=source_init,
            tol=tol,
            max_iterations=max_iterations,
            progress=progress,
            infinity=infinity,
            threads=threads,
            paper_sweeps=paper_sweeps,
            return_stats=return_stats,
            order=order,
        )
        return _warn_nan_columns(out, at, return_stats)

    @property
    def nbytes(self) -> int:
        """Bytes the tube holds in its arrays (the band structure included)."""
        t = self._tube
        g = t.geom
        arrays = [t.linear, t.roles, t.phi, g.signed, g.direction] + ([g.distance] if g.distance is not None else [])  # type: ignore[union-attr]
        return int(sum(np.asarray(a).nbytes for a in arrays) + t.band.nbytes)


def _warn_nan_columns(out: Any, at: Any, return_stats: bool) -> Any:
    """``out`` of :meth:`Tube.solve_many`, after a RuntimeWarning naming the points of ``at``
    whose column is NaN in every row: they lie off the band (``sol(points)`` reads NaN there too),
    which a matrix fed on to clustering or MDS would otherwise carry silently."""
    if at is None:
        return out
    values = out[0] if return_stats else out
    v = np.asarray(values)
    if v.ndim != 2 or v.shape[0] == 0:
        return out
    off = np.flatnonzero(np.all(np.isnan(v), axis=0))
    if off.size:
        p = np.asarray(at, dtype=float).reshape(v.shape[1], -1)
        i = int(off[0])
        warnings.warn(
            f"{off.size} of the {v.shape[1]} points of at lie off the band (e.g. at[{i}] = "
            f"{tuple(float(c) for c in p[i])}): their columns are NaN, as sol(points) reads there. Move them onto "
            "the surface (ts.distance_matrix snaps points within the inner tube onto it)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return out
