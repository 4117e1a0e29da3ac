//! Loader for the RecurDyn finite-element log (measured data of the large robot).
//!
//! The file is a CSV table with the header
//!
//! ```text
//! x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,
//! ```
//!
//! (22 named columns and an empty trailing one that holds a free-text marker,
//! ignored). Blank lines (empty or only whitespace) are skipped anywhere, as
//! [`crate::io::measurements`] skips them. Units: metres, degrees, newtons. `fci`, `fzi`, `fhi` are the total,
//! vertical and horizontal tension of cable `i` at the platform attachment.
//! Cable 1 is the reference cable: its `fc1` and `fz1` are always required.
//! For cables 2..4 the forces are optional: all three empty, or `fc`/`fz` given
//! with `fh` empty, or all three given.
//!
//! Two kinds of problems are told apart:
//!
//! * **malformed input** (unreadable file, wrong header, wrong field count, a
//!   value that is not a finite number, a required value missing, a length or
//!   total tension that is not positive, ...) is an error naming the file, the
//!   line and the column;
//! * **data-quality problems** reject the row, with a reason, and loading goes
//!   on: exact duplicates, tensions that are not consistent with each other,
//!   a repeated pose with different tensions, and rounded hand transcriptions.
//!
//! # Tension consistency tolerance
//!
//! When `fc`, `fz` and `fh` are all given, `|fc - sqrt(fz^2 + fh^2)|` must not
//! exceed what the written precision of the three numbers can explain: one unit
//! in the last written digit of `fc`, plus one unit in the last written digit
//! of `fz` and of `fh` propagated through the square root
//! (`(|fz| u_fz + |fh| u_fh) / sqrt(fz^2 + fh^2)`), plus `1e-9 * fc` for the
//! floating-point arithmetic of the simulator and of this check. On the shared
//! log the simulator rows have residuals below 5e-10 N against tolerances of
//! about 6e-7 N, the two hand-written rows (3 or 4 decimals) 2e-7 N and 1.6e-5 N
//! against about 1e-3 N, while the one inconsistent row is off by 106 N.
//! The same tolerance is used for `|fz| <= fc` when `fh` is missing.
//!
//! ```
//! use sagcal::io::recurdyn::{looks_like_recurdyn, read_recurdyn, LoadOptions};
//! let header = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";
//! assert!(looks_like_recurdyn(&header.split(',').collect::<Vec<_>>()));
//! // Row 3's cable 1 tensions disagree: fc1 = 500 N but sqrt(300^2 + 400^2) = 500 N is not 510 N.
//! let text = format!("{header}\n\
//!     1.234567,2.345678,15.456789,0.1,0.2,0.3,183.3,169.2,155.6,170.9,500,300,400,,,,,,,,,,\n\
//!     3.234567,2.345678,15.456789,0.1,0.2,0.3,183.1,169.4,155.8,170.7,510,300,400,,,,,,,,,,\n");
//! let path = std::env::temp_dir().join(format!("sagcal-recurdyn-doc-{}.csv", std::process::id()));
//! std::fs::write(&path, text).unwrap();
//! let log = read_recurdyn(&path, &LoadOptions::default())?;
//! assert_eq!((log.rows.len(), log.rows[0].line), (1, 2));
//! let total = log.rows[0].tensions[0].unwrap().total_n;
//! assert_eq!(total, 500.0);
//! assert_eq!(log.rejected[0].line, 3);
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Error, Result};

/// The 22 named columns of a RecurDyn log, in file order.
const COLUMNS: [&str; 22] = [
    "x", "y", "z", "pitch", "roll", "yaw", "L1", "L2", "L3", "L4", "fc1", "fz1", "fh1", "fc2", "fz2", "fh2", "fc3",
    "fz3", "fh3", "fc4", "fz4", "fh4",
];

/// Number of data columns (the trailing marker column is not data).
const N_DATA: usize = COLUMNS.len();
/// Columns `x` .. `fz1` (indices 0..12) must always hold a value.
const N_REQUIRED: usize = 12;
/// Index of `x` (then `y`, `z`).
const POS: usize = 0;
/// Index of `pitch`.
const PITCH: usize = 3;
/// Index of `roll`.
const ROLL: usize = 4;
/// Index of `yaw`.
const YAW: usize = 5;
/// Index of `L1` (then `L2`, `L3`, `L4`).
const LEN: usize = 6;
/// Index of `fc1`; cable `c` (0-based) has `fc, fz, fh` at `FORCE + 3 c + {0, 1, 2}`.
const FORCE: usize = 10;
/// Number of columns describing the pose: position, orientation, cable lengths.
const N_POSE: usize = 10;
/// Relative slack of the tension checks for floating-point arithmetic.
const TENSION_RELATIVE_SLACK: f64 = 1e-9;
/// A position written with at most this many decimals is a hand transcription.
const ROUNDED_MAX_DECIMALS: i32 = 2;

/// Tension of one cable at its platform attachment, as logged.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CableTensionReading {
    /// Total tension `fc`, newtons (positive).
    pub total_n: f64,
    /// Vertical component `fz`, newtons.
    pub vertical_n: f64,
    /// Horizontal component `fh`, newtons, when the log gives it.
    pub horizontal_n: Option<f64>,
}

/// One kept row of a RecurDyn log: a static equilibrium pose with its cable data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecurDynRow {
    /// 1-based line number in the file (the header is line 1).
    pub line: usize,
    /// Platform frame origin `x, y, z` in the world frame, metres.
    pub position_m: [f64; 3],
    /// Roll angle (column `roll`), degrees.
    pub roll_deg: f64,
    /// Pitch angle (column `pitch`), degrees.
    pub pitch_deg: f64,
    /// Yaw angle (column `yaw`), degrees.
    pub yaw_deg: f64,
    /// Cable lengths `L1..L4`, metres (positive).
    pub cable_lengths_m: [f64; 4],
    /// Cable tensions, cable 1 first; `tensions[0]` (the reference cable) is always `Some`.
    pub tensions: [Option<CableTensionReading>; 4],
}

/// A row left out for a data-quality reason: named by its line alone, it is
/// not counted among the rows read ([`crate::model::DataRow`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RejectedRow {
    /// 1-based line number in the file (the header is line 1).
    pub line: usize,
    /// Why the row was left out.
    pub reason: String,
}

/// Options of [`read_recurdyn`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoadOptions {
    /// Keep rows whose position is written with at most 2 decimals (hand
    /// transcriptions); by default they are rejected.
    pub keep_rounded: bool,
}

/// A loaded RecurDyn log: the kept rows and the rejected ones, in file order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecurDynLog {
    /// The file that was read.
    pub path: PathBuf,
    /// Rows that passed every check.
    pub rows: Vec<RecurDynRow>,
    /// Rows left out, with the reason.
    pub rejected: Vec<RejectedRow>,
}

/// Whether a header row is the RecurDyn log header: exactly the columns
/// `x,y,z,pitch,roll,yaw,L1..L4,fc1,fz1,fh1,..,fc4,fz4,fh4` in this order,
/// optionally followed by one empty column name. Surrounding whitespace and a
/// UTF-8 byte-order mark are ignored.
pub fn looks_like_recurdyn(header_fields: &[&str]) -> bool {
    header_mismatch(header_fields).is_none()
}

/// Why a header is not the RecurDyn header, or `None` when it is.
fn header_mismatch(header_fields: &[&str]) -> Option<String> {
    let clean = |i: usize, s: &str| {
        let s = if i == 0 { s.trim_start_matches('\u{feff}') } else { s };
        s.trim().to_string()
    };
    let fields: Vec<String> = header_fields.iter().enumerate().map(|(i, s)| clean(i, s)).collect();
    for (i, expected) in COLUMNS.iter().enumerate() {
        match fields.get(i) {
            None => return Some(format!("column {} `{expected}` is missing", i + 1)),
            Some(found) if found != expected => {
                return Some(format!("column {} is `{found}`, expected `{expected}`", i + 1));
            }
            Some(_) => {}
        }
    }
    match fields.len() {
        n if n == N_DATA => None,
        n if n == N_DATA + 1 && fields[N_DATA].is_empty() => None,
        n if n == N_DATA + 1 => Some(format!(
            "column {} is `{}`, expected an empty name (the marker column)",
            N_DATA + 1,
            fields[N_DATA]
        )),
        n => Some(format!("{n} columns, expected {N_DATA} or {}", N_DATA + 1)),
    }
}

/// Read a RecurDyn log.
///
/// Malformed input is an error ([`Error::Io`], [`Error::Format`] or
/// [`Error::Field`] with the line and column); rows with data-quality problems
/// are returned in [`RecurDynLog::rejected`] with the reason.
pub fn read_recurdyn(path: &Path, options: &LoadOptions) -> Result<RecurDynLog> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(bytes.as_slice());
    let mut record = csv::ByteRecord::new();
    let mut lines = LineCounter::new(&bytes);

    // Header.
    if !read_filled_record(&mut reader, &mut record, path)? {
        return Err(format_error(
            path,
            format!("empty file: expected a RecurDyn header `{},`", COLUMNS.join(",")),
        ));
    }
    lines.line_of(&record);
    let header: Vec<String> = record.iter().map(|f| String::from_utf8_lossy(f).into_owned()).collect();
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    if let Some(why) = header_mismatch(&header_refs) {
        return Err(format_error(
            path,
            format!(
                "not a RecurDyn log header ({why}): expected the columns `{},` (22 named columns and an optional empty \
                 one), found `{}`",
                COLUMNS.join(","),
                header.join(",").escape_debug()
            ),
        ));
    }
    let n_fields = header.len();

    let mut log = RecurDynLog {
        path: path.to_path_buf(),
        rows: Vec::new(),
        rejected: Vec::new(),
    };
    // The first kept row (row, line) of each value and pose.
    let mut kept_values: HashMap<[Option<u64>; N_DATA], (usize, usize)> = HashMap::new();
    let mut kept_poses: HashMap<[u64; N_POSE], (usize, usize)> = HashMap::new();

    while read_filled_record(&mut reader, &mut record, path)? {
        let line = lines.line_of(&record);
        let at = (log.rows.len() + 1, line);
        let values = parse_record(&record, n_fields, at, path)?;
        let row = build_row(&values, at, path)?;

        let value_key: [Option<u64>; N_DATA] = std::array::from_fn(|i| values[i].map(|v| float_key(v.value)));
        let pose_key: [u64; N_POSE] = std::array::from_fn(|i| value_key[i].unwrap_or(0));

        let reason = if !options.keep_rounded {
            rounded_reason(&values)
        } else {
            None
        }
        .or_else(|| tension_reason(&values))
        .or_else(|| {
            kept_values
                .get(&value_key)
                .map(|(row, first)| format!("duplicate of row {row} (line {first})"))
        })
        .or_else(|| {
            kept_poses
                .get(&pose_key)
                .map(|(row, first)| format!("same pose as row {row} (line {first}) with different tensions"))
        });

        match reason {
            Some(reason) => log.rejected.push(RejectedRow { line, reason }),
            None => {
                kept_values.insert(value_key, at);
                kept_poses.insert(pose_key, at);
                log.rows.push(row);
            }
        }
    }

    if log.rows.is_empty() && log.rejected.is_empty() {
        return Err(format_error(
            path,
            "no data rows: the file holds only the header".to_string(),
        ));
    }
    Ok(log)
}

/// A parsed number with the resolution it was written with.
#[derive(Debug, Clone, Copy)]
struct Value {
    /// The number.
    value: f64,
    /// Decimals written (digits after the point, minus the exponent).
    decimals: i32,
}

impl Value {
    /// One unit in the last written digit.
    fn unit(&self) -> f64 {
        10f64.powi(-self.decimals)
    }
}

/// Read the next record; `false` at the end of the file.
fn read_record(reader: &mut csv::Reader<&[u8]>, record: &mut csv::ByteRecord, path: &Path) -> Result<bool> {
    reader.read_byte_record(record).map_err(|e| csv_error(e, path))
}

/// Read the next record that is not a blank line; `false` at the end of the file.
///
/// The csv reader skips empty lines but reads a line of spaces as a record of
/// one blank field: such a line is skipped here too.
fn read_filled_record(reader: &mut csv::Reader<&[u8]>, record: &mut csv::ByteRecord, path: &Path) -> Result<bool> {
    while read_record(reader, record, path)? {
        let blank = record.len() == 1 && record[0].iter().all(u8::is_ascii_whitespace);
        if !blank {
            return Ok(true);
        }
    }
    Ok(false)
}

/// Turn a csv error into a crate error.
fn csv_error(e: csv::Error, path: &Path) -> Error {
    let line = e.position().map(|p| p.line());
    match e.into_kind() {
        csv::ErrorKind::Io(source) => Error::io(path, source),
        other => {
            let at = line.map(|l| format!("line {l}: ")).unwrap_or_default();
            format_error(path, format!("{at}cannot read CSV: {other:?}"))
        }
    }
}

/// An [`Error::Format`] for `path`.
fn format_error(path: &Path, message: String) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        message,
    }
}

/// An [`Error::Field`] for column `index` of the data row `row` on line `line`
/// (the rows kept before it counted, as reports count them).
fn field_error(path: &Path, (row, line): (usize, usize), index: usize, message: String) -> Error {
    Error::Field {
        path: path.to_path_buf(),
        row,
        line: Some(line),
        field: column_name(index),
        message,
    }
}

/// The name of column `index` (0-based) for messages.
fn column_name(index: usize) -> String {
    match COLUMNS.get(index) {
        Some(name) => (*name).to_string(),
        None if index == N_DATA => "marker (column 23)".to_string(),
        None => format!("column {}", index + 1),
    }
}

/// Line numbers of records. The csv crate's own `Position::line` miscounts
/// CRLF endings and blank lines, and its byte offset may point at the line
/// ending or blank lines before the record, so the line is counted here from
/// the first byte of the record proper.
struct LineCounter<'a> {
    /// The whole file.
    bytes: &'a [u8],
    /// Bytes before `offset` have been counted.
    offset: usize,
    /// 1-based line number of the byte at `offset`.
    line: usize,
}

impl<'a> LineCounter<'a> {
    /// Start at line 1, byte 0.
    fn new(bytes: &'a [u8]) -> Self {
        LineCounter {
            bytes,
            offset: 0,
            line: 1,
        }
    }

    /// 1-based line on which `record` starts (records come in file order).
    fn line_of(&mut self, record: &csv::ByteRecord) -> usize {
        let reported = record
            .position()
            .and_then(|p| usize::try_from(p.byte()).ok())
            .unwrap_or(self.offset);
        let mut start = reported.clamp(self.offset, self.bytes.len());
        while matches!(self.bytes.get(start), Some(b'\r' | b'\n')) {
            start += 1;
        }
        self.line += self.bytes[self.offset..start].iter().filter(|b| **b == b'\n').count();
        self.offset = start;
        self.line
    }
}

/// Check the field count and parse the 22 data fields (empty ones are `None`).
fn parse_record(
    record: &csv::ByteRecord,
    n_fields: usize,
    at: (usize, usize),
    path: &Path,
) -> Result<[Option<Value>; N_DATA]> {
    let n = record.len();
    if n != n_fields {
        let (index, what) = if n < n_fields {
            (n, "this field and the ones after it are missing")
        } else {
            (n_fields, "this field and the ones after it are extra")
        };
        return Err(field_error(
            path,
            at,
            index,
            format!(
                "row has {n} field{}, the header {n_fields}: {what}",
                if n == 1 { "" } else { "s" }
            ),
        ));
    }
    let mut values = [None; N_DATA];
    for (index, slot) in values.iter_mut().enumerate() {
        let raw = record.get(index).unwrap_or_default();
        let text = std::str::from_utf8(raw)
            .map_err(|_| field_error(path, at, index, "not valid UTF-8 text".to_string()))?
            .trim();
        if text.is_empty() {
            if index < N_REQUIRED {
                return Err(field_error(path, at, index, "required value is empty".to_string()));
            }
            continue;
        }
        let value: f64 = text
            .parse()
            .map_err(|_| field_error(path, at, index, format!("not a number: `{text}`")))?;
        if !value.is_finite() {
            return Err(field_error(path, at, index, format!("not a finite number: `{text}`")));
        }
        *slot = Some(Value {
            value,
            decimals: written_decimals(text),
        });
    }
    Ok(values)
}

/// Decimals of a number as written: digits after the point minus the exponent
/// (`9.93` -> 2, `1.5e-3` -> 4, `12` -> 0).
fn written_decimals(text: &str) -> i32 {
    let (mantissa, exponent) = match text.find(['e', 'E']) {
        Some(i) => (&text[..i], text[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let after_point = mantissa
        .find('.')
        .map(|i| mantissa[i + 1..].chars().filter(char::is_ascii_digit).count())
        .unwrap_or(0);
    i32::try_from(after_point).unwrap_or(i32::MAX).saturating_sub(exponent)
}

/// Validate the values that must hold whatever the row's quality, and build the row.
fn build_row(values: &[Option<Value>; N_DATA], at: (usize, usize), path: &Path) -> Result<RecurDynRow> {
    let req = |i: usize| values[i].map(|v| v.value).unwrap_or_default();
    let mut cable_lengths_m = [0.0; 4];
    for (c, length) in cable_lengths_m.iter_mut().enumerate() {
        *length = req(LEN + c);
        if *length <= 0.0 {
            return Err(field_error(
                path,
                at,
                LEN + c,
                format!("cable length must be positive, got {length}"),
            ));
        }
    }
    let mut tensions = [None; 4];
    for (c, slot) in tensions.iter_mut().enumerate() {
        *slot = cable_tension(values, c, at, path)?;
    }
    Ok(RecurDynRow {
        line: at.1,
        position_m: [req(POS), req(POS + 1), req(POS + 2)],
        roll_deg: req(ROLL),
        pitch_deg: req(PITCH),
        yaw_deg: req(YAW),
        cable_lengths_m,
        tensions,
    })
}

/// The tension reading of cable `c` (0-based), checking which fields may be empty.
fn cable_tension(
    values: &[Option<Value>; N_DATA],
    c: usize,
    at: (usize, usize),
    path: &Path,
) -> Result<Option<CableTensionReading>> {
    let (ic, iz, ih) = (FORCE + 3 * c, FORCE + 3 * c + 1, FORCE + 3 * c + 2);
    let k = c + 1;
    let (fc, fz, fh) = match (values[ic], values[iz], values[ih]) {
        (None, None, None) => return Ok(None),
        (Some(fc), Some(fz), fh) => (fc.value, fz.value, fh.map(|v| v.value)),
        (_, _, Some(_)) => {
            return Err(field_error(
                path,
                at,
                ih,
                format!("fh{k} is given but fc{k} and fz{k} are not both given"),
            ));
        }
        (Some(_), None, None) => {
            return Err(field_error(path, at, iz, format!("fc{k} is given but fz{k} is empty")));
        }
        (None, Some(_), None) => {
            return Err(field_error(path, at, ic, format!("fz{k} is given but fc{k} is empty")));
        }
    };
    if fc <= 0.0 {
        return Err(field_error(
            path,
            at,
            ic,
            format!("total tension must be positive, got {fc} N"),
        ));
    }
    if let Some(fh) = fh.filter(|fh| *fh < 0.0) {
        return Err(field_error(
            path,
            at,
            ih,
            format!("horizontal tension is a magnitude and cannot be negative, got {fh} N"),
        ));
    }
    Ok(Some(CableTensionReading {
        total_n: fc,
        vertical_n: fz,
        horizontal_n: fh,
    }))
}

/// The rejection reason of a hand-transcribed row (position with at most 2 decimals).
fn rounded_reason(values: &[Option<Value>; N_DATA]) -> Option<String> {
    let decimals =
        |range: std::ops::Range<usize>| -> Vec<i32> { range.filter_map(|i| values[i].map(|v| v.decimals)).collect() };
    let position = decimals(POS..POS + 3).into_iter().max()?;
    if position > ROUNDED_MAX_DECIMALS {
        return None;
    }
    let angles = decimals(PITCH..YAW + 1).into_iter().max().unwrap_or(0);
    let lengths = decimals(LEN..LEN + 4);
    let forces = decimals(FORCE..N_DATA);
    let span = |d: &[i32]| {
        let (lo, hi) = (
            d.iter().min().copied().unwrap_or(0),
            d.iter().max().copied().unwrap_or(0),
        );
        if lo == hi {
            plural_decimals(lo)
        } else {
            format!("{lo} to {hi} decimals")
        }
    };
    Some(format!(
        "rounded: position given to {} m ({}), orientation to {} deg ({}), tensions to {}, cable lengths to {}; a \
         hand transcription, not a simulator log row",
        resolution(position),
        plural_decimals(position),
        resolution(angles),
        plural_decimals(angles),
        span(&forces),
        span(&lengths),
    ))
}

/// `1 decimal`, `2 decimals`.
fn plural_decimals(d: i32) -> String {
    if d == 1 {
        "1 decimal".to_string()
    } else {
        format!("{d} decimals")
    }
}

/// The resolution of a number written with `d` decimals: `0.01` for 2, `100` for -2.
fn resolution(d: i32) -> String {
    match d {
        1..=12 => format!("0.{}1", "0".repeat(d.unsigned_abs() as usize - 1)),
        -12..=0 => format!("{}", 10u64.pow(d.unsigned_abs())),
        _ => format!("1e{}", -i64::from(d)),
    }
}

/// The rejection reason of a row whose tensions contradict each other.
fn tension_reason(values: &[Option<Value>; N_DATA]) -> Option<String> {
    (0..4).find_map(|c| {
        let k = c + 1;
        let base = FORCE + 3 * c;
        let (fc, fz) = (values[base]?, values[base + 1]?);
        let slack = TENSION_RELATIVE_SLACK * fc.value.abs() + fc.unit();
        match values[base + 2] {
            Some(fh) => {
                let norm = fz.value.hypot(fh.value);
                let propagated = if norm > 0.0 {
                    (fz.value.abs() * fz.unit() + fh.value.abs() * fh.unit()) / norm
                } else {
                    fz.unit().max(fh.unit())
                };
                let tolerance = slack + propagated;
                let diff = (fc.value - norm).abs();
                (diff > tolerance).then(|| {
                    format!(
                        "cable {k}: fc{k} = {:.3} N but sqrt(fz{k}^2 + fh{k}^2) = {norm:.3} N (difference {diff:.3} N, \
                         tolerance {tolerance:.1e} N)",
                        fc.value
                    )
                })
            }
            None => {
                let tolerance = slack + fz.unit();
                (fz.value.abs() - fc.value > tolerance).then(|| {
                    format!(
                        "cable {k}: |fz{k}| = {:.3} N exceeds fc{k} = {:.3} N (a component cannot exceed the total)",
                        fz.value.abs(),
                        fc.value
                    )
                })
            }
        }
    })
}

/// Exact-equality key of a number (`-0.0` and `0.0` are the same).
fn float_key(v: f64) -> u64 {
    if v == 0.0 {
        0
    } else {
        v.to_bits()
    }
}
