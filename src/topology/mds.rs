//! Classical and landmark multidimensional scaling (paper §"Geometric Reconstruction": the
//! encounter distances are embedded Isomap-style, k = 3).
//!
//! # Classical MDS (Torgerson 1952; Gower 1966)
//! For squared distances `D²` the double-centred matrix `B = −½ J D² J`, `J = I − 11ᵀ/n`, is the
//! Gram matrix of the centred points when `D` is Euclidean. The embedding takes its top-k
//! eigenpairs, `X = U_k Λ_k^{1/2}`. For non-Euclidean inputs `B` has negative eigenvalues: those
//! among the top k are clipped to 0 and counted ([`Embedding::clipped`]), and the share of
//! negative spectrum is reported ([`Embedding::negative_mass`]).
//!
//! # Partial eigensolver: block Krylov with Rayleigh–Ritz
//! `B` is never formed. Its product with a block of `p` vectors is `−½ J (D² (J X))`: centre the
//! columns, one symmetric pass over the condensed matrix squaring entries on the fly (rayon,
//! rows split in equal-work chunks, one accumulator per chunk, reduced in a fixed order so the
//! result is deterministic), centre again. One pass costs O(n² p) flops and reads the n(n−1)/2
//! buffer once. The solver grows an orthonormal basis of the block Krylov space
//! `span{X₀, BX₀, B²X₀, …}` (block Lanczos with full reorthogonalisation by two rounds of
//! classical Gram–Schmidt, Golub & Van Loan §10.3), keeps the products `BQ`, and after every
//! block solves the small projected problem `QᵀBQ` densely (nalgebra's `SymmetricEigen`). It
//! stops when the top-k Ritz pairs have residual `‖Bu − θu‖ ≤ tol·max|θ|`. The block size
//! `p = k + 5` captures eigenvalues of multiplicity up to `p` (a circle gives a double top
//! eigenvalue, which single-vector Lanczos would miss). The start block is pseudo-random from a
//! fixed seed and orthogonal to `1` (`B1 = 0`, so the whole basis stays in `1⊥`). Cost:
//! O(n² p · blocks + n m²) for a basis of m vectors; n = 5 000, k = 3 typically needs 5–15
//! blocks. Collapsed directions (an exact invariant subspace, or a null space) are replaced by
//! fresh random vectors, so low-rank and all-zero inputs need no special case.
//!
//! # The spectrum's masses
//! [`Embedding::explained`] and [`Embedding::negative_mass`] need the sums `P` and `N` of the
//! positive and negative eigenvalues over the whole spectrum. For n − 1 ≤
//! [`MdsOptions::exact_below`] the basis is grown to all of `1⊥` and they are exact. Above, the
//! part of the spectrum outside the basis is estimated: its trace `tr B − tr QᵀBQ` is exact
//! (`tr B = Σ_{i<j} d²_ij / n`), and `tr |R|` of the remainder `R = P⊥BP⊥` comes from stochastic
//! Lanczos quadrature (Ubaru, Chen & Saad 2017) on Rademacher probes projected off the basis, a
//! deflated Hutchinson estimate in the spirit of Hutch++ (Meyer et al. 2021). Then
//! `P_R = (tr R + tr|R|)/2`, `N_R = (tr|R| − tr R)/2`. [`Embedding::spectrum_exact`] says which.
//!
//! # Landmark MDS (de Silva & Tenenbaum 2004)
//! Classical MDS on the m × m landmark distances gives `L_k = Λ_k^{1/2} V_kᵀ`; every point `a`
//! (landmark or not) is placed by distance-based triangulation
//! `x_a = −½ L_k^# (δ_a − δ_μ)`, `L_k^# = Λ_k^{−1/2} V_kᵀ`, where `δ_a` are the squared distances
//! from `a` to the landmarks and `δ_μ` their column means over the landmarks. O(m² ·) for the
//! landmark problem plus O(n m k) for the triangulation; memory O(n m), never n².

use super::distance::{DistanceMatrix, PointCloud};
use nalgebra::{DMatrix, SymmetricEigen};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use thiserror::Error;

/// An embedding of n points in k dimensions and what it kept of the spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct Embedding {
    /// The coordinates, n × k (unit of the input distances). Column c is `sqrt(λ_c) · u_c`, or
    /// 0 when `λ_c ≤ 1e-9 · max|λ|` (clipped or rounding noise); each eigenvector's
    /// largest-magnitude entry is made positive.
    pub coords: PointCloud,
    /// The top k eigenvalues of `B = −½ J D² J`, descending, before clipping (unit: squared
    /// distance). Padded with zeros when n < k.
    pub eigenvalues: Vec<f64>,
    /// Share of the positive spectrum's sum carried by the kept positive eigenvalues, in [0, 1]
    /// (1 when the spectrum has no positive part).
    pub explained: f64,
    /// How many of the top k eigenvalues were negative (below `−1e-9 · max|λ|`, i.e. beyond
    /// rounding) and clipped to 0.
    pub clipped: usize,
    /// `|Σ negative λ| / Σ |λ|` over the whole spectrum, in [0, 1]: 0 for Euclidean distances.
    pub negative_mass: f64,
    /// Whether `explained` and `negative_mass` come from the whole spectrum (true) or from the
    /// stochastic estimate of the part the solver did not resolve (false); see the module docs.
    pub spectrum_exact: bool,
}

/// Tuning of the eigensolver. The defaults suit every input; tests use them to force a path.
#[derive(Debug, Clone, PartialEq)]
pub struct MdsOptions {
    /// Residual tolerance relative to the spectral radius (default: `1e-10`).
    pub tol: f64,
    /// Grow the basis to the whole space, giving an exact spectrum, when n − 1 is at most this
    /// (default: `200`).
    pub exact_below: usize,
    /// Largest basis size before giving up with [`MdsError::NotConverged`] (default: `1000`).
    pub max_basis: usize,
    /// Rademacher probes for the spectral-mass estimate (default: `8`).
    pub probes: usize,
    /// Lanczos steps per probe for the spectral-mass estimate (default: `12`).
    pub probe_steps: usize,
    /// Seed of the start block and the probes (default: `0x5eed`).
    pub seed: u64,
}

impl Default for MdsOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            exact_below: 200,
            max_basis: 1000,
            probes: 8,
            probe_steps: 12,
            seed: 0x5eed,
        }
    }
}

/// What went wrong in an MDS call.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MdsError {
    #[error("the target dimension k must be at least 1")]
    ZeroDimension,
    #[error("landmark MDS needs at least one landmark")]
    NoLandmarks,
    #[error("{rows} distance rows given for {landmarks} landmarks; give one row per landmark")]
    RowCount { rows: usize, landmarks: usize },
    #[error(
        "distance row {row} has {len} entries but row 0 has {want}; every row covers all points"
    )]
    RowLength { row: usize, len: usize, want: usize },
    #[error("landmark {index} is point {landmark}, but there are only {n} points")]
    LandmarkOutOfRange {
        index: usize,
        landmark: usize,
        n: usize,
    },
    #[error("distance ({row}, {col}) is {value}; distances must be finite and non-negative")]
    BadDistance { row: usize, col: usize, value: f64 },
    #[error(
        "landmarks {a} and {b} are {ab} apart one way and {ba} the other; landmark distances must be symmetric"
    )]
    Asymmetric {
        a: usize,
        b: usize,
        ab: f64,
        ba: f64,
    },
    #[error("the squared distances overflow f64; rescale the distances (e.g. to kilometres)")]
    Overflow,
    #[error(
        "the eigensolver did not converge within a basis of {basis} vectors (residual {residual:e}); raise MdsOptions::max_basis"
    )]
    NotConverged { basis: usize, residual: f64 },
}

/// Eigenvalues whose magnitude is below this share of the spectral radius are rounding noise.
const ZERO_REL: f64 = 1e-9;

/// Classical MDS of `d` into `k` dimensions with the default [`MdsOptions`].
pub fn classical_mds(d: &DistanceMatrix, k: usize) -> Result<Embedding, MdsError> {
    classical_mds_with(d, k, &MdsOptions::default())
}

/// Classical MDS of `d` into `k` dimensions.
pub fn classical_mds_with(
    d: &DistanceMatrix,
    k: usize,
    opts: &MdsOptions,
) -> Result<Embedding, MdsError> {
    let spec = top_spectrum(d, k, opts)?;
    let n = d.len();
    let mut coords = vec![0.0; n * k];
    let noise = spec.noise();
    for (c, (lam, u)) in spec.values.iter().zip(&spec.vectors).enumerate() {
        if *lam > noise {
            let s = lam.sqrt();
            for (i, ui) in u.iter().enumerate() {
                coords[i * k + c] = s * ui;
            }
        }
    }
    spec.into_embedding(k, coords)
}

/// Landmark MDS (de Silva & Tenenbaum 2004).
///
/// `rows[i][j]` is the distance from point `landmarks[i]` to point `j`, for all n points (so
/// `rows[i][landmarks[i]] = 0`). The landmarks' own distances must be symmetric to `1e-9`
/// relative. The reported spectrum is the landmark problem's. With fewer than k + 1
/// non-degenerate landmarks the missing axes are 0.
pub fn landmark_mds(
    landmarks: &[usize],
    rows: &[Vec<f64>],
    k: usize,
) -> Result<Embedding, MdsError> {
    landmark_mds_with(landmarks, rows, k, &MdsOptions::default())
}

/// [`landmark_mds`] with explicit solver options.
pub fn landmark_mds_with(
    landmarks: &[usize],
    rows: &[Vec<f64>],
    k: usize,
    opts: &MdsOptions,
) -> Result<Embedding, MdsError> {
    if k == 0 {
        return Err(MdsError::ZeroDimension);
    }
    let m = landmarks.len();
    if m == 0 {
        return Err(MdsError::NoLandmarks);
    }
    if rows.len() != m {
        return Err(MdsError::RowCount {
            rows: rows.len(),
            landmarks: m,
        });
    }
    let n = rows[0].len();
    for (row, r) in rows.iter().enumerate() {
        if r.len() != n {
            return Err(MdsError::RowLength {
                row,
                len: r.len(),
                want: n,
            });
        }
        if let Some(col) = r.iter().position(|v| !v.is_finite() || *v < 0.0) {
            return Err(MdsError::BadDistance {
                row,
                col,
                value: r[col],
            });
        }
    }
    if let Some(index) = landmarks.iter().position(|&l| l >= n) {
        return Err(MdsError::LandmarkOutOfRange {
            index,
            landmark: landmarks[index],
            n,
        });
    }
    for a in 0..m {
        for b in a + 1..m {
            let (ab, ba) = (rows[a][landmarks[b]], rows[b][landmarks[a]]);
            if (ab - ba).abs() > 1e-9 * ab.max(ba) {
                return Err(MdsError::Asymmetric { a, b, ab, ba });
            }
        }
    }
    let dl = DistanceMatrix::from_fn(m, |a, b| {
        0.5 * (rows[a][landmarks[b]] + rows[b][landmarks[a]])
    });
    let spec = top_spectrum(&dl, k, opts)?;
    let noise = spec.noise();

    // δ_μ: mean squared distance from each landmark to the landmarks.
    let mean_sq: Vec<f64> = (0..m)
        .map(|j| (0..m).map(|a| dl.get(a, j).powi(2)).sum::<f64>() / m as f64)
        .collect();
    // Rows of the pseudo-inverse L_k^# = Λ^{-1/2} Vᵀ (zero for clipped axes).
    let pinv: Vec<Vec<f64>> = spec
        .values
        .iter()
        .zip(&spec.vectors)
        .map(|(&lam, v)| {
            if lam > noise {
                v.iter().map(|x| x / lam.sqrt()).collect()
            } else {
                vec![0.0; m]
            }
        })
        .collect();
    let mut coords = vec![0.0; n * k];
    coords.par_chunks_mut(k).enumerate().for_each(|(p, out)| {
        for (c, row) in pinv.iter().enumerate() {
            let s: f64 = (0..m)
                .map(|j| row[j] * (rows[j][p] * rows[j][p] - mean_sq[j]))
                .sum();
            out[c] = -0.5 * s;
        }
    });
    spec.into_embedding(k, coords)
}

/// The top of the spectrum of `B` and the masses of the whole spectrum.
struct Spectrum {
    /// Top eigenvalues of B (n × n, the constant vector's 0 included), descending, ≤ k of them.
    values: Vec<f64>,
    /// Matching unit eigenvectors, each of length n.
    vectors: Vec<Vec<f64>>,
    pos_mass: f64,
    neg_mass: f64,
    exact: bool,
    /// Largest |Ritz value|, an estimate of the spectral radius of B.
    radius: f64,
}

impl Spectrum {
    /// Eigenvalues at most this large are rounding noise (of either sign): they get no axis,
    /// since `sqrt` would turn 1e-16 into 1e-8 and landmark MDS would divide by it.
    fn noise(&self) -> f64 {
        ZERO_REL * self.radius
    }

    /// The embedding, or [`MdsError::Overflow`] when a coordinate is not finite: the
    /// landmarks' own distances can be small while the rows to other points are finite but
    /// so large that their squares overflow (landmark MDS squares every row entry).
    fn into_embedding(self, k: usize, coords: Vec<f64>) -> Result<Embedding, MdsError> {
        let noise = self.noise();
        let mut eigenvalues = self.values;
        eigenvalues.resize(k, 0.0);
        let clipped = eigenvalues.iter().filter(|&&l| l < -noise).count();
        let kept: f64 = eigenvalues.iter().filter(|&&l| l > 0.0).sum();
        let explained = if self.pos_mass > 0.0 {
            (kept / self.pos_mass).min(1.0)
        } else {
            1.0
        };
        let total = self.pos_mass + self.neg_mass;
        let negative_mass = if total > 0.0 {
            self.neg_mass / total
        } else {
            0.0
        };
        // k ≥ 1 is checked before any embedding is built, so the only way PointCloud::new
        // can fail is a non-finite coordinate.
        let coords = PointCloud::new(k, coords).map_err(|_| MdsError::Overflow)?;
        Ok(Embedding {
            coords,
            eigenvalues,
            explained,
            clipped,
            negative_mass,
            spectrum_exact: self.exact,
        })
    }
}

/// Top-k eigenpairs of `B = −½ J D² J` (block Krylov + Rayleigh–Ritz) and the spectral masses.
fn top_spectrum(d: &DistanceMatrix, k: usize, opts: &MdsOptions) -> Result<Spectrum, MdsError> {
    if k == 0 {
        return Err(MdsError::ZeroDimension);
    }
    let n = d.len();
    // DistanceMatrix::from_fn does not validate, so check here: NaN would stall the eigensolver.
    if let Some(pos) = d
        .condensed()
        .iter()
        .position(|v| !v.is_finite() || *v < 0.0)
    {
        let (row, col) = condensed_position(n, pos);
        return Err(MdsError::BadDistance {
            row,
            col,
            value: d.condensed()[pos],
        });
    }
    let trace_b = d.condensed().iter().map(|x| x * x).sum::<f64>() / n.max(1) as f64;
    if !trace_b.is_finite() {
        return Err(MdsError::Overflow);
    }
    let dim = n.saturating_sub(1); // B lives on 1⊥
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let exhaustive = dim <= opts.exact_below;
    let p = (k + 5).min(dim);

    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut bq: Vec<Vec<f64>> = Vec::new();
    // Projected matrix QᵀBQ, grown by columns; h[j][i] = q_i · (B q_j).
    let mut h: Vec<Vec<f64>> = Vec::new();
    let mut block = fresh_block(p, &q, n, &mut rng);
    let mut ritz: Option<(Vec<f64>, DMatrix<f64>)> = None;
    while !block.is_empty() {
        let products = apply_b(d, &block);
        for (v, w) in block.into_iter().zip(products) {
            q.push(v);
            bq.push(w);
        }
        let m = q.len();
        for w in &bq[h.len()..m] {
            let col: Vec<f64> = q.iter().map(|qi| dot(qi, w)).collect();
            h.push(col);
        }
        for col in h.iter_mut() {
            col.resize(m, f64::NAN);
        }
        let full = m >= dim;
        if full || !exhaustive {
            let hm = DMatrix::from_fn(m, m, |i, j| {
                let (a, b) = (h[j][i], h[i][j]);
                if a.is_nan() {
                    b
                } else if b.is_nan() {
                    a
                } else {
                    0.5 * (a + b)
                }
            });
            let eig = SymmetricEigen::new(hm);
            let order = descending(eig.eigenvalues.as_slice());
            let values: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
            let radius = values.iter().fold(0.0f64, |a, l| a.max(l.abs()));
            let mut worst = 0.0f64;
            for &i in order.iter().take(k) {
                let s = eig.eigenvectors.column(i);
                let mut r = vec![0.0; n];
                for j in 0..m {
                    axpy(s[j], &bq[j], &mut r);
                    axpy(-eig.eigenvalues[i] * s[j], &q[j], &mut r);
                }
                worst = worst.max(norm(&r));
            }
            let sorted_vecs = DMatrix::from_fn(m, m, |r, c| eig.eigenvectors[(r, order[c])]);
            ritz = Some((values, sorted_vecs));
            if full || worst <= opts.tol * radius || radius == 0.0 {
                break;
            }
            if m >= opts.max_basis {
                return Err(MdsError::NotConverged {
                    basis: m,
                    residual: worst / radius,
                });
            }
        }
        // Next block: B times the newest block, made orthogonal to everything so far.
        let newest = bq[bq.len() - p.min(bq.len())..].to_vec();
        block = extend_basis(newest, &q, dim, &mut rng);
    }

    let (values, vecs) = ritz.unwrap_or_else(|| (Vec::new(), DMatrix::zeros(0, 0)));
    let radius = values.iter().fold(0.0f64, |a, l| a.max(l.abs()));
    let m = q.len();
    let ritz_vector = |c: usize| -> Vec<f64> {
        let mut u = vec![0.0; n];
        for j in 0..m {
            axpy(vecs[(j, c)], &q[j], &mut u);
        }
        fix_sign(&mut u);
        u
    };
    let exact = m >= dim;
    let (pos_mass, neg_mass) = if exact {
        masses(&values)
    } else {
        let (pq, nq) = masses(&values);
        let trace_r = trace_b - values.iter().sum::<f64>();
        let abs_r = slq_abs_trace(d, &q, opts, &mut rng).max(trace_r.abs());
        (pq + 0.5 * (abs_r + trace_r), nq + 0.5 * (abs_r - trace_r))
    };

    // Merge in the constant vector's eigenvalue 0, which the 1⊥ solver never sees.
    let mut out_vals = Vec::with_capacity(k);
    let mut out_vecs = Vec::with_capacity(k);
    let mut c = 0;
    let mut constant_used = n == 0;
    while out_vals.len() < k {
        let next = values.get(c).copied();
        match next {
            Some(v) if v >= 0.0 || constant_used => {
                out_vals.push(v);
                out_vecs.push(ritz_vector(c));
                c += 1;
            }
            _ if !constant_used => {
                constant_used = true;
                out_vals.push(0.0);
                out_vecs.push(vec![1.0 / (n as f64).sqrt(); n]);
            }
            _ => break,
        }
    }
    Ok(Spectrum {
        values: out_vals,
        vectors: out_vecs,
        pos_mass,
        neg_mass,
        exact,
        radius,
    })
}

/// `(i, j)`, `i < j`, of position `pos` in the condensed layout of an `n × n` matrix.
fn condensed_position(n: usize, pos: usize) -> (usize, usize) {
    let mut start = 0;
    for i in 0..n {
        let len = n - i - 1;
        if pos < start + len {
            return (i, i + 1 + pos - start);
        }
        start += len;
    }
    (n, n)
}

/// Sums of the positive and of the negative (as a magnitude) values, ignoring rounding noise.
fn masses(values: &[f64]) -> (f64, f64) {
    let radius = values.iter().fold(0.0f64, |a, l| a.max(l.abs()));
    let noise = ZERO_REL * radius;
    let pos = values.iter().filter(|&&l| l > noise).sum();
    let neg = values.iter().filter(|&&l| l < -noise).map(|l| -l).sum();
    (pos, neg)
}

/// Indices sorting `v` in descending order (ties by index).
fn descending(v: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| v[b].total_cmp(&v[a]).then(a.cmp(&b)));
    idx
}

/// Makes the largest-magnitude entry positive (first such entry on ties).
fn fix_sign(u: &mut [f64]) {
    let mut best = (0.0f64, 0usize);
    for (i, x) in u.iter().enumerate() {
        if x.abs() > best.0 {
            best = (x.abs(), i);
        }
    }
    if u.get(best.1).is_some_and(|&x| x < 0.0) {
        u.iter_mut().for_each(|x| *x = -*x);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for t in 0..4 {
            acc[t] += x[t] * y[t];
        }
    }
    acc[0] + acc[1] + acc[2] + acc[3] + tail
}

fn axpy(s: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += s * xi;
    }
}

fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

fn centre(x: &mut [f64]) {
    if x.is_empty() {
        return;
    }
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.iter_mut().for_each(|v| *v -= mean);
}

/// Removes from `v` its components along `basis` (orthonormal) and along `1`: two rounds of
/// classical Gram–Schmidt. Returns the norm left.
fn project_out(v: &mut [f64], basis: &[Vec<f64>]) -> f64 {
    for _ in 0..2 {
        centre(v);
        let coef: Vec<f64> = basis.par_iter().map(|b| dot(b, v)).collect();
        for (c, b) in coef.iter().zip(basis) {
            axpy(-c, b, v);
        }
    }
    norm(v)
}

/// Orthonormalises `cands` against `basis` and each other; a candidate that collapses (it lay
/// in the span already) is replaced by a random vector, unless `1⊥` (dimension `dim`) is full.
fn extend_basis(
    cands: Vec<Vec<f64>>,
    basis: &[Vec<f64>],
    dim: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Vec<f64>> {
    let mut all: Vec<Vec<f64>> = basis.to_vec();
    let start = all.len();
    for mut v in cands {
        if all.len() >= dim {
            break;
        }
        let before = norm(&v);
        let mut after = project_out(&mut v, &all);
        let mut tries = 0;
        while !(after > 1e-8 * before && after > 0.0) && tries < 3 {
            v = random_vector(v.len(), rng);
            let b = norm(&v);
            after = project_out(&mut v, &all);
            if after > 1e-8 * b {
                break;
            }
            tries += 1;
        }
        if after > 0.0 && after.is_finite() && tries < 3 {
            v.iter_mut().for_each(|x| *x /= after);
            all.push(v);
        }
    }
    all.split_off(start)
}

fn fresh_block(p: usize, basis: &[Vec<f64>], n: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let cands = (0..p).map(|_| random_vector(n, rng)).collect();
    extend_basis(cands, basis, n.saturating_sub(1), rng)
}

fn random_vector(n: usize, rng: &mut ChaCha8Rng) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

/// `B x = −½ J D² J x` for each vector of the block.
fn apply_b(d: &DistanceMatrix, xs: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out = Vec::with_capacity(xs.len());
    let mut rest = xs;
    while !rest.is_empty() {
        let w = match rest.len() {
            8.. => 8,
            4..=7 => 4,
            2..=3 => 2,
            _ => 1,
        };
        let (head, tail) = rest.split_at(w);
        let ys = match w {
            8 => d2_times::<8>(d, head),
            4 => d2_times::<4>(d, head),
            2 => d2_times::<2>(d, head),
            _ => d2_times::<1>(d, head),
        };
        out.extend(ys);
        rest = tail;
    }
    for y in out.iter_mut() {
        centre(y);
        y.iter_mut().for_each(|v| *v *= -0.5);
    }
    out
}

/// `D² (J x)` for `W` vectors at once, in one pass over the condensed matrix.
fn d2_times<const W: usize>(d: &DistanceMatrix, xs: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = d.len();
    let mut x = vec![0.0; n * W];
    for (c, v) in xs.iter().enumerate() {
        let mean = v.iter().sum::<f64>() / n.max(1) as f64;
        for i in 0..n {
            x[i * W + c] = v[i] - mean;
        }
    }
    let cond = d.condensed();
    let row_start = |i: usize| n * i - i * (i + 1) / 2;
    // Equal-work row ranges; a fixed count (not the thread count) keeps sums deterministic.
    let chunks = 16.min(n.max(1));
    let total = cond.len();
    let mut bounds = vec![0usize];
    let mut i = 0;
    for c in 1..chunks {
        let target = total * c / chunks;
        while i < n && row_start(i) < target {
            i += 1;
        }
        bounds.push(i);
    }
    bounds.push(n);
    let partial: Vec<Vec<f64>> = bounds
        .par_windows(2)
        .map(|r| {
            let mut y = vec![0.0; n * W];
            for i in r[0]..r[1] {
                let len = n - i - 1;
                let row = &cond[row_start(i)..row_start(i) + len];
                let mut xi = [0.0; W];
                xi.copy_from_slice(&x[i * W..i * W + W]);
                let mut acc = [0.0; W];
                let xs = x[(i + 1) * W..].chunks_exact(W);
                let ys = y[(i + 1) * W..].chunks_exact_mut(W);
                for ((&dv, xj), yj) in row.iter().zip(xs).zip(ys) {
                    let w2 = dv * dv;
                    for c in 0..W {
                        acc[c] += w2 * xj[c];
                        yj[c] += w2 * xi[c];
                    }
                }
                for c in 0..W {
                    y[i * W + c] += acc[c];
                }
            }
            y
        })
        .collect();
    let mut sum = vec![0.0; n * W];
    for part in &partial {
        axpy(1.0, part, &mut sum);
    }
    (0..xs.len())
        .map(|c| (0..n).map(|i| sum[i * W + c]).collect())
        .collect()
}

/// Stochastic Lanczos quadrature estimate of `tr |R|`, `R = P⊥ B P⊥` with `P⊥` projecting off
/// `basis` and `1`: Rademacher probes projected off the basis, `probe_steps` Lanczos steps each
/// (full reorthogonalisation), Gauss quadrature `‖z‖² Σ τ_j² |θ_j|`.
fn slq_abs_trace(
    d: &DistanceMatrix,
    basis: &[Vec<f64>],
    opts: &MdsOptions,
    rng: &mut ChaCha8Rng,
) -> f64 {
    let n = d.len();
    let probes = opts.probes.max(1);
    let steps = opts.probe_steps.max(1);
    // Per probe: Lanczos vectors, alphas, betas, squared start norm, still running.
    let mut lv: Vec<Vec<Vec<f64>>> = Vec::with_capacity(probes);
    let mut alpha: Vec<Vec<f64>> = vec![Vec::new(); probes];
    let mut beta: Vec<Vec<f64>> = vec![Vec::new(); probes];
    let mut start_sq = vec![0.0; probes];
    let mut running = vec![true; probes];
    for s in start_sq.iter_mut() {
        let mut z: Vec<f64> = (0..n)
            .map(|_| if rng.random::<bool>() { 1.0 } else { -1.0 })
            .collect();
        let nz = project_out(&mut z, basis);
        *s = nz * nz;
        if nz > 0.0 {
            z.iter_mut().for_each(|x| *x /= nz);
        }
        lv.push(vec![z]);
    }
    for (p, s) in start_sq.iter().enumerate() {
        running[p] = *s > 0.0;
    }
    for _ in 0..steps {
        let active: Vec<usize> = (0..probes).filter(|&p| running[p]).collect();
        if active.is_empty() {
            break;
        }
        let current: Vec<Vec<f64>> = active
            .iter()
            .map(|&p| lv[p].last().cloned().unwrap_or_default())
            .collect();
        let products = apply_b(d, &current);
        for (&p, mut w) in active.iter().zip(products) {
            project_out(&mut w, basis);
            let v = &lv[p];
            let a = dot(&w, &v[v.len() - 1]);
            alpha[p].push(a);
            let before = norm(&w);
            let b = project_out(&mut w, v);
            if b <= 1e-10 * before.max(f64::MIN_POSITIVE) || alpha[p].len() >= n {
                running[p] = false;
                continue;
            }
            w.iter_mut().for_each(|x| *x /= b);
            beta[p].push(b);
            lv[p].push(w);
        }
    }
    let mut total = 0.0;
    for p in 0..probes {
        let m = alpha[p].len();
        if m == 0 {
            continue;
        }
        let t = DMatrix::from_fn(m, m, |i, j| {
            if i == j {
                alpha[p][i]
            } else if i + 1 == j || j + 1 == i {
                beta[p][i.min(j)]
            } else {
                0.0
            }
        });
        let eig = SymmetricEigen::new(t);
        let quad: f64 = (0..m)
            .map(|j| eig.eigenvectors[(0, j)].powi(2) * eig.eigenvalues[j].abs())
            .sum();
        total += start_sq[p] * quad;
    }
    total / probes as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_k_and_tiny_inputs() {
        let d = DistanceMatrix::zeros(3);
        assert_eq!(classical_mds(&d, 0), Err(MdsError::ZeroDimension));
        let e = classical_mds(&d, 2).unwrap();
        assert_eq!(e.eigenvalues, vec![0.0, 0.0]);
        assert_eq!(e.coords.coords(), &[0.0; 6]);
        assert_eq!((e.explained, e.negative_mass, e.clipped), (1.0, 0.0, 0));
        let empty = classical_mds(&DistanceMatrix::zeros(0), 3).unwrap();
        assert!(empty.coords.is_empty());
        // Two points 2 apart: B has eigenvalues 2 and 0.
        let nan = DistanceMatrix::from_fn(3, |i, j| if (i, j) == (1, 2) { f64::NAN } else { 1.0 });
        assert!(matches!(
            classical_mds(&nan, 2),
            Err(MdsError::BadDistance { row: 1, col: 2, .. })
        ));
        let huge = DistanceMatrix::from_fn(3, |_, _| 1e200);
        assert_eq!(classical_mds(&huge, 2), Err(MdsError::Overflow));
        // Landmarks close together, a point finite but so far that its squared distances
        // overflow: an error, not an embedding without points (which callers indexed).
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|a| {
                let mut r: Vec<f64> = (0..3).map(|b| if a == b { 0.0 } else { 1.0 }).collect();
                r.push(1e200);
                r
            })
            .collect();
        assert!(matches!(
            landmark_mds(&[0, 1, 2], &rows, 2),
            Err(MdsError::Overflow)
        ));
        let two = DistanceMatrix::from_condensed(2, vec![2.0]).unwrap();
        let e = classical_mds(&two, 3).unwrap();
        assert!(
            (e.eigenvalues[0] - 2.0).abs() < 1e-12,
            "{:?}",
            e.eigenvalues
        );
        assert_eq!(&e.eigenvalues[1..], &[0.0, 0.0]);
        let x = e.coords.coords();
        assert!(((x[0] - x[3]).abs() - 2.0).abs() < 1e-12);
    }
}
