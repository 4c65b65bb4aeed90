"""The band and closest points of :class:`~tubesweep.surfaces.mesh.SmoothMeshSurface`: the smooth
closest-point map of a triangle mesh, computed in the Rust core
(``tubesweep_core::surface::mesh_smooth``) on all threads and only at the band's candidate nodes.
"""

from __future__ import annotations

from typing import Any, Callable, Optional, Tuple

import numpy as np

from .._linalg import row_norms
from ..band import BandGeometry
from ..closest_point import DIRECTION_EPS
from ..grid import Grid

#: Samples in each local fit (as for point clouds, docs/point-clouds.md).
NEIGHBOURS = 20
#: Face samples about this many grid spacings apart (the fits then follow the polyhedron to a
#: fraction of Δx and round its creases over a few Δx).
SAMPLE_SPACING = 1.0
#: The names of the maps, in the order of the core's ``MapKind`` codes.
KINDS = ("fitted", "fine", "rim", "fallback", "far")
#: Candidates are searched this many grid spacings beyond the band's half-width: the smooth map's
#: distance differs from the exact one by at most a quarter of a triangle's size (the fits stay far closer: their samples lie on the mesh), and triangles
#: larger than Δx are fitted (a node whose smooth distance is within the half-width is never lost).
MARGIN = 0.5
#: A mesh whose triangles' median size (longest edge) exceeds this many grid spacings is coarse
#: against the grid: its band is the exact map's, and ``order="auto"`` runs first order on it (the
#: fitted map of Spot at n = 200, 4.7 Δx, made the second-order sweeps run away; docs/point-clouds.md).
COARSE = 3.0
#: Triangles larger than this many grid spacings (longest edge) are fitted
#: (``tubesweep_core::surface::mesh_smooth::FINE_LOW``).
FINE = 2.0
#: Nodes per call of the native closest points (bounds the memory of a band's evaluation).
CHUNK = 1 << 20


def closest(surface: Any, x: np.ndarray, h: Optional[float]) -> Tuple[np.ndarray, np.ndarray]:
    """The smooth map's closest points of ``x`` (M, 3) for grid spacing ``h`` (None: the exact
    closest points) and the map of each (codes of :data:`KINDS`)."""
    x = np.ascontiguousarray(np.asarray(x, dtype=float).reshape(-1, 3))
    # before any band, or on a mesh coarse against the grid: the exact closest points
    if h is None or median_size(surface) > COARSE * h or "facing" in surface.report:
        _, cp, _, _ = surface.closest(x)
        return cp, np.full(len(x), 1, np.uint8)
    mode = "auto"
    out = np.empty_like(x)
    kinds = np.empty(len(x), np.uint8)
    for s0 in range(0, len(x), CHUNK):
        cp, kind = surface.smooth_map.closest(x[s0 : s0 + CHUNK], float(h or 1.0), np.inf, mode)
        out[s0 : s0 + CHUNK] = cp
        kinds[s0 : s0 + CHUNK] = kind
    return out, kinds


def band(surface: Any, grid: Grid, half_width: float, exact_band: Callable[[], BandGeometry]) -> BandGeometry:
    """The band of the smooth map (see :meth:`SmoothMeshSurface.band`); ``exact_band()`` gives the
    exact map's (:meth:`MeshSurface.band`), used on a coarse mesh."""
    surface.check_grid(grid)
    h = grid.spacing
    surface._h = h
    surface._band_cache = None
    size = median_size(surface)
    if size > COARSE * h:
        # coarse: today's band of the exact map, and first order (order2_obstacle)
        surface.report = {"coarse": size / h, "h": h}
        return exact_band()
    if largest_size(surface) > FINE * h or not surface.closed:
        # fits will be needed (large triangles, or a boundary's blend): first the exact map's band,
        # and where the mesh faces itself across a gap narrower than its tubes that band and first
        # order (order2_obstacle), without the fits' cost
        exact = exact_band()
        pairs = facing_pairs(grid, exact)
        if pairs:
            surface.report = {"facing": pairs, "h": h}
            return exact
    reach = half_width + MARGIN * h
    candidates = surface.band_candidates(grid, reach)
    parts: list = []
    counts = np.zeros(len(KINDS), np.int64)
    for s0 in range(0, len(candidates), CHUNK):
        lin = candidates[s0 : s0 + CHUNK]
        x = grid.node_points(lin)
        cp, kind = surface.smooth_map.closest(np.ascontiguousarray(x), h, reach, "auto")
        norm = row_norms(x - cp)
        keep = norm <= half_width  # False where nothing is within reach (NaN: beyond the band)
        counts += np.bincount(kind[keep], minlength=len(KINDS))[: len(KINDS)]
        parts.append((lin[keep], norm[keep], x[keep], cp[keep]))
    surface.report = {name: int(c) for name, c in zip(KINDS[:4], counts[:4])}
    surface.report["h"] = h
    if not parts or sum(len(q[0]) for q in parts) == 0:
        return BandGeometry(np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3), np.float32))
    linear, norm, x, cp = (np.concatenate([q[i] for q in parts]) for i in range(4))
    # the map's noise near the surface (for the facing-sheets test): |cp(cp(x)) − cp(x)|
    pick = np.linspace(0, len(linear) - 1, min(len(linear), 512)).astype(np.int64)
    again, _ = surface.smooth_map.closest(np.ascontiguousarray(cp[pick]), h, np.inf, "auto")
    surface._noise = float(np.quantile(row_norms(again - cp[pick]), 0.9))
    surface._band_cache = (x, cp)
    ok = norm > DIRECTION_EPS * h
    direction = np.zeros((len(linear), 3))
    direction[ok] = (x[ok] - cp[ok]) / norm[ok, None]
    return BandGeometry(linear, norm, norm.copy(), direction.astype(np.float32), consumable=True)


def median_size(surface: Any) -> float:
    """The median longest edge of the mesh's non-degenerate triangles (computed once)."""
    known = getattr(surface, "_median_size", None)
    if known is not None:
        return float(known)
    f = surface.faces[surface._good]
    v = surface.vertices
    edges = [np.linalg.norm(v[f[:, i]] - v[f[:, j]], axis=1) for i, j in ((0, 1), (1, 2), (2, 0))]
    surface._median_size = float(np.median(np.maximum(np.maximum(edges[0], edges[1]), edges[2])))
    return float(surface._median_size)


def largest_size(surface: Any) -> float:
    """The largest longest edge of the mesh's non-degenerate triangles."""
    f = surface.faces[surface._good]
    v = surface.vertices
    edges = [np.linalg.norm(v[f[:, i]] - v[f[:, j]], axis=1) for i, j in ((0, 1), (1, 2), (2, 0))]
    return float(np.max(np.maximum(np.maximum(edges[0], edges[1]), edges[2])))


def facing_pairs(grid: Grid, geom: BandGeometry) -> int:
    """Pairs of grid neighbours of the band, both more than 0.75 Δx from the mesh, whose extension
    directions point more than 120° apart: the two sides of a gap narrower than the tubes (across a
    single sheet two neighbours cannot both be that far from it)."""
    h = grid.spacing
    lin = geom.linear
    if len(lin) == 0:
        return 0
    dist = geom.distance if geom.distance is not None else np.abs(geom.signed)
    far = dist > 0.75 * h
    count = 0
    for k in range(grid.ndim):
        stride = int(np.prod(grid.shape[k + 1 :]))
        nxt = lin + stride
        pos = np.minimum(np.searchsorted(lin, nxt), len(lin) - 1)
        hit = (lin[pos] == nxt) & far & far[pos] & ((lin // stride) % grid.shape[k] < grid.shape[k] - 1)
        dots = np.einsum("ij,ij->i", geom.direction[hit], geom.direction[pos[hit]])
        count += int(np.count_nonzero(dots < -0.5))
    return count


def order2_obstacle(surface: Any, tube_pairs: int) -> Optional[str]:
    """Why ``order=2`` does not run on this mesh's tube, or None (see the module constants)."""
    report = surface.report
    if "coarse" in report:
        return (
            f"the mesh is coarse against the grid: its triangles' median size is {report['coarse']:.1f} grid spacings "
            f"(second order on a mesh needs at most {COARSE:g}); subdivide the mesh, or use the grid it resolves"
        )
    pairs = report.get("facing", 0) or tube_pairs
    if pairs:
        return (
            f"the mesh faces itself across gaps narrower than its tubes ({pairs} node pairs): the second-order "
            "sweeps are not safe there on a mesh (they ran away on the bunny at n = 200); a finer grid resolves the gap"
        )
    return None
