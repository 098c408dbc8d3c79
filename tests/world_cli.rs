//! `swarmmap check` as a black box: summary on success, the error and status 2 otherwise.

use assert_cmd::Command;
use predicates::prelude::*;

fn swarmmap() -> Command {
    Command::cargo_bin("swarmmap").expect("binary built")
}

#[test]
fn check_prints_a_summary_of_each_scenario() {
    // Scenario 3 sweeps at half the speed and maps with twice the planar Rips points
    // (docs/accuracy.md, step 29).
    for (file, windows, obstacles, speed, sweep, rips) in [
        (
            "worlds/scenario1.ron",
            4,
            "3 (1 Rect, 1 Circle, 1 Polygon)",
            "0.005",
            "5400 s = 5700",
            2400,
        ),
        (
            "worlds/scenario2.ron",
            6,
            "1 (1 Rect)",
            "0.005",
            "5400 s = 5700",
            2400,
        ),
        (
            "worlds/scenario3.ron",
            5,
            "6 (2 Rect, 2 Circle, 2 Polygon)",
            "0.0025",
            "10800 s = 11100",
            4800,
        ),
    ] {
        // The outlier filter's rank scales with the sweep: 8 at 0.005 m/s, 16 at 0.0025.
        let rank = if speed == "0.0025" { 16 } else { 8 };
        swarmmap()
            .args(["check", file])
            .assert()
            .success()
            .stderr(predicate::str::is_empty())
            .stdout(predicate::str::contains(format!("obstacles  {obstacles}")))
            .stdout(predicate::str::contains("30 m × 10 m"))
            .stdout(predicate::str::contains("200 agents, 60 landmarks"))
            .stdout(predicate::str::contains("r_d = 0.1 m"))
            .stdout(predicate::str::contains(format!(
                "sweeps x 1.5 → 28.5 m at {speed} m/s"
            )))
            .stdout(predicate::str::contains(format!("sweep {sweep} s")))
            .stdout(predicate::str::contains(format!(
                "windows    {windows} with overlap Δt = 300 s"
            )))
            .stdout(predicate::str::contains(format!("W{windows} ")))
            .stdout(predicate::str::contains(format!("W{} ", windows + 1)).not())
            .stdout(predicate::str::contains(format!(
                "mapping    Embedded method, switch cost 1 s, c = 35, m = 400, outlier rank {rank} (from the sweep), k = 5; \
                 encounters after the first landmark; weights between encounter middles; \
                 {rips} planar Rips points"
            )));
    }
}

#[test]
fn check_summarises_the_paper_mapping_without_rips_points() {
    swarmmap()
        .args([
            "check",
            "worlds/scenario1.ron",
            "--set",
            "mapping.method=Paper",
        ])
        .args(["--set", "mapping.after_landmarks=false"])
        .args(["--set", "mapping.encounter_midpoints=false"])
        .assert()
        .success()
        .stdout(predicate::str::contains(
            "mapping    Paper method, switch cost 1 s, c = 35, m = 400, outlier rank 8 (from the sweep), k = 5; \
             every encounter; the paper's interval-gap weights\n",
        ));
}

#[test]
fn check_prints_an_outlier_rank_the_world_fixes() {
    swarmmap()
        .args([
            "check",
            "worlds/scenario3.ron",
            "--set",
            "mapping.outlier_rank=12",
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("m = 400, outlier rank 12, k = 5;"));
}

#[test]
fn check_rejects_an_invalid_world_with_status_2() {
    swarmmap()
        .args(["check", "tests/fixtures/worlds/negative_radius.ron"])
        .assert()
        .code(2)
        .stdout("")
        .stderr(predicate::str::contains(
            "tests/fixtures/worlds/negative_radius.ron:6:36: obstacles[1].radius is -1 (must be > 0 metres); give the circle a positive radius",
        ));
}

#[test]
fn check_reports_syntax_errors_with_position() {
    swarmmap()
        .args(["check", "tests/fixtures/worlds/unknown_field.ron"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("unknown_field.ron:4:"))
        .stderr(predicate::str::contains("did you mean `detection_radius`?"))
        .stderr(predicate::str::contains("`landmark_fraction`"));
}

#[test]
fn check_a_missing_file_is_an_input_error() {
    swarmmap()
        .args(["check", "worlds/does-not-exist.ron"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "worlds/does-not-exist.ron: cannot read the world file",
        ));
}

#[test]
fn check_applies_overrides() {
    swarmmap()
        .args([
            "check",
            "worlds/scenario1.ron",
            "--set",
            "mapping.windows=6",
            "--set",
            "swarm.agents=50",
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("windows    6 with"))
        .stdout(predicate::str::contains("50 agents, 15 landmarks"));
    swarmmap()
        .args(["check", "worlds/scenario1.ron", "--set", "mapping.window=6"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("did you mean `mapping.windows`?"));
    swarmmap()
        .args([
            "check",
            "worlds/scenario1.ron",
            "--set",
            "simulation.dt=1.0",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "(--set simulation.dt=1.0): simulation.dt is 1 s",
        ));
    swarmmap()
        .args(["check", "worlds/scenario1.ron", "--set", "seed"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("expected PATH=VALUE"));
    // Counts read as counts, and a quoted number gets the fix (forty-first session's review).
    let tmp = tempfile::tempdir().unwrap();
    let one = tmp.path().join("one.ron");
    std::fs::write(&one, "(swarm: (agents: 1))").unwrap();
    swarmmap()
        .arg("check")
        .arg(&one)
        .assert()
        .success()
        .stdout(predicate::str::contains("1 agent, 0 landmarks"));
    let quoted = tmp.path().join("quoted.ron");
    std::fs::write(&quoted, "(swarm: (agents: \"ten\"))").unwrap();
    swarmmap()
        .arg("check")
        .arg(&quoted)
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "quoted.ron:1:17: a whole number is expected",
        ));
}

#[test]
fn check_has_help() {
    swarmmap()
        .args(["check", "--help"])
        .assert()
        .success()
        .stdout(predicate::str::contains("--set <PATH=VALUE>"));
}

/// Output piped into a reader that has already gone (`| true`) ends the command quietly:
/// no panic message on stderr.
#[cfg(unix)]
#[test]
fn a_closed_stdout_pipe_is_not_a_panic() {
    let bin = assert_cmd::cargo::cargo_bin("swarmmap");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' check worlds/scenario1.ron | true",
            bin.display()
        ))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
}

/// The "free for agent centres" share printed by `swarmmap check`, e.g. `97.3`.
fn free_share(out: &[u8]) -> f64 {
    let text = String::from_utf8_lossy(out);
    let line = text
        .lines()
        .find(|l| l.starts_with("arena"))
        .expect("an arena line");
    let after = line
        .split("free for agent centres: ")
        .nth(1)
        .expect("share");
    after.split(" %").next().unwrap().parse().expect("a number")
}

#[test]
fn obstacles_scale_grows_every_obstacle_and_blames_itself_when_they_leave_the_arena() {
    let share = |args: &[&str]| {
        let out = swarmmap()
            .args(["check", "worlds/scenario3.ron"])
            .args(args)
            .output()
            .expect("runs");
        assert!(out.status.success(), "{args:?}");
        free_share(&out.stdout)
    };
    let (as_is, larger) = (share(&[]), share(&["--set", "obstacles.scale=1.5"]));
    // Scaled by 1.5 the six obstacles cover 2.25 times their area; the blocked share also
    // holds the arena's border band (one body radius, unchanged) and each obstacle's
    // (which grows only 1.5 times), and the printed share is rounded to 0.1 %, so the
    // blocked share grows by about 2.1 times: more than 1.8.
    let (blocked, blocked_larger) = (100.0 - as_is, 100.0 - larger);
    assert!(
        blocked_larger > 1.8 * blocked,
        "{blocked} -> {blocked_larger}"
    );
    swarmmap()
        .args([
            "check",
            "worlds/scenario3.ron",
            "--set",
            "obstacles.scale=20",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "(--set obstacles.scale=20): obstacles[",
        ));
    swarmmap()
        .args([
            "check",
            "worlds/scenario3.ron",
            "--set",
            "obstacles.scale=-1",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("must be a finite number > 0"));
}

/// Left alone by the forty-first session: `check` passed a world whose swarm has no
/// landmark (or a single agent) in silence, though its runs cannot be stitched (or record
/// nothing); `run` only said so after the simulation.
#[test]
fn check_warns_of_a_swarm_without_landmarks_or_partners() {
    for (set, warning) in [
        (
            "swarm.landmark_fraction=0.002",
            "warning: no agent will be a landmark, even with every agent inside the leader's \
             domain (round(swarm.landmark_fraction × agents) = round(0.002 × 200) = 0;",
        ),
        (
            "swarm.agents=1",
            "warning: 1 agent meets no one: the run will record no encounters",
        ),
    ] {
        swarmmap()
            .args(["check", "worlds/scenario1.ron", "--set", set])
            .assert()
            .success()
            .stdout(predicate::str::contains("world      scenario1"))
            .stderr(predicate::str::contains(warning));
    }
}
