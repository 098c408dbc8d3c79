//! Evaluation campaigns (`swarmmap eval`): every world × parameter combination × seed is
//! simulated, mapped and scored against its ground truth, in parallel.
//!
//! Each finished run is stored as `DIR/runs/<key>.json` (its `summary.json` plus its
//! parameters), written atomically, so an interrupted campaign resumes where it stopped:
//! rerunning into the same directory skips every run whose file exists. The key changes
//! with the world's text, the overrides, the seed and the models given with `--model`
//! ([`Job::key`]), not with swarmmap's own code: after changing the mapping, use a new
//! directory. A failing run is recorded with its error and the others go on.
//! `DIR/eval.csv` has one row per run, `DIR/summary.csv` one per world and parameters.

use crate::io::write_atomic;
use crate::mapping::output::Summary;
use crate::pipeline::{run_world_variants, same_simulation};
use crate::world::{World, WorldSpec, apply_override};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One run of a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    pub world: PathBuf,
    /// `(path, value)` overrides, in order.
    pub overrides: Vec<(String, String)>,
    pub seed: u64,
}

impl Job {
    /// The parameters as `path=value;…` (empty for none).
    pub fn params(&self) -> String {
        self.overrides
            .iter()
            .map(|(p, v)| format!("{p}={v}"))
            .collect::<Vec<_>>()
            .join(";")
    }

    /// A file-name key that changes with the world's text, the overrides, the seed and
    /// `models`: the classifier models the run is judged with, when they are not the
    /// shipped ones (`--model FILE`; [`models_part`]). Runs judged with the shipped models
    /// keep the keys they had before models were part of it. (The build that made a run is
    /// recorded in it, [`RunRecord::build`], not in its key: a new build replaces the file.)
    pub fn key(&self, world_text: &str, models: Option<&[u8]>) -> String {
        let params = self.params();
        let mut parts = vec![world_text.as_bytes(), params.as_bytes()];
        parts.extend(models);
        run_key(&self.world, &parts, self.seed)
    }
}

/// What a stored run's key takes from the models this process judges with: `None` for the
/// shipped models, else their JSON. A window's robust holes, and so every score, depend on
/// the model, so a campaign rerun with `--model FILE` into a directory of runs judged by
/// other models must not reuse them.
pub fn models_part() -> Option<Vec<u8>> {
    use crate::mapping::classify::Models;
    let active = Models::active();
    // Plain data (numbers and strings; a non-finite number becomes `null`), so serializing
    // cannot fail.
    (active != Models::shipped())
        .then(|| serde_json::to_vec(&active).expect("classifier models serialize to JSON"))
}

/// The identity of this build of swarmmap: the SHA-256 of the running executable, in hex,
/// read once. Stored runs (`eval`'s `DIR/runs/`, `calibrate --runs`) record it, since they
/// hold what this build's simulation and mapping made: another build (an upgrade, a change
/// to the code) runs them again instead of reusing what it would not have made, unless the
/// user asks to reuse runs of any build.
pub fn build_id() -> std::io::Result<&'static str> {
    static ID: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    if let Some(id) = ID.get() {
        return Ok(id);
    }
    use std::io::Read;
    let mut file = std::fs::File::open(std::env::current_exe()?)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        match file.read(&mut buf)? {
            0 => break,
            n => h.update(&buf[..n]),
        }
    }
    let hex: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    Ok(ID.get_or_init(|| hex))
}

/// A stored run's file-name key, `<world stem>-<12 hex digits>-s<seed>`: the hex digits are
/// the start of the SHA-256 of `parts` (the world's text and whatever else the stored
/// result depends on), so changing any of them names another file.
pub fn run_key(world: &Path, parts: &[&[u8]], seed: u64) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update(p);
    }
    let digest = h.finalize();
    let hex: String = digest[..6].iter().map(|b| format!("{b:02x}")).collect();
    let stem = world
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("world");
    format!("{stem}-{hex}-s{seed}")
}

/// Expands `--set path=v1,v2` sweeps into every combination (the cartesian product, in
/// the order given).
pub fn combinations(sweeps: &[(String, Vec<String>)]) -> Vec<Vec<(String, String)>> {
    let mut out = vec![Vec::new()];
    for (path, values) in sweeps {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                values.iter().map(move |v| {
                    let mut c = prefix.clone();
                    c.push((path.clone(), v.clone()));
                    c
                })
            })
            .collect();
    }
    out
}

/// What is stored for each finished run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunRecord {
    pub world: String,
    pub world_file: String,
    pub params: String,
    pub seed: u64,
    /// The run's summary (absent if it failed).
    pub summary: Option<serde_json::Value>,
    pub error: Option<String>,
    /// The build of swarmmap that made the run ([`build_id`]); absent in runs stored before
    /// builds were recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build: Option<String>,
}

/// A job's world: its file's text with the job's overrides and seed, checked.
fn job_world(job: &Job, text: &str) -> Result<World, String> {
    let name = job.world.display().to_string();
    let mut spec = crate::world::parse_str(text, &name).map_err(|e| e.to_string())?;
    for (p, v) in &job.overrides {
        apply_override(&mut spec, p, v).map_err(|e| e.to_string())?;
    }
    apply_override(&mut spec, "seed", &job.seed.to_string()).map_err(|e| e.to_string())?;
    WorldSpec::check(spec).map_err(|e| e.to_string())
}

/// The record of `job`, labelled by its world's name (`label`, else the file's stem).
fn record(job: &Job, label: Option<String>, result: Result<Summary, String>) -> RunRecord {
    let name = job.world.display().to_string();
    let world = label.unwrap_or_else(|| {
        job.world
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("world")
            .to_string()
    });
    let (summary, error) = match result {
        Ok(s) => (serde_json::to_value(&s).ok(), None),
        Err(e) => (None, Some(e)),
    };
    RunRecord {
        world,
        world_file: name,
        params: job.params(),
        seed: job.seed,
        summary,
        error,
        build: None,
    }
}

/// Jobs to run that simulate alike ([`same_simulation`]): one simulation, mapped once per
/// job ([`run_world_variants`]).
struct SimGroup<'a> {
    seed: u64,
    /// Each job, where its record goes, and its world.
    members: Vec<(&'a Job, PathBuf, World)>,
}

/// Runs every job not yet recorded in `dir/runs/`, `jobs` at a time, calling `tick`
/// after each; returns all records (old and new) sorted by world, params, seed. With
/// `build` (this build, [`build_id`]), a run recorded by another build, or by none, counts
/// as not recorded and is run again; with `None`, any recorded run is reused.
///
/// Jobs that differ only in `mapping.*` settings (same world file, seed and other
/// overrides) share one simulation: the simulator reads no mapping setting, so each job's
/// summary is the one its own simulation would give, and a sweep of mapping settings costs
/// one simulation per seed, not one per value. Their `timings` each hold that simulation's
/// time. Jobs whose parameter sets give the very same world share their mapping too.
pub fn run_campaign(
    jobs: &[Job],
    dir: &Path,
    threads: usize,
    build: Option<&str>,
    tick: &(dyn Fn(&RunRecord) + Sync),
) -> std::io::Result<Vec<RunRecord>> {
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs)?;
    let mut texts = BTreeMap::new();
    for j in jobs {
        if !texts.contains_key(&j.world) {
            texts.insert(j.world.clone(), std::fs::read_to_string(&j.world)?);
        }
    }
    let models = models_part();
    let store = |rec: RunRecord, path: &Path| -> std::io::Result<RunRecord> {
        let rec = RunRecord {
            build: build.map(String::from),
            ..rec
        };
        let mut bytes = serde_json::to_vec_pretty(&rec).map_err(std::io::Error::other)?;
        bytes.push(b'\n');
        write_atomic(path, &bytes)?;
        tick(&rec);
        Ok(rec)
    };
    let mut out = Vec::new();
    let mut groups: Vec<SimGroup> = Vec::new();
    // The groups of each seed, so that finding a job's group scans only its seed's.
    let mut by_seed: HashMap<u64, Vec<usize>> = HashMap::new();
    for job in jobs {
        let text = &texts[&job.world];
        let path = runs.join(format!("{}.json", job.key(text, models.as_deref())));
        if let Ok(old) = std::fs::read_to_string(&path)
            && let Ok(rec) = serde_json::from_str::<RunRecord>(&old)
            && (build.is_none() || rec.build.as_deref() == build)
        {
            tick(&rec);
            out.push(rec);
            continue;
        }
        match job_world(job, text) {
            Err(e) => out.push(store(record(job, None, Err(e)), &path)?),
            Ok(world) => {
                let of_seed = by_seed.entry(job.seed).or_default();
                let shared = of_seed
                    .iter()
                    .copied()
                    .find(|&g| same_simulation(&groups[g].members[0].2, &world));
                match shared {
                    Some(g) => groups[g].members.push((job, path, world)),
                    None => {
                        of_seed.push(groups.len());
                        groups.push(SimGroup {
                            seed: job.seed,
                            members: vec![(job, path, world)],
                        });
                    }
                }
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.clamp(1, jobs.len().max(1)))
        .build()
        .map_err(std::io::Error::other)?;
    let stored = Mutex::new(Vec::new());
    pool.install(|| {
        groups.par_iter().for_each(|g| {
            // Parameter sets that give one world (`eval` warns of them) are mapped once.
            let mut worlds: Vec<&World> = Vec::new();
            let which: Vec<usize> = g
                .members
                .iter()
                .map(|(_, _, w)| {
                    worlds.iter().position(|u| *u == w).unwrap_or_else(|| {
                        worlds.push(w);
                        worlds.len() - 1
                    })
                })
                .collect();
            // Each job is stored as soon as its world is mapped.
            let finished = |u: usize, result: Result<Summary, String>| {
                for ((job, path, world), _) in
                    g.members.iter().zip(&which).filter(|(_, w)| **w == u)
                {
                    let rec = store(record(job, Some(world.name.clone()), result.clone()), path);
                    stored.lock().unwrap_or_else(|e| e.into_inner()).push(rec);
                }
            };
            let unique: Vec<World> = worlds.iter().map(|w| (*w).clone()).collect();
            let simulated = run_world_variants(&unique, g.seed, &|u, result| {
                finished(u, result.map_err(|e| e.to_string()));
            });
            if let Err(e) = simulated {
                for u in 0..unique.len() {
                    finished(u, Err(e.to_string()));
                }
            }
        });
    });
    for rec in stored.into_inner().unwrap_or_else(|e| e.into_inner()) {
        out.push(rec?);
    }
    out.sort_by(|a, b| {
        (a.world_file.as_str(), a.params.as_str(), a.seed).cmp(&(
            b.world_file.as_str(),
            b.params.as_str(),
            b.seed,
        ))
    });
    Ok(out)
}

/// Scores of one run, from its summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Score {
    pub windows: usize,
    pub windows_ok: usize,
    pub b0_ok: usize,
    pub b1_ok: usize,
    /// Windows whose truth has no hole, and how many of them the map shows without one.
    pub holeless: usize,
    pub holeless_ok: usize,
    /// Windows with a truth-position oracle (`fidelity.oracle`), and how many of those
    /// oracles equal the truth.
    pub oracle: usize,
    pub oracle_ok: usize,
    /// Windows with a hole check (`holes`), and how many of them found exactly the
    /// truth's obstacles ([`crate::eval::HoleCheck::right`]).
    pub hole_checks: usize,
    pub holes_ok: usize,
    pub connections: usize,
    pub connections_ok: usize,
    pub global_ok: bool,
    /// Whether the global map's holes are exactly the arena's obstacles
    /// ([`crate::eval::HoleCheck::right_with_gluing`]); `None` without a hole check.
    pub global_holes_ok: Option<bool>,
    pub spearman: Vec<f64>,
    pub procrustes: Vec<f64>,
    pub time: f64,
    pub window_betti: String,
    pub window_truth: String,
    pub window_oracle: String,
    /// Per window with a hole check: obstacles found / obstacles in the truth, and `+k`
    /// for k robust holes that encircle no obstacle (or one already found).
    pub window_holes: String,
    pub global: String,
    pub global_truth: String,
}

fn pair(v: &serde_json::Value) -> Option<[u64; 2]> {
    Some([v.get(0)?.as_u64()?, v.get(1)?.as_u64()?])
}

/// Scores a stored summary.
pub fn score(summary: &serde_json::Value) -> Score {
    let mut s = Score::default();
    let (mut est, mut tru, mut ora, mut hol) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for w in summary["windows"].as_array().into_iter().flatten() {
        let (Some(b), t) = (pair(&w["betti"]), pair(&w["truth"])) else {
            continue;
        };
        est.push(format!("{}:{}", b[0], b[1]));
        if let Some(t) = t {
            tru.push(format!("{}:{}", t[0], t[1]));
            s.windows += 1;
            s.windows_ok += usize::from(b == t);
            s.b0_ok += usize::from(b[0] == t[0]);
            s.b1_ok += usize::from(b[1] == t[1]);
            if t[1] == 0 {
                s.holeless += 1;
                s.holeless_ok += usize::from(b[1] == 0);
            }
            if let Some(o) = pair(&w["fidelity"]["oracle"]) {
                ora.push(format!("{}:{}", o[0], o[1]));
                s.oracle += 1;
                s.oracle_ok += usize::from(o == t);
            }
            if let Ok(h) = serde_json::from_value::<crate::eval::HoleCheck>(w["holes"].clone()) {
                s.hole_checks += 1;
                s.holes_ok += usize::from(h.right());
                let extra = h.spurious();
                hol.push(if extra > 0 {
                    format!("{}/{}+{extra}", h.matched(), h.truth.len())
                } else {
                    format!("{}/{}", h.matched(), h.truth.len())
                });
            }
        }
        if let Some(x) = w["fidelity"]["spearman"].as_f64() {
            s.spearman.push(x);
        }
        if let Some(x) = w["fidelity"]["procrustes"].as_f64() {
            s.procrustes.push(x);
        }
    }
    for c in summary["connections"].as_array().into_iter().flatten() {
        if let (Some(n), Some(t)) = (c["count"].as_u64(), c["truth"].as_u64()) {
            s.connections += 1;
            s.connections_ok += usize::from(n == t);
        }
    }
    let g = &summary["global"];
    if let (Some(b), Some(t)) = (pair(&g["betti"]), pair(&g["truth"])) {
        s.global_ok = b == t;
        s.global = format!("{}:{}", b[0], b[1]);
        s.global_truth = format!("{}:{}", t[0], t[1]);
    }
    if let Ok(h) = serde_json::from_value::<crate::eval::HoleCheck>(g["holes"].clone()) {
        let gluing = g["gluing_cycles"].as_u64().unwrap_or(0) as usize;
        s.global_holes_ok = Some(h.right_with_gluing(gluing));
    }
    s.time = summary["timings"]
        .as_object()
        .map(|m| m.values().filter_map(|v| v.as_f64()).sum())
        .unwrap_or(0.0);
    s.window_betti = est.join(" ");
    s.window_truth = tru.join(" ");
    s.window_oracle = ora.join(" ");
    s.window_holes = hol.join(" ");
    s
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// A mean with `digits` decimals, or `none` where there is nothing to average (a run
/// whose windows have no fidelity: no truth, or no events): an empty CSV field, `-` in the
/// table, never `NaN`.
fn shown_mean(v: &[f64], digits: usize, none: &str) -> String {
    mean(v).map_or_else(|| none.to_string(), |m| format!("{m:.digits$}"))
}

/// `eval.csv`: one row per run.
pub fn csv(records: &[RunRecord]) -> String {
    let mut out = String::from(
        "world,params,seed,windows,windows_ok,b0_ok,b1_ok,holeless,holeless_ok,oracle_ok,\
         connections,connections_ok,global,global_truth,global_ok,spearman,procrustes,seconds,\
         window_betti,window_truth,window_oracle,holes_ok,window_holes,global_holes_ok,error\n",
    );
    for r in records {
        let s = r.summary.as_ref().map(score).unwrap_or_default();
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{}\n",
            quote(&r.world),
            quote(&r.params),
            r.seed,
            s.windows,
            s.windows_ok,
            s.b0_ok,
            s.b1_ok,
            s.holeless,
            s.holeless_ok,
            s.oracle_ok,
            s.connections,
            s.connections_ok,
            s.global,
            s.global_truth,
            u8::from(s.global_ok),
            shown_mean(&s.spearman, 4, ""),
            shown_mean(&s.procrustes, 4, ""),
            s.time,
            s.window_betti,
            s.window_truth,
            s.window_oracle,
            s.holes_ok,
            s.window_holes,
            s.global_holes_ok
                .map_or(String::new(), |b| u8::from(b).to_string()),
            quote(r.error.as_deref().unwrap_or("")),
        ));
    }
    out
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A (world, params) group of a campaign, aggregated over its seeds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Group {
    pub world: String,
    pub params: String,
    /// Runs, and how many of them failed (no summary).
    pub runs: usize,
    pub failed: usize,
    /// The counts of [`Score`], summed over the group's runs.
    pub sum: Score,
    /// Runs with a global truth, and how many of them got the global (β0, β1) right.
    pub global_runs: usize,
    pub global_ok: usize,
    /// Runs with a global hole check, and how many of them passed it.
    pub global_holes_runs: usize,
    pub global_holes_ok: usize,
    /// Per seed: whether its global map was right (runs with a global truth only).
    pub global_by_seed: BTreeMap<u64, bool>,
    pub seconds: Vec<f64>,
}

/// Groups the records by (world, params), in that order.
pub fn groups(records: &[RunRecord]) -> Vec<Group> {
    let mut by: BTreeMap<(String, String), Group> = BTreeMap::new();
    for r in records {
        let g = by
            .entry((r.world.clone(), r.params.clone()))
            .or_insert_with(|| Group {
                world: r.world.clone(),
                params: r.params.clone(),
                ..Group::default()
            });
        g.runs += 1;
        let Some(summary) = r.summary.as_ref() else {
            g.failed += 1;
            continue;
        };
        let s = score(summary);
        let t = &mut g.sum;
        t.windows += s.windows;
        t.windows_ok += s.windows_ok;
        t.b0_ok += s.b0_ok;
        t.b1_ok += s.b1_ok;
        t.holeless += s.holeless;
        t.holeless_ok += s.holeless_ok;
        t.oracle += s.oracle;
        t.oracle_ok += s.oracle_ok;
        t.hole_checks += s.hole_checks;
        t.holes_ok += s.holes_ok;
        t.connections += s.connections;
        t.connections_ok += s.connections_ok;
        t.spearman.extend_from_slice(&s.spearman);
        t.procrustes.extend_from_slice(&s.procrustes);
        if !s.global_truth.is_empty() {
            g.global_runs += 1;
            g.global_ok += usize::from(s.global_ok);
            g.global_by_seed.insert(r.seed, s.global_ok);
        }
        if let Some(ok) = s.global_holes_ok {
            g.global_holes_runs += 1;
            g.global_holes_ok += usize::from(ok);
        }
        g.seconds.push(s.time);
    }
    by.into_values().collect()
}

/// The accuracy table: one line per (world, params), aggregated over seeds, then each
/// group's global figure with its 95 % Wilson interval and, for a world run with several
/// parameter sets, their paired comparisons ([`confidence`]).
pub fn table(records: &[RunRecord]) -> String {
    let groups = groups(records);
    let labels = Labels::of(&groups);
    let (ww, pw) = (labels.world_width, labels.params_width);
    let mut out = labels.preamble();
    out.push_str(&format!(
        "{:<ww$} {:<pw$} runs fail  windows ok  β0 ok   β1 ok   holes ok  no-hole ok  oracle ok  conn ok   global ok  glob. holes  spearman  procr.  s/run\n",
        "world", "params"
    ));
    for (g, label) in groups.iter().zip(&labels.params) {
        let s = &g.sum;
        out.push_str(&format!(
            "{:<ww$} {:<pw$} {:>4} {:>4}  {:>10}  {:>6}  {:>6}  {:>8}  {:>10}  {:>9}  {:>7}  {:>9}  {:>11}  {:>8}  {:>6}  {:>5.1}\n",
            g.world,
            label,
            g.runs,
            g.failed,
            pct(s.windows_ok, s.windows),
            pct(s.b0_ok, s.windows),
            pct(s.b1_ok, s.windows),
            pct(s.holes_ok, s.hole_checks),
            pct(s.holeless_ok, s.holeless),
            pct(s.oracle_ok, s.oracle),
            pct(s.connections_ok, s.connections),
            pct(g.global_ok, g.global_runs),
            pct(g.global_holes_ok, g.global_holes_runs),
            shown_mean(&s.spearman, 2, "-"),
            shown_mean(&s.procrustes, 3, "-"),
            mean(&g.seconds).unwrap_or(0.0),
        ));
    }
    out.push_str(&confidence(&groups));
    for r in records.iter().filter(|r| r.error.is_some()) {
        out.push_str(&format!(
            "failed: {} [{}] seed {}: {}\n",
            r.world_file,
            r.params,
            r.seed,
            r.error.as_deref().unwrap_or("")
        ));
    }
    out
}

/// How the table names its groups: the `--set` values every group shares are printed once
/// above it, and each row shows only its own (a sweep's values), so a long list of fixed
/// overrides does not push the figures out of line.
struct Labels {
    /// `path=value` settings of every group, in the order of the first group's.
    common: Vec<String>,
    /// Per group: its other settings joined by `;`, `(defaults)` for a group without
    /// settings, or `(settings above)` when all of its settings are common.
    params: Vec<String>,
    world_width: usize,
    params_width: usize,
}

impl Labels {
    fn of(groups: &[Group]) -> Self {
        let split = |p: &str| -> Vec<String> {
            p.split(';')
                .filter(|x| !x.is_empty())
                .map(str::to_string)
                .collect()
        };
        let sets: Vec<Vec<String>> = groups.iter().map(|g| split(&g.params)).collect();
        let common: Vec<String> = match sets.first() {
            Some(first) => first
                .iter()
                .filter(|kv| sets.iter().all(|s| s.contains(kv)))
                .cloned()
                .collect(),
            None => Vec::new(),
        };
        let params: Vec<String> = sets
            .iter()
            .map(|set| {
                let own: Vec<&str> = set
                    .iter()
                    .filter(|kv| !common.contains(kv))
                    .map(String::as_str)
                    .collect();
                if !own.is_empty() {
                    own.join(";")
                } else if set.is_empty() {
                    "(defaults)".to_string()
                } else {
                    "(settings above)".to_string()
                }
            })
            .collect();
        let world_width = groups
            .iter()
            .map(|g| g.world.chars().count())
            .fold(12, usize::max);
        let params_width = params
            .iter()
            .map(|p| p.chars().count())
            .fold(31, usize::max);
        Self {
            common,
            params,
            world_width,
            params_width,
        }
    }

    /// `settings of every run: a=1; b=2` and a newline, or nothing.
    fn preamble(&self) -> String {
        if self.common.is_empty() {
            String::new()
        } else {
            format!("settings of every run: {}\n", self.common.join("; "))
        }
    }
}

fn pct(a: usize, b: usize) -> String {
    if b == 0 {
        "    -".to_string()
    } else {
        format!("{:>5.1}%", 100.0 * a as f64 / b as f64)
    }
}

/// A world with at most this many pairs of parameter sets has every pair compared; with
/// more, each set is compared with the first (in the table's order) only.
const MAX_PAIRS: usize = 15;

/// How sure the global figures are ([`crate::eval::stats`]): each group's global (β0, β1)
/// right in k of n runs with its 95 % Wilson interval, and, for every world run with
/// several parameter sets, pairs of them compared on the seeds both ran (the seeds right
/// under one only, and the exact McNemar p-value; every pair up to [`MAX_PAIRS`], else each
/// set against the first). Failed runs have no map and are left out, as in the table. Empty
/// when no run has a global truth. Window shares get no interval: one run's windows are not
/// independent draws.
pub fn confidence(groups: &[Group]) -> String {
    use crate::eval::stats::{Z95, mcnemar_exact, wilson};
    let mut out = String::new();
    let labels = Labels::of(groups);
    // Each group with a global truth, with its table label.
    let with_truth: Vec<(&Group, &str)> = groups
        .iter()
        .zip(&labels.params)
        .filter(|(g, _)| g.global_runs > 0)
        .map(|(g, l)| (g, l.as_str()))
        .collect();
    if with_truth.is_empty() {
        return out;
    }
    let (ww, pw) = (labels.world_width, labels.params_width);
    out.push_str("global ok over independent runs (failed runs left out), 95% Wilson interval:\n");
    for &(g, label) in &with_truth {
        let (lo, hi) = wilson(g.global_ok, g.global_runs, Z95).unwrap_or((0.0, 1.0));
        out.push_str(&format!(
            "  {:<ww$} {:<pw$} {:>4} of {:<4} {:>6}  [{:.1}%, {:.1}%]\n",
            g.world,
            label,
            g.global_ok,
            g.global_runs,
            pct(g.global_ok, g.global_runs),
            100.0 * lo,
            100.0 * hi
        ));
    }
    let mut by_world: BTreeMap<&str, Vec<(&Group, &str)>> = BTreeMap::new();
    for &(g, label) in &with_truth {
        by_world
            .entry(g.world.as_str())
            .or_default()
            .push((g, label));
    }
    let mut lines = String::new();
    for (world, gs) in by_world.iter().filter(|(_, gs)| gs.len() > 1) {
        let all = gs.len() * (gs.len() - 1) / 2 <= MAX_PAIRS;
        if !all {
            lines.push_str(&format!(
                "  {world}: {} parameter sets, each compared with the first only\n",
                gs.len()
            ));
        }
        for i in 0..gs.len() {
            for j in i + 1..gs.len() {
                if !all && i > 0 {
                    continue;
                }
                let ((a, label_a), (b, label_b)) = (gs[i], gs[j]);
                let (mut common, mut only_a, mut only_b) = (0, 0, 0);
                for (seed, ok_a) in &a.global_by_seed {
                    if let Some(ok_b) = b.global_by_seed.get(seed) {
                        common += 1;
                        only_a += usize::from(*ok_a && !ok_b);
                        only_b += usize::from(*ok_b && !ok_a);
                    }
                }
                lines.push_str(&format!(
                    "  {world}: {} vs {}: {common} common seeds",
                    label_a, label_b,
                ));
                if common > 0 {
                    lines.push_str(&format!(
                        ", right only with the first on {only_a}, only with the second on {only_b}, {}",
                        p_value(mcnemar_exact(only_a, only_b))
                    ));
                }
                lines.push('\n');
            }
        }
    }
    if !lines.is_empty() {
        out.push_str(
            "global ok, paired by seed (exact McNemar test; p per pair, not corrected for multiple comparisons):\n",
        );
        out.push_str(&lines);
    }
    out
}

/// `p = 0.0625` (four decimals), or `p < 0.0001`.
fn p_value(p: f64) -> String {
    if p < 1e-4 {
        "p < 0.0001".to_string()
    } else {
        format!("p = {p:.4}")
    }
}

/// `summary.csv`: one row per (world, params), the counts behind the table and the global
/// figure's 95 % Wilson interval (`global_low`, `global_high`, shares from 0 to 1; empty
/// without a run with a global truth).
pub fn summary_csv(groups: &[Group]) -> String {
    use crate::eval::stats::{Z95, wilson};
    let mut out = String::from(
        "world,params,runs,failed,windows,windows_ok,b0_ok,b1_ok,hole_checks,holes_ok,\
         holeless,holeless_ok,oracle,oracle_ok,connections,connections_ok,global_runs,\
         global_ok,global_low,global_high,global_holes_runs,global_holes_ok,spearman,\
         procrustes,seconds\n",
    );
    for g in groups {
        let s = &g.sum;
        let (lo, hi) = wilson(g.global_ok, g.global_runs, Z95)
            .map_or((String::new(), String::new()), |(l, h)| {
                (format!("{l:.4}"), format!("{h:.4}"))
            });
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3}\n",
            quote(&g.world),
            quote(&g.params),
            g.runs,
            g.failed,
            s.windows,
            s.windows_ok,
            s.b0_ok,
            s.b1_ok,
            s.hole_checks,
            s.holes_ok,
            s.holeless,
            s.holeless_ok,
            s.oracle,
            s.oracle_ok,
            s.connections,
            s.connections_ok,
            g.global_runs,
            g.global_ok,
            lo,
            hi,
            g.global_holes_runs,
            g.global_holes_ok,
            shown_mean(&s.spearman, 4, ""),
            shown_mean(&s.procrustes, 4, ""),
            mean(&g.seconds).unwrap_or(0.0),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_change_with_the_models_only_when_given() {
        let job = Job {
            world: PathBuf::from("worlds/w.ron"),
            overrides: vec![("a".into(), "1".into())],
            seed: 3,
        };
        let plain = job.key("(name: \"w\")", None);
        // The shipped models add nothing: keys stored before models were part of it stay.
        let before = run_key(&job.world, &[b"(name: \"w\")", b"a=1"], 3);
        assert_eq!(plain, before);
        assert!(plain.starts_with("w-") && plain.ends_with("-s3"), "{plain}");
        let m1 = job.key("(name: \"w\")", Some(b"{\"m\":1}"));
        let m2 = job.key("(name: \"w\")", Some(b"{\"m\":2}"));
        assert!(m1 != plain && m1 != m2, "{plain} {m1} {m2}");
        assert_eq!(models_part(), None, "tests map with the shipped models");
        // This build's identity: the test binary's SHA-256, the same each time it is asked.
        let id = build_id().unwrap();
        assert!(
            id.len() == 64 && id.bytes().all(|b| b.is_ascii_hexdigit()),
            "{id}"
        );
        assert_eq!(build_id().unwrap(), id);
    }

    #[test]
    fn sweeps_expand_to_the_cartesian_product() {
        let c = combinations(&[
            ("a".into(), vec!["1".into(), "2".into()]),
            ("b".into(), vec!["x".into()]),
        ]);
        assert_eq!(c.len(), 2);
        assert_eq!(
            c[1],
            vec![("a".into(), "2".into()), ("b".into(), "x".into())]
        );
        assert_eq!(combinations(&[]), vec![Vec::new()]);
    }

    /// A stored run of `world` with `params` and `seed` whose global map is right or not.
    fn record(world: &str, params: &str, seed: u64, right: bool) -> RunRecord {
        let b1 = if right { 2 } else { 1 };
        RunRecord {
            world: world.into(),
            world_file: format!("{world}.ron"),
            params: params.into(),
            seed,
            summary: Some(serde_json::json!({
                "windows": [{"betti": [1, b1], "truth": [1, 2]}],
                "connections": [],
                "global": {"betti": [1, b1], "truth": [1, 2]},
                "timings": {"a": 2.0}
            })),
            error: None,
            build: None,
        }
    }

    #[test]
    fn groups_give_intervals_and_paired_comparisons() {
        // Setting `s=1`: seeds 1-15 right of 20. Setting `s=2`: all 20 right. Seed 21 of
        // `s=2` failed outright; `other` has one setting, so no comparison of its own.
        let mut rs = Vec::new();
        for seed in 1..=20 {
            rs.push(record("w", "s=1", seed, seed <= 15));
            rs.push(record("w", "s=2", seed, true));
        }
        rs.push(RunRecord {
            summary: None,
            error: Some("boom".into()),
            ..record("w", "s=2", 21, true)
        });
        rs.push(record("other", "", 1, false));
        let gs = groups(&rs);
        assert_eq!(gs.len(), 3);
        let (o, a, b) = (&gs[0], &gs[1], &gs[2]);
        assert_eq!(
            (o.world.as_str(), o.global_ok, o.global_runs),
            ("other", 0, 1)
        );
        assert_eq!((a.params.as_str(), a.runs, a.failed), ("s=1", 20, 0));
        assert_eq!((a.global_ok, a.global_runs, a.sum.windows_ok), (15, 20, 15));
        assert_eq!(
            (b.runs, b.failed, b.global_ok, b.global_runs),
            (21, 1, 20, 20)
        );
        let text = confidence(&gs);
        // 15 of 20: statsmodels' Wilson interval [0.5313, 0.8881].
        assert!(text.contains("15 of 20    75.0%  [53.1%, 88.8%]"), "{text}");
        assert!(
            text.contains("20 of 20   100.0%  [83.9%, 100.0%]"),
            "{text}"
        );
        // Five seeds right only with the second setting: p = 2 / 2^5.
        assert!(
            text.contains("w: s=1 vs s=2: 20 common seeds, right only with the first on 0, only with the second on 5, p = 0.0625"),
            "{text}"
        );
        assert!(!text.contains("other: "), "{text}");
        let csv = summary_csv(&gs);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 4, "{csv}");
        assert!(lines[0].starts_with("world,params,runs,failed,windows,windows_ok,"));
        assert!(lines[2].starts_with("w,s=1,20,0,20,15,"), "{}", lines[2]);
        assert!(lines[2].contains(",20,15,0.5313,0.8881,"), "{}", lines[2]);
        assert!(lines[3].starts_with("w,s=2,21,1,"), "{}", lines[3]);
        // The table carries the same block after its rows, and the failure.
        let t = table(&rs);
        assert!(
            t.contains(&text) && t.contains("failed: w.ron [s=2] seed 21: boom"),
            "{t}"
        );
    }

    #[test]
    fn many_parameter_sets_are_compared_with_the_first_only() {
        // Seven sets give 21 pairs, over MAX_PAIRS: six comparisons, each with `s=0`.
        // `s=0` is right on seeds 1-30; the others on none: p = 2 / 2^30.
        let mut rs = Vec::new();
        for k in 0..7 {
            for seed in 1..=30 {
                rs.push(record("w", &format!("s={k}"), seed, k == 0));
            }
        }
        let text = confidence(&groups(&rs));
        assert!(
            text.contains("w: 7 parameter sets, each compared with the first only"),
            "{text}"
        );
        assert_eq!(text.matches(" vs ").count(), 6, "{text}");
        assert_eq!(text.matches("w: s=0 vs ").count(), 6, "{text}");
        assert!(
            text.contains("on 30, only with the second on 0, p < 0.0001"),
            "{text}"
        );
    }

    #[test]
    fn settings_every_group_shares_are_printed_once() {
        let rs = vec![
            record("a_long_world_name", "x=1;s=1", 1, true),
            record("a_long_world_name", "x=1;s=2", 1, false),
        ];
        let t = table(&rs);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[0], "settings of every run: x=1", "{t}");
        assert!(lines[1].starts_with("world             params "), "{t}");
        // Rows name only their own setting, and the world column fits the long name.
        assert!(lines[2].starts_with("a_long_world_name s=1 "), "{t}");
        assert!(lines[3].starts_with("a_long_world_name s=2 "), "{t}");
        assert!(
            t.contains("a_long_world_name: s=1 vs s=2: 1 common seeds"),
            "{t}"
        );
        // A lone group with settings: all of them above, none in its row.
        let t = table(&rs[..1]);
        assert!(t.starts_with("settings of every run: x=1; s=1\n"), "{t}");
        assert!(t.contains("a_long_world_name (settings above) "), "{t}");
        // No settings: no preamble, `(defaults)`.
        let t = table(&[record("w", "", 1, true)]);
        assert!(
            t.starts_with("world ") && t.contains("\nw            (defaults) "),
            "{t}"
        );
    }

    #[test]
    fn no_interval_without_a_global_truth() {
        let mut r = record("w", "", 1, true);
        r.summary = Some(serde_json::json!({"windows": [], "global": {"betti": [1, 0]}}));
        let gs = groups(&[r]);
        assert_eq!(gs[0].global_runs, 0);
        assert_eq!(confidence(&gs), "");
        assert!(summary_csv(&gs).lines().nth(1).unwrap().contains(",0,0,,,"));
    }

    #[test]
    fn no_fidelity_is_an_empty_field_and_a_dash_not_nan() {
        // Found by an adversarial pass (thirty-seventh session): a run whose windows had no
        // fidelity wrote `NaN` into eval.csv and summary.csv and printed it in the table.
        let mut r = record("w", "", 1, true);
        r.summary = Some(serde_json::json!({
            "windows": [{"betti": [0, 0], "truth": [1, 0], "fidelity": {}}],
            "global": {"betti": [0, 0], "truth": [1, 0]}
        }));
        let rows = csv(std::slice::from_ref(&r));
        let row = rows.lines().nth(1).unwrap();
        assert!(!row.contains("NaN") && row.contains(",0,,,"), "{row}");
        let gs = groups(std::slice::from_ref(&r));
        let line = summary_csv(&gs);
        assert!(
            !line.contains("NaN") && line.lines().nth(1).unwrap().contains(",,,"),
            "{line}"
        );
        let t = table(&[r]);
        assert!(!t.contains("NaN") && t.contains("       -       -"), "{t}");
    }

    #[test]
    fn scores_count_windows_connections_and_global() {
        let v = serde_json::json!({
            "windows": [
                {"betti": [1, 0], "truth": [1, 0], "fidelity": {"spearman": 0.5, "procrustes": null}},
                {"betti": [1, 1], "truth": [2, 1], "fidelity": {"oracle": [2, 1]},
                 "holes": {"truth": [[1.0, 2.0]], "found": [null]}},
            ],
            "connections": [{"count": 2, "truth": 2}, {"count": 1, "truth": 2}],
            "global": {"betti": [1, 1], "truth": [1, 1], "gluing_cycles": 1,
                       "holes": {"truth": [[1.0, 2.0], [5.0, 2.0]], "found": [1]}},
            "timings": {"a": 1.0, "b": 2.0}
        });
        let s = score(&v);
        assert_eq!((s.windows, s.windows_ok, s.b0_ok, s.b1_ok), (2, 1, 1, 2));
        assert_eq!((s.holeless, s.holeless_ok), (1, 1));
        assert_eq!((s.connections, s.connections_ok), (2, 1));
        assert!(s.global_ok);
        assert_eq!(s.time, 3.0);
        assert_eq!(s.window_betti, "1:0 1:1");
        assert_eq!((s.oracle, s.oracle_ok), (1, 1));
        assert_eq!(s.window_oracle, "2:1");
        assert_eq!((s.hole_checks, s.holes_ok), (1, 0));
        assert_eq!(s.window_holes, "0/1+1");
        assert_eq!(s.global_holes_ok, Some(true));
    }
}
