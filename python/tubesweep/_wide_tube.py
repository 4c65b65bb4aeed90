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


from ._curvature import SHORTCUT_FACTOR, typical_curvature
from ._fallback import gradient_range
from ._warn import user_stacklevel

#: The paper's inner tube, in grid spacings (its Sect. 4): no estimate or warning at or below it.
PAPER_INNER = 2.0


#: The warning fires from this estimated share of the distances.
SHORTCUT_WARNING = 0.1


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
