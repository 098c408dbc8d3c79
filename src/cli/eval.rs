//! `swarmmap eval WORLD... --seeds 1..20 [--jobs N] [--set path=v1,v2]... [--out DIR]`:
//! accuracy over many worlds, seeds and parameter values.

use super::{Failure, input};
use anyhow::{Context, anyhow};
use clap::Args;
use std::path::PathBuf;
use std::sync::Mutex;
use swarmmap::eval::campaign::{Job, combinations, csv, groups, run_campaign, summary_csv, table};
use swarmmap::io::write_atomic;
use swarmmap::world::WorldSpec;

/// Options of `swarmmap eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// World files (RON).
    #[arg(required = true)]
    pub worlds: Vec<PathBuf>,
    /// Seeds: `A..B` (inclusive), or a comma-separated list.
    #[arg(long, default_value = "1..20")]
    pub seeds: String,
    /// Runs in parallel (default: the number of cores; at most 1024).
    #[arg(long, value_parser = super::thread_count)]
    pub jobs: Option<usize>,
    /// Sweep a world field over values, e.g. `--set swarm.detection_radius=0.01,0.03,0.1`
    /// (repeatable; every combination is run).
    #[arg(long = "set", value_name = "PATH=V1[,V2...]")]
    pub set: Vec<String>,
    /// Campaign directory: `runs/` (one file per finished run, reused on rerun), `eval.csv`
    /// (one row per run) and `summary.csv` (one row per world and parameters).
    #[arg(long, default_value = "runs/eval")]
    pub out: PathBuf,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Reuse the runs stored in DIR whatever build of swarmmap made them (by default a
    /// run stored by another build, an upgrade or a change to the code, is run again).
    #[arg(long)]
    pub reuse_any_build: bool,
}

/// The values of `--set PATH=V1,V2,...`: split at the commas outside brackets and quotes,
/// so that a value may itself be a section or a list (`swarm=(agents: 10, speed: 0.1)`,
/// `obstacles=[Circle(...), Rect(...)]`).
fn sweep_values(values: &str) -> Vec<String> {
    let mut out = Vec::new();
    let (mut depth, mut quoted, mut escaped) = (0usize, false, false);
    let mut current = String::new();
    for c in values.chars() {
        if quoted {
            quoted = escaped || c != '"';
            escaped = !escaped && c == '\\';
        } else {
            match c {
                '"' => quoted = true,
                '(' | '[' | '{' => depth += 1,
                ')' | ']' | '}' => depth = depth.saturating_sub(1),
                ',' if depth == 0 => {
                    out.push(current.trim().to_string());
                    current.clear();
                    continue;
                }
                _ => {}
            }
        }
        current.push(c);
    }
    out.push(current.trim().to_string());
    out
}

/// Most seeds one campaign or fit takes: far beyond any campaign this machine could run
/// (a million runs of the smallest bundled world take weeks), and a bound on the memory a
/// typo such as `1..18446744073709551615` would otherwise ask for.
pub const MAX_SEEDS: u64 = 1_000_000;

/// Parses `A..B` (inclusive) or `a,b,c`. A seed listed twice is refused: each seed is one
/// independent run, and a repeated one would be counted twice in every figure and interval.
pub fn parse_seeds(s: &str) -> Result<Vec<u64>, String> {
    let bad = || format!("--seeds `{s}` is not `A..B` or a list like `1,2,5`");
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u64, u64) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim()
                .trim_start_matches('=')
                .parse()
                .map_err(|_| bad())?,
        );
        if a > b {
            return Err(format!("--seeds {s}: the range is empty (start after end)"));
        }
        if b - a >= MAX_SEEDS {
            return Err(format!(
                "--seeds {s} asks for {} runs of each world; at most {MAX_SEEDS} seeds per \
                 campaign, so split it into several (each resumes in its own --out)",
                u128::from(b - a) + 1
            ));
        }
        Ok((a..=b).collect())
    } else {
        let seeds: Vec<u64> = s
            .split(',')
            .map(|x| x.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?;
        let mut seen = std::collections::BTreeSet::new();
        if let Some(d) = seeds.iter().find(|&&x| !seen.insert(x)) {
            return Err(format!(
                "--seeds {s}: seed {d} is listed twice; each seed is one independent run, so list it once"
            ));
        }
        Ok(seeds)
    }
}

pub fn run(args: &EvalArgs) -> Result<(), Failure> {
    let seeds = parse_seeds(&args.seeds).map_err(|e| input(anyhow!(e)))?;
    super::refuse_repeated_worlds(&args.worlds)?;
    super::refuse_seed_set(&args.set)?;
    // Before any run: a campaign directory that cannot be written is the user's to fix.
    swarmmap::sim::prepare_out_dir(&args.out).map_err(input)?;
    let mut sweeps: Vec<(String, Vec<String>)> = Vec::new();
    for s in &args.set {
        let (path, values) = s.split_once('=').ok_or_else(|| {
            input(anyhow!(
                "--set `{s}`: expected PATH=VALUE[,VALUE...], e.g. swarm.agents=100,200"
            ))
        })?;
        let values = sweep_values(values);
        let path = path.trim().to_string();
        // A repeated value or field would run the same parameters twice and count them
        // as two sets (or let the last one win unseen).
        let mut seen = std::collections::BTreeSet::new();
        if let Some(v) = values.iter().find(|v| !seen.insert(v.as_str())) {
            return Err(input(anyhow!(
                "--set `{s}`: the value {v} is listed twice; list each value once"
            )));
        }
        let key = super::setting_key(&path);
        if sweeps.iter().any(|(p, _)| super::setting_key(p) == key) {
            return Err(input(anyhow!(
                "--set {path} is given twice; give its values in one --set {path}=V1,V2,..."
            )));
        }
        // Overrides apply in the order given: a section after one of its fields would drop
        // that field's values unseen (as for run, simulate and check).
        if let Some((p, _)) = sweeps
            .iter()
            .find(|(p, _)| super::inside(&super::setting_key(p), &key))
        {
            return Err(input(anyhow!(
                "--set {path} replaces the whole of what an earlier --set {p} set, so its values \
                 would be lost; give a section before its fields"
            )));
        }
        sweeps.push((path, values));
    }
    let combos = combinations(&sweeps);
    // Validate every world × combination up front, so a typo fails at once, not per run.
    // Runs are grouped by the world's name: two files of one name would be merged into one
    // row, their seeds paired as one world's.
    let mut names: std::collections::BTreeMap<String, &std::path::PathBuf> = Default::default();
    for w in &args.worlds {
        // Two parameter sets that give one world (an `obstacles.scale` of a world without
        // obstacles, `50` and `50.0`) get the same runs, made once (`run_campaign`) and
        // shown under both sets: said, since it is rarely what was meant.
        let mut made: Vec<(swarmmap::world::World, &Vec<(String, String)>)> = Vec::new();
        for c in &combos {
            let mut spec = WorldSpec::load(w).map_err(input)?;
            for (p, v) in c {
                swarmmap::world::apply_override(&mut spec, p, v).map_err(input)?;
            }
            let world = spec.check().map_err(input)?;
            if let Some((_, earlier)) = made.iter().find(|(other, _)| *other == world) {
                let show = |c: &[(String, String)]| {
                    c.iter()
                        .map(|(p, v)| format!("--set {p}={v}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                };
                eprintln!(
                    "warning: {}: `{}` and `{}` give the same world (a value that changes \
                     nothing here, such as obstacles.scale on a world without obstacles, or \
                     one written twice, as 50 and 50.0); its runs are made once and shown \
                     under both",
                    w.display(),
                    show(earlier),
                    show(c)
                );
            }
            made.push((world.clone(), c));
            if let Some(first) = names.insert(world.name.clone(), w)
                && first != w
            {
                return Err(input(anyhow!(
                    "{} and {} are both named `{}`, so the campaign would count their runs as \
                     one world's; give each world its own `name`",
                    first.display(),
                    w.display(),
                    world.name
                )));
            }
        }
    }
    let mut jobs = Vec::new();
    for w in &args.worlds {
        for c in &combos {
            for &seed in &seeds {
                jobs.push(Job {
                    world: w.clone(),
                    overrides: c.clone(),
                    seed,
                });
            }
        }
    }
    let threads = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let bar = super::progress_bar(args.quiet, "evaluating");
    if let Some(b) = &bar {
        b.set_length(jobs.len() as u64);
    }
    let failures = Mutex::new(Vec::new());
    let tick = |r: &swarmmap::eval::campaign::RunRecord| {
        if let Some(e) = &r.error
            && let Ok(mut f) = failures.lock()
        {
            f.push((r.world_file.clone(), r.params.clone(), r.seed, e.clone()));
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let build = super::reusable_build(args.reuse_any_build)?;
    let records = run_campaign(&jobs, &args.out, threads.max(1), build, &tick)
        .with_context(|| format!("running the campaign in {}", args.out.display()))?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let csv_path = args.out.join("eval.csv");
    write_atomic(&csv_path, csv(&records).as_bytes())
        .with_context(|| format!("writing {}", csv_path.display()))?;
    let summary_path = args.out.join("summary.csv");
    write_atomic(&summary_path, summary_csv(&groups(&records)).as_bytes())
        .with_context(|| format!("writing {}", summary_path.display()))?;
    print!("{}", table(&records));
    println!(
        "per-run rows: {}; per world and parameters: {}",
        csv_path.display(),
        summary_path.display()
    );
    // Said, not only counted in the table (found by review: the messages were collected and
    // dropped). A failed run is stored like any other and reused by a rerun into the same
    // DIR, as the same world and seed fail the same way.
    let mut failures = failures.into_inner().unwrap_or_else(|e| e.into_inner());
    failures.sort();
    if !failures.is_empty() {
        eprintln!(
            "warning: {} run(s) failed and are left out of the figures (their rows in {} give \
             the error; a rerun into {} reuses them unless their files under runs/ are removed):",
            failures.len(),
            csv_path.display(),
            args.out.display()
        );
        for (world, params, seed, e) in failures.iter().take(10) {
            let params = if params.is_empty() {
                String::new()
            } else {
                format!(" [{params}]")
            };
            eprintln!("  {world}{params} seed {seed}: {e}");
        }
        if failures.len() > 10 {
            eprintln!("  … and {} more", failures.len() - 10);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::parse_seeds;

    #[test]
    fn seeds_parse() {
        assert_eq!(parse_seeds("1..3").unwrap(), vec![1, 2, 3]);
        assert_eq!(parse_seeds("4,7").unwrap(), vec![4, 7]);
        assert!(parse_seeds("3..1").is_err());
        assert!(parse_seeds("x").is_err());
        // A sweep's values are split at the commas between values only (found by review:
        // `obstacles=[...]` or a whole section could not be given to eval).
        assert_eq!(super::sweep_values("100, 200"), ["100", "200"]);
        assert_eq!(
            super::sweep_values("(agents: 10, speed: 0.1),(agents: 20)"),
            ["(agents: 10, speed: 0.1)", "(agents: 20)"]
        );
        assert_eq!(
            super::sweep_values("[Circle(center: (1.0, 2.0), radius: 0.5)], []"),
            ["[Circle(center: (1.0, 2.0), radius: 0.5)]", "[]"]
        );
        assert_eq!(
            super::sweep_values(r#""a, \"b\", c",d"#),
            [r#""a, \"b\", c""#, "d"]
        );
        // A range too large to hold is refused, not a panic (found by review: capacity
        // overflow, status 101).
        let huge = parse_seeds("1..18446744073709551615").unwrap_err();
        assert!(huge.contains("18446744073709551615 runs"), "{huge}");
        assert!(parse_seeds("0..999999").is_ok_and(|s| s.len() == 1_000_000));
        assert!(parse_seeds("0..1000000").is_err());
        let twice = parse_seeds("1,2,1").unwrap_err();
        assert!(twice.contains("seed 1 is listed twice"), "{twice}");
    }
}
