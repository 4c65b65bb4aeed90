"""The paper's first-order scheme on a prepared tube (the scheme stage of ``ts.solve`` and
``Tube.solve`` where first order runs): the sources fixed on the inner tube (``_sources``), the
sweeps of Algorithm 3 (or 2) with the Godunov (Eq. 3) or Lax–Friedrichs (Eq. 4) update and the
extension equation (8), or a Hamiltonian's (``_hamiltonian_solve``), then the values checked and
the :class:`~tubesweep.Solution` with its stats."""

from __future__ import annotations

import dataclasses
import time
from typing import Any, Optional, Tuple

import numpy as np

from . import _hamiltonian_solve
from ._creases import warn_paper_tube_creases
from ._fallback import Fallback
from ._parts import drop_unsourced, on_sourced_parts, part_labels, source_parts
from ._facing import warn_facing_pairs
from ._prepare import _PreparedTube, paper_creases_of, thinned_count, uncut_band
from ._roles import ROLE_FIXED, ROLE_INNER, ROLE_OUTER
from ._request import SolveRequest
from ._result_check import check_values
from ._sources import SOURCE_RADIUS, _fix_sources, slowness_on_surface
from ._wide_tube import tube_shortcut, warn_wide_tube
from ._validate import (
    ACTIVATION_FRACTION,
    FRONT_WINDOW,
    check_infinity,
    check_threads,
    check_tolerance_scale,
    tolerance_slowness,
    first_order_tol,
    speed_on_surface,
    warn_unconverged,
)
from .second_order import with_fallback
from .solution import Solution
from .stats import SolveStats

# band nodes at which a solution samples its surface's φ array, to notice a later change
_PHI_SAMPLE = 4096


def first_order(req: SolveRequest, tube: _PreparedTube, fallback: Optional[Fallback], reuse: bool) -> Solution:
    """The first-order solution on ``tube`` (:func:`solve_on_tube`); where ``order="auto"`` fell
    back to it (``fallback``: why), its errors measured and warned of, and the reason kept in
    ``sol.stats.order_fallback``."""
    if fallback is not None:
        fallback.measure(tube)
    shortcut = tube_shortcut(tube)  # an inner tube wider than the paper's (before the sweeps consume it)
    sol = solve_on_tube(tube, req, reuse)
    if shortcut is not None:
        sol.stats = dataclasses.replace(sol.stats, tube_shortcut=shortcut)
        warn_wide_tube(shortcut, tube.inner, tube.grid.spacing)
    if fallback is None:
        return sol
    fallback.warn(sol.values, tube)
    return with_fallback(sol, fallback.reason, fallback.creases)


@dataclasses.dataclass
class _Fixed:
    """The nodes the sources fix: their positions in the band, values and the index of the source
    each value comes from; ``radius``: the exact initialisation's reach in grid spacings."""

    positions: np.ndarray
    values: np.ndarray
    sources: np.ndarray
    radius: float


def solve_on_tube(tube: _PreparedTube, req: SolveRequest, reuse: bool) -> Solution:
    """Fixes the sources on the prepared tube and sweeps. With ``reuse`` the tube is left as it
    was (its roles and directions are copied); without, its arrays are consumed and dropped
    before the sweeps."""
    if not isinstance(req.paper_sweeps, (bool, np.bool_)):
        raise TypeError(f"paper_sweeps must be True or False; got {req.paper_sweeps!r}")
    grid, surf = tube.grid, tube.surface
    crease_thinned = thinned_count(tube)
    if crease_thinned == 0:  # the paper's tube: its creases' corners are cut
        warn_paper_tube_creases(paper_creases_of(tube), tube.inner, grid.spacing)
    band, cut_edges = _band_to_sweep(tube, req.scheme)
    # the parts of the surface (before the sweeps consume the tube): a part without a source
    # keeps inf whatever reached it across a narrow gap (``_parts``)
    parts = part_labels(tube, band)
    sourced = None if parts is None else source_parts(grid, band, parts, req.sources, surf)
    h = grid.spacing
    roles = tube.roles.copy() if reuse else tube.roles
    # a callable at the nodes' closest points (an array is read at the nodes)
    speed_nodes = speed_on_surface(req.speed, grid, tube.linear, tube.phi, _directions_of(tube), tube.inner * h)
    slowness: Any = 1.0 / speed_nodes
    # (the default: 1e-10 of the travel time across the grid, at most 1e-10; a Hamiltonian's own
    # travel times set it in _hamiltonian_solve)
    tol = first_order_tol(req.tol, h, float(np.mean(slowness)), max(grid.shape))
    if req.general is None:
        check_tolerance_scale(
            tol, h, float(np.mean(slowness)), max(grid.shape), front_slowness=tolerance_slowness(slowness)
        )
    fixed = _fix(tube, band, roles, req, cut_edges)
    phi, phi_sample = tube.phi, _phi_sample(surf, tube.linear)
    if req.general is None:
        values, st, setup = _sweep_isotropic(tube, band, roles, fixed, slowness, tol, req, reuse)
    else:
        setup = time.perf_counter() - req.started
        values, st, tol = _hamiltonian_solve.solve_band(
            req.general,
            surf,
            grid,
            tube.geom,
            band,
            roles,
            fixed.positions,
            fixed.values,
            req.sources,
            speed_nodes,
            req.source_init == "exact",
            fixed.radius,
            req.tol,
            req.max_iterations,
            check_infinity(req.infinity),
            req.progress,
            check_threads(req.threads),
            ACTIVATION_FRACTION,
            not req.paper_sweeps,
        )
    warn_unconverged(st, tol, req.max_iterations)
    values[values >= st["infinity"]] = np.inf  # never reached (another component of the surface)
    if parts is not None:
        drop_unsourced(values, parts, sourced)
    # no NaN, and no inf next to a reached node in a solve reported converged (the inner tube of a
    # part without a source is unreachable: next to a reached part across a narrow gap, not stranded)
    reachable = on_sourced_parts(parts, sourced)
    check_values(
        grid,
        band,
        values,
        (roles != ROLE_OUTER) if reachable is None else (roles != ROLE_OUTER) & reachable,
        st,
        check_infinity(req.infinity),
        reachability=req.general is None or req.general.label == "isotropic",
    )
    stats = _stats(tube, band, roles, fixed, st, slowness, req, setup, cut_edges, crease_thinned)
    sol = Solution(
        grid,
        band,
        values,
        roles,
        phi,
        stats,
        req.sources,
        surf,
        req.scheme,
        tube.method,
        tube.inner,
        tube.outer_eff,
        (fixed.positions, fixed.sources),
        req.general is None or req.general.label == "isotropic",
        tube.facing,
        phi_sample,
    )
    sol._parts = parts
    return sol


def _directions_of(tube: _PreparedTube) -> np.ndarray:
    """The tube's unit directions away from the surface, per band node: the solver's own copy (one
    call) or the kept geometry's (a :class:`Tube`, a general Hamiltonian)."""
    return tube.direction if tube.direction is not None else tube.geom.direction  # type: ignore[union-attr]


def _band_to_sweep(tube: _PreparedTube, scheme: str) -> Tuple[Any, int]:
    """The band the sweeps run on and its edges cut inside the tube: the tube's, except that the
    Lax–Friedrichs update, which extrapolates a missing neighbour and does not settle beside edges
    cut inside the tube (``_shortcuts``), runs on the whole band, and the narrow gaps the cut would
    have closed are warned about."""
    if scheme == "lxf" and tube.cut_edges:
        band = uncut_band(tube)
        warn_facing_pairs(tube.grid, tube.linear, tube.roles, tube.facing, tube.inner)
        return band, 0
    return tube.band, tube.cut_edges


def _fix(tube: _PreparedTube, band: Any, roles: np.ndarray, req: SolveRequest, cut_edges: int) -> _Fixed:
    """The sources fixed on the inner tube (their nodes' ``roles`` set to fixed), or the error of
    a source radius or a grid that leaves no inner node to solve for."""
    grid, h = tube.grid, tube.grid.spacing
    # the exact initialisation's radius in grid spacings
    radius = SOURCE_RADIUS if req.source_radius is None else max(SOURCE_RADIUS, float(req.source_radius) / h)
    positions, values, sources = _fix_sources(
        tube.surface,
        grid,
        band,
        tube.linear,
        roles,
        req.sources,
        slowness_on_surface(req.speed, grid),
        req.source_init,
        tube.inner * h,
        radius,
        cut_edges > 0,
    )
    roles[positions] = ROLE_FIXED
    if tube.method != "naive" and len(req.sources) == 1 and not np.any(roles == ROLE_INNER):
        if radius > SOURCE_RADIUS:
            raise ValueError(
                f"source_radius = {req.source_radius:g} covers the whole inner tube: every node lies within it of the "
                "source, so its value is the source's initialisation and nothing is solved; use a smaller "
                f"source_radius (a few grid spacings, h = {h:.4g}, up to a small fraction of the surface's size) or "
                "leave it out"
            )
        raise ValueError(
            f"the grid is too coarse for this surface: every node of the inner tube lies within {radius:g} grid "
            f"spacings (h = {h:.4g}) of a source, so its value is the source's initialisation and nothing is solved; "
            f"refine the grid"
        )
    return _Fixed(positions, values, sources, radius)


def _phi_sample(surf: Any, linear: np.ndarray) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """A φ array is used in place: a sample of it at the band's nodes, for the solution to notice a
    change before it projects points with it (geodesic paths); None for other surfaces."""
    array = getattr(surf, "_array", None)
    if array is None:
        return None
    pick = linear[:: max(1, len(linear) // _PHI_SAMPLE)].copy()  # not a view: `linear` is dropped
    return pick, array.reshape(-1)[pick].copy()


def _sweep_isotropic(
    tube: _PreparedTube,
    band: Any,
    roles: np.ndarray,
    fixed: _Fixed,
    slowness: Any,
    tol: float,
    req: SolveRequest,
    reuse: bool,
) -> Tuple[np.ndarray, dict, float]:
    """The Godunov or Lax–Friedrichs sweeps (the core's): the values, the core's stats and the
    set-up time. The linear indices are dropped before the sweeps and the fixed nodes go to the
    solver sparsely; the directions are converted to the extension weights in place (no second
    K×d buffer)."""
    if reuse:
        directions = tube.geom.directions_for_solver()  # type: ignore[union-attr]  # a copy: the tube's stay as they are
    else:
        directions = tube.direction  # overwritten by the solver (a copy unless the geometry is consumable)
        tube.direction = tube.linear = tube.roles = None  # type: ignore[assignment]
    method, paper = tube.method, bool(req.paper_sweeps)
    missing_policy = "infinity" if (method == "naive" and req.scheme == "godunov") else "extrapolate"
    setup = time.perf_counter() - req.started
    values, st = band.solve(
        roles,
        fixed.positions,
        fixed.values,
        tube.grid.spacing,
        slowness,
        directions,
        req.scheme,
        missing_policy,
        float(tol),
        int(req.max_iterations),
        check_infinity(req.infinity),
        req.progress,
        check_threads(req.threads),
        True,
        ACTIVATION_FRACTION * float(tol),
        not paper,
        not paper,
        0.0 if paper else FRONT_WINDOW,
    )
    return values, st, setup


def _stats(
    tube: _PreparedTube,
    band: Any,
    roles: np.ndarray,
    fixed: _Fixed,
    st: dict,
    slowness: Any,
    req: SolveRequest,
    setup: float,
    cut_edges: int,
    crease_thinned: int,
) -> SolveStats:
    """The first-order solve's :class:`SolveStats`, with the memory it held during the sweeps."""
    grid = tube.grid
    n_outer = int(np.count_nonzero(roles == ROLE_OUTER))
    # held per node during the sweeps: values (f64), role, active flag and coupling mask, φ (f32),
    # extension weights (d × f32), per-node slowness (f64) when the speed varies; per row a lower
    # bound of its values (8 bytes, for the front window), and with the window a byte per node
    # marking the layer nodes in upwind 2-cycles; the fixed values are sparse. (With the rim
    # left to the end the core also holds a role copy and a rim mask, then the rim mask and a
    # byte of dependency counts, 2 bytes per node.)
    windowed = grid.ndim == 3 and req.scheme == "godunov" and not req.paper_sweeps and FRONT_WINDOW > 0
    per_node = 8 + 1 + 1 + 1 + 4 + 4 * grid.ndim + (8 if np.ndim(slowness) else 0) + (1 if windowed else 0)
    return SolveStats.of_sweeps(
        st,
        band_points=len(roles),
        inner_points=len(roles) - n_outer,
        outer_points=n_outer,
        fixed_points=len(fixed.positions),
        setup_seconds=setup,
        band_bytes=band.nbytes + per_node * len(roles) + 8 * band.n_rows,
        window_edge=st["window_edge"],
        facing_pairs=int(tube.facing[0].size),
        narrowest_gap=float(np.min(tube.facing[2])) if tube.facing[2].size else float("inf"),
        cut_edges=cut_edges,
        crease_thinned=crease_thinned,
        thin_strip_iterations=(int(st["thin_strip_iterations"][0]), int(st["thin_strip_iterations"][1])),
        prefetch_iterations=int(st["prefetch_iterations"]),
        local_solver=st.get("local_solver", req.scheme),
        box_cut=tube.box_cut,
        creases=tube.paper_creases,
        bridged_holes=tube.bridged_holes,
        slits=tube.slits,
    )
