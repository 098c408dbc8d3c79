//! The working column of the cohomology reduction: a monotone radix heap.
//!
//! During the reduction of one column the pivot only moves forward (adding a column with
//! pivot `p` cancels `p` and adds entries that all come after it), so the column is a
//! *monotone* priority queue and a radix heap (Ahuja, Mehlhorn, Orlin & Tarjan, 1990)
//! applies: entries are binned by the highest bit in which their key differs from the
//! last minimum, pushes are `O(1)` appends, and a pop only redistributes one bin. For the
//! long columns of big holes (millions of entries, most of them cancelling in pairs) this
//! beats a binary heap, whose sift-downs miss the cache at every level.
//!
//! The key is the whole filtration order, not the value alone: the value's bits, then the
//! triangle's vertices (the tie-break), so that equal keys are equal triangles. The many
//! cofacets that share a value (every cofacet `{a, b, k}` whose longest edge is `{a, b}`
//! has that edge's value) are ordered by the radix bins too; keyed by value alone they
//! queued in a binary heap that took 38 % of a long reduction's time (docs/accuracy.md,
//! step 35). The key holds the triangle itself, so the column stores 16-byte keys.
//!
//! Monotone only up to cancellation: the engine keeps reduction-matrix columns (edges) and
//! adds a column by pushing the coboundary of each of its edges, so entries older than the
//! current pivot do arrive. Their sum cancels below the pivot, but each entry alone can be
//! older than `last`, where the radix bins would misplace it. Such entries go to a separate
//! binary heap, `below`, which is consulted first: it is empty in the common case, and
//! whatever survives cancellation there is older than everything in the bins.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::engine::{Tri, canonical, pop_pivot};

/// Bits per vertex in a [`key`]: vertices below 2²¹ (the engine's apex table for that many
/// points would take 8 TiB).
const VERTEX_BITS: u32 = 21;
const VERTEX_MASK: u64 = (1 << VERTEX_BITS) - 1;

/// The radix key of a triangle: smaller is older, in the order of [`Tri`]'s `Ord` (value
/// bits, then the vertices `a > b > c` lexicographically, larger older). The key holds the
/// whole triangle ([`unkey`]), so the column stores keys: 16 bytes an entry, not 24.
#[inline(always)]
fn key(t: &Tri) -> u128 {
    debug_assert!(t.a < 1 << VERTEX_BITS);
    let abc = ((t.a as u64) << (2 * VERTEX_BITS)) | ((t.b as u64) << VERTEX_BITS) | t.c as u64;
    ((t.v as u128) << 64) | !abc as u128
}

/// The triangle of a [`key`].
#[inline(always)]
fn unkey(k: u128) -> Tri {
    let abc = !(k as u64);
    Tri {
        v: (k >> 64) as u64,
        a: ((abc >> (2 * VERTEX_BITS)) & VERTEX_MASK) as u32,
        b: ((abc >> VERTEX_BITS) & VERTEX_MASK) as u32,
        c: (abc & VERTEX_MASK) as u32,
    }
}

/// A Z/2 column of triangles with a monotone "oldest entry" query.
pub(crate) struct Column {
    /// Key of the current minimum.
    last: u128,
    /// Copies of the key `last` (they cancel in pairs).
    top: usize,
    /// Bin `i` (1..=128): keys that differ from `last` first in bit `i − 1`.
    bins: Vec<Vec<u128>>,
    /// Keys below `last` when pushed.
    below: BinaryHeap<Reverse<u128>>,
    len: usize,
}

impl Column {
    pub(crate) fn new() -> Self {
        Self {
            last: 0,
            top: 0,
            bins: vec![Vec::new(); 129],
            below: BinaryHeap::new(),
            len: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.last = 0;
        self.top = 0;
        for b in &mut self.bins {
            b.clear();
        }
        self.below.clear();
        self.len = 0;
    }

    /// Entries held, counting not yet cancelled pairs.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Adds an entry.
    #[inline]
    pub(crate) fn push(&mut self, t: Tri) {
        self.push_key(key(&t));
    }

    #[inline(always)]
    fn push_key(&mut self, k: u128) {
        self.len += 1;
        if k < self.last {
            self.below.push(Reverse(k));
        } else if k == self.last {
            self.top += 1;
        } else {
            let i = 128 - (k ^ self.last).leading_zeros() as usize;
            self.bins[i].push(k);
        }
    }

    /// The oldest entry after cancelling pairs (it stays in the column).
    pub(crate) fn pivot(&mut self) -> Option<Tri> {
        let before = self.below.len();
        let low = pop_pivot(&mut self.below);
        self.len -= before - self.below.len();
        if let Some(Reverse(k)) = low {
            return Some(unkey(k));
        }
        loop {
            // Copies of one triangle: an odd count leaves one.
            if self.top % 2 == 1 {
                self.len -= self.top - 1;
                self.top = 1;
                return Some(unkey(self.last));
            }
            self.len -= self.top;
            self.top = 0;
            let i = self.bins.iter().position(|b| !b.is_empty())?;
            let bin = std::mem::take(&mut self.bins[i]);
            self.last = bin.iter().copied().min()?;
            self.len -= bin.len();
            for &k in &bin {
                self.push_key(k);
            }
            // Hand the emptied buffer back to keep its capacity.
            let mut bin = bin;
            bin.clear();
            if self.bins[i].is_empty() {
                self.bins[i] = bin;
            }
        }
    }

    /// Cancels pairs in bulk (sorting each bin), shrinking a column that has grown long.
    pub(crate) fn compact(&mut self) {
        self.top %= 2;
        self.len = self.top;
        let mut below = std::mem::take(&mut self.below).into_vec();
        canonical(&mut below);
        self.len += below.len();
        self.below = BinaryHeap::from(below);
        for b in &mut self.bins {
            canonical(b);
            self.len += b.len();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key holds the whole triangle and orders keys as `Tri` orders triangles (older
    /// first), ties in value included.
    #[test]
    fn keys_round_trip_and_follow_the_filtration_order() {
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = |m: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % m
        };
        let big = (1u64 << VERTEX_BITS) - 1;
        let mut tris: Vec<Tri> = (0..2000)
            .map(|i| {
                let v = [0.0, 1.0, 2.5, 1e300, f64::from_bits(next(u64::MAX >> 1))][i % 5];
                let n = if i % 3 == 0 { big } else { 50 };
                let (a, b, c) = (next(n) + 2, next(n) + 1, next(n));
                Tri::new(v, a as usize, b as usize, c as usize)
            })
            .filter(|t| t.a != t.b && t.b != t.c && t.a < 1 << VERTEX_BITS)
            .collect();
        tris.push(Tri::new(
            3.0,
            big as usize,
            big as usize - 1,
            big as usize - 2,
        ));
        for t in &tris {
            assert_eq!(unkey(key(t)), *t);
        }
        for s in tris.windows(2) {
            // `Tri`: greater = older; keys: smaller = older.
            assert_eq!(s[0].cmp(&s[1]), key(&s[1]).cmp(&key(&s[0])), "{s:?}");
        }
    }

    #[test]
    fn pops_in_order_and_cancels_pairs() {
        let t = |v: f64, a| Tri::new(v, a, 1, 0);
        let mut c = Column::new();
        for x in [
            t(3.0, 5),
            t(1.0, 2),
            t(1.0, 3),
            t(2.0, 4),
            t(1.0, 2),
            t(3.0, 5),
            t(3.0, 6),
        ] {
            c.push(x);
        }
        // (1.0, 2) cancels; among value 1.0 the larger colex index is older.
        assert_eq!(c.pivot(), Some(t(1.0, 3)));
        c.push(t(1.0, 3));
        assert_eq!(c.pivot(), Some(t(2.0, 4)));
        c.push(t(2.0, 4));
        c.compact();
        assert_eq!(c.len(), 1);
        assert_eq!(c.pivot(), Some(t(3.0, 6)));
        c.push(t(3.0, 6));
        assert_eq!(c.pivot(), None);
    }

    /// Entries older than the last pivot (a reduction adding the coboundaries of a
    /// column's edges one by one) are ordered correctly and cancel in pairs.
    #[test]
    fn entries_below_the_last_pivot_keep_the_order() {
        let t = |v: f64, a| Tri::new(v, a, 1, 0);
        let mut c = Column::new();
        for x in [t(8.0, 2), t(12.0, 3), t(16.0, 4)] {
            c.push(x);
        }
        assert_eq!(c.pivot(), Some(t(8.0, 2)));
        // Add a column whose sum is {8 (cancels the pivot), 9}, pushed with a pair at 7
        // and a pair at 6 that cancel below the pivot.
        for x in [
            t(7.0, 5),
            t(8.0, 2),
            t(6.0, 6),
            t(9.0, 7),
            t(7.0, 5),
            t(6.0, 6),
        ] {
            c.push(x);
        }
        assert_eq!(c.pivot(), Some(t(9.0, 7)));
        // One unpaired entry below the pivot is the new pivot.
        c.push(t(5.0, 8));
        assert_eq!(c.pivot(), Some(t(5.0, 8)));
        c.compact();
        assert_eq!(c.len(), 4);
        c.push(t(5.0, 8));
        assert_eq!(c.pivot(), Some(t(9.0, 7)));
        c.push(t(9.0, 7));
        assert_eq!(c.pivot(), Some(t(12.0, 3)));
        c.clear();
        assert_eq!(c.pivot(), None);
    }
}
