//! Why a calibration job gives no robot file ([`crate::calib::calibrate_job`]).
//!
//! Apart from the files it reads, a calibration ends without a robot file
//! for one of these: the fit fails its own consistency tests and the caller
//! did not accept it ([`CalibrationError::Refused`]), or a reading is off by
//! a unit that no fit can mend ([`CalibrationError::UnitMistakes`]). A step
//! of the calibration that fails is [`Error::NotWritten`], with the step's
//! error as its cause.
//!
//! [`Error::NotWritten`]: crate::Error::NotWritten
//!
//! ```
//! use sagcal::calib::refusal;
//! use sagcal::error::{CalibrationError, FrontEnd};
//! let refused = refusal("m.csv", "the load cell fails", FrontEnd::Cli);
//! assert!(matches!(refused, sagcal::Error::Calibration(CalibrationError::Refused { .. })));
//! // A refusal, not an input error: the message says so and nothing else.
//! assert!(refused.to_string().starts_with("m.csv: the calibration fails its own consistency tests"));
//! ```

/// A calibration that gives no robot file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrationError {
    /// The fit fails its own consistency tests and was not accepted anyway.
    #[error(
        "{source_name}: the calibration fails its own consistency tests, so no robot file is written \
         ({accept} {anyway}): {reason}"
    )]
    Refused {
        /// The measurements, as the caller named them.
        source_name: String,
        /// How the caller accepts it anyway (`--accept-inconsistent`, `accept_inconsistent=True`).
        accept: String,
        /// What accepting does (`writes it anyway`, `returns it anyway`).
        anyway: &'static str,
        /// Which sensors fail, and how.
        reason: String,
    },
    /// Readings off by a unit (millimetres for metres, ...): the data must be fixed.
    #[error("{}; fix the data (or the robot file) and calibrate again", .mistakes.join("; "))]
    UnitMistakes {
        /// One message per mistake found.
        mistakes: Vec<String>,
    },
}
