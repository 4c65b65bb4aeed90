"""Checks of a triangle mesh's shape against what the solve can resolve: vertices repeated instead
of shared (a triangle soup), and parts closer to each other than a grid spacing, which no tube
keeps apart (``surfaces.mesh.MeshSurface``)."""

from __future__ import annotations

import warnings
from typing import Any, Optional, Tuple

import numpy as np

from .._distinct import distinct_rows, used_vertices
from .._warn import user_stacklevel

#: The share of a mesh's area within about a grid spacing of another part facing it
#: (:data:`THIN_REACH`, :data:`GAP_REACH`) above which the solve warns: a flat ellipsoid
#: 0.5 × 0.5 × 0.025 gives 40 %, 18 % and 9.7 % at N = 41, 61, 81 (its far side 5.0, 3.2 and 1.9
#: spacings short), twice as thick 7.8 % at N = 41 (0.8 spacings) and 0.7 % or none beyond; the
#: bunny at n = 50 1.5 %, at n = 100–200, Spot and the icosphere at n = 50–200 at most 0.13 %
#: (``benches/experiments/thin_parts_meshes.py``; scratch for the bundled meshes).
THIN_SHARE = 0.02

#: At most this many faces are tested (evenly strided): the share is an estimate of area.
THIN_FACES = 20000

#: Parts up to this many grid spacings thick (or gaps this narrow) count as thin. The band is cut
#: between two facing parts only when they lie more than a spacing apart: a box plate and a slot
#: in a block, aligned with the grid or shifted by 0.3 spacings, at N = 41, 61 and 101, were
#: crossed (the plate's bottom 29–72 spacings short) up to 1.00 spacing and solved within 1.4
#: spacings from 1.02 (``benches/experiments/thin_parts_meshes.py --plates``); a margin of 5 %.
THIN_REACH = 1.05

#: Gaps up to this many grid spacings wide count as narrow (probed on the side the normal points
#: to): a slot's mouth is crossed in the tube above it where the closest points of two nodes
#: beside each other jump across it by less than ``_shortcuts.MEDIAL_JUMP`` = 1.5 spacings (a slot
#: 0.3 deep in a block at N = 61, aligned with the grid: 25.6 spacings short up to 1.35 spacings
#: wide, 17.8 at 1.5, within 2.4 from 1.75; shifted by 0.3 spacings: crossed at 1.2, not at 1.35).
GAP_REACH = 1.6


def unique_edges(f: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Undirected edges of the triangles: per-face ids of edges (AB, AC, BC) and use counts."""
    e = np.concatenate([f[:, [0, 1]], f[:, [0, 2]], f[:, [1, 2]]])
    e.sort(axis=1)
    n = int(f.max()) + 1
    _, inv, counts = np.unique(e[:, 0] * n + e[:, 1], return_inverse=True, return_counts=True)
    return inv.reshape(3, -1).T, counts


def warn_repeated_vertices(v: np.ndarray, f: np.ndarray, boundary_edges: int) -> None:
    """A RuntimeWarning for an open-looking mesh whose triangles do not share their vertices but
    repeat them (equal coordinates under other indices, a triangle soup as STL writes it): read as
    given, its shared edges are boundaries, and a closed surface loses its smooth map (a closed
    icosphere's errors 2–3 times the merged mesh's)."""
    used = used_vertices(f, len(v))
    repeated = len(used) - len(distinct_rows(v[used])[0])
    if repeated > 0.1 * len(used):
        warnings.warn(
            f"{repeated} of the mesh's {len(used)} vertices repeat another's coordinates under another index, so the "
            f"triangles do not share them and the mesh reads as open ({boundary_edges} boundary edges). Merge them "
            "first, e.g. trimesh.Trimesh(vertices, faces).merge_vertices() (from_mesh reads .stl files merged)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


def thin_parts(mesh: Any, h: float) -> Tuple[float, Optional[np.ndarray]]:
    """The share of the mesh's area (of up to :data:`THIN_FACES` faces) that lies within
    :data:`THIN_REACH` grid spacings ``h`` of another part facing it, and a point there (None when
    there is none): a face whose point ``q = THIN_REACH·h/2`` behind its centre, on either side,
    lies as near to a face whose normal is opposite to its own as to itself (a plate of thickness
    t ≤ 2q: its other side lies |t − q| ≤ q from that point; two sheets closer than 2q). There the
    tube's two sides are one and the front crosses between them; the narrow gaps that the band is
    cut across (``_shortcuts``) are only found from a spacing up."""
    good = mesh._good[:: max(1, -(-len(mesh._good) // THIN_FACES))]
    v, f = mesh.vertices, mesh.faces[good]
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    # faces wound against their neighbours face the other way here: a plate whose bottom was wound
    # like its top had "no part facing it", unwarned, 98% short across it (a review)
    normals = mesh.face_normals if not getattr(mesh, "_flipped_edges", 0) else oriented_normals(mesh)
    centre, normal = (a + b + c) / 3.0, normals[good]
    thin = np.zeros(len(good), bool)
    for side, reach in ((1.0, THIN_REACH), (-1.0, GAP_REACH)):
        q = 0.5 * reach * h
        d, _, face, _ = mesh.closest(centre - side * q * normal, max_distance=q)
        found = face >= 0
        opposite = np.einsum("ij,ij->i", normals[np.maximum(face, 0)], normal) < -0.5
        thin |= found & (d <= q) & opposite
    total = float(area.sum())
    share = float(area[thin].sum()) / total if total > 0 else 0.0
    return share, (centre[np.argmax(thin)] if np.any(thin) else None)


def oriented_normals(mesh: Any) -> np.ndarray:
    """The mesh's face normals, each turned so that faces sharing an edge (shared by exactly two)
    run it in opposite directions, as consistently wound faces do; in each connected piece the
    orientation most of its faces were given is kept (a piece that cannot be oriented, a Möbius
    band, keeps an arbitrary one). The sign of each face is read from the connected components of
    the graph with two nodes per face (as given, turned): an edge whose faces run it alike joins
    each face as given to the other turned. O(faces)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = mesh.faces
    n = len(f)
    edge_ids, counts = unique_edges(f)  # per face: its edges AB, AC, BC
    # whether the face runs each edge from its smaller vertex: a→b, c→a, b→c
    forward = np.c_[f[:, 0] < f[:, 1], f[:, 2] < f[:, 0], f[:, 1] < f[:, 2]].ravel()
    ids = edge_ids.ravel()
    face = np.repeat(np.arange(n), 3)
    order = np.argsort(ids, kind="stable")
    ids, face, forward = ids[order], face[order], forward[order]
    pair = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])  # each edge's first entry
    pair = pair[counts[ids[pair]] == 2]  # edges of exactly two faces (the others join nothing)
    i, j = face[pair], face[pair + 1]
    alike = forward[pair] == forward[pair + 1]  # run the same way: one of the two is turned
    rows = np.r_[i, i + n]
    cols = np.r_[np.where(alike, j + n, j), np.where(alike, j, j + n)]
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(2 * n, 2 * n))
    _, label = connected_components(graph, directed=False)
    keep, turn = label[:n], label[n:]
    sign = np.where(keep <= turn, 1.0, -1.0)
    # per piece, the orientation most of its faces were given (by area-free count)
    piece = np.minimum(keep, turn)
    given = np.bincount(piece, weights=sign, minlength=2 * n)
    sign *= np.where(given[piece] < 0, -1.0, 1.0)
    return mesh.face_normals * sign[:, None]


def warn_thin_parts(share: float, where: Optional[np.ndarray], h: float, inner: float) -> None:
    """A RuntimeWarning when :func:`thin_parts` found more than :data:`THIN_SHARE` of the area."""
    if share < THIN_SHARE or where is None:
        return
    at = ", ".join(f"{float(x):.3g}" for x in where)
    warnings.warn(
        f"about {share:.0%} of the mesh's area lies within about a grid spacing of another part of it that faces it (a "
        f"part thinner than {THIN_REACH:g} spacings or a gap narrower than {GAP_REACH:g}, e.g. near ({at})): there the "
        "tube cannot keep the two sides apart and the front can cross between them, so distances past such parts can "
        "come out short by as much as the way around the part "
        "(a plate a spacing thick from its top's centre to its bottom's: nearly the whole way round its edge; a slot "
        "1.5 spacings wide and 0.3 deep, from one side of it to the other: up to twice its depth). A grid spacing below "
        "the part's thickness or the gap's width "
        f"divided by {2 * inner + 2:g} (now {h:.3g}) resolves it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
