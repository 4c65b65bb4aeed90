"""Triangulations for display: parameter grids with seams and poles merged, and marching cubes."""

from __future__ import annotations

from typing import Any, Callable, Tuple

import numpy as np

__all__ = ["grid_mesh", "polyline", "marching_cubes"]


def grid_mesh(points: np.ndarray, merge_tol: float = 1e-9) -> Tuple[np.ndarray, np.ndarray]:
    """Triangulates a parametrised patch sampled on a (nu, nv, 3) grid of points.

    Parameter seams (a periodic angle sampled at both ends), poles (a whole row mapping to one
    point) and twisted identifications (the Möbius band, where (2π, s) is (0, −s)) are all handled
    the same way: vertices closer than ``merge_tol`` are merged and degenerate triangles dropped.

    Returns ``(V (n, 3) float, F (m, 3) int64)``.
    """
    nu, nv, _ = points.shape
    V = points.reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu - 1), np.arange(nv - 1), indexing="ij")
    a = (i * nv + j).ravel()
    b = ((i + 1) * nv + j).ravel()
    c = ((i + 1) * nv + j + 1).ravel()
    d = (i * nv + j + 1).ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    scale = max(float(np.max(np.abs(V))), 1.0)
    key = np.round(V / (merge_tol * scale)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    V = V[first]
    F = inverse[F]
    ok = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])
    return V, F[ok].astype(np.int64)


def polyline(points: np.ndarray, closed: bool = True) -> Tuple[np.ndarray, np.ndarray]:
    """A curve as vertices (n, 2) and segments (m, 2) — the 2D analogue of a triangulation."""
    n = len(points)
    idx = np.arange(n)
    seg = np.stack([idx, np.roll(idx, -1)], 1) if closed else np.stack([idx[:-1], idx[1:]], 1)
    return np.asarray(points, dtype=float), seg.astype(np.int64)


def marching_cubes(
    phi: Callable[[np.ndarray], np.ndarray], box: Tuple[Any, Any], n: int
) -> Tuple[np.ndarray, np.ndarray]:
    """Zero level set of a vectorised φ over ``box`` on an n³ grid (scikit-image marching cubes)."""
    try:
        from skimage.measure import marching_cubes as _mc
    except ImportError as exc:  # pragma: no cover - optional dependency
        raise ImportError(
            "triangulating an implicit surface needs scikit-image: pip install 'tubesweep[mesh]', "
            "or pip install '.[mesh]' in a checkout"
        ) from exc
    lo = np.asarray(box[0], dtype=float)
    hi = np.asarray(box[1], dtype=float)
    axes = [np.linspace(lo[k], hi[k], n) for k in range(3)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    vol = np.asarray(phi(X), dtype=float).reshape(n, n, n)
    spacing = tuple((hi - lo) / (n - 1))
    V, F, _, _ = _mc(vol, level=0.0, spacing=spacing)
    return V + lo, F.astype(np.int64)
