//! What the model of `N` cables gets wrong ([`diagnose_suspended`]):
//! `sagcal diagnose` on a robot of 3 to 8 cables.
//!
//! 1. The baseline (the calibration of [`crate::calib::suspended`]) is
//!    tested: its chi-square against the `1 - false_alarm` quantile of its
//!    degrees of freedom. Where it passes, no cause is named.
//! 2. Each extension of the model ([`SuspendedExtension`]: the cables'
//!    stiffness, their weight, the platform's weight, the encoders' common
//!    gain, the load cells' gain or bias, one drum's gain, one cable's
//!    weight) has its one parameter fitted by
//!    the profile of the calibration's chi-square ([`fit_profile`]) and is
//!    tested by the likelihood ratio against chi-square with one degree of
//!    freedom at `false_alarm / K` (Bonferroni over the `K` extensions, so
//!    the whole search's false-alarm rate is at most `false_alarm` on data
//!    the baseline describes).
//! 3. Each model is scored by prediction: its summed chi-square on poses
//!    held out of its calibration ([`super::suspended::held_out`]).
//! 4. A cause is named only if the extension is significant, predicts
//!    held-out poses better than the baseline and than every other such
//!    extension (Vuong's paired test on the poses' held-out chi-squares at
//!    [`INDISTINGUISHABLE_Z`] standard errors), its fitted
//!    value is one a real robot has, the extended model passes the
//!    chi-square test ([`SuspendedVerdict`]), and its residuals hold no
//!    term it lacks (score tests of each reading against its own drivers,
//!    [`residual_structure`]). The likelihood ratio is the
//!    more powerful test against one named alternative, so an extension can
//!    be named where the baseline's omnibus test passes. An extension whose
//!    value no real robot has is reported as a stand-in, and one that leaves
//!    the model failing, or structure in its residuals, as taking up part
//!    of the misfit: neither is named. The effects the N-cable model does
//!    not carry ([`NOT_MODELLED`]) are found by the baseline's test, never
//!    named as themselves; an extension can still stand in for one with a
//!    plausible value, and where the residual tests lack the power to see
//!    what it leaves, be named (docs/diagnose.md).
//!
//! [`verify_suspended`] tests a robot file, held as it is, against a data
//! file (`sagcal verify`): each row's pose and forces fitted to its
//! readings, the whole file, each row and each reading tested.
//!
//! ```
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::diagnose::suspended::{diagnose_suspended, SuspendedDiagnoseSettings, SUSPENDED_EXTENSIONS};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("six")?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! let settings = SuspendedDiagnoseSettings { extensions: SUSPENDED_EXTENSIONS.to_vec(), folds: 1, false_alarm: 1e-3 };
//! let refused = diagnose_suspended(&robot, &[], &settings, &options, &|_, _| {}).unwrap_err();
//! assert!(refused.to_string().contains("folds"), "{refused}");
//! # Ok::<(), sagcal::Error>(())
//! ```

mod extensions;
pub mod held_out;
mod pipeline;
mod profile;
mod residual_structure;
mod truth;
mod verify;

pub use extensions::{
    extensions_named, suspended_catalogue, SuspendedExtension, MAX_SPECIFIC_MODULUS_J_PER_KG, NOT_MODELLED,
    SUSPENDED_EXTENSIONS,
};
pub use held_out::{cross_validated_chi_square, fit_poses_robot_held, fold_of, held_out_chi_squares};
pub use pipeline::{
    diagnose_suspended, paired_z, SuspendedBaseline, SuspendedDiagnoseSettings, SuspendedDiagnosis,
    SuspendedExtensionFit, SuspendedVerdict, INDISTINGUISHABLE_Z,
};
pub use profile::{calibrate_with, calibrated_chi_square, fit_profile, ProfileFit};
pub use residual_structure::{residual_structure, ResidualStructure, ResidualTerm};
pub use truth::{errors_against_truth, TruthError};
pub use verify::{
    verify_suspended, ResidualSummary, SuspectReading, SuspendedVerifiedRow, SuspendedVerifyReport, VerifiedReading,
    DETECTION_POWER_Z,
};
