//! The paper's Table II protocol (Sec. V-B), and its Cramer-Rao bound.
//!
//! For each pose count and trial: pick that many poses of the log at random,
//! add the sensor noise to the encoders (lengths + true offsets, zero here),
//! the load cell and the localiser's pose, perturb the initial guess (every
//! anchor by `anchor_perturbation_m` in a random direction, every offset by
//! `+-offset_perturbation_m`), calibrate, and compare with the truth (the
//! robot file's anchors, zero offsets).
//!
//! The poses come either from the log itself (`Source::Log`: RecurDyn's
//! finite-element lengths and tensions, model mismatch included) or from the
//! model at the log's positions (`Source::Model`: the closed-form equilibrium
//! at each logged position and reference tension; no mismatch, so the
//! Cramer-Rao bound describes the best achievable error).
//!
//! Every trial has its own random stream, seeded from `(seed, pose count,
//! trial)`, so results do not depend on the number of threads.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::{CableModel, OrientationPrior};
//! use sagcal::experiments::table2::{pose_pool, run_trial, trial_inputs, Protocol, Source};
//! use sagcal::model::effect_kind::EffectSet;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 12, &mut rng)?;
//! // A noise-free log of the truth: the model source re-solves each row's equilibrium.
//! let log = measure(&truth, &equilibria, &NoisePreset::None.sigmas(truth.platform_weight_n), &mut rng);
//! let pool = pose_pool(&truth, &log, Source::Model)?;
//! for (p, eq) in pool.iter().zip(&equilibria) {
//!     assert!((0..4).all(|i| (p.cable_lengths_m[i] - eq.cable_lengths_m[i]).abs() < 1e-6));
//! }
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
//! // Trial 0 with 8 poses: its subset, noise and guess follow from (seed, poses, trial) alone.
//! let (chosen, data, guess, _) = trial_inputs(&truth, &pool, 8, 0, 5, &protocol);
//! assert_eq!((chosen.len(), data.len()), (8, 8));
//! assert!((0..4).all(|i| ((guess.anchors_m[i] - truth.anchors_m[i]).norm() - 1.0).abs() < 1e-12));
//! assert!(guess.length_offsets_m.iter().all(|o| o.abs() == 10.0)); // the truth's are 0
//! let trial = run_trial(&truth, &pool, 8, 0, 5, &protocol);
//! assert!(trial.converged, "{:?}", trial.failure);
//! assert_eq!(trial.lines, chosen.iter().map(|&k| pool[k].line).collect::<Vec<_>>());
//! // The error is of the size the Cramer-Rao bound expects.
//! let (error_m, bound_m) = (trial.error.unwrap().anchor_mean_euclidean_m, trial.anchor_crlb_m.unwrap());
//! assert!(error_m < 3.0 * bound_m, "{error_m} m against a bound of {bound_m} m");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;

use crate::calib::gross_errors::{calibrate_checked, test_fit, GrossErrorOptions, Verdict};
use crate::calib::{
    calibrate, cramer_rao_bound, refine_with_effects, CalibrationError, CalibrationOptions, CalibrationResult,
    ParameterUncertainty,
};
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::Equilibrium;

pub use super::selection::Selection;
use super::selection::{failed_selection, selection_inputs};
pub use super::trial::{pose_pool, trial_inputs, PoolPose, Protocol, Source, TrialResult};

/// The summary for one pose count.
#[derive(Debug, Clone, Serialize)]
pub struct PoseCountResult {
    /// Poses per trial.
    pub poses: usize,
    /// Trials run.
    pub trials: usize,
    /// Trials that reached the right basin.
    pub converged: usize,
    /// Mean over converged trials of the mean Euclidean anchor error, metres.
    pub anchor_mae_m: f64,
    /// Standard error of that mean over the trials, metres.
    pub anchor_mae_standard_error_m: f64,
    /// Mean over converged trials of the per-coordinate anchor MAE, metres.
    pub anchor_coord_mae_m: f64,
    /// Mean over converged trials of the offset MAE, metres.
    pub offset_mae_m: f64,
    /// Mean over trials of the bound's expected mean Euclidean anchor error, metres.
    pub anchor_crlb_m: f64,
    /// Mean over trials of the bound's expected offset MAE, metres.
    pub offset_crlb_m: f64,
    /// Median calibration time, milliseconds.
    pub median_solve_ms: f64,
    /// Trials whose calibration kept the orientation prior (always all with `on`, none with `off`).
    pub orientation_prior_kept: usize,
    /// Readings flagged by the gross-error tests (left out with
    /// [`Protocol::apply_gross_errors`]), over all trials.
    pub readings_left_out: usize,
    /// Trials whose fit failed its consistency tests (`calibrate` would refuse it).
    pub inconsistent: usize,
    /// The trials that did not converge, with the reason.
    pub not_converged: Vec<TrialResult>,
}

/// Expected `E|e|` of a zero-mean Gaussian with covariance `c` (3x3), by a
/// fixed-seed Monte Carlo of 4000 draws (exact enough for a report).
fn expected_norm(c: &[[f64; 3]; 3]) -> Option<f64> {
    let m = Matrix3::from_fn(|r, col| c[r][col]);
    let l = m.cholesky()?.l();
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let draws = 4000;
    let mut sum = 0.0;
    for _ in 0..draws {
        let z = Vector3::from_fn(|_, _| StandardNormal.sample(&mut rng));
        sum += (l * z).norm();
    }
    Some(sum / draws as f64)
}

fn bound_summary(bound: &ParameterUncertainty) -> (Option<f64>, Option<f64>) {
    match bound {
        ParameterUncertainty::Full {
            anchor_covariance_m2,
            offset_sigma_m,
            ..
        } => {
            let anchors: Option<Vec<f64>> = anchor_covariance_m2.iter().map(expected_norm).collect();
            let anchor = anchors.map(|a| a.iter().sum::<f64>() / a.len() as f64);
            // E|x| = sqrt(2/pi) sigma for a Gaussian.
            let offset = offset_sigma_m
                .iter()
                .map(|s| s * (2.0 / std::f64::consts::PI).sqrt())
                .sum::<f64>()
                / offset_sigma_m.len() as f64;
            (anchor, Some(offset))
        }
        ParameterUncertainty::RankDeficient { .. } => (None, None),
    }
}

/// Run one trial.
pub fn run_trial(
    truth: &Robot,
    pool: &[PoolPose],
    poses: usize,
    trial: usize,
    seed: u64,
    protocol: &Protocol,
) -> TrialResult {
    run_selected_trial(truth, pool, poses, trial, seed, protocol, &Selection::Random)
}

/// Run one trial with the poses chosen by `selection` ([`Selection::Random`]: [`run_trial`]).
pub fn run_selected_trial(
    truth: &Robot,
    pool: &[PoolPose],
    poses: usize,
    trial: usize,
    seed: u64,
    protocol: &Protocol,
    selection: &Selection,
) -> TrialResult {
    let (chosen, data, guess, options) = match selection_inputs(truth, pool, poses, trial, seed, protocol, selection) {
        Ok(inputs) => inputs,
        Err(e) => return failed_selection(poses, trial, e),
    };
    let equilibria: Vec<Equilibrium> = chosen.iter().map(|&k| pool[k].equilibrium.clone()).collect();
    let lines = chosen.iter().map(|&k| pool[k].line).collect();
    let started = std::time::Instant::now();
    let (result, data, gross) = calibrate_tested(&guess, data, &options, protocol.apply_gross_errors);
    let result = result.and_then(|baseline| {
        if protocol.estimate.is_empty() {
            return Ok(baseline);
        }
        let extended = CalibrationOptions {
            free_effects: protocol.estimate,
            ..options.as_used_by(&baseline)
        };
        refine_with_effects(&baseline, &data, &extended)
    });
    let solve_ms = started.elapsed().as_secs_f64() * 1e3;
    // The bound of the estimator actually used: with the orientation prior if
    // the calibration kept it, and the estimated effects free.
    let orientation_prior_used = result
        .as_ref()
        .ok()
        .and_then(|r| r.orientation_check.map(|c| c.prior_used));
    let bound_options = CalibrationOptions {
        free_effects: protocol.estimate,
        ..match &result {
            Ok(r) => options.as_used_by(r),
            Err(_) => options,
        }
    };
    let (anchor_crlb_m, offset_crlb_m) =
        cramer_rao_bound(truth, &equilibria, &bound_options).map_or((None, None), |b| bound_summary(&b));
    match result {
        Ok(result) => {
            let error = CalibrationError::between(&result.robot, truth);
            let in_basin = in_right_basin(truth, &data, &options, &result, &error, protocol);
            let converged = result.converged() && in_basin;
            let failure = (!converged).then(|| {
                if !result.converged() {
                    format!("solver: {}", result.final_stage().termination)
                } else {
                    format!(
                        "wrong basin: an anchor is {:.2} m from the truth and the solve started at the truth ends elsewhere, at a lower cost",
                        error.anchor_max_euclidean_m
                    )
                }
            });
            TrialResult {
                trial,
                lines,
                converged,
                error: Some(error),
                failure,
                solve_ms,
                anchor_crlb_m,
                offset_crlb_m,
                orientation_prior_used,
                gross_errors: gross,
            }
        }
        Err(e) => TrialResult {
            trial,
            lines,
            converged: false,
            error: None,
            failure: Some(e.to_string()),
            solve_ms,
            anchor_crlb_m,
            offset_crlb_m,
            orientation_prior_used,
            gross_errors: gross,
        },
    }
}

/// A trial's calibration with `calibrate`'s gross-error tests: with `apply`,
/// the readings they flag are left out ([`calibrate_checked`]); without, the
/// fit on every reading is tested only. Returns the fit, the data it used,
/// and (readings flagged or left out, whether the fit is consistent).
fn calibrate_tested(
    guess: &Robot,
    data: Vec<PoseMeasurement>,
    options: &CalibrationOptions,
    apply: bool,
) -> (Result<CalibrationResult>, Vec<PoseMeasurement>, Option<(usize, bool)>) {
    let check = GrossErrorOptions::default();
    if apply {
        return match calibrate_checked(guess, &data, options, &check) {
            Ok(c) => {
                let gross = Some((c.excluded.len(), c.verdict == Verdict::Consistent));
                (Ok(c.result), c.measurements, gross)
            }
            Err(e) => (Err(e), data, None),
        };
    }
    let result = calibrate(guess, &data, options);
    let gross = result
        .as_ref()
        .ok()
        .and_then(|r| test_fit(r, &data, options, &check).ok())
        .map(|t| (t.flagged.len(), t.consistent()));
    (result, data, gross)
}

/// Right basin: the solver stopped at a minimum, and it is the data's own
/// minimum: within the radius of the truth, or, if farther (few poses make
/// the bound itself large), the minimum a solve started at the truth finds
/// (anchors within 1 cm) or a lower one. With few poses the cost can have
/// several minima of nearly equal depth along a poorly observed direction;
/// one at least as deep as the truth's is the data's answer, not a failure
/// of the initialisation. Costs compare only under the same orientation prior.
fn in_right_basin(
    truth: &Robot,
    data: &[PoseMeasurement],
    options: &CalibrationOptions,
    result: &CalibrationResult,
    error: &CalibrationError,
    protocol: &Protocol,
) -> bool {
    error.anchor_max_euclidean_m < protocol.basin_radius_m || {
        calibrate(truth, data, options).is_ok_and(|reference| {
            let same_minimum =
                (0..CABLE_COUNT).all(|i| (reference.robot.anchors_m[i] - result.robot.anchors_m[i]).norm() < 0.01);
            let same_prior =
                reference.orientation_check.map(|c| c.prior_used) == result.orientation_check.map(|c| c.prior_used);
            let reference_cost = reference.final_stage().final_cost;
            let deeper = same_prior
                && result.excluded_poses.len() <= reference.excluded_poses.len()
                && result.final_stage().final_cost <= reference_cost * (1.0 + 1e-9);
            same_minimum || deeper
        })
    }
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// Summarise the trials of one pose count.
pub fn summarise(poses: usize, trials: Vec<TrialResult>) -> PoseCountResult {
    let ok: Vec<&CalibrationError> = trials
        .iter()
        .filter(|t| t.converged)
        .filter_map(|t| t.error.as_ref())
        .collect();
    let mut times: Vec<f64> = trials.iter().map(|t| t.solve_ms).collect();
    times.sort_by(f64::total_cmp);
    PoseCountResult {
        poses,
        trials: trials.len(),
        converged: ok.len(),
        anchor_mae_m: mean(ok.iter().map(|e| e.anchor_mean_euclidean_m)),
        anchor_mae_standard_error_m: {
            let m = mean(ok.iter().map(|e| e.anchor_mean_euclidean_m));
            let var = mean(ok.iter().map(|e| (e.anchor_mean_euclidean_m - m).powi(2)));
            (var / (ok.len().max(2) - 1) as f64).sqrt()
        },
        anchor_coord_mae_m: mean(ok.iter().map(|e| e.anchor_coordinate_mae_m)),
        offset_mae_m: mean(ok.iter().map(|e| e.offset_mae_m)),
        anchor_crlb_m: mean(trials.iter().filter_map(|t| t.anchor_crlb_m)),
        offset_crlb_m: mean(trials.iter().filter_map(|t| t.offset_crlb_m)),
        median_solve_ms: times.get(times.len() / 2).copied().unwrap_or(f64::NAN),
        orientation_prior_kept: trials.iter().filter(|t| t.orientation_prior_used == Some(true)).count(),
        readings_left_out: trials.iter().filter_map(|t| t.gross_errors).map(|g| g.0).sum(),
        inconsistent: trials.iter().filter(|t| t.gross_errors.is_some_and(|g| !g.1)).count(),
        not_converged: trials.into_iter().filter(|t| !t.converged).collect(),
    }
}

/// Check a protocol's counts before any trial runs: at least one pose
/// count, each of [`crate::calib::MIN_POSES`] poses or more and at most the
/// `pool` usable poses, and at least one trial (messages name the flags of
/// `sagcal experiment table2`).
pub fn check_counts(pose_counts: &[usize], trials: usize, pool: usize) -> Result<()> {
    if pose_counts.is_empty() {
        return Err(Error::InvalidInput("--poses: no pose count given".into()));
    }
    for &n in pose_counts {
        if n < crate::calib::MIN_POSES {
            return Err(Error::InvalidInput(format!(
                "--poses {n}: at least {} poses per trial are needed to calibrate",
                crate::calib::MIN_POSES
            )));
        }
        if n > pool {
            return Err(Error::InvalidInput(format!(
                "--poses {n}: more poses than the data's {pool} usable poses"
            )));
        }
    }
    if trials == 0 {
        return Err(Error::InvalidInput("--trials must be at least 1".into()));
    }
    Ok(())
}

/// Run `trials` trials for every pose count in parallel; `progress` is called once per finished trial.
pub fn run_protocol(
    truth: &Robot,
    pool: &[PoolPose],
    pose_counts: &[usize],
    trials: usize,
    seed: u64,
    protocol: &Protocol,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<PoseCountResult>> {
    run_selected_protocol(
        truth,
        pool,
        pose_counts,
        trials,
        seed,
        protocol,
        &Selection::Random,
        progress,
    )
}

/// [`run_protocol`] with the poses of every trial chosen by `selection`.
#[allow(clippy::too_many_arguments)]
pub fn run_selected_protocol(
    truth: &Robot,
    pool: &[PoolPose],
    pose_counts: &[usize],
    trials: usize,
    seed: u64,
    protocol: &Protocol,
    selection: &Selection,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<PoseCountResult>> {
    check_counts(pose_counts, trials, pool.len())?;
    let jobs: Vec<(usize, usize)> = pose_counts
        .iter()
        .flat_map(|&n| (0..trials).map(move |t| (n, t)))
        .collect();
    let results: Vec<(usize, TrialResult)> = jobs
        .par_iter()
        .map(|&(n, t)| {
            let r = run_selected_trial(truth, pool, n, t, seed, protocol, selection);
            progress();
            (n, r)
        })
        .collect();
    Ok(pose_counts
        .iter()
        .map(|&n| {
            let mut of_n: Vec<TrialResult> = results
                .iter()
                .filter(|(m, _)| *m == n)
                .map(|(_, r)| r.clone())
                .collect();
            of_n.sort_by_key(|r| r.trial);
            summarise(n, of_n)
        })
        .collect())
}
