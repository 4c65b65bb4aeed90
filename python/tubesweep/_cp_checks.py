"""Checks that a user's closest-point function is one (paper Sect. 5.2 needs ``cp(x)``, the point of
Σ nearest to ``x``), and how noisy it is.

A callable that is not a closest-point map gives a band and directions that mean nothing, and
the solve a wrong answer with no warning: the identity (every point its own closest point: the
band fills the box and the solve returns Euclidean distances), a map that returns points away
from the surface (``x + c``: the band is empty or shifted), or one that returns points on the
surface that are not the nearest. Three tests, on a few thousand points (O(1) extra calls):

* before the band search, on a seeded random sample of the box: the identity (``cp(x) = x`` at
  more than :data:`IDENTITY_FRACTION` of the sample) and idempotence (``cp(cp(x)) = cp(x)``: a
  closest point lies on the surface, so it is its own closest point; refused when the median of
  ``|cp(cp(x)) − cp(x)| / max(|x − cp(x)|, h)`` exceeds :data:`FAR_RATIO`);
* on a sample of the band's nodes: idempotence to a fraction of a grid spacing
  (:data:`BAND_IDEMPOTENCE`), and the nearest-point property against the other sampled closest
  points (``|x − cp(x)| ≤ |x − cp(y)|`` up to the map's noise).

The noise of the map near the surface (the 90th percentile of ``|cp(cp(x)) − cp(x)|`` at the band's
sample) is returned: nodes closer to the surface than a few times it have unreliable directions,
and the facing-sheets test leaves them out (``_facing._warn_if_tubes_touch``) instead of reading a
noisy map as a surface that faces itself across gaps.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._linalg import row_norms
from .grid import Grid

#: Points of the box sampled before the band search, and of the band after it.
BOX_SAMPLE = 512
BAND_SAMPLE = 2048
#: ``cp(x)`` within :data:`IDENTITY_DISTANCE` spacings of ``x`` at more than this fraction of the
#: box's random sample: (nearly) the identity. A surface passes that close to a random point of
#: the box with a small probability (0.3% for the sphere of radius 0.5 in [−1, 1]³ at h = 1/15),
#: the identity (or ``x`` plus a small shift) always.
IDENTITY_FRACTION = 0.5
IDENTITY_DISTANCE = 0.05
#: The median of ``|cp(cp(x)) − cp(x)| / max(|x − cp(x)|, h)`` over the box's sample above which
#: the map does not return points of a surface (``x + c`` gives 1; an exact map 0; a map only
#: reliable near the surface, whose far points land near but not on it, well below).
FAR_RATIO = 0.5
#: The median of ``|cp(cp(x)) − cp(x)|`` at the band's sample, in grid spacings, above which the
#: map is not a closest-point map near the surface (it must be accurate well below a spacing).
BAND_IDEMPOTENCE = 0.25
#: The share of the band's sample whose closest point is farther than another sampled closest
#: point (by more than half a spacing plus the noise) above which the map is refused.
NOT_NEAREST_FRACTION = 0.05

Evaluate = Callable[[np.ndarray], np.ndarray]


def check_box_sample(evaluate: Evaluate, grid: Grid) -> None:
    """The identity and idempotence tests on a random sample of the box (``evaluate(points)``:
    the map, NaN allowed where it is undefined)."""
    rng = np.random.default_rng(20161)
    lo, hi = np.asarray(grid.lower, float), np.asarray(grid.upper, float)
    x = lo + rng.random((BOX_SAMPLE, grid.ndim)) * (hi - lo)
    c = evaluate(x)
    ok = np.all(np.isfinite(c), axis=1)
    if not np.any(ok):
        raise ValueError(
            f"cp returned NaN or inf at every point of a random sample of the grid's box (e.g. at "
            f"{tuple(round(float(v), 6) for v in x[0])}); it must be finite near the surface"
        )
    if np.count_nonzero(ok) < 16:
        return  # undefined almost everywhere in the box: the band search decides
    x, c = x[ok], c[ok]
    h = grid.spacing
    d = row_norms(x - c)
    identity = float(np.mean(d <= IDENTITY_DISTANCE * h))
    if identity > IDENTITY_FRACTION:
        raise ValueError(
            f"cp is not a closest-point map: it returns its argument (or a point within {IDENTITY_DISTANCE:g} grid spacings "
            f"of it) at {identity:.0%} of a random sample of the grid's "
            "box (a closest-point map returns, for a point off the surface, the nearest point ON the surface; the "
            "identity would make the whole box the band and the result Euclidean distances)"
        )
    c2 = evaluate(c)
    ok2 = np.all(np.isfinite(c2), axis=1)
    if np.count_nonzero(ok2) < 16:
        return
    ratio = row_norms(c2[ok2] - c[ok2]) / np.maximum(d[ok2], h)
    if float(np.median(ratio)) > FAR_RATIO:
        raise ValueError(
            f"cp is not a closest-point map: cp(cp(x)) differs from cp(x) by a median {float(np.median(ratio)):.2g} × "
            "|x − cp(x)| over a random sample of the box, so the points it returns do not lie on a surface (a closest "
            "point lies on the surface and is its own closest point). Check that cp returns points of the surface, in "
            "the grid's coordinates"
        )


def check_band_sample(evaluate: Evaluate, x: np.ndarray, c: np.ndarray, grid: Grid) -> float:
    """The idempotence and nearest-point tests at band nodes ``x`` with closest points ``c``
    (a sample of at most :data:`BAND_SAMPLE`); returns the map's noise near the surface (in the
    grid's units, 0 for an exact map)."""
    if len(x) == 0:
        return 0.0
    h = grid.spacing
    if len(x) > BAND_SAMPLE:
        pick = np.linspace(0, len(x) - 1, BAND_SAMPLE).astype(np.int64)
        x, c = x[pick], c[pick]
    c2 = evaluate(c)
    ok = np.all(np.isfinite(c2), axis=1)
    if not np.any(ok):
        return 0.0
    r = row_norms(c2[ok] - c[ok])
    median = float(np.median(r))
    if median > BAND_IDEMPOTENCE * h:
        raise ValueError(
            f"cp is not a closest-point map near the surface: cp(cp(x)) differs from cp(x) by a median of "
            f"{median / h:.3g} grid spacings at the band's nodes (a closest point is its own closest point; the map "
            f"must be accurate well below a grid spacing, h = {h:.4g}, within the tube)"
        )
    noise = float(np.quantile(r, 0.9))
    d = row_norms(x - c)
    slack = 0.5 * h + 4.0 * noise
    worse = np.zeros(len(x), bool)
    for s in range(0, len(x), 256):
        xs = x[s : s + 256]
        dist = np.sqrt(((xs[:, None, :] - c[None, :, :]) ** 2).sum(axis=2))
        worse[s : s + 256] = d[s : s + 256] > dist.min(axis=1) + slack
    share = float(np.mean(worse))
    if share > NOT_NEAREST_FRACTION:
        raise ValueError(
            f"cp is not a closest-point map: at {share:.0%} of a sample of the band's nodes another point it returned "
            "is nearer to the node than the node's own cp(x), by more than half a grid spacing. cp must return the "
            "NEAREST point of the surface"
        )
    return noise
