//! Creases read through a smoothing: the test for a re-distanced φ whose own kinks hide its
//! creases from [`super::creases`] (a voxel mask's staircase, noise, or a crease that a smoothing
//! rounded). python/tubesweep/_coarse_creases.py holds the thresholds and what they were
//! measured on; this is its per-node work.
//!
//! φ is smoothed over the band (passes of the 3-node mean along each axis, over the neighbours
//! present), its normals are read by central differences at the nodes next to the surface, and at
//! each such node the largest angle to the normals of such nodes up to `reach` nodes away along
//! each axis is its turn. A crease node turns by more than `turn` degrees (`turn_concave` where
//! the smoothed φ's Laplacian is not positive: beside a concave crease) beside a face (a node
//! within the reach turning by less than `face`) and away from a thin part (no node within the
//! reach whose normal reverses, turning by more than `sheets` within one node more). Across a
//! crease the paper's tube (its Eq. (3)) lets the front cut the corner; the report sizes that.
//! O(band) for the smoothing, O(nodes next to the surface × (2·reach + 1)^D) for the turns, in
//! parallel.

use rayon::prelude::*;

use crate::band::NarrowBand;
use crate::error::{Error, Result};

/// The thresholds of [`smoothed_creases`], in degrees but for `near` (grid spacings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothedCreaseTest {
    /// Passes of the 3-node mean along each axis.
    pub passes: usize,
    /// How far (nodes along each axis) normals are compared.
    pub reach: usize,
    /// Nodes with |φ| at most this many grid spacings carry the normals compared.
    pub near: f64,
    /// A turn above this marks a crease node beside a convex edge (the smoothed φ's Laplacian
    /// positive there).
    pub turn: f64,
    /// The same beside a concave crease (the Laplacian zero or negative). Lower than `turn`: a
    /// smooth part that turns this much within the reach is mostly convex (a thin tube, a
    /// capsule, an ellipsoid's rim) or small (the smooth crotch of a tree of tubes, which the
    /// caller leaves out by a least count of nodes: python/tubesweep/_coarse_creases.py,
    /// `MIN_CONCAVE_NODES`), and the smoothing reads a concave crease lower than a convex edge.
    pub turn_concave: f64,
    /// A crease read from `turn_concave` alone (no node above `turn`) holds this many nodes at
    /// least, else it is none: small smooth concave parts read that high too.
    pub min_concave_nodes: usize,
    /// A node turning by less than this is a face.
    pub face: f64,
    /// A turn above this within `reach + 1` nodes is a reversal: two sides of a thin part.
    pub sheets: f64,
    /// The percentile of the crease nodes' turns reported.
    pub percentile: f64,
}

/// The unit normals of the smoothed φ at the nodes next to the surface.
pub struct SmoothedNormals<const D: usize> {
    /// Their band positions, increasing.
    pub at: Vec<usize>,
    normal: Vec<[f64; D]>,
    /// The smoothed φ's Laplacian there (times Δx²): positive beside a convex edge, negative
    /// beside a concave crease.
    laplacian: Vec<f64>,
    /// Each band node's row of `normal`, `u32::MAX` for none.
    slot: Vec<u32>,
}

/// The normals of φ (`phi`, one value per band node) smoothed by `passes` passes, at the nodes
/// with |φ| ≤ `near`·`spacing` whose axis neighbours are all in the band.
pub fn smoothed_normals<const D: usize>(
    band: &NarrowBand<D>,
    phi: &[f64],
    spacing: f64,
    passes: usize,
    near: f64,
) -> Result<SmoothedNormals<D>> {
    let n = band.len();
    if phi.len() != n {
        return Err(Error::invalid(
            "phi",
            format!("one value per band node is needed ({n} nodes, {} values)", phi.len()),
        ));
    }
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(Error::invalid("spacing", format!("must be positive; got {spacing}")));
    }
    let sentinel = band.sentinel();
    let mut smoothed = phi.to_vec();
    for _ in 0..passes {
        for k in 0..D {
            let previous = smoothed;
            smoothed = (0..n)
                .into_par_iter()
                .with_min_len(4096)
                .map(|i| {
                    let [minus, plus] = band.neighbours_of(i)[k];
                    let (mut total, mut count) = (previous[i], 1.0);
                    for j in [minus, plus] {
                        if j != sentinel {
                            total += previous[j as usize];
                            count += 1.0;
                        }
                    }
                    total / count
                })
                .collect();
        }
    }
    let found: Vec<(usize, [f64; D], f64)> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .filter_map(|i| {
            if !(phi[i].abs() <= near * spacing) {
                return None;
            }
            let mut gradient = [0.0; D];
            let mut laplacian = 0.0;
            for (k, pair) in band.neighbours_of(i).iter().enumerate() {
                if pair[0] == sentinel || pair[1] == sentinel {
                    return None;
                }
                let (minus, plus) = (smoothed[pair[0] as usize], smoothed[pair[1] as usize]);
                gradient[k] = plus - minus;
                laplacian += plus + minus - 2.0 * smoothed[i];
            }
            let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            Some((i, gradient.map(|g| g / norm), laplacian))
        })
        .collect();
    let mut slot = vec![u32::MAX; n];
    for (row, &(i, _, _)) in found.iter().enumerate() {
        slot[i] = row as u32;
    }
    let mut at = Vec::with_capacity(found.len());
    let mut normal = Vec::with_capacity(found.len());
    let mut laplacian = Vec::with_capacity(found.len());
    for (i, n, l) in found {
        at.push(i);
        normal.push(n);
        laplacian.push(l);
    }
    Ok(SmoothedNormals {
        at,
        normal,
        laplacian,
        slot,
    })
}

/// The offsets of at most `reach` nodes along each axis but none, each reached from an earlier
/// one (`back`, an index into this list, 0 for the node itself) by one step along `axis` to
/// `side` (0 minus, 1 plus): the walk along the neighbour table.
fn walk(reach: usize, dims: usize) -> Vec<(usize, usize, usize)> {
    let width = 2 * reach as i64 + 1;
    let mut offsets: Vec<Vec<i64>> = (0..width.pow(dims as u32))
        .map(|mut code| {
            (0..dims)
                .map(|_| {
                    let v = code % width - reach as i64;
                    code /= width;
                    v
                })
                .collect()
        })
        .collect();
    offsets.sort_by_key(|o| o.iter().map(|v| v.abs()).sum::<i64>());
    let index = |o: &[i64]| offsets.iter().position(|p| p.as_slice() == o).unwrap_or(0);
    (1..offsets.len())
        .map(|i| {
            let o = &offsets[i];
            let axis = o.iter().position(|&v| v != 0).unwrap_or(0);
            let mut back = o.clone();
            back[axis] -= o[axis].signum();
            (index(&back), axis, usize::from(o[axis] > 0))
        })
        .collect()
}

/// Visits the band positions of the nodes reached from `start` along `steps` ([`walk`]), in
/// order, until `visit` returns false; `position` is the walk's buffer (one entry per step and one
/// for `start`), reused from node to node.
fn walk_from<const D: usize>(
    band: &NarrowBand<D>,
    steps: &[(usize, usize, usize)],
    start: u32,
    position: &mut [u32],
    mut visit: impl FnMut(usize) -> bool,
) {
    let sentinel = band.sentinel();
    position[0] = start;
    for (i, &(back, axis, side)) in steps.iter().enumerate() {
        let from = position[back];
        let to = if from == sentinel {
            sentinel
        } else {
            band.neighbours_of(from as usize)[axis][side]
        };
        position[i + 1] = to;
        if to != sentinel && !visit(to as usize) {
            return;
        }
    }
}

impl<const D: usize> SmoothedNormals<D> {
    /// At the rows `rows` (of [`Self::at`]), the largest angle in degrees between their normal and
    /// those of the nodes up to `reach` nodes away along each axis (0 where none has a normal).
    pub fn turning(&self, band: &NarrowBand<D>, rows: &[usize], reach: usize) -> Vec<f64> {
        let steps = walk(reach, D);
        rows.par_iter()
            .with_min_len(256)
            .map_init(
                || vec![0u32; steps.len() + 1],
                |position, &row| {
                    let mine = self.normal[row];
                    let mut closest = 1.0_f64;
                    walk_from(band, &steps, self.at[row] as u32, position, |to| {
                        if let Some(&slot) = self.slot.get(to).filter(|&&s| s != u32::MAX) {
                            let other = self.normal[slot as usize];
                            closest = closest.min((0..D).map(|c| mine[c] * other[c]).sum());
                        }
                        true
                    });
                    closest.clamp(-1.0, 1.0).acos().to_degrees()
                },
            )
            .collect()
    }

    /// [`Self::turning`] at every node that has a normal, in the order of [`Self::at`].
    pub fn turning_all(&self, band: &NarrowBand<D>, reach: usize) -> Vec<f64> {
        let all: Vec<usize> = (0..self.at.len()).collect();
        self.turning(band, &all, reach)
    }

    /// Whether any node up to `reach` nodes from each of `rows` has `flag` (per band position).
    fn near_any(&self, band: &NarrowBand<D>, rows: &[usize], reach: usize, flag: &[bool]) -> Vec<bool> {
        let steps = walk(reach, D);
        rows.par_iter()
            .with_min_len(256)
            .map_init(
                || vec![0u32; steps.len() + 1],
                |position, &row| {
                    let mut found = false;
                    walk_from(band, &steps, self.at[row] as u32, position, |to| {
                        found = flag[to];
                        !found
                    });
                    found
                },
            )
            .collect()
    }
}

/// The crease nodes that [`smoothed_creases`] finds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SmoothedCreases {
    /// How many.
    pub nodes: usize,
    /// Their turn in degrees (the test's `percentile` of them).
    pub turn: f64,
    /// The share of them beside a convex edge (the smoothed φ's Laplacian positive there, as
    /// inside a cube's edge), where the smoothing reads the faces' angle higher than beside a
    /// concave crease (a cube's 90° edges as 74°, two balls fused at 122° as 76°).
    pub convex: f64,
}

/// The crease nodes that `test` finds on φ (see the module documentation); none (the default)
/// where there is none.
pub fn smoothed_creases<const D: usize>(
    band: &NarrowBand<D>,
    phi: &[f64],
    spacing: f64,
    test: &SmoothedCreaseTest,
) -> Result<SmoothedCreases> {
    let normals = smoothed_normals(band, phi, spacing, test.passes, test.near)?;
    let turning = normals.turning_all(band, test.reach);
    let rows: Vec<usize> = (0..normals.at.len())
        .filter(|&r| {
            let convex = normals.laplacian[r] > 0.0;
            turning[r] > if convex { test.turn } else { test.turn_concave }
        })
        .collect();
    if rows.is_empty() {
        return Ok(SmoothedCreases::default());
    }
    let mut face = vec![false; band.len()];
    for (r, &t) in turning.iter().enumerate() {
        face[normals.at[r]] = t < test.face;
    }
    let mut sheet = vec![false; band.len()];
    for (&r, &t) in rows.iter().zip(&normals.turning(band, &rows, test.reach + 1)) {
        sheet[normals.at[r]] = t > test.sheets;
    }
    let beside = normals.near_any(band, &rows, test.reach, &face);
    let thin = normals.near_any(band, &rows, test.reach, &sheet);
    let kept_rows: Vec<usize> = rows
        .iter()
        .zip(beside.iter().zip(&thin))
        .filter(|(_, (&b, &t))| b && !t)
        .map(|(&r, _)| r)
        .collect();
    if kept_rows.is_empty() {
        return Ok(SmoothedCreases::default());
    }
    // where some turn by more than `turn`, those are the crease's report (its count and its turn
    // as before `turn_concave` came in: the flanks of a sharp concave crease read lower turns and
    // would pull its percentile down); else the concave ones that read between the two, if there
    // are `min_concave_nodes` of them
    let above: Vec<usize> = kept_rows.iter().copied().filter(|&r| turning[r] > test.turn).collect();
    if above.is_empty() && kept_rows.len() < test.min_concave_nodes {
        return Ok(SmoothedCreases::default());
    }
    let kept_rows = if above.is_empty() { kept_rows } else { above };
    let convex = kept_rows.iter().filter(|&&r| normals.laplacian[r] > 0.0).count() as f64 / kept_rows.len() as f64;
    let mut kept: Vec<f64> = kept_rows.iter().map(|&r| turning[r]).collect();
    kept.sort_by(f64::total_cmp);
    // the percentile as numpy's default (linear between the closest ranks)
    let rank = test.percentile.clamp(0.0, 100.0) / 100.0 * (kept.len() - 1) as f64;
    let low = rank.floor() as usize;
    let high = (low + 1).min(kept.len() - 1);
    Ok(SmoothedCreases {
        nodes: kept.len(),
        turn: kept[low] + (rank - low as f64) * (kept[high] - kept[low]),
        convex,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band_of(n: usize, phi: impl Fn([f64; 3]) -> f64, width: f64) -> (NarrowBand<3>, Vec<f64>, f64) {
        let h = 2.0 / (n - 1) as f64;
        let mut linear = Vec::new();
        let mut values = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let x = [-1.0 + i as f64 * h, -1.0 + j as f64 * h, -1.0 + k as f64 * h];
                    let v = phi(x);
                    if v.abs() <= width * h {
                        linear.push(((i * n + j) * n + k) as u64);
                        values.push(v);
                    }
                }
            }
        }
        (NarrowBand::from_sorted_linear([n, n, n], &linear).unwrap(), values, h)
    }

    const TEST: SmoothedCreaseTest = SmoothedCreaseTest {
        passes: 2,
        reach: 2,
        near: 0.75,
        turn: 60.0,
        turn_concave: 40.0,
        min_concave_nodes: 30,
        face: 25.0,
        sheets: 120.0,
        percentile: 90.0,
    };

    #[test]
    fn the_walk_reaches_every_offset_once_from_one_already_reached() {
        let steps = walk(2, 3);
        assert_eq!(steps.len(), 124);
        assert!(steps.iter().enumerate().all(|(i, &(back, _, _))| back <= i));
    }

    /// Two balls of radius 0.5 joined by `min`, their faces meeting at `faces_degrees`.
    fn fused_balls(faces_degrees: f64) -> impl Fn([f64; 3]) -> f64 {
        let c = 0.5 * (0.5 * faces_degrees).to_radians().sin();
        move |x: [f64; 3]| {
            let a = ((x[0] + c).powi(2) + x[1] * x[1] + x[2] * x[2]).sqrt();
            let b = ((x[0] - c).powi(2) + x[1] * x[1] + x[2] * x[2]).sqrt();
            a.min(b) - 0.5
        }
    }

    #[test]
    fn a_sphere_has_no_crease_and_two_fused_balls_have_one() {
        let (band, phi, h) = band_of(41, |x| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.5, 4.0);
        assert_eq!(
            smoothed_creases(&band, &phi, h, &TEST).unwrap(),
            SmoothedCreases::default()
        );
        let normals = smoothed_normals(&band, &phi, h, 2, 0.75).unwrap();
        let most = normals.turning_all(&band, 2).into_iter().fold(0.0, f64::max);
        assert!(most > 10.0 && most < 25.0, "{most}"); // a ball ten spacings in radius
        let (band, phi, h) = band_of(41, fused_balls(122.0), 4.0);
        let found = smoothed_creases(&band, &phi, h, &TEST).unwrap();
        assert!(
            found.nodes > 50 && found.turn > 60.0 && found.turn < 0.75 * 122.0,
            "{found:?}"
        );
        assert!(found.convex < 0.2, "{found:?}"); // a concave crease
        let cube = |x: [f64; 3]| x[0].abs().max(x[1].abs()).max(x[2].abs()) - 0.5;
        let (band, phi, h) = band_of(41, cube, 4.0);
        let found = smoothed_creases(&band, &phi, h, &TEST).unwrap();
        assert!(found.nodes > 100 && found.convex > 0.8, "{found:?}"); // convex edges
    }

    #[test]
    fn a_concave_crease_reads_from_the_lower_turn_and_a_thin_tube_does_not() {
        // two balls fused at 90°: the concave crease turns by less than `turn` within the reach
        let (band, phi, h) = band_of(41, fused_balls(90.0), 4.0);
        let found = smoothed_creases(&band, &phi, h, &TEST).unwrap();
        assert!(
            found.nodes > 100 && found.turn > 45.0 && found.turn < 55.0 && found.convex == 0.0,
            "{found:?}"
        ); // 192 nodes, 49.9°
        let convex_only = SmoothedCreaseTest {
            turn_concave: TEST.turn,
            ..TEST
        };
        assert_eq!(
            smoothed_creases(&band, &phi, h, &convex_only).unwrap(),
            SmoothedCreases::default()
        );
        // a torus whose tube is 5 spacings in radius turns by up to ~58° within the reach, all
        // of it convex: no crease
        let torus = |x: [f64; 3]| ((x[0] * x[0] + x[1] * x[1]).sqrt() - 0.5).hypot(x[2]) - 0.25;
        let (band, phi, h) = band_of(41, torus, 4.0);
        assert_eq!(
            smoothed_creases(&band, &phi, h, &TEST).unwrap(),
            SmoothedCreases::default()
        );
    }

    #[test]
    fn phi_of_the_wrong_length_is_refused() {
        let (band, phi, h) = band_of(21, |x| x[2], 2.0);
        assert!(smoothed_creases(&band, &phi[1..], h, &TEST).is_err());
    }
}
