//! The surface as the second-order geometry reads it: a level set φ (a signed distance at the band
//! nodes) or a closest-point map, given by the offsets d = x − cp(x) at the band nodes (the
//! paper's Sect. 5.2 surfaces, closed ones only for `order=2`).
//!
//! The metric B = (I − φD²φ)⁻¹ of the corrected equation needs φD²φ, which does not depend on the
//! sign of φ (φ → −φ flips D²φ too). A closest-point map has no global sign, but a *local* one
//! suffices: at node i, with a reference direction ν (the offset d_m of largest length among i and
//! its axis neighbours: where |d_i| ≈ 0 its own direction is noise), the stencil's values are
//! φ̃_j = sgn(d_j·ν)|d_j|, a signed distance near node i. The central differences of φ̃ then give
//! n and D²φ exactly as for a level set, so a surface given both ways gets the same B, n, Dcp (to
//! rounding). (The Jacobian of cp by central differences, Dcp + nnᵀ = I − φD²φ, would be the
//! same matrix, but its O(Δx²) truncation error does not vanish on the surface; that of
//! φ̃'s second differences is multiplied by φ = O(Δx).)

use crate::band::NarrowBand;

use super::geometry::gradient_and_hessian_by;
use super::local_fit::fitted_gradient_and_hessian_by;

/// A level set or a closest-point map, per band node.
#[derive(Clone, Copy)]
pub enum Implicit<'a, const D: usize> {
    /// φ (signed) per band node.
    LevelSet(&'a [f64]),
    /// The offsets x − cp(x) per band node.
    ClosestPoint(&'a [[f64; D]]),
}

/// φ, ∇φ and D²φ at a node in a local orientation (see the module documentation).
pub struct LocalGeometry<const D: usize> {
    /// φ at the node, signed in the orientation of `gradient` (≥ 0 for a closest-point map).
    pub phi: f64,
    pub gradient: [f64; D],
    pub hessian: [[f64; D]; D],
}

impl<const D: usize> Implicit<'_, D> {
    /// The number of band nodes it describes.
    pub fn len(&self) -> usize {
        match self {
            Implicit::LevelSet(p) => p.len(),
            Implicit::ClosestPoint(d) => d.len(),
        }
    }

    /// True when it describes no node.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// φ at node `i`: signed for a level set, the distance |x − cp(x)| for a closest-point map.
    #[inline]
    pub fn phi(&self, i: usize) -> f64 {
        match self {
            Implicit::LevelSet(p) => p[i],
            Implicit::ClosestPoint(d) => norm(&d[i]),
        }
    }

    /// True for a closest-point map.
    pub fn is_closest_point(&self) -> bool {
        matches!(self, Implicit::ClosestPoint(_))
    }

    /// φ, ∇φ and D²φ at node `i` by central differences (the 3^D stencil through the band's
    /// neighbour table), or None when a stencil node is not in the band.
    pub fn local(&self, band: &NarrowBand<D>, i: usize, h: f64) -> Option<LocalGeometry<D>> {
        self.local_by(band, i, |phi| {
            gradient_and_hessian_by(band, i, h, phi).map(|(g, hess)| (phi(i), g, hess))
        })
    }

    /// As [`Self::local`], φ, ∇φ and D²φ from the least-squares quadratic over the nodes within
    /// two grid steps ([`super::local_fit`]): robust to noise in φ.
    pub fn local_fitted(&self, band: &NarrowBand<D>, i: usize, h: f64, wide: bool) -> Option<LocalGeometry<D>> {
        self.local_by(band, i, |phi| fitted_gradient_and_hessian_by(band, i, h, wide, phi))
    }

    /// φ, ∇φ and D²φ at node `i` as `differences` gives them from the (locally signed) φ.
    #[allow(clippy::type_complexity)]
    fn local_by(
        &self,
        band: &NarrowBand<D>,
        i: usize,
        differences: impl Fn(&dyn Fn(usize) -> f64) -> Option<(f64, [f64; D], [[f64; D]; D])>,
    ) -> Option<LocalGeometry<D>> {
        match self {
            Implicit::LevelSet(phi) => {
                let (phi, gradient, hessian) = differences(&|j| phi[j])?;
                Some(LocalGeometry { phi, gradient, hessian })
            }
            Implicit::ClosestPoint(d) => {
                let sentinel = band.sentinel();
                let mut nu = d[i];
                let mut longest = norm(&nu);
                for axis in band.neighbours_of(i).iter() {
                    for &j in axis {
                        if j != sentinel {
                            let l = norm(&d[j as usize]);
                            if l > longest {
                                longest = l;
                                nu = d[j as usize];
                            }
                        }
                    }
                }
                let local = |j: usize| {
                    let dot: f64 = (0..D).map(|k| d[j][k] * nu[k]).sum();
                    let l = norm(&d[j]);
                    if dot < 0.0 {
                        -l
                    } else {
                        l
                    }
                };
                let (phi, gradient, hessian) = differences(&local)?;
                Some(LocalGeometry { phi, gradient, hessian })
            }
        }
    }

    /// The closest point of node `i` at `x`: the map's own for a closest-point map, x − φ n for a
    /// level set (`phi` its value there, the node's own or a fitted one; `normal` = ∇φ/|∇φ| in
    /// the orientation of φ).
    #[inline]
    pub fn closest_point(&self, i: usize, x: &[f64; D], phi: f64, normal: &[f64; D]) -> [f64; D] {
        let mut cp = [0.0; D];
        match self {
            Implicit::LevelSet(_) => {
                for k in 0..D {
                    cp[k] = x[k] - phi * normal[k];
                }
            }
            Implicit::ClosestPoint(d) => {
                for k in 0..D {
                    cp[k] = x[k] - d[i][k];
                }
            }
        }
        cp
    }
}

#[inline]
fn norm<const D: usize>(v: &[f64; D]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::second_order::geometry::{sym, tube_geometry_of};
    use crate::sweep::NodeRole;

    /// The sphere of radius 0.5 given as a level set and as a closest-point map: the same B and
    /// normal lines at every inner node (to rounding), whatever the map's lack of a sign.
    #[test]
    fn closest_point_map_gives_the_level_sets_metric() {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let (phi, offsets) = crate::test_bands::sphere_phi_and_offsets(&band, h);
        let a = tube_geometry_of(&band, &roles, &Implicit::LevelSet(&phi), &dirs, h, 4.0 * h).unwrap();
        let b = tube_geometry_of(&band, &roles, &Implicit::ClosestPoint(&offsets), &dirs, h, 4.0 * h).unwrap();
        assert_eq!(b.summary.incomplete_stencils, 0);
        assert!((a.summary.max_curvature - b.summary.max_curvature).abs() < 1e-9);
        assert!((b.summary.grad_norm_max - 1.0).abs() < 0.01 && (b.summary.grad_norm_min - 1.0).abs() < 0.01);
        let (mut worst_b, mut worst_n): (f64, f64) = (0.0, 0.0);
        // (the geometries hold the nodes that are not in the extension layer, in band order)
        let inner = (0..band.len()).filter(|&i| roles[i] != NodeRole::Outer);
        for ((i, ga), gb) in inner.zip(&a.nodes).zip(&b.nodes) {
            if roles[i] != NodeRole::Inner {
                continue;
            }
            for k in 0..3 {
                for l in k..3 {
                    let s = sym(k, l);
                    worst_b = worst_b.max((ga.b(s) - gb.b(s)).abs() as f64);
                }
            }
            // the normals agree up to sign (a closest-point map's orientation is local)
            let dot: f32 = (0..3).map(|k| ga.normal[k] * gb.normal[k]).sum();
            worst_n = worst_n.max(1.0 - dot.abs() as f64);
        }
        assert!(worst_b < 1e-5 && worst_n < 1e-6, "B {worst_b:e}, normals {worst_n:e}");
    }
}
