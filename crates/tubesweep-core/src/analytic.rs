//! Exact signed distances of the library's analytic surfaces, evaluated on all threads: the
//! Python package's `Circle`, `Sphere` and `Torus` call these instead of NumPy expressions, with
//! the same arithmetic (so the same bits), because the band search evaluates φ at every
//! candidate node and the outward directions at every rim place.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Points per parallel task.
const CHUNK: usize = 1 << 13;

fn check_points(points: &[f64], d: usize, out: &[f64]) -> Result<()> {
    if d == 0 || points.len() % d != 0 {
        return Err(Error::invalid(
            "points",
            format!("expected an (M, {d}) array"),
        ));
    }
    if out.len() != points.len() / d {
        return Err(Error::invalid(
            "out",
            format!(
                "expected {} values (one per point), got {}",
                points.len() / d,
                out.len()
            ),
        ));
    }
    Ok(())
}

/// `φ(x) = |x − c| − r`, the signed distance to the circle (d = 2) or sphere (d = 3) of radius
/// `r` about `c`, at the points (`M` rows of `d = centre.len()` coordinates) into `out`. `|x − c|`
/// is `sqrt(Σ_k (x_k − c_k)²)` summed in axis order.
pub fn sphere_signed_distance(
    points: &[f64],
    centre: &[f64],
    radius: f64,
    out: &mut [f64],
) -> Result<()> {
    let d = centre.len();
    check_points(points, d, out)?;
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * d))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(d)) {
                let mut sq = (x[0] - centre[0]) * (x[0] - centre[0]);
                for k in 1..d {
                    sq += (x[k] - centre[k]) * (x[k] - centre[k]);
                }
                *o = sq.sqrt() - radius;
            }
        });
    Ok(())
}

/// `φ(x) = hypot(hypot(q_x, q_y) − R, q_z) − r` with `q = x − c`: the signed distance to the
/// torus about the z axis through `c` with centre-circle radius `R` and tube radius `r`, at the
/// points (`M` rows of 3 coordinates) into `out`.
pub fn torus_signed_distance(
    points: &[f64],
    centre: [f64; 3],
    major: f64,
    minor: f64,
    out: &mut [f64],
) -> Result<()> {
    check_points(points, 3, out)?;
    out.par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK * 3))
        .for_each(|(out, p)| {
            for (o, x) in out.iter_mut().zip(p.chunks_exact(3)) {
                let q = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
                *o = (q[0].hypot(q[1]) - major).hypot(q[2]) - minor;
            }
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_and_circle_distances() {
        let p = [0.0, 0.0, 0.0, 3.0, 4.0, 0.0, 1.0, 2.0, 2.0];
        let mut out = [0.0; 3];
        sphere_signed_distance(&p, &[0.0, 0.0, 0.0], 2.0, &mut out).unwrap();
        assert_eq!(out, [-2.0, 3.0, 1.0]);
        let mut out2 = [0.0; 2];
        sphere_signed_distance(&[4.0, 5.0, 1.0, 1.0], &[1.0, 1.0], 1.0, &mut out2).unwrap();
        assert_eq!(out2, [4.0, -1.0]);
        assert!(sphere_signed_distance(&p[..8], &[0.0; 3], 1.0, &mut out).is_err());
        assert!(sphere_signed_distance(&p, &[0.0; 3], 1.0, &mut out2).is_err());
    }

    #[test]
    fn torus_distances() {
        // on the outer equator, the inner equator, the top circle and the centre
        let p = [0.7, 0.0, 0.0, 0.0, -0.3, 0.0, 0.5, 0.0, 0.2, 0.0, 0.0, 0.0];
        let mut out = [0.0; 4];
        torus_signed_distance(&p, [0.0; 3], 0.5, 0.2, &mut out).unwrap();
        for (v, e) in out.iter().zip([0.0, 0.0, 0.0, 0.3]) {
            assert!((v - e).abs() < 1e-15, "{v} vs {e}");
        }
    }
}
