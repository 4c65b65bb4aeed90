//! The metric `M` of `sqrt(∇uᵀ M ∇u) = 1/F` as the upwind local solver reads it
//! ([`crate::scheme::upwind::metric`]): its symmetric part `(M + Mᵀ)/2` (the Hamiltonian
//! `pᵀ M p` sees nothing else), packed as its upper triangle row by row, `D(D+1)/2` numbers per
//! matrix (48 bytes in 3D, 24 in 2D, 8 in 1D, against `8 D²` for the full matrix), and one matrix
//! for all nodes when `M` is constant (as [`super::slowness_at`] allows one slowness).
//!
//! The local solve unpacks it into the full symmetric matrix at each node. For an exactly
//! symmetric `M` the entries are `M`'s own bits (`(a + a)/2 = a`), so the solution is the one the
//! full matrix gives; for a slightly asymmetric one it is the solution of `(M + Mᵀ)/2`, exactly: the
//! upwind solver never sees an asymmetric `M`.

use super::metric::determinant;
use super::slowness_at;

/// `sqrt(pᵀ S(x) p) − s(x)` with `S = (M + Mᵀ)/2` packed: the upwind solver's metric (its
/// [`crate::LocalSolver`] impl is in [`crate::scheme::upwind::metric`]). [`super::Metric`] is the same
/// equation for the Lax–Friedrichs update of Sect. 5.1, reading `M` as given.
pub struct SymmetricMetric<'a, const D: usize> {
    /// Slowness `1/F` per band node (or a single value for all nodes).
    pub slowness: &'a [f64],
    /// `S_ij`, `i ≤ j`, row by row: [`Self::PACKED`] numbers per matrix, one matrix per band node
    /// or one for all.
    packed: Vec<f64>,
    /// `PACKED` per node, or 0 with one matrix for all nodes (the node's first entry is `node · stride`).
    stride: usize,
    /// Whether every matrix's eigenvalues span at most [`QUICK_PROOF_CONDITION`] (by the bound
    /// `λ_max / λ_min ≤ (tr S)^D / det S`): the upwind solver's quick deficit proof is used only then.
    well_conditioned: bool,
}

/// The largest eigenvalue ratio of `M` for which the upwind metric's quick deficit proof
/// ([`crate::scheme::upwind::metric`]) keeps its rounding within the proofs' margin (1e-12 of `s²`):
/// measured overshoots of the bound at its own edge were 6e-16 at a ratio of 1, 5.5e-13 at 1e4,
/// 3.6e-12 at 1e6. Above it (by the bound `tr^D / det`, which may exceed the ratio up to `D^D`
/// times) the corners are tested one by one, whose rounding stays within the margin further (at
/// a ratio of 1e8 it overshoots 40 times less).
pub const QUICK_PROOF_CONDITION: f64 = 1e4;

impl<'a, const D: usize> SymmetricMetric<'a, D> {
    /// The numbers stored per matrix, `D(D+1)/2`.
    pub const PACKED: usize = D * (D + 1) / 2;

    /// Packs `(M + Mᵀ)/2` of `metric`: one matrix per band node, or a single one (length 1) for all
    /// nodes.
    pub fn new(slowness: &'a [f64], metric: &[[[f64; D]; D]]) -> Self {
        let mut packed = Vec::with_capacity(metric.len() * Self::PACKED);
        for m in metric {
            for i in 0..D {
                packed.push(m[i][i]);
                for j in i + 1..D {
                    packed.push(0.5 * (m[i][j] + m[j][i]));
                }
            }
        }
        let well_conditioned = packed
            .chunks_exact(Self::PACKED)
            .all(|p| quick_proof_applies(unpack::<D>(p)));
        Self {
            slowness,
            packed,
            stride: if metric.len() == 1 { 0 } else { Self::PACKED },
            well_conditioned,
        }
    }

    /// The number of matrices stored: the band's nodes, or 1 for one matrix for all nodes.
    pub fn matrices(&self) -> usize {
        self.packed.len() / Self::PACKED
    }

    /// The bytes of the packed matrices (`8 D(D+1)/2` per node, or per solve for a constant `M`).
    pub fn bytes(&self) -> usize {
        self.packed.len() * core::mem::size_of::<f64>()
    }

    /// The bytes an update of one node reads of the packed matrices and the slowness (0 for
    /// one value for all nodes), for the sweeps' row prefetch (`sweep/row_prefetch.rs`).
    pub(crate) fn bytes_per_node(&self) -> usize {
        self.stride * core::mem::size_of::<f64>() + crate::scheme::upwind::per_node_bytes(self.slowness)
    }

    /// Asks for the cache lines of the matrices and slowness of the nodes `start..end`.
    pub(crate) fn prefetch_nodes(&self, start: usize, end: usize) {
        if self.stride > 0 {
            crate::prefetch::prefetch_range(&self.packed, start * self.stride, end * self.stride);
        }
        crate::scheme::upwind::prefetch_per_node(self.slowness, start, end);
    }

    /// `(M + Mᵀ)/2` at a band node, unpacked.
    #[inline(always)]
    pub fn at(&self, node: usize) -> [[f64; D]; D] {
        let start = node * self.stride;
        unpack::<D>(&self.packed[start..start + Self::PACKED])
    }

    /// Whether every matrix's eigenvalue ratio is provably at most [`QUICK_PROOF_CONDITION`].
    #[inline(always)]
    pub fn well_conditioned(&self) -> bool {
        self.well_conditioned
    }

    /// The slowness at a band node.
    #[inline(always)]
    pub fn slowness_at(&self, node: usize) -> f64 {
        slowness_at(self.slowness, node)
    }

    /// `max s / sqrt(λ_min(S))` over the nodes, with `λ_min ≥ det S / (tr S)^(D−1)` (as
    /// [`crate::Hamiltonian::slowness_bound`] of [`super::Metric`]); `None` if some `S` is not positive
    /// definite.
    pub fn slowness_bound(&self) -> Option<f64> {
        let nodes = if self.stride == 0 {
            self.slowness.len()
        } else {
            self.matrices()
        };
        let mut bound = 0.0f64;
        let mut lam_min = 0.0;
        for n in 0..nodes {
            if n == 0 || self.stride != 0 {
                let m = self.at(n);
                let tr: f64 = (0..D).map(|k| m[k][k]).sum();
                let det = determinant(m);
                if !(det > 0.0 && tr > 0.0) {
                    return None;
                }
                lam_min = det / tr.powi(D as i32 - 1);
            }
            bound = bound.max(slowness_at(self.slowness, n) / f64::sqrt(lam_min));
        }
        bound.is_finite().then_some(bound)
    }
}

/// Whether the symmetric positive definite `m`'s eigenvalue ratio is provably at most
/// [`QUICK_PROOF_CONDITION`]: `λ_max ≤ tr`, `λ_min ≥ det / tr^(D−1)`, so the ratio is at most
/// `tr^D / det`.
pub(crate) fn quick_proof_applies<const D: usize>(m: [[f64; D]; D]) -> bool {
    let tr: f64 = (0..D).map(|k| m[k][k]).sum();
    tr.powi(D as i32) <= QUICK_PROOF_CONDITION * determinant(m)
}

/// The full symmetric matrix of one packed upper triangle.
#[inline(always)]
fn unpack<const D: usize>(p: &[f64]) -> [[f64; D]; D] {
    let mut m = [[0.0; D]; D];
    let mut k = 0;
    for i in 0..D {
        m[i][i] = p[k];
        k += 1;
        for j in i + 1..D {
            m[i][j] = p[k];
            m[j][i] = p[k];
            k += 1;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::hamiltonians::Metric;
    use crate::Hamiltonian;

    const M3: [[f64; 3]; 3] = [[2.0, 0.6, -0.3], [0.6, 0.9, 0.2], [-0.3, 0.2, 0.5]];

    #[test]
    fn a_symmetric_matrix_unpacks_to_its_own_bits() {
        let m = [M3, [[1.0, 0.1, 0.2], [0.1, 3.0, -0.4], [0.2, -0.4, 0.7]]];
        let s = [1.0];
        let sym = SymmetricMetric::new(&s, &m);
        assert_eq!((sym.matrices(), sym.bytes()), (2, 96));
        for (n, want) in m.iter().enumerate() {
            assert_eq!(sym.at(n), *want);
        }
        let one = SymmetricMetric::<2>::new(&s, &[[[2.0, 0.3], [0.3, 1.0]]]);
        assert_eq!((one.matrices(), one.bytes()), (1, 24));
        assert_eq!(one.at(0), one.at(12345));
        assert_eq!(SymmetricMetric::<1>::new(&s, &[[[4.0]]]).bytes(), 8);
    }

    #[test]
    fn the_quick_proof_applies_only_to_well_conditioned_metrics() {
        let s = [1.0];
        // M3: bound tr³/det = 81; diag(1, 1, 1e-3): ratio 1e3, bound 8.0e3; diag(1, 1, 1e-4): 1e4, 8.0e4
        assert!(SymmetricMetric::new(&s, &[M3]).well_conditioned());
        assert!(
            SymmetricMetric::<3>::new(&s, &[[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1e-3]]]).well_conditioned()
        );
        let ill = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1e-4]];
        assert!(!SymmetricMetric::<3>::new(&s, &[ill]).well_conditioned());
        // one ill-conditioned node among well-conditioned ones switches it off for the solve
        assert!(!SymmetricMetric::<3>::new(&s, &[M3, ill, M3]).well_conditioned());
        assert!(SymmetricMetric::<2>::new(&s, &[[[1.0, 0.0], [0.0, 1e-3]]]).well_conditioned());
        assert!(!SymmetricMetric::<2>::new(&s, &[[[1.0, 0.0], [0.0, 1e-4]]]).well_conditioned());
    }

    #[test]
    fn an_asymmetric_matrix_is_stored_as_its_symmetric_part() {
        let a = [
            [2.0, 0.6 + 3e-11, -0.3],
            [0.6, 0.9, 0.2 - 1e-11],
            [-0.3 + 2e-11, 0.2, 0.5],
        ];
        let s = [1.0];
        let got = SymmetricMetric::new(&s, &[a]).at(0);
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(got[i][j], (a[i][j] + a[j][i]) / 2.0);
            }
        }
    }

    #[test]
    fn the_slowness_bound_is_the_full_metric_s() {
        let m = vec![M3; 5];
        let s = [0.5, 0.7, 0.6, 0.9, 0.2];
        let full = Metric {
            slowness: &s,
            metric: &m,
            sigma: None,
        };
        let want = full.slowness_bound().unwrap();
        assert_eq!(SymmetricMetric::new(&s, &m).slowness_bound(), Some(want));
        // one matrix for all nodes, the slowness per node
        assert_eq!(SymmetricMetric::new(&s, &m[..1]).slowness_bound(), Some(want));
        let bad = [[[1.0, 2.0], [2.0, 1.0]]];
        assert_eq!(SymmetricMetric::<2>::new(&s, &bad).slowness_bound(), None);
    }
}
