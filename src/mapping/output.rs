//! What `swarmmap map` writes: `maps/window_<i>.json` per window, `maps/connection_<i>.json`
//! per consecutive pair and `summary.json` (documented column by column in the README,
//! "Output files"). The report (`crate::report`) reads only these files.

use super::classify::Classifier;
use super::local::LocalMap;
use super::pipeline::true_position;
use super::stitch::Connection;
use crate::log::EncounterLog;
use crate::topology::DistanceMatrix;
use crate::topology::linkage::single_linkage;
use crate::topology::mds::classical_mds;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Geometric fidelity of one window against the log's truth columns.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct Fidelity {
    /// Spearman rank correlation between the encounter metric and true distances over
    /// the (representative, event) pairs of the window.
    pub spearman: Option<f64>,
    /// RMS Procrustes residual of the embedding's first two coordinates against the true
    /// positions (similarity fit), divided by the diagonal of the window's domain.
    pub procrustes: Option<f64>,
    /// (β0, β1) that the topology stage finds on the events' *true* positions: each real
    /// component's events at their true positions, then the `Embedded` method's topology
    /// stage (MaxMin of [`crate::mapping::dense::EMBEDDED_POINTS`] points shared among the
    /// components by their encounters, planar Vietoris–Rips) judged by the shipped `Oracle` model. It separates the two sources of
    /// error: a window whose `oracle` is right but whose `betti` is wrong lost its features
    /// in the metric; one whose `oracle` is wrong too lost them in the sampling or the
    /// classification.
    pub oracle: Option<[usize; 2]>,
}

/// One window's line in `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
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
    /// The robust holes matched to the obstacles of the truth (with a world and the log's
    /// truth columns; [`crate::eval::holes`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holes: Option<crate::eval::HoleCheck>,
}

/// The connections between two consecutive windows in `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ConnectionSummary {
    /// 1-based indices of the two windows.
    pub between: [usize; 2],
    /// Estimated number of connections (clusters of the inter-domain cloud).
    pub count: usize,
    /// True number: components of the reachable free space in D_i ∩ D_{i+1}.
    pub truth: Option<usize>,
}

/// The global map's Betti numbers in `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GlobalSummary {
    pub betti: [usize; 2],
    pub truth: Option<[usize; 2]>,
    /// Cycle rank of the gluing graph (holes no single window saw whole).
    pub gluing_cycles: usize,
    /// The local holes the global map kept, matched to the arena's true holes (with a
    /// world and the log's truth columns; [`crate::eval::holes::check_global`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holes: Option<crate::eval::HoleCheck>,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    pub world: String,
    pub seed: Option<u64>,
    pub windows: Vec<WindowSummary>,
    pub connections: Vec<ConnectionSummary>,
    pub global: GlobalSummary,
    /// Seconds spent in each stage, wall clock, one after another (they add up to the run).
    pub timings: BTreeMap<String, f64>,
    /// Seconds of each stage's work done on other cores while the simulation ran
    /// (`swarmmap run`; not part of `timings`' total).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub alongside: BTreeMap<String, f64>,
    /// The world the maps were judged against when it is not the one in `meta.json`
    /// (`swarmmap map --world FILE`), as `meta.json` writes a world: the report draws it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub judged_world: Option<serde_json::Value>,
}

/// An event of a window as written in `window_<i>.json`.
#[derive(Debug, Clone, Serialize)]
struct EventOut {
    /// Number of the encounter in the log's order (by start time, then `a`, then `b`: the
    /// row order of the `encounters.csv` swarmmap writes).
    encounter: usize,
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
    /// The window's encounters per Rips vertex, which picked the classifier's model.
    events_per_point: f64,
    /// The classifier's thresholds the diagrams were judged with (see `classify.rs`).
    classifier: Classifier,
    /// The outlier filter's configured neighbour rank k the representatives were picked
    /// with (`mapping.outlier_rank`, else scaled with the leader's sweep:
    /// `subsample::rank_for_sweep`).
    outlier_rank: usize,
    events: Vec<EventOut>,
    components: &'a [super::local::Component],
}

/// The JSON text of `maps/window_<i>.json`, with the thresholds of the classifier the
/// diagrams were judged with (the report draws them), the density that picked them, and
/// the outlier filter's neighbour rank.
pub fn window_json(map: &LocalMap, log: &EncounterLog, truth: Option<[usize; 2]>) -> String {
    let events = map
        .events
        .iter()
        .zip(&map.points)
        .zip(&map.noise)
        .map(|((&i, p), &noise)| {
            let e = &log.encounters[i];
            EventOut {
                encounter: i,
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
        events_per_point: map.events_per_point,
        classifier: map.classifier,
        outlier_rank: map.outlier_rank,
        events,
        components: &map.components,
    };
    serde_json::to_string_pretty(&out).expect("window maps serialise")
}

/// A point of an inter-domain cloud in `connection_<i>.json`.
#[derive(Serialize)]
struct CloudPointOut {
    /// Number of the encounter in the log's order (by start time, then `a`, then `b`: the
    /// row order of the `encounters.csv` swarmmap writes).
    encounter: usize,
    start: f64,
    a: u32,
    b: u32,
    /// Cluster label (one cluster per connection).
    label: usize,
    /// 2-D classical MDS of the correspondence metric, seconds (for drawing only).
    xy: [f64; 2],
    /// True position (midpoint of the two agents at `start`), metres, when the log has it.
    truth: Option<[f64; 2]>,
}

/// A single-linkage merge in `connection_<i>.json`, in SciPy linkage-matrix form.
#[derive(Serialize)]
struct MergeOut {
    a: usize,
    b: usize,
    /// Merge height, seconds; `null` when the two clusters are not connected in the
    /// encounter graph of W_i ∪ W_{i+1} (they never merge below any cut-off).
    height: Option<f64>,
    size: usize,
}

#[derive(Serialize)]
struct ConnectionOut<'a> {
    between: [usize; 2],
    /// The single-linkage cut-off c, seconds.
    cutoff: f64,
    count: usize,
    static_agents: &'a [u32],
    joins: &'a [(usize, usize)],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    also_joins: &'a [(usize, usize)],
    points: Vec<CloudPointOut>,
    merges: Vec<MergeOut>,
}

/// The JSON text of `maps/connection_<i>.json`: the inter-domain cloud of one pair of
/// windows with its cluster labels, a 2-D projection for drawing and its single-linkage
/// merges (for the dendrogram), and the cut-off `cutoff` (seconds) it was cut at.
///
/// The projection is classical MDS of the cloud's correspondence metric, with unreachable
/// pairs set to twice the largest finite distance (so separate parts stay apart); it costs
/// O(n²) for the n points of the cloud (a few static agents × (k + 1)).
pub fn connection_json(conn: &Connection, log: &EncounterLog, cutoff: f64) -> String {
    let n = conn.points.len();
    let (merges, xy) = match &conn.metric {
        Some(metric) if metric.len() == n && n > 0 => {
            let dendrogram = single_linkage(metric);
            let merges = dendrogram
                .merges
                .iter()
                .map(|m| MergeOut {
                    a: m.a,
                    b: m.b,
                    height: (m.height.is_finite() && m.height < super::stitch::UNREACHABLE)
                        .then_some(m.height),
                    size: m.size,
                })
                .collect();
            let finite_max = metric
                .condensed()
                .iter()
                .copied()
                .filter(|d| d.is_finite() && *d < super::stitch::UNREACHABLE)
                .fold(0.0f64, f64::max);
            let far = if finite_max > 0.0 {
                2.0 * finite_max
            } else {
                1.0
            };
            let display = DistanceMatrix::from_fn(n, |i, j| {
                let d = metric.get(i, j);
                if d.is_finite() && d < super::stitch::UNREACHABLE {
                    d
                } else {
                    far
                }
            });
            let xy = match classical_mds(&display, 2) {
                Ok(e) if e.coords.len() == n => (0..n)
                    .map(|i| {
                        let p = e.coords.point(i);
                        [
                            p.first().copied().unwrap_or(0.0),
                            p.get(1).copied().unwrap_or(0.0),
                        ]
                    })
                    .collect(),
                _ => vec![[0.0; 2]; n],
            };
            (merges, xy)
        }
        _ => (Vec::new(), vec![[0.0; 2]; n]),
    };
    let points = conn
        .points
        .iter()
        .zip(&conn.labels)
        .zip(xy)
        .map(|((&i, &label), xy)| {
            let e = &log.encounters[i];
            CloudPointOut {
                encounter: i,
                start: e.start,
                a: e.a,
                b: e.b,
                label,
                xy,
                truth: e.truth.as_ref().map(true_position),
            }
        })
        .collect();
    let out = ConnectionOut {
        between: conn.between,
        cutoff,
        count: conn.count,
        static_agents: &conn.static_agents,
        joins: &conn.joins,
        also_joins: &conn.also_joins,
        points,
        merges,
    };
    let mut s = serde_json::to_string_pretty(&out).expect("connections serialise");
    s.push('\n');
    s
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

/// What a window's hole check found wrong, for the run table: the obstacles of the truth
/// no robust hole encircles, and the robust holes that are not obstacles.
fn hole_note(h: &crate::eval::HoleCheck) -> String {
    let mut parts = Vec::new();
    let missed: Vec<String> = h
        .missed()
        .iter()
        .map(|&t| format!("({:.1}, {:.1})", h.truth[t][0], h.truth[t][1]))
        .collect();
    if !missed.is_empty() {
        parts.push(format!("missed the obstacle at {}", missed.join(", ")));
    }
    match h.spurious() {
        0 => {}
        1 => parts.push("1 hole encircles no obstacle of its own".into()),
        n => parts.push(format!("{n} holes encircle no obstacle of their own")),
    }
    parts.join("; ")
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
            if let Some(h) = w.holes.as_ref().filter(|h| !h.right()) {
                s.push_str(&format!("        holes: {}\n", hole_note(h)));
            }
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
        if let Some(h) = self
            .global
            .holes
            .as_ref()
            .filter(|h| !h.right_with_gluing(self.global.gluing_cycles))
        {
            // A gluing cycle closes a hole no window saw whole, with no cycle to match, so
            // the obstacles none of the kept local holes encircles are not all missed: say
            // how many the gluing graph accounts for.
            let missed: Vec<String> = h
                .missed()
                .iter()
                .map(|&t| format!("({:.1}, {:.1})", h.truth[t][0], h.truth[t][1]))
                .collect();
            let mut note = format!(
                "{} of the {} obstacles are local holes of the global map, {} closed by gluing",
                h.matched(),
                h.truth.len(),
                self.global.gluing_cycles
            );
            if !missed.is_empty() {
                note.push_str(&format!(
                    "; none of its local holes encircles {}",
                    missed.join(", ")
                ));
            }
            match h.spurious() {
                0 => {}
                1 => note.push_str("; 1 hole encircles no obstacle of its own"),
                n => note.push_str(&format!("; {n} holes encircle no obstacle of their own")),
            }
            s.push_str(&format!("        holes: {note}\n"));
        }
        let total: f64 = self.timings.values().sum();
        let parts: Vec<String> = self
            .timings
            .iter()
            .map(|(k, v)| format!("{k} {v:.2} s ({:.0} %)", 100.0 * v / total.max(1e-12)))
            .collect();
        s.push_str(&format!("time: {total:.2} s = {}\n", parts.join(", ")));
        if !self.alongside.is_empty() {
            let parts: Vec<String> = self
                .alongside
                .iter()
                .map(|(k, v)| format!("{k} {v:.2} s"))
                .collect();
            s.push_str(&format!(
                "alongside the simulation, on another core: {}\n",
                parts.join(", ")
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::HoleCheck;

    fn window(betti: [usize; 2], truth: [usize; 2], holes: HoleCheck) -> WindowSummary {
        WindowSummary {
            index: 1,
            start: 0.0,
            end: 100.0,
            events: 10,
            betti,
            truth: Some(truth),
            domain: Some([0.0, 8.0]),
            fidelity: Fidelity::default(),
            holes: Some(holes),
        }
    }

    /// The run table names the obstacles a wrong window missed and its holes that are no
    /// obstacle, and for the global map says how many obstacles the gluing graph closes.
    #[test]
    fn the_table_names_missed_obstacles_and_false_holes() {
        let truth = vec![[2.5, 7.0], [6.3, 3.0]];
        let summary = Summary {
            world: "w".into(),
            seed: Some(1),
            windows: vec![
                window(
                    [1, 2],
                    [1, 2],
                    HoleCheck {
                        truth: truth.clone(),
                        found: vec![Some(1), Some(0)],
                    },
                ),
                window(
                    [1, 2],
                    [1, 2],
                    HoleCheck {
                        truth: truth.clone(),
                        found: vec![Some(0), None],
                    },
                ),
            ],
            connections: Vec::new(),
            global: GlobalSummary {
                betti: [1, 2],
                truth: Some([1, 3]),
                gluing_cycles: 1,
                holes: Some(HoleCheck {
                    truth: vec![[2.5, 7.0], [6.3, 3.0], [15.0, 5.0]],
                    found: vec![Some(0)],
                }),
            },
            timings: BTreeMap::from([("mapping".to_string(), 1.0)]),
            alongside: BTreeMap::new(),
            judged_world: None,
        };
        let t = summary.table();
        let holes: Vec<&str> = t
            .lines()
            .filter(|l| l.trim_start().starts_with("holes:"))
            .collect();
        assert_eq!(
            holes,
            vec![
                "        holes: missed the obstacle at (6.3, 3.0); 1 hole encircles no obstacle of its own",
                "        holes: 1 of the 3 obstacles are local holes of the global map, 1 closed by \
                 gluing; none of its local holes encircles (6.3, 3.0), (15.0, 5.0)",
            ],
            "{t}"
        );
    }
}
