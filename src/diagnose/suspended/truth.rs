//! What each model of a diagnosis gains where the truth is known (a
//! simulation's robot file): its calibrated anchors and offsets against the
//! true ones, for the baseline and for every extension at its fitted value.
//! The gain of a named cause is then measured, not assumed: the anchor
//! error of the baseline against that of the extended model.
//!
//! ```
//! use sagcal::diagnose::suspended::{errors_against_truth, SuspendedExtension};
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("six")?;
//! let three = SuspendedRobot::builtin("three")?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! // A truth of another number of cables is refused by name.
//! let models = [(SuspendedExtension::Elastic, 0.0)];
//! let refused = errors_against_truth(&robot, &[], &models, &three, &options).unwrap_err();
//! assert!(refused.to_string().contains("3 cables"), "{refused}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use rayon::prelude::*;
use serde::Serialize;

use super::extensions::SuspendedExtension;
use super::profile::calibrate_with;
use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// One model's calibration against the truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TruthError {
    /// The model: `baseline` or the extension's name.
    pub model: String,
    /// The extension's parameter at which it was calibrated.
    pub value: f64,
    /// Mean absolute error of the anchor coordinates, metres.
    pub anchor_mae_m: f64,
    /// Mean Euclidean distance of the anchors from the true ones, metres.
    pub anchor_mean_distance_m: f64,
    /// Largest Euclidean distance of an anchor from its true one, metres.
    pub anchor_max_distance_m: f64,
    /// Mean absolute error of the length offsets, metres.
    pub offset_mae_m: f64,
    /// Why the calibration failed (the errors are then NaN).
    pub failure: Option<String>,
}

/// Each of `models` (an extension at a value; `Elastic` at 0 is the
/// baseline) calibrated on `measurements` and compared with `truth`, a
/// robot of `robot`'s cables.
pub fn errors_against_truth(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    models: &[(SuspendedExtension, f64)],
    truth: &SuspendedRobot,
    options: &CalibrationOptions,
) -> Result<Vec<TruthError>> {
    let n = robot.cable_count();
    if truth.cable_count() != n {
        return Err(Error::InvalidInput(format!(
            "the truth `{}` has {} cables and the robot `{}` {n}: a truth is the same robot",
            truth.name,
            truth.cable_count(),
            robot.name
        )));
    }
    let errors = models
        .par_iter()
        .map(|&(extension, value)| {
            let model = match extension == SuspendedExtension::Elastic && value == 0.0 {
                true => "baseline".to_string(),
                false => extension.name(),
            };
            let mut row = TruthError {
                model,
                value,
                anchor_mae_m: f64::NAN,
                anchor_mean_distance_m: f64::NAN,
                anchor_max_distance_m: f64::NAN,
                offset_mae_m: f64::NAN,
                failure: None,
            };
            match calibrate_with(robot, measurements, extension, value, options) {
                Ok(fit) => {
                    let distances: Vec<f64> = (0..n)
                        .map(|i| (fit.robot.anchors_m[i] - truth.anchors_m[i]).norm())
                        .collect();
                    let coordinates: f64 = (0..n)
                        .map(|i| (fit.robot.anchors_m[i] - truth.anchors_m[i]).abs().sum())
                        .sum();
                    let offsets: f64 = (0..n)
                        .map(|i| (fit.robot.length_offsets_m[i] - truth.length_offsets_m[i]).abs())
                        .sum();
                    row.anchor_mae_m = coordinates / (3 * n) as f64;
                    row.anchor_mean_distance_m = distances.iter().sum::<f64>() / n as f64;
                    row.anchor_max_distance_m = distances.iter().copied().fold(0.0, f64::max);
                    row.offset_mae_m = offsets / n as f64;
                }
                Err(e) => row.failure = Some(e.to_string()),
            }
            row
        })
        .collect();
    Ok(errors)
}
