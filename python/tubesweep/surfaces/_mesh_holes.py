"""The holes of an open mesh (its boundary loops) against the grid's band.

The two-layer method (Algorithm 3) solves in a band of ``outer`` grid spacings around the surface,
its inner tube reading the extension nodes around it. Where the mesh has a hole narrower than
the band (``2·outer`` spacings: a scan's gap, a sensor's blind spot, a hole punched to test a
solver), the band spans it and the front crosses it: a distance reached across the hole is that
of the surface with the hole filled, shorter than the mesh's own geodesic round it (a sphere of
radius 0.6 with three holes 0.108 wide, ``benches/experiments/mesh_holes.py``: below the holes
0.027–0.046 off at N = 41–101, where the band spans them, 0.014–0.017 at N = 121 and 161, where
it does not; elsewhere at most 0.003–0.01). Nothing inside the band can tell that the nodes over
the hole are not on the surface, so the solve reports them (``sol.stats.bridged_holes``) and
warns where the detour round one is large (:data:`WARN_SHARE`).

A hole is also not a gap between two sheets. The facing tests (``_mesh_smooth.facing_pairs``, the
tube's ``Band.facing_sheet_pairs``) find node pairs over a hole as two sides facing each other,
and such pairs sent the whole solve to first order as if the mesh faced itself across a gap
(the sphere above at N = 41, 81, 101 and 121: mean errors 2.7e-2 to 6.1e-3 away from the holes,
where second order gives 2.2e-4 to 7.9e-5). :func:`across_holes` tells those pairs apart: both
nodes' closest points lie on the mesh's boundary.

Each boundary component (boundary edges joined at their vertices) is a loop; its width is the
smallest width of the convex hull of its vertices in their best-fitting plane (a circle's
diameter), and it is a hole when the hull's centre lies off the mesh by more than a quarter of
that width (an open surface's outline around a strip, whose centre lies on the strip, is not; nor
is a straight crack, whose centre lies on its own edge: a limitation).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .._warn import user_stacklevel
from ._mesh_checks import unique_edges

#: The share of the width by which the hull's centre must lie off the mesh for a loop to be a
#: hole (an open surface's outer edge around a strip narrower than the tube has its centre on it).
HOLE_CENTRE = 0.25


#: The warning is given when a bridged hole's detour (:class:`Holes`) exceeds this share of the
#: mesh's size (its bounding box's diagonal, about its largest geodesic distance), as the
#: first-order size warnings from 10% of the largest distance; ``sol.stats.bridged_holes`` reports
#: every one. (The bundled bunny's base has a slot 0.0085 wide whose detour, 0.023, is 9.2% of its
#: size; the errors next to it at n = 60–200 are no larger than elsewhere, 1.5–4.6 spacings.)
WARN_SHARE = 0.1


@dataclass(frozen=True)
class Holes:
    """The holes of a mesh: per hole its width (the convex hull's smallest width in the loop's
    plane), its detour (half the hull's perimeter less its width: how much longer a geodesic
    round the hole is than one across it, at most; 0.57 widths for a round hole), its centre
    (the hull's centroid, in 3D) and its number of boundary vertices."""

    width: np.ndarray
    detour: np.ndarray
    centre: np.ndarray
    vertices: np.ndarray


def boundary_edges(faces: np.ndarray) -> np.ndarray:
    """The mesh's boundary edges ``(E, 2)``: the edges of exactly one triangle (triangles that name a
    vertex twice left out, as ``MeshSurface`` counts them)."""
    f = np.asarray(faces, dtype=np.int64)
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    if len(f) == 0:
        return np.zeros((0, 2), np.int64)
    ids, counts = unique_edges(f)
    once = counts[ids] == 1  # (faces, 3): the AB, AC, BC edges used once
    ends = np.stack([f[:, [0, 1]], f[:, [0, 2]], f[:, [1, 2]]], axis=1)  # (faces, 3, 2)
    return np.sort(ends[once], axis=1)


def _loops(n_vertices: int, edges: np.ndarray) -> list:
    """The boundary vertices grouped by connected component of the boundary edges."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    on = np.unique(edges)
    index = np.full(n_vertices, -1, np.int64)
    index[on] = np.arange(on.size)
    a, b = index[edges[:, 0]], index[edges[:, 1]]
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(on.size, on.size))
    _, label = connected_components(graph, directed=False)
    order = np.argsort(label, kind="stable")
    splits = np.flatnonzero(np.diff(label[order])) + 1
    return [on[g] for g in np.split(order, splits)]


def _hull_width(points: np.ndarray) -> tuple:
    """The smallest width of the convex hull of ``points`` (3D) in their best-fitting plane, its
    perimeter, and its centroid in 3D."""
    from scipy.spatial import ConvexHull, QhullError

    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    flat = (points - centre) @ vt[:2].T
    try:
        hull = ConvexHull(flat)
    except (QhullError, ValueError):  # collinear (a slit of zero width) or fewer than three
        span = float(np.ptp(flat[:, 0])) if len(flat) else 0.0
        return 0.0, 2.0 * span, centre
    ring = flat[hull.vertices]
    widths = []
    for i in range(len(ring)):
        p, q = ring[i], ring[(i + 1) % len(ring)]
        t = q - p
        n = np.array([-t[1], t[0]]) / max(float(np.hypot(t[0], t[1])), 1e-300)
        widths.append(float(np.max(np.abs((ring - p) @ n))))
    # the centroid of the hull's area (the mean of the ring's vertices leans towards dense ones)
    x, y = ring[:, 0], ring[:, 1]
    xs, ys = np.roll(x, -1), np.roll(y, -1)
    cross = x * ys - xs * y
    area = cross.sum() / 2.0
    if abs(area) > 0:
        c2 = np.array([((x + xs) * cross).sum(), ((y + ys) * cross).sum()]) / (6.0 * area)
    else:
        c2 = ring.mean(axis=0)
    perimeter = float(np.sum(np.hypot(xs - x, ys - y)))
    return min(widths), perimeter, centre + c2 @ vt[:2]


def holes(surface: Any) -> Holes:
    """The holes of ``surface`` (a ``MeshSurface``), computed once per mesh."""
    cached: Optional[Holes] = surface.__dict__.get("_holes")
    if cached is not None:
        return cached
    found = Holes(np.zeros(0), np.zeros(0), np.zeros((0, 3)), np.zeros(0, np.int64))
    edges = np.zeros((0, 2), np.int64) if surface.closed else boundary_edges(surface.faces)
    if len(edges):
        v = surface.vertices
        widths, detours, centres, counts = [], [], [], []
        for loop in _loops(len(v), edges):
            width, perimeter, centre = _hull_width(v[loop])
            widths.append(width)
            detours.append(max(perimeter / 2.0 - width, 0.0))
            centres.append(centre)
            counts.append(loop.size)
        width_a, centre_a = np.asarray(widths), np.asarray(centres)
        hole = surface.closest(centre_a)[0] > HOLE_CENTRE * width_a
        found = Holes(width_a[hole], np.asarray(detours)[hole], centre_a[hole], np.asarray(counts, np.int64)[hole])
    surface.__dict__["_holes"] = found
    return found


def bridged(surface: Any, h: float, outer: float) -> Optional[dict]:
    """The holes of ``surface`` that the band of spacing ``h`` and width ``outer`` spans, as
    ``sol.stats.bridged_holes``: ``count``, ``widest`` (the widest one's width), ``reach`` (the
    band's span, ``2·outer·h``), ``detour`` (the largest :class:`Holes` detour among them: how
    much shorter a distance reached across one can come out), ``where`` (that hole's centre) and
    ``size`` (the surface's bounding-box diagonal); None when there are none."""
    found = holes(surface)
    reach = 2.0 * outer * h
    narrow = found.width < reach
    if not np.any(narrow):
        return None
    k = int(np.argmax(found.detour[narrow]))
    v = surface.vertices
    return {
        "count": int(np.count_nonzero(narrow)),
        "widest": float(np.max(found.width[narrow])),
        "reach": float(reach),
        "detour": float(found.detour[narrow][k]),
        "where": tuple(round(float(c), 6) for c in found.centre[narrow][k]),
        "size": float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))),
    }


def bridged_holes(surface: Any, h: float, outer: float) -> Optional[dict]:
    """:func:`bridged`, warned (:func:`warn_bridged_holes`): ``MeshSurface._bridged_holes``, read
    by the tube's preparation."""
    info = bridged(surface, h, outer)
    warn_bridged_holes(info, h, outer)
    return info


def warn_bridged_holes(info: Optional[dict], h: float, outer: float) -> None:
    """The warning for :func:`bridged`'s holes, when the largest detour is over
    :data:`WARN_SHARE` of the mesh's size."""
    if info is None or info["detour"] <= WARN_SHARE * info["size"]:
        return
    spacing = info["widest"] / (2.0 * outer)
    finer = f"a grid spacing below {spacing:.3g} (now {h:.3g}) keeps them open, or " if spacing > 0 else ""
    warnings.warn(
        f"the mesh has {info['count']} hole(s) narrower than its band ({info['reach']:.3g} across at this grid; "
        f"the widest {info['widest']:.3g}): the band bridges them, and a distance reached across one is that of "
        f"the surface with the hole filled, up to {info['detour']:.3g} ({info['detour'] / info['size']:.0%} of the "
        f"mesh's size) shorter than the mesh's geodesic round it (near {info['where']}). sol.stats.bridged_holes has "
        f"them; {finer}fill them first (e.g. trimesh.repair.fill_holes) where they are gaps in a scan",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def across_holes(surface: Any, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """For node pairs (points ``first[i]``, ``second[i]``, ``(M, 3)``) that a facing test found:
    whether both nodes' closest points lie on the mesh's boundary, so that the pair lies over a
    hole (or beyond an outer edge) rather than across a gap between two sheets."""
    if surface.closed or len(first) == 0:
        return np.zeros(len(first), bool)
    on_rim = boundary_mask(surface)
    return on_rim(np.asarray(first, float)) & on_rim(np.asarray(second, float))


def pairs_over_holes(surface: Any, grid: Any, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """:func:`across_holes` for node pairs given by their linear indices on ``grid``:
    ``MeshSurface._pairs_over_holes``, read by the tube's preparation (``_prepare``), which leaves
    such pairs out of the facing pairs (no warning, no cut, not in ``sol.stats.facing_pairs``)."""
    return across_holes(surface, grid.node_points(first), grid.node_points(second))


def boundary_mask(surface: Any) -> Any:
    """A function of points ``(M, 3)`` giving whether each one's exact closest point on the mesh
    lies on a boundary edge or vertex (feature codes of ``closest_points_on_triangles``)."""
    from ._triangle_projection import EDGE_AB, EDGE_AC, EDGE_BC, VERT_A, VERT_B, VERT_C

    f = np.asarray(surface.faces, dtype=np.int64)
    edges = boundary_edges(f)
    rim_vertex = np.zeros(len(surface.vertices), bool)
    rim_vertex[edges.ravel()] = True
    n = len(surface.vertices)
    keys = np.sort(edges[:, 0] * n + edges[:, 1]) if len(edges) else np.zeros(0, np.int64)

    def is_rim_edge(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if keys.size == 0:
            return np.zeros(len(a), bool)
        key = np.minimum(a, b) * n + np.maximum(a, b)
        pos = np.minimum(np.searchsorted(keys, key), keys.size - 1)
        return np.asarray(keys[pos] == key)

    def on_rim(x: np.ndarray) -> np.ndarray:
        _, _, face, code = surface.closest(x)
        out = np.zeros(len(x), bool)
        ok = face >= 0
        tri = f[np.maximum(face, 0)]
        for c, corner in ((VERT_A, 0), (VERT_B, 1), (VERT_C, 2)):
            sel = ok & (code == c)
            out[sel] = rim_vertex[tri[sel, corner]]
        for c, (i, j) in ((EDGE_AB, (0, 1)), (EDGE_AC, (0, 2)), (EDGE_BC, (1, 2))):
            sel = ok & (code == c)
            out[sel] = is_rim_edge(tri[sel, i], tri[sel, j])
        return out

    return on_rim
