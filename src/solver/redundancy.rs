//! Redundancy numbers of the residual rows at a least-squares solution, for
//! Baarda's data snooping (`crate::calib::gross_errors`).
//!
//! With `A` the whitened Jacobian (rows `a_i = J_i / sigma_i`) and
//! `H = A^T A` the undamped information matrix, the hat matrix is
//! `A H^-1 A^T`; its diagonal `h_i = a_i^T H^-1 a_i` is the leverage of row
//! `i` and `r_i = 1 - h_i` its redundancy number (Baarda 1968; Förstner
//! 1987): the share of an error in reading `i` that shows in its own
//! residual. The normalised residual of a reading is then
//! `w_i = e_i / (sigma_i sqrt(r_i))`, standard normal when the model holds.
//! The `r_i` sum to the redundancy `n - u` of the adjustment.

use crate::error::SolverError;
use nalgebra::DMatrix;

use super::linear_system::LinearSystem;
use super::linearization::linearize;
use crate::graph::{Factor, FactorGraph};

/// Per factor (graph order) whose kind is in `kinds`, the redundancy number
/// of each residual row (`None` for the other factors), at the graph's values.
/// Each row costs one solve with the factored information matrix, over the
/// blocks the row touches.
pub fn redundancy_numbers(graph: &FactorGraph, kinds: &[&str]) -> Result<Vec<Option<Vec<f64>>>, SolverError> {
    let mut system = factored_information(graph, "redundancy numbers")?;
    let mut all = Vec::with_capacity(graph.factors.len());
    for factor in &graph.factors {
        if !kinds.contains(&factor.kind()) {
            all.push(None);
            continue;
        }
        let (_, rows) = whitened_rows(graph, factor.as_ref(), &system, "redundancy numbers")?;
        let mut numbers = Vec::with_capacity(rows.len());
        for a in &rows {
            let leverage = system.inverse_quadratic_form(a).ok_or(SolverError::SolveFailed {
                what: "redundancy numbers",
            })?;
            numbers.push((1.0 - leverage).clamp(0.0, 1.0));
        }
        all.push(Some(numbers));
    }
    Ok(all)
}

/// The undamped information matrix `H = A^T A` at the graph's values,
/// factored (`what` names the caller in errors). A rank-deficient fit (a
/// direction the data do not fix) has no inverse: the smallest damping that
/// factors stands in for it, which leaves every quadratic form of a row the
/// data do control unchanged to that order.
pub(super) fn factored_information(graph: &FactorGraph, what: &str) -> Result<LinearSystem, SolverError> {
    let mut system = LinearSystem::new(&graph.values, &graph.factors, &graph.local_groups)?;
    let hessian = linearize(graph, &graph.values, &system)
        .map_err(|e| e.during(format!("{what} at the solution")))?
        .hessian;
    let diagonal = system.diagonal(&hessian);
    let factored = [0.0, 1e-12, 1e-9, 1e-6].into_iter().any(|relative| {
        let damping: Vec<f64> = diagonal.iter().map(|d| relative * d.abs().max(1e-300)).collect();
        system.factorize(&hessian, &damping)
    });
    if !factored {
        return Err(SolverError::Singular { what: what.to_string() });
    }
    Ok(system)
}

/// One factor at the graph's values: its whitened residual `r_i / sigma_i`
/// and each row's whitened Jacobian `a_i = J_i / sigma_i`, dense over the
/// system's unknowns (`what` names the caller in errors).
pub(super) fn whitened_rows(
    graph: &FactorGraph,
    factor: &dyn Factor,
    system: &LinearSystem,
    what: &str,
) -> Result<(Vec<f64>, Vec<Vec<f64>>), SolverError> {
    let rows = factor.residual_dim();
    let mut blocks: Vec<DMatrix<f64>> = factor
        .variables()
        .iter()
        .map(|&id| DMatrix::zeros(rows, graph.values.tangent_dim(id)))
        .collect();
    let residual =
        factor
            .evaluate(&graph.values, Some(&mut blocks))
            .ok_or_else(|| SolverError::UndefinedAtSolution {
                what: what.to_string(),
                kind: factor.kind(),
            })?;
    let sigmas = factor.sigmas();
    let whitened = (0..rows).map(|row| residual[row] / sigmas[row]).collect();
    let jacobian = (0..rows)
        .map(|row| {
            let mut a = vec![0.0; system.dim];
            for (block, &id) in blocks.iter().zip(factor.variables()) {
                if let Some(offset) = system.offsets[id.0] {
                    for c in 0..block.ncols() {
                        a[offset + c] = block[(row, c)] / sigmas[row];
                    }
                }
            }
            a
        })
        .collect();
    Ok((whitened, jacobian))
}

#[cfg(test)]
mod tests {
    use nalgebra::DVector;

    use super::*;
    use crate::graph::{Factor, Values, VariableId, VariableValue};

    /// A direct reading of a scalar variable with standard deviation `sigma`.
    struct Reading {
        variables: [VariableId; 1],
        value: f64,
        noise: crate::graph::Noise,
    }

    impl Factor for Reading {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn residual_dim(&self) -> usize {
            1
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            if let Some(blocks) = jacobians {
                blocks[0][(0, 0)] = 1.0;
            }
            Some(DVector::from_element(
                1,
                values.vector(self.variables[0])[0] - self.value,
            ))
        }
        fn noise(&self) -> &crate::graph::Noise {
            &self.noise
        }
        fn kind(&self) -> &'static str {
            "reading"
        }
    }

    /// `n` readings of one quantity with weights `1/sigma_i^2`: the leverage of
    /// reading `i` is its weight over the sum of weights (the weighted mean),
    /// and the redundancy numbers sum to `n - 1`.
    #[test]
    fn redundancy_of_a_weighted_mean() {
        let mut graph = FactorGraph::new();
        let x = graph
            .values
            .insert("x", VariableValue::Vector(DVector::from_element(1, 0.3)));
        let sigmas = [1.0, 2.0, 0.5, 1.0];
        for (k, s) in sigmas.iter().enumerate() {
            graph.add(Reading {
                variables: [x],
                value: k as f64,
                noise: crate::graph::Noise::gaussian(DVector::from_element(1, *s)),
            });
        }
        let numbers = redundancy_numbers(&graph, &["reading"]).unwrap();
        let total_weight: f64 = sigmas.iter().map(|s| 1.0 / (s * s)).sum();
        let mut sum = 0.0;
        for (s, r) in sigmas.iter().zip(&numbers) {
            let r = r.as_ref().unwrap()[0];
            assert!((r - (1.0 - 1.0 / (s * s) / total_weight)).abs() < 1e-12, "{r}");
            sum += r;
        }
        assert!((sum - 3.0).abs() < 1e-12);
    }
}
