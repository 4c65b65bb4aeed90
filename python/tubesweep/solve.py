"""The surface eikonal solver: the two-layer tube method (Algorithm 3) and the naive single tube
(Algorithm 2) on a sparse narrow band."""

from __future__ import annotations

import time
from typing import Any, Callable, Optional, Tuple, Union

import numpy as np

from ._validate import (
    ACTIVATION_FRACTION,
    FRONT_WINDOW,
    check_threads as _threads,
    check_infinity as _infinity,
    as_grid,
    as_sources,
    check_hamiltonian,
    check_tolerance,
    check_tolerance_scale,
    FIRST_ORDER_TOL,
    first_order_tol,
    checked_point_speeds,
    speed_at_points,
    speed_on_surface,
    progress_callback,
    warn_unconverged,
)
from ._fallback import Fallback
from ._result_check import check_values
from .grid import Grid
from .moving import check_warm_refused
from .stats import SolveStats
from .surface import as_surface
from ._creases import warn_paper_tube_creases
from ._parts import drop_unsourced, on_sourced_parts, part_labels, source_parts
from ._prepare import (
    METHODS,
    ROLE_FIXED,
    ROLE_INNER,
    ROLE_OUTER,
    ROLE_RTOL,
    _PreparedTube,
    _prepare_tube,
    paper_creases_of,
    thinned_at_creases,
    thinned_count,
    uncut_band,
    unstranded,
    warn_facing_pairs,
)
from ._sources import SOURCE_RADIUS, _fix_sources
from . import _hamiltonian_solve
from .solution import Solution

__all__ = ["solve", "Solution", "METHODS", "SOURCE_INITS", "ROLE_RTOL", "SOURCE_RADIUS"]

#: The default stopping tolerance of the first-order sweeps (``tol=None``) at travel times across
#: the grid of 1 or more (below, that share of them: ``_validate.first_order_tol``; ``order=2``
#: has its own, ``second_order.default_tol``).
DEFAULT_TOL = FIRST_ORDER_TOL

SOURCE_INITS = ("exact", "node")


# band nodes at which a solution samples its surface's φ array, to notice a later change
_PHI_SAMPLE = 4096


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
    t0 = time.perf_counter()
    order = _check_order(order)
    grid = as_grid(grid)
    surf = as_surface(surface)
    surf.check_grid(grid)
    src = as_sources(sources, grid)
    general, scheme = _resolve_scheme(hamiltonian, flow, allow_supersonic)
    check_tolerance(tol, max_iterations)
    cb = progress_callback(progress)
    _check_source_init(source_init)
    _infinity(infinity)  # checked whichever order runs (order=2 has no use for it)
    check_warm_refused(warm_refused)
    tube: Optional[_PreparedTube] = None
    fallback: Optional[Fallback] = None  # order="auto" running the first-order scheme, and why
    if order != 1:
        from . import second_order as _so

        try:
            if source_radius is not None:
                raise _so.OptionOfOrder1(
                    "source_radius applies to order=1 (order=2 factors the point source itself); leave it out"
                )
            _so.check_supported(surf, general, scheme, method, source_init, paper_sweeps)
            _so.check_widths(inner, outer)
            tube = thinned_at_creases(_prepare_tube(surf, grid, inner, outer, method, keep_geometry=True, creases=True))
            return _so.solve_on_tube(
                tube,
                src,
                speed,
                tol,
                max_iterations,
                cb,
                threads,
                t0,
                warm=warm,
                warm_refused=warm_refused,
            )
        except _so.Order2NotApplicable as e:
            if order == 2:
                raise
            fallback = Fallback.of(e, order)
    if warm is not None and warm_refused == "raise":
        from .moving import refusal_for_order1

        raise refusal_for_order1(None if fallback is None else fallback.reason)
    _check_source_radius(source_radius, source_init, grid)
    # the one call keeps nothing for later: the float64 geometry is dropped before the sweeps
    # (unless a general Hamiltonian needs it) and the directions become the extension weights;
    # with order="auto" refused by the second-order geometry, the tube it built is solved on as a
    # Tube's is (the same values)
    reuse = tube is not None
    if tube is None:
        tube = _prepare_tube(surf, grid, inner, outer, method, keep_geometry=general is not None)
    if fallback is not None:
        tube = unstranded(tube)  # no piece of the thinned inner tube cut off (first-order sweeps)
        fallback.measure(tube)
    sol = _solve_on_tube(
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
        reuse=reuse,
        source_radius=source_radius,
    )
    if fallback is not None:
        from .second_order import with_fallback

        fallback.warn(sol.values, tube)
        return with_fallback(sol, fallback.reason, fallback.creases)
    return sol


def _directions_of(tube: _PreparedTube) -> np.ndarray:
    """The tube's unit directions away from the surface, per band node: the solver's own copy (one
    call) or the kept geometry's (a :class:`Tube`, a general Hamiltonian)."""
    return tube.direction if tube.direction is not None else tube.geom.direction  # type: ignore[union-attr]


def _check_source_radius(source_radius: Any, source_init: str, grid: Optional[Grid] = None) -> None:
    """``source_radius``: a positive distance, with ``source_init="exact"``, below the grid's
    diagonal (the chord's validity within it is checked with the surface, ``_sources``)."""
    if source_radius is None:
        return
    if isinstance(source_radius, bool) or not isinstance(source_radius, (int, float, np.integer, np.floating)):
        raise TypeError(f"source_radius must be a number (a distance) or None; got {source_radius!r}")
    if not (np.isfinite(source_radius) and source_radius > 0):
        raise ValueError(f"source_radius must be a positive finite distance; got {source_radius!r}")
    if grid is not None:
        diagonal = float(np.linalg.norm(np.asarray(grid.upper, float) - np.asarray(grid.lower, float)))
        if source_radius > diagonal:
            raise ValueError(
                f"source_radius = {source_radius:g} exceeds the grid's diagonal ({diagonal:.4g}): it is the radius of the "
                "ball around each source whose nodes are fixed to the straight (chord) distance, which is the "
                "distance along the surface only where the surface is flat. Use a few grid spacings "
                f"(h = {grid.spacing:.4g}) up to a small fraction of the surface's size, or leave it out"
            )
    if source_init != "exact":
        raise ValueError(
            "source_radius applies to source_init='exact' (the nodes near a source fixed to the exact time)"
        )


def _check_order(order: Any) -> Union[int, str]:
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


def _solve_on_tube(
    tube: _PreparedTube,
    src: np.ndarray,
    general: Any,
    scheme: str,
    speed: Any,
    source_init: str,
    tol: Optional[float],
    max_iterations: int,
    cb: Any,
    infinity: Any,
    threads: int,
    paper_sweeps: bool,
    t0: float,
    reuse: bool,
    source_radius: Optional[float] = None,
) -> "Solution":
    """Fixes the sources on the prepared tube and sweeps. With ``reuse`` the tube is left as it
    was (its roles and directions are copied); without, its arrays are consumed and dropped
    before the sweeps."""
    if not isinstance(paper_sweeps, (bool, np.bool_)):
        raise TypeError(f"paper_sweeps must be True or False; got {paper_sweeps!r}")
    grid, surf, band = tube.grid, tube.surface, tube.band
    cut_edges = tube.cut_edges
    crease_thinned = thinned_count(tube)
    if crease_thinned == 0:  # the paper's tube: its creases' corners are cut
        warn_paper_tube_creases(paper_creases_of(tube), tube.inner, grid.spacing)
    if scheme == "lxf" and cut_edges:
        # the Lax–Friedrichs update extrapolates a missing neighbour and does not settle beside
        # edges cut inside the tube (``_shortcuts``): it runs on the whole band, and the narrow
        # gaps the cut would have closed are warned about
        band, cut_edges = uncut_band(tube), 0
        warn_facing_pairs(grid, tube.linear, tube.roles, tube.facing, tube.inner)
    # the parts of the surface (before the sweeps consume the tube): a part without a source
    # keeps inf whatever reached it across a narrow gap (``_parts``)
    parts = part_labels(tube, band)
    sourced = None if parts is None else source_parts(grid, band, parts, src, surf)
    h = grid.spacing
    inner_width = tube.inner * h
    roles = tube.roles.copy() if reuse else tube.roles
    linear = tube.linear
    # a callable at the nodes' closest points (an array is read at the nodes)
    speed_nodes = speed_on_surface(speed, grid, linear, tube.phi, _directions_of(tube), inner_width)
    slowness: Any = 1.0 / speed_nodes

    def slowness_at(p: np.ndarray) -> np.ndarray:
        if callable(speed):
            return 1.0 / speed_at_points(speed, p, "a source or the closest point of a node near it")
        if np.ndim(speed) == 0:
            return np.full(len(p), 1.0 / float(speed))
        from .euclidean import _interp_dense

        f = _interp_dense(np.asarray(speed, dtype=float), grid, p)
        return 1.0 / checked_point_speeds(f, p, "interpolated from the speed array next to a source")

    # (the default: 1e-10 of the travel time across the grid, at most 1e-10; a Hamiltonian's own
    # travel times set it in _hamiltonian_solve)
    given_tol = tol
    tol = first_order_tol(tol, h, float(np.mean(slowness)), max(grid.shape))
    if general is None:
        check_tolerance_scale(tol, h, float(np.mean(slowness)), max(grid.shape))
    # the exact initialisation's radius in grid spacings
    radius = SOURCE_RADIUS if source_radius is None else max(SOURCE_RADIUS, float(source_radius) / h)
    positions, fixed_vals, fixed_sources = _fix_sources(
        surf, grid, band, linear, roles, src, slowness_at, source_init, inner_width, radius, cut_edges > 0
    )
    roles[positions] = ROLE_FIXED
    if tube.method != "naive" and len(src) == 1 and not np.any(roles == ROLE_INNER) and radius > SOURCE_RADIUS:
        raise ValueError(
            f"source_radius = {source_radius:g} covers the whole inner tube: every node lies within it of the source, so "
            f"its value is the source's initialisation and nothing is solved; use a smaller source_radius (a few "
            f"grid spacings, h = {h:.4g}, up to a small fraction of the surface's size) or leave it out"
        )
    if tube.method != "naive" and len(src) == 1 and not np.any(roles == ROLE_INNER):
        raise ValueError(
            f"the grid is too coarse for this surface: every node of the inner tube lies within {radius:g} grid "
            f"spacings (h = {h:.4g}) of a source, so its value is the source's initialisation and nothing is solved; "
            f"refine the grid"
        )
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
            directions = tube.geom.directions_for_solver()  # type: ignore[union-attr]  # a copy: the tube's stay as they are
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
        values, st, tol = _hamiltonian_solve.solve_band(
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
            radius,
            given_tol,
            max_iterations,
            _infinity(infinity),
            cb,
            _threads(threads),
            ACTIVATION_FRACTION,
            not paper_sweeps,
        )
    warn_unconverged(st, tol, max_iterations)
    values[values >= st["infinity"]] = np.inf  # never reached (another component of the surface)
    if parts is not None:
        drop_unsourced(values, parts, sourced)
    # no NaN, and no inf next to a reached node in a solve reported converged (the inner tube of a
    # part without a source is unreachable: next to a reached part across a narrow gap, not stranded)
    reachable = on_sourced_parts(parts, sourced)
    check_values(
        grid,
        band,
        values,
        (roles != ROLE_OUTER) if reachable is None else (roles != ROLE_OUTER) & reachable,
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
        cut_edges=cut_edges,
        crease_thinned=crease_thinned,
        thin_strip_iterations=(int(st["thin_strip_iterations"][0]), int(st["thin_strip_iterations"][1])),
        prefetch_iterations=int(st["prefetch_iterations"]),
        local_solver=st.get("local_solver", scheme),
        box_cut=tube.box_cut,
        creases=tube.paper_creases,
        bridged_holes=tube.bridged_holes,
        slits=tube.slits,
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
