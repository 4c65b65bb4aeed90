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

from ..band import band_edges
from ._mesh_checks import unique_edges
from ._mesh_parts import CHUNK, face_parts, merged_vertices, vertex_parts

#: Two sheets whose open edges leave a shared vertex along each other, the shorter one's far end
#: within this share of the longer one's length of it, meet along a seam there, not at a point
#: (:func:`_joined_at_seams`; a cube's faces divided 6 and 7 times: 0; two bowls whose rims touch
#: at a vertex leave it along one tangent, their next vertices some 5% of an edge apart).
SEAM_ON = 1e-3
#: Two sheets sharing this many vertices or more are joined (a curved seam whose vertices are
#: shared in part: a cylinder's caps of 8 segments on a side of 36; several contacts are left to
#: the band, as before pinches were judged).
SHARED_VERTICES = 3
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
    same = merged_vertices(surface)
    merged = same[faces]
    good = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 0] != merged[:, 2])
    if not np.any(good):
        return None
    tri = merged[good]
    ids, counts = unique_edges(tri)  # (faces, 3) edge ids: AB, AC, BC
    # a triangle joins its three edges: the sheets are the parts of that graph (numpy only)
    n_edges = int(ids.max()) + 1
    label = vertex_parts(n_edges, ids)
    _, sheet_good = np.unique(label[ids[:, 0]], return_inverse=True)
    sheet_good = sheet_good.ravel()
    if sheet_good.max(initial=0) == 0:
        return None
    representative = np.zeros(int(same.max()) + 1, np.int64)
    representative[same] = np.arange(len(surface.vertices))
    position = np.asarray(surface.vertices, float)[representative]  # per merged vertex
    sheet_good = _joined_at_seams(tri, ids, counts, sheet_good, position)
    if sheet_good.max(initial=0) == 0:
        return None
    sheet = np.full(len(faces), -1, np.int64)
    sheet[good] = sheet_good
    # a pinch: a (merged) vertex whose triangles lie on several sheets
    corner = merged[good].ravel()
    of = np.repeat(sheet_good.ravel(), 3)
    order = np.lexsort((of, corner))
    corner, of = corner[order], of[order]
    change = np.r_[False, (corner[1:] == corner[:-1]) & (of[1:] != of[:-1])]
    pinch_vertex = np.unique(corner[change])
    if pinch_vertex.size == 0:
        return None
    return sheet, position[pinch_vertex]


def _joined_at_seams(
    tri: np.ndarray, ids: np.ndarray, counts: np.ndarray, sheet: np.ndarray, position: np.ndarray
) -> np.ndarray:
    """``sheet`` (per triangle of ``tri``, merged vertices) with the sheets joined that meet along
    a seam: patches of one surface meshed apart, sharing vertices but no edges (T-junctions: a
    CAD export's cap with fewer segments than its side, a box's faces divided 6 and 7 times),
    where an open edge of one runs along an open edge of the other from a shared vertex
    (:data:`SEAM_COS`), or where both ends of an open edge of one are vertices of the other (a
    coarse patch's chord along a finer one's curved rim turns away from the finer chords by up
    to half the angle between them). Without this a cube of such faces was cut along its edges
    but at its corners: 28 spacings off, or unreached, at N = 41 and 81 (a helper's review)."""
    slots = ((0, 1), (0, 2), (1, 2))
    open_slot = counts[ids] == 1
    face, slot = np.nonzero(open_slot)
    if face.size == 0:
        return sheet
    ends = np.array(slots)[slot]
    p = tri[face, ends[:, 0]]
    q = tri[face, ends[:, 1]]
    # each open edge from both its ends: (vertex, sheet, vector along the edge)
    vertex = np.r_[p, q]
    of = np.r_[sheet[face], sheet[face]]
    d = np.r_[position[q] - position[p], position[p] - position[q]]
    order = np.argsort(vertex, kind="stable")
    vertex, of, d = vertex[order], of[order], d[order]
    firsts, seconds = [], []
    longest = int(np.max(np.unique(vertex, return_counts=True)[1]))
    for k in range(1, longest):
        same = (vertex[k:] == vertex[:-k]) & (of[k:] != of[:-k])
        firsts.append(of[:-k][same & _overlap(d[k:], d[:-k])])
        seconds.append(of[k:][same & _overlap(d[k:], d[:-k])])
    # an open edge of sheet s whose two ends both lie on sheet t: (edge, t) found from both ends
    n = int(sheet.max()) + 1
    on = np.unique(np.stack([tri.ravel(), np.repeat(sheet, 3)], axis=1), axis=0)  # (vertex, sheet)
    start = np.searchsorted(on[:, 0], np.arange(int(tri.max()) + 2))
    edge_sheet = sheet[face]
    keys = []
    for end in (p, q):
        count = start[end + 1] - start[end]
        edge = np.repeat(np.arange(end.size), count)
        other = on[
            np.repeat(start[end], count) + np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count), 1
        ]
        keep = other != edge_sheet[edge]
        keys.append(np.unique(edge[keep] * n + other[keep]))
    both = np.intersect1d(keys[0], keys[1], assume_unique=True)
    firsts.append(edge_sheet[both // n])
    seconds.append(both % n)
    # two sheets sharing SHARED_VERTICES vertices or more meet along a seam or at several points:
    # not cut (as before pinches were judged)
    pair = np.unique(on[:, 0], return_index=True, return_counts=True)
    many = pair[2] > 1
    if np.any(many):
        starts, counts_at = pair[1][many], pair[2][many]
        rows = (
            np.repeat(starts, counts_at)
            + np.arange(int(counts_at.sum()))
            - np.repeat(np.cumsum(counts_at) - counts_at, counts_at)
        )
        group = np.repeat(np.arange(starts.size), counts_at)
        sheets_at = on[rows, 1]
        # the pairs of sheets at each shared vertex (vertices on few sheets: a short double loop)
        ii, jj = [], []
        most = int(counts_at.max())
        for x in range(1, most):
            ok = group[x:] == group[:-x]
            ii.append(sheets_at[:-x][ok])
            jj.append(sheets_at[x:][ok])
        si, sj = np.concatenate(ii), np.concatenate(jj)
        key, shared = np.unique(np.minimum(si, sj) * n + np.maximum(si, sj), return_counts=True)
        joined_many = key[shared >= SHARED_VERTICES]
        firsts.append(joined_many // n)
        seconds.append(joined_many % n)
    a, b = np.concatenate(firsts), np.concatenate(seconds)
    if a.size == 0:
        return sheet
    joined = vertex_parts(n, np.stack([a, b, b], axis=1))
    _, out = np.unique(joined[sheet], return_inverse=True)
    return out.ravel()


def _overlap(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """Whether two open edges leaving one vertex (vectors ``d1``, ``d2``) run along each other:
    the shorter one's far end lies on the longer one (a straight seam), not merely in the same
    direction (two bowls whose rims touch at a point leave it along one tangent)."""
    l1, l2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
    short = np.where((l1 <= l2)[:, None], d1, d2)
    long_ = np.where((l1 <= l2)[:, None], d2, d1)
    long_len2 = np.maximum(np.einsum("ij,ij->i", long_, long_), 1e-300)
    t = np.clip(np.einsum("ij,ij->i", short, long_) / long_len2, 0.0, 1.0)
    off = np.linalg.norm(short - t[:, None] * long_, axis=1)
    return (np.einsum("ij,ij->i", short, long_) > 0.0) & (off <= SEAM_ON * np.sqrt(long_len2))


def pinch_cut_pairs(surface: Any, grid: Any, band: Any, linear: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The band edges (``node``, ``neighbour``: band positions, ``node < neighbour``) between nodes
    whose nearest faces lie on two sheets of one piece, but not those round a pinch: where both
    closest points lie within :data:`PINCH_REACH` spacings of the same pinch, or, where no edge
    between the two sheets comes that close (a coarse mesh), the edges that come closest to it
    (so that the way through the pinch stays open). ``MeshSurface._pinch_cut_pairs``, read by the
    tube's preparation. Empty where the mesh has no pinch."""
    empty = np.zeros(0, np.int64)
    found = pinches(surface)
    n = len(linear)
    if found is None or n == 0:
        return empty, empty
    sheet, points = found
    piece = face_parts(surface)
    h = float(grid.spacing)
    node_sheet = np.empty(n, np.int64)
    node_piece = np.zeros(n, np.int64)
    pinch = np.empty(n, np.int64)  # the nearest pinch to each node's closest point, and how far
    far = np.empty(n)
    for s in range(0, n, CHUNK):
        _, cp, face, _ = surface.closest(grid.node_points(linear[s : s + CHUNK]))
        node_sheet[s : s + CHUNK] = np.where(face >= 0, sheet[np.maximum(face, 0)], -1)
        if piece is not None:
            node_piece[s : s + CHUNK] = np.where(face >= 0, piece[np.maximum(face, 0)], -1)
        pinch[s : s + CHUNK], far[s : s + CHUNK] = _nearest(cp, points)
    firsts, seconds = [], []
    for a, b in band_edges(band, n, CHUNK):
        between = (
            (node_sheet[a] != node_sheet[b])
            & (node_sheet[a] >= 0)
            & (node_sheet[b] >= 0)
            & (node_piece[a] == node_piece[b])
        )
        firsts.append(a[between])
        seconds.append(b[between])
    a, b = np.concatenate(firsts), np.concatenate(seconds)
    if a.size == 0:
        return a, b
    # each edge's reach from its pinch: the farther closest point (∞ when their nearest pinches
    # differ); per pinch and pair of sheets, the edges within PINCH_REACH spacings stay, or the
    # closest ones where none is that close
    reach = np.where(pinch[a] == pinch[b], np.maximum(far[a], far[b]), np.inf)
    lo, hi = np.minimum(node_sheet[a], node_sheet[b]), np.maximum(node_sheet[a], node_sheet[b])
    _, group = np.unique(np.stack([pinch[a], lo, hi], axis=1), axis=0, return_inverse=True)
    group = group.ravel()
    closest_in_group = np.full(int(group.max()) + 1, np.inf)
    np.minimum.at(closest_in_group, group, reach)
    limit = np.maximum(PINCH_REACH * h, closest_in_group[group] * (1.0 + 1e-9))
    cut = ~(reach <= limit)
    return a[cut], b[cut]


def _nearest(x: np.ndarray, points: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The nearest of ``points`` (the pinches: few) to each point of ``x``, and its distance; in
    blocks of them (numpy only)."""
    best = np.full(len(x), np.inf)
    which = np.zeros(len(x), np.int64)
    block = max(1, (1 << 22) // max(len(x), 1))
    for s in range(0, len(points), block):
        d2 = np.sum((x[:, None, :] - points[None, s : s + block, :]) ** 2, axis=2)
        k = np.argmin(d2, axis=1)
        d = np.sqrt(d2[np.arange(len(x)), k])
        better = d < best
        best[better] = d[better]
        which[better] = k[better] + s
    return which, best
