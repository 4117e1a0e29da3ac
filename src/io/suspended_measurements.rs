//! The measurement file of a robot of `N` cables: sagcal's CSV
//! ([`crate::io::measurements`]) with a column per cable and per load cell.
//!
//! ```text
//! x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,...,lN_m,f1_n,f5_n
//! ```
//!
//! | columns | meaning | unit |
//! |---|---|---|
//! | `x_m` .. `yaw_deg` | the localiser's pose, as in the four-cable file | m, degrees |
//! | `l1_m` .. `lN_m` | encoder reading of each cable: its length plus an unknown offset | m |
//! | `f<k>_n` | the load cell on cable `k` (1-based): the tension at its attachment, positive | N |
//!
//! The same rules as the four-cable file: finite numbers (bare or in double
//! quotes), `#` comments and blank lines anywhere, at least one row; the
//! header names the number of cables and which carry load cells, and
//! [`read_suspended_measurements`] refuses a file whose header does not
//! match the robot's. Numbers are written with full round-trip precision.
//!
//! ```
//! use sagcal::io::suspended_measurements::{read_suspended_measurements, write_suspended_measurements};
//! use sagcal::model::suspended::{SuspendedMeasurement, SuspendedRobot};
//! let robot = SuspendedRobot::builtin("eight")?;
//! let row = SuspendedMeasurement {
//!     line: 0,
//!     position_m: [1.0, -0.5, 2.0],
//!     roll_deg: 0.1,
//!     pitch_deg: -0.2,
//!     yaw_deg: 0.3,
//!     encoder_lengths_m: vec![7.1, 8.2, 8.3, 7.4, 7.5, 8.6, 8.7, 7.8],
//!     load_cell_tensions_n: vec![412.5, 230.25],
//! };
//! let path = std::env::temp_dir().join(format!("sagcal-suspended-doc-{}.csv", std::process::id()));
//! write_suspended_measurements(&path, &robot, &["eight cables".into()], &[row.clone()])?;
//! let text = std::fs::read_to_string(&path).unwrap();
//! assert!(text.contains("l8_m,f1_n,f5_n\n"));
//! let read = read_suspended_measurements(&path, &robot)?;
//! assert_eq!(read[0], SuspendedMeasurement { line: 3, ..row });
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::Path;

use super::atomic::write_atomically;
use super::measurements::unquote;
use crate::error::{Error, Result};
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// The localiser's six columns, first in every row.
const POSE_COLUMNS: [&str; 6] = ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"];

/// The header of `robot`'s measurement file: the pose, `l1_m .. lN_m`, then
/// `f<k>_n` for each load cell.
pub fn suspended_header(robot: &SuspendedRobot) -> Vec<String> {
    POSE_COLUMNS
        .iter()
        .map(|c| c.to_string())
        .chain((1..=robot.cable_count()).map(|i| format!("l{i}_m")))
        .chain(robot.load_cells.iter().map(|c| format!("f{}_n", c + 1)))
        .collect()
}

/// The values of a row in the order of [`suspended_header`].
pub fn row_values(row: &SuspendedMeasurement) -> Vec<f64> {
    row.position_m
        .iter()
        .copied()
        .chain([row.roll_deg, row.pitch_deg, row.yaw_deg])
        .chain(row.encoder_lengths_m.iter().copied())
        .chain(row.load_cell_tensions_n.iter().copied())
        .collect()
}

/// Write `rows` of `robot` to `path` whole or not at all, each comment a `#`
/// line before the header. Refuses (writing nothing) an empty set, a row
/// whose counts do not fit the robot, a non-finite value or a tension that
/// is not positive, naming the row and the column.
pub fn write_suspended_measurements(
    path: &Path,
    robot: &SuspendedRobot,
    comments: &[String],
    rows: &[SuspendedMeasurement],
) -> Result<()> {
    write_atomically(
        path,
        suspended_measurements_text(path, robot, comments, rows)?.as_bytes(),
    )
}

/// The text [`write_suspended_measurements`] writes to `path` (for a
/// command that writes it with other files, [`crate::io::OutputSet`]): the
/// same checks, the errors naming `path`; nothing is written.
pub fn suspended_measurements_text(
    path: &Path,
    robot: &SuspendedRobot,
    comments: &[String],
    rows: &[SuspendedMeasurement],
) -> Result<String> {
    let header = suspended_header(robot);
    let refuse = |message: String| Error::InvalidInput(format!("refusing to write {}: {message}", path.display()));
    if rows.is_empty() {
        return Err(refuse(
            "no measurements (a measurement file needs at least one row)".into(),
        ));
    }
    let mut text: String = comments
        .iter()
        .flat_map(|c| c.lines())
        .map(|l| format!("# {l}\n"))
        .collect();
    text += &header.join(",");
    text.push('\n');
    for (i, row) in rows.iter().enumerate() {
        let values = row_values(row);
        if values.len() != header.len() {
            return Err(refuse(format!(
                "row {} has {} values, the robot's file {} columns",
                i + 1,
                values.len(),
                header.len()
            )));
        }
        for (column, value) in header.iter().zip(&values) {
            if let Some(problem) = value_problem(column, *value) {
                return Err(refuse(format!("row {}, field `{column}`: {problem}", i + 1)));
            }
        }
        let fields: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
        text += &fields.join(",");
        text.push('\n');
    }
    Ok(text)
}

/// What is wrong with `value` in `column`, if anything.
fn value_problem(column: &str, value: f64) -> Option<String> {
    if !value.is_finite() {
        Some(format!("not a finite number: {value}"))
    } else if column.starts_with('f') && value <= 0.0 {
        Some(format!("a load cell's tension must be positive, got {value} N"))
    } else {
        None
    }
}

/// Read `robot`'s measurement file. Errors name the file, and for a value
/// the row (data rows from 1), its line and the column.
pub fn read_suspended_measurements(path: &Path, robot: &SuspendedRobot) -> Result<Vec<SuspendedMeasurement>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = String::from_utf8_lossy(bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes)).into_owned();
    let format = |message: String| Error::Format {
        path: path.to_path_buf(),
        message,
    };
    let expected = suspended_header(robot);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| format("empty file: no header".into()))?;
    let found: Vec<&str> = header.split(',').map(str::trim).collect();
    if found != expected {
        return Err(format(format!(
            "the header is `{header}`, but robot `{}` ({} cables, load cells on {}) needs `{}`",
            robot.name,
            robot.cable_count(),
            robot.load_cells_phrase(),
            expected.join(",")
        )));
    }
    let rows: Vec<SuspendedMeasurement> = lines
        .enumerate()
        .map(|(index, (line, text))| parse_row(path, robot, &expected, (index + 1, line), text))
        .collect::<Result<_>>()?;
    if rows.is_empty() {
        return Err(format("no measurements: the file has a header and no rows".into()));
    }
    Ok(rows)
}

/// One data row (the `row`-th, on line `line`).
fn parse_row(
    path: &Path,
    robot: &SuspendedRobot,
    header: &[String],
    (row, line): (usize, usize),
    text: &str,
) -> Result<SuspendedMeasurement> {
    let err = |field: &str, message: String| Error::Field {
        path: path.to_path_buf(),
        row,
        line: Some(line),
        field: field.to_string(),
        message,
    };
    let fields: Vec<&str> = text.split(',').collect();
    if fields.len() != header.len() {
        let field = header.get(fields.len()).map_or("the row", String::as_str);
        return Err(err(
            field,
            format!(
                "wrong number of fields: expected {}, found {}",
                header.len(),
                fields.len()
            ),
        ));
    }
    let mut values = Vec::with_capacity(fields.len());
    for (column, raw) in header.iter().zip(fields) {
        let raw = unquote(raw.trim());
        let value: f64 = raw
            .parse()
            .map_err(|_| err(column, format!("not a number: `{}`", raw.escape_debug())))?;
        if let Some(problem) = value_problem(column, value) {
            return Err(err(column, problem));
        }
        values.push(value);
    }
    Ok(measurement_at(robot, line, &values))
}

/// The measurement of line `line` from its values in [`suspended_header`]
/// order (no checks).
fn measurement_at(robot: &SuspendedRobot, line: usize, values: &[f64]) -> SuspendedMeasurement {
    let n = robot.cable_count();
    SuspendedMeasurement {
        line,
        position_m: [values[0], values[1], values[2]],
        roll_deg: values[3],
        pitch_deg: values[4],
        yaw_deg: values[5],
        encoder_lengths_m: values[6..6 + n].to_vec(),
        load_cell_tensions_n: values[6 + n..].to_vec(),
    }
}

/// One measurement of `robot` from its values in [`suspended_header`]
/// order, for data that never were a file (the Python binding's arrays):
/// the checks and messages of [`read_suspended_measurements`] for a row,
/// `source` naming the data and `row` its 1-based row; the line is 0.
pub fn suspended_measurement_from_values(
    source: &Path,
    robot: &SuspendedRobot,
    row: usize,
    values: &[f64],
) -> Result<SuspendedMeasurement> {
    let header = suspended_header(robot);
    let err = |field: &str, message: String| Error::Field {
        path: source.to_path_buf(),
        row,
        line: None,
        field: field.to_string(),
        message,
    };
    if values.len() != header.len() {
        return Err(err(
            "the row",
            format!(
                "{} values, but robot `{}` has {} columns: {}",
                values.len(),
                robot.name,
                header.len(),
                header.join(", ")
            ),
        ));
    }
    for (column, &value) in header.iter().zip(values) {
        if let Some(problem) = value_problem(column, value) {
            return Err(err(column, problem));
        }
    }
    Ok(measurement_at(robot, 0, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot() -> SuspendedRobot {
        SuspendedRobot::builtin("three").unwrap()
    }

    fn file(name: &str, text: &str) -> std::path::PathBuf {
        let path = std::env::temp_dir().join(format!("sagcal-suspended-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    /// Blunders name the file, the row, the line and the column.
    #[test]
    fn blunders_are_named() {
        let header = "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,f1_n\n";
        for (name, text, expected) in [
            (
                "neg.csv",
                format!("{header}1,2,3,0,0,0,10,11,12,-5\n"),
                "row 1 (line 2), field `f1_n`",
            ),
            (
                "nan.csv",
                format!("# c\n{header}1,2,3,0,0,0,NaN,11,12,5\n"),
                "row 1 (line 3), field `l1_m`",
            ),
            ("short.csv", format!("{header}1,2,3,0,0,0,10,11\n"), "field `l3_m`"),
            (
                "word.csv",
                format!("{header}1,2,3,0,0,0,10,11,x,5\n"),
                "not a number: `x`",
            ),
            (
                "four.csv",
                "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n1,2,3,0,0,0,1,1,1,1,1\n".into(),
                "needs `x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,f1_n`",
            ),
            ("empty.csv", header.to_string(), "no measurements"),
        ] {
            let path = file(name, &text);
            let message = read_suspended_measurements(&path, &robot()).unwrap_err().to_string();
            std::fs::remove_file(&path).unwrap();
            assert!(
                message.contains(name) && message.contains(expected),
                "{expected}: {message}"
            );
        }
    }

    /// A row that would not read back is refused, and nothing is written.
    #[test]
    fn writing_refuses_what_would_not_read_back() {
        let path = std::env::temp_dir().join(format!("sagcal-suspended-{}-refused.csv", std::process::id()));
        let row = SuspendedMeasurement {
            line: 0,
            position_m: [0.0, 0.0, 5.0],
            roll_deg: 0.0,
            pitch_deg: 0.0,
            yaw_deg: 0.0,
            encoder_lengths_m: vec![10.0, 11.0, f64::NAN],
            load_cell_tensions_n: vec![100.0],
        };
        let message = write_suspended_measurements(&path, &robot(), &[], &[row])
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("row 1, field `l3_m`: not a finite number"),
            "{message}"
        );
        assert!(!path.exists());
    }
}
