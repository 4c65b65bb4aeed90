"""The stagnation safeguard of the second-order sweeps, as the user hears of it: when the sweeps
stop converging they accept decreases only from then on (``second_order/stagnation.rs`` and
``sweep/factored_box.rs`` in the core), and the report says how far from settled the values were."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

#: When the stagnation safeguard of the second-order sweeps fires (they stopped converging and
#: accept decreases only from then on), a warning says so if the largest change of the iterations
#: before it was above this many stopping tolerances (``sol.stats.order2["fallback_change"]``):
#: about how far from settled the values were. Below it, the stats alone record it (two solves that
#: differ only in their path differ by up to 20 tolerances: docs/moving-surfaces.md).
FALLBACK_WARNING = 100.0


#: A stall at changes below this many machine epsilons times the largest travel time is the
#: round-off of the values (a ``tol`` below it cannot be met), not a limit cycle of the scheme:
#: the sphere at N = 41 with ``tol=1e-16`` stalls at 1.9e-14, about 100 of them.
ROUND_OFF = 1e4

#: A round-off stall above this share of the median travel time comes from slow regions whose travel
#: times dwarf the others (obstacles): raising ``tol`` to it is not advised.
SLOW_REGION = 1e-6

#: A ``tol`` this many times below the solve's default is the user's own, tighter than the scheme
#: settles to on some surfaces: the warning then names ``tol`` rather than the grid (the six-fold
#: star at N = 1601 with 1e-4 of the default stalls at 130 tolerances, 2.0e-11).
TIGHT_TOL = 10.0


def fallback_message(
    iteration: Any,
    change: Any,
    tol: float,
    values: np.ndarray,
    recorded: str = "sol.stats.order2['fallback_iteration'] and ['fallback_change']",
    default_tol: Optional[float] = None,
) -> Optional[str]:
    """The warning's text for a stagnation fallback at phase-2 ``iteration`` after changes of up
    to ``change`` (None when it did not fire or was small); ``values``: the solve's travel times,
    whose largest finite one sets the round-off; ``recorded``: where the stats keep it;
    ``default_tol``: the solve's default ``tol`` (the advice names ``tol`` when it is
    :data:`TIGHT_TOL` times below it)."""
    if iteration is None or change is None or not change > FALLBACK_WARNING * tol:
        return None
    finite = values[np.isfinite(values)]
    scale = float(np.max(np.abs(finite))) if finite.size else 0.0
    if change <= ROUND_OFF * np.finfo(np.float64).eps * scale:
        typical = float(np.median(np.abs(finite)))
        if change > SLOW_REGION * typical:
            # (an obstacle at speed 1e-20: travel times of 1e19 inside it, 1.5 outside; the advised
            # tol of 1e6 stopped the sweeps early everywhere, 13% off; a helper's review)
            return (
                f"the second-order sweeps' changes stopped falling at {change:.3g} (their iteration {iteration}), the "
                f"round-off of travel times up to {scale:.3g}, which only the slowest regions have (half the travel "
                f"times are below {typical:.3g}): the values there are as settled as float64 allows. A tol that large would stop the sweeps early everywhere: keep it, and filter this "
                "warning if it is expected (an obstacle of a tiny speed)"
            )
        return (
            f"the second-order sweeps' changes stopped falling at {change:.3g} (their iteration {iteration}), the "
            f"round-off of travel times up to {scale:.3g}: tol={tol:g} is below what float64 resolves for them. The "
            f"values are as settled as they can be; a tol of {change:.0e} or more stops there without this warning"
        )
    if default_tol is not None and tol * TIGHT_TOL < default_tol:
        advice = (
            f"tol={tol:g} is {default_tol / tol:.0f} times below the default ({default_tol:.3g}) and tighter than the "
            f"sweeps settle to here: a tol of {change:.0e} or more, or the default, stops before this"
        )
    else:
        advice = "a finer grid or a smoother surface usually avoids it"
    return (
        f"the second-order sweeps stopped converging at their iteration {iteration} (the largest change of the "
        f"iterations before was {change:.3g}, {change / tol:.0f} times tol={tol:g}) and accepted decreases only "
        "from then on: the values may be off the second-order solution by up to about that much. "
        f"{recorded} record it; {advice}"
    )
