"""``order=2`` near point sources: a second-order solution is ``u = u₀ + w`` with ``u₀`` the
chord distance to the nearest source (docs/second-order.md); :class:`~tubesweep.solution.Solution`
evaluates it here so that the source's cone is not interpolated. Below both ``solution`` and
``second_order`` (which solves and sets ``Solution._factoring``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _native
from ._interpolation import interpolate_band

#: ``sol(points)`` evaluates ``w + σ|cp(P) − x_s|`` (interpolated ``w = u − u₀``) at points within
#: this many grid spacings of a source at least: the value at a source is exactly 0.
FACTORED_RADIUS = 3.0

#: ... and within this many curvature radii 1/κ (κ the largest principal curvature found in the
#: tube). Multilinear interpolation errs by about Δx²/8 times the second derivative: u's across the
#: geodesic, cot(κr)κ on a sphere (the source's cone, 1/r near it), against w's (w = u − u₀, the
#: geodesic minus the chord: about rκ²/4). They cross at r ≈ 1.26/κ, a chord of ≈ 1.2/κ; beyond,
#: u itself is interpolated (its curvature falls to 0 at the source's equator, w's does not).
#: Surfaces only: on a curve the distance along it has no cone beyond the source's own kink.
FACTORED_CURVATURE_RADII = 1.2


def factored_reach(spacing: float, max_curvature: float, ndim: int) -> float:
    """The distance from a source within which ``sol(points)`` evaluates the factored form (on
    surfaces whose closest points are known to rounding: the solver passes ``FACTORED_RADIUS``
    grid spacings for a sampled φ)."""
    reach = FACTORED_RADIUS * spacing
    if ndim == 3 and max_curvature > 0 and np.isfinite(max_curvature):
        reach = max(reach, FACTORED_CURVATURE_RADII / max_curvature)
    return reach


def factored_values(sol: Any, p: np.ndarray, values: np.ndarray, interpolation: str = "linear") -> np.ndarray:
    """``sol(points)`` of a second-order solution near a point source: ``w = u − u₀``
    interpolated plus ``σ_s |cp(P) − x_s|`` (``u₀`` at the point: the chord from the source to
    its closest point on the surface, the point itself when it is on the surface) at the points
    within :func:`factored_reach` of a source, so that the source's cone is not interpolated (the
    value at a source is exactly 0). The sources near a point are found with a kd-tree in the
    core (``tubesweep_core::solution::source_feet``): nothing of size points × sources, and the
    same operations as ``Tube.solve_many``'s evaluation, bit for bit."""
    u0, feet, slowness, reach = sol._factoring
    grid = sol.grid
    h = grid.spacing
    if len(p) == 0:
        return values
    # (points off the band read NaN as before: their closest points are not asked for, a map
    # may be undefined there)
    close = np.isfinite(values)
    if np.any(close):
        close[close] = _native.source_feet_within(feet, slowness, np.ascontiguousarray(p[close]), float(reach))
    if np.any(close):
        q = np.ascontiguousarray(p[close])
        # the points' closest points: the point itself when it is on the surface (to rounding). A
        # point off the surface read the chord from itself: a source given on a voxel mask's
        # surface, which its smoothed φ places half a voxel away, read Δx/2 at the source
        d_surface, foot = sol.surface.project(q, grid)
        foot = np.where((d_surface <= 1e-9 * h)[:, None], q, foot)
        chord = _native.source_feet_chords(feet, slowness, np.ascontiguousarray(foot, dtype=float))
        w = interpolate_band(sol._band, sol.values - u0, grid, q, interpolation)
        # never negative: w interpolated at a source rounds to ±1e-21 (the chord is 0 there)
        values[close] = np.maximum(w + chord, 0.0)
    return values


#: Sources whose slownesses differ by less than this factor are not checked by
#: :func:`undercut_sources` (within it a source's cone undercuts another's fixed nodes by at most
#: 1e-3 of the fix radius's travel time).
UNDERCUT_SLOWNESS_RATIO = 1.0 + 1e-3


def undercut_sources(feet: np.ndarray, slowness: np.ndarray, fix_radius: float) -> Any:
    """Why ``order=2``'s factoring cannot take several sources at these speeds, or None. Each node
    takes ``u₀ = min_s σ_s |cp − x_s|`` (the chord from the nearest source by travel time at its
    own slowness) and the nodes within ``fix_radius`` of a source are fixed at that value: where a
    faster source's cone reaches a slower source's fixed nodes with a smaller value, they are fixed
    too low, and everything downstream follows (two sources on a sphere, the speed 100 times
    higher on one's side: values near the slower source 0.010 for a distance of 0.05, at N = 61,
    labelled second order). That happens for sources ``s``, ``t`` with ``σ_s < σ_t`` and
    ``|x_s − x_t| < r (σ_s + σ_t) / σ_s``, r the fix radius. O(S²) for S sources (in blocks)."""
    feet = np.asarray(feet, dtype=float)
    sigma = np.asarray(slowness, dtype=float)
    if len(sigma) < 2 or np.max(sigma) <= UNDERCUT_SLOWNESS_RATIO * np.min(sigma):
        return None
    block = max(1, 4_000_000 // len(sigma))
    for start in range(0, len(sigma), block):
        t = slice(start, start + block)
        d = np.linalg.norm(feet[t, None, :] - feet[None, :, :], axis=-1)  # (b, S): target t, source s
        faster = sigma[None, :] * UNDERCUT_SLOWNESS_RATIO < sigma[t, None]
        reach = fix_radius * (sigma[None, :] + sigma[t, None]) / sigma[None, :]
        hit = np.argwhere(faster & (d < reach))
        if hit.size:
            i, j = int(hit[0, 0]) + start, int(hit[0, 1])
            ratio = sigma[i] / sigma[j]
            where = tuple(round(float(c), 4) for c in feet[i])
            return (
                f"order=2 factors the travel time from each source at its own speed, and the source at {where} is "
                f"{ratio:.3g} times slower than one {float(d[hit[0, 0], j]):.3g} away, whose factor would fix the nodes "
                f"around it too low (the second-order factoring holds for sources whose speeds differ by less than "
                f"{UNDERCUT_SLOWNESS_RATIO - 1:.0e}, or that lie more than {fix_radius * (ratio + 1):.3g} apart). "
                "order=1, the paper's scheme, solves it; so does solving each source apart and taking the minimum"
            )
    return None
