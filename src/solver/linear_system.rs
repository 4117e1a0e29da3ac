//! The normal equations `H dx = -g` in sparse form.
//!
//! The sparsity pattern of `H = J^T W J` (lower triangle) follows from which
//! variables share a factor. It is built once per problem at the block level
//! (one dense block per pair of connected free variables), its symbolic
//! Cholesky (AMD ordering, supernodal) is computed once, and every damping
//! trial only refactors numerically into buffers allocated once
//! (`SymbolicCholesky::factorize_numeric_llt`, single-threaded).
//!
//! `H` is accumulated block by block ([`LinearSystem::accumulate`]) straight
//! into the storage its factorisation reads: the dense blocks of the block
//! elimination (`schur`), copied whole before each factorisation, or one
//! dense column-major block per pair of variables, scattered into faer's
//! compressed columns.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::DMatrix;

use super::accumulate::{FactorRuns, SlotBlock};
use super::dense::zeroed;
use super::schur::SchurLayout;
use super::sparse_cholesky::SparseCholesky;
use crate::graph::{Factor, Values, VariableId};

/// Where the free variables sit in the tangent vector, and the pattern of `H`.
pub struct LinearSystem {
    /// Tangent offset of each variable (`None` when fixed), indexed by `VariableId`.
    pub offsets: Vec<Option<usize>>,
    /// Total tangent dimension of the free variables.
    pub dim: usize,
    /// Per factor, how its `J^T J` blocks add into the storage of `H`.
    factor_runs: Vec<FactorRuns>,
    /// Per tangent index, the storage position of its diagonal entry.
    diagonal_slots: Vec<usize>,
    /// Per tangent index, the index in `positions` of its diagonal entry
    /// (faer's sparse Cholesky only; empty for the block elimination).
    diagonal_entries: Vec<usize>,
    /// Length of the storage of `H`.
    storage_len: usize,
    /// Storage position of every entry of the lower triangle, in the order
    /// of the sparse Cholesky's pattern (faer's sparse Cholesky only).
    positions: Vec<usize>,
    /// Every stored block of the lower triangle and where it is stored.
    blocks: Vec<StoredBlock>,
    factorization: Factorization,
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
    /// faer's supernodal sparse Cholesky of the whole pattern.
    Sparse(Box<SparseCholesky>),
}

/// Block starts by `(row variable, column variable)` index.
type BlockMap = HashMap<(usize, usize), usize, BuildHasherDefault<IndexHasher>>;

/// A multiplicative hasher for small integer keys (variable indices): the
/// pattern analysis looks up one block per pair of variables of every
/// factor, and the default SipHash dominated it.
#[derive(Default)]
struct IndexHasher(u64);

impl Hasher for IndexHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
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

mod block_elimination;

/// The stored blocks of the lower triangle of `H`, in storage order, and
/// where each factor's slot pairs accumulate.
struct BlockPattern {
    blocks: BlockMap,
    /// `(row variable, column variable, start)` of each block, in storage order.
    block_order: Vec<(VariableId, VariableId, usize)>,
    /// Number of stored scalars.
    entry_count: usize,
    /// Per factor: the blocks it touches (start in the block-wise storage, stride: rows of the block).
    factor_blocks: Vec<Vec<SlotBlock>>,
}

impl BlockPattern {
    fn new(values: &Values, factors: &[Box<dyn Factor>], offsets: &[Option<usize>]) -> Self {
        let mut pattern = Self {
            blocks: BlockMap::default(),
            block_order: Vec::new(),
            entry_count: 0,
            factor_blocks: Vec::with_capacity(factors.len()),
        };
        // Every free variable gets its diagonal block, even if no factor touches it
        // (then H is singular and the solver reports it instead of crashing).
        for (id, _) in values.iter() {
            if offsets[id.0].is_some() {
                pattern.block_for(values, id, id);
            }
        }
        for factor in factors {
            let vars = factor.variables();
            let mut list = Vec::with_capacity(vars.len() * (vars.len() + 1) / 2);
            for (slot_a, &a) in vars.iter().enumerate() {
                let Some(oa) = offsets[a.0] else {
                    continue;
                };
                let stride = values.tangent_dim(a);
                for (slot_b, &b) in vars.iter().enumerate() {
                    let Some(ob) = offsets[b.0] else {
                        continue;
                    };
                    if oa < ob || (a == b && slot_a != slot_b) {
                        continue;
                    }
                    list.push(SlotBlock {
                        slot_a,
                        slot_b,
                        start: pattern.block_for(values, a, b),
                        stride,
                    });
                }
            }
            pattern.factor_blocks.push(list);
        }
        pattern
    }

    /// The start of block `(a, b)` (dense, column-major; a diagonal block's
    /// upper triangle is never written), stored after the others if new.
    fn block_for(&mut self, values: &Values, a: VariableId, b: VariableId) -> usize {
        let entry_count = &mut self.entry_count;
        let block_order = &mut self.block_order;
        *self.blocks.entry((a.0, b.0)).or_insert_with(|| {
            let start = *entry_count;
            *entry_count += values.tangent_dim(a) * values.tangent_dim(b);
            block_order.push((a, b, start));
            start
        })
    }
}

impl LinearSystem {
    /// Analyse the pattern of `H` for these factors and free variables.
    ///
    /// `local_groups` (see [`crate::graph::FactorGraph::local_groups`]): when
    /// every factor touches at most one group, the groups are eliminated
    /// block by block (`solver::schur`); otherwise, or without groups,
    /// `H` is factored by faer's supernodal sparse Cholesky.
    pub fn new(values: &Values, factors: &[Box<dyn Factor>], local_groups: &[Vec<VariableId>]) -> Result<Self, String> {
        let layout = TangentLayout::new(values, local_groups);
        if layout.dim == 0 {
            return Err("every variable is fixed: nothing to solve".into());
        }
        // `J^T J` is added by variable pairs: a variable named twice by one
        // factor would need the cross products of its two slots.
        for (index, factor) in factors.iter().enumerate() {
            let variables = factor.variables();
            if let Some((k, v)) = variables.iter().enumerate().find(|(k, v)| variables[..*k].contains(v)) {
                return Err(format!(
                    "factor {index} ({}) names variable '{}' twice (slot {k}): a factor's variables must be distinct",
                    factor.kind(),
                    values.variable(*v).name
                ));
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

    /// The pattern for faer's sparse Cholesky: every block a factor touches,
    /// stored column-major from its start, in the order first touched.
    fn with_sparse_cholesky(
        values: &Values,
        factors: &[Box<dyn Factor>],
        layout: TangentLayout,
    ) -> Result<Self, String> {
        let pattern = BlockPattern::new(values, factors, &layout.offsets);
        let offset = |v: VariableId| layout.offsets[v.0].unwrap_or(0);
        let block = |&(a, b, start): &(VariableId, VariableId, usize)| StoredBlock {
            row: offset(a),
            col: offset(b),
            rows: values.tangent_dim(a),
            cols: values.tangent_dim(b),
            first: start,
            stride: values.tangent_dim(a),
        };
        let blocks: Vec<StoredBlock> = pattern.block_order.iter().map(block).collect();
        let entries = blocks.iter().flat_map(StoredBlock::entries);
        let (indices, positions): (Vec<(usize, usize)>, Vec<usize>) =
            entries.map(|(row, col, position)| ((row, col), position)).unzip();
        let mut diagonal_entries = vec![0; layout.dim];
        for (k, &(row, col)) in indices.iter().enumerate() {
            if row == col {
                diagonal_entries[row] = k;
            }
        }
        let sparse = SparseCholesky::new(&indices, layout.dim)?;
        let mut diagonal_slots = vec![0; layout.dim];
        for block in blocks.iter().filter(|b| b.row == b.col) {
            for i in 0..block.rows {
                diagonal_slots[block.row + i] = block.first + i + i * block.stride;
            }
        }
        let mut dims = Vec::new();
        let factor_runs = factors
            .iter()
            .zip(&pattern.factor_blocks)
            .map(|(factor, blocks)| {
                let variables = factor.variables();
                dims.clear();
                dims.extend(variables.iter().map(|&v| values.tangent_dim(v)));
                FactorRuns::new(variables, &layout.offsets, &dims, blocks)
            })
            .collect();
        Ok(Self {
            offsets: layout.offsets,
            dim: layout.dim,
            factor_runs,
            diagonal_slots,
            diagonal_entries,
            storage_len: pattern.entry_count,
            positions,
            blocks,
            factorization: Factorization::Sparse(Box::new(sparse)),
        })
    }

    /// A zeroed value array for `H`.
    pub fn zero_hessian(&self) -> Vec<f64> {
        zeroed(self.storage_len)
    }

    /// Length of [`LinearSystem::zero_hessian`]'s array.
    pub fn zero_hessian_len(&self) -> usize {
        self.storage_len
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
        self.factor_runs[index].accumulate(jacobians, residual, hessian, gradient, rows_buffer);
    }

    /// The diagonal of `H` from its value array.
    pub fn diagonal(&self, hessian: &[f64]) -> Vec<f64> {
        self.diagonal_slots.iter().map(|&k| hessian[k]).collect()
    }

    /// Factor `H + diag(damping)` (Cholesky); `false` if it is not
    /// numerically positive definite. Solves with [`LinearSystem::solve_factored`].
    pub fn factorize(&mut self, hessian: &[f64], damping: &[f64]) -> bool {
        let sparse = match &mut self.factorization {
            Factorization::Schur(layout) => return layout.factorize(hessian, damping),
            Factorization::Sparse(sparse) => sparse,
        };
        sparse.factorize(hessian, &self.positions, &self.diagonal_entries, damping)
    }

    /// Solve with the last successful [`LinearSystem::factorize`]; `None` if
    /// there is none or the solution is not finite.
    pub fn solve_factored(&mut self, rhs: &[f64]) -> Option<Vec<f64>> {
        let sparse = match &mut self.factorization {
            Factorization::Schur(layout) => return layout.solve(rhs),
            Factorization::Sparse(sparse) => sparse,
        };
        sparse.solve(rhs)
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
        for (row, col, position) in self.blocks.iter().flat_map(StoredBlock::entries) {
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
        sigmas: nalgebra::DVector<f64>,
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
        fn sigmas(&self) -> &nalgebra::DVector<f64> {
            &self.sigmas
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
                sigmas: nalgebra::DVector::from_element(2, 1.0),
            })
        };
        let factors = vec![factor(vec![x, y]), factor(vec![y, x, y])];
        for groups in [Vec::new(), vec![vec![y]]] {
            let error = LinearSystem::new(&values, &factors, &groups).err().expect("an error");
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
                sigmas: nalgebra::DVector::from_element(a.nrows(), 0.5),
            }));
        }
        let mut by_storage = Vec::new();
        for (local_groups, schur) in [(vec![vec![l1, l2], vec![l3]], true), (Vec::new(), false)] {
            let system = LinearSystem::new(&values, &graph.factors, &local_groups).unwrap();
            assert_eq!(system.uses_block_elimination(), schur);
            let linearized = crate::solver::linearize(&graph, &values, &system).unwrap();
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
}
