//! One initial guess and one set of measurements calibrated several times
//! under options that differ only in the orientation prior and the free
//! effects (`diagnose` refits every hypothesis from the initial guess): the
//! stages those options do not enter are made once.
//!
//! Stages (1) and (2) of the catenary pipeline (module docs of
//! [`crate::calib`]), the rigid calibration and the per-pose warm-ups of its
//! two starts, read only the sensor sigmas, the robust kernels and the solver
//! settings: the rigid graph holds the localiser's orientation whatever the
//! orientation prior says and has no effect variables, and the warm-ups solve
//! the statics of the robot as given. A calibration from a
//! [`PreparedCalibration`] is therefore the same, digit for digit, as
//! [`calibrate`] with the same arguments.

use super::entry::calibrate;
use super::graph::validate_measurements;
use super::options::{CableModel, CalibrationOptions, OrientationPrior};
use super::orientation;
use super::pipeline::{calibrate_prepared, CatenaryPreparation};
use super::result::CalibrationResult;
use crate::error::Result;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::Robot;

/// An initial guess and measurements with the stages of their catenary
/// calibration that the orientation prior and the free effects do not enter.
pub struct PreparedCalibration {
    initial: Robot,
    measurements: Vec<PoseMeasurement>,
    /// The options the stages were made with.
    options: CalibrationOptions,
    /// `None` if the stages failed (or the model is rigid): [`calibrate`]
    /// then reports the error itself.
    prepared: Option<CatenaryPreparation>,
}

impl PreparedCalibration {
    /// Make the rigid stage and the warm-ups for `initial` and `measurements` under `options`.
    pub fn new(initial: &Robot, measurements: &[PoseMeasurement], options: &CalibrationOptions) -> Self {
        let _shared_system = super::system_scope::Scope::enter();
        let prepared = (options.model == CableModel::Catenary && validate_measurements(measurements).is_ok())
            .then(|| CatenaryPreparation::new(initial, measurements, options, &mut |_| {}).ok())
            .flatten();
        PreparedCalibration {
            initial: initial.clone(),
            measurements: measurements.to_vec(),
            options: *options,
            prepared,
        }
    }

    /// [`calibrate`] of the initial guess and measurements under `options`:
    /// from the prepared stages when `options` differ from the ones they were
    /// made with only in the orientation prior and the free effects, else
    /// from the start.
    pub fn calibrate(&self, options: &CalibrationOptions) -> Result<CalibrationResult> {
        let _shared_system = super::system_scope::Scope::enter();
        let shared = CalibrationOptions {
            orientation_prior: options.orientation_prior,
            free_effects: options.free_effects,
            ..self.options
        };
        let (initial, measurements) = (&self.initial, self.measurements.as_slice());
        match &self.prepared {
            Some(prepared) if shared == *options => {
                if options.orientation_prior == OrientationPrior::Auto {
                    orientation::testing_orientation_prepared(initial, measurements, options, prepared, &mut |_| {})
                } else {
                    calibrate_prepared(initial, measurements, options, prepared, &mut |_| {})
                }
            }
            _ => calibrate(initial, measurements, options),
        }
    }

    /// The initial guess.
    pub fn initial(&self) -> &Robot {
        &self.initial
    }

    /// The measurements it calibrates.
    pub fn measurements(&self) -> &[PoseMeasurement] {
        &self.measurements
    }
}
