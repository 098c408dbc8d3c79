//! Geometric fidelity of a local map against the log's truth columns (issue #4 §4; paper
//! §"Geometric Reconstruction", which notes that the point clouds "also contain some
//! geometric information").
//!
//! - [`spearman`]: how well the encounter metric orders pairs of encounters like their true
//!   distances do. Spearman's ρ is Pearson's correlation of the ranks, ties getting the
//!   average of the ranks they span (the standard "fractional ranking"; Spearman, Amer. J.
//!   Psychol. 1904; Kendall & Gibbons, *Rank Correlation Methods*, 1990). It is invariant
//!   under any increasing transformation, which suits a metric measured in seconds compared
//!   with distances in metres. O(n log n).
//! - [`procrustes_error`]: how close the embedding's first two coordinates are to the true
//!   positions once the unknowable gauge is removed. The encounter metric is in seconds and
//!   the map has no orientation or handedness, so the estimate is fitted to the truth by the
//!   best similarity: translation, rotation *or reflection*, and uniform scale (ordinary
//!   Procrustes analysis; Schönemann, Psychometrika 1966; Gower & Dijksterhuis, *Procrustes
//!   Problems*, 2004). With both sets centred, X the estimate and Y the truth (n × 2), the
//!   best orthogonal Q maximises tr(Q M), M = XᵀY, and that maximum is the nuclear norm ‖M‖*
//!   (the sum of M's singular values); the best scale is s = ‖M‖* / ‖X‖², and the residual
//!   sum of squares is ‖Y‖² − ‖M‖*² / ‖X‖². For a 2 × 2 M = [[a, b], [c, d]] the nuclear norm
//!   has the closed form max(√((a + d)² + (b − c)²), √((a − d)² + (b + c)²)): the first term
//!   is the best rotation, the second the best reflection. O(n), no SVD needed.
//!
//! Both return `NaN` where the quantity is undefined (mismatched lengths, too few points,
//! non-finite input, a constant sample for ρ), so a CSV column can carry it unchanged.

/// Spearman's rank correlation ρ ∈ [−1, 1] of two paired samples, ties given average ranks.
///
/// `NaN` if the lengths differ, there are fewer than 2 pairs, a value is not finite, or a
/// sample is constant.
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() || a.len() < 2 || !all_finite(a) || !all_finite(b) {
        return f64::NAN;
    }
    pearson(&average_ranks(a), &average_ranks(b))
}

/// Pearson's correlation coefficient of two paired samples; `NaN` under the same conditions
/// as [`spearman`].
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() || a.len() < 2 || !all_finite(a) || !all_finite(b) {
        return f64::NAN;
    }
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (dx, dy) = (x - ma, y - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if saa == 0.0 || sbb == 0.0 {
        return f64::NAN;
    }
    (sab / (saa.sqrt() * sbb.sqrt())).clamp(-1.0, 1.0)
}

/// Ranks 1..=n of `x` in increasing order, tied values sharing the average of their ranks.
/// Values are compared with `f64::total_cmp`.
pub fn average_ranks(x: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&i, &j| x[i].total_cmp(&x[j]));
    let mut ranks = vec![0.0; x.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && x[order[end]] == x[order[start]] {
            end += 1;
        }
        // Positions start..end hold ranks start+1..=end; their mean:
        let rank = (start + end + 1) as f64 / 2.0;
        for &k in &order[start..end] {
            ranks[k] = rank;
        }
        start = end;
    }
    ranks
}

/// A similarity transform of the plane: `y = scale · rotation · x + translation`, where
/// `rotation` is orthogonal (a rotation or a reflection).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    /// Uniform scale (truth units per estimate unit, e.g. metres per second), ≥ 0.
    pub scale: f64,
    /// Orthogonal 2 × 2 matrix, row-major.
    pub rotation: [[f64; 2]; 2],
    /// Translation, in truth units.
    pub translation: [f64; 2],
}

impl Similarity {
    /// The image of `x`.
    pub fn apply(&self, x: [f64; 2]) -> [f64; 2] {
        let q = &self.rotation;
        [
            self.scale * (q[0][0] * x[0] + q[0][1] * x[1]) + self.translation[0],
            self.scale * (q[1][0] * x[0] + q[1][1] * x[1]) + self.translation[1],
        ]
    }

    /// Whether the orthogonal part is a reflection (determinant −1).
    pub fn is_reflection(&self) -> bool {
        let q = &self.rotation;
        q[0][0] * q[1][1] - q[0][1] * q[1][0] < 0.0
    }
}

/// The result of fitting an estimate onto the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Procrustes {
    /// The best similarity mapping the estimate onto the truth.
    pub transform: Similarity,
    /// Root-mean-square residual distance after the fit, in truth units (metres).
    pub rms: f64,
}

/// Fits `est` onto `truth` (paired points) by the similarity that minimises the sum of
/// squared distances; `None` if the lengths differ, the sets are empty, or a coordinate is
/// not finite. If all estimated points coincide the best scale is 0 and the fit maps every
/// point to the truth's centroid.
pub fn procrustes(est: &[[f64; 2]], truth: &[[f64; 2]]) -> Option<Procrustes> {
    if est.len() != truth.len() || est.is_empty() {
        return None;
    }
    let finite = |s: &[[f64; 2]]| s.iter().all(|p| p[0].is_finite() && p[1].is_finite());
    if !finite(est) || !finite(truth) {
        return None;
    }
    let n = est.len() as f64;
    let centroid = |s: &[[f64; 2]]| {
        let (sx, sy) = s.iter().fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
        [sx / n, sy / n]
    };
    let (cx, cy) = (centroid(est), centroid(truth));
    // M = XᵀY with X, Y centred, and ‖X‖².
    let (mut m, mut xx) = ([[0.0f64; 2]; 2], 0.0);
    for (p, q) in est.iter().zip(truth) {
        let x = [p[0] - cx[0], p[1] - cx[1]];
        let y = [q[0] - cy[0], q[1] - cy[1]];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v += x[r] * y[c];
            }
        }
        xx += x[0] * x[0] + x[1] * x[1];
    }
    let [[a, b], [c, d]] = m;
    let rot = (a + d).hypot(b - c);
    let refl = (a - d).hypot(b + c);
    // tr(Q M) for Q = [[cos, −sin], [sin, cos]] is cos θ (a + d) + sin θ (b − c); for the
    // reflection Q = [[cos, sin], [sin, −cos]] it is cos θ (a − d) + sin θ (b + c).
    let (nuclear, q) = if rot >= refl {
        let t = (b - c).atan2(a + d);
        (rot, [[t.cos(), -t.sin()], [t.sin(), t.cos()]])
    } else {
        let t = (b + c).atan2(a - d);
        (refl, [[t.cos(), t.sin()], [t.sin(), -t.cos()]])
    };
    let scale = if xx > 0.0 { nuclear / xx } else { 0.0 };
    // The closed form ‖Y‖² − ‖M‖*² / ‖X‖² cancels catastrophically for near-perfect fits
    // (the rms would only be good to √ε); summing the actual residuals keeps full precision.
    let residual: f64 = est
        .iter()
        .zip(truth)
        .map(|(p, t)| {
            let x = [p[0] - cx[0], p[1] - cx[1]];
            let fx = scale * (q[0][0] * x[0] + q[0][1] * x[1]) - (t[0] - cy[0]);
            let fy = scale * (q[1][0] * x[0] + q[1][1] * x[1]) - (t[1] - cy[1]);
            fx * fx + fy * fy
        })
        .sum();
    let moved = [
        scale * (q[0][0] * cx[0] + q[0][1] * cx[1]),
        scale * (q[1][0] * cx[0] + q[1][1] * cx[1]),
    ];
    Some(Procrustes {
        transform: Similarity {
            scale,
            rotation: q,
            translation: [cy[0] - moved[0], cy[1] - moved[1]],
        },
        rms: (residual / n).sqrt(),
    })
}

/// RMS residual (truth units, metres) after the optimal similarity transform of `est`
/// onto `truth`; divide by the window's diagonal to normalise. `NaN` where [`procrustes`]
/// gives `None`.
pub fn procrustes_error(est: &[[f64; 2]], truth: &[[f64; 2]]) -> f64 {
    procrustes(est, truth).map_or(f64::NAN, |p| p.rms)
}

fn all_finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}
