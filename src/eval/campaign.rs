//! Evaluation campaigns (`swarmmap eval`): every world × parameter combination × seed is
//! simulated, mapped and scored against its ground truth, in parallel.
//!
//! Each finished run is stored as `DIR/runs/<key>.json` (its `summary.json` plus its
//! parameters), written atomically, so an interrupted campaign resumes where it stopped:
//! rerunning into the same directory skips every run whose file exists. A failing run is
//! recorded with its error and the others go on. `DIR/eval.csv` has one row per run.

use crate::io::write_atomic;
use crate::mapping::output::Summary;
use crate::pipeline::{RunOptions, run_world};
use crate::world::{WorldSpec, apply_override};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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

    /// A file-name key that changes with the world's text, the overrides and the seed.
    pub fn key(&self, world_text: &str) -> String {
        run_key(
            &self.world,
            &[world_text.as_bytes(), self.params().as_bytes()],
            self.seed,
        )
    }
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
}

fn run_one(job: &Job, text: &str) -> RunRecord {
    let name = job.world.display().to_string();
    let result = (|| -> Result<Summary, String> {
        let mut spec = crate::world::parse_str(text, &name).map_err(|e| e.to_string())?;
        for (p, v) in &job.overrides {
            apply_override(&mut spec, p, v).map_err(|e| e.to_string())?;
        }
        apply_override(&mut spec, "seed", &job.seed.to_string()).map_err(|e| e.to_string())?;
        let world = WorldSpec::check(spec).map_err(|e| e.to_string())?;
        let opts = RunOptions {
            seed: job.seed,
            out: None,
            trajectories: None,
            progress: None,
            alongside: false,
        };
        let (_, mapped) = run_world(&world, &opts).map_err(|e| e.to_string())?;
        Ok(mapped.summary)
    })();
    let world = job
        .world
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("world")
        .to_string();
    match result {
        Ok(s) => RunRecord {
            world: s.world.clone(),
            world_file: name,
            params: job.params(),
            seed: job.seed,
            summary: serde_json::to_value(&s).ok(),
            error: None,
        },
        Err(e) => RunRecord {
            world,
            world_file: name,
            params: job.params(),
            seed: job.seed,
            summary: None,
            error: Some(e),
        },
    }
}

/// Runs every job not yet recorded in `dir/runs/`, `jobs` at a time, calling `tick`
/// after each; returns all records (old and new) sorted by world, params, seed.
pub fn run_campaign(
    jobs: &[Job],
    dir: &Path,
    threads: usize,
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(std::io::Error::other)?;
    let records: Vec<std::io::Result<RunRecord>> = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let text = &texts[&job.world];
                let path = runs.join(format!("{}.json", job.key(text)));
                if let Ok(old) = std::fs::read_to_string(&path)
                    && let Ok(rec) = serde_json::from_str::<RunRecord>(&old)
                {
                    tick(&rec);
                    return Ok(rec);
                }
                let rec = run_one(job, text);
                let mut bytes = serde_json::to_vec_pretty(&rec).map_err(std::io::Error::other)?;
                bytes.push(b'\n');
                write_atomic(&path, &bytes)?;
                tick(&rec);
                Ok(rec)
            })
            .collect()
    });
    let mut out = records.into_iter().collect::<std::io::Result<Vec<_>>>()?;
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

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
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
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.3},{},{},{},{},{},{},{}\n",
            r.world,
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
            mean(&s.spearman),
            mean(&s.procrustes),
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

/// The accuracy table: one line per (world, params), aggregated over seeds.
pub fn table(records: &[RunRecord]) -> String {
    let mut groups: BTreeMap<(String, String), Vec<&RunRecord>> = BTreeMap::new();
    for r in records {
        groups
            .entry((r.world.clone(), r.params.clone()))
            .or_default()
            .push(r);
    }
    let mut out = String::from(
        "world        params                          runs fail  windows ok  β0 ok   β1 ok   holes ok  no-hole ok  oracle ok  conn ok   global ok  glob. holes  spearman  procr.  s/run\n",
    );
    let pct = |a: usize, b: usize| {
        if b == 0 {
            "    -".to_string()
        } else {
            format!("{:>5.1}%", 100.0 * a as f64 / b as f64)
        }
    };
    for ((world, params), rs) in &groups {
        let fails = rs.iter().filter(|r| r.summary.is_none()).count();
        let scores: Vec<Score> = rs
            .iter()
            .filter_map(|r| r.summary.as_ref())
            .map(score)
            .collect();
        let sum = |f: fn(&Score) -> usize| scores.iter().map(f).sum::<usize>();
        let (w, wok) = (sum(|s| s.windows), sum(|s| s.windows_ok));
        let sp: Vec<f64> = scores.iter().flat_map(|s| s.spearman.clone()).collect();
        let pr: Vec<f64> = scores.iter().flat_map(|s| s.procrustes.clone()).collect();
        let times: Vec<f64> = scores.iter().map(|s| s.time).collect();
        out.push_str(&format!(
            "{:<12} {:<31} {:>4} {:>4}  {:>10}  {:>6}  {:>6}  {:>8}  {:>10}  {:>9}  {:>7}  {:>9}  {:>11}  {:>8.2}  {:>6.3}  {:>5.1}\n",
            world,
            if params.is_empty() { "(defaults)" } else { params },
            rs.len(),
            fails,
            pct(wok, w),
            pct(sum(|s| s.b0_ok), w),
            pct(sum(|s| s.b1_ok), w),
            pct(sum(|s| s.holes_ok), sum(|s| s.hole_checks)),
            pct(sum(|s| s.holeless_ok), sum(|s| s.holeless)),
            pct(sum(|s| s.oracle_ok), sum(|s| s.oracle)),
            pct(sum(|s| s.connections_ok), sum(|s| s.connections)),
            pct(scores.iter().filter(|s| s.global_ok).count(), scores.len()),
            pct(
                scores.iter().filter(|s| s.global_holes_ok == Some(true)).count(),
                scores.iter().filter(|s| s.global_holes_ok.is_some()).count(),
            ),
            mean(&sp),
            mean(&pr),
            mean(&times),
        ));
    }
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

#[cfg(test)]
mod tests {
    use super::*;

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
