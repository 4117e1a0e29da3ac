//! Local refinement: nonlinear elimination of the per-pose variables.
//!
//! In the calibration graph every pose's variables (platform pose, reference
//! tension) meet the rest of the problem only through the global anchors and
//! offsets, and the tight attachment-height constraint bends their valley:
//! a Gauss-Newton step that moves the anchors by decimetres leaves every pose
//! millimetres off its statics, which the 0.1 mm constraint prices at
//! hundreds of sigma, so plain LM creeps along the valley in millimetre steps.
//! After every trial step the solver therefore re-minimises each group of
//! local variables with everything else held (a few damped Gauss-Newton
//! iterations on a dense system of the group's size), i.e. it evaluates the
//! *reduced* cost `min_local cost(global, local)` as in variable projection
//! (Golub & Pereyra, "Separable nonlinear least squares", 2003) and
//! nonlinear elimination (Lanzkron, Rose & Wilkes, 1996). At a minimum of the
//! full problem the refinement changes nothing.

use super::linear_system::dot;
use super::schur::{backward_substitute, cholesky_in_place, forward_substitute};
use crate::graph::{FactorGraph, LinearizationBuffers, Values, VariableId};

/// Gauss-Newton iterations per group and refinement.
const MAX_ITERATIONS: usize = 8;
/// Stop a group when its cost falls by less than this fraction.
const RELATIVE_TOLERANCE: f64 = 1e-12;

/// One group of local variables and the factors that touch it.
struct Group {
    /// Free variables of the group.
    variables: Vec<VariableId>,
    /// Tangent offset of each variable within the group, plus the total at the end.
    offsets: Vec<usize>,
    /// Indices of the factors touching the group.
    factors: Vec<usize>,
    /// Per factor of `factors`: its variable slots that belong to the group,
    /// with the variable's tangent offset within the group.
    factor_slots: Vec<Vec<(usize, usize)>>,
}

/// The graph's local groups, resolved against its factors.
pub(crate) struct LocalGroups {
    groups: Vec<Group>,
}

impl LocalGroups {
    /// Resolve `graph.local_groups` (fixed variables are left out).
    pub(crate) fn new(graph: &FactorGraph) -> Self {
        let mut group_of = vec![None; graph.values.len()];
        let mut groups = Vec::new();
        for ids in &graph.local_groups {
            let variables: Vec<VariableId> = ids
                .iter()
                .copied()
                .filter(|&v| !graph.values.variable(v).fixed)
                .collect();
            if variables.is_empty() {
                continue;
            }
            let mut offsets = vec![0];
            for &v in &variables {
                group_of[v.0] = Some(groups.len());
                offsets.push(offsets.last().copied().unwrap_or(0) + graph.values.tangent_dim(v));
            }
            groups.push(Group {
                variables,
                offsets,
                factors: Vec::new(),
                factor_slots: Vec::new(),
            });
        }
        for (index, factor) in graph.factors.iter().enumerate() {
            let mut touched: Vec<usize> = factor.variables().iter().filter_map(|v| group_of[v.0]).collect();
            touched.sort_unstable();
            touched.dedup();
            for g in touched {
                let group = &mut groups[g];
                let slots = factor
                    .variables()
                    .iter()
                    .enumerate()
                    .filter_map(|(slot, v)| {
                        let k = group.variables.iter().position(|g| g == v)?;
                        Some((slot, group.offsets[k]))
                    })
                    .collect();
                group.factors.push(index);
                group.factor_slots.push(slots);
            }
        }
        Self { groups }
    }

    /// No groups: nothing to refine.
    pub(crate) fn none() -> Self {
        Self { groups: Vec::new() }
    }

    /// Whether there is anything to refine.
    pub(crate) fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Re-minimise every group in place. A group whose model is undefined
    /// keeps its values.
    pub(crate) fn refine(&self, graph: &FactorGraph, values: &mut Values) {
        let mut workspace = Workspace::default();
        for group in &self.groups {
            refine_group(graph, group, values, &mut workspace);
        }
    }
}

/// Buffers reused across groups: factor linearisations, `H`, `g`, the step.
#[derive(Default)]
struct Workspace {
    buffers: LinearizationBuffers,
    hessian: Vec<f64>,
    gradient: Vec<f64>,
    damped: Vec<f64>,
    step: Vec<f64>,
}

fn group_cost(graph: &FactorGraph, group: &Group, values: &Values) -> Option<f64> {
    group
        .factors
        .iter()
        .map(|&f| FactorGraph::factor_cost(graph.factors[f].as_ref(), values))
        .sum()
}

/// `H` (column-major `dim x dim`, lower triangle and diagonal filled) and `g`
/// of the group's factors with respect to the group's variables, and the
/// group's cost; `None` if a factor is undefined or not finite.
fn linearize_group(graph: &FactorGraph, group: &Group, values: &Values, work: &mut Workspace) -> Option<f64> {
    let dim = group.offsets[group.offsets.len() - 1];
    work.hessian.clear();
    work.hessian.resize(dim * dim, 0.0);
    work.gradient.clear();
    work.gradient.resize(dim, 0.0);
    let mut cost = 0.0;
    for (&f, slots) in group.factors.iter().zip(&group.factor_slots) {
        let Ok(linearized) = work.buffers.linearize(graph.factors[f].as_ref(), values) else {
            return None;
        };
        cost += linearized.cost;
        if linearized.is_zero {
            continue;
        }
        let rows = linearized.residual.len();
        for &(slot_a, offset_a) in slots {
            let ja = linearized.jacobians[slot_a].as_slice();
            for (c, column) in ja.chunks_exact(rows).enumerate() {
                work.gradient[offset_a + c] += dot::<0>(column, &linearized.residual);
            }
            for &(slot_b, offset_b) in slots {
                if offset_a < offset_b {
                    continue;
                }
                let jb = linearized.jacobians[slot_b].as_slice();
                for (i, column_a) in ja.chunks_exact(rows).enumerate() {
                    for (j, column_b) in jb.chunks_exact(rows).enumerate() {
                        let (row, col) = (offset_a + i, offset_b + j);
                        if row >= col {
                            work.hessian[row + col * dim] += dot::<0>(column_a, column_b);
                        }
                    }
                }
            }
        }
    }
    work.hessian
        .iter()
        .chain(&work.gradient)
        .all(|v| v.is_finite())
        .then_some(cost)
}

fn refine_group(graph: &FactorGraph, group: &Group, values: &mut Values, work: &mut Workspace) {
    let dim = group.offsets[group.offsets.len() - 1];
    let mut damping = 1e-8;
    // The cost at the current values: the linearisation's at the start, then
    // that of the last accepted trial.
    let mut cost = f64::NAN;
    for iteration in 0..MAX_ITERATIONS {
        let Some(linearized_cost) = linearize_group(graph, group, values, work) else {
            return;
        };
        if iteration == 0 {
            cost = linearized_cost;
        }
        let originals: Vec<_> = group
            .variables
            .iter()
            .map(|&v| values.variable(v).value.clone())
            .collect();
        let mut improved = false;
        while damping < 1e8 {
            work.damped.clone_from(&work.hessian);
            for i in 0..dim {
                work.damped[i + i * dim] += damping * work.hessian[i + i * dim].max(1e-12);
            }
            if !cholesky_in_place(&mut work.damped, dim) {
                damping *= 10.0;
                continue;
            }
            work.step.clear();
            work.step.extend(work.gradient.iter().map(|g| -g));
            forward_substitute(&work.damped, dim, &mut work.step);
            backward_substitute(&work.damped, dim, &mut work.step);
            // Predicted decrease of the damped Gauss-Newton step,
            // 1/2 dx.(lambda D dx - g): below the tolerance the group is at
            // its minimum and the trial evaluation is saved.
            let predicted: f64 = 0.5
                * (0..dim)
                    .map(|i| {
                        let dx = work.step[i];
                        dx * (damping * work.hessian[i + i * dim].max(1e-12) * dx - work.gradient[i])
                    })
                    .sum::<f64>();
            if predicted < RELATIVE_TOLERANCE * cost {
                return;
            }
            for (k, &v) in group.variables.iter().enumerate() {
                let slice = &work.step[group.offsets[k]..group.offsets[k + 1]];
                values.set(v, originals[k].retract(slice));
            }
            match group_cost(graph, group, values) {
                Some(new_cost) if new_cost < cost => {
                    let decrease = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
                    cost = new_cost;
                    damping = (damping / 10.0).max(1e-12);
                    improved = decrease > RELATIVE_TOLERANCE;
                    break;
                }
                _ => {
                    for (k, &v) in group.variables.iter().enumerate() {
                        values.set(v, originals[k].clone());
                    }
                    damping *= 10.0;
                }
            }
        }
        if !improved {
            return;
        }
    }
}
