//! Held-out prediction of a diagnosis: poses of the same truth that the
//! diagnosis did not see, localised as `sagcal localize --pose-prior` does
//! (the four encoders, the load cell and the localiser's pose as a prior),
//! once with the baseline's calibrated robot and once with the final
//! model's (its anchors, offsets and `[effects]`). A model that holds
//! gives each row a chi-square per degree of freedom of about 1; a declared
//! cause that does not lower the mean over unseen poses does not predict.
//! The effects of time and motion act on the rows through their order
//! ([`crate::model::effects::Effects::without_time_and_motion`]): the unseen
//! poses continue the session the diagnosis saw.

use serde::Serialize;

use crate::localize::{LocalizeOptions, Localizer, Readings};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::Robot;
use crate::model::sensors::SensorNoise;

/// The held-out rows of one case under two robots.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeldOutPrediction {
    /// Rows localised.
    pub rows: usize,
    /// Rows that both robots localised (the means are over these).
    pub localised: usize,
    /// Mean chi-square per degree of freedom with the baseline's robot.
    pub chi_square_per_dof_before: f64,
    /// The same with the final model's robot.
    pub chi_square_per_dof_after: f64,
}

/// Localise `rows` with `before` and `after` (readings with the sigmas of
/// `noise`, the localiser's pose as a prior) and compare (module docs).
pub fn held_out_prediction(
    before: &Robot,
    after: &Robot,
    noise: &SensorNoise,
    rows: &[PoseMeasurement],
) -> HeldOutPrediction {
    let options = LocalizeOptions {
        pose_prior: true,
        calibration_uncertainty: false,
        ..LocalizeOptions::default()
    };
    let per_dof = |robot: &Robot| -> Vec<Option<f64>> {
        let Ok(localizer) = Localizer::with_options(robot, noise, options) else {
            return vec![None; rows.len()];
        };
        rows.iter()
            .map(|m| robot.effects.without_time_and_motion(m, robot.reference_cable))
            .map(|m| {
                let readings = Readings {
                    encoder_lengths_m: m.encoder_lengths_m,
                    load_cell_n: Some(m.reference_tension_n),
                    localiser_pose: Some(m.localiser_pose()),
                };
                let found = localizer.localize(&readings, None).ok()?;
                (found.degrees_of_freedom > 0).then(|| found.chi_square / found.degrees_of_freedom as f64)
            })
            .collect()
    };
    let (with_before, with_after) = (per_dof(before), per_dof(after));
    let both: Vec<(f64, f64)> = with_before
        .iter()
        .zip(&with_after)
        .filter_map(|(b, a)| Some(((*b)?, (*a)?)))
        .collect();
    let mean = |values: Vec<f64>| {
        if values.is_empty() {
            f64::NAN
        } else {
            values.iter().sum::<f64>() / values.len() as f64
        }
    };
    HeldOutPrediction {
        rows: rows.len(),
        localised: both.len(),
        chi_square_per_dof_before: mean(both.iter().map(|p| p.0).collect()),
        chi_square_per_dof_after: mean(both.iter().map(|p| p.1).collect()),
    }
}
