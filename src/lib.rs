//! # sagcal
//!
//! Self-calibration of suspended cable-driven parallel robots whose cables sag,
//! after Dindarloo et al., *A Graph-Based Self-Calibration Technique for
//! Cable-Driven Robots with Sagging Cable*.
//!
//! sagcal does four jobs for an operator, in the order they meet them:
//! **plan** the poses worth visiting ([`plan`]), **calibrate** the
//! anchors and encoder offsets ([`calib`]), **diagnose** what the model gets
//! wrong ([`diagnose`]), and **localise** the calibrated robot from its cable
//! readings ([`localize`]).
//!
//! The layers, data flowing one way (no module names one above it; the
//! test `tests/layout.rs` checks it):
//!
//! | layer | purpose |
//! |---|---|
//! | [`error`], [`stats`], [`steps`], [`simd`] | the error type; chi-square quantiles, correlation, BIC; the count of work done (tests bound running time by it); which instruction set the hand-written kernels run (the switch `SAGCAL_SIMD`) |
//! | [`model`] | cable physics (catenary, elastic, pulley), robot, statics, effects, measurements |
//! | [`io`] | files (robot TOML; sagcal CSV, RecurDyn logs, the authors' dataset folder) -> `model` types (`model` never sees a file) |
//! | [`sim`] | closed-form and discretised simulators (the truth of the experiments) |
//! | [`graph`] | variables, the factor trait, noise, robust kernels ([`calib`]'s factors wrap [`generated`]) |
//! | [`solver`] | sparse Levenberg-Marquardt: pattern, Schur / Cholesky, covariance |
//! | [`calib`], [`diagnose`], [`localize`], [`plan`] | the jobs: staged calibration; residual tests, candidate effects, verdict; pose and tensions from the cable readings; the poses to visit (optimal design on the Cramer-Rao bound) |
//! | [`check`] | what sagcal understood from a user's robot and data files, before any fit, and their likely mistakes |
//! | [`experiments`] | Table II protocol, hidden effects, the benchmark problem |
//! | [`plot`] | figures, SVG or PNG (rendered with a bundled font) |
//! | the `sagcal` binary | a thin clap layer, one file per command |
//!
//! The residuals and their analytic Jacobians are derived with SymForce in
//! `codegen/` and emitted into [`generated`].
//!
//! Each job has a short program in `examples/` on the built-in robot:
//! `cargo run --release --example calibrate` (also `diagnose`, `localize`,
//! `simulate`).
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
#![deny(rustdoc::broken_intra_doc_links)]

pub mod calib;
pub mod cancel;
pub mod check;
pub mod diagnose;
pub mod error;
pub mod experiments;
#[path = "../generated/mod.rs"]
#[allow(missing_docs, clippy::all)]
pub mod generated;
pub mod graph;
pub mod io;
pub mod localize;
pub mod model;
pub mod plan;
pub mod plot;
pub mod sim;
pub mod simd;
pub mod solver;
pub mod stats;
pub mod steps;

pub use error::{Error, Result};
