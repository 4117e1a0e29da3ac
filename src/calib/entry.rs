//! The calibration's entry point, [`calibrate`]: the measurements checked,
//! then the staged pipeline once ([`super::pipeline`]) or, for
//! [`OrientationPrior::Auto`] with catenary cables, the calibrations with and
//! without the orientation prior ([`super::orientation`]).

use super::graph::validate_measurements;
use super::options::{CableModel, CalibrationOptions, OrientationPrior};
use super::orientation;
use super::pipeline::calibrate_once;
use super::result::CalibrationResult;
use super::system_scope;
use crate::error::Result;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::Robot;

/// Calibrate anchors and length offsets from `measurements`, starting from `initial`.
///
/// Stages (see the module docs): for the catenary model, a rigid-cable
/// calibration from `initial`, then from both `initial` and that calibration
/// (and, if neither ends in a minimum consistent with the noise, from their
/// anchors mixed cable by cable) per-pose statics with closed-form offsets,
/// the relaxed-statics graph and the full graph; the lowest final cost wins.
/// For the rigid model, the rigid graph alone.
pub fn calibrate(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    calibrate_with_stages(initial, measurements, options, &mut |_| {})
}

/// [`calibrate`], telling `stage` the name of each stage before it is
/// solved (`rigid`, `catenary (relaxed statics)`, `catenary`, once per start
/// and per fit of the orientation test); it changes nothing computed.
pub(super) fn calibrate_with_stages(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<CalibrationResult> {
    let _shared_system = system_scope::Scope::enter();
    validate_measurements(measurements)?;
    if options.orientation_prior == OrientationPrior::Auto && options.model == CableModel::Catenary {
        return orientation::calibrate_testing_orientation(initial, measurements, options, stage);
    }
    calibrate_once(initial, measurements, options, stage)
}
