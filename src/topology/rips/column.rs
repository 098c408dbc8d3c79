//! The working column of the cohomology reduction: a monotone radix heap.
//!
//! During the reduction of one column the pivot only moves forward (adding a column with
//! pivot `p` cancels `p` and adds entries that all come after it), so the column is a
//! *monotone* priority queue and a radix heap (Ahuja, Mehlhorn, Orlin & Tarjan, 1990)
//! applies: entries are binned by the highest bit in which their value differs from the
//! last minimum, pushes are `O(1)` appends, and a pop only redistributes one bin. For the
//! long columns of big holes (millions of entries, most of them cancelling in pairs) this
//! beats a binary heap, whose sift-downs miss the cache at every level.
//!
//! Monotone only up to cancellation: the engine keeps reduction-matrix columns (edges) and
//! adds a column by pushing the coboundary of each of its edges, so entries older than the
//! current pivot do arrive. Their sum cancels below the pivot, but each entry alone can be
//! older than `last`, where the radix bins would misplace it. Such entries go to a separate
//! binary heap, `below`, which is consulted first: it is empty in the common case, and
//! whatever survives cancellation there is older than everything in the bins.

use std::collections::BinaryHeap;

use super::engine::{Tri, canonical, pop_pivot};

/// A Z/2 column of triangles with a monotone "oldest entry" query.
pub(crate) struct Column {
    /// Value bits of the current minimum.
    last: u64,
    /// Entries whose value equals `last`, ordered by the tie-break (Tri: greater = older).
    top: BinaryHeap<Tri>,
    /// Bin `i` (1..=64): entries whose value differs from `last` first in bit `i − 1`.
    bins: Vec<Vec<Tri>>,
    /// Entries whose value was below `last` when pushed.
    below: BinaryHeap<Tri>,
    len: usize,
}

impl Column {
    pub(crate) fn new() -> Self {
        Self {
            last: 0,
            top: BinaryHeap::new(),
            bins: vec![Vec::new(); 65],
            below: BinaryHeap::new(),
            len: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.last = 0;
        self.top.clear();
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
        self.len += 1;
        if t.v < self.last {
            self.below.push(t);
        } else if t.v == self.last {
            self.top.push(t);
        } else {
            let i = 64 - (t.v ^ self.last).leading_zeros() as usize;
            self.bins[i].push(t);
        }
    }

    /// The oldest entry after cancelling pairs (it stays in the column).
    pub(crate) fn pivot(&mut self) -> Option<Tri> {
        if let Some(x) = pop_counted(&mut self.below, &mut self.len) {
            return Some(x);
        }
        loop {
            if let Some(x) = pop_counted(&mut self.top, &mut self.len) {
                return Some(x);
            }
            let i = self.bins.iter().position(|b| !b.is_empty())?;
            let bin = std::mem::take(&mut self.bins[i]);
            self.last = bin.iter().map(|t| t.v).min()?;
            self.len -= bin.len();
            for &t in &bin {
                self.push(t);
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
        let mut top = std::mem::take(&mut self.top).into_vec();
        canonical(&mut top);
        self.len = top.len();
        self.top = BinaryHeap::from(top);
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

/// [`pop_pivot`] on one of the column's heaps, taking the cancelled pairs off `len`.
fn pop_counted(heap: &mut BinaryHeap<Tri>, len: &mut usize) -> Option<Tri> {
    let before = heap.len();
    let x = pop_pivot(heap);
    *len -= before - heap.len();
    x
}

#[cfg(test)]
mod tests {
    use super::*;

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
