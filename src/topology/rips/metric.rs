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
            .collect();
        Some(Self { p })
    }
}

impl<const D: usize> Metric for Points<D> {
    fn len(&self) -> usize {
        self.p.len()
    }
    #[inline(always)]
    fn value(&self, i: usize, j: usize) -> f64 {
        let (a, b) = (&self.p[i], &self.p[j]);
        let mut s = 0.0;
        for k in 0..D {
            let d = a[k] - b[k];
            s += d * d;
        }
        s
    }
    fn to_distance(&self, v: f64) -> f64 {
        v.sqrt()
    }
    fn threshold_value(&self, t: f64) -> f64 {
        sq_threshold(t)
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
}
