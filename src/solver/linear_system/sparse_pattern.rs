//! The pattern of `H` for faer's sparse Cholesky, read off the factors'
//! slot pairs: one dense column-major block per pair of connected free
//! variables, stored in the order first touched, and every entry of the
//! lower triangle handed to faer with its storage position.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::{Factorization, HessianStorage, LinearSystem, StoredBlock, TangentLayout};
use crate::error::SolverError;
use crate::graph::{Factor, Values, VariableId};
use crate::solver::accumulate::{FactorRuns, SlotBlock};
use crate::solver::shapes::FallbackCounter;
use crate::solver::sparse_cholesky::SparseCholesky;

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
    /// The pattern for faer's sparse Cholesky: every block a factor touches,
    /// stored column-major from its start, in the order first touched.
    pub(super) fn with_sparse_cholesky(
        values: &Values,
        factors: &[Box<dyn Factor>],
        layout: TangentLayout,
    ) -> Result<Self, SolverError> {
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
        let sparse = SparseCholesky::new(&indices, positions, layout.dim)?;
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
            storage: HessianStorage {
                factor_runs,
                diagonal_slots,
                len: pattern.entry_count,
                blocks,
            },
            factorization: Factorization::Sparse(Box::new(sparse)),
            fallbacks: FallbackCounter::default(),
        })
    }
}
