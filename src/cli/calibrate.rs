//! `swarmmap calibrate [WORLD...] [--seeds 1..5] [--set PATH=VALUE]... [--out FILE]`: fit the
//! robust-feature classifier on training worlds and write the model file.

use super::{
    Failure, apply_sets, input, load_world, refuse_repeated_worlds, reusable_build, setting_key,
};
use anyhow::{Context, anyhow};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use std::path::PathBuf;
use swarmmap::eval::calibrate::{
    CrossValidation, FitOptions, Sample, cross_validate, fit, h1_landscape,
};
use swarmmap::eval::campaign::run_key;
use swarmmap::eval::truth::{FreeSpace, window_band};
use swarmmap::io::write_atomic;
use swarmmap::mapping::classify::{Density, Feature, Model, Models};
use swarmmap::mapping::pipeline::{MapConfig, map_windows, oracle_features, true_positions};
use swarmmap::sim::{SimOptions, simulate};
use swarmmap::world::{MappingMethod, World, WorldSpec, given};

/// Options of `swarmmap calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// Training worlds (default: every `worlds/training/*.ron`). Never the evaluation
    /// scenarios: a classifier fitted on them would be judged on its own training data.
    pub worlds: Vec<PathBuf>,
    /// Seeds: `A..B` (inclusive) or a comma-separated list.
    #[arg(long, default_value = "1..5")]
    pub seeds: String,
    /// Override a field of every training world, e.g. `--set mapping.method=Embedded`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Runs in parallel (default: the number of cores; at most 1024).
    #[arg(long, value_parser = super::thread_count)]
    pub jobs: Option<usize>,
    /// Model file to update (default: `assets/classifier.json`, the model compiled into
    /// swarmmap). The fitted model replaces the models of the fitted method (or the oracle)
    /// that were fitted at a density inside its training windows' range of encounters per
    /// Rips vertex, and joins the others: a fit at another sampling adds a model to the
    /// method's bank, a refit at the same sampling replaces it. Other methods are kept.
    #[arg(long, default_value = "assets/classifier.json")]
    pub out: PathBuf,
    /// Make the fitted model the method's only one at its sweep speed, whatever the
    /// densities of the others (models fitted at other sweeps stay).
    #[arg(long)]
    pub only: bool,
    /// Fit the truth-position oracle's model instead (the `Embedded` topology stage on the
    /// events' true positions; `summary.json` `fidelity.oracle`) and replace its entry.
    #[arg(long)]
    pub oracle: bool,
    /// Fit the method's model and the oracle's from the same training runs (one
    /// simulation per world and seed instead of two).
    #[arg(long, conflicts_with = "oracle")]
    pub with_oracle: bool,
    /// Largest share of the training windows without a true hole in which the fitted model
    /// may report one; accuracy is maximised under this constraint (`1` = unconstrained).
    #[arg(long, default_value_t = swarmmap::eval::calibrate::MAX_FALSE_HOLES)]
    pub max_false_holes: f64,
    /// Also search a largest crossing share for H1 (`h1_crossing`: the share of the moving
    /// agents' time lines near a loop's void that pass through it, "Mapping"), for the
    /// `Embedded` method; a crossing test is kept only where it scores more than none.
    #[arg(long)]
    pub crossing: bool,
    /// Also search a least split stability for H1 (`h1_stability`: the life, in σ, of the
    /// weaker of the loops that the two halves of a window's encounters show at a hole's
    /// place, "Mapping"), for the `Embedded` method; implies `--set
    /// mapping.split_stability=true` for the training runs (refused with a `--set` that turns
    /// it off; nothing with `--oracle` alone, whose fit has no stability test); a stability
    /// test is kept only where it scores more than none.
    #[arg(long)]
    pub stability: bool,
    /// Also estimate the fit's accuracy on windows it was not fitted on: hold out each seed
    /// (or each world) in turn, fit on the rest under the same cap, judge the held-out
    /// windows. Repeat the option for both. The model written is still the fit on all.
    #[arg(long = "cross-validate", value_enum, value_name = "GROUPS")]
    pub cross_validate: Vec<CvGroups>,
    /// Also write the H1 grid the fit searches to this CSV, one row per grid point
    /// (h1_ratio, h1_span, and h1_crossing / h1_stability when --crossing / --stability
    /// search them) with the training windows it gets right and its false-hole share, to
    /// see how flat the optimum is and which other rules score nearly as well.
    #[arg(long, value_name = "CSV")]
    pub landscape: Option<PathBuf>,
    /// Keep each finished training run's diagrams in DIR (one JSON file per world, `--set`
    /// values and seed) and reuse them on a later call, so an interrupted or extended fit
    /// (more seeds, another cap, cross-validation) does not simulate them again. Only the
    /// runs this build of swarmmap stored are reused (another build runs them again),
    /// unless `--reuse-any-build`.
    #[arg(long, value_name = "DIR")]
    pub runs: Option<PathBuf>,
    /// With `--runs`, reuse the runs stored there whatever build of swarmmap made them.
    #[arg(long, requires = "runs")]
    pub reuse_any_build: bool,
}

/// One training run as `--runs` keeps it: per fit it fed, its windows' features, truths
/// and densities. Numbers are kept as their `f64` bits, so that a reused run fits exactly
/// the model a fresh one does (decimal JSON need not read back the same last bit); a death
/// of `None` is an essential class (JSON has no infinity).
#[derive(serde::Serialize, serde::Deserialize)]
struct StoredRun {
    world: String,
    seed: u64,
    fits: Vec<StoredFit>,
    /// The build of swarmmap that made the run (`eval::campaign::build_id`); absent in
    /// runs stored before builds were recorded. Another build's run is made again unless
    /// `--reuse-any-build`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    build: Option<String>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct StoredFit {
    oracle: bool,
    densities: Vec<u64>,
    windows: Vec<StoredWindow>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct StoredWindow {
    truth: [usize; 2],
    /// Per component: its bars.
    components: Vec<Vec<StoredBar>>,
}

/// A bar as `--runs` keeps it: `(dim, birth, death, crossing share, stability)`, numbers
/// as bits. (A file of an earlier build, without the stability, does not read as a run and
/// is run again.)
type StoredBar = (usize, u64, Option<u64>, Option<u64>, Option<u64>);

impl StoredWindow {
    fn from_sample(s: &Sample) -> Self {
        Self {
            truth: s.truth,
            components: s
                .components
                .iter()
                .map(|c| {
                    c.iter()
                        .map(|f| {
                            let death = f.death.is_finite().then_some(f.death.to_bits());
                            (
                                f.dim,
                                f.birth.to_bits(),
                                death,
                                f.crossing.map(f64::to_bits),
                                f.stability.map(f64::to_bits),
                            )
                        })
                        .collect()
                })
                .collect(),
        }
    }

    fn sample(&self) -> Sample {
        Sample {
            truth: self.truth,
            components: self
                .components
                .iter()
                .map(|c| {
                    c.iter()
                        .map(|&(dim, birth, death, crossing, stability)| Feature {
                            dim,
                            birth: f64::from_bits(birth),
                            death: death.map_or(f64::INFINITY, f64::from_bits),
                            crossing: crossing.map(f64::from_bits),
                            stability: stability.map(f64::from_bits),
                        })
                        .collect()
                })
                .collect(),
        }
    }
}

/// How `--cross-validate` groups the training windows into folds.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum CvGroups {
    /// One fold per seed: new runs of the same worlds.
    Seeds,
    /// One fold per training world: layouts the fit has never seen.
    Worlds,
}

impl CvGroups {
    /// What one fold holds out, in the printed figures.
    fn noun(self) -> &'static str {
        match self {
            CvGroups::Seeds => "seed",
            CvGroups::Worlds => "world",
        }
    }

    /// The option's value, as written on the command line.
    fn value(self) -> &'static str {
        match self {
            CvGroups::Seeds => "seeds",
            CvGroups::Worlds => "worlds",
        }
    }
}

/// Whether `a` and `b` name one file: the same path, or (both existing, or in the same
/// existing directory) the same place once links and `..` are resolved.
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    let place = |p: &std::path::Path| {
        std::fs::canonicalize(p).ok().or_else(|| {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => std::path::Path::new("."),
            };
            Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
        })
    };
    a == b || matches!((place(a), place(b)), (Some(x), Some(y)) if x == y)
}

pub fn run(args: &CalibrateArgs) -> Result<(), Failure> {
    let seeds = super::eval::parse_seeds(&args.seeds).map_err(|e| input(anyhow!(e)))?;
    super::refuse_seed_set(&args.set)?;
    if !(0.0..=1.0).contains(&args.max_false_holes) {
        return Err(input(anyhow!(
            "--max-false-holes is {}; it is a share of the hole-free training windows, from 0 to 1 (1 = unconstrained)",
            given(args.max_false_holes)
        )));
    }
    // Found before the training runs, not after them.
    if let Some(landscape) = &args.landscape
        && same_file(landscape, &args.out)
    {
        return Err(input(anyhow!(
            "--landscape {} is the --out model file too, so one would overwrite the other; give \
             the landscape its own file, e.g. landscape.csv",
            landscape.display()
        )));
    }
    for (flag, path) in [
        ("--out", Some(&args.out)),
        ("--landscape", args.landscape.as_ref()),
    ] {
        if let Some(p) = path.filter(|p| p.is_dir()) {
            return Err(input(anyhow!(
                "{flag} {} is a directory; give the file to write, e.g. {}",
                p.display(),
                p.join(if flag == "--out" {
                    "classifier.json"
                } else {
                    "landscape.csv"
                })
                .display()
            )));
        }
        // And a file that cannot be written (its directory is a file, cannot be made, or
        // is read-only) is said now, not after the fit it would hold.
        if let Some(p) = path {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => std::path::Path::new("."),
            };
            if dir.exists() && !dir.is_dir() {
                return Err(input(anyhow!(
                    "{flag} {}: {} is a file, not a directory; give a path inside a directory",
                    p.display(),
                    dir.display()
                )));
            }
            if let Err(e) = swarmmap::sim::prepare_out_dir(dir) {
                return Err(input(anyhow!("{flag} {}: {e}", p.display())));
            }
        }
    }
    // The model file the fit joins, read and checked before any training run (a bad one
    // would otherwise be found only after them, and the fit lost).
    let existing = if args.out.exists() {
        Some(Models::load(&args.out).map_err(input)?)
    } else {
        None
    };
    refuse_repeated_worlds(&args.worlds)?;
    let mut paths = args.worlds.clone();
    if paths.is_empty() {
        let dir = PathBuf::from("worlds/training");
        let entries = std::fs::read_dir(&dir)
            .with_context(|| format!("listing {}", dir.display()))
            .map_err(input)?;
        paths = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "ron"))
            .collect();
        paths.sort();
    }
    if paths.is_empty() {
        return Err(input(anyhow!(
            "no training worlds: give world files or add worlds/training/*.ron"
        )));
    }
    // `--stability` needs the bars' stabilities from the method's training runs (the
    // oracle's fit has no stability test, so `--oracle` alone leaves the sets as they are).
    // What the `--set`s ask for is read from a spec they alone fill, so
    // `mapping=(split_stability: false)` counts as much as `mapping.split_stability=false`.
    let mut set = args.set.clone();
    if args.stability && !args.oracle {
        let touches = |s: &String| {
            s.split_once('=').is_some_and(|(path, _)| {
                matches!(
                    setting_key(path).as_str(),
                    "mapping" | "mapping.split_stability"
                )
            })
        };
        let touching: Vec<String> = set.iter().filter(|s| touches(s)).cloned().collect();
        let mut asked = WorldSpec::default();
        apply_sets(&mut asked, &touching)?;
        if asked.mapping.and_then(|m| m.split_stability) == Some(false) {
            let mut off: Vec<String> = touching
                .iter()
                .filter(|s| {
                    let mut alone = WorldSpec::default();
                    apply_sets(&mut alone, std::slice::from_ref(*s)).is_ok()
                        && alone.mapping.and_then(|m| m.split_stability) == Some(false)
                })
                .map(|s| format!("`--set {s}`"))
                .collect();
            if off.is_empty() {
                off = touching.iter().map(|s| format!("`--set {s}`")).collect();
            }
            return Err(input(anyhow!(
                "--stability fits the Embedded method's stability test, which needs the \
                 training runs' stabilities, but {} turn{} them off; drop {}",
                off.join(" and "),
                if off.len() == 1 { "s" } else { "" },
                if off.len() == 1 { "it" } else { "them" }
            )));
        }
        // A field-form set that leaves the default (`=None`) or asks for `true` gives way
        // to the one appended here (two sets of one field are refused as a lost value).
        set.retain(|s| {
            s.split_once('=')
                .is_none_or(|(path, _)| setting_key(path) != "mapping.split_stability")
        });
        set.push("mapping.split_stability=true".to_string());
    }
    let worlds: Vec<World> = paths
        .iter()
        .map(|p| load_world(p, &set))
        .collect::<Result<_, _>>()?;
    // A model is tied to one sweep speed (`Bank::for_sweep`): the training runs share it.
    let sweep = worlds[0].leader.speed;
    if let Some((w, p)) = worlds
        .iter()
        .zip(&paths)
        .find(|(w, _)| w.leader.speed != sweep)
    {
        return Err(input(anyhow!(
            "the training worlds sweep at different speeds ({}: {} m/s, {}: {} m/s); a model \
             is fitted at one sweep: give them one with --set leader.speed=V",
            paths[0].display(),
            given(sweep),
            p.display(),
            given(w.leader.speed)
        )));
    }
    // A model records its sweep, not the outlier rank it was fitted at: a map at this
    // sweep uses the rank scaled with it unless its own world fixes one.
    let scaled = swarmmap::mapping::subsample::rank_for_sweep(sweep);
    if let Some((k, p)) = worlds.iter().zip(&paths).find_map(|(w, p)| {
        w.mapping
            .outlier_rank
            .filter(|&k| k != scaled)
            .map(|k| (k, p))
    }) {
        eprintln!(
            "warning: {} maps with mapping.outlier_rank {k}, but the model records only its \
             sweep ({} m/s), where maps use rank {scaled} unless their world sets the same \
             rank; fit without the setting, or give it to the worlds mapped with this model",
            p.display(),
            given(sweep)
        );
    }
    // The fits each run feeds: the method's, the oracle's, or both.
    let oracle = args.oracle;
    let mut targets = Vec::new();
    if !oracle {
        targets.push(false);
    }
    if oracle || args.with_oracle {
        targets.push(true);
    }
    // With `--runs DIR`, each job's file there: it changes with the world's text, the
    // `--set` values, the fits the run feeds and the seed.
    let mut jobs: Vec<(&World, u64, Option<PathBuf>)> = Vec::new();
    for (world, path) in worlds.iter().zip(&paths) {
        let key_parts = match &args.runs {
            None => None,
            Some(dir) => {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("creating the --runs directory {}", dir.display()))
                    .map_err(input)?;
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("reading {}", path.display()))
                    .map_err(input)?;
                let mut parts = text.into_bytes();
                for s in &set {
                    parts.extend_from_slice(s.as_bytes());
                    parts.push(0);
                }
                parts.extend(targets.iter().map(|&t| u8::from(t)));
                Some((dir, parts))
            }
        };
        for &seed in &seeds {
            let stored = key_parts
                .as_ref()
                .map(|(dir, parts)| dir.join(format!("{}.json", run_key(path, &[parts], seed))));
            jobs.push((world, seed, stored));
        }
    }
    // This build, whose stored runs alone are reused (none: any build's, with
    // `--reuse-any-build`).
    let build = reusable_build(args.reuse_any_build)?;
    let threads = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| Failure::Other(e.into()))?;
    type Job = Vec<(Target, Vec<Sample>, Vec<f64>, String, u64)>;
    let results: Vec<Result<Job, String>> = pool.install(|| {
        jobs.par_iter()
            .map(|(world, seed, stored)| {
                let (world, seed) = (*world, *seed);
                if let Some(file) = stored
                    && let Ok(text) = std::fs::read_to_string(file)
                    && let Ok(run) = serde_json::from_str::<StoredRun>(&text)
                    && (build.is_none() || run.build.as_deref() == build)
                {
                    eprintln!(
                        "calibrate: {} seed {seed} reused from {}",
                        world.name,
                        file.display()
                    );
                    return Ok(run
                        .fits
                        .into_iter()
                        .map(|f| {
                            let target = if f.oracle {
                                Target::Oracle
                            } else {
                                Target::Method(world.mapping.method)
                            };
                            let samples = f.windows.iter().map(StoredWindow::sample).collect();
                            let densities = f.densities.into_iter().map(f64::from_bits).collect();
                            (target, samples, densities, world.name.clone(), seed)
                        })
                        .collect());
                }
                let out = simulate(world, &SimOptions::new(seed))
                    .map_err(|e| format!("{} seed {seed}: {e}", world.name))?;
                let cfg = MapConfig::for_world(world);
                let fs = FreeSpace::for_world(world).map_err(|e| e.to_string())?;
                let maps = map_windows(&out.log, &cfg);
                let densities: Vec<f64> = maps.iter().map(|m| m.events_per_point).collect();
                let truths: Vec<[usize; 2]> = cfg
                    .windows()
                    .iter()
                    .map(|w| {
                        let (a, b) = window_band(world, w.start, w.end);
                        fs.reached_by(world, w.end).betti_in_band(a, b)
                    })
                    .collect();
                let mut fits = Vec::new();
                for &for_oracle in &targets {
                    let samples: Vec<Sample> = maps
                        .iter()
                        .zip(&truths)
                        .map(|(m, &truth)| {
                            if !for_oracle {
                                return Ok(Sample::from_map(m, truth));
                            }
                            let positions = true_positions(m, &out.log).ok_or_else(|| {
                                format!("{} seed {seed}: the log has no truth columns", world.name)
                            })?;
                            Ok(Sample {
                                components: oracle_features(
                                    m,
                                    &positions,
                                    world.mapping.rips_points,
                                ),
                                truth,
                            })
                        })
                        .collect::<Result<_, String>>()?;
                    let target = if for_oracle {
                        Target::Oracle
                    } else {
                        Target::Method(world.mapping.method)
                    };
                    fits.push((target, samples, densities.clone(), world.name.clone(), seed));
                }
                if let Some(file) = stored {
                    let run = StoredRun {
                        world: world.name.clone(),
                        seed,
                        fits: fits
                            .iter()
                            .map(|(target, samples, densities, _, _)| StoredFit {
                                oracle: matches!(target, Target::Oracle),
                                densities: densities.iter().map(|d| d.to_bits()).collect(),
                                windows: samples.iter().map(StoredWindow::from_sample).collect(),
                            })
                            .collect(),
                        build: build.map(String::from),
                    };
                    let mut bytes = serde_json::to_vec(&run).map_err(|e| e.to_string())?;
                    bytes.push(b'\n');
                    write_atomic(file, &bytes)
                        .map_err(|e| format!("writing {}: {e}", file.display()))?;
                }
                eprintln!("calibrate: {} seed {seed} done", world.name);
                Ok(fits)
            })
            .collect()
    });
    let mut models: Models = existing.unwrap_or_else(Models::active);
    let mut by_method: Vec<Training> = Vec::new();
    for (target, samples, densities, world, seed) in results
        .into_iter()
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| Failure::Other(anyhow!(e)))?
        .into_iter()
        .flatten()
    {
        let origin = vec![(world, seed); samples.len()];
        match by_method.iter_mut().find(|t| t.target == target) {
            Some(t) => {
                t.samples.extend(samples);
                t.densities.extend(densities);
                t.origin.extend(origin);
            }
            None => by_method.push(Training {
                target,
                samples,
                densities,
                origin,
            }),
        }
    }
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    // One file for every method fitted (`--landscape`), written once at the end.
    let mut csv = String::from(
        "method,h1_ratio,h1_span,h1_crossing,h1_stability,windows,b1_right,holeless,false_holes,within_cap\n",
    );
    // The fits the false-hole cap constrains nothing in, warned of once before any fit
    // (`--with-oracle` fits the method and the oracle on the same windows; a later fit's
    // error must not hide the warning).
    let unconstrained: Vec<String> = by_method
        .iter()
        .filter(|t| t.samples.iter().all(|s| s.truth[1] > 0) && args.max_false_holes < 1.0)
        .map(|t| format!("{} ({} windows)", target_name(&t.target), t.samples.len()))
        .collect();
    if !unconstrained.is_empty() {
        let fits = match unconstrained.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => unconstrained.concat(),
        };
        eprintln!(
            "warning: no training window of the {fits} fit{} is hole-free, so \
             --max-false-holes constrains nothing and the fit may show holes where there are \
             none; add a world without obstacles to the training worlds (e.g. \
             worlds/training/t_empty.ron)",
            if unconstrained.len() == 1 { "" } else { "s" }
        );
    }
    for Training {
        target: method,
        samples,
        densities,
        origin,
    } in &by_method
    {
        let options = FitOptions {
            max_false_holes: args.max_false_holes,
            crossing: args.crossing && *method == Target::Method(MappingMethod::Embedded),
            stability: args.stability && *method == Target::Method(MappingMethod::Embedded),
        };
        let f = fit(samples, options).ok_or_else(|| {
            input(anyhow!(
                "no classifier shows false holes in at most {} of the {} training windows \
                 without a hole; allow more with --max-false-holes",
                given(args.max_false_holes),
                samples.iter().filter(|s| s.truth[1] == 0).count()
            ))
        })?;
        println!(
            "{}: h0_ratio {:.2}, h1_ratio {:.2}, h1_span {:.2}, h1_crossing {}, h1_stability {}; training windows {}: \
             both right {:.1} %, β0 {:.1} %, β1 {:.1} %, false holes {:.1} % of hole-free windows",
            target_name(method),
            f.classifier.h0_ratio,
            f.classifier.h1_ratio,
            f.classifier.h1_span,
            crossing_text(f.classifier.h1_crossing),
            stability_text(f.classifier.h1_stability),
            f.windows,
            100.0 * f.accuracy,
            100.0 * f.b0_accuracy,
            100.0 * f.b1_accuracy,
            100.0 * f.false_holes
        );
        if args.landscape.is_some() {
            let holeless = samples.iter().filter(|s| s.truth[1] == 0).count();
            for p in h1_landscape(samples, options) {
                csv.push_str(&format!(
                    "{},{},{},{},{},{},{},{},{},{}\n",
                    target_name(method),
                    p.h1_ratio,
                    p.h1_span,
                    p.h1_crossing.map_or(String::new(), |x| x.to_string()),
                    p.h1_stability.map_or(String::new(), |x| x.to_string()),
                    samples.len(),
                    p.b1_right,
                    holeless,
                    p.false_holes,
                    p.false_share <= args.max_false_holes + 1e-12
                ));
            }
        }
        let mut held_out = String::new();
        for &groups in &args.cross_validate {
            let labels: Vec<String> = origin
                .iter()
                .map(|(world, seed)| match groups {
                    CvGroups::Seeds => format!("seed {seed}"),
                    CvGroups::Worlds => world.clone(),
                })
                .collect();
            let cv = cross_validate(samples, &labels, options).map_err(|e| input(anyhow!(e)))?;
            print_cross_validation(groups, &cv);
            held_out.push_str(&format!(
                "; held out by {}: {:.1} % right, false holes in {:.1} %",
                groups.noun(),
                100.0 * cv.accuracy,
                100.0 * cv.false_holes
            ));
        }
        let bank = match method {
            Target::Method(method) => models.get_mut(*method),
            Target::Oracle => &mut models.oracle,
        };
        let density = Density::of(densities);
        if let Some(d) = density {
            println!(
                "  fitted at {:.2}–{:.2} encounters per Rips vertex (median {:.2})",
                d.min, d.max, d.median
            );
        }
        let fitted_on = format!(
            "swarmmap calibrate{}{}{}{} --seeds {} --max-false-holes {} {}{}{}: {} windows, {:.1} % right (β0 {:.1} %, β1 {:.1} %, false holes in {:.1} % of hole-free windows)",
            match method {
                Target::Oracle => " --oracle",
                Target::Method(_) => "",
            },
            if args.only { " --only" } else { "" },
            if args.crossing && *method == Target::Method(MappingMethod::Embedded) {
                " --crossing"
            } else {
                ""
            },
            if args.stability && *method == Target::Method(MappingMethod::Embedded) {
                " --stability"
            } else {
                ""
            },
            args.seeds,
            given(args.max_false_holes),
            args.cross_validate
                .iter()
                .map(|g| format!("--cross-validate {} ", g.value()))
                .collect::<String>(),
            args.set
                .iter()
                .map(|s| format!("--set {s} "))
                .collect::<String>(),
            names.join(" "),
            f.windows,
            100.0 * f.accuracy,
            100.0 * f.b0_accuracy,
            100.0 * f.b1_accuracy,
            100.0 * f.false_holes
        ) + &held_out;
        let model = Model {
            classifier: f.classifier,
            fitted_on,
            events_per_point: density,
            leader_speed: Some(sweep),
        };
        if args.only {
            bank.replace_sweep(model);
        } else {
            bank.insert(model);
        }
        println!(
            "  {} now holds {} model{}",
            target_name(method),
            bank.0.len(),
            if bank.0.len() == 1 { "" } else { "s" }
        );
    }
    if let Some(path) = &args.landscape {
        write_atomic(path, csv.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("H1 landscape written to {}", path.display());
    }
    let mut text = serde_json::to_string_pretty(&models).map_err(|e| Failure::Other(e.into()))?;
    text.push('\n');
    write_atomic(&args.out, text.as_bytes())
        .with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "model written to {0} (use it with `--model {0}`, or rebuild swarmmap to make it the \
         default)",
        args.out.display()
    );
    Ok(())
}

/// Prints a cross-validation: the pooled held-out figures, then one line per fold.
fn print_cross_validation(groups: CvGroups, cv: &CrossValidation) {
    let (lo, hi) = cv
        .folds
        .iter()
        .map(|f| f.right as f64 / f.windows as f64)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    println!(
        "  held out by {}: {} folds, each judged by the model fitted on the others: {:.1} % of \
         {} windows right (folds {:.1}–{:.1} %), false holes in {:.1} % of {} hole-free windows",
        groups.noun(),
        cv.folds.len(),
        100.0 * cv.accuracy,
        cv.windows,
        100.0 * lo,
        100.0 * hi,
        100.0 * cv.false_holes,
        cv.holeless
    );
    for f in &cv.folds {
        println!(
            "    without {:<12} h1_ratio {:.2}, h1_span {:.2}, h1_crossing {}, h1_stability {}, h0_ratio {:.2}: {}/{} right, false holes {}/{}",
            f.held_out,
            f.classifier.h1_ratio,
            f.classifier.h1_span,
            crossing_text(f.classifier.h1_crossing),
            stability_text(f.classifier.h1_stability),
            f.classifier.h0_ratio,
            f.right,
            f.windows,
            f.false_holes,
            f.holeless
        );
    }
}

/// The training windows of one fitted target, with each sample's (world, seed) for
/// cross-validation.
struct Training {
    target: Target,
    samples: Vec<Sample>,
    /// Each sample's encounters per Rips vertex (the map's, also for the oracle, which
    /// samples the same events with as many points).
    densities: Vec<f64>,
    origin: Vec<(String, u64)>,
}

/// What a fit is for: a mapping method's model, or the truth-position oracle's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    Method(MappingMethod),
    Oracle,
}

/// The model entry a fit replaces, as printed and in `--landscape` rows.
fn target_name(target: &Target) -> String {
    match target {
        Target::Method(m) => format!("{m:?}"),
        Target::Oracle => "Oracle".to_string(),
    }
}

/// A model's largest crossing share as printed: the value, or `none` (no crossing test).
fn crossing_text(c: Option<f64>) -> String {
    c.map_or_else(|| "none".to_string(), |x| format!("{x:.3}"))
}

/// A model's least split stability as printed: the value, or `none` (no stability test).
fn stability_text(c: Option<f64>) -> String {
    c.map_or_else(|| "none".to_string(), |x| format!("{x:.2}"))
}
