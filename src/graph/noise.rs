//! A factor's noise model: the standard deviation of each residual
//! component, `sigma_f`, and the robust kernel `rho_f` on the whitened
//! squared norm, in the objective `sum_f 1/2 rho_f(||r_f / sigma_f||^2)`
//! (module docs of [`crate::graph`]). A factor holds one and hands it to
//! the solver through [`crate::graph::Factor::noise`].
//!
//! ```
//! use sagcal::graph::{Noise, RobustKernel};
//! let encoders = Noise::isotropic(4, 0.01, RobustKernel::Huber(1.345));
//! assert_eq!(encoders.sigmas.as_slice(), &[0.01; 4]);
//! assert_eq!(Noise::gaussian(nalgebra::DVector::from_element(1, 5.0)).kernel, RobustKernel::None);
//! ```

use nalgebra::DVector;

use super::robust::RobustKernel;

/// Per-component standard deviations and a robust kernel.
#[derive(Debug, Clone, PartialEq)]
pub struct Noise {
    /// Standard deviation of every residual component (the residual's units).
    pub sigmas: DVector<f64>,
    /// The robust kernel applied to the whitened squared norm.
    pub kernel: RobustKernel,
}

impl Noise {
    /// `sigmas` under `kernel`.
    pub fn new(sigmas: DVector<f64>, kernel: RobustKernel) -> Self {
        Noise { sigmas, kernel }
    }

    /// `dim` components of one standard deviation `sigma` under `kernel`.
    pub fn isotropic(dim: usize, sigma: f64, kernel: RobustKernel) -> Self {
        Noise::new(DVector::from_element(dim, sigma), kernel)
    }

    /// `sigmas`, plain least squares (no robust kernel).
    pub fn gaussian(sigmas: DVector<f64>) -> Self {
        Noise::new(sigmas, RobustKernel::None)
    }
}
