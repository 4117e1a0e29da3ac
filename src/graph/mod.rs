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
//! use sagcal::graph::{linearize_factor, Factor, FactorGraph, Noise, Values, VariableId, VariableValue};
//! /// A direct reading `z` of a scalar variable, standard deviation `sigma`.
//! struct Reading { variable: [VariableId; 1], z: f64, noise: Noise }
//! impl Factor for Reading {
//!     fn variables(&self) -> &[VariableId] { &self.variable }
//!     fn residual_dim(&self) -> usize { 1 }
//!     fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
//!         if let Some(blocks) = jacobians { blocks[0][(0, 0)] = 1.0; }
//!         Some(DVector::from_element(1, values.vector(self.variable[0])[0] - self.z))
//!     }
//!     fn noise(&self) -> &Noise { &self.noise }
//!     fn kind(&self) -> &'static str { "reading" }
//! }
//! let mut graph = FactorGraph::new();
//! let x = graph.values.insert("x", VariableValue::Vector(DVector::from_element(1, 0.0)));
//! graph.add(Reading { variable: [x], z: 3.0, noise: Noise::gaussian(DVector::from_element(1, 1.0)) });
//! graph.add(Reading { variable: [x], z: 5.0, noise: Noise::gaussian(DVector::from_element(1, 2.0)) });
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

mod factor;
mod factor_graph;
mod linearization;
mod noise;
mod slot_mask;
mod weighing;

pub use crate::error::LinearizeError;
pub use factor::{evaluate_through_into, Factor};
pub use factor_graph::FactorGraph;
pub use linearization::{linearize_factor, LinearizationBuffers, WhitenedLinearization};
pub use masked::MaskedFactor;
pub use noise::Noise;
pub use robust::RobustKernel;
pub use shared::SharedEvaluation;
pub use slot_mask::SlotMask;
pub use values::{Values, VariableId, VariableValue};
pub use weighing::whitened_squared_norm;
