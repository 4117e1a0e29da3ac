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

use nalgebra::{DMatrix, DVector};

use crate::graph::{linearize_factor, FactorGraph, Values, VariableId};

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
            });
        }
        for (index, factor) in graph.factors.iter().enumerate() {
            let mut touched: Vec<usize> = factor.variables().iter().filter_map(|v| group_of[v.0]).collect();
            touched.sort_unstable();
            touched.dedup();
            for g in touched {
                groups[g].factors.push(index);
            }
        }
        Self { groups }
    }

    /// Whether there is anything to refine.
    pub(crate) fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Re-minimise every group in place. A group whose model is undefined
    /// keeps its values.
    pub(crate) fn refine(&self, graph: &FactorGraph, values: &mut Values) {
        for group in &self.groups {
            refine_group(graph, group, values);
        }
    }
}

fn group_cost(graph: &FactorGraph, group: &Group, values: &Values) -> Option<f64> {
    group
        .factors
        .iter()
        .map(|&f| FactorGraph::factor_cost(graph.factors[f].as_ref(), values))
        .sum()
}

/// `H`, `g` of the group's factors with respect to the group's variables.
fn linearize_group(graph: &FactorGraph, group: &Group, values: &Values) -> Option<(DMatrix<f64>, DVector<f64>)> {
    let dim = *group.offsets.last()?;
    let mut hessian = DMatrix::<f64>::zeros(dim, dim);
    let mut gradient = DVector::<f64>::zeros(dim);
    for &f in &group.factors {
        let factor = graph.factors[f].as_ref();
        let linearized = linearize_factor(factor, values).ok()?;
        let rows = linearized.residual.len();
        let mut jacobian = DMatrix::zeros(rows, dim);
        for (slot, &v) in factor.variables().iter().enumerate() {
            if let Some(k) = group.variables.iter().position(|&g| g == v) {
                let start = group.offsets[k];
                let block = &linearized.jacobians[slot];
                jacobian.columns_mut(start, block.ncols()).copy_from(block);
            }
        }
        let whitened = DVector::from_column_slice(&linearized.residual);
        hessian += jacobian.transpose() * &jacobian;
        gradient += jacobian.transpose() * whitened;
    }
    (hessian.iter().all(|v| v.is_finite()) && gradient.iter().all(|v| v.is_finite())).then_some((hessian, gradient))
}

fn refine_group(graph: &FactorGraph, group: &Group, values: &mut Values) {
    let Some(mut cost) = group_cost(graph, group, values) else {
        return;
    };
    let mut damping = 1e-8;
    for _ in 0..MAX_ITERATIONS {
        let Some((hessian, gradient)) = linearize_group(graph, group, values) else {
            return;
        };
        let originals: Vec<_> = group
            .variables
            .iter()
            .map(|&v| values.variable(v).value.clone())
            .collect();
        let mut improved = false;
        while damping < 1e8 {
            let mut damped = hessian.clone();
            for i in 0..damped.nrows() {
                damped[(i, i)] += damping * hessian[(i, i)].max(1e-12);
            }
            let Some(step) = damped.cholesky().map(|c| c.solve(&(-&gradient))) else {
                damping *= 10.0;
                continue;
            };
            for (k, &v) in group.variables.iter().enumerate() {
                let slice = &step.as_slice()[group.offsets[k]..group.offsets[k + 1]];
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
