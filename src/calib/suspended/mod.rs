//! Calibration of a platform hung from any number `N >= 3` of sagging
//! cables ([`calibrate_suspended`]).
//!
//! The four-cable graph solves the other cables' forces from the reference
//! cable's (paper eq. 11). With `N` cables `2N - 6` force components are
//! free at every pose (none for three cables, ten for eight), so this graph
//! carries every cable's `(f_h, f_v)` as a variable of its pose, closed by
//! each cable's length (eq. 14) and attachment height (eq. 15), by the six
//! equations of equilibrium (eq. 5-8) and by every load cell (eq. 16). For
//! three cables this is necessary, not a choice: the dependent block of
//! [`crate::model::suspended`] is singular at every equilibrium.
//!
//! The stages: (1) massless straight cables from the guess, with the
//! localiser's full pose (nothing else holds the orientation without
//! statics) and the offsets in closed form; (2) every pose's equilibrium at
//! its measured position for those anchors
//! ([`crate::model::suspended::solve_at`]), the offsets again in closed
//! form; (3) the catenary graph with the anchors held; (4) all free.
//!
//! ```
//! use sagcal::calib::suspended::{calibrate_suspended, min_poses};
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::suspended::SuspendedRobot;
//! use sagcal::model::sensors::NoisePreset;
//! let robot = SuspendedRobot::builtin("three")?;
//! // 12 anchor and offset unknowns, 4 equations per pose (one load cell, 3 positions) without the orientation.
//! assert_eq!(min_poses(&robot, false), 4);
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! assert!(calibrate_suspended(&robot, &[], &options, None, &mut |_| {}).is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

mod calibrate;
pub mod factors;
mod graph;
mod gross_errors;
mod options;
mod report;
mod start;
mod trilateration;

pub use calibrate::{calibrate_suspended, SuspendedCalibration};
pub use graph::{
    build_suspended_graph, min_poses, pose_starts_from_graph, robot_from_suspended_graph, Exclusions, PoseStart,
    SuspendedGraph, SuspendedPoseVariables, SuspendedReading, SuspendedStage, EQUILIBRIUM_SIGMA_PER_WEIGHT,
};
pub use gross_errors::{reading_count, worst_reading, SuspendedGrossError, READING_KINDS};
pub use options::suspended_options;
pub use report::{SuspendedCalibrationReport, UndeterminedForces};
pub use start::{catenary_starts, chord_shares, offsets_in_closed_form, straight_offsets};
pub use trilateration::{anchors_by_trilateration, STARTS};
