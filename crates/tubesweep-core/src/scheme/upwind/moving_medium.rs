//! The upwind local solver for the moving medium (Sect. 6.3) `|∇u| = |1 − v·∇u| / F`, written as
//! the convex, positively homogeneous `G(p) = F|p| + v·p = 1` (a Randers metric), which has the
//! same solution where `|v| < F` (docs/hamiltonians.md).
//!
//! *Projection on a face.* With `p = P + q`, `P` in the face's axes `K` and `q` off them,
//! `min_q F sqrt(|P|² + |q|²) + v_⊥·q` is attained at `q = −v_⊥ |P| / F_K` and equals
//! `F_K |P| + v_K·P`, `F_K = sqrt(F² − |v_⊥|²)`: again a Randers form, subsonic on the face
//! (`|v_K| < F_K ⟺ |v| < F`).
//!
//! *The quadratic.* With the vertex values `u_j = base + w_j`, the unknown `μ = base + t`, sides
//! `σ_j` (+1 for the minus neighbour) and `ω_j = σ_j v_j`, the one-sided differences are
//! `P_j = σ_j (t − w_j)/h` and `F_K |P| = 1 − v_K·P` reads
//!
//! ```text
//!     F_K² Σ (t − w_j)² = (h + Q − W t)²,   W = Σ ω_j,  Q = Σ ω_j w_j,
//! ```
//!
//! i.e. `A t² − 2 B t + C = 0` with `A = m F_K² − W²` (> 0 when subsonic), `B = F_K² Σ w_j − W(h + Q)`,
//! `C = F_K² Σ w_j² − (h + Q)²`. A root is the face's value when `g = h + Q − W t > 0` (then
//! `1 − v·P = g/h > 0`: the branch of the equation as written) and the characteristic
//! `∂G/∂P = F_K P/|P| + v_K` enters from the face: `σ_j ∂G/∂P_j ∝ F_K² (t − w_j) + ω_j g ≥ 0`.
//! On a vertex (`m = 1`) `t = h / (F_K + ω)`, the exact time of the plane wave along the axis.
//!
//! *Supersonic nodes* (`|v| ≥ F`) have no subsonic face: no face admits a solution and the node
//! keeps its value. The Python layer refuses such flows for this solver (the Lax–Friedrichs
//! update of the equation as written is used with `allow_supersonic=True`).

use super::{larger_root, per_node_bytes, prefetch_per_node, upwind_min, weight_floor, Faces, LocalSolver};
use crate::scheme::hamiltonians::{slowness_at, MovingMedium};
use crate::Hamiltonian;

/// The moving medium at one node: `F²`, `F`, `v`.
struct Randers<const D: usize> {
    f2: f64,
    f: f64,
    v: [f64; D],
}

/// `F_K²` and the flow's components on the face's axes (in increasing order).
#[derive(Clone, Copy)]
struct Face<const D: usize> {
    fk2: f64,
    vk: [f64; D],
}

impl<const D: usize> Faces<D> for Randers<D> {
    type Projected = Face<D>;
    const JUMP: bool = true;

    #[inline(always)]
    fn least_slowness(&self) -> f64 {
        // no direction is faster than F + |v| ≤ F + Σ|v_k| (a bound without a square root)
        1.0 / (self.f + self.v.iter().map(|x| x.abs()).sum::<f64>())
    }

    /// `∂G/∂p = F p/|p| + v` (`v` where `p = 0`).
    #[inline(always)]
    fn velocity(&self, p: [f64; D]) -> [f64; D] {
        let n = p.iter().map(|x| x * x).sum::<f64>().sqrt();
        let scale = if n > 0.0 { self.f / n } else { 0.0 };
        core::array::from_fn(|k| scale * p[k] + self.v[k])
    }

    /// The signs of [`Faces::velocity`] without the square root and without branches: where `p_k`
    /// and `v_k` agree in sign, that sign; otherwise the sign of the larger of `F |p_k|` and
    /// `|p| |v_k|` (`p_k`'s on a tie).
    #[inline(always)]
    fn upwind_orthant(&self, p: [f64; D]) -> usize {
        let n2 = p.iter().map(|x| x * x).sum::<f64>();
        let mut o = 0;
        for k in 0..D {
            let (a, b) = (p[k], self.v[k]);
            let pick_a = ((a >= 0.0) == (b >= 0.0)) | (self.f2 * a * a >= n2 * b * b);
            let negative = (pick_a & (a < 0.0)) | (!pick_a & (b < 0.0));
            o |= (negative as usize) << k;
        }
        o
    }

    /// `q* = −v_off |P| / F_K`, `F_K = sqrt(F² − |v_off|²)` (see the projection above).
    #[inline(always)]
    fn complete(&self, p: [f64; D], off: u32) -> [f64; D] {
        let n2: f64 = (0..D).filter(|&k| off >> k & 1 == 0).map(|k| p[k] * p[k]).sum();
        let fk2 = (0..D)
            .filter(|&k| off >> k & 1 == 1)
            .fold(self.f2, |a, k| a - self.v[k] * self.v[k]);
        let scale = (n2 / fk2).sqrt();
        core::array::from_fn(|k| if off >> k & 1 == 1 { -self.v[k] * scale } else { p[k] })
    }

    #[inline(always)]
    fn inside(&self, p: [f64; D]) -> bool {
        // F|p| ≤ r = 1 − 1e-12 − v·p, without the square root
        let r = 1.0 - 1e-12 - (0..D).map(|k| self.v[k] * p[k]).sum::<f64>();
        r >= 0.0 && self.f2 * p.iter().map(|x| x * x).sum::<f64>() <= r * r
    }

    /// [`Faces::inside`] at the corners with the products `v_k p_k` and `p_k²` of both choices per
    /// axis computed once (the same bits as at each corner alone), every corner evaluated (no
    /// branch on `def` or on the answers) and those of `def` picked ([`super::SUBSETS_OF`]).
    #[inline(always)]
    fn inside_corners(&self, p: [f64; D], moved: [f64; D], def: usize) -> bool {
        let vp: [[f64; 2]; D] = core::array::from_fn(|k| [self.v[k] * p[k], self.v[k] * moved[k]]);
        let pp: [[f64; 2]; D] = core::array::from_fn(|k| [p[k] * p[k], moved[k] * moved[k]]);
        let mut fails = 0u32;
        for sub in 1..(1usize << D) {
            let r = 1.0 - 1e-12 - (0..D).map(|k| vp[k][sub >> k & 1]).sum::<f64>();
            let inside = (r >= 0.0) & (self.f2 * (0..D).map(|k| pp[k][sub >> k & 1]).sum::<f64>() <= r * r);
            fails |= (!inside as u32) << sub;
        }
        let ok = fails & super::SUBSETS_OF[def] as u32 == 0;
        debug_assert_eq!(ok, super::every_corner_inside(self, p, moved, def));
        ok
    }

    /// `φ(d) = (−v·d + R(d)) / (F² − |v|²)`, `R = sqrt((v·d)² + (F² − |v|²)|d|²)`. Mirroring `d_k`
    /// keeps `|d|` and changes `v·d` by `−2 v_k d_k`, and
    /// `R' − R = −2 v_k d_k (v·d + v·d') / (R + R')`, so
    /// `φ(d') − φ(d) = 2 v_k d_k β / (F² − |v|²)` with `β = 1 − (v·d + v·d')/(R + R')` in
    /// `[1 − |v|/F, 1 + |v|/F]` (`|v·d| ≤ R |v|/F`). When `v_k d_k > 0` (the path from that
    /// side runs with the flow) mirroring costs at most `τ |d_k|`, `τ = 2 |v_k| / (F (F − |v|))`;
    /// when `v_k d_k < 0` it gains at least `2 |v_k| |d_k| / (F (F + |v|))`: a negative slack.
    /// `d_k > 0` from the minus neighbour. Infinite when supersonic.
    #[inline(always)]
    fn mirror_slack(&self) -> [[f64; 2]; D] {
        let speed = self.v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(self.f > speed) {
            return [[f64::INFINITY; 2]; D];
        }
        let (up, down) = (2.0 / (self.f * (self.f - speed)), -2.0 / (self.f * (self.f + speed)));
        core::array::from_fn(|k| {
            let a = self.v[k].abs();
            match self.v[k] {
                x if x > 0.0 => [up * a, down * a],
                x if x < 0.0 => [down * a, up * a],
                _ => [0.0, 0.0],
            }
        })
    }

    #[inline(always)]
    fn project(&self, mask: u32) -> Option<Face<D>> {
        let mut fk2 = self.f2;
        let mut on = 0.0;
        let mut vk = [0.0; D];
        let mut j = 0;
        for k in 0..D {
            let v2 = self.v[k] * self.v[k];
            if mask >> k & 1 == 0 {
                fk2 -= v2;
            } else {
                on += v2;
                vk[j] = self.v[k];
                j += 1;
            }
        }
        // supersonic (|v| ≥ F): no face has a solution
        (fk2 > on).then_some(Face { fk2, vk })
    }

    #[inline(always)]
    fn solve<const M: usize, const STRICT: bool>(
        &self,
        p: &Face<D>,
        w: &[f64; M],
        sg: &[f64; M],
        h: f64,
        below: f64,
    ) -> Option<f64> {
        if M == 1 {
            // t = h / (F_K + ω) < T  ⟺  h − T ω < T F_K
            let om = sg[0] * p.vk[0];
            let r = h - below * om;
            return (STRICT || r < 0.0 || r * r < below * below * p.fk2).then(|| h / (p.fk2.sqrt() + om));
        }
        let om: [f64; M] = core::array::from_fn(|j| sg[j] * p.vk[j]);
        let (mut big_w, mut q, mut u1, mut u2) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..M {
            big_w += om[j];
            q += om[j] * w[j];
            u1 += w[j];
            u2 += w[j] * w[j];
        }
        let hq = h + q;
        let a = M as f64 * p.fk2 - big_w * big_w;
        let b = p.fk2 * u1 - big_w * hq;
        let c = p.fk2 * u2 - hq * hq;
        // the causality weights F_K²(t − w_j) + ω_j g sum to a t − b
        let t = larger_root::<STRICT>(a, b, c, below)?;
        let g = hq - big_w * t;
        let floor = weight_floor::<STRICT>(a * t - b);
        let causal = (0..M).fold(g > 0.0, |ok, j| ok & (p.fk2 * (t - w[j]) + om[j] * g >= floor));
        causal.then_some(t)
    }

    type Strict = ();

    #[inline(always)]
    fn solve_strict(&self, p: &Face<D>, w: &[f64; D], sg: &[f64; D], h: f64) -> Option<(f64, ())> {
        self.solve::<D, true>(p, w, sg, h, f64::INFINITY).map(|t| (t, ()))
    }
}

impl<'a, const D: usize> LocalSolver<D> for MovingMedium<'a, D> {
    #[inline(always)]
    fn update(&self, node: usize, minus: [f64; D], plus: [f64; D], h: f64, old: f64) -> f64 {
        let f = 1.0 / slowness_at(self.slowness, node);
        let v = self.flow[node];
        let faces = Randers { f2: f * f, f, v };
        upwind_min(&faces, minus, plus, h, old)
    }

    fn slowness_bound(&self) -> Option<f64> {
        Hamiltonian::<D>::slowness_bound(self)
    }

    fn builtin(&self) -> super::Builtin<'_, D> {
        super::Builtin::MovingMedium(self)
    }

    fn bytes_per_node(&self) -> usize {
        per_node_bytes(self.flow) + per_node_bytes(self.slowness)
    }

    fn prefetch_nodes(&self, start: usize, end: usize) {
        prefetch_per_node(self.flow, start, end);
        prefetch_per_node(self.slowness, start, end);
    }
}

#[cfg(test)]
pub(crate) fn tests_faces<const D: usize>(f: f64, v: [f64; D]) -> impl Faces<D> {
    Randers { f2: f * f, f, v }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::godunov::godunov_update;
    use crate::scheme::upwind::tests::linear_neighbours;

    fn solver<'a, const D: usize>(s: &'a [f64], flow: &'a [[f64; D]]) -> MovingMedium<'a, D> {
        MovingMedium {
            slowness: s,
            flow,
            sigma: None,
        }
    }

    #[test]
    fn zero_flow_is_the_isotropic_godunov_update() {
        let s = [0.7];
        let flow = [[0.0; 3]];
        let ms = solver(&s, &flow);
        let h = 0.1;
        for (minus, plus) in [
            ([1.0, 1.02, 1.5], [1.3, 1.1, 1.01]),
            ([1.0, 1.5, 1.5], [1.3, 1.6, 1.7]),
            ([1.0, 1.03, 1.05], [1.3, 1.04, 1.02]),
            ([2.0, 2.0, 2.0], [2.0, 2.0, 2.0]),
        ] {
            let mins: [f64; 3] = core::array::from_fn(|k| f64::min(minus[k], plus[k]));
            let want = godunov_update(mins, h * s[0]);
            let got = ms.update(0, minus, plus, h, 1e6);
            assert!((got - want).abs() < 1e-14, "{got} {want}");
        }
    }

    #[test]
    fn exact_on_plane_waves() {
        // u = n·x / (F + v·n) solves F|∇u| + v·∇u = 1 for every unit n
        let (f, h) = (1.0, 0.05);
        let s = [1.0 / f];
        for v in [[0.3, -0.4, 0.1], [0.0, 0.6, 0.0], [-0.5, 0.5, 0.5]] {
            let flow = [v];
            let ms = solver(&s, &flow);
            for i in 0..50 {
                let (a, b) = (i as f64 * 0.7, i as f64 * 0.31);
                let n = [a.cos() * b.sin(), a.sin() * b.sin(), b.cos()];
                let c = f + v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
                let q = core::array::from_fn(|k| n[k] / c);
                let (minus, plus) = linear_neighbours(q, h);
                let got = ms.update(0, minus, plus, h, 1e6);
                assert!(got.abs() < 1e-13, "v {v:?} n {n:?}: {got}");
            }
        }
    }

    #[test]
    fn monotone_in_the_neighbour_values() {
        let s = [1.0];
        let flow = [[0.4, -0.3]];
        let ms = solver(&s, &flow);
        let h = 0.1;
        let mut x = 0.123_f64;
        for _ in 0..2000 {
            let mut r = || {
                x = (x * 9301.0 + 0.4927).fract();
                x * 0.2
            };
            let minus = [r(), r()];
            let plus = [r(), r()];
            let base = ms.update(0, minus, plus, h, 1e6);
            for k in 0..4 {
                let (mut m2, mut p2) = (minus, plus);
                if k < 2 {
                    m2[k] += 0.01
                } else {
                    p2[k - 2] += 0.01
                }
                let up = ms.update(0, m2, p2, h, 1e6);
                assert!(up >= base - 1e-15, "{minus:?} {plus:?}: {base} -> {up}");
                assert!(up <= base + 0.01 + 1e-15);
            }
            assert!(base > minus.iter().chain(&plus).cloned().fold(f64::INFINITY, f64::min));
        }
    }

    #[test]
    fn a_supersonic_node_keeps_its_value() {
        let s = [1.0];
        let flow = [[1.2, 0.0]];
        assert_eq!(solver(&s, &flow).update(0, [0.0, 0.0], [0.0, 0.0], 0.1, 5.0), 5.0);
    }
}
