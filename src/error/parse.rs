//! Why a setting given as text is not one sagcal takes ([`ParseError`]):
//! a choice by name (`--noise loud`), a number, a scale or a box.
//!
//! ```
//! use sagcal::error::ParseError;
//! use sagcal::model::sensors::NoisePreset;
//! let error = NoisePreset::parse("loud").unwrap_err();
//! assert!(matches!(error, ParseError::UnknownChoice { ref given, .. } if given == "loud"));
//! assert_eq!(error.to_string(), "unknown noise setting `loud` (paper, authors, none)");
//! // Into the crate's error, as an invalid input.
//! let error: sagcal::Error = error.into();
//! assert_eq!(error.to_string(), "invalid input: unknown noise setting `loud` (paper, authors, none)");
//! ```

/// A setting given as text that is not one sagcal takes.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ParseError {
    /// A name that is none of the choices.
    #[error("unknown {what} `{given}`{choices}")]
    UnknownChoice {
        /// What was chosen (`noise setting`, `closure`).
        what: &'static str,
        /// The text given.
        given: String,
        /// The choices as the message lists them, with what leads to them
        /// (` (paper, authors, none)`, `: level, yaw or mixed`).
        choices: String,
    },
    /// An environment variable set to none of its values.
    #[error("{variable}={given:?}: expected {choices}")]
    UnknownVariable {
        /// The variable (`SAGCAL_SIMD`).
        variable: &'static str,
        /// Its value.
        given: String,
        /// The values it takes.
        choices: &'static str,
    },
    /// Text that is not a number of the kind asked for.
    #[error("`{given}` is not a {what}")]
    NotANumber {
        /// The kind of number (`number`, `pose count`).
        what: &'static str,
        /// The text given.
        given: String,
    },
    /// A number outside the range of what it sets.
    #[error("{what} must be {expected}, got `{given}`")]
    OutOfRange {
        /// What the number sets (`robust kernel scale`).
        what: &'static str,
        /// The range (`a positive number`).
        expected: &'static str,
        /// The text given.
        given: String,
    },
    /// Bounds that are not a box `x0,x1,y0,y1,z0,z1`.
    #[error("`{given}`: a workspace is six finite numbers x0,x1,y0,y1,z0,z1 (metres) with x0 < x1, y0 < y1, z0 < z1")]
    NotABox {
        /// The bounds as given.
        given: String,
    },
}
