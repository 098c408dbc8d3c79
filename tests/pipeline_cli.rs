//! End to end: `run`, `map` on a log without truth, malformed logs, `eval` resuming, and
//! determinism of the mapping outputs.

use assert_cmd::Command;
use predicates::prelude::PredicateBooleanExt;
use predicates::str::contains;
use std::fs;
use std::path::Path;

const TINY: &str = "tests/fixtures/worlds/tiny.ron";

fn swarmmap() -> Command {
    Command::cargo_bin("swarmmap").unwrap()
}

/// `swarmmap run` of the tiny world without its report, in a fresh directory (kept while
/// the returned guard lives).
fn tiny_run_without_report() -> (tempfile::TempDir, std::path::PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("r");
    swarmmap()
        .args(["run", TINY, "--no-report", "--quiet", "--out"])
        .arg(&dir)
        .assert()
        .success();
    (tmp, dir)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

/// `summary.json` without its `timings` and `alongside`, the only parts that depend on
/// the machine.
fn summary_without_timings(dir: &Path) -> serde_json::Value {
    let mut v = json(&dir.join("summary.json"));
    let o = v.as_object_mut().unwrap();
    o.remove("timings");
    o.remove("alongside");
    v
}

#[test]
fn run_writes_every_output_and_is_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    // The second run maps after the simulation instead of alongside it: the same outputs.
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    for (dir, after) in [(&a, false), (&b, true)] {
        let mut cmd = swarmmap();
        cmd.args(["run", TINY, "--quiet", "--out"]).arg(dir);
        if after {
            cmd.arg("--map-after");
        }
        let out = cmd.assert().success().stdout(contains("global (β0,β1)"));
        let stdout = String::from_utf8_lossy(&out.get_output().stdout).to_string();
        assert_eq!(
            stdout.contains("alongside the simulation"),
            !after && cores > 1,
            "{stdout}"
        );
    }
    for f in [
        "encounters.csv",
        "static_intervals.csv",
        "leader.csv",
        "meta.json",
        "summary.json",
    ] {
        assert!(a.join(f).exists(), "{f} missing");
    }
    let s = json(&a.join("summary.json"));
    assert_eq!(s["world"], "tiny");
    assert_eq!(s["windows"].as_array().unwrap().len(), 2);
    assert_eq!(s["connections"].as_array().unwrap().len(), 1);
    // Truth is known for a simulated run: the whole arena has one component and one hole.
    assert_eq!(s["global"]["truth"], serde_json::json!([1, 1]));
    for w in s["windows"].as_array().unwrap() {
        assert!(w["truth"].is_array(), "{w}");
        assert!(w["events"].as_u64().unwrap() > 0);
    }
    for i in 1..=2 {
        let wa = fs::read(a.join(format!("maps/window_{i}.json"))).unwrap();
        let wb = fs::read(b.join(format!("maps/window_{i}.json"))).unwrap();
        assert!(wa == wb, "window {i} differs between identical runs");
    }
    assert_eq!(summary_without_timings(&a), summary_without_timings(&b));
}

/// Regression (forty-first session's review): `run` mapped the simulator's unrounded log
/// while its files hold six decimals, so `map DIR` of the same run gave other maps (tiny:
/// every window's file and the connection differed; a larger world changed its Betti
/// numbers). The simulator now hands out the log as written.
#[test]
fn mapping_a_run_again_from_its_files_gives_its_maps() {
    let (_tmp, dir) = tiny_run_without_report();
    let maps = |dir: &Path| -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<_> = fs::read_dir(dir.join("maps"))
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (
                    p.file_name().unwrap().to_string_lossy().into_owned(),
                    fs::read(&p).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let (before, summary) = (maps(&dir), summary_without_timings(&dir));
    assert!(
        before.len() >= 4,
        "{:?}",
        before.iter().map(|m| &m.0).collect::<Vec<_>>()
    );
    swarmmap().arg("map").arg(&dir).assert().success();
    for ((name, a), (_, b)) in before.iter().zip(&maps(&dir)) {
        assert!(
            a == b,
            "maps/{name} differs when the run is mapped from its files"
        );
    }
    assert_eq!(maps(&dir).len(), before.len());
    assert_eq!(summary_without_timings(&dir), summary);
    // `map` times the maps' writing (it writes no log): before the forty-fourth session
    // it had no writing stage, and the maps' writing was left out of every time line.
    let s = json(&dir.join("summary.json"));
    assert!(s["timings"]["writing"].as_f64().unwrap() > 0.0, "{s}");
}

/// Found by the forty-first session's review: `--seed 5 --set seed=6` ran seed 5 while
/// meta.json recorded a world of seed 6, and `eval --set seed=5,6` ran the same runs twice
/// as two parameter sets. Both are refused before any work; `--set seed` alone is a seed.
#[test]
fn the_seed_is_given_one_way() {
    let tmp = tempfile::tempdir().unwrap();
    for cmd in ["run", "simulate"] {
        let out = tmp.path().join(cmd);
        swarmmap()
            .args([
                cmd, TINY, "--quiet", "--seed", "5", "--set", "seed=6", "--out",
            ])
            .arg(&out)
            .assert()
            .code(2)
            .stderr(contains("both --seed 5 and --set seed=6"));
        assert!(!out.exists(), "{cmd} made its output");
    }
    let out = tmp.path().join("eval");
    swarmmap()
        .args([
            "eval", TINY, "--seeds", "1", "--set", "seed=5,6", "--quiet", "--out",
        ])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains("each run's seed comes from --seeds"));
    let out = tmp.path().join("set");
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--set", "seed=3", "--out"])
        .arg(&out)
        .assert()
        .success();
    assert_eq!(json(&out.join("meta.json"))["seed"], 3);
}

/// Found by the forty-first session's review: `run` said nothing of what `map` warns of in
/// the same run's log. Each warning names the world settings that change it.
#[test]
fn run_warns_of_what_map_would() {
    let tmp = tempfile::tempdir().unwrap();
    for (set, said) in [
        ("swarm.landmark_fraction=0", "no agent became a landmark"),
        ("swarm.agents=1", "a single agent meets no one"),
        (
            "swarm.agents=3",
            "every window's encounters were judged noise",
        ),
    ] {
        let out = tmp.path().join(set);
        swarmmap()
            .args(["run", TINY, "--no-report", "--quiet", "--set", set, "--out"])
            .arg(&out)
            .assert()
            .success()
            .stderr(contains(format!("warning: {said}")));
    }
}

/// A run's recorded world is not asked again whether its placement area holds the agents:
/// they were placed (found by the forty-first session's review: the tightened bound would
/// have refused to map runs made before it).
#[test]
fn a_recorded_world_is_not_refused_by_a_tighter_placement_bound() {
    let (tmp, dir) = tiny_run_without_report();
    let meta_path = dir.join("meta.json");
    let mut meta = json(&meta_path);
    meta["world"]["swarm"]["agents"] = serde_json::json!(300_000);
    fs::write(&meta_path, serde_json::to_string(&meta).unwrap()).unwrap();
    swarmmap().arg("map").arg(&dir).assert().success();
    // The same world as a file is refused: it could not be placed.
    let file = tmp.path().join("packed.ron");
    fs::write(
        &file,
        fs::read_to_string(TINY)
            .unwrap()
            .replace("agents: 40", "agents: 300000"),
    )
    .unwrap();
    swarmmap()
        .arg("check")
        .arg(&file)
        .assert()
        .code(2)
        .stderr(contains("at most 45 %"));
}

/// Regression: `map` on a run made with `--seed 3` wrote `"seed": 1` into summary.json (the
/// world file's own `seed` field, from meta.json's copy of the world) instead of the run's.
#[test]
fn map_reports_the_seed_the_run_was_made_with() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("r");
    swarmmap()
        .args([
            "run",
            TINY,
            "--seed",
            "3",
            "--no-report",
            "--quiet",
            "--out",
        ])
        .arg(&dir)
        .assert()
        .success();
    assert_eq!(json(&dir.join("summary.json"))["seed"], 3);
    swarmmap().arg("map").arg(&dir).assert().success();
    assert_eq!(json(&dir.join("summary.json"))["seed"], 3, "after map");
    // A real log has no seed, whatever world file it is judged against.
    let bare = tmp.path().join("bare");
    fs::create_dir(&bare).unwrap();
    fs::copy(dir.join("encounters.csv"), bare.join("encounters.csv")).unwrap();
    swarmmap()
        .args(["map", "--world", TINY])
        .arg(&bare)
        .assert()
        .success();
    assert!(json(&bare.join("summary.json"))["seed"].is_null());
}

/// A simulated log stripped to what a real experiment would record: `encounters.csv`
/// without truth columns and `static_intervals.csv`, no metadata.
fn real_log(tmp: &Path) -> std::path::PathBuf {
    let run = tmp.join("run");
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--out"])
        .arg(&run)
        .assert()
        .success();
    // Strip the truth columns and the metadata: what a real experiment would record.
    let log = tmp.join("log");
    fs::create_dir_all(&log).unwrap();
    let text = fs::read_to_string(run.join("encounters.csv")).unwrap();
    let stripped: String = text
        .lines()
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    fs::write(log.join("encounters.csv"), stripped).unwrap();
    fs::copy(
        run.join("static_intervals.csv"),
        log.join("static_intervals.csv"),
    )
    .unwrap();
    log
}

#[test]
fn a_log_without_truth_or_world_maps_without_truth() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    swarmmap()
        .args(["map", "--windows", "2", "--overlap", "30"])
        .arg(&log)
        .assert()
        .success();
    let s = json(&log.join("summary.json"));
    assert_eq!(s["world"], "log");
    let windows = s["windows"].as_array().unwrap();
    assert_eq!(windows.len(), 2);
    assert!(windows.iter().all(|w| w["truth"].is_null()));
    assert!(s["global"]["truth"].is_null());
}

/// `map --set mapping.FIELD=VALUE` maps a log with other mapping settings, on top of the
/// defaults without a world and of the world's with one (found by the fortieth session's
/// review: a real log could not be mapped at the settings the shipped models were fitted
/// at); what map cannot take is refused before anything is written.
#[test]
fn map_takes_mapping_settings_with_or_without_a_world() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    let run = tmp.path().join("run");
    for (dir, cut) in [
        (&log, &["--windows", "2", "--overlap", "30"][..]),
        (&run, &[][..]),
    ] {
        swarmmap()
            .args(["map", "--set", "mapping.method=Embedded", "--set"])
            .args([
                "mapping.rips_points=60",
                "--set",
                "mapping.cluster_cutoff=7.5",
            ])
            .args(cut)
            .arg(dir)
            .assert()
            .success();
        // The Embedded method's 60 planar Rips points (default 1 200, more than the
        // window's encounters).
        let w = json(&dir.join("maps/window_1.json"));
        let points: usize = w["components"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["representatives"].as_array().unwrap().len())
            .sum();
        assert_eq!(points, 60, "{dir:?}");
        assert_eq!(json(&dir.join("maps/connection_1.json"))["cutoff"], 7.5);
    }
    // The whole section keeps the world's windows (2 of them, overlapping 30 s), which the
    // defaults (4, 300 s) would not fit in the tiny run (found by the fortieth session's
    // review).
    swarmmap()
        .args([
            "map",
            "--set",
            "mapping=(method: Embedded, rips_points: 60)",
        ])
        .arg(&run)
        .assert()
        .success();
    let s = json(&run.join("summary.json"));
    assert_eq!(s["windows"].as_array().unwrap().len(), 2, "{s}");
    for (sets, says) in [
        (
            &["--set", "swarm.agents=3"][..],
            "map takes only mapping.FIELD=VALUE",
        ),
        (
            &["--set", "mapping.windows=3"][..],
            "pass --windows instead",
        ),
        (
            &["--set", "mapping.rips_pints=60"][..],
            "no such mapping setting; map takes mapping.cluster_cutoff,",
        ),
        (
            &["--set", "mapping=(overlap: 10)"][..],
            "pass --overlap instead",
        ),
        (
            &["--method", "paper", "--set", "mapping.method=Embedded"][..],
            "give the method once",
        ),
        (
            &["--set", "mapping.rips_points=0"][..],
            "map (--set mapping.rips_points=0): mapping.rips_points is 0",
        ),
    ] {
        map_refused(&log, sets, says);
    }
}

/// `swarmmap map --windows 2 --overlap 30 EXTRA LOG` fails with status 2, says `says`, and
/// leaves the log's `summary.json` as it was.
fn map_refused(log: &Path, extra: &[&str], says: &str) {
    let before = fs::read(log.join("summary.json")).unwrap();
    swarmmap()
        .args(["map", "--windows", "2", "--overlap", "30"])
        .args(extra)
        .arg(log)
        .assert()
        .code(2)
        .stderr(contains(says));
    assert_eq!(fs::read(log.join("summary.json")).unwrap(), before);
}

/// `swarmmap map --windows 2 --overlap 30 EXTRA LOG`, which must succeed: its stderr.
fn map_warnings(log: &Path, extra: &[&str]) -> String {
    let out = swarmmap()
        .args(["map", "--windows", "2", "--overlap", "30"])
        .args(extra)
        .arg(log)
        .output()
        .unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stderr).unwrap()
}

/// A window far sparser than the shipped model's training windows is warned about (found
/// by the fortieth session's review: a tenth of a log's rows gave dozens of false holes in
/// silence); at a density the model knows, nothing is said.
#[test]
fn map_warns_of_windows_far_sparser_than_the_models_training() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    let map = |extra: &[&str]| {
        let mut args = vec!["--method", "embedded"];
        args.extend_from_slice(extra);
        map_warnings(&log, &args)
    };
    // The tiny world's ≈ 180 encounters a window over as many Rips points: ≈ 1.4 a vertex.
    let sparse = map(&[]);
    assert!(
        sparse.contains("encounters per Rips vertex, far fewer than the 4.39–12.08"),
        "{sparse}"
    );
    assert!(sparse.contains("fewer windows"), "{sparse}");
    // 50 points: ≈ 3.6 a vertex, within the margin of the model's least (4.39 / 1.5).
    let fine = map(&["--set", "mapping.rips_points=50"]);
    assert!(!fine.contains("Rips vertex"), "{fine}");
}

/// `map --sweep` gives a log without a world its leader's sweep: the outlier rank
/// (recorded in each window's JSON) and the models fitted nearest it follow; a sweep that is
/// not a positive speed, or that differs from the world's, is refused with no output.
#[test]
fn map_sweep_picks_the_rank_and_models_of_a_worldless_log() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    // The shipped models, plus a Paper model at the tiny world's 0.02 m/s marked by an H1
    // ratio no data reaches.
    let mut models = swarmmap::mapping::classify::Models::shipped();
    let mut marked = models.paper.0[0].clone();
    marked.leader_speed = Some(0.02);
    marked.events_per_point = None;
    marked.classifier.h1_ratio = 1e9;
    models.paper.0.push(marked);
    let model = tmp.path().join("models.json");
    fs::write(&model, serde_json::to_string(&models).unwrap()).unwrap();
    let windows = |extra: &[&str]| -> Vec<serde_json::Value> {
        swarmmap()
            .arg("--model")
            .arg(&model)
            .args(["map", "--windows", "2", "--overlap", "30"])
            .args(extra)
            .arg(&log)
            .assert()
            .success();
        (1..=2)
            .map(|i| json(&log.join(format!("maps/window_{i}.json"))))
            .collect()
    };
    for (extra, rank, marked) in [
        (&[][..], 8, false),
        (&["--sweep", "0.005"][..], 8, false),
        (&["--sweep", "0.02"][..], 2, true),
        (&["--sweep", "0.0025"][..], 16, false),
        // A rank set in the mapping settings holds whatever the sweep.
        (
            &["--sweep", "0.0025", "--set", "mapping.outlier_rank=5"][..],
            5,
            false,
        ),
        (&["--set", "mapping.outlier_rank=5"][..], 5, false),
    ] {
        for w in windows(extra) {
            assert_eq!(w["outlier_rank"], rank, "{extra:?}");
            assert_eq!(w["classifier"]["h1_ratio"] == 1e9, marked, "{extra:?}");
        }
    }
    for (extra, says) in [
        (
            &["--sweep", "0"][..],
            "--sweep is 0; it is the leader's sweep speed",
        ),
        (&["--sweep", "-0.005"][..], "a positive number"),
        (&["--sweep", "inf"][..], "a positive number"),
        (&["--sweep", "NaN"][..], "a positive number"),
        (
            &["--world", TINY, "--sweep", "0.005"][..],
            "sweeps at 0.02 m/s (its leader.speed)",
        ),
    ] {
        map_refused(&log, extra, says);
    }
    // The world's own sweep is accepted, and maps as the world does.
    swarmmap()
        .args(["map", "--world", TINY, "--sweep", "0.02"])
        .arg(&log)
        .assert()
        .success();
    assert_eq!(json(&log.join("maps/window_1.json"))["outlier_rank"], 2);
    // --method takes the sweep too.
    swarmmap()
        .args([
            "map",
            "--windows",
            "2",
            "--overlap",
            "30",
            "--method",
            "paper",
        ])
        .args(["--sweep", "0.0025"])
        .arg(&log)
        .assert()
        .success();
    assert_eq!(json(&log.join("maps/window_1.json"))["outlier_rank"], 16);
    // A simulated run's world (its meta.json) fixes the sweep as --world does.
    let run = tmp.path().join("run");
    swarmmap()
        .args(["map", "--sweep", "0.005"])
        .arg(&run)
        .assert()
        .code(2)
        .stderr(contains("meta.json) sweeps at 0.02 m/s"))
        .stderr(contains(
            "drop --sweep (the run recorded the sweep it was simulated at)",
        ));
    // A rank the run's world fixes is read back from its meta.json.
    let fixed = tmp.path().join("fixed");
    swarmmap()
        .args([
            "simulate",
            TINY,
            "--quiet",
            "--set",
            "mapping.outlier_rank=5",
            "--out",
        ])
        .arg(&fixed)
        .assert()
        .success();
    swarmmap().arg("map").arg(&fixed).assert().success();
    assert_eq!(json(&fixed.join("maps/window_2.json"))["outlier_rank"], 5);
}

/// A static interval far beyond the encounters (a mistyped end) stretches the windows: the
/// empty window is warned about, and a cluster that reaches only one map is no connection
/// (found by the fortieth session's review: "connections 1–2: 1" was printed beside an
/// empty window 2, in silence).
#[test]
fn an_empty_window_is_warned_about_and_joins_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    let path = log.join("static_intervals.csv");
    let mut text = fs::read_to_string(&path).unwrap();
    let first = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();
    text.push_str(&format!("{first},0,1000000000,landmark\n"));
    fs::write(&path, text).unwrap();
    let stderr = map_warnings(&log, &[]);
    assert!(
        stderr.contains("window 2 holds no encounter")
            && stderr.contains("but the windows are cut over 0–1e9 s"),
        "{stderr}"
    );
    let s = json(&log.join("summary.json"));
    assert_eq!(s["windows"][1]["events"], 0, "{s}");
    assert_eq!(s["connections"][0]["count"], 0, "{s}");
    let c = json(&log.join("maps/connections.json"));
    assert_eq!(c[0]["joins"].as_array().unwrap().len(), 0);
}

/// Each contact logged twice (by both robots, swapped ids and a later clock) and a static
/// interval inside another of its agent are warned of (found by the fortieth session's
/// review: a log doubled this way mapped in silence).
#[test]
fn map_warns_of_contacts_logged_twice_and_overlapping_static_intervals() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    let path = log.join("encounters.csv");
    let text = fs::read_to_string(&path).unwrap();
    let mut out = text.clone();
    for row in text.lines().skip(1).take(5) {
        let f: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        out.push_str(&format!(
            "{},{},{},{}\n",
            f[0] + 0.03,
            f[1] + 0.03,
            f[3],
            f[2]
        ));
    }
    fs::write(&path, out).unwrap();
    let st = log.join("static_intervals.csv");
    let mut text = fs::read_to_string(&st).unwrap();
    text.push_str("0,0,5,pause\n0,1,2,pause\n");
    fs::write(&st, text).unwrap();
    let stderr = map_warnings(&log, &[]);
    assert!(
        stderr.contains("has 5 row(s) overlapping in time an earlier encounter of the same"),
        "{stderr}"
    );
    assert!(
        stderr.contains("static_intervals.csv has 1 interval(s) overlapping"),
        "{stderr}"
    );
    assert!(!stderr.contains("no line end"), "{stderr}");
    // A log cut off mid-row (found by the forty-first session's review).
    let text = fs::read_to_string(&path).unwrap();
    fs::write(&path, text.trim_end()).unwrap();
    let stderr = map_warnings(&log, &[]);
    assert!(
        stderr.contains("encounters.csv's last line has no line end"),
        "{stderr}"
    );
}

/// `--method embedded` on a real log, with and without landmark intervals: every window
/// keeps its component (the method falls back to all encounters where it has no landmark
/// encounters to anchor on), and a log without landmarks is warned about, since nothing can
/// stitch its windows.
#[test]
fn the_embedded_method_maps_a_log_with_or_without_landmarks() {
    let tmp = tempfile::tempdir().unwrap();
    let log = real_log(tmp.path());
    let map = |log: &Path| {
        swarmmap()
            .args([
                "map",
                "--windows",
                "2",
                "--overlap",
                "30",
                "--method",
                "embedded",
            ])
            .arg(log)
            .assert()
            .success()
    };
    let with = map(&log);
    let stderr = String::from_utf8(with.get_output().stderr.clone()).unwrap();
    // (The tiny log is far sparser than the model's training windows: that is warned of.)
    assert!(!stderr.contains("no landmark static intervals"), "{stderr}");
    let s = json(&log.join("summary.json"));
    assert!(
        s["windows"]
            .as_array()
            .unwrap()
            .iter()
            .all(|w| w["betti"][0] == 1),
        "{s}"
    );
    assert_eq!(s["connections"][0]["count"], 1, "{s}");

    fs::remove_file(log.join("static_intervals.csv")).unwrap();
    map(&log).stderr(contains("no landmark static intervals"));
    let s = json(&log.join("summary.json"));
    assert!(
        s["windows"]
            .as_array()
            .unwrap()
            .iter()
            .all(|w| w["betti"][0] == 1),
        "{s}"
    );
    assert_eq!(s["connections"][0]["count"], 0, "{s}");
    assert_eq!(s["global"]["betti"][0], 2, "{s}");
}

/// `map --windows` takes the range a world file's `mapping.windows` takes: 0 windows map
/// nothing, and 100 000 windows of a short log ran for minutes writing one file each.
#[test]
fn map_rejects_a_window_count_outside_1_to_10000() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(
        tmp.path().join("encounters.csv"),
        "start,end,a,b\n1.0,2.0,0,1\n",
    )
    .unwrap();
    for n in ["0", "10001"] {
        swarmmap()
            .args(["map", "--windows", n])
            .arg(tmp.path())
            .assert()
            .code(2)
            .stderr(contains(format!(
                "--windows is {n}; use 1 to 10000 windows"
            )));
    }
}

#[test]
fn a_malformed_log_names_the_line_and_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(
        tmp.path().join("encounters.csv"),
        "start,end,a,b\n1.0,2.0,0,1\n3.0,oops,1,2\n",
    )
    .unwrap();
    swarmmap()
        .arg("map")
        .arg(tmp.path())
        .assert()
        .code(2)
        .stderr(contains(
            "encounters.csv:3: column `end` is `oops`, which is not a number",
        ));
    fs::write(
        tmp.path().join("encounters.csv"),
        "start,end,a,b\n5.0,2.0,0,1\n",
    )
    .unwrap();
    swarmmap()
        .arg("map")
        .arg(tmp.path())
        .assert()
        .code(2)
        .stderr(contains("encounters.csv:2: end 2 is before start 5"));
}

/// Regression: a log with finite but absurd times (1e200 s) panicked in the `Embedded`
/// mapping: the landmarks' encounters are close to each other, but landmark MDS squares the
/// rows to every other encounter, which overflowed, and the embedding came back with no
/// points. Such times are now rejected where they are read, with the line and a hint, and
/// exit 2 (this log panicked the previous build).
#[test]
fn a_log_with_absurd_times_is_rejected_not_mapped() {
    let tmp = tempfile::tempdir().unwrap();
    let rows: String = (0..400)
        .map(|i| {
            let (a, b) = (i % 20, (i * 7 + 3) % 20);
            let b = if a == b { (b + 1) % 20 } else { b };
            let t = i as f64 * 5e197;
            format!("{t:e},{:e},{},{}\n", t + 1e195, a.min(b), a.max(b))
        })
        .collect();
    fs::write(
        tmp.path().join("encounters.csv"),
        format!("start,end,a,b\n{rows}"),
    )
    .unwrap();
    fs::write(
        tmp.path().join("static_intervals.csv"),
        "agent,start,end,reason\n0,0,2e200,landmark\n1,0,2e200,landmark\n2,0,2e200,landmark\n",
    )
    .unwrap();
    swarmmap()
        .args(["map", "--method", "embedded"])
        .arg(tmp.path())
        .assert()
        .code(2)
        .stderr(contains(
            "encounters.csv:2: column `end` is `1e195`, beyond ±1e12 s",
        ))
        .stderr(contains("panicked").not());
}

/// Found by the forty-first session's review: two world files of one name were merged
/// into one row of the table (their seeds paired as one world's), and a name with a comma
/// or a quote broke the rows of `eval.csv` and `summary.csv`.
#[test]
fn eval_refuses_two_worlds_of_one_name_and_quotes_names_in_its_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let tiny = fs::read_to_string(TINY).unwrap();
    let other = tmp.path().join("other.ron");
    fs::write(&other, tiny.replace("agents: 40", "agents: 30")).unwrap();
    let out = tmp.path().join("same");
    swarmmap()
        .args(["eval", TINY])
        .arg(&other)
        .args(["--seeds", "1", "--quiet", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains("are both named `tiny`"));
    let odd = tmp.path().join("odd.ron");
    fs::write(
        &odd,
        tiny.replace("name: \"tiny\"", r#"name: "tiny, \"v2\"""#),
    )
    .unwrap();
    let out = tmp.path().join("odd");
    swarmmap()
        .arg("eval")
        .arg(&odd)
        .args(["--seeds", "1", "--quiet", "--out"])
        .arg(&out)
        .assert()
        .success();
    for file in ["eval.csv", "summary.csv"] {
        let mut reader = csv::Reader::from_path(out.join(file)).unwrap();
        let header = reader.headers().unwrap().len();
        let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(rows.len(), 1, "{file}");
        assert_eq!(rows[0].len(), header, "{file}: {:?}", rows[0]);
        assert_eq!(&rows[0][0], r#"tiny, "v2""#, "{file}");
    }
}

#[test]
fn eval_writes_one_row_per_run_and_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("eval");
    let args = [
        "eval", TINY, "--seeds", "1..2", "--jobs", "2", "--quiet", "--out",
    ];
    swarmmap()
        .args(args)
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("tiny"))
        .stdout(contains("95% Wilson interval"));
    let csv = fs::read_to_string(out.join("eval.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    // One summary row for the one (world, params) group, with the global figure's interval.
    let summary = fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 2, "{summary}");
    assert!(
        summary.starts_with("world,params,runs,failed,"),
        "{summary}"
    );
    assert!(
        summary.lines().nth(1).unwrap().starts_with("tiny,,2,0,"),
        "{summary}"
    );
    let stored: Vec<_> = fs::read_dir(out.join("runs")).unwrap().collect();
    assert_eq!(stored.len(), 2);
    // A rerun finds both runs done and writes the same rows.
    let before = fs::metadata(out.join("runs")).unwrap().modified().unwrap();
    swarmmap().args(args).arg(&out).assert().success();
    assert_eq!(fs::read_to_string(out.join("eval.csv")).unwrap(), csv);
    assert_eq!(
        fs::metadata(out.join("runs")).unwrap().modified().unwrap(),
        before
    );
    // A typo in a sweep fails at once, with status 2.
    swarmmap()
        .args(["eval", TINY, "--set", "swarm.agentz=10", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(contains("agentz"));
}

/// The stored runs of an `eval` into `out`, by (params, seed).
fn stored_runs(out: &Path) -> std::collections::BTreeMap<(String, u64), serde_json::Value> {
    fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| {
            let rec = json(&e.unwrap().path());
            let key = (
                rec["params"].as_str().unwrap().to_string(),
                rec["seed"].as_u64().unwrap(),
            );
            (key, rec)
        })
        .collect()
}

/// A sweep of mapping settings simulates each seed once (the variants of a seed carry the
/// one simulation's time) and scores every variant exactly as a campaign of that variant
/// alone, which simulates for itself.
#[test]
fn eval_shares_one_simulation_among_mapping_variants() {
    let tmp = tempfile::tempdir().unwrap();
    let eval = |dir: &str, cutoffs: &str| {
        let out = tmp.path().join(dir);
        swarmmap()
            .args([
                "eval", TINY, "--seeds", "1,2", "--jobs", "2", "--quiet", "--set",
            ])
            .arg(format!("mapping.cluster_cutoff={cutoffs}"))
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        stored_runs(&out)
    };
    let swept = eval("swept", "20,50");
    assert_eq!(swept.len(), 4, "{:?}", swept.keys());
    let without_timings = |rec: &serde_json::Value| {
        let mut s = rec["summary"].clone();
        s.as_object_mut().unwrap().remove("timings");
        s
    };
    let key = |cutoff: &str, seed: u64| (format!("mapping.cluster_cutoff={cutoff}"), seed);
    for seed in [1, 2] {
        let (a, b) = (&swept[&key("20", seed)], &swept[&key("50", seed)]);
        assert!(a["summary"]["timings"]["simulation"].is_f64(), "{a}");
        assert_eq!(
            a["summary"]["timings"]["simulation"], b["summary"]["timings"]["simulation"],
            "seed {seed}: the two cut-offs share one simulation"
        );
    }
    for cutoff in ["20", "50"] {
        let own = eval(&format!("alone{cutoff}"), cutoff);
        for seed in [1, 2] {
            assert_eq!(
                without_timings(&swept[&key(cutoff, seed)]),
                without_timings(&own[&key(cutoff, seed)]),
                "seed {seed}, cut-off {cutoff}"
            );
        }
    }
}

/// Two parameter sets that give one world (a world without obstacles scaled, a value
/// written twice) are warned of, and their runs are made once: both records hold the same
/// summary, timings included.
#[test]
fn eval_warns_of_parameter_sets_that_give_one_world_and_runs_it_once() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("eval");
    swarmmap()
        .args(["eval", TINY, "--seeds", "1", "--quiet"])
        .args(["--set", "mapping.cluster_cutoff=50,50.0", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stderr(contains(
            "`--set mapping.cluster_cutoff=50` and `--set mapping.cluster_cutoff=50.0` give \
             the same world",
        ));
    let runs = stored_runs(&out);
    let summaries: Vec<_> = runs.values().map(|r| r["summary"].clone()).collect();
    assert_eq!(summaries.len(), 2);
    assert!(summaries[0].is_object(), "{:?}", summaries[0]);
    assert_eq!(summaries[0], summaries[1]);
}

/// The shipped model file with every method's thresholds replaced.
fn model_file(dir: &Path, name: &str, h1_ratio: f64, h1_span: f64) -> std::path::PathBuf {
    let mut m = json(Path::new("assets/classifier.json"));
    for method in ["Paper", "Embedded", "Oracle"] {
        // An entry is one model or a bank of them (one per sampling density): set every one.
        let models = match m[method].as_array_mut() {
            Some(bank) => bank.iter_mut().collect::<Vec<_>>(),
            None => vec![&mut m[method]],
        };
        for model in models {
            model["classifier"]["h1_ratio"] = serde_json::json!(h1_ratio);
            model["classifier"]["h1_span"] = serde_json::json!(h1_span);
        }
    }
    let path = dir.join(name);
    fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    path
}

/// A campaign rerun with `--model FILE` into a directory of runs judged by the shipped
/// models maps them again (the stored runs are keyed by the model too) instead of reusing
/// scores another model gave; a rerun with the same file reuses its own runs.
#[test]
fn eval_does_not_reuse_runs_judged_by_another_model() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("eval");
    let eval = |model: Option<&Path>| {
        let mut cmd = swarmmap();
        if let Some(m) = model {
            cmd.arg("--model").arg(m);
        }
        cmd.args(["eval", TINY, "--seeds", "1", "--quiet", "--out"])
            .arg(&out)
            .assert()
            .success();
        fs::read_to_string(out.join("eval.csv")).unwrap()
    };
    let shipped = eval(None);
    // Every H1 bar is a hole: each window shows at least one (the shipped model finds
    // none on this seed).
    let lenient = model_file(tmp.path(), "lenient.json", 1.0, 0.0);
    let judged = eval(Some(&lenient));
    assert_eq!(fs::read_dir(out.join("runs")).unwrap().count(), 2);
    // The window Betti numbers, column 18 (not the row: its `seconds` differ anyway).
    let betti = |csv: &str| {
        csv.lines()
            .nth(1)
            .unwrap()
            .split(',')
            .nth(18)
            .unwrap()
            .to_string()
    };
    assert_eq!(betti(&shipped), "1:0 1:0", "{shipped}");
    assert!(
        betti(&judged).split(' ').all(|w| !w.ends_with(":0")),
        "{judged}"
    );
    assert_eq!(eval(Some(&lenient)), judged);
    assert_eq!(eval(None), shipped);
    assert_eq!(fs::read_dir(out.join("runs")).unwrap().count(), 2);
}

/// `swarmmap map DIR --model MODEL`.
fn map_with(dir: &Path, model: &Path) -> assert_cmd::assert::Assert {
    swarmmap()
        .arg("map")
        .arg(dir)
        .arg("--model")
        .arg(model)
        .assert()
}

/// `--model FILE` judges the diagrams with FILE's thresholds (recorded in each window's
/// map), and a bad model file is refused with its place and exit status 2 before anything
/// is written.
#[test]
fn a_model_file_replaces_the_shipped_thresholds() {
    let (tmp, dir) = tiny_run_without_report();
    // No H1 bar of a finite diagram has death / birth ≥ 10⁹: no hole anywhere.
    let strict = model_file(tmp.path(), "strict.json", 1e9, 0.0);
    map_with(&dir, &strict).success();
    let s = json(&dir.join("summary.json"));
    for w in s["windows"].as_array().unwrap() {
        assert_eq!(w["betti"][1], 0, "{w}");
    }
    assert_eq!(s["global"]["betti"][1], 0, "{}", s["global"]);
    let w1 = json(&dir.join("maps/window_1.json"));
    assert_eq!(w1["classifier"]["h1_ratio"], 1e9);
    // The most lenient rule keeps every H1 bar: the tiny world's hole is among them.
    let lenient = model_file(tmp.path(), "lenient.json", 1.0, 0.0);
    map_with(&dir, &lenient).success();
    let s = json(&dir.join("summary.json"));
    let holes: u64 = s["windows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["betti"][1].as_u64().unwrap())
        .sum();
    assert!(holes >= 1, "{s}");
    assert_eq!(
        json(&dir.join("maps/window_1.json"))["classifier"]["h1_ratio"],
        1.0
    );
    // Bad model files: the summary stays as the last good map wrote it.
    let before_bad = fs::read(dir.join("summary.json")).unwrap();
    let broken = tmp.path().join("broken.json");
    fs::write(&broken, "{\n  \"Paper\": 1\n}\n").unwrap();
    let out_of_range = model_file(tmp.path(), "range.json", 0.5, 0.0);
    let missing = tmp.path().join("missing.json");
    for (file, says) in [
        (&broken, "broken.json:2:"),
        (&out_of_range, "out of range"),
        // The place of the model out of range (found by the fortieth session's review: the
        // message named only the file), and the place given once, not again at its end.
        (
            &out_of_range,
            "range.json:14:3: the Embedded model's thresholds (h0_ratio",
        ),
        (
            &broken,
            "expected a model object or a list of model objects; a model file",
        ),
        (&missing, "cannot read the model file"),
    ] {
        map_with(&dir, file).code(2).stderr(contains(says));
        assert_eq!(fs::read(dir.join("summary.json")).unwrap(), before_bad);
    }
}
