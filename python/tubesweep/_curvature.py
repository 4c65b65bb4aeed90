"""The typical curvature of a surface read off its tube: how sharply the surface bends against the
tube's width (the paper's tube cuts across a bend by about its half-width times the angle the
normal turns: ``_wide_tube``, ``_fallback``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .band import band_neighbours

#: The largest share by which the paper's tube shortens distances, per unit of w·κ (the tube's
#: half-width times the surface's typical principal curvature): the sphere's 0.59–0.71 for inner
#: 3–8 (``benches/experiments/wide_tube.py``).
SHORTCUT_FACTOR = 0.7


def typical_curvature(tube: Any) -> float:
    """The median over the band nodes 0.5 to 2 spacings off the surface of the mean of the
    principal curvatures' magnitudes, read as |div n|/(d − 1) of the unit directions away from the
    surface (forward differences, the node and its neighbours on one side of the surface): 2 on
    the sphere of radius 0.5, robust to a rim's fan of directions or a mesh's edges; 0 without
    such nodes."""
    grid, linear = tube.grid, tube.linear
    h = grid.spacing
    direction = tube.direction if tube.direction is not None else tube.geom.direction
    away = np.abs(np.asarray(tube.phi, dtype=float))
    at = np.flatnonzero((away >= 0.5 * h) & (away <= 2.0 * h))
    if at.size == 0:
        return 0.0
    n_at = np.asarray(direction[at], dtype=float)
    divergence = np.zeros(at.size)
    whole = np.ones(at.size, dtype=bool)
    for i, (_, _, pos) in enumerate(band_neighbours(grid, tube.band, linear, at)):
        if i % 2:  # forward differences: the + side of each axis
            continue
        k = i // 2
        ok = pos >= 0
        n_next = np.zeros_like(n_at)
        n_next[ok] = direction[pos[ok]]
        whole &= ok & (np.einsum("ij,ij->i", n_at, n_next) > 0)
        divergence += (n_next[:, k] - n_at[:, k]) / h
    if not np.any(whole):
        return 0.0
    return float(np.median(np.abs(divergence[whole]))) / (grid.ndim - 1)
