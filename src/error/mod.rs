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

mod calibration;
mod crate_error;
mod effect_spec;
mod front_end;
mod linearize;
mod parse;
mod png;
mod solver;

pub use calibration::CalibrationError;
pub use crate_error::{Error, Result};
pub use effect_spec::EffectSpecError;
pub use front_end::FrontEnd;
pub use linearize::LinearizeError;
pub use parse::ParseError;
pub use png::PngError;
pub use solver::SolverError;
