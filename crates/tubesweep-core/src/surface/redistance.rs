//! Closest points on the zero level set of a φ *sampled on the grid* (its multilinear
//! interpolant), for `LevelSet(phi_array, redistance=True)`: a φ that is not a distance function
//! is replaced in the band by the signed distance to its zero level set, and the extension
//! direction by `sgn(φ)(x − cp(x))/|x − cp(x)|` (the paper's `sgn(φ) n` of Eq. (8), or the
//! closest-point direction of Sect. 5.2).
//!
//! For each point x, independently (on all threads):
//!
//! 1. Newton steps onto the zero level set, `y ← y − φ(y) ∇φ(y) / |∇φ(y)|²` (the first is the
//!    estimate `φ/|∇φ|`);
//! 2. orthogonality iterations: `y` moves in the tangent plane towards the foot of x,
//!    `y ← y + (I − n nᵀ)(x − y)` with `n = ∇φ(y)/|∇φ(y)|`, and back onto the level set by two
//!    Newton steps, until a step moves `y` by at most `tol · max(1, max |x|)`; then `y` is the
//!    closest point cp(x).
//!
//! φ between the nodes is the multilinear interpolant of the samples, constant beyond the grid's
//! faces (the cell and its fractions clamped to the grid), and ∇φ its central differences with
//! step `eps`. The Newton steps keep `y` in the grid's box (clamped coordinate by coordinate), where
//! φ is known. This is the algorithm and the arithmetic of `tubesweep.redistance`, which keeps it
//! for a callable φ; for samples every evaluation is here, with no Python in the loop.

use crate::error::{Error, Result};
use rayon::prelude::*;

/// A φ sampled at every node of a grid (C order), evaluated between the nodes by multilinear
/// interpolation.
#[derive(Debug, Clone, Copy)]
pub struct SampledField<'a, const D: usize> {
    samples: &'a [f64],
    shape: [usize; D],
    stride: [usize; D],
    lower: [f64; D],
    /// The grid's upper corner, `lower + (shape − 1) · spacing`.
    upper: [f64; D],
    /// The lowest corner of the last cell along each axis, `shape − 2`.
    last_cell: [i64; D],
    spacing: f64,
}

impl<'a, const D: usize> SampledField<'a, D> {
    /// `samples` holds φ at the nodes of the grid of `shape` (at least 2 nodes per axis) with
    /// lower corner `lower` and spacing `spacing`, in C order.
    pub fn new(samples: &'a [f64], shape: [usize; D], lower: [f64; D], spacing: f64) -> Result<Self> {
        if shape.iter().any(|&n| n < 2) {
            return Err(Error::invalid(
                "grid",
                format!("needs at least 2 nodes per axis to interpolate, got shape {shape:?}"),
            ));
        }
        let total = shape.iter().try_fold(1usize, |p, &n| p.checked_mul(n));
        if total != Some(samples.len()) {
            return Err(Error::invalid(
                "phi",
                format!(
                    "expected {} samples (the grid {shape:?}), got {}",
                    total.unwrap_or(usize::MAX),
                    samples.len()
                ),
            ));
        }
        if !(spacing > 0.0 && spacing.is_finite()) || lower.iter().any(|l| !l.is_finite()) {
            return Err(Error::invalid(
                "grid",
                "the spacing must be positive and the lower corner finite",
            ));
        }
        let mut stride = [1usize; D];
        for k in (0..D - 1).rev() {
            stride[k] = stride[k + 1] * shape[k + 1];
        }
        let (mut upper, mut last_cell) = (lower, [0i64; D]);
        for k in 0..D {
            upper[k] = lower[k] + (shape[k] - 1) as f64 * spacing;
            last_cell[k] = (shape[k] - 2) as i64;
        }
        Ok(SampledField {
            samples,
            shape,
            stride,
            lower,
            upper,
            last_cell,
            spacing,
        })
    }

    /// φ at `p`: the multilinear interpolant of the cell that holds `p`, the cell and the
    /// fractions clamped to the grid (so φ is constant along the normal beyond a face). The
    /// corners are summed in the order of their bits, each weight the product of its factors in
    /// axis order.
    #[inline]
    pub fn value(&self, p: &[f64; D]) -> f64 {
        let mut base = [0usize; D];
        let mut frac = [0.0f64; D];
        for k in 0..D {
            (base[k], frac[k]) = self.locate(k, p[k]);
        }
        self.interpolate(&base, &frac)
    }

    /// The cell index along `axis` of the coordinate `c` and its fraction in the cell, both
    /// clamped to the grid ([`value`](Self::value)).
    #[inline(always)]
    fn locate(&self, axis: usize, c: f64) -> (usize, f64) {
        let t = (c - self.lower[axis]) / self.spacing;
        let b = self.cell_index(axis, t);
        (b, (t - b as f64).clamp(0.0, 1.0))
    }

    /// `⌊t⌋` clamped to the cells along `axis`, `0 ..= shape − 2`: the same cell for every `t`
    /// (NaN and values beyond `i64` included, which the clamp brings into the grid), in integers,
    /// without the call to the C library's `floor` that `f64::floor` compiles to on the x86-64
    /// baseline or a second conversion from a float.
    #[inline(always)]
    fn cell_index(&self, axis: usize, t: f64) -> usize {
        let i = t as i64; // towards zero, saturating; NaN → 0
        i.saturating_sub(i64::from(i as f64 > t)).clamp(0, self.last_cell[axis]) as usize
    }

    /// The multilinear interpolant of the cell with lowest corner `base` at the fractions `frac`:
    /// the corners summed in the order of their bits, each weight the product of its factors in
    /// axis order (the arithmetic of [`value`](Self::value), which calls it).
    #[inline(always)]
    fn interpolate(&self, base: &[usize; D], frac: &[f64; D]) -> f64 {
        let origin: usize = (0..D).map(|k| base[k] * self.stride[k]).sum();
        // the factors of axis k: 1 − frac (no step) and frac (a step)
        let mut factor = [[0.0f64; 2]; D];
        for k in 0..D {
            factor[k] = [1.0 - frac[k], frac[k]];
        }
        let mut out = 0.0;
        for corner in 0..1usize << D {
            let mut w = factor[0][corner & 1];
            let mut at = origin + (corner & 1) * self.stride[0];
            for k in 1..D {
                let bit = corner >> k & 1;
                w *= factor[k][bit];
                at += bit * self.stride[k];
            }
            out += w * self.samples[at];
        }
        out
    }

    /// φ at `p` and its exact gradient there: the multilinear interpolant of the cell that holds
    /// `p` and its derivatives (as [`value`](Self::value), the cell and the fractions clamped to
    /// the grid; along an axis where `p` lies beyond the grid's face the derivative is zero, φ
    /// being constant there). At a cell face it is the derivative of the cell `value` reads.
    #[inline]
    pub(crate) fn value_and_gradient(&self, p: &[f64; D]) -> (f64, [f64; D]) {
        let (base, frac, inside) = self.cell_of(p);
        self.value_and_gradient_in(&base, &frac, &inside)
    }

    /// φ at `p` and its exact gradient ([`value_and_gradient`](Self::value_and_gradient)) and,
    /// when `wanted(φ, ∇φ)`, the [`half_step_gradient`](Self::half_step_gradient) there, in one
    /// location of `p` (the same bits as the separate calls).
    #[inline]
    pub(crate) fn value_gradient_and_half_step_if(
        &self,
        p: &[f64; D],
        wanted: impl FnOnce(f64, &[f64; D]) -> bool,
    ) -> (f64, [f64; D], Option<[f64; D]>) {
        let (base, frac, inside) = self.cell_of(p);
        let (v, g) = self.value_and_gradient_in(&base, &frac, &inside);
        let half_step = wanted(v, &g).then(|| self.half_step_gradient_in(&base, &frac));
        (v, g, half_step)
    }

    /// The cell that holds `p` (clamped to the grid), the fractions of `p` in it (clamped to
    /// [0, 1]) and, per axis, whether `p` lies within the grid along it (the location of
    /// [`locate`](Self::locate)).
    #[inline(always)]
    fn cell_of(&self, p: &[f64; D]) -> ([usize; D], [f64; D], [bool; D]) {
        let mut base = [0usize; D];
        let mut frac = [0.0f64; D];
        let mut inside = [true; D];
        for k in 0..D {
            let t = (p[k] - self.lower[k]) / self.spacing;
            base[k] = self.cell_index(k, t);
            let f = t - base[k] as f64;
            inside[k] = (0.0..=1.0).contains(&f);
            frac[k] = f.clamp(0.0, 1.0);
        }
        (base, frac, inside)
    }

    /// The value and exact gradient of the cell `base`'s interpolant at the fractions `frac`
    /// ([`value_and_gradient`](Self::value_and_gradient)).
    #[inline(always)]
    fn value_and_gradient_in(&self, base: &[usize; D], frac: &[f64; D], inside: &[bool; D]) -> (f64, [f64; D]) {
        let origin: usize = (0..D).map(|k| base[k] * self.stride[k]).sum();
        // the corners (bit k of the corner: a step along axis k), reduced one axis at a time by
        // linear interpolation, carrying the differences along the axes already reduced
        let mut value = [0.0f64; 8];
        let mut diff = [[0.0f64; D]; 8];
        for (corner, v) in value.iter_mut().enumerate().take(1 << D) {
            let mut at = origin;
            for k in 0..D {
                if corner >> k & 1 == 1 {
                    at += self.stride[k];
                }
            }
            *v = self.corner(at);
        }
        for a in 0..D {
            let f = frac[a];
            for c in 0..1usize << (D - 1 - a) {
                let (lo, hi) = (2 * c, 2 * c + 1);
                let mut d = [0.0f64; D];
                for k in 0..a {
                    d[k] = diff[lo][k] + f * (diff[hi][k] - diff[lo][k]);
                }
                d[a] = value[hi] - value[lo];
                value[c] = value[lo] + f * d[a];
                diff[c] = d;
            }
        }
        let (value, mut grad) = (value[0], diff[0]);
        for a in 0..D {
            if !inside[a] {
                grad[a] = 0.0;
            }
        }
        for g in grad.iter_mut() {
            *g /= self.spacing;
        }
        (value, grad)
    }

    /// The sample at linear index `at` of a corner of a cell of the grid (a cell index within
    /// `0 ..= shape − 2` along each axis, as [`cell_index`](Self::cell_index) gives, plus 0 or 1
    /// along each, or the window of [`half_step_gradient_in`](Self::half_step_gradient_in) checked
    /// to lie in the grid): in the grid by construction, so read without a bounds check, the
    /// innermost load of the re-distancing's evaluations.
    #[inline(always)]
    fn corner(&self, at: usize) -> f64 {
        debug_assert!(at < self.samples.len());
        // SAFETY: `new` checked `samples.len()` = ∏ shape; the callers' cells lie in the grid
        unsafe { *self.samples.get_unchecked(at) }
    }

    /// φ at the node of D-index `node`.
    #[inline]
    pub(crate) fn sample(&self, node: [usize; D]) -> f64 {
        let mut at = 0;
        for k in 0..D {
            at += node[k] * self.stride[k];
        }
        self.samples[at]
    }

    /// The coordinate along `axis` of the nodes of index `index` on it.
    #[inline]
    pub(crate) fn coordinate(&self, axis: usize, index: usize) -> f64 {
        self.lower[axis] + index as f64 * self.spacing
    }

    /// The grid spacing.
    #[inline]
    pub(crate) fn spacing(&self) -> f64 {
        self.spacing
    }

    /// The samples, in C order.
    #[inline]
    pub(crate) fn samples(&self) -> &'a [f64] {
        self.samples
    }

    /// The grid's shape.
    #[inline]
    pub(crate) fn shape(&self) -> [usize; D] {
        self.shape
    }

    /// Central differences of [`value`](Self::value) with step `eps` along each axis (the cell and
    /// fraction of `y` along the other axes located once for all 2D values).
    #[inline]
    pub(crate) fn gradient(&self, y: &[f64; D], eps: f64) -> [f64; D] {
        let mut base = [0usize; D];
        let mut frac = [0.0f64; D];
        for k in 0..D {
            (base[k], frac[k]) = self.locate(k, y[k]);
        }
        let mut g = [0.0; D];
        for k in 0..D {
            let (mut b, mut f) = (base, frac);
            (b[k], f[k]) = self.locate(k, y[k] + eps);
            let up = self.interpolate(&b, &f);
            (b[k], f[k]) = self.locate(k, y[k] - eps);
            let down = self.interpolate(&b, &f);
            g[k] = (up - down) / (2.0 * eps);
        }
        g
    }

    /// The central differences of [`value`](Self::value) with step half a spacing,
    /// `(φ(y + Δx/2 eₖ) − φ(y − Δx/2 eₖ)) / Δx` along each axis ([`gradient`](Self::gradient) with
    /// `eps = Δx/2`, equal to rounding), in closed form: along axis `k` the interpolant is
    /// piecewise linear, so the difference is the mean of its slope over the window of one spacing
    /// around `y`, the slopes of the (at most two) cells the window overlaps weighted by the
    /// window's length in each; beyond the grid's faces φ is constant (slope zero), as `value`
    /// has it. One location of `y` and the samples of its 3^D block, instead of 2D interpolations.
    #[inline]
    pub(crate) fn half_step_gradient(&self, y: &[f64; D]) -> [f64; D] {
        let mut base = [0usize; D];
        let mut frac = [0.0f64; D];
        for k in 0..D {
            (base[k], frac[k]) = self.locate(k, y[k]);
        }
        self.half_step_gradient_in(&base, &frac)
    }

    /// [`half_step_gradient`](Self::half_step_gradient) at the fractions `frac` of the cell `base`.
    #[inline(always)]
    fn half_step_gradient_in(&self, base: &[usize; D], frac: &[f64; D]) -> [f64; D] {
        let mut factor = [[0.0f64; 2]; D]; // 1 − frac and frac per axis
        for k in 0..D {
            factor[k] = [1.0 - frac[k], frac[k]];
        }
        let origin: usize = (0..D).map(|k| base[k] * self.stride[k]).sum();
        let mut g = [0.0; D];
        for k in 0..D {
            let (b, f, step) = (base[k], factor[k][1], self.stride[k]);
            // the corners of the other axes with their multilinear weights at y (2^(D−1) of them)
            let mut weight = [1.0f64; 4];
            let mut offset = [0usize; 4];
            let mut count = 1;
            for a in 0..D {
                if a != k {
                    for c in 0..count {
                        weight[c + count] = weight[c] * factor[a][1];
                        weight[c] *= factor[a][0];
                        offset[c + count] = offset[c] + self.stride[a];
                    }
                    count *= 2;
                }
            }
            // the window's cells along k, the lower one's first node, and its length in each
            let (first, lower_len, upper_len) = if f >= 0.5 {
                (b as isize, 1.5 - f, f - 0.5)
            } else {
                (b as isize - 1, 0.5 - f, f + 0.5)
            };
            let last = self.shape[k] as isize - 2; // the last cell along k
            let row = origin - b * step;
            let mut sum = 0.0;
            if first >= 0 && first < last {
                // both cells in the grid: the interpolant along the other axes at three nodes
                let n0 = row + first as usize * step;
                for c in 0..1usize << (D - 1) {
                    let at = n0 + offset[c];
                    let (v0, v1, v2) = (self.corner(at), self.corner(at + step), self.corner(at + 2 * step));
                    sum += weight[c] * (lower_len * (v1 - v0) + upper_len * (v2 - v1));
                }
            } else {
                // a cell beyond the grid's faces: φ is constant there, its slope zero
                for (cell, len) in [(first, lower_len), (first + 1, upper_len)] {
                    if (0..=last).contains(&cell) && len > 0.0 {
                        let node = row + cell as usize * step;
                        for c in 0..1usize << (D - 1) {
                            let at = node + offset[c];
                            sum += weight[c] * len * (self.samples[at + step] - self.samples[at]);
                        }
                    }
                }
            }
            g[k] = sum / self.spacing;
        }
        g
    }

    /// `y` moved onto the grid's box, coordinate by coordinate: φ is known only there (beyond a
    /// face the interpolant is φ on the face, constant along the normal, whose gradient along
    /// that axis vanishes).
    #[inline]
    pub(crate) fn clamp_to_box(&self, y: &mut [f64; D]) {
        for k in 0..D {
            y[k] = y[k].clamp(self.lower[k], self.upper[k]);
        }
    }

    /// `steps` Newton steps from `y` onto the zero level set, `y` kept in the grid's box (moved
    /// onto it before the first step and after each: [`clamp_to_box`](Self::clamp_to_box)); false
    /// if `|∇φ|²` fell to 1e-24 or below on the way (`y` then stays where it was).
    ///
    /// Without the box a step could overshoot beyond a face, where φ no longer varies along the
    /// face's normal: from inside a convex φ such as `|x|² − r²` near a face the first step jumps
    /// past the surface by about the distance it had to go, and at a node 0.26 from a circle
    /// 0.05 from the box's side (Δx = 0.079) it landed 0.1 beyond the side, with a vanishing
    /// gradient. The node was then dropped from the band, and the band nodes beyond it stayed
    /// unreached.
    #[inline]
    pub(crate) fn newton(&self, y: &mut [f64; D], steps: usize, eps: f64) -> bool {
        let mut good = true;
        self.clamp_to_box(y);
        for _ in 0..steps {
            let g = self.gradient(y, eps);
            let n2 = sum_of_squares(&g);
            good &= n2 > 1e-24;
            let s = if good { self.value(y) / n2 } else { 0.0 };
            for k in 0..D {
                y[k] -= s * g[k];
            }
            self.clamp_to_box(y);
        }
        good
    }
}

#[inline]
pub(crate) fn sum_of_squares<const D: usize>(v: &[f64; D]) -> f64 {
    let mut s = v[0] * v[0];
    for x in &v[1..] {
        s += x * x;
    }
    s
}

/// The iterations of the projection.
#[derive(Debug, Clone, Copy)]
pub struct ProjectionOptions {
    /// The step of the central differences of ∇φ.
    pub eps: f64,
    /// Newton steps before the orthogonality iterations.
    pub newton_steps: usize,
    /// The most orthogonality iterations.
    pub orthogonality_steps: usize,
    /// A point has settled when an iteration moves it by at most `tol · max(1, max |x|)`.
    pub tol: f64,
}

/// Closest points on the zero level set, for each point.
#[derive(Debug, Clone, Default)]
pub struct Projection {
    /// The closest points, `D` coordinates each.
    pub closest: Vec<f64>,
    /// `sgn φ(x) · |x − cp(x)|`.
    pub signed: Vec<f64>,
    /// False where ∇φ vanished or the iterations did not settle (points far from the surface
    /// compared with its reach).
    pub converged: Vec<bool>,
}

/// The closest points on `{φ = 0}` of `points` (`D` coordinates each) for the sampled `field`
/// (see the module documentation), on all threads.
pub fn project_to_zero_level_set<const D: usize>(
    field: &SampledField<'_, D>,
    points: &[f64],
    options: ProjectionOptions,
) -> Result<Projection> {
    if !points.len().is_multiple_of(D) || points.iter().any(|x| !x.is_finite()) {
        return Err(Error::invalid(
            "points",
            format!("must be finite, {D} coordinates each"),
        ));
    }
    if !(options.eps > 0.0 && options.eps.is_finite()) {
        return Err(Error::invalid(
            "eps",
            format!("the step of the differences must be positive, got {}", options.eps),
        ));
    }
    let scale = points.par_iter().map(|x| x.abs()).reduce(|| 0.0, f64::max).max(1.0);
    let settled = options.tol * scale;
    let m = points.len() / D;
    let mut out = Projection {
        closest: vec![0.0; m * D],
        signed: vec![0.0; m],
        converged: vec![false; m],
    };
    points
        .par_chunks(D)
        .zip(out.closest.par_chunks_mut(D))
        .zip(out.signed.par_iter_mut())
        .zip(out.converged.par_iter_mut())
        .for_each(|(((x, cp), signed), converged)| {
            let x: [f64; D] = x.try_into().expect("chunks of D");
            let phi_x = field.value(&x);
            let mut y = x;
            let mut ok = field.newton(&mut y, options.newton_steps, options.eps);
            let mut active = ok;
            for _ in 0..options.orthogonality_steps {
                if !active {
                    break;
                }
                let g = field.gradient(&y, options.eps);
                let norm = sum_of_squares(&g).sqrt().max(1e-300);
                let mut n = [0.0; D];
                let mut r = [0.0; D];
                for k in 0..D {
                    n[k] = g[k] / norm;
                    r[k] = x[k] - y[k];
                }
                let mut along = r[0] * n[0];
                for k in 1..D {
                    along += r[k] * n[k];
                }
                let mut z = [0.0; D];
                for k in 0..D {
                    z[k] = y[k] + (r[k] - along * n[k]);
                }
                let good = field.newton(&mut z, 2, options.eps);
                ok &= good;
                let mut step = [0.0; D];
                for k in 0..D {
                    step[k] = z[k] - y[k];
                }
                let moved = sum_of_squares(&step).sqrt();
                y = z;
                active = moved > settled && good;
            }
            if active {
                ok = false; // did not settle
            }
            let mut diff = [0.0; D];
            for k in 0..D {
                diff[k] = x[k] - y[k];
            }
            let dist = sum_of_squares(&diff).sqrt();
            *signed = if phi_x < 0.0 { -dist } else { dist };
            cp.copy_from_slice(&y);
            *converged = ok;
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// φ = (|x|² − r²)·(1 + 0.3 x₀) sampled on [−1, 1]^D: not a distance function.
    fn quadric<const D: usize>(n: usize, r: f64) -> (Vec<f64>, [usize; D], f64) {
        let h = 2.0 / (n - 1) as f64;
        let total = n.pow(D as u32);
        let samples = (0..total)
            .map(|mut l| {
                let mut x = [0.0; D];
                for k in (0..D).rev() {
                    x[k] = -1.0 + h * (l % n) as f64;
                    l /= n;
                }
                (x.iter().map(|v| v * v).sum::<f64>() - r * r) * (1.0 + 0.3 * x[0])
            })
            .collect();
        (samples, [n; D], h)
    }

    #[test]
    fn the_half_step_gradient_is_the_central_differences_of_the_interpolant() {
        // a quadric and random samples, at random points, on cell faces and nodes, and at the box's faces
        let (samples, shape, h) = quadric::<3>(9, 0.5);
        let field = SampledField::new(&samples, shape, [-1.0; 3], h).unwrap();
        let noise: Vec<f64> = (0..81).map(|l| ((l * 7919) % 101) as f64 / 50.0 - 1.0).collect();
        let flat = SampledField::new(&noise, [9, 9], [-1.0; 2], h).unwrap();
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut points: Vec<[f64; 3]> = (0..2000).map(|_| [next(), next(), next()]).collect();
        points.extend([
            [-1.0, -1.0, -1.0],
            [1.0, 1.0, 1.0],
            [0.0, 0.25, -0.75],
            [1.0, 0.1, -1.0],
            [-0.875, 0.5, 0.999],
        ]);
        for p in &points {
            let (a, b) = (field.half_step_gradient(p), field.gradient(p, 0.5 * h));
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-13 * (1.0 + b[k].abs()),
                    "{p:?}: {a:?} against {b:?}"
                );
            }
            let q = [p[0], p[2]];
            let (a, b) = (flat.half_step_gradient(&q), flat.gradient(&q, 0.5 * h));
            for k in 0..2 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-13 * (1.0 + b[k].abs()),
                    "{q:?}: {a:?} against {b:?}"
                );
            }
        }
    }

    #[test]
    fn interpolation_is_exact_at_nodes_and_for_multilinear_functions() {
        let n = 9;
        let h = 0.25;
        // φ = 1 + 2x − y + 0.5 x y: multilinear, so reproduced everywhere in the box
        let f = |x: f64, y: f64| 1.0 + 2.0 * x - y + 0.5 * x * y;
        let samples: Vec<f64> = (0..n * n)
            .map(|l| f(-1.0 + h * (l / n) as f64, -1.0 + h * (l % n) as f64))
            .collect();
        let field = SampledField::new(&samples, [n, n], [-1.0, -1.0], h).unwrap();
        for p in [[-1.0, -1.0], [0.3, -0.7], [0.99, 1.0], [1.0, 1.0], [-0.125, 0.625]] {
            assert!((field.value(&p) - f(p[0], p[1])).abs() < 1e-14, "{p:?}");
        }
        // and the gradient of the interpolant, exact for a multilinear function
        for p in [[0.3, -0.7], [-0.9, 0.95], [0.5, 0.25]] {
            let (v, g) = field.value_and_gradient(&p);
            assert!((v - f(p[0], p[1])).abs() < 1e-14, "{p:?}");
            assert!((g[0] - (2.0 + 0.5 * p[1])).abs() < 1e-13 && (g[1] - (-1.0 + 0.5 * p[0])).abs() < 1e-13);
        }
        // beyond a face φ is the face's value
        assert!((field.value(&[1.5, 0.3]) - f(1.0, 0.3)).abs() < 1e-14);
        assert!(SampledField::new(&samples, [n, n + 1], [-1.0, -1.0], h).is_err());
        assert!(SampledField::new(&samples[..1], [1, 1], [-1.0, -1.0], h).is_err());
    }

    #[test]
    fn projection_finds_the_distance_to_a_skewed_quadric() {
        // the zero set of (|x|² − r²)(1 + 0.3 x₀) is the sphere of radius r: the signed distance
        // is |x| − r, up to the interpolation error O(h²)
        let (samples, shape, h) = quadric::<3>(81, 0.5);
        let field = SampledField::new(&samples, shape, [-1.0; 3], h).unwrap();
        let pts: Vec<f64> = (0..200)
            .flat_map(|i| {
                let t = i as f64 * 0.731;
                let rho = 0.5 + 2.0 * h * (i as f64 * 0.37).sin();
                let (a, b) = (t.cos(), (1.3 * t).sin() * 0.8);
                let c = (1.0 - b * b).sqrt();
                [rho * c * a, rho * c * t.sin(), rho * b]
            })
            .collect();
        let opts = ProjectionOptions {
            eps: 0.5 * h,
            newton_steps: 6,
            orthogonality_steps: 30,
            tol: 1e-12,
        };
        let p = project_to_zero_level_set(&field, &pts, opts).unwrap();
        for (i, x) in pts.chunks(3).enumerate() {
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            assert!(p.converged[i]);
            assert!(
                (p.signed[i] - (r - 0.5)).abs() < 2e-3,
                "point {i}: {} against {}",
                p.signed[i],
                r - 0.5
            );
            let c = &p.closest[3 * i..3 * i + 3];
            assert!(field.value(&[c[0], c[1], c[2]]).abs() < 1e-10);
        }
        assert!(project_to_zero_level_set(&field, &[0.0, f64::NAN, 0.0], opts).is_err());
        assert!(project_to_zero_level_set(&field, &[0.0, 0.0], opts).is_err());
    }
}
