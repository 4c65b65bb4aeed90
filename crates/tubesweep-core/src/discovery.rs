//! Band discovery helpers: the last step of the coarse-to-fine search for the band of a surface
//! given by a distance-like function (`tubesweep.surface.coarse_to_fine_candidates`).
//!
//! The search keeps blocks of 2^L nodes per axis near the surface and splits them level by level;
//! the level-set function itself is a Python callable, so the search loop stays in Python. Its
//! last split, of the kept 2 × … × 2 blocks into single nodes, produces the candidate list, the
//! largest array of the search (O(N^(d−1)) entries): [`split_pair_blocks`] does it here, straight
//! into sorted C-order linear indices, without a K-sized temporary or a sort.

use crate::error::{Error, Result};

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
    for o in origins {
        for k in 0..D {
            if o[k] % 2 != 0 || o[k] >= shape[k] as u64 {
                return Err(Error::invalid("origins", format!("block origin {o:?} is not an even grid index inside the grid {shape:?}")));
            }
        }
    }
    let mut sorted = origins.to_vec();
    sorted.sort_unstable();
    if sorted.windows(2).any(|w| w[0] == w[1]) {
        return Err(Error::invalid("origins", "block origins repeat"));
    }
    let mut stride = [1u64; D];
    for k in (0..D.saturating_sub(1)).rev() {
        stride[k] = stride[k + 1] * shape[k + 1] as u64;
    }
    // count first, so the output is allocated once at its final size
    let mut count = 0usize;
    emit(&shape, &stride, &sorted, 0, 0, &mut |_| count += 1);
    let mut out = Vec::with_capacity(count);
    emit(&shape, &stride, &sorted, 0, 0, &mut |l| out.push(l));
    Ok(out)
}

/// Emits, in C order, the nodes of the blocks `group` (sorted; all share their coordinates along
/// the axes before `axis`, whose contribution to the linear index is `base`).
fn emit<const D: usize>(shape: &[usize; D], stride: &[u64; D], group: &[[u64; D]], axis: usize, base: u64, out: &mut dyn FnMut(u64)) {
    if axis + 1 == D {
        let n = shape[axis] as u64;
        for o in group {
            out(base + o[axis]);
            if o[axis] + 1 < n {
                out(base + o[axis] + 1);
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
                emit(shape, stride, &group[start..end], axis + 1, base + (c + a) * stride[axis], out);
            }
        }
        start = end;
    }
}

#[cfg(test)]
mod tests {
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
        assert_eq!(split_pair_blocks(shape2, &origins2).unwrap(), reference(shape2, &origins2));
        assert!(split_pair_blocks(shape2, &[]).unwrap().is_empty());
    }

    #[test]
    fn rejects_odd_outside_and_repeated_origins() {
        assert!(split_pair_blocks([6usize, 6], &[[1, 0]]).is_err());
        assert!(split_pair_blocks([6usize, 6], &[[6, 0]]).is_err());
        assert!(split_pair_blocks([6usize, 6], &[[2, 2], [2, 2]]).is_err());
    }
}
