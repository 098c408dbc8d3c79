//! `swarmmap map RUN_DIR [--windows N] [--overlap S] [--set mapping.FIELD=VALUE]`: local
//! maps, connections and the global map of an encounter log, from a simulation or a real
//! experiment. An existing `RUN_DIR/report/` is regenerated from the new maps.

use super::{Failure, input};
use clap::Args;
use std::path::PathBuf;
use swarmmap::log::EncounterLog;
use swarmmap::log::StaticReason;
use swarmmap::mapping::local::LocalParams;
use swarmmap::mapping::pipeline::MapConfig;
use swarmmap::mapping::stitch::StitchParams;
use swarmmap::pipeline::{
    PipelineError, Timings, map_log, seed_from_run, spec_from_run, write_maps,
};
use swarmmap::world::short;
use swarmmap::world::{MappingMethod, MappingParams};

/// Options of `swarmmap map`.
#[derive(Args, Debug)]
pub struct MapArgs {
    /// Directory with encounters.csv (and optionally static_intervals.csv, leader.csv,
    /// meta.json). Outputs go to RUN_DIR/maps/ and RUN_DIR/summary.json.
    pub run_dir: PathBuf,
    /// Number of windows N (default: the world's `mapping.windows`, else 4).
    #[arg(long)]
    pub windows: Option<usize>,
    /// Overlap Δt between windows in seconds (default: the world's `mapping.overlap`,
    /// else 300).
    #[arg(long)]
    pub overlap: Option<f64>,
    /// World file to evaluate against, instead of the one in RUN_DIR/meta.json. Without
    /// either, the log is mapped without ground truth.
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// Local-mapping method (default: the world's `mapping.method`, else `paper`):
    /// `paper` (Rips on the encounter metric) or `embedded` (Rips on the plane of the
    /// encounter point cloud, anchored on encounters with static landmarks).
    #[arg(long, value_enum)]
    pub method: Option<Method>,
    /// Override a mapping parameter, `mapping.FIELD=VALUE` (repeatable; the whole section
    /// as `mapping=(...)`), on top of the world's or, without a world, of the defaults: to
    /// map a real log with the settings the shipped models were fitted at (the README's
    /// "Commands" gives them). The windows are cut with --windows and --overlap instead.
    #[arg(long = "set", value_name = "mapping.FIELD=VALUE")]
    pub set: Vec<String>,
    /// The leader's sweep speed the log was recorded at, m/s (default: the world's
    /// `leader.speed`; without a world, the paper's 0.005). It picks the classifier's
    /// models fitted nearest it and scales the outlier filter's neighbour rank; a world
    /// fixes it, so with one it may only repeat the world's.
    #[arg(long, value_name = "M_PER_S", allow_negative_numbers = true)]
    pub sweep: Option<f64>,
}

/// `--method` values.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    Paper,
    Embedded,
}

impl From<Method> for MappingMethod {
    fn from(m: Method) -> Self {
        match m {
            Method::Paper => MappingMethod::Paper,
            Method::Embedded => MappingMethod::Embedded,
        }
    }
}

/// The mapping parameters `--set` gives on top of the defaults (for a log without a world),
/// after refusing a `--set` that `map` cannot take: one outside `mapping`, the windows and
/// the overlap (cut from the log with `--windows` and `--overlap`), and a field that a flag
/// also gives.
fn mapping_sets(args: &MapArgs) -> Result<MappingParams, Failure> {
    for assignment in &args.set {
        let path = assignment
            .split_once('=')
            .map_or(assignment.as_str(), |(p, _)| p);
        let key = super::setting_key(path);
        if key.starts_with("mapping.") && !swarmmap::world::SETTING_PATHS.contains(&key.as_str()) {
            let valid: Vec<&str> = swarmmap::world::SETTING_PATHS
                .iter()
                .copied()
                .filter(|p| {
                    p.starts_with("mapping.")
                        && !matches!(*p, "mapping.windows" | "mapping.overlap")
                })
                .collect();
            return Err(input(anyhow::anyhow!(
                "--set {assignment}: no such mapping setting; map takes {} (and the whole \
                 mapping=(...))",
                valid.join(", ")
            )));
        }
        if key != "mapping" && !key.starts_with("mapping.") {
            return Err(input(anyhow::anyhow!(
                "--set {assignment}: map takes only mapping.FIELD=VALUE (or the whole \
                 mapping=(...)); the log is already recorded, so the arena, the swarm, the \
                 leader and the simulation are fixed by it (or by the world it is judged \
                 against: --world)"
            )));
        }
    }
    let mut spec = swarmmap::world::WorldSpec::default();
    spec.origin.name = "map".into();
    super::apply_sets(&mut spec, &args.set)?;
    let asked = spec.mapping.clone().unwrap_or_default();
    for (given, flag, field) in [
        (asked.windows.is_some(), "--windows", "mapping.windows"),
        (asked.overlap.is_some(), "--overlap", "mapping.overlap"),
    ] {
        if given {
            return Err(input(anyhow::anyhow!(
                "--set gives {field}, but map cuts the log into windows with {flag} (checked \
                 against the log's own span, not a world's run); pass {flag} instead"
            )));
        }
    }
    if asked.method.is_some() && args.method.is_some() {
        return Err(input(anyhow::anyhow!(
            "both --method and --set mapping.method are given, so one would be lost; give \
             the method once"
        )));
    }
    Ok(spec.check().map_err(input)?.mapping)
}

/// The sweep speed the log is mapped at: `--sweep`, else the world's, else the paper's. A
/// world fixes the sweep (its leader moved the domain the log was recorded in), so a
/// `--sweep` that differs from it is refused rather than silently preferred.
fn sweep_of(args: &MapArgs, world: Option<&swarmmap::world::World>) -> Result<f64, Failure> {
    let Some(v) = args.sweep else {
        return Ok(
            world.map_or(swarmmap::mapping::classify::DEFAULT_SWEEP, |w| {
                w.leader.speed
            }),
        );
    };
    if !(v.is_finite() && v > 0.0) {
        return Err(input(anyhow::anyhow!(
            "--sweep is {}; it is the leader's sweep speed in m/s, a positive number (the \
             paper's is {})",
            swarmmap::world::given(v),
            swarmmap::mapping::classify::DEFAULT_SWEEP
        )));
    }
    if let Some(w) = world
        && v != w.leader.speed
    {
        let (whose, fix) = match &args.world {
            Some(path) => (
                format!("the world {}", path.display()),
                "drop --sweep, or correct the world's leader.speed",
            ),
            None => (
                format!(
                    "the run's world ({})",
                    args.run_dir.join("meta.json").display()
                ),
                "drop --sweep (the run recorded the sweep it was simulated at), or judge the \
                 log against another world with --world",
            ),
        };
        return Err(input(anyhow::anyhow!(
            "--sweep is {} m/s, but {whose} sweeps at {} m/s (its leader.speed), and the \
             world fixes the sweep; {fix}",
            swarmmap::world::given(v),
            swarmmap::world::given(w.leader.speed)
        )));
    }
    Ok(v)
}

pub fn run(args: &MapArgs) -> Result<(), Failure> {
    let mut timings = Timings::default();
    let (log, notes) = timings
        .time("reading", || EncounterLog::read_dir_noting(&args.run_dir))
        .map_err(input)?;
    let defaults = mapping_sets(args)?;
    let spec = match &args.world {
        Some(path) => Some(swarmmap::world::WorldSpec::load(path).map_err(input)?),
        None => spec_from_run(&args.run_dir).map_err(input)?,
    };
    let world = match spec {
        Some(mut spec) => {
            // The windows stay the world's (or the flags'): a `--set mapping=(...)` of the
            // whole section would otherwise reset them to the defaults.
            let cut = spec.mapping.as_ref().map(|m| (m.windows, m.overlap));
            super::apply_sets(&mut spec, &args.set)?;
            if let (Some(m), Some((windows, overlap))) = (spec.mapping.as_mut(), cut) {
                (m.windows, m.overlap) = (windows, overlap);
            } else if let Some(m) = spec.mapping.as_mut() {
                (m.windows, m.overlap) = (None, None);
            }
            Some(spec.check().map_err(input)?)
        }
        None => None,
    };
    let sweep = sweep_of(args, world.as_ref())?;
    let (mut cfg, stitch) = match &world {
        Some(w) => (
            MapConfig::for_world(w),
            StitchParams::from_mapping(&w.mapping),
        ),
        None => {
            let m = defaults.clone();
            let span = log.span().ok_or_else(|| {
                input(anyhow::anyhow!(
                    "{}: the log has no encounters to map",
                    args.run_dir.display()
                ))
            })?;
            (
                MapConfig {
                    windows: m.windows,
                    overlap: m.overlap,
                    span,
                    local: LocalParams::from_mapping_at(&m, sweep),
                },
                StitchParams::from_mapping(&m),
            )
        }
    };
    if let Some(n) = args.windows {
        if n == 0 || n > swarmmap::world::MAX_WINDOWS {
            return Err(input(anyhow::anyhow!(
                "--windows is {n}; use 1 to {} windows, as in a world file's mapping.windows (the paper uses 4 to 6)",
                swarmmap::world::MAX_WINDOWS
            )));
        }
        cfg.windows = n;
    }
    if let Some(o) = args.overlap {
        if !(o.is_finite() && o >= 0.0) {
            return Err(input(anyhow::anyhow!(
                "--overlap must be a non-negative number of seconds, got {}",
                swarmmap::world::given(o)
            )));
        }
        cfg.overlap = o;
    }
    let encounters_csv = args.run_dir.join("encounters.csv");
    if log.encounters.is_empty() {
        eprintln!(
            "warning: {} holds no encounters: every map is empty",
            encounters_csv.display()
        );
    }
    if !notes.encounters_in_order {
        eprintln!(
            "warning: {}'s rows are not in order of start time (then a, then b, with a < b \
             in each row): the maps number encounters in that order (`encounter` in \
             maps/window_<i>.json, `points` in maps/connections.json), not by the file's \
             rows; sort the file that way to make the numbers its data rows",
            encounters_csv.display()
        );
    }
    if notes.repeated_encounters > 0 {
        eprintln!(
            "warning: {} has {} row(s) repeating an earlier encounter (the same start, end \
             and pair of agents); each is mapped as one more encounter: remove them if the \
             file holds some rows twice",
            encounters_csv.display(),
            notes.repeated_encounters
        );
    }
    if notes.overlapping_encounters > 0 {
        eprintln!(
            "warning: {} has {} row(s) overlapping in time an earlier encounter of the same \
             two agents; one contact is one interval, so these are contacts recorded twice \
             (as when each robot logs the encounter with its own clock) and each is mapped as \
             one more encounter: keep one robot's rows, or merge each pair's overlapping rows",
            encounters_csv.display(),
            notes.overlapping_encounters
        );
    }
    for path in &notes.unterminated {
        eprintln!(
            "warning: {}'s last line has no line end: was the file cut off while it was being \
             written? Its last row was read as it stands, perhaps cut short (an agent 47 read as \
             4); check it, or end the line if the file is whole",
            path.display()
        );
    }
    if notes.overlapping_static > 0 {
        eprintln!(
            "warning: {} has {} interval(s) overlapping an earlier one of the same agent; an \
             agent stands at one place at a time: merge them, or correct the times",
            args.run_dir.join("static_intervals.csv").display(),
            notes.overlapping_static
        );
    }
    if let Some(w) = &world {
        for line in disagreements(&log, w, cfg.span) {
            eprintln!("warning: {line}");
        }
    }
    let length = (cfg.span.1 - cfg.span.0) / cfg.windows as f64;
    if cfg.span.1 <= cfg.span.0 && !log.encounters.is_empty() {
        return Err(input(anyhow::anyhow!(
            "{}: the log spans no time (every encounter and static interval starts and ends \
             at {} s), so it cannot be cut into time windows; a log to map needs encounters \
             over some time",
            encounters_csv.display(),
            short(cfg.span.0)
        )));
    }
    if cfg.overlap >= length {
        let whose = match (args.overlap, &world) {
            (Some(_), _) => "--overlap".to_string(),
            (None, Some(_)) => "the world's mapping.overlap".to_string(),
            (None, None) => "the default overlap".to_string(),
        };
        return Err(input(anyhow::anyhow!(
            "{whose} is {} s, not shorter than one window ({} s = {} s of log / {} windows), \
             so every window would span the whole log; pass --overlap below {} s, or fewer \
             --windows",
            swarmmap::world::given(cfg.overlap),
            short(length),
            short(cfg.span.1 - cfg.span.0),
            cfg.windows,
            swarmmap::world::suggest(length, swarmmap::world::Inward::Down, |v| v <= length),
        )));
    }
    if let Some(method) = args.method {
        let mut m = world
            .as_ref()
            .map_or_else(|| defaults.clone(), |w| w.mapping.clone());
        m.method = method.into();
        cfg.local = LocalParams::from_mapping_at(&m, sweep);
    }
    if !log
        .static_intervals
        .iter()
        .any(|s| s.reason == StaticReason::Landmark)
    {
        eprintln!(
            "warning: {} has no landmark static intervals (static_intervals.csv, reason \
             `landmark`): no static agent bridges time or stands through the windows' \
             overlaps, so the metric is travel time alone and consecutive local maps cannot \
             be stitched (every window is its own component of the global map)",
            args.run_dir.display()
        );
    }
    // The run's seed (a real log has none): a world file's `seed` field says nothing about
    // which seed produced this log.
    let seed = seed_from_run(&args.run_dir).map_err(input)?;
    // The world's truth can fail (an arena too large to rasterise): name the file it came from.
    let world_file = match &args.world {
        Some(path) => path.clone(),
        None => args.run_dir.join("meta.json"),
    };
    let mut mapped =
        map_log(&log, world.as_ref(), &cfg, &stitch, seed, &mut timings).map_err(|e| {
            if matches!(e, PipelineError::Truth(_)) {
                input(anyhow::anyhow!("{}: the world's {e}", world_file.display()))
            } else {
                input(e)
            }
        })?;
    // A world given with --world is recorded, so the report draws the world the maps were
    // judged against, not meta.json's (found by review: it drew the run's world under the
    // other world's truth).
    if args.world.is_some() {
        mapped.summary.judged_world = world.as_ref().map(swarmmap::sim::world_json);
    }
    // A report made from the previous maps would be stale: it goes before they are
    // replaced (an interrupted or failed write then leaves no report of other maps, nor
    // the figures of a report interrupted earlier) and, if there was one, is made again
    // from the new ones.
    let page = args.run_dir.join("report").join("index.html");
    let had_report = swarmmap::report::has_report(&args.run_dir);
    swarmmap::report::remove_report(&args.run_dir).map_err(|source| PipelineError::Write {
        path: args.run_dir.join("report"),
        source,
    })?;
    write_maps(&args.run_dir, &log, &mut mapped)?;
    print!("{}", mapped.summary.table());
    if let Some(w) = swarmmap::pipeline::density_warning(&mapped.maps, &cfg.local.classifier) {
        eprintln!("warning: {w}");
    }
    if let Some(w) = empty_windows(&log, &mapped.maps, cfg.span, world.is_some()) {
        eprintln!("warning: {w}");
    }
    if !log.encounters.is_empty() && mapped.summary.global.betti[0] == 0 {
        // Every component of every window was judged noise: the maps are empty although
        // the log is not (a log too sparse for its windows, or windows too short).
        eprintln!(
            "warning: every window's encounters were judged noise (β0 = 0 everywhere) although \
             {} holds {} encounter(s): the log is too sparse for {} window(s); {}",
            encounters_csv.display(),
            log.encounters.len(),
            cfg.windows,
            if cfg.windows > 1 {
                "map it with fewer --windows, or record more encounters"
            } else {
                "record more encounters"
            }
        );
    }
    if had_report {
        swarmmap::report::write_report(&args.run_dir).map_err(super::report::failure)?;
        println!("report refreshed: {}", page.display());
    }
    Ok(())
}

/// A warning when some windows hold no encounter although the log has some: the windows
/// are cut over a span (the run's, or the log's with its static intervals) that the
/// encounters do not fill, as a mistyped end in `static_intervals.csv` or a log of part of
/// a run makes it. `None` when every window holds encounters, or the log none.
fn empty_windows(
    log: &EncounterLog,
    maps: &[swarmmap::mapping::local::LocalMap],
    span: (f64, f64),
    with_world: bool,
) -> Option<String> {
    let empty: Vec<String> = maps
        .iter()
        .filter(|m| m.events.is_empty())
        .map(|m| m.index.to_string())
        .collect();
    let first = log.encounters.iter().map(|e| e.start).reduce(f64::min)?;
    let last = log.encounters.iter().map(|e| e.end).reduce(f64::max)?;
    if empty.is_empty() {
        return None;
    }
    let why = if with_world {
        "the run's span, from its world: is this log the whole run?".to_string()
    } else {
        "the span of the encounters and of static_intervals.csv together: a row of \
         static_intervals.csv far outside the encounters' times, such as a mistyped time, \
         stretches every window; correct it, or pass --world for the run's own span"
            .to_string()
    };
    Some(format!(
        "window{} {} {} no encounter: the log's encounters span {}–{} s, but the windows are \
         cut over {}–{} s ({why})",
        if empty.len() == 1 { "" } else { "s" },
        empty.join(", "),
        if empty.len() == 1 { "holds" } else { "hold" },
        short(first),
        short(last),
        short(span.0),
        short(span.1)
    ))
}

/// Where a log and the world it is mapped with disagree: encounters outside the run's span
/// (they fall in no window), agents the world does not have, a leader outside the arena.
/// The log is still mapped (a real experiment's log need not match a world exactly), but
/// the user hears of it, since the truth columns then describe another run.
fn disagreements(
    log: &EncounterLog,
    world: &swarmmap::world::World,
    span: (f64, f64),
) -> Vec<String> {
    let mut out = Vec::new();
    let outside = log
        .encounters
        .iter()
        .filter(|e| e.end < span.0 || e.start > span.1)
        .count();
    if outside > 0 {
        out.push(format!(
            "{outside} encounter(s) lie outside the run's {}–{} s and are in no window; is \
             this the world the log came from (--world)?",
            span.0, span.1
        ));
    }
    let agents = world.swarm.agents;
    let highest = log
        .encounters
        .iter()
        .flat_map(|e| [e.a, e.b])
        .chain(log.static_intervals.iter().map(|s| s.agent))
        .max();
    if let Some(h) = highest.filter(|&h| h as usize >= agents) {
        out.push(format!(
            "the log names agent {h}, but the world has {agents} agent(s) (0 to {}); is this \
             the world the log came from (--world)?",
            agents - 1
        ));
    }
    let width = world.arena.width;
    if let Some(&(t, x)) = log
        .leader
        .iter()
        .find(|&&(_, x)| !(0.0..=width).contains(&x))
    {
        out.push(format!(
            "the leader is at x = {x} m at t = {t} s, outside the {width} m arena; the \
             windows' domains are clipped to the arena"
        ));
    }
    out
}
