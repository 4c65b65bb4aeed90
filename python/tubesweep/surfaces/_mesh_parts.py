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
cut. A part that holds no source then stays unreached (``inf``), as with ``smooth=False``.

A piece is what the triangles join through shared vertices, vertices at the same coordinates
counting as one (an export's seam, a triangle soup); pieces that may touch or cross (a union of
shells never booleaned) count as one, so that only pieces provably apart are cut
(:func:`apart`).

One piece (most meshes): nothing is computed beyond the pieces themselves, once per mesh.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ..grid import Grid

#: Band nodes per query of their nearest faces and neighbours (bounds the memory).
CHUNK = 1 << 18


def vertex_parts(n_vertices: int, faces: np.ndarray) -> np.ndarray:
    """Per vertex the smallest vertex index of its connected part (vertices joined by the
    triangles' edges): label propagation with pointer jumping, O(edges · log) in NumPy."""
    f = np.asarray(faces, dtype=np.int64)
    a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    label = np.arange(n_vertices, dtype=np.int64)
    while True:
        low = np.minimum(label[a], label[b])
        new = label.copy()
        for ends in (a, b, label[a], label[b]):  # the ends, and their roots (hooking)
            np.minimum.at(new, ends, low)
        while True:  # pointer jumping: every vertex to its root
            jumped = new[new]
            if np.array_equal(jumped, new):
                break
            new = jumped
        if np.array_equal(new, label):
            return label
        label = new


def face_parts(surface: Any) -> Optional[np.ndarray]:
    """Per face of ``surface`` (a ``MeshSurface``) its separate piece, numbered 0, 1, ..., or
    None when the mesh is one piece; computed once and kept. Triangles are joined through shared
    vertices, vertices at the same coordinates counting as one (a seam of an export, a triangle
    soup), and two pieces whose surfaces may touch or cross (:func:`apart`) count as one."""
    if "_face_parts" not in surface.__dict__:
        faces = surface.faces
        _, same = np.unique(surface.vertices, axis=0, return_inverse=True)
        merged = same.ravel()[faces]
        label = vertex_parts(int(merged.max()) + 1, merged)[merged[:, 0]]
        _, parts = np.unique(label, return_inverse=True)
        parts = parts.ravel().astype(np.int64)
        if parts.max(initial=0) > 0:
            parts = _joined_where_touching(surface, parts)
        surface._face_parts = parts if parts.max(initial=0) > 0 else None
    return surface._face_parts


def _joined_where_touching(surface: Any, parts: np.ndarray) -> np.ndarray:
    """``parts`` (per face) with the pieces that are not :func:`apart` merged, renumbered."""
    count = int(parts.max()) + 1
    v, f = surface.vertices, surface.faces
    longest = np.zeros(count)
    edge = np.max(np.linalg.norm(v[f] - v[np.roll(f, 1, axis=1)], axis=2), axis=1)
    np.maximum.at(longest, parts, edge)
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    np.minimum.at(lo, parts, v[f].min(axis=1))
    np.maximum.at(hi, parts, v[f].max(axis=1))
    # candidate pairs: boxes within the longer piece's longest edge of each other (farther, apart)
    reach = np.maximum(longest[:, None], longest[None, :])
    gap = np.max(np.maximum(lo[:, None, :] - hi[None, :, :], lo[None, :, :] - hi[:, None, :]), axis=2)
    a, b = np.nonzero(np.triu(gap <= reach, k=1))
    label = np.arange(count)
    for i, j in zip(a, b):
        if not apart(surface, parts, int(i), int(j), longest) and label[i] != label[j]:
            label[label == label[j]] = label[i]
    _, joined = np.unique(label[parts], return_inverse=True)
    return joined.ravel().astype(np.int64)


def apart(surface: Any, parts: np.ndarray, i: int, j: int, longest: np.ndarray) -> bool:
    """Whether pieces ``i`` and ``j`` of ``surface`` are provably apart: every vertex of each lies
    farther from the other than its own piece's longest edge over √3, so no point of its
    triangles reaches the other (every point of a triangle lies within its longest edge over √3
    of a vertex: the circumradius of an acute triangle, half the longest edge of an obtuse one).
    Two shells that cross or touch, or whose gap is narrower, are one piece (their front may pass
    between them as before)."""
    from .. import _native

    for p, q in ((i, j), (j, i)):
        verts = np.unique(surface.faces[parts == p])
        reach = float(longest[p]) / np.sqrt(3.0)
        tree = _native.TriangleTree(surface.vertices, np.ascontiguousarray(surface.faces[parts == q]))
        d, _, _, _ = tree.closest(np.ascontiguousarray(surface.vertices[verts]), reach)
        if not np.all(d > reach):
            return False
    return True


def node_parts(surface: Any, grid: Grid, linear: np.ndarray) -> Optional[np.ndarray]:
    """Per grid node of ``linear`` (linear indices) the part of the mesh ``surface`` its nearest
    face lies on, or None on a mesh of one part."""
    parts = face_parts(surface)
    if parts is None:
        return None
    n = len(linear)
    part = np.empty(n, np.int64)
    for s in range(0, n, CHUNK):
        _, _, face, _ = surface.closest(grid.node_points(linear[s : s + CHUNK]))
        part[s : s + CHUNK] = np.where(face >= 0, parts[np.maximum(face, 0)], -1)
    return part


def point_parts(surface: Any, points: np.ndarray) -> np.ndarray:
    """Per point the part of the mesh ``surface`` its nearest face lies on (-1 where none is;
    all 0 on a mesh of one part)."""
    parts = face_parts(surface)
    if parts is None:
        return np.zeros(len(points), np.int64)
    out = np.empty(len(points), np.int64)
    for s in range(0, len(points), CHUNK):
        _, _, face, _ = surface.closest(points[s : s + CHUNK])
        out[s : s + CHUNK] = np.where(face >= 0, parts[np.maximum(face, 0)], -1)
    return out


def part_cut_pairs(surface: Any, grid: Grid, band: Any, linear: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The band edges (``node``, ``neighbour``: band positions, ``node < neighbour``) between nodes
    whose nearest faces lie on two parts of the mesh ``surface``; empty on a mesh of one part."""
    empty = np.zeros(0, np.int64)
    part = node_parts(surface, grid, linear) if len(linear) else None
    if part is None:
        return empty, empty
    n = len(linear)
    nodes, neighbours = [], []
    for s in range(0, n, CHUNK):
        at = np.arange(s, min(s + CHUNK, n), dtype=np.int64)
        nb = band.neighbours_of_nodes(at).reshape(len(at), -1)
        node = np.repeat(at, nb.shape[1])
        other = nb.ravel()
        keep = (other < n) & (other > node)
        node, other = node[keep], other[keep]
        crossing = part[node] != part[other]
        nodes.append(node[crossing])
        neighbours.append(other[crossing])
    return np.concatenate(nodes), np.concatenate(neighbours)
