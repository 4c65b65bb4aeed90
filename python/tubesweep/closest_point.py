"""Surfaces given by a closest-point function (paper Sect. 5.2).

A closest-point function ``cp(x) = argmin_{y ∈ Σ} |x − y|`` represents any reasonable surface,
including open surfaces (a hemisphere, a disc) and non-orientable ones (the Möbius band), for which
no signed distance function exists. The paper builds the two tubes from ``F(x) = |x − cp(x)|``,

    Γ_in = {F ≤ inner·Δx},   Γ_out = {inner·Δx < F ≤ outer·Δx},

and extends the solution in ``Γ_out`` along ``(x − cp(x)) / |x − cp(x)|`` (the replacement of
``sgn(φ) n`` in Eq. (8)). That vector needs no global orientation: it always points away from the
surface, which is all the upwind extension (Eq. (5)) uses.

**Open surfaces.** Near the boundary curve ∂Σ, ``cp(x)`` is a point of ∂Σ for grid nodes beyond the
rim, so the tube closes around the rim in a half-cylinder and the extension direction there points
away from ∂Σ: the extension carries the rim value outwards and no node of the band lacks a
neighbour, so nothing special is needed at ∂Σ — the tests (``tests/test_closest_point.py``) check
first-order convergence up to the rim for both Hamiltonians. Where the *grid box* cuts the tube, the
sweep treats a missing neighbour of an inner node by linear extrapolation for Lax–Friedrichs
(one-sided differences, ``MissingNeighbour::Extrapolate`` in the Rust core) and as infinity for
Godunov (upwind), so large values cannot leak inwards from a cut tube end either.
"""

from __future__ import annotations

from typing import Callable, Optional, Tuple

import numpy as np

from ._linalg import row_norms
from ._cp_checks import BAND_SAMPLE, check_band_sample, check_box_sample
from ._validate import call_on_points
from .grid import Grid
from .band import EVAL_CHUNK, BandGeometry, coarse_to_fine_candidates
from .surface import Surface

__all__ = ["ClosestPoint", "DIRECTION_EPS"]

#: Nodes closer than this fraction of Δx to their closest point get a zero extension direction
#: (they are inner nodes; only extension-layer nodes read the direction).
DIRECTION_EPS = 1e-9


def _evaluate_cp(cp: Callable[[np.ndarray], np.ndarray], points: np.ndarray, finite: bool = True) -> np.ndarray:
    m, d = points.shape
    out = np.empty((m, d))
    for s in range(0, m, EVAL_CHUNK):
        chunk = points[s : s + EVAL_CHUNK]
        v = call_on_points(cp, chunk, "cp's values")
        if v.shape != chunk.shape:
            raise ValueError(
                f"cp must map points of shape (M, {d}) to closest points of shape (M, {d}); it returned shape {v.shape} "
                f"for M = {chunk.shape[0]}"
            )
        out[s : s + EVAL_CHUNK] = v
    if finite and not np.all(np.isfinite(out)):
        bad = int(np.flatnonzero(~np.isfinite(out).all(axis=1))[0])
        raise ValueError(
            f"cp returned NaN or inf at {tuple(float(x) for x in points[bad])}; it must be finite at every point near the surface"
        )
    return out


def _refuse_undefined_next_to(grid: Grid, undefined: np.ndarray, linear: np.ndarray, advice: str = "") -> None:
    """Refuses candidate nodes where cp is not finite (``undefined``, linear indices) that are
    grid neighbours of band nodes (``linear``, sorted): cp may be undefined far from the surface,
    but such a node next to the band may be a band node lost. ``advice``: a surface kind's own
    cause and cure, which replaces the generic one."""
    if undefined.size == 0 or linear.size == 0:
        return
    idx = grid.unravel(undefined)
    for k in range(grid.ndim):
        for side in (1, -1):
            moved = idx.copy()
            moved[:, k] += side
            inside = (moved[:, k] >= 0) & (moved[:, k] < grid.shape[k])
            lin = grid.linear_index(moved[inside])
            at = np.minimum(np.searchsorted(linear, lin), len(linear) - 1)
            hit = linear[at] == lin
            if np.any(hit):
                p = grid.points(idx[inside][hit][:1])[0]
                raise ValueError(
                    f"cp returned NaN or inf at {tuple(float(c) for c in p)}, next to the band; "
                    + (advice or "it must be finite at every point near the surface (it may be undefined far from it)")
                )


class ClosestPoint(Surface):
    """A curve or surface given by its closest-point function (paper Sect. 5.2).

    Parameters
    ----------
    cp : callable ``cp(points (M, d)) -> (M, d)``
        Vectorised closest-point function: the point of Σ nearest to each input point. It must be
        accurate (well below Δx) in the band ``|x − cp(x)| ≤ outer·Δx``. The coarse-to-fine band
        search also calls it at the centres of coarse blocks, up to a block diagonal away from Σ:
        there a returned point that is *not* the nearest one over-estimates the distance and could
        drop a block — if your cp is only reliable close to Σ, raise ``lipschitz``.
    ndim : int, optional
        2 or 3; by default the grid's dimension.
    lipschitz : float
        Lipschitz bound of ``x ↦ |x − cp(x)|`` used by the coarse-to-fine band search
        (:func:`tubesweep.band.coarse_to_fine_candidates`). A distance function has constant 1; a larger
        value only makes the search visit more blocks.

    Raises
    ------
    ValueError
        If ``ndim`` is not 2 or 3 or ``lipschitz`` is below 1; at solve time, if ``cp`` returns
        the wrong shape or non-finite values.
    TypeError
        If ``cp`` is not callable.

    Notes
    -----
    The tube is ``{|x − cp(x)| ≤ h}``; the extension direction at an extension-layer node is
    ``(x − cp(x)) / |x − cp(x)|``. ``BandGeometry.signed`` equals the unsigned distance (a
    closest-point surface has no inside).

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> def cp(x):  # the upper hemisphere of radius 0.5 (at the centre and on the axis, any point)
    ...     r = np.linalg.norm(x, axis=1, keepdims=True)
    ...     rho = np.linalg.norm(x[:, :2], axis=1, keepdims=True)
    ...     up = np.where(r > 0, 0.5 * x / np.where(r > 0, r, 1), [0, 0, 0.5])
    ...     rim_xy = np.where(rho > 0, 0.5 * x[:, :2] / np.where(rho > 0, rho, 1), [0.5, 0])
    ...     return np.where(x[:, 2:] >= 0, up, np.c_[rim_xy, 0 * x[:, 2]])
    >>> surf = ts.ClosestPoint(cp)
    """

    #: True for the library's open surfaces (``order=2`` runs the first-order update at the nodes
    #: next to their rim); a user's map is taken as closed, and the nodes where its closest points
    #: show a rim or an edge run the first-order update too (docs/second-order.md)
    open_surface: bool = False

    def __init__(self, cp: Callable[[np.ndarray], np.ndarray], *, ndim: Optional[int] = None, lipschitz: float = 1.0):
        if not callable(cp):
            raise TypeError(f"cp must be a callable cp(points (M, d)) -> (M, d); got {type(cp).__name__}")
        if ndim is not None and ndim not in (2, 3):
            raise ValueError(f"ndim must be 2 or 3; got {ndim}")
        if not (np.isfinite(lipschitz) and lipschitz >= 1.0):
            raise ValueError(f"lipschitz must be >= 1 (|x − cp(x)| is 1-Lipschitz for an exact cp); got {lipschitz}")
        self._cp = cp
        #: the map's noise near the surface found by the last band (grid units; see _cp_checks)
        self._noise = 0.0
        self.ndim = ndim
        self.lipschitz = float(lipschitz)

    def __repr__(self) -> str:
        return f"ClosestPoint(callable {getattr(self._cp, '__name__', type(self._cp).__name__)}, ndim={self.ndim})"

    def closest_point(self, points: np.ndarray) -> np.ndarray:
        """The user's closest-point function, with the shape and finiteness of its answer checked.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` closest points on the surface.

        Raises
        ------
        ValueError
            If the points are not ``(M, d)`` or ``cp`` returns the wrong shape or non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> circle = ts.ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
        >>> circle.closest_point(np.array([[2.0, 0.0]])).tolist()
        [[0.5, 0.0]]
        """
        p = np.asarray(points, dtype=float)
        if p.ndim != 2:
            raise ValueError(f"points must have shape (M, d); got {p.shape}")
        return _evaluate_cp(self._cp, p)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """The unsigned distance ``|x − cp(x)|`` to the surface.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` distances.

        Raises
        ------
        ValueError
            As :meth:`closest_point`.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> circle = ts.ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
        >>> circle.distance(np.array([[2.0, 0.0]])).tolist()
        [1.5]
        """
        p = np.asarray(points, dtype=float)
        return row_norms(p - self.closest_point(p))

    def _far_distance(self, points: np.ndarray) -> np.ndarray:
        """``|x − cp(x)|`` for the band search's samples, 0 where cp is not finite (such a block
        may hold band nodes: it is kept and split)."""
        p = np.asarray(points, dtype=float)
        d = row_norms(p - _evaluate_cp(self._cp, p, finite=False))
        return np.where(np.isfinite(d), d, 0.0)

    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        from . import _native

        self.check_grid(grid)
        d = grid.ndim
        # cp may be NaN far from the surface (undefined there, e.g. on an axis): a coarse block whose
        # centre has no closest point is kept and split; the candidates are checked below
        # the identity, or a map whose points are not on a surface, refused before the search
        check_box_sample(lambda p: _evaluate_cp(self._cp, p, finite=False), grid)
        candidates = coarse_to_fine_candidates(grid, half_width, self.lipschitz, lambda p, reach: self._far_distance(p))
        # cp once per candidate, chunk by chunk: the distances select the band, and the kept
        # offsets x − cp(x) give its directions (no second cp evaluation at the band's nodes)
        shape, lower = list(grid.shape), [float(x) for x in grid.lower]
        parts_lin, parts_norm, parts_diff, undefined = [], [], [], []
        for s0 in range(0, len(candidates), EVAL_CHUNK):
            lin = candidates[s0 : s0 + EVAL_CHUNK]
            x = _native.node_points(shape, lin.view(np.uint64), lower, grid.spacing)
            diff = x - _evaluate_cp(self._cp, x, finite=False)
            norm = row_norms(diff)
            keep = norm <= half_width  # (False where cp is not finite)
            undefined.append(lin[~np.isfinite(norm)])
            parts_lin.append(lin[keep])
            parts_norm.append(norm[keep])
            parts_diff.append(diff[keep])
        if not parts_lin or sum(len(p) for p in parts_lin) == 0:
            empty = np.zeros(0)
            return BandGeometry(np.zeros(0, np.int64), empty, empty, np.zeros((0, d), np.float32))
        linear = np.concatenate(parts_lin)
        norm = np.concatenate(parts_norm)
        diff = np.concatenate(parts_diff)
        _refuse_undefined_next_to(grid, np.concatenate(undefined), linear)
        # a sample of the band: idempotence and the nearest-point property near the surface, and
        # the map's noise there (for the facing-sheets test, _facing._warn_if_tubes_touch)
        pick = np.linspace(0, len(linear) - 1, min(len(linear), BAND_SAMPLE)).astype(np.int64)
        xs = grid.node_points(linear[pick])
        self._noise = check_band_sample(lambda p: _evaluate_cp(self._cp, p, finite=False), xs, xs - diff[pick], grid)
        ok = norm > DIRECTION_EPS * grid.spacing
        direction = np.zeros((len(linear), d))
        direction[ok] = diff[ok] / norm[ok, None]
        return BandGeometry(linear, norm, norm.copy(), direction.astype(np.float32), consumable=True)

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        p = np.asarray(points, dtype=float)
        c = self.closest_point(p)
        return row_norms(p - c), c
