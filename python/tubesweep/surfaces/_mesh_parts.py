"""A triangle mesh's connected parts, and the band's edges between them (cut, so that the front
of one part never reaches another).

The two-layer method (Algorithm 3) lets a node read each band neighbour; where the tubes of two
separate parts of a mesh touch, a node of one reads a node of the other and the front crosses.
The cuts across narrow gaps (``_shortcuts``) come from the facing test on the band's closest
points, which the smooth map (``_mesh_smooth``) can blend across a gap narrower than its fits:
two icospheres of radius 0.3 1.2 spacings apart at N = 51, a source on one, gave the other
finite distances (1.42 at its far pole) with ``converged=True`` and no warning. Which part a node
belongs to needs no such test on a mesh: it is the part of the face nearest to the node (the
exact closest point, ``MeshSurface.closest``), and every band edge between nodes of two parts is
cut. A part that holds no source then stays unreached (``inf``), as with ``smooth=False``; every
solve also labels the inner tube by piece and drops the pieces without a source (``_parts``:
second order's exact start reaches a few spacings across a gap), and a point is read from the
nodes of its own piece (``_sheet_readout``, ``Solution.on_mesh``).

A piece is what the triangles join through shared vertices, vertices at the same coordinates
counting as one (an export's seam, a triangle soup); pieces that may touch or cross (a union of
shells never booleaned) count as one, so that only pieces provably apart are cut
(:func:`apart`).

One piece (most meshes): nothing is computed beyond the pieces themselves, once per mesh.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from .. import _native
from .._distinct import distinct_rows
from ..band import band_edges
from ..grid import Grid
from ._mesh_checks import unique_edges

#: Band nodes per query of their nearest faces and neighbours (bounds the memory).
CHUNK = 1 << 18


def vertex_parts(n_vertices: int, faces: np.ndarray) -> np.ndarray:
    """Per vertex the smallest vertex index of its connected part (vertices joined by the
    triangles' edges; a row ``[a, b, b]`` is the edge ab alone): union–find in Rust,
    ``tubesweep_core::surface::mesh_parts``, O(faces)."""
    f = np.ascontiguousarray(np.asarray(faces, dtype=np.int64).reshape(-1, 3))
    return np.asarray(_native.mesh_vertex_parts(int(n_vertices), f))


def merged_vertices(surface: Any) -> np.ndarray:
    """Per vertex of ``surface`` an index shared by the vertices at the same coordinates (a seam
    of an export, a triangle soup), computed once and kept."""
    if "_merged_vertices" not in surface.__dict__:
        surface.__dict__["_merged_vertices"] = distinct_rows(surface.vertices)[1]
    merged: np.ndarray = surface.__dict__["_merged_vertices"]
    return merged


def face_parts(surface: Any) -> Optional[np.ndarray]:
    """Per face of ``surface`` (a ``MeshSurface``) its separate piece, numbered 0, 1, ..., or
    None when the mesh is one piece; computed once and kept. Triangles are joined through shared
    vertices, vertices at the same coordinates counting as one (a seam of an export, a triangle
    soup), and two pieces whose surfaces may touch or cross (:func:`apart`) count as one."""
    if "_face_parts" not in surface.__dict__:
        faces = surface.faces
        merged = merged_vertices(surface)[faces]
        label = vertex_parts(int(merged.max()) + 1, merged)[merged[:, 0]]
        _, parts = np.unique(label, return_inverse=True)
        parts = parts.ravel().astype(np.int64)
        if parts.max(initial=0) > 0:
            parts = _joined_where_touching(surface, parts)
        surface._face_parts = parts if parts.max(initial=0) > 0 else None
    return surface._face_parts


def _joined_where_touching(surface: Any, parts: np.ndarray) -> np.ndarray:
    """``parts`` (per face) with the pieces that are not :func:`apart` merged, renumbered. Only
    pieces whose boxes come within an edge of each other are compared (sorted along x and swept),
    each piece's faces grouped once and its tree built once: linear in the pieces, not quadratic."""
    count = int(parts.max()) + 1
    tri = surface.vertices[surface.faces]
    edge = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)
    longest = np.zeros(count)
    np.maximum.at(longest, parts, edge)
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    np.minimum.at(lo, parts, tri.min(axis=1))
    np.maximum.at(hi, parts, tri.max(axis=1))
    order = np.argsort(parts, kind="stable")
    starts = np.searchsorted(parts[order], np.arange(count + 1))
    root = np.arange(count)

    def find(k: int) -> int:
        while root[k] != k:
            root[k] = root[root[k]]
            k = int(root[k])
        return k

    trees: dict = {}
    for i, j in _box_pairs(lo, hi, longest):
        ri, rj = find(i), find(j)
        if ri == rj:
            continue
        # the smaller piece sampled against the larger one's tree
        a, b = (i, j) if starts[i + 1] - starts[i] <= starts[j + 1] - starts[j] else (j, i)
        if b not in trees:
            trees[b] = _piece_tree(surface, order[starts[b] : starts[b + 1]])
        faces = order[starts[a] : starts[a + 1]]
        if not apart(tri[faces], edge[faces] / np.sqrt(3.0), trees[b], lo[b], hi[b]):
            root[ri] = rj
    label = np.array([find(k) for k in range(count)])
    _, joined = np.unique(label[parts], return_inverse=True)
    return joined.ravel().astype(np.int64)


def _box_pairs(lo: np.ndarray, hi: np.ndarray, longest: np.ndarray) -> list:
    """The pairs of pieces whose boxes come within the distance at which :func:`apart` can find
    them touching (the longer one's longest edge over 8√3) of each other: sorted along the axis
    on which the boxes spread most and swept."""
    within = longest / (SAMPLES_PER_EDGE * np.sqrt(3.0))
    reach = float(within.max())
    axis = int(np.argmax(np.ptp(0.5 * (lo + hi), axis=0)))
    by_x = np.argsort(lo[:, axis], kind="stable")
    ends = np.searchsorted(lo[by_x, axis], hi[by_x, axis] + reach, side="right")
    out: list = []
    for k, i in enumerate(by_x):
        others = by_x[k + 1 : ends[k]]
        if others.size == 0:
            continue
        near = np.maximum(within[i], within[others])
        gap = np.max(np.maximum(lo[others] - hi[i], lo[i] - hi[others]), axis=1)
        out.extend((int(i), int(j)) for j in others[gap <= near])
    return out


def _piece_tree(surface: Any, faces: np.ndarray) -> Any:
    return _native.TriangleTree(surface.vertices, np.ascontiguousarray(surface.faces[faces]))


#: Subdivisions per edge of a triangle sampled near another piece (:func:`apart`): pieces closer
#: than 1/(8√3) of their triangles' longest edge, 7 %, count as touching.
SAMPLES_PER_EDGE = 8
_I, _J = np.meshgrid(np.arange(SAMPLES_PER_EDGE + 1), np.arange(SAMPLES_PER_EDGE + 1), indexing="ij")
#: The samples' barycentric weights (S, 3).
_BARYCENTRIC = np.stack([_I, _J, SAMPLES_PER_EDGE - _I - _J], axis=-1)[_I + _J <= SAMPLES_PER_EDGE] / SAMPLES_PER_EDGE


def apart(tri: np.ndarray, bound: np.ndarray, tree: Any, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the triangles ``tri`` (T, 3, 3) of one piece are provably apart from the piece
    whose ``tree`` and box (``lo``, ``hi``) are given: every point of a triangle lies within its
    ``bound``, its longest edge over √3, of one of its vertices (the circumradius of an acute triangle, half the
    longest edge of an obtuse one), so a triangle whose vertices are all farther than that from
    the other piece is apart; a nearer one is sampled at :data:`SAMPLES_PER_EDGE` subdivisions
    per edge, each sample standing for the points within its sub-triangles' bound. Two shells
    that cross or touch (a union never booleaned) are one piece, and their front passes between
    them."""
    # triangles whose box comes within their bound of the other piece's box
    gap = np.max(np.maximum(tri.min(axis=1) - hi, lo - tri.max(axis=1)), axis=1)
    tri, bound = tri[gap <= bound], bound[gap <= bound]
    if len(tri) == 0:
        return True
    d, _, _, _ = tree.closest(np.ascontiguousarray(tri.reshape(-1, 3)), float(bound.max()))
    near = d.reshape(-1, 3).min(axis=1) <= bound
    if not np.any(near):
        return True
    samples = np.einsum("sk,tkc->tsc", _BARYCENTRIC, tri[near])
    d, _, _, _ = tree.closest(np.ascontiguousarray(samples.reshape(-1, 3)), float(bound[near].max()))
    return bool(np.all(d.reshape(len(samples), -1).min(axis=1) > bound[near] / SAMPLES_PER_EDGE))


def _nearest_pieces(surface: Any, parts: np.ndarray, count: int, points_of: Any) -> np.ndarray:
    """Per point the piece (of ``parts``, per face) of its nearest face, -1 where none is; the
    ``count`` points come ``CHUNK`` at a time from ``points_of(start, stop)``."""
    out = np.empty(count, np.int64)
    for s in range(0, count, CHUNK):
        _, _, face, _ = surface.closest(points_of(s, min(s + CHUNK, count)))
        out[s : s + CHUNK] = np.where(face >= 0, parts[np.maximum(face, 0)], -1)
    return out


def node_parts(surface: Any, grid: Grid, linear: np.ndarray) -> Optional[np.ndarray]:
    """Per grid node of ``linear`` (linear indices) the part of the mesh ``surface`` its nearest
    face lies on, or None on a mesh of one part."""
    parts = face_parts(surface)
    if parts is None:
        return None
    return _nearest_pieces(surface, parts, len(linear), lambda a, b: grid.node_points(linear[a:b]))


def point_parts(surface: Any, points: np.ndarray) -> np.ndarray:
    """Per point the part of the mesh ``surface`` its nearest face lies on (-1 where none is;
    all 0 on a mesh of one part)."""
    parts = face_parts(surface)
    if parts is None:
        return np.zeros(len(points), np.int64)
    return _nearest_pieces(surface, parts, len(points), lambda a, b: points[a:b])


def part_cut_pairs(
    surface: Any, grid: Grid, band: Any, linear: np.ndarray
) -> Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]:
    """The band edges (``node``, ``neighbour``: band positions, ``node < neighbour``) between nodes
    whose nearest faces lie on two parts of the mesh ``surface``, and each band node's part
    (:func:`node_parts`); empty and None on a mesh of one part."""
    empty = np.zeros(0, np.int64)
    part = node_parts(surface, grid, linear) if len(linear) else None
    if part is None:
        return empty, empty, None
    nodes, neighbours = [], []
    for node, other in band_edges(band, len(linear), CHUNK):
        crossing = part[node] != part[other]
        nodes.append(node[crossing])
        neighbours.append(other[crossing])
    return np.concatenate(nodes), np.concatenate(neighbours), part


#: Separate pieces holding under this share of a mesh's area are debris (a stray triangle):
#: a mesh open only in them is closed for ``order="auto"``'s first-order size warning.
DEBRIS_AREA = 0.01


def open_only_in_debris(surface: Any) -> bool:
    """Whether the mesh's boundary edges all lie on separate pieces of under :data:`DEBRIS_AREA`
    of its area (computed once): a closed sphere with one stray triangle far away read as open,
    and its first-order errors (17.8 % at N = 13) went unwarned, as an open surface's."""
    if "_open_only_in_debris" not in surface.__dict__:
        parts = face_parts(surface)
        answer = False
        if parts is not None:
            f = surface.faces
            edge_ids, counts = unique_edges(f)
            open_faces = np.any(counts[edge_ids] == 1, axis=1)
            v = surface.vertices
            area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
            open_area = float(area[np.isin(parts, np.unique(parts[open_faces]))].sum())
            answer = open_area < DEBRIS_AREA * float(area.sum())
        surface.__dict__["_open_only_in_debris"] = answer
    return bool(surface.__dict__["_open_only_in_debris"])
