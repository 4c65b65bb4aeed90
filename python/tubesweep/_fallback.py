"""``order="auto"``'s fallback to the first-order scheme (:class:`Fallback`): why, kept in
``sol.stats.order_fallback``, and how large its errors are, said in a warning.

Where the surface or the grid rules out the second-order scheme (a grid that does not resolve
the surface, a mesh given as it is), ``order="auto"`` runs the paper's first-order scheme. On a
curved closed surface its errors are a share of about Δx·κ of the distances (κ the surface's
curvature: the error grows with the turning of the geodesics), and a few grid spacings where
fronts meet: 3.2Δx at the antipode of the sphere of radius 0.5 at N = 12–81 (Δx·κ = 0.2 at
N = 20, and the antipode is 22% short), 2.5–3.1Δx at the circle's at N = 12–61, up to 2–4.3Δx on
the torus (0.6, 0.25) at N = 16–31 (11–19% of its distances at N = 21–31, where the warning
says 10–16%), 0.6–2.4Δx on the ellipsoid (0.8, 0.5, 0.3) at N = 16–41 (2–4.5%, where it says
11–20%: its geodesics turn less than its curvature), against second-order solves at N = 201.
The warning takes the smaller of the two estimates (:func:`first_order_share`), so that a flat
part does not warn for the spacings alone (``tests/test_fallback.py``; the table:
``benches/experiments/fallback_size.py``).

Not warned about: an option the caller chose that only the first-order scheme has
(``second_order.OptionOfOrder1``: the caller chose that scheme), and open surfaces, whose
distance near the rim curves whatever the surface does (a flat disc one spacing across would
read as a curvature of 10).
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any, Tuple

import numpy as np

from ._creases import warn_refused_creases
from ._warn import user_stacklevel
from .second_order import Order2NotApplicable, warn_fallback

#: The first-order scheme's error where fronts meet, in grid spacings (the sphere's antipode:
#: 3.2Δx at every N from 12 to 81).
FIRST_ORDER_SPACINGS = 3.0

#: The warning fires when the estimated error is at least this share of the distances (the
#: sphere of radius 0.5 at N = 41, 3.2Δx short at its antipode, is just below: 9.9%).
SIZE_WARNING = 0.1


def mean_curvature(tube: Any) -> float:
    """The mean of ``|Δφ| / (d − 1)`` over the band nodes 1–2 spacings off the surface whose
    2d neighbours are in the band: the surface's mean curvature magnitude seen by the tube (a
    distance's Laplacian is the sum of its level set's principal curvatures), 0 without such
    nodes. ``tube``: a prepared tube (``_prepare._PreparedTube``), whose ``phi`` is the signed or
    unsigned distance at its band nodes."""
    grid, linear = tube.grid, tube.linear
    h, d = grid.spacing, grid.ndim
    phi = np.asarray(tube.phi, dtype=float)
    away = np.abs(phi)
    at = np.flatnonzero((away >= h * (1 - 1e-6)) & (away <= 2 * h))
    if d < 2 or at.size == 0:
        return 0.0
    nodes = grid.unravel(linear[at])
    strides = [int(np.prod(grid.shape[k + 1 :])) for k in range(d)]
    laplacian = -2 * d * phi[at]
    whole = np.ones(at.size, dtype=bool)
    for k, stride in enumerate(strides):
        for step in (1, -1):
            target = linear[at] + step * stride
            j = np.minimum(np.searchsorted(linear, target), len(linear) - 1)
            found = (nodes[:, k] + step >= 0) & (nodes[:, k] + step < grid.shape[k]) & (linear[j] == target)
            whole &= found
            laplacian += np.where(found, phi[j], 0.0)
    if not whole.any():
        return 0.0
    return float(np.mean(np.abs(laplacian[whole]))) / (h * h * (d - 1))


def first_order_share(values: Any, spacing: float, curvature: float) -> Tuple[float, float]:
    """The first-order scheme's error as a share of the distances, the smaller of
    :data:`FIRST_ORDER_SPACINGS` grid spacings against the largest finite value of ``values``
    and ``spacing·curvature``; and that largest value (0, 0 when none is positive)."""
    v = np.asarray(values, dtype=float)
    finite = v[np.isfinite(v)]
    largest = float(finite.max()) if finite.size else 0.0
    if largest <= 0:
        return 0.0, 0.0
    return min(FIRST_ORDER_SPACINGS * float(spacing) / largest, float(spacing) * float(curvature)), largest


def warn_first_order(reason: str, values: Any, tube: Any, kappa: float, *, said: bool) -> None:
    """After ``order="auto"`` ran the first-order scheme on ``tube`` for ``reason``: the crease
    warning when creases caused it, else a RuntimeWarning when its errors are a large share of
    the distances (:data:`SIZE_WARNING`; ``kappa`` from :meth:`Fallback.measure`). Nothing when
    ``said`` (the fallback was warned about already, a runaway or a φ that is not a distance, or
    the caller chose an option of the first-order scheme: ``second_order.warn_fallback``), nor on
    an open surface (``kappa`` 0)."""
    spacing = tube.grid.spacing
    if said or warn_refused_creases(reason, tube.inner, spacing):
        return
    share, largest = first_order_share(values, spacing, kappa)
    if share < SIZE_WARNING:
        return
    size = f"up to about {100 * share:.0f}% of the distances" if share < 1 else "as large as the distances"
    warnings.warn(
        f"order='auto' ran the paper's first-order scheme, whose errors are about Δx·κ of each distance on a surface "
        f"of curvature κ and {FIRST_ORDER_SPACINGS:g}·Δx where fronts meet: here Δx = {spacing:.3g}, κ about "
        f"{kappa:.3g} and distances up to {largest:.3g}, so errors {size}. A finer grid lowers them in proportion (why "
        f"order 2 did not apply, kept in sol.stats.order_fallback: {reason})",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


@dataclasses.dataclass
class Fallback:
    """``order="auto"`` running the first-order scheme: ``reason``, the refusal's text (kept in
    ``sol.stats.order_fallback``); ``said``, whether nothing more is to be said after the solve
    (warned already, or an option the caller chose: ``second_order.warn_fallback``); ``kappa``,
    the tube's :func:`mean_curvature` for the size warning (:meth:`measure`)."""

    reason: str
    said: bool
    kappa: float = 0.0

    @classmethod
    def of(cls, refusal: Order2NotApplicable, order: Any) -> "Fallback":
        """The fallback for ``refusal``, warned about now when the refusal's kind asks for it."""
        return cls(str(refusal), warn_fallback(refusal, order))

    def measure(self, tube: Any) -> None:
        """Reads the curvature that :meth:`warn` needs from ``tube`` before the solve, which
        drops the band's linear indices (none when nothing is to be said, or on an open surface)."""
        surface = tube.surface
        if self.said or getattr(surface, "open_surface", False) or getattr(surface, "closed", True) is False:
            return
        self.kappa = mean_curvature(tube)

    def warn(self, values: Any, tube: Any) -> None:
        """After the solve on ``tube``: the crease or size warning for its ``values``
        (:func:`warn_first_order`)."""
        warn_first_order(self.reason, values, tube, self.kappa, said=self.said)
