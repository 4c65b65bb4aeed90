"""``order=2``: the second-order surface solver (docs/second-order.md).

The paper's tube equation ``|∇u| = 1/F`` is wrong by ``φκ = O(Δx)`` off the surface, so its
scheme is first order whatever the stencil. ``order=2`` solves the metric-corrected equation
``|B∇u| = 1/F``, ``B = (I − φD²φ)⁻¹`` (whose exact solution is the normal extension of the
surface solution) with limited BDF2–BDF3 upwind differences, a second-order extension layer and point
sources factored as ``u = u₀ + w``, ``u₀`` the chord distance to the source
(``tubesweep_core::second_order``)."""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _native
from ._box_cut import box_reason
from ._coarse_creases import widened_for_order2
from ._creases import thinned_spacings, warn_creases
from ._factoring import FACTORED_RADIUS, factored_reach, undercut_sources
from ._parts import drop_unsourced, part_labels, source_parts
from ._prepare import thinned_count
from ._roles import ROLE_OUTER
from ._order2_refusals import NarrowExtension, OptionOfOrder1, Order2NotApplicable, Order2RanAway, ran_away_message
from ._result_check import stranded_nodes
from ._runaway import runaway_cause, runaway_report, warn_runaway
from .mask import mask_advice
from .moving import values_checksum
from ._stagnation import fallback_message
from ._warn import user_stacklevel
from ._sources import check_on_surface
from ._validate import (
    FRONT_WINDOW,
    check_threads as _threads,
    check_tolerance_scale,
    checked_point_speeds,
    tolerance_slowness,
    speed_at_points,
    speed_on_surface,
)
from .stats import SolveStats
from .surface import LevelSet

__all__ = ["ORDERS", "Order2NotApplicable", "check_order", "FIX_RADIUS", "FACTORED_RADIUS", "default_tol"]

#: A warning says how many inner-tube nodes ran the first-order update when they are more than
#: this fraction of the tube (fewer are reported in ``sol.stats.order2`` only): the rims of the
#: library's open surfaces and a crease take 4–26% at N = 41–161.
FIRST_ORDER_WARNING = 0.4

#: The values of ``order``: the paper's first-order scheme, second order, or ``"auto"`` (second
#: order where it applies, first order otherwise, the reason in ``sol.stats.order_fallback``).
ORDERS = (1, 2, "auto")


#: Inner-tube nodes whose closest point is within this many grid spacings of a source are fixed
#: at ``u₀`` (the chord distance, O(Δx³) from the geodesic there), where fixed nodes join them to
#: the source along the band's uncut edges (``tubesweep_core::second_order::joined``).
FIX_RADIUS = 2.0

#: Phase 1 (first order, monotone) stops at this times ``Δx² × mean slowness / ℓ`` (``ℓ`` half the
#: grid's longest side, ``ramp_length``); ∞: no phase 1. In 3D the second-order sweeps start from
#: the fixed nodes behind their front window, which reaches every node anyway: on the sphere at
#: N = 201 5.6 million updates instead of 7.3 (2.9 of them phase 1's), 18–27% fewer on the
#: spheroid, ellipsoid, torus and rounded cube, values as close to the converged ones. In 2D (no
#: window) the star at N = 1601 needs a tight start (from 1.0 its phase 2 stalled into the
#: safeguard, far max 5.6e-4 instead of 1.2e-5). Phase 2 (second order) stops at ``TOL_FACTOR[d]``
#: times ``Δx² × mean slowness / ℓ`` unless ``tol`` is given: in 3D 5e-4 (at N = 201 the values
#: come within 6e-7–2.0e-6 of the converged ones on the sphere, ellipsoid, torus and rounded cube,
#: 0.04–3.4% of their far max errors, 7e-8–1.2e-7 in the mean; 2e-4 took 4–7% more updates for
#: 2.5–8.1e-7, and 1e-3 left the torus 7.4e-6 away, 12% of its far max error). Dividing by ``ℓ``
#: makes both tolerances the same fraction of the travel times in any units. "Mean slowness" is
#: ``_validate.tolerance_slowness``: the mean, capped at twice the lower quartile (obstacles).
TOL_FIRST_FACTOR = {2: 1e-2, 3: math.inf}
TOL_FACTOR = {2: 1e-3, 3: 5e-4}

#: In 2D the default ``tol`` falls further, as ``Δx³``, on grids finer than ``ℓ/200`` (N = 401 over
#: [−1, 1]²): the changes of phase 2 fall by a factor 1 − ρ that shrinks like Δx/ℓ on a fine curve, so
#: a stop at a change of ``tol`` leaves the values about ``tol·ℓ/Δx`` from the fixed point; with the
#: Δx² tolerance alone that is first order in Δx and outgrew the O(Δx²) error. The circle of
#: ``tubesweep reproduce second-order`` at N = 1601 and 3201: mean errors 1.12e-7 and 4.09e-8 with
#: the Δx² tolerance, 9.7e-8 and 2.4e-8 once converged, for 3% more iterations
#: (``benches/experiments/fine_curve_tolerance.py``). In 3D (N ≤ 301 or so) the gap stays
#: within 12 tolerances, 0.1% of the errors.
FINE_CURVE_SPACINGS = 200.0

#: The extension layer's BDF2 correction ramps to first order where the two neighbours' w differ
#: by more than this many ``σΔx`` (fully at twice it; ∞: never): a resolved solution has
#: ``|∂w| ≲ 2σ``, so it leaves BDF2 alone there, and it keeps phase 2 from running away from a
#: poor start (``tubesweep_core::second_order::solver``, ``Sweeper::outer``).
EXTENSION_LIMIT = 2.0

#: Phase 1 (2D: 3D has none) on the first-order driver (``False``: the paper's first-order tube
#: scheme with the isotropic part of the metric correction, exact on a curve, from the fixed
#: nodes: ``tubesweep_core::second_order::start``) or on the second-order module's own sweeps
#: (``True``: the factored scheme, whose changes fall by only a few percent per iteration on a
#: fine curve). Without front windows in 2D, the driver's start halved the 2D solve's updates
#: (0.46–0.61 on the circle, the star, an ellipse, three sources, a speed field, a smoothed mask
#: and a closest-point circle at N = 201–1601) and 2D order=2 took 0.6–0.7 of the time, with errors
#: as small against the exact distances (far max and mean within 4% on the star at N = 201–1601
#: and the circle at 101–801; the circle's far max at N = 1601 4.3e-7 instead of 5.3e-7:
#: ``benches/experiments/first_phase_2d.py``, measured before phase 2 had its window in 2D).
_OWN_FIRST_PHASE = {2: False, 3: True}

# the front windows of the two phases in 3D (factors of the first-order driver's width; 0: none):
# on the sphere at N = 201, 30 million updates without them, 10 million with them (7 million
# with the activation thresholds at the phases' tolerances), the same errors
WINDOWS = (2.0, 2.0)

# in 2D phase 1 runs on the first-order driver (``_OWN_FIRST_PHASE``), and phase 2 behind the same
# window as in 3D. From the first-order start without it, every node was updated in every
# iteration while the changes fell by a few percent per iteration: on the circle 39 / 164 / 1497
# updates per band node at N = 201 / 1601 / 10001, and at N = 10001 the sweeps stalled, ran away
# and returned the first-order solution. Behind the window 16 / 32 / 64, second order at 10001;
# 0.08–0.58 of the updates on the seven cases of ``benches/experiments/window_2d.py`` at
# N = 201–4001, the errors against the exact distances of the star at N = 201–1601 and the circle
# at 101–1601 within 3% (``window_2d.py --sizes 201,801,1601,4001`` and ``--sizes 10001``)
WINDOWS_2D = (0.0, WINDOWS[1])

#: Where the 90th percentile of the band's slowness is more than this many times its smallest
#: value (part of the curve far faster than most of it), 2D phase 2 runs without its window
#: (``windows_of``). There the BDF2 ramp's kink test leaves the fast region's nodes first order,
#: they do not settle, and the window's edge waits on them: a circle whose speed rises smoothly to
#: 30 times, at N = 4001, took 2600–3400 iterations and 14–26 times the updates of the solve
#: without the window, and still fell into the stagnation fallback. At 10 times the window is
#: kept: 0.8–1.6 times the updates, mean errors 50–250 times smaller and no fallback
#: (``window_2d.py --fast 10,30``). Only the slowness decides (not the sources), so that a
#: batch's rows equal the single solves bit for bit; a slow obstacle on under a tenth of the band
#: keeps the window
WINDOW_2D_CONTRAST = 12.0


def windows_of(ndim: int, slowness: Any) -> Tuple[float, float]:
    """The front windows of the two phases (``WINDOWS`` in 3D; in 2D ``WINDOWS_2D``, without the
    second phase's where the band's slowness varies more than ``WINDOW_2D_CONTRAST``)."""
    if ndim == 3:
        return WINDOWS
    s = np.asarray(slowness, dtype=float)
    if s.ndim == 0 or s.size == 0:
        return WINDOWS_2D
    k = int(0.9 * (s.size - 1))
    q90 = float(np.partition(s, k)[k])
    return WINDOWS_2D if q90 <= WINDOW_2D_CONTRAST * float(s.min()) else (WINDOWS_2D[0], 0.0)


def check_order(order: Any) -> Union[int, str]:
    """``order`` as 1, 2 or ``"auto"``, or a ValueError naming it and the choices."""
    if isinstance(order, str) and order == "auto":
        return "auto"
    if isinstance(order, (bool, np.bool_)) or not isinstance(order, (int, np.integer)) or int(order) not in (1, 2):
        raise ValueError(
            "order must be 1 (the paper's first-order scheme), 2 (second order, docs/second-order.md) or 'auto' "
            f"(second order where it applies, first order otherwise); got {order!r}"
        )
    return int(order)


def with_fallback(sol: Any, reason: str, creases: Optional[dict] = None) -> Any:
    """``sol`` (an ``order=1`` solution) with ``stats.order_fallback`` set to why ``order=2`` did
    not apply, and ``stats.creases`` to ``creases`` where the fallback found some
    (``_fallback.Fallback.creases``)."""
    sol.stats = dataclasses.replace(sol.stats, order_fallback=reason)
    if creases is not None:
        sol.stats = dataclasses.replace(sol.stats, creases=creases)
    return sol


def ramp_length(grid: Any) -> float:
    """The length ``ℓ`` that makes the limiter and the tolerances independent of units: half the
    grid's longest side (1 for the library's ``[-1, 1]`` grids). The limiter's ramp has width
    ``ε = σΔx²/ℓ`` (crates/tubesweep-core/src/second_order/local.rs, ``reconstruct``)."""
    return 0.5 * float(np.max(np.asarray(grid.upper, dtype=float) - np.asarray(grid.lower, dtype=float)))


def default_tol(spacing: float, slowness: float, length: float, ndim: int = 3) -> float:
    """Phase 2's stopping tolerance when none is given: ``5e-4 Δx²/ℓ`` (3D) or ``1e-3 Δx²/ℓ`` (2D)
    times the slowness scale ``slowness`` (``ℓ`` = :func:`ramp_length`), far below the scheme's
    O(Δx²) error and far above machine precision, in any units; in 2D times
    ``min(1, 200 Δx/ℓ)`` as well (:data:`FINE_CURVE_SPACINGS`). The solve passes
    ``_validate.tolerance_slowness``: the mean slowness, capped where an obstacle pulls it up."""
    tol = TOL_FACTOR[ndim] * spacing * spacing * slowness / length
    if ndim == 2:
        tol *= min(1.0, FINE_CURVE_SPACINGS * spacing / length)
    return tol


def check_supported(
    surf: Any, general: Any, scheme: str, method: str, source_init_given: Optional[str], paper_sweeps: bool
) -> None:
    """Refuses, with the reason and the fix, what ``order=2`` does not do."""
    from .closest_point import ClosestPoint

    if general is not None or scheme != "godunov":
        raise OptionOfOrder1(
            "order=2 solves the isotropic eikonal equation with the Godunov update only "
            f"(hamiltonian={scheme!r} given); use order=1 for Lax–Friedrichs, flows and general Hamiltonians"
        )
    if method != "two-layer":
        raise OptionOfOrder1(
            f"order=2 needs method='two-layer' (got {method!r}); the naive tube is the paper's baseline"
        )
    if paper_sweeps:
        raise OptionOfOrder1(
            "paper_sweeps=True runs the paper's first-order sweeps; it cannot be combined with order=2"
        )
    if source_init_given == "node":
        raise OptionOfOrder1(
            "order=2 factors the point sources (u = u₀ + w); source_init='node' is the paper's first-order "
            "initialisation: use order=1 for it"
        )
    kind = type(surf).__name__
    if not isinstance(surf, (LevelSet, ClosestPoint)):
        raise Order2NotApplicable(
            f"order=2 needs a level set (φ as an array, a callable or a library surface) or a closed smooth "
            f"closest-point surface; {kind} gives closest points"
            + (
                " of a triangle mesh, which is piecewise flat: its curvature is not there to correct (it is all on "
                "the edges), and second order cannot be reached on it"
                if "Mesh" in kind
                else " the second-order geometry cannot read"
            )
            + ". Use order=1 for it"
        )


def check_widths(inner: Any, outer: Any) -> None:
    """Refuses ``outer < inner + 2`` as given (before any widening of the extension layer), so that
    whether ``order=2`` applies depends on the arguments and not on the grid: a layer widened
    from ``outer = 3`` to 4 where some inner node lacked a neighbour was accepted, ``outer = 3.5``
    (never widened) refused. Widths that are not numbers are left to the tube's own checks."""
    numbers = all(
        isinstance(w, (int, float, np.integer, np.floating)) and not isinstance(w, (bool, np.bool_)) and np.isfinite(w)
        for w in (inner, outer)
    )
    if numbers and float(outer) < float(inner) + 2.0 - 1e-9:
        raise NarrowExtension(
            f"order=2 needs two band neighbours on each side of every inner-tube node: outer ≥ inner + 2 grid spacings "
            f"(got inner={float(inner):g}, outer={float(outer):g}); pass outer={float(inner) + 2.0:g} or more (the "
            "defaults are inner=2, outer=4), or order=1"
        )


def _native_solve(*args: Any, **kwargs: Any) -> Any:
    """``_native.second_order_solve``, its refusals of the geometry (``order=2: ...``: a crease, a
    curvature the tube does not resolve, a φ that is not a distance, a closest-point map of an open
    surface or with edges) raised as :class:`Order2NotApplicable`."""
    try:
        return _native.second_order_solve(*args, **kwargs)
    except ValueError as e:
        if "order=2" in str(e):
            raise Order2NotApplicable(str(e)) from None
        raise


@dataclasses.dataclass
class TubeInputs:
    """What every second-order solve on a prepared tube reads besides its sources (computed once
    for a batch: :mod:`tubesweep.many_order2`)."""

    slowness: Any  # float, or one per band node
    tol: float
    default_tol: float  # what tol is when the user gives none (the warnings compare against it)
    tol_first: float
    length: float
    offsets: Optional[np.ndarray]  # x − cp(x) per band node for a closest-point surface
    directions: np.ndarray
    exact_feet: bool  # the surface gives closest points to rounding (sol(points)'s reach, _factoring)


def tube_inputs(tube: Any, speed: Any, tol: Optional[float]) -> TubeInputs:
    """The checks and the per-node inputs of a second-order solve on ``tube`` (a
    ``solve._PreparedTube`` with its geometry kept), independent of the sources."""
    from .closest_point import ClosestPoint

    grid, surf, geom = tube.grid, tube.surface, tube.geom
    h = grid.spacing
    d = grid.ndim
    if tube.outer_eff < tube.inner + 2.0 - 1e-9:
        raise Order2NotApplicable(
            f"order=2 needs two band neighbours on each side of every inner-tube node: outer ≥ inner + 2 grid spacings "
            f"(got inner={tube.inner:g}, outer={tube.outer_eff:g}); the defaults are inner=2, outer=4"
        )
    if getattr(surf, "smooth", False):  # a mesh through its smooth map (surfaces/_mesh_smooth.py)
        node, neighbour, _ = tube.facing
        depth = np.median(np.maximum(np.abs(tube.phi[node]), np.abs(tube.phi[neighbour]))) / h if node.size else np.inf
        obstacle = surf.order2_obstacle(int(node.size), float(depth), h)
        if obstacle is not None:
            raise Order2NotApplicable(obstacle)
    linear = tube.linear
    speed_nodes = speed_on_surface(speed, grid, linear, geom.signed, geom.direction, tube.inner * h)
    slowness: Any = 1.0 / speed_nodes
    mean_slowness = float(np.mean(slowness))
    # the tolerances' slowness: the mean unless an obstacle pulls it up (_validate.tolerance_slowness)
    tol_slowness = tolerance_slowness(slowness)
    length = ramp_length(grid)
    default = default_tol(h, tol_slowness, length, d)
    if tol is None:
        tol = default
    # travel times too large or too small for the local updates' squares, a tol not small against
    # them: refused as for order=1 (they came out inf, or 1.5x off, reported converged)
    check_tolerance_scale(tol, h, mean_slowness, max(grid.shape), front_slowness=tol_slowness)
    offsets = None
    if isinstance(surf, ClosestPoint):
        # x − cp(x) at the band nodes in float64 (the band keeps only float32 directions): n and
        # D²φ come from its local signed distance (tubesweep_core::second_order::implicit)
        nodes = grid.node_points(linear)
        offsets = np.ascontiguousarray(nodes - surf.closest_point(nodes))
        del nodes
    directions = geom.direction if geom.direction.dtype == np.float32 else geom.direction.astype(np.float32)
    return TubeInputs(
        slowness=float(slowness) if np.ndim(slowness) == 0 else np.ascontiguousarray(slowness, dtype=float),
        tol=float(tol),
        default_tol=default,
        tol_first=TOL_FIRST_FACTOR[d] * h * h * tol_slowness / length,
        length=length,
        offsets=offsets,
        directions=np.ascontiguousarray(directions),
        # beyond 3Δx, sol(points) needs the points' closest points: only where the surface gives
        # them to rounding (a closest-point map, a φ callable; not a sampled φ, whose multilinear
        # interpolation errs by about Δx²κ/8 along the normal)
        exact_feet=isinstance(surf, ClosestPoint) or (getattr(surf, "_fn", None) is not None and not surf.redistance),
    )


def source_feet(
    surf: Any, grid: Any, src: np.ndarray, inner_width: float, speed: Any, names: Optional[List[str]] = None
) -> Tuple[np.ndarray, np.ndarray]:
    """The sources' foot points on the surface and the slowness at each; a source farther from
    the surface than the inner tube is refused (``names[i]`` names source i in the message)."""
    dist, proj = surf.project(src, grid)
    check_on_surface(src, dist, inner_width, names)
    h = grid.spacing
    # a source given on the surface is kept as given (its foot point differs by rounding only)
    on = np.linalg.norm(proj - src, axis=1) <= 1e-9 * h
    feet = np.where(on[:, None], src, proj)
    if callable(speed):
        src_slowness = 1.0 / speed_at_points(speed, feet, "a source")
    elif np.ndim(speed) == 0:
        src_slowness = np.full(len(feet), 1.0 / float(speed))
    else:
        from .euclidean import _interp_dense

        src_slowness = 1.0 / checked_point_speeds(
            _interp_dense(np.asarray(speed, dtype=float), grid, feet),
            feet,
            "interpolated from the speed array at a source",
        )
    return np.ascontiguousarray(feet, dtype=float), np.ascontiguousarray(src_slowness, dtype=float)


def warm_start(
    warm: Any, tube: Any, feet: np.ndarray, tol: float, warm_refused: str
) -> Tuple[Optional[np.ndarray], Dict[str, Any], Optional[Dict[str, Any]]]:
    """The warm start of a solve on ``tube`` from ``warm`` (:mod:`tubesweep.moving`): the carried
    values (None to start cold), the native solve's other warm arguments, and the report for
    ``sol.stats.order2["warm"]`` (None without ``warm``). A refused start raises
    :class:`~tubesweep.moving.WarmStartRefused`, or with ``warm_refused="cold"`` starts cold and
    says why in the report."""
    if warm is None:
        return None, {}, None
    from .moving import WarmStartRefused, carried_values

    try:
        carried, more, info = carried_values(warm, tube, feet, tube.inner * tube.grid.spacing, float(tol))
    except WarmStartRefused as e:
        if warm_refused != "cold":
            raise
        return None, {}, {"refused": str(e)}
    previous = warm[1] if isinstance(warm, (tuple, list)) else warm  # (older, previous)
    if (previous.stats.order2 or {}).get("runaway") is not None:
        # its sweeps ran away where the factored update is not causal; the warm sweeps (no nodes
        # put at first order) run away there again before starting cold (the circle with a fast
        # half: 215 iterations against a cold solve's 176, the same values): start cold at once
        return None, {}, {**info, "carried": 0, "restarted": PREVIOUS_RUNAWAY}
    return carried, more, info


#: ``sol.stats.order2["warm"]["restarted"]`` of a warm solve that started cold at once because the
#: previous solve's sweeps ran away (``sol.stats.order2["runaway"]``).
PREVIOUS_RUNAWAY = "previous_runaway"


#: ``sol.stats.order_fallback`` of a solve whose second-order sweeps ran away and whose first-order
#: factored restart converged (its values are returned).
RAN_AWAY_RESTARTED = (
    "the second-order sweeps ran away (a travel time fell below zero): the values are the first-order factored "
    "solution from the sources (order 1); sol.stats.order2['runaway_iteration'] says when"
)


def warn_about(
    st: Dict[str, Any], tube: Any, max_iterations: int, tol: float, values: np.ndarray, default: Optional[float] = None
) -> None:
    """The warnings of a second-order solve from its native report ``st``: not converged, the
    sweeps ran away, a large stagnation fallback, many first-order nodes, convex creases;
    ``default``: the solve's default ``tol`` (:func:`~tubesweep._stagnation.fallback_message`)."""
    if not st["converged"]:
        warnings.warn(
            f"order=2: the sweeps did not converge in max_iterations={max_iterations}: the largest change in the last "
            f"iteration was {st['last_change']:.3g} (tol={tol:g}). Increase max_iterations or tol; the values returned "
            "are the last iterate",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    if st["runaway_iteration"] is not None:
        warnings.warn(
            f"order=2: the second-order sweeps ran away at their iteration {st['runaway_iteration']} (a travel time "
            "fell below zero) and were abandoned: the values returned are the first-order factored solution (order 1). "
            "sol.stats.order2['runaway_iteration'] records it; order=1 avoids it, and so may a finer grid where this one barely resolves the surface",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    fallback = fallback_message(st["fallback_iteration"], st["fallback_change"], tol, values, default_tol=default)
    if fallback is not None:
        warnings.warn("order=2: " + fallback, RuntimeWarning, stacklevel=user_stacklevel())
    warn_first_order_nodes(st, tube.surface)
    warn_creases(
        st.get("creases"),
        tube.inner,
        tube.grid.spacing,
        thinned=thinned_spacings(tube, thinned_count(tube) > 0),
        redistanced=bool(getattr(tube.surface, "redistance", False)),
    )


def warn_first_order_nodes(
    st: Dict[str, Any], surface: Any, where: str = "sol.first_order_points() shows where"
) -> None:
    """The warning that more than :data:`FIRST_ORDER_WARNING` of the inner tube ran the
    first-order update (the native report's ``first_order_nodes``, ``inner_nodes`` and
    ``first_order_reasons``: the tube's geometry, the same for every source of a batch), with
    the cure for ``surface``'s kind."""
    # (the nodes where the sweeps ran away are said apart: _runaway.warn_runaway)
    first_order = int(st["first_order_nodes"]) - int(st["first_order_reasons"].get("runaway", 0))
    if first_order > FIRST_ORDER_WARNING * st["inner_nodes"]:
        r = st["first_order_reasons"]
        # (φ not a distance at most of them: a finer grid does not cure that, re-distancing does; a
        # tanh-flattened φ at N = 61 with 44% such nodes was told to refine the grid. A cloud's or a
        # mesh's distance is a distance: there its gradient breaks where the closest points jump
        # between two parts facing each other, and re-distancing a LevelSet was advised for a cloud
        # of two plates 0.1 apart, benches/experiments/cloud_holes.py)
        given_phi = isinstance(surface, LevelSet) and not getattr(surface, "redistance", False)
        what, label = (
            ("φ is not a distance", "φ not a distance")
            if given_phi
            else ("the distance to the surface is not smooth", "distance not smooth")
        )
        if 2 * int(r["gradient"]) <= first_order:
            cure = "A finer grid resolves more of it"
        elif given_phi:
            cure = "Most of them because φ is not a distance there: LevelSet(phi, redistance=True) cures it"
        else:
            cure = (
                "Most of them because the distance to the surface is not smooth there: it has a ridge where parts "
                "of the surface face each other across a gap narrower than the tube (sol.narrow_gaps() shows "
                "where), which a finer grid resolves where the gap is real"
            )
        warnings.warn(
            f"order=2: {first_order} of the {st['inner_nodes']} inner-tube nodes "
            f"({100 * first_order / st['inner_nodes']:.0f}%) ran the first-order update, where the grid does not "
            f"resolve the surface or {what} ({r['curvature']} unresolved curvature: creases, corners, "
            f"rims, noise; {r['gradient']} {label}; "
            f"{r['stencil']} stencils cut by the box or the band). "
            f"Errors near them and beyond them are first order; {where}. {cure}",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


#: The native report's entries that ``sol.stats.order2`` keeps as they are.
_REPORTED = (
    "first_order_iterations",
    "second_order_iterations",
    "fallback_iteration",
    "fallback_change",
    "runaway_iteration",
    "restart_failed",
    "unreached",
    "max_curvature",
    "grad_norm_range",
    "first_order_nodes",
    "first_order_reasons",
    "inner_nodes",
    "geometry_fitted",
    "creases",
)


def order2_report(
    st: Dict[str, Any], tol: float, surf: Any, spacing: float, warm_info: Optional[Dict[str, Any]], started_warm: bool
) -> Dict[str, Any]:
    """``sol.stats.order2`` from the native report ``st`` (the warm start's report completed with
    what the sweeps did, when it ran)."""
    order2 = {k: st[k] for k in _REPORTED}
    order2["tol"] = float(tol)
    if warm_info is not None:
        if started_warm:
            warm_info["restarted"] = st["warm_restarted"]
            warm_info["changed"] = st["warm_changed"]
            warm_info["extrapolated"] = st["warm_extrapolated"]
        order2["warm"] = warm_info
    order2["fix_radius"] = FIX_RADIUS * spacing
    if getattr(surf, "smooth", False):  # a mesh's smooth map: band nodes per map (surfaces/_mesh_smooth.py)
        order2["mesh_map"] = dict(surf.report)
    return order2


def keep_for_warm_starts(
    sol: Any,
    st: Dict[str, Any],
    tube: Any,
    tol: float,
    anchors: Optional[np.ndarray] = None,
    started: Optional[np.ndarray] = None,
) -> None:
    """What a later warm start from ``sol`` reads: the inner tube's components when counted, and
    the nodes' digests with the solve's tolerance and a checksum of its values, or why none were
    kept; with the digests the nodes' anchors (``moving._unpropagated_drift``): a warm solve's
    carried ``anchors`` (NaN: renewed) where its node moved by no more than the tolerance from
    its start ``started``, else the new value (its readers were woken)."""
    # the inner tube's components, when a warm start counted them (the next warm start reads them)
    sol._inner_components = tube.inner_components
    # digests stand for the fixed point of each node's update: kept only for a solve that reached it
    # (not one stopped at max_iterations, nor one whose second-order sweeps ran away)
    if st.get("digests") is None:
        return
    if not st["converged"]:
        sol._digested = "the previous solve did not converge"
    elif st["runaway_iteration"] is not None:
        sol._digested = "the previous solve's second-order sweeps ran away (its values are first order)"
    elif st.get("runaway_first_iteration") is not None:
        # the digests stand for the tube's updates, not for those of the nodes put at first order
        sol._digested = (
            "the previous solve's second-order sweeps ran away and were solved again with nodes at first order"
        )
    else:
        sol._digests = st["digests"]
        sol._digested = (float(tol), values_checksum(sol.values))
        values = np.asarray(sol.values, dtype=float)
        if anchors is None or started is None or len(anchors) != len(values):
            sol._anchor = values.copy()
        else:
            with np.errstate(invalid="ignore"):
                quiet = (np.abs(values - started) <= tol) | (np.isinf(values) & (values == started))
            sol._anchor = np.where(quiet & ~np.isnan(anchors), anchors, values)


def run_native(
    tube: Any,
    inputs: TubeInputs,
    feet: np.ndarray,
    src_slowness: np.ndarray,
    max_iterations: int,
    cb: Any,
    threads: int,
    warm_values: Optional[np.ndarray],
    warm_more: Dict[str, Any],
    keep_digests: bool,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]]:
    """The native second-order solve (``tubesweep_core::second_order``) on ``tube``: the values
    (clamped at 0), u₀, the roles after the sources were fixed, and the native report."""
    grid = tube.grid
    h, d = grid.spacing, grid.ndim
    windows = windows_of(d, inputs.slowness)
    try:
        values, u0, roles_out, st = _native_solve(
            tube.band,
            np.ascontiguousarray(tube.roles),
            np.ascontiguousarray(tube.geom.signed, dtype=np.float64),
            inputs.directions,
            [float(c) for c in grid.lower],
            h,
            feet,
            src_slowness,
            inputs.slowness,
            FIX_RADIUS * h,
            tube.outer_eff * h,
            inputs.tol_first,
            float(inputs.tol),
            int(max_iterations),
            cb,
            threads=_threads(threads),
            front_window=FRONT_WINDOW if d == 3 else 0.0,
            own_first_phase=_OWN_FIRST_PHASE[d],
            offsets=inputs.offsets,
            window_first=windows[0],
            window_second=windows[1],
            ramp_length=inputs.length,
            extension_limit=EXTENSION_LIMIT,
            warm=warm_values,
            keep_digests=keep_digests,
            **warm_more,
        )
    except Order2NotApplicable as e:
        # a tube cut by the grid box: the reason names the box, not φ or the resolution
        reason = box_reason(tube.box_cut, str(e), tube.outer_eff * h)
        raise Order2NotApplicable(mask_advice(tube.surface, reason)) from None
    # u = u₀ + w rounds to just below 0 next to a source (−9e-22 on a circle of radius 4Δx): a
    # travel time is never negative. Clamped here, not in the sweeps, whose runaway guard reads the
    # sign (a value below −Δx times the mean slowness)
    np.maximum(values, 0.0, out=values)
    return values, u0, roles_out, st


def split_at_creases(tube: Any, values: np.ndarray) -> Optional[str]:
    """Why second order's values on ``tube`` (its inner tube thinned at creases) cannot stand, or
    None: where a thin part meets creases (a neck between two balls), the thinning can take its
    whole inner tube away, and the sweeps, whose extension nodes only read nodes nearer the
    surface, stop there: nodes next to the surface (within half a cell's diagonal of it, a layer
    that follows the surface and joins only what the surface joins) left at inf next to reached
    ones of that layer (``_result_check.stranded_nodes``). Two balls joined by a cylinder of
    radius 1.9 spacings at N = 41 left the far ball at inf with no warning (a helper's review);
    the paper's scheme reaches it. (The paper's inner tube, with the thinned nodes, would also join
    two curves a few spacings apart, a thin ring's, whose unsourced one rightly stays at inf.)
    O(unreached) when some nodes are unreached, nothing otherwise."""
    if thinned_count(tube) == 0 or np.all(np.isfinite(values)):
        return None
    layer = np.abs(np.asarray(tube.phi, dtype=float)) <= SURFACE_LAYER * tube.grid.spacing
    stranded = stranded_nodes(tube.grid, tube.band, values, layer)
    if stranded.size == 0:
        return None
    where = tuple(round(float(c), 4) for c in tube.grid.node_points(tube.linear[stranded[:1]])[0])
    return (
        f"the inner tube, thinned at the creases of φ's level sets, splits near {where}: a part thinner than a few "
        f"grid spacings meets creases there, and the second-order sweeps left {stranded.size} nodes next to the "
        "surface beyond it unreached. order=1, the paper's scheme on its own tube, reaches them; a finer grid resolves "
        "the part"
    )


#: :func:`split_at_creases` follows the surface through the nodes within this many grid spacings
#: of it (half a cell's diagonal: every cell the surface crosses has a corner that close).
SURFACE_LAYER = 0.5 * math.sqrt(3.0)


def solve_on_tube(
    tube: Any,
    src: np.ndarray,
    speed: Any,
    tol: Optional[float],
    max_iterations: int,
    cb: Any,
    threads: int,
    t0: float,
    warm: Any = None,
    warm_refused: str = "raise",
    keep_digests: bool = False,
) -> Any:
    """The second-order solve on a prepared tube (``solve._PreparedTube``, its geometry kept);
    ``warm``: a previous solution to start from (:mod:`tubesweep.moving`); ``keep_digests``: the
    solution keeps its nodes' digests, for a warm start from it to sweep only where the update
    changed (8 bytes per node; a ``ts.Tube``'s solves and warm solves keep them). The stages:
    the per-node inputs, the sources' feet, the warm start, the native solve, the warnings, the
    report and the :class:`~tubesweep.Solution`."""
    grid, surf, band = tube.grid, tube.surface, tube.band
    h, d = grid.spacing, grid.ndim
    inputs = tube_inputs(tube, speed, tol)
    tol = inputs.tol
    feet, src_slowness = source_feet(surf, grid, src, tube.inner * h, speed)
    undercut = undercut_sources(feet, src_slowness, FIX_RADIUS * h)
    if undercut is not None:
        raise Order2NotApplicable(undercut)
    warm_values, warm_more, warm_info = warm_start(warm, tube, feet, tol, warm_refused)
    anchors = warm_more.pop("_anchors", None)  # (moving._ANCHOR)
    parts = part_labels(tube)  # a part without a source keeps inf (``_parts``)
    sourced = None if parts is None else source_parts(grid, band, parts, feet, tube.surface)
    setup = time.perf_counter() - t0
    values, u0, roles_out, st = run_native(
        tube,
        inputs,
        feet,
        src_slowness,
        max_iterations,
        cb,
        threads,
        warm_values,
        warm_more,
        keep_digests or warm is not None,
    )
    if st["restart_failed"]:
        raise Order2RanAway(ran_away_message(st["runaway_iteration"], inputs.slowness, src_slowness, surf))
    if parts is not None:
        drop_unsourced(values, parts, sourced)
    split = split_at_creases(tube, values)
    if split is not None:
        raise Order2NotApplicable(split)
    widened_for_order2(st, tube)  # a rounded crease read through a smoothing
    warn_about(st, tube, max_iterations, tol, values, inputs.default_tol)
    runaway = runaway_report(st, tube)  # solved again with the runaway's nodes at first order
    warn_runaway(runaway, int(st["inner_nodes"]), runaway_cause(inputs.slowness, src_slowness, surf))
    n_outer = int(np.count_nonzero(roles_out == ROLE_OUTER))
    positions = np.flatnonzero(roles_out == 0)
    stats = SolveStats.of_sweeps(
        st,
        sweeps=st["iterations"] * 2**d,
        band_points=len(roles_out),
        inner_points=len(roles_out) - n_outer,
        outer_points=n_outer,
        fixed_points=len(positions),
        setup_seconds=setup,
        band_bytes=band.nbytes + st["solver_bytes"],
        facing_pairs=int(tube.facing[0].size),
        narrowest_gap=float(np.min(tube.facing[2])) if tube.facing[2].size else float("inf"),
        cut_edges=tube.cut_edges,
        crease_thinned=thinned_count(tube),
        # a runaway's values are the first-order factored restart's (warn_about says so)
        order=2 if st["runaway_iteration"] is None else 1,
        order_fallback=None if st["runaway_iteration"] is None else RAN_AWAY_RESTARTED,
        order2={**order2_report(st, tol, surf, h, warm_info, warm_values is not None), "runaway": runaway},
        box_cut=tube.box_cut,
        bridged_holes=tube.bridged_holes,
        slits=tube.slits,
    )
    # the source of each fixed node: the nearest foot point (a kd-tree in the core: nothing of size
    # fixed nodes × sources)
    labels = (
        _native.nearest_feet(feet, np.ascontiguousarray(grid.node_points(tube.linear[positions])))
        if len(positions)
        else np.empty(0, np.int64)
    )
    array = getattr(surf, "_array", None)
    phi_sample = None
    if array is not None:
        pick = tube.linear[:: max(1, len(tube.linear) // 4096)].copy()
        phi_sample = (pick, array.reshape(-1)[pick].copy())
    from .solution import Solution

    sol = Solution(
        grid,
        band,
        values,
        roles_out,
        tube.phi,
        stats,
        src,
        surf,
        "godunov",
        tube.method,
        tube.inner,
        tube.outer_eff,
        (positions, labels.astype(np.int64)),
        True,
        tube.facing,
        phi_sample,
    )
    sol._parts = parts
    sol._factoring = (
        u0,
        feet,
        src_slowness,
        factored_reach(h, float(st["max_curvature"]), d) if inputs.exact_feet else FACTORED_RADIUS * h,
    )
    sol._first_order_positions = st["first_order_positions"]
    keep_for_warm_starts(sol, st, tube, float(tol), anchors, warm_values)
    sol.order = 2
    return sol
