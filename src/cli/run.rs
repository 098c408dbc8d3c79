//! `swarmmap run WORLD [--seed N] [--out DIR]`: simulate, map, stitch and evaluate in one
//! command, print the compact accuracy table, and write the report (`DIR/report/`).

use super::{Failure, input, load_world, progress_bar};
use clap::Args;
use std::path::PathBuf;
use swarmmap::pipeline::{Alongside, RunOptions, run_world};

/// Options of `swarmmap run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// World file (RON), e.g. `worlds/scenario2.ron`.
    pub world: PathBuf,
    /// Seed of the simulation (default: the world's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output directory (default: `runs/<world>-seed<N>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a world field, e.g. `--set swarm.detection_radius=0.03` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Write trajectories.csv every INTERVAL seconds (always written, for the report's
    /// replay; default interval: max(1 s, run duration / 600); the flag without a value: 1 s).
    #[arg(long, value_name = "INTERVAL", num_args = 0..=1, default_missing_value = "1.0")]
    pub trajectories: Option<f64>,
    /// Do not write the report (DIR/report/); `swarmmap report DIR` writes it later.
    #[arg(long)]
    pub no_report: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Map after the simulation instead of alongside it on the other cores (the outputs are
    /// the same; for timing comparisons, or to leave the other cores free).
    #[arg(long)]
    pub map_after: bool,
}

pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let flag = super::run_seed(args.seed, &args.set)?;
    let world = load_world(&args.world, &args.set)?;
    let seed = flag.unwrap_or(world.seed);
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("runs/{}-seed{seed}", file_safe(&world.name))));
    // Before the simulation, which may take hours: an output it cannot write is the
    // user's to fix, and said now (`run_world` checks too, for library callers).
    swarmmap::sim::prepare_out_dir(&out).map_err(input)?;
    let bar = progress_bar(args.quiet, "simulating");
    let report = |f: f64| {
        if let Some(b) = &bar {
            b.set_position((f * 1000.0) as u64);
        }
    };
    let opts = RunOptions {
        seed,
        out: Some(out.clone()),
        trajectories: Some(
            args.trajectories
                .unwrap_or_else(|| swarmmap::report::default_trajectory_interval(&world)),
        ),
        progress: Some(&report),
        alongside: if args.map_after {
            Alongside::Off
        } else {
            Alongside::Free
        },
    };
    let result = run_world(&world, &opts);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let (sim, mapped) = result.map_err(|e| {
        if e.is_input() {
            input(e)
        } else {
            Failure::Other(e.into())
        }
    })?;
    let log = sim.log;
    print!("{}", mapped.summary.table());
    let bank = swarmmap::mapping::pipeline::MapConfig::for_world(&world)
        .local
        .classifier;
    if let Some(w) = swarmmap::pipeline::density_warning(&mapped.maps, &bank) {
        eprintln!("warning: {w}");
    }
    for w in run_warnings(&world, &log, &mapped) {
        eprintln!("warning: {w}");
    }
    println!("outputs: {}", out.display());
    if !args.no_report {
        let written = swarmmap::report::write_report(&out).map_err(super::report::failure)?;
        println!("{}", super::report::describe(&written));
    }
    Ok(())
}

/// What `map` would warn of in a log, said of a simulated run in terms of its world's
/// settings (found by review: `run` kept silent about a run without encounters, without
/// landmarks, with empty windows or with every window judged noise).
fn run_warnings(
    world: &swarmmap::world::World,
    log: &swarmmap::log::EncounterLog,
    mapped: &swarmmap::pipeline::Mapped,
) -> Vec<String> {
    let mut out = Vec::new();
    if log.encounters.is_empty() && world.swarm.agents < 2 {
        out.push(
            "a single agent meets no one, so the run recorded no encounters and every map is \
             empty; give swarm.agents at least 2"
                .to_string(),
        );
        return out;
    }
    if log.encounters.is_empty() {
        out.push(format!(
            "the run recorded no encounters, so every map is empty: {} agents with a \
             detection radius of {} m never came within it of each other; more agents \
             (swarm.agents) or a larger radius (swarm.detection_radius) record some",
            world.swarm.agents,
            swarmmap::world::given(world.swarm.detection_radius)
        ));
        return out;
    }
    if !log
        .static_intervals
        .iter()
        .any(|s| s.reason == swarmmap::log::StaticReason::Landmark)
    {
        out.push(
            "no agent became a landmark (round(swarm.landmark_fraction × the agents inside D(t)) \
             stayed 0): \
             no static agent bridges time or stands through the windows' overlaps, so the \
             metric is travel time alone and consecutive local maps cannot be stitched; raise \
             swarm.landmark_fraction or swarm.agents"
                .to_string(),
        );
    }
    let empty: Vec<String> = mapped
        .maps
        .iter()
        .filter(|m| m.events.is_empty())
        .map(|m| m.index.to_string())
        .collect();
    if !empty.is_empty() {
        out.push(format!(
            "window(s) {} of {} hold no encounter: the run records too few for its windows; \
             fewer windows (mapping.windows) or more agents (swarm.agents)",
            empty.join(", "),
            mapped.maps.len()
        ));
    }
    if mapped.summary.global.betti[0] == 0 {
        out.push(format!(
            "every window's encounters were judged noise (β0 = 0 everywhere) although the run \
             recorded {} encounter(s): too few for {} window(s); fewer windows \
             (mapping.windows) or more agents (swarm.agents)",
            log.encounters.len(),
            mapped.maps.len()
        ));
    }
    out
}

/// `name` as one path component: characters other than letters, digits, `-`, `_` and `.`
/// become `_`, and a leading `.` too, so a world's name (free text) cannot reach outside
/// `runs/` (`../x`, `/etc/x`) or hide the directory.
fn file_safe(name: &str) -> String {
    let mut out: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.starts_with('.') {
        out.replace_range(..1, "_");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::file_safe;

    #[test]
    fn world_names_become_one_safe_path_component() {
        assert_eq!(file_safe("scenario2"), "scenario2");
        assert_eq!(file_safe("my world (v2)"), "my_world__v2_");
        assert_eq!(file_safe("../../esc"), "_._.._esc");
        assert_eq!(file_safe("/etc/x"), "_etc_x");
        assert_eq!(file_safe(".hidden"), "_hidden");
        assert_eq!(file_safe("café"), "café");
    }
}
