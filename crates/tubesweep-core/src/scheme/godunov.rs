//! The Godunov local solver for the eikonal equation `|∇u| = 1/F` (paper Eq. (3), Zhao 2005).
//!
//! Given the smaller neighbour value along each axis, `a_k = min(u_{k-}, u_{k+})`, and the
//! right-hand side `f = h / F(x)`, the update is the largest root `ū` of
//!
//! ```text
//!     Σ_k [(ū − a_k)^+]^2 = f^2,
//! ```
//!
//! found by sorting `a_1 ≤ a_2 ≤ … ≤ a_d` and taking the first `m` values that are below the
//! candidate: `ū = a_1 + f` if that does not exceed `a_2` (the first branch of Eq. (3)); else
//! the two-term root `(a_1 + a_2 + sqrt(2 f^2 − (a_1 − a_2)^2)) / 2` (the second branch of
//! Eq. (3)); in 3D, if that exceeds `a_3`, the three-term root. Whether it does is decided by
//! comparing `2 f^2 − (a_1 − a_2)^2` with `(2 a_3 − a_1 − a_2)^2`, so that the only square root
//! taken is the returned root's: on the Gauss–Seidel chain of a row every update waits for the
//! previous one.

/// The Godunov update (Eq. (3)) for `D` axes. `mins[k]` is the smaller neighbour value along axis
/// `k`, `f = h / F` at the node. Returns the new candidate value; the caller keeps the smaller of
/// it and the old value.
#[inline(always)]
pub fn godunov_update<const D: usize>(mins: [f64; D], f: f64) -> f64 {
    let mut a = mins;
    sort_small(&mut a);
    let u1 = a[0] + f;
    if D == 1 || u1 <= a[1] {
        return u1;
    }
    // two terms: (u − a0)^2 + (u − a1)^2 = f^2  (second branch of Eq. (3))
    let d = a[0] - a[1];
    let disc2 = nonneg(2.0 * f * f - d * d);
    let two_term_root = || 0.5 * (a[0] + a[1] + disc2.sqrt());
    if D == 2 {
        return two_term_root();
    }
    // the two-term root stays at or below a2 iff sqrt(disc2) ≤ g = 2 a2 − a0 − a1 (≥ 0, as
    // the a_k are sorted), i.e. iff disc2 ≤ g²: decided without the square root, which is then
    // taken only for the root returned (it sits on the Gauss–Seidel chain of the sweep)
    let g = 2.0 * a[2] - a[0] - a[1];
    if disc2 <= g * g {
        return two_term_root();
    }
    if D == 3 {
        // three terms: 3u^2 − 2 s u + (q − f^2) = 0
        let s = a[0] + a[1] + a[2];
        let q = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        let disc = s * s - 3.0 * (q - f * f);
        return (s + nonneg(disc).sqrt()) * (1.0 / 3.0);
    }
    // general D (not used by the solvers, kept for completeness)
    let mut sum = a[0] + a[1];
    let mut sum_sq = a[0] * a[0] + a[1] * a[1];
    for m in 2..D {
        sum += a[m];
        sum_sq += a[m] * a[m];
        let mf = (m + 1) as f64;
        let disc = sum * sum - mf * (sum_sq - f * f);
        let u = (sum + disc.max(0.0).sqrt()) / mf;
        if m + 1 == D || u <= a[m + 1] {
            return u;
        }
    }
    unreachable!("the loop returns at m = D − 1")
}

/// The Godunov update for a node coupled to extension-layer neighbours: the largest root `ū` of
///
/// ```text
///     Σ_k [(c_k ū − r_k)^+]^2 = f^2 ,     0 < c_k ≤ 1 ,
/// ```
///
/// the terms taken where `c_k ū > r_k`. This is Eq. (3) with the neighbour along axis `k` replaced
/// by its own (affine) dependence on the node: an extension-layer neighbour `O` whose update (5)
/// reads the node with weight `w` holds `u_O = w ū + r`, so `ū − u_O = (1 − w) ū − r`, i.e.
/// `c_k = 1 − w`; axes without such a neighbour have `c_k = 1` and `r_k` the neighbour's value.
/// Solving the two equations together (block Gauss–Seidel) removes the slowly contracting node ↔
/// layer cycle that plain Gauss–Seidel iterates by a factor `w` per pass; the fixed point is the
/// same. The axes are ordered by `r_k / c_k` by cross-multiplying, and the number of terms is
/// decided by comparing squares, so the only square root and division are the returned root's.
#[inline(always)]
pub fn godunov_update_coupled<const D: usize>(r: [f64; D], c: [f64; D], f: f64) -> f64 {
    // order the axes by r_k / c_k (insertion sort of at most three pairs; c_k > 0)
    let mut p: [(f64, f64); D] = [(0.0, 0.0); D];
    for k in 0..D {
        p[k] = (r[k], c[k]);
    }
    for i in 1..D {
        let mut j = i;
        while j > 0 && p[j].0 * p[j - 1].1 < p[j - 1].0 * p[j].1 {
            p.swap(j, j - 1);
            j -= 1;
        }
    }
    // add axes while the root exceeds the next r_k / c_k: A ū² − 2 B ū + C = 0
    let (mut sa, mut sb, mut sc) = (0.0f64, 0.0f64, -f * f);
    for m in 0..D {
        let (rk, ck) = p[m];
        sa += ck * ck;
        sb += ck * rk;
        sc += rk * rk;
        let disc = nonneg(sb * sb - sa * sc);
        if m + 1 == D {
            return (sb + disc.sqrt()) / sa;
        }
        // the root (sb + sqrt(disc)) / sa stays at or below the next r / c iff
        // c sqrt(disc) ≤ g = r sa − c sb (sa, c > 0), i.e. iff c² disc ≤ g², since
        // g = Σ_{k ≤ m} c_k (r c_k − c r_k) ≥ 0 with the axes ordered by r_k / c_k: decided
        // without the square root and the division, which are then taken only for the root
        // returned (they sit on the Gauss–Seidel chain of the sweep)
        let (rn, cn) = p[m + 1];
        let g = rn * sa - cn * sb;
        if cn * cn * disc <= g * g {
            return (sb + disc.sqrt()) / sa;
        }
    }
    unreachable!("the loop returns at m = D − 1")
}

/// One axis of [`godunov_update_coupled`]: the axis's smaller neighbour holds `a` and is an
/// extension-layer node that reads this node with weight `w` in its update (5), so its value is
/// `w ū + r` with `r = a − w·old` (`old`: this node's current value, at most the value the
/// neighbour last read, so `r` over-estimates the rest of its combination and the update stays an
/// upper bound). Returns `(r, 1 − w)`; when `1 − w` is below [`COUPLING_MIN`] the neighbour is a
/// copy of this node and the axis carries no derivative: `(inf, 1)` drops it (`inf` is the
/// numerical infinity). Where `a − w·old` cancels more than [`COUPLING_CANCELLATION`] of `w·old`'s
/// digits (a node inside an obstacle, `old` ≈ 1e19, whose neighbour's rest is ≈ 1), its rounding
/// can under-estimate the rest, and the coupled root would fall below the solution, where no later
/// update raises it (a circle's arc at speed 1e-20: points across the circle 97% short,
/// converged; a helper's review): the axis is then taken uncoupled, `(a, 1)`, as a plain
/// Gauss–Seidel neighbour, with the same fixed point.
#[inline(always)]
pub fn coupled_axis(a: f64, w: f64, old: f64, inf: f64) -> (f64, f64) {
    let c = 1.0 - w;
    if c > COUPLING_MIN {
        let r = a - w * old;
        if r > 0.0 && w * old <= COUPLING_CANCELLATION * r {
            (r, c)
        } else {
            (a, 1.0)
        }
    } else {
        (inf, 1.0)
    }
}

/// The most by which `w·old` may exceed the rest `r = a − w·old` in [`coupled_axis`] (2^26: `r`
/// keeps some 26 of its 52 bits; with `1 − w` above [`COUPLING_MIN`] and the values along a normal
/// equal, `w·old/r` is at most about 1e6).
pub const COUPLING_CANCELLATION: f64 = 67_108_864.0;

/// Below this `1 − w`, an extension neighbour that reads the node with weight `w` is treated as a
/// copy of it (the axis is dropped from the coupled update).
pub const COUPLING_MIN: f64 = 1e-6;

/// `max(x, 0)` as a plain compare-select (the values here are never NaN; `f64::max` spends
/// extra instructions on NaN handling).
#[inline(always)]
fn nonneg(x: f64) -> f64 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// The smaller of two values as a plain compare-select (no NaN handling: the solver never holds
/// NaN, it uses a finite numerical infinity).
#[inline(always)]
pub fn fmin(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// Sorts at most three values with a branchy network (faster than a general sort here).
#[inline(always)]
fn sort_small<const D: usize>(a: &mut [f64; D]) {
    if D >= 2 {
        let (x, y) = (a[0], a[1]);
        a[0] = fmin(x, y);
        a[1] = if x < y { y } else { x };
    }
    if D >= 3 {
        let (y, z) = (a[1], a[2]);
        a[1] = fmin(y, z);
        a[2] = if y < z { z } else { y };
        let (x, y) = (a[0], a[1]);
        a[0] = fmin(x, y);
        a[1] = if x < y { y } else { x };
    }
    if D > 3 {
        a.sort_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sided_branch() {
        // |a_x − a_y| > f: first branch of Eq. (3)
        assert_eq!(godunov_update([0.0, 5.0], 1.0), 1.0);
        assert_eq!(godunov_update([5.0, 0.0], 1.0), 1.0);
    }

    #[test]
    fn two_sided_branch_matches_eq3() {
        let (ax, ay, h) = (0.3_f64, 0.5_f64, 0.4_f64);
        let expect = 0.5 * (ax + ay + (2.0 * h * h - (ax - ay) * (ax - ay)).sqrt());
        assert!((godunov_update([ax, ay], h) - expect).abs() < 1e-15);
    }

    #[test]
    fn three_dimensional_root_satisfies_the_discrete_equation() {
        let a = [0.1, 0.12, 0.15];
        let f = 0.2;
        let u = godunov_update(a, f);
        let r: f64 = a.iter().map(|&ak| ((u - ak).max(0.0)).powi(2)).sum();
        assert!((r - f * f).abs() < 1e-14, "residual {}", r - f * f);
        assert!(u > 0.15);
    }

    #[test]
    fn diagonal_of_plane_wave() {
        // u = (x + y) / sqrt(2): neighbours at distance h/sqrt(2) below
        let h = 0.01;
        let u0 = 1.0;
        let a = u0 - h / 2f64.sqrt();
        let u = godunov_update([a, a], h);
        assert!((u - u0).abs() < 1e-12);
    }

    #[test]
    fn coupled_update_with_unit_coefficients_is_the_plain_update() {
        for a in [[0.1, 0.12, 0.15], [0.5, 0.1, 0.9], [0.0, 5.0, 7.0], [0.3, 0.3, 0.3]] {
            let f = 0.2;
            let x = godunov_update(a, f);
            let y = godunov_update_coupled(a, [1.0; 3], f);
            assert!((x - y).abs() < 1e-14, "{x} vs {y}");
        }
    }

    #[test]
    fn coupled_update_is_the_fixed_point_of_the_node_layer_cycle() {
        // node n with neighbours a_x = 0.3 (fixed) and, along y, an extension node O = w u_n + r
        let (ax, w, r, f) = (0.3f64, 0.7f64, 0.12f64, 0.1f64);
        // plain Gauss–Seidel on the cycle, from above
        let mut u = 10.0f64;
        for _ in 0..2000 {
            let o = w * u + r;
            u = u.min(godunov_update([ax, o], f));
        }
        let c = 1.0 - w;
        let v = godunov_update_coupled([ax, r], [1.0, c], f);
        assert!((u - v).abs() < 1e-12, "{u} vs {v}");
        // and the discrete equation holds with O at its consistent value
        let o = w * v + r;
        let res = (v - ax).max(0.0).powi(2) + (v - o).max(0.0).powi(2);
        assert!((res - f * f).abs() < 1e-14);
    }

    #[test]
    fn a_rest_lost_to_rounding_takes_the_axis_uncoupled() {
        let inf = 1e30;
        // old ≈ 1e19 (inside an obstacle), the neighbour's rest ≈ 1: a − w·old is rounding noise
        let (w, old) = (0.3, 1.234_567_891e19);
        let a = w * old + 1.0;
        assert_eq!(coupled_axis(a, w, old, inf), (a, 1.0));
        // a rest of 1e-3 beside old ≈ 1 keeps the coupling
        let (r, c) = coupled_axis(0.3 * 0.9 + 1e-3, 0.3, 0.9, inf);
        assert!((r - 1e-3).abs() < 1e-15 && c == 0.7);
    }

    #[test]
    fn a_neighbour_that_copies_the_node_drops_its_axis() {
        let inf = 1e6;
        // w = 1/2: a = w·old + r with r = 0.1
        let (r, c) = coupled_axis(0.5 * 0.4 + 0.1, 0.5, 0.4, inf);
        assert!((r - 0.1).abs() < 1e-15 && (c - 0.5).abs() < 1e-15);
        // a near-copy (1 − w below COUPLING_MIN) leaves the axis out: the update is the 1D one
        let (a, c) = coupled_axis(0.4, 1.0 - 1e-9, 0.4, inf);
        assert_eq!((a, c), (inf, 1.0));
        let u = godunov_update_coupled([0.3, a, 0.9], [1.0, c, 1.0], 0.1);
        assert!((u - 0.4).abs() < 1e-15, "{u}");
    }

    /// The largest root of Σ_k [(c_k u − r_k)^+]² = f² by the textbook route: for m = 1, 2, …
    /// axes in increasing r_k / c_k, the root of the first m terms, accepted once it does not
    /// exceed the next r_k / c_k (square root and division taken for every m).
    fn reference_root(r: [f64; 3], c: [f64; 3], f: f64) -> f64 {
        let mut k: Vec<(f64, f64)> = r.iter().copied().zip(c.iter().copied()).collect();
        k.sort_by(|x, y| (x.0 / x.1).partial_cmp(&(y.0 / y.1)).unwrap());
        let (mut sa, mut sb, mut sc) = (0.0, 0.0, -f * f);
        for m in 0..3 {
            sa += k[m].1 * k[m].1;
            sb += k[m].1 * k[m].0;
            sc += k[m].0 * k[m].0;
            let u = (sb + (sb * sb - sa * sc).max(0.0).sqrt()) / sa;
            if m == 2 || u <= k[m + 1].0 / k[m + 1].1 {
                return u;
            }
        }
        unreachable!()
    }

    #[test]
    fn the_branch_tests_without_square_roots_pick_the_textbook_root() {
        // the branch of Eq. (3) is decided by comparing squares (no square root or division):
        // the same roots as the textbook route, on random neighbours, on exact ties between
        // branches (a root landing exactly on the next neighbour) and with unreached neighbours
        let inf = crate::DEFAULT_INFINITY;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut one, mut two, mut three) = (0, 0, 0);
        for i in 0..20_000 {
            let f = 0.01 + 0.1 * next();
            let mut a = [next() * 0.2, next() * 0.2, next() * 0.2];
            match i % 4 {
                // a tie: a2 exactly where the two-term root of a0, a1 lands
                1 => a[2] = 0.5 * (a[0] + a[1] + (2.0 * f * f - (a[0] - a[1]).powi(2)).max(0.0).sqrt()),
                2 => a[(i / 4) % 3] = inf,
                _ => {}
            }
            let c = [1.0 - 0.9 * next(), 1.0, 1.0 - 0.9 * next()];
            let plain = godunov_update(a, f);
            let want = reference_root(a, [1.0; 3], f);
            assert!(
                (plain - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{a:?} {f}: {plain} vs {want}"
            );
            let coupled = godunov_update_coupled(a, c, f);
            let want = reference_root(a, c, f);
            assert!(
                (coupled - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{a:?} {c:?} {f}: {coupled} vs {want}"
            );
            // and the root solves its own equation
            let res: f64 = (0..3).map(|k| (c[k] * coupled - a[k]).max(0.0).powi(2)).sum();
            assert!((res - f * f).abs() <= 1e-12 * f * f, "residual {}", res - f * f);
            let mut s = a;
            s.sort_by(|x, y| x.partial_cmp(y).unwrap());
            match (plain <= s[1], plain <= s[2]) {
                (true, _) => one += 1,
                (false, true) => two += 1,
                _ => three += 1,
            }
        }
        // every branch of Eq. (3) was taken many times
        assert!(one > 1000 && two > 1000 && three > 1000, "{one} {two} {three}");
    }

    #[test]
    fn infinite_neighbours_are_ignored() {
        let inf = crate::DEFAULT_INFINITY;
        assert_eq!(godunov_update([0.5, inf, inf], 0.1), 0.6);
    }
}
