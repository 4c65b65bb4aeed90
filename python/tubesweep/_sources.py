"""Point sources on the surface: the exact local initialisation of the inner-tube nodes near each
source (docs/source-initialisation.md)."""

from __future__ import annotations

from typing import Any, Callable, Tuple

import numpy as np

from .grid import Grid
from .surface import Surface
from ._prepare import ROLE_INNER

#: With ``source_init="exact"``, inner-tube nodes whose closest point lies within this many grid
#: spacings of a source are fixed to the exact local distance ``|cp(x) − x_s|`` times the mean
#: slowness.
SOURCE_RADIUS = 2.0


def _fix_sources(
    surface: Surface,
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    sources: np.ndarray,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    source_init: str,
    inner_width: float,
    radius: float = SOURCE_RADIUS,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions in the band and values of the nodes fixed by the point sources, and the index of
    the source each node's value comes from (the nearest, where several sources fix one node).
    ``radius``: the exact initialisation's reach in grid spacings."""
    h = grid.spacing
    d = grid.ndim
    dist, proj = surface.project(sources, grid)
    for i, (dd, s) in enumerate(zip(dist, sources)):
        if dd > inner_width * (1 + 1e-6):
            raise ValueError(
                f"sources[{i}] = {tuple(float(x) for x in s)} is {dd:.4g} from the surface, farther than the inner tube "
                f"(inner·Δx = {inner_width:.4g}); put the source on the surface or increase `inner`"
            )
    best: dict = {}
    r = int(np.ceil(radius + inner_width / h)) + 1
    offsets = np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * d), indexing="ij"), axis=-1).reshape(-1, d)
    for i, (s, sp) in enumerate(zip(sources, proj)):
        if source_init == "node":
            idx = grid.nearest_index(s[None])
            pos = int(band.find(idx)[0])
            if pos < 0 or roles[pos] != ROLE_INNER:
                raise ValueError(
                    f"sources[{i}]: the grid node nearest to the source is not in the inner tube; "
                    "move the source onto the surface, refine the grid or increase `inner`"
                )
            if pos not in best or best[pos][0] > 0.0:
                best[pos] = (0.0, i)
            continue
        idx = np.floor(grid.continuous_index(s[None])[0]).astype(np.int64) + offsets
        pos = band.find(np.ascontiguousarray(idx))
        ok = pos >= 0
        pos = pos[ok]
        pos = pos[roles[pos] == ROLE_INNER]
        if pos.size == 0:
            raise ValueError(f"sources[{i}] has no inner-tube node near it; refine the grid or increase `inner`")
        x = grid.points(grid.unravel(linear[pos]))
        _, cp = surface.project(x, grid)
        geo = np.linalg.norm(cp - sp, axis=1)
        near = geo <= radius * h
        if not np.any(near):
            near = geo <= geo.min()
        slow = 0.5 * (slowness_at(cp[near]) + slowness_at(sp[None])[0])
        for p, v in zip(pos[near], geo[near] * slow):
            if p not in best or v < best[p][0]:
                best[p] = (v, i)
    positions = np.fromiter(best.keys(), dtype=np.int64, count=len(best))
    values = np.fromiter((v for v, _ in best.values()), dtype=float, count=len(best))
    labels = np.fromiter((k for _, k in best.values()), dtype=np.int64, count=len(best))
    return positions, values, labels
