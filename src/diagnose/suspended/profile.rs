//! One extension's parameter fitted by the profile of the calibration's
//! chi-square: at each value of the parameter every anchor, offset, pose and
//! force is calibrated again ([`calibrate_suspended`]), and the parameter
//! moves to the minimum of the parabola through three such chi-squares
//! (Newton's step on the profile, `theta - chi2' / chi2''`). Near its
//! minimum the profile chi-square is `chi2(theta_hat) + (theta -
//! theta_hat)^2 / sigma^2`, so its curvature gives the parameter's 1-sigma,
//! `sigma = sqrt(2 / chi2'')` (the profile likelihood; Pawitan, *In All
//! Likelihood*, 2001, ch. 3.4), and `chi2(null) - chi2(theta_hat)` is the
//! likelihood-ratio statistic of one degree of freedom (Wilks).
//!
//! ```
//! use sagcal::diagnose::suspended::{calibrated_chi_square, SuspendedExtension};
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("three")?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! // Too few poses: the error of the calibration, not a number.
//! assert!(calibrated_chi_square(&robot, &[], SuspendedExtension::Elastic, 0.0, &options).is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use super::extensions::SuspendedExtension;
use crate::calib::suspended::{calibrate_suspended, SuspendedCalibration};
use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// Newton steps at most.
const MAX_STEPS: usize = 8;
/// The search stops when a step is below this fraction of the 1-sigma.
const STEP_TOLERANCE_SIGMAS: f64 = 0.01;

/// The fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileFit {
    /// The parameter's value at the profile's minimum.
    pub value: f64,
    /// Its 1-sigma from the profile's curvature.
    pub sigma: f64,
    /// The calibration's chi-square there.
    pub chi_square: f64,
    /// The calibration's chi-square at the baseline's value.
    pub null_chi_square: f64,
}

/// The calibration of `robot` from `measurements` with `extension` at `value`.
pub fn calibrate_with(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    extension: SuspendedExtension,
    value: f64,
    options: &CalibrationOptions,
) -> Result<SuspendedCalibration> {
    let (robot, measurements) = extension.apply(robot, measurements, value);
    calibrate_suspended(&robot, &measurements, options, None, &mut |_| {})
}

/// The chi-square `2 F` of [`calibrate_with`].
pub fn calibrated_chi_square(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    extension: SuspendedExtension,
    value: f64,
    options: &CalibrationOptions,
) -> Result<f64> {
    let fit = calibrate_with(robot, measurements, extension, value, options)?;
    Ok(2.0 * fit.final_cost)
}

/// Fit `extension`'s parameter to `measurements` (module docs), starting at
/// its null value with its first step; an error where the profile has no
/// minimum (flat or concave: the readings do not determine the parameter).
pub fn fit_profile(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    extension: SuspendedExtension,
    options: &CalibrationOptions,
) -> Result<ProfileFit> {
    let chi = |value: f64| calibrated_chi_square(robot, measurements, extension, value, options);
    let null_value = extension.null_value();
    let null_chi_square = chi(null_value)?;
    let mut value = null_value;
    let mut centre = null_chi_square;
    let mut step = extension.first_step(robot, measurements);
    let mut sigma = f64::NAN;
    for _ in 0..MAX_STEPS {
        let (plus, minus) = (chi(value + step), chi(value - step));
        let (Ok(plus), Ok(minus)) = (plus, minus) else {
            step /= 4.0;
            continue;
        };
        let curvature = (plus + minus - 2.0 * centre) / (step * step);
        if !(curvature > 0.0 && curvature.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the readings do not determine the {} (the chi-square is not convex in it around {value:.4e})",
                extension.parameter()
            )));
        }
        sigma = (2.0 / curvature).sqrt();
        let slope = (plus - minus) / (2.0 * step);
        // Newton's step, kept within ten of the probes' spacing.
        let newton = (-slope / curvature).clamp(-10.0 * step, 10.0 * step);
        let (next, next_chi) = descend(&chi, value, centre, newton)?;
        let moved = (next - value).abs();
        (value, centre) = (next, next_chi);
        step = sigma.min(10.0 * step).max(1e-3 * sigma);
        if moved < STEP_TOLERANCE_SIGMAS * sigma {
            break;
        }
    }
    if !sigma.is_finite() {
        return Err(Error::InvalidInput(format!(
            "no calibration converged near the baseline's {}",
            extension.parameter()
        )));
    }
    Ok(ProfileFit {
        value,
        sigma,
        chi_square: centre,
        null_chi_square,
    })
}

/// From `value` (chi-square `centre`), `step` or the largest of its halves
/// (at most five) that does not raise the chi-square; where none does, stay.
fn descend(chi: &dyn Fn(f64) -> Result<f64>, value: f64, centre: f64, step: f64) -> Result<(f64, f64)> {
    let mut trial = step;
    for _ in 0..6 {
        if let Ok(at) = chi(value + trial) {
            if at <= centre {
                return Ok((value + trial, at));
            }
        }
        trial /= 2.0;
    }
    Ok((value, centre))
}
