"""The uniform Cartesian grid that every solver works on."""

from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np

__all__ = ["Grid", "MAX_NODES", "MAX_COORDINATE", "MIN_SPACING", "RESOLUTION"]

_SPACING_RTOL = 1e-9

#: The most nodes a grid may have: its C-order linear indices are int64 (and the core's u64),
#: counted with Python integers so that no product of the shape wraps.
MAX_NODES = 2**63 - 1
#: The valid range of the coordinates and the spacing: the solver keeps φ in single precision
#: (float32 holds 1.2e-38 to 3.4e38; at coordinates of 1e60 the band's φ overflowed to inf), and
#: squares distances and travel times (``_validate.MAX_MAGNITUDE``).
MAX_COORDINATE = 1e30
MIN_SPACING = 1e-30
#: The smallest spacing relative to the largest coordinate magnitude of the box: float64 holds a
#: coordinate to about 1.1e-16 of it, so a spacing of 1e-11 of it keeps the nodes' positions and
#: the differences of φ between neighbours accurate to about 2e-5 of a spacing.
RESOLUTION = 1e-11


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

    Raises
    ------
    ValueError
        If the corners are not finite or not increasing, fewer than 3 nodes lie along an axis,
        the grid is not 2D or 3D, or the spacing differs between axes (the error gives the
        ``upper`` that makes it uniform).
    TypeError
        If the corners or the shape are not sequences of numbers.

    Examples
    --------
    >>> grid = Grid(lower=(-1, -1), upper=(1, 1), shape=(101, 101))
    >>> grid.spacing
    0.02
    """

    def __init__(self, lower: Sequence[float], upper: Sequence[float], shape: Sequence[int]):
        from ._numbers import ArgumentTypeError, whole_number

        def numbers(corner: Sequence[float]) -> np.ndarray:
            # every element one real number: not a bool, string, None or sequence (NumPy would read
            # True as 1, "1" as 1.0 and None as NaN)
            items = (
                [corner]
                if isinstance(corner, (str, bytes)) or corner is None
                else list(np.asarray(corner, dtype=object).reshape(-1))
            )
            if not items or any(
                x is None or isinstance(x, (str, bytes, bool, np.bool_)) or np.ndim(x) != 0 for x in items
            ):
                raise TypeError
            return np.asarray(corner, dtype=float).reshape(-1)

        try:
            lo, hi = numbers(lower), numbers(upper)
        except (TypeError, ValueError):
            raise ArgumentTypeError(
                f"lower and upper must be sequences of real numbers (not bools, strings or None); got "
                f"{lower!r} and {upper!r}"
            ) from None
        try:
            if isinstance(shape, (str, bytes)) or np.ndim(shape) != 1:
                raise TypeError
            items = list(shape)
        except (TypeError, ValueError):
            raise ArgumentTypeError(
                f"shape must be a sequence of whole numbers of nodes per axis, got {shape!r}"
            ) from None
        try:
            shp = tuple(whole_number(n, "shape", "whole numbers of nodes per axis") for n in items)
        except ArgumentTypeError:
            raise ArgumentTypeError(f"shape must hold whole numbers of nodes per axis, got {shape!r}") from None
        if not (lo.size == hi.size == len(shp)):
            raise ValueError(
                f"lower, upper and shape must have the same length (2 or 3); got {lo.size}, {hi.size}, {len(shp)}"
            )
        if len(shp) not in (2, 3):
            raise ValueError(f"only 2D and 3D grids are supported; got {len(shp)} axes")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            raise ValueError("lower and upper must be finite")
        big = float(max(np.max(np.abs(lo)), np.max(np.abs(hi))))
        if big > MAX_COORDINATE:
            raise ValueError(
                f"the grid's coordinates must lie within ±{MAX_COORDINATE:g}; got a corner at {big:.3g}. The "
                "solver squares distances and travel times, which overflow beyond that: rescale the units"
            )
        nodes = math.prod(shp)
        if nodes > MAX_NODES:
            raise ValueError(
                f"shape {shp} has {nodes:.3g} nodes; at most 2^63 - 1 are supported (64-bit node indices). "
                "Use fewer nodes per axis"
            )
        for k, n in enumerate(shp):
            if n < 3:
                raise ValueError(f"shape[{k}] = {n}: every axis needs at least 3 nodes")
            if not hi[k] > lo[k]:
                raise ValueError(f"upper[{k}] = {hi[k]} must be greater than lower[{k}] = {lo[k]}")
        steps = (hi - lo) / (np.asarray(shp, dtype=float) - 1)
        h = steps[0]
        if not MIN_SPACING <= h:
            raise ValueError(
                f"the grid spacing {h:.3g} is below {MIN_SPACING:g}: the solver keeps φ in single precision "
                "(float32), which cannot resolve it. Rescale the units of the grid (and of the surface)"
            )
        if h < RESOLUTION * big:
            raise ValueError(
                f"the grid spacing {h:.3g} is below the resolution of its coordinates: float64 stores a coordinate of "
                f"magnitude {big:.3g} to about {big * 2.2e-16:.2g}, so the nodes' positions and φ's differences between "
                f"neighbours would be mostly rounding. The spacing must be at least {RESOLUTION:g} × the largest "
                f"coordinate ({RESOLUTION * big:.3g}): shift the coordinates (e.g. subtract the box's centre) or use "
                "fewer nodes"
            )
        for k in range(1, len(shp)):
            if abs(steps[k] - h) > _SPACING_RTOL * h:
                fix_n = (hi[k] - lo[k]) / h + 1
                raise ValueError(
                    f"non-uniform spacing: axis {k} has spacing {steps[k]:.10g} but axis 0 has {h:.10g} (they differ by "
                    f"{abs(steps[k] - h) / h:.2g} of it). tubesweep needs equal spacing in every axis: use upper[{k}] = "
                    f"{lo[k] + h * (shp[k] - 1):.10g} or shape[{k}] ≈ {fix_n:.6g} (must be an integer)"
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
        return math.prod(self._shape)  # a Python int: no int64 product to wrap

    def __repr__(self) -> str:
        return (
            f"Grid(lower={tuple(float(x) for x in self._lower)}, upper={tuple(float(x) for x in self._upper)}, "
            f"shape={self._shape})"
        )

    def __eq__(self, other: object) -> bool:
        # equal up to rounding, measured in grid spacings: the corners within a millionth of a
        # spacing (plus the rounding of their own size), and the spacings so close that the far
        # nodes agree as well (numpy's default relative tolerance let two boxes at x = 1000 shifted
        # by 0.18 spacings compare equal)
        if not isinstance(other, Grid) or self._shape != other._shape:
            return False
        h = float(self._spacing)
        slack = 1e-6 * h + 1e-13 * float(np.max(np.abs(self._lower)))
        far = max(self._shape) - 1
        return bool(
            np.all(np.abs(np.asarray(self._lower) - np.asarray(other._lower)) <= slack)
            and abs(float(self._spacing) - float(other._spacing)) * max(far, 1) <= slack
        )

    def __hash__(self) -> int:
        # equal grids (equal shapes, corners and spacings up to rounding, as __eq__ compares them)
        # must hash alike: only the shape is exact, so the hash is the shape's
        return hash(("tubesweep.Grid", self._shape))

    # ------------------------------------------------------------------ coordinates
    def axis(self, k: int) -> np.ndarray:
        """Node coordinates along one axis.

        Parameters
        ----------
        k : int
            The axis (0 is x).

        Returns
        -------
        numpy.ndarray
            ``(shape[k],)`` coordinates.

        Raises
        ------
        IndexError
            If ``k`` is not an axis of the grid.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.axis(0).tolist()
        [-1.0, -0.5, 0.0, 0.5, 1.0]
        """
        return self._lower[k] + self._spacing * np.arange(self._shape[k])

    def meshgrid(self) -> Tuple[np.ndarray, ...]:
        """Dense coordinate arrays of the grid's shape (allocates the whole box).

        Returns
        -------
        tuple of numpy.ndarray
            One array of ``grid.shape`` per axis, indexed like ``numpy.meshgrid(..., indexing="ij")``.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> X, Y = grid.meshgrid()
        >>> X.shape
        (5, 5)
        """
        return tuple(np.meshgrid(*[self.axis(k) for k in range(self.ndim)], indexing="ij"))

    def points(self, indices: "np.ndarray | Sequence[Sequence[int]]") -> np.ndarray:
        """Coordinates of nodes given by their integer indices.

        Parameters
        ----------
        indices : array_like
            ``(M, d)`` node indices.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` coordinates.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.points([[0, 0], [4, 2]]).tolist()
        [[-1.0, -1.0], [1.0, 0.0]]
        """
        idx = np.asarray(indices)
        return self._lower + self._spacing * idx.astype(float)

    def node_points(self, linear: np.ndarray) -> np.ndarray:
        """Coordinates of the nodes with the given C-order linear indices (computed in Rust).

        Parameters
        ----------
        linear : array_like
            ``(M,)`` linear indices.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` coordinates, the bits of ``points(unravel(linear))``.

        Raises
        ------
        ValueError
            If an index lies outside the grid.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.node_points([0, 24]).tolist()
        [[-1.0, -1.0], [1.0, 1.0]]
        """
        from . import _native

        lin = np.ascontiguousarray(linear, dtype=np.int64)
        if lin.size and lin.min() < 0:  # (reported as 18446744073709551615 by the core: a helper's review)
            raise ValueError(
                f"linear indices must lie in [0, {self.size}) (grid.size): {int(lin.min())} is outside the grid "
                "(NumPy's negative indexing does not apply here)"
            )
        return _native.node_points(
            list(self._shape), lin.view(np.uint64), [float(x) for x in self._lower], self._spacing
        )

    def continuous_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Fractional node index of points.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` fractional indices (0 at the lower corner).

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.continuous_index([[0.25, -1.0]]).tolist()
        [[2.5, 0.0]]
        """
        p = np.asarray(points, dtype=float)
        with np.errstate(over="ignore", invalid="ignore"):  # points near ±1e308: ±inf, far off the grid
            return (p - self._lower) / self._spacing

    def nearest_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Index of the node nearest to each point.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points in the box.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` int64 node indices.

        Raises
        ------
        ValueError
            If a point lies outside the box.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.nearest_index([[0.3, -0.9]]).tolist()
        [[3, 0]]
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        if not np.all(self.contains(p)):
            raise ValueError("points outside the grid have no nearest node")
        return np.rint(self.continuous_index(p)).astype(np.int64)

    def cell_index(self, points: "np.ndarray | Sequence[Sequence[float]]") -> np.ndarray:
        """Index of the lower corner of the cell that holds each point.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` int64 indices, clipped to the box's cells.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.cell_index([[0.3, -0.9]]).tolist()
        [[2, 0]]
        """
        t = self.continuous_index(np.atleast_2d(points))
        return np.clip(np.floor(t), 0, np.asarray(self._shape) - 2).astype(np.int64)

    def contains(self, points: "np.ndarray | Sequence[Sequence[float]]", tol: float = 1e-9) -> np.ndarray:
        """Which points lie inside the box.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points.
        tol : float
            Slack in grid spacings (default 1e-9).

        Returns
        -------
        numpy.ndarray
            ``(M,)`` booleans.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.contains([[0.0, 0.0], [2.0, 0.0]]).tolist()
        [True, False]
        """
        t = self.continuous_index(np.atleast_2d(points))
        return np.all((t >= -tol) & (t <= np.asarray(self._shape) - 1 + tol), axis=1)

    def linear_index(self, indices: np.ndarray) -> np.ndarray:
        """C-order linear index of node indices.

        Parameters
        ----------
        indices : array_like
            ``(M, d)`` node indices.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` int64 linear indices.

        Raises
        ------
        ValueError
            If an index lies outside the grid.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.linear_index([[1, 2]]).tolist()
        [7]
        """
        idx = np.asarray(indices, dtype=np.int64)
        return np.ravel_multi_index(tuple(idx.T), self._shape)

    def unravel(self, linear: np.ndarray) -> np.ndarray:
        """Node indices of C-order linear indices.

        Parameters
        ----------
        linear : array_like
            ``(M,)`` linear indices.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` node indices.

        Raises
        ------
        ValueError
            If an index lies outside the grid.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (5, 5))
        >>> grid.unravel([7]).tolist()
        [[1, 2]]
        """
        return np.stack(np.unravel_index(np.asarray(linear, dtype=np.int64), self._shape), axis=1)
