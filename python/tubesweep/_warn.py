"""Warnings attributed to the user's own line: the first caller outside the tubesweep package."""

from __future__ import annotations

import os
import sys
from typing import Any

import numpy as np

_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def user_stacklevel() -> int:
    """The ``stacklevel`` for :func:`warnings.warn` that names the first frame outside tubesweep.

    Call it in the argument list of ``warnings.warn``: level 1 is the function issuing the warning,
    and each enclosing tubesweep frame adds one, so however deep inside the library a warning is
    raised, Python shows the user's line that called into it (and its once-per-location filter
    then counts that line, not a library line).
    """
    frame = sys._getframe(1)
    level = 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE_DIR):
        frame = frame.f_back  # type: ignore[assignment]
        level += 1
    return level


def where_node(grid: Any, node: Any) -> str:
    """A grid node's position, for a message: ``(x, y, z)`` to four digits."""
    return "(" + ", ".join(f"{float(v):.4g}" for v in grid.node_points(np.array([int(node)]))[0]) + ")"


def percent(share: float) -> str:
    """A share as a short percentage: '0.1%', '12%', or '< 0.01%'."""
    if share < 1e-4:
        return "< 0.01%"
    return f"{100 * share:.2g}%" if share < 0.1 else f"{100 * share:.0f}%"
