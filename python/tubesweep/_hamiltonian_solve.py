"""The band solve of a general Hamiltonian (:mod:`tubesweep.hamiltonians`): its per-node data
prepared, the sources re-initialised with its local travel time, and the sweeps run in the Rust
core with the upwind local solver or the Lax–Friedrichs update of the paper's Sect. 5.1; and the
scales of its coefficients that the checks and the memory estimate read."""

from __future__ import annotations

import warnings
from typing import Any, Callable, Optional

import numpy as np

from .grid import Grid
from .hamiltonians import Hamiltonian, _Prepared
from ._validate import check_tolerance_scale, first_order_tol
from ._warn import user_stacklevel


def _coefficient_bytes(prep: _Prepared, n_nodes: int, d: int) -> int:
    """The bytes of the flow or metric the native solver holds for ``n_nodes`` nodes: the flow
    ``8 d`` per node; the metric ``8 d²`` per node with the Lax–Friedrichs update (M as given), and
    with the upwind solver its symmetric part packed, ``8 d(d+1)/2`` per matrix stored (one for a
    constant M)."""
    if prep.metric is None:
        return 8 * d * n_nodes
    if prep.scheme == "lxf":
        return 8 * d * d * n_nodes
    return 8 * (d * (d + 1) // 2) * len(prep.metric)


def _mean_cell_time(ham: Hamiltonian, prep: _Prepared, n_nodes: int, grid: Grid) -> float:
    """The mean travel time of one grid step along ±each axis under ``ham``'s local (constant)
    Hamiltonian, over up to 4,096 nodes spread through the band: the scale of the values that
    ``tol`` is compared with. A metric or a flow changes it from spacing × slowness (a metric
    ``M = 1e30·I`` makes it 1e-15 times smaller)."""
    nodes = np.unique(np.linspace(0, n_nodes - 1, min(n_nodes, 4096)).astype(np.int64))
    d, h = grid.ndim, grid.spacing
    times = [
        ham.local_time(prep, nodes, np.broadcast_to(sign * h * np.eye(d)[k], (len(nodes), d)))
        for k in range(d)
        for sign in (1.0, -1.0)
    ]
    return float(np.mean(times))


#: A constant ``sigma=`` this many times the smallest admissible one is warned about: its numerical
#: viscosity grows the errors in proportion (the sphere at N = 41 with the identity metric, the
#: quarter-way point: 4.8% off at σ = 1, 12% at 2, 17% at 3, 29% at 10 and 49% at 100, where the
#: antipode came out at 0.46 instead of 1.57; ``benches/experiments/wide_sigma.py``).
WIDE_SIGMA = 2.0


def warn_wide_sigma(st: dict, given: Any) -> None:
    """The warning for a ``sigma=`` (``given``) of at least :data:`WIDE_SIGMA` times the bound the
    binding checked it against (``st["sigma_needed"]``, taken out of the sweeps' report: per axis,
    the largest |∂H/∂p_k| over the band, the least viscosity that keeps the update monotone); on
    surfaces (:func:`solve_band`) and in the box (``anisotropic_box``)."""
    if st.get("sigma_needed") is None:
        return
    sigma = np.asarray(given, dtype=float)
    needed = np.asarray(st.pop("sigma_needed"), dtype=float)
    ratio = float(np.max(sigma / np.maximum(needed, 1e-300)))
    if ratio < WIDE_SIGMA:
        return
    warnings.warn(
        f"sigma = {np.round(sigma, 4).tolist()} is {ratio:.3g} times the smallest viscosity that keeps the "
        f"Lax–Friedrichs update monotone here ({np.round(needed, 4).tolist()}, the largest |∂H/∂p_k| over the band, "
        "Sect. 5.1): its numerical viscosity, and the error with it, grows in proportion (tens of per cent at 10 "
        "times). Leave sigma out (each node's own bound, the least viscosity) or pass one close to that",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def solve_band(
    ham: Hamiltonian,
    surface: Any,
    grid: Grid,
    geom: Any,
    band: Any,
    roles: np.ndarray,
    positions: np.ndarray,
    fixed_values: np.ndarray,
    sources: np.ndarray,
    speed_nodes: Any,
    exact_sources: bool,
    source_radius: float,
    tol: Optional[float],
    max_iterations: int,
    infinity: Optional[float],
    progress: Optional[Callable[[int, float, int], None]],
    threads: int = 0,
    activation_fraction: float = 0.0,
    defer_outer_rim: bool = True,
) -> tuple:
    """Prepares the per-node data of ``ham``, re-initialises the source nodes with its local
    travel time (for ``exact_sources``), and runs the sweeps with the upwind local solver or the
    general Lax–Friedrichs update (Sect. 5.1), as ``prep.scheme`` says. ``tol`` None: 1e-10 of
    the Hamiltonian's travel time across the grid, at most 1e-10 (``_validate.first_order_tol``);
    the sweeps skip changes below ``activation_fraction`` of it. Returns the values, the native
    report and the ``tol`` used."""
    x = grid.node_points(geom.linear)
    slow = np.ascontiguousarray(np.broadcast_to(1.0 / np.asarray(speed_nodes, dtype=float), (len(roles),)))
    prep = ham.prepare(surface, grid, geom.linear, x, geom.direction, slow, roles)
    cell_slowness = _mean_cell_time(ham, prep, len(roles), grid) / grid.spacing
    tol = first_order_tol(tol, grid.spacing, cell_slowness, max(grid.shape))
    activation_threshold = activation_fraction * tol
    check_tolerance_scale(
        tol,
        grid.spacing,
        cell_slowness,
        max(grid.shape),
        "the Hamiltonian's travel time along the axes, averaged over the band",
        "the Hamiltonian's coefficients",
    )
    fixed = np.array(fixed_values, dtype=float)
    if exact_sources and positions.size:
        _, cp = surface.project(x[positions], grid)
        _, sp = surface.project(sources, grid)
        best = np.full(len(positions), np.inf)
        reach = (source_radius + 4.0) * grid.spacing
        for s in sp:
            disp = cp - s
            near = np.linalg.norm(disp, axis=1) <= reach
            t = ham.local_time(prep, positions, disp)
            best = np.where(near, np.minimum(best, t), best)
        fixed = np.where(np.isfinite(best), best, fixed)
    values, st = band.solve_general(
        roles,
        positions,
        fixed,
        grid.spacing,
        prep.kind,
        prep.slowness,
        geom.directions_for_solver(),
        "extrapolate",
        float(tol),
        int(max_iterations),
        None if infinity is None else float(infinity),
        flow=prep.flow,
        metric=prep.metric,
        sigma=prep.sigma,
        progress=progress,
        threads=int(threads),
        skip_inactive=True,
        activation_threshold=float(activation_threshold),
        defer_outer_rim=bool(defer_outer_rim),
        scheme=prep.scheme,
    )
    st = dict(st)
    warn_wide_sigma(st, prep.sigma)
    # "upwind" for the moving medium and metrics, Eq. (3) itself for the isotropic Hamiltonian
    st["local_solver"] = "lxf" if prep.scheme == "lxf" else ("godunov" if prep.kind == "isotropic" else "upwind")
    st.update(prep.extra if "inverse" not in prep.extra else {})
    return values, st, tol
