//! Where the zero level set of a sampled φ lies, cell by cell: the cells it crosses (a sign change
//! among their corners), the points where it crosses their edges, and the nodes within a given
//! number of cells of them, for the re-distancing of `LevelSet(phi_array, redistance=True)`
//! ([`crate::surface::redistance_band`]).
//!
//! The interface is that of φ's multilinear interpolant (the [`SampledField`] the projection
//! uses): on a cell edge the interpolant is linear, so where the edge's end values differ in sign
//! (`φ > 0` against `φ ≤ 0`) it vanishes at the linear interpolation point, a point of the zero
//! level set known exactly whatever φ is (a 0/1 mask, a plateau, a φ far from a distance), with no
//! use of ∇φ. Every cell the interpolant's zero set passes through has such an edge.
//!
//! Only the crossed cells and the nodes near them are stored (the scan reads the samples once):
//! the nodes are kept as intervals along the grid's last axis, row by row, so that memory scales
//! with the band, plus one short list per row of the box's leading axes.

use crate::error::{Error, Result};
use rayon::prelude::*;

use super::redistance::{sum_of_squares, SampledField};

/// A 2D or 3D grid seen as 3D: a 2D grid `(n0, n1)` is the single slab `(1, n0, n1)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lattice {
    /// Nodes per axis (the first is 1 for a 2D grid).
    pub dims: [usize; 3],
    /// A 2D grid: its cells span no first axis.
    pub flat: bool,
}

impl Lattice {
    pub fn new(shape: &[usize]) -> Result<Self> {
        if !(shape.len() == 2 || shape.len() == 3) || shape.iter().any(|&n| n < 2) {
            return Err(Error::invalid(
                "phi",
                format!("must be a 2D or 3D array with at least 2 nodes per axis, got shape {shape:?}"),
            ));
        }
        let flat = shape.len() == 2;
        let dims = if flat {
            [1, shape[0], shape[1]]
        } else {
            [shape[0], shape[1], shape[2]]
        };
        Ok(Lattice { dims, flat })
    }

    /// The rows along the last axis: `dims[0] · dims[1]`.
    pub fn rows(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    /// `(i, j, k)` of a node's linear index.
    #[inline]
    pub fn split(&self, l: usize) -> (usize, usize, usize) {
        let row = l / self.dims[2];
        (row / self.dims[1], row % self.dims[1], l % self.dims[2])
    }

    /// The cells along the first axis whose lowest corner can be `i`: none beyond the first for
    /// a 2D grid.
    fn cell_slabs(&self) -> usize {
        if self.flat {
            1
        } else {
            self.dims[0] - 1
        }
    }

    /// The linear offsets of a cell's corners from its lowest one, corner `c` having bit `a` set
    /// for a step along axis `a` of the grid (`a = 0` the first), and their number (4 or 8).
    pub fn corner_offsets(&self) -> ([usize; 8], usize) {
        let strides = [self.dims[1] * self.dims[2], self.dims[2], 1];
        let axes: &[usize] = if self.flat { &[1, 2] } else { &[0, 1, 2] };
        let count = 1 << axes.len();
        let mut out = [0usize; 8];
        for (c, o) in out.iter_mut().enumerate().take(count) {
            *o = axes
                .iter()
                .enumerate()
                .filter(|(bit, _)| c >> bit & 1 == 1)
                .map(|(_, &a)| strides[a])
                .sum();
        }
        (out, count)
    }
}

/// Whether the corner values of a cell differ in sign (`φ > 0` against `φ ≤ 0`).
#[inline]
pub(crate) fn crosses(corners: &[f64]) -> bool {
    let positive = corners[0] > 0.0;
    corners[1..].iter().any(|&v| (v > 0.0) != positive)
}

/// The sorted linear indices of the lowest corners of the cells the zero level set crosses (a
/// sign change among the corners: [`crosses`]). One pass over the samples, on all threads: each
/// row of the grid's last axis becomes a bit set of its positive samples (`φ > 0`), and a row of
/// cells crosses where, over the 2 (2D) or 4 (3D) rows of its corners, its two columns of corners
/// hold both a positive and a non-positive sample (word-wide operations on the bit sets, 64 cells
/// at a time).
pub fn crossed_cells(shape: &[usize], samples: &[f64]) -> Result<Vec<u64>> {
    let lattice = Lattice::new(shape)?;
    if samples.len() != lattice.rows() * lattice.dims[2] {
        return Err(Error::invalid(
            "phi",
            format!(
                "expected {} samples for the shape {shape:?}, got {}",
                lattice.rows() * lattice.dims[2],
                samples.len()
            ),
        ));
    }
    let [_, n1, n2] = lattice.dims;
    let words = n2.div_ceil(64);
    // the positive samples of each row, bit k of word k / 64
    let mut positive = vec![0u64; lattice.rows() * words];
    positive
        .par_chunks_mut(words)
        .zip(samples.par_chunks(n2))
        .with_min_len(16)
        .for_each(|(bits, row)| {
            for (w, chunk) in bits.iter_mut().zip(row.chunks(64)) {
                let mut b = 0u64;
                for (k, &v) in chunk.iter().enumerate() {
                    b |= u64::from(v > 0.0) << k;
                }
                *w = b;
            }
        });
    // the cells along the last axis: k in 0..n2 − 1
    let valid = |w: usize| -> u64 {
        let cells = n2 - 1;
        let from = w * 64;
        if from + 64 <= cells {
            u64::MAX
        } else if from >= cells {
            0
        } else {
            (1u64 << (cells - from)) - 1
        }
    };
    let full = |w: usize| -> u64 {
        let from = w * 64;
        if from + 64 <= n2 {
            u64::MAX
        } else {
            (1u64 << (n2 - from)) - 1
        }
    };
    let corner_rows: &[(usize, usize)] = if lattice.flat {
        &[(0, 0), (0, 1)]
    } else {
        &[(0, 0), (0, 1), (1, 0), (1, 1)]
    };
    let cell_rows = lattice.cell_slabs() * (n1 - 1);
    let parts: Vec<Vec<u64>> = (0..cell_rows)
        .into_par_iter()
        .with_min_len(64)
        .map(|r| {
            let (i, j) = (r / (n1 - 1), r % (n1 - 1));
            let base = (i * n1 + j) * n2;
            // per column k: a positive corner (any), a non-positive corner (any)
            let column = |w: usize| -> (u64, u64) {
                if w >= words {
                    return (0, 0);
                }
                let (mut any_pos, mut all_pos) = (0u64, u64::MAX);
                for &(di, dj) in corner_rows {
                    let b = positive[((i + di) * n1 + j + dj) * words + w];
                    any_pos |= b;
                    all_pos &= b;
                }
                (any_pos, !all_pos & full(w))
            };
            let mut out = Vec::new();
            let mut next = column(0);
            for w in 0..words {
                let (p, q) = next;
                next = column(w + 1);
                // column k + 1 of bit k: the word shifted, the next word's first bit on top
                let p1 = (p >> 1) | (next.0 << 63);
                let q1 = (q >> 1) | (next.1 << 63);
                let mut crossing = (p | p1) & (q | q1) & valid(w);
                while crossing != 0 {
                    let k = w * 64 + crossing.trailing_zeros() as usize;
                    out.push((base + k) as u64);
                    crossing &= crossing - 1;
                }
            }
            out
        })
        .collect();
    Ok(parts.concat())
}

/// The points where the zero level set of `field`'s interpolant crosses the edges at the node
/// `node` (a D-index), a corner of a crossed cell, passed to `visit`: those on the node's own
/// edges (one step along an axis), or, where none of them crosses, those on the edges of the
/// crossed cells the node is a corner of ([`edge_crossings`]). A face neighbour on the zero level
/// set by rounding is passed too, marked `true` (see below), and so are the crossed cells' corners
/// on it where the node's own edges cross nowhere; the others `false`. Returned: whether a face
/// neighbour's |φ| is within [`ON_SURFACE`] of the node's, and whether the node's is of a
/// neighbour's (read here with the samples, for the caller's tests of nodes on the zero set).
#[inline]
pub(crate) fn crossings_at_corner<const D: usize>(
    field: &SampledField<'_, D>,
    node: [usize; D],
    mut visit: impl FnMut([f64; D], bool),
) -> NearZero {
    let mut near_zero = NearZero::default();
    let shape = field.shape();
    let here = field.sample(node);
    let mut own = false;
    for a in 0..D {
        for up in [false, true] {
            let mut other = node;
            if up {
                if node[a] + 1 >= shape[a] {
                    continue;
                }
                other[a] += 1;
            } else {
                if node[a] == 0 {
                    continue;
                }
                other[a] -= 1;
            }
            let sign = if up { 1.0 } else { -1.0 };
            let there = field.sample(other);
            near_zero.neighbour |= there.abs() <= ON_SURFACE * here.abs();
            near_zero.node |= here.abs() <= ON_SURFACE * there.abs();
            if let Some(q) = crossing_on_edge(field, node, here, there, a, sign) {
                visit(q, false);
                own = true;
            } else if there.abs() <= ON_SURFACE * here.abs()
                && (beside_other_sign(field, other, there) || at_rounding(field, other, there))
            {
                // a neighbour on the zero level set whose rounding left it on the node's side (a
                // box's exact distance, its edges on nodes, φ = +5.6e-17 there: no crossing on
                // the node's edges, and a node a spacing beyond an edge started from a face's
                // crossing √2 spacings away and stayed there, 0.41Δx too far at N = 61)
                visit(std::array::from_fn(|b| field.coordinate(b, other[b])), true);
            }
        }
    }
    if own {
        return near_zero;
    }
    for around in 0..1usize << D {
        let mut lowest = node;
        let mut inside = true;
        for a in 0..D {
            if around >> a & 1 == 1 {
                if lowest[a] == 0 {
                    inside = false;
                }
                lowest[a] = lowest[a].wrapping_sub(1);
            } else if lowest[a] + 1 >= shape[a] {
                inside = false;
            }
        }
        if inside {
            edge_crossings(field, lowest, here.abs(), &mut visit);
        }
    }
    near_zero
}

/// What [`crossings_at_corner`] read of the samples next to a node.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct NearZero {
    /// A face neighbour's |φ| is within [`ON_SURFACE`] of the node's.
    pub neighbour: bool,
    /// The node's |φ| is within [`ON_SURFACE`] of a face neighbour's.
    pub node: bool,
}

/// A sample whose |φ| is within this fraction of a neighbour's lies on the zero level set, for the
/// neighbour's crossings ([`crossings_at_corner`]): rounding of a φ that vanishes at the node.
pub(crate) const ON_SURFACE: f64 = 1e-6;

/// A node whose |φ| is within this many spacings times |∇φ| there (central differences with
/// step Δx/2) lies on the zero level set: rounding of a φ that vanishes there.
pub(crate) const AT_ROUNDING: f64 = 1e-12;

/// Whether φ = `value` at the node `node` is rounding's of zero ([`AT_ROUNDING`]): a box's edge
/// and corner nodes whose every face neighbour of the other sign lies diagonally (φ = +1e-17 on
/// all its surface's nodes: 128 nodes 0.5Δx too far at N = 121, a helper's review).
#[inline]
pub(crate) fn at_rounding<const D: usize>(field: &SampledField<'_, D>, node: [usize; D], value: f64) -> bool {
    let x: [f64; D] = std::array::from_fn(|a| field.coordinate(a, node[a]));
    let g = field.half_step_gradient(&x);
    value * value <= (AT_ROUNDING * field.spacing()).powi(2) * sum_of_squares(&g)
}

/// Whether the node `node` (φ = `value` there) has a face neighbour of the other sign: the zero
/// level set passes between them, and through the node where `value` is rounding's.
#[inline]
fn beside_other_sign<const D: usize>(field: &SampledField<'_, D>, node: [usize; D], value: f64) -> bool {
    let shape = field.shape();
    (0..D).any(|a| {
        [node[a].checked_sub(1), Some(node[a] + 1).filter(|&i| i < shape[a])]
            .into_iter()
            .flatten()
            .any(|i| {
                let mut near = node;
                near[a] = i;
                (field.sample(near) > 0.0) != (value > 0.0)
            })
    })
}

/// Where the interpolant's zero level set crosses the grid edge from `node` (φ = `value` there)
/// along `axis` in the direction `sign` (±1) to its neighbour (φ = `other`): the linear
/// interpolation of the two values, with no use of ∇φ; None where they have the same sign.
#[inline]
fn crossing_on_edge<const D: usize>(
    field: &SampledField<'_, D>,
    node: [usize; D],
    value: f64,
    other: f64,
    axis: usize,
    sign: f64,
) -> Option<[f64; D]> {
    if (value > 0.0) == (other > 0.0) {
        return None;
    }
    let t = value / (value - other);
    let mut q: [f64; D] = std::array::from_fn(|b| field.coordinate(b, node[b]));
    q[axis] += sign * t * field.spacing();
    Some(q)
}

/// The points where the zero level set of `field`'s interpolant crosses the edges of the cell
/// whose lowest corner is the node `lowest` (a D-index), passed to `visit` marked `false`; and
/// the cell's corners on the zero level set by rounding (|φ| within [`ON_SURFACE`] of `scale`, the
/// node's, and [`at_rounding`]), marked `true`: a box's corner node, diagonal to a node a spacing
/// beyond two of its faces, whose own edges cross nowhere (it started √3 spacings away, 0.32Δx too
/// far).
#[inline]
fn edge_crossings<const D: usize>(
    field: &SampledField<'_, D>,
    lowest: [usize; D],
    scale: f64,
    mut visit: impl FnMut([f64; D], bool),
) {
    let mut values = [0.0f64; 8];
    for (c, v) in values.iter_mut().enumerate().take(1 << D) {
        let mut node = lowest;
        for (a, n) in node.iter_mut().enumerate() {
            *n += c >> (D - 1 - a) & 1;
        }
        *v = field.sample(node);
    }
    if !crosses(&values[..1 << D]) {
        return;
    }
    for c in 0..1usize << D {
        let corner: [usize; D] = std::array::from_fn(|b| lowest[b] + (c >> (D - 1 - b) & 1));
        for a in 0..D {
            let bit = 1 << (D - 1 - a);
            if c & bit != 0 {
                continue;
            }
            if let Some(p) = crossing_on_edge(field, corner, values[c], values[c | bit], a, 1.0) {
                visit(p, false);
            }
        }
        if values[c].abs() <= ON_SURFACE * scale && at_rounding(field, corner, values[c]) {
            visit(std::array::from_fn(|b| field.coordinate(b, corner[b])), true);
        }
    }
}

/// The nodes within a number of cells of a set of cells, as intervals along the last axis.
#[derive(Debug, Clone)]
pub(crate) struct NodeSet {
    pub lattice: Lattice,
    /// The nodes' inclusive intervals `[a, b]` of `k`, row `(i, j)` after row, sorted and
    /// disjoint within a row, with the position of each interval's first node among all the set's
    /// nodes (C order): `(a, b, position)`.
    intervals: Vec<(u32, u32, usize)>,
    /// Per row, the index of its first interval in `intervals`; one more entry at the end.
    row_first: Vec<u32>,
}

/// Sorted, merged inclusive intervals (adjacent ones joined).
fn merged(mut v: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
    v.sort_unstable();
    let mut out: Vec<(u32, u32)> = Vec::with_capacity(v.len());
    for (a, b) in v {
        match out.last_mut() {
            Some(last) if a <= last.1.saturating_add(1) => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    out
}

impl NodeSet {
    /// The corners of the `cells` (sorted lowest-corner linear indices) and every node within
    /// `reach` nodes of one along each axis (the cells dilated by a cube): the nodes whose
    /// distance to the interface in these cells can be at most `reach · Δx`.
    pub fn around_cells(lattice: Lattice, cells: &[u64], reach: usize) -> NodeSet {
        let [n0, n1, n2] = lattice.dims;
        let r = reach;
        // along the last axis: the cell's two nodes and `reach` on each side
        let mut rows0: Vec<Vec<(u32, u32)>> = vec![Vec::new(); lattice.rows()];
        for &l in cells {
            let (i, j, k) = lattice.split(l as usize);
            let (a, b) = (k.saturating_sub(r), (k + 1 + r).min(n2 - 1));
            let row = &mut rows0[i * n1 + j];
            match row.last_mut() {
                Some(last) if a as u32 <= last.1 + 1 => last.1 = last.1.max(b as u32),
                _ => row.push((a as u32, b as u32)),
            }
        }
        // along an axis of the rows: node `m` gets the rows of the cells `m − 1 − reach ..= m + reach`
        let spread = |src: &Vec<Vec<(u32, u32)>>, axis: usize| -> Vec<Vec<(u32, u32)>> {
            (0..lattice.rows())
                .into_par_iter()
                .with_min_len(64)
                .map(|row| {
                    let (i, j) = (row / n1, row % n1);
                    let m = if axis == 0 { i } else { j };
                    let n = if axis == 0 { n0 } else { n1 };
                    let mut v = Vec::new();
                    for c in m.saturating_sub(1 + r)..=(m + r).min(n - 1) {
                        let from = if axis == 0 { c * n1 + j } else { i * n1 + c };
                        v.extend_from_slice(&src[from]);
                    }
                    if v.is_empty() {
                        v
                    } else {
                        merged(v)
                    }
                })
                .collect()
        };
        let mut rows = spread(&rows0, 1);
        drop(rows0);
        if !lattice.flat {
            rows = spread(&rows, 0);
        }
        let mut intervals = Vec::with_capacity(rows.iter().map(Vec::len).sum());
        let mut row_first = Vec::with_capacity(rows.len() + 1);
        let mut count = 0usize;
        for row in &rows {
            row_first.push(u32::try_from(intervals.len()).expect("fewer intervals than 2³²"));
            for &(a, b) in row {
                intervals.push((a, b, count));
                count += (b - a) as usize + 1;
            }
        }
        row_first.push(u32::try_from(intervals.len()).expect("fewer intervals than 2³²"));
        NodeSet {
            lattice,
            intervals,
            row_first,
        }
    }

    /// The number of nodes.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.intervals.last().map_or(0, |&(a, b, at)| at + (b - a) as usize + 1)
    }

    /// The intervals of row `row`.
    #[inline(always)]
    fn row(&self, row: usize) -> &[(u32, u32, usize)] {
        &self.intervals[self.row_first[row] as usize..self.row_first[row + 1] as usize]
    }

    /// The nodes' linear indices, sorted.
    #[cfg(test)]
    pub fn linear(&self) -> Vec<u64> {
        let n2 = self.lattice.dims[2];
        (0..self.row_first.len() - 1)
            .into_par_iter()
            .with_min_len(64)
            .flat_map_iter(|row| {
                self.row(row)
                    .iter()
                    .flat_map(move |&(a, b, _)| (a as usize..=b as usize).map(move |k| (row * n2 + k) as u64))
            })
            .collect()
    }

    /// The nodes' `(i, j, k)`, in the set's order (their positions): what [`Lattice::split`] gives
    /// of [`linear`](Self::linear)'s entries, without a division per node.
    pub fn coordinates(&self) -> Vec<[u32; 3]> {
        let n1 = self.lattice.dims[1];
        (0..self.row_first.len() - 1)
            .into_par_iter()
            .with_min_len(64)
            .flat_map_iter(|row| {
                let (i, j) = ((row / n1) as u32, (row % n1) as u32);
                self.row(row)
                    .iter()
                    .flat_map(move |&(a, b, _)| (a..=b).map(move |k| [i, j, k]))
            })
            .collect()
    }

    /// The position among the set's nodes of node `(i, j, k)`, if it is one.
    #[inline]
    pub fn position(&self, i: usize, j: usize, k: usize) -> Option<usize> {
        let k = k as u32;
        for &(a, b, at) in self.row(i * self.lattice.dims[1] + j) {
            if k < a {
                return None;
            }
            if k <= b {
                return Some(at + (k - a) as usize);
            }
        }
        None
    }

    /// [`face_neighbours`](Self::face_neighbours) when `wanted`, else nothing.
    #[inline]
    pub fn face_neighbours_if(&self, wanted: bool, node: (usize, usize, usize), visit: impl FnMut(usize)) {
        if wanted {
            self.face_neighbours(node, visit);
        }
    }

    /// The positions in the set of the nodes `k − 1`, `k`, `k + 1` of row `(i, j)` (None where a node
    /// is not in the set or beyond the row's ends), in one pass over the row's intervals.
    #[inline]
    fn positions_around(&self, i: usize, j: usize, k: usize) -> [Option<usize>; 3] {
        let mut out = [None; 3];
        let (lo, hi) = (k.saturating_sub(1) as u32, (k + 1) as u32);
        for &(a, b, at) in self.row(i * self.lattice.dims[1] + j) {
            if b < lo {
                continue;
            }
            if a <= lo && hi <= b && k > 0 {
                // the three in one interval (most rows)
                let first = at + (lo - a) as usize;
                return [Some(first), Some(first + 1), Some(first + 2)];
            }
            if a > hi {
                break;
            }
            if b >= lo {
                for m in a.max(lo)..=b.min(hi) {
                    out[(m + 1 - k as u32) as usize] = Some(at + (m - a) as usize);
                }
            }
        }
        if k == 0 {
            out[0] = None;
        }
        out
    }

    /// The positions in the set of the nodes around node `(i, j, k)` (one step or none along each
    /// axis, the node itself left out: 8 in 2D, 26 in 3D), passed to `visit`.
    #[inline]
    pub fn neighbours_around(&self, (i, j, k): (usize, usize, usize), mut visit: impl FnMut(usize)) {
        let [n0, n1, _] = self.lattice.dims;
        for a in i.saturating_sub(1)..=(i + 1).min(n0 - 1) {
            for b in j.saturating_sub(1)..=(j + 1).min(n1 - 1) {
                let centre_row = a == i && b == j;
                for (c, p) in self.positions_around(a, b, k).into_iter().enumerate() {
                    if let Some(p) = p {
                        if !(centre_row && c == 1) {
                            visit(p);
                        }
                    }
                }
            }
        }
    }

    /// The positions of the face neighbours of node `(i, j, k)` in the set, passed to `visit`.
    #[inline]
    pub fn face_neighbours(&self, (i, j, k): (usize, usize, usize), mut visit: impl FnMut(usize)) {
        let [n0, n1, n2] = self.lattice.dims;
        let mut try_node = |i: usize, j: usize, k: usize| {
            if let Some(p) = self.position(i, j, k) {
                visit(p);
            }
        };
        if i > 0 {
            try_node(i - 1, j, k);
        }
        if i + 1 < n0 {
            try_node(i + 1, j, k);
        }
        if j > 0 {
            try_node(i, j - 1, k);
        }
        if j + 1 < n1 {
            try_node(i, j + 1, k);
        }
        if k > 0 {
            try_node(i, j, k - 1);
        }
        if k + 1 < n2 {
            try_node(i, j, k + 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossed_cells_and_the_nodes_around_them_are_those_a_brute_force_finds() {
        // a sphere's |x|² − r² on an uneven 3D grid and a circle's on a 2D one
        for shape in [vec![13usize, 11, 9], vec![17, 14]] {
            let d = shape.len();
            let total: usize = shape.iter().product();
            let idx = |mut l: usize| {
                let mut m = vec![0usize; d];
                for a in (0..d).rev() {
                    m[a] = l % shape[a];
                    l /= shape[a];
                }
                m
            };
            let samples: Vec<f64> = (0..total)
                .map(|l| {
                    idx(l)
                        .iter()
                        .zip(&shape)
                        .map(|(&m, &n)| (m as f64 - 0.45 * n as f64).powi(2))
                        .sum::<f64>()
                        - 9.0
                })
                .collect();
            let cells = crossed_cells(&shape, &samples).unwrap();
            let lattice = Lattice::new(&shape).unwrap();
            let (offsets, count) = lattice.corner_offsets();
            let brute: Vec<u64> = (0..total)
                .filter(|&l| {
                    let m = idx(l);
                    m.iter().zip(&shape).all(|(&m, &n)| m + 1 < n)
                        && crosses(&offsets[..count].iter().map(|&o| samples[l + o]).collect::<Vec<_>>())
                })
                .map(|l| l as u64)
                .collect();
            assert!(!cells.is_empty());
            assert_eq!(cells, brute);
            for reach in [0usize, 2] {
                let set = NodeSet::around_cells(lattice, &cells, reach);
                let near: Vec<u64> = (0..total)
                    .filter(|&l| {
                        let m = idx(l);
                        cells.iter().any(|&c| {
                            let cm = idx(c as usize);
                            m.iter().zip(&cm).all(|(&a, &b)| a + reach >= b && a <= b + 1 + reach)
                        })
                    })
                    .map(|l| l as u64)
                    .collect();
                let linear = set.linear();
                assert_eq!(linear, near, "reach {reach}");
                for (p, &l) in linear.iter().enumerate() {
                    let (i, j, k) = lattice.split(l as usize);
                    assert_eq!(set.position(i, j, k), Some(p));
                }
                assert_eq!(set.len(), linear.len());
                // the nodes around each node, against position() one by one
                for &l in linear.iter().step_by(7) {
                    let (i, j, k) = lattice.split(l as usize);
                    let mut got = Vec::new();
                    set.neighbours_around((i, j, k), |p| got.push(p));
                    let mut want = Vec::new();
                    for a in i.saturating_sub(1)..=(i + 1).min(lattice.dims[0] - 1) {
                        for b in j.saturating_sub(1)..=(j + 1).min(lattice.dims[1] - 1) {
                            for c in k.saturating_sub(1)..=(k + 1).min(lattice.dims[2] - 1) {
                                if (a, b, c) != (i, j, k) {
                                    want.extend(set.position(a, b, c));
                                }
                            }
                        }
                    }
                    got.sort_unstable();
                    want.sort_unstable();
                    assert_eq!(got, want);
                }
            }
        }
        // rows longer than a word of the bit sets: an oscillating φ crosses at every word boundary
        for shape in [vec![4usize, 5, 200], vec![6, 129], vec![3, 3, 65], vec![2, 64]] {
            let total: usize = shape.iter().product();
            let samples: Vec<f64> = (0..total)
                .map(|l| {
                    let k = l % shape[shape.len() - 1];
                    let row = l / shape[shape.len() - 1];
                    (0.37 * k as f64 + 1.3 * row as f64).sin() + if k % 7 == 0 { 0.0 } else { 0.1 }
                })
                .collect();
            let lattice = Lattice::new(&shape).unwrap();
            let (offsets, count) = lattice.corner_offsets();
            let [_, n1, n2] = lattice.dims;
            let brute: Vec<u64> = (0..total)
                .filter(|&l| {
                    let (i, j, k) = lattice.split(l);
                    (lattice.flat || i + 1 < lattice.dims[0])
                        && j + 1 < n1
                        && k + 1 < n2
                        && crosses(&offsets[..count].iter().map(|&o| samples[l + o]).collect::<Vec<_>>())
                })
                .map(|l| l as u64)
                .collect();
            assert!(brute.len() > 10);
            assert_eq!(crossed_cells(&shape, &samples).unwrap(), brute, "{shape:?}");
        }
        assert!(crossed_cells(&[4, 4, 4], &[1.0; 63]).is_err());
        assert!(crossed_cells(&[4], &[1.0; 4]).is_err());
        assert!(crossed_cells(&[4, 4], &[1.0; 16]).unwrap().is_empty());
    }
}
