"""``order="auto"``'s fallback to the first-order scheme (:class:`Fallback`): why, kept in
``sol.stats.order_fallback``, and how large its errors are, said in a warning.

Where the surface or the grid rules out the second-order scheme (a grid that does not resolve
the surface, a mesh given as it is, a φ that is not a distance), ``order="auto"`` runs the
paper's first-order scheme. Its errors are a few grid spacings where fronts meet, whatever the
grid: the largest errors are 2.7–3.1Δx on the sphere of radius 0.5 at N = 12–20, 2.5–2.8Δx on
the circle at N = 12–16, 2.0–4.3Δx on the torus (0.6, 0.25) at N = 16–31 and 0.6–2.4Δx on the
ellipsoid (0.8, 0.5, 0.3) at N = 16–41, against second-order solves at N = 201. On a
surface a few tens of spacings across that is a large share of the distances: the warning
states :data:`FIRST_ORDER_SPACINGS` spacings against the largest distance, divided by the mean
|∇φ| where φ is not a distance (the tube is that much wider: φ = 0.5·(|x| − 0.5) at N = 41 is
24% off, and the warning says 23%), and adds about
:data:`UNRESOLVED_SHORTCUT` spacings for each edge or tip whose curvature radius is below the
tube's width that a path crosses and where the tube is not thinned (``RoundedCube()`` at N = 71,
5.9% short across two edges; inside edges rounded tighter than three spacings the inner tube is
thinned as at a crease, ``band::crease_ridges``, and N = 41–61 come out 2.7–5.9% short). ``benches/experiments/fallback_size.py`` prints the errors against what the warning
says; ``tests/test_fallback.py``.

On an open surface (a hemisphere, a scan with holes, a cloud with a stray patch) no fronts need
meet around it, and a flat patch's first-order errors are a few per cent, so only its bends are
sized: by their curvature read on the concave side, where a rim's fan of directions does not
reach (``_curvature.concave_curvature``), :data:`OPEN_BEND` times the closed surfaces' estimate, as
"roughly" and good to a factor of three (``benches/experiments/open_fallback_size.py``; plane
patches and discs: nothing).

Not warned about: an option the caller chose that only the first-order scheme has
(``second_order.OptionOfOrder1``: the caller chose that scheme).
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from ._coarse_creases import paper_creases
from ._curvature import SHORTCUT_FACTOR, concave_curvature, typical_curvature
from ._creases import refused_for_creases, shortcut, thinned_spacings, warn_refused_creases, where_creases
from ._prepare import thinned_count
from .band import band_neighbours
from .surface import LevelSet
from .mask import ROUGH_REDISTANCED
from .surfaces._mesh_parts import open_only_in_debris
from ._warn import user_stacklevel
from ._order2_refusals import (
    NOISY_PHI,
    NOT_A_DISTANCE,
    NarrowExtension,
    OptionOfOrder1,
    Order2NotApplicable,
    warn_fallback,
)

#: The first-order scheme's error where fronts meet, in grid spacings (the sphere's antipode:
#: 2.7–3.1Δx at N = 12–20).
FIRST_ORDER_SPACINGS = 3.0

#: How early a front arrives, in grid spacings, after crossing an edge, a tip or a corner whose
#: curvature radius is below the tube's width (as at a crease), where the inner tube is not thinned
#: there: ``RoundedCube()`` (radius 0.1) from its bottom face's centre on the paper's tube, largest
#: errors 4.6–6.8Δx at N = 41–61 where two edges were crossed, 2.3–3.4Δx per edge; thinned (edges
#: rounded over less than three spacings) :data:`~tubesweep._creases.THINNED_SHORTCUT` instead.
UNRESOLVED_SHORTCUT = 3.5

#: The tube's cut across the surface's bends (:attr:`Fallback.bend`) is the size stated where it is
#: at least this many times the share that the distances' length gives (a capsule 5.8 spacings
#: across and 1.1 long: 5.2; a sphere: 1.5).
BEND_OVER_SHARE = 2.0

#: An open surface's bends are sized at this share of a closed one's estimate (SHORTCUT_FACTOR·inner·Δx·κ,
#: κ read on the concave side): the first-order errors measured were 0.3–1.5 times what it then
#: states, 0.3–0.4 on a hemisphere from its pole (paths over it turn by a quarter circle at most),
#: 0.9–1.1 round sphere clouds with a hole or a stray patch, 1.4–1.5 on a cloud of the cow Spot with
#: a hole (``benches/experiments/open_fallback_size.py``)
OPEN_BEND = 0.7

#: The warning fires when the estimated error is at least this share of the distances: a surface
#: whose farthest path is 30 grid spacings long or more is not warned about for the 3Δx alone.
SIZE_WARNING = 0.1

#: How far from 1 the mean |∇φ| of a signed distance reads through central differences where the
#: grid does not resolve the surface (the sphere of radius 0.5 at N = 12: 0.97): nearer than this,
#: φ is taken for a distance
GRADIENT_READ = 0.05

#: A φ given as it is whose |∇φ| spreads by more than this factor over the tube (95th against 5th
#: percentile) is not a distance, which the second-order geometry reads as unresolved curvature:
#: the fallback's reason says so (φ = |x|² − 0.25 at N = 61: 0.8–1.2, refused for "a curvature the
#: tube does not resolve"; a signed distance at N = 20 gets no note: ``tests/test_fallback.py``)
GRADIENT_SPREAD = 1.2

#: A fallback for curvatures the tube does not resolve (the second-order geometry's refusal,
#: with the share of the inner tube: "(22%) have a principal curvature the tube does not resolve")
_UNRESOLVED = re.compile(r"\((\d+)%\)[^()]*curvature the tube does not resolve")
#: ... and how many nodes (``tubesweep_core::second_order::check_geometry_of``)
_UNRESOLVED_NODES = re.compile(r"(\d+) of the \d+ inner-tube nodes \(\d+%\) have a principal curvature the tube")

#: Unresolved curvature on less than this share of the inner tube is edges, tips or corners,
#: crossed as creases are (``RoundedCube()`` at N = 41–61: 19–22%; the ellipsoid's tips at N = 41:
#: 17%); on more, the whole surface is too small for the grid (the sphere at N = 20: 43%), which
#: the other estimates size.
EDGES_SHARE = 0.35


def gradient_range(tube: Any, far: float = 2.0) -> Tuple[float, float, float]:
    """The mean, 5th and 95th percentiles of ``|∇φ|`` (central differences) over the band nodes
    1 to ``far`` spacings off the surface whose 2d neighbours are in the band: 1 for a signed
    distance, the scale of a scaled one (1, 1, 1 without such nodes). ``tube``: a prepared tube
    (``_prepare._PreparedTube``), whose ``phi`` is the signed or unsigned distance, or the given
    φ, at its band nodes."""
    grid, linear = tube.grid, tube.linear
    h = grid.spacing
    phi = np.asarray(tube.phi, dtype=float)
    away = np.abs(phi)
    at = np.flatnonzero((away >= h * (1 - 1e-6)) & (away <= far * h))
    if at.size == 0:
        return 1.0, 1.0, 1.0
    gradient = np.zeros((at.size, grid.ndim))
    whole = np.ones(at.size, dtype=bool)
    for i, (_, _, pos) in enumerate(band_neighbours(grid, tube.band, linear, at)):
        k, side = divmod(i, 2)  # axis k, the + side then the − side
        whole &= pos >= 0
        gradient[:, k] += (1 if side == 0 else -1) * np.where(pos >= 0, phi[pos], 0.0)
    norms = np.linalg.norm(gradient[whole], axis=1) / (2 * h)
    if norms.size == 0 or not np.mean(norms) > 0:
        return 1.0, 1.0, 1.0
    low, high = np.percentile(norms, [5, 95])
    return float(np.mean(norms)), float(low), float(high)


def first_order_share(values: Any, spacing: float, gradient: float = 1.0) -> Tuple[float, float]:
    """The first-order scheme's error as a share of the distances: :data:`FIRST_ORDER_SPACINGS`
    grid spacings against the largest finite value of ``values``, divided by the mean ``|∇φ|``
    (a φ that is not a distance widens the tube by its inverse); and that largest value (0, 0
    when none is positive)."""
    v = np.asarray(values, dtype=float)
    finite = v[np.isfinite(v)]
    largest = float(finite.max()) if finite.size else 0.0
    if largest <= 0:
        return 0.0, 0.0
    return FIRST_ORDER_SPACINGS * float(spacing) / (largest * gradient), largest


def warn_first_order(
    reason: str,
    values: Any,
    tube: Any,
    gradient: Optional[float],
    *,
    said: bool,
    bend: float = 0.0,
) -> None:
    """After ``order="auto"`` ran the first-order scheme on ``tube`` for ``reason``: the crease
    warning when creases caused it, else a RuntimeWarning when its errors are a large share of
    the distances (:data:`SIZE_WARNING`; ``gradient`` from :meth:`Fallback.measure`), or φ is not a
    distance (whose cure, ``redistance=True``, the reason names). Nothing when ``said`` (the
    fallback was warned about already, a runaway, or the caller chose an option of the
    first-order scheme: ``second_order.warn_fallback``). On an open surface (``gradient`` None: near
    a rim the distance curves whatever the surface does) only ``bend`` is sized. ``bend``: the share
    by which the tube cuts across the surface's bends (:attr:`Fallback.bend`), the estimate where it
    is larger."""
    spacing = tube.grid.spacing
    thinned = thinned_count(tube) > 0
    if said or warn_refused_creases(reason, tube.inner, spacing, thinned=thinned_spacings(tube, thinned)):
        return
    if gradient is None:
        if bend >= SIZE_WARNING:
            _warn_open_bend(reason, values, tube, bend)
        return
    if abs(gradient - 1.0) < GRADIENT_READ:
        gradient = 1.0  # a distance, read through central differences
    share, largest = first_order_share(values, spacing, gradient)
    if largest <= 0:
        return
    unresolved = _UNRESOLVED.search(reason)
    edges_only = unresolved is not None and int(unresolved.group(1)) < 100 * EDGES_SHARE
    # (the inner tube thinned at the edges: _creases.thinned_spacings per edge, as at a crease;
    # the star's tips, 94 unresolved nodes of which the crease test thinned 4 at N = 61, are not)
    nodes = _UNRESOLVED_NODES.search(reason)
    at_edges = thinned and (nodes is None or 2 * thinned_count(tube) >= int(nodes.group(1)))
    per_edge = thinned_spacings(tube, True) if at_edges else UNRESOLVED_SHORTCUT
    crossing = per_edge * spacing / gradient if edges_only else 0.0
    # a surface bent more tightly than the distances are long (a capsule 5.8 spacings across, 1.1
    # long: 3Δx is 5% of the largest distance, but round it 51% short, unwarned; a review).
    # (On a sphere the bend reads 1.5 times the 3Δx of the share, both about right: the bend is
    # taken where the surface bends more tightly than its length says, twice the share or more,
    # and not where edges or tips are the cause, sized per crossing below)
    bent = not edges_only and bend > BEND_OVER_SHARE * share
    share = bend if bent else share
    rough = ROUGH_REDISTANCED in reason  # (a re-distanced φ: mask.mask_advice)
    not_a_distance = NOT_A_DISTANCE in reason or rough
    if share < SIZE_WARNING and 2 * crossing < SIZE_WARNING * largest and not not_a_distance:
        return
    size = f"up to about {100 * share:.0f}% of the distances" if share < 1 else "as large as the distances"
    if bent:
        # (the mean curvature's: round a cylinder, whose other curvature is 0, paths turn twice as
        # sharply, and a capsule's far side came out 51% short where 19% was stated)
        size = (
            ("as large as the distances" if share >= 1 else f"of {100 * share:.0f}% of the distances or more")
            + " along paths that turn round the surface (it bends "
            f"on a scale of about {SHORTCUT_FACTOR * tube.inner / max(bend, 1e-300):.2g} grid spacings, one over its "
            "mean curvature, not much wider than the tube, which cuts across the bend)"
        )
    if not not_a_distance:
        scaled = ""
    elif rough:
        scaled = (
            f"; the re-distanced φ reads |∇φ| = {gradient:.3g} on average through central differences, its zero level "
            "set rough at the grid's scale, which widens the tube and the errors by 1/|∇φ|"
        )
    elif gradient == 1.0:
        scaled = "; φ is not a distance (its |∇φ| is 1 on average but spreads over the tube)"
    else:
        scaled = (
            f"; φ is not a distance (mean |∇φ| = {gradient:.3g}), which scales the tube and the errors by 1/|∇φ| (a "
            "distance sampled on another box or spacing than the grid's reads so too: sample it at grid.meshgrid())"
        )
    edges = (
        f", and up to about {crossing:.3g} more ({100 * crossing / largest:.0f}% of the largest) for each edge, tip "
        "or corner with a curvature radius below the tube's width that a path crosses (as at a crease)"
        if crossing
        else ""
    )
    if rough:
        cure = "smoothing φ over a spacing or two before re-distancing, or a coarser grid, lowers them"
    elif not_a_distance:
        cure = (
            "LevelSet(φ, redistance=True) removes that scaling"
            if gradient != 1.0
            else "LevelSet(φ, redistance=True) cures it"
        )
    else:
        cure = "a finer grid lowers them in proportion"
    warnings.warn(
        f"order='auto' ran the paper's first-order scheme, whose errors are a few grid spacings where fronts meet "
        f"(about {FIRST_ORDER_SPACINGS:g}·Δx on a sphere){scaled}: here Δx = {spacing:.3g} and distances up to "
        f"{largest:.3g}, so errors {size}{edges}. {cure[0].upper()}{cure[1:]} (why order 2 did not apply, kept in "
        f"sol.stats.order_fallback: {reason})",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _warn_open_bend(reason: str, values: Any, tube: Any, bend: float) -> None:
    """:func:`warn_first_order` on an open surface whose bends cost a share ``bend`` of the
    distances (:attr:`Fallback.bend`, read on the concave side)."""
    spacing = tube.grid.spacing
    _, largest = first_order_share(values, spacing)
    scale = SHORTCUT_FACTOR * OPEN_BEND * tube.inner / bend
    size = "as large as the distances" if bend >= 1 else f"of roughly {100 * bend:.0f}% of the distances"
    warnings.warn(
        f"order='auto' ran the paper's first-order scheme on an open surface that bends on a scale of about "
        f"{scale:.2g} grid spacings (one over its mean curvature), not much wider than the tube, which cuts across "
        f"the bends: here Δx = {spacing:.3g} and distances up to {largest:.3g}, so errors {size} along paths over "
        "the bends (an estimate good to a factor of three). A finer grid lowers them (why order 2 did not "
        f"apply, kept in sol.stats.order_fallback: {reason})",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


@dataclasses.dataclass
class Fallback:
    """``order="auto"`` running the first-order scheme: ``reason``, the refusal's text (kept in
    ``sol.stats.order_fallback``); ``said``, whether nothing more is to be said after the solve
    (warned already, or an option the caller chose: ``second_order.warn_fallback``);
    ``gradient``, the tube's mean ``|∇φ|`` for the size warning (:meth:`measure`; None on an open
    surface)."""

    reason: str
    said: bool
    gradient: Optional[float] = None
    #: widths that leave second order no room (``second_order.NarrowExtension``), said after the solve
    narrow: bool = False
    #: the creases of a re-distanced φ that its kinks hide from the crease tests, found through a
    #: smoothing (``_coarse_creases.paper_creases``; :meth:`measure`): ``sol.stats.creases``
    creases: Optional[Dict[str, Any]] = None
    #: an option only the first-order scheme has (``second_order.OptionOfOrder1``): the caller chose
    #: that scheme, whose tube is the paper's (not thinned at creases)
    option_of_order1: bool = False
    #: the share by which the tube cuts across the surface's bends, ``SHORTCUT_FACTOR``·inner·Δx·κ over
    #: |∇φ| (κ: ``_curvature.typical_curvature``; :meth:`measure`); on an open surface :data:`OPEN_BEND`
    #: times that, κ read on the concave side (``_curvature.concave_curvature``)
    bend: float = 0.0

    @classmethod
    def of(cls, refusal: Order2NotApplicable, order: Any) -> "Fallback":
        """The fallback for ``refusal``, warned about now when the refusal's kind asks for it."""
        return cls(
            str(refusal),
            warn_fallback(refusal, order),
            narrow=isinstance(refusal, NarrowExtension),
            option_of_order1=isinstance(refusal, OptionOfOrder1),
        )

    def measure(self, tube: Any) -> None:
        """Reads the mean ``|∇φ|`` that :meth:`warn` needs from ``tube`` before the solve, which
        drops the band's linear indices (none when nothing is to be said, or on an open surface)."""
        surface = tube.surface
        closed = getattr(surface, "closed", True) is not False or (
            getattr(surface, "faces", None) is not None and open_only_in_debris(surface)
        )
        if self.said:
            return
        if getattr(surface, "open_surface", False) or not closed:
            # (only its bends are sized, read on their concave side: its φ near a rim cannot be read
            # through differences, 3Δx would be a false alarm on a flat patch, and typical_curvature
            # reads a small patch's rim as a tight bend: a disc one spacing across said 75%)
            if getattr(surface, "faces", None) is None and not getattr(surface, "redistance", False):
                kappa = concave_curvature(tube)
                self.bend = OPEN_BEND * SHORTCUT_FACTOR * tube.inner * tube.grid.spacing * kappa
            return
        redistanced = isinstance(surface, LevelSet) and (surface.redistance or NOISY_PHI in self.reason)
        if redistanced and not refused_for_creases(self.reason):
            # a voxel mask or a noisy φ, whose kinks run the first-order scheme and hide a crease
            # from the crease tests: two balls fused at 122° as a voxel mask, 4–5Δx early beyond
            # the crease at N = 41–81 with no warning (tests/test_coarse_creases.py); refused for
            # an unresolved curvature rather than for noise, a closed cylinder's mask at N = 61–101
            # (3.2–5.2Δx across its two rims) and fused discs' in 2D (6–8Δx), a helper's review
            self.creases = paper_creases(tube.grid, tube.band, tube.phi)
        self.gradient, low, high = gradient_range(tube)
        self._measure_bend(tube)
        given = isinstance(surface, LevelSet) and not surface.redistance
        if given:
            # the spread over the whole tube: a φ that flattens away from the surface (ε·tanh(d/ε),
            # ε = 4Δx at N = 41: |∇φ| 0.94 and 0.79 at 1 and 2 spacings, 0.42 at 4) is blamed on
            # the grid when read 1–2 spacings off only
            _, low, high = gradient_range(tube, far=np.inf)
        # (a note, not the reason: a library surface's edges on a coarse grid spread |∇φ| read
        # through central differences too, and are no φ to re-distance; NOT_A_DISTANCE, which
        # the size warning reads as the cause, comes only from the geometry's own refusal)
        if given and high > GRADIENT_SPREAD * low and NOT_A_DISTANCE not in self.reason:
            self.reason += (
                f"; |∇φ| ranges over [{low:.3g}, {high:.3g}] in the tube, so φ is not a distance, which reads as "
                "curvature: LevelSet(φ, redistance=True) re-distances it and may run second order"
            )

    def _measure_bend(self, tube: Any) -> None:
        """:attr:`bend` on ``tube`` (before the solve: it reads the band's linear indices). Not on
        a mesh (its facets' edges and corners read as tight bends: the bunny at 14% or more where
        its first-order errors are 3%; a mesh's band is cut across its narrow parts instead) nor on
        a re-distanced φ (a voxel mask's staircase: 25% on a sphere's)."""
        surface = tube.surface
        if getattr(surface, "faces", None) is not None or getattr(surface, "redistance", False):
            return
        kappa = typical_curvature(tube)
        self.bend = SHORTCUT_FACTOR * tube.inner * tube.grid.spacing * kappa / max(self.gradient or 1.0, 1e-300)

    def warn(self, values: Any, tube: Any) -> None:
        """After the solve on ``tube``: the crease or size warning for its ``values``
        (:func:`warn_first_order`), or that the widths chose the first-order scheme."""
        if self.narrow:
            share, largest = first_order_share(values, tube.grid.spacing)
            size = f" (here {share:.0%} of the largest distance, {largest:.3g}, or more: the error grows with inner)"
            warnings.warn(
                f"order='auto' ran the first-order scheme, whose errors are {FIRST_ORDER_SPACINGS:g} grid spacings or "
                f"more where fronts meet{size if largest > 0 else ''}: {self.reason}. A widening of the extension "
                "layer during the solve does not change this: the widths given decide",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
            return
        if self.creases is not None:
            warn_smoothed_creases(self.creases, tube.inner, tube.grid.spacing)
            return
        warn_first_order(self.reason, values, tube, self.gradient, said=self.said, bend=self.bend)


def warn_smoothed_creases(creases: Dict[str, Any], inner: float, spacing: float) -> None:
    """After ``order="auto"`` ran the first-order scheme on a re-distanced φ whose creases were
    found through a smoothing (:attr:`Fallback.creases`): a front crossing one cuts its corner, by
    up to ``2·tan(θ/2)·inner·Δx``, the paper's tube's figure: the tube is thinned where the ridge
    test finds crease nodes, which leaves less, but on a voxel mask not steadily (two fused balls'
    masks 3.5–7.2Δx early at N = 41–81 where 4.8–15Δx is said, ``benches/experiments/mask_creases.py``;
    a cube's or a closed cylinder's 90° edges 1–3 times below it, a helper's review)."""
    size = shortcut(creases["shortcut_per_inner_width"], inner, spacing)
    warnings.warn(
        f"order='auto' ran the first-order scheme, and φ's level sets have creases or corners "
        f"({where_creases(creases)}): a front that crosses one cuts the corner and arrives early by up to about "
        f"{size:.3g} ({size / spacing:.2g}·Δx) per crease (2·tan(θ/2)·inner·Δx, first order in Δx). sol.stats.creases has the figures and "
        "sol.stats.order_fallback why order 2 did not apply; a finer grid lowers it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
