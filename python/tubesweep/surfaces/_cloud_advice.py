"""What a point cloud's errors and warnings say about it (:class:`CloudAdvice`, a part of
:class:`~tubesweep.surfaces.points.PointCloudSurface`): the causes of folded closest points that the
cloud shows (samples in lines, sharp edges, samples a little off their neighbours' surface, uneven
sampling, noise) and their cures, for the band's error and the second-order runaway's message
(``_prepare``, ``second_order``)."""

from __future__ import annotations

import warnings
from typing import Any, Optional

from .._warn import user_stacklevel

#: Samples farther apart (median nearest-neighbour distance) than this many grid spacings: refused.
SPARSE_FACTOR = 3.0
#: More than this share of samples that their neighbours' fits miss (``points.CREASE_RESIDUAL``): the
#: cloud has sharp edges, named in its errors and warnings.
CREASE_SHARE = 0.005
#: How early a front arrives, in grid spacings, per sharp edge of a cloud that it crosses (the fits
#: round the edge off and the closest points bounce between its faces): a noise-free box 0.8
#: across and a closed cylinder (radius 0.4, height 0.8), 30,000 samples each, N = 61: the box's
#: far face 7.9 spacings short across two edges, its sides 3.8 across one, at first order; beyond
#: the cylinder's two rims, over its cap, 7.4 at first order and 3.8 at second (a helper's
#: review, against exact polyhedral geodesics on fine meshes of them); 20,000 samples of that
#: cylinder, from its side to its caps' centres across one rim: 4.1–4.5 at first order, 1.0–1.2 at
#: second (``tests/test_point_cloud.py``).
CREASE_SPACINGS = 5.0
#: Samples their fits miss that lie farther than this many median spacings from every other sample
#: are strays the outlier test kept rather than a sharp edge's (whose samples are as dense as the
#: rest): 1 % of a sphere's 20,000 samples spread over its box, 118 of them kept, read as "sharp
#: edges or corners" first (a helper's review); their spacings 20 times the median or more.
STRAY_SPACINGS = 5.0
#: A widest fit more than this many times the median one: the sampling is uneven enough that a
#: fold of the closest points may come from parts sampled too sparsely for their curvature.
UNEVEN_FITS = 4.0
#: Samples that lie on their neighbours' fits to within this share of the median fit's radius are
#: noise-free, and a runaway or a fold is not blamed on samples off the surface: a torus sliced
#: across its axis (slices 0.04 apart, 0.003 along them) read 3.7e-7 against fits of 0.09 and ran
#: away with neighbours=80–100 (60 solved at second order), its message blaming noise (stop 79).
NOISE_FREE = 1e-4


class CloudAdvice:
    """The messages of a :class:`~tubesweep.surfaces.points.PointCloudSurface` (which sets the
    attributes read here: ``points``, ``spacing``, ``noise``, ``smoothing`` and the analysis's
    ``_median_fit``, ``_sparsest_fit``, ``_creases``, ``_lines``)."""

    points: Any
    spacing: float
    noise: float
    smoothing: float
    _median_fit: float
    _sparsest_fit: float
    _creases: Any
    _strays: Any

    def _uneven(self) -> Optional[float]:
        """How many times the median fit the widest one spans, when above :data:`UNEVEN_FITS`
        (parts may be sampled too sparsely), else None."""
        ratio = self._sparsest_fit / self._median_fit
        return ratio if ratio > UNEVEN_FITS else None

    def _said_creases(self) -> Optional[str]:
        """Where the cloud's sharp edges are named, ``"x, y, z"`` of one of their samples, or None
        when it has none (:data:`CREASE_SHARE`)."""
        count, where = self._creases
        if count <= CREASE_SHARE * len(self.points) or where is None:
            return None
        return _where(where)

    def _mostly_strays(self) -> bool:
        """Most of the samples that their fits miss lie far from every other (:data:`STRAY_SPACINGS`)."""
        strays, stray = getattr(self, "_strays", (0, None))
        return stray is not None and 2 * strays >= self._creases[0]

    def _crease_advice(self) -> str:
        """The cloud's sharp edges and their cure, or "" when it has none (:data:`CREASE_SHARE`);
        strays first where most of those samples lie far from every other (:data:`STRAY_SPACINGS`)."""
        at = self._said_creases()
        if at is None:
            return ""
        count = self._creases[0]
        if self._mostly_strays():
            strays, stray = self._strays
            return (
                f"{strays} of the {count} samples that their fits miss lie more than {STRAY_SPACINGS:g} times the "
                f"median spacing from every other sample (e.g. at ({_where(stray)})): stray points off the surface that the "
                "outlier test kept. Leave them out (cloud.crease_samples lists the samples their fits miss); if the "
                "surface has sharp edges there instead, give it as a mesh (from_mesh)"
            )
        return (
            f"the cloud has sharp edges or corners ({count} samples that their fits miss, e.g. at ({at})), which the "
            f"local fits (about {self._median_fit:.2g} across) cannot follow: the closest points bounce between the "
            "faces there. Give the surface as a mesh (from_mesh: meshes keep their creases and run first order "
            "there); a larger neighbours= rounds the edges over more samples, which helps only where the fits then "
            "span several grid spacings. If the surface is smooth there, those samples lie off it (scan outliers "
            "too close to their neighbours for the outlier test): leave them out (cloud.crease_samples lists them)"
        )

    def _warn_creases(self, grid: Any) -> None:
        """A RuntimeWarning, once per grid, where the cloud has sharp edges (:data:`CREASE_SHARE`),
        with how early a front arrives beyond them (:data:`CREASE_SPACINGS`): named before only
        when a solve failed or its closest points were not found (a box), and a closed cylinder's
        cloud was 3.8 spacings short at second order, 7.4 at first, with no word of it."""
        at = self._said_creases()
        if at is None or getattr(self, "_creases_warned", None) == grid:
            return
        self._creases_warned = grid
        if self._mostly_strays():
            return  # (strays the outlier test kept: said by the errors they cause, _crease_advice)
        count = self._creases[0]
        early = CREASE_SPACINGS * grid.spacing
        warnings.warn(
            f"the cloud has sharp edges or corners, or samples off its surface ({count} samples that their fits miss, "
            f"e.g. at ({at}); cloud.crease_samples lists them). At an edge the local fits round it off and the closest "
            f"points bounce between its faces, so a front arrives early by up to about {early:.3g} "
            f"({CREASE_SPACINGS:g}·Δx) for each edge it crosses (a noise-free box's edges and a closed cylinder's rims "
            "at N = 61: 3.7–4.5Δx per edge at first order, 1.0–1.9Δx at second), first order in Δx: give such a "
            "surface as a mesh (from_mesh), whose creases run first order on a band cut at them. Samples off a smooth "
            "surface (dents, scan artefacts) bend it only there: leave them out",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )

    def _sampling_advice(self) -> str:
        """The samples in lines (``_cloud_analysis.lines_advice``) and the sharp edges
        (:meth:`_crease_advice`), the causes of folded closest points that the cloud shows."""
        lines, crease = getattr(self, "_lines", ""), self._crease_advice()
        return f"{lines}. Or: {crease}" if lines and crease else lines or crease

    #: Why the band of a cloud's closest points may not close, for the band's error (``_prepare``).
    @property
    def band_advice(self) -> str:
        """What folds a cloud's closest points so that the tube is not enclosed (for the error of
        ``_prepare._prepare_tube``): samples a little off the surface, or, where the sampling is
        uneven, parts sampled too sparsely for their curvature."""
        advice = (
            "Some samples lie off their neighbours' surface by about half a grid spacing (too little for the outlier "
            "test, too much for the local fits to smooth out), which folds the closest points there: leave such "
            "samples out, pass a larger neighbours= to from_points (smoother fits), or use a coarser grid"
        )
        advice += self._strays_note()
        uneven = self._uneven()
        if uneven is not None:
            advice += (
                f". Or parts of the cloud are sampled too sparsely for their curvature: the widest fit spans "
                f"{self._sparsest_fit:.3g}, {uneven:.0f} times the median fit "
                "(sample those parts more densely, or pass a smaller neighbours=)"
            )
        crease = self._sampling_advice()
        if self.smoothing > 0:  # the last band's fits were widened for the noise
            advice = (
                f"The samples lie off their neighbours' fits by about {self.noise:.3g} (noise, or samples too sparse for "
                f"the surface's curvature; the fits reached {self.smoothing:.3g} to smooth it out, and the grid resolves "
                "the surface finer than that): use a coarser grid, or denser or less noisy samples. "
                f"Or: {advice[0].lower()}{advice[1:]}"
            )
        return f"{sentence(crease)}. Or: {advice}" if crease else advice

    def _strays_note(self) -> str:
        """Where outliers were left out: that stray points which remain near one another pass the
        outlier test and fold the closest points too, or "". 0.5% of a sphere's 20,000 samples
        replaced by points spread over a box: 32 of 100 left out, the others fitting one another
        in pairs, and the solve refused blaming samples "about half a grid spacing" off (a review)."""
        left_out = int(getattr(self, "report", {}).get("outliers", 0))
        if not left_out:
            return ""
        return (
            f". {left_out} samples were left out as outliers already: stray points that remain near one another (a "
            "scanner's, in pairs or small clusters off the surface) pass that test and fold the closest points too; "
            "remove them from the scan"
        )

    def _gap_note(self, h: float) -> str:
        """For the warning of parts that face each other across narrow gaps (``_facing.warn_facing_pairs``)
        on a grid of spacing ``h``: where the samples lie more than a grid spacing apart, such a gap
        can be a fold of the fits between them, and a finer grid only makes the samples sparser
        against it (150 samples of a sphere 2.7 spacings apart at N = 81: 5 pairs, 0.05% of the
        surface, and the advice to refine the grid ran into the sparse-sample refusal)."""
        if not self.spacing > h:
            return ""
        return (
            f"; here the cloud's samples lie {self.spacing / h:.1f} grid spacings apart, so such a gap may be a fold of "
            f"its fits between them, which a finer grid does not cure (it is refused below a spacing of "
            f"{self.spacing / SPARSE_FACTOR:.3g}): more samples there do"
        )

    #: What of a cloud the grid may not resolve, for the message of a second-order runaway
    #: (``second_order.ran_away_message``) and of a widened extension layer (``_prepare``).
    @property
    def unresolved_advice(self) -> str:
        """Where a cloud's closest points fold or bend more than the grid resolves: samples a little
        off their neighbours' surface, or on a noise-free cloud (:data:`NOISE_FREE`) the fits over
        unevenly spread samples; where the sampling is uneven, parts sampled too sparsely."""
        advice = "samples a little off their neighbours' surface, which a larger neighbours= smooths out"
        if self.noise < NOISE_FREE * self._median_fit:
            advice = (
                "the fits over unevenly spread samples, not noise, since the samples lie on their neighbours' fits to "
                f"{self.noise:.2g}: a scan taken in lines or slices, or rims and gaps left unsampled, where the closest "
                "points of neighbouring nodes come from fits over different samples; another neighbours=, whose fits "
                "span another number of lines, or denser samples there cure it"
            )
        uneven = self._uneven()
        if uneven is not None:
            advice = (
                f"parts of the cloud sampled too sparsely for the grid, where a fit spans up to {self._sparsest_fit:.3g}, "
                f"{uneven:.0f} times the median fit, and denser samples cure it; or " + advice
            )
        crease = self._crease_advice() or self._few_misses_advice()
        return f"{crease}; or {advice}" if crease else advice

    def _few_misses_advice(self) -> str:
        """Where a few samples (too few for sharp edges, :data:`CREASE_SHARE`) lie far off their
        neighbours' fits: stray points just off the surface that the outlier test kept, or "". Five
        such samples half a spacing off a clean sphere's 8,000 sent 37% of the inner tube to first
        order (mean error ×10), and the message blamed the fits over unevenly spread samples (a
        review)."""
        count, where = self._creases
        if count == 0 or where is None:
            return ""
        return (
            f"{count} samples that their neighbours' fits miss by far more than the noise (e.g. at ({_where(where)})), "
            "too few for a sharp edge: stray points just off the surface, which the outlier test kept, fold the "
            "closest points near them; where the trouble is near them, leave them out (cloud.crease_samples lists them)"
        )


def _where(point: Any) -> str:
    """A sample's coordinates for a message: ``"x, y, z"`` to four digits."""
    return ", ".join(f"{float(c):.4g}" for c in point)


def sentence(text: str) -> str:
    """``text`` with its first letter capitalised (the rest as it is: names such as ``neighbours=``)."""
    return text[:1].upper() + text[1:]
