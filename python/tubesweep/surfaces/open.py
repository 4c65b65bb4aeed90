"""Open and non-orientable surfaces in the closest-point representation (paper Sect. 5.2):
hemisphere, disc, square plane patch and the Möbius band. Each is a
:class:`tubesweep.ClosestPoint`; none has a signed distance function (the Möbius band is not even
orientable), so φ is not defined — the tube is ``{|x − cp(x)| ≤ h}``."""

from __future__ import annotations

from typing import Any, Sequence, Tuple, Union

import numpy as np

from .. import _native
from ..closest_point import ClosestPoint
from ._triangulation import grid_mesh
from .analytic import finite_center, size_parameter

__all__ = ["Hemisphere", "Disc", "PlanePatch", "MobiusBand"]

_CUBE = ((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))


def _safe_unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=1, keepdims=True)
    return np.where(n > 1e-300, v / np.where(n > 1e-300, n, 1.0), fallback)


def _native_cp(surface: Any, base: type, kind: str, p: np.ndarray, size: float) -> np.ndarray:
    """The closest points of an open library surface, computed in the Rust core; a subclass that
    overrides ``_cp_numpy`` gets its own NumPy formula instead."""
    if type(surface)._cp_numpy is not base._cp_numpy:  # type: ignore[attr-defined]
        return surface._cp_numpy(p)
    x = np.asarray(p, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"points must have shape (M, 3); got {x.shape}")
    return _native.open_surface_closest_points(kind, np.ascontiguousarray(x), [float(c) for c in surface.center], size)


class Hemisphere(ClosestPoint):
    """The upper hemisphere ``{|x − c| = radius, z ≥ c_z}``: an open surface bounded by its rim.

    Parameters
    ----------
    radius : float
        The radius (default 0.5).
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    Closest point: the radial projection when it lands on the upper half, else the nearest point of
    the rim circle. :meth:`geodesic_distance` is the great-circle distance, exact because a closed
    hemisphere is geodesically convex. The default source sits at polar angle π/4 in the x–z plane.

    Examples
    --------
    >>> import tubesweep as ts
    >>> h = ts.surfaces.Hemisphere(0.5)
    >>> sol = ts.solve(h, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [h.default_source])
    """

    open_surface = True

    default_box = _CUBE

    def __init__(self, radius: float = 0.5, center: Sequence[float] = (0.0, 0.0, 0.0)):
        self.radius = size_parameter("radius", radius)
        self.center = finite_center(center, 3)
        super().__init__(self._cp, ndim=3)

    def _cp(self, p: np.ndarray) -> np.ndarray:
        return _native_cp(self, Hemisphere, "hemisphere", p, self.radius)

    def _cp_numpy(self, p: np.ndarray) -> np.ndarray:
        """The closest point in NumPy (the core's ``hemisphere_closest_points`` gives the same bits)."""
        q = np.asarray(p, dtype=float) - self.center
        up = _safe_unit(q, np.array([0.0, 0.0, 1.0])) * self.radius
        h = np.c_[q[:, :2], np.zeros(len(q))]
        rim = _safe_unit(h, np.array([1.0, 0.0, 0.0])) * self.radius
        return np.where(q[:, 2:3] >= 0.0, up, rim) + self.center

    @property
    def default_source(self) -> np.ndarray:
        s = np.sqrt(0.5)
        return self.center + self.radius * np.array([-s, 0.0, s])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Great-circle distance between the closest points of ``points`` and of ``source``.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points on (or near) the surface.
        source : sequence of float
            A point on the surface.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` exact geodesic distances (NaN where the formula does not apply).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Hemisphere()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        a = self._cp(np.asarray(points, dtype=float).reshape(-1, 3)) - self.center
        b = self._cp(np.asarray(source, dtype=float).reshape(1, 3))[0] - self.center
        c = (a @ b) / self.radius**2
        return self.radius * np.arccos(np.clip(c, -1.0, 1.0))

    def triangulation(self, n: int = 48) -> Tuple[np.ndarray, np.ndarray]:
        """Latitude–longitude triangulation (n rings, 4n sectors): ``(V, F)``.

        Parameters
        ----------
        n : int
            Resolution (rings, sectors or polyline points; see the summary).

        Returns
        -------
        vertices : numpy.ndarray
            ``(V, d)`` points on the surface.
        faces : numpy.ndarray
            ``(F, 3)`` triangles (``(F, 2)`` segments for a curve).

        Raises
        ------
        ValueError
            If ``n`` is too small to make a mesh.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Hemisphere()
        >>> v, f = s.triangulation()
        """
        th, ph = np.meshgrid(np.linspace(0, 0.5 * np.pi, n + 1), np.linspace(0, 2 * np.pi, 4 * n + 1), indexing="ij")
        P = self.radius * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1) + self.center
        return grid_mesh(P)


class Disc(ClosestPoint):
    """Flat disc of ``radius`` in the plane z = c_z about ``center``: an open surface.

    Parameters
    ----------
    radius : float
        The radius (default 0.6).
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    Closest point: drop z, then clip the in-plane offset to the radius. :meth:`geodesic_distance`
    is the Euclidean distance between closest points (exact: the disc is convex).

    Examples
    --------
    >>> import tubesweep as ts
    >>> d = ts.surfaces.Disc()
    >>> sol = ts.solve(d, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [d.default_source])
    """

    open_surface = True

    default_box = _CUBE

    def __init__(self, radius: float = 0.6, center: Sequence[float] = (0.0, 0.0, 0.0)):
        self.radius = size_parameter("radius", radius)
        self.center = finite_center(center, 3)
        super().__init__(self._cp, ndim=3)

    def _cp(self, p: np.ndarray) -> np.ndarray:
        return _native_cp(self, Disc, "disc", p, self.radius)

    def _cp_numpy(self, p: np.ndarray) -> np.ndarray:
        """The closest point in NumPy (the core's ``disc_closest_points`` gives the same bits)."""
        q = np.asarray(p, dtype=float) - self.center
        r = np.hypot(q[:, 0], q[:, 1])
        f = np.where(r > self.radius, self.radius / np.where(r > 0, r, 1.0), 1.0)
        return np.c_[q[:, 0] * f, q[:, 1] * f, np.zeros(len(q))] + self.center

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-0.5 * self.radius, 0.0, 0.0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Euclidean distance between the closest points (exact on a convex flat surface).

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points on (or near) the surface.
        source : sequence of float
            A point on the surface.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` exact geodesic distances (NaN where the formula does not apply).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Disc()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        return np.linalg.norm(
            self._cp(np.asarray(points, dtype=float).reshape(-1, 3))
            - self._cp(np.asarray(source, dtype=float).reshape(1, 3)),
            axis=1,
        )

    def triangulation(self, n: int = 32) -> Tuple[np.ndarray, np.ndarray]:
        """Polar-grid triangulation (n rings, 4n sectors): ``(V, F)``.

        Parameters
        ----------
        n : int
            Resolution (rings, sectors or polyline points; see the summary).

        Returns
        -------
        vertices : numpy.ndarray
            ``(V, d)`` points on the surface.
        faces : numpy.ndarray
            ``(F, 3)`` triangles (``(F, 2)`` segments for a curve).

        Raises
        ------
        ValueError
            If ``n`` is too small to make a mesh.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Disc()
        >>> v, f = s.triangulation()
        """
        rr, ph = np.meshgrid(np.linspace(0, self.radius, n + 1), np.linspace(0, 2 * np.pi, 4 * n + 1), indexing="ij")
        P = np.stack([rr * np.cos(ph), rr * np.sin(ph), np.zeros_like(rr)], -1) + self.center
        return grid_mesh(P)


class PlanePatch(ClosestPoint):
    """Square plane patch ``[−s, s]² × {0}`` about ``center`` (open, with corners).

    Parameters
    ----------
    half_size : float
        Half the side s (default 0.6).
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    Closest point: drop z and clip x, y to ``[−s, s]``. :meth:`geodesic_distance` is Euclidean
    (exact: the square is convex).

    Examples
    --------
    >>> import tubesweep as ts
    >>> p = ts.surfaces.PlanePatch()
    >>> sol = ts.solve(p, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [p.default_source])
    """

    open_surface = True

    default_box = _CUBE

    def __init__(self, half_size: float = 0.6, center: Sequence[float] = (0.0, 0.0, 0.0)):
        self.half_size = size_parameter("half_size", half_size)
        self.center = finite_center(center, 3)
        super().__init__(self._cp, ndim=3)

    def _cp(self, p: np.ndarray) -> np.ndarray:
        return _native_cp(self, PlanePatch, "plane-patch", p, self.half_size)

    def _cp_numpy(self, p: np.ndarray) -> np.ndarray:
        """The closest point in NumPy (the core's ``plane_patch_closest_points`` gives the same bits)."""
        q = np.asarray(p, dtype=float) - self.center
        s = self.half_size
        return np.c_[np.clip(q[:, 0], -s, s), np.clip(q[:, 1], -s, s), np.zeros(len(q))] + self.center

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-0.5 * self.half_size, -0.5 * self.half_size, 0.0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Euclidean distance between the closest points.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points on (or near) the surface.
        source : sequence of float
            A point on the surface.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` exact geodesic distances (NaN where the formula does not apply).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.PlanePatch()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        return np.linalg.norm(
            self._cp(np.asarray(points, dtype=float).reshape(-1, 3))
            - self._cp(np.asarray(source, dtype=float).reshape(1, 3)),
            axis=1,
        )

    def triangulation(self, n: int = 32) -> Tuple[np.ndarray, np.ndarray]:
        """Regular (n × n quads) triangulation: ``(V, F)``.

        Parameters
        ----------
        n : int
            Resolution (rings, sectors or polyline points; see the summary).

        Returns
        -------
        vertices : numpy.ndarray
            ``(V, d)`` points on the surface.
        faces : numpy.ndarray
            ``(F, 3)`` triangles (``(F, 2)`` segments for a curve).

        Raises
        ------
        ValueError
            If ``n`` is too small to make a mesh.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.PlanePatch()
        >>> v, f = s.triangulation()
        """
        s = self.half_size
        x, y = np.meshgrid(np.linspace(-s, s, n + 1), np.linspace(-s, s, n + 1), indexing="ij")
        return grid_mesh(np.stack([x, y, np.zeros_like(x)], -1) + self.center)


#: The methods of :class:`MobiusBand` whose arithmetic the core's closest point repeats: a
#: subclass that overrides one of them takes the NumPy route.
_MOBIUS_NUMPY_METHODS = ("point", "_derivs", "_interior", "_boundary", "_closest_parameters_numpy")


class MobiusBand(ClosestPoint):
    """The Möbius band: an open, non-orientable surface (no signed distance; none is needed).

    Parameters
    ----------
    R : float
        Radius of the centre circle (default 0.6).
    w : float
        Half-width of the band (default 0.3), ``0 < w < R``.
    newton_iterations : int
        At most this many Newton steps per point in the closest-point projection (each point
        stops when its step falls below 1e-13; near the band 4–6 steps suffice).

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    ``X(θ, s) = ((R + s cos(θ/2)) cos θ, (R + s cos(θ/2)) sin θ, s sin(θ/2))``, ``θ ∈ [0, 2π)``,
    ``|s| ≤ w``; its boundary is one closed curve (``s = ±w``). The extension direction
    ``(x − cp(x)) / |x − cp(x)|`` of Sect. 5.2 needs no orientation. The closest point is found
    point by point in Rust: Newton's method in (θ, s) for the interior critical point and in θ on
    the boundary curve, the nearer admissible candidate winning. There is no closed-form geodesic
    distance.

    Examples
    --------
    >>> import tubesweep as ts
    >>> m = ts.surfaces.MobiusBand()
    >>> sol = ts.solve(m, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [m.default_source])
    """

    open_surface = True

    default_box = _CUBE

    def __init__(self, R: float = 0.6, w: float = 0.3, newton_iterations: int = 60):
        R, w = size_parameter("R", R), size_parameter("w", w)
        if not (0 < w < R):
            raise ValueError(f"need 0 < w < R; got R={R}, w={w}")
        self.R = float(R)
        self.w = float(w)
        if not (
            isinstance(newton_iterations, (int, np.integer))
            and not isinstance(newton_iterations, bool)
            and 1 <= newton_iterations <= 10_000
        ):
            raise ValueError(
                f"newton_iterations must be an integer from 1 to 10,000 (60 is plenty: Newton's method "
                f"converges in a few steps); got {newton_iterations!r}"
            )
        self.newton_iterations = int(newton_iterations)
        super().__init__(self._cp, ndim=3)

    # --- parametrisation and derivatives ----------------------------------------------------
    def point(self, th: np.ndarray, s: Union[float, np.ndarray]) -> np.ndarray:
        """The band's point X(θ, s).

        Parameters
        ----------
        th : numpy.ndarray
            Angles θ.
        s : numpy.ndarray
            Offsets across the band, ``|s| ≤ w``.

        Returns
        -------
        numpy.ndarray
            ``(M, 3)`` points.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.MobiusBand()
        >>> s.point(np.array([0.0]), np.array([0.0])).round(6).tolist()
        [[0.6, 0.0, 0.0]]
        """
        th, s = np.broadcast_arrays(np.asarray(th, float), np.asarray(s, float))
        rho = self.R + s * np.cos(0.5 * th)
        return np.stack([rho * np.cos(th), rho * np.sin(th), s * np.sin(0.5 * th)], -1)

    def _derivs(self, th: np.ndarray, s: np.ndarray):
        c2, s2 = np.cos(0.5 * th), np.sin(0.5 * th)
        c, si = np.cos(th), np.sin(th)
        rho = self.R + s * c2
        X = np.stack([rho * c, rho * si, s * s2], -1)
        Xt = np.stack([-0.5 * s * s2 * c - rho * si, -0.5 * s * s2 * si + rho * c, 0.5 * s * c2], -1)
        Xs = np.stack([c2 * c, c2 * si, s2], -1)
        Xtt = np.stack(
            [-0.25 * s * c2 * c + s * s2 * si - rho * c, -0.25 * s * c2 * si - s * s2 * c - rho * si, -0.25 * s * s2],
            -1,
        )
        Xts = np.stack([-0.5 * s2 * c - c2 * si, -0.5 * s2 * si + c2 * c, 0.5 * c2], -1)
        return X, Xt, Xs, Xtt, Xts

    def _interior(self, x: np.ndarray, th: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Newton's method for the critical point of ½|X(θ, s) − x|² (steps clipped to 0.2),
        iterated on the points that have not yet converged."""
        _, _, Xs, _, _ = self._derivs(th, np.zeros_like(th))
        s = np.sum((x - self.point(th, 0.0)) * Xs, axis=1)
        active = np.arange(len(x))
        for _ in range(self.newton_iterations):
            if active.size == 0:
                break
            ta, sa, xa = th[active], s[active], x[active]
            X, Xt, Xs, Xtt, Xts = self._derivs(ta, sa)
            D = X - xa
            g1 = np.sum(D * Xt, 1)
            g2 = np.sum(D * Xs, 1)
            h11 = np.sum(Xt * Xt, 1) + np.sum(D * Xtt, 1)
            h12 = np.sum(Xt * Xs, 1) + np.sum(D * Xts, 1)
            h22 = np.sum(Xs * Xs, 1)
            det = h11 * h22 - h12 * h12
            ok = (det > 1e-14) & (h11 > 0)
            safe = np.where(ok, det, 1.0)
            # Newton where the Hessian is positive definite, gradient descent elsewhere
            dth = np.where(ok, (h22 * g1 - h12 * g2) / safe, g1 / np.maximum(np.sum(Xt * Xt, 1), 1e-14))
            ds = np.where(ok, (h11 * g2 - h12 * g1) / safe, g2)
            dth = np.clip(dth, -0.2, 0.2)
            ds = np.clip(ds, -0.2, 0.2)
            th[active] = ta - dth
            s[active] = sa - ds
            active = active[np.maximum(np.abs(dth), np.abs(ds)) > 1e-13]
        return th, s

    def _boundary(self, x: np.ndarray, th: np.ndarray, sb: float) -> np.ndarray:
        """Newton's method in θ for the nearest point of the boundary curve s = sb."""
        active = np.arange(len(x))
        for _ in range(self.newton_iterations):
            if active.size == 0:
                break
            ta, xa = th[active], x[active]
            X, Xt, _, Xtt, _ = self._derivs(ta, np.full_like(ta, sb))
            D = X - xa
            g = np.sum(D * Xt, 1)
            h = np.sum(Xt * Xt, 1) + np.sum(D * Xtt, 1)
            step = np.where(h > 1e-14, g / np.where(h > 1e-14, h, 1.0), g / np.maximum(np.sum(Xt * Xt, 1), 1e-14))
            step = np.clip(step, -0.2, 0.2)
            th[active] = ta - step
            active = active[np.abs(step) > 1e-13]
        return th

    def closest_parameters(self, p: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Parameters (θ, s) of the closest point of the band to each point (in Rust, on all threads).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 3)`` points.

        Returns
        -------
        theta : numpy.ndarray
            ``(M,)`` angles.
        s : numpy.ndarray
            ``(M,)`` offsets across the band.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.MobiusBand()
        >>> th, off = s.closest_parameters(np.array([[0.7, 0.0, 0.0]]))
        """
        x = np.ascontiguousarray(np.asarray(p, dtype=float).reshape(-1, 3))
        if not all(getattr(type(self), m) is getattr(MobiusBand, m) for m in _MOBIUS_NUMPY_METHODS):
            # a subclass changed the band or its projection: the NumPy route follows the change
            return self._closest_parameters_numpy(x)
        return _native.mobius_closest_parameters(x, self.R, self.w, self.newton_iterations)

    def _closest_parameters_numpy(self, p: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """The vectorised NumPy formulation of :meth:`closest_parameters` (the tests' reference)."""
        x = np.asarray(p, dtype=float).reshape(-1, 3)
        th0 = np.arctan2(x[:, 1], x[:, 0])
        best_th = np.empty(len(x))
        best_s = np.empty(len(x))
        best_d = np.full(len(x), np.inf)
        ti, si = self._interior(x, th0.copy())
        cands = [(ti, si, np.abs(si) <= self.w)]
        for sb in (-self.w, self.w):
            tb = self._boundary(x, th0.copy(), sb)
            cands.append((tb, np.full_like(tb, sb), np.ones(len(x), bool)))
        for th, s, ok in cands:
            d = np.linalg.norm(self.point(th, s) - x, axis=1)
            better = ok & (d < best_d)
            best_d = np.where(better, d, best_d)
            best_th = np.where(better, th, best_th)
            best_s = np.where(better, s, best_s)
        return best_th, best_s

    def _cp(self, p: np.ndarray) -> np.ndarray:
        th, s = self.closest_parameters(p)
        return self.point(th, s)

    @property
    def default_source(self) -> np.ndarray:
        return np.array([self.R, 0.0, 0.0])

    def triangulation(self, n: int = 48) -> Tuple[np.ndarray, np.ndarray]:
        """Parameter-grid triangulation (8n × n quads) with the half-twist seam merged: ``(V, F)``.

        Parameters
        ----------
        n : int
            Resolution (rings, sectors or polyline points; see the summary).

        Returns
        -------
        vertices : numpy.ndarray
            ``(V, d)`` points on the surface.
        faces : numpy.ndarray
            ``(F, 3)`` triangles (``(F, 2)`` segments for a curve).

        Raises
        ------
        ValueError
            If ``n`` is too small to make a mesh.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.MobiusBand()
        >>> v, f = s.triangulation()
        """
        th, s = np.meshgrid(np.linspace(0, 2 * np.pi, 8 * n + 1), np.linspace(-self.w, self.w, n + 1), indexing="ij")
        return grid_mesh(self.point(th, s))
