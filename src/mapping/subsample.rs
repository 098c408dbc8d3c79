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
    /// Neighbour rank k of the density estimate (default: `8`).
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
