//! Disjoint sets of the indices `0..n`, the one union-find of the
//! workspace: connected parts of faces, of corners around vertices, of
//! cells into regions.

/// Disjoint sets of `0..n` (`n < 2^32`). A set's root is its smallest
/// member, so a set is named by its first element whatever the order of
/// the unions; `find` halves the path it walks.
///
/// ```
/// use bsp_core::internals::UnionFind;
/// let mut sets = UnionFind::new(5);
/// sets.union(3, 1);
/// sets.union(4, 3);
/// assert_eq!(sets.find(4), 1);
/// assert_eq!(sets.find(2), 2);
/// assert!(!sets.union(1, 4));
/// ```
#[derive(Clone, Debug)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The root (smallest member) of `x`'s set.
    #[inline]
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let up = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = up;
            x = up;
        }
        x
    }

    /// Joins the sets of `a` and `b`; `false` if they were one already.
    #[inline]
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        let (a, b) = (self.find(a), self.find(b));
        if a == b {
            return false;
        }
        self.parent[a.max(b) as usize] = a.min(b);
        true
    }

    /// `true` if `x` is the root of its set.
    #[inline]
    pub fn is_root(&self, x: u32) -> bool {
        self.parent[x as usize] == x
    }

    /// The number of elements.
    pub fn len(&self) -> usize {
        self.parent.len()
    }

    /// `true` if there are no elements.
    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// Each element's set numbered from 0 in the order of the sets' first
    /// elements, and the number of sets.
    pub fn numbered(&mut self) -> (Vec<u32>, usize) {
        let n = self.parent.len();
        let mut id = vec![u32::MAX; n];
        let mut count = 0u32;
        let out = (0..n as u32)
            .map(|i| {
                let r = self.find(i) as usize;
                if id[r] == u32::MAX {
                    id[r] = count;
                    count += 1;
                }
                id[r]
            })
            .collect();
        (out, count as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_are_the_smallest_members() {
        let mut u = UnionFind::new(8);
        for (a, b) in [(7, 5), (5, 6), (2, 4), (6, 4)] {
            assert!(u.union(a, b));
        }
        assert!(!u.union(7, 2));
        assert_eq!(
            (0..8).map(|x| u.find(x)).collect::<Vec<_>>(),
            [0, 1, 2, 3, 2, 2, 2, 2]
        );
        assert!(u.is_root(2) && !u.is_root(7));
        assert_eq!(u.numbered(), (vec![0, 1, 2, 3, 2, 2, 2, 2], 4));
    }
}
