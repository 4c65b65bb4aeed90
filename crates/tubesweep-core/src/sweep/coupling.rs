//! The coupled Godunov update's set-up: which extension-layer neighbours of each inner node read
//! it through their update (5), so that the inner update ([`godunov_update_coupled`], paper
//! Eq. (3) with Eq. (5) substituted) solves the node and those neighbours together: the same fixed
//! point as the pointwise updates, in fewer sweeps (docs/architecture.md).

use super::problem::*;
use crate::scheme::hamiltonian::InnerScheme;
use rayon::prelude::*;

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// For the Godunov scheme, which neighbours of each inner node are extension-layer nodes whose
    /// update (5) reads that node: bit `2k + side` of entry `n` for the neighbour `nb[n][k][side]`
    /// (`side` 0: the minus neighbour, which reads its plus neighbour along `k` when its weight
    /// `w_k < 0`; `side` 1: the plus neighbour, which reads its minus neighbour when `w_k > 0`).
    /// The inner update then solves the node and those neighbours together
    /// ([`godunov_update_coupled`]). Empty for the other schemes or without a layer.
    pub(super) fn coupling_mask(&self, weights: &[[f32; D]], coupled: bool) -> Vec<u8> {
        if !coupled || weights.is_empty() || !matches!(self.scheme, InnerScheme::Godunov) {
            return Vec::new();
        }
        let sentinel = self.band.sentinel();
        let roles = self.roles;
        (0..roles.len())
            .into_par_iter()
            .map(|n| {
                if roles[n] != NodeRole::Inner {
                    return 0u8;
                }
                let nb = self.band.neighbours_of(n);
                let mut mask = 0u8;
                for k in 0..D {
                    for side in 0..2 {
                        let q = nb[k][side];
                        if q == sentinel || roles[q as usize] != NodeRole::Outer {
                            continue;
                        }
                        let wq = weights[q as usize][k];
                        let reads = if side == 0 { wq < 0.0 } else { wq > 0.0 };
                        if reads {
                            mask |= 1 << (2 * k + side);
                        }
                    }
                }
                mask
            })
            .collect()
    }
}
