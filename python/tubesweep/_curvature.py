"""The typical curvature of a surface read off its tube: how sharply the surface bends against the
tube's width (the paper's tube cuts across a bend by about its half-width times the angle the
normal turns: ``_wide_tube``, ``_fallback``)."""

from __future__ import annotations

from typing import Any, Tuple

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
    divergence, _ = _divergences(tube)
    if divergence.size == 0:
        return 0.0
    return float(np.median(np.abs(divergence))) / (tube.grid.ndim - 1)


def concave_curvature(tube: Any) -> float:
    """The median, over the band nodes 0.5 to 2 spacings off the surface on its concave side
    (where the unit directions away from the surface converge, div n < 0), of the mean principal
    curvature carried back to the surface: κ = k/(1 + d·k) with k = −div n/(dim − 1) at the
    node's distance d (the sphere of radius R from inside: k = 1/(R − d), κ = 1/R). An open
    surface's rim fans its directions out and a flat part keeps them parallel, so neither reads
    as a bend, as they do in :func:`typical_curvature` (a plane patch 3 spacings across read as a
    sphere 1.4 spacings wide); nodes bent on a scale over :data:`FLAT_SPACINGS` spacings are taken
    for flat. 0 with fewer than :data:`CONCAVE_NODES` concave nodes."""
    divergence, distance = _divergences(tube)
    h = tube.grid.spacing
    k = -divergence / (tube.grid.ndim - 1)
    bent = k * h > 1.0 / FLAT_SPACINGS
    if np.count_nonzero(bent) < CONCAVE_NODES:
        return 0.0
    return float(np.median(k[bent] / (1.0 + distance[bent] * k[bent])))


#: :func:`concave_curvature` reads a surface bent on a scale above this many grid spacings as flat
#: (a share of 0.7·inner/100 of the distances at most: none that a warning states).
FLAT_SPACINGS = 100.0
#: ... and reads no curvature off fewer concave nodes than this.
CONCAVE_NODES = 8


def _divergences(tube: Any) -> Tuple[np.ndarray, np.ndarray]:
    """div n of the unit directions away from the surface at the band nodes 0.5 to 2 spacings
    off it whose forward neighbours are in the band on the same side (directions less than 90°
    apart), and those nodes' distances to the surface."""
    grid, linear = tube.grid, tube.linear
    h = grid.spacing
    direction = tube.direction if tube.direction is not None else tube.geom.direction
    away = np.abs(np.asarray(tube.phi, dtype=float))
    at = np.flatnonzero((away >= 0.5 * h) & (away <= 2.0 * h))
    if at.size == 0:
        return np.zeros(0), np.zeros(0)
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
    return divergence[whole], away[at][whole]
