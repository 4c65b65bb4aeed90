//! Upwind (Godunov-type) local solvers for convex, positively homogeneous Hamiltonians
//! `H(x, p) = G_x(p) − 1` (the moving medium `F|p| + v·p = 1` of Sect. 6.3, a Randers metric, and
//! the Riemannian metric `F sqrt(pᵀ M p) = 1`), the scheme of Tsai, Cheng, Osher & Zhao (SIAM J.
//! Numer. Anal. 41, 2003, the paper's ref. [35]) written in its equivalent semi-Lagrangian form.
//!
//! # The update
//!
//! The `2D` axis neighbours `y = x ± h e_k` of a node are the vertices of a cross-polytope; its
//! faces ("upwind simplices") are the sets `K` of axes with one side `σ_k ∈ {−, +}` each: `3^D − 1`
//! of them (vertices, edges, and in 3D triangles). With `φ(d)` the travel time along a straight
//! displacement `d` (the Lagrangian dual of `H`: `φ(d) = sup { p·d : G(p) ≤ 1 }`), the update is
//!
//! ```text
//!     u(x) ← min over faces K, min over λ ≥ 0, Σλ = 1 of   Σ_k λ_k u(y_k) + φ(x − Σ_k λ_k y_k)
//! ```
//!
//! For `H = |p| − 1/F` this is exactly the Godunov update (3). On one face the minimum over `λ` is
//! a convex problem; its interior critical point (KKT) is where the one-sided differences
//! `P_k = σ_k (μ − u_k)/h` (k ∈ K) of the unknown value `μ` solve the *projected* Hamiltonian
//! `min_{p_⊥} G(P + p_⊥) = 1` (the components off the face are free: the characteristic then lies
//! in the face) and `λ_k ∝ σ_k ∂G/∂p_k ≥ 0` (the characteristic enters the node from the face:
//! causality). The value is then `μ`. Because every face's own faces are enumerated too, the minimum
//! over the *valid* interior points of all faces equals the minimum over all closed faces.
//!
//! For the two built-in Hamiltonians the projected Hamiltonian has the same form and the
//! equation for `μ` is a quadratic (see [`moving_medium`] and [`metric`]):
//!
//! * Randers `F|p| + v·p`: the minimum over `p_⊥` is `F_K |P| + v_K·P` with
//!   `F_K = sqrt(F² − |v_⊥|²)`;
//! * Riemannian `F sqrt(pᵀ M p)`: `F sqrt(Pᵀ S_K P)` with the Schur complement
//!   `S_K = M_KK − M_K⊥ M_⊥⊥⁻¹ M_⊥K`.
//!
//! # Monotonicity and causality
//!
//! Each face's value `min_λ Σ λ_k u_k + φ(·)` is non-decreasing in every neighbour value (a minimum
//! of non-decreasing functions), and so is the minimum over faces: the update is monotone, as the
//! eikonal Godunov update is, and the sweeps converge monotonically from above to the unique
//! fixed point (the proof of the paper's Corollary 1 carries over word for word). It is causal:
//! `φ > 0`, so the new value exceeds the smallest neighbour value it uses. It is consistent: for
//! a linear `u` with `H(∇u) = 0`, the face that contains the backward characteristic returns `u(x)`
//! exactly and every other face returns at least that (the update is exact on plane waves).
//!
//! # Cost
//!
//! The minimum is searched with the node's current value `old` as the bound (the sweep keeps the
//! smaller value anyway): faces are visited by increasing dimension, and a face is skipped, before
//! anything is solved, when its smallest vertex value plus `h s_lo / sqrt(m)` (a lower bound of
//! `φ` over the face, `s_lo` the node's least travel time per unit length) is not below the best
//! value so far. Skipping is exact: it never changes the result.

pub mod metric;
pub mod moving_medium;

/// An upwind local solver: the new value of a node from its neighbour values (Sect. 5.1's
/// interface, with a Godunov-type update in place of Lax–Friedrichs).
pub trait LocalSolver<const D: usize>: Sync {
    /// The smaller of `old` and the upwind update of node `node` from the neighbour values
    /// `minus[k] = u(x − h e_k)`, `plus[k] = u(x + h e_k)` (absent neighbours hold the numerical
    /// infinity).
    fn update(&self, node: usize, minus: [f64; D], plus: [f64; D], h: f64, old: f64) -> f64;
    /// An upper bound on the travel time per unit length (as [`crate::Hamiltonian::slowness_bound`]).
    fn slowness_bound(&self) -> Option<f64>;
}

/// One node's Hamiltonian as seen by [`upwind_min`]: the projection on a face and the solve there.
pub(crate) trait Faces<const D: usize> {
    /// Data of the projected Hamiltonian on a face (its axes in increasing order).
    type Projected: Copy;
    /// The least travel time per unit length over all directions (a positive lower bound).
    fn least_slowness(&self) -> f64;
    /// `τ_k`, per axis and side, bounding how much the travel time `φ(d)` can grow when the
    /// component `d_k` of a displacement towards the node from that side's neighbour is mirrored
    /// (pointed from the other neighbour): `φ(d') − φ(d) ≤ τ_k |d_k|` (0 where `φ` is even in
    /// `d_k`, infinite when unknown). See [`upwind_min`].
    fn mirror_slack(&self) -> [[f64; 2]; D];
    /// The projected Hamiltonian on the faces spanning the axes of `mask` (`None`: no solution
    /// on them, e.g. a supersonic node).
    fn project(&self, mask: u32) -> Option<Self::Projected>;
    /// The value `μ − base` at the node from the face with vertex values `base + w[..]` (`w ≥ 0`,
    /// one per axis of the face) on sides `sg[..]` (+1: the minus neighbour, −1: the plus
    /// neighbour), if the face admits a causal solution and it is below `below` (> 0).
    /// Implementations decide `t < below` before taking a square root (see
    /// [`larger_root_below`]): most visits of a node change nothing.
    fn solve<const M: usize>(
        &self,
        proj: &Self::Projected,
        w: &[f64; M],
        sg: &[f64; M],
        h: f64,
        below: f64,
    ) -> Option<f64>;
}

/// `1 / sqrt(m)` for `m = 0..=3`.
const INV_SQRT: [f64; 4] = [0.0, 1.0, std::f64::consts::FRAC_1_SQRT_2, 0.577_350_269_189_625_8];

/// The faces of dimension `M − 1` on the axes of `mask` (its `M` set bits): all `2^M` side
/// choices, each solved unless its smallest vertex value plus `bound` is not below `best`.
#[inline(always)]
fn faces_on<const D: usize, const M: usize, F: Faces<D>>(
    faces: &F,
    mask: u32,
    nb: &[[f64; 2]; D],
    dominated: &[usize; D],
    h: f64,
    bound: f64,
    best: &mut f64,
) {
    let mut axes = [0usize; M];
    let mut j = 0;
    for k in 0..D {
        if mask >> k & 1 == 1 {
            axes[j] = k;
            j += 1;
        }
    }
    let mut proj = None;
    for sides in 0u32..(1 << M) {
        let mut u = [0.0; M];
        let mut sg = [0.0; M];
        let mut skip = false;
        for j in 0..M {
            let side = (sides >> j & 1) as usize;
            u[j] = nb[axes[j]][side];
            sg[j] = 1.0 - 2.0 * side as f64;
            skip |= dominated[axes[j]] == side;
        }
        if skip {
            continue;
        }
        let base = u.iter().cloned().fold(f64::INFINITY, f64::min);
        if !(base + bound < *best) {
            continue;
        }
        let p = match proj {
            Some(p) => p,
            None => match faces.project(mask) {
                Some(p) => {
                    proj = Some(p);
                    p
                }
                None => return,
            },
        };
        let w: [f64; M] = core::array::from_fn(|j| u[j] - base);
        if let Some(t) = faces.solve::<M>(&p, &w, &sg, h, *best - base) {
            let mu = base + t;
            if mu < *best {
                *best = mu;
            }
        }
    }
}

/// The minimum of `old` and the face values (see the module documentation), faces visited by
/// increasing dimension. `old` may be the numerical infinity; it must not be NaN.
///
/// *Mirrored faces.* Let a face use, on axis `k`, the neighbour whose value is larger by
/// `δ_k = |u_{k+} − u_{k−}|`, and let its mirror use the other one. At the same weights `λ` the
/// mirror's vertex values are lower by `λ_k δ_k` and its displacement differs only in the sign of
/// `d_k`, `|d_k| = h λ_k`, so its value is at most the face's `− λ_k (δ_k − h τ_k)`. When
/// `δ_k ≥ h τ_k` no face on the larger side of axis `k` can be below its mirror, and all of them
/// are skipped: for an isotropic `H` (`τ = 0`) exactly the faces of the Godunov update (3) remain.
/// The result is unchanged.
#[inline]
pub(crate) fn upwind_min<const D: usize, F: Faces<D>>(
    faces: &F,
    minus: [f64; D],
    plus: [f64; D],
    h: f64,
    old: f64,
) -> f64 {
    debug_assert!((1..=3).contains(&D));
    let nb: [[f64; 2]; D] = core::array::from_fn(|k| [minus[k], plus[k]]);
    let tau = faces.mirror_slack();
    // the side (0: minus, 1: plus) whose faces are dominated by their mirrors, 2 for neither
    let dominated: [usize; D] = core::array::from_fn(|k| {
        let delta = plus[k] - minus[k];
        let up = (delta >= 0.0) as usize;
        if delta.abs() >= h * tau[k][up] {
            up
        } else {
            2
        }
    });
    let lo = h * faces.least_slowness();
    let mut best = old;
    for k in 0..D {
        faces_on::<D, 1, F>(faces, 1 << k, &nb, &dominated, h, lo, &mut best);
    }
    if D >= 2 {
        for k in 0..D {
            for l in k + 1..D {
                faces_on::<D, 2, F>(faces, 1 << k | 1 << l, &nb, &dominated, h, lo * INV_SQRT[2], &mut best);
            }
        }
    }
    if D == 3 {
        faces_on::<D, 3, F>(faces, 7, &nb, &dominated, h, lo * INV_SQRT[3], &mut best);
    }
    best
}

/// The larger root of `a t² − 2 b t + c = 0` (`a > 0`) if it is real and below `below`.
///
/// Only the larger root can be a face's value: for both built-in Hamiltonians the causality
/// weights sum to `a t − b` (see [`moving_medium`], [`metric`]), which is `−sqrt(b² − ac) ≤ 0` at
/// the smaller root, so its weights cannot all be non-negative unless the roots coincide. And
/// `t₁ < T` iff `T` lies right of both roots: `a T > b` and `a T² − 2 b T + c > 0`, decided
/// without the square root.
#[inline(always)]
pub(crate) fn larger_root_below(a: f64, b: f64, c: f64, below: f64) -> Option<f64> {
    if !(a * below > b && (a * below - 2.0 * b) * below + c > 0.0) {
        return None;
    }
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return None;
    }
    Some((b + disc.sqrt()) / a)
}

#[cfg(test)]
pub(crate) mod tests {
    /// Neighbour values of the linear function `u(x) = q·x` at the origin, spacing `h`.
    pub fn linear_neighbours<const D: usize>(q: [f64; D], h: f64) -> ([f64; D], [f64; D]) {
        (core::array::from_fn(|k| -q[k] * h), core::array::from_fn(|k| q[k] * h))
    }
}

/// The isotropic Hamiltonian through this interface is the Godunov update (3) itself.
impl<'a, const D: usize> LocalSolver<D> for crate::scheme::hamiltonians::Isotropic<'a> {
    #[inline]
    fn update(&self, node: usize, minus: [f64; D], plus: [f64; D], h: f64, old: f64) -> f64 {
        let mins: [f64; D] = core::array::from_fn(|k| crate::scheme::godunov::fmin(minus[k], plus[k]));
        let f = h * crate::scheme::hamiltonians::slowness_at(self.slowness, node);
        crate::scheme::godunov::godunov_update(mins, f).min(old)
    }

    fn slowness_bound(&self) -> Option<f64> {
        crate::Hamiltonian::<D>::slowness_bound(self)
    }
}

#[cfg(test)]
mod pruning_tests {
    use super::*;

    /// The same faces with every skip switched off (no mirror slack, no lower bound).
    struct NoPruning<'a, F>(&'a F);

    impl<'a, const D: usize, F: Faces<D>> Faces<D> for NoPruning<'a, F> {
        type Projected = F::Projected;
        fn least_slowness(&self) -> f64 {
            0.0
        }
        fn mirror_slack(&self) -> [[f64; 2]; D] {
            [[f64::INFINITY; 2]; D]
        }
        fn project(&self, mask: u32) -> Option<F::Projected> {
            self.0.project(mask)
        }
        fn solve<const M: usize>(
            &self,
            p: &F::Projected,
            w: &[f64; M],
            sg: &[f64; M],
            h: f64,
            below: f64,
        ) -> Option<f64> {
            self.0.solve::<M>(p, w, sg, h, below)
        }
    }

    #[test]
    fn skipping_faces_never_changes_the_result() {
        let mut x = 0.377_f64;
        let mut r = move || {
            x = (x * 997.0 + 0.1234).fract();
            x
        };
        for i in 0..20000 {
            let h = 0.05;
            let minus: [f64; 3] = core::array::from_fn(|_| 0.1 * r());
            let plus: [f64; 3] = core::array::from_fn(|_| 0.1 * r());
            let old = if i % 2 == 0 { 1e6 } else { 0.05 + 0.1 * r() };
            let v = [r() - 0.5, r() - 0.5, 0.6 * (r() - 0.5)];
            let randers = moving_medium::tests_faces(1.3, v);
            let a = upwind_min(&randers, minus, plus, h, old);
            let b = upwind_min(&NoPruning(&randers), minus, plus, h, old);
            assert_eq!(a, b, "moving medium {minus:?} {plus:?} {v:?}");
            let q = [
                [1.0 + r(), 0.3 * r(), -0.2 * r()],
                [0.0, 0.5 + r(), 0.4 * r()],
                [0.0, 0.0, 0.3 + r()],
            ];
            // M = QᵀQ (positive definite), tilted
            let m: [[f64; 3]; 3] =
                core::array::from_fn(|a| core::array::from_fn(|b| (0..3).map(|k| q[k][a] * q[k][b]).sum()));
            let riem = metric::tests_faces(0.8, m);
            let a = upwind_min(&riem, minus, plus, h, old);
            let b = upwind_min(&NoPruning(&riem), minus, plus, h, old);
            assert_eq!(a, b, "metric {minus:?} {plus:?} {m:?}");
        }
    }
}
