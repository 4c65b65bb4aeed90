//! Tests of `narrow_band.rs`.

use super::*;
use crate::band::schedule::NO_TILE;

fn linear<const D: usize>(shape: [usize; D], idx: [usize; D]) -> u64 {
    let mut l = 0u64;
    for k in 0..D {
        l = l * shape[k] as u64 + idx[k] as u64;
    }
    l
}

#[test]
fn full_box_neighbours_match_arithmetic() {
    let shape = [4usize, 5, 3];
    let band = NarrowBand::<3>::full_box(shape).unwrap();
    assert_eq!(band.len(), 60);
    for n in 0..band.len() {
        let idx = band.index_of(n);
        assert_eq!(linear(shape, idx), n as u64);
        for k in 0..3 {
            for side in 0..2 {
                let mut j = [idx[0] as i64, idx[1] as i64, idx[2] as i64];
                j[k] += if side == 0 { -1 } else { 1 };
                let expect = band.find(j).map(|p| p as u32).unwrap_or(band.sentinel());
                assert_eq!(band.neighbours_of(n)[k][side], expect);
                assert_eq!(
                    unsafe { band.neighbour_table().neighbour_unchecked(n, k, side) },
                    expect
                );
                if let Some(p) = band.find(j) {
                    assert_eq!(
                        linear(shape, band.index_of(p)),
                        linear(shape, [j[0] as usize, j[1] as usize, j[2] as usize])
                    );
                }
            }
        }
    }
}

/// Every neighbour of a node along a leading axis lies in the row `row_neighbours` names for
/// the node's row, and each named row is the one whose lead differs by one along that axis.
fn assert_row_neighbours_hold<const D: usize>(band: &NarrowBand<D>) {
    let rows = band.row_neighbours();
    let per = 2 * (D - 1);
    assert_eq!(rows.len(), band.n_rows() * per);
    let mut row_of = vec![0usize; band.len()];
    for r in 0..band.n_rows() {
        let (s, e) = band.row_range(r);
        row_of[s..e].iter_mut().for_each(|x| *x = r);
    }
    for r in 0..band.n_rows() {
        let lead = band.row_lead(r);
        for k in 0..D - 1 {
            for side in 0..2 {
                let q = rows[r * per + 2 * k + side] as usize;
                let mut want = [0i64; D];
                for j in 0..D - 1 {
                    want[j] = lead[j] as i64;
                }
                want[k] += if side == 0 { -1 } else { 1 };
                let exists = (0..band.n_rows()).find(|&p| (0..D - 1).all(|j| band.row_lead(p)[j] as i64 == want[j]));
                assert_eq!(exists.unwrap_or(band.n_rows()), q, "row {r} axis {k} side {side}");
            }
        }
        let (s, e) = band.row_range(r);
        for n in s..e {
            let nb = band.neighbours_of(n);
            for k in 0..D - 1 {
                for side in 0..2 {
                    if nb[k][side] != band.sentinel() {
                        assert_eq!(row_of[nb[k][side] as usize], rows[r * per + 2 * k + side] as usize);
                    }
                }
            }
        }
    }
}

#[test]
fn row_neighbours_name_the_rows_of_the_lead_neighbours() {
    assert_row_neighbours_hold(&NarrowBand::<3>::full_box([4, 5, 3]).unwrap());
    assert_row_neighbours_hold(&NarrowBand::<2>::full_box([6, 4]).unwrap());
    let (shell, ..) = crate::test_bands::shell_band(21, 0.5, &[-0.45, 0.45]);
    assert_row_neighbours_hold(&shell);
}

#[test]
fn sparse_band_neighbours() {
    // an annulus-like set of nodes in 2D
    let shape = [20usize, 20];
    let mut lin = Vec::new();
    for i in 0..20usize {
        for j in 0..20usize {
            let r = (((i as f64) - 9.5).powi(2) + ((j as f64) - 9.5).powi(2)).sqrt();
            if (r - 6.0).abs() <= 1.6 {
                lin.push(linear(shape, [i, j]));
            }
        }
    }
    let band = NarrowBand::<2>::from_sorted_linear(shape, &lin).unwrap();
    assert_eq!(band.len(), lin.len());
    for n in 0..band.len() {
        let idx = band.index_of(n);
        for k in 0..2 {
            for side in 0..2 {
                let mut j = [idx[0] as i64, idx[1] as i64];
                j[k] += if side == 0 { -1 } else { 1 };
                let inset = j.iter().all(|&c| (0..20).contains(&c))
                    && lin
                        .binary_search(&linear(shape, [j[0] as usize, j[1] as usize]))
                        .is_ok();
                let nb = band.neighbours_of(n)[k][side];
                assert_eq!(nb != band.sentinel(), inset, "node {idx:?} axis {k} side {side}");
                // the one entry without the others (the second-order sweeps' reads)
                assert_eq!(unsafe { band.neighbour_table().neighbour_unchecked(n, k, side) }, nb);
            }
        }
    }
    assert_eq!(band.indices().len(), band.len());
}

#[test]
fn an_empty_band_has_an_empty_schedule() {
    let band = NarrowBand::<3>::from_sorted_linear([5, 5, 5], &[]).unwrap();
    assert_eq!(band.len(), 0);
    for (signs, sched) in (0..4).flat_map(|signs| {
        [
            (signs, band.schedule()),
            (signs, band.strip_schedule(0)),
            (signs, band.strip_schedule(1)),
        ]
    }) {
        assert!(sched.rows(signs).is_empty());
        let (strips, strip_tiles) = (sched.strips(signs), sched.strip_tiles(signs));
        assert_eq!(strips.first(), Some(&0));
        assert_eq!(*strips.last().unwrap() as usize, strip_tiles.len());
        assert_eq!(strip_tiles.len(), sched.tiles(signs).len() - 1);
    }
    assert_eq!(NarrowBand::<2>::from_sorted_linear([5, 5], &[]).unwrap().len(), 0);
}

#[test]
fn rejects_unsorted_and_small_shapes() {
    assert!(NarrowBand::<2>::from_sorted_linear([5, 5], &[3, 2]).is_err());
    assert!(NarrowBand::<2>::from_sorted_linear([5, 5], &[3, 3]).is_err());
    assert!(NarrowBand::<2>::from_sorted_linear([5, 5], &[25]).is_err());
    assert!(NarrowBand::<2>::full_box([2, 5]).is_err());
}

#[test]
fn row_orders_are_permutations_in_the_requested_direction() {
    let band = NarrowBand::<3>::full_box([3, 4, 3]).unwrap();
    for signs in 0..4 {
        let order = band.row_order(signs);
        let mut sorted = order.to_vec();
        sorted.sort();
        assert_eq!(sorted, (0..12).collect::<Vec<u32>>());
        let first = band.index_of(band.row_range(order[0] as usize).0);
        assert_eq!(first[0], if signs & 1 != 0 { 2 } else { 0 });
        assert_eq!(first[1], if signs & 2 != 0 { 3 } else { 0 });
    }
}

/// The strip pipeline's dependencies give every row the values of the sequential sweep: a
/// row's lower neighbour rows (in the sweep's orientation) are done before it starts, its
/// upper ones cannot have started. In tile terms: the neighbour row lies in the same tile
/// (ordered inside it) or in a tile that is reached from the row's tile by following the
/// strip order and the `upstream` links (lower), or one from which the row's tile is reached
/// (upper). Checked on a spherical shell, where strips and tiles have gaps.
#[test]
fn strip_pipeline_orders_every_pair_of_neighbour_rows() {
    let n = 61usize;
    let band = crate::test_bands::shell_band(n, 0.6, &[0.0]).0;
    // the square tiles and the rectangular ones, strips along either leading axis
    for (signs, sched) in (0..4).flat_map(|signs| {
        [
            (signs, band.schedule()),
            (signs, band.strip_schedule(0)),
            (signs, band.strip_schedule(1)),
        ]
    }) {
        let (rows, tiles) = (sched.rows(signs), sched.tiles(signs));
        let (strip_tiles, strips, upstream) = (sched.strip_tiles(signs), sched.strips(signs), sched.upstream(signs));
        assert!(strips.len() > 4, "{} strips", strips.len() - 1);
        let mut sorted = strip_tiles.to_vec();
        sorted.sort();
        assert_eq!(sorted, (0..tiles.len() as u32 - 1).collect::<Vec<_>>());
        // tile of each row, position of each row in its tile, strip and place of each tile
        let mut tile_of = vec![0usize; band.n_rows()];
        let mut place = vec![0usize; band.n_rows()];
        for t in 0..tiles.len() - 1 {
            for (i, &r) in rows[tiles[t] as usize..tiles[t + 1] as usize].iter().enumerate() {
                tile_of[r as usize] = t;
                place[r as usize] = i;
            }
        }
        let mut strip_of = vec![0usize; tiles.len() - 1];
        let mut in_strip = vec![0usize; tiles.len() - 1];
        for s in 0..strips.len() - 1 {
            for (i, &t) in strip_tiles[strips[s] as usize..strips[s + 1] as usize]
                .iter()
                .enumerate()
            {
                strip_of[t as usize] = s;
                in_strip[t as usize] = i;
            }
        }
        // `before(x, y)`: tile x is done before tile y starts
        let before = |x: usize, y: usize| -> bool {
            // y waits for the tiles before it in its strip; a tile reached through an
            // upstream link is itself done
            let (mut t, mut strict) = (y, true);
            loop {
                if strip_of[t] == strip_of[x] {
                    return in_strip[x] < in_strip[t] || (!strict && in_strip[x] == in_strip[t]);
                }
                // walk back along the strip to a tile with an upstream link
                let s = strip_of[t];
                let mut found = None;
                for &c in strip_tiles[strips[s] as usize..strips[s] as usize + in_strip[t] + 1]
                    .iter()
                    .rev()
                {
                    if upstream[c as usize] != NO_TILE {
                        found = Some(upstream[c as usize] as usize);
                        break;
                    }
                }
                match found {
                    Some(u) if strip_of[u] >= strip_of[x] => (t, strict) = (u, false),
                    _ => return false,
                }
            }
        };
        let row_of = |lead: [usize; 2]| (0..band.n_rows()).find(|&r| band.row_lead(r)[..2] == lead);
        for r in 0..band.n_rows() {
            let lead = band.row_lead(r);
            for k in 0..2 {
                for step in [-1i64, 1] {
                    let c = lead[k] as i64 + step;
                    if c < 0 || c >= n as i64 {
                        continue;
                    }
                    let mut other = [lead[0], lead[1]];
                    other[k] = c as usize;
                    let Some(q) = row_of(other) else { continue };
                    // lower in this orientation: the coordinate walked first
                    let lower = (step < 0) != (signs & (1 << k) != 0);
                    let (ta, tb) = (tile_of[q], tile_of[r]);
                    let ok = if ta == tb {
                        (place[q] < place[r]) == lower
                    } else if lower {
                        before(ta, tb)
                    } else {
                        before(tb, ta)
                    };
                    assert!(ok, "orientation {signs}: rows {lead:?} and {other:?}");
                }
            }
        }
    }
}
