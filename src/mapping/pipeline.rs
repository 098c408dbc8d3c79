//! The mapping stage end to end: windows → local maps → (with a world) truth and fidelity.
//! Windows are independent, so they are mapped in parallel (rayon); the result does not
//! depend on the number of threads.

use super::local::{LocalMap, LocalParams, local_map};
use super::output::{Fidelity, WindowSummary};
use super::windows::{Window, windows};
use crate::eval::fidelity::{procrustes_error, spearman};
use crate::eval::truth::{FreeSpace, window_band};
use crate::log::EncounterLog;
use crate::topology::rips::RipsOptions;
use crate::world::World;
use rayon::prelude::*;

/// How to cut the log into windows and map each.
#[derive(Debug, Clone, PartialEq)]
pub struct MapConfig {
    /// Number of windows N.
    pub windows: usize,
    /// Overlap Δt between consecutive windows, seconds.
    pub overlap: f64,
    /// The mapped span `[t0, t1]`, seconds.
    pub span: (f64, f64),
    pub local: LocalParams,
}

impl MapConfig {
    /// The configuration a world asks for: its `mapping` section over the whole run
    /// `[0, T]`, dispersion included (paper: ∪ W_i = [0, T]).
    pub fn for_world(world: &World) -> Self {
        Self {
            windows: world.mapping.windows,
            overlap: world.mapping.overlap,
            span: (0.0, world.total_duration()),
            local: LocalParams::from_mapping_at(&world.mapping, world.leader.speed),
        }
    }

    /// The windows of this configuration.
    pub fn windows(&self) -> Vec<Window> {
        windows(self.span.0, self.span.1, self.windows, self.overlap)
    }
}

/// Maps every window of the log.
pub fn map_windows(log: &EncounterLog, cfg: &MapConfig) -> Vec<LocalMap> {
    cfg.windows()
        .par_iter()
        .map(|w| local_map(log, w, &cfg.local))
        .collect()
}

/// The true position of an encounter: the midpoint of the two agents at its start.
pub fn true_position(t: &[f64; 4]) -> [f64; 2] {
    [(t[0] + t[2]) / 2.0, (t[1] + t[3]) / 2.0]
}

/// Geometric fidelity of a local map against the log's truth columns (none without them).
pub fn fidelity(map: &LocalMap, log: &EncounterLog, diagonal: f64, rips_points: usize) -> Fidelity {
    // A window without events has all of its (no) truth, so ask the log: a log without
    // truth columns gives no fidelity, not even for an empty window; an empty simulated
    // log (no encounter lacks truth) still gives the empty window's oracle, (0, 0).
    if log.encounters.iter().any(|e| e.truth.is_none()) {
        return Fidelity::default();
    }
    let Some(truth) = true_positions(map, log) else {
        return Fidelity::default();
    };
    // Rank correlation over (representative, event) pairs, thinned to at most ~50 000
    // pairs with a fixed stride so it stays cheap and deterministic.
    let total: usize = map.rows.iter().map(|(_, r)| r.len()).sum();
    let stride = (total / 50_000).max(1);
    let (mut metric, mut dist) = (Vec::new(), Vec::new());
    let mut k = 0usize;
    for (p, row) in &map.rows {
        for (j, &d) in row.iter().enumerate() {
            k += 1;
            if !k.is_multiple_of(stride) || !d.is_finite() || j == *p {
                continue;
            }
            let (a, b) = (truth[*p], truth[j]);
            metric.push(d);
            dist.push((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    let rho = spearman(&metric, &dist);
    // Procrustes per component (each has its own embedding frame), weighted by size.
    let (mut sum, mut count) = (0.0, 0usize);
    for c in &map.components {
        let est: Vec<[f64; 2]> = c
            .events
            .iter()
            .map(|&j| [map.points[j][0], map.points[j][1]])
            .collect();
        let tr: Vec<[f64; 2]> = c.events.iter().map(|&j| truth[j]).collect();
        let e = procrustes_error(&est, &tr);
        if e.is_finite() {
            sum += e * e * c.events.len() as f64;
            count += c.events.len();
        }
    }
    let procrustes = (count > 0 && diagonal > 0.0).then(|| (sum / count as f64).sqrt() / diagonal);
    Fidelity {
        spearman: rho.is_finite().then_some(rho),
        procrustes,
        oracle: Some(oracle_betti(map, &truth, rips_points)),
    }
}

/// Per real component of `map`, the features of the `Embedded` topology stage run on the
/// true positions `truth` (one per event of `map`) of its events; see [`Fidelity::oracle`].
pub fn oracle_features(
    map: &LocalMap,
    truth: &[[f64; 2]],
    rips_points: usize,
) -> Vec<Vec<super::classify::Feature>> {
    let mapped: usize = map.components.iter().map(|c| c.events.len()).sum();
    map.components
        .iter()
        .filter_map(|c| {
            let coords: Vec<[f64; 3]> = c
                .events
                .iter()
                .map(|&j| [truth[j][0], truth[j][1], 0.0])
                .collect();
            let (diagram, _) = super::dense::dense_rips(
                &coords,
                &super::dense::DenseParams::embedded_with(rips_points)
                    .for_share(c.events.len() as f64 / mapped as f64),
                &RipsOptions::default(),
            )?;
            Some(super::classify::features(&diagram))
        })
        .collect()
}

/// The true positions of a map's events, if the log has truth columns.
pub fn true_positions(map: &LocalMap, log: &EncounterLog) -> Option<Vec<[f64; 2]>> {
    map.events
        .iter()
        .map(|&i| log.encounters[i].truth.as_ref().map(true_position))
        .collect()
}

/// (β0, β1) of the oracle: [`oracle_features`] judged by the oracle model fitted nearest
/// the window's density (the oracle samples the same events with as many points).
fn oracle_betti(map: &LocalMap, truth: &[[f64; 2]], rips_points: usize) -> [usize; 2] {
    let classifier = super::classify::Models::active()
        .oracle
        .pick(map.events_per_point)
        .classifier;
    let mut betti = [0, 0];
    for features in oracle_features(map, truth, rips_points) {
        let b = classifier.betti(&features);
        betti[0] += b[0];
        betti[1] += b[1];
    }
    betti
}

/// The summary line of each window; with a world, its truth and fidelity too.
pub fn summarise(
    maps: &[LocalMap],
    log: &EncounterLog,
    truth: Option<(&World, &FreeSpace)>,
) -> Vec<WindowSummary> {
    // Windows are independent (the fidelity reruns the topology stage on true positions):
    // in parallel, collected in order.
    maps.par_iter()
        .map(|m| summarise_window(m, log, truth))
        .collect()
}

/// The summary line of one window; with a world, its truth and fidelity too.
pub fn summarise_window(
    m: &LocalMap,
    log: &EncounterLog,
    truth: Option<(&World, &FreeSpace)>,
) -> WindowSummary {
    let band = truth.map(|(w, _)| window_band(w, m.start, m.end));
    let diagonal = match (truth, band) {
        (Some((w, _)), Some((a, b))) => (b - a).hypot(w.arena.height),
        _ => 0.0,
    };
    WindowSummary {
        index: m.index,
        start: m.start,
        end: m.end,
        events: m.events.len(),
        betti: m.betti,
        truth: truth
            .zip(band)
            .map(|((w, fs), (a, b))| fs.reached_by(w, m.end).betti_in_band(a, b)),
        domain: band.map(|(a, b)| [a, b]),
        holes: truth.zip(band).and_then(|((w, fs), (a, b))| {
            let positions = true_positions(m, log)?;
            Some(crate::eval::holes::check(
                m,
                &positions,
                &fs.reached_by(w, m.end).holes_in_band(a, b),
            ))
        }),
        fidelity: fidelity(
            m,
            log,
            diagonal,
            truth.map_or(super::dense::EMBEDDED_POINTS, |(w, _)| {
                w.mapping.rips_points
            }),
        ),
    }
}

#[cfg(test)]
mod oracle_tests {
    use super::*;
    use crate::log::Encounter;
    use crate::mapping::local::Component;
    use rand::{RngExt, SeedableRng};

    /// A one-component map whose events lie, in truth, uniformly in the region
    /// `keep` of the square [-2, 2]²; the map's own points are meaningless (zeros).
    fn map_over(keep: impl Fn(f64, f64) -> bool) -> (LocalMap, Vec<[f64; 2]>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut truth = Vec::new();
        while truth.len() < 2000 {
            let (x, y) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            if keep(x, y) {
                truth.push([x, y]);
            }
        }
        let n = truth.len();
        let map = LocalMap {
            index: 1,
            start: 0.0,
            end: 1.0,
            events: (0..n).collect(),
            points: vec![[0.0; 3]; n],
            noise: vec![false; n],
            components: vec![Component {
                events: (0..n).collect(),
                representatives: (0..300).collect(),
                scale: 0.0,
                diagram: Vec::new(),
                betti: [1, 0],
                holes: Vec::new(),
                candidates: Vec::new(),
            }],
            betti: [1, 0],
            explained: 1.0,
            events_per_point: 1.0,
            outlier_rank: 8,
            classifier: crate::mapping::classify::Classifier::default(),
            rows: Vec::new(),
        };
        (map, truth)
    }

    #[test]
    fn oracle_sees_the_hole_of_an_annulus_and_none_in_a_disc() {
        let (map, truth) = map_over(|x, y| (1.0..=2.0).contains(&x.hypot(y)));
        assert_eq!(
            oracle_betti(&map, &truth, super::super::dense::EMBEDDED_POINTS),
            [1, 1]
        );
        let (map, truth) = map_over(|x, y| x.hypot(y) <= 2.0);
        assert_eq!(
            oracle_betti(&map, &truth, super::super::dense::EMBEDDED_POINTS),
            [1, 0]
        );
    }

    #[test]
    fn fidelity_carries_the_oracle_only_with_truth_columns() {
        let (map, truth) = map_over(|x, y| (1.0..=2.0).contains(&x.hypot(y)));
        let mut log = EncounterLog::default();
        for p in &truth {
            log.encounters.push(Encounter {
                start: 0.0,
                end: 0.0,
                a: 0,
                b: 1,
                truth: Some([p[0], p[1], p[0], p[1]]),
            });
        }
        assert_eq!(
            fidelity(&map, &log, 1.0, super::super::dense::EMBEDDED_POINTS).oracle,
            Some([1, 1])
        );
        for e in &mut log.encounters {
            e.truth = None;
        }
        assert_eq!(
            fidelity(&map, &log, 1.0, super::super::dense::EMBEDDED_POINTS).oracle,
            None
        );
    }
}
