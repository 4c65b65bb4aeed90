//! The order in which a sweep visits the band's rows, arranged so that sweeps run in parallel and
//! still give *bit-identical* results to the sequential Gauss–Seidel sweep.
//!
//! A row (all nodes sharing the leading `d − 1` indices) reads only its own nodes and the nodes
//! of the rows next to it along each leading axis. In the sequential lexicographic sweep of a
//! given orientation, row `r` is processed after its "lower" neighbour rows and before its
//! "upper" ones. Group the rows into square *tiles* of `TILE` × `TILE` rows (in the sweep's
//! orientation) and the tiles into *waves* by the sum of their tile coordinates: tiles of one
//! wave never touch each other, every lower neighbour of a row lies in its own tile (earlier in
//! lexicographic order) or in an earlier wave, and every upper neighbour in its own tile (later)
//! or a later wave. Processing the waves in order, the tiles of a wave in parallel and the rows
//! of a tile lexicographically therefore reads exactly the same neighbour values as the
//! sequential sweep (a 2D band has one leading axis: its waves hold one tile, it runs
//! sequentially).
//!
//! The same dependencies can also be met without a barrier after every wave. In 3D, call the
//! tiles with the same first tile coordinate `a` a *strip*, ordered by the second coordinate
//! `b`. Tile `(a, b)` may run as soon as `(a − 1, b)` (the previous strip) and `(a, b − 1)` (its
//! own strip, earlier) are done: then every lower neighbour is final, and no upper neighbour can
//! have started, since `(a + 1, b)` waits for `(a, b)` and `(a, b + 1)` follows it in its strip.
//! Two tiles that run at the same time are never face neighbours. Threads take whole strips in
//! order and wait for the one tile of the previous strip they depend on (a pipelined
//! wavefront): one synchronisation per tile instead of a barrier per wave, the same values.
//!
//! Nothing in that argument needs square tiles. The parallel sweeps use two schedules of
//! rectangular tiles, [`THIN_SIDE`] rows along one leading axis and [`LONG_SIDE`] along the
//! other, and pick one per iteration: the strips thin along the axis in which the iteration's
//! work is concentrated (a front crossing that axis), so that more strips share it
//! (docs/development/performance-history.md, "Strips thin across the front"). The values stay those of the
//! sequential sweep whichever is picked.

use rayon::prelude::*;

/// Leading-axis rows per tile side of the square tiles (the sequential sweep and 2D bands).
pub const TILE: usize = 8;

/// Rows along the thin side of the parallel sweeps' rectangular tiles (the thickness of a strip).
pub const THIN_SIDE: usize = 2;

/// Rows along the long side of the parallel sweeps' rectangular tiles.
pub const LONG_SIDE: usize = 16;

/// The wave/tile/row order for each orientation of the leading axes.
#[derive(Debug, Clone, Default)]
pub struct SweepSchedule {
    /// Per orientation: rows in processing order.
    rows: Vec<Vec<u32>>,
    /// Per orientation: boundaries of the tiles in `rows` (one more than the tiles).
    tiles: Vec<Vec<u32>>,
    /// Per orientation: boundaries of the waves in `tiles` (one more than the waves).
    waves: Vec<Vec<u32>>,
    /// Per orientation: the tiles (indices into [`tiles`](Self::tiles)) strip by strip, each strip
    /// in the order of its second tile coordinate (empty unless there are two leading axes).
    strip_tiles: Vec<Vec<u32>>,
    /// Per orientation: boundaries of the strips in `strip_tiles` (one more than the strips).
    strips: Vec<Vec<u32>>,
    /// Per orientation and tile: the tile of the previous strip it waits for, or [`NO_TILE`].
    upstream: Vec<Vec<u32>>,
}

/// No tile (see [`SweepSchedule::upstream`]).
pub const NO_TILE: u32 = u32::MAX;

impl SweepSchedule {
    /// Builds the schedule of square [`TILE`] × [`TILE`] tiles from the leading indices of the
    /// rows (`lead[r][k]` for `k < lead_dims`) and the grid shape.
    pub fn new<const D: usize>(leads: &[[usize; D]], shape: [usize; D]) -> Self {
        Self::with_tile_sides(leads, shape, [TILE, TILE], 0)
    }

    /// The same with tiles of `sides[k]` rows along leading axis `k`, and strips made of the
    /// tiles with the same tile coordinate along `strip_axis` (0 or 1), ordered along the other
    /// (3D; a 2D band's single leading axis ignores both).
    pub fn with_tile_sides<const D: usize>(
        leads: &[[usize; D]],
        shape: [usize; D],
        sides: [usize; 2],
        strip_axis: usize,
    ) -> Self {
        assert!(strip_axis < 2, "the strip axis is one of the two leading axes");
        assert!(sides.iter().all(|&s| s > 0), "tile sides must be positive");
        let lead_dims = D - 1;
        let n_orient = 1usize << lead_dims;
        // the orientations are independent: one task each
        let per_orientation: Vec<_> = (0..n_orient)
            .into_par_iter()
            .map(|signs| {
                let keyed = rows_in_order(leads, shape, sides, signs);
                let mut rows = Vec::with_capacity(keyed.len());
                let mut tiles = vec![0u32];
                let mut waves = vec![0u32];
                for (i, &(wave, tile, _, r)) in keyed.iter().enumerate() {
                    if i > 0 {
                        let (pw, pt, _, _) = keyed[i - 1];
                        if pt != tile || pw != wave {
                            tiles.push(i as u32);
                        }
                        if pw != wave {
                            waves.push((tiles.len() - 1) as u32);
                        }
                    }
                    rows.push(r);
                }
                tiles.push(keyed.len() as u32);
                waves.push((tiles.len() - 1) as u32);
                // strips: the tiles by (a, b), with a tile's key `a·stride + b` (two leading axes)
                let (mut strip_tiles, mut strips, mut upstream) = (Vec::new(), Vec::new(), Vec::new());
                if lead_dims == 2 && keyed.is_empty() {
                    // no rows: one empty strip over the one empty tile
                    strips = vec![0u32, 0];
                    upstream = vec![NO_TILE; tiles.len() - 1];
                    strip_tiles = (0..tiles.len() as u32 - 1).collect();
                    strips[1] = strip_tiles.len() as u32;
                } else if lead_dims == 2 {
                    let stride = (shape[1] / sides[1] + 1) as u64;
                    let mut by_coords: Vec<(u64, u64, u32)> = (0..tiles.len() - 1)
                        .map(|t| {
                            let key = keyed[tiles[t] as usize].1;
                            let (a, b) = (key / stride, key % stride);
                            if strip_axis == 0 {
                                (a, b, t as u32)
                            } else {
                                (b, a, t as u32)
                            }
                        })
                        .collect();
                    by_coords.sort_unstable();
                    upstream = vec![NO_TILE; tiles.len() - 1];
                    strips.push(0u32);
                    for (i, &(a, b, t)) in by_coords.iter().enumerate() {
                        if i > 0 && by_coords[i - 1].0 != a {
                            strips.push(i as u32);
                        }
                        strip_tiles.push(t);
                        if a > 0 {
                            if let Ok(j) = by_coords.binary_search_by(|&(x, y, _)| (x, y).cmp(&(a - 1, b))) {
                                upstream[t as usize] = by_coords[j].2;
                            }
                        }
                    }
                    strips.push(strip_tiles.len() as u32);
                }
                (rows, tiles, waves, strip_tiles, strips, upstream)
            })
            .collect();
        let mut sched = SweepSchedule::default();
        for (rows, tiles, waves, strip_tiles, strips, upstream) in per_orientation {
            sched.strip_tiles.push(strip_tiles);
            sched.strips.push(strips);
            sched.upstream.push(upstream);
            sched.rows.push(rows);
            sched.tiles.push(tiles);
            sched.waves.push(waves);
        }
        sched
    }

    /// Rows in processing order for orientation `signs`.
    #[inline]
    pub fn rows(&self, signs: usize) -> &[u32] {
        &self.rows[signs]
    }

    /// Tile boundaries (indices into [`rows`](Self::rows)) for orientation `signs`.
    #[inline]
    pub fn tiles(&self, signs: usize) -> &[u32] {
        &self.tiles[signs]
    }

    /// Wave boundaries (indices into [`tiles`](Self::tiles)) for orientation `signs`.
    #[inline]
    pub fn waves(&self, signs: usize) -> &[u32] {
        &self.waves[signs]
    }

    /// Tiles strip by strip for orientation `signs` (see the module documentation); empty when
    /// the band has fewer than two leading axes.
    #[inline]
    pub fn strip_tiles(&self, signs: usize) -> &[u32] {
        &self.strip_tiles[signs]
    }

    /// Strip boundaries (indices into [`strip_tiles`](Self::strip_tiles)) for orientation `signs`.
    #[inline]
    pub fn strips(&self, signs: usize) -> &[u32] {
        &self.strips[signs]
    }

    /// Per tile, the tile of the previous strip that must be done before it starts, or
    /// [`NO_TILE`].
    #[inline]
    pub fn upstream(&self, signs: usize) -> &[u32] {
        &self.upstream[signs]
    }

    pub fn heap_bytes(&self) -> usize {
        self.rows.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.tiles.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.waves.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.strip_tiles.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.strips.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.upstream.iter().map(|v| v.len() * 4).sum::<usize>()
    }
}

/// The rows of one orientation (`signs`: bit `k` set = leading axis `k` walked backwards) in the
/// schedule's order, each as `(wave, tile, row, r)`: the sum of its tile coordinates, its tile's
/// linear index and its own in this orientation's coordinates, and the row's index; sorted by
/// those keys (the row key is unique, so the order is total).
///
/// With two leading axes the rows are bucketed by tile (a counting sort), the non-empty tiles
/// sorted by `(wave, tile)` and each tile's few rows by their key: linear in the rows, where one
/// sort of all rows by the whole key cost about 2–3 ms per band at N = 201 (both strip
/// schedules, 4 orientations each, at a band's first parallel solve).
fn rows_in_order<const D: usize>(
    leads: &[[usize; D]],
    shape: [usize; D],
    sides: [usize; 2],
    signs: usize,
) -> Vec<(u64, u64, u64, u32)> {
    let lead_dims = D - 1;
    let key = |lead: &[usize; D]| {
        let mut wave = 0u64;
        let mut tile = 0u64;
        let mut row = 0u64;
        for k in 0..lead_dims {
            let c = if signs & (1 << k) != 0 {
                shape[k] - 1 - lead[k]
            } else {
                lead[k]
            };
            let side = sides[k.min(1)];
            let t = (c / side) as u64;
            wave += t;
            tile = tile * (shape[k] / side + 1) as u64 + t;
            row = row * shape[k] as u64 + c as u64;
        }
        if lead_dims == 1 {
            // one leading axis: no two tiles are independent, run them in sequence
            wave = row;
            tile = row;
        }
        (wave, tile, row)
    };
    let n_tiles: usize = (0..lead_dims).map(|k| shape[k] / sides[k.min(1)] + 1).product();
    if lead_dims != 2 || n_tiles > 4 * leads.len() + 1024 {
        // one leading axis, or far more tiles than rows: one sort of everything
        let mut keyed: Vec<(u64, u64, u64, u32)> = leads
            .iter()
            .enumerate()
            .map(|(r, lead)| {
                let (wave, tile, row) = key(lead);
                (wave, tile, row, r as u32)
            })
            .collect();
        keyed.sort_unstable();
        return keyed;
    }
    // counting sort by tile
    let keys: Vec<(u64, u64, u64)> = leads.iter().map(key).collect();
    let mut start = vec![0u32; n_tiles + 1];
    for &(_, tile, _) in &keys {
        start[tile as usize + 1] += 1;
    }
    for t in 0..n_tiles {
        start[t + 1] += start[t];
    }
    let mut fill = start.clone();
    let mut bucketed = vec![0u32; keys.len()];
    for (r, &(_, tile, _)) in keys.iter().enumerate() {
        bucketed[fill[tile as usize] as usize] = r as u32;
        fill[tile as usize] += 1;
    }
    // the non-empty tiles by (wave, tile)
    let mut tiles: Vec<(u64, u64)> = (0..n_tiles)
        .filter(|&t| start[t + 1] > start[t])
        .map(|t| (keys[bucketed[start[t] as usize] as usize].0, t as u64))
        .collect();
    tiles.sort_unstable();
    let mut keyed = Vec::with_capacity(keys.len());
    for &(_, t) in &tiles {
        let bucket = &mut bucketed[start[t as usize] as usize..start[t as usize + 1] as usize];
        bucket.sort_unstable_by_key(|&r| keys[r as usize].2);
        keyed.extend(bucket.iter().map(|&r| {
            let (wave, tile, row) = keys[r as usize];
            (wave, tile, row, r)
        }));
    }
    keyed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows of a shell-like band: every (i, j) within a ring of the leading plane.
    fn ring_leads(n: usize) -> Vec<[usize; 3]> {
        let c = (n - 1) as f64 / 2.0;
        let mut leads = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let r = ((i as f64 - c).powi(2) + (j as f64 - c).powi(2)).sqrt();
                if r < 0.45 * n as f64 && (r > 0.2 * n as f64 || (i + j) % 3 == 0) {
                    leads.push([i, j, 0]);
                }
            }
        }
        leads
    }

    #[test]
    fn the_bucketed_order_is_the_order_of_one_sort_by_the_whole_key() {
        // rings, and two far corners of a large plane (more tiles than rows: one sort)
        let cases = [1usize, 2, 9, 37, 64]
            .into_iter()
            .map(|n| (ring_leads(n), [n, n + 3, 5]))
            .chain(std::iter::once((
                vec![[0, 3, 0], [999, 998, 0], [0, 2, 0]],
                [1000, 1000, 5],
            )));
        for (leads, shape) in cases {
            let n = shape[0];
            for sides in [[8, 8], [2, 16], [16, 2], [1, 1], [3, 5]] {
                for signs in 0..4 {
                    let got = rows_in_order(&leads, shape, sides, signs);
                    let mut want: Vec<(u64, u64, u64, u32)> = leads
                        .iter()
                        .enumerate()
                        .map(|(r, lead)| {
                            let (mut wave, mut tile, mut row) = (0u64, 0u64, 0u64);
                            for k in 0..2 {
                                let c = if signs & (1 << k) != 0 {
                                    shape[k] - 1 - lead[k]
                                } else {
                                    lead[k]
                                };
                                let t = (c / sides[k]) as u64;
                                wave += t;
                                tile = tile * (shape[k] / sides[k] + 1) as u64 + t;
                                row = row * shape[k] as u64 + c as u64;
                            }
                            (wave, tile, row, r as u32)
                        })
                        .collect();
                    want.sort_unstable();
                    assert_eq!(got, want, "n {n} sides {sides:?} signs {signs}");
                }
            }
        }
    }
}
