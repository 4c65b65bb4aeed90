"""The surface eikonal solver: the two-layer tube method (Algorithm 3) and the naive single tube
(Algorithm 2) on a sparse narrow band."""

from __future__ import annotations

import time
from typing import Any, Callable, List, Optional, Union

from ._first_order import first_order
from ._order_choice import order2_on, refuse_warm_for_order1, second_order_or_fallback
from ._prepare import METHODS, _PreparedTube, _prepare_tube, thinned_at_creases, unstranded
from ._roles import ROLE_RTOL
from ._request import SOURCE_INITS, SolveRequest, check_source_radius
from ._sources import SOURCE_RADIUS
from ._validate import FIRST_ORDER_TOL, as_grid
from .grid import Grid
from .second_order import check_order
from .solution import Solution
from .surface import as_surface

__all__ = ["solve", "Solution", "METHODS", "SOURCE_INITS", "ROLE_RTOL", "SOURCE_RADIUS"]

#: The default stopping tolerance of the first-order sweeps (``tol=None``) at travel times across
#: the grid of 1 or more (below, that share of them: ``_validate.first_order_tol``; ``order=2``
#: has its own, ``second_order.default_tol``).
DEFAULT_TOL = FIRST_ORDER_TOL


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
    source_radius: Optional[float] = None,
    tol: Optional[float] = None,
    order: Union[int, str] = "auto",
    max_iterations: int = 10000,
    progress: Optional[Callable[[int, float, int], None]] = None,
    infinity: Optional[float] = None,
    threads: int = 0,
    paper_sweeps: bool = False,
    warm: Any = None,
    warm_refused: str = "raise",
) -> Solution:
    """First-arrival time (geodesic distance for ``speed=1``) on an implicit curve or surface.

    Solves ``|∇_Σ u| = 1/F`` on Σ by the embedding of the paper: the eikonal equation
    ``|∇u| = 1/F`` in the inner tube ``|φ| ≤ inner·Δx`` (Godunov, Eq. 3, or Lax–Friedrichs, Eq. 4)
    and, for ``method="two-layer"`` (Algorithm 3), the extension equation (8)
    ``[sgn(φ) n]·∇u = 0`` in the layer ``inner·Δx < |φ| ≤ outer·Δx`` with the upwind update (5).
    ``method="naive"`` is Algorithm 2 (one tube ``|φ| ≤ inner·Δx``, numerical infinity outside);
    it is kept as the baseline that does not converge for a tube of width O(Δx) (Sect. 3).
    That is the paper's first-order scheme, ``order=1``. By default (``order="auto"``) smooth
    closed level sets and closest-point surfaces are solved to second order instead (the
    metric-corrected tube equation, docs/second-order.md), and everything else with ``order=1``;
    ``sol.stats.order`` says which ran and ``sol.stats.order_fallback`` why not 2.

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
        ``Metric(M)``) solves ``H(x, ∇u) = 0``: ``MovingMedium`` and ``Metric`` with the upwind
        (Godunov-type) local solver by default, or with the general Lax–Friedrichs update of
        Sect. 5.1 when built with ``scheme="lxf"``.
    speed : float, ndarray of ``grid.shape``, or callable ``F(points) -> (M,)``
        The speed F > 0 (1: geodesic distance). It lives on the surface: a callable is evaluated
        at the tube nodes' closest points (extended constantly along the normals, as the solution
        is); an array is read at the nodes, and one that varies along the normals by more than 1%
        across the inner tube is warned of (the front runs along the tube's faster side).
    flow : callable ``v(points (M, d)) -> (M, d)`` or array of ``grid.shape + (d,)``, optional
        Ambient flow of a moving medium: solves ``|∇u| = |1 − v·∇u| / F`` (Sect. 6.3) with the
        upwind local solver (shorthand for ``hamiltonian=ts.hamiltonians.MovingMedium(flow)``;
        ``hamiltonian="lxf"`` with a flow uses the paper's Lax–Friedrichs update of Sect. 5.1).
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
    source_radius : float, optional
        With ``source_init="exact"``: fix the inner nodes whose closest point is within this
        distance (in the surface's units, at least ``SOURCE_RADIUS``·Δx) of a source, in place of
        ``SOURCE_RADIUS``·Δx. A radius that does not shrink with the grid removes the point
        source's ``O(h log 1/h)`` pollution of the first-order error (order 1 instead of about
        0.6 on a plane, docs/hamiltonians.md). The local value is the straight (chord) distance
        times the slowness, or the Hamiltonian's travel time along it, so the surface should be
        flat and the speed, flow or metric constant within the radius.
    tol, max_iterations : float or None, int
        Stop when no value changes by more than ``tol`` in an iteration of 2^d sweeps, or after
        ``max_iterations`` (then ``stats.converged`` is False, with a warning). ``tol=None`` (the
        default) stands with ``order=1`` for 1e-10 of the travel time across the grid (its longest side at the mean slowness), at most 1e-10, and with ``order=2`` for ``5e-4 Δx²/ℓ`` (3D) or ``1e-3 Δx²/ℓ`` (2D; times
        ``200 Δx/ℓ`` where that is below 1) times the mean slowness (at most twice its lower quartile, so that an obstacle does not
        loosen it), ℓ half the grid's longest side.
    progress : callable, optional
        Called after every iteration as ``progress(iteration, max_change, updates)``.
    threads : int
        Worker threads for the sweeps (0, the default: the cores that are idle when the solve
        starts, all of them on a quiet machine, and each iteration runs in parallel only where
        that was measured to be faster; 1: sequential; k: k threads); the result does not depend
        on it (parallel sweeps are bit-identical to sequential ones).
    infinity : float, optional
        The finite numerical infinity unknown values start at (default: derived from the band, a
        safe upper bound on every travel time); it only affects the Lax–Friedrichs iteration count.
        A user value must exceed every travel time: values within a millionth of it count as
        never reached and are returned as ``inf``. Not used by ``order=2``.
    order : {"auto", 1, 2}
        ``"auto"`` (the default): second order where it applies, the paper's first-order scheme
        where it does not (below). 1: the paper's first-order scheme. 2: second order (docs/second-order.md):
        the metric-corrected tube equation with limited BDF2–BDF3 differences and factored point
        sources, for level sets (arrays, callables, library surfaces), closest-point surfaces,
        point clouds and meshes (through their smooth map) with the Godunov update;
        ``sol.stats.order2`` reports its phases. It is decided node by node: where the local
        geometry is not resolved (an open surface's rim, a crease, noise, a curvature the tube
        does not resolve, φ not a distance there) a node runs the first-order update
        (``sol.stats.order2["first_order_nodes"]``, ``sol.first_order_points()``). Refused with a
        ``ValueError`` saying why: a tube more than half unresolved (the grid does not resolve the
        surface), a level set's convex creases or corners (the cube), a mesh with ``smooth=False``,
        with creases of its own and coarse against the grid, or facing itself across gaps narrower than its tubes,
        Lax–Friedrichs, flows and Hamiltonian objects, ``method="naive"``, ``paper_sweeps``,
        ``source_init="node"``, ``source_radius`` and ``outer < inner + 2``. ``"auto"`` runs 2 where it applies (the same values) and where it
        does not the first-order scheme (the same values as ``order=1``, except that at a level
        set's creases the inner tube is thinned, as for 2: docs/second-order.md), with
        ``sol.stats.order_fallback`` holding the text of the error ``order=2`` gives
        (``sol.stats.order`` says which ran).
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
        (``benches/experiments/sweep_variants.py``).
    warm : Solution or (Solution, Solution), optional
        The solution of the previous step of a moving surface (docs/moving-surfaces.md): the
        second-order sweeps start from its values carried onto this band instead of from the
        sources alone, and end at the cold solve's values. A pair ``(older, previous)`` starts from
        the values extrapolated in time. Refused (:class:`tubesweep.moving.WarmStartRefused`) for
        another grid, first-order solves, other sources, a surface that moved farther than
        ``outer − inner`` grid spacings or changed topology.
    warm_refused : {"raise", "cold"}
        What a refused warm start does: raise (the default), or solve cold and record why in
        ``sol.stats.order2["warm"]`` (a solve that runs first order has no such report:
        ``sol.stats.order == 1``).

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
    >>> sol([(0, 0.5, 0)])  # exact π/4 = 0.785398  # doctest: +ELLIPSIS
    array([0.7854...])
    >>> sol.stats.order, ts.solve(sphere, grid, sources=[(-0.5, 0, 0)], order=1)([(0, 0.5, 0)])  # doctest: +ELLIPSIS
    (2, array([0.77...]))
    """
    started = time.perf_counter()
    order = check_order(order)
    grid = as_grid(grid)
    surf = as_surface(surface)
    surf.check_grid(grid)
    req = SolveRequest.checked(
        grid,
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
    # the second-order tube (thinned at creases, its geometry kept), built by the attempt: with
    # order="auto" refused by its geometry or its sweeps, the first-order scheme runs on it as on
    # a Tube's (the same values)
    built: List[_PreparedTube] = []

    def order2() -> Solution:
        built.append(
            thinned_at_creases(_prepare_tube(surf, grid, inner, outer, method, keep_geometry=True, creases=True))
        )
        return order2_on(built[0], req)

    sol, fallback = second_order_or_fallback(req, surf, method, inner, outer, order2)
    if sol is not None:
        return sol
    refuse_warm_for_order1(req, fallback)
    check_source_radius(source_radius, source_init, grid)
    # the one call keeps nothing for later: the float64 geometry is dropped before the sweeps
    # (unless a general Hamiltonian needs it) and the directions become the extension weights
    reuse = bool(built)
    tube = built[0] if built else _prepare_tube(surf, grid, inner, outer, method, keep_geometry=req.general is not None)
    if fallback is not None:
        tube = unstranded(tube)  # no piece of the thinned inner tube cut off (first-order sweeps)
    return first_order(req, tube, fallback, reuse)
