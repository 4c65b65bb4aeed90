//! The outward extension direction `sgn(φ) ∇φ/|∇φ|` of a level set at the band nodes (paper
//! Eq. (8)), with `∇φ` by central differences (Sect. 4), for a φ known at the band nodes.
//!
//! The band nodes are given by their sorted C-order linear indices and φ there. The neighbour
//! `x ± Δx e_k` of a node is looked up in the band (the adjacent entry along the last axis, one
//! merge pass per other axis and side: the shifted index `linear[i] + offset` is found by
//! walking the sorted indices once, kept in a [`neighbour_table`]); where it is not a band node (the band's outer rim, or
//! outside the grid) φ there must be supplied by the caller: [`rim_nodes`] lists those places
//! and [`outward_directions`] takes φ at them, in the same order. (φ is a user's function that
//! the Python package evaluates, so the two halves are separate calls.)

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use rayon::prelude::*;

/// Linear-index strides of the axes of a C-order grid of `shape`.
fn strides(shape: &[usize]) -> Vec<u64> {
    let mut s = vec![1u64; shape.len()];
    for k in (0..shape.len().saturating_sub(1)).rev() {
        s[k] = s[k + 1] * shape[k + 1] as u64;
    }
    s
}

/// Grid indices (up to 3 axes; unused axes 0) of the nodes `linear[range]`, on all threads.
fn node_coordinates(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Vec<[u32; 3]> {
    let d = shape.len();
    linear[range]
        .par_iter()
        .map(|&l| {
            let mut c = [0u32; 3];
            let mut key = l;
            for k in (0..d).rev() {
                c[k] = (key % shape[k] as u64) as u32;
                key /= shape[k] as u64;
            }
            c
        })
        .collect()
}

fn check(shape: &[usize], linear: &[u64], range: &std::ops::Range<usize>) -> Result<()> {
    if !(2..=3).contains(&shape.len()) || shape.iter().any(|&n| n == 0 || n > u32::MAX as usize) {
        return Err(Error::invalid(
            "grid",
            format!("only 2D and 3D grids are supported, got shape {shape:?}"),
        ));
    }
    if range.start > range.end || range.end > linear.len() {
        return Err(Error::invalid(
            "range",
            format!("{range:?} is not a range of the {} band nodes", linear.len()),
        ));
    }
    let total: u64 = shape.iter().map(|&n| n as u64).product();
    if linear[range.clone()].windows(2).any(|w| w[0] >= w[1])
        || linear[range.clone()].last().is_some_and(|&l| l >= total)
    {
        return Err(Error::invalid(
            "linear",
            "band nodes must be strictly increasing linear indices inside the grid",
        ));
    }
    Ok(())
}

/// Band nodes per parallel task of [`outward_directions_with`].
const CHUNK: usize = 1 << 14;

/// Calls `f(o, c)` for the nodes `o` of chunk `j` (of [`CHUNK`] nodes) of the `m` band nodes from
/// `start` on, in order, with `c` the node's index along the last axis (of `n_last` nodes): one
/// division per row, not per node.
#[inline(always)]
fn nodes_of_chunk(linear: &[u64], start: usize, j: usize, m: usize, n_last: u64, mut f: impl FnMut(usize, u32)) {
    let (lo, hi) = (j * CHUNK, ((j + 1) * CHUNK).min(m));
    let mut row_start = u64::MAX;
    for o in lo..hi {
        let l = linear[start + o];
        if row_start == u64::MAX || l >= row_start + n_last {
            row_start = l / n_last * n_last;
        }
        f(o, (l - row_start) as u32);
    }
}

/// Entry of a [`neighbour_table`] where the neighbour is not a band node or lies outside the grid.
pub const NO_NEIGHBOUR: i32 = i32::MIN;

/// The neighbour table of band nodes `range` (`m` of them) along the axes but the last: for every
/// group `(axis k < d − 1, side)` in the order `k = 0, 1, …`, side `+1` then `−1`, `m` entries,
/// the position in the band of the neighbour `x ± Δx e_k` of node `i` less `i` (as i32: 4 bytes
/// per node and group), or [`NO_NEIGHBOUR`] where that neighbour is not a band node or lies
/// outside the grid (a place where φ must come from the caller). Along the last axis the
/// neighbours are the adjacent entries of the sorted band and need no table. The groups' merge
/// passes are independent and run in parallel; one table serves both [`rim_nodes_of`] and
/// [`outward_directions_with`]. An error if a neighbour is 2^31 or more band nodes away from a
/// node (a band of billions of nodes within one stride of axis 0).
pub fn neighbour_table(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Result<Vec<i32>> {
    check(shape, linear, &range)?;
    let stride = strides(shape);
    let coords = node_coordinates(shape, linear, range.clone());
    let m = range.len();
    let mut table = vec![NO_NEIGHBOUR; 2 * (shape.len() - 1) * m];
    if m == 0 {
        return Ok(table);
    }
    let fits: Vec<bool> = table
        .par_chunks_mut(m)
        .enumerate()
        .map(|(group, out)| {
            let (k, sign) = (group / 2, if group % 2 == 0 { 1i64 } else { -1 });
            // one merge pass over the sorted indices for this offset, written straight into the table
            let offset = sign * stride[k] as i64;
            let target = |x: u64| -> Option<u64> { u64::try_from(x as i128 + offset as i128).ok() };
            let mut j = match target(linear[range.start]) {
                Some(t) => linear.partition_point(|&y| y < t),
                None => 0,
            };
            for (o, i) in range.clone().enumerate() {
                let Some(t) = target(linear[i]) else { continue };
                while j < linear.len() && linear[j] < t {
                    j += 1;
                }
                if j == linear.len() {
                    break;
                }
                if linear[j] == t && in_grid(&coords[o], k, sign, shape) {
                    match i32::try_from(j as i64 - i as i64) {
                        Ok(delta) if delta != NO_NEIGHBOUR => out[o] = delta,
                        _ => return false,
                    }
                }
            }
            true
        })
        .collect();
    if fits.contains(&false) {
        return Err(Error::invalid(
            "linear",
            "a neighbour is 2^31 or more band nodes away: too large a band for a neighbour table",
        ));
    }
    Ok(table)
}

/// The band position of the neighbour along the last axis (`n` nodes) on side `sign` of band node
/// `i` (index `c` along that axis): the adjacent entry of the sorted band, if it is that node.
#[inline]
fn last_axis_neighbour(linear: &[u64], i: usize, c: u32, n: usize, sign: i64) -> Option<usize> {
    if sign > 0 {
        ((c as usize) + 1 < n && linear.get(i + 1) == Some(&(linear[i] + 1))).then_some(i + 1)
    } else {
        (c > 0 && i > 0 && linear[i - 1] == linear[i] - 1).then(|| i - 1)
    }
}

/// For every group `(axis k, side)` in the order `k = 0, 1, …`, side `+1` then `−1`: the band
/// positions `i` in `range` whose neighbour `linear[i] ± stride_k` is not a band node (or lies
/// outside the grid along axis `k`), in increasing order. Returns the positions of all groups
/// concatenated and the size of each group (2·d entries).
pub fn rim_nodes(shape: &[usize], linear: &[u64], range: std::ops::Range<usize>) -> Result<(Vec<u64>, Vec<usize>)> {
    let table = neighbour_table(shape, linear, range.clone())?;
    rim_nodes_of(shape, linear, range, &table)
}

/// [`rim_nodes`] from the [`neighbour_table`] of band nodes `range`.
pub fn rim_nodes_of(
    shape: &[usize],
    linear: &[u64],
    range: std::ops::Range<usize>,
    table: &[i32],
) -> Result<(Vec<u64>, Vec<usize>)> {
    check(shape, linear, &range)?;
    let (d, m) = (shape.len(), range.len());
    if table.len() != 2 * (d - 1) * m {
        return Err(Error::invalid(
            "neighbours",
            format!("expected shape ({}, {m})", 2 * (d - 1)),
        ));
    }
    // along the leading axes, the table's entries without a neighbour; along the last axis, the
    // nodes whose adjacent band entry is not their neighbour (chunk by chunk, in order)
    let n_last = shape[d - 1] as u64;
    let mut groups: Vec<Vec<u64>> = (0..2 * (d - 1))
        .into_par_iter()
        .map(|g| {
            let row = &table[g * m..(g + 1) * m];
            row.iter()
                .zip(range.clone())
                .filter(|(&delta, _)| delta == NO_NEIGHBOUR)
                .map(|(_, i)| i as u64)
                .collect()
        })
        .collect();
    for sign in [1i64, -1] {
        let parts: Vec<Vec<u64>> = (0..m.div_ceil(CHUNK))
            .into_par_iter()
            .map(|j| {
                let mut out = Vec::new();
                nodes_of_chunk(linear, range.start, j, m, n_last, |o, c_last| {
                    let i = range.start + o;
                    if last_axis_neighbour(linear, i, c_last, shape[d - 1], sign).is_none() {
                        out.push(i as u64);
                    }
                });
                out
            })
            .collect();
        groups.push(parts.concat());
    }
    let counts = groups.iter().map(Vec::len).collect();
    Ok((groups.concat(), counts))
}

/// Whether the neighbour along axis `k` on side `sign` of the node with grid index `c` lies
/// inside the grid.
#[inline]
fn in_grid(c: &[u32; 3], k: usize, sign: i64, shape: &[usize]) -> bool {
    let c = c[k] as i64 + sign;
    c >= 0 && c < shape[k] as i64
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
    table: &[i32],
    rim_phi: &[f64],
    direction: &mut [f32],
) -> Result<Vec<f64>> {
    check(shape, linear, &range)?;
    if table.len() != 2 * (shape.len() - 1) * range.len() {
        return Err(Error::invalid(
            "neighbours",
            format!("expected shape ({}, {})", 2 * (shape.len() - 1), range.len()),
        ));
    }
    let m = range.len();
    let leads_inside = |row: &[i32]| {
        row.par_iter()
            .zip(range.clone())
            .all(|(&delta, i)| delta == NO_NEIGHBOUR || (0..linear.len() as i64).contains(&(i as i64 + delta as i64)))
    };
    if m > 0 && !table.chunks_exact(m).all(leads_inside) {
        return Err(Error::invalid("neighbours", "entries must lead to band positions"));
    }
    let d = shape.len();
    if phi.len() != linear.len() {
        return Err(Error::invalid(
            "phi",
            format!(
                "expected {} values (one per band node), got {}",
                linear.len(),
                phi.len()
            ),
        ));
    }
    let n_last = shape[d - 1] as u64;
    // the neighbour of node `o` of the range for group `g` (the node's index along the last axis
    // is `c_last`), if it is a band node
    let first = range.start;
    let neighbour = |o: usize, c_last: u32, g: usize| -> Option<usize> {
        let (k, sign) = (g / 2, if g.is_multiple_of(2) { 1i64 } else { -1 });
        let i = first + o;
        if k + 1 < d {
            let delta = table[g * m + o];
            (delta != NO_NEIGHBOUR).then(|| (i as i64 + delta as i64) as usize)
        } else {
            last_axis_neighbour(linear, i, c_last, shape[d - 1], sign)
        }
    };
    directions_by_central_differences(
        d,
        spacing,
        phi,
        range,
        Some((linear, n_last)),
        rim_phi,
        direction,
        neighbour,
    )
}

/// [`outward_directions`] with the neighbours read off a band already built from the same
/// linear indices ([`NarrowBand::neighbours_of`]): no neighbour table, no merge passes. φ off
/// the band comes from `rim_phi` in the order of [`rim_nodes_in_band`].
pub fn outward_directions_in_band<const D: usize>(
    band: &NarrowBand<D>,
    spacing: f64,
    phi: &[f64],
    range: std::ops::Range<usize>,
    rim_phi: &[f64],
    direction: &mut [f32],
) -> Result<Vec<f64>> {
    if range.start > range.end || range.end > band.len() {
        return Err(Error::invalid(
            "range",
            format!("{range:?} is not a range of the {} band nodes", band.len()),
        ));
    }
    if phi.len() != band.len() {
        return Err(Error::invalid(
            "phi",
            format!("expected {} values (one per band node), got {}", band.len(), phi.len()),
        ));
    }
    let sentinel = band.sentinel();
    let first = range.start;
    let neighbour = |o: usize, _: u32, g: usize| -> Option<usize> {
        // group 2k: side +1 (the band's `plus`, entry 1); group 2k + 1: side −1 (entry 0)
        // SAFETY: o < m, so first + o < range.end ≤ band.len()
        let nb = unsafe { band.neighbours_of_unchecked(first + o) }[g / 2][1 - g % 2];
        (nb != sentinel).then_some(nb as usize)
    };
    directions_by_central_differences(D, spacing, phi, range, None, rim_phi, direction, neighbour)
}

/// [`rim_nodes`] read off a band already built from the same linear indices: for every group
/// `(axis k, side)` in the order `k = 0, 1, …`, side `+1` then `−1`, the positions `i` in `range`
/// whose neighbour there is not a band node, in increasing order.
pub fn rim_nodes_in_band<const D: usize>(
    band: &NarrowBand<D>,
    range: std::ops::Range<usize>,
) -> Result<(Vec<u64>, Vec<usize>)> {
    if range.start > range.end || range.end > band.len() {
        return Err(Error::invalid(
            "range",
            format!("{range:?} is not a range of the {} band nodes", band.len()),
        ));
    }
    let sentinel = band.sentinel();
    let groups: Vec<Vec<u64>> = (0..2 * D)
        .into_par_iter()
        .map(|g| {
            let (k, side) = (g / 2, 1 - g % 2);
            range
                .clone()
                // SAFETY: i < range.end ≤ band.len()
                .filter(|&i| unsafe { band.neighbours_of_unchecked(i) }[k][side] == sentinel)
                .map(|i| i as u64)
                .collect()
        })
        .collect();
    let counts = groups.iter().map(Vec::len).collect();
    Ok((groups.concat(), counts))
}

/// [`outward_directions_in_band`] for a φ evaluated in Rust (`phi`, the library's analytic
/// surfaces), in one pass: chunk by chunk, φ at the chunk's off-band neighbours `x ± Δx e_k` is
/// evaluated at once, with the node coordinates of [`crate::band::discovery::node_points`], and the
/// differences follow. The same points and arithmetic as listing the rim places
/// ([`rim_nodes_in_band`]), evaluating φ there and calling [`outward_directions_in_band`] (the
/// callable route of the Python package), so the same bits, without the rim's lists, the
/// prefix sums and a second pass over the band. `linear` are the band's sorted linear indices and
/// `values` φ at its nodes; returns |∇φ| per node, in single precision (what the checks on it
/// need, and 4 bytes per node less at the set-up's peak: docs/development/performance-history.md, "The narrow band's set-up memory").
pub fn outward_directions_of_function_in_band<const D: usize>(
    band: &NarrowBand<D>,
    linear: &[u64],
    values: &[f64],
    lower: [f64; D],
    spacing: f64,
    phi: &crate::band::discovery::PhiFn<'_>,
    direction: &mut [f32],
) -> Result<Vec<f32>> {
    let m = band.len();
    if linear.len() != m || values.len() != m || direction.len() != m * D {
        return Err(Error::invalid(
            "band",
            format!("expected {m} linear indices, values and directions (×{D}) for the band's nodes"),
        ));
    }
    let (shape, sentinel) = (band.shape(), band.sentinel());
    let mut norms_out = vec![0.0f32; m];
    direction
        .par_chunks_mut(CHUNK * D)
        .zip(norms_out.par_chunks_mut(CHUNK))
        .enumerate()
        .try_for_each(|(j, (dir, norms_out))| -> Result<()> {
            let lo = j * CHUNK;
            let n = norms_out.len();
            let mut norms = vec![0.0f64; n];
            let norms = &mut norms[..];
            let coords = crate::band::discovery::node_points(shape, &linear[lo..lo + n], lower, spacing)?;
            // the chunk's off-band neighbours, node by node and group by group (axis k, side +1
            // then −1), and φ there
            let mut places: Vec<f64> = Vec::new();
            for o in 0..n {
                // SAFETY: lo + o < m = band.len()
                let nb = unsafe { band.neighbours_of_unchecked(lo + o) };
                for g in 0..2 * D {
                    if nb[g / 2][1 - g % 2] == sentinel {
                        let at = places.len();
                        places.extend_from_slice(&coords[o * D..(o + 1) * D]);
                        places[at + g / 2] += if g % 2 == 0 { spacing } else { -spacing };
                    }
                }
            }
            let mut off_band = vec![0.0; places.len() / D];
            phi(&places, &mut off_band)?;
            let mut next = off_band.iter();
            let mut block = Block::new();
            let two_h = 2.0 * spacing;
            for o in 0..n {
                // SAFETY: as above
                let nb = unsafe { band.neighbours_of_unchecked(lo + o) };
                let neighbour_phi = |g: usize| {
                    let q = nb[g / 2][1 - g % 2];
                    if q == sentinel {
                        *next.next().expect("one value per off-band place")
                    } else {
                        values[q as usize]
                    }
                };
                block.push(o, values[lo + o], D, neighbour_phi, two_h, dir, norms);
            }
            block.finish(D, two_h, dir, norms);
            norms_out.iter_mut().zip(norms.iter()).for_each(|(o, &v)| *o = v as f32);
            Ok(())
        })?;
    Ok(norms_out)
}

/// The arithmetic of [`outward_directions`] for nodes `range` of a band of `phi.len()` nodes in
/// `d` dimensions. `neighbour(o, c_last, g)` is the band position of the neighbour of node
/// `range.start + o` in group `g` (axis `g / 2`, side `+1` for even `g`), or `None` where φ comes
/// from `rim_phi`; `c_last` is the node's index along the last axis when `linear` (the sorted
/// linear indices and the last axis's length) is given, 0 otherwise.
#[allow(clippy::too_many_arguments)]
fn directions_by_central_differences<N>(
    d: usize,
    spacing: f64,
    phi: &[f64],
    range: std::ops::Range<usize>,
    linear: Option<(&[u64], u64)>,
    rim_phi: &[f64],
    direction: &mut [f32],
    neighbour: N,
) -> Result<Vec<f64>>
where
    N: Fn(usize, u32, usize) -> Option<usize> + Sync,
{
    let m = range.len();
    // calls f(o, c_last) for the nodes o of chunk j, in order
    let visit_chunk = |j: usize, f: &mut dyn FnMut(usize, u32)| match linear {
        Some((linear, n_last)) => nodes_of_chunk(linear, range.start, j, m, n_last, f),
        None => (j * CHUNK..((j + 1) * CHUNK).min(m)).for_each(|o| f(o, 0)),
    };
    if direction.len() != m * d {
        return Err(Error::invalid("direction", format!("expected shape ({m}, {d})")));
    }
    // The nodes go to the threads in chunks. Each node needs φ at its 2d neighbours; where one
    // is off the band, the value comes from `rim_phi`, which holds group after group (axis k,
    // side +1 then −1), each in node order. So the chunks first count their missing neighbours
    // per group, and the prefix sums say where each chunk's values start in every group.
    let chunks = m.div_ceil(CHUNK);
    let groups = 2 * d;
    let missing: Vec<[usize; 6]> = (0..chunks)
        .into_par_iter()
        .map(|j| {
            let mut count = [0usize; 6];
            visit_chunk(j, &mut |o, c_last| {
                for (g, n) in count.iter_mut().enumerate().take(groups) {
                    *n += neighbour(o, c_last, g).is_none() as usize;
                }
            });
            count
        })
        .collect();
    // where chunk j's values of group g start in `rim_phi`: all of the earlier groups, then
    // group g's values of the earlier chunks
    let mut start = vec![[0usize; 6]; chunks];
    let mut next = 0usize;
    for g in 0..groups {
        for j in 0..chunks {
            start[j][g] = next;
            next += missing[j][g];
        }
    }
    if next != rim_phi.len() {
        return Err(Error::invalid(
            "rim_phi",
            format!("expected {next} values (one per rim place), got {}", rim_phi.len()),
        ));
    }
    let mut norms = vec![0.0f64; m];
    direction
        .par_chunks_mut(CHUNK * d)
        .zip(norms.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(j, (dir, norms))| {
            let mut rim = start[j];
            let lo = j * CHUNK;
            // The neighbour values are gathered for a block of nodes at a time, and the block's
            // differences, norms and directions are then computed axis by axis over plain arrays,
            // which the compiler turns into vector divisions and square roots: the same operations
            // in the same order per node, so the same bits.
            let mut block = Block::new();
            let two_h = 2.0 * spacing;
            visit_chunk(j, &mut |o, c_last| {
                let neighbour_phi = |g: usize| match neighbour(o, c_last, g) {
                    Some(p) => phi[p],
                    None => {
                        rim[g] += 1;
                        rim_phi[rim[g] - 1]
                    }
                };
                block.push(o - lo, phi[range.start + o], d, neighbour_phi, two_h, dir, norms);
            });
            block.finish(d, two_h, dir, norms);
        });
    Ok(norms)
}

/// Nodes per block of [`Block`].
const BLOCK: usize = 256;

/// φ at the neighbours of a block of up to [`BLOCK`] consecutive nodes of a chunk (group
/// `2k + side`, side 0 the plus neighbour), φ at the nodes themselves, and where the block starts
/// in the chunk.
struct Block {
    phi: [[f64; BLOCK]; 6],
    own: [f64; BLOCK],
    first: usize,
    len: usize,
}

impl Block {
    fn new() -> Box<Self> {
        Box::new(Block {
            phi: [[0.0; BLOCK]; 6],
            own: [0.0; BLOCK],
            first: 0,
            len: 0,
        })
    }

    /// Appends node `o` of the chunk, with φ there `own` and at its neighbours `neighbour_phi(g)`
    /// (group `g = 2k + side`, side 0 the plus neighbour, asked in that order), and finishes the
    /// block into the chunk's `dir` and `norms` when it is full.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn push(
        &mut self,
        o: usize,
        own: f64,
        d: usize,
        mut neighbour_phi: impl FnMut(usize) -> f64,
        two_h: f64,
        dir: &mut [f32],
        norms: &mut [f64],
    ) {
        let i = self.len;
        for g in 0..2 * d {
            self.phi[g][i] = neighbour_phi(g);
        }
        self.own[i] = own;
        if i == 0 {
            self.first = o;
        }
        self.len += 1;
        if self.len == BLOCK {
            self.finish(d, two_h, dir, norms);
        }
    }

    /// Writes the block's directions and |∇φ| to the chunk's `dir` and `norms` and empties it:
    /// `g_k = (φ(x + Δx e_k) − φ(x − Δx e_k)) / (2Δx)`, `|g|` summed in axis order,
    /// `sgn(φ) g/|g|` (`g` itself where `|g| ≤ 1e-12`).
    fn finish(&mut self, d: usize, two_h: f64, dir: &mut [f32], norms: &mut [f64]) {
        let n = self.len;
        if n == 0 {
            return;
        }
        let mut grad = [[0.0f64; BLOCK]; 3];
        let mut sq = [0.0f64; BLOCK];
        for k in 0..d {
            let (plus, minus, gk) = (&self.phi[2 * k][..n], &self.phi[2 * k + 1][..n], &mut grad[k][..n]);
            for i in 0..n {
                gk[i] = (plus[i] - minus[i]) / two_h;
                sq[i] += gk[i] * gk[i];
            }
        }
        let (dir, norms) = (
            &mut dir[self.first * d..(self.first + n) * d],
            &mut norms[self.first..self.first + n],
        );
        let mut scale = [0.0f64; BLOCK];
        for i in 0..n {
            let norm = sq[i].sqrt();
            norms[i] = norm;
            scale[i] = if norm > 1e-12 { norm } else { 1.0 };
        }
        for i in 0..n {
            let p = self.own[i];
            let sgn = if p > 0.0 {
                1.0
            } else if p < 0.0 {
                -1.0
            } else {
                0.0
            };
            for k in 0..d {
                dir[i * d + k] = (sgn * (grad[k][i] / scale[i])) as f32;
            }
        }
        self.len = 0;
    }
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

    #[test]
    fn a_function_gives_the_directions_of_its_values_at_the_rim_places() {
        // a sphere's φ evaluated in Rust: the fused pass against the rim places, φ there by the
        // node coordinates ± Δx, and the directions from them
        let (shape, lower, h) = ([30usize, 26, 33], [-0.8f64, -0.7, -0.85], 0.05);
        let phi = |p: &[f64], out: &mut [f64]| {
            crate::surface::analytic::sphere_signed_distance(p, &[0.02, -0.03, 0.0], 0.55, out)
        };
        let (linear, values) = crate::band::discovery::discover_band(shape, lower, h, 4.0 * h, 1.0, &phi).unwrap();
        let band = NarrowBand::<3>::from_sorted_linear(shape, &linear).unwrap();
        let (rim, counts) = rim_nodes_in_band(&band, 0..linear.len()).unwrap();
        let mut rim_phi = Vec::new();
        let mut start = 0;
        for (g, &count) in counts.iter().enumerate() {
            let places: Vec<u64> = rim[start..start + count].iter().map(|&i| linear[i as usize]).collect();
            let mut x = crate::band::discovery::node_points(shape, &places, lower, h).unwrap();
            for p in x.chunks_mut(3) {
                p[g / 2] += if g % 2 == 0 { h } else { -h };
            }
            let mut v = vec![0.0; count];
            phi(&x, &mut v).unwrap();
            rim_phi.extend(v);
            start += count;
        }
        let mut a = vec![0.0f32; 3 * linear.len()];
        let mut b = a.clone();
        let na = outward_directions_in_band(&band, h, &values, 0..linear.len(), &rim_phi, &mut a).unwrap();
        let nb = outward_directions_of_function_in_band(&band, &linear, &values, lower, h, &phi, &mut b).unwrap();
        assert!(!rim_phi.is_empty());
        let na: Vec<f32> = na.iter().map(|&v| v as f32).collect();
        assert_eq!((&na, &a), (&nb, &b));
        assert!(outward_directions_of_function_in_band(&band, &linear[1..], &values, lower, h, &phi, &mut b).is_err());
    }

    #[test]
    fn a_built_band_gives_the_rim_places_and_directions_of_the_merge_passes() {
        // a spherical shell in 3D (φ = |x − c| − 8) and a band touching the grid's faces in 2D
        // (where no neighbour may wrap around), whole and in sub-ranges
        fn same<const D: usize>(shape: [usize; D], linear: &[u64], phi: &[f64], range: std::ops::Range<usize>) {
            let band = NarrowBand::<D>::from_sorted_linear(shape, linear).unwrap();
            let (rim, counts) = rim_nodes(&shape, linear, range.clone()).unwrap();
            assert_eq!(
                rim_nodes_in_band(&band, range.clone()).unwrap(),
                (rim.clone(), counts.clone())
            );
            // φ off the band: any values will do, as long as both read the same ones
            let rim_phi: Vec<f64> = (0..rim.len()).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut a = vec![0.0f32; range.len() * D];
            let mut b = a.clone();
            let na = outward_directions(&shape, 0.5, linear, phi, range.clone(), &rim_phi, &mut a).unwrap();
            let nb = outward_directions_in_band(&band, 0.5, phi, range.clone(), &rim_phi, &mut b).unwrap();
            assert_eq!((&na, &a), (&nb, &b));
            if !rim_phi.is_empty() {
                assert!(outward_directions_in_band(&band, 0.5, phi, range.clone(), &rim_phi[1..], &mut b).is_err());
            }
        }
        let n = 23usize;
        let c = (n - 1) as f64 / 2.0;
        let r = |l: u64| {
            let (i, j, k) = (
                (l / (n * n) as u64) as f64,
                ((l / n as u64) % n as u64) as f64,
                (l % n as u64) as f64,
            );
            ((i - c).powi(2) + (j - c).powi(2) + (k - c).powi(2)).sqrt() - 8.0
        };
        let lin3: Vec<u64> = (0..(n * n * n) as u64).filter(|&l| r(l).abs() <= 2.5).collect();
        let phi3: Vec<f64> = lin3.iter().map(|&l| r(l)).collect();
        for range in [0..lin3.len(), 17..lin3.len() / 2, 5..5] {
            same([n, n, n], &lin3, &phi3, range);
        }
        let lin2: Vec<u64> = (0..(n * n) as u64)
            .filter(|&l| l % n as u64 <= 2 || l / n as u64 >= (n - 2) as u64)
            .collect();
        let phi2: Vec<f64> = lin2
            .iter()
            .map(|&l| (l % n as u64) as f64 - 1.3 + 0.01 * (l / n as u64) as f64)
            .collect();
        same([n, n], &lin2, &phi2, 0..lin2.len());
        let band2 = NarrowBand::<2>::from_sorted_linear([n, n], &lin2).unwrap();
        assert!(rim_nodes_in_band(&band2, 0..lin2.len() + 1).is_err());
    }
}
