"""Many sources on one band: :meth:`tubesweep.Tube.solve_many`.

K independent solves of Algorithm 3 on a band built once, run in parallel *across* the sources
(``tubesweep_core::sweep::many_sources``): each solve runs on one thread, the sources on ``threads``
threads at once with the GIL released. Each row is the single ``tube.solve`` of that source, bit
for bit (the parallel sweeps of one solve are bit-identical to sequential ones, so this holds for
any ``threads`` of the single solve). With ``at=points`` only the values at the points are kept:
memory O(band · threads + K · M) instead of K band arrays.
"""

from __future__ import annotations

import time
import warnings
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional, Tuple

import numpy as np

from . import _native
from ._validate import (
    check_memory,
    check_flag,
    ACTIVATION_FRACTION,
    FRONT_WINDOW,
    as_points,
    as_sources,
    check_infinity,
    check_threads,
    check_tolerance,
    check_tolerance_scale,
    tolerance_slowness,
    first_order_tol,
    speed_on_surface,
)
from ._creases import warn_paper_tube_creases
from ._warn import user_stacklevel
from ._wide_tube import tube_shortcut, warn_wide_tube
from ._facing import warn_facing_pairs
from ._prepare import paper_creases_of, thinned_count, uncut_band
from ._roles import ROLE_INNER
from ._parts import drop_unsourced_rows, part_labels
from ._sheet_readout import own_side_plan
from ._fallback import Fallback
from ._sources import SOURCE_RADIUS, _fix_sources, slowness_on_surface
from .many_order2 import renamed, solve_many_order2
from . import second_order as so
from ._request import check_source_init, resolve_scheme
from .second_order import check_order

if TYPE_CHECKING:  # pragma: no cover
    from .tube import Tube

__all__ = ["solve_many", "source_groups"]


def source_groups(sources: Any, ndim: int) -> List[np.ndarray]:
    """The K sources of ``solve_many`` as a list of (P, d) arrays: an array (K, d) is K point
    sources, an array (K, P, d) or a list whose entries are points (d,) or groups (P, d) of
    points may mix them (a group is one multi-source solve: the distance to the nearest of its
    points)."""
    if isinstance(sources, np.ndarray) and sources.dtype != object:
        if sources.ndim == 1:
            raise ValueError(
                f"sources must be K points (K, {ndim}) or a list of points and groups; got one point of shape "
                f"{sources.shape}: pass [point] for a single source"
            )
        if sources.ndim == 2:
            p = as_points(sources, ndim, "sources")
            return [p[i : i + 1] for i in range(len(p))]
        if sources.ndim == 3:
            return _non_empty([as_points(g, ndim, f"sources[{k}]") for k, g in enumerate(sources)])
        raise ValueError(
            f"sources must have shape (K, {ndim}) (K point sources), (K, P, {ndim}) (K groups of P points) "
            f"or be a list of points and groups; got shape {sources.shape}"
        )
    if isinstance(sources, (str, bytes)) or not hasattr(sources, "__len__"):
        raise TypeError(
            f"sources must be an array (K, {ndim}) or a list of points ({ndim},) and groups (P, {ndim}); "
            f"got {type(sources).__name__}"
        )
    if len(sources) and all(np.ndim(g) == 0 for g in sources):
        # one flat point ("sources[0] must have shape (M, 3); got shape ()" before: a helper's review)
        raise ValueError(
            f"sources must be K points (K, {ndim}) or a list of points and groups; got one point of {len(sources)} "
            f"numbers: pass [point] for a single source"
        )
    return _non_empty([as_points(g, ndim, f"sources[{k}]") for k, g in enumerate(sources)])


def _non_empty(groups: List[np.ndarray]) -> List[np.ndarray]:
    for k, g in enumerate(groups):
        if len(g) == 0:
            raise ValueError(
                f"sources[{k}] is an empty group: give each group at least one point (or leave the entry out)"
            )
    return groups


def fixed_nodes(
    tube: "Tube", groups: List[np.ndarray], speed: Any, source_init: str, uncut: Any = None, order: Any = 1
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The band positions and values each source fixes, concatenated, and the offsets (K + 1,)
    of each source's run: ``_fix_sources`` of a single solve, source by source. ``uncut``: the
    band before its cut (``_prepare.uncut_band``; the Lax–Friedrichs scheme), to fix them on;
    ``order`` other than 1: on the tube thinned at creases (``Tube._tube_first_auto``)."""
    t = tube._tube if order == 1 else tube._tube_first_auto
    band, connected = (uncut, False) if uncut is not None else (t.band, t.cut_edges > 0)
    grid, surf = t.grid, t.surface
    inner_width = t.inner * grid.spacing
    slowness_at = slowness_on_surface(speed, grid)
    n_inner = int(np.count_nonzero(t.roles == ROLE_INNER))
    positions, values, offsets = [], [], [0]
    for k, g in enumerate(groups):
        try:
            src = as_sources(g, grid)
            pos, val, _ = _fix_sources(
                surf,
                grid,
                band,
                t.linear,
                t.roles,
                src,
                slowness_at,
                source_init,
                inner_width,
                connected=connected,
            )
        except ValueError as e:
            raise renamed(e, k, len(g) > 1) from None
        if t.method != "naive" and len(src) == 1 and np.unique(pos).size >= n_inner:
            raise ValueError(
                f"sources[{k}]: the grid is too coarse for this surface: every node of the inner tube lies within "
                f"{SOURCE_RADIUS:g} grid spacings (h = {grid.spacing:.4g}) of the source, so its value is the source's "
                "initialisation and nothing is solved; refine the grid"
            )
        positions.append(pos)
        values.append(val)
        offsets.append(offsets[-1] + len(pos))
    return (
        np.ascontiguousarray(np.concatenate(positions), dtype=np.int64),
        np.ascontiguousarray(np.concatenate(values), dtype=float),
        np.asarray(offsets, dtype=np.int64),
    )


def _check_split_at_creases(
    tube: "Tube", groups: List[np.ndarray], st: Dict[str, Any], speed: Any, tol: Optional[float], max_iterations: int
) -> None:
    """Raises :class:`second_order.Order2NotApplicable` where the inner tube, thinned at creases,
    splits (``second_order.split_at_creases``, which a single solve's band values show and the
    batch's rows at ``at`` do not): two balls joined by a thin neck read inf beyond it in every row,
    silently, until a ``tube.solve`` had refused the tube (a review). Only where creases thinned
    the tube and a row left nodes unreached (also a part no source is on): the single solve of that
    row's source decides, its warnings already given by the batch."""
    if thinned_count(tube._tube_order2) == 0:
        return
    unreached = np.flatnonzero(np.asarray(st.get("unreached", 0)) > 0)
    if unreached.size:
        _single_solve_decides(
            tube, groups[int(unreached[0])], order=2, speed=speed, tol=tol, max_iterations=max_iterations
        )


def _single_solve_decides(tube: "Tube", group: np.ndarray, **options: Any) -> None:
    """``tube.solve(group, **options)`` for what it raises: a row of the batch that the batch's
    own output cannot judge (it holds no band values, or only the rows at ``at``) is judged by
    the single solve of its source, which refuses as the batch should. Its warnings are the
    batch's, already given."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tube.solve(group, **options)


def check_many_progress(progress: Any) -> Optional[Callable[[int, int], Any]]:
    if progress is None or progress is False:
        return None
    if not callable(progress):
        raise TypeError("progress must be a callable (done, total) -> None, or None")
    return progress


def solve_many(
    tube: "Tube",
    sources: Any,
    *,
    at: Any = None,
    hamiltonian: Any = "godunov",
    speed: Any = 1.0,
    source_init: str = "exact",
    tol: Optional[float] = None,
    max_iterations: int = 10000,
    progress: Optional[Callable[[int, int], Any]] = None,
    infinity: Optional[float] = None,
    threads: int = 0,
    paper_sweeps: bool = False,
    return_stats: bool = False,
    order: Any = "auto",
    number_from: int = 0,
) -> Any:
    """See :meth:`tubesweep.Tube.solve_many` (the local run; a Dask client goes through
    :mod:`tubesweep.distributed`). ``number_from``: the first source's number in messages (a Dask
    chunk's place among the sources)."""
    t0 = time.perf_counter()
    check_flag(return_stats, "return_stats")
    order = check_order(order)
    tube._check_phi_unchanged()
    t = tube._tube
    grid = t.grid
    groups = source_groups(sources, grid.ndim)
    if len(groups) == 0:
        raise ValueError("sources is empty: give at least one source (a point, or a group of points)")
    general, scheme = resolve_scheme(hamiltonian, None, False)
    if general is not None:
        raise ValueError(
            "solve_many takes hamiltonian='godunov' or 'lxf'; for a ts.hamiltonians object solve each "
            "source with tube.solve"
        )
    check_tolerance(tol, max_iterations)
    cb = check_many_progress(progress)
    check_source_init(source_init)
    if not isinstance(paper_sweeps, (bool, np.bool_)):
        raise TypeError(f"paper_sweeps must be True or False; got {paper_sweeps!r}")
    nthreads = check_threads(threads)
    inf = check_infinity(infinity)
    points = None if at is None else as_points(at, grid.ndim, "at")
    # the K rows, checked before any source is set up (at order=1 a batch too large for memory
    # was refused by the allocation after minutes of per-source set-up: 120,000 sources, 172 s)
    width = len(points) if points is not None else len(t.linear)
    check_memory(
        8.0 * len(groups) * width,
        f"solve_many's {len(groups)} rows of {width} values",
        "pass at= the points you need (K × M values), or fewer sources per call",
    )
    first = dict(
        points=points,
        scheme=scheme,
        speed=speed,
        source_init=source_init,
        tol=tol,
        max_iterations=max_iterations,
        cb=cb,
        inf=inf,
        nthreads=nthreads,
        paper_sweeps=bool(paper_sweeps),
    )
    fallback: Optional[Fallback] = None  # order="auto" running the first-order scheme, and why
    if order != 1:
        try:
            so.check_supported(t.surface, None, scheme, t.method, source_init, bool(paper_sweeps))
            so.check_widths(tube._args[0], tube._args[1])  # the widths given decide, as tube.solve's
            if tube._order2_refusal is not None:  # this band's geometry, refused before
                raise so.Order2NotApplicable(tube._order2_refusal)
            try:
                out, st = solve_many_order2(
                    tube,
                    groups,
                    points=points,
                    speed=speed,
                    tol=tol,
                    max_iterations=max_iterations,
                    progress=cb,
                    threads=nthreads,
                    number_from=number_from,
                )
                _check_split_at_creases(tube, groups, st, speed, tol, max_iterations)
            except so.Order2NotApplicable as e:
                tube._order2_refusal = str(e)  # depends on the band only: not computed again
                raise
        except so.Order2NotApplicable as e:
            if order == 2:
                raise
            fallback = Fallback.of(e, order)
            if fallback.option_of_order1:
                order = 1  # an option of the first-order scheme: its tube, as ts.solve's and tube.solve's
        else:
            orders, reason = _runaway_rows(tube, groups, out, st, order, first, number_from)
            if return_stats:
                # the lowest order of any row ("orders": each row's)
                st.update(
                    order=int(orders.min()),
                    orders=orders,
                    order_fallback=reason,
                    seconds_total=time.perf_counter() - t0,
                )
                return out, st
            return out
    numbers = np.arange(len(groups)) + number_from if number_from else None
    out, st = _first_order_batch(tube, groups, order, fallback, **first, numbers=numbers)
    if return_stats:
        st["seconds_total"] = time.perf_counter() - t0
        st["orders"] = np.ones(len(groups), dtype=np.int8)
        return out, st
    return out


def _runaway_rows(
    tube: "Tube",
    groups: List[np.ndarray],
    out: np.ndarray,
    st: Dict[str, Any],
    order: Any,
    first: Dict[str, Any],
    number_from: int,
) -> Tuple[np.ndarray, Optional[str]]:
    """The rows of a second-order batch whose sweeps ran away, as ``tube.solve`` gives each: where
    the first-order factored restart ran away too (``restart_failed``), ``order=2`` raises and
    ``"auto"`` solves them with the first-order scheme (their rows of ``out`` and of the per-source
    stats ``st`` replaced); where it held, the row is that restart's (order 1). Returns each row's
    order and why some rows are first order (None: none is)."""
    orders = np.full(len(groups), 2, dtype=np.int8)
    reason = None
    restarted = (st["runaway_iteration"] >= 0) & ~st["restart_failed"]
    if np.any(restarted):
        orders[restarted] = 1  # (warned by solve_many_order2)
        reason = so.RAN_AWAY_RESTARTED.replace(
            "sol.stats.order2['runaway_iteration']", "the stats' 'runaway_iteration'"
        )
    text = st.pop("ran_away", None)
    failed = np.flatnonzero(st["restart_failed"])
    if failed.size == 0:
        return orders, reason
    numbers = failed + number_from
    ran_away = so.Order2RanAway(
        f"{text} ({failed.size} of {len(groups)} solves, sources {numbers[:5].tolist()}{'…' if failed.size > 5 else ''})"
    )
    if order == 2:
        raise ran_away
    warnings.warn(
        f"{ran_away}; their rows are the first-order solution (the stats' 'order_fallback' keeps this)",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
    lower = Fallback(str(ran_away), said=True)
    rows, sub = _first_order_batch(
        tube, [groups[i] for i in failed], "auto", lower, **{**first, "cb": None}, numbers=numbers
    )
    out[failed] = rows
    for key, value in sub.items():  # their stats are the first-order solves' (converged, iterations, ...)
        mine = st.get(key)
        if isinstance(value, np.ndarray) and isinstance(mine, np.ndarray) and mine.shape[:1] == (len(groups),):
            mine[failed] = value
    orders[failed] = 1
    return orders, lower.reason


def _first_order_batch(
    tube: "Tube",
    groups: List[np.ndarray],
    order: Any,
    fallback: Optional[Fallback],
    *,
    points: Optional[np.ndarray],
    scheme: str,
    speed: Any,
    source_init: str,
    tol: Optional[float],
    max_iterations: int,
    cb: Optional[Callable[[int, int], Any]],
    inf: float,
    nthreads: int,
    paper_sweeps: bool,
    numbers: Optional[np.ndarray] = None,
) -> Tuple[np.ndarray, Dict[str, Any]]:
    """The paper's first-order scheme for every group (``_native.solve_many_on_band``): on the
    paper's tube for ``order=1``, on the tube thinned at creases for ``"auto"``'s fallback (as
    ``tube.solve``), ``fallback`` then saying why; ``numbers``: the groups' places among the
    sources (the rows of those that ran away at second order). Returns the rows and the stats."""
    t0 = time.perf_counter()
    t = tube._tube
    grid = t.grid
    if order != 1:
        t = tube._tube_first_auto  # "auto"'s first order: on the tube thinned at creases, as ts.solve's
    if fallback is not None:
        fallback.measure(t)
    shortcut = tube_shortcut(t)  # an inner tube wider than the paper's
    warn_wide_tube(shortcut, t.inner, grid.spacing)
    linear = t.linear
    h = grid.spacing
    assert t.geom is not None  # a Tube keeps its geometry
    speed_nodes = speed_on_surface(speed, grid, linear, t.phi, t.geom.direction, t.inner * h)
    slowness: Any = 1.0 / speed_nodes
    tol = first_order_tol(tol, h, float(np.mean(slowness)), max(grid.shape))  # the first-order scheme's default
    check_tolerance_scale(
        tol, h, float(np.mean(slowness)), max(grid.shape), front_slowness=tolerance_slowness(slowness)
    )
    # the Lax–Friedrichs scheme runs on the band before its cut (``_shortcuts``), with the warning
    uncut = scheme == "lxf" and t.cut_edges > 0
    band = uncut_band(t) if uncut else t.band
    if uncut:
        warn_facing_pairs(grid, t.linear, t.roles, t.facing, t.inner)
    positions, values, offsets = fixed_nodes(tube, groups, speed, source_init, band if uncut else None, order)
    # on a band cut across narrow gaps, points next to a gap read from their own side: the values
    # at their cells' corners come back as extra points
    plan = None
    labels = part_labels(t, band)  # (a point whose cell spans two parts reads its reached corners)
    if points is not None:
        plan = own_side_plan(
            grid,
            t.surface,
            band,
            t.facing,
            len(t.linear),
            points,
            cut=bool(t.cut_edges) and not uncut,
            labels=labels,
        )
    read_at = points if plan is None else np.ascontiguousarray(np.concatenate([points, plan.corners]))
    missing_policy = "infinity" if (t.method == "naive" and scheme == "godunov") else "extrapolate"
    directions = t.geom.directions_for_solver()  # a copy: the tube's stay as they are
    setup = time.perf_counter() - t0
    out, st = _native.solve_many_on_band(
        band,
        t.roles,
        positions,
        values,
        offsets,
        h,
        slowness,
        directions,
        scheme,
        missing_policy,
        float(tol),
        int(max_iterations),
        inf,
        cb,
        nthreads,
        ACTIVATION_FRACTION * float(tol),
        not paper_sweeps,
        not paper_sweeps,
        0.0 if paper_sweeps else FRONT_WINDOW,
        read_at,
        None if points is None else [float(v) for v in grid.lower],
    )
    del directions
    unreached = np.flatnonzero(np.any(np.isinf(out), axis=1)) if inf is not None else []
    if len(unreached):
        # a user's infinity below the travel times stops the fronts where they meet it: refused as
        # tube.solve refuses it (rows of inf at reachable points, converged, unwarned: a review);
        # the single solve of a row with inf in it decides (also a part no source is on)
        _single_solve_decides(
            tube,
            groups[int(unreached[0])],
            order=order,
            hamiltonian=scheme,
            speed=speed,
            source_init=source_init,
            tol=tol,
            max_iterations=max_iterations,
            infinity=inf,
            paper_sweeps=paper_sweeps,
        )
    if fallback is not None:
        fallback.warn(out, t)
    if thinned_count(t) == 0:  # the paper's tube: its creases' corners are cut
        warn_paper_tube_creases(paper_creases_of(t), t.inner, h)
    # a part without a source keeps inf (``_parts``), read as the single solve reads it
    out = drop_unsourced_rows(out, t, groups, None if points is None else read_at, band, labels)
    if plan is not None:
        m = len(points)  # type: ignore[arg-type]
        out = plan.apply(np.ascontiguousarray(out[:, :m]), out[:, m:])
    bad = np.flatnonzero(~st["converged"])
    if bad.size:
        ids = bad if numbers is None else numbers[bad]
        warnings.warn(
            f"{bad.size} of {len(groups)} solves did not converge in max_iterations={max_iterations} (sources "
            f"{ids[:5].tolist()}{'…' if bad.size > 5 else ''}; the largest change in the last iteration "
            f"{float(np.max(st['last_change'][bad])):.3g}, tol={tol:g}): their rows are the last iterate. Increase "
            "max_iterations or tol",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    stats: Dict[str, Any] = dict(st)
    stats["setup_seconds"] = setup
    stats["order"] = 1
    stats["order_fallback"] = None if fallback is None else fallback.reason
    stats["creases"] = t.paper_creases if fallback is None or fallback.creases is None else fallback.creases
    stats["bridged_holes"] = t.bridged_holes
    stats["slits"] = t.slits
    stats["tube_shortcut"] = shortcut
    return out, stats
