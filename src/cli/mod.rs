//! Subcommands. Each lives in its own file and returns `Result<(), Failure>`; the exit
//! code comes from the failure's kind, never from a panic.

mod check;
mod persistence;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Why a command failed, which decides the exit status.
#[derive(Debug)]
pub enum Failure {
    /// The user's input is invalid (bad world file, malformed CSV): exit status 2.
    Input(anyhow::Error),
    /// Anything else (I/O, internal): exit status 1.
    Other(anyhow::Error),
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure::Other(e.into())
    }
}

/// Marks an error as an input error (exit status 2).
pub fn input<E: Into<anyhow::Error>>(e: E) -> Failure {
    Failure::Input(e.into())
}

#[derive(Parser)]
#[command(
    name = "swarmmap",
    version,
    about = "Topological maps from the encounters of a robot swarm"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a world file and print a short summary.
    Check(check::CheckArgs),
    /// Vietoris–Rips persistence diagram (H0, H1) of a CSV of points or distances.
    Persistence(persistence::PersistenceArgs),
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result: Result<(), Failure> = match cli.command {
        Command::Check(args) => check::run(&args),
        Command::Persistence(a) => persistence::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Other(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
