//! Creases and corners of φ's level sets: where they are, and how much they cost.
//!
//! Across a crease the normal n = ∇φ/|∇φ| jumps. In the tube the paper's equation (its Eq. (3),
//! |P∇u| = 1/F with P = I − nnᵀ) lets the front move along n for free, so on the side of the crease
//! where the tubes of the two faces overlap (inside a convex edge, outside a concave one) a path
//! runs up one face's normal to the bisector and down the other's: the front arrives early by
//! about 2·inner·Δx·tan(θ/2) per crease it crosses, θ the angle between the two faces' normals,
//! whatever the order of the update (the cube max|x| − 0.5, θ = 90°, from the bottom centre to
//! the top centre: 1.575 at N = 41 and 1.779 at N = 81 instead of 2.0, 4.25Δx and 4.42Δx per
//! edge with inner = 2; 2.45Δx and 2.51Δx with inner = 1). That error is first order in Δx.
//!
//! The crease nodes are the inner-tube nodes within [`CREASE_REACH`] grid spacings of a level set
//! whose geometry is unresolved by its curvature or its gradient ([`Unresolved::Curvature`]: a convex edge; [`Unresolved::Gradient`]:
//! the central differences across a kink of φ = min(φ₁, φ₂) give |∇φ| < 1), whose normal turns
//! by more than [`CREASE_ANGLE`] degrees to a neighbour's (noise, a φ that is not a distance and a
//! curvature resolved by the grid turn it by much less) and where φ has a kink: |∇φ| by central
//! differences off 1 by more than [`GRAD_NORM_TOLERANCE`] (across a kink they average the two
//! faces' gradients, |∇φ| ≈ cos(θ/2), where a smooth surface that the grid barely resolves, such
//! as the tip of the spheroid 0.25/0.25/0.5 at N = 41, keeps |∇φ| ≈ 1); or, for shallower
//! creases, whose neighbours turn by less, by more than [`SHALLOW_CREASE_ANGLE`] degrees where
//! φ's central differences are shorter than its one-sided ones ([`kink_ratio`] under [`KINK_RATIO`]).
//! Closest-point maps are left out (beyond the rim of an open surface the directions turn
//! around the rim, which is not a crease), and so is a noisy φ (`fitted_everywhere`: its normals
//! turn by tens of degrees between neighbours where the noise spikes; the sphere with noise of
//! 3e-3 at N = 121 re-distanced showed six such nodes).

use rayon::prelude::*;

use crate::band::facing_sheets::check_node_fields;
use crate::band::NarrowBand;
use crate::error::Result;
use crate::sweep::NodeRole;

use super::geometry::{geometry_pass, NodeGeometry, Unresolved};
use super::implicit::Implicit;
use super::GRAD_NORM_TOLERANCE;

/// The smallest turn of the normal between neighbouring nodes, in degrees, that marks a crease:
/// above what a smooth surface gives where the grid barely resolves it (the torus 0.5/0.2 at
/// N = 41, κΔx = 0.25: up to 28° between neighbours on the inner side of its tube), below the
/// creases of the library and the tests (the double torus: 54–56°, two spheres joined by `min`
/// and the cube: 90°).
pub const CREASE_ANGLE: f64 = 40.0;

/// A shallower crease is found where the normal turns by more than this many degrees between
/// neighbours and φ's central differences are shorter than its one-sided ones by [`KINK_RATIO`]
/// ([`kink_ratio`]): next to a crease the central differences average the two faces' gradients
/// and neighbours turn by about half the faces' angle, so faces meeting at 60° (a lens of two
/// spheres cut by `max`) turned by 35°, under [`CREASE_ANGLE`], and went unreported while the
/// front cut their corner (1.2–1.4Δx early on average at N = 81–121 at second order, 2.2–2.4Δx at
/// first: a helper's review; `benches/experiments/shallow_creases.py`).
pub const SHALLOW_CREASE_ANGLE: f64 = 20.0;

/// [`kink_ratio`] below which φ has a kink at a node: cos(θ/2) across a crease whose faces meet
/// at θ (0.92–0.94 next to the 60° lens and union at N = 61–121, 0.96 at 40°, which stays
/// unreported), while a smooth φ that the grid resolves reads within a few thousandths of 1 (the
/// sphere, the torus (0.5, 0.2), the quadric of the ellipsoid (0.8, 0.5, 0.3) from N = 31 on;
/// coarser grids, where they dip below it, turn their normals by over [`CREASE_ANGLE`] anyway).
/// Scale-free, unlike the test of |∇φ| against 1, so a φ that is no distance does not read as
/// kinked everywhere.
pub const KINK_RATIO: f64 = 0.95;

/// Whether the unit normal `normal` is ∇φ/|∇φ| of the central differences `gradient` (within
/// 0.5°): the directions of a φ given as it is, not those of its closest points.
fn central_differences_agree<const D: usize>(gradient: &[f64; D], normal: &[f64; D]) -> bool {
    let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
    norm > 0.0 && (0..D).map(|k| gradient[k] * normal[k]).sum::<f64>() / norm > 0.5f64.to_radians().cos()
}

/// |∇φ| by central differences at node `i` over the mean of its forward and backward differences'
/// norms (`phi`: φ per node; None where an axis neighbour is not in the band): 1 for a linear φ,
/// 1 − O((κΔx)²) for a smooth one, about cos(θ/2) next to a crease whose faces meet at θ.
pub fn kink_ratio<const D: usize>(
    band: &NarrowBand<D>,
    i: usize,
    spacing: f64,
    phi: impl Fn(usize) -> f64,
) -> Option<f64> {
    let sentinel = band.sentinel();
    let here = phi(i);
    let (mut central, mut forward, mut backward) = (0.0f64, 0.0f64, 0.0f64);
    for pair in band.neighbours_of(i).iter() {
        if pair[0] == sentinel || pair[1] == sentinel {
            return None;
        }
        let fwd = (phi(pair[1] as usize) - here) / spacing;
        let bwd = (here - phi(pair[0] as usize)) / spacing;
        central += 0.25 * (fwd + bwd) * (fwd + bwd);
        forward += fwd * fwd;
        backward += bwd * bwd;
    }
    let one_sided = 0.5 * (forward.sqrt() + backward.sqrt());
    (one_sided > 0.0).then(|| central.sqrt() / one_sided)
}

/// Crease nodes lie within this many grid spacings of the surface (|φ| ≤ 0.75Δx), where a
/// crease's kink of φ meets the surface: further out, the normals of a smooth surface the grid
/// barely resolves turn fast near its focal points (the spheroid 0.25/0.25/0.5 at N = 41: up to
/// 29° between neighbours within 1.5Δx, 39° beyond), and a re-distanced φ has kinks midway
/// across the narrow channels of a surface that faces itself (the gyroid-like φ of issue 43 at
/// N = 41: 192 nodes turning by up to 66° within 1.5Δx, none within 0.75Δx), while across a
/// crease the normals turn by its angle at every distance (the cube: 55° by central differences
/// at every |φ| ≤ 2Δx; 236 crease nodes at N = 41, the double torus 30 at N = 81).
pub const CREASE_REACH: f64 = 0.75;

/// The crease nodes of a tube and the largest turn of the normal there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Creases {
    /// Inner-tube nodes at a crease or corner (see the module documentation).
    pub nodes: usize,
    /// The largest angle, in degrees, between a crease node's normal and a neighbour's
    /// ([`creases_of`]); [`creases_of_level_set`] also reads it from the neighbour on one side to
    /// the one on the other (the faces' angle: 90° on the cube, where neighbours turn by 55°).
    pub angle: f64,
    /// The faces' largest angle, in degrees: the widest turn of the normal across a crease node,
    /// from the neighbour on one side to the one on the other, or to a neighbour. Where the
    /// directions come from central differences of φ (a φ = max(φ₁, φ₂) given as it is), they
    /// average the two faces' normals next to the crease and neighbours turn by about half of
    /// it: a lens whose faces meet at 113° turned by 52–61° between neighbours (a review).
    pub faces_angle: f64,
}

impl Creases {
    /// How early, in units of inner·Δx, a front arrives after crossing a crease whose faces'
    /// normals differ by `self.angle`: 2·tan(θ/2) (capped at θ = 150°).
    pub fn shortcut_per_inner_width(&self) -> f64 {
        2.0 * (self.angle.min(150.0).to_radians() / 2.0).tan()
    }
}

/// The creases among the inner-tube nodes of `band` (`nodes`: their geometry, in band order, one
/// per node whose role is not [`NodeRole::Outer`]), from the given unit directions (away from the
/// surface: sgn(φ)∇φ/|∇φ|, turned back into ∇φ/|∇φ| by φ's sign).
pub fn creases_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    spacing: f64,
    directions: &[[f32; D]],
    nodes: &[NodeGeometry],
) -> Creases {
    let found = crease_nodes_of(band, roles, surface, spacing, directions, nodes);
    let smallest = found.iter().map(|&(_, c, _)| c).fold(1.0f64, f64::min);
    let widest = found.iter().map(|&(_, _, w)| w).fold(1.0f64, f64::min);
    creases_from(found.len(), smallest, widest)
}

/// The creases found: `nodes` of them, the smallest cosine of a turn to a neighbour there
/// `smallest`, of a turn across a node `widest`.
fn creases_from(nodes: usize, smallest: f64, widest: f64) -> Creases {
    let mut found = Creases::default();
    if nodes > 0 {
        found.nodes = nodes;
        found.angle = smallest.clamp(-1.0, 1.0).acos().to_degrees();
        found.faces_angle = widest.clamp(-1.0, 1.0).acos().to_degrees();
    }
    found
}

/// The crease nodes of [`creases_of`] (band positions) with the cosines of the largest turn of
/// the normal from each to an axis neighbour and across it ([`widest_turn`]).
fn crease_nodes_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    spacing: f64,
    directions: &[[f32; D]],
    nodes: &[NodeGeometry],
) -> Vec<(usize, f64, f64)> {
    let normal = |i: usize| {
        let s = if surface.phi(i) < 0.0 { -1.0 } else { 1.0 };
        let mut n = [0.0f64; D];
        for c in 0..D {
            n[c] = s * directions[i][c] as f64;
        }
        n
    };
    let threshold = CREASE_ANGLE.to_radians().cos();
    let shallow = SHALLOW_CREASE_ANGLE.to_radians().cos();
    let sentinel = band.sentinel();
    let mut found = Vec::new();
    let mut k = 0usize;
    for (i, role) in roles.iter().enumerate() {
        if *role == NodeRole::Outer {
            continue;
        }
        let geo = &nodes[k];
        k += 1;
        if geo.first_order() != Unresolved::Curvature as u8 && geo.first_order() != Unresolved::Gradient as u8
            || surface.phi(i).abs() > CREASE_REACH * spacing
        {
            continue;
        }
        let cos_min = smallest_turn(band, i, |j| Some(normal(j)));
        // a kink of φ there: central differences across it average the two faces' gradients,
        // |∇φ| ≈ cos(θ/2) (a smooth surface the grid barely resolves keeps |∇φ| ≈ 1); None where
        // node j has no local fit
        let kink_at = |j: usize| {
            surface.local(band, j, spacing).map(|l| {
                let norm = l.gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
                (norm - 1.0).abs() > GRAD_NORM_TOLERANCE
            })
        };
        // at the node, or at an axis neighbour within a spacing of the surface: a node within a
        // few hundredths of a spacing of a concave crease's edge can fit |∇φ| ≈ 1 while its
        // normal turns by 90° to the next node (two spheres of radius 0.5 joined by min, centres
        // 0.6 apart, re-distanced: no crease node at N = 61 and 121, 8–10 at N = 41, 81 and 161,
        // though the tube was thinned there each time and the far sphere came out 0.27–0.36Δx
        // late on average; within 0.75Δx N = 121 had none again). Neighbours farther out read
        // the medial sheet inside a thin part's rim (the ellipsoid 0.6/0.5/0.15 re-distanced at
        // N = 61–81: 100 "crease" nodes, a review); within a spacing such a rim of a radius near
        // a spacing still counts, as the edge it is for the tube (the refusal says so)
        let near_kink = |j: usize| surface.phi(j).abs() <= (CREASE_REACH + 0.25) * spacing && kink_at(j) == Some(true);
        let kink = || {
            kink_at(i).unwrap_or(true)
                || band
                    .neighbours_of(i)
                    .iter()
                    .flatten()
                    .any(|&j| j != sentinel && near_kink(j as usize))
        };
        // (only where the directions are φ's central differences, which blur a crease: directions
        // from closest points, a re-distanced φ's, turn by the faces' angle between neighbours)
        let shallow_kink = || {
            cos_min < shallow
                && surface
                    .local(band, i, spacing)
                    .is_some_and(|l| central_differences_agree(&l.gradient, &normal(i)))
                && kink_ratio(band, i, spacing, |j| surface.phi(j)).is_some_and(|r| r < KINK_RATIO)
        };
        if (cos_min < threshold && kink()) || shallow_kink() {
            // (a node on the surface has no direction: left out of the faces' angle)
            let faces_normal = |j: usize| Some(normal(j)).filter(|n| n.iter().any(|&c| c != 0.0));
            found.push((i, cos_min, widest_turn(band, i, cos_min, faces_normal)));
        }
    }
    found
}

/// The creases of a re-distanced level set in the paper's tube, for the first-order scheme
/// (`order=1`), found by the second-order geometry's own test ([`creases_of`] behind the gates of
/// [`super::geometry::tube_geometry`]: a node whose curvature or gradient the central differences do not resolve,
/// and no crease on a φ found noisy). [`creases_of_level_set`], without those gates, reads the
/// kinks of a re-distanced φ's samples as creases (a voxel mask's staircase, the bumps of noise);
/// the gates keep them out. The paper's tube's report gives the faces' angle (`faces_angle`, the
/// widest turn across a crease node, as [`creases_of_level_set`] reports it); `angle`, the turn
/// between neighbours, tells a sharp crease (as wide) from a rounded one (narrower). `roles`: the paper's tube (inner and extension
/// nodes), `outer_width` its half-width (outer·Δx), which the curvature gate reads. Costs the
/// geometry pass of a second-order solve (36 bytes per inner node while it runs). None where φ
/// is found noisy and no crease is looked for (the caller may look through a smoothing instead).
pub fn creases_of_redistanced<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    phi: &[f64],
    directions: &[[f32; D]],
    spacing: f64,
    outer_width: f64,
) -> Result<Option<Creases>> {
    let surface = Implicit::LevelSet(phi);
    let (nodes, summary) = geometry_pass(band, roles, &surface, directions, spacing, outer_width, false)?;
    if summary.fitted_everywhere {
        return Ok(None);
    }
    Ok(Some(creases_of(band, roles, &surface, spacing, directions, &nodes)))
}

/// The cosine of the faces' angle at crease node `i`: the widest turn of the normal from one side
/// of the node to the other along an axis, or to a neighbour (`cos_min`). Across a crease the
/// central differences average the faces' normals at the nodes next to it, so neighbours turn by
/// less: the cube's 90° edges by 55°.
fn widest_turn<const D: usize>(
    band: &NarrowBand<D>,
    i: usize,
    cos_min: f64,
    normal: impl Fn(usize) -> Option<[f64; D]>,
) -> f64 {
    let sentinel = band.sentinel();
    let mut widest = cos_min;
    for pair in band.neighbours_of(i).iter() {
        if pair[0] != sentinel && pair[1] != sentinel {
            if let Some(cos) = cos_between(&normal, pair[0], pair[1]) {
                widest = widest.min(cos);
            }
        }
    }
    widest
}

/// The cosine of the turn between the normals at nodes `p` and `q` (None where either has none).
fn cos_between<const D: usize>(normal: &impl Fn(usize) -> Option<[f64; D]>, p: u32, q: u32) -> Option<f64> {
    let (np, nq) = (normal(p as usize)?, normal(q as usize)?);
    Some((0..D).map(|c| np[c] * nq[c]).sum())
}

/// [`widest_turn`] (`widest`) widened by the turns across node `i` between its diagonal
/// neighbours in each plane of two axes (`i + e_a ± e_b` against `i − e_a ∓ e_b`). Where the
/// normals come from φ's central differences they blur the faces next to a crease, more so
/// along the axes: a box's exact distance with its 90° edges on nodes read 78° across the axis
/// pairs (the paper's tube's warning then said 3.3Δx per edge where fronts came out 4.0–4.3Δx
/// early), and the diagonal pairs beside an edge node have the faces' own normals.
fn widest_turn_diagonally<const D: usize>(
    band: &NarrowBand<D>,
    i: usize,
    widest: f64,
    normal: impl Fn(usize) -> Option<[f64; D]>,
) -> f64 {
    let sentinel = band.sentinel();
    // the neighbour of `j` along `axis` on `side` (0: below, 1: above), if in the band
    let step = |j: u32, axis: usize, side: usize| -> Option<u32> {
        (j != sentinel)
            .then(|| band.neighbours_of(j as usize)[axis][side])
            .filter(|&k| k != sentinel)
    };
    let here = band.neighbours_of(i);
    let mut widest = widest;
    for a in 0..D {
        for b in a + 1..D {
            for side in 0..2 {
                // i + e_a + (side? −e_b : +e_b) against i − e_a + (side? +e_b : −e_b)
                let p = step(here[a][1], b, 1 - side);
                let q = step(here[a][0], b, side);
                if let Some(cos) = p.zip(q).and_then(|(p, q)| cos_between(&normal, p, q)) {
                    widest = widest.min(cos);
                }
            }
        }
    }
    widest
}

/// The cosine of the largest turn of the normal from node `i` to its axis neighbours in the band
/// (1 when none turns); `normal(j)` is None where node `j` has no direction (a node on the surface).
fn smallest_turn<const D: usize>(band: &NarrowBand<D>, i: usize, normal: impl Fn(usize) -> Option<[f64; D]>) -> f64 {
    let sentinel = band.sentinel();
    let Some(ni) = normal(i) else { return 1.0 };
    let mut cos_min = 1.0f64;
    for axis in band.neighbours_of(i).iter() {
        for &j in axis {
            if j != sentinel {
                if let Some(nj) = normal(j as usize) {
                    let dot: f64 = (0..D).map(|c| ni[c] * nj[c]).sum();
                    cos_min = cos_min.min(dot);
                }
            }
        }
    }
    cos_min
}

/// The creases of a level set in the paper's tube, for the first-order scheme (Algorithm 3 on
/// Eq. (3)), which computes no curvatures: the test of [`creases_of`] without its first gate — an
/// inner-tube node (`inner`) within [`CREASE_REACH`] spacings of the surface whose normal turns by
/// more than [`CREASE_ANGLE`] degrees to a neighbour's and where φ has a kink (|∇φ| by central
/// differences of `phi` off 1 by more than [`GRAD_NORM_TOLERANCE`]). The angle reported is the
/// widest turn at a crease node, also from its neighbour on one side to the one on the other
/// (the cube's edges: 90°, where neighbours turn by 55°). `direction`: the unit
/// outward directions sgn(φ)∇φ/|∇φ|, D per node (zero on the surface, where the central
/// differences' normal stands in). The turn and the kink are each far beyond what a smooth surface that the tube
/// resolves gives so near it (the torus (0.5, 0.2) at N = 41: up to 28° between neighbours), so
/// only creases count, not where two sides' tubes meet deeper inside a small sphere.
pub fn creases_of_level_set<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
) -> Result<Creases> {
    check_node_fields(band, inner, phi, direction, spacing)?;
    let sentinel = band.sentinel();
    // ∇φ by central differences (None where a neighbour is outside the band)
    let gradient = |n: usize| -> Option<[f64; D]> {
        let nb = band.neighbours_of(n);
        let mut g = [0.0f64; D];
        for (k, pair) in nb.iter().enumerate() {
            if pair[0] == sentinel || pair[1] == sentinel {
                return None;
            }
            g[k] = (phi[pair[1] as usize] as f64 - phi[pair[0] as usize] as f64) / (2.0 * spacing);
        }
        Some(g)
    };
    // ∇φ/|∇φ|: the direction turned back by φ's sign, or on the surface (no direction there; the
    // cube's faces at N = 41 lie on nodes) the central differences'
    let normal = |n: usize| -> Option<[f64; D]> {
        let s = if phi[n] < 0.0 { -1.0 } else { 1.0 };
        let v: [f64; D] = std::array::from_fn(|k| s * direction[D * n + k] as f64);
        if v.iter().any(|&c| c != 0.0) {
            return Some(v);
        }
        let g = gradient(n)?;
        let norm = g.iter().map(|c| c * c).sum::<f64>().sqrt();
        (norm > 0.0).then(|| g.map(|c| c / norm))
    };
    let threshold = CREASE_ANGLE.to_radians().cos();
    let shallow = SHALLOW_CREASE_ANGLE.to_radians().cos();
    // the smallest cosine at a crease node, per node (2: not one)
    let turn_at = |i: usize| -> f64 {
        if !inner[i] || (phi[i] as f64).abs() > CREASE_REACH * spacing {
            return 2.0;
        }
        let cos_min = smallest_turn(band, i, normal);
        let shallow_kink = || {
            cos_min < shallow
                && gradient(i)
                    .zip(normal(i))
                    .is_some_and(|(g, n)| central_differences_agree(&g, &n))
                && kink_ratio(band, i, spacing, |j| phi[j] as f64).is_some_and(|r| r < KINK_RATIO)
        };
        if cos_min >= threshold && !shallow_kink() {
            return 2.0;
        }
        // the faces' angle (the bound 2·tan(θ/2) halved with the neighbours' turn), also across
        // the node diagonally, where the central differences blur the faces less
        let widest = widest_turn_diagonally(band, i, widest_turn(band, i, cos_min, normal), normal);
        // a stencil node outside the band counts as a kink, as in creases_of
        let kink = shallow_kink()
            || gradient(i)
                .is_none_or(|g| (g.iter().map(|c| c * c).sum::<f64>().sqrt() - 1.0).abs() > GRAD_NORM_TOLERANCE);
        if kink {
            widest
        } else {
            2.0
        }
    };
    let (nodes, smallest) = (0..band.len())
        .into_par_iter()
        .map(|i| {
            let c = turn_at(i);
            if c <= 1.0 {
                (1usize, c)
            } else {
                (0, 1.0)
            }
        })
        .reduce(|| (0, 1.0), |a, b| (a.0 + b.0, a.1.min(b.1)));
    Ok(creases_from(nodes, smallest, smallest))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_right_angle_costs_two_inner_widths() {
        let c = Creases {
            nodes: 1,
            angle: 90.0,
            faces_angle: 90.0,
        };
        assert!((c.shortcut_per_inner_width() - 2.0).abs() < 1e-12);
        assert_eq!(Creases::default().shortcut_per_inner_width(), 0.0);
    }

    /// The paper's tube of the cube max|x| − 0.5 at N = 21 and 41 has crease nodes along its
    /// edges (116 at N = 21) and its faces' angle, 90° (from one side of a node to the other:
    /// neighbours turn by 55° by central differences); a sphere, a torus the grid barely resolves (the inner
    /// side of Torus(0.5, 0.2) at N = 41, κΔx = 0.25) and a small sphere whose two sides' tubes
    /// meet at its centre (radius 3Δx) have none.
    #[test]
    fn the_paper_tube_of_a_cube_has_creases_and_smooth_surfaces_none() {
        use crate::band::crease_ridges::tests::band_of;
        let cube = |x: [f64; 3]| x[0].abs().max(x[1].abs()).max(x[2].abs()) - 0.5;
        for n in [21, 41] {
            let (band, phi, dir, inner, h) = band_of(n, cube);
            let c = creases_of_level_set(&band, &inner, &phi, &dir, h).unwrap();
            assert!(c.nodes >= 10 * (n / 2), "{n}: {c:?}");
            assert!((c.angle - 90.0).abs() < 1.0, "{n}: {c:?}");
            // the tube's directions are zero on the surface (its faces lie on nodes here): the
            // central differences' normals stand in, and the same nodes are found
            let mut zeroed = dir.clone();
            for (i, v) in phi.iter().enumerate() {
                if *v == 0.0 {
                    zeroed[3 * i..3 * i + 3].fill(0.0);
                }
            }
            assert!(zeroed != dir);
            assert_eq!(creases_of_level_set(&band, &inner, &phi, &zeroed, h).unwrap(), c, "{n}");
        }
        let sphere = |r: f64| move |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - r;
        let torus = |x: [f64; 3]| ((x[0] * x[0] + x[1] * x[1]).sqrt() - 0.5).hypot(x[2]) - 0.2;
        for (n, c) in [
            (41, creases_of_level_set_of(41, sphere(0.5))),
            (41, creases_of_level_set_of(41, torus)),
            (21, creases_of_level_set_of(21, sphere(0.3))),
        ] {
            assert_eq!(c, Creases::default(), "{n}");
        }
        // the fields are checked
        let (band, phi, dir, inner, h) = band_of(21, cube);
        assert!(creases_of_level_set(&band, &inner[1..], &phi, &dir, h).is_err());
    }

    /// A box's exact distance (half-sides 0.5, 0.4, 0.3, its faces and edges on nodes): the
    /// central differences blur the faces' normals next to its edges along the axes, where the
    /// widest turn read 78°; across the node diagonally its faces' angle, 90°.
    #[test]
    fn the_paper_tube_of_a_box_s_exact_distance_has_its_faces_angle() {
        use crate::band::crease_ridges::tests::band_of;
        let b = [0.5, 0.4, 0.3];
        let exact = |x: [f64; 3]| {
            let q: [f64; 3] = std::array::from_fn(|k| x[k].abs() - b[k]);
            let outside = q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
            outside + q[0].max(q[1]).max(q[2]).min(0.0)
        };
        for n in [41, 61] {
            let (band, phi, dir, inner, h) = band_of(n, exact);
            let c = creases_of_level_set(&band, &inner, &phi, &dir, h).unwrap();
            assert!(c.nodes > 0 && (c.faces_angle - 90.0).abs() < 1.0, "{n}: {c:?}");
        }
    }

    /// A lens of two spheres (radius 0.5) cut by `max`, their normals turning by 60° at its rim:
    /// neighbours' central-difference normals turn by about 35° there, under [`CREASE_ANGLE`], and
    /// its kink ratio reads 0.88–0.93 (about cos(30°)); found by the shallow test at N = 41 and
    /// 61, its faces' angle read as 56–71°. Turning by 40° (ratio about 0.96) it is not at N = 61; nor are the sphere and the
    /// torus (0.5, 0.2), whose ratio stays within a few thousandths of 1.
    #[test]
    fn a_lens_turning_by_60_degrees_is_found_by_its_kink_ratio() {
        use crate::band::crease_ridges::tests::band_of;
        let lens = |turn: f64| {
            let a = 0.5 * (turn.to_radians() / 2.0).sin();
            move |x: [f64; 3]| {
                let (y, z) = (x[1] + 0.007, x[2] - 0.003);
                let d = |c: f64| ((x[0] - 0.011 - c).powi(2) + y * y + z * z).sqrt() - 0.5;
                d(-a).max(d(a))
            }
        };
        for n in [41, 61] {
            let (band, phi, dir, inner, h) = band_of(n, lens(60.0));
            let c = creases_of_level_set(&band, &inner, &phi, &dir, h).unwrap();
            assert!(c.nodes > 20 && (50.0..75.0).contains(&c.angle), "{n}: {c:?}");
            let lowest = (0..band.len())
                .filter(|&i| inner[i] && (phi[i] as f64).abs() <= CREASE_REACH * h)
                .filter_map(|i| kink_ratio(&band, i, h, |j| phi[j] as f64))
                .fold(1.0f64, f64::min);
            assert!((0.85..KINK_RATIO).contains(&lowest), "{n}: {lowest}");
            if n == 61 {
                // (at N = 41 its faces read 52° apart, and it is found)
                assert_eq!(creases_of_level_set_of(n, lens(40.0)), Creases::default(), "{n}");
            }
        }
        let (band, phi, _, inner, h) =
            band_of(41, |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.5);
        let sphere = (0..band.len())
            .filter(|&i| inner[i])
            .filter_map(|i| kink_ratio(&band, i, h, |j| phi[j] as f64))
            .fold(1.0f64, f64::min);
        assert!(sphere > 0.99, "{sphere}");
    }

    fn creases_of_level_set_of(n: usize, phi: impl Fn([f64; 3]) -> f64) -> Creases {
        let (band, phi, dir, inner, h) = crate::band::crease_ridges::tests::band_of(n, phi);
        creases_of_level_set(&band, &inner, &phi, &dir, h).unwrap()
    }
}
