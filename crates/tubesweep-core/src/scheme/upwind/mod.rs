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
//! Most visits are settled by one face ([`natural_orthant`]): the simplex of the orthant the
//! characteristic comes from (by the central differences) is solved, and when its critical point
//! lies strictly inside it a duality bound proves, with `D` comparisons (and in concave places a
//! few evaluations of `G`), that no other face does better — one quadratic and one square root,
//! as the three-term branch of Eq. (3). When that simplex has no critical point inside, its faces
//! and then (in 3D) its vertex on the axis the characteristic is most nearly along are tried and
//! proved the same way ([`natural_faces`]: Eq. (3)'s two- and one-term branches). Otherwise the
//! minimum is searched with the node's current value `old` as the bound (the sweep keeps the
//! smaller value anyway): the other orthants' full faces first, then the faces not yet ruled out
//! by increasing dimension, and a face is skipped, before anything is solved, when its smallest
//! vertex value plus `h s_lo / sqrt(m)` (a lower bound of `φ` over the face, `s_lo` the node's
//! least travel time per unit length) is not below the best value so far, or when its mirror on
//! some axis is provably no worse. Skipping is exact: it never changes the result.

mod builtin;
pub mod metric;
pub mod moving_medium;

pub use builtin::Builtin;

// the plain compare-select minimum (no NaN handling: the sweeps hold no NaN), as in Eq. (3)
use crate::scheme::godunov::fmin;

/// An upwind local solver: the new value of a node from its neighbour values (Sect. 5.1's
/// interface, with a Godunov-type update in place of Lax–Friedrichs).
pub trait LocalSolver<const D: usize>: Sync {
    /// The smaller of `old` and the upwind update of node `node` from the neighbour values
    /// `minus[k] = u(x − h e_k)`, `plus[k] = u(x + h e_k)` (absent neighbours hold the numerical
    /// infinity).
    fn update(&self, node: usize, minus: [f64; D], plus: [f64; D], h: f64, old: f64) -> f64;
    /// An upper bound on the travel time per unit length (as [`crate::Hamiltonian::slowness_bound`]).
    fn slowness_bound(&self) -> Option<f64>;
    /// Which built-in solver this is, for the sweep's static dispatch ([`Builtin`]); `Other` (the
    /// default) for any other.
    fn builtin(&self) -> Builtin<'_, D> {
        Builtin::Other
    }
    /// The bytes of the solver's own per-node data (a metric, a flow, a slowness) that an update
    /// of one node reads: counted with the kernel's arrays when the sweeps decide whether to fetch
    /// rows ahead (`sweep/row_prefetch.rs`). 0 (the default) when it has none.
    fn bytes_per_node(&self) -> usize {
        0
    }
    /// Asks for the cache lines of the per-node data of the nodes `start..end` (a row the sweep
    /// will visit soon; `sweep/row_prefetch.rs`). The default fetches nothing.
    fn prefetch_nodes(&self, _start: usize, _end: usize) {}
}

/// One node's Hamiltonian as seen by [`upwind_min`]: the projection on a face and the solve there.
pub(crate) trait Faces<const D: usize> {
    /// Data of the projected Hamiltonian on a face (its axes in increasing order).
    type Projected: Copy;
    /// Whether [`upwind_min`] runs a copy of the fast path per orthant, chosen by a jump
    /// (measured: the moving medium gains, the metric, whose fast path is larger, does not).
    const JUMP: bool = false;
    /// The least travel time per unit length over all directions (a positive lower bound).
    fn least_slowness(&self) -> f64;
    /// A positive multiple of the characteristic velocity `∂G/∂p` at a positive multiple of `p`:
    /// its signs say from which side of each axis the characteristic comes, its smallest component
    /// which axis it is most nearly across.
    fn velocity(&self, p: [f64; D]) -> [f64; D];
    /// The orthant the characteristic comes from at a positive multiple of `p`: bit `k` set where
    /// the velocity [`Faces::velocity`] is negative (`∂G/∂p_k < 0`: from the plus side).
    #[inline(always)]
    fn upwind_orthant(&self, p: [f64; D]) -> usize {
        let vel = self.velocity(p);
        (0..D).map(|k| ((vel[k] < 0.0) as usize) << k).sum()
    }
    /// Whether `G(p) ≤ 1 − 1e-12`: `p` lies inside the unit ball `{G ≤ 1}` with a margin.
    fn inside(&self, p: [f64; D]) -> bool;
    /// Whether [`Faces::inside`] holds at every `p_S`, `S` a non-empty subset of the axes in the
    /// bit mask `def`, `p_S` taking `moved[k]` on the axes of `S` and `p[k]` on the others (the
    /// corners of a box, for the deficit proof of [`natural_orthant`]). Implementations may share
    /// work between the corners; the answer is that of [`Faces::inside`] at each.
    #[inline(always)]
    fn inside_corners(&self, p: [f64; D], moved: [f64; D], def: usize) -> bool {
        every_corner_inside(self, p, moved, def)
    }
    /// The full gradient `(P, q*)` of a solution on the face of the axes not in the bit mask
    /// `off` (one or two axes, not all): `P` (given in place, `p`'s components on `off` ignored)
    /// and the off-face components `q*` that minimise `G(P + q)` (the projection of
    /// [`Faces::project`]), so that `G = 1` there.
    fn complete(&self, p: [f64; D], off: u32) -> [f64; D];
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
    ///
    /// With `STRICT`, `below` is ignored and the value is returned only when the face's
    /// critical point lies *strictly* inside it: every causality weight at least [`STRICT_WEIGHT`]
    /// times their sum (see [`upwind_min`]). The value is then the same bits the plain call
    /// returns.
    fn solve<const M: usize, const STRICT: bool>(
        &self,
        proj: &Self::Projected,
        w: &[f64; M],
        sg: &[f64; M],
        h: f64,
        below: f64,
    ) -> Option<f64>;
    /// What the strict solve of a full face ([`Faces::solve_strict`]) leaves for
    /// [`Faces::deficit_proved`].
    type Strict: Copy;
    /// The strict solve of the full face of an orthant (`solve::<D, true>`, the same bits) and
    /// what it computed on the way that the deficit proof of [`natural_orthant`] can reuse.
    fn solve_strict(&self, proj: &Self::Projected, w: &[f64; D], sg: &[f64; D], h: f64) -> Option<(f64, Self::Strict)>;
    /// A sufficient condition for the deficit proof of [`natural_orthant`], from what the strict
    /// solve left (`strict`) and the deficits (`deficit[k]` > 0 on the axes of the bit mask `def`,
    /// 0 elsewhere): `true` when `def` is empty, or only when [`Faces::inside_corners`] holds at
    /// every corner (but for rounding within its margin); `false` sends the proof to
    /// [`Faces::inside_corners`]. The default decides only the empty `def`.
    #[inline(always)]
    fn deficit_proved(&self, _strict: &Self::Strict, _deficit: &[f64; D], def: usize) -> bool {
        def == 0
    }
}

/// The share of their sum each causality weight of a full face must reach for the face to prove
/// its own faces cannot do better ([`upwind_min`]). Below it (the characteristic within a
/// thousandth of a face of the simplex) the faces are all enumerated.
pub(crate) const STRICT_WEIGHT: f64 = 1e-3;

/// For the face on the axes `K` (a bit mask) with sides `s` (bit `k` set: the plus neighbour on
/// axis `k`, only the bits of `K` set): the orthants `σ` (bit masks of `D ≤ 3` sides) that contain
/// it, i.e. `σ & K == s`, as a bit mask over `σ`. Indexed `[K][s]`.
const CONTAINING_ORTHANTS: [[u8; 8]; 8] = {
    let mut t = [[0u8; 8]; 8];
    let mut k = 0;
    while k < 8 {
        let mut s = 0;
        while s < 8 {
            let mut o = 0;
            while o < 8 {
                if o & k == s {
                    t[k][s] |= 1 << o;
                }
                o += 1;
            }
            s += 1;
        }
        k += 1;
    }
    t
};

/// For a bit mask `def` of axes (`D ≤ 3`): its non-empty subsets `S`, as a bit mask over `S` (bit
/// `S` set when `S ≠ ∅` and `S ⊆ def`). The deficit proof's corners ([`Faces::inside_corners`]) are
/// evaluated for every `S` without branches and this picks those that count.
pub(crate) const SUBSETS_OF: [u8; 8] = {
    let mut t = [0u8; 8];
    let mut def = 0;
    while def < 8 {
        let mut sub = 1;
        while sub < 8 {
            if sub & !def == 0 {
                t[def] |= 1 << sub;
            }
            sub += 1;
        }
        def += 1;
    }
    t
};

/// The corner `p_S` of [`Faces::inside_corners`]: `moved[k]` on the axes of the bit mask `sub`,
/// `p[k]` on the others.
#[inline(always)]
pub(crate) fn corner<const D: usize>(p: [f64; D], moved: [f64; D], sub: usize) -> [f64; D] {
    core::array::from_fn(|k| if sub >> k & 1 == 1 { moved[k] } else { p[k] })
}

/// [`Faces::inside`] at every corner of `def`, one by one: the default of
/// [`Faces::inside_corners`] and the reference its shared evaluations are checked against.
pub(crate) fn every_corner_inside<const D: usize, F: Faces<D> + ?Sized>(
    faces: &F,
    p: [f64; D],
    moved: [f64; D],
    def: usize,
) -> bool {
    let mut sub = def;
    while sub != 0 {
        if !faces.inside(corner(p, moved, sub)) {
            return false;
        }
        sub = (sub - 1) & def;
    }
    true
}

/// The bytes per node of a solver's array given per node, 0 for one value for all nodes (a
/// slice of length 1, as [`crate::scheme::hamiltonians::slowness_at`] reads it).
pub(crate) fn per_node_bytes<T>(data: &[T]) -> usize {
    if data.len() > 1 {
        std::mem::size_of::<T>()
    } else {
        0
    }
}

/// [`crate::prefetch::prefetch_range`] of a solver's array given per node (nothing for one value
/// for all nodes).
pub(crate) fn prefetch_per_node<T>(data: &[T], start: usize, end: usize) {
    if data.len() > 1 {
        crate::prefetch::prefetch_range(data, start, end);
    }
}

/// The sign of a side: `+1` for the minus neighbour (`side = 0`), `−1` for the plus neighbour.
#[inline(always)]
fn side_sign(side: usize) -> f64 {
    // a load, not a branch (the side is data: a mispredicted branch costs more than the update)
    [1.0, -1.0][side & 1]
}

/// `1 / sqrt(m)` for `m = 0..=3`.
const INV_SQRT: [f64; 4] = [0.0, 1.0, std::f64::consts::FRAC_1_SQRT_2, 0.577_350_269_189_625_8];

/// The faces of dimension `M − 1` on the axes of `mask` (its `M` set bits): all `2^M` side
/// choices, each solved unless a side is dominated, the face lies in an orthant whose full face
/// proved it cannot do better (`proved`, a bit mask over orthants), or its smallest vertex value
/// plus `bound` is not below `best`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn faces_on<const D: usize, const M: usize, F: Faces<D>>(
    faces: &F,
    mask: u32,
    nb: &[[f64; 2]; D],
    dominated: &[usize; D],
    proved: u32,
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
    let containing = &CONTAINING_ORTHANTS[mask as usize];
    let mut proj = None;
    for sides in 0u32..(1 << M) {
        let mut u = [0.0; M];
        let mut sg = [0.0; M];
        let mut skip = false;
        let mut s = 0usize;
        for j in 0..M {
            let side = (sides >> j & 1) as usize;
            u[j] = nb[axes[j]][side];
            sg[j] = side_sign(side);
            skip |= dominated[axes[j]] == side;
            s |= side << axes[j];
        }
        if skip || containing[s] as u32 & proved != 0 {
            continue;
        }
        let base = u.iter().cloned().fold(f64::INFINITY, fmin);
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
        if let Some(t) = faces.solve::<M, false>(&p, &w, &sg, h, *best - base) {
            let mu = base + t;
            if mu < *best {
                *best = mu;
            }
        }
    }
}

/// The fast path of [`upwind_min`]: the full face of orthant `o` (bit `k`: the plus neighbour on
/// axis `k`), if its critical point lies strictly inside it, as `(μ, done)`; `done` when every
/// other face is proved not below `μ`.
///
/// *The proof.* `μ` is the minimum over the closed simplex of orthant `o`. For another orthant
/// `σ`, weak duality gives, for every `p` with `G(p) ≤ 1`, `V_σ ≥ min_k (u_{k,σ_k} + h s_k p_k)`
/// (`s_k = ±1`, the side's sign): `V_σ = min_λ Σ λ_k u_{k,σ_k} + φ(d(λ))` and `φ(d) ≥ p·d`. The
/// gradient `P` of the face (`P_k = s_k (μ − u_k)/h`, `G(P) = 1`) gives exactly `μ` on the axes
/// `σ` shares with `o`, and `c_k = u_{k+} + u_{k−} − μ` on an axis it flips. Where `c_k ≥ μ + η`
/// (the discrete `u` convex along the axis, `η` a rounding margin) nothing more is needed; on the
/// other axes `p` is moved inwards from `P` by the deficit, and kept if `G(p) ≤ 1` still, for
/// every subset of them. Then every orthant's simplex, and so every face, is at least `μ`; it is
/// above `μ` by a margin, `μ`'s simplex holding the only minimiser (strictly inside it).
#[inline(always)]
fn natural_orthant<const D: usize, F: Faces<D>>(
    faces: &F,
    pf: &F::Projected,
    nb: &[[f64; 2]; D],
    o: usize,
    h: f64,
) -> Option<(f64, bool)> {
    let u: [f64; D] = core::array::from_fn(|k| nb[k][o >> k & 1]);
    let base = u.iter().cloned().fold(f64::INFINITY, fmin);
    let w: [f64; D] = core::array::from_fn(|k| u[k] - base);
    let sg: [f64; D] = core::array::from_fn(|k| side_sign(o >> k & 1));
    let (t, strict) = faces.solve_strict(pf, &w, &sg, h)?;
    let mu = base + t;
    // the rounding margin: far above the rounding of the values, far below their differences
    let eta = 1e-11 * mu.abs();
    let mut deficit = [0.0; D];
    let mut def = 0usize;
    for k in 0..D {
        let other = nb[k][1 - (o >> k & 1)];
        let d = 2.0 * mu + eta - other - u[k];
        // without a branch: which axes fall short is data
        let short = d > 0.0;
        deficit[k] = if short { d } else { 0.0 };
        def |= (short as usize) << k;
    }
    // one branch, taken by nearly every visit: whether an axis falls short is data (a third
    // of the visits at N = 161), the quick proof settles most of those
    if faces.deficit_proved(&strict, &deficit, def) {
        return Some((mu, true));
    }
    let inv_h = 1.0 / h;
    let gp: [f64; D] = core::array::from_fn(|k| sg[k] * (mu - u[k]) * inv_h);
    Some((mu, moved_inside(faces, gp, &deficit, def, &sg, inv_h)))
}

/// Whether `p − Σ_{k∈S} s_k deficit_k e_k / h` lies inside the unit ball for every non-empty subset
/// `S` of the axes in `def` (the deficit axes of [`natural_orthant`]).
#[inline(always)]
fn moved_inside<const D: usize, F: Faces<D>>(
    faces: &F,
    gp: [f64; D],
    deficit: &[f64; D],
    def: usize,
    sg: &[f64; D],
    inv_h: f64,
) -> bool {
    // each axis's moved component once (the same bits in every subset that moves it)
    let moved: [f64; D] = core::array::from_fn(|k| gp[k] - sg[k] * deficit[k] * inv_h);
    faces.inside_corners(gp, moved, def)
}

/// The fast path's second chance, when the natural orthant's simplex has no critical point
/// inside it (the characteristic runs along one of its faces, as along a symmetry plane or
/// where one axis is nearly across the characteristic): its faces of dimension `D − 2`, the
/// simplices of `D − 1` of its neighbours, each solved until one is proved ([`prove_face`]);
/// then, in 3D, its vertex on the axis the characteristic is most nearly along (where two axes
/// are nearly across it, as on the great circle half-way round a sphere from a point source).
/// `Some(μ)` when proved.
#[inline(always)]
fn natural_faces<const D: usize, F: Faces<D>>(
    faces: &F,
    nb: &[[f64; 2]; D],
    o: usize,
    h: f64,
    best: &mut f64,
) -> Option<f64> {
    if D < 2 {
        return None;
    }
    let full = (1u32 << D) - 1;
    // the face without the axis the characteristic is most nearly across (the smallest velocity
    // component at the central differences) first: on a symmetry plane, the one that proves
    let vel = faces.velocity(core::array::from_fn(|k| nb[k][1] - nb[k][0]));
    let (mut first, mut along) = (0, 0);
    for k in 1..D {
        if vel[k].abs() < vel[first].abs() {
            first = k;
        }
        if vel[k].abs() > vel[along].abs() {
            along = k;
        }
    }
    for i in 0..D {
        let off = match i {
            0 => first,
            _ if i <= first => i - 1,
            _ => i,
        };
        // the face's axes in increasing order, M = D − 1 of them
        let proved = match D {
            2 => prove_face::<D, 1, F>(faces, nb, o, full & !(1 << off), h, best)?,
            _ => prove_face::<D, 2, F>(faces, nb, o, full & !(1 << off), h, best)?,
        };
        if proved.is_some() {
            return proved;
        }
    }
    if D == 3 {
        return prove_face::<D, 1, F>(faces, nb, o, 1 << along, h, best)?;
    }
    None
}

/// The face of orthant `o` on the axes of `mask` (`M` of them), proved as in
/// [`natural_orthant`] with the full gradient `(P, q*)` of the face ([`Faces::complete`],
/// `G = 1`): the two neighbours on each axis off the face must give `c ≥ μ + η`, and the other
/// sides of its own axes too, with `p` moved inwards where they fall short, as there. Every face
/// is then at least `μ`, and the faces holding the minimiser (the face itself, and the simplices
/// around it, whose critical points have a negative weight on an axis off it) do not tie with
/// it. `None` when the face has no projection (no face has a solution), `Some(Some(μ))` when
/// proved (`best` lowered to `μ` whenever the face has a value).
#[inline(always)]
fn prove_face<const D: usize, const M: usize, F: Faces<D>>(
    faces: &F,
    nb: &[[f64; 2]; D],
    o: usize,
    mask: u32,
    h: f64,
    best: &mut f64,
) -> Option<Option<f64>> {
    let pk = faces.project(mask)?;
    let Some(mu) = face_value::<D, M, F>(faces, &pk, nb, o, mask, h) else {
        return Some(None);
    };
    if mu < *best {
        *best = mu;
    }
    let eta = 1e-11 * mu.abs();
    let inv_h = 1.0 / h;
    let p: [f64; D] = core::array::from_fn(|k| {
        let side = o >> k & 1;
        (side_sign(side)) * (mu - nb[k][side]) * inv_h
    });
    let full = (1u32 << D) - 1;
    let p = faces.complete(p, full & !mask);
    for k in 0..D {
        if mask >> k & 1 == 0 && !(nb[k][0] + h * p[k] >= mu + eta && nb[k][1] - h * p[k] >= mu + eta) {
            return Some(None);
        }
    }
    // the other sides of the face's own axes, as in `natural_orthant`
    let mut deficit = [0.0; D];
    let mut def = 0usize;
    for k in 0..D {
        let side = o >> k & 1;
        let d = 2.0 * mu + eta - nb[k][1 - side] - nb[k][side];
        if mask >> k & 1 == 1 && d > 0.0 {
            deficit[k] = d;
            def |= 1 << k;
        }
    }
    let sg: [f64; D] = core::array::from_fn(|k| side_sign(o >> k & 1));
    Some((def == 0 || moved_inside(faces, p, &deficit, def, &sg, inv_h)).then_some(mu))
}

/// The value on the face of orthant `o` spanning the axes of `mask` (`M` of them), if its
/// critical point lies strictly inside it.
#[inline(always)]
fn face_value<const D: usize, const M: usize, F: Faces<D>>(
    faces: &F,
    proj: &F::Projected,
    nb: &[[f64; 2]; D],
    o: usize,
    mask: u32,
    h: f64,
) -> Option<f64> {
    let mut u = [0.0; M];
    let mut sg = [0.0; M];
    let mut j = 0;
    for k in 0..D {
        if mask >> k & 1 == 1 {
            let side = o >> k & 1;
            u[j] = nb[k][side];
            sg[j] = side_sign(side);
            j += 1;
        }
    }
    let base = u.iter().cloned().fold(f64::INFINITY, fmin);
    let w: [f64; M] = core::array::from_fn(|j| u[j] - base);
    let t = faces.solve::<M, true>(proj, &w, &sg, h, f64::INFINITY)?;
    Some(base + t)
}

/// The minimum of `old` and the face values (see the module documentation). `old` may be the
/// numerical infinity; it must not be NaN.
///
/// *Mirrored faces.* Let a face use, on axis `k`, the neighbour on side `S`, and let its mirror
/// use the other one, whose value is lower by `δ_k = u_{k,S} − u_{k,other}` (possibly negative).
/// At the same weights `λ` the mirror's vertex values are lower by `λ_k δ_k` and its
/// displacement differs only in the sign of `d_k`, `|d_k| = h λ_k`, so its value is at most the
/// face's `− λ_k (δ_k − h τ_{k,S})` with `τ` of [`Faces::mirror_slack`] (which may be negative:
/// mirroring may shorten every path). When `δ_k ≥ h τ_{k,S}` no face on side `S` of axis `k` can
/// be below its mirror, and all of them are skipped: for an isotropic `H` (`τ = 0`) exactly the
/// faces of the Godunov update (3) remain.
///
/// *Orthants first.* Each orthant left (a side per axis, none dominated) has a full face, the
/// simplex of its `D` neighbours. It is solved first, without a bound: when its critical point
/// lies strictly inside (every causality weight at least [`STRICT_WEIGHT`] of their sum) it is
/// the minimum over the closed simplex, so none of its own faces can do better and all of them
/// are skipped. Then the faces not yet ruled out are visited by increasing dimension, and a face
/// is skipped, before anything is solved, when its smallest vertex value plus `h s_lo / sqrt(m)`
/// (a lower bound of `φ` over the face, `s_lo` the node's least travel time per unit length) is
/// not below the best value so far. For an isotropic `H` and a characteristic inside an octant
/// this is one solve, the three-term branch of Eq. (3).
///
/// The result is unchanged by the skipping (`skipping_faces_never_changes_the_result`): a skipped
/// face's value is at least one that is computed. (A face of a proving simplex is above the
/// simplex's value by a margin that grows with the square of the smallest weight, so
/// [`STRICT_WEIGHT`] keeps rounding from deciding.)
#[inline(always)]
pub(crate) fn upwind_min<const D: usize, F: Faces<D>>(
    faces: &F,
    minus: [f64; D],
    plus: [f64; D],
    h: f64,
    old: f64,
) -> f64 {
    debug_assert!((1..=3).contains(&D));
    // every face's value exceeds its smallest vertex value (φ > 0): when no neighbour is below
    // `old` (an unreached node among unreached ones), nothing can be
    let lowest = (0..D).fold(f64::INFINITY, |m, k| fmin(fmin(m, minus[k]), plus[k]));
    if lowest >= old {
        return old;
    }
    let nb: [[f64; 2]; D] = core::array::from_fn(|k| [minus[k], plus[k]]);
    let full = (1u32 << D) - 1;
    let Some(pf) = faces.project(full) else {
        // no face has a solution (a supersonic node)
        return old;
    };
    // the orthant the characteristic comes from, by the central differences (times 2h: only
    // the direction of the gradient matters)
    let o0 = faces.upwind_orthant(core::array::from_fn(|k| plus[k] - minus[k]));
    // the fast path, inlined where the solver is (the sweep's row loop); the rest out of line
    // with `F::JUMP`, one copy per orthant, chosen by a jump: the orthant is then a constant in
    // each (its sides and signs folded in), and the jump predicted (neighbouring nodes share the
    // orthant), so that the update does not wait for the orthant's computation
    let first = if F::JUMP {
        match o0 {
            0 => natural_orthant(faces, &pf, &nb, 0, h),
            1 => natural_orthant(faces, &pf, &nb, 1, h),
            2 => natural_orthant(faces, &pf, &nb, 2, h),
            3 => natural_orthant(faces, &pf, &nb, 3, h),
            4 => natural_orthant(faces, &pf, &nb, 4, h),
            5 => natural_orthant(faces, &pf, &nb, 5, h),
            6 => natural_orthant(faces, &pf, &nb, 6, h),
            _ => natural_orthant(faces, &pf, &nb, 7, h),
        }
    } else {
        natural_orthant(faces, &pf, &nb, o0, h)
    };
    if let Some((mu, true)) = first {
        return fmin(mu, old);
    }
    upwind_min_rest(faces, &pf, &nb, o0, first, h, old)
}

/// [`upwind_min`] after the natural orthant `o0`'s simplex (`first`, [`natural_orthant`]) did not
/// settle the node alone: its faces, then the other faces not ruled out. Out of line: a few
/// percent of the visits come here.
#[inline(never)]
fn upwind_min_rest<const D: usize, F: Faces<D>>(
    faces: &F,
    pf: &F::Projected,
    nb: &[[f64; 2]; D],
    o0: usize,
    first: Option<(f64, bool)>,
    h: f64,
    old: f64,
) -> f64 {
    let nb = *nb;
    let pf = *pf;
    let mut best = old;
    let mut proved = 0u32;
    match first {
        Some((mu, _)) => {
            proved |= 1 << o0;
            if mu < best {
                best = mu;
            }
        }
        None => {
            // `best` holds the proved face's value (and any lower one tried before it, which the
            // proof says cannot be, short of rounding)
            if natural_faces(faces, &nb, o0, h, &mut best).is_some() {
                return best;
            }
        }
    }
    let tau = faces.mirror_slack();
    // the side (0: minus, 1: plus) whose faces are dominated by their mirrors, 2 for neither
    let dominated: [usize; D] = core::array::from_fn(|k| {
        let delta = nb[k][1] - nb[k][0];
        if delta >= h * tau[k][1] {
            1
        } else if -delta >= h * tau[k][0] {
            0
        } else {
            2
        }
    });
    let lo = h * faces.least_slowness();
    let proj = Some(pf);
    // the other orthants' full faces
    for o in 0..(1usize << D) {
        if o == o0 || (0..D).any(|k| dominated[k] == o >> k & 1) {
            continue;
        }
        let u: [f64; D] = core::array::from_fn(|k| nb[k][o >> k & 1]);
        let base = u.iter().cloned().fold(f64::INFINITY, fmin);
        if !(base + lo * INV_SQRT[D] < best) {
            // neither this simplex nor any of its faces can do better (their bounds are larger)
            continue;
        }
        let Some(p) = proj else { break };
        let w: [f64; D] = core::array::from_fn(|k| u[k] - base);
        let sg: [f64; D] = core::array::from_fn(|k| side_sign(o >> k & 1));
        if let Some(t) = faces.solve::<D, true>(&p, &w, &sg, h, f64::INFINITY) {
            proved |= 1 << o;
            let mu = base + t;
            if mu < best {
                best = mu;
            }
        }
    }
    for k in 0..D {
        faces_on::<D, 1, F>(faces, 1 << k, &nb, &dominated, proved, h, lo, &mut best);
    }
    if D >= 2 {
        for k in 0..D {
            for l in k + 1..D {
                faces_on::<D, 2, F>(
                    faces,
                    1 << k | 1 << l,
                    &nb,
                    &dominated,
                    proved,
                    h,
                    lo * INV_SQRT[2],
                    &mut best,
                );
            }
        }
    }
    if D == 3 {
        faces_on::<D, 3, F>(faces, 7, &nb, &dominated, proved, h, lo * INV_SQRT[3], &mut best);
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
///
/// The root is `(b + sqrt(b² − ac)) · (1/a)`: the division waits only for `a`, which the
/// solvers have before `b` and `c` (it does not depend on the vertex values), so it runs beside
/// the square root instead of after it (the update's value is on the sweep's critical path: the
/// next node reads it).
#[inline(always)]
pub(crate) fn larger_root_below(a: f64, b: f64, c: f64, below: f64) -> Option<f64> {
    let inv_a = 1.0 / a;
    if !(a * below > b && (a * below - 2.0 * b) * below + c > 0.0) {
        return None;
    }
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return None;
    }
    Some((b + disc.sqrt()) * inv_a)
}

/// [`larger_root_below`] without the bound (`STRICT`) or with it; the same bits either way.
#[inline(always)]
pub(crate) fn larger_root<const STRICT: bool>(a: f64, b: f64, c: f64, below: f64) -> Option<f64> {
    if STRICT {
        let inv_a = 1.0 / a;
        let disc = b * b - a * c;
        if !(disc >= 0.0) {
            return None;
        }
        Some((b + disc.sqrt()) * inv_a)
    } else {
        larger_root_below(a, b, c, below)
    }
}

/// The least each causality weight must reach: 0, or with `STRICT` [`STRICT_WEIGHT`] times their
/// sum `total`.
#[inline(always)]
pub(crate) fn weight_floor<const STRICT: bool>(total: f64) -> f64 {
    if STRICT {
        STRICT_WEIGHT * total
    } else {
        0.0
    }
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
mod pruning_tests;
