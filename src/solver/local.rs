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

use super::dense::{backward_substitute, cholesky_in_place, dot, forward_substitute};
use super::shapes::{CABLE_ROWS, GROUP, POSE, POSITION_PRIOR_ROWS, PRIOR_ROWS};
use super::simd;
use std::cell::RefCell;

use crate::graph::{FactorGraph, LinearizationBuffers, SlotMask, Values, VariableId, VariableValue};

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
    /// Per factor of `factors`: its slots of `factor_slots` as a mask.
    factor_masks: Vec<SlotMask>,
}

/// The graph's local groups, resolved against its factors.
pub(crate) struct LocalGroups {
    groups: Vec<Group>,
    /// Buffers reused by every refinement of the solve.
    workspace: RefCell<Workspace>,
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
                factor_masks: Vec::new(),
            });
        }
        for (index, factor) in graph.factors.iter().enumerate() {
            let mut touched: Vec<usize> = factor.variables().iter().filter_map(|v| group_of[v.0]).collect();
            touched.sort_unstable();
            touched.dedup();
            for g in touched {
                let group = &mut groups[g];
                let slots: Vec<(usize, usize)> = factor
                    .variables()
                    .iter()
                    .enumerate()
                    .filter_map(|(slot, v)| {
                        let k = group.variables.iter().position(|g| g == v)?;
                        Some((slot, group.offsets[k]))
                    })
                    .collect();
                group.factors.push(index);
                group
                    .factor_masks
                    .push(SlotMask::of(slots.iter().map(|&(slot, _)| slot)));
                group.factor_slots.push(slots);
            }
        }
        Self {
            groups,
            workspace: RefCell::default(),
        }
    }

    /// No groups: nothing to refine.
    pub(crate) fn none() -> Self {
        Self {
            groups: Vec::new(),
            workspace: RefCell::default(),
        }
    }

    /// Whether there is anything to refine.
    pub(crate) fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Re-minimise every group in place. A group whose model is undefined
    /// keeps its values.
    pub(crate) fn refine(&self, graph: &FactorGraph, values: &mut Values) {
        let mut workspace = self.workspace.borrow_mut();
        for group in &self.groups {
            refine_group(graph, group, values, &mut workspace);
        }
    }
}

/// Buffers reused across groups: factor linearisations, the group's system
/// at the current point and at the trial point, the damped matrix, the step.
#[derive(Default)]
struct Workspace {
    buffers: LinearizationBuffers,
    current: GroupSystem,
    trial: GroupSystem,
    damped: Vec<f64>,
    step: Vec<f64>,
    /// The group's values before a step, restored when the step is rejected.
    originals: Vec<VariableValue>,
    /// The group's tangent index of each column in `gathered`.
    columns: Vec<usize>,
    /// The group's Jacobian columns of the factor being added, column-major.
    gathered: Vec<f64>,
}

/// `H` (column-major `dim x dim`, lower triangle and diagonal filled) and `g`
/// of a group's factors with respect to the group's variables.
#[derive(Default)]
struct GroupSystem {
    hessian: Vec<f64>,
    gradient: Vec<f64>,
}

/// Linearise the group's factors at `values` into `out` (only their blocks
/// of the group's variables, [`LinearizationBuffers::linearize_slots`]); the
/// group's cost, or `None` if a factor is undefined or not finite.
fn linearize_group(
    graph: &FactorGraph,
    group: &Group,
    values: &Values,
    buffers: &mut LinearizationBuffers,
    columns: &mut Vec<usize>,
    gathered: &mut Vec<f64>,
    out: &mut GroupSystem,
) -> Option<f64> {
    let dim = group.offsets[group.offsets.len() - 1];
    out.hessian.clear();
    out.hessian.resize(dim * dim, 0.0);
    out.gradient.clear();
    out.gradient.resize(dim, 0.0);
    let mut cost = 0.0;
    let mut rows_buffer = [0.0; CABLE_ROWS * GROUP];
    for ((&f, slots), &mask) in group.factors.iter().zip(&group.factor_slots).zip(&group.factor_masks) {
        let Ok(linearized) = buffers.linearize_slots(graph.factors[f].as_ref(), values, mask) else {
            return None;
        };
        cost += linearized.cost;
        if linearized.is_zero {
            continue;
        }
        // The group's columns of this factor, gathered contiguous (column-major, `rows` each).
        let rows = linearized.residual.len();
        columns.clear();
        gathered.clear();
        for &(slot, offset) in slots {
            let block = &linearized.jacobians[slot];
            columns.extend((0..block.ncols()).map(|c| offset + c));
            gathered.extend_from_slice(block.as_slice());
        }
        let residual = &linearized.residual;
        match (rows, columns.len()) {
            // A pose's catenary rows on its pose and tension; its pose prior.
            (CABLE_ROWS, GROUP) if contiguous(columns) && simd::avx2() => {
                add_normal_equations_avx2(columns[0], gathered, residual, dim, out, &mut rows_buffer)
            }
            (CABLE_ROWS, GROUP) => {
                add_normal_equations_by_rows::<CABLE_ROWS, GROUP>(columns, gathered, residual, dim, out)
            }
            (PRIOR_ROWS, POSE) => {
                add_normal_equations_by_rows::<PRIOR_ROWS, POSE>(columns, gathered, residual, dim, out)
            }
            (POSITION_PRIOR_ROWS, POSE) => {
                add_normal_equations_by_rows::<POSITION_PRIOR_ROWS, POSE>(columns, gathered, residual, dim, out)
            }
            (1, _) => add_normal_equations::<1>(columns, gathered, residual, dim, out),
            (CABLE_ROWS, _) => add_normal_equations::<CABLE_ROWS>(columns, gathered, residual, dim, out),
            (PRIOR_ROWS, _) => add_normal_equations::<PRIOR_ROWS>(columns, gathered, residual, dim, out),
            _ => add_normal_equations::<0>(columns, gathered, residual, dim, out),
        }
    }
    all_finite(&out.hessian, &out.gradient).then_some(cost)
}

/// Whether every entry of both is finite: `v * 0.0` is NaN exactly when `v`
/// is not finite, and a sum with a NaN term is NaN in any order, so four
/// running sums side by side give the answer of the entry-by-entry test.
fn all_finite(a: &[f64], b: &[f64]) -> bool {
    let mut lanes = [0.0f64; 4];
    for part in [a, b] {
        let mut chunks = part.chunks_exact(4);
        for chunk in &mut chunks {
            for (lane, v) in lanes.iter_mut().zip(chunk) {
                *lane += v * 0.0;
            }
        }
        for v in chunks.remainder() {
            lanes[0] += v * 0.0;
        }
    }
    !lanes.iter().any(|v| v.is_nan())
}

/// Whether `columns` are consecutive tangent indices.
fn contiguous(columns: &[usize]) -> bool {
    columns.iter().enumerate().all(|(k, &c)| c == columns[0] + k)
}

/// [`add_normal_equations_by_rows`] for four rows on eight consecutive
/// columns from `first`, by the AVX2 kernels of the full solve: the same
/// sums in the same order, bit for bit (test). The caller checked that the
/// CPU has AVX2.
fn add_normal_equations_avx2(
    first: usize,
    gathered: &[f64],
    residual: &[f64],
    dim: usize,
    out: &mut GroupSystem,
    rows: &mut [f64; CABLE_ROWS * GROUP],
) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the caller checked `simd::avx2()`.
    unsafe {
        simd::gram::scatter_four_rows(&gathered[..CABLE_ROWS * GROUP], rows, GROUP, 0);
        simd::gram::gram_block::<CABLE_ROWS, GROUP, 1, false, false>(rows, residual, 0, &mut out.gradient[first..]);
        simd::gram::gram_block::<CABLE_ROWS, GROUP, GROUP, true, false>(
            rows,
            rows,
            dim,
            &mut out.hessian[first + first * dim..],
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (first, gathered, residual, dim, out, rows);
}

/// Add one factor's `J^T J` (lower triangle) and `J^T r` over the group's
/// columns (`gathered`: column-major, the residual's length each; column `k`
/// is the group's tangent index `columns[k]`), `R` rows (`R = 0`: any
/// number): one dot product per entry, summed over the rows in order and
/// added to the entry once per factor.
#[inline(always)]
fn add_normal_equations<const R: usize>(
    columns: &[usize],
    gathered: &[f64],
    residual: &[f64],
    dim: usize,
    out: &mut GroupSystem,
) {
    let rows = residual.len();
    for (&a, ja) in columns.iter().zip(gathered.chunks_exact(rows)) {
        out.gradient[a] += dot::<R>(ja, residual);
        for (&b, jb) in columns.iter().zip(gathered.chunks_exact(rows)) {
            if a >= b {
                out.hessian[a + b * dim] += dot::<R>(ja, jb);
            }
        }
    }
}

/// [`add_normal_equations`] for `R` rows and `C` columns known at compile
/// time: the columns transposed to rows first, so that the entries of one
/// column of `J^T J` (and of `J^T r`) are summed side by side; each entry is
/// still `sum_r a_r b_r` in row order, added once, so the sums are bit for
/// bit those of the dot products (test).
#[inline(always)]
fn add_normal_equations_by_rows<const R: usize, const C: usize>(
    columns: &[usize],
    gathered: &[f64],
    residual: &[f64],
    dim: usize,
    out: &mut GroupSystem,
) {
    let columns: &[usize; C] = columns.try_into().expect("C columns");
    let residual: &[f64; R] = residual.try_into().expect("R rows");
    let gathered = &gathered[..R * C];
    let rows: [[f64; C]; R] = std::array::from_fn(|r| std::array::from_fn(|c| gathered[c * R + r]));
    let mut gradient: [f64; C] = std::array::from_fn(|a| rows[0][a] * residual[0]);
    for r in 1..R {
        for a in 0..C {
            gradient[a] += rows[r][a] * residual[r];
        }
    }
    for a in 0..C {
        out.gradient[columns[a]] += gradient[a];
    }
    for b in 0..C {
        let mut sums: [f64; C] = std::array::from_fn(|a| rows[0][a] * rows[0][b]);
        for row in &rows[1..] {
            for a in 0..C {
                sums[a] += row[a] * row[b];
            }
        }
        let column_b = columns[b] * dim;
        for a in 0..C {
            if columns[a] >= columns[b] {
                out.hessian[columns[a] + column_b] += sums[a];
            }
        }
    }
}

/// Re-minimise one group with everything else held: damped Gauss-Newton on
/// the group's dense system. Every trial point is linearised whole (its cost
/// is the same sum as a value-only pass), so an accepted trial needs no
/// second pass over the group's factors.
fn refine_group(graph: &FactorGraph, group: &Group, values: &mut Values, work: &mut Workspace) {
    let dim = group.offsets[group.offsets.len() - 1];
    let mut damping = 1e-8;
    let Workspace {
        buffers,
        current,
        trial,
        damped,
        step,
        originals,
        columns,
        gathered,
    } = work;
    // The cost at the current values: the linearisation's at the start, then
    // that of the last accepted trial.
    let Some(mut cost) = linearize_group(graph, group, values, buffers, columns, gathered, current) else {
        return;
    };
    for _ in 0..MAX_ITERATIONS {
        crate::steps::tick();
        originals.resize_with(group.variables.len(), || VariableValue::Vector(Default::default()));
        for (original, &v) in originals.iter_mut().zip(&group.variables) {
            assign(original, &values.variable(v).value);
        }
        let mut improved = false;
        while damping < 1e8 {
            damped.clone_from(&current.hessian);
            for i in 0..dim {
                damped[i + i * dim] += damping * current.hessian[i + i * dim].max(1e-12);
            }
            step.clear();
            step.extend(current.gradient.iter().map(|g| -g));
            if !solve_in_place(damped, dim, step) {
                damping *= 10.0;
                continue;
            }
            // Predicted decrease of the damped Gauss-Newton step,
            // 1/2 dx.(lambda D dx - g): below the tolerance the group is at
            // its minimum and the trial evaluation is saved.
            let predicted: f64 = 0.5
                * (0..dim)
                    .map(|i| {
                        let dx = step[i];
                        dx * (damping * current.hessian[i + i * dim].max(1e-12) * dx - current.gradient[i])
                    })
                    .sum::<f64>();
            if predicted < RELATIVE_TOLERANCE * cost {
                return;
            }
            for (k, &v) in group.variables.iter().enumerate() {
                let slice = &step[group.offsets[k]..group.offsets[k + 1]];
                let value = values.value_mut(v);
                assign(value, &originals[k]);
                value.retract_in_place(slice);
            }
            match linearize_group(graph, group, values, buffers, columns, gathered, trial) {
                Some(new_cost) if new_cost < cost => {
                    let decrease = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
                    cost = new_cost;
                    damping = (damping / 10.0).max(1e-12);
                    improved = decrease > RELATIVE_TOLERANCE;
                    std::mem::swap(current, trial);
                    break;
                }
                _ => {
                    for (k, &v) in group.variables.iter().enumerate() {
                        assign(values.value_mut(v), &originals[k]);
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

/// `x <- A^-1 x` by the Cholesky factorisation of `a` (column-major
/// `dim x dim`, overwritten by its factor); `false` if `a` is not positive
/// definite. A pose's group (eight columns: the pose and its tension) goes
/// through the same code with the size known at compile time (unrolled, no
/// bounds checks; the same operations in the same order).
fn solve_in_place(a: &mut [f64], dim: usize, x: &mut [f64]) -> bool {
    #[inline(always)]
    fn solve(a: &mut [f64], dim: usize, x: &mut [f64]) -> bool {
        let (a, x) = (&mut a[..dim * dim], &mut x[..dim]);
        if !cholesky_in_place(a, dim) {
            return false;
        }
        forward_substitute(a, dim, x);
        backward_substitute(a, dim, x);
        true
    }
    match dim {
        GROUP => solve(a, GROUP, x),
        _ => solve(a, dim, x),
    }
}

/// `*to = from.clone()`, reusing `to`'s vector where the lengths agree.
fn assign(to: &mut VariableValue, from: &VariableValue) {
    match (to, from) {
        (VariableValue::Vector(a), VariableValue::Vector(b)) if a.len() == b.len() => a.copy_from(b),
        (to, from) => *to = from.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row-wise kernel adds bit for bit what the dot products add, for
    /// the shapes it serves, with columns in an order that is not the
    /// group's (a factor listing its tension before its pose).
    #[test]
    fn the_row_wise_kernel_matches_the_dot_products() {
        fn check<const R: usize, const C: usize>(columns: &[usize]) {
            let dim = 9;
            let gathered: Vec<f64> = (0..R * C)
                .map(|k| ((k * 7 % 13) as f64 - 6.0) * 0.37 + 1e-3 * k as f64)
                .collect();
            let residual: Vec<f64> = (0..R).map(|r| 0.3 - 0.71 * r as f64).collect();
            let start = || GroupSystem {
                hessian: (0..dim * dim).map(|k| 0.01 * k as f64).collect(),
                gradient: (0..dim).map(|k| -0.5 * k as f64).collect(),
            };
            let (mut by_rows, mut by_dots) = (start(), start());
            add_normal_equations_by_rows::<R, C>(columns, &gathered, &residual, dim, &mut by_rows);
            add_normal_equations::<0>(columns, &gathered, &residual, dim, &mut by_dots);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&by_rows.hessian), bits(&by_dots.hessian), "{R} x {C}");
            assert_eq!(bits(&by_rows.gradient), bits(&by_dots.gradient), "{R} x {C}");
            assert_ne!(bits(&by_rows.hessian), bits(&start().hessian));
            if R == CABLE_ROWS && C == GROUP && contiguous(columns) && simd::avx2_under_test() {
                let mut by_avx2 = start();
                add_normal_equations_avx2(columns[0], &gathered, &residual, dim, &mut by_avx2, &mut [0.0; 32]);
                assert_eq!(bits(&by_avx2.hessian), bits(&by_dots.hessian), "AVX2 {R} x {C}");
                assert_eq!(bits(&by_avx2.gradient), bits(&by_dots.gradient), "AVX2 {R} x {C}");
            }
        }
        check::<4, 8>(&[6, 7, 0, 1, 2, 3, 4, 5]);
        check::<4, 8>(&[1, 2, 3, 4, 5, 6, 7, 8]);
        check::<6, 6>(&[0, 1, 2, 3, 4, 5]);
        check::<3, 6>(&[3, 4, 5, 6, 7, 8]);
    }

    /// The lane-wise finiteness test finds a NaN or an infinity anywhere in
    /// either slice (in a full lane group and in the remainder) and passes
    /// finite values, however large.
    #[test]
    fn all_finite_finds_every_non_finite_entry() {
        let a: Vec<f64> = (0..11).map(|k| 1e300 * (k as f64 - 5.0)).collect();
        let b = vec![0.5; 6];
        assert!(all_finite(&a, &b));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..a.len() {
                let mut a = a.clone();
                a[k] = bad;
                assert!(!all_finite(&a, &b), "{bad} at a[{k}]");
            }
            for k in 0..b.len() {
                let mut b = b.clone();
                b[k] = bad;
                assert!(!all_finite(&a, &b), "{bad} at b[{k}]");
            }
        }
    }
}
