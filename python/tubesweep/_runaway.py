"""Where the factored second-order sweeps run away (``tubesweep_core::second_order::demotion``).

The factored update ``u = u₀ + w`` is not causal where the speed is far higher than at the sources
(a region 70–1000 times faster) or where the closest points jump between parts of the surface (a
point cloud's fits over a hole in its samples): there the second-order sweeps run away, and their
first-order factored restart can creep after them. The native solve finds those nodes and solves
again from the sources with only them at the paper's first-order update (unfactored, monotone),
second order elsewhere; this module words the cause, the report (``sol.stats.order2["runaway"]``)
and the warning."""

from __future__ import annotations

import warnings
from typing import Any, Dict, Optional

import numpy as np

from ._warn import user_stacklevel

#: :func:`runaway_cause` names the speed as the cause of a runaway from this ratio of the
#: sources' slowness to the smallest in the band on (a fast region of 70–1000 times ran away on
#: the sphere at N = 41; 3–50 did not).
RAN_AWAY_CONTRAST = 10.0


def speed_contrast(slowness: Any, src_slowness: np.ndarray) -> float:
    """How many times faster than the sources the fastest part of the band is."""
    fastest = float(np.min(slowness))
    return float(np.max(src_slowness)) / fastest if fastest > 0 else float("inf")


def runaway_cause(slowness: Any, src_slowness: np.ndarray, surface: Any = None) -> str:
    """Why the factored update is not causal, as a clause after "not causal": the speed where it
    is far higher than at the sources, else what of the ``surface`` the grid may not resolve (its
    ``unresolved_advice`` where it has one: a point cloud's sampling)."""
    contrast = speed_contrast(slowness, src_slowness)
    if contrast >= RAN_AWAY_CONTRAST:
        return f"where the speed is much higher than at the sources (here up to {contrast:.3g} times)"
    speed = "a constant speed" if contrast <= 1.0 + 1e-9 else f"a speed at most {contrast:.3g} times the sources'"
    what = getattr(surface, "unresolved_advice", None) or (
        "a dent, bump or noise that the grid does not resolve: a finer grid or a smoother φ may avoid it"
    )
    return f"on this band, with {speed}: the surface is the likely cause ({what})"


def first_order_errors(cause: str) -> str:
    """What the nodes put at first order do to the errors, for a runaway of ``cause``
    (:func:`runaway_cause`): in a fast region, first order in its short travel times."""
    if cause.startswith("where the speed"):
        return "first order there, most of them in the fast region, whose travel times are that many times shorter"
    return "first order there and downstream of them"


def runaway_report(st: Dict[str, Any], tube: Any) -> Optional[Dict[str, Any]]:
    """``sol.stats.order2["runaway"]``: when the sweeps ran away and were solved again with the
    runaway's nodes at first order, the first attempt's phase-2 iteration at which they ran away,
    the inner-tube nodes left at first order, and the point where the values fell farthest."""
    if st.get("runaway_first_iteration") is None:
        return None
    at = st.get("runaway_at")
    near = None
    if at is not None:
        point = tube.grid.node_points(np.asarray(tube.linear)[[int(at)]])[0]
        near = tuple(round(float(c), 4) for c in point)
    return {
        "iteration": int(st["runaway_first_iteration"]),
        "nodes": int(st["first_order_reasons"]["runaway"]),
        "near": near,
    }


def warn_runaway(report: Optional[Dict[str, Any]], inner_nodes: int, cause: str) -> None:
    """The warning of a solve whose sweeps ran away and were solved again (``report``:
    :func:`runaway_report`), with its share of the inner tube and its cause (:func:`runaway_cause`)."""
    if report is None:
        return
    share = 100.0 * report["nodes"] / max(inner_nodes, 1)
    warnings.warn(
        f"order=2: the second-order sweeps ran away near {report['near']} at their iteration {report['iteration']} "
        f"(a travel time fell below zero): the factored update is not causal {cause}. Solved again from the "
        f"sources with the {report['nodes']} inner-tube nodes there ({share:.2g}% of them) at the paper's first-order "
        f"update and second order elsewhere: errors are {first_order_errors(cause)}. sol.first_order_points() shows where; "
        "sol.stats.order2['runaway'] records it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
