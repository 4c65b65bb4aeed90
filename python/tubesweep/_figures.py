"""Matplotlib pictures for the command line and the demo (matplotlib is imported lazily: it is
an optional dependency, ``pip install tubesweep[plot]``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import numpy as np


def _plt() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("pictures need matplotlib: pip install 'tubesweep[plot]'") from None
    return plt


def solution_png(sol: Any, path: Path, title: str = "", levels: int = 16) -> Path:
    """A picture of a surface solution: 2D — the band coloured by u with iso-lines and the
    curve; 3D — the surface points coloured by u, seen from two sides."""
    plt = _plt()
    grid = sol.grid
    if grid.ndim == 2:
        fig, ax = plt.subplots(figsize=(6, 5.4))
        dense = sol.to_dense()
        X, Y = grid.meshgrid()
        finite = np.where(np.isfinite(dense), dense, np.nan)
        m = ax.pcolormesh(X, Y, finite, shading="auto", cmap="viridis")
        fig.colorbar(m, ax=ax, label="u")
        phi = np.full(grid.size, np.nan)
        phi[sol.linear] = sol.phi
        ax.contour(X, Y, phi.reshape(grid.shape), levels=[0.0], colors="w", linewidths=0.8)
        if np.any(np.isfinite(finite)):
            ax.contour(X, Y, finite, levels=levels, colors="k", linewidths=0.4)
        ax.plot(sol.sources[:, 0], sol.sources[:, 1], "r*", ms=12)
        ax.set_aspect("equal")
        lo, hi = sol.points.min(0), sol.points.max(0)
        pad = 0.05 * (hi - lo).max()
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    else:
        on = np.abs(sol.phi) <= 0.5 * grid.spacing
        pts = sol.points[on]
        vals = sol.values[on]
        fig = plt.figure(figsize=(10, 4.8))
        for i, (elev, azim) in enumerate(((20, -60), (20, 120))):
            ax = fig.add_subplot(1, 2, i + 1, projection="3d")
            sc = ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], c=vals, s=2, cmap="viridis", depthshade=False)
            ax.scatter(*sol.sources.T, c="r", marker="*", s=120)
            ax.view_init(elev, azim)
            ax.set_box_aspect((1, 1, 1))
            ax.set_xlabel("x"), ax.set_ylabel("y"), ax.set_zlabel("z")
        fig.colorbar(sc, ax=fig.axes, shrink=0.7, label="u")
    if title:
        fig.suptitle(title)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def field_png(
    grid: Any, u: np.ndarray, path: Path, sources: np.ndarray, title: str = "", speed: Optional[np.ndarray] = None
) -> Path:
    """A 2D travel-time field (or the middle slice of a 3D one) with iso-lines."""
    plt = _plt()
    if grid.ndim == 3:
        k = grid.shape[2] // 2
        u = u[:, :, k]
        speed = speed[:, :, k] if speed is not None else None
    x, y = grid.axis(0), grid.axis(1)
    fig, ax = plt.subplots(figsize=(6, 5.4))
    back = speed if speed is not None else u
    m = ax.pcolormesh(x, y, back.T, shading="auto", cmap="cividis" if speed is not None else "viridis")
    fig.colorbar(m, ax=ax, label="speed F" if speed is not None else "u")
    ax.contour(x, y, u.T, levels=20, colors="w" if speed is not None else "k", linewidths=0.6)
    ax.plot(sources[:, 0], sources[:, 1], "r*", ms=12)
    ax.set_aspect("equal")
    if title:
        ax.set_title(title)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path
