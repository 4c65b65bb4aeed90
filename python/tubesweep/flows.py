"""Ambient flows ``v(x)`` for the moving-medium eikonal equation ``|∇u| = |1 − v·∇u| / F``
(paper Sect. 6.3). Each factory returns a vectorised callable ``v(points (M, d)) -> (M, d)`` that
can be passed as ``ts.solve(..., flow=v)``.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ._validate import real_array

__all__ = [
    "point_vortices",
    "solid_body_rotation",
    "rotation_travel_time_circle",
    "rotation_travel_time_sphere",
    "Flow",
]

Flow = Callable[[np.ndarray], np.ndarray]


def point_vortices(centers: Any, strengths: Any, *, core: float = 0.0) -> Flow:
    """The N-point vortex flow on a sphere centred at the origin (paper Sect. 6.3, after Newton 2001).

    ``v(x) = (1/2π) Σ_j s_j (x_j × x) / |x_j − x|² · (1 − exp(−|x_j − x|²/δ²))``. ``x_j × x`` is
    orthogonal to ``x``, so the flow is tangent to every sphere about the origin.

    Parameters
    ----------
    centers : array_like
        ``(N, 3)`` vortex centres on the sphere.
    strengths : array_like or float
        ``(N,)`` vortex strengths ``s_j`` (positive: counter-clockwise about ``x_j``).
    core : float
        Vortex core radius δ ≥ 0 (a Lamb–Oseen core; 0, the default, is the singular flow of the
        paper).

    Returns
    -------
    Flow
        A callable ``v(points (M, 3)) -> (M, 3)`` for ``ts.solve(..., flow=v)``.

    Raises
    ------
    ValueError
        If the centres are not ``(N, 3)`` finite points, the strengths do not match them, or
        ``core`` is negative.

    Notes
    -----
    One vortex alone moves points on circles about ``x_j`` at speed ``|v| = (s/4π) cot(θ/2)``
    (θ the angle from ``x_j``) for δ = 0: unbounded near the centre. With F = 3 and s = 4
    (Figs. 10–11) ``|v| ≥ F`` within an angle θ ≈ 0.21 of each centre, so the paper's figures need
    ``allow_supersonic=True``. A core δ keeps a single vortex below ``≈ 0.638·|s|R/(2πδ)``. At
    ``x = x_j`` the term is taken as 0.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> v = ts.flows.point_vortices([[0, 0, 0.5], [0.5, 0, 0]], [4.0, -4.0], core=0.1)
    >>> v(np.array([[0.0, 0.5, 0.0]])).shape
    (1, 3)
    """
    c = real_array(centers, "centers")
    if c.ndim == 1:
        c = c.reshape(1, -1)
    if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] == 0:
        raise ValueError(
            f"centers must have shape (N, 3) (point vortices live on a sphere in 3D); got {np.shape(centers)}"
        )
    given = real_array(strengths, "strengths")
    # (one per vortex or one for all: [1, 2] for one vortex raised numpy's broadcast error)
    s = np.broadcast_to(given, (c.shape[0],)).copy() if given.ndim == 0 or given.shape == (c.shape[0],) else None
    if s is None or not np.all(np.isfinite(s)):
        raise ValueError(
            f"strengths must be a number or one finite number per vortex ({c.shape[0]}); got {strengths!r}"
        )
    if not (np.isfinite(core) and core >= 0):
        raise ValueError(f"core must be a non-negative vortex core radius; got {core!r}")
    delta2 = float(core) ** 2

    def flow(points: np.ndarray) -> np.ndarray:
        x = np.asarray(points, dtype=float)
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"point_vortices flow is defined for points of shape (M, 3); got {x.shape}")
        v = np.zeros_like(x)
        for xj, sj in zip(c, s):
            r2 = np.sum((x - xj) ** 2, axis=1)
            safe = np.where(r2 > 1e-300, r2, 1.0)
            w = np.where(r2 > 1e-300, sj / (2 * np.pi) / safe, 0.0)
            if delta2 > 0:
                w = w * -np.expm1(-r2 / delta2)
            v += w[:, None] * np.cross(xj, x)
        return v

    flow.centers = c  # type: ignore[attr-defined]
    flow.strengths = s  # type: ignore[attr-defined]
    flow.core = float(core)  # type: ignore[attr-defined]
    return flow


def solid_body_rotation(
    omega: float, axis: Sequence[float] = (0.0, 0.0, 1.0), center: Sequence[float] | None = None
) -> Flow:
    """Rigid rotation of the medium with angular speed ``omega`` about ``axis`` through ``center``.

    ``v(x) = ω â × (x − c)`` in 3D and ``v(x) = ω (−(y − c_y), x − c_x)`` in 2D (``axis`` ignored).
    It is tangent to every sphere or circle about ``c``, and has an exact moving-medium solution on
    both (:func:`rotation_travel_time_sphere`, :func:`rotation_travel_time_circle`).

    Parameters
    ----------
    omega : float
        Angular speed (positive: counter-clockwise about ``axis``).
    axis : sequence of float
        The rotation axis in 3D (default z).
    center : sequence of float, optional
        A point on the axis (default the origin).

    Returns
    -------
    Flow
        A callable ``v(points (M, d)) -> (M, d)``.

    Raises
    ------
    ValueError
        If ``omega`` is not finite or the axis is zero.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> v = ts.flows.solid_body_rotation(2.0)
    >>> v(np.array([[1.0, 0.0, 0.0]])).tolist()
    [[0.0, 2.0, 0.0]]
    """
    if not np.isfinite(omega):
        raise ValueError(f"omega must be finite; got {omega!r}")
    a = np.asarray(axis, dtype=float).reshape(3)
    na = np.linalg.norm(a)
    if na == 0:
        raise ValueError("axis must be a non-zero vector")
    a = a / na

    def flow(points: np.ndarray) -> np.ndarray:
        x = np.asarray(points, dtype=float)
        c = np.zeros(x.shape[1]) if center is None else np.asarray(center, dtype=float).reshape(x.shape[1])
        r = x - c
        if x.shape[1] == 2:
            return omega * np.stack([-r[:, 1], r[:, 0]], axis=1)
        if x.shape[1] == 3:
            return omega * np.cross(a, r)
        raise ValueError(f"solid_body_rotation is defined in 2D and 3D; got points of shape {x.shape}")

    flow.omega = float(omega)  # type: ignore[attr-defined]
    flow.axis = a  # type: ignore[attr-defined]
    return flow


def rotation_travel_time_circle(
    points: np.ndarray, radius: float, source_angle: float, speed: float, omega: float
) -> np.ndarray:
    """Exact first-arrival time on the circle ``|x| = radius`` in a medium turning rigidly at ``omega``.

    ``u(α) = min(R α / (F + ωR), R (2π − α) / (F − ωR))`` with α the angle from the source,
    counter-clockwise: the wave runs with the flow at ``F + ωR`` and against it at ``F − ωR``.

    Parameters
    ----------
    points : numpy.ndarray
        ``(M, 2)`` points (projected radially onto the circle).
    radius : float
        R.
    source_angle : float
        The source's polar angle.
    speed : float
        F.
    omega : float
        Angular speed of the medium, ``|ω| R < F``.

    Returns
    -------
    numpy.ndarray
        ``(M,)`` arrival times.

    Raises
    ------
    ValueError
        If ``|ω| R ≥ F`` (supersonic: no such formula).

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> u = ts.flows.rotation_travel_time_circle(np.array([[0.0, 0.5]]), 0.5, 0.0, 1.0, 1.0)
    >>> round(float(u[0]), 4)  # a quarter turn downstream at speed 1 + 0.5
    0.5236
    """
    p = np.asarray(points, dtype=float)
    a = np.mod(np.arctan2(p[:, 1], p[:, 0]) - source_angle, 2 * np.pi)
    vr = omega * radius
    if abs(vr) >= speed:
        raise ValueError("the rotation is supersonic (|ω|R ≥ F); the exact formula needs |ω|R < F")
    return np.minimum(radius * a / (speed + vr), radius * (2 * np.pi - a) / (speed - vr))


def rotation_travel_time_sphere(
    points: np.ndarray, radius: float, source: Sequence[float], speed: float, omega: float, iterations: int = 80
) -> np.ndarray:
    """Exact first-arrival time on the sphere ``|x| = radius`` in a medium turning rigidly about z.

    In the co-rotating frame the wave speed is F in every direction, so the front at time ``t`` is
    the geodesic circle of radius ``F t`` about the source, carried by the rotation: ``x`` is
    reached at the root of ``g(t) = d(R_{−ωt} x, x_s) − F t``, found by bisection.

    Parameters
    ----------
    points : numpy.ndarray
        ``(M, 3)`` points (projected radially onto the sphere).
    radius : float
        R.
    source : sequence of float
        The source (projected onto the sphere).
    speed : float
        F.
    omega : float
        Angular speed of the medium about z, ``|ω| R < F``.
    iterations : int
        Bisection steps (default 80: machine precision).

    Returns
    -------
    numpy.ndarray
        ``(M,)`` arrival times.

    Raises
    ------
    ValueError
        If ``|ω| R ≥ F``.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> u = ts.flows.rotation_travel_time_sphere(np.array([[0.0, 0.5, 0.0]]), 0.5, (0.5, 0, 0), 1.0, 0.0)
    >>> round(float(u[0]), 6)  # still medium: the great-circle distance π/4
    0.785398
    """
    x = np.asarray(points, dtype=float)
    x = radius * x / np.linalg.norm(x, axis=1, keepdims=True)
    xs = np.asarray(source, dtype=float)
    xs = radius * xs / np.linalg.norm(xs)
    if abs(omega) * radius >= speed:
        raise ValueError("the rotation is supersonic (|ω|R ≥ F); the exact formula needs |ω|R < F")

    def g(t: np.ndarray) -> np.ndarray:
        c, s = np.cos(-omega * t), np.sin(-omega * t)
        y = np.stack([c * x[:, 0] - s * x[:, 1], s * x[:, 0] + c * x[:, 1], x[:, 2]], axis=1)
        cosang = np.clip(y @ xs / radius**2, -1.0, 1.0)
        return radius * np.arccos(cosang) - speed * t

    lo = np.zeros(len(x))
    hi = np.full(len(x), np.pi * radius / (speed - abs(omega) * radius))
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        pos = g(mid) > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    return 0.5 * (lo + hi)
