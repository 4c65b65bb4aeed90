"""Pinches: vertices where parts of a mesh meet at a point only (non-manifold vertices: two
spheres touching at a shared vertex, a bowtie).

The band around two sheets that meet at a point joins them over the whole neck where they lie
within its reach of each other, and the front crosses anywhere there instead of through the
point: two icospheres of radius 0.5 sharing a vertex, the source at the far pole of one, gave the
other's far pole 10–11 grid spacings short at n = 61 and 101 (first order, 158–640 facing pairs
cut across the neck), unwarned. The pieces of ``_mesh_parts`` are joined through shared vertices,
so the two spheres are one piece and nothing cut them apart.

:func:`pinches` splits the mesh at such vertices: its triangles joined through shared *edges*
(vertices at the same coordinates counting as one, as for the pieces), and the vertices whose
triangles lie on more than one of these sheets. :func:`pinch_cut_pairs` labels each band node
with the sheet of its nearest face and gives the band edges between two sheets of one piece,
except where both nodes' closest points lie within :data:`PINCH_REACH` grid spacings of a pinch
(the way through it); the tube's preparation cuts them (``_shortcuts.cut_pinches``). Near the
pinch the answer is first order (the far sphere above: 2.4, 1.5 and 1.0 spacings short on
average at n = 61, 101 and 141, ``benches/experiments/mesh_slits.py``).

A limit: sheets that share a vertex and also cross each other elsewhere (shells never
booleaned, which ``_mesh_parts`` keeps as one piece so that the front crosses where they
intersect) are cut apart there too.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ._mesh_checks import unique_edges
from ._mesh_parts import CHUNK, face_parts

#: Band edges between two sheets stay where both nodes' closest points lie within this many grid
#: spacings of a pinch vertex (the nodes round the point where the sheets meet).
PINCH_REACH = 0.5


def pinches(surface: Any) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """Per face of ``surface`` (a ``MeshSurface``) its sheet (triangles joined through shared
    edges), and the pinch vertices' coordinates (where triangles of several sheets meet); None
    when no vertex is a pinch. Computed once and kept."""
    if "_pinches" not in surface.__dict__:
        surface.__dict__["_pinches"] = _find(surface)
    found: Optional[Tuple[np.ndarray, np.ndarray]] = surface.__dict__["_pinches"]
    return found


def _find(surface: Any) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    faces = np.asarray(surface.faces, dtype=np.int64)
    if len(faces) == 0:
        return None
    _, same = np.unique(surface.vertices, axis=0, return_inverse=True)
    merged = same.ravel()[faces]
    good = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 0] != merged[:, 2])
    if not np.any(good):
        return None
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    ids, _ = unique_edges(merged[good])  # (faces, 3) edge ids
    # triangles and edges as the two kinds of nodes of one graph: sheets are its components
    n_edges = int(ids.max()) + 1
    n_good = int(np.count_nonzero(good))
    rows = n_edges + np.repeat(np.arange(n_good), 3)
    graph = coo_matrix((np.ones(rows.size, np.int8), (rows, ids.ravel())), shape=(n_edges + n_good,) * 2)
    count, label = connected_components(graph, directed=False)
    if count == 1:
        return None
    _, sheet_good = np.unique(label[n_edges:], return_inverse=True)
    sheet = np.full(len(faces), -1, np.int64)
    sheet[good] = sheet_good.ravel()
    if sheet_good.max(initial=0) == 0:
        return None
    # a pinch: a (merged) vertex whose triangles lie on several sheets
    corner = merged[good].ravel()
    of = np.repeat(sheet_good.ravel(), 3)
    order = np.lexsort((of, corner))
    corner, of = corner[order], of[order]
    change = np.r_[False, (corner[1:] == corner[:-1]) & (of[1:] != of[:-1])]
    pinch_vertex = np.unique(corner[change])
    if pinch_vertex.size == 0:
        return None
    representative = np.zeros(int(same.max()) + 1, np.int64)
    representative[same.ravel()] = np.arange(len(surface.vertices))
    return sheet, np.asarray(surface.vertices, float)[representative[pinch_vertex]]


def pinch_cut_pairs(surface: Any, grid: Any, band: Any, linear: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The band edges (``node``, ``neighbour``: band positions, ``node < neighbour``) between nodes
    whose nearest faces lie on two sheets of one piece, but not where both closest points lie
    within :data:`PINCH_REACH` spacings of a pinch: ``MeshSurface._pinch_cut_pairs``, read by
    the tube's preparation. Empty where the mesh has no pinch."""
    empty = np.zeros(0, np.int64)
    found = pinches(surface)
    n = len(linear)
    if found is None or n == 0:
        return empty, empty
    from scipy.spatial import cKDTree

    sheet, points = found
    piece = face_parts(surface)
    h = float(grid.spacing)
    node_sheet = np.empty(n, np.int64)
    node_piece = np.zeros(n, np.int64)
    near = np.zeros(n, bool)
    tree = cKDTree(points)
    for s in range(0, n, CHUNK):
        _, cp, face, _ = surface.closest(grid.node_points(linear[s : s + CHUNK]))
        node_sheet[s : s + CHUNK] = np.where(face >= 0, sheet[np.maximum(face, 0)], -1)
        if piece is not None:
            node_piece[s : s + CHUNK] = np.where(face >= 0, piece[np.maximum(face, 0)], -1)
        near[s : s + CHUNK] = np.isfinite(tree.query(cp, distance_upper_bound=PINCH_REACH * h)[0])
    firsts, seconds = [], []
    for s in range(0, n, CHUNK):
        at = np.arange(s, min(s + CHUNK, n), dtype=np.int64)
        nb = band.neighbours_of_nodes(at).reshape(len(at), -1)
        a = np.repeat(at, nb.shape[1])
        b = nb.ravel()
        keep = (b < n) & (b > a)
        a, b = a[keep], b[keep]
        cut = (
            (node_sheet[a] != node_sheet[b])
            & (node_sheet[a] >= 0)
            & (node_sheet[b] >= 0)
            & (node_piece[a] == node_piece[b])
            & ~(near[a] & near[b])
        )
        firsts.append(a[cut])
        seconds.append(b[cut])
    return np.concatenate(firsts), np.concatenate(seconds)
