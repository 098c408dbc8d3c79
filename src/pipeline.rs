//! The pipeline of named stages (see `ARCHITECTURE.md`):
//! world → simulation → encounter log → local maps → global map → evaluation, each timed.
//!
//! `swarmmap run` calls [`run_world`]; `swarmmap map` calls [`map_log`] on a log read from
//! disk; `swarmmap eval` calls [`run_world`] for many worlds and seeds in parallel.

use crate::eval::truth::{FreeSpace, TruthError, overlap, window_band};
use crate::io::write_atomic;
use crate::log::{EncounterLog, LogError};
use crate::mapping::classify::Classifier;
use crate::mapping::local::LocalMap;
use crate::mapping::output::{
    ConnectionSummary, GlobalSummary, Summary, connection_json, window_json,
};
use crate::mapping::pipeline::{MapConfig, map_windows, summarise};
use crate::mapping::stitch::{Connection, GlobalMap, StitchParams, connect, global_map};
use crate::sim::{SimError, SimOptions, SimOutput, simulate, write_run};
use crate::world::{World, WorldError, WorldSpec};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
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
    /// The classifier the diagrams were judged with (recorded in `maps/window_<i>.json`).
    pub classifier: Classifier,
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
    let value =
        serde_json::from_str(&text).map_err(|e| meta_err(format!("not valid JSON: {e}")))?;
    Ok(Some((path, value)))
}

/// The seed a simulation ran with, from the top-level `seed` of its `meta.json` (not the
/// world's own `seed` field, which `--seed` overrides), if there is one.
pub fn seed_from_run(dir: &Path) -> Result<Option<u64>, PipelineError> {
    Ok(read_meta(dir)?.and_then(|(_, meta)| meta.get("seed").and_then(serde_json::Value::as_u64)))
}

/// Reads the world a simulation ran with from its `meta.json`, if there is one.
pub fn world_from_run(dir: &Path) -> Result<Option<World>, PipelineError> {
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
    let mut spec: WorldSpec = serde_json::from_value(world)
        .map_err(|e| meta_err(format!("its `world` is not a valid world: {e}")))?;
    spec.origin.name = format!("{} (world)", path.display());
    Ok(Some(spec.check()?))
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
    let maps = timings.time("local maps", || map_windows(log, cfg));
    let windows = cfg.windows();
    // Consecutive pairs are independent: stitch them in parallel (collected in order, so
    // the result does not depend on the number of threads).
    let connections: Vec<Connection> = timings.time("stitching", || {
        let pairs: Vec<_> = windows.windows(2).zip(maps.windows(2)).collect();
        pairs
            .par_iter()
            .map(|(w, m)| connect(log, &w[0], &w[1], &m[0], &m[1], &cfg.local, stitch))
            .collect()
    });
    let global = timings.time("stitching", || global_map(&maps, &connections, log));
    let truth = match world {
        Some(w) => Some((w, timings.time("evaluation", || FreeSpace::for_world(w))?)),
        None => None,
    };
    let (windows_summary, connections_summary, global_truth) = timings.time("evaluation", || {
        let ws = summarise(&maps, log, truth.as_ref().map(|(w, f)| (*w, f)));
        let cs = connections
            .iter()
            .zip(windows.windows(2))
            .map(|(c, w)| ConnectionSummary {
                between: c.between,
                count: c.count,
                truth: truth.as_ref().map(|(world, fs)| {
                    let a = window_band(world, w[0].start, w[0].end);
                    let b = window_band(world, w[1].start, w[1].end);
                    overlap(a, b).map_or(0, |(x0, x1)| fs.components_in_band(x0, x1))
                }),
            })
            .collect();
        let gt = truth.as_ref().map(|(_, fs)| fs.global_betti());
        (ws, cs, gt)
    });
    let summary = Summary {
        world: world.map_or_else(|| "log".to_string(), |w| w.name.clone()),
        seed,
        windows: windows_summary,
        connections: connections_summary,
        global: GlobalSummary {
            betti: global.betti,
            truth: global_truth,
            gluing_cycles: global.gluing_cycles,
        },
        timings: timings.0.clone(),
    };
    Ok(Mapped {
        maps,
        connections,
        global,
        summary,
        classifier: cfg.local.classifier,
        stitch: *stitch,
    })
}

/// Writes `maps/window_<i>.json`, `maps/connections.json`, `maps/connection_<i>.json` (one
/// per consecutive pair, named after its first window), `maps/global.json` and
/// `summary.json` into `dir`, each atomically.
pub fn write_maps(dir: &Path, log: &EncounterLog, m: &Mapped) -> Result<(), PipelineError> {
    let write = |name: String, text: String| {
        let path = dir.join(name);
        write_atomic(&path, text.as_bytes()).map_err(|source| PipelineError::Write { path, source })
    };
    for (map, s) in m.maps.iter().zip(&m.summary.windows) {
        write(
            format!("maps/window_{}.json", map.index),
            window_json(map, log, s.truth, &m.classifier),
        )?;
    }
    for c in &m.connections {
        write(
            format!("maps/connection_{}.json", c.between[0]),
            connection_json(c, log, m.stitch.cutoff),
        )?;
    }
    write("maps/connections.json".into(), to_json(&m.connections))?;
    write("maps/global.json".into(), to_json(&m.global))?;
    write("summary.json".into(), to_json(&m.summary))?;
    Ok(())
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
}

/// Simulates a world and maps its log: `swarmmap run` without the printing.
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
    let out = timings.time("simulation", || simulate(world, &sim_opts))?;
    if let Some(dir) = &opts.out {
        timings.time("writing", || write_run(dir, world, &out))?;
    }
    let cfg = MapConfig::for_world(world);
    let stitch = StitchParams {
        cutoff: world.mapping.cluster_cutoff,
        neighbours: world.mapping.neighbours,
    };
    let mapped = map_log(
        &out.log,
        Some(world),
        &cfg,
        &stitch,
        Some(opts.seed),
        &mut timings,
    )?;
    if let Some(dir) = &opts.out {
        write_maps(dir, &out.log, &mapped)?;
    }
    Ok((out, mapped))
}
