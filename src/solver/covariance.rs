//! Covariance of selected variables from the undamped information matrix.
//!
//! At the solution, `Sigma = H^-1` with `H = J^T W J` undamped (Gauss-Newton
//! approximation of the Fisher information). The marginal covariance of a
//! subset of variables is the matching block of `H^-1`, obtained by solving
//! `H X = E` for their unit columns with the sparse Cholesky. If `H` is
//! singular the problem is rank deficient: a dense eigen-analysis names the
//! unobservable directions (eigenvectors with eigenvalue below `1e-10` of the
//! largest) instead of printing a meaningless inverse.

use nalgebra::{DMatrix, SymmetricEigen};
use serde::Serialize;

use super::{linearize, LinearSystem};
use crate::graph::{FactorGraph, VariableId};

/// A direction in parameter space the data cannot determine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnobservableDirection {
    /// Eigenvalue of `H` along it, relative to the largest.
    pub relative_eigenvalue: f64,
    /// The largest components: `(variable name, tangent coordinate, weight)`, by decreasing |weight|.
    pub components: Vec<(String, usize, f64)>,
}

/// The result of a covariance query.
#[derive(Debug, Clone, PartialEq)]
pub enum Covariance {
    /// The joint covariance of the selected variables, in selection order.
    Full(DMatrix<f64>),
    /// `H` is singular: these directions are not observable.
    RankDeficient(Vec<UnobservableDirection>),
}

/// Marginal covariance of `selected` (all must be free) at the graph's current values.
pub fn marginal_covariance(graph: &FactorGraph, selected: &[VariableId]) -> Result<Covariance, String> {
    let system = LinearSystem::new(&graph.values, &graph.factors)?;
    let (hessian, _, _) = linearize(graph, &graph.values, &system)
        .ok_or_else(|| "the model is undefined at the solution".to_string())?;
    let columns: Vec<usize> = selected
        .iter()
        .flat_map(|&id| {
            let offset = system.offsets[id.0];
            let dim = graph.values.tangent_dim(id);
            offset.into_iter().flat_map(move |o| o..o + dim)
        })
        .collect();
    let dense_limit = 4000;
    // A tiny relative floor keeps the Cholesky from succeeding on a numerically singular H.
    let max_diagonal = system.diagonal(&hessian).iter().fold(0.0f64, |m, d| m.max(*d));
    let zero_damping = vec![0.0; system.dim];
    let mut covariance = DMatrix::zeros(columns.len(), columns.len());
    let mut factored = true;
    for (k, &col) in columns.iter().enumerate() {
        let mut unit = vec![0.0; system.dim];
        unit[col] = 1.0;
        match system.solve(&hessian, &zero_damping, &unit) {
            Some(x) => {
                for (m, &row) in columns.iter().enumerate() {
                    covariance[(m, k)] = x[row];
                }
            }
            None => {
                factored = false;
                break;
            }
        }
    }
    // Even when the Cholesky succeeds, an eigenvalue ratio near 1e-16 means garbage: check small problems.
    if system.dim <= dense_limit {
        let dense = system.dense(&hessian);
        let eigen = SymmetricEigen::new(dense);
        let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut directions = Vec::new();
        for (i, &value) in eigen.eigenvalues.iter().enumerate() {
            if value <= 1e-10 * largest {
                directions.push(describe(graph, &system, eigen.eigenvectors.column(i).as_slice(), value / largest));
            }
        }
        if !directions.is_empty() {
            return Ok(Covariance::RankDeficient(directions));
        }
    }
    if !factored || max_diagonal == 0.0 {
        return Ok(Covariance::RankDeficient(Vec::new()));
    }
    Ok(Covariance::Full(covariance))
}

fn describe(graph: &FactorGraph, system: &LinearSystem, vector: &[f64], relative: f64) -> UnobservableDirection {
    let mut components = Vec::new();
    for (id, variable) in graph.values.iter() {
        if let Some(offset) = system.offsets[id.0] {
            for c in 0..variable.value.tangent_dim() {
                let w = vector[offset + c];
                if w.abs() > 0.05 {
                    components.push((variable.name.clone(), c, w));
                }
            }
        }
    }
    components.sort_by(|a, b| b.2.abs().total_cmp(&a.2.abs()));
    components.truncate(12);
    UnobservableDirection {
        relative_eigenvalue: relative,
        components,
    }
}
