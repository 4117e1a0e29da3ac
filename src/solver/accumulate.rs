//! One factor's `J^T J` and `J^T r`, added to the storage of `H` by runs of
//! contiguous columns.
//!
//! A factor's free variables whose tangent columns follow each other in the
//! step vector, and whose blocks of `H` sit next to each other in its
//! storage, form a *run*: a pose and its reference tension (the group `D_k`
//! of the block elimination), or the four anchors and four offsets (the dense
//! reduced system `A`). The product of two runs is then one dense block of
//! `H` (for a pose's length rows: `8 x 8`, `16 x 8` and `16 x 16`) instead of
//! up to 55 small ones per variable pair. Each run's Jacobian columns are
//! gathered row by row, so that neighbouring entries of a column of `H` are
//! neighbouring SIMD lanes; every entry still adds `sum_r a_r b_r` with the
//! rows in order, so the sums are those of the variable-by-variable loop.
//! Where the storage does not line up (faer's compressed columns), every
//! variable is a run of its own.

use nalgebra::DMatrix;

use crate::graph::VariableId;

use super::shapes::{
    avx2_run_shapes, portable_run_shapes, run_shapes, FallbackCounter, ANCHORS, CABLE_ROWS, GLOBALS, GROUP, POSE,
    PRIOR_ROWS, TENSION,
};
use super::simd;

/// Consecutive factor slots `first_slot..end_slot` whose tangent columns are
/// `offset..offset + width` of the step vector, and `column..column + width`
/// of the factor's gathered columns (the widths of the runs before it).
#[derive(Clone, Copy, Debug)]
struct Run {
    first_slot: usize,
    end_slot: usize,
    offset: usize,
    width: usize,
    column: usize,
}

/// The product `J_a^T J_b` of runs `a` and `b` (`a`'s columns have the larger
/// tangent indices; `a == b`: the lower triangle) goes to the storage of `H`
/// at `start + i + j * stride` (`i` a column of run `a`, `j` of run `b`).
#[derive(Clone, Copy, Debug)]
struct RunBlock {
    run_a: usize,
    run_b: usize,
    start: usize,
    stride: usize,
}

/// Where one slot pair's block of `H` is stored: `J_a^T J_b` for the factor's
/// slots `slot_a`, `slot_b` (`offset(a) >= offset(b)`) at `start + i + j * stride`.
#[derive(Clone, Copy, Debug)]
pub(super) struct SlotBlock {
    pub slot_a: usize,
    pub slot_b: usize,
    pub start: usize,
    pub stride: usize,
}

/// How one factor adds into `H`: its runs and the blocks between them.
#[derive(Clone, Debug, Default)]
pub(super) struct FactorRuns {
    runs: Vec<Run>,
    blocks: Vec<RunBlock>,
    /// Free tangent columns of the factor (the sum of the run widths).
    columns: usize,
}

impl FactorRuns {
    /// The runs of a factor on `variables` (tangent `offsets` by variable
    /// index, `None`: fixed; `dims` per slot), given where each of its slot
    /// pairs is stored (`slot_blocks`). Slots are merged into runs only where
    /// every merged block's entries land exactly where the slot pairs' would.
    /// The variables are distinct (`LinearSystem::new` refuses a factor that
    /// names one twice).
    pub(super) fn new(
        variables: &[VariableId],
        offsets: &[Option<usize>],
        dims: &[usize],
        slot_blocks: &[SlotBlock],
    ) -> Self {
        let runs = merged_runs(variables, offsets, dims, |_, _| true);
        Self::from_runs(runs, variables, offsets, slot_blocks)
            .unwrap_or_else(|| Self::singletons(variables, offsets, dims, slot_blocks))
    }

    /// The runs of a factor whose variables are distinct, in the block
    /// elimination's storage (`schur`): consecutive free slots with
    /// consecutive tangent columns inside one zone (the globals, or one
    /// group) form a run, and the product of two runs is the dense block
    /// at `schur.place` of their first columns.
    pub(super) fn in_zones(
        variables: &[VariableId],
        offsets: &[Option<usize>],
        dims: &[usize],
        schur: &super::schur::SchurLayout,
    ) -> Self {
        let runs = merged_runs(variables, offsets, dims, |run, offset| {
            offset < schur.zone_end(run.offset)
        });
        let mut blocks = Vec::with_capacity(runs.len() * (runs.len() + 1) / 2);
        for (ka, a) in runs.iter().enumerate() {
            for (kb, b) in runs.iter().enumerate() {
                if a.offset >= b.offset {
                    let (start, stride) = schur.place(a.offset, b.offset);
                    blocks.push(RunBlock {
                        run_a: ka,
                        run_b: kb,
                        start,
                        stride,
                    });
                }
            }
        }
        let columns = runs.iter().map(|r| r.width).sum();
        Self { runs, blocks, columns }
    }

    /// Every free slot a run of its own: the slot pairs' blocks as they are.
    fn singletons(
        variables: &[VariableId],
        offsets: &[Option<usize>],
        dims: &[usize],
        slot_blocks: &[SlotBlock],
    ) -> Self {
        let mut run_of_slot = vec![usize::MAX; variables.len()];
        let mut runs = Vec::new();
        for (slot, v) in variables.iter().enumerate() {
            if let Some(offset) = offsets[v.0] {
                run_of_slot[slot] = runs.len();
                runs.push(Run {
                    first_slot: slot,
                    end_slot: slot + 1,
                    offset,
                    width: dims[slot],
                    column: 0,
                });
            }
        }
        place_columns(&mut runs);
        let blocks = slot_blocks
            .iter()
            .map(|b| RunBlock {
                run_a: run_of_slot[b.slot_a],
                run_b: run_of_slot[b.slot_b],
                start: b.start,
                stride: b.stride,
            })
            .collect();
        let columns = runs.iter().map(|r| r.width).sum();
        Self { runs, blocks, columns }
    }

    /// The blocks between `runs`, if every slot pair inside each of them is
    /// stored where the merged block puts it.
    fn from_runs(
        runs: Vec<Run>,
        variables: &[VariableId],
        offsets: &[Option<usize>],
        slot_blocks: &[SlotBlock],
    ) -> Option<Self> {
        let offset = |slot: usize| offsets[variables[slot].0].unwrap_or(0);
        let slots = variables.len();
        let mut table: Vec<Option<&SlotBlock>> = vec![None; slots * slots];
        for block in slot_blocks {
            table[block.slot_a + block.slot_b * slots] = Some(block);
        }
        let stored = |a: usize, b: usize| table[a + b * slots];
        let mut blocks = Vec::new();
        for (ka, a) in runs.iter().enumerate() {
            for (kb, b) in runs.iter().enumerate() {
                if a.offset < b.offset {
                    continue;
                }
                let first = stored(a.first_slot, b.first_slot)?;
                let block = RunBlock {
                    run_a: ka,
                    run_b: kb,
                    start: first.start,
                    stride: first.stride,
                };
                for slot_a in a.first_slot..a.end_slot {
                    for slot_b in b.first_slot..b.end_slot {
                        if ka == kb && slot_a < slot_b {
                            continue;
                        }
                        let pair = stored(slot_a, slot_b)?;
                        let expected =
                            block.start + (offset(slot_a) - a.offset) + (offset(slot_b) - b.offset) * block.stride;
                        if pair.stride != block.stride || pair.start != expected {
                            return None;
                        }
                    }
                }
                blocks.push(block);
            }
        }
        // Every slot pair must belong to exactly one merged block.
        let covered: usize = blocks
            .iter()
            .map(|b| {
                let (na, nb) = (
                    runs[b.run_a].end_slot - runs[b.run_a].first_slot,
                    runs[b.run_b].end_slot - runs[b.run_b].first_slot,
                );
                if b.run_a == b.run_b {
                    na * (na + 1) / 2
                } else {
                    na * nb
                }
            })
            .sum();
        if covered != slot_blocks.len() {
            return None;
        }
        let columns = runs.iter().map(|r| r.width).sum();
        Some(Self { runs, blocks, columns })
    }

    /// Add `J^T J` (whitened Jacobian blocks per slot, column-major with
    /// `residual.len()` rows) into `hessian` and `J^T r` into `gradient`;
    /// `rows_buffer` is reused scratch.
    ///
    /// On the AVX2 path (`simd::avx2`) the same code runs compiled for it
    /// (four lanes instead of SSE2's two; no FMA, so every sum is rounded as
    /// in the SSE2 build and the results are bit for bit the same: unit test).
    pub(super) fn accumulate(
        &self,
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
        rows_buffer: &mut Vec<f64>,
        fallbacks: &FallbackCounter,
    ) {
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: `accumulate_avx2` only needs AVX2, which the CPU has (`simd::avx2`).
            unsafe { self.accumulate_avx2(jacobians, residual, hessian, gradient, rows_buffer, fallbacks) };
            return;
        }
        self.accumulate_any::<false>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks);
    }

    /// [`FactorRuns::accumulate_any`] compiled with AVX2 (a closure-taking
    /// wrapper would not inline the kernels into the AVX2 build: +9 % instructions).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn accumulate_avx2(
        &self,
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
        rows_buffer: &mut Vec<f64>,
        fallbacks: &FallbackCounter,
    ) {
        self.accumulate_any::<true>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks);
    }

    /// [`FactorRuns::accumulate`] for the instruction set it is inlined into
    /// (`AVX2`: only from [`FactorRuns::accumulate_avx2`], whose products go
    /// to the intrinsic kernel of `simd::gram`).
    #[inline(always)]
    fn accumulate_any<const AVX2: bool>(
        &self,
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
        rows_buffer: &mut Vec<f64>,
        fallbacks: &FallbackCounter,
    ) {
        match residual.len() {
            1 => self.accumulate_rows::<1, AVX2>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks),
            CABLE_ROWS => {
                self.accumulate_rows::<CABLE_ROWS, AVX2>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks)
            }
            PRIOR_ROWS => {
                self.accumulate_rows::<PRIOR_ROWS, AVX2>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks)
            }
            _ => self.accumulate_rows::<0, AVX2>(jacobians, residual, hessian, gradient, rows_buffer, fallbacks),
        }
    }

    /// [`FactorRuns::accumulate`] for `R`-row factors (`R = 0`: any row count).
    #[inline(always)]
    fn accumulate_rows<const R: usize, const AVX2: bool>(
        &self,
        jacobians: &[DMatrix<f64>],
        residual: &[f64],
        hessian: &mut [f64],
        gradient: &mut [f64],
        rows_buffer: &mut Vec<f64>,
        fallbacks: &FallbackCounter,
    ) {
        let rows = if R == 0 { residual.len() } else { R };
        // (1) Each run's columns, row by row: at `rows * run.column`, `rows x width`.
        if rows_buffer.len() < rows * self.columns {
            rows_buffer.resize(rows * self.columns, 0.0);
        }
        for run in &self.runs {
            let base = rows * run.column;
            if AVX2
                && R == CABLE_ROWS
                && gather_four_rows_avx2(run, jacobians, &mut rows_buffer[base..base + R * run.width])
            {
                add_run_gradient::<R, AVX2>(&rows_buffer[base..base + rows * run.width], run, residual, gradient);
                continue;
            }
            let mut column = 0;
            for jacobian in &jacobians[run.first_slot..run.end_slot] {
                let data = jacobian.as_slice();
                for (c, values) in data.chunks_exact(rows).enumerate() {
                    for (r, &value) in values.iter().enumerate() {
                        rows_buffer[base + r * run.width + column + c] = value;
                    }
                }
                column += data.len() / rows;
            }
            // (2) J^T r for the run's columns.
            add_run_gradient::<R, AVX2>(&rows_buffer[base..base + rows * run.width], run, residual, gradient);
        }
        // (3) J_a^T J_b for every pair of runs, one dense block each.
        for block in &self.blocks {
            let (a, b) = (&self.runs[block.run_a], &self.runs[block.run_b]);
            let rows_a = &rows_buffer[self.base(block.run_a, rows)..][..rows * a.width];
            let rows_b = &rows_buffer[self.base(block.run_b, rows)..][..rows * b.width];
            add_run_product::<R, AVX2>(
                RunRows {
                    data: rows_a,
                    width: a.width,
                },
                RunRows {
                    data: rows_b,
                    width: b.width,
                },
                block.run_a == block.run_b,
                rows,
                block.stride,
                &mut hessian[block.start..],
                fallbacks,
            );
        }
    }

    /// Start of run `k`'s rows in the gathered buffer.
    fn base(&self, k: usize, rows: usize) -> usize {
        rows * self.runs[k].column
    }
}

/// `J^T r` of one run (its columns gathered row by row in `run_rows`) added
/// to the run's entries of `gradient`, each entry summed over the rows in order.
#[inline(always)]
fn add_run_gradient<const R: usize, const AVX2: bool>(
    run_rows: &[f64],
    run: &Run,
    residual: &[f64],
    gradient: &mut [f64],
) {
    let run_gradient = &mut gradient[run.offset..run.offset + run.width];
    let rows = residual.len();
    let columns = RunRows {
        data: run_rows,
        width: run.width,
    };
    if AVX2
        && add_gram_avx2::<R>(
            columns,
            RunRows {
                data: residual,
                width: 1,
            },
            false,
            0,
            run_gradient,
        )
    {
        return;
    }
    for (c, g) in run_gradient.iter_mut().enumerate() {
        let mut sum = run_rows[c] * residual[0];
        for r in 1..rows {
            sum += run_rows[r * run.width + c] * residual[r];
        }
        *g += sum;
    }
}

/// A four-row factor's run gathered row by row by the AVX2 copy; `false`
/// (nothing written) where there is no AVX2 build. Only called from code
/// compiled for AVX2.
#[inline(always)]
fn gather_four_rows_avx2(run: &Run, jacobians: &[DMatrix<f64>], rows: &mut [f64]) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let mut column = 0;
        for jacobian in &jacobians[run.first_slot..run.end_slot] {
            // SAFETY: reached only from `accumulate_avx2`, which runs only where the CPU has AVX2.
            unsafe { simd::gram::scatter_four_rows(jacobian.as_slice(), rows, run.width, column) };
            column += jacobian.ncols();
        }
        true
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (run, jacobians, rows);
        false
    }
}

/// The runs of consecutive free slots whose tangent columns follow each
/// other (and that `may_join(run, offset)` lets a run take the next slot's
/// columns at `offset`).
fn merged_runs(
    variables: &[VariableId],
    offsets: &[Option<usize>],
    dims: &[usize],
    may_join: impl Fn(&Run, usize) -> bool,
) -> Vec<Run> {
    let mut runs: Vec<Run> = Vec::new();
    for (slot, v) in variables.iter().enumerate() {
        let Some(offset) = offsets[v.0] else {
            continue;
        };
        match runs.last_mut() {
            Some(run) if run.end_slot == slot && run.offset + run.width == offset && may_join(run, offset) => {
                run.end_slot += 1;
                run.width += dims[slot];
            }
            _ => runs.push(Run {
                first_slot: slot,
                end_slot: slot + 1,
                offset,
                width: dims[slot],
                column: 0,
            }),
        }
    }
    place_columns(&mut runs);
    runs
}

/// Each run's first gathered column: the widths of the runs before it.
fn place_columns(runs: &mut [Run]) {
    let mut column = 0;
    for run in runs {
        run.column = column;
        column += run.width;
    }
}

/// A run's Jacobian columns stored row by row: entry `(r, c)` at `data[r * width + c]`.
#[derive(Clone, Copy)]
struct RunRows<'a> {
    data: &'a [f64],
    width: usize,
}

/// Add `A^T B` (or, when `same`, the lower triangle of `A^T A`) for two
/// runs of `rows` rows to the block at the start of `block`, entry `(i, j)`
/// at `i + j * stride`, each entry summed over the rows in order.
///
/// The run shapes of a calibration graph (the table of `shapes`) go to
/// kernels whose sizes are known at compile time (unrolled, vectorised, no
/// bounds checks); the rest to the general loop, counted in `fallbacks`.
#[inline(always)]
fn add_run_product<const R: usize, const AVX2: bool>(
    a: RunRows,
    b: RunRows,
    same: bool,
    rows: usize,
    stride: usize,
    block: &mut [f64],
    fallbacks: &FallbackCounter,
) {
    if AVX2 && add_gram_avx2::<R>(a, b, same, stride, block) {
        return;
    }
    if R != 0 {
        macro_rules! kernels {
            ($(($ca:tt, $cb:tt, $same:literal)),*) => {
                match (a.width, b.width, same) {
                    $(($ca, $cb, $same) => return run_product::<R, $ca, $cb, $same>(a.data, b.data, stride, block),)*
                    _ => {}
                }
            };
        }
        portable_run_shapes!(kernels);
    }
    fallbacks.product();
    for j in 0..b.width {
        let first = if same { j } else { 0 };
        let column = &mut block[j * stride + first..j * stride + a.width];
        for (k, h) in column.iter_mut().enumerate() {
            let i = first + k;
            let mut sum = a.data[i] * b.data[j];
            for r in 1..rows {
                sum += a.data[r * a.width + i] * b.data[r * b.width + j];
            }
            *h += sum;
        }
    }
}

/// [`add_run_product`] by the AVX2 kernel for the shapes of a calibration
/// graph with four rows (the catenary length and height factors): `true` if
/// it took the product, `false` for a shape it has no kernel for. Only
/// called from code compiled for AVX2 (`accumulate_any::<true>`).
#[inline(always)]
fn add_gram_avx2<const R: usize>(a: RunRows, b: RunRows, same: bool, stride: usize, block: &mut [f64]) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! kernels {
            ($(($ca:tt, $cb:tt, $same:literal)),*) => {
                match (a.width, b.width, same) {
                    $(($ca, $cb, $same) => {
                        // SAFETY: reached only from `accumulate_avx2`, which runs only where the CPU has AVX2.
                        unsafe { simd::gram::gram_block::<CABLE_ROWS, $ca, $cb, $same, false>(a.data, b.data, stride, block) };
                        return true;
                    })*
                    _ => {}
                }
            };
        }
        if R == CABLE_ROWS {
            avx2_run_shapes!(kernels);
        }
    }
    let _ = (a, b, same, stride, block);
    false
}

/// [`add_run_product`] for `R` rows and runs of `CA` and `CB` columns.
#[inline(always)]
fn run_product<const R: usize, const CA: usize, const CB: usize, const SAME: bool>(
    a: &[f64],
    b: &[f64],
    stride: usize,
    block: &mut [f64],
) {
    let (a, b) = (&a[..R * CA], &b[..R * CB]);
    for j in 0..CB {
        let first = if SAME { j } else { 0 };
        let column = &mut block[j * stride..j * stride + CA];
        for i in first..CA {
            let mut sum = a[i] * b[j];
            for r in 1..R {
                sum += a[r * CA + i] * b[r * CB + j];
            }
            column[i] += sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A factor on four variables (tangent dims 3, 1, 2, 2 at offsets 0, 3, 4
    /// and 6: one run) whose `H` is one dense column-major `8 x 8` block, and
    /// a fifth variable fixed: the merged run gives `J^T J` and `J^T r` as a
    /// dense product does, and bit for bit what the per-variable blocks give.
    #[test]
    fn merged_runs_match_the_dense_product_and_the_per_variable_blocks() {
        let dims = [3usize, 1, 2, 2, 4];
        let offsets = [Some(0), Some(3), Some(4), Some(6), None];
        let variables: Vec<VariableId> = (0..5).map(VariableId).collect();
        let n = 8;
        let mut slot_blocks = Vec::new();
        for a in 0..4 {
            for b in 0..=a {
                let (oa, ob) = (offsets[a].unwrap(), offsets[b].unwrap());
                slot_blocks.push(SlotBlock {
                    slot_a: a,
                    slot_b: b,
                    start: oa + ob * n,
                    stride: n,
                });
            }
        }
        let merged = FactorRuns::new(&variables, &offsets, &dims, &slot_blocks);
        assert_eq!(merged.runs.len(), 1);
        assert_eq!(merged.blocks.len(), 1);
        let single = FactorRuns::singletons(&variables, &offsets, &dims, &slot_blocks);
        assert_eq!(single.blocks.len(), 10);
        for rows in [1usize, 4, 5, 6] {
            let value = |k: usize| ((k * 7919 % 113) as f64 - 56.0) / 17.0;
            let jacobians: Vec<DMatrix<f64>> = dims
                .iter()
                .scan(0, |seen, &d| {
                    let block = DMatrix::from_fn(rows, d, |r, c| value(*seen + r + rows * c));
                    *seen += rows * d;
                    Some(block)
                })
                .collect();
            let residual: Vec<f64> = (0..rows).map(|r| value(1000 + r)).collect();
            let mut run_buffer = Vec::new();
            let (mut h_merged, mut g_merged) = (vec![0.0; n * n], vec![0.0; n]);
            let fallbacks = FallbackCounter::default();
            merged.accumulate(
                &jacobians,
                &residual,
                &mut h_merged,
                &mut g_merged,
                &mut run_buffer,
                &fallbacks,
            );
            // The 8 x 8 block has a kernel for 1, 4 and 6 rows; 5 rows take the general loop.
            assert_eq!(fallbacks.read().products, usize::from(rows == 5), "{rows} rows");
            let (mut h_single, mut g_single) = (vec![0.0; n * n], vec![0.0; n]);
            single.accumulate(
                &jacobians,
                &residual,
                &mut h_single,
                &mut g_single,
                &mut run_buffer,
                &fallbacks,
            );
            assert_eq!(h_merged, h_single, "{rows} rows");
            assert_eq!(g_merged, g_single, "{rows} rows");
            // The build for the CPU's instruction set (AVX2 where it has it) and the portable one agree bit for bit.
            let (mut h_any, mut g_any) = (vec![0.0; n * n], vec![0.0; n]);
            merged.accumulate_any::<false>(
                &jacobians,
                &residual,
                &mut h_any,
                &mut g_any,
                &mut run_buffer,
                &fallbacks,
            );
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&h_any), bits(&h_merged), "{rows} rows");
            assert_eq!(bits(&g_any), bits(&g_merged), "{rows} rows");
            // The independent product: the free columns side by side.
            let j = DMatrix::from_fn(rows, n, |r, c| {
                let slot = [0, 0, 0, 1, 2, 2, 3, 3][c];
                jacobians[slot][(r, c - offsets[slot].unwrap())]
            });
            let h = j.transpose() * &j;
            let g = j.transpose() * nalgebra::DVector::from_column_slice(&residual);
            for col in 0..n {
                assert!((g_merged[col] - g[col]).abs() < 1e-12);
                for row in 0..n {
                    let stored = h_merged[row + col * n];
                    let expected = if row >= col { h[(row, col)] } else { 0.0 };
                    assert!(
                        (stored - expected).abs() < 1e-12,
                        "({row}, {col}): {stored} vs {expected}"
                    );
                }
            }
        }
    }

    /// Blocks that do not line up in the storage (as in faer's compressed
    /// columns, one block per variable pair) are left per variable.
    #[test]
    fn storage_that_does_not_line_up_keeps_one_run_per_variable() {
        let dims = [2usize, 2];
        let offsets = [Some(0), Some(2)];
        let variables = [VariableId(0), VariableId(1)];
        let slot_blocks = [
            SlotBlock {
                slot_a: 0,
                slot_b: 0,
                start: 0,
                stride: 2,
            },
            SlotBlock {
                slot_a: 1,
                slot_b: 0,
                start: 4,
                stride: 2,
            },
            SlotBlock {
                slot_a: 1,
                slot_b: 1,
                start: 8,
                stride: 2,
            },
        ];
        let runs = FactorRuns::new(&variables, &offsets, &dims, &slot_blocks);
        assert_eq!(runs.runs.len(), 2);
        assert_eq!(runs.blocks.len(), 3);
    }
}
