//! Property tests of the input paths `tests/input_fuzz.rs` does not reach, against the
//! project's rule (STYLE.md §5): bad input never panics and never loses data; an error says
//! where (CSV line, `file:line:col` or the file), what is wrong and how to fix it, and exits
//! with status 2.
//!
//! The paths, through the binary where only it reads them, else through the public API:
//! - `swarmmap persistence FILE` (points) and `--distance-matrix` (a full matrix): CSV-shaped
//!   noise and one mutation of a valid file (a field replaced by NaN, inf, a huge number, a
//!   word or nothing; a field dropped or added; an entry made asymmetric, negative or a
//!   non-zero diagonal; a row or a column dropped), judged by an oracle written here from
//!   `DistanceMatrix::from_full` and `PointCloud::from_rows`: a file they accept gives exit 0
//!   and a diagram, one they reject gives exit 2 at the line of the culprit;
//! - the `--set PATH=VALUE` parser, `world::apply_assignment`: random paths (listed, misspelt,
//!   `obstacles[i]`, noise) and RON-shaped values; the CLI (`swarmmap check --set`) agrees
//!   with the library, status and message;
//! - a run directory (`tests/fixtures/report/tiny`) with one JSON file truncated, a byte
//!   changed, a range deleted or a leaf replaced by another JSON value: `report::load_run`
//!   and `report::render` in the library, `swarmmap report` and `swarmmap map` (which reads
//!   only `meta.json` of these) through the binary: success, or an input error naming the
//!   file.
//!
//! The failures these properties found are pinned, ignored, at the end, each with the place
//! in src/ where it goes wrong.

use assert_cmd::Command;
use proptest::prelude::*;
use proptest::sample::Index;
use std::path::{Path, PathBuf};
use std::time::Duration;
use swarmmap::world::{SETTING_PATHS, WorldError, WorldSpec, apply_assignment, parse_str};

/// Cases per library-level property.
const CASES: u32 = 256;
/// Cases per property that spawns the binary: each case is one process (≈ 10–60 ms).
const CLI_CASES: u32 = 48;

fn swarmmap() -> Command {
    let mut cmd = Command::cargo_bin("swarmmap").expect("binary built");
    // A hang is a failure too, but it must not stall the suite.
    cmd.timeout(Duration::from_secs(60));
    cmd
}

/// What a run of the binary left: its exit status (`None` for a signal), stdout and stderr.
struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

fn outcome(cmd: &mut Command) -> Outcome {
    let out = cmd.output().expect("the binary runs");
    Outcome {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Exit 0 or 2: never a panic (101), another failure (1) or a signal.
fn assert_ok_or_input_error(o: &Outcome) -> Result<(), TestCaseError> {
    prop_assert!(
        matches!(o.code, Some(0) | Some(2)),
        "exit status {:?}; stderr: {}",
        o.code,
        o.stderr
    );
    prop_assert!(
        !o.stderr.contains("panicked"),
        "a panic (status {:?}): {}",
        o.code,
        o.stderr
    );
    Ok(())
}

/// Lines of `bytes`: `\n`, `\r\n` and a lone `\r` each end one.
fn line_count(bytes: &[u8]) -> u64 {
    let crlf = bytes.windows(2).filter(|w| w == b"\r\n").count();
    let ends = bytes
        .iter()
        .filter(|b| **b == b'\n' || **b == b'\r')
        .count();
    (ends + 1 - crlf) as u64
}

// ================================================================ persistence: helpers

/// Runs `swarmmap persistence [--distance-matrix] FILE` on `bytes`.
fn persistence(bytes: &[u8], matrix: bool) -> (PathBuf, Outcome, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("input.csv");
    std::fs::write(&path, bytes).expect("write the input");
    let mut cmd = swarmmap();
    cmd.arg("persistence");
    if matrix {
        cmd.arg("--distance-matrix");
    }
    cmd.arg(&path);
    let o = outcome(&mut cmd);
    (path, o, dir)
}

/// The line an error of `persistence` names: `error: FILE:LINE: message`; `None` when it
/// names only the file.
fn error_line(stderr: &str, path: &Path) -> Option<u64> {
    let rest = stderr.strip_prefix(&format!("error: {}:", path.display()))?;
    let (digits, _) = rest.split_once(':')?;
    digits.parse().ok()
}

/// A successful diagram on stdout, or an error that names the file and, unless the file has
/// no rows at all, a line inside it.
fn assert_persistence_contract(
    bytes: &[u8],
    path: &Path,
    o: &Outcome,
) -> Result<(), TestCaseError> {
    assert_ok_or_input_error(o)?;
    if o.code == Some(0) {
        prop_assert!(o.stdout.starts_with("dim,birth,death\n"), "{}", o.stdout);
        prop_assert!(o.stderr.is_empty(), "{}", o.stderr);
        return Ok(());
    }
    let prefix = format!("error: {}", path.display());
    prop_assert!(o.stderr.starts_with(&prefix), "{}", o.stderr);
    prop_assert!(o.stdout.is_empty(), "output on a failure: {}", o.stdout);
    match error_line(&o.stderr, path) {
        Some(line) => prop_assert!(
            (1..=line_count(bytes)).contains(&line),
            "line {} is outside the file's {} lines: {}",
            line,
            line_count(bytes),
            o.stderr
        ),
        None => prop_assert!(
            o.stderr.contains("has no rows"),
            "an error without a line: {}",
            o.stderr
        ),
    }
    Ok(())
}

/// Asserts exit 2 with the error at `line`.
fn assert_error_at(path: &Path, o: &Outcome, line: u64) -> Result<(), TestCaseError> {
    assert_ok_or_input_error(o)?;
    prop_assert_eq!(o.code, Some(2), "accepted: {}", o.stdout);
    prop_assert_eq!(
        error_line(&o.stderr, path),
        Some(line),
        "expected line {}: {}",
        line,
        o.stderr
    );
    Ok(())
}

fn assert_accepted(o: &Outcome) -> Result<(), TestCaseError> {
    assert_ok_or_input_error(o)?;
    prop_assert_eq!(o.code, Some(0), "rejected: {}", o.stderr);
    prop_assert!(o.stdout.starts_with("dim,birth,death\n"), "{}", o.stdout);
    Ok(())
}

/// Tokens of CSV-shaped noise.
const CSV_TOKENS: &[&str] = &[
    "0", "1", "-2.5", "3e2", "1e151", "1e309", "NaN", "inf", "-inf", "x", "", " ", ",", ",", ",",
    "\n", "\n", "\n", "\r\n", "\r", "\"", "\"1\"", "\t", "é", "+", "-", ".",
];

/// Fields that are not numbers a reader may accept, and ones that are.
const BAD_NUMBERS: &[&str] = &[
    "NaN", "nan", "inf", "-inf", "infinity", "1e309", "-1e400", "1e151", "-2e150", "x", "0x10",
    "1.2.3", "--1", "1e", "\"\"", " ", "", "١",
];
const GOOD_NUMBERS: &[&str] = &["-0", "+3", "1e2", "0.5", " 7 ", "\"4\"", "1e149"];

/// Whether `PointCloud::from_rows` takes `token` as a coordinate (after CSV trimming).
fn is_good_coordinate(token: &str) -> bool {
    GOOD_NUMBERS.contains(&token)
}

/// Whether the CSV field `token` (unquoted, trimmed) parses as an `f64`.
fn parses_as_f64(token: &str) -> bool {
    let t = token.trim();
    let t = t
        .strip_prefix('"')
        .and_then(|t| t.strip_suffix('"'))
        .unwrap_or(t);
    t.trim().parse::<f64>().is_ok()
}

fn csv_text(rows: &[Vec<String>]) -> String {
    rows.iter().map(|r| r.join(",") + "\n").collect()
}

/// One change of a valid points file.
#[derive(Debug, Clone)]
enum PointEdit {
    /// Field `(row, col)` replaced by a token.
    Replace(Index, Index, &'static str),
    /// Field `(row, col)` removed.
    Drop(Index, Index),
    /// A field appended to a row.
    Add(Index, &'static str),
}

fn point_edit() -> impl Strategy<Value = PointEdit> {
    let token = prop_oneof![
        proptest::sample::select(BAD_NUMBERS),
        proptest::sample::select(GOOD_NUMBERS)
    ];
    prop_oneof![
        (any::<Index>(), any::<Index>(), token.clone())
            .prop_map(|(r, c, t)| PointEdit::Replace(r, c, t)),
        (any::<Index>(), any::<Index>()).prop_map(|(r, c)| PointEdit::Drop(r, c)),
        (any::<Index>(), token).prop_map(|(r, t)| PointEdit::Add(r, t)),
    ]
}

/// One change of a valid distance matrix.
#[derive(Debug, Clone)]
enum MatrixEdit {
    /// Entry `(i, j)`, `i != j`, replaced on one side only.
    OneSide(Index, Index, &'static str),
    /// Entries `(i, j)` and `(j, i)` replaced.
    BothSides(Index, Index, &'static str),
    /// Diagonal entry `(i, i)` replaced.
    Diagonal(Index, &'static str),
    /// Row `i` removed.
    DropRow(Index),
    /// Column `j` removed from every row.
    DropColumn(Index),
    /// A zero appended to every row.
    AddColumn,
    /// The last entry of row `i` removed.
    Shorten(Index),
}

/// Matrix entries: invalid ones, and valid ones that differ from every generated distance
/// (those are multiples of 0.5 in [0.5, 50]).
const BAD_ENTRIES: &[&str] = &["NaN", "inf", "-inf", "1e309", "-1", "-0.5", "x", "\"\"", ""];
const OTHER_ENTRIES: &[&str] = &["1000", "0", "-0", "0.25", "1e300"];

fn matrix_edit() -> impl Strategy<Value = MatrixEdit> {
    let token = prop_oneof![
        proptest::sample::select(BAD_ENTRIES),
        proptest::sample::select(OTHER_ENTRIES)
    ];
    prop_oneof![
        (any::<Index>(), any::<Index>(), token.clone())
            .prop_map(|(i, j, t)| MatrixEdit::OneSide(i, j, t)),
        (any::<Index>(), any::<Index>(), token.clone())
            .prop_map(|(i, j, t)| MatrixEdit::BothSides(i, j, t)),
        (any::<Index>(), token).prop_map(|(i, t)| MatrixEdit::Diagonal(i, t)),
        any::<Index>().prop_map(MatrixEdit::DropRow),
        any::<Index>().prop_map(MatrixEdit::DropColumn),
        Just(MatrixEdit::AddColumn),
        any::<Index>().prop_map(MatrixEdit::Shorten),
    ]
}

/// Two different indices below `n` (`n >= 2`), smaller first.
fn pair(i: &Index, j: &Index, n: usize) -> (usize, usize) {
    let a = i.index(n);
    let b = (a + 1 + j.index(n - 1)) % n;
    (a.min(b), a.max(b))
}

// ================================================================ persistence: properties

/// `persistence` on `rows` (points, or a distance matrix with `matrix`): the general
/// contract, then accepted when `expected` is `None`, else an error at line `expected`.
fn assert_mutation_outcome(
    rows: &[Vec<String>],
    matrix: bool,
    expected: Option<u64>,
) -> Result<(), TestCaseError> {
    let text = csv_text(rows);
    let (path, o, _dir) = persistence(text.as_bytes(), matrix);
    assert_persistence_contract(text.as_bytes(), &path, &o)?;
    match expected {
        None => assert_accepted(&o),
        Some(line) => assert_error_at(&path, &o, line),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CLI_CASES))]

    /// CSV-shaped noise and arbitrary text, read as points or as a matrix: a diagram, or
    /// exit 2 with an error at a line of the file.
    #[test]
    fn persistence_noise_never_panics(
        text in prop_oneof![
            proptest::collection::vec(proptest::sample::select(CSV_TOKENS), 0..60)
                .prop_map(|t| t.concat()),
            any::<String>(),
        ],
        matrix in any::<bool>(),
    ) {
        let (path, o, _dir) = persistence(text.as_bytes(), matrix);
        assert_persistence_contract(text.as_bytes(), &path, &o)?;
    }

    /// One change of a valid points file: accepted when every row is still a point of the
    /// same dimension with finite coordinates within ±1e150, else exit 2 at the first line
    /// that breaks a rule (a row of another width is judged against line 1).
    #[test]
    fn persistence_points_mutation_is_reported_at_its_line(
        n in 2usize..7,
        d in 1usize..4,
        seed in proptest::collection::vec(-200i32..200, 24),
        edit in proptest::option::of(point_edit()),
    ) {
        let mut rows: Vec<Vec<String>> = (0..n)
            .map(|i| (0..d).map(|k| format!("{}", f64::from(seed[i * d + k]) / 4.0)).collect())
            .collect();
        // `None`: accepted; `Some(line)`: rejected at that line.
        let expected: Option<u64> = match &edit {
            None => None,
            Some(PointEdit::Replace(r, c, t)) => {
                let (r, c) = (r.index(n), c.index(d));
                rows[r][c] = (*t).to_string();
                if is_good_coordinate(t) || (d == 1 && t.is_empty()) {
                    // A row of one empty field is a blank line, which the reader skips.
                    None
                } else {
                    Some(r as u64 + 1)
                }
            }
            Some(PointEdit::Drop(r, c)) => {
                let (r, c) = (r.index(n), c.index(d));
                rows[r].remove(c);
                match (d, r) {
                    (1, _) => None,
                    (_, 0) => Some(2),
                    _ => Some(r as u64 + 1),
                }
            }
            Some(PointEdit::Add(r, t)) => {
                let r = r.index(n);
                rows[r].push((*t).to_string());
                // A field that parses as a number (NaN and inf included) lets the reader on
                // to compare the row's width with line 1's.
                if r == 0 && parses_as_f64(t) { Some(2) } else { Some(r as u64 + 1) }
            }
        };
        assert_mutation_outcome(&rows, false, expected)?;
    }

    /// One change of a valid distance matrix: accepted when it is still square, symmetric,
    /// finite, non-negative with a zero diagonal; else exit 2 at the line of the first row
    /// that breaks a rule.
    #[test]
    fn persistence_matrix_mutation_is_reported_at_its_line(
        n in 2usize..7,
        seed in proptest::collection::vec(1u32..=100, 36),
        edit in proptest::option::of(matrix_edit()),
    ) {
        let mut rows: Vec<Vec<String>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let (a, b) = (i.min(j), i.max(j));
                        if a == b { "0".to_string() } else { format!("{}", f64::from(seed[a * 6 + b]) / 2.0) }
                    })
                    .collect()
            })
            .collect();
        let bad = |t: &str| BAD_ENTRIES.contains(&t);
        let expected: Option<u64> = match &edit {
            None => None,
            Some(MatrixEdit::OneSide(i, j, t)) => {
                let (a, b) = pair(i, j, n);
                // Write above or below the diagonal, as `i` says.
                let (r, c) = if i.index(2) == 0 { (a, b) } else { (b, a) };
                rows[r][c] = (*t).to_string();
                // A bad entry fails its own row; a good one makes (a, b) ≠ (b, a).
                Some(if bad(t) { r } else { a } as u64 + 1)
            }
            Some(MatrixEdit::BothSides(i, j, t)) => {
                let (a, b) = pair(i, j, n);
                rows[a][b] = (*t).to_string();
                rows[b][a] = (*t).to_string();
                if bad(t) { Some(a as u64 + 1) } else { None }
            }
            Some(MatrixEdit::Diagonal(i, t)) => {
                let i = i.index(n);
                rows[i][i] = (*t).to_string();
                if matches!(*t, "0" | "-0") { None } else { Some(i as u64 + 1) }
            }
            Some(MatrixEdit::DropRow(i)) => {
                rows.remove(i.index(n));
                Some(1)
            }
            Some(MatrixEdit::DropColumn(j)) => {
                let j = j.index(n);
                for r in &mut rows {
                    r.remove(j);
                }
                Some(1)
            }
            Some(MatrixEdit::AddColumn) => {
                for r in &mut rows {
                    r.push("0".into());
                }
                Some(1)
            }
            Some(MatrixEdit::Shorten(i)) => {
                let i = i.index(n);
                rows[i].pop();
                Some(if i == 0 { 2 } else { i as u64 + 1 })
            }
        };
        assert_mutation_outcome(&rows, true, expected)?;
    }
}

#[test]
fn persistence_rejects_bad_options_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("points.csv");
    std::fs::write(&path, "0,0\n1,0\n0,1\n").unwrap();
    for (args, needle) in [
        (&["--maxdim", "2"][..], "--maxdim"),
        (&["--threshold", "NaN"][..], "threshold NaN"),
        (&["--threshold", "inf"][..], "threshold inf"),
        (&["--threshold", "-1"][..], "threshold -1"),
    ] {
        let o = outcome(swarmmap().arg("persistence").args(args).arg(&path));
        assert_eq!(o.code, Some(2), "{args:?}: {}", o.stderr);
        assert!(o.stderr.contains(needle), "{args:?}: {}", o.stderr);
        assert!(o.stdout.is_empty(), "{args:?}: {}", o.stdout);
    }
    let o = outcome(
        swarmmap()
            .arg("persistence")
            .arg(dir.path().join("missing.csv")),
    );
    assert_ne!(o.code, Some(0));
    assert_ne!(o.code, Some(101));
    assert!(o.stderr.contains("missing.csv"), "{}", o.stderr);
}

#[test]
fn persistence_empty_and_blank_files_name_the_file() {
    for text in ["", "\n", "\n\n\r\n"] {
        let (path, o, _dir) = persistence(text.as_bytes(), false);
        assert_eq!(o.code, Some(2), "{text:?}");
        assert_eq!(
            o.stderr,
            format!(
                "error: {}: the file has no rows; expected one point (or matrix row) per line\n",
                path.display()
            )
        );
    }
}

// ================================================================ --set: helpers

fn empty_world() -> WorldSpec {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/worlds/empty.ron");
    let text = std::fs::read_to_string(path).expect("worlds/empty.ron");
    parse_str(&text, "worlds/empty.ron").expect("worlds/empty.ron parses")
}

/// Whether `path` (trimmed) is one `WorldSpec::set` knows: listed, or `obstacles[i]`
/// (which empty.ron, with no obstacles, still rejects as a bad setting).
fn is_known_path(path: &str) -> bool {
    SETTING_PATHS.contains(&path) || path.starts_with("obstacles[")
}

/// RON values of every shape a setting takes, and noise.
const SET_VALUES: &[&str] = &[
    "0",
    "1",
    "-1",
    "0.03",
    "1e308",
    "1e309",
    "-1e309",
    "NaN",
    "inf",
    "-inf",
    "18446744073709551615",
    "18446744073709551616",
    "4294967296",
    "true",
    "false",
    "\"text\"",
    "\"\"",
    "()",
    "[]",
    "Window",
    "Disk(radius: 1.0)",
    "Disk()",
    "Paper",
    "Embedded",
    "(width: 20.0)",
    "(width: -1.0)",
    "(agents: 0)",
    "(dt: 0.0)",
    "[Circle(center: (5.0, 5.0), radius: 1.0)]",
    "[Rect(min: (1.0, 1.0), max: (0.0, 0.0))]",
    "Some(3)",
    "None",
    "(",
    ")",
    "\"",
    "=",
    "==1",
    " 2 ",
    "0x10",
    "1_000",
    "r#\"raw\"#",
    "é",
    "",
];

/// Paths: listed ones, `obstacles[i]`, near misses and noise, with stray whitespace.
fn set_path() -> impl Strategy<Value = String> {
    let listed = proptest::sample::select(SETTING_PATHS).prop_map(str::to_string);
    let misspelt = (
        proptest::sample::select(SETTING_PATHS),
        any::<Index>(),
        "[a-z._\\[\\]0-9]",
    )
        .prop_map(|(p, i, c)| {
            let mut s = p.to_string();
            s.insert_str(i.index(s.len() + 1), &c);
            s
        });
    let obstacle = "[ 0-9a-z-]{0,4}".prop_map(|i| format!("obstacles[{i}]"));
    let noise = "[ -~]{0,24}";
    let path = prop_oneof![4 => listed, 2 => misspelt, 1 => obstacle, 1 => noise];
    (path, "[ \t]{0,2}", "[ \t]{0,2}").prop_map(|(p, a, b)| format!("{a}{p}{b}"))
}

fn set_value() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => proptest::sample::select(SET_VALUES).prop_map(str::to_string),
        1 => "[ -~]{0,16}",
    ]
}

// ================================================================ --set: properties

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// `apply_assignment` on a real world: an unknown path is `UnknownSetting` naming it, a
    /// value that does not fit is `BadSetting` naming the override, an accepted one is
    /// recorded as an override; a failed override changes nothing; a check error about the
    /// overridden field names the override.
    #[test]
    fn set_never_panics_and_names_the_override(path in set_path(), value in set_value()) {
        let mut spec = empty_world();
        let before = spec.origin.overrides.clone();
        let assignment = format!("{path}={value}");
        // The path ends at the first `=`, as `--set` documents; a path may hold none.
        let (p, v) = assignment.split_once('=').expect("an `=`");
        let (p, v) = (p.trim(), v.trim());
        match apply_assignment(&mut spec, &assignment) {
            Ok(()) => {
                prop_assert!(is_known_path(p), "accepted the unknown path {:?}", p);
                prop_assert_eq!(spec.origin.overrides.last(), Some(&(p.to_string(), v.to_string())));
                if let Err(e) = spec.clone().check() {
                    let WorldError::Invalid { location, field, .. } = &e else {
                        return Err(TestCaseError::fail(format!("check gave {e:?}")));
                    };
                    if field == p || field.starts_with(&format!("{p}.")) || field.starts_with(&format!("{p}[")) {
                        prop_assert!(
                            location.contains(&format!("--set {p}={v}")),
                            "the error about the overridden {} does not name the override: {}",
                            field,
                            e
                        );
                    }
                    prop_assert!(location.starts_with("worlds/empty.ron"), "{}", e);
                }
            }
            Err(e) => {
                prop_assert_eq!(&spec.origin.overrides, &before, "a failed override was recorded");
                let text = e.to_string();
                match &e {
                    WorldError::UnknownSetting { .. } => {
                        prop_assert!(!is_known_path(p), "a listed path is unknown: {}", text);
                        prop_assert!(text.starts_with(&format!("--set {p}")), "{}", text);
                        prop_assert!(text.contains("swarm.detection_radius"), "no list: {}", text);
                    }
                    WorldError::BadSetting { message, .. } => {
                        prop_assert!(is_known_path(p), "a bad value for an unknown path: {}", text);
                        prop_assert!(text.starts_with("--set "), "{}", text);
                        prop_assert!(text.contains(p), "the path is not named: {}", text);
                        prop_assert!(!message.is_empty(), "{}", text);
                    }
                    other => return Err(TestCaseError::fail(format!("unexpected error {other:?}"))),
                }
            }
        }
    }

    /// A finite number set on a numeric field is stored exactly, not rounded or dropped.
    #[test]
    fn set_stores_a_number_exactly(x in -1e300f64..1e300, field in 0usize..4) {
        let mut spec = empty_world();
        let path = ["swarm.detection_radius", "arena.width", "leader.speed", "mapping.overlap"][field];
        apply_assignment(&mut spec, &format!("{path}={x:?}")).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let stored = match field {
            0 => spec.swarm.as_ref().and_then(|s| s.detection_radius),
            1 => spec.arena.as_ref().and_then(|a| a.width),
            2 => spec.leader.as_ref().and_then(|l| l.speed),
            _ => spec.mapping.as_ref().and_then(|m| m.overlap),
        };
        prop_assert_eq!(stored, Some(x));
    }
}

#[test]
fn set_without_equals_sign_is_a_bad_setting() {
    for assignment in ["", "swarm.agents", " ", "seed 3"] {
        let mut spec = empty_world();
        let err = apply_assignment(&mut spec, assignment).unwrap_err();
        assert!(
            matches!(err, WorldError::NoValue { .. }),
            "{assignment:?}: {err:?}"
        );
        assert!(
            err.to_string().contains("expected PATH=VALUE"),
            "{assignment:?}: {err}"
        );
        // Echoed as given, not with an `=` it did not have (forty-first session's review).
        assert!(
            err.to_string()
                .starts_with(&format!("--set {assignment}: expected")),
            "{assignment:?}: {err}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CLI_CASES))]

    /// `swarmmap check worlds/empty.ron --set=…` agrees with the library: exit 0 when the
    /// override and the check pass, else exit 2 with the library's message.
    #[test]
    fn check_with_set_agrees_with_the_library(path in set_path(), value in set_value()) {
        let assignment = format!("{path}={value}");
        let mut spec = empty_world();
        let expected = apply_assignment(&mut spec, &assignment).and_then(|()| spec.check().map(|_| ()));
        let o = outcome(
            swarmmap()
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .args(["check", "worlds/empty.ron"])
                .arg(format!("--set={assignment}")),
        );
        assert_ok_or_input_error(&o)?;
        match expected {
            Ok(()) => prop_assert_eq!(o.code, Some(0), "{}", o.stderr),
            Err(e) => {
                prop_assert_eq!(o.code, Some(2), "{}", o.stdout);
                prop_assert!(o.stderr.contains(&e.to_string()), "expected {}, got {}", e, o.stderr);
            }
        }
    }
}

// ================================================================ run directory: helpers

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/report/tiny");

/// The JSON files a run directory's readers take (`maps/connections.json` is written for
/// people and read by nothing).
const RUN_JSON: &[&str] = &[
    "meta.json",
    "summary.json",
    "maps/window_1.json",
    "maps/window_2.json",
    "maps/connection_1.json",
    "maps/global.json",
];

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// Values a JSON leaf is replaced with: other types, bounds, huge and negative numbers.
const JSON_VALUES: &[&str] = &[
    "null",
    "true",
    "\"x\"",
    "[]",
    "{}",
    "0",
    "-1",
    "1.5",
    "1e308",
    "-1e308",
    "4294967296",
    "18446744073709551615",
    "100000",
    "[0, 0]",
    "[1, 2, 3]",
];

/// One corruption of a JSON file.
#[derive(Debug, Clone)]
enum JsonEdit {
    /// Cut at a byte.
    Truncate(Index),
    /// One byte replaced.
    Byte(Index, u8),
    /// A byte range removed.
    Delete(Index, usize),
    /// A leaf (number, string, boolean, null) replaced by another JSON value.
    Leaf(Index, &'static str),
}

fn json_edit() -> impl Strategy<Value = JsonEdit> {
    prop_oneof![
        1 => any::<Index>().prop_map(JsonEdit::Truncate),
        1 => (
            any::<Index>(),
            proptest::sample::select(&b"{}[]\",:0123456789.-eE ntfx\\\n"[..])
        )
            .prop_map(|(i, b)| JsonEdit::Byte(i, b)),
        1 => (any::<Index>(), 1usize..64).prop_map(|(i, n)| JsonEdit::Delete(i, n)),
        3 => (any::<Index>(), proptest::sample::select(JSON_VALUES))
            .prop_map(|(i, v)| JsonEdit::Leaf(i, v)),
    ]
}

/// JSON pointers of every leaf of `v`.
fn leaves(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                leaves(x, format!("{at}/{i}"), out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                let k = k.replace('~', "~0").replace('/', "~1");
                leaves(x, format!("{at}/{k}"), out);
            }
        }
        _ => out.push(at),
    }
}

/// Applies `edit` to `bytes`; returns the new bytes and, for a leaf, what was replaced.
fn corrupt(bytes: &[u8], edit: &JsonEdit) -> (Vec<u8>, String) {
    let mut b = bytes.to_vec();
    match edit {
        JsonEdit::Truncate(i) => {
            let at = i.index(b.len());
            b.truncate(at);
            (b, format!("truncated at byte {at}"))
        }
        JsonEdit::Byte(i, x) => {
            let at = i.index(b.len());
            b[at] = *x;
            (b, format!("byte {at} := {:?}", *x as char))
        }
        JsonEdit::Delete(i, n) => {
            let at = i.index(b.len());
            let end = (at + n).min(b.len());
            b.drain(at..end);
            (b, format!("bytes {at}..{end} deleted"))
        }
        JsonEdit::Leaf(i, v) => {
            let mut doc: serde_json::Value = serde_json::from_slice(bytes).expect("fixture JSON");
            let mut all = Vec::new();
            leaves(&doc, String::new(), &mut all);
            let at = all[i.index(all.len())].clone();
            *doc.pointer_mut(&at).expect("a leaf") = serde_json::from_str(v).expect("a value");
            (
                serde_json::to_vec_pretty(&doc).expect("serialise"),
                format!("{at} := {v}"),
            )
        }
    }
}

/// A copy of the fixture run with `file` corrupted by `edit`.
fn corrupted_run(file: &str, edit: &JsonEdit) -> (tempfile::TempDir, PathBuf, String) {
    let tmp = tempfile::tempdir().expect("temporary directory");
    let dir = tmp.path().join("run");
    copy_dir(Path::new(FIXTURE), &dir);
    let path = dir.join(file);
    let (bytes, what) = corrupt(&std::fs::read(&path).expect("fixture file"), edit);
    std::fs::write(&path, bytes).expect("write the corrupted file");
    (tmp, dir, format!("{file}: {what}"))
}

/// The name that an error about `file` must carry.
fn file_name(file: &str) -> &str {
    file.rsplit('/').next().unwrap_or(file)
}

// ================================================================ run directory: properties

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// `load_run` then `render` on a corrupted run: a report, or an input error that names
    /// the corrupted file; what `load_run` accepts `render` draws.
    #[test]
    fn report_library_rejects_a_corrupted_file_by_name(
        file in proptest::sample::select(RUN_JSON),
        edit in json_edit(),
    ) {
        let (_tmp, dir, what) = corrupted_run(file, &edit);
        match swarmmap::report::load_run(&dir) {
            Ok(run) => {
                if let Err(e) = swarmmap::report::render(&run) {
                    return Err(TestCaseError::fail(format!("{what}: loaded, but render failed: {e}")));
                }
            }
            Err(e) => {
                prop_assert!(e.is_input(), "{}: not an input error: {}", what, e);
                prop_assert!(
                    e.to_string().contains(file_name(file)),
                    "{}: the error does not name {}: {}",
                    what,
                    file,
                    e
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// `swarmmap report` on a corrupted run: exit 0, or exit 2 naming the file, and no
    /// report written on a failure.
    #[test]
    fn report_cli_rejects_a_corrupted_file_by_name(
        file in proptest::sample::select(RUN_JSON),
        edit in json_edit(),
    ) {
        let (_tmp, dir, what) = corrupted_run(file, &edit);
        let o = outcome(swarmmap().arg("report").arg(&dir));
        assert_ok_or_input_error(&o).map_err(|e| TestCaseError::fail(format!("{what}: {e}")))?;
        if o.code == Some(2) {
            prop_assert!(o.stderr.contains(file_name(file)), "{}: {}", what, o.stderr);
            prop_assert!(!dir.join("report").exists(), "{}: a failed report was written", what);
        }
    }

    /// `swarmmap map` reads `meta.json` (the world and the seed) besides the log: exit 0,
    /// or exit 2 naming it.
    #[test]
    fn map_cli_rejects_a_corrupted_meta_by_name(edit in json_edit()) {
        let (_tmp, dir, what) = corrupted_run("meta.json", &edit);
        let o = outcome(swarmmap().arg("map").arg(&dir));
        assert_ok_or_input_error(&o).map_err(|e| TestCaseError::fail(format!("{what}: {e}")))?;
        if o.code == Some(2) {
            prop_assert!(o.stderr.contains("meta.json"), "{}: {}", what, o.stderr);
        }
    }
}

#[test]
fn report_and_map_of_the_fixture_succeed() {
    // The properties above judge corruptions of this run: it must be valid to begin with.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    copy_dir(Path::new(FIXTURE), &dir);
    let o = outcome(swarmmap().arg("map").arg(&dir));
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    let o = outcome(swarmmap().arg("report").arg(&dir));
    assert_eq!(o.code, Some(0), "{}", o.stderr);
}

// ================================================================ regressions: failures these tests found, fixed

/// The line `persistence` names for `text`, read as points.
fn persistence_error_line(text: &[u8]) -> (Option<i32>, Option<u64>, String) {
    let (path, o, _dir) = persistence(text, false);
    (o.code, error_line(&o.stderr, &path), o.stderr)
}

// `parse_rows` (src/cli/persistence.rs) took its line numbers from `csv::Position::line`,
// which counts only `\n` and lags the records after a blank line or a `\r\n`
// (BurntSushi/rust-csv#395); it now numbers them from byte offsets with `log::LineIndex`.

#[test]
fn persistence_cr_line_endings_name_the_right_line() {
    let (code, line, stderr) = persistence_error_line(b"0,0\r1,0\r2,x\r");
    assert_eq!((code, line), (Some(2), Some(3)), "{stderr}");
}

#[test]
fn persistence_crlf_line_endings_name_the_right_line() {
    let (code, line, stderr) = persistence_error_line(b"0,0\r\n1,0\r\n2,x\r\n");
    assert_eq!((code, line), (Some(2), Some(3)), "{stderr}");
}

#[test]
fn persistence_blank_lines_name_the_right_line() {
    let (code, line, stderr) = persistence_error_line(b"0,0\n\n\n1,x\n");
    assert_eq!((code, line), (Some(2), Some(4)), "{stderr}");
    let (code, line, stderr) = persistence_error_line(b"1,1\n\n\n1,2,3\n");
    assert_eq!((code, line), (Some(2), Some(4)), "{stderr}");
}

#[test]
fn persistence_non_utf8_is_an_input_error_at_its_line() {
    let (code, line, stderr) = persistence_error_line(b"0,0\n1,\xff\n");
    assert_eq!((code, line), (Some(2), Some(2)), "{stderr}");
}

#[test]
fn a_summary_naming_another_map_file_blames_summary_json() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    copy_dir(Path::new(FIXTURE), &dir);
    // The first window's index set to 7: there is no window 7.
    let path = dir.join("summary.json");
    let mut summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    summary["windows"][0]["index"] = serde_json::json!(7);
    std::fs::write(&path, summary.to_string()).unwrap();
    let err = swarmmap::report::load_run(&dir).unwrap_err();
    // Was: "…/maps/window_7.json: file not found; run `swarmmap map RUN_DIR` …".
    assert!(err.to_string().contains("summary.json"), "{err}");
}

#[test]
fn map_rejects_a_meta_seed_that_is_not_a_number() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    copy_dir(Path::new(FIXTURE), &dir);
    let path = dir.join("meta.json");
    let mut meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    meta["seed"] = serde_json::json!("x");
    std::fs::write(&path, meta.to_string()).unwrap();
    // Was: exit 0, and summary.json recorded `"seed": null`.
    let o = outcome(swarmmap().arg("map").arg(&dir));
    assert_eq!(o.code, Some(2), "{}", o.stdout);
    assert!(o.stderr.contains("meta.json"), "{}", o.stderr);
}
