"""Building the computational tube for a solve (paper Fig. 4): the band of a surface, the role of
each node (inner tube, extension layer; Algorithm 2 or 3), the checks that the grid resolves the
surface (memory, tubes of facing sheets that touch, a surface thinner than two cells), and the
band structure the sweeps run on. Shared by :func:`tubesweep.solve` and :class:`tubesweep.Tube`."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _native
from ._validate import (
    available_memory_bytes,
    check_memory,
    real_scalar,
)
from .grid import Grid
from .band import BandGeometry, _evaluate, band_neighbours
from .surface import LevelSet, Surface
from ._warn import user_stacklevel
from ._box_cut import box_cut, warn_box_cut
from ._coarse_creases import creases_of_redistanced
from ._creases import crease_nodes_to_extend, creases_in_paper_tube
from ._thin_level_set import thin_share, warn_thin
from ._shortcuts import cut_between_parts, cut_pinches, cut_shortcuts, cuts_medial_edges, cuts_shortcuts

METHODS = ("two-layer", "naive")
#: A node belongs to the inner tube when ``|φ| ≤ inner·Δx·(1 + ROLE_RTOL)``. The relative
#: tolerance makes nodes that sit exactly on the inner radius (up to rounding, common on
#: symmetric grids) consistently inner.
ROLE_RTOL = 1e-9

ROLE_FIXED, ROLE_INNER, ROLE_OUTER = 0, 1, 2


def _widening_message(
    missing: np.ndarray, phi: np.ndarray, h: float, inner: float, outer: float, surface: Any = None
) -> str:
    """Why inner-tube nodes (band positions ``missing``) lack a neighbour in the band of half-width
    ``outer`` spacings. For a distance function a neighbour lies at most one spacing farther from
    the surface, so an inner node within ``outer − 1`` spacings of it whose neighbour falls
    outside says φ is not a distance function there; when every such node lies beyond that (only
    possible when ``outer − inner`` is about 1) the extension layer is merely too thin to hold the
    neighbours, rounding included, and φ is not to blame. A surface with its own
    ``unresolved_advice`` (a point cloud) has it named instead of φ."""
    far = np.abs(phi[missing].astype(float)) > (outer - 1.0) * h * (1 - 1e-6)
    widen = f"Widening the extension layer to outer = {outer + 1}"
    if np.all(far):
        return (
            f"{missing.size} inner-tube nodes had a neighbour outside the band with outer = {outer}: the extension "
            f"layer (outer − inner = {outer - inner:g} grid spacings) is too thin to hold every neighbour of the inner "
            f"tube (a neighbour can lie a full spacing farther out, and rounding puts some just beyond). {widen}; "
            "pass outer ≥ inner + 2 to avoid this"
        )
    advice = getattr(surface, "unresolved_advice", None)
    cause = "φ is not close to a distance function there" if advice is None else "the closest points fold there"
    text = (
        f"{missing.size} inner-tube nodes had a neighbour outside the band with outer = {outer}: {cause} (at "
        f"{int(np.count_nonzero(~far))} of them the neighbour is more than one spacing farther out)"
    )
    return f"{text}. {widen}" if advice is None else f"{text}: {advice}. {widen}"


def _where(grid: Grid, node: Any) -> str:
    """A grid node's position, for a message: ``(x, y, z)`` to four digits."""
    return "(" + ", ".join(f"{float(v):.4g}" for v in grid.node_points(np.array([int(node)]))[0]) + ")"


def _percent(share: float) -> str:
    """A share as a short percentage: '0.1%', '12%', or '< 0.01%'."""
    if share < 1e-4:
        return "< 0.01%"
    return f"{100 * share:.2g}%" if share < 0.1 else f"{100 * share:.0f}%"


_MAX_WIDENINGS = 4
_ROLE_CHUNK = 1 << 18


def _tube_roles(geom: BandGeometry, inner_width: float, method: str) -> np.ndarray:
    """Roles of the band nodes: inner tube where ``|φ| ≤ inner·Δx`` (every node for the naive
    method), else extension layer; chunk by chunk, without K-sized temporaries."""
    roles = np.full(len(geom.linear), ROLE_INNER if method == "naive" else ROLE_OUTER, np.uint8)
    if method != "naive":
        limit = inner_width * (1 + ROLE_RTOL)
        for lo in range(0, len(roles), _ROLE_CHUNK):
            part = roles[lo : lo + _ROLE_CHUNK]
            part[geom.unsigned(lo, lo + _ROLE_CHUNK) <= limit] = ROLE_INNER
    return roles


@dataclasses.dataclass
class _PreparedTube:
    """The band of a surface on a grid with what every solve on it needs: the sorted linear
    indices, the roles before the sources are fixed, the native band, φ in single precision, and
    either the directions the solver may overwrite (``direction``; one solve) or the whole
    geometry (``geom``, never modified; a general Hamiltonian reads it, and a :class:`Tube`
    solves many times). ``seconds``: the time the preparation took."""

    grid: Grid
    surface: Surface
    inner: float
    outer_eff: float
    method: str
    geom: Optional[BandGeometry]
    linear: np.ndarray
    roles: np.ndarray
    band: Any
    phi: np.ndarray
    direction: Optional[np.ndarray]
    seconds: float
    #: the pairs of neighbouring nodes across a gap narrower than the tubes: their band positions
    #: and their gaps (``_warn_if_tubes_touch``)
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray] = (np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0))
    #: where the grid box cuts the tube (``_box_cut.box_cut``), None where it does not
    box_cut: Optional[Dict[str, Any]] = None
    #: the edges of the band's neighbour table removed across narrow gaps and medial edges
    #: (``_shortcuts.cut_shortcuts``; triangle meshes, and point clouds across resolved gaps)
    cut_edges: int = 0
    #: the inner-tube nodes at creases that second order (and ``order="auto"``) makes extension
    #: nodes (``_creases.crease_nodes_to_extend``; band positions); their roles are changed only
    #: by :func:`thinned_at_creases`, so that ``order=1`` keeps the paper's tube
    crease_nodes: np.ndarray = dataclasses.field(default_factory=lambda: np.empty(0, np.int64))
    #: the creases of a level set in the paper's tube, where ``order=1`` cuts their corners
    #: (``_creases.creases_in_paper_tube``, or for a re-distanced φ ``creases_of_redistanced``,
    #: found on first use for a Tube: :func:`paper_creases_of`): a dict as ``order2["creases"]``,
    #: None for other surfaces and until then
    paper_creases: Optional[Dict[str, Any]] = None
    #: the holes of an open mesh narrower than the band, which it bridges
    #: (``surfaces._mesh_holes.bridged``), or a point cloud's small holes over which its facing
    #: pairs lie (``surfaces._cloud_holes``); None for other surfaces and where there are none
    bridged_holes: Optional[Dict[str, Any]] = None
    #: an open mesh's slits (``surfaces._mesh_slits``), None for other surfaces and where there
    #: are none (warned where the band joins their sides)
    slits: Optional[Dict[str, Any]] = None
    #: the inner tube's connected components and the checksum of its flags, once a warm start
    #: counted them (``moving.inner_components``)
    inner_components: Optional[Tuple[int, int, np.ndarray]] = None
    #: each band node's piece of a triangle mesh of separate pieces (``surfaces._mesh_parts``, from
    #: the band's cut), None on other surfaces
    pieces: Optional[np.ndarray] = None
    #: the creases of a re-distanced φ read through a smoothing for second order, once read
    #: (``_coarse_creases.widened_for_order2``): a 1-tuple of the dict or None
    smoothed_creases: Optional[Tuple[Optional[Dict[str, Any]]]] = None


# The memory a solve adds per band node at its peak, for the check below: 57–58 B for `ts.solve` at
# N = 1001 and 2001 (`benches/run.py --scale`), more through `ts.Tube` and the general Hamiltonians
# (up to about 110 B at N = 301).
_BAND_BYTES_PER_NODE = 110
# Points per axis (along the box's longest side) of the coarse sample that estimates the band.
_BAND_ESTIMATE_POINTS = 17


#: Rounds of :func:`_not_stranding` before it gives up thinning the tube at all.
_RECONNECT_ROUNDS = 8


def unstranded(tube: _PreparedTube) -> _PreparedTube:
    """``tube`` (thinned at its creases, :func:`thinned_at_creases`) for the first-order scheme of
    ``order="auto"``: with the crease nodes next to a speck of the inner tube that the thinning
    cut off given back to it (:func:`_not_stranding`). Such a speck keeps +∞ where no source lies
    in it, and the first-order sweeps, unlike the second-order ones
    (``second_order.split_at_creases``), do not say so. On a noisy φ re-distanced the ridge test
    finds "creases" over much of the tube, and ``"auto"`` runs first order there: a sphere with
    noise of 0.4Δx at N = 61 had 5,468 of 12,574 inner nodes thinned, leaving 122 specks of 1 to 3
    nodes beside the main piece, and +∞ at 4 of 2,000 points on the sphere with
    ``converged=True`` (a helper's review). Whole parts that the thinning parts stay apart (a
    cube's corner whose tube reached across a narrow gap to a sphere). ``tube`` itself when
    nothing is cut off."""
    if thinned_count(tube) == 0:
        return tube
    paper = tube.roles.copy()
    paper[tube.crease_nodes] = ROLE_INNER
    keep = _not_stranding(tube.band, paper, tube.crease_nodes, tube.inner)
    if keep.size == tube.crease_nodes.size:
        return tube
    paper[keep] = ROLE_OUTER
    return dataclasses.replace(tube, roles=paper, crease_nodes=keep)


def _not_stranding(band: Any, roles: np.ndarray, extended: np.ndarray, inner: float) -> np.ndarray:
    """The crease nodes ``extended`` (band positions) that can be taken out of the paper's inner
    tube (``roles``) without leaving a speck of it on its own: a piece of no more nodes than a
    node's inner-tube stencil holds, (2·inner + 1)^d, which no part of a surface that the grid
    resolves is (a sphere of radius 3Δx holds some 400). The thinned nodes next to a speck are kept
    in the tube, round by round; after :data:`_RECONNECT_ROUNDS` rounds none is thinned."""
    if extended.size == 0:
        return extended
    speck = int((2 * math.floor(inner) + 1) ** band.ndim)
    thinned = roles == ROLE_INNER
    thinned[extended] = False
    kept = np.zeros(len(roles), dtype=bool)
    kept[extended] = True
    for _ in range(_RECONNECT_ROUNDS):
        labels = _native.band_component_labels(band, thinned)
        names, sizes = np.unique(labels[thinned], return_counts=True)
        stranded = np.flatnonzero(thinned & np.isin(labels, names[sizes <= speck]))
        if stranded.size == 0:
            return np.flatnonzero(kept)
        around = band.neighbours_of_nodes(stranded.astype(np.int64)).reshape(-1)
        around = around[(around >= 0) & (around < len(roles))]
        back = around[kept[around]]
        if back.size == 0:  # specks of the paper's tube itself
            return np.flatnonzero(kept)
        kept[back] = False
        thinned[back] = True
    return np.empty(0, np.int64)


def thinned_at_creases(tube: _PreparedTube) -> _PreparedTube:
    """``tube`` with its crease nodes (``_PreparedTube.crease_nodes``) made extension nodes: the
    tube of ``order=2`` and of ``order="auto"`` on a level set with creases (docs/second-order.md).
    ``tube`` itself when it has none; otherwise a copy sharing everything but the roles."""
    if tube.crease_nodes.size == 0:
        return tube
    roles = tube.roles.copy()
    roles[tube.crease_nodes] = ROLE_OUTER
    return dataclasses.replace(tube, roles=roles)


def paper_creases_of(tube: _PreparedTube) -> Optional[Dict[str, Any]]:
    """The creases of ``tube``'s level set in the paper's tube (:attr:`_PreparedTube.paper_creases`),
    found on first use for a re-distanced φ of a :class:`~tubesweep.Tube` (whose geometry is kept):
    the second-order geometry's test (``_creases.creases_of_redistanced``) costs its pass, which
    only a solve on the paper's tube needs."""
    surf = tube.surface
    if (
        tube.paper_creases is None
        and tube.geom is not None
        and tube.method == "two-layer"
        and isinstance(surf, LevelSet)
        and getattr(surf, "redistance", False)
    ):
        h = tube.grid.spacing
        tube.paper_creases = creases_of_redistanced(
            tube.grid, tube.band, tube.roles, tube.geom.signed, tube.geom.direction, tube.outer_eff * h, surf
        )
    return tube.paper_creases


def thinned_count(tube: _PreparedTube) -> int:
    """How many of ``tube``'s crease nodes :func:`thinned_at_creases` made extension nodes: all of
    them in the thinned tube, 0 in the paper's (``sol.stats.crease_thinned``)."""
    nodes = tube.crease_nodes
    if nodes.size == 0 or not np.all(tube.roles[nodes] == ROLE_OUTER):
        return 0
    return int(nodes.size)


def uncut_band(tube: _PreparedTube) -> Any:
    """The band of ``tube`` without its cut (``_shortcuts``), built again from its nodes, for the
    Lax–Friedrichs scheme: it extrapolates a missing neighbour and does not settle beside edges cut
    inside the tube (on the bunny at n = 61: 3000 iterations, the last change 2e-3). Built only
    when asked, so that a cut band does not hold a second neighbour table."""
    return _native.Band.from_linear(
        list(tube.grid.shape), np.ascontiguousarray(tube.linear, dtype=np.int64).view(np.uint64)
    )


def _check_band_memory(surf: Surface, grid: Grid, half_width: float) -> None:
    """Raises MemoryError before the band search when the band would not fit in memory. Skipped
    when even a band filling the whole box would fit (every grid up to a few hundred nodes per
    axis); otherwise the surface's area is estimated from its distance at a coarse sample of the
    box (the nodes within one coarse spacing H of it fill a shell of volume ≈ 2·H·area), and the
    band of half-width w holds about 2·w·area / h^d nodes."""
    avail = available_memory_bytes()
    if avail is None or grid.size * _BAND_BYTES_PER_NODE <= 0.9 * avail or getattr(surf, "redistance", False):
        return
    nodes = _estimated_band_nodes(surf, grid, half_width)
    check_memory(
        nodes * _BAND_BYTES_PER_NODE,
        f"the band (about {nodes:.3g} nodes at grid spacing {grid.spacing:.3g})",
        "use a coarser grid (fewer nodes per axis) or a thinner tube",
    )


def _estimated_band_nodes(surf: Surface, grid: Grid, half_width: float) -> float:
    """About how many nodes of ``grid`` lie within ``half_width`` of ``surf`` (see
    :func:`_check_band_memory`), from the surface's distance at a coarse sample of the box."""
    lower, upper = np.asarray(grid.lower, dtype=float), np.asarray(grid.upper, dtype=float)
    big_h = float(np.max(upper - lower)) / (_BAND_ESTIMATE_POINTS - 1)
    axes = [np.minimum(np.arange(lo, hi + 0.5 * big_h, big_h), hi) for lo, hi in zip(lower, upper)]
    points = np.stack([c.reshape(-1) for c in np.meshgrid(*axes, indexing="ij")], axis=1)
    try:
        dist = np.asarray(surf.project(points, grid)[0], dtype=float)
    except Exception:  # a surface undefined at some sample far from it: no estimate, the search decides
        return 0.0
    area = np.count_nonzero(np.isfinite(dist) & (dist <= big_h)) * big_h**grid.ndim / (2 * big_h)
    return 2 * half_width * area / grid.spacing**grid.ndim


def _lacking_neighbours(grid: Grid, band: Any, linear: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """The linear indices (sorted, unique) of the in-grid neighbours that the band nodes
    ``missing`` (band positions) lack in the band."""
    lacking = [np.empty(0, np.int64)]
    for moved, inside, pos in band_neighbours(grid, band, linear, missing):
        absent = moved[inside & (pos < 0)]
        lacking.append(np.ravel_multi_index(tuple(absent.T), grid.shape).astype(np.int64))
    return np.unique(np.concatenate(lacking))


def _ridge_pairs(
    grid: Grid, band: Any, linear: np.ndarray, roles: np.ndarray, phi: np.ndarray, kink: Optional[np.ndarray]
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs of neighbouring band nodes of which one straddles a kink of a level set's φ (a
    ridge between facing parts, ``BandGeometry.kink``) and one lies in the inner tube, with the
    gap ``2|φ|`` at the kink's node. There the central differences give no reliable direction,
    so the directions' tests of ``Band.facing_sheet_pairs`` can miss the pair (two spheres
    ``min(d₁, d₂)`` 5 spacings apart were crossed without a word)."""
    empty = np.empty(0, np.int64)
    if kink is None or not np.any(kink):
        return empty, empty, np.empty(0)
    at = np.flatnonzero(kink)
    nodes, neighbours = [], []
    for _, _, pos in band_neighbours(grid, band, linear, at):
        ok = pos >= 0
        a, b = at[ok], pos[ok]
        ok = (roles[a] == ROLE_INNER) | (roles[b] == ROLE_INNER)
        a, b = a[ok], b[ok]
        nodes.append(np.minimum(a, b))
        neighbours.append(np.maximum(a, b))
    node, neighbour = np.concatenate(nodes), np.concatenate(neighbours)
    gap = 2.0 * np.abs(phi[np.where(kink[node], node, neighbour)]).astype(float)
    return node, neighbour, gap


def _warn_if_tubes_touch(
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    phi: np.ndarray,
    direction: np.ndarray,
    inner: float,
    kink: Optional[np.ndarray] = None,
    noise: float = 0.0,
    warn: bool = True,
    note: str = "",
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Warns where two parts of the surface face each other across a gap so narrow that the inner
    tube of one touches the band of the other (``_native.Band.facing_sheet_pairs``,
    ``tubesweep_core::band::facing_sheets``): the eikonal equation crosses the gap there and the travel
    times beyond it come out too short, a shortcut the surface does not have. Returns the pairs'
    band positions and their gaps. ``warn=False`` where the band is cut across the pairs
    (``_shortcuts``): the front does not cross them, and ``stats.facing_pairs`` reports them."""
    h = grid.spacing
    node, neighbour, gap = band.facing_sheet_pairs(
        roles == ROLE_INNER,
        np.ascontiguousarray(phi, dtype=np.float32),
        np.ascontiguousarray(direction, dtype=np.float32).reshape(len(linear), grid.ndim),
        h,
    )
    if noise > 0 and node.size:
        # a noisy closest-point map (``_cp_checks``): nodes within a few times its noise of the
        # surface have directions the noise can turn around, which the facing test would read as
        # two sheets (at noise 0.01 spacings, 13 pairs on a sphere); they are left out
        clear = 4.0 * noise
        keep = (np.abs(phi[node]) > clear) & (np.abs(phi[neighbour]) > clear)
        node, neighbour, gap = node[keep], neighbour[keep], gap[keep]
    ridge = _ridge_pairs(grid, band, linear, roles, phi, kink)
    if ridge[0].size:
        node, neighbour, gap = _union_pairs((node, neighbour, gap), ridge)  # (a pair found both ways once)
    if warn:
        warn_facing_pairs(grid, linear, roles, (node, neighbour, gap), inner, note)
    return node, neighbour, gap


def _specks(surf: Any, grid: Grid) -> str:
    """For a refused re-distanced φ array: its nodes whose sign differs from all their axis
    neighbours', named first (a bubble smaller than a cell: one node of the other sign 6 spacings
    off a sphere was refused for "sharp edges", with no place given); "" when there are none."""
    arr = getattr(surf, "_array", None)
    if arr is None:
        return ""
    negative = np.asarray(arr) < 0
    alone = np.ones(negative.shape, bool)
    for axis in range(negative.ndim):
        for step in (1, -1):
            alone &= np.roll(negative, step, axis) != negative
    for axis in range(negative.ndim):  # (np.roll wraps around: the box's faces are not judged)
        edge = [slice(None)] * negative.ndim
        for end in (0, -1):
            edge[axis] = end  # type: ignore[call-overload]
            alone[tuple(edge)] = False
    nodes = np.flatnonzero(alone)
    if nodes.size == 0:
        return ""
    where = tuple(round(float(c), 6) for c in grid.node_points(nodes[:1])[0])
    return (
        f"φ changes sign at {nodes.size} isolated node(s) whose neighbours all have the other sign (e.g. at {where}): "
        "surfaces smaller than a grid cell, which the tube cannot hold; remove such specks (noise in a segmentation, "
        "e.g. with scipy.ndimage.binary_opening) and solve again. "
    )


def _union_pairs(
    a: Tuple[np.ndarray, np.ndarray, np.ndarray], b: Tuple[np.ndarray, np.ndarray, np.ndarray]
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The facing pairs ``(node, neighbour, gap)`` of ``a`` and ``b``, a pair in both once (the
    smaller gap)."""
    node, neighbour, gap = (np.concatenate([x, y]) for x, y in zip(a, b))
    order = np.lexsort((gap, neighbour, node))
    node, neighbour, gap = node[order], neighbour[order], gap[order]
    first = np.ones(node.size, bool)
    first[1:] = (node[1:] != node[:-1]) | (neighbour[1:] != neighbour[:-1])
    return node[first], neighbour[first], gap[first]


def warn_facing_pairs(
    grid: Grid,
    linear: np.ndarray,
    roles: np.ndarray,
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray],
    inner: float,
    note: str = "",
    resolving: Optional[float] = None,
) -> None:
    """The warning of :func:`_warn_if_tubes_touch` for the pairs ``facing`` (band positions of the
    nodes and their neighbours, and the gaps), if there are any; ``note`` ends it (a point
    cloud's, ``PointCloudSurface._gap_note`` and ``_unresolved_gap_note``). A gap ``resolving`` grid
    spacings wide is resolved (default ``2·inner + 2``: the tubes of the two sides apart)."""
    node, neighbour, gap = facing
    if node.size == 0:
        return
    h = grid.spacing
    narrowest = int(np.argmin(gap))
    where = _where(grid, linear[node[narrowest]])
    needed = float(gap[narrowest]) / (2 * inner + 2 if resolving is None else resolving)
    # how much of the surface: the inner-tube nodes of the pairs among all inner-tube nodes
    inner_nodes = roles == ROLE_INNER
    touched = np.unique(np.concatenate([node, neighbour]))
    share = np.count_nonzero(inner_nodes[touched]) / max(int(np.count_nonzero(inner_nodes)), 1)
    warnings.warn(
        f"the surface faces itself across gaps narrower than its tubes at {node.size} node pair(s), about "
        f"{_percent(share)} of the surface (the narrowest {float(gap[narrowest]):.3g} wide, near {where}). Distances "
        "reached across such a gap can come out too short; elsewhere the result holds. sol.narrow_gaps() shows where; "
        f"a grid spacing below {needed:.3g} (now {h:.3g}) resolves a real gap, while a crease or scan artefact stays "
        f"narrower than any grid{note}",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _check_surface_spans_two_cells(
    surf: Surface, grid: Grid, linear: np.ndarray, roles: np.ndarray, inner: float
) -> None:
    """Refuses a surface that the grid cannot resolve: one whose closest points from the inner
    tube span less than two grid spacings along every axis of their bounding box (a disc or plane
    patch smaller than a cell; on a disc of radius 0.02Δx the distances came out 29% short, with
    no warning; a closed mesh or closest-point curve that small too, while a level set that small
    is refused earlier, by the distance check, its tube reaching the centre). The inner tube of a surface that small has at most ``(2·inner + 3)^d`` nodes, so the
    closest points are computed only for a band that small: nothing is added to other solves."""
    h = grid.spacing
    # counted before they are listed: the list of a large band's inner nodes (8 bytes per inner
    # node) would raise the set-up's peak memory
    n_inner = int(np.count_nonzero(roles == ROLE_INNER))
    if n_inner == 0 or n_inner > (2 * int(np.ceil(inner)) + 3) ** grid.ndim:
        return
    inner_nodes = np.flatnonzero(roles == ROLE_INNER)
    _, closest = surf.project(grid.node_points(linear[inner_nodes]), grid)
    closest = closest[np.all(np.isfinite(closest), axis=1)]
    if closest.size == 0:
        return
    extent = float(np.max(np.ptp(closest, axis=0)))
    if extent == 0.0:
        raise ValueError(
            "the surface is a single point: every node of the inner tube has the same closest point "
            f"{tuple(float(x) for x in closest[0])}, so there is no curve or surface to solve on (for a "
            "closest-point map, check that cp returns the nearest point of the surface)"
        )
    if extent < 2.0 * h:
        raise ValueError(
            f"the grid is too coarse for this surface: the surface spans only {extent:.3g} along the longest side of "
            f"its bounding box (from the inner tube's closest points), less than two grid spacings (h = {h:.4g}), so the "
            f"grid cannot resolve it; refine the grid to a spacing below {extent / 2:.3g}, or shrink the box"
        )


def _prepare_tube(
    surf: Surface,
    grid: Grid,
    inner: float,
    outer: float,
    method: str,
    keep_geometry: bool,
    reusable: bool = False,
    creases: bool = False,
) -> _PreparedTube:
    """The band of ``surf`` (Algorithm 3's inner tube and extension layer, or Algorithm 2's
    single tube) with its roles, widened while inner nodes lack a neighbour in it. ``reusable``
    keeps the geometry unmodified for many solves (:class:`Tube`). ``creases`` (a level set given
    as a distance, the two-layer method): the inner-tube nodes on the overlap side of a crease are
    found (``_creases.crease_nodes_to_extend``), for :func:`thinned_at_creases` to make them
    extension nodes (``order=2`` and ``"auto"``); the roles themselves stay the paper's."""
    t0 = time.perf_counter()
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    widths = []
    for name, val in (("inner", inner), ("outer", outer)):
        w = real_scalar(val, name, "a finite number of grid spacings")
        if not np.isfinite(w):
            raise ValueError(f"{name} must be a finite number of grid spacings; got {val!r}")
        widths.append(w)
    inner, outer = widths
    if inner < 1.0:
        raise ValueError(
            f"inner = {inner} grid spacings is thinner than the grid can resolve: the inner tube needs at least 1 "
            "(the paper uses 2)"
        )
    if method == "two-layer" and outer < inner + 1.0:
        raise ValueError(
            f"outer = {outer} must exceed inner = {inner} by at least 1 grid spacing so that the extension layer "
            "holds every neighbour of the inner tube (the paper uses inner=2, outer=4)"
        )
    h = grid.spacing
    inner_width = inner * h
    outer_eff = float(outer) if method == "two-layer" else float(inner)

    _check_band_memory(surf, grid, outer_eff * h)
    # a re-distanced band, and the bound on |∇φ| its candidates were found with when the user gave it
    redistanced = bool(getattr(surf, "redistance", False))
    given_bound = getattr(surf, "lipschitz", None) if redistanced else None
    previously_lacking: Optional[np.ndarray] = None
    for attempt in range(_MAX_WIDENINGS + 1):
        # (catch_warnings only where needed: entering and leaving it resets Python's record of the
        # warnings already shown, and a solve repeated in a loop would then repeat its warnings)
        with warnings.catch_warnings() if attempt > 0 else contextlib.nullcontext():
            if attempt > 0:  # warnings about the band's nodes and φ's gradient were given at the first attempt
                warnings.filterwarnings("ignore", message=".*could not be projected onto it", category=RuntimeWarning)
                warnings.filterwarnings("ignore", message="φ is only roughly a distance", category=RuntimeWarning)
                warnings.filterwarnings("ignore", message="φ's slope nearly vanishes", category=RuntimeWarning)
            geom = surf.band(grid, outer_eff * h)
        if geom.linear.size == 0:
            array = getattr(surf, "_array", None) if isinstance(surf, LevelSet) and not surf.redistance else None
            # (a φ array given as is that changes sign: a surface is there, but φ is not its distance)
            signs = array is not None and bool(np.any(array < 0) and np.any(array > 0))
            raise ValueError(
                "the band is empty: no grid node lies within the tube; check that the surface passes through the grid "
                "and that φ is in the grid's units"
                + (
                    " (φ changes sign, but its values near the change are far larger than a distance, e.g. a mask's "
                    "±0.5: LevelSet(phi, redistance=True), or LevelSet.from_mask(mask, grid) for a mask)"
                    if signs
                    else ""
                )
            )
        roles = _tube_roles(geom, inner_width, method)
        linear = geom.linear
        if attempt == 0:
            _check_surface_spans_two_cells(surf, grid, linear, roles, inner)
        band = geom.native_band  # built by the surface, or None
        # The float64 φ (and |φ| where stored) only decide the roles: from here on the solver
        # keeps φ in single precision, and the band is built without them (memory is per band
        # node: see docs/architecture.md).
        phi = geom.signed.astype(np.float32)
        kink = geom.kink
        inside = geom.inside
        direction: Optional[np.ndarray] = None
        if reusable:
            # kept for every solve: the solver gets copies of its directions
            geom = dataclasses.replace(geom, consumable=False)
        elif not keep_geometry:
            direction = geom.directions_for_solver()
            geom = None  # type: ignore[assignment]
        if band is None or len(band) != len(linear):
            band = _native.Band.from_linear(
                list(grid.shape), np.ascontiguousarray(linear, dtype=np.int64).view(np.uint64)
            )
        if method == "naive":
            break
        missing = band.nodes_missing_neighbours(roles == ROLE_INNER)
        if missing.size == 0:
            break
        lacking = _lacking_neighbours(grid, band, linear, missing)
        # a callable φ that is NaN or inf next to the inner tube (undefined over a region that
        # reaches the surface): said as such, not as a φ far from a distance after widenings
        fn = getattr(surf, "_fn", None) if isinstance(surf, LevelSet) and not redistanced else None
        if fn is not None and lacking.size:
            _evaluate(fn, grid.node_points(lacking), "phi callable")
        if (
            redistanced
            and given_bound is None
            and previously_lacking is not None
            and np.all(np.isin(previously_lacking, lacking))
        ):
            # A re-distanced band, its candidates found with an estimated bound on |∇φ|, holds the
            # nodes within the layer that could be projected onto the zero level set; the layer
            # was widened and none of the missing neighbours came in, so they are nodes the
            # projection cannot place (the box's |x|_∞ − r at N = 41 widened four times in 13 s
            # before ending in the error below). Going on without them gave wrong answers
            # elsewhere (a circle 3 spacings in radius came out far short at its antipode), so the
            # solve stops here. With a given bound below |∇φ| the candidates depend on the
            # layer's width and a later widening can still bring them in: widened as for any φ.
            raise ValueError(
                _specks(surf, grid)
                + f"{lacking.size} nodes next to the inner tube could not be projected onto φ's zero level set, and a wider "
                "extension layer does not bring them in: the zero level set has sharp edges or corners there, or the "
                "surface is not much larger than the tube (its radius of curvature about the tube's width). Smooth φ "
                "there (round the edges over more than the tube's width), pass a signed distance function, or refine the grid"
                + (
                    "; or sample the callable φ on the grid and pass the array (LevelSet(phi_array, redistance=True) "
                    "locates the zero level set cell by cell, edges and corners included: a cube's distance at N = 61, "
                    "refused as a callable, solves as an array). A callable φ that is flat across its zero level set "
                    "(∇φ = 0 there, as (|x| − 0.5)³) is refused so too, its Newton projection stalling: sampled on the "
                    "grid it solves at order 2"
                    if getattr(surf, "_array", True) is None
                    else ""
                )
            )
        previously_lacking = lacking
        if attempt == _MAX_WIDENINGS:
            # a mesh's smooth map that folds: its exact closest points on this grid (first order)
            fold = getattr(surf, "fold_to_exact", None)
            if fold is not None and fold(h):
                warnings.warn(
                    f"the extension layer does not enclose the inner tube even with outer = {outer_eff}: "
                    f"{getattr(surf, 'band_advice')}. The exact closest points are used on this grid instead, "
                    "with the first-order scheme (order=2 is refused there)",
                    RuntimeWarning,
                    stacklevel=user_stacklevel(),
                )
                return _prepare_tube(surf, grid, inner, outer, method, keep_geometry, reusable, creases)
            # a surface kind's own cause (a point cloud's, a mesh's), or φ's for a level set not
            # re-distanced (a mesh's smooth map failing here was told to re-distance its φ: a review)
            cause = getattr(surf, "band_advice", None)
            if cause is None and isinstance(surf, LevelSet) and not redistanced:
                cause = "φ is far from a distance function (use ts.LevelSet(phi, redistance=True))"
            raise ValueError(
                f"the extension layer does not enclose the inner tube even with outer = {outer_eff}: {missing.size} "
                f"inner nodes lack a neighbour (the first near {_where(grid, linear[missing[0]])}). "
                + (f"{cause}, or " if cause else "")
                + "the grid is too coarse for the surface (the tube reaches across it, e.g. a sphere not much larger "
                "than the tube: refine the grid)"
                + (
                    ""
                    if given_bound is None
                    else f", or the lipschitz bound given, {given_bound:g}, is below |∇φ| near "
                    "the surface and keeps nodes from the band's candidates (leave it out to have it estimated)"
                )
            )
        warnings.warn(
            _widening_message(missing, phi, h, inner, outer_eff, surf), RuntimeWarning, stacklevel=user_stacklevel()
        )
        outer_eff += 1.0
    # a surface that leaves the grid box: the distances are those of the part inside (warned)
    cut = box_cut(grid, linear, phi, inner_width)
    warn_box_cut(cut, int(np.count_nonzero(roles != ROLE_OUTER)), surf, grid)
    directions = direction if direction is not None else geom.direction
    cuts = cuts_shortcuts(surf)
    gap_note = getattr(surf, "_gap_note", None)
    note = gap_note(h) if gap_note is not None else ""
    noise = float(getattr(surf, "_noise", 0.0))
    facing = _warn_if_tubes_touch(
        grid, band, linear, roles, phi, directions, inner, kink, noise, warn=not cuts and inside is None, note=note
    )
    if inside is not None:
        # an unsigned φ with a known inside (BandGeometry.inside): the pairs of the signed φ too
        signed_phi = np.where(inside, -phi, phi)
        facing = _union_pairs(
            facing,
            _warn_if_tubes_touch(grid, band, linear, roles, signed_phi, directions, inner, kink, noise, warn=False),
        )
        del signed_phi
        if not cuts:
            warn_facing_pairs(grid, linear, roles, facing, inner, note)
    # a mesh or a point cloud: pairs over a hole are no gap (cut nowhere, not warned)
    over_holes = getattr(surf, "_pairs_over_holes", None)
    hole_pairs = None
    if over_holes is not None and facing[0].size:
        on_hole = over_holes(grid, linear[facing[0]], linear[facing[1]], facing[2])
        hole_pairs = (linear[facing[0][on_hole]], linear[facing[1][on_hole]], facing[2][on_hole])
        facing = (facing[0][~on_hole], facing[1][~on_hole], facing[2][~on_hole])
    cut_edges = 0
    pieces = None
    cut_facing = facing
    resolved = getattr(surf, "resolved_gap", None)  # a cloud: the gaps its fits keep apart
    if cuts and resolved is not None:
        node, neighbour, gap = facing
        narrow = gap < resolved(h)
        cut_facing = (node[~narrow], neighbour[~narrow], gap[~narrow])
        warn_facing_pairs(
            grid,
            linear,
            roles,
            (node[narrow], neighbour[narrow], gap[narrow]),
            inner,
            getattr(surf, "_unresolved_gap_note")(h) + (gap_note(h) if gap_note is not None else ""),
            resolving=float(getattr(surf, "resolving_spacings")),
        )
    if cuts:
        band, cut_edges = cut_shortcuts(
            band, roles == ROLE_INNER, phi, directions, h, cut_facing, medial=cuts_medial_edges(surf)
        )
        band, parted, pieces = cut_between_parts(surf, grid, band, linear)
        band, pinched = cut_pinches(surf, grid, band, linear)
        cut_edges += parted + pinched
    thin_parts = getattr(surf, "_warn_thin_parts", None)  # a mesh: parts closer than a spacing
    if thin_parts is not None:
        thin_parts(h, inner)
    elif isinstance(surf, LevelSet) and not facing[0].size:  # (where gaps are found, they are said)
        warn_thin(*thin_share(grid, band, linear, phi), h, inner)
    holes_of = getattr(surf, "_bridged_holes", None)  # an open mesh's or a cloud's holes the band spans
    bridged_holes = holes_of(h, outer_eff, grid, hole_pairs) if holes_of is not None else None
    slits_of = getattr(surf, "_slits", None)  # an open mesh's slits, which the band may join
    slits = slits_of(h) if slits_of is not None else None
    # (after the facing test, which reads the paper's inner tube). On a re-distanced φ, whose kinks
    # include those of its samples (a voxel mask's staircase: a sphere's mask said "creases …
    # turning by up to 84°" to the plain test), the paper's tube's creases are those of the
    # second-order geometry's test (:func:`paper_creases_of`), which costs its pass: run for the
    # one call at order=1 here, for a Tube when an order=1 solve needs it. Crease nodes are thinned
    # all the same: a closed cylinder r = 0.35, h = 0.8, bottom centre, re-distanced
    # from its distance function came out 9.4, 8.1, 9.9Δx short at N = 41, 61, 81 in the paper's
    # tube (2.4, 2.5, 3.5Δx thinned), its voxel mask 7.3–7.9Δx (4.1–4.2Δx), a sphere's voxel mask
    # 3.5e-2 off on average at N = 41 (1.7e-2)
    extended = np.empty(0, np.int64)
    paper_creases = None
    if method == "two-layer" and isinstance(surf, LevelSet):
        if not getattr(surf, "redistance", False):
            paper_creases = creases_in_paper_tube(band, roles == ROLE_INNER, phi, directions, h)
        elif not creases and not reusable:  # the one call at order=1
            paper_creases = creases_of_redistanced(grid, band, roles, phi, directions, outer_eff * h, surf)
        if creases:
            extended = crease_nodes_to_extend(band, roles == ROLE_INNER, phi, directions, h)
    return _PreparedTube(
        grid,
        surf,
        float(inner),
        outer_eff,
        method,
        geom,
        linear,
        roles,
        band,
        phi,
        direction,
        time.perf_counter() - t0,
        facing,
        cut,
        cut_edges,
        extended,
        paper_creases=paper_creases,
        pieces=pieces,
        bridged_holes=bridged_holes,
        slits=slits,
    )
