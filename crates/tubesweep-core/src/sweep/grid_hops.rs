//! The longest breadth-first grid path from the sources through the band: the number of grid
//! steps `H` that sets the numerical infinity ([`crate::SweepProblem::auto_infinity`]) and the
//! width of the front window ([`crate::SolveOptions::front_window`]).
//!
//! A level-synchronous breadth-first search: the nodes `H` steps away are the frontier of level
//! `H`, and the next frontier is the unvisited neighbours of this one. Only the number of levels
//! is kept, not a distance per node. The frontier is scattered over the band, so the search is
//! bound by the latency of fetching each node's neighbour-table entry; the entries of nodes a
//! little ahead in the frontier are prefetched ([`NarrowBand::prefetch_neighbours`]), and the
//! visited set is a bitset (an eighth of a byte per node) that stays in cache. (Expanding long
//! frontiers on two threads, with an atomic bitset, was slower on the sphere at N = 401 and
//! N = 1001: the threads contend for the bitset's cache lines.)

use crate::band::NarrowBand;

/// How many frontier nodes ahead the neighbour-table entries are prefetched (16 and 64 were
/// slower than 32 on the sphere at N = 401).
const PREFETCH_AHEAD: usize = 32;

/// The largest number of grid steps (moves to a neighbour along one axis, inside the band) from
/// the nearest of `sources` to any band node reachable from them; 0 without sources. Sources
/// out of range are ignored.
pub fn max_grid_hops<const D: usize>(band: &NarrowBand<D>, sources: impl Iterator<Item = usize>) -> u32 {
    let n = band.len();
    let sentinel = band.sentinel() as usize;
    let mut visited = vec![0u64; n / 64 + 1];
    // true when `m` was not visited yet (and marks it)
    let mut claim = |m: usize| -> bool {
        let (word, bit) = (&mut visited[m >> 6], 1u64 << (m & 63));
        let fresh = *word & bit == 0;
        *word |= bit;
        fresh
    };
    let mut frontier: Vec<u32> = sources.filter(|&i| i < n && claim(i)).map(|i| i as u32).collect();
    let mut next = Vec::new();
    let mut level = 0u32;
    loop {
        next.clear();
        for (j, &i) in frontier.iter().enumerate() {
            if let Some(&ahead) = frontier.get(j + PREFETCH_AHEAD) {
                band.prefetch_neighbours(ahead as usize);
            }
            // SAFETY: frontier entries are band positions (< n)
            let nb = unsafe { band.neighbours_of_unchecked(i as usize) };
            for axis in nb.iter() {
                for &m in axis {
                    if m as usize != sentinel && claim(m as usize) {
                        next.push(m);
                    }
                }
            }
        }
        if next.is_empty() {
            return level;
        }
        level += 1;
        std::mem::swap(&mut frontier, &mut next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The breadth-first search of one queue with a distance per node, for comparison.
    fn reference<const D: usize>(band: &NarrowBand<D>, sources: &[usize]) -> u32 {
        let sentinel = band.sentinel() as usize;
        let mut hops = vec![u32::MAX; band.len()];
        let mut queue = std::collections::VecDeque::new();
        for &s in sources {
            hops[s] = 0;
            queue.push_back(s);
        }
        let mut most = 0;
        while let Some(i) = queue.pop_front() {
            for axis in band.neighbours_of(i) {
                for m in axis {
                    if m as usize != sentinel && hops[m as usize] == u32::MAX {
                        hops[m as usize] = hops[i] + 1;
                        most = most.max(hops[i] + 1);
                        queue.push_back(m as usize);
                    }
                }
            }
        }
        most
    }

    #[test]
    fn a_full_box_from_a_corner_needs_the_sum_of_its_sides() {
        let band = NarrowBand::<3>::full_box([7, 5, 4]).unwrap();
        assert_eq!(max_grid_hops(&band, std::iter::once(0)), 6 + 4 + 3);
        // from the centre of a 2D box, the farthest corner; no sources, no steps
        let band = NarrowBand::<2>::full_box([9, 9]).unwrap();
        let centre = band.find([4, 4]).unwrap();
        assert_eq!(max_grid_hops(&band, std::iter::once(centre)), 8);
        assert_eq!(max_grid_hops(&band, std::iter::empty()), 0);
    }

    #[test]
    fn on_a_shell_the_levels_are_the_queue_search_s_distances() {
        let n = 81usize;
        let c = (n - 1) as f64 / 2.0;
        let mut lin = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let r = ((i as f64 - c).powi(2) + (j as f64 - c).powi(2) + (k as f64 - c).powi(2)).sqrt();
                    if (r - 0.4 * n as f64).abs() <= 4.0 {
                        lin.push(((i * n + j) * n + k) as u64);
                    }
                }
            }
        }
        let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &lin).unwrap();
        let pole = band
            .find([
                (n / 2) as i64,
                (n / 2) as i64,
                (n / 2 + (0.4 * n as f64) as usize) as i64,
            ])
            .unwrap();
        for sources in [vec![pole], vec![pole, 17, band.len() - 1]] {
            let expected = reference(&band, &sources);
            assert!(expected > 50, "a shell this size is {expected} steps across");
            assert_eq!(
                max_grid_hops(&band, sources.iter().copied()),
                expected,
                "sources {sources:?}"
            );
        }
    }
}
