//! A smooth closest-point map of a triangle mesh, for second order on meshes (paper Sect. 5.2;
//! docs/point-clouds.md, "Meshes at second order").
//!
//! The exact closest point of a mesh ([`super::mesh`]) is not smooth at grid scale where the
//! triangles are large against Δx: near a convex edge every node of a wedge maps to one point of
//! the edge, so I − φD²φ of the metric-corrected equation is singular there. This map replaces it,
//! node by node, with the moving-least-squares projection onto the smooth surface the mesh samples
//! (the machinery of the point clouds, [`super::point_cloud`]'s local quadric):
//!
//! 1. the exact closest point c₀ of x on the mesh (the AABB tree), its triangle and that
//!    triangle's size s (longest edge) and normal n₀;
//! 2. where the mesh is fine against the grid (s ≤ [`FINE_LOW`]·Δx) the exact closest point is
//!    kept: the polyhedron is then within a small fraction of Δx of its smooth surface, and the
//!    central differences of its distance over the 3^D stencil already average its creases (an
//!    icosphere of 10,242 vertices, s ≈ Δx at N = 101: mean error 1.7e-4 at order 2, as its
//!    signed distance given as a level set);
//! 3. elsewhere the fit: the samples (vertices and face centroids) nearest to the current centre
//!    c among those whose normal agrees with n₀ (n·n₀ ≥ [`NORMAL_AGREEMENT`]; on a mesh that is
//!    not consistently oriented |n·n₀|), their weighted quadric height function, and the
//!    fixed point c ← the projection of x onto it, starting from c₀. The normal filter keeps the
//!    other sheet of a thin part (an ear, a leg, a horn tip) out of the fit: its samples face
//!    the other way. That is what made a plain k-nearest fit fail on Spot (the band's
//!    "extension layer does not enclose the inner tube");
//! 4. the fit is kept only when it agrees with the mesh: its foot within [`FOOT_AGREEMENT`]·s of
//!    c₀ and its normal within 60° of n₀; else the exact closest point (a fall-back, counted);
//! 5. on an open mesh, the map is the exact one within [`RIM_LOW`]·Δx of the boundary and
//!    blends to the fit by [`RIM_HIGH`]·Δx (nodes beyond the boundary map onto it, as for the
//!    paper's open surfaces, and the second-order geometry runs them first order);
//! 6. between fine and coarse (s between [`FINE_LOW`]·Δx and [`FINE_HIGH`]·Δx) the two maps
//!    are blended with a C² ramp, so the map has no seam there.
//!
//! Every blend is cp = (1 − w)·cp_fit + w·cp_exact with w a quintic smooth step, continuous with
//! two derivatives in x wherever the triangle it reads does not change.

use super::mesh::{ClosestSearch, TriangleTree};
use super::point_cloud::fit::{distance, Fit};
use crate::error::{Error, Result};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use std::collections::HashMap;
use std::num::NonZero;

type V3 = [f64; 3];

/// The default number of samples in a fit (as for point clouds).
pub const DEFAULT_NEIGHBOURS: usize = 20;
/// Triangles up to this many grid spacings (longest edge) use the exact closest point.
pub const FINE_LOW: f64 = 2.0;
/// Triangles from this many grid spacings use the fit; between, a blend of both.
pub const FINE_HIGH: f64 = 3.0;
/// Within this many grid spacings of an open mesh's boundary, the exact closest point.
pub const RIM_LOW: f64 = 2.0;
/// From this many grid spacings of the boundary, the fit; between, a blend of both.
pub const RIM_HIGH: f64 = 4.0;
/// A sample enters a fit when its normal makes less than 60° with the exact foot's triangle's.
pub const NORMAL_AGREEMENT: f64 = 0.5;
/// A fit's foot farther from the exact closest point than this fraction of the triangle's size
/// is not the map of the surface there (the fall-back).
pub const FOOT_AGREEMENT: f64 = 0.25;
/// Iterations of the fixed point c ← foot(x; fit at c).
const MAX_ITERATIONS: usize = 3;
/// The fixed point stops when the foot moves by less than this fraction of the fit's radius.
const TOLERANCE: f64 = 1e-10;
/// Queries per block of [`SmoothMesh::closest_points`] (the answer does not depend on threads).
const BLOCK: usize = 2048;

/// A face whose longest edge L exceeds this many times its height H over that edge (L²/2·area)
/// is thin: the barycentric grid of [`SmoothMesh::new`] puts its m² samples in rows a spacing
/// apart along L but only H/m apart across them, and a fit's nearest samples then lie in one or
/// two rows, its quadric undetermined across them. A capsule from trimesh, whose cylinder is one
/// ring of 0.80 × 0.059 triangles (L/H = 13.7), had feet up to 4Δx off the surface, its band
/// not enclosed at N = 61–121 and 8–10% short at N = 41; the icosphere's and Spot's faces are
/// far below it (at most 6.5).
pub const THIN_FACE: f64 = 8.0;

/// The samples of a thin face ([`THIN_FACE`]): a grid along its longest edge and across it, about
/// `spacing` apart both ways (at least one row), the points inside the face; None for a face
/// that is not thin.
fn thin_face_samples(t: &[V3; 3], spacing: f64) -> Option<Vec<V3>> {
    let k = (0..3)
        .max_by(|&i, &j| {
            let li = norm(sub(t[(i + 1) % 3], t[i]));
            let lj = norm(sub(t[(j + 1) % 3], t[j]));
            li.total_cmp(&lj)
        })
        .unwrap_or(0);
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    let long = norm(sub(b, a));
    let area2 = norm(cross(sub(b, a), sub(c, a)));
    if !(long > 0.0 && area2 > 0.0) || long * long <= THIN_FACE * area2 {
        return None;
    }
    let e = [0, 1, 2].map(|i| (b[i] - a[i]) / long);
    let foot = dot(sub(c, a), e);
    let across = [0, 1, 2].map(|i| c[i] - a[i] - foot * e[i]);
    let height = norm(across);
    let n = [0, 1, 2].map(|i| across[i] / height);
    let along_parts = (long / spacing).ceil().clamp(1.0, 4096.0) as usize;
    let across_parts = (height / spacing).ceil().clamp(1.0, 64.0) as usize;
    let mut out = Vec::new();
    for i in 0..along_parts {
        let x = (i as f64 + 0.5) * long / along_parts as f64;
        // the face's height at x: rising to `height` over the foot of c, falling after it
        let top = if x <= foot {
            height * x / foot.max(f64::MIN_POSITIVE)
        } else {
            height * (long - x) / (long - foot).max(f64::MIN_POSITIVE)
        };
        for j in 0..across_parts {
            let y = (j as f64 + 0.5) * height / across_parts as f64;
            if y <= top {
                out.push([0, 1, 2].map(|q| a[q] + x * e[q] + y * n[q]));
            }
        }
    }
    if out.is_empty() {
        out.push([0, 1, 2].map(|q| (a[q] + b[q] + c[q]) / 3.0));
    }
    Some(out)
}

/// Which map gave a node's closest point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum MapKind {
    /// The fit (possibly blended in part with the exact closest point).
    Fitted = 0,
    /// The exact closest point: the mesh is fine against the grid there.
    Fine = 1,
    /// The exact closest point (or mostly): within a few Δx of an open mesh's boundary.
    Rim = 2,
    /// The exact closest point because the fit failed or disagreed with the mesh.
    Fallback = 3,
    /// No triangle within the search distance: NaN.
    Far = 4,
}

/// How [`SmoothMesh::closest_points`] chooses (the default is [`Mode::Auto`]; the others are for
/// measurements).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// As in the module documentation.
    Auto,
    /// The exact closest point everywhere.
    Exact,
    /// The fit everywhere it agrees with the mesh (no fine-mesh shortcut).
    Fitted,
}

/// A triangle mesh with its AABB tree, its samples (vertices and face centroids, with normals)
/// in a kd-tree, and its boundary.
pub struct SmoothMesh {
    tree: TriangleTree,
    normals: Vec<V3>,
    size: Vec<f64>,
    samples: Vec<V3>,
    sample_normals: Vec<V3>,
    kd: ImmutableKdTree<f64, u32, 3, 32>,
    /// Midpoints of the boundary edges (kd-tree) and the edges.
    rim_kd: Option<ImmutableKdTree<f64, u32, 3, 32>>,
    rim_edges: Vec<[V3; 2]>,
    neighbours: usize,
    oriented: bool,
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: V3) -> V3 {
    let n = norm(a);
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        [0.0; 3]
    }
}

/// The quintic smooth step: 0 for t ≤ 0, 1 for t ≥ 1, C² between.
fn smooth_step(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * t * (t * (6.0 * t - 15.0) + 10.0)
}

/// Distance from `p` to the segment `[a, b]`.
fn segment_distance(p: V3, a: V3, b: V3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]))
}

/// The candidate samples around an anchor, reused while a fit's neighbourhood stays inside them.
#[derive(Default)]
struct Cache {
    anchor: V3,
    radius: f64,
    /// (distance to the current centre, sample index)
    points: Vec<(f64, u32)>,
}

impl SmoothMesh {
    /// The mesh of `vertices` and `faces` (non-degenerate triangles, indices into `vertices`),
    /// fitted over `neighbours` samples: the vertices and points spread over each face about
    /// `spacing` apart (0: the face's centroid only).
    pub fn new(vertices: &[V3], faces: &[[u32; 3]], neighbours: usize, spacing: f64) -> Result<Self> {
        if !(8..=100).contains(&neighbours) {
            return Err(Error::invalid(
                "neighbours",
                format!("must be between 8 and 100; got {neighbours}"),
            ));
        }
        if faces.is_empty() {
            return Err(Error::invalid("faces", "the mesh has no triangles"));
        }
        if let Some(f) = faces.iter().find(|f| f.iter().any(|&i| i as usize >= vertices.len())) {
            return Err(Error::invalid(
                "faces",
                format!("a face indexes a missing vertex: {f:?}"),
            ));
        }
        if vertices.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(Error::invalid("vertices", "every vertex must be finite"));
        }
        let tris: Vec<[V3; 3]> = faces
            .iter()
            .map(|f| {
                [
                    vertices[f[0] as usize],
                    vertices[f[1] as usize],
                    vertices[f[2] as usize],
                ]
            })
            .collect();
        let normals: Vec<V3> = tris
            .iter()
            .map(|t| unit(cross(sub(t[1], t[0]), sub(t[2], t[0]))))
            .collect();
        let size: Vec<f64> = tris
            .iter()
            .map(|t| {
                norm(sub(t[1], t[0]))
                    .max(norm(sub(t[2], t[0])))
                    .max(norm(sub(t[2], t[1])))
            })
            .collect();
        // vertex normals, angle-weighted (Thürrner & Wüthrich), and the edges' use
        let mut vn = vec![[0.0; 3]; vertices.len()];
        let mut used = vec![false; vertices.len()];
        let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(3 * faces.len() / 2);
        for (f, t) in faces.iter().zip(&tris) {
            let n = unit(cross(sub(t[1], t[0]), sub(t[2], t[0])));
            for k in 0..3 {
                let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let u = sub(q, p);
                let w = sub(r, p);
                let angle = norm(cross(u, w)).atan2(dot(u, w));
                let i = f[k] as usize;
                used[i] = true;
                for c in 0..3 {
                    vn[i][c] += angle * n[c];
                }
                let (a, b) = (f[k], f[(k + 1) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_insert((0, 0));
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        // consistently oriented: every edge used at most once in each direction
        let oriented = edges.values().all(|&(f, b)| f <= 1 && b <= 1);
        let mut rim_edges: Vec<[V3; 2]> = edges
            .iter()
            .filter(|(_, &(f, b))| f + b == 1)
            .map(|(&(a, b), _)| [vertices[a as usize], vertices[b as usize]])
            .collect();
        rim_edges.sort_by(|p, q| p.partial_cmp(q).unwrap_or(std::cmp::Ordering::Equal));
        let mut samples = Vec::with_capacity(vertices.len() + faces.len());
        let mut sample_normals = Vec::with_capacity(vertices.len() + faces.len());
        for i in 0..vertices.len() {
            let n = unit(vn[i]);
            if used[i] && norm(n) > 0.0 {
                samples.push(vertices[i]);
                sample_normals.push(n);
            }
        }
        // face samples: the centroids of the m² triangles of each face's subdivision into m
        // parts per edge, m = ⌈size / spacing⌉ (1: the face's centroid); a thin face, a grid
        // of its own axes (thin_face_samples)
        for ((t, n), &s) in tris.iter().zip(&normals).zip(&size) {
            let m = if spacing > 0.0 {
                (s / spacing).ceil().clamp(1.0, 64.0) as usize
            } else {
                1
            };
            if m > 1 {
                if let Some(grid) = thin_face_samples(t, spacing) {
                    sample_normals.extend(std::iter::repeat_n(*n, grid.len()));
                    samples.extend(grid);
                    continue;
                }
            }
            let at = |i: f64, j: f64| {
                let (u, v) = (i / m as f64, j / m as f64);
                [0, 1, 2].map(|c| t[0][c] + u * (t[1][c] - t[0][c]) + v * (t[2][c] - t[0][c]))
            };
            for i in 0..m {
                for j in 0..m - i {
                    let (fi, fj) = (i as f64, j as f64);
                    samples.push(at(fi + 1.0 / 3.0, fj + 1.0 / 3.0));
                    sample_normals.push(*n);
                    if i + j + 1 < m {
                        samples.push(at(fi + 2.0 / 3.0, fj + 2.0 / 3.0));
                        sample_normals.push(*n);
                    }
                }
            }
        }
        if samples.len() < neighbours + 2 {
            return Err(Error::invalid(
                "faces",
                format!(
                    "the mesh has {} samples; the fit needs at least {}",
                    samples.len(),
                    neighbours + 2
                ),
            ));
        }
        let kd = ImmutableKdTree::new_from_slice(&samples);
        let rim_kd = if rim_edges.is_empty() {
            None
        } else {
            let mid: Vec<V3> = rim_edges
                .iter()
                .map(|e| [0, 1, 2].map(|c| 0.5 * (e[0][c] + e[1][c])))
                .collect();
            Some(ImmutableKdTree::new_from_slice(&mid))
        };
        Ok(SmoothMesh {
            tree: TriangleTree::new(tris),
            normals,
            size,
            samples,
            sample_normals,
            kd,
            rim_kd,
            rim_edges,
            neighbours,
            oriented,
        })
    }

    /// Whether every edge is used at most once in each direction (the fits' normal filter is
    /// then signed, which separates the two sheets of a thin part).
    pub fn oriented(&self) -> bool {
        self.oriented
    }

    /// The number of boundary edges (0 for a closed mesh).
    pub fn boundary_edges(&self) -> usize {
        self.rim_edges.len()
    }

    /// Distance from `p` to the mesh's boundary (∞ for a closed mesh): the exact distance to the
    /// boundary edges whose midpoints are among the 8 nearest to `p`.
    fn rim_distance(&self, p: V3) -> f64 {
        let Some(kd) = &self.rim_kd else { return f64::INFINITY };
        let k = NonZero::new(8.min(self.rim_edges.len())).unwrap();
        kd.nearest_n::<SquaredEuclidean>(&p, k)
            .iter()
            .map(|n| {
                let e = &self.rim_edges[n.item as usize];
                segment_distance(p, e[0], e[1])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The fit's neighbourhood of centre `c` among the samples agreeing with `n0`: the k + 1
    /// nearest (the last gets weight 0) into `out`, and the fit's radius. `None` when too few agree.
    fn neighbourhood(&self, c: &V3, n0: V3, cache: &mut Cache, out: &mut Vec<V3>) -> Option<f64> {
        let k1 = self.neighbours + 1;
        for attempt in 0..3 {
            if attempt > 0 || cache.points.is_empty() || distance(c, &cache.anchor) >= cache.radius {
                let want = (3 * self.neighbours + 1) << attempt;
                let found = self.kd.nearest_n::<SquaredEuclidean>(c, NonZero::new(want).unwrap());
                cache.anchor = *c;
                cache.radius = found.last().map_or(0.0, |n| n.distance.sqrt());
                cache.points.clear();
                for n in &found {
                    let s = dot(self.sample_normals[n.item as usize], n0);
                    let agree = if self.oriented { s } else { s.abs() };
                    if agree >= NORMAL_AGREEMENT {
                        cache.points.push((0.0, n.item));
                    }
                }
                if found.len() < want {
                    cache.radius = f64::INFINITY; // every sample seen
                }
            }
            if cache.points.len() < k1 {
                if cache.radius.is_infinite() {
                    return None;
                }
                continue;
            }
            for e in cache.points.iter_mut() {
                e.0 = distance(&self.samples[e.1 as usize], c);
            }
            cache.points.select_nth_unstable_by(k1 - 1, |p, q| p.0.total_cmp(&q.0));
            let radius = cache.points[k1 - 1].0;
            // the cache holds every agreeing sample within its radius of the anchor
            if distance(c, &cache.anchor) + radius <= cache.radius {
                out.clear();
                out.extend(cache.points[..k1].iter().map(|e| self.samples[e.1 as usize]));
                return Some(radius);
            }
        }
        None
    }

    /// The fitted closest point of `x` from the exact one `c0` on a triangle of normal `n0` and
    /// size `s`, or `None` where the fit fails or disagrees with the mesh.
    fn fitted(&self, x: &V3, c0: V3, n0: V3, s: f64, cache: &mut Cache) -> Option<V3> {
        let mut c = c0;
        let mut nb: Vec<V3> = Vec::with_capacity(self.neighbours + 1);
        let mut fit_normal = n0;
        for it in 0..MAX_ITERATIONS {
            let radius = self.neighbourhood(&c, n0, cache, &mut nb)?;
            let f = Fit::new(&nb, &c, radius)?;
            let a = f.project(x);
            let foot = f.lift(&a);
            let (_, grad, _) = f.height(&a);
            // the graph's normal at the foot: n − ∇g·t, in the fit's frame
            let mut n = f.frame[2];
            for k in 0..3 {
                n[k] -= grad[0] * f.frame[0][k] + grad[1] * f.frame[1][k];
            }
            fit_normal = unit(n);
            let moved = distance(&foot, &c);
            c = foot;
            if it > 0 && moved <= TOLERANCE * f.radius {
                break;
            }
        }
        let ok = c.iter().all(|v| v.is_finite())
            && distance(&c, &c0) <= FOOT_AGREEMENT * s
            && dot(fit_normal, n0).abs() >= NORMAL_AGREEMENT;
        ok.then_some(c)
    }

    /// The closest point of one point (see the module documentation), given its exact answer.
    fn closest_one(&self, x: &V3, h: f64, mode: Mode, exact: V3, triangle: usize, cache: &mut Cache) -> (V3, MapKind) {
        if mode == Mode::Exact {
            return (exact, MapKind::Fine);
        }
        let s = self.size[triangle];
        let w_fine = if mode == Mode::Auto {
            1.0 - smooth_step((s / h - FINE_LOW) / (FINE_HIGH - FINE_LOW))
        } else {
            0.0
        };
        let w_rim = 1.0 - smooth_step((self.rim_distance(exact) / h - RIM_LOW) / (RIM_HIGH - RIM_LOW));
        let w = w_fine.max(w_rim);
        if w >= 1.0 {
            return (exact, if w_rim >= 1.0 { MapKind::Rim } else { MapKind::Fine });
        }
        match self.fitted(x, exact, self.normals[triangle], s, cache) {
            Some(fit) => {
                let cp = [0, 1, 2].map(|k| (1.0 - w) * fit[k] + w * exact[k]);
                let kind = if w_rim > 0.5 {
                    MapKind::Rim
                } else if w_fine > 0.5 {
                    MapKind::Fine
                } else {
                    MapKind::Fitted
                };
                (cp, kind)
            }
            None => (exact, MapKind::Fallback),
        }
    }

    /// Closest points of `x` for a grid of spacing `h`, searching within `max_distance` (NaN and
    /// [`MapKind::Far`] beyond), in parallel in fixed blocks (the same answer for any number of
    /// threads).
    pub fn closest_points(&self, x: &[V3], h: f64, max_distance: f64, mode: Mode) -> (Vec<V3>, Vec<MapKind>) {
        let blocks: Vec<Vec<(V3, MapKind)>> = x
            .par_chunks(BLOCK)
            .map(|block| {
                let mut search = ClosestSearch::new(&self.tree);
                let mut cache = Cache::default();
                block
                    .iter()
                    .map(|p| match search.closest(*p, max_distance) {
                        Some(c) => self.closest_one(p, h, mode, c.point, c.triangle, &mut cache),
                        None => ([f64::NAN; 3], MapKind::Far),
                    })
                    .collect()
            })
            .collect();
        blocks.into_iter().flatten().unzip()
    }
}

#[cfg(test)]
mod tests {

    /// A thin face is sampled about a spacing apart along and across its longest edge, every
    /// sample inside it; a face that is not thin keeps the barycentric grid.
    #[test]
    fn a_thin_face_is_sampled_a_spacing_apart_both_ways() {
        let t = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.8], [0.059, 0.0, 0.8]];
        let h = 0.02;
        let samples = thin_face_samples(&t, h).expect("thin");
        // 40 columns along the edge of 0.8, rows 0.0197 apart across the height of 0.0589
        assert!(samples.len() > 40 && samples.len() < 80, "{}", samples.len());
        for p in &samples {
            // inside: 0 ≤ x ≤ 0.059·z/0.8, y = 0, 0 ≤ z ≤ 0.8
            assert!(
                p[1].abs() < 1e-15 && p[0] >= 0.0 && p[0] <= 0.059 * p[2] / 0.8 + 1e-12,
                "{p:?}"
            );
        }
        let nearest = |p: &V3| {
            samples
                .iter()
                .filter(|q| *q != p)
                .map(|q| norm(sub(*q, *p)))
                .fold(f64::INFINITY, f64::min)
        };
        // the samples' nearest neighbours lie a fraction of the spacing away, not 0.004 as across
        // the barycentric grid's rows
        assert!(samples.iter().all(|p| nearest(p) > 0.4 * h && nearest(p) <= 1.01 * h));
        assert!(thin_face_samples(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.8, 0.0]], h).is_none());
    }
    use super::*;

    /// An octahedron subdivided `levels` times, projected onto the sphere of radius `r`.
    fn sphere_mesh(levels: usize, r: f64) -> (Vec<V3>, Vec<[u32; 3]>) {
        let mut v: Vec<V3> = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let mut f: Vec<[u32; 3]> = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        for _ in 0..levels {
            let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
            let mut nf = Vec::new();
            for t in &f {
                let mut m = [0u32; 3];
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    m[k] = *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                        v.push(unit([0, 1, 2].map(|c| v[a as usize][c] + v[b as usize][c])));
                        (v.len() - 1) as u32
                    });
                }
                nf.extend([
                    [t[0], m[0], m[2]],
                    [m[0], t[1], m[1]],
                    [m[2], m[1], t[2]],
                    [m[0], m[1], m[2]],
                ]);
            }
            f = nf;
        }
        (v.iter().map(|p| p.map(|c| r * c)).collect(), f)
    }

    #[test]
    fn fitted_closest_points_are_smooth_across_a_coarse_mesh_s_edges() {
        let (v, f) = sphere_mesh(4, 0.5); // 1,026 vertices, edges up to 0.07: coarse at Δx = 0.01
        let m = SmoothMesh::new(&v, &f, DEFAULT_NEIGHBOURS, 0.01).unwrap();
        assert!(m.oriented() && m.boundary_edges() == 0);
        // points 0.02 outside the sphere along an arc that crosses many edges
        let step = 2e-3;
        let x: Vec<V3> = (0..300)
            .map(|i| {
                let t = 0.3 + i as f64 * step;
                [0.52 * t.cos(), 0.52 * t.sin() * 0.8, 0.52 * t.sin() * 0.6]
            })
            .collect();
        let (cp, kind) = m.closest_points(&x, 0.01, f64::INFINITY, Mode::Auto);
        let (exact, _) = m.closest_points(&x, 0.01, f64::INFINITY, Mode::Exact);
        assert!(kind.iter().all(|&k| k == MapKind::Fitted));
        let phi = |c: &[V3]| -> Vec<f64> { x.iter().zip(c).map(|(p, q)| norm(sub(*p, *q))).collect() };
        let bend = |p: &[f64]| {
            p.windows(3)
                .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs() / (step * step))
                .fold(0.0, f64::max)
        };
        let (fitted, polyhedron) = (phi(&cp), phi(&exact));
        // the fit follows the mesh (its samples lie on it) ...
        for (a, b) in fitted.iter().zip(&polyhedron) {
            assert!((a - b).abs() < 2e-3, "{a} {b}");
        }
        // ... with its edges' kinks rounded: the distance's largest second difference along the
        // arc about half the polyhedron's (measured 6.5 against 12.3: the fits over samples about
        // Δx apart follow the faces and round the edges over a few Δx only)
        assert!(
            bend(&fitted) < 0.7 * bend(&polyhedron),
            "{} {}",
            bend(&fitted),
            bend(&polyhedron)
        );
        // on the sphere, x − cp(x) is radial
        for (p, c) in x.iter().zip(&cp) {
            assert!(norm(cross(unit(sub(*p, *c)), unit(*p))) < 0.05);
        }
    }

    #[test]
    fn fine_triangles_keep_the_exact_closest_point() {
        let (v, f) = sphere_mesh(3, 0.5);
        let m = SmoothMesh::new(&v, &f, DEFAULT_NEIGHBOURS, 0.0).unwrap();
        let x = vec![[0.3, 0.3, 0.3]];
        let (cp, kind) = m.closest_points(&x, 1.0, f64::INFINITY, Mode::Auto);
        let (exact, _) = m.closest_points(&x, 1.0, f64::INFINITY, Mode::Exact);
        assert_eq!(kind[0], MapKind::Fine);
        assert_eq!(cp[0], exact[0]);
    }

    #[test]
    fn an_open_mesh_keeps_the_exact_map_at_its_boundary() {
        // the upper half of the sphere mesh: its boundary is the equator
        let (v, f) = sphere_mesh(4, 0.5);
        let upper: Vec<[u32; 3]> = f
            .into_iter()
            .filter(|t| t.iter().map(|&i| v[i as usize][2]).sum::<f64>() > 0.0)
            .collect();
        let m = SmoothMesh::new(&v, &upper, DEFAULT_NEIGHBOURS, 0.01).unwrap();
        assert!(m.boundary_edges() > 0);
        let x = vec![[0.52, 0.0, 0.01], [0.0, 0.0, 0.52], [0.3, 0.0, -0.2]];
        let (cp, kind) = m.closest_points(&x, 0.01, f64::INFINITY, Mode::Auto);
        let (exact, _) = m.closest_points(&x, 0.01, f64::INFINITY, Mode::Exact);
        assert_eq!(kind, vec![MapKind::Rim, MapKind::Fitted, MapKind::Rim]);
        assert_eq!(cp[0], exact[0]);
        assert_eq!(cp[2], exact[2]);
        assert!((norm(cp[1]) - 0.5).abs() < 1.5e-3); // the polyhedron: up to 1.2e-3 inside
    }

    #[test]
    fn points_beyond_the_search_distance_are_far() {
        let (v, f) = sphere_mesh(2, 0.5);
        let m = SmoothMesh::new(&v, &f, DEFAULT_NEIGHBOURS, 0.0).unwrap();
        let (cp, kind) = m.closest_points(&[[3.0, 0.0, 0.0]], 0.02, 1.0, Mode::Auto);
        assert_eq!(kind[0], MapKind::Far);
        assert!(cp[0][0].is_nan());
        assert!(SmoothMesh::new(&v, &f, 5, 0.0).is_err());
        assert!(SmoothMesh::new(&v, &[[0, 1, 99]], 20, 0.0).is_err());
    }
}
