//! Reading a run directory for the report: only files on disk (`summary.json`,
//! `maps/*.json`, the log's CSV files, `meta.json`, `trajectories.csv`), each checked so
//! that a bad file gives an error naming it rather than a panic or a wrong figure.

use super::ReportError;
use crate::log::EncounterLog;
use crate::mapping::classify::Classifier;
use crate::mapping::output::Summary;
use crate::pipeline::judged_world;
use crate::world::World;
use serde::Deserialize;
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// An event of a window as read from `maps/window_<i>.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct EventIn {
    /// Index into `encounters.csv` (absent in maps written before the report existed).
    #[serde(default)]
    pub encounter: Option<usize>,
    /// Start time, seconds.
    pub start: f64,
    /// 3-D encounter point cloud coordinates, seconds.
    pub point: [f64; 3],
    pub noise: bool,
}

/// A bar of a component's diagram (death `None` = essential), seconds.
#[derive(Debug, Clone, Deserialize)]
pub struct BarIn {
    pub dim: usize,
    pub birth: f64,
    pub death: Option<f64>,
    pub robust: bool,
}

/// A robust hole or a candidate, and its representative cycle (pairs of indices into the
/// window's events).
#[derive(Debug, Clone, Deserialize)]
pub struct HoleIn {
    pub birth: f64,
    pub death: f64,
    pub cycle: Vec<(usize, usize)>,
    /// The death triangle's three events (absent in maps written before it existed).
    #[serde(default)]
    pub void: Option<[usize; 3]>,
}

/// A real component of a window.
#[derive(Debug, Clone, Deserialize)]
pub struct ComponentIn {
    /// Indices into the window's events.
    pub events: Vec<usize>,
    /// Sampling scale σ of the diagram, seconds.
    pub scale: f64,
    pub diagram: Vec<BarIn>,
    pub betti: [usize; 2],
    pub holes: Vec<HoleIn>,
    /// Loops the global map may count when a neighbour sees one too (absent in maps
    /// written before candidates existed).
    #[serde(default)]
    pub candidates: Vec<HoleIn>,
}

impl ComponentIn {
    /// Hole `h` counting the robust holes first, then the candidates (the indexing of
    /// `global.json`'s `holes`).
    pub fn mark(&self, h: usize) -> Option<&HoleIn> {
        crate::mapping::local::mark(&self.holes, &self.candidates, h)
    }
}

/// `maps/window_<i>.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct WindowIn {
    pub index: usize,
    /// Time span, seconds.
    pub start: f64,
    pub end: f64,
    pub betti: [usize; 2],
    pub truth: Option<[usize; 2]>,
    /// The classifier's thresholds (absent in maps written before the report existed).
    #[serde(default)]
    pub classifier: Option<Classifier>,
    /// The outlier filter's neighbour rank the representatives were picked with (absent in
    /// maps written before it was recorded).
    #[serde(default)]
    pub outlier_rank: Option<usize>,
    pub events: Vec<EventIn>,
    pub components: Vec<ComponentIn>,
}

/// A point of an inter-domain cloud.
#[derive(Debug, Clone, Deserialize)]
pub struct CloudPointIn {
    pub start: f64,
    pub label: usize,
    /// 2-D projection of the correspondence metric, seconds.
    pub xy: [f64; 2],
    /// True position, metres.
    pub truth: Option<[f64; 2]>,
}

/// A single-linkage merge; `height` `None` = never (not connected).
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct MergeIn {
    pub a: usize,
    pub b: usize,
    pub height: Option<f64>,
    pub size: usize,
}

/// `maps/connection_<i>.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct ConnectionIn {
    pub between: [usize; 2],
    /// Single-linkage cut-off c, seconds.
    pub cutoff: f64,
    pub count: usize,
    pub points: Vec<CloudPointIn>,
    pub merges: Vec<MergeIn>,
}

/// `maps/global.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct GlobalIn {
    /// `(window index, component index)`.
    pub nodes: Vec<(usize, usize)>,
    /// Pairs of node indices.
    pub edges: Vec<(usize, usize)>,
    /// `(window index, component, hole)` of each distinct local hole.
    pub holes: Vec<(usize, usize, usize)>,
    pub gluing_cycles: usize,
    pub betti: [usize; 2],
}

/// One row of `trajectories.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Seconds.
    pub time: f64,
    pub agent: u32,
    /// Metres.
    pub x: f64,
    pub y: f64,
    /// 0 walk, 1 pause, 2 landmark, 3 return.
    pub state: u8,
}

/// Everything the report reads from a run directory.
#[derive(Debug, Clone)]
pub struct RunData {
    pub dir: PathBuf,
    /// The world the maps were judged against: `summary.json`'s `judged_world` (`map
    /// --world`), else the one in `meta.json` (none for a log without metadata).
    pub world: Option<World>,
    pub summary: Summary,
    /// One per summary window, in order.
    pub windows: Vec<WindowIn>,
    /// One per consecutive pair, in order.
    pub connections: Vec<ConnectionIn>,
    pub global: GlobalIn,
    /// The encounter log (truth columns, static intervals and leader track when recorded).
    pub log: EncounterLog,
    /// `trajectories.csv`, sorted by (time, agent), when the run recorded it.
    pub trajectories: Option<Vec<Sample>>,
}

const REMAP: &str = "run `swarmmap map RUN_DIR` (or `swarmmap run`) to write the maps";

fn read_json<T: DeserializeOwned>(path: &Path, hint: &'static str) -> Result<T, ReportError> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(ReportError::Missing {
                path: path.to_path_buf(),
                hint,
            });
        }
        Err(e) => return Err(invalid(path, e.to_string())),
    };
    serde_json::from_str(&text).map_err(|e| {
        let (place, what) = crate::io::json_error_at(path, &e);
        invalid(Path::new(&place), format!("not a swarmmap output: {what}"))
    })
}

/// `summary.json` (at `summary`) lists a `what` numbered `index` whose file `path` must
/// exist. When `maps/` exists but that file does not, the summary names a map the run never
/// wrote (a corrupted or hand-edited summary), so the error is the summary's; without
/// `maps/`, `read_json` reports the missing map as such.
fn listed_exists(summary: &Path, path: &Path, what: &str, index: usize) -> Result<(), ReportError> {
    let maps = path.parent().filter(|m| m.is_dir());
    if path.exists() || maps.is_none() {
        return Ok(());
    }
    Err(invalid(
        summary,
        format!(
            "lists {what} {index}, but {} does not exist; the summary and maps/ disagree: rerun `swarmmap map RUN_DIR`",
            path.display()
        ),
    ))
}

fn invalid_line(path: &Path, line: u64, message: impl Into<String>) -> ReportError {
    ReportError::InvalidLine {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

fn invalid(path: &Path, message: impl Into<String>) -> ReportError {
    ReportError::Invalid {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn check_window(path: &Path, w: &WindowIn) -> Result<(), ReportError> {
    let n = w.events.len();
    let finite = w
        .events
        .iter()
        .all(|e| e.start.is_finite() && e.point.iter().all(|x| x.is_finite()));
    if !(finite && w.start.is_finite() && w.end.is_finite()) {
        return Err(invalid(path, "a time or a point coordinate is not finite"));
    }
    for (c, comp) in w.components.iter().enumerate() {
        if let Some(&j) = comp.events.iter().find(|&&j| j >= n) {
            return Err(invalid(
                path,
                format!("component {c} lists event {j}, but the window has {n} events"),
            ));
        }
        for hole in comp.holes.iter().chain(&comp.candidates) {
            if let Some(&j) = hole.void.iter().flatten().find(|&&j| j >= n) {
                return Err(invalid(
                    path,
                    format!(
                        "a hole of component {c} has the void event {j}, but the window has {n} events"
                    ),
                ));
            }
            if let Some(&(a, b)) = hole.cycle.iter().find(|&&(a, b)| a >= n || b >= n) {
                return Err(invalid(
                    path,
                    format!(
                        "a hole of component {c} has the edge ({a}, {b}), but the window has {n} events"
                    ),
                ));
            }
        }
        let bars_ok = comp
            .diagram
            .iter()
            .all(|b| b.birth.is_finite() && b.death.is_none_or(|d| d.is_finite()) && b.dim < 2);
        if !bars_ok || !comp.scale.is_finite() {
            return Err(invalid(
                path,
                format!(
                    "component {c} has a bar or scale that is not finite, or of dimension above 1"
                ),
            ));
        }
    }
    Ok(())
}

fn check_connection(path: &Path, c: &ConnectionIn) -> Result<(), ReportError> {
    let n = c.points.len();
    if c.merges.len() >= n.max(1) {
        return Err(invalid(
            path,
            format!(
                "{} merges for {n} points; a dendrogram has at most n − 1",
                c.merges.len()
            ),
        ));
    }
    for (k, m) in c.merges.iter().enumerate() {
        // Merge k creates cluster n + k from two clusters made before it.
        if m.a >= n + k || m.b >= n + k || m.a == m.b {
            return Err(invalid(
                path,
                format!(
                    "merge {k} joins clusters {} and {}, which do not exist yet",
                    m.a, m.b
                ),
            ));
        }
        if m.height.is_some_and(|h| !h.is_finite()) {
            return Err(invalid(path, format!("merge {k} has a non-finite height")));
        }
    }
    let finite = c.cutoff.is_finite()
        && c.points.iter().all(|p| {
            p.start.is_finite()
                && p.xy.iter().all(|x| x.is_finite())
                && p.truth.is_none_or(|t| t.iter().all(|x| x.is_finite()))
        });
    if !finite {
        return Err(invalid(
            path,
            "a coordinate, a time or the cut-off is not finite",
        ));
    }
    Ok(())
}

fn check_global(path: &Path, g: &GlobalIn) -> Result<(), ReportError> {
    let n = g.nodes.len();
    if let Some(&(a, b)) = g.edges.iter().find(|&&(a, b)| a >= n || b >= n) {
        return Err(invalid(
            path,
            format!("edge ({a}, {b}) names a node beyond the {n} nodes"),
        ));
    }
    Ok(())
}

/// Reads `trajectories.csv` (`time,agent,x,y,state`).
pub fn read_trajectories(path: &Path) -> Result<Vec<Sample>, ReportError> {
    let file = std::fs::File::open(path).map_err(|e| invalid(path, e.to_string()))?;
    // Lines numbered from byte offsets, so `\r` and `\r\n` endings count as the file's.
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(crate::log::LineIndex::new(file));
    let headers = reader
        .headers()
        .map_err(|e| invalid_line(path, 1, e.to_string()))?;
    let expected = ["time", "agent", "x", "y", "state"];
    if headers.is_empty() {
        return Err(invalid(
            path,
            format!(
                "the file is empty; it needs the header {} and a row per sample (delete it to report without the replay)",
                expected.join(",")
            ),
        ));
    }
    if headers.iter().collect::<Vec<_>>() != expected {
        return Err(invalid_line(
            path,
            1,
            format!("the header must be {}", expected.join(",")),
        ));
    }
    let mut out = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let at = reader.position().byte();
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                let line = reader
                    .get_ref()
                    .line_of(e.position().map_or(at, csv::Position::byte));
                return Err(invalid_line(path, line, e.to_string()));
            }
        }
        let line = reader
            .get_ref()
            .line_of(record.position().map_or(at, csv::Position::byte));
        let field = |i: usize| record.get(i).unwrap_or("");
        let num = |i: usize| -> Result<f64, ReportError> {
            field(i)
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    invalid_line(
                        path,
                        line,
                        format!(
                            "column `{}` is `{}`, not a finite number",
                            expected[i],
                            crate::log::shown(field(i))
                        ),
                    )
                })
        };
        let agent: u32 = field(1).parse().map_err(|_| {
            invalid_line(
                path,
                line,
                format!(
                    "column `agent` is `{}`, not an agent id",
                    crate::log::shown(field(1))
                ),
            )
        })?;
        let state = match field(4) {
            "walk" => 0,
            "pause" => 1,
            "landmark" => 2,
            "return" => 3,
            other => {
                return Err(invalid_line(
                    path,
                    line,
                    format!(
                        "state `{}` is not walk, pause, landmark or return",
                        crate::log::shown(other)
                    ),
                ));
            }
        };
        out.push(Sample {
            time: num(0)?,
            agent,
            x: num(2)?,
            y: num(3)?,
            state,
        });
    }
    // The simulator writes them sorted; sort anyway so a hand-made file works too.
    out.sort_by(|p, q| p.time.total_cmp(&q.time).then(p.agent.cmp(&q.agent)));
    Ok(out)
}

/// Reads and checks everything the report needs from a run directory.
pub fn load_run(dir: &Path) -> Result<RunData, ReportError> {
    if dir.is_file() {
        let parent = dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        return Err(invalid(
            dir,
            format!(
                "a file, not a run directory; give the directory that holds the run's \
                 summary.json (perhaps {})",
                parent.display()
            ),
        ));
    }
    if !dir.is_dir() {
        return Err(ReportError::Missing {
            path: dir.to_path_buf(),
            hint: "give the directory of a run (`swarmmap run` or `swarmmap map` output)",
        });
    }
    let summary_path = dir.join("summary.json");
    let summary: Summary = read_json(&summary_path, REMAP)?;
    let mut windows = Vec::with_capacity(summary.windows.len());
    for w in &summary.windows {
        let path = dir.join(format!("maps/window_{}.json", w.index));
        listed_exists(&summary_path, &path, "window", w.index)?;
        let win: WindowIn = read_json(&path, REMAP)?;
        check_window(&path, &win)?;
        if win.index != w.index {
            return Err(invalid(
                &path,
                format!(
                    "its index is {}, but summary.json lists it as window {}; rerun `swarmmap map RUN_DIR`",
                    win.index, w.index
                ),
            ));
        }
        windows.push(win);
    }
    let mut connections = Vec::with_capacity(summary.connections.len());
    for c in &summary.connections {
        let path = dir.join(format!("maps/connection_{}.json", c.between[0]));
        listed_exists(&summary_path, &path, "connection", c.between[0])?;
        let conn: ConnectionIn = read_json(&path, REMAP)?;
        check_connection(&path, &conn)?;
        connections.push(conn);
    }
    let global_path = dir.join("maps/global.json");
    let global: GlobalIn = read_json(&global_path, REMAP)?;
    check_global(&global_path, &global)?;
    let log = EncounterLog::read_dir(dir)?;
    for w in &windows {
        if let Some(bad) = w
            .events
            .iter()
            .filter_map(|e| e.encounter)
            .find(|&i| i >= log.encounters.len())
        {
            return Err(invalid(
                &dir.join(format!("maps/window_{}.json", w.index)),
                format!(
                    "event of encounter {bad}, but encounters.csv has {} rows; were the maps written from another log?",
                    log.encounters.len()
                ),
            ));
        }
    }
    let world = judged_world(dir, summary.judged_world.as_ref(), &summary_path)?;
    let traj_path = dir.join("trajectories.csv");
    let trajectories = if traj_path.exists() {
        Some(read_trajectories(&traj_path)?)
    } else {
        None
    };
    Ok(RunData {
        dir: dir.to_path_buf(),
        world,
        summary,
        windows,
        connections,
        global,
        log,
        trajectories,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `global.json` indexes a component's robust holes and then its candidates; a map
    /// written before candidates existed reads as having none.
    #[test]
    fn a_global_hole_indexes_holes_then_candidates() {
        let hole = |birth: f64| format!(r#"{{"birth": {birth}, "death": 9.0, "cycle": [[0, 1]]}}"#);
        let text = format!(
            r#"{{"events": [0, 1], "scale": 1.0, "diagram": [], "betti": [1, 1],
                "holes": [{}], "candidates": [{}, {}]}}"#,
            hole(1.0),
            hole(2.0),
            hole(3.0)
        );
        let c: ComponentIn = serde_json::from_str(&text).unwrap();
        let births: Vec<Option<f64>> = (0..4).map(|h| c.mark(h).map(|x| x.birth)).collect();
        assert_eq!(births, vec![Some(1.0), Some(2.0), Some(3.0), None]);
        let old = r#"{"events": [], "scale": 1.0, "diagram": [], "betti": [1, 0], "holes": []}"#;
        let c: ComponentIn = serde_json::from_str(old).unwrap();
        assert!(c.candidates.is_empty() && c.mark(0).is_none());
    }
}
