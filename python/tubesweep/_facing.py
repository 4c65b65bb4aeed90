"""Parts of the surface that face each other across gaps narrower than the tubes (the tube stage's
check, ``tubesweep_core::band::facing_sheets``): the node pairs found, warned of, and where the
surface kind allows it (a mesh, a point cloud) the band cut across them (``_shortcuts``)."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any, Callable, Optional, Tuple

import numpy as np

from ._roles import ROLE_INNER
from ._warn import percent, user_stacklevel, where_node
from .band import band_neighbours
from .grid import Grid
from ._shortcuts import cut_between_parts, cut_pinches, cut_shortcuts, cuts_medial_edges, cuts_shortcuts


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
    where = where_node(grid, linear[node[narrowest]])
    needed = float(gap[narrowest]) / (2 * inner + 2 if resolving is None else resolving)
    # how much of the surface: the inner-tube nodes of the pairs among all inner-tube nodes
    inner_nodes = roles == ROLE_INNER
    touched = np.unique(np.concatenate([node, neighbour]))
    share = np.count_nonzero(inner_nodes[touched]) / max(int(np.count_nonzero(inner_nodes)), 1)
    warnings.warn(
        f"the surface faces itself across gaps narrower than its tubes at {node.size} node pair(s), about "
        f"{percent(share)} of the surface (the narrowest {float(gap[narrowest]):.3g} wide, near {where}). Distances "
        "reached across such a gap can come out too short, by up to the way round between its sides; "
        "distances not reached across one hold. sol.narrow_gaps() shows where; "
        f"a grid spacing below {needed:.3g} (now {h:.3g}) resolves a real gap, while a crease or scan artefact stays "
        f"narrower than any grid{note}",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


@dataclasses.dataclass
class Gaps:
    """What the tube stage found of the parts that face each other (:func:`facing_gaps`): the
    band, cut across the gaps where the surface kind allows it; the pairs ``(node, neighbour,
    gap)`` (band positions) across gaps narrower than the tubes, those over a hole left out;
    those over a hole (linear indices, or None); how many band edges were cut; the pieces the
    band was cut into between a surface's parts (or None)."""

    band: Any
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray]
    over_holes: Optional[Tuple[np.ndarray, np.ndarray, np.ndarray]]
    cut_edges: int
    pieces: Any


def facing_gaps(
    surf: Any,
    grid: Grid,
    band: Any,
    linear: np.ndarray,
    roles: np.ndarray,
    phi: np.ndarray,
    directions: np.ndarray,
    inner: float,
    kink: Optional[np.ndarray],
    inside: Optional[Callable[[np.ndarray], np.ndarray]],
) -> Gaps:
    """The pairs of band nodes across gaps narrower than the tubes (:func:`_warn_if_tubes_touch`;
    with an unsigned φ's known inside, the signed φ's too), warned of where the band is not cut
    across them; a mesh's or a point cloud's band cut across them (``_shortcuts``: above concave
    edges, across narrow gaps the fits resolve, between parts and at pinches)."""
    h = grid.spacing
    cuts = cuts_shortcuts(surf)
    gap_note = getattr(surf, "_gap_note", None)
    note = gap_note(h) if gap_note is not None else ""
    noise = float(getattr(surf, "_noise", 0.0))
    facing = _warn_if_tubes_touch(
        grid, band, linear, roles, phi, directions, inner, kink, noise, warn=not cuts and inside is None, note=note
    )
    if inside is not None:
        # an unsigned φ with a known inside (BandGeometry.inside): the pairs of the signed φ too,
        # signed where the "across" test can read the sign (Band.across_candidates; elsewhere
        # the signed φ's pairs are the unsigned φ's: the same pairs as signed everywhere)
        at = band.across_candidates(
            roles == ROLE_INNER,
            np.ascontiguousarray(phi, dtype=np.float32),
            np.ascontiguousarray(directions, dtype=np.float32).reshape(len(linear), grid.ndim),
            h,
        )
        signed_phi = phi.copy()
        if at.size:
            signed_phi[at[inside(at)]] *= -1
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
    # an open mesh: pairs at a notch of its rim are no gap either (left out altogether)
    at_notches = getattr(surf, "_pairs_at_notches", None)
    if at_notches is not None and facing[0].size:
        notch = at_notches(grid, linear[facing[0]], linear[facing[1]], facing[2])
        facing = (facing[0][~notch], facing[1][~notch], facing[2][~notch])
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
    return Gaps(band, facing, hole_pairs, cut_edges, pieces)
