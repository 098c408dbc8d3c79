//! The mapping stage end to end: windows → local maps → (with a world) truth and fidelity.
//! Windows are independent, so they are mapped in parallel (rayon); the result does not
//! depend on the number of threads.

use super::local::{LocalMap, LocalParams, local_map};
use super::output::{Fidelity, WindowSummary};
use super::windows::{Window, windows};
use crate::eval::fidelity::{procrustes_error, spearman};
use crate::eval::truth::{FreeSpace, window_band};
use crate::log::EncounterLog;
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
            local: LocalParams::from_mapping(&world.mapping),
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
pub fn fidelity(map: &LocalMap, log: &EncounterLog, diagonal: f64) -> Fidelity {
    let truth: Option<Vec<[f64; 2]>> = map
        .events
        .iter()
        .map(|&i| log.encounters[i].truth.as_ref().map(true_position))
        .collect();
    let Some(truth) = truth else {
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
    }
}

/// The summary line of each window; with a world, its truth and fidelity too.
pub fn summarise(
    maps: &[LocalMap],
    log: &EncounterLog,
    truth: Option<(&World, &FreeSpace)>,
) -> Vec<WindowSummary> {
    maps.iter()
        .map(|m| {
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
                    .map(|((_, fs), (a, b))| fs.betti_in_band(a, b)),
                domain: band.map(|(a, b)| [a, b]),
                fidelity: fidelity(m, log, diagonal),
            }
        })
        .collect()
}
