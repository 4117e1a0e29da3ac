//! sagcal's own measurement file: one static pose per row, the input of the
//! calibration. [`read_measurements`] also reads RecurDyn logs (see
//! [`crate::io::recurdyn`]) and converts them to the same measurements.
//!
//! # Format
//!
//! A CSV table with exactly this header:
//!
//! ```text
//! x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n
//! ```
//!
//! and one row per static pose:
//!
//! | columns | meaning | unit |
//! |---|---|---|
//! | `x_m`, `y_m`, `z_m` | localiser position of the platform frame origin in the world frame | m |
//! | `roll_deg`, `pitch_deg`, `yaw_deg` | localiser orientation, `R = Rz(yaw) Ry(pitch) Rx(roll)` | degrees |
//! | `l1_m` .. `l4_m` | encoder reading of cable 1..4: the true cable length plus an unknown per-cable offset | m |
//! | `f_ref_n` | load-cell tension of the reference cable at the platform attachment | N |
//!
//! * Every value is a finite number (`12`, `-0.5`, `1.25e-3`; no `NaN`, no
//!   `inf`), bare or in double quotes as spreadsheets write them (`"1.25"`).
//!   Surrounding spaces are ignored.
//! * Encoder readings carry an unknown offset, so any finite value is allowed,
//!   zero and negative ones included.
//! * `f_ref_n` is a tension magnitude and must be positive.
//! * Lines whose first non-blank character is `#` are comments, anywhere in
//!   the file, before the header too (`# simulated by sagcal, seed 7`). Blank
//!   lines are ignored. Line endings may be `\n` or `\r\n`, and a UTF-8
//!   byte-order mark at the start is ignored.
//! * The file must hold at least one row.
//!
//! Example:
//!
//! ```text
//! # simulated by sagcal, seed 7
//! x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n
//! 9.94283158474076,9.93145571155357,15.9060269359906,-1.06322173025346,-0.19122393512445,0.971850603803798,183.324069126233,169.162981532604,155.642263929178,170.927219368362,698.722056942942
//! ```
//!
//! Errors name the file, the row (the data rows counted from 1), its line
//! (from 1, the header, comments and blank lines counted) and the column. [`write_measurements`] writes numbers with full
//! round-trip precision, so writing and reading back gives bit-identical values.
//!
//! # RecurDyn logs
//!
//! [`read_measurements`] recognises the RecurDyn header
//! (`x,y,z,pitch,roll,yaw,L1,..,L4,fc1,fz1,fh1,..,fc4,fz4,fh4,`) and reads the
//! file with [`read_recurdyn`]: position and angles as logged, the encoder
//! readings are the simulated cable lengths (offset zero), and the reference
//! tension is the total tension `fc` of the reference cable
//! ([`ReadOptions::reference_cable`]). Rows the RecurDyn loader rejects, and
//! rows without a tension for the reference cable, are listed in
//! [`MeasurementSet::rejected`] with the reason.
//!
//! # The authors' dataset folder
//!
//! When `path` is a folder, [`read_measurements`] reads it as the dataset
//! folder of the paper's published program (`pos_i_cpp_test.csv`,
//! `R_i_cpp_test.csv`, `lc_meas_cpp_test.csv`, `forces_cpp_test.csv`; see
//! [`crate::io::authors`] for the columns and the mapping).
//!
//! ```
//! use sagcal::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
//! let dir = std::env::temp_dir().join(format!("sagcal-measurements-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let good = dir.join("good.csv");
//! std::fs::write(&good, "# simulated by sagcal, seed 7\n\
//!     x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n\
//!     9.94,9.93,15.9,-1.06,-0.19,0.97,183.32,169.16,155.64,170.93,698.72\n").unwrap();
//! let set = read_measurements(&good, &ReadOptions::default())?;
//! assert_eq!(set.format, MeasurementFormat::Sagcal);
//! assert_eq!((set.poses[0].line, set.poses[0].encoder_lengths_m[3]), (3, 170.93));
//! // A load cell that pulls the wrong way is an error naming the file, the row and the column.
//! let bad = dir.join("bad.csv");
//! std::fs::write(&bad, "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n\
//!     9.94,9.93,15.9,-1.06,-0.19,0.97,183.32,169.16,155.64,170.93,-698.72\n").unwrap();
//! let message = read_measurements(&bad, &ReadOptions::default()).unwrap_err().to_string();
//! assert!(message.contains("bad.csv: row 1 (line 2), field `f_ref_n`"), "{message}");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Error, Result};
use crate::io::atomic::write_atomically;
use crate::io::authors::{is_authors_folder, read_authors_folder};
use crate::io::recurdyn::{looks_like_recurdyn, read_recurdyn, LoadOptions, RecurDynRow, RejectedRow};
use crate::model::measurement::mark_time_order;
pub use crate::model::measurement::PoseMeasurement;

/// The header of a sagcal measurement file, in column order.
pub const MEASUREMENT_HEADER: [&str; 11] = [
    "x_m",
    "y_m",
    "z_m",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "l1_m",
    "l2_m",
    "l3_m",
    "l4_m",
    "f_ref_n",
];

/// Number of columns of a sagcal measurement file.
const N_COLUMNS: usize = MEASUREMENT_HEADER.len();
/// Index of `f_ref_n`.
const F_REF: usize = 10;
/// Number of cables (RecurDyn tension columns).
const N_CABLES: usize = 4;
/// The start of the RecurDyn header, for messages.
const RECURDYN_HEADER: &str = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";
/// At most this many rejection reasons are quoted when every row is rejected.
const MAX_QUOTED_REASONS: usize = 3;

/// The format a measurement file was read from (JSON: `sagcal`, `recurdyn`, `authors`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MeasurementFormat {
    /// sagcal's own measurement file (this module).
    Sagcal,
    /// A RecurDyn finite-element log ([`crate::io::recurdyn`]).
    RecurDyn,
    /// The dataset folder of the paper's published program ([`crate::io::authors`]).
    Authors,
}

impl std::fmt::Display for MeasurementFormat {
    /// The format as a person names it: `sagcal CSV`, `RecurDyn log`, `authors' folder`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MeasurementFormat::Sagcal => "sagcal CSV",
            MeasurementFormat::RecurDyn => "RecurDyn log",
            MeasurementFormat::Authors => "authors' folder",
        })
    }
}

/// The measurements of one file.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSet {
    /// The file that was read.
    pub path: PathBuf,
    /// The format it was in.
    pub format: MeasurementFormat,
    /// The poses, in file order; never empty.
    pub poses: Vec<PoseMeasurement>,
    /// Rows left out, with the reason, in file order (RecurDyn logs only;
    /// empty for sagcal files, where every problem is an error).
    pub rejected: Vec<RejectedRow>,
}

/// Options of [`read_measurements`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// 0-based index of the cable whose RecurDyn tension column is the load
    /// cell (0: `fc1`). Must be below 4; only used for RecurDyn logs.
    pub reference_cable: usize,
    /// Keep RecurDyn rows that are rounded hand transcriptions (see
    /// [`LoadOptions::keep_rounded`]); ignored for sagcal files.
    pub keep_rounded: bool,
}

/// Read a measurement file, sagcal's own format or a RecurDyn log, told apart
/// by the header (the first line that is neither blank nor a comment); or,
/// when `path` is a folder, the authors' dataset folder ([`crate::io::authors`]).
///
/// Malformed input is an error naming the file (and the line and column when
/// the problem is in one value): [`Error::Io`] when the file cannot be read,
/// [`Error::Format`] for a header of neither format or a file without rows,
/// [`Error::Field`] for a row with the wrong number of fields, a value that is
/// not a finite number, or a tension that is not positive.
/// [`Error::InvalidInput`] when `options.reference_cable` is not below 4.
pub fn read_measurements(path: &Path, options: &ReadOptions) -> Result<MeasurementSet> {
    if options.reference_cable >= N_CABLES {
        return Err(Error::InvalidInput(format!(
            "reference cable index {} is out of range: cables are numbered 0..{} (0-based)",
            options.reference_cable,
            N_CABLES - 1
        )));
    }
    if is_authors_folder(path) {
        return Ok(MeasurementSet {
            path: path.to_path_buf(),
            format: MeasurementFormat::Authors,
            poses: read_authors_folder(path)?,
            rejected: Vec::new(),
        });
    }
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf".as_slice()).unwrap_or(&bytes);
    let mut lines = bytes
        .split(|b| *b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .enumerate()
        .map(|(i, l)| (i + 1, l));

    let mut first_comment = None;
    let (header_line, header) = loop {
        match lines.next() {
            None => {
                return Err(format_error(
                    path,
                    format!(
                        "empty file: expected the header `{}` of a sagcal measurement file (or a RecurDyn log)",
                        MEASUREMENT_HEADER.join(",")
                    ),
                ));
            }
            Some((_, l)) if is_blank(l) => {}
            Some((n, l)) if is_comment(l) => {
                first_comment.get_or_insert(n);
            }
            Some(found) => break found,
        }
    };
    let header_text = String::from_utf8_lossy(header);
    let header_fields: Vec<&str> = header_text.split(',').collect();

    if let Some(why) = sagcal_header_mismatch(&header_fields) {
        if looks_like_recurdyn(&header_fields) {
            if let Some(comment) = first_comment {
                return Err(format_error(
                    path,
                    format!(
                        "line {header_line} is a RecurDyn log header, but RecurDyn logs cannot hold comments: remove \
                         line {comment} and the other comment lines before the header"
                    ),
                ));
            }
            return read_recurdyn_measurements(path, options);
        }
        return Err(format_error(
            path,
            format!(
                "line {header_line}: not a measurement file header ({why}): expected the sagcal header `{}`; \
                 RecurDyn logs (header `{RECURDYN_HEADER}`) are accepted too; found `{}`",
                MEASUREMENT_HEADER.join(","),
                header_text.escape_debug()
            ),
        ));
    }

    let mut poses = Vec::new();
    for (line, text) in lines {
        if is_blank(text) || is_comment(text) {
            continue;
        }
        poses.push(parse_row(text, (poses.len() + 1, line), path)?);
    }
    if poses.is_empty() {
        return Err(format_error(
            path,
            format!("no measurements: the file holds the header (line {header_line}) but no data rows"),
        ));
    }
    // A sagcal file's rows are the order the robot took its poses in.
    mark_time_order(&mut poses);
    Ok(MeasurementSet {
        path: path.to_path_buf(),
        format: MeasurementFormat::Sagcal,
        poses,
        rejected: Vec::new(),
    })
}

/// Write `poses` as a sagcal measurement file, `comments` first as `# ...`
/// lines (a comment with line breaks becomes several comment lines).
///
/// Every value is checked first (finite; reference tension positive; at
/// least one pose): invalid data is an [`Error::InvalidInput`] naming the
/// file, the row and the column, and nothing is written. The file is written
/// to a temporary file in the same directory and renamed over `path`, so on
/// any error `path` is left as it was and no temporary file remains. Numbers
/// are written with Rust's shortest round-trip representation, so
/// [`read_measurements`] gives back bit-identical values.
pub fn write_measurements(path: &Path, comments: &[String], poses: &[PoseMeasurement]) -> Result<()> {
    write_atomically(path, measurements_text(path, comments, poses)?.as_bytes())
}

/// The text [`write_measurements`] writes to `path` (for a command that
/// writes it with other files, [`crate::io::OutputSet`]): the same checks,
/// the errors naming `path`; nothing is written.
pub fn measurements_text(path: &Path, comments: &[String], poses: &[PoseMeasurement]) -> Result<String> {
    validate_for_writing(path, poses)?;

    let mut text = String::new();
    for comment in comments {
        // `str::lines` drops a final empty line: keep an empty comment as one `#` line.
        let mut parts: Vec<&str> = comment.lines().collect();
        if parts.is_empty() {
            parts.push("");
        }
        for part in parts {
            if part.is_empty() {
                text.push_str("#\n");
            } else {
                text.push_str("# ");
                text.push_str(part);
                text.push('\n');
            }
        }
    }
    text.push_str(&MEASUREMENT_HEADER.join(","));
    text.push('\n');
    for pose in poses {
        let values = pose_values(pose);
        let fields: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
        text.push_str(&fields.join(","));
        text.push('\n');
    }
    Ok(text)
}

/// The 11 values of a pose, in [`MEASUREMENT_HEADER`] order (as a file row holds them).
pub fn pose_values(pose: &PoseMeasurement) -> [f64; N_COLUMNS] {
    let [x, y, z] = pose.position_m;
    let [l1, l2, l3, l4] = pose.encoder_lengths_m;
    [
        x,
        y,
        z,
        pose.roll_deg,
        pose.pitch_deg,
        pose.yaw_deg,
        l1,
        l2,
        l3,
        l4,
        pose.reference_tension_n,
    ]
}

/// Refuse data that [`read_measurements`] would not read back (the check
/// [`write_measurements`] makes first; callers that write other files with
/// the measurements make it before writing any of them).
pub fn validate_for_writing(path: &Path, poses: &[PoseMeasurement]) -> Result<()> {
    if poses.is_empty() {
        return Err(Error::InvalidInput(format!(
            "refusing to write {}: no measurements (a measurement file needs at least one row)",
            path.display()
        )));
    }
    for (i, pose) in poses.iter().enumerate() {
        for (column, value) in MEASUREMENT_HEADER.iter().zip(pose_values(pose)) {
            let problem = if !value.is_finite() {
                Some(format!("not a finite number: {value}"))
            } else if *column == MEASUREMENT_HEADER[F_REF] {
                tension_problem(value)
            } else {
                None
            };
            if let Some(problem) = problem {
                let source = if pose.line > 0 {
                    format!(" (line {} of its source)", pose.line)
                } else {
                    String::new()
                };
                return Err(Error::InvalidInput(format!(
                    "refusing to write {}: row {} of {}{source}, field `{column}`: {problem}",
                    path.display(),
                    i + 1,
                    poses.len()
                )));
            }
        }
    }
    Ok(())
}

/// What is wrong with a reference tension, if anything (`value` is finite).
fn tension_problem(value: f64) -> Option<String> {
    if value == 0.0 {
        Some("zero tension: the reference tension must be positive".to_string())
    } else if value < 0.0 {
        Some(format!(
            "negative tension: the reference tension must be positive, got {value} N"
        ))
    } else {
        None
    }
}

/// Read a RecurDyn log and convert its rows to measurements.
fn read_recurdyn_measurements(path: &Path, options: &ReadOptions) -> Result<MeasurementSet> {
    let log = read_recurdyn(
        path,
        &LoadOptions {
            keep_rounded: options.keep_rounded,
        },
    )?;
    let c = options.reference_cable;
    let mut poses = Vec::with_capacity(log.rows.len());
    let mut rejected = log.rejected;
    for row in &log.rows {
        match from_recurdyn(row, c) {
            Some(pose) => poses.push(pose),
            None => rejected.push(RejectedRow {
                line: row.line,
                reason: format!(
                    "no tension logged for the reference cable {} (columns fc{k},fz{k},fh{k} are empty)",
                    c + 1,
                    k = c + 1
                ),
            }),
        }
    }
    rejected.sort_by_key(|r| r.line);
    if poses.is_empty() {
        let quoted: Vec<String> = rejected
            .iter()
            .take(MAX_QUOTED_REASONS)
            .map(|r| format!("line {}: {}", r.line, r.reason))
            .collect();
        let more = rejected.len().saturating_sub(MAX_QUOTED_REASONS);
        return Err(format_error(
            path,
            format!(
                "no measurements: every row of the RecurDyn log was rejected ({} rejected: {}{})",
                rejected.len(),
                quoted.join("; "),
                if more > 0 {
                    format!("; and {more} more")
                } else {
                    String::new()
                }
            ),
        ));
    }
    Ok(MeasurementSet {
        path: log.path,
        format: MeasurementFormat::RecurDyn,
        poses,
        rejected,
    })
}

/// The measurement of a RecurDyn row, or `None` when the reference cable has no tension.
fn from_recurdyn(row: &RecurDynRow, reference_cable: usize) -> Option<PoseMeasurement> {
    let tension = row.tensions.get(reference_cable).copied().flatten()?;
    Some(PoseMeasurement {
        line: row.line,
        position_m: row.position_m,
        roll_deg: row.roll_deg,
        pitch_deg: row.pitch_deg,
        yaw_deg: row.yaw_deg,
        encoder_lengths_m: row.cable_lengths_m,
        reference_tension_n: tension.total_n,
        excluded: Default::default(),
        order: None,
    })
}

/// Why `fields` is not the sagcal header, or `None` when it is.
fn sagcal_header_mismatch(fields: &[&str]) -> Option<String> {
    for (i, expected) in MEASUREMENT_HEADER.iter().enumerate() {
        match fields.get(i).map(|f| f.trim()) {
            None => return Some(format!("column {} `{expected}` is missing", i + 1)),
            Some(found) if found != *expected => {
                return Some(format!(
                    "column {} is `{}`, expected `{expected}`",
                    i + 1,
                    found.escape_debug()
                ));
            }
            Some(_) => {}
        }
    }
    (fields.len() != N_COLUMNS).then(|| format!("{} columns, expected {N_COLUMNS}", fields.len()))
}

/// Parse one data row (the `row`-th, on line `line`, without its line ending).
fn parse_row(text: &[u8], (row, line): (usize, usize), path: &Path) -> Result<PoseMeasurement> {
    let fields: Vec<&[u8]> = text.split(|b| *b == b',').collect();
    let n = fields.len();
    if n != N_COLUMNS {
        let (field, what) = if n < N_COLUMNS {
            (
                MEASUREMENT_HEADER[n].to_string(),
                format!("`{}` and the columns after it are missing", MEASUREMENT_HEADER[n]),
            )
        } else {
            (
                format!("column {}", N_COLUMNS + 1),
                format!("column {} and the ones after it are extra", N_COLUMNS + 1),
            )
        };
        return Err(Error::Field {
            path: path.to_path_buf(),
            row,
            line: Some(line),
            field,
            message: format!("wrong number of fields: expected {N_COLUMNS}, found {n} ({what})"),
        });
    }
    let mut values = [0.0; N_COLUMNS];
    for (index, (raw, slot)) in fields.iter().zip(values.iter_mut()).enumerate() {
        let err = |message: String| Error::Field {
            path: path.to_path_buf(),
            row,
            line: Some(line),
            field: MEASUREMENT_HEADER[index].to_string(),
            message,
        };
        let text = unquote(
            std::str::from_utf8(raw)
                .map_err(|_| err("not valid UTF-8 text".to_string()))?
                .trim(),
        );
        if text.is_empty() {
            return Err(err("value is empty".to_string()));
        }
        let value: f64 = text
            .parse()
            .map_err(|_| err(format!("not a number: `{}`", text.escape_debug())))?;
        if !value.is_finite() {
            return Err(err(format!("not a finite number: `{text}`")));
        }
        if index == F_REF {
            if let Some(problem) = tension_problem(value) {
                return Err(err(problem));
            }
        }
        *slot = value;
    }
    Ok(pose_from_values(line, &values))
}

/// A CSV value without the double quotes around it, if it has them
/// (`"1.25"` as spreadsheets write numbers), and the spaces inside them.
pub(crate) fn unquote(text: &str) -> &str {
    match text.strip_prefix('"').and_then(|t| t.strip_suffix('"')) {
        Some(inner) => inner.trim(),
        None => text,
    }
}

/// A line holding only whitespace.
fn is_blank(line: &[u8]) -> bool {
    line.iter().all(u8::is_ascii_whitespace)
}

/// A comment line: `#` after optional leading whitespace.
fn is_comment(line: &[u8]) -> bool {
    line.trim_ascii_start().starts_with(b"#")
}

/// An [`Error::Format`] for `path`.
fn format_error(path: &Path, message: String) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        message,
    }
}

/// A measurement from the 11 values of one row in [`MEASUREMENT_HEADER`]
/// order, for data that never were a file (the Python binding's arrays).
///
/// The checks and messages are those of [`read_measurements`] for a row of a
/// file: every value finite, the reference tension positive. `source` names
/// the data in the error ([`Error::Field`]) and `row` is its 1-based row;
/// [`PoseMeasurement::line`] is set to 0 (in-memory data).
pub fn measurement_from_values(source: &Path, row: usize, values: &[f64; N_COLUMNS]) -> Result<PoseMeasurement> {
    for (index, value) in values.iter().enumerate() {
        let problem = if !value.is_finite() {
            Some(format!("not a finite number: `{value}`"))
        } else if index == F_REF {
            tension_problem(*value)
        } else {
            None
        };
        if let Some(message) = problem {
            return Err(Error::Field {
                path: source.to_path_buf(),
                row,
                line: None,
                field: MEASUREMENT_HEADER[index].to_string(),
                message,
            });
        }
    }
    Ok(pose_from_values(0, values))
}

/// The pose of line `line` from its 11 values in [`MEASUREMENT_HEADER`] order
/// (the inverse of [`pose_values`]; no checks).
fn pose_from_values(line: usize, values: &[f64; N_COLUMNS]) -> PoseMeasurement {
    let [x, y, z, roll, pitch, yaw, l1, l2, l3, l4, f_ref] = *values;
    PoseMeasurement {
        line,
        position_m: [x, y, z],
        roll_deg: roll,
        pitch_deg: pitch,
        yaw_deg: yaw,
        encoder_lengths_m: [l1, l2, l3, l4],
        reference_tension_n: f_ref,
        excluded: Default::default(),
        order: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoted_numbers_are_numbers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        std::fs::write(
            &path,
            "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n\
             \"1.25\",2,3,0,0,0,\" 10 \",11,12,13,\"698.5\"\n",
        )
        .unwrap();
        let set = read_measurements(&path, &ReadOptions::default()).unwrap();
        assert_eq!(set.poses[0].position_m, [1.25, 2.0, 3.0]);
        assert_eq!(set.poses[0].encoder_lengths_m[0], 10.0);
        assert_eq!(set.poses[0].reference_tension_n, 698.5);
        // One quote only, or quotes around a non-number: an error naming the field.
        for bad in ["\"1.25", "\"abc\""] {
            std::fs::write(
                &path,
                format!("x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n{bad},2,3,0,0,0,10,11,12,13,698\n"),
            )
            .unwrap();
            let message = read_measurements(&path, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(message.contains("row 1 (line 2), field `x_m`"), "{message}");
        }
    }

    #[test]
    fn unquote_strips_one_pair() {
        assert_eq!(unquote("\"1.5\""), "1.5");
        assert_eq!(unquote("\" 1.5 \""), "1.5");
        assert_eq!(unquote("1.5"), "1.5");
        assert_eq!(unquote("\""), "\"");
        assert_eq!(unquote("\"\""), "");
    }
}
