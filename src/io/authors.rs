//! The dataset folder of the paper's published program: four header-less CSV
//! files, one static pose per line, read into sagcal's measurements.
//! [`crate::io::measurements::read_measurements`] reads such a folder
//! whenever `--data` names a directory.
//!
//! # Layout
//!
//! The authors' calibration program (Dindarloo et al., the paper's footnote 1:
//! the GitHub repository `MohammadrezaDindarloo/ARASFactorSLAC`, e.g.
//! `ArasFactor_long_cable_realdata_self_calibration_base/scampi_factor_graph/`,
//! its `master.cpp` and `dataset/`) reads these files from its `dataset/`
//! folder, line `k` of every file being the same static pose `k`:
//!
//! | file | columns | meaning | sagcal field |
//! |---|---|---|---|
//! | `pos_i_cpp_test.csv` | `x, y, z` | localiser position of the platform frame origin in the world frame, m | `x_m, y_m, z_m` |
//! | `R_i_cpp_test.csv` | `pitch, roll, yaw` | localiser orientation, degrees; the program builds `Rot3::Ypr(yaw, pitch, roll)` = `Rz(yaw) Ry(pitch) Rx(roll)` | `pitch_deg, roll_deg, yaw_deg` |
//! | `lc_meas_cpp_test.csv` | `l1, l2, l3, l4` | relative cable-length (encoder) readings of cables 1..4, m | `l1_m .. l4_m` |
//! | `forces_cpp_test.csv` | `f_h, f_v` | the reference cable's horizontal and vertical force at the platform, N | `f_ref_n = hypot(f_h, f_v)` |
//!
//! The mapping, checked against the published files:
//!
//! * The rotation convention is sagcal's own (`R = Rz(yaw) Ry(pitch) Rx(roll)`,
//!   [`crate::io::measurements`]); only the column order differs: pitch first,
//!   as in the RecurDyn log the files were cut from.
//! * The published `forces_cpp_test.csv` holds the RecurDyn log's `fh1, fz1`
//!   (first line `624.341,68.629`, the log's `fc1 = 628.10 N`): the horizontal
//!   force `f_h` along the cable's plane axis `ŝ_c` and the vertical force
//!   `f_v` along `ŝ_z` (paper Sec. III-A, Fig. 1). The program uses only their
//!   norm, `first_cable_force_magnitude = ‖(f_h, f_v)‖`, as the load-cell
//!   reading `f^m` of the force factor (paper eq. 15): the tension of the
//!   reference cable at its platform attachment. sagcal does the same, so the
//!   signs of the two components do not matter; their norm must be positive.
//! * The reference cable is the one with the force sensor (paper Sec. IV), the
//!   robot file's `reference_cable` (the published program: cable 1).
//! * The encoder readings are relative lengths: cable length plus an unknown
//!   offset, so any finite value is allowed.
//!
//! # Rules
//!
//! * No header line: every line is numbers, as the program reads each field
//!   with `stod`. A trailing comma (`1,2,3,`) is allowed, as the program's
//!   reader ignores it; blank lines are allowed only at the end of a file.
//!   Line endings `\n` or `\r\n`; a UTF-8 byte-order mark is ignored.
//! * Every value is a finite number; the four files have the same number of
//!   lines (rows are paired by line number), at least one.
//!
//! Errors name the file, the row and its line (the same number: the files
//! have no header) and the column; files that disagree on the number of rows are an error naming
//! both; a folder without the four files is an error listing the missing ones.
//!
//! ```
//! # fn main() -> sagcal::Result<()> {
//! let dir = std::env::temp_dir().join(format!("sagcal-authors-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! for (file, text) in [
//!     ("pos_i_cpp_test.csv", "9.93,9.92,10.91\n"),
//!     ("R_i_cpp_test.csv", "-1.31,0.68,-0.04\n"),
//!     ("lc_meas_cpp_test.csv", "184.29,170.21,156.78,171.96\n"),
//!     ("forces_cpp_test.csv", "624.341,68.629\n"),
//! ] {
//!     std::fs::write(dir.join(file), text).unwrap();
//! }
//! let poses = sagcal::io::authors::read_authors_folder(&dir)?;
//! assert_eq!(poses[0].pitch_deg, -1.31);
//! assert_eq!(poses[0].roll_deg, 0.68);
//! assert!((poses[0].reference_tension_n - 628.1016).abs() < 1e-3);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;

/// Localiser positions, `x, y, z` in metres.
pub const POSITION_FILE: &str = "pos_i_cpp_test.csv";
/// Localiser orientations, `pitch, roll, yaw` in degrees.
pub const ORIENTATION_FILE: &str = "R_i_cpp_test.csv";
/// Relative cable-length readings of cables 1..4, metres.
pub const LENGTHS_FILE: &str = "lc_meas_cpp_test.csv";
/// The reference cable's horizontal and vertical force, newtons.
pub const FORCES_FILE: &str = "forces_cpp_test.csv";

/// The four files with the names sagcal gives their columns in messages.
const FILES: [(&str, &[&str]); 4] = [
    (POSITION_FILE, &["x_m", "y_m", "z_m"]),
    (ORIENTATION_FILE, &["pitch_deg", "roll_deg", "yaw_deg"]),
    (LENGTHS_FILE, &["l1_m", "l2_m", "l3_m", "l4_m"]),
    (FORCES_FILE, &["f_h_n", "f_v_n"]),
];

/// Whether `path` is a folder, the form in which `--data` names the authors' dataset.
pub fn is_authors_folder(path: &Path) -> bool {
    path.is_dir()
}

/// Read the authors' dataset folder `dir` (module docs) into one measurement
/// per line, `line` being the line number shared by the four files.
///
/// Errors: [`Error::Format`] for a folder that lacks one of the files, a file
/// without rows, a blank line before the end, or files with different row
/// counts (naming both); [`Error::Field`] naming file, line and column for a
/// value that is missing, extra, not a finite number, or a reference force
/// of zero norm; [`Error::Io`] when a file cannot be read.
pub fn read_authors_folder(dir: &Path) -> Result<Vec<PoseMeasurement>> {
    let missing: Vec<&str> = FILES
        .iter()
        .map(|(name, _)| *name)
        .filter(|name| !dir.join(name).is_file())
        .collect();
    if !missing.is_empty() {
        return Err(Error::Format {
            path: dir.to_path_buf(),
            message: format!(
                "a folder given as data must be the authors' dataset folder, but {} missing: it needs {} \
                 (or give a sagcal measurement file or a RecurDyn log instead of a folder)",
                match missing.len() {
                    1 => format!("{} is", missing[0]),
                    _ => format!("{} are", missing.join(", ")),
                },
                FILES.map(|(name, _)| name).join(", ")
            ),
        });
    }
    let tables = FILES
        .iter()
        .map(|(name, columns)| read_table(&dir.join(name), columns))
        .collect::<Result<Vec<_>>>()?;
    let rows = tables[0].len();
    for ((name, _), table) in FILES.iter().zip(&tables).skip(1) {
        if table.len() != rows {
            return Err(Error::Format {
                path: dir.to_path_buf(),
                message: format!(
                    "{POSITION_FILE} has {rows} rows but {name} has {}: the four files are paired line by line \
                     and must have the same number of rows",
                    table.len()
                ),
            });
        }
    }
    let forces_path = dir.join(FORCES_FILE);
    (0..rows)
        .map(|k| {
            let (pos, rot, len, force) = (&tables[0][k], &tables[1][k], &tables[2][k], &tables[3][k]);
            // Paper eq. (15): the load cell reads the norm of (f_h, f_v).
            let tension = force[0].hypot(force[1]);
            if !(tension > 0.0 && tension.is_finite()) {
                return Err(Error::Field {
                    path: forces_path.clone(),
                    row: k + 1,
                    line: Some(k + 1),
                    field: "f_h_n".into(),
                    message: format!(
                        "the reference cable's force ({}, {}) N has norm {tension} N: the tension must be positive",
                        force[0], force[1]
                    ),
                });
            }
            Ok(PoseMeasurement {
                line: k + 1,
                position_m: [pos[0], pos[1], pos[2]],
                roll_deg: rot[1],
                pitch_deg: rot[0],
                yaw_deg: rot[2],
                encoder_lengths_m: [len[0], len[1], len[2], len[3]],
                reference_tension_n: tension,
                excluded: Default::default(),
                order: None,
            })
        })
        .collect()
}

/// The rows of one header-less file of `columns.len()` numbers per line.
fn read_table(path: &Path, columns: &[&str]) -> Result<Vec<Vec<f64>>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf".as_slice()).unwrap_or(&bytes);
    let text = std::str::from_utf8(bytes).map_err(|e| format_error(path, format!("not UTF-8 text: {e}")))?;
    let lines: Vec<&str> = text.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l)).collect();
    let used = lines.iter().rposition(|l| !l.trim().is_empty()).map_or(0, |i| i + 1);
    if used == 0 {
        return Err(format_error(path, "no rows: the file is empty".into()));
    }
    lines[..used]
        .iter()
        .enumerate()
        .map(|(i, line)| parse_line(path, i + 1, line, columns))
        .collect()
}

/// The numbers of line `row` (1-based).
fn parse_line(path: &Path, row: usize, line: &str, columns: &[&str]) -> Result<Vec<f64>> {
    if line.trim().is_empty() {
        return Err(format_error(
            path,
            format!(
                "line {row} is blank: blank lines are allowed only at the end, as the files are paired line by line"
            ),
        ));
    }
    let mut fields: Vec<&str> = line.split(',').map(str::trim).collect();
    // `1,2,3,`: the authors' reader stops at the last comma.
    if fields.len() == columns.len() + 1 && fields.last().is_some_and(|f| f.is_empty()) {
        fields.pop();
    }
    // The files have no header: row `row` is line `row`.
    let field_error = |index: usize, message: String| Error::Field {
        path: path.to_path_buf(),
        row,
        line: Some(row),
        field: columns[index.min(columns.len() - 1)].to_string(),
        message,
    };
    if fields.len() != columns.len() {
        let (index, what) = if fields.len() < columns.len() {
            (fields.len(), "this value and the ones after it are missing")
        } else {
            (columns.len() - 1, "there are values after this one")
        };
        return Err(field_error(
            index,
            format!(
                "expected {} values ({}), found {}: {what}",
                columns.len(),
                columns.join(", "),
                fields.len()
            ),
        ));
    }
    fields
        .iter()
        .enumerate()
        .map(|(index, text)| match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(field_error(index, format!("not a finite number: `{text}`"))),
            Err(_) if text.is_empty() => Err(field_error(index, "empty value".into())),
            Err(_) => Err(field_error(
                index,
                format!(
                    "not a number: `{}` (the authors' files have no header line)",
                    text.escape_debug()
                ),
            )),
        })
        .collect()
}

fn format_error(path: &Path, message: String) -> Error {
    Error::Format {
        path: PathBuf::from(path),
        message,
    }
}
