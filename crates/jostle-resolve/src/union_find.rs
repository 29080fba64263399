//! Union-find over dense body indices, shared by the resolvers' island searches (the
//! Millington resolver's islands and the soft step's direct islands).

/// Disjoint sets of `0..n` with path halving; the root of a set is always its smallest index,
/// so the sets and their roots are deterministic whatever the order of the unions.
#[derive(Clone, Debug, Default)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// Makes `n` singleton sets, reusing the storage.
    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    /// The root (smallest index) of `x`'s set.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Joins the sets of `a` and `b`; the lower root becomes the root.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi as usize] = lo;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_are_the_smallest_members() {
        let mut sets = UnionFind::default();
        sets.reset(6);
        sets.union(4, 2);
        sets.union(5, 4);
        sets.union(3, 1);
        assert_eq!([2, 2, 2].map(|x| sets.find(x)), [2, 2, 2]);
        assert_eq!(sets.find(5), 2);
        assert_eq!(sets.find(3), 1);
        assert_eq!(sets.find(0), 0);
    }
}
