//! Subcommands. Each lives in its own file and returns `Result<(), Failure>`; the exit
//! code comes from the failure's kind, never from a panic.

mod calibrate;
mod check;
mod eval;
mod map;
mod persistence;
mod report;
mod run;
mod simulate;

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

/// Refuses a world file given twice (the same file by any path): its runs would be counted
/// twice in every figure and interval of a campaign or a fit.
pub fn refuse_repeated_worlds(worlds: &[std::path::PathBuf]) -> Result<(), Failure> {
    let mut seen = std::collections::BTreeMap::new();
    for w in worlds {
        let key = std::fs::canonicalize(w).unwrap_or_else(|_| w.clone());
        if let Some(first) = seen.insert(key, w) {
            let also = if first == w {
                String::new()
            } else {
                format!(" (also as {})", first.display())
            };
            return Err(input(anyhow::anyhow!(
                "{} is given twice{also}; give each world once",
                w.display()
            )));
        }
    }
    Ok(())
}

/// The build whose stored runs a campaign or a fit may reuse: this one
/// (`campaign::build_id`), or, with `--reuse-any-build`, none in particular.
pub fn reusable_build(reuse_any_build: bool) -> Result<Option<&'static str>, Failure> {
    if reuse_any_build {
        return Ok(None);
    }
    swarmmap::eval::campaign::build_id().map(Some).map_err(|e| {
        Failure::Other(
            anyhow::Error::new(e).context("reading swarmmap's own executable to tell its build"),
        )
    })
}

/// The first `--set` that sets the world's `seed`.
fn seed_set(sets: &[String]) -> Option<&String> {
    sets.iter().find(|s| {
        s.split_once('=')
            .is_some_and(|(p, _)| setting_key(p) == "seed")
    })
}

/// The seed of a single run (`simulate`, `run`): `--seed`, else the world's `seed` (which
/// `--set seed=N` may change). Both `--seed` and `--set seed` are refused: the run would
/// use one and `meta.json` record the other in its world.
pub fn run_seed(flag: Option<u64>, sets: &[String]) -> Result<Option<u64>, Failure> {
    match (flag, seed_set(sets)) {
        (Some(n), Some(set)) => Err(input(anyhow::anyhow!(
            "both --seed {n} and --set {set} give the run's seed, so one would be lost; give one"
        ))),
        _ => Ok(flag),
    }
}

/// Refuses `--set seed=N` in `eval` and `calibrate`, whose runs take their seeds from
/// `--seeds`: the set would be ignored, and a sweep of it would count identical runs as
/// different parameter sets.
pub fn refuse_seed_set(sets: &[String]) -> Result<(), Failure> {
    match seed_set(sets) {
        Some(set) => Err(input(anyhow::anyhow!(
            "--set {set}: each run's seed comes from --seeds, which replaces the world's; give \
             the seeds as --seeds (a range A..B or a list like 1,2,5)"
        ))),
        None => Ok(()),
    }
}

/// Loads a world file and applies `--set PATH=VALUE` overrides; any problem is an input
/// error (status 2).
pub fn load_world(
    path: &std::path::Path,
    sets: &[String],
) -> Result<swarmmap::world::World, Failure> {
    let mut spec = swarmmap::world::WorldSpec::load(path).map_err(input)?;
    apply_sets(&mut spec, sets)?;
    spec.check().map_err(input)
}

/// Applies `--set PATH=VALUE` overrides in order, refusing one whose value a later one
/// would drop unseen: the same field twice, or a field and then its whole section
/// (`swarm.agents=3` then `swarm=(...)`, `obstacles[0]=...` or `obstacles.scale=2` then
/// `obstacles=[...]`). A section and then one of its fields is a refinement, and repeated
/// `obstacles.scale` factors compose; both are fine. (`eval` sweeps values as
/// `--set PATH=V1,V2`.)
pub fn apply_sets(spec: &mut swarmmap::world::WorldSpec, sets: &[String]) -> Result<(), Failure> {
    let mut earlier: Vec<(String, &String)> = Vec::new();
    for assignment in sets {
        if let Some((path, _)) = assignment.split_once('=') {
            let key = setting_key(path);
            let dropped = earlier
                .iter()
                .find(|(k, _)| (*k == key && key != "obstacles.scale") || inside(k, &key));
            if let Some((k, first)) = dropped {
                let what = if *k == key {
                    format!("--set {key} is given twice")
                } else {
                    format!("--set {key} replaces the whole of what an earlier --set {k} set")
                };
                return Err(input(anyhow::anyhow!(
                    "{what} (`{first}`, then `{assignment}`), so one value would be lost; \
                     give each field once, and a section before its fields"
                )));
            }
            earlier.push((key, assignment));
        }
        swarmmap::world::apply_assignment(spec, assignment).map_err(input)?;
    }
    Ok(())
}

/// Whether the setting `key` lies inside the section `section` (`swarm.agents` in `swarm`,
/// `obstacles[0]` and `obstacles.scale` in `obstacles`), both as [`setting_key`] writes them:
/// a later `--set` of the section drops it.
fn inside(key: &str, section: &str) -> bool {
    key.strip_prefix(section)
        .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// A `--set` path as compared for repeats: trimmed, each part trimmed, indices as numbers
/// (`obstacles[01]` is `obstacles[1]`).
pub fn setting_key(path: &str) -> String {
    path.trim()
        .split('.')
        .map(|part| {
            let part = part.trim();
            match part.strip_suffix(']').and_then(|p| p.split_once('[')) {
                Some((name, index)) => match index.trim().parse::<usize>() {
                    Ok(i) => format!("{}[{i}]", name.trim()),
                    Err(_) => part.to_string(),
                },
                None => part.to_string(),
            }
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// Most worker threads a command takes (`--jobs`, `--threads`): far beyond any machine's
/// cores, and a bound on the stacks a typo would otherwise ask for.
pub const MAX_THREADS: usize = 1024;

/// Parses a thread count for clap: 0 to [`MAX_THREADS`].
pub fn thread_count(text: &str) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number"))?;
    if n > MAX_THREADS {
        return Err(format!(
            "{n} threads is too many; use at most {MAX_THREADS} (the machine has {} cores)",
            std::thread::available_parallelism().map_or(1, usize::from)
        ));
    }
    Ok(n)
}

/// A progress bar on stderr when it is a terminal and `quiet` is off.
pub fn progress_bar(quiet: bool, label: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    (!quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(1000);
        let template = format!("{{spinner}} {label} [{{bar:40}}] {{percent}}% (eta {{eta}})");
        if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    })
}

#[derive(Parser)]
#[command(
    name = "swarmmap",
    version,
    about = "Topological maps from the encounters of a robot swarm"
)]
struct Cli {
    /// Judge persistence diagrams with the models of FILE (written by `swarmmap calibrate
    /// --out FILE`) instead of the shipped assets/classifier.json, for map, run and eval
    /// (and as calibrate's starting point when its --out file does not exist yet).
    #[arg(long, global = true, value_name = "FILE")]
    model: Option<std::path::PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a world file and print a short summary.
    Check(check::CheckArgs),
    /// Simulate the swarm through a world's sweep and write its encounter log.
    Simulate(simulate::SimulateArgs),
    /// Map an encounter log: local maps, connections, global map (and truth if known).
    Map(map::MapArgs),
    /// Simulate, map, stitch and evaluate a world in one go.
    Run(run::RunArgs),
    /// Accuracy over many worlds, seeds and parameter values, in parallel.
    Eval(eval::EvalArgs),
    /// Fit the robust-feature classifier on training worlds.
    Calibrate(calibrate::CalibrateArgs),
    /// Vietoris–Rips persistence diagram (H0, H1) of a CSV of points or distances.
    Persistence(persistence::PersistenceArgs),
    /// Write the report of a run (SVG figures and a self-contained index.html) into RUN_DIR/report/.
    Report(report::ReportArgs),
}

pub fn main() -> ExitCode {
    restore_sigpipe();
    let cli = Cli::parse();
    if let Err(e) = swarmmap::io::install_interrupt_handler() {
        eprintln!("warning: Ctrl-C will not clean up partial files: {e}");
    }
    let result: Result<(), Failure> =
        use_model(cli.model.as_deref()).and_then(|()| match cli.command {
            Command::Check(args) => check::run(&args),
            Command::Simulate(args) => simulate::run(&args),
            Command::Map(args) => map::run(&args),
            Command::Run(args) => run::run(&args),
            Command::Eval(args) => eval::run(&args),
            Command::Calibrate(args) => calibrate::run(&args),
            Command::Persistence(a) => persistence::run(a),
            Command::Report(args) => report::run(&args),
        });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {}", describe(&e));
            ExitCode::from(2)
        }
        Err(Failure::Other(e)) => {
            eprintln!("error: {}", describe(&e));
            ExitCode::from(1)
        }
    }
}

/// An error and its causes, `: `-separated as anyhow's `{:#}` writes them, but without a
/// cause that the message before it already ends with (our errors name their source in
/// their own text, as "cannot write X: <the OS error>").
fn describe(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.is_empty() {
            text = part;
        } else if !text.ends_with(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
    }
    text
}

/// `--model FILE`: every later mapping in this process judges with FILE's models; a bad file
/// is an input error (status 2), reported before any command runs.
fn use_model(path: Option<&std::path::Path>) -> Result<(), Failure> {
    use swarmmap::mapping::classify::Models;
    if let Some(path) = path {
        let first = Models::use_instead(Models::load(path).map_err(input)?);
        // Called once, before anything has mapped.
        debug_assert!(first);
    }
    Ok(())
}

/// Restores the default action of SIGPIPE, which Rust's runtime sets to "ignore": a command
/// whose output is piped into `head` then ends quietly when the reader goes away, like any
/// Unix tool, instead of panicking in `println!` on a broken pipe. Only pipes and sockets
/// raise SIGPIPE, never the output files, so no file can be torn by it.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: `signal` with `SIG_DFL` installs no handler code; it runs first thing in
    // `main`, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
