//! The outward extension direction `sgn(φ) ∇φ/|∇φ|` of a level set at the band nodes (paper
//! Eq. (8)), with `∇φ` by central differences (Sect. 4), for a φ known at the band nodes.
//!
//! The band nodes are given by their sorted C-order linear indices and φ there. The neighbour
//! `x ± Δx e_k` of a node is looked up in the band (one merge pass per axis and side, see
//! [`crate::band::shifted_positions`]); where it is not a band node (the band's outer rim, or
//! outside the grid) φ there must be supplied by the caller: [`rim_nodes`] lists those places
//! and [`outward_directions`] takes φ at them, in the same order. (φ is a user's function that
//! the Python package evaluates, so the two halves are separate calls.)

use crate::band::shifted_positions;
use rayon::prelude::*;
use crate::error::{Error, Result};

/// Linear-index strides of the axes of a C-order grid of `shape`.
fn strides(shape: &[usize]) -> Vec<u64> {
    let mut s = vec![1u64; shape.len()];
    for k in (0..shape.len().saturating_sub(1)).rev() {
        s[k] = s[k + 1] * shape[k + 1] as u64;
    }
    s
}

/// Grid indices (up to 3 axes; unused axes 0) of the nodes `linear[range]`: one division per
/// node for the last axis, the leading ones recomputed only when the row changes (rows hold
/// several consecutive band nodes).
fn node_coordinates(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Vec<[u32; 3]> {
    let d = shape.len();
    let n_last = shape[d - 1] as u64;
    let mut out = Vec::with_capacity(range.len());
    let mut row = u64::MAX;
    let mut lead = [0u32; 3];
    for &l in &linear[range] {
        let r = l / n_last;
        if r != row {
            row = r;
            let mut key = r;
            for k in (0..d - 1).rev() {
                lead[k] = (key % shape[k] as u64) as u32;
                key /= shape[k] as u64;
            }
        }
        let mut c = lead;
        c[d - 1] = (l - r * n_last) as u32;
        out.push(c);
    }
    out
}

fn check(shape: &[usize], linear: &[u64], range: &std::ops::Range<usize>) -> Result<()> {
    if !(2..=3).contains(&shape.len()) || shape.iter().any(|&n| n == 0 || n > u32::MAX as usize) {
        return Err(Error::invalid("grid", format!("only 2D and 3D grids are supported, got shape {shape:?}")));
    }
    if range.start > range.end || range.end > linear.len() {
        return Err(Error::invalid("range", format!("{range:?} is not a range of the {} band nodes", linear.len())));
    }
    let total: u64 = shape.iter().map(|&n| n as u64).product();
    if linear[range.clone()].windows(2).any(|w| w[0] >= w[1]) || linear[range.clone()].last().is_some_and(|&l| l >= total) {
        return Err(Error::invalid("linear", "band nodes must be strictly increasing linear indices inside the grid"));
    }
    Ok(())
}

/// The neighbour table of band nodes `range` (`m` of them): for every group `(axis k, side)` in
/// the order `k = 0, 1, …`, side `+1` then `−1`, `m` entries, the band position of the neighbour
/// `x ± Δx e_k` of each node, or −1 where that neighbour is not a band node or lies outside the
/// grid (the places where φ must come from the caller). The groups' passes are independent and
/// run in parallel; one table serves both [`rim_nodes_of`] and [`outward_directions_with`].
pub fn neighbour_table(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Result<Vec<i64>> {
    check(shape, linear, &range)?;
    let stride = strides(shape);
    let coords = node_coordinates(shape, linear, range.clone());
    let m = range.len();
    let mut table = vec![-1i64; 2 * shape.len() * m];
    if m == 0 {
        return Ok(table);
    }
    table.par_chunks_mut(m).enumerate().for_each(|(group, out)| {
        let (k, sign) = (group / 2, if group % 2 == 0 { 1i64 } else { -1 });
        let pos = neighbour_positions(linear, stride[k], sign, range.clone());
        for (o, (t, &p)) in out.iter_mut().zip(pos.iter()).enumerate() {
            if neighbour_known(&coords[o], p, k, sign, shape) {
                *t = p;
            }
        }
    });
    Ok(table)
}

/// For every group `(axis k, side)` in the order `k = 0, 1, …`, side `+1` then `−1`: the band
/// positions `i` in `range` whose neighbour `linear[i] ± stride_k` is not a band node (or lies
/// outside the grid along axis `k`), in increasing order. Returns the positions of all groups
/// concatenated and the size of each group (2·d entries).
pub fn rim_nodes(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Result<(Vec<u64>, Vec<usize>)> {
    let table = neighbour_table(shape, linear, range.clone())?;
    rim_nodes_of(&table, shape.len(), range)
}

/// [`rim_nodes`] from the [`neighbour_table`] of band nodes `range` of a `d`-dimensional grid.
pub fn rim_nodes_of(table: &[i64], d: usize, range: std::ops::Range<usize>) -> Result<(Vec<u64>, Vec<usize>)> {
    let m = range.len();
    if table.len() != 2 * d * m {
        return Err(Error::invalid("neighbours", format!("expected shape ({}, {m})", 2 * d)));
    }
    if m == 0 {
        return Ok((Vec::new(), vec![0; 2 * d]));
    }
    let mut nodes = Vec::new();
    let mut counts = Vec::with_capacity(2 * d);
    for group in table.chunks_exact(m) {
        let before = nodes.len();
        for (&p, i) in group.iter().zip(range.clone()) {
            if p < 0 {
                nodes.push(i as u64);
            }
        }
        counts.push(nodes.len() - before);
    }
    Ok((nodes, counts))
}

/// The band position of `linear[i] + sign · stride` for `i` in `range`, or −1 (as
/// [`shifted_positions`]). Along the last axis (`stride` 1) the neighbour of a band node, if it is
/// one, is the next or previous entry of the sorted `linear`: no merge pass is needed.
fn neighbour_positions(linear: &[u64], stride: u64, sign: i64, range: std::ops::Range<usize>) -> Vec<i64> {
    if stride != 1 {
        return shifted_positions(linear, sign * stride as i64, range);
    }
    range
        .map(|i| {
            let j = if sign > 0 { i + 1 } else { i.wrapping_sub(1) };
            match linear.get(j) {
                Some(&l) if l as i128 == linear[i] as i128 + sign as i128 => j as i64,
                _ => -1,
            }
        })
        .collect()
}

/// Whether the neighbour along axis `k` on side `sign` of the node with grid index `c` is a band
/// node (`pos`, from the merge) inside the grid.
#[inline]
fn neighbour_known(c: &[u32; 3], pos: i64, k: usize, sign: i64, shape: &[usize]) -> bool {
    let c = c[k] as i64 + sign;
    pos >= 0 && c >= 0 && c < shape[k] as i64
}

/// The outward unit directions `sgn(φ) g/|g|` (as f32, written to `direction`, `range.len()`
/// rows of `d`) and `|g|` (returned) at band nodes `range`, where
/// `g_k = (φ(x + Δx e_k) − φ(x − Δx e_k)) / (2Δx)`: φ at band neighbours from `phi`, elsewhere
/// from `rim_phi`, which holds φ at the places [`rim_nodes`] lists, in its order. Where `|g|` is
/// at most 1e-12 the direction is `sgn(φ) g` (zero in practice). The arithmetic is that of the
/// NumPy code it replaces (`|g|` summed in axis order), so the directions are the same bits.
pub fn outward_directions(
    shape: &[usize],
    spacing: f64,
    linear: &[u64],
    phi: &[f64],
    range: std::ops::Range<usize>,
    rim_phi: &[f64],
    direction: &mut [f32],
) -> Result<Vec<f64>> {
    let table = neighbour_table(shape, linear, range.clone())?;
    outward_directions_with(shape, spacing, linear, phi, range, &table, rim_phi, direction)
}

/// [`outward_directions`] with the [`neighbour_table`] of band nodes `range` already made (for
/// [`rim_nodes_of`]): no second set of merge passes.
#[allow(clippy::too_many_arguments)]
pub fn outward_directions_with(
    shape: &[usize],
    spacing: f64,
    linear: &[u64],
    phi: &[f64],
    range: std::ops::Range<usize>,
    table: &[i64],
    rim_phi: &[f64],
    direction: &mut [f32],
) -> Result<Vec<f64>> {
    check(shape, linear, &range)?;
    if table.len() != 2 * shape.len() * range.len() {
        return Err(Error::invalid("neighbours", format!("expected shape ({}, {})", 2 * shape.len(), range.len())));
    }
    if table.iter().any(|&p| p < -1 || p >= linear.len() as i64) {
        return Err(Error::invalid("neighbours", "entries must be band positions or −1"));
    }
    let d = shape.len();
    let m = range.len();
    if phi.len() != linear.len() {
        return Err(Error::invalid("phi", format!("expected {} values (one per band node), got {}", linear.len(), phi.len())));
    }
    if direction.len() != m * d {
        return Err(Error::invalid("direction", format!("expected shape ({m}, {d})")));
    }
    // g accumulates φ(x + Δx e_k), then φ(x − Δx e_k) is subtracted: both sides are needed
    let mut up = vec![0.0f64; m];
    let mut g = vec![0.0f64; m * d];
    let mut next_rim = 0usize;
    for k in 0..d {
        for sign in [1i64, -1] {
            let pos = &table[(2 * k + usize::from(sign < 0)) * m..][..m];
            for o in 0..m {
                let v = if pos[o] >= 0 {
                    phi[pos[o] as usize]
                } else {
                    let v = *rim_phi.get(next_rim).ok_or_else(|| {
                        Error::invalid("rim_phi", format!("too few values: the rim has more than {} places", rim_phi.len()))
                    })?;
                    next_rim += 1;
                    v
                };
                if sign == 1 {
                    up[o] = v;
                } else {
                    g[o * d + k] = (up[o] - v) / (2.0 * spacing);
                }
            }
        }
    }
    if next_rim != rim_phi.len() {
        return Err(Error::invalid("rim_phi", format!("expected {next_rim} values (one per rim place), got {}", rim_phi.len())));
    }
    let mut norms = vec![0.0f64; m];
    for (o, i) in range.enumerate() {
        let gi = &g[o * d..(o + 1) * d];
        let mut sq = 0.0f64;
        for &c in gi {
            sq += c * c;
        }
        let norm = sq.sqrt();
        let safe = if norm > 1e-12 { norm } else { 1.0 };
        let sgn = if phi[i] > 0.0 {
            1.0
        } else if phi[i] < 0.0 {
            -1.0
        } else {
            0.0
        };
        for k in 0..d {
            direction[o * d + k] = (sgn * (gi[k] / safe)) as f32;
        }
        norms[o] = norm;
    }
    Ok(norms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_of_a_plane_and_the_rim_order() {
        // φ = x − 2.5 (axis 0) on a 6×4 grid, band |φ| ≤ 1.5: rows x = 1..4
        let shape = [6usize, 4];
        let h = 1.0;
        let linear: Vec<u64> = (4..20).collect();
        let phi: Vec<f64> = linear.iter().map(|&l| (l / 4) as f64 - 2.5).collect();
        let (rim, counts) = rim_nodes(&shape, &linear, 0..linear.len()).unwrap();
        // axis 0: +1 missing on the last row, −1 on the first; axis 1: the last and first column
        assert_eq!(counts, vec![4, 4, 4, 4]);
        assert_eq!(&rim[..4], &[12, 13, 14, 15]);
        assert_eq!(&rim[4..8], &[0, 1, 2, 3]);
        assert_eq!(&rim[8..12], &[3, 7, 11, 15]);
        // φ at the rim places, group by group
        let mut rim_phi = Vec::new();
        for (g, &n) in counts.iter().enumerate() {
            let (k, sign) = (g / 2, if g % 2 == 0 { 1.0 } else { -1.0 });
            let start: usize = counts[..g].iter().sum();
            for &i in &rim[start..start + n] {
                let x0 = (linear[i as usize] / 4) as f64 + if k == 0 { sign } else { 0.0 };
                rim_phi.push(x0 - 2.5);
            }
        }
        let mut dir = vec![0.0f32; 2 * linear.len()];
        let norms = outward_directions(&shape, h, &linear, &phi, 0..linear.len(), &rim_phi, &mut dir).unwrap();
        for (o, &p) in phi.iter().enumerate() {
            assert_eq!(norms[o], 1.0);
            assert_eq!(dir[2 * o], if p > 0.0 { 1.0 } else { -1.0 });
            assert_eq!(dir[2 * o + 1], 0.0);
        }
        assert!(outward_directions(&shape, h, &linear, &phi, 0..linear.len(), &rim_phi[1..], &mut dir).is_err());
    }

    #[test]
    fn a_sub_range_sees_the_whole_band() {
        let shape = [5usize, 5];
        let linear: Vec<u64> = (0..25).collect();
        let (rim, counts) = rim_nodes(&shape, &linear, 6..9).unwrap();
        assert!(rim.is_empty() && counts == vec![0; 4]);
        assert!(rim_nodes(&shape, &linear, 6..30).is_err());
    }
}
