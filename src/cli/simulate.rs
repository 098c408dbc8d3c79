//! `swarmmap simulate WORLD --out DIR [--seed N] [--trajectories [INTERVAL]] [--quiet]`:
//! runs the swarm through the whole sweep and writes the encounter log.

use super::{Failure, input};
use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use swarmmap::sim::{SimError, SimOptions, simulate, write_run};
use swarmmap::world::World;

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
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(args: &SimulateArgs) -> Result<(), Failure> {
    let world = World::load(&args.world).map_err(input)?;
    let seed = args.seed.unwrap_or(world.seed);
    let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = ProgressBar::new(1000);
        if let Ok(style) =
            ProgressStyle::with_template("{spinner} simulating [{bar:40}] {percent}% (eta {eta})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    });
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
