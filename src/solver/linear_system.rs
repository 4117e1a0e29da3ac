//! The normal equations `H dx = -g` in sparse form.
//!
//! The sparsity pattern of `H = J^T W J` (lower triangle) follows from which
//! variables share a factor. It is built once per problem at the block level
//! (one dense block per pair of connected free variables), its symbolic
//! Cholesky (AMD ordering) is computed once, and every damping trial only
//! refactors numerically (faer's `Llt::try_new_with_symbolic`).

use std::collections::HashMap;

use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, Mat, Side};
use nalgebra::DMatrix;

use crate::graph::{Factor, Values, VariableId};

/// Where the free variables sit in the tangent vector, and the pattern of `H`.
pub struct LinearSystem {
    /// Tangent offset of each variable (`None` when fixed), indexed by `VariableId`.
    pub offsets: Vec<Option<usize>>,
    /// Total tangent dimension of the free variables.
    pub dim: usize,
    /// Per factor, per pair `(a, b)` of its free variable slots with `offset(a) >= offset(b)`: start of that block in `values`.
    factor_blocks: Vec<Vec<(usize, usize, usize)>>,
    /// Diagonal entry positions in `values`, per tangent index.
    diagonal_slots: Vec<usize>,
    /// Number of stored entries (lower triangle, block-wise).
    entry_count: usize,
    pattern: SymbolicSparseColMat<usize>,
    argsort: faer::sparse::Argsort<usize>,
    symbolic: SymbolicLlt<usize>,
}

/// A block of `H` between variables `row_var` (larger offset) and `col_var`.
struct BlockLayout {
    start: usize,
}

impl LinearSystem {
    /// Analyse the pattern of `H` for these factors and free variables.
    pub fn new(values: &Values, factors: &[Box<dyn Factor>]) -> Result<Self, String> {
        let mut offsets = vec![None; values.len()];
        let mut dim = 0;
        for (id, variable) in values.iter() {
            if !variable.fixed {
                offsets[id.0] = Some(dim);
                dim += variable.value.tangent_dim();
            }
        }
        if dim == 0 {
            return Err("every variable is fixed: nothing to solve".into());
        }
        let tangent = |id: VariableId| values.tangent_dim(id);
        let mut blocks: HashMap<(usize, usize), BlockLayout> = HashMap::new();
        let mut block_order: Vec<(VariableId, VariableId)> = Vec::new();
        let mut entry_count = 0;
        let mut factor_blocks = Vec::with_capacity(factors.len());
        let mut block_for =
            |a: VariableId, b: VariableId, blocks: &mut HashMap<(usize, usize), BlockLayout>| -> usize {
                let layout = blocks.entry((a.0, b.0)).or_insert_with(|| {
                    let size = if a == b {
                        tangent(a) * (tangent(a) + 1) / 2
                    } else {
                        tangent(a) * tangent(b)
                    };
                    let start = entry_count;
                    entry_count += size;
                    block_order.push((a, b));
                    BlockLayout { start }
                });
                layout.start
            };
        // Every free variable gets its diagonal block, even if no factor touches it
        // (then H is singular and the solver reports it instead of crashing).
        for (id, _) in values.iter() {
            if offsets[id.0].is_some() {
                block_for(id, id, &mut blocks);
            }
        }
        for factor in factors {
            let vars = factor.variables();
            let mut list = Vec::new();
            for (slot_a, &a) in vars.iter().enumerate() {
                for (slot_b, &b) in vars.iter().enumerate() {
                    let (Some(oa), Some(ob)) = (offsets[a.0], offsets[b.0]) else {
                        continue;
                    };
                    if oa < ob || (a == b && slot_a != slot_b) {
                        continue;
                    }
                    list.push((slot_a, slot_b, block_for(a, b, &mut blocks)));
                }
            }
            factor_blocks.push(list);
        }
        // Scalar (row, col) of every stored entry, in storage order.
        let mut indices = vec![
            Pair {
                row: 0usize,
                col: 0usize
            };
            entry_count
        ];
        let mut diagonal_slots = vec![0; dim];
        for &(a, b) in &block_order {
            let start = blocks[&(a.0, b.0)].start;
            let (oa, ob) = (offsets[a.0].unwrap_or(0), offsets[b.0].unwrap_or(0));
            let (da, db) = (tangent(a), tangent(b));
            let mut k = start;
            for j in 0..db {
                for i in 0..da {
                    if a == b && i < j {
                        continue;
                    }
                    indices[k] = Pair {
                        row: oa + i,
                        col: ob + j,
                    };
                    if a == b && i == j {
                        diagonal_slots[oa + i] = k;
                    }
                    k += 1;
                }
            }
        }
        let (pattern, argsort) = SymbolicSparseColMat::try_new_from_indices(dim, dim, &indices)
            .map_err(|e| format!("cannot build the sparsity pattern: {e:?}"))?;
        let symbolic = SymbolicLlt::try_new(pattern.as_ref(), Side::Lower)
            .map_err(|e| format!("symbolic Cholesky failed: {e:?}"))?;
        Ok(Self {
            offsets,
            dim,
            factor_blocks,
            diagonal_slots,
            entry_count,
            pattern,
            argsort,
            symbolic,
        })
    }

    /// A zeroed value array for `H`.
    pub fn zero_hessian(&self) -> Vec<f64> {
        vec![0.0; self.entry_count]
    }

    /// Add factor `index`'s weighted `J^T J` blocks (whitened, robust-weighted
    /// Jacobian blocks `jacobians`) into `hessian`, and `J^T r` into `gradient`.
    pub fn accumulate(
        &self,
        index: usize,
        variables: &[VariableId],
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
    ) {
        for (slot, &var) in variables.iter().enumerate() {
            if let Some(offset) = self.offsets[var.0] {
                let jac = &jacobians[slot];
                for c in 0..jac.ncols() {
                    let mut sum = 0.0;
                    for r in 0..jac.nrows() {
                        sum += jac[(r, c)] * residual[r];
                    }
                    gradient[offset + c] += sum;
                }
            }
        }
        for &(slot_a, slot_b, start) in &self.factor_blocks[index] {
            let (ja, jb) = (&jacobians[slot_a], &jacobians[slot_b]);
            let same = variables[slot_a] == variables[slot_b];
            let mut k = start;
            for j in 0..jb.ncols() {
                for i in 0..ja.ncols() {
                    if same && i < j {
                        continue;
                    }
                    let mut sum = 0.0;
                    for r in 0..ja.nrows() {
                        sum += ja[(r, i)] * jb[(r, j)];
                    }
                    hessian[k] += sum;
                    k += 1;
                }
            }
        }
    }

    /// The diagonal of `H` from its value array.
    pub fn diagonal(&self, hessian: &[f64]) -> Vec<f64> {
        self.diagonal_slots.iter().map(|&k| hessian[k]).collect()
    }

    /// Solve `(H + diag(damping)) x = rhs`; `None` if the matrix is not positive definite.
    pub fn solve(&self, hessian: &[f64], damping: &[f64], rhs: &[f64]) -> Option<Vec<f64>> {
        let mut values = hessian.to_vec();
        for (i, &k) in self.diagonal_slots.iter().enumerate() {
            values[k] += damping[i];
        }
        let matrix = SparseColMat::new_from_argsort(self.pattern.clone(), &self.argsort, &values).ok()?;
        let llt = Llt::try_new_with_symbolic(self.symbolic.clone(), matrix.as_ref(), Side::Lower).ok()?;
        let mut x = Mat::<f64>::from_fn(self.dim, 1, |i, _| rhs[i]);
        llt.solve_in_place_with_conj(Conj::No, x.as_mut());
        let solution: Vec<f64> = (0..self.dim).map(|i| x[(i, 0)]).collect();
        solution.iter().all(|v| v.is_finite()).then_some(solution)
    }

    /// `H` as a dense symmetric matrix (for the rank analysis of small problems).
    pub fn dense(&self, hessian: &[f64]) -> DMatrix<f64> {
        let matrix = SparseColMat::new_from_argsort(self.pattern.clone(), &self.argsort, hessian);
        let mut dense = DMatrix::zeros(self.dim, self.dim);
        if let Ok(matrix) = matrix {
            for col in 0..self.dim {
                let rows = matrix.symbolic().row_idx_of_col_raw(col);
                let vals = matrix.val_of_col(col);
                for (&row, &v) in rows.iter().zip(vals) {
                    dense[(row, col)] = v;
                    dense[(col, row)] = v;
                }
            }
        }
        dense
    }
}
