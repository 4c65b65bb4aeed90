//! Per-node geometry of the tube for the second-order solver, computed once per band from φ at
//! the band nodes (docs/second-order.md, "The corrected equation").
//!
//! At an inner-tube node the metric-corrected eikonal equation reads |B ∇u| = 1/F with
//! B = (I − φ D²φ)⁻¹: its exact solution is the normal extension of the surface solution, which
//! the paper's |∇u| = 1/F (its Eq. (1) in the tube) is not, by O(φκ) = O(Δx) at every inner node.
//! n = ∇φ/|∇φ| and D²φ come from central differences of φ (the mixed derivatives from the four
//! diagonal neighbours, reached through the band's neighbour table), B from the 3×3 (2×2)
//! inverse. The principal curvatures at the foot point follow from the eigenvalues λ of D²φ at
//! height φ, κ = λ / (1 − φλ); the tube must stay inside the focal distance, h_out·κ < 1.

use rayon::prelude::*;

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::NodeRole;

use super::creases::{creases_of, Creases};
use super::implicit::{Implicit, LocalGeometry};
use super::symmetric::{curvatures_below, symmetric_eigenvalues, symmetric_inverse};

/// What the second-order sweeps read at one inner-tube node (the extension layer's nodes read
/// only the given directions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeGeometry {
    /// ∇φ/|∇φ| (the first `D` entries) by central differences of φ (the given direction times
    /// sgn(φ) where the stencil is incomplete).
    pub normal: [f32; 3],
    /// B = (I − φ D²φ)⁻¹, symmetric, packed as (00, 01, 02, 11, 12, 22) (2D: 00, 01, 11 in the
    /// places 0, 1, 3); I at a first-order node, whose B₀₀ place holds minus the reason instead
    /// (B is positive definite, so B₀₀ > 0 at every other node): read B through [`Self::b`].
    packed_b: [f32; 6],
}

impl NodeGeometry {
    /// A first-order node's geometry: B = `identity` (packed), `reason` kept in B₀₀'s place.
    fn first_order_node(normal: [f32; 3], identity: [f32; 6], reason: Unresolved) -> Self {
        let mut packed_b = identity;
        packed_b[0] = -(reason as u8 as f32);
        NodeGeometry { normal, packed_b }
    }

    /// The entry `s` of the packed B ([`sym`]'s places): 1 in B₀₀'s place at a first-order node.
    #[inline(always)]
    pub fn b(&self, s: usize) -> f32 {
        let v = self.packed_b[s];
        if s == 0 && v < 0.0 {
            1.0
        } else {
            v
        }
    }

    /// A resolved node's geometry (tests).
    #[cfg(test)]
    pub(super) fn resolved_for_tests() -> Self {
        NodeGeometry {
            normal: [0.6, 0.8, 0.0],
            packed_b: [1.2, 0.1, 0.0, 1.1, 0.0, 1.0],
        }
    }

    /// This node's geometry at first order (B = I, its normal kept), for `reason`.
    pub(super) fn at_first_order<const D: usize>(&self, reason: Unresolved) -> Self {
        let mut identity = [0.0f32; 6];
        for k in 0..D {
            identity[sym(k, k)] = 1.0;
        }
        Self::first_order_node(self.normal, identity, reason)
    }

    /// Why the node runs the paper's first-order update (Eq. (3), B = I) instead of the
    /// second-order one: 0 where the local geometry is resolved, else one of the
    /// [`Unresolved`] reasons. Decided node by node ([`node_geometry`]): a crease, a corner, a
    /// noise spike, an unresolved curvature, a stencil cut by the box or the band's edge, or the
    /// rim of an open surface turns off second order only where it is. Kept in the sign of B₀₀'s
    /// place, so that a node's geometry is 36 bytes (a byte of its own would pad it to 40: 2 more
    /// bytes per band node, a rounded cube's order=2 memory 1.55× order=1's against 1.50).
    #[inline(always)]
    pub fn first_order(&self) -> u8 {
        if self.packed_b[0] < 0.0 {
            -self.packed_b[0] as u8
        } else {
            0
        }
    }

    /// The packed entries as stored (the digest reads them, the first-order reason included).
    #[inline(always)]
    pub fn packed(&self) -> &[f32; 6] {
        &self.packed_b
    }
}

/// Why a node's geometry is not resolved (the values of [`NodeGeometry::first_order`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Unresolved {
    /// A node of its 3^D stencil of φ is not in the band (the band's edge, the box's faces).
    Stencil = 1,
    /// |∇φ| is off 1 by more than [`super::GRAD_NORM_TOLERANCE`]: φ is not a distance there.
    Gradient = 2,
    /// A principal curvature κ with `outer_width`·κ ≥ 1, or I − φD²φ singular: a crease, a
    /// corner, noise, a curvature the tube does not resolve, or beyond an open surface's rim.
    Curvature = 3,
    /// The sweeps ran away here ([`super::demotion`]): the factored update is not causal.
    Runaway = 4,
}

/// Index of entry (k, l) of a packed symmetric matrix.
#[inline(always)]
pub(crate) const fn sym(k: usize, l: usize) -> usize {
    const IDX: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
    IDX[k][l]
}

/// What the geometry pass found about the surface, for the caller's checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometrySummary {
    /// The largest principal curvature |κ| at the foot points of the inner-tube nodes.
    pub max_curvature: f64,
    /// The smallest and largest |∇φ| (central differences) at the inner-tube nodes.
    pub grad_norm_min: f64,
    pub grad_norm_max: f64,
    /// Inner-tube nodes whose 3^D-stencil of φ was not all in the band (their geometry falls back
    /// to the given direction and B = I).
    pub incomplete_stencils: usize,
    /// Inner-tube nodes (fixed ones included) whose |∇φ| is off 1 by more than
    /// [`super::GRAD_NORM_TOLERANCE`], and those whose curvature the tube does not resolve
    /// ([`Unresolved`]): with the incomplete stencils, the nodes that run first order.
    pub off_distance: usize,
    pub unresolved_curvature: usize,
    /// All inner-tube nodes (the fraction's denominator).
    pub inner_nodes: usize,
    /// Inner-tube nodes whose central differences give |∇φ| off 1 by more than
    /// [`NOISY_GRADIENT`] (the measure of noise, [`Self::noisy`]).
    pub rough_gradients: usize,
    /// The count, sum and sum of squares of those |∇φ| (their spread, [`Self::noisy`]), in fixed
    /// point ([`MOMENT_SCALE`]): integers, so that the sums are the same whatever the split.
    pub gradient_moments: (usize, u128, u128),
    /// Whether every node's derivatives come from the local fit ([`super::local_fit`]): set
    /// before the pass when a first pass found φ noisy.
    pub fitted_everywhere: bool,
    /// The creases and corners of a level set among the nodes of unresolved curvature
    /// ([`super::creases`]), found after the pass.
    pub creases: Creases,
}

/// φ is taken as noisy, and the geometry computed again from the local fits at every node, when
/// the central differences give |∇φ| off 1 by more than [`NOISY_GRADIENT`] at more than this
/// fraction of the inner-tube nodes. Noise that makes some nodes fail the tests also spoils B at
/// the others (the sphere with Gaussian noise of 1e-3 at N = 121: a mean error on a meridian of
/// 2.6e-3 with the two-step fit only where the tests failed, 1.6e-3 with it everywhere, 7.3e-5
/// with the three-step fit ([`WIDE_FIT`]) everywhere; noise of 3e-4: 7.6e-4 by central
/// differences, 3.4e-5 fitted), while a rim, a crease or a box cut fails only where it is (the
/// hemisphere's rim: 4–9% of the tube at N = 81–161), where the central differences are the
/// more accurate ones (the hemisphere at N = 121: 6.3e-5 with the fit everywhere, against
/// 1.6e-5 without).
pub const NOISY_FRACTION: f64 = 0.25;

/// See [`NOISY_FRACTION`]: above the central differences' own error of |∇φ| on a resolved
/// signed distance ((Δx κ)²/3: no library surface reaches a quarter of its tube at any grid that
/// `order=2` accepts), below what noise of 0.02Δx gives (Gaussian noise of 3e-4 at N = 121: 43%
/// of the inner tube).
pub const NOISY_GRADIENT: f64 = 0.01;

/// See [`NOISY_FRACTION`]: noise also spreads |∇φ| (its standard deviation over the inner tube:
/// 0.0127 with Gaussian noise of 3e-4 at N = 121, 0.042 with 1e-3), while a signed distance
/// scaled by a constant, c·d, moves it as a whole (0.0010 at N = 41 and 0.0001 at N = 121 for
/// c = 0.97 or 0.9, every node off 1 by more than [`NOISY_GRADIENT`]). Such a φ is not noise, and
/// the fit everywhere only hid its real reason: it runs second order where |∇φ| is within
/// [`super::GRAD_NORM_TOLERANCE`] of 1 and is refused for its gradient elsewhere, which
/// `redistance=True` or dividing φ by c cures.
pub const NOISY_SPREAD: f64 = 0.5 * NOISY_GRADIENT;

/// See [`GeometrySummary::fit_is_kept`]: how much more of the inner tube the fit everywhere may
/// leave first order and still replace the central differences.
pub const SMOOTH_MARGIN: f64 = 0.1;

/// [`GeometrySummary::gradient_moments`]' fixed point: |∇φ| in units of 2⁻²⁴, capped at
/// [`MOMENT_CAP`] (a sum of squares of 2⁴⁸·10⁸ per node stays far inside u128 for any band).
const MOMENT_SCALE: f64 = 16_777_216.0;
const MOMENT_CAP: f64 = 1e4;

/// When φ is noisy ([`NOISY_FRACTION`]), the fit is taken over the nodes within three grid steps
/// (123 in 3D, 29 in 2D; at a node near the band's edge over those of them in the band), which
/// averages the noise out of the surface's closest points (x − φ∇φ) as well as out of B: the
/// sphere with noise of 1e-3 at N = 121, 7.3e-5 against 1.6e-3 with the two-step fit.
pub const WIDE_FIT: bool = true;

impl GeometrySummary {
    /// Nothing seen yet ([`Self::merge`]'s identity).
    pub(crate) fn empty() -> Self {
        GeometrySummary {
            max_curvature: 0.0,
            grad_norm_min: f64::INFINITY,
            grad_norm_max: 0.0,
            incomplete_stencils: 0,
            off_distance: 0,
            unresolved_curvature: 0,
            inner_nodes: 0,
            rough_gradients: 0,
            gradient_moments: (0, 0, 0),
            fitted_everywhere: false,
            creases: Creases::default(),
        }
    }

    /// Both parts' nodes (maxima, minima and counts: the same whatever the split).
    pub(crate) fn merge(self, other: Self) -> Self {
        GeometrySummary {
            max_curvature: self.max_curvature.max(other.max_curvature),
            grad_norm_min: self.grad_norm_min.min(other.grad_norm_min),
            grad_norm_max: self.grad_norm_max.max(other.grad_norm_max),
            incomplete_stencils: self.incomplete_stencils + other.incomplete_stencils,
            off_distance: self.off_distance + other.off_distance,
            unresolved_curvature: self.unresolved_curvature + other.unresolved_curvature,
            inner_nodes: self.inner_nodes + other.inner_nodes,
            rough_gradients: self.rough_gradients + other.rough_gradients,
            gradient_moments: (
                self.gradient_moments.0 + other.gradient_moments.0,
                self.gradient_moments.1 + other.gradient_moments.1,
                self.gradient_moments.2 + other.gradient_moments.2,
            ),
            fitted_everywhere: self.fitted_everywhere || other.fitted_everywhere,
            creases: Creases {
                nodes: self.creases.nodes + other.creases.nodes,
                angle: self.creases.angle.max(other.creases.angle),
                faces_angle: self.creases.faces_angle.max(other.creases.faces_angle),
            },
        }
    }

    /// Whether a pass with these counts found φ noisy ([`NOISY_FRACTION`]).
    pub fn noisy(&self) -> bool {
        let spread = self.gradient_mean_spread().1;
        !self.fitted_everywhere
            && self.rough_gradients as f64 > NOISY_FRACTION * self.inner_nodes as f64
            && spread > NOISY_SPREAD
    }

    /// Whether the pass with the fit everywhere (`fitted`, run because this pass found φ noisy)
    /// replaces this one: unless this one would run second order ([`super::check_geometry_of`])
    /// and the fit would not, or would leave more than [`SMOOTH_MARGIN`] more of the inner tube
    /// first order. Noise fails the central differences' tests and passes the fit's. What only
    /// looks like noise — |∇φ| off 1 by more than [`NOISY_GRADIENT`] at a quarter of the inner
    /// tube and spread — fails the fit's more widely, its three steps reaching further off: a φ
    /// smooth but not a distance (0.4·tanh(d/0.4) at N = 41, |∇φ| falling from 1 to 0.94 across
    /// the inner tube: 15% of it first order by central differences, 49% fitted, 10% short at
    /// order 1, 0.9% at order 2), and a signed distance on a coarse grid ((Δx·κ)²/3 ≈ 0.04 at the
    /// sphere's inner edge at N = 20: no node first order by central differences, most of the tube
    /// fitted; 22% short at the antipode at order 1, 5.6% at order 2).
    pub(crate) fn fit_is_kept(&self, fitted: &Self, outer_width: f64, spacing: f64, closest_point: bool) -> bool {
        if super::check_geometry_of(self, outer_width, spacing, closest_point).is_err() {
            // both refused (the solve runs first order): the reason that leads. Where the central
            // differences fail almost only for |∇φ|, φ is not a distance, which the fit reads as
            // curvature (an ellipsoid's algebraic distance c·(|x/a, y/b, z/c| − 1), |∇φ| down to
            // 0.36: 94% "curvature" fitted); noise fails both tests alike (0.3Δx re-distanced:
            // 3716 |∇φ|, 2852 curvature), and the fit's reason stays
            return self.off_distance <= 3 * (self.unresolved_curvature + self.incomplete_stencils);
        }
        super::check_geometry_of(fitted, outer_width, spacing, closest_point).is_ok()
            && fitted.first_order_nodes() as f64
                <= self.first_order_nodes() as f64 + SMOOTH_MARGIN * self.inner_nodes as f64
    }

    /// The mean and standard deviation of |∇φ| by central differences over the inner tube (0
    /// and 0 when none was measured).
    pub fn gradient_mean_spread(&self) -> (f64, f64) {
        let (count, sum, squares) = self.gradient_moments;
        let n = count.max(1) as f64;
        let mean = sum as f64 / MOMENT_SCALE / n;
        let spread = (squares as f64 / (MOMENT_SCALE * MOMENT_SCALE) / n - mean * mean)
            .max(0.0)
            .sqrt();
        (mean, spread)
    }

    /// The inner-tube nodes that run the first-order update (every [`Unresolved`] reason).
    pub fn first_order_nodes(&self) -> usize {
        self.incomplete_stencils + self.off_distance + self.unresolved_curvature
    }

    /// After the last node: no node with a stencil gives a minimum |∇φ| of 0.
    pub(crate) fn finish(&mut self) {
        if !self.grad_norm_min.is_finite() {
            self.grad_norm_min = 0.0;
        }
    }
}

/// The geometry of one inner-tube node from φ there (`phi`, signed), its outward direction
/// sgn(φ) n and φ's differences `local` ([`Implicit::local`], None for an incomplete stencil),
/// decided node by node: where the local geometry is resolved — a complete stencil, |∇φ| within
/// [`super::GRAD_NORM_TOLERANCE`] of 1 and every principal curvature κ at the foot point with
/// `outer_width`·κ < 1 — n = ∇φ/|∇φ| and B = (I − φD²φ)⁻¹ for the second-order update. Where
/// the central differences fail those tests, `refit` gives the noise-robust derivatives
/// ([`Implicit::local_fitted`]); if they pass, they replace `local` (which the factoring reads
/// next). Elsewhere the node is marked [`NodeGeometry::first_order`] with its reason, and gets
/// the given direction times sgn(φ) and B = I (the paper's Eq. (3) at that node). What it finds
/// goes into `summary`: the counts, and the extremes of |∇φ| and κ over the resolved nodes.
pub(crate) fn node_geometry<const D: usize>(
    phi: f64,
    direction: &[f32; D],
    local: &mut Option<LocalGeometry<D>>,
    outer_width: f64,
    summary: &mut GeometrySummary,
    refit: impl FnOnce() -> Option<LocalGeometry<D>>,
) -> NodeGeometry {
    let mut identity = [0.0f32; 6];
    for k in 0..D {
        identity[sym(k, k)] = 1.0;
    }
    let sign = if phi < 0.0 { -1.0f32 } else { 1.0 };
    let mut normal = [0.0f32; 3];
    for k in 0..D {
        normal[k] = sign * direction[k];
    }
    summary.inner_nodes += 1;
    let Some(found) = local.as_ref() else {
        summary.incomplete_stencils += 1;
        return NodeGeometry::first_order_node(normal, identity, Unresolved::Stencil);
    };
    let first = if summary.fitted_everywhere {
        Err(Unresolved::Curvature)
    } else {
        resolve(found, outer_width, summary.max_curvature)
    };
    if !summary.fitted_everywhere {
        let norm = found.gradient.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !((norm - 1.0).abs() <= NOISY_GRADIENT) {
            summary.rough_gradients += 1;
        }
        if norm.is_finite() {
            let q = (norm.min(MOMENT_CAP) * MOMENT_SCALE).round() as u128;
            let m = &mut summary.gradient_moments;
            *m = (m.0 + 1, m.1 + q, m.2 + q * q);
        }
    }
    let resolved = match first {
        Ok(r) => r,
        Err(reason) => match refit().map(|f| (resolve(&f, outer_width, summary.max_curvature), f)) {
            Some((Ok(r), fitted)) => {
                *local = Some(fitted);
                r
            }
            _ => {
                match reason {
                    Unresolved::Gradient => summary.off_distance += 1,
                    _ => summary.unresolved_curvature += 1,
                }
                return NodeGeometry::first_order_node(normal, identity, reason);
            }
        },
    };
    summary.max_curvature = summary.max_curvature.max(resolved.kappa);
    summary.grad_norm_min = summary.grad_norm_min.min(resolved.norm);
    summary.grad_norm_max = summary.grad_norm_max.max(resolved.norm);
    normal[..D].copy_from_slice(&resolved.normal);
    debug_assert!(resolved.b[0] > 0.0, "B is positive definite at a resolved node");
    NodeGeometry {
        normal,
        packed_b: resolved.b,
    }
}

/// What [`resolve`] finds at a resolved node.
struct Resolved<const D: usize> {
    normal: [f32; D],
    b: [f32; 6],
    /// |∇φ|, and the largest principal curvature when it may exceed `largest` (else 0).
    norm: f64,
    kappa: f64,
}

/// n and B from φ's derivatives at a node, or why the node is not resolved; `largest` is the
/// largest curvature found so far (only a node that may exceed it, or the tube's bound, gets its
/// eigenvalues computed: [`curvatures_below`]).
fn resolve<const D: usize>(
    local: &LocalGeometry<D>,
    outer_width: f64,
    largest: f64,
) -> std::result::Result<Resolved<D>, Unresolved> {
    let (g, hess) = (local.gradient, local.hessian);
    // φ in the orientation of the differences (the same as `phi` for a level set)
    let p = local.phi;
    let norm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !((norm - 1.0).abs() <= super::GRAD_NORM_TOLERANCE) {
        return Err(Unresolved::Gradient);
    }
    // principal curvatures at the foot point from the eigenvalues at height φ
    let bound = 1.0 / outer_width;
    let mut kappa = 0.0f64;
    if !curvatures_below(&hess, p, largest.min(bound)) {
        for lam in symmetric_eigenvalues(&hess).iter().take(D) {
            let den = 1.0 - p * lam;
            kappa = kappa.max(if den > 0.0 { (lam / den).abs() } else { f64::INFINITY });
        }
        if !(kappa < bound) {
            return Err(Unresolved::Curvature);
        }
    }
    let mut m = [[0.0; D]; D];
    for k in 0..D {
        for l in 0..D {
            m[k][l] = if k == l { 1.0 } else { 0.0 } - p * hess[k][l];
        }
    }
    let inverse = symmetric_inverse(&m).ok_or(Unresolved::Curvature)?;
    let mut out = Resolved {
        normal: [0.0; D],
        b: [0.0; 6],
        norm,
        kappa,
    };
    for k in 0..D {
        out.normal[k] = (g[k] / norm) as f32;
        for l in k..D {
            out.b[sym(k, l)] = (0.5 * (inverse[k][l] + inverse[l][k])) as f32;
        }
    }
    Ok(out)
}

/// The geometry of the inner-tube nodes and the surface summary.
pub struct TubeGeometry {
    /// One entry per node that is not in the extension layer, in band order (the k-th such node's
    /// is `nodes[k]`: the sweeps count them along each row, [`crate::second_order::solver`]).
    pub nodes: Vec<NodeGeometry>,
    /// |φ| per node, in units of a power of two near the spacing ([`power_of_two_near`]), apart
    /// from the rest: the extension update only compares it between neighbours.
    pub abs_phi: Vec<f32>,
    pub summary: GeometrySummary,
}

/// φ's central-difference gradient and Hessian at node `n`, φ at band node j being `phi(j)`, or
/// None when a node of its 3^D-stencil (axis and diagonal neighbours) is not in the band.
pub(crate) fn gradient_and_hessian_by<const D: usize>(
    band: &NarrowBand<D>,
    n: usize,
    h: f64,
    phi: impl Fn(usize) -> f64,
) -> Option<([f64; D], [[f64; D]; D])> {
    let sentinel = band.sentinel();
    let nb = band.neighbours_of(n);
    let mut g = [0.0; D];
    let mut hess = [[0.0; D]; D];
    let p0 = phi(n);
    for k in 0..D {
        let (m, p) = (nb[k][0], nb[k][1]);
        if m == sentinel || p == sentinel {
            return None;
        }
        let (pm, pp) = (phi(m as usize), phi(p as usize));
        g[k] = (pp - pm) / (2.0 * h);
        hess[k][k] = (pp - 2.0 * p0 + pm) / (h * h);
        for l in k + 1..D {
            // φ(x ± h e_k ± h e_l) through the neighbours' neighbours along l
            let mut corner = [[0.0; 2]; 2];
            for (sk, &a) in [m, p].iter().enumerate() {
                let nba = band.neighbours_of(a as usize);
                for sl in 0..2 {
                    let c = nba[l][sl];
                    if c == sentinel {
                        return None;
                    }
                    corner[sk][sl] = phi(c as usize);
                }
            }
            let v = (corner[1][1] - corner[1][0] - corner[0][1] + corner[0][0]) / (4.0 * h * h);
            hess[k][l] = v;
            hess[l][k] = v;
        }
    }
    Some((g, hess))
}

/// The geometry of the inner-tube nodes of `band` (the nodes not in the extension layer, in band
/// order): `phi` (signed, per node), `directions` the outward unit
/// directions sgn(φ) n the solver's extension reads (per node), `roles` to know the inner tube,
/// `outer_width` the tube's half-width (outer·Δx), which bounds the curvature a node may have
/// and still run second order ([`node_geometry`]).
pub fn tube_geometry<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    phi: &[f64],
    directions: &[[f32; D]],
    spacing: f64,
    outer_width: f64,
) -> Result<TubeGeometry> {
    tube_geometry_of(band, roles, &Implicit::LevelSet(phi), directions, spacing, outer_width)
}

/// As [`tube_geometry`] for a level set or a closest-point map ([`Implicit`]).
pub fn tube_geometry_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    spacing: f64,
    outer_width: f64,
) -> Result<TubeGeometry> {
    let (nodes, mut summary) = geometry_pass(band, roles, surface, directions, spacing, outer_width, true)?;
    if !surface.is_closest_point() && !summary.fitted_everywhere {
        summary.creases = creases_of(band, roles, surface, spacing, directions, &nodes);
    }
    let abs_phi = abs_phi_of(surface, spacing);
    Ok(TubeGeometry {
        nodes,
        abs_phi,
        summary,
    })
}

/// The pass of [`tube_geometry_of`] without the creases: every inner node's geometry (in band
/// order) and the summary, the nodes fitted everywhere when φ is noisy. In parallel over runs of
/// [`GEOMETRY_CHUNK`] band nodes; the summary merges maxima, minima and counts, so it and the
/// nodes are the same whatever the split. `fit_noise` false: where φ is noisy the summary says
/// `fitted_everywhere` without the fitted pass (for a crease report, which a noisy φ skips).
pub(crate) fn geometry_pass<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    spacing: f64,
    outer_width: f64,
    fit_noise: bool,
) -> Result<(Vec<NodeGeometry>, GeometrySummary)> {
    let n = band.len();
    check_tube_inputs(n, roles, surface, directions, spacing, outer_width)?;
    let empty = |fitted: bool| GeometrySummary {
        fitted_everywhere: fitted,
        ..GeometrySummary::empty()
    };
    let pass = |fitted: bool| {
        let parts: Vec<(Vec<NodeGeometry>, GeometrySummary)> = (0..n.div_ceil(GEOMETRY_CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut summary = empty(fitted);
                let mut nodes = Vec::new();
                for i in c * GEOMETRY_CHUNK..((c + 1) * GEOMETRY_CHUNK).min(n) {
                    if roles[i] != NodeRole::Outer {
                        let mut local = surface.local(band, i, spacing);
                        nodes.push(node_geometry(
                            surface.phi(i),
                            &directions[i],
                            &mut local,
                            outer_width,
                            &mut summary,
                            || surface.local_fitted(band, i, spacing, WIDE_FIT && fitted),
                        ));
                    }
                }
                (nodes, summary)
            })
            .collect();
        let inner = parts.iter().map(|p| p.0.len()).sum();
        let mut nodes = Vec::with_capacity(inner);
        let mut summary = empty(fitted);
        for (part, s) in parts {
            nodes.extend(part);
            summary = summary.merge(s);
        }
        (nodes, summary)
    };
    let (mut nodes, mut summary) = pass(false);
    if summary.noisy() && !fit_noise {
        summary.fitted_everywhere = true;
    } else if summary.noisy() {
        let (fitted_nodes, fitted_summary) = pass(true);
        if summary.fit_is_kept(&fitted_summary, outer_width, spacing, surface.is_closest_point()) {
            (nodes, summary) = (fitted_nodes, fitted_summary);
        }
    }
    summary.finish();
    Ok((nodes, summary))
}

/// Band nodes per task of [`geometry_pass`].
const GEOMETRY_CHUNK: usize = 4096;

/// One role, φ and direction per band node (`n`), and a positive finite spacing: what the
/// geometry ([`tube_geometry_of`]) and the one-pass set-up ([`super::tube_setup_of`]) read.
pub(crate) fn check_tube_inputs<const D: usize>(
    n: usize,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    spacing: f64,
    outer_width: f64,
) -> Result<()> {
    if roles.len() != n || surface.len() != n || directions.len() != n {
        return Err(Error::invalid(
            "phi",
            format!("roles, phi and directions need one entry per band node ({n})"),
        ));
    }
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(Error::invalid(
            "spacing",
            format!("must be positive and finite, got {spacing}"),
        ));
    }
    if !(outer_width > 0.0 && outer_width.is_finite()) {
        return Err(Error::invalid(
            "outer_width",
            format!("must be positive and finite, got {outer_width}"),
        ));
    }
    Ok(())
}

/// |φ| per node in units of a power of two near the spacing: f32 then holds |φ| on a grid in
/// any units (it under- or overflowed beyond about 1e±38), and the comparisons keep their bits.
pub(crate) fn abs_phi_of<const D: usize>(surface: &Implicit<'_, D>, spacing: f64) -> Vec<f32> {
    let unit = power_of_two_near(spacing);
    (0..surface.len())
        .map(|i| (surface.phi(i).abs() / unit) as f32)
        .collect()
}

/// The power of two nearest `x` (> 0, finite) in the log: dividing by it is exact, so a quantity
/// of size about `x` is stored in f32 with the same bits as before, in any units.
pub(crate) fn power_of_two_near(x: f64) -> f64 {
    2f64.powi((x.log2().round() as i32).clamp(-1000, 1000))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_s_geometry_is_36_bytes_and_keeps_its_first_order_reason_in_b() {
        // 2 bytes per band node more with a byte of its own (issue 31's memory target)
        assert_eq!(std::mem::size_of::<NodeGeometry>(), 36);
        let mut identity = [0.0f32; 6];
        for k in 0..3 {
            identity[sym(k, k)] = 1.0;
        }
        for reason in [Unresolved::Stencil, Unresolved::Gradient, Unresolved::Curvature] {
            let g = NodeGeometry::first_order_node([0.0, 0.0, 1.0], identity, reason);
            assert_eq!(g.first_order(), reason as u8);
            assert_eq!((0..6).map(|s| g.b(s)).collect::<Vec<_>>(), identity.to_vec());
        }
        let b = [1.25f32, 0.1, 0.0, 0.75, 0.0, 1.0];
        let g = NodeGeometry {
            normal: [1.0, 0.0, 0.0],
            packed_b: b,
        };
        assert_eq!(g.first_order(), 0);
        assert_eq!((0..6).map(|s| g.b(s)).collect::<Vec<_>>(), b.to_vec());
    }

    /// The set-up's largest curvature is the one every node's eigenvalues give, bit for bit.
    #[test]
    fn the_largest_curvature_is_every_nodes_maximum() {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let (phi, _) = crate::test_bands::sphere_phi_and_offsets(&band, h);
        let surface = Implicit::LevelSet(&phi);
        let geo = tube_geometry_of(&band, &roles, &surface, &dirs, h, 4.0 * h).unwrap();
        let mut max = 0.0f64;
        for i in 0..band.len() {
            if roles[i] == NodeRole::Outer {
                continue;
            }
            if let Some(local) = surface.local(&band, i, h) {
                for lam in symmetric_eigenvalues(&local.hessian) {
                    let den = 1.0 - local.phi * lam;
                    max = max.max(if den > 0.0 { (lam / den).abs() } else { f64::INFINITY });
                }
            }
        }
        assert_eq!(geo.summary.max_curvature.to_bits(), max.to_bits());
        assert!((max - 2.0).abs() < 0.1, "{max}");
    }

    #[test]
    fn sphere_geometry_has_b_equal_to_one_plus_phi_kappa_tangentially() {
        // sphere of radius 0.5 on 41³ nodes over [−1, 1]³: B's tangential eigenvalues are 1 + φ/R,
        // its normal one 1, to the central differences' O(h²)
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let idx = band.indices();
        let phi: Vec<f64> = idx
            .iter()
            .map(|i| {
                let x: Vec<f64> = i.iter().map(|&c| -1.0 + h * c as f64).collect();
                (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.5
            })
            .collect();
        let geo = tube_geometry(&band, &roles, &phi, &dirs, h, 4.0 * h).unwrap();
        assert_eq!(geo.summary.incomplete_stencils, 0);
        assert!((geo.summary.max_curvature - 2.0).abs() < 0.05, "{:?}", geo.summary);
        assert!((geo.summary.grad_norm_max - 1.0).abs() < 0.01 && (geo.summary.grad_norm_min - 1.0).abs() < 0.01);
        let mut worst: f64 = 0.0;
        let inner = (0..band.len()).filter(|&i| roles[i] != NodeRole::Outer);
        for (i, g) in inner.zip(&geo.nodes) {
            if roles[i] != NodeRole::Inner {
                continue;
            }
            let mut m = [[0.0; 3]; 3];
            for k in 0..3 {
                for l in 0..3 {
                    m[k][l] = g.b(sym(k, l)) as f64;
                }
            }
            let mut e = symmetric_eigenvalues(&m);
            e.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let t = 1.0 + phi[i] / 0.5;
            let want = if t < 1.0 { [t, t, 1.0] } else { [1.0, t, t] };
            for (a, b) in e.iter().zip(want) {
                worst = worst.max((a - b).abs());
            }
        }
        assert!(worst < 0.01, "worst B eigenvalue deviation {worst}");
    }
}
