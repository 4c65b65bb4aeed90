//! Exact closest points on a triangle mesh with a bounding-volume hierarchy (AABB tree).
//!
//! A triangle mesh Σ enters the solver in the closest-point representation of the paper's
//! Sect. 5.2: at every band node `x` we need `cp(x) = argmin_{z∈Σ} |x − z|`, the distance
//! `|x − cp(x)|` (inner tube / extension layer) and the extension direction
//! `(x − cp(x)) / |x − cp(x)|` of Eq. (8). [`TriangleTree`] answers these queries exactly:
//! a binary tree of axis-aligned boxes over the triangles (split at the median centroid along
//! the longest axis, a few triangles per leaf), searched depth-first, nearer child first, and
//! pruned by the squared box distance against the best squared distance so far. The
//! point–triangle projection is the Voronoi-region test (vertices, edges, face).
//! Queries of many points run in parallel (rayon).

use rayon::prelude::*;

/// Which feature of the triangle `(a, b, c)` holds the closest point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Feature {
    Face = 0,
    VertexA = 1,
    VertexB = 2,
    VertexC = 3,
    EdgeAB = 4,
    EdgeAC = 5,
    EdgeBC = 6,
}

type V3 = [f64; 3];

#[inline]
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
fn axpy(a: V3, s: f64, d: V3) -> V3 {
    [a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]]
}

/// Closest point on triangle `(a, b, c)` to `p` and the feature it lies on.
pub fn closest_point_on_triangle(p: V3, a: V3, b: V3, c: V3) -> (V3, Feature) {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::VertexA);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::VertexB);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (axpy(a, v, ab), Feature::EdgeAB);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::VertexC);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (axpy(a, w, ac), Feature::EdgeAC);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (axpy(b, w, sub(c, b)), Feature::EdgeBC);
    }
    let denom = va + vb + vc;
    let denom = if denom != 0.0 { 1.0 / denom } else { 0.0 };
    let v = vb * denom;
    let w = vc * denom;
    (axpy(axpy(a, v, ab), w, ac), Feature::Face)
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: V3,
    hi: V3,
    /// leaf: first triangle in `order`; inner: index of the left child (right = left + 1)
    start: u32,
    /// leaf: number of triangles; inner: 0
    count: u32,
}

#[inline]
fn box_dist2(p: V3, lo: V3, hi: V3) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        let d = if p[k] < lo[k] {
            lo[k] - p[k]
        } else if p[k] > hi[k] {
            p[k] - hi[k]
        } else {
            0.0
        };
        s += d * d;
    }
    s
}

/// The answer of one query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    pub distance: f64,
    pub point: V3,
    pub triangle: usize,
    pub feature: Feature,
}

/// An AABB tree over triangles for exact closest-point queries.
#[derive(Clone, Debug)]
pub struct TriangleTree {
    tris: Vec<[V3; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

const LEAF_SIZE: usize = 4;

impl TriangleTree {
    /// Builds the tree. `triangles[i] = [a, b, c]`; the ids reported by queries are indices
    /// into `triangles`. Panics on an empty list.
    pub fn new(triangles: Vec<[V3; 3]>) -> Self {
        assert!(!triangles.is_empty(), "TriangleTree needs at least one triangle");
        let n = triangles.len();
        let cent: Vec<V3> = triangles
            .iter()
            .map(|t| [(t[0][0] + t[1][0] + t[2][0]) / 3.0, (t[0][1] + t[1][1] + t[2][1]) / 3.0, (t[0][2] + t[1][2] + t[2][2]) / 3.0])
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 2);
        nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], start: 0, count: 0 });
        // iterative build: (node index, start, end)
        let mut stack = vec![(0usize, 0usize, n)];
        while let Some((ni, s, e)) = stack.pop() {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            let mut clo = [f64::INFINITY; 3];
            let mut chi = [f64::NEG_INFINITY; 3];
            for &t in &order[s..e] {
                for v in &triangles[t as usize] {
                    for k in 0..3 {
                        lo[k] = lo[k].min(v[k]);
                        hi[k] = hi[k].max(v[k]);
                    }
                }
                let c = cent[t as usize];
                for k in 0..3 {
                    clo[k] = clo[k].min(c[k]);
                    chi[k] = chi[k].max(c[k]);
                }
            }
            nodes[ni].lo = lo;
            nodes[ni].hi = hi;
            if e - s <= LEAF_SIZE {
                nodes[ni].start = s as u32;
                nodes[ni].count = (e - s) as u32;
                continue;
            }
            let ext = sub(chi, clo);
            let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] { 0 } else if ext[1] >= ext[2] { 1 } else { 2 };
            let mid = (s + e) / 2;
            order[s..e].select_nth_unstable_by(mid - s, |&x, &y| cent[x as usize][axis].total_cmp(&cent[y as usize][axis]));
            let left = nodes.len();
            nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], start: 0, count: 0 });
            nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], start: 0, count: 0 });
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push((left, s, mid));
            stack.push((left + 1, mid, e));
        }
        TriangleTree { tris: triangles, order, nodes }
    }

    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Bytes held by the tree.
    pub fn heap_bytes(&self) -> usize {
        self.tris.len() * std::mem::size_of::<[V3; 3]>() + self.order.len() * 4 + self.nodes.len() * std::mem::size_of::<Node>()
    }

    /// Squared distance from `p` to the root box (a cheap lower bound).
    pub fn box_distance(&self, p: V3) -> f64 {
        box_dist2(p, self.nodes[0].lo, self.nodes[0].hi).sqrt()
    }

    /// The exact closest point on the mesh to `p`, searching only within `max_distance`
    /// (`None` when nothing is that close; use `f64::INFINITY` for no limit). Among triangles at
    /// exactly the same distance the one with the smallest index is reported, so the answer does
    /// not depend on the order of the search.
    pub fn closest(&self, p: V3, max_distance: f64) -> Option<Closest> {
        self.closest_from(p, max_distance, None, &mut Vec::with_capacity(64))
    }

    /// [`closest`](Self::closest), starting from triangle `hint` (typically the answer for a
    /// nearby point): its distance bounds the search from the start, which then only opens the
    /// boxes that can hold something closer. The answer is the same with or without a hint.
    fn closest_from(&self, p: V3, max_distance: f64, hint: Option<usize>, stack: &mut Vec<(u32, f64)>) -> Option<Closest> {
        let mut best2 = if max_distance.is_finite() { max_distance * max_distance } else { f64::INFINITY };
        let mut best: Option<(V3, usize, Feature)> = None;
        if let Some(t) = hint {
            let tri = &self.tris[t];
            let (q, f) = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
            let dd = sub(p, q);
            let e2 = dot(dd, dd);
            if e2 <= best2 {
                best2 = e2;
                best = Some((q, t, f));
            }
        }
        stack.clear();
        let root_d = box_dist2(p, self.nodes[0].lo, self.nodes[0].hi);
        if root_d <= best2 {
            stack.push((0, root_d));
        }
        while let Some((ni, d2)) = stack.pop() {
            if d2 > best2 {
                continue;
            }
            let node = self.nodes[ni as usize];
            if node.count > 0 {
                for &t in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let tri = &self.tris[t as usize];
                    let (q, f) = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
                    let dd = sub(p, q);
                    let e2 = dot(dd, dd);
                    let better = match best {
                        None => e2 <= best2,
                        Some((_, bt, _)) => e2 < best2 || (e2 == best2 && (t as usize) < bt),
                    };
                    if better {
                        best2 = e2;
                        best = Some((q, t as usize, f));
                    }
                }
            } else {
                let l = node.start;
                let r = l + 1;
                let dl = box_dist2(p, self.nodes[l as usize].lo, self.nodes[l as usize].hi);
                let dr = box_dist2(p, self.nodes[r as usize].lo, self.nodes[r as usize].hi);
                // push the farther child first so that the nearer one is searched first
                if dl <= dr {
                    if dr <= best2 {
                        stack.push((r, dr));
                    }
                    if dl <= best2 {
                        stack.push((l, dl));
                    }
                } else {
                    if dl <= best2 {
                        stack.push((l, dl));
                    }
                    if dr <= best2 {
                        stack.push((r, dr));
                    }
                }
            }
        }
        best.map(|(q, t, f)| Closest { distance: best2.sqrt(), point: q, triangle: t, feature: f })
    }

    /// [`closest`](Self::closest) for many points `(M, 3)` (row-major), in parallel. Points are
    /// taken in blocks in their given order and each query starts from the previous point's
    /// triangle ([`closest_from`](Self::closest_from)): for grid nodes in C order, consecutive
    /// points are neighbours and the bound prunes most of the tree.
    pub fn closest_many(&self, points: &[f64], max_distance: f64) -> Vec<Option<Closest>> {
        const BLOCK: usize = 2048;
        let blocks: Vec<Vec<Option<Closest>>> = points
            .par_chunks(3 * BLOCK)
            .map(|block| {
                let mut stack = Vec::with_capacity(64);
                let mut hint = None;
                block
                    .chunks_exact(3)
                    .map(|c| {
                        let r = self.closest_from([c[0], c[1], c[2]], max_distance, hint, &mut stack);
                        if let Some(ref a) = r {
                            hint = Some(a.triangle);
                        }
                        r
                    })
                    .collect()
            })
            .collect();
        blocks.concat()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p: V3, tris: &[[V3; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let (q, _) = closest_point_on_triangle(p, t[0], t[1], t[2]);
                let d = sub(p, q);
                dot(d, d).sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn lcg(state: &mut u64) -> f64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*state >> 11) as f64) / ((1u64 << 53) as f64)
    }

    fn close(p: V3, q: V3) -> bool {
        (0..3).all(|k| (p[k] - q[k]).abs() < 1e-15)
    }

    #[test]
    fn regions_of_one_triangle() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let (q, f) = closest_point_on_triangle([0.2, 0.2, 1.0], a, b, c);
        assert!(close(q, [0.2, 0.2, 0.0]) && f == Feature::Face);
        assert_eq!(closest_point_on_triangle([-1.0, -1.0, 0.5], a, b, c).1, Feature::VertexA);
        assert_eq!(closest_point_on_triangle([2.0, -0.1, 0.0], a, b, c).1, Feature::VertexB);
        assert_eq!(closest_point_on_triangle([-0.1, 3.0, 0.0], a, b, c).1, Feature::VertexC);
        assert_eq!(closest_point_on_triangle([0.5, -1.0, 0.0], a, b, c), ([0.5, 0.0, 0.0], Feature::EdgeAB));
        assert_eq!(closest_point_on_triangle([-1.0, 0.5, 0.0], a, b, c), ([0.0, 0.5, 0.0], Feature::EdgeAC));
        let (q, f) = closest_point_on_triangle([1.0, 1.0, 0.0], a, b, c);
        assert_eq!(f, Feature::EdgeBC);
        assert!(close(q, [0.5, 0.5, 0.0]));
    }

    #[test]
    fn warm_started_batches_give_the_answers_of_single_queries() {
        // a small closed mesh (octahedron) and a line of nearby points, as grid nodes come
        let v: [V3; 6] = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        let f = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        let tris: Vec<[V3; 3]> = f.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect();
        let tree = TriangleTree::new(tris);
        let mut state = 7u64;
        let mut pts = Vec::new();
        for i in 0..5000 {
            let t = i as f64 / 5000.0;
            pts.extend_from_slice(&[1.5 * (6.0 * t).cos(), 1.5 * (6.0 * t).sin(), 2.0 * t - 1.0 + 0.01 * lcg(&mut state)]);
            // exact ties too: points on the axes are equidistant from several faces
            if i % 97 == 0 {
                pts.extend_from_slice(&[0.0, 0.0, 3.0 * lcg(&mut state) - 1.5]);
            }
        }
        for max_d in [f64::INFINITY, 0.9] {
            let batch = tree.closest_many(&pts, max_d);
            for (i, c) in pts.chunks_exact(3).enumerate() {
                assert_eq!(batch[i], tree.closest([c[0], c[1], c[2]], max_d), "point {i}");
            }
        }
    }

    #[test]
    fn tree_matches_brute_force() {
        let mut s = 7u64;
        let tris: Vec<[V3; 3]> = (0..500)
            .map(|_| {
                let base = [lcg(&mut s), lcg(&mut s), lcg(&mut s)];
                let mut t = [base; 3];
                for v in t.iter_mut().skip(1) {
                    for k in 0..3 {
                        v[k] += 0.1 * (lcg(&mut s) - 0.5);
                    }
                }
                t
            })
            .collect();
        let tree = TriangleTree::new(tris.clone());
        let pts: Vec<f64> = (0..600).map(|_| 1.4 * lcg(&mut s) - 0.2).collect();
        let got = tree.closest_many(&pts, f64::INFINITY);
        for (c, g) in pts.chunks_exact(3).zip(got) {
            let g = g.unwrap();
            let want = brute([c[0], c[1], c[2]], &tris);
            assert!((g.distance - want).abs() < 1e-12, "{} vs {}", g.distance, want);
            let t = tris[g.triangle];
            let (q, _) = closest_point_on_triangle([c[0], c[1], c[2]], t[0], t[1], t[2]);
            assert_eq!(q, g.point);
        }
        // a search radius below the true distance finds nothing
        assert!(tree.closest([5.0, 5.0, 5.0], 0.5).is_none());
    }
}
