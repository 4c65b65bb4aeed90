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
//!    linear interpolation of the two end values ([`edge_crossings`]), with no use of ∇φ.
//! 2. **Closest points, layer by layer.** The nodes within `reach` cells of a crossed cell
//!    ([`NodeSet`]) are ordered by their number of face steps from a crossed cell's corner. A
//!    corner takes the nearest edge crossing of its crossed cells, a node of a later layer the
//!    nearest closest point of its face neighbours of the layer before, as its starting point,
//!    or the point Newton steps from the node reach on the zero level set if that is nearer
//!    (where φ is smooth it lies next to the closest point, and the refinement is short).
//! 3. **Refinement on the interpolant.** From that point on the zero level set, the
//!    orthogonality iterations of the projection: `y ← P(y + (I − n nᵀ)(x − y))`, a move in the
//!    tangent plane towards the foot of the node (the normal `n` from central differences of φ
//!    with step `eps`, as the projection takes it), then Newton steps `P` back onto the level
//!    set with the exact gradient of the cell's interpolant (quadratic convergence), until
//!    `x − y` is along the normal. Each step must land on the zero level set (|φ| below
//!    `1e-9 · Δx · |∇φ|`), otherwise the tangential move is halved (once), and
//!    failing that the iterations stop. So every iterate is a point of the zero level set, whose
//!    distance from the node bounds the node's distance from above, and ∇φ is only read next to
//!    the zero level set, where the sign change makes it non-zero: never on a plateau. The
//!    iterations stop when their moves no longer shrink (they circle among the kinks of a mask's
//!    voxel steps); a node whose iterations do not settle keeps the iterate nearest to it.
//!
//! Where φ is smooth the iterations settle on the same closest point as the projection from the
//! node itself (the same fixed point, `x − y` along the central-difference normal), so the
//! distances agree with it to the settling tolerance; the distance to the interpolant's zero set
//! is second order in Δx (the interpolant moves the surface by `Δx²|D²φ|/(8|∇φ|)` at most).
//! Where the interface has kinks (a mask's voxel steps, a crease) the iterations may stop
//! before settling: the point reached is the nearest zero-set point found, counted in
//! [`RedistancedBand::unsettled`]. The work and the memory scale with the band: one pass over the
//! samples finds the crossed cells, everything else is per node near them.

use crate::error::{Error, Result};
use rayon::prelude::*;

use super::interface_cells::{crossed_cells, edge_crossings, Lattice, NodeSet};
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
    /// A point has settled when an iteration moves it by at most `tol · Δx` (its distance is then
    /// within about `(tol · Δx)² / |x − cp(x)|` of the fixed point's).
    pub tol: f64,
}

/// A point is on the zero level set when `|φ| ≤ ON_ZERO_SET · Δx · |∇φ|` there (about that many
/// grid spacings from it along the normal); the iterations go on until they settle (a move of
/// at most `tol`), each with Newton steps, so a settled point is on it to rounding.
const ON_ZERO_SET: f64 = 1e-9;

/// The refinement stops when [`STALLED_STEPS`] moves in a row are each more than [`STALL_RATIO`]
/// times the one before.
const STALL_RATIO: f64 = 0.9;
const STALLED_STEPS: usize = 2;

/// Halvings of a tangential move that does not land on the zero level set closer to the node.
const HALVINGS: usize = 1;

/// The Newton steps of the projection from the node (`tubesweep.redistance.NEWTON_STEPS`).
const PROJECTION_NEWTON_STEPS: usize = 6;

/// The most Newton steps that take a point back onto the zero level set after a tangential move.
const NEWTON_STEPS: usize = 4;

/// Newton steps from `z` onto the zero level set of the multilinear interpolant, with its exact
/// gradient in the cell that holds the point (quadratic convergence within a cell; the points kept
/// in the grid's box), until `|φ| ≤ on_zero_set`, [`NEWTON_STEPS`] at most: whether it got there.
/// Only the orthogonality direction uses the central differences, so the fixed point (φ = 0, `x − y`
/// along them) is that of the projection from the node.
#[inline]
fn onto_zero_set<const D: usize>(field: &SampledField<'_, D>, z: &mut [f64; D], on_zero_set: f64) -> bool {
    field.clamp_to_box(z);
    for _ in 0..NEWTON_STEPS {
        let (v, g) = field.value_and_gradient(z);
        if v.abs() <= on_zero_set {
            return true;
        }
        let n2 = sum_of_squares(&g);
        if !(n2 > 1e-300) {
            return false;
        }
        let s = v / n2;
        for k in 0..D {
            z[k] -= s * g[k];
        }
        field.clamp_to_box(z);
    }
    field.value(z).abs() <= on_zero_set
}

/// The closest point of the node `x` on the zero level set of `field`'s interpolant, from `start`
/// (a point of it): step 3 of the module documentation. Returns the point and whether it settled;
/// a point that did not settle is the nearest to `x` of the iterates.
#[inline]
fn refine<const D: usize>(
    field: &SampledField<'_, D>,
    x: &[f64; D],
    start: [f64; D],
    options: &RedistanceOptions,
    settled: f64,
) -> ([f64; D], bool) {
    let distance = |y: &[f64; D]| {
        let mut s = 0.0;
        for k in 0..D {
            s += (x[k] - y[k]) * (x[k] - y[k]);
        }
        s.sqrt()
    };
    let mut y = start;
    let (mut nearest, mut best) = (start, distance(&start));
    let (mut last_move, mut stalled) = (f64::INFINITY, 0);
    for _ in 0..options.max_steps {
        let g = field.gradient(&y, options.eps);
        let n2 = sum_of_squares(&g);
        if !(n2 > 1e-300) {
            break;
        }
        let norm = n2.sqrt();
        let on_zero_set = ON_ZERO_SET * field.spacing() * norm;
        let mut n = [0.0; D];
        let mut t = [0.0; D];
        let mut along = 0.0;
        for k in 0..D {
            n[k] = g[k] / norm;
            along += (x[k] - y[k]) * n[k];
        }
        for k in 0..D {
            t[k] = (x[k] - y[k]) - along * n[k];
        }
        let mut scale = 1.0;
        let mut next = None;
        for _ in 0..=HALVINGS {
            let mut z = [0.0; D];
            for k in 0..D {
                z[k] = y[k] + scale * t[k];
            }
            if onto_zero_set(field, &mut z, on_zero_set) {
                next = Some(z);
                break;
            }
            scale *= 0.5;
        }
        let Some(z) = next else {
            // no move lands on the zero level set: settled if the node is along the normal
            return if sum_of_squares(&t).sqrt() <= settled {
                (y, true)
            } else {
                (nearest, false)
            };
        };
        let mut step = [0.0; D];
        for k in 0..D {
            step[k] = z[k] - y[k];
        }
        y = z;
        if sum_of_squares(&step).sqrt() <= settled {
            return (y, true);
        }
        let dz = distance(&y);
        if dz < best {
            (nearest, best) = (y, dz);
        }
        // moves that no longer shrink: the iterates circle among the kinks of the interface (a
        // mask's voxel steps) instead of settling; where they settle they shrink by the ratio of
        // the node's distance to the radius of curvature per step
        let moved = sum_of_squares(&step).sqrt();
        stalled = if moved > STALL_RATIO * last_move {
            stalled + 1
        } else {
            0
        };
        if stalled >= STALLED_STEPS {
            break;
        }
        last_move = moved;
    }
    (nearest, false)
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
    let linear = set.linear();
    let m = linear.len();
    // the layers: face steps from a crossed cell's corner (breadth first)
    const UNSEEN: u32 = u32::MAX;
    let mut layer = vec![UNSEEN; m];
    let (offsets, count) = lattice.corner_offsets();
    let mut frontier: Vec<usize> = Vec::new();
    for &c in &cells {
        for &o in &offsets[..count] {
            let (i, j, k) = lattice.split(c as usize + o);
            let p = set.position(i, j, k).expect("a crossed cell's corners are in the set");
            if layer[p] == UNSEEN {
                layer[p] = 0;
                frontier.push(p);
            }
        }
    }
    let n_cells = cells.len();
    drop(cells);
    let mut layers: Vec<Vec<usize>> = Vec::new();
    while !frontier.is_empty() {
        let depth = layers.len() as u32 + 1;
        let mut next = Vec::new();
        for &p in &frontier {
            set.face_neighbours(lattice.split(linear[p] as usize), |q| {
                if layer[q] == UNSEEN {
                    layer[q] = depth;
                    next.push(q);
                }
            });
        }
        layers.push(std::mem::replace(&mut frontier, next));
    }
    let settled = options.tol * h;
    let node_of = |p: usize| -> ([usize; D], [f64; D]) {
        let mut l = linear[p] as usize;
        let mut idx = [0usize; D];
        let mut x = [0.0; D];
        for a in (0..D).rev() {
            idx[a] = l % shape[a];
            l /= shape[a];
            x[a] = field.coordinate(a, idx[a]);
        }
        (idx, x)
    };
    let mut closest = vec![[0.0f64; D]; m];
    let mut converged = vec![false; m];
    for (depth, nodes) in layers.iter().enumerate() {
        let found: Vec<([f64; D], bool)> = nodes
            .par_iter()
            .with_min_len(64)
            .map(|&p| {
                let (idx, x) = node_of(p);
                let mut start = None;
                let mut nearest = f64::INFINITY;
                let mut consider = |q: [f64; D]| {
                    let mut s = 0.0;
                    for k in 0..D {
                        s += (x[k] - q[k]) * (x[k] - q[k]);
                    }
                    if s < nearest {
                        nearest = s;
                        start = Some(q);
                    }
                };
                if depth == 0 {
                    // the edge crossings of the crossed cells the node is a corner of
                    for around in 0..1usize << D {
                        let mut lowest = idx;
                        let mut inside = true;
                        for a in 0..D {
                            if around >> a & 1 == 1 {
                                if lowest[a] == 0 {
                                    inside = false;
                                }
                                lowest[a] = lowest[a].wrapping_sub(1);
                            } else if lowest[a] + 1 >= shape[a] {
                                inside = false;
                            }
                        }
                        if inside {
                            edge_crossings(field, lowest, &mut consider);
                        }
                    }
                } else {
                    set.face_neighbours(lattice.split(linear[p] as usize), |q| {
                        if layer[q] < depth as u32 {
                            consider(closest[q]);
                        }
                    });
                }
                // and the Newton projection of the node itself, where ∇φ lets it reach the zero
                // level set (where φ is smooth, near the node's closest point: few refinements)
                // (the projection's first Newton steps, with the central differences, whose
                // direction at the node points at its closest point where φ is smooth)
                let mut own = x;
                if field.newton(&mut own, PROJECTION_NEWTON_STEPS, options.eps) {
                    let (_, g) = field.value_and_gradient(&own);
                    if onto_zero_set(field, &mut own, ON_ZERO_SET * h * sum_of_squares(&g).sqrt()) {
                        consider(own);
                    }
                }
                let start = start.expect("a corner of a crossed cell, or a neighbour of the layer before");
                refine(field, &x, start, &options, settled)
            })
            .collect();
        for (&p, (y, ok)) in nodes.iter().zip(found) {
            closest[p] = y;
            converged[p] = ok;
        }
    }
    drop(layer);
    // the band: the nodes within the half-width
    let mut out = RedistancedBand {
        crossed_cells: n_cells,
        ..Default::default()
    };
    let keep = options.half_width * (1.0 + 1e-9); // ties on the band's edge: rounding
    for p in 0..m {
        let (idx, x) = node_of(p);
        let y = &closest[p];
        let mut diff = [0.0; D];
        for k in 0..D {
            diff[k] = x[k] - y[k];
        }
        let dist = sum_of_squares(&diff).sqrt();
        if dist > keep {
            continue;
        }
        out.linear.push(linear[p]);
        out.signed.push(if field.sample(idx) < 0.0 { -dist } else { dist });
        let good = dist > 1e-9 * h;
        for v in diff {
            out.direction.push(if good { (v / dist) as f32 } else { 0.0 });
        }
        out.unsettled += usize::from(!converged[p]);
        // a face neighbour's closest point more than MEDIAL_GAP spacings away: the node is near
        // points equidistant from two parts of the zero set (a focal point or two facing sheets)
        let mut apart = false;
        set.face_neighbours_if(
            dist <= 0.5 * options.half_width,
            lattice.split(linear[p] as usize),
            |q| {
                let mut s = 0.0;
                for k in 0..D {
                    s += (closest[q][k] - y[k]) * (closest[q][k] - y[k]);
                }
                apart |= s > (MEDIAL_GAP * h) * (MEDIAL_GAP * h);
            },
        );
        out.medial += usize::from(apart);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::redistance::{project_to_zero_level_set, ProjectionOptions};

    /// `f(x)` sampled at the nodes of the grid `[−1, 1]^D` with `n` nodes per axis.
    fn sampled<const D: usize>(n: usize, f: impl Fn(&[f64; D]) -> f64) -> (Vec<f64>, f64) {
        let h = 2.0 / (n - 1) as f64;
        let samples = (0..n.pow(D as u32))
            .map(|mut l| {
                let mut x = [0.0; D];
                for k in (0..D).rev() {
                    x[k] = -1.0 + h * (l % n) as f64;
                    l /= n;
                }
                f(&x)
            })
            .collect();
        (samples, h)
    }

    fn node<const D: usize>(n: usize, h: f64, mut l: usize) -> [f64; D] {
        let mut x = [0.0; D];
        for k in (0..D).rev() {
            x[k] = -1.0 + h * (l % n) as f64;
            l /= n;
        }
        x
    }

    fn options(h: f64) -> RedistanceOptions {
        RedistanceOptions {
            half_width: 4.0 * h,
            eps: 0.5 * h,
            max_steps: 60,
            tol: 1e-12,
        }
    }

    fn norm<const D: usize>(x: &[f64; D]) -> f64 {
        x.iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// The largest error of the band's signed distances against `exact`, and whether the band
    /// holds every node within `inside` of the exact surface.
    fn band_error<const D: usize>(
        n: usize,
        phi: impl Fn(&[f64; D]) -> f64,
        exact: impl Fn(&[f64; D]) -> f64,
    ) -> (f64, RedistancedBand, f64) {
        let (samples, h) = sampled::<D>(n, phi);
        let field = SampledField::new(&samples, [n; D], [-1.0; D], h).unwrap();
        let band = redistanced_band_of_samples(&field, options(h)).unwrap();
        let mut worst = 0.0f64;
        for (&l, &s) in band.linear.iter().zip(&band.signed) {
            worst = worst.max((s - exact(&node::<D>(n, h, l as usize))).abs());
        }
        // every node within the half-width less a cell of the exact surface is in the band
        let missing = (0..n.pow(D as u32))
            .filter(|&l| exact(&node::<D>(n, h, l)).abs() <= 3.0 * h)
            .filter(|&l| band.linear.binary_search(&(l as u64)).is_err())
            .count();
        assert_eq!(missing, 0);
        (worst, band, h)
    }

    #[test]
    fn a_skewed_quadric_is_redistanced_to_second_order_and_as_the_projection_from_the_node() {
        let phi = |x: &[f64; 3]| (x.iter().map(|v| v * v).sum::<f64>() - 0.25) * (1.0 + 0.3 * x[0]);
        let exact = |x: &[f64; 3]| norm(x) - 0.5;
        let (coarse, _, _) = band_error::<3>(21, phi, exact);
        let (fine, band, h) = band_error::<3>(41, phi, exact);
        assert!(fine < 0.3 * h * h / 0.5 * 2.0, "{fine}"); // ≈ Δx²/(8r) from the interpolant
        assert!(coarse / fine > 3.0, "second order: {coarse} → {fine}");
        assert_eq!(band.unsettled, 0);
        // the same fixed point as the projection from the node itself, to its settling tolerance
        let (samples, _) = sampled::<3>(41, phi);
        let field = SampledField::new(&samples, [41; 3], [-1.0; 3], h).unwrap();
        let pts: Vec<f64> = band.linear.iter().flat_map(|&l| node::<3>(41, h, l as usize)).collect();
        let old = project_to_zero_level_set(
            &field,
            &pts,
            ProjectionOptions {
                eps: 0.5 * h,
                newton_steps: 6,
                orthogonality_steps: 300,
                tol: 1e-12,
            },
        )
        .unwrap();
        for (i, &s) in band.signed.iter().enumerate() {
            assert!(old.converged[i]);
            assert!((old.signed[i] - s).abs() < 1e-10, "{} against {s}", old.signed[i]);
        }
    }

    #[test]
    fn a_mask_is_redistanced_to_within_its_voxels_and_converges() {
        // 0/1 masks of a circle and a sphere, φ = 0.5 − mask: ∇φ vanishes away from the surface
        let mut last = f64::INFINITY;
        for n in [41, 81] {
            let (worst, band, h) = band_error::<2>(n, |x| if norm(x) < 0.5 { -0.5 } else { 0.5 }, |x| norm(x) - 0.5);
            assert!(worst < 0.75 * h, "n = {n}: {worst}");
            assert!(worst < 0.6 * last);
            last = worst;
            // and the directions are unit vectors off the surface
            for (i, &s) in band.signed.iter().enumerate() {
                let v = &band.direction[2 * i..2 * i + 2];
                if s.abs() > 1e-6 {
                    assert!(((v[0] * v[0] + v[1] * v[1]).sqrt() - 1.0).abs() < 1e-6);
                }
            }
        }
        let (worst, _, h) = band_error::<3>(31, |x| if norm(x) < 0.5 { -0.5 } else { 0.5 }, |x| norm(x) - 0.5);
        assert!(worst < 0.75 * h, "{worst}");
    }

    #[test]
    fn plateaus_and_a_flat_phi_far_from_the_surface_are_no_obstacle() {
        // the sphere's distance clamped to ±2Δx (∇φ = 0 beyond), and the same scaled by 1e-6
        for scale in [1.0, 1e-6] {
            let n = 41;
            let h = 2.0 / (n - 1) as f64;
            let (worst, band, _) = band_error::<3>(
                n,
                |x| scale * (norm(x) - 0.5).clamp(-2.0 * h, 2.0 * h),
                |x| norm(x) - 0.5,
            );
            assert!(worst < 0.3 * h * h / 0.5 * 2.0, "{worst}");
            assert_eq!(band.unsettled, 0);
        }
        // no sign change: no band
        let (samples, h) = sampled::<2>(11, |x| 1.0 + x[0] * x[0]);
        let field = SampledField::new(&samples, [11; 2], [-1.0; 2], h).unwrap();
        let band = redistanced_band_of_samples(&field, options(h)).unwrap();
        assert!(band.linear.is_empty() && band.crossed_cells == 0);
        let mut bad = options(h);
        bad.half_width = f64::NAN;
        assert!(redistanced_band_of_samples(&field, bad).is_err());
    }
}
