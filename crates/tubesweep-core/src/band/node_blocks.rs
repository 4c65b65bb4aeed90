//! A pass over every node of a band in parallel blocks, each node adding what it finds to its
//! block's list, the lists joined in the nodes' order: the band's pair tests (facing sheets, their
//! *across* candidates, medial edges).

use rayon::prelude::*;

/// Nodes per parallel task.
const BLOCK: usize = 1 << 14;

/// `visit(a, out)` for every node `a` of `0..k_nodes`, in parallel blocks; what the visits push,
/// in the nodes' order.
pub(crate) fn per_node<T: Send>(k_nodes: usize, visit: impl Fn(usize, &mut Vec<T>) + Sync) -> Vec<T> {
    let parts: Vec<Vec<T>> = (0..k_nodes.div_ceil(BLOCK))
        .into_par_iter()
        .map(|blk| {
            let mut out = Vec::new();
            for a in blk * BLOCK..((blk + 1) * BLOCK).min(k_nodes) {
                visit(a, &mut out);
            }
            out
        })
        .collect();
    parts.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_visits_come_back_in_the_nodes_order_across_blocks() {
        let n = 3 * BLOCK + 5;
        let got = per_node(n, |a, out: &mut Vec<usize>| {
            if a % 7 == 0 {
                out.push(a);
            }
        });
        assert_eq!(got, (0..n).filter(|a| a % 7 == 0).collect::<Vec<_>>());
    }
}
