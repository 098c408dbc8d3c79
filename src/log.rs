//! The encounter log: what the swarm records (paper §"Sensing and Communication", eq. for
//! E_i = [t_0, t_1, ID¹, ID²]) and what every mapping stage reads.
//!
//! A log comes from the simulator or from a real experiment. The mapping reads only the
//! coordinate-free columns; the ground-truth columns (true positions at the start of an
//! encounter) are optional and read only by evaluation.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Agent identifier (index into the swarm).
pub type AgentId = u32;

/// One encounter: agents `a < b` had their centres within r_d during `[start, end]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Encounter {
    /// Start time in seconds.
    pub start: f64,
    /// End time in seconds (`>= start`).
    pub end: f64,
    pub a: AgentId,
    pub b: AgentId,
    /// Ground truth, if known: the true positions of `a` and `b` at `start`, metres.
    pub truth: Option<[f64; 4]>,
}

/// Why an agent was static.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StaticReason {
    /// Held static as a landmark (MaxMin selection).
    Landmark,
    /// A spontaneous stop of the random walk.
    Pause,
}

impl StaticReason {
    /// The name used in `static_intervals.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            StaticReason::Landmark => "landmark",
            StaticReason::Pause => "pause",
        }
    }
}

/// An interval `[start, end]` during which `agent` did not move.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticInterval {
    pub agent: AgentId,
    pub start: f64,
    pub end: f64,
    pub reason: StaticReason,
}

/// A complete log: encounters sorted by `(start, a, b)`, static intervals sorted by
/// `(agent, start)`, and the leader's track as `(time, x)` samples.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EncounterLog {
    pub encounters: Vec<Encounter>,
    pub static_intervals: Vec<StaticInterval>,
    pub leader: Vec<(f64, f64)>,
}

/// File names of a run directory (see the README, "Output files").
pub const ENCOUNTERS_CSV: &str = "encounters.csv";
/// Static intervals of landmarks and pauses.
pub const STATIC_CSV: &str = "static_intervals.csv";
/// The leader's track.
pub const LEADER_CSV: &str = "leader.csv";

/// What is wrong with a log, and where.
#[derive(Debug, Error)]
pub enum LogError {
    /// A file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A required file is missing.
    #[error("{path}: file not found; a log directory needs {what}")]
    Missing { path: PathBuf, what: &'static str },
    /// A problem at a line of a CSV file.
    #[error("{path}:{line}: {message}")]
    Csv {
        path: PathBuf,
        line: u64,
        message: String,
    },
}

struct Columns {
    index: HashMap<String, usize>,
}

impl Columns {
    fn get(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }
}

/// A reader that records where every line of its input ends, so that a byte offset names
/// its line whatever the line endings. The `csv` crate counts a line only at a `\n`, and
/// only after it has recorded the next record's position: every line of a `\r\n` file was
/// reported one early, every line of a `\r` file as line 1, and a record after blank
/// lines at the first blank one (BurntSushi/rust-csv#395). Here `\n`, `\r\n` and a lone
/// `\r` each end one line.
pub struct LineIndex<R> {
    inner: R,
    /// Offset and length (1, or 2 for `\r\n`) of every line terminator seen so far, in
    /// increasing order.
    ends: Vec<(u64, u8)>,
    /// Bytes read so far.
    offset: u64,
    /// Whether the last byte read was a `\r`.
    after_cr: bool,
}

impl<R> LineIndex<R> {
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            ends: Vec::new(),
            offset: 0,
            after_cr: false,
        }
    }

    /// The 1-based line of a record the `csv` crate places at byte `offset` (of the bytes
    /// already read): the line of the first byte at or after `offset` that does not end a
    /// line, since csv places a record after blank lines at the first of them.
    pub fn line_of(&self, offset: u64) -> u64 {
        let mut i = self.ends.partition_point(|e| e.0 < offset);
        let mut at = offset;
        while let Some(&(end, len)) = self.ends.get(i)
            && end == at
        {
            at += u64::from(len);
            i += 1;
        }
        i as u64 + 1
    }
}

impl<R: std::io::Read> std::io::Read for LineIndex<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for (i, &b) in buf[..n].iter().enumerate() {
            let at = self.offset + i as u64;
            if b == b'\n' && self.after_cr {
                if let Some(last) = self.ends.last_mut() {
                    last.1 = 2;
                }
            } else if b == b'\r' || b == b'\n' {
                self.ends.push((at, 1));
            }
            self.after_cr = b == b'\r';
        }
        self.offset += n as u64;
        Ok(n)
    }
}

/// A CSV reader that reports every problem with its file and line.
struct CsvFile {
    path: PathBuf,
    reader: csv::Reader<LineIndex<std::fs::File>>,
    columns: Columns,
}

impl CsvFile {
    fn open(path: &Path, required: &[&str]) -> Result<Self, LogError> {
        let file = std::fs::File::open(path).map_err(|source| LogError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(LineIndex::new(file));
        let headers = match reader.headers() {
            Ok(h) => h.clone(),
            Err(e) => return Err(csv_error(path, reader.get_ref(), 0, &e)),
        };
        let index: HashMap<String, usize> = headers
            .iter()
            .enumerate()
            .map(|(i, h)| (h.to_string(), i))
            .collect();
        if headers.iter().all(str::is_empty) {
            return Err(LogError::Csv {
                path: path.to_path_buf(),
                line: 1,
                message: format!(
                    "the file is empty; it needs a header line with the columns {} and a line per record",
                    required.join(",")
                ),
            });
        }
        // A column named twice: rows would be read from one of the two in silence.
        for (i, h) in headers.iter().enumerate() {
            if let Some(j) = headers
                .iter()
                .skip(i + 1)
                .position(|o| !h.is_empty() && o == h)
            {
                return Err(LogError::Csv {
                    path: path.to_path_buf(),
                    line: 1,
                    message: format!(
                        "the header names column `{}` twice (fields {} and {}); name each \
                         column once",
                        shown(h),
                        i + 1,
                        i + j + 2
                    ),
                });
            }
        }
        for r in required {
            if !index.contains_key(*r) {
                let header = headers.iter().collect::<Vec<_>>().join(",");
                // One field holding every name: another separator than the comma.
                let separator = [(';', "`;`"), ('\t', "tabs"), ('|', "`|`")]
                    .into_iter()
                    .find(|(c, _)| headers.len() == 1 && header.contains(*c))
                    .map_or(String::new(), |(_, name)| {
                        format!(
                            "; the file separates its fields with {name}: save it with commas \
                             (comma-separated values)"
                        )
                    });
                return Err(LogError::Csv {
                    path: path.to_path_buf(),
                    line: 1,
                    message: format!(
                        "missing column `{r}`; the header must contain {} (found: {}){separator}",
                        required.join(","),
                        shown(&header)
                    ),
                });
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            columns: Columns { index },
        })
    }

    /// Visits every record with its 1-based line number.
    fn for_each(
        &mut self,
        mut f: impl FnMut(&Row<'_>) -> Result<(), String>,
    ) -> Result<(), LogError> {
        let mut record = csv::StringRecord::new();
        loop {
            let byte = self.reader.position().byte();
            match self.reader.read_record(&mut record) {
                Ok(false) => return Ok(()),
                Ok(true) => {
                    let byte = record.position().map_or(byte, |p| p.byte());
                    let line = self.reader.get_ref().line_of(byte);
                    let row = Row {
                        record: &record,
                        columns: &self.columns,
                        line,
                    };
                    f(&row).map_err(|message| LogError::Csv {
                        path: self.path.clone(),
                        line,
                        message,
                    })?;
                }
                Err(e) => return Err(csv_error(&self.path, self.reader.get_ref(), byte, &e)),
            }
        }
    }
}

/// The error of a CSV problem at byte `byte` (or at the position the error carries).
fn csv_error<R>(path: &Path, lines: &LineIndex<R>, byte: u64, e: &csv::Error) -> LogError {
    let line = lines.line_of(e.position().map_or(byte, |p| p.byte()));
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!(
            "this row has {len} fields but the header has {expected_len}; every row needs one value per column"
        ),
        csv::ErrorKind::Utf8 { .. } => "not valid UTF-8 text; save the file as UTF-8".to_string(),
        _ => e.to_string(),
    };
    LogError::Csv {
        path: path.to_path_buf(),
        line,
        message,
    }
}

/// Largest |time| a log may hold, seconds. Far beyond any experiment, it catches unit
/// mistakes (epoch milliseconds or nanoseconds) and corrupt values: the mapping squares
/// time differences (classical MDS), which overflow f64 from about 1e154 s.
pub const MAX_TIME: f64 = 1e12;

/// Largest |position| a log may hold, metres (truth columns and the leader's x).
pub const MAX_POSITION: f64 = 1e9;

struct Row<'a> {
    record: &'a csv::StringRecord,
    columns: &'a Columns,
    /// The record's 1-based line in its file.
    line: u64,
}

/// A cell as an error message shows it: control characters (a NUL byte, a tab) and the
/// backslash escaped as Rust writes them (`\0`, `\t`, `\\`), so that a message shows what
/// the file holds and a NUL byte cannot be mistaken for the text `\0`.
pub(crate) fn shown(cell: &str) -> String {
    let mut out = String::with_capacity(cell.len());
    for c in cell.chars() {
        if c.is_control() || c == '\\' {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

impl Row<'_> {
    fn text(&self, name: &str) -> Option<&str> {
        self.columns.get(name).and_then(|i| self.record.get(i))
    }

    fn f64(&self, name: &str) -> Result<f64, String> {
        let s = self.text(name).unwrap_or("");
        let v: f64 = s
            .parse()
            .map_err(|_| format!("column `{name}` is `{}`, which is not a number", shown(s)))?;
        if !v.is_finite() {
            return Err(format!(
                "column `{name}` is `{}`; times and positions must be finite numbers",
                shown(s)
            ));
        }
        Ok(v)
    }

    /// A number within ±`max`; beyond it the message says `beyond ±{limit}; {hint}`.
    fn bounded(&self, name: &str, max: f64, limit: &str, hint: &str) -> Result<f64, String> {
        let v = self.f64(name)?;
        if v.abs() > max {
            return Err(format!(
                "column `{name}` is `{}`, beyond ±{limit}; {hint}",
                shown(self.text(name).unwrap_or(""))
            ));
        }
        Ok(v)
    }

    /// A time in seconds, within ±[`MAX_TIME`].
    fn time(&self, name: &str) -> Result<f64, String> {
        self.bounded(
            name,
            MAX_TIME,
            "1e12 s (about 31 700 years)",
            "times are seconds (milliseconds or nanoseconds since an epoch? divide by 1e3 or 1e9)",
        )
    }

    /// A position in metres, within ±[`MAX_POSITION`].
    fn position(&self, name: &str) -> Result<f64, String> {
        self.bounded(
            name,
            MAX_POSITION,
            "1e9 m",
            "positions are metres in the arena's frame",
        )
    }

    fn agent(&self, name: &str) -> Result<AgentId, String> {
        let s = self.text(name).unwrap_or("");
        s.parse().map_err(|_| {
            format!(
                "column `{name}` is `{}`; agent ids are whole numbers from 0 to {}",
                shown(s),
                AgentId::MAX
            )
        })
    }
}

/// What reading a log noticed that is not an error but that a user should hear of.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadNotes {
    /// Whether `encounters.csv`'s rows were already in the log's order (by start time,
    /// then `a`, then `b`, each row's agents taken as `a < b`). Encounters are numbered in
    /// that order (the maps' `encounter` indices), so only then are the numbers the file's
    /// data rows.
    pub encounters_in_order: bool,
    /// Rows of `encounters.csv` that repeat an earlier row exactly (the same start, end and
    /// agents): each is read as one more encounter.
    pub repeated_encounters: usize,
    /// Encounters that overlap in time an earlier encounter of the same two agents without
    /// repeating it exactly. One contact is one interval, so such rows are one contact
    /// recorded twice (each robot logging it, with its own clock) or a logger's fault;
    /// each is read as one more encounter.
    pub overlapping_encounters: usize,
    /// Static intervals of `static_intervals.csv` that overlap an earlier one of the same
    /// agent (an agent stands at one place at a time).
    pub overlapping_static: usize,
    /// The files read whose last line has no line end: a file cut off while it was being
    /// written ends that way, its last row perhaps cut short (`…,8,4` for agent 47), and
    /// such a row still reads as a valid one.
    pub unterminated: Vec<PathBuf>,
}

/// Whether the non-empty file at `path` ends without a line end (`\n` or `\r`).
fn unterminated(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::File::open(path) else {
        return false;
    };
    let mut last = [0u8; 1];
    f.seek(SeekFrom::End(-1)).is_ok()
        && f.read_exact(&mut last).is_ok()
        && last[0] != b'\n'
        && last[0] != b'\r'
}

impl EncounterLog {
    /// The log exactly as its CSV files hold it: every time and position rounded to the
    /// six decimals the simulator writes (README, "Output files"). The simulator hands out
    /// only such logs, so a run mapped in memory (`swarmmap run`, `eval`) and the same run
    /// mapped again from its files (`swarmmap map DIR`) read the same numbers and give the
    /// same maps; rounding them only in the files moved ties in the metric and changed
    /// whole windows (found by the forty-first session's review).
    pub fn as_written(mut self) -> Self {
        let mut buf = String::new();
        let mut round = |x: &mut f64| *x = written(*x, &mut buf);
        for e in &mut self.encounters {
            round(&mut e.start);
            round(&mut e.end);
            if let Some(truth) = &mut e.truth {
                truth.iter_mut().for_each(&mut round);
            }
        }
        for iv in &mut self.static_intervals {
            round(&mut iv.start);
            round(&mut iv.end);
        }
        for (t, x) in &mut self.leader {
            round(t);
            round(x);
        }
        self
    }

    /// Reads a log directory: `encounters.csv` (required), `static_intervals.csv`
    /// (optional: without it no time is bridged by static agents) and `leader.csv`
    /// (optional). Truth columns `a_x,a_y,b_x,b_y` are read when all four are present.
    pub fn read_dir(dir: &Path) -> Result<Self, LogError> {
        Self::read_dir_noting(dir).map(|(log, _)| log)
    }

    /// [`read_dir`](Self::read_dir), also saying what it noticed ([`ReadNotes`]).
    pub fn read_dir_noting(dir: &Path) -> Result<(Self, ReadNotes), LogError> {
        let enc_path = dir.join(ENCOUNTERS_CSV);
        if !enc_path.exists() {
            return Err(LogError::Missing {
                path: enc_path,
                what: "encounters.csv with columns start,end,a,b",
            });
        }
        let (encounters, notes) = read_encounters(&enc_path)?;
        let mut log = EncounterLog {
            encounters,
            ..Default::default()
        };
        let st = dir.join(STATIC_CSV);
        if st.exists() {
            log.static_intervals = read_static(&st)?;
        }
        let mut notes = notes;
        notes.unterminated = [ENCOUNTERS_CSV, STATIC_CSV, LEADER_CSV]
            .iter()
            .map(|f| dir.join(f))
            .filter(|p| unterminated(p))
            .collect();
        // Sorted by (agent, start): an interval overlaps an earlier one of its agent when
        // it starts before the latest end so far (a long interval can hold several).
        let mut latest: Option<(AgentId, f64)> = None;
        for s in &log.static_intervals {
            match latest {
                Some((agent, end)) if agent == s.agent => {
                    notes.overlapping_static += usize::from(s.start < end);
                    latest = Some((agent, end.max(s.end)));
                }
                _ => latest = Some((s.agent, s.end)),
            }
        }
        let le = dir.join(LEADER_CSV);
        if le.exists() {
            log.leader = read_leader(&le)?;
        }
        Ok((log, notes))
    }

    /// Whether every encounter carries ground-truth positions.
    pub fn has_truth(&self) -> bool {
        !self.encounters.is_empty() && self.encounters.iter().all(|e| e.truth.is_some())
    }

    /// The time span `[min start, max end]` of the encounters and static intervals.
    pub fn span(&self) -> Option<(f64, f64)> {
        let times = self
            .encounters
            .iter()
            .map(|e| (e.start, e.end))
            .chain(self.static_intervals.iter().map(|s| (s.start, s.end)));
        times.fold(None, |acc, (a, b)| match acc {
            None => Some((a, b)),
            Some((lo, hi)) => Some((f64::min(lo, a), f64::max(hi, b))),
        })
    }
}

fn interval(row: &Row<'_>) -> Result<(f64, f64), String> {
    let (start, end) = (row.time("start")?, row.time("end")?);
    if end < start {
        return Err(format!(
            "end {} is before start {}; an interval must have end >= start",
            crate::world::given(end),
            crate::world::given(start)
        ));
    }
    Ok((start, end))
}

fn read_encounters(path: &Path) -> Result<(Vec<Encounter>, ReadNotes), LogError> {
    let mut f = CsvFile::open(path, &["start", "end", "a", "b"])?;
    let truth_cols = ["a_x", "a_y", "b_x", "b_y"];
    let with_truth = truth_cols.iter().all(|c| f.columns.get(c).is_some());
    let mut out = Vec::new();
    f.for_each(|row| {
        let (start, end) = interval(row)?;
        let (a, b) = (row.agent("a")?, row.agent("b")?);
        if a == b {
            return Err(format!(
                "agent {a} meets itself; an encounter needs two different agents"
            ));
        }
        let truth = if with_truth {
            Some([
                row.position("a_x")?,
                row.position("a_y")?,
                row.position("b_x")?,
                row.position("b_y")?,
            ])
        } else {
            None
        };
        // Normalise to a < b, swapping the truth columns with the ids.
        let (a, b, truth) = if a < b {
            (a, b, truth)
        } else {
            (b, a, truth.map(|t| [t[2], t[3], t[0], t[1]]))
        };
        out.push(Encounter {
            start,
            end,
            a,
            b,
            truth,
        });
        Ok(())
    })?;
    let order = |x: &Encounter, y: &Encounter| {
        x.start
            .total_cmp(&y.start)
            .then(x.a.cmp(&y.a))
            .then(x.b.cmp(&y.b))
    };
    let encounters_in_order = out.is_sorted_by(|x, y| order(x, y).is_le());
    let mut seen = std::collections::HashSet::with_capacity(out.len());
    let repeated_encounters = out
        .iter()
        .filter(|e| !seen.insert((e.start.to_bits(), e.end.to_bits(), e.a, e.b)))
        .count();
    // Stable: rows equal in (start, a, b) keep the file's order.
    out.sort_by(order);
    // Each pair's latest interval so far, in start order: a later one starting before it
    // ends (and not an exact repeat, counted above) overlaps it.
    let mut last: HashMap<(AgentId, AgentId), (f64, f64)> = HashMap::new();
    let mut overlapping_encounters = 0;
    for e in &out {
        if let Some(&(start, end)) = last.get(&(e.a, e.b))
            && e.start < end
            && (start, end) != (e.start, e.end)
        {
            overlapping_encounters += 1;
        }
        let keep = last.get(&(e.a, e.b)).is_none_or(|&(_, end)| e.end > end);
        if keep {
            last.insert((e.a, e.b), (e.start, e.end));
        }
    }
    let notes = ReadNotes {
        encounters_in_order,
        repeated_encounters,
        overlapping_encounters,
        overlapping_static: 0,
        unterminated: Vec::new(),
    };
    Ok((out, notes))
}

fn read_static(path: &Path) -> Result<Vec<StaticInterval>, LogError> {
    let mut f = CsvFile::open(path, &["agent", "start", "end"])?;
    let has_reason = f.columns.get("reason").is_some();
    let mut out = Vec::new();
    f.for_each(|row| {
        let (start, end) = interval(row)?;
        let reason = match row.text("reason").filter(|_| has_reason) {
            None | Some("landmark") => StaticReason::Landmark,
            Some("pause") => StaticReason::Pause,
            Some(other) => {
                return Err(format!(
                    "column `reason` is `{}`; use `landmark` or `pause`",
                    shown(other)
                ));
            }
        };
        out.push(StaticInterval {
            agent: row.agent("agent")?,
            start,
            end,
            reason,
        });
        Ok(())
    })?;
    out.sort_by(|x, y| x.agent.cmp(&y.agent).then(x.start.total_cmp(&y.start)));
    Ok(out)
}

/// The leader's track, sorted by time. Rows may come in any order, and a row may repeat
/// another; two rows that put the leader at two places at one time are an error, since the
/// track could not say which to draw.
fn read_leader(path: &Path) -> Result<Vec<(f64, f64)>, LogError> {
    let mut f = CsvFile::open(path, &["time", "x"])?;
    let mut rows = Vec::new();
    f.for_each(|row| {
        rows.push((row.time("time")?, row.position("x")?, row.line));
        Ok(())
    })?;
    // Stable: rows of one time keep their file order, so the earlier line comes first.
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(w) = rows
        .windows(2)
        .find(|w| w[0].0 == w[1].0 && w[0].1 != w[1].1)
    {
        let ((time, x0, first), (_, x1, second)) = (w[0], w[1]);
        return Err(LogError::Csv {
            path: path.to_path_buf(),
            line: second,
            message: format!(
                "this row puts the leader at x = {} m at time {} s, but line {first} \
                 puts it at x = {} m then; keep one row per time (correct or remove one; \
                 leader.csv is optional, only the report draws it)",
                crate::world::given(x1),
                crate::world::given(time),
                crate::world::given(x0)
            ),
        });
    }
    let mut out: Vec<(f64, f64)> = rows.into_iter().map(|(t, x, _)| (t, x)).collect();
    out.dedup();
    Ok(out)
}

/// `x` as the log files write it (`{:.6}`) and read it back: the same `f64` a reader of
/// the file gets.
pub(crate) fn written(x: f64, buf: &mut String) -> f64 {
    use std::fmt::Write as _;
    buf.clear();
    let _ = write!(buf, "{x:.6}");
    buf.parse().unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir_with(files: &[(&str, &str)]) -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        for (name, text) in files {
            std::fs::write(d.path().join(name), text).unwrap();
        }
        d
    }

    #[test]
    fn reads_a_log_without_truth() {
        let d = dir_with(&[
            (
                "encounters.csv",
                "start,end,a,b\n2.0,3.0,5,1\n1.0,1.5,0,1\n",
            ),
            (
                "static_intervals.csv",
                "agent,start,end,reason\n1,0,10,landmark\n2,4,5,pause\n",
            ),
        ]);
        let log = EncounterLog::read_dir(d.path()).unwrap();
        assert_eq!(log.encounters.len(), 2);
        assert_eq!((log.encounters[0].a, log.encounters[0].b), (0, 1));
        assert_eq!((log.encounters[1].a, log.encounters[1].b), (1, 5));
        assert!(!log.has_truth());
        assert_eq!(log.static_intervals[1].reason, StaticReason::Pause);
        assert_eq!(log.span(), Some((0.0, 10.0)));
    }

    #[test]
    fn swaps_truth_with_ids() {
        let d = dir_with(&[(
            "encounters.csv",
            "start,end,a,b,a_x,a_y,b_x,b_y\n0,1,3,2,1,2,3,4\n",
        )]);
        let e = &EncounterLog::read_dir(d.path()).unwrap().encounters[0];
        assert_eq!((e.a, e.b), (2, 3));
        assert_eq!(e.truth, Some([3.0, 4.0, 1.0, 2.0]));
    }

    fn error_of(text: &str) -> String {
        let d = dir_with(&[("encounters.csv", text)]);
        EncounterLog::read_dir(d.path()).unwrap_err().to_string()
    }

    #[test]
    fn errors_name_the_line_and_the_fix() {
        let e = error_of("start,end,a,b\n0,1,0,1\n0,x,0,1\n");
        assert!(
            e.ends_with("encounters.csv:3: column `end` is `x`, which is not a number"),
            "{e}"
        );
        let e = error_of("start,end,a,b\n5,1,0,1\n");
        assert!(
            e.contains("encounters.csv:2: end 1 is before start 5"),
            "{e}"
        );
        let e = error_of("start,end,a,b\nNaN,1,0,1\n");
        assert!(
            e.contains(":2: column `start` is `NaN`; times and positions must be finite"),
            "{e}"
        );
        let e = error_of("start,end,a,b\n0,1e200,0,1\n");
        assert!(
            e.contains(":2: column `end` is `1e200`, beyond ±1e12 s") && e.contains("divide by"),
            "{e}"
        );
        let e = error_of("start,end,a,b,a_x,a_y,b_x,b_y\n0,1,0,1,0,0,-2e9,0\n");
        assert!(
            e.contains(":2: column `b_x` is `-2e9`, beyond ±1e9 m"),
            "{e}"
        );
        let e = error_of("start,end,a\n0,1,0\n");
        assert!(e.contains(":1: missing column `b`"), "{e}");
        let e = error_of("start,end,a,b\n0,1,0,1\n0,1,0\n");
        assert!(
            e.contains(":3: this row has 3 fields but the header has 4"),
            "{e}"
        );
        let e = error_of("start,end,a,b\n0,1,-1,1\n");
        assert!(
            e.contains(":2: column `a` is `-1`; agent ids are whole numbers from 0 to 4294967295"),
            "{e}"
        );
        let e = error_of("start,end,a,b\n0,1,4,4\n");
        assert!(e.contains(":2: agent 4 meets itself"), "{e}");
        // A control character in a cell is shown, not printed raw.
        let e = error_of("start,end,a,b\n0,1\0,4,5\n");
        assert!(
            e.contains(":2: column `end` is `1\\0`, which is not a number"),
            "{e}"
        );
        // The text `1\0` (a backslash and a zero) is not shown as a NUL byte would be.
        let e = error_of("start,end,a,b\n0,1\\0,4,5\n");
        assert!(
            e.contains(":2: column `end` is `1\\\\0`, which is not a number"),
            "{e}"
        );
        let d = tempfile::tempdir().unwrap();
        let e = EncounterLog::read_dir(d.path()).unwrap_err().to_string();
        assert!(e.contains("file not found"), "{e}");
    }

    /// Rows overlapping an earlier encounter of the same pair (each robot logging the
    /// contact) and static intervals overlapping one of the same agent are counted; an exact
    /// repeat is counted as a repeat only, and touching intervals are no overlap.
    #[test]
    fn overlapping_rows_of_one_pair_or_agent_are_noted() {
        let d = dir_with(&[
            (
                "encounters.csv",
                "start,end,a,b\n0,2,1,2\n1.5,3,2,1\n0,2,1,2\n3,4,1,2\n5,6,1,3\n",
            ),
            (
                "static_intervals.csv",
                "agent,start,end,reason\n1,0,10,landmark\n1,10,12,pause\n1,11,20,landmark\n\
                 2,0,100,landmark\n2,10,20,pause\n2,30,40,pause\n2,50,60,pause\n",
            ),
        ]);
        let (log, notes) = EncounterLog::read_dir_noting(d.path()).unwrap();
        assert_eq!(log.encounters.len(), 5);
        assert_eq!(notes.repeated_encounters, 1);
        assert_eq!(notes.overlapping_encounters, 1);
        // Agent 1's third interval; agent 2's three pauses inside its long landmark one.
        assert_eq!(notes.overlapping_static, 4);
    }

    /// Found by the forty-first session's review: a log cut off mid-row (`…,8,4` for agent
    /// 47) reads as a valid row; a last line without a line end is noted, per file.
    #[test]
    fn a_last_line_without_a_line_end_is_noted() {
        let d = dir_with(&[
            ("encounters.csv", "start,end,a,b\n0,2,1,2\n3,4,8,4"),
            ("static_intervals.csv", "agent,start,end\n1,0,10\n"),
            ("leader.csv", "time,x\n0,1.5\r\n"),
        ]);
        let (log, notes) = EncounterLog::read_dir_noting(d.path()).unwrap();
        assert_eq!(log.encounters.len(), 2);
        assert_eq!(notes.unterminated, vec![d.path().join("encounters.csv")]);
        std::fs::write(d.path().join("encounters.csv"), "start,end,a,b\n0,2,1,2\n").unwrap();
        let (_, notes) = EncounterLog::read_dir_noting(d.path()).unwrap();
        assert!(notes.unterminated.is_empty());
    }

    /// Found by the fortieth session's review: a column named twice was read from its last
    /// copy in silence; a file of semicolons or UTF-16 text got no hint of what to change.
    #[test]
    fn a_header_naming_a_column_twice_or_another_separator_is_explained() {
        let e = error_of("start,end,a,b,a\n0,1,1,2,7\n");
        assert!(
            e.contains("encounters.csv:1: the header names column `a` twice (fields 3 and 5)"),
            "{e}"
        );
        // Empty names (trailing commas) are no columns of ours: allowed.
        let d = dir_with(&[("encounters.csv", "start,end,a,b,,\n0,1,1,2,,\n")]);
        assert_eq!(
            EncounterLog::read_dir(d.path()).unwrap().encounters.len(),
            1
        );
        for (sep, name) in [(";", "`;`"), ("\t", "tabs")] {
            let e = error_of(&format!("start{sep}end{sep}a{sep}b\n0{sep}1{sep}1{sep}2\n"));
            assert!(
                e.contains("missing column `start`")
                    && e.contains(&format!("separates its fields with {name}")),
                "{e}"
            );
        }
        let utf16: Vec<u8> = "\u{feff}start,end,a,b\n0,1,1,2\n"
            .encode_utf16()
            .flat_map(u16::to_le_bytes)
            .collect();
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("encounters.csv"), utf16).unwrap();
        let e = EncounterLog::read_dir(d.path()).unwrap_err().to_string();
        assert!(e.contains("save the file as UTF-8"), "{e}");
    }

    fn leader_of(text: &str) -> Result<Vec<(f64, f64)>, String> {
        let d = dir_with(&[
            ("encounters.csv", "start,end,a,b\n0,1,0,1\n"),
            ("leader.csv", text),
        ]);
        EncounterLog::read_dir(d.path())
            .map(|log| log.leader)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn the_leader_track_is_sorted_and_its_repeated_rows_read_once() {
        let track = leader_of("time,x\n10,2.0\n0,1.5\n5,1.75\n10,2.0\n").unwrap();
        assert_eq!(track, vec![(0.0, 1.5), (5.0, 1.75), (10.0, 2.0)]);
    }

    #[test]
    fn two_places_of_the_leader_at_one_time_name_both_lines() {
        // Line 2 and line 4 disagree about t = 10 s; line 3 lies between them in time order.
        let e = leader_of("time,x\n10,2.0\n0,1.5\n10,2.5\n").unwrap_err();
        assert!(
            e.contains("leader.csv:4: this row puts the leader at x = 2.5 m at time 10 s, but line 2 puts it at x = 2 m")
                && e.contains("keep one row per time"),
            "{e}"
        );
    }
}
