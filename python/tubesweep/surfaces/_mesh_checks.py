"""Checks of a triangle mesh's shape against what the solve can resolve: vertices repeated instead
of shared (a triangle soup), and parts closer to each other than a grid spacing, which no tube
keeps apart (``surfaces.mesh.MeshSurface``)."""

from __future__ import annotations

import warnings
from typing import Any, Optional, Tuple

import numpy as np

from .._warn import user_stacklevel

#: The share of a mesh's area within a grid spacing of another part facing it above which the
#: solve warns: a flat ellipsoid 0.5 × 0.5 × 0.025 gives 32 %, 14 % and 7.9 % at N = 41, 61, 81
#: (its far side 17, 9 and 6 spacings short), twice as thick 5.7 % at N = 41 (2.8 spacings) and
#: none beyond; a box plate 0.08 thick, the icosphere, Spot and the bunny at n = 50–200 at most
#: 0.95 % (``benches/experiments/thin_parts_meshes.py``).
THIN_SHARE = 0.02

#: At most this many faces are tested (evenly strided): the share is an estimate of area.
THIN_FACES = 20000


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
    used = np.unique(f)
    repeated = len(used) - len(np.unique(v[used], axis=0))
    if repeated > 0.1 * len(used):
        warnings.warn(
            f"{repeated} of the mesh's {len(used)} vertices repeat another's coordinates under another index, so the "
            f"triangles do not share them and the mesh reads as open ({boundary_edges} boundary edges). Merge them "
            "first, e.g. trimesh.Trimesh(vertices, faces).merge_vertices() (from_mesh reads .stl files merged)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


def thin_parts(mesh: Any, h: float) -> Tuple[float, Optional[np.ndarray]]:
    """The share of the mesh's area (of up to :data:`THIN_FACES` faces) that lies within a grid
    spacing ``h`` of another part facing it, and a point there (None when there is none): a face
    whose point half a spacing behind its centre, on either side, lies within 0.45h of a face
    whose normal is opposite to its own (a plate thinner than a spacing, two sheets closer than
    one). There the tube's two sides are one and the front crosses between them; the narrow gaps
    that the band is cut across (``_shortcuts``) are only found from about a spacing up."""
    good = mesh._good[:: max(1, -(-len(mesh._good) // THIN_FACES))]
    v, f = mesh.vertices, mesh.faces[good]
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    centre, normal = (a + b + c) / 3.0, mesh.face_normals[good]
    thin = np.zeros(len(good), bool)
    for side in (1.0, -1.0):
        d, _, face, _ = mesh.closest(centre - side * 0.5 * h * normal, max_distance=0.5 * h)
        found = face >= 0
        opposite = np.einsum("ij,ij->i", mesh.face_normals[np.maximum(face, 0)], normal) < -0.5
        thin |= found & (d < 0.45 * h) & opposite
    total = float(area.sum())
    share = float(area[thin].sum()) / total if total > 0 else 0.0
    return share, (centre[np.argmax(thin)] if np.any(thin) else None)


def warn_thin_parts(share: float, where: Optional[np.ndarray], h: float, inner: float) -> None:
    """A RuntimeWarning when :func:`thin_parts` found more than :data:`THIN_SHARE` of the area."""
    if share < THIN_SHARE or where is None:
        return
    at = ", ".join(f"{float(x):.3g}" for x in where)
    warnings.warn(
        f"about {share:.0%} of the mesh's area lies within a grid spacing of another part of it that faces it (a part "
        f"thinner than a spacing, e.g. near ({at})): there the tube cannot keep the two sides apart and the front "
        "crosses between them, so distances past such parts can come out short by as much as the way around the part "
        "(the front goes straight through: a flat ellipsoid 0.05 thick at N = 41–81, 17–6 spacings at its far side; "
        "a plate under a spacing thick, nearly the whole way round its edge). A grid spacing below the part's thickness "
        f"divided by {2 * inner + 2:g} (now {h:.3g}) resolves it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
