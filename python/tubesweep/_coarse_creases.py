"""Creases of a re-distanced φ read through a smoothing: the test for the level sets whose own
staircase or noise hides their creases from the crease tests of :mod:`tubesweep._creases`.

A voxel mask's zero level set (``LevelSet.from_mask``) is a staircase whose normals turn by up to
45° between neighbouring nodes everywhere, and a noisy φ re-distanced kinks at the grid's scale:
the crease tests, which compare the normals of neighbours (``creases_of_redistanced``, the
second-order geometry's), stand down on such a φ, and a real crease went unsaid. Two balls of radius
0.5 fused at 122° and given as a voxel mask came out 4–6 spacings early beyond their crease at
N = 41–81 with no warning.

Here φ is smoothed first, over a few nodes of the band (:data:`PASSES` passes of the 3-node mean
along each axis, about a Gaussian of 1.15 spacings), which takes out the staircase but not a crease:
the normals of the smoothed φ next to the surface are compared with those of the nodes up to
:data:`REACH` nodes away along each axis, and a node whose normal turns by more than :data:`TURN`
within that reach, beside a face (a node there turning by less than :data:`FACE`), is a crease
node. A smooth surface turns by about 2√3/ρ radians over that reach (ρ its radius of curvature in
spacings, plus the staircase's 8–12°): 20–28° on a ball of 20–10 voxels in radius, 58° on a
torus's tube of 5. A part whose curvature radius is below about four spacings, which the tube does
not resolve either, reads as a crease where it lies beside flatter faces (a thin ellipsoid's rim)
and as none where it turns so all over (a small sphere). The smoothing rounds a crease, so the turn
read is below the faces' angle: two fused balls whose faces meet at 90° read below :data:`TURN`
(their shortcut is about the first-order scheme's own error), at 106° 60–71°, at 122° 75–84°
(:data:`READ_SHARE`; ``tests/test_coarse_creases.py``). O(band): a few gathers over the band, and
the reach's (2·REACH + 1)^d − 1 steps along the neighbour table for the nodes next to the surface
only (20–50 ms at N = 81).
"""

from __future__ import annotations

import itertools
from typing import Any, Dict, Iterator, Optional, Tuple

import numpy as np

from ._creases import REVERSED
from ._creases import creases_of_redistanced as fine_creases_of_redistanced

__all__ = ["smoothed_turning", "coarse_creases", "paper_creases", "creases_of_redistanced"]

#: Passes of the 3-node mean along each axis before the normals are read.
PASSES = 2
#: How far (nodes along each axis) a node's normal is compared with others'.
REACH = 2
#: A turn of the smoothed normal (degrees) within :data:`REACH` beyond which a node is a crease node.
TURN = 60.0
#: A crease node lies beside a face, a node within :data:`REACH` whose normal turns by less than
#: this (degrees): a ball ten voxels in radius turns by 28°, one of four by 50° or more.
FACE = 35.0
#: Nodes this close to the surface (spacings) carry the normals that are compared.
NEAR = 0.75


def smoothed_turning(grid: Any, band: Any, phi: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The band positions of the nodes within :data:`NEAR` spacings of φ's zero level set (``phi``:
    one value per band node) where the smoothed φ has a
    normal, and at each the largest angle (degrees) between its normal and those of such nodes up to
    :data:`REACH` nodes away along each axis."""
    return _turning(grid, np.asarray(band.neighbours()), phi)


def _turning(grid: Any, table: np.ndarray, phi: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """:func:`smoothed_turning` on the band's neighbour table ``table``: (K, d, 2), the minus and
    plus neighbours' band positions, K where absent."""
    h = float(grid.spacing)
    count, ndim = table.shape[0], table.shape[1]
    # the mean over the neighbours in the band (fewer at its edge, far from the surface)
    smoothed = np.asarray(phi, dtype=np.float64).copy()
    for _ in range(PASSES):
        for k in range(ndim):
            minus, plus = table[:, k, 0], table[:, k, 1]
            padded = np.append(smoothed, 0.0)
            smoothed = (padded[minus] + smoothed + padded[plus]) / (1.0 + (minus < count) + (plus < count))
    padded = np.append(smoothed, np.nan)
    at = np.flatnonzero(np.abs(np.asarray(phi, dtype=np.float64)) <= NEAR * h)
    gradient = np.stack([padded[table[at, k, 1]] - padded[table[at, k, 0]] for k in range(ndim)], axis=1)
    norm = np.linalg.norm(gradient, axis=1)
    has = np.isfinite(norm) & (norm > 0)
    at, gradient, norm = at[has], gradient[has], norm[has]
    if at.size == 0:
        return at, np.zeros(0)
    normal = gradient / norm[:, None]
    slot = np.full(count + 1, -1, dtype=np.int32)  # each band node's row of `normal`, -1 for none
    slot[at] = np.arange(at.size, dtype=np.int32)
    closest = np.ones(at.size)  # the smallest cosine of the turn
    for pos in _within_reach(table, at):
        other = slot[pos]
        pair = np.flatnonzero(other >= 0)
        cosine = np.einsum("ij,ij->i", normal[pair], normal[other[pair]])
        closest[pair] = np.minimum(closest[pair], cosine)  # (each node once per offset)
    return at, np.degrees(np.arccos(np.clip(closest, -1.0, 1.0)))


def _within_reach(table: np.ndarray, at: np.ndarray) -> Iterator[np.ndarray]:
    """For each offset of at most :data:`REACH` nodes along each axis (but none), the band position
    of the node that far from each of the nodes ``at`` (``len(table)`` where it is not in the band),
    walked one axis step at a time along the neighbour table ``table`` (the nodes on the way lie
    within REACH·√d spacings of the surface, inside the tube)."""
    count, ndim = table.shape[0], table.shape[1]
    walked = {(0,) * ndim: at}
    for offset in sorted(itertools.product(range(-REACH, REACH + 1), repeat=ndim), key=lambda o: sum(map(abs, o))):
        if not any(offset):
            continue
        k = next(i for i in range(ndim) if offset[i])
        back = tuple((v - 1 if v > 0 else v + 1) if i == k else v for i, v in enumerate(offset))
        start = walked[back]
        pos = np.full(at.size, count)
        inside = start < count
        pos[inside] = table[start[inside], k, 1 if offset[k] > 0 else 0]
        walked[offset] = pos
        yield pos


def coarse_creases(grid: Any, band: Any, phi: np.ndarray) -> Tuple[int, float]:
    """How many nodes next to the surface turn by more than :data:`TURN` within :data:`REACH`
    (:func:`smoothed_turning`) beside a face: with a node within that reach that turns by less than
    :data:`FACE`. A part whose whole surface turns more is small, its curvature unresolved rather
    than creased (a sphere shrinking to nothing, 1.4–4 spacings in radius, reads 60–180° all over).
    And the largest such turn in degrees (0, 0.0 when there is none)."""
    table = np.asarray(band.neighbours())
    at, turning = _turning(grid, table, phi)
    crease = turning > TURN
    if not np.any(crease):
        return 0, 0.0
    face = np.zeros(len(table) + 1, dtype=bool)
    face[at[turning < FACE]] = True
    beside = np.zeros(int(np.count_nonzero(crease)), dtype=bool)
    for pos in _within_reach(table, at[crease]):
        beside |= face[pos]
    if not np.any(beside):
        return 0, 0.0
    return int(np.count_nonzero(beside)), float(turning[crease][beside].max())


#: The smoothing reads a crease whose faces meet at θ as a turn of about this share of θ or more:
#: two balls fused at 106°, 122° and 140° as voxel masks or noisy φ re-distanced (0.3Δx), N = 41–81,
#: read 60–71°, 62–89° and 63–104° (0.57–0.74 θ); a cube's mask, its edges at 90°, 65–82° at its
#: corners (``tests/test_coarse_creases.py``).
READ_SHARE = 0.6


def paper_creases(grid: Any, band: Any, phi: np.ndarray) -> Optional[Dict[str, Any]]:
    """The creases that :func:`coarse_creases` finds, as ``sol.stats.creases`` (see
    ``_creases.creases_of_redistanced``): ``angle_degrees`` and ``faces_angle_degrees`` the
    faces' angle read back from the smoothed turn (its :data:`READ_SHARE`, at most
    ``_creases.REVERSED``), ``smoothed_turn_degrees`` the turn itself; None where there are none."""
    nodes, turn = coarse_creases(grid, band, phi)
    if not nodes:
        return None
    faces = min(turn / READ_SHARE, REVERSED)
    return {
        "nodes": nodes,
        "angle_degrees": faces,
        "faces_angle_degrees": faces,
        "shortcut_per_inner_width": 2 * float(np.tan(np.radians(faces) / 2)),
        "redistanced": True,
        "smoothed_turn_degrees": turn,
    }


def creases_of_redistanced(
    grid: Any, band: Any, roles: np.ndarray, phi: np.ndarray, direction: np.ndarray, outer_width: float
) -> Dict[str, Any]:
    """The paper's tube's creases on a re-distanced φ: the second-order geometry's test
    (``_creases.creases_of_redistanced``), or where it stands down on a φ it finds noisy (a voxel
    mask's staircase, noise) this module's test through a smoothing (:func:`paper_creases`)."""
    found, noisy = fine_creases_of_redistanced(band, roles, phi, direction, grid.spacing, outer_width)
    return (paper_creases(grid, band, phi) or found) if noisy else found
