//! Density-based subsampling of a window's encounters on the encounter metric (paper
//! §"Topological Feature Extraction", after Dirafzoon et al. 2014).
//!
//! Persistence is computed on m representative encounters, never on all of them, and the
//! full encounters × encounters matrix is never formed: MaxMin (farthest-point) selection
//! needs one single-source shortest-path run per pick, and those m rows are all the later
//! stages need (the m × m matrix for persistence, the m × n rows for landmark MDS).
//!
//! Outliers (a handful of stray encounters far from everything, e.g. a late encounter
//! joined to the rest by one long wait) are exactly what farthest-point selection picks
//! first, so we select `oversample · m` candidates, estimate each candidate's local density
//! from its own row (the distance to its k-th nearest encounter), drop candidates whose
//! k-NN radius exceeds `outlier_factor` times the median, and keep the first m survivors
//! in MaxMin order. Cost: O(oversample · m · (n + E) log n) time, O(m · n) memory.
//!
//! The radius counts encounters, not places. Among the `Embedded` method's candidates (the
//! encounters with landmarks) every encounter of one landmark interval is at distance 0
//! from the others, so a landmark met more than k times has a radius of 0; once such
//! landmarks are half the picks the median is 0 and every landmark met k times or fewer is
//! dropped, wherever it stands. The filter then keeps the landmarks met often, whose
//! distances rest on many walks. Measured on scenario 3, seeds 1–20 (docs/accuracy.md,
//! steps 49 and 50):
//! - a radius that counts a landmark's copies once keeps the rarely met landmarks (and
//!   still drops the strays) and makes the maps worse: 14 global maps right of 20 against
//!   15, 13 with the classifier refitted;
//! - k = 16 instead of 8 makes them better: 18 of 20, and 16 of the held-out seeds 21–40
//!   (was 14), but scenarios 1 and 2, swept twice as fast, get worse (18 and 16 of 20
//!   against 20 and 18).
//!
//! The count a landmark reaches grows with how long it stands, and a landmark stands
//! while the leader's domain (l metres wide) passes it: l / v_leader, twice as long in
//! scenario 3, whose leader sweeps at half the paper's speed (scenario 2 seed 7: landmark
//! intervals over 60 s last a median 352 s, 75th and 90th percentiles of their encounters
//! 35 and 52; scenario 3 seed 7: 716 s, 57 and 96). So the rank scales with the sweep
//! ([`rank_for_sweep`]): k = 8 at the paper's 0.005 m/s, 16 at scenario 3's 0.0025 m/s;
//! a landmark met at the same rate, not the same number of times, counts as sparse.
//!
//! The picks are sequential (each needs the previous one's row), so when cores would
//! otherwise sit idle, [`maxmin_with`] computes the rows of the likely next picks beside
//! each needed one; the result is the same, bit for bit.

use super::encounter_graph::EncounterGraph;
use rayon::prelude::*;

/// A subsample: the picked encounters and their distance rows.
#[derive(Debug, Clone)]
pub struct Subsample {
    /// Indices (into the graph's encounters) of the picks, in MaxMin order.
    pub picks: Vec<usize>,
    /// `rows[i][j]`: metric distance from `picks[i]` to encounter `j` (all encounters).
    pub rows: Vec<Vec<f64>>,
}

/// Parameters of the subsampling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubsampleParams {
    /// Number of representatives m (default: `400`).
    pub m: usize,
    /// Candidates per kept representative (default: `1.0`: outliers are dropped from the m
    /// picks, so a window may keep slightly fewer than m).
    pub oversample: f64,
    /// Neighbour rank k of the density estimate (default: `8`; a world's mapping scales
    /// it with the sweep, [`rank_for_sweep`], unless its `mapping.outlier_rank` fixes it).
    pub k: usize,
    /// A candidate whose k-NN radius exceeds this multiple of the median is an outlier
    /// (default: `3.0`).
    pub outlier_factor: f64,
}

impl Default for SubsampleParams {
    fn default() -> Self {
        Self {
            m: 400,
            oversample: 1.0,
            k: 8,
            outlier_factor: 3.0,
        }
    }
}

/// The neighbour rank k of the density estimate for a leader sweeping at `sweep` m/s: 8 at
/// the paper's sweep ([`super::classify::DEFAULT_SWEEP`], every shipped model's), in
/// proportion to how long a landmark stands (`l / sweep`) elsewhere (module docs), within
/// 1 to [`MAX_RANK`]. A sweep that is not positive and finite counts as the paper's, as
/// in [`super::classify::Bank::for_sweep`].
pub fn rank_for_sweep(sweep: f64) -> usize {
    let base = SubsampleParams::default().k;
    if !(sweep.is_finite() && sweep > 0.0) {
        return base;
    }
    // A float-to-integer cast saturates (an infinite k from a subnormal sweep is
    // `usize::MAX`), so the clamp bounds every case.
    let k = base as f64 * super::classify::DEFAULT_SWEEP / sweep;
    (k.round() as usize).clamp(1, MAX_RANK)
}

/// The largest neighbour rank [`rank_for_sweep`] gives (a sweep 100 times slower than the
/// paper's).
pub const MAX_RANK: usize = 800;

/// Farthest-point selection of up to `count` encounters among `members` (one connected
/// component), starting from the member farthest from `members[0]` so the start does not
/// depend on input order artefacts.
pub fn maxmin(graph: &EncounterGraph, members: &[usize], count: usize) -> Subsample {
    maxmin_with(graph, members, count, &|| 0)
}

/// How many of the last picks' rows bound the distances to a guessed pick
/// ([`maxmin_with`]).
const GUESS_ROWS: usize = 8;
/// Most guessed rows per needed row ([`maxmin_with`]): each further guess in a chain is
/// less likely to be picked (only one guess was measured, on two cores).
pub const MAX_LOOKAHEAD: usize = 3;
/// Most guessed rows kept for later ([`maxmin_with`]): a wrong guess is dropped, oldest
/// first, so the rows kept and the search for new guesses stay small.
const KEPT_AHEAD: usize = 2 * MAX_LOOKAHEAD;

/// [`maxmin`] that also computes, beside each row it needs, the rows of the `lookahead()`
/// members most likely to be picked next (asked again before each row it needs, so a
/// caller can raise it once other work has left cores idle; at most [`MAX_LOOKAHEAD`]),
/// on the current rayon pool; the picks and rows
/// are exactly [`maxmin`]'s (each row is the same shortest-path run, whichever thread
/// makes it and whether or not it is used), only the wall-clock time differs.
///
/// MaxMin picks one after another, each pick needing the previous one's row, so it leaves
/// the other cores idle when one window is mapped alone (the last window of
/// `swarmmap run`, after the simulation). Which member the next pick will be is guessed
/// from the triangle inequality: once `x` is picked, member `j`'s distance to the picks is
/// at least `min(nearest(j), max_p |d(p, j) − d(p, x)|)` over the last
/// [`GUESS_ROWS`] picks `p`, and the member where that bound is largest is the guess (on
/// scenario 2's windows the guess was the next pick in 85–93 % of the steps). A wrong
/// guess costs one row's work, on a core that is idle only if the caller's `lookahead`
/// counts idle cores (the pipeline asks for none inside a campaign's pool, whose threads
/// run other jobs); while `lookahead()` is 0 nothing is guessed. At most [`KEPT_AHEAD`]
/// guessed rows are kept beyond the O(m · n) of the picks' rows.
pub fn maxmin_with(
    graph: &EncounterGraph,
    members: &[usize],
    count: usize,
    lookahead: &(dyn Fn() -> usize + Sync),
) -> Subsample {
    maxmin_counting(graph, members, count, lookahead).0
}

/// [`maxmin_with`], and how many guessed rows it used.
fn maxmin_counting(
    graph: &EncounterGraph,
    members: &[usize],
    count: usize,
    lookahead: &(dyn Fn() -> usize + Sync),
) -> (Subsample, usize) {
    let mut used = 0;
    let mut picks = Vec::new();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    if members.is_empty() || count == 0 {
        return (Subsample { picks, rows }, used);
    }
    let probe = graph.distances_from(members[0]);
    let mut next = farthest(members, &probe);
    let mut nearest = vec![f64::INFINITY; members.len()];
    // Rows computed ahead of their pick: (place in `members`, row).
    let mut ahead: Vec<(usize, Vec<f64>)> = Vec::new();
    while picks.len() < count.min(members.len()) {
        let row = match ahead.iter().position(|&(k, _)| members[k] == next) {
            Some(at) => {
                used += 1;
                ahead.remove(at).1
            }
            None => match lookahead().min(MAX_LOOKAHEAD) {
                0 => graph.distances_from(next),
                lookahead => {
                    let (row, made) = rayon::join(
                        || graph.distances_from(next),
                        || {
                            guesses(members, &nearest, &rows, next, &ahead, lookahead)
                                .into_par_iter()
                                .map(|k| (k, graph.distances_from(members[k])))
                                .collect::<Vec<_>>()
                        },
                    );
                    ahead.extend(made);
                    let surplus = ahead.len().saturating_sub(KEPT_AHEAD);
                    ahead.drain(..surplus);
                    row
                }
            },
        };
        for (k, &j) in members.iter().enumerate() {
            nearest[k] = nearest[k].min(row[j]);
        }
        picks.push(next);
        rows.push(row);
        let (k, d) = nearest
            .iter()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |best, (k, &d)| {
                if d > best.1 { (k, d) } else { best }
            });
        if d <= 0.0 {
            // Every remaining member coincides with a pick: nothing more to represent (with
            // one pick too: picking the same place again gave landmark MDS a zero matrix).
            break;
        }
        next = members[k];
        // A row computed ahead is kept only while its member may still be picked.
        ahead.retain(|&(k, _)| nearest[k] > 0.0);
    }
    (Subsample { picks, rows }, used)
}

/// The places in `members` of up to `lookahead` members guessed to be picked after `next`
/// ([`maxmin_with`]), none of them `next` or already in `ahead`: each guess is the member
/// with the largest lower bound on its distance to the picks so far, `next` and the
/// earlier guesses.
fn guesses(
    members: &[usize],
    nearest: &[f64],
    rows: &[Vec<f64>],
    next: usize,
    ahead: &[(usize, Vec<f64>)],
    lookahead: usize,
) -> Vec<usize> {
    let recent = &rows[rows.len().saturating_sub(GUESS_ROWS)..];
    let mut bound = nearest.to_vec();
    let mut out: Vec<usize> = Vec::new();
    let mut assumed = next;
    for _ in 0..lookahead {
        for (b, &j) in bound.iter_mut().zip(members) {
            // `f64::max` skips the NaN of two infinite distances.
            let gap = recent
                .iter()
                .map(|r| (r[j] - r[assumed]).abs())
                .fold(0.0, f64::max);
            *b = b.min(gap);
        }
        let free = |k: usize| {
            members[k] != next && !out.contains(&k) && ahead.iter().all(|&(a, _)| a != k)
        };
        let best = bound
            .iter()
            .enumerate()
            .filter(|&(k, &b)| b > 0.0 && free(k))
            .fold(None, |best: Option<(usize, f64)>, (k, &b)| match best {
                Some((_, top)) if top >= b => best,
                _ => Some((k, b)),
            });
        let Some((k, _)) = best else { break };
        out.push(k);
        assumed = members[k];
    }
    out
}

fn farthest(members: &[usize], row: &[f64]) -> usize {
    members
        .iter()
        .copied()
        .fold((members[0], f64::NEG_INFINITY), |best, j| {
            let d = row[j];
            if d.is_finite() && d > best.1 {
                (j, d)
            } else {
                best
            }
        })
        .0
}

/// Density-aware subsample of one component: MaxMin candidates, outliers dropped.
pub fn subsample(graph: &EncounterGraph, members: &[usize], p: &SubsampleParams) -> Subsample {
    subsample_with(graph, members, p, &|| 0)
}

/// [`subsample`] with [`maxmin_with`]'s `lookahead`: the same result, computed with up to
/// `lookahead()` guessed rows beside each needed one.
pub fn subsample_with(
    graph: &EncounterGraph,
    members: &[usize],
    p: &SubsampleParams,
    lookahead: &(dyn Fn() -> usize + Sync),
) -> Subsample {
    let want = ((p.m as f64) * p.oversample).ceil() as usize;
    let cand = maxmin_with(graph, members, want, lookahead);
    if cand.picks.len() <= 3 {
        return cand;
    }
    let k = p.k.min(members.len() - 1).max(1);
    let radius: Vec<f64> = cand
        .rows
        .iter()
        .map(|row| {
            let mut d: Vec<f64> = members.iter().map(|&j| row[j]).collect();
            let k = k.min(d.len() - 1);
            d.select_nth_unstable_by(k, f64::total_cmp);
            d[k]
        })
        .collect();
    let mut sorted = radius.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let limit = p.outlier_factor * median;
    let mut out = Subsample {
        picks: Vec::new(),
        rows: Vec::new(),
    };
    for ((pick, row), r) in cand.picks.into_iter().zip(cand.rows).zip(radius) {
        if out.picks.len() == p.m {
            break;
        }
        if r <= limit {
            out.picks.push(pick);
            out.rows.push(row);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::Encounter;
    use crate::mapping::encounter_graph::Bridging;

    /// Agent 0 meets agents 1..=n at times 0..n-1 and one stray encounter much later.
    fn line_log(n: u32) -> Vec<Encounter> {
        let mut v: Vec<Encounter> = (1..=n)
            .map(|k| Encounter {
                start: (k - 1) as f64,
                end: (k - 1) as f64,
                a: 0,
                b: k,
                truth: None,
            })
            .collect();
        v.push(Encounter {
            start: 1000.0,
            end: 1000.0,
            a: 0,
            b: n + 1,
            truth: None,
        });
        v
    }

    #[test]
    fn maxmin_spreads_and_outliers_are_dropped() {
        let enc = line_log(100);
        let g = EncounterGraph::build(&enc, &[], Bridging::Paper);
        let members: Vec<usize> = (0..enc.len()).collect();
        let s = maxmin(&g, &members, 4);
        // Farthest from the first member is the stray encounter, then the start of the line
        // (1000 s away), then its end (98 s from the start), then its middle.
        assert_eq!(s.picks, vec![100, 0, 99, 49]);
        let p = SubsampleParams {
            m: 5,
            oversample: 2.0,
            k: 3,
            outlier_factor: 3.0,
        };
        let s = subsample(&g, &members, &p);
        assert_eq!(s.picks.len(), 5);
        assert!(
            !s.picks.contains(&100),
            "the stray encounter is an outlier: {:?}",
            s.picks
        );
    }

    /// The rank scales with how long a landmark stands, l / sweep: 8 at the paper's sweep,
    /// 16 at scenario 3's half speed, within 1 to [`MAX_RANK`].
    #[test]
    fn the_rank_scales_with_the_sweep() {
        let cases = [
            (0.005, 8),
            (0.0025, 16),
            (0.01, 4),
            (0.02, 2),
            (1.0, 1),
            (1e-5, MAX_RANK),
            (f64::MIN_POSITIVE, MAX_RANK),
            (5e-324, MAX_RANK),
            (0.0, 8),
            (-0.005, 8),
            (f64::NAN, 8),
            (f64::INFINITY, 8),
        ];
        for (sweep, k) in cases {
            assert_eq!(rank_for_sweep(sweep), k, "sweep {sweep}");
        }
        let world = crate::world::World::load("worlds/scenario3.ron").unwrap();
        let cfg = crate::mapping::pipeline::MapConfig::for_world(&world);
        assert_eq!(cfg.local.subsample.k, 16);
        let world = crate::world::World::load("worlds/scenario2.ron").unwrap();
        let cfg = crate::mapping::pipeline::MapConfig::for_world(&world);
        assert_eq!(cfg.local.subsample.k, 8);
    }

    /// The filter's radius counts encounters (module docs): ten landmarks stand one second
    /// apart along a walker's line, landmarks 0 and 9 met twice, the others twenty times
    /// each, and one more is met once 1000 s later (a stray). Each landmark is one MaxMin
    /// pick (its encounters are at distance 0 from each other); with k = 3 the landmarks
    /// met twenty times have a radius of 0, so the median is 0, and the landmarks met
    /// three times or fewer are dropped with the stray.
    #[test]
    fn landmarks_met_k_times_or_fewer_are_dropped_where_the_median_radius_is_0() {
        use crate::log::{StaticInterval, StaticReason};
        let mut enc = Vec::new();
        let mut statics = Vec::new();
        for l in 0..11u32 {
            let at = if l == 10 { 1000.0 } else { l as f64 };
            let met = match l {
                0 | 9 => 2,
                10 => 1,
                _ => 20,
            };
            statics.push(StaticInterval {
                agent: l,
                start: 0.0,
                end: 2000.0,
                reason: StaticReason::Landmark,
            });
            for c in 0..met {
                // The walker (agent 100) meets the landmark at `at`; other passers meet it
                // once each, a little later.
                let (b, t) = if c == 0 {
                    (100, at)
                } else {
                    (200 + 20 * l + c, at + 0.001 * c as f64)
                };
                enc.push(Encounter {
                    start: t,
                    end: t,
                    a: l,
                    b,
                    truth: None,
                });
            }
        }
        let g = EncounterGraph::build(&enc, &statics, Bridging::Paper);
        let members: Vec<usize> = (0..enc.len()).collect();
        let all = maxmin(&g, &members, 40);
        let landmarks = |picks: &[usize]| {
            let mut l: Vec<u32> = picks.iter().map(|&j| enc[j].a).collect();
            l.sort_unstable();
            l
        };
        assert_eq!(landmarks(&all.picks), (0..11).collect::<Vec<u32>>());
        let p = SubsampleParams {
            m: 40,
            oversample: 1.0,
            k: 3,
            outlier_factor: 3.0,
        };
        let kept = subsample(&g, &members, &p);
        assert_eq!(landmarks(&kept.picks), (1..9).collect::<Vec<u32>>());
    }

    /// Guessing rows ahead changes nothing but the time: the picks and every row are
    /// [`maxmin`]'s, bit for bit, for one to [`MAX_LOOKAHEAD`] guesses and any number of
    /// threads, on logs of the bundled worlds' graph (static landmarks, switch costs,
    /// middles), over all encounters, over the landmark encounters only (which share their
    /// star's node), and over unsorted members with duplicates; and the guessed rows are
    /// used (the test would pass vacuously if nothing were guessed).
    #[test]
    fn rows_guessed_ahead_leave_the_picks_and_rows_unchanged() {
        use crate::mapping::synthetic::{SyntheticParams, synthetic_log};
        for seed in 1..=2u64 {
            let p = SyntheticParams {
                agents: 60,
                landmarks: 12,
                seed,
                ..Default::default()
            };
            let log = synthetic_log(&p, 1_500);
            let g = EncounterGraph::build_timed(
                &log.encounters,
                &log.static_intervals,
                Bridging::Paper,
                1.0,
                true,
            );
            let all: Vec<usize> = (0..log.encounters.len()).collect();
            let landmark: Vec<usize> = all
                .iter()
                .copied()
                .filter(|&j| log.encounters[j].a < 12 || log.encounters[j].b < 12)
                .collect();
            let shuffled: Vec<usize> = (0..all.len())
                .map(|k| (k * 7919) % all.len())
                .chain([5, 5, 17])
                .collect();
            let cases = [
                (&all, 120, true),
                (&landmark, 400, true),
                (&shuffled, 120, true),
                (&all, 3, false),
                (&all, 1, false),
                (&vec![9], 4, false),
            ];
            for (members, count, guessed) in cases {
                let want = maxmin(&g, members, count);
                assert!(
                    want.picks.len() >= count.min(members.len()).min(3),
                    "seed {seed}"
                );
                for threads in [1, 2, 4] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap();
                    for lookahead in 1..=MAX_LOOKAHEAD {
                        let (got, used) =
                            pool.install(|| maxmin_counting(&g, members, count, &|| lookahead));
                        let at = format!("seed {seed}, {count} picks, lookahead {lookahead}");
                        assert_eq!(got.picks, want.picks, "{at}");
                        assert_eq!(got.rows.len(), want.rows.len());
                        for (a, b) in got.rows.iter().zip(&want.rows) {
                            assert!(
                                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                                "{at}: a row differs"
                            );
                        }
                        if guessed {
                            assert!(used > 0, "{at}: no guessed row was used");
                        }
                    }
                }
            }
        }
    }
}
