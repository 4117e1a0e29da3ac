//! Data simulators. [`closed_form`] uses sagcal's own catenary model (no model
//! mismatch: what the Cramer-Rao bound describes).
//! [`discretised`]: an independent check, elastic lumped-mass chains over swivelling pulleys.
//! [`effects`]: data with effects the closed-form model lacks, through [`discretised`].
//! [`suspended`]: the closed-form model on robots of 3 to 8 cables.
//! [`discretised_suspended`]: the discretised simulator on robots of 3 to 8 cables.
//! [`suspended_effects`]: data of robots of 3 to 8 cables with effects, through [`discretised_suspended`].
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let mut robot = Robot::builtin("large")?;
//! robot.length_offsets_m = [1.0, -2.0, 0.5, 0.0];
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
//! let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 3, &mut rng)?;
//! let noise = NoisePreset::None.sigmas(robot.platform_weight_n);
//! let data = measure(&robot, &equilibria, &noise, &mut rng);
//! // Without noise an encoder reads the cable length plus its offset (paper eq. 14).
//! for (m, e) in data.iter().zip(&equilibria) {
//!     for i in 0..4 {
//!         assert!((m.encoder_lengths_m[i] - (e.cable_lengths_m[i] + robot.length_offsets_m[i])).abs() < 1e-9);
//!     }
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod closed_form;
pub mod discretised;
pub mod discretised_suspended;
pub mod effects;
pub mod suspended;
pub mod suspended_effects;
