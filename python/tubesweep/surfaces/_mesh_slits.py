"""Slits: an open mesh's boundary coming within a few grid spacings of itself, edge on, across
empty space (a cylinder slit along its length, a sheet with a narrow cut, a comb's teeth).

Where the two sides of a slit lie in one sheet (the gap runs in their tangent planes), the band
joins them, and nothing in the band tells that the nodes between them are off the surface: the
facing tests (``_mesh_smooth.facing_pairs``, the tube's ``Band.facing_sheet_pairs``) look for
sheets facing each other along their normals, the medial cuts (``_shortcuts``) for closest
points jumping by more than 1.5 spacings, and the hole test (``_mesh_holes``) for closed loops
round a hole. The front crosses a slit narrower than about 1.5 spacings: a cylinder of radius
0.3 slit along its length, the source on the slit's edge, came out 95–99% short on the far side
at N = 41–121, unwarned (and up to 2.1 spacings at second order, whose source fixed the nodes
across: ``tubesweep_core::second_order::joined`` keeps them apart now).

:func:`find` reads the mesh: boundary vertices closer than :data:`GAP_SPACINGS` grid spacings on
one boundary loop, far apart along it (:data:`ALONG`), whose midpoint lies off the mesh
(:data:`OFF_MESH`) and whose gap runs in both sides' tangent planes (:data:`EDGE_ON`). Sides that
face each other across a gap (the walls of a slot) are left to the facing tests, which cut the
band between them (the bundled bunny's base has a slot 0.0065 wide whose way round is 20% of its
size, its errors next to it those elsewhere; its pairs' sides turn their normals 0.16–0.89
towards the gap, a slit cylinder's 0.02–0.07). The slits are reported (``sol.stats.slits``) and
warned about where the band joins their sides (narrower than :data:`WARN_SPACINGS` across a grid
axis, up to :data:`DIAGONAL_SPACINGS` more diagonally) and the way round is over ``WARN_SHARE``
of the mesh's size, with the grid spacing that keeps the sides apart.

*Not kept*: cutting the band across a slit, by the places of the nodes' closest points along the
boundary loop (the edges whose two places lie more than their distance apart along it). It gave
the slit cylinder and clean slits in a sheet their right distances, but a helper's review found
it cut strips narrower than about 4 spacings beside a slit lengthwise (a comb's teeth 18–90
spacings too long), left nodes unreached behind zig-zag slit edges, let order 2 run (and cross)
where the facing pairs across a slit of 3–3.5 spacings had sent it to order 1, missed the stretch
between boundary vertices 12 spacings apart along a slit, and doubled the set-up of a sheet with
six slits (docs/development/history-notes.md).

Not judged: open edges on two loops (two holes, a hole and the outline; separate parts are cut
apart anyway), boundaries that are no simple loops, meshes of more than :data:`MAX_BOUNDARY`
boundary vertices, and point clouds.
"""

from __future__ import annotations

import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from .._distinct import distinct
from .._warn import user_stacklevel
from ._mesh_holes import WARN_SHARE, boundary_edges_of, holes

#: Boundary vertices closer than this many grid spacings are judged (the cuts kept a slit's sides
#: apart from 3.2 spacings on).
GAP_SPACINGS = 4.0
#: ... when the way between them along their boundary loop is more than this many times their
#: distance (a rim's consecutive vertices, and two sides of a corner, are not a slit),
ALONG = 3.0
#: ... their midpoint lies off the mesh by more than this share of their distance,
OFF_MESH = 0.25
#: ... and the gap's direction makes an angle with both sides' normals whose cosine is below this
#: (17°: in their tangent planes; sides facing each other are the facing tests').
EDGE_ON = 0.3
#: The warning is given where a slit is narrower than this many grid spacings across an axis of
#: the grid (the medial cuts, ``_shortcuts.MEDIAL_JUMP``, keep a slit's sides apart from 1.5
#: spacings: the slit cylinder came out 95–99% short at 1.5, right from 1.6 on, at first and at
#: second order),
WARN_SPACINGS = 1.6
#: ... and this many more diagonally in a grid plane (the cylinder turned by 45° about its axis:
#: its far edge's vertices read 4.1–15.5 spacings short with slits of 1.8–2.3 spacings, their cells
#: straddling the slit, 0.20 at 3, ``benches/experiments/mesh_slits.py``; a helper's review: 0.7
#: at 2.6, and turned by 22.5° right at 2.0).
DIAGONAL_SPACINGS = 1.0
#: Meshes with more boundary vertices than this are not judged (the loops are walked in Python).
MAX_BOUNDARY = 200_000


def slits(surface: Any, h: float, *_: Any) -> Optional[dict]:
    """:func:`find`, warned (:func:`warn_slits`): ``MeshSurface._slits``, read by the tube's
    preparation (``_prepare``) as ``sol.stats.slits``."""
    info = find(surface, h)
    warn_slits(info, h)
    return info


def find(surface: Any, h: float) -> Optional[dict]:
    """The slits of ``surface`` (a ``MeshSurface``) at grid spacing ``h`` (module notes), the pair
    with the longest way round: ``gap`` (the narrowest pair's distance), ``where`` (that pair's
    midpoint), ``detour`` (the way between them along their boundary loop less their distance:
    how much shorter a distance reached across can come out), ``count`` (vertex pairs) and
    ``size`` (the used vertices' bounding-box diagonal), ``joined`` (the pairs narrower than the
    band keeps apart in their direction, :func:`apart_spacings`) and ``spacing`` (the grid spacing
    below which it keeps them all apart); None when there is none."""
    found = _slit_pairs(surface, h)
    if found is None:
        return None
    a, b, d, along = found
    v = surface.vertices
    k = int(np.argmax(along - d))
    used = v[surface.used_vertices]
    # the width across: each vertex's nearest partner (the pairs slanting along the slit are wider
    # and lie diagonally in the grid)
    order = np.argsort(d, kind="stable")
    first = np.zeros(d.size, bool)
    for end in (a, b):
        _, at = np.unique(end[order], return_index=True)
        first[order[at]] = True
    across = d[first]
    apart = apart_spacings((v[b[first]] - v[a[first]]) / across[:, None])
    return {
        "count": int(d.size),
        "gap": float(d.min()),
        "where": tuple(round(float(c), 6) for c in 0.5 * (v[a[k]] + v[b[k]])),
        "detour": float(along[k] - d[k]),
        "size": float(np.linalg.norm(used.max(axis=0) - used.min(axis=0))),
        "joined": int(np.count_nonzero(across < apart * h)),
        "spacing": float(np.min(across / apart)),
    }


def apart_spacings(direction: np.ndarray) -> np.ndarray:
    """Per unit ``direction`` across a slit, the width in grid spacings from which the band keeps
    its sides apart: :data:`WARN_SPACINGS` along an axis, :data:`WARN_SPACINGS` +
    :data:`DIAGONAL_SPACINGS` diagonally in a grid plane (in between as ``1 − max |u_k|``)."""
    t = (1.0 - np.max(np.abs(direction), axis=1)) / (1.0 - np.sqrt(0.5))
    return WARN_SPACINGS + DIAGONAL_SPACINGS * t


def _slit_pairs(surface: Any, h: float) -> Optional[Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The boundary vertex pairs across slits (module notes): vertices ``a``, ``b``, their
    distance and the way between them along their loop; None when there are none. Kept per
    spacing."""
    cache: Dict[float, Any] = surface.__dict__.setdefault("_slit_cache", {})
    if h not in cache:
        cache[h] = _search(surface, h)
    return cache[h]


def _search(surface: Any, h: float) -> Optional[Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    if surface.closed:
        return None
    edges = boundary_edges_of(surface)
    if len(edges) == 0:
        return None
    v = surface.vertices
    on = distinct(edges)
    if on.size > MAX_BOUNDARY:
        return None
    loop, s, length = _loops(surface, edges)
    if length.size == 0:
        return None
    # only pairs on one simple loop are judged: searched loop by loop (a triangle soup's 60,000
    # boundary vertices on 20,000 loops made 30 million pairs across loops, 11 s of its refusal)
    on = on[loop[on] >= 0]
    i, j = _close_pairs(v[on], GAP_SPACINGS * h, loop[on])
    if i.size == 0:
        return None
    a, b = on[i], on[j]
    d = np.linalg.norm(v[a] - v[b], axis=1)
    along = np.abs(s[a] - s[b])
    along = np.minimum(along, length[loop[a]] - along)
    far = (d > 0.01 * h) & (along > ALONG * d)
    # pairs across a hole not much wider than themselves are that hole's (``_mesh_holes``); a hole
    # much wider (the outline of a slit cylinder passes for one) can still pinch into a slit
    found = holes(surface)
    hole = found.vertex_hole
    width = np.r_[found.width, np.inf][np.where(hole[a] >= 0, hole[a], -1)]
    far &= ~((hole[a] >= 0) & (hole[a] == hole[b]) & (width < 2.0 * d))
    if not np.any(far):
        return None
    a, b, d, along = a[far], b[far], d[far], along[far]
    normal = _vertex_normals(surface)
    gap = (v[b] - v[a]) / d[:, None]
    edge_on = (np.abs(np.sum(normal[a] * gap, axis=1)) < EDGE_ON) & (np.abs(np.sum(normal[b] * gap, axis=1)) < EDGE_ON)
    if not np.any(edge_on):
        return None
    a, b, d, along = a[edge_on], b[edge_on], d[edge_on], along[edge_on]
    off = surface.closest(0.5 * (v[a] + v[b]))[0] > OFF_MESH * d
    if not np.any(off):
        return None
    return a[off], b[off], d[off], along[off]


def warn_slits(info: Optional[dict], h: float) -> None:
    """The warning for :func:`find`'s slits, when the band joins the sides of some (``joined``)
    and the way round is over ``WARN_SHARE`` of the mesh's size (as for its holes)."""
    if info is None or not info["joined"] or info["detour"] <= WARN_SHARE * info["size"]:
        return
    warnings.warn(
        f"the mesh's open edges come within {info['gap']:.3g} of each other across empty space "
        f"({info['gap'] / h:.2g} grid spacings: a slit, near {info['where']}): the band joins the two sides, so the "
        "front can cross the slit and values read next to its edges mix both sides: distances across it can come out "
        "short, by up to about "
        f"{info['detour']:.3g} ({info['detour'] / info['size']:.0%} of the mesh's size: the way round along its "
        f"open edges). sol.stats.slits has it; a grid spacing below {info['spacing']:.3g} (now {h:.3g}) "
        "keeps the sides apart; if the surface is closed there, close the slit in the mesh",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _vertex_normals(surface: Any) -> np.ndarray:
    """Unit normals at the vertices, the sum of their triangles' area-weighted normals (their
    signs do not matter here)."""
    v = surface.vertices
    f = np.asarray(surface.faces, dtype=np.int64)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    out = np.zeros_like(v)
    for k in range(3):
        np.add.at(out, f[:, k], n)
    norm = np.linalg.norm(out, axis=1, keepdims=True)
    return out / np.where(norm > 0.0, norm, 1.0)


def _close_pairs(x: np.ndarray, radius: float, group: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Index pairs ``i < j`` of the points ``x`` closer than ``radius`` and in the same ``group``
    (non-negative labels; cells of that size per group)."""
    if len(x) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    cell = np.floor(x / radius).astype(np.int64)
    cell -= cell.min(axis=0)
    dims = cell.max(axis=0) + 3
    key = ((cell[:, 0] + 1) * dims[1] + (cell[:, 1] + 1)) * dims[2] + (cell[:, 2] + 1)
    # each group's cells in a range of keys of its own (the padding of one cell on each side keeps
    # the neighbours' offsets inside it), unless that overflows: then pairs across groups are
    # dropped after the search
    span = int(np.prod(dims, dtype=np.float64))
    if span * float(group.max() + 1) < 2.0**62:
        key = key + group.astype(np.int64) * span
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    firsts, seconds = [], []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                other = key + (dx * dims[1] + dy) * dims[2] + dz
                lo = np.searchsorted(sorted_key, other, "left")
                hi = np.searchsorted(sorted_key, other, "right")
                count = hi - lo
                i = np.repeat(np.arange(len(x)), count)
                offset = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
                j = order[np.repeat(lo, count) + offset]
                keep = (i < j) & (group[i] == group[j]) & (np.linalg.norm(x[i] - x[j], axis=1) < radius)
                firsts.append(i[keep])
                seconds.append(j[keep])
    return np.concatenate(firsts), np.concatenate(seconds)


def _loops(surface: Any, edges: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per vertex its boundary loop (-1 off the boundary, -2 on a boundary that is no simple
    loop), its arclength from the loop's first vertex, and per loop its length; computed once per
    mesh."""
    cached: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray]] = surface.__dict__.get("_boundary_loops")
    if cached is not None:
        return cached
    v = surface.vertices
    n = len(v)
    loop = np.full(n, -1, np.int64)
    s = np.zeros(n)
    degree = np.bincount(edges.ravel(), minlength=n)
    ends_of: Dict[int, list] = {}
    for p, q in edges.tolist():
        ends_of.setdefault(p, []).append(q)
        ends_of.setdefault(q, []).append(p)
    seen = np.zeros(n, bool)
    lengths: list = []
    for start in np.flatnonzero(degree > 0).tolist():
        if seen[start]:
            continue
        path, prev, cur, simple = [start], -1, start, True
        seen[start] = True
        while True:
            nxt = ends_of[cur]
            if len(nxt) != 2:
                simple = False
                break
            step = nxt[1] if nxt[0] == prev else nxt[0]
            prev, cur = cur, step
            if cur == start:
                break
            if seen[cur]:
                simple = False
                break
            seen[cur] = True
            path.append(cur)
        p = np.asarray(path)
        if not simple:
            loop[p] = -2
            continue
        steps = np.linalg.norm(np.diff(v[np.r_[p, p[:1]]], axis=0), axis=1)
        s[p] = np.r_[0.0, np.cumsum(steps[:-1])]
        loop[p] = len(lengths)
        lengths.append(float(steps.sum()))
    out = (loop, s, np.asarray(lengths, float))
    surface.__dict__["_boundary_loops"] = out
    return out
