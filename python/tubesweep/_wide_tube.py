"""The paper's tube made wider than its two grid spacings at first order (``order=1``, or an
option only the first-order scheme has, with ``inner`` above 2): how much shorter the distances
come out, kept in ``sol.stats.tube_shortcut`` and warned of when large.

The paper's scheme solves |∇u| = 1/F at every inner-tube node (Eq. (3)): the Euclidean eikonal
equation in a shell of half-width w = inner·Δx about the surface. A path that bends with the
surface cuts through that shell on the inside of the bend, so the distances come out short by
about w times the angle the normal turns along the path: on the sphere of radius 0.5, whose
normal turns by π between a source and its antipode, the largest error is about
(2.4·inner − 2)·Δx at N = 61 and 81, for the radius 0.3 as for 0.5, that is 0.59–0.71 of w·κ of
the largest distance for inner from 3 to 8 (27 % short at inner = 8, N = 81; 4 % at the default 2).
The second-order scheme's metric correction (docs/second-order.md) removes this whatever the
tube's width. ``benches/experiments/wide_tube.py`` prints the errors against the estimate;
``tests/test_wide_tube.py``.
"""

from __future__ import annotations

import warnings
from typing import Any, Optional

import numpy as np

from ._fallback import gradient_range
from ._warn import user_stacklevel
from .band import band_neighbours

#: The paper's inner tube, in grid spacings (its Sect. 4): no estimate or warning at or below it.
PAPER_INNER = 2.0

#: The largest share by which distances come out short, per unit of w·κ (the tube's half-width
#: times the surface's typical principal curvature): the sphere's 0.59–0.71 for inner 3–8.
SHORTCUT_FACTOR = 0.7

#: The warning fires from this estimated share of the distances.
SHORTCUT_WARNING = 0.1


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


def tube_shortcut(tube: Any) -> Optional[float]:
    """The estimated largest share by which the first-order scheme's distances come out short on
    ``tube`` (a prepared tube, before its sweeps), :data:`SHORTCUT_FACTOR`·w·κ with w the inner
    tube's half-width in length (inner·Δx over the mean |∇φ|) and κ :func:`typical_curvature`;
    None where the inner tube is the paper's or thinner."""
    if tube.inner <= PAPER_INNER + 1e-9:
        return None
    gradient = gradient_range(tube)[0]
    width = tube.inner * tube.grid.spacing / gradient
    return SHORTCUT_FACTOR * width * typical_curvature(tube)


def warn_wide_tube(share: Optional[float], inner: float, spacing: float) -> None:
    """Warns where :func:`tube_shortcut`'s ``share`` reaches :data:`SHORTCUT_WARNING`."""
    if share is None or share < SHORTCUT_WARNING:
        return
    warnings.warn(
        f"inner={inner:g}: the first-order scheme solves the eikonal equation across an inner tube "
        f"{inner:g} grid spacings ({inner * spacing:.3g}) to each side of the surface, and a path that bends with "
        f"the surface cuts through it on the inside of the bend: distances come out up to about {share:.0%} short "
        'here (sol.stats.tube_shortcut). Keep the paper\'s inner=2, or use order=2 (or the default "auto"), '
        "whose metric correction removes this at any width",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
