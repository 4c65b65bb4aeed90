//! A level set function φ *sampled on the whole grid* (the user hands in an array of the grid's
//! shape): its band `|φ| ≤ half-width` and its extension directions `sgn(φ) ∇φ/|∇φ|` (paper
//! Eq. (8), central differences as in Sect. 4), read straight from the samples.
//!
//! The array is read once to find the band, on all threads, with no temporary of the grid's size
//! (the NumPy route, `np.flatnonzero(np.abs(phi) <= w)`, made two: |φ| and a mask); the
//! directions then read φ at the band nodes' neighbours from the array itself, so nothing has to
//! be looked up in the band. Along an axis where a node's neighbour lies outside the grid the
//! difference is one-sided, `(φ(x) − φ(x − Δx e_k)) / Δx` (and likewise on the other side): the
//! arithmetic of the NumPy code this replaced, so the directions are the same bits.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Grid nodes per parallel task when the array is scanned.
const SCAN_CHUNK: usize = 1 << 16;

/// Band nodes per parallel task when the directions are computed.
const NODE_CHUNK: usize = 1 << 13;

fn check_shape(shape: &[usize], samples: &[f64]) -> Result<()> {
    if !(2..=3).contains(&shape.len()) || shape.contains(&0) {
        return Err(Error::invalid(
            "grid",
            format!("only 2D and 3D grids are supported, got shape {shape:?}"),
        ));
    }
    let total = shape.iter().try_fold(1usize, |p, &n| p.checked_mul(n));
    if total != Some(samples.len()) {
        return Err(Error::invalid(
            "phi",
            format!(
                "expected {} samples (the grid {shape:?}), got {}",
                total.unwrap_or(usize::MAX),
                samples.len()
            ),
        ));
    }
    Ok(())
}

/// Differences along an axis need two nodes on it.
fn check_differences(shape: &[usize]) -> Result<()> {
    if shape.contains(&1) {
        return Err(Error::invalid(
            "grid",
            format!("needs at least 2 nodes per axis for differences, got shape {shape:?}"),
        ));
    }
    Ok(())
}

/// The position of the first sample that is NaN or infinite, if any (on all threads).
pub fn first_non_finite(samples: &[f64]) -> Option<usize> {
    samples
        .par_chunks(SCAN_CHUNK)
        .enumerate()
        .find_map_first(|(j, chunk)| chunk.iter().position(|v| !v.is_finite()).map(|i| j * SCAN_CHUNK + i))
}

/// The band of a sampled φ: the sorted C-order linear indices of the nodes with
/// `|φ| ≤ half_width`, and φ there. `samples` holds φ at every node of the grid of `shape`, in C
/// order. NaN samples are never in the band (the caller checks for them first,
/// [`first_non_finite`]).
pub fn band_of_samples(shape: &[usize], samples: &[f64], half_width: f64) -> Result<(Vec<u64>, Vec<f64>)> {
    check_shape(shape, samples)?;
    if half_width.is_nan() || half_width < 0.0 {
        return Err(Error::invalid(
            "half_width",
            format!("must be a non-negative width, got {half_width}"),
        ));
    }
    let parts: Vec<(Vec<u64>, Vec<f64>)> = samples
        .par_chunks(SCAN_CHUNK)
        .enumerate()
        .map(|(j, chunk)| {
            let mut linear = Vec::new();
            let mut values = Vec::new();
            let base = (j * SCAN_CHUNK) as u64;
            for (i, &v) in chunk.iter().enumerate() {
                if v.abs() <= half_width {
                    linear.push(base + i as u64);
                    values.push(v);
                }
            }
            (linear, values)
        })
        .collect();
    Ok(crate::band::discovery::concat_band_parts(parts))
}

/// The outward directions `sgn(φ) g/|g|` (as f32, written to `direction`, one row of `d` per
/// node) and `|g|` (returned) at the band nodes with linear indices `linear` (each inside the
/// grid), where `g_k = (φ(x + Δx e_k) − φ(x − Δx e_k)) / (2Δx)` with φ read from `samples`, one-sided
/// where the neighbour lies outside the grid. `|g|` is summed in axis order; where it is at most
/// 1e-12 the direction is `sgn(φ) g`.
pub fn outward_directions_of_samples(
    shape: &[usize],
    spacing: f64,
    samples: &[f64],
    linear: &[u64],
    direction: &mut [f32],
) -> Result<Vec<f64>> {
    check_shape(shape, samples)?;
    check_differences(shape)?;
    let d = shape.len();
    if direction.len() != linear.len() * d {
        return Err(Error::invalid(
            "direction",
            format!("expected shape ({}, {d})", linear.len()),
        ));
    }
    if let Some(&l) = linear.iter().find(|&&l| l >= samples.len() as u64) {
        return Err(Error::invalid(
            "linear",
            format!("node {l} lies outside the grid of {} nodes", samples.len()),
        ));
    }
    let stride = strides(shape);
    let mut norms = vec![0.0f64; linear.len()];
    direction
        .par_chunks_mut(NODE_CHUNK * d)
        .zip(norms.par_chunks_mut(NODE_CHUNK))
        .zip(linear.par_chunks(NODE_CHUNK))
        .for_each(|((dir, norms), lin)| {
            for (o, &l) in lin.iter().enumerate() {
                let l = l as usize;
                let own = samples[l];
                let (g, sq) = gradient_at(shape, &stride, spacing, samples, l);
                let norm = sq.sqrt();
                norms[o] = norm;
                let scale = if norm > 1e-12 { norm } else { 1.0 };
                let sgn = if own > 0.0 {
                    1.0
                } else if own < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                for k in 0..d {
                    dir[o * d + k] = (sgn * (g[k] / scale)) as f32;
                }
            }
        });
    Ok(norms)
}

/// Strides of the axes of a C-order grid of `shape` (2 or 3 axes; the unused one 1).
fn strides(shape: &[usize]) -> [usize; 3] {
    let mut stride = [1usize; 3];
    for k in (0..shape.len() - 1).rev() {
        stride[k] = stride[k + 1] * shape[k + 1];
    }
    stride
}

/// `g_k = (φ(x + Δx e_k) − φ(x − Δx e_k)) / (2Δx)` at node `l` (one-sided where the neighbour
/// lies outside the grid: the differences of `numpy.gradient`) and `|g|²` summed in axis order.
#[inline]
fn gradient_at(shape: &[usize], stride: &[usize; 3], spacing: f64, samples: &[f64], l: usize) -> ([f64; 3], f64) {
    let own = samples[l];
    let mut g = [0.0f64; 3];
    let mut sq = 0.0f64;
    for k in 0..shape.len() {
        let c = (l / stride[k]) % shape[k];
        let (up_in, down_in) = (c + 1 < shape[k], c > 0);
        let up = if up_in { samples[l + stride[k]] } else { own };
        let down = if down_in { samples[l - stride[k]] } else { own };
        // (1 + 1)·Δx = 2Δx exactly; one-sided: Δx
        let width = (up_in as u8 + down_in as u8) as f64 * spacing;
        g[k] = (up - down) / width;
        if k == 0 {
            sq = g[0] * g[0];
        } else {
            sq += g[k] * g[k];
        }
    }
    (g, sq)
}

/// The largest `|∇φ|` over every node of the grid, by the differences of
/// [`outward_directions_of_samples`] (those of `numpy.gradient`): a bound on |∇φ| for the band
/// search of a φ that is not a distance function. One pass, on all threads, nothing stored.
pub fn max_gradient_norm_of_samples(shape: &[usize], spacing: f64, samples: &[f64]) -> Result<f64> {
    check_shape(shape, samples)?;
    check_differences(shape)?;
    let stride = strides(shape);
    let largest = (0..samples.len())
        .into_par_iter()
        .with_min_len(SCAN_CHUNK)
        .map(|l| gradient_at(shape, &stride, spacing, samples, l).1)
        .reduce(|| 0.0, f64::max);
    Ok(largest.sqrt())
}

/// Nodes per axis of the blocks over which [`redistance_candidates_of_samples`] bounds |∇φ|.
const GRADIENT_BLOCK: usize = 8;

/// The candidates for the band of a sampled φ that is *not* a distance function (the re-distanced
/// band, `LevelSet(phi, redistance=True)`): the sorted C-order linear indices of the nodes `x`
/// with `|φ(x)| ≤ half_width · G(x)`, and φ there, where `G(x)` bounds the gradient of φ's
/// multilinear interpolant on every cell within `half_width` of `x`.
///
/// A node within distance `half_width` of the interpolant's zero set reaches it along a segment
/// of that length, on which `|φ|` changes by at most `half_width · max |∇φ|`; so every such node
/// is a candidate. On a cell the interpolant's derivative along axis `k` is a convex combination
/// of the differences `(φ(y + Δx e_k) − φ(y)) / Δx` along the cell's edges in that direction, so
/// `|∇φ| ≤ (Σ_k m_k²)^{1/2} / Δx` on the cell, with `m_k` the largest such difference
/// ([`cell_gradient_bound_sq`]): `G` is the largest of these over the cells of blocks of
/// [`GRADIENT_BLOCK`]^d nodes, the node's own block and the blocks next to it as far as
/// `half_width` plus a cell's diagonal reaches. A single bound over the whole box, as for a
/// callable φ, takes φ's steepest part anywhere (for `|x|² − r²`, the box's corners) and makes
/// several times as many candidates, each of which the projection onto the zero level set then
/// has to iterate. Two passes over the samples on all threads; the per-block bounds are the
/// only storage (one value per block).
pub fn redistance_candidates_of_samples(
    shape: &[usize],
    spacing: f64,
    samples: &[f64],
    half_width: f64,
) -> Result<(Vec<u64>, Vec<f64>)> {
    check_shape(shape, samples)?;
    check_differences(shape)?;
    if half_width.is_nan() || half_width < 0.0 {
        return Err(Error::invalid(
            "half_width",
            format!("must be a non-negative width, got {half_width}"),
        ));
    }
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(Error::invalid(
            "spacing",
            format!("must be positive and finite, got {spacing}"),
        ));
    }
    // a 2D grid as one slab of a 3D one: (1, n0, n1)
    let dims: [usize; 3] = if shape.len() == 2 {
        [1, shape[0], shape[1]]
    } else {
        [shape[0], shape[1], shape[2]]
    };
    let blocks: [usize; 3] = std::array::from_fn(|k| dims[k].div_ceil(GRADIENT_BLOCK));
    let block_of = |i: usize, j: usize, k: usize| {
        ((i / GRADIENT_BLOCK) * blocks[1] + j / GRADIENT_BLOCK) * blocks[2] + k / GRADIENT_BLOCK
    };
    // per block, the largest |Σ_a m_a²| over the cells whose lowest corner is one of its nodes,
    // m_a the largest |Δφ| along the cell's edges in direction a (a 2D grid's cells span no
    // first axis)
    let plane = dims[1] * dims[2];
    let flat = dims[0] == 1;
    let per_slab: Vec<Vec<f64>> = (0..blocks[0])
        .into_par_iter()
        .map(|bi| {
            let mut m = vec![0.0f64; blocks[1] * blocks[2]];
            let last_i = if flat { 1 } else { dims[0] - 1 };
            for i in bi * GRADIENT_BLOCK..((bi + 1) * GRADIENT_BLOCK).min(last_i) {
                for j in 0..dims[1] - 1 {
                    let row = i * plane + j * dims[2];
                    for k in 0..dims[2] - 1 {
                        let sq = cell_gradient_bound_sq(samples, row + k, plane, dims[2], flat);
                        let b = &mut m[(j / GRADIENT_BLOCK) * blocks[2] + k / GRADIENT_BLOCK];
                        if sq > *b {
                            *b = sq;
                        }
                    }
                }
            }
            m
        })
        .collect();
    let cells: Vec<f64> = per_slab.into_iter().flatten().collect();
    // the blocks within reach of a node: `half_width` and a cell's diagonal from anywhere in its
    // own block
    let reach = ((half_width / spacing + (shape.len() as f64).sqrt()) / GRADIENT_BLOCK as f64)
        .ceil()
        .max(1.0) as usize;
    let bound: Vec<f64> = (0..cells.len())
        .into_par_iter()
        .map(|b| {
            let (bi, bj, bk) = (b / (blocks[1] * blocks[2]), (b / blocks[2]) % blocks[1], b % blocks[2]);
            let mut m = 0.0f64;
            for ni in bi.saturating_sub(reach)..=(bi + reach).min(blocks[0] - 1) {
                for nj in bj.saturating_sub(reach)..=(bj + reach).min(blocks[1] - 1) {
                    for nk in bk.saturating_sub(reach)..=(bk + reach).min(blocks[2] - 1) {
                        m = m.max(cells[(ni * blocks[1] + nj) * blocks[2] + nk]);
                    }
                }
            }
            // |∇φ| ≤ sqrt(m) / Δx; the threshold with a hair of slack for the rounding
            half_width * m.sqrt() / spacing * (1.0 + 1e-9)
        })
        .collect();
    // whole rows (along the last axis) per task, about SCAN_CHUNK nodes
    let (n_rows, rows_per_task) = (dims[0] * dims[1], (SCAN_CHUNK / dims[2]).max(1));
    let parts: Vec<(Vec<u64>, Vec<f64>)> = (0..n_rows.div_ceil(rows_per_task))
        .into_par_iter()
        .map(|task| {
            let (mut linear, mut values) = (Vec::new(), Vec::new());
            for ij in task * rows_per_task..((task + 1) * rows_per_task).min(n_rows) {
                let (i, j) = (ij / dims[1], ij % dims[1]);
                let row = ij * dims[2];
                for k in 0..dims[2] {
                    let v = samples[row + k];
                    if v.abs() <= bound[block_of(i, j, k)] {
                        linear.push((row + k) as u64);
                        values.push(v);
                    }
                }
            }
            (linear, values)
        })
        .collect();
    Ok(crate::band::discovery::concat_band_parts(parts))
}

/// `Σ_a m_a²` for the cell whose lowest corner is node `l`, `m_a` the largest `|Δφ|` along its
/// edges in direction `a` (the first axis left out on a 2D grid, `flat`): the interpolant's
/// gradient on the cell is at most `sqrt` of it over Δx, since its derivative along `a` is a
/// convex combination of those edges' differences over Δx. `plane` and `row` are the strides of
/// the first two axes.
#[inline]
fn cell_gradient_bound_sq(samples: &[f64], l: usize, plane: usize, row: usize, flat: bool) -> f64 {
    let edges_2d = |base: usize| -> (f64, f64, [f64; 4]) {
        let c = [
            samples[base],
            samples[base + 1],
            samples[base + row],
            samples[base + row + 1],
        ];
        let along_k = (c[1] - c[0]).abs().max((c[3] - c[2]).abs());
        let along_j = (c[2] - c[0]).abs().max((c[3] - c[1]).abs());
        (along_j, along_k, c)
    };
    let (mj, mk, low) = edges_2d(l);
    if flat {
        return mj * mj + mk * mk;
    }
    let (nj, nk, high) = edges_2d(l + plane);
    let mi = (0..4).fold(0.0f64, |m, q| m.max((high[q] - low[q]).abs()));
    let (mj, mk) = (mj.max(nj), mk.max(nk));
    mi * mi + mj * mj + mk * mk
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere_samples(n: usize, r: f64) -> Vec<f64> {
        let c = (n - 1) as f64 / 2.0;
        (0..n * n * n)
            .map(|l| {
                let (i, j, k) = ((l / (n * n)) as f64, ((l / n) % n) as f64, (l % n) as f64);
                ((i - c).powi(2) + (j - c).powi(2) + (k - c).powi(2)).sqrt() - r
            })
            .collect()
    }

    #[test]
    fn the_band_is_every_node_within_the_width_in_order() {
        let n = 41;
        let s = sphere_samples(n, 12.0);
        let (linear, values) = band_of_samples(&[n, n, n], &s, 2.5).unwrap();
        let expected: Vec<u64> = (0..s.len() as u64).filter(|&l| s[l as usize].abs() <= 2.5).collect();
        assert_eq!(linear, expected);
        assert!(linear.iter().zip(&values).all(|(&l, &v)| v == s[l as usize]));
        assert!(band_of_samples(&[n, n], &s, 2.5).is_err());
        assert!(band_of_samples(&[n, n, n], &s, f64::NAN).is_err());
    }

    #[test]
    fn the_largest_gradient_is_that_of_the_steepest_node() {
        // φ = 3·x₀² on a 5×4 grid (Δx = 1): |∇φ| = 6·x₀ inside, one-sided 3·(16 − 9) = 21 at
        // the last row, the largest
        let s: Vec<f64> = (0..20).map(|l| 3.0 * ((l / 4) as f64).powi(2)).collect();
        assert_eq!(max_gradient_norm_of_samples(&[5, 4], 1.0, &s).unwrap(), 21.0);
        assert!(max_gradient_norm_of_samples(&[20, 1], 1.0, &s).is_err());
    }

    #[test]
    fn non_finite_samples_are_found_first_to_last() {
        let mut s = vec![0.5; 300_000];
        assert_eq!(first_non_finite(&s), None);
        s[250_000] = f64::INFINITY;
        s[70_001] = f64::NAN;
        assert_eq!(first_non_finite(&s), Some(70_001));
    }

    #[test]
    fn directions_point_away_from_the_surface_and_are_one_sided_at_the_box() {
        // φ = x − 2.5 along axis 0 of a 6×4 grid (Δx = 0.5: φ = 0.5 i − 1.25), every node
        let shape = [6usize, 4];
        let s: Vec<f64> = (0..24).map(|l| 0.5 * (l / 4) as f64 - 1.25).collect();
        let linear: Vec<u64> = (0..24).collect();
        let mut dir = vec![0.0f32; 48];
        let norms = outward_directions_of_samples(&shape, 0.5, &s, &linear, &mut dir).unwrap();
        for l in 0..24 {
            // one-sided on the first and last row and column: still exactly 1 and 0
            assert_eq!(norms[l], 1.0, "node {l}");
            assert_eq!(dir[2 * l], if s[l] > 0.0 { 1.0 } else { -1.0 });
            assert_eq!(dir[2 * l + 1], 0.0);
        }
        // a sphere: the direction is the unit radial vector to within O(Δx²)
        let n = 31;
        let s = sphere_samples(n, 10.7);
        let (linear, _) = band_of_samples(&[n, n, n], &s, 2.0).unwrap();
        let mut dir = vec![0.0f32; 3 * linear.len()];
        let norms = outward_directions_of_samples(&[n, n, n], 1.0, &s, &linear, &mut dir).unwrap();
        let c = (n - 1) as f64 / 2.0;
        for (o, &l) in linear.iter().enumerate() {
            let l = l as usize;
            let x = [(l / (n * n)) as f64 - c, ((l / n) % n) as f64 - c, (l % n) as f64 - c];
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            let sgn = s[l].signum();
            for k in 0..3 {
                let e = (dir[3 * o + k] as f64 - sgn * x[k] / r).abs();
                assert!(e < 0.01, "node {l}: {e}");
            }
            assert!((norms[o] - 1.0).abs() < 0.01);
        }
        assert!(outward_directions_of_samples(&[n, n, n], 1.0, &s, &[(n * n * n) as u64], &mut [0.0; 3]).is_err());
        assert!(outward_directions_of_samples(&[n, n, n], 1.0, &s, &linear, &mut dir[1..]).is_err());
        assert!(outward_directions_of_samples(&[n * n * n, 1], 1.0, &s, &linear[..1], &mut dir[..2]).is_err());
    }

    #[test]
    fn redistance_candidates_hold_every_node_near_the_surface_and_few_others() {
        // φ = |x − c|² − r² (x in nodes, Δx = 0.25): |∇φ| is 2r/Δx at the surface but up to
        // 2√3·c/Δx in the box's corners, where the whole-box bound comes from
        let (n, r, spacing) = (97usize, 20.3f64, 0.25f64);
        let c = (n - 1) as f64 / 2.0;
        let s: Vec<f64> = sphere_samples(n, 0.0).iter().map(|&d| d * d - r * r).collect();
        let half_width = 4.0 * spacing;
        let (linear, values) = redistance_candidates_of_samples(&[n, n, n], spacing, &s, half_width).unwrap();
        assert!(linear.windows(2).all(|w| w[0] < w[1]));
        assert!(linear.iter().zip(&values).all(|(&l, &v)| v == s[l as usize]));
        // every node within the width of the sphere (the interpolant's zero set lies within
        // O(Δx²) of it, far less than the margin of 0.1) is a candidate
        let radius = |l: usize| {
            let x = [(l / (n * n)) as f64 - c, ((l / n) % n) as f64 - c, (l % n) as f64 - c];
            (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
        };
        let near: Vec<u64> = (0..s.len())
            .filter(|&l| ((radius(l) - r) * spacing).abs() <= half_width - 0.1)
            .map(|l| l as u64)
            .collect();
        assert!(
            near.iter().all(|l| linear.binary_search(l).is_ok()),
            "a node near the surface is missing"
        );
        // the whole-box bound (1.25 × the steepest node) takes several times the candidates
        let global = 1.25 * max_gradient_norm_of_samples(&[n, n, n], spacing, &s).unwrap();
        let (everywhere, _) = band_of_samples(&[n, n, n], &s, global * half_width).unwrap();
        assert!(
            linear.len() * 2 < everywhere.len(),
            "{} candidates against {}",
            linear.len(),
            everywhere.len()
        );
        assert!(
            linear.len() * 2 < near.len() * 5,
            "{} candidates for {} nodes near the surface",
            linear.len(),
            near.len()
        );
        // a 2D grid: a circle, the same rule
        let m = 61;
        let cm = (m - 1) as f64 / 2.0;
        let s2: Vec<f64> = (0..m * m)
            .map(|l| {
                let (i, j) = ((l / m) as f64 - cm, (l % m) as f64 - cm);
                i * i + j * j - 20.0 * 20.0
            })
            .collect();
        let (linear2, _) = redistance_candidates_of_samples(&[m, m], 1.0, &s2, 3.0).unwrap();
        let near2 = (0..m * m).filter(|&l| {
            let (i, j) = ((l / m) as f64 - cm, (l % m) as f64 - cm);
            ((i * i + j * j).sqrt() - 20.0).abs() <= 2.9
        });
        assert!(near2.into_iter().all(|l| linear2.binary_search(&(l as u64)).is_ok()));
        // bad arguments
        assert!(redistance_candidates_of_samples(&[n, n, n], spacing, &s, f64::NAN).is_err());
        assert!(redistance_candidates_of_samples(&[n, n, n], 0.0, &s, half_width).is_err());
        assert!(redistance_candidates_of_samples(&[n, n], spacing, &s, half_width).is_err());
        assert!(redistance_candidates_of_samples(&[n * n * n, 1], spacing, &s, half_width).is_err());
    }
}
