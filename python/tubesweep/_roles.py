"""The roles of the band's nodes (paper Fig. 4): a fixed node (a source's), the inner tube Γ^in,
where the eikonal equation is solved, and the extension layer Γ^out, where the extension equation
(8) carries the values along the normals (Algorithm 3; every node is inner in Algorithm 2)."""

from __future__ import annotations

from typing import Any

import numpy as np

#: A node belongs to the inner tube when ``|φ| ≤ inner·Δx·(1 + ROLE_RTOL)``. The relative
#: tolerance makes nodes that sit exactly on the inner radius (up to rounding, common on
#: symmetric grids) consistently inner.
ROLE_RTOL = 1e-9

ROLE_FIXED, ROLE_INNER, ROLE_OUTER = 0, 1, 2

_ROLE_CHUNK = 1 << 18


def tube_roles(geom: Any, inner_width: float, method: str) -> np.ndarray:
    """Roles of the band nodes: inner tube where ``|φ| ≤ inner·Δx`` (every node for the naive
    method), else extension layer; chunk by chunk, without K-sized temporaries."""
    roles = np.full(len(geom.linear), ROLE_INNER if method == "naive" else ROLE_OUTER, np.uint8)
    if method != "naive":
        limit = inner_width * (1 + ROLE_RTOL)
        for lo in range(0, len(roles), _ROLE_CHUNK):
            part = roles[lo : lo + _ROLE_CHUNK]
            part[geom.unsigned(lo, lo + _ROLE_CHUNK) <= limit] = ROLE_INNER
    return roles
