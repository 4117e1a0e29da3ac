//! The [`FactorGraph`]: variables with values, the factors between them
//! and the groups of local variables, with its cost.

use super::factor::Factor;
use super::values::{Values, VariableId};
use super::weighing::squared_norm_over;

/// A factor graph: variables with values, and factors between them.
#[derive(Default)]
pub struct FactorGraph {
    /// Current values of every variable.
    pub values: Values,
    /// The factors.
    pub factors: Vec<Box<dyn Factor>>,
    /// Groups of *local* variables (e.g. one pose and its reference tension):
    /// each group shares factors only with itself and with variables outside
    /// every group. The solver re-minimises each group with the others fixed
    /// after every step (see [`crate::solver`]); empty: no local refinement.
    pub local_groups: Vec<Vec<VariableId>>,
}

impl FactorGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add a factor.
    pub fn add(&mut self, factor: impl Factor + 'static) {
        self.factors.push(Box::new(factor));
    }

    /// Whitened residual of one factor at `values`, with the robust kernel's
    /// cost `1/2 rho(s)`; `None` if the model is undefined there.
    pub fn factor_cost(factor: &dyn Factor, values: &Values) -> Option<f64> {
        // Short residuals on the stack (every factor of the calibration).
        let rows = factor.residual_dim();
        let mut stack = [0.0; 16];
        let mut heap = Vec::new();
        let residual = if rows <= stack.len() {
            &mut stack[..rows]
        } else {
            heap.resize(rows, 0.0);
            &mut heap[..]
        };
        if !factor.evaluate_into(values, residual, None) {
            return None;
        }
        let s = squared_norm_over(residual, factor.sigmas());
        s.is_finite().then(|| 0.5 * factor.robust_kernel().rho(s))
    }

    /// Total cost `sum 1/2 rho(|r/sigma|^2)`; `None` if any factor is undefined.
    pub fn cost(&self, values: &Values) -> Option<f64> {
        self.factors.iter().map(|f| Self::factor_cost(f.as_ref(), values)).sum()
    }
}
