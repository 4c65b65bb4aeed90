//! Nearest-source labels: which point source's front reaches each band node first.
//!
//! With several point sources the first-arrival time is `u = min_k u_k`, and the band splits
//! into the regions where each `u_k` is the smallest (for speed 1, the geodesic Voronoi cells of
//! the sources on the surface). The sweeps carry no labels; they are recovered from the converged
//! `u` alone. Every local update takes its value from neighbours that are reached no later: the
//! Godunov root of Eq. (3) exceeds the smallest neighbour value it uses, and the extension update
//! of Eq. (5) is a weighted mean of upwind neighbour values, so at least one of them is no larger.
//! Going from a node to its smallest neighbour therefore leads back, through ever earlier nodes,
//! to a node fixed by a source. The labels are assigned in that order: the nodes in increasing
//! `u` (ties by band position), each taking the label of its smallest already-labelled neighbour
//! whose value is at most its own. A few nodes are left without one: extension-layer nodes tied
//! in value with a neighbour later in that order (the sphere with four sources at N = 61 has 3),
//! and more in a Lax–Friedrichs or unconverged solution. They take the label of their smallest
//! labelled neighbour afterwards, breadth first from the labelled nodes (each node once, so the
//! whole stays linear in the band after the sort). Unreached nodes (`u = ∞`) keep `-1`.
//!
//! The labels are first-order like `u`: a node within about one grid spacing of the boundary
//! between two cells may take the other source's label.

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use rayon::prelude::*;

/// The label of the source whose front reaches each band node first, from the converged values
/// `values` (one per band node; `f64::INFINITY` for unreached nodes) and the nodes fixed by the
/// sources: band positions `fixed` and the source each was fixed from, `fixed_labels` (one per
/// entry of `fixed`). Returns one label per band node, `-1` where none reaches it.
pub fn nearest_source_labels<const D: usize>(
    band: &NarrowBand<D>,
    values: &[f64],
    fixed: &[u32],
    fixed_labels: &[u32],
) -> Result<Vec<i64>> {
    let n = band.len();
    if values.len() != n {
        return Err(Error::invalid(
            "values",
            format!("expected one per band node ({n}), got {}", values.len()),
        ));
    }
    if fixed.len() != fixed_labels.len() {
        return Err(Error::invalid("fixed_labels", "expected one label per fixed node"));
    }
    if let Some(i) = values.iter().position(|v| v.is_nan()) {
        return Err(Error::invalid(
            "values",
            format!("NaN at band position {i}; labels need a solved field"),
        ));
    }
    let mut label = vec![-1i64; n];
    for (&p, &l) in fixed.iter().zip(fixed_labels) {
        let p = p as usize;
        if p >= n {
            return Err(Error::invalid(
                "fixed",
                format!("band position {p} is out of range (band of {n} nodes)"),
            ));
        }
        label[p] = l as i64;
    }
    let mut order: Vec<u32> = (0..n as u32)
        .filter(|&i| label[i as usize] < 0 && values[i as usize].is_finite())
        .collect();
    order.par_sort_unstable_by(|&a, &b| values[a as usize].total_cmp(&values[b as usize]).then(a.cmp(&b)));
    let sentinel = band.sentinel();
    // the label of the smallest labelled neighbour of `i` (ties: the smaller band position),
    // among those no later than `i` when `no_later`
    let pick = |i: usize, label: &[i64], no_later: bool| -> i64 {
        let mut best = (-1i64, f64::INFINITY, u32::MAX);
        for pair in band.neighbours_of(i) {
            for m in pair {
                if m == sentinel {
                    continue;
                }
                let l = label[m as usize];
                let v = values[m as usize];
                if l < 0 || (no_later && v > values[i]) {
                    continue;
                }
                if v < best.1 || (v == best.1 && m < best.2) {
                    best = (l, v, m);
                }
            }
        }
        best.0
    };
    for &i in &order {
        let i = i as usize;
        label[i] = pick(i, &label, true);
    }
    // the rest, breadth first: each round labels the unlabelled reached nodes next to labelled
    // ones (from the labels of the rounds before), in band order
    let reached_unlabelled = |m: usize, label: &[i64]| label[m] < 0 && values[m].is_finite();
    let mut queued = vec![false; n];
    let mut round: Vec<u32> = Vec::new();
    for &i in &order {
        let i = i as usize;
        if label[i] < 0
            && band
                .neighbours_of(i)
                .iter()
                .flatten()
                .any(|&m| m != sentinel && label[m as usize] >= 0)
        {
            queued[i] = true;
            round.push(i as u32);
        }
    }
    while !round.is_empty() {
        round.sort_unstable();
        let found: Vec<i64> = round.iter().map(|&i| pick(i as usize, &label, false)).collect();
        for (&i, &l) in round.iter().zip(&found) {
            label[i as usize] = l;
        }
        let mut next = Vec::new();
        for &i in &round {
            for pair in band.neighbours_of(i as usize) {
                for m in pair {
                    if m != sentinel && !queued[m as usize] && reached_unlabelled(m as usize, &label) {
                        queued[m as usize] = true;
                        next.push(m);
                    }
                }
            }
        }
        round = next;
    }
    Ok(label)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full 2D box with the exact distance to two point sources: every node takes the label
    /// of the nearer source, and an unreached node keeps -1.
    #[test]
    fn labels_follow_the_nearer_source_on_a_plane() {
        let (nx, ny) = (41usize, 31usize);
        let band = NarrowBand::<2>::full_box([nx, ny]).unwrap();
        let sources = [(10.0, 12.0), (30.0, 17.0)];
        let mut values = vec![0.0; band.len()];
        let mut fixed = Vec::new();
        let mut fixed_labels = Vec::new();
        for n in 0..band.len() {
            let [i, j] = band.index_of(n);
            let d: Vec<f64> = sources
                .iter()
                .map(|s| ((i as f64 - s.0).powi(2) + (j as f64 - s.1).powi(2)).sqrt())
                .collect();
            values[n] = d[0].min(d[1]);
            if d[0] == 0.0 || d[1] == 0.0 {
                fixed.push(n as u32);
                fixed_labels.push(if d[0] == 0.0 { 0 } else { 1 });
            }
        }
        let far = band.find([0, 0]).unwrap();
        values[far] = f64::INFINITY;
        let labels = nearest_source_labels(&band, &values, &fixed, &fixed_labels).unwrap();
        let mut checked = 0;
        for n in 0..band.len() {
            let [i, j] = band.index_of(n);
            if n == far {
                assert_eq!(labels[n], -1);
                continue;
            }
            let d0 = ((i as f64 - sources[0].0).powi(2) + (j as f64 - sources[0].1).powi(2)).sqrt();
            let d1 = ((i as f64 - sources[1].0).powi(2) + (j as f64 - sources[1].1).powi(2)).sqrt();
            // away from the bisector by more than a grid spacing the label is the nearer source
            if (d0 - d1).abs() > 1.5 {
                assert_eq!(labels[n], if d0 < d1 { 0 } else { 1 }, "node ({i}, {j})");
                checked += 1;
            } else {
                assert!(labels[n] == 0 || labels[n] == 1);
            }
        }
        assert!(checked > band.len() * 9 / 10);
    }

    /// Values that decrease away from the only source (no converged solution looks like this):
    /// every reached node still gets the source's label, breadth first.
    #[test]
    fn nodes_without_an_earlier_neighbour_are_labelled_breadth_first() {
        let band = NarrowBand::<2>::full_box([301, 301]).unwrap();
        let source = band.find([150, 150]).unwrap();
        let mut values = vec![0.0; band.len()];
        for n in 0..band.len() {
            let [i, j] = band.index_of(n);
            values[n] = 1000.0 - ((i as f64 - 150.0).powi(2) + (j as f64 - 150.0).powi(2)).sqrt();
        }
        values[band.find([0, 0]).unwrap()] = f64::INFINITY;
        let labels = nearest_source_labels(&band, &values, &[source as u32], &[7]).unwrap();
        for n in 0..band.len() {
            assert_eq!(labels[n], if values[n].is_finite() { 7 } else { -1 });
        }
    }

    #[test]
    fn rejects_mismatched_input() {
        let band = NarrowBand::<2>::full_box([4, 4]).unwrap();
        let values = vec![1.0; 16];
        assert!(nearest_source_labels(&band, &values[..15], &[0], &[0]).is_err());
        assert!(nearest_source_labels(&band, &values, &[0, 1], &[0]).is_err());
        assert!(nearest_source_labels(&band, &values, &[16], &[0]).is_err());
        let mut bad = values.clone();
        bad[3] = f64::NAN;
        assert!(nearest_source_labels(&band, &bad, &[0], &[0]).is_err());
    }
}
