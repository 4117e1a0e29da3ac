//! # sagcal
//!
//! Self-calibration of suspended cable-driven parallel robots whose cables sag,
//! after Dindarloo et al., *A Graph-Based Self-Calibration Technique for
//! Cable-Driven Robots with Sagging Cable*.
//!
//! Layers, data flowing one way: [`io`] (files) -> [`model`] (catenary,
//! robot, kineto-statics) -> graph / solver / calib (factor graph and sparse
//! Levenberg-Marquardt) -> the `sagcal` command line. The residuals and their
//! analytic Jacobians are derived with SymForce in `codegen/` and emitted into
//! [`generated`].
//!
//! ```
//! use sagcal::model::{Catenary, Robot};
//! let robot = Robot::builtin("large").unwrap();
//! let cable = Catenary {
//!     span_m: 160.0,
//!     horizontal_tension_n: 600.0,
//!     vertical_tension_n: 80.0,
//!     cable_weight_n_per_m: robot.cable_weight_n_per_m,
//! };
//! // A heavy cable is longer than the straight line with the same end slope.
//! assert!(cable.length_m() > 160.0);
//! ```

#![warn(missing_docs)]

pub mod calib;
pub mod diagnose;
pub mod error;
pub mod experiments;
#[path = "../generated/mod.rs"]
#[allow(missing_docs, clippy::all)]
pub mod generated;
pub mod graph;
pub mod io;
pub mod model;
pub mod plot;
pub mod sim;
pub mod solver;
pub mod stats;

pub use error::{Error, Result};
