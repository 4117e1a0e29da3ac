//! What a model predicts on poses it did not see: `F`-fold cross-validation
//! over the poses (pose `k` in fold `k mod F`). For each fold the model
//! (the baseline, or an extension with its parameter fitted again,
//! [`super::fit_profile`]) is calibrated on the other folds' poses; then,
//! its anchors, offsets and parameter held, each held-out pose's own pose
//! and forces are fitted to its readings, and what is left is the held-out
//! chi-square. Summed over the folds, it scores the model by prediction, not
//! by its in-sample fit: a parameter that only absorbs noise raises it.
//!
//! ```
//! use sagcal::diagnose::suspended::fold_of;
//! assert_eq!((0..7).map(|k| fold_of(k, 3)).collect::<Vec<_>>(), vec![0, 1, 2, 0, 1, 2, 0]);
//! ```

use super::extensions::SuspendedExtension;
use super::profile::{calibrate_with, fit_profile};
use crate::calib::suspended::{build_suspended_graph, catenary_starts, Exclusions, SuspendedGraph, SuspendedStage};
use crate::calib::{CalibrationOptions, OrientationPrior};
use crate::error::{Result, SolverError};
use crate::graph::FactorGraph;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::solver::optimize;

/// The fold of pose `k` of `folds`.
pub fn fold_of(k: usize, folds: usize) -> usize {
    k % folds
}

/// Per pose of `measurements` (held out), the chi-square of its readings
/// under the calibrated `robot`: each pose's platform pose and forces
/// fitted, nothing of the robot. (The model's equations, tight constraints
/// rather than readings, are left out of the sums.)
pub fn held_out_chi_squares(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    options: &CalibrationOptions,
) -> Result<Vec<f64>> {
    let with_orientation = options.orientation_prior != OrientationPrior::Off;
    let built =
        fit_poses_robot_held(robot, measurements, options, with_orientation).map_err(|e| e.during("held-out poses"))?;
    let mut per_pose = vec![0.0; measurements.len()];
    for (factor, readings) in built.graph.factors.iter().zip(&built.readings) {
        if let (Some(&(pose, _)), Some(cost)) = (
            readings.first(),
            FactorGraph::factor_cost(factor.as_ref(), &built.graph.values),
        ) {
            per_pose[pose] += 2.0 * cost;
        }
    }
    Ok(per_pose)
}

/// The graph of every pose of `measurements` (its platform pose and cable
/// forces) under `robot`, its anchors and offsets held, solved: the
/// localiser's orientation a reading only `with_orientation`.
pub fn fit_poses_robot_held(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    options: &CalibrationOptions,
    with_orientation: bool,
) -> std::result::Result<SuspendedGraph, SolverError> {
    let (starts, _) = catenary_starts(robot, measurements);
    let mut built = build_suspended_graph(
        robot,
        measurements,
        &starts,
        SuspendedStage::Catenary,
        options,
        with_orientation,
        &Exclusions::new(),
    );
    for &id in built.anchors.iter().chain(&built.length_offsets) {
        built.graph.values.set_fixed(id, true);
    }
    optimize(&mut built.graph, &options.lm)?;
    Ok(built)
}

/// Per pose, the held-out chi-square of `extension` over `folds` folds
/// (each pose is held out once): its parameter fitted on each fold's
/// training poses, or held at its null value (the baseline) where `fit` is false.
pub fn cross_validated_chi_square(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    extension: SuspendedExtension,
    fit: bool,
    folds: usize,
    options: &CalibrationOptions,
) -> Result<Vec<f64>> {
    let mut per_pose = vec![0.0; measurements.len()];
    for fold in 0..folds {
        let (training, held): (Vec<_>, Vec<_>) = measurements
            .iter()
            .enumerate()
            .partition(|(k, _)| fold_of(*k, folds) != fold);
        let training: Vec<SuspendedMeasurement> = training.into_iter().map(|(_, m)| m.clone()).collect();
        let held: Vec<SuspendedMeasurement> = held.into_iter().map(|(_, m)| m.clone()).collect();
        let value = if fit {
            fit_profile(robot, &training, extension, options)?.value
        } else {
            extension.null_value()
        };
        let calibrated = calibrate_with(robot, &training, extension, value, options)?;
        let (_, held) = extension.apply(robot, &held, value);
        // The calibrated robot carries the extension's robot side already.
        let scores = held_out_chi_squares(&calibrated.robot, &held, options)?;
        let held_poses = (0..measurements.len()).filter(|k| fold_of(*k, folds) == fold);
        for (k, score) in held_poses.zip(scores) {
            per_pose[k] = score;
        }
    }
    Ok(per_pose)
}
