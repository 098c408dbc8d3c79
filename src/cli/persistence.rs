//! `swarmmap persistence FILE`: the Vietoris–Rips persistence diagram of a CSV file.
//!
//! Input: one point a row, comma separated, no header; or, with `--distance-matrix`, a full
//! symmetric matrix with a zero diagonal. Output on stdout: a header and one row per bar,
//! `dim,birth,death` (`inf` for an essential class), sorted by `(dim, birth, death)`. With
//! `--cycles` a fourth column `cycle` holds, for H1 bars, the edges of a representative
//! cycle as `i-j;k-l;…` (0-based row numbers of the input, `i < j`), empty for H0 bars, and
//! a fifth column `void` the three vertices `i;j;k` (`i < j < k`) of the triangle whose
//! entry kills the class (its longest edge has length `death`; it spans the void itself,
//! docs/accuracy.md, step 16), empty for H0 bars and essential classes.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::anyhow;
use clap::Args;

use super::{Failure, input};
use swarmmap::log::LineIndex;
use swarmmap::topology::rips::{Diagram, RipsOptions, rips_matrix, rips_points};
use swarmmap::topology::{DistanceMatrix, MatrixError, PointCloud};

/// Options of `swarmmap persistence`.
#[derive(Debug, Args)]
pub struct PersistenceArgs {
    /// CSV file: one point per row, comma separated, no header.
    pub file: PathBuf,
    /// Read FILE as a full n×n distance matrix instead of points.
    #[arg(long)]
    pub distance_matrix: bool,
    /// Highest homology dimension, 0 or 1.
    #[arg(long, default_value_t = 1)]
    pub maxdim: usize,
    /// Largest edge length, in the input's distance units (default: the enclosing radius,
    /// which gives the same diagram as no threshold).
    #[arg(long, allow_hyphen_values = true)]
    pub threshold: Option<f64>,
    /// Add a `cycle` column with a representative cycle of every H1 bar, and a `void`
    /// column with the triangle that kills it.
    #[arg(long)]
    pub cycles: bool,
    /// Worker threads; 0 uses all cores (at most 1024).
    #[arg(long, default_value_t = 0, value_parser = super::thread_count)]
    pub threads: usize,
}

/// Runs the subcommand.
pub fn run(args: PersistenceArgs) -> Result<(), Failure> {
    let opts = RipsOptions {
        maxdim: args.maxdim,
        threshold: args.threshold,
        cycles: args.cycles,
        threads: args.threads,
    }
    .check()
    .map_err(input)?;
    // A missing file or a directory is the user's input, as for every other command.
    let bytes = std::fs::read(&args.file).map_err(|e| {
        let what = if args.file.is_dir() {
            "it is a directory; give the CSV file of points or distances".to_string()
        } else {
            e.to_string()
        };
        input(anyhow!("cannot read {}: {what}", args.file.display()))
    })?;
    let rows = parse_rows(&bytes).map_err(|e| input(anyhow!("{}:{e}", args.file.display())))?;
    let diagram = if args.distance_matrix {
        let m = matrix(&rows).map_err(|e| input(located(&args.file, &rows, e)))?;
        rips_matrix(&m, &opts)
    } else {
        let p = points(&rows).map_err(|e| input(located(&args.file, &rows, e)))?;
        rips_points(&p, &opts)
    };
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    write_diagram(&mut out, &diagram, args.cycles)?;
    out.flush()?;
    Ok(())
}

/// A CSV row: its 1-based line number and its numbers.
type Row = (u64, Vec<f64>);

/// Parses rows of numbers; errors read `LINE: message` (blank lines are skipped). Lines
/// are numbered from byte offsets ([`LineIndex`]), so `\r\n`, `\r` and blank
/// lines do not shift them.
fn parse_rows(bytes: &[u8]) -> Result<Vec<Row>, String> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(LineIndex::new(bytes));
    let mut rows: Vec<Row> = Vec::new();
    let mut rec = csv::StringRecord::new();
    loop {
        let at = rdr.position().byte();
        match rdr.read_record(&mut rec) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                let line = rdr.get_ref().line_of(e.position().map_or(at, |p| p.byte()));
                let what = match e.kind() {
                    csv::ErrorKind::Utf8 { .. } => {
                        "not valid UTF-8 text; save the file as UTF-8".to_string()
                    }
                    _ => e.to_string(),
                };
                return Err(format!("{line}: {what}"));
            }
        }
        let line = rdr
            .get_ref()
            .line_of(rec.position().map_or(at, |p| p.byte()));
        let mut vals = Vec::with_capacity(rec.len());
        for (col, field) in rec.iter().enumerate() {
            let v: f64 = field.parse().map_err(|_| {
                let fix = not_a_number_fix(field, &rec, rows.is_empty());
                format!(
                    "{line}: field {}: '{field}' is not a number; {fix}",
                    col + 1
                )
            })?;
            vals.push(v);
        }
        if let Some((first_line, first)) = rows.first()
            && first.len() != vals.len()
        {
            return Err(format!(
                "{line}: row has {} columns but line {first_line} has {}; every row needs the same number of columns",
                vals.len(),
                first.len()
            ));
        }
        rows.push((line, vals));
    }
    if rows.is_empty() {
        return Err(" the file has no rows; expected one point (or matrix row) per line".into());
    }
    Ok(rows)
}

/// How to mend a field that is not a number, from what the line looks like: a header
/// (`first`: no row read yet, and no field of the line is a number, none of them empty), an
/// empty field, a decimal comma (a quoted `1,5`), or another separator (a spreadsheet's
/// `;`, spaces or tabs).
fn not_a_number_fix(field: &str, record: &csv::StringRecord, first: bool) -> &'static str {
    let number = |f: &str| f.parse::<f64>().is_ok();
    // Numbers joined by another separator: `0;0`, `1,5;2,5` (decimal commas), `0 0`.
    let separated = |f: &str| {
        f.contains([';', '\t', ' '])
            && f.split([';', '\t', ' '])
                .filter(|p| !p.is_empty())
                .all(|p| number(&p.replacen(',', ".", 1)))
    };
    if first
        && record
            .iter()
            .all(|f| !f.is_empty() && !number(f) && !separated(f))
    {
        "this looks like a header row, and the file takes none: delete the line (the columns \
         are the coordinates, or the matrix's columns, in order)"
    } else if field.is_empty() {
        "the field is empty: write a number there, or remove the extra comma"
    } else if number(&field.replacen(',', ".", 1)) {
        "write the number with a decimal point, not a decimal comma"
    } else if separated(field) && field.contains(';') {
        "fields are separated by commas, not ';' (a spreadsheet's export with decimal commas?): \
         write each number with a decimal point and separate them with ','"
    } else if separated(field) {
        "fields are separated by commas, not spaces or tabs (and numbers take no thousands \
         separator): separate the numbers with ','"
    } else {
        "every field must be a decimal number"
    }
}

fn points(rows: &[Row]) -> Result<PointCloud, MatrixError> {
    let r: Vec<&[f64]> = rows.iter().map(|(_, v)| v.as_slice()).collect();
    PointCloud::from_rows(&r)
}

fn matrix(rows: &[Row]) -> Result<DistanceMatrix, MatrixError> {
    let r: Vec<&[f64]> = rows.iter().map(|(_, v)| v.as_slice()).collect();
    DistanceMatrix::from_full(&r)
}

/// Prefixes a matrix error with `FILE:LINE:` of the offending row.
fn located(file: &Path, rows: &[Row], e: MatrixError) -> anyhow::Error {
    let row = match e {
        MatrixError::NonFinite { row, .. }
        | MatrixError::TooLarge { row, .. }
        | MatrixError::NotSquare { row, .. }
        | MatrixError::Diagonal { row, .. }
        | MatrixError::BadEntry { row, .. }
        | MatrixError::Asymmetric { row, .. } => Some(row),
        _ => None,
    };
    // The library counts points and entries from 0; the file's fields from 1.
    let col = match e {
        MatrixError::NonFinite { col, .. }
        | MatrixError::TooLarge { col, .. }
        | MatrixError::BadEntry { col, .. }
        | MatrixError::Asymmetric { col, .. } => Some(col),
        MatrixError::Diagonal { row, .. } => Some(row),
        _ => None,
    };
    // As a field that is not a number is named: `FILE:LINE: field N: ...`.
    let field = col.map_or(String::new(), |c| format!("field {}: ", c + 1));
    match row.and_then(|r| rows.get(r)) {
        Some((line, _)) => anyhow!("{}:{line}: {field}{e}", file.display()),
        None => anyhow!("{}: {e}", file.display()),
    }
}

/// A number of the output: exactly (Rust's shortest round-trip digits), with an exponent
/// where the plain form would run to many digits (|x| ≥ 1e16 or below 1e-6): `1e149`, not
/// 150 digits.
fn csv_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-6..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Writes the diagram as CSV (see the module docs).
pub fn write_diagram(w: &mut dyn Write, d: &Diagram, cycles: bool) -> std::io::Result<()> {
    writeln!(
        w,
        "dim,birth,death{}",
        if cycles { ",cycle,void" } else { "" }
    )?;
    for b in &d.bars {
        write!(
            w,
            "{},{},{}",
            b.dim,
            csv_number(b.birth),
            csv_number(b.death)
        )?;
        if cycles {
            let c = b.cycle.as_deref().unwrap_or(&[]);
            let s: Vec<String> = c.iter().map(|(i, j)| format!("{i}-{j}")).collect();
            let void = b
                .death_triangle
                .map(|[i, j, k]| format!("{i};{j};{k}"))
                .unwrap_or_default();
            write!(w, ",{},{void}", s.join(";"))?;
        }
        writeln!(w)?;
    }
    Ok(())
}
