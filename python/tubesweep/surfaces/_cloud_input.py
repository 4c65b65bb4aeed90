"""The samples a user hands to :func:`~tubesweep.surfaces.from_points` (and their normals),
checked before any analysis: numbers, the shape of a cloud, finite, within the solver's range."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validate import real_array
from ..grid import MAX_COORDINATE


def checked_points(points: Any, name: str = "points") -> np.ndarray:
    """``points`` (or the cloud's ``normals``, by ``name``) as a contiguous ``(M, 3)`` or ``(M, 2)``
    float array, or the error that names what is wrong with it: not numbers, the wrong shape,
    empty, NaN or inf (with the first such row and how to drop them), coordinates beyond the
    solver's single-precision range."""
    what = f"{name} must be an array of shape (M, 3) (or (M, 2) for a curve) of numbers"
    try:
        a = np.asarray(points)
    except ValueError:  # ragged nesting
        raise TypeError(f"{what}; got {type(points).__name__}") from None
    not_numbers = (str, bytes, bool, np.bool_)
    if a.dtype.kind in "USb" or (a.dtype == object and any(isinstance(x, not_numbers) for x in a.reshape(-1))):
        # strings (even of digits), bytes and booleans are not coordinates
        raise TypeError(f"{what}; got dtype {a.dtype}")
    try:
        p = real_array(a, name)
    except TypeError as e:
        raise TypeError(f"{what}: {e}") from None
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"{name} must have shape (M, 3) (or (M, 2) for a curve); got {p.shape}")
    if p.shape[0] == 0:
        raise ValueError(f"{name} is empty: a point cloud needs samples of the surface")
    finite = np.isfinite(p).all(axis=1)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        raise ValueError(
            f"{name} holds {bad.size} points with NaN or inf (the first, index {int(bad[0])}: "
            f"{tuple(float(x) for x in p[bad[0]])}); drop them, e.g. {name}[np.isfinite({name}).all(axis=1)]"
        )
    big = float(np.max(np.abs(p)))
    if big > MAX_COORDINATE:
        raise ValueError(
            f"{name} has coordinates up to {big:.3g}; they must lie within ±{MAX_COORDINATE:g} (the solver keeps "
            "distances in single precision): rescale the cloud"
        )
    return np.ascontiguousarray(p)
