//! Point clouds as closest-point surfaces (paper Sect. 5.2): the closest point of x is its
//! moving-least-squares projection onto local fits of the samples (`fit.rs`).
//!
//! The surface is the set of points y that lie on the fit centred at y itself (a weighted quadric
//! height function over the k nearest samples of y, in their principal frame). The closest point of
//! x is found by the fixed-point iteration c ← the projection of x onto the fit centred at c,
//! starting from c = x; it stops when the foot moves by less than 1e-12 of the fit's radius (a few
//! iterations in the tube). The weights are continuous in c, so the map is smooth at grid scale,
//! which the second-order geometry needs (it differentiates x − cp(x) twice).
//!
//! Samples are analysed once (`analyse`): the distance to the nearest other sample (the spacing),
//! the support radius, the leave-one-out residual of each sample against the fit of its neighbours
//! (outliers), and the largest angular gap of its 2k nearest neighbours around it in the tangent
//! plane (a gap wider than [`RIM_GAP`] marks a sample on a rim: a hole or the boundary of an open
//! scan), unless samples farther out fill it ([`PointCloud::bridged_gap`]: where the sampling
//! only thins, the last dense samples see all their 2k neighbours on one side). On a cloud with a
//! rim, a foot that leaves the convex hull of its neighbours in the tangent plane is moved back to
//! the hull's boundary, so nodes beyond the rim get closest points on the rim, as for the
//! library's open surfaces.

pub(crate) mod fit;
mod isolated;

pub use isolated::LINK;

use crate::error::{Error, Result};
use fit::{basis_len, clamp_to_hull, distance, gap_and_bisector, Fit};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use std::num::NonZero;

/// The default number of neighbours in a fit (measured in docs/point-clouds.md).
pub const DEFAULT_NEIGHBOURS: usize = 20;
/// A sample whose leave-one-out residual exceeds this fraction of its fit's radius is an outlier.
pub const OUTLIER_RATIO: f64 = 0.5;
/// Angular gap (radians) among a sample's 2k nearest neighbours in its tangent plane above which
/// the sample lies on a rim (120°; an interior sample of a uniformly random cloud reaches it with
/// probability about 40·(1 − 120/360)³⁹ ≈ 6e-6, and then rarely with two more beside it).
pub const RIM_GAP: f64 = 120.0 / 180.0 * std::f64::consts::PI;
/// A rim sample counts only with at least this many rim samples among its k nearest neighbours (a
/// rim is a curve of samples; in 3D only).
pub const RIM_CLUSTER: usize = 2;
/// A foot found from a neighbour's foot farther from the query than twice its nearest sample plus
/// this fraction of the neighbourhood's radius is found again from the query itself
/// ([`PointCloud::closest_points`]).
const STALE_START: f64 = 0.1;
/// A foot farther than this fraction of its neighbourhood's radius from every sample lies between
/// two sheets that the neighbourhood blends (on one sheet a foot lies within about a sample
/// spacing of a sample: 0.1 of the radius on a curve, 0.3 on a surface, with k = 20).
const BLENDED_HOLE: f64 = 0.6;
/// A sample beyond a fit's own neighbours farther from its graph than this fraction of its
/// distance lies on another sheet and fills no gap around the sample (the next turn of a spiral
/// near its end: 0.9 and more; a noisy sheet's samples, noise 0.75 of their spacing, reach it
/// now and then).
const ANOTHER_SHEET: f64 = 0.85;
/// On a curve (2D), a sample is an end when its nearest neighbour on one side lies farther than
/// this many times the mean spacing of its neighbours (their consecutive distances along the
/// fit, the largest left out), and a sample found farther out across that gap closes it only
/// within this many spacings (the larger of the two samples'). A C-shaped curve of 2,000 samples
/// of a circle of radius 0.5 (spacing 0.0016, k = 20) had gaps up to 0.065, 40 spacings, closed by
/// the fits and the distance from one end to the other came out as the gap instead of the way
/// round, unwarned. Random sampling puts a gap above 11 mean spacings once in some 60,000 gaps
/// (exponential gaps); a first rule of 4 of the two samples' own spacings made false ends on
/// randomly sampled and noisy circles (27–388 of 200–4,000 samples; a review).
const END_SPACINGS: f64 = 11.0;
/// ... or farther than this many times the fit's misfit (its samples' noise): on a noisy sphere
/// (noise 0.75 of the spacing) the samples beyond the fit's own stay within it.
const NOISE_MARGIN: f64 = 4.0;
/// A foot farther from its query than the query's nearest sample by more than this fraction of
/// the neighbourhood's radius plus [`NOISY_FOOT`] times the samples' noise is found again from that
/// sample, and the nearer foot kept ([`PointCloud::closest_points`]; between the turns of a spiral
/// 8 spacings apart, a node 3.8 spacings from one turn had its foot on the other, 4.2 away).
const FARTHER_FOOT: f64 = 0.02;
/// ... (without the noise a scan's noise of 0.3Δx set the check off at most nodes of a sphere, for
/// 1.7 times the band's set-up time).
const NOISY_FOOT: f64 = 3.0;
/// A foot farther than this many times [`PointCloud::reach`] from every sample lies off the
/// samples. The rim test bridges a hole whose far side a probe at up to twice the reach finds
/// within half that distance ([`PointCloud::bridged_gap`]): its middle lies up to 1.5 reaches
/// from the samples.
const BRIDGED_REACH: f64 = 1.5;
/// A neighbourhood whose samples all lie at its radius from the centre (ties) reaches this
/// fraction farther ([`PointCloud::neighbourhood`]).
const TIED_RADIUS: f64 = 1e-6;
/// Queries per block of [`PointCloud::closest_points`].
const BLOCK: usize = 256;
/// Iterations of the fixed point c ← foot(x; fit at c).
const MAX_ITERATIONS: usize = 12;
/// The fixed point stops when the foot moves by less than this fraction of the fit's radius.
const TOLERANCE: f64 = 1e-10;

/// What a closest-point query found, per point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Foot {
    /// On the surface, inside the samples.
    Interior = 0,
    /// Moved back to the rim of an open cloud.
    Rim = 1,
    /// No fit (a degenerate neighbourhood): the closest point is NaN.
    Failed = 2,
    /// The fixed point wandered off the samples from the query and from its nearest sample: the
    /// projection onto the nearest sample's own fit, kept within its neighbours (a last resort, as
    /// accurate as that fit where the surface is smooth, a sample spacing or so at a crease).
    NearestFit = 3,
}

/// Per-sample analysis of a cloud (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct SampleAnalysis {
    /// Distance to the nearest other sample.
    pub spacing: Vec<f64>,
    /// The fit's support radius at the sample (distance to its (k+1)-th neighbour).
    pub radius: Vec<f64>,
    /// Leave-one-out residual over the radius; NaN where the neighbourhood is degenerate.
    pub residual: Vec<f64>,
    /// Largest angular gap (radians) of the 2k nearest neighbours around the sample.
    pub gap: Vec<f64>,
    /// The nearest other sample (`u32::MAX` for a lone sample).
    pub nearest: Vec<u32>,
}

/// The 2k + 1 nearest samples of an anchor (with their distances to the current centre).
struct Candidates<const D: usize> {
    anchor: [f64; D],
    radius: f64,
    points: Vec<(f64, u32)>,
}

impl<const D: usize> Default for Candidates<D> {
    fn default() -> Self {
        Candidates {
            anchor: [f64::NAN; D],
            radius: -1.0,
            points: Vec::new(),
        }
    }
}

/// A point cloud with its kd-tree (kiddo) and its rim samples.
pub struct PointCloud<const D: usize> {
    points: Vec<[f64; D]>,
    tree: ImmutableKdTree<f64, u32, D, 32>,
    neighbours: usize,
    rim: Vec<bool>,
    /// The rim samples and their neighbours (where a foot may leave the samples' hull).
    rim_zone: Vec<bool>,
    has_rim: bool,
    /// An upper bound of the distance from a point of the surface to its nearest sample.
    reach: f64,
    /// The samples' noise (a robust spread of their distances from their fits; 0 until set).
    noise: f64,
}

impl<const D: usize> PointCloud<D> {
    /// The cloud of `points` (distinct, finite), fitted over `neighbours` samples.
    pub fn new(points: Vec<[f64; D]>, neighbours: usize) -> Result<Self> {
        let need = basis_len(D) + 2;
        if neighbours < need || neighbours > 100 {
            return Err(Error::invalid(
                "neighbours",
                format!(
                    "must be between {need} and 100 (the fit has {} coefficients); got {neighbours}",
                    basis_len(D)
                ),
            ));
        }
        if points.len() < neighbours + 2 {
            return Err(Error::invalid(
                "points",
                format!(
                    "the fit needs at least {} samples (neighbours + 2 = {}); got {}",
                    neighbours + 2,
                    neighbours + 2,
                    points.len()
                ),
            ));
        }
        if points.len() >= u32::MAX as usize {
            return Err(Error::invalid("points", "at most 2³² − 1 samples"));
        }
        if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(Error::invalid(
                "points",
                format!("sample {i} is not finite: {:?}", points[i]),
            ));
        }
        let tree = ImmutableKdTree::new_from_slice(&points);
        let rim = vec![false; points.len()];
        let mut cloud = PointCloud {
            points,
            tree,
            neighbours,
            rim_zone: rim.clone(),
            rim,
            has_rim: false,
            noise: 0.0,
            reach: 0.0,
        };
        let radius: Vec<f64> = (0..cloud.points.len())
            .into_par_iter()
            .map(|i| {
                let nb = cloud.tree.nearest_n::<SquaredEuclidean>(&cloud.points[i], cloud.k1());
                nb.last().map_or(0.0, |n| n.distance.sqrt())
            })
            .collect();
        cloud.reach = radius.iter().copied().fold(0.0, f64::max);
        Ok(cloud)
    }

    fn k1(&self) -> NonZero<usize> {
        NonZero::new(self.neighbours + 1).unwrap()
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for a cloud of no samples (never: `new` refuses it).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The samples.
    pub fn points(&self) -> &[[f64; D]] {
        &self.points
    }

    /// The `k` samples nearest to each sample of `which` (itself among them: first, unless
    /// another sample lies at the same place), nearest first, `k` per sample in one flat list
    /// (in parallel): the neighbourhoods in which the samples that their fits miss are counted as
    /// a sharp edge's.
    pub fn nearest_samples(&self, which: &[usize], k: usize) -> Result<Vec<u32>> {
        if k == 0 || k > self.points.len() {
            return Err(Error::invalid(
                "k",
                format!("between 1 and the number of samples, {}; got {k}", self.points.len()),
            ));
        }
        if let Some(&bad) = which.iter().find(|&&i| i >= self.points.len()) {
            return Err(Error::invalid(
                "which",
                format!("sample indices below {} (got {bad})", self.points.len()),
            ));
        }
        let k = NonZero::new(k).unwrap();
        Ok(which
            .par_iter()
            .flat_map_iter(|&i| {
                self.tree
                    .nearest_n::<SquaredEuclidean>(&self.points[i], k)
                    .into_iter()
                    .map(|n| n.item)
            })
            .collect())
    }

    /// Sets the samples' noise (from [`PointCloud::analyse`]'s residuals): a foot that lies farther
    /// than the nearest sample by more than the noise allows is found again ([`FARTHER_FOOT`]).
    pub fn set_noise(&mut self, noise: f64) -> Result<()> {
        if !(noise >= 0.0 && noise.is_finite()) {
            return Err(Error::invalid("noise", "a finite value ≥ 0"));
        }
        self.noise = noise;
        Ok(())
    }

    /// Whether any sample lies on a rim (after [`PointCloud::mark_rim`]).
    pub fn has_rim(&self) -> bool {
        self.has_rim
    }

    /// The rim flags per sample.
    pub fn rim(&self) -> &[bool] {
        &self.rim
    }

    /// The per-sample analysis (in parallel).
    pub fn analyse(&self) -> SampleAnalysis {
        self.analyse_bridging(2.0 * self.reach)
    }

    /// [`PointCloud::analyse`] with the gaps bridged by samples found up to `bridge` away
    /// ([`PointCloud::bridged_gap`]; `analyse` bridges up to twice the sparsest fit's radius). A
    /// noisy cloud's analysis over wide neighbourhoods bridges only as far as its own fits reach:
    /// a hole narrower than twice the wide fits' radius would otherwise pass for thinner sampling.
    pub fn analyse_bridging(&self, bridge: f64) -> SampleAnalysis {
        let k = self.neighbours;
        let rows: Vec<(f64, f64, f64, f64, u32)> = (0..self.points.len())
            .into_par_iter()
            .map(|i| {
                let p = &self.points[i];
                let many = self
                    .tree
                    .nearest_n::<SquaredEuclidean>(p, NonZero::new(2 * k + 1).unwrap());
                let nearest = many.iter().find(|n| n.item as usize != i).map_or(u32::MAX, |n| n.item);
                let others: Vec<[f64; D]> = many
                    .iter()
                    .filter(|n| n.item as usize != i)
                    .map(|n| self.points[n.item as usize])
                    .collect();
                let spacing = others.first().map_or(f64::NAN, |o| distance(o, p));
                let own = &others[..(k + 1).min(others.len())];
                let radius = own.last().map_or(f64::NAN, |o| distance(o, p));
                match Fit::new(own, p, radius) {
                    Some(fit) => {
                        let a = fit.project(p);
                        let residual = distance(&fit.lift(&a), p) / fit.radius;
                        let (ap, _) = fit.local(p);
                        // the fit's own neighbours, and those beyond near its graph: samples of
                        // another sheet close by (the next turn past a spiral's end) fill no gap,
                        // nor do those beyond half the bridge (the widest fit's radius: around a
                        // sliced scan's last slice, the far side of its own ring hid the cap)
                        let noise = NOISE_MARGIN * fit.misfit(own, p, radius);
                        let around: Vec<[f64; 2]> = others
                            .iter()
                            .enumerate()
                            .filter_map(|(j, o)| {
                                let (a, w) = fit.local(o);
                                let d = distance(o, p);
                                (j < own.len()
                                    || (d <= 0.5 * bridge && on_graph(&fit, &a, w, (ANOTHER_SHEET * d).max(noise))))
                                .then_some(a)
                            })
                            .collect();
                        let around = if D == 2 { beyond_ends(&ap, around) } else { around };
                        (
                            spacing,
                            radius,
                            residual,
                            self.bridged_gap(p, &fit, &ap, around, bridge),
                            nearest,
                        )
                    }
                    None => (spacing, radius, f64::NAN, 0.0, nearest),
                }
            })
            .collect();
        SampleAnalysis {
            spacing: rows.iter().map(|r| r.0).collect(),
            radius: rows.iter().map(|r| r.1).collect(),
            residual: rows.iter().map(|r| r.2).collect(),
            gap: rows.iter().map(|r| r.3).collect(),
            nearest: rows.iter().map(|r| r.4).collect(),
        }
    }

    /// The largest angular gap around sample `p` among `around` (its 2k nearest neighbours in the
    /// fit's tangent coordinates, `ap` its own), once the samples farther out in the gap's
    /// direction are counted: while the gap exceeds [`RIM_GAP`], probe points go out along its
    /// bisector t at distances s = r, 2r, 4r, ... (r the fit's radius) up to `bridge` (by default
    /// 2·[`PointCloud::reach`], the sparsest fit's radius: a gap no wider than that is spanned by
    /// the fits anyway), and the
    /// first sample within s/2 of a probe and near the fit (its offset from the fitted graph or
    /// from the tangent plane, the smaller, under half its distance: [`on_graph`]; on a curve,
    /// also within [`END_SPACINGS`] spacings of `p`) joins the neighbours. Where the sampling only thins (a scan denser
    /// on one side) the gap closes; beyond a true rim the nearest sample to every probe is the rim
    /// itself, about s away, and the gap stays.
    fn bridged_gap(&self, p: &[f64; D], fit: &Fit<D>, ap: &[f64; 2], mut around: Vec<[f64; 2]>, bridge: f64) -> f64 {
        let (mut gap, mut dir) = gap_and_bisector::<D>(ap, &around);
        // (a curve's: a sample across the gap closes it only within END_SPACINGS spacings)
        let p_spacing = if D == 2 && gap > RIM_GAP {
            self.spacing_of(p)
        } else {
            0.0
        };
        let mut closed = 0;
        while gap > RIM_GAP && closed < 4 {
            let mut t = [0.0; D];
            for k in 0..D {
                for j in 0..D - 1 {
                    t[k] += dir[j] * fit.frame[j][k];
                }
            }
            let mut s = fit.radius;
            let mut found = None;
            while s <= bridge && found.is_none() {
                let mut probe = *p;
                for k in 0..D {
                    probe[k] += s * t[k];
                }
                let q = &self.points[self.tree.nearest_one::<SquaredEuclidean>(&probe).item as usize];
                // the offset from the fitted graph (or the tangent plane, the smaller): the surface's own
                // continuation follows the graph's curvature, another sheet curving beside it (the
                // next turn of a spiral past its end) does not
                let (aq, wq) = fit.local(q);
                if distance(q, &probe) <= 0.5 * s
                    && on_graph(fit, &aq, wq, 0.5 * distance(q, p))
                    && (D != 2 || distance(q, p) <= END_SPACINGS * p_spacing.max(self.spacing_of(q)))
                {
                    found = Some(*q);
                }
                s *= 2.0;
            }
            let Some(q) = found else { break };
            around.push(fit.local(&q).0);
            (gap, dir) = gap_and_bisector::<D>(ap, &around);
            closed += 1;
        }
        gap
    }

    /// The distance from sample `q` to its nearest other sample.
    fn spacing_of(&self, q: &[f64; D]) -> f64 {
        self.tree
            .nearest_n::<SquaredEuclidean>(q, NonZero::new(2).unwrap())
            .iter()
            .map(|n| distance(&self.points[n.item as usize], q))
            .find(|&d| d > 0.0)
            .unwrap_or(f64::INFINITY)
    }

    /// Marks the rim: samples whose gap exceeds [`RIM_GAP`] and (in 3D) with at least
    /// [`RIM_CLUSTER`] such samples among their k nearest neighbours. Returns the rim's size.
    pub fn mark_rim(&mut self, gap: &[f64]) -> Result<usize> {
        if gap.len() != self.points.len() {
            return Err(Error::invalid("gap", "one value per sample"));
        }
        let candidate: Vec<bool> = gap.iter().map(|&g| g > RIM_GAP).collect();
        let rim: Vec<bool> = if D == 2 {
            candidate
        } else {
            (0..self.points.len())
                .into_par_iter()
                .map(|i| {
                    candidate[i]
                        && self
                            .tree
                            .nearest_n::<SquaredEuclidean>(&self.points[i], self.k1())
                            .iter()
                            .filter(|n| n.item as usize != i && candidate[n.item as usize])
                            .count()
                            >= RIM_CLUSTER
                })
                .collect()
        };
        let count = rim.iter().filter(|&&r| r).count();
        // the rim's zone: the 2k + 1 nearest samples of every rim sample, where feet are clamped
        let mut zone = rim.clone();
        let kc = NonZero::new(2 * self.neighbours + 1).unwrap();
        for (i, _) in rim.iter().enumerate().filter(|(_, &r)| r) {
            for n in self.tree.nearest_n::<SquaredEuclidean>(&self.points[i], kc) {
                zone[n.item as usize] = true;
            }
        }
        self.rim_zone = zone;
        self.rim = rim;
        self.has_rim = count > 0;
        Ok(count)
    }

    /// The closest point of `x` on the cloud's surface and what was found.
    /// `rho` is the smoothing radius ρ (0: the k nearest samples only).
    pub fn closest_point(&self, x: &[f64; D], rho: f64) -> ([f64; D], Foot) {
        self.closest_point_from(x, *x, rho, &mut Candidates::default())
    }

    /// The neighbourhood of `c` (into `out`) and its radius R = max(r_{k+1}(c), ρ): the samples
    /// within R. They come from `cache` (every sample within the cache's radius of an anchor: the
    /// 2k + 1 nearest, or all within 2ρ when that is more) while |c − anchor| + R ≤ the cache's
    /// radius, which proves it holds them all; else the cache is queried again around `c`.
    fn neighbourhood(&self, c: &[f64; D], rho: f64, cache: &mut Candidates<D>, out: &mut Vec<[f64; D]>) -> (f64, bool) {
        let k1 = self.neighbours + 1;
        // (a cloud of fewer than 2k + 1 samples, which a fit of k + 1 allows: all of them)
        let kc = (2 * self.neighbours + 1).min(self.points.len());
        let mut radius = 0.0;
        for attempt in 0..2 {
            if attempt == 1 || cache.points.is_empty() || distance(c, &cache.anchor) >= cache.radius {
                cache.anchor = *c;
                cache.points = self
                    .tree
                    .nearest_n::<SquaredEuclidean>(c, NonZero::new(kc).unwrap())
                    .iter()
                    .map(|n| (0.0, n.item))
                    .collect();
                cache.radius = distance(c, &self.points[cache.points[kc - 1].1 as usize]);
                if cache.radius < 2.0 * rho {
                    cache.radius = 2.0 * rho;
                    cache.points = self
                        .tree
                        .within_unsorted::<SquaredEuclidean>(c, cache.radius * cache.radius)
                        .iter()
                        .map(|n| (0.0, n.item))
                        .collect();
                }
            }
            for e in cache.points.iter_mut() {
                e.0 = distance(&self.points[e.1 as usize], c);
            }
            cache.points.select_nth_unstable_by(k1 - 1, |p, q| p.0.total_cmp(&q.0));
            radius = cache.points[k1 - 1].0.max(rho);
            if distance(c, &cache.anchor) + radius <= cache.radius || attempt == 1 {
                break;
            }
        }
        let mut rim = false;
        for tied in [false, true] {
            out.clear();
            rim = false;
            for e in cache.points.iter().filter(|e| e.0 < radius) {
                out.push(self.points[e.1 as usize]);
                rim |= self.rim_zone[e.1 as usize];
            }
            // samples tied at the radius (c on the axis of a ring of samples: a sliced scan's last
            // slice around its unsampled cap) would all weigh nothing and leave no fit: the radius
            // then reaches just past them, so that they weigh alike
            if tied || radius <= rho || out.len() > basis_len(D) {
                break;
            }
            radius *= 1.0 + TIED_RADIUS;
        }
        (radius, rim)
    }

    /// [`PointCloud::closest_point`] from the first centre `start` (x, or the foot of a nearby
    /// point), with a cache of candidate neighbours shared by nearby queries. The answer is the
    /// fixed point to [`TOLERANCE`], whatever the start near it.
    ///
    /// Every point of the surface lies within `reach` of a sample, or [`BRIDGED_REACH`] times that
    /// over a hole the rim test bridges. Far from the samples the fit
    /// around c spans a wide cap and can hold a fixed point of its own off the samples (a noisy
    /// sphere's: feet 0.12–0.23 off it, a quarter of the radius, three times the reach, which put
    /// nodes far outside into the inner tube and ended the solve after a minute of widened
    /// layers); such a foot is found again from x's nearest sample, on the surface, or fails.
    fn closest_point_from(
        &self,
        x: &[f64; D],
        start: [f64; D],
        rho: f64,
        cache: &mut Candidates<D>,
    ) -> ([f64; D], Foot) {
        let (foot, kind, off_samples, blended, radius) = self.fixed_point(x, start, rho, cache);
        let nearest = self.tree.nearest_one::<SquaredEuclidean>(x);
        let on_surface = self.points[nearest.item as usize];
        if !off_samples && !blended {
            // A closest point is never much farther than the nearest sample. Past an open cloud's
            // rim the fixed point can settle on another sheet (the next turn beyond a spiral's
            // end, 7.1 spacings off where the end lay 4.0 away; between a spiral's turns, on the
            // farther turn): it is found again from that sample, and the nearer foot kept
            let far = distance(&foot, x);
            if far > nearest.distance.sqrt() + FARTHER_FOOT * radius + NOISY_FOOT * self.noise && on_surface != start {
                if let (again, k @ (Foot::Interior | Foot::Rim), false, false, _) =
                    self.fixed_point(x, on_surface, rho, cache)
                {
                    if distance(&again, x) < far {
                        return (again, k);
                    }
                }
            }
            return (foot, kind);
        }
        if on_surface != start {
            if let (again, k @ (Foot::Interior | Foot::Rim), false, false, _) =
                self.fixed_point(x, on_surface, rho, cache)
            {
                return (again, k);
            }
        }
        if !off_samples {
            // every fit near x blends the sheets (a gap the fits do not resolve, which the band
            // search warns of): the blended foot, as before this check
            return (foot, kind);
        }
        match self.nearest_fit_foot(x, &on_surface, rho, cache) {
            Some(f) => (f, Foot::NearestFit),
            None => ([f64::NAN; D], Foot::Failed),
        }
    }

    /// The last resort of [`PointCloud::closest_point_from`]: `x` projected once onto the fit
    /// centred at its nearest sample `sample` and kept within the hull of that fit's samples in
    /// its tangent plane, so the foot lies among the samples (where edges or corners make the
    /// fixed point bounce off them: the Stanford bunny's vertices, 380 of them on such edges,
    /// failed a node 1.6–4.7 spacings from them at N = 31–61). None where that fit does not exist.
    fn nearest_fit_foot(
        &self,
        x: &[f64; D],
        sample: &[f64; D],
        rho: f64,
        cache: &mut Candidates<D>,
    ) -> Option<[f64; D]> {
        let mut nb: Vec<[f64; D]> = Vec::with_capacity(self.neighbours + 1);
        let (radius, _) = self.neighbourhood(sample, rho, cache, &mut nb);
        let fit = Fit::new(&nb, sample, radius)?;
        let pts: Vec<[f64; 2]> = nb.iter().map(|p| fit.local(p).0).collect();
        let foot = fit.lift(&clamp_to_hull::<D>(&fit.project(x), &pts));
        foot.iter().all(|v| v.is_finite()).then_some(foot)
    }

    /// The fixed point c ← the projection of `x` onto the fit centred at c, from `start`, and
    /// whether its foot lies farther than [`BRIDGED_REACH`] times `reach` from every sample (the
    /// last neighbourhood bounds that distance from above; only past the bound is the tree
    /// asked), and whether its fit
    /// blends two sheets (a foot in a hole of its samples, [`BLENDED_HOLE`]: midway between the turns of a
    /// spiral 8 spacings apart, the graph through both turns' samples held a node 4 spacings from
    /// either at 0.15 spacings from its "surface"), and the last neighbourhood's radius.
    fn fixed_point(
        &self,
        x: &[f64; D],
        start: [f64; D],
        rho: f64,
        cache: &mut Candidates<D>,
    ) -> ([f64; D], Foot, bool, bool, f64) {
        let mut c = start;
        let mut foot = [f64::NAN; D];
        let mut nb: Vec<[f64; D]> = Vec::with_capacity(self.neighbours + 1);
        let mut on_rim = false;
        let mut last_radius = 0.0;
        for it in 0..MAX_ITERATIONS {
            let (radius, near_rim) = self.neighbourhood(&c, rho, cache, &mut nb);
            let Some(f) = Fit::new(&nb, &c, radius) else {
                return ([f64::NAN; D], Foot::Failed, false, false, 0.0);
            };
            let mut a = f.project(x);
            on_rim = false;
            if near_rim {
                // an open cloud: the foot stays within the hull of its neighbours in the tangent
                // plane, so beyond the rim the closest point lies on it
                let pts: Vec<[f64; 2]> = nb.iter().map(|p| f.local(p).0).collect();
                let clamped = clamp_to_hull::<D>(&a, &pts);
                on_rim = clamped != a;
                a = clamped;
            }
            foot = f.lift(&a);
            let moved = distance(&foot, &c);
            c = foot;
            last_radius = radius;
            if it > 0 && moved <= TOLERANCE * f.radius {
                break;
            }
        }
        if !foot.iter().all(|v| v.is_finite()) {
            return ([f64::NAN; D], Foot::Failed, false, false, 0.0);
        }
        let bound = nb.iter().map(|s| distance(s, &foot)).fold(f64::INFINITY, f64::min);
        let nearest = || self.tree.nearest_one::<SquaredEuclidean>(&foot).distance.sqrt();
        let off_samples = bound > BRIDGED_REACH * self.reach && nearest() > BRIDGED_REACH * self.reach;
        let blended = !off_samples && bound > BLENDED_HOLE * last_radius && nearest() > BLENDED_HOLE * last_radius;
        (
            foot,
            if on_rim { Foot::Rim } else { Foot::Interior },
            off_samples,
            blended,
            last_radius,
        )
    }

    /// [`PointCloud::closest_point`] for many points, in parallel: in fixed blocks of
    /// [`BLOCK`] points (so the answer does not depend on the threads), each query starting from
    /// the previous point's foot when that point is near, sharing the candidate neighbours. A foot
    /// found from such a start that lies farther than `trust` from its point is checked against the
    /// point's nearest sample, and found again from the point itself when that sample is much
    /// nearer (0: every such foot is checked; a band search passes its half-width, beyond which
    /// it drops the nodes, so that only the feet it would drop are checked).
    pub fn closest_points(&self, x: &[[f64; D]], rho: f64, trust: f64) -> (Vec<[f64; D]>, Vec<Foot>) {
        let per_block: Vec<Vec<([f64; D], Foot)>> = x
            .par_chunks(BLOCK)
            .map(|block| {
                let mut cache = Candidates::default();
                let mut previous: Option<([f64; D], [f64; D])> = None;
                block
                    .iter()
                    .map(|p| {
                        let reused = match previous {
                            Some((px, pf)) if pf[0].is_finite() && distance(&px, p) <= 2.0 * cache.radius => Some(pf),
                            _ => None,
                        };
                        let mut r = self.closest_point_from(p, reused.unwrap_or(*p), rho, &mut cache);
                        if reused.is_some() && !(distance(&r.0, p) <= trust) {
                            // a start on another part of the surface can hold the fixed point at a
                            // foot that is only locally nearest: up a column of nodes through a
                            // circle's centre the feet stayed on the far side, and the band lost
                            // the column beyond it. A closest point is never much farther than the
                            // nearest sample, so such a foot is found again from the point itself
                            let nearest = self.tree.nearest_one::<SquaredEuclidean>(p).distance.sqrt();
                            if !(distance(&r.0, p) <= 2.0 * nearest + STALE_START * cache.radius) {
                                r = self.closest_point_from(p, *p, rho, &mut cache);
                            }
                        }
                        previous = Some((*p, r.0));
                        r
                    })
                    .collect()
            })
            .collect();
        per_block.into_iter().flatten().unzip()
    }

    /// A lower bound of the distance from each point to the surface: the distance to the nearest
    /// sample less [`BRIDGED_REACH`] times [`PointCloud::reach`] (for the coarse-to-fine band
    /// search: the fits' bridge over a hole lies that far from the samples).
    pub fn distance_lower_bounds(&self, x: &[[f64; D]]) -> Vec<f64> {
        x.par_iter()
            .map(|p| {
                let n = self.tree.nearest_one::<SquaredEuclidean>(p);
                (n.distance.sqrt() - BRIDGED_REACH * self.reach).max(0.0)
            })
            .collect()
    }

    /// The widest fit's radius: an upper bound of the distance from a point of the surface to
    /// its nearest sample, but over a hole the rim test bridges ([`BRIDGED_REACH`] times it).
    pub fn reach(&self) -> f64 {
        self.reach
    }
}

/// Whether a sample at tangent coordinates `a` and height `w` (scaled, as [`Fit::local`] gives
/// them) lies within `within` of the fitted graph or of the tangent plane (whichever is nearer: a
/// noisy fit's curvature, extrapolated past its radius, may miss its own sheet).
fn on_graph<const D: usize>(fit: &Fit<D>, a: &[f64; 2], w: f64, within: f64) -> bool {
    w.abs().min((w - fit.height(a).0).abs()) * fit.radius <= within
}

/// On a curve: the neighbours `around` (tangent coordinates) of a sample at `ap` without those on
/// a side whose nearest lies farther than [`END_SPACINGS`] times their mean spacing (the
/// consecutive distances along the tangent, the largest left out): across a gap in the curve.
fn beyond_ends(ap: &[f64; 2], around: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let mut t: Vec<f64> = around.iter().map(|a| a[0]).chain(std::iter::once(ap[0])).collect();
    t.sort_by(f64::total_cmp);
    let steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.len() < 2 {
        return around;
    }
    let largest = steps.iter().copied().fold(0.0, f64::max);
    let mean = (steps.iter().sum::<f64>() - largest) / (steps.len() - 1) as f64;
    let below = around
        .iter()
        .filter(|a| a[0] < ap[0])
        .map(|a| ap[0] - a[0])
        .fold(f64::INFINITY, f64::min);
    let above = around
        .iter()
        .filter(|a| a[0] > ap[0])
        .map(|a| a[0] - ap[0])
        .fold(f64::INFINITY, f64::min);
    let reach = END_SPACINGS * mean;
    around
        .into_iter()
        .filter(|a| (a[0] < ap[0] && below <= reach) || (a[0] > ap[0] && above <= reach) || a[0] == ap[0])
        .collect()
}

#[cfg(test)]
mod tests;
