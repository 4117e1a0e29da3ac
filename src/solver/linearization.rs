//! Linearisation of the whole graph: every factor whitened, reweighted and
//! added into `H = J^T J` and `g = J^T r` in the pattern of a
//! [`LinearSystem`] ([`Linearization`]), with the [`Workspace`] the
//! iterations reuse. Shared by the Levenberg-Marquardt loop, the covariance
//! and the redundancy numbers.

use super::dense::fill_zeros;
use super::linear_system::LinearSystem;
use crate::error::SolverError;
use crate::graph::{FactorGraph, LinearizationBuffers, Values};

/// Whitened, robust-reweighted linearisation of the whole graph.
pub(crate) struct Linearization {
    /// `H = J^T J` in the pattern of the [`LinearSystem`].
    pub hessian: Vec<f64>,
    /// `g = J^T r`.
    pub gradient: Vec<f64>,
    /// `sum 1/2 rho(|r / sigma|^2)`.
    pub cost: f64,
}

/// Linearise every factor at `values`.
pub(crate) fn linearize(
    graph: &FactorGraph,
    values: &Values,
    system: &LinearSystem,
) -> Result<Linearization, SolverError> {
    linearize_with(graph, values, system, &mut Workspace::default())
}

/// What the iterations reuse instead of allocating: the factors' Jacobian
/// buffers, the trial point's values and a spent linearisation's arrays.
#[derive(Default)]
pub(super) struct Workspace {
    buffers: LinearizationBuffers,
    /// Scratch of [`LinearSystem::accumulate`].
    rows_buffer: Vec<f64>,
    pub(super) candidate: Values,
    pub(super) spare: Option<Linearization>,
}

/// [`linearize`] into the arrays of `work.spare` (if any) with `work`'s buffers.
pub(super) fn linearize_with(
    graph: &FactorGraph,
    values: &Values,
    system: &LinearSystem,
    work: &mut Workspace,
) -> Result<Linearization, SolverError> {
    let (mut hessian, mut gradient) = match work.spare.take() {
        Some(spare) => (spare.hessian, spare.gradient),
        None => (Vec::new(), Vec::new()),
    };
    fill_zeros(&mut hessian, system.zero_hessian_len());
    gradient.clear();
    gradient.resize(system.dim, 0.0);
    let mut cost = 0.0;
    let Workspace {
        buffers, rows_buffer, ..
    } = work;
    for (index, factor) in graph.factors.iter().enumerate() {
        let variables = factor.variables();
        let linearized = buffers.linearize_at(index, factor.as_ref(), values).map_err(|what| {
            let names: Vec<&str> = variables.iter().map(|&v| values.variable(v).name.as_str()).collect();
            SolverError::Factor {
                kind: factor.kind(),
                variables: names.join(", "),
                source: what,
            }
        })?;
        cost += linearized.cost;
        if linearized.is_zero {
            // Adding exact zeros would change nothing (an inactive tension guard).
            continue;
        }
        system.accumulate(
            index,
            &linearized.jacobians,
            &linearized.residual,
            &mut hessian,
            &mut gradient,
            rows_buffer,
        );
    }
    Ok(Linearization {
        hessian,
        gradient,
        cost,
    })
}
