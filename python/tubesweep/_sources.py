"""Point sources on the surface: the exact local initialisation of the inner-tube nodes near each
source (docs/source-initialisation.md)."""

from __future__ import annotations

import warnings
from typing import Any, Callable, List, Optional, Tuple

import numpy as np

from .grid import Grid
from .surface import Surface
from ._roles import ROLE_INNER
from ._warn import user_stacklevel
from ._validate import checked_point_speeds, speed_at_points

#: With ``source_init="exact"``, inner-tube nodes whose closest point lies within this many grid
#: spacings of a source are fixed to the exact local distance ``|cp(x) − x_s|`` times the mean
#: slowness.
SOURCE_RADIUS = 2.0

#: A ``source_radius`` is refused where the chord distance the nodes within it are fixed to is
#: estimated to differ from the distance along the surface by more than this many grid spacings
#: (a tenth of a spacing: a small share of the first-order scheme's own error, which is of the
#: order of a spacing).
CHORD_TOLERANCE = 0.1


def how_far(distance: float) -> str:
    """How far a point is from the surface, for the messages that refuse it: +∞ is a projection
    that did not reach the zero level set (``redistance.redistanced_project``)."""
    if distance == np.inf:
        return (
            "is not near the surface (φ there does not lead to its zero level set: its slope vanishes, as deep inside a "
            "voxel mask or at a ball's centre, where a re-distanced φ is only known within its band)"
        )
    if np.isnan(distance):
        # a closest point that the surface could not give (a point cloud's fits find no surface
        # so far from the samples, at the centre of a sphere of them)
        return "is far from the surface (its closest point there is not defined: NaN)"
    return f"is {distance:.4g} from the surface"


def beyond_inner_tube(label: str, point: Any, distance: float) -> str:
    """The start of the messages that refuse a point off the surface: ``"label = (x, y, z) is d
    from the surface, farther than the inner tube"`` (each message goes on with its own cure)."""
    return f"{label} = {tuple(float(c) for c in point)} {how_far(float(distance))}, farther than the inner tube"


def check_on_surface(
    sources: np.ndarray, dist: np.ndarray, inner_width: float, names: Optional[List[str]] = None
) -> None:
    """Refuses a source farther from the surface than the inner tube (``dist``: the sources'
    distances to their closest points, ``inner_width``: inner·Δx; ``names[i]`` names source i in
    the message, ``sources[i]`` by default)."""
    # (NaN too: a closest point the surface could not give)
    far = np.flatnonzero(~(np.asarray(dist, dtype=float) <= inner_width * (1 + 1e-6)))
    if far.size:
        i = int(far[0])
        raise ValueError(
            f"{beyond_inner_tube(names[i] if names else f'sources[{i}]', sources[i], dist[i])} (inner·Δx = {inner_width:.4g}); put the source "
            "on the surface or increase `inner`"
        )


def slowness_on_surface(speed: Any, grid: Grid) -> Callable[[np.ndarray], np.ndarray]:
    """The slowness at points on the surface (a source, the closest points of the nodes near it)
    for the exact initialisation: a callable speed evaluated there, a constant one inverted, an
    array interpolated."""

    def at(p: np.ndarray) -> np.ndarray:
        if callable(speed):
            return 1.0 / speed_at_points(speed, p, "a source or the closest point of a node near it")
        if np.ndim(speed) == 0:
            return np.full(len(p), 1.0 / float(speed))
        from .euclidean import _interp_dense

        f = _interp_dense(np.asarray(speed, dtype=float), grid, p)
        return 1.0 / checked_point_speeds(f, p, "interpolated from the speed array next to a source")

    return at


def _fix_sources(
    surface: Surface,
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    sources: np.ndarray,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    source_init: str,
    inner_width: float,
    radius: float = SOURCE_RADIUS,
    connected: bool = False,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions in the band and values of the nodes fixed by the point sources, and the index of
    the source each node's value comes from (the nearest, where several sources fix one node).
    ``radius``: the exact initialisation's reach in grid spacings. ``connected`` (a band cut across
    narrow gaps, ``_shortcuts``): only the nodes joined to the node nearest the source through the
    band's edges within the ball are fixed, so that the chord does not reach across a gap to the
    other side of a thin part."""
    h = grid.spacing
    d = grid.ndim
    dist, proj = surface.project(sources, grid)
    check_on_surface(sources, dist, inner_width)
    if source_init == "node":
        return _fixed_at_nearest_nodes(grid, band, roles, sources)
    r = int(np.ceil(radius + inner_width / h)) + 1
    # the nodes around a source: a box of (2r + 1)^d offsets, or for a box larger than the band
    # (a large source_radius) the band's nodes within it: memory of the band's size, not the box's
    band_index = grid.unravel(linear) if (2 * r + 1) ** d > len(linear) else None
    offsets = (
        np.stack(np.meshgrid(*([np.arange(-r, r + 1)] * d), indexing="ij"), axis=-1).reshape(-1, d)
        if band_index is None
        else None
    )
    if offsets is not None and radius <= SOURCE_RADIUS:
        # the default: the sources in batches (one per source took 0.24 ms of Python, 61 s for
        # 200,000 sources against 8 s for the second-order solve)
        return _fixed_in_batches(
            surface, grid, band, linear, roles, sources, proj, slowness_at, radius, offsets, connected
        )
    best: dict = {}
    # the largest estimated chord error in the balls, and the shortest chord where it exceeds
    # CHORD_TOLERANCE spacings (checked below)
    chord_error, chord_fit = 0.0, np.inf
    for i, (s, sp) in enumerate(zip(sources, proj)):
        corner = np.floor(grid.continuous_index(s[None])[0]).astype(np.int64)
        if band_index is None:
            found = band.find(np.ascontiguousarray(corner + offsets))
            found = found[found >= 0]
        else:
            found = np.flatnonzero(np.all(np.abs(band_index - corner) <= r, axis=1))
        pos = found[roles[found] == ROLE_INNER]
        if pos.size == 0:
            raise ValueError(f"sources[{i}] has no inner-tube node near it; refine the grid or increase `inner`")
        x = grid.points(grid.unravel(linear[pos]))
        _, cp = surface.project(x, grid)
        geo = np.linalg.norm(cp - sp, axis=1)
        near = geo <= radius * h
        if not np.any(near):
            near = geo <= geo.min()
        if connected:
            near = _joined_to_nearest(band, pos, geo, near)
        if radius > SOURCE_RADIUS:
            err = _chord_errors(surface, grid, sp, cp[near], geo[near])
            if err.size:
                chord_error = max(chord_error, float(err.max()))
                over = err > CHORD_TOLERANCE * h
                if np.any(over):
                    chord_fit = min(chord_fit, float(geo[near][over].min()))
        slow = 0.5 * (slowness_at(cp[near]) + slowness_at(sp[None])[0])
        for p, v in zip(pos[near], geo[near] * slow):
            if p not in best or v < best[p][0]:
                best[p] = (v, i)
    positions = np.fromiter(best.keys(), dtype=np.int64, count=len(best))
    values = np.fromiter((v for v, _ in best.values()), dtype=float, count=len(best))
    labels = np.fromiter((k for _, k in best.values()), dtype=np.int64, count=len(best))
    if radius > SOURCE_RADIUS:
        _check_source_balls(grid, proj, radius * h, chord_error, chord_fit)
    return positions, values, labels


#: The nodes fixed by the sources: their band positions, values and sources' indices.
Fixed = Tuple[np.ndarray, np.ndarray, np.ndarray]

#: Sources per batch of :func:`_fixed_in_batches` (bounds the memory: a batch looks up
#: ``BATCH`` × (2r + 1)^d nodes, 1331 per source in 3D with the default widths).
BATCH = 512
#: At most this many node lookups per batch (``BATCH`` sources times the ball's offsets): the
#: batch's index, coordinate and mask arrays stay some tens of MB whatever ``inner`` (inner = 8
#: with 512 sources a batch held 3.6 million lookups, 375 MB at the peak)
LOOKUPS = 1 << 18


def _nearest_per_node(pos: np.ndarray, val: np.ndarray, src: np.ndarray) -> Fixed:
    """Per band position its smallest value and that value's source (the first source among
    equal values, as a loop over the sources in order that keeps a strictly smaller one)."""
    order = np.lexsort((src, val, pos))
    pos, val, src = pos[order], val[order], src[order]
    first = np.ones(len(pos), dtype=bool)
    first[1:] = pos[1:] != pos[:-1]
    return pos[first], val[first], src[first]


def _fixed_at_nearest_nodes(grid: Grid, band: Any, roles: np.ndarray, sources: np.ndarray) -> Fixed:
    """``source_init="node"``: the inner-tube node nearest each source, fixed to 0 (the first
    source of each node labels it)."""
    pos = np.asarray(band.find(np.ascontiguousarray(grid.nearest_index(sources))), dtype=np.int64)
    bad = np.flatnonzero((pos < 0) | (roles[np.maximum(pos, 0)] != ROLE_INNER))
    if bad.size:
        raise ValueError(
            f"sources[{int(bad[0])}]: the grid node nearest to the source is not in the inner tube; "
            "move the source onto the surface, refine the grid or increase `inner`"
        )
    return _nearest_per_node(pos, np.zeros(len(pos)), np.arange(len(pos), dtype=np.int64))


def _fixed_in_batches(
    surface: Surface,
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    sources: np.ndarray,
    proj: np.ndarray,
    slowness_at: Callable[[np.ndarray], np.ndarray],
    radius: float,
    offsets: np.ndarray,
    connected: bool,
) -> Fixed:
    """:func:`_fix_sources` with the default radius, :data:`BATCH` sources at a time: the
    inner-tube nodes in each source's box of ``offsets``, their closest points projected once per
    batch, the nodes within ``radius`` spacings of the source's foot ``proj`` (or the nearest,
    where none is; on a ``connected`` band those joined to it), fixed to the chord times the mean
    of the slownesses at the two ends, and per node the nearest source's value."""
    h = grid.spacing
    d = grid.ndim
    # only the offsets that can hold such a node: within the radius and the inner tube of the
    # foot (the box's half-width r is at least their sum plus one), from the corner of the
    # foot's cell, within √d spacings of it (58% of the box in 3D)
    reach = float(np.max(np.abs(offsets))) - 1 + np.sqrt(d)
    offsets = offsets[np.sum(offsets.astype(float) ** 2, axis=1) <= reach**2 + 1e-9]
    best: Fixed = (np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64))
    # (fewer sources per batch where the balls are wide: a wide inner tube)
    batch = max(1, min(BATCH, LOOKUPS // len(offsets)))
    for s0 in range(0, len(sources), batch):
        chunk = np.arange(s0, min(s0 + batch, len(sources)), dtype=np.int64)
        corner = np.floor(grid.continuous_index(proj[chunk])).astype(np.int64)
        found = np.asarray(band.find(np.ascontiguousarray((corner[:, None, :] + offsets[None]).reshape(-1, d))))
        found = found.reshape(len(chunk), -1)
        inner = found >= 0
        inner[inner] = roles[found[inner]] == ROLE_INNER
        empty = np.flatnonzero(~inner.any(axis=1))
        if empty.size:
            raise ValueError(
                f"sources[{int(chunk[empty[0]])}] has no inner-tube node near it; refine the grid or increase `inner`"
            )
        per = inner.sum(axis=1)
        which = np.repeat(chunk, per)  # each found node's source, in the sources' order
        pos = found[inner]
        # each node's closest point once (sources near one another share their nodes)
        unique, back = np.unique(pos, return_inverse=True)
        _, cp_unique = surface.project(grid.points(grid.unravel(linear[unique])), grid)
        cp = cp_unique[back.ravel()]
        geo = np.linalg.norm(cp - proj[which], axis=1)
        near = geo <= radius * h
        # a source none of whose nodes is within the radius: its nearest ones
        starts = np.concatenate([[0], np.cumsum(per)[:-1]])
        nearest = np.minimum.reduceat(geo, starts)
        without = ~np.logical_or.reduceat(near, starts)
        if np.any(without):
            near |= without[which - s0] & (geo <= nearest[which - s0])
        if connected:
            for a, n in zip(starts, per):
                near[a : a + n] = _joined_to_nearest(band, pos[a : a + n], geo[a : a + n], near[a : a + n])
        source_slowness = slowness_at(proj[chunk])
        slow = 0.5 * (slowness_at(cp[near]) + source_slowness[which[near] - s0])
        best = _nearest_per_node(
            np.concatenate([best[0], pos[near]]),
            np.concatenate([best[1], geo[near] * slow]),
            np.concatenate([best[2], which[near]]),
        )
    return best


def _joined_to_nearest(band: Any, pos: np.ndarray, geo: np.ndarray, near: np.ndarray) -> np.ndarray:
    """``near`` without the nodes that the band's edges within it do not join to the node whose
    closest point is nearest the source (a walk over the neighbour table of a cut band)."""
    chosen = np.flatnonzero(near)
    if chosen.size < 2:
        return near
    where = {int(p): j for j, p in enumerate(pos[chosen])}
    table = band.neighbours_of_nodes(np.ascontiguousarray(pos[chosen], dtype=np.int64))
    start = int(np.argmin(geo[chosen]))
    seen = {start}
    stack = [start]
    while stack:
        j = stack.pop()
        for q in table[j].ravel():
            k = where.get(int(q))
            if k is not None and k not in seen:
                seen.add(k)
                stack.append(k)
    out = np.zeros_like(near)
    out[chosen[sorted(seen)]] = True
    return out


def _chord_errors(surface: Surface, grid: Grid, foot: np.ndarray, cp: np.ndarray, chord: np.ndarray) -> np.ndarray:
    """The error of each chord ``|cp − foot|`` as the distance along the surface, estimated by
    Richardson extrapolation from the two chords through the surface point nearest the chord's
    midpoint (on a sphere of radius R the chord is short by c³/(24R²), the two chords by a
    quarter of it); non-finite estimates (a projection that failed) count as 0."""
    if len(cp) == 0:
        return np.empty(0)
    _, mid = surface.project(0.5 * (cp + foot[None, :]), grid)
    two = np.linalg.norm(mid - foot[None, :], axis=1) + np.linalg.norm(cp - mid, axis=1)
    err = (two - chord) * (4.0 / 3.0)
    return np.where(np.isfinite(err), err, 0.0)


def closest_pair(points: np.ndarray, within: float) -> Tuple[float, int, int]:
    """The distance between the two nearest of ``points`` (M ≥ 2) and their indices, when it is
    below ``within``; else ``(inf, -1, -1)``. Sorted along the axis of widest spread and swept:
    O(M) memory, and O(M log M) time unless many points crowd within ``within`` of one another
    along that axis (the K × K table of all the gaps took 1 GB at K = 4000 sources)."""
    axis = int(np.argmax(np.ptp(points, axis=0)))
    order = np.argsort(points[:, axis], kind="stable")
    p = points[order]
    best, bi, bj = np.inf, -1, -1
    for k in range(1, len(p)):
        limit = min(best, within)
        near = np.flatnonzero(p[k:, axis] - p[:-k, axis] < limit)
        if near.size == 0:
            break  # farther offsets only spread more along the sorted axis
        gaps = np.linalg.norm(p[near + k] - p[near], axis=1)
        m = int(np.argmin(gaps))
        if gaps[m] < limit:
            best, bi, bj = float(gaps[m]), int(order[near[m]]), int(order[near[m] + k])
    return best, bi, bj


def _check_source_balls(grid: Grid, feet: np.ndarray, reach: float, chord_error: float, chord_fit: float) -> None:
    """With a ``source_radius`` beyond the default: refuses a radius within which the chord is not
    the distance along the surface (the surface curves), and warns when the balls of two sources
    overlap (their nodes take the nearer source's chord, and the fronts' meeting line is not
    solved for)."""
    h = grid.spacing
    if chord_error > CHORD_TOLERANCE * h:
        # the shortest chord whose error exceeds the tolerance: a radius below it keeps every chord
        fit = chord_fit
        raise ValueError(
            f"source_radius = {reach:.4g} is too large for this surface: within it the straight (chord) distance "
            f"the nodes are fixed to differs from the distance along the surface by up to about {chord_error:.3g} "
            f"({chord_error / h:.2g} grid spacings; the surface curves within the radius). Use source_radius < "
            f"{fit:.3g}, or leave it out (the default, {SOURCE_RADIUS:g} grid spacings)"
        )
    if len(feet) > 1:
        gap, i, j = closest_pair(feet, 2.0 * reach)
        if gap < 2.0 * reach:
            warnings.warn(
                f"source_radius = {reach:.4g}: the balls of exact values around sources[{min(i, j)}] and "
                f"sources[{max(i, j)}] overlap (they are {gap:.4g} apart, less than twice the radius): the nodes "
                f"in both are fixed to the nearer chord and where the two fronts meet is not solved for. Use "
                f"source_radius < {0.5 * gap:.4g} to keep the sources' balls apart",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
