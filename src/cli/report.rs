//! `swarmmap report RUN_DIR`: (re)writes `RUN_DIR/report/` (SVG figures and a
//! self-contained `index.html`) from the files of an existing run.

use super::{Failure, input};
use clap::Args;
use std::path::PathBuf;
use swarmmap::report::{ReportError, write_report};

/// Options of `swarmmap report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// A run directory written by `swarmmap run` (or `swarmmap simulate` + `swarmmap map`):
    /// summary.json, maps/, encounters.csv; meta.json and trajectories.csv when present.
    pub run_dir: PathBuf,
}

/// Maps a report error to its exit status: 2 for a bad or missing input file, else 1.
pub fn failure(e: ReportError) -> Failure {
    if e.is_input() {
        input(e)
    } else {
        Failure::Other(e.into())
    }
}

pub fn run(args: &ReportArgs) -> Result<(), Failure> {
    let written = write_report(&args.run_dir).map_err(failure)?;
    println!("{}", describe(&written));
    Ok(())
}

/// One line: where the page is, its size, the figures and whether it has a replay.
pub fn describe(w: &swarmmap::report::Written) -> String {
    format!(
        "report: {} ({:.0} KiB, {} figures, {})",
        w.index.display(),
        w.bytes as f64 / 1024.0,
        w.figures,
        if w.replay {
            "with replay"
        } else if w.trajectories {
            "replay unavailable: trajectories.csv holds no samples"
        } else {
            "replay unavailable: no trajectories.csv"
        }
    )
}
