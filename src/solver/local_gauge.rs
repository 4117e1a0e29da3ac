//! Covariance of selected (global) variables when some directions of the
//! local groups' own variables are not determined by the data.
//!
//! A robot of many cables carries every cable's forces as variables of its
//! pose; with light cables and few load cells, the readings fix some force
//! combinations at a pose only up to directions that no factor sees, or
//! hardly sees (the statics are indeterminate, or nearly so). `H` is then
//! singular or nearly, and [`super::marginal_covariance`] reports
//! unobservable directions, though the globals may be well determined.
//!
//! Here each local group `b` (a pose's own variables) gets a vague prior of
//! 1-sigma `largest_sigma` on each of its tangent coordinates (in their own
//! units: newtons for forces), `eps = 1 / largest_sigma^2`, and the globals
//! `G` their information with the groups eliminated. With `A_b` the
//! whitened Jacobian of the rows that touch group `b` in its own columns,
//! `A_b = U S V^T` (thin SVD), and `C_b` the same rows in the globals'
//! columns:
//!
//! ```text
//! S = sum_b C_b^T (I - U D U^T) C_b + (rows of no group)^T (rows of no group),   D = s^2 / (s^2 + eps)
//! ```
//!
//! the Schur complement of `J^T J + eps I_local` (the block elimination,
//! Golub and Van Loan, *Matrix Computations*, 4th ed., sec. 3.2.10), formed
//! as `P^T P + E^T E` with `P = C_b - U U^T C_b` and `E = sqrt(1 - D) U^T
//! C_b`: from the Jacobian, not from `J^T J`, whose constraint rows (the
//! attachment heights at 0.1 mm, the equilibrium at 1e-5 of the weight)
//! would square its condition number past the double precision in which
//! the undetermined directions are told from the determined. A direction
//! no reading sees (`s = 0`) leaves its rows to the globals whatever the
//! prior; one the readings fix (`s^2 >> eps`) absorbs them. A direction with
//! `s^2 < eps` (a 1-sigma above `largest_sigma` from the readings) is
//! counted as undetermined: it takes no degree of freedom from the fit.
//! The globals' covariance is `S^-1`, its block of the selected variables
//! returned.
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use sagcal::graph::{Factor, FactorGraph, Noise, Values, VariableId, VariableValue};
//! use sagcal::solver::{marginal_covariance_over_local_gauge, Covariance};
//! /// One unit-sigma reading of `sum_k row_k . x_k`, `x_k` the variables.
//! struct Linear { variables: Vec<VariableId>, rows: Vec<Vec<f64>>, noise: Noise }
//! impl Factor for Linear {
//!     fn variables(&self) -> &[VariableId] { &self.variables }
//!     fn residual_dim(&self) -> usize { 1 }
//!     fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
//!         let dot = |k: usize| self.rows[k].iter().zip(values.vector(self.variables[k]).iter()).map(|(a, x)| a * x).sum::<f64>();
//!         if let Some(blocks) = jacobians {
//!             for (block, row) in blocks.iter_mut().zip(&self.rows) { block.copy_from_slice(row); }
//!         }
//!         Some(DVector::from_element(1, (0..self.rows.len()).map(dot).sum()))
//!     }
//!     fn noise(&self) -> &Noise { &self.noise }
//!     fn kind(&self) -> &'static str { "linear" }
//! }
//! // A global `g` and a local pair `l` seen only through `l0 + l1`:
//! // `l0 - l1` is a local gauge; `g`'s variance is 2 (two unit-sigma readings).
//! let mut graph = FactorGraph::new();
//! let g = graph.values.insert("g", VariableValue::Vector(DVector::zeros(1)));
//! let l = graph.values.insert("l", VariableValue::Vector(DVector::zeros(2)));
//! let unit = || Noise::gaussian(DVector::from_element(1, 1.0));
//! graph.add(Linear { variables: vec![g, l], rows: vec![vec![1.0], vec![1.0, 1.0]], noise: unit() });
//! graph.add(Linear { variables: vec![l], rows: vec![vec![1.0, 1.0]], noise: unit() });
//! graph.local_groups.push(vec![l]);
//! let found = marginal_covariance_over_local_gauge(&graph, &[g], 1e6)?;
//! let Covariance::Full(c) = found.covariance else { panic!("{:?}", found.covariance) };
//! assert!((c[(0, 0)] - 2.0).abs() < 1e-9);
//! assert_eq!(found.undetermined, vec![(0, 1)]); // group 0 leaves one direction undetermined
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::collections::HashMap;

use nalgebra::DMatrix;

use super::covariance::{marginal_covariance, Covariance};
use crate::error::SolverError;
use crate::graph::{linearize_factor, FactorGraph, VariableId};

/// The selected variables' covariance with the local groups' undetermined
/// directions left to the vague prior, and which groups had such directions.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalGaugeCovariance {
    /// The covariance of the selected variables, or why there is none.
    pub covariance: Covariance,
    /// `(index in graph.local_groups, undetermined directions)` of each group with any.
    pub undetermined: Vec<(usize, usize)>,
}

/// Where a free variable's columns lie: among the globals or in a group.
#[derive(Debug, Clone, Copy)]
enum Place {
    Global(usize),
    Local(usize, usize),
}

/// The marginal covariance of `selected` (module docs): the plain one
/// ([`marginal_covariance`]) when it is determined; otherwise the globals'
/// information with each local group eliminated under a vague prior of
/// 1-sigma `largest_sigma` on its coordinates. The undetermined directions
/// are counted either way.
pub fn marginal_covariance_over_local_gauge(
    graph: &FactorGraph,
    selected: &[VariableId],
    largest_sigma: f64,
) -> Result<LocalGaugeCovariance, SolverError> {
    let plain = marginal_covariance(graph, selected)?;
    let (places, globals, group_sizes) = layout(graph, selected);
    let Some(rows) = rows_by_group(graph, &places, globals, group_sizes.len())? else {
        return Ok(LocalGaugeCovariance {
            covariance: plain,
            undetermined: Vec::new(),
        });
    };
    let eps = 1.0 / (largest_sigma * largest_sigma);
    let mut information = DMatrix::zeros(globals, globals);
    let mut undetermined = Vec::new();
    for (group, (global_rows, local_rows)) in rows.into_iter().enumerate() {
        let Some(local) = local_rows else {
            information += global_rows.transpose() * &global_rows;
            continue;
        };
        let dropped = eliminate(&mut information, &global_rows, local, group_sizes[group], eps);
        if dropped > 0 {
            undetermined.push((group, dropped));
        }
    }
    // A regular problem keeps the plain covariance, to the bit.
    let covariance = match (plain, information.cholesky()) {
        (Covariance::Full(c), _) => Covariance::Full(c),
        (plain, None) => plain,
        (_, Some(cholesky)) => {
            let chosen: usize = selected.iter().map(|&id| graph.values.tangent_dim(id)).sum();
            Covariance::Full(cholesky.inverse().view((0, 0), (chosen, chosen)).into_owned())
        }
    };
    Ok(LocalGaugeCovariance {
        covariance,
        undetermined,
    })
}

/// Each free variable's place; the globals' column count (the selected
/// variables first, in order, then every free variable in no group); each
/// group's column count.
fn layout(graph: &FactorGraph, selected: &[VariableId]) -> (HashMap<VariableId, Place>, usize, Vec<usize>) {
    let free = |id: VariableId| !graph.values.variable(id).fixed;
    let mut places = HashMap::new();
    let mut globals = 0;
    for &id in selected.iter().filter(|&&id| free(id)) {
        places.insert(id, Place::Global(globals));
        globals += graph.values.tangent_dim(id);
    }
    let mut sizes = Vec::with_capacity(graph.local_groups.len());
    for (g, group) in graph.local_groups.iter().enumerate() {
        let mut size = 0;
        for &id in group {
            if free(id) && !places.contains_key(&id) {
                places.insert(id, Place::Local(g, size));
                size += graph.values.tangent_dim(id);
            }
        }
        sizes.push(size);
    }
    for (id, _) in graph.values.iter() {
        if free(id) && !places.contains_key(&id) {
            places.insert(id, Place::Global(globals));
            globals += graph.values.tangent_dim(id);
        }
    }
    (places, globals, sizes)
}

/// Per group (and a last entry for the rows touching no group), the
/// whitened Jacobian rows in the globals' columns and in the group's own;
/// `None` when a factor touches two groups (no block elimination then).
#[allow(clippy::type_complexity)]
fn rows_by_group(
    graph: &FactorGraph,
    places: &HashMap<VariableId, Place>,
    globals: usize,
    groups: usize,
) -> Result<Option<Vec<(DMatrix<f64>, Option<Vec<Vec<f64>>>)>>, SolverError> {
    let mut global_rows: Vec<Vec<Vec<f64>>> = vec![Vec::new(); groups + 1];
    let mut local_rows: Vec<Vec<Vec<(usize, f64)>>> = vec![Vec::new(); groups + 1];
    for factor in &graph.factors {
        let linear = linearize_factor(factor.as_ref(), &graph.values).map_err(|source| {
            SolverError::Factor {
                kind: factor.kind(),
                variables: factor
                    .variables()
                    .iter()
                    .map(|&id| graph.values.variable(id).name.clone())
                    .collect::<Vec<_>>()
                    .join(", "),
                source,
            }
            .during("covariance at the solution")
        })?;
        let touched: Vec<usize> = factor
            .variables()
            .iter()
            .filter_map(|id| match places.get(id) {
                Some(Place::Local(g, _)) => Some(*g),
                _ => None,
            })
            .collect();
        if touched.windows(2).any(|w| w[0] != w[1]) {
            return Ok(None);
        }
        let group = touched.first().copied().unwrap_or(groups);
        for row in 0..factor.residual_dim() {
            let mut global = vec![0.0; globals];
            let mut local = Vec::new();
            for (block, id) in linear.jacobians.iter().zip(factor.variables()) {
                for c in 0..block.ncols() {
                    match places.get(id) {
                        Some(Place::Global(o)) => global[o + c] += block[(row, c)],
                        Some(Place::Local(_, o)) => local.push((o + c, block[(row, c)])),
                        None => {}
                    }
                }
            }
            global_rows[group].push(global);
            local_rows[group].push(local);
        }
    }
    let dense = |rows: &[Vec<f64>], width: usize| DMatrix::from_fn(rows.len(), width, |r, c| rows[r][c]);
    Ok(Some(
        global_rows
            .into_iter()
            .zip(local_rows)
            .enumerate()
            .map(|(g, (global, local))| {
                let global = dense(&global, globals);
                let local = (g < groups).then(|| {
                    local
                        .into_iter()
                        .map(|entries| {
                            let mut row = Vec::new();
                            for (c, v) in entries {
                                if row.len() <= c {
                                    row.resize(c + 1, 0.0);
                                }
                                row[c] += v;
                            }
                            row
                        })
                        .collect()
                });
                (global, local)
            })
            .collect(),
    ))
}

/// Add one group's rows to `information` with the group eliminated under
/// the prior `eps` (module docs); the count of its undetermined directions.
fn eliminate(
    information: &mut DMatrix<f64>,
    global: &DMatrix<f64>,
    local: Vec<Vec<f64>>,
    size: usize,
    eps: f64,
) -> usize {
    let rows = local.len();
    let a = DMatrix::from_fn(rows, size, |r, c| local[r].get(c).copied().unwrap_or(0.0));
    let svd = a.svd(true, false);
    let (Some(u), values) = (svd.u, svd.singular_values) else {
        return size;
    };
    let projected = u.transpose() * global;
    let outside = global - &u * &projected;
    *information += outside.transpose() * &outside;
    let kept = DMatrix::from_fn(values.len(), global.ncols(), |k, c| {
        let s2 = values[k] * values[k];
        (eps / (s2 + eps)).sqrt() * projected[(k, c)]
    });
    *information += kept.transpose() * kept;
    // Directions with less information than the prior, and those no row reaches.
    values.iter().filter(|&&v| v * v < eps).count() + size.saturating_sub(values.len())
}
