"""``order=2`` near point sources: a second-order solution is ``u = u₀ + w`` with ``u₀`` the
chord distance to the nearest source (docs/second-order.md); :class:`~tubesweep.solution.Solution`
evaluates it here so that the source's cone is not interpolated. Below both ``solution`` and
``second_order`` (which solves and sets ``Solution._factoring``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._interpolation import interpolate_band

#: ``sol(points)`` evaluates ``w + σ|P − x_s|`` (interpolated ``w = u − u₀``) at points within
#: this many grid spacings of a source: the value at a source is exactly 0.
FACTORED_RADIUS = 3.0


def factored_values(sol: Any, p: np.ndarray, values: np.ndarray, interpolation: str = "linear") -> np.ndarray:
    """``sol(points)`` of a second-order solution near a point source: ``w = u − u₀``
    interpolated plus ``σ_s |P − x_s|`` at the points within ``FACTORED_RADIUS`` grid spacings of
    a source, so that the source's cone is not interpolated (the value at a source is exactly 0)."""
    u0, feet, slowness = sol._factoring
    grid = sol.grid
    h = grid.spacing
    if len(p) == 0:
        return values
    dist = np.sqrt(((p[:, None, :] - feet[None, :, :]) ** 2).sum(axis=2))
    near = np.argmin(dist, axis=1)
    nearest = dist[np.arange(len(p)), near]
    close = nearest <= FACTORED_RADIUS * h
    if np.any(close):
        w = interpolate_band(sol._band, sol.values - u0, grid, p[close], interpolation)
        values[close] = w + slowness[near[close]] * nearest[close]
    return values
