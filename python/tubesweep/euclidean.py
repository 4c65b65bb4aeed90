"""First-arrival times in the whole box: the fast sweeping method of Sect. 2 (Algorithm 1)."""

from __future__ import annotations

import dataclasses
import time
import warnings
from functools import lru_cache
from typing import Any, Callable, Literal, Optional, Tuple, Union, overload

import numpy as np

from . import _native
from ._validate import (
    check_flag,
    ACTIVATION_FRACTION,
    check_threads as _threads,
    check_infinity as _infinity,
    as_grid,
    as_sources,
    check_hamiltonian,
    check_memory,
    check_tolerance,
    check_tolerance_scale,
    first_order_tol,
    tolerance_slowness,
    speed_at_points,
    progress_callback,
    speed_values,
    warn_unconverged,
)
from ._result_check import check_values
from ._stagnation import fallback_message
from ._warn import user_stacklevel
from .box_order2 import NOT_GODUNOV, check_order, order2_tol, solve_order2
from .box_solution import BoxSolution
from .grid import Grid
from .stats import SolveStats

__all__ = ["travel_time", "SOURCE_RADIUS"]

#: Nodes within this many grid spacings of a point source are initialised with the exact local
#: travel time |x − x_s| times the mean slowness (trapezoidal rule), so the source singularity
#: costs no O(1) error (scikit-fmm's 1.707 instead of √2 one cell off a source).
SOURCE_RADIUS = 2.0

# values + output copy + role + the box's band (last index 4, neighbour table 4·2(d − 1) ≤ 16, row
# flags 1, schedule about 1); the fixed values are sparse
_BYTES_PER_BOX_NODE = 8 + 8 + 1 + 4 + 16 + 1 + 1


@lru_cache(maxsize=2)
def _box_band(shape: Tuple[int, ...]) -> Any:
    return _native.Band.full_box(list(shape))


def _source_nodes(
    grid: Grid, sources: np.ndarray, slowness_at: Callable[[np.ndarray], np.ndarray]
) -> Tuple[np.ndarray, np.ndarray]:
    """Linear indices and exact local travel times of the nodes near the sources."""
    h = grid.spacing
    r = int(np.ceil(SOURCE_RADIUS))
    offsets = np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * grid.ndim), indexing="ij"), axis=-1).reshape(
        -1, grid.ndim
    )
    best: dict = {}
    for s in sources:
        base = np.floor(grid.continuous_index(s[None])[0]).astype(np.int64)
        idx = base + offsets
        ok = np.all((idx >= 0) & (idx < np.asarray(grid.shape)), axis=1)
        idx = idx[ok]
        x = grid.points(idx)
        dist = np.linalg.norm(x - s, axis=1)
        near = dist <= SOURCE_RADIUS * h + 1e-12 * h
        idx, x, dist = idx[near], x[near], dist[near]
        slow = 0.5 * (slowness_at(x) + slowness_at(s[None])[0])
        t = dist * slow
        for lin, val in zip(grid.linear_index(idx), t):
            if lin not in best or val < best[lin]:
                best[lin] = val
    lin = np.fromiter(best.keys(), dtype=np.int64, count=len(best))
    val = np.fromiter(best.values(), dtype=float, count=len(best))
    return lin, val


@overload
def travel_time(
    grid: Grid,
    sources: Any,
    *,
    speed: Any = ...,
    hamiltonian: Any = ...,
    tol: Optional[float] = ...,
    max_iterations: int = ...,
    return_stats: Literal[False] = ...,
    progress: Any = ...,
    infinity: Optional[float] = ...,
    threads: int = ...,
    order: Union[int, str] = ...,
    return_solution: Literal[False] = ...,
    flow: Any = ...,
    allow_supersonic: bool = ...,
) -> np.ndarray: ...
@overload
def travel_time(
    grid: Grid,
    sources: Any,
    *,
    speed: Any = ...,
    hamiltonian: Any = ...,
    tol: Optional[float] = ...,
    max_iterations: int = ...,
    return_stats: Literal[True],
    progress: Any = ...,
    infinity: Optional[float] = ...,
    threads: int = ...,
    order: Union[int, str] = ...,
    return_solution: Literal[False] = ...,
    flow: Any = ...,
    allow_supersonic: bool = ...,
) -> Tuple[np.ndarray, SolveStats]: ...
@overload
def travel_time(
    grid: Grid,
    sources: Any,
    *,
    speed: Any = ...,
    hamiltonian: str = ...,
    tol: Optional[float] = ...,
    max_iterations: int = ...,
    return_stats: Literal[False] = ...,
    progress: Any = ...,
    infinity: Optional[float] = ...,
    threads: int = ...,
    order: Union[int, str] = ...,
    return_solution: Literal[True],
) -> BoxSolution: ...


def travel_time(
    grid: Grid,
    sources: Any,
    *,
    speed: Union[float, np.ndarray, Callable[[np.ndarray], np.ndarray]] = 1.0,
    hamiltonian: Any = "godunov",
    tol: Optional[float] = None,
    max_iterations: int = 1000,
    return_stats: bool = False,
    progress: Optional[Callable[[int, float, int], None]] = None,
    infinity: Optional[float] = None,
    threads: int = 0,
    order: Union[int, str] = 1,
    return_solution: bool = False,
    flow: Any = None,
    allow_supersonic: bool = False,
) -> Union[np.ndarray, Tuple[np.ndarray, SolveStats], BoxSolution, Tuple[BoxSolution, SolveStats]]:
    """First-arrival time ``u`` with ``|∇u| = 1/F`` in the whole box, from point sources.

    The fast sweeping method (paper Sect. 2, Algorithm 1): Gauss–Seidel sweeps in the 2^d
    alternating orders with the Godunov update (Eq. 3 and its 3D form) or the Lax–Friedrichs update
    (Eq. 4, values only ever decrease). Nodes within ``SOURCE_RADIUS`` grid spacings of a source
    start at the exact local travel time, so point sources anywhere in the box (not only on nodes)
    are accurate.

    Parameters
    ----------
    grid : Grid
        The box and its nodes.
    sources : array-like (K, d)
        Source points anywhere in the box.
    speed : float, ndarray of ``grid.shape``, or callable ``f(points (M, d)) -> (M,)``
        Wave speed F > 0.
    hamiltonian : {"godunov", "lxf"} or a ``ts.hamiltonians`` object
        ``ts.hamiltonians.Metric(M)`` solves ``sqrt(∇uᵀ M ∇u) = 1/F`` (``M`` constant, an array of
        ``grid.shape + (d, d)`` or a callable on points), ``MovingMedium(v)`` the moving medium;
        both with the upwind local solver by default (``scheme="lxf"`` for Sect. 5.1's update).
    flow : callable ``v(points (M, d)) -> (M, d)``, array of ``grid.shape + (d,)`` or a vector, optional
        A moving medium: ``|∇u| = |1 − v·∇u| / F``, a front with normal ``n`` advancing at
        ``F + v·n``; with ``hamiltonian="godunov"`` (default) the upwind local solver, with
        ``"lxf"`` the Lax–Friedrichs update. ``|v| ≥ F`` is a ``ValueError`` unless
        ``allow_supersonic=True`` (then Lax–Friedrichs, with a warning).
    allow_supersonic : bool
        Solve a flow with ``|v| ≥ F`` somewhere anyway (Lax–Friedrichs, with a ``RuntimeWarning``).
    tol : float, optional
        Stop when the largest change in one iteration (2^d sweeps) is below ``tol``. Default
        with ``order=1`` 1e-10 of the travel time across the box (its longest side), at most 1e-10; with ``order=2`` each phase stops below
        ``1e-3 · s̄ · Δx² / L`` (``s̄`` the mean slowness, at most twice its lower quartile so that an
        obstacle does not loosen it; ``L`` the box's longest side), far below its O(Δx²) error.
    max_iterations : int
        A ``RuntimeWarning`` is issued if the sweeps have not converged by then.
    return_stats : bool
        Also return a :class:`SolveStats`.
    progress : callable, optional
        Called after every iteration as ``progress(iteration, max_change, updates)``.
    threads : int
        Worker threads for the sweeps (0: all cores, 1: sequential). The result does not depend
        on it: parallel sweeps are bit-identical to sequential ones.
    infinity : float, optional
        The finite "numerical infinity" that unknown values start at (default
        derived from the band: twice the cost of the longest grid path from a source, a safe upper
        bound on every travel time). It only matters for Lax–Friedrichs, whose update averages
        neighbours: a larger value costs more iterations. Not used by ``order=2``.
    order : {1, 2, "auto"}
        1: the first-order scheme of the paper (Algorithm 1). 2: the factored eikonal equation
        ``u = u₀ + w`` (``u₀`` the distance to the nearest source times the slowness there) with
        the limited second-order Godunov update, a monotone first-order phase and a second-order
        phase with a stagnation safeguard (``stats.order2``); Godunov only. Errors
        are O(Δx²) also for variable speed, and exact (up to the stopping test) for a constant
        speed and one source (docs/box-second-order.md). ``"auto"``: 2 with the Godunov update,
        1 with Lax–Friedrichs, a flow or a Hamiltonian object (``stats.order`` says which ran,
        ``stats.order_fallback`` why not 2). The default is 1, where :func:`tubesweep.solve`'s is
        ``"auto"``: in the box, the paper's Algorithm 1 is the reference every table and benchmark
        of the box compares against, and the box is where sharp speed contrasts (layers,
        obstacles) are common, on which the factored sweeps can run away and fall back to
        order 1 (``stats.order2["runaway_iteration"]``); ``order=2`` also costs 3–10× the time
        per solve. On a surface the default's choice is made from the geometry alone.
    return_solution : bool
        Return a :class:`BoxSolution` (the values with point evaluation, ``sol(points,
        interpolation="linear" | "cubic")``, exactly 0 at a source) instead of the array.

    Returns
    -------
    u : numpy.ndarray or BoxSolution
        Travel times, an array of ``grid.shape``; with ``return_solution=True`` a
        :class:`BoxSolution` holding it, with point evaluation.
    stats : SolveStats
        Only with ``return_stats=True``.

    Raises
    ------
    ValueError
        For sources outside the box, a speed that is not positive and finite, a bad tolerance,
        ``order`` other than 1, 2 or ``"auto"`` (or ``order=2`` with Lax–Friedrichs), or a box too large for
        the memory available (use the narrow-band solver for surfaces).

    Warns
    -----
    RuntimeWarning
        If the sweeps have not converged within ``max_iterations``; with ``order=2``, also if the
        factored sweeps ran away on a sharp speed contrast (the values are then ``order=1``'s,
        ``stats.order2["runaway_iteration"]``).

    Examples
    --------
    >>> import tubesweep as ts
    >>> grid = ts.Grid((-1, -1), (1, 1), (201, 201))
    >>> u = ts.travel_time(grid, [(0.013, -0.2)], speed=2.0)
    >>> sol = ts.travel_time(grid, [(0.013, -0.2)], speed=lambda p: 2 + p[:, 0], order=2, return_solution=True)
    >>> float(sol([(0.013, -0.2)])[0])  # exactly 0 at the source
    0.0
    """
    t0 = time.perf_counter()
    check_flag(return_stats, "return_stats")
    check_flag(return_solution, "return_solution")
    grid = as_grid(grid)
    src = as_sources(sources, grid)
    from . import hamiltonians as _hams

    general = _hams.resolve(hamiltonian, flow, allow_supersonic)
    scheme = check_hamiltonian(hamiltonian) if general is None else general.label
    order = check_order(order)
    fallback: Optional[str] = None
    if order != 1 and scheme != "godunov":
        if order == 2:
            raise ValueError(NOT_GODUNOV)
        fallback = NOT_GODUNOV  # order="auto": the first-order scheme, the reason in the stats
    order = 1 if order == "auto" and fallback is not None else (2 if order == "auto" else order)
    if general is not None and return_solution:
        raise ValueError(
            "return_solution=True is for the eikonal equation; with flow= or a Hamiltonian object "
            "travel_time returns the array (pass return_solution=False)"
        )
    check_tolerance(tol, max_iterations)
    cb = progress_callback(progress)
    # before anything of the box's size is allocated (a callable speed also takes the nodes'
    # coordinates, twice: the meshgrid and the stacked points)
    per_node = _BYTES_PER_BOX_NODE + (16 * grid.ndim if callable(speed) else 0)
    if general is not None:  # the nodes' coordinates, the slowness and the flow or metric per node
        per_node += 8 * grid.ndim + 8 + general._box_bytes_per_node(grid.ndim)
    check_memory(grid.size * per_node, f"a {grid.shape} box", "use a coarser grid or the narrow-band surface solver")

    if callable(speed) or np.ndim(speed) > 0:
        pts = (
            np.stack([c.reshape(-1) for c in grid.meshgrid()], axis=1) if callable(speed) else np.empty((0, grid.ndim))
        )
        f = speed_values(speed, grid, pts, None)
        slowness: Any = 1.0 / f
        del pts
    else:
        slowness = 1.0 / speed_values(speed, grid, np.empty((0, grid.ndim)), None)

    if general is not None:
        from .anisotropic_box import travel_time_general

        result = travel_time_general(
            grid,
            src,
            general,
            slowness,
            tol,
            max_iterations,
            return_stats,
            cb,
            _infinity(infinity),
            _threads(threads),
            _box_band(grid.shape),
            SOURCE_RADIUS,
            t0,
        )
        if return_stats and fallback is not None:
            result = (result[0], dataclasses.replace(result[1], order_fallback=fallback))
        return result
    if tol is None and order == 1:
        # 1e-10 of the travel time across the box, at most 1e-10
        tol = first_order_tol(tol, grid.spacing, float(np.mean(slowness)), max(grid.shape))
    elif tol is None:
        # the mean slowness, capped where an obstacle pulls it up (_validate.tolerance_slowness)
        tol = order2_tol(grid, tolerance_slowness(slowness))
    check_tolerance_scale(tol, grid.spacing, float(np.mean(slowness)), max(grid.shape))

    def slowness_at(x: np.ndarray) -> np.ndarray:
        if callable(speed):
            return 1.0 / speed_at_points(speed, x, "a source")
        if np.ndim(slowness) == 0:
            return np.full(len(x), float(slowness))
        # multilinear interpolation of the slowness array
        return _interp_dense(np.asarray(slowness).reshape(grid.shape), grid, x)

    lin, val = _source_nodes(grid, src, slowness_at)
    if order == 2:
        return _order2(
            grid,
            src,
            slowness,
            slowness_at,
            lin,
            val,
            tol,
            max_iterations,
            cb,
            _threads(threads),
            t0,
            return_stats,
            return_solution,
        )
    band = _box_band(grid.shape)
    roles = np.ones(grid.size, dtype=np.uint8)
    roles[lin] = 0
    setup = time.perf_counter() - t0
    values, st = band.solve(
        roles,
        np.ascontiguousarray(lin, dtype=np.int64),
        np.ascontiguousarray(val, dtype=float),
        grid.spacing,
        slowness,
        None,
        scheme,
        "extrapolate",
        float(tol),
        int(max_iterations),
        _infinity(infinity),
        cb,
        _threads(threads),
        True,
        ACTIVATION_FRACTION * float(tol),
    )
    warn_unconverged(st, tol, max_iterations)
    values[values >= st["infinity"]] = np.inf
    check_values(grid, band, values, None, st, _infinity(infinity))  # every node of the box is reachable
    u = values.reshape(grid.shape)
    if not (return_stats or return_solution):
        return u
    stats = SolveStats.of_sweeps(
        st,
        band_points=grid.size,
        inner_points=grid.size - len(lin),
        outer_points=0,
        fixed_points=len(lin),
        setup_seconds=setup,
        band_bytes=band.nbytes + grid.size * 10 + 8 * band.n_rows,  # values, role, active flag; per row a lower bound
        local_solver=scheme,
        thin_strip_iterations=(int(st["thin_strip_iterations"][0]), int(st["thin_strip_iterations"][1])),
        prefetch_iterations=int(st["prefetch_iterations"]),
        order_fallback=fallback,
    )
    return _result(grid, u, src, slowness_at, stats, 1, return_stats, return_solution)


def _result(
    grid: Grid,
    u: np.ndarray,
    src: np.ndarray,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    stats: SolveStats,
    order: int,
    return_stats: bool,
    return_solution: bool,
) -> Any:
    if not return_solution:
        return (u, stats) if return_stats else u
    sol = BoxSolution(grid, u, src, np.asarray(slowness_at(src), float), slowness_at, stats, order, SOURCE_RADIUS)
    return (sol, stats) if return_stats else sol


def _order2(
    grid: Grid,
    src: np.ndarray,
    slowness: Any,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    lin: np.ndarray,
    val: np.ndarray,
    tol: float,
    max_iterations: int,
    cb: Any,
    threads: int,
    t0: float,
    return_stats: bool,
    return_solution: bool,
) -> Any:
    """``order=2``: the factored second-order sweeps (box_order2.py); the same fixed nodes as order 1."""
    setup = time.perf_counter() - t0
    values, st, _ = solve_order2(grid, src, slowness, slowness_at, lin, val, tol, max_iterations, cb, threads)
    if not st["converged"]:
        safeguard = (
            f"; the stagnation safeguard switched to accepting decreases only after iteration "
            f"{st['safeguard_iteration']}"
            if st["safeguard_iteration"] is not None
            else ""
        )
        warnings.warn(
            f"the second-order sweeps did not converge in max_iterations={max_iterations}: the largest change in "
            f"the last iteration was {st['last_change']:.3g} (tol={tol:g}, {st['first_order_iterations']} first-order "
            f"and {st['second_order_iterations']} second-order iterations{safeguard}). Increase max_iterations or "
            f"tol; the values returned are the last iterate",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    if st["converged"] and st["safeguard_iteration"] is not None:
        fallback = fallback_message(
            st["safeguard_iteration"] - st["first_order_iterations"],
            st["safeguard_change"],
            tol,
            values,
            recorded="stats.order2['fallback_iteration'] and ['fallback_change']",
            default_tol=order2_tol(grid, tolerance_slowness(slowness)),
        )
        if fallback is not None:
            warnings.warn("order=2: " + fallback, RuntimeWarning, stacklevel=user_stacklevel())
    if st["runaway_iteration"] is not None:
        warnings.warn(
            f"order=2: the factored sweeps ran away at iteration {st['runaway_iteration']} (travel times falling without "
            "bound: the speed varies too sharply for the factored update, e.g. a region far faster than the source's) "
            "and were abandoned: the values returned are the plain first-order scheme's (order=1). "
            "stats.order2['runaway_iteration'] records it; a smoother speed or order=1 avoids it",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    if np.any(np.isnan(values)):
        raise FloatingPointError(
            "the second-order solve produced NaN: the travel times left the float64 range in the local updates. "
            "Rescale the units of the grid or the speed so that the travel times lie between about 1e-100 and 1e100"
        )
    u = values.reshape(grid.shape)
    if not (return_stats or return_solution):
        return u
    stats = SolveStats.of_sweeps(
        st,
        band_points=grid.size,
        inner_points=grid.size - len(lin),
        outer_points=0,
        fixed_points=len(lin),
        setup_seconds=setup,
        # values, factor, source, fixed flag, two sweep stamps; the slowness if per node
        band_bytes=grid.size * (8 + 8 + 4 + 1 + 8) + (0 if np.ndim(slowness) == 0 else 8 * grid.size),
        order=2,
        order2={
            "first_order_iterations": st["first_order_iterations"],
            "second_order_iterations": st["second_order_iterations"],
            "fallback_iteration": (
                None if st["safeguard_iteration"] is None else st["safeguard_iteration"] - st["first_order_iterations"]
            ),
            "fallback_change": st["safeguard_change"],
            "runaway_iteration": st["runaway_iteration"],
            "plain_iterations": st["plain_iterations"],
            "unreached": int(np.count_nonzero(~np.isfinite(values))),
            "tol": float(tol),
            "fix_radius": SOURCE_RADIUS * grid.spacing,
        },
    )
    return _result(grid, u, src, slowness_at, stats, 2, return_stats, return_solution)


def _interp_dense(arr: np.ndarray, grid: Grid, x: np.ndarray) -> np.ndarray:
    """Multilinear interpolation of a dense array of grid.shape at points x (M, d)."""
    t = grid.continuous_index(x)
    base = np.clip(np.floor(t), 0, np.asarray(grid.shape) - 2).astype(np.int64)
    frac = np.clip(t - base, 0.0, 1.0)
    out = np.zeros(len(x))
    d = grid.ndim
    for corner in range(1 << d):
        bits = np.array([(corner >> k) & 1 for k in range(d)])
        w = np.prod(np.where(bits == 1, frac, 1 - frac), axis=1)
        out += w * arr[tuple((base + bits).T)]
    return out
