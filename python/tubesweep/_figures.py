"""pyplot for the reproduction figures (matplotlib is imported lazily: it is an optional
dependency: ``pip install 'tubesweep[plot]'``, or ``pip install '.[plot]'`` in a checkout).
Solutions are drawn by :mod:`tubesweep._plot`."""

from __future__ import annotations

from typing import Any


def _plt() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(
            "pictures need matplotlib: pip install 'tubesweep[plot]', or pip install '.[plot]' in a checkout"
        ) from None
    return plt
