//! `swarmmap check WORLD [--set PATH=VALUE]...`: validate a world and print its summary.

use super::{Failure, input};
use clap::Args;
use std::path::PathBuf;
use swarmmap::world::WorldSpec;

/// Validate a world file and print a short summary (exit status 2 if it is invalid).
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// World file (RON), e.g. `worlds/scenario1.ron`.
    pub world: PathBuf,
    /// Override a field before validation, e.g. `--set swarm.detection_radius=0.03`
    /// (repeatable; VALUE is written as in a world file).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
}

pub fn run(args: &CheckArgs) -> Result<(), Failure> {
    // A missing or unreadable world file is the user's input too: status 2.
    let mut spec = WorldSpec::load(&args.world).map_err(input)?;
    super::apply_sets(&mut spec, &args.set)?;
    let world = spec.check().map_err(input)?;
    println!("{}", world.summary());
    for w in world.warnings() {
        eprintln!("warning: {w}");
    }
    Ok(())
}
