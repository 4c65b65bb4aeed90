"""The per-sample analysis of a point cloud (``PointCloudSurface``, paper Sect. 5.2): each
sample's spacing, its fit's radius, its leave-one-out residual against that fit and the largest
angular gap of its neighbours around it (``tubesweep_core::surface::point_cloud``'s ``analyse``),
from which the outliers, the rim, the samples' noise and the creases are read.

On a noisy cloud (a scan) the fits over the cloud's k nearest neighbours are too narrow to tell the
noise from the surface: a sample far off the surface sees its nearest neighbours on one side (a
false rim, which makes a closed scan an open surface and sends ``order="auto"`` to first order),
and the residuals of the Gaussian tail pass half a fit's radius (false outliers, left out with a
warning). Where the noise exceeds :data:`NOISY_FIT` of the fits' median radius, the residuals and
the gaps are therefore taken over neighbourhoods wide enough to span :data:`NOISE_SCALE` times
the noise (at most 100 neighbours; the closest points keep the cloud's own ``neighbours``, and
are smoothed over a radius set by the noise and the grid, ``PointCloudSurface.smoothing_radius``),
and an outlier must also lie :data:`OUTLIER_NOISE` times the noise off its fit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

__all__ = [
    "SampleAnalysis",
    "analyse",
    "analyse_own",
    "widen",
    "NOISY_FIT",
    "NOISE_SCALE",
    "OUTLIER_NOISE",
    "WIDEST",
    "MIN_THINNED",
    "MIN_THINNED_CURVE",
    "THINNING_ROUNDS",
]

#: A cloud whose noise exceeds this fraction of its fits' median radius is analysed over wider
#: neighbourhoods: over 20 neighbours, 20000 samples of a sphere with noise of 0.25–1 grid
#: spacings at N = 61 (noise/radius 0.22–0.28) showed 16–84 false rim samples (single runs;
#: ``tests/test_point_cloud_noise.py`` checks that such a cloud now shows none).
NOISY_FIT = 0.1
#: ... wide enough to reach this many times the noise: those clouds show no rim over 60–100
#: neighbours.
NOISE_SCALE = 8.0
#: A wide neighbourhood's empty sector (radians) above which the sample's own neighbourhood
#: decides whether it lies on a rim (its gap over 120°, ``point_cloud::RIM_GAP``): a hole about as
#: wide as the wide neighbourhood leaves it some 110° from the hole's edge.
WIDE_RIM_GAP = np.pi / 2
#: The widest analysis (the Rust core's limit of neighbours).
WIDEST = 100
#: An outlier lies farther off its fit than half the fit's radius (``points.OUTLIER_RATIO``) and
#: than this many times the samples' noise: the Gaussian noise of those clouds put 0.8–3 % of the
#: samples beyond half a fit's radius (single runs; the test above checks that none is left out).
OUTLIER_NOISE = 6.0
#: A sample its fit misses counts as a sharp edge's with at least this many more such samples
#: among its own neighbours (an edge is a line of them; the noise's tail is scattered).
CREASE_CLUSTER = 1
#: ... and misses by more than this many times the noise (the floor of 5 % of the fit's radius is
#: two noises on a sphere with noise 0.001, and the tail beyond it clusters by chance)
CREASE_NOISE = 3.0
#: Rounds of thinning, and the fewest samples a thinned cloud keeps.
THINNING_ROUNDS = 4
MIN_THINNED = 1000
MIN_THINNED_CURVE = 250
#: The noise of Gaussian samples from the median of their absolute deviations.
MAD_TO_SIGMA = 1.4826


@dataclass
class SampleAnalysis:
    """What ``analyse`` found, per sample (``points``' order)."""

    #: the native cloud fitted over the cloud's own ``neighbours`` (its closest points)
    cloud: Any
    #: distance to the nearest other sample
    spacing: np.ndarray
    #: radius of the fit over the cloud's own neighbours (the distance to the (k+1)-th)
    radius: np.ndarray
    #: the nearest other sample
    nearest: np.ndarray
    #: leave-one-out residual over the analysis fit's radius (NaN: a degenerate neighbourhood)
    residual: np.ndarray
    #: the analysis fit's radius (``radius``, or wider on a noisy cloud)
    analysis_radius: np.ndarray
    #: the largest angular gap of the neighbours around the sample, in radians
    gap: np.ndarray
    #: the cloud's own neighbours (its fits of the closest points)
    neighbours: int
    #: the neighbours of the analysis fits
    analysis_neighbours: int
    #: the noise measured on a thinned cloud (where the noise is thicker than the widest fits)
    thinned_noise: Optional[float] = None

    @property
    def noise(self) -> float:
        """The samples' noise: 1.4826 × the median distance of a sample from its fit."""
        if self.thinned_noise is not None:
            return self.thinned_noise
        return _noise(self.residual, self.analysis_radius)

    def _share(self) -> float:
        """The noise over the analysis fits' median radius."""
        median_fit = float(np.nanmedian(self.analysis_radius))
        return self.noise / median_fit if median_fit > 0 else 0.0

    def outliers(self, ratio: float) -> np.ndarray:
        """The samples farther off their fit than ``ratio`` of its radius and than
        :data:`OUTLIER_NOISE` times the noise (NaN residuals: degenerate neighbourhoods)."""
        off = self.residual * self.analysis_radius
        return ~((self.residual <= ratio) | (off <= OUTLIER_NOISE * self.noise))

    def creases(self, ratio: float, points: np.ndarray) -> np.ndarray:
        """The samples of ``points`` that their fits miss by more than ``ratio`` of the fit's
        radius and four times the median residual (over a noisy cloud's wider neighbourhoods, six
        times the noise), with at least :data:`CREASE_CLUSTER` such samples among their
        ``neighbours`` nearest: sharp edges and corners, which are lines of such samples. The
        noise's Gaussian tail passes the residual test alone on 1 % of a smooth cloud's samples
        (20000 samples of a sphere with noise 0.003: 228, taken for sharp edges), scattered; six
        noises on every cloud lost a box's edges under noise of 0.002 (the edges' misfit raises
        the measured noise: 338 edge samples without noise, 3)."""
        if self.analysis_radius is self.radius:
            floor = max(ratio, 4.0 * float(np.nanmedian(self.residual)))
            candidate = (self.residual > floor) & (self.residual * self.radius > CREASE_NOISE * self.noise)
        else:
            off = self.residual * self.analysis_radius
            candidate = (self.residual > ratio) & (off > OUTLIER_NOISE * self.noise)
        which = np.flatnonzero(candidate)
        if which.size == 0:
            return candidate
        k = min(self.neighbours + 1, len(points))
        # (the native cloud's kd-tree, of these same points; the sample itself is among its
        # nearest, and a candidate)
        near = self.cloud.nearest_samples(which.astype(np.int64), k)
        clustered = candidate[near.astype(np.int64)].sum(axis=1) > CREASE_CLUSTER
        out = np.zeros_like(candidate)
        out[which[clustered]] = True
        return out


def analyse(points: np.ndarray, neighbours: int) -> SampleAnalysis:
    """The cloud of ``points`` fitted over ``neighbours`` and its samples' analysis, over wider
    neighbourhoods where the noise is a sizeable part of the fits (:data:`NOISY_FIT`)."""
    return widen(analyse_own(points, neighbours), points)


def analyse_own(points: np.ndarray, neighbours: int) -> SampleAnalysis:
    """The analysis over the cloud's own ``neighbours`` alone (what the near repeats need)."""
    from .. import _native

    p = np.ascontiguousarray(points)
    cloud = _native.PointCloud(p, neighbours)
    spacing, radius, residual, gap, nearest = cloud.analyse()
    return SampleAnalysis(cloud, spacing, radius, nearest, residual, radius, gap, neighbours, neighbours)


def widen(analysis: SampleAnalysis, points: np.ndarray) -> SampleAnalysis:
    """``analysis`` (of ``points``, over their own neighbours) with the residuals, gaps and noise
    taken over wider neighbourhoods where the noise is a sizeable part of the fits."""
    from .. import _native

    p = np.ascontiguousarray(points)
    neighbours = analysis.analysis_neighbours
    share = analysis._share()
    if not share > NOISY_FIT:
        return analysis
    # a neighbourhood's radius grows as the square root of its samples on a surface (linearly on a
    # curve, whose analysis is then wider still: a noisy circle's samples, noise 1Δx at N = 101,
    # showed a false rim over 50 neighbours, none over 100)
    wide = int(np.ceil((neighbours + 1) * (NOISE_SCALE * share) ** 2)) - 1
    wide = min(max(wide, neighbours), WIDEST, len(p) - 2)
    if wide <= neighbours:
        return analysis
    # the gaps: bridged only as far as the cloud's own fits reach (a hole narrower than twice the
    # wide fits' radius is no thinner sampling), and where the wide neighbourhood spans a hole
    # (an empty sector of over 90° then), the own neighbourhood's gap decides. A hole 0.24 across
    # in 20000 samples of a sphere of radius 0.6 with noise 0.02 showed 14–41 rim samples over 20
    # neighbours (and false ones elsewhere), 0–6 over 100
    own_gap = analysis.gap
    _, analysis.analysis_radius, analysis.residual, wide_gap, _ = _native.PointCloud(p, wide).analyse(
        2.0 * analysis.cloud.reach
    )
    analysis.gap = np.where(wide_gap > WIDE_RIM_GAP, np.maximum(own_gap, wide_gap), wide_gap)
    analysis.analysis_neighbours = wide
    # noise thicker than the widest fits reach (a dense scan: 50000 samples of a sphere with noise
    # of 8 % of its radius, some ten spacings; the fits follow the noise, and measured a third of
    # it): measured again on random subsets, each sparser by the square of the noise's share
    thinned = p
    rng = np.random.default_rng(0)
    share = analysis._share()
    # (at least four times sparser a round: fits that follow the noise read too small a share)
    fewest = MIN_THINNED if p.shape[1] == 3 else MIN_THINNED_CURVE
    for _ in range(THINNING_ROUNDS):
        keep = int(len(thinned) / float(np.clip((share / NOISY_FIT) ** 2, 4.0, 16.0)))
        if not share > NOISY_FIT or keep < fewest:
            break
        thinned = np.ascontiguousarray(thinned[np.sort(rng.choice(len(thinned), keep, replace=False))])
        _, radius_t, residual_t, _, _ = _native.PointCloud(thinned, min(wide, keep - 2)).analyse()
        analysis.thinned_noise = max(_noise(residual_t, radius_t), analysis.noise)
        share = analysis.thinned_noise / float(np.nanmedian(radius_t))
    return analysis


def _noise(residual: np.ndarray, radius: np.ndarray) -> float:
    """1.4826 × the median distance of a sample from its fit."""
    return MAD_TO_SIGMA * float(np.nanmedian(residual * radius))


#: A 3D cloud with more than this share of its samples on a rim is likely sampled in lines (a
#: scanner's) farther apart than along them: each fit's nearest samples lie on a line or two, and
#: their angular gaps say rim (latitude rings of a sphere 0.026 apart with samples 0.002 along
#: them: 51% of 57,249 samples; a hemisphere shows 1.9%, a strip 20 times longer than wide 5.5%).
LINES_RIM_SHARE = 0.25
#: ... and at least this many samples: a small patch's rim is a large share of it (27–42% of
#: discs of 60–150 samples; a patch's rim share falls as one over the square root of its size).
LINES_MIN_SAMPLES = 2000


def lines_advice(rim: int, samples: int, neighbours: int) -> str:
    """What a rim of ``rim`` of ``samples`` samples over ``neighbours`` neighbours says when it is
    over :data:`LINES_RIM_SHARE`, or "" (for the warning of ``PointCloudSurface`` and its band's
    error)."""
    if samples < LINES_MIN_SAMPLES or rim <= LINES_RIM_SHARE * samples:
        return ""
    return (
        f"{rim} of the {samples} samples ({rim / samples:.0%}) see their neighbours on one side only, as on a rim: the "
        "samples may come in lines (a scanner's) much farther apart than the samples along them, so that the "
        f"{neighbours} nearest samples of each fit lie on a line or two and cannot tell the surface's shape across "
        "the lines. Pass a larger neighbours= to from_points (fits spanning several lines; latitude rings of a "
        "sphere 13 sample spacings apart needed neighbours=100), or thin the samples along the lines"
    )


#: A 3D cloud whose neighbourhoods of :data:`CURVE_NEIGHBOURS` × the fit's samples spread across
#: by less than this share of their spread along (the median of the second over the largest
#: eigenvalue of their covariance) samples a curve, not a surface: a circle or a helix of 3000
#: samples over 20 neighbours 4.5e-4, the circle with noise of 0.6% of its radius 0.018; a
#: sphere 0.80, a hemisphere 0.78, a strip 20 times longer than wide 0.69, a sphere sampled in
#: latitude rings 13 sample spacings apart 0.73 (``benches/experiments/cloud_curves.py``).
CURVE_SPREAD = 0.05
#: ... neighbourhoods this many times the fits' (a scanner's lines are reached across).
CURVE_NEIGHBOURS = 4
#: ... measured at up to this many samples, evenly strided.
CURVE_SAMPLES = 1000


def curve_spread(cloud: Any, points: np.ndarray, neighbours: int) -> float:
    """The median, over up to :data:`CURVE_SAMPLES` samples, of the second over the largest
    eigenvalue of the covariance of each one's ``CURVE_NEIGHBOURS·neighbours`` nearest samples:
    about 1 on a surface, near 0 on a curve (:data:`CURVE_SPREAD`)."""
    k = min(CURVE_NEIGHBOURS * int(neighbours), len(points) - 1)
    which = np.unique(np.linspace(0, len(points) - 1, min(CURVE_SAMPLES, len(points))).astype(np.int64))
    near = np.asarray(cloud.nearest_samples(which, k), dtype=np.int64).reshape(len(which), -1)
    x = points[near]
    x = x - x.mean(axis=1, keepdims=True)
    eig = np.linalg.eigvalsh(np.einsum("mki,mkj->mij", x, x))  # ascending
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = eig[:, -2] / eig[:, -1]
    return float(np.nanmedian(ratio)) if np.any(np.isfinite(ratio)) else 1.0
