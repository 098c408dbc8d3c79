//! Do the agents walk through a loop's void? The crossing share of an H1 bar (the `Embedded`
//! method; our addition to the paper's §"Topological Feature Extraction", which judges a
//! bar by its persistence alone).
//!
//! A hole of the free space is a place no agent enters. An agent's two consecutive
//! encounters, `Δt` apart, bound its walk between them: at most `v · Δt` long, and in the
//! encounter point cloud (whose unit is a second of walk) it runs about along the straight
//! segment between the two encounters' places. Round a real obstacle every such segment
//! goes round the void, except where the embedding misplaces an encounter. A noise loop is
//! a void of the *cloud*, not of the arena: agents walked through that place, and their
//! time lines cross it.
//!
//! So, for an H1 bar whose death triangle (its void, [`crate::topology::rips::Bar`]) has
//! centroid `c` and whose death is `d` (the void's scale is `r = d / √3`, the circumradius
//! of an equilateral triangle of side `d`), the *crossing share* is
//!
//! `#{ segments passing within CORE · r of c } / #{ segments with an end within NEAR · r of c }`,
//!
//! over the time-line segments of moving agents: consecutive encounters of one agent
//! (ordered by their middles) while it is not a static landmark. A landmark's own
//! encounters all lie at its place; their segments say nothing about walking.
//!
//! Measured (docs/accuracy.md, step 37) on scenario 3 (seeds 1–20, bars with a life of
//! at least 2.5 σ): loops round an obstacle have shares of 0–0.045 (median 0.003), loops
//! that are no obstacle 0.005–0.134 (median 0.049). A strong signal but not a clean cut:
//! the embedding scatters some small obstacles' encounters across their void. The
//! classifier's `h1_crossing` ([`super::classify::Classifier`]) is the largest share a hole
//! may have; `swarmmap calibrate --crossing` fits it with the other thresholds, and the
//! shipped models have none (fitted on the training worlds it gains 4 of 450 windows and
//! loses scenario 3's small obstacles).
//!
//! Cost: O(s) per bar for s segments (two per encounter at most); computed only for bars
//! whose life is at least [`CROSSING_FLOOR`] σ: 95–124 per window of scenario 2, 225–270 of
//! scenario 3 (seed 1, seed 7).

use crate::log::Encounter;

/// Segments passing within `CORE · r` of the void's centre cross it.
pub const CORE: f64 = 0.5;

/// Segments with an end within `NEAR · r` of the void's centre are the ones that could.
pub const NEAR: f64 = 2.0;

/// The smallest life, in σ, that a rule with a crossing test may ask
/// (`swarmmap calibrate --crossing` searches lives from it).
pub const CROSSING_MIN_SPAN: f64 = 1.0;

/// Bars with a life below `CROSSING_FLOOR · σ` get no share, and pass any crossing test.
/// It is the candidate test's share ([`super::classify::CANDIDATE_SHARE`]) of
/// [`CROSSING_MIN_SPAN`], so every bar that a rule with a crossing test, or its candidate
/// test, can keep has a share.
pub const CROSSING_FLOOR: f64 = 0.75;

/// The time-line segments of a component's moving agents on the plane of its cloud.
#[derive(Debug, Clone, Default)]
pub struct TimeLines {
    segments: Vec<[[f64; 2]; 2]>,
}

impl TimeLines {
    /// The segments between consecutive encounters (indices `members` into `enc`, placed at
    /// `points`) of every agent, in order of the encounters' middles, leaving out pairs in
    /// which `moving(agent, encounter)` is false for either end, and pairs with a non-finite
    /// place.
    pub fn new(
        points: &[[f64; 3]],
        enc: &[Encounter],
        members: &[usize],
        moving: impl Fn(u32, usize) -> bool,
    ) -> Self {
        let mut visits: Vec<(u32, f64, usize)> = Vec::with_capacity(2 * members.len());
        for &j in members {
            let e = &enc[j];
            let mid = 0.5 * (e.start + e.end);
            visits.push((e.a, mid, j));
            visits.push((e.b, mid, j));
        }
        visits.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
        let plane = |j: usize| [points[j][0], points[j][1]];
        let segments = visits
            .windows(2)
            .filter(|w| w[0].0 == w[1].0)
            .filter(|w| moving(w[0].0, w[0].2) && moving(w[1].0, w[1].2))
            .map(|w| [plane(w[0].2), plane(w[1].2)])
            .filter(|s| s.iter().flatten().all(|v| v.is_finite()))
            .collect();
        Self { segments }
    }

    /// The segments, each as its two ends.
    pub fn segments(&self) -> &[[[f64; 2]; 2]] {
        &self.segments
    }

    /// The crossing share of a void centred at `centre` with scale `r` (module docs);
    /// `None` if no segment ends near it.
    pub fn share(&self, centre: [f64; 2], r: f64) -> Option<f64> {
        let (core, near) = (CORE * r, NEAR * r);
        let (mut crossing, mut close) = (0usize, 0usize);
        for &[p, q] in &self.segments {
            if dist(p, centre) > near && dist(q, centre) > near {
                continue;
            }
            close += 1;
            if segment_dist(p, q, centre) < core {
                crossing += 1;
            }
        }
        (close > 0).then(|| crossing as f64 / close as f64)
    }
}

fn dist(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// Distance from `c` to the segment `p`–`q`.
fn segment_dist(p: [f64; 2], q: [f64; 2], c: [f64; 2]) -> f64 {
    let d = [q[0] - p[0], q[1] - p[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = if len2 > 0.0 {
        (((c[0] - p[0]) * d[0] + (c[1] - p[1]) * d[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist([p[0] + t * d[0], p[1] + t * d[1]], c)
}

/// The centre and scale `r` of the void of a triangle with corners `tri` (planar) and
/// longest edge `death` (module docs).
pub fn void_disc(tri: [[f64; 2]; 3], death: f64) -> ([f64; 2], f64) {
    let c = [
        (tri[0][0] + tri[1][0] + tri[2][0]) / 3.0,
        (tri[0][1] + tri[1][1] + tri[2][1]) / 3.0,
    ];
    (c, death / 3f64.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn enc(a: u32, b: u32, t: f64) -> Encounter {
        Encounter {
            start: t,
            end: t,
            a,
            b,
            truth: None,
        }
    }

    /// An agent walking round a ring of radius 1.8 about the origin, with encounters every
    /// 30° (never inside): the chords of a 30° step stay 1.74 from the centre, so the share
    /// of a void of scale 1 there is 0 (every segment ends within 2 of it).
    #[test]
    fn a_ring_round_the_void_does_not_cross_it() {
        let mut points = Vec::new();
        let mut e = Vec::new();
        for k in 0..12 {
            let a = k as f64 * std::f64::consts::PI / 6.0;
            points.push([1.8 * a.cos(), 1.8 * a.sin(), 0.0]);
            e.push(enc(1, 100 + k, k as f64));
        }
        let members: Vec<usize> = (0..12).collect();
        let lines = TimeLines::new(&points, &e, &members, |_, _| true);
        assert_eq!(
            lines.segments().len(),
            11,
            "agent 1's time line; the others met once"
        );
        assert_eq!(lines.share([0.0, 0.0], 1.0), Some(0.0));
    }

    /// One agent going straight through the void and three going round it: of the four
    /// segments with an end within 2 r, one passes within 0.5 r.
    #[test]
    fn a_walk_through_the_void_crosses_it() {
        let points = vec![
            [-1.5, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [-1.5, 1.5, 0.0],
            [1.5, 1.5, 0.0],
            [-1.5, -1.5, 0.0],
            [1.5, -1.5, 0.0],
            [0.0, 1.9, 0.0],
            [0.0, -1.9, 0.0],
        ];
        // Agent 1 crosses (0 → 1); agent 2 goes over the top (2 → 6 → 3); agent 3 under
        // (4 → 7 → 5). Partners 10.. meet once each.
        let e = vec![
            enc(1, 10, 0.0),
            enc(1, 11, 10.0),
            enc(2, 12, 0.0),
            enc(2, 13, 20.0),
            enc(3, 14, 0.0),
            enc(3, 15, 20.0),
            enc(2, 16, 10.0),
            enc(3, 17, 10.0),
        ];
        let members: Vec<usize> = (0..8).collect();
        let lines = TimeLines::new(&points, &e, &members, |_, _| true);
        assert_eq!(lines.segments().len(), 5);
        // r = 1: every segment has an end within 2 (the corners are 2.12 from the centre,
        // the tops 1.9, the crossing's ends 1.5); only agent 1's passes within 0.5.
        assert_eq!(lines.share([0.0, 0.0], 1.0), Some(0.2));
        // A void far away has no segment near it.
        assert_eq!(lines.share([50.0, 0.0], 1.0), None);
        // Leaving out agent 1's time line (as for a static landmark) removes the crossing.
        let still = TimeLines::new(&points, &e, &members, |agent, _| agent != 1);
        assert_eq!(still.share([0.0, 0.0], 1.0), Some(0.0));
    }

    /// The distance to a segment against brute force along it.
    #[test]
    fn segment_distance_matches_sampling() {
        let cases = [
            ([0.0, 0.0], [4.0, 0.0], [2.0, 3.0]),
            ([0.0, 0.0], [4.0, 0.0], [-3.0, 4.0]),
            ([1.0, 1.0], [1.0, 1.0], [4.0, 5.0]),
            ([-2.0, 1.0], [3.0, -1.5], [0.3, 0.7]),
        ];
        for (p, q, c) in cases {
            let brute = (0..=100_000)
                .map(|k| {
                    let t = k as f64 / 100_000.0;
                    dist([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])], c)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                (segment_dist(p, q, c) - brute).abs() < 1e-4,
                "{p:?} {q:?} {c:?}"
            );
        }
    }

    /// Non-finite places are left out, and the void's disc is the centroid with d / √3.
    #[test]
    fn non_finite_places_are_left_out_and_the_disc_is_the_centroid() {
        let points = vec![[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let e = vec![enc(1, 10, 0.0), enc(1, 11, 1.0), enc(1, 12, 2.0)];
        let lines = TimeLines::new(&points, &e, &[0, 1, 2], |_, _| true);
        assert!(lines.segments().is_empty());
        let (c, r) = void_disc([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]], 3.0);
        assert_eq!(c, [1.0, 1.0]);
        assert!((r - 3.0 / 3f64.sqrt()).abs() < 1e-15);
    }
}
