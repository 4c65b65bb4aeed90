"""Anisotropic first-arrival times in the whole box: ``ts.travel_time(grid, sources, flow=v)`` (the
moving medium ``F|∇u| + v·∇u = 1``) or ``hamiltonian=ts.hamiltonians.Metric(M)``
(``sqrt(∇uᵀ M ∇u) = 1/F``), with the upwind local solver (``scheme="godunov"``, default) or the
Lax–Friedrichs update of Sect. 5.1 (``"lxf"``). Called from :func:`tubesweep.travel_time`.
"""

from __future__ import annotations

import time
from typing import Any, Callable, Optional

import numpy as np

from ._hamiltonian_solve import warn_wide_sigma
from ._result_check import check_values
from ._validate import ACTIVATION_FRACTION, check_tolerance_scale, first_order_tol, warn_unconverged
from .grid import Grid
from .stats import SolveStats

__all__ = ["travel_time_general"]


def _source_values(ham: Any, prep: Any, grid: Grid, sources: np.ndarray, radius: float) -> tuple:
    """Linear indices and exact local travel times (the Hamiltonian frozen at each node) of the
    nodes within ``radius`` grid spacings of a source."""
    h = grid.spacing
    r = int(np.ceil(radius))
    offsets = np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * grid.ndim), indexing="ij"), axis=-1).reshape(
        -1, grid.ndim
    )
    best: dict = {}
    for s in sources:
        base = np.floor(grid.continuous_index(s[None])[0]).astype(np.int64)
        idx = base + offsets
        idx = idx[np.all((idx >= 0) & (idx < np.asarray(grid.shape)), axis=1)]
        x = grid.points(idx)
        near = np.linalg.norm(x - s, axis=1) <= radius * h + 1e-12 * h
        idx, x = idx[near], x[near]
        lin = grid.linear_index(idx)
        t = ham.local_time(prep, lin, x - s)
        for li, val in zip(lin, t):
            if li not in best or val < best[li]:
                best[li] = float(val)
    lin = np.fromiter(best.keys(), dtype=np.int64, count=len(best))
    val = np.fromiter(best.values(), dtype=float, count=len(best))
    return lin, val


def travel_time_general(
    grid: Grid,
    sources: np.ndarray,
    ham: Any,
    slowness: Any,
    tol: Optional[float],
    max_iterations: int,
    return_stats: bool,
    cb: Optional[Callable],
    infinity: Optional[float],
    threads: int,
    band: Any,
    source_radius: float,
    t0: float,
) -> Any:
    """The box solve of :func:`tubesweep.travel_time` for a general Hamiltonian ``ham``."""
    from ._hamiltonian_solve import _mean_cell_time, _coefficient_bytes

    linear = np.arange(grid.size, dtype=np.int64)
    x = np.stack([c.reshape(-1) for c in grid.meshgrid()], axis=1)
    slow = np.ascontiguousarray(np.broadcast_to(np.asarray(slowness, dtype=float).reshape(-1), (grid.size,)))
    roles = np.ones(grid.size, dtype=np.uint8)
    prep = ham.prepare(None, grid, linear, x, None, slow, roles)
    del x
    cell_slowness = _mean_cell_time(ham, prep, grid.size, grid) / grid.spacing
    # (tol None: 1e-10 of the Hamiltonian's travel time across the box, at most 1e-10)
    tol = first_order_tol(tol, grid.spacing, cell_slowness, max(grid.shape))
    check_tolerance_scale(
        tol,
        grid.spacing,
        cell_slowness,
        max(grid.shape),
        "the Hamiltonian's travel time along the axes, averaged over the box",
        "the Hamiltonian's coefficients",
    )
    lin, val = _source_values(ham, prep, grid, sources, source_radius)
    roles[lin] = 0
    setup = time.perf_counter() - t0
    values, st = band.solve_general(
        roles,
        np.ascontiguousarray(lin),
        np.ascontiguousarray(val),
        grid.spacing,
        prep.kind,
        prep.slowness,
        None,
        "extrapolate",
        float(tol),
        int(max_iterations),
        infinity,
        flow=prep.flow,
        metric=prep.metric,
        sigma=prep.sigma,
        progress=cb,
        threads=int(threads),
        skip_inactive=True,
        activation_threshold=ACTIVATION_FRACTION * float(tol),
        defer_outer_rim=True,
        scheme=prep.scheme,
    )
    st = dict(st)
    warn_wide_sigma(st, prep.sigma)
    warn_unconverged(st, tol, max_iterations)
    values[values >= st["infinity"]] = np.inf
    check_values(grid, band, values, None, st, infinity, reachability=False)  # no NaN (as ts.solve for these H)
    u = values.reshape(grid.shape)
    if not return_stats:
        return u
    stats = SolveStats.of_sweeps(
        st,
        band_points=grid.size,
        inner_points=grid.size - len(lin),
        outer_points=0,
        fixed_points=len(lin),
        setup_seconds=setup,
        band_bytes=band.nbytes + grid.size * 10 + _coefficient_bytes(prep, grid.size, grid.ndim) + 8 * band.n_rows,
        thin_strip_iterations=(int(st["thin_strip_iterations"][0]), int(st["thin_strip_iterations"][1])),
        prefetch_iterations=int(st["prefetch_iterations"]),
        local_solver="lxf" if prep.scheme == "lxf" else ("godunov" if prep.kind == "isotropic" else "upwind"),
    )
    return u, stats
