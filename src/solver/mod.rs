//! A sparse Levenberg-Marquardt for [`crate::graph::FactorGraph`]s.
//!
//! Each iteration linearises every factor once (whitened by its sigmas,
//! reweighted by its robust kernel), assembles `H = J^T J` and `g = J^T r`
//! into the pattern analysed once by [`LinearSystem`] (which eliminates the
//! graph's local groups block by block when the structure allows, see the
//! `schur` module, else uses faer's sparse Cholesky), and tries damped steps
//! `(H + lambda D) dx = -g` with `D = clamp(diag H)` (Marquardt scaling).
//! A trial is accepted when the gain ratio
//! `rho = (actual cost decrease) / (decrease predicted by the linear model)`
//! is positive; lambda then follows Nielsen's rule
//! (`lambda *= max(1/3, 1 - (2 rho - 1)^3)`), and on rejection or a failed
//! factorisation it grows by `nu`, `nu` doubling (Madsen, Nielsen & Tingleff,
//! *Methods for Non-Linear Least Squares Problems*, 2004, Sec. 3.2). A
//! rejected step reuses the linearisation.
//!
//! Graphs may name groups of *local* variables
//! ([`FactorGraph::local_groups`]); every trial point then has each group
//! re-minimised with the rest held before its cost is judged (nonlinear
//! elimination, see the `local` module), which keeps long steps of the global
//! variables on the curved valley of a tight model constraint.
//!
//! The calibration builds its graph and calls [`optimize`]; the benchmark
//! problem shows the loop on its own:
//!
//! ```
//! use sagcal::experiments::benchmark::BenchmarkProblem;
//! use sagcal::solver::optimize;
//!
//! let problem = BenchmarkProblem::new(9, 1)?;
//! let mut built = problem.graph();
//! let summary = optimize(&mut built.graph, &BenchmarkProblem::stopping()).map_err(sagcal::Error::from)?;
//! assert!(summary.final_cost < 1e-3 * summary.initial_cost);
//! # Ok::<(), sagcal::Error>(())
//! ```

mod accumulate;
mod covariance;
mod dense;
mod linear_system;
mod local;
mod redundancy;
mod schur;
mod score;
mod shapes;
mod simd;
mod sparse_cholesky;
mod system_cache;

use local::LocalGroups;

pub use crate::error::SolverError;
pub use covariance::{marginal_covariance, marginal_covariance_cached, Covariance, UnobservableDirection};
use dense::fill_zeros;
pub use linear_system::LinearSystem;
pub use redundancy::redundancy_numbers;
pub use score::{score_system, score_tests, Direction, ScoreSystem, ScoreTest};
pub use shapes::Fallbacks;
pub use system_cache::SystemCache;

use serde::Serialize;

use crate::graph::{FactorGraph, LinearizationBuffers, Values};

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
struct Workspace {
    buffers: LinearizationBuffers,
    /// Scratch of [`LinearSystem::accumulate`].
    rows_buffer: Vec<f64>,
    candidate: Values,
    spare: Option<Linearization>,
}

/// [`linearize`] into the arrays of `work.spare` (if any) with `work`'s buffers.
fn linearize_with(
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
