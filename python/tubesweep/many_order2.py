"""Many sources at second order: :meth:`tubesweep.Tube.solve_many` with ``order=2`` (or ``"auto"``
where second order applies).

The tube's geometry (n and B = (I − φD²φ)⁻¹ per node, ``tubesweep_core::second_order::geometry``)
is computed once for the batch and shared by every solve; each source gets its own factoring
(u = u₀ + w, the nodes near it fixed) and its own second-order sweeps on one thread, the sources on
``threads`` threads at once with the GIL released (``tubesweep_core::second_order::many``). Each
row is the single ``tube.solve([source], order=2)`` of that source bit for bit, read at ``at`` as
``sol(at)`` reads it (the factored form near the source). Memory: one band's working arrays per
thread, the tube's geometry once, and the K × M values (nothing of size sources × band nodes
with ``at``).
"""

from __future__ import annotations

import re
import warnings
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional, Tuple

import numpy as np

from . import _native
from ._coarse_creases import widened_for_order2
from ._creases import thinned_spacings, warn_creases
from ._factoring import FACTORED_CURVATURE_RADII, FACTORED_RADIUS, undercut_sources
from ._parts import drop_unsourced_rows, part_labels
from ._prepare import thinned_count
from ._runaway import first_order_errors, runaway_cause
from ._sheet_readout import own_side_plan
from .mask import mask_advice
from ._stagnation import FALLBACK_WARNING, fallback_message
from ._validate import FRONT_WINDOW, as_sources
from ._warn import user_stacklevel
from . import second_order as so

if TYPE_CHECKING:  # pragma: no cover
    from .tube import Tube

__all__ = ["solve_many_order2"]


def renamed(e: ValueError, k: int, group: bool) -> ValueError:
    """A source error of a single solve (which numbers the points of one solve) renamed to the
    source's place among the K: ``sources[k]`` or ``sources[k][j]``."""
    text = re.sub(r"sources\[(\d+)\]", (lambda m: f"sources[{k}][{m.group(1)}]") if group else f"sources[{k}]", str(e))
    return ValueError(text)


def solve_many_order2(
    tube: "Tube",
    groups: List[np.ndarray],
    *,
    points: Optional[np.ndarray],
    speed: Any,
    tol: Optional[float],
    max_iterations: int,
    progress: Optional[Callable[[int, int], Any]],
    threads: int,
    number_from: int = 0,
) -> Tuple[np.ndarray, Dict[str, Any]]:
    """The second-order batch (see the module's documentation): ``(values, stats)``, values
    ``(K, band_points)`` or ``(K, M)`` at ``points``. Raises :class:`second_order.Order2NotApplicable`
    where ``order=2`` does not apply to the tube (the caller falls back under ``order="auto"``).
    Sources whose sweeps ran away are flagged in the stats' ``restart_failed``, ``ran_away`` saying
    why; their rows are to be replaced."""
    t = tube._tube_order2  # thinned at a level set's creases, as ts.solve's
    grid, surf = t.grid, t.surface
    h = grid.spacing
    d = grid.ndim
    inputs = so.tube_inputs(t, speed, tol)
    srcs: List[np.ndarray] = []
    names: List[str] = []
    for k, g in enumerate(groups):
        try:
            srcs.append(as_sources(g, grid))
        except ValueError as e:
            raise renamed(e, k, len(g) > 1) from None
        names.extend([f"sources[{k}]"] if len(g) == 1 else [f"sources[{k}][{j}]" for j in range(len(g))])
    every = np.ascontiguousarray(np.concatenate(srcs), dtype=float)
    offsets = np.concatenate([[0], np.cumsum([len(s) for s in srcs])]).astype(np.int64)
    feet, src_slowness = so.source_feet(surf, grid, every, t.inner * h, speed, names)
    for k in range(len(srcs)):  # a row's several points factored at their own speeds (_factoring)
        undercut = undercut_sources(
            feet[offsets[k] : offsets[k + 1]], src_slowness[offsets[k] : offsets[k + 1]], so.FIX_RADIUS * h
        )
        if undercut is not None:
            raise so.Order2NotApplicable(f"sources[{k}]: {undercut}")
    at_feet = None
    plan = None
    labels = part_labels(t)  # (read once: the plan and the parts without a source)
    if points is not None:
        points = np.ascontiguousarray(points, dtype=float)
        # on a band cut across narrow gaps (or a mesh of separate pieces), points next to a gap
        # read from their own side (as sol(points)): their cells' corners are read as extra points
        plan = own_side_plan(grid, surf, t.band, t.facing, len(t.linear), points, cut=bool(t.cut_edges), labels=labels)
        if plan is not None:
            points = np.ascontiguousarray(np.concatenate([points, plan.corners]))
        # the points' closest points (used within the reach of a source only), on every kind of
        # surface, as sol(points) reads them (_factoring.factored_values); a point the surface
        # cannot project is never within that reach
        with np.errstate(invalid="ignore", over="ignore"):
            d_surface, proj = surf.project(points, grid)
        d_surface = np.asarray(d_surface, dtype=float)
        proj = np.asarray(proj, dtype=float)
        keep = (d_surface <= 1e-9 * h) | ~np.all(np.isfinite(proj), axis=1)
        at_feet = np.ascontiguousarray(np.where(keep[:, None], points, proj))
    windows = so.windows_of(d, inputs.slowness)
    try:
        values, st = _native.second_order_solve_many(
            t.band,
            np.ascontiguousarray(t.roles),
            np.ascontiguousarray(t.geom.signed, dtype=np.float64),  # type: ignore[union-attr]
            inputs.directions,
            [float(c) for c in grid.lower],
            h,
            feet,
            src_slowness,
            offsets,
            inputs.slowness,
            so.FIX_RADIUS * h,
            t.outer_eff * h,
            inputs.tol_first,
            inputs.tol,
            int(max_iterations),
            progress,
            threads=threads,
            front_window=FRONT_WINDOW if d == 3 else 0.0,
            own_first_phase=so._OWN_FIRST_PHASE[grid.ndim],
            cp_offsets=inputs.offsets,
            window_first=windows[0],
            window_second=windows[1],
            ramp_length=inputs.length,
            extension_limit=so.EXTENSION_LIMIT,
            at=points,
            at_feet=at_feet,
            reach_spacings=FACTORED_RADIUS,
            reach_curvature_radii=FACTORED_CURVATURE_RADII if inputs.exact_feet else 0.0,
        )
    except ValueError as e:
        if "order=2" in str(e):
            raise so.Order2NotApplicable(mask_advice(t.surface, str(e))) from None
        raise
    st = dict(st)
    # a part without a source keeps inf (``_parts``), read as the single solve reads it
    values = drop_unsourced_rows(values, t, groups, points, labels=labels)
    if plan is not None:
        m = len(points) - len(plan.corners)  # type: ignore[arg-type]
        values = plan.apply(np.ascontiguousarray(values[:, :m]), values[:, m:])
    failed = np.flatnonzero(st["restart_failed"])
    if failed.size:
        # values falling without bound for these sources: no factored solution; the caller raises
        # (order=2) or solves them at first order ("auto"), with this text (second_order.Order2RanAway)
        st["ran_away"] = so.ran_away_message(
            int(st["runaway_iteration"][failed[0]]), inputs.slowness, src_slowness, t.surface
        )
    st["tol"] = inputs.tol
    st["bridged_holes"] = t.bridged_holes
    st["slits"] = t.slits
    so.warn_first_order_nodes(st, t.surface, "tube.solve(source).first_order_points() shows where")
    widened_for_order2(st, t)  # a rounded crease read through a smoothing
    warn_creases(
        st.get("creases"),
        t.inner,
        h,
        thinned=thinned_spacings(t, thinned_count(t) > 0),
        redistanced=bool(getattr(t.surface, "redistance", False)),
    )
    for name, what in (
        (
            "converged",
            "did not converge in max_iterations={m}: their rows are the last iterate. Increase max_iterations or tol",
        ),
        (
            "runaway_iteration",
            "ran away (a travel time fell below zero): their rows are the first-order factored solution (order 1); order=1 avoids it, and so may a finer grid where this one barely resolves the surface",
        ),
    ):
        bad = np.flatnonzero(~st["converged"]) if name == "converged" else np.flatnonzero(st[name] >= 0)
        bad = np.setdiff1d(bad, failed)  # (those rows are replaced: said by the caller)
        if bad.size:
            warnings.warn(
                f"order=2: {bad.size} of {len(groups)} solves "
                + what.format(m=max_iterations)
                + f" (sources {(bad[:5] + number_from).tolist()}{'…' if bad.size > 5 else ''})",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
    warn_runaway_rows(st, failed, len(groups), number_from, runaway_cause(inputs.slowness, src_slowness, t.surface))
    # the stagnation fallbacks large enough to warn of (``_stagnation``), as the single solve does
    large = np.flatnonzero(
        (st["fallback_iteration"] >= 0)
        & (st["fallback_change"] > FALLBACK_WARNING * inputs.tol)
        & ~st["restart_failed"]
    )
    if large.size:
        worst = int(large[np.argmax(st["fallback_change"][large])])
        text = fallback_message(
            int(st["fallback_iteration"][worst]),
            float(st["fallback_change"][worst]),
            inputs.tol,
            values[worst],
            recorded="the stats' 'fallback_iteration' and 'fallback_change' (return_stats=True)",
            default_tol=inputs.default_tol,
        )
        warnings.warn(
            f"order=2: {large.size} of {len(groups)} solves (sources {(large[:5] + number_from).tolist()}"
            f"{'…' if large.size > 5 else ''}) fell back to decreases only; in solve {worst + number_from}, the largest: "
            f"{text}",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return values, st


def warn_runaway_rows(st: Dict[str, Any], failed: np.ndarray, k: int, number_from: int, cause: str) -> None:
    """The warning of a batch's solves whose sweeps ran away and were solved again with the
    runaway's nodes at first order (``_runaway``; the stats' ``runaway_nodes`` per row), the
    rows that ran away again left to the caller."""
    redone = np.setdiff1d(np.flatnonzero((st["runaway_first_iteration"] >= 0) & (st["runaway_iteration"] < 0)), failed)
    if not redone.size:
        return
    most = int(np.max(st["runaway_nodes"][redone]))
    share = 100.0 * most / max(int(st["inner_nodes"]), 1)
    warnings.warn(
        f"order=2: the second-order sweeps of {redone.size} of {k} solves (sources "
        f"{(redone[:5] + number_from).tolist()}{'…' if redone.size > 5 else ''}) ran away: the factored update is not "
        f"causal {cause}. They were solved again from their sources with up to {most} inner-tube nodes ({share:.2g}% "
        "of them) at the paper's first-order update, second order elsewhere: their errors are "
        f"{first_order_errors(cause)}. The stats' 'runaway_nodes' (return_stats=True) counts them per solve",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
