//! Cubic interpolation of band values: the tensor product of Catmull–Rom (Keys' cubic
//! convolution, `a = −1/2`) weights over the `4^d` nodes around a point's cell. It reproduces
//! quadratics, so its error is O(Δx³) where the values are smooth (multilinear: O(Δx²)), and it is
//! C¹. Where the `4^d` stencil leaves the band or the grid, or meets an unreached value, the point
//! gets the multilinear value ([`crate::solution::interpolate::interpolate`]) instead, NaN where that
//! leaves the band too.

use crate::band::NarrowBand;
use crate::solution::interpolate::interpolate;
use rayon::prelude::*;

/// Catmull–Rom weights of the nodes at offsets −1, 0, 1, 2 for a point at fraction `f ∈ [0, 1]`
/// of its cell.
#[inline(always)]
pub fn catmull_rom_weights(f: f64) -> [f64; 4] {
    let f2 = f * f;
    let f3 = f2 * f;
    [
        0.5 * (-f3 + 2.0 * f2 - f),
        0.5 * (3.0 * f3 - 5.0 * f2 + 2.0),
        0.5 * (-3.0 * f3 + 4.0 * f2 + f),
        0.5 * (f3 - f2),
    ]
}

/// The cubic value at one point, or `None` when its `4^d` stencil is incomplete.
fn cubic_at<const D: usize>(band: &NarrowBand<D>, values: &[f64], lower: [f64; D], h: f64, p: &[f64]) -> Option<f64> {
    let shape = band.shape();
    let mut base = [0i64; D];
    let mut weights = [[0.0f64; 4]; D];
    for k in 0..D {
        let t = (p[k] - lower[k]) / h;
        if !(t >= 0.0 && t <= (shape[k] - 1) as f64) {
            return None;
        }
        let i = (t.floor() as i64).clamp(0, shape[k] as i64 - 2);
        if i < 1 || i + 2 > shape[k] as i64 - 1 {
            return None;
        }
        base[k] = i - 1;
        weights[k] = catmull_rom_weights((t - i as f64).clamp(0.0, 1.0));
    }
    let mut acc = 0.0;
    for corner in 0..(1usize << (2 * D)) {
        let mut idx = base;
        let mut w = 1.0;
        for k in 0..D {
            let o = (corner >> (2 * k)) & 3;
            idx[k] += o as i64;
            w *= weights[k][o];
        }
        let v = values[band.find(idx)?];
        if !v.is_finite() {
            return None;
        }
        acc += w * v;
    }
    Some(acc)
}

/// Interpolates `values` (one per band node) at `points` (flattened, `D` coordinates each) by
/// Catmull–Rom cubics where the `4^d` stencil is in the band and reached, multilinearly
/// elsewhere. Returns the values and whether each point got the cubic.
pub fn interpolate_cubic<const D: usize>(
    band: &NarrowBand<D>,
    values: &[f64],
    lower: [f64; D],
    h: f64,
    points: &[f64],
) -> (Vec<f64>, Vec<bool>) {
    let cubic: Vec<Option<f64>> = points
        .par_chunks(D)
        .map(|p| cubic_at(band, values, lower, h, p))
        .collect();
    let fallback: Vec<usize> = (0..cubic.len()).filter(|&i| cubic[i].is_none()).collect();
    let mut linear_points = Vec::with_capacity(fallback.len() * D);
    for &i in &fallback {
        linear_points.extend_from_slice(&points[i * D..(i + 1) * D]);
    }
    let linear = interpolate(band, values, lower, h, &linear_points);
    let mut out: Vec<f64> = cubic.iter().map(|c| c.unwrap_or(f64::NAN)).collect();
    let used: Vec<bool> = cubic.iter().map(|c| c.is_some()).collect();
    for (j, &i) in fallback.iter().enumerate() {
        out[i] = linear[j];
    }
    (out, used)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_interpolate_nodes() {
        for f in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let w = catmull_rom_weights(f);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        assert_eq!(catmull_rom_weights(0.0), [0.0, 1.0, 0.0, 0.0]);
        assert_eq!(catmull_rom_weights(1.0), [0.0, 0.0, 1.0, 0.0]);
    }

    #[test]
    fn reproduces_quadratics_and_falls_back_to_linear() {
        let band = NarrowBand::<3>::full_box([7, 7, 7]).unwrap();
        let h = 0.5;
        let q = |x: [f64; 3]| 1.0 + x[0] - 2.0 * x[1] * x[2] + 0.7 * x[0] * x[0] - x[2] * x[2];
        let vals: Vec<f64> = band
            .indices()
            .iter()
            .map(|i| q(std::array::from_fn(|k| i[k] as f64 * h)))
            .collect();
        let pts = [1.3, 1.1, 0.77, 0.6, 1.9, 1.4, 0.1, 1.0, 1.0];
        let (out, used) = interpolate_cubic(&band, &vals, [0.0; 3], h, &pts);
        for m in 0..2 {
            let p = [pts[3 * m], pts[3 * m + 1], pts[3 * m + 2]];
            assert!(used[m]);
            assert!((out[m] - q(p)).abs() < 1e-12, "{} vs {}", out[m], q(p));
        }
        // the first cell of axis 0: no node at offset −1, multilinear instead
        assert!(!used[2]);
        let lin = interpolate(&band, &vals, [0.0; 3], h, &pts[6..9]);
        assert_eq!(out[2].to_bits(), lin[0].to_bits());
        // a stencil node missing from the band: multilinear; a cell corner missing: NaN
        let sparse: Vec<u64> = (0..7u64 * 7 * 7).filter(|&m| m != 7 * 7 * 3 + 7 * 3 + 2).collect();
        let band2 = NarrowBand::<3>::from_sorted_linear([7, 7, 7], &sparse).unwrap();
        let vals2: Vec<f64> = band2
            .indices()
            .iter()
            .map(|i| q(std::array::from_fn(|k| i[k] as f64 * h)))
            .collect();
        let (out2, used2) = interpolate_cubic(&band2, &vals2, [0.0; 3], h, &[0.75, 0.75, 0.75, 1.6, 1.6, 1.1]);
        assert!(!used2[0] && !used2[1]);
        assert!(
            out2[0].is_finite()
                && (out2[0] - interpolate(&band2, &vals2, [0.0; 3], h, &[0.75, 0.75, 0.75])[0]).abs() == 0.0
        );
        assert!(out2[1].is_nan());
    }
}
