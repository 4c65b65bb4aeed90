//! Small symmetric matrices (2×2 and 3×3) of the per-node geometry ([`super::geometry`]): the
//! eigenvalues of φ's Hessian D²φ, from which the principal curvatures κ = λ/(1 − φλ) at the foot
//! point follow, a test that they stay below a bound without computing them, and the inverse that
//! gives B = (I − φ D²φ)⁻¹ of the corrected equation |B∇u| = 1/F (docs/second-order.md).

/// Relative margin of [`curvatures_below`]: a node whose curvatures come within it of the bound
/// gets its eigenvalues computed (far above the eigenvalues' rounding, ~1e-15 relative).
const CURVATURE_MARGIN: f64 = 1e-6;

/// Whether every principal curvature κ = λ/(1 − φλ) at a 3D node (λ the eigenvalues of the
/// symmetric `hess`, φ = `p`) is below `bound`·(1 − [`CURVATURE_MARGIN`]) in size, decided
/// without the eigenvalues: where 1 − φλ > 0, κ increases with λ, so |κ| ≤ k exactly when λ lies
/// in [−k/(1 − φk), k/(1 + φk)] (an interval inside that domain), which Sylvester's criterion
/// checks on D²φ − λ₋I and λ₊I − D²φ (positive leading minors). False (compute them) in 2D, where
/// the eigenvalues are cheap, and whenever it cannot decide.
///
/// Such a node cannot raise the set-up's largest curvature, which is therefore the same with or
/// without the test and whatever the order or split of the nodes: on the sphere at N = 201 all
/// but a few hundred inner nodes skip the eigenvalues (one `acos` and two `cos` each).
#[inline]
pub(crate) fn curvatures_below<const D: usize>(hess: &[[f64; D]; D], p: f64, bound: f64) -> bool {
    if D != 3 || !(bound > 0.0 && bound.is_finite() && p.is_finite()) {
        return false;
    }
    let k = bound * (1.0 - CURVATURE_MARGIN);
    let (den_hi, den_lo) = (1.0 + p * k, 1.0 - p * k);
    if !(den_hi > 0.0 && den_lo > 0.0) {
        return false;
    }
    let (hi, lo) = (k / den_hi, -k / den_lo);
    let positive_definite = |shift: f64, sign: f64| {
        let m = |r: usize, c: usize| sign * (hess[r][c] - if r == c { shift } else { 0.0 });
        let d1 = m(0, 0);
        let d2 = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
        let d3 = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
            + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
        d1 > 0.0 && d2 > 0.0 && d3 > 0.0
    };
    positive_definite(lo, 1.0) && positive_definite(hi, -1.0)
}

/// Eigenvalues of a symmetric D×D matrix (2 or 3), unordered.
pub(crate) fn symmetric_eigenvalues<const D: usize>(m: &[[f64; D]; D]) -> [f64; 3] {
    if D == 2 {
        let (a, b, d) = (m[0][0], m[0][1], m[1][1]);
        let mean = 0.5 * (a + d);
        let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        return [mean + r, mean - r, 0.0];
    }
    // Smith's trigonometric method for a real symmetric 3×3 matrix
    let p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    let q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    if p1 == 0.0 {
        return [m[0][0], m[1][1], m[2][2]];
    }
    let p2 = (m[0][0] - q).powi(2) + (m[1][1] - q).powi(2) + (m[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let mut bm = [[0.0; 3]; 3];
    for k in 0..3 {
        for l in 0..3 {
            bm[k][l] = (m[k][l] - if k == l { q } else { 0.0 }) / p;
        }
    }
    let det = bm[0][0] * (bm[1][1] * bm[2][2] - bm[1][2] * bm[2][1])
        - bm[0][1] * (bm[1][0] * bm[2][2] - bm[1][2] * bm[2][0])
        + bm[0][2] * (bm[1][0] * bm[2][1] - bm[1][1] * bm[2][0]);
    let r = (det / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let e1 = q + 2.0 * p * phi.cos();
    let e3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    [e1, 3.0 * q - e1 - e3, e3]
}

/// Inverse of a symmetric D×D matrix, or None when it is (nearly) singular.
pub(crate) fn symmetric_inverse<const D: usize>(m: &[[f64; D]; D]) -> Option<[[f64; D]; D]> {
    let mut out = [[0.0; D]; D];
    if D == 2 {
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        if !(det.abs() > 1e-12) {
            return None;
        }
        out[0][0] = m[1][1] / det;
        out[1][1] = m[0][0] / det;
        out[0][1] = -m[0][1] / det;
        out[1][0] = -m[1][0] / det;
        return Some(out);
    }
    let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    if !(det.abs() > 1e-12) {
        return None;
    }
    let inv = [
        [
            c00,
            m[0][2] * m[2][1] - m[0][1] * m[2][2],
            m[0][1] * m[1][2] - m[0][2] * m[1][1],
        ],
        [
            c01,
            m[0][0] * m[2][2] - m[0][2] * m[2][0],
            m[0][2] * m[1][0] - m[0][0] * m[1][2],
        ],
        [
            c02,
            m[0][1] * m[2][0] - m[0][0] * m[2][1],
            m[0][0] * m[1][1] - m[0][1] * m[1][0],
        ],
    ];
    for k in 0..D {
        for l in 0..D {
            out[k][l] = inv[k][l] / det;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curvature_test_never_skips_a_node_that_could_raise_the_bound() {
        let mut next = crate::test_random::uniform(7);
        let (mut skipped, mut computed_below) = (0, 0);
        for _ in 0..200_000 {
            let mut m = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in r..3 {
                    m[r][c] = 4.0 * next() - 2.0;
                    m[c][r] = m[r][c];
                }
            }
            let p = 0.2 * next() - 0.1;
            let curvature = symmetric_eigenvalues(&m)
                .iter()
                .map(|&lam| {
                    let den = 1.0 - p * lam;
                    if den > 0.0 {
                        (lam / den).abs()
                    } else {
                        f64::INFINITY
                    }
                })
                .fold(0.0, f64::max);
            // bounds near the node's own curvature, where a wrong answer would show
            let bound = if curvature.is_finite() {
                curvature * (0.999 + 0.002 * next())
            } else {
                10.0 * next()
            };
            if curvatures_below(&m, p, bound) {
                skipped += 1;
                assert!(
                    curvature < bound * (1.0 - 0.5 * CURVATURE_MARGIN),
                    "{m:?} {p} {bound} {curvature}"
                );
            } else if curvature < bound * (1.0 - 2.0 * CURVATURE_MARGIN) {
                computed_below += 1;
            }
        }
        // it decides nearly every node clearly below the bound without the eigenvalues
        assert!(skipped > 95_000, "{skipped}");
        assert!(computed_below <= 10, "{computed_below} {skipped}");
        // 2D, a zero or infinite bound: never skipped
        assert!(!curvatures_below(&[[0.1, 0.0], [0.0, 0.1]], 0.0, 1.0));
        assert!(!curvatures_below(&[[0.0; 3]; 3], 0.0, 0.0));
        assert!(!curvatures_below(&[[0.0; 3]; 3], 0.0, f64::INFINITY));
    }

    #[test]
    fn eigenvalues_of_a_rotated_diagonal_matrix() {
        // R diag(1, 2, 4) Rᵀ with a rotation about z by 0.3 rad
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let r = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let d = [1.0, 2.0, 4.0];
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
            }
        }
        let mut e = symmetric_eigenvalues(&m);
        e.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for (a, b) in e.iter().zip(d) {
            assert!((a - b).abs() < 1e-12, "{e:?}");
        }
        let inv = symmetric_inverse(&m).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|k| m[i][k] * inv[k][j]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }
}
