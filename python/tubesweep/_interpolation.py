"""Point evaluation of grid values: multilinear (the default) or cubic (Catmull–Rom), in a band
(:class:`~tubesweep.Solution`) or on the whole grid (:class:`~tubesweep.BoxSolution`)."""

from __future__ import annotations

from typing import Any, Callable, Optional, Tuple

import numpy as np

from . import _native
from .grid import Grid

INTERPOLATIONS = ("linear", "cubic")


def check_interpolation(interpolation: Any) -> str:
    if not (isinstance(interpolation, str) and interpolation in INTERPOLATIONS):
        raise ValueError(
            f"interpolation must be 'linear' (multilinear, the default) or 'cubic' (Catmull–Rom where "
            f"the 4^d stencil is available, multilinear elsewhere); got {interpolation!r}"
        )
    return interpolation


def interpolate_band(band: Any, values: np.ndarray, grid: Grid, points: np.ndarray, interpolation: str) -> np.ndarray:
    """``values`` (one per band node) at ``points`` (M, d): multilinear, NaN where the cell's corners
    leave the band; or cubic where the 4^d stencil is in the band and reached, multilinear elsewhere."""
    if check_interpolation(interpolation) == "linear":
        return band.interpolate(values, list(grid.lower), grid.spacing, points)
    out, _ = _native.band_interpolate_cubic(band, values, list(grid.lower), grid.spacing, points)
    return out


def cell_corners(grid: Grid, band: Any, points: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 2^d corners of each point's cell as the core's multilinear interpolation takes them
    (``tubesweep_core::solution::interpolate``): their grid indices ``(M, 2^d, d)``, band
    positions ``(M, 2^d)`` (−1 off the band) and weights ``(M, 2^d)``."""
    d = grid.ndim
    t = grid.continuous_index(np.asarray(points, dtype=float).reshape(-1, d))
    # (a point on a grid plane to rounding is on it, as in the core)
    t = np.where(np.abs(t - np.round(t)) <= 1e-9, np.round(t), t)
    base = np.clip(np.floor(t).astype(np.int64), 0, np.asarray(grid.shape) - 2)
    frac = np.clip(t - base, 0.0, 1.0)
    offsets = np.array([[(c >> k) & 1 for k in range(d)] for c in range(1 << d)], dtype=np.int64)
    corners = base[:, None, :] + offsets[None, :, :]
    pos = band.find(np.ascontiguousarray(corners.reshape(-1, d))).reshape(len(t), 1 << d)
    weight = np.prod(np.where(offsets[None, :, :] == 1, frac[:, None, :], 1.0 - frac[:, None, :]), axis=2)
    return corners, pos, weight


def catmull_rom_weights(f: np.ndarray) -> np.ndarray:
    """Weights (..., 4) of the nodes at offsets −1, 0, 1, 2 for fractions ``f`` of the cell."""
    f2 = f * f
    f3 = f2 * f
    return 0.5 * np.stack([-f3 + 2 * f2 - f, 3 * f3 - 5 * f2 + 2, -3 * f3 + 4 * f2 + f, f3 - f2], axis=-1)


def interpolate_dense(
    values: np.ndarray,
    grid: Grid,
    points: np.ndarray,
    interpolation: str,
    transform: Optional[Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]] = None,
    chunk: int = 1 << 14,
) -> np.ndarray:
    """``values`` (an array of ``grid.shape``) at ``points`` (M, d); NaN outside the grid.

    ``transform(rows, node_points, node_values)`` may replace the stencil's values before they are
    weighted (e.g. subtract a factor), ``rows`` the points' positions in ``points``; the
    interpolated result is returned as is (the caller adds the factor back at the points). Cubic
    where the 4^d stencil lies in the grid, multilinear elsewhere."""
    check_interpolation(interpolation)
    d = grid.ndim
    shape = np.asarray(grid.shape)
    flat = values.reshape(-1)
    out = np.full(len(points), np.nan)
    for lo in range(0, len(points), chunk):
        p = points[lo : lo + chunk]
        rows = np.arange(lo, lo + len(p))
        t = grid.continuous_index(p)
        inside = np.all((t >= -1e-9) & (t <= shape - 1 + 1e-9), axis=1)
        base = np.clip(np.floor(t), 0, shape - 2).astype(np.int64)
        frac = np.clip(t - base, 0.0, 1.0)
        cubic = (
            inside & np.all((base >= 1) & (base <= shape - 3), axis=1)
            if interpolation == "cubic"
            else np.zeros(len(p), bool)
        )
        for mask, offsets, weights in (
            (inside & ~cubic, np.arange(2), lambda f: np.stack([1 - f, f], axis=-1)),
            (cubic, np.arange(-1, 3), catmull_rom_weights),
        ):
            if not np.any(mask):
                continue
            b, fr = base[mask], frac[mask]
            w1 = weights(fr)  # (m, d, n)
            n = len(offsets)
            grids = np.meshgrid(*([np.arange(n)] * d), indexing="ij")
            combos = np.stack([g.reshape(-1) for g in grids], axis=1)  # (n^d, d)
            idx = b[:, None, :] + offsets[combos][None, :, :]  # (m, n^d, d)
            w = np.ones((len(b), len(combos)))
            for k in range(d):
                w *= w1[:, k, :][:, combos[:, k]]
            lin = np.ravel_multi_index(tuple(np.moveaxis(idx, -1, 0)), grid.shape)
            v = flat[lin]
            if transform is not None:
                v = transform(rows[mask], np.asarray(grid.lower) + grid.spacing * idx, v)
            out[lo + np.flatnonzero(mask)] = np.sum(w * v, axis=1)
    return out
