//! Persistence diagrams: bars with their dimension, birth, death and, for H1, an optional
//! representative cycle.

use std::cmp::Ordering;

/// One persistence interval `[birth, death)`, in the units of the input distances.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// Homology dimension (0 or 1).
    pub dim: usize,
    /// Scale at which the class is born.
    pub birth: f64,
    /// Scale at which the class dies; `f64::INFINITY` for an essential class.
    pub death: f64,
    /// For H1 bars computed with `cycles = true`: the edges `(i, j)`, `i < j`, of a Z/2 cycle
    /// that carries the class (sorted). Every edge has length ≤ `birth` and one has length
    /// exactly `birth`.
    pub cycle: Option<Vec<(usize, usize)>>,
    /// For H1 bars with a finite death: the vertices (sorted) of the triangle whose entry
    /// kills the class; its longest edge has length exactly `death`. The cycle runs through
    /// the birth edge, which can lie far from what keeps the class alive; this triangle
    /// spans the void itself.
    pub death_triangle: Option<[usize; 3]>,
}

impl Bar {
    /// `death − birth` (infinite for an essential class).
    pub fn persistence(&self) -> f64 {
        self.death - self.birth
    }

    /// Whether the class never dies.
    pub fn is_essential(&self) -> bool {
        self.death == f64::INFINITY
    }
}

/// A persistence diagram: bars sorted by `(dim, birth, death)`, zero-length bars dropped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Diagram {
    /// The bars, sorted by `(dim, birth, death)`.
    pub bars: Vec<Bar>,
}

impl Diagram {
    /// Builds a diagram, dropping bars with `death <= birth` and sorting the rest.
    pub fn new(mut bars: Vec<Bar>) -> Self {
        bars.retain(|b| b.death > b.birth);
        bars.sort_by(|x, y| bar_order(x, y).then_with(|| x.cycle.cmp(&y.cycle)));
        Self { bars }
    }

    /// The bars of dimension `d`.
    pub fn dim(&self, d: usize) -> impl Iterator<Item = &Bar> {
        self.bars.iter().filter(move |b| b.dim == d)
    }

    /// The Betti number β_d at `scale`: bars of dimension `d` with `birth <= scale < death`.
    pub fn betti_at(&self, d: usize, scale: f64) -> usize {
        self.dim(d)
            .filter(|b| b.birth <= scale && scale < b.death)
            .count()
    }
}

/// The diagram order: `(dim, birth, death)`.
fn bar_order(x: &Bar, y: &Bar) -> Ordering {
    x.dim
        .cmp(&y.dim)
        .then(x.birth.total_cmp(&y.birth))
        .then(x.death.total_cmp(&y.death))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bar(dim: usize, birth: f64, death: f64) -> Bar {
        Bar {
            dim,
            birth,
            death,
            cycle: None,
            death_triangle: None,
        }
    }

    #[test]
    fn sorts_drops_and_counts() {
        let d = Diagram::new(vec![
            bar(1, 0.5, 0.7),
            bar(0, 0.0, f64::INFINITY),
            bar(0, 0.0, 0.3),
            bar(1, 0.2, 0.2),
        ]);
        assert_eq!(d.bars.len(), 3);
        assert_eq!(d.bars[0].death, 0.3);
        assert_eq!(d.betti_at(0, 0.1), 2);
        assert_eq!(d.betti_at(0, 0.3), 1);
        assert_eq!(d.betti_at(1, 0.6), 1);
        assert_eq!(d.betti_at(1, 0.7), 0);
        assert_eq!(d.dim(1).count(), 1);
    }
}
