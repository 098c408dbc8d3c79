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
    /// (β0, β1) that the topology stage finds on the events' *true* positions: each real
    /// component's events at their true positions, the same number of representatives
    /// (density filter + MaxMin), planar Vietoris–Rips and the shipped `Embedded`
    /// classifier. It separates the two sources of error: a window whose `oracle` is
    /// right but whose `betti` is wrong lost its features in the metric; one whose
    /// `oracle` is wrong too lost them in the sampling or the classification.
    pub oracle: Option<[usize; 2]>,
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

/// The connections between two consecutive windows in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ConnectionSummary {
    /// 1-based indices of the two windows.
    pub between: [usize; 2],
    /// Estimated number of connections (clusters of the inter-domain cloud).
    pub count: usize,
    /// True number: components of the reachable free space in D_i ∩ D_{i+1}.
    pub truth: Option<usize>,
}

/// The global map's Betti numbers in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct GlobalSummary {
    pub betti: [usize; 2],
    pub truth: Option<[usize; 2]>,
    /// Cycle rank of the gluing graph (holes no single window saw whole).
    pub gluing_cycles: usize,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub world: String,
    pub seed: Option<u64>,
    pub windows: Vec<WindowSummary>,
    pub connections: Vec<ConnectionSummary>,
    pub global: GlobalSummary,
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

fn betti_cell(b: [usize; 2], t: Option<[usize; 2]>) -> String {
    match t {
        Some(t) => format!(
            "({},{}) vs ({},{}) {}",
            b[0],
            b[1],
            t[0],
            t[1],
            if b == t { "ok" } else { "WRONG" }
        ),
        None => format!("({},{})", b[0], b[1]),
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.digits$}"))
}

impl Summary {
    /// The compact table `swarmmap run` and `swarmmap map` print: per window β vs truth,
    /// connections vs truth, global β vs truth, fidelity, and each stage's time.
    pub fn table(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "{} (seed {})\n",
            self.world,
            self.seed.map_or_else(|| "-".into(), |x| x.to_string())
        ));
        s.push_str("window  span (s)           events  (β0,β1) vs truth   spearman  procrustes\n");
        for w in &self.windows {
            s.push_str(&format!(
                "{:>6}  {:>7.0}–{:<7.0}  {:>8}  {:<19} {:>8}  {:>10}\n",
                w.index,
                w.start,
                w.end,
                w.events,
                betti_cell(w.betti, w.truth),
                opt(w.fidelity.spearman, 2),
                opt(w.fidelity.procrustes, 3),
            ));
        }
        for c in &self.connections {
            let truth = c.truth.map_or_else(String::new, |t| {
                format!(" vs {t} {}", if t == c.count { "ok" } else { "WRONG" })
            });
            s.push_str(&format!(
                "connections {}–{}: {}{}\n",
                c.between[0], c.between[1], c.count, truth
            ));
        }
        s.push_str(&format!(
            "global (β0,β1): {}\n",
            betti_cell(self.global.betti, self.global.truth)
        ));
        let total: f64 = self.timings.values().sum();
        let parts: Vec<String> = self
            .timings
            .iter()
            .map(|(k, v)| format!("{k} {v:.2} s ({:.0} %)", 100.0 * v / total.max(1e-12)))
            .collect();
        s.push_str(&format!("time: {total:.2} s = {}\n", parts.join(", ")));
        s
    }
}
