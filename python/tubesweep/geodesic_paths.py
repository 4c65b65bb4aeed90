"""Geodesic paths: shortest paths on the surface, traced back from the solved arrival times.

The first-arrival time ``u`` of an isotropic eikonal equation ``|∇_Σ u| = 1/F`` grows along its
characteristics, which are the paths of least travel time (the geodesics for ``F = 1``): a
characteristic runs against ``∇u``. A path from a point of the surface back to the source that
reaches it first is therefore traced by steps against the gradient,

    x_{k+1} = P_Σ( x_k − s ∇u(x_k) / |∇u(x_k)| ),

with ``s`` a fraction of the grid spacing and ``P_Σ`` the surface's closest-point projection
(``Surface.project``), until ``x_k`` lies within :data:`FINISH_RADIUS` grid spacings of a source,
whose position ends the path.

``∇u`` is the multilinear interpolant of the central differences of ``u`` at the band nodes
(the difference of the interpolated ``u`` one grid spacing either side of the point), which is
continuous from cell to cell; the extension equation (8) makes ``u`` constant along the normals
in the extension layer, so ``∇u`` is tangent to the surface up to the scheme's error. Where two
fronts meet ``u`` has a kink, and there one-sided differences are taken (see :func:`_gradient`)
so that a path leaves the kink instead of running along it. The paths' lengths are first-order
accurate (measured against great circles and exact polyhedral geodesics: docs/paths-and-labels.md).

A path stops early, with a :class:`RuntimeWarning`, where ``∇u`` vanishes, leaves the band, or
``u`` stops decreasing for :data:`STALL_STEPS` steps, and after ``max_steps`` steps.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any, List, Optional, Tuple

import numpy as np

from ._validate import as_points
from ._sources import SOURCE_RADIUS, beyond_inner_tube
from ._warn import user_stacklevel

if TYPE_CHECKING:  # pragma: no cover
    from .solution import Solution

__all__ = ["trace_paths"]

#: The smallest step, in grid spacings (a path takes about length / (step·Δx) steps, each a few
#: NumPy calls and two projections).
MIN_STEP = 0.01

#: Steps in a row without a decrease of ``u`` after which a path is declared stalled.
STALL_STEPS = 8

#: A step makes progress when it lowers u by more than this fraction of ``step·Δx·|∇u|``, the
#: decrease expected of it (see :data:`STALL_STEPS`).
PROGRESS_FRACTION = 1e-3

#: A path ends with a straight segment to a source once it is this many grid spacings from it
#: (the radius of the nodes a source fixes, ``solve.SOURCE_RADIUS``: there u is the exact
#: distance, and a gradient stencil that straddles the source's cone points poorly).
FINISH_RADIUS = SOURCE_RADIUS

#: A stalled path whose end lies within this many grid spacings (plus half the gap) of the midpoint
#: of a pair of band nodes across a gap narrower than the tubes (``Solution.narrow_gaps``) is
#: reported as stopped at such a gap: of the paths that stalled on Spot at grid 81 and the bunny
#: at grid 101 every one did, and 8 of 10 on the bunny at grid 201 (``benches/experiments/facing_gaps.py``).
GAP_REACH = 3.0


class _SourceFinder:
    """Which source, if any, lies within ``radius`` of each point: the sources bucketed in cubes
    of side ``radius`` over the grid's box, and each point checks the 3^d cubes around its own."""

    def __init__(self, grid: Any, sources: np.ndarray, radius: float):
        self.lower = np.asarray(grid.lower, dtype=float)
        self.cell = float(radius)
        # cubes over the box, two more on every side (points and sources may lie a little outside)
        self.dims = np.ceil((np.asarray(grid.upper, dtype=float) - self.lower) / self.cell).astype(np.int64) + 5
        self.sources = sources
        self.radius = radius
        keys = self._keys(self._cubes(sources))
        self.order = np.argsort(keys, kind="stable")
        self.keys = keys[self.order]
        d = grid.ndim
        self.offsets = np.stack(np.meshgrid(*([np.arange(-1, 2)] * d), indexing="ij"), axis=-1).reshape(-1, d)

    def _cubes(self, points: np.ndarray) -> np.ndarray:
        return np.floor((points - self.lower) / self.cell).astype(np.int64)

    def _keys(self, cubes: np.ndarray) -> np.ndarray:
        c = np.clip(cubes + 2, 0, self.dims - 1)
        key = np.zeros(len(c), dtype=np.int64)
        for k in range(c.shape[1]):
            key = key * self.dims[k] + c[:, k]
        return key

    def within(self, points: np.ndarray) -> np.ndarray:
        """Index of the nearest source within ``radius`` of each point (M,), -1 where none."""
        m, d = points.shape
        base = self._cubes(points)
        keys = self._keys((base[:, None, :] + self.offsets[None, :, :]).reshape(-1, d))
        lo = np.searchsorted(self.keys, keys, "left")
        count = np.searchsorted(self.keys, keys, "right") - lo
        owner = np.repeat(np.arange(m), len(self.offsets))
        best = np.full(m, -1, dtype=np.int64)
        best_d = np.full(m, np.inf)
        for j in range(int(count.max(initial=0))):
            has = np.flatnonzero(count > j)
            cand = self.order[lo[has] + j]
            who = owner[has]
            dist = np.linalg.norm(points[who] - self.sources[cand], axis=1)
            near = dist <= self.radius
            who, cand, dist = who[near], cand[near], dist[near]
            if who.size == 0:
                continue
            # per point the nearest candidate (then the lowest index), against the best so far
            first = np.lexsort((cand, dist, who))
            who, cand, dist = who[first], cand[first], dist[first]
            lead = np.r_[True, who[1:] != who[:-1]]
            who, cand, dist = who[lead], cand[lead], dist[lead]
            better = (dist < best_d[who]) | ((dist == best_d[who]) & (cand < best[who]))
            best[who[better]], best_d[who[better]] = cand[better], dist[better]
        return best


class _CellLabels:
    """Whether the interpolation stencil of a point (the 2^d corners of its cell) lies wholly in
    one source's region: with several sources u = min_k u_k has a kink where two regions meet,
    and a difference across it mixes the two fronts' gradients."""

    def __init__(self, sol: "Solution"):
        self.sol = sol
        self.labels = sol.nearest_source()
        d = sol.grid.ndim
        self.corners = np.stack(np.meshgrid(*([np.arange(2)] * d), indexing="ij"), axis=-1).reshape(-1, d)

    def clean(self, x: np.ndarray, target: np.ndarray) -> np.ndarray:
        """(M,) True where x lies in the grid and every corner of its cell is a band node labelled
        ``target`` (a point outside the grid is never clean: its difference is NaN)."""
        grid = self.sol.grid
        base = grid.cell_index(x)
        corners = (base[None, :, :] + self.corners[:, None, :]).reshape(-1, x.shape[1])
        pos = self.sol._band.find(np.ascontiguousarray(corners)).reshape(len(self.corners), len(x))
        inside = grid.contains(x, tol=0.0)
        return inside & np.all((pos >= 0) & (self.labels[np.maximum(pos, 0)] == target[None, :]), axis=0)


def _gradient(
    sol: "Solution",
    x: np.ndarray,
    u0: np.ndarray,
    cells: Optional[_CellLabels] = None,
    target: Optional[np.ndarray] = None,
) -> np.ndarray:
    """∇u at points (M, d) where u is ``u0``: per axis the central difference of the interpolated
    u one grid spacing either side (the multilinear interpolant of the nodes' central
    differences). Two cases take a one-sided difference instead, so that the path leaves a kink
    of u for one side rather than running along it: with several sources, where the stencil
    reaches into another source's region on one side only (``cells``, ``target``: the region the
    path descends in), the other side's; and across a ridge of u (u larger at the point than on
    both sides: two fronts meet there), the steeper side's. Where one side of the stencil
    leaves the band or the grid, the other side's difference; NaN where both do."""
    h = sol.grid.spacing
    m, d = x.shape
    shifted = np.empty((2 * d, m, d))
    for k in range(d):
        shifted[2 * k] = x
        shifted[2 * k, :, k] += h
        shifted[2 * k + 1] = x
        shifted[2 * k + 1, :, k] -= h
    u = sol._at(shifted.reshape(-1, d)).reshape(2 * d, m)
    g = np.empty((m, d))
    clean = None
    if cells is not None and target is not None:
        clean = cells.clean(shifted.reshape(-1, d), np.tile(target, 2 * d)).reshape(2 * d, m)
    for k in range(d):
        ahead, behind = u[2 * k] - u0, u0 - u[2 * k + 1]
        ridge = (ahead < 0) & (behind > 0)
        g[:, k] = np.where(ridge, np.where(-ahead > behind, ahead, behind) / h, (ahead + behind) / (2 * h))
        # one side of the stencil outside the band or the grid: the other side's difference
        g[:, k] = np.where(
            np.isnan(ahead) & ~np.isnan(behind),
            behind / h,
            np.where(np.isnan(behind) & ~np.isnan(ahead), ahead / h, g[:, k]),
        )
        if clean is not None:
            fwd, bwd = clean[2 * k], clean[2 * k + 1]
            g[:, k] = np.where(fwd & ~bwd, ahead / h, np.where(bwd & ~fwd, behind / h, g[:, k]))
    return g


def _onto_surface(sol: "Solution", x: np.ndarray) -> np.ndarray:
    """The surface's closest points to ``x``, projected twice: a level set's projection is a
    Newton step along its gradient, whose second application takes the point from O(Δx²·|φ|) of
    the surface to rounding (an exact closest-point map returns its own points unchanged)."""
    grid = sol.grid
    _, y = sol.surface.project(x, grid)
    _, y = sol.surface.project(np.ascontiguousarray(y, dtype=float), grid)
    return np.ascontiguousarray(y, dtype=float)


def _near_narrow_gaps(sol: "Solution", ends: np.ndarray) -> int:
    """How many of the points ``ends`` (M, d) lie within :data:`GAP_REACH` grid spacings of a pair
    of band nodes across a gap narrower than the tubes (``Solution.narrow_gaps``), measured to the
    pair's midpoint with half its gap added (the midpoint lies in the middle of the gap, and a
    path stalls on either side of it). The midpoints are bucketed in cubes of the largest reach,
    so each end looks at 3^d cubes."""
    mid, gap = sol.narrow_gaps()
    if mid.size == 0 or ends.size == 0:
        return 0
    reach = GAP_REACH * sol.grid.spacing + 0.5 * gap
    side = float(reach.max())
    buckets: dict = {}
    for i, cell in enumerate(map(tuple, np.floor(mid / side).astype(np.int64))):
        buckets.setdefault(cell, []).append(i)
    d = mid.shape[1]
    offsets = np.stack(np.meshgrid(*([np.arange(-1, 2)] * d), indexing="ij"), -1).reshape(-1, d)
    near = 0
    for end, cell in zip(ends, np.floor(ends / side).astype(np.int64)):
        idx = [i for off in offsets for i in buckets.get(tuple(cell + off), ())]
        if idx and np.any(np.linalg.norm(mid[idx] - end, axis=1) <= reach[idx]):
            near += 1
    return near


def starts_beyond_inner_tube(
    surface: Any, grid: Any, points: np.ndarray, inner: float
) -> Tuple[np.ndarray, np.ndarray]:
    """The indices of the ``points`` (M, d) farther from the surface than the inner tube
    (``inner`` grid spacings), where a path cannot start, and every point's distance."""
    dist, _ = surface.project(points, grid)
    return np.flatnonzero(~(dist <= inner * grid.spacing * (1 + 1e-6))), dist


def trace_paths(
    sol: "Solution", starts: Any, *, step: float = 0.5, max_steps: Optional[int] = None
) -> List[np.ndarray]:
    """Polylines (P_i, d) from each start (projected onto the surface) to the source that reaches
    it first, by steps of ``step`` grid spacings against ∇u (see the module's docstring).

    Raises ``ValueError`` for a solution of an anisotropic Hamiltonian, a ``step`` outside
    [MIN_STEP, 1], a start farther from the surface than the inner tube, outside the band, or not
    reached by any source, and when the surface's φ array was changed after the solve.
    """
    sol._check_surface_unchanged()
    if not sol._isotropic:
        raise ValueError(
            f"geodesic paths need an isotropic Hamiltonian (godunov, lxf or Isotropic()); this solution is "
            f"{sol.hamiltonian!r}, whose fastest paths do not run against ∇u"
        )
    if isinstance(step, (bool, np.bool_)) or not (
        isinstance(step, (int, float, np.floating, np.integer)) and MIN_STEP <= float(step) <= 1.0
    ):
        raise ValueError(f"step must be a number of grid spacings in [{MIN_STEP}, 1]; got {step!r}")
    grid = sol.grid
    h = grid.spacing
    d = grid.ndim
    p = as_points(starts, d, "starts")
    if max_steps is None:
        # far longer than any path that stays in the grid: each step goes s·(1 − O(Δx)) along it
        max_steps = int(np.ceil(8 * sum(grid.shape) / float(step)))
    elif isinstance(max_steps, (bool, np.bool_)) or not (isinstance(max_steps, (int, np.integer)) and max_steps >= 1):
        raise ValueError(f"max_steps must be a positive integer; got {max_steps!r}")
    far, dist = starts_beyond_inner_tube(sol.surface, grid, p, sol.inner)
    x = _onto_surface(sol, p)
    if far.size:
        i = int(far[0])
        raise ValueError(
            f"{beyond_inner_tube(f'starts[{i}]', p[i], dist[i])} ({sol.inner:g} grid spacings = {sol.inner * h:.4g}); "
            "start the path on the surface"
        )
    u = sol._at(x)
    for i in np.flatnonzero(~np.isfinite(u)):  # type: ignore[assignment]
        raise ValueError(
            f"starts[{int(i)}] = {tuple(float(v) for v in p[i])} "
            + (
                "is not reached by any source (another component of the surface)"
                if u[i] == np.inf
                else "lies where the solution is not defined (outside the band or the grid)"
            )
        )
    src = _onto_surface(sol, np.asarray(sol.sources, dtype=float))
    s = float(step) * h
    # a path ends once it is within FINISH_RADIUS grid spacings of a source, with a straight last
    # segment: closer in, the stencil of the gradient straddles the source's cone
    finder = _SourceFinder(grid, np.ascontiguousarray(src, dtype=float), FINISH_RADIUS * h)
    paths: List[List[np.ndarray]] = [[x[i].copy()] for i in range(len(x))]
    active = np.arange(len(x))
    cur, ucur = x.copy(), u.copy()
    # with several sources each path descends in the region of the source that reaches its start first
    cells = _CellLabels(sol) if len(sol.sources) > 1 else None
    target = sol.nearest_source(x) if cells is not None else None
    best_u = u.copy()
    no_progress = np.zeros(len(x), dtype=np.int64)
    stalled: List[int] = []
    for taken in range(max_steps + 1):
        if active.size == 0:
            break
        arrived = finder.within(cur[active])
        done = arrived >= 0
        for i, k in zip(active[done], arrived[done]):
            if np.linalg.norm(paths[i][-1] - src[k]) > 0:
                paths[i].append(src[k].copy())
        active = active[~done]
        if active.size == 0 or taken == max_steps:
            break
        g = _gradient(sol, cur[active], ucur[active], cells, None if cells is None else target[active])  # type: ignore[index]
        gn = np.linalg.norm(g, axis=1)
        bad = ~(gn > 0) | ~np.all(np.isfinite(g), axis=1)
        stalled.extend(int(i) for i in active[bad])
        active = active[~bad]
        if active.size == 0:
            break
        g, gn = g[~bad], gn[~bad]
        nxt = _onto_surface(sol, cur[active] - (s / gn)[:, None] * g)
        un = sol._at(nxt)
        lost = ~np.isfinite(un)
        stalled.extend(int(i) for i in active[lost])
        keep = ~lost
        active, nxt, un, gn = active[keep], nxt[keep], un[keep], gn[keep]
        for i, q in zip(active, nxt):
            paths[i].append(q.copy())
        cur[active], ucur[active] = nxt, un
        # progress is a decrease of at least PROGRESS_FRACTION of the step's expected s·|∇u|: a
        # path caught where u barely varies (decreases at the rounding level) stalls instead of
        # running on in place until max_steps
        better = un < best_u[active] - PROGRESS_FRACTION * s * gn
        best_u[active] = np.where(better, un, best_u[active])
        no_progress[active] = np.where(better, 0, no_progress[active] + 1)
        stuck = no_progress[active] >= STALL_STEPS
        stalled.extend(int(i) for i in active[stuck])
        active = active[~stuck]
    if stalled:
        at_gaps = _near_narrow_gaps(sol, np.array([paths[i][-1] for i in stalled]))
        gaps_note = ""
        if at_gaps:
            gaps_note = (
                f"; {at_gaps} of them stopped within {GAP_REACH:g} grid spacings of a gap narrower than the tubes, "
                "where the front can cross from another part of the surface (sol.narrow_gaps(), "
                "sol.stats.facing_pairs): refine the grid there"
            )
        warnings.warn(
            f"{len(stalled)} geodesic path(s) stopped before reaching a source (first: starts[{min(stalled)}]): "
            "the gradient of u vanished, left the band, or u stopped decreasing (a cut locus or a region the "
            f"scheme resolves poorly); refine the grid or start elsewhere{gaps_note}",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    if active.size:
        warnings.warn(
            f"{active.size} geodesic path(s) did not reach a source within max_steps = {max_steps} steps "
            f"(first: starts[{int(active[0])}]); increase max_steps",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return [np.asarray(path) for path in paths]
