"""Small dense helpers for the set-up's hot paths."""

from __future__ import annotations

import numpy as np


def row_norms(v: np.ndarray) -> np.ndarray:
    """The Euclidean norm of each row of ``v`` (M, d): the same bits as
    ``np.linalg.norm(v, axis=1)`` (which sums the squares along the row in order), 3–4× faster for
    the few columns of points in 2D and 3D, where NumPy's strided reduction dominates."""
    v = np.asarray(v)
    if v.ndim != 2 or v.shape[1] > 4 or not np.issubdtype(v.dtype, np.floating):
        return np.linalg.norm(v, axis=1)
    if v.shape[1] == 0:
        return np.zeros(v.shape[0], dtype=v.dtype)
    sq = v[:, 0] * v[:, 0]
    for k in range(1, v.shape[1]):
        sq += v[:, k] * v[:, k]
    return np.sqrt(sq)
