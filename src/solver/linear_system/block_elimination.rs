//! The pattern of `H` for the block elimination (`solver::schur`), read off
//! the tangent layout instead of the factors' slot pairs.
//!
//! The elimination stores `H` as dense zones: the globals' `g x g` lower
//! triangle, and per local group its `m x m` lower triangle and its `m x g`
//! coupling to the globals ([`SchurLayout::place`]). Inside a zone the
//! entry `(row, col)` sits at `first + row + col * stride` for one `first`
//! and `stride`, so any run of consecutive tangent columns inside one zone
//! is one dense block: a factor's `J^T J` goes to `H` by the products of its
//! runs (`FactorRuns::in_zones`) with no per-slot-pair bookkeeping, which
//! the general pattern (`sparse_pattern`'s `BlockPattern`: one hash lookup per slot
//! pair) spent most of a small solve's setup on. Every entry still receives
//! the same sum in the same order (the kernels are the same), so a system
//! built this way solves bit for bit as one built from the slot pairs
//! (unit test `dense_h_is_j_transpose_j_in_both_storages` and the
//! calibration outputs).

use super::{Factorization, HessianStorage, LinearSystem, StoredBlock, TangentLayout};
use crate::graph::{Factor, Values};
use crate::solver::accumulate::FactorRuns;
use crate::solver::schur::SchurLayout;
use crate::solver::shapes::FallbackCounter;

/// Whether a factor has free variables in two different local groups (the
/// elimination then does not apply).
pub(super) fn couples_two_groups(factors: &[Box<dyn Factor>], layout: &TangentLayout) -> bool {
    let group_of = |offset: usize| layout.group_ranges.partition_point(|&(start, _)| start <= offset) - 1;
    factors.iter().any(|factor| {
        let mut groups = factor
            .variables()
            .iter()
            .filter_map(|v| layout.offsets[v.0])
            .filter(|&offset| offset >= layout.globals)
            .map(group_of);
        groups.next().is_some_and(|first| groups.any(|k| k != first))
    })
}

impl LinearSystem {
    /// The system for the block elimination of `layout`'s local groups (no
    /// factor couples two of them: [`couples_two_groups`]).
    pub(super) fn with_block_elimination(values: &Values, factors: &[Box<dyn Factor>], layout: TangentLayout) -> Self {
        let g = layout.globals;
        let schur = SchurLayout::zones(g, layout.group_ranges.clone());
        // The stored zones, for `dense` (every entry of a zone is stored,
        // zero where no factor adds to it).
        let mut blocks = Vec::with_capacity(1 + 2 * layout.group_ranges.len());
        let zone = |row: usize, col: usize, rows: usize, cols: usize| {
            let (first, stride) = schur.place(row, col);
            StoredBlock {
                row,
                col,
                rows,
                cols,
                first,
                stride,
            }
        };
        if g > 0 {
            blocks.push(zone(0, 0, g, g));
        }
        for &(start, m) in &layout.group_ranges {
            blocks.push(zone(start, start, m, m));
            if g > 0 {
                blocks.push(zone(start, 0, m, g));
            }
        }
        let diagonal_slots = (0..layout.dim).map(|i| schur.place(i, i).0).collect();
        let mut dims = Vec::new();
        // The factors' variables are distinct (checked by `LinearSystem::new`).
        let factor_runs = factors
            .iter()
            .map(|factor| {
                let variables = factor.variables();
                dims.clear();
                dims.extend(variables.iter().map(|&v| values.tangent_dim(v)));
                FactorRuns::in_zones(variables, &layout.offsets, &dims, &schur)
            })
            .collect();
        LinearSystem {
            offsets: layout.offsets,
            dim: layout.dim,
            storage: HessianStorage {
                factor_runs,
                diagonal_slots,
                len: schur.storage_len(),
                blocks,
            },
            factorization: Factorization::Schur(schur),
            fallbacks: FallbackCounter::default(),
        }
    }
}
