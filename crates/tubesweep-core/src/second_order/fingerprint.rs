//! What changed between two tubes of a moving surface, node by node (issue 47,
//! docs/moving-surfaces.md): a 64-bit digest per band node of everything its second-order update
//! reads of its own, compared across the two bands by grid position.
//!
//! The update of node i (the inner update of Eq. (3) with the corrected metric B and the
//! factored u₀ of [`super`], or the extension update along the normal) reads: the node's role,
//! u₀, |φ| and outward direction, its slowness, at a node not in the extension layer its
//! geometry ([`NodeGeometry`]: the normal, B and whether it runs first order) and ∂u₀, and the
//! values, |φ| and u₀ of the band nodes at distance 1 and 2 along the axes (and at distance 3,
//! the value and u₀ of the BDF3 ramp's third neighbour). [`node_fingerprints`]
//! digests the node's own part and which of its neighbours along the axes are in the band (a
//! neighbour entering or leaving the band changes it; one at distance 2 changes the neighbour
//! between); a node whose digest is unchanged but one of whose read nodes changed is woken by
//! [`super::active`] (the readers of every changed node, up to distance 3, start active). Where neither happened, the node's update is the previous solve's, and the previous
//! value, a fixed point of it to the tolerance, can stay until a neighbour moves.
//!
//! Two digests that agree by chance where the inputs differ: about 2⁻⁶⁴ per node.

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::{NodeRole, Slowness};

use super::factoring::Factoring;
use super::geometry::{NodeGeometry, TubeGeometry};

/// A digest as a sum of independent products (each input times its own odd multiplier, so that
/// the products do not wait on one another), finished by splitmix64's mixer.
#[derive(Clone, Copy)]
struct Digest(u64, u64);

impl Digest {
    fn new() -> Self {
        Digest(0, 0x9E37_79B9_7F4A_7C15)
    }
    #[inline(always)]
    fn add(self, x: u64) -> Self {
        // the multiplier steps by an even constant: odd, and another for every input
        Digest(
            self.0.wrapping_add((x ^ 0x5851_F42D_4C95_7F2D).wrapping_mul(self.1)),
            self.1.wrapping_add(0x2545_F491_4F6C_DD1E),
        )
    }
    #[inline(always)]
    fn finish(self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn add_geometry(mut self, g: &NodeGeometry) -> Self {
        // the packed B holds the first-order reason too
        for &c in g.normal.iter().chain(g.packed()) {
            self = self.add(c.to_bits() as u64);
        }
        self
    }
}

/// Per band node, the digest of what its second-order update reads of its own (see the module).
/// `geometry`, `factoring`, `directions`, `slowness`: the solve's, on `band`. O(band).
pub fn node_fingerprints<const D: usize>(
    band: &NarrowBand<D>,
    geometry: &TubeGeometry,
    factoring: &Factoring<D>,
    directions: &[[f32; D]],
    slowness: Slowness<'_>,
) -> Result<Vec<u64>> {
    let n = band.len();
    let roles = &factoring.roles;
    let n_inner = roles.iter().filter(|&&r| r != NodeRole::Outer).count();
    if roles.len() != n
        || factoring.u0.len() != n
        || geometry.abs_phi.len() != n
        || directions.len() != n
        || geometry.nodes.len() != n_inner
        || factoring.grad_u0.len() != n_inner
    {
        return Err(Error::invalid(
            "band",
            format!("one entry per band node ({n}) is needed"),
        ));
    }
    if let Slowness::PerNode(s) = slowness {
        if s.len() != n {
            return Err(Error::invalid(
                "speed",
                format!("one slowness per band node ({n}) is needed"),
            ));
        }
    }
    let sentinel = band.sentinel();
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    for i in 0..n {
        let mut d = Digest::new()
            .add(roles[i] as u64)
            .add(factoring.u0[i].to_bits())
            .add(geometry.abs_phi[i].to_bits() as u64);
        for &c in &directions[i] {
            d = d.add(c.to_bits() as u64);
        }
        if let Slowness::PerNode(s) = slowness {
            d = d.add(s[i].to_bits());
        }
        if roles[i] != NodeRole::Outer {
            d = d.add_geometry(&geometry.nodes[k]);
            for &c in &factoring.grad_u0[k] {
                d = d.add(c.to_bits() as u64);
            }
            k += 1;
        }
        // which neighbours along the axes are in the band (their grid positions follow from the
        // node's own); one at distance 2 that came or went changes the one between, whose readers
        // start active
        let mut present = 0u64;
        for pair in band.neighbours_of(i) {
            for j in pair {
                present = (present << 1) | (j != sentinel) as u64;
            }
        }
        d = d.add(present);
        out.push(d.finish());
    }
    Ok(out)
}

/// Per node of the new band (`new_linear`, its grid positions in band order), whether its update
/// may differ from the previous solve's: new to the band, or its digest differs from the one the
/// same grid node had in the previous band (`old_linear`, `old_digests`). Both position lists are
/// sorted (the bands' order); one merge. Returns the flags and how many are set.
pub fn changed_nodes(
    old_linear: &[u64],
    old_digests: &[u64],
    new_linear: &[u64],
    new_digests: &[u64],
) -> Result<(Vec<bool>, usize)> {
    if old_linear.len() != old_digests.len() || new_linear.len() != new_digests.len() {
        return Err(Error::invalid("warm", "one digest per band node is needed"));
    }
    if old_linear.windows(2).any(|w| w[0] >= w[1]) || new_linear.windows(2).any(|w| w[0] >= w[1]) {
        return Err(Error::invalid("warm", "band indices must be sorted and distinct"));
    }
    let mut out = Vec::with_capacity(new_linear.len());
    let mut count = 0;
    let mut j = 0;
    for (&l, &d) in new_linear.iter().zip(new_digests) {
        while j < old_linear.len() && old_linear[j] < l {
            j += 1;
        }
        let same = j < old_linear.len() && old_linear[j] == l && old_digests[j] == d;
        count += !same as usize;
        out.push(!same);
    }
    Ok((out, count))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_changes_with_its_digest_or_when_it_is_new() {
        let (flags, count) = changed_nodes(&[1, 4, 6], &[10, 40, 60], &[1, 4, 5, 6], &[10, 41, 50, 60]).unwrap();
        assert_eq!(flags, vec![false, true, true, false]);
        assert_eq!(count, 2);
        assert!(changed_nodes(&[4, 1], &[0, 0], &[1], &[0]).is_err());
        assert!(changed_nodes(&[1], &[0, 0], &[1], &[0]).is_err());
    }

    #[test]
    fn digests_differ_where_a_single_input_differs() {
        let a = Digest::new().add(1).add(2).finish();
        assert_ne!(a, Digest::new().add(2).add(1).finish());
        assert_ne!(a, Digest::new().add(1).add(3).finish());
        assert_ne!(a, Digest::new().add(1).add(2).add(0).finish());
        assert_eq!(a, Digest::new().add(1).add(2).finish());
    }
}
