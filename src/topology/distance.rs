//! Point clouds and distance matrices.
//!
//! A [`DistanceMatrix`] stores only the strict upper triangle, row by row (SciPy's
//! "condensed" layout): for `i < j` the entry lives at `n·i − i(i+1)/2 + j − i − 1`.
//! That halves the memory of a full matrix, which matters for persistence on a few
//! thousand points.

use super::rips::written;
use thiserror::Error;

/// `n` points in `dim` dimensions, stored row-major in one flat vector.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud {
    dim: usize,
    coords: Vec<f64>,
}

impl PointCloud {
    /// Builds a cloud from a flat row-major buffer. Fails if the buffer length is not a
    /// multiple of `dim` or a coordinate is not finite.
    pub fn new(dim: usize, coords: Vec<f64>) -> Result<Self, MatrixError> {
        if dim == 0 {
            return Err(MatrixError::ZeroDimension);
        }
        if !coords.len().is_multiple_of(dim) {
            return Err(MatrixError::Ragged {
                len: coords.len(),
                dim,
            });
        }
        if let Some(k) = coords.iter().position(|c| !c.is_finite()) {
            return Err(MatrixError::NonFinite {
                row: k / dim,
                col: k % dim,
            });
        }
        if let Some(k) = coords.iter().position(|c| c.abs() > MAX_COORDINATE) {
            return Err(MatrixError::TooLarge {
                row: k / dim,
                col: k % dim,
                value: coords[k],
            });
        }
        Ok(Self { dim, coords })
    }

    /// Builds a cloud from rows; every row must have the same length.
    pub fn from_rows<R: AsRef<[f64]>>(rows: &[R]) -> Result<Self, MatrixError> {
        let dim = rows.first().map(|r| r.as_ref().len()).unwrap_or(1);
        let mut coords = Vec::with_capacity(rows.len() * dim);
        for r in rows {
            let r = r.as_ref();
            if r.len() != dim {
                return Err(MatrixError::Ragged { len: r.len(), dim });
            }
            coords.extend_from_slice(r);
        }
        Self::new(dim.max(1), coords)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.coords.len() / self.dim
    }

    /// Whether the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    /// Ambient dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Coordinates of point `i`.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dim..(i + 1) * self.dim]
    }

    /// The flat row-major coordinate buffer.
    pub fn coords(&self) -> &[f64] {
        &self.coords
    }

    /// Euclidean distance between points `i` and `j`.
    pub fn dist(&self, i: usize, j: usize) -> f64 {
        self.point(i)
            .iter()
            .zip(self.point(j))
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    }
}

/// A symmetric matrix of pairwise distances with a zero diagonal, condensed layout.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceMatrix {
    n: usize,
    data: Vec<f64>,
}

impl DistanceMatrix {
    /// An `n × n` matrix of zeros.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            data: vec![0.0; n * n.saturating_sub(1) / 2],
        }
    }

    /// Fills entry `(i, j)`, `i < j`, with `f(i, j)`.
    pub fn from_fn(n: usize, mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(n * n.saturating_sub(1) / 2);
        for i in 0..n {
            for j in i + 1..n {
                data.push(f(i, j));
            }
        }
        Self { n, data }
    }

    /// Euclidean distances between the points of a cloud.
    pub fn from_points(points: &PointCloud) -> Self {
        Self::from_fn(points.len(), |i, j| points.dist(i, j))
    }

    /// Wraps a condensed buffer (length `n(n−1)/2`), checking entries are finite and ≥ 0.
    pub fn from_condensed(n: usize, data: Vec<f64>) -> Result<Self, MatrixError> {
        let want = n * n.saturating_sub(1) / 2;
        if data.len() != want {
            return Err(MatrixError::CondensedLength {
                len: data.len(),
                want,
            });
        }
        let m = Self { n, data };
        for i in 0..n {
            for j in i + 1..n {
                let v = m.get(i, j);
                if !v.is_finite() || v < 0.0 {
                    return Err(MatrixError::BadEntry {
                        row: i,
                        col: j,
                        value: v,
                    });
                }
            }
        }
        Ok(m)
    }

    /// Reads a full square matrix, checking it is square, symmetric (to `1e-9` relative),
    /// has a zero diagonal and finite non-negative entries. The upper triangle is kept.
    pub fn from_full<R: AsRef<[f64]>>(rows: &[R]) -> Result<Self, MatrixError> {
        let n = rows.len();
        for (i, r) in rows.iter().enumerate() {
            let r = r.as_ref();
            if r.len() != n {
                return Err(MatrixError::NotSquare {
                    row: i,
                    len: r.len(),
                    n,
                });
            }
            if r[i] != 0.0 {
                return Err(MatrixError::Diagonal {
                    row: i,
                    value: r[i],
                });
            }
            for (j, &v) in r.iter().enumerate() {
                if !v.is_finite() || v < 0.0 {
                    return Err(MatrixError::BadEntry {
                        row: i,
                        col: j,
                        value: v,
                    });
                }
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (rows[i].as_ref()[j], rows[j].as_ref()[i]);
                if (a - b).abs() > 1e-9 * a.abs().max(b.abs()).max(f64::MIN_POSITIVE) {
                    return Err(MatrixError::Asymmetric {
                        row: i,
                        col: j,
                        a,
                        b,
                    });
                }
            }
        }
        Ok(Self::from_fn(n, |i, j| rows[i].as_ref()[j]))
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether the matrix is empty.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    #[inline]
    fn index(&self, i: usize, j: usize) -> usize {
        debug_assert!(i < j && j < self.n);
        self.n * i - i * (i + 1) / 2 + j - i - 1
    }

    /// Distance between `i` and `j` (zero on the diagonal).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        use std::cmp::Ordering::*;
        match i.cmp(&j) {
            Less => self.data[self.index(i, j)],
            Greater => self.data[self.index(j, i)],
            Equal => 0.0,
        }
    }

    /// Sets the distance between `i ≠ j`.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        let k = if i < j {
            self.index(i, j)
        } else {
            self.index(j, i)
        };
        self.data[k] = v;
    }

    /// The condensed buffer (upper triangle, row by row).
    pub fn condensed(&self) -> &[f64] {
        &self.data
    }

    /// The sub-matrix on the given indices, in their order.
    pub fn subset(&self, idx: &[usize]) -> Self {
        Self::from_fn(idx.len(), |a, b| self.get(idx[a], idx[b]))
    }
}

/// Largest |coordinate| of a [`PointCloud`]: the squared difference of two coordinates stays
/// below 4e300, so Euclidean distances in up to ~40 dimensions cannot overflow f64 (beyond
/// that they would silently become infinite and every class essential).
pub const MAX_COORDINATE: f64 = 1e150;

/// What is wrong with a point cloud or distance matrix.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MatrixError {
    #[error("points must have at least one coordinate")]
    ZeroDimension,
    #[error(
        "{len} coordinates do not split into points of dimension {dim}; every row needs the same number of columns"
    )]
    Ragged { len: usize, dim: usize },
    #[error("coordinate {col} of point {row} is not a finite number")]
    NonFinite { row: usize, col: usize },
    #[error(
        "coordinate {col} of point {row} is {}, beyond ±1e150: squared distances would overflow; rescale the points",
        written(*.value)
    )]
    TooLarge { row: usize, col: usize, value: f64 },
    #[error("a condensed matrix for this many points needs {want} entries, got {len}")]
    CondensedLength { len: usize, want: usize },
    #[error(
        "row {row} has {len} entries but the matrix has {n} rows; a distance matrix must be square"
    )]
    NotSquare { row: usize, len: usize, n: usize },
    #[error(
        "diagonal entry ({row}, {row}) is {}; a point is at distance 0 from itself",
        written(*.value)
    )]
    Diagonal { row: usize, value: f64 },
    #[error(
        "entry ({row}, {col}) is {}; distances must be finite and non-negative",
        written(*.value)
    )]
    BadEntry { row: usize, col: usize, value: f64 },
    #[error(
        "entries ({row}, {col}) = {} and ({col}, {row}) = {} differ; a distance matrix must be symmetric",
        written(*.a),
        written(*.b)
    )]
    Asymmetric {
        row: usize,
        col: usize,
        a: f64,
        b: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn condensed_layout_matches_scipy() {
        let m = DistanceMatrix::from_fn(4, |i, j| (10 * i + j) as f64);
        assert_eq!(m.condensed(), &[1.0, 2.0, 3.0, 12.0, 13.0, 23.0]);
        assert_eq!(m.get(3, 1), 13.0);
        assert_eq!(m.get(2, 2), 0.0);
    }

    #[test]
    fn full_matrix_checks() {
        let ok = vec![vec![0.0, 1.0], vec![1.0, 0.0]];
        assert_eq!(DistanceMatrix::from_full(&ok).unwrap().get(0, 1), 1.0);
        let asym = vec![vec![0.0, 1.0], vec![2.0, 0.0]];
        assert!(matches!(
            DistanceMatrix::from_full(&asym),
            Err(MatrixError::Asymmetric { .. })
        ));
        let neg = vec![vec![0.0, -1.0], vec![-1.0, 0.0]];
        assert!(matches!(
            DistanceMatrix::from_full(&neg),
            Err(MatrixError::BadEntry { .. })
        ));
    }
}
