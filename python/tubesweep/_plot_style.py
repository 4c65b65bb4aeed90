"""Shared pieces of the pictures of :mod:`tubesweep._plot`: styles, iso-values, colour bars,
per-source colours and checks of the paths drawn."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence

import numpy as np

from ._validate import real_array


#: The colour bar's label by what is shown.
DISTANCE_LABEL = "geodesic distance"
TIME_LABEL = "travel time"

_SOURCE_STYLE = dict(c="r", marker="*", edgecolors="k", linewidths=0.6, gid="sources")
_START_STYLE = dict(marker="o", facecolors="w", edgecolors="r", linewidths=1.4, gid="path starts")
#: Iso-line labels keep this share of the surface's size away from the sources' stars.
LABEL_CLEARANCE = 0.15
#: Contour labels of a travel-time field keep this share of the box's size away from the stars.
FIELD_LABEL_CLEARANCE = 0.08
_LABEL_BOX = dict(boxstyle="round,pad=0.12", fc="w", ec="none", alpha=0.75)


def _need_matplotlib() -> Any:
    try:
        import matplotlib
    except ImportError:
        raise ImportError(
            "plotting needs the optional package 'matplotlib': pip install 'tubesweep[plot]', "
            "or pip install '.[plot]' in a checkout"
        ) from None
    return matplotlib


def _levels(levels: Any, umax: float) -> np.ndarray:
    """The iso-values: ``levels`` values, or that many round values in (0, umax)."""
    from matplotlib.ticker import MaxNLocator

    if np.ndim(levels) == 0:
        if isinstance(levels, np.ndarray):
            levels = levels.item()
        if (
            isinstance(levels, (bool, np.bool_))
            or not isinstance(levels, (int, float, np.integer, np.floating))
            or not (float(levels).is_integer() and 0 <= levels <= 1000)
        ):
            raise ValueError(
                f"levels must be a number of iso-lines (an integer from 0 to 1000) or a sequence of their "
                f"values; got {levels!r}"
            )
        lv = MaxNLocator(int(levels) + 1).tick_values(0.0, umax) if levels > 0 else np.zeros(0)
    else:
        lv = real_array(levels, "levels").reshape(-1)
        if not np.all(np.isfinite(lv)):
            raise ValueError(f"levels must be finite values of the solution; got {levels!r}")
    return lv[(lv > 0) & (lv < umax)]  # type: ignore[index, operator, return-value]


def _label_text(value: float) -> str:
    return f"{value:.3g}"


def _colorbar(fig: Any, mappable: Any, axes: Any, label: str, lv: np.ndarray) -> Any:
    cb = fig.colorbar(mappable, ax=axes, shrink=0.75, label=label)
    for c in lv:  # the iso-values drawn on the bar, so each line's value can be read off
        cb.ax.axhline(c, color="k", lw=0.7)
    return cb


def _check_paths(paths: Optional[Sequence[Any]], ndim: int) -> List[np.ndarray]:
    lines = [real_array(q, f"paths[{i}]") for i, q in enumerate(paths or [])]
    for i, q in enumerate(lines):
        if q.ndim != 2 or q.shape[1] != ndim or len(q) < 1:
            raise ValueError(f"paths[{i}] must be an array of shape (P, {ndim}); got shape {q.shape}")
    return lines


def _label_colors(labels: np.ndarray) -> np.ndarray:
    """One qualitative colour per source (tab10, repeating), grey where no front arrives."""
    import matplotlib

    tab = matplotlib.colormaps["tab10"]
    rgba = np.array([tab(int(k) % 10) for k in np.maximum(labels, 0)], dtype=float).reshape(-1, 4)
    rgba[labels < 0] = (0.7, 0.7, 0.7, 1.0)
    return rgba


def _source_legend(fig: Any, axes: Any, n: int) -> None:
    from matplotlib.patches import Patch

    handles = [Patch(color=_label_colors(np.array([k]))[0], label=f"nearest to source {k}") for k in range(n)]
    fig.legend(handles=handles, loc="lower center", ncol=min(n, 4), fontsize=8, frameon=False)
