//! The pipeline of named stages (see `ARCHITECTURE.md`):
//! world → simulation → encounter log → local maps → global map → evaluation, each timed.
//!
//! `swarmmap run` calls [`run_world`]; `swarmmap map` calls [`map_log`] on a log read from
//! disk; `swarmmap eval` calls [`run_world_variants`] for many worlds and seeds in parallel
//! (one simulation for the runs that differ only in their mapping settings).

use crate::eval::truth::{FreeSpace, TruthError, overlap, window_band};
use crate::io::{is_numbered_map, remove_stale, write_atomic};
use crate::log::{EncounterLog, LogError};
use crate::mapping::local::LocalMap;
use crate::mapping::local::local_map_with;
use crate::mapping::output::WindowSummary;
use crate::mapping::output::{
    ConnectionSummary, GlobalSummary, Summary, connection_json, window_json,
};
use crate::mapping::pipeline::{MapConfig, summarise_window};
use crate::mapping::stitch::{Connection, GlobalMap, StitchParams, connect, global_map};
use crate::mapping::windows::Window;
use crate::sim::{SimError, SimOptions, SimOutput, simulate, write_run};
use crate::world::{World, WorldError, WorldSpec};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, mpsc};
use std::time::Instant;
use thiserror::Error;

/// Why a pipeline stage failed.
#[derive(Debug, Error)]
pub enum PipelineError {
    #[error(transparent)]
    World(#[from] WorldError),
    #[error(transparent)]
    Log(#[from] LogError),
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error("ground truth: {0}")]
    Truth(#[from] TruthError),
    #[error("{path}: {message}")]
    Meta { path: PathBuf, message: String },
    #[error("writing {path}: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl PipelineError {
    /// Whether the user's input is at fault (exit status 2) rather than the machine.
    pub fn is_input(&self) -> bool {
        !matches!(self, PipelineError::Write { .. })
            && !matches!(self, PipelineError::Sim(SimError::Write { .. }))
    }
}

/// Everything the mapping stages produce for one log.
#[derive(Debug, Clone)]
pub struct Mapped {
    pub maps: Vec<LocalMap>,
    pub connections: Vec<Connection>,
    pub global: GlobalMap,
    pub summary: Summary,
    /// The stitching parameters (the cut-off is recorded in `maps/connection_<i>.json`).
    pub stitch: StitchParams,
}

/// Wall-clock seconds per stage, in the order the stages ran.
#[derive(Debug, Clone, Default)]
pub struct Timings(pub BTreeMap<String, f64>);

impl Timings {
    /// Runs `f`, recording its duration under `stage`.
    pub fn time<T>(&mut self, stage: &str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        *self.0.entry(stage.to_string()).or_default() += t.elapsed().as_secs_f64();
        out
    }
}

/// A run's `meta.json` as JSON, with its path; `None` when the directory has none.
fn read_meta(dir: &Path) -> Result<Option<(PathBuf, serde_json::Value)>, PipelineError> {
    let path = dir.join("meta.json");
    if !path.exists() {
        return Ok(None);
    }
    let meta_err = |message: String| PipelineError::Meta {
        path: path.clone(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| meta_err(e.to_string()))?;
    let value = serde_json::from_str(&text).map_err(|e| {
        let (place, what) = crate::io::json_error_at(&path, &e);
        PipelineError::Meta {
            path: PathBuf::from(place),
            message: format!("not valid JSON: {what}"),
        }
    })?;
    check_format(&value).map_err(meta_err)?;
    Ok(Some((path, value)))
}

/// Refuses a `meta.json` whose `format` is not [`crate::sim::META_FORMAT`], the one this
/// build writes: a later format's fields may mean other things, and a file of another
/// tool's is not a run. A file without the field (written by hand beside a real
/// experiment's log) is read as it stands.
fn check_format(meta: &serde_json::Value) -> Result<(), String> {
    use crate::sim::META_FORMAT;
    match meta.get("format") {
        None => Ok(()),
        Some(serde_json::Value::String(f)) if f == META_FORMAT => Ok(()),
        Some(serde_json::Value::String(f)) if f.starts_with("swarmmap-simulation/") => {
            Err(format!(
                "`format` is \"{f}\", which this build of swarmmap does not read (it reads \"{META_FORMAT}\"); \
             map it with the swarmmap that wrote it, or simulate the run again"
            ))
        }
        Some(other) => Err(format!(
            "`format` is {other}, not \"{META_FORMAT}\": not a swarmmap run's meta.json; \
             move the file away to map the log without it"
        )),
    }
}

/// The seed a simulation ran with, from the top-level `seed` of its `meta.json` (not the
/// world's own `seed` field, which `--seed` overrides), if there is one.
///
/// A `seed` that is present but not a non-negative integer is an error, not a missing seed.
pub fn seed_from_run(dir: &Path) -> Result<Option<u64>, PipelineError> {
    let Some((path, meta)) = read_meta(dir)? else {
        return Ok(None);
    };
    match meta.get("seed") {
        None | Some(serde_json::Value::Null) => Ok(None),
        Some(v) => v.as_u64().map(Some).ok_or_else(|| PipelineError::Meta {
            path,
            message: format!(
                "`seed` is {v}, not a non-negative integer; write the seed the simulation ran with, or remove the field"
            ),
        }),
    }
}

/// A warning when windows are far sparser than the training windows of the models that
/// judge them ([`crate::mapping::classify::Bank::too_sparse_for`]): their holes are then
/// likely noise. `None` when no window is.
pub fn density_warning(maps: &[LocalMap], bank: &crate::mapping::classify::Bank) -> Option<String> {
    let sparse: Vec<(&LocalMap, crate::mapping::classify::Density)> = maps
        .iter()
        .filter(|m| m.events_per_point.is_finite() && m.events_per_point > 0.0)
        .filter_map(|m| bank.too_sparse_for(m.events_per_point).map(|d| (m, d)))
        .collect();
    let (_, d) = sparse.first()?;
    let densities: Vec<f64> = sparse.iter().map(|(m, _)| m.events_per_point).collect();
    let low = densities.iter().copied().fold(f64::INFINITY, f64::min);
    let high = densities.iter().copied().fold(0.0, f64::max);
    let mut names: Vec<String> = sparse.iter().map(|(m, _)| m.index.to_string()).collect();
    let (which, verb, held) = match names.len() {
        1 => (format!("window {}", names[0]), "holds", format!("{low:.2}")),
        _ => {
            let last = names.pop().unwrap_or_default();
            (
                format!("windows {} and {last}", names.join(", ")),
                "hold",
                format!("{low:.2}–{high:.2}"),
            )
        }
    };
    // Fewer Rips points would quiet the warning without making the log denser: the
    // stitching of such a log still splinters (scenario 1's log thinned to a tenth, at 300
    // points: every window right, connections 14, 8 and 11, global β1 30), so it is not
    // offered as the fix.
    let more = if maps.len() > 1 {
        "record more encounters per window (fewer windows: mapping.windows, map's --windows)"
    } else {
        "record more encounters"
    };
    Some(format!(
        "{which} {verb} {held} encounters per Rips vertex, far fewer than the {}–{} of the \
         windows the classifier was fitted on: on such sparse clouds its thresholds show \
         noise loops as holes, and the stitching splits; {more}, or fit a model at this \
         density (swarmmap calibrate)",
        crate::world::short(d.min),
        crate::world::short(d.max),
    ))
}

/// Reads the world a simulation ran with from its `meta.json`, if there is one.
pub fn world_from_run(dir: &Path) -> Result<Option<World>, PipelineError> {
    match spec_from_run(dir)? {
        Some(spec) => Ok(Some(spec.check()?)),
        None => Ok(None),
    }
}

/// The world a run's maps were judged against: `summary.json`'s `judged_world` when
/// `swarmmap map --world FILE` gave one (`summary_path` names the file in errors), else
/// the world in `meta.json` ([`world_from_run`]).
pub fn judged_world(
    dir: &Path,
    judged: Option<&serde_json::Value>,
    summary_path: &Path,
) -> Result<Option<World>, PipelineError> {
    let Some(value) = judged else {
        return world_from_run(dir);
    };
    let spec = recorded_spec(
        value.clone(),
        summary_path,
        "judged_world",
        "map the run again",
    )?;
    Ok(Some(spec.check()?))
}

/// The world spec a run's `meta.json` records, before its check (to take `--set`
/// overrides first, as `swarmmap map --set` does); `None` without a `meta.json`.
pub fn spec_from_run(dir: &Path) -> Result<Option<WorldSpec>, PipelineError> {
    let Some((path, value)) = read_meta(dir)? else {
        return Ok(None);
    };
    let meta_err = |message: String| PipelineError::Meta {
        path: path.clone(),
        message,
    };
    let world = value
        .get("world")
        .cloned()
        .ok_or_else(|| meta_err("has no `world` object; is it a swarmmap run?".into()))?;
    recorded_spec(
        world,
        &path,
        "world",
        "fix that field, or simulate the run again",
    )
    .map(Some)
}

/// The world spec a run recorded as `field` of the JSON file at `path` (`meta.json`'s
/// `world`, `summary.json`'s `judged_world`), marked as recorded (its agents were placed);
/// an invalid one is an error naming the field at fault ("world.arena.width: invalid type:
/// …") and `fix`.
fn recorded_spec(
    value: serde_json::Value,
    path: &Path,
    field: &str,
    fix: &str,
) -> Result<WorldSpec, PipelineError> {
    let mut spec: WorldSpec =
        serde_path_to_error::deserialize(value).map_err(|e| PipelineError::Meta {
            path: path.to_path_buf(),
            message: format!(
                "its `{field}` is not a valid world: {field}.{}: {}; {fix}",
                e.path(),
                e.inner()
            ),
        })?;
    spec.origin.name = format!("{} ({field})", path.display());
    spec.origin.recorded = true;
    Ok(spec)
}

/// Maps a log: local maps of every window, connections, the global map, and (with the
/// world) the truth of each.
pub fn map_log(
    log: &EncounterLog,
    world: Option<&World>,
    cfg: &MapConfig,
    stitch: &StitchParams,
    seed: Option<u64>,
    timings: &mut Timings,
) -> Result<Mapped, PipelineError> {
    let windows = cfg.windows();
    let done = Partial::new(windows.len());
    finish(log, world, cfg, stitch, seed, &windows, done, timings)
}

/// Work done on prefixes of the log before the final log existed (module docs of
/// [`run_world`]); every entry is what [`finish`] would compute from the final log.
struct Partial {
    maps: Vec<Option<LocalMap>>,
    summaries: Vec<Option<WindowSummary>>,
    /// `connections[k]` joins windows `k` and `k + 1` (0-based).
    connections: Vec<Option<Connection>>,
    free: Option<FreeSpace>,
}

impl Partial {
    fn new(windows: usize) -> Self {
        Self {
            maps: (0..windows).map(|_| None).collect(),
            summaries: vec![None; windows],
            connections: (0..windows.saturating_sub(1)).map(|_| None).collect(),
            free: None,
        }
    }
}

/// The connection between windows `k` and `k + 1` (0-based) of `windows`.
fn connect_pair(
    log: &EncounterLog,
    windows: &[Window],
    k: usize,
    maps: [&LocalMap; 2],
    cfg: &MapConfig,
    stitch: &StitchParams,
) -> Connection {
    connect(
        log,
        &windows[k],
        &windows[k + 1],
        maps[0],
        maps[1],
        &cfg.local,
        stitch,
    )
}

/// How many guessed rows each of `windows` maps still to be made on `free` threads may
/// compute beside each row it needs ([`local_map_with`]): the threads beyond one per
/// window, shared out (`0` while the windows alone keep every thread busy). Farthest-point
/// selection is sequential, so the last window left (of `swarmmap map`, or of `swarmmap
/// run` after the simulation) would otherwise leave the other cores idle.
fn spare_threads(free: usize, windows: usize) -> usize {
    (free / windows.max(1)).saturating_sub(1)
}

/// Completes the mapping of the final `log`: whatever `done` lacks is computed here
/// (windows and consecutive pairs in parallel, collected in order, so the result depends
/// neither on the number of threads nor on what `done` held).
#[allow(clippy::too_many_arguments)]
fn finish(
    log: &EncounterLog,
    world: Option<&World>,
    cfg: &MapConfig,
    stitch: &StitchParams,
    seed: Option<u64>,
    windows: &[Window],
    done: Partial,
    timings: &mut Timings,
) -> Result<Mapped, PipelineError> {
    let Partial {
        maps,
        summaries,
        connections,
        free,
    } = done;
    // Windows not yet mapped: once at most half as many are left as threads, the rest guess
    // rows ahead. Not when called on a pool's thread (a campaign's job): that pool's other
    // threads run other jobs, so a guess would not use an idle core.
    let left = AtomicUsize::new(maps.iter().filter(|m| m.is_none()).count());
    let own_pool = rayon::current_thread_index().is_none();
    let lookahead = || {
        let free = if own_pool {
            rayon::current_num_threads()
        } else {
            0
        };
        spare_threads(free, left.load(Ordering::Acquire))
    };
    let maps: Vec<LocalMap> = timings.time("local maps", || {
        maps.into_par_iter()
            .zip(windows)
            .map(|(m, w)| {
                m.unwrap_or_else(|| {
                    let map = local_map_with(log, w, &cfg.local, &lookahead);
                    left.fetch_sub(1, Ordering::AcqRel);
                    map
                })
            })
            .collect()
    });
    let connections: Vec<Connection> = timings.time("stitching", || {
        connections
            .into_par_iter()
            .enumerate()
            .map(|(k, c)| {
                c.unwrap_or_else(|| {
                    connect_pair(log, windows, k, [&maps[k], &maps[k + 1]], cfg, stitch)
                })
            })
            .collect()
    });
    let global = timings.time("stitching", || global_map(&maps, &connections, log));
    let truth = match (world, free) {
        (Some(w), Some(f)) => Some((w, f)),
        (Some(w), None) => Some((w, timings.time("evaluation", || FreeSpace::for_world(w))?)),
        (None, _) => None,
    };
    let (windows_summary, connections_summary, global_truth) = timings.time("evaluation", || {
        let ws: Vec<WindowSummary> = summaries
            .into_par_iter()
            .zip(&maps)
            .map(|(s, m)| {
                s.unwrap_or_else(|| summarise_window(m, log, truth.as_ref().map(|(w, f)| (*w, f))))
            })
            .collect();
        let cs = connections
            .iter()
            .zip(windows.windows(2))
            .map(|(c, w)| ConnectionSummary {
                between: c.between,
                count: c.count,
                truth: truth.as_ref().map(|(world, fs)| {
                    let a = window_band(world, w[0].start, w[0].end);
                    let b = window_band(world, w[1].start, w[1].end);
                    // What the swarm could have reached by the overlap's end (W_i's end).
                    overlap(a, b).map_or(0, |(x0, x1)| {
                        fs.reached_by(world, w[0].end).components_in_band(x0, x1)
                    })
                }),
            })
            .collect();
        let gt = truth.as_ref().map(|(w, fs)| {
            let holes = fs.holes_in_band(0.0, w.arena.width);
            (
                fs.global_betti(),
                crate::eval::holes::check_global(&maps, &global, log, &holes),
            )
        });
        (ws, cs, gt)
    });
    let summary = Summary {
        world: world.map_or_else(|| "log".to_string(), |w| w.name.clone()),
        seed,
        windows: windows_summary,
        connections: connections_summary,
        global: GlobalSummary {
            betti: global.betti,
            truth: global_truth.as_ref().map(|g| g.0),
            gluing_cycles: global.gluing_cycles,
            holes: global_truth.and_then(|g| g.1),
        },
        timings: timings.0.clone(),
        alongside: BTreeMap::new(),
        judged_world: None,
    };
    Ok(Mapped {
        maps,
        connections,
        global,
        summary,
        stitch: *stitch,
    })
}

/// Writes `maps/window_<i>.json`, `maps/connections.json`, `maps/connection_<i>.json` (one
/// per consecutive pair, named after its first window), `maps/global.json` and
/// `summary.json` into `dir`, each atomically. An earlier `summary.json` is removed first
/// and the new one written last, once every map is in place and the earlier mapping's
/// extra files are gone: a `summary.json` present means a complete set of maps that it
/// describes, and an interrupted or failed write leaves none (`swarmmap report` then asks
/// for the maps to be made again) rather than the old summary beside new maps.
///
/// The maps' texts are made in parallel (a connection's dendrogram and display embedding
/// cost more than a window's thousands of events) and written in order. The time this
/// takes, up to the summary's own text, is added to the summary's `writing` stage.
pub fn write_maps(dir: &Path, log: &EncounterLog, m: &mut Mapped) -> Result<(), PipelineError> {
    let started = Instant::now();
    let summary = dir.join("summary.json");
    if let Err(source) = std::fs::remove_file(&summary)
        && source.kind() != std::io::ErrorKind::NotFound
    {
        return Err(PipelineError::Write {
            path: summary,
            source,
        });
    }
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        write_atomic(&path, text.as_bytes()).map_err(|source| PipelineError::Write { path, source })
    };
    let windows = m.maps.len().min(m.summary.windows.len());
    let files: Vec<(String, String)> = (0..windows + m.connections.len())
        .into_par_iter()
        .map(|k| match k.checked_sub(windows) {
            None => {
                let map = &m.maps[k];
                let text = window_json(map, log, m.summary.windows[k].truth);
                (format!("window_{}.json", map.index), text)
            }
            Some(c) => {
                let c = &m.connections[c];
                let text = connection_json(c, log, m.stitch.cutoff);
                (format!("connection_{}.json", c.between[0]), text)
            }
        })
        .collect();
    let mut written = std::collections::BTreeSet::new();
    for (file, text) in files.into_iter().chain([
        ("connections.json".to_string(), to_json(&m.connections)),
        ("global.json".to_string(), to_json(&m.global)),
    ]) {
        write(&format!("maps/{file}"), &text)?;
        written.insert(file);
    }
    // A log mapped before with more windows left files these maps do not replace.
    let maps = dir.join("maps");
    remove_stale(&maps, &written, is_numbered_map)
        .map_err(|source| PipelineError::Write { path: maps, source })?;
    *m.summary.timings.entry("writing".to_string()).or_default() += started.elapsed().as_secs_f64();
    write("summary.json", &to_json(&m.summary))
}

/// Pretty JSON with a trailing newline.
fn to_json<T: serde::Serialize>(v: &T) -> String {
    let mut s = serde_json::to_string_pretty(v).expect("outputs serialise");
    s.push('\n');
    s
}

/// Options of [`run_world`].
pub struct RunOptions<'a> {
    pub seed: u64,
    /// Where to write the run; `None` keeps everything in memory.
    pub out: Option<PathBuf>,
    pub trajectories: Option<f64>,
    pub progress: Option<&'a dyn Fn(f64)>,
    /// Whether to map windows on the other cores while the simulation goes on
    /// ([`run_world`]); the outputs are the same in every mode.
    pub alongside: Alongside,
}

/// How [`run_world`] maps while the simulation runs ("Mapping while the simulation runs").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alongside {
    /// Simulate, then map every window from the final log. `swarmmap run --map-after`
    /// uses this, and `swarmmap eval`, which runs many simulations side by side, does the
    /// same through [`run_world_variants`].
    Off,
    /// Map each window on the other cores as soon as its part of the log is final; the
    /// simulation never waits, so a prefix that comes while another still waits for the
    /// worker is left to the final pass. Worth it for one run on a machine with idle
    /// cores: `swarmmap run` uses this.
    Free,
    /// As [`Alongside::Free`], but the simulation waits at each cut until the worker has
    /// taken the prefix, and the worker maps every prefix it was handed before the rest
    /// is mapped from the final log. Which windows the worker maps then depends on the run
    /// alone, not on the machine's load: for tests and for measuring the worker.
    Lockstep,
}

/// Most windows for which [`run_world`] maps alongside the simulation: each prefix handed
/// out is a copy of the log so far, so with many short windows the copies would cost the
/// simulation thread more than the worker saves.
pub const ALONGSIDE_MAX_WINDOWS: usize = 64;

/// Simulates a world and maps its log: `swarmmap run` without the printing.
///
/// # Mapping while the simulation runs
///
/// The simulation is one thread; with [`RunOptions::alongside`] other than
/// [`Alongside::Off`] (and more than one core) a second thread maps while it runs. The simulator hands out the log's prefix at the
/// end `c` of each window as soon as every encounter that started by `c` has ended
/// ([`SimOptions::with_prefixes`]; one at a time: a prefix that comes while another still
/// waits for the worker is not copied, and its window is left to the final pass, and with
/// more than [`ALONGSIDE_MAX_WINDOWS`] windows nothing runs alongside); on it the worker
/// maps the window, computes its
/// summary line (truth and fidelity) and, with the previous window's map, their
/// connection, and it rasterises the world's free space first. The rest (windows whose
/// prefix came too late, the last window, the last connection, the global map) is done
/// from the final log once the simulation ends.
///
/// Why a prefix gives the same local map as the final log: a window ending at `c` reads
/// the encounters that meet it, all of which started by `c`, are in the prefix exactly as
/// in the final log and at the same indices (the prefix is the final log's first
/// encounters, which are sorted by start). Of the static intervals it reads which
/// encounters each meets (`s.start <= e.end && e.start <= s.end`), whether it meets the
/// window, and along an agent's time line the gaps `start − end` between consecutive
/// items and which of two ends is later. A static interval still running at the prefix's
/// time `t` ends, in the prefix, at `t + dt`, and in truth no earlier: both are later
/// than every encounter end in the prefix (all ≤ t), so each of these comparisons comes
/// out the same (a gap after such an interval is negative either way, clamped to 0; an
/// agent has at most one running interval, and its other intervals ended by `t`). The
/// connection of windows `c'` < `c` reads the encounters and static intervals that meet
/// their union, which ends at `c`, and whether a landmark's interval ends by `c'`: the
/// same argument. The fidelity reads the truth columns of the window's own encounters.
/// `tests/alongside.rs` checks the outputs byte for byte against mapping the final log.
pub fn run_world(
    world: &World,
    opts: &RunOptions<'_>,
) -> Result<(SimOutput, Mapped), PipelineError> {
    let mut timings = Timings::default();
    let mut sim_opts = SimOptions::new(opts.seed);
    if let Some(t) = opts.trajectories {
        sim_opts = sim_opts.with_trajectories(t);
    }
    if let Some(p) = opts.progress {
        sim_opts = sim_opts.with_progress(p);
    }
    let cfg = MapConfig::for_world(world);
    let stitch = StitchParams::from_mapping(&world.mapping);
    let windows = cfg.windows();
    if let Some(dir) = &opts.out {
        // Before the simulation, which may take hours: an output it cannot write is said now.
        crate::sim::prepare_out_dir(dir)?;
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let alongside_pays = (2..=ALONGSIDE_MAX_WINDOWS).contains(&windows.len());
    let on = opts.alongside != Alongside::Off;
    let (out, done, alongside) = if on && cores > 1 && alongside_pays {
        simulate_alongside(
            world,
            sim_opts,
            &cfg,
            &stitch,
            &windows,
            (cores - 1, opts.alongside == Alongside::Lockstep),
            &mut timings,
        )?
    } else {
        let out = timings.time("simulation", || simulate(world, &sim_opts))?;
        (out, Partial::new(windows.len()), Timings::default())
    };
    if let Some(dir) = &opts.out {
        timings.time("writing", || write_run(dir, world, &out))?;
    }
    let mut mapped = finish(
        &out.log,
        Some(world),
        &cfg,
        &stitch,
        Some(opts.seed),
        &windows,
        done,
        &mut timings,
    )?;
    mapped.summary.alongside = alongside.0;
    if let Some(dir) = &opts.out {
        write_maps(dir, &out.log, &mut mapped)?;
    }
    Ok((out, mapped))
}

/// Whether two worlds simulate alike: they differ in nothing but their `mapping` section,
/// which the simulator never reads (it only copies it into `meta.json`).
pub fn same_simulation(a: &World, b: &World) -> bool {
    World {
        mapping: b.mapping.clone(),
        ..a.clone()
    } == *b
}

/// Simulates the first of `worlds` once (without writing it) and maps its log with each
/// of them, in parallel on the current rayon pool: what [`run_world`] with
/// [`Alongside::Off`] gives for each world, summary for summary, but with one simulation
/// instead of one per world (and one raster of the free space, which the worlds share).
/// Each summary is handed to `done` with its world's index as
/// soon as it is ready (so that a campaign stores it at once); its `timings` hold the one
/// simulation's time. The error is the simulation's, shared by every world (none is then
/// handed to `done`).
///
/// # Panics
///
/// When two of `worlds` do not [simulate alike](same_simulation): one world's log would
/// be judged against another's truth.
pub fn run_world_variants(
    worlds: &[World],
    seed: u64,
    done: &(dyn Fn(usize, Result<Summary, PipelineError>) + Sync),
) -> Result<(), PipelineError> {
    let Some(first) = worlds.first() else {
        return Ok(());
    };
    assert!(
        worlds.iter().all(|w| same_simulation(first, w)),
        "run_world_variants: worlds that differ beyond their mapping settings"
    );
    let mut timings = Timings::default();
    let out = timings.time("simulation", || simulate(first, &SimOptions::new(seed)))?;
    // The free space is the arena's, the obstacles' and the swarm's, which every world
    // shares: rasterised once (an error is left for each world's `finish` to report).
    let free = timings
        .time("evaluation", || FreeSpace::for_world(first))
        .ok();
    worlds.par_iter().enumerate().for_each(|(i, world)| {
        let cfg = MapConfig::for_world(world);
        let stitch = StitchParams::from_mapping(&world.mapping);
        let windows = cfg.windows();
        let mut timings = timings.clone();
        let partial = Partial {
            free: free.clone(),
            ..Partial::new(windows.len())
        };
        let mapped = finish(
            &out.log,
            Some(world),
            &cfg,
            &stitch,
            Some(seed),
            &windows,
            partial,
            &mut timings,
        );
        done(i, mapped.map(|m| m.summary));
    });
    Ok(())
}

/// Runs the simulation on this thread while a worker with a pool of `threads` threads
/// maps each window's prefix ([`run_world`], "Mapping while the simulation runs");
/// with `lockstep` ([`Alongside::Lockstep`]) the simulation waits at each cut until the
/// worker has taken the prefix. Returns the simulation, what the worker finished, and
/// the worker's busy time per stage.
fn simulate_alongside(
    world: &World,
    sim_opts: SimOptions<'_>,
    cfg: &MapConfig,
    stitch: &StitchParams,
    windows: &[Window],
    (threads, lockstep): (usize, bool),
    timings: &mut Timings,
) -> Result<(SimOutput, Partial, Timings), PipelineError> {
    let cuts: Vec<f64> = windows.iter().map(|w| w.end).collect();
    let claims = Mutex::new(Claims {
        stop: false,
        taken: vec![false; windows.len()],
    });
    // Without lockstep a send never blocks: it is made only when nothing waits. With it,
    // a send returns once the worker has received the prefix, and the worker claims each
    // prefix before it receives the next, so every prefix but the last handed out is
    // claimed before the simulation can end (a worker that has stopped makes the send fail).
    let (tx, rx) = mpsc::sync_channel::<(usize, EncounterLog)>(usize::from(!lockstep));
    let waiting = AtomicUsize::new(0);
    // Set once the worker has finished: its threads are then free for the final windows'
    // guessed rows ([`spare_threads`]).
    let worker_done = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (claims, waiting, worker_done) = (&claims, &waiting, &worker_done);
        let worker = scope.spawn(move || {
            let work = move || map_prefixes(rx, waiting, claims, world, cfg, stitch, windows);
            let out = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pool.install(work),
                Err(_) => work(),
            };
            worker_done.store(true, Ordering::Release);
            out
        });
        // At most one prefix waits for the worker: a cut that comes while one waits is left
        // to the final pass, so the copies stay few and memory stays bounded however many
        // windows there are.
        let hand_out = |k: usize, build: &dyn Fn() -> EncounterLog| {
            if lockstep || waiting.load(Ordering::Acquire) == 0 {
                waiting.fetch_add(1, Ordering::AcqRel);
                // The worker only stops receiving once the simulation has ended.
                let _ = tx.send((k, build()));
            }
        };
        let sim = timings.time("simulation", || {
            simulate(world, &sim_opts.with_prefixes(&cuts, &hand_out))
        });
        // Without lockstep the worker stops taking prefixes now, and the windows it has not
        // started are mapped here from the final log while it finishes the one in progress.
        // In lockstep it maps every prefix it was handed (none waits: each send waited for
        // its receipt), and the rest is mapped once it is done.
        let taken = (!lockstep).then(|| {
            let mut c = claims
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            c.stop = true;
            c.taken.clone()
        });
        drop(tx);
        let rest = |taken: &[bool], timings: &mut Timings| -> Vec<(usize, LocalMap)> {
            match &sim {
                Ok(out) => timings.time("local maps", || {
                    // Guesses only take the worker's threads once it has finished the window
                    // it was mapping when the simulation ended.
                    let left = AtomicUsize::new(taken.iter().filter(|t| !**t).count());
                    let cores = rayon::current_num_threads();
                    let lookahead = || {
                        let free = if worker_done.load(Ordering::Acquire) {
                            cores
                        } else {
                            cores.saturating_sub(threads)
                        };
                        spare_threads(free, left.load(Ordering::Acquire))
                    };
                    windows
                        .par_iter()
                        .enumerate()
                        .filter(|(k, _)| !taken[*k])
                        .map(|(k, w)| {
                            let map = local_map_with(&out.log, w, &cfg.local, &lookahead);
                            left.fetch_sub(1, Ordering::AcqRel);
                            (k, map)
                        })
                        .collect()
                }),
                Err(_) => Vec::new(),
            }
        };
        let mine = taken.as_deref().map(|t| rest(t, timings));
        // Waiting for the worker counts as mapping time.
        let (mut done, busy) = timings.time("local maps", || {
            worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        });
        let mine = mine.unwrap_or_else(|| {
            let taken: Vec<bool> = done.maps.iter().map(Option::is_some).collect();
            rest(&taken, timings)
        });
        for (k, map) in mine {
            done.maps[k] = Some(map);
        }
        Ok((sim?, done, busy))
    })
}

/// Which windows the worker of [`simulate_alongside`] has started, and whether it may
/// start another: the simulation's end sets `stop`, and the rest is the main thread's.
struct Claims {
    stop: bool,
    taken: Vec<bool>,
}

/// The worker of [`simulate_alongside`]: the free-space raster, then for each prefix as it
/// comes its window's map, summary line and connection with the previous window, until the
/// channel closes or the simulation has ended (what is left is done from the final log).
fn map_prefixes(
    rx: mpsc::Receiver<(usize, EncounterLog)>,
    waiting: &AtomicUsize,
    claims: &Mutex<Claims>,
    world: &World,
    cfg: &MapConfig,
    stitch: &StitchParams,
    windows: &[Window],
) -> (Partial, Timings) {
    let mut busy = Timings::default();
    let mut done = Partial::new(windows.len());
    // An error is left for the final pass to compute again and report.
    done.free = busy.time("evaluation", || FreeSpace::for_world(world)).ok();
    while let Ok((k, log)) = rx.recv() {
        waiting.fetch_sub(1, Ordering::AcqRel);
        {
            let mut c = claims
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if c.stop {
                break;
            }
            c.taken[k] = true;
        }
        let map = busy.time("local maps", || {
            local_map_with(&log, &windows[k], &cfg.local, &|| {
                spare_threads(rayon::current_num_threads(), 1)
            })
        });
        if let Some(free) = &done.free {
            let line = busy.time("evaluation", || {
                summarise_window(&map, &log, Some((world, free)))
            });
            done.summaries[k] = Some(line);
        }
        if let Some(Some(previous)) = k.checked_sub(1).map(|j| done.maps[j].as_ref()) {
            let c = busy.time("stitching", || {
                connect_pair(&log, windows, k - 1, [previous, &map], cfg, stitch)
            });
            done.connections[k - 1] = Some(c);
        }
        done.maps[k] = Some(map);
    }
    (done, busy)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only the mapping section may differ between worlds that share a simulation.
    #[test]
    fn worlds_simulate_alike_when_only_their_mapping_differs() {
        let base = World::empty("w", 6.0, 3.0);
        let mut mapping = base.clone();
        mapping.mapping.cluster_cutoff = 20.0;
        mapping.mapping.windows = base.mapping.windows + 1;
        assert!(same_simulation(&base, &mapping) && same_simulation(&mapping, &base));
        let mut agents = base.clone();
        agents.swarm.agents += 1;
        let mut seed = base.clone();
        seed.seed += 1;
        let mut leader = mapping.clone();
        leader.leader.speed *= 2.0;
        for other in [&agents, &seed, &leader] {
            assert!(!same_simulation(&base, other), "{other:?}");
        }
    }

    /// Mapping one simulation with several worlds gives, for each, the summary of its own
    /// run ([`run_world`] mapping after the simulation), timings aside; the one simulation
    /// is timed once for all.
    #[test]
    fn variants_of_one_simulation_map_as_their_own_runs() {
        let text = include_str!("../tests/fixtures/worlds/tiny.ron");
        let tiny = crate::world::parse_str(text, "tiny.ron")
            .and_then(WorldSpec::check)
            .expect("the tiny world is valid");
        let mut other = tiny.clone();
        other.mapping.cluster_cutoff = 20.0;
        other.mapping.subsample = 100;
        let worlds = [tiny, other];
        let seed = 2;
        let got = Mutex::new(Vec::new());
        run_world_variants(&worlds, seed, &|i, s| {
            got.lock().unwrap().push((i, s.expect("maps")));
        })
        .expect("simulates");
        let mut got = got.into_inner().unwrap();
        got.sort_by_key(|(i, _)| *i);
        assert_eq!(got.len(), 2);
        let without_timings = |s: &Summary| {
            let mut v = serde_json::to_value(s).unwrap();
            v.as_object_mut().unwrap().remove("timings");
            v
        };
        for (i, shared) in &got {
            let opts = RunOptions {
                seed,
                out: None,
                trajectories: None,
                progress: None,
                alongside: Alongside::Off,
            };
            let (_, own) = run_world(&worlds[*i], &opts).expect("runs");
            assert_eq!(
                without_timings(shared),
                without_timings(&own.summary),
                "world {i}"
            );
        }
        let simulation = |k: usize| got[k].1.timings["simulation"];
        assert!(simulation(0) > 0.0);
        assert_eq!(simulation(0), simulation(1));
    }
}
