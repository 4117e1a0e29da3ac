//! Experiments that exercise the jobs end to end on simulated or logged data,
//! each reproducible from a seed.
//!
//! - [`table2`]: the paper's Table II protocol with its Cramer-Rao bound
//!   (`sagcal experiment table2`);
//! - [`hidden_effects`]: effects hidden in simulated data, diagnosed blind and
//!   scored (`sagcal experiment hidden-effects`);
//! - [`localize_after_calibration`]: calibrate by the Table II protocol, then
//!   localise the held-out poses (`sagcal experiment localize`);
//! - [`suspended_sweep`]: effects hidden in data of robots of 3 to 8 cables,
//!   scored by the calibration's own verdict (`sagcal experiment hidden-effects --robots six`);
//! - [`plan_candidates`]: candidate poses for `sagcal plan`;
//! - [`suspended_plan`]: `sagcal plan` on a robot of 3 to 8 cables;
//! - [`benchmark`]: the reproducible calibration graph the solver benches and
//!   the peer comparison share.
//!
//! ```
//! use sagcal::experiments::benchmark::{BenchmarkProblem, ANCHOR_PERTURBATION_M};
//! // The same (poses, seed) gives the same problem, for every solver that is compared on it.
//! let problem = BenchmarkProblem::new(6, 42)?;
//! assert_eq!(problem.measurements, BenchmarkProblem::new(6, 42)?.measurements);
//! let moved = (problem.initial.anchors_m[0] - problem.truth.anchors_m[0]).norm();
//! assert!((moved - ANCHOR_PERTURBATION_M).abs() < 1e-12);
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod benchmark;
mod held_out;
mod hidden_draws;
pub mod hidden_effects;
mod hidden_options;
mod identifiability;
mod leave_one_out;
pub mod localize_after_calibration;
pub mod plan_candidates;
pub mod pose_plan;
pub mod selection;
pub mod suspended_effect_draws;
pub mod suspended_plan;
pub mod suspended_sweep;
pub mod suspended_trials;
pub mod table2;
mod trial;

pub use held_out::{held_out_prediction, HeldOutPrediction};
