//! How a Table II trial chooses its poses from the pool: at random (the
//! paper's protocol), planned by [`crate::plan`] (A- or D-optimal on the
//! Cramer-Rao bound), or sequentially (plan a first batch, calibrate, re-plan
//! the rest at the estimate).
//!
//! The planner knows only a nominal robot: the truth with every anchor moved
//! by [`PlanSettings::anchor_error_m`] in a random direction (drawn from the
//! trial's own stream, so the same for every selection), which is how the
//! plan's benefit is tested when the robot is not where its drawing says.
//! The trial's noise and initial guess come from the same stream as a random
//! trial's (the random subset is still drawn, then replaced), so planned and
//! random trials of one index share the guess.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::{CableModel, OrientationPrior};
//! use sagcal::experiments::selection::{PlanSettings, Selection};
//! use sagcal::experiments::table2::{pose_pool, run_selected_trial, Protocol, Source};
//! use sagcal::model::effect_kind::EffectSet;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::plan::Criterion;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 16, &mut rng)?;
//! let log = measure(&truth, &equilibria, &NoisePreset::None.sigmas(truth.platform_weight_n), &mut rng);
//! let pool = pose_pool(&truth, &log, Source::Model)?;
//! let protocol = Protocol {
//!     noise: NoisePreset::Paper,
//!     model: CableModel::Catenary,
//!     anchor_perturbation_m: 1.0,
//!     offset_perturbation_m: 10.0,
//!     basin_radius_m: 3.0,
//!     orientation_prior: OrientationPrior::On,
//!     estimate: EffectSet::NONE,
//!     apply_gross_errors: false,
//! };
//! let planned = Selection::Planned(PlanSettings {
//!     criterion: Criterion::A,
//!     orientation_prior: OrientationPrior::On,
//!     anchor_error_m: 0.5,
//! });
//! let random = run_selected_trial(&truth, &pool, 6, 0, 3, &protocol, &Selection::Random);
//! let chosen = run_selected_trial(&truth, &pool, 6, 0, 3, &protocol, &planned);
//! assert!(random.converged && chosen.converged, "{:?} {:?}", random.failure, chosen.failure);
//! // Six poses planned (A-optimal at a robot 0.5 m off) promise a smaller anchor error than six at random.
//! let (bound_random, bound_planned) = (random.anchor_crlb_m.unwrap(), chosen.anchor_crlb_m.unwrap());
//! assert!(bound_planned < bound_random, "{bound_planned} m planned, {bound_random} m random");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::trial::{
    noisy_measurements, perturbed_guess, trial_inputs, trial_options, trial_stream, PoolPose, Protocol, TrialResult,
};
use crate::calib::{calibrate, CalibrationOptions, OrientationPrior};
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{self, Equilibrium, StaticsOptions};
use crate::plan::{candidate_information, choose_more_poses, Criterion, DesignOptions};

/// What the planner assumes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// The design criterion.
    pub criterion: Criterion,
    /// The orientation prior of the bound the plan minimises (`On` where the
    /// calibration keeps the localiser's orientation, e.g. model data).
    pub orientation_prior: OrientationPrior,
    /// How far each anchor of the planner's nominal robot is from the truth, metres.
    pub anchor_error_m: f64,
}

/// How a trial's poses are chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Selection {
    /// A random subset (the paper's protocol).
    Random,
    /// The plan over the pool at the nominal robot.
    Planned(PlanSettings),
    /// Plan the first half (at least 4 poses) at the nominal robot, calibrate
    /// on it, plan the rest at that estimate, calibrate on all starting from it.
    Sequential(PlanSettings),
}

/// A trial whose poses could not be chosen.
pub(crate) fn failed_selection(poses: usize, trial: usize, error: Error) -> TrialResult {
    TrialResult {
        trial,
        lines: Vec::with_capacity(poses),
        converged: false,
        error: None,
        failure: Some(format!("pose selection: {error}")),
        solve_ms: 0.0,
        anchor_crlb_m: None,
        offset_crlb_m: None,
        orientation_prior_used: None,
        gross_errors: None,
    }
}

/// The planner's nominal robot: the truth with every anchor moved by
/// `anchor_error_m` in a random direction (stream `(seed, poses, trial)`).
fn nominal_robot(truth: &Robot, settings: &PlanSettings, seed: u64, poses: usize, trial: usize) -> Robot {
    let mut nominal = truth.clone();
    if settings.anchor_error_m == 0.0 {
        return nominal;
    }
    let stream = (seed ^ 0x706c_616e).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ ((poses as u64) << 32) ^ trial as u64;
    let mut rng = ChaCha8Rng::seed_from_u64(stream);
    for i in 0..CABLE_COUNT {
        let direction = loop {
            let v = Vector3::from_fn(|_, _| StandardNormal.sample(&mut rng));
            if v.norm() > 1e-3 {
                break v.normalize();
            }
        };
        nominal.anchors_m[i] += settings.anchor_error_m * direction;
    }
    nominal
}

/// `count` more pool indices planned at `nominal`, with `fixed` already measured.
fn plan_indices(
    nominal: &Robot,
    truth: &Robot,
    pool: &[PoolPose],
    fixed: &[usize],
    count: usize,
    settings: &PlanSettings,
    options: &CalibrationOptions,
) -> Result<Vec<usize>> {
    // The pool's poses as the nominal robot would hang there (the truth's own
    // equilibria when the nominal is the truth).
    let same = nominal.anchors_m == truth.anchors_m;
    let statics_options = StaticsOptions::default();
    let mut usable: Vec<usize> = Vec::with_capacity(pool.len());
    let mut equilibria: Vec<Equilibrium> = Vec::with_capacity(pool.len());
    for (k, p) in pool.iter().enumerate() {
        let eq = if same {
            Some(p.equilibrium.clone())
        } else {
            statics::solve_with_reference_tension(
                nominal,
                p.pose.position_m,
                p.reference_tension_n,
                Some(p.pose.rotation),
                &statics_options,
            )
            .ok()
        };
        if let Some(eq) = eq {
            usable.push(k);
            equilibria.push(eq);
        }
    }
    let bound_options = CalibrationOptions {
        orientation_prior: settings.orientation_prior,
        ..*options
    };
    let information = candidate_information(nominal, &equilibria, &bound_options)?;
    let fixed_local: Vec<usize> = fixed
        .iter()
        .filter_map(|k| usable.iter().position(|u| u == k))
        .collect();
    let design = choose_more_poses(
        &information,
        &fixed_local,
        &DesignOptions {
            criterion: settings.criterion,
            ..DesignOptions::new(count)
        },
    )?;
    Ok(design.chosen.iter().map(|&c| usable[c]).collect())
}

type TrialInputs = (Vec<usize>, Vec<PoseMeasurement>, Robot, CalibrationOptions);

/// The inputs of one trial under `selection` (module docs).
pub(crate) fn selection_inputs(
    truth: &Robot,
    pool: &[PoolPose],
    poses: usize,
    trial: usize,
    seed: u64,
    protocol: &Protocol,
    selection: &Selection,
) -> Result<TrialInputs> {
    let settings = match selection {
        Selection::Random => return Ok(trial_inputs(truth, pool, poses, trial, seed, protocol)),
        Selection::Planned(s) | Selection::Sequential(s) => s,
    };
    let (mut rng, _random_subset) = trial_stream(pool, poses, trial, seed);
    let options = trial_options(truth, protocol);
    let noise = protocol.noise.sigmas(truth.platform_weight_n);
    let nominal = nominal_robot(truth, settings, seed, poses, trial);
    if let Selection::Planned(_) = selection {
        let chosen = plan_indices(&nominal, truth, pool, &[], poses, settings, &options)?;
        let data = noisy_measurements(pool, &chosen, &noise, &mut rng);
        let guess = perturbed_guess(truth, protocol, &mut rng);
        return Ok((chosen, data, guess, options));
    }
    let first = poses.div_ceil(2).max(crate::calib::MIN_POSES).min(poses);
    let mut chosen = plan_indices(&nominal, truth, pool, &[], first, settings, &options)?;
    let mut data = noisy_measurements(pool, &chosen, &noise, &mut rng);
    let guess = perturbed_guess(truth, protocol, &mut rng);
    if first == poses {
        return Ok((chosen, data, guess, options));
    }
    // Re-plan at the first batch's estimate (at the nominal if it failed).
    let estimate = calibrate(&guess, &data, &options).map_or(nominal, |r| r.robot);
    let rest = plan_indices(&estimate, truth, pool, &chosen, poses - first, settings, &options)?;
    data.extend(noisy_measurements(pool, &rest, &noise, &mut rng));
    chosen.extend(rest);
    Ok((chosen, data, estimate, options))
}
