"""Which scheme a solve runs (``ts.solve``, ``Tube.solve``): second order where it applies
(``second_order``), otherwise the paper's first-order scheme, with the reason kept for
``order="auto"`` (``_fallback.Fallback``) and raised for ``order=2``."""

from __future__ import annotations

from typing import Any, Callable, Optional, Tuple

from . import second_order as _so
from ._fallback import Fallback
from ._request import SolveRequest
from .moving import refusal_for_order1
from .solution import Solution


def second_order_or_fallback(
    req: SolveRequest, surface: Any, method: str, inner: float, outer: float, run: Callable[[], Solution]
) -> Tuple[Optional[Solution], Optional[Fallback]]:
    """``(run(), None)``, the second-order solution, where second order applies to the request
    and the surface; ``(None, fallback)`` where ``order="auto"`` falls back to the first-order
    scheme (``fallback.reason``: the error ``order=2`` gives); ``(None, None)`` for ``order=1``.
    ``run`` builds the second-order tube and solves on it; its ``Order2NotApplicable`` (a
    geometry the scheme does not resolve, a runaway) is a fallback too. For ``order=2`` every
    refusal is raised."""
    if req.order == 1:
        return None, None
    try:
        if req.source_radius is not None:
            raise _so.OptionOfOrder1(
                "source_radius applies to order=1 (order=2 factors the point source itself); leave it out"
            )
        _so.check_supported(surface, req.general, req.scheme, method, req.source_init, req.paper_sweeps)
        _so.check_widths(inner, outer)
        return run(), None
    except _so.Order2NotApplicable as e:
        if req.order == 2:
            raise
        return None, Fallback.of(e, req.order)


def order2_on(tube: Any, req: SolveRequest, keep_digests: bool = False) -> Solution:
    """The request's second-order solve on a prepared ``tube`` (its geometry kept;
    ``second_order.solve_on_tube``)."""
    return _so.solve_on_tube(
        tube,
        req.sources,
        req.speed,
        req.tol,
        req.max_iterations,
        req.progress,
        req.threads,
        req.started,
        warm=req.warm,
        warm_refused=req.warm_refused,
        keep_digests=keep_digests,
    )


def refuse_warm_for_order1(req: SolveRequest, fallback: Optional[Fallback]) -> None:
    """A warm start (``warm=``) cannot start the first-order scheme: refused (``WarmStartRefused``,
    saying why second order did not run) unless ``warm_refused="cold"``, which solves cold."""
    if req.warm is not None and req.warm_refused == "raise":
        raise refusal_for_order1(None if fallback is None else fallback.reason)
