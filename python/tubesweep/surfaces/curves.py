"""Analytic curves in the plane beyond the circle and the star: the ellipse."""

from __future__ import annotations

from typing import Sequence, Tuple

import numpy as np

from .._linalg import row_norms
from ..surface import LevelSet
from ._triangulation import polyline
from .analytic import finite_center, size_parameter

__all__ = ["Ellipse"]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)


class Ellipse(LevelSet):
    """Ellipse ``(x/a)² + (y/b)² = 1`` about ``center``, as its exact signed distance function.

    Parameters
    ----------
    a, b : float
        Semi-axes along x and y (defaults 0.6 and 0.35).
    center : sequence of float
        The centre, 2 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    φ is the exact signed distance (negative inside): the closest point ``γ(t) = (a cos t, b sin t)``
    is found by sampling t and refining with Newton's method on ``(γ(t) − x)·γ'(t) = 0``.
    :meth:`geodesic_distance` is the exact arclength along the ellipse (Gauss–Legendre quadrature of
    the elliptic integral), the shorter way round.

    Examples
    --------
    >>> import tubesweep as ts
    >>> e = ts.surfaces.Ellipse()
    >>> sol = ts.solve(e, ts.Grid((-1, -1), (1, 1), (201, 201)), [e.default_source])
    """

    default_box = ((-1.0, -1.0), (1.0, 1.0))

    def __init__(self, a: float = 0.6, b: float = 0.35, center: Sequence[float] = (0.0, 0.0)):
        a, b = size_parameter("a", a), size_parameter("b", b)
        self.a = float(a)
        self.b = float(b)
        self.center = finite_center(center, 2)
        self._t0 = np.linspace(0.0, 2 * np.pi, 64, endpoint=False)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 2

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
        >>> s = ts.surfaces.Ellipse()
        >>> s.curve(np.array([0.0])).shape
        (1, 2)
        """
        t = np.asarray(t, dtype=float)
        return self.center + np.stack([self.a * np.cos(t), self.b * np.sin(t)], axis=-1)

    def closest_parameter(self, p: np.ndarray) -> np.ndarray:
        """Parameter t of the closest point γ(t) to each point of p (M, 2).

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
        >>> s = ts.surfaces.Ellipse()
        >>> t = s.closest_parameter(np.array([[1.0, 0.0]]))
        """
        q = np.asarray(p, dtype=float).reshape(-1, 2) - self.center
        a, b = self.a, self.b
        out = np.empty(len(q))
        samp = np.stack([a * np.cos(self._t0), b * np.sin(self._t0)], 1)
        for s in range(0, len(q), 8192):
            x = q[s : s + 8192, 0]
            y = q[s : s + 8192, 1]
            d2 = (x[:, None] - samp[None, :, 0]) ** 2 + (y[:, None] - samp[None, :, 1]) ** 2
            t = self._t0[np.argmin(d2, axis=1)]
            for _ in range(30):
                st, ct = np.sin(t), np.cos(t)
                g = (b * b - a * a) * st * ct + a * x * st - b * y * ct
                gp = (b * b - a * a) * (ct * ct - st * st) + a * x * ct + b * y * st
                step = np.where(gp > 1e-14, g / np.where(gp > 1e-14, gp, 1.0), 0.0)
                t = t - np.clip(step, -0.05, 0.05)
            out[s : s + 8192] = t
        return out

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
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
        >>> s = ts.surfaces.Ellipse()
        >>> s.signed_distance(np.zeros((1, 2))).shape
        (1,)
        """
        p = np.asarray(p, dtype=float)
        t = self.closest_parameter(p)
        dist = row_norms(p - self.curve(t))
        q = p - self.center
        inside = (q[:, 0] / self.a) ** 2 + (q[:, 1] / self.b) ** 2 < 1.0
        return np.where(inside, -dist, dist)

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([self.a, 0.0])

    def arclength(self, t: np.ndarray) -> np.ndarray:
        """Arclength from parameter 0 to t (0 ≤ t ≤ 2π), 8 × 24-point Gauss–Legendre panels.

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
        >>> s = ts.surfaces.Ellipse()
        >>> float(s.arclength(np.array([2 * np.pi]))[0]) > 0
        True
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        edges = np.linspace(0.0, 1.0, 9)
        total = np.zeros_like(t)
        for lo, hi in zip(edges[:-1], edges[1:]):
            s = (0.5 * (hi - lo) * _GL_X + 0.5 * (hi + lo))[None, :] * t[:, None]
            speed = np.sqrt((self.a * np.sin(s)) ** 2 + (self.b * np.cos(s)) ** 2)
            total += 0.5 * (hi - lo) * t * (speed @ _GL_W)
        return total

    @property
    def perimeter(self) -> float:
        return float(self.arclength(np.array([2 * np.pi]))[0])

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Exact arclength (the shorter way round) between the closest points of ``points`` and ``source``.

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
        >>> s = ts.surfaces.Ellipse()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        t = np.mod(self.closest_parameter(points), 2 * np.pi)
        ts = np.mod(self.closest_parameter(np.asarray(source, dtype=float).reshape(1, 2)), 2 * np.pi)
        d = np.abs(self.arclength(t) - self.arclength(ts)[0])
        return np.minimum(d, self.perimeter - d)

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
        >>> s = ts.surfaces.Ellipse()
        >>> s.sample(10).shape
        (10, 2)
        """
        return self.curve(np.linspace(0, 2 * np.pi, n, endpoint=False))

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
        >>> s = ts.surfaces.Ellipse()
        >>> v, f = s.triangulation()
        """
        return polyline(self.sample(n))
