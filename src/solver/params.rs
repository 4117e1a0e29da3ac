//! [`LmParams`]: the Levenberg-Marquardt loop's stopping rules and damping
//! limits, with their defaults.

/// Stopping rules and damping limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmParams {
    /// Maximum number of linearisations.
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub relative_cost_tolerance: f64,
    /// Stop when the largest gradient component (`|J^T r|_inf`) falls below this.
    pub gradient_tolerance: f64,
    /// Stop when the step is this small relative to the variables' scale.
    pub relative_step_tolerance: f64,
    /// Initial damping `lambda`.
    pub initial_damping: f64,
    /// Give up when `lambda` exceeds this without an acceptable step.
    pub max_damping: f64,
    /// Re-minimise the graph's local groups after every trial step (the
    /// nonlinear elimination of the module docs); `false`: plain
    /// Levenberg-Marquardt (the groups are still eliminated in the linear solve).
    pub local_refinement: bool,
}

impl Default for LmParams {
    /// 500 iterations, cost tolerance 1e-12, gradient 1e-10, step 1e-12,
    /// lambda 1e-10 .. 1e16, local refinement on.
    fn default() -> Self {
        Self {
            max_iterations: 500,
            relative_cost_tolerance: 1e-12,
            gradient_tolerance: 1e-10,
            relative_step_tolerance: 1e-12,
            initial_damping: 1e-10,
            max_damping: 1e16,
            local_refinement: true,
        }
    }
}
