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
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Slack of the side test, in grid spacings (curved sheets: the projection's shrinking is not exact).
SIDE_SLACK = 0.25


def own_side_values(sol: Any, points: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``out`` (the multilinear values of ``sol`` at ``points``) with the points whose cell holds a
    node of a pair across a narrow gap read from the corners of their own side only."""
    node, neighbour, _ = sol._facing
    if node.size == 0 or len(points) == 0:
        return out
    grid = sol.grid
    d, h = grid.ndim, grid.spacing
    k_nodes = len(sol.values)
    shape = np.asarray(grid.shape)
    t = grid.continuous_index(points)
    base = np.clip(np.floor(t).astype(np.int64), 0, shape - 2)
    frac = np.clip(t - base, 0.0, 1.0)
    offsets = np.array([[(c >> k) & 1 for k in range(d)] for c in range(1 << d)], dtype=np.int64)
    corners = base[:, None, :] + offsets[None, :, :]
    pos = sol._band.find(np.ascontiguousarray(corners.reshape(-1, d))).reshape(len(points), -1)
    paired = np.zeros(k_nodes + 1, bool)
    paired[node] = True
    paired[neighbour] = True
    rows = np.flatnonzero(np.any(paired[np.where(pos >= 0, pos, k_nodes)], axis=1))
    if rows.size == 0:
        return out
    corner_points = grid.points(corners[rows].reshape(-1, d))
    _, corner_cp = sol.surface.project(corner_points, grid)
    _, foot = sol.surface.project(points[rows], grid)
    corner_points = corner_points.reshape(rows.size, -1, d)
    corner_cp = np.asarray(corner_cp).reshape(rows.size, -1, d)
    foot = np.asarray(foot)[:, None, :]
    own = np.linalg.norm(corner_cp - foot, axis=2) <= np.linalg.norm(corner_points - foot, axis=2) + SIDE_SLACK * h
    sub = pos[rows]
    vals = sol.values[np.maximum(sub, 0)]
    own &= (sub >= 0) & np.isfinite(vals)
    weight = np.prod(np.where(offsets[None, :, :] == 1, frac[rows, None, :], 1.0 - frac[rows, None, :]), axis=2)
    weight = np.where(own, weight, 0.0)
    total = weight.sum(axis=1)
    ok = total > 0
    res = out.copy()
    res[rows[ok]] = (weight[ok] * np.where(own[ok], vals[ok], 0.0)).sum(axis=1) / total[ok]
    return res
