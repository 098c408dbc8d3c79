//! `swarmmap report RUN_DIR` and the report written by `swarmmap run`: byte-identical
//! regeneration, a run without trajectories, a log without world or truth, bad inputs
//! (exit status 2, the file named), `--no-report`.

use assert_cmd::Command;
use predicates::str::contains;
use std::fs;
use std::path::Path;

const FIXTURE: &str = "tests/fixtures/report/tiny";
const TINY: &str = "tests/fixtures/worlds/tiny.ron";

fn swarmmap() -> Command {
    Command::cargo_bin("swarmmap").unwrap()
}

fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            fs::copy(entry.path(), target).unwrap();
        }
    }
}

fn fixture_copy() -> (tempfile::TempDir, std::path::PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    copy_dir(Path::new(FIXTURE), &dir);
    (tmp, dir)
}

fn report_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = fs::read_dir(dir.join("report"))
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

#[test]
fn report_regenerates_byte_identical_files() {
    let (_tmp, dir) = fixture_copy();
    swarmmap()
        .arg("report")
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("8 figures, with replay"));
    let first = report_files(&dir);
    assert_eq!(first.len(), 9, "8 figures and index.html");
    assert!(first.iter().all(|(name, _)| !name.ends_with(".tmp")));
    swarmmap().arg("report").arg(&dir).assert().success();
    assert!(first == report_files(&dir), "a second report differs");
    let html = String::from_utf8(
        first
            .iter()
            .find(|f| f.0 == "index.html")
            .unwrap()
            .1
            .clone(),
    )
    .unwrap();
    // Self-contained: no external scripts, styles, images or fetches.
    for needle in [
        "src=\"http",
        "href=\"http",
        "<link rel=\"stylesheet",
        "fetch(",
        "XMLHttpRequest",
    ] {
        assert!(!html.contains(needle), "page references {needle}");
    }
}

#[test]
fn a_run_without_trajectories_gets_a_page_that_says_so() {
    let (_tmp, dir) = fixture_copy();
    fs::remove_file(dir.join("trajectories.csv")).unwrap();
    swarmmap()
        .arg("report")
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("replay unavailable"));
    let html = fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(html.contains("id=\"replay-unavailable\""));
    assert!(!html.contains("id=\"replay-data\""));
    // The environment figure still shows landmarks, from the encounters' truth columns.
    assert!(dir.join("report/environment.svg").exists());
}

#[test]
fn missing_or_malformed_inputs_exit_2_and_name_the_file() {
    let (_tmp, dir) = fixture_copy();
    swarmmap()
        .arg("report")
        .arg(dir.join("nonexistent"))
        .assert()
        .code(2)
        .stderr(contains("nonexistent"));

    let (_t1, d1) = fixture_copy();
    fs::remove_file(d1.join("summary.json")).unwrap();
    swarmmap()
        .arg("report")
        .arg(&d1)
        .assert()
        .code(2)
        .stderr(contains("summary.json: file not found"));

    let (_t2, d2) = fixture_copy();
    fs::write(d2.join("maps/window_2.json"), "{ not json").unwrap();
    swarmmap()
        .arg("report")
        .arg(&d2)
        .assert()
        .code(2)
        .stderr(contains("window_2.json"));

    // A dendrogram merge that names a cluster not made yet.
    let (_t3, d3) = fixture_copy();
    let path = d3.join("maps/connection_1.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    c["merges"][0]["a"] = serde_json::json!(100_000);
    fs::write(&path, serde_json::to_string(&c).unwrap()).unwrap();
    swarmmap()
        .arg("report")
        .arg(&d3)
        .assert()
        .code(2)
        .stderr(contains("connection_1.json").and(contains("merge 0")));

    // A hole cycle that points past the window's events.
    let (_t4, d4) = fixture_copy();
    let path = d4.join("maps/window_1.json");
    let mut w: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    w["components"][0]["holes"] =
        serde_json::json!([{"birth": 1.0, "death": 2.0, "cycle": [[0, 99999]]}]);
    fs::write(&path, serde_json::to_string(&w).unwrap()).unwrap();
    swarmmap()
        .arg("report")
        .arg(&d4)
        .assert()
        .code(2)
        .stderr(contains("window_1.json"));

    // A hole void that points past the window's events.
    let (_t6, d6) = fixture_copy();
    let path = d6.join("maps/window_1.json");
    let mut w: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    w["components"][0]["holes"] = serde_json::json!([
        {"birth": 1.0, "death": 2.0, "cycle": [[0, 1]], "void": [0, 1, 99999]}
    ]);
    fs::write(&path, serde_json::to_string(&w).unwrap()).unwrap();
    swarmmap()
        .arg("report")
        .arg(&d6)
        .assert()
        .code(2)
        .stderr(contains("window_1.json").and(contains("void event 99999")));
    assert!(!d6.join("report").exists());

    let (_t5, d5) = fixture_copy();
    fs::write(
        d5.join("trajectories.csv"),
        "time,agent,x,y,state\n0,1,2,3,flying\n",
    )
    .unwrap();
    swarmmap()
        .arg("report")
        .arg(&d5)
        .assert()
        .code(2)
        .stderr(contains("trajectories.csv:2: state `flying`"));
    // Nothing was written for a failed report.
    assert!(!d5.join("report").exists());
}

use predicates::prelude::PredicateBooleanExt;

#[test]
fn a_log_without_world_or_truth_gets_a_report_without_truth() {
    let (_tmp, dir) = fixture_copy();
    fs::remove_file(dir.join("meta.json")).unwrap();
    fs::remove_file(dir.join("trajectories.csv")).unwrap();
    let text = fs::read_to_string(dir.join("encounters.csv")).unwrap();
    let stripped: String = text
        .lines()
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    fs::write(dir.join("encounters.csv"), stripped).unwrap();
    swarmmap()
        .args(["map", "--windows", "2", "--overlap", "30"])
        .arg(&dir)
        .assert()
        .success();
    swarmmap()
        .arg("report")
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("7 figures"));
    let html = fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(html.contains("A log without a world file"));
    assert!(!dir.join("report/environment.svg").exists());
    let cloud = fs::read_to_string(dir.join("report/window_1_cloud.svg")).unwrap();
    assert!(!cloud.contains("true positions"));
}

#[test]
fn run_writes_the_report_and_trajectories_unless_told_not_to() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    swarmmap()
        .args(["run", TINY, "--quiet", "--out"])
        .arg(&a)
        .assert()
        .success()
        .stdout(contains("report: ").and(contains("with replay")));
    assert!(a.join("report/index.html").exists());
    assert!(a.join("trajectories.csv").exists());
    // The diagrams' captions say the outlier rank the windows were mapped with (2 at the
    // tiny world's 0.02 m/s).
    let html = fs::read_to_string(a.join("report/index.html")).unwrap();
    assert!(
        html.contains("neighbour rank k = 2."),
        "{}",
        &html[..html.len().min(2000)]
    );
    let meta: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(a.join("meta.json")).unwrap()).unwrap();
    // Default interval: max(1 s, 210 s / 600) = 1 s.
    assert_eq!(
        meta["outputs"]["trajectory_interval"],
        serde_json::json!(1.0)
    );
    swarmmap()
        .args(["run", TINY, "--quiet", "--no-report", "--out"])
        .arg(&b)
        .assert()
        .success();
    assert!(!b.join("report").exists());
    assert!(b.join("trajectories.csv").exists());
    // The report can be made later.
    swarmmap().arg("report").arg(&b).assert().success();
    assert!(b.join("report/index.html").exists());
}

#[test]
fn remapping_refreshes_an_existing_report() {
    let (_tmp, dir) = fixture_copy();
    swarmmap().arg("report").arg(&dir).assert().success();
    assert!(!dir.join("report/window_3_cloud.svg").exists());
    swarmmap()
        .args(["map", "--windows", "3", "--overlap", "30"])
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("report refreshed"));
    assert!(dir.join("report/window_3_cloud.svg").exists());
    let html = fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(
        html.contains("3 windows"),
        "the page describes the new maps"
    );
}

/// Found by the forty-first session's review: after `map --world OTHER` the summary judged
/// the maps against OTHER while the report drew the run's own world from meta.json. The
/// summary now records the world it was judged against, and the report draws it.
#[test]
fn a_report_draws_the_world_the_maps_were_judged_against() {
    let (tmp, dir) = fixture_copy();
    swarmmap().arg("report").arg(&dir).assert().success();
    let own = fs::read(dir.join("report/environment.svg")).unwrap();
    let moved = tmp.path().join("moved.ron");
    let tiny = fs::read_to_string("tests/fixtures/worlds/tiny.ron").unwrap();
    assert!(tiny.contains("center: (3.0, 2.0)"));
    fs::write(
        &moved,
        tiny.replace("center: (3.0, 2.0)", "center: (4.5, 2.0)"),
    )
    .unwrap();
    swarmmap()
        .args(["map", "--world"])
        .arg(&moved)
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("report refreshed"));
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["judged_world"]["obstacles"][0]["Circle"]["center"],
        serde_json::json!([4.5, 2.0])
    );
    let other = fs::read(dir.join("report/environment.svg")).unwrap();
    assert!(other != own, "the report still draws the run's own world");
    // Made again from the files alone, the report draws the same world.
    swarmmap().arg("report").arg(&dir).assert().success();
    assert!(fs::read(dir.join("report/environment.svg")).unwrap() == other);
    // Mapped again with the run's own world, it draws that one again.
    swarmmap().arg("map").arg(&dir).assert().success();
    assert!(fs::read(dir.join("report/environment.svg")).unwrap() == own);
}

/// A report interrupted before its page was written (figures, no `index.html`) is made
/// again by the next `map`, not dropped (found by the fortieth session's review: only a
/// report with its page counted as existing, and the stale figures were just deleted).
#[test]
fn remapping_completes_a_report_interrupted_before_its_page() {
    let (_tmp, dir) = fixture_copy();
    swarmmap().arg("report").arg(&dir).assert().success();
    fs::remove_file(dir.join("report/index.html")).unwrap();
    swarmmap()
        .args(["map", "--windows", "3", "--overlap", "30"])
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("report refreshed"));
    assert!(dir.join("report/index.html").exists());
    assert!(dir.join("report/window_3_cloud.svg").exists());
}
