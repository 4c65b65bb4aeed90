"""The uniform Cartesian grid that every solver works on."""

from __future__ import annotations

from typing import Sequence, Tuple

import numpy as np

__all__ = ["Grid"]

_SPACING_RTOL = 1e-9


class Grid:
    """A uniform Cartesian grid in 2D or 3D.

    Node ``(i, j[, k])`` sits at ``lower + spacing * (i, j[, k])``; arrays of ``grid.shape`` are
    indexed like ``numpy.meshgrid(..., indexing="ij")`` (axis 0 is x). The spacing
    ``(upper - lower) / (shape - 1)`` must be the same in every axis.

    Parameters
    ----------
    lower, upper : sequence of float
        Coordinates of the first and last node along each axis.
    shape : sequence of int
        Number of nodes along each axis (at least 3).

    Examples
    --------
    >>> grid = Grid(lower=(-1, -1), upper=(1, 1), shape=(101, 101))
    >>> grid.spacing
    0.02
    """

    def __init__(self, lower: Sequence[float], upper: Sequence[float], shape: Sequence[int]):
        try:
            lo = np.asarray(lower, dtype=float).reshape(-1)
            hi = np.asarray(upper, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise TypeError(f"lower and upper must be sequences of real numbers; got {lower!r} and {upper!r}") from None
        try:
            if isinstance(shape, (str, bytes)):
                raise TypeError
            whole = all(not isinstance(n, bool) and float(n) == int(n) for n in shape)
            shp = tuple(int(n) for n in shape)
        except (TypeError, ValueError, OverflowError):
            raise TypeError(f"shape must be a sequence of whole numbers of nodes per axis, got {shape!r}") from None
        if not whole:
            raise ValueError(f"shape must hold whole numbers of nodes per axis, got {shape!r}")
        if not (lo.size == hi.size == len(shp)):
            raise ValueError(
                f"lower, upper and shape must have the same length (2 or 3); got {lo.size}, {hi.size}, {len(shp)}"
            )
        if len(shp) not in (2, 3):
            raise ValueError(f"only 2D and 3D grids are supported; got {len(shp)} axes")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            raise ValueError("lower and upper must be finite")
        for k, n in enumerate(shp):
            if n < 3:
                raise ValueError(f"shape[{k}] = {n}: every axis needs at least 3 nodes")
            if not hi[k] > lo[k]:
                raise ValueError(f"upper[{k}] = {hi[k]} must be greater than lower[{k}] = {lo[k]}")
        steps = (hi - lo) / (np.asarray(shp) - 1)
        h = steps[0]
        for k in range(1, len(shp)):
            if abs(steps[k] - h) > _SPACING_RTOL * h:
                fix_n = (hi[k] - lo[k]) / h + 1
                raise ValueError(
                    f"non-uniform spacing: axis {k} has spacing {steps[k]:.6g} but axis 0 has {h:.6g}. "
                    f"tubesweep needs equal spacing in every axis: use upper[{k}] = {lo[k] + h * (shp[k] - 1):.6g} "
                    f"or shape[{k}] ≈ {fix_n:.6g} (must be an integer)"
                )
        self._lower = lo
        self._upper = lo + h * (np.asarray(shp) - 1)
        self._shape = shp
        self._spacing = float(h)

    # ------------------------------------------------------------------ properties
    @property
    def lower(self) -> np.ndarray:
        """Coordinates of node (0, 0[, 0])."""
        return self._lower.copy()

    @property
    def upper(self) -> np.ndarray:
        """Coordinates of the last node."""
        return self._upper.copy()

    @property
    def shape(self) -> Tuple[int, ...]:
        return self._shape

    @property
    def ndim(self) -> int:
        return len(self._shape)

    @property
    def spacing(self) -> float:
        """The grid spacing Δx (the same in every axis)."""
        return self._spacing

    @property
    def size(self) -> int:
        """Number of nodes in the box."""
        return int(np.prod(self._shape))

    def __repr__(self) -> str:
        return (
            f"Grid(lower={tuple(float(x) for x in self._lower)}, upper={tuple(float(x) for x in self._upper)}, "
            f"shape={self._shape})"
        )

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Grid)
            and self._shape == other._shape
            and np.allclose(self._lower, other._lower)
            and np.isclose(self._spacing, other._spacing)
        )

    def __hash__(self) -> int:
        # equal grids (equal shapes, corners and spacings up to rounding, as __eq__ compares them)
        # must hash alike: only the shape is exact, so the hash is the shape's
        return hash(("tubesweep.Grid", self._shape))

    # ------------------------------------------------------------------ coordinates
    def axis(self, k: int) -> np.ndarray:
        """Node coordinates along axis ``k``."""
        return self._lower[k] + self._spacing * np.arange(self._shape[k])

    def meshgrid(self) -> Tuple[np.ndarray, ...]:
        """Dense coordinate arrays of ``grid.shape`` (allocates the whole box)."""
        return tuple(np.meshgrid(*[self.axis(k) for k in range(self.ndim)], indexing="ij"))

    def points(self, indices: "np.ndarray | Sequence[Sequence[int]]") -> np.ndarray:
        """Coordinates of nodes given by integer indices of shape (M, d)."""
        idx = np.asarray(indices)
        return self._lower + self._spacing * idx.astype(float)

    def node_points(self, linear: np.ndarray) -> np.ndarray:
        """Coordinates (M, d) of the nodes with C-order linear indices ``linear``: the bits of
        ``points(unravel(linear))``, computed in Rust on all threads without the (M, d) index
        array (for the band's nodes, in order, one division per grid row)."""
        from . import _native

        lin = np.ascontiguousarray(linear, dtype=np.int64)
        # a negative index turns into one above every node: refused there like any outside one
        return _native.node_points(
            list(self._shape), lin.view(np.uint64), [float(x) for x in self._lower], self._spacing
        )

    def continuous_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Fractional node index of points (M, d)."""
        p = np.asarray(points, dtype=float)
        return (p - self._lower) / self._spacing

    def nearest_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Index (M, d) of the node nearest to each point; the points must lie in the box."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        if not np.all(self.contains(p)):
            raise ValueError("points outside the grid have no nearest node")
        return np.rint(self.continuous_index(p)).astype(np.int64)

    def cell_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Index (M, d) of the lower corner of the cell that holds each point."""
        t = self.continuous_index(np.atleast_2d(points))
        return np.clip(np.floor(t), 0, np.asarray(self._shape) - 2).astype(np.int64)

    def contains(self, points: "np.ndarray | Sequence[Sequence[float]]", tol: float = 1e-9) -> np.ndarray:
        """Boolean mask (M,): points inside the box (within ``tol`` grid spacings)."""
        t = self.continuous_index(np.atleast_2d(points))
        return np.all((t >= -tol) & (t <= np.asarray(self._shape) - 1 + tol), axis=1)

    def linear_index(self, indices: np.ndarray) -> np.ndarray:
        """C-order linear index of node indices (M, d)."""
        idx = np.asarray(indices, dtype=np.int64)
        return np.ravel_multi_index(tuple(idx.T), self._shape)

    def unravel(self, linear: np.ndarray) -> np.ndarray:
        """Node indices (M, d) of C-order linear indices."""
        return np.stack(np.unravel_index(np.asarray(linear, dtype=np.int64), self._shape), axis=1)
