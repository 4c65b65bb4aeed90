"""Distinct values and rows by sorting: what ``np.unique`` returns, at the cost of a sort.

NumPy 2.3 and later find ``np.unique``'s distinct values of an array by hashing, which on the
10⁵–10⁶ large integers of a mesh's edge keys or a band's node indices costs 20–40 times a sort
(the bunny's 208,353 edge keys: 52 ms against 1.8 ms); ``np.unique(..., axis=0)`` sorts rows as
structured records, 2–3 times a ``lexsort`` of their columns (``benches/experiments/mesh_check_passes.py``). The mesh checks run several such
passes per mesh, so they use these instead. Each returns exactly what the ``np.unique`` call
named in its docstring returns (``tests/test_distinct.py`` compares them)."""

from __future__ import annotations

from typing import Tuple

import numpy as np


def distinct(values: np.ndarray) -> np.ndarray:
    """The sorted distinct values of ``values`` (flattened), as ``np.unique(values)``; for
    integers (floats with NaN would keep every NaN)."""
    s = np.sort(np.asarray(values).ravel())
    if s.size == 0:
        return s
    keep = np.empty(s.size, dtype=bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]


def used_vertices(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """The vertex indices that ``faces`` name, sorted, as ``np.unique(faces)`` (int64): one
    ``bincount``."""
    return np.flatnonzero(np.bincount(np.asarray(faces, dtype=np.int64).ravel(), minlength=n_vertices))


def distinct_rows(rows: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The first index of each distinct row of the 2-D array ``rows`` and, per row, the number
    of its distinct row, as ``np.unique(rows, axis=0, return_index=True, return_inverse=True)[1:]``
    (rows numbered in lexicographic order; the row values with ``rows[first]``). Finite values."""
    a = np.asarray(rows)
    if a.ndim != 2:
        raise ValueError(f"rows must be 2-D, got shape {a.shape}")
    if len(a) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    order = np.lexsort(a.T[::-1])  # stable: the first row of each group comes first
    s = a[order]
    new = np.empty(len(a), dtype=bool)
    new[0] = True
    np.any(s[1:] != s[:-1], axis=1, out=new[1:])
    rank = np.cumsum(new) - 1
    inverse = np.empty(len(a), np.int64)
    inverse[order] = rank
    return order[new].astype(np.int64), inverse
