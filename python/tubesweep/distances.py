"""Geodesic distance matrices and farthest-point sampling: many solves on one band.

:func:`distance_matrix` solves once from each of M points (:meth:`Tube.solve_many` with
``at=points``, in parallel across the points, or on a Dask cluster) and reads every solution at
the M points: the one-way estimates ``D[i, j] = u_i(x_j)``. They differ from ``D[j, i]`` by the
discretisation error, and ``u_i(x_i)`` is the interpolated initialisation near the source, not 0.
The matrix returned is ``(D + Dᵀ) / 2`` with a zero diagonal: symmetric bit for bit (floating-point
addition commutes) and zero on the diagonal by construction, and no less accurate than either
estimate. ``info=True`` also returns the asymmetry removed.

:func:`farthest_point_sampling` picks well-spread points greedily: each new point is the surface
point farthest (geodesically) from those chosen so far, found from the running minimum of one
solve per chosen point.
"""

from __future__ import annotations

import re
import time
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np

from ._sources import beyond_inner_tube
from ._warn import user_stacklevel
from ._validate import as_points, check_flag
from .many import check_many_progress
from ._roles import ROLE_INNER
from .second_order import check_order
from .grid import Grid
from .tube import Tube

__all__ = ["distance_matrix", "farthest_point_sampling", "snap_to_surface"]


def _as_tube(surface: Any, grid: Any, inner: Optional[float], outer: Optional[float]) -> Tube:
    """``surface`` itself when it is a :class:`Tube` (``grid``, ``inner`` and ``outer`` left out or
    its own: they were ignored before, a helper's review), else its tube on ``grid`` (widths 2 and 4
    grid spacings unless given)."""
    if isinstance(surface, Tube):
        if grid is not None and not isinstance(grid, Grid):
            raise TypeError(
                f"grid must be a ts.Grid or None (with a ts.Tube, None: the tube's grid); got {type(grid).__name__}. "
                "With a tube the call is distance_matrix(tube, None, points) or farthest_point_sampling(tube, None, k)"
            )
        if grid is not None and grid != surface.grid:
            raise ValueError("grid: this ts.Tube was built on another grid; pass grid=None (or the tube's grid)")
        for name, given, own in (("inner", inner, surface.inner), ("outer", outer, surface.outer)):
            if given is not None and float(given) != float(own):
                raise ValueError(
                    f"{name}={given!r}: this ts.Tube was built with {name}={own:g}, which its solves use; leave "
                    f"{name} out, or build the tube with it (ts.Tube(surface, grid, {name}={given!r}))"
                )
        return surface
    if grid is None:
        raise ValueError("grid is required (a ts.Grid) unless surface is a ts.Tube")
    return Tube(surface, grid, inner=2.0 if inner is None else inner, outer=4.0 if outer is None else outer)


def snap_to_surface(tube: Tube, points: Any, name: str = "points") -> np.ndarray:
    """The closest points on the tube's surface of ``points`` (M, d), each of which must lie
    within the inner tube (``inner`` grid spacings) of the surface; farther ones are refused."""
    p = as_points(points, tube.grid.ndim, name)
    if p.shape[0] == 0:
        raise ValueError(f"{name} is empty: give at least one point on the surface")
    inside = tube.grid.contains(p)
    if not np.all(inside):
        i = int(np.flatnonzero(~inside)[0])
        raise ValueError(
            f"{name}[{i}] = {tuple(float(x) for x in p[i])} lies outside the grid; move it onto the surface"
        )
    dist, proj = tube.surface.project(p, tube.grid)
    dist = np.asarray(dist, dtype=float)
    limit = tube.inner * tube.grid.spacing
    bad = np.flatnonzero(~(dist <= limit * (1 + 1e-6)) | ~np.all(np.isfinite(proj), axis=1))
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"{beyond_inner_tube(f'{name}[{i}]', p[i], dist[i])} (inner·Δx = {limit:.4g}){f' ({bad.size} points in all)' if bad.size > 1 else ''}: points must "
            "lie on the surface (they are snapped to it from within the inner tube); move them onto it"
        )
    return np.ascontiguousarray(proj, dtype=float)


def distance_matrix(
    surface: Any,
    grid: Any,
    points: Any,
    *,
    client: Any = None,
    inner: Optional[float] = None,
    outer: Optional[float] = None,
    hamiltonian: str = "godunov",
    source_init: str = "exact",
    tol: Optional[float] = None,
    max_iterations: int = 10000,
    threads: int = 0,
    chunk_size: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    info: bool = False,
    order: Union[int, str] = "auto",
) -> Union[np.ndarray, Tuple[np.ndarray, dict]]:
    """Geodesic distances (M, M) between ``points`` on the surface.

    Parameters
    ----------
    surface : any surface ``ts.solve`` takes, or a :class:`ts.Tube` (then ``grid`` may be None)
    grid : Grid
    points : (M, d) points on the surface; each is snapped to its closest point on the surface,
        and a point farther than the inner tube (``inner`` grid spacings) is refused.
    client : dask.distributed.Client, optional — run the M solves on the cluster
        (``pip install 'tubesweep[distributed]'``, or ``pip install '.[distributed]'`` in a
        checkout; see :meth:`Tube.solve_many`).
    threads : solves run at once locally (0: all cores), each on one thread.
    inner, outer : the tube's half-widths in grid spacings (2 and 4 unless given); a
        :class:`ts.Tube` has its own, and other values are refused.
    progress : callable ``(done, M')``, optional (M' the distinct points).
    order : ``"auto"`` (the default: second order where it applies, as :func:`tubesweep.solve`), 1 or 2.
    info : also return a dict: ``asymmetry`` (the largest ``|D[i, j] − D[j, i]|`` of the one-way
        estimates, removed by the average; ``asymmetry_mean`` its mean over the pairs),
        ``diagonal`` (the largest one-way ``u_i(x_i)``, set to 0), ``points`` (the snapped
        points), ``seconds``, ``order`` and ``order_fallback`` (the order run, and why second order
        did not apply), ``unconverged`` (how many of the solves stopped at ``max_iterations``:
        their rows are the last iterate, and a warning says so), ``bridged_holes`` (an open
        mesh's or a point cloud's holes the band spans, as ``sol.stats.bridged_holes``), ``slits``
        (an open mesh's slits, as ``sol.stats.slits``).

    Returns
    -------
    D : (M, M) float — symmetric bit for bit, zero diagonal, and exactly 0 between points that
        snap to the same surface point (one solve for them: their rows are identical); ``inf``
        between points on parts of the surface that no path joins. Accurate to the solver's order
        (second order in the grid spacing where it applies: docs/many-sources.md).

    Raises
    ------
    ValueError
        For a point farther from the surface than the inner tube, or as :func:`tubesweep.solve`.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> points = 0.5 * np.eye(3)
    >>> D = ts.distance_matrix(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), points)
    >>> D.shape, bool(np.all(D == D.T))
    ((3, 3), True)
    """
    check_flag(info, "info")
    t0 = time.perf_counter()
    tube = _as_tube(surface, grid, inner, outer)
    snapped = snap_to_surface(tube, points)
    # one solve per distinct point: points that snap to the same surface point get the same row
    # and column, 0 apart
    distinct, first, inverse = np.unique(snapped, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    distinct = snapped[np.sort(first)]  # in the order the points were given
    inverse = np.argsort(np.argsort(first))[inverse]
    one_way, stats = tube.solve_many(
        distinct,
        at=distinct,
        hamiltonian=hamiltonian,
        source_init=source_init,
        tol=tol,
        max_iterations=max_iterations,
        threads=threads,
        client=client,
        chunk_size=chunk_size,
        progress=progress,
        order=order,
        return_stats=True,
    )
    if np.isnan(one_way).any():
        i, j = np.argwhere(np.isnan(one_way))[0]
        i, j = int(np.flatnonzero(inverse == i)[0]), int(np.flatnonzero(inverse == j)[0])
        raise RuntimeError(
            f"the solution from points[{i}] could not be read at points[{j}] (its interpolation stencil "
            "leaves the band): increase outer"
        )
    # pairs no path joins are inf both ways (inf − inf is not computed: no RuntimeWarning)
    both = np.isfinite(one_way) & np.isfinite(one_way.T)
    diff = np.abs(np.where(both, one_way, 0.0) - np.where(both, one_way.T, 0.0))
    asymmetry = float(np.max(diff, initial=0.0))
    off = both & ~np.eye(len(one_way), dtype=bool)
    asymmetry_mean = float(np.mean(diff[off])) if np.any(off) else 0.0
    diagonal = float(np.max(np.abs(np.diag(one_way)), initial=0.0))
    matrix = 0.5 * (one_way + one_way.T)
    np.fill_diagonal(matrix, 0.0)
    if len(distinct) < len(snapped):
        matrix = matrix[np.ix_(inverse, inverse)]
    if info:
        return matrix, {
            "asymmetry": asymmetry,
            "asymmetry_mean": asymmetry_mean,
            "diagonal": diagonal,
            "points": snapped,
            "seconds": time.perf_counter() - t0,
            "order": stats.get("order", 1),
            "order_fallback": stats.get("order_fallback"),
            "unconverged": int(np.count_nonzero(~np.asarray(stats["converged"], dtype=bool))),
            "bridged_holes": stats.get("bridged_holes"),
            "slits": stats.get("slits"),
        }
    return matrix


#: Closest points within this many grid spacings of each other stand for the same surface point in
#: :func:`farthest_point_sampling` (rounding of the projections, not a resolved distance).
_SAME_POINT = 1e-6


def farthest_point_sampling(
    surface: Any,
    grid: Any,
    k: int,
    *,
    start: Any = None,
    inner: Optional[float] = None,
    outer: Optional[float] = None,
    tol: Optional[float] = None,
    threads: int = 0,
    progress: Optional[Callable[[int, int], Any]] = None,
    order: Union[int, str] = "auto",
) -> Tuple[np.ndarray, np.ndarray]:
    """``k`` well-spread points on the surface by geodesic farthest-point sampling.

    Each new point is the surface point farthest from the points chosen so far: the closest point
    of the inner-tube node where the running minimum of their distances is largest (one solve
    per point, the minimum updated incrementally). ``start`` (a point on the surface) is the
    first point; by default the first point is the farthest from an arbitrary surface point (one
    extra solve), so the sampling does not depend on the surface's parametrisation.

    Parameters
    ----------
    surface : any surface ``ts.solve`` takes, or a :class:`ts.Tube`
        The surface (with a Tube, ``grid`` may be None).
    grid : Grid
        The grid.
    k : int
        How many points.
    start : array_like, optional
        The first point, on the surface.
    inner, outer : float, optional
        The tube's half-widths in grid spacings (2 and 4 unless given); a :class:`ts.Tube` has its
        own, and other values are refused.
    tol, threads
        As for :func:`tubesweep.solve`.
    progress : callable, optional
        Called as ``progress(done, k)``.
    order : {"auto", 1, 2}
        The order of each solve, as :func:`tubesweep.solve` (``"auto"``: second order where it
        applies).

    Returns
    -------
    points : (k, d) — on the surface
    radii : (k,) — the sampling radius of each step: the geodesic distance from each point to the
        nearest of those chosen before it (``inf`` for the first); non-increasing, and
        ``radii[i]`` bounds the distance of every surface point to the first ``i`` points (up to
        the discretisation error). A point on a part of the surface the others do not reach has
        radius ``inf``.

    Raises
    ------
    ValueError
        If ``k`` is not a positive whole number or exceeds the number of distinct surface points
        the grid resolves (the closest points of the inner-tube nodes; no point is chosen twice),
        or ``start`` lies off the surface.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> points, radii = ts.farthest_point_sampling(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), 4)
    >>> points.shape
    (4, 3)
    """
    if not (isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1):
        raise ValueError(f"k must be a positive whole number of points; got {k!r}")
    order = check_order(order)
    check_many_progress(progress)  # before the first solve
    tube = _as_tube(surface, grid, inner, outer)
    t = tube._tube
    g = tube.grid
    inner_pos = np.flatnonzero(t.roles == ROLE_INNER)
    # the surface point each inner node stands for
    _, candidates = tube.surface.project(g.node_points(t.linear[inner_pos]), g)
    candidates = np.asarray(candidates, dtype=float)
    usable = np.all(np.isfinite(candidates), axis=1)
    # nodes whose closest points coincide (to rounding) stand for one point: a point is never
    # chosen twice, so k is at most the number of distinct ones
    distinct = int(np.unique(np.round(candidates[usable] / (_SAME_POINT * g.spacing)), axis=0).shape[0])
    if k > distinct:
        raise ValueError(
            f"k = {k} exceeds the {distinct} distinct surface points the grid resolves (the closest points of its "
            f"{inner_pos.size} inner-tube nodes): pass k ≤ {distinct} or refine the grid"
        )

    said = _SaidOnce()

    def distances_from(p: np.ndarray) -> np.ndarray:
        with said:
            return tube.solve([p], tol=tol, threads=threads, order=order).values[inner_pos]

    if start is None:
        seed = candidates[int(np.flatnonzero(usable)[0])]
        first = distances_from(seed)
        first = np.where(usable & np.isfinite(first), first, -np.inf)
        current = candidates[int(np.argmax(first))]
    else:
        current = snap_to_surface(tube, start, "start")
        if len(current) != 1:
            raise ValueError(f"start must be one point of shape ({g.ndim},); got {len(current)} points")
        current = current[0]
    points = [current]
    radii = [np.inf]
    nearest = np.full(inner_pos.size, np.inf)
    # candidates standing for a chosen point (or too close to one to be told apart): never chosen
    taken = ~usable
    for step in range(1, k + 1):
        nearest = np.minimum(nearest, distances_from(points[-1]))
        taken |= np.linalg.norm(candidates - points[-1], axis=1) <= _SAME_POINT * g.spacing
        if progress is not None:
            progress(step, k)
        if step == k:
            break
        score = np.where(taken, -np.inf, nearest)
        best = int(np.argmax(score))
        if score[best] == -np.inf:  # every candidate taken (k was checked against the distinct points)
            raise ValueError(
                f"k = {k}: only {step} distinct surface points could be chosen on this grid; pass k ≤ {step} or "
                "refine the grid"
            )
        points.append(candidates[best])
        # the discrete distances near a chosen point are of the size of the scheme's error, not 0:
        # the radius is at least 0
        radii.append(max(float(score[best]), 0.0))
    said.say()
    return np.array(points), np.array(radii)


class _SaidOnce:
    """The warnings of a sampling's solves, each kind said once after them (the first solve's
    figures), not once per point: a box's mask gave its crease warning 13 times for k = 12 (a
    helper's review). A kind is the text with its numbers left out."""

    def __init__(self) -> None:
        self.caught: Dict[str, warnings.WarningMessage] = {}

    def __enter__(self) -> None:
        self._context = warnings.catch_warnings(record=True)
        self._record = self._context.__enter__()
        warnings.simplefilter("always")

    def __exit__(self, *exc: Any) -> None:
        self._context.__exit__(*exc)
        for w in self._record:
            self.caught.setdefault(re.sub(r"[-+]?\d[\d.,e+-]*", "#", str(w.message)), w)

    def say(self) -> None:
        for w in self.caught.values():
            warnings.warn(w.message, w.category, stacklevel=user_stacklevel())
