//! Union–find whose roots are the smallest members of their sets, so that a set's label does not
//! depend on the order in which its members were joined: the inner tube's connected components
//! (`second_order::warm::component_labels`) and a mesh's connected parts
//! (`surface::mesh_parts::vertex_parts`). Path halving; O(α) per operation.

/// Disjoint sets of `0..n`, each rooted at its smallest member.
pub(crate) struct SmallestRoot {
    parent: Vec<u32>,
}

impl SmallestRoot {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Self {
        SmallestRoot {
            parent: (0..n as u32).collect(),
        }
    }

    /// The smallest member of `i`'s set.
    pub(crate) fn root(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let up = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = up;
            i = up;
        }
        i
    }

    /// Joins the sets of `a` and `b`: the larger root goes under the smaller.
    pub(crate) fn join(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_is_rooted_at_its_smallest_member_whatever_the_order_of_the_joins() {
        let mut sets = SmallestRoot::new(6);
        sets.join(5, 3);
        sets.join(3, 4);
        sets.join(4, 1);
        assert_eq!((0..6).map(|i| sets.root(i)).collect::<Vec<_>>(), vec![0, 1, 2, 1, 1, 1]);
    }
}
