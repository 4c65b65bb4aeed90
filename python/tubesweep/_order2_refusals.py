"""Why ``order=2`` does not apply (docs/second-order.md, "What it needs"): the refusals' classes,
the texts the first-order fallback reads in them, and the warning of a fallback that the solve
found only by running. Re-exported by :mod:`tubesweep.second_order`."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ._runaway import runaway_cause
from ._warn import user_stacklevel

__all__ = [
    "NOISY_PHI",
    "NOT_A_DISTANCE",
    "NarrowExtension",
    "OptionOfOrder1",
    "Order2NotApplicable",
    "Order2RanAway",
    "ran_away_message",
    "warn_fallback",
]


class Order2NotApplicable(ValueError):
    """``order=2`` does not apply to this surface, grid or these options (a mesh, a tube most of
    which the grid does not resolve, convex creases or corners of a level set, a Hamiltonian or an
    option of the first-order scheme; a rim, a concave crease or noise only turn it off node by
    node). The message says why and what to do; with
    ``order="auto"`` the solve uses ``order=1`` instead and records the message in
    ``sol.stats.order_fallback``."""


class OptionOfOrder1(Order2NotApplicable):
    """An option the caller chose that only the first-order scheme has (a Hamiltonian, a flow, the
    naive tube, the paper's sweeps, ``source_init="node"``, ``source_radius``, narrow widths):
    ``order="auto"`` runs it without a warning of its errors' size (the caller chose that scheme),
    as it does not for a fallback the surface or the grid caused (:mod:`tubesweep._fallback`)."""


class NarrowExtension(OptionOfOrder1):
    """Widths that leave second order no room (``outer < inner + 2``). Unlike the other options of
    the first-order scheme, ``order="auto"`` warns of it after the solve (``_fallback.Fallback``):
    widths are chosen for the tube, not for the scheme (``inner=3`` with the default ``outer=4`` ran first order, the sphere's antipode 18%
    short at N = 41, against 0.8% with ``outer=5``)."""


class Order2RanAway(Order2NotApplicable):
    """The second-order sweeps ran away (travel times falling below zero) and so did their
    first-order factored restart: the factored update ``u = u₀ + w`` is not causal where the speed
    is far higher than at the sources (a region 70–1000 times faster), and no factored solution
    exists there. It depends on the speed and the sources, not on the band: a :class:`~tubesweep.Tube`
    does not keep it as a refusal. With ``order="auto"`` the solve warns and returns the paper's
    first-order scheme, which is not factored."""


def ran_away_message(iteration: Any, slowness: Any, src_slowness: np.ndarray, surface: Any = None) -> str:
    """:class:`Order2RanAway`'s text: where it ran away, and why (``_runaway.runaway_cause``)."""
    return (
        f"order=2: the second-order sweeps ran away at their iteration {iteration} (travel times fell below zero) and "
        f"the first-order factored restart did too: the factored update is not causal "
        f"{runaway_cause(slowness, src_slowness, surface)}. order=1, the paper's scheme, which is not factored, solves it"
    )


#: The refusal of a tube whose φ is mostly not a signed distance says this
#: (``tubesweep_core::second_order::check_geometry_of``): its cure is in the user's hands.
NOT_A_DISTANCE = "redistance=True) re-distances φ"

#: The refusal of a tube whose φ was found noisy says this (``tubesweep_core::second_order::NOISY_PHI``):
#: the first-order fallback then looks for the creases that the noise hides (``_coarse_creases``).
NOISY_PHI = "reads as noisy at the grid's scale"


def warn_fallback(e: Order2NotApplicable, order: Any) -> bool:
    """With ``order="auto"``, a warning for a fallback to the first-order scheme that the solve
    found only by running (:class:`Order2RanAway`); the other refusals (a mesh, a grid that does
    not resolve the surface, a φ that is not a signed distance, ...) are in
    ``sol.stats.order_fallback``, and in a warning after the solve that sizes the errors when
    they are large or φ is not a distance (:mod:`tubesweep._fallback`).
    Whether the fallback needs no word after the solve: warned here, or an option the caller chose
    (:class:`OptionOfOrder1`)."""
    if order != "auto":
        return False
    if isinstance(e, OptionOfOrder1):
        return True
    if not isinstance(e, Order2RanAway):
        return False  # a φ that is not a distance: said with its errors' size after the solve
    text = f"{e}; the first-order solution is returned"
    warnings.warn(f"{text} (sol.stats.order_fallback keeps this)", RuntimeWarning, stacklevel=user_stacklevel())
    return True
