"""Slits: an open mesh's boundary coming within a few grid spacings of itself, edge on, across
empty space (a cylinder slit along its length, a sheet with a narrow cut).

Where the two sides of a slit lie in one sheet (the gap runs in their tangent planes), the band
joins them, and nothing in the band tells that the nodes between them are off the surface: the
facing tests (``_mesh_smooth.facing_pairs``, the tube's ``Band.facing_sheet_pairs``) look for
sheets facing each other along their normals, the medial cuts (``_shortcuts``) for closest
points jumping by more than 1.5 spacings, and the hole test (``_mesh_holes``) for closed loops
round a hole. The front crossed the slit: a cylinder of radius 0.3 slit along its length, the
source on the slit's edge, came out 95–99% short on the far side at N = 41–121 with slits up to
1.5 spacings wide (up to 2.1 at second order, whose source fixed the nodes across:
``tubesweep_core::second_order::joined``), unwarned.

:func:`find` reads the mesh: boundary vertices closer than :data:`GAP_SPACINGS` grid spacings on
one boundary loop, far apart along it (:data:`ALONG`), whose midpoint lies off the mesh
(:data:`OFF_MESH`) and whose gap runs in both sides' tangent planes (:data:`EDGE_ON`). Sides that
face each other across a gap (the walls of a slot) are left to the facing tests, which cut the
band between them (the bundled bunny's base has a slot 0.0065 wide whose way round is 20% of its
size, its errors next to it those elsewhere; its pairs' sides turn their normals 0.16–0.89
towards the gap, a slit cylinder's 0.02–0.07). :func:`slit_cut_pairs` then places the band nodes
near a slit along its boundary loop, by their closest points, and the tube's preparation cuts the
band edges whose two places lie far apart along the loop: the front goes round the slit's end
(``benches/experiments/mesh_slits.py``: the cylinder's far side within 0.08 spacings of the way
round, a sheet's points round a slit's end within 0.16–0.41 spacings, 1.4 at a slit of 3.95).
Facing pairs across a slit are no gap between sheets (:func:`pairs_over_openings`).

Not judged: open edges on two loops (two holes, a hole and the outline; separate parts are cut
apart anyway), boundaries that are no simple loops, meshes of more than :data:`MAX_BOUNDARY`
boundary vertices, and point clouds. Where a point lies within a cell of a slit narrower than a
spacing, ``sol(points)`` reads corners on both sides (0.64–0.8 of the way round at the far edge
itself, right from a spacing on).
"""

from __future__ import annotations

import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from .._warn import user_stacklevel
from ._mesh_holes import WARN_SHARE, boundary_edges, holes, pairs_over_holes

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
#: Band nodes within this many grid spacings of a slit's vertex pair are placed along its loop
#: (:func:`slit_cut_pairs`),
CUT_REACH = GAP_SPACINGS + 2.0
#: ... where their closest point on the mesh lies within this many spacings of the loop (the
#: nodes beyond the open edges, whose closest points lie on it, and those over the faces next to
#: it: across a slit narrower than a spacing most edges join two of those; only nodes beyond the
#: edges, 13–35 spacings short);
POSITION_REACH = 2.0
#: and the band edge between two of them is cut where the way between their places along the
#: loop exceeds their closest points' distance by more than this many spacings. The plane sheet
#: with a slit of 0.3–4 spacings (``benches/experiments/mesh_slits.py``): at 2 the front cut the
#: slit's end by 1.7 spacings; with places at the nearest boundary vertex, at 0.5, the cut split
#: a side's own edges. Not kept (the slit's mouth leaked 8–54 spacings): cutting only where the
#: two places' middle lies off the mesh, or where each lies beyond the other's edge, to spare the
#: faces next to a convex corner of the outline, where places jump across the corner's bisector
#: and the cut runs along it for up to :data:`POSITION_REACH` spacings.
TIP_SPACINGS = 1.0
#: Band nodes per block of the search for those nodes.
CHUNK = 1 << 16
#: Meshes with more boundary vertices than this are not judged (the loops are walked in Python).
MAX_BOUNDARY = 200_000


def slits(surface: Any, h: float, cut_edges: Optional[int] = None) -> Optional[dict]:
    """:func:`find` with ``cut_edges``, the band edges the tube's preparation (``_prepare``) cut
    across the slits (:func:`slit_cut_pairs`; none where the medial cuts had cut them already):
    ``MeshSurface._slits``, as ``sol.stats.slits``. Warned (:func:`warn_slits`) where the band is
    not cut (``cut_edges`` None)."""
    info = find(surface, h)
    if info is not None:
        info["cut_edges"] = int(cut_edges or 0)
        if cut_edges is None:
            warn_slits(info, h)
    return info


def find(surface: Any, h: float) -> Optional[dict]:
    """The slits of ``surface`` (a ``MeshSurface``) at grid spacing ``h`` (module notes), the pair
    with the longest way round: ``gap`` (the narrowest pair's distance), ``where`` (that pair's
    midpoint), ``detour`` (the way between them along their boundary loop less their distance:
    how much shorter a distance reached across can come out), ``count`` (vertex pairs) and
    ``size`` (the used vertices' bounding-box diagonal); None when there is none."""
    found = _slit_pairs(surface, h)
    if found is None:
        return None
    a, b, d, along = found
    v = surface.vertices
    k = int(np.argmax(along - d))
    used = v[surface.used_vertices]
    return {
        "count": int(d.size),
        "gap": float(d.min()),
        "where": tuple(round(float(c), 6) for c in 0.5 * (v[a[k]] + v[b[k]])),
        "detour": float(along[k] - d[k]),
        "size": float(np.linalg.norm(used.max(axis=0) - used.min(axis=0))),
    }


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
    edges = boundary_edges(surface.faces)
    if len(edges) == 0:
        return None
    v = surface.vertices
    on = np.unique(edges)
    if on.size > MAX_BOUNDARY:
        return None
    loop, s, length = _loops(surface, edges)
    if length.size == 0:
        return None
    i, j = _close_pairs(v[on], GAP_SPACINGS * h)
    if i.size == 0:
        return None
    a, b = on[i], on[j]
    d = np.linalg.norm(v[a] - v[b], axis=1)
    same = (loop[a] >= 0) & (loop[a] == loop[b])
    along = np.abs(s[a] - s[b])
    along = np.minimum(along, length[np.maximum(loop[a], 0)] - along)
    far = same & (d > 0.01 * h) & (along > ALONG * d)
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


def slit_cut_pairs(surface: Any, grid: Any, band: Any, linear: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The band edges across the slits of ``surface`` (``node``, ``neighbour``: band positions):
    ``MeshSurface._slit_cut_pairs``, read by the tube's preparation, which cuts them. Each band
    node within :data:`CUT_REACH` grid spacings of a slit whose closest point lies within
    :data:`POSITION_REACH` spacings of the slit's boundary loop takes its place along the loop
    (the arclength of the nearest point of the loop); an edge between two such nodes is cut when
    the way between their places along the loop exceeds their closest points' distance by more
    than :data:`TIP_SPACINGS` spacings: the two sides of the slit, up to about a spacing from its
    end. Empty where there is no slit."""
    empty = np.zeros(0, np.int64)
    h = float(grid.spacing)
    found = _slit_pairs(surface, h)
    if found is None or len(linear) == 0:
        return empty, empty
    from scipy.spatial import cKDTree

    a, b, _, _ = found
    v = surface.vertices
    edges = boundary_edges(surface.faces)
    loop, s, length = _loops(surface, edges)
    edges = edges[np.isin(loop[edges[:, 0]], np.unique(loop[a]))]  # the slits' loops' edges
    mids = cKDTree(0.5 * (v[a] + v[b]))
    near = []
    for start in range(0, len(linear), CHUNK):
        at = np.arange(start, min(start + CHUNK, len(linear)), dtype=np.int64)
        dist, _ = mids.query(grid.node_points(linear[at]), distance_upper_bound=CUT_REACH * h)
        near.append(at[np.isfinite(dist)])
    nodes = np.concatenate(near)
    if nodes.size == 0:
        return empty, empty
    cp = surface.closest(grid.node_points(linear[nodes]))[1]
    dist, place, on_loop = _places(v, edges, loop, s, length, cp)
    placed = dist <= POSITION_REACH * h
    where = np.full(len(linear), -1, np.int64)  # per band node: its entry in `nodes`, -1 if none
    where[nodes[placed]] = np.flatnonzero(placed)
    nb = band.neighbours_of_nodes(nodes[placed]).reshape(int(placed.sum()), -1)
    first = np.repeat(nodes[placed], nb.shape[1])
    second = nb.ravel()
    keep = (second < len(linear)) & (second > first)
    first, second = first[keep], second[keep]
    keep = where[second] >= 0
    first, second = first[keep], second[keep]
    p, q = where[first], where[second]
    same = on_loop[p] == on_loop[q]
    along = np.abs(place[p] - place[q])
    along = np.minimum(along, length[on_loop[p]] - along)
    apart = np.linalg.norm(cp[p] - cp[q], axis=1)
    cut = same & (along - apart > TIP_SPACINGS * h)
    return first[cut], second[cut]


def pairs_over_openings(surface: Any, grid: Any, first: np.ndarray, second: np.ndarray, *_: Any) -> np.ndarray:
    """``MeshSurface._pairs_over_holes``: the facing pairs (linear indices on ``grid``) over a
    hole (``_mesh_holes.pairs_over_holes``) or across a slit, whose two closest points lie on
    the slit's loop farther apart along it than :func:`slit_cut_pairs` cuts. The tube's
    preparation leaves them out of the facing pairs (no warning, no cut, not in
    ``sol.stats.facing_pairs``): the band is cut across slits by :func:`slit_cut_pairs`, and a
    plane sheet with a slit 2.4 spacings wide no longer ran first order as "facing itself"."""
    out = pairs_over_holes(surface, grid, first, second)
    h = float(grid.spacing)
    found = _slit_pairs(surface, h)
    if found is None or len(first) == 0:
        return out
    v = surface.vertices
    edges = boundary_edges(surface.faces)
    loop, s, length = _loops(surface, edges)
    edges = edges[np.isin(loop[edges[:, 0]], np.unique(loop[found[0]]))]
    cp1 = surface.closest(grid.node_points(first))[1]
    cp2 = surface.closest(grid.node_points(second))[1]
    d1, place1, loop1 = _places(v, edges, loop, s, length, cp1)
    d2, place2, loop2 = _places(v, edges, loop, s, length, cp2)
    along = np.abs(place1 - place2)
    along = np.minimum(along, length[loop1] - along)
    candidate = (
        (d1 <= POSITION_REACH * h)
        & (d2 <= POSITION_REACH * h)
        & (loop1 == loop2)
        & (along - np.linalg.norm(cp1 - cp2, axis=1) > TIP_SPACINGS * h)
    )
    return out | candidate


def _places(
    v: np.ndarray, edges: np.ndarray, loop: np.ndarray, s: np.ndarray, length: np.ndarray, x: np.ndarray
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For points ``x``: the distance to the nearest point of the boundary ``edges`` (on simple
    loops, :func:`_loops`), that point's arclength along its loop, and the loop. Brute force in
    blocks over the edges near each point (a k-d tree of the edges' midpoints, radius half the
    longest edge plus the nearest midpoint's distance)."""
    from scipy.spatial import cKDTree

    p0, p1 = v[edges[:, 0]], v[edges[:, 1]]
    seg = p1 - p0
    seg_len2 = np.maximum(np.einsum("ij,ij->i", seg, seg), 1e-300)
    ds = s[edges[:, 1]] - s[edges[:, 0]]
    lengths = length[loop[edges[:, 0]]]
    ds = np.where(ds > lengths / 2, ds - lengths, np.where(ds < -lengths / 2, ds + lengths, ds))
    tree = cKDTree(0.5 * (p0 + p1))
    half = 0.5 * float(np.sqrt(seg_len2.max()))
    first, _ = tree.query(x)
    best = np.full(len(x), np.inf)
    place = np.zeros(len(x))
    which = np.zeros(len(x), np.int64)
    for i, cand in enumerate(tree.query_ball_point(x, first + 2.0 * half)):
        c = np.asarray(cand, np.int64)
        t = np.clip(np.einsum("ij,ij->i", x[i] - p0[c], seg[c]) / seg_len2[c], 0.0, 1.0)
        d = np.linalg.norm(p0[c] + t[:, None] * seg[c] - x[i], axis=1)
        k = int(np.argmin(d))
        best[i] = d[k]
        place[i] = (s[edges[c[k], 0]] + t[k] * ds[c[k]]) % lengths[c[k]]
        which[i] = loop[edges[c[k], 0]]
    return best, place, which


def warn_slits(info: Optional[dict], h: float) -> None:
    """The warning for :func:`find`'s slits, when the way round is over ``WARN_SHARE`` of the
    mesh's size (as for its holes)."""
    if info is None or info["detour"] <= WARN_SHARE * info["size"]:
        return
    warnings.warn(
        f"the mesh's open edges come within {info['gap']:.3g} of each other across empty space near {info['where']} "
        f"({info['gap'] / h:.2g} grid spacings: a slit; {info['count']} vertex pair(s) closer than "
        f"{GAP_SPACINGS:g} spacings): the band joins the two sides and the front can cross the slit, so distances "
        f"reached across it can come out short, by up to about {info['detour']:.3g} "
        f"({info['detour'] / info['size']:.0%} of the mesh's size: the way round along its open edges). "
        f"sol.stats.slits has it; a grid spacing below {info['gap'] / GAP_SPACINGS:.3g} (now {h:.3g}) keeps the "
        "sides apart; if the surface is closed there, close the slit in the mesh",
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


def _close_pairs(x: np.ndarray, radius: float) -> Tuple[np.ndarray, np.ndarray]:
    """Index pairs ``i < j`` of the points ``x`` closer than ``radius`` (cells of that size)."""
    cell = np.floor(x / radius).astype(np.int64)
    cell -= cell.min(axis=0)
    dims = cell.max(axis=0) + 3
    key = ((cell[:, 0] + 1) * dims[1] + (cell[:, 1] + 1)) * dims[2] + (cell[:, 2] + 1)
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
                keep = (i < j) & (np.linalg.norm(x[i] - x[j], axis=1) < radius)
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
