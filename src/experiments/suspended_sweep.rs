//! The hidden-effect sweep on robots of 3 to 8 cables: what the catenary
//! calibration makes of data in which an effect of the catalogue is hidden.
//!
//! Each case draws its poses (as Table II's trials do: the level closure on
//! three cables, a yaw within +-5 degrees held on more), one effect at a
//! magnitude drawn from its plausible range for the robot
//! ([`super::suspended_effect_draws`]), and the readings of the discretised
//! simulator with that effect acting ([`crate::sim::suspended_effects`]);
//! `none` cases have the chains alone. The calibration starts from the
//! robot file (the truth's anchors, zero offsets) with the tests for single
//! gross errors at `false_alarm`, and is scored by its own verdict:
//!
//! - **refused**: the chi-square test at 99.9 % (after any readings left
//!   out) finds the readings inconsistent with the model: the effect is
//!   found out, though not named (the sweep scores the calibration alone;
//!   `sagcal diagnose` names causes, [`crate::diagnose::suspended`]);
//! - **passed, biased**: the fit passes, yet an anchor coordinate lies
//!   further from the truth than the two-sided Bonferroni 99.9 % quantile
//!   of `3 N` standard normals times its 1-sigma: a wrong robot reported
//!   as consistent, the case the operator cannot see;
//! - **passed**: the fit passes and every anchor is within that bound.
//!
//! Under `none` a refusal is a false alarm (expected rate at most about
//! 0.1 %, plus the chains' `O(1/n^2)` departure from the catenary).
//!
//! ```
//! use sagcal::experiments::suspended_sweep::{suspended_effect_sweep, SuspendedSweepOptions, SweepVerdict};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("three")?;
//! let options = SuspendedSweepOptions {
//!     poses: 8, seeds: 1, seed: 4, segments: 10, noise: NoisePreset::Authors, false_alarm: 0.01,
//! };
//! let sweep = suspended_effect_sweep(&robot, &options, &|_, _| {})?;
//! assert_eq!(sweep.rows.len(), 10); // none and nine effects
//! // Every case is judged (or says why it could not be) and names its seed.
//! for case in &sweep.cases {
//!     assert_eq!(case.verdict == SweepVerdict::Failed, case.failure.is_some());
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use super::suspended_effect_draws::{
    draw_suspended_effect, suspended_effect_ranges, SuspendedEffectRange, SUSPENDED_EFFECTS,
};
use super::suspended_trials::trial_poses;
use crate::calib::gross_errors::GrossErrorOptions;
use crate::calib::suspended::{calibrate_suspended, SuspendedCalibrationReport};
use crate::calib::{CalibrationOptions, OrientationPrior};
use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::sensors::NoisePreset;
use crate::model::suspended::{SuspendedEquilibrium, SuspendedRobot};
use crate::sim::suspended_effects::measure_suspended_with_effects;
use crate::stats::chi_square_critical;

/// How the sweep is run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SuspendedSweepOptions {
    /// Poses per case.
    pub poses: usize,
    /// Cases per effect.
    pub seeds: usize,
    /// Case `k` of effect `e` uses the seed `seed + 1000 e + k`.
    pub seed: u64,
    /// Segments per cable of the discretised simulator.
    pub segments: usize,
    /// The sensors' noise (also the factors' sigmas).
    pub noise: NoisePreset,
    /// The tests for single gross errors' false-alarm rate over all readings.
    pub false_alarm: f64,
}

/// What the calibration made of one case, serialised as `refused`,
/// `passed, biased`, `passed` or `failed`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SweepVerdict {
    /// The fit failed its own tests.
    #[serde(rename = "refused")]
    Refused,
    /// The fit passed with an anchor beyond the Bonferroni bound of its 1-sigma.
    #[serde(rename = "passed, biased")]
    PassedBiased,
    /// The fit passed, every anchor within the bound.
    #[serde(rename = "passed")]
    Passed,
    /// No data or no fit: the reason in the case's `failure`.
    #[serde(rename = "failed")]
    Failed,
}

/// One case of the sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedSweepCase {
    /// The effect hidden (`none`: no effect).
    pub effect: String,
    /// Its spec as `sagcal simulate --effect` takes it (`None` for `none`).
    pub spec: Option<String>,
    /// The case's seed (`sagcal simulate --seed` draws other poses: the sweep's closure differs).
    pub seed: u64,
    /// The calibration's verdict on the case.
    pub verdict: SweepVerdict,
    /// The fit's chi-square and its degrees of freedom.
    pub chi_square: f64,
    /// Degrees of freedom.
    pub degrees_of_freedom: usize,
    /// Readings the tests for single gross errors left out.
    pub readings_left_out: usize,
    /// The largest anchor coordinate error over its 1-sigma.
    pub worst_anchor_sigmas: f64,
    /// The largest Euclidean anchor error, metres.
    pub worst_anchor_error_m: f64,
    /// Why a case failed.
    pub failure: Option<String>,
}

/// One effect's score.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedSweepRow {
    /// The effect.
    pub effect: String,
    /// Its range for the robot.
    pub range: String,
    /// Cases.
    pub cases: usize,
    /// Fits refused.
    pub refused: usize,
    /// Fits passed with an anchor outside the bound.
    pub passed_biased: usize,
    /// Fits passed with every anchor inside it.
    pub passed: usize,
    /// Cases without data or fit.
    pub failed: usize,
    /// Median of the cases' largest anchor error, metres (NaN without a fit).
    pub median_worst_anchor_error_m: f64,
}

/// The sweep's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedSweep {
    /// The robot.
    pub robot: String,
    /// Its cables.
    pub cables: usize,
    /// The options.
    pub options: SuspendedSweepOptions,
    /// The bias bound, in 1-sigma of an anchor coordinate.
    pub bias_bound_sigmas: f64,
    /// Per effect, its score.
    pub rows: Vec<SuspendedSweepRow>,
    /// Every case.
    pub cases: Vec<SuspendedSweepCase>,
}

/// Run the sweep on `robot` (module docs); `progress(done, total)` as cases finish.
pub fn suspended_effect_sweep(
    robot: &SuspendedRobot,
    options: &SuspendedSweepOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SuspendedSweep> {
    if options.seeds == 0 || options.poses == 0 {
        return Err(Error::InvalidInput(
            "at least one case per effect of at least one pose".into(),
        ));
    }
    let coordinates = 3 * robot.cable_count();
    let bias_bound_sigmas = chi_square_critical(1, 0.001 / coordinates as f64).sqrt();
    let jobs: Vec<(usize, usize)> = (0..SUSPENDED_EFFECTS.len())
        .flat_map(|e| (0..options.seeds).map(move |k| (e, k)))
        .collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let cases: Vec<SuspendedSweepCase> = jobs
        .par_iter()
        .map(|&(e, k)| {
            let seed = options.seed.wrapping_add(1000 * e as u64 + k as u64);
            let case = run_case(robot, options, SUSPENDED_EFFECTS[e], seed, bias_bound_sigmas);
            progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1, jobs.len());
            case
        })
        .collect();
    let rows = suspended_effect_ranges(robot)
        .into_iter()
        .map(|range| score(&range, &cases))
        .collect();
    Ok(SuspendedSweep {
        robot: robot.name.clone(),
        cables: robot.cable_count(),
        options: *options,
        bias_bound_sigmas,
        rows,
        cases,
    })
}

/// One case: draw, simulate, calibrate, judge.
fn run_case(
    robot: &SuspendedRobot,
    options: &SuspendedSweepOptions,
    effect: &str,
    seed: u64,
    bias_bound_sigmas: f64,
) -> SuspendedSweepCase {
    let mut case = SuspendedSweepCase {
        effect: effect.into(),
        spec: None,
        seed,
        verdict: SweepVerdict::Failed,
        chi_square: f64::NAN,
        degrees_of_freedom: 0,
        readings_left_out: 0,
        worst_anchor_sigmas: f64::NAN,
        worst_anchor_error_m: f64::NAN,
        failure: None,
    };
    if let Err(e) = fit_case(robot, options, &mut case, bias_bound_sigmas) {
        case.failure = Some(e.to_string());
    }
    case
}

/// The body of [`run_case`], filling `case` in.
fn fit_case(
    robot: &SuspendedRobot,
    options: &SuspendedSweepOptions,
    case: &mut SuspendedSweepCase,
    bias_bound_sigmas: f64,
) -> Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(case.seed);
    let equilibria = trial_poses(robot, options.poses, &mut rng)?;
    let spec = draw_suspended_effect(
        &case.effect,
        robot,
        mean_load_cell_tension_n(robot, &equilibria),
        &mut rng,
    );
    let mut effects = Effects::default();
    if let Some(spec) = &spec {
        effects.apply_spec(spec)?;
    }
    case.spec = spec;
    let noise = options.noise.sigmas(robot.platform_weight_n);
    let data = measure_suspended_with_effects(robot, &effects, &equilibria, &noise, options.segments, &mut rng)?;
    let mut calibration = CalibrationOptions::new(noise);
    calibration.orientation_prior = OrientationPrior::On;
    let tests = GrossErrorOptions {
        false_alarm: options.false_alarm,
        ..GrossErrorOptions::default()
    };
    let result = calibrate_suspended(robot, &data, &calibration, Some(&tests), &mut |_| {})?;
    let report = SuspendedCalibrationReport::new(robot, &result);
    case.chi_square = report.chi_square;
    case.degrees_of_freedom = report.degrees_of_freedom;
    case.readings_left_out = report.readings_left_out.len();
    case.worst_anchor_error_m = robot
        .anchors_m
        .iter()
        .zip(&result.robot.anchors_m)
        .map(|(t, e)| (t - e).norm())
        .fold(0.0, f64::max);
    case.worst_anchor_sigmas = match &report.anchor_sigma_m {
        Some(sigmas) => (0..robot.cable_count())
            .flat_map(|i| (0..3).map(move |k| (i, k)))
            .map(|(i, k)| (result.robot.anchors_m[i][k] - robot.anchors_m[i][k]).abs() / sigmas[i][k])
            .fold(0.0, f64::max),
        None => f64::INFINITY,
    };
    case.verdict = if report.inconsistency().is_some() {
        SweepVerdict::Refused
    } else if case.worst_anchor_sigmas > bias_bound_sigmas {
        SweepVerdict::PassedBiased
    } else {
        SweepVerdict::Passed
    };
    Ok(())
}

/// The mean tension of the load-cell cables over the poses, newtons.
fn mean_load_cell_tension_n(robot: &SuspendedRobot, equilibria: &[SuspendedEquilibrium]) -> f64 {
    let tensions: Vec<f64> = equilibria
        .iter()
        .flat_map(|eq| robot.load_cells.iter().map(|&c| eq.tensions[c].magnitude_n()))
        .collect();
    tensions.iter().sum::<f64>() / tensions.len().max(1) as f64
}

/// One effect's row from its cases.
fn score(range: &SuspendedEffectRange, cases: &[SuspendedSweepCase]) -> SuspendedSweepRow {
    let mine: Vec<&SuspendedSweepCase> = cases.iter().filter(|c| c.effect == range.effect).collect();
    let count = |verdict: SweepVerdict| mine.iter().filter(|c| c.verdict == verdict).count();
    let mut errors: Vec<f64> = mine
        .iter()
        .map(|c| c.worst_anchor_error_m)
        .filter(|e| e.is_finite())
        .collect();
    errors.sort_by(f64::total_cmp);
    let median = match errors.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => errors[n / 2],
        n => 0.5 * (errors[n / 2 - 1] + errors[n / 2]),
    };
    SuspendedSweepRow {
        effect: range.effect.clone(),
        range: range.range.clone(),
        cases: mine.len(),
        refused: count(SweepVerdict::Refused),
        passed_biased: count(SweepVerdict::PassedBiased),
        passed: count(SweepVerdict::Passed),
        failed: count(SweepVerdict::Failed),
        median_worst_anchor_error_m: median,
    }
}
