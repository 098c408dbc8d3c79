//! The report (issue #6): the paper's figures for a run and a page a person can open.
//!
//! `swarmmap run` writes it at the end; `swarmmap report RUN_DIR` regenerates it from the
//! files of a run alone ([`data::load_run`]): `summary.json`, `maps/window_<i>.json`,
//! `maps/connection_<i>.json`, `maps/global.json`, the log's CSV files, `meta.json` (the
//! world, when known) and `trajectories.csv` (the replay, when recorded).
//!
//! Outputs, under `RUN_DIR/report/`, each written atomically:
//! - one SVG per figure ([`figures`]), the six kinds of the paper's figure rows (§"Simulation
//!   Results"): environment, per-window persistence diagram and encounter point cloud,
//!   per-pair inter-domain cloud and single-linkage dendrogram, global map beside the truth;
//! - `index.html` ([`html`]): self-contained (figures inline, script and data inline, no
//!   network), with the summary table, every figure and an animated replay of the swarm
//!   from decimated, delta-encoded trajectories ([`replay`]).
//!
//! Rendering is a pure function of the files read: no clock, no hash-map iteration order,
//! fixed number formats; the same run directory gives byte-identical files. Cost: linear in
//! the events and trajectory samples read; a scenario-2 run renders in well under a second.

pub mod data;
pub mod figures;
pub mod html;
pub mod replay;

pub use data::{RunData, load_run};
pub use figures::Figure;

use crate::io::write_atomic;
use crate::log::LogError;
use crate::pipeline::PipelineError;
use crate::world::World;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a report could not be made.
#[derive(Debug, Error)]
pub enum ReportError {
    /// A file the report needs does not exist.
    #[error("{path}: file not found; {hint}")]
    Missing { path: PathBuf, hint: &'static str },
    /// A file exists but is not what a run writes.
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// A line of a CSV file is not what a run writes.
    #[error("{path}:{line}: {message}")]
    InvalidLine {
        path: PathBuf,
        line: u64,
        message: String,
    },
    /// The encounter log could not be read.
    #[error(transparent)]
    Log(#[from] LogError),
    /// `meta.json` could not be read.
    #[error(transparent)]
    Meta(#[from] PipelineError),
    /// Drawing a figure failed.
    #[error("drawing {figure}: {message}")]
    Plot { figure: String, message: String },
    /// Writing an output failed.
    #[error("writing {path}: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl ReportError {
    /// Whether the run directory's contents are at fault (exit status 2) rather than the
    /// machine or the program.
    pub fn is_input(&self) -> bool {
        match self {
            ReportError::Missing { .. }
            | ReportError::Invalid { .. }
            | ReportError::InvalidLine { .. } => true,
            ReportError::Log(_) => true,
            ReportError::Meta(e) => e.is_input(),
            ReportError::Plot { .. } | ReportError::Write { .. } => false,
        }
    }
}

/// A rendered report, not yet written.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub figures: Vec<Figure>,
    /// Whether the page has a replay (the run recorded trajectories).
    pub replay: bool,
    /// Whether the run directory has a `trajectories.csv` (without a replay: one that
    /// holds no sample).
    pub trajectories: bool,
    /// The text of `index.html`.
    pub html: String,
}

/// Renders the figures and the page of a loaded run.
pub fn render(run: &RunData) -> Result<Report, ReportError> {
    let figures = figures::all(run)?;
    let replay = run.trajectories.as_deref().and_then(replay::encode);
    let html = html::page(run, &figures, replay.as_ref());
    Ok(Report {
        figures,
        replay: replay.is_some(),
        trajectories: run.trajectories.is_some(),
        html,
    })
}

/// What [`write_report`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// `RUN_DIR/report/index.html`.
    pub index: PathBuf,
    /// Size of `index.html` in bytes.
    pub bytes: usize,
    pub figures: usize,
    pub replay: bool,
    /// Whether the run directory has a `trajectories.csv`.
    pub trajectories: bool,
}

/// Removes the report of `dir` (`report/index.html` first, then its figures), for a caller
/// about to replace what it was made from: a report left beside new maps or a new log would
/// describe a run that is no longer there. Only swarmmap's own files; a missing `report/`
/// is nothing to do.
pub fn remove_report(dir: &Path) -> std::io::Result<()> {
    let out = dir.join("report");
    let none = std::collections::BTreeSet::new();
    crate::io::remove_stale(&out, &none, |n| n == "index.html")?;
    crate::io::remove_stale(&out, &none, is_report_figure)
}

/// Whether `name` is one of the figures a report writes.
fn is_report_figure(name: &str) -> bool {
    matches!(name, "environment.svg" | "global.svg") || crate::io::is_numbered_figure(name)
}

/// Whether `dir/report/` holds a report, or part of one: the figures a report interrupted
/// before its page was written leaves (`map` then makes the whole report again).
pub fn has_report(dir: &Path) -> bool {
    std::fs::read_dir(dir.join("report")).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name == "index.html" || is_report_figure(&name)
        })
    })
}

/// Reads a run directory and writes `report/*.svg` and `report/index.html` into it (the page
/// last, so a complete page means a complete report).
pub fn write_report(dir: &Path) -> Result<Written, ReportError> {
    let run = load_run(dir)?;
    let report = render(&run)?;
    let out = dir.join("report");
    let write = |path: PathBuf, bytes: &[u8]| {
        write_atomic(&path, bytes).map_err(|source| ReportError::Write { path, source })
    };
    for f in &report.figures {
        write(out.join(&f.name), f.svg.as_bytes())?;
    }
    let index = out.join("index.html");
    write(index.clone(), report.html.as_bytes())?;
    // Figures of windows and connections an earlier mapping had and this one has not.
    let names: std::collections::BTreeSet<String> =
        report.figures.iter().map(|f| f.name.clone()).collect();
    crate::io::remove_stale(&out, &names, crate::io::is_numbered_figure).map_err(|source| {
        ReportError::Write {
            path: out.clone(),
            source,
        }
    })?;
    Ok(Written {
        index,
        bytes: report.html.len(),
        figures: report.figures.len(),
        replay: report.replay,
        trajectories: report.trajectories,
    })
}

/// Trajectory interval `swarmmap run` records by default, seconds: one sample per
/// max(1 s, run duration / [`replay::MAX_FRAMES`]), enough for the replay and no more.
pub fn default_trajectory_interval(world: &World) -> f64 {
    (world.total_duration() / replay::MAX_FRAMES as f64).max(1.0)
}
