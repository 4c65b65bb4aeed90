//! The inner-tube nodes that let the front cut a crease's corner, to be turned into extension
//! nodes (Algorithm 3's outer layer, Eq. (8)) so that their values come from their closest points.
//!
//! Across a crease the normal jumps. On the side where the tubes of the crease's two faces
//! overlap (inside a convex edge, outside a concave one) the level sets of φ meet at an angle and
//! the paper's tube equation (Eq. (3), |P∇u| = 1/F, P = I − nnᵀ) lets the front move along n for
//! free: a path runs up one face's normal to the bisector and down the other's, and the front
//! arrives early by about 2·tan(θ/2)·inner·Δx per crease crossed (θ the angle between the faces'
//! normals; `second_order::creases`). That side is where |φ| has a ridge (its level sets' two
//! families of normals converge onto the bisector: the medial surface of the crease), so the
//! bisector's nodes are found by the second difference of |φ| across them, strongly negative
//! there and small on a smooth surface:
//!
//! * `|φ(a + e_k)| + |φ(a − e_k)| − 2|φ(a)| < −`[`RIDGE_SECOND_DIFFERENCE`]`·Δx` along an axis
//!   (a signed distance whose level sets the grid resolves, κ·outer·Δx < 1, gives at most
//!   2κΔx² ≤ 0.5Δx within the inner tube of width 2Δx; the cube's edge gives Δx, two spheres
//!   joined by `min`, 74° apart, 1.2Δx),
//! * the directions at `a ± e_k` (at `a ± 2e_k` for a node on the surface, which has none) turn
//!   by more than [`RIDGE_ANGLE`] degrees and converge (`(n(a + e_k) − n(a − e_k))·e_k < 0` with
//!   n pointing away from the surface on a's side; beyond a convex edge, where the level sets of
//!   `max` move apart, they diverge),
//! * the three nodes on one side of the surface (or on it).
//!
//! These ridge nodes and their neighbours on the same side of the surface become extension nodes
//! where they lie farther than [`RIDGE_REACH`] grid spacings from the surface; the nodes nearer
//! it stay in the inner tube and carry the front across the crease. On the cube max|x| − 0.5
//! (bottom centre to top centre, exact 2.0) this takes the shortcut per edge from 4.25Δx and
//! 4.42Δx (N = 41, 81) to 0.56Δx, and on the cube turned at random to 0.9–1.3Δx
//! (`benches/experiments/creases.py`). A ridge counts only where it comes within
//! [`RIDGE_SEED`] spacings of the surface, as a crease's and a tightly rounded edge's do, and
//! where the faces' normals persist a step beyond the pair (a spike of noise turns one node's):
//! the medial surface of a smooth surface the tube resolves lies deeper, so its tube is unchanged
//! (none on the sphere at N = 41–121, on the torus (0.5, 0.2) from N = 61 and on the ellipsoid
//! (0.8, 0.5, 0.3) from N = 81). Where a tube reaches within three spacings of the focal set (that
//! torus's core circle at N = 41, 404 nodes; that ellipsoid's tips at N = 61, 10 nodes) second order
//! changes little: the torus's largest error 0.24% against 0.25%, the ellipsoid's 5.3e-3 against
//! 5.0e-3 (against N = 161).

use crate::band::facing_sheets::check_node_fields;
use crate::band::NarrowBand;
use crate::error::Result;
use rayon::prelude::*;

/// The second difference of |φ| across a ridge node, in grid spacings (see the module docs).
pub const RIDGE_SECOND_DIFFERENCE: f64 = 0.75;

/// The smallest turn, in degrees, of the directions across a ridge node (the crease detector's
/// `second_order::creases::CREASE_ANGLE`; across a crease of the library and the tests the
/// directions two spacings apart turn by 55° to 90°).
pub const RIDGE_ANGLE: f64 = 40.0;

/// A ridge is a crease's when it comes this near the surface (in grid spacings). Inside a rounded
/// edge of radius r the ridge lies r deep, and where r is below the tube's width the tube cuts the
/// edge's corner as at a crease: `RoundedCube(0.4, 0.05)` from a face's centre to the opposite
/// one's, 11.3% short at N = 81 (r = 2Δx) and 8.6% at N = 101 when only ridges within one
/// spacing counted, 0.6% and 5.2% now; `RoundedCube()` (r = 0.1) 1.0% at N = 41 (17.7%). A
/// smooth surface that the tube resolves (κ·outer·Δx < 1) has its medial surface deeper than
/// outer = 4 spacings; where two sides' tubes meet inside a sphere of radius 2.75–3.75Δx (N = 12–31)
/// its centre's ridge counts too, as the crossing it is (the antipode 1.0Δx short instead of 2.7Δx).
pub const RIDGE_SEED: f64 = 3.0;

/// Nodes within this many grid spacings of the surface stay in the inner tube at a crease: the
/// front crosses the crease through them. Nodes on the surface of the cube (N = 41, 81) and a
/// quarter spacing off it (N = 40, 80) kept it crossing; with a quarter spacing the tube was
/// cut at N = 80 (the front arrived late by 0.7Δx per edge).
pub const RIDGE_REACH: f64 = 0.5;

/// The band positions of the inner-tube nodes (`inner`) that lie on the overlap side of a crease
/// (see the module's documentation: ridge nodes anywhere in the band, and their neighbours), farther than [`RIDGE_REACH`] spacings from the surface:
/// `phi` is φ per node (signed), `direction` the unit outward directions (D per node), `spacing`
/// the grid spacing.
pub fn crease_ridge_nodes<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
) -> Result<Vec<usize>> {
    check_node_fields(band, inner, phi, direction, spacing)?;
    let k_nodes = band.len();
    let sentinel = band.sentinel();
    let cos_turn = RIDGE_ANGLE.to_radians().cos();
    // the normal ∇φ/|∇φ| (the directions are sgn(φ)∇φ/|∇φ|, ∇φ/|∇φ| on the surface)
    let normal = |n: usize| -> [f64; D] {
        let s = if phi[n] < 0.0 { -1.0 } else { 1.0 };
        std::array::from_fn(|k| s * direction[D * n + k] as f64)
    };
    // a node on the surface has no direction: the normal of the next node along the axis
    let normal_beyond = |n: usize, k: usize, side: usize| -> [f64; D] {
        let v = normal(n);
        if v.iter().any(|&c| c != 0.0) {
            return v;
        }
        match band.neighbours_of(n)[k][side] {
            b if b == sentinel => v,
            b => normal(b as usize),
        }
    };
    let step = |n: usize, k: usize, side: usize| -> Option<usize> {
        let b = band.neighbours_of(n)[k][side];
        (b != sentinel).then_some(b as usize)
    };
    let turns = |u: &[f64; D], v: &[f64; D]| (0..D).map(|c| u[c] * v[c]).sum::<f64>() < cos_turn;
    // the faces' normals persist one step beyond (a crease; a spike of noise turns one node's)
    let persists = |m: Option<usize>, p: Option<usize>, k: usize| match (m, p) {
        (Some(m), Some(p)) => turns(&normal_beyond(m, k, 0), &normal_beyond(p, k, 1)),
        _ => true,
    };
    // what node `a`'s tests mark, as bits: 1 for `a` itself, 2 << k for its plus neighbour
    // along axis k (the pair test); the tests read only, so the nodes run on all threads and the
    // marks are gathered after (the same marks as one pass in band order)
    let marks_of = |a: usize| -> u8 {
        let mut bits = 0u8;
        let pa = phi[a] as f64;
        let s = if pa < 0.0 { -1.0 } else { 1.0 };
        for (k, pair) in band.neighbours_of(a).iter().enumerate() {
            let (m, p) = (pair[0], pair[1]);
            // two neighbours off the surface on one side whose normals turn and converge
            if p != sentinel && (phi[p as usize] as f64) * pa > 0.0 {
                let (na, np) = (normal(a), normal(p as usize));
                let turn: f64 = (0..D).map(|c| na[c] * np[c]).sum();
                if turn < cos_turn && s * (np[k] - na[k]) < 0.0 && persists(step(a, k, 0), step(p as usize, k, 1), k) {
                    bits |= 1 | (2 << k);
                }
            }
            if m == sentinel || p == sentinel {
                continue;
            }
            let (m, p) = (m as usize, p as usize);
            // on a's side of the surface (or on it)
            if (phi[m] as f64) * pa < 0.0 || (phi[p] as f64) * pa < 0.0 {
                continue;
            }
            let second = (phi[m] as f64).abs() + (phi[p] as f64).abs() - 2.0 * pa.abs();
            if second >= -RIDGE_SECOND_DIFFERENCE * spacing {
                continue;
            }
            // away from the surface on a's side: sgn(φ(a))·n
            let (nm, np) = (normal_beyond(m, k, 0), normal_beyond(p, k, 1));
            let turn: f64 = (0..D).map(|c| nm[c] * np[c]).sum();
            if turn < cos_turn && s * (np[k] - nm[k]) < 0.0 && persists(step(m, k, 0), step(p, k, 1), k) {
                bits |= 1;
                break;
            }
        }
        bits
    };
    let bits: Vec<u8> = (0..k_nodes).into_par_iter().with_min_len(4096).map(marks_of).collect();
    let mut marked = vec![false; k_nodes];
    for (a, &b) in bits.iter().enumerate() {
        if b == 0 {
            continue;
        }
        marked[a] |= b & 1 != 0;
        let nb = band.neighbours_of(a);
        for (k, pair) in nb.iter().enumerate() {
            if b & (2 << k) != 0 {
                marked[pair[1] as usize] = true;
            }
        }
    }
    // a crease's ridge reaches the surface: the ridges of |φ| that stay deeper (the medial
    // surface of a smooth surface the grid barely resolves, the torus 0.5/0.2 at N = 41) are left
    let seed = RIDGE_SEED * spacing * (1.0 + 1e-5);
    let mut kept = vec![false; k_nodes];
    let mut stack: Vec<usize> = (0..k_nodes)
        .filter(|&a| marked[a] && (phi[a] as f64).abs() <= seed)
        .collect();
    for &a in &stack {
        kept[a] = true;
    }
    while let Some(a) = stack.pop() {
        for &b in band.neighbours_of(a).iter().flatten() {
            if b != sentinel && marked[b as usize] && !kept[b as usize] {
                kept[b as usize] = true;
                stack.push(b as usize);
            }
        }
    }
    let marked = kept;
    // (φ comes in single precision: a node at half a spacing stays)
    let reach = RIDGE_REACH * spacing * (1.0 + 1e-5);
    let mut out = Vec::new();
    for b in 0..k_nodes {
        if !inner[b] || (phi[b] as f64).abs() <= reach {
            continue;
        }
        let near = marked[b]
            || band
                .neighbours_of(b)
                .iter()
                .flatten()
                .any(|&a| a != sentinel && marked[a as usize] && phi[a as usize] as f64 * phi[b] as f64 > 0.0);
        if near {
            out.push(b);
        }
    }
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The band of |φ| ≤ 4Δx on [−1, 1]³ at `n` nodes per axis with φ (f32), the outward
    /// directions by central differences and the inner tube |φ| ≤ 2Δx (also the crease tests'
    /// of `second_order::creases`).
    pub(crate) fn band_of(
        n: usize,
        phi: impl Fn([f64; 3]) -> f64,
    ) -> (NarrowBand<3>, Vec<f32>, Vec<f32>, Vec<bool>, f64) {
        let h = 2.0 / (n - 1) as f64;
        let at = |i: usize| -1.0 + h * i as f64;
        let mut linear = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    if phi([at(i), at(j), at(k)]).abs() <= 4.0 * h {
                        linear.push(((i * n + j) * n + k) as u64);
                    }
                }
            }
        }
        let band = NarrowBand::<3>::from_sorted_linear([n, n, n], &linear).unwrap();
        let (mut ph, mut dir, mut inner) = (Vec::new(), Vec::new(), Vec::new());
        for &l in &linear {
            let l = l as usize;
            let x = [at(l / (n * n)), at(l / n % n), at(l % n)];
            let v = phi(x);
            // central differences, signed away from the surface
            let g: [f64; 3] = std::array::from_fn(|c| {
                let (mut p, mut m) = (x, x);
                p[c] += h;
                m[c] -= h;
                (phi(p) - phi(m)) / (2.0 * h)
            });
            let norm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
            let s = if v < 0.0 { -1.0 } else { 1.0 };
            dir.extend(g.iter().map(|c| (s * c / norm) as f32));
            ph.push(v as f32);
            inner.push(v.abs() <= 2.0 * h + 1e-12);
        }
        (band, ph, dir, inner, h)
    }

    /// The cube max|x| − 0.5 at N = 21 (Δx = 0.1): ridge nodes inside along its edges and
    /// corners, none farther than the inner tube or on the surface; a sphere: none.
    #[test]
    fn the_cube_has_ridge_nodes_inside_its_edges_and_a_sphere_none() {
        let cube = |x: [f64; 3]| x[0].abs().max(x[1].abs()).max(x[2].abs()) - 0.5;
        let (band, phi, dir, inner, h) = band_of(21, cube);
        let found = crease_ridge_nodes(&band, &inner, &phi, &dir, h).unwrap();
        assert!(!found.is_empty());
        for &b in &found {
            assert!(inner[b] && phi[b] < 0.0 && (phi[b] as f64) < -RIDGE_REACH * h);
        }
        let sphere = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() - 0.5;
        let (band, phi, dir, inner, h) = band_of(21, sphere);
        assert!(crease_ridge_nodes(&band, &inner, &phi, &dir, h).unwrap().is_empty());
    }
}
