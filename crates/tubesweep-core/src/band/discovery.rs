//! Band discovery helpers: the block bookkeeping of the coarse-to-fine search for the band of a
//! surface given by a distance-like function (`tubesweep.band.coarse_to_fine_candidates`).
//!
//! The search keeps blocks of 2^L nodes per axis near the surface and splits them level by level;
//! the level-set function is usually a Python callable, so the loop over levels stays in Python and
//! only calls it ([`discover_band`] runs the whole loop for a φ evaluated in Rust, the library's
//! analytic surfaces). Here: the children of the kept blocks with their centres and radii
//! ([`block_children`], [`children_radius_max`]), which the caller tests with φ at the centres,
//! and the last split, of the kept 2 × … × 2 blocks into single nodes, which produces the
//! candidate list, the largest array of the search (O(N^(d−1)) entries): [`split_pair_blocks`]
//! does it straight into sorted C-order linear indices, without a K-sized temporary or a sort.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// Checks that every parent block origin is a multiple of `2 · block` inside the grid.
fn check_parents<const D: usize>(shape: &[usize; D], parents: &[[u64; D]], block: u64) -> Result<()> {
    if block == 0 {
        return Err(Error::invalid("block", "the child block size must be positive"));
    }
    for o in parents {
        for k in 0..D {
            if o[k] % (2 * block) != 0 || o[k] >= shape[k] as u64 {
                return Err(Error::invalid(
                    "parents",
                    format!(
                        "block origin {o:?} is not a multiple of {} inside the grid {shape:?}",
                        2 * block
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Calls `f(child origin, child's last node)` for every child of blocks of `2 · block` nodes per
/// axis with lowest corners `parents`: the 2^d blocks of `block` nodes per axis that start inside
/// the grid, parent by parent, the corners in C order (axis 0 slowest). A block at the upper edge
/// of the grid is cut to it (its last node is the grid's last along that axis).
#[inline]
fn for_children<const D: usize>(
    shape: &[usize; D],
    parents: &[[u64; D]],
    block: u64,
    mut f: impl FnMut(&[u64; D], &[u64; D]),
) {
    for p in parents {
        'corner: for corner in 0..(1usize << D) {
            let mut o = [0u64; D];
            let mut last = [0u64; D];
            for k in 0..D {
                o[k] = p[k] + block * ((corner >> (D - 1 - k)) & 1) as u64;
                if o[k] >= shape[k] as u64 {
                    continue 'corner;
                }
                last[k] = (o[k] + block).min(shape[k] as u64) - 1;
            }
            f(&o, &last);
        }
    }
}

/// `|last − o|` in grid spacings: twice a block's radius (its centre to a corner) over `Δx`.
#[inline]
fn diagonal<const D: usize>(o: &[u64; D], last: &[u64; D]) -> f64 {
    let mut sq = 0.0f64;
    for k in 0..D {
        let e = (last[k] - o[k]) as f64;
        sq += e * e;
    }
    sq.sqrt()
}

/// The largest `|last − o|` (in grid spacings) over the children [`block_children`] makes of
/// `parents`: the caller's search reach for the level. 0 without children.
pub fn children_radius_max<const D: usize>(shape: [usize; D], parents: &[[u64; D]], block: u64) -> Result<f64> {
    check_parents(&shape, parents, block)?;
    let mut best = 0.0f64;
    for_children(&shape, parents, block, |o, last| best = best.max(diagonal(o, last)));
    Ok(best)
}

/// The children of the blocks of `2 · block` nodes per axis with lowest corners `parents` (each a
/// multiple of `2 · block` inside the grid): the blocks of `block` nodes per axis that start
/// inside the grid, parent by parent, corners in C order. Returns their origins, their centres
/// `lower + Δx · (o + last)/2` in world coordinates and their radii `Δx/2 · |last − o|` (centre to
/// a corner node), with the arithmetic of the NumPy code it replaces, so the same bits: a block is
/// kept when `|φ(centre)| ≤ half_width + lipschitz · radius`, exact for a `lipschitz`-Lipschitz φ.
#[allow(clippy::type_complexity)]
pub fn block_children<const D: usize>(
    shape: [usize; D],
    parents: &[[u64; D]],
    block: u64,
    lower: [f64; D],
    spacing: f64,
) -> Result<(Vec<[u64; D]>, Vec<[f64; D]>, Vec<f64>)> {
    check_parents(&shape, parents, block)?;
    let cap = parents.len() << D;
    let (mut origins, mut centres, mut radii) = (
        Vec::with_capacity(cap),
        Vec::with_capacity(cap),
        Vec::with_capacity(cap),
    );
    for_children(&shape, parents, block, |o, last| {
        origins.push(*o);
        centres.push(core::array::from_fn(|k| {
            lower[k] + spacing * (0.5 * (o[k] + last[k]) as f64)
        }));
        radii.push(0.5 * spacing * diagonal(o, last));
    });
    Ok((origins, centres, radii))
}

/// The C-order linear indices, strictly increasing, of the grid nodes of the blocks of 2 nodes
/// per axis whose lowest corners are `origins`, cut to the grid of shape `shape` (a block at the
/// upper edge of an odd axis has one node along it).
///
/// Every origin coordinate must be even and inside the grid (the blocks of a coarse-to-fine
/// search started on a lattice of even spacing), so that the blocks are disjoint; `origins` may
/// come in any order and must not repeat. The nodes are emitted in C order by walking the origins
/// sorted lexicographically: along each axis the pair `2i, 2i + 1` of a block never interleaves
/// with another block's pair, so no sort of the output is needed.
pub fn split_pair_blocks<const D: usize>(shape: [usize; D], origins: &[[u64; D]]) -> Result<Vec<u64>> {
    if let Some(o) = origins
        .par_iter()
        .find_first(|o| (0..D).any(|k| o[k] % 2 != 0 || o[k] >= shape[k] as u64))
    {
        return Err(Error::invalid(
            "origins",
            format!("block origin {o:?} is not an even grid index inside the grid {shape:?}"),
        ));
    }
    let mut stride = [1u64; D];
    for k in (0..D.saturating_sub(1)).rev() {
        stride[k] = stride[k + 1] * shape[k + 1] as u64;
    }
    // sorted lexicographically, which is the order of their linear indices (every coordinate is
    // inside the grid): sorting those u64 keys is several times faster than comparing arrays
    let mut keys: Vec<u64> = origins
        .par_iter()
        .map(|o| (0..D).map(|k| o[k] * stride[k]).sum())
        .collect();
    keys.par_sort_unstable();
    if keys.par_windows(2).any(|w| w[0] == w[1]) {
        return Err(Error::invalid("origins", "block origins repeat"));
    }
    let sorted: Vec<[u64; D]> = keys
        .par_iter()
        .map(|&l| {
            let mut o = [0u64; D];
            let mut key = l;
            for k in (0..D).rev() {
                o[k] = key % shape[k] as u64;
                key /= shape[k] as u64;
            }
            o
        })
        .collect();
    drop(keys);
    // the origins by their first coordinate: their nodes come in C order group after group, so
    // the groups are emitted on all threads, each into its own part of the output, whose size is
    // counted first (a block has 2 nodes along an axis, 1 where the grid ends after its origin)
    let nodes_of = |o: &[u64; D]| {
        (0..D)
            .map(|k| if o[k] + 1 < shape[k] as u64 { 2 } else { 1 })
            .product::<usize>()
    };
    let mut groups: Vec<&[[u64; D]]> = Vec::new();
    let mut rest = &sorted[..];
    while let Some(first) = rest.first() {
        let len = rest.partition_point(|o| o[0] == first[0]);
        let (group, tail) = rest.split_at(len);
        groups.push(group);
        rest = tail;
    }
    let counts: Vec<usize> = groups.par_iter().map(|g| g.iter().map(nodes_of).sum()).collect();
    let mut out = vec![0u64; counts.iter().sum()];
    let mut parts: Vec<&mut [u64]> = Vec::with_capacity(groups.len());
    let mut tail = &mut out[..];
    for &c in &counts {
        let (part, t) = tail.split_at_mut(c);
        parts.push(part);
        tail = t;
    }
    groups.par_iter().zip(parts).for_each(|(group, part)| {
        let mut written = 0;
        emit(&shape, &stride, group, 0, 0, part, &mut written);
        debug_assert_eq!(written, part.len());
    });
    Ok(out)
}

/// The world coordinates `lower + Δx · index` of the grid nodes with C-order linear indices
/// `linear` (each inside the grid of `shape`), with the arithmetic of `Grid.points`, so the same
/// bits: the points at which the caller evaluates φ for the candidates of the band, as `D`
/// coordinates per node, one node after another.
pub fn node_points<const D: usize>(
    shape: [usize; D],
    linear: &[u64],
    lower: [f64; D],
    spacing: f64,
) -> Result<Vec<f64>> {
    let total: u64 = shape.iter().map(|&n| n as u64).product();
    if let Some(&bad) = linear.iter().find(|&&l| l >= total) {
        return Err(Error::invalid(
            "linear",
            format!("linear index {bad} is outside the grid {shape:?}"),
        ));
    }
    // in chunks on all threads; within a chunk one division per row, not per node (the
    // candidates come in C order, many to a row)
    const CHUNK: usize = 1 << 14;
    let n_last = shape[D - 1] as u64;
    let mut out = vec![0.0f64; linear.len() * D];
    out.par_chunks_mut(CHUNK * D)
        .zip(linear.par_chunks(CHUNK))
        .for_each(|(out, linear)| {
            let mut row_begin = u64::MAX; // the linear index of the current row's first grid node
            let mut lead = [0.0f64; D];
            for (x, &l) in out.chunks_exact_mut(D).zip(linear) {
                if row_begin == u64::MAX || l < row_begin || l >= row_begin + n_last {
                    let r = l / n_last;
                    row_begin = r * n_last;
                    let mut key = r;
                    for k in (0..D - 1).rev() {
                        let n = shape[k] as u64;
                        lead[k] = lower[k] + spacing * (key % n) as f64;
                        key /= n;
                    }
                }
                lead[D - 1] = lower[D - 1] + spacing * (l - row_begin) as f64;
                x.copy_from_slice(&lead);
            }
        });
    Ok(out)
}

/// A level-set function evaluated in Rust: `phi(points, out)` writes φ at the points (`D`
/// coordinates each) to `out`.
pub type PhiFn<'a> = dyn Fn(&[f64], &mut [f64]) -> Result<()> + Sync + 'a;

/// Children (or candidates) per parallel task of [`discover_band`]: the Python search's
/// `EVAL_CHUNK`, which bounds the temporaries.
const EVAL_CHUNK: usize = 1 << 18;

/// The band `|φ| ≤ half_width` of a level set whose φ is evaluated in Rust (`phi(points, out)`,
/// `D` coordinates per point), found coarse-to-fine: the search of the Python package's
/// `coarse_to_fine_candidates` and `discover_band` (see their documentation) with the same levels,
/// tests and arithmetic, so the same nodes and values, but no call back into Python and no
/// array of all the candidates' coordinates. `lipschitz` bounds |∇φ|. Returns sorted C-order
/// linear indices and φ there.
pub fn discover_band<const D: usize>(
    shape: [usize; D],
    lower: [f64; D],
    spacing: f64,
    half_width: f64,
    lipschitz: f64,
    phi: &PhiFn<'_>,
) -> Result<(Vec<u64>, Vec<f64>)> {
    if shape.contains(&0) || !(spacing > 0.0 && half_width >= 0.0 && lipschitz > 0.0) {
        return Err(Error::invalid("grid", format!("need a non-empty grid, a positive spacing and Lipschitz bound, and a width ≥ 0; got shape {shape:?}, spacing {spacing}, half-width {half_width}, lipschitz {lipschitz}")));
    }
    let total: u64 = shape.iter().map(|&n| n as u64).product();
    let longest = *shape.iter().max().expect("D ≥ 1") as f64;
    // blocks of 2^L nodes per axis, L = ⌊log2(longest / 4)⌋ (at least 0)
    let level = (longest / 4.0).log2().floor();
    let mut block: u64 = if level >= 1.0 { 1 << level as u32 } else { 1 };
    let candidates: Vec<u64> = if block == 1 {
        (0..total).collect()
    } else {
        // the first level: the children of the lattice of twice the block's spacing, C order
        let mut parents: Vec<[u64; D]> = vec![[0; D]];
        for k in 0..D {
            parents = parents
                .iter()
                .flat_map(|p| {
                    (0..shape[k] as u64).step_by(2 * block as usize).map(move |c| {
                        let mut q = *p;
                        q[k] = c;
                        q
                    })
                })
                .collect();
        }
        loop {
            let kept: Vec<Vec<[u64; D]>> = parents
                .par_chunks((EVAL_CHUNK >> D).max(1))
                .map(|ps| {
                    let (origins, centres, radii) = block_children(shape, ps, block, lower, spacing)?;
                    let mut value = vec![0.0; origins.len()];
                    phi(centres.as_flattened(), &mut value)?;
                    Ok(origins
                        .into_iter()
                        .zip(value.iter().zip(&radii))
                        .filter(|(_, (v, r))| v.abs() <= half_width + lipschitz * **r + 1e-12)
                        .map(|(o, _)| o)
                        .collect())
                })
                .collect::<Result<_>>()?;
            parents = kept.concat();
            block /= 2;
            if block == 1 {
                break;
            }
        }
        split_pair_blocks(shape, &parents)?
    };
    // φ at the candidates and the filter, a slice at a time. Each slice's band nodes are kept at
    // the start of its place in one pair of buffers of the candidates' size, then moved together:
    // the buffers' pages past a slice's kept nodes are never touched (zeroed allocations), and
    // each buffer is one allocation, returned whole. (A pair of vectors per slice, joined at the
    // end, left the allocator holding their freed memory: about 15 bytes per band node at the
    // set-up's peak at N = 2001; docs/development/performance-history.md, "The narrow band's set-up memory".)
    let slice = EVAL_CHUNK / 8;
    let (mut linear, mut values) = (vec![0u64; candidates.len()], vec![0.0f64; candidates.len()]);
    let kept: Vec<usize> = candidates
        .par_chunks(slice)
        .zip(linear.par_chunks_mut(slice).zip(values.par_chunks_mut(slice)))
        .map(|(lin, (l, v))| {
            let points = node_points(shape, lin, lower, spacing)?;
            let mut value = vec![0.0; lin.len()];
            phi(&points, &mut value)?;
            keep_within(lin, &value, half_width, l, v)
        })
        .collect::<Result<_>>()?;
    drop(candidates);
    let mut end = 0;
    for (i, &k) in kept.iter().enumerate() {
        linear.copy_within(i * slice..i * slice + k, end);
        values.copy_within(i * slice..i * slice + k, end);
        end += k;
    }
    linear.truncate(end);
    values.truncate(end);
    linear.shrink_to_fit();
    values.shrink_to_fit();
    Ok((linear, values))
}

/// The band nodes' linear indices and values found in parts (slices of the grid or of the
/// candidates, in order), joined in that order.
pub(crate) fn concat_band_parts(parts: Vec<(Vec<u64>, Vec<f64>)>) -> (Vec<u64>, Vec<f64>) {
    let kept: usize = parts.iter().map(|p| p.0.len()).sum();
    let (mut linear, mut values) = (Vec::with_capacity(kept), Vec::with_capacity(kept));
    for (l, v) in parts {
        linear.extend_from_slice(&l);
        values.extend_from_slice(&v);
    }
    (linear, values)
}

/// Copies the candidates with `|value| ≤ half_width` (the band's nodes) to the fronts of
/// `linear_out` and `values_out`, in order, and returns how many there are: the filter of the
/// band search after φ at the candidates is known. An error if the outputs are too short or the
/// inputs differ in length.
pub fn keep_within(
    linear: &[u64],
    values: &[f64],
    half_width: f64,
    linear_out: &mut [u64],
    values_out: &mut [f64],
) -> Result<usize> {
    if values.len() != linear.len() {
        return Err(Error::invalid(
            "values",
            format!(
                "expected {} values (one per candidate), got {}",
                linear.len(),
                values.len()
            ),
        ));
    }
    if linear_out.len() < linear.len() || values_out.len() < linear.len() {
        return Err(Error::invalid(
            "out",
            format!("the outputs must hold {} entries", linear.len()),
        ));
    }
    let mut n = 0;
    for (&l, &v) in linear.iter().zip(values) {
        // written unconditionally, kept by advancing: no branch to mispredict
        linear_out[n] = l;
        values_out[n] = v;
        n += (v.abs() <= half_width) as usize;
    }
    Ok(n)
}

/// Emits, in C order, the nodes of the blocks `group` (sorted; all share their coordinates along
/// the axes before `axis`, whose contribution to the linear index is `base`) into `out` from
/// position `written` on, which it advances.
fn emit<const D: usize>(
    shape: &[usize; D],
    stride: &[u64; D],
    group: &[[u64; D]],
    axis: usize,
    base: u64,
    out: &mut [u64],
    written: &mut usize,
) {
    if axis + 1 == D {
        let n = shape[axis] as u64;
        for o in group {
            out[*written] = base + o[axis];
            *written += 1;
            if o[axis] + 1 < n {
                out[*written] = base + o[axis] + 1;
                *written += 1;
            }
        }
        return;
    }
    let n = shape[axis] as u64;
    let mut start = 0;
    while start < group.len() {
        let c = group[start][axis];
        let mut end = start + 1;
        while end < group.len() && group[end][axis] == c {
            end += 1;
        }
        for a in 0..2 {
            if c + a < n {
                emit(
                    shape,
                    stride,
                    &group[start..end],
                    axis + 1,
                    base + (c + a) * stride[axis],
                    out,
                    written,
                );
            }
        }
        start = end;
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_rust_search_finds_every_node_within_the_width() {
        // a sphere off the centre of a non-cubic grid that cuts it, against a scan of every node
        let (shape, lower, h) = ([37usize, 50, 29], [-1.0f64, -1.2, -0.8], 0.05);
        let surface =
            crate::surface::analytic::AnalyticSurface::from_parameters("sphere", &[0.1, -0.05, 0.2, 0.62]).unwrap();
        let phi = |p: &[f64], out: &mut [f64]| surface.signed_distance(p, out);
        for half_width in [0.0, 0.07, 0.2] {
            let (linear, values) = discover_band(shape, lower, h, half_width, 1.0, &phi).unwrap();
            let all: Vec<u64> = (0..(37 * 50 * 29) as u64).collect();
            let points = node_points(shape, &all, lower, h).unwrap();
            let mut v = vec![0.0; all.len()];
            phi(&points, &mut v).unwrap();
            let want: Vec<u64> = all
                .iter()
                .copied()
                .filter(|&l| v[l as usize].abs() <= half_width)
                .collect();
            assert_eq!(linear, want, "half-width {half_width}");
            assert!(linear.iter().zip(&values).all(|(&l, &x)| x == v[l as usize]));
        }
        assert!(discover_band(shape, lower, -h, 0.1, 1.0, &phi).is_err());
        // a tiny grid: every node is a candidate
        let (linear, _) = discover_band(
            [6, 7, 5],
            [-0.3, -0.3, -0.2],
            0.1,
            0.05,
            1.0,
            &|p: &[f64], out: &mut [f64]| {
                crate::surface::analytic::sphere_signed_distance(p, &[0.0, 0.0, 0.0], 0.2, out)
            },
        )
        .unwrap();
        assert!(!linear.is_empty());
    }
    use super::*;

    /// The straightforward answer: every node of every block, sorted.
    fn reference<const D: usize>(shape: [usize; D], origins: &[[u64; D]]) -> Vec<u64> {
        let mut out = Vec::new();
        for o in origins {
            for corner in 0..(1usize << D) {
                let mut idx = [0u64; D];
                let mut inside = true;
                for k in 0..D {
                    idx[k] = o[k] + ((corner >> (D - 1 - k)) & 1) as u64;
                    inside &= idx[k] < shape[k] as u64;
                }
                if inside {
                    out.push(idx.iter().zip(shape.iter()).fold(0u64, |l, (&i, &n)| l * n as u64 + i));
                }
            }
        }
        out.sort_unstable();
        out
    }

    #[test]
    fn matches_sorting_every_child_in_2d_and_3d() {
        // odd shapes (blocks cut at the upper edge), origins in scrambled order
        let shape3 = [7usize, 9, 5];
        let mut origins3 = Vec::new();
        for i in (0..7u64).step_by(2) {
            for j in (0..9u64).step_by(2) {
                for k in (0..5u64).step_by(2) {
                    if (i * 7 + j * 3 + k) % 5 != 1 {
                        origins3.push([i, j, k]);
                    }
                }
            }
        }
        origins3.reverse();
        origins3.swap(0, 5);
        let got = split_pair_blocks(shape3, &origins3).unwrap();
        assert_eq!(got, reference(shape3, &origins3));
        assert!(got.windows(2).all(|w| w[0] < w[1]));

        let shape2 = [6usize, 11];
        let origins2: Vec<[u64; 2]> = vec![[4, 10], [0, 0], [2, 4], [0, 8], [4, 0], [2, 2]];
        assert_eq!(
            split_pair_blocks(shape2, &origins2).unwrap(),
            reference(shape2, &origins2)
        );
        assert!(split_pair_blocks(shape2, &[]).unwrap().is_empty());
    }

    #[test]
    fn children_cover_their_parents_and_are_cut_to_the_grid() {
        // 2D, shape 7 × 10, parents of 4 × 4 nodes: children of 2 × 2, cut at the upper edges
        let shape = [7usize, 10];
        let parents = [[4u64, 8], [0, 0], [4, 4]];
        let (o, c, r) = block_children(shape, &parents, 2, [-1.0, 0.5], 0.25).unwrap();
        // parent by parent, corners in C order, only those starting inside the grid
        let want: Vec<[u64; 2]> = vec![
            [4, 8],
            [6, 8],
            [0, 0],
            [0, 2],
            [2, 0],
            [2, 2],
            [4, 4],
            [4, 6],
            [6, 4],
            [6, 6],
        ];
        assert_eq!(o, want);
        for ((o, c), r) in o.iter().zip(&c).zip(&r) {
            let last = [(o[0] + 2).min(7) - 1, (o[1] + 2).min(10) - 1];
            for k in 0..2 {
                let lower = [-1.0, 0.5][k];
                assert_eq!(c[k], lower + 0.25 * (0.5 * (o[k] + last[k]) as f64));
            }
            let e = [(last[0] - o[0]) as f64, (last[1] - o[1]) as f64];
            assert_eq!(*r, 0.5 * 0.25 * (e[0] * e[0] + e[1] * e[1]).sqrt());
        }
        assert_eq!(children_radius_max(shape, &parents, 2).unwrap(), 2f64.sqrt());
        assert_eq!(children_radius_max(shape, &[[6, 8]], 1).unwrap(), 0.0);
        assert!(block_children(shape, &[[2, 0]], 2, [0.0; 2], 1.0).is_err()); // not a multiple of 4
        assert!(block_children(shape, &[[8, 0]], 2, [0.0; 2], 1.0).is_err()); // outside
    }

    #[test]
    fn node_points_are_lower_plus_spacing_times_index() {
        let shape = [3usize, 4, 5];
        let linear: Vec<u64> = vec![0, 4, 5, 19, 20, 59];
        let p = node_points(shape, &linear, [0.5, -1.0, 2.0], 0.1).unwrap();
        for (n, &l) in linear.iter().enumerate() {
            let idx = [l / 20, (l / 5) % 4, l % 5];
            for k in 0..3 {
                assert_eq!(p[3 * n + k], [0.5, -1.0, 2.0][k] + 0.1 * idx[k] as f64);
            }
        }
        assert!(node_points(shape, &[60], [0.0; 3], 1.0).is_err());
    }

    #[test]
    fn rejects_odd_outside_and_repeated_origins() {
        assert!(split_pair_blocks([6usize, 6], &[[1, 0]]).is_err());
        assert!(split_pair_blocks([6usize, 6], &[[6, 0]]).is_err());
        assert!(split_pair_blocks([6usize, 6], &[[2, 2], [2, 2]]).is_err());
    }

    #[test]
    fn keep_within_keeps_the_band_in_order() {
        let lin = [3u64, 5, 8, 9, 14];
        let val = [0.5, -0.1, 0.2, -0.3, f64::NAN];
        let (mut lo, mut vo) = ([0u64; 5], [0.0; 5]);
        let n = keep_within(&lin, &val, 0.25, &mut lo, &mut vo).unwrap();
        assert_eq!((n, &lo[..n], &vo[..n]), (2, &[5u64, 8][..], &[-0.1, 0.2][..]));
        assert!(keep_within(&lin, &val, 0.25, &mut lo[..4], &mut vo).is_err());
        assert!(keep_within(&lin, &val[..4], 0.25, &mut lo, &mut vo).is_err());
    }
}
