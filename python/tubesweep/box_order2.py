"""``travel_time(..., order=2)``: the factored eikonal equation in the whole box with the limited
second-order Godunov update (``tubesweep_core::factored_box``; docs/second-order.md)."""

from __future__ import annotations

from typing import Any, Callable, Optional, Tuple, Union

import numpy as np

from . import _native
from ._validate import ACTIVATION_FRACTION
from .grid import Grid

__all__ = ["ORDERS", "ORDER2_TOL", "check_order", "order2_tol", "solve_order2"]

ORDERS = (1, 2, "auto")

#: Default stopping tolerance of ``order=2``: a phase stops when no value changes by more than
#: ``ORDER2_TOL · s̄ · Δx² / L`` in an iteration (``s̄`` the mean slowness, capped at twice its lower
#: quartile where an obstacle pulls it up: ``_validate.tolerance_slowness``; ``L`` the box's longest
#: side): far below the O(Δx²) discretisation error, far above rounding.
ORDER2_TOL = 1e-3


#: Why ``order=2`` does not apply in the box with Lax–Friedrichs, a flow or a Hamiltonian object
#: (the ``ValueError`` of an explicit ``order=2``; ``stats.order_fallback`` with ``order="auto"``).
NOT_GODUNOV = (
    "order=2 uses the Godunov update (of the eikonal equation): pass hamiltonian='godunov' (without flow= or a "
    "Hamiltonian object), or order=1 for Lax–Friedrichs and the anisotropic Hamiltonians"
)


def check_order(order: Any) -> Union[int, str]:
    if isinstance(order, str) and order == "auto":
        return "auto"
    if isinstance(order, (bool, np.bool_)) or not isinstance(order, (int, np.integer)) or int(order) not in (1, 2):
        raise ValueError(
            "order must be 1 (the paper's first-order scheme, the default), 2 (the factored second-order scheme, "
            f"hamiltonian='godunov' only) or 'auto' (2 with the Godunov update, 1 otherwise); got {order!r}"
        )
    return int(order)


def box_length(grid: Grid) -> float:
    return float(np.max(np.asarray(grid.upper) - np.asarray(grid.lower)))


def order2_tol(grid: Grid, slowness: float) -> float:
    """The default tolerance for the slowness scale ``slowness`` (``_validate.tolerance_slowness``)."""
    return ORDER2_TOL * slowness * grid.spacing**2 / box_length(grid)


def solve_order2(
    grid: Grid,
    sources: np.ndarray,
    slowness: Any,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    fixed_nodes: np.ndarray,
    fixed_values: np.ndarray,
    tol: float,
    max_iterations: int,
    progress: Optional[Callable[[int, float, int], None]],
    threads: int,
) -> Tuple[np.ndarray, dict, np.ndarray]:
    """Runs the native two-phase solve; the values (flat, C order), its stats dict and the
    slowness at each source."""
    source_slowness = np.ascontiguousarray(slowness_at(sources), dtype=float)
    slow: Any = (
        float(slowness) if np.ndim(slowness) == 0 else np.ascontiguousarray(np.asarray(slowness, float).reshape(-1))
    )
    values, st = _native.factored_box_solve(
        list(grid.shape),
        [float(x) for x in grid.lower],
        grid.spacing,
        slow,
        np.ascontiguousarray(sources, float),
        source_slowness,
        np.ascontiguousarray(fixed_nodes, dtype=np.int64),
        np.ascontiguousarray(fixed_values, float),
        float(tol),
        int(max_iterations),
        True,
        box_length(grid),
        int(threads),
        progress,
        ACTIVATION_FRACTION * float(tol),
    )
    # u = u₀ + w rounds to just below 0 next to a source (a runaway, far below, is handled by the
    # core): a travel time is never negative
    np.maximum(values, 0.0, out=values)
    return values, st, source_slowness
