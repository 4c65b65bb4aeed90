"""The check every solve runs on its values before it returns them: no NaN, and no node left at
the numerical infinity next to one the front reached (a reachable node).

A node that no front reaches (a component of the surface without a source) legitimately holds
``inf``; a node whose neighbour in the inner tube was reached is reachable, so ``inf`` there means
the sweeps stopped short of it: a user's ``infinity`` below the travel times (the front stops
where it meets it), or a numerical failure. A solve that reports ``converged=True`` never returns
such values (docs/architecture.md, "Errors").
"""

from __future__ import annotations

import warnings
from typing import Any, Optional

import numpy as np

from .grid import Grid
from ._warn import user_stacklevel


def _first_point(grid: Grid, band: Any, positions: np.ndarray) -> tuple:
    lin = band.linear()[positions[:1]]
    return tuple(round(float(x), 6) for x in grid.node_points(lin)[0])


def stranded_nodes(grid: Grid, band: Any, values: np.ndarray, inner: Optional[np.ndarray]) -> np.ndarray:
    """Band positions of the inner-tube nodes at ``inf`` with an inner-tube neighbour that the
    front reached (finite), neighbours in the band's own table: an edge cut across a narrow gap
    (``_shortcuts``) joins nothing, and a part of a mesh that faces a reached one across such a gap
    is unreached, not stranded. Costs nothing when every node was reached; otherwise O(unreached)."""
    unreached = np.flatnonzero(~np.isfinite(values))
    if inner is not None:
        unreached = unreached[inner[unreached]]
    if unreached.size == 0:
        return unreached
    if inner is None:
        inner = np.ones(len(values), bool)
    nb = band.neighbours_of_nodes(np.ascontiguousarray(unreached, dtype=np.int64)).reshape(unreached.size, -1)
    found = nb < len(values)
    at = np.where(found, nb, 0)
    stranded = np.any(found & np.isfinite(values[at]) & inner[at], axis=1)
    return unreached[stranded]


def check_values(
    grid: Grid,
    band: Any,
    values: np.ndarray,
    inner: Optional[np.ndarray],
    stats: dict,
    user_infinity: Optional[float],
    reachability: bool = True,
) -> None:
    """Refuses to return NaN, and ``inf`` at a reachable node of a solve that reports it converged.

    ``values`` are the solution with the unreached nodes already at ``inf``; ``inner`` marks the
    inner tube (the fixed nodes included; None: every node, the box); ``stats`` the core's statistics (``converged`` is set to
    False with a warning where the check finds unreached nodes and no user infinity explains
    them); ``user_infinity`` the ``infinity`` the caller gave (None: derived from the band).
    ``reachability=False`` skips the second test (Hamiltonians under which a node next to a
    reached one need not be reachable)."""
    nan = np.isnan(values)
    if np.any(nan):
        where = _first_point(grid, band, np.flatnonzero(nan))
        raise FloatingPointError(
            f"the solve produced NaN at {int(np.count_nonzero(nan))} band nodes (the first near {where}): the travel "
            "times left the float64 range in the local updates. Rescale the units of the grid or the speed so that the "
            "travel times lie between about 1e-100 and 1e100"
        )
    if not (reachability and stats.get("converged", False)):
        return
    if user_infinity is not None and not np.any(np.isfinite(values)):
        raise ValueError(
            f"infinity={user_infinity:g} is not above the travel times: even the values the sources fix are above it, "
            "so no node counts as reached. Leave infinity=None (a safe bound derived from the band) or give a value "
            "well above the largest travel time"
        )
    stranded = stranded_nodes(grid, band, values, inner)
    if stranded.size == 0:
        return
    where = _first_point(grid, band, stranded)
    reached = values[np.isfinite(values)]
    top = float(np.max(reached)) if reached.size else 0.0
    if user_infinity is not None:
        raise ValueError(
            f"infinity={user_infinity:g} is not above the travel times: the front stopped where the values met it "
            f"(largest value reached {top:.6g}), leaving {stranded.size} reachable nodes (the first near {where}) at it. "
            "Leave infinity=None (a safe bound derived from the band) or give a value well above the largest travel "
            "time"
        )
    stats["converged"] = False
    warnings.warn(
        f"{stranded.size} reachable band nodes (the first near {where}) were left at the numerical infinity next to "
        f"nodes the front reached: the solve is reported as not converged, and those values are inf",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
