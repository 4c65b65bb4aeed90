"""Creases and corners of a level set: the shortcut the tube allows across them, said in a
warning with its size (crates/tubesweep-core/src/second_order/creases.rs), and the inner-tube
nodes there that become extension nodes (crates/tubesweep-core/src/band/crease_ridges.rs).

In the tube the paper's equation lets the front move along the normal for free, so where the
tubes of a crease's two faces overlap a path runs up one face's normal and down the other's: the
front arrives early by about ``2·inner·Δx·tan(θ/2)`` per crease it crosses (θ the angle between
the faces' normals) in the paper's tube (``order=1``): the cube ``max|x| − 0.5`` at N = 81, bottom
centre to top centre, 1.78 instead of 2.0. With ``order=2`` and ``"auto"`` the inner tube is
thinned there (its nodes on the overlap side beyond half a spacing take their values from their
closest points), which leaves about one spacing per crease crossed
(:data:`THINNED_SHORTCUT`; ``benches/experiments/creases.py``). Either is first order in Δx;
rounding the edges over more than the tube's width (outer·Δx) removes it; rounded over less, they
act as creases (``_fallback.UNRESOLVED_SHORTCUT``).
"""

from __future__ import annotations

import re
import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from ._warn import user_stacklevel

_CONVEX_CREASES = re.compile(r"convex creases or corners")
_PER_INNER_WIDTH = re.compile(r"cut the corner by about ([0-9.]+)·inner·Δx")

#: How early, in grid spacings, a front arrives per crease crossed once the inner tube is thinned
#: there (``order=2`` and ``"auto"``): the cube max|x| − 0.5 from the bottom centre to the top
#: centre, 0.56Δx per edge at N = 41 and 81 (nodes on its faces), 1.24Δx and 1.26Δx at N = 40 and
#: 80 (a quarter spacing off them), 0.34Δx at N = 121 (second order); turned at random, 0.9Δx to
#: 1.3Δx at N = 41–81 (2.9Δx to 3.5Δx at order=1). ``benches/experiments/creases.py``.
THINNED_SHORTCUT = 1.5

#: The same for a re-distanced φ (a voxel mask, ``redistance=True``), whose zero level set between
#: the nodes adds its own error at the edge: a closed cylinder's two rims 1.2–1.75Δx each
#: re-distanced, 2.05–2.1Δx as a voxel mask, N = 41–81; a cube with a = 0.413 re-distanced at
#: N = 61, 1.9Δx per edge (review scratch ``/tmp/reviewA``).
THINNED_SHORTCUT_REDISTANCED = 2.5

#: In the paper's tube (``order=1``) of a re-distanced φ a front comes out up to this many times
#: 2·tan(θ/2)·inner·Δx early per crease (the zero set between the nodes adds its own error): two
#: spheres of radius 0.5, centres 0.8 apart (faces at 106°), joined by min and re-distanced,
#: 1.31, 1.32 and 1.48 times it at the worst point beyond the crease at N = 41, 61, 81
#: (``tests/test_level_set_messages.py``)
PAPER_TUBE_REDISTANCED = 1.5


def thinned_spacings(tube: Any, thinned: bool) -> float:
    """How many spacings a front gains per crease on ``tube`` (a prepared tube) thinned there
    (``thinned``): :data:`THINNED_SHORTCUT`, or :data:`THINNED_SHORTCUT_REDISTANCED` for a
    re-distanced φ; 0 when not thinned."""
    if not thinned:
        return 0.0
    return THINNED_SHORTCUT_REDISTANCED if getattr(tube.surface, "redistance", False) else THINNED_SHORTCUT


#: Beyond this turn of the normal (degrees) a crease's shortcut is not bounded by 2·tan(θ/2)·inner·Δx
#: (the core's ``Creases::shortcut_per_inner_width`` caps θ there too).
REVERSED = 150.0


def per_inner_width(angle: float) -> float:
    """2·tan(θ/2) at the faces' angle θ (degrees), θ capped at :data:`REVERSED` as the core's
    ``Creases::shortcut_per_inner_width``: how early a front arrives per crease, in inner·Δx."""
    return 2 * float(np.tan(np.radians(min(float(angle), REVERSED)) / 2))


def shortcut(per_inner_width: float, inner: float, spacing: float) -> float:
    """How early a front arrives after crossing one crease: ``per_inner_width`` (2·tan(θ/2))
    times the inner tube's half-width ``inner·Δx``."""
    return float(per_inner_width) * float(inner) * float(spacing)


def _per_crease(
    per_inner_width: float, inner: float, spacing: float, thinned: float, *, scaled: bool = True
) -> Tuple[float, str]:
    """How early a front arrives per crease crossed, and how that was reckoned: ``thinned``
    spacings on the tube thinned at the creases (:func:`thinned_spacings`; 0: not thinned), times
    tan(θ/2) where the faces turn by more than 90° (``per_inner_width``: 2·tan(θ/2) at the
    largest turn θ of the normal; two spheres joined by max at 120° or cut by max(d₁, −d₂) at
    124°, re-distanced, N = 41–161: up to 5.4–6.1Δx beyond the crease where 2.5Δx was said, a
    helper's review), else :func:`shortcut`. ``scaled=False``: ``thinned`` spacings alone (where
    the normal reverses, two sheets facing each other, no angle bounds it)."""
    if thinned:
        factor = thinned * (max(1.0, float(per_inner_width) / 2) if scaled else 1.0)
        return factor * float(spacing), f"{factor:.2g}·Δx with the inner tube thinned there"
    return (
        shortcut(per_inner_width, inner, spacing),
        f"2·tan(θ/2)·inner·Δx = {per_inner_width:.3g}·inner·Δx at the largest turn θ, the inner tube not thinned there",
    )


def _early(angle: float, size: float, reckoned: str, thinned: bool = False) -> str:
    """How early a front arrives after a crease whose normal turns by ``angle`` degrees: up to
    ``size`` (``reckoned`` says how), or, beyond :data:`REVERSED`, that much or more as it can
    cross over between two sheets facing each other. ``thinned``: the inner tube is thinned at
    the creases (order 2), where a concave one makes the front late instead."""
    if angle <= REVERSED:
        if not thinned:
            return f"arrives early by up to about {size:.3g} {reckoned}"
        # (early across a concave crease too where the grid meets it at a slant: two spheres
        # joined by min at 75–120°, turned at random, 0.6–2.2Δx early on average, a helper's review)
        return (
            f"arrives early by up to about {size:.3g} {reckoned}, where the tube cuts the crease's corner; across a concave "
            "crease it can instead arrive late, by a fraction of a spacing (two spheres joined by min, the grid "
            "aligned with them: 0.43·Δx on average)"
        )
    return (
        f"arrives early by {size:.3g} or more: the normal reverses there, two sheets face each other across a gap "
        "narrower than the tube, and a front can cross over"
    )


def warn_creases(
    creases: Optional[dict], inner: float, spacing: float, *, thinned: float, redistanced: bool = False
) -> None:
    """A RuntimeWarning when the second-order solve found creases (``sol.stats.order2["creases"]``):
    the shortcut per crease, ``thinned`` spacings where the inner tube was thinned there
    (:func:`thinned_spacings`), else the paper's tube's ``2·tan(θ/2)·inner·Δx`` at the largest angle.
    ``redistanced``: the directions come from φ's closest points (a re-distanced φ), where the
    normal turns between neighbours by the faces' angle; otherwise from central differences of φ,
    which average the faces' normals next to a crease (:func:`faces_angle`). Creases read through a
    smoothing (``_coarse_creases.widened_for_order2``: ``smoothed_turn_degrees``) are sized by the
    faces' angle read back from it, and where only the smoothing found them (``smoothing_only``)
    the inner tube was not thinned at them."""
    if not creases or not creases.get("nodes"):
        return
    if creases.get("smoothing_only"):
        _warn_smoothed_only(creases, inner, spacing)
        return
    angle = float(creases["angle_degrees"])
    faces = faces_angle(creases) if not redistanced or "smoothed_turn_degrees" in creases else angle
    if thinned and faces > 90 and not redistanced:
        thinned = max(thinned, THINNED_SHORTCUT_REDISTANCED)
    # 2·tan(θ/2) capped at θ = 150° as the core's (Creases::shortcut_per_inner_width): at 180° the
    # normal reverses, two sheets face each other across a gap (two spheres a 0.02 gap apart said
    # "up to about 3.27e+15"), and a front that crosses over is early by more than any such bound
    size, how = _per_crease(per_inner_width(faces), inner, spacing, thinned, scaled=faces <= REVERSED)
    early = _early(faces, size, f"({how}, first order in Δx)", thinned=bool(thinned))
    smoothed = " (read through a smoothing of φ)" if "smoothed_turn_degrees" in creases else ""
    turning = f"{angle:.0f}°" + (f", the faces by up to {faces:.0f}°{smoothed}" if faces > angle + 5 else "")
    warnings.warn(
        f"φ's level sets have creases or corners ({creases['nodes']} tube nodes, the normal turning by up to "
        f"{turning}): a front that crosses one {early}, "
        "and the nodes there run the first-order update. sol.first_order_points() shows where; rounding the edges "
        "over more than the tube's width (outer·Δx), or a finer grid, reduces it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _warn_smoothed_only(creases: dict, inner: float, spacing: float) -> None:
    """:func:`warn_creases` for creases that only the test through a smoothing found: their nodes
    ran the first-order update (their curvature unresolved) and the inner tube was not thinned at
    them, so a front crossing one cuts the corner by up to 2·tan(θ/2)·inner·Δx."""
    angle = float(creases["angle_degrees"])
    size = shortcut(creases["shortcut_per_inner_width"], inner, spacing)
    early = _early(angle, size, f"({size / spacing:.2g}·Δx, 2·tan(θ/2)·inner·Δx, first order in Δx)")
    warnings.warn(
        f"φ's level sets have creases or corners ({where_creases(creases)}): a front that crosses one {early}, and the "
        "nodes there run the first-order update. sol.first_order_points() shows where; a finer grid reduces it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def faces_angle(creases: dict) -> float:
    """The faces' angle at the creases of a φ whose directions come from its central differences
    (a φ = max(φ₁, φ₂) given as it is): the widest turn of the normal across a crease node
    (``faces_angle_degrees``), where neighbours turn by about half of it next to the crease. A
    lens of two spheres whose faces meet at 113°, N = 61–101: 52–61° between neighbours, and
    beyond the crease 2.2–3.3Δx early on average (3.5 at worst) where the warning said 1.5Δx; at
    120°, N = 101: 90°, 4.0Δx (4.4) where it said 1.5Δx (a helper's review). Beyond a right angle
    the thinned tube's shortcut then is that of a re-distanced φ, :data:`THINNED_SHORTCUT_REDISTANCED`,
    times tan(θ/2)."""
    return max(float(creases["angle_degrees"]), float(creases.get("faces_angle_degrees", 0.0)))


def refused_for_creases(reason: str) -> bool:
    """Whether ``order="auto"`` ran the first-order scheme for convex creases (``reason``, the
    refusal's text), which :func:`warn_refused_creases` says."""
    return _CONVEX_CREASES.search(reason) is not None


def warn_refused_creases(reason: str, inner: float, spacing: float, *, thinned: float) -> bool:
    """A RuntimeWarning when ``order="auto"`` ran the first-order scheme because of convex creases:
    the shortcut per crease, ``thinned`` spacings on the tube thinned at them
    (:func:`thinned_spacings`), else ``2·tan(θ/2)·inner·Δx`` at the largest turn θ that the refusal names (the
    paper's tube; a re-distanced φ kept it until its crease nodes were thinned too: the box
    max|x| − 0.5 re-distanced at N = 41 came out 4.8Δx short per edge there, 1.16Δx thinned);
    whether it warned."""
    if not refused_for_creases(reason):
        return False
    given = _PER_INNER_WIDTH.search(reason)  # 2·tan(θ/2) at the largest turn θ, as the refusal gives it
    size, how = _per_crease(float(given.group(1)) if given else 2.0, inner, spacing, thinned)
    warnings.warn(
        f"order=1 ran: φ's level sets have convex creases or corners over much of the tube, where a front cuts the "
        f"corner and arrives early by up to about {size:.3g} per crease it crosses ({how}: first order in Δx). "
        "sol.stats.order_fallback says more; round the edges over more than the tube's width (outer·Δx), or refine "
        "the grid until they are (a thin part's rim tighter than the tube counts as such an edge), for second order "
        "and no shortcut",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
    return True


def crease_nodes_to_extend(
    band: Any, inner: np.ndarray, phi: np.ndarray, direction: np.ndarray, spacing: float
) -> np.ndarray:
    """The band positions of the inner-tube nodes (``inner``) on the overlap side of a crease,
    farther than half a spacing from the surface (``tubesweep_core::band::crease_ridges``): as
    extension nodes their values come from their closest points, and the front no longer cuts the
    corner through them. A smooth surface has none."""
    return band.crease_ridge_nodes(
        np.ascontiguousarray(inner, dtype=bool),
        np.ascontiguousarray(phi, dtype=np.float32),
        np.ascontiguousarray(direction, dtype=np.float32).reshape(len(inner), -1),
        float(spacing),
    )


def creases_in_paper_tube(
    band: Any, inner: np.ndarray, phi: np.ndarray, direction: np.ndarray, spacing: float
) -> Dict[str, Any]:
    """The creases of a level set in the paper's tube, where the first-order scheme cuts their
    corners (``tubesweep_core::second_order::creases::creases_of_level_set``: the second-order
    geometry's crease test without the curvatures): ``nodes``, ``angle_degrees`` (the faces'
    angle, the widest turn of the normal across a crease node) and ``shortcut_per_inner_width``
    (2·tan(θ/2)), as ``sol.stats.order2["creases"]``."""
    nodes, angle = band.creases_of_level_set(
        np.ascontiguousarray(inner, dtype=bool),
        np.ascontiguousarray(phi, dtype=np.float32),
        np.ascontiguousarray(direction, dtype=np.float32).reshape(len(inner), -1),
        float(spacing),
    )
    return _paper_creases(nodes, angle)


def _paper_creases(nodes: int, angle: float) -> Dict[str, Any]:
    """The stats dict of the paper's tube's creases (``sol.stats.creases``): ``nodes`` crease
    nodes whose faces turn by up to ``angle`` degrees."""
    return {
        "nodes": int(nodes),
        "angle_degrees": float(angle),
        "faces_angle_degrees": float(angle),
        "shortcut_per_inner_width": per_inner_width(angle) if nodes else 0.0,
    }


def creases_of_redistanced(
    band: Any, roles: np.ndarray, phi: np.ndarray, direction: np.ndarray, spacing: float, outer_width: float
) -> Tuple[Dict[str, Any], bool, float]:
    """As :func:`creases_in_paper_tube` for a re-distanced φ (a voxel mask, ``redistance=True``),
    whose sampled zero set has kinks of its own (a mask's staircase, noise): the crease test of the
    second-order geometry, behind its gates (curvature or gradient unresolved by central
    differences, no crease on a φ found noisy), with the faces' angle
    (``tubesweep_core::second_order::creases::creases_of_redistanced``). ``roles``: the paper's
    tube; ``outer_width``: its half-width (outer·Δx). And whether φ was found noisy (then no
    crease was looked for), and the largest turn between neighbours at the crease nodes (degrees),
    which tells a sharp crease (as wide as the faces' angle) from a rounded one."""
    nodes, angle, noisy, between = band.creases_of_redistanced(
        np.ascontiguousarray(roles, dtype=np.uint8),
        np.ascontiguousarray(phi, dtype=np.float64),
        np.ascontiguousarray(direction, dtype=np.float32).reshape(len(roles), -1),
        float(spacing),
        float(outer_width),
    )
    return {**_paper_creases(nodes, angle), "redistanced": True}, bool(noisy), float(between)


def where_creases(creases: dict) -> str:
    """How many nodes a crease report holds and how far their faces turn, for a warning; for the
    creases found through a smoothing (``_coarse_creases``, a voxel mask or a noisy φ), the turn
    read and the faces' angle that it stands for."""
    nodes, angle = creases["nodes"], float(creases["angle_degrees"])
    turn = creases.get("smoothed_turn_degrees")
    if turn is None:
        return f"{nodes} tube nodes, the faces turning by up to {angle:.0f}°"
    # (a smooth part read as creased: convex, tighter than about four spacings; concave, three)
    tight = (
        "a concave part curved more tightly than about three"
        if creases.get("concave")
        else "a part curved more tightly than about four"
    )
    return (
        f"{nodes} tube nodes next to the surface where its normal, read through a smoothing of φ over about a "
        f"spacing, turns by {turn:.0f}° within two spacings, taken for faces whose normals differ by up to "
        f"{angle:.0f}° (a cube's 90° edges read about 75°), or {tight} spacings"
    )


def warn_paper_tube_creases(creases: Optional[dict], inner: float, spacing: float) -> None:
    """A RuntimeWarning when the first-order scheme runs on the paper's tube (``order=1``) of a
    level set with creases (:func:`creases_in_paper_tube`): a front crossing one cuts its corner
    and arrives early by about 2·tan(θ/2)·inner·Δx (the cube at N = 41: 4.25Δx per edge)."""
    if not creases or not creases.get("nodes"):
        return
    angle = float(creases["angle_degrees"])
    size = shortcut(creases["shortcut_per_inner_width"], inner, spacing)
    reckoned = "2·tan(θ/2)·inner·Δx"
    thinned = THINNED_SHORTCUT
    if creases.get("redistanced"):
        size *= PAPER_TUBE_REDISTANCED
        reckoned = f"{PAPER_TUBE_REDISTANCED:g}·2·tan(θ/2)·inner·Δx on a re-distanced φ"
        thinned = THINNED_SHORTCUT_REDISTANCED
    early = _early(angle, size, f"({size / spacing:.2g}·Δx) per crease it crosses ({reckoned}, first order in Δx)")
    if "smoothed_turn_degrees" in creases:  # (a voxel mask, a noisy φ: "auto" may run first order)
        instead = "order='auto' (the default) thins the tube there, which leaves less, and says how much"
    else:
        instead = (
            f"Second order's tube (order='auto', the default, or order=2, with outer ≥ inner + 2) is thinned there, "
            f"which leaves about {thinned:g}Δx per crease"
        )
    warnings.warn(
        f"φ's level sets have creases or corners ({where_creases(creases)}): in the paper's tube (order=1) a front "
        f"crossing one cuts the corner and {early}. {instead}; rounding the edges over more than the tube's width "
        "(outer·Δx) leaves none. sol.stats.creases has the figures",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
