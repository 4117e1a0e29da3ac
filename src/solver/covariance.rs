//! Covariance of selected variables from the undamped information matrix.
//!
//! At the solution, `Sigma = H^-1` with `H = J^T W J` undamped (Gauss-Newton
//! approximation of the Fisher information). The marginal covariance of a
//! subset of variables is the matching block of `H^-1`, obtained by solving
//! `H X = E` for their unit columns with the sparse Cholesky. If `H` is
//! singular the problem is rank deficient: a dense eigen-analysis names the
//! unobservable directions (eigenvectors with eigenvalue below `1e-10` of the
//! largest) instead of printing a meaningless inverse.

use crate::error::SolverError;
use nalgebra::{DMatrix, SymmetricEigen};
use serde::Serialize;

use super::linear_system::LinearSystem;
use super::linearization::linearize;
use super::system_cache::SystemCache;
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
///
/// 1. `H` (undamped) is factored by the sparse Cholesky; if that fails, `H`
///    is singular and, for problems small enough to decompose densely, its
///    null space is reported.
/// 2. Otherwise the selected block `Sigma_s` of `H^-1` is formed. Its
///    eigen-decomposition tells whether the selected parameters are determined:
///    an eigenvalue above `1e8` (a 10 km standard deviation in metres) or
///    `1e14` times the smallest one marks a direction the data do not fix
///    (rounding noise made `H` look positive definite), reported with its
///    components in the selected variables.
pub fn marginal_covariance(graph: &FactorGraph, selected: &[VariableId]) -> Result<Covariance, SolverError> {
    marginal_covariance_cached(graph, selected, &mut SystemCache::default())
}

/// [`marginal_covariance`] with the linear system of `cache` when it was
/// built for a graph of the same structure (see [`SystemCache`]): the same
/// result, bit for bit.
pub fn marginal_covariance_cached(
    graph: &FactorGraph,
    selected: &[VariableId],
    cache: &mut SystemCache,
) -> Result<Covariance, SolverError> {
    let system = cache.system(&graph.values, &graph.factors, &graph.local_groups)?;
    let hessian = linearize(graph, &graph.values, system)
        .map_err(|e| e.during("covariance at the solution"))?
        .hessian;
    let mut columns = Vec::new();
    let mut labels = Vec::new();
    for &id in selected {
        let offset = system.offsets[id.0].ok_or_else(|| SolverError::Fixed(graph.values.variable(id).name.clone()))?;
        for c in 0..graph.values.tangent_dim(id) {
            columns.push(offset + c);
            labels.push((graph.values.variable(id).name.clone(), c));
        }
    }
    let zero_damping = vec![0.0; system.dim];
    if !system.factorize(&hessian, &zero_damping) {
        return Ok(Covariance::RankDeficient(null_space(graph, system, &hessian)));
    }
    let mut covariance = DMatrix::zeros(columns.len(), columns.len());
    // Columns of globals kept by the block elimination: their block of
    // H^-1 is the inverse of the reduced system alone.
    let reduced = system.eliminated_globals().filter(|&g| columns.iter().all(|&c| c < g));
    for (k, &col) in columns.iter().enumerate() {
        let mut unit = vec![0.0; reduced.unwrap_or(system.dim)];
        unit[col] = 1.0;
        let solved = match reduced {
            Some(_) => system.solve_globals(&unit),
            None => system.solve_factored(&unit),
        };
        let Some(x) = solved else {
            return Ok(Covariance::RankDeficient(null_space(graph, system, &hessian)));
        };
        for (m, &row) in columns.iter().enumerate() {
            covariance[(m, k)] = x[row];
        }
    }
    let symmetric = (&covariance + covariance.transpose()) * 0.5;
    let eigen = SymmetricEigen::new(symmetric.clone());
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
    let smallest = eigen.eigenvalues.iter().fold(f64::INFINITY, |m, v| m.min(*v));
    let mut directions = Vec::new();
    for (i, &value) in eigen.eigenvalues.iter().enumerate() {
        if !value.is_finite()
            || value > 1e8
            || (smallest > 0.0 && value > 1e14 * smallest)
            || smallest <= 0.0 && value == largest
        {
            let vector = eigen.eigenvectors.column(i);
            let mut components: Vec<(String, usize, f64)> = labels
                .iter()
                .zip(vector.iter())
                .filter(|(_, w)| w.abs() > 0.05)
                .map(|((name, c), w)| (name.clone(), *c, *w))
                .collect();
            components.sort_by(|a, b| b.2.abs().total_cmp(&a.2.abs()));
            directions.push(UnobservableDirection {
                relative_eigenvalue: if value > 0.0 { smallest / value } else { 0.0 },
                components,
            });
        }
    }
    if directions.is_empty() {
        Ok(Covariance::Full(symmetric))
    } else {
        Ok(Covariance::RankDeficient(directions))
    }
}

/// Null space of a singular `H` by dense eigen-decomposition (up to 4000 unknowns).
fn null_space(graph: &FactorGraph, system: &LinearSystem, hessian: &[f64]) -> Vec<UnobservableDirection> {
    if system.dim > 4000 {
        return Vec::new();
    }
    let eigen = SymmetricEigen::new(system.dense(hessian));
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    eigen
        .eigenvalues
        .iter()
        .enumerate()
        .filter(|(_, &value)| value <= 1e-14 * largest)
        .map(|(i, &value)| describe(graph, system, eigen.eigenvectors.column(i).as_slice(), value / largest))
        .collect()
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
