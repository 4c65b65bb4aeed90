"""Warnings attributed to the user's own line: the first caller outside the tubesweep package."""

from __future__ import annotations

import os
import sys

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
