//! The re-distanced band of a sampled φ (`LevelSet(phi_array, redistance=True)`) from *any* φ
//! whose zero level set crosses the grid: a 0/1 mask (`mask − 0.5`), plateaus where ∇φ vanishes,
//! single-precision noise, φ that is nowhere a distance function.
//!
//! The surface is the zero level set of φ's multilinear interpolant (the [`SampledField`] of
//! [`crate::surface::redistance`]); the signed distance to it is found in three steps, in the
//! manner of the sub-cell closest points of Chopp (2001) and Russo & Smereka (2000):
//!
//! 1. **Sub-cell interface location.** The cells with a sign change among their corners
//!    ([`crossed_cells`]) hold the zero level set; on their edges it is known exactly, at the
//!    linear interpolation of the two end values ([`crossings_at_corner`]), with no use of ∇φ.
//! 2. **Closest points, layer by layer.** The nodes within `reach` cells of a crossed cell
//!    ([`NodeSet`]) are ordered by their number of face steps from a crossed cell's corner (as
//!    many as a node within the half-width can be away). A corner takes the nearest crossing on
//!    its own edges (failing those, the nearest edge crossing of its crossed cells) as its
//!    starting point, or where `|φ|/|∇φ|` says the zero level set is far nearer (a rim that
//!    grazes the node, its edges crossed only at zero nodes a spacing away: [`grazing_starts`])
//!    the nearest zero-set point between it and its cells' corners of the other sign, a node of a later layer the nearest closest point of the nodes around it
//!    (face, edge and corner neighbours) of the layers before (and the normal there): next to its
//!    own closest point, so the refinement is short, and a node whose start lies more than a
//!    spacing beyond the half-width, or which lies high above the tangent plane there
//!    ([`BEND_ALLOWANCE`]), is left out (its distance exceeds the half-width) without
//!    refinement. The layers grow as they are refined, each from the nodes of the one before that
//!    are within the half-width (a band node has a path of face steps to the surface along which
//!    its distance falls, so it is reached from band nodes): on the sphere at N = 201, 305k nodes
//!    searched for 252k in the band. The closest points found are kept in one list, layer after
//!    layer, and each node its place in it (written in parallel once a layer is done, so a layer's
//!    nodes read only those of the layers before: the same bits on any number of threads).
//! 3. **Refinement on the interpolant.** From that point on the zero level set, the
//!    orthogonality iterations of the projection: `y ← P(y + (I − n nᵀ)(x − y))`, a move in the
//!    tangent plane towards the foot of the node (the normal `n` from central differences of φ
//!    with step `eps`, as the projection takes it: continuous across the cells' faces, so the
//!    closest points vary smoothly from node to node, which the second-order solve's curvature
//!    needs; for the default step `Δx/2` in closed form, `SampledField::half_step_gradient`), then Newton steps `P` back onto the level set with the exact gradient of the cell's
//!    interpolant (quadratic convergence), until `|x − y|` is within `tol · Δx` of the distance
//!    to the tangent plane at `y` (`|t|² ≤ 2 tol Δx |x − y|`, `t` the tangential part of
//!    `x − y`). Each step must land on the zero level set (within `1e-7 · Δx` of it,
//!    `|φ| / |∇φ|`), otherwise the tangential move is halved (once), and failing that the
//!    iterations stop. So every iterate is a point of the zero level set, whose distance from the
//!    node bounds the node's distance from above, and ∇φ is only read next to the zero level set,
//!    where the sign change makes it non-zero: never on a plateau. The iterations also stop at a
//!    move not below half the one before (they circle among the kinks of a mask's voxel steps;
//!    where φ is smooth the moves shrink far faster, see below), trying the
//!    zero-set point between the last two iterates; such a node keeps the iterate nearest to it.
//!    The plain iterations converge linearly: the tangential error is multiplied by about
//!    `ρ = −s κ` per step (`s` the node's signed height above the tangent plane, `κ` the
//!    curvature along the error). The moves are taken as `t / (1 − ρ̂)`, with `ρ̂` from the
//!    curvature that the start's node saw (kept with its closest point) and then by secant
//!    updates from the ratio of successive moves: exact on a sphere, and the same fixed point
//!    (`t = 0`). On the sphere `|x|² − R²` at N = 201 the nodes take two moves instead of four or five.
//!    Once a landing has given the exact gradient of the interpolant at `y`, the next move is
//!    taken in the interpolant's own tangent plane there (what Newton's steps would take off it),
//!    so that a small move lands without a Newton step: 2.9 interpolant evaluations per node
//!    instead of 3.7 on that sphere. A node whose distance to the tangent plane, less the move
//!    left (within [`SMALL_MOVE`] spacings), exceeds the half-width is beyond the band: it stops
//!    there, its point still a start for the nodes after it.
//!
//! Where φ is smooth the iterations settle on the same closest point as the projection from the
//! node itself (the same fixed point, `x − y` along the central-difference normal), so the
//! distances agree with it to the settling tolerance; the distance to the interpolant's zero set
//! is second order in Δx (the interpolant moves the surface by `Δx²|D²φ|/(8|∇φ|)` at most).
//! Where the interface has kinks (a mask's voxel steps, a crease) the iterations may stop
//! before settling: the point reached is the nearest zero-set point found, counted in
//! [`RedistancedBand::unsettled`]. The work and the memory scale with the band: one pass over the
//! samples (as bit sets) finds the crossed cells, everything else is per node near them.

use crate::error::{Error, Result};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering::Relaxed};

use super::interface_cells::{at_rounding, crossed_cells, crossings_at_corner, Lattice, NodeSet};
use super::redistance::{sum_of_squares, SampledField};

/// The re-distanced band.
#[derive(Debug, Clone, Default)]
pub struct RedistancedBand {
    /// The nodes within the half-width of the zero level set: sorted C-order linear indices.
    pub linear: Vec<u64>,
    /// Their signed distances, `sgn φ(x) · |x − cp(x)|`.
    pub signed: Vec<f64>,
    /// Their extension directions `(x − cp(x)) / |x − cp(x)|` (zero on the surface), `D` each.
    pub direction: Vec<f32>,
    /// The cells the zero level set crosses.
    pub crossed_cells: usize,
    /// Nodes of the band whose refinement stopped before `x − cp(x)` was along the normal (a kink
    /// of the interface, such as a mask's voxel steps): their distance is that to the nearest
    /// point of the zero level set the iterations found.
    pub unsettled: usize,
    /// Nodes of the band's inner half (the inner tube, with the default widths) with a face
    /// neighbour whose closest point lies more than [`MEDIAL_GAP`]
    /// spacings from theirs: near points equidistant from two parts of the zero level set, where
    /// the tube is about as wide as the surface's radius of curvature, or two sheets face each
    /// other within it (a grid too coarse for the surface).
    pub medial: usize,
}

/// See [`RedistancedBand::medial`]: neighbouring nodes at distance `d` from a surface of radius of
/// curvature `R` have closest points `Δx·R/(R − d)` apart on its concave side, 5Δx at `d = 4R/5`,
/// and a mask's voxel steps move them by a spacing or two; across a point equidistant from two
/// parts of the surface they jump from one to the other.
pub const MEDIAL_GAP: f64 = 5.0;

/// The options of [`redistanced_band_of_samples`].
#[derive(Debug, Clone, Copy)]
pub struct RedistanceOptions {
    /// The band's half-width: nodes farther from the zero level set are left out.
    pub half_width: f64,
    /// The step of the central differences of ∇φ.
    pub eps: f64,
    /// The most refinement iterations per node.
    pub max_steps: usize,
    /// A point `y` has settled when `|x − y|` is within `tol · Δx` of the distance from `x` to the
    /// tangent plane at `y`.
    pub tol: f64,
}

/// A point is on the zero level set when `|φ| ≤ ON_ZERO_SET · Δx · |∇φ|` there (about that many
/// grid spacings from it along the normal): every iterate is. Far below the interpolant's own
/// error (`Δx²|D²φ|/(8|∇φ|)`, 7.5e-3 Δx on `|x|² − R²` at N = 201) and near the directions' f32
/// rounding; 1e-9 instead took a third Newton step at many of the smoothed mask's landings. A node whose iterations stall at kinks (a
/// mask's voxel steps, the gyroid-like φ's tight folds) may stop at another point with either:
/// up to 0.12 and 0.22 Δx apart there (`benches/experiments/band_fingerprints.py`).
const ON_ZERO_SET: f64 = 1e-7;

/// The refinement stops when a move is more than [`STALL_RATIO`] times the one before.
const STALL_RATIO: f64 = 0.5;

/// Halvings of a tangential move that does not land on the zero level set closer to the node.
const HALVINGS: usize = 1;

/// The largest contraction [`refine`] assumes, either sign.
const RHO_LIMIT: f64 = 0.5;

/// A move within this many spacings is small: a node whose distance to the tangent plane, less
/// that move, is beyond the band's half-width is not refined further (see [`refine`]).
const SMALL_MOVE: f64 = 0.01;

/// No closest point yet (a node's slot among those found).
const NONE: u32 = u32::MAX;

/// A node is refined only if its start lies within the half-width plus this many spacings.
const PRUNE_MARGIN: f64 = 1.0;

/// A node of a later layer whose height `s` above the tangent plane at its start (a neighbour's
/// closest point, with its normal) exceeds the half-width by more than `BEND_ALLOWANCE · t²/Δx +
/// BEYOND_MARGIN · Δx` (`t` the start's offset along the plane) is beyond the band and left out
/// unrefined: a surface whose radii of curvature are a spacing or more bends towards the node by
/// at most `t²/(2Δx)` over `t`. Most of the nodes that the refinement used to take only to find
/// them beyond the band are left out so (`BEYOND_MARGIN` keeps those just past the edge: without
/// it a node of a noisy sphere 0.001–0.013 Δx inside the edge was lost). With the looser landing
/// of [`ON_ZERO_SET`], which came with it, the bands of the nine φ of
/// `benches/experiments/band_fingerprints.py` kept their nodes (the gyroid-like φ gained 6 at
/// N = 121) and their settled distances to 1e-7 Δx.
const BEND_ALLOWANCE: f64 = 0.5;

/// See [`BEND_ALLOWANCE`].
const BEYOND_MARGIN: f64 = 0.1;

/// The most Newton steps that take a point back onto the zero level set after a tangential move.
const NEWTON_STEPS: usize = 4;

/// A crossed cell's corner looks for a start nearer than the crossings on its edges
/// ([`grazing_starts`]) where `|φ|/|∇φ|` there is this many times nearer than all of them: on a
/// smooth φ an edge crossing is within about √D times the distance along the normal.
const GRAZING_RATIO: f64 = 2.0;

/// Halvings of a segment in [`grazing_starts`]: to 2⁻⁵⁰ of its length, far within
/// [`ON_ZERO_SET`].
const BISECTIONS: usize = 50;

/// Newton steps from `z` onto the zero level set of the multilinear interpolant, with its exact
/// gradient in the cell that holds the point (quadratic convergence within a cell; the points kept
/// in the grid's box), until `|φ| ≤ within · |∇φ|` (`z` within about `within` of the zero level
/// set), [`NEWTON_STEPS`] at most: where it got there, the gradient that gives the iterations'
/// normal at the point reached (the central differences with step `eps`; for `eps = Δx/2` read
/// in the same call as the value there, [`SampledField::value_gradient_and_half_step_if`]).
#[inline]
fn onto_zero_set<const D: usize>(
    field: &SampledField<'_, D>,
    z: &mut [f64; D],
    within: f64,
    eps: f64,
) -> Option<([f64; D], [f64; D])> {
    let half_step = eps == 0.5 * field.spacing();
    field.clamp_to_box(z);
    for step in 0..=NEWTON_STEPS {
        // after a step the point is most likely on the zero level set: its normal in the same call
        let landed = |v: f64, g: &[f64; D]| v * v <= within * within * sum_of_squares(g);
        let (v, g, normal) = if half_step {
            field.value_gradient_and_half_step_if(z, landed)
        } else {
            let (v, g) = field.value_and_gradient(z);
            (v, g, None)
        };
        let n2 = sum_of_squares(&g);
        if landed(v, &g) {
            return Some((normal.unwrap_or_else(|| normal_gradient(field, z, eps)), g));
        }
        if step == NEWTON_STEPS || !(n2 > 1e-300) {
            return None;
        }
        let s = v / n2;
        for k in 0..D {
            z[k] -= s * g[k];
        }
        field.clamp_to_box(z);
    }
    None
}

/// The gradient that gives the iterations' normal at `y`: the central differences of φ with step
/// `eps`, in closed form for the default step, half a spacing ([`SampledField::half_step_gradient`]).
#[inline]
fn normal_gradient<const D: usize>(field: &SampledField<'_, D>, y: &[f64; D], eps: f64) -> [f64; D] {
    if eps == 0.5 * field.spacing() {
        field.half_step_gradient(y)
    } else {
        field.gradient(y, eps)
    }
}

/// Points of the zero level set near the node `x` (a D-index `node`, a crossed cell's corner)
/// next to a node where φ vanishes and where `|φ|/|∇φ|` there (central differences with step `eps`) is [`GRAZING_RATIO`] times nearer
/// than the nearest crossing on its edges (`edge`, squared), none elsewhere: the zero level set on
/// the segments from the node to the corners of the other sign of the cells around it, and along
/// its normal as far as that crossing, by bisection of the interpolant (continuous along a
/// segment, which changes sign between its ends).
fn grazing_starts<const D: usize>(
    field: &SampledField<'_, D>,
    node: [usize; D],
    x: &[f64; D],
    edge: f64,
    zero_neighbour: bool,
    eps: f64,
) -> Vec<[f64; D]> {
    let here = field.sample(node);
    let shape = field.shape();
    // a face neighbour on the zero level set (`zero_neighbour`: a rim on the grid's nodes; φ there
    // a millionth of the node's or less, `interface_cells::ON_SURFACE`: rounding left 1e-16 on the cylinder's
    // caps): a φ with noise has none, and there the nodes keep their edges' crossings (with noise
    // of 0.3Δx some nodes near small folds of the zero set found them nearer, and facing sheets
    // were then read there)
    if here == 0.0 || !zero_neighbour {
        return Vec::new();
    }
    let g = normal_gradient(field, x, eps);
    let g2 = sum_of_squares(&g);
    if !(g2 > 1e-300) || here * here / g2 * GRAZING_RATIO * GRAZING_RATIO >= edge {
        return Vec::new();
    }
    let other_sign = |v: f64| if here > 0.0 { v < 0.0 } else { v > 0.0 };
    let bisect = |mut a: [f64; D], mut b: [f64; D]| -> [f64; D] {
        for _ in 0..BISECTIONS {
            let mid: [f64; D] = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
            if other_sign(field.value(&mid)) {
                b = mid;
            } else {
                a = mid;
            }
        }
        std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
    };
    let mut found = Vec::new();
    // the corners of the cells around the node: offsets −1, 0, +1 along each axis
    for around in 0..3usize.pow(D as u32) {
        let mut corner = node;
        let mut inside = true;
        let mut code = around;
        for a in 0..D {
            match code % 3 {
                0 if node[a] > 0 => corner[a] -= 1,
                2 if node[a] + 1 < shape[a] => corner[a] += 1,
                1 => {}
                _ => inside = false,
            }
            code /= 3;
        }
        if inside && corner != node && other_sign(field.sample(corner)) {
            let end: [f64; D] = std::array::from_fn(|a| field.coordinate(a, corner[a]));
            found.push(bisect(*x, end));
        }
    }
    // along the normal, as far as the nearest edge crossing
    let reach = edge.sqrt() / g2.sqrt() * here.signum();
    let mut end: [f64; D] = std::array::from_fn(|k| x[k] - reach * g[k]);
    field.clamp_to_box(&mut end);
    if other_sign(field.value(&end)) {
        found.push(bisect(*x, end));
    }
    found
}

/// `|a − b|²`.
#[inline]
fn squared_distance<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        s += (a[k] - b[k]) * (a[k] - b[k]);
    }
    s
}

/// `g / |g|`, or None where `g` vanishes.
#[inline]
fn unit<const D: usize>(g: [f64; D]) -> Option<[f64; D]> {
    let n2 = sum_of_squares(&g);
    if !(n2 > 1e-300) {
        return None;
    }
    let norm = n2.sqrt();
    Some(g.map(|v| v / norm))
}

/// A closest point found by [`refine`]: the point, the unit normal used there, whether it settled.
#[derive(Debug, Clone, Copy)]
struct Foot<const D: usize> {
    y: [f64; D],
    n: [f64; D],
    settled: bool,
    /// The curvature the iterations saw there (see [`refine`]), 0 where unknown.
    kappa: f64,
}

/// The closest point found for node `p` (its slot among the `feet`), if any.
#[inline]
fn foot_at<'f, const D: usize>(feet: &'f [Foot<D>], slot: &[AtomicU32], p: usize) -> Option<&'f Foot<D>> {
    let s = slot[p].load(Relaxed);
    (s != NONE).then(|| &feet[s as usize])
}

/// The closest point of the node `x` on the zero level set of `field`'s interpolant, from `start`
/// (a point of it) and, when known, the unit normal there: step 3 of the module documentation.
/// A point that did not settle is the nearest to `x` of the iterates.
#[inline]
fn refine<const D: usize>(
    field: &SampledField<'_, D>,
    x: &[f64; D],
    start: [f64; D],
    start_normal: Option<([f64; D], f64)>,
    options: &RedistanceOptions,
    beyond: f64,
) -> Foot<D> {
    let h = field.spacing();
    let tol = options.tol * h;
    let normal = |y: &[f64; D]| unit(normal_gradient(field, y, options.eps));
    let mut y = start;
    let (start_normal, start_kappa) = match start_normal {
        Some((n, kappa)) => (Some(n), kappa),
        None => (None, 0.0),
    };
    let Some(mut n) = start_normal.or_else(|| normal(&y)) else {
        return Foot {
            y,
            n: [0.0; D],
            settled: false,
            kappa: 0.0,
        };
    };
    let mut best = Foot {
        y,
        n,
        settled: false,
        kappa: 0.0,
    };
    let mut best_d2 = f64::INFINITY;
    let mut last = f64::INFINITY;
    let mut previous = y;
    // the contraction of the plain iterations, ρ (the tangential error is multiplied by about
    // ρ = −s κ per step, s the signed distance along the normal, κ the curvature along the
    // error): the steps are taken as t / (1 − ρ̂), ρ̂ its estimate, from the curvature seen at the
    // start's node and then by secant updates from successive moves (exact on a sphere)
    let mut rho = f64::NAN;
    let mut kappa = start_kappa;
    let mut t_last = [0.0; D];
    // the unit normal of the interpolant's zero level set at y (its exact gradient), once known
    let mut exact: Option<[f64; D]> = None;
    // whether the last move was accelerated, and whether the moves are plain from here on
    let (mut accelerated, mut plain) = (false, false);
    for _ in 0..options.max_steps {
        let mut r = [0.0; D];
        let mut along = 0.0;
        for k in 0..D {
            r[k] = x[k] - y[k];
            along += r[k] * n[k];
        }
        let mut t = [0.0; D];
        for k in 0..D {
            t[k] = r[k] - along * n[k];
        }
        let d2 = sum_of_squares(&r);
        let t2 = sum_of_squares(&t);
        // the contraction: from the curvature first, then from the ratio of the last two moves
        if rho.is_nan() {
            rho = (-along * kappa).clamp(-RHO_LIMIT, RHO_LIMIT);
        } else if plain {
            rho = 0.0;
        } else {
            let last2 = sum_of_squares(&t_last);
            if last2 > 0.0 {
                let mut dot = 0.0;
                for k in 0..D {
                    dot += t[k] * t_last[k];
                }
                rho = (rho + dot / last2 * (1.0 - rho)).clamp(-RHO_LIMIT, RHO_LIMIT);
                if along.abs() > 1e-3 * h {
                    kappa = -rho / along;
                }
            }
        }
        t_last = t;
        // a node beyond the band: its distance to the tangent plane, less what is left of the
        // move, exceeds `beyond` once the moves have become small (it is left out of the band)
        if t2 <= (SMALL_MOVE * h) * (SMALL_MOVE * h) && (d2 - t2).sqrt() - t2.sqrt() > beyond {
            return Foot {
                y,
                n,
                settled: false,
                kappa,
            };
        }
        // the distance to the tangent plane is √(|r|² − |t|²): |r| is within |t|²/(2|r|) of it
        if t2 <= 2.0 * tol * d2.sqrt() {
            return Foot {
                y,
                n,
                settled: true,
                kappa,
            };
        }
        if d2 < best_d2 {
            best = Foot {
                y,
                n,
                settled: false,
                kappa,
            };
            best_d2 = d2;
        }
        // a move that does not shrink: the iterates circle across a cell face, where the
        // interpolant's gradient jumps, or among the kinks of the interface (a mask's voxel
        // steps); where they settle they shrink by the ratio of the node's distance to the
        // radius of curvature per step
        let moved = t2.sqrt();
        if moved > STALL_RATIO * last {
            // across a kink the last two iterates lie on either side of it: the point of the zero
            // level set between them is nearer
            let mut mid = [0.0; D];
            for k in 0..D {
                mid[k] = 0.5 * (y[k] + previous[k]);
            }
            if let Some((g, _)) = onto_zero_set(field, &mut mid, ON_ZERO_SET * h, options.eps) {
                let s = squared_distance(x, &mid);
                if let (true, Some(n)) = (s < best_d2, unit(g)) {
                    best = Foot {
                        y: mid,
                        n,
                        settled: false,
                        kappa,
                    };
                    best_d2 = s;
                }
            }
            if accelerated && !plain {
                // an accelerated move that overshot (the curvature estimate was off, as it can
                // be from a neighbour's): plain moves from the nearest point instead, once
                plain = true;
                (y, n, exact) = (best.y, best.n, None);
                (last, t_last, accelerated) = (f64::INFINITY, [0.0; D], false);
                continue;
            }
            break;
        }
        last = moved;
        previous = y;
        let mut scale = 1.0 / (1.0 - rho);
        accelerated = rho != 0.0;
        let mut next = None;
        for _ in 0..=HALVINGS {
            let mut z = [0.0; D];
            for k in 0..D {
                z[k] = y[k] + scale * t[k];
            }
            // in the tangent plane of the interpolant itself, where known: what Newton's steps
            // would take off the move, so a small move lands on the zero level set as it is
            if let Some(e) = exact.filter(|_| scale * moved <= SMALL_MOVE * h) {
                let mut off = 0.0;
                for k in 0..D {
                    off += (z[k] - y[k]) * e[k];
                }
                for k in 0..D {
                    z[k] -= off * e[k];
                }
            }
            if let Some((g, e)) = onto_zero_set(field, &mut z, ON_ZERO_SET * h, options.eps) {
                next = unit(g).map(|n| (z, n, unit(e)));
                break;
            }
            scale *= 0.5;
        }
        let Some((z, normal, e)) = next else {
            break; // no move lands on the zero level set
        };
        (y, n, exact) = (z, normal, e);
    }
    best
}

/// The signed distance to the zero level set of the sampled φ `field` at every node within
/// `options.half_width` of it (see the module documentation), on all threads.
pub fn redistanced_band_of_samples<const D: usize>(
    field: &SampledField<'_, D>,
    options: RedistanceOptions,
) -> Result<RedistancedBand> {
    if !(options.half_width >= 0.0 && options.half_width.is_finite()) {
        return Err(Error::invalid(
            "half_width",
            format!("must be a non-negative width, got {}", options.half_width),
        ));
    }
    if !(options.eps > 0.0 && options.eps.is_finite()) {
        return Err(Error::invalid(
            "eps",
            format!("the step of the differences must be positive, got {}", options.eps),
        ));
    }
    let shape = field.shape();
    let h = field.spacing();
    let lattice = Lattice::new(&shape)?;
    let cells = crossed_cells(&shape, field.samples())?;
    if cells.is_empty() {
        return Ok(RedistancedBand::default());
    }
    let reach = (options.half_width / h * (1.0 + 1e-9)).ceil() as usize;
    let set = NodeSet::around_cells(lattice, &cells, reach);
    let ijk = set.coordinates();
    let m = ijk.len();
    if m >= NONE as usize {
        return Err(Error::invalid(
            "phi",
            format!("the band would hold {m} candidate nodes, more than 2³² − 1: use a coarser grid or a thinner band"),
        ));
    }
    let dims = lattice.dims.map(|n| n as u64);
    // each node's (i, j, k), read instead of divisions of its linear index
    let split = |p: usize| -> (usize, usize, usize) {
        let [i, j, k] = ijk[p];
        (i as usize, j as usize, k as usize)
    };
    // the layers: face steps from a crossed cell's corner (breadth first), as far as a node within
    // the half-width can be: its closest point lies in a crossed cell, within √D/2 spacings of a
    // corner, so at most √D (half_width/Δx + √D/2) face steps from it
    let deepest = ((D as f64).sqrt() * (options.half_width / h) + D as f64 / 2.0 + 1e-9).floor() as u32;
    // the nodes reached (bit p: node p), and those reached for the next layer: read off in the
    // nodes' order (C order), so the layers need no sorting
    let words = m.div_ceil(64);
    let seen: Vec<AtomicU64> = (0..words).map(|_| AtomicU64::new(0)).collect();
    let fresh: Vec<AtomicU64> = (0..words).map(|_| AtomicU64::new(0)).collect();
    let reach_node = |p: usize| {
        let bit = 1u64 << (p % 64);
        if seen[p / 64].fetch_or(bit, Relaxed) & bit == 0 {
            fresh[p / 64].fetch_or(bit, Relaxed);
        }
    };
    let take_fresh = || -> Vec<usize> {
        fresh
            .par_iter()
            .enumerate()
            .with_min_len(256)
            .flat_map_iter(|(w, word)| {
                let mut bits = word.swap(0, Relaxed);
                std::iter::from_fn(move || {
                    (bits != 0).then(|| {
                        let b = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        64 * w + b
                    })
                })
            })
            .collect()
    };
    let (offsets, count) = lattice.corner_offsets();
    cells.par_iter().with_min_len(256).for_each(|&c| {
        for &o in &offsets[..count] {
            let (i, j, k) = lattice.split(c as usize + o);
            reach_node(set.position(i, j, k).expect("a crossed cell's corners are in the set"));
        }
    });
    let mut frontier = take_fresh();
    let n_cells = cells.len();
    drop(cells);
    let node_of = |p: usize| -> ([usize; D], [f64; D]) {
        let mut idx = [0usize; D];
        let mut x = [0.0; D];
        for a in 0..D {
            idx[a] = ijk[p][3 - D + a] as usize;
            x[a] = field.coordinate(a, idx[a]);
        }
        (idx, x)
    };
    // a node whose start lies farther than this is not refined (its distance is then more than
    // the half-width: the start is a neighbour's closest point, within about a spacing of its own)
    let prune = options.half_width + PRUNE_MARGIN * h;
    let distance = |p: usize, y: &[f64; D]| {
        let (_, x) = node_of(p);
        squared_distance(&x, y).sqrt()
    };
    // (ties on the band's edge: rounding)
    let keep = options.half_width * (1.0 + 1e-9);
    // a node whose height above its start's tangent plane, less the bend allowed, exceeds this is
    // beyond the band without refinement
    let above = keep + BEYOND_MARGIN * h;
    // the closest points found, layer after layer (each in C order), and each node's among them
    // (NONE: none yet): the nodes of the layers before have one, those of this layer and after not
    let mut feet: Vec<Foot<D>> = Vec::new();
    let slot: Vec<AtomicU32> = (0..m).map(|_| AtomicU32::new(NONE)).collect();
    let mut depth = 0u32;
    while !frontier.is_empty() {
        // each layer in the nodes' order (C order): the nodes next to each other in the list read
        // the same neighbours' closest points and the same samples
        let before = &feet[..];
        let foot_of = |p: usize| foot_at(before, &slot, p);
        let found: Vec<(u32, Foot<D>)> = frontier
            .par_iter()
            .with_min_len(64)
            .filter_map(|&p| {
                let (idx, x) = node_of(p);
                // the nearest start: a point and the neighbour it comes from (usize::MAX: none)
                let mut start = None;
                let mut nearest = f64::INFINITY;
                // (returns the squared distance of `q`)
                let mut consider = |q: [f64; D], from: usize| {
                    let s = squared_distance(&x, &q);
                    if s < nearest {
                        nearest = s;
                        start = Some((q, from));
                    }
                    s
                };
                // a crossed cell's corner: also the nearest start of the plain rule (its edges'
                // crossings) where one that the rules for nodes on the zero level set add (below)
                // is nearer, refined too, the nearer closest point kept: where those starts lead
                // to a local closest point farther than the plain one (a flat cap a spacing above
                // a node 0.79 spacings inside a cylinder's side) the node is as before
                let mut plain: Option<[f64; D]> = None;
                if depth == 0 {
                    let (mut edge, mut added) = (f64::INFINITY, f64::INFINITY);
                    let near_zero = crossings_at_corner(field, idx, |q, on_zero| {
                        let s = consider(q, usize::MAX);
                        if on_zero {
                            added = added.min(s);
                        } else if s < edge {
                            edge = s;
                            plain = Some(q);
                        }
                    });
                    // a node far nearer the surface than any crossing on its edges, by φ/|∇φ|:
                    // next to a rim that the grid's nodes lie on, where φ vanishes at nodes and the
                    // surface grazes the node's edges (a closed cylinder's exact distance with its
                    // caps on grid planes: the node beside the rim, 0.02Δx off the surface, started
                    // from the zero node a spacing away and stalled there, 0.7–1Δx too far). The
                    // zero level set between the node and the corners of the other sign of its
                    // cells, and along the normal, by bisection (on a smooth φ an edge crossing is
                    // within about √D·|φ|/|∇φ|, and none is looked for)
                    // a node on the zero level set itself, its φ rounding's (a CSG union's corner
                    // on a node, φ = +1e-17, its face neighbours outside or on the surface: it
                    // started from its cells' crossings 1.41Δx away, a helper's review)
                    if near_zero.node && at_rounding(field, idx, field.sample(idx)) {
                        added = 0.0;
                        consider(x, usize::MAX);
                    }
                    for q in grazing_starts(field, idx, &x, edge, near_zero.neighbour, options.eps) {
                        added = added.min(consider(q, usize::MAX));
                    }
                    if added >= edge {
                        plain = None; // the plain start is the nearest: refined once
                    }
                } else {
                    // only the points are read here; the normal and curvature of the nearest below
                    set.neighbours_around(split(p), |q| {
                        if let Some(f) = foot_of(q) {
                            consider(f.y, q);
                        }
                    });
                }
                let (start, from) = start?;
                if nearest.sqrt() > prune {
                    return None;
                }
                let normal = (from != usize::MAX)
                    .then(|| foot_of(from))
                    .flatten()
                    .map(|f| (f.n, if f.settled { f.kappa } else { 0.0 }));
                // far above the start's tangent plane: beyond the band, left out unrefined
                if let Some((n, _)) = normal {
                    let mut along = 0.0;
                    for k in 0..D {
                        along += (x[k] - start[k]) * n[k];
                    }
                    let lateral2 = nearest - along * along;
                    if along.abs() - BEND_ALLOWANCE * lateral2 / h > above {
                        return None;
                    }
                }
                let mut foot = refine(field, &x, start, normal, &options, keep);
                if let Some(q) = plain {
                    let other = refine(field, &x, q, None, &options, keep);
                    if squared_distance(&x, &other.y) < squared_distance(&x, &foot.y) {
                        foot = other;
                    }
                }
                Some((p as u32, foot))
            })
            .collect();
        // the layer's closest points kept, and the next layer: the face neighbours not yet reached
        // of the nodes within the half-width (a band node has a path of face steps to the surface
        // along which its distance falls, so it is reached from band nodes)
        let (offset, last) = (feet.len(), depth == deepest);
        found.par_iter().enumerate().with_min_len(256).for_each(|(i, (p, f))| {
            let p = *p as usize;
            slot[p].store((offset + i) as u32, Relaxed);
            if !last && distance(p, &f.y) <= keep {
                set.face_neighbours(split(p), reach_node);
            }
        });
        feet.extend(found.into_iter().map(|(_, f)| f));
        if last {
            break;
        }
        frontier = take_fresh();
        depth += 1;
    }
    drop((seen, fresh));
    // the band: the nodes within the half-width, in the set's (C) order
    let foot_of = |p: usize| foot_at(&feet, &slot, p);
    let kept: Vec<(u64, f64, [f32; D], bool, bool)> = (0..m)
        .into_par_iter()
        .with_min_len(1024)
        .filter_map(|p| {
            let foot = foot_of(p)?;
            let (idx, x) = node_of(p);
            let y = &foot.y;
            let mut diff = [0.0; D];
            for k in 0..D {
                diff[k] = x[k] - y[k];
            }
            let dist = sum_of_squares(&diff).sqrt();
            if dist > keep {
                return None;
            }
            let signed = if field.sample(idx) < 0.0 { -dist } else { dist };
            // a face neighbour's closest point more than MEDIAL_GAP spacings away: the node is near
            // points equidistant from two parts of the zero set (a focal point or two facing sheets)
            let mut apart = false;
            set.face_neighbours_if(dist <= 0.5 * options.half_width, split(p), |q| {
                if let Some(other) = foot_of(q) {
                    apart |= squared_distance(&other.y, y) > (MEDIAL_GAP * h) * (MEDIAL_GAP * h);
                }
            });
            let good = dist > 1e-9 * h;
            let direction = diff.map(|v| if good { (v / dist) as f32 } else { 0.0 });
            let [i, j, k] = ijk[p].map(|c| c as u64);
            let linear = (i * dims[1] + j) * dims[2] + k;
            Some((linear, signed, direction, foot.settled, apart))
        })
        .collect();
    drop((feet, slot));
    let mut out = RedistancedBand {
        crossed_cells: n_cells,
        linear: Vec::with_capacity(kept.len()),
        signed: Vec::with_capacity(kept.len()),
        direction: Vec::with_capacity(D * kept.len()),
        ..Default::default()
    };
    for (l, signed, direction, settled, apart) in kept {
        out.linear.push(l);
        out.signed.push(signed);
        out.direction.extend_from_slice(&direction);
        out.unsettled += usize::from(!settled);
        out.medial += usize::from(apart);
    }
    Ok(out)
}

#[cfg(test)]
#[path = "redistance_band_tests.rs"]
mod tests;
