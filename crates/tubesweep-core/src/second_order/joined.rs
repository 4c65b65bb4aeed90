//! The fixed nodes of a source joined to it through the band ([`super::factoring`]).
//!
//! The factoring fixes the inner-tube nodes whose closest point lies within `fix_radius` (2Δx) of
//! a source at u₀, the chord: a ball in space, not on the surface. Where the surface comes back
//! within that ball across a gap the band keeps apart (the two sides of a slit, a curve's two
//! ends, cut apart by [`crate::band::NarrowBand::cut_edges`]), the nodes on the far side were
//! fixed at the chord across the gap: a cylinder of radius 0.3 slit along its length, the source
//! at the slit's edge, came out 98% short on the far side at N = 81 with slits 1.8–2.0 grid
//! spacings wide, which the first-order scheme, which fixes no ball, kept apart.
//!
//! [`keep_joined`] keeps fixed only the nodes joined to their source's nearest fixed node through
//! fixed nodes along the band's (uncut) edges; the others are updated like any node. Where the
//! band itself joins the two sides (a narrower gap), the fixed nodes stay as they were: the band,
//! not the ball, lets the front across (``_mesh_slits`` warns of such gaps).

use std::collections::HashMap;

use crate::band::NarrowBand;
use crate::sweep::NodeRole;

/// A node a source fixed: its band position, its rank among the nodes not in the extension layer
/// (its entry of ∇u₀), the nearest source within the radius, the chord to it, and the ∇u₀ it
/// takes if it is not fixed after all.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FixedNode<const D: usize> {
    pub(crate) node: u32,
    pub(crate) rank: u32,
    pub(crate) source: u32,
    pub(crate) chord: f64,
    pub(crate) grad_u0: [f32; D],
}

/// Unfixes the nodes of `fixed` that are not joined to their source: per source its root, the
/// fixed node nearest to it; a fixed node is kept when fixed nodes join it to a root along the
/// band's edges. An unfixed node takes back its role in `roles` and its ∇u₀ in `grad_u0` (one
/// entry per node not in the extension layer, in band order), and leaves its source's count in
/// `fixed_per_source`. Returns how many were unfixed. O(fixed nodes).
pub(crate) fn keep_joined<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    fixed: &[FixedNode<D>],
    out_roles: &mut [NodeRole],
    grad_u0: &mut [[f32; D]],
    fixed_per_source: &mut [usize],
) -> usize {
    if fixed.len() < 2 {
        return 0;
    }
    let position: HashMap<u32, usize> = fixed.iter().enumerate().map(|(k, f)| (f.node, k)).collect();
    let mut root: HashMap<u32, usize> = HashMap::new();
    for (k, f) in fixed.iter().enumerate() {
        let r = root.entry(f.source).or_insert(k);
        if f.chord < fixed[*r].chord {
            *r = k;
        }
    }
    let mut joined = vec![false; fixed.len()];
    let mut stack: Vec<usize> = Vec::new();
    for &k in root.values() {
        if !joined[k] {
            joined[k] = true;
            stack.push(k);
        }
    }
    let sentinel = band.sentinel();
    while let Some(k) = stack.pop() {
        for pair in band.neighbours_of(fixed[k].node as usize) {
            for j in pair {
                if j == sentinel {
                    continue;
                }
                if let Some(&m) = position.get(&j) {
                    if !joined[m] {
                        joined[m] = true;
                        stack.push(m);
                    }
                }
            }
        }
    }
    let mut unjoined = 0;
    for (f, _) in fixed.iter().zip(&joined).filter(|(_, &j)| !j) {
        out_roles[f.node as usize] = roles[f.node as usize];
        grad_u0[f.rank as usize] = f.grad_u0;
        fixed_per_source[f.source as usize] -= 1;
        unjoined += 1;
    }
    unjoined
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D box band cut along x = 4½ (the two sides of a slit): the fixed nodes of a source at
    /// (4, 5) within 2 nodes of it on the far side are unfixed and take their ∇u₀ back; those on
    /// its own side stay fixed with ∇u₀ zero; the counts follow.
    #[test]
    fn fixed_nodes_across_a_cut_are_unfixed() {
        let mut band = NarrowBand::<2>::full_box([10, 10]).unwrap();
        let idx = band.indices();
        let at = |x: usize, y: usize| idx.iter().position(|p| *p == [x, y]).unwrap();
        let pairs: Vec<(usize, usize)> = (0..10).map(|y| (at(4, y), at(5, y))).collect();
        assert_eq!(band.cut_edges(&pairs).unwrap(), 10);
        let roles = vec![NodeRole::Inner; band.len()];
        let mut fixed = Vec::new();
        for (i, p) in idx.iter().enumerate() {
            let c = ((p[0] as f64 - 4.0).powi(2) + (p[1] as f64 - 5.0).powi(2)).sqrt();
            if c <= 2.0 {
                fixed.push(FixedNode {
                    node: i as u32,
                    rank: i as u32,
                    source: 0,
                    chord: c,
                    grad_u0: [1.0, 0.5],
                });
            }
        }
        let mut out_roles = roles.clone();
        for f in &fixed {
            out_roles[f.node as usize] = NodeRole::Fixed;
        }
        let mut grad = vec![[0.0f32; 2]; band.len()];
        let mut count = vec![fixed.len()];
        let far = fixed.iter().filter(|f| idx[f.node as usize][0] >= 5).count();
        assert_eq!(far, 4); // (5, 4..=6) and (6, 5)
        let unfixed = keep_joined(&band, &roles, &fixed, &mut out_roles, &mut grad, &mut count);
        assert_eq!(unfixed, far);
        assert_eq!(count, vec![fixed.len() - far]);
        for f in &fixed {
            let i = f.node as usize;
            if idx[i][0] >= 5 {
                assert_eq!(out_roles[i], NodeRole::Inner);
                assert_eq!(grad[i], [1.0, 0.5]);
            } else {
                assert_eq!(out_roles[i], NodeRole::Fixed);
                assert_eq!(grad[i], [0.0, 0.0]);
            }
        }
        // the band uncut: nothing is unfixed
        let band = NarrowBand::<2>::full_box([10, 10]).unwrap();
        let mut out_roles = roles.clone();
        let mut count = vec![fixed.len()];
        assert_eq!(
            keep_joined(&band, &roles, &fixed, &mut out_roles, &mut grad, &mut count),
            0
        );
    }
}
