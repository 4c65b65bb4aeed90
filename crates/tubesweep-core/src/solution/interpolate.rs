//! Multilinear interpolation of band values at arbitrary points. A point whose interpolation
//! stencil (the 2^d corners of its cell) leaves the band gets NaN; one whose cell mixes reached
//! corners and unreached ones (+∞) reads the reached ones, renormalised, where they carry at least
//! [`REACHED_SHARE`] of the weight, and +∞ otherwise.

use crate::band::NarrowBand;
use rayon::prelude::*;

/// A point whose cell has unreached corners (+∞) reads the reached ones where they carry at least
/// this share of its multilinear weight: it lies on their side. Where two parts of a surface come
/// within a cell of each other, a node between them can take its closest point, and so its value,
/// from the unreached part (a shell three spacings thick, re-distanced, the source on its outer
/// sphere: 36 of 20,000 points on the outer sphere read +∞ through such a corner weighing 0.001;
/// a helper's review). The readout beside a cut band's gaps renormalises so too
/// (`_sheet_readout.OwnSidePlan` in the Python package).
pub const REACHED_SHARE: f64 = 0.5;

/// Interpolates `values` (one per band node) at `points` (flattened, `D` coordinates each) on the
/// grid with lower corner `lower` and spacing `h`. Returns NaN where a corner is missing from the
/// band or the point lies outside the grid; where corners are unreached (+∞), the reached ones
/// renormalised if they carry [`REACHED_SHARE`] of the weight, else +∞.
pub fn interpolate<const D: usize>(
    band: &NarrowBand<D>,
    values: &[f64],
    lower: [f64; D],
    h: f64,
    points: &[f64],
) -> Vec<f64> {
    let shape = band.shape();
    points
        .par_chunks(D)
        .map(|p| {
            let mut base = [0i64; D];
            let mut frac = [0.0f64; D];
            for k in 0..D {
                let mut t = (p[k] - lower[k]) / h;
                let tol = 1e-9;
                if !(t >= -tol && t <= (shape[k] - 1) as f64 + tol) {
                    return f64::NAN;
                }
                // a point on a grid plane to rounding (a node's own coordinates, lower + i·h,
                // read back) takes no weight from the next plane: an unreached node there gave
                // a reached node's own point inf through a weight of 1e-16
                if (t - t.round()).abs() <= tol {
                    t = t.round();
                }
                let i = (t.floor() as i64).clamp(0, shape[k] as i64 - 2);
                base[k] = i;
                frac[k] = (t - i as f64).clamp(0.0, 1.0);
            }
            let mut acc = 0.0;
            let mut reached = 0.0;
            let mut unreached = false;
            for corner in 0..(1usize << D) {
                let mut idx = base;
                let mut w = 1.0;
                for k in 0..D {
                    if corner >> k & 1 == 1 {
                        idx[k] += 1;
                        w *= frac[k];
                    } else {
                        w *= 1.0 - frac[k];
                    }
                }
                match band.find(idx) {
                    Some(n) => {
                        if w != 0.0 {
                            if values[n].is_finite() {
                                acc += w * values[n];
                                reached += w;
                            } else {
                                unreached = true;
                            }
                        }
                    }
                    None => {
                        if w != 0.0 {
                            return f64::NAN;
                        }
                    }
                }
            }
            if !unreached {
                acc
            } else if reached >= REACHED_SHARE {
                acc / reached
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_linear_functions_and_flags_missing_corners() {
        let band = NarrowBand::<2>::full_box([5, 5]).unwrap();
        let h = 0.25;
        let vals: Vec<f64> = band
            .indices()
            .iter()
            .map(|i| 2.0 * i[0] as f64 * h - i[1] as f64 * h)
            .collect();
        let pts = [0.3, 0.6, 1.0, 1.0, 2.0, 0.0];
        let out = interpolate(&band, &vals, [0.0, 0.0], h, &pts);
        assert!((out[0] - (0.6 - 0.6)).abs() < 1e-12);
        assert!((out[1] - 1.0).abs() < 1e-12);
        assert!(out[2].is_nan());
        let sparse = NarrowBand::<2>::from_sorted_linear([5, 5], &[0, 1, 5]).unwrap();
        let out = interpolate(&sparse, &[0.0, 1.0, 2.0], [0.0, 0.0], 1.0, &[0.0, 0.5, 0.5, 0.5]);
        assert!((out[0] - 0.5).abs() < 1e-12);
        assert!(out[1].is_nan());
    }

    #[test]
    fn a_node_read_back_at_its_own_coordinates_takes_no_weight_from_its_neighbours() {
        // lower + i·h read back is i to rounding, not i: a weight of 1e-16 on an unreached
        // neighbour made a reached node's own point inf
        let band = NarrowBand::<2>::full_box([4, 4]).unwrap();
        let (lower, h) = ([-1.0, -1.0], 0.04); // (-1 + 0.04 + 1) / 0.04 = 1.0000000000000009
        let mut vals = vec![1.0; band.len()];
        let far = band.find([2, 1]).unwrap();
        vals[far] = f64::INFINITY;
        let node = [lower[0] + h * 1.0, lower[1] + h * 1.0];
        assert_eq!(interpolate(&band, &vals, lower, h, &node), vec![1.0]);
        // a point off the plane by more than the rounding reads its reached corners
        assert_eq!(
            interpolate(&band, &vals, lower, h, &[node[0] + 1e-6, node[1]]),
            vec![1.0]
        );
    }

    #[test]
    fn a_cell_with_unreached_corners_reads_the_reached_ones_where_they_weigh_half() {
        let band = NarrowBand::<2>::full_box([3, 3]).unwrap();
        let mut vals: Vec<f64> = band.indices().iter().map(|i| i[0] as f64 + 2.0 * i[1] as f64).collect();
        vals[band.find([1, 1]).unwrap()] = f64::INFINITY;
        // the cell [0, 1]²: its corner (1, 1) unreached; at (0.2, 0.3) it weighs 0.06
        let p = [0.2, 0.3];
        let (w00, w10, w01) = (0.8 * 0.7, 0.2 * 0.7, 0.8 * 0.3);
        let own = (w00 * 0.0 + w10 * 1.0 + w01 * 2.0) / (w00 + w10 + w01);
        assert!((interpolate(&band, &vals, [0.0, 0.0], 1.0, &p)[0] - own).abs() < 1e-15);
        // ... at (0.8, 0.7), 0.56: the point lies on the unreached side
        assert_eq!(
            interpolate(&band, &vals, [0.0, 0.0], 1.0, &[0.8, 0.7])[0],
            f64::INFINITY
        );
        // a missing corner still gives NaN
        let sparse = NarrowBand::<2>::from_sorted_linear([3, 3], &[0, 1, 3]).unwrap();
        assert!(interpolate(&sparse, &[0.0, f64::INFINITY, 1.0], [0.0, 0.0], 1.0, &[0.5, 0.5])[0].is_nan());
    }
}
