//! Tests of `redistance_band.rs`.

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
        max_steps: 40,
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
    // the same fixed point as the projection from the node itself
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
    let (mut apart, mut err_new, mut err_old) = (0.0f64, 0.0f64, 0.0f64);
    for (i, &s) in band.signed.iter().enumerate() {
        assert!(old.converged[i]);
        let e = exact(&node::<3>(41, h, band.linear[i] as usize));
        apart = apart.max((old.signed[i] - s).abs());
        err_new = err_new.max((s - e).abs());
        err_old = err_old.max((old.signed[i] - e).abs());
    }
    // the same fixed point: the distances within 1e-6 Δx of each other (2e-7 Δx measured)
    assert!(apart < 1e-6 * h, "{}", apart / h);
    assert!(err_new <= err_old + 1e-6 * h, "{err_new} against {err_old}");
}

#[test]
fn the_accelerated_moves_settle_in_two_or_three_where_plain_ones_take_five() {
    // the sphere |x|² − R² (R = 0.5) at N = 201, a node 3.5Δx outside it, started from a point
    // of the zero set 1.2Δx (along the surface) from its foot: the plain orthogonality moves
    // shrink the error by ρ = s/R ≈ 0.07 each, the accelerated ones by far more
    let n = 201;
    let (samples, h) = sampled::<3>(n, |x| x.iter().map(|v| v * v).sum::<f64>() - 0.25);
    let field = SampledField::new(&samples, [n; 3], [-1.0; 3], h).unwrap();
    let x = [0.5 + 3.5 * h, 0.0, 0.0];
    let a = 1.2 * h / 0.5;
    let start = [0.5 * a.cos(), 0.5 * a.sin(), 0.0];
    let settled_within = |steps: usize, kappa: f64| {
        let mut o = options(h);
        o.max_steps = steps;
        let normal = unit(field.half_step_gradient(&start)).unwrap();
        refine(&field, &x, start, Some((normal, kappa)), &o, f64::INFINITY)
    };
    // from the curvature the start's node saw (2 = 1/R), two moves and the check that
    // settles: three iterations; from none, a plain first move and then the secant estimate:
    // four (plain moves all along would take about six)
    for (kappa, iterations) in [(2.0, 3), (0.0, 4)] {
        let foot = settled_within(iterations, kappa);
        assert!(foot.settled, "kappa {kappa}");
        assert!(
            (foot.y[0] - 0.5).abs() < 1e-9 && foot.y[1].abs() < 1e-6 * h,
            "{:?}",
            foot.y
        );
        // the curvature it passes on to the next layer: 1/R to a per cent
        assert!((foot.kappa - 2.0).abs() < 0.02, "{}", foot.kappa);
    }
    assert!(!settled_within(2, 2.0).settled && !settled_within(3, 0.0).settled);
}

#[test]
fn the_band_is_the_nodes_within_its_half_width_and_no_others() {
    // the sphere |x|² − R² at N = 41: its interpolant's zero set lies within Δx²/4 (Δx/80) of
    // the sphere, so the band (grown only from its own nodes, the nodes beyond it left after
    // their first small move) holds every node within 4Δx − Δx/20 of the sphere and none
    // beyond 4Δx + Δx/20
    let n = 41;
    let (samples, h) = sampled::<3>(n, |x| x.iter().map(|v| v * v).sum::<f64>() - 0.25);
    let field = SampledField::new(&samples, [n; 3], [-1.0; 3], h).unwrap();
    let band = redistanced_band_of_samples(&field, options(h)).unwrap();
    let exact = |l: usize| norm(&node::<3>(n, h, l)) - 0.5;
    let inner = (0..n * n * n).filter(|&l| exact(l).abs() <= 3.95 * h).count();
    let outer = (0..n * n * n).filter(|&l| exact(l).abs() <= 4.05 * h).count();
    assert!(band.linear.iter().all(|&l| exact(l as usize).abs() <= 4.05 * h));
    let held = band
        .linear
        .iter()
        .filter(|&&l| exact(l as usize).abs() <= 3.95 * h)
        .count();
    assert_eq!(held, inner);
    assert!(band.linear.len() >= inner && band.linear.len() <= outer);
    assert_eq!(band.unsettled, 0);
    // a node 4.6Δx out is left after its first small move, unsettled and beyond 4Δx; without
    // the bound it settles at its distance, a little nearer
    let x = [0.5 + 4.6 * h, 0.0, 0.0];
    let a = 0.8 * h / 0.5;
    let start = [0.5 * a.cos(), 0.5 * a.sin(), 0.0];
    let normal = unit(field.half_step_gradient(&start)).map(|n| (n, 2.0));
    let left = refine(&field, &x, start, normal, &options(h), 4.0 * h);
    let settled = refine(&field, &x, start, normal, &options(h), f64::INFINITY);
    let distance = |y: &[f64; 3]| norm(&[x[0] - y[0], x[1] - y[1], x[2] - y[2]]);
    assert!(!left.settled && settled.settled);
    assert!(distance(&left.y) > 4.0 * h);
    // (the point left is within 0.01Δx of the foot, where the interpolant's zero set lies up
    // to about Δx times that off the sphere: 1.6e-4 Δx here)
    let apart = distance(&left.y) - distance(&settled.y);
    assert!(apart >= 0.0 && apart < 1e-3 * h, "{}", apart / h);
    assert!((distance(&settled.y) - 4.6 * h).abs() < 0.02 * h);
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
        let (worst, _, _) = band_error::<3>(
            n,
            |x| scale * (norm(x) - 0.5).clamp(-2.0 * h, 2.0 * h),
            |x| norm(x) - 0.5,
        );
        assert!(worst < 0.3 * h * h / 0.5 * 2.0, "{worst}");
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

#[test]
fn a_node_grazed_by_a_rim_on_the_grid_starts_from_the_zero_set_beside_it() {
    // a closed cylinder's exact distance (radius 0.4, caps at z = ±0.32 on grid planes, N = 51):
    // φ vanishes at the cap's nodes, and a node beside the rim on the cap's plane, a few hundredths
    // of a spacing outside it, has no crossing on its edges nearer than the zero node a spacing
    // away; started from there its iterations stalled at up to 0.51Δx (0.98Δx at N = 101). The
    // zero set of the interpolant lies 0.24Δx from it there (its rim is cut off within the cell)
    let (r, half) = (0.4, 0.32);
    let exact = |x: &[f64; 3]| {
        let (dr, dz) = ((x[0] * x[0] + x[1] * x[1]).sqrt() - r, x[2].abs() - half);
        dr.max(dz).min(0.0) + (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt()
    };
    let n = 51;
    let (samples, h) = sampled::<3>(n, exact);
    let field = SampledField::new(&samples, [n; 3], [-1.0; 3], h).unwrap();
    let band = redistanced_band_of_samples(&field, options(h)).unwrap();
    let (mut grazed, mut worst) = (0, 0.0f64);
    for (&l, &s) in band.linear.iter().zip(&band.signed) {
        let e = exact(&node::<3>(n, h, l as usize));
        if e.abs() < 0.1 * h {
            grazed += 1;
            worst = worst.max((s - e).abs());
        }
    }
    assert!(grazed > 500, "{grazed}");
    assert!(worst < 0.3 * h, "{}", worst / h);
}

#[test]
fn a_neighbour_on_the_zero_set_by_rounding_is_a_crossing_of_the_node_s_edge() {
    // a box's exact distance (half-sides 0.5, 0.4, 0.3, its faces and edges on the nodes at
    // N = 61): rounding left φ = +5.6e-17 on some edge nodes, so a node a spacing beyond such an
    // edge saw no crossing on its own edges and started from a face's, √2 spacings away, where it
    // stayed: 112 nodes 0.41Δx too far (and a node diagonal to a corner, whose own edges cross
    // nowhere, 0.32Δx until the cells' corners on the zero set by rounding started it too)
    let b = [0.5, 0.4, 0.3];
    let exact = |x: &[f64; 3]| {
        let q: [f64; 3] = std::array::from_fn(|k| x[k].abs() - b[k]);
        let outside = q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
        outside + q[0].max(q[1]).max(q[2]).min(0.0)
    };
    let n = 61;
    let (samples, h) = sampled::<3>(n, exact);
    let field = SampledField::new(&samples, [n; 3], [-1.0; 3], h).unwrap();
    let band = redistanced_band_of_samples(&field, options(h)).unwrap();
    let errors: Vec<f64> = band
        .linear
        .iter()
        .zip(&band.signed)
        .map(|(&l, &s)| (s - exact(&node::<3>(n, h, l as usize))).abs() / h)
        .collect();
    let off = errors.iter().filter(|&&e| e > 0.1).count();
    let worst = errors.iter().cloned().fold(0.0, f64::max);
    assert!(
        off == 0 && worst < 0.01,
        "{off} nodes off by more than 0.1Δx, worst {worst}"
    );
}

#[test]
fn nodes_on_the_zero_set_by_rounding_start_there() {
    // a helper's review: a box's exact distance with every node of its surface at φ = +1e-17 (its
    // edge and corner nodes have their face neighbours of the other sign only diagonally) had 128
    // nodes 0.5Δx too far at N = 121 (44 at N = 61); a union of two boxes, a corner of one on a
    // node (φ there +rounding, its face neighbours outside or on the surface), was placed 1.41Δx
    // from it, with 40 nodes off by more than 0.1Δx outside
    let box_at = |x: &[f64; 3], c: [f64; 3], b: [f64; 3]| {
        let q: [f64; 3] = std::array::from_fn(|k| (x[k] - c[k]).abs() - b[k]);
        let outside = q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
        outside + q[0].max(q[1]).max(q[2]).min(0.0)
    };
    let n = 61;
    let rounded = |x: &[f64; 3]| {
        let d = box_at(x, [0.0; 3], [0.5, 0.4, 0.3]);
        if d.abs() < 1e-12 {
            1e-17
        } else {
            d
        }
    };
    let union = |x: &[f64; 3]| box_at(x, [0.0; 3], [0.5, 0.3, 0.3]).min(box_at(x, [0.3, 0.2, 0.0], [0.3, 0.3, 0.2]));
    for (phi, outside_only, bound) in [(&rounded as &dyn Fn(&[f64; 3]) -> f64, false, 0.1), (&union, true, 0.3)] {
        let (samples, h) = sampled::<3>(n, phi);
        let field = SampledField::new(&samples, [n; 3], [-1.0; 3], h).unwrap();
        let band = redistanced_band_of_samples(&field, options(h)).unwrap();
        let mut worst = 0.0f64;
        for (&l, &s) in band.linear.iter().zip(&band.signed) {
            let e = phi(&node::<3>(n, h, l as usize));
            // (inside a union min(d₁, d₂) is not the distance)
            if !outside_only || e > 0.0 {
                worst = worst.max((s.abs() - e.abs()) / h);
            }
        }
        assert!(worst < bound, "{worst}");
    }
}
