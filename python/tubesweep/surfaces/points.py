"""Point clouds as closest-point surfaces (paper Sect. 5.2).

:func:`from_points` takes ``(M, 3)`` samples of a surface (``(M, 2)`` of a curve), or a file of
them (:func:`read_points`), and returns a :class:`PointCloudSurface`. Its closest point of ``x`` is
the moving-least-squares projection of ``x`` onto the samples, computed in the Rust core
(``tubesweep_core::surface::point_cloud``) on all threads and only at the band's candidate nodes:

* the k nearest samples (a kiddo kd-tree) of the current foot c, weighted by Wendland's function
  of their distance to c (support: the (k+1)-th nearest, so the weights are continuous in c);
* their weighted principal frame (the normal is the axis of least spread: no orientation needed)
  and the weighted least-squares quadric height function over it (a parabola for curves);
* Newton's method for the point of that graph nearest to x, and c ← that point, until it stops
  moving. The map is smooth at grid scale, so ``order="auto"`` runs second order on a closed cloud.

Before any solve the samples are analysed (``_cloud_analysis``): repeated samples (and samples
within a thousandth of the fits' median radius of another) are kept once, samples far off the fit
of their neighbours (outliers: beyond half the fit's radius and six times the samples' noise) are
left out with a warning, and samples with an empty angular sector among their neighbours mark a
rim (holes, the boundary of a scan). On a noisy cloud (a scan) the analysis takes wider
neighbourhoods, and the fits of the closest points reach 11 times the noise, up to 8 grid
spacings (:meth:`PointCloudSurface.smoothing_radius`). A cloud with a rim is an open
surface: nodes beyond the rim get closest points on it (the open-surface treatment of Sect. 5.2) and
``order="auto"`` runs the paper's first-order scheme. ``surface.report`` says what was found, and
where.
"""

from __future__ import annotations

import contextlib
import warnings
from pathlib import Path
from typing import Any, Dict, Iterator, Optional, Tuple, Union

import numpy as np

from ..closest_point import DIRECTION_EPS, ClosestPoint, _refuse_undefined_next_to
from .._linalg import row_norms
from ..grid import Grid
from ..band import BandGeometry, coarse_to_fine_candidates
from .._warn import user_stacklevel
from ._cloud_analysis import CURVE_NEIGHBOURS, CURVE_SPREAD, analyse, analyse_own, curve_spread, lines_advice, widen
from ._cloud_holes import bridged_holes, pairs_over_holes, warn_close_ends
from ._cloud_files import read_points
from ._cloud_input import checked_points
from ._cloud_widening import closest_with, keep_feet, known_feet
from ._cloud_advice import SPARSE_FACTOR, STRAY_SPACINGS, CloudAdvice, sentence

__all__ = ["from_points", "read_points", "PointCloudSurface"]

#: Neighbours of a fit (docs/point-clouds.md: 20 is the most accurate of 12–40 on the sphere).
DEFAULT_NEIGHBOURS = 20
#: A sample whose residual against its neighbours' fit exceeds this fraction of the fit's radius is
#: an outlier (``tubesweep_core::surface::point_cloud::OUTLIER_RATIO``).
OUTLIER_RATIO = 0.5
#: On a noisy cloud (noise above NOISY·Δx) the fits reach at least FIT_RADIUS grid spacings
#: (docs/point-clouds.md).
FIT_RADIUS = 3.0
NOISY = 0.005
#: ... and at least this many times the noise, so that a fit sees the noise as a thin layer
#: about the surface. Spheres with Gaussian noise of 0.5Δx (noise measured 0.45Δx): 20000 samples
#: at N = 61 folded with fits of 3Δx (second order ran away, first order off by 2.4Δx), not with
#: 5Δx; 50000 at N = 41 folded with 3.3Δx, not with 4.1Δx; noise Δx needed more than 6.5Δx (the
#: extension layer did not close) (``benches/experiments/noisy_clouds.py``)
NOISE_SPAN = 11.0
#: ... and wide enough that the noise averaged over the samples within the fit (noise/√samples)
#: stays under this fraction of Δx, which matters where the samples are sparse against the grid:
#: 5000 samples with noise 0.25Δx at N = 81 (0.7 samples per Δx²) did not close their extension
#: layer with fits of 3Δx
NOISE_AVERAGED = 0.03
#: A closed noisy cloud whose noise-wide fits would hold more than twice the samples they need
#: (this many, and enough to average the noise to NOISE_AVERAGED·Δx) fits a random share of its
#: samples instead (a fit costs in proportion to its samples: 50000 samples of a sphere with noise
#: 0.5Δx at N = 41 held 2000 per fit, and the band's closest points took 18 s)
FIT_SAMPLES = 400
#: ... but at most this many grid spacings (a wider fit flattens the surface's curvature): beyond
#: it the grid resolves the surface finer than its noise allows, which is warned of
MAX_SMOOTHING = 8.0
#: Noise above this many grid spacings is refused before the band is searched: a sphere of 20,000
#: samples (radius 0.6) at N = 61 solved with noise of 0.62, 0.80 and 0.97 spacings (largest errors
#: 0.33–0.47 spacings, 62–82 s), and with 1.07, 1.18 and 1.28 searched the band for 8–9 minutes
#: and then refused it (a review; scratch ``/tmp/s73/noise``)
NOISE_REFUSED = 1.0
#: A noisy cloud's rim of fewer samples than this is a step of its density, not a hole: 1 sample
#: at the equator of a sphere with noise 0.006, sampled 15 times more densely above it
#: (``tests/test_point_cloud_noise.py``); holes in noisy scans showed 4 and more
NOISY_RIM = 3
#: More outliers than this share of the samples: refused (the cloud is not a surface's samples).
MAX_OUTLIER_SHARE = 0.1
#: Samples closer to another than this fraction of the fits' median radius (the distance to the
#: (k+1)-th neighbour, which repeats do not shrink much, unlike the nearest-sample distance) are
#: near repeats: kept once (a fit over such pairs sees half as many distinct samples, and fails).
NEAR_REPEAT = 1e-3
#: A sample whose residual against its fit exceeds this fraction of the fit's radius (and the
#: noise's share, ``_cloud_analysis.SampleAnalysis.creases``) lies where the fits cannot follow the
#: surface: a sharp edge or corner. Noise-free samples of a 0.8³ box: 2.9% of them, of a cylinder
#: with flat caps 1.5%; of a sphere or a torus none; a sphere with noise of 1-2% of its radius
#: none (median residual 0.14-0.18).
CREASE_RESIDUAL = 0.05
#: Band nodes whose closest points come from their nearest sample's fit alone (``Foot::NearestFit``
#: of the Rust core: the fixed point wandered off the samples) are warned of above this share of
#: the band (a noise-free box's edges at N = 61: 71 of some 30k nodes; one sample 0.5Δx off a
#: sphere of 5000: one node, not warned of)
NEAREST_FIT_SHARE = 1e-3
#: Nodes per call of the native closest points (bounds the memory of a band's evaluation).
CHUNK = 1 << 20
#: A gap between two parts of a cloud wider than this many fit radii is kept apart (the band cut
#: across it): two sphere clouds 5 spacings apart at N = 61 (fits of 3 spacings) are, 4.6 and 4.8
#: apart still crossed (``benches/experiments/cloud_gaps.py``)
RESOLVED_GAP = 5.0 / 3.0


class PointCloudSurface(CloudAdvice, ClosestPoint):
    """A point cloud as a closest-point surface (moving-least-squares projection, see the module).

    Build it with :func:`from_points`.

    Attributes
    ----------
    points : numpy.ndarray
        The samples used (repeated and nearly repeated samples once, outliers left out).
    outliers : numpy.ndarray
        The samples left out as outliers (coordinates, ``(K, d)``).
    rim : numpy.ndarray
        Indices into ``points`` of the samples on a rim (holes, the boundary of a scan).
    crease_samples : numpy.ndarray
        Indices into ``points`` of the samples their neighbours' fits miss by far more than the
        noise: at sharp edges or corners, or samples off a smooth surface that the outlier test
        kept (``report["crease_samples"]`` counts them).
    open_surface : bool
        True when the cloud has a rim (second order then runs first order at the rim's nodes and
        beyond them, docs/point-clouds.md).
    report : dict
        Samples given, repeated (or within ``NEAR_REPEAT`` of the fits' median radius of another),
        outliers, rim samples, the spacing (median distance to the
        nearest sample), the density's range (``density_ratio``: the 95th over the 5th percentile
        of the fits' radii, to the power of the dimension; a part sparser than the rest that holds
        under 5 % of the samples does not show in it) and, after a solve, the band nodes whose closest point lies on the rim
        (``rim_nodes``) and those whose closest point came from their nearest sample's fit, where
        the fits found none (``nearest_fit_nodes``: first order there at best, warned of above
        0.1 % of the band).

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> rng = np.random.default_rng(0)
    >>> x = rng.normal(size=(5000, 3))
    >>> cloud = ts.surfaces.from_points(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
    >>> cloud.open_surface, len(cloud.rim)
    (False, 0)
    """

    #: The band is cut across the narrow gaps that the fits resolve (``tubesweep._shortcuts``,
    #: :meth:`resolved_gap`): two sheets a few spacings apart (a thin shell, the two sides of a thin
    #: part) are kept apart. Not at medial edges, as a mesh's is, nor across narrower gaps: the
    #: fits fold where the samples are sparse, and cuts there strand parts of the cloud or bend
    #: its distances (``benches/experiments/cloud_gaps.py``).
    cuts_shortcuts = True
    cuts_medial_edges = False
    _pairs_over_holes = pairs_over_holes  # facing pairs over a small hole: no gap (_prepare)
    _bridged_holes = bridged_holes  # the holes over which they lie, warned (stats.bridged_holes)
    _warn_thin_parts = warn_close_ends  # a curve's ends closer than its tubes, warned
    #: A gap this many grid spacings wide is resolved where the samples are dense (the fits'
    #: radius FIT_RADIUS·Δx): the grid spacing the narrow-gap warning advises is the gap over it.
    resolving_spacings = RESOLVED_GAP * FIT_RADIUS

    def resolved_gap(self, h: float) -> float:
        """The narrowest gap between two parts of the cloud that a solve on a grid of spacing
        ``h`` keeps apart (the band is cut across it; narrower gaps are warned about).

        It is :data:`RESOLVED_GAP` (5/3) times the fits' support radius, the larger of
        ``FIT_RADIUS``·Δx and the fits' median radius: across a narrower gap a fit centred on one
        side reaches the other's samples. Two sphere clouds 6 spacings apart at N = 61 (support 3
        spacings): cut, the outer sphere's mean error 0.13 → 4.9e-4 of a largest distance of
        1.57; 4 apart, 0.07, not cut and warned (``benches/experiments/cloud_gaps.py``).

        Parameters
        ----------
        h : float
            The grid spacing.

        Returns
        -------
        float
            The gap, in the cloud's units.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> x = np.random.default_rng(0).normal(size=(5000, 3))
        >>> cloud = ts.surfaces.from_points(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
        >>> round(cloud.resolved_gap(0.05), 3)  # 5 spacings
        0.25
        """
        return RESOLVED_GAP * max(FIT_RADIUS * h, self._median_fit)

    def _unresolved_gap_note(self, h: float) -> str:
        """Ends the warning of the gaps narrower than :meth:`resolved_gap` (``_prepare``)."""
        return (
            f"; the cloud's fits (radius {self.resolved_gap(h) / RESOLVED_GAP:.3g}) blend the two sides of a gap narrower than "
            f"{self.resolved_gap(h):.3g}, so the band is not cut there (it is across wider gaps)"
        )

    def __init__(
        self,
        points: Any,
        *,
        normals: Any = None,
        neighbours: int = DEFAULT_NEIGHBOURS,
        outliers: str = "remove",
        name: str = "point cloud",
    ):
        p = checked_points(points)
        d = p.shape[1]
        if isinstance(neighbours, bool) or not isinstance(neighbours, (int, np.integer)):
            raise TypeError(f"neighbours must be a whole number; got {neighbours!r}")
        low = 5 if d == 2 else 8
        if not low <= int(neighbours) <= 100:
            raise ValueError(
                f"neighbours must be between {low} and 100 (the fit has {3 if d == 2 else 6} coefficients); got {neighbours}"
            )
        if outliers not in ("remove", "raise"):
            raise ValueError(f"outliers must be 'remove' or 'raise'; got {outliers!r}")
        if normals is not None:
            n = checked_points(normals, "normals")
            if n.shape != p.shape:
                raise ValueError(f"normals must have the points' shape {p.shape}; got {n.shape}")
        given = len(p)
        unique, first = np.unique(p, axis=0, return_index=True)
        keep = np.sort(first)
        p = p[keep]
        self.normals: Optional[np.ndarray] = None if normals is None else n[keep]
        repeated = given - len(p)
        need = int(neighbours) + 2
        if len(p) < need:
            raise ValueError(
                f"the cloud has {len(p)} distinct points ({given} given); the fit needs at least {need} "
                f"(neighbours + 2, neighbours = {neighbours}): give more samples"
                + (" (all the points are the same)" if len(p) == 1 else "")
            )
        centred = p - p.mean(axis=0)
        sv = np.linalg.svd(centred, compute_uv=False)
        if d == 3 and sv[1] <= 1e-9 * sv[0]:
            raise ValueError(
                "the points all lie on one line: a cloud in 3D must sample a surface (for a curve give (M, 2) points)"
            )
        if d == 2 and sv[0] <= 0:
            raise ValueError("the points all coincide")
        self.ndim = d
        self.lipschitz = 1.0
        self._noise = 0.0
        self.name = name
        self.neighbours = int(neighbours)
        a = analyse_own(p, self.neighbours)
        if d == 3:
            spread = curve_spread(a.cloud, p, self.neighbours)
            if spread < CURVE_SPREAD:
                raise ValueError(
                    f"the points lie along a curve, not on a surface: around each sample, its "
                    f"{CURVE_NEIGHBOURS * self.neighbours} nearest spread across by {np.sqrt(spread):.2g} of their "
                    "spread along (the median). A cloud in 3D must sample a surface; a plane curve is given as (M, 2) "
                    "points (tubesweep has no geodesics along a space curve: they are its arclength)"
                )
        for _ in range(8):  # chains of near repeats: each round keeps one of each nearest pair
            near = a.spacing < NEAR_REPEAT * np.median(a.radius)
            if not near.any():
                break
            # a near repeat goes when its nearest sample comes first: the first of a cluster stays
            drop = near & (a.nearest.astype(np.int64) < np.arange(len(p)))
            p = p[~drop]
            if self.normals is not None:
                self.normals = self.normals[~drop]
            repeated += int(drop.sum())
            if len(p) < need:
                raise ValueError(
                    f"the cloud has {len(p)} distinct points ({given} given, {repeated} of them repeated or nearly: "
                    f"closer than {NEAR_REPEAT:g} of the fits' median radius to another); the fit needs at least {need}"
                )
            a = analyse_own(p, self.neighbours)
        a = widen(a, p)
        # a few samples apart from the rest fit one another and pass the residual test; a group
        # smaller than one fit cannot be a piece of surface (tubesweep_core's point_cloud::isolated)
        radius = np.ascontiguousarray(a.radius, dtype=np.float64)
        isolated = a.cloud.isolated(a.spacing, radius, float(np.nanmedian(radius)), need)
        bad = a.outliers(OUTLIER_RATIO) | isolated
        self.outliers = p[bad]
        if bad.any():
            where = tuple(round(float(c), 6) for c in p[np.flatnonzero(bad)[0]])
            share = float(np.mean(bad))
            n_iso = int(isolated.sum())
            apart = f"; {n_iso} of them in groups of fewer than {need} samples apart from the rest" if n_iso else ""
            if outliers == "raise" or share > MAX_OUTLIER_SHARE:
                raise ValueError(
                    f"{int(bad.sum())} of {len(p)} samples ({share:.1%}) lie off the surface their neighbours fit "
                    f"(farther than {OUTLIER_RATIO} of the fit's radius{apart}; the first at {where})"
                    + (
                        f": more than {MAX_OUTLIER_SHARE:.0%}, so the cloud is not the samples of one smooth surface "
                        "(too noisy, or too sparse for its curvature), or its samples come in lines (a scanner's) much "
                        "farther apart than along them, so that each fit's nearest samples lie on one line: then pass "
                        "a larger neighbours= (fits spanning several lines)"
                        if share > MAX_OUTLIER_SHARE
                        else "; pass outliers='remove' to leave them out"
                    )
                )
            warnings.warn(
                f"{int(bad.sum())} of {len(p)} samples lie off the surface their neighbours fit{apart} (the first at "
                f"{where}); they are left out (surface.outliers holds them)",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
            p = p[~bad]
            if self.normals is not None:
                self.normals = self.normals[~bad]
            if len(p) < need:
                raise ValueError(f"after leaving out the outliers {len(p)} samples remain; the fit needs {need}")
            a = analyse(p, self.neighbours)
        cloud = a.cloud
        rim_count = cloud.mark_rim(np.ascontiguousarray(a.gap))
        if 0 < rim_count < NOISY_RIM and a.analysis_radius is not a.radius:
            # a rim of one or two samples on a noisy cloud: a density step, not a hole (one the
            # noise-wide fits did not span would show more)
            rim_count = cloud.mark_rim(np.zeros(len(p)))
        self.points = p
        self._tree = cloud
        self.rim = np.flatnonzero(cloud.rim)
        self.open_surface = rim_count > 0
        self._lines = lines_advice(rim_count, len(p), self.neighbours) if d == 3 else ""
        if self._lines:
            warnings.warn(self._lines, RuntimeWarning, stacklevel=user_stacklevel())
        self.spacing = float(np.median(a.spacing))
        # the fits' radii: the median and the widest (the band's error names uneven sampling)
        self._median_fit = float(np.nanmedian(a.radius))
        self._sparsest_fit = float(np.nanmax(a.radius))
        #: the samples' noise: 1.4826 × the median distance of a sample from its neighbours' fit
        #: (over wider neighbourhoods on a noisy cloud, ``_cloud_analysis``)
        self.noise = a.noise
        cloud.set_noise(self.noise)
        # sharp edges and corners: samples their fit misses by far more than the noise
        crease = a.creases(CREASE_RESIDUAL, p)
        self._creases = (int(np.count_nonzero(crease)), p[int(np.argmax(crease))] if np.any(crease) else None)
        stray = crease & (np.asarray(a.spacing) > STRAY_SPACINGS * self.spacing)  # (kept outliers: _cloud_advice)
        self._strays = (int(np.count_nonzero(stray)), p[int(np.argmax(stray))] if np.any(stray) else None)
        #: the samples their fits miss (indices into ``points``): at sharp edges, or off the surface
        self.crease_samples = np.flatnonzero(crease)
        q05, q95 = np.quantile(a.radius, [0.05, 0.95])
        self.report: Dict[str, Any] = {
            "samples": given,
            "repeated": repeated,
            "outliers": len(self.outliers),
            "rim_samples": rim_count,
            "spacing": self.spacing,
            "noise": self.noise,
            "density_ratio": float(q95 / q05) ** d if q05 > 0 else float("inf"),
            "crease_samples": self._creases[0],
        }
        #: why order=2 does not apply (second_order.check_supported), or None
        self.order2_refusal: Optional[str] = None
        if self.open_surface:
            where = tuple(round(float(c), 4) for c in p[self.rim[0]])
            self.order2_refusal = (
                f"the point cloud has a rim (a hole or a boundary: {rim_count} samples, e.g. at {where}; "
                "surface.rim lists them)"
            )
        #: the smoothing radius ρ of the fits (set by the last band: smoothing_radius(Δx); 0 before)
        self.smoothing = 0.0
        self._cp = self._closest

    def _closest(self, x: np.ndarray) -> np.ndarray:
        cp, _ = self._fits().closest(np.ascontiguousarray(x, dtype=float), self.smoothing)
        return cp

    def _fit_share(self, h: float) -> float:
        """The share of the samples that the closest points' fits take on a grid of spacing ``h``:
        all (1.0), or on a closed noisy cloud whose noise-wide fits would hold more than twice the
        samples they need (:data:`FIT_SAMPLES`), a random share of them."""
        rho = self.smoothing_radius(h)
        if not rho or self.open_surface:
            return 1.0
        within = self._within(rho)
        need = max(FIT_SAMPLES, (self.noise / (NOISE_AVERAGED * h)) ** 2)
        return 1.0 if within < 2 * need else need / within

    def _fits(self) -> Any:
        """The native cloud whose fits give the closest points: the samples, or the random share
        of them that the last band chose (``_fit_share``; the same share, the same samples)."""
        share = getattr(self, "_share", 1.0)
        if share >= 1.0:
            return self._tree
        cached = getattr(self, "_thinned", None)
        if cached is None or cached[0] != share:
            from .. import _native

            m = len(self.points)
            keep = np.sort(np.random.default_rng(0).choice(m, max(int(share * m), self.neighbours + 2), replace=False))
            tree = _native.PointCloud(np.ascontiguousarray(self.points[keep]), self.neighbours)
            tree.set_noise(self.noise)
            self._thinned = cached = (share, tree)
        return cached[1]

    def __getstate__(self) -> dict:
        # the native kd-tree does not pickle: a copy builds it again
        state = self.__dict__.copy()
        state["_tree"] = None
        state["_thinned"] = None
        state["_cp"] = None
        state["_band_cache"] = None
        state["_widening_feet"] = None
        return state

    def __setstate__(self, state: dict) -> None:
        from .. import _native

        self.__dict__.update(state)
        self._tree = _native.PointCloud(np.ascontiguousarray(self.points), self.neighbours)
        self._tree.set_noise(self.noise)
        if len(self.rim):
            self._tree.mark_rim(
                np.ascontiguousarray(np.where(np.isin(np.arange(len(self.points)), self.rim), 9.0, 0.0))
            )
        self._cp = self._closest

    def __repr__(self) -> str:
        return (
            f"PointCloudSurface({self.name!r}, {len(self.points)} samples, ndim={self.ndim}, "
            f"spacing={self.spacing:.3g}, open={self.open_surface})"
        )

    def _far_distance(self, points: np.ndarray) -> np.ndarray:
        # a lower bound (the nearest sample's distance less the reach): the search keeps more blocks,
        # never fewer
        return np.asarray(self._tree.lower_bounds(np.ascontiguousarray(points, dtype=float)))

    def smoothing_radius(self, h: float) -> float:
        """The radius ρ over which the fits average the samples on a grid of spacing ``h``: 0 (the
        k nearest samples alone) on a clean cloud; on a noisy one (noise above 0.005·h) at least
        3·h (a fit over the k nearest alone has a curvature of noise/r², which makes the
        projection from the tube's far nodes unstable), 11 times the noise (:data:`NOISE_SPAN`:
        a fit then sees the noise as a thin layer about the surface) and wide enough to hold the
        samples that average the noise to 0.03·h (:data:`NOISE_AVERAGED`), up to 8·h (a wider fit
        flattens the surface's curvature; beyond it a warning names the spacing that resolves
        the noise).

        Parameters
        ----------
        h : float
            The grid spacing.

        Returns
        -------
        float
            ρ, in the cloud's units.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> x = np.random.default_rng(0).normal(size=(5000, 3))
        >>> cloud = ts.surfaces.from_points(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
        >>> cloud.smoothing_radius(0.05)  # noise-free
        0.0
        """
        if not self.noise > NOISY * h:
            return 0.0
        return float(np.clip(self._noise_reach(h), FIT_RADIUS * h, MAX_SMOOTHING * h))

    def _noise_reach(self, h: float) -> float:
        """The fits' reach that the noise asks for: NOISE_SPAN noises, and the radius within which
        the samples (:meth:`_within`) average the noise to NOISE_AVERAGED·h (on a surface; a
        curve's fits of NOISE_SPAN noises, with as few samples as a curve holds, stay within
        0.06Δx: 4000 samples of a circle with noise 0.5Δx at N = 101, ``tests/test_point_cloud_noise.py``)."""
        if self.points.shape[1] == 2:
            return NOISE_SPAN * self.noise
        return max(NOISE_SPAN * self.noise, self._median_fit * self._averaging() / h)

    def _averaging(self) -> float:
        """The averaging reach over the fits' median radius, times h^(2/(d − 1)): the samples
        within ρ, (k + 1)·(ρ / r)^(d − 1), reach (noise / (NOISE_AVERAGED·h))²."""
        return float(((self.noise / NOISE_AVERAGED) ** 2 / (self.neighbours + 1)) ** (1 / (self.points.shape[1] - 1)))

    def _within(self, rho: float) -> float:
        """About how many samples lie within ``rho`` of a point of the surface: (k + 1)·(ρ / r)^(d − 1),
        r the fits' median radius (the (k + 1)-th nearest sample's distance)."""
        return (self.neighbours + 1) * (rho / self._median_fit) ** (self.points.shape[1] - 1)

    def _warn_noise_unresolved(self, h: float) -> None:
        """Warns when the noise needs fits wider than MAX_SMOOTHING·h (once per grid spacing), and
        refuses the grid when the noise exceeds :data:`NOISE_REFUSED` grid spacings."""
        if not self._noise_reach(h) > MAX_SMOOTHING * h or getattr(self, "_noise_warned", None) == h:
            return
        # the averaging reach r·c·h^(−2/e) (e = d − 1) is MAX_SMOOTHING·h at h = (r·c / MAX_SMOOTHING)^(e/(e+2))
        e = self.points.shape[1] - 1
        averaged = (self._median_fit * self._averaging() / MAX_SMOOTHING) ** (e / (e + 2)) if e == 2 else 0.0
        coarser = max(NOISE_SPAN * self.noise / MAX_SMOOTHING, averaged)
        coarser = _round_up(coarser * (1 + 1e-9))  # (printed rounded to the nearest, it can fall short)
        if self.noise > NOISE_REFUSED * h:
            raise ValueError(
                f"the samples are too noisy for this grid: they lie off their neighbours' fits by about {self.noise:.3g} "
                f"({self.noise / h:.2g} grid spacings), more than the widest fits ({MAX_SMOOTHING:g} grid spacings) "
                "smooth out, and the closest points fold (the band would be searched for minutes and then not close). "
                f"Use a grid spacing ≥ {coarser:.3g} (now {h:.3g}; e.g. surface.grid(n) with a smaller n), or denser or "
                "less noisy samples"
            )
        self._noise_warned = h
        warnings.warn(
            f"the samples are noisy for this grid: they lie off their neighbours' fits by about {self.noise:.3g} "
            f"({self.noise / h:.2g} grid spacings; noise, or samples too sparse for the surface's curvature), and fits "
            f"of {MAX_SMOOTHING:g} grid spacings (the widest, not to flatten the surface) leave part of it in the "
            "closest points, which may fold; the distances are uncertain by about as much. A grid spacing ≥ "
            f"{coarser:.3g} (now {h:.3g}) lets the fits smooth it out, or denser samples do",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )

    @contextlib.contextmanager
    def _band_widening(self) -> Iterator[None]:
        """While the tube's preparation widens the band: the feet found kept for the wider bands
        (:mod:`._cloud_widening`)."""
        self._widening_feet: Optional[dict] = {}
        try:
            yield
        finally:
            self._widening_feet = None

    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        """The band nodes within ``half_width`` of the cloud's surface, found coarse-to-fine (a lower
        bound of the distance from the nearest sample), their closest points computed once, in Rust
        on all threads, and kept for the second-order geometry.

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance).

        Returns
        -------
        BandGeometry

        Raises
        ------
        ValueError
            If the samples are much sparser than the grid (the message names the spacing needed),
            or a fit fails next to the band.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
        >>> circle = ts.surfaces.from_points(0.5 * np.c_[np.cos(t), np.sin(t)])
        >>> grid = circle.grid(61)
        >>> len(circle.band(grid, 4 * grid.spacing).linear) > 0
        True
        """
        self.check_grid(grid)
        h = grid.spacing
        d = grid.ndim
        if self.spacing > SPARSE_FACTOR * h:
            raise ValueError(
                f"the samples are {self.spacing:.3g} apart (median distance to the nearest sample), "
                f"{self.spacing / h:.1f} grid spacings: the grid resolves the surface finer than the samples do. "
                f"Use a grid with spacing ≥ {self.spacing / SPARSE_FACTOR:.3g} (e.g. surface.grid(n) with a smaller n) "
                "or denser samples"
            )
        self.smoothing = self.smoothing_radius(h)
        self._share = self._fit_share(h)
        if self.smoothing:
            self._warn_noise_unresolved(h)
        fits = self._fits()
        candidates = coarse_to_fine_candidates(grid, half_width, 1.0, lambda p, reach: self._far_distance(p))
        parts: list = []
        undefined = []
        known = known_feet(self, grid)
        computed: list = []
        for s0 in range(0, len(candidates), CHUNK):
            lin = candidates[s0 : s0 + CHUNK]
            x = grid.node_points(lin)
            cp, feet = closest_with(known, fits, lin, x, self.smoothing, half_width)
            norm = row_norms(x - cp)
            keep = norm <= half_width  # False where the fit failed (NaN)
            found = np.isfinite(norm)
            if known is not None:  # (widening: every node's foot found is kept, nearer or farther)
                computed.append((lin[found], cp[found], feet[found]))
            undefined.append(lin[~found])
            parts.append((lin[keep], norm[keep], x[keep], cp[keep], feet[keep]))
        if known is not None:
            self._widening_feet = keep_feet(known, grid, self.smoothing, computed)
        if not parts or sum(len(q[0]) for q in parts) == 0:
            self._band_cache = None
            return BandGeometry(np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros((0, d), np.float32))
        linear, norm, x, cp, feet = (np.concatenate([q[i] for q in parts]) for i in range(5))
        crease = self._sampling_advice()
        _refuse_undefined_next_to(
            grid,
            np.concatenate(undefined),
            linear,
            "the cloud's local fits find no surface there (their feet wander off the samples). "
            + (f"{sentence(crease)}. Or: some" if crease else "Some")
            + " samples lie off "
            "their neighbours' surface by about half a grid spacing (too little for the outlier test, too much for "
            "the local fits to smooth out)"
            + (
                f", or the samples are noisy (noise ≈ {self.noise:.3g}, {self.noise / h:.2f} grid spacings)"
                if self.noise > NOISY * h
                else ""
            )
            + ": leave such samples out, pass a larger neighbours= to from_points (smoother fits), or use a coarser grid"
            + self._strays_note(),
        )
        self.report["rim_nodes"] = int(np.count_nonzero(feet == 1))
        # feet whose fixed point wandered off the samples, from the query and from its nearest
        # sample: projected onto that sample's own fit instead (Foot::NearestFit)
        self.report["nearest_fit_nodes"] = nearest = int(np.count_nonzero(feet == 3))
        if nearest > NEAREST_FIT_SHARE * len(linear) and getattr(self, "_nearest_fit_warned", None) != grid:
            self._nearest_fit_warned = grid  # (once per grid: a widened layer searches the band again)
            warnings.warn(
                f"{nearest} of the {len(linear)} band nodes ({100 * nearest / len(linear):.2g}%) have closest points "
                "that the cloud's local fits do not find (their fixed point wanders off the samples): each was "
                "projected onto its nearest sample's own fit instead, which keeps it among the samples but is not "
                f"smooth, so the distances there are first order at best (cloud.report['nearest_fit_nodes']). The cause: "
                f"{self.unresolved_advice}",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        self._warn_creases(grid)
        # the map's noise near the surface (for the facing-sheets test): |cp(cp(x)) − cp(x)|, and
        # the fitted surface's own wiggle, the samples' noise averaged over a fit's samples (their
        # count within ρ, over the Wendland weights' and the quadric's share: 1/18; at noise
        # 0.25Δx, ρ = 3Δx, the surface of 20000 sphere samples wiggles by ±0.1Δx, and nodes
        # 0.02–0.1Δx off it on either side looked like sheets facing each other)
        pick = np.linspace(0, len(linear) - 1, min(len(linear), 512)).astype(np.int64)
        again, _ = fits.closest(np.ascontiguousarray(cp[pick]), self.smoothing)
        samples = self._within(max(self.smoothing, self._median_fit)) * self._share
        self._noise = max(float(np.quantile(row_norms(again - cp[pick]), 0.9)), self.noise * np.sqrt(18.0 / samples))
        self._band_cache = (x, cp)
        ok = norm > DIRECTION_EPS * h
        direction = np.zeros((len(linear), d))
        direction[ok] = (x[ok] - cp[ok]) / norm[ok, None]
        return BandGeometry(linear, norm, norm.copy(), direction.astype(np.float32), consumable=True)

    def closest_point(self, points: np.ndarray) -> np.ndarray:
        """The closest points on the cloud's surface (moving-least-squares projection; NaN where
        no fit exists).

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M, d)`` closest points.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
        >>> circle = ts.surfaces.from_points(0.5 * np.c_[np.cos(t), np.sin(t)])
        >>> np.round(circle.closest_point(np.array([[1.0, 0.0]])), 6).tolist()
        [[0.5, 0.0]]
        """
        p = np.ascontiguousarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != self.ndim:
            raise ValueError(f"points must have shape (M, {self.ndim}); got {p.shape}")
        cache = getattr(self, "_band_cache", None)
        if cache is not None and cache[0].shape == p.shape and np.array_equal(cache[0], p):
            return cache[1].copy()  # the band's nodes again (the second-order geometry)
        out = np.empty_like(p)
        for s0 in range(0, len(p), CHUNK):
            out[s0 : s0 + CHUNK], _ = self._fits().closest(p[s0 : s0 + CHUNK], self.smoothing)
        return out

    # ------------------------------------------------------------------ conveniences
    @property
    def default_source(self) -> np.ndarray:
        """The sample farthest from the samples' mean."""
        p = self.points
        return p[int(np.argmax(((p - p.mean(0)) ** 2).sum(1)))].copy()

    @property
    def bounds(self) -> Tuple[np.ndarray, np.ndarray]:
        return self.points.min(0), self.points.max(0)

    def grid(self, n: int = 101, padding: float = 8.0) -> Grid:
        """A grid around the cloud with the same spacing in every axis: ``n`` nodes along the longest
        side of the bounding box, ``padding`` empty spacings beyond it on every side.

        Parameters
        ----------
        n : int
            Nodes along the longest axis (at least ``2·padding + 3``).
        padding : float
            Spacings between the bounding box and the grid's faces.

        Returns
        -------
        Grid

        Raises
        ------
        ValueError
            If ``n`` cannot hold the padding.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
        >>> ts.surfaces.from_points(np.c_[np.cos(t), np.sin(t)]).grid(61).shape
        (61, 61)
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
            raise TypeError(f"n must be a whole number of nodes along the longest axis; got {n!r}")
        if not (np.isfinite(padding) and padding >= 0) or n < 2 * padding + 3:
            raise ValueError(f"n = {n} nodes cannot hold {padding} spacings of padding on both sides")
        lo, hi = self.bounds
        ext = hi - lo
        h = float(ext.max()) / (n - 1 - 2 * padding)
        counts = np.maximum(3, np.ceil(ext / h - 1e-9).astype(int) + 1 + int(np.ceil(2 * padding)))
        counts[int(np.argmax(ext))] = n
        lower = 0.5 * (lo + hi) - 0.5 * h * (counts - 1)
        return Grid(lower, lower + h * (counts - 1), counts)


def from_points(
    points: Union[str, Path, Any],
    normals: Any = None,
    *,
    neighbours: int = DEFAULT_NEIGHBOURS,
    outliers: str = "remove",
) -> PointCloudSurface:
    """A point cloud as a surface for :func:`tubesweep.solve` (closest points by moving least squares).

    Parameters
    ----------
    points : array_like or str or pathlib.Path
        ``(M, 3)`` samples of a surface (``(M, 2)`` of a curve), or a point file
        (:func:`read_points`: ``.xyz``, ``.txt``, ``.csv``, ``.pts``, ``.npy``, ``.ply``).
    normals : array_like, optional
        ``(M, d)`` normals, kept for :func:`tubesweep.export`; not needed (the fits find the normals,
        and no orientation is used).
    neighbours : int
        Samples in each local fit (default 20; more smooths more noise and blurs more curvature).
    outliers : {"remove", "raise"}
        Samples off the surface their neighbours fit: left out with a warning, or an error.

    Returns
    -------
    PointCloudSurface

    Raises
    ------
    ValueError
        An empty cloud, NaN or inf samples, fewer distinct samples than the fit needs, samples all
        on one line (3D), more than 10 % outliers (or any, with ``outliers="raise"``), a file that
        is not a point file. At solve time: samples much sparser than the grid (the message names
        the spacing needed).
    TypeError
        If ``points`` is not numbers.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> rng = np.random.default_rng(1)
    >>> x = rng.normal(size=(20000, 3))
    >>> cloud = ts.surfaces.from_points(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
    >>> sol = ts.solve(cloud, ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3), sources=[cloud.points[0]])
    >>> sol.stats.order
    2
    """
    name = "point cloud"
    if isinstance(points, (str, Path)):
        name = Path(points).stem
        points = read_points(points)
    surface = PointCloudSurface(points, normals=normals, neighbours=neighbours, outliers=outliers, name=name)
    return surface


def _round_up(x: float, digits: int = 3) -> float:
    """``x`` rounded up to ``digits`` significant digits."""
    unit = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(np.ceil(x / unit) * unit)
