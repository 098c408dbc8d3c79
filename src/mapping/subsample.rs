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

use super::encounter_graph::EncounterGraph;

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
    let mut picks = Vec::new();
    let mut rows = Vec::new();
    if members.is_empty() || count == 0 {
        return Subsample { picks, rows };
    }
    let probe = graph.distances_from(members[0]);
    let mut next = farthest(members, &probe);
    let mut nearest = vec![f64::INFINITY; members.len()];
    while picks.len() < count.min(members.len()) {
        let row = graph.distances_from(next);
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
        if d <= 0.0 && picks.len() > 1 {
            // Every remaining member coincides with a pick: nothing more to represent.
            break;
        }
        next = members[k];
    }
    Subsample { picks, rows }
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
    let want = ((p.m as f64) * p.oversample).ceil() as usize;
    let cand = maxmin(graph, members, want);
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
}
