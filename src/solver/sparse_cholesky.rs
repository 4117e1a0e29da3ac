//! faer's supernodal sparse Cholesky of `H`, for graphs whose structure
//! the block elimination (`schur`) does not serve: the symbolic analysis
//! once, then numerical factorisations and solves into buffers allocated once.

use crate::error::SolverError;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::{LltParams, LltRegularization};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};

/// faer's sparse Cholesky: the symbolic analysis (AMD ordering, supernodal)
/// done once, and numerical buffers reused by every factorisation.
pub(super) struct SparseCholesky {
    /// The lower triangle of `H`, compressed columns.
    pattern: SymbolicSparseColMat<usize>,
    /// Per entry of the lower triangle (in the order given to [`SparseCholesky::new`]), its index in the compressed-column values.
    csc_position: Vec<usize>,
    /// Per entry of the lower triangle (the same order), its position in the storage of `H`.
    positions: Vec<usize>,
    /// Per tangent index, the entry (the same order) of its diagonal element.
    diagonal_entries: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// `H + damping` in compressed-column order.
    matrix_values: Vec<f64>,
    /// Values of the Cholesky factor.
    factor_values: Vec<f64>,
    /// Scratch memory of faer's factorisation and triangular solves.
    scratch: MemBuffer,
    /// Whether `factor_values` holds a valid factorisation.
    factored: bool,
    /// The dimension of `H`.
    dim: usize,
}

impl SparseCholesky {
    /// The pattern of `H`'s lower triangle (`indices`: `(row, col)` of
    /// every entry, `row >= col`; `positions`: where each entry is stored in
    /// `H`'s value array) analysed for a `dim x dim` system.
    pub(super) fn new(indices: &[(usize, usize)], positions: Vec<usize>, dim: usize) -> Result<Self, SolverError> {
        let mut diagonal_entries = vec![0; dim];
        for (k, &(row, col)) in indices.iter().enumerate() {
            if row == col {
                diagonal_entries[row] = k;
            }
        }
        let entry_count = indices.len();
        // Compressed columns: sort the entries by (column, row).
        let order = column_major_order(indices, dim);
        let mut col_ptr = vec![0usize; dim + 1];
        let mut row_idx = Vec::with_capacity(entry_count);
        let mut csc_position = vec![0usize; entry_count];
        for (position, &k) in order.iter().enumerate() {
            let (row, col) = indices[k];
            col_ptr[col + 1] += 1;
            row_idx.push(row);
            csc_position[k] = position;
        }
        for col in 0..dim {
            col_ptr[col + 1] += col_ptr[col];
        }
        let pattern = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| SolverError::SymbolicCholesky(format!("{e:?}")))?;
        let scratch = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::<LltParams, f64>::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Ok(Self {
            matrix_values: vec![0.0; entry_count],
            factor_values: vec![0.0; symbolic.len_val()],
            scratch: MemBuffer::try_new(scratch).map_err(|_| SolverError::OutOfMemory)?,
            factored: false,
            dim,
            symbolic,
            pattern,
            csc_position,
            positions,
            diagonal_entries,
        })
    }

    /// Factor `H + diag(damping)`, `H` read from `hessian` at the positions
    /// given to [`SparseCholesky::new`]; `false` if it is not finite or not
    /// numerically positive definite.
    pub(super) fn factorize(&mut self, hessian: &[f64], damping: &[f64]) -> bool {
        self.factored = false;
        for (&csc, &position) in self.csc_position.iter().zip(&self.positions) {
            self.matrix_values[csc] = hessian[position];
        }
        for (i, &k) in self.diagonal_entries.iter().enumerate() {
            self.matrix_values[self.csc_position[k]] += damping[i];
        }
        if self.matrix_values.iter().any(|v| !v.is_finite()) {
            return false;
        }
        let matrix = SparseColMatRef::new(self.pattern.as_ref(), &self.matrix_values);
        let factored = self.symbolic.factorize_numeric_llt(
            &mut self.factor_values,
            matrix,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.scratch),
            Spec::default(),
        );
        self.factored = factored.is_ok();
        self.factored
    }

    /// Solve with the last successful [`SparseCholesky::factorize`]; `None`
    /// if there is none or the solution is not finite.
    pub(super) fn solve(&mut self, rhs: &[f64]) -> Option<Vec<f64>> {
        if !self.factored {
            return None;
        }
        let mut solution = rhs.to_vec();
        let llt = LltRef::new(&self.symbolic, &self.factor_values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut solution, self.dim, 1),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        solution.iter().all(|v| v.is_finite()).then_some(solution)
    }
}

/// The permutation that sorts `(row, col)` entries by column, then row: two
/// stable counting sorts (by row, then by column), linear in the entries.
fn column_major_order(indices: &[(usize, usize)], dim: usize) -> Vec<usize> {
    let counting_sort = |order: &[usize], key: &dyn Fn(usize) -> usize| -> Vec<usize> {
        let mut start = vec![0usize; dim + 1];
        for &k in order {
            start[key(k) + 1] += 1;
        }
        for i in 0..dim {
            start[i + 1] += start[i];
        }
        let mut sorted = vec![0usize; order.len()];
        for &k in order {
            let slot = &mut start[key(k)];
            sorted[*slot] = k;
            *slot += 1;
        }
        sorted
    };
    let identity: Vec<usize> = (0..indices.len()).collect();
    let by_row = counting_sort(&identity, &|k| indices[k].0);
    counting_sort(&by_row, &|k| indices[k].1)
}
