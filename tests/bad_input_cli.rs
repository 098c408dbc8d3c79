//! Bad input found by an adversarial pass over the command line (thirty-third session):
//! each case exits with an error that says what and how to fix, or, for outputs an earlier
//! run left behind, removes them instead of mixing them with the new run's.

use assert_cmd::Command;
use predicates::prelude::PredicateBooleanExt;
use predicates::str::contains;
use std::fs;
use std::path::Path;

const TINY: &str = "tests/fixtures/worlds/tiny.ron";

fn swarmmap() -> Command {
    Command::cargo_bin("swarmmap").expect("binary built")
}

/// `swarmmap simulate` (or `run`) of the tiny world into `dir/r`.
fn tiny_run(dir: &Path, command: &str) -> std::path::PathBuf {
    let run = dir.join("r");
    swarmmap()
        .args([command, TINY, "--quiet", "--out"])
        .arg(&run)
        .assert()
        .success();
    run
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// A value far from the metres and seconds of a world is echoed with an exponent, not as
/// hundreds of digits, and the numbers computed from it likewise.
#[test]
fn huge_and_tiny_values_are_written_with_an_exponent_in_messages() {
    for (set, says) in [
        ("swarm.speed=1e200", "walking at 1e200 m/s"),
        (
            "obstacles=[Circle(center: (1e250, 5), radius: 1)]",
            "spans x 1e250 to 1e250, y 4 to 6 m",
        ),
        ("swarm.landmark_fraction=1e40", "is 1e40 (must be in [0, 1)"),
        ("leader.window=1e20", "is 1e20 m, longer than the arena"),
        ("leader.start_x=1e30", "is 1e30 m, outside"),
        ("swarm.body_radius=1e30", "is 1e30 m, not below half"),
        (
            "swarm.wall_following=1e99",
            "is 1e99 (must be a probability",
        ),
        ("simulation.dt=1e-300", "simulation.dt is 1e-300 s, so the"),
        (
            "mapping.overlap=1e300",
            "mapping.overlap is 1e300 s, not shorter",
        ),
        (
            "obstacles=[Rect(min: (1e300, 1), max: (2, 2))]",
            "max is (2, 2) but min is (1e300, 1)",
        ),
        (
            "swarm.placement=Disk(radius: 1e-300)",
            "is a disc of radius 1e-300 m around",
        ),
        (
            "leader.speed=1e-320",
            "leader.speed is 1e-320 m/s, so the sweep from x = ",
        ),
    ] {
        let out = swarmmap()
            .args(["check", TINY, "--set", set])
            .assert()
            .code(2)
            .stderr(contains(says))
            .get_output()
            .stderr
            .clone();
        let text = String::from_utf8(out).unwrap();
        assert!(
            !text.contains("0000000000"),
            "{set}: a number is written out in full: {text}"
        );
    }
}

/// `swarmmap check WORLD --set ...` with every set in `sets`.
fn check_with(world: &str, sets: &[&str]) -> std::process::Output {
    let mut c = swarmmap();
    c.args(["check", world]);
    for s in sets {
        c.args(["--set", s]);
    }
    c.output().unwrap()
}

/// The text of `stderr` between `before` and the first `until` after it.
fn between<'t>(stderr: &'t str, before: &str, until: &str) -> &'t str {
    stderr
        .split(before)
        .nth(1)
        .and_then(|rest| rest.split(until).next())
        .unwrap_or_else(|| panic!("no {before:?} in: {stderr}"))
}

/// The largest time step the encounter check suggests is one it accepts: rounded down, not
/// to the nearest (0.0166667 s would still be refused for r_d = 1 cm at 0.3 m/s).
#[test]
fn the_suggested_time_step_passes_the_check() {
    let sets = [
        "swarm.detection_radius=0.01",
        "swarm.body_radius=0.004",
        "swarm.speed=0.3",
    ];
    let refused = check_with(TINY, &[&sets[..], &["simulation.dt=0.03"]].concat());
    assert_eq!(refused.status.code(), Some(2));
    let text = String::from_utf8(refused.stderr).unwrap();
    let suggested = between(&text, "set simulation.dt ≤ r_d / (2·speed) = ", " ");
    assert_eq!(suggested, "0.0166666");
    let dt = format!("simulation.dt={suggested}");
    let accepted = check_with(TINY, &[&sets[..], &[dt.as_str()]].concat());
    assert!(accepted.status.success(), "{dt} refused");
}

/// Every bound a message proposes is one the check accepts: both ends of the leader's range
/// when the window nearly fills the arena (once two backwards values), and the largest
/// overlap when one window lasts 814.2857… s (once rounded up to 814.286).
#[test]
fn suggested_ranges_and_overlaps_pass_the_check() {
    let narrow = [
        "obstacles=[]",
        "arena.width=7.777777",
        "leader.window=7.777776",
    ];
    let out = check_with(TINY, &[&narrow[..], &["leader.start_x=0"]].concat());
    let text = String::from_utf8(out.stderr).unwrap();
    let range = between(&text, "use an x between ", ", or leave");
    let (lo, hi) = range.split_once(" and ").unwrap();
    assert!(
        lo.parse::<f64>().unwrap() <= hi.parse::<f64>().unwrap(),
        "{range}"
    );
    for x in [lo, hi] {
        let start = format!("leader.start_x={x}");
        let o = check_with(TINY, &[&narrow[..], &[start.as_str()]].concat());
        let e = String::from_utf8(o.stderr).unwrap();
        assert!(!e.contains("leader.start_x is"), "{x} refused: {e}");
    }

    let seven = ["mapping.windows=7", "simulation.dispersion_time=300"];
    let scenario2 = "worlds/scenario2.ron";
    let out = check_with(scenario2, &[&seven[..], &["mapping.overlap=900"]].concat());
    let text = String::from_utf8(out.stderr).unwrap();
    let below = between(&text, "use an overlap Δt below ", " ");
    assert_eq!(below, "814.285");
    let overlap = format!("mapping.overlap={below}");
    let accepted = check_with(scenario2, &[&seven[..], &[overlap.as_str()]].concat());
    assert!(accepted.status.success(), "{overlap} refused");
}

#[test]
fn world_values_the_physics_cannot_represent_are_refused() {
    swarmmap()
        .args(["check", TINY, "--set", "arena.height=1e300"])
        .assert()
        .code(2)
        .stderr(
            contains("arena.height is 1e300 m, more than 10000 m").and(contains("at most 10 km")),
        );
    // A radius beyond the arena's diagonal overflowed Rapier's f32 and recorded nothing.
    swarmmap()
        .args(["check", TINY, "--set", "swarm.detection_radius=1e39"])
        .assert()
        .code(2)
        .stderr(contains(
            "swarm.detection_radius is 1e39 m, more than the arena's diagonal",
        ));
}

#[test]
fn world_files_with_a_byte_order_mark_or_bytes_that_are_not_utf8() {
    let tmp = tempfile::tempdir().unwrap();
    let text = fs::read(TINY).unwrap();
    let bom = tmp.path().join("bom.ron");
    fs::write(&bom, [b"\xef\xbb\xbf".as_slice(), &text].concat()).unwrap();
    swarmmap()
        .args(["check"])
        .arg(&bom)
        .assert()
        .success()
        .stdout(contains("tiny"));
    let latin1 = tmp.path().join("latin1.ron");
    fs::write(&latin1, b"(\n  name: \"caf\xe9\",\n)").unwrap();
    swarmmap()
        .args(["check"])
        .arg(&latin1)
        .assert()
        .code(2)
        .stderr(contains(
            "latin1.ron:2:13: this byte is not UTF-8 text; save the world file as UTF-8",
        ));
    let negative = tmp.path().join("neg.ron");
    let t = String::from_utf8(text)
        .unwrap()
        .replace("seed: 3", "seed: -1");
    fs::write(&negative, t).unwrap();
    swarmmap()
        .args(["check"])
        .arg(&negative)
        .assert()
        .code(2)
        .stderr(contains("this whole number is out of range for its field"));
}

#[test]
fn thread_counts_are_bounded() {
    swarmmap()
        .args(["eval", TINY, "--seeds", "1..1", "--jobs", "10000"])
        .assert()
        .code(2)
        .stderr(contains("10000 threads is too many; use at most 1024"));
    swarmmap()
        .args(["persistence", "points.csv", "--threads", "5000"])
        .assert()
        .code(2)
        .stderr(contains("use at most 1024"));
}

#[test]
fn a_model_threshold_near_the_largest_float_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let mut m: serde_json::Value =
        serde_json::from_str(&fs::read_to_string("assets/classifier.json").unwrap()).unwrap();
    m["Paper"]["classifier"]["h1_span"] = serde_json::json!(1e308);
    let path = tmp.path().join("m.json");
    fs::write(&path, m.to_string()).unwrap();
    swarmmap()
        .arg("--model")
        .arg(&path)
        .args(["check", TINY])
        .assert()
        .code(2)
        .stderr(contains("h1_span 1e308").and(contains("at most 1e12")));
}

#[test]
fn map_refuses_an_overlap_as_long_as_a_window_and_drops_the_old_windows() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    // tiny: 210 s of log.
    swarmmap()
        .arg("map")
        .arg(&run)
        .args(["--windows", "2", "--overlap", "1e9"])
        .assert()
        .code(2)
        .stderr(contains(
            "--overlap is 1e9 s, not shorter than one window (105 s = 210 s of log / 2 windows)",
        ));
    swarmmap()
        .arg("map")
        .arg(&run)
        .args(["--windows", "100"])
        .assert()
        .code(2)
        .stderr(contains(
            "the world's mapping.overlap is 30 s, not shorter than one window (2.1 s",
        ));
    // Five windows, then two: the files of windows 3-5 and their figures go.
    for n in ["5", "2"] {
        swarmmap()
            .arg("map")
            .arg(&run)
            .args(["--windows", n, "--overlap", "10"])
            .assert()
            .success();
    }
    assert_eq!(
        names(&run.join("maps")),
        [
            "connection_1.json",
            "connections.json",
            "global.json",
            "window_1.json",
            "window_2.json"
        ]
    );
    let figures = names(&run.join("report"));
    assert!(
        figures.contains(&"window_2_diagram.svg".to_string()),
        "{figures:?}"
    );
    assert!(
        !figures
            .iter()
            .any(|f| f.starts_with("window_3") || f.starts_with("connection_2")),
        "{figures:?}"
    );
}

#[test]
fn a_new_simulation_removes_what_was_derived_from_the_old_log() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    fs::write(run.join("notes.txt"), "mine").unwrap();
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--seed", "9", "--out"])
        .arg(&run)
        .assert()
        .success();
    assert_eq!(
        names(&run),
        [
            "encounters.csv",
            "leader.csv",
            "maps",
            "meta.json",
            "notes.txt",
            "report",
            "static_intervals.csv"
        ]
    );
    assert!(names(&run.join("maps")).is_empty());
    assert!(names(&run.join("report")).is_empty());
    // The report now asks for maps of the new log instead of showing the old ones.
    swarmmap().arg("report").arg(&run).assert().failure();
}

#[test]
fn a_mapping_that_fails_midway_leaves_no_summary_or_report_of_other_maps() {
    // Found by an adversarial pass (thirty-seventh session): the new windows 1-2 were
    // written, window 3 failed, and the old summary.json and report stayed beside them;
    // `swarmmap report` then drew the mismatched files without a word.
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    assert!(run.join("report/index.html").exists() && run.join("summary.json").exists());
    fs::create_dir(run.join("maps/window_3.json")).unwrap();
    swarmmap()
        .arg("map")
        .arg(&run)
        .args(["--windows", "3", "--overlap", "10"])
        .assert()
        .code(1)
        .stderr(contains("window_3.json"));
    assert!(!run.join("summary.json").exists());
    assert!(!run.join("report/index.html").exists());
    assert!(
        !names(&run.join("report"))
            .iter()
            .any(|f| f.ends_with(".svg")),
        "old figures left"
    );
    swarmmap()
        .arg("report")
        .arg(&run)
        .assert()
        .code(2)
        .stderr(contains("swarmmap map RUN_DIR"));
    // Once the obstacle is gone the same command maps and reports again.
    fs::remove_dir(run.join("maps/window_3.json")).unwrap();
    swarmmap()
        .arg("map")
        .arg(&run)
        .args(["--windows", "3", "--overlap", "10"])
        .assert()
        .success();
    swarmmap().arg("report").arg(&run).assert().success();
}

#[test]
fn a_replacement_that_fails_halfway_leaves_the_old_run_marked_for_the_next() {
    // Found in review (thirty-seventh session): had `meta.json` gone first, a removal that
    // failed later would leave the old trajectories unmarked, and the next run (recording
    // none) would keep them beside its own log.
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("r");
    swarmmap()
        .args([
            "run",
            TINY,
            "--quiet",
            "--seed",
            "1",
            "--trajectories",
            "1",
            "--out",
        ])
        .arg(&run)
        .assert()
        .success();
    fs::remove_dir_all(run.join("maps")).unwrap();
    fs::write(run.join("maps"), "in the way").unwrap();
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--seed", "2", "--out"])
        .arg(&run)
        .assert()
        .code(1);
    // Still marked as the old run, whose log and trajectories are intact.
    assert!(run.join("meta.json").exists() && run.join("trajectories.csv").exists());
    fs::remove_file(run.join("maps")).unwrap();
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--seed", "2", "--out"])
        .arg(&run)
        .assert()
        .success();
    assert!(!run.join("trajectories.csv").exists(), "{:?}", names(&run));
    let meta: serde_json::Value =
        serde_json::from_slice(&fs::read(run.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["seed"], 2);
}

#[test]
fn an_output_path_that_is_a_file_is_named_once_with_the_fix() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("afile");
    fs::write(&file, "x").unwrap();
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--out"])
        .arg(&file)
        .assert()
        .code(2)
        .stderr(
            contains("it is a file, not a directory; give --out a new or existing directory")
                .and(contains("File exists").not()),
        );
    assert_eq!(fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn an_output_directory_that_cannot_be_written_is_refused_before_simulating() {
    // Found by an adversarial pass (thirty-seventh session): `simulate` ran the whole
    // simulation, then failed to write it. A sweep this slow takes minutes; the refusal
    // must come at once (the timeout fails the test otherwise).
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("afile");
    fs::write(&file, "x").unwrap();
    let beneath = file.join("sub");
    for command in ["simulate", "run"] {
        for out in [&file, &beneath] {
            swarmmap()
                .args([
                    command,
                    TINY,
                    "--quiet",
                    "--set",
                    "leader.speed=0.00005",
                    "--out",
                ])
                .arg(out)
                .timeout(std::time::Duration::from_secs(20))
                .assert()
                .code(2)
                .stderr(contains(out.display().to_string()));
        }
    }
    assert_eq!(names(tmp.path()), ["afile"]);
    assert_eq!(fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn a_campaign_refuses_the_same_run_listed_twice() {
    // Found by an adversarial pass (thirty-seventh session): `--seeds 1,1,...` counted ten
    // copies of one run as ten independent runs in the 95 % interval.
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("ev");
    let dotted = format!("./{TINY}");
    let cases: [(&[&str], &str); 7] = [
        (&[TINY, "--seeds", "1,2,1"], "seed 1 is listed twice"),
        (
            &[TINY, TINY, "--seeds", "1"],
            "is given twice; give each world once",
        ),
        (
            &[TINY, &dotted, "--seeds", "1"],
            "is given twice (also as tests/fixtures/worlds/tiny.ron)",
        ),
        (
            &[TINY, "--seeds", "1", "--set", "swarm.agents=3,3"],
            "the value 3 is listed twice",
        ),
        (
            &[
                TINY,
                "--seeds",
                "1",
                "--set",
                "swarm.agents=3",
                "--set",
                "swarm.agents=4",
            ],
            "--set swarm.agents is given twice",
        ),
        (
            &[
                TINY,
                "--seeds",
                "1",
                "--set",
                "swarm.agents=3,4",
                "--set",
                "swarm=(speed: 0.1)",
            ],
            "--set swarm replaces the whole of what an earlier --set swarm.agents set",
        ),
        (
            &[
                TINY,
                "--seeds",
                "1",
                "--set",
                "obstacles[00]=None",
                "--set",
                "obstacles[0]=None",
            ],
            "--set obstacles[0] is given twice",
        ),
    ];
    for (args, says) in cases {
        swarmmap()
            .arg("eval")
            .args(args)
            .args(["--quiet", "--out"])
            .arg(&out)
            .assert()
            .code(2)
            .stderr(contains(says));
    }
    assert!(!out.exists(), "refused before any run");
    swarmmap()
        .args(["calibrate", TINY, TINY, "--seeds", "1..1", "--out"])
        .arg(tmp.path().join("new").join("m.json"))
        .assert()
        .code(2)
        .stderr(contains("is given twice"));
    // The output's directory is only checked, not made, before the refusal.
    assert!(!tmp.path().join("new").exists());
}

#[test]
fn a_field_set_twice_is_refused_by_every_command() {
    // Before, `run`, `simulate`, `check` and `calibrate` let the last `--set` of a field win
    // unseen, so `--set swarm.agents=3 --set swarm.agents=4` ran 4 agents without a word.
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let twice = ["--set", "swarm.agents=3", "--set", " swarm.agents = 4"];
    for command in [
        &["check"][..],
        &["simulate", "--quiet"],
        &["run", "--no-report"],
    ] {
        let mut cmd = swarmmap();
        cmd.args(command).arg(TINY).args(twice);
        if command[0] != "check" {
            cmd.arg("--out").arg(&out);
        }
        cmd.assert().code(2).stderr(contains(
            "--set swarm.agents is given twice (`swarm.agents=3`, then ` swarm.agents = 4`), so one value would be lost",
        ));
    }
    swarmmap()
        .args(["calibrate", TINY, "--seeds", "1..1"])
        .args(twice)
        .arg("--out")
        .arg(tmp.path().join("m.json"))
        .assert()
        .code(2)
        .stderr(contains("--set swarm.agents is given twice"));
    assert!(!out.exists() && !tmp.path().join("m.json").exists());
    // A section after one of its fields would drop the field; found in review.
    let circle = "Circle(center: (1.0, 1.0), radius: 0.2)";
    for (first, then, says) in [
        (
            "swarm.agents=3",
            "swarm=(speed: 0.1)",
            "--set swarm replaces the whole of what an earlier --set swarm.agents set",
        ),
        (
            "obstacles.scale=2",
            "obstacles=[]",
            "--set obstacles replaces the whole of what an earlier --set obstacles.scale set",
        ),
        (
            "obstacles[00]=C",
            "obstacles[0]=C",
            "--set obstacles[0] is given twice",
        ),
    ] {
        swarmmap()
            .args(["check", TINY, "--set"])
            .arg(first.replace('C', circle))
            .arg("--set")
            .arg(then.replace('C', circle))
            .assert()
            .code(2)
            .stderr(contains(says));
    }
    // Different fields, a section and then its fields, and scale factors (they compose)
    // are fine.
    for sets in [
        &["swarm.agents=3", "seed=2"][..],
        &["swarm=(speed: 0.1)", "swarm.agents=3"],
        &["obstacles.scale=0.5", "obstacles.scale=0.5"],
    ] {
        let mut cmd = swarmmap();
        cmd.args(["check", TINY]);
        for s in sets {
            cmd.args(["--set", s]);
        }
        cmd.assert().success();
    }
}

#[test]
fn smaller_findings_of_an_adversarial_pass() {
    let tmp = tempfile::tempdir().unwrap();
    let log = |name: &str, text: &str| {
        let dir = tmp.path().join(name);
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("encounters.csv"), text).unwrap();
        dir
    };
    // An empty file says so, not "found: " nothing.
    let empty = log("empty", "");
    swarmmap()
        .arg("map")
        .arg(&empty)
        .assert()
        .code(2)
        .stderr(contains(
            "encounters.csv:1: the file is empty; it needs a header line",
        ));
    // A log at one instant cannot be cut into windows (no --overlap or --windows helps).
    let instant = log("instant", "start,end,a,b\n0,0,0,1\n0,0,1,2\n");
    swarmmap()
        .arg("map")
        .arg(&instant)
        .args(["--windows", "1", "--overlap", "0"])
        .assert()
        .code(2)
        .stderr(contains("the log spans no time").and(contains("--overlap below").not()));
    // Without truth columns no window has an oracle, not even an empty one. Three
    // encounters are all noise, and `map` says why the maps are empty.
    let sparse = log("sparse", "start,end,a,b\n0,1,0,1\n1,2,1,2\n90,91,0,2\n");
    swarmmap()
        .arg("map")
        .arg(&sparse)
        .args(["--windows", "3", "--overlap", "1"])
        .assert()
        .success()
        .stderr(contains("judged noise (β0 = 0 everywhere)").and(contains("3 encounter(s)")));
    let summary: serde_json::Value =
        serde_json::from_slice(&fs::read(sparse.join("summary.json")).unwrap()).unwrap();
    for w in summary["windows"].as_array().unwrap() {
        assert!(w["fidelity"]["oracle"].is_null(), "{w}");
    }
    // `obstacles[i]` on a world without obstacles.
    swarmmap()
        .args(["check", "worlds/empty.ron", "--set"])
        .arg("obstacles[5]=Circle(center: (1.0, 1.0), radius: 0.2)")
        .assert()
        .code(2)
        .stderr(contains("the world has no obstacles").and(contains("from 0 to").not()));
    // A missing file or a directory is bad input for `persistence` too (status 2).
    for path in [tmp.path().join("none.csv"), tmp.path().to_path_buf()] {
        swarmmap()
            .arg("persistence")
            .arg(&path)
            .assert()
            .code(2)
            .stderr(contains("cannot read"));
    }
    // A campaign directory that is a file: refused up front (status 2).
    swarmmap()
        .args(["eval", TINY, "--seeds", "1", "--quiet", "--out"])
        .arg(empty.join("encounters.csv"))
        .assert()
        .code(2)
        .stderr(contains("is a file, not a directory"));
}

#[test]
fn stored_runs_of_another_build_are_made_again() {
    // The adversarial pass of the thirty-seventh session: `eval` and `calibrate --runs`
    // reused runs whatever build had made them, so an upgrade judged old maps as new.
    // Another build here: a copy of the binary with one byte appended (still runnable).
    let tmp = tempfile::tempdir().unwrap();
    let other = tmp.path().join("swarmmap-other");
    let mut bytes = fs::read(assert_cmd::cargo::cargo_bin("swarmmap")).unwrap();
    bytes.push(0);
    fs::write(&other, bytes).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        fs::set_permissions(&other, fs::Permissions::from_mode(0o755)).unwrap();
    }
    let build_of = |dir: &Path| -> String {
        let runs = dir.join("runs");
        let file = runs.join(&names(&runs)[0]);
        let v: serde_json::Value = serde_json::from_slice(&fs::read(file).unwrap()).unwrap();
        v["build"].as_str().unwrap().to_string()
    };
    let ev = tmp.path().join("ev");
    let eval = |cmd: &mut Command, extra: &[&str]| {
        cmd.args(["eval", TINY, "--seeds", "1", "--quiet", "--out"])
            .arg(&ev)
            .args(extra)
            .assert()
            .success();
    };
    eval(&mut swarmmap(), &[]);
    let first = build_of(&ev);
    eval(&mut Command::new(&other), &[]);
    let second = build_of(&ev);
    assert_ne!(
        first, second,
        "the other build ran it again and recorded itself"
    );
    assert_eq!(
        names(&ev.join("runs")).len(),
        1,
        "the run's file was replaced"
    );
    // Asked to, a build reuses what another made.
    eval(&mut swarmmap(), &["--reuse-any-build"]);
    assert_eq!(build_of(&ev), second);

    let runs = tmp.path().join("cal");
    let calibrate = |cmd: &mut Command, extra: &[&str], says: &str| {
        cmd.args(["calibrate", TINY, "--seeds", "1..1", "--out"])
            .arg(tmp.path().join("m.json"))
            .arg("--runs")
            .arg(&runs)
            .args(extra)
            .assert()
            .success()
            .stderr(contains(says));
    };
    calibrate(&mut swarmmap(), &[], "seed 1 done");
    calibrate(&mut swarmmap(), &[], "seed 1 reused");
    calibrate(&mut Command::new(&other), &[], "seed 1 done");
    calibrate(&mut swarmmap(), &["--reuse-any-build"], "seed 1 reused");
}

#[test]
fn a_world_name_cannot_lead_the_default_output_outside_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let world = std::env::current_dir().unwrap().join(TINY);
    swarmmap()
        .current_dir(tmp.path())
        .arg("run")
        .arg(&world)
        .args(["--set", "name=../../esc", "--no-report", "--quiet"])
        .assert()
        .success()
        .stdout(contains("outputs: runs/_._.._esc-seed3"));
    assert_eq!(names(tmp.path()), ["runs"]);
}

#[test]
fn calibrate_refuses_a_directory_as_its_output_before_training() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = tmp.path().join("runs");
    for flag in ["--out", "--landscape"] {
        swarmmap()
            .args(["calibrate", TINY, "--seeds", "1..1", flag])
            .arg(tmp.path())
            .arg("--runs")
            .arg(&runs)
            .assert()
            .code(2)
            .stderr(contains("is a directory; give the file to write"));
        // Refused before any training run: none was kept.
        assert!(!runs.exists() || names(&runs).is_empty());
    }
    // A file whose directory is a file, or cannot be made: refused before training too
    // (found by an adversarial pass, thirty-seventh session: the fit was thrown away).
    let file = tmp.path().join("afile");
    fs::write(&file, "x").unwrap();
    for flag in ["--out", "--landscape"] {
        for (target, says) in [
            (file.join("m.json"), "is a file, not a directory"),
            (
                Path::new("/proc/none/m.json").to_path_buf(),
                "cannot write /proc/none",
            ),
        ] {
            swarmmap()
                .args(["calibrate", TINY, "--seeds", "1..1", flag])
                .arg(&target)
                .arg("--runs")
                .arg(&runs)
                .assert()
                .code(2)
                .stderr(contains(flag).and(contains(says)));
            assert!(!runs.exists() || names(&runs).is_empty());
        }
    }
}

#[test]
fn a_trajectory_interval_longer_than_the_run_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    swarmmap()
        .args([
            "simulate",
            TINY,
            "--quiet",
            "--trajectories",
            "1e300",
            "--out",
        ])
        .arg(tmp.path().join("r"))
        .assert()
        .code(2)
        .stderr(contains(
            "option `trajectories` is 1e300: expected an interval no longer than the run",
        ));
}

#[test]
fn map_warns_where_the_log_and_its_world_disagree() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "simulate");
    // An encounter long after tiny's 210 s, between agents the 40-agent world lacks.
    let mut csv = fs::read_to_string(run.join("encounters.csv")).unwrap();
    csv.push_str("5000.0,5001.0,7,100,1.0,1.0,1.05,1.0\n");
    fs::write(run.join("encounters.csv"), csv).unwrap();
    swarmmap().arg("map").arg(&run).assert().success().stderr(
        contains("warning: 1 encounter(s) lie outside the run's 0–210 s").and(contains(
            "warning: the log names agent 100, but the world has 40 agent(s)",
        )),
    );
    // An encounter moved to the end and repeated (found by an adversarial pass, thirty-
    // seventh session: the maps number encounters by time, not by the file's rows, and a
    // repeated row doubled the events silently).
    let csv = fs::read_to_string(run.join("encounters.csv")).unwrap();
    let mut lines: Vec<&str> = csv.lines().collect();
    let first = lines.remove(1);
    lines.push(first);
    lines.push(first);
    fs::write(run.join("encounters.csv"), lines.join("\n") + "\n").unwrap();
    swarmmap().arg("map").arg(&run).assert().success().stderr(
        contains("rows are not in order of start time")
            .and(contains("1 row(s) repeating an earlier encounter")),
    );
    // In order and without repeats: neither warning.
    lines.pop();
    let last = lines.pop().unwrap();
    lines.insert(1, last);
    fs::write(run.join("encounters.csv"), lines.join("\n") + "\n").unwrap();
    swarmmap().arg("map").arg(&run).assert().success().stderr(
        contains("not in order")
            .not()
            .and(contains("repeating").not()),
    );
    // A log with no encounters maps to nothing, and says so.
    fs::write(
        run.join("encounters.csv"),
        "start,end,a,b,a_x,a_y,b_x,b_y\n",
    )
    .unwrap();
    swarmmap()
        .arg("map")
        .arg(&run)
        .assert()
        .success()
        .stderr(contains("holds no encounters: every map is empty"));
}

/// The names swarmmap derives from a log are common ones: in a directory that does not
/// hold a swarmmap run (no `meta.json` of ours) a new simulation removes none of them.
#[test]
fn a_simulation_into_a_users_own_directory_removes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("mine");
    fs::create_dir_all(dir.join("maps")).unwrap();
    fs::create_dir_all(dir.join("report")).unwrap();
    for f in [
        "summary.json",
        "trajectories.csv",
        "maps/global.json",
        "report/index.html",
    ] {
        fs::write(dir.join(f), "the user's").unwrap();
    }
    swarmmap()
        .args(["simulate", TINY, "--quiet", "--out"])
        .arg(&dir)
        .assert()
        .success();
    for f in [
        "summary.json",
        "trajectories.csv",
        "maps/global.json",
        "report/index.html",
    ] {
        assert_eq!(
            fs::read_to_string(dir.join(f)).unwrap(),
            "the user's",
            "{f}"
        );
    }
}

#[test]
fn messages_for_an_obstacle_field_override_and_a_report_of_a_file() {
    swarmmap()
        .args(["check", TINY, "--set", "obstacles[0].radius=2"])
        .assert()
        .code(2)
        .stderr(contains("an obstacle is set whole, not field by field"));
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("summary.json");
    fs::write(&file, "{}").unwrap();
    swarmmap()
        .arg("report")
        .arg(&file)
        .assert()
        .code(2)
        .stderr(contains(
            "a file, not a run directory; give the directory that holds the run's summary.json",
        ));
}

#[test]
fn a_fraction_where_a_whole_number_belongs_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("f.ron");
    fs::write(&path, "(swarm: (agents: 10.5))").unwrap();
    swarmmap()
        .arg("check")
        .arg(&path)
        .assert()
        .code(2)
        .stderr(contains(
            "f.ron:1:20: a whole number is expected here, not a fraction",
        ));
}

#[test]
fn a_bad_field_in_meta_json_is_named_by_its_path() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "simulate");
    let mut meta = meta_json(&run);
    meta["world"]["arena"]["width"] = serde_json::json!("wide");
    fs::write(run.join("meta.json"), meta.to_string()).unwrap();
    swarmmap()
        .arg("map")
        .arg(&run)
        .assert()
        .code(2)
        .stderr(contains(
            "world.arena.width: invalid type: string \"wide\", expected f64",
        ));
}

#[test]
fn an_empty_or_sample_free_trajectories_file_is_named_as_such() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    fs::write(run.join("trajectories.csv"), "").unwrap();
    swarmmap()
        .arg("report")
        .arg(&run)
        .assert()
        .code(2)
        .stderr(contains("trajectories.csv: the file is empty").and(contains("delete it")));
    fs::write(run.join("trajectories.csv"), "time,agent,x,y,state\n").unwrap();
    swarmmap()
        .arg("report")
        .arg(&run)
        .assert()
        .success()
        .stdout(contains(
            "replay unavailable: trajectories.csv holds no samples",
        ));
    let html = fs::read_to_string(run.join("report/index.html")).unwrap();
    assert!(
        html.contains("<code>trajectories.csv</code> holds no samples"),
        "the replay's absence is explained"
    );
}

#[test]
fn a_control_character_in_a_cell_is_shown_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    let text = fs::read_to_string(run.join("trajectories.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[1] = lines[1].replacen(',', "\u{0},", 1);
    fs::write(run.join("trajectories.csv"), lines.join("\n") + "\n").unwrap();
    swarmmap().arg("report").arg(&run).assert().code(2).stderr(
        contains("trajectories.csv:2: column `time` is `")
            .and(contains("\\0`, not a finite number")),
    );
}

/// `trajectories.csv` errors name `file:line` as every other CSV reader does, counting the
/// lines of the file, a blank one included (found by the fortieth session's review: they
/// said "file: line N:", counting records).
#[test]
fn a_bad_trajectory_row_is_named_by_its_file_line() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    let text = fs::read_to_string(run.join("trajectories.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines.insert(1, String::new());
    lines[3] = lines[3]
        .replace("walk", "run")
        .replace("pause", "run")
        .replace("landmark", "run");
    // `\n`, `\r\n` and classic Mac `\r` endings: the same line 4 (the review found `\r`
    // files named line 1).
    for eol in ["\n", "\r\n", "\r"] {
        fs::write(run.join("trajectories.csv"), lines.join(eol) + eol).unwrap();
        swarmmap()
            .arg("report")
            .arg(&run)
            .assert()
            .code(2)
            .stderr(contains(
                "trajectories.csv:4: state `run` is not walk, pause, landmark or return",
            ));
    }
}

#[test]
fn set_accepts_some_and_none_and_refuses_a_half_quoted_name() {
    swarmmap()
        .args(["check", TINY, "--set", "swarm.agents=Some(12)"])
        .assert()
        .success()
        .stdout(contains("12 agents"));
    // `None` clears a setting: the default swarm of 100 agents.
    swarmmap()
        .args(["check", TINY, "--set", "swarm.agents=None"])
        .assert()
        .success()
        .stdout(contains("100 agents"));
    swarmmap()
        .args(["check", TINY, "--set", "name=\"abc"])
        .assert()
        .code(2)
        .stderr(contains("a quoted name must be one whole string"));
}

/// Found by the forty-first session's review: a JSON error of `meta.json` or `summary.json`
/// gave its place in prose ("at line 1 column 8") after the message, not as `file:line:col`.
#[test]
fn json_errors_name_their_file_line_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "run");
    let summary = std::fs::read_to_string(run.join("summary.json")).unwrap();
    std::fs::write(run.join("summary.json"), &summary[..40]).unwrap();
    let out = swarmmap().arg("report").arg(&run).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    // Cut after 40 bytes: the error is on the line where the text ends.
    let line = summary[..40].lines().count();
    assert!(
        stderr.contains(&format!("summary.json:{line}:")),
        "{stderr}"
    );
    assert!(!stderr.contains(" at line "), "{stderr}");
    let meta = std::fs::read_to_string(run.join("meta.json")).unwrap();
    std::fs::write(run.join("meta.json"), meta.replacen('{', "{ \"x\": ,", 1)).unwrap();
    let out = swarmmap().arg("map").arg(&run).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("meta.json:1:8: not valid JSON"), "{stderr}");
}

/// Left alone by the forty-first session: `meta.json`'s format tag was never read, so a file
/// of a later format (or another tool's) was taken for this build's. A file without the
/// tag (written by hand beside a real log) is still read.
#[test]
fn meta_json_of_another_format_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tiny_run(tmp.path(), "simulate");
    let mut meta = meta_json(&run);
    let cases = [
        (
            serde_json::json!("swarmmap-simulation/2"),
            "`format` is \"swarmmap-simulation/2\", which this build of swarmmap does not read",
        ),
        (
            serde_json::json!(7),
            "`format` is 7, not \"swarmmap-simulation/1\": not a swarmmap run's meta.json",
        ),
    ];
    for (format, message) in cases {
        meta["format"] = format;
        fs::write(run.join("meta.json"), meta.to_string()).unwrap();
        swarmmap()
            .arg("map")
            .arg(&run)
            .assert()
            .code(2)
            .stderr(contains("meta.json").and(contains(message)));
    }
    meta.as_object_mut().unwrap().remove("format");
    fs::write(run.join("meta.json"), meta.to_string()).unwrap();
    swarmmap().arg("map").arg(&run).assert().success();
}

/// A run's `meta.json` as JSON, to edit and write back.
fn meta_json(run: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(run.join("meta.json")).unwrap()).unwrap()
}
