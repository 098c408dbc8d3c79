//! `swarmmap persistence`, black box.

use assert_cmd::Command;
use predicates::prelude::*;
use std::io::Write;

fn fixture(name: &str) -> String {
    format!(
        "{}/tests/fixtures/persistence/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn cmd() -> Command {
    Command::cargo_bin("swarmmap").unwrap()
}

/// Runs `swarmmap` with `args`, asserts success and returns its stdout.
fn stdout_of(args: &[&str]) -> String {
    let out = cmd()
        .args(args)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    String::from_utf8(out).unwrap()
}

fn temp_csv(text: &str) -> tempfile::NamedTempFile {
    let mut f = tempfile::Builder::new().suffix(".csv").tempfile().unwrap();
    f.write_all(text.as_bytes()).unwrap();
    f
}

#[test]
fn square_points() {
    let f = temp_csv("0,0\n1,0\n1,1\n0,1\n");
    cmd()
        .args(["persistence", f.path().to_str().unwrap()])
        .assert()
        .success()
        .stdout("dim,birth,death\n0,0,1\n0,0,1\n0,0,1\n0,0,inf\n1,1,1.4142135623730951\n");
}

#[test]
fn square_with_cycles_and_maxdim0() {
    let f = temp_csv("0,0\n1,0\n1,1\n0,1\n");
    let text = stdout_of(&["persistence", f.path().to_str().unwrap(), "--cycles"]);
    assert!(
        text.starts_with("dim,birth,death,cycle,void\n0,0,1,,\n"),
        "{text}"
    );
    let last = text.lines().last().unwrap();
    let (bar, void) = last.rsplit_once(',').unwrap();
    assert_eq!(bar, "1,1,1.4142135623730951,0-1;0-3;1-2;2-3");
    let v: Vec<usize> = void.split(';').map(|x| x.parse().unwrap()).collect();
    assert_eq!(v.len(), 3);
    assert!(v.windows(2).all(|w| w[0] < w[1]) && v[2] <= 3, "{void}");
    // Essential H0 classes have no void either.
    assert!(text.contains("\n0,0,inf,,\n"));
    // A quadrilateral whose shorter diagonal, 1-3 (√2), kills the class born at its longest
    // side (2-3): both triangles it closes contain 1 and 3; the other diagonal (0-2) is longer.
    let q = temp_csv("0,0\n1,0\n1.2,1.1\n0,1\n");
    let text = stdout_of(&["persistence", q.path().to_str().unwrap(), "--cycles"]);
    let last = text.lines().last().unwrap();
    assert!(last.starts_with("1,"), "{text}");
    let fields: Vec<&str> = last.split(',').collect();
    assert!((fields[2].parse::<f64>().unwrap() - 2f64.sqrt()).abs() < 1e-12);
    let v: Vec<usize> = fields[4].split(';').map(|x| x.parse().unwrap()).collect();
    assert!(v == [0, 1, 3] || v == [1, 2, 3], "{last}");
    cmd()
        .args(["persistence", f.path().to_str().unwrap(), "--maxdim", "0"])
        .assert()
        .success()
        .stdout("dim,birth,death\n0,0,1\n0,0,1\n0,0,1\n0,0,inf\n");
}

#[test]
fn distance_matrix_and_threshold() {
    let text = stdout_of(&[
        "persistence",
        &fixture("graph_metric_150.dist.csv"),
        "--distance-matrix",
    ]);
    assert_eq!(text.lines().filter(|l| l.starts_with("0,")).count(), 150);
    let f = temp_csv("0,1,3\n1,0,1\n3,1,0\n");
    cmd()
        .args([
            "persistence",
            f.path().to_str().unwrap(),
            "--distance-matrix",
            "--threshold",
            "0.5",
        ])
        .assert()
        .success()
        .stdout("dim,birth,death\n0,0,inf\n0,0,inf\n0,0,inf\n");
}

fn bad(text: &str, extra: &[&str], msg: &str) {
    let f = temp_csv(text);
    let mut args = vec!["persistence", f.path().to_str().unwrap()];
    args.extend_from_slice(extra);
    cmd()
        .args(&args)
        .assert()
        .code(2)
        .stderr(predicate::str::contains(msg));
}

#[test]
fn bad_files_name_the_line_and_exit_2() {
    bad(
        "0,0\n1,0\n1\n",
        &[],
        ":3: row has 1 columns but line 1 has 2",
    );
    bad("0,0\n1,x\n", &[], ":2: field 2: 'x' is not a number");
    // Left alone by the forty-first session: a header row, `;` separators or spaces got
    // only "not a number".
    bad(
        "x,y\n0,0\n",
        &[],
        ":1: field 1: 'x' is not a number; this looks like a header row",
    );
    bad("0,0\n1,x\n", &[], "every field must be a decimal number");
    bad(
        "0;0\n1;2\n",
        &[],
        ":1: field 1: '0;0' is not a number; fields are separated by commas, not ';'",
    );
    bad(
        "0 0\n1 2\n",
        &[],
        ":1: field 1: '0 0' is not a number; fields are separated by commas, not spaces or tabs",
    );
    // Found in review: a header with spaces got the separator hint, an empty first row the
    // header hint, and a quoted decimal comma only "not a number".
    bad(
        "x coord,y coord\n0,0\n",
        &[],
        ":1: field 1: 'x coord' is not a number; this looks like a header row",
    );
    bad(
        ",\n0,0\n",
        &[],
        ":1: field 1: '' is not a number; the field is empty",
    );
    bad(
        "0,\"1,5\"\n0,0\n",
        &[],
        ":1: field 2: '1,5' is not a number; write the number with a decimal point",
    );
    bad(
        "0,0\n1,nan\n",
        &[],
        ":2: field 2: coordinate 1 of point 1 is not a finite number",
    );
    // Regression: coordinates this large made every distance overflow to infinity, and
    // the diagram came out with every point an essential class, without a word.
    bad(
        "0,0\n1,0\n3e200,1\n",
        &[],
        ":3: field 1: coordinate 0 of point 2 is 3e200, beyond ±1e150: squared distances would overflow",
    );
    bad("", &[], "no rows");
    bad(
        "0,1\n2,0\n",
        &["--distance-matrix"],
        ":1: field 2: entries (0, 1) = 1 and (1, 0) = 2 differ",
    );
    bad(
        "0,-1\n-1,0\n",
        &["--distance-matrix"],
        ":1: field 2: entry (0, 1) is -1; distances must be finite and non-negative",
    );
    bad(
        "0,1\n1,2\n",
        &["--distance-matrix"],
        ":2: field 2: diagonal entry (1, 1) is 2",
    );
    // A far entry is echoed with an exponent (found by the fortieth session's review).
    bad(
        "0,-1e200\n-1e200,0\n",
        &["--distance-matrix"],
        ":1: field 2: entry (0, 1) is -1e200;",
    );
    bad(
        "0,1,2\n1,0,1\n",
        &["--distance-matrix"],
        ":1: row 0 has 3 entries but the matrix has 2 rows",
    );
    bad(
        "0,0\n",
        &["--maxdim", "2"],
        "homology dimension 2 is not supported",
    );
    bad(
        "0,0\n",
        &["--threshold", "-1"],
        "threshold -1 is not a finite non-negative distance",
    );
    // A far number is echoed with an exponent, not as hundreds of digits.
    bad(
        "0,0\n",
        &["--threshold", "-1e300"],
        "threshold -1e300 is not a finite non-negative distance",
    );
}

/// A missing file named on the command line is bad input (status 2), as for `check` and
/// `map` (thirty-seventh session; it was status 1 here alone).
#[test]
fn missing_file_is_an_input_error_as_for_every_command() {
    cmd()
        .args(["persistence", "/nonexistent/points.csv"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "cannot read /nonexistent/points.csv",
        ));
}

/// Far values are written with an exponent, exactly (found by the fortieth session's
/// review: 1e149 came out as 150 digits); they read back to the same numbers.
#[test]
fn far_values_are_written_with_an_exponent() {
    let f = temp_csv("0,0\n1e149,0\n2e149,1\n");
    let out = cmd()
        .args(["persistence", f.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().all(|l| l.len() < 40), "{text}");
    let deaths: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(deaths, [1e149, 1e149, f64::INFINITY]);
}
