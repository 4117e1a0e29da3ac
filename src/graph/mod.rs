//! The factor graph: variables, factors, noise models and robust kernels.
//!
//! The objective minimised by [`crate::solver`] is
//! ```text
//! sum_f  1/2 rho_f( || r_f(x) / sigma_f ||^2 )
//! ```
//! with `r_f` a factor's residual (the generated functions of `generated/`
//! wrapped in [`crate::calib`]), `sigma_f` its per-component standard
//! deviations and `rho_f` its robust kernel.
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use sagcal::graph::{linearize_factor, Factor, FactorGraph, Values, VariableId, VariableValue};
//! /// A direct reading `z` of a scalar variable, standard deviation `sigma`.
//! struct Reading { variable: [VariableId; 1], z: f64, sigma: DVector<f64> }
//! impl Factor for Reading {
//!     fn variables(&self) -> &[VariableId] { &self.variable }
//!     fn residual_dim(&self) -> usize { 1 }
//!     fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
//!         if let Some(blocks) = jacobians { blocks[0][(0, 0)] = 1.0; }
//!         Some(DVector::from_element(1, values.vector(self.variable[0])[0] - self.z))
//!     }
//!     fn sigmas(&self) -> &DVector<f64> { &self.sigma }
//!     fn kind(&self) -> &'static str { "reading" }
//! }
//! let mut graph = FactorGraph::new();
//! let x = graph.values.insert("x", VariableValue::Vector(DVector::from_element(1, 0.0)));
//! graph.add(Reading { variable: [x], z: 3.0, sigma: DVector::from_element(1, 1.0) });
//! graph.add(Reading { variable: [x], z: 5.0, sigma: DVector::from_element(1, 2.0) });
//! // At x = 0: 1/2 ((0 - 3) / 1)^2 + 1/2 ((0 - 5) / 2)^2.
//! assert_eq!(graph.cost(&graph.values), Some(0.5 * 9.0 + 0.5 * 6.25));
//! // The solver sees each factor whitened: residual r / sigma, Jacobian J / sigma.
//! let linear = linearize_factor(graph.factors[1].as_ref(), &graph.values).unwrap();
//! assert_eq!((linear.residual[0], linear.jacobians[0][(0, 0)]), (-2.5, 0.5));
//! ```

pub mod masked;
pub mod robust;
pub mod shared;
pub mod values;

pub use crate::error::LinearizeError;
pub use masked::MaskedFactor;
pub use robust::RobustKernel;
pub use shared::SharedEvaluation;
pub use values::{Values, VariableId, VariableValue};

use nalgebra::{DMatrix, DVector};

/// A residual on a few variables, with analytic Jacobians.
///
/// The Jacobian blocks are taken along each variable's retraction
/// ([`VariableValue::retract`]): for a pose, `[d rotation tangent, d position]`.
pub trait Factor: Send + Sync {
    /// The variables this factor reads, in the order of the Jacobian blocks.
    fn variables(&self) -> &[VariableId];
    /// Length of the residual vector.
    fn residual_dim(&self) -> usize;
    /// The unwhitened residual; when `jacobians` is given, also fill one block
    /// per variable (`residual_dim x tangent_dim`, already sized). `None` where
    /// the model is undefined (e.g. a slack cable): the solver rejects such steps.
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>>;
    /// [`Factor::evaluate`] into `residual` (`residual_dim` entries) instead
    /// of a new vector; `false` where the model is undefined. The solver calls
    /// this one. The default calls [`Factor::evaluate`] and copies; factors
    /// evaluated thousands of times per iteration override it to allocate
    /// nothing (and then implement `evaluate` by [`evaluate_through_into`]).
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        match self.evaluate(values, jacobians) {
            Some(r) => {
                assert_eq!(
                    r.len(),
                    residual.len(),
                    "a {} factor returned a residual of another length than its residual_dim",
                    self.kind()
                );
                residual.copy_from_slice(r.as_slice());
                true
            }
            None => false,
        }
    }
    /// [`Factor::evaluate_into`] for a caller that reads only the Jacobian
    /// blocks in `wanted` ([`LinearizationBuffers::linearize_slots`]); the
    /// others may be left as they were. The default fills every block.
    fn evaluate_slots(
        &self,
        values: &Values,
        residual: &mut [f64],
        jacobians: Option<&mut [DMatrix<f64>]>,
        wanted: SlotMask,
    ) -> bool {
        let _ = wanted;
        self.evaluate_into(values, residual, jacobians)
    }
    /// Standard deviation of every residual component (same units as the residual).
    fn sigmas(&self) -> &DVector<f64>;
    /// The robust kernel applied to the whitened squared norm.
    fn robust_kernel(&self) -> RobustKernel {
        RobustKernel::None
    }
    /// A short name of the factor type, for per-type statistics (`"catenary_length"`, ...).
    fn kind(&self) -> &'static str;
    /// Whether [`Factor::evaluate`] writes every entry of every Jacobian
    /// block it is given; the solver then skips zeroing its reused blocks
    /// before the call. `false` (the default) for factors that fill only
    /// their non-zero entries.
    fn writes_every_jacobian_entry(&self) -> bool {
        false
    }
}

/// [`Factor::evaluate`] of a factor that implements [`Factor::evaluate_into`]:
/// the residual in a new vector.
pub fn evaluate_through_into(
    factor: &(impl Factor + ?Sized),
    values: &Values,
    jacobians: Option<&mut [DMatrix<f64>]>,
) -> Option<DVector<f64>> {
    let mut residual = DVector::zeros(factor.residual_dim());
    factor
        .evaluate_into(values, residual.as_mut_slice(), jacobians)
        .then_some(residual)
}

/// A factor graph: variables with values, and factors between them.
#[derive(Default)]
pub struct FactorGraph {
    /// Current values of every variable.
    pub values: Values,
    /// The factors.
    pub factors: Vec<Box<dyn Factor>>,
    /// Groups of *local* variables (e.g. one pose and its reference tension):
    /// each group shares factors only with itself and with variables outside
    /// every group. The solver re-minimises each group with the others fixed
    /// after every step (see [`crate::solver`]); empty: no local refinement.
    pub local_groups: Vec<Vec<VariableId>>,
}

impl FactorGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add a factor.
    pub fn add(&mut self, factor: impl Factor + 'static) {
        self.factors.push(Box::new(factor));
    }

    /// Whitened residual of one factor at `values`, with the robust kernel's
    /// cost `1/2 rho(s)`; `None` if the model is undefined there.
    pub fn factor_cost(factor: &dyn Factor, values: &Values) -> Option<f64> {
        // Short residuals on the stack (every factor of the calibration).
        let rows = factor.residual_dim();
        let mut stack = [0.0; 16];
        let mut heap = Vec::new();
        let residual = if rows <= stack.len() {
            &mut stack[..rows]
        } else {
            heap.resize(rows, 0.0);
            &mut heap[..]
        };
        if !factor.evaluate_into(values, residual, None) {
            return None;
        }
        let s = squared_norm_over(residual, factor.sigmas());
        s.is_finite().then(|| 0.5 * factor.robust_kernel().rho(s))
    }

    /// Total cost `sum 1/2 rho(|r/sigma|^2)`; `None` if any factor is undefined.
    pub fn cost(&self, values: &Values) -> Option<f64> {
        self.factors.iter().map(|f| Self::factor_cost(f.as_ref(), values)).sum()
    }
}

/// `|r / sigma|^2`.
pub fn whitened_squared_norm(residual: &DVector<f64>, sigmas: &DVector<f64>) -> f64 {
    squared_norm_over(residual.as_slice(), sigmas)
}

/// [`whitened_squared_norm`] of a residual slice.
fn squared_norm_over(residual: &[f64], sigmas: &DVector<f64>) -> f64 {
    // Over slices: nalgebra's strided matrix iterator costs several times the arithmetic here.
    residual
        .iter()
        .zip(sigmas.as_slice())
        .map(|(r, s)| (r / s) * (r / s))
        .sum()
}

/// One factor linearised for a Gauss-Newton system: residual and Jacobian
/// blocks whitened by its sigmas and reweighted by its robust kernel
/// (`sqrt(w) r / sigma`, `sqrt(w) J / sigma`), and its cost `1/2 rho(s)`.
pub struct WhitenedLinearization {
    /// Whitened, reweighted residual.
    pub residual: Vec<f64>,
    /// Whitened, reweighted Jacobian blocks, one per variable.
    pub jacobians: Vec<DMatrix<f64>>,
    /// The factor's cost `1/2 rho(|r / sigma|^2)`.
    pub cost: f64,
    /// Whether the residual and every Jacobian entry are zero (an inactive
    /// guard): the factor then adds nothing to `J^T J` or `J^T r`.
    pub is_zero: bool,
    /// Scratch: `sqrt(w) / sigma_r` per row.
    row_weights: Vec<f64>,
    /// Scratch: the unwhitened residual.
    raw_residual: Vec<f64>,
}

/// Linearise one factor at `values`; `Err` names what went wrong (the model is
/// undefined there, or a residual or Jacobian entry is not finite).
pub fn linearize_factor(factor: &dyn Factor, values: &Values) -> Result<WhitenedLinearization, LinearizeError> {
    let rows = factor.residual_dim();
    let mut linearized = WhitenedLinearization {
        residual: Vec::with_capacity(rows),
        jacobians: factor
            .variables()
            .iter()
            .map(|&v| DMatrix::zeros(rows, values.tangent_dim(v)))
            .collect(),
        cost: 0.0,
        is_zero: false,
        row_weights: Vec::with_capacity(rows),
        raw_residual: Vec::with_capacity(rows),
    };
    linearize_into(factor, values, &mut linearized, SlotMask::ALL)?;
    Ok(linearized)
}

/// Reusable buffers for linearising many factors one after the other: one
/// set of Jacobian blocks per factor shape, so that a solver iteration over
/// thousands of factors allocates nothing for them.
#[derive(Default)]
pub struct LinearizationBuffers {
    by_shape: Vec<WhitenedLinearization>,
    /// [`LinearizationBuffers::linearize_at`]: the shape of the factor at
    /// each index (`u32::MAX`: not seen yet).
    shape_of_factor: Vec<u32>,
}

impl LinearizationBuffers {
    /// Linearise `factor` at `values` into the buffers of its shape (see [`linearize_factor`]).
    pub fn linearize(
        &mut self,
        factor: &dyn Factor,
        values: &Values,
    ) -> Result<&WhitenedLinearization, LinearizeError> {
        self.linearize_slots(factor, values, SlotMask::ALL)
    }

    /// [`LinearizationBuffers::linearize`] for a reader of the Jacobian
    /// blocks in `wanted` only (the solver's per-pose refinement reads the
    /// pose's blocks, not the anchors'): only those blocks are zeroed before
    /// the call, whitened and checked, and `is_zero` looks at them alone; the
    /// others are left as the factor wrote them and must not be read. The
    /// residual, the cost and the wanted blocks are bit for bit those of
    /// [`LinearizationBuffers::linearize`].
    pub fn linearize_slots(
        &mut self,
        factor: &dyn Factor,
        values: &Values,
        wanted: SlotMask,
    ) -> Result<&WhitenedLinearization, LinearizeError> {
        let index = self.shape_index(factor, values, wanted);
        let linearized = &mut self.by_shape[index];
        linearize_into(factor, values, linearized, wanted)?;
        Ok(linearized)
    }

    /// [`LinearizationBuffers::linearize`] of the factor at `index` of a
    /// graph whose factors do not change while these buffers are used (the
    /// solver's pass over a graph): the buffers found for `index` the first
    /// time are taken again without comparing shapes. Bit for bit
    /// [`LinearizationBuffers::linearize`]. Inlined into the solver's pass
    /// whatever codegen unit each lands in (its call per factor showed as
    /// +0.5 % instructions of a solve when a module move separated them).
    #[inline]
    pub(crate) fn linearize_at(
        &mut self,
        index: usize,
        factor: &dyn Factor,
        values: &Values,
    ) -> Result<&WhitenedLinearization, LinearizeError> {
        if self.shape_of_factor.len() <= index {
            self.shape_of_factor.resize(index + 1, u32::MAX);
        }
        let shape = match self.shape_of_factor[index] {
            u32::MAX => {
                let shape = self.shape_index(factor, values, SlotMask::ALL);
                self.shape_of_factor[index] = shape as u32;
                shape
            }
            known => {
                let shape = known as usize;
                self.zero_blocks(shape, factor, SlotMask::ALL);
                shape
            }
        };
        let linearized = &mut self.by_shape[shape];
        debug_assert_eq!(linearized.jacobians.len(), factor.variables().len());
        linearize_into(factor, values, linearized, SlotMask::ALL)?;
        Ok(linearized)
    }

    /// The buffers of `factor`'s shape (made if new), its `wanted` blocks
    /// zeroed unless the factor writes every entry.
    fn shape_index(&mut self, factor: &dyn Factor, values: &Values, wanted: SlotMask) -> usize {
        let rows = factor.residual_dim();
        let variables = factor.variables();
        let same_shape = |l: &WhitenedLinearization| {
            l.jacobians.len() == variables.len()
                && l.jacobians
                    .iter()
                    .zip(variables)
                    .all(|(j, &v)| j.nrows() == rows && j.ncols() == values.tangent_dim(v))
        };
        match self.by_shape.iter().position(same_shape) {
            Some(index) => {
                self.zero_blocks(index, factor, wanted);
                index
            }
            None => {
                self.by_shape.push(WhitenedLinearization {
                    residual: Vec::with_capacity(rows),
                    jacobians: variables
                        .iter()
                        .map(|&v| DMatrix::zeros(rows, values.tangent_dim(v)))
                        .collect(),
                    cost: 0.0,
                    is_zero: false,
                    row_weights: Vec::with_capacity(rows),
                    raw_residual: Vec::with_capacity(rows),
                });
                self.by_shape.len() - 1
            }
        }
    }

    /// Zero the `wanted` blocks of the buffers at `index` for a factor that
    /// writes only its non-zero entries (the others overwrite every entry).
    fn zero_blocks(&mut self, index: usize, factor: &dyn Factor, wanted: SlotMask) {
        if !factor.writes_every_jacobian_entry() {
            for (slot, jacobian) in self.by_shape[index].jacobians.iter_mut().enumerate() {
                if wanted.contains(slot) {
                    jacobian.as_mut_slice().fill(0.0);
                }
            }
        }
    }
}

/// Which Jacobian blocks (variable slots) of a factor a linearisation is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SlotMask(u64);

impl SlotMask {
    /// Every slot.
    pub const ALL: SlotMask = SlotMask(u64::MAX);

    /// The slots in `slots` (slots from 64 on are always included).
    pub fn of(slots: impl IntoIterator<Item = usize>) -> Self {
        SlotMask(
            slots
                .into_iter()
                .fold(0, |mask, slot| mask | 1u64.checked_shl(slot as u32).unwrap_or(0)),
        )
    }

    /// Whether `slot` is in the mask.
    pub fn contains(self, slot: usize) -> bool {
        slot >= 64 || self.0 >> slot & 1 == 1
    }
}

/// Evaluate, whiten and reweight one factor into `out`, whose Jacobian
/// blocks are sized for the factor and, where `wanted`, zeroed.
fn linearize_into(
    factor: &dyn Factor,
    values: &Values,
    out: &mut WhitenedLinearization,
    wanted: SlotMask,
) -> Result<(), LinearizeError> {
    let rows = factor.residual_dim();
    out.raw_residual.clear();
    out.raw_residual.resize(rows, 0.0);
    let defined = factor.evaluate_slots(values, &mut out.raw_residual, Some(&mut out.jacobians), wanted);
    let residual = &out.raw_residual;
    if !defined {
        return Err(LinearizeError::Undefined);
    }
    let sigmas = factor.sigmas();
    let s = squared_norm_over(residual, sigmas);
    let sigmas = sigmas.as_slice();
    if !s.is_finite() {
        return Err(LinearizeError::NonFiniteResidual);
    }
    let kernel = factor.robust_kernel();
    let scale = kernel.weight(s).sqrt();
    out.residual.clear();
    out.residual
        .extend(residual.iter().zip(sigmas).map(|(r, sigma)| r / sigma * scale));
    // The row weights `scale / sigma_r` once per row, not per entry (the same quotients).
    out.row_weights.clear();
    out.row_weights.extend(sigmas.iter().map(|sigma| scale / sigma));
    // One pass over the entries: weighted, then checked for a non-finite
    // entry (an error) and, only when the residual is all zero, for all zero
    // (nothing to add: an inactive guard).
    let residual_zero = out.residual.iter().all(|&r| r == 0.0);
    let wanted_blocks = out
        .jacobians
        .iter_mut()
        .enumerate()
        .filter(|(slot, _)| wanted.contains(*slot))
        .map(|(_, jacobian)| jacobian.as_mut_slice());
    let weights = &out.row_weights;
    let (finite, zero) = match (rows, residual_zero) {
        #[cfg(target_arch = "x86_64")]
        (4, false) if crate::simd::avx2() => {
            // SAFETY: the CPU has AVX2 (`simd::avx2`, the crate's one dispatch).
            unsafe { weigh_four_rows_avx2(wanted_blocks, weights) }
        }
        (4, false) => weigh_columns::<4, false>(wanted_blocks, weights),
        (4, true) => weigh_columns::<4, true>(wanted_blocks, weights),
        (6, false) => weigh_columns::<6, false>(wanted_blocks, weights),
        (1, _) => weigh_columns::<1, true>(wanted_blocks, weights),
        (_, false) => weigh_columns::<0, false>(wanted_blocks, weights),
        (_, true) => weigh_columns::<0, true>(wanted_blocks, weights),
    };
    if !finite {
        return Err(LinearizeError::NonFiniteJacobian);
    }
    out.is_zero = residual_zero && zero;
    out.cost = 0.5 * kernel.rho(s);
    Ok(())
}

/// [`weigh_columns`] for four rows (a column is one 256-bit register)
/// compiled for AVX2: the same products and running sums, bit for bit
/// (no FMA; unit test).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn weigh_four_rows_avx2<'a>(blocks: impl Iterator<Item = &'a mut [f64]>, weights: &[f64]) -> (bool, bool) {
    weigh_columns::<4, false>(blocks, weights)
}

/// Multiply every column of `blocks` (column-major, `weights.len()` rows)
/// by the row weights, entry by entry; returns whether every weighted entry
/// is finite and (only computed when `ZERO`, else `false`) whether all are
/// zero. `R` rows known at compile time (`R = 0`: any), so that the rows of
/// a column are multiplied side by side; the checks keep one running sum per
/// row (`v * 0.0` is NaN exactly when `v` is not finite, a sum of `|v|` is
/// zero exactly when every `v` is), whose order does not change the answer.
#[inline(always)]
fn weigh_columns<'a, const R: usize, const ZERO: bool>(
    blocks: impl Iterator<Item = &'a mut [f64]>,
    weights: &[f64],
) -> (bool, bool) {
    let rows = weights.len();
    if R != 0 && rows == R {
        let weights: [f64; R] = std::array::from_fn(|r| weights[r]);
        let mut not_finite = [0.0; R];
        let mut magnitude = [0.0; R];
        for block in blocks {
            for column in block.chunks_exact_mut(R) {
                for r in 0..R {
                    let v = column[r] * weights[r];
                    column[r] = v;
                    not_finite[r] += v * 0.0;
                    if ZERO {
                        magnitude[r] += v.abs();
                    }
                }
            }
        }
        let finite = !not_finite.iter().any(|v| v.is_nan());
        return (finite, ZERO && magnitude.iter().all(|&m| m == 0.0));
    }
    let mut not_finite = 0.0;
    let mut magnitude = 0.0;
    for block in blocks {
        for column in block.chunks_exact_mut(rows) {
            for (entry, weight) in column.iter_mut().zip(weights) {
                let v = *entry * weight;
                *entry = v;
                not_finite += v * 0.0;
                if ZERO {
                    magnitude += v.abs();
                }
            }
        }
    }
    (!f64::is_nan(not_finite), ZERO && magnitude == 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `r = [x0 y0 - 1, x1 + y0^2] * k` on `x` (2) and `y` (1); with
    /// `nan_in_y`, `y`'s Jacobian block is NaN (a block no reader wants).
    struct Product {
        variables: [VariableId; 2],
        sigmas: DVector<f64>,
        k: f64,
        nan_in_y: bool,
    }

    impl Factor for Product {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn residual_dim(&self) -> usize {
            2
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            let (x, y) = (values.vector(self.variables[0]), values.vector(self.variables[1])[0]);
            if let Some(blocks) = jacobians {
                blocks[0][(0, 0)] = self.k * y;
                blocks[0][(1, 1)] = self.k;
                blocks[1][(0, 0)] = if self.nan_in_y { f64::NAN } else { self.k * x[0] };
                blocks[1][(1, 0)] = self.k * 2.0 * y;
            }
            Some(DVector::from_vec(vec![
                self.k * (x[0] * y - 1.0),
                self.k * (x[1] + y * y),
            ]))
        }
        fn sigmas(&self) -> &DVector<f64> {
            &self.sigmas
        }
        fn kind(&self) -> &'static str {
            "product"
        }
    }

    fn setup(k: f64, nan_in_y: bool) -> (Values, Product) {
        let mut values = Values::default();
        let x = values.insert("x", VariableValue::Vector(DVector::from_vec(vec![0.7, -0.3])));
        let y = values.insert("y", VariableValue::Vector(DVector::from_vec(vec![1.9])));
        let factor = Product {
            variables: [x, y],
            sigmas: DVector::from_vec(vec![0.1, 0.3]),
            k,
            nan_in_y,
        };
        (values, factor)
    }

    #[test]
    fn slot_masks_hold_the_slots_named_and_every_slot_from_64_on() {
        let mask = SlotMask::of([0, 2, 63]);
        let held: Vec<usize> = (0..70).filter(|&s| mask.contains(s)).collect();
        assert_eq!(held, [0, 2, 63, 64, 65, 66, 67, 68, 69]);
        assert!((0..100).all(|s| SlotMask::ALL.contains(s)));
        assert!(!SlotMask::of([]).contains(0));
    }

    /// The wanted block, the residual and the cost are bit for bit those of
    /// the full linearisation (here, after the same buffers held another
    /// factor's blocks), and hand-computed.
    #[test]
    fn a_masked_linearisation_gives_the_wanted_blocks_bit_for_bit() {
        let (values, factor) = setup(2.0, false);
        let mut buffers = LinearizationBuffers::default();
        let full = buffers.linearize(&factor, &values).unwrap();
        let (full_residual, full_cost, full_x) = (full.residual.clone(), full.cost, full.jacobians[0].clone());
        let mut masked_buffers = LinearizationBuffers::default();
        let (_, other) = setup(5.0, false);
        masked_buffers.linearize(&other, &values).unwrap();
        let masked = masked_buffers
            .linearize_slots(&factor, &values, SlotMask::of([0]))
            .unwrap();
        assert_eq!(masked.residual, full_residual);
        assert_eq!(masked.cost.to_bits(), full_cost.to_bits());
        assert_eq!(masked.jacobians[0], full_x);
        // r / sigma and J / sigma by hand.
        let r0 = 2.0 * (0.7 * 1.9 - 1.0) / 0.1;
        assert!((masked.residual[0] - r0).abs() < 1e-12);
        assert!((masked.jacobians[0][(0, 0)] - 2.0 * 1.9 / 0.1).abs() < 1e-12);
        assert!((masked.jacobians[0][(1, 1)] - 2.0 / 0.3).abs() < 1e-12);
        assert_eq!(masked.jacobians[0][(0, 1)], 0.0);
    }

    /// The buffers found for a factor index are reused with its blocks
    /// zeroed again (a factor that writes only its non-zero entries, here
    /// after the buffers were filled with NaN): bit for bit a fresh
    /// linearisation, for two factors at two indices, twice.
    #[test]
    fn a_linearisation_by_index_is_a_fresh_one() {
        let (values, first) = setup(2.0, false);
        let (_, second) = setup(-3.5, false);
        let fresh: Vec<_> = [&first, &second]
            .iter()
            .map(|f| {
                let l = linearize_factor(*f, &values).unwrap();
                (l.residual, l.jacobians, l.cost.to_bits())
            })
            .collect();
        let mut buffers = LinearizationBuffers::default();
        for _ in 0..2 {
            for (index, factor) in [&first, &second].into_iter().enumerate() {
                let l = buffers.linearize_at(index, factor, &values).unwrap();
                assert_eq!(
                    (&l.residual, &l.jacobians, l.cost.to_bits()),
                    (&fresh[index].0, &fresh[index].1, fresh[index].2)
                );
                assert_eq!(l.jacobians[0][(1, 0)], 0.0);
            }
            buffers
                .by_shape
                .iter_mut()
                .flat_map(|l| l.jacobians.iter_mut())
                .for_each(|j| j.fill(f64::NAN));
        }
        assert_eq!(buffers.by_shape.len(), 1);
    }

    /// A non-finite entry in a block nobody asked for does not fail the
    /// masked linearisation; in a wanted block (or unmasked) it does.
    #[test]
    fn only_wanted_blocks_are_checked_for_finite_entries() {
        let (values, factor) = setup(1.0, true);
        let mut buffers = LinearizationBuffers::default();
        assert_eq!(
            buffers.linearize(&factor, &values).err(),
            Some(LinearizeError::NonFiniteJacobian)
        );
        assert!(buffers.linearize_slots(&factor, &values, SlotMask::of([0])).is_ok());
        assert_eq!(
            buffers.linearize_slots(&factor, &values, SlotMask::of([1])).err(),
            Some(LinearizeError::NonFiniteJacobian)
        );
    }

    /// At `k = 0` the residual and every block are zero: an inactive factor, masked or not.
    #[test]
    fn a_zero_factor_is_zero_in_its_wanted_blocks() {
        let (values, factor) = setup(0.0, false);
        let mut buffers = LinearizationBuffers::default();
        assert!(buffers.linearize(&factor, &values).unwrap().is_zero);
        assert!(
            buffers
                .linearize_slots(&factor, &values, SlotMask::of([1]))
                .unwrap()
                .is_zero
        );
        let (values, factor) = setup(1.0, false);
        assert!(
            !buffers
                .linearize_slots(&factor, &values, SlotMask::of([0]))
                .unwrap()
                .is_zero
        );
    }

    /// The fixed-row kernels weigh exactly as the general loop and agree on
    /// finiteness and all-zero, for finite, infinite, NaN and zero entries.
    #[test]
    fn fixed_row_weighing_matches_the_general_loop() {
        fn check<const R: usize>(entries: &[f64], weights: &[f64]) {
            let (mut fixed, mut general) = (entries.to_vec(), entries.to_vec());
            let a = weigh_columns::<R, true>(std::iter::once(fixed.as_mut_slice()), weights);
            let b = weigh_columns::<0, true>(std::iter::once(general.as_mut_slice()), weights);
            assert_eq!(a, b, "{entries:?}");
            assert!(fixed.iter().zip(&general).all(|(x, y)| x.to_bits() == y.to_bits()));
            let expected_finite = entries
                .iter()
                .zip(weights.iter().cycle())
                .all(|(e, w)| (e * w).is_finite());
            assert_eq!(a.0, expected_finite);
            assert_eq!(a.1, entries.iter().all(|&e| e == 0.0));
            assert!(!weigh_columns::<R, false>(std::iter::once(entries.to_vec().as_mut_slice()), weights).1);
            #[cfg(target_arch = "x86_64")]
            if R == 4 && crate::simd::avx2_under_test() {
                let mut avx2 = entries.to_vec();
                // SAFETY: the CPU has AVX2 (`avx2_under_test` just above).
                let c = unsafe { weigh_four_rows_avx2(std::iter::once(avx2.as_mut_slice()), weights) };
                assert_eq!(c.0, a.0, "{entries:?}");
                assert!(avx2.iter().zip(&general).all(|(x, y)| x.to_bits() == y.to_bits()));
            }
        }
        let weights4 = [0.5, 3.0, 1e-3, 7.0];
        let mut entries: Vec<f64> = (0..24).map(|k| (k as f64 * 0.37).sin()).collect();
        check::<4>(&entries, &weights4);
        entries[13] = f64::INFINITY;
        check::<4>(&entries, &weights4);
        entries[13] = f64::NAN;
        check::<4>(&entries, &weights4);
        check::<4>(&[0.0; 24], &weights4);
        check::<4>(&[-0.0; 8], &weights4);
        let weights6 = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let entries6: Vec<f64> = (0..36).map(|k| k as f64 - 17.0).collect();
        check::<6>(&entries6, &weights6);
        check::<1>(&[2.0, f64::NEG_INFINITY], &[0.25]);
        check::<1>(&[0.0, 0.0], &[0.25]);
    }
}
