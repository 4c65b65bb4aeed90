use super::*;

/// Deterministic points spread over the sphere of radius `r` (a Fibonacci lattice).
fn sphere(n: usize, r: f64) -> Vec<[f64; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            [r * s * t.cos(), r * s * t.sin(), r * z]
        })
        .collect()
}

#[test]
fn sphere_closest_points_are_accurate() {
    let cloud = PointCloud::new(sphere(20_000, 0.5), DEFAULT_NEIGHBOURS).unwrap();
    let queries: Vec<[f64; 3]> = sphere(500, 0.6).into_iter().chain(sphere(300, 0.42)).collect();
    let (cp, feet) = cloud.closest_points(&queries, 0.0, 0.0);
    for (q, (c, f)) in queries.iter().zip(cp.iter().zip(&feet)) {
        assert_eq!(*f, Foot::Interior);
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let exact = [0.5 * q[0] / r, 0.5 * q[1] / r, 0.5 * q[2] / r];
        assert!(distance(c, &exact) < 1e-6, "{:?} vs {:?}", c, exact);
    }
}

#[test]
fn a_closed_cloud_has_no_rim_and_no_outliers() {
    let mut cloud = PointCloud::new(sphere(5_000, 0.5), DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    assert_eq!(cloud.mark_rim(&a.gap).unwrap(), 0);
    assert!(a.residual.iter().all(|&r| r < 1e-3));
}

#[test]
fn a_plane_patch_has_a_rim_and_clamps_to_it() {
    let mut pts = Vec::new();
    for i in 0..40 {
        for j in 0..40 {
            pts.push([i as f64 / 39.0, j as f64 / 39.0, 0.0]);
        }
    }
    let mut cloud = PointCloud::new(pts, DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    assert!(cloud.mark_rim(&a.gap).unwrap() >= 4 * 38);
    let (c, f) = cloud.closest_point(&[0.5, 0.5, 0.1], 0.0);
    assert_eq!(f, Foot::Interior);
    assert!(distance(&c, &[0.5, 0.5, 0.0]) < 1e-12);
    let (c, f) = cloud.closest_point(&[1.1, 0.5, 0.05], 0.0);
    assert_eq!(f, Foot::Rim);
    assert!(distance(&c, &[1.0, 0.5, 0.0]) < 1e-9, "{c:?}");
}

#[test]
fn an_outlier_has_a_large_residual() {
    let mut pts = sphere(5_000, 0.5);
    pts.push([0.0, 0.0, 0.56]);
    let cloud = PointCloud::new(pts, DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    let last = *a.residual.last().unwrap();
    assert!(last > OUTLIER_RATIO, "{last}");
    let inliers = &a.residual[..a.residual.len() - 1];
    assert!(inliers.iter().filter(|&&r| r > OUTLIER_RATIO).count() == 0);
}

#[test]
fn a_circle_of_samples() {
    let pts: Vec<[f64; 2]> = (0..400)
        .map(|i| {
            let t = i as f64 * std::f64::consts::TAU / 400.0;
            [0.5 * t.cos(), 0.5 * t.sin()]
        })
        .collect();
    let mut cloud = PointCloud::new(pts, 10).unwrap();
    let a = cloud.analyse();
    assert_eq!(cloud.mark_rim(&a.gap).unwrap(), 0);
    let (c, f) = cloud.closest_point(&[0.3, 0.4], 0.0);
    assert_eq!(f, Foot::Interior);
    assert!(distance(&c, &[0.3, 0.4]) < 1e-5, "{c:?}");
    let (c, _) = cloud.closest_point(&[0.6, 0.8], 0.0);
    assert!(distance(&c, &[0.3, 0.4]) < 1e-5, "{c:?}");
}

#[test]
fn bad_clouds_are_refused() {
    assert!(PointCloud::<3>::new(vec![], DEFAULT_NEIGHBOURS).is_err());
    assert!(PointCloud::new(sphere(10, 0.5), DEFAULT_NEIGHBOURS).is_err());
    let mut p = sphere(100, 0.5);
    p[3][1] = f64::NAN;
    assert!(PointCloud::new(p, DEFAULT_NEIGHBOURS).is_err());
}

#[test]
fn a_small_group_of_stray_samples_is_isolated_and_the_surface_is_not() {
    // three samples 0.1 apart, far from a sampled sphere: their own fit passes the residual test
    let mut p = sphere(3000, 0.5);
    p.extend([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]);
    let cloud = PointCloud::new(p.clone(), DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    let mut r = a.radius.clone();
    r.sort_by(f64::total_cmp);
    let flags = cloud
        .isolated(&a.spacing, &a.radius, r[r.len() / 2], DEFAULT_NEIGHBOURS + 2)
        .unwrap();
    assert_eq!(flags.iter().filter(|&&f| f).count(), 3);
    assert!(flags[3000..].iter().all(|&f| f));
    // two spheres far apart (two parts, each a surface): none isolated
    let mut two = sphere(2000, 0.5);
    two.extend(sphere(2000, 0.5).iter().map(|q| [q[0] + 3.0, q[1], q[2]]));
    let cloud = PointCloud::new(two, DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    let flags = cloud
        .isolated(&a.spacing, &a.radius, 0.0, DEFAULT_NEIGHBOURS + 2)
        .unwrap();
    assert!(flags.iter().all(|&f| !f));
}

#[test]
fn the_ends_of_a_spiral_are_its_rim_though_the_next_turn_lies_beyond_them() {
    // an Archimedean spiral r = 0.15 + b θ, turns 0.12 apart, sampled every 0.0033: past its inner
    // end the tangent points at the next turn, which curves the other way and must not fill the gap
    let b = 0.12 / std::f64::consts::TAU;
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut t: f64 = 0.0;
    while 0.15 + b * t < 0.8 {
        let r = 0.15 + b * t;
        pts.push([r * t.cos(), r * t.sin()]);
        t += 0.0033 / (r * r + b * b).sqrt();
    }
    let n = pts.len();
    let mut cloud = PointCloud::new(pts, DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    assert_eq!(cloud.mark_rim(&a.gap).unwrap(), 2);
    assert!(cloud.rim[0] && cloud.rim[n - 1]);
}

#[test]
fn a_cloud_of_fewer_than_twice_the_neighbours_answers_without_panicking() {
    // the candidates' cache took the 2k + 1 nearest samples and read the last of them: a cloud of
    // k + 2 to 2k samples (which a fit allows) panicked with an index out of bounds
    for n in [DEFAULT_NEIGHBOURS + 2, 30, 2 * DEFAULT_NEIGHBOURS] {
        let cloud = PointCloud::new(sphere(n, 0.5), DEFAULT_NEIGHBOURS).unwrap();
        let (c, _) = cloud.closest_point(&[0.0, 0.0, 0.7], 0.0);
        let r = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        assert!((r - 0.5).abs() < 0.05, "{n} samples: |foot| = {r}");
    }
}

/// The nearest samples of a sample: itself first, then the others by distance (the brute-force
/// order on a small cloud); k out of range and an index beyond the cloud are refused.
#[test]
fn nearest_samples_are_the_sample_then_the_nearest_others() {
    let points = sphere(400, 0.5);
    let cloud = PointCloud::new(points.clone(), DEFAULT_NEIGHBOURS).unwrap();
    let which = [0usize, 17, 399];
    let near = cloud.nearest_samples(&which, 6).unwrap();
    assert_eq!(near.len(), 18);
    for (row, &i) in which.iter().enumerate() {
        let mut order: Vec<usize> = (0..points.len()).collect();
        order.sort_by(|&a, &b| distance(&points[i], &points[a]).total_cmp(&distance(&points[i], &points[b])));
        let got: Vec<usize> = near[6 * row..6 * row + 6].iter().map(|&j| j as usize).collect();
        assert_eq!(got, order[..6].to_vec(), "sample {i}");
    }
    assert!(cloud.nearest_samples(&which, 0).is_err());
    assert!(cloud.nearest_samples(&which, 401).is_err());
    assert!(cloud.nearest_samples(&[400], 3).is_err());
}

#[test]
fn a_sparsely_sampled_stretch_of_a_curve_is_not_isolated_by_its_random_gaps() {
    // an ellipse 0.6 × 0.35, its right half sampled 20 times more densely than its left, at
    // random: the left half's gaps often exceed three times both neighbours' spacings, and its
    // samples fell apart into groups smaller than a fit, taken for strays (a helper's review)
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut pts: Vec<[f64; 2]> = Vec::new();
    while pts.len() < 4200 {
        let t = uniform() * std::f64::consts::TAU;
        if t.cos() > 0.0 || uniform() < 0.05 {
            pts.push([0.6 * t.cos(), 0.35 * t.sin()]);
        }
    }
    let cloud = PointCloud::new(pts, DEFAULT_NEIGHBOURS).unwrap();
    let a = cloud.analyse();
    let mut r = a.radius.clone();
    r.sort_by(f64::total_cmp);
    let median = r[r.len() / 2];
    let need = DEFAULT_NEIGHBOURS + 2;
    let with_radii = cloud.isolated(&a.spacing, &a.radius, median, need).unwrap();
    assert_eq!(with_radii.iter().filter(|&&f| f).count(), 0);
    // (by the spacings and the median radius alone, part of the sparse half is cut off)
    let without = cloud.isolated(&a.spacing, &[], median, need).unwrap();
    assert!(without.iter().filter(|&&f| f).count() > 10);
}

/// A sphere of radius 0.5 sampled on circles of latitude `dz` apart (`ds` apart along them),
/// the slices of a scan, with no sample above the last slice nor below the first (its caps).
fn sliced_sphere(dz: f64, ds: f64) -> Vec<[f64; 3]> {
    let mut pts = Vec::new();
    let mut z = -0.5 + 0.5 * dz;
    while z < 0.5 {
        let r = (0.25 - z * z).sqrt();
        let m = ((std::f64::consts::TAU * r / ds) as usize).max(8);
        for i in 0..m {
            let t = std::f64::consts::TAU * i as f64 / m as f64;
            pts.push([r * t.cos(), r * t.sin(), z]);
        }
        z += dz;
    }
    pts
}

#[test]
fn a_point_on_the_axis_of_a_ring_of_samples_has_a_closest_point() {
    // slices 0.06 apart, the last at z = 0.49 (a ring of radius 0.0995 around the unsampled
    // cap): every sample of that ring lies at the same distance from a point on its axis, and
    // their fit weighed them all zero and failed (NaN, which refused the cloud's solve)
    let cloud = PointCloud::new(sliced_sphere(0.06, 0.003), 100).unwrap();
    for z in [0.5, 0.52] {
        let (c, f) = cloud.closest_point(&[0.0, 0.0, z], 0.0);
        assert_eq!(f, Foot::Interior, "at z = {z}");
        // the cap is bridged by the fits over the last slices (flat to within 1e-3)
        assert!(distance(&c, &[0.0, 0.0, 0.49]) < 1e-3, "{c:?}");
    }
}

#[test]
fn a_cap_left_unsampled_within_one_and_a_half_reaches_is_bridged_a_wider_one_is_a_rim() {
    // the first slice at z = -0.47 rings a cap of radius 0.17, 1.25 times the widest fit (0.136
    // over 100 neighbours): its middle is found on the fits' bridge (before, a foot that far from
    // every sample was taken as off the samples and projected onto a ring sample's own fit,
    // folding the closest points)
    let mut cloud = PointCloud::new(sliced_sphere(0.06, 0.003), 100).unwrap();
    let a = cloud.analyse();
    assert_eq!(cloud.mark_rim(&a.gap).unwrap(), 0);
    let reach = cloud.reach();
    assert!(0.17 > reach && 0.17 < BRIDGED_REACH * reach, "{reach}");
    let (c, f) = cloud.closest_point(&[0.01, 0.0, -0.5], 0.0);
    assert_eq!(f, Foot::Interior);
    assert!(distance(&c, &[0.01, 0.0, -0.47]) < 2e-3, "{c:?}");
    // slices only within |z| ≤ 0.4: caps of radius 0.3, over twice the reach, are rims (the
    // nearest samples around a last slice's sample, along its own ring, hid the cap: the ring's
    // far samples, beyond the reach, no longer close the gap)
    let pts: Vec<[f64; 3]> = sliced_sphere(0.06, 0.003)
        .into_iter()
        .filter(|p| p[2].abs() <= 0.4)
        .collect();
    let mut cloud = PointCloud::new(pts.clone(), 100).unwrap();
    let a = cloud.analyse();
    let rim = cloud.mark_rim(&a.gap).unwrap();
    let last = pts.iter().filter(|p| p[2].abs() > 0.34).count();
    assert_eq!(rim, last, "{rim} of {last}");
}
