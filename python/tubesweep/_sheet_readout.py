"""Reading the solution at points next to a narrow gap of a cut band (``_shortcuts``): only from
the nodes of the point's own side.

Where two parts of the surface face each other across a gap narrower than the tubes, the cell
of a point on one part can have corners whose closest points lie on the other part, with the
other part's travel times: the multilinear interpolation of :meth:`Solution.__call__` would mix
the two (on a plate 1.5 grid spacings thick, a point of the bottom face read 0.87 where the
solve had 1.03 at its own nodes and 0 across the plate). A triangle mesh's band is cut across
such gaps, so the values of the two sides differ; at the points whose cell holds a node of a
pair across a gap, the corners of the other side are left out and the weights of the rest
renormalised.

A corner ``c`` lies on the side of the point's closest point ``p`` when its own closest point
is no farther from ``p`` than ``c`` itself (up to a quarter spacing): projecting onto the sheet
through ``p`` brings a node nearer to ``p``, while the closest point of a node of the other sheet
lies across the gap, farther from ``p`` than the node, which lies between the two.

A surface of separate parts facing each other across a narrow gap (``_parts``: a level set's band
is not cut there) keeps a part no source reaches at +∞. A single solve reads a point whose cell
mixes reached and unreached corners from the reached ones where they carry half the cell's weight
or more (the core's interpolation, ``REACHED_SHARE``: a shell three spacings thick read +∞ at 36
of 20,000 points of its outer sphere, the source's, through a corner weighing 0.001), while a
batch sets a part without a source to +∞ only after reading the points
(``_parts.drop_unsourced_points``). So the points whose cell holds corners of a part and of
another part or the extension layer are read from their corners in both, by the same rule
(:meth:`OwnSidePlan.apply`), and the two give the same bits.

The plan (which points, which corners, their weights) depends on the geometry only; the corner
values are read by interpolation at the corners themselves, so that a single solve and a batch
(``Tube.solve_many(at=...)``, which reads its rows in the core) give the same bits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Tuple

import numpy as np

from ._interpolation import cell_corners
from ._parts import NO_PART, corner_parts
from .grid import Grid
from .surfaces._mesh_parts import face_parts, point_parts

#: Slack of the side test, in grid spacings (curved sheets: the projection's shrinking is not exact).
SIDE_SLACK = 0.25


@dataclass
class OwnSidePlan:
    """The points to read from their own side: their rows among the points, their cells' corners
    (R·2^d, d) and the corners' multilinear weights with the other side's set to 0 (R, 2^d)."""

    rows: np.ndarray
    corners: np.ndarray
    weights: np.ndarray

    def apply(self, out: np.ndarray, corner_values: np.ndarray) -> np.ndarray:
        """``out`` (..., M) with its planned points read from ``corner_values`` (..., R·2^d), the
        values at :attr:`corners` (unreached corners left out too); a point with no corner left
        keeps its value, and one whose own side is mostly unreached (less than half its corners'
        weight reached) reads inf: its side of the gap is a part no source reaches, the few
        reached corners lie across it (a point cloud's closest points near a gap)."""
        vals = corner_values.reshape(corner_values.shape[:-1] + self.weights.shape)
        finite = np.isfinite(vals)
        w = np.where(finite, self.weights, 0.0)
        total = w.sum(axis=-1)
        own = self.weights.sum(axis=-1)
        summed = (w * np.where(finite, vals, 0.0)).sum(axis=-1)
        res = out.copy()
        sub = res[..., self.rows]
        ok = total >= 0.5 * own
        sub[ok & (total > 0)] = summed[ok & (total > 0)] / total[ok & (total > 0)]
        sub[~ok] = np.inf
        res[..., self.rows] = sub
        return res


def own_side_plan(
    grid: Grid,
    surface: Any,
    band: Any,
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray],
    n_nodes: int,
    points: np.ndarray,
    cut: bool = True,
    labels: Optional[np.ndarray] = None,
) -> Optional[OwnSidePlan]:
    """The :class:`OwnSidePlan` of ``points`` on a band of ``n_nodes`` nodes whose pairs across
    narrow gaps are ``facing`` (when the band is ``cut`` across them), and on a triangle mesh of
    separate pieces (``surfaces._mesh_parts``, cut band or not) with the corners on another
    piece than the point's nearest face left out; with the band's part ``labels``
    (``_parts.part_labels``), also the points whose cell holds corners of two parts, all their
    corners kept. None when no point's cell holds a node of a pair or spans two pieces or parts."""
    node, neighbour, _ = facing
    use_facing = cut and node.size > 0
    node_parts = getattr(surface, "_node_parts", None)
    pieces = node_parts is not None and face_parts(surface) is not None
    if not (use_facing or pieces or labels is not None) or len(points) == 0:
        return None
    d, h = grid.ndim, grid.spacing
    corners, pos, weight = cell_corners(grid, band, points)
    chosen = np.zeros(len(points), bool)
    if labels is not None:
        chosen |= _mixes_parts(labels, pos, weight)
    if use_facing:
        paired = np.zeros(n_nodes + 1, bool)
        paired[node] = True
        paired[neighbour] = True
        chosen |= np.any(paired[np.where(pos >= 0, pos, n_nodes)], axis=1)
    if pieces and node_parts is not None:
        # each corner's piece against the point's (its nearest face's): a cell across the gap
        # between two pieces reads only its own piece's corners
        inside = np.all((corners >= 0) & (corners < np.asarray(grid.shape)), axis=2)
        lin = grid.linear_index(np.clip(corners, 0, np.asarray(grid.shape) - 1).reshape(-1, d))
        corner_piece = np.where(inside, node_parts(grid, lin).reshape(pos.shape), -1)
        point_piece = point_parts(surface, points)
        same_piece = corner_piece == point_piece[:, None]
        chosen |= np.any(~same_piece & (pos >= 0), axis=1)
    rows = np.flatnonzero(chosen)
    if rows.size == 0:
        return None
    corner_points = grid.points(corners[rows].reshape(-1, d))
    own = pos[rows] >= 0
    if use_facing:
        # (the points chosen only for their parts keep every corner: a level set's band is not cut)
        _, corner_cp = surface.project(corner_points, grid)
        _, foot = surface.project(points[rows], grid)
        at = corner_points.reshape(rows.size, -1, d)
        corner_cp = np.asarray(corner_cp).reshape(rows.size, -1, d)
        foot = np.asarray(foot)[:, None, :]
        own &= np.linalg.norm(corner_cp - foot, axis=2) <= np.linalg.norm(at - foot, axis=2) + SIDE_SLACK * h
    if pieces:
        own &= same_piece[rows]
    return OwnSidePlan(rows, np.ascontiguousarray(corner_points), np.where(own, weight[rows], 0.0))


def _mixes_parts(labels: np.ndarray, pos: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Which cells (rows of ``pos``, band positions of their corners, −1 off the band) have
    corners of nonzero ``weight`` on a part of ``labels`` and others on another part or on none
    (extension nodes, ``NO_PART``): a batch sets the corners of a part without a source to +∞
    only after reading the points (``_parts.drop_unsourced_points``), so such a point is read
    from its corners, as the single solve's is."""
    lab = corner_parts(labels, pos, weight).astype(np.int64)
    on_part = lab != NO_PART
    low = np.where(on_part, lab, np.iinfo(np.int64).max).min(axis=1)
    high = np.where(on_part, lab, -1).max(axis=1)
    off_part = np.any((weight > 0) & ~on_part & (pos >= 0), axis=1)
    return (high >= 0) & ((low != high) | off_part)
