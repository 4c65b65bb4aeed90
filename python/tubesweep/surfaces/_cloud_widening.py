"""A point cloud's band while the tube's preparation widens it (``_prepare._widened_band``,
``PointCloudSurface._band_widening``): the closest points found for the nodes of a narrower band are
kept, and a wider band computes only its new nodes' (each widening computed every node again: a
sparsely sampled sphere's refusal at N = 61, five bands: median 16.6 s, 4.0 s with the feet kept,
``benches/experiments/cloud_widening.py``). Kept for one preparation only, so that two solves of a cloud
compute the same bits: a node's foot depends, within the fits' tolerance, on the nodes computed
before it in its block (``tubesweep_core::surface::point_cloud``'s ``closest_points``)."""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ..grid import Grid


def known_feet(cloud: Any, grid: Grid) -> Optional[dict]:
    """The feet kept while ``cloud`` widens its band, for this grid and smoothing ({} while
    widening with none yet), or None outside a widening."""
    known: Optional[dict] = getattr(cloud, "_widening_feet", None)
    if known is None:
        return None
    if known and (known["grid"] != grid or known["smoothing"] != cloud.smoothing):
        return {}
    return known


def closest_with(
    known: Optional[dict], fits: Any, lin: np.ndarray, x: np.ndarray, rho: float, trust: float
) -> Tuple[np.ndarray, np.ndarray]:
    """The fits' closest points and feet of the nodes ``lin`` (at ``x``), those in ``known`` (a
    narrower band's, ``PointCloudSurface._band_widening``) taken from it, the others computed."""
    if not known or not len(known["linear"]):
        return fits.closest(np.ascontiguousarray(x), rho, trust)
    pos = np.minimum(np.searchsorted(known["linear"], lin), len(known["linear"]) - 1)
    hit = known["linear"][pos] == lin
    cp = np.empty_like(x)
    feet = np.empty(len(lin), dtype=known["feet"].dtype)
    cp[hit], feet[hit] = known["cp"][pos[hit]], known["feet"][pos[hit]]
    miss = ~hit
    if np.any(miss):
        cp[miss], feet[miss] = fits.closest(np.ascontiguousarray(x[miss]), rho, trust)
    return cp, feet


def keep_feet(known: dict, grid: Grid, smoothing: float, computed: list) -> dict:
    """``known`` with the feet ``computed`` in one band search added ((nodes, closest points, feet)
    per chunk), sorted by node, each node once."""
    parts = [(known["linear"], known["cp"], known["feet"])] if known else []
    parts += computed
    if not parts:
        return {}
    lin, cp, feet = (np.concatenate([q[i] for q in parts]) for i in range(3))
    order = np.argsort(lin, kind="stable")
    lin, first = np.unique(lin[order], return_index=True)
    return {"grid": grid, "smoothing": smoothing, "linear": lin, "cp": cp[order][first], "feet": feet[order][first]}
