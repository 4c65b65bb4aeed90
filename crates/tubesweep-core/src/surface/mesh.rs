//! Exact closest points on a triangle mesh with a bounding-volume hierarchy (AABB tree).
//!
//! A triangle mesh Σ enters the solver in the closest-point representation of the paper's
//! Sect. 5.2: at every band node `x` we need `cp(x) = argmin_{z∈Σ} |x − z|`, the distance
//! `|x − cp(x)|` (inner tube / extension layer) and the extension direction
//! `(x − cp(x)) / |x − cp(x)|` of Eq. (8). [`TriangleTree`] answers these queries exactly:
//! a binary tree of axis-aligned boxes over the triangles (split at the median centroid along
//! the longest axis, a few triangles per leaf), searched depth-first, nearer child first, and
//! pruned by the squared box distance against the best squared distance so far. An inner node
//! holds its two children's boxes (in `f32`, rounded outwards: one cache line per step), and a
//! leaf tests each triangle's own box before projecting onto it, which skips most projections
//! (a leaf's box is looser than its triangles'). The point–triangle projection is the
//! Voronoi-region test (vertices, edges, face). Queries of many points run in parallel (rayon).

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

/// `a − b` componentwise.
#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// `a · b`, summed in axis order.
#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
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

/// An inner node of the tree: the boxes of its two children side by side (one cache line), so
/// that a step of the search reads one node. The boxes are `f32`, rounded outwards, so they
/// still contain their triangles and their distances stay lower bounds.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    lo: [[f32; 3]; 2],
    hi: [[f32; 3]; 2],
    /// Per child, a reference to it (see [`ChildRef`]).
    child: [ChildRef; 2],
}

/// A subtree: an inner node's index in `nodes` (`count == 0`), or a leaf's first position in
/// `order` and its number of triangles.
#[derive(Clone, Copy, Debug)]
struct ChildRef {
    start: u32,
    count: u32,
}

/// Where the tree's build puts a subtree's reference: the root (`None`), or child `side` of
/// inner node `ni` (`Some((ni, side))`).
type Slot = Option<(usize, usize)>;

/// The largest `f32` at or below `x` (the box corners are rounded outwards).
fn f32_down(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) <= x || y.is_nan() {
        y
    } else if y == 0.0 {
        -f32::from_bits(1)
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() - 1)
    } else {
        f32::from_bits(y.to_bits() + 1)
    }
}

/// The smallest `f32` at or above `x`.
fn f32_up(x: f64) -> f32 {
    -f32_down(-x)
}

/// A box with `f32` corners that contains the `f64` box `[lo, hi]`.
fn outward(lo: V3, hi: V3) -> ([f32; 3], [f32; 3]) {
    (
        [f32_down(lo[0]), f32_down(lo[1]), f32_down(lo[2])],
        [f32_up(hi[0]), f32_up(hi[1]), f32_up(hi[2])],
    )
}

/// Squared distance from `p` to the box `[lo, hi]` (0 inside); branch-free, since whether a
/// coordinate lies below, inside or above the box is hard to predict.
#[inline]
fn box_dist2(p: V3, lo: [f32; 3], hi: [f32; 3]) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        // at most one of the two differences is positive
        let d = (lo[k] as f64 - p[k]).max(p[k] - hi[k] as f64).max(0.0);
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
    /// The triangles' indices, each leaf's contiguous.
    order: Vec<u32>,
    /// Per position in `order`: that triangle's own box, which a leaf tests before the exact
    /// projection (a leaf's box is looser than its triangles').
    boxes: Vec<([f32; 3], [f32; 3])>,
    nodes: Vec<Node>,
    /// The whole tree: its box and the reference to the root.
    root_box: ([f32; 3], [f32; 3]),
    root: ChildRef,
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
            .map(|t| {
                [
                    (t[0][0] + t[1][0] + t[2][0]) / 3.0,
                    (t[0][1] + t[1][1] + t[2][1]) / 3.0,
                    (t[0][2] + t[1][2] + t[2][2]) / 3.0,
                ]
            })
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes: Vec<Node> = Vec::with_capacity(n / LEAF_SIZE + 2);
        let blank = Node {
            lo: [[0.0; 3]; 2],
            hi: [[0.0; 3]; 2],
            child: [ChildRef { start: 0, count: 0 }; 2],
        };
        // iterative build: (the slot that refers to the subtree, start, end); a slot is a child
        // of an inner node, or None for the root
        let mut root = ChildRef { start: 0, count: 0 };
        let mut root_box = ([0.0f32; 3], [0.0f32; 3]);
        let mut stack: Vec<(Slot, usize, usize)> = vec![(None, 0, n)];
        while let Some((slot, s, e)) = stack.pop() {
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
            let reference = if e - s <= LEAF_SIZE {
                ChildRef {
                    start: s as u32,
                    count: (e - s) as u32,
                }
            } else {
                let ext = sub(chi, clo);
                let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
                    0
                } else if ext[1] >= ext[2] {
                    1
                } else {
                    2
                };
                let mid = (s + e) / 2;
                order[s..e].select_nth_unstable_by(mid - s, |&x, &y| {
                    cent[x as usize][axis].total_cmp(&cent[y as usize][axis])
                });
                let ni = nodes.len();
                nodes.push(blank);
                stack.push((Some((ni, 0)), s, mid));
                stack.push((Some((ni, 1)), mid, e));
                ChildRef {
                    start: ni as u32,
                    count: 0,
                }
            };
            let (blo, bhi) = outward(lo, hi);
            match slot {
                None => {
                    root = reference;
                    root_box = (blo, bhi);
                }
                Some((ni, side)) => {
                    nodes[ni].child[side] = reference;
                    nodes[ni].lo[side] = blo;
                    nodes[ni].hi[side] = bhi;
                }
            }
        }
        let boxes = order
            .iter()
            .map(|&t| {
                let tr = &triangles[t as usize];
                let mut lo = tr[0];
                let mut hi = tr[0];
                for v in &tr[1..] {
                    for k in 0..3 {
                        lo[k] = lo[k].min(v[k]);
                        hi[k] = hi[k].max(v[k]);
                    }
                }
                outward(lo, hi)
            })
            .collect();
        TriangleTree {
            tris: triangles,
            order,
            boxes,
            nodes,
            root_box,
            root,
        }
    }

    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Bytes held by the tree.
    pub fn heap_bytes(&self) -> usize {
        self.tris.len() * std::mem::size_of::<[V3; 3]>()
            + self.order.len() * 4
            + self.boxes.len() * std::mem::size_of::<([f32; 3], [f32; 3])>()
            + self.nodes.len() * std::mem::size_of::<Node>()
    }

    /// Squared distance from `p` to the root box (a cheap lower bound).
    pub fn box_distance(&self, p: V3) -> f64 {
        box_dist2(p, self.root_box.0, self.root_box.1).sqrt()
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
    fn closest_from(
        &self,
        p: V3,
        max_distance: f64,
        hint: Option<usize>,
        stack: &mut Vec<(ChildRef, f64)>,
    ) -> Option<Closest> {
        let mut best2 = if max_distance.is_finite() {
            max_distance * max_distance
        } else {
            f64::INFINITY
        };
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
        let root_d = box_dist2(p, self.root_box.0, self.root_box.1);
        if root_d <= best2 {
            stack.push((self.root, root_d));
        }
        while let Some((node, d2)) = stack.pop() {
            if d2 > best2 {
                continue;
            }
            if node.count > 0 {
                let (a, b) = (node.start as usize, (node.start + node.count) as usize);
                for (&t, bx) in self.order[a..b].iter().zip(&self.boxes[a..b]) {
                    // the triangle's own box first: it bounds the distance from below
                    if box_dist2(p, bx.0, bx.1) > best2 {
                        continue;
                    }
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
                self.push_children(p, node, best2, stack);
            }
        }
        best.map(|(q, t, f)| Closest {
            distance: best2.sqrt(),
            point: q,
            triangle: t,
            feature: f,
        })
    }

    /// Pushes the children of inner node `node` whose boxes lie within `bound2` (squared) of
    /// `p`, with their box distances: the farther first, so that the nearer one is searched first.
    #[inline]
    fn push_children(&self, p: V3, node: ChildRef, bound2: f64, stack: &mut Vec<(ChildRef, f64)>) {
        let n = &self.nodes[node.start as usize];
        let dl = box_dist2(p, n.lo[0], n.hi[0]);
        let dr = box_dist2(p, n.lo[1], n.hi[1]);
        let (near, far) = if dl <= dr {
            ((n.child[0], dl), (n.child[1], dr))
        } else {
            ((n.child[1], dr), (n.child[0], dl))
        };
        if far.1 <= bound2 {
            stack.push(far);
        }
        if near.1 <= bound2 {
            stack.push(near);
        }
    }

    /// Whether some triangle lies within `threshold` of `p`: the answer of
    /// `closest(p, ∞).distance <= threshold` (the same distances, so the same answer) without
    /// finding the closest triangle. The search starts from triangle `hint` and stops at the
    /// first triangle within the threshold, which it returns. This is what the coarse-to-fine
    /// band search asks of a block's centre, where the threshold (the band's half-width and the
    /// block's radius) is wide and the closest triangle would take many projections to pin
    /// down.
    fn any_within(
        &self,
        p: V3,
        threshold: f64,
        hint: Option<usize>,
        stack: &mut Vec<(ChildRef, f64)>,
    ) -> Option<usize> {
        if !(threshold >= 0.0) {
            return None;
        }
        let within = |t: usize| {
            let tri = &self.tris[t];
            let dd = sub(p, closest_point_on_triangle(p, tri[0], tri[1], tri[2]).0);
            dot(dd, dd).sqrt() <= threshold
        };
        if let Some(t) = hint {
            if within(t) {
                return Some(t);
            }
        }
        // boxes are pruned against a hair more than threshold², so that rounding never prunes a
        // box whose triangle passes the test above
        let reach2 = threshold * threshold * (1.0 + 1e-9);
        stack.clear();
        let root_d = box_dist2(p, self.root_box.0, self.root_box.1);
        if root_d <= reach2 {
            stack.push((self.root, root_d));
        }
        while let Some((node, _)) = stack.pop() {
            if node.count > 0 {
                let (a, b) = (node.start as usize, (node.start + node.count) as usize);
                for (&t, bx) in self.order[a..b].iter().zip(&self.boxes[a..b]) {
                    if box_dist2(p, bx.0, bx.1) <= reach2 && within(t as usize) {
                        return Some(t as usize);
                    }
                }
            } else {
                self.push_children(p, node, reach2, stack);
            }
        }
        None
    }

    /// [`any_within`](Self::any_within) for many points `(M, 3)` (row-major) with a threshold
    /// each, in parallel; each query starts from the triangle the previous point found.
    pub fn any_within_many(&self, points: &[f64], thresholds: &[f64]) -> Vec<bool> {
        const BLOCK: usize = 2048;
        assert_eq!(points.len(), 3 * thresholds.len(), "one threshold per point");
        let blocks: Vec<Vec<bool>> = points
            .par_chunks(3 * BLOCK)
            .zip(thresholds.par_chunks(BLOCK))
            .map(|(block, limits)| {
                let mut stack = Vec::with_capacity(64);
                let mut hint = None;
                block
                    .chunks_exact(3)
                    .zip(limits)
                    .map(|(c, &t)| {
                        let found = self.any_within([c[0], c[1], c[2]], t, hint, &mut stack);
                        hint = found.or(hint);
                        found.is_some()
                    })
                    .collect()
            })
            .collect();
        blocks.concat()
    }

    /// [`closest`](Self::closest) for many points `(M, 3)` (row-major), in parallel. Points are
    /// taken in blocks in their given order and each query starts from the previous point's
    /// triangle ([`closest_from`](Self::closest_from)): for grid nodes in C order, consecutive
    /// points are neighbours and the bound prunes most of the tree.
    pub fn closest_many(&self, points: &[f64], max_distance: f64) -> Vec<Option<Closest>> {
        let blocks: Vec<Vec<Option<Closest>>> = points
            .par_chunks(3 * QUERY_BLOCK)
            .map(|block| {
                let mut search = ClosestSearch::new(self);
                block
                    .chunks_exact(3)
                    .map(|c| search.closest([c[0], c[1], c[2]], max_distance))
                    .collect()
            })
            .collect();
        blocks.concat()
    }
}

/// Points per parallel task of the batched queries.
pub const QUERY_BLOCK: usize = 2048;

/// A sequence of closest-point queries on one tree, each starting from the triangle the previous
/// one found ([`TriangleTree::closest`] with that triangle's distance as the first bound): for
/// points that follow each other in space, such as grid nodes in C order. The answers are those of
/// single queries.
pub struct ClosestSearch<'a> {
    tree: &'a TriangleTree,
    stack: Vec<(ChildRef, f64)>,
    hint: Option<usize>,
}

impl<'a> ClosestSearch<'a> {
    pub fn new(tree: &'a TriangleTree) -> Self {
        ClosestSearch {
            tree,
            stack: Vec::with_capacity(64),
            hint: None,
        }
    }

    /// The closest point on the mesh to `p` within `max_distance` (see [`TriangleTree::closest`]).
    pub fn closest(&mut self, p: V3, max_distance: f64) -> Option<Closest> {
        let r = self.tree.closest_from(p, max_distance, self.hint, &mut self.stack);
        if let Some(ref a) = r {
            self.hint = Some(a.triangle);
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_random::next_uniform as lcg;

    fn brute(p: V3, tris: &[[V3; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let (q, _) = closest_point_on_triangle(p, t[0], t[1], t[2]);
                let d = sub(p, q);
                dot(d, d).sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn close(p: V3, q: V3) -> bool {
        (0..3).all(|k| (p[k] - q[k]).abs() < 1e-15)
    }

    #[test]
    fn regions_of_one_triangle() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let (q, f) = closest_point_on_triangle([0.2, 0.2, 1.0], a, b, c);
        assert!(close(q, [0.2, 0.2, 0.0]) && f == Feature::Face);
        assert_eq!(
            closest_point_on_triangle([-1.0, -1.0, 0.5], a, b, c).1,
            Feature::VertexA
        );
        assert_eq!(closest_point_on_triangle([2.0, -0.1, 0.0], a, b, c).1, Feature::VertexB);
        assert_eq!(closest_point_on_triangle([-0.1, 3.0, 0.0], a, b, c).1, Feature::VertexC);
        assert_eq!(
            closest_point_on_triangle([0.5, -1.0, 0.0], a, b, c),
            ([0.5, 0.0, 0.0], Feature::EdgeAB)
        );
        assert_eq!(
            closest_point_on_triangle([-1.0, 0.5, 0.0], a, b, c),
            ([0.0, 0.5, 0.0], Feature::EdgeAC)
        );
        let (q, f) = closest_point_on_triangle([1.0, 1.0, 0.0], a, b, c);
        assert_eq!(f, Feature::EdgeBC);
        assert!(close(q, [0.5, 0.5, 0.0]));
    }

    #[test]
    fn warm_started_batches_give_the_answers_of_single_queries() {
        // a small closed mesh (octahedron) and a line of nearby points, as grid nodes come
        let v: [V3; 6] = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let f = [
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let tris: Vec<[V3; 3]> = f.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect();
        let tree = TriangleTree::new(tris);
        let mut state = 7u64;
        let mut pts = Vec::new();
        for i in 0..5000 {
            let t = i as f64 / 5000.0;
            pts.extend_from_slice(&[
                1.5 * (6.0 * t).cos(),
                1.5 * (6.0 * t).sin(),
                2.0 * t - 1.0 + 0.01 * lcg(&mut state),
            ]);
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
    fn any_within_answers_as_the_closest_distance_does() {
        // the octahedron again, points around it, thresholds around their distances (exact ties
        // included: the threshold equal to the distance)
        let v: [V3; 6] = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let f = [
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let tree = TriangleTree::new(f.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect());
        let mut state = 5u64;
        let (mut pts, mut limits) = (Vec::new(), Vec::new());
        for _ in 0..4000 {
            let p = [
                3.0 * lcg(&mut state) - 1.5,
                3.0 * lcg(&mut state) - 1.5,
                3.0 * lcg(&mut state) - 1.5,
            ];
            let d = tree.closest(p, f64::INFINITY).unwrap().distance;
            for t in [d, d * (1.0 - 1e-12), d * 0.5, d * 2.0 + 0.1, 0.0, -1.0] {
                pts.extend_from_slice(&p);
                limits.push(t);
            }
        }
        let got = tree.any_within_many(&pts, &limits);
        for (i, c) in pts.chunks_exact(3).enumerate() {
            let d = tree.closest([c[0], c[1], c[2]], f64::INFINITY).unwrap().distance;
            assert_eq!(
                got[i],
                d <= limits[i],
                "point {i}: distance {d}, threshold {}",
                limits[i]
            );
        }
        assert!(got.iter().any(|&b| b) && got.iter().any(|&b| !b));
    }

    #[test]
    fn box_corners_round_outwards_to_f32() {
        let mut s = 11u64;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            -0.1,
            1e-40,
            -1e-40,
            3.4e38,
            -3.4e38,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
        ];
        values.extend((0..10_000).map(|i| (lcg(&mut s) - 0.5) * 10f64.powi(i % 9 - 4)));
        for x in values {
            let (d, u) = (f32_down(x), f32_up(x));
            assert!((d as f64) <= x && (u as f64) >= x, "{x}: {d} {u}");
            // and tightly: the next f32 above d lies above x
            if d.is_finite() && d != 0.0 {
                let next = f32::from_bits(if d > 0.0 { d.to_bits() + 1 } else { d.to_bits() - 1 });
                assert!(next as f64 > x, "{x}: {d}, {next}");
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
