//! The localiser's orientation: used as a prior, or dropped when a
//! chi-square test finds it inconsistent with the fitted statics
//! ([`OrientationPrior::Auto`], module docs of [`crate::calib`]).

use super::graph::{build_graph, measured_pose};
use super::options::{CableModel, CalibrationOptions, OrientationPrior};
use super::pipeline::{calibrate_prepared, finish, solve_stage, CatenaryPreparation};
use super::result::{CalibrationResult, OrientationCheck};
use crate::error::Result;
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::robot::Robot;
use crate::stats::{chi_square_critical, chi_square_quantile_999};

/// Chi-square of the localiser's orientations (less the robot's localiser
/// mount, [`crate::model::effects::Effects::localiser_mount_deg`]) against the
/// fitted poses of a calibration made with the orientation prior. Conservative: the fitted
/// orientation is pulled towards the measured one, so consistent data give
/// less than the `3 N` degrees of freedom tested against.
///
/// Rows whose orientation readings were left out as gross errors do not
/// count. When the test fails because of a few rows alone (each beyond the
/// chi-square critical value with 3 degrees of freedom at `1e-3 / N`,
/// Bonferroni over the rows; at most 5 % of them, and at least one), the test
/// is made without them: one mistyped angle is a blunder of its row, for the
/// gross-error tests to name, not a localiser at odds with the statics.
fn orientation_check(result: &CalibrationResult, measurements: &[PoseMeasurement], sigma_rad: f64) -> OrientationCheck {
    let used = (0..measurements.len()).filter(|k| !result.excluded_poses.contains(k));
    // A localiser mounted with a rotation M reads R M: the platform orientation it implies is R_read M^-1.
    let mount = result.robot.effects.localiser_mount_deg.map(f64::to_radians);
    let unmount = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::from(mount)).inverse();
    let left_out = |k: usize| (0..3).any(|a| measurements[k].excluded.contains(Sensor::Orientation(a)));
    let angles: Vec<f64> = used
        .zip(&result.poses)
        .filter(|(k, _)| !left_out(*k))
        .map(|(k, fitted)| (measured_pose(&measurements[k]).rotation * unmount).angle_to(&fitted.rotation))
        .collect();
    let check = chi_square_of(&angles, sigma_rad);
    if check.chi_square <= check.limit || angles.is_empty() {
        return check;
    }
    let critical = chi_square_critical(3, 1e-3 / angles.len() as f64);
    let (outliers, rest): (Vec<f64>, Vec<f64>) = angles.iter().partition(|a| (*a / sigma_rad).powi(2) > critical);
    let allowed = (angles.len() / 20).max(1);
    if outliers.is_empty() || outliers.len() > allowed {
        return check;
    }
    chi_square_of(&rest, sigma_rad)
}

/// The orientation test of these angles between measured and fitted orientations.
fn chi_square_of(angles: &[f64], sigma_rad: f64) -> OrientationCheck {
    let chi_square = angles.iter().map(|a| (a / sigma_rad).powi(2)).sum();
    let components = 3 * angles.len();
    OrientationCheck {
        prior_used: true,
        chi_square,
        components,
        limit: chi_square_quantile_999(components),
        mean_angle_deg: angles.iter().sum::<f64>() / angles.len().max(1) as f64 * 180.0 / std::f64::consts::PI,
    }
}

/// The full catenary graph under `options`, started from `result`'s solution
/// (its poses left out stay out).
fn refit_from(
    result: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<CalibrationResult> {
    let used: Vec<PoseMeasurement> = (0..measurements.len())
        .filter(|k| !result.excluded_poses.contains(k))
        .map(|k| measurements[k])
        .collect();
    let mut built = build_graph(
        &result.robot,
        &used,
        &result.poses,
        &result.reference_tensions(),
        CableModel::Catenary,
        options,
    );
    let mut stages = result.stages.clone();
    let name = "catenary (orientation prior, from the fit without it)";
    stage(name);
    stages.push(solve_stage(name, &mut built, &options.lm)?);
    finish(&result.robot, built, stages, result.excluded_poses.clone())
}

impl CalibrationOptions {
    /// These options with [`OrientationPrior::Auto`] resolved to what `result`
    /// used (`On` if it kept the prior, else `Off`): the options under which
    /// to compare `result` with its Cramer-Rao bound.
    pub fn as_used_by(&self, result: &CalibrationResult) -> CalibrationOptions {
        let orientation_prior = match (self.orientation_prior, result.orientation_check) {
            (OrientationPrior::Auto, Some(check)) if check.prior_used => OrientationPrior::On,
            (OrientationPrior::Auto, _) => OrientationPrior::Off,
            (other, _) => other,
        };
        CalibrationOptions {
            orientation_prior,
            ..*self
        }
    }
}

/// [`OrientationPrior::Auto`]: calibrate with the orientation prior, test the
/// localiser's orientations against the fitted statics ([`orientation_check`]),
/// and calibrate again without the prior if they are inconsistent (or if the
/// calibration with it fails), unless a second calibration with the prior,
/// started from the anchors found without it, passes the test (the first one
/// had ended in a wrong basin). The test is recorded in the result. `stage`
/// is told the name of each stage before it is solved.
pub(super) fn calibrate_testing_orientation(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<CalibrationResult> {
    let with_prior = CalibrationOptions {
        orientation_prior: OrientationPrior::On,
        ..*options
    };
    // The rigid stage and the warm-ups do not depend on the prior: made once
    // for both calibrations (an error there is the same for both).
    let prepared = CatenaryPreparation::new(initial, measurements, &with_prior, stage)?;
    testing_orientation_prepared(initial, measurements, options, &prepared, stage)
}

/// [`calibrate_testing_orientation`] from the rigid stage and warm-ups of a
/// [`CatenaryPreparation`] made for the same initial guess and measurements.
pub(super) fn testing_orientation_prepared(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    prepared: &CatenaryPreparation,
    stage: &mut dyn FnMut(&str),
) -> Result<CalibrationResult> {
    let with_prior = CalibrationOptions {
        orientation_prior: OrientationPrior::On,
        ..*options
    };
    let without_prior = CalibrationOptions {
        orientation_prior: OrientationPrior::Off,
        ..*options
    };
    let Ok(mut result) = calibrate_prepared(initial, measurements, &with_prior, prepared, stage) else {
        return calibrate_prepared(initial, measurements, &without_prior, prepared, stage);
    };
    let mut check = orientation_check(&result, measurements, options.noise.orientation_sigma_rad);
    if check.chi_square <= check.limit {
        result.orientation_check = Some(check);
        return Ok(result);
    }
    let mut result = calibrate_prepared(initial, measurements, &without_prior, prepared, stage)?;
    // A failed test says the localiser disagrees with the statics *at the
    // anchors found*: if the fit with the prior ended in a wrong basin (its
    // statics orientations then disagree with every localiser reading), the
    // test blames the localiser for the anchors. The fit without the prior
    // does not depend on the orientations, so its solution (anchors, offsets,
    // poses, tensions) is the start of a second fit with the prior, one stage
    // from a minimum; if that one passes, the localiser was right.
    if let Ok(mut again) = refit_from(&result, measurements, &with_prior, stage) {
        let second = orientation_check(&again, measurements, options.noise.orientation_sigma_rad);
        if second.chi_square <= second.limit {
            again.orientation_check = Some(second);
            return Ok(again);
        }
    }
    check.prior_used = false;
    result.orientation_check = Some(check);
    Ok(result)
}
