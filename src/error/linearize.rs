//! Why one factor could not be linearised at the given values.
//!
//! The graph knows nothing of cables or platforms: it reports that a
//! factor's model is undefined there ([`Factor::evaluate`] returned `None`)
//! or that it returned a number that is not finite. The solver rejects a
//! trial step on any of them; the caller that knows the factor's physics
//! says what it means (for a catenary factor, a slack cable).
//!
//! ```
//! use sagcal::error::LinearizeError;
//! assert_eq!(LinearizeError::NonFiniteJacobian.to_string(), "non-finite Jacobian");
//! ```
//!
//! [`Factor::evaluate`]: crate::graph::Factor::evaluate

/// Why a factor could not be linearised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LinearizeError {
    /// The factor's model is undefined at these values (`evaluate` returned `None`).
    #[error("model undefined at these values")]
    Undefined,
    /// A residual component is infinite or NaN.
    #[error("non-finite residual")]
    NonFiniteResidual,
    /// A Jacobian entry is infinite or NaN.
    #[error("non-finite Jacobian")]
    NonFiniteJacobian,
}
