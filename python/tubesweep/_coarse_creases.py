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
within that reach (:data:`TURN_CONCAVE` beside a concave crease), beside a face (a node there
turning by less than :data:`FACE`) and away from a thin part (no node there whose normal reverses
within one node more), is a crease node. A smooth surface turns by about 2√3/ρ radians over that
reach (ρ its radius of curvature in spacings, plus the staircase's 8–12°): 20–28° on a ball of
20–10 voxels in radius, 58° on a torus's tube of 5. A convex part whose curvature radius is below
about four spacings (a concave one, about three: a gyroid-like φ's necks at N = 41), which the
tube does not resolve either, reads as a crease where it lies beside flatter faces (a thin
ellipsoid's rim) and as none where it turns so all over (a small sphere). The smoothing rounds a crease, so the turn
read is below the faces' angle: two fused balls whose faces meet at 90° read 45–55°, at 106°
60–71°, at 122° 75–84° (:data:`READ_SHARE`; ``tests/test_coarse_creases.py``). Those 90° are as
much as a smooth convex part turns (a torus's tube five voxels in radius: 52–58°), but the smooth
parts read above :data:`TURN_CONCAVE` were convex or small (a smooth crotch of a tree of tubes), so
a concave crease (the smoothed φ's Laplacian not positive, as between fused parts) of
:data:`MIN_CONCAVE_NODES` nodes or more is one from that lower turn (below it, two balls fused at
80° still go unsaid: ``benches/experiments/mask_creases.py``).

Used for the paper's tube (``order=1``) and the first-order fallback of ``"auto"`` on a
re-distanced φ, and for second order's report on one where nodes ran the first-order update for
an unresolved curvature (a crease that a smoothing rounded: :func:`widened_for_order2`). The
per-node work is the core's (``tubesweep_core::second_order::smoothed_creases``, in parallel):
O(band) for the smoothing, the reach's (2·REACH + 1)^d − 1 steps along the neighbour table for
the nodes next to the surface (17 ms for two fused balls' mask at N = 121 on two cores, whose
solve takes 0.5 s; 118 ms in numpy before).
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Tuple

import numpy as np

from ._creases import REVERSED, per_inner_width
from ._creases import creases_of_redistanced as fine_creases_of_redistanced

__all__ = [
    "smoothed_turning",
    "coarse_creases",
    "paper_creases",
    "creases_of_redistanced",
    "passes_for",
    "faces_of_turn",
    "widened",
    "widened_for_order2",
]

#: Passes of the 3-node mean along each axis before the normals are read.
PASSES = 2
#: How far (nodes along each axis) a node's normal is compared with others'.
REACH = 2
#: A turn of the smoothed normal (degrees) within :data:`REACH` beyond which a node is a crease node.
TURN = 60.0
#: The same beside a concave crease (the smoothed φ's Laplacian not positive at the node), with
#: :data:`MIN_CONCAVE_NODES` at least where none turns by more than :data:`TURN`. The smooth parts
#: read above it that are large were convex (voxel masks, ``smooth=1`` and φ re-distanced,
#: N = 41–81: a torus's tube of five voxels 43–58°, an ellipsoid's rim of two to three 47–50°, a
#: capsule of six 41–44°, a thin ellipsoid's rim; noisy spheres and tori; a 2D star); smooth
#: concave necks read nothing above 38° (two balls at 90° joined by a smooth minimum blending over
#: 4–12 voxels; over 2 voxels, 40°) unless tighter than about two spacings (a peanut's neck, 43–47°
#: at 60–120 nodes, 2.6–2.8Δx early beyond it with ``"auto"`` against 1.4Δx elsewhere: a crease at
#: that grid); two balls fused at 90° read 45–55°, at 80° 39–43°. For ``order=1`` and
#: the first-order fallback of ``"auto"``, where those balls came out 2.2–4.5Δx early; second
#: order's report (:func:`widened_for_order2`) keeps :data:`TURN` for them (0.9–2.2Δx early there,
#: and a gyroid-like φ's smooth concave necks at N = 41 read 48°, their values within 0.4Δx of a
#: finer solve's: a scratch run).
TURN_CONCAVE = 40.0
#: A crease read from :data:`TURN_CONCAVE` alone holds this many nodes at least: the crotch of a
#: tree of tubes blended by a smooth minimum reads 43–50° at 1–18 nodes, where the answer beyond it
#: is no earlier than elsewhere (a helper's review, scratch runs: 3.7–4.7Δx said with ``"auto"``, N = 61–81), and
#: noise of half a spacing on a torus made one node of 41°; the creases above hold 60–360.
MIN_CONCAVE_NODES = 30
#: A crease node lies beside a face, a node within :data:`REACH` whose normal turns by less than
#: this (degrees): faces of balls ten voxels in radius keep nodes below it beside their crease; a
#: capsule four voxels in radius, whose nodes turn by 29–61° with their place in the grid, had
#: some below 35° beside ones over 60° and read as creased (a helper's review).
FACE = 25.0
#: A normal that turns by more than this (degrees) within :data:`REACH` + 1 nodes reverses: two sides
#: of a thin part, no crease.
SHEETS = 120.0
#: The crease nodes' turn that stands for the faces' angle: this percentile of them.
TURN_PERCENTILE = 90.0
#: Nodes this close to the surface (spacings) carry the normals that are compared.
NEAR = 0.75


def smoothed_turning(grid: Any, band: Any, phi: np.ndarray, passes: int = PASSES) -> Tuple[np.ndarray, np.ndarray]:
    """The band positions of the nodes within :data:`NEAR` spacings of φ's zero level set (``phi``:
    one value per band node) where the smoothed φ has a normal, and at each the largest angle
    (degrees) between its normal and those of such nodes up to :data:`REACH` nodes away along each
    axis; ``passes`` of the smoothing (:func:`passes_for`). In the core
    (``tubesweep_core::second_order::smoothed_creases``)."""
    at, turning = band.smoothed_turning(_values(phi), float(grid.spacing), int(passes), REACH, NEAR)
    return np.asarray(at), np.asarray(turning)


def coarse_creases(
    grid: Any, band: Any, phi: np.ndarray, passes: int = PASSES, turn_concave: float = TURN_CONCAVE
) -> Tuple[int, float, float]:
    """How many nodes next to the surface turn by more than :data:`TURN` within :data:`REACH`
    (:func:`smoothed_turning`; :data:`TURN_CONCAVE` beside a concave crease) beside a face and
    away from a thin part, and their turn in degrees (the :data:`TURN_PERCENTILE` of them), and
    the share of them beside a convex edge (0, 0.0, 0.0 when there is none). Where some turn by
    more than :data:`TURN`, only those are counted (the flanks of a sharp concave crease read
    lower); where none does, at least :data:`MIN_CONCAVE_NODES`. Beside a face: with a node
    within that reach that turns by less than :data:`FACE` (a part whose whole surface turns more is
    small, its curvature unresolved rather than creased: a sphere shrinking to nothing, 1.4–4
    spacings in radius, reads 60–180° all over). Away from a thin part: no node within that reach
    whose normal reverses (turns by more than :data:`SHEETS`) within one node more, as across a part
    thinner than about six spacings, whose two sides are not a crease (a dumbbell's neck 2.4
    spacings in radius read as one at 90°; creases of up to 140° turn by at most 104° within three
    nodes). The percentile, not the largest: a cube's corners, where three faces meet, turn more
    than its edges, and a few nodes read its 90° edges as 124–150° (a helper's review). In the core
    (``tubesweep_core::second_order::smoothed_creases``, O(band))."""
    nodes, turn, convex = band.smoothed_creases(
        _values(phi),
        float(grid.spacing),
        int(passes),
        REACH,
        NEAR,
        TURN,
        turn_concave,
        MIN_CONCAVE_NODES,
        FACE,
        SHEETS,
        TURN_PERCENTILE,
    )
    return int(nodes), float(turn), float(convex)


def _values(phi: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(phi, dtype=np.float64)


#: The smoothing reads a crease whose faces meet at θ as a turn of about this share of θ or more:
#: two balls fused at 106°, 122° and 140° as voxel masks or noisy φ re-distanced (0.3Δx), N = 41–81,
#: read 60–71°, 62–89° and 63–104° (0.57–0.74 θ); a cube's mask, its edges at 90°, 65–82° at its
#: corners (``tests/test_coarse_creases.py``).
READ_SHARE = 0.6

#: Below :data:`TURN` (only concave creases read there) the share falls to this at
#: :data:`TURN_CONCAVE`: two balls fused at 80°, 90° and 100° read 39–43°, 45–55° and 46–60° (shares
#: 0.49–0.54, 0.50–0.61, 0.46–0.60; masks, ``smooth=1``, N = 41–81), so a turn read there is taken
#: for the faces' angle :func:`faces_of_turn` gives, 80–100°.
READ_SHARE_LOW = 0.5

#: The same beside convex edges (most crease nodes where the smoothed φ's Laplacian is positive),
#: which the smoothing reads higher: a cube's 90° edges as 66–82° (mask, ``smooth=1``, noisy,
#: re-distanced, N = 41–81), a closed cylinder's rims as 77° (a helper's review: read at
#: :data:`READ_SHARE`, 124–128°, and a figure 3–10 times the error measured).
READ_SHARE_CONVEX = 0.75


def faces_of_turn(turn: float, convex: bool) -> float:
    """The faces' angle (degrees) that a smoothed turn of ``turn`` degrees stands for: the turn over
    :data:`READ_SHARE_CONVEX` beside convex edges; beside a concave crease over :data:`READ_SHARE`
    from :data:`TURN` up, and below it over a share that falls linearly to :data:`READ_SHARE_LOW`
    at :data:`TURN_CONCAVE` + 10° and stays there (the turns between 50° and 60° all stand for
    100°); at most ``_creases.REVERSED``."""
    if convex:
        share = READ_SHARE_CONVEX
    else:
        low_end = TURN_CONCAVE + 10.0
        share = READ_SHARE_LOW + (READ_SHARE - READ_SHARE_LOW) * float(
            np.clip((turn - low_end) / (TURN - low_end), 0.0, 1.0)
        )
    return min(turn / share, REVERSED)


def paper_creases(
    grid: Any, band: Any, phi: np.ndarray, passes: int = PASSES, turn_concave: float = TURN_CONCAVE
) -> Optional[Dict[str, Any]]:
    """The creases that :func:`coarse_creases` finds, as ``sol.stats.creases`` (see
    ``_creases.creases_of_redistanced``): ``angle_degrees`` and ``faces_angle_degrees`` the
    faces' angle read back from the smoothed turn (its :data:`READ_SHARE`, or
    :data:`READ_SHARE_CONVEX` beside convex edges, at most
    ``_creases.REVERSED``), ``smoothed_turn_degrees`` the turn itself; None where there are none."""
    nodes, turn, convex = coarse_creases(grid, band, phi, passes, turn_concave)
    if not nodes:
        return None
    faces = faces_of_turn(turn, convex > 0.5)
    return {
        "nodes": nodes,
        "angle_degrees": faces,
        "faces_angle_degrees": faces,
        "shortcut_per_inner_width": per_inner_width(faces),
        "redistanced": True,
        "smoothed_turn_degrees": turn,
        "concave": convex <= 0.5,
    }


def creases_of_redistanced(
    grid: Any,
    band: Any,
    roles: np.ndarray,
    phi: np.ndarray,
    direction: np.ndarray,
    outer_width: float,
    surface: Any,
) -> Dict[str, Any]:
    """The paper's tube's creases on a re-distanced φ (``surface``'s): the second-order geometry's
    test (``_creases.creases_of_redistanced``), widened where this module's test through a
    smoothing reads a rounded crease (:func:`widened`), and where the first finds none or stands
    down on a φ it finds noisy (a voxel mask's staircase, noise), this module's (a voxel mask
    smoothed over a voxel, two balls fused at 122–140°, N = 41–61: 7.3–10Δx early at worst with
    ``order=1`` and no warning or 5.4Δx said)."""
    found, noisy, between = fine_creases_of_redistanced(band, roles, phi, direction, grid.spacing, outer_width)
    coarse = paper_creases(grid, band, phi, passes_for(surface))
    if coarse is None:
        return found
    if noisy or not found["nodes"]:
        return coarse
    merged = widened(found, coarse, between)
    # (the paper's tube's report gives the faces' angle as its angle, and its shortcut from it)
    faces = float(merged["faces_angle_degrees"])
    return {**merged, "angle_degrees": faces, "shortcut_per_inner_width": per_inner_width(faces)}


def widened(found: Dict[str, Any], coarse: Dict[str, Any], between: Optional[float] = None) -> Dict[str, Any]:
    """A crease report of the neighbours' test (``found``, with crease nodes) widened by the one
    through a smoothing (``coarse``, :func:`paper_creases`) where the crease is rounded: a sharp
    crease turns the normal between neighbours by more than the smoothed normal turns within two
    spacings (two balls fused at 122°, re-distanced from their distance: 118° against 82°); a
    rounded one by less, only about half its angle between neighbours (the same balls as a voxel
    mask with ``smooth=1``: 48°), and its faces' angle is the smoothing's
    (``smoothed_turn_degrees`` says so). ``between``: the turn between neighbours, where
    ``found["angle_degrees"]`` is not it (the paper's tube's report)."""
    turn = coarse["smoothed_turn_degrees"]
    if turn <= (float(found["angle_degrees"]) if between is None else between):
        return found
    faces = max(float(found["faces_angle_degrees"]), coarse["faces_angle_degrees"])
    return {
        **found,
        "faces_angle_degrees": faces,
        "shortcut_per_inner_width": per_inner_width(faces),
        "smoothed_turn_degrees": turn,
        "concave": coarse["concave"],
    }


def passes_for(surface: Any) -> int:
    """The smoothing passes that take out ``surface``'s kinks at the grid's scale: one on a voxel
    mask smoothed over a voxel or more (``from_mask(smooth=σ)``, whose steps are gone but whose
    creases the user's smoothing rounded already: two passes more read two balls fused at 122° at
    62–80° where one reads 69–76°, and at 106° nothing), else :data:`PASSES`."""
    smoothing = getattr(surface, "_mask_smoothing", None)
    return 1 if smoothing is not None and smoothing >= 1.0 else PASSES


def widened_for_order2(st: Dict[str, Any], tube: Any) -> None:
    """Second order's crease report (``st["creases"]``, the native report's, for
    ``sol.stats.order2``) on a re-distanced φ, read through a smoothing as well where nodes ran
    the first-order update for an unresolved curvature. A crease that a smoothing rounded (a voxel
    mask with ``smooth=1``) turns by about half its angle between neighbours, which the crease test
    reads: two balls fused at 140°, N = 61, 75° read, the warning's 2.5Δx against 3.3Δx measured;
    at N = 41 the test found none, and the front came out 4.6Δx (122°) and 6.0Δx (140°) early with
    no warning (``tests/test_coarse_creases.py``). Where the smoothed normal turns more, the faces'
    angle read back from it widens the report (:func:`widened`); where only the
    smoothing finds creases, they are reported with ``smoothing_only`` (the inner tube not thinned
    at them, the warning's figure is the paper's tube's). Computed once per tube."""
    surface = tube.surface
    if not getattr(surface, "redistance", False) or not st["first_order_reasons"]["curvature"]:
        return
    if tube.smoothed_creases is None:
        # (concave creases from TURN too: the nodes there ran first order already, two balls fused at
        # 90–106° came out 0.9–2.2Δx early, and a gyroid-like φ's concave necks at N = 41, smooth, read 48°)
        tube.smoothed_creases = (paper_creases(tube.grid, tube.band, tube.phi, passes_for(surface), TURN),)
    coarse = tube.smoothed_creases[0]
    if coarse is None:
        return
    found = st.get("creases")
    if found and found.get("nodes"):
        st["creases"] = widened(found, coarse)
    else:
        st["creases"] = {**{k: v for k, v in coarse.items() if k != "redistanced"}, "smoothing_only": True}
