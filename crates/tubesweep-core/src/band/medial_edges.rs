//! Where the band's neighbours have closest points far apart: edges across the medial axis of
//! a surface with concave creases (a triangle mesh's closest-point map).
//!
//! The two-layer method (Algorithm 3) solves the eikonal equation in the inner tube as a
//! d-dimensional problem: a step of one grid spacing between two neighbours stands for the step
//! between their closest points on the surface. On one smooth sheet the two closest points lie
//! at most `h / (1 − |φ|κ)` apart (`κ` the curvature along the step, on the concave side). Above a
//! concave crease (every concave edge of a triangle mesh, whose closest-point map is exact) the
//! closest points of two neighbours lie on the two faces, and the step of `h` in the tube stands
//! for a path along the surface much longer than `h`: the front cuts across the valley above the
//! crease, and the travel times beyond come out too short. On Spot and the Stanford bunny at
//! n = 200 these shortcuts make most of the first-order error against exact polyhedral geodesics
//! (`benches/experiments/narrow_gaps_meshes.py`).
//!
//! An edge `(a, b = a + h·e_k)` with a node in the inner tube is a *medial edge* when
//! `|cp(a) − cp(b)| > `[`MEDIAL_JUMP`]` · h`, with `cp(x) = x − |φ| n` (`n` the outward extension
//! direction of Eq. (8)). Removing those edges from the neighbour table
//! ([`NarrowBand::cut_edges`]) leaves the front the paths along which closest points move
//! continuously, near the surface.

use super::node_blocks::per_node;
use crate::band::facing_sheets::check_node_fields;
use crate::band::NarrowBand;
use crate::error::{Error, Result};

/// The jump of the closest point between two neighbours, in grid spacings, above which their
/// edge is a medial edge: `1 / (1 − |φ|κ) = 1.5` at `|φ|κ = 1/3`, beyond what a resolved smooth
/// sheet gives in the inner tube (two spacings from the surface, a radius of curvature above six
/// spacings). Measured on the bundled meshes at n = 200 against exact polyhedral geodesics
/// (mean error relative to the largest distance): Spot 0.83 % uncut, 0.73 % at 2, 0.29 % at 1.5;
/// the bunny 0.87 %, 0.73 %, 0.41 %.
pub const MEDIAL_JUMP: f64 = 1.5;

/// The largest jump, in grid spacings, that the threshold between two extension nodes allows for
/// (a resolved sheet's steps grow as 1/(1 − |φ|/R) away from its concave side; capped here).
pub const EXTENSION_JUMP_CAP: f64 = 4.0;

/// The medial edges of `band` (see the module's documentation): pairs `(a, b)` of band positions,
/// `b` the plus neighbour of `a` along some axis, whose closest points `x − |φ[n]| direction[n]`
/// lie more than `jump · spacing` apart where one is in the inner tube (`inner[n]`), and more than
/// the jump of a sheet with the smallest radius of curvature that `jump` allows, R = 2/(1 − 1/jump)
/// spacings (6 at 1.5), at the larger |φ| of the two, 1/(1 − |φ|/R) (at most
/// [`EXTENSION_JUMP_CAP`]) spacings, between two extension nodes. Those matter too: between
/// two parts of a mesh 4–8 spacings apart the nodes near the middle are all extension nodes, each
/// extended from its own part's side, and an edge between two of them whose closest points lie on
/// the two parts carried the front across (two spheres 5 spacings apart at N = 81: the second,
/// which no source reaches, reached everywhere without a word).
pub fn medial_edges<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
    jump: f64,
) -> Result<Vec<(usize, usize)>> {
    check_node_fields(band, inner, phi, direction, spacing)?;
    let k_nodes = band.len();
    if !(jump >= 1.0 && jump.is_finite()) {
        return Err(Error::invalid(
            "jump",
            format!("must be a finite number of grid spacings of at least 1 (neighbours on a plane are 1 apart); got {jump}"),
        ));
    }
    let sentinel = band.sentinel();
    let limit2 = jump * jump;
    // the smallest radius of curvature, in spacings, whose inner-tube steps (|φ| ≤ 2, the default
    // inner width; the callers pass MEDIAL_JUMP for that width) jump by less than `jump`:
    // 1/(1 − 2/R) = jump
    let resolved = 2.0 / (1.0 - 1.0 / jump);
    // |φ| n in grid spacings
    let offset = |n: usize| -> [f64; D] {
        let t = (phi[n] as f64).abs() / spacing;
        std::array::from_fn(|j| t * direction[D * n + j] as f64)
    };
    Ok(per_node(k_nodes, |a, out: &mut Vec<(usize, usize)>| {
        let oa = offset(a);
        for (k, pair) in band.neighbours_of(a).iter().enumerate() {
            let b = pair[1];
            if b == sentinel {
                continue;
            }
            let limit2 = if inner[a] || inner[b as usize] {
                limit2
            } else {
                // two extension nodes: the jump a resolved sheet gives that far out
                let t = (phi[a] as f64).abs().max((phi[b as usize] as f64).abs()) / spacing;
                let lim = 1.0 / (1.0 - t / resolved).max(1.0 / EXTENSION_JUMP_CAP);
                lim * lim
            };
            let ob = offset(b as usize);
            // cp(a) − cp(b) = (a − b) − |φ_a| n_a + |φ_b| n_b, a − b = −e_k
            let jump2: f64 = (0..D)
                .map(|j| {
                    let c = if j == k { -1.0 } else { 0.0 } - oa[j] + ob[j];
                    c * c
                })
                .sum();
            if jump2 > limit2 {
                out.push((a, b as usize));
            }
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The whole `n × n` box with the unsigned distance to the two lines y = ±s·x (concave
    /// creases at the origin: the V y = s|x| seen from above, and three more valleys), nodes at
    /// spacing `h` centred on the origin.
    fn valley(n: usize, h: f64, s: f64) -> (NarrowBand<2>, Vec<f32>, Vec<f32>) {
        let band = NarrowBand::<2>::full_box([n, n]).unwrap();
        let (mut phi, mut dir) = (Vec::new(), Vec::new());
        let c = (n / 2) as f64;
        let len = (1.0 + s * s).sqrt();
        for idx in band.indices() {
            let (y, x) = ((idx[0] as f64 - c) * h, (idx[1] as f64 - c) * h);
            // the two arms' lines s·|x| − y = 0 with unit normals (∓s, 1)/len pointing up
            let best = [1.0f64, -1.0]
                .iter()
                .map(|&side| {
                    let nrm = [1.0 / len, -side * s / len]; // (y, x) components
                    let d = (y - side * s * x) / len;
                    (d, nrm)
                })
                .min_by(|p, q| p.0.abs().total_cmp(&q.0.abs()))
                .unwrap();
            phi.push(best.0.abs() as f32);
            let sg = best.0.signum();
            dir.push((sg * best.1[0]) as f32);
            dir.push((sg * best.1[1]) as f32);
        }
        (band, phi, dir)
    }

    /// Two parallel lines y = ±3.5h: the nodes near the middle are all extension nodes, and the
    /// edges between those whose closest points lie on the two lines (7 spacings apart) are
    /// medial edges, while the edges along each line's own side are not.
    #[test]
    fn two_sheets_a_few_spacings_apart_are_cut_between_their_extension_nodes() {
        let (n, h, a) = (21usize, 0.1, 0.35);
        let band = NarrowBand::<2>::full_box([n, n]).unwrap();
        let c = (n / 2) as f64;
        let (mut phi, mut dir, mut inner) = (Vec::new(), Vec::new(), Vec::new());
        for idx in band.indices() {
            let y = (idx[0] as f64 - c) * h;
            // the nearer line (+a at a tie): unsigned distance, direction away from it (y, x)
            let (d, s) = if (y - a).abs() <= (y + a).abs() {
                (y - a, 1.0)
            } else {
                (y + a, -1.0)
            };
            phi.push(d.abs() as f32);
            dir.push(if d == 0.0 { s } else { d.signum() } as f32);
            dir.push(0.0);
            inner.push(d.abs() <= 2.0 * h + 1e-9);
        }
        let edges = medial_edges(&band, &inner, &phi, &dir, h, MEDIAL_JUMP).unwrap();
        assert!(!edges.is_empty());
        for &(p, q) in &edges {
            let (ip, iq) = (band.index_of(p), band.index_of(q));
            // across the middle row only (y = −h → 0), between two extension nodes
            assert_eq!((ip[0], iq[0]), (c as usize - 1, c as usize), "{ip:?} {iq:?}");
            assert!(!inner[p] && !inner[q]);
        }
        assert_eq!(edges.len(), n);
    }

    #[test]
    fn a_flat_sheet_has_no_medial_edge_and_a_valley_has_them_above_its_crease() {
        let h = 0.1;
        let (band, phi, dir) = valley(21, h, 0.0);
        let inner: Vec<bool> = phi.iter().map(|&p| (p as f64) <= 2.0 * h).collect();
        assert!(medial_edges(&band, &inner, &phi, &dir, h, MEDIAL_JUMP)
            .unwrap()
            .is_empty());
        // slopes of 45°: the closest points of the nodes above the crease jump between the arms
        let (band, phi, dir) = valley(21, h, 1.0);
        let inner: Vec<bool> = phi.iter().map(|&p| (p as f64) <= 2.0 * h).collect();
        let edges = medial_edges(&band, &inner, &phi, &dir, h, MEDIAL_JUMP).unwrap();
        assert!(!edges.is_empty());
        for &(a, b) in &edges {
            // the unsigned distance to the two lines y = ±x: every medial edge straddles (or
            // touches) one of the bisectors x = 0 and y = 0 of the four right-angled valleys
            let (ia, ib) = (band.index_of(a), band.index_of(b));
            let straddles = |k: usize| ia[k].min(ib[k]) <= 10 && ia[k].max(ib[k]) >= 10;
            assert!(straddles(0) || straddles(1), "{ia:?} {ib:?}");
        }
    }

    #[test]
    fn medial_edges_refuse_mismatched_inputs_and_a_jump_below_one() {
        let (band, phi, dir) = valley(9, 0.1, 1.0);
        let inner = vec![true; band.len()];
        assert!(medial_edges(&band, &inner[1..], &phi, &dir, 0.1, 1.5).is_err());
        assert!(medial_edges(&band, &inner, &phi, &dir, 0.1, 0.5).is_err());
        assert!(medial_edges(&band, &inner, &phi, &dir, -1.0, 1.5).is_err());
    }
}
