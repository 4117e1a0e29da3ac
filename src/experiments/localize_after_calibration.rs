//! Localisation after calibration, end to end: what position error a user
//! sees when the robot was calibrated by the paper's Table II protocol and
//! then localises the poses it was not calibrated on.
//!
//! Per trial ([`crate::experiments::table2::trial_inputs`], the same random
//! streams as `experiment table2`): draw `poses` of the pool, add the
//! sensor noise, perturb the initial guess, calibrate; then, for every pool
//! pose *not* drawn, read its four encoders and its load cell with fresh
//! noise of the same sigmas (a stream of its own, seeded from the trial's)
//! and localise it cold (no warm start) with
//!
//! * the calibrated robot, whose recorded covariance gives each pose's
//!   predicted sigma (reading noise and calibration),
//! * the truth (the robot file's anchors, zero offsets): the floor the
//!   reading noise and the model's own error leave.
//!
//! The position error is the distance to the pool's pose (RecurDyn's logged
//! position, or the model's equilibrium). A row no stable equilibrium
//! explains, that fails its consistency test or lies outside the robot's
//! frame ([`crate::localize::Frame`]), is counted as flagged and
//! left out of the error statistics.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::{CableModel, OrientationPrior};
//! use sagcal::experiments::localize_after_calibration::{run_trial, summarise, LocalizeTrial};
//! use sagcal::experiments::table2::{pose_pool, Protocol, Source};
//! use sagcal::model::effect_kind::EffectSet;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! use sagcal::stats::chi_square_critical;
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 12, &mut rng)?;
//! let log = measure(&truth, &equilibria, &NoisePreset::None.sigmas(truth.platform_weight_n), &mut rng);
//! let pool = pose_pool(&truth, &log, Source::Model)?;
//! let protocol = Protocol {
//!     noise: NoisePreset::Paper,
//!     model: CableModel::Catenary,
//!     anchor_perturbation_m: 1.0,
//!     offset_perturbation_m: 10.0,
//!     basin_radius_m: 3.0,
//!     orientation_prior: OrientationPrior::Auto,
//!     estimate: EffectSet::NONE,
//!     apply_gross_errors: false,
//! };
//! // Calibrate on 8 poses of the 12, localise the other 4 from their encoders and load cell.
//! let trial = run_trial(&truth, &pool, 8, 0, 5, &protocol);
//! assert!(trial.calibrated && trial.held_out == 4);
//! assert_eq!((trial.errors_m.len(), trial.flagged), (4, 0));
//! for (e, s) in trial.errors_m.iter().zip(&trial.predicted_sigma_m) {
//!     assert!(*e < 3.0 * s, "{e} m off, predicted sigma {s} m");
//! }
//! // The summary's 95 % radius: chi-square with 3 dof, sqrt(7.815 / 3) = 1.61 x the sigmas' norm.
//! let hand = LocalizeTrial {
//!     trial: 0,
//!     calibrated: true,
//!     anchor_error_m: Some(0.1),
//!     held_out: 2,
//!     errors_m: vec![0.03, 0.04],
//!     predicted_sigma_m: vec![0.02, 0.02],
//!     flagged: 0,
//!     truth_errors_m: vec![0.0, 0.0],
//! };
//! assert!((chi_square_critical(3, 0.05) - 7.8147).abs() < 1e-4);
//! let summary = summarise(&[hand])?;
//! assert!((summary.position_rms_error_m - (0.5f64 * (0.03f64.powi(2) + 0.04f64.powi(2))).sqrt()).abs() < 1e-12);
//! assert_eq!(summary.within_95_percent, 0.5); // 0.03 < 1.61 x 0.02 = 0.032 < 0.04
//! # Ok::<(), sagcal::Error>(())
//! ```

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;

use super::table2::{trial_inputs, PoolPose, Protocol};
use crate::calib::calibrate;
use crate::error::Result;
use crate::localize::{Localizer, Readings};
use crate::model::robot::{Robot, CABLE_COUNT};

/// What one trial's held-out poses gave.
#[derive(Debug, Clone, Serialize)]
pub struct LocalizeTrial {
    /// Trial index.
    pub trial: usize,
    /// Whether the calibration returned (a failed calibration localises nothing).
    pub calibrated: bool,
    /// Mean Euclidean anchor error of the calibration, metres.
    pub anchor_error_m: Option<f64>,
    /// Held-out poses localised.
    pub held_out: usize,
    /// Position errors with the calibrated robot (unflagged rows), metres.
    pub errors_m: Vec<f64>,
    /// Predicted 1-sigma position error (norm of the three axes' sigmas) of
    /// the same rows, metres.
    pub predicted_sigma_m: Vec<f64>,
    /// Rows flagged with the calibrated robot.
    pub flagged: usize,
    /// Position errors with the truth, metres.
    pub truth_errors_m: Vec<f64>,
}

/// The summary over trials.
#[derive(Debug, Clone, Serialize)]
pub struct LocalizeSummary {
    /// Trials run.
    pub trials: usize,
    /// Trials whose calibration returned.
    pub calibrated: usize,
    /// Mean over trials of the calibration's mean anchor error, metres.
    pub anchor_error_m: f64,
    /// RMS of the position error over every localised held-out row, metres.
    pub position_rms_error_m: f64,
    /// Median over trials of the per-trial RMS, metres.
    pub median_trial_rms_m: f64,
    /// Largest position error, metres.
    pub position_max_error_m: f64,
    /// RMS of the predicted sigmas (reading noise and calibration), metres.
    pub predicted_rms_sigma_m: f64,
    /// Share of localised rows whose error is within their predicted
    /// 3-D 95 % radius (chi-square, 3 dof: 2.80 times the RMS-axis sigma).
    pub within_95_percent: f64,
    /// Share of held-out rows flagged.
    pub flagged_share: f64,
    /// RMS position error with the truth, metres.
    pub truth_rms_error_m: f64,
}

/// Run `trials` trials of `poses` calibration poses each (in parallel;
/// every trial reproducible from `(seed, poses, trial)`); `progress` is
/// called once per finished trial.
pub fn run(
    truth: &Robot,
    pool: &[PoolPose],
    poses: usize,
    trials: usize,
    seed: u64,
    protocol: &Protocol,
    progress: &(dyn Fn() + Sync),
) -> Vec<LocalizeTrial> {
    (0..trials)
        .into_par_iter()
        .map(|trial| {
            let result = run_trial(truth, pool, poses, trial, seed, protocol);
            progress();
            result
        })
        .collect()
}

/// One trial (module docs).
pub fn run_trial(
    truth: &Robot,
    pool: &[PoolPose],
    poses: usize,
    trial: usize,
    seed: u64,
    protocol: &Protocol,
) -> LocalizeTrial {
    let (chosen, data, guess, options) = trial_inputs(truth, pool, poses, trial, seed, protocol);
    let held_out: Vec<usize> = (0..pool.len()).filter(|k| !chosen.contains(k)).collect();
    let mut out = LocalizeTrial {
        trial,
        calibrated: false,
        anchor_error_m: None,
        held_out: held_out.len(),
        errors_m: Vec::new(),
        predicted_sigma_m: Vec::new(),
        flagged: 0,
        truth_errors_m: Vec::new(),
    };
    let noise = options.noise;
    let Ok(result) = calibrate(&guess, &data, &options) else {
        return out;
    };
    out.calibrated = true;
    out.anchor_error_m = Some(
        (0..CABLE_COUNT)
            .map(|i| (result.robot.anchors_m[i] - truth.anchors_m[i]).norm())
            .sum::<f64>()
            / CABLE_COUNT as f64,
    );
    let (Ok(calibrated), Ok(reference)) = (Localizer::new(&result.robot, &noise), Localizer::new(truth, &noise)) else {
        return out;
    };
    let stream = seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ ((poses as u64) << 32) ^ trial as u64;
    let mut rng = ChaCha8Rng::seed_from_u64(stream);
    for &k in &held_out {
        let p = &pool[k];
        let mut normal = |sigma: f64| -> f64 {
            let z: f64 = StandardNormal.sample(&mut rng);
            sigma * z
        };
        let readings = Readings {
            encoder_lengths_m: std::array::from_fn(|i| p.cable_lengths_m[i] + normal(noise.encoder_sigma_m)),
            load_cell_n: Some(p.reference_tension_n + normal(noise.load_cell_sigma_n)),
            localiser_pose: None,
        };
        match calibrated.localize(&readings, None) {
            Ok(found) if calibrated.flag(&found).is_none() => {
                out.errors_m.push((found.pose.position_m - p.pose.position_m).norm());
                out.predicted_sigma_m.push(found.position_sigma_m.norm());
            }
            _ => out.flagged += 1,
        }
        if let Ok(found) = reference.localize(&readings, None) {
            out.truth_errors_m
                .push((found.pose.position_m - p.pose.position_m).norm());
        }
    }
    out
}

/// Summarise trials ([`LocalizeSummary`]).
pub fn summarise(trials: &[LocalizeTrial]) -> Result<LocalizeSummary> {
    let rms = |v: &mut dyn Iterator<Item = f64>| {
        let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
        if n == 0 {
            f64::NAN
        } else {
            (s / n as f64).sqrt()
        }
    };
    let all = || trials.iter().flat_map(|t| t.errors_m.iter().copied());
    let mut per_trial: Vec<f64> = trials
        .iter()
        .filter(|t| !t.errors_m.is_empty())
        .map(|t| rms(&mut t.errors_m.iter().copied()))
        .collect();
    per_trial.sort_by(f64::total_cmp);
    let rows: usize = trials.iter().map(|t| t.errors_m.len()).sum();
    let held_out: usize = trials.iter().filter(|t| t.calibrated).map(|t| t.held_out).sum();
    // 95 % quantile of chi-square with 3 dof is 7.815: radius sqrt(7.815) = 2.80
    // sigma per axis, i.e. 2.80 / sqrt(3) times the norm of the axes' sigmas.
    let radius_per_norm = (7.814_727_903_251_178_f64 / 3.0).sqrt();
    let within = trials
        .iter()
        .flat_map(|t| t.errors_m.iter().zip(&t.predicted_sigma_m))
        .filter(|(e, s)| **e <= radius_per_norm * **s)
        .count();
    let anchors: Vec<f64> = trials.iter().filter_map(|t| t.anchor_error_m).collect();
    Ok(LocalizeSummary {
        trials: trials.len(),
        calibrated: trials.iter().filter(|t| t.calibrated).count(),
        anchor_error_m: anchors.iter().sum::<f64>() / anchors.len().max(1) as f64,
        position_rms_error_m: rms(&mut all()),
        median_trial_rms_m: per_trial.get(per_trial.len() / 2).copied().unwrap_or(f64::NAN),
        position_max_error_m: all().fold(f64::NAN, f64::max),
        predicted_rms_sigma_m: rms(&mut trials.iter().flat_map(|t| t.predicted_sigma_m.iter().copied())),
        within_95_percent: within as f64 / rows.max(1) as f64,
        flagged_share: trials.iter().map(|t| t.flagged).sum::<usize>() as f64 / held_out.max(1) as f64,
        truth_rms_error_m: rms(&mut trials.iter().flat_map(|t| t.truth_errors_m.iter().copied())),
    })
}
