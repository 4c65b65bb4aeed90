"""First-arrival times in the whole box as a result with point evaluation: what
``travel_time(..., return_solution=True)`` returns."""

from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ._interpolation import check_interpolation, interpolate_dense
from ._validate import as_points
from .grid import Grid
from .stats import SolveStats

__all__ = ["BoxSolution"]


class BoxSolution:
    """Travel times ``u`` at every node of the box, with :meth:`__call__` to evaluate them anywhere.

    What ``travel_time(..., return_solution=True)`` returns; ``np.asarray(sol)`` gives the values.

    Attributes
    ----------
    grid : Grid
        The box and its nodes.
    values : numpy.ndarray
        The nodal travel times, an array of ``grid.shape`` (what ``travel_time`` returns without
        ``return_solution``).
    sources : numpy.ndarray
        ``(K, d)`` source points.
    source_slowness : numpy.ndarray
        ``(K,)`` slowness ``1/F`` at each source.
    order : int
        The scheme's order (1 or 2).
    stats : SolveStats
        What the solve did.

    Examples
    --------
    >>> import tubesweep as ts
    >>> grid = ts.Grid((-1, -1), (1, 1), (81, 81))
    >>> sol = ts.travel_time(grid, [(0.013, -0.2)], speed=2.0, order=2, return_solution=True)
    >>> sol.values.shape, sol.order
    ((81, 81), 2)
    >>> u = sol([(0.5, 0.5), (0.013, -0.2)], interpolation="cubic")  # |p − x_s| / 2; exactly 0 at the source
    """

    def __init__(
        self,
        grid: Grid,
        values: np.ndarray,
        sources: np.ndarray,
        source_slowness: np.ndarray,
        slowness_at: Callable[[np.ndarray], np.ndarray],
        stats: SolveStats,
        order: int,
        source_radius: float,
    ):
        self.grid = grid
        self.values = values
        self.sources = sources
        self.source_slowness = source_slowness
        self.stats = stats
        self.order = order
        self._slowness_at = slowness_at
        self._source_radius = source_radius

    def __repr__(self) -> str:
        s = self.stats
        return f"BoxSolution(order={self.order}, shape={self.grid.shape}, iterations={s.iterations}, converged={s.converged})"

    def __array__(self, dtype: Any = None, copy: Optional[bool] = None) -> np.ndarray:
        return np.array(self.values, dtype=dtype, copy=True) if copy else np.asarray(self.values, dtype=dtype)

    def _nearest_source(self, p: np.ndarray) -> "tuple[np.ndarray, np.ndarray]":
        """For each point, the source ``j`` minimising ``sⱼ|p − xⱼ|`` and that value."""
        k = len(self.sources)
        j = np.empty(len(p), np.int64)
        d = np.empty(len(p))
        step = max(1, (1 << 22) // k)
        for lo in range(0, len(p), step):
            q = p[lo : lo + step]
            t = self.source_slowness[None, :] * np.linalg.norm(q[:, None, :] - self.sources[None, :, :], axis=2)
            j[lo : lo + step] = np.argmin(t, axis=1)
            d[lo : lo + step] = t[np.arange(len(q)), j[lo : lo + step]]
        return j, d

    def __call__(self, points: Any, interpolation: str = "linear") -> np.ndarray:
        """The travel time at points, by factored interpolation of the nodal values.

        With ``j`` the source minimising ``u₀ = sⱼ|P − xⱼ|`` (``sⱼ`` the slowness at source
        ``j``), the difference ``w = u − u₀`` is interpolated and ``u₀(P)`` added back, so the
        source's cone costs no interpolation error. Within ``SOURCE_RADIUS`` grid spacings of the
        source the result is blended (fully within one spacing) with the exact local travel time
        that the nodes there hold, ``|P − xⱼ|·(s(P) + sⱼ)/2``: the value *at* a source is
        exactly 0.

        Parameters
        ----------
        points : array_like
            ``(M, d)`` points (or one point ``(d,)``).
        interpolation : {"linear", "cubic"}
            ``"linear"`` (the default): multilinear over the point's cell. ``"cubic"``:
            Catmull–Rom cubics over the 4^d nodes around the point where they lie in the box,
            multilinear in the boundary cells.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` travel times; NaN outside the box.

        Raises
        ------
        ValueError
            If the points do not have the grid's dimension or are not finite, or
            ``interpolation`` is not one of the two.

        Examples
        --------
        >>> import tubesweep as ts
        >>> sol = ts.travel_time(ts.Grid((-1, -1), (1, 1), (41, 41)), [(0.1, 0.2)], order=2, return_solution=True)
        >>> float(sol([(0.1, 0.2)])[0]), round(float(sol([(0.4, 0.6)])[0]), 12)
        (0.0, 0.5)
        """
        check_interpolation(interpolation)
        g = self.grid
        p = as_points(points, g.ndim, "points")
        j, u0 = self._nearest_source(p)
        src, slow = self.sources, self.source_slowness

        def minus_factor(rows: np.ndarray, node_points: np.ndarray, node_values: np.ndarray) -> np.ndarray:
            jj = j[rows]
            r = np.linalg.norm(node_points - src[jj][:, None, :], axis=2)
            return node_values - slow[jj][:, None] * r

        with np.errstate(invalid="ignore"):
            out = u0 + interpolate_dense(self.values, g, p, interpolation, minus_factor)
        h = g.spacing
        r = u0 / slow[j]
        near = np.flatnonzero((r < self._source_radius * h) & np.isfinite(out))
        if near.size:
            local = r[near] * 0.5 * (self._slowness_at(p[near]) + slow[j[near]])
            lam = np.clip(self._source_radius - r[near] / h, 0.0, 1.0)
            out[near] = lam * local + (1.0 - lam) * out[near]
        # never negative: u₀ + w interpolated rounds to just below 0 next to a source (NaN stays)
        np.maximum(out, 0.0, out=out)
        return out
