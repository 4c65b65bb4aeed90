//! The upwind local solver for the Riemannian eikonal equation `sqrt(∇uᵀ M ∇u) = 1/F`,
//! `G(p) = F sqrt(pᵀ M p) = 1`, `M` symmetric positive definite.
//!
//! *Projection on a face.* `min_q (P + q)ᵀ M (P + q)` over `q` off the face's axes `K` is
//! `Pᵀ S_K P` with the Schur complement `S_K = M_KK − M_K⊥ M_⊥⊥⁻¹ M_⊥K` (computed by eliminating
//! the off-face axes one by one; positive definite with `M`). Equivalently `S_K = ((M⁻¹)_KK)⁻¹`:
//! the travel time along a displacement `d` in the face is `s sqrt(dᵀ M⁻¹ d)`.
//!
//! *The quadratic.* With `u_j = base + w_j`, `μ = base + t`, sides `σ_j` and
//! `C_ij = σ_i σ_j (S_K)_ij`, the equation `Pᵀ S_K P = s²`, `P_j = σ_j (t − w_j)/h`, reads
//!
//! ```text
//!     Σ_ij C_ij (t − w_i)(t − w_j) = s² h²,
//! ```
//!
//! `A t² − 2 B t + C = 0` with `A = Σ C_ij`, `B = Σ_ij C_ij w_j`, `C = Σ C_ij w_i w_j − s²h²`. The
//! characteristic `∂G/∂P ∝ S_K P` enters from the face iff `(C (t − w))_j ≥ 0` for every `j`. On a
//! vertex `t = s h / sqrt((S_K)_kk) = s h sqrt((M⁻¹)_kk)`.
//!
//! *Symmetry.* `M` is exactly symmetric (the equation sees only its symmetric part, which
//! [`SymmetricMetric`] stores): `C` is built from the entries above the diagonal, and the
//! deficit proof of the natural orthant ([`Faces::deficit_proved`]) reads `M P` off the causality
//! weights, `W = C (t − w) = σ h M P`, instead of forming `M P` again.

use super::{larger_root, upwind_min, weight_floor, Faces, LocalSolver};
use crate::scheme::hamiltonians::SymmetricMetric;

/// The larger of two values as a plain compare-select (no NaN handling).
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

struct Riemann<const D: usize> {
    m: [[f64; D]; D],
    s: f64,
    /// 0 when [`Faces::deficit_proved`] may use its quick test (the solve's metrics are well
    /// conditioned, [`SymmetricMetric::well_conditioned`]); `f64::MAX` otherwise, which no axis in
    /// `def` reaches, so that it decides only `def = 0`.
    refuse: f64,
}

impl<const D: usize> Faces<D> for Riemann<D> {
    /// `S_K` in its first `m` rows and columns.
    type Projected = [[f64; D]; D];

    #[inline(always)]
    fn least_slowness(&self) -> f64 {
        // λ_max(M) ≤ tr M
        let tr: f64 = (0..D).map(|k| self.m[k][k]).sum();
        self.s / tr.sqrt()
    }

    /// `∂G/∂p ∝ M p`.
    #[inline(always)]
    fn velocity(&self, p: [f64; D]) -> [f64; D] {
        core::array::from_fn(|k| (0..D).map(|l| self.m[k][l] * p[l]).sum())
    }

    /// `q* = −(M_off,K · P) / M_off,off` for one axis off the face; for two (`a < b`, the face a
    /// vertex `k`) the 2×2 system `M_⊥⊥ q* = −M_⊥k P_k` by Cramer's rule.
    #[inline(always)]
    fn complete(&self, p: [f64; D], off: u32) -> [f64; D] {
        let m = &self.m;
        let mut out = p;
        if off.count_ones() == 1 {
            let j = off.trailing_zeros() as usize;
            let r = &m[j];
            out[j] = -(0..D).filter(|&k| k != j).map(|k| r[k] * p[k]).sum::<f64>() / r[j];
        } else if D == 3 {
            let k = (7 & !off).trailing_zeros() as usize;
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            let (ra, rb) = (m[a][k] * p[k], m[b][k] * p[k]);
            let det = m[a][a] * m[b][b] - m[a][b] * m[b][a];
            out[a] = -(m[b][b] * ra - m[a][b] * rb) / det;
            out[b] = -(m[a][a] * rb - m[b][a] * ra) / det;
        }
        out
    }

    #[inline(always)]
    fn inside(&self, p: [f64; D]) -> bool {
        let r = self.s * (1.0 - 1e-12);
        self.form(p) <= r * r
    }

    /// [`Faces::inside`] at the corners, expanded about `p`: with `d = p − moved` (0 off `def`),
    /// `q(S) = pᵀMp + Σ_{k∈S} d_k (d_k M_kk − g_k) + Σ_{k<l∈S} d_k d_l (M_kl + M_lk)`,
    /// `g = (M + Mᵀ) p`; every corner evaluated (no branch on `def` or on the answers) and those
    /// of `def` picked ([`super::SUBSETS_OF`]). The same answer as [`Faces::inside`] at each corner
    /// but where `q` lies within rounding (~1e-15 of `s²`) of the bound `s²(1 − 1e-12)²`: either
    /// answer is then a correct proof (the margin is 1e-12).
    #[inline(always)]
    fn inside_corners(&self, p: [f64; D], moved: [f64; D], def: usize) -> bool {
        let m = &self.m;
        let d: [f64; D] = core::array::from_fn(|k| p[k] - moved[k]);
        let g: [f64; D] = core::array::from_fn(|k| (0..D).map(|l| (m[k][l] + m[l][k]) * p[l]).sum::<f64>());
        let q0 = 0.5 * (0..D).map(|k| p[k] * g[k]).sum::<f64>();
        let e: [f64; D] = core::array::from_fn(|k| d[k] * (d[k] * m[k][k] - g[k]));
        let c: [[f64; D]; D] = core::array::from_fn(|k| core::array::from_fn(|l| d[k] * d[l] * (m[k][l] + m[l][k])));
        let r = self.s * (1.0 - 1e-12);
        let lim = r * r - q0;
        let mut fails = 0u32;
        for sub in 1..(1usize << D) {
            let mut q = 0.0;
            for k in 0..D {
                if sub >> k & 1 == 1 {
                    q += e[k];
                    for l in k + 1..D {
                        if sub >> l & 1 == 1 {
                            q += c[k][l];
                        }
                    }
                }
            }
            fails |= ((q > lim) as u32) << sub;
        }
        let ok = fails & super::SUBSETS_OF[def] as u32 == 0;
        debug_assert!(ok == super::every_corner_inside(self, p, moved, def) || self.near_the_bound(p, moved, def));
        ok
    }

    /// `φ(d) = s sqrt(dᵀAd)`, `A = M⁻¹`, even. Mirroring `d_k` changes `dᵀAd` by
    /// `4 |d_k| |A_k⊥·d_⊥|`, and `sqrt(dᵀAd) ≥ |d| / sqrt(λ_max(M))`, so
    /// `τ_k = 2 s sqrt(tr M) Σ_{l≠k} |A_kl|` (0 when `A`'s row k is diagonal); and by the triangle
    /// inequality `τ_k = 2 s sqrt(A_kk)`. The smaller of the two, for both sides.
    #[inline(always)]
    fn mirror_slack(&self) -> [[f64; 2]; D] {
        let m = &self.m;
        let tr: f64 = (0..D).map(|k| m[k][k]).sum();
        let (off, diag) = inverse_rows(m);
        core::array::from_fn(|k| {
            let t = if off[k] == 0.0 {
                0.0
            } else {
                2.0 * self.s * (tr.sqrt() * off[k]).min(diag[k].sqrt())
            };
            [t, t]
        })
    }

    #[inline(always)]
    fn project(&self, mask: u32) -> Option<[[f64; D]; D]> {
        let m = &self.m;
        let mut out = [[0.0; D]; D];
        let full = (1u32 << D) - 1;
        if mask == full {
            return (m[0][0] > 0.0).then_some(*m);
        }
        let off = (full & !mask).count_ones();
        if off == 1 {
            // one axis j off the face: S = M_KK − M_Kj M_jK / M_jj
            let j = (full & !mask).trailing_zeros() as usize;
            let piv = m[j][j];
            if !(piv > 0.0) {
                return None;
            }
            let mut a = 0;
            for r in 0..D {
                if r == j {
                    continue;
                }
                let mut b = 0;
                for c in 0..D {
                    if c == j {
                        continue;
                    }
                    out[a][b] = m[r][c] - m[r][j] * m[j][c] / piv;
                    b += 1;
                }
                a += 1;
            }
        } else {
            // D = 3, a vertex k: S = 1 / (M⁻¹)_kk = det M / (the cofactor of M_kk)
            let k = mask.trailing_zeros() as usize;
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let cof = m[i][i] * m[j][j] - m[i][j] * m[j][i];
            let det = m[k][k] * cof - m[k][i] * (m[i][k] * m[j][j] - m[i][j] * m[j][k])
                + m[k][j] * (m[i][k] * m[j][i] - m[i][i] * m[j][k]);
            if !(cof > 0.0) {
                return None;
            }
            out[0][0] = det / cof;
        }
        (out[0][0] > 0.0).then_some(out)
    }

    #[inline(always)]
    fn solve<const M: usize, const STRICT: bool>(
        &self,
        sk: &[[f64; D]; D],
        w: &[f64; M],
        sg: &[f64; M],
        h: f64,
        below: f64,
    ) -> Option<f64> {
        self.quadratic::<M, STRICT>(sk, w, sg, h, below).map(|(t, _)| t)
    }

    type Strict = Weights<D>;

    #[inline(always)]
    fn solve_strict(&self, sk: &[[f64; D]; D], w: &[f64; D], sg: &[f64; D], h: f64) -> Option<(f64, Weights<D>)> {
        let (t, weights) = self.quadratic::<D, true>(sk, w, sg, h, f64::INFINITY)?;
        Some((
            t,
            Weights {
                weights,
                t,
                w: *w,
                sh: self.s * h,
            },
        ))
    }

    /// With `d = Σ_{k∈S} σ_k δ_k e_k / h` (the deficit axes `S ⊆ def` moved inwards) and
    /// `W = σ h M P` (the causality weights, [`Weights`]; `M` symmetric):
    ///
    /// ```text
    ///     h² q(P − d) = h² q(P) − 2 Σ_S δ_k W_k + Σ_{k,l∈S} σ_k σ_l δ_k δ_l M_kl,
    /// ```
    ///
    /// and the last sum is at most `(Σ_S δ_k sqrt(M_kk))² ≤ D Σ_S δ_k² M_kk` (`|M_kl| ≤
    /// sqrt(M_kk M_ll)`, then Cauchy–Schwarz). So every corner lies inside the margin of
    /// [`Faces::inside`] when every deficit axis gives `δ_k (2 W_k − D δ_k M_kk) ≥ max(L, 0)`,
    /// `L = h² q(P) − (s h (1 − 1e-12))²` (a sum of such terms then reaches `L`): `D` products
    /// and comparisons instead of the `2^D − 1` corners. Where the deficits are rounding-sized
    /// (the discrete solution linear along an axis: most visits) the linear term decides;
    /// larger ones fall back to the corners.
    #[inline(always)]
    fn deficit_proved(&self, st: &Weights<D>, deficit: &[f64; D], def: usize) -> bool {
        let q0 = tree_sum::<D>(core::array::from_fn(|k| (st.t - st.w[k]) * st.weights[k]));
        let r = st.sh * (1.0 - 1e-12);
        let need = fmax(q0 - r * r, 0.0) + self.refuse;
        let dd = D as f64;
        // each axis's test, those off `def` against 0 (their deficit is 0): without a branch,
        // so that `def = 0` (every gain 0) passes too; a NaN fails
        let fails = (0..D).fold(0u32, |fails, k| {
            let gain = deficit[k] * (2.0 * st.weights[k] - dd * deficit[k] * self.m[k][k]);
            fails | !(gain >= need * ((def >> k & 1) as f64)) as u32
        });
        fails == 0
    }
}

/// What the strict solve of a full face leaves for [`Faces::deficit_proved`]: the causality
/// weights `W = C (t − w)` (`W_k = σ_k h (M P)_k`, `P` the face's gradient), `t`, `w` and `s h`.
#[derive(Clone, Copy)]
pub(crate) struct Weights<const D: usize> {
    weights: [f64; D],
    t: f64,
    w: [f64; D],
    sh: f64,
}

impl<const D: usize> Riemann<D> {
    /// The face's value `t` and its causality weights `W = C (t − w)` ([`Faces::solve`]).
    #[inline(always)]
    fn quadratic<const M: usize, const STRICT: bool>(
        &self,
        sk: &[[f64; D]; D],
        w: &[f64; M],
        sg: &[f64; M],
        h: f64,
        below: f64,
    ) -> Option<(f64, [f64; M])> {
        let sh = self.s * h;
        if M == 1 {
            let ok = STRICT || sh * sh < below * below * sk[0][0];
            // one axis: the weight is the value times S_kk (> 0)
            return ok.then(|| {
                let t = sh / sk[0][0].sqrt();
                (t, [t * sk[0][0]; M])
            });
        }
        // C_ij = σ_i σ_j S_ij (σ_i² = 1: the diagonal as it is); its row sums r = C 1 and z = C w
        // give A = Σ r, B = Σ z, C = w·z − s²h² and the causality weights (C (t − w))_i = t r_i − z_i:
        // sums of M terms, not of M² (a shorter chain, and other rounding than the sums over i, j)
        // (M symmetric: the entries above the diagonal, mirrored)
        let c: [[f64; M]; M] = core::array::from_fn(|i| {
            core::array::from_fn(|j| match i.cmp(&j) {
                core::cmp::Ordering::Equal => sk[i][i],
                core::cmp::Ordering::Less => sg[i] * sg[j] * sk[i][j],
                core::cmp::Ordering::Greater => sg[j] * sg[i] * sk[j][i],
            })
        });
        let r: [f64; M] = core::array::from_fn(|i| tree_sum::<M>(core::array::from_fn(|j| c[i][j])));
        let z: [f64; M] = core::array::from_fn(|i| tree_sum::<M>(core::array::from_fn(|j| c[i][j] * w[j])));
        let a = tree_sum::<M>(r);
        if !(a > 0.0) {
            return None;
        }
        let b = tree_sum::<M>(z);
        let cc = tree_sum::<M>(core::array::from_fn(|i| w[i] * z[i])) - sh * sh;
        // the causality weights sum to a t − b
        let t = larger_root::<STRICT>(a, b, cc, below)?;
        let floor = weight_floor::<STRICT>(a * t - b);
        let weights: [f64; M] = core::array::from_fn(|i| t * r[i] - z[i]);
        let causal = (0..M).fold(true, |ok, i| ok & (weights[i] >= floor));
        causal.then_some((t, weights))
    }
    /// `pᵀ M p` (the same sums in the same order wherever it is evaluated).
    #[inline(always)]
    fn form(&self, p: [f64; D]) -> f64 {
        (0..D)
            .map(|k| p[k] * (0..D).map(|l| self.m[k][l] * p[l]).sum::<f64>())
            .sum()
    }

    /// Whether some corner's `pᵀMp` lies within 1e-14 `s²` of the bound of [`Faces::inside`].
    fn near_the_bound(&self, p: [f64; D], moved: [f64; D], def: usize) -> bool {
        let r = self.s * (1.0 - 1e-12);
        let mut sub = def;
        let mut near = false;
        while sub != 0 {
            near |= (self.form(super::corner(p, moved, sub)) - r * r).abs() <= 1e-14 * self.s * self.s;
            sub = (sub - 1) & def;
        }
        near
    }
}

/// The sum of `M ≤ 3` terms, left to right (the quadratic's sums each have `M` terms, not `M²`).
#[inline(always)]
fn tree_sum<const M: usize>(x: [f64; M]) -> f64 {
    match M {
        1 => x[0],
        2 => x[0] + x[1],
        _ => x.iter().skip(2).fold(x[0] + x[1], |s, v| s + v),
    }
}

/// `Σ_{l≠k} |(M⁻¹)_kl|` and `(M⁻¹)_kk` per row, for `D ≤ 3` (by cofactors); infinite if `M` is
/// singular.
#[inline(always)]
fn inverse_rows<const D: usize>(m: &[[f64; D]; D]) -> ([f64; D], [f64; D]) {
    let mut out = [0.0; D];
    let mut diag = [f64::INFINITY; D];
    if D == 2 {
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let a = (m[0][1].abs() + m[1][0].abs()) * 0.5 / det.abs();
        out[0] = a;
        out[1] = a;
        diag[0] = m[1][1] / det.abs();
        diag[1] = m[0][0] / det.abs();
    } else if D == 3 {
        // cofactor C_ij (of M_ij); (M⁻¹)_kl = C_lk / det
        let c = |i: usize, j: usize| {
            let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
            let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
            m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
        };
        let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
        for k in 0..3 {
            out[k] = (c((k + 1) % 3, k).abs() + c((k + 2) % 3, k).abs()) / det.abs();
            diag[k] = c(k, k) / det.abs();
        }
    } else {
        out = [f64::INFINITY; D];
    }
    if out.iter().chain(&diag).all(|x| x.is_finite() && *x >= 0.0) {
        (out, diag)
    } else {
        ([f64::INFINITY; D], [f64::INFINITY; D])
    }
}

impl<'a, const D: usize> LocalSolver<D> for SymmetricMetric<'a, D> {
    /// The node's `(M + Mᵀ)/2` unpacked from its `D(D+1)/2` numbers into the full (exactly
    /// symmetric) matrix.
    #[inline(always)]
    fn update(&self, node: usize, minus: [f64; D], plus: [f64; D], h: f64, old: f64) -> f64 {
        let faces = Riemann {
            m: self.at(node),
            s: self.slowness_at(node),
            refuse: if self.well_conditioned() { 0.0 } else { f64::MAX },
        };
        upwind_min(&faces, minus, plus, h, old)
    }

    fn slowness_bound(&self) -> Option<f64> {
        SymmetricMetric::slowness_bound(self)
    }

    fn builtin(&self) -> super::Builtin<'_, D> {
        super::Builtin::Metric(self)
    }

    fn bytes_per_node(&self) -> usize {
        SymmetricMetric::bytes_per_node(self)
    }

    fn prefetch_nodes(&self, start: usize, end: usize) {
        SymmetricMetric::prefetch_nodes(self, start, end)
    }
}

#[cfg(test)]
pub(crate) fn tests_faces<const D: usize>(s: f64, m: [[f64; D]; D]) -> impl Faces<D> {
    Riemann {
        m,
        s,
        refuse: if crate::scheme::hamiltonians::symmetric_metric::quick_proof_applies(m) {
            0.0
        } else {
            f64::MAX
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::godunov::godunov_update;
    use crate::scheme::upwind::tests::linear_neighbours;

    #[test]
    fn identity_metric_is_the_isotropic_godunov_update() {
        let s = [1.3];
        let m = [[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]];
        let met = SymmetricMetric::new(&s, &m);
        let h = 0.1;
        for (minus, plus) in [
            ([1.0, 1.02, 1.5], [1.3, 1.1, 1.01]),
            ([1.0, 1.03, 1.05], [1.3, 1.04, 1.02]),
        ] {
            let mins: [f64; 3] = core::array::from_fn(|k| f64::min(minus[k], plus[k]));
            let want = godunov_update(mins, h * s[0]);
            assert!((met.update(0, minus, plus, h, 1e6) - want).abs() < 1e-14);
        }
    }

    #[test]
    fn exact_on_plane_waves_of_a_tilted_metric() {
        // u = q·x with qᵀ M q = s²
        let s = [0.8];
        let m3 = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];
        let met = SymmetricMetric::new(&s, &[m3]);
        let h = 0.05;
        for i in 0..60 {
            let (a, b) = (i as f64 * 0.7, i as f64 * 0.29);
            let n = [a.cos() * b.sin(), a.sin() * b.sin(), b.cos()];
            let mut q2 = 0.0;
            for r in 0..3 {
                for c in 0..3 {
                    q2 += n[r] * m3[r][c] * n[c];
                }
            }
            let q = core::array::from_fn(|k| s[0] * n[k] / q2.sqrt());
            let (minus, plus) = linear_neighbours(q, h);
            let got = met.update(0, minus, plus, h, 1e6);
            assert!(got.abs() < 1e-13, "n {n:?}: {got}");
        }
    }

    #[test]
    fn schur_complement_is_the_inverse_of_the_inverse_block() {
        let m3 = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];
        let r = Riemann {
            m: m3,
            s: 1.0,
            refuse: 0.0,
        };
        // vertex along x: S = 1/(M⁻¹)_00 = det M / (M11 M22 − M12²)
        let det = 2.0 * (0.9 * 0.5 - 0.04) - 0.6 * (0.6 * 0.5 + 0.06) + (-0.3) * (0.6 * 0.2 + 0.27);
        let p = r.project(1).unwrap();
        assert!((p[0][0] - det / (0.9 * 0.5 - 0.04)).abs() < 1e-14);
        // edge (x, y): S = M_KK − M_K2 M_2K / M_22
        let e = r.project(3).unwrap();
        assert!((e[0][1] - (0.6 - (-0.3) * 0.2 / 0.5)).abs() < 1e-15 && (e[1][1] - (0.9 - 0.04 / 0.5)).abs() < 1e-15);
    }
}
