//! Why an effect specification `NAME:PARAM=VALUE[,PARAM=VALUE...]` is not
//! one sagcal takes ([`EffectSpecError`]).
//!
//! ```
//! use sagcal::error::EffectSpecError;
//! use sagcal::model::effects::Effects;
//! let error = Effects::from_specs(&["elastic:ea_n=-1"]).unwrap_err();
//! assert!(matches!(error, EffectSpecError::OutOfRange { ref key, value, .. } if key == "ea_n" && value == -1.0));
//! assert_eq!(error.to_string(), "effect `elastic`: parameter `ea_n` (axial stiffness EA, N) must be > 0, got -1");
//! ```

/// An effect specification sagcal does not take; each message names the
/// effect and the parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EffectSpecError {
    /// Not of the form `NAME:PARAM=VALUE`.
    #[error("effect `{spec}`: expected NAME:PARAM=VALUE[,PARAM=VALUE...] (effects: {effects})")]
    Malformed {
        /// The specification.
        spec: String,
        /// The effects sagcal knows, comma-separated.
        effects: &'static str,
    },
    /// An effect sagcal does not know.
    #[error("unknown effect `{name}` (effects: {effects})")]
    UnknownEffect {
        /// The name given.
        name: String,
        /// The effects sagcal knows, comma-separated.
        effects: String,
    },
    /// `NAME:` with nothing after it.
    #[error("effect `{name}`: no parameters given (parameters: {parameters})")]
    NoParameters {
        /// The effect.
        name: String,
        /// Its parameters, comma-separated.
        parameters: String,
    },
    /// `PARAM` without `=VALUE`.
    #[error("effect `{name}`: parameter `{param}` has no `=VALUE`")]
    NoValue {
        /// The effect.
        name: String,
        /// The parameter as given.
        param: String,
    },
    /// A parameter the effect does not have.
    #[error("effect `{name}`: unknown parameter `{key}` (parameters: {parameters})")]
    UnknownParameter {
        /// The effect.
        name: String,
        /// The parameter given.
        key: String,
        /// The effect's parameters, comma-separated.
        parameters: String,
    },
    /// A value that is not a number.
    #[error("effect `{name}`: parameter `{key}`: `{value}` is not a number")]
    NotANumber {
        /// The effect.
        name: String,
        /// The parameter.
        key: String,
        /// The text given.
        value: String,
    },
    /// An infinite or NaN value.
    #[error("effect `{name}`: parameter `{key}` must be finite, got {value}")]
    NotFinite {
        /// The effect.
        name: String,
        /// The parameter.
        key: String,
        /// The value.
        value: f64,
    },
    /// A value outside the parameter's physical range.
    #[error("effect `{name}`: parameter `{key}` ({meaning}) must be {range}, got {value}")]
    OutOfRange {
        /// The effect.
        name: String,
        /// The parameter.
        key: String,
        /// What the parameter is, with its unit (`axial stiffness EA, N`).
        meaning: &'static str,
        /// Its range (`> 0`, `>= 0 and < 1`).
        range: &'static str,
        /// The value.
        value: f64,
    },
}
