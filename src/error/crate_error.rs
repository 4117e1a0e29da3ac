//! [`Error`], the one error type of the crate's API, and its [`Result`].
//!
//! ```
//! let failed = sagcal::Error::InvalidInput("poses must be at least 1".into());
//! assert_eq!(failed.to_string(), "invalid input: poses must be at least 1");
//! ```

use super::calibration::CalibrationError;
use super::effect_spec::EffectSpecError;
use super::parse::ParseError;
use super::png::PngError;
use super::solver::SolverError;
use std::path::PathBuf;

/// Everything that can go wrong in sagcal, from reading a file to solving the statics.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file as a whole is not in a format sagcal understands.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// One field of one row of a data file is wrong: `m.csv: row 10 (line
    /// 12), field `f_ref_n`: ...` (rows as [`crate::model::DataRow`] counts them).
    #[error("{path}: {}, field `{field}`: {message}", row_and_line(.row, .line))]
    Field {
        /// The file (or what holds the data, `measurements` for an array).
        path: PathBuf,
        /// The row, counted from 1 among the file's data rows (an array's rows).
        row: usize,
        /// Its line in the file (from 1, the header and comments counted);
        /// `None` for data that were not read from a file.
        line: Option<usize>,
        /// The column name.
        field: String,
        /// What is wrong with the value.
        message: String,
    },
    /// A robot description is invalid (coincident anchors, unknown reference cable, ...).
    #[error("robot {path}: {message}")]
    Robot {
        /// The robot file (or `<built-in>`).
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The job was stopped on request ([`crate::cancel`]).
    #[error("cancelled")]
    Cancelled,
    /// The kineto-static problem has no solution with positive cable tensions.
    #[error("no static equilibrium: {0}")]
    NoEquilibrium(String),
    /// The solver failed; the message names the stage or computation.
    #[error("solver: {0}")]
    Solver(#[source] SolverError),
    /// A calibration gives no robot file: refused, or readings off by a unit.
    #[error(transparent)]
    Calibration(#[from] CalibrationError),
    /// A step of a calibration failed, so no robot file is written (the
    /// message is the step's own after the source's name: `m.csv: no robot
    /// file is written: invalid input: ...`).
    #[error("{source_name}: no robot file is written: {cause}")]
    NotWritten {
        /// The measurements, as the caller named them.
        source_name: String,
        /// What failed.
        #[source]
        cause: Box<Error>,
    },
    /// A figure could not be rendered to PNG.
    #[error(transparent)]
    Png(#[from] PngError),
    /// An argument given on the command line or through the API is out of range.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A setting given as text is not one sagcal takes.
    #[error("invalid input: {0}")]
    Parse(#[from] ParseError),
    /// An effect specification is not one sagcal takes.
    #[error("invalid input: {0}")]
    EffectSpec(#[from] EffectSpecError),
}

/// `row 10 (line 12)`, or `row 10` without a file.
fn row_and_line(row: &usize, line: &Option<usize>) -> String {
    match line {
        Some(line) => format!("row {row} (line {line})"),
        None => format!("row {row}"),
    }
}

/// Shorthand for `Result<T, sagcal::Error>`.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Build an [`Error::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// A solver failure; a stop on request is [`Error::Cancelled`] whichever
/// layer noticed it.
impl From<SolverError> for Error {
    fn from(error: SolverError) -> Self {
        match error {
            SolverError::Cancelled => Error::Cancelled,
            other => Error::Solver(other),
        }
    }
}
