//! Placing the encounters of moving agents between the landmarks they connect (the
//! `Embedded` method's point cloud; paper §"Metric Estimation" gives the metric, this is our
//! estimate of *where* an encounter lies from it).
//!
//! The representatives of the `Embedded` method are encounters with static landmarks, and
//! landmark MDS places them well: the metric between two landmarks is the shortest travel
//! time of an agent between them. An encounter of two *moving* agents is known far less
//! well: the metric only says how long its agents took to reach some landmark, before or
//! after. Landmark MDS turns these distances, all inflated by that travel time, into a
//! position pushed outwards from the cloud's centre along a ray (the "star" of the report's
//! cloud figures), and the rays open false holes between them.
//!
//! Instead we place such an encounter `e` where its shortest paths leave it. Among the `k`
//! representatives nearest to `e` in the metric, an *exit* is one not reached through a
//! nearer one (`δ(e, j) + d(j, i) > δ(e, i)` for every nearer `j`): the landmark an agent of
//! `e` actually walked to or came from. `e` is placed at the mean of its exits' positions
//! weighted by `1 / δ`: for an agent that met landmark `A` a time `g₁` before and `B` a time
//! `g₂` after, that is `(g₂ A + g₁ B) / (g₁ + g₂)`, the mean of a random walk pinned at both
//! ends (a Brownian bridge). Encounters at distance 0 from a representative (with its
//! landmark) keep their MDS position.
//!
//! Measured on the training worlds (docs/accuracy.md, step 6; classifiers fitted without the
//! false-hole cap): bridged clouds get 80.9 % of the training windows right against 73.3 %
//! for landmark-MDS clouds. On synthetic logs it lowers the Procrustes error (test below).
//! Cost: O(n · (m + k²)) for n encounters and m representatives.

/// Number of nearest representatives searched for exits.
pub const EXIT_CANDIDATES: usize = 6;

/// Re-places every encounter `j` of `members` (indices into the window's events) whose
/// distance to the nearest representative is positive.
///
/// - `points[j]`: the landmark-MDS position of event `j` (updated in place);
/// - `picks[i]`: the event index of representative `i`, `rows[i][j]` its distance to `j`.
pub fn place_between_landmarks(
    points: &mut [[f64; 3]],
    members: &[usize],
    picks: &[usize],
    rows: &[Vec<f64>],
    k: usize,
) {
    if picks.is_empty() || k == 0 {
        return;
    }
    let anchors: Vec<[f64; 3]> = picks.iter().map(|&p| points[p]).collect();
    let mut near: Vec<(f64, usize)> = Vec::with_capacity(picks.len());
    for &j in members {
        near.clear();
        near.extend(rows.iter().enumerate().map(|(i, r)| (r[j], i)));
        let k = k.min(near.len());
        near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        near.truncate(k);
        near.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let nearest = near[0].0;
        if !(nearest > 0.0 && nearest.is_finite()) {
            continue;
        }
        let mut sum = [0.0; 3];
        let mut weight = 0.0;
        for (n, &(d, i)) in near.iter().enumerate() {
            if !d.is_finite() {
                break;
            }
            let tolerance = 1e-9 * d.max(1.0);
            let behind = near[..n]
                .iter()
                .any(|&(dj, jj)| dj + rows[jj][picks[i]] <= d + tolerance);
            if behind {
                continue;
            }
            let w = 1.0 / d;
            for (s, a) in sum.iter_mut().zip(anchors[i]) {
                *s += w * a;
            }
            weight += w;
        }
        points[j] = sum.map(|s| s / weight);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three landmarks on a line at x = 0, 10, 20 (metric = travel time at unit speed) and
    /// an encounter met 3 s after the first and 7 s before the second.
    fn setup() -> (Vec<[f64; 3]>, Vec<usize>, Vec<Vec<f64>>) {
        let points = vec![
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [20.0, 0.0, 0.0],
            [99.0, 99.0, 0.0],
        ];
        let picks = vec![0, 1, 2];
        // rows[i][j]: representative i to event j; event 3 is 3 from rep 0, 7 from rep 1 and
        // (through rep 1) 17 from rep 2.
        let rows = vec![
            vec![0.0, 10.0, 20.0, 3.0],
            vec![10.0, 0.0, 10.0, 7.0],
            vec![20.0, 10.0, 0.0, 17.0],
        ];
        (points, picks, rows)
    }

    #[test]
    fn a_moving_encounter_lies_on_the_bridge_between_its_exits() {
        let (mut points, picks, rows) = setup();
        place_between_landmarks(&mut points, &[0, 1, 2, 3], &picks, &rows, 6);
        // (g2 A + g1 B) / (g1 + g2) = (7 · 0 + 3 · 10) / 10 = 3; rep 2 is behind rep 1.
        assert!((points[3][0] - 3.0).abs() < 1e-12, "{:?}", points[3]);
        assert!(points[3][1].abs() < 1e-12);
        // Representatives themselves do not move.
        assert_eq!(points[..3], [[0.0; 3], [10.0, 0.0, 0.0], [20.0, 0.0, 0.0]]);
    }

    #[test]
    fn a_representative_reached_directly_is_an_exit_too() {
        let (mut points, picks, mut rows) = setup();
        // A shorter direct path to rep 2 (16 < 7 + 10): it becomes a third exit.
        rows[2][3] = 16.0;
        place_between_landmarks(&mut points, &[3], &picks, &rows, 6);
        let w = [1.0 / 3.0, 1.0 / 7.0, 1.0 / 16.0];
        let x = (w[1] * 10.0 + w[2] * 20.0) / (w[0] + w[1] + w[2]);
        assert!((points[3][0] - x).abs() < 1e-12, "{:?} vs {x}", points[3]);
    }

    #[test]
    fn only_the_k_nearest_are_searched() {
        let (mut points, picks, mut rows) = setup();
        rows[2][3] = 16.0;
        place_between_landmarks(&mut points, &[3], &picks, &rows, 2);
        assert!((points[3][0] - 3.0).abs() < 1e-12, "{:?}", points[3]);
    }

    #[test]
    fn unreachable_encounters_keep_their_position() {
        let (mut points, picks, mut rows) = setup();
        for r in &mut rows {
            r[3] = f64::INFINITY;
        }
        place_between_landmarks(&mut points, &[3], &picks, &rows, 6);
        assert_eq!(points[3], [99.0, 99.0, 0.0]);
    }

    /// On synthetic logs (a 6 m square, 30 static landmarks among 100 agents, r_d = 10 cm),
    /// re-placing the moving agents' encounters lowers the embedding's error against the
    /// true positions, seed after seed.
    #[test]
    fn bridging_lowers_the_embedding_error_on_synthetic_logs() {
        use crate::mapping::local::LocalParams;
        use crate::mapping::synthetic::square_embedding_error;
        let mut p = LocalParams::from_mapping(&crate::world::MappingParams {
            method: crate::world::MappingMethod::Embedded,
            ..Default::default()
        });
        assert!(p.bridge);
        for seed in 1..=3 {
            let error = |p: &LocalParams| square_embedding_error(p, seed);
            p.bridge = true;
            let bridged = error(&p);
            p.bridge = false;
            let mds = error(&p);
            eprintln!("seed {seed}: Procrustes {mds:.4} (landmark MDS) -> {bridged:.4} (bridged)");
            assert!(bridged < mds, "seed {seed}: {bridged} vs {mds}");
        }
    }
}
