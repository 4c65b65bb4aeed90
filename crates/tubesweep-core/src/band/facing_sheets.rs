//! Where the tubes of two parts of the surface that face each other across a narrow gap touch.
//!
//! The two-layer method (Algorithm 3) solves the eikonal equation in the inner tube as a
//! d-dimensional problem and relies on every node's neighbours lying on the same part of the
//! surface as the node itself. Where two parts of the surface face each other across a gap of
//! less than about `(2·inner + 2)` grid spacings (a thin plate or shell, an ear against a head, a
//! narrow fold), an inner-tube node of one part has a band neighbour whose closest point lies on
//! the other part. The Godunov update (Eq. (3)) then reads that neighbour, the front crosses the
//! gap, and every travel time beyond the crossing comes out too short (a shortcut the surface
//! does not have) — a wrong answer that nothing else reports.
//!
//! A pair of neighbours `a` and `b = a + h·e_k` (at least one of them in the inner tube) is taken
//! to straddle such a gap by either of two tests. With `t = |φ|/h`, `n` the outward extension
//! directions of Eq. (8) (`(x − cp(x))/|x − cp(x)|`, pointing away from each node's own closest
//! point; the normal for nodes on the surface) and `cp(x) = x − |φ| n`:
//!
//! 1. *Facing.* Both lie off the surface, `t_a, t_b > ` [`MIN_OFF_SURFACE`], on the same side of
//!    it (φ's signs agree; always so for an unsigned φ); their directions point against each
//!    other, `n_a · n_b < ` [`FACING_COSINE`]; and each lies on its own side of the other's
//!    closest point, `n_a · (b − cp(a)) > 0` and `n_b · (a − cp(b)) > 0`, i.e. `t_a + n_a[k] > 0`
//!    and `t_b − n_b[k] > 0`. Two nodes on either side of one sheet fail the signs (a signed φ,
//!    which may be only roughly a distance: with `|∇φ| > 2` the last condition alone would let
//!    them through) or the last condition (an unsigned φ, an exact distance: each lies behind the
//!    other's tangent plane).
//! 2. *Across.* The two lie on opposite sides of the surface (φ's signs differ) yet their
//!    directions point the same way, `n_a · n_b > 0`, and the chord `cp(a) − cp(b)` is longer
//!    than [`MIN_ACROSS`] spacings and runs along both directions, within 30° of each
//!    ([`ACROSS_COSINE`]). On one sheet two nodes on opposite sides point opposite ways, and two
//!    on one side have the same sign. This catches gaps of one to two spacings, where the node
//!    between the sheets and the node beyond one of them point the same way (a plate 1.9 spacings
//!    thick, crossed by one node). It needs a signed φ: on open or unsigned surfaces (closest
//!    points, open meshes) only the first test runs.
//!
//! For a level set the Python side adds a third case (`solve._ridge_pairs`): a node whose central
//! differences straddle a kink of φ, where the directions are not reliable.
//!
//! Smooth surfaces, open surfaces' rims and the Möbius band give no pair; neither do convex
//! edges (the cube's: `n_a · n_b ≈ 0`, and the chord cannot lie within 30° of two perpendicular
//! directions), where the method's error is first order. A gap narrower than about one spacing
//! (two on an unsigned surface) looks like a single sheet to both tests and is in practice not
//! found. The pair's gap is `|cp(a) − cp(b)|`.

use super::node_blocks::per_node;
use crate::band::NarrowBand;
use crate::error::{Error, Result};

/// Nodes closer to the surface than this many grid spacings are not tested by the facing test:
/// on it (a mesh's nodes within 1e-12 spacings) a node carries a face normal, not a direction
/// away from its closest point. At a quarter spacing, plates 1.5–1.9 spacings thick were missed
/// wherever a face passed within a quarter spacing of a node (about 40% of placements).
pub const MIN_OFF_SURFACE: f64 = 0.02;

/// The largest cosine between two nodes' directions for them to face each other (120°).
pub const FACING_COSINE: f64 = -0.5;

/// The shortest chord `|cp(a) − cp(b)|`, in grid spacings, that the second test takes for a
/// gap (the closest points `x − |φ| n` of a φ that is only roughly a distance miss the sheet
/// along `n` by up to `|1 − |∇φ||·|φ|`; the test's other conditions exclude those pairs).
pub const MIN_ACROSS: f64 = 1.0;

/// The smallest cosine between the chord and each node's direction for the chord to run across
/// the two sheets (30°).
pub const ACROSS_COSINE: f64 = 0.866;

/// Checks the per-node fields that the band's tests of the surface read (facing sheets, medial
/// edges, crease ridges): one `inner` flag, one `phi` and `D` direction components per node of
/// `band`, and a positive finite `spacing`.
pub(crate) fn check_node_fields<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
) -> Result<()> {
    let k_nodes = band.len();
    if inner.len() != k_nodes || phi.len() != k_nodes || direction.len() != D * k_nodes {
        return Err(Error::invalid(
            "inner, phi, direction",
            format!(
                "expected {k_nodes} entries each ({} directions), one per band node",
                D * k_nodes
            ),
        ));
    }
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(Error::invalid("spacing", "must be a positive finite number"));
    }
    Ok(())
}

/// A pair of neighbouring band nodes whose closest points lie on two parts of the surface that
/// face each other across a gap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacingPair {
    /// The node with the smaller index along the axis (a band position).
    pub node: usize,
    /// Its neighbour `node + e_axis` (a band position).
    pub neighbour: usize,
    /// `|cp(node) − cp(neighbour)|` in the grid's units: about the gap's width.
    pub gap: f64,
}

/// The pairs of neighbouring nodes of `band` that straddle a gap between two facing parts of
/// the surface (see the module's documentation). `inner[n]` says whether node `n` is in the inner
/// tube, `phi[n]` is its signed or unsigned distance and `direction[D·n .. D·n + D]` its unit
/// outward direction (zero where undefined); `spacing` is the grid spacing.
pub fn facing_sheet_pairs<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
) -> Result<Vec<FacingPair>> {
    check_node_fields(band, inner, phi, direction, spacing)?;
    let k_nodes = band.len();
    let sentinel = band.sentinel();
    let dir = |n: usize| -> [f64; D] { std::array::from_fn(|k| direction[D * n + k] as f64) };
    let dot = |u: &[f64; D], v: &[f64; D]| -> f64 { (0..D).map(|j| u[j] * v[j]).sum() };
    let pairs_from = |a: usize, out: &mut Vec<FacingPair>| {
        let pa = phi[a] as f64;
        let ta = pa.abs() / spacing;
        let na = dir(a);
        for (k, pair) in band.neighbours_of(a).iter().enumerate() {
            let b = pair[1];
            if b == sentinel || !(inner[a] || inner[b as usize]) {
                continue;
            }
            let b = b as usize;
            let pb = phi[b] as f64;
            let nb = dir(b);
            let cosine = dot(&na, &nb);
            // the signs and the directions first: most pairs lie on one side of one sheet and
            // point the same way, and neither test can take them
            let same_side = pa * pb > 0.0;
            let opposite_sides = pa * pb < 0.0;
            if !((same_side && cosine < FACING_COSINE) || (opposite_sides && cosine > 0.0)) {
                continue;
            }
            let tb = pb.abs() / spacing;
            let (chord2, runs_across) = chord_across(k, ta, &na, tb, &nb);
            // facing: on one side, pointing against each other, each on its own side of the
            // other's closest point
            let facing =
                same_side && ta > MIN_OFF_SURFACE && tb > MIN_OFF_SURFACE && ta + na[k] > 0.0 && tb - nb[k] > 0.0;
            // across: on opposite sides of the surface yet pointing the same way, so that the
            // inside node's closest point and the outside node's lie on different sheets
            let across = opposite_sides && runs_across;
            if facing || across {
                out.push(FacingPair {
                    node: a,
                    neighbour: b,
                    gap: spacing * chord2.sqrt(),
                });
            }
        }
    };
    Ok(per_node(k_nodes, pairs_from))
}

/// The squared chord `|cp(a) − cp(b)|²` in grid spacings of neighbours `a` and `b = a + h·e_k`
/// (`t = |φ|/h`, `n` their directions: `(a − b) − t_a n_a + t_b n_b`), and whether it passes the
/// *across* test's conditions that do not read φ's sign: longer than [`MIN_ACROSS`] spacings and
/// within 30° of both directions ([`ACROSS_COSINE`]).
#[inline]
fn chord_across<const D: usize>(k: usize, ta: f64, na: &[f64; D], tb: f64, nb: &[f64; D]) -> (f64, bool) {
    let dot = |u: &[f64; D], v: &[f64; D]| -> f64 { (0..D).map(|j| u[j] * v[j]).sum() };
    let chord: [f64; D] = std::array::from_fn(|j| if j == k { -1.0 } else { 0.0 } - ta * na[j] + tb * nb[j]);
    let chord2 = dot(&chord, &chord);
    let across = chord2 > MIN_ACROSS * MIN_ACROSS && {
        let (ca, cb) = (dot(&chord, na), dot(&chord, nb));
        let min2 = ACROSS_COSINE * ACROSS_COSINE * chord2;
        ca * ca >= min2 && cb * cb >= min2
    };
    (chord2, across)
}

/// The band positions (sorted) of the nodes of every neighbour pair (one of them in the inner
/// tube) that the *across* test takes once φ's signs differ: directions pointing the same way and
/// [`chord_across`]. Reads `|phi|` only. Where an unsigned φ's inside is known but costly to find
/// (a closed mesh's smooth map: an exact closest point per node), only these nodes need it: the
/// pairs of [`facing_sheet_pairs`] with φ signed by the inside at these nodes alone are those with
/// φ signed everywhere, once joined with the unsigned φ's (a *facing* pair of a signed φ is one
/// of the unsigned φ's, and an *across* pair has both nodes here).
pub fn across_candidates<const D: usize>(
    band: &NarrowBand<D>,
    inner: &[bool],
    phi: &[f32],
    direction: &[f32],
    spacing: f64,
) -> Result<Vec<usize>> {
    check_node_fields(band, inner, phi, direction, spacing)?;
    let sentinel = band.sentinel();
    let dir = |n: usize| -> [f64; D] { std::array::from_fn(|k| direction[D * n + k] as f64) };
    let mut nodes: Vec<usize> = per_node(band.len(), |a, out: &mut Vec<usize>| {
        let (ta, na) = ((phi[a] as f64).abs() / spacing, dir(a));
        for (k, pair) in band.neighbours_of(a).iter().enumerate() {
            let b = pair[1];
            if b == sentinel || !(inner[a] || inner[b as usize]) {
                continue;
            }
            let b = b as usize;
            let nb = dir(b);
            if (0..D).map(|j| na[j] * nb[j]).sum::<f64>() > 0.0
                && chord_across(k, ta, &na, (phi[b] as f64).abs() / spacing, &nb).1
            {
                out.extend([a, b]);
            }
        }
    });
    nodes.sort_unstable();
    nodes.dedup();
    Ok(nodes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band of the whole `n × n` box, with φ and directions of two horizontal lines
    /// `y = y0` and `y = y1` (each node takes the nearer one).
    fn two_lines(n: usize, h: f64, y0: f64, y1: f64) -> (NarrowBand<2>, Vec<f32>, Vec<f32>) {
        let band = NarrowBand::<2>::full_box([n, n]).unwrap();
        let mut phi = Vec::new();
        let mut dir = Vec::new();
        for idx in band.indices() {
            // axis 0 across the lines, axis 1 along them
            let y = idx[0] as f64 * h;
            let (d0, d1) = ((y - y0).abs(), (y - y1).abs());
            let (d, s) = if d0 <= d1 {
                (d0, (y - y0).signum())
            } else {
                (d1, (y - y1).signum())
            };
            // inside (negative) between the lines
            let inside = y > y0.min(y1) && y < y0.max(y1);
            phi.push(if inside { -d } else { d } as f32);
            dir.extend([if d > 0.0 { s as f32 } else { 0.0 }, 0.0]);
        }
        (band, phi, dir)
    }

    #[test]
    fn two_lines_closer_than_the_tubes_give_pairs_with_their_gap() {
        let h = 0.1;
        // lines 0.5 apart (5 spacings): inner tubes of 2 spacings touch across the middle
        let (band, phi, dir) = two_lines(12, h, 0.3, 0.8);
        let inner: Vec<bool> = phi.iter().map(|&p| (p as f64).abs() <= 2.0 * h + 1e-6).collect();
        let pairs = facing_sheet_pairs(&band, &inner, &phi, &dir, h).unwrap();
        // one pair per column, across the middle (nodes at y = 0.5 and 0.6)
        assert_eq!(pairs.len(), 12);
        for p in &pairs {
            let (ia, ib) = (band.index_of(p.node), band.index_of(p.neighbour));
            assert_eq!((ia[0], ib[0]), (5, 6));
            assert!((p.gap - 0.5).abs() < 1e-6, "gap {}", p.gap);
        }
    }

    #[test]
    fn a_strip_thinner_than_two_spacings_gives_the_pair_across_it() {
        // lines 0.175 apart: the node at y = 0.5 lies between them (closest to the lower line,
        // pointing up), the node at y = 0.6 just beyond the upper one (pointing up too)
        let h = 0.1;
        let (band, phi, dir) = two_lines(10, h, 0.415, 0.59);
        let inner: Vec<bool> = phi.iter().map(|&p| (p as f64).abs() <= 2.0 * h + 1e-6).collect();
        let pairs = facing_sheet_pairs(&band, &inner, &phi, &dir, h).unwrap();
        assert!(!pairs.is_empty());
        for p in &pairs {
            let (ia, ib) = (band.index_of(p.node), band.index_of(p.neighbour));
            assert_eq!((ia[0], ib[0]), (5, 6));
            assert!((p.gap - 0.175).abs() < 1e-6, "gap {}", p.gap);
        }
    }

    #[test]
    fn signs_at_the_across_candidates_alone_give_the_pairs_of_signs_everywhere() {
        // strips 1.1 to 1.9 spacings thick: the across pairs need the signs; with them at the
        // candidates alone (others outside), joined with the unsigned φ's pairs, the same pairs
        let h = 0.1;
        for top in [0.52, 0.56, 0.6] {
            let (band, phi, dir) = two_lines(10, h, 0.415, top);
            let inner: Vec<bool> = phi.iter().map(|&p| (p as f64).abs() <= 2.0 * h + 1e-6).collect();
            let unsigned: Vec<f32> = phi.iter().map(|p| p.abs()).collect();
            let key = |p: &FacingPair| (p.node, p.neighbour);
            let mut everywhere: Vec<_> = facing_sheet_pairs(&band, &inner, &phi, &dir, h)
                .unwrap()
                .iter()
                .map(key)
                .collect();
            let at = across_candidates(&band, &inner, &unsigned, &dir, h).unwrap();
            assert!(
                !at.is_empty() && at.len() < band.len() / 4,
                "top {top}: {} candidates",
                at.len()
            );
            let mut partly = unsigned.clone();
            for &n in &at {
                partly[n] = phi[n];
            }
            let mut joined: Vec<_> = facing_sheet_pairs(&band, &inner, &unsigned, &dir, h)
                .unwrap()
                .iter()
                .chain(facing_sheet_pairs(&band, &inner, &partly, &dir, h).unwrap().iter())
                .map(key)
                .collect();
            for v in [&mut everywhere, &mut joined] {
                v.sort_unstable();
                v.dedup();
            }
            let unsigned_only = facing_sheet_pairs(&band, &inner, &unsigned, &dir, h).unwrap().len();
            assert!(everywhere.len() > unsigned_only, "top {top}: the signs add pairs");
            assert_eq!(joined, everywhere, "top {top}");
        }
    }

    #[test]
    fn a_level_set_that_is_a_multiple_of_a_distance_gives_no_pair() {
        // φ = g·(signed distance) to one line: the closest points x − |φ| n of two nodes on one
        // side lie (g − 1) spacings apart along n, a chord like the strip's, but both nodes are
        // outside; two nodes on either side of the line each lie on its own side of the other's
        // closest point once g > 2, but their signs differ
        let h = 0.1;
        for g in [1.5f32, 2.0, 2.5, 3.0] {
            let (band, phi, dir) = two_lines(12, h, 0.55, 10.0);
            let phi: Vec<f32> = phi.iter().map(|&p| g * p).collect();
            let all = vec![true; band.len()];
            assert!(
                facing_sheet_pairs(&band, &all, &phi, &dir, h).unwrap().is_empty(),
                "g = {g}"
            );
        }
    }

    #[test]
    fn one_line_and_far_apart_lines_give_no_pair() {
        let h = 0.1;
        // one line seen from both sides
        let (band, phi, dir) = two_lines(12, h, 0.55, 10.0);
        let all = vec![true; band.len()];
        assert!(facing_sheet_pairs(&band, &all, &phi, &dir, h).unwrap().is_empty());
        // two lines 0.9 apart: the nodes between them that meet are in no inner tube
        let (band, phi, dir) = two_lines(14, h, 0.2, 1.1);
        let inner: Vec<bool> = phi.iter().map(|&p| (p as f64).abs() <= 2.0 * h + 1e-6).collect();
        assert!(facing_sheet_pairs(&band, &inner, &phi, &dir, h).unwrap().is_empty());
    }

    #[test]
    fn a_convex_corner_gives_no_pair() {
        // the inside of the square's corner x, y ≤ 1: nodes take the nearer side, directions
        // point inwards; across the diagonal they are at right angles
        let h = 0.1;
        let band = NarrowBand::<2>::full_box([11, 11]).unwrap();
        let mut phi = Vec::new();
        let mut dir = Vec::new();
        for idx in band.indices() {
            let (x, y) = (idx[0] as f64 * h, idx[1] as f64 * h);
            let (dx, dy) = (1.0 - x, 1.0 - y);
            if dx <= dy {
                phi.push(-dx as f32);
                dir.extend([if dx > 0.0 { -1.0f32 } else { 0.0 }, 0.0]);
            } else {
                phi.push(-dy as f32);
                dir.extend([0.0, -1.0f32]);
            }
        }
        let all = vec![true; band.len()];
        assert!(facing_sheet_pairs(&band, &all, &phi, &dir, h).unwrap().is_empty());
    }

    #[test]
    fn mismatched_lengths_are_refused() {
        let (band, phi, dir) = two_lines(5, 0.1, 0.1, 0.3);
        let inner = vec![true; band.len()];
        assert!(facing_sheet_pairs(&band, &inner[1..], &phi, &dir, 0.1).is_err());
        assert!(facing_sheet_pairs(&band, &inner, &phi, &dir[1..], 0.1).is_err());
        assert!(facing_sheet_pairs(&band, &inner, &phi, &dir, 0.0).is_err());
    }
}
