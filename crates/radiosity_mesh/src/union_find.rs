//! Disjoint sets, shared by the grouping of model faces and the finding of solids.

/// Disjoint sets over face numbers, to group triangles into surfaces and faces into solids.
pub(crate) struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` sets of one each.
    pub(crate) fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }

    /// The root of `x`'s set: its smallest member.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            // Path halving keeps the trees flat without recursion.
            self.0[x as usize] = self.0[self.0[x as usize] as usize];
            x = self.0[x as usize];
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The smaller root wins, so a group's root is its first triangle: deterministic order.
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}
