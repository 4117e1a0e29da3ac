//! The paper's Table II protocol (Sec. V-B) on a robot of any number of
//! cables ([`suspended_trials`]): per trial, poses drawn in the robot's
//! workspace, the sensors' noise added, every anchor of the guess moved
//! `guess_m` in a random direction and its offsets set to zero, a
//! calibration, and its error against the truth beside the Cramer-Rao bound
//! of the same poses.
//!
//! The bound is the inverse Fisher information of the anchors and offsets
//! (`(J^T Sigma^-1 J)^-1` with every pose's variables marginalised out) of
//! the calibration graph at the true anchors, offsets, poses and forces
//! ([`anchor_and_offset_uncertainty`]). An efficient estimator's mean
//! squared anchor error is its trace, so the table compares root mean
//! squares: `sqrt(mean |a_hat - a|^2)` over anchors and converged trials
//! against `sqrt(mean trace Sigma_a)`.
//!
//! Every trial has its own random stream, seeded from `seed + trial`.
//!
//! A robot with elastic cables (a finite `axial_stiffness_n`) is simulated
//! by the discretised simulator at [`SEGMENTS`] segments per cable: its
//! drums pay out the closed-form lengths and it settles where it stretches
//! to (the bound is taken at the closed-form poses and forces, which differ
//! from those by the cables' stretch).
//!
//! ```
//! use sagcal::experiments::suspended_trials::{suspended_trials, SuspendedTrialsOptions};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let three = SuspendedRobot::builtin("three")?;
//! let options = SuspendedTrialsOptions { poses: 12, trials: 3, noise: NoisePreset::Paper, guess_m: 10.0, seed: 4 };
//! let summary = suspended_trials(&three, &options, &mut |_, _| {})?;
//! assert_eq!(summary.converged, 3, "{:?}", summary.failures);
//! // Errors of the size the bound allows (three trials: a loose check).
//! assert!(summary.anchor_rms_error_m < 3.0 * summary.anchor_rms_bound_m, "{summary:?}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::calib::suspended::{
    build_suspended_graph, calibrate_suspended, Exclusions, PoseStart, SuspendedCalibrationReport, SuspendedStage,
};
use crate::calib::{anchor_and_offset_uncertainty, CalibrationOptions, OrientationPrior, ParameterUncertainty};
use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::sensors::NoisePreset;
use crate::model::suspended::{SuspendedEquilibrium, SuspendedRobot};
use crate::sim::closed_form::{Closure, Workspace};
use crate::sim::suspended::sample_suspended;
use crate::sim::suspended_effects::simulate_readings;

/// Segments per cable of the discretised simulator of an elastic robot.
pub const SEGMENTS: usize = 100;

/// How the trials are run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SuspendedTrialsOptions {
    /// Poses per trial.
    pub poses: usize,
    /// Trials.
    pub trials: usize,
    /// The sensors' noise (also the factors' sigmas).
    pub noise: NoisePreset,
    /// How far every anchor of the guess is from the truth, metres.
    pub guess_m: f64,
    /// The seed of trial 0's stream.
    pub seed: u64,
}

/// The trials' summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedTrialsSummary {
    /// The robot.
    pub robot: String,
    /// Its cables.
    pub cables: usize,
    /// Its load cells, 1-based.
    pub load_cells: Vec<usize>,
    /// The options.
    pub options: SuspendedTrialsOptions,
    /// Trials whose calibration converged and passed its chi-square test.
    pub converged: usize,
    /// RMS Euclidean anchor error over the converged trials, metres.
    pub anchor_rms_error_m: f64,
    /// The Cramer-Rao bound's RMS Euclidean anchor error, metres.
    pub anchor_rms_bound_m: f64,
    /// RMS offset error over the converged trials, metres.
    pub offset_rms_error_m: f64,
    /// The bound's RMS offset error, metres.
    pub offset_rms_bound_m: f64,
    /// Trials whose Fisher information was singular (no bound).
    pub unbounded: usize,
    /// The trials that did not converge, each with the reason.
    pub failures: Vec<String>,
}

/// Run the trials on `truth` (its anchors and offsets the truth); `progress(done, total)` after each.
pub fn suspended_trials(
    truth: &SuspendedRobot,
    options: &SuspendedTrialsOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<SuspendedTrialsSummary> {
    if options.trials == 0 || options.poses == 0 {
        return Err(Error::InvalidInput("at least one trial of at least one pose".into()));
    }
    let noise = options.noise.sigmas(truth.platform_weight_n);
    let mut calibration = CalibrationOptions::new(noise);
    calibration.orientation_prior = OrientationPrior::On;
    let mut sums = Sums::default();
    let mut failures = Vec::new();
    for trial in 0..options.trials {
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed.wrapping_add(trial as u64));
        let equilibria = trial_poses(truth, options.poses, &mut rng)?;
        let data = simulate_readings(truth, &Effects::default(), &equilibria, &noise, SEGMENTS, &mut rng)?;
        let guess = moved_guess(truth, options.guess_m, &mut rng);
        // The bound at the truth: the graph's information at the true values.
        let starts: Vec<PoseStart> = equilibria
            .iter()
            .map(|eq| PoseStart {
                pose: eq.pose,
                forces: eq.tensions.clone(),
            })
            .collect();
        let at_truth = build_suspended_graph(
            truth,
            &data,
            &starts,
            SuspendedStage::Catenary,
            &calibration,
            true,
            &Exclusions::new(),
        );
        match anchor_and_offset_uncertainty(&at_truth.graph, &at_truth.anchors, &at_truth.length_offsets)? {
            ParameterUncertainty::Full {
                anchor_covariance_m2,
                offset_sigma_m,
                ..
            } => {
                sums.bounds += 1;
                sums.anchor_bound += anchor_covariance_m2
                    .iter()
                    .map(|c| c[0][0] + c[1][1] + c[2][2])
                    .sum::<f64>();
                sums.offset_bound += offset_sigma_m.iter().map(|s| s * s).sum::<f64>();
            }
            ParameterUncertainty::RankDeficient { .. } => sums.unbounded += 1,
        }
        // The protocol's fits use every reading, as the paper's do.
        match calibrate_suspended(&guess, &data, &calibration, None, &mut |_| {}) {
            Ok(result) => match SuspendedCalibrationReport::new(&guess, &result).inconsistency() {
                None => {
                    sums.converged += 1;
                    for i in 0..truth.cable_count() {
                        sums.anchor_error += (result.robot.anchors_m[i] - truth.anchors_m[i]).norm_squared();
                        sums.offset_error += (result.robot.length_offsets_m[i] - truth.length_offsets_m[i]).powi(2);
                    }
                }
                Some(reason) => failures.push(format!("trial {trial}: {reason}")),
            },
            Err(e) => failures.push(format!("trial {trial}: {e}")),
        }
        progress(trial + 1, options.trials);
    }
    let n = truth.cable_count() as f64;
    let rms = |sum: f64, count: usize| (sum / (n * count.max(1) as f64)).sqrt();
    Ok(SuspendedTrialsSummary {
        robot: truth.name.clone(),
        cables: truth.cable_count(),
        load_cells: truth.load_cells.iter().map(|c| c + 1).collect(),
        options: *options,
        converged: sums.converged,
        anchor_rms_error_m: rms(sums.anchor_error, sums.converged),
        anchor_rms_bound_m: rms(sums.anchor_bound, sums.bounds),
        offset_rms_error_m: rms(sums.offset_error, sums.converged),
        offset_rms_bound_m: rms(sums.offset_bound, sums.bounds),
        unbounded: sums.unbounded,
        failures,
    })
}

/// A trial's poses drawn in the robot's workspace (or around its anchors):
/// on three cables each the level equilibrium at its position, on more the
/// member with a yaw drawn within +-5 degrees held.
pub(crate) fn trial_poses(
    robot: &SuspendedRobot,
    poses: usize,
    rng: &mut impl Rng,
) -> Result<Vec<SuspendedEquilibrium>> {
    let workspace = robot
        .workspace
        .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
    let closure = if robot.cable_count() > 3 {
        Closure::Yaw { max_yaw_deg: 5.0 }
    } else {
        Closure::Level
    };
    sample_suspended(robot, &workspace, poses, closure, rng)
}

/// Running sums over the trials.
#[derive(Debug, Default)]
struct Sums {
    converged: usize,
    bounds: usize,
    unbounded: usize,
    anchor_error: f64,
    offset_error: f64,
    anchor_bound: f64,
    offset_bound: f64,
}

/// `truth` with every anchor moved `distance_m` in a direction drawn
/// uniformly on the sphere, and zero offsets.
fn moved_guess(truth: &SuspendedRobot, distance_m: f64, rng: &mut impl Rng) -> SuspendedRobot {
    let mut guess = truth.clone();
    for anchor in &mut guess.anchors_m {
        let direction = Vector3::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal)).normalize();
        *anchor += direction * distance_m;
    }
    guess.length_offsets_m = vec![0.0; truth.cable_count()];
    guess
}
