//! The [`Factor`] trait: a residual on a few variables with analytic
//! Jacobians, its sigmas and robust kernel, and [`evaluate_through_into`]
//! for factors that evaluate into a caller's buffer.

use nalgebra::{DMatrix, DVector};

use super::noise::Noise;
use super::robust::RobustKernel;
use super::slot_mask::SlotMask;
use super::values::{Values, VariableId};

/// A residual on a few variables, with analytic Jacobians.
///
/// The Jacobian blocks are taken along each variable's retraction
/// ([`VariableValue::retract`]): for a pose, `[d rotation tangent, d position]`.
///
/// [`VariableValue::retract`]: super::VariableValue::retract
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
    ///
    /// [`LinearizationBuffers::linearize_slots`]: super::LinearizationBuffers::linearize_slots
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
    /// The noise model: the standard deviation of every residual component
    /// (same units as the residual) and the robust kernel on the whitened
    /// squared norm.
    fn noise(&self) -> &Noise;
    /// Standard deviation of every residual component (of [`Factor::noise`];
    /// not to be overridden).
    fn sigmas(&self) -> &DVector<f64> {
        &self.noise().sigmas
    }
    /// The robust kernel applied to the whitened squared norm (of
    /// [`Factor::noise`]; not to be overridden).
    fn robust_kernel(&self) -> RobustKernel {
        self.noise().kernel
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
