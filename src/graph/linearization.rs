//! Linearisation of one factor for a Gauss-Newton system: the whitened,
//! robust-reweighted residual and Jacobian blocks
//! ([`WhitenedLinearization`]), made fresh ([`linearize_factor`]) or into
//! reused buffers ([`LinearizationBuffers`]).

use nalgebra::DMatrix;

use super::factor::Factor;
use super::slot_mask::SlotMask;
use super::values::Values;
#[cfg(target_arch = "x86_64")]
use super::weighing::weigh_four_rows_avx2;
use super::weighing::{squared_norm_over, weigh_columns};
use crate::error::LinearizeError;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{Noise, VariableId, VariableValue};
    use nalgebra::DVector;

    /// `r = [x0 y0 - 1, x1 + y0^2] * k` on `x` (2) and `y` (1); with
    /// `nan_in_y`, `y`'s Jacobian block is NaN (a block no reader wants).
    struct Product {
        variables: [VariableId; 2],
        noise: Noise,
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
        fn noise(&self) -> &Noise {
            &self.noise
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
            noise: Noise::gaussian(DVector::from_vec(vec![0.1, 0.3])),
            k,
            nan_in_y,
        };
        (values, factor)
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
}
