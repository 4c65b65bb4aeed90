//! The narrow band: the grid nodes of the computational tube (inner tube and extension layer,
//! paper Fig. 4), stored sparsely so that memory and work scale with the tube, O(N^(d−1)) nodes,
//! not with the box, O(N^d).
//!
//! Layout (chosen for the sweeping kernel):
//! * nodes are sorted in C order of their grid index (the last axis varies fastest), so that a
//!   grid *row* (all nodes sharing every index but the last) is a contiguous slice;
//! * rows are identified by the linear index of their leading coordinates (`row_keys`, sorted);
//! * each node has a precomputed neighbour table, two entries (minus, plus) per axis, holding the
//!   neighbour's position in the band or the sentinel `len()` when the neighbour is not in the
//!   band (the solver stores the numerical infinity in an extra slot at that position). Only the
//!   leading axes are stored as positions; along the last axis the neighbours are the next and
//!   previous node of the row, so two presence bits say whether they are there
//!   ([`NarrowBand::neighbours_of`]);
//! * for each of the 2^(d−1) orientations of the leading axes, a permutation of the rows gives the
//!   Gauss–Seidel sweep order; the last axis is reversed by walking a row backwards.
//!
//! Cost per band node: 4 bytes of last-axis coordinate and 8·(d − 1) + 1 bytes of neighbour table
//! (17 in 3D).

use crate::band::schedule::{SweepSchedule, LONG_SIDE, THIN_SIDE};
use crate::error::try_filled;
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::sync::OnceLock;

/// The band nodes and their neighbour table. `D` is the dimension (2 or 3).
#[derive(Debug, Clone)]
pub struct NarrowBand<const D: usize> {
    shape: [usize; D],
    row_keys: Vec<u64>,
    row_start: Vec<u32>,
    last: Vec<u32>,
    /// Per node, `2 (D − 1)` entries: the minus and plus neighbours along each leading axis.
    pub(super) lead: Vec<u32>,
    /// Per node: bit 0 set when the previous node of the row is its minus neighbour along the last
    /// axis, bit 1 when the next node is its plus neighbour.
    pub(super) along_row: Vec<u8>,
    schedule: SweepSchedule,
    /// 3D only: the parallel sweeps' schedules of rectangular tiles, strips thin along the first
    /// leading axis (`[0]`) and along the second (`[1]`) (see [`crate::band::schedule`]); built at the
    /// first parallel solve, so that a band only ever swept on one thread does not hold them.
    strip_schedules: OnceLock<[SweepSchedule; 2]>,
}

/// A borrowed view of a band's neighbour table: the arrays' addresses and the sentinel. The sweep
/// kernel copies it once per row, so that the table's addresses stay in registers instead of
/// being loaded from the band again at every node after each write of a value
/// (docs/development/performance-history.md, "The kernel's arrays in registers").
#[derive(Clone, Copy)]
pub struct NeighbourTable<'a, const D: usize> {
    lead: &'a [u32],
    along_row: &'a [u8],
    sentinel: u32,
}

impl<const D: usize> NeighbourTable<'_, D> {
    /// [`NarrowBand::sentinel`].
    #[inline(always)]
    pub fn sentinel(&self) -> u32 {
        self.sentinel
    }

    /// The neighbours of node `n` ([`NarrowBand::neighbours_of`]), without the bounds check.
    ///
    /// # Safety
    /// `n` is a node of the band.
    #[inline(always)]
    pub unsafe fn neighbours_of_unchecked(&self, n: usize) -> [[u32; 2]; D] {
        debug_assert!(n < self.sentinel as usize);
        let sentinel = self.sentinel;
        let mut nb = [[sentinel; 2]; D];
        let base = n * 2 * (D - 1);
        for k in 0..D - 1 {
            nb[k][0] = *self.lead.get_unchecked(base + 2 * k);
            nb[k][1] = *self.lead.get_unchecked(base + 2 * k + 1);
        }
        let bits = *self.along_row.get_unchecked(n);
        if bits & 1 != 0 {
            nb[D - 1][0] = n as u32 - 1;
        }
        if bits & 2 != 0 {
            nb[D - 1][1] = n as u32 + 1;
        }
        nb
    }

    /// One entry of [`Self::neighbours_of_unchecked`]: the neighbour of node `n` along `axis` on
    /// `side` (0: minus, 1: plus), or the sentinel, without building the other entries (along the
    /// last axis a presence bit and n ± 1).
    ///
    /// # Safety
    /// `n` is a node of the band, `axis < D`, `side < 2`.
    #[inline(always)]
    pub unsafe fn neighbour_unchecked(&self, n: usize, axis: usize, side: usize) -> u32 {
        debug_assert!(n < self.sentinel as usize && axis < D && side < 2);
        if axis + 1 < D {
            *self.lead.get_unchecked(n * 2 * (D - 1) + 2 * axis + side)
        } else if (*self.along_row.get_unchecked(n) >> side) & 1 != 0 {
            (n + 2 * side).wrapping_sub(1) as u32
        } else {
            self.sentinel
        }
    }
}

impl<const D: usize> NarrowBand<D> {
    /// Builds the band from the C-order linear indices of its nodes, which must be strictly
    /// increasing (sorted, no duplicates) and inside the grid of shape `shape`.
    pub fn from_sorted_linear(shape: [usize; D], linear: &[u64]) -> Result<Self> {
        let total = check_shape(&shape)?;
        if linear.len() >= u32::MAX as usize {
            return Err(Error::invalid(
                "indices",
                format!(
                    "the band has {} nodes; at most {} are supported",
                    linear.len(),
                    u32::MAX - 1
                ),
            ));
        }
        for w in linear.windows(2) {
            if w[0] >= w[1] {
                return Err(Error::invalid(
                    "indices",
                    "band nodes must be sorted in C order without duplicates",
                ));
            }
        }
        if let Some(&l) = linear.last() {
            if l >= total {
                return Err(Error::invalid("indices", "a band node lies outside the grid"));
            }
        }
        let n_last = shape[D - 1] as u64;
        let mut row_keys = Vec::new();
        let mut row_start = Vec::new();
        let mut last = Vec::with_capacity(linear.len());
        // one division per row, not per node: the nodes of a row are consecutive
        let mut row_begin = 0u64; // the linear index of the current row's first grid node
        for (pos, &l) in linear.iter().enumerate() {
            if row_keys.is_empty() || l >= row_begin + n_last {
                let key = l / n_last;
                row_begin = key * n_last;
                row_keys.push(key);
                row_start.push(pos as u32);
            }
            last.push((l - row_begin) as u32);
        }
        row_start.push(linear.len() as u32);
        Self::assemble(shape, row_keys, row_start, last)
    }

    /// The whole box as a band (used by the Euclidean solver of Sect. 2).
    pub fn full_box(shape: [usize; D]) -> Result<Self> {
        let total = check_shape(&shape)?;
        if total >= u32::MAX as u64 {
            return Err(Error::invalid(
                "grid",
                format!("the grid has {total} nodes; at most {} are supported", u32::MAX - 1),
            ));
        }
        let total = total as usize;
        let n_last = shape[D - 1];
        let n_rows = total / n_last;
        // sized by the shape alone: allocated fallibly (an Err, not an abort, when it does not fit)
        let mut row_keys = try_filled("the box's band", n_rows, 0u64)?;
        row_keys.iter_mut().enumerate().for_each(|(r, k)| *k = r as u64);
        let mut row_start = try_filled("the box's band", n_rows + 1, 0u32)?;
        row_start
            .iter_mut()
            .enumerate()
            .for_each(|(r, s)| *s = (r * n_last) as u32);
        let mut last = try_filled("the box's band", total, 0u32)?;
        last.iter_mut().enumerate().for_each(|(p, l)| *l = (p % n_last) as u32);
        Self::assemble(shape, row_keys, row_start, last)
    }

    fn assemble(shape: [usize; D], row_keys: Vec<u64>, row_start: Vec<u32>, last: Vec<u32>) -> Result<Self> {
        let len = last.len();
        // the neighbour table and the flags: allocated fallibly (an Err, not an abort)
        let lead = try_filled("the band's neighbour table", len * 2 * (D - 1), len as u32)?;
        let along_row = try_filled("the band's neighbour table", len, 0)?;
        let mut band = NarrowBand {
            shape,
            row_keys,
            row_start,
            last,
            lead,
            along_row,
            schedule: SweepSchedule::default(),
            strip_schedules: OnceLock::new(),
        };
        band.build_neighbours();
        band.schedule = SweepSchedule::new(&band.row_leads(), band.shape);
        Ok(band)
    }

    /// Number of band nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.last.len()
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.last.is_empty()
    }

    /// The sentinel neighbour index meaning "not in the band".
    #[inline]
    pub fn sentinel(&self) -> u32 {
        self.len() as u32
    }

    pub fn shape(&self) -> [usize; D] {
        self.shape
    }

    pub fn n_rows(&self) -> usize {
        self.row_keys.len()
    }

    /// The neighbours of node `n`: `[k] = [minus, plus]` along axis `k`, each a band position or
    /// [`sentinel`](Self::sentinel). Panics if `n` is not a node.
    #[inline]
    pub fn neighbours_of(&self, n: usize) -> [[u32; 2]; D] {
        assert!(n < self.len(), "node {n} is not in the band of {} nodes", self.len());
        // SAFETY: checked just above
        unsafe { self.neighbours_of_unchecked(n) }
    }

    /// [`neighbours_of`](Self::neighbours_of) without the bounds check.
    ///
    /// # Safety
    /// `n < self.len()`.
    #[inline(always)]
    pub unsafe fn neighbours_of_unchecked(&self, n: usize) -> [[u32; 2]; D] {
        self.neighbour_table().neighbours_of_unchecked(n)
    }

    /// The neighbour table as a small copyable view, which the sweep kernel copies once per row
    /// into locals (see [`NeighbourTable`]).
    #[inline(always)]
    pub fn neighbour_table(&self) -> NeighbourTable<'_, D> {
        NeighbourTable {
            lead: &self.lead,
            along_row: &self.along_row,
            sentinel: self.last.len() as u32,
        }
    }

    /// Asks the processor to fetch the neighbour-table entries of node `n` into cache ahead of
    /// [`neighbours_of`](Self::neighbours_of); a hint only (nothing happens for `n` out of range
    /// or on other architectures than x86-64). Pays where nodes are visited out of memory order,
    /// as in a breadth-first search.
    #[inline(always)]
    pub fn prefetch_neighbours(&self, n: usize) {
        self.prefetch_neighbour_range(n, n + 1);
    }

    /// The bytes of the neighbour table per node: two `u32` per leading axis and a byte of
    /// presence bits along the rows.
    pub const fn neighbour_table_bytes_per_node(&self) -> usize {
        2 * (D - 1) * std::mem::size_of::<u32>() + std::mem::size_of::<u8>()
    }

    /// The same hint for the neighbour-table entries of the nodes `start..end` (a row's, in the
    /// sweeps: [`crate::sweep`]'s row prefetch).
    #[inline(always)]
    pub fn prefetch_neighbour_range(&self, start: usize, end: usize) {
        crate::prefetch::prefetch_range(&self.lead, start * 2 * (D - 1), end * 2 * (D - 1));
        crate::prefetch::prefetch_range(&self.along_row, start, end);
    }

    /// Node range `[start, end)` of row `r`.
    #[inline]
    pub fn row_range(&self, r: usize) -> (usize, usize) {
        (self.row_start[r] as usize, self.row_start[r + 1] as usize)
    }

    /// Row visiting order for the orientation `signs` of the leading `D − 1` axes (bit `k` set =
    /// axis `k` walked backwards), grouped in tiles and waves (see [`SweepSchedule`]).
    #[inline]
    pub fn row_order(&self, signs: usize) -> &[u32] {
        self.schedule.rows(signs)
    }

    /// The sequential sweep's schedule (square tiles).
    #[inline]
    pub fn schedule(&self) -> &SweepSchedule {
        &self.schedule
    }

    /// 3D: the parallel sweeps' schedule with strips thin along leading axis `axis` (0 or 1),
    /// built at the first call. Panics on a 2D band, whose sweeps run sequentially.
    pub fn strip_schedule(&self, axis: usize) -> &SweepSchedule {
        assert!(D == 3, "only a 3D band has strips of tiles");
        &self.strip_schedules.get_or_init(|| {
            let leads = self.row_leads();
            let build = |sides, strip_axis| SweepSchedule::with_tile_sides(&leads, self.shape, sides, strip_axis);
            [build([THIN_SIDE, LONG_SIDE], 0), build([LONG_SIDE, THIN_SIDE], 1)]
        })[axis]
    }

    /// The leading indices of every row.
    fn row_leads(&self) -> Vec<[usize; D]> {
        (0..self.n_rows()).map(|r| self.row_lead(r)).collect()
    }

    /// The first two grid indices of row `r`'s nodes (3D: the row's place in the plane of the
    /// leading axes).
    #[inline]
    pub fn row_leading_indices(&self, r: usize) -> [usize; 2] {
        let lead = self.row_lead(r);
        [lead[0], if D > 2 { lead[1] } else { 0 }]
    }

    /// The grid index of band node `n`.
    pub fn index_of(&self, n: usize) -> [usize; D] {
        let r = match self.row_start.binary_search(&(n as u32)) {
            Ok(mut r) => {
                // empty rows do not exist, but be safe with equal starts
                while r + 1 < self.row_start.len() && self.row_start[r + 1] as usize == n {
                    r += 1;
                }
                r
            }
            Err(r) => r - 1,
        };
        let mut idx = [0usize; D];
        let mut key = self.row_keys[r] as usize;
        for k in (0..D - 1).rev() {
            idx[k] = key % self.shape[k];
            key /= self.shape[k];
        }
        idx[D - 1] = self.last[n] as usize;
        idx
    }

    /// The C-order linear grid index of every node, in band order (strictly increasing).
    pub fn linear_indices(&self) -> Vec<u64> {
        let last_len = self.shape[D - 1] as u64;
        let mut out = Vec::with_capacity(self.len());
        for r in 0..self.n_rows() {
            let base = self.row_keys[r] * last_len;
            let (s, e) = self.row_range(r);
            out.extend(self.last[s..e].iter().map(|&c| base + c as u64));
        }
        out
    }

    /// All grid indices, in band order.
    pub fn indices(&self) -> Vec<[usize; D]> {
        let mut out = Vec::with_capacity(self.len());
        for r in 0..self.n_rows() {
            let mut key = self.row_keys[r] as usize;
            let mut lead = [0usize; D];
            for k in (0..D - 1).rev() {
                lead[k] = key % self.shape[k];
                key /= self.shape[k];
            }
            let (s, e) = self.row_range(r);
            for n in s..e {
                let mut idx = lead;
                idx[D - 1] = self.last[n] as usize;
                out.push(idx);
            }
        }
        out
    }

    /// Position of the node with grid index `idx` in the band, if it is a band node.
    #[inline]
    pub fn find(&self, idx: [i64; D]) -> Option<usize> {
        let mut key: u64 = 0;
        for k in 0..D - 1 {
            if idx[k] < 0 || idx[k] as usize >= self.shape[k] {
                return None;
            }
            key = key * self.shape[k] as u64 + idx[k] as u64;
        }
        let l = idx[D - 1];
        if l < 0 || l as usize >= self.shape[D - 1] {
            return None;
        }
        let r = self.row_keys.binary_search(&key).ok()?;
        let (s, e) = self.row_range(r);
        self.last[s..e].binary_search(&(l as u32)).ok().map(|p| s + p)
    }

    /// The rows next to each row along the leading axes: `2 (D − 1)` entries per row, the minus
    /// and plus neighbour row along each leading axis, [`n_rows`](Self::n_rows) where there is
    /// none. A node's neighbours along the leading axes lie in these rows (its neighbours along
    /// the last axis in its own row). One merge pass over the sorted row keys per direction.
    pub fn row_neighbours(&self) -> Vec<u32> {
        let rows = self.n_rows();
        let per = 2 * (D - 1);
        let mut out = vec![rows as u32; rows * per];
        let mut stride = 1u64;
        for k in (0..D - 1).rev() {
            // the lead coordinate k of a row key is (key / stride) % shape[k]
            let extent = self.shape[k] as u64;
            // plus neighbours: key + stride, searched with a pointer that only moves forward
            let mut q = 0usize;
            for r in 0..rows {
                let key = self.row_keys[r];
                if (key / stride) % extent + 1 >= extent {
                    continue;
                }
                let want = key + stride;
                while q < rows && self.row_keys[q] < want {
                    q += 1;
                }
                if q < rows && self.row_keys[q] == want {
                    out[r * per + 2 * k + 1] = q as u32;
                    out[q * per + 2 * k] = r as u32;
                }
            }
            stride *= extent;
        }
        out
    }

    fn row_lead(&self, r: usize) -> [usize; D] {
        let mut key = self.row_keys[r] as usize;
        let mut lead = [0usize; D];
        for k in (0..D - 1).rev() {
            lead[k] = key % self.shape[k];
            key /= self.shape[k];
        }
        lead
    }

    fn build_neighbours(&mut self) {
        let len = self.len() as u32;
        // strides of the leading axes in row-key space
        let mut stride = [0u64; D];
        let mut s = 1u64;
        for k in (0..D - 1).rev() {
            stride[k] = s;
            s *= self.shape[k] as u64;
        }
        // split the tables into one mutable slice per row
        let per = 2 * (D - 1);
        let mut slices: Vec<(&mut [u32], &mut [u8])> = Vec::with_capacity(self.n_rows());
        let mut rest: &mut [u32] = &mut self.lead;
        let mut rest_row: &mut [u8] = &mut self.along_row;
        for r in 0..self.row_keys.len() {
            let n = (self.row_start[r + 1] - self.row_start[r]) as usize;
            let (head, tail) = rest.split_at_mut(n * per);
            let (head_row, tail_row) = rest_row.split_at_mut(n);
            slices.push((head, head_row));
            rest = tail;
            rest_row = tail_row;
        }
        let row_keys = &self.row_keys;
        let row_start = &self.row_start;
        let last = &self.last;
        let shape = self.shape;
        slices.into_par_iter().enumerate().for_each(|(r, (out, out_row))| {
            let s = row_start[r] as usize;
            let e = row_start[r + 1] as usize;
            // last axis: consecutive nodes in the row
            for n in s..e {
                let mut bits = 0u8;
                if n > s && last[n - 1] + 1 == last[n] {
                    bits |= 1;
                }
                if n + 1 < e && last[n + 1] == last[n] + 1 {
                    bits |= 2;
                }
                out_row[n - s] = bits;
            }
            // leading axes: merge with the neighbouring rows
            let mut key = row_keys[r];
            let mut lead = [0usize; D];
            for k in (0..D - 1).rev() {
                lead[k] = (key % shape[k] as u64) as usize;
                key /= shape[k] as u64;
            }
            for k in 0..D - 1 {
                for side in 0..2 {
                    let target = if side == 0 {
                        if lead[k] == 0 {
                            continue;
                        }
                        row_keys[r] - stride[k]
                    } else {
                        if lead[k] + 1 >= shape[k] {
                            continue;
                        }
                        row_keys[r] + stride[k]
                    };
                    let Ok(rr) = row_keys.binary_search(&target) else {
                        continue;
                    };
                    let (ts, te) = (row_start[rr] as usize, row_start[rr + 1] as usize);
                    let mut t = ts;
                    for n in s..e {
                        while t < te && last[t] < last[n] {
                            t += 1;
                        }
                        if t < te && last[t] == last[n] {
                            out[(n - s) * per + 2 * k + side] = t as u32;
                        }
                    }
                }
            }
        });
        debug_assert!(self.lead.iter().all(|&p| p <= len));
    }

    /// Bytes held by this structure (for memory reports).
    pub fn heap_bytes(&self) -> usize {
        self.row_keys.len() * 8
            + self.row_start.len() * 4
            + self.last.len() * 4
            + self.lead.len() * 4
            + self.along_row.len()
            + self.schedule.heap_bytes()
            + self
                .strip_schedules
                .get()
                .map_or(0, |s| s.iter().map(SweepSchedule::heap_bytes).sum())
    }
}

/// Checks the shape and returns the number of grid nodes, which must be below 2^63 (the linear
/// indices are 64-bit, signed in NumPy): computed with checked arithmetic, so that a shape whose
/// product overflows is refused instead of wrapping.
fn check_shape<const D: usize>(shape: &[usize; D]) -> Result<u64> {
    if !(2..=3).contains(&D) {
        return Err(Error::invalid(
            "grid",
            format!("only 2D and 3D grids are supported, got {D}D"),
        ));
    }
    for (k, &n) in shape.iter().enumerate() {
        if n < 3 {
            return Err(Error::invalid(
                "shape",
                format!("axis {k} has {n} nodes; at least 3 are needed"),
            ));
        }
    }
    match shape.iter().try_fold(1u64, |p, &n| p.checked_mul(n as u64)) {
        Some(total) if total <= i64::MAX as u64 => Ok(total),
        _ => Err(Error::invalid(
            "shape",
            format!("the grid {shape:?} has 2^63 nodes or more; at most 2^63 - 1 are supported"),
        )),
    }
}

impl<const D: usize> NarrowBand<D> {
    /// Band positions of the selected nodes that lack a neighbour which lies inside the grid but
    /// not in the band. For the two-layer method every inner-tube node must have all its in-grid
    /// neighbours in the band (the extension layer must enclose the inner tube).
    pub fn nodes_missing_neighbours(&self, select: &[bool]) -> Vec<usize> {
        let sentinel = self.sentinel();
        let mut out = Vec::new();
        for r in 0..self.n_rows() {
            let lead = self.row_lead(r);
            let (s, e) = self.row_range(r);
            for n in s..e {
                if !select[n] {
                    continue;
                }
                let mut idx = lead;
                idx[D - 1] = self.last[n] as usize;
                let nb = self.neighbours_of(n);
                let missing = (0..D).any(|k| {
                    (nb[k][0] == sentinel && idx[k] > 0) || (nb[k][1] == sentinel && idx[k] + 1 < self.shape[k])
                });
                if missing {
                    out.push(n);
                }
            }
        }
        out
    }
}

#[cfg(test)]
#[path = "narrow_band_tests.rs"]
mod tests;
