//! The Levenberg-Marquardt loop of the module docs: [`optimize`] and
//! [`optimize_cached`], the damped trial steps (`damped_step`), the
//! retraction of a step and Nielsen's damping (`Damping`).

use super::linear_system::LinearSystem;
use super::linearization::{linearize_with, Linearization, Workspace};
use super::local::LocalGroups;
use super::params::LmParams;
use super::summary::{IterationSummary, SolveSummary, Termination};
use super::system_cache::SystemCache;
use crate::error::SolverError;
use crate::graph::{FactorGraph, Values};

/// `next` = `values` with a tangent step applied to every free variable.
fn retract_all(values: &Values, system: &LinearSystem, step: &[f64], next: &mut Values) {
    next.copy_from(values);
    for (id, variable) in values.iter() {
        if let Some(offset) = system.offsets[id.0] {
            let dim = variable.value.tangent_dim();
            next.value_mut(id).retract_in_place(&step[offset..offset + dim]);
        }
    }
}

/// Minimise the graph's cost from its current values; the values are updated in place.
pub fn optimize(graph: &mut FactorGraph, params: &LmParams) -> Result<SolveSummary, SolverError> {
    optimize_cached(graph, params, &mut SystemCache::default())
}

/// [`optimize`] with the linear system taken from `cache` when it was built
/// for a graph of the same structure (and kept there for the next solve):
/// the same result, bit for bit, without a second pattern analysis.
pub fn optimize_cached(
    graph: &mut FactorGraph,
    params: &LmParams,
    cache: &mut SystemCache,
) -> Result<SolveSummary, SolverError> {
    let system = cache.system(&graph.values, &graph.factors, &graph.local_groups)?;
    let groups = if params.local_refinement {
        LocalGroups::new(graph)
    } else {
        LocalGroups::none()
    };
    let mut values = graph.values.clone();
    if !groups.is_empty() {
        groups.refine(graph, &mut values);
    }
    let mut work = Workspace::default();
    let Ok(mut linearization) = linearize_with(graph, &values, system, &mut work) else {
        return Ok(SolveSummary {
            initial_cost: f64::NAN,
            final_cost: f64::NAN,
            iterations: 0,
            termination: Termination::InvalidStart,
            history: Vec::new(),
        });
    };
    let initial_cost = linearization.cost;
    let mut damping = Damping {
        value: params.initial_damping,
        nu: 2.0,
        max: params.max_damping,
    };
    let mut history = Vec::new();
    let mut termination = Termination::MaxIterations;
    for iteration in 1..=params.max_iterations {
        crate::steps::tick();
        if crate::cancel::requested() {
            return Err(SolverError::Cancelled);
        }
        let cost = linearization.cost;
        let gradient = &linearization.gradient;
        if gradient.iter().fold(0.0f64, |m, g| m.max(g.abs())) < params.gradient_tolerance {
            termination = Termination::GradientConverged;
            break;
        }
        let (accepted, trials) = damped_step(graph, &groups, system, &values, &linearization, &mut damping, &mut work);
        let Some(Accepted {
            step,
            linearization: next,
            gain_ratio,
        }) = accepted
        else {
            termination = Termination::DampingExhausted;
            history.push(IterationSummary {
                iteration,
                cost,
                gain_ratio: f64::NAN,
                damping: damping.value,
                step_norm: 0.0,
                trials,
            });
            break;
        };
        let new_cost = next.cost;
        let step_norm = step.iter().map(|x| x * x).sum::<f64>().sqrt();
        let relative_decrease = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
        let step_scale = 1.0 + variables_scale(&values);
        history.push(IterationSummary {
            iteration,
            cost: new_cost,
            gain_ratio,
            damping: damping.value,
            step_norm,
            trials,
        });
        // The trial point (in `work.candidate`) becomes the current one.
        std::mem::swap(&mut values, &mut work.candidate);
        work.spare = Some(std::mem::replace(&mut linearization, next));
        if relative_decrease < params.relative_cost_tolerance {
            termination = Termination::CostConverged;
            break;
        }
        if step_norm < params.relative_step_tolerance * step_scale {
            termination = Termination::StepConverged;
            break;
        }
    }
    let final_cost = linearization.cost;
    graph.values = values;
    Ok(SolveSummary {
        initial_cost,
        final_cost,
        iterations: history.len(),
        termination,
        history,
    })
}

/// Nielsen's damping (Madsen, Nielsen & Tingleff, *Methods for Non-Linear
/// Least Squares Problems*, 2004, eq. 2.21): `lambda`, and the factor `nu` it
/// grows by after each rejected step.
struct Damping {
    value: f64,
    nu: f64,
    /// The damping past which no further trial is made ([`LmParams::max_damping`]).
    max: f64,
}

impl Damping {
    /// A rejected step: `lambda *= nu`, `nu *= 2`.
    fn reject(&mut self) {
        self.value *= self.nu;
        self.nu *= 2.0;
    }

    /// An accepted step of gain ratio `rho`: `lambda *= max(1/3, 1 - (2 rho - 1)^3)`.
    fn accept(&mut self, gain_ratio: f64) {
        self.value *= (1.0 / 3.0f64).max(1.0 - (2.0 * gain_ratio - 1.0).powi(3));
        self.value = self.value.max(1e-15);
        self.nu = 2.0;
    }
}

/// A step that lowered the cost, with the linearisation at its end point
/// (the next iteration's; the end point itself is left in `Workspace::candidate`).
struct Accepted {
    step: Vec<f64>,
    linearization: Linearization,
    gain_ratio: f64,
}

/// Solve the damped normal equations at `linearization`, raising the damping
/// until a step lowers the cost (after the per-pose refinement) or the damping
/// passes its limit; returns the accepted step, if any, and the trials made.
fn damped_step(
    graph: &FactorGraph,
    groups: &LocalGroups,
    system: &mut LinearSystem,
    values: &Values,
    linearization: &Linearization,
    damping: &mut Damping,
    work: &mut Workspace,
) -> (Option<Accepted>, usize) {
    let cost = linearization.cost;
    let gradient = &linearization.gradient;
    let diagonal: Vec<f64> = system
        .diagonal(&linearization.hessian)
        .iter()
        .map(|d| d.clamp(1e-6, 1e32))
        .collect();
    let rhs: Vec<f64> = gradient.iter().map(|g| -g).collect();
    let mut trials = 0;
    while damping.value <= damping.max {
        trials += 1;
        let damp: Vec<f64> = diagonal.iter().map(|d| damping.value * d).collect();
        let Some(step) = system.solve(&linearization.hessian, &damp, &rhs) else {
            damping.reject();
            continue;
        };
        // Predicted decrease of 1/2|r + J dx|^2: -g.dx - 1/2 dx.H dx = 1/2 dx.(lambda D dx - g).
        let predicted: f64 = 0.5
            * step
                .iter()
                .zip(&damp)
                .zip(gradient)
                .map(|((dx, d), g)| dx * (d * dx - g))
                .sum::<f64>();
        let mut candidate = std::mem::take(&mut work.candidate);
        retract_all(values, system, &step, &mut candidate);
        if !groups.is_empty() {
            groups.refine(graph, &mut candidate);
        }
        // The trial point is linearised whole, not only costed: its cost is
        // the same sum, and an accepted step (nearly every trial) then needs no
        // second pass over the factors. A point where the model is undefined
        // or a Jacobian is not finite is rejected.
        let trial = linearize_with(graph, &candidate, system, work);
        work.candidate = candidate;
        match trial {
            Ok(next) if next.cost < cost && predicted > 0.0 => {
                let gain_ratio = (cost - next.cost) / predicted;
                damping.accept(gain_ratio);
                let accepted = Accepted {
                    step,
                    linearization: next,
                    gain_ratio,
                };
                return (Some(accepted), trials);
            }
            Ok(rejected) => {
                work.spare = Some(rejected);
                damping.reject();
            }
            Err(_) => damping.reject(),
        }
    }
    (None, trials)
}

/// A rough scale of the free variables (Euclidean norm of the vector ones).
fn variables_scale(values: &Values) -> f64 {
    values
        .iter()
        .filter(|(_, v)| !v.fixed)
        .map(|(_, v)| match &v.value {
            crate::graph::VariableValue::Vector(x) => x.norm_squared(),
            crate::graph::VariableValue::Pose(p) => p.position_m.norm_squared(),
        })
        .sum::<f64>()
        .sqrt()
}
