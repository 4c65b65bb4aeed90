"""Holes in a point cloud against the grid's band (the cloud's counterpart of ``_mesh_holes``).

A scan has holes: the sensor's blind spots, a part that shadowed another. Where such a hole is
narrower than the band (``2·outer`` grid spacings), the band spans it, and the facing-sheets test
(``_facing._warn_if_tubes_touch``) finds node pairs over it whose closest points lie on the two
sides of the hole: it took them for two sheets facing each other across a gap and warned "the
surface faces itself across gaps" (a sphere of radius 0.6 sampled 40,000 times, three holes 0.1
wide: 5 pairs at N = 61, 2 at N = 81, ``benches/experiments/cloud_holes.py``). A hole is no gap
between two sheets: the front crossing it gives the distance on the surface with the hole
filled, shorter than the way round by at most the hole's detour (about 0.57 of its width for a
round hole), which the solve reports (``sol.stats.bridged_holes``) and warns about where it is
large against the cloud's size (``_mesh_holes.WARN_SHARE``, as for meshes).

A cloud's rim (``PointCloudSurface.rim``: samples whose neighbours leave an angular gap) is too
sparse to be joined into loops as a mesh's boundary is (a hole 0.1 wide in 40,000 samples of the
sphere above showed 7–18 of its some 30 rim samples). The pairs are judged where they are
instead, in groups (pairs within :data:`GROUP` widths of a group's first one): a group lies over
a small hole when

* rim samples lie within ``r = W + 2Δx`` of it (``W`` the group's widest gap): it is at a rim,
* none lies between ``r`` and ``2r``: the rim closes round it there (a notch in an outline, a
  slit, a C-shaped part and two sheets' edges facing each other have rims that go on; so do
  holes closer than that to another hole or to the outline, which stay gaps),
* no sample lies near the middle of those rim samples (:data:`EMPTY`): a separate part lying in
  the hole (a plug) is no hole,
* samples lie between ``r`` and ``2r`` in each of :data:`SECTORS` sectors round it in their
  best-fitting plane, and within :data:`FLAT` ``·r`` of a quadric over that plane: one sheet
  goes on all round it (two small parts side by side have nothing round them; two sheets facing
  each other are no quadric's graph),
* the group's closest points lie across it in that surface (:data:`TANGENT`; two sheets
  facing each other have theirs along its normal).

Curves are not judged: a gap in a curve is the curve's end (a C-shaped cloud's gap), no hole.
Two ends of a curve closer together than the tubes are warned about instead
(:func:`warn_close_ends`), whether or not the facing test found pairs between them.
"""

from __future__ import annotations

import warnings
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from .._warn import user_stacklevel
from ._mesh_holes import WARN_SHARE

#: Pairs within this many of their widest gap of a group's first pair join that group.
GROUP = 2.0
#: The sectors round a hole that must each hold samples of the surface around it.
SECTORS = 8
#: The samples around a hole lie within this share of the ring's inner radius of a quadric (two
#: sheets facing each other across the gap lie half the gap off any one).
FLAT = 0.25
#: ... and the pairs' closest points lie across the hole: their difference makes an angle with
#: the surface's normal whose cosine is below this (two sheets facing each other: about 1).
TANGENT = 0.5
#: ... and no sample lies nearer the middle of its rim samples than this share of their median
#: distance from it.
EMPTY = 0.3
#: A curve's ends count as two when more than this many of their spacings apart (an end of a
#: curve may show as two rim samples side by side).
DISTINCT_ENDS = 4.0
#: Two ends of a curve closer than this many grid spacings are warned about: the cuts kept a
#: C-shaped curve's ends apart at 4.2 and 4.8 spacings, not at 3.1 and 3.2 (its far end 0.32 for
#: 3.1 the way round).
END_GAP = 4.0
#: A curve with more rim samples than this (a noisy one) has its ends not compared.
MAX_ENDS = 200
#: At most this many groups are judged (the rest stay gaps): each reads every sample once.
MAX_GROUPS = 200


def _groups(mid: np.ndarray, gap: np.ndarray) -> List[np.ndarray]:
    """The pairs (midpoints ``mid``, gaps ``gap``) in groups: each group the pairs within
    :data:`GROUP` times the widest gap of its first (widest-first) pair."""
    left = np.argsort(-gap, kind="stable")
    groups: List[np.ndarray] = []
    while left.size and len(groups) < MAX_GROUPS:
        lead = left[0]
        near = np.linalg.norm(mid[left] - mid[lead], axis=1) <= GROUP * gap[lead]
        groups.append(left[near])
        left = left[~near]
    return groups


def _judge(
    cloud: Any, centre: np.ndarray, width: float, h: float, nodes: Tuple[np.ndarray, np.ndarray]
) -> Optional[Tuple[float, float]]:
    """Whether a group of pairs at ``centre`` with widest gap ``width`` (their nodes' points
    ``nodes``) lies over a small hole (module notes): then its width and detour, else None."""
    r = width + 2.0 * h
    rim = cloud.points[cloud.rim]
    d_rim = np.linalg.norm(rim - centre, axis=1)
    on = rim[d_rim <= r]
    if len(on) < 3 or np.any((d_rim > r) & (d_rim <= 2.0 * r)):
        return None
    pts = cloud.points
    d = np.linalg.norm(pts - centre, axis=1)
    # the hole is empty: no sample near the middle of its rim (a separate part lying over it, a
    # plug or a coin over a plate's hole, has its own rim there and its samples in the middle)
    middle = on.mean(axis=0)
    if np.min(np.linalg.norm(pts[d <= r] - middle, axis=1)) < EMPTY * np.median(np.linalg.norm(on - middle, axis=1)):
        return None
    ring = pts[(d > r) & (d <= 2.0 * r)]
    if len(ring) < 3 * SECTORS:
        return None
    c = ring.mean(axis=0)
    _, _, vt = np.linalg.svd(ring - c, full_matrices=False)
    flat = (ring - centre) @ vt[:2].T
    # the ring's height over its plane against a quadric in the plane's coordinates
    u, v = flat[:, 0] / r, flat[:, 1] / r
    basis = np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], axis=1)
    height = (ring - c) @ vt[2]
    coef, *_ = np.linalg.lstsq(basis, height, rcond=None)
    if np.quantile(np.abs(height - basis @ coef), 0.9) > FLAT * r:
        return None
    # the pairs' closest points lie across the hole, in the surface (two sheets': along its normal)
    normal = vt[2] - (coef[1] * vt[0] + coef[2] * vt[1]) / r
    across = cloud._closest(nodes[1]) - cloud._closest(nodes[0])
    if not np.all(np.isfinite(across)):
        return None
    length = np.linalg.norm(across, axis=1)
    wide = length > 0.25 * width
    # (feet found again may fall together where the band's, found from a neighbour's, did not: the
    # sphere's hole at N = 61 above, 0.013 apart for a gap of 0.096; such pairs are not judged)
    if np.any(np.abs(across[wide] @ normal) > TANGENT * length[wide] * np.linalg.norm(normal)):
        return None
    sector = ((np.arctan2(flat[:, 1], flat[:, 0]) + np.pi) / (2 * np.pi) * SECTORS).astype(np.int64) % SECTORS
    if np.unique(sector).size < SECTORS:
        return None
    extent = float(np.max(np.linalg.norm(on[:, None] - on[None], axis=2)))
    # a round hole's detour, (π/2 − 1)·width, or an elongated one's length less its width
    return width, max((np.pi / 2 - 1) * width, extent - width)


def _holes(cloud: Any, grid: Any, first: np.ndarray, second: np.ndarray, gap: np.ndarray) -> Tuple[np.ndarray, list]:
    """Per pair whether it lies over a small hole, and per such hole (width, detour, centre)."""
    over = np.zeros(len(first), bool)
    found: list = []
    if grid.ndim != 3 or len(cloud.rim) == 0 or len(first) == 0:
        return over, found
    a, b = grid.node_points(first), grid.node_points(second)
    mid = 0.5 * (a + b)
    for group in _groups(mid, np.asarray(gap, float)):
        centre = mid[group].mean(axis=0)
        judged = _judge(cloud, centre, float(np.max(gap[group])), grid.spacing, (a[group], b[group]))
        if judged is not None:
            over[group] = True
            found.append((judged[0], judged[1], centre))
    return over, found


def pairs_over_holes(cloud: Any, grid: Any, first: np.ndarray, second: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """Which facing pairs (linear indices ``first``, ``second`` on ``grid``, their gaps ``gap``)
    lie over a small hole of the cloud: ``PointCloudSurface._pairs_over_holes``, read by the
    tube's preparation (``_prepare``), which leaves them out of the facing pairs (no warning, no
    cut, not in ``sol.stats.facing_pairs``). The holes found are kept for :func:`bridged_holes`."""
    over, found = _holes(cloud, grid, first, second, gap)
    cloud.__dict__["_last_holes"] = (grid, first[over], second[over], found)
    return over


def bridged_holes(
    cloud: Any, h: float, outer: float, grid: Any = None, pairs: Optional[Tuple[np.ndarray, ...]] = None
) -> Optional[dict]:
    """The holes over which the facing pairs ``pairs`` (linear indices, indices, gaps: those of
    :func:`pairs_over_holes`) lie, as ``sol.stats.bridged_holes`` (the keys of
    ``_mesh_holes.bridged``), warned when the largest detour is over ``WARN_SHARE`` of the
    cloud's size: ``PointCloudSurface._bridged_holes``. None when there are none. Unlike a
    mesh's, only the holes over which the band's facing test found pairs are listed."""
    if pairs is None or grid is None or len(pairs[0]) == 0:
        return None
    last = cloud.__dict__.get("_last_holes")
    if last is not None and last[0] == grid and np.array_equal(last[1], pairs[0]) and np.array_equal(last[2], pairs[1]):
        found = last[3]  # (the judgement of the pairs just made: the same groups)
    else:
        _, found = _holes(cloud, grid, *pairs)
    if not found:
        return None
    width, detour, centre = (np.asarray([f[i] for f in found]) for i in range(3))
    k = int(np.argmax(detour))
    p = cloud.points
    info: Dict[str, Any] = {
        "count": len(found),
        "widest": float(np.max(width)),
        "reach": float(2.0 * outer * h),
        "detour": float(detour[k]),
        "where": tuple(round(float(c), 6) for c in centre[k]),
        "width": float(width[k]),
        "size": float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))),
    }
    if info["detour"] > WARN_SHARE * info["size"]:
        warnings.warn(
            f"the point cloud has {info['count']} hole(s) narrower than its band ({info['reach']:.3g} across at this "
            f"grid; the widest {info['widest']:.3g}): the band bridges them, and a distance reached across one can be "
            f"that of the surface with the hole filled (in part where the hole is over about 1.5 spacings wide), up to about {info['detour']:.3g} ({info['detour'] / info['size']:.0%} "
            f"of the cloud's size) shorter than the way round the hole near {info['where']}. sol.stats.bridged_holes has "
            f"them; a grid spacing below {info['width'] / (2.0 * outer):.3g} (now {h:.3g}) keeps that one open, or "
            "sample the missing surface where it is a gap in a scan",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return info


def warn_close_ends(cloud: Any, h: float, inner: float) -> None:
    """On a curve (a 2D cloud): a warning when two of its ends (rim samples, not neighbours of each
    other) lie closer together than :data:`END_GAP` grid spacings ``h``: the band joins them, and
    the front can cross the gap between them. Below about two spacings the facing test finds no
    node pair across such a gap, and a C-shaped curve of 4,000 samples with a gap of 1–2 spacings
    was solved as closed, its far end 99% short, unwarned. ``PointCloudSurface._warn_thin_parts``,
    read by the tube's preparation (the mesh's hook of the same name warns of its thin parts)."""
    if cloud.ndim != 2 or not 1 < len(cloud.rim) <= MAX_ENDS:
        return
    p = cloud.points
    ends = p[cloud.rim]
    # each end's spacing: the distance to its nearest other sample (one end at a time: no
    # ends × samples array)
    spacing = np.empty(len(ends))
    for k, (end, at) in enumerate(zip(ends, cloud.rim)):
        dist = np.linalg.norm(p - end, axis=1)
        dist[at] = np.inf
        spacing[k] = dist.min()
    d = np.linalg.norm(ends[:, None] - ends[None], axis=2)
    apart = d > DISTINCT_ENDS * np.maximum(spacing[:, None], spacing[None])
    reach = END_GAP * h
    close = np.triu(apart & (d < reach), 1)
    if not close.any():
        return
    i, j = np.unravel_index(int(np.argmin(np.where(close, d, np.inf))), d.shape)
    where = tuple(round(float(c), 6) for c in 0.5 * (ends[i] + ends[j]))
    warnings.warn(
        f"two ends of the curve lie {d[i, j]:.3g} apart near {where}, {d[i, j] / h:.1f} grid spacings: the band joins "
        "them and the front can cross the gap, so distances reached across it can come out short, by up to the length "
        f"of the curve between the two ends. A grid spacing below {d[i, j] / END_GAP:.3g} (now {h:.3g}) keeps them "
        "apart; if the curve is closed there, sample the gap",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
