//! The persistence computation proper, generic over the [`Metric`].
//!
//! Stages, for `n` points and a threshold `t`:
//! 1. **Threshold**: the enclosing radius `min_i max_j d(i, j)` unless the caller gives one.
//! 2. **H0** by Prim's algorithm on the implicit complete graph, `O(n²)` time, `O(n)` memory.
//!    With a total order on edges the minimum spanning forest is unique and equals the edges
//!    that Kruskal's union–find (the H0 reduction) pairs with vertices; those edges are the
//!    pivots of the 0-dimensional coboundary matrix, so *clearing* removes them from the
//!    H1 computation.
//! 3. **Apparent pairs** (Bauer 2021, §3.5), found in parallel: for every other edge `e`,
//!    scan the vertices `k` from the top down for the first cofacet `e ∪ {k}` of the same
//!    diameter — that is `e`'s oldest cofacet `τ`; if `e` is also `τ`'s youngest facet,
//!    `(e, τ)` is a persistence pair of length zero and its column needs no reduction.
//!    For generic points this settles every edge except those of the relative-neighbourhood
//!    graph not in the spanning tree, about `0.3 n` edges, so the expected cost is a few
//!    vertex probes per edge. The pair is stored as the apex `k` in one `u32` per edge: a
//!    pivot lookup for a triangle `τ` computes `τ`'s youngest facet and compares its apex,
//!    with no hash map over the millions of apparent pairs.
//! 4. **Cohomology reduction** (Bauer 2021, §3) of the remaining edges in reverse
//!    filtration order, with the implicit coboundary (cofacets enumerated from the points,
//!    never stored), the emergent-pair shortcut (a column whose oldest cofacet is nobody's
//!    pivot is already reduced), and a radix heap as the working column (`column.rs`); reduced columns
//!    are kept as their few reduction-matrix entries and their coboundaries regenerated
//!    (only from the pivot up: below it they cancel). Which vertices a coboundary scan
//!    tests is the metric's choice ([`Metric::cofacets`]): a 2-D or 3-D point cloud scans
//!    only the grid cells within reach of the edge.
//!    The working column holds only cofacets up to a bound that is raised as it empties;
//!    a raise doubles the bound unless a sample of the column predicts more than
//!    [`PUSH_BUDGET`] new entries, then it steps less (`Reducer::raise`). The cocycle of a
//!    big hole among ~10⁴ points has ~10⁵ edges, and doubling pushed 10⁸–10⁹ entries at
//!    once (6 GiB and more for one column).
//!
//! The filtration is simplexwise: edges by `(value, colex index descending)`, triangles by
//! `(value, colex index descending)` (colex order of vertex triples `a > b > c`), which is
//! Ripser's order. Exact ties are thus broken consistently everywhere.
//!
//! Time `O(n² · p + r · n log n)` where `p` is the mean number of probes per edge and `r`
//! the work of the few reduced columns; memory `4·n(n−1)/2` bytes for the apex table plus
//! the metric (nothing more for 2-D and 3-D points) plus the working column, which the push
//! budget keeps to a few hundred MB.

use std::collections::{BinaryHeap, HashMap};

use rayon::prelude::*;

use super::column::Column;
use super::metric::Metric;

/// Apex marker: the edge is not in an apparent pair (or is beyond the threshold).
pub(crate) const NONE: u32 = u32::MAX;
/// Apex marker: the edge is a spanning-forest edge (an H0 death, cleared for H1).
pub(crate) const TREE: u32 = u32::MAX - 1;

/// Colex index of the edge `{a, b}`, `a > b`.
#[inline(always)]
pub(crate) fn eidx(a: usize, b: usize) -> usize {
    debug_assert!(a > b);
    a * (a - 1) / 2 + b
}

/// A triangle `{a > b > c}` with its filtration value as bits (values are ≥ +0.0, so bit
/// order is value order). `Ord`: *greater* means *earlier* in the filtration, so a
/// max-heap pops the oldest triangle (the cohomology pivot).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Tri {
    pub v: u64,
    pub a: u32,
    pub b: u32,
    pub c: u32,
}

impl Tri {
    pub(crate) fn new(v: f64, x: usize, y: usize, z: usize) -> Self {
        let (mut a, mut b, mut c) = (x, y, z);
        if a < b {
            std::mem::swap(&mut a, &mut b);
        }
        if b < c {
            std::mem::swap(&mut b, &mut c);
        }
        if a < b {
            std::mem::swap(&mut a, &mut b);
        }
        Self {
            v: v.to_bits(),
            a: a as u32,
            b: b as u32,
            c: c as u32,
        }
    }

    pub(crate) fn value(&self) -> f64 {
        f64::from_bits(self.v)
    }
}

impl Ord for Tri {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        o.v.cmp(&self.v)
            .then((self.a, self.b, self.c).cmp(&(o.a, o.b, o.c)))
    }
}

impl PartialOrd for Tri {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

/// An edge `{a > b}` with its value bits. `Ord`: greater means *later* in the filtration
/// (higher value, then lower colex index), so a max-heap pops the youngest edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Edge {
    pub v: u64,
    pub a: u32,
    pub b: u32,
}

impl Edge {
    pub(crate) fn new(v: f64, x: usize, y: usize) -> Self {
        let (a, b) = if x > y { (x, y) } else { (y, x) };
        Self {
            v: v.to_bits(),
            a: a as u32,
            b: b as u32,
        }
    }
    pub(crate) fn value(&self) -> f64 {
        f64::from_bits(self.v)
    }
    pub(crate) fn index(&self) -> usize {
        eidx(self.a as usize, self.b as usize)
    }
}

impl Ord for Edge {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.v.cmp(&o.v).then((o.a, o.b).cmp(&(self.a, self.b)))
    }
}

impl PartialOrd for Edge {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

/// A finite or essential H1 pair found by the reduction, in filtration values.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair1 {
    pub birth: Edge,
    pub death: Option<Tri>,
}

/// Everything the engine found, in filtration values.
pub(crate) struct Raw {
    /// Values of the spanning-forest edges (H0 deaths), as edges.
    pub tree: Vec<Edge>,
    /// Number of connected components at the threshold (essential H0 classes).
    pub components: usize,
    /// H1 pairs from the reduction (apparent pairs are omitted: they have length zero).
    pub pairs: Vec<Pair1>,
    /// Apex table (see the module docs), present when H1 was computed.
    pub apex: Vec<u32>,
    /// Reduced (non-apparent) pairs: death triangle → birth edge.
    pub reduced: HashMap<Tri, Edge>,
}

/// Enclosing radius (as a filtration value): `min_i max_j value(i, j)`.
pub(crate) fn enclosing<M: Metric>(m: &M) -> f64 {
    let n = m.len();
    (0..n)
        .into_par_iter()
        .map(|i| (0..n).map(|j| m.value(i, j)).fold(0.0, f64::max))
        .reduce(|| f64::INFINITY, f64::min)
}

/// Prim's algorithm with the total edge order; returns the forest edges and the number of
/// components, considering only edges with value ≤ `t`.
fn spanning_forest<M: Metric>(m: &M, t: f64) -> (Vec<Edge>, usize) {
    let n = m.len();
    let mut in_tree = vec![false; n];
    // Best known edge into the tree for every vertex outside it.
    let mut best: Vec<Option<Edge>> = vec![None; n];
    let mut tree = Vec::with_capacity(n.saturating_sub(1));
    let mut components = 0;
    let mut remaining = n;
    let mut next = 0usize;
    while remaining > 0 {
        // `next` is either the head of a new component or the closest outside vertex.
        let u = next;
        if best[u].is_none() {
            components += 1;
        } else if let Some(e) = best[u] {
            tree.push(e);
        }
        in_tree[u] = true;
        remaining -= 1;
        let mut choice: Option<(usize, Edge)> = None;
        let mut first_out = None;
        for w in 0..n {
            if in_tree[w] {
                continue;
            }
            if first_out.is_none() {
                first_out = Some(w);
            }
            let v = m.value(u, w);
            if v <= t {
                let e = Edge::new(v, u, w);
                if best[w].is_none_or(|b| e < b) {
                    best[w] = Some(e);
                }
            }
            if let Some(b) = best[w]
                && choice.is_none_or(|(_, c)| b < c)
            {
                choice = Some((w, b));
            }
        }
        match (choice, first_out) {
            (Some((w, _)), _) => next = w,
            (None, Some(w)) => next = w,
            (None, None) => break,
        }
    }
    (tree, components)
}

/// Oldest cofacet of `{a > b}` (value `d`) with value ≤ `t`. Every cofacet has value
/// ≥ `d` and the colex index grows with the apex `k`, so if some `k` has both other edges
/// ≤ `d`, the oldest cofacet is the one with the largest such `k`; this is found by
/// scanning down from the top in blocks whose test the compiler can vectorise. Otherwise
/// (rare: relative-neighbourhood edges) a full scan finds the minimum value.
#[inline]
fn oldest_cofacet<M: Metric>(m: &M, a: usize, b: usize, d: f64, t: f64) -> Option<Tri> {
    const W: usize = 16;
    let n = m.len();
    let mut hi = n;
    while hi > 0 {
        let lo = hi.saturating_sub(W);
        let mut any = false;
        for k in lo..hi {
            any |= m.value(a, k).max(m.value(b, k)) <= d;
        }
        if any {
            for k in (lo..hi).rev() {
                if k != a && k != b && m.value(a, k).max(m.value(b, k)) <= d {
                    return Some(Tri::new(d, a, b, k));
                }
            }
        }
        hi = lo;
    }
    let mut best: Option<(f64, usize)> = None;
    for k in (0..n).rev() {
        let x = m.value(a, k).max(m.value(b, k));
        if k != a && k != b && x <= t && best.is_none_or(|(bx, _)| x < bx) {
            best = Some((x, k));
        }
    }
    best.map(|(x, k)| Tri::new(x, a, b, k))
}

/// The youngest facet of a triangle and the vertex opposite to it.
#[inline]
pub(crate) fn youngest_facet<M: Metric>(m: &M, t: &Tri) -> (Edge, usize) {
    let (a, b, c) = (t.a as usize, t.b as usize, t.c as usize);
    let e1 = Edge::new(m.value(a, b), a, b);
    let e2 = Edge::new(m.value(a, c), a, c);
    let e3 = Edge::new(m.value(b, c), b, c);
    let mut y = (e1, c);
    if e2 > y.0 {
        y = (e2, b);
    }
    if e3 > y.0 {
        y = (e3, a);
    }
    y
}

/// Where the column with pivot `τ` lives, if anywhere.
enum Owner {
    Apparent(Edge),
    Reduced(usize),
}

struct Reducer<'a, M: Metric> {
    m: &'a M,
    t: f64,
    apex: &'a [u32],
    /// Pivot triangle → index into `columns`.
    pivots: HashMap<Tri, usize>,
    /// Reduction-matrix columns (edges whose coboundaries sum to the reduced column).
    columns: Vec<Vec<Edge>>,
    /// Cofacets one bound raise may push ([`PUSH_BUDGET`]).
    budget: usize,
}

impl<M: Metric> Reducer<'_, M> {
    fn owner(&self, tau: &Tri) -> Option<Owner> {
        let (e, k) = youngest_facet(self.m, tau);
        if e.v == tau.v && self.apex[e.index()] == k as u32 {
            return Some(Owner::Apparent(e));
        }
        self.pivots.get(tau).map(|&j| Owner::Reduced(j))
    }

    /// Pushes the cofacets of `e` with value in `(lo, hi]` (`hi` ≤ the threshold). Which
    /// vertices are tested is the metric's choice ([`Metric::cofacets`]): a point cloud
    /// scans only the grid cells near `e`.
    fn push_coboundary(&self, heap: &mut Column, e: &Edge, lo: f64, hi: f64) {
        let (a, b) = (e.a as usize, e.b as usize);
        self.m.cofacets(a, b, e.value(), lo, hi, |k, x| {
            heap.push(Tri::new(x, a, b, k))
        });
    }

    /// The next bound above `lo` for the reduction-matrix column `v`: twice `lo` (at most
    /// the threshold), or less where that would push more than the budget of cofacets.
    /// A persistent class of a big hole has a cocycle of ~10⁵ edges at 10⁴ points, and the
    /// cofacets of all of them in `(lo, 2·lo]` reach 10⁸–10⁹ heap entries; a counting scan
    /// of a sample of the column (no pushes) sizes the step instead. The diagram does not depend on the
    /// bounds chosen, only the memory and the number of scans do.
    fn raise(&self, v: &[Edge], lo: f64) -> f64 {
        let hi = (2.0 * lo).min(self.t);
        let n = self.m.len();
        if v.len().saturating_mul(n) <= self.budget || hi <= lo {
            return hi;
        }
        const B: usize = 64;
        let width = (hi - lo) / B as f64;
        // Every `stride`-th edge estimates the counts well enough for a soft budget.
        let stride = v.len().div_ceil(SAMPLE);
        let hist = v
            .par_iter()
            .step_by(stride)
            .fold(
                || [0usize; B],
                |mut h, e| {
                    self.m
                        .cofacets(e.a as usize, e.b as usize, e.value(), lo, hi, |_, x| {
                            h[(((x - lo) / width) as usize).min(B - 1)] += 1;
                        });
                    h
                },
            )
            .reduce(
                || [0usize; B],
                |mut x, y| {
                    for (a, b) in x.iter_mut().zip(y) {
                        *a += b;
                    }
                    x
                },
            );
        // The longest prefix of buckets within the budget, and at least one bucket.
        let mut total = 0usize;
        let mut last = 0;
        for (i, c) in hist.iter().enumerate() {
            total += c * stride;
            if total > self.budget {
                break;
            }
            last = i;
        }
        if last == B - 1 {
            hi
        } else {
            lo + width * (last + 1) as f64
        }
    }

    /// Reduces the column of `e` (whose oldest cofacet is `p0`); returns its pivot.
    fn reduce(&mut self, e: Edge, p0: Option<Tri>, heap: &mut Column) -> Option<Tri> {
        let p0 = p0?;
        if self.owner(&p0).is_none() {
            // Emergent pair: the unreduced column already has a fresh pivot.
            self.pivots.insert(p0, self.columns.len());
            self.columns.push(vec![e]);
            return Some(p0);
        }
        // Truncated reduction: the heap holds the working column restricted to values
        // ≤ `bound`, so while it is non-empty its top is the true pivot. When it empties,
        // the bound is raised and the missing cofacets of the reduction-matrix column are
        // pushed. Most deaths are close to their births, so most columns never generate
        // (or heap) the ~n cofacets of every added column; long bars pay once per raise
        // for a scan without pushes.
        let mut bound = if p0.value() > 0.0 {
            (2.0 * p0.value()).min(self.t)
        } else {
            self.t
        };
        heap.clear();
        self.push_coboundary(heap, &e, f64::NEG_INFINITY, bound);
        let mut v = vec![e];
        let mut compact_at = COMPACT_MIN;
        loop {
            if heap.len() > compact_at {
                heap.compact();
                compact_at = COMPACT_MIN.max(2 * heap.len());
            }
            let Some(p) = heap.pivot() else {
                if bound >= self.t {
                    return None;
                }
                let lo = bound;
                canonical(&mut v);
                bound = self.raise(&v, lo);
                for f in &v {
                    self.push_coboundary(heap, f, lo, bound);
                }
                continue;
            };
            match self.owner(&p) {
                Some(Owner::Apparent(f)) => {
                    self.push_coboundary(heap, &f, f64::NEG_INFINITY, bound);
                    v.push(f);
                }
                Some(Owner::Reduced(j)) => {
                    // Column `j`'s coboundary sum has pivot `p`, so its cofacets of lower
                    // value cancel in pairs: they are not pushed (they would only be
                    // popped off the column's `below` heap again).
                    let lo = p.value().next_down();
                    let col = std::mem::take(&mut self.columns[j]);
                    for f in &col {
                        self.push_coboundary(heap, f, lo, bound);
                    }
                    v.extend_from_slice(&col);
                    self.columns[j] = col;
                }
                None => {
                    canonical(&mut v);
                    self.pivots.insert(p, self.columns.len());
                    self.columns.push(v);
                    return Some(p);
                }
            }
        }
    }
}

/// Cofacets a bound raise may push at once (24 bytes each) before [`Reducer::raise`]
/// takes a smaller step than doubling.
const PUSH_BUDGET: usize = 1 << 23;
/// Edges of a column sampled to size a bound raise.
const SAMPLE: usize = 512;

/// Heap size (entries) below which a working column is never compacted.
const COMPACT_MIN: usize = 1 << 16;

/// Sorts a Z/2 chain and cancels repeated entries in pairs.
pub(crate) fn canonical<T: Ord + Copy>(v: &mut Vec<T>) {
    v.sort_unstable();
    let (mut w, mut i) = (0, 0);
    while i < v.len() {
        let mut j = i;
        while j < v.len() && v[j] == v[i] {
            j += 1;
        }
        if (j - i) % 2 == 1 {
            v[w] = v[i];
            w += 1;
        }
        i = j;
    }
    v.truncate(w);
}

/// Pops the top of a Z/2 heap column, cancelling equal entries in pairs, and leaves the
/// surviving top in place.
pub(crate) fn pop_pivot<T: Ord + Copy>(heap: &mut BinaryHeap<T>) -> Option<T> {
    loop {
        let top = heap.pop()?;
        if heap.peek() == Some(&top) {
            heap.pop();
            continue;
        }
        heap.push(top);
        return Some(top);
    }
}

/// Runs the whole computation. `t` is the threshold as a filtration value.
pub(crate) fn compute<M: Metric>(m: &M, t: f64, h1: bool) -> Raw {
    compute_with(m, t, h1, PUSH_BUDGET)
}

/// [`compute`] with a given push budget for the bound raises.
fn compute_with<M: Metric>(m: &M, t: f64, h1: bool, budget: usize) -> Raw {
    let n = m.len();
    let (tree, components) = spanning_forest(m, t);
    if !h1 || n < 3 {
        return Raw {
            tree,
            components,
            pairs: Vec::new(),
            apex: Vec::new(),
            reduced: HashMap::new(),
        };
    }
    let mut apex = vec![NONE; n * (n - 1) / 2];
    for e in &tree {
        apex[e.index()] = TREE;
    }
    // Split the apex table into rows: row `a` holds the edges {a, b}, b < a.
    let mut rows: Vec<&mut [u32]> = Vec::with_capacity(n);
    let mut rest = apex.as_mut_slice();
    for a in 0..n {
        let (row, r) = rest.split_at_mut(a);
        rows.push(row);
        rest = r;
    }
    let mut todo: Vec<(Edge, Option<Tri>)> = rows
        .into_par_iter()
        .enumerate()
        .flat_map_iter(|(a, row)| {
            let mut out = Vec::new();
            for (b, slot) in row.iter_mut().enumerate() {
                if *slot == TREE {
                    continue;
                }
                let d = m.value(a, b);
                if d > t {
                    continue;
                }
                let e = Edge::new(d, a, b);
                let p = oldest_cofacet(m, a, b, d, t);
                if let Some(tau) = p
                    && tau.v == e.v
                {
                    let (y, k) = youngest_facet(m, &tau);
                    if y == e {
                        *slot = k as u32;
                        continue;
                    }
                }
                out.push((e, p));
            }
            out
        })
        .collect();
    // Reverse filtration order: youngest edge first.
    todo.sort_unstable_by_key(|x| std::cmp::Reverse(x.0));
    let mut red = Reducer {
        m,
        t,
        apex: &apex,
        pivots: HashMap::new(),
        columns: Vec::new(),
        budget,
    };
    let mut heap = Column::new();
    let mut pairs = Vec::new();
    let mut reduced = HashMap::new();
    for (e, p0) in todo {
        let death = red.reduce(e, p0, &mut heap);
        if let Some(tau) = death {
            reduced.insert(tau, e);
        }
        pairs.push(Pair1 { birth: e, death });
    }
    drop(red);
    Raw {
        tree,
        components,
        pairs,
        apex,
        reduced,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::PointCloud;
    use crate::topology::rips::metric::{Full, Points};

    /// Points round two holes of different sizes with a deterministic jitter: long H1
    /// bars whose cocycles grow to thousands of edges.
    fn two_holes(n: usize) -> PointCloud {
        let mut pts = Vec::with_capacity(n);
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        while pts.len() < n {
            let (px, py) = (4.0 * next(), 2.0 * next());
            let d1 = (px - 1.0).hypot(py - 1.0);
            let d2 = (px - 3.0).hypot(py - 1.0);
            if d1 > 0.6 && d2 > 0.3 {
                pts.push([px, py]);
            }
        }
        PointCloud::from_rows(&pts).unwrap()
    }

    fn key(raw: &Raw) -> Vec<(Edge, Option<Tri>)> {
        let mut v: Vec<_> = raw.pairs.iter().map(|p| (p.birth, p.death)).collect();
        v.sort_by_key(|x| x.0);
        v
    }

    /// The bound raises only choose what to push when, never what the column sums to: a
    /// budget so small that every raise of a long column takes the sampled, shortened step
    /// gives the same pairs as plain doubling.
    #[test]
    fn the_push_budget_does_not_change_the_pairs() {
        let pc = two_holes(700);
        let m = Points::<2>::new(&pc).unwrap();
        let t = enclosing(&m);
        let doubling = compute_with(&m, t, true, usize::MAX);
        let tight = compute_with(&m, t, true, 1);
        let shipped = compute_with(&m, t, true, PUSH_BUDGET);
        assert_eq!(key(&doubling), key(&tight));
        assert_eq!(key(&doubling), key(&shipped));
        // The two holes are there, so long columns were reduced.
        let long = doubling
            .pairs
            .iter()
            .filter(|p| p.death.is_some_and(|d| d.value() > 4.0 * p.birth.value()))
            .count();
        assert!(long >= 2, "{long} long bars");
    }

    /// The point metric's grid scan ([`Metric::cofacets`]) and the matrix's full scan give
    /// the same pairs, death triangles included, on long bars and on a lattice full of ties.
    #[test]
    fn grid_and_full_scans_give_the_same_pairs() {
        let lattice: Vec<[f64; 2]> = (0..400)
            .map(|i| [(i % 20) as f64, (i / 20) as f64])
            .collect();
        // Scaled so far down that every squared distance is subnormal, where rounding is
        // absolute (a review found the grid missing cofacets there).
        let tiny = two_holes(400);
        let tiny: Vec<[f64; 2]> = (0..tiny.len())
            .map(|i| [tiny.point(i)[0] * 1e-161, tiny.point(i)[1] * 1e-161])
            .collect();
        for pc in [
            two_holes(700),
            PointCloud::from_rows(&lattice).unwrap(),
            PointCloud::from_rows(&tiny).unwrap(),
        ] {
            let p = Points::<2>::new(&pc).unwrap();
            let f = Full::squared_from_points(&pc);
            let t = enclosing(&p);
            assert_eq!(t, enclosing(&f));
            let (a, b) = (compute(&p, t, true), compute(&f, t, true));
            assert_eq!(key(&a), key(&b));
            assert!(!a.pairs.is_empty());
        }
    }
}
