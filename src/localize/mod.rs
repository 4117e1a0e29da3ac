//! Localisation after calibration (the paper's Sec. VI future work): the
//! calibrated robot's pose and cable tensions from its four encoder readings,
//! optionally its load cell and a localiser prior.
//!
//! Four lengths fix the 6-DoF pose only through the statics: 8 unknowns (pose
//! and the reference cable's `(f_h, f_v)`) against 8 equations, the four
//! catenary lengths (eq. 1-4, 14: encoder = length + calibrated offset) and
//! the four attachment heights (eq. 15) with the tensions of eq. (11). This
//! is problem (c) of `model::statics` ([`crate::model::statics::solve_forward`]),
//! solved here with the generated analytic Jacobians, the robot file's
//! `[effects]` (elastic cable, pulley, encoder scale, load-cell model, centre
//! of mass shift, segmented cable) and fixed-size matrices. A load-cell
//! reading is a 9th equation (eq. 16; least squares, chi-square with 1 degree
//! of freedom); `--pose-prior` adds the localiser's 6 rows.
//!
//! [`Localizer::localize`] returns the equilibrium with the covariance of the
//! pose from the reading noise, a chi-square consistency test of the row and
//! the equilibrium's stability at fixed cable lengths ([`stiffness`]): the
//! stable solution nearest the warm start (or prior) is chosen, a row no
//! stable equilibrium explains is an error or flagged, never forced.
//!
//! The hot path (a warm start that converges to a stable equilibrium)
//! allocates nothing: every matrix is fixed-size.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::localize::{Localizer, Readings};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//!
//! let robot = Robot::builtin("large")?;
//! // Where the platform hangs, and what its encoders and load cell read there.
//! let truth = solve_level(&robot, Vector3::new(2.0, -3.0, 15.0), &StaticsOptions::default())?;
//! let readings = Readings {
//!     encoder_lengths_m: truth.cable_lengths_m,
//!     load_cell_n: Some(truth.tensions[robot.reference_cable].magnitude_n()),
//!     localiser_pose: None,
//! };
//! let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n))?;
//! let found = localizer.localize(&readings, None)?;
//! assert!((found.pose.position_m - truth.pose.position_m).norm() < 1e-9);
//! assert!(found.stable && found.consistent);
//! # Ok::<(), sagcal::Error>(())
//! ```

mod equations;
mod equilibria;
mod frame;
mod localizer;
mod newton;
mod sequence;
mod settings;
pub mod stiffness;
pub mod suspended;
mod suspended_rows;

pub use equations::{
    model_at_pose, parameter_partials, ModelAtPose, ParameterPartials, SlotRobot, EPSILON, MEASUREMENT_ROWS,
    PARAMETERS, UNKNOWNS,
};
pub use equilibria::tilt_deg;
pub use frame::Frame;
pub use localizer::{trilaterate, LocalizeOptions, Localized, Localizer, Readings};
pub use sequence::{EquilibriumSearch, SequenceRow};
pub use settings::{require_pose_priors, LocalizeSettings};
pub use suspended_rows::{localize_suspended_rows, SuspendedLocalizationReport, SuspendedRowReport};
