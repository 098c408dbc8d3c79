//! Density-filtered farthest-point subsampling of an embedded point cloud (after the
//! "density based subsampling" of Dirafzoon et al. 2014, which the paper uses).
//!
//! Encounters whose embedding is wrong by more than the sampling scale scatter into the
//! regions where no encounter can happen (obstacles) and fill the holes. They are rare
//! there, so their local density is low: we estimate density by the distance to the k-th
//! nearest neighbour, keep the densest `keep` share of the points, and pick m of those by
//! farthest-point selection so the subsample covers the dense set evenly.
//! Cost: O(n log n) grid k-NN in the embedding for typical clouds; the selection about
//! π n ln m distance evaluations for an even cloud (at worst m · n; [`dense_maxmin`]).

use crate::topology::PointCloud;
use crate::topology::rips::{Diagram, RipsOptions, rips_points};
use std::collections::HashMap;

/// Parameters of the dense subsample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DenseParams {
    /// Coordinates used (2: the plane of the first two MDS axes, or 3) (default: `2`).
    pub dims: usize,
    /// Neighbour rank of the density estimate (default: `10`).
    pub k: usize,
    /// Share of the densest points kept (default: `0.8`).
    pub keep: f64,
    /// Number of representatives m (default: `400`).
    pub m: usize,
}

/// Points of the planar Vietoris–Rips complex of the `Embedded` method (and of the
/// truth-position oracle, [`crate::mapping::output::Fidelity::oracle`]).
pub const EMBEDDED_POINTS: usize = 1200;

impl DenseParams {
    /// The `Embedded` method's topology stage: MaxMin of [`EMBEDDED_POINTS`] points on the
    /// plane of the first two coordinates, without density filter (`keep = 1`). Measured on
    /// the true positions of encounters (docs/accuracy.md, "Which stage loses the holes"):
    /// the filter keeps the dense clusters of encounters at static landmarks and drops the moving
    /// agents' encounters between them, which opens false holes in empty arenas; and with
    /// 300 points the sampling scale σ is too coarse for 1–1.5 m obstacles.
    pub fn embedded() -> Self {
        Self::embedded_with(EMBEDDED_POINTS)
    }

    /// [`Self::embedded`] with `m` points instead of [`EMBEDDED_POINTS`] (a world's
    /// `mapping.rips_points`).
    pub fn embedded_with(m: usize) -> Self {
        Self {
            dims: 2,
            k: 10,
            keep: 1.0,
            m,
        }
    }
}

/// Fewest points a component's planar Rips complex gets under [`DenseParams::for_share`].
pub const MIN_COMPONENT_POINTS: usize = 50;

impl DenseParams {
    /// The same parameters with `m` scaled to a component holding `share` (in (0, 1]) of
    /// its window's mapped encounters: `max(MIN_COMPONENT_POINTS, round(m · share))`, never
    /// more than `m`. Every component is then sampled at the density of a one-component
    /// window, so that the classifier's scale-free thresholds mean the same thing in both.
    /// With `m` points in each of the two strips beside scenario 2's bar, a strip was
    /// sampled twice as densely as a whole window (σ 0.77–0.92 against 0.89–1.52, scenario 2 seeds 6, 7, 12), and the
    /// estimate's ≈ 0.6 m cells stood out as holes (docs/accuracy.md, step 17).
    pub fn for_share(&self, share: f64) -> Self {
        let scaled = if share.is_finite() && share > 0.0 {
            (self.m as f64 * share.min(1.0)).round() as usize
        } else {
            self.m
        };
        Self {
            m: scaled.max(MIN_COMPONENT_POINTS).min(self.m),
            ..*self
        }
    }
}

impl Default for DenseParams {
    fn default() -> Self {
        Self {
            dims: 2,
            k: 10,
            keep: 0.8,
            m: 400,
        }
    }
}

/// Euclidean distance on the first `dims` coordinates.
pub(crate) fn dist(a: &[f64; 3], b: &[f64; 3], dims: usize) -> f64 {
    (0..dims)
        .map(|i| (a[i] - b[i]) * (a[i] - b[i]))
        .sum::<f64>()
        .sqrt()
}

/// The k-th nearest-neighbour distance of every point, via a uniform grid on the first
/// two coordinates.
pub fn knn_radius(points: &[[f64; 3]], k: usize, dims: usize) -> Vec<f64> {
    let n = points.len();
    if n <= 1 {
        return vec![0.0; n];
    }
    let k = k.clamp(1, n - 1);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(f64::MIN_POSITIVE);
    // Cells holding about k points each.
    // A nearly collinear cloud has a tiny area: size cells by the longer side too.
    let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let cell = (area * k as f64 / n as f64)
        .sqrt()
        .max(side * k as f64 / n as f64)
        .max(1e-12);
    let key = |p: &[f64; 3]| {
        (
            ((p[0] - lo[0]) / cell).floor() as i64,
            ((p[1] - lo[1]) / cell).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, p) in points.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i);
    }
    let mut d = Vec::new();
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (cx, cy) = key(p);
            let mut ring = 1i64;
            loop {
                d.clear();
                // Once the ring spans more cells than are occupied, scanning the occupied
                // cells is cheaper than walking mostly empty ones (a far outlier would
                // otherwise need a ring of millions of cells).
                let exhaustive = (2 * ring + 1).saturating_mul(2 * ring + 1) >= grid.len() as i64;
                if exhaustive {
                    d.extend(
                        (0..n)
                            .filter(|&j| j != i)
                            .map(|j| dist(p, &points[j], dims)),
                    );
                    d.select_nth_unstable_by(k - 1, f64::total_cmp);
                    return d[k - 1];
                }
                for x in cx - ring..=cx + ring {
                    for y in cy - ring..=cy + ring {
                        if let Some(v) = grid.get(&(x, y)) {
                            d.extend(
                                v.iter()
                                    .filter(|&&j| j != i)
                                    .map(|&j| dist(p, &points[j], dims)),
                            );
                        }
                    }
                }
                // The k-th distance is exact once it is within the searched ring.
                if d.len() >= k {
                    d.select_nth_unstable_by(k - 1, f64::total_cmp);
                    if d[k - 1] <= ring as f64 * cell {
                        return d[k - 1];
                    }
                }
                ring *= 2;
            }
        })
        .collect()
}

/// Indices (into `points`) of the dense subsample, in farthest-point order.
///
/// Farthest-point selection: start from the first kept point, then repeatedly pick the
/// kept point farthest from every pick so far (ties: the first in index order), until `m`
/// are picked or every kept point coincides with a pick. Done naively this is `m · n`
/// distance evaluations (9 · 10⁷ for 4 800 picks of scenario 2's 18 800-encounter window;
/// 9.4 % of `swarmmap map`'s CPU samples there, docs/accuracy.md, step 28). Two facts make
/// it local: a pick `j` taken at radius `r`
/// (the largest nearest-pick distance) can only lower the nearest-pick distance of points
/// within `r` of it, since every other point is already within `r` of a pick; and `r`
/// only shrinks. So the points sit in a uniform grid on the first two coordinates (a
/// superset of the 3-D ball's points), each pick updates the points of the grid cells
/// within `r`, and a max-heap with lazy deletion (stale entries carry a larger distance
/// than the point's current one) finds the next pick. About `π n ln m` evaluations for an
/// even cloud; the picks are exactly those of the naive loop (`maxmin_naive`, which the
/// tests compare against).
pub fn dense_maxmin(points: &[[f64; 3]], p: &DenseParams) -> Vec<usize> {
    let dims = p.dims.clamp(2, 3);
    let kept = dense_kept(points, p, dims);
    if kept.is_empty() {
        return kept;
    }
    let m = p.m.min(kept.len());
    if kept
        .iter()
        .any(|&i| points[i][..dims].iter().any(|c| !c.is_finite()))
    {
        // NaN distances order differently under the heap's total order; the naive loop
        // keeps its behaviour for them (dense_rips rejects such picks anyway).
        return maxmin_naive(points, &kept, m, dims);
    }
    maxmin_grid(points, &kept, m, dims)
}

/// The points of `points` that the density filter keeps, in index order.
fn dense_kept(points: &[[f64; 3]], p: &DenseParams, dims: usize) -> Vec<usize> {
    if p.keep >= 1.0 {
        // Nothing is filtered: the k-NN radii would only rank points that all stay.
        return (0..points.len()).collect();
    }
    let r = knn_radius(points, p.k, dims);
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| r[a].total_cmp(&r[b]).then(a.cmp(&b)));
    let kept =
        ((points.len() as f64 * p.keep).ceil() as usize).clamp(1.min(points.len()), points.len());
    let mut kept: Vec<usize> = order[..kept].to_vec();
    kept.sort_unstable();
    kept
}

/// Farthest-point selection of `m` of `kept` by the definition: `m · |kept|` distances.
fn maxmin_naive(points: &[[f64; 3]], kept: &[usize], m: usize, dims: usize) -> Vec<usize> {
    let mut picks = vec![kept[0]];
    let mut nearest: Vec<f64> = kept
        .iter()
        .map(|&j| dist(&points[j], &points[kept[0]], dims))
        .collect();
    while picks.len() < m {
        let (k, d) = nearest
            .iter()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |b, (k, &d)| if d > b.1 { (k, d) } else { b },
            );
        if d <= 0.0 {
            break;
        }
        let j = kept[k];
        picks.push(j);
        for (t, &i) in kept.iter().enumerate() {
            nearest[t] = nearest[t].min(dist(&points[i], &points[j], dims));
        }
    }
    picks
}

/// Heap entry of [`maxmin_grid`]: the greatest distance first, then the smallest position
/// in `kept` (the naive loop's tie-break).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Far(f64, usize);

impl Eq for Far {}

impl PartialOrd for Far {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Far {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0).then(other.1.cmp(&self.1))
    }
}

/// Longest side of the selection grid, in cells: bounds its memory for clouds that one
/// far outlier stretches (the selection stays exact, only slower).
const GRID_MAX_SIDE: usize = 2048;

/// [`maxmin_naive`]'s picks with local updates (see [`dense_maxmin`]); finite points only.
fn maxmin_grid(points: &[[f64; 3]], kept: &[usize], m: usize, dims: usize) -> Vec<usize> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &i in kept {
        for c in 0..2 {
            lo[c] = lo[c].min(points[i][c]);
            hi[c] = hi[c].max(points[i][c]);
        }
    }
    let span = [hi[0] - lo[0], hi[1] - lo[1]];
    let side = span[0].max(span[1]);
    // Cells of about the final pick spacing.
    let cell = (span[0] * span[1] / m.max(1) as f64)
        .sqrt()
        .max(side / GRID_MAX_SIDE as f64)
        .max(1e-300);
    let size = |s: f64| ((s / cell).floor() as usize + 1).min(GRID_MAX_SIDE + 1);
    let (gx, gy) = (size(span[0]), size(span[1]));
    let at =
        |v: f64, c: usize, g: usize| (((v - lo[c]) / cell).floor().max(0.0) as usize).min(g - 1);
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); gx * gy];
    for (t, &i) in kept.iter().enumerate() {
        let q = &points[i];
        grid[at(q[1], 1, gy) * gx + at(q[0], 0, gx)].push(t as u32);
    }
    let mut picks = vec![kept[0]];
    let mut nearest: Vec<f64> = kept
        .iter()
        .map(|&j| dist(&points[j], &points[kept[0]], dims))
        .collect();
    let mut heap: std::collections::BinaryHeap<Far> = nearest
        .iter()
        .enumerate()
        .map(|(t, &d)| Far(d, t))
        .collect();
    while picks.len() < m {
        let Some(Far(d, k)) = heap.pop() else { break };
        if d.to_bits() != nearest[k].to_bits() {
            continue; // stale: the point has come nearer a pick since
        }
        if d <= 0.0 {
            break;
        }
        let j = kept[k];
        picks.push(j);
        let pj = &points[j];
        let (x0, x1) = (at(pj[0] - d, 0, gx), at(pj[0] + d, 0, gx));
        let (y0, y1) = (at(pj[1] - d, 1, gy), at(pj[1] + d, 1, gy));
        for y in y0..=y1 {
            for x in x0..=x1 {
                for &t in &grid[y * gx + x] {
                    let t = t as usize;
                    let e = dist(&points[kept[t]], pj, dims);
                    if e < nearest[t] {
                        nearest[t] = e;
                        heap.push(Far(e, t));
                    }
                }
            }
        }
    }
    picks
}

/// Vietoris–Rips persistence of the dense subsample of `points` (on their first
/// `p.dims` coordinates), with the subsample as indices into `points`; `None` if a picked
/// point is not finite.
pub fn dense_rips(
    points: &[[f64; 3]],
    p: &DenseParams,
    opts: &RipsOptions,
) -> Option<(Diagram, Vec<usize>)> {
    let picks = dense_maxmin(points, p);
    let dims = p.dims.clamp(2, 3);
    let rows: Vec<Vec<f64>> = picks.iter().map(|&k| points[k][..dims].to_vec()).collect();
    let cloud = PointCloud::from_rows(&rows).ok()?;
    Some((rips_points(&cloud, opts), picks))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The k-th nearest-neighbour distance of point `i` by brute force (the oracle).
    fn brute_kth(pts: &[[f64; 3]], i: usize, k: usize) -> f64 {
        let mut d: Vec<f64> = pts
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, q)| dist(&pts[i], q, 2))
            .collect();
        d.sort_by(f64::total_cmp);
        d[k - 1]
    }

    /// A deterministic cloud: a lattice (exact ties), a uniform scatter, duplicates and a
    /// far outlier, with a third coordinate.
    fn mixed_cloud(seed: u64) -> Vec<[f64; 3]> {
        let mut s = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut u = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts = Vec::new();
        for i in 0..12 {
            for j in 0..9 {
                pts.push([i as f64 * 0.5, j as f64 * 0.5, 0.0]);
            }
        }
        for _ in 0..900 {
            pts.push([u() * 8.0 - 1.0, u() * 5.0 - 0.5, u() * 0.3]);
        }
        pts.push(pts[17]);
        pts.push(pts[400]);
        pts.push([400.0, -250.0, 1.0]);
        pts
    }

    #[test]
    fn grid_maxmin_picks_exactly_what_the_naive_loop_picks() {
        for seed in 0..4 {
            let pts = mixed_cloud(seed);
            for dims in [2, 3] {
                let kept: Vec<usize> = (0..pts.len()).collect();
                for m in [1, 2, 50, 400, pts.len()] {
                    assert_eq!(
                        maxmin_grid(&pts, &kept, m, dims),
                        maxmin_naive(&pts, &kept, m, dims),
                        "seed {seed}, dims {dims}, m {m}"
                    );
                }
                // More picks asked for than there are points: all of them, in the same order.
                let p = DenseParams {
                    dims,
                    m: pts.len() + 10,
                    ..DenseParams::embedded()
                };
                assert_eq!(
                    dense_maxmin(&pts, &p),
                    maxmin_naive(&pts, &kept, pts.len(), dims)
                );
            }
        }
    }

    #[test]
    fn grid_maxmin_handles_degenerate_clouds() {
        // Collinear, all equal, and a single point.
        let line: Vec<[f64; 3]> = (0..300).map(|i| [i as f64 * 0.01, 2.0, 0.0]).collect();
        let same = vec![[1.0, 1.0, 1.0]; 40];
        for pts in [line, same, vec![[0.0, 0.0, 0.0]]] {
            let kept: Vec<usize> = (0..pts.len()).collect();
            for m in [1, 5, 100, 1000] {
                let m = m.min(kept.len());
                assert_eq!(
                    maxmin_grid(&pts, &kept, m, 2),
                    maxmin_naive(&pts, &kept, m, 2)
                );
            }
        }
        // Non-finite coordinates take the naive path through dense_maxmin.
        let mut pts = mixed_cloud(9);
        pts[3][0] = f64::NAN;
        let p = DenseParams::embedded_with(100);
        let kept: Vec<usize> = (0..pts.len()).collect();
        assert_eq!(dense_maxmin(&pts, &p), maxmin_naive(&pts, &kept, 100, 2));
    }

    #[test]
    fn knn_matches_brute_force() {
        let pts: Vec<[f64; 3]> = (0..300)
            .map(|i| {
                let t = i as f64;
                [
                    (t * 0.37).sin() * 5.0 + t * 0.01,
                    (t * 0.73).cos() * 3.0,
                    0.0,
                ]
            })
            .collect();
        let r = knn_radius(&pts, 5, 2);
        for (i, got) in r.iter().enumerate() {
            let want = brute_kth(&pts, i, 5);
            assert!((got - want).abs() < 1e-12, "point {i}: {got} vs {want}");
        }
    }

    /// Regression: a far-away handful of points (an embedding outlier) made the ring search
    /// walk millions of empty cells (`swarmmap eval worlds/touching.ron` ran for minutes).
    #[test]
    fn far_outliers_do_not_stall_the_search() {
        let mut pts: Vec<[f64; 3]> = (0..2000)
            .map(|i| [(i % 50) as f64 * 0.1, (i / 50) as f64 * 0.1, 0.0])
            .collect();
        pts.extend([[1e7, 1e7, 0.0], [1e7 + 1.0, 1e7, 0.0], [-1e7, 3.0, 0.0]]);
        // And a nearly collinear cloud (a degenerate second MDS axis): tiny cells.
        let line: Vec<[f64; 3]> = (0..3000)
            .map(|i| [i as f64, 1e-9 * (i % 7) as f64, 0.0])
            .collect();
        let t = std::time::Instant::now();
        let r = knn_radius(&line, 5, 2);
        assert!(
            t.elapsed().as_secs_f64() < 5.0,
            "line took {:?}",
            t.elapsed()
        );
        assert!((r[1500] - 3.0).abs() < 1e-6, "{}", r[1500]);
        let t = std::time::Instant::now();
        let r = knn_radius(&pts, 5, 2);
        assert!(t.elapsed().as_secs_f64() < 5.0, "took {:?}", t.elapsed());
        for i in (0..2000).step_by(97).chain(2000..2003) {
            assert_eq!(r[i], brute_kth(&pts, i, 5), "point {i}");
        }
    }

    #[test]
    fn sparse_points_are_dropped() {
        // A dense grid and one far-away point: the lone point is not kept.
        let mut pts: Vec<[f64; 3]> = (0..400)
            .map(|i| [(i % 20) as f64, (i / 20) as f64, 0.0])
            .collect();
        pts.push([100.0, 100.0, 0.0]);
        let picks = dense_maxmin(
            &pts,
            &DenseParams {
                keep: 0.9,
                m: 50,
                ..Default::default()
            },
        );
        assert_eq!(picks.len(), 50);
        assert!(!picks.contains(&400));
    }

    #[test]
    fn for_share_scales_the_points_between_a_floor_and_m() {
        let p = DenseParams::embedded();
        assert_eq!(p.for_share(1.0).m, EMBEDDED_POINTS);
        assert_eq!(p.for_share(0.5).m, EMBEDDED_POINTS / 2);
        assert_eq!(p.for_share(0.25).m, EMBEDDED_POINTS / 4);
        assert_eq!(p.for_share(0.001).m, MIN_COMPONENT_POINTS);
        // Never more than m, and a share that is not positive and finite keeps m.
        assert_eq!(p.for_share(3.0).m, EMBEDDED_POINTS);
        assert_eq!(p.for_share(f64::NAN).m, EMBEDDED_POINTS);
        assert_eq!(p.for_share(0.0).m, EMBEDDED_POINTS);
        // Only m changes.
        let q = p.for_share(0.5);
        assert_eq!((q.dims, q.k, q.keep), (p.dims, p.k, p.keep));
    }
}
