//! Placing every encounter of moving agents on its agents' time lines (the `Embedded`
//! method's point cloud, after [`super::bridge`]; the paper's §"Metric Estimation" gives the
//! metric, this is our estimate of *where* an encounter lies from the log).
//!
//! [`super::bridge`] places an encounter of two moving agents between the landmarks its
//! shortest paths lead to, on the straight segment between them. Encounters whose agents
//! walked for long between landmarks (the median such gap is 20–40 s, 2–4 m of walk, in
//! scenario 3) then gather on segments across the obstacles, and the cloud becomes a web
//! of lines whose empty triangles look like the small obstacles' holes.
//!
//! # The model
//! Each agent's position is a random walk in time; between two of its encounters `j`, `k`,
//! `Δt` apart, its displacement is taken as an isotropic Gaussian with variance
//! `∝ Δt + τ` (Brownian motion: the runs of 1 m at 0.1 m/s make the walk diffusive over
//! the gaps that matter, and `τ` = [`TIMELINE_FLOOR`] keeps two encounters close in time
//! from being forced onto one point: they are still up to `r_d` apart). An encounter is
//! one point shared by the time lines of both its agents, and the encounters with static
//! landmarks are fixed where landmark MDS (and the bridge) put them. The most likely
//! positions of all other encounters given the fixed ones minimise
//!
//! `Σ_agents Σ_consecutive (j, k) ‖x_j − x_k‖² / (Δt_jk + τ)`,
//!
//! a Gaussian Markov random field whose minimiser is harmonic: with the graph Laplacian
//! `L` of the time-line edges (weights `1 / (Δt + τ)`), `L_ff x_f = −L_fa x_a` for the free
//! positions `x_f` and the fixed `x_a`, one system per coordinate. For one agent walking
//! from one fixed encounter to the next this is the Brownian bridge (linear interpolation in
//! time); the bridge of [`super::bridge`] is that same estimate with the exits found through
//! the metric. What the field adds is that an encounter is pulled by *both* agents' walks
//! and, through their other encounters, by every agent they met: an encounter behind a
//! small obstacle is placed by the agents that went round it on that side.
//!
//! Measured (docs/accuracy.md, step 36): on scenario 3, seed 7, window 1 the moving
//! encounters' median error falls from 0.34 m (bridged) to 0.31 m, and the missed obstacle's
//! bar rises from 3.19 σ (noise up to 2.92 σ) to 3.98 σ (noise up to 2.49 σ). Over seeds
//! 1–20 of scenario 3 the best single H1 rule gets 83 of the 100 windows right on these
//! clouds and 79 on the bridged ones: a small gain, so the option is off by default.
//!
//! # Solving
//! `L_ff` is symmetric positive definite on every connected part of the time-line graph
//! that holds a fixed encounter (a weighted Laplacian with a Dirichlet boundary), so the
//! systems are solved by conjugate gradients with a Jacobi preconditioner, started from the
//! bridged positions. Free encounters whose part holds no fixed one keep their position
//! (their system is singular: nothing pins them). A sparse Cholesky factorisation
//! (`nalgebra-sparse`) would need a fill-reducing ordering that crate does not provide; CG
//! on this M-matrix needs O(edges) memory and a few hundred iterations. Cost: O(n log n)
//! to sort the time lines, O(edges · iterations) to solve; deterministic (fixed order).

use crate::log::Encounter;
use std::collections::BTreeMap;

/// `τ`, seconds: the time an agent of the bundled worlds (r_d = 0.1 m, v = 0.1 m/s)
/// takes to cross its detection radius. On scenario 3 (seed 7, window 1) τ = 0.1, 1, 3
/// and 10 s give the missed obstacle 3.77, 3.98, 3.64 and 3.13 σ (docs/accuracy.md, step 36).
pub const TIMELINE_FLOOR: f64 = 1.0;

/// Residual, relative to the system's scale, at which conjugate gradients stop.
const TOLERANCE: f64 = 1e-10;

/// Re-places every encounter of `members` (indices into `enc`) that is not `fixed` at the
/// most likely position given the fixed ones and its agents' time lines (module docs).
/// `points[j]` holds encounter `j`'s current position (the start of the solve; kept when
/// nothing pins it). `floor` is τ in seconds and must be positive (at τ = 0 two encounters
/// of one agent at the same time would have to coincide; such a pair is left unlinked).
/// Encounters with a non-finite time or position take no part: they link nothing and keep
/// their position. Returns the number of encounters placed.
pub fn place_on_timelines(
    points: &mut [[f64; 3]],
    enc: &[Encounter],
    members: &[usize],
    fixed: &[bool],
    floor: f64,
) -> usize {
    // Each agent's encounters among the members, in time order of their middles.
    let mut lines: BTreeMap<u32, Vec<(f64, usize)>> = BTreeMap::new();
    debug_assert!(floor > 0.0, "τ must be positive, got {floor}");
    let usable = |j: usize| {
        let e = &enc[j];
        (e.start + e.end).is_finite() && points[j].iter().all(|x| x.is_finite())
    };
    for &j in members.iter().filter(|&&j| usable(j)) {
        let e = &enc[j];
        let mid = 0.5 * (e.start + e.end);
        for agent in [e.a, e.b] {
            lines.entry(agent).or_default().push((mid, j));
        }
    }
    // Free encounters get consecutive indices; fixed ones are boundary values.
    let mut free_index = vec![usize::MAX; enc.len()];
    let mut free = Vec::new();
    for &j in members.iter().filter(|&&j| usable(j)) {
        if !fixed[j] && free_index[j] == usize::MAX {
            free_index[j] = free.len();
            free.push(j);
        }
    }
    if free.is_empty() {
        return 0;
    }
    let n = free.len();
    let mut diag = vec![0.0; n];
    let mut rhs = vec![[0.0; 3]; n];
    let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    // Union–find over the free encounters, with a flag for parts touching a fixed one.
    let mut parent: Vec<usize> = (0..n).collect();
    let mut pinned = vec![false; n];
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for line in lines.values_mut() {
        line.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        for pair in line.windows(2) {
            let ((t1, j), (t2, k)) = (pair[0], pair[1]);
            if j == k {
                continue;
            }
            let w = 1.0 / ((t2 - t1).max(0.0) + floor);
            if !w.is_finite() {
                continue;
            }
            match (free_index[j], free_index[k]) {
                (usize::MAX, usize::MAX) => {}
                (a, usize::MAX) | (usize::MAX, a) => {
                    let other = if a == free_index[j] { k } else { j };
                    diag[a] += w;
                    for (r, x) in rhs[a].iter_mut().zip(points[other]) {
                        *r += w * x;
                    }
                    let ra = root(&mut parent, a);
                    pinned[ra] = true;
                }
                (a, b) => {
                    diag[a] += w;
                    diag[b] += w;
                    adj[a].push((b, w));
                    adj[b].push((a, w));
                    let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                    if ra != rb {
                        parent[ra] = rb;
                        pinned[rb] |= pinned[ra];
                    }
                }
            }
        }
    }
    // Only the parts pinned by a fixed encounter are solved; the rest keep their places.
    let solved: Vec<bool> = (0..n)
        .map(|i| {
            let r = root(&mut parent, i);
            pinned[r]
        })
        .collect();
    // A free neighbour lies in the same part, so it is solved exactly when `i` is.
    let apply = |x: &[f64], y: &mut [f64]| {
        for i in 0..n {
            y[i] = if solved[i] {
                diag[i] * x[i] - adj[i].iter().map(|&(k, w)| w * x[k]).sum::<f64>()
            } else {
                0.0
            };
        }
    };
    for c in 0..3 {
        let b: Vec<f64> = (0..n)
            .map(|i| if solved[i] { rhs[i][c] } else { 0.0 })
            .collect();
        let mut x: Vec<f64> = (0..n)
            .map(|i| if solved[i] { points[free[i]][c] } else { 0.0 })
            .collect();
        conjugate_gradients(&apply, &diag, &b, &mut x, 20 * n + 100);
        for i in 0..n {
            if solved[i] && x[i].is_finite() {
                points[free[i]][c] = x[i];
            }
        }
    }
    solved.iter().filter(|&&s| s).count()
}

/// Jacobi-preconditioned conjugate gradients for `A x = b`, `A` symmetric positive
/// definite on the rows where `diag > 0` (the others are zero in `A` and `b`), from the
/// start `x`; stops at a residual of [`TOLERANCE`] times max(‖b‖, ‖A x₀‖) or after
/// `max_iter` steps.
fn conjugate_gradients(
    apply: &dyn Fn(&[f64], &mut [f64]),
    diag: &[f64],
    b: &[f64],
    x: &mut [f64],
    max_iter: usize,
) {
    let n = b.len();
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    let precondition = |r: &[f64], z: &mut [f64]| {
        for i in 0..n {
            z[i] = if diag[i] > 0.0 { r[i] / diag[i] } else { 0.0 };
        }
    };
    let mut ax = vec![0.0; n];
    apply(x, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    // The scale of the system: ‖b‖, or ‖A x₀‖ where the boundary values are all near 0 (a
    // coordinate the walks barely use), so that the stop does not chase a vanishing ‖b‖.
    let scale = dot(b, b).sqrt().max(dot(&ax, &ax).sqrt());
    if scale == 0.0 || !scale.is_finite() {
        return;
    }
    let mut z = vec![0.0; n];
    precondition(&r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut ap = vec![0.0; n];
    for _ in 0..max_iter {
        if dot(&r, &r).sqrt() <= TOLERANCE * scale || rz <= 0.0 {
            break;
        }
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap.is_nan() || pap <= 0.0 {
            break;
        }
        let alpha = rz / pap;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        precondition(&r, &mut z);
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encounter(t: f64, a: u32, b: u32) -> Encounter {
        Encounter {
            start: t,
            end: t,
            a,
            b,
            truth: None,
        }
    }

    /// One agent (0) meets landmark 10 at t = 0 (at x = 0), agents 1 and 2 at t = 2 and 5,
    /// and landmark 11 at t = 10 (at x = 10): its free encounters lie on the segment,
    /// at the share of the time line's resistance Σ (Δt + τ) walked so far.
    #[test]
    fn one_walk_between_two_landmarks_is_the_brownian_bridge() {
        let enc = vec![
            encounter(0.0, 0, 10),
            encounter(2.0, 0, 1),
            encounter(5.0, 0, 2),
            encounter(10.0, 0, 11),
        ];
        let mut points = vec![
            [0.0; 3],
            [7.0, 3.0, 1.0],
            [-4.0, 2.0, 0.0],
            [10.0, 0.0, 0.0],
        ];
        let fixed = [true, false, false, true];
        for tau in [0.25, 1.0, 2.5] {
            let placed = place_on_timelines(&mut points, &enc, &[0, 1, 2, 3], &fixed, tau);
            assert_eq!(placed, 2);
            let total = 10.0 + 3.0 * tau;
            for (j, walked) in [(1, 2.0 + tau), (2, 5.0 + 2.0 * tau)] {
                let x = 10.0 * walked / total;
                assert!(
                    (points[j][0] - x).abs() < 1e-9,
                    "τ {tau}: {:?} vs {x}",
                    points[j]
                );
                assert!(points[j][1].abs() < 1e-9 && points[j][2].abs() < 1e-9);
            }
            assert_eq!(points[0], [0.0; 3]);
            assert_eq!(points[3], [10.0, 0.0, 0.0]);
        }
    }

    /// Two agents cross: 0 walks from (−1, 0) to (1, 0), 1 from (0, −1) to (0, 1), and they
    /// meet half way. Their encounter is the mean of both bridges, the origin; with the
    /// second walk pinned at (0, −1) and (2, 1) instead, it is the mean of (0, 0) and (1, 0).
    #[test]
    fn an_encounter_is_pulled_by_both_walks() {
        let enc = vec![
            encounter(0.0, 0, 10),
            encounter(10.0, 0, 11),
            encounter(0.0, 1, 12),
            encounter(10.0, 1, 13),
            encounter(5.0, 0, 1),
        ];
        let fixed = [true, true, true, true, false];
        let all = [0, 1, 2, 3, 4];
        let mut points = vec![
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
        ];
        place_on_timelines(&mut points, &enc, &all, &fixed, 1.0);
        assert!(points[4].iter().all(|x| x.abs() < 1e-9), "{:?}", points[4]);
        points[3] = [2.0, 1.0, 0.0];
        place_on_timelines(&mut points, &enc, &all, &fixed, 1.0);
        assert!((points[4][0] - 0.5).abs() < 1e-9, "{:?}", points[4]);
        assert!(points[4][1].abs() < 1e-9, "{:?}", points[4]);
    }

    /// Against a dense solve of the same harmonic system on a random web of walks.
    #[test]
    fn conjugate_gradients_match_a_dense_solve() {
        use nalgebra::{DMatrix, DVector};
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let agents = 12u32;
        let mut enc = Vec::new();
        for k in 0..120 {
            let a = rng.random_range(0..agents);
            let b = (a + rng.random_range(1..agents)) % agents;
            let start = k as f64 * 0.7 + rng.random::<f64>();
            enc.push(Encounter {
                end: start + 3.0 * rng.random::<f64>(),
                ..encounter(start, a, b)
            });
        }
        let mid = |j: usize| 0.5 * (enc[j].start + enc[j].end);
        let fixed: Vec<bool> = (0..enc.len()).map(|k| k % 7 == 0).collect();
        let start: Vec<[f64; 3]> = (0..enc.len())
            .map(|_| {
                [
                    rng.random::<f64>(),
                    rng.random::<f64>(),
                    rng.random::<f64>(),
                ]
            })
            .collect();
        let all: Vec<usize> = (0..enc.len()).collect();
        let mut points = start.clone();
        let placed = place_on_timelines(&mut points, &enc, &all, &fixed, 1.0);
        // The dense system: Laplacian of the time lines, rows of the free encounters.
        let n = enc.len();
        let mut l = DMatrix::<f64>::zeros(n, n);
        for agent in 0..agents {
            let mut line: Vec<(f64, usize)> = (0..n)
                .filter(|&j| enc[j].a == agent || enc[j].b == agent)
                .map(|j| (mid(j), j))
                .collect();
            line.sort_by(|x, y| x.0.total_cmp(&y.0));
            for p in line.windows(2) {
                let w = 1.0 / (p[1].0 - p[0].0 + 1.0);
                let (j, k) = (p[0].1, p[1].1);
                l[(j, j)] += w;
                l[(k, k)] += w;
                l[(j, k)] -= w;
                l[(k, j)] -= w;
            }
        }
        let free: Vec<usize> = (0..n).filter(|&j| !fixed[j]).collect();
        assert_eq!(
            placed,
            free.len(),
            "every walk here meets a fixed encounter"
        );
        let lff = DMatrix::from_fn(free.len(), free.len(), |a, b| l[(free[a], free[b])]);
        let chol = lff
            .cholesky()
            .expect("pinned Laplacian is positive definite");
        for c in 0..3 {
            let rhs = DVector::from_fn(free.len(), |a, _| {
                -(0..n)
                    .filter(|&k| fixed[k])
                    .map(|k| l[(free[a], k)] * start[k][c])
                    .sum::<f64>()
            });
            let x = chol.solve(&rhs);
            for (a, &j) in free.iter().enumerate() {
                assert!(
                    (points[j][c] - x[a]).abs() < 1e-7,
                    "{j}/{c}: {} vs {}",
                    points[j][c],
                    x[a]
                );
            }
        }
    }

    /// On synthetic logs (a 6 m square, 30 static landmarks among 100 agents, r_d = 10 cm),
    /// placing the moving agents' encounters on their time lines lowers the embedding's
    /// error against the true positions below the bridge's, seed after seed.
    #[test]
    fn time_lines_lower_the_embedding_error_on_synthetic_logs() {
        use crate::mapping::local::LocalParams;
        use crate::mapping::synthetic::square_embedding_error;
        let mut p = LocalParams::from_mapping(&crate::world::MappingParams {
            method: crate::world::MappingMethod::Embedded,
            agent_timelines: true,
            ..Default::default()
        });
        assert_eq!(p.timelines, Some(TIMELINE_FLOOR));
        for seed in 1..=3 {
            let error = |p: &LocalParams| square_embedding_error(p, seed);
            p.timelines = Some(TIMELINE_FLOOR);
            let on_lines = error(&p);
            p.timelines = None;
            let bridged = error(&p);
            eprintln!(
                "seed {seed}: Procrustes {bridged:.4} (bridged) -> {on_lines:.4} (time lines)"
            );
            assert!(on_lines < bridged, "seed {seed}: {on_lines} vs {bridged}");
        }
    }

    /// A walk whose landmark position is not finite takes no part; another walk is solved
    /// as if it were alone.
    #[test]
    fn a_non_finite_position_stays_in_its_own_walk() {
        let enc = vec![
            encounter(0.0, 0, 10),
            encounter(5.0, 0, 1),
            encounter(10.0, 0, 11),
            encounter(0.0, 2, 12),
            encounter(5.0, 2, 3),
            encounter(10.0, 2, 13),
        ];
        let mut points = vec![
            [0.0; 3],
            [3.0, 3.0, 3.0],
            [10.0, 0.0, 0.0],
            [f64::NAN, 0.0, 0.0],
            [3.0, 3.0, 3.0],
            [10.0, 0.0, 0.0],
        ];
        let fixed = [true, false, true, true, false, true];
        let placed = place_on_timelines(&mut points, &enc, &[0, 1, 2, 3, 4, 5], &fixed, 1.0);
        assert_eq!(placed, 2, "the second walk is still pinned by (10, 0, 0)");
        assert!((points[1][0] - 5.0).abs() < 1e-9, "{:?}", points[1]);
        assert!(points[1][1].abs() < 1e-9 && points[1][2].abs() < 1e-9);
        // Pinned by its end alone, the second walk's encounter goes there.
        assert!((points[4][0] - 10.0).abs() < 1e-9, "{:?}", points[4]);
        assert!(points[3][0].is_nan());
    }

    #[test]
    fn walks_that_meet_no_fixed_encounter_keep_their_positions() {
        let enc = vec![
            encounter(0.0, 0, 10),
            encounter(4.0, 0, 11),
            encounter(1.0, 2, 3),
            encounter(3.0, 2, 3),
        ];
        let mut points = vec![[0.0; 3], [4.0, 0.0, 0.0], [9.0, 9.0, 9.0], [8.0, 8.0, 8.0]];
        let placed = place_on_timelines(
            &mut points,
            &enc,
            &[0, 1, 2, 3],
            &[true, true, false, false],
            1.0,
        );
        assert_eq!(placed, 0);
        assert_eq!(points[2], [9.0, 9.0, 9.0]);
        assert_eq!(points[3], [8.0, 8.0, 8.0]);
    }
}
