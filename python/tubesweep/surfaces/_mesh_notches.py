"""Facing pairs at a notch of an open mesh's rim: no gap.

The facing tests (``_mesh_smooth.facing_pairs``, the tube's ``Band.facing_sheet_pairs``) take two
neighbouring band nodes whose directions turn against each other for the two sides of a narrow
gap, and one such pair sends a mesh's whole solve to first order ("the second-order sweeps can run
away across such a gap"). Where an open mesh's boundary zigzags at the grid's scale (a disc
triangulated on a jittered lattice, its triangles kept inside a circle: a scan's or a cut's rim),
a node beyond a notch's corner, its direction along the surface, and a node above the next
triangle, its direction along the normal, pass that test: the disc tilted in the box had one pair
at every N from 61 to 121 and ran first order, its mean error away from the rim 0.007–0.011,
against under 1e-4 at second order (``benches/experiments/rim_notches.py``).

Across a real gap the two nodes' closest points lie far apart along the mesh (the sheets join,
if at all, round the gap's far end); at a notch they lie on neighbouring triangles. A pair is no
gap where one of its closest points lies on the boundary, the two see each other within
:data:`EDGE_ON` of both triangles' planes (across a gap they face each other along the normals),
and the mesh joins them by a path along its edges (from the one closest point to a vertex of its
triangle, along edges, to a vertex of the other's triangle, to the other) of at most
:data:`NOTCH_REACH` grid spacings or :data:`NOTCH_RATIO` times their distance: the solution
differs across it by no more than that path, so the second-order sweeps have nothing to run away
with. Such pairs are left out of the facing pairs (no cut, no warning, not in
``sol.stats.facing_pairs``). The path is searched for only between closest points on one piece
of the mesh, with the straight line as the bound on the rest of the way, and the verdicts are
kept per grid (a review's timings before and after these limits: docs/development/history-notes.md).
"""

from __future__ import annotations

import heapq
from typing import Any, Dict, List, Tuple

import numpy as np

from ..grid import Grid
from ._mesh_holes import boundary_edges_of
from ._mesh_parts import vertex_parts
from ._triangle_projection import EDGE_AB, EDGE_AC, EDGE_BC, VERT_A, VERT_B, VERT_C

#: The longest path along the mesh between a pair's two closest points, in grid spacings, for which
#: the pair is a notch's and no gap (the solution differs across it by no more)...
NOTCH_REACH = 3.0
#: ... or, where longer, in units of the distance between the two closest points: a slot of width
#: w and depth d is joined round its end by about 2d + w, so this takes bays up to half as deep as
#: they are wide (a notch the grid resolves) for notches, and slots deeper than that for gaps.
NOTCH_RATIO = 2.0
#: The two closest points of a notch's pair see each other within this many degrees of both
#: their triangles' planes (the tilted disc's: within a few degrees); across a gap between two
#: sheets they face each other along the normals, and no path is searched for.
EDGE_ON = 30.0


def _boundary_table(surface: Any) -> np.ndarray:
    """``(F, 7)`` bool: whether each face's feature (the codes of
    :func:`~tubesweep.surfaces.mesh.closest_points_on_triangles`) lies on the mesh's boundary (a
    boundary edge, or a vertex of one: ``_mesh_holes.boundary_edges_of``); computed once per mesh."""
    table = surface.__dict__.get("_boundary_features")
    if table is None:
        f = np.asarray(surface.faces, dtype=np.int64)
        boundary = boundary_edges_of(surface)  # (E, 2), each sorted
        n = len(surface.vertices)
        ends = np.sort(np.stack([f[:, [0, 1]], f[:, [0, 2]], f[:, [1, 2]]], axis=1), axis=2)
        edge_on = np.isin(ends[:, :, 0] * n + ends[:, :, 1], boundary[:, 0] * n + boundary[:, 1])  # AB, AC, BC
        vertex_on = np.zeros(n, dtype=bool)
        vertex_on[boundary.ravel()] = True
        table = np.zeros((len(f), 7), dtype=bool)
        for code, k in ((VERT_A, 0), (VERT_B, 1), (VERT_C, 2)):
            table[:, code] = vertex_on[f[:, k]]
        for code, k in ((EDGE_AB, 0), (EDGE_AC, 1), (EDGE_BC, 2)):
            table[:, code] = edge_on[:, k]
        surface.__dict__["_boundary_features"] = table
    return table


def _edge_graph(surface: Any) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh's vertex graph in CSR form (offsets, neighbours, edge lengths); computed once."""
    graph = surface.__dict__.get("_edge_graph")
    if graph is None:
        f = np.asarray(surface.faces, dtype=np.int64)
        e = np.concatenate([f[:, [0, 1]], f[:, [0, 2]], f[:, [1, 2]]])
        e = np.unique(np.sort(e, axis=1), axis=0)
        e = e[e[:, 0] != e[:, 1]]
        both = np.concatenate([e, e[:, ::-1]])
        both = both[np.argsort(both[:, 0], kind="stable")]
        v = surface.vertices
        offsets = np.searchsorted(both[:, 0], np.arange(len(v) + 1))
        length = np.linalg.norm(v[both[:, 0]] - v[both[:, 1]], axis=1)
        graph = (offsets, both[:, 1], length)
        surface.__dict__["_edge_graph"] = graph
    return graph


def _vertex_pieces(surface: Any) -> np.ndarray:
    """Per vertex its piece of the mesh's edge graph (``_mesh_parts.vertex_parts``); computed once."""
    pieces = surface.__dict__.get("_vertex_pieces")
    if pieces is None:
        pieces = vertex_parts(len(surface.vertices), surface.faces)
        surface.__dict__["_vertex_pieces"] = pieces
    return pieces


def _joined_within(surface: Any, c1: np.ndarray, f1: int, c2: np.ndarray, f2: int, limit: float) -> bool:
    """Whether the mesh joins ``c1`` (on face ``f1``) and ``c2`` (on face ``f2``) by a path through
    the faces' vertices along edges of at most ``limit``: an A* search, the straight line to ``c2``
    its bound on the rest of the way, so that it visits only the vertices of the ellipse within
    ``limit`` of both ends (a real gap's fruitless search stays small)."""
    if f1 == f2:
        return bool(np.linalg.norm(c1 - c2) <= limit)
    offsets, neighbours, length = _edge_graph(surface)
    v = surface.vertices
    faces = surface.faces
    goal = {int(k): float(np.linalg.norm(v[k] - c2)) for k in faces[f2]}
    best: Dict[int, float] = {}
    heap: List[Tuple[float, float, int]] = []

    def reach(k: int, d: float) -> None:
        bound = d + float(np.sqrt(((v[k] - c2) ** 2).sum()))
        if bound <= limit and d < best.get(k, np.inf):
            best[k] = d
            heapq.heappush(heap, (bound, d, k))

    for k in faces[f1]:
        reach(int(k), float(np.linalg.norm(v[k] - c1)))
    while heap:
        _, d, k = heapq.heappop(heap)
        if d > best.get(k, np.inf):
            continue
        if k in goal and d + goal[k] <= limit:
            return True
        for s in range(offsets[k], offsets[k + 1]):
            reach(int(neighbours[s]), d + float(length[s]))
    return False


def pairs_at_notches(surface: Any, grid: Grid, first: np.ndarray, second: np.ndarray, *_: Any) -> np.ndarray:
    """For facing node pairs given by their linear indices on ``grid``: whether each lies at a
    notch of the mesh's rim (see the module): one of its two exact closest points on the
    boundary, and the two joined along the mesh within :data:`NOTCH_REACH` spacings or
    :data:`NOTCH_RATIO` times their distance, whichever is longer.
    ``MeshSurface._pairs_at_notches``, read by the tube's preparation (``_facing``), which leaves
    such pairs out of the facing pairs. All False on a closed mesh."""
    out = np.zeros(len(first), dtype=bool)
    if getattr(surface, "closed", True) or len(first) == 0:
        return out
    _, c1, f1, k1 = surface.closest(grid.node_points(first))
    _, c2, f2, k2 = surface.closest(grid.node_points(second))
    table = _boundary_table(surface)
    found = (f1 >= 0) & (f2 >= 0)
    on_rim = np.zeros(len(first), dtype=bool)
    on_rim[found] = table[f1[found], k1[found]] | table[f2[found], k2[found]]
    faces = np.asarray(surface.faces)
    pieces = _vertex_pieces(surface)
    on_rim[found] &= pieces[faces[f1[found], 0]] == pieces[faces[f2[found], 0]]  # no path between pieces
    apart = np.linalg.norm(c1 - c2, axis=1)
    # a notch lies in the surface: the two closest points see each other along it, within
    # EDGE_ON of both triangles' planes; across a gap between two sheets, along their normals
    way = (c2 - c1) / np.maximum(apart, 1e-300)[:, None]
    normals = surface.face_normals
    for f in (f1, f2):  # (on_rim is False already where a closest point was not found)
        on_rim &= np.abs(np.einsum("ij,ij->i", normals[np.maximum(f, 0)], way)) <= np.sin(np.radians(EDGE_ON))
    limit = np.maximum(NOTCH_REACH * grid.spacing, NOTCH_RATIO * apart)
    # the verdicts on this grid, kept: the smooth map's facing test and the tube's meet many of the
    # same node pairs
    on = (grid.spacing, tuple(grid.lower), tuple(grid.shape), NOTCH_REACH, NOTCH_RATIO)
    cache = surface.__dict__.get("_notch_verdicts")
    if cache is None or cache[0] != on:
        cache = (on, {})
        surface.__dict__["_notch_verdicts"] = cache
    known: Dict[Tuple[int, int], bool] = cache[1]
    for i in np.flatnonzero(on_rim):
        key = (int(first[i]), int(second[i]))
        if key not in known:
            known[key] = _joined_within(surface, c1[i], int(f1[i]), c2[i], int(f2[i]), float(limit[i]))
        out[i] = known[key]
    return out
