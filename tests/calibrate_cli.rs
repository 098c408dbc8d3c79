//! `swarmmap calibrate`: it replaces exactly the entry it fits in the model file (a method's,
//! or the truth-position oracle's with `--oracle`, or both with `--with-oracle`), keeps the
//! others, says what it was fitted on and at what density, and a fit at another sampling
//! density joins the method's bank instead of replacing it.

use assert_cmd::Command;
use predicates::prelude::PredicateBooleanExt;
use predicates::str::contains;
use swarmmap::mapping::classify::{Models, SHIPPED};

const WORLD: &str = "tests/fixtures/worlds/tiny.ron";

/// Calibrates on the tiny world (seeds 1 and 2) into `out`; returns what it printed.
fn calibrate(out: &std::path::Path, extra: &[&str]) -> String {
    let assert = Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD, "--seeds", "1,2", "--jobs", "1", "--out"])
        .arg(out)
        .args(extra)
        .assert()
        .success()
        .stdout(contains("training windows 4"));
    String::from_utf8_lossy(&assert.get_output().stdout).into_owned()
}

/// A temporary directory holding `model.json`, a copy of the shipped model file.
fn shipped_copy() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    std::fs::write(&out, SHIPPED).unwrap();
    (dir, out)
}

fn models(path: &std::path::Path) -> Models {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs the tiny world (seed 1) with the models of `model` and one `--set`, in `dir/run`;
/// returns its first window's `maps/window_1.json`.
fn first_window(model: &std::path::Path, set: &str, dir: &std::path::Path) -> serde_json::Value {
    let run = dir.join("run");
    Command::cargo_bin("swarmmap")
        .unwrap()
        .arg("--model")
        .arg(model)
        .args([
            "run",
            WORLD,
            "--seed",
            "1",
            "--no-report",
            "--set",
            set,
            "--out",
        ])
        .arg(&run)
        .assert()
        .success();
    serde_json::from_str(&std::fs::read_to_string(run.join("maps/window_1.json")).unwrap()).unwrap()
}

#[test]
fn calibrate_replaces_only_the_fitted_entry() {
    let (_dir, out) = shipped_copy();
    let shipped = Models::shipped();

    // tiny.ron maps with the paper's method: its entry is refitted, the others kept.
    calibrate(&out, &[]);
    let m = models(&out);
    assert!(
        m.paper
            .first()
            .fitted_on
            .starts_with("swarmmap calibrate --seeds 1,2 ")
    );
    assert!(m.paper.first().fitted_on.contains("tiny.ron: 4 windows"));
    assert_eq!(m.embedded, shipped.embedded);
    assert_eq!(m.oracle, shipped.oracle);

    calibrate(&out, &["--oracle"]);
    let m2 = models(&out);
    assert!(
        m2.oracle
            .first()
            .fitted_on
            .starts_with("swarmmap calibrate --oracle --seeds 1,2 ")
    );
    assert_eq!(m2.paper, m.paper);
    assert_eq!(m2.embedded, shipped.embedded);
}

#[test]
fn a_bad_model_file_is_an_input_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    std::fs::write(&out, "not json").unwrap();
    Command::cargo_bin("swarmmap")
        .unwrap()
        .args([
            "calibrate",
            WORLD,
            "--seeds",
            "1",
            "--jobs",
            "1",
            "--oracle",
            "--out",
        ])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains("not a model file"))
        // Refused before any training run (found by the fortieth session's review: the file
        // was read only after them, and the fit lost).
        .stderr(contains("done").not());
}

/// Regression: a cap outside [0, 1] was accepted and fitted as if unconstrained.
#[test]
fn a_false_hole_cap_outside_0_to_1_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    for cap in ["2", "-0.1", "NaN"] {
        Command::cargo_bin("swarmmap")
            .unwrap()
            .args(["calibrate", WORLD, "--seeds", "1"])
            .arg(format!("--max-false-holes={cap}"))
            .arg("--out")
            .arg(&out)
            .assert()
            .code(2)
            .stderr(contains(format!("--max-false-holes is {cap}")))
            .stderr(contains("from 0 to 1"));
    }
    assert!(!out.exists(), "nothing is fitted or written");
}

/// Found by the forty-first session's review: `--landscape` naming the `--out` file wrote
/// the model over the landscape and said both were written; `--set seed=N` was accepted and
/// recorded in the model's `fitted_on`, though `--seeds` decides every run's seed.
#[test]
fn calibrate_refuses_one_file_for_two_outputs_and_a_seed_set() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    // The same file by another path (`Path` equality already ignores `.`, not `..`).
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let same = dir.path().join("sub").join("..").join("model.json");
    for (extra, said) in [
        (
            vec!["--landscape".to_string(), same.display().to_string()],
            "is the --out model file too",
        ),
        (
            vec!["--set".to_string(), "seed=5".to_string()],
            "each run's seed comes from --seeds",
        ),
    ] {
        Command::cargo_bin("swarmmap")
            .unwrap()
            .args(["calibrate", WORLD, "--seeds", "1", "--out"])
            .arg(&out)
            .args(&extra)
            .assert()
            .code(2)
            .stderr(contains(said));
    }
    assert!(!out.exists(), "nothing is fitted or written");
}

/// `--stability` needs the stabilities: a run that turns them off is refused, not fitted
/// with a test that never bites, whether the `--set` names the field or the whole section.
#[test]
fn stability_without_stabilities_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    for off in [
        "mapping.split_stability=false",
        " mapping.split_stability = false",
        "mapping=(split_stability: false)",
        "mapping=(windows: 5, split_stability: false)",
    ] {
        Command::cargo_bin("swarmmap")
            .unwrap()
            .args(["calibrate", WORLD, "--seeds", "1", "--stability"])
            .args(["--set", off, "--out"])
            .arg(&out)
            .assert()
            .code(2)
            .stderr(contains(format!("`--set {off}` turns them off; drop it")));
        assert!(!out.exists(), "nothing is fitted or written for {off}");
    }
}

/// The forms `--stability` accepts get as far as loading the worlds (here refused for a
/// swarm of no agents, so nothing is simulated): the default (`=None`), `true`, a whole
/// `mapping` section that leaves the field out, and with `--oracle`, whose fit has no
/// stability test, even `false`. Two sets that both turn it off are both named.
#[test]
fn stability_accepts_the_forms_that_leave_stabilities_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    for (extra, set) in [
        (None, "mapping.split_stability=None"),
        (None, "mapping.split_stability = true"),
        (None, "mapping=(windows: 5)"),
        (None, "mapping=None"),
        (Some("--oracle"), "mapping.split_stability=false"),
    ] {
        let mut cmd = Command::cargo_bin("swarmmap").unwrap();
        cmd.args(["calibrate", WORLD, "--seeds", "1", "--stability"]);
        cmd.args(extra);
        cmd.args(["--set", set, "--set", "swarm.agents=0", "--out"])
            .arg(&out)
            .assert()
            .code(2)
            .stderr(contains("swarm.agents is 0"));
    }
    Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD, "--seeds", "1", "--stability"])
        .args(["--set", "mapping=(split_stability: false)"])
        .args(["--set", "mapping.split_stability=false", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains(
            "`--set mapping=(split_stability: false)` and `--set mapping.split_stability=false` \
             turn them off; drop them",
        ));
    assert!(!out.exists(), "nothing is fitted or written");
}

#[test]
fn cross_validation_prints_every_fold_and_records_the_held_out_figures() {
    let (_dir, out) = shipped_copy();
    let assert = Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD, "--seeds", "1,2", "--jobs", "1"])
        .args(["--cross-validate", "seeds", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("held out by seed: 2 folds"))
        .stdout(contains("without seed 1 "))
        .stdout(contains("without seed 2 "));
    let stdout = String::from_utf8(assert.get_output().stdout.clone()).unwrap();
    // Each fold judges the 2 windows of its seed.
    assert_eq!(stdout.matches("right, false holes").count(), 2, "{stdout}");
    assert!(stdout.contains("/2 right"), "{stdout}");
    let m = models(&out);
    assert!(
        m.paper.first().fitted_on.contains("; held out by seed: "),
        "{}",
        m.paper.first().fitted_on
    );

    // One training world cannot be held out against the others.
    Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD, "--seeds", "1,2", "--jobs", "1"])
        .args(["--cross-validate", "worlds", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains("at least two groups"));
}

#[test]
fn the_landscape_lists_the_whole_grid_and_the_fitted_rule_is_its_best_point() {
    let (dir, out) = shipped_copy();
    let land = dir.path().join("landscape.csv");
    calibrate(
        &out,
        &[
            "--max-false-holes",
            "1",
            "--landscape",
            land.to_str().unwrap(),
        ],
    );
    let text = std::fs::read_to_string(&land).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "method,h1_ratio,h1_span,h1_crossing,h1_stability,windows,b1_right,holeless,false_holes,within_cap"
        )
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // Death / birth 1 to 8 in steps of 0.1, a life of 0 to 20 σ in steps of 0.25 σ; no
    // crossing or stability test without `--crossing` / `--stability`.
    assert_eq!(rows.len(), 71 * 81);
    assert!(rows.iter().all(|r| r.len() == 10
        && r[0] == "Paper"
        && r[3].is_empty()
        && r[4].is_empty()
        && r[5] == "4"));
    // Unconstrained, every point is within the cap, and the fitted rule scores the most.
    assert!(rows.iter().all(|r| r[9] == "true"));
    let best = rows
        .iter()
        .map(|r| r[6].parse::<usize>().unwrap())
        .max()
        .unwrap();
    let c = models(&out).paper.first().classifier;
    let fitted = rows
        .iter()
        .find(|r| {
            r[1].parse::<f64>().unwrap() == c.h1_ratio && r[2].parse::<f64>().unwrap() == c.h1_span
        })
        .expect("the fitted rule is a grid point");
    assert_eq!(fitted[6].parse::<usize>().unwrap(), best);
}

/// With `--crossing` the `Embedded` method's grid also runs over the largest crossing share
/// (24 values, each with the lives from 1 σ), the fit says so, and the model it writes
/// carries `h1_crossing` exactly when its rule has one.
#[test]
fn crossing_adds_the_share_to_the_embedded_grid() {
    let (_dir, out, text) = gated_landscape(Gate::Crossing);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 71 * 81 + 24 * 71 * 77);
    let shares: std::collections::BTreeSet<&str> = rows.iter().map(|r| r[3]).collect();
    assert_eq!(shares.len(), 25, "{shares:?}");
    assert!(shares.contains("") && shares.contains("0.01") && shares.contains("0.2"));
    gated_fit_is_the_best_rule(&out, &rows, Gate::Crossing);
}

/// With `--stability` the `Embedded` method's training runs record split stabilities, the
/// grid also runs over the least stability (31 values, each with the lives from 1 σ), and
/// the model it writes carries `h1_stability` exactly when its rule has one.
#[test]
fn stability_adds_the_split_stability_to_the_embedded_grid() {
    let (_dir, out, text) = gated_landscape(Gate::Stability);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 71 * 81 + 31 * 71 * 77);
    let values: std::collections::BTreeSet<&str> = rows.iter().map(|r| r[4]).collect();
    assert_eq!(values.len(), 32, "{values:?}");
    assert!(values.contains("") && values.contains("0.5") && values.contains("8"));
    assert!(
        rows.iter().all(|r| r[3].is_empty()),
        "no crossing test asked"
    );
    // Stabilities were computed: some rule with a stability test scores differently from
    // the same rule without one.
    let score = |r: &Vec<&str>| format!("{},{},{}", r[1], r[2], r[6]);
    let plain: std::collections::BTreeSet<String> =
        rows.iter().filter(|r| r[4].is_empty()).map(score).collect();
    assert!(
        rows.iter()
            .filter(|r| r[4] == "8")
            .any(|r| !plain.contains(&score(r))),
        "a stability of at least 8 σ changes no score: were stabilities recorded?"
    );
    gated_fit_is_the_best_rule(&out, &rows, Gate::Stability);
}

/// An `Embedded` fit of a copy of the shipped models with `gate` asked for: the temporary
/// directory, the model file and the landscape CSV's text. The fit's printout names the
/// gate.
fn gated_landscape(gate: Gate) -> (tempfile::TempDir, std::path::PathBuf, String) {
    let (option, field) = match gate {
        Gate::Crossing => ("--crossing", "h1_crossing"),
        Gate::Stability => ("--stability", "h1_stability"),
    };
    let (dir, out) = shipped_copy();
    let land = dir.path().join("landscape.csv");
    let stdout = calibrate(
        &out,
        &[
            option,
            "--set",
            "mapping.method=Embedded",
            "--landscape",
            land.to_str().unwrap(),
        ],
    );
    assert!(stdout.contains(field), "{stdout}");
    let text = std::fs::read_to_string(&land).unwrap();
    (dir, out, text)
}

/// A test beyond persistence that `calibrate` may fit, with its landscape column.
#[derive(Clone, Copy)]
enum Gate {
    Crossing,
    Stability,
}

/// The `Embedded` model that `calibrate` wrote to `out`, fitted with `gate`, against its
/// landscape `rows`: its rule is a grid point that scores the most within the cap, it has
/// the gate only if no rule without one scores as much, the fit says it was asked for, and
/// the model file names the gate exactly when the rule has one.
fn gated_fit_is_the_best_rule(out: &std::path::Path, rows: &[Vec<&str>], gate: Gate) {
    let (column, option, field) = match gate {
        Gate::Crossing => (3, " --crossing ", "h1_crossing"),
        Gate::Stability => (4, " --stability ", "h1_stability"),
    };
    let m = models(out);
    let fit = &m.embedded.for_sweep(TINY_SWEEP).0[0];
    assert!(fit.fitted_on.contains(option), "{}", fit.fitted_on);
    let c = fit.classifier;
    let value = match gate {
        Gate::Crossing => c.h1_crossing,
        Gate::Stability => c.h1_stability,
    };
    let row = rows
        .iter()
        .find(|r| {
            r[1].parse::<f64>().unwrap() == c.h1_ratio
                && r[2].parse::<f64>().unwrap() == c.h1_span
                && r[column] == value.map_or(String::new(), |x| x.to_string())
        })
        .expect("the fitted rule is a grid point");
    let right = |r: &Vec<&str>| r[6].parse::<usize>().unwrap();
    let within: Vec<&Vec<&str>> = rows.iter().filter(|r| r[9] == "true").collect();
    let best = within.iter().map(|r| right(r)).max().unwrap();
    assert_eq!(right(row), best);
    let plain_best = within
        .iter()
        .filter(|r| r[column].is_empty())
        .map(|r| right(r))
        .max()
        .unwrap();
    assert_eq!(value.is_some(), plain_best < best, "{c:?}");
    let text = std::fs::read_to_string(out).unwrap();
    let entry = &text[text.find("\"Embedded\"").unwrap()..];
    let entry = &entry[..entry.find("\"Oracle\"").unwrap_or(entry.len())];
    assert_eq!(entry.contains(field), value.is_some());
}

/// One calibration fits the method's and the oracle's models from the same runs, and each
/// records the density of its training windows.
#[test]
fn with_oracle_fits_both_entries_from_one_set_of_runs() {
    let (_dir, out) = shipped_copy();
    let shipped = Models::shipped();
    let stdout = calibrate(&out, &["--with-oracle"]);
    for says in [
        "Paper: h0_ratio",
        "Oracle: h0_ratio",
        "encounters per Rips vertex",
    ] {
        assert!(stdout.contains(says), "{stdout}");
    }
    let m = models(&out);
    assert_eq!(m.embedded, shipped.embedded);
    for (bank, shipped, prefix) in [
        (&m.paper, &shipped.paper, "swarmmap calibrate --seeds 1,2 "),
        (
            &m.oracle,
            &shipped.oracle,
            "swarmmap calibrate --oracle --seeds 1,2 ",
        ),
    ] {
        // The fit joins the shipped model, which was fitted at another sweep.
        assert_eq!(bank.0.len(), 2, "{bank:?}");
        assert_eq!(bank.for_sweep(0.005), *shipped);
        let fit = &bank.for_sweep(TINY_SWEEP).0[0];
        assert!(fit.fitted_on.starts_with(prefix), "{}", fit.fitted_on);
        let d = fit.events_per_point.expect("the density is recorded");
        assert!(
            d.min <= d.median && d.median <= d.max && d.min > 0.0,
            "{d:?}"
        );
    }
    // The oracle samples the same events with as many points: the same density.
    assert_eq!(
        m.paper.for_sweep(TINY_SWEEP).first().events_per_point,
        m.oracle.for_sweep(TINY_SWEEP).first().events_per_point
    );
}

/// A fit at a sparser sampling (a third of the representatives: about three times the
/// encounters per Rips vertex) joins the bank; a refit at the first sampling replaces its
/// model; `--only` leaves one model. Maps made with the bank record the density and the
/// model that judged them.
/// tiny.ron's leader sweeps at 0.02 m/s: its fits are the models of that sweep.
const TINY_SWEEP: f64 = 0.02;

#[test]
fn a_fit_at_another_density_joins_the_bank() {
    let (dir, out) = shipped_copy();
    let shipped = Models::shipped().paper;
    // The models of tiny's sweep, and those of every other sweep.
    let at_tiny = |m: &Models| m.paper.for_sweep(TINY_SWEEP).0;
    let others = |m: &Models| -> Vec<_> {
        m.paper
            .0
            .iter()
            .filter(|x| x.sweep() != TINY_SWEEP)
            .cloned()
            .collect()
    };
    calibrate(&out, &[]);
    let dense = at_tiny(&models(&out))[0].clone();
    calibrate(&out, &["--set", "mapping.subsample=50"]);
    let m = models(&out);
    assert_eq!(at_tiny(&m).len(), 2, "{:?}", m.paper);
    assert_eq!(
        at_tiny(&m)[0],
        dense,
        "ordered by density, the denser sampling first"
    );
    let sparse = at_tiny(&m)[1].clone();
    assert!(sparse.fitted_on.contains("--set mapping.subsample=50 "));
    assert!(sparse.events_per_point.unwrap().median > 2.0 * dense.events_per_point.unwrap().median);
    calibrate(&out, &[]);
    assert_eq!(at_tiny(&models(&out)), vec![dense.clone(), sparse.clone()]);
    calibrate(&out, &["--only"]);
    let only = at_tiny(&models(&out));
    assert_eq!(only.len(), 1);
    assert!(
        only[0]
            .fitted_on
            .starts_with("swarmmap calibrate --only --seeds 1,2 ")
    );
    // The shipped model, fitted at another sweep, stays through all of these.
    assert_eq!(others(&models(&out)), shipped.0);

    // A run mapped with a two-model bank records each window's density and the model of
    // the nearest one.
    let mut bank = models(&out);
    bank.paper.0 = vec![dense.clone(), sparse.clone()];
    bank.paper.0[1].classifier.h1_ratio = 1e9;
    let model = dir.path().join("bank.json");
    std::fs::write(&model, serde_json::to_string(&bank).unwrap()).unwrap();
    for (sub, ratio) in [("150", dense.classifier.h1_ratio), ("50", 1e9)] {
        let w = first_window(&model, &format!("mapping.subsample={sub}"), dir.path());
        assert_eq!(w["classifier"]["h1_ratio"], ratio, "subsample {sub}");
        assert!(w["events_per_point"].as_f64().unwrap() > 1.0);
    }
}

/// A fit records the sweep of its training runs and joins the shipped model of another
/// sweep; a run is judged by the models of the sweep nearest its leader's, whatever their
/// densities.
#[test]
fn a_run_is_judged_by_the_models_of_its_sweep() {
    let (dir, out) = shipped_copy();
    calibrate(&out, &[]);
    let mut m = models(&out);
    assert_eq!(m.paper.0.len(), 2, "{:?}", m.paper);
    let fitted = m.paper.for_sweep(TINY_SWEEP).0;
    assert_eq!(fitted.len(), 1);
    assert_eq!(fitted[0].leader_speed, Some(TINY_SWEEP));
    // Mark the two models apart by an H1 ratio no data reaches.
    for x in &mut m.paper.0 {
        if x.sweep() == TINY_SWEEP {
            x.classifier.h1_ratio = 1e9;
        } else {
            x.classifier.h1_ratio = 2e9;
        }
    }
    let model = dir.path().join("sweeps.json");
    std::fs::write(&model, serde_json::to_string(&m).unwrap()).unwrap();
    for (speed, ratio) in [("0.02", 1e9), ("0.03", 1e9), ("0.006", 2e9)] {
        let w = first_window(&model, &format!("leader.speed={speed}"), dir.path());
        assert_eq!(w["classifier"]["h1_ratio"], ratio, "leader speed {speed}");
    }
}

/// Training worlds that sweep at different speeds would give a model of no one sweep.
#[test]
fn training_worlds_of_different_sweeps_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let fast = dir.path().join("fast.ron");
    let text = std::fs::read_to_string(WORLD).unwrap();
    std::fs::write(&fast, text.replace("speed: 0.02,", "speed: 0.04,")).unwrap();
    Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD])
        .arg(&fast)
        .args(["--seeds", "1", "--jobs", "1", "--out"])
        .arg(dir.path().join("m.json"))
        .assert()
        .code(2)
        .stderr(contains("sweep at different speeds"))
        .stderr(contains("--set leader.speed="));
    assert!(!dir.path().join("m.json").exists());
}

/// `--runs DIR` keeps each training run's diagrams; a second fit reuses them (no new
/// simulation) and writes the same model, essential classes included; an unreadable file
/// is run again.
#[test]
fn runs_kept_with_runs_dir_are_reused_and_fit_the_same_model() {
    let (dir, out) = shipped_copy();
    let runs = dir.path().join("runs");
    let first = calibrate(&out, &["--runs", runs.to_str().unwrap()]);
    let fitted = std::fs::read_to_string(&out).unwrap();
    let mut files: Vec<_> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 2, "one file per seed: {files:?}");
    std::fs::write(&out, SHIPPED).unwrap();
    let assert = Command::cargo_bin("swarmmap")
        .unwrap()
        .args([
            "calibrate",
            WORLD,
            "--seeds",
            "1,2",
            "--jobs",
            "1",
            "--runs",
        ])
        .arg(&runs)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    assert_eq!(stderr.matches("reused from").count(), 2, "{stderr}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), fitted);
    // A damaged file is not trusted: that run is simulated again.
    std::fs::write(&files[0], "{ not json").unwrap();
    std::fs::write(&out, SHIPPED).unwrap();
    let again = calibrate(&out, &["--runs", runs.to_str().unwrap()]);
    assert_eq!(again, first);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), fitted);
}

/// Left alone by the forty-first session: on training worlds whose every window holds a
/// hole the false-hole cap is vacuous, and `calibrate` said nothing. The tiny world's disc
/// lies in both its windows; with the cap lifted (`--max-false-holes 1`) there is nothing
/// to warn of, and `--with-oracle` warns once for both its fits.
#[test]
fn calibrate_warns_when_no_training_window_is_hole_free() {
    let dir = tempfile::tempdir().unwrap();
    let warning = "warning: no training window of the Paper (2 windows) fit is hole-free, so \
                   --max-false-holes constrains nothing";
    let fit = |extra: &[&str]| {
        Command::cargo_bin("swarmmap")
            .unwrap()
            .args(["calibrate", WORLD, "--seeds", "1", "--jobs", "1", "--out"])
            .arg(dir.path().join("model.json"))
            .args(extra)
            .assert()
            .success()
    };
    fit(&[]).stderr(contains(warning));
    fit(&["--max-false-holes", "1"]).stderr(contains("hole-free, so").not());
    // With the oracle fitted on the same windows: one warning naming both fits (it was
    // printed once per fit, the forty-second session's note).
    let both = fit(&["--with-oracle"]);
    let stderr = String::from_utf8_lossy(&both.get_output().stderr).into_owned();
    assert_eq!(stderr.matches("hole-free, so").count(), 1, "{stderr}");
    assert!(
        stderr.contains("of the Paper (2 windows) and Oracle (2 windows) fits is hole-free"),
        "{stderr}"
    );
}

/// A model records its sweep, not the outlier rank it was fitted at: training worlds that
/// fix a rank other than the one their sweep gives (2 at the tiny world's 0.02 m/s) are
/// warned of; the sweep's own rank is not.
#[test]
fn calibrate_warns_of_a_fixed_outlier_rank_the_model_cannot_record() {
    let dir = tempfile::tempdir().unwrap();
    let fit = |rank: &str| {
        let out = Command::cargo_bin("swarmmap")
            .unwrap()
            .args(["calibrate", WORLD, "--seeds", "1", "--jobs", "1", "--set"])
            .arg(format!("mapping.outlier_rank={rank}"))
            .arg("--out")
            .arg(dir.path().join("model.json"))
            .assert()
            .success();
        String::from_utf8_lossy(&out.get_output().stderr).into_owned()
    };
    let fixed = fit("5");
    assert!(
        fixed.contains(
            "maps with mapping.outlier_rank 5, but the model records only its sweep (0.02 \
             m/s), where maps use rank 2"
        ),
        "{fixed}"
    );
    let own = fit("2");
    assert!(!own.contains("outlier_rank"), "{own}");
}
