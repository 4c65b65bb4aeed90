"""Parts of the surface that no path joins: a value only from a source on the node's own part.

Where two parts of the surface face each other across a gap narrower than the tubes
(``_facing._warn_if_tubes_touch``), the two-layer method (Algorithm 3) lets a node read a
neighbour whose closest point lies on the other part, so the front can cross the gap. Where the
band is cut there (``_shortcuts``, triangle meshes) it cannot; elsewhere a part that carries no
source was given finite, too short travel times: two spheres 6 grid spacings apart as a
re-distanced φ (``ts.LevelSet(phi, redistance=True)``, and so every step of ``ts.evolve``), the
far one reached at 1.27 with ``converged=True`` and a warning of "1 node pair, 0.027 % of the
surface".

A connected surface has a connected inner tube: its nodes lie within ``inner``·Δx of the surface,
and the balls of that radius around the surface's points overlap along it, so its nodes are
joined along the axes. An inner-tube component (a *part*) that holds no source is therefore one
that no path on the surface reaches, and its nodes keep ``inf`` whatever reached them across a
gap. The inner tube here is the paper's: the nodes that second order moves to the extension
layer at creases (``_creases``) count as inner (a cube's thinned inner tube stays connected
around its edges at N = 41 and 81, but a sharper crease could split it). Only inner-tube nodes are
set to inf: a point on the surface reads at least one of them (the nearest corner of its cell lies
within √3/2 spacings), while an extension node can lie as close to the other part as to its own
(with ``inner=1`` a point on the sourced part read inf through such a corner of weight 6e-6). And
only where the inner tube is thick enough to be connected (:func:`_thick_enough`: a φ far from a
distance makes it thinner).

Only tubes with facing pairs are labelled (elsewhere no front crosses between parts): O(band)
union–find in the core (``second_order::warm::component_labels``) and one pass over the inner
tube's neighbours (:func:`_thick_enough`).
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import _native
from ._interpolation import cell_corners
from .grid import Grid
from ._shortcuts import cuts_medial_edges
from ._roles import ROLE_OUTER

#: The label of a node of no part (an extension node).
NO_PART = np.iinfo(np.uint32).max


def part_labels(tube: Any, band: Any = None) -> Optional[np.ndarray]:
    """Per band node of ``tube`` (a ``_prepare._PreparedTube``) its part of the surface (uint32:
    the smallest band position of its inner-tube component on ``band``, the band the sweeps run
    on, default the tube's; :data:`NO_PART` for extension nodes), or None when no two parts face
    each other across a gap (nothing can cross), the inner tube is too thin to be connected
    (:func:`_thick_enough`), or ``band`` is cut at medial edges (``_shortcuts``:
    a mesh, whose inner tube the cuts above concave edges could split, so its parts are left to
    the cuts; a point cloud's band is cut only between facing sheets, which leaves each sheet's
    inner tube whole, and the Lax–Friedrichs scheme runs on the uncut band, where a mesh's
    separate pieces label its inner tube: ``surfaces._mesh_parts``)."""
    band = tube.band if band is None else band
    cut = band is tube.band and tube.cut_edges > 0
    part = tube.pieces
    node_parts = getattr(tube.surface, "_node_parts", None)
    if part is None and node_parts is not None and tube.linear is not None:
        part = node_parts(tube.grid, tube.linear)  # (a tube prepared without the cut)
    if part is not None:
        # a mesh's separate pieces, from each node's nearest face (surfaces._mesh_parts), label
        # the inner tube, cut or not: second order's exact start reaches across a narrow gap
        # (FIX_RADIUS), as the Lax–Friedrichs scheme on its uncut band does
        labels = np.where(part >= 0, part, NO_PART).astype(np.uint32)
        labels[tube.roles == ROLE_OUTER] = NO_PART
        return labels
    if tube.facing[0].size == 0 or (cut and cuts_medial_edges(tube.surface)):
        return None  # no front crosses between parts; a mesh's band is cut between them already
    inner = tube.roles != ROLE_OUTER
    if len(tube.crease_nodes):
        inner = inner.copy()
        inner[tube.crease_nodes] = True  # the paper's inner tube (see the module)
    if not _thick_enough(tube, band, inner):
        return None
    # extension nodes keep NO_PART: only the inner tube is dropped, so that a point read next to a
    # narrow gap keeps the values of its own side (with inner = 1 a point on the sourced part had
    # a corner of weight 6e-6 on the other part's extension layer)
    return _native.band_component_labels(band, np.ascontiguousarray(inner))


#: The inner tube is labelled only where it is at least this many grid spacings thick on either
#: side of the surface: the nodes within w of a plane are joined along the axes when 2w ≥ √3·Δx
#: (the largest L1 norm of a unit normal).
THICK_ENOUGH = 0.5 * np.sqrt(3.0)


def _thick_enough(tube: Any, band: Any, inner: np.ndarray) -> bool:
    """Whether the inner tube of a connected surface is connected: its half-width in distance,
    ``inner``·Δx over |∇φ| (central differences of the band's φ at its inner nodes, the 95th
    percentile), is at least :data:`THICK_ENOUGH` spacings. φ = 2·d with ``inner=1`` is half a spacing thick and
    broke a sphere's inner tube into nine parts, eight of them set to inf."""
    h = tube.grid.spacing
    # (not at the facing pairs: across the ridge between two sheets φ jumps, a sheet's sign to the
    # other's; and a high percentile, not the largest, for the kinks elsewhere)
    away = inner.copy()
    away[tube.facing[0]] = False
    away[tube.facing[1]] = False
    nodes = np.flatnonzero(away)
    nb = band.neighbours_of_nodes(np.ascontiguousarray(nodes, dtype=np.int64)).reshape(nodes.size, -1, 2)
    n = len(inner)
    phi = np.append(np.asarray(tube.phi, dtype=float), np.nan)
    ends = np.where(nb < n, nb, n)
    slope = (phi[ends[:, :, 1]] - phi[ends[:, :, 0]]) / (2.0 * h)
    grad = np.sqrt(np.sum(slope**2, axis=1))
    grad = grad[np.isfinite(grad)]
    return grad.size == 0 or tube.inner / float(np.quantile(grad, 0.95)) >= THICK_ENOUGH


def parts_at(grid: Grid, band: Any, labels: np.ndarray, points: np.ndarray, weighted: bool = False) -> np.ndarray:
    """The parts of the band nodes at the corners of each point's cell, ``(M, 2^d)`` (NO_PART
    where a corner is not in the band; with ``weighted``, also where its multilinear weight is 0,
    computed as the core's interpolation computes it: :func:`~tubesweep._interpolation.cell_corners`)."""
    _, pos, weight = cell_corners(grid, band, points)
    return corner_parts(labels, pos, weight if weighted else None)


def corner_parts(labels: np.ndarray, pos: np.ndarray, weight: Optional[np.ndarray] = None) -> np.ndarray:
    """The parts of ``labels`` at band positions ``pos`` (cells' corners, −1 off the band: NO_PART),
    and NO_PART where ``weight``, when given, is 0."""
    out = np.append(labels, np.uint32(NO_PART))[np.where(pos >= 0, pos, len(labels))]
    if weight is not None:
        out[weight == 0.0] = NO_PART
    return out


def source_parts(
    grid: Grid, band: Any, labels: np.ndarray, sources: np.ndarray, surface: Any = None
) -> Optional[np.ndarray]:
    """The parts that hold the sources (those of the corners of each source's cell; on a mesh of
    separate pieces, ``surface``, the pieces of the sources' nearest faces: a cell next to the
    gap has corners on both), or None when a source's cell has no labelled corner (then nothing
    is dropped)."""
    if surface is not None and getattr(surface, "_node_parts", None) is not None:
        from .surfaces._mesh_parts import face_parts, point_parts

        pieces = face_parts(surface)
        if pieces is not None:  # (the labels are the pieces: part_labels)
            own = point_parts(surface, np.asarray(sources, dtype=float).reshape(-1, grid.ndim))
            if np.all(own >= 0):
                sourced = np.unique(own).astype(np.uint32)
                if not np.any(np.isin(labels, sourced)):
                    # every value would be inf: the sources' pieces own no node of the inner tube
                    # (an icosphere whose 20,480 triangles were each shrunk apart: all inf,
                    # converged=True, unwarned)
                    count = int(np.max(pieces)) + 1
                    raise ValueError(
                        f"the sources lie on {sourced.size} of the mesh's {count} separate pieces, and no node of the "
                        "inner tube belongs to them: pieces smaller than the grid resolves (its spacing is "
                        f"{grid.spacing:.4g}), which no path joins to the rest. Join the mesh's pieces (e.g. "
                        "trimesh's merge_vertices, or a mesh whose triangles share their vertices), or refine the grid"
                    )
                return sourced
    at = parts_at(grid, band, labels, np.asarray(sources, dtype=float).reshape(-1, grid.ndim))
    found = at != NO_PART
    if not np.all(np.any(found, axis=1)):
        return None
    return np.unique(at[found])


def on_sourced_parts(labels: Optional[np.ndarray], sourced: Optional[np.ndarray]) -> Optional[np.ndarray]:
    """Per band node whether it may be reached: False on the inner tube of a part without a
    source (None when nothing is dropped: every node may)."""
    if labels is None or sourced is None:
        return None
    return (labels == NO_PART) | np.isin(labels, sourced)


def drop_unsourced(values: np.ndarray, labels: np.ndarray, sourced: Optional[np.ndarray]) -> int:
    """Sets to inf (in place) the finite values of nodes on parts other than ``sourced``; returns
    how many there were."""
    if sourced is None:
        return 0
    off = np.isfinite(values) & (labels != NO_PART) & ~np.isin(labels, sourced)
    values[off] = np.inf
    return int(np.count_nonzero(off))


def drop_unsourced_points(values: np.ndarray, corner_parts: np.ndarray, sourced: Optional[np.ndarray]) -> np.ndarray:
    """``values`` read at points (M,) as a solve whose band values :func:`drop_unsourced` set
    reads them: inf where a corner of nonzero weight (``corner_parts`` from :func:`parts_at` with
    ``weighted``) lies on a part other than ``sourced`` (NaN, a corner off the band, stays)."""
    if sourced is None:
        return values
    off = np.any((corner_parts != NO_PART) & ~np.isin(corner_parts, sourced), axis=1)
    off &= ~np.isnan(values)
    if not np.any(off & np.isfinite(values)):
        return values
    out = values.copy()
    out[off] = np.inf
    return out


def drop_unsourced_rows(
    rows: np.ndarray,
    tube: Any,
    groups: Any,
    points: Optional[np.ndarray],
    band: Any = None,
    labels: Optional[np.ndarray] = None,
) -> np.ndarray:
    """The rows of ``Tube.solve_many`` (one per source group: band values, or the values read at
    ``points``, before any own-side reading of them) with inf on the parts of the surface other
    than their sources', as each single solve's; ``band`` the band the sweeps ran on, ``labels``
    its :func:`part_labels` where the caller has them."""
    parts = part_labels(tube, band) if labels is None else labels
    if parts is None:
        return rows
    grid, band = tube.grid, tube.band if band is None else band
    corners = None if points is None else parts_at(grid, band, parts, points, weighted=True)
    out = np.array(rows, dtype=float, copy=True)
    for k, group in enumerate(groups):
        sourced = source_parts(grid, band, parts, group, tube.surface)
        if corners is None:
            drop_unsourced(out[k], parts, sourced)
        else:
            out[k] = drop_unsourced_points(out[k], corners, sourced)
    return out
