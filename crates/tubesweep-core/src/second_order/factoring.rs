//! Additive factoring of point sources for the second-order solver: u = u₀ + w with
//! u₀(x) = σ_s |cp(x) − x_s|, the chord from the source's foot point to the node's closest point
//! times the source's slowness σ_s (the nearest source by that measure, with several). u₀ is
//! constant along the normals, like the exact solution, and removes the source's cone, near which
//! the second-order differences of u itself are first order at best (and the sweeps cycle).
//! The inner-tube nodes whose closest point lies within `fix_radius` of a source are fixed at
//! u = u₀: the chord differs from the geodesic by κ²c³/24, O(Δx³) there; those only that fixed
//! nodes join to the source along the band's edges ([`super::joined`]: not across a slit).

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::NodeRole;

use super::geometry::power_of_two_near;
use super::implicit::{Implicit, LocalGeometry};
use super::joined::{keep_joined, FixedNode};

/// u₀ at every node, ∂u₀ at the nodes not in the extension layer, and the roles with the fixed
/// nodes marked.
pub struct Factoring<const D: usize> {
    pub u0: Vec<f64>,
    /// ∇u₀ = σ_s Dcpᵀ (cp − x_s)/|cp − x_s| with Dcp = I − nnᵀ − φD²φ (the Jacobian of the
    /// closest point of a signed distance), exact up to the differences of φ. One entry per node
    /// not in the extension layer, in band order, like [`super::TubeGeometry::nodes`] (zero at
    /// the fixed nodes). Stored over [`Self::grad_u0_unit`], so that f32 holds it at any speed
    /// scale (σ ∇u₀ under- or overflowed f32 beyond speeds of about 1e±38).
    pub grad_u0: Vec<[f32; D]>,
    /// A power of two near the largest source slowness: ∇u₀ = `grad_u0` × this, exactly.
    pub grad_u0_unit: f64,
    pub roles: Vec<NodeRole>,
    /// Nodes fixed by each source.
    pub fixed_per_source: Vec<usize>,
}

/// `lower`, `spacing`: the grid; `phi` (signed) and `directions` (the outward unit directions
/// sgn(φ) n) per node; `sources` the sources'
/// foot points on the surface and `source_slowness` σ_s at each.
#[allow(clippy::too_many_arguments)]
pub fn factor_sources<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    phi: &[f64],
    directions: &[[f32; D]],
    lower: [f64; D],
    spacing: f64,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    fix_radius: f64,
) -> Result<Factoring<D>> {
    factor_sources_of(
        band,
        roles,
        &Implicit::LevelSet(phi),
        directions,
        lower,
        spacing,
        sources,
        source_slowness,
        fix_radius,
    )
}

/// As [`factor_sources`] for a level set or a closest-point map ([`Implicit`]): for a map, the
/// foot points are its own closest points.
#[allow(clippy::too_many_arguments)]
pub fn factor_sources_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    lower: [f64; D],
    spacing: f64,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    fix_radius: f64,
) -> Result<Factoring<D>> {
    let n = band.len();
    check_source_arguments(sources, source_slowness)?;
    let unit = grad_u0_unit_of(source_slowness);
    let mut u0 = vec![0.0; n];
    let mut grad_u0 = Vec::with_capacity(roles.iter().filter(|&&r| r != NodeRole::Outer).count());
    let mut out_roles = roles.to_vec();
    let mut fixed_per_source = vec![0usize; sources.len()];
    let mut fixed = Vec::new();
    let indices = band.indices();
    for i in 0..n {
        let mut x = [0.0; D];
        for k in 0..D {
            x[k] = lower[k] + spacing * indices[i][k] as f64;
        }
        let inner = roles[i] != NodeRole::Outer;
        let local = if inner { surface.local(band, i, spacing) } else { None };
        let node = node_factor(
            surface,
            i,
            &x,
            &directions[i],
            inner,
            local.as_ref(),
            sources,
            source_slowness,
            unit,
            fix_radius,
            &mut fixed_per_source,
        );
        u0[i] = node.u0;
        fixed.extend(node.fixed_node(i, grad_u0.len()));
        if inner {
            grad_u0.push(node.grad_u0);
        }
        if node.fixed {
            out_roles[i] = NodeRole::Fixed;
        }
    }
    keep_joined(band, roles, &fixed, &mut out_roles, &mut grad_u0, &mut fixed_per_source);
    check_sources_fixed(&fixed_per_source, fix_radius)?;
    Ok(Factoring {
        u0,
        grad_u0,
        grad_u0_unit: unit,
        roles: out_roles,
        fixed_per_source,
    })
}

/// At least one source, and one positive finite slowness per source.
pub(crate) fn check_source_arguments<const D: usize>(sources: &[[f64; D]], source_slowness: &[f64]) -> Result<()> {
    if sources.is_empty() {
        return Err(Error::invalid("sources", "at least one source is needed"));
    }
    if source_slowness.len() != sources.len() || source_slowness.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(Error::invalid(
            "source_slowness",
            "one positive finite slowness per source",
        ));
    }
    Ok(())
}

/// [`Factoring::grad_u0_unit`]: a power of two near the largest source slowness.
pub(crate) fn grad_u0_unit_of(source_slowness: &[f64]) -> f64 {
    power_of_two_near(source_slowness.iter().fold(0.0f64, |a, &b| a.max(b)))
}

/// The error for a source that fixed no inner-tube node.
pub(crate) fn check_sources_fixed(fixed_per_source: &[usize], fix_radius: f64) -> Result<()> {
    if let Some(s) = fixed_per_source.iter().position(|&c| c == 0) {
        return Err(Error::invalid(
            "sources",
            format!("sources[{s}] has no inner-tube node within {fix_radius:.3} of it; put the source on the surface or refine the grid"),
        ));
    }
    Ok(())
}

/// What the factoring gives one node.
pub(crate) struct NodeFactor<const D: usize> {
    pub(crate) u0: f64,
    /// ∇u₀ over the unit (zero at a fixed node; not used in the extension layer).
    pub(crate) grad_u0: [f32; D],
    /// Within `fix_radius` of a source (inner-tube nodes only).
    pub(crate) fixed: bool,
    /// At a fixed node: the nearest source within `fix_radius`, the chord to it, and the ∇u₀
    /// over the unit the node takes if [`super::joined::keep_joined`] unfixes it.
    pub(crate) fixed_by: Option<(u32, f64, [f32; D])>,
}

impl<const D: usize> NodeFactor<D> {
    /// The [`FixedNode`] of band position `node`, its ∇u₀ entry at `rank`, when a source fixed it.
    pub(crate) fn fixed_node(&self, node: usize, rank: usize) -> Option<FixedNode<D>> {
        self.fixed_by.map(|(source, chord, grad_u0)| FixedNode {
            node: node as u32,
            rank: rank as u32,
            source,
            chord,
            grad_u0,
        })
    }
}

/// What the factoring reads at a node besides the sources: its closest point, and at an
/// inner-tube node the unit normal, φ and D²φ (in the orientation of the differences; no D²φ
/// where the stencil is incomplete). The same for every source: a batch computes it once
/// ([`TubeFeet`]).
#[derive(Clone, Copy, Debug)]
pub struct NodeFoot<const D: usize> {
    pub normal: [f64; D],
    pub phi: f64,
    pub hessian: Option<[[f64; D]; D]>,
}

/// The closest point of node `i` at `x` and its [`NodeFoot`], from its outward direction sgn(φ) n
/// and φ's differences there (`local`, [`Implicit::local`]; None in the extension layer or for an
/// incomplete stencil).
#[inline]
pub(crate) fn node_foot<const D: usize>(
    surface: &Implicit<'_, D>,
    i: usize,
    x: &[f64; D],
    direction: &[f32; D],
    local: Option<&LocalGeometry<D>>,
) -> ([f64; D], NodeFoot<D>) {
    // closest point: x − φ ∇φ/|∇φ|² from f64 differences where the stencil allows;
    // φ in the orientation of the differences, ∇φ/|∇φ| (the layer's geometry holds the
    // outward direction sgn(φ) n)
    let mut phi_i = surface.phi(i);
    let sign = if phi_i < 0.0 { -1.0 } else { 1.0 };
    let mut nrm = [0.0; D];
    for k in 0..D {
        nrm[k] = sign * direction[k] as f64;
    }
    if let Some(l) = local {
        phi_i = l.phi;
        let g2: f64 = l.gradient.iter().map(|v| v * v).sum();
        if g2 > 0.0 {
            let gn = g2.sqrt();
            for k in 0..D {
                nrm[k] = l.gradient[k] / gn;
            }
        }
    }
    let cp = surface.closest_point(i, x, phi_i, &nrm);
    (
        cp,
        NodeFoot {
            normal: nrm,
            phi: phi_i,
            hessian: local.map(|l| l.hessian),
        },
    )
}

/// u₀ and ∇u₀ at node `i` at `x`, with its outward direction sgn(φ) n, whether it is an
/// inner-tube node, and φ's differences there (`local`, [`Implicit::local`]; None in the extension
/// layer or for an incomplete stencil), ∇u₀ over `unit` ([`Factoring::grad_u0_unit`]); counts into
/// `fixed_per_source` the sources it is within `fix_radius` of.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn node_factor<const D: usize>(
    surface: &Implicit<'_, D>,
    i: usize,
    x: &[f64; D],
    direction: &[f32; D],
    inner: bool,
    local: Option<&LocalGeometry<D>>,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    unit: f64,
    fix_radius: f64,
    fixed_per_source: &mut [usize],
) -> NodeFactor<D> {
    let (cp, foot) = node_foot(surface, i, x, direction, local);
    factor_at(
        &cp,
        inner.then_some(&foot),
        sources,
        source_slowness,
        unit,
        fix_radius,
        fixed_per_source,
    )
}

/// [`node_factor`] from the node's closest point `cp` and, at an inner-tube node, its
/// [`NodeFoot`] (None in the extension layer).
#[inline]
pub(crate) fn factor_at<const D: usize>(
    cp: &[f64; D],
    inner: Option<&NodeFoot<D>>,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    unit: f64,
    fix_radius: f64,
    fixed_per_source: &mut [usize],
) -> NodeFactor<D> {
    let mut best = (f64::INFINITY, 0usize, 0.0);
    for (s, (xs, &sl)) in sources.iter().zip(source_slowness).enumerate() {
        let c: f64 = (0..D).map(|k| (cp[k] - xs[k]).powi(2)).sum::<f64>().sqrt();
        if sl * c < best.0 {
            best = (sl * c, s, c);
        }
    }
    let (value, s, chord) = best;
    let mut node = NodeFactor {
        u0: value,
        grad_u0: [0.0f32; D],
        fixed: false,
        fixed_by: None,
    };
    let Some(foot) = inner else {
        return node;
    };
    // the nodes within fix_radius of some source are fixed (the nearest's value)
    let mut nearest: Option<(u32, f64)> = None;
    for (t, xs) in sources.iter().enumerate() {
        let c = (0..D).map(|k| (cp[k] - xs[k]).powi(2)).sum::<f64>().sqrt();
        if c <= fix_radius {
            fixed_per_source[t] += 1;
            node.fixed = true;
            if nearest.is_none_or(|(_, best)| c < best) {
                nearest = Some((t as u32, c));
            }
        }
    }
    // (∇u₀ also at a fixed node, which keep_joined may unfix; zero there while it is fixed)
    if chord > 0.0 {
        let nrm = &foot.normal;
        let mut e = [0.0; D];
        for k in 0..D {
            e[k] = (cp[k] - sources[s][k]) / chord;
        }
        // Dcp e = e − n (n·e) − φ H e
        let ne: f64 = (0..D).map(|k| nrm[k] * e[k]).sum();
        for k in 0..D {
            let mut v = e[k] - nrm[k] * ne;
            if let Some(hessian) = &foot.hessian {
                v -= foot.phi * (0..D).map(|m| hessian[k][m] * e[m]).sum::<f64>();
            }
            node.grad_u0[k] = (source_slowness[s] * v / unit) as f32;
        }
    }
    if let Some((t, c)) = nearest {
        node.fixed_by = Some((t, c, node.grad_u0));
        node.grad_u0 = [0.0f32; D];
    }
    node
}

/// The source-independent part of the factoring on a whole band ([`node_foot`] per node), for a
/// batch of solves on it: computed once with the tube's geometry
/// ([`super::setup::batch_setup_of`], from the same differences of φ as a single solve's set-up,
/// refitted where that refits them), then each source's factoring is [`factor_sources_at`], the
/// same values as [`super::tube_setup_of`]'s for that source, bit for bit, without φ's
/// differences again (on the sphere at N = 101 they were most of a source's set-up).
pub struct TubeFeet<const D: usize> {
    /// The closest point of every band node.
    pub closest_points: Vec<[f64; D]>,
    /// One entry per node not in the extension layer, in band order.
    pub inner: Vec<NodeFoot<D>>,
}

impl<const D: usize> TubeFeet<D> {
    /// Bytes held.
    pub fn nbytes(&self) -> usize {
        self.closest_points.len() * std::mem::size_of::<[f64; D]>()
            + self.inner.len() * std::mem::size_of::<NodeFoot<D>>()
    }
}

/// One source's factoring from the band's [`TubeFeet`]: u₀, ∇u₀, the roles with the nodes near the
/// sources fixed; the errors of [`factor_sources_of`].
pub fn factor_sources_at<const D: usize>(
    band: &NarrowBand<D>,
    feet: &TubeFeet<D>,
    roles: &[NodeRole],
    sources: &[[f64; D]],
    source_slowness: &[f64],
    fix_radius: f64,
) -> Result<Factoring<D>> {
    let n = roles.len();
    if feet.closest_points.len() != n || feet.inner.len() != roles.iter().filter(|&&r| r != NodeRole::Outer).count() {
        return Err(Error::invalid("feet", format!("one closest point per band node ({n})")));
    }
    check_source_arguments(sources, source_slowness)?;
    let unit = grad_u0_unit_of(source_slowness);
    let mut u0 = Vec::with_capacity(n);
    let mut grad_u0 = Vec::with_capacity(feet.inner.len());
    let mut out_roles = roles.to_vec();
    let mut fixed_per_source = vec![0usize; sources.len()];
    let mut fixed = Vec::new();
    let mut inner = feet.inner.iter();
    for (i, cp) in feet.closest_points.iter().enumerate() {
        let foot = if roles[i] != NodeRole::Outer {
            inner.next()
        } else {
            None
        };
        let node = factor_at(
            cp,
            foot,
            sources,
            source_slowness,
            unit,
            fix_radius,
            &mut fixed_per_source,
        );
        u0.push(node.u0);
        fixed.extend(node.fixed_node(i, grad_u0.len()));
        if foot.is_some() {
            grad_u0.push(node.grad_u0);
        }
        if node.fixed {
            out_roles[i] = NodeRole::Fixed;
        }
    }
    keep_joined(band, roles, &fixed, &mut out_roles, &mut grad_u0, &mut fixed_per_source);
    check_sources_fixed(&fixed_per_source, fix_radius)?;
    Ok(Factoring {
        u0,
        grad_u0,
        grad_u0_unit: unit,
        roles: out_roles,
        fixed_per_source,
    })
}
