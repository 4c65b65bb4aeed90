//! Small groups of samples apart from the rest of a cloud: a few stray points from a scanner's
//! reflection, far from the surface, that fit one another. Each sample's leave-one-out residual
//! ([`PointCloud::analyse`]) does not find them: their neighbours' fit runs through the group
//! itself, and its radius reaches out to the main cloud, so a residual of a fraction of that
//! radius passes. Left in, they are taken for a rim (their neighbours all lie on one side), the
//! closed surface for an open one, and the cloud's bounding box reaches out to them.
//!
//! Two samples are linked when one is among the other's k + 1 nearest and their distance is at
//! most [`LINK`] times the larger of their spacings (the distance to each one's nearest other
//! sample), the fits' median radius, or the smaller of their own fits' radii, whichever is
//! largest: neighbours on the surface are linked at any density, a group far from it is not (its
//! fits reach out to the surface, the surface's fits do not reach back). The fits' own radii keep
//! a sparsely sampled stretch of a curve together, whose random gaps often exceed three times
//! both neighbours' spacings: an ellipse sampled 20 times more sparsely on one half lost 52 exact
//! samples as groups apart from the rest, a hole where its solve read NaN (a helper's review). A
//! connected part with fewer samples than one fit needs cannot be a piece of surface on its own.

use rayon::prelude::*;

use super::fit::distance;
use super::PointCloud;
use crate::error::{Error, Result};
use kiddo::SquaredEuclidean;

/// Samples farther apart than this many times the larger of their spacings (and than the fits'
/// median radius) are not linked.
pub const LINK: f64 = 3.0;

impl<const D: usize> PointCloud<D> {
    /// Per sample, whether it lies in a connected part of fewer than `min_size` samples (see the
    /// module); `spacing`, `radius` (each sample's fit's, NaN where it has none; empty: not used)
    /// and `median_radius` from [`PointCloud::analyse`].
    pub fn isolated(&self, spacing: &[f64], radius: &[f64], median_radius: f64, min_size: usize) -> Result<Vec<bool>> {
        let n = self.points.len();
        if spacing.len() != n {
            return Err(Error::invalid("spacing", "one value per sample"));
        }
        if !radius.is_empty() && radius.len() != n {
            return Err(Error::invalid("radius", "one value per sample, or none"));
        }
        let own = |i: usize| {
            if radius.is_empty() || radius[i].is_nan() {
                0.0
            } else {
                radius[i]
            }
        };
        let links: Vec<Vec<u32>> = (0..n)
            .into_par_iter()
            .map(|i| {
                let p = &self.points[i];
                self.tree
                    .nearest_n::<SquaredEuclidean>(p, self.k1())
                    .into_iter()
                    .filter(|nb| {
                        let j = nb.item as usize;
                        let reach = (LINK * spacing[i].max(spacing[j]))
                            .max(median_radius)
                            .max(own(i).min(own(j)));
                        j > i && distance(&self.points[j], p) <= reach
                    })
                    .map(|nb| nb.item)
                    .collect()
            })
            .collect();
        // union-find with path halving
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut a: u32) -> u32 {
            while parent[a as usize] != a {
                parent[a as usize] = parent[parent[a as usize] as usize];
                a = parent[a as usize];
            }
            a
        }
        for (i, js) in links.iter().enumerate() {
            for &j in js {
                let (a, b) = (root(&mut parent, i as u32), root(&mut parent, j));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        let roots: Vec<u32> = (0..n as u32).map(|i| root(&mut parent, i)).collect();
        let mut size = vec![0usize; n];
        for &r in &roots {
            size[r as usize] += 1;
        }
        Ok(roots.iter().map(|&r| size[r as usize] < min_size).collect())
    }
}
