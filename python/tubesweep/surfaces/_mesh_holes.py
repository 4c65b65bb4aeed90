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

Each boundary component (boundary edges joined at their vertices) is a loop. Only simple loops
are judged (every vertex on two boundary edges; loops of a single missing triangle, a triangle
soup's, are left out, as are seams: loops whose vertices mostly come in coincident pairs, an
export's split). A loop's width is the smallest width of the convex hull of its vertices in their
best-fitting plane (a circle's diameter), its detour half the hull's perimeter less that width,
and it is a hole when the centre of its bounding box in that plane lies off the mesh by more
than a quarter of its width (an open surface's outline around a strip or a notched plate, whose
centre lies on the surface, is not). A pair over a hole is one whose two closest points lie on
the same hole: a notch in an outline or two sheets' edges facing each
other stay gaps. Not judged: loops through a vertex shared by two holes, and straight cracks.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .._warn import user_stacklevel
from ._mesh_checks import unique_edges
from ._mesh_parts import vertex_parts

#: The share of the width by which the centre must lie off the mesh for a loop to be a hole (an
#: open surface's outline around a strip narrower than the band has its centre on it).
HOLE_CENTRE = 0.25

#: The warning is given when a bridged hole's detour (:class:`Holes`) exceeds this share of the
#: mesh's size (its used vertices' bounding-box diagonal, about its largest geodesic distance), as
#: the first-order size warnings from 10% of the largest distance; ``sol.stats.bridged_holes``
#: reports every one. (The bundled bunny's base has a slot 0.0085 wide whose detour, 0.023, is
#: 9.2% of its size; the largest errors next to its holes at n = 60–200, 1.5–4.6 spacings, are
#: those elsewhere, 1.7–4.5: ``benches/experiments/mesh_holes.py --bunny``.)
WARN_SHARE = 0.1

#: Directions over a half turn at which a loop's width is measured (its hull's width is the
#: smallest, its perimeter π times the mean: Cauchy's formula).
DIRECTIONS = 90


@dataclass(frozen=True)
class Holes:
    """The holes of a mesh: per hole its width (the convex hull's smallest width in the loop's
    plane), its detour (half the hull's perimeter less its width: how much longer a path round
    a convex hole is than one across it, at most; 0.57 widths for a round hole, about the length
    of a slot) and its centre; and per boundary vertex and boundary edge its hole (-1 where it
    lies on none), for :func:`across_holes`."""

    width: np.ndarray
    detour: np.ndarray
    centre: np.ndarray
    vertex_hole: np.ndarray
    edge_keys: np.ndarray
    edge_hole: np.ndarray


def boundary_edges(faces: np.ndarray) -> np.ndarray:
    """The mesh's boundary edges ``(E, 2)``, each sorted: the edges of exactly one triangle
    (triangles that name a vertex twice left out, as ``MeshSurface`` counts them)."""
    f = np.asarray(faces, dtype=np.int64)
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    if len(f) == 0:
        return np.zeros((0, 2), np.int64)
    ids, counts = unique_edges(f)
    once = counts[ids] == 1  # (faces, 3): the AB, AC, BC edges used once
    ends = np.stack([f[:, [0, 1]], f[:, [0, 2]], f[:, [1, 2]]], axis=1)  # (faces, 3, 2)
    return np.sort(ends[once], axis=1)


def boundary_edges_of(surface: Any) -> np.ndarray:
    """:func:`boundary_edges` of ``surface`` (a ``MeshSurface``), computed once and kept (the
    holes and the slits read them)."""
    if "_boundary_edges" not in surface.__dict__:
        surface.__dict__["_boundary_edges"] = boundary_edges(surface.faces)
    edges: np.ndarray = surface.__dict__["_boundary_edges"]
    return edges


def _simple_loops(n_vertices: int, edges: np.ndarray) -> list:
    """The boundary vertices of each simple loop (every vertex on two boundary edges), loops of
    more than three vertices only."""
    degree = np.bincount(edges.ravel(), minlength=n_vertices)
    label = vertex_parts(n_vertices, np.column_stack([edges[:, 0], edges[:, 1], edges[:, 1]]))
    on = np.flatnonzero(degree > 0)
    bad = np.zeros(n_vertices, bool)
    bad[label[on[degree[on] != 2]]] = True  # components through a vertex of another degree
    on = on[~bad[label[on]]]
    order = np.argsort(label[on], kind="stable")
    groups = np.split(on[order], np.flatnonzero(np.diff(label[on][order])) + 1) if on.size else []
    return [g for g in groups if g.size > 3]


def _is_seam(points: np.ndarray) -> bool:
    """Whether most of a loop's vertices have another at the same coordinates (a split seam)."""
    _, inverse, counts = np.unique(points, axis=0, return_inverse=True, return_counts=True)
    return bool(np.count_nonzero(counts[inverse.ravel()] > 1) > 0.5 * len(points))


def _width(points: np.ndarray) -> tuple:
    """The smallest width of the convex hull of ``points`` (3D) in their best-fitting plane, its
    perimeter, and the centre of their bounding box in that plane (in 3D)."""
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    flat = (points - centre) @ vt[:2].T
    angle = np.arange(DIRECTIONS) * (np.pi / DIRECTIONS)
    along = flat @ np.stack([np.cos(angle), np.sin(angle)])  # (points, directions)
    widths = along.max(axis=0) - along.min(axis=0)
    middle = (flat.max(axis=0) + flat.min(axis=0)) / 2.0
    return float(widths.min()), float(np.pi * widths.mean()), centre + middle @ vt[:2]


def holes(surface: Any) -> Holes:
    """The holes of ``surface`` (a ``MeshSurface``), computed once per mesh."""
    cached: Optional[Holes] = surface.__dict__.get("_holes")
    if cached is not None:
        return cached
    v = surface.vertices
    edges = np.zeros((0, 2), np.int64) if surface.closed else boundary_edges_of(surface)
    widths, detours, centres, members = [], [], [], []
    for loop in _simple_loops(len(v), edges) if len(edges) else []:
        if _is_seam(v[loop]):
            continue
        width, perimeter, centre = _width(v[loop])
        widths.append(width)
        detours.append(max(perimeter / 2.0 - width, 0.0))
        centres.append(centre)
        members.append(loop)
    width_a, centre_a = np.asarray(widths, float), np.asarray(centres, float).reshape(-1, 3)
    hole = surface.closest(centre_a)[0] > HOLE_CENTRE * width_a if len(widths) else np.zeros(0, bool)
    vertex_hole = np.full(len(v), -1, np.int64)
    for k, loop in enumerate(m for m, is_hole in zip(members, hole) if is_hole):
        vertex_hole[loop] = k
    n = len(v)
    keys = edges[:, 0] * n + edges[:, 1]
    order = np.argsort(keys)
    edge_hole = vertex_hole[edges[order, 0]]
    found = Holes(
        width_a[hole],
        np.asarray(detours, float)[hole],
        centre_a[hole],
        vertex_hole,
        keys[order],
        np.where(edge_hole == vertex_hole[edges[order, 1]], edge_hole, -1),
    )
    surface.__dict__["_holes"] = found
    return found


def bridged(surface: Any, h: float, outer: float) -> Optional[dict]:
    """The holes of ``surface`` that the band of spacing ``h`` and width ``outer`` spans, as
    ``sol.stats.bridged_holes``: ``count``, ``widest`` (the widest one's width), ``reach`` (the
    band's span, ``2·outer·h``), ``detour`` (the largest :class:`Holes` detour among them: how
    much shorter a distance reached across one can come out), ``where`` and ``width`` (that
    hole's centre and width) and ``size`` (the mesh's used vertices' bounding-box diagonal); None
    when there are none."""
    found = holes(surface)
    reach = 2.0 * outer * h
    narrow = found.width < reach
    if not np.any(narrow):
        return None
    k = int(np.argmax(found.detour[narrow]))
    v = surface.vertices[surface.used_vertices]
    return {
        "count": int(np.count_nonzero(narrow)),
        "widest": float(np.max(found.width[narrow])),
        "reach": float(reach),
        "detour": float(found.detour[narrow][k]),
        "where": tuple(round(float(c), 6) for c in found.centre[narrow][k]),
        "width": float(found.width[narrow][k]),
        "size": float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))),
    }


def bridged_holes(surface: Any, h: float, outer: float, *_: Any) -> Optional[dict]:
    """:func:`bridged`, warned (:func:`warn_bridged_holes`): ``MeshSurface._bridged_holes``, read
    by the tube's preparation (which also passes the grid and the pairs over holes, for a point
    cloud's: ``_cloud_holes.bridged_holes``)."""
    info = bridged(surface, h, outer)
    warn_bridged_holes(info, h, outer)
    return info


def warn_bridged_holes(info: Optional[dict], h: float, outer: float) -> None:
    """The warning for :func:`bridged`'s holes, when the largest detour is over
    :data:`WARN_SHARE` of the mesh's size."""
    if info is None or info["detour"] <= WARN_SHARE * info["size"]:
        return
    spacing = info["width"] / (2.0 * outer)
    finer = f"a grid spacing below {spacing:.3g} (now {h:.3g}) keeps that one open, or " if spacing > 0 else ""
    warnings.warn(
        f"the mesh has {info['count']} hole(s) narrower than its band ({info['reach']:.3g} across at this grid; "
        f"the widest {info['widest']:.3g}): the band bridges them, and a distance reached across one can be that of "
        f"the surface with the hole filled (in part where the hole is over about 1.5 spacings wide), up to about {info['detour']:.3g} ({info['detour'] / info['size']:.0%} of "
        f"the mesh's size) shorter than the mesh's geodesic round the hole near {info['where']}. "
        f"sol.stats.bridged_holes has them; {finer}fill them first (e.g. trimesh.repair.fill_holes) where they are "
        "gaps in a scan",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def across_holes(surface: Any, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """For node pairs (points ``first[i]``, ``second[i]``, ``(M, 3)``) that a facing test found:
    whether both nodes' exact closest points lie on the same hole of the mesh, so that the pair
    lies over it (across the hole, or at a corner of its rim: the sphere's holes 10.8 spacings
    wide at N = 161 gave three such pairs) rather than across a gap between two sheets (feature
    codes of ``closest_points_on_triangles``). An outline taken for a hole (an annulus's outer
    edge, :data:`HOLE_CENTRE`) would let a notch in it pass for a hole: a limitation."""
    if surface.closed or len(first) == 0:
        return np.zeros(len(first), bool)
    found = holes(surface)
    if found.width.size == 0:
        return np.zeros(len(first), bool)
    a = _hole_of(surface, found, np.asarray(first, float))
    b = _hole_of(surface, found, np.asarray(second, float))
    return (a >= 0) & (a == b)


def pairs_over_holes(surface: Any, grid: Any, first: np.ndarray, second: np.ndarray, *_: Any) -> np.ndarray:
    """:func:`across_holes` for node pairs given by their linear indices on ``grid``:
    ``MeshSurface._pairs_over_holes``, read by the tube's preparation (``_prepare``), which leaves
    such pairs out of the facing pairs (no warning, no cut, not in ``sol.stats.facing_pairs``)."""
    return across_holes(surface, grid.node_points(first), grid.node_points(second))


def _hole_of(surface: Any, found: Holes, x: np.ndarray) -> np.ndarray:
    """The hole whose boundary holds each point's exact closest point, -1 where none does."""
    from ._triangle_projection import EDGE_AB, EDGE_AC, EDGE_BC, VERT_A, VERT_B, VERT_C

    f = np.asarray(surface.faces, dtype=np.int64)
    n = len(surface.vertices)
    _, _, face, code = surface.closest(x)
    out = np.full(len(x), -1, np.int64)
    ok = face >= 0
    tri = f[np.maximum(face, 0)]
    for c, corner in ((VERT_A, 0), (VERT_B, 1), (VERT_C, 2)):
        sel = ok & (code == c)
        out[sel] = found.vertex_hole[tri[sel, corner]]
    keys = found.edge_keys
    for c, (i, j) in ((EDGE_AB, (0, 1)), (EDGE_AC, (0, 2)), (EDGE_BC, (1, 2))):
        sel = ok & (code == c)
        if keys.size == 0 or not np.any(sel):
            continue
        key = np.minimum(tri[sel, i], tri[sel, j]) * n + np.maximum(tri[sel, i], tri[sel, j])
        pos = np.minimum(np.searchsorted(keys, key), keys.size - 1)
        out[sel] = np.where(keys[pos] == key, found.edge_hole[pos], -1)
    return out
