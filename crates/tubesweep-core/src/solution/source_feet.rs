//! Point sources' foot points on the surface, for the evaluation of a second-order solution near
//! them (`sol(points)`, docs/second-order.md "Evaluation near a source"): which points lie within
//! a reach of some source, and the chord from a point's foot to the nearest source (times that
//! source's slowness). A kd-tree (kiddo) over the feet when there are many, so that neither the
//! memory nor the time is of size (points × sources); the distances compared are always the
//! exact [`chord`]s, so the tree and the plain loop over a few feet give the same bits.

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// Up to this many feet the queries loop over them all.
const FEW: usize = 16;

/// The tree's radii are widened by this relative margin before the exact chords decide, so that
/// its own rounding of the squared distances never leaves out a foot.
const MARGIN: f64 = 1e-9;

/// |a − b|, the squares summed from the first axis on (the same operations as
/// `tubesweep._factoring.pair_distance`).
#[inline]
pub fn chord<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = (a[0] - b[0]) * (a[0] - b[0]);
    for k in 1..D {
        s += (a[k] - b[k]) * (a[k] - b[k]);
    }
    s.sqrt()
}

/// The feet of a solve's point sources, with their slownesses.
pub struct SourceFeet<'a, const D: usize> {
    feet: &'a [[f64; D]],
    slowness: &'a [f64],
    tree: Option<ImmutableKdTree<f64, u32, D, 32>>,
    slowness_min: f64,
    uniform: bool,
}

impl<'a, const D: usize> SourceFeet<'a, D> {
    /// `feet` and `slowness` of the same length (at least one foot).
    pub fn new(feet: &'a [[f64; D]], slowness: &'a [f64]) -> Self {
        debug_assert_eq!(feet.len(), slowness.len());
        let tree = (feet.len() > FEW).then(|| ImmutableKdTree::new_from_slice(feet));
        let slowness_min = slowness.iter().copied().fold(f64::INFINITY, f64::min);
        let uniform = slowness.iter().all(|&s| s == slowness[0]);
        SourceFeet {
            feet,
            slowness,
            tree,
            slowness_min,
            uniform,
        }
    }

    /// Whether some foot's [`chord`] to `p` is at most `reach`.
    pub fn within(&self, p: &[f64; D], reach: f64) -> bool {
        match &self.tree {
            None => self.feet.iter().any(|f| chord(p, f) <= reach),
            Some(tree) => {
                let r = reach * (1.0 + MARGIN);
                tree.within_unsorted::<SquaredEuclidean>(p, r * r)
                    .iter()
                    .any(|nb| chord(p, &self.feet[nb.item as usize]) <= reach)
            }
        }
    }

    /// The smallest σ_s·|foot − x_s| over the sources (u₀ at a point whose foot on the surface is
    /// `foot`).
    pub fn chord_min(&self, foot: &[f64; D]) -> f64 {
        let exact = |j: usize| chord(foot, &self.feet[j]) * self.slowness[j];
        match &self.tree {
            None => (0..self.feet.len()).map(exact).fold(f64::INFINITY, f64::min),
            Some(tree) => {
                let j = tree.nearest_one::<SquaredEuclidean>(foot).item as usize;
                let best = exact(j);
                // no foot farther than this can give less (σ ≥ the smallest slowness)
                let r = if self.uniform {
                    chord(foot, &self.feet[j])
                } else {
                    best / self.slowness_min
                } * (1.0 + MARGIN);
                tree.within_unsorted::<SquaredEuclidean>(foot, r * r)
                    .iter()
                    .map(|nb| exact(nb.item as usize))
                    .fold(best, f64::min)
            }
        }
    }
}

/// The index of the nearest foot to each point (ties: any of them), by a kd-tree.
pub fn nearest_feet<const D: usize>(feet: &[[f64; D]], points: &[[f64; D]]) -> Vec<usize> {
    if feet.is_empty() {
        return vec![0; 0];
    }
    let tree: ImmutableKdTree<f64, u32, D, 32> = ImmutableKdTree::new_from_slice(feet);
    points
        .iter()
        .map(|p| tree.nearest_one::<SquaredEuclidean>(p).item as usize)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree gives the plain loop's answers, bit for bit, with equal and unequal slownesses.
    #[test]
    fn the_tree_gives_the_loops_bits() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let feet: Vec<[f64; 3]> = (0..300).map(|_| [rnd(), rnd(), rnd()]).collect();
        for uniform in [true, false] {
            let slowness: Vec<f64> = (0..300)
                .map(|_| if uniform { 1.5 } else { 1.0 + rnd().abs() })
                .collect();
            let tree = SourceFeet::new(&feet, &slowness);
            assert!(tree.tree.is_some());
            for _ in 0..500 {
                let p = [rnd(), rnd(), rnd()];
                let reach = 0.2 * rnd().abs();
                let loop_within = feet.iter().any(|f| chord(&p, f) <= reach);
                assert_eq!(tree.within(&p, reach), loop_within);
                let loop_min = feet
                    .iter()
                    .zip(&slowness)
                    .map(|(f, s)| chord(&p, f) * s)
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(tree.chord_min(&p).to_bits(), loop_min.to_bits());
            }
            // at a foot itself: 0 and within any reach
            assert_eq!(tree.chord_min(&feet[5]), 0.0);
            assert!(tree.within(&feet[5], 0.0));
        }
        // many identical feet
        let same = vec![[0.25, 0.5, -0.5]; 100];
        let s = vec![1.0; 100];
        let t = SourceFeet::new(&same, &s);
        assert_eq!(t.chord_min(&[0.25, 0.5, 0.5]), 1.0);
    }
}
