//! The normal equations `H dx = -g` in sparse form.
//!
//! A [`LinearSystem`] is built once per graph structure and answers three
//! questions, one part each:
//!
//! - where the free variables sit in the step vector (`offsets`, `dim`: the
//!   globals first, then each local group's variables together);
//! - where the entries of `H = J^T W J` (lower triangle) are stored and how
//!   each factor's `J^T J` and `J^T r` add into them (`HessianStorage`: per
//!   factor its runs of contiguous columns, see `accumulate`), accumulated
//!   ([`LinearSystem::accumulate`]) straight into the storage its
//!   factorisation reads;
//! - how `H + damping` is factored (`Factorization`): the block elimination
//!   of the local groups (`schur`; its dense zones read off the tangent
//!   layout, `block_elimination`), or faer's supernodal sparse Cholesky
//!   (`sparse_cholesky`; one dense block per pair of connected variables,
//!   read off the factors' slot pairs and scattered into faer's compressed
//!   columns, `sparse_pattern`), whose symbolic analysis (AMD ordering) is
//!   done once while every damping trial only refactors numerically into
//!   buffers allocated once.
//!
//! Beside them, a count of the work done by general loops for shapes outside
//! the table of `shapes` ([`LinearSystem::fallbacks`]).

use crate::error::SolverError;
use nalgebra::DMatrix;

use super::accumulate::FactorRuns;
use super::dense::zeroed;
use super::schur::SchurLayout;
use super::shapes::{FallbackCounter, Fallbacks};
use super::sparse_cholesky::SparseCholesky;
use crate::graph::{Factor, Values, VariableId};

mod block_elimination;
mod sparse_pattern;

/// The normal equations of a graph of one structure: where the free
/// variables sit in the tangent vector, where the entries of `H` are stored
/// and how each factor adds to them, and how `H + damping` is factored.
pub struct LinearSystem {
    /// Tangent offset of each variable (`None` when fixed), indexed by `VariableId`.
    pub offsets: Vec<Option<usize>>,
    /// Total tangent dimension of the free variables.
    pub dim: usize,
    /// The storage of `H` and how each factor adds into it.
    storage: HessianStorage,
    /// How `H + damping` is factored, with what that path alone needs.
    factorization: Factorization,
    /// The work done by general loops for shapes outside the table of `shapes`.
    fallbacks: FallbackCounter,
}

/// The storage of `H`'s lower triangle, laid out for the factorisation that
/// reads it, and where each factor's `J^T J` goes in it.
struct HessianStorage {
    /// Per factor, how its `J^T J` blocks add into the storage.
    factor_runs: Vec<FactorRuns>,
    /// Per tangent index, the storage position of its diagonal entry.
    diagonal_slots: Vec<usize>,
    /// Length of the storage.
    len: usize,
    /// Every stored block of the lower triangle and where it is stored.
    blocks: Vec<StoredBlock>,
}

/// One stored block of `H`: rows `row..row + rows`, columns `col..col + cols`
/// of the tangent vector (a diagonal block: its lower triangle), entry
/// `(i, j)` at `first + i + j * stride` of the storage.
struct StoredBlock {
    row: usize,
    col: usize,
    rows: usize,
    cols: usize,
    first: usize,
    stride: usize,
}

impl StoredBlock {
    /// `(tangent row, tangent column, storage position)` of each stored entry.
    fn entries(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        let diagonal = self.row == self.col;
        (0..self.cols).flat_map(move |j| {
            let first = if diagonal { j } else { 0 };
            (first..self.rows).map(move |i| (self.row + i, self.col + j, self.first + i + j * self.stride))
        })
    }
}

/// Largest tangent dimension of the global variables for block elimination
/// (its reduced system is a dense Cholesky of this size).
const MAX_SCHUR_GLOBALS: usize = 400;

/// How `H + damping` is factored.
enum Factorization {
    /// Block elimination of the local groups ([`SchurLayout`]).
    Schur(SchurLayout),
    /// faer's supernodal sparse Cholesky of the whole pattern (with the
    /// storage position of each of its entries).
    Sparse(Box<SparseCholesky>),
}

/// Where each free variable's tangent block sits in the step vector: the
/// global variables first, then each local group's free variables together.
struct TangentLayout {
    /// Per variable index, its offset (`None`: fixed).
    offsets: Vec<Option<usize>>,
    /// Length of the step vector.
    dim: usize,
    /// Length of the global part (before the first group).
    globals: usize,
    /// Per group with a free variable, `(start, length)` in the step vector.
    group_ranges: Vec<(usize, usize)>,
}

impl TangentLayout {
    fn new(values: &Values, local_groups: &[Vec<VariableId>]) -> Self {
        let mut offsets = vec![None; values.len()];
        let mut in_group = vec![false; values.len()];
        for id in local_groups.iter().flatten() {
            in_group[id.0] = true;
        }
        // Globals first, then each group's free variables together.
        let mut dim = 0;
        for (id, variable) in values.iter() {
            if !variable.fixed && !in_group[id.0] {
                offsets[id.0] = Some(dim);
                dim += variable.value.tangent_dim();
            }
        }
        let globals = dim;
        let mut group_ranges = Vec::with_capacity(local_groups.len());
        for group in local_groups {
            let start = dim;
            for &id in group {
                if !values.variable(id).fixed && offsets[id.0].is_none() {
                    offsets[id.0] = Some(dim);
                    dim += values.tangent_dim(id);
                }
            }
            if dim > start {
                group_ranges.push((start, dim - start));
            }
        }
        Self {
            offsets,
            dim,
            globals,
            group_ranges,
        }
    }
}

impl LinearSystem {
    /// Analyse the pattern of `H` for these factors and free variables.
    ///
    /// `local_groups` (see [`crate::graph::FactorGraph::local_groups`]): when
    /// every factor touches at most one group, the groups are eliminated
    /// block by block (`solver::schur`); otherwise, or without groups,
    /// `H` is factored by faer's supernodal sparse Cholesky.
    pub fn new(
        values: &Values,
        factors: &[Box<dyn Factor>],
        local_groups: &[Vec<VariableId>],
    ) -> Result<Self, SolverError> {
        let layout = TangentLayout::new(values, local_groups);
        if layout.dim == 0 {
            return Err(SolverError::NothingToSolve);
        }
        // `J^T J` is added by variable pairs: a variable named twice by one
        // factor would need the cross products of its two slots.
        for (index, factor) in factors.iter().enumerate() {
            let variables = factor.variables();
            if let Some((k, v)) = variables.iter().enumerate().find(|(k, v)| variables[..*k].contains(v)) {
                return Err(SolverError::RepeatedVariable {
                    index,
                    kind: factor.kind(),
                    variable: values.variable(*v).name.clone(),
                    slot: k,
                });
            }
        }
        // The reduced system of the elimination is dense: worth it while it is small.
        if !layout.group_ranges.is_empty()
            && layout.globals <= MAX_SCHUR_GLOBALS
            && !block_elimination::couples_two_groups(factors, &layout)
        {
            return Ok(Self::with_block_elimination(values, factors, layout));
        }
        Self::with_sparse_cholesky(values, factors, layout)
    }

    /// A zeroed value array for `H`.
    pub fn zero_hessian(&self) -> Vec<f64> {
        zeroed(self.storage.len)
    }

    /// Length of [`LinearSystem::zero_hessian`]'s array.
    pub fn zero_hessian_len(&self) -> usize {
        self.storage.len
    }

    /// Add factor `index`'s weighted `J^T J` blocks (whitened, robust-weighted
    /// Jacobian blocks `jacobians`, one per variable slot) into `hessian`, and
    /// `J^T r` into `gradient`; `rows_buffer` is scratch the caller reuses.
    pub fn accumulate(
        &self,
        index: usize,
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
        rows_buffer: &mut Vec<f64>,
    ) {
        self.storage.factor_runs[index].accumulate(
            jacobians,
            residual,
            hessian,
            gradient,
            rows_buffer,
            &self.fallbacks,
        );
    }

    /// The diagonal of `H` from its value array.
    pub fn diagonal(&self, hessian: &[f64]) -> Vec<f64> {
        self.storage.diagonal_slots.iter().map(|&k| hessian[k]).collect()
    }

    /// Factor `H + diag(damping)` (Cholesky); `false` if it is not
    /// numerically positive definite. Solves with [`LinearSystem::solve_factored`].
    pub fn factorize(&mut self, hessian: &[f64], damping: &[f64]) -> bool {
        match &mut self.factorization {
            Factorization::Schur(layout) => layout.factorize(hessian, damping, &self.fallbacks),
            Factorization::Sparse(sparse) => sparse.factorize(hessian, damping),
        }
    }

    /// Solve with the last successful [`LinearSystem::factorize`]; `None` if
    /// there is none or the solution is not finite.
    pub fn solve_factored(&mut self, rhs: &[f64]) -> Option<Vec<f64>> {
        match &mut self.factorization {
            Factorization::Schur(layout) => layout.solve(rhs, &self.fallbacks),
            Factorization::Sparse(sparse) => sparse.solve(rhs),
        }
    }

    /// The number of leading tangent indices (the globals) that the block
    /// elimination keeps in its reduced system; `None` for faer's path.
    pub(crate) fn eliminated_globals(&self) -> Option<usize> {
        match &self.factorization {
            Factorization::Schur(layout) => Some(layout.globals()),
            Factorization::Sparse(_) => None,
        }
    }

    /// The globals' part of the solution of `(H + damping) x = [rhs_globals; 0]`
    /// with the last successful factorisation, by the block elimination's
    /// reduced system alone (bit for bit the same part of
    /// [`LinearSystem::solve_factored`]); `None` without a factorisation, on
    /// faer's path, or if a value is not finite.
    pub(crate) fn solve_globals(&self, rhs_globals: &[f64]) -> Option<Vec<f64>> {
        match &self.factorization {
            Factorization::Schur(layout) => layout.solve_globals(rhs_globals),
            Factorization::Sparse(_) => None,
        }
    }

    /// `a^T (H + damping)^-1 a` with the last successful
    /// [`LinearSystem::factorize`] (a row's leverage when `a` is a whitened
    /// Jacobian row and the damping zero); `None` if there is no
    /// factorisation or the value is not finite. The block elimination visits
    /// only the groups where `a` is non-zero, with the same value as
    /// [`LinearSystem::solve_factored`] and the dot product.
    pub fn inverse_quadratic_form(&mut self, a: &[f64]) -> Option<f64> {
        if let Factorization::Schur(layout) = &self.factorization {
            return layout.inverse_quadratic_form(a);
        }
        let x = self.solve_factored(a)?;
        let form: f64 = a.iter().zip(&x).map(|(a, x)| a * x).sum();
        form.is_finite().then_some(form)
    }

    /// Whether the local groups are eliminated block by block (else faer's sparse Cholesky).
    pub fn uses_block_elimination(&self) -> bool {
        matches!(self.factorization, Factorization::Schur(_))
    }

    /// The products, group eliminations and group substitutions this
    /// system has done by general loops since it was built, for want of a
    /// fixed-size kernel for their shape (the table of the `shapes`
    /// module): zero for the catenary calibration graph, so a new factor
    /// shape shows here instead of only in the running time. The results do
    /// not depend on it.
    pub fn fallbacks(&self) -> Fallbacks {
        self.fallbacks.read()
    }

    /// Solve `(H + diag(damping)) x = rhs`; `None` if the matrix is not positive definite.
    pub fn solve(&mut self, hessian: &[f64], damping: &[f64], rhs: &[f64]) -> Option<Vec<f64>> {
        if !self.factorize(hessian, damping) {
            return None;
        }
        self.solve_factored(rhs)
    }

    /// `H` as a dense symmetric matrix (for the rank analysis of small problems).
    pub fn dense(&self, hessian: &[f64]) -> DMatrix<f64> {
        let mut dense = DMatrix::zeros(self.dim, self.dim);
        for (row, col, position) in self.storage.blocks.iter().flat_map(StoredBlock::entries) {
            dense[(row, col)] = hessian[position];
            dense[(col, row)] = hessian[position];
        }
        dense
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear residual `r = A [x_v1; x_v2; ...]` on vector variables.
    struct Linear {
        variables: Vec<VariableId>,
        a: DMatrix<f64>,
        noise: crate::graph::Noise,
    }

    impl Factor for Linear {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn residual_dim(&self) -> usize {
            self.a.nrows()
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<nalgebra::DVector<f64>> {
            let x: Vec<f64> = self
                .variables
                .iter()
                .flat_map(|&v| values.vector(v).iter().copied())
                .collect();
            if let Some(blocks) = jacobians {
                let mut column = 0;
                for block in blocks.iter_mut() {
                    let width = block.ncols();
                    block.copy_from(&self.a.columns(column, width));
                    column += width;
                }
            }
            Some(&self.a * nalgebra::DVector::from_vec(x))
        }
        fn noise(&self) -> &crate::graph::Noise {
            &self.noise
        }
        fn kind(&self) -> &'static str {
            "linear"
        }
    }

    /// A factor that names one variable twice is refused with an error that
    /// names the factor and the variable, on either storage.
    #[test]
    fn a_factor_naming_a_variable_twice_is_an_error() {
        let mut values = Values::new();
        let x = values.insert(
            "x",
            crate::graph::VariableValue::Vector(nalgebra::DVector::from_element(2, 1.0)),
        );
        let y = values.insert(
            "y",
            crate::graph::VariableValue::Vector(nalgebra::DVector::from_element(1, 1.0)),
        );
        let factor = |variables: Vec<VariableId>| -> Box<dyn Factor> {
            let cols = variables.iter().map(|&v| values.tangent_dim(v)).sum();
            Box::new(Linear {
                variables,
                a: DMatrix::from_element(2, cols, 1.0),
                noise: crate::graph::Noise::gaussian(nalgebra::DVector::from_element(2, 1.0)),
            })
        };
        let factors = vec![factor(vec![x, y]), factor(vec![y, x, y])];
        for groups in [Vec::new(), vec![vec![y]]] {
            let error = LinearSystem::new(&values, &factors, &groups)
                .err()
                .expect("an error")
                .to_string();
            assert!(error.contains("factor 1") && error.contains("'y' twice"), "{error}");
        }
        assert!(LinearSystem::new(&values, &factors[..1], &[]).is_ok());
    }

    /// `H` read back densely is the same `J^T J` whether it is stored for the
    /// block elimination or for faer's sparse Cholesky, and equals the
    /// product of the dense Jacobian (two globals of sizes 3 and 1, two
    /// local groups of sizes 2 + 1 and 2).
    #[test]
    fn dense_h_is_j_transpose_j_in_both_storages() {
        let mut values = Values::new();
        let vector =
            |n: usize, k: f64| crate::graph::VariableValue::Vector(nalgebra::DVector::from_fn(n, |i, _| k + i as f64));
        let g1 = values.insert("g1", vector(3, 0.5));
        let g2 = values.insert("g2", vector(1, -1.0));
        let l1 = values.insert("l1", vector(2, 2.0));
        let l2 = values.insert("l2", vector(1, 0.25));
        let l3 = values.insert("l3", vector(2, -0.75));
        let specs: Vec<(Vec<VariableId>, DMatrix<f64>)> = [
            (vec![l1, l2, g1, g2], 4, 0.1),
            (vec![l3, g1], 3, 0.7),
            (vec![g2, l3], 2, 1.3),
            (vec![g1], 3, 2.1),
            // The last global's columns end where the first group's begin:
            // consecutive in the step vector, but in two zones of the
            // elimination's storage (two runs, not one).
            (vec![g2, l1], 2, 0.3),
        ]
        .into_iter()
        .map(|(variables, rows, seed)| {
            let cols: usize = variables.iter().map(|&v| values.tangent_dim(v)).sum();
            let a = DMatrix::from_fn(rows, cols, |i, j| ((i * 7 + j * 3) as f64 * 0.61 + seed).sin());
            (variables, a)
        })
        .collect();
        let mut graph = crate::graph::FactorGraph::new();
        graph.values = values.clone();
        for (variables, a) in &specs {
            graph.factors.push(Box::new(Linear {
                variables: variables.clone(),
                a: a.clone(),
                noise: crate::graph::Noise::gaussian(nalgebra::DVector::from_element(a.nrows(), 0.5)),
            }));
        }
        let mut by_storage = Vec::new();
        for (local_groups, schur) in [(vec![vec![l1, l2], vec![l3]], true), (Vec::new(), false)] {
            let system = LinearSystem::new(&values, &graph.factors, &local_groups).unwrap();
            assert_eq!(system.uses_block_elimination(), schur);
            let linearized = crate::solver::linearization::linearize(&graph, &values, &system).unwrap();
            let dense = system.dense(&linearized.hessian);
            // The whitened dense Jacobian in the system's column order.
            let rows: usize = specs.iter().map(|(_, a)| a.nrows()).sum();
            let mut j = DMatrix::zeros(rows, system.dim);
            let mut row = 0;
            for (variables, a) in &specs {
                let mut column = 0;
                for &v in variables {
                    let width = values.tangent_dim(v);
                    let offset = system.offsets[v.0].unwrap();
                    j.view_mut((row, offset), (a.nrows(), width))
                        .copy_from(&(a.columns(column, width) / 0.5));
                    column += width;
                }
                row += a.nrows();
            }
            let expected = j.transpose() * &j;
            assert!((&dense - &expected).abs().max() < 1e-12, "{dense} {expected}");
            by_storage.push((dense, system.offsets.clone()));
        }
        // The same entries, bit for bit, up to the order of the tangent vector.
        let (schur_h, schur_offsets) = &by_storage[0];
        let (sparse_h, sparse_offsets) = &by_storage[1];
        for &a in &[g1, g2, l1, l2, l3] {
            for &b in &[g1, g2, l1, l2, l3] {
                for i in 0..values.tangent_dim(a) {
                    for k in 0..values.tangent_dim(b) {
                        let s = schur_h[(schur_offsets[a.0].unwrap() + i, schur_offsets[b.0].unwrap() + k)];
                        let t = sparse_h[(sparse_offsets[a.0].unwrap() + i, sparse_offsets[b.0].unwrap() + k)];
                        assert_eq!(s.to_bits(), t.to_bits());
                    }
                }
            }
        }
    }

    /// A shape outside the table of `shapes` is solved by the general loops
    /// and counted; the table's shapes are not. Globals of 16 columns (four
    /// 3-vectors, then four scalars: anchors and offsets) and a group of 8 (a
    /// 6-vector and a 2-vector: a pose and its tension), counted over one
    /// linearisation, factorisation and solve.
    #[test]
    fn a_shape_outside_the_table_is_counted() {
        let vector = |n: usize, k: f64| {
            crate::graph::VariableValue::Vector(nalgebra::DVector::from_fn(n, |i, _| k + 0.1 * i as f64))
        };
        let mut values = Values::new();
        let anchors: Vec<VariableId> = (0..4)
            .map(|i| values.insert(format!("anchor {i}"), vector(3, i as f64)))
            .collect();
        let offsets: Vec<VariableId> = (0..4)
            .map(|i| values.insert(format!("offset {i}"), vector(1, -(i as f64))))
            .collect();
        let pose = values.insert("pose", vector(6, 0.5));
        let tension = values.insert("tension", vector(2, 1.5));
        let lever = values.insert("lever", vector(3, 2.5));
        let factor = |variables: Vec<VariableId>, rows: usize| -> Box<dyn Factor> {
            let cols = variables.iter().map(|&v| values.tangent_dim(v)).sum();
            let seed = (rows * 10 + variables.len()) as f64;
            Box::new(Linear {
                variables,
                a: DMatrix::from_fn(rows, cols, |i, j| ((i * 7 + j * 3) as f64 * 0.61 + seed).sin()),
                noise: crate::graph::Noise::gaussian(nalgebra::DVector::from_element(rows, 0.5)),
            })
        };
        let globals = [anchors.clone(), offsets].concat();
        let group_and = |others: &[VariableId]| [vec![pose, tension], others.to_vec()].concat();
        // A length factor, a height factor, a pose prior, a tension factor.
        let table = || {
            vec![
                factor(group_and(&globals), 4),
                factor(group_and(&anchors), 4),
                factor(vec![pose], 6),
                factor(vec![tension], 1),
            ]
        };
        let count = |factors: Vec<Box<dyn Factor>>, groups: Vec<Vec<VariableId>>| {
            let mut graph = crate::graph::FactorGraph::new();
            graph.values = values.clone();
            // The lever is fixed unless it is a group of its own.
            graph.values.set_fixed(lever, !groups.contains(&vec![lever]));
            graph.factors = factors;
            let values = &graph.values;
            let mut system = LinearSystem::new(values, &graph.factors, &groups).unwrap();
            assert!(system.uses_block_elimination());
            let linearized = crate::solver::linearization::linearize(&graph, values, &system).unwrap();
            let ones = vec![1.0; system.dim];
            assert!(system.solve(&linearized.hessian, &ones, &ones).is_some());
            system.fallbacks()
        };
        let pose_group = vec![pose, tension];
        assert_eq!(count(table(), vec![pose_group.clone()]), Fallbacks::default());
        // Five rows: the three products of the group and the globals.
        let mut five_rows = table();
        five_rows.push(factor(group_and(&globals), 5));
        let expected = Fallbacks {
            products: 3,
            eliminations: 0,
            substitutions: 0,
        };
        assert_eq!(count(five_rows, vec![pose_group.clone()]), expected);
        // A group of 3: its products (3 x 3, 3 x 16), its elimination and its two substitutions.
        let mut lever_group = table();
        lever_group.push(factor([vec![lever], globals.clone()].concat(), 4));
        let expected = Fallbacks {
            products: 2,
            eliminations: 1,
            substitutions: 2,
        };
        assert_eq!(count(lever_group, vec![pose_group, vec![lever]]), expected);
    }
}
