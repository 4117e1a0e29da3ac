//! Why a solve, a covariance or a test statistic could not be computed.
//!
//! The solver's own failures, typed, so that a caller can tell a graph with
//! nothing to solve from a factor that cannot be linearised at the solution
//! or a stop on request. Each carries its cause ([`std::error::Error::source`]).
//!
//! ```
//! use sagcal::error::{LinearizeError, SolverError};
//! let failed = SolverError::During {
//!     what: "covariance at the solution".into(),
//!     source: Box::new(SolverError::Factor {
//!         kind: "reading",
//!         variables: "x".into(),
//!         source: LinearizeError::NonFiniteResidual,
//!     }),
//! };
//! assert_eq!(failed.to_string(), "covariance at the solution: reading factor on [x]: non-finite residual");
//! assert!(std::error::Error::source(&failed).is_some());
//! ```

use super::linearize::LinearizeError;

/// A failure of the solver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SolverError {
    /// Every variable of the graph is held fixed.
    #[error("every variable is fixed: nothing to solve")]
    NothingToSolve,
    /// A factor names one variable in two of its slots.
    #[error(
        "factor {index} ({kind}) names variable '{variable}' twice (slot {slot}): a factor's variables must be distinct"
    )]
    RepeatedVariable {
        /// The factor's index in the graph.
        index: usize,
        /// Its kind ([`crate::graph::Factor::kind`]).
        kind: &'static str,
        /// The variable's name.
        variable: String,
        /// The second slot that names it.
        slot: usize,
    },
    /// faer's symbolic analysis of the pattern failed.
    #[error("symbolic Cholesky failed: {0}")]
    SymbolicCholesky(String),
    /// The Cholesky workspace could not be allocated.
    #[error("out of memory for the Cholesky workspace")]
    OutOfMemory,
    /// One factor cannot be linearised at the values asked for.
    #[error("{kind} factor on [{variables}]: {source}")]
    Factor {
        /// The factor's kind.
        kind: &'static str,
        /// Its variables' names, comma-separated.
        variables: String,
        /// Why.
        #[source]
        source: LinearizeError,
    },
    /// A failure while computing `what` (a stage of a calibration, a
    /// covariance at the solution, ...).
    #[error("{what}: {source}")]
    During {
        /// What was being computed (`covariance at the solution`, `rigid stage`, ...).
        what: String,
        /// Why.
        #[source]
        source: Box<SolverError>,
    },
    /// The information matrix has no inverse, even with the smallest damping tried.
    #[error("{what}: the information matrix is singular")]
    Singular {
        /// What it was factored for.
        what: String,
    },
    /// A factor's model is undefined at the solution.
    #[error("{what}: a `{kind}` factor is undefined at the solution")]
    UndefinedAtSolution {
        /// What the rows were for.
        what: String,
        /// The factor's kind.
        kind: &'static str,
    },
    /// Solving with the factored information matrix failed.
    #[error("{what}: the solve with the information matrix failed")]
    SolveFailed {
        /// What the solve was for.
        what: &'static str,
    },
    /// A variable asked for is held fixed: it has no covariance.
    #[error("{0} is fixed")]
    Fixed(String),
    /// A score direction has another number of weights than its factor has rows.
    #[error("{what}: a direction has {weights} weights for a factor of {rows} rows")]
    DirectionShape {
        /// What the score was for.
        what: &'static str,
        /// The direction's weights.
        weights: usize,
        /// The factor's rows.
        rows: usize,
    },
    /// The job was stopped on request ([`crate::cancel`]).
    #[error("cancelled")]
    Cancelled,
}

impl SolverError {
    /// This failure, as the cause of a failure of `what` (a stage, a
    /// covariance): the message reads `what: cause`. A stop on request
    /// stays [`SolverError::Cancelled`].
    pub fn during(self, what: impl Into<String>) -> Self {
        if matches!(self, SolverError::Cancelled) {
            return self;
        }
        SolverError::During {
            what: what.into(),
            source: Box::new(self),
        }
    }
}
