//! `swarmmap simulate WORLD --out DIR [--seed N] [--trajectories [INTERVAL]] [--quiet]`:
//! runs the swarm through the whole sweep and writes the encounter log.

use super::{Failure, input, load_world, progress_bar};
use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use swarmmap::sim::{SimError, SimOptions, prepare_out_dir, simulate, write_run};

/// Options of `swarmmap simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// World file (RON).
    pub world: PathBuf,
    /// Output directory (created if missing; existing files are replaced atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of every random choice (default: the world's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Also write trajectories.csv, one sample per agent every INTERVAL seconds of
    /// simulated time (default interval: 1 s).
    #[arg(long, value_name = "INTERVAL", num_args = 0..=1, default_missing_value = "1.0")]
    pub trajectories: Option<f64>,
    /// Override a world field, e.g. `--set swarm.detection_radius=0.03` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(args: &SimulateArgs) -> Result<(), Failure> {
    let flag = super::run_seed(args.seed, &args.set)?;
    let world = load_world(&args.world, &args.set)?;
    let seed = flag.unwrap_or(world.seed);
    // Before the simulation, which may take hours: an output it cannot write is the
    // user's to fix, and said now.
    prepare_out_dir(&args.out).map_err(input)?;
    let bar = progress_bar(args.quiet, "simulating");
    let report = |f: f64| {
        if let Some(b) = &bar {
            b.set_position((f * 1000.0) as u64);
        }
    };
    let mut opts = SimOptions::new(seed).with_progress(&report);
    if let Some(i) = args.trajectories {
        opts = opts.with_trajectories(i);
    }
    let out = simulate(&world, &opts).map_err(|e| match e {
        SimError::NonFinite { .. } | SimError::Write { .. } => Failure::Other(e.into()),
        _ => input(e),
    })?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    write_run(&args.out, &world, &out)
        .with_context(|| format!("writing the run into {}", args.out.display()))?;
    let s = &out.stats;
    if !args.quiet {
        eprintln!(
            "{}: {} agents, {:.0} s simulated in {:.2} s; {} encounters, {} static intervals \
             -> {}",
            world.name,
            world.swarm.agents,
            s.simulated_time,
            s.wall_time_s,
            s.encounters,
            s.static_intervals,
            args.out.display()
        );
    }
    Ok(())
}
