//! The input of `sagcal localize`: rows of cable readings, from a
//! readings-only CSV, sagcal's measurement file, a RecurDyn log
//! ([`read_readings`] tells them apart by the header) or the authors' dataset
//! folder ([`crate::io::authors`], when the path is a folder).
//!
//! # Readings-only format
//!
//! ```text
//! # encoder readings of the calibrated robot
//! l1_m,l2_m,l3_m,l4_m,f_ref_n
//! 183.324069126233,169.162981532604,155.642263929178,170.927219368362,698.72
//! ```
//!
//! The header is `l1_m,l2_m,l3_m,l4_m` with an optional fifth column
//! `f_ref_n` (the load cell, N, positive; an empty field: not read on that
//! row). Encoder readings are any finite numbers (cable length plus the
//! calibrated offset). Comments (`#`) and blank lines are ignored, as in the
//! measurement file ([`crate::io::measurements`]). Errors name the file, the
//! row (the data rows counted from 1), its line and the column.
//!
//! Measurement files and RecurDyn logs are read by
//! [`read_measurements`]: their localiser pose is kept (for comparison, or a
//! prior) and their load cell is the reference cable's tension.
//!
//! ```
//! use sagcal::io::readings::{read_readings, ReadingsFormat};
//! let path = std::env::temp_dir().join(format!("sagcal-readings-doc-{}.csv", std::process::id()));
//! // The second row has no load-cell reading (an empty field).
//! std::fs::write(&path, "# encoder readings of the calibrated robot\n\
//!     l1_m,l2_m,l3_m,l4_m,f_ref_n\n\
//!     183.32,169.16,155.64,170.93,698.72\n\
//!     183.40,169.10,155.70,170.90,\n").unwrap();
//! let file = read_readings(&path, 0)?;
//! assert_eq!(file.format, ReadingsFormat::ReadingsOnly);
//! assert_eq!(file.rows.len(), 2);
//! assert_eq!((file.rows[0].load_cell_n, file.rows[1].load_cell_n), (Some(698.72), None));
//! assert_eq!((file.rows[1].line, file.rows[1].encoder_lengths_m[0]), (4, 183.40));
//! assert!(file.rows[0].localiser_pose.is_none()); // readings alone carry no pose
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
use crate::io::recurdyn::RejectedRow;
use crate::model::pose::PlatformPose;
use crate::model::robot::CABLE_COUNT;

/// The readings-only header (the fifth column optional).
pub const READINGS_HEADER: [&str; 5] = ["l1_m", "l2_m", "l3_m", "l4_m", "f_ref_n"];

/// One row of readings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadingRow {
    /// 1-based line in the file; 0 for readings that were not read from a
    /// file (reports name a row as [`crate::model::DataRow`] does).
    pub line: usize,
    /// Encoder readings of cables 1..4, metres.
    pub encoder_lengths_m: [f64; CABLE_COUNT],
    /// The load cell, newtons, if read.
    pub load_cell_n: Option<f64>,
    /// The localiser's pose, if the file has one.
    pub localiser_pose: Option<PlatformPose>,
}

/// The format a readings file was in (JSON: `readings-only`, `sagcal`,
/// `recurdyn`, `authors`, as [`MeasurementFormat`] names the same formats).
///
/// [`MeasurementFormat`]: crate::io::measurements::MeasurementFormat
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReadingsFormat {
    /// `l1_m,l2_m,l3_m,l4_m[,f_ref_n]`.
    ReadingsOnly,
    /// sagcal's measurement file.
    Sagcal,
    /// A RecurDyn log.
    #[serde(rename = "recurdyn")]
    RecurDyn,
    /// The authors' dataset folder.
    Authors,
}

impl std::fmt::Display for ReadingsFormat {
    /// The format as a person names it: `readings-only CSV`, `sagcal CSV`, ...
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ReadingsFormat::ReadingsOnly => "readings-only CSV",
            ReadingsFormat::Sagcal => "sagcal CSV",
            ReadingsFormat::RecurDyn => "RecurDyn log",
            ReadingsFormat::Authors => "authors' folder",
        })
    }
}

/// The rows of one file.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadingsFile {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: ReadingsFormat,
    /// The rows, in file order; never empty.
    pub rows: Vec<ReadingRow>,
    /// Rows the RecurDyn loader left out, with the reason.
    pub rejected: Vec<RejectedRow>,
}

/// An [`Error::Field`] for the data row `row` on line `line`.
fn field_error(path: &Path, (row, line): (usize, usize), field: &str, message: String) -> Error {
    Error::Field {
        path: path.to_path_buf(),
        row,
        line: Some(line),
        field: field.into(),
        message,
    }
}

/// Read the rows of `path` in any of the four formats (module docs);
/// `reference_cable` (0-based) picks a RecurDyn log's load-cell column.
pub fn read_readings(path: &Path, reference_cable: usize) -> Result<ReadingsFile> {
    if crate::io::authors::is_authors_folder(path) {
        return read_measurement_rows(path, reference_cable);
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let header = lines.next().map(|(_, l)| l).unwrap_or("");
    let fields: Vec<&str> = header.split(',').map(str::trim).collect();
    let with_load_cell = fields == READINGS_HEADER;
    if !(with_load_cell || fields == READINGS_HEADER[..CABLE_COUNT]) {
        return read_measurement_rows(path, reference_cable);
    }
    let mut rows = Vec::new();
    for (line, text) in lines {
        let at = (rows.len() + 1, line);
        let values: Vec<&str> = text
            .split(',')
            .map(|v| crate::io::measurements::unquote(v.trim()))
            .collect();
        if values.len() != fields.len() {
            return Err(field_error(
                path,
                at,
                fields.last().copied().unwrap_or(""),
                format!("expected {} fields, found {}", fields.len(), values.len()),
            ));
        }
        let number = |k: usize| -> Result<f64> {
            values[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| field_error(path, at, fields[k], format!("`{}` is not a finite number", values[k])))
        };
        let mut encoder_lengths_m = [0.0; CABLE_COUNT];
        for (k, value) in encoder_lengths_m.iter_mut().enumerate() {
            *value = number(k)?;
        }
        let load_cell_n = match with_load_cell && !values[CABLE_COUNT].is_empty() {
            true => {
                let f = number(CABLE_COUNT)?;
                if f <= 0.0 {
                    return Err(field_error(
                        path,
                        at,
                        "f_ref_n",
                        format!("tension {f} N must be positive"),
                    ));
                }
                Some(f)
            }
            false => None,
        };
        rows.push(ReadingRow {
            line,
            encoder_lengths_m,
            load_cell_n,
            localiser_pose: None,
        });
    }
    if rows.is_empty() {
        return Err(Error::Format {
            path: path.to_path_buf(),
            message: "no rows after the header".into(),
        });
    }
    Ok(ReadingsFile {
        path: path.to_path_buf(),
        format: ReadingsFormat::ReadingsOnly,
        rows,
        rejected: Vec::new(),
    })
}

fn read_measurement_rows(path: &Path, reference_cable: usize) -> Result<ReadingsFile> {
    let set = read_measurements(
        path,
        &ReadOptions {
            reference_cable,
            keep_rounded: false,
        },
    )
    .map_err(|e| match e {
        Error::Format { path, message } => Error::Format {
            path,
            message: format!("{message}; or the readings-only header `l1_m,l2_m,l3_m,l4_m[,f_ref_n]`"),
        },
        other => other,
    })?;
    let rows = set
        .poses
        .iter()
        .map(|m| ReadingRow {
            line: m.line,
            encoder_lengths_m: m.encoder_lengths_m,
            load_cell_n: Some(m.reference_tension_n),
            localiser_pose: Some(m.localiser_pose()),
        })
        .collect();
    Ok(ReadingsFile {
        path: set.path,
        format: match set.format {
            MeasurementFormat::Sagcal => ReadingsFormat::Sagcal,
            MeasurementFormat::RecurDyn => ReadingsFormat::RecurDyn,
            MeasurementFormat::Authors => ReadingsFormat::Authors,
        },
        rows,
        rejected: set.rejected,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoted_numbers_are_numbers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        std::fs::write(&path, "l1_m,l2_m,l3_m,l4_m,f_ref_n\n\"1.25\",\" 2 \",3,4,\"5.5\"\n").unwrap();
        let file = read_readings(&path, 0).unwrap();
        assert_eq!(file.rows[0].encoder_lengths_m, [1.25, 2.0, 3.0, 4.0]);
        assert_eq!(file.rows[0].load_cell_n, Some(5.5));
        // Quotes around something that is not a number are still an error naming the field.
        std::fs::write(&path, "l1_m,l2_m,l3_m,l4_m\n1,\"x\",3,4\n").unwrap();
        let message = read_readings(&path, 0).unwrap_err().to_string();
        assert!(message.contains("row 1 (line 2), field `l2_m`"), "{message}");
    }
}
