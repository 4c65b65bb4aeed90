"""Closed analytic surfaces beyond the sphere: ellipsoid, torus, rounded cube (sharp-ish
features) and a genus-2 double torus. Each is a :class:`tubesweep.LevelSet` whose φ is a signed
distance function (exact, or 1-Lipschitz with |∇φ| = 1 almost everywhere for the double torus)."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .. import _native
from .._linalg import row_norms
from ..surface import LevelSet
from ._triangulation import grid_mesh, marching_cubes
from .analytic import _points, finite_center, own_phi, size_parameter

__all__ = ["Ellipsoid", "Torus", "RoundedCube", "DoubleTorus"]

_CUBE = ((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))


class Ellipsoid(LevelSet):
    """Ellipsoid ``(x/a)² + (y/b)² + (z/c)² = 1`` about ``center``, as its exact signed distance.

    Parameters
    ----------
    a, b, c : float
        Semi-axes along x, y, z (defaults 0.6, 0.45, 0.3).
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    The closest point is ``y_i = a_i² x_i / (a_i² + t)`` with t the root in ``(−min a_i², ∞)`` of
    ``Σ (a_i x_i / (a_i² + t))² = 1``, a convex decreasing function of t: Newton's method from the
    left never passes the root. There is no closed-form geodesic distance on a triaxial ellipsoid,
    so this class has no ``geodesic_distance``.

    Examples
    --------
    >>> import tubesweep as ts
    >>> e = ts.surfaces.Ellipsoid(0.5, 0.5, 0.4)
    >>> sol = ts.solve(e, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [e.default_source])
    """

    default_box = _CUBE

    def __init__(self, a: float = 0.6, b: float = 0.45, c: float = 0.3, center: Sequence[float] = (0.0, 0.0, 0.0)):
        self.axes = np.array([size_parameter("a", a), size_parameter("b", b), size_parameter("c", c)])
        self.center = finite_center(center, 3)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 3

    def closest_point(self, p: np.ndarray) -> np.ndarray:
        """Exact closest point on the ellipsoid of each point of p (M, 3).

        Parameters
        ----------
        p : numpy.ndarray
            ``(M, 3)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, 3)`` closest points on the surface.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> s = ts.surfaces.Ellipsoid()
        >>> s.closest_point(np.array([[1.0, 0.0, 0.0]])).round(6).tolist()
        [[0.6, 0.0, 0.0]]
        """
        x = np.asarray(p, dtype=float).reshape(-1, 3) - self.center
        ax = self.axes
        a2 = ax * ax
        kmin = int(np.argmin(ax))
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            t = self._newton_root(x, ax, a2, kmin)
        den = a2 + t[:, None]
        y = np.empty_like(x)
        degenerate = den[:, kmin] <= 1e-12 * a2[kmin]
        nd = ~degenerate
        y[nd] = a2 * x[nd] / den[nd]
        if np.any(degenerate):
            # interior points on the plane x_kmin = 0 far from the surface: the closest point lies
            # above/below them along the shortest axis (t = −a_kmin²)
            xd = x[degenerate]
            others = [k for k in range(3) if k != kmin]
            yd = np.zeros_like(xd)
            for k in others:
                yd[:, k] = a2[k] * xd[:, k] / (a2[k] - a2[kmin]) if a2[k] > a2[kmin] else 0.0
            rest = 1.0 - sum((yd[:, k] / ax[k]) ** 2 for k in others)
            yd[:, kmin] = np.where(xd[:, kmin] >= 0, 1.0, -1.0) * ax[kmin] * np.sqrt(np.clip(rest, 0.0, None))
            y[degenerate] = yd
        return y + self.center

    @staticmethod
    def _newton_root(x: np.ndarray, ax: np.ndarray, a2: np.ndarray, kmin: int) -> np.ndarray:
        """The root ``t`` of ``F(t) = Σ (a_i x_i / (a_i² + t))² − 1`` for each point of ``x``
        (relative to the centre), or ``−a_kmin²`` where there is none above it: Newton's method
        from ``t₀ = max_i (a_i |x_i| − a_i²)``, where ``F ≥ 0`` (``F`` is convex and decreasing, so
        the steps move right and never pass the root), until ``F ≤ 0`` or a step no longer advances
        ``t``, at most 100 steps (the core's ``ELLIPSOID_NEWTON_STEPS``: keep the two equal); a term
        with ``x_i = 0``, or with ``a_i² + t`` exactly 0 (``t₀`` rounded onto the pole for
        ``|x_kmin|`` below about 1e-17), is 0. The arithmetic of the core's
        ``tubesweep_core::surface::analytic::ellipsoid_root``, operation for operation (the same bits)."""
        ax_x = ax * x
        t = np.maximum(np.max(ax * np.abs(x) - a2, axis=1), -a2[kmin])
        active = np.ones(len(x), dtype=bool)
        for _ in range(100):
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            ta = t[idx]
            den = a2 + ta[:, None]
            axa = ax_x[idx]
            # a term is 0 where x_i = 0 and where a_i² + t is exactly 0 (t₀ rounded onto the pole)
            live = (axa != 0.0) & (den != 0.0)
            r = np.where(live, axa / den, 0.0)
            q = r * r
            slope = np.where(live, q / den, 0.0)
            f = (q[:, 0] + q[:, 1]) + q[:, 2] - 1.0
            nxt = ta + f / (2.0 * ((slope[:, 0] + slope[:, 1]) + slope[:, 2]))
            advance = (f > 0.0) & (nxt > ta)
            t[idx[advance]] = nxt[advance]
            active[idx[~advance]] = False
        return t

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads, the arithmetic (and bits) of _signed_distance_numpy
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
        >>> s = ts.surfaces.Ellipsoid()
        >>> s.signed_distance(np.zeros((1, 3))).shape
        (1,)
        """
        return _native.ellipsoid_signed_distance(
            _points(p, 3), [float(c) for c in self.center], [float(a) for a in self.axes]
        )

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("ellipsoid", [*map(float, self.center), *map(float, self.axes)]) if own_phi(self, Ellipsoid) else None

    def _signed_distance_numpy(self, p: np.ndarray) -> np.ndarray:
        """The NumPy formulation of :meth:`signed_distance` (the reference the tests compare with)."""
        p = np.asarray(p, dtype=float)
        y = self.closest_point(p)
        dist = row_norms(p - y)
        inside = np.sum(((p - self.center) / self.axes) ** 2, axis=1) < 1.0
        return np.where(inside, -dist, dist)

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-self.axes[0], 0.0, 0.0])

    def triangulation(self, n: int = 64) -> Tuple[np.ndarray, np.ndarray]:
        """Latitude–longitude triangulation with about 2n² triangles: ``(V, F)``.

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
        >>> s = ts.surfaces.Ellipsoid()
        >>> v, f = s.triangulation()
        """
        th, ph = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, 2 * n + 1), indexing="ij")
        P = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1) * self.axes + self.center
        return grid_mesh(P)


class Torus(LevelSet):
    """Torus about the z axis: ``φ = sqrt((sqrt(x² + y²) − R)² + z²) − r``, the exact signed distance.

    Parameters
    ----------
    R : float
        Distance from the centre to the tube's centre circle (default 0.5).
    r : float
        Tube radius (default 0.2), ``0 < r < R``.
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    :meth:`geodesic_distance` is exact along the *outer equator* (the circle of radius R + r in the
    plane z = 0), which is a geodesic by the mirror symmetry z → −z. It is the shortest path between
    two of its points only while they are closer (along it) than the first conjugate point, at
    arclength ``π sqrt(r (R + r))`` (the Jacobi equation with Gaussian curvature
    ``K = 1 / (r (R + r))`` on the outer equator); beyond that, ``geodesic_distance`` returns NaN.
    Checked against exact polyhedral geodesics (pygeodesic, 12,800-vertex triangulation, defaults
    R = 0.5, r = 0.2): equal to within 2.4e-4 (the inscribed polygon's chord error) up to the conjugate
    arclength 1.175; beyond it shorter paths leave the equator (by 0.021 at arclength 1.32).

    Examples
    --------
    >>> import tubesweep as ts
    >>> t = ts.surfaces.Torus(0.5, 0.25)
    >>> sol = ts.solve(t, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [t.default_source])
    """

    default_box = _CUBE

    def __init__(self, R: float = 0.5, r: float = 0.2, center: Sequence[float] = (0.0, 0.0, 0.0)):
        R, r = size_parameter("R", R), size_parameter("r", r)
        if not (R > r > 0):
            raise ValueError(f"need R > r > 0 (a ring torus); got R={R}, r={r}")
        self.R = float(R)
        self.r = float(r)
        self.center = finite_center(center, 3)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 3

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads: hypot(hypot(q_x, q_y) − R, q_z) − r with q = p − center
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
        >>> s = ts.surfaces.Torus()
        >>> s.signed_distance(np.zeros((1, 3))).shape
        (1,)
        """
        return _native.torus_signed_distance(_points(p, 3), [float(c) for c in self.center], self.R, self.r)

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("torus", [*map(float, self.center), self.R, self.r]) if own_phi(self, Torus) else None

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([self.R + self.r, 0.0, 0.0])

    @property
    def conjugate_arclength(self) -> float:
        """Arclength along the outer equator to the first conjugate point, ``π sqrt(r (R + r))``."""
        return float(np.pi * np.sqrt(self.r * (self.R + self.r)))

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Exact distance between points on (or near) the outer equator and a source on it: the arclength ``(R + r)·|Δθ|`` of the azimuth difference; NaN for points that are not on the outer equator (more than 1e-6 off it) or farther than :attr:`conjugate_arclength`.

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
        >>> s = ts.surfaces.Torus()
        >>> d = s.geodesic_distance(np.atleast_2d(s.default_source), s.default_source)
        """
        q = np.asarray(points, dtype=float).reshape(-1, 3) - self.center
        s = np.asarray(source, dtype=float).reshape(3) - self.center
        Ro = self.R + self.r
        tol = 1e-6 * Ro
        if abs(s[2]) > tol or abs(np.hypot(s[0], s[1]) - Ro) > tol:
            raise ValueError(
                f"source {tuple(s + self.center)} is not on the outer equator (radius R + r = {Ro}, z = 0)"
            )
        on = (np.abs(q[:, 2]) <= tol) & (np.abs(np.hypot(q[:, 0], q[:, 1]) - Ro) <= tol)
        dth = np.abs(np.angle(np.exp(1j * (np.arctan2(q[:, 1], q[:, 0]) - np.arctan2(s[1], s[0])))))
        d = Ro * dth
        return np.where(on & (d <= self.conjugate_arclength), d, np.nan)

    def triangulation(self, n: int = 48) -> Tuple[np.ndarray, np.ndarray]:
        """Parameter-grid triangulation (4n × 2n quads): ``(V, F)``.

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
        >>> s = ts.surfaces.Torus()
        >>> v, f = s.triangulation()
        """
        th, ps = np.meshgrid(np.linspace(0, 2 * np.pi, 4 * n + 1), np.linspace(0, 2 * np.pi, 2 * n + 1), indexing="ij")
        rho = self.R + self.r * np.cos(ps)
        P = np.stack([rho * np.cos(th), rho * np.sin(th), self.r * np.sin(ps)], -1) + self.center
        return grid_mesh(P)


class RoundedCube(LevelSet):
    """Cube of half-side ``half_size`` with edges and corners rounded to ``radius``.

    Parameters
    ----------
    half_size : float
        Half the side (default 0.5).
    radius : float
        Rounding radius (default 0.1), ``0 < radius ≤ half_size``.
    center : sequence of float
        The centre, 3 coordinates.

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    A surface with sharp-ish features (curvature 1/radius along the edges, flat faces). φ is the
    exact signed distance ``|max(q, 0)| + min(max_k q_k, 0) − radius`` with
    ``q = |x − c| − (half_size − radius)`` componentwise. No closed-form geodesic distance.

    Examples
    --------
    >>> import tubesweep as ts
    >>> cube = ts.surfaces.RoundedCube()
    >>> sol = ts.solve(cube, ts.Grid((-1, -1, -1), (1, 1, 1), (81, 81, 81)), [cube.default_source])
    >>> sol.stats.order  # the edges' radius 0.1 is 4 spacings: second order (at N = 61, first order and 11% short)
    2
    """

    default_box = _CUBE

    def __init__(self, half_size: float = 0.5, radius: float = 0.1, center: Sequence[float] = (0.0, 0.0, 0.0)):
        half_size, radius = size_parameter("half_size", half_size), size_parameter("radius", radius)
        if not (0 < radius <= half_size):
            raise ValueError(f"need 0 < radius <= half_size; got radius={radius}, half_size={half_size}")
        self.half_size = float(half_size)
        self.radius = float(radius)
        self.center = finite_center(center, 3)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 3

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads, the arithmetic (and bits) of _signed_distance_numpy
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
        >>> s = ts.surfaces.RoundedCube()
        >>> s.signed_distance(np.zeros((1, 3))).shape
        (1,)
        """
        return _native.rounded_cube_signed_distance(
            _points(p, 3), [float(c) for c in self.center], self.half_size, self.radius
        )

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return (
            ("rounded-cube", [*map(float, self.center), self.half_size, self.radius])
            if own_phi(self, RoundedCube)
            else None
        )

    def _signed_distance_numpy(self, p: np.ndarray) -> np.ndarray:
        """The NumPy formulation of :meth:`signed_distance` (the reference the tests compare with)."""
        q = np.abs(np.asarray(p, dtype=float) - self.center) - (self.half_size - self.radius)
        return row_norms(np.maximum(q, 0.0)) + np.minimum(np.max(q, axis=1), 0.0) - self.radius

    @property
    def default_source(self) -> np.ndarray:
        return self.center + np.array([-self.half_size, 0.0, 0.0])

    def triangulation(self, n: int = 96) -> Tuple[np.ndarray, np.ndarray]:
        """Marching cubes of φ on an n³ grid over the bounding box (needs scikit-image).

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
        >>> s = ts.surfaces.RoundedCube()
        >>> v, f = s.triangulation()
        """
        e = self.half_size * 1.1
        return marching_cubes(self.signed_distance, (self.center - e, self.center + e), n)


class DoubleTorus(LevelSet):
    """A genus-2 surface: the union of two ring tori about the z axis centred at ``(±offset, 0, 0)``.

    Parameters
    ----------
    R, r : float
        Centre-circle and tube radii of each torus (defaults 0.35, 0.12).
    offset : float
        Half the distance between the two torus centres (default 0.36, so the tubes overlap).

    Raises
    ------
    ValueError
        If a size is not positive and finite (or the sizes are inconsistent, e.g. a tube radius not
        below the centre-circle radius), or the centre is not finite.

    Notes
    -----
    φ = min(φ₁, φ₂) of the two exact torus distances. It is the exact signed distance outside the
    solid; inside, near the two creases where the tori meet, ``|φ|`` may under-estimate the distance
    (φ stays 1-Lipschitz with ``|∇φ| = 1`` almost everywhere, which is all the method needs). The
    creases are sharp features: geodesics bend over them.

    Examples
    --------
    >>> import tubesweep as ts
    >>> dt = ts.surfaces.DoubleTorus()
    >>> sol = ts.solve(dt, ts.Grid((-1, -1, -1), (1, 1, 1), (81, 81, 81)), [dt.default_source])  # doctest: +SKIP
    """

    default_box = _CUBE

    def __init__(self, R: float = 0.35, r: float = 0.12, offset: float = 0.36):
        R, r, offset = size_parameter("R", R), size_parameter("r", r), size_parameter("offset", offset)
        if not (R > r > 0):
            raise ValueError(f"need R > r > 0; got R={R}, r={r}")
        if not (offset > 0 and 2 * offset < 2 * (R + r) and offset > R - r):
            raise ValueError("offset must make the two tubes overlap in one region each side: R − r < offset < R + r")
        self.R, self.r, self.offset = float(R), float(r), float(offset)
        super().__init__(self.signed_distance, lipschitz=1.0)
        self.ndim = 3

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        # in Rust on all threads, the arithmetic (and bits) of _signed_distance_numpy
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
        >>> s = ts.surfaces.DoubleTorus()
        >>> s.signed_distance(np.zeros((1, 3))).shape
        (1,)
        """
        return _native.double_torus_signed_distance(_points(p, 3), self.R, self.r, self.offset)

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        return ("double-torus", [self.R, self.r, self.offset]) if own_phi(self, DoubleTorus) else None

    def _signed_distance_numpy(self, p: np.ndarray) -> np.ndarray:
        """The NumPy formulation of :meth:`signed_distance` (the reference the tests compare with)."""
        p = np.asarray(p, dtype=float)
        out: Any = None
        for cx in (-self.offset, self.offset):
            phi = np.hypot(np.hypot(p[:, 0] - cx, p[:, 1]) - self.R, p[:, 2]) - self.r
            out = phi if out is None else np.minimum(out, phi)
        return out

    @property
    def default_source(self) -> np.ndarray:
        return np.array([-(self.offset + self.R + self.r), 0.0, 0.0])

    def _check_distance_like(self, lo: float, hi: float, outer: float) -> None:
        # φ is 1-Lipschitz with |∇φ| = 1 a.e. by construction; central differences straddling a
        # crease (where the min switches torus) shorten the gradient to ≈ 0.5 there, which the
        # generic near-distance check would report. Nothing to check.
        return None

    def triangulation(self, n: int = 128) -> Tuple[np.ndarray, np.ndarray]:
        """Marching cubes of φ on an n³ grid over the bounding box (needs scikit-image).

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
        >>> s = ts.surfaces.DoubleTorus()
        >>> v, f = s.triangulation()
        """
        ex = self.offset + self.R + self.r + 0.05
        return marching_cubes(self.signed_distance, ((-ex, -ex, -ex), (ex, ex, ex)), n)
