//! Distances as the engine sees them.
//!
//! The engine works on *filtration values* that are a monotone function of the distance:
//! squared Euclidean distances for point clouds (no square root in the inner loops, and in
//! 2-D and 3-D no stored matrix at all: a distance is recomputed from the coordinates, which
//! stay in cache), and the distances themselves for a matrix. Because the square root is
//! monotone, the order by squared distance refines the order by distance, so both give the
//! same bars once values are mapped back with [`Metric::to_distance`] (bars that the
//! mapping makes zero-length are dropped).

use crate::topology::{DistanceMatrix, PointCloud};

/// A symmetric dissimilarity on `0..len()` with zero diagonal.
pub(crate) trait Metric: Sync {
    /// Number of points.
    fn len(&self) -> usize;
    /// Filtration value of the edge `{i, j}`; must be bit-identical for `(i, j)` and `(j, i)`.
    fn value(&self, i: usize, j: usize) -> f64;
    /// Maps a filtration value back to a distance.
    fn to_distance(&self, v: f64) -> f64;
    /// The largest filtration value whose distance is ≤ `t`.
    fn threshold_value(&self, t: f64) -> f64;

    /// Calls `f(k, x)`, in no particular order, for every vertex `k ∉ {a, b}` whose
    /// cofacet `{a, b, k}` of the edge `{a, b}` (value `d`) has its value
    /// `x = max(d, value(a, k), value(b, k))` in `(lo, hi]`.
    ///
    /// The default tests every vertex ([`default_cofacets`]).
    #[inline]
    fn cofacets(&self, a: usize, b: usize, d: f64, lo: f64, hi: f64, f: impl FnMut(usize, f64))
    where
        Self: Sized,
    {
        default_cofacets(self, a, b, d, lo, hi, f);
    }
}

/// [`Metric::cofacets`] by testing every vertex, in blocks whose test the compiler can
/// vectorise; only a block with a hit is scanned again to call `f` (a long column's bound
/// raises find few of each edge's ~n cofacets in their range).
#[inline]
pub(crate) fn default_cofacets<M: Metric>(
    m: &M,
    a: usize,
    b: usize,
    d: f64,
    lo: f64,
    hi: f64,
    mut f: impl FnMut(usize, f64),
) {
    const W: usize = 16;
    let n = m.len();
    let value = |k: usize| d.max(m.value(a, k)).max(m.value(b, k));
    let mut start = 0;
    while start < n {
        let end = (start + W).min(n);
        let mut any = false;
        for k in start..end {
            let x = value(k);
            any |= (x <= hi) & (x > lo);
        }
        if any {
            for k in start..end {
                let x = value(k);
                if x <= hi && x > lo && k != a && k != b {
                    f(k, x);
                }
            }
        }
        start = end;
    }
}

/// A dense `n × n` matrix of filtration values, rows contiguous (fast row scans).
pub(crate) struct Full {
    n: usize,
    v: Vec<f64>,
    squared: bool,
}

impl Full {
    pub(crate) fn from_matrix(d: &DistanceMatrix) -> Self {
        let n = d.len();
        let mut v = vec![0.0; n * n];
        let mut k = 0;
        let c = d.condensed();
        for i in 0..n {
            for j in i + 1..n {
                // `abs` turns a -0.0 entry into +0.0 so that bit patterns order like values.
                let x = c[k].abs();
                v[i * n + j] = x;
                v[j * n + i] = x;
                k += 1;
            }
        }
        Self {
            n,
            v,
            squared: false,
        }
    }

    pub(crate) fn squared_from_points(p: &PointCloud) -> Self {
        let n = p.len();
        let mut v = vec![0.0; n * n];
        for i in 0..n {
            for j in i + 1..n {
                let x = sq_dist(p.point(i), p.point(j));
                v[i * n + j] = x;
                v[j * n + i] = x;
            }
        }
        Self {
            n,
            v,
            squared: true,
        }
    }
}

fn sq_dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// The largest `s` with `sqrt(s) <= t`.
fn sq_threshold(t: f64) -> f64 {
    if t.is_infinite() {
        return f64::INFINITY;
    }
    let mut s = t * t;
    while s > 0.0 && s.sqrt() > t {
        s = s.next_down();
    }
    while s.next_up().sqrt() <= t && s.is_finite() {
        s = s.next_up();
    }
    s
}

impl Metric for Full {
    fn len(&self) -> usize {
        self.n
    }
    #[inline(always)]
    fn value(&self, i: usize, j: usize) -> f64 {
        self.v[i * self.n + j]
    }
    fn to_distance(&self, v: f64) -> f64 {
        if self.squared { v.sqrt() } else { v }
    }
    fn threshold_value(&self, t: f64) -> f64 {
        if self.squared { sq_threshold(t) } else { t }
    }
}

/// Points in `D` dimensions; values are squared distances computed on demand.
pub(crate) struct Points<const D: usize> {
    p: Vec<[f64; D]>,
    /// The points bucketed by their first two coordinates ([`Grid`]).
    grid: Option<Grid<D>>,
}

/// The squared distance of [`Points::value`], also used on the grid's copy of the
/// coordinates (same operations in the same order, so bit-identical values).
#[inline(always)]
fn sq<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        let d = a[k] - b[k];
        s += d * d;
    }
    s
}

/// A uniform grid over the first two coordinates, for [`Metric::cofacets`] of a point
/// cloud: a cofacet `{a, b, k}` of value ≤ `hi` needs `k` within `√hi` of both `a` and
/// `b` in every coordinate, so only the cells of a box round them are scanned. The points
/// are copied in row-major cell order, so the cells of one grid row within the box are one
/// contiguous run, tested in vectorisable blocks like the default scan. The reductions of
/// long bars push the cofacets of ~10⁵ cocycle edges at every bound raise, most of them at
/// bounds far below the diameter of the cloud (docs/accuracy.md, step 35).
struct Grid<const D: usize> {
    /// Cells per side.
    g: usize,
    x0: f64,
    y0: f64,
    /// Cells per unit of length.
    inv: f64,
    /// `start[c]..start[c + 1]`: cell `c`'s points in `pts` and `idx` (cell `c` is row
    /// `c / g`, column `c % g`).
    start: Vec<usize>,
    pts: Vec<[f64; D]>,
    idx: Vec<u32>,
}

/// Mean points per grid cell.
const PER_CELL: usize = 8;
/// Below this many points the default scan is used.
const GRID_MIN: usize = 256;

impl<const D: usize> Grid<D> {
    fn new(p: &[[f64; D]]) -> Option<Self> {
        if D < 2 || p.len() < GRID_MIN || p.len() > u32::MAX as usize {
            return None;
        }
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for q in p {
            (x0, x1) = (x0.min(q[0]), x1.max(q[0]));
            (y0, y1) = (y0.min(q[1]), y1.max(q[1]));
        }
        let side = (x1 - x0).max(y1 - y0);
        if !(side.is_finite() && side > 0.0) {
            return None;
        }
        let g = ((p.len() / PER_CELL) as f64).sqrt().ceil().max(1.0) as usize;
        let inv = g as f64 / side;
        if !inv.is_finite() {
            return None;
        }
        let mut grid = Self {
            g,
            x0,
            y0,
            inv,
            start: vec![0; g * g + 1],
            pts: Vec::with_capacity(p.len()),
            idx: Vec::with_capacity(p.len()),
        };
        let cell = |q: &[f64; D]| grid.row(q[1]) * g + grid.col(q[0]);
        let mut order: Vec<(usize, u32)> = p
            .iter()
            .enumerate()
            .map(|(i, q)| (cell(q), i as u32))
            .collect();
        order.sort_unstable();
        for &(c, i) in &order {
            grid.start[c + 1] += 1;
            grid.pts.push(p[i as usize]);
            grid.idx.push(i);
        }
        for c in 0..g * g {
            grid.start[c + 1] += grid.start[c];
        }
        Some(grid)
    }

    /// The cell column of abscissa `x`, clamped to the grid. Monotone in `x`.
    #[inline]
    fn col(&self, x: f64) -> usize {
        (((x - self.x0) * self.inv).floor().max(0.0) as usize).min(self.g - 1)
    }

    /// The cell row of ordinate `y`, clamped to the grid. Monotone in `y`.
    #[inline]
    fn row(&self, y: f64) -> usize {
        (((y - self.y0) * self.inv).floor().max(0.0) as usize).min(self.g - 1)
    }
}

impl<const D: usize> Points<D> {
    pub(crate) fn new(cloud: &PointCloud) -> Option<Self> {
        if cloud.dim() != D {
            return None;
        }
        let p = (0..cloud.len())
            .map(|i| {
                let mut a = [0.0; D];
                a.copy_from_slice(cloud.point(i));
                a
            })
            .collect::<Vec<_>>();
        let grid = Grid::new(&p);
        Some(Self { p, grid })
    }
}

impl<const D: usize> Metric for Points<D> {
    fn len(&self) -> usize {
        self.p.len()
    }
    #[inline(always)]
    fn value(&self, i: usize, j: usize) -> f64 {
        sq(&self.p[i], &self.p[j])
    }
    fn to_distance(&self, v: f64) -> f64 {
        v.sqrt()
    }
    fn threshold_value(&self, t: f64) -> f64 {
        sq_threshold(t)
    }

    /// Scans only the grid cells of the box `k` must lie in, or every vertex (the default)
    /// when that box covers more than half the grid.
    #[inline]
    fn cofacets(
        &self,
        a: usize,
        b: usize,
        d: f64,
        lo: f64,
        hi: f64,
        mut f: impl FnMut(usize, f64),
    ) {
        const W: usize = 16;
        if d > hi {
            return;
        }
        let Some(grid) = &self.grid else {
            return default_cofacets(self, a, b, d, lo, hi, f);
        };
        // √hi, widened so that rounding cannot exclude a point whose computed value is ≤ hi.
        // The margin is relative, which holds while squares are normal numbers: below
        // `TINY` a subnormal square's absolute rounding can admit a point farther than √hi
        // by more than any relative margin, so such bounds (all-but-coincident clouds)
        // scan every vertex.
        const TINY: f64 = 1e-290;
        let r = hi.sqrt() * (1.0 + 1e-9);
        if !r.is_finite() || hi < TINY {
            return default_cofacets(self, a, b, d, lo, hi, f);
        }
        let (pa, pb) = (&self.p[a], &self.p[b]);
        let (xlo, xhi) = (pa[0].max(pb[0]) - r, pa[0].min(pb[0]) + r);
        let (ylo, yhi) = (pa[1].max(pb[1]) - r, pa[1].min(pb[1]) + r);
        if xlo > xhi || ylo > yhi {
            return;
        }
        let (c0, c1) = (grid.col(xlo), grid.col(xhi));
        let (r0, r1) = (grid.row(ylo), grid.row(yhi));
        if 2 * (c1 - c0 + 1) * (r1 - r0 + 1) > grid.g * grid.g {
            return default_cofacets(self, a, b, d, lo, hi, f);
        }
        let value = |q: &[f64; D]| d.max(sq(pa, q)).max(sq(pb, q));
        for row in r0..=r1 {
            let (s, e) = (
                grid.start[row * grid.g + c0],
                grid.start[row * grid.g + c1 + 1],
            );
            let mut i = s;
            while i < e {
                let end = (i + W).min(e);
                let mut any = false;
                for q in &grid.pts[i..end] {
                    let x = value(q);
                    any |= (x <= hi) & (x > lo);
                }
                if any {
                    for j in i..end {
                        let x = value(&grid.pts[j]);
                        let k = grid.idx[j] as usize;
                        if x <= hi && x > lo && k != a && k != b {
                            f(k, x);
                        }
                    }
                }
                i = end;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_threshold_is_tight() {
        for t in [0.0, 0.1, 0.3, 1.0, 2.5, 1e-7, 12345.678] {
            let s = sq_threshold(t);
            assert!(s.sqrt() <= t);
            assert!(s.next_up().sqrt() > t);
        }
    }

    #[test]
    fn points_and_full_agree() {
        let c = PointCloud::from_rows(&[[0.0, 0.0], [3.0, 4.0], [1.0, -2.0]]).unwrap();
        let p = Points::<2>::new(&c).unwrap();
        let f = Full::squared_from_points(&c);
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(p.value(i, j), f.value(i, j));
                assert_eq!(p.value(i, j), p.value(j, i));
            }
        }
        assert_eq!(p.to_distance(p.value(0, 1)), 5.0);
    }

    /// A deterministic xorshift stream in [0, 1).
    fn stream(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Every cofacet `Metric::cofacets` reports, as `(k, value bits)`, sorted.
    fn listed<M: Metric>(
        m: &M,
        a: usize,
        b: usize,
        lo: f64,
        hi: f64,
        grid: bool,
    ) -> Vec<(usize, u64)> {
        let d = m.value(a, b);
        let mut out = Vec::new();
        if grid {
            m.cofacets(a, b, d, lo, hi, |k, x| out.push((k, x.to_bits())));
        } else {
            default_cofacets(m, a, b, d, lo, hi, |k, x| out.push((k, x.to_bits())));
        }
        out.sort_unstable();
        out
    }

    /// The grid scan reports exactly the cofacets of the full scan, with the same values,
    /// on clouds with clusters, exact duplicates, collinear runs and points on cell
    /// boundaries, for ranges from empty to everything.
    #[test]
    fn grid_cofacets_equal_the_full_scan() {
        let mut r = stream(0x2545_f491_4f6c_dd1d);
        let mut rows: Vec<[f64; 3]> = Vec::new();
        for i in 0..600 {
            let p = match i % 4 {
                0 => [100.0 * r(), 60.0 * r(), r()],
                1 => [20.0 + r(), 30.0 + 0.5 * r(), r()],
                2 => [(i / 4) as f64 * 0.5, 7.0, 0.0],
                _ => rows[i - 1],
            };
            rows.push(p);
        }
        let c2 =
            PointCloud::from_rows(&rows.iter().map(|p| [p[0], p[1]]).collect::<Vec<_>>()).unwrap();
        let c3 = PointCloud::from_rows(&rows).unwrap();
        let (p2, p3) = (
            Points::<2>::new(&c2).unwrap(),
            Points::<3>::new(&c3).unwrap(),
        );
        assert!(p2.grid.is_some() && p3.grid.is_some());
        let n = rows.len();
        let mut checked = 0;
        for _ in 0..400 {
            let a = (r() * n as f64) as usize;
            let b = (r() * n as f64) as usize;
            if a == b {
                continue;
            }
            for (lo, hi) in [
                (f64::NEG_INFINITY, 4.0 * r()),
                (f64::NEG_INFINITY, 400.0 * r()),
                (10.0 * r(), 10.0 + 200.0 * r()),
                (0.0, 0.0),
                (f64::NEG_INFINITY, f64::INFINITY),
                (f64::NEG_INFINITY, 1e12),
            ] {
                assert_eq!(
                    listed(&p2, a, b, lo, hi, true),
                    listed(&p2, a, b, lo, hi, false)
                );
                assert_eq!(
                    listed(&p3, a, b, lo, hi, true),
                    listed(&p3, a, b, lo, hi, false)
                );
                checked += 1;
            }
        }
        assert!(checked > 2000);
        // Some ranges were narrow enough to take the grid path and still found cofacets.
        let near = listed(&p2, 1, 5, f64::NEG_INFINITY, 4.0, true);
        assert!(!near.is_empty());
    }

    /// A cloud whose extent is zero in one coordinate, or in both, gets a grid only when it
    /// is usable, and the scan stays exact.
    #[test]
    fn degenerate_clouds_scan_exactly() {
        let line: Vec<[f64; 2]> = (0..300).map(|i| [i as f64, 3.0]).collect();
        let same: Vec<[f64; 2]> = (0..300).map(|_| [1.5, -2.0]).collect();
        for rows in [line, same] {
            let c = PointCloud::from_rows(&rows).unwrap();
            let p = Points::<2>::new(&c).unwrap();
            for (a, b, hi) in [(0, 1, 4.0), (10, 20, 150.0), (299, 0, 1e6), (5, 6, 0.0)] {
                assert_eq!(
                    listed(&p, a, b, f64::NEG_INFINITY, hi, true),
                    listed(&p, a, b, f64::NEG_INFINITY, hi, false)
                );
            }
        }
        // Squared distances in the subnormal range round absolutely, so a point can be
        // farther than the computed √bound by more than any relative margin. Put `q` on the
        // first abscissa of grid column 3 and `a` (and its duplicate `b`) just left of it,
        // at a distance whose square rounds down: the bound is exactly the cofacet's value.
        let mut r = stream(7);
        let mut tiny: Vec<[f64; 2]> = vec![[0.0, 0.0], [1e-158, 1e-158]];
        tiny.extend((0..297).map(|_| [1e-158 * r(), 1e-158 * r()]));
        let grid = Grid::new(&tiny).unwrap();
        let mut x = 3.0 / grid.inv;
        while grid.col(x) < 3 {
            x = x.next_up();
        }
        while grid.col(x.next_down()) == 3 {
            x = x.next_down();
        }
        let dx = 10.4f64.sqrt() * 2f64.powi(-537);
        tiny.extend([[x, 5e-159], [x - dx, 5e-159], [x - dx, 5e-159]]);
        let c = PointCloud::from_rows(&tiny).unwrap();
        let p = Points::<2>::new(&c).unwrap();
        let (q, a, b) = (299, 300, 301);
        let hi = p.value(a, q);
        assert!(hi > 0.0 && hi < f64::MIN_POSITIVE);
        let full = listed(&p, a, b, f64::NEG_INFINITY, hi, false);
        assert!(full.contains(&(q, hi.to_bits())));
        assert_eq!(listed(&p, a, b, f64::NEG_INFINITY, hi, true), full);
    }
}
