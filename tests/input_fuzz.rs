//! Property tests of every input reader against the project's rule (STYLE.md §5): bad input
//! never panics and never loses data, and its error says where (CSV line, or
//! `file:line:col`), what is wrong and how to fix it.
//!
//! The readers, through the public API: `EncounterLog::read_dir` for `encounters.csv` (with
//! and without the truth columns), `static_intervals.csv` and `leader.csv`; `world::parse_str`
//! and `World::from_str_named` for world files.
//!
//! Three kinds of input:
//! - arbitrary bytes and text, and CSV-shaped or RON-shaped noise that gets past the header
//!   or the first bracket: the readers return `Ok` or `Err`, never panic; a result holds only
//!   values the rules allow; an error points inside the file;
//! - one mutation of a valid log (a field replaced by a random string, NaN, inf, a huge
//!   number or nothing; a field dropped or added; start and end swapped; a header name
//!   changed), judged by an oracle written here from the documented rules: a log the rules
//!   accept is read whole, value for value; one they reject gets an error at the mutated
//!   line that names the column and the value;
//! - mutations of the bundled worlds (a character range deleted, characters inserted, a
//!   number replaced by a random token): no panic, every position inside the text, and a
//!   replaced number that breaks its own rule is reported at its field's name.
//!
//! The failures these properties found are pinned as regression tests at the end (a panic
//! and an unbounded raster for elongated arenas, wrong CSV lines for `\r\n` and `\r` line
//! endings, a field located inside a raw string); all were fixed in src/.

use proptest::prelude::*;
use proptest::sample::Index;
use std::path::Path;
use swarmmap::log::{
    ENCOUNTERS_CSV, Encounter, EncounterLog, LEADER_CSV, LogError, MAX_POSITION, MAX_TIME,
    STATIC_CSV, StaticInterval, StaticReason,
};
use swarmmap::world::{FreeSpaceRaster, World, WorldError, parse_str};

/// Cases per property: the whole file runs in a few seconds in release.
const CASES: u32 = 256;

// ================================================================ logs: helpers

/// A valid `encounters.csv`, so that `read_dir` goes on to the file under test.
const VALID_ENCOUNTERS: &str = "start,end,a,b\n0,1,0,1\n";

/// Writes `files` into a fresh directory and reads it as a log.
fn read_log(files: &[(&str, &[u8])]) -> (tempfile::TempDir, Result<EncounterLog, LogError>) {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).expect("write a log file");
    }
    let log = EncounterLog::read_dir(dir.path());
    (dir, log)
}

/// The files of a log whose file `file` holds `bytes` (with a valid `encounters.csv` when
/// `file` is another one).
fn log_files<'a>(file: &'a str, bytes: &'a [u8]) -> Vec<(&'a str, &'a [u8])> {
    if file == ENCOUNTERS_CSV {
        vec![(file, bytes)]
    } else {
        vec![(ENCOUNTERS_CSV, VALID_ENCOUNTERS.as_bytes()), (file, bytes)]
    }
}

/// Lines of `bytes`: `\n`, `\r\n` and a lone `\r` each end one.
fn line_count(bytes: &[u8]) -> u64 {
    let crlf = bytes.windows(2).filter(|w| w == b"\r\n").count();
    (record_bound(bytes) - crlf) as u64
}

/// Records `bytes` can hold at most: one per line, whatever ends the lines.
fn record_bound(bytes: &[u8]) -> usize {
    bytes
        .iter()
        .filter(|b| **b == b'\n' || **b == b'\r')
        .count()
        + 1
}

/// An error for a log whose files all exist and are readable: a CSV error in `file`, at a
/// line of the file, printed `path:line: message`.
fn assert_csv_error(
    err: &LogError,
    dir: &Path,
    file: &str,
    bytes: &[u8],
) -> Result<(), TestCaseError> {
    let LogError::Csv {
        path,
        line,
        message,
    } = err
    else {
        return Err(TestCaseError::fail(format!(
            "expected a CSV error in {file}, got {err}"
        )));
    };
    prop_assert_eq!(path, &dir.join(file));
    prop_assert!(
        (1..=line_count(bytes)).contains(line),
        "line {} is outside the file's {} lines: {}",
        line,
        line_count(bytes),
        err
    );
    prop_assert!(!message.is_empty(), "empty message: {}", err);
    let prefix = format!("{}:{line}: ", path.display());
    prop_assert!(err.to_string().starts_with(&prefix), "{}", err);
    Ok(())
}

fn assert_time(t: f64) -> Result<(), TestCaseError> {
    prop_assert!(
        t.is_finite() && t.abs() <= MAX_TIME,
        "time {} let through",
        t
    );
    Ok(())
}

fn assert_position(x: f64) -> Result<(), TestCaseError> {
    prop_assert!(
        x.is_finite() && x.abs() <= MAX_POSITION,
        "position {} let through",
        x
    );
    Ok(())
}

/// What any log read without error holds: finite times within ±`MAX_TIME` with
/// `start <= end`, two different agents `a < b`, truth for every encounter or for none,
/// positions within ±`MAX_POSITION`, encounters sorted by `(start, a, b)` and static
/// intervals by `(agent, start)` as `EncounterLog` documents, the leader's track by time.
fn assert_well_formed(log: &EncounterLog) -> Result<(), TestCaseError> {
    for e in &log.encounters {
        assert_time(e.start)?;
        assert_time(e.end)?;
        prop_assert!(e.start <= e.end, "{:?}", e);
        prop_assert!(e.a < e.b, "{:?}", e);
        for x in e.truth.iter().flatten() {
            assert_position(*x)?;
        }
    }
    let with_truth = log.encounters.iter().filter(|e| e.truth.is_some()).count();
    prop_assert!(
        with_truth == 0 || with_truth == log.encounters.len(),
        "truth for some encounters only"
    );
    prop_assert!(
        log.encounters
            .windows(2)
            .all(|w| (w[0].start, w[0].a, w[0].b) <= (w[1].start, w[1].a, w[1].b)),
        "encounters not sorted by (start, a, b)"
    );
    for s in &log.static_intervals {
        assert_time(s.start)?;
        assert_time(s.end)?;
        prop_assert!(s.start <= s.end, "{:?}", s);
    }
    prop_assert!(
        log.static_intervals
            .windows(2)
            .all(|w| (w[0].agent, w[0].start) <= (w[1].agent, w[1].start)),
        "static intervals not sorted by (agent, start)"
    );
    for &(t, x) in &log.leader {
        assert_time(t)?;
        assert_position(x)?;
    }
    prop_assert!(
        log.leader.windows(2).all(|w| w[0].0 <= w[1].0),
        "leader track not sorted by time"
    );
    Ok(())
}

// ================================================================ logs: arbitrary input

/// Field values that probe every rule: specials, bounds, ids, quotes, whitespace, Unicode.
const SPECIAL_FIELDS: &[&str] = &[
    "",
    " ",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+inf",
    "infinity",
    "-0",
    "1e12",
    "-1e12",
    "1.0000001e12",
    "1e9",
    "-1.0000001e9",
    "1e308",
    "1e309",
    "-1e400",
    "5e-324",
    "4294967295",
    "4294967296",
    "-1",
    "+3",
    "0x10",
    "1_000",
    "1.5",
    "1e",
    ".5",
    "5.",
    "landmark",
    "pause",
    "Landmark",
    "\"",
    "\"\"",
    "\"0\"",
    "\"1,2\"",
    "\u{feff}",
    "\u{a0}1\u{a0}",
    "\u{2028}",
    "é",
    "😀",
    "\0",
];

fn special_field() -> impl Strategy<Value = String> {
    prop::sample::select(SPECIAL_FIELDS).prop_map(str::to_string)
}

/// One CSV field: mostly plausible numbers, often a probe, sometimes anything at all.
fn noisy_field() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (0u32..20).prop_map(|n| n.to_string()),
        4 => (-10.0f64..1e4).prop_map(|x| x.to_string()),
        3 => special_field(),
        1 => any::<f64>().prop_map(|x| x.to_string()),
        1 => any::<i64>().prop_map(|x| x.to_string()),
        1 => any::<String>(),
    ]
}

fn line_ending() -> impl Strategy<Value = &'static str> {
    prop::sample::select(&["\n", "\r\n", "\r"][..])
}

/// CSV-shaped noise for a file with `required` and `optional` columns: a header with every
/// required column, some optional ones and maybe a stray one, in any order, then rows of
/// noisy fields (mostly as many as the header has), then maybe raw bytes.
fn csv_noise(
    required: &'static [&'static str],
    optional: &'static [&'static str],
) -> impl Strategy<Value = Vec<u8>> {
    let header = (
        prop::sample::subsequence(optional, 0..=optional.len()),
        prop::option::weighted(0.2, "[a-z_]{1,6}"),
    )
        .prop_flat_map(move |(opt, stray)| {
            let mut cols: Vec<String> =
                required.iter().chain(&opt).map(|s| s.to_string()).collect();
            cols.extend(stray);
            Just(cols).prop_shuffle()
        });
    (header, line_ending(), any::<bool>())
        .prop_flat_map(|(header, eol, final_eol)| {
            let n = header.len();
            let width = prop_oneof![8 => Just(n), 1 => Just(n - 1), 1 => Just(n + 1)];
            let row = width.prop_flat_map(|w| prop::collection::vec(noisy_field(), w));
            let tail = prop::option::weighted(0.25, prop::collection::vec(any::<u8>(), 0..32));
            (
                Just(header),
                prop::collection::vec(row, 0..8),
                Just(eol),
                Just(final_eol),
                tail,
            )
        })
        .prop_map(|(header, rows, eol, final_eol, tail)| {
            let mut text = header.join(",");
            for row in rows {
                text.push_str(eol);
                text.push_str(&row.join(","));
            }
            if final_eol {
                text.push_str(eol);
            }
            let mut bytes = text.into_bytes();
            bytes.extend(tail.into_iter().flatten());
            bytes
        })
}

/// Raw bytes, arbitrary text, or CSV-shaped noise for one log file.
fn log_input(
    required: &'static [&'static str],
    optional: &'static [&'static str],
) -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        1 => prop::collection::vec(any::<u8>(), 0..400),
        1 => any::<String>().prop_map(String::into_bytes),
        4 => csv_noise(required, optional),
    ]
}

/// Reads a log whose `file` holds `bytes`: `Ok` with a well-formed log that has no more
/// records than the file has lines, or a CSV error inside `file`.
fn assert_reads_or_points_into(file: &str, bytes: &[u8]) -> Result<(), TestCaseError> {
    let (dir, got) = read_log(&log_files(file, bytes));
    match got {
        Ok(log) => {
            assert_well_formed(&log)?;
            let records = match file {
                ENCOUNTERS_CSV => log.encounters.len(),
                STATIC_CSV => log.static_intervals.len(),
                _ => log.leader.len(),
            };
            prop_assert!(records <= record_bound(bytes), "{} records", records);
        }
        Err(err) => assert_csv_error(&err, dir.path(), file, bytes)?,
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// `encounters.csv`, without or with (some of) the truth columns `a_x,a_y,b_x,b_y`.
    #[test]
    fn arbitrary_encounters_never_panic(
        bytes in log_input(&["start", "end", "a", "b"], &["a_x", "a_y", "b_x", "b_y"])
    ) {
        assert_reads_or_points_into(ENCOUNTERS_CSV, &bytes)?;
    }

    /// `encounters.csv` with all four truth columns, so that their values are read.
    #[test]
    fn arbitrary_encounters_with_truth_never_panic(
        bytes in csv_noise(&["start", "end", "a", "b", "a_x", "a_y", "b_x", "b_y"], &[])
    ) {
        assert_reads_or_points_into(ENCOUNTERS_CSV, &bytes)?;
    }

    #[test]
    fn arbitrary_static_intervals_never_panic(
        bytes in log_input(&["agent", "start", "end"], &["reason"])
    ) {
        assert_reads_or_points_into(STATIC_CSV, &bytes)?;
    }

    #[test]
    fn arbitrary_leader_tracks_never_panic(bytes in log_input(&["time", "x"], &[])) {
        assert_reads_or_points_into(LEADER_CSV, &bytes)?;
    }
}

// ================================================================ logs: mutations and oracle

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LogFile {
    Encounters,
    Static,
    Leader,
}

impl LogFile {
    fn name(self) -> &'static str {
        match self {
            LogFile::Encounters => ENCOUNTERS_CSV,
            LogFile::Static => STATIC_CSV,
            LogFile::Leader => LEADER_CSV,
        }
    }

    /// Required columns, in the order the README lists them.
    fn required(self) -> &'static [&'static str] {
        match self {
            LogFile::Encounters => &["start", "end", "a", "b"],
            LogFile::Static => &["agent", "start", "end"],
            LogFile::Leader => &["time", "x"],
        }
    }

    /// The two columns a swap exchanges.
    fn swapped(self) -> (&'static str, &'static str) {
        match self {
            LogFile::Leader => ("time", "x"),
            _ => ("start", "end"),
        }
    }
}

/// A log file as a table of fields.
#[derive(Debug, Clone)]
struct Table {
    file: LogFile,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    eol: &'static str,
    final_eol: bool,
}

impl Table {
    fn text(&self) -> String {
        let mut text = self.header.join(",");
        for row in &self.rows {
            text.push_str(self.eol);
            text.push_str(&row.join(","));
        }
        if self.final_eol {
            text.push_str(self.eol);
        }
        text
    }

    fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h.trim() == name)
    }
}

/// A time in seconds with up to two decimals, as a simulator or a spreadsheet writes it.
fn centi(k: i32) -> String {
    (f64::from(k) / 100.0).to_string()
}

impl Table {
    /// The table of `header` and `rows` with its columns in the order given by `perm` (a
    /// permutation of `0..8`, restricted to the table's columns).
    fn permuted(
        file: LogFile,
        header: Vec<&str>,
        rows: Vec<Vec<String>>,
        perm: &[usize],
        eol: &'static str,
        final_eol: bool,
    ) -> Self {
        let order: Vec<usize> = perm.iter().copied().filter(|&i| i < header.len()).collect();
        Self {
            file,
            header: order.iter().map(|&i| header[i].to_string()).collect(),
            rows: rows
                .into_iter()
                .map(|r| order.iter().map(|&i| r[i].clone()).collect())
                .collect(),
            eol,
            final_eol,
        }
    }
}

fn permutation() -> impl Strategy<Value = Vec<usize>> {
    Just((0..8).collect::<Vec<usize>>()).prop_shuffle()
}

/// A valid log file of 1 to 6 rows, columns in any order, lines ended by one of `eols`.
fn valid_table(file: LogFile, eols: &'static [&'static str]) -> BoxedStrategy<Table> {
    let eol = prop::sample::select(eols);
    match file {
        LogFile::Encounters => {
            let row = (
                0i32..1_000_000,
                0i32..10_000,
                0u32..30,
                1u32..30,
                any::<bool>(),
                prop::array::uniform4(-5_000i32..5_000),
            );
            (
                any::<bool>(),
                prop::collection::vec(row, 1..=6),
                permutation(),
                eol,
                any::<bool>(),
            )
                .prop_map(move |(truth, rows, perm, eol, final_eol)| {
                    let mut header = vec!["start", "end", "a", "b"];
                    if truth {
                        header.extend(["a_x", "a_y", "b_x", "b_y"]);
                    }
                    let rows = rows
                        .into_iter()
                        .map(|(start, len, a, gap, flip, xy)| {
                            let (a, b) = if flip { (a + gap, a) } else { (a, a + gap) };
                            let mut r = vec![
                                centi(start),
                                centi(start + len),
                                a.to_string(),
                                b.to_string(),
                            ];
                            if truth {
                                r.extend(xy.iter().map(|&k| centi(k)));
                            }
                            r
                        })
                        .collect();
                    Table::permuted(file, header, rows, &perm, eol, final_eol)
                })
                .boxed()
        }
        LogFile::Static => {
            let row = (0u32..30, 0i32..1_000_000, 0i32..10_000, any::<bool>());
            (
                any::<bool>(),
                prop::collection::vec(row, 1..=6),
                permutation(),
                eol,
                any::<bool>(),
            )
                .prop_map(move |(with_reason, rows, perm, eol, final_eol)| {
                    let mut header = vec!["agent", "start", "end"];
                    if with_reason {
                        header.push("reason");
                    }
                    let rows = rows
                        .into_iter()
                        .map(|(agent, start, len, pause)| {
                            let mut r = vec![agent.to_string(), centi(start), centi(start + len)];
                            if with_reason {
                                r.push(if pause { "pause" } else { "landmark" }.to_string());
                            }
                            r
                        })
                        .collect();
                    Table::permuted(file, header, rows, &perm, eol, final_eol)
                })
                .boxed()
        }
        LogFile::Leader => {
            let row = (0i32..1_000_000, -5_000i32..5_000);
            (
                prop::collection::vec(row, 1..=6),
                permutation(),
                eol,
                any::<bool>(),
            )
                .prop_map(move |(rows, perm, eol, final_eol)| {
                    let rows = rows
                        .into_iter()
                        .map(|(t, x)| vec![centi(t), centi(x)])
                        .collect();
                    Table::permuted(file, vec!["time", "x"], rows, &perm, eol, final_eol)
                })
                .boxed()
        }
    }
}

/// A field that keeps the CSV structure (no comma, quote or line break): a probe, any
/// number, a valid-looking id or time, or random text.
fn field_token() -> impl Strategy<Value = String> {
    let plain = |s: &String| !s.contains([',', '"', '\n', '\r']);
    prop_oneof![
        3 => special_field().prop_filter("keeps the CSV structure", plain),
        2 => any::<f64>().prop_map(|x| x.to_string()),
        1 => (-1e13f64..1e13).prop_map(|x| x.to_string()),
        1 => any::<i64>().prop_map(|x| x.to_string()),
        2 => (0u32..60).prop_map(|x| x.to_string()),
        1 => (" {0,2}", 0u32..60, " {0,2}").prop_map(|(l, x, r)| format!("{l}{x}{r}")),
        2 => "[^,\"\r\n]{0,12}",
    ]
}

/// One change to a valid table.
#[derive(Debug, Clone)]
enum Mutation {
    /// Field `col` of row `row` becomes the token.
    Replace {
        row: Index,
        col: Index,
        token: String,
    },
    /// Field `col` of row `row` is removed.
    Drop { row: Index, col: Index },
    /// A field is inserted into row `row` before field `at`.
    Add {
        row: Index,
        at: Index,
        token: String,
    },
    /// The row's start and end (time and x for the leader) are exchanged.
    Swap { row: Index },
    /// Header column `col` gets a name no reader knows.
    Rename { col: Index, name: String },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let unknown = "[a-z_]{1,8}".prop_filter("not a column name", |s| {
        ![
            "start", "end", "a", "b", "a_x", "a_y", "b_x", "b_y", "agent", "reason", "time", "x",
        ]
        .contains(&s.as_str())
    });
    prop_oneof![
        6 => (any::<Index>(), any::<Index>(), field_token())
            .prop_map(|(row, col, token)| Mutation::Replace { row, col, token }),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(row, col)| Mutation::Drop { row, col }),
        1 => (any::<Index>(), any::<Index>(), field_token())
            .prop_map(|(row, at, token)| Mutation::Add { row, at, token }),
        1 => any::<Index>().prop_map(|row| Mutation::Swap { row }),
        1 => (any::<Index>(), unknown).prop_map(|(col, name)| Mutation::Rename { col, name }),
    ]
}

/// The mutated table and the CSV line the mutation is on (1 is the header).
fn apply(t: &Table, m: &Mutation) -> (Table, u64) {
    let mut out = t.clone();
    let line_of = |row: usize| row as u64 + 2;
    let line = match m {
        Mutation::Replace { row, col, token } => {
            let r = row.index(out.rows.len());
            let c = col.index(out.rows[r].len());
            out.rows[r][c] = token.clone();
            line_of(r)
        }
        Mutation::Drop { row, col } => {
            let r = row.index(out.rows.len());
            let c = col.index(out.rows[r].len());
            out.rows[r].remove(c);
            line_of(r)
        }
        Mutation::Add { row, at, token } => {
            let r = row.index(out.rows.len());
            let c = at.index(out.rows[r].len() + 1);
            out.rows[r].insert(c, token.clone());
            line_of(r)
        }
        Mutation::Swap { row } => {
            let r = row.index(out.rows.len());
            let (x, y) = t.file.swapped();
            let (i, j) = (t.column(x).expect("column"), t.column(y).expect("column"));
            out.rows[r].swap(i, j);
            line_of(r)
        }
        Mutation::Rename { col, name } => {
            let c = col.index(out.header.len());
            out.header[c] = name.clone();
            1
        }
    };
    (out, line)
}

/// Where the oracle expects an error, and what its message must contain.
#[derive(Debug)]
struct Expected {
    line: u64,
    needles: Vec<String>,
}

/// A cell as the documented messages show it: control characters and the backslash as
/// Rust escapes them (`\0`, `\t`, `\u{1b}`, `\\`), everything else as it is.
fn shown(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_control() || c == '\\' {
                c.escape_debug().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A number under the documented rules: Rust's float syntax, finite, within ±`max`.
fn number(name: &str, s: &str, max: f64) -> Result<f64, Vec<String>> {
    let culprit = format!("column `{name}` is `{}`", shown(s));
    match s.parse::<f64>() {
        Err(_) => Err(vec![culprit, "not a number".into()]),
        Ok(v) if !v.is_finite() => Err(vec![culprit, "must be finite".into()]),
        Ok(v) if v.abs() > max => Err(vec![culprit, "beyond ±".into()]),
        Ok(v) => Ok(v),
    }
}

fn agent(name: &str, s: &str) -> Result<u32, Vec<String>> {
    s.parse::<u32>().map_err(|_| {
        vec![
            format!("column `{name}` is `{}`", shown(s)),
            "agent ids are whole numbers from 0 to 4294967295".into(),
        ]
    })
}

fn interval<'r>(get: &dyn Fn(&str) -> &'r str) -> Result<(f64, f64), Vec<String>> {
    let start = number("start", get("start"), MAX_TIME)?;
    let end = number("end", get("end"), MAX_TIME)?;
    if end < start {
        return Err(vec![format!(
            "end {} is before start {}",
            as_written(end),
            as_written(start)
        )]);
    }
    Ok((start, end))
}

/// A number as messages write it (README, "Errors"): exactly, with an exponent outside
/// 1e-6 ≤ |x| < 1e9.
fn as_written(x: f64) -> String {
    if x == 0.0 || (1e-6..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// The oracle: what `read_dir` must give for the table, written here from the documented
/// rules (the README's table of output files and the doc comments of `swarmmap::log`):
/// required columns, one value per column, finite times within ±`MAX_TIME` with
/// `end >= start`, agent ids `u32` and different, truth read only when all four columns
/// are there and within ±`MAX_POSITION`, `reason` `landmark` or `pause`, rows sorted
/// stably as listed. Numbers and ids use Rust's syntax; whitespace around fields and
/// header names is ignored, as the reader trims them.
fn oracle(t: &Table) -> Result<EncounterLog, Expected> {
    for r in t.file.required() {
        if t.column(r).is_none() {
            return Err(Expected {
                line: 1,
                needles: vec![format!("missing column `{r}`")],
            });
        }
    }
    let truth = ["a_x", "a_y", "b_x", "b_y"];
    let with_truth = truth.iter().all(|c| t.column(c).is_some());
    let with_reason = t.column("reason").is_some();
    let mut log = EncounterLog::default();
    for (i, row) in t.rows.iter().enumerate() {
        let line = i as u64 + 2;
        if row.len() != t.header.len() {
            let needles = vec![format!(
                "this row has {} fields but the header has {}",
                row.len(),
                t.header.len()
            )];
            return Err(Expected { line, needles });
        }
        let get = |name: &str| row[t.column(name).expect("column")].trim();
        let parsed = match t.file {
            LogFile::Encounters => (|| {
                let (start, end) = interval(&get)?;
                let (a, b) = (agent("a", get("a"))?, agent("b", get("b"))?);
                if a == b {
                    return Err(vec![format!("agent {a} meets itself")]);
                }
                let xy = if with_truth {
                    let mut xy = [0.0; 4];
                    for (v, c) in xy.iter_mut().zip(truth) {
                        *v = number(c, get(c), MAX_POSITION)?;
                    }
                    Some(xy)
                } else {
                    None
                };
                let (a, b, xy) = if a < b {
                    (a, b, xy)
                } else {
                    (b, a, xy.map(|t| [t[2], t[3], t[0], t[1]]))
                };
                log.encounters.push(Encounter {
                    start,
                    end,
                    a,
                    b,
                    truth: xy,
                });
                Ok(())
            })(),
            LogFile::Static => (|| {
                let (start, end) = interval(&get)?;
                let reason = match with_reason.then(|| get("reason")) {
                    None | Some("landmark") => StaticReason::Landmark,
                    Some("pause") => StaticReason::Pause,
                    Some(other) => {
                        return Err(vec![
                            format!("column `reason` is `{}`", shown(other)),
                            "use `landmark` or `pause`".into(),
                        ]);
                    }
                };
                let agent = agent("agent", get("agent"))?;
                log.static_intervals.push(StaticInterval {
                    agent,
                    start,
                    end,
                    reason,
                });
                Ok(())
            })(),
            LogFile::Leader => (|| {
                let time = number("time", get("time"), MAX_TIME)?;
                let x = number("x", get("x"), MAX_POSITION)?;
                log.leader.push((time, x));
                Ok(())
            })(),
        };
        parsed.map_err(|needles| Expected { line, needles })?;
    }
    Ok(log)
}

/// `EncounterLog` documents only the sort keys (`(start, a, b)`, `(agent, start)`; the
/// leader's track is read in time order), which `assert_well_formed` checks; rows with
/// equal keys may come in any order, so the rows read and the oracle's are compared in a
/// total order.
fn total_order(log: &mut EncounterLog) {
    let truth = |e: &Encounter| e.truth.map(|t| t.map(f64::to_bits));
    log.encounters.sort_by(|x, y| {
        (x.start.total_cmp(&y.start))
            .then(x.a.cmp(&y.a))
            .then(x.b.cmp(&y.b))
            .then(x.end.total_cmp(&y.end))
            .then(truth(x).cmp(&truth(y)))
    });
    log.static_intervals.sort_by(|x, y| {
        (x.agent.cmp(&y.agent))
            .then(x.start.total_cmp(&y.start))
            .then(x.end.total_cmp(&y.end))
            .then((x.reason as u8).cmp(&(y.reason as u8)))
    });
    log.leader
        .sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
}

/// Reads the table as its log file and compares with the oracle: the same rows, value for
/// value, or an error at `line` naming the culprit.
fn assert_matches_oracle(t: &Table, line: u64) -> Result<(), TestCaseError> {
    let text = t.text();
    let file = t.file.name();
    let (dir, got) = read_log(&log_files(file, text.as_bytes()));
    match (oracle(t), got) {
        (Ok(mut want), Ok(mut log)) => {
            assert_well_formed(&log)?;
            total_order(&mut want);
            total_order(&mut log);
            match t.file {
                LogFile::Encounters => prop_assert_eq!(&log.encounters, &want.encounters),
                LogFile::Static => prop_assert_eq!(&log.static_intervals, &want.static_intervals),
                LogFile::Leader => prop_assert_eq!(&log.leader, &want.leader),
            }
        }
        (Err(want), Err(err)) => {
            // The oracle itself must blame the mutated line.
            prop_assert_eq!(want.line, line, "oracle: {:?}", want);
            assert_csv_error(&err, dir.path(), file, text.as_bytes())?;
            let LogError::Csv {
                line: got, message, ..
            } = &err
            else {
                unreachable!()
            };
            prop_assert_eq!(
                *got,
                line,
                "wrong line in {:?} for\n{}",
                err.to_string(),
                text
            );
            for needle in &want.needles {
                prop_assert!(
                    message.contains(needle.as_str()),
                    "{:?} lacks {:?}",
                    message,
                    needle
                );
            }
        }
        (Ok(_), Err(err)) => {
            return Err(TestCaseError::fail(format!(
                "a valid log was rejected: {err}\n{text}"
            )));
        }
        (Err(want), Ok(_)) => {
            return Err(TestCaseError::fail(format!(
                "an invalid log was accepted (expected an error at line {}: {:?})\n{text}",
                want.line, want.needles
            )));
        }
    }
    Ok(())
}

/// Every line ending a reader meets: Unix, Windows, classic Mac OS.
const ALL_EOLS: &[&str] = &["\n", "\r\n", "\r"];

fn log_file() -> impl Strategy<Value = LogFile> {
    prop::sample::select(&[LogFile::Encounters, LogFile::Static, LogFile::Leader][..])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// The generator and the oracle agree with the reader on valid logs: read whole.
    #[test]
    fn valid_logs_are_read_whole(
        t in log_file().prop_flat_map(|f| valid_table(f, ALL_EOLS))
    ) {
        prop_assert!(oracle(&t).is_ok(), "the generator made an invalid table: {:?}", t);
        assert_matches_oracle(&t, 0)?;
    }

}

proptest! {
    // Three files share this property: as many cases as three properties would run.
    #![proptest_config(ProptestConfig::with_cases(3 * CASES))]

    /// One mutation of a valid log of each file: read whole if the rules accept it,
    /// otherwise rejected at the mutated line.
    #[test]
    fn mutated_logs_are_read_whole_or_rejected_at_the_line(
        t in log_file().prop_flat_map(|f| valid_table(f, ALL_EOLS)),
        m in mutation(),
    ) {
        let (t, line) = apply(&t, &m);
        assert_matches_oracle(&t, line)?;
    }
}

// ================================================================ worlds: helpers

/// Origin name of the texts parsed here.
const ORIGIN: &str = "t.ron";

/// The bundled worlds, fast to check (at most ≈ 60 ms each in release): mutated, then
/// parsed and checked.
const CHECKED_WORLDS: &[(&str, &str)] = &[
    ("empty", include_str!("../worlds/empty.ron")),
    ("scenario1", include_str!("../worlds/scenario1.ron")),
    ("scenario2", include_str!("../worlds/scenario2.ron")),
    ("corridor", include_str!("../worlds/corridor.ron")),
    (
        "corridor_lanes",
        include_str!("../worlds/corridor_lanes.ron"),
    ),
    ("touching", include_str!("../worlds/touching.ron")),
];

/// The other bundled worlds (up to ≈ 0.2 s to check): mutated and parsed.
const PARSED_WORLDS: &[(&str, &str)] = &[
    ("pillars", include_str!("../worlds/pillars.ron")),
    ("nonconvex", include_str!("../worlds/nonconvex.ron")),
    ("scenario3", include_str!("../worlds/scenario3.ron")),
];

/// The rest of line `line` from column `col` (1-based, in chars, lines ended by `\n`, as
/// ron counts them); `None` when the position is not in the text. The end of a line, and
/// of the text, is a position.
fn at(text: &str, line: usize, col: usize) -> Option<&str> {
    let l = text.split('\n').nth(line.checked_sub(1)?)?;
    let start = col.checked_sub(1)?;
    match l.char_indices().nth(start) {
        Some((i, _)) => Some(&l[i..]),
        None if start == l.chars().count() => Some(""),
        None => None,
    }
}

/// `line:col` in `s`.
fn line_col(s: &str) -> Option<(usize, usize)> {
    let (l, c) = s.split_once(':')?;
    Some((l.parse().ok()?, c.parse().ok()?))
}

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// A world error against the text it came from. Syntax: `t.ron:line:col: ` with the
/// position inside the text. Invalid: located at the file alone, or at `t.ron:line:col`
/// where the text shows the name of the culprit field or of a section holding it (or, for
/// a list element, the element itself). Nothing else can come from parsing and checking.
fn assert_world_error(err: &WorldError, text: &str) -> Result<(), TestCaseError> {
    match err {
        WorldError::Syntax {
            origin,
            line,
            col,
            message,
        } => {
            prop_assert_eq!(origin, ORIGIN);
            prop_assert!(
                at(text, *line, *col).is_some(),
                "{} points outside the text {:?}",
                err,
                text
            );
            prop_assert!(!message.is_empty());
            let prefix = format!("{ORIGIN}:{line}:{col}: ");
            prop_assert!(err.to_string().starts_with(&prefix), "{}", err);
        }
        WorldError::Invalid {
            location, field, ..
        } => {
            if location == ORIGIN {
                return Ok(());
            }
            let pos = location.strip_prefix("t.ron:").and_then(line_col);
            prop_assert!(pos.is_some(), "location {:?} of {}", location, err);
            let (line, col) = pos.expect("checked");
            let rest = at(text, line, col);
            prop_assert!(rest.is_some(), "{} points outside the text {:?}", err, text);
            let rest = rest.expect("checked");
            let names_a_step = field
                .split(['.', '[', ']'])
                .filter(|s| s.starts_with(|c: char| c.is_alphabetic()))
                .any(|name| {
                    rest.strip_prefix(name)
                        .is_some_and(|after| !after.starts_with(is_ident_char))
                });
            let at_an_element =
                field.contains('[') && rest.starts_with(|c: char| is_ident_char(c) || c == '(');
            prop_assert!(
                names_a_step || at_an_element,
                "{} points at {:?}, not at `{}` or a section holding it, in {:?}",
                err,
                rest,
                field,
                text
            );
        }
        other => {
            return Err(TestCaseError::fail(format!(
                "parsing and checking gave {other:?}"
            )));
        }
    }
    Ok(())
}

/// Parses and checks `text`; every error must pass `assert_world_error`.
fn assert_world_reads_or_points_into(text: &str, check: bool) -> Result<(), TestCaseError> {
    match parse_str(text, ORIGIN) {
        Err(err) => assert_world_error(&err, text)?,
        Ok(spec) if check => {
            if let Err(err) = spec.check() {
                assert_world_error(&err, text)?;
            }
        }
        Ok(_) => {}
    }
    Ok(())
}

// ================================================================ worlds: arbitrary input

/// RON tokens of world files, for noise that often gets past the first bracket.
const RON_TOKENS: &[&str] = &[
    "(",
    "(",
    ")",
    ")",
    "[",
    "]",
    ",",
    ",",
    ":",
    ":",
    " ",
    "\n",
    "name",
    "arena",
    "width",
    "height",
    "obstacles",
    "Rect",
    "Circle",
    "Polygon",
    "Wall",
    "min",
    "max",
    "center",
    "radius",
    "points",
    "from",
    "to",
    "thickness",
    "swarm",
    "agents",
    "speed",
    "detection_radius",
    "landmark_fraction",
    "body_radius",
    "placement",
    "Disk",
    "Window",
    "leader",
    "window",
    "start_x",
    "end_x",
    "simulation",
    "dt",
    "dispersion_time",
    "mapping",
    "windows",
    "overlap",
    "method",
    "Paper",
    "Embedded",
    "seed",
    "Some",
    "None",
    "0",
    "1",
    "-1",
    "2.5",
    "10.0",
    "30.0",
    "0.004",
    "1e9",
    "1e308",
    "NaN",
    "inf",
    "-inf",
    "\"w\"",
    "\"\"",
    "'c'",
    "true",
    "// note\n",
    "/* c */",
    "#![enable(implicit_some)]",
];

fn ron_noise() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(RON_TOKENS), 0..60).prop_map(|t| t.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn arbitrary_world_text_never_panics(text in any::<String>()) {
        assert_world_reads_or_points_into(&text, true)?;
    }

    #[test]
    fn ron_shaped_noise_never_panics(text in ron_noise()) {
        assert_world_reads_or_points_into(&text, true)?;
    }
}

// ================================================================ worlds: mutations

/// A number of a world file that is not inside a list: its field path (`arena.width`),
/// where the field's name starts and where its value starts (just after the colon; 1-based
/// line and column), and the number's byte range.
#[derive(Debug, Clone)]
struct Number {
    path: String,
    name_at: (usize, usize),
    value_at: (usize, usize),
    range: std::ops::Range<usize>,
}

/// The numbers of a world file outside lists, found by a scanner written here: `//`
/// comments and strings skipped, `name:` remembered, `(` opens a section named by the
/// field before it, `[` a list.
fn numbers(text: &str) -> Vec<Number> {
    // An open bracket: the field it is the value of, and whether it is a list.
    let mut open: Vec<(Option<String>, bool)> = Vec::new();
    // The last `name:`: the name, where it starts, where its value starts.
    type Pos = (usize, usize);
    let mut field: Option<(String, Pos, Pos)> = None;
    let mut out = Vec::new();
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let (mut i, mut line, mut col) = (0, 1, 1);
    let advance = |i: &mut usize, line: &mut usize, col: &mut usize| {
        if chars[*i].1 == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    while i < chars.len() {
        let c = chars[i].1;
        let next = chars.get(i + 1).map(|x| x.1);
        let here = (line, col);
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i].1 != '\n' {
                advance(&mut i, &mut line, &mut col);
            }
        } else if c == '"' {
            advance(&mut i, &mut line, &mut col);
            while i < chars.len() && chars[i].1 != '"' {
                advance(&mut i, &mut line, &mut col);
            }
            advance(&mut i, &mut line, &mut col);
        } else if c == '(' || c == '[' {
            open.push((field.take().map(|f| f.0), c == '['));
            advance(&mut i, &mut line, &mut col);
        } else if c == ')' || c == ']' {
            open.pop();
            field = None;
            advance(&mut i, &mut line, &mut col);
        } else if c == ',' {
            field = None;
            advance(&mut i, &mut line, &mut col);
        } else if c.is_ascii_digit() || (c == '-' && next.is_some_and(|n| n.is_ascii_digit())) {
            let start = chars[i].0;
            while i < chars.len()
                && (chars[i].1.is_ascii_alphanumeric() || "._+-".contains(chars[i].1))
            {
                advance(&mut i, &mut line, &mut col);
            }
            let end = chars.get(i).map_or(text.len(), |x| x.0);
            let sections: Option<Vec<String>> = match open.split_first() {
                Some(((None, false), rest)) => rest
                    .iter()
                    .map(|(name, list)| name.clone().filter(|_| !list))
                    .collect(),
                _ => None,
            };
            if let (Some(mut path), Some((name, name_at, value_at))) = (sections, field.take()) {
                path.push(name);
                out.push(Number {
                    path: path.join("."),
                    name_at,
                    value_at,
                    range: start..end,
                });
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = chars[i].0;
            while i < chars.len() && is_ident_char(chars[i].1) {
                advance(&mut i, &mut line, &mut col);
            }
            let word = &text[start..chars.get(i).map_or(text.len(), |x| x.0)];
            let mut j = i;
            while j < chars.len() && chars[j].1 == ' ' {
                j += 1;
            }
            if chars.get(j).map(|x| x.1) == Some(':') {
                field = Some((word.to_string(), here, here));
            }
        } else if c == ':' {
            advance(&mut i, &mut line, &mut col);
            if let Some(f) = field.as_mut() {
                f.2 = (line, col);
            }
        } else {
            advance(&mut i, &mut line, &mut col);
        }
    }
    out
}

/// Tokens to put where a number was: wrong signs and sizes, non-finite values, other
/// types, broken syntax.
const NUMBER_TOKENS: &[&str] = &[
    "-1",
    "0",
    "-0.0",
    "1e-300",
    "5e-324",
    "0.5",
    "2",
    "1e9",
    "1e308",
    "1.8e308",
    "1e400",
    "-1e400",
    "NaN",
    "inf",
    "-inf",
    "+inf",
    "+5",
    ".5",
    "5.",
    "1e",
    "1.0.0",
    "--1",
    "1 2",
    "1_000",
    "0x1F",
    "0b101",
    "99999999999999999999",
    "-9223372036854775809",
    "18446744073709551616",
    "abc",
    "true",
    "None",
    "Some(1.0)",
    "\"x\"",
    "'c'",
    "()",
    "[]",
    "(",
    ")",
    "[",
    "]",
    ",",
    "",
    ":",
    "/*",
    "//",
    "é",
    "\u{0}",
];

fn number_token() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => prop::sample::select(NUMBER_TOKENS).prop_map(str::to_string),
        2 => any::<f64>().prop_map(|x| x.to_string()),
        1 => any::<i64>().prop_map(|x| x.to_string()),
        1 => "[0-9a-z.e+_-]{0,6}",
    ]
}

/// A change to a world file.
#[derive(Debug, Clone)]
enum WorldMutation {
    /// Up to 20 characters from the `at`-th on are deleted.
    Delete { at: Index, len: usize },
    /// Characters are inserted before the `at`-th.
    Insert { at: Index, chars: String },
    /// The `which`-th number outside a list becomes the token.
    Replace { which: Index, token: String },
}

const INSERT_CHARS: &[char] = &[
    '(', ')', '[', ']', ',', ':', '"', '\'', '/', '*', '#', '-', '+', '.', 'e', '0', '1', '9', 'a',
    'r', '_', ' ', '\n', '\t', '\r', 'é', '∞', '\u{0}', '\u{feff}',
];

fn world_mutation() -> impl Strategy<Value = WorldMutation> {
    let ch = prop_oneof![3 => prop::sample::select(INSERT_CHARS), 1 => any::<char>()];
    prop_oneof![
        (any::<Index>(), 1usize..=20).prop_map(|(at, len)| WorldMutation::Delete { at, len }),
        (any::<Index>(), prop::collection::vec(ch, 1..=4)).prop_map(|(at, c)| {
            WorldMutation::Insert {
                at,
                chars: c.into_iter().collect(),
            }
        }),
        (any::<Index>(), number_token())
            .prop_map(|(which, token)| WorldMutation::Replace { which, token }),
    ]
}

fn mutate_world(text: &str, m: &WorldMutation) -> String {
    let byte = |k: usize| text.char_indices().nth(k).map_or(text.len(), |x| x.0);
    let n = text.chars().count();
    match m {
        WorldMutation::Delete { at, len } => {
            let k = at.index(n);
            format!("{}{}", &text[..byte(k)], &text[byte((k + len).min(n))..])
        }
        WorldMutation::Insert { at, chars } => {
            let k = byte(at.index(n + 1));
            format!("{}{chars}{}", &text[..k], &text[k..])
        }
        WorldMutation::Replace { which, token } => {
            let nums = numbers(text);
            let r = nums[which.index(nums.len())].range.clone();
            format!("{}{token}{}", &text[..r.start], &text[r.end..])
        }
    }
}

/// One of the bundled worlds and whether it is checked as well as parsed.
fn bundled_world() -> impl Strategy<Value = (&'static str, &'static str, bool)> {
    let all: Vec<(&str, &str, bool)> = CHECKED_WORLDS
        .iter()
        .map(|&(n, t)| (n, t, true))
        .chain(PARSED_WORLDS.iter().map(|&(n, t)| (n, t, false)))
        .collect();
    prop::sample::select(all)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn mutated_worlds_never_panic(
        (name, text, check) in bundled_world(),
        m in world_mutation(),
    ) {
        let mutated = mutate_world(text, &m);
        assert_world_reads_or_points_into(&mutated, check)
            .map_err(|e| TestCaseError::fail(format!("{name}: {e}")))?;
    }

    /// A replaced number outside a list: a syntax error at or after the start of the
    /// field's value (ron puts a bad value's span at the whitespace after the colon), and a
    /// value that breaks its own field's rule reported at that field's name.
    #[test]
    fn replaced_numbers_are_reported_at_their_field(
        (name, text) in prop::sample::select(CHECKED_WORLDS),
        which in any::<Index>(),
        token in number_token(),
    ) {
        let nums = numbers(text);
        prop_assert!(nums.len() >= 5, "{}: the scanner found only {:?}", name, nums);
        let num = &nums[which.index(nums.len())];
        let mutated = format!("{}{token}{}", &text[..num.range.start], &text[num.range.end..]);
        let checked = parse_str(&mutated, ORIGIN).and_then(|spec| spec.check());
        let Err(err) = checked else { return Ok(()) };
        assert_world_error(&err, &mutated)?;
        match &err {
            WorldError::Syntax { line, col, .. } => prop_assert!(
                (*line, *col) >= num.value_at,
                "{}: `{}` = {:?} at {:?} reported before it: {}",
                name, num.path, token, num.value_at, err
            ),
            WorldError::Invalid { location, field, .. } if *field == num.path => {
                let want = format!("{ORIGIN}:{}:{}", num.name_at.0, num.name_at.1);
                prop_assert_eq!(location, &want, "{}: {}", name, err);
            }
            _ => {}
        }
    }
}

#[test]
fn the_number_scanner_finds_the_fields_of_empty_ron() {
    let text = CHECKED_WORLDS[0].1;
    let paths: Vec<String> = numbers(text).into_iter().map(|n| n.path).collect();
    assert_eq!(
        paths,
        [
            "arena.width",
            "arena.height",
            "swarm.agents",
            "swarm.detection_radius",
            "swarm.landmark_fraction",
            "mapping.windows",
            "mapping.cluster_cutoff",
            "mapping.switch_cost",
            "mapping.rips_points",
            "seed",
        ]
    );
    // A value that breaks its field's rule is reported at the field's name.
    let n = numbers(text)
        .into_iter()
        .find(|n| n.path == "arena.height")
        .unwrap();
    let mutated = format!("{}-1{}", &text[..n.range.start], &text[n.range.end..]);
    let err = World::from_str_named(&mutated, ORIGIN)
        .unwrap_err()
        .to_string();
    let want = format!("t.ron:{}:{}: arena.height is -1", n.name_at.0, n.name_at.1);
    assert!(err.starts_with(&want), "{err}");
}

// ================================================================ known failures

/// `empty.ron` with `height` set to `value`.
fn empty_world_with_height(value: &str) -> String {
    let text = CHECKED_WORLDS[0].1;
    assert!(text.contains("height: 10.0"));
    text.replace("height: 10.0", &format!("height: {value}"))
}

/// Regression (found by `mutated_worlds_never_panic`, shrunk to `empty.ron` with a height
/// of about 8.3e246): `FreeSpaceRaster::new` grew square cells to `sqrt(width · height /
/// 4e6)`, far wider than a 30 m × 1e300 m arena, so its row count saturated `usize` and
/// `Vec::with_capacity` panicked ("capacity overflow"; a flat arena with `placement:
/// Window` took the same path). The counts are now clamped.
#[test]
fn a_tall_arena_is_checked_without_a_panic() {
    let text = empty_world_with_height("1e300");
    if let Err(err) = World::from_str_named(&text, ORIGIN) {
        assert_world_error(&err, &text).unwrap();
    }
    // The check now refuses it (sides over 10 km) before any raster; a `World` built in
    // code still reaches the raster, whose counts stay clamped.
    let mut world = World::from_str_named(CHECKED_WORLDS[0].1, ORIGIN).expect("valid");
    world.arena.height = 1e300;
    let raster = FreeSpaceRaster::new(&world, world.swarm.body_radius);
    assert!(raster.nx * raster.ny <= 4_000_000);
}

/// Regression, the same cause short of a panic: an arena of aspect ratio r > 4e6 got
/// about `sqrt(4e6 · r)` cells, beyond the documented four million (a 30 m × 1e9 m arena
/// 11.5 million; 1e20 m aborted the process when the allocation failed). The world check
/// now refuses sides over 10 km, but a `World` built in code reaches the raster unchecked.
#[test]
fn free_space_raster_is_bounded_for_an_elongated_arena() {
    let err = World::from_str_named(&empty_world_with_height("1e9"), ORIGIN).unwrap_err();
    assert!(err.to_string().contains("more than 10000 m"), "{err}");
    let mut world = World::from_str_named(CHECKED_WORLDS[0].1, ORIGIN).expect("valid");
    world.arena.height = 1e9;
    let raster = FreeSpaceRaster::new(&world, world.swarm.body_radius);
    let cells = raster.nx * raster.ny;
    assert!(
        cells <= 4_000_000,
        "{} × {} = {cells} cells",
        raster.nx,
        raster.ny
    );
}

/// The error of reading an `encounters.csv` of `text` (which must be invalid).
fn encounters_error(text: &str) -> String {
    let (_dir, got) = read_log(&[(ENCOUNTERS_CSV, text.as_bytes())]);
    got.unwrap_err().to_string()
}

/// Regressions of the CSV line numbers. csv-core counts a line when it consumes a `\n`,
/// which with CRLF happens only after it has taken the next record's position, so every
/// error in a Windows file was one line early (found by the `mutated_*` properties, shrunk
/// to `start,end,a,b\r\n,0.01,0,1`; upstream BurntSushi/rust-csv#395); it counts lines by
/// `\n` only, so in a CR-only file (classic Mac OS, Excel's "CSV (Macintosh)") every error
/// was at line 1; and it places a record that follows blank lines at the first blank one
/// (found for `swarmmap persistence` by `tests/input_fuzz_cli.rs`). The reader now numbers
/// lines from byte offsets (`LineIndex`).
#[test]
fn line_endings_and_blank_lines_do_not_shift_the_line() {
    let not_a_number = "column `end` is `x`, which is not a number";
    for (text, line, message) in [
        ("start,end,a,b\r\n0,1,0,1\r\n0,x,0,1\r\n", 3, not_a_number),
        (
            "start,end,a,b\r\n0,1,0,1\r\n0,1,0\r\n",
            3,
            "this row has 3 fields",
        ),
        ("start,end,a,b\r0,1,0,1\r0,x,0,1\r", 3, not_a_number),
        ("start,end,a,b\n0,1,0,1\n\n\r\n\r0,x,0,1\n", 6, not_a_number),
    ] {
        let err = encounters_error(text);
        assert!(
            err.contains(&format!("encounters.csv:{line}: {message}")),
            "{text:?}: {err}"
        );
    }
}

/// Regression (found by reading src/world/locate.rs): its tokenizer did not know RON's raw
/// strings, so field text inside `r#"..."#` was taken for fields and the error pointed into
/// the string (line 2) instead of at the real `width` (line 3).
#[test]
fn raw_string_does_not_mislead_the_field_locator() {
    let text = "(\n  name: r#\"x \" arena: (width: -1.0) \"#,\n  arena: (width: -2.0),\n)\n";
    let err = World::from_str_named(text, ORIGIN).unwrap_err().to_string();
    assert!(err.starts_with("t.ron:3:11: arena.width is -2"), "{err}");
}
