//! What a solve reports: its [`SolveSummary`], one [`IterationSummary`] per
//! linearisation, and the [`Termination`] that ended it.

use serde::Serialize;

/// Why the solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The relative cost decrease fell below the tolerance.
    CostConverged,
    /// The gradient vanished.
    GradientConverged,
    /// The step became negligible.
    StepConverged,
    /// No damping produced a lower cost (a local minimum at working precision).
    DampingExhausted,
    /// The iteration budget ran out.
    MaxIterations,
    /// The model is undefined at the starting values (e.g. a slack cable).
    InvalidStart,
}

impl Termination {
    /// Whether the solver stopped at a minimum (not for lack of iterations or a bad start).
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::CostConverged
                | Termination::GradientConverged
                | Termination::StepConverged
                | Termination::DampingExhausted
        )
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = match self {
            Termination::CostConverged => "cost converged",
            Termination::GradientConverged => "gradient converged",
            Termination::StepConverged => "step converged",
            Termination::DampingExhausted => "no further decrease at any damping",
            Termination::MaxIterations => "iteration limit reached",
            Termination::InvalidStart => "model undefined at the initial values",
        };
        f.write_str(text)
    }
}

/// One linearisation of the solve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IterationSummary {
    /// 1-based iteration number.
    pub iteration: usize,
    /// Cost after this iteration.
    pub cost: f64,
    /// Gain ratio of the accepted step (NaN if none was accepted).
    pub gain_ratio: f64,
    /// Damping used by the accepted step.
    pub damping: f64,
    /// Norm of the accepted step (tangent space).
    pub step_norm: f64,
    /// Damping trials in this iteration (rejected steps and failed factorisations included).
    pub trials: usize,
}

/// The outcome of a solve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolveSummary {
    /// Cost at the start.
    pub initial_cost: f64,
    /// Cost at the end.
    pub final_cost: f64,
    /// Number of linearisations.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Per-iteration history.
    pub history: Vec<IterationSummary>,
}
