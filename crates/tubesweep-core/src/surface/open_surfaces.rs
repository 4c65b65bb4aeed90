//! Closest points on the library's simple open surfaces (the closest-point representation of the
//! paper's Sect. 5.2): the upper hemisphere of Fig. 9, the flat disc and the square plane patch.
//!
//! Each is the arithmetic of the Python `_cp_numpy` of `tubesweep.surfaces.Hemisphere`, `Disc`
//! and `PlanePatch`, operation for operation, so the closest points are the same bits (tested from
//! Python); NaN coordinates go the way NumPy's comparisons send them. Points are rows of three
//! coordinates; the work is split over all threads.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Points per parallel task.
const CHUNK: usize = 1 << 12;

type V3 = [f64; 3];

/// `v / |v|` where `|v| > 1e-300`, else `fallback` (NumPy's `_safe_unit`; the norm sums the
/// squares in axis order).
#[inline]
fn safe_unit(v: V3, fallback: V3) -> V3 {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 1e-300 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        fallback
    }
}

/// Applies `cp` to every row of `points` (M × 3) into `out` (M × 3), on all threads.
fn map_points(points: &[f64], out: &mut [f64], cp: impl Fn(V3) -> V3 + Sync) -> Result<()> {
    if !points.len().is_multiple_of(3) {
        return Err(Error::invalid("points", "expected an (M, 3) array"));
    }
    if out.len() != points.len() {
        return Err(Error::invalid(
            "out",
            format!("expected {} values (three per point)", points.len()),
        ));
    }
    out.par_chunks_mut(3 * CHUNK)
        .zip(points.par_chunks(3 * CHUNK))
        .for_each(|(o, p)| {
            for (o, x) in o.chunks_exact_mut(3).zip(p.chunks_exact(3)) {
                o.copy_from_slice(&cp([x[0], x[1], x[2]]));
            }
        });
    Ok(())
}

fn check_centre_and_size(centre: V3, size: f64, name: &'static str) -> Result<()> {
    if !centre.iter().all(|c| c.is_finite()) {
        return Err(Error::invalid("centre", "must be finite"));
    }
    if !(size > 0.0 && size.is_finite()) {
        return Err(Error::invalid(name, format!("must be positive and finite, got {size}")));
    }
    Ok(())
}

/// The upper hemisphere `{|x − c| = radius, z ≥ c_z}`: the radial projection where `z ≥ c_z`,
/// else the nearest point of the rim circle (with NumPy's fallbacks at the centre and on the axis).
pub fn hemisphere_closest_points(points: &[f64], centre: V3, radius: f64, out: &mut [f64]) -> Result<()> {
    check_centre_and_size(centre, radius, "radius")?;
    map_points(points, out, |x| {
        let q = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
        let u = if q[2] >= 0.0 {
            safe_unit(q, [0.0, 0.0, 1.0])
        } else {
            safe_unit([q[0], q[1], 0.0], [1.0, 0.0, 0.0])
        };
        [
            u[0] * radius + centre[0],
            u[1] * radius + centre[1],
            u[2] * radius + centre[2],
        ]
    })
}

/// The flat disc of `radius` in the plane `z = c_z`: drop z, then clip the in-plane offset to the
/// radius.
pub fn disc_closest_points(points: &[f64], centre: V3, radius: f64, out: &mut [f64]) -> Result<()> {
    check_centre_and_size(centre, radius, "radius")?;
    map_points(points, out, |x| {
        let q = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
        let r = q[0].hypot(q[1]);
        let f = if r > radius {
            radius / if r > 0.0 { r } else { 1.0 }
        } else {
            1.0
        };
        [q[0] * f + centre[0], q[1] * f + centre[1], 0.0 + centre[2]]
    })
}

/// The square plane patch `[−s, s]² × {0}` about `centre`: drop z and clip x and y to `[−s, s]`.
pub fn plane_patch_closest_points(points: &[f64], centre: V3, half_size: f64, out: &mut [f64]) -> Result<()> {
    check_centre_and_size(centre, half_size, "half_size")?;
    // NumPy's clip: the larger of x and −s, then the smaller of that and s, NaN passing through
    let clip = |v: f64| {
        let lo = if v.is_nan() || v > -half_size { v } else { -half_size };
        if lo.is_nan() || lo < half_size {
            lo
        } else {
            half_size
        }
    };
    map_points(points, out, |x| {
        let q = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
        [clip(q[0]) + centre[0], clip(q[1]) + centre[1], 0.0 + centre[2]]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(f: fn(&[f64], V3, f64, &mut [f64]) -> Result<()>, x: V3, c: V3, s: f64) -> V3 {
        let mut out = [0.0; 3];
        f(&x, c, s, &mut out).unwrap();
        out
    }

    #[test]
    fn closest_points_lie_on_the_surfaces_and_are_nearest() {
        let c = [0.1, -0.2, 0.3];
        // above the equator: radial; below: the rim; at the centre: the pole
        let p = one(hemisphere_closest_points, [0.1, -0.2, 1.3], c, 0.5);
        assert!((p[0] - 0.1).abs() < 1e-15 && (p[1] + 0.2).abs() < 1e-15 && (p[2] - 0.8).abs() < 1e-15);
        let p = one(hemisphere_closest_points, [1.1, -0.2, -0.7], c, 0.5);
        assert!((p[0] - 0.6).abs() < 1e-15 && (p[1] + 0.2).abs() < 1e-15 && (p[2] - 0.3).abs() < 1e-15);
        assert_eq!(one(hemisphere_closest_points, c, c, 0.5), [0.1, -0.2, 0.8]);
        // the disc: inside, drop z; outside, clip the radius
        assert_eq!(one(disc_closest_points, [0.2, -0.1, 2.0], c, 0.6), [0.2, -0.1, 0.3]);
        let p = one(disc_closest_points, [1.1, -0.2, 0.0], c, 0.6);
        assert!((p[0] - 0.7).abs() < 1e-15 && (p[1] + 0.2).abs() < 1e-15 && p[2] == 0.3);
        // the plane patch: clip x and y
        let p = one(plane_patch_closest_points, [2.0, -2.0, 5.0], c, 0.6);
        assert!((p[0] - 0.7).abs() < 1e-15 && (p[1] + 0.8).abs() < 1e-15 && p[2] == 0.3);
        // NaN passes through the clip as in NumPy
        assert!(one(plane_patch_closest_points, [f64::NAN, 0.0, 0.0], c, 0.6)[0].is_nan());
    }

    #[test]
    fn rejects_bad_arguments() {
        let mut out = [0.0; 3];
        assert!(hemisphere_closest_points(&[0.0, 0.0], [0.0; 3], 0.5, &mut out[..2]).is_err());
        assert!(disc_closest_points(&[0.0; 3], [0.0; 3], 0.0, &mut out).is_err());
        assert!(plane_patch_closest_points(&[0.0; 3], [f64::NAN, 0.0, 0.0], 0.5, &mut out).is_err());
        assert!(disc_closest_points(&[0.0; 3], [0.0; 3], 0.5, &mut out[..2]).is_err());
    }
}
