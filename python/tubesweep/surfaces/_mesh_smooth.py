"""The band, closest points and methods (:class:`SmoothMap`) of
:class:`~tubesweep.surfaces.mesh.SmoothMeshSurface`: the smooth
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
from ._mesh_holes import across_holes
from ._mesh_notches import pairs_at_notches
from ._mesh_parts import merged_vertices

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
#: against the grid. If it has creases of its own (:data:`SHARP_TURN`), its band is the exact
#: map's and ``order="auto"`` runs first order on it (the fitted map of Spot at n = 200, 4.7 Δx,
#: made the second-order sweeps run away; docs/point-clouds.md). If not, its triangles sample a
#: smooth surface: the map is built for the spacing that resolves them (median size / COARSE),
#: smooth at that scale on the finer grid, and second order runs (an icosphere of 320 triangles
#: against its exact polyhedral geodesics at N = 41–121: 0.59–0.21 %, where first order gave
#: 8.9–2.2 %, worse than at N = 31; ``benches/experiments/coarse_meshes.py``).
COARSE = 3.0
#: An edge whose two triangles' normals turn by more than this many degrees is a crease of the
#: mesh itself (a cube's 90°, an icosahedron's 41.8°), not the facet of a smooth surface's
#: triangulation (an icosphere of 80 triangles turns by 22.5°, a torus of 576 by 30°)...
SHARP_TURN = 35.0
#: ... and a mesh with more than this share of its edges' length at such creases is a polyhedron
#: (Spot: 1.4 %, its ears and horns; the bunny: 0.8 %).
SHARP_SHARE = 0.01
#: Node pairs facing each other across a "gap" (``order2_obstacle``) whose median depth — the
#: larger |φ| of the two, in grid spacings — is below this are the bumps of a rough mesh rather
#: than two sheets of a narrow gap: an icosphere of 20,480 triangles with Gaussian vertex noise
#: of 0.4–1% of its radius at N = 61, 30–126 pairs of median depth 0.14–0.24 (largest 0.69),
#: against 1.5–2.0 for the bundled bunny's and Spot's real gaps (smallest 0.7 on Spot).
SHALLOW_PAIRS = 0.5
#: A mesh whose triangles' median ratio of the longest edge to the height on it exceeds this is
#: made of slivers (a CAD export's cylinder, each triangle the full height: 22; the bundled bunny
#: 2.0, Spot 1.9, an icosphere 1.3), across which the smooth map can fold (:func:`sliver_advice`).
SLIVER_RATIO = 8.0
#: Triangles larger than this many grid spacings (longest edge) are fitted
#: (``tubesweep_core::surface::mesh_smooth::FINE_LOW``).
FINE = 2.0
#: Nodes per call of the native closest points (bounds the memory of a band's evaluation).
CHUNK = 1 << 20


def closest(surface: Any, x: np.ndarray, h: Optional[float]) -> Tuple[np.ndarray, np.ndarray]:
    """The smooth map's closest points of ``x`` (M, 3) for grid spacing ``h`` (None: the exact
    closest points) and the map of each (codes of :data:`KINDS`)."""
    x = np.ascontiguousarray(np.asarray(x, dtype=float).reshape(-1, 3))
    # before any band, on a mesh coarse against the grid, or where the smooth map folded: the exact
    # closest points
    if h is None or "coarse" in surface.report or "facing" in surface.report or "folded" in surface.report:
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
    grid_h = grid.spacing
    surface._band_cache = None
    if getattr(surface, "_folded_h", None) == grid_h:
        # the smooth map folded on this grid (SmoothMap.fold_to_exact): the exact map, first order
        surface._h = grid_h
        surface.report = {"folded": True, "h": grid_h}
        return exact_band()
    size = median_size(surface)
    # the map's length scale: the grid's spacing, or on a coarse mesh without creases of its own
    # the spacing that resolves its triangles
    h = grid_h
    if size > COARSE * grid_h:
        share, turn = sharp_edges(surface)
        if share > SHARP_SHARE:
            # a coarse polyhedron: the exact map's band, and first order (order2_obstacle)
            surface._h = grid_h
            surface.report = {"coarse": size / grid_h, "h": grid_h, "sharp_share": share, "sharp_turn": turn}
            return exact_band()
        h = size / COARSE
    surface._h = h
    if largest_size(surface) > FINE * h or not surface.closed:
        # fits will be needed (large triangles, or a boundary's blend): first the exact map's band,
        # and where the mesh faces itself across a gap narrower than its tubes that band and first
        # order (order2_obstacle), without the fits' cost
        exact = exact_band()
        pairs = facing_pairs(grid, exact, surface)
        if pairs:
            surface.report = {"facing": pairs, "h": grid_h}
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
    surface.report["h"] = grid_h
    if h > grid_h:
        surface.report["map_spacing"] = h
    if not parts or sum(len(q[0]) for q in parts) == 0:
        return BandGeometry(np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3), np.float32))
    linear, norm, x, cp = (np.concatenate([q[i] for q in parts]) for i in range(4))
    # the map's noise near the surface (for the facing-sheets test): |cp(cp(x)) − cp(x)|
    pick = np.linspace(0, len(linear) - 1, min(len(linear), 512)).astype(np.int64)
    again, _ = surface.smooth_map.closest(np.ascontiguousarray(cp[pick]), h, np.inf, "auto")
    surface._noise = float(np.quantile(row_norms(again - cp[pick]), 0.9))
    surface._band_cache = (x, cp)
    ok = norm > DIRECTION_EPS * grid_h
    direction = np.zeros((len(linear), 3))
    direction[ok] = (x[ok] - cp[ok]) / norm[ok, None]
    inside = None
    if surface.signed:
        # whether nodes lie inside the mesh (the exact closest feature's pseudo-normal), for the
        # facing test's second case ("across", tubesweep_core::band::facing_sheets), which needs
        # them to find gaps of one to two spacings that the unsigned φ shows as one sheet (a closed
        # plate 0.02 thick at N = 81, 0.8 spacings: the front crossed it, 0.020 where 1.02 is
        # exact, unwarned at order 2). φ itself stays unsigned: the facing test of the unsigned φ
        # also reads a rough mesh's bumps (``order2_obstacle``). Asked only for the nodes whose
        # sign that test can read (``_facing.facing_gaps``); from all of them it took a tenth of
        # the icosphere's solve at N = 101. Searched from the smooth closest points, which lie
        # within a quarter triangle of the mesh, the tree is pruned at once
        def inside(at: np.ndarray) -> np.ndarray:
            _, foot, face, feature = surface.closest(cp[at])
            return np.asarray(np.einsum("ij,ij->i", x[at] - foot, surface._pseudonormal(face, feature)) < 0)

    return BandGeometry(linear, norm, norm.copy(), direction.astype(np.float32), consumable=True, inside=inside)


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


def sharp_edges(surface: Any) -> Tuple[float, float]:
    """The share of the mesh's edge length (edges between two triangles) whose triangles' normals
    turn by more than :data:`SHARP_TURN`, and the largest turn in degrees (computed once). The
    turn across an edge whose two triangles are not oriented alike is that of their unoriented
    planes (2% of an icosphere's triangles flipped read as creases of 177° and sent N = 61 to
    first order, 0.017% → 0.91% mean error, a helper's sweep)."""
    known = getattr(surface, "_sharp_edges", None)
    if known is not None:
        return known
    f = surface.faces[surface._good]
    v = surface.vertices
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= row_norms(n)[:, None]
    # vertices at the same position are one (an STL's triangles each have their own)
    g = merged_vertices(surface)[f]
    directed = np.concatenate([g[:, [i, j]] for i, j in ((0, 1), (1, 2), (2, 0))])
    edges = np.sort(directed, axis=1)
    ends = np.concatenate([f[:, [i, j]] for i, j in ((0, 1), (1, 2), (2, 0))])
    face = np.tile(np.arange(len(f)), 3)
    all_length = row_norms(v[ends[:, 0]] - v[ends[:, 1]])
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    edges, face, ends, directed = edges[order], face[order], ends[order], directed[order]
    pair = np.all(edges[1:] == edges[:-1], axis=1)
    length = row_norms(v[ends[:-1][pair, 0]] - v[ends[:-1][pair, 1]])
    if 4.0 * length.sum() < all_length.sum():
        # under half of the edges (by length) shared by two triangles: nothing to tell smooth
        # facets from creases with; taken as creases (the exact map and first order, as before)
        surface._sharp_edges = (1.0, float("nan"))
        return surface._sharp_edges
    a, b = face[:-1][pair], face[1:][pair]
    # two triangles oriented alike run their shared edge in opposite directions; where they run it
    # the same way one of them is flipped, and its normal is turned back for the comparison
    alike = np.where(directed[:-1][pair, 0] == directed[1:][pair, 1], 1.0, -1.0)
    turn = np.degrees(np.arccos(np.clip(alike * np.einsum("ij,ij->i", n[a], n[b]), -1.0, 1.0)))
    sharp = turn > SHARP_TURN
    surface._sharp_edges = (float(length[sharp].sum() / length.sum()), float(turn.max()))
    return surface._sharp_edges


def largest_size(surface: Any) -> float:
    """The largest longest edge of the mesh's non-degenerate triangles."""
    f = surface.faces[surface._good]
    v = surface.vertices
    edges = [np.linalg.norm(v[f[:, i]] - v[f[:, j]], axis=1) for i, j in ((0, 1), (1, 2), (2, 0))]
    return float(np.max(np.maximum(np.maximum(edges[0], edges[1]), edges[2])))


def facing_pairs(grid: Grid, geom: BandGeometry, surface: Any = None) -> int:
    """Pairs of grid neighbours of the band, both more than 0.75 Δx from the mesh, whose extension
    directions point more than 120° apart: the two sides of a gap narrower than the tubes (across a
    single sheet two neighbours cannot both be that far from it). Given the mesh (``surface``),
    pairs over one of its holes (``_mesh_holes.across_holes``) and at a notch of its rim
    (``_mesh_notches.pairs_at_notches``) are not counted: neither is a gap between sheets."""
    h = grid.spacing
    lin = geom.linear
    if len(lin) == 0:
        return 0
    dist = geom.distance if geom.distance is not None else np.abs(geom.signed)
    far = dist > 0.75 * h
    first, second = [], []
    for k in range(grid.ndim):
        stride = int(np.prod(grid.shape[k + 1 :]))
        nxt = lin + stride
        pos = np.minimum(np.searchsorted(lin, nxt), len(lin) - 1)
        hit = (lin[pos] == nxt) & far & far[pos] & ((lin // stride) % grid.shape[k] < grid.shape[k] - 1)
        dots = np.einsum("ij,ij->i", geom.direction[hit], geom.direction[pos[hit]])
        facing = dots < -0.5
        first.append(lin[hit][facing])
        second.append(lin[pos[hit]][facing])
    a, b = np.concatenate(first), np.concatenate(second)
    if surface is not None and a.size:
        gap = ~across_holes(surface, grid.node_points(a), grid.node_points(b))
        gap[gap] = ~pairs_at_notches(surface, grid, a[gap], b[gap])
        return int(np.count_nonzero(gap))
    return int(a.size)


def sliver_advice(surface: Any) -> str:
    """What to do about a mesh of slivers (:data:`SLIVER_RATIO`), or "". An open cylinder of 2,048
    triangles 0.25 long and 0.007 wide (a CAD export's, subdivided) ran first order at N = 101 as
    "facing itself across gaps" at 1,200 node pairs lying on the surface itself (7 s, 1.07
    spacings off the unrolled distances), its map folded; subdivided to edges of 0.03
    (165,888 triangles), second order (1.1 s, 0.51 spacings)."""
    if "_sliver_ratio" not in surface.__dict__:
        f = surface.faces[surface._good]
        v = surface.vertices
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        longest = np.max(np.stack([row_norms(b - a), row_norms(c - b), row_norms(a - c)]), axis=0)
        area2 = row_norms(np.cross(b - a, c - a))
        ok = area2 > 0
        surface.__dict__["_sliver_ratio"] = float(np.median(longest[ok] ** 2 / area2[ok])) if np.any(ok) else 0.0
    ratio = surface.__dict__["_sliver_ratio"]
    if ratio <= SLIVER_RATIO:
        return ""
    h = getattr(surface, "report", {}).get("h")
    size = f"the grid spacing, {h:.3g}" if h else "the grid spacing"
    return (
        f"its triangles are slivers (the median longest edge is {ratio:.0f} times the height on it, as in a CAD "
        "export): the smooth closest-point map can fold across them, which reads as gaps or bumps. Subdividing "
        f"the long edges to about {size} (e.g. trimesh.remesh.subdivide_to_size(vertices, faces, max_edge=...)) "
        "lets second order run"
    )


def order2_obstacle(
    surface: Any, tube_pairs: int, pair_depth: float = np.inf, spacing: Optional[float] = None
) -> Optional[str]:
    """Why ``order=2`` does not run on this mesh's tube, or None (see the module constants).
    ``spacing``: the tube's grid spacing, where the smooth map folded (:meth:`SmoothMap.fold_to_exact`)
    whatever the last band's report says (a band on another grid since overwrote it: a review)."""
    report = surface.report
    folded = getattr(surface, "_folded_h", None)
    if (folded is not None and folded == spacing) or (spacing is None and report.get("folded")):
        slivers = sliver_advice(surface)
        return (
            "the mesh's smooth closest-point map folds across its triangles on this grid (its band did not close)"
            + (f": {slivers}" if slivers else "")
            + "; order=1 runs on its exact closest points"
        )
    if "coarse" in report:
        turn = report["sharp_turn"]
        creases = (
            "its triangles share under half their edges, so its creases cannot be told from its facets"
            if np.isnan(turn)
            else f"{report['sharp_share']:.1%} of its edge length turns by more than {SHARP_TURN:g}°, up to {turn:.0f}°"
        )
        return (
            f"the mesh is coarse against the grid: its triangles' median size is {report['coarse']:.1f} grid spacings "
            f"(second order on a mesh needs at most {COARSE:g} where it has creases of its own; here {creases}); "
            "use the grid it resolves, or a mesh whose triangles sample a smooth surface"
        )
    pairs = report.get("facing", 0) or tube_pairs
    slivers = sliver_advice(surface) if pairs else ""
    if slivers:
        return f"the mesh seems to face itself across gaps narrower than its tubes ({pairs} node pairs), but {slivers}"
    if pairs and "facing" not in report and pair_depth < SHALLOW_PAIRS:
        share, turn = sharp_edges(surface)
        if share <= SHARP_SHARE:
            # a few bumps of a mesh smooth elsewhere (vertex noise of 0.1% of the icosphere's radius
            # at N = 61: one pair, no edge turning by 35°): second order runs, 0.9% off against
            # 7.1% at first order (its runaway guard would still fall back)
            return None
        return (
            f"the mesh is rough at the grid's scale: {pairs} pairs of neighbouring nodes face each other across its "
            f"bumps, within {pair_depth:.2f} grid spacings of it (median; the two sides of a real gap lie 1.5-2 "
            f"spacings off), {share:.1%} of its edge length turning by more than {SHARP_TURN:g}° (up to {turn:.0f}°). "
            "No grid resolves such bumps, and the second-order sweeps can run away across them: order=1 runs on the "
            "mesh as it is; a smoothed mesh (e.g. trimesh.smoothing.filter_taubin) may run second order"
        )
    if pairs:
        return (
            f"the mesh faces itself across gaps narrower than its tubes ({pairs} node pairs): the second-order "
            "sweeps can run away across such a gap on a mesh. A gap of a few grid spacings closes with a finer grid; "
            "where the surface nearly touches itself (the bundled bunny and Spot), no grid of practical size resolves "
            "it, and order=1 (the band cut across the gap) is the answer"
        )
    return None


class SmoothMap:
    """The methods of :class:`~tubesweep.surfaces.mesh.SmoothMeshSurface` that read and build the
    smooth map (a mixin before ``MeshSurface`` in its bases: ``super()`` is the exact map's)."""

    vertices: np.ndarray
    faces: np.ndarray
    _good: np.ndarray
    _h: Optional[float]
    _smooth_map: Any
    _band_cache: Optional[Tuple[np.ndarray, np.ndarray]]

    @property
    def smooth_map(self) -> Any:
        """The native map for the grid spacing of the last band (built on first use)."""
        spacing = SAMPLE_SPACING * (self._h or 0.0)
        if self._smooth_map is None or self._smooth_map[0] != spacing:
            from .. import _native

            faces = np.ascontiguousarray(self.faces[self._good])
            self._smooth_map = (spacing, _native.SmoothMesh(self.vertices, faces, NEIGHBOURS, spacing))
        return self._smooth_map[1]

    def __getstate__(self) -> dict:
        state: dict = super().__getstate__()  # type: ignore[assignment]  # MeshSurface's
        state["_smooth_map"] = None
        state["_band_cache"] = None
        return state

    def _cp(self, x: np.ndarray) -> np.ndarray:
        return closest(self, x, self._h)[0]

    def fold_to_exact(self, h: float) -> bool:
        """Called when the band of the smooth map at grid spacing ``h`` does not close even widened
        (``_prepare``): from then on the band at that spacing is the exact map's, and
        ``order2_obstacle`` refuses second order there. True the first time, False when the exact
        map was in use already."""
        report = getattr(self, "report", {})
        if getattr(self, "_folded_h", None) == h or "coarse" in report or "facing" in report:
            return False  # the exact map's band already
        self._folded_h = h
        return True

    @property
    def band_advice(self) -> str:
        """Why the band of the smooth map may not close (for the band's error, ``_prepare``): the
        map folds across the mesh's triangles (slivers, :func:`sliver_advice`), where the exact
        closest points do not. A CAD cylinder of 256 sections (triangles 88 times longer than
        high) at N = 101 was refused with the advice to re-distance φ (a review); with
        ``smooth=False`` it runs first order, 1.4 spacings off the unrolled distances at worst."""
        slivers = sliver_advice(self)
        return (
            "the mesh's smooth closest-point map folds across its triangles: from_mesh(..., smooth=False) takes the "
            "mesh's exact closest points instead, which do not fold (the first-order scheme)"
            + (f". Here {slivers}" if slivers else "")
        )

    @property
    def unresolved_advice(self) -> Optional[str]:
        """What the grid may not resolve of this mesh where the second-order sweeps run away: its
        slivers (:func:`sliver_advice`), or None."""
        return sliver_advice(self) or None

    def order2_obstacle(
        self, facing_pairs: int, pair_depth: float = np.inf, spacing: Optional[float] = None
    ) -> Optional[str]:
        """Why ``order=2`` does not run on the last band's tube (a coarse mesh, or facing sheets),
        or None; read by the second-order solve.

        Parameters
        ----------
        facing_pairs : int
            The node pairs of the tube whose sides face each other across a narrow gap (the
            tube's own check, ``_facing._warn_if_tubes_touch``).
        pair_depth : float
            Their median depth: the larger |φ| of each pair's two nodes, in grid spacings (pairs
            hugging the mesh are its bumps, not a gap).
        spacing : float, optional
            The tube's grid spacing: where the smooth map folded on it, second order is refused
            whatever band was built since.

        Returns
        -------
        str or None
            The reason, or None when second order may run.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> geometry = spot.band(spot.grid(200), 0.02)
        >>> spot.order2_obstacle(0)[:36]
        'the mesh is coarse against the grid:'
        """
        return order2_obstacle(self, facing_pairs, pair_depth, spacing)

    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        """The band nodes within ``half_width`` of the smooth map's surface, their closest points
        computed once in Rust (kept for the second-order geometry) and counted by map in
        :attr:`report`. On a mesh coarse against the grid (median triangle above 3 Δx) with creases
        of its own (:data:`SHARP_TURN`), the exact map's band of :meth:`MeshSurface.band`; without
        them, the map built for the spacing that resolves the triangles (``report["map_spacing"]``).

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance).

        Returns
        -------
        BandGeometry

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> grid = spot.grid(40)
        >>> len(spot.band(grid, 4 * grid.spacing).linear) > 0
        True
        """
        return band(self, grid, half_width, lambda: super(SmoothMap, self).band(grid, half_width))  # type: ignore[misc]

    def closest_point(self, points: np.ndarray) -> np.ndarray:
        """The smooth map's closest points (for the grid of the last band; exact before any band).

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, 3)`` closest points.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> spot.closest_point(spot.vertices[:2] + 0.01).shape
        (2, 3)
        """
        p = np.ascontiguousarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must have shape (M, 3); got {p.shape}")
        cache = self._band_cache
        if cache is not None and cache[0].shape == p.shape and np.array_equal(cache[0], p):
            return cache[1].copy()  # the band's nodes again (the second-order geometry)
        return closest(self, p, self._h)[0]

    def exact_project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        """The exact map's distances and closest points on the mesh's triangles (as
        ``smooth=False``'s :meth:`project`), for estimates that need no fit.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points.
        grid : Grid
            The grid.

        Returns
        -------
        distance, closest : numpy.ndarray
            ``(M,)`` and ``(M, 3)``.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> d, cp = spot.exact_project(spot.vertices[:2], spot.grid(100))
        >>> float(d.max()) < 1e-12
        True
        """
        return super().project(points, grid)  # type: ignore[misc]

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        """The smooth map's closest points for ``grid`` and the distances to them.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points.
        grid : Grid
            The grid (its spacing decides where the map is exact).

        Returns
        -------
        distance, closest : numpy.ndarray
            ``(M,)`` and ``(M, 3)``.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> d, cp = spot.project(spot.vertices[:2], spot.grid(100))
        """
        p = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 3))
        cp = closest(self, p, grid.spacing)[0]
        return np.linalg.norm(p - cp, axis=1), cp
