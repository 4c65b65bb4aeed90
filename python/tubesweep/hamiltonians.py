"""General static Hamilton–Jacobi equations ``H(x, ∇_Σ u) = 0`` on surfaces, solved in the inner
tube with an upwind (Godunov-type) local solver (``scheme="godunov"``, the default for
:class:`MovingMedium` and :class:`Metric`) or the Lax–Friedrichs sweeping update of the paper's
Sect. 5.1 (``scheme="lxf"``), and the usual extension (Eq. 5 applied to Eq. 8) in the outer layer.

Pass one of these objects as ``ts.solve(..., hamiltonian=...)``:

* :class:`Isotropic` — ``|∇u| = 1/F`` (agrees with ``hamiltonian="lxf"``, Eq. 4);
* :class:`MovingMedium` — ``|∇u| = |1 − v·∇u| / F``, the anisotropic eikonal equation in a
  moving medium of Sect. 6.3 (also reached with ``ts.solve(..., flow=v)``);
* :class:`Metric` — ``sqrt(∇uᵀ M(x) ∇u) = 1/F`` with ``M`` symmetric positive definite.

Following Sect. 5.1, the intrinsic gradient is replaced by the extrinsic one in the tube. The upwind
solver takes, at every node, the minimum over the upwind simplices of the exact local solution
(quadratics for both built-in anisotropic Hamiltonians; Tsai, Cheng, Osher & Zhao 2003, the paper's
ref. [35]); it is monotone and as accurate as the isotropic Godunov update. For ``scheme="lxf"`` each
Hamiltonian gets artificial viscosities ``σ_k ≥ max_p |∂H/∂p_k|`` computed exactly per node by the
Rust core (``1`` isotropic, ``1 + |v_k|/F`` moving medium, ``sqrt(M_kk)`` metric); ``sigma=``
overrides them with constants (they must be at least as large, or the update is not monotone).
See ``docs/hamiltonians.md`` for the derivations and measured convergence.
"""

from __future__ import annotations

import copy
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, Optional

import numpy as np

from .grid import Grid
from ._validate import call_on_points, check_flag, real_array
from ._warn import user_stacklevel

__all__ = ["Hamiltonian", "Isotropic", "MovingMedium", "Metric", "NORMAL_FLOW_RTOL"]

#: Warn when the flow's normal component exceeds this fraction of its largest magnitude.
NORMAL_FLOW_RTOL = 1e-2


@dataclass
class _Prepared:
    """Per-node inputs of the native general solver, and per-node local travel-time data."""

    kind: str
    slowness: np.ndarray
    flow: Optional[np.ndarray] = None
    metric: Optional[np.ndarray] = None
    sigma: Optional[np.ndarray] = None
    #: the local solver this solve uses: "godunov" (upwind) or "lxf" (Sect. 5.1)
    scheme: str = "lxf"
    extra: Dict[str, Any] = field(default_factory=dict)


def _check_sigma(sigma: Any, d: Optional[int] = None) -> Optional[np.ndarray]:
    if sigma is None:
        return None
    s = np.atleast_1d(real_array(sigma, "sigma"))
    if d is not None and s.size == 1:
        s = np.full(d, float(s[0]))
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"sigma must be positive finite viscosities σ_k ≥ max|∂H/∂p_k| (Sect. 5.1); got {sigma!r}")
    if d is not None and s.size != d:
        raise ValueError(f"sigma must be a number or {d} numbers (one per axis); got {s.size}")
    return np.ascontiguousarray(s)


def _normals(surface: Any, grid: Grid, x: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Unit normals at the band nodes: the band's extension direction ``sgn(φ) n`` (its sign does
    not matter here), or, on nodes where φ = 0 exactly, central differences of φ."""
    n = np.asarray(direction, dtype=float)
    zero = np.linalg.norm(n, axis=1) < 0.5
    if np.any(zero) and hasattr(surface, "phi"):
        h = grid.spacing
        xz = x[zero]
        g = np.empty_like(xz)
        for k in range(grid.ndim):
            e = np.zeros(grid.ndim)
            e[k] = h
            g[:, k] = surface.phi(xz + e, grid) - surface.phi(xz - e, grid)
        g /= np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
        n = n.copy()
        n[zero] = g
    return n


def _interp_nodes(arr: np.ndarray, grid: Grid, x: np.ndarray) -> np.ndarray:
    """Multilinear interpolation of an array of ``grid.shape + tail`` at points x (M, d): (M,) + tail."""
    d = grid.ndim
    tail = arr.shape[d:]
    flat = arr.reshape(tuple(grid.shape) + (-1,))
    t = grid.continuous_index(x)
    base = np.clip(np.floor(t), 0, np.asarray(grid.shape) - 2).astype(np.int64)
    frac = np.clip(t - base, 0.0, 1.0)
    out = np.zeros((len(x), flat.shape[-1]))
    for corner in range(1 << d):
        bits = np.array([(corner >> k) & 1 for k in range(d)])
        w = np.prod(np.where(bits == 1, frac, 1 - frac), axis=1)
        out += w[:, None] * flat[tuple((base + bits).T)]
    return out.reshape((len(x),) + tail)


def _field(
    value: Any,
    grid: Grid,
    linear: np.ndarray,
    points: np.ndarray,
    tail: tuple,
    name: str,
    interpolate: bool = False,
) -> np.ndarray:
    """A per-node field from a constant, an array of ``grid.shape + tail``, or a callable on points.
    An array is read at the nodes, or with ``interpolate`` interpolated (multilinearly) at
    ``points`` — the nodes' closest points, where a callable is evaluated too."""
    want = (len(linear),) + tail
    if callable(value):
        out = call_on_points(value, points, f"{name} callable's values")
        if out.shape != want:
            raise ValueError(
                f"{name} callable must map points (M, {grid.ndim}) to an array of shape (M,)+{tail}; "
                f"returned {out.shape} for M = {len(linear)}"
            )
    else:
        arr = real_array(value, name)
        if arr.shape == tail:
            out = np.broadcast_to(arr, want).copy()
        elif arr.shape == tuple(grid.shape) + tail:
            out = _interp_nodes(arr, grid, points) if interpolate else arr.reshape((-1,) + tail)[linear]
        else:
            raise ValueError(
                f"{name} must be a constant of shape {tail}, an array of shape grid.shape + {tail} = "
                f"{tuple(grid.shape) + tail}, or a callable; got shape {arr.shape}"
            )
    if not np.all(np.isfinite(out)):
        i = int(np.flatnonzero(~np.all(np.isfinite(out.reshape(len(out), -1)), axis=1))[0])
        raise ValueError(f"{name} is NaN or inf at {tuple(float(c) for c in points[i])}; it must be finite on the band")
    return np.ascontiguousarray(out)


def _fmt(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{float(c):.4g}" for c in p) + ")"


def _regions(linear: np.ndarray, grid: Grid, select: np.ndarray) -> list:
    """Connected components (grid-axis neighbours) of the selected band nodes, as arrays of band
    positions."""
    pos = np.flatnonzero(select)
    lookup = {int(l): int(i) for i, l in zip(pos, linear[pos])}
    strides = [int(np.prod(grid.shape[k + 1 :])) for k in range(grid.ndim)]
    idx = grid.unravel(linear[pos])
    index_of = {int(l): j for j, l in enumerate(linear[pos])}
    seen = np.zeros(len(pos), dtype=bool)
    out = []
    for start in range(len(pos)):
        if seen[start]:
            continue
        seen[start] = True
        stack, comp = [start], []
        while stack:
            j = stack.pop()
            comp.append(lookup[int(linear[pos[j]])])
            for k, st in enumerate(strides):
                for step in (-1, 1):
                    c = idx[j, k] + step
                    if 0 <= c < grid.shape[k]:
                        q = index_of.get(int(linear[pos[j]]) + step * st)
                        if q is not None and not seen[q]:
                            seen[q] = True
                            stack.append(q)
        out.append(np.asarray(comp, dtype=np.int64))
    return out


class Hamiltonian:
    """Base class of the built-in Hamiltonians for ``ts.solve(..., hamiltonian=...)``.

    The equation itself is evaluated in the Rust core; this class prepares its per-node data.
    Use :class:`Isotropic`, :class:`MovingMedium` or :class:`Metric`.

    Parameters
    ----------
    sigma : float or sequence of float, optional
        Constant viscosities σ_k of the Lax–Friedrichs update (Sect. 5.1), overriding the
        automatic per-node ones.

    Attributes
    ----------
    label : str
        The name in ``Solution.hamiltonian``.

    Raises
    ------
    ValueError
        If ``sigma`` is not positive and finite.

    Examples
    --------
    >>> import tubesweep as ts
    >>> isinstance(ts.hamiltonians.Isotropic(), ts.hamiltonians.Hamiltonian)
    True
    """

    kind: str = ""
    label: str = ""

    #: the local solver when neither ``scheme`` nor ``sigma`` is given
    default_scheme: str = "godunov"

    def __init__(self, sigma: Any = None, scheme: Optional[str] = None):
        self.sigma = _check_sigma(sigma)
        if scheme is None:
            scheme = "lxf" if sigma is not None else self.default_scheme
        if not isinstance(scheme, str) or scheme.lower() not in ("godunov", "lxf"):
            raise ValueError(f"scheme must be 'godunov' (the upwind local solver) or 'lxf' (Sect. 5.1); got {scheme!r}")
        self.scheme = scheme.lower()
        if self.scheme == "godunov" and sigma is not None:
            raise ValueError(
                "sigma (the Lax–Friedrichs viscosities of Sect. 5.1) only applies to scheme='lxf'; "
                "drop sigma, or pass scheme='lxf'"
            )

    def _box_bytes_per_node(self, d: int) -> int:
        """Bytes per box node of the flow or metric, for the memory check of a box solve."""
        return 8 * d * d

    def prepare(
        self,
        surface: Any,
        grid: Grid,
        linear: np.ndarray,
        x: np.ndarray,
        direction: np.ndarray,
        slowness: np.ndarray,
        roles: np.ndarray,
    ) -> _Prepared:  # pragma: no cover - interface
        """Per-node data for the solver (called by :func:`tubesweep.solve`, not by users).

        Parameters
        ----------
        surface : Surface
            The surface solved on.
        grid : Grid
            The grid.
        linear : numpy.ndarray
            The band nodes' linear indices.
        x : numpy.ndarray
            Their closest points on the surface.
        direction : numpy.ndarray
            Their unit normals.
        slowness : numpy.ndarray
            1/F at the nodes.
        roles : numpy.ndarray
            Their roles (fixed, inner, extension layer).

        Returns
        -------
        _Prepared
            The arrays the Rust core reads.

        Raises
        ------
        ValueError
            Where the equation cannot be solved as given (e.g. a supersonic flow).

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source], hamiltonian=ts.hamiltonians.Isotropic())
        """
        raise NotImplementedError

    def local_time(self, prep: _Prepared, nodes: np.ndarray, disp: np.ndarray) -> np.ndarray:
        """Travel time from a source to nearby band nodes, for a locally constant Hamiltonian.

        Used to fix the nodes within ``SOURCE_RADIUS``·Δx of a source (``source_init="exact"``).

        Parameters
        ----------
        prep : _Prepared
            The data from :meth:`prepare`.
        nodes : numpy.ndarray
            Band positions of the nodes.
        disp : numpy.ndarray
            ``(M, d)`` displacements, closest point minus source.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` travel times.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source], hamiltonian=ts.hamiltonians.Isotropic())
        """
        return np.linalg.norm(disp, axis=1) * prep.slowness[nodes]

    def _sigma(self, d: int) -> Optional[np.ndarray]:
        return None if self.sigma is None else _check_sigma(self.sigma, d)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class Isotropic(Hamiltonian):
    """``H(x, p) = |p| − 1/F(x)``: the eikonal equation through the general update of Sect. 5.1.

    With σ_k = 1 it is identical to ``hamiltonian="lxf"`` (Eq. 4); mainly a reference for the
    general solver. With ``scheme="godunov"`` it is the Godunov update (3) through the
    upwind-solver interface.

    Parameters
    ----------
    sigma : float or sequence of float, optional
        Constant viscosities (default 1).
    scheme : {"lxf", "godunov"}, optional
        The local solver (default ``"lxf"``, Sect. 5.1).

    Raises
    ------
    ValueError
        If ``sigma`` is not positive and finite.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source], hamiltonian=ts.hamiltonians.Isotropic())
    >>> sol.hamiltonian
    'isotropic'
    """

    kind = "isotropic"
    label = "isotropic"
    default_scheme = "lxf"

    def __init__(self, sigma: Any = None, *, scheme: Optional[str] = None):
        super().__init__(sigma, scheme)

    def prepare(self, surface, grid, linear, x, direction, slowness, roles):
        return _Prepared(self.kind, slowness, sigma=self._sigma(grid.ndim), scheme=self.scheme)


class MovingMedium(Hamiltonian):
    """The anisotropic eikonal equation in a moving medium (paper Sect. 6.3)::

        |∇_Σ u| = |1 − v(x)·∇u| / F(x)

    ``u`` is the first-arrival time of a wave with speed ``F`` relative to a medium moving with
    velocity ``v``: a front with unit normal ``n`` advances at ``F + v·n``.

    Parameters
    ----------
    flow : callable, numpy.ndarray or sequence of float
        ``v(points (M, d)) -> (M, d)`` (e.g. :func:`tubesweep.flows.point_vortices`), an array of
        ``grid.shape + (d,)``, or a constant vector. A callable is evaluated at the
        closest points ``cp(x)`` of the band nodes (the flow lives on the surface and is extended
        constantly along normals); so is an array with the upwind solver (multilinear
        interpolation at ``cp(x)``: the array and the callable give the same field), while with
        ``scheme="lxf"`` an array is read at the nodes (the paper's Sect. 6.3 set-up).
    allow_supersonic : bool
        The paper assumes ``|v| ≪ F``. Where ``|v| ≥ F`` the medium outruns the wave and the
        first-arrival problem changes character (the equation loses the monotone front
        propagation). By default that is a ``ValueError`` saying where and by how much;
        ``True`` computes the Lax–Friedrichs solution of the equation as written anyway, with a
        ``RuntimeWarning`` (also with ``scheme="godunov"``: the upwind solver needs ``|v| < F``).
    scheme : {"godunov", "lxf"}
        The local solver in the inner tube: the upwind solver (default) or the Lax–Friedrichs
        update of Sect. 5.1 (the default when ``sigma`` is given).
    sigma : float or sequence of float, optional
        Constant viscosities overriding the per-node ``1 + |v_k|/F`` (``scheme="lxf"``).

    Raises
    ------
    ValueError
        At solve time, where ``|v| ≥ F`` in the inner tube (unless ``allow_supersonic``), or if the
        flow has the wrong shape or non-finite values.

    Warns
    -----
    RuntimeWarning
        When the flow's normal component, which is removed, exceeds ``NORMAL_FLOW_RTOL`` times the
        largest ``|v|``, or when a supersonic flow is solved anyway.

    Notes
    -----
    The paper assumes ``v·n = 0``. The normal component of ``v`` (with the band's normal) is always
    removed — ``v ← v − (v·n) n`` — and a ``RuntimeWarning`` is raised when it is larger than
    ``NORMAL_FLOW_RTOL`` times the largest ``|v|``.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> medium = ts.hamiltonians.MovingMedium(ts.flows.solid_body_rotation(1.0))
    >>> sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source], hamiltonian=medium)
    """

    kind = "moving_medium"
    label = "moving-medium"

    def __init__(self, flow: Any, *, allow_supersonic: bool = False, scheme: Optional[str] = None, sigma: Any = None):
        super().__init__(sigma, scheme)
        if flow is None:
            raise ValueError(
                "MovingMedium needs a flow: a callable v(points) -> (M, d), an array of grid.shape + (d,) or a vector"
            )
        self.flow = flow
        self.allow_supersonic = bool(check_flag(allow_supersonic, "allow_supersonic"))

    def __repr__(self) -> str:
        return (
            f"MovingMedium(flow={getattr(self.flow, '__name__', type(self.flow).__name__)}, "
            f"allow_supersonic={self.allow_supersonic}, scheme={self.scheme!r})"
        )

    def prepare(self, surface, grid, linear, x, direction, slowness, roles):
        """Per-node data for the solver (called by :func:`tubesweep.solve`, not by users).

        ``surface=None`` for the whole box (:func:`tubesweep.travel_time`): the flow is read at the
        nodes and kept whole.

        Parameters
        ----------
        surface : Surface or None
            The surface solved on (None: the whole box).
        grid : Grid
            The grid.
        linear : numpy.ndarray
            The band nodes' linear indices.
        x : numpy.ndarray
            Their closest points on the surface.
        direction : numpy.ndarray
            Their unit normals.
        slowness : numpy.ndarray
            1/F at the nodes.
        roles : numpy.ndarray
            Their roles (fixed, inner, extension layer).

        Returns
        -------
        _Prepared
            The arrays the Rust core reads.

        Raises
        ------
        ValueError
            Where the equation cannot be solved as given (e.g. a supersonic flow).

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source], hamiltonian=ts.hamiltonians.Isotropic())
        """
        d = grid.ndim
        # a callable at the closest points; an array too with the upwind solver (interpolated there,
        # so that both forms give the same field), at the nodes with LxF (the paper's set-up, bit for bit)
        at_cp = surface is not None and (callable(self.flow) or (self.scheme != "lxf" and np.ndim(self.flow) > 1))
        if at_cp:
            _, cp = surface.project(x, grid)
            v = _field(self.flow, grid, linear, cp, (d,), "flow", interpolate=True)
        else:
            v = _field(self.flow, grid, linear, x, (d,), "flow")
        n = _normals(surface, grid, x, direction) if surface is not None else np.zeros_like(v)
        vn = np.sum(v * n, axis=1)
        speed_v = np.linalg.norm(v, axis=1)
        vmax = float(speed_v.max()) if speed_v.size else 0.0
        i = int(np.argmax(np.abs(vn))) if vn.size else 0
        if vn.size and abs(vn[i]) > NORMAL_FLOW_RTOL * vmax and vmax > 0:
            warnings.warn(
                f"flow has a normal component up to |v·n| = {abs(vn[i]):.3g} (at {_fmt(x[i])}, {abs(vn[i]) / vmax:.1%} of "
                f"max |v| = {vmax:.3g}); the moving-medium equation (Sect. 6.3) assumes v·n = 0. The normal component "
                "is removed: v is projected onto the tangent plane with the band's normal",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        v = np.ascontiguousarray(v - vn[:, None] * n)
        speed_v = np.linalg.norm(v, axis=1)
        f = 1.0 / slowness
        ratio = speed_v / f
        active = roles != 2
        bad = active & (ratio >= 1.0)
        if np.any(bad):
            j = int(np.flatnonzero(bad)[np.argmax(ratio[bad])])
            nb = int(np.count_nonzero(bad))
            regions = sorted(_regions(linear, grid, bad), key=lambda r: -float(ratio[r].max()))
            where = "; ".join(
                f"around {_fmt(x[r].mean(axis=0))} ({len(r)} nodes, up to {float(ratio[r].max()):.3g})"
                for r in regions[:5]
            ) + ("; …" if len(regions) > 5 else "")
            msg = (
                f"flow: |v| ≥ F at {nb} of {int(np.count_nonzero(active))} inner-tube nodes — the medium outruns the wave "
                f"there and the first-arrival problem changes character (the paper assumes |v| ≪ F). Worst at "
                f"{_fmt(x[j])}: |v| = {speed_v[j]:.4g} vs F = {f[j]:.4g} (|v|/F = {ratio[j]:.3g}). "
                f"{len(regions)} supersonic region(s), with their max |v|/F: {where}."
            )
            if not self.allow_supersonic:
                raise ValueError(
                    msg
                    + " Pass allow_supersonic=True to compute the Lax–Friedrichs solution of the equation as written "
                    "anyway, or make the flow subsonic (e.g. a vortex core: ts.flows.point_vortices(..., core=δ))"
                )
            warnings.warn(
                msg
                + " allow_supersonic=True: computing the Lax–Friedrichs solution anyway"
                + (" (the upwind solver needs |v| < F everywhere)" if self.scheme == "godunov" else ""),
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        scheme = "lxf" if np.any(bad) else self.scheme
        return _Prepared(
            self.kind,
            slowness,
            flow=v,
            sigma=self._sigma(d),
            scheme=scheme,
            extra={
                "max_mach": float(ratio[active].max()) if np.any(active) else 0.0,
                "supersonic_nodes": int(np.count_nonzero(bad)),
            },
        )

    def local_time(self, prep: _Prepared, nodes: np.ndarray, disp: np.ndarray) -> np.ndarray:
        assert prep.flow is not None
        v = prep.flow[nodes]
        f = 1.0 / prep.slowness[nodes]
        a = f * f - np.sum(v * v, axis=1)
        dv = np.sum(disp * v, axis=1)
        r2 = np.sum(disp * disp, axis=1)
        ok = a > 1e-12 * f * f
        safe_a = np.where(ok, a, 1.0)
        t = (-dv + np.sqrt(np.maximum(dv * dv + safe_a * r2, 0.0))) / safe_a
        return np.where(ok, t, np.sqrt(r2) / f)


class Metric(Hamiltonian):
    """A Riemannian (anisotropic) eikonal equation ``sqrt(∇uᵀ M(x) ∇u) = 1/F(x)``.

    ``M`` (symmetric positive definite, acting on gradients) is the inverse of the length metric:
    for constant ``M`` the solution from ``x_s`` is ``u = sqrt((x − x_s)ᵀ M⁻¹ (x − x_s)) / F``.

    Parameters
    ----------
    M : array_like or callable
        A constant ``(d, d)`` matrix, an array of ``grid.shape + (d, d)``, or a callable
        ``M(points (K, d)) -> (K, d, d)`` (evaluated at the closest points of the band nodes; an
        array is interpolated there with the upwind solver, read at the nodes with ``"lxf"``).
    restrict : {"gradient", "length"}
        What the equation means on a surface, where ``M`` (given in the ambient space) has to be
        restricted to the tangent plane. ``"gradient"`` (default): ``M``'s tangential block acts
        on the surface gradient, ``sqrt(∇_Σuᵀ P M P ∇_Σu) = 1/F``. ``"length"``: the ambient
        length metric ``M⁻¹`` restricted to the surface (the induced Riemannian metric: a path's
        length is ``∫ sqrt(ẋᵀ M⁻¹ ẋ)`` along it), whose dual on gradients is
        ``M − (Mn)(Mn)ᵀ / (nᵀMn)``. The two agree where the normal ``n`` is an eigenvector of
        ``M`` and differ elsewhere: ``M = diag(2, 1, 1)`` on the sphere of radius 0.5, from
        ``(−0.5, 0, 0)`` to ``(0, 0.5, 0)``, gives 0.6555 and 0.6753 (docs/hamiltonians.md). In
        the box (:func:`tubesweep.travel_time`) there is nothing to restrict.
    tangential : bool
        On a surface only the tangential block of ``M`` matters. With ``True`` (default) the
        normal–tangent coupling is removed, ``M ← P M P + m_n n nᵀ`` with ``P = I − n nᵀ``, so
        that the small normal component of the extrinsic gradient cannot leak into the tangential
        metric; the normal entry ``m_n`` is the mean of the tangential block's eigenvalues
        (``tr(PMP)/(d − 1)``) with the upwind solver, ``nᵀMn`` with ``scheme="lxf"``. ``False``
        uses ``M`` as given (right for a full-box solve).
    scheme : {"godunov", "lxf"}
        The local solver in the inner tube: the upwind solver (default) or the Lax–Friedrichs
        update of Sect. 5.1 (the default when ``sigma`` is given).
    sigma : float or sequence of float, optional
        Constant viscosities overriding the per-node ``sqrt(M_kk)`` (``scheme="lxf"``).

    Raises
    ------
    ValueError
        If ``M`` is not symmetric positive definite, has the wrong shape or is no array of numbers.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1), (1, 1), (101, 101))
    >>> M = np.diag([4.0, 1.0])  # travel is twice as fast along x (u = sqrt(dᵀM⁻¹d))
    >>> sol = ts.solve(ts.surfaces.Circle(0.5), grid, [(0.5, 0.0)], hamiltonian=ts.hamiltonians.Metric(M))
    """

    kind = "metric"
    label = "metric"

    def __init__(
        self,
        M: Any,
        *,
        restrict: str = "gradient",
        tangential: bool = True,
        scheme: Optional[str] = None,
        sigma: Any = None,
    ):
        super().__init__(sigma, scheme)
        if restrict not in ("gradient", "length"):
            raise ValueError(
                f"restrict must be 'gradient' (M's tangential block acts on the surface gradient) or 'length' "
                f"(the length metric M⁻¹ restricted to the surface); got {restrict!r}"
            )
        if restrict == "length" and not tangential:
            raise ValueError(
                "restrict='length' takes the surface's tangent plane from its normals: it needs tangential=True"
            )
        if not callable(M):
            try:
                np.asarray(M)  # (complex values are refused where M is read, naming M)
            except (TypeError, ValueError) as err:  # (numpy's "inhomogeneous shape" before: a helper's review)
                raise ValueError(
                    "M must be a (d, d) matrix, an array of shape grid.shape + (d, d) or a callable; got "
                    f"{type(M).__name__} that is no array of numbers ({err})"
                ) from None
        self.M = M
        self.restrict = restrict
        self.tangential = bool(tangential)

    def __repr__(self) -> str:
        extra = ", restrict='length'" if self.restrict == "length" else ""
        return f"Metric(tangential={self.tangential}{extra}, scheme={self.scheme!r})"

    def prepare(self, surface, grid, linear, x, direction, slowness, roles):
        d = grid.ndim
        if surface is not None and (callable(self.M) or (self.scheme != "lxf" and np.ndim(self.M) > 2)):
            # at the closest points, an array interpolated there (as the flow, above)
            _, cp = surface.project(x, grid)
            m = _field(self.M, grid, linear, cp, (d, d), "M", interpolate=True)
        elif self._constant():
            # one matrix for all nodes (1, d, d): the upwind solver stores it once, the native
            # Lax–Friedrichs update repeats it per node
            m = _field(self.M, grid, linear[:1], x[:1], (d, d), "M")
        else:
            m = _field(self.M, grid, linear, x, (d, d), "M")
        asym = np.abs(m - np.swapaxes(m, 1, 2)).max(axis=(1, 2))
        scale = np.abs(m).max(axis=(1, 2))
        if np.any(asym > 1e-10 * np.maximum(scale, 1e-300)):
            i = int(np.argmax(asym))
            raise ValueError(f"M must be symmetric; at {_fmt(x[i])} |M − Mᵀ| = {asym[i]:.3g}. Use (M + Mᵀ)/2")
        lam = np.linalg.eigvalsh(m)[:, 0]
        if np.any(lam <= 0):
            i = int(np.argmin(lam))
            raise ValueError(f"M must be positive definite; at {_fmt(x[i])} its smallest eigenvalue is {lam[i]:.3g}")
        if self.tangential and surface is not None:
            m = np.broadcast_to(m, (len(linear), d, d))  # the tangential part is per node
            n = _normals(surface, grid, x, direction)
            has = np.linalg.norm(n, axis=1) > 0.5
            P = np.eye(d)[None] - n[:, :, None] * n[:, None, :]
            pmp = P @ m @ P
            if self.restrict == "length":
                # the dual of M⁻¹ restricted to the tangent plane, (P M⁻¹ P)⁺ = M − (Mn)(Mn)ᵀ/(nᵀMn)
                # (a Schur complement: no inverse formed); it annihilates n, so P·P changes nothing
                mn = np.einsum("kij,kj->ki", m, n)
                nmn = np.einsum("ki,ki->k", n, mn)
                pmp = np.where(
                    has[:, None, None],
                    m - mn[:, :, None] * mn[:, None, :] / np.where(has, nmn, 1.0)[:, None, None],
                    pmp,
                )
            if self.scheme == "lxf" and self.restrict == "gradient":
                mnn = np.einsum("ki,kij,kj->k", n, m, n)
            else:
                # the normal block is free (the surface's equation does not see it): the tangential
                # mean makes the tube as isotropic across as the eikonal solver's, so the front cuts
                # the curved tube's inner side no faster than it does there (docs/hamiltonians.md)
                mnn = np.trace(pmp, axis1=1, axis2=2) / (d - 1)
            mt = pmp + mnn[:, None, None] * n[:, :, None] * n[:, None, :]
            m = np.where(has[:, None, None], mt, m)
        m = np.ascontiguousarray(m)
        # M⁻¹ is formed only where a local travel time is asked for (local_time), not per node: here
        # only whether it exists (the LU factorisation np.linalg.inv would run, without a zero pivot)
        if np.any(np.linalg.slogdet(m)[0] == 0):
            raise ValueError(
                "M is numerically singular at some band node (after its tangential part was taken): "
                "its eigenvalues span too many orders of magnitude; rescale M or use tangential=False"
            )
        return _Prepared(self.kind, slowness, metric=m, sigma=self._sigma(d), scheme=self.scheme)

    def _constant(self) -> bool:
        """Whether ``M`` is one ``(d, d)`` matrix (stored once unless the tangential part makes it per node)."""
        return not callable(self.M) and np.ndim(self.M) == 2

    def _box_bytes_per_node(self, d: int) -> int:
        # the upwind solver stores a constant M once, the Lax–Friedrichs update per node
        return 0 if self._constant() and self.scheme != "lxf" else 8 * d * d

    def local_time(self, prep: _Prepared, nodes: np.ndarray, disp: np.ndarray) -> np.ndarray:
        m = prep.metric
        assert m is not None
        # one matrix for all nodes (1, d, d), or the nodes' own
        inv = np.linalg.inv(m if len(m) == 1 else m[nodes])
        inv = np.broadcast_to(inv, (len(nodes),) + inv.shape[1:])
        return prep.slowness[nodes] * np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", disp, inv, disp), 0.0))


def resolve(hamiltonian: Any, flow: Any, allow_supersonic: bool) -> Optional[Hamiltonian]:
    """The general Hamiltonian a ``solve`` call asks for, or None for the eikonal schemes
    (``"godunov"``, ``"lxf"``). ``flow`` selects :class:`MovingMedium`."""
    check_flag(allow_supersonic, "allow_supersonic")
    if isinstance(hamiltonian, Hamiltonian):
        if flow is not None:
            raise ValueError(
                "pass either flow= or a Hamiltonian object as hamiltonian=, not both "
                "(use hamiltonian=ts.hamiltonians.MovingMedium(flow) for full control)"
            )
        if allow_supersonic:
            if not isinstance(hamiltonian, MovingMedium):
                raise ValueError("allow_supersonic only applies to the moving-medium equation (flow=...)")
            hamiltonian = copy.copy(hamiltonian)  # leave the caller's object as it is
            hamiltonian.allow_supersonic = True
        return hamiltonian
    if flow is not None:
        if not (isinstance(hamiltonian, str) and hamiltonian.lower() in ("godunov", "lxf")):
            raise ValueError(f"hamiltonian must be 'godunov', 'lxf' or a ts.hamiltonians object; got {hamiltonian!r}")
        return MovingMedium(flow, allow_supersonic=allow_supersonic, scheme=hamiltonian.lower())
    if allow_supersonic:
        raise ValueError("allow_supersonic=True needs a flow (the moving-medium equation); pass flow=v")
    return None
