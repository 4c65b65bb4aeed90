"""Analytic curves (2D) and surfaces (3D) given by exact signed distance functions."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .. import _native
from .._linalg import row_norms
from ..surface import LevelSet
from .._validate import real_scalar
from ._triangulation import grid_mesh, polyline

__all__ = ["Circle", "Sphere", "Star"]


def own_phi(surface: Any, cls: type) -> bool:
    """Whether ``surface``'s φ is ``cls.signed_distance`` itself (not replaced or overridden by a
    subclass), so that the core may evaluate it without calling back into Python."""
    return type(surface).signed_distance is getattr(cls, "signed_distance") and surface._fn == surface.signed_distance


def size_parameter(name: str, value: Any) -> float:
    """A surface's length (radius, semi-axis, half-size): a positive finite real number. A bool,
    a string or a complex number is a TypeError, a non-positive or non-finite one a ValueError,
    each naming the parameter."""
    v = real_scalar(value, name, "a positive real number (a length in the grid's units)")
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be positive and finite; got {value!r}")
    return v


def finite_center(center: Any, d: int) -> np.ndarray:
    """A surface's ``center``: ``d`` finite coordinates, or a ValueError that says so."""
    try:
        c = np.asarray(center, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        c = np.array([np.nan])
    if c.shape != (d,) or not np.all(np.isfinite(c)):
        raise ValueError(f"center must be {d} finite coordinates; got {center!r}")
    return c


def _points(p: np.ndarray, d: int) -> np.ndarray:
    """``p`` as the C-ordered (M, d) float64 array the native distances read."""
    p = np.ascontiguousarray(p, dtype=float)
    if p.ndim != 2 or p.shape[1] != d:
        raise ValueError(f"points must have shape (M, {d}); got {p.shape}")
    return p


class Circle(LevelSet):
    """Circle of ``radius`` about ``center``: φ = |x − c| − r, the exact signed distance.

    Parameters
    ----------
    radius : float
        The radius (default 0.5).
    center : sequence of float
        The centre, 2 coordinates (default the origin).

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Examples
    --------
    >>> import tubesweep as ts
    >>> c = ts.surfaces.Circle(0.5)
    >>> sol = ts.solve(c, ts.Grid((-1, -1), (1, 1), (101, 101)), [c.default_source])
    """

    default_box = ((-1.0, -1.0), (1.0, 1.0))

    def __init__(self, radius: float = 0.5, center: Sequence[float] = (0.0, 0.0)):
        self.radius = size_parameter("radius", radius)
        self.center = finite_center(center, 2)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 2

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads, with the arithmetic of row_norms(p - center) - radius
        """The exact signed distance of points to the surface (negative inside).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 2)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` signed distances (negative inside).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Circle(0.5)
        >>> s.signed_distance(np.zeros((1, 2))).shape
        (1,)
        """
        return _native.sphere_signed_distance(_points(p, self.ndim), [float(c) for c in self.center], self.radius)  # type: ignore[arg-type]

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("sphere", [*map(float, self.center), self.radius]) if own_phi(self, Circle) else None

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-self.radius, 0.0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Exact arclength on the circle between the projections of ``points`` and ``source``.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 2)`` points on (or near) the surface.
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
        >>> s = ts.surfaces.Circle(0.5)
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        a = np.arctan2(*(np.asarray(points) - self.center).T[::-1])
        s = np.asarray(source, dtype=float) - self.center
        b = np.arctan2(s[1], s[0])
        return self.radius * np.abs(np.angle(np.exp(1j * (a - b))))

    def sample(self, n: int = 1000) -> np.ndarray:
        """Points spread over the curve.

        Parameters
        ----------
        n : int
            How many points.

        Returns
        -------
        numpy.ndarray
            ``(n, 2)`` points on the curve.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Circle(0.5)
        >>> s.sample(10).shape
        (10, 2)
        """
        t = np.linspace(0, 2 * np.pi, n, endpoint=False)
        return self.center + self.radius * np.stack([np.cos(t), np.sin(t)], axis=1)

    def triangulation(self, n: int = 400) -> Tuple[np.ndarray, np.ndarray]:
        """The curve as a closed polyline: vertices (n, 2) and segments (n, 2).

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
        >>> s = ts.surfaces.Circle(0.5)
        >>> v, f = s.triangulation()
        """
        return polyline(self.sample(n))


class Sphere(LevelSet):
    """Sphere of ``radius`` about ``center``: φ = |x − c| − r, the exact signed distance.

    Parameters
    ----------
    radius : float
        The radius (default 0.5).
    center : sequence of float
        The centre, 3 coordinates (default the origin).

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [s.default_source])
    """

    default_box = ((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))

    def __init__(self, radius: float = 0.5, center: Sequence[float] = (0.0, 0.0, 0.0)):
        self.radius = size_parameter("radius", radius)
        self.center = finite_center(center, 3)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 3

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads, with the arithmetic of row_norms(p - center) - radius
        """The exact signed distance of points to the surface (negative inside).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 3)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` signed distances (negative inside).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> s.signed_distance(np.zeros((1, 3))).shape
        (1,)
        """
        return _native.sphere_signed_distance(_points(p, self.ndim), [float(c) for c in self.center], self.radius)  # type: ignore[arg-type]

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("sphere", [*map(float, self.center), self.radius]) if own_phi(self, Sphere) else None

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-self.radius, 0.0, 0.0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Great-circle distance between the radial projections of ``points`` and ``source``.

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
        >>> s = ts.surfaces.Sphere(0.5)
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        a = np.asarray(points, dtype=float) - self.center
        a = a / np.linalg.norm(a, axis=1, keepdims=True)
        b = np.asarray(source, dtype=float) - self.center
        b = b / np.linalg.norm(b)
        return self.radius * np.arccos(np.clip(a @ b, -1.0, 1.0))

    def triangulation(self, n: int = 64) -> Tuple[np.ndarray, np.ndarray]:
        """Latitude–longitude triangulation (n rings, 2n sectors, poles merged): ``(V, F)``.

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
        >>> s = ts.surfaces.Sphere(0.5)
        >>> v, f = s.triangulation()
        """
        th, ph = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, 2 * n + 1), indexing="ij")
        P = self.radius * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1) + self.center
        return grid_mesh(P)


class Star(LevelSet):
    """The six-fold star of the paper's Sect. 6.1: r(θ) = r0 + ε sin²(3θ).

    Parameters
    ----------
    r0 : float
        The smallest radius (default 0.5).
    eps : float
        The depth of the lobes (default 0.2).
    exact : bool
        True (default): φ is the exact signed distance to the curve (a projection onto a dense
        sampling of the curve refined by Newton's method). False: φ = |x| − r(θ), the simple level
        set, only roughly a distance (|∇φ| up to ≈ 1.6).

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    The paper prints ``sin²(3πθ)``, a misprint: with θ the polar angle, six-fold symmetry and
    r = 0.5 at the source (0.5, 0) need ``sin²(3θ)``.

    Examples
    --------
    >>> import tubesweep as ts
    >>> star = ts.surfaces.Star()
    >>> sol = ts.solve(star, ts.Grid((-1, -1), (1, 1), (201, 201)), [star.default_source])
    """

    default_box = ((-1.0, -1.0), (1.0, 1.0))

    def __init__(self, r0: float = 0.5, eps: float = 0.2, *, exact: bool = True):
        self.r0 = size_parameter("r0", r0)
        try:
            self.eps = real_scalar(eps, "eps")
        except TypeError:
            self.eps = float("nan")  # refused below, as a ValueError like a negative amplitude
        if not (np.isfinite(self.eps) and self.eps >= 0):
            raise ValueError(f"eps must be a finite real number >= 0 (the star's amplitude); got {eps!r}")
        self.exact = bool(exact)
        if not (self.r0 > self.eps >= 0 or (self.r0 > 0 and self.eps >= 0)):
            raise ValueError("need r0 > 0 and eps >= 0")
        self._dense_t = np.linspace(0.0, 2 * np.pi, 4097)[:-1]
        self._dense_xy = self.curve(self._dense_t)
        self._cum = None
        super().__init__(self.signed_distance if exact else self.simple_phi, lipschitz=1.0 if exact else 2.0)
        self.ndim = 2

    # --- geometry ---------------------------------------------------------------------------
    def r(self, t: np.ndarray) -> np.ndarray:
        """The radius r(θ) = r0 + ε sin²(3θ).

        Parameters
        ----------
        t : numpy.ndarray
            Polar angles θ.

        Returns
        -------
        numpy.ndarray
            The values at each θ.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.r(np.array([0.0])).shape
        (1,)
        """
        return self.r0 + self.eps * np.sin(3 * t) ** 2

    def dr(self, t: np.ndarray) -> np.ndarray:
        """The derivative r'(θ).

        Parameters
        ----------
        t : numpy.ndarray
            Polar angles θ.

        Returns
        -------
        numpy.ndarray
            The values at each θ.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.dr(np.array([0.0])).shape
        (1,)
        """
        return 3 * self.eps * np.sin(6 * t)

    def d2r(self, t: np.ndarray) -> np.ndarray:
        """The second derivative r''(θ).

        Parameters
        ----------
        t : numpy.ndarray
            Polar angles θ.

        Returns
        -------
        numpy.ndarray
            The values at each θ.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.d2r(np.array([0.0])).shape
        (1,)
        """
        return 18 * self.eps * np.cos(6 * t)

    def curve(self, t: np.ndarray) -> np.ndarray:
        """The curve's point at each parameter.

        Parameters
        ----------
        t : numpy.ndarray
            ``(M,)`` parameters (the polar angle θ for the star).

        Returns
        -------
        numpy.ndarray
            ``(M, 2)`` points.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.curve(np.array([0.0])).shape
        (1, 2)
        """
        r = self.r(t)
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=-1)

    def speed(self, t: np.ndarray) -> np.ndarray:
        """The speed of the parametrisation |γ'(θ)| = sqrt(r² + r'²).

        Parameters
        ----------
        t : numpy.ndarray
            Polar angles θ.

        Returns
        -------
        numpy.ndarray
            The values at each θ.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.speed(np.array([0.0])).shape
        (1,)
        """
        return np.sqrt(self.r(t) ** 2 + self.dr(t) ** 2)

    @property
    def default_source(self) -> np.ndarray:
        return np.array([self.r(np.array(0.0)) * 1.0, 0.0])

    def simple_phi(self, p: np.ndarray) -> np.ndarray:
        """The simple level set φ = |x| − r(θ) (only roughly a distance).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 2)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.simple_phi(np.array([[0.5, 0.0]])).tolist()
        [0.0]
        """
        p = np.asarray(p, dtype=float)
        return np.hypot(p[:, 0], p[:, 1]) - self.r(np.arctan2(p[:, 1], p[:, 0]))

    def closest_parameter(self, p: np.ndarray) -> np.ndarray:
        """Polar angle θ of the closest point on the curve to each point of p (M, 2).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 2)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` curve parameters of the closest points.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> t = s.closest_parameter(np.array([[1.0, 0.0]]))
        """
        p = np.asarray(p, dtype=float)
        out = np.empty(len(p))
        # Points with |simple φ| ≤ 0.2 are within 0.2 of the curve, so their closest point is
        # within asin(0.2 / r0) of their polar angle: search a window there; search the whole
        # curve for the (few) others.
        polar = np.arctan2(p[:, 1], p[:, 0])
        near = np.abs(self.simple_phi(p)) <= min(0.2, 0.9 * self.r0)
        window = np.linspace(-0.8, 0.8, 129)
        for s in range(0, len(p), 4096):
            q = p[s : s + 4096]
            nq = near[s : s + 4096]
            t = np.empty(len(q))
            if np.any(nq):
                cand = polar[s : s + 4096][nq][:, None] + window[None, :]
                d2 = ((self.curve(cand) - q[nq][:, None, :]) ** 2).sum(-1)
                t[nq] = cand[np.arange(len(cand)), np.argmin(d2, axis=1)]
            if np.any(~nq):
                d2 = ((q[~nq][:, None, :] - self._dense_xy[None, :, :]) ** 2).sum(-1)
                t[~nq] = self._dense_t[np.argmin(d2, axis=1)]
            for _ in range(8):  # Newton on g(t) = (γ(t) − q)·γ'(t) = 0
                r, dr, d2r = self.r(t), self.dr(t), self.d2r(t)
                c, si = np.cos(t), np.sin(t)
                g1 = np.stack([dr * c - r * si, dr * si + r * c], -1)
                g2 = np.stack([d2r * c - 2 * dr * si - r * c, d2r * si + 2 * dr * c - r * si], -1)
                diff = np.stack([r * c, r * si], -1) - q
                f = (diff * g1).sum(-1)
                fp = (g1 * g1).sum(-1) + (diff * g2).sum(-1)
                step = np.where(np.abs(fp) > 1e-14, f / np.where(np.abs(fp) > 1e-14, fp, 1.0), 0.0)
                t = t - np.clip(step, -0.01, 0.01)
            out[s : s + 4096] = t
        return out

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads: the algorithm of _signed_distance_numpy (equal to rounding)
        """The exact signed distance of points to the surface (negative inside).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 2)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` signed distances (negative inside).

        Raises
        ------
        ValueError
            If the points do not have the surface's dimension.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.signed_distance(np.zeros((1, 2))).shape
        (1,)
        """
        return _native.star_signed_distance(_points(p, 2), self.r0, self.eps)

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("star", [self.r0, self.eps]) if own_phi(self, Star) else None

    def _signed_distance_numpy(self, p: np.ndarray) -> np.ndarray:
        """The NumPy formulation of :meth:`signed_distance` (the reference the tests compare with)."""
        p = np.asarray(p, dtype=float)
        t = self.closest_parameter(p)
        dist = row_norms(p - self.curve(t))
        inside = np.hypot(p[:, 0], p[:, 1]) < self.r(np.arctan2(p[:, 1], p[:, 0]))
        return np.where(inside, -dist, dist)

    # --- exact geodesic distance --------------------------------------------------------------
    def arclength(self, t: np.ndarray) -> np.ndarray:
        """Arclength from θ = 0 to θ = t (t in [0, 2π]), by composite Gauss–Legendre quadrature.

        Parameters
        ----------
        t : numpy.ndarray
            Curve parameters in [0, 2π].

        Returns
        -------
        numpy.ndarray
            Arclengths from parameter 0 to each ``t``.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> float(s.arclength(np.array([2 * np.pi]))[0]) > 0
        True
        """
        t = np.asarray(t, dtype=float)
        # each 1/12 turn between extrema of r is smooth: integrate piecewise with 20-point GL
        xg, wg = np.polynomial.legendre.leggauss(20)
        edges = np.linspace(0, 2 * np.pi, 13)
        seg_len = np.array(
            [
                0.5 * (b - a) * np.sum(wg * self.speed(0.5 * (b - a) * xg + 0.5 * (a + b)))
                for a, b in zip(edges[:-1], edges[1:])
            ]
        )
        cum = np.concatenate([[0.0], np.cumsum(seg_len)])
        k = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, 11)
        a = edges[k]
        part = np.array(
            [
                0.5 * (tt - aa) * np.sum(wg * self.speed(0.5 * (tt - aa) * xg + 0.5 * (aa + tt)))
                for tt, aa in zip(t.reshape(-1), a.reshape(-1))
            ]
        )
        return (cum[k].reshape(-1) + part).reshape(t.shape)

    @property
    def perimeter(self) -> float:
        return float(self.arclength(np.array([2 * np.pi]))[0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float] = (0.5, 0.0)) -> np.ndarray:
        """Exact arclength (the shorter way round) between the closest curve points of ``points`` and ``source``.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 2)`` points on (or near) the surface.
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
        >>> s = ts.surfaces.Star()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        t = np.mod(self.closest_parameter(np.asarray(points, dtype=float)), 2 * np.pi)
        ts = np.mod(self.closest_parameter(np.asarray(source, dtype=float).reshape(1, 2))[0], 2 * np.pi)
        L = self.perimeter
        d = np.abs(self.arclength(t) - self.arclength(np.array([ts]))[0])
        return np.minimum(d, L - d)

    def sample(self, n: int = 2000) -> np.ndarray:
        """Points spread over the curve.

        Parameters
        ----------
        n : int
            How many points.

        Returns
        -------
        numpy.ndarray
            ``(n, 2)`` points on the curve.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Star()
        >>> s.sample(10).shape
        (10, 2)
        """
        return self.curve(np.linspace(0, 2 * np.pi, n, endpoint=False))

    def triangulation(self, n: int = 600) -> Tuple[np.ndarray, np.ndarray]:
        """The curve as a closed polyline: vertices (n, 2) and segments (n, 2).

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
        >>> s = ts.surfaces.Star()
        >>> v, f = s.triangulation()
        """
        return polyline(self.sample(n))
