//! Cutting the band's neighbour table across a narrow gap between two facing parts of the
//! surface (see [`crate::band::facing_sheets`]).
//!
//! Where the tubes of two sheets touch, the Godunov update (Eq. (3)) of a node of one sheet reads
//! its neighbour on the other, the front crosses the gap, and every travel time beyond the
//! crossing comes out too short. The two-layer method (Algorithm 3) needs each node's neighbours
//! on its own part of the surface: removing the edges between the pairs of neighbours that
//! straddle the gap ([`crate::band::facing_sheets::FacingPair`]) leaves each node the one-sided
//! stencil it has at the edge of the band, so the front can only travel along the surface. A
//! removed neighbour reads as "not in the band" everywhere the table is read (the sweeps, the
//! second-order stencils, which then fall back to the first-order update at those nodes).

use crate::band::NarrowBand;
use crate::error::{Error, Result};

impl<const D: usize> NarrowBand<D> {
    /// Removes the edges between the neighbouring nodes of each pair `(a, b)` (band positions,
    /// `b` a neighbour of `a` along some axis, in either order) from the neighbour table, both
    /// ways. Returns the number of edges removed (a pair given twice, or already cut, counts
    /// once). An error names the first pair that is not a pair of neighbours.
    pub fn cut_edges(&mut self, pairs: &[(usize, usize)]) -> Result<usize> {
        let len = self.len();
        let sentinel = len as u32;
        let per = 2 * (D - 1);
        let mut cut = 0;
        for (i, &(a, b)) in pairs.iter().enumerate() {
            if a >= len || b >= len {
                return Err(Error::invalid(
                    "pairs",
                    format!("pair {i} ({a}, {b}) is not a pair of band positions (the band has {len} nodes)"),
                ));
            }
            // along the last axis: the next or the previous node of the row, by a presence bit
            let (lo, hi) = (a.min(b), a.max(b));
            if hi == lo + 1 && self.along_row[lo] & 2 != 0 {
                self.along_row[lo] &= !2;
                self.along_row[hi] &= !1;
                cut += 1;
                continue;
            }
            // along a leading axis: a's entry that holds b, and b's opposite entry
            let found = (0..D - 1).find_map(|k| {
                (0..2).find_map(|side| (self.lead[a * per + 2 * k + side] == b as u32).then_some((k, side)))
            });
            match found {
                Some((k, side)) => {
                    self.lead[a * per + 2 * k + side] = sentinel;
                    self.lead[b * per + 2 * k + 1 - side] = sentinel;
                    cut += 1;
                }
                None if self.is_cut_pair(a, b) => {}
                None => {
                    return Err(Error::invalid(
                        "pairs",
                        format!("pair {i}: band nodes {a} and {b} are not neighbours"),
                    ))
                }
            }
        }
        Ok(cut)
    }

    /// Whether `a` and `b` are grid neighbours (their grid indices differ by one along one axis),
    /// whatever the table says: a pair cut before.
    fn is_cut_pair(&self, a: usize, b: usize) -> bool {
        let (ia, ib) = (self.index_of(a), self.index_of(b));
        let diff: usize = (0..D).map(|k| ia[k].abs_diff(ib[k])).sum();
        diff == 1
    }
}

#[cfg(test)]
mod tests {
    use crate::band::NarrowBand;

    fn full(n: usize) -> NarrowBand<3> {
        NarrowBand::<3>::full_box([n, n, n]).unwrap()
    }

    #[test]
    fn cut_edges_remove_both_directions_along_every_axis() {
        let mut band = full(4);
        let s = band.sentinel();
        let at = |i: usize, j: usize, k: usize| band.find([i as i64, j as i64, k as i64]).unwrap();
        let (a, x, y, z) = (at(1, 1, 1), at(2, 1, 1), at(1, 2, 1), at(1, 1, 2));
        let before = band.neighbours_of(a);
        assert_eq!(before[0][1] as usize, x);
        assert_eq!(before[1][1] as usize, y);
        assert_eq!(before[2][1] as usize, z);
        // given in either order; twice counts once
        assert_eq!(band.cut_edges(&[(a, x), (y, a), (a, z), (z, a)]).unwrap(), 3);
        let after = band.neighbours_of(a);
        assert_eq!([after[0][1], after[1][1], after[2][1]], [s, s, s]);
        assert_eq!(band.neighbours_of(x)[0][0], s);
        assert_eq!(band.neighbours_of(y)[1][0], s);
        assert_eq!(band.neighbours_of(z)[2][0], s);
        // the other entries are untouched
        assert_eq!(after[0][0], before[0][0]);
        assert_eq!(after[1][0], before[1][0]);
        assert_eq!(after[2][0], before[2][0]);
    }

    #[test]
    fn cut_edges_refuse_nodes_that_are_not_neighbours() {
        let mut band = full(4);
        let a = band.find([1, 1, 1]).unwrap();
        let far = band.find([3, 3, 3]).unwrap();
        let err = band.cut_edges(&[(a, far)]).unwrap_err().to_string();
        assert!(err.contains("not neighbours"), "{err}");
        let err = band.cut_edges(&[(a, 10_000)]).unwrap_err().to_string();
        assert!(err.contains("band positions"), "{err}");
    }
}
