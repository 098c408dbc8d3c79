//! What `swarmmap map` writes: `maps/window_<i>.json` per window and `summary.json`
//! (documented column by column in the README, "Output files").

use super::local::LocalMap;
use crate::log::EncounterLog;
use serde::Serialize;
use std::collections::BTreeMap;

/// Geometric fidelity of one window against the log's truth columns.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Fidelity {
    /// Spearman rank correlation between the encounter metric and true distances over
    /// the (representative, event) pairs of the window.
    pub spearman: Option<f64>,
    /// RMS Procrustes residual of the embedding's first two coordinates against the true
    /// positions (similarity fit), divided by the diagonal of the window's domain.
    pub procrustes: Option<f64>,
}

/// One window's line in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct WindowSummary {
    pub index: usize,
    pub start: f64,
    pub end: f64,
    pub events: usize,
    pub betti: [usize; 2],
    pub truth: Option<[usize; 2]>,
    /// The domain D_i as `[x_min, x_max]`, metres, when the leader's track is known.
    pub domain: Option<[f64; 2]>,
    pub fidelity: Fidelity,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub world: String,
    pub seed: Option<u64>,
    pub windows: Vec<WindowSummary>,
    /// Seconds spent in each stage.
    pub timings: BTreeMap<String, f64>,
}

/// An event of a window as written in `window_<i>.json`.
#[derive(Debug, Clone, Serialize)]
struct EventOut {
    start: f64,
    end: f64,
    a: u32,
    b: u32,
    /// Position in the 3-D encounter point cloud.
    point: [f64; 3],
    /// Whether the event belongs to a noise component.
    noise: bool,
}

#[derive(Serialize)]
struct WindowOut<'a> {
    index: usize,
    start: f64,
    end: f64,
    betti: [usize; 2],
    truth: Option<[usize; 2]>,
    explained: f64,
    events: Vec<EventOut>,
    components: &'a [super::local::Component],
}

/// The JSON text of `maps/window_<i>.json`.
pub fn window_json(map: &LocalMap, log: &EncounterLog, truth: Option<[usize; 2]>) -> String {
    let events = map
        .events
        .iter()
        .zip(&map.points)
        .zip(&map.noise)
        .map(|((&i, p), &noise)| {
            let e = &log.encounters[i];
            EventOut {
                start: e.start,
                end: e.end,
                a: e.a,
                b: e.b,
                point: *p,
                noise,
            }
        })
        .collect();
    let out = WindowOut {
        index: map.index,
        start: map.start,
        end: map.end,
        betti: map.betti,
        truth,
        explained: map.explained,
        events,
        components: &map.components,
    };
    serde_json::to_string_pretty(&out).expect("window maps serialise")
}
