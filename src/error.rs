//! One error type for the whole crate.
//!
//! Every variant names *where* the problem is (file, row, field) so the CLI can
//! print it as is and exit non-zero. Library code never panics on user input.
//!
//! ```
//! use sagcal::io::measurements::{read_measurements, ReadOptions};
//! let missing = std::path::Path::new("no-such-measurements.csv");
//! let err = read_measurements(missing, &ReadOptions::default()).unwrap_err();
//! assert!(matches!(err, sagcal::Error::Io { .. }));
//! // The message starts with the file, as the CLI prints it.
//! assert!(err.to_string().starts_with("no-such-measurements.csv: "));
//! ```
//!
//! A message that names an input the user gave names it the way the caller
//! spelled it ([`FrontEnd`]): a flag of the `sagcal` command, or a keyword
//! argument of the Python package.

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
    /// One field of one row of a data file is wrong.
    #[error("{path}: row {row}, field `{field}`: {message}")]
    Field {
        /// The file.
        path: PathBuf,
        /// 1-based line number in the file (the header is line 1).
        row: usize,
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
    /// An argument given on the command line or through the API is out of range.
    #[error("invalid input: {0}")]
    InvalidInput(String),
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

/// The front end that called a job: how a message names an input the user gave.
///
/// The jobs check their settings and word their refusals in the library; the
/// command line and the Python package only say which of them is asking, and
/// the message names the flag (`--encoder-sigma-m`) or the keyword argument
/// (`encoder_sigma_m`) the user wrote.
///
/// ```
/// use sagcal::error::FrontEnd;
/// assert_eq!(FrontEnd::Cli.option("encoder_sigma_m"), "--encoder-sigma-m");
/// assert_eq!(FrontEnd::Python.option("encoder_sigma_m"), "encoder_sigma_m");
/// assert_eq!(FrontEnd::Cli.switch("accept_inconsistent"), "--accept-inconsistent");
/// assert_eq!(FrontEnd::Python.switch("accept_inconsistent"), "accept_inconsistent=True");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontEnd {
    /// The `sagcal` command: options are flags, `--encoder-sigma-m`.
    Cli,
    /// The Python package: options are keyword arguments, `encoder_sigma_m`.
    Python,
}

impl FrontEnd {
    /// The option whose Python keyword is `keyword` (snake case), as this
    /// front end spells it: `--encoder-sigma-m` or `encoder_sigma_m`.
    pub fn option(self, keyword: &str) -> String {
        match self {
            FrontEnd::Cli => format!("--{}", keyword.replace('_', "-")),
            FrontEnd::Python => keyword.to_string(),
        }
    }

    /// The on/off option `keyword`, turned on: `--accept-inconsistent` or
    /// `accept_inconsistent=True`.
    pub fn switch(self, keyword: &str) -> String {
        match self {
            FrontEnd::Cli => self.option(keyword),
            FrontEnd::Python => format!("{keyword}=True"),
        }
    }
}
