"""Implicit surfaces as the solver sees them.

A surface hands the solver, for the grid nodes within a half-width of it (the band):

* an unsigned distance-like value (``|φ|`` for a level set, ``|x − cp(x)|`` for a closest-point
  surface) that decides inner tube versus extension layer;
* the outward extension direction ``sgn(φ) n`` (paper Eq. (8)), or ``(x − cp(x)) / |x − cp(x)|``
  for a closest-point surface (Sect. 5.2);
* closest points on the surface, used to initialise point sources.

:class:`LevelSet` is defined here; ``ClosestPoint`` and the library surfaces of
``tubesweep.surfaces`` subclass :class:`Surface` the same way.
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Callable, List, Optional, Tuple, Union

import numpy as np

from .band import EVAL_CHUNK, BandGeometry, _evaluate, _kinks, discover_band
from .grid import Grid
from .stats import SolveStats
from ._validate import check_flag, real_array, real_scalar
from ._warn import user_stacklevel

__all__ = ["Surface", "LevelSet", "BandGeometry", "as_surface"]


# |∇φ| outside [GRAD_ERROR_LOW, GRAD_ERROR_HIGH] on the inner tube is an error, outside
# [GRAD_WARN_LOW, GRAD_WARN_HIGH] a warning: the method needs φ close to a signed distance.
GRAD_ERROR_LOW, GRAD_ERROR_HIGH = 1.0 / 3.0, 3.0
GRAD_WARN_LOW, GRAD_WARN_HIGH = 0.6, 1.8


class Surface:
    """Base class of implicit curves and surfaces: what :func:`tubesweep.solve` needs of one.

    A surface gives its band on a grid (:meth:`band`: the nodes within a distance, with φ and the
    extension directions) and projects points onto itself (:meth:`project`). :class:`LevelSet`,
    :class:`ClosestPoint` and the meshes of :func:`tubesweep.surfaces.from_mesh` are surfaces;
    subclass one of them rather than this class.

    Attributes
    ----------
    ndim : int or None
        2 (a curve) or 3 (a surface); None until known.

    Examples
    --------
    >>> import tubesweep as ts
    >>> isinstance(ts.surfaces.Sphere(0.5), ts.Surface)
    True
    """

    #: dimension of the embedding space, or None if it follows the grid
    ndim: Optional[int] = None

    def band(self, grid: Grid, half_width: float) -> BandGeometry:  # pragma: no cover - interface
        """The band of the surface on a grid: the nodes within ``half_width`` of it.

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance, not grid spacings).

        Returns
        -------
        BandGeometry
            The band's nodes (C-order linear indices), φ there and the outward extension directions
            ``n`` of Eq. (8); the solver's input.

        Raises
        ------
        ValueError
            If the surface is of the wrong dimension for the grid, or (level sets) φ is far from a
            distance function near the surface.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> geometry = ts.surfaces.Circle(0.5).band(grid, 4 * grid.spacing)
        """
        raise NotImplementedError

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:  # pragma: no cover
        """Closest points on the surface, and the distance to them.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points near the surface.
        grid : Grid
            The grid (a sampled φ is interpolated on it).

        Returns
        -------
        distance : numpy.ndarray
            ``(M,)`` unsigned distances.
        closest : numpy.ndarray
            ``(M, d)`` the closest points.

        Raises
        ------
        ValueError
            If the points have the wrong shape or the surface's function returns non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> d, cp = ts.surfaces.Circle(0.5).project(np.array([[0.6, 0.0]]), grid)
        >>> np.round(cp, 6).tolist()
        [[0.5, 0.0]]
        """
        raise NotImplementedError

    def check_grid(self, grid: Grid) -> None:
        """Checks that the grid suits the surface (its dimension; for a φ array, its shape).

        Parameters
        ----------
        grid : Grid
            The grid to solve on.

        Raises
        ------
        ValueError
            If the dimensions or shapes differ; the message says which.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> ts.LevelSet(np.zeros((5, 5))).check_grid(ts.Grid((-1, -1), (1, 1), (5, 5)))
        """
        if self.ndim is not None and self.ndim != grid.ndim:
            raise ValueError(
                f"surface is {self.ndim}D but the grid is {grid.ndim}D: a φ array needs one axis per grid axis "
                f"(grid.shape = {tuple(grid.shape)}), a curve a 2D grid and a surface a 3D grid; build the grid with "
                f"as many axes as the surface has coordinates"
            )


def _norm_bounds(values: np.ndarray, norm: np.ndarray, half_width: float) -> Tuple[float, float, bool]:
    """The range of |∇φ| (``norm``) over the band nodes within half the band of the surface
    (``|φ| ≤ half_width/2``), and True; over all of them, and False, when there are none.
    Chunk by chunk: a temporary of the band's size (8 bytes per node for ``|φ|``) would raise
    the set-up's peak memory."""
    lo, hi, lo_all, hi_all, any_near = np.inf, -np.inf, np.inf, -np.inf, False
    for start in range(0, len(values), EVAL_CHUNK):
        v, g = values[start : start + EVAL_CHUNK], norm[start : start + EVAL_CHUNK]
        # np.minimum and np.maximum pass a NaN on, as the minimum over the whole band would
        lo_all, hi_all = float(np.minimum(lo_all, g.min())), float(np.maximum(hi_all, g.max()))
        near = g[np.abs(v) <= 0.5 * half_width]
        if near.size:
            any_near = True
            lo, hi = float(np.minimum(lo, near.min())), float(np.maximum(hi, near.max()))
    if any_near:
        return lo, hi, True
    return lo_all, hi_all, False


def _check_sign_change(values: np.ndarray, grid: Grid) -> None:
    """Refuses a band whose φ keeps one sign (``values``: φ at its nodes, within the tube's reach
    of where φ is smallest in magnitude) and stays farther from 0 than 1.5 half cell diagonals (a
    surface between the nodes of a φ as steep as 1.5 at most, the band search's default bound): φ
    has no zero level set on the grid, so there is no surface (a φ of r + 0.1 was told that it is
    no distance function, a helper's review). Nearer, a surface may lie between the nodes (a
    sphere of radius 0.5 at N = 4), which the checks that follow call a grid too coarse."""
    reach = 1.5 * 0.5 * np.sqrt(grid.ndim) * grid.spacing
    if values.size and (np.all(values > 0) or np.all(values < 0)) and np.min(np.abs(values)) > reach:
        sign = "> 0" if values[0] > 0 else "< 0"
        closest = float(np.min(np.abs(values)))
        raise ValueError(
            f"surface: φ has no zero level set on the grid: it is {sign} at every node (|φ| ≥ {closest:.3g} within "
            "the tube's reach), so there is no surface to solve on. Pass a φ that is negative inside the surface and "
            "positive outside, on a grid that holds the surface"
        )


class LevelSet(Surface):
    """A curve or surface given as the zero level set of φ, close to a signed distance function.

    Parameters
    ----------
    phi : ndarray of ``grid.shape`` or callable ``phi(points (M, d)) -> (M,)``
        The level set function sampled on the grid, or a vectorised function. Only the band is
        evaluated for a callable (found coarse-to-fine, never the whole box). A C-ordered float64
        array is used in place, not copied (no second array of the grid's size): do not change it
        while a solution or a :class:`~tubesweep.Tube` built from it is in use (a Tube refuses to
        solve after a change, and a solution to trace geodesic paths or, at second order, to read
        values at points, whose projections use it); pass ``phi.copy()`` to keep it free.
    lipschitz : float, optional
        Bound on ``|∇φ|`` used by the coarse-to-fine band search (1 for an exact distance; the
        default 1.5 leaves room for near-distance functions). With ``redistance=True`` the default
        is estimated from |∇φ| on a coarse lattice of the grid box for a callable and then from
        |∇φ| at the band's candidates; an array needs none (it is not used: the band is found
        from the cells the zero level set crosses).
    redistance : bool
        For φ that is *not* a distance function (e.g. ``x² + y² − r²``): in the band only, replace
        φ by the signed distance to its zero level set (:mod:`tubesweep.redistance`). An array may
        be any φ whose sign changes across the surface (far from a distance, with plateaus, float32,
        a 0/1 mask: see :meth:`from_mask`): the zero level set of its multilinear interpolant is
        located cell by cell and the closest points on it refined from there. A callable is
        projected from each node (Newton steps along ∇φ, then closest-point iterations). The tube
        widths are then true distances and the extension direction is ``(x − cp(x))/|x − cp(x)|``.
        Costs a few dozen φ evaluations per band node.

    Raises
    ------
    ValueError
        If a φ array is not 2D or 3D or holds NaN or inf, or ``lipschitz`` is not a valid bound.
    TypeError
        If φ is neither an array nor a callable.

    Notes
    -----
    The outward normal ``n = ∇φ / |∇φ|`` comes from central differences of φ at the band nodes, as
    in the paper (Sect. 4). The method needs φ close to a signed distance function (``|∇φ| ≈ 1``
    near the surface); far from it the solver raises an error that says so.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1), (1, 1), (101, 101))
    >>> X, Y = grid.meshgrid()
    >>> circle = ts.LevelSet(np.hypot(X, Y) - 0.5)                   # a signed distance, sampled
    >>> squashed = ts.LevelSet(X**2 + Y**2 - 0.25, redistance=True)   # not a distance: re-distanced
    >>> sol = ts.solve(squashed, grid, [(0.5, 0.0)])
    """

    #: The smoothing width of :meth:`from_mask` (in voxels) for a mask's surface, None otherwise.
    _mask_smoothing: Optional[float] = None

    def __init__(
        self,
        phi: Union[np.ndarray, Callable[[np.ndarray], np.ndarray]],
        *,
        lipschitz: Optional[float] = None,
        redistance: bool = False,
    ):
        self._non_finite: Optional[tuple] = None
        if callable(phi):
            self._fn: Optional[Callable[[np.ndarray], np.ndarray]] = phi
            self._array: Optional[np.ndarray] = None
        else:
            from . import _native

            # C order, as the core reads it (no copy for a C-ordered float64 array)
            arr = real_array(phi, "phi array")
            if arr.ndim not in (2, 3):  # before ascontiguousarray, which makes a 0-d array 1-d
                raise ValueError(
                    f"phi array must be 2D or 3D (the grid's shape); got {arr.ndim} dimensions (shape {arr.shape})"
                )
            arr = np.ascontiguousarray(arr)
            # NaN or inf far from the surface (φ undefined there) is fine: the band never reads it,
            # and the band's search checks that none lies next to the band (see band())
            bad = _native.first_non_finite(arr)
            self._non_finite = None if bad is None else tuple(int(x) for x in np.unravel_index(bad, arr.shape))
            if self._non_finite is not None and redistance:
                raise ValueError(
                    f"phi contains NaN or inf (first at index {self._non_finite}); with redistance=True "
                    "φ must be finite everywhere"
                )
            self._fn = None
            self._array = arr
            self.ndim = arr.ndim
        self.redistance = bool(check_flag(redistance, "redistance"))
        if lipschitz is not None:
            lipschitz = real_scalar(lipschitz, "lipschitz", "a real number (a bound on |∇φ|)")
        if lipschitz is None:
            self.lipschitz: Optional[float] = None if self.redistance else 1.5
        elif self.redistance:
            if not (np.isfinite(lipschitz) and lipschitz > 0):
                raise ValueError(f"lipschitz must be a positive bound on |∇φ|; got {lipschitz}")
            self.lipschitz = float(lipschitz)
        else:
            if not (np.isfinite(lipschitz) and lipschitz >= 1.0):
                raise ValueError(f"lipschitz must be >= 1 (a distance function has |∇φ| = 1); got {lipschitz}")
            self.lipschitz = float(lipschitz)

    @classmethod
    def from_mask(cls, mask: Any, grid: Grid, *, smooth: float = 0.0) -> "LevelSet":
        """The surface of a voxel mask (a segmentation) on the grid's nodes.

        Parameters
        ----------
        mask : ndarray of ``grid.shape``, boolean or of 0 and 1
            True (1) inside the object, False (0) outside. The object must not touch the grid's
            boundary (pad the mask with outside voxels).
        grid : Grid
            The grid whose nodes are the mask's voxels.
        smooth : float
            The width σ, in voxels, of a Gaussian smoothing of the mask before its surface is taken
            (0, the default: none). It removes the voxel steps and moves curved parts inward by
            about σ²κ/2 (σ in length units, κ the sum of the principal curvatures). Needs scipy.

        Returns
        -------
        LevelSet
            The zero level set of ``0.5 − mask`` (smoothed), interpolated multilinearly between the
            nodes (half-way between inside and outside nodes), re-distanced in the band
            (``redistance=True``).

        Raises
        ------
        ValueError
            If the mask's shape is not the grid's, it holds values other than 0 and 1, it is all
            inside or all outside, the object touches the grid's boundary, or ``smooth`` is negative
            or erases the object.
        TypeError
            If the mask is a file's path rather than an array, or ``grid`` is not a ``ts.Grid``.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
        >>> X, Y, Z = grid.meshgrid()
        >>> ball = ts.LevelSet.from_mask(X**2 + Y**2 + Z**2 < 0.25, grid, smooth=1)
        >>> sol = ts.solve(ball, grid, [(-0.5, 0, 0)])
        >>> sol.stats.order  # smoothed over a voxel: second order (a raw mask runs first order)
        2
        """
        from .mask import level_set_function_of_mask

        surface = LevelSet(level_set_function_of_mask(mask, grid, smooth), redistance=True)
        surface._mask_smoothing = float(smooth)  # for the advice of a refusal (mask.mask_advice)
        return surface

    @property
    def is_dense(self) -> bool:
        return self._array is not None

    def check_grid(self, grid: Grid) -> None:
        if (
            self._array is not None
            and self._array.ndim == 2
            and self._array.shape[1] == grid.ndim
            and self._array.shape != grid.shape
        ):
            m, d = self._array.shape
            raise ValueError(
                f"the surface is an array of shape ({m}, {d}), which looks like {m} points or mesh vertices, not φ "
                f"sampled on the grid (shape {grid.shape}): build a surface from them with "
                "ts.surfaces.from_points(points) (a point cloud)"
                + (" or ts.surfaces.from_mesh((vertices, faces)) (a triangle mesh)" if d == 3 else "")
            )
        super().check_grid(grid)
        if self._array is not None and self._array.shape != grid.shape:
            raise ValueError(
                f"phi has shape {self._array.shape} but the grid has shape {grid.shape}; sample φ on the grid's nodes"
            )

    def phi(self, points: np.ndarray, grid: Grid) -> np.ndarray:
        """φ at arbitrary points: the callable, or the multilinear interpolation of the samples.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points.
        grid : Grid
            The grid a sampled φ lives on.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` values of φ.

        Raises
        ------
        ValueError
            If the callable returns values of the wrong shape or non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> ls = ts.LevelSet(lambda p: np.linalg.norm(p, axis=1) - 0.5)
        >>> ls.phi(np.array([[1.0, 0.0]]), ts.Grid((-1, -1), (1, 1), (5, 5))).tolist()
        [0.5]
        """
        if self._fn is not None:
            return _evaluate(self._fn, points, "phi callable")
        from .euclidean import _interp_dense

        assert self._array is not None
        return _interp_dense(self._array, grid, points)

    def _outward_directions(
        self, grid: Grid, linear: np.ndarray, values: np.ndarray, lo: int, hi: int, direction: np.ndarray, band: Any
    ) -> np.ndarray:
        """For a callable φ: ``sgn(φ) ∇φ/|∇φ|`` at band nodes ``lo:hi`` into ``direction`` (float32)
        by central differences, in Rust (``tubesweep._native.Band.outward_directions``); returns
        ``|∇φ|``. φ at a neighbour that is itself a band node is already known; the callable is
        evaluated only at the others (the band's outer rim), one batch per axis and side.
        ``band`` is the native band of ``linear``, whose neighbours give the rim places."""
        # the neighbours come from the band's own table (no search)
        pos, counts = band.rim_nodes(lo, hi)
        rim_phi = self._phi_at_rim_places(grid, linear, pos, counts)
        return band.outward_directions(grid.spacing, values, lo, hi, rim_phi, direction)

    def _phi_at_rim_places(self, grid: Grid, linear: np.ndarray, pos: np.ndarray, counts: List[int]) -> np.ndarray:
        """The callable φ at the places ``Band.rim_nodes`` lists (``pos``, ``counts``): for group
        ``g`` (axis ``g // 2``, side +1 for even ``g``) at ``x ± Δx e_k`` of its band nodes, group
        after group, one batch each."""
        from . import _native

        h = grid.spacing
        ulinear = linear.view(np.uint64)  # non-negative int64: the same bits
        parts = []
        start = 0
        for group, count in enumerate(counts):
            if count:
                x = _native.node_points(
                    list(grid.shape), ulinear[pos[start : start + count]], [float(c) for c in grid.lower], h
                )
                x[:, group // 2] += (1 if group % 2 == 0 else -1) * h
                parts.append(_evaluate(self._fn, x, "phi callable"))  # type: ignore[arg-type]
            start += count
        return np.concatenate(parts) if parts else np.zeros(0)

    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        self.check_grid(grid)
        if self.redistance:
            from .redistance import redistanced_band

            return redistanced_band(self, grid, half_width)
        from . import _native

        native_phi = self._native_phi() if self._fn is not None else None
        if native_phi is not None:
            # a library surface whose φ is evaluated in Rust: the search, the band structure, φ at
            # its rim and the directions in one call, with no call back into Python (the same
            # nodes and bits as the callable route below)
            kind, parameters = native_phi
            ulinear, values, native_band, direction, norm = _native.analytic_level_set_band(
                kind,
                [float(p) for p in parameters],
                list(grid.shape),
                [float(x) for x in grid.lower],
                grid.spacing,
                float(half_width),
                float(self.lipschitz),  # type: ignore[arg-type]
            )
            linear = ulinear.view(np.int64)
            if linear.size == 0:
                return BandGeometry(linear, values, values, direction)
            _check_sign_change(values, grid)
            self._check_distance_like(*_norm_bounds(values, norm, half_width)[:2], half_width / grid.spacing)
            return BandGeometry(
                linear,
                None,
                values,
                direction,
                consumable=True,
                native_band=native_band,
                kink=_kinks(norm, grid, linear, native_band),
            )
        if self._array is not None:
            # one pass over the samples in Rust, on all threads, with no temporary of the grid's
            # size (tubesweep_core::band::sampled)
            ulinear, values = _native.band_of_samples(self._array, half_width)
            linear = ulinear.view(np.int64)  # below 2^63: the same bits
        else:
            linear, values = discover_band(self._fn, grid, half_width, self.lipschitz)  # type: ignore[arg-type]
        if linear.size == 0:
            if self._non_finite is not None:
                raise ValueError(
                    f"phi contains NaN or inf (first at index {self._non_finite}) and no grid node with a "
                    "finite φ lies within the tube: φ must be finite near the surface"
                )
            return BandGeometry(linear, values, values, np.zeros((0, grid.ndim), np.float32))
        # the solver's band structure, built now: the solver takes it over (and for a callable φ
        # its neighbours give the outward directions, no separate neighbour search)
        native_band = _native.Band.from_linear(list(grid.shape), linear.view(np.uint64))
        # the outward direction sgn(φ) ∇φ/|∇φ|, chunk by chunk (temporaries stay O(chunk))
        direction = np.empty((len(linear), grid.ndim), np.float32)
        norms = np.empty(len(linear), np.float32)
        for lo in range(0, len(linear), EVAL_CHUNK):
            hi = min(len(linear), lo + EVAL_CHUNK)
            if self._array is not None:
                # central differences of the samples, one-sided at the grid's faces
                norm = _native.outward_directions_of_samples(  # type: ignore[assignment]
                    self._array, grid.spacing, linear[lo:hi].view(np.uint64), direction[lo:hi]
                )
            else:
                norm = self._outward_directions(grid, linear, values, lo, hi, direction[lo:hi], native_band)
            norms[lo:hi] = norm
        if self._non_finite is not None and not np.all(np.isfinite(norms)):
            # a NaN or inf sample next to a band node (its central differences read it)
            at = int(np.flatnonzero(~np.isfinite(norms))[0])
            where = tuple(int(x) for x in np.unravel_index(int(linear[at]), grid.shape))
            raise ValueError(
                f"phi contains NaN or inf next to the surface: a neighbour of the band node at index {where} (within "
                f"{half_width / grid.spacing:g} grid spacings of the surface) is not finite. φ may be NaN far from the "
                "surface, but must be finite within the tube and one grid spacing beyond it"
            )
        _check_sign_change(values, grid)
        # bounded in single precision, as the library surfaces' band call returns |∇φ|
        self._check_distance_like(*_norm_bounds(values, norms, half_width)[:2], half_width / grid.spacing)
        # distance = |φ|, not stored
        kink = _kinks(norms, grid, linear, native_band)
        del norms
        return BandGeometry(linear, None, values, direction, consumable=True, native_band=native_band, kink=kink)

    def __repr__(self) -> str:
        if self._array is not None:
            what = "array " + "×".join(map(str, self._array.shape))
        else:
            what = "callable " + getattr(self._fn, "__name__", type(self._fn).__name__)
        return f"LevelSet({what}{', redistance=True' if self.redistance else ''})"

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        """For a library surface whose φ is evaluated in Rust (and not replaced by a subclass):
        its kind and parameters for ``tubesweep._native.analytic_level_set_band``; else None."""
        return None

    def _check_distance_like(self, lo: float, hi: float, outer: float) -> None:
        """``lo``, ``hi``: the range of |∇φ| at the nodes within half the band of the surface;
        ``outer``: the band's half-width in grid spacings (a narrower tube is a cure when wide)."""
        # (the band's reach, not the caller's outer: it may have widened by itself, and with the
        # single-tube method inner sets it)
        narrower = (
            f", or narrow the tube (its band reaches {outer:g} grid spacings from the surface now: 4 by default, "
            "set by outer=, or by inner= with the single-tube method; it also widens by itself where inner-tube "
            "nodes lack neighbours)"
            if outer > 4.0 + 1e-9
            else ""
        )
        if (lo < GRAD_ERROR_LOW or hi > GRAD_ERROR_HIGH) and self._native_phi() is not None:
            # a library surface's φ is an exact distance: only the grid can be at fault
            raise ValueError(
                f"the grid is too coarse for this surface: its tube (outer × grid spacing on each side) reaches a point "
                f"where φ's gradient vanishes (|∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the surface, ≈ 1 expected), "
                "such as the centre of a sphere not much larger than the tube or the core of a thin torus: refine the "
                f"grid{narrower}, or make the surface larger than a few grid spacings"
            )
        if lo < GRAD_ERROR_LOW and abs(hi - 1.0) <= 0.1:
            # as steep as a distance at most and at best, but flat somewhere: most likely a distance whose tube
            # reaches where its gradient vanishes (two spheres min(d1, d2) 4.5 spacings apart at N = 41
            # were first told to re-distance)
            raise ValueError(
                f"surface: |∇φ| falls to {lo:.3g} near the surface, though it is ≈ 1 elsewhere (up to {hi:.3g}). If φ is "
                "a distance, "
                "the grid is too coarse for the surface: the tube (outer × grid spacing on each side) reaches a point "
                "where ∇φ vanishes, such as the middle of a gap between two parts of the surface that face each other, "
                f"the centre of a sphere not much larger than the tube or the core of a thin tube; refine the grid{narrower}. "
                "Otherwise (a union min(φ₁, φ₂) of overlapping parts, for one, is no distance inside their overlap, "
                "whatever the grid) use ts.LevelSet(phi, redistance=True) (on the command line: --redistance), which "
                "re-distances φ in the band"
            )
        if lo < GRAD_ERROR_LOW or hi > GRAD_ERROR_HIGH:
            raise ValueError(
                f"surface: φ is not close to a signed distance function: |∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the "
                "surface (it should be ≈ 1). Use ts.LevelSet(phi, redistance=True) (on the command line: --redistance), which "
                "re-distances φ in the band, "
                "or pass a signed distance function; the tube widths are measured in units of φ. If φ is a distance "
                "function, the grid is too coarse for the surface: the tube (outer × grid spacing on each side) "
                "reaches a point where ∇φ vanishes, such as the centre of a sphere not much larger than the tube, "
                "the core of a thin tube, or the middle of a gap between two parts of the surface that face each "
                f"other; refine the grid{narrower}"
            )
        if lo < GRAD_WARN_LOW or hi > GRAD_WARN_HIGH:
            warnings.warn(
                f"φ is only roughly a distance function: |∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the surface; "
                "the tube is measured in units of φ, so its real width varies accordingly",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        if self.redistance:
            from .redistance import redistanced_project

            return redistanced_project(self, points, grid)
        h = grid.spacing
        m, d = points.shape
        # φ at the points and a spacing either side along each axis, in one evaluation (the same
        # values as one call per set: φ is evaluated point by point)
        shifted = [points]
        for k in range(d):
            e = np.zeros(d)
            e[k] = h
            shifted += [points + e, points - e]
        values = self.phi(np.concatenate(shifted), grid)
        phi = values[:m]
        g = np.empty_like(points)
        for k in range(d):
            g[:, k] = (values[(2 * k + 1) * m : (2 * k + 2) * m] - values[(2 * k + 2) * m : (2 * k + 3) * m]) / (2 * h)
        n2 = np.maximum(np.sum(g * g, axis=1), 1e-24)
        closest = points - (phi / n2)[:, None] * g
        return np.abs(phi), closest


def as_surface(surface: Any) -> Surface:
    """Accepts a Surface, a φ array (or array-like: nested lists, as ``LevelSet`` does), or a φ
    callable. A path is refused with a pointer to ``ts.surfaces.from_mesh``."""
    if isinstance(surface, Surface):
        return surface
    if isinstance(surface, (str, bytes, os.PathLike)):
        raise TypeError(
            f"surface {str(surface)!r} is a {'path' if isinstance(surface, os.PathLike) else 'string'}: a mesh file is "
            "loaded with ts.surfaces.from_mesh(path) (OBJ, PLY, STL, OFF), e.g. "
            "ts.solve(ts.surfaces.from_mesh(path), grid, sources); the library's surfaces are classes, e.g. "
            "ts.surfaces.Sphere(0.5)"
        )
    if isinstance(getattr(surface, "stats", None), SolveStats):
        # a solution is callable (its values at points), and was taken for φ: "φ returned NaN"
        raise TypeError(
            f"surface is a {type(surface).__name__} (a solve's result), not a surface: pass the surface to solve on"
            + (" (this solution's is sol.surface)" if hasattr(surface, "surface") else "")
            + ": a φ, a ts.LevelSet, a library surface, a mesh or a cloud"
        )
    if callable(surface) or isinstance(surface, (np.ndarray, list, tuple)) or hasattr(surface, "__array__"):
        return LevelSet(surface)
    raise TypeError(
        "surface must be a tubesweep.LevelSet / ClosestPoint / library surface, a φ array of grid.shape, "
        f"or a callable phi(points) -> values; got {type(surface).__name__}"
    )
