//! The *outer rim* of the extension layer ([`crate::SolveOptions::defer_outer_rim`]): the layer
//! nodes that no inner-tube node depends on, found once per solve, and their values extended from
//! the converged rest of the band in one pass.
//!
//! A layer node is *needed* if it is a neighbour of an inner node (the Godunov and
//! Lax–Friedrichs updates read every neighbour) or a layer node that a needed layer node reads
//! in its update (5); the rest is the rim. Nothing outside the rim reads a rim node, so the rest
//! of the band converges with the rim held still, and only then are the rim's values set.
//!
//! Every rim node holds the convex combination (5) of its upwind neighbours, and those lie
//! outside the rim (converged) or are rim nodes nearer the surface. So the rim is evaluated
//! once, in dependency order (Kahn's algorithm: a rim node after the rim nodes it reads), which
//! gives exactly the fixed point that sweeping the rim alone converges to. Rim nodes that read
//! each other in a cycle (an upwind 2-cycle, where the directions from two sheets of the surface
//! meet) have no such order, nor have the rim nodes downwind of them; those few are evaluated
//! in passes, each in an order that is the dependency order except where a cycle closes, until
//! the nodes where the cycles close are within the tolerance of their fixed point.

use super::problem::NodeRole;
use crate::band::NarrowBand;
use crate::scheme::extension::extension_apply_upwind;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU8, Ordering};

/// The upwind neighbour that the update (5) of a layer node with weights `w` reads along each
/// axis: `Some(band position)` for `w_k ≠ 0` (a neighbour in the band: the weights of absent
/// neighbours are 0), `None` otherwise. A node without upwind neighbour (NaN weights) reads
/// nothing.
#[inline(always)]
fn upwind_reads<const D: usize>(w: [f32; D], nb: &[[u32; 2]; D]) -> [Option<u32>; D] {
    let mut out = [None; D];
    for k in 0..D {
        if w[k] > 0.0 {
            out[k] = Some(nb[k][0]);
        } else if w[k] < 0.0 {
            out[k] = Some(nb[k][1]);
        }
    }
    out
}

/// The rim: `true` for the [`NodeRole::Outer`] nodes that no inner node depends on (see the
/// module notes). `weights` are the upwind weights of Eq. (5)
/// ([`crate::sweep::extension_weights_in_place`]), one per node.
pub fn outer_rim<const D: usize>(band: &NarrowBand<D>, roles: &[NodeRole], weights: &[[f32; D]]) -> Vec<bool> {
    let sentinel = band.sentinel();
    let is_outer = |q: u32| q != sentinel && roles[q as usize] == NodeRole::Outer;
    // the layer nodes next to an inner node (neighbours are mutual: a node asks its own)
    let mut needed: Vec<bool> = (0..roles.len())
        .into_par_iter()
        .map(|q| {
            roles[q] == NodeRole::Outer
                && band
                    .neighbours_of(q)
                    .iter()
                    .flatten()
                    .any(|&m| m != sentinel && roles[m as usize] == NodeRole::Inner)
        })
        .collect();
    // the layer nodes that those read and that are not next to an inner node themselves (few:
    // upwind is towards the surface), then whatever those read, and so on
    let mut stack: Vec<u32> = (0..roles.len())
        .into_par_iter()
        .filter(|&q| needed[q])
        .flat_map_iter(|q| upwind_reads(weights[q], &band.neighbours_of(q)).into_iter().flatten())
        .filter(|&m| is_outer(m) && !needed[m as usize])
        .collect();
    while let Some(q) = stack.pop() {
        if std::mem::replace(&mut needed[q as usize], true) {
            continue;
        }
        for m in upwind_reads(weights[q as usize], &band.neighbours_of(q as usize))
            .into_iter()
            .flatten()
        {
            if is_outer(m) && !needed[m as usize] {
                stack.push(m);
            }
        }
    }
    roles
        .par_iter()
        .zip(needed.par_iter())
        .map(|(&r, &nd)| r == NodeRole::Outer && !nd)
        .collect()
}

/// The `cyclic` rim nodes (sorted) in an order that puts every node after the nodes it reads,
/// except where a cycle closes: the postorder of a depth-first search along the reads.
fn reads_first_order<const D: usize>(band: &NarrowBand<D>, weights: &[[f32; D]], cyclic: &[u32]) -> Vec<u32> {
    let local = |m: u32| cyclic.binary_search(&m).ok();
    let reads = |i: usize| upwind_reads(weights[cyclic[i] as usize], &band.neighbours_of(cyclic[i] as usize));
    let mut seen = vec![false; cyclic.len()];
    let mut order = Vec::with_capacity(cyclic.len());
    // (node, the next axis of its reads to follow)
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for start in 0..cyclic.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push((start, 0));
        while let Some(&(i, axis)) = stack.last() {
            let next = (axis..D).find_map(|k| reads(i)[k].and_then(local).filter(|&j| !seen[j]).map(|j| (k, j)));
            match next {
                Some((k, j)) => {
                    stack.last_mut().expect("not empty").1 = k + 1;
                    seen[j] = true;
                    stack.push((j, 0));
                }
                None => {
                    order.push(cyclic[i]);
                    stack.pop();
                }
            }
        }
    }
    order
}

/// What [`extend_into_rim`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RimPasses {
    /// Passes: the one in dependency order, then those over the cyclic part (see
    /// [`extend_into_rim`]).
    pub passes: usize,
    /// Local updates (evaluations of Eq. (5)).
    pub updates: u64,
    /// The largest change in the first pass (from the numerical infinity the rim starts at).
    pub first_change: f64,
    /// How far another pass would move a value: 0 when the rim has no cycles.
    pub last_change: f64,
    /// Whether the cyclic part (if any) came within the tolerance.
    pub converged: bool,
}

/// Roots per parallel task of the pass in dependency order.
const ROOTS_PER_TASK: usize = 1024;

/// The values, written by the threads of the pass in dependency order (each node by one).
struct SharedValues(*mut f64);
// SAFETY: the pass in dependency order writes each node from one thread and orders every read
// after that write (see `extend_into_rim`)
unsafe impl Sync for SharedValues {}

/// How many root nodes ahead their weights and neighbour entries are prefetched.
const PREFETCH_AHEAD: usize = 16;

/// Sets the rim's values (`rim` from [`outer_rim`]) from the rest of the band, which must hold
/// its converged values; `u` has the band's length plus the sentinel slot (the numerical
/// infinity), and the rim nodes hold the numerical infinity on entry.
///
/// The rim nodes that can be put in dependency order are evaluated once, in the first pass. The
/// rest (cycles and what lies downwind of them) is then evaluated in passes, each in the
/// postorder of a depth-first search along the reads, so that only the nodes where a cycle
/// closes read a value set later in the pass; after each pass those are evaluated again (without
/// writing), and the passes stop once none would move by more than `tol`, or when `max_passes`
/// passes in all have run (at least the first).
pub fn extend_into_rim<const D: usize>(
    band: &NarrowBand<D>,
    rim: &[bool],
    weights: &[[f32; D]],
    u: &mut [f64],
    tol: f64,
    max_passes: usize,
) -> RimPasses {
    let n = band.len();
    let sentinel = band.sentinel();
    let is_rim = |q: u32| q != sentinel && rim[q as usize];
    // per rim node: in bits 0–1, how many rim nodes it reads that are not evaluated yet (at
    // most one per axis); in bit 2 + 2k + side, whether its neighbour `nb[k][side]` is a rim node
    // that reads it (the plus neighbour along k reads its minus neighbour when its weight
    // w_k > 0, the minus neighbour its plus neighbour when w_k < 0)
    let pending: Vec<AtomicU8> = (0..n)
        .into_par_iter()
        .map(|q| {
            if !rim[q] {
                return AtomicU8::new(0);
            }
            let nb = band.neighbours_of(q);
            let reads = upwind_reads(weights[q], &nb)
                .into_iter()
                .flatten()
                .filter(|&m| is_rim(m))
                .count() as u8;
            let mut read_by = 0u8;
            for k in 0..D {
                for (side, &p) in nb[k].iter().enumerate() {
                    if is_rim(p) {
                        let wp = weights[p as usize][k];
                        if (side == 1 && wp > 0.0) || (side == 0 && wp < 0.0) {
                            read_by |= 1 << (2 * k + side);
                        }
                    }
                }
            }
            AtomicU8::new(reads | read_by << 2)
        })
        .collect();
    // the rim nodes that read no rim node, in band order; each is followed at once by the rim
    // nodes it completes (depth first: they are its neighbours, so their data is still in cache)
    let roots: Vec<u32> = (0..n as u32)
        .into_par_iter()
        .filter(|&q| rim[q as usize] && pending[q as usize].load(Ordering::Relaxed) & 3 == 0)
        .collect();
    // Eq. (5) at rim node q from the current values (a node without upwind neighbour keeps its
    // value)
    let candidate = |q: usize, value: &dyn Fn(usize) -> f64| -> f64 {
        let w = weights[q];
        if w[0].is_nan() {
            return value(q);
        }
        extension_apply_upwind(w, &band.neighbours_of(q), |i| value(i as usize))
    };
    // Runs of roots go to the threads. A node is evaluated by the one thread that takes its
    // count to zero (or as a root), after every rim node it reads was evaluated: that thread's
    // decrement (acquire) follows the others' (release), which follow their writes. So every
    // value is set once, from final values, whatever the threads' timing: the same bits.
    let shared = SharedValues(u.as_mut_ptr());
    let (updates, first_change) = roots
        .par_chunks(ROOTS_PER_TASK)
        .map(|chunk| {
            let shared = &shared;
            // SAFETY: see above: a value is read only after its one write, ordered by `pending`
            let value = |i: usize| unsafe { *shared.0.add(i) };
            let mut stack = Vec::new();
            let (mut updates, mut first_change) = (0u64, 0.0f64);
            for (j, &root) in chunk.iter().enumerate() {
                if let Some(&ahead) = chunk.get(j + PREFETCH_AHEAD) {
                    crate::prefetch::prefetch(&weights[ahead as usize]);
                    band.prefetch_neighbours(ahead as usize);
                }
                stack.push(root);
                while let Some(q) = stack.pop() {
                    let q = q as usize;
                    let v = candidate(q, &value);
                    updates += 1;
                    first_change = first_change.max((value(q) - v).abs());
                    // SAFETY: only this thread writes q (see above)
                    unsafe { *shared.0.add(q) = v };
                    let nb = band.neighbours_of(q);
                    let read_by = pending[q].load(Ordering::Relaxed) >> 2;
                    for k in 0..D {
                        for side in 0..2 {
                            if read_by >> (2 * k + side) & 1 == 1 {
                                let p = nb[k][side];
                                if pending[p as usize].fetch_sub(1, Ordering::AcqRel) & 3 == 1 {
                                    stack.push(p);
                                }
                            }
                        }
                    }
                }
            }
            (updates, first_change)
        })
        .reduce(|| (0, 0.0), |a, b| (a.0 + b.0, a.1.max(b.1)));
    let mut stats = RimPasses {
        passes: 1,
        converged: true,
        updates,
        first_change,
        ..Default::default()
    };
    // the cycles and what lies downwind of them: still waiting for a rim node they read
    let cyclic: Vec<u32> = (0..n as u32)
        .into_par_iter()
        .filter(|&q| rim[q as usize] && pending[q as usize].load(Ordering::Relaxed) & 3 != 0)
        .collect();
    if cyclic.is_empty() {
        return stats;
    }
    stats.converged = false;
    let order = reads_first_order(band, weights, &cyclic);
    // the nodes that read a node after them in the order (where a cycle closes): only they can
    // be left off their fixed point by a pass, since every other node reads values set before
    // it in the same pass
    let local = |m: u32| cyclic.binary_search(&m).ok();
    let mut position = vec![0u32; cyclic.len()];
    for (i, &q) in order.iter().enumerate() {
        position[local(q).expect("the order holds the cyclic nodes")] = i as u32;
    }
    let closing: Vec<u32> = order
        .iter()
        .enumerate()
        .filter(|&(i, &q)| {
            upwind_reads(weights[q as usize], &band.neighbours_of(q as usize))
                .into_iter()
                .flatten()
                .filter_map(local)
                .any(|j| position[j] as usize > i)
        })
        .map(|(_, &q)| q)
        .collect();
    drop(position);
    while stats.passes < max_passes {
        for &q in &order {
            u[q as usize] = candidate(q as usize, &|i| u[i]);
        }
        // how far another pass would move the nodes where cycles close (evaluated, not written)
        let residual = closing
            .iter()
            .map(|&q| (candidate(q as usize, &|i| u[i]) - u[q as usize]).abs())
            .fold(0.0f64, f64::max);
        stats.passes += 1;
        stats.updates += (order.len() + closing.len()) as u64;
        stats.last_change = residual;
        if residual <= tol {
            stats.converged = true;
            break;
        }
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of `len` nodes (the middle row of a 3 × `len` grid): band positions 0 .. len.
    fn row(len: usize) -> NarrowBand<2> {
        let lin: Vec<u64> = (len..2 * len).map(|i| i as u64).collect();
        NarrowBand::<2>::from_sorted_linear([3, len], &lin).unwrap()
    }

    #[test]
    fn a_chain_of_rim_nodes_is_evaluated_in_one_pass_in_dependency_order() {
        let band = row(6);
        let inf = 9.0;
        // node 0 fixed, each layer node reading its minus neighbour: the chain runs upwards
        let mut roles = [NodeRole::Outer; 6];
        roles[0] = NodeRole::Fixed;
        let mut weights = vec![[0.0f32, 1.0]; 6];
        weights[0] = [0.0, 0.0];
        let rim: Vec<bool> = roles.iter().map(|&r| r == NodeRole::Outer).collect();
        let mut u = vec![1.5, inf, inf, inf, inf, inf, inf]; // and the sentinel slot
        let st = extend_into_rim(&band, &rim, &weights, &mut u, 0.0, 10);
        assert_eq!(u[..6], [1.5; 6]);
        assert_eq!(
            (st.passes, st.updates, st.first_change, st.last_change, st.converged),
            (1, 5, inf - 1.5, 0.0, true)
        );
        // the other way: node 5 fixed, every layer node reading its plus neighbour
        let mut roles = [NodeRole::Outer; 6];
        roles[5] = NodeRole::Fixed;
        let mut weights = vec![[0.0f32, -1.0]; 6];
        weights[5] = [0.0, 0.0];
        let rim: Vec<bool> = roles.iter().map(|&r| r == NodeRole::Outer).collect();
        let mut u = vec![inf, inf, inf, inf, inf, 0.25, inf];
        let st = extend_into_rim(&band, &rim, &weights, &mut u, 0.0, 10);
        assert_eq!(u[..6], [0.25; 6]);
        assert_eq!((st.passes, st.updates), (1, 5));
    }

    #[test]
    fn a_cycle_and_what_reads_it_are_swept_to_the_tolerance() {
        // two rows of four: layer nodes 1 and 2 read each other (weight 1/2 each, the other half
        // from the fixed nodes 5 and 6 below them), node 3 reads node 2. Fixed point:
        // u1 = (a + u2)/2, u2 = (b + u1)/2, so u1 = (2a + b)/3, u2 = (a + 2b)/3; u3 = u2.
        let band = NarrowBand::<2>::from_sorted_linear([3, 4], &(0..8).collect::<Vec<u64>>()).unwrap();
        let mut roles = [NodeRole::Fixed; 8];
        let mut weights = vec![[0.0f32, 0.0]; 8];
        for q in [1usize, 2, 3] {
            roles[q] = NodeRole::Outer;
        }
        weights[1] = [-0.5, -0.5]; // its plus neighbours: node 5 (fixed) and node 2
        weights[2] = [-0.5, 0.5]; // node 6 (fixed) and its minus neighbour, node 1
        weights[3] = [0.0, 1.0]; // node 2
        let (a, b, inf) = (3.0, 6.0, 100.0);
        let start = vec![0.0, inf, inf, inf, 0.0, a, b, 0.0, inf];
        let rim: Vec<bool> = roles.iter().map(|&r| r == NodeRole::Outer).collect();
        let tol = 1e-12;
        let mut u = start.clone();
        let st = extend_into_rim(&band, &rim, &weights, &mut u, tol, 1000);
        assert!(st.converged && st.passes > 10 && st.last_change <= tol, "{st:?}");
        assert!(
            (u[1] - (2.0 * a + b) / 3.0).abs() < 1e-10 && (u[2] - (a + 2.0 * b) / 3.0).abs() < 1e-10,
            "{u:?}"
        );
        assert_eq!(u[3], u[2]);
        // the first pass finds no node in order; each later pass evaluates the three nodes in the
        // order [2, 1, 3] (node 2 reads node 1, evaluated after it: the cycle closes at node 2)
        // and node 2 once more for the residual
        assert_eq!(st.updates, 4 * (st.passes as u64 - 1));
        // a budget of passes too small to converge says so
        let mut u = start.clone();
        let st = extend_into_rim(&band, &rim, &weights, &mut u, tol, 3);
        assert!(!st.converged && st.passes == 3 && st.last_change > tol, "{st:?}");
    }

    #[test]
    fn the_rim_is_the_layer_that_no_inner_node_depends_on() {
        // inner node 0, layer nodes 1 .. 5, each reading its minus neighbour: only node 1, next
        // to the inner node, is needed
        let band = row(6);
        let mut roles = [NodeRole::Outer; 6];
        roles[0] = NodeRole::Inner;
        let mut weights = vec![[0.0f32, 1.0]; 6];
        weights[0] = [0.0, 0.0];
        assert_eq!(
            outer_rim(&band, &roles, &weights),
            vec![false, false, true, true, true, true]
        );
        // node 1 reading its plus neighbour makes node 2 needed
        weights[1] = [0.0, -1.0];
        assert_eq!(
            outer_rim(&band, &roles, &weights),
            vec![false, false, false, true, true, true]
        );
        // and a chain: node 2 reads node 3, which reads node 4
        weights[2] = [0.0, -1.0];
        weights[3] = [0.0, -1.0];
        assert_eq!(
            outer_rim(&band, &roles, &weights),
            vec![false, false, false, false, false, true]
        );
    }
}
