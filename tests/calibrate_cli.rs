//! `swarmmap calibrate`: it replaces exactly the entry it fits in the model file (a method's,
//! or the truth-position oracle's with `--oracle`), keeps the others, and says what it was
//! fitted on.

use assert_cmd::Command;
use predicates::str::contains;
use swarmmap::mapping::classify::{Models, SHIPPED};

const WORLD: &str = "tests/fixtures/worlds/tiny.ron";

fn calibrate(out: &std::path::Path, extra: &[&str]) {
    Command::cargo_bin("swarmmap")
        .unwrap()
        .args(["calibrate", WORLD, "--seeds", "1,2", "--jobs", "1", "--out"])
        .arg(out)
        .args(extra)
        .assert()
        .success()
        .stdout(contains("training windows 4"));
}

fn models(path: &std::path::Path) -> Models {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn calibrate_replaces_only_the_fitted_entry() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("model.json");
    std::fs::write(&out, SHIPPED).unwrap();
    let shipped = Models::shipped();

    // tiny.ron maps with the paper's method: its entry is refitted, the others kept.
    calibrate(&out, &[]);
    let m = models(&out);
    assert!(
        m.paper
            .fitted_on
            .starts_with("swarmmap calibrate --seeds 1,2 ")
    );
    assert!(m.paper.fitted_on.contains("tiny.ron: 4 windows"));
    assert_eq!(m.embedded, shipped.embedded);
    assert_eq!(m.oracle, shipped.oracle);

    calibrate(&out, &["--oracle"]);
    let m2 = models(&out);
    assert!(
        m2.oracle
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
        .stderr(contains("is not a model file"));
}
