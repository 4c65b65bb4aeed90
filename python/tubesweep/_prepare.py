"""Building the computational tube for a solve (paper Fig. 4): the band of a surface, the role of
each node (inner tube, extension layer; Algorithm 2 or 3), the checks that the grid resolves the
surface (memory, tubes of facing sheets that touch, a surface thinner than two cells), and the
band structure the sweeps run on. Shared by :func:`tubesweep.solve` and :class:`tubesweep.Tube`."""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
import time
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, TypeVar

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
from ._warn import user_stacklevel, where_node
from ._roles import ROLE_INNER, ROLE_OUTER, tube_roles
from ._facing import facing_gaps
from ._box_cut import box_cut, warn_box_cut
from ._coarse_creases import creases_of_redistanced
from .redistance import LIPSCHITZ_MARGIN, estimate_lipschitz
from ._creases import crease_nodes_to_extend, creases_in_paper_tube
from ._thin_level_set import thin_share, warn_thin

METHODS = ("two-layer", "naive")


def _widening_message(
    missing: np.ndarray,
    phi: np.ndarray,
    h: float,
    inner: float,
    outer: float,
    surface: Any = None,
    grid: Optional[Grid] = None,
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
    bound = _low_lipschitz(surface, grid)
    if bound:
        # (a re-distanced φ is a distance: a bound below its gradient left nodes out of the search,
        # blamed on φ; a helper's review)
        cause = f"the band search missed them{bound}"
    text = (
        f"{missing.size} inner-tube nodes had a neighbour outside the band with outer = {outer}: {cause} (at "
        f"{int(np.count_nonzero(~far))} of them the neighbour is more than one spacing farther out)"
    )
    return f"{text}. {widen}" if advice is None else f"{text}: {advice}. {widen}"


_MAX_WIDENINGS = 4


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
    keep = np.setdiff1d(keep, _unextendable(tube, keep), assume_unique=True)
    if keep.size == tube.crease_nodes.size:
        return tube
    paper[keep] = ROLE_OUTER
    return dataclasses.replace(tube, roles=paper, crease_nodes=keep)


def _unextendable(tube: _PreparedTube, thinned: np.ndarray) -> np.ndarray:
    """The nodes of ``thinned`` (crease nodes made extension nodes, band positions) whose
    extension update (Eq. (5): from the upwind neighbours along the node's direction) can reach
    no value: every neighbour it reads is another of them, or missing. A φ that is a staircase
    along the normals (a mask's Euclidean distance transform, where neighbours share |φ|) has such
    rings: a ball's at N = 81 left 240 of 912 thinned nodes at +∞, and 11 of 400 points on the
    sphere read ``inf`` with ``converged=True`` (a review). They stay in the inner tube. The
    other extension nodes count as reached (they are in the paper's tube, whose first-order
    solve reaches them)."""
    if thinned.size == 0 or tube.geom is None:
        return thinned[:0]
    k_nodes = len(tube.roles)
    d = np.asarray(tube.geom.direction[thinned], dtype=float)
    around = tube.band.neighbours_of_nodes(np.ascontiguousarray(thinned, dtype=np.int64))  # (M, D, 2)
    read = np.where(d > 0, around[:, :, 0], np.where(d < 0, around[:, :, 1], k_nodes))
    read = np.where((read >= 0) & (read < k_nodes), read, k_nodes)
    reached = np.ones(k_nodes + 1, dtype=bool)
    reached[k_nodes] = False
    reached[thinned] = False
    while True:  # reached once any neighbour it reads is (each round reaches a layer more)
        now = np.any(reached[read], axis=1) & ~reached[thinned]
        if not np.any(now):
            return thinned[~reached[thinned]]
        reached[thinned[now]] = True


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
    # a mesh's exact map where it has a smooth one (whose fits need 22 samples: a cube of 12
    # triangles turned the estimate off, and n = 3000 aborted in an allocation: a helper's review)
    project = getattr(surf, "exact_project", surf.project)
    try:
        dist = np.asarray(project(points, grid)[0], dtype=float)
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


def _checked_widths(inner: float, outer: float, method: str) -> Tuple[float, float]:
    """``inner`` and ``outer`` as finite numbers of grid spacings that leave the inner tube at least
    one spacing and the extension layer room for every inner node's neighbours, or the error."""
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
    return inner, outer


def _low_lipschitz(surf: Any, grid: Optional[Grid]) -> str:
    """A note when ``surf`` is a callable φ whose given ``lipschitz`` lies below its gradient (the
    band search skips cells where |φ| exceeds the bound times their size, and so misses nodes),
    else ''."""
    given = getattr(surf, "lipschitz", None)
    if grid is None or not isinstance(surf, LevelSet) or surf._fn is None or given is None:
        return ""
    if surf.redistance is False and given == 1.5:  # (the default bound, not a user's)
        return ""
    try:
        steepest = estimate_lipschitz(surf, grid) / LIPSCHITZ_MARGIN
    except ValueError:
        return ""
    if steepest <= given:
        return ""
    return (
        f": lipschitz={given:g} is below φ's gradient (|∇φ| reads up to {steepest:.3g} over the box), and the band "
        "search skips the cells where |φ| exceeds lipschitz times their size; pass a larger lipschitz"
        + (" or leave it None (estimated then)" if surf.redistance else "")
    )


def _empty_band_message(surf: Surface, grid: Grid) -> str:
    """Why the band is empty: the surface does not pass through the grid or φ is not in its units
    (or, for a φ array given as is that changes sign, far larger than a distance near the change;
    or a φ callable that is not finite at any node of a coarse lattice of the box: one returning
    NaN everywhere was told to check that the surface passes through the grid, a helper's review)."""
    fn = getattr(surf, "_fn", None) if isinstance(surf, LevelSet) else None
    if fn is not None:
        axes = [np.linspace(lo, hi, 5) for lo, hi in zip(grid.lower, grid.upper)]
        lattice = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, grid.ndim)
        with np.errstate(all="ignore"):
            try:
                values = np.asarray(fn(lattice), dtype=float).reshape(-1)
            except Exception:  # (its own errors were raised during the band search)
                values = np.zeros(1)
        if values.size and not np.any(np.isfinite(values)):
            return (
                f"the band is empty: the φ callable returned NaN or inf at every point of a 5^{grid.ndim} lattice of "
                f"the grid box (e.g. {values[0]} at {tuple(float(c) for c in lattice[0])}): it must return finite "
                "values near the surface"
            )
        bound = _low_lipschitz(surf, grid)
        if bound:
            return f"the band is empty{bound}"
    array = getattr(surf, "_array", None) if isinstance(surf, LevelSet) and not surf.redistance else None
    # (a φ array given as is that changes sign: a surface is there, but φ is not its distance)
    signs = array is not None and bool(np.any(array < 0) and np.any(array > 0))
    return (
        "the band is empty: no grid node lies within the tube; check that the surface passes through the grid "
        "and that φ is in the grid's units"
        + (
            " (φ changes sign, but its values near the change are far larger than a distance, e.g. a mask's "
            "±0.5: LevelSet(phi, redistance=True), or LevelSet.from_mask(mask, grid) for a mask)"
            if signs
            else ""
        )
    )


def _unprojected_message(surf: Surface, grid: Grid, count: int) -> str:
    """Why ``count`` nodes next to a re-distanced φ's inner tube stay out of the band however wide
    its layer: the projection cannot place them on the zero level set."""
    return (
        _specks(surf, grid)
        + f"{count} nodes next to the inner tube could not be projected onto φ's zero level set, and a wider "
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


def _unclosed_message(
    surf: Surface, grid: Grid, first: int, missing: int, outer: float, given_bound: Optional[float]
) -> str:
    """Why the extension layer does not enclose the inner tube after the widenings (``missing``
    inner nodes lack a neighbour, the first at linear index ``first``): the surface kind's own
    cause, φ far from a distance, a grid too coarse, or a ``lipschitz`` bound given too low."""
    redistanced = bool(getattr(surf, "redistance", False))
    # a surface kind's own cause (a point cloud's, a mesh's), or φ's for a level set not
    # re-distanced (a mesh's smooth map failing here was told to re-distance its φ: a review)
    cause = getattr(surf, "band_advice", None)
    if cause is None and isinstance(surf, LevelSet) and not redistanced:
        cause = "φ is far from a distance function (use ts.LevelSet(phi, redistance=True))"
    return (
        f"the extension layer does not enclose the inner tube even with outer = {outer}: {missing} "
        f"inner nodes lack a neighbour (the first near {where_node(grid, first)}). "
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


@dataclasses.dataclass
class _Band:
    """The band the widenings settled on (:func:`_widened_band`): the surface's band geometry (None
    once consumed), the nodes' linear indices and roles, the native band, φ in single precision,
    the kinks and inside of the geometry, the directions for the solver (when consumed) and the
    extension layer's width in grid spacings."""

    geom: Any
    linear: np.ndarray
    roles: np.ndarray
    band: Any
    phi: np.ndarray
    kink: Optional[np.ndarray]
    inside: Optional[Callable[[np.ndarray], np.ndarray]]
    direction: Optional[np.ndarray]
    outer: float


_T = TypeVar("_T")


def _keeping_band_work(attempts: Callable[..., _T]) -> Callable[..., _T]:
    """``attempts`` run within the surface's ``_band_widening`` context where it has one (a point
    cloud keeps what it computed for the band's nodes while the band is widened)."""

    @functools.wraps(attempts)
    def run(surf: Surface, *args: Any) -> _T:
        with getattr(surf, "_band_widening", contextlib.nullcontext)():
            return attempts(surf, *args)

    return run


@_keeping_band_work
def _widened_band(
    surf: Surface,
    grid: Grid,
    inner: float,
    outer_eff: float,
    method: str,
    keep_geometry: bool,
    reusable: bool,
) -> Optional[_Band]:
    """The band of ``surf`` within ``outer_eff`` grid spacings with its roles, widened (a warning
    each time) while inner-tube nodes lack a neighbour in it, or the error when that does not
    close it. None where a mesh's smooth map folds on this grid and its exact closest points are
    to be used instead (``fold_to_exact``: build the tube again)."""
    h = grid.spacing
    inner_width = inner * h
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
            raise ValueError(_empty_band_message(surf, grid))
        roles = tube_roles(geom, inner_width, method)
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
            raise ValueError(_unprojected_message(surf, grid, lacking.size))
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
                return None
            raise ValueError(_unclosed_message(surf, grid, linear[missing[0]], missing.size, outer_eff, given_bound))
        warnings.warn(
            _widening_message(missing, phi, h, inner, outer_eff, surf, grid),
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
        outer_eff += 1.0
    return _Band(geom, linear, roles, band, phi, kink, inside, direction, outer_eff)


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
    inner, outer = _checked_widths(inner, outer, method)
    h = grid.spacing
    inner_width = inner * h
    layer = float(outer) if method == "two-layer" else float(inner)  # the band's half-width in spacings
    _check_band_memory(surf, grid, layer * h)
    b = _widened_band(surf, grid, inner, layer, method, keep_geometry, reusable)
    if b is None:  # a mesh's smooth map that folds: its exact closest points on this grid
        return _prepare_tube(surf, grid, inner, outer, method, keep_geometry, reusable, creases)
    linear, roles, phi, outer_eff = b.linear, b.roles, b.phi, b.outer
    # a surface that leaves the grid box: the distances are those of the part inside (warned)
    directions = b.direction if b.direction is not None else b.geom.direction
    cut = box_cut(grid, linear, phi, inner_width, directions)
    warn_box_cut(cut, int(np.count_nonzero(roles != ROLE_OUTER)), surf, grid)
    gaps = facing_gaps(surf, grid, b.band, linear, roles, phi, directions, inner, b.kink, b.inside)
    band, facing = gaps.band, gaps.facing
    thin_parts = getattr(surf, "_warn_thin_parts", None)  # a mesh: parts closer than a spacing
    if thin_parts is not None:
        thin_parts(h, inner)
    elif isinstance(surf, LevelSet):
        # (also where facing gaps were found and said, from a larger share: the gap warning gives no
        # size, and a plate 1.2 spacings thick tilted off the grid's planes showed 14% of its
        # surface as gaps and was crossed, its far side 0.05 for a distance of 1.0; a review)
        warn_thin(*thin_share(grid, band, linear, phi), h, inner, gaps=bool(facing[0].size))
    holes_of = getattr(surf, "_bridged_holes", None)  # an open mesh's or a cloud's holes the band spans
    bridged_holes = holes_of(h, outer_eff, grid, gaps.over_holes) if holes_of is not None else None
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
        b.geom,
        linear,
        roles,
        band,
        phi,
        b.direction,
        time.perf_counter() - t0,
        facing,
        cut,
        gaps.cut_edges,
        extended,
        paper_creases=paper_creases,
        pieces=gaps.pieces,
        bridged_holes=bridged_holes,
        slits=slits,
    )
