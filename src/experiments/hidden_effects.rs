//! The hidden-effect experiment: simulate a robot with one effect of the
//! catalogue (or none) through the discretised simulator, run
//! [`crate::diagnose::diagnose`] without telling it, and score the verdict.
//!
//! # Magnitudes
//!
//! Each case draws its effects' magnitudes from the physically plausible
//! ranges for the robot ([`effect_ranges`]: derived from the robot's own data
//! and justified there, e.g. the rope's stiffness from its weight per metre).
//!
//! The experiment reports, per effect, the smallest ratio of the baseline's
//! anchor error to its stated 1-sigma: above 1, every magnitude drawn changes
//! the calibrated anchors by more than their uncertainty.
//!
//! # Poses
//!
//! Each case's static poses close their family of equilibria by
//! [`HiddenEffectOptions::closure`]: by default about half are the most level
//! member, the others the member of a random yaw within
//! [`DEFAULT_MAX_YAW_DEG`](crate::sim::closed_form::DEFAULT_MAX_YAW_DEG), as a robot settles wherever its statics put it.
//!
//! # Scoring
//!
//! A case is right when the verdict names the hidden effect (`none` for none).
//! `pulley` is reported but left out of the detection score: a pulley radius
//! is almost entirely absorbed by the anchors ([`identifiability`]),
//! so it is supported as a known geometry input instead (the robot file's
//! `[effects] pulley_radius_m`), and each pulley case also reports the anchor
//! error of a calibration that is given the radius.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::experiments::hidden_effects::{
//!     case_seed, draw_effects, simulate_case, HiddenEffectOptions, TRUTH_ANCHOR_SPREAD_M, TRUTH_OFFSET_SPREAD_M,
//! };
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::Robot;
//! let nominal = Robot::builtin("large")?;
//! let hidden = [EffectKind::EncoderScale, EffectKind::LoadCell];
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let e = draw_effects(&nominal, &hidden, 150.0, &mut rng);
//! // Drum gains 1 +- 0.1..0.3 %; load cell bias 5-12 % of the 150 N mean tension, gain 1 +- 2..5 %.
//! assert!(e.encoder_gain.iter().all(|g| (0.001..0.003).contains(&(g - 1.0).abs())));
//! assert!((0.05..0.12).contains(&(e.load_cell_bias_n.abs() / 150.0)));
//! assert!((0.02..0.05).contains(&(e.load_cell_gain - 1.0).abs()));
//! assert!(e.axial_stiffness_n.is_none() && e.pulley_radius_m == 0.0); // nothing else hidden
//! // A case: a truth drawn off the nominal robot, its effects set, the data of its simulator.
//! let options = HiddenEffectOptions { poses: 4, segments: 10, ..HiddenEffectOptions::default() };
//! let seed = case_seed(7, 0, &hidden, 0);
//! assert_ne!(seed, case_seed(7, 0, &hidden, 1));
//! let (data, truth, guess) = simulate_case(&nominal, &hidden, seed, &options)?;
//! assert_eq!((data.len(), guess.anchors_m), (4, nominal.anchors_m));
//! for i in 0..4 {
//!     let moved = truth.anchors_m[i] - nominal.anchors_m[i];
//!     assert!(moved.amax() <= TRUTH_ANCHOR_SPREAD_M && truth.length_offsets_m[i].abs() <= TRUTH_OFFSET_SPREAD_M);
//!     assert!((0.001..0.003).contains(&(truth.effects.encoder_gain[i] - 1.0).abs()));
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{DMatrix, DVector, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use super::held_out::{held_out_prediction, HeldOutPrediction};
use crate::calib::{calibrate, validate_measurements, CalibrationError, CalibrationOptions};
use crate::diagnose::{diagnose, power_against, CandidateFit, DiagnoseOptions};
use crate::error::{Error, Result};
use crate::model::effect_kind::EffectKind;
pub use crate::model::effect_ranges::{effect_ranges, EffectRange, CABLE_DENSITY_KG_M3};
use crate::model::effects::Effects;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::NoisePreset;
use crate::model::statics::Equilibrium;
use crate::sim::closed_form::{sample_equilibria, sample_equilibria_with, Closure, Workspace};
use crate::sim::effects::measure_with_effects;
use crate::stats::{chi_square_critical, noncentral_chi_square_survival};

pub use super::hidden_draws::{draw_effects, mid_range_effects, smallest_effects};
pub use super::hidden_options::HiddenEffectOptions;
pub use super::identifiability::{identifiability, Identifiability};
use super::leave_one_out::{honest, left_out_with};
pub use super::leave_one_out::{Catalogue, LeftOut};

/// One case: what was hidden and what the diagnosis said.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HiddenCase {
    /// Robot name.
    pub robot: String,
    /// The case's seed.
    pub seed: u64,
    /// The sensor noise of the case.
    pub noise: NoisePreset,
    /// The hidden effects joined by `+` in sorted order, or `none`.
    pub hidden: String,
    /// The hidden effect's parameters (`sagcal simulate --effect` specifications).
    pub truth: String,
    /// The diagnosis' verdict.
    pub verdict: String,
    /// Whether the verdict names exactly the hidden effects ([`names_exactly`]: an ambiguous pair holding one counts).
    pub correct: bool,
    /// The diagnosis' final model (stand-ins included).
    pub final_model: String,
    /// Whether the final model explains the data.
    pub explained: bool,
    /// The final model's sensor tests that fail.
    pub failing_tests: Vec<String>,
    /// The stand-ins of the final model.
    pub stand_ins: Vec<String>,
    /// With [`Catalogue::LeaveOneOut`]: per hidden effect, the diagnosis
    /// without it in the catalogue.
    pub left_out: Vec<LeftOut>,
    /// The smallest power, over the hidden effects, of the diagnosis' first
    /// test at the effect's true magnitude, and for per-drum gains of telling
    /// them from one common gain (`None` for none or a singular information
    /// matrix): the case is detectable when it is >= 0.9.
    pub power: Option<f64>,
    /// Mean absolute anchor-coordinate error of the baseline, metres.
    pub anchor_mae_before_m: f64,
    /// The same for the verdict's model.
    pub anchor_mae_after_m: f64,
    /// The same for the hidden effect's extended model, whatever the verdict.
    pub anchor_mae_extended_m: Option<f64>,
    /// Baseline anchor error over its 1-sigma (mean over anchors of `|error| / sqrt(trace Sigma)`).
    pub baseline_error_over_sigma: f64,
    /// Pulley cases: anchor error of a calibration given the true radius.
    pub anchor_mae_known_geometry_m: Option<f64>,
    /// [`HELD_OUT_POSES`] unseen poses of the same truth localised with the
    /// baseline's robot and the final model's.
    pub held_out: HeldOutPrediction,
}

/// The mean reference-cable tension over `poses` sampled equilibria, newtons.
///
/// Errors: no pose to average over.
pub fn mean_reference_tension_n(robot: &Robot, poses: usize, seed: u64) -> Result<f64> {
    if poses == 0 {
        return Err(Error::InvalidInput(
            "poses (--poses): the mean reference tension needs at least 1 pose, got 0".into(),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let equilibria = sample_equilibria(robot, &Workspace::default_for(robot), poses, &mut rng)?;
    Ok(equilibria
        .iter()
        .map(|eq| eq.tensions[robot.reference_cable].magnitude_n())
        .sum::<f64>()
        / equilibria.len().max(1) as f64)
}

/// The anchors of the true robot are drawn this far off the nominal ones,
/// per coordinate, metres: the nominal robot file is only a guess.
pub const TRUTH_ANCHOR_SPREAD_M: f64 = 0.5;
/// The encoders' true length offsets are drawn from `+-` this, metres.
pub const TRUTH_OFFSET_SPREAD_M: f64 = 3.0;

/// A case before its sensors are read: the true robot (drawn off the
/// nominal one, its effects not yet set), the drawn effects, the true
/// equilibria and the random stream after them. The noise reading enters
/// only the sensors, so the cases of one seed under several noise readings
/// share it ([`run_sweep`]).
pub struct SimulatedTruth {
    truth: Robot,
    effects: Effects,
    equilibria: Vec<Equilibrium>,
    rng: ChaCha8Rng,
    nominal: Robot,
    closure: Closure,
    seed: u64,
}

/// Draw the truth of the case `seed` hiding `hidden` (the poses closed by
/// `options.closure`; `options.noise` is not used).
pub fn simulate_truth(
    nominal: &Robot,
    hidden: &[EffectKind],
    seed: u64,
    options: &HiddenEffectOptions,
) -> Result<SimulatedTruth> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut truth = nominal.clone();
    for i in 0..CABLE_COUNT {
        let spread = TRUTH_ANCHOR_SPREAD_M;
        truth.anchors_m[i] += Vector3::from_fn(|_, _| rng.random_range(-spread..spread));
        truth.length_offsets_m[i] = rng.random_range(-TRUTH_OFFSET_SPREAD_M..TRUTH_OFFSET_SPREAD_M);
    }
    let workspace = Workspace::default_for(&truth);
    let equilibria = sample_equilibria_with(&truth, &workspace, options.poses, options.closure, &mut rng)?;
    let mean_tension = equilibria
        .iter()
        .map(|eq| eq.tensions[truth.reference_cable].magnitude_n())
        .sum::<f64>()
        / equilibria.len() as f64;
    let effects = draw_effects(&truth, hidden, mean_tension, &mut rng);
    Ok(SimulatedTruth {
        truth,
        effects,
        equilibria,
        rng,
        nominal: nominal.clone(),
        closure: options.closure,
        seed,
    })
}

impl SimulatedTruth {
    /// The case's data under `noise`: the measurements (the discretised
    /// robot with `segments` per cable), the true robot with its effects set
    /// and the initial guess (the nominal robot).
    pub fn measure(&self, noise: NoisePreset, segments: usize) -> Result<(Vec<PoseMeasurement>, Robot, Robot)> {
        let mut rng = self.rng.clone();
        let sigmas = noise.sigmas(self.truth.platform_weight_n);
        let measurements = measure_with_effects(
            &self.truth,
            &self.effects,
            &self.equilibria,
            &sigmas,
            segments,
            &mut rng,
        )?;
        let mut truth = self.truth.clone();
        truth.effects = self.effects;
        Ok((measurements, truth, self.nominal.clone()))
    }

    /// [`HELD_OUT_POSES`] more poses of the same truth under `noise`, from a
    /// random stream of their own (seeded from the case's), so the case's
    /// data are the same with or without them. The robot takes them after
    /// the case's poses: their rows (and a drift with them) follow on.
    pub fn held_out(&self, noise: NoisePreset, segments: usize) -> Result<Vec<PoseMeasurement>> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ HELD_OUT_STREAM);
        let workspace = Workspace::default_for(&self.truth);
        let unseen = sample_equilibria_with(&self.truth, &workspace, HELD_OUT_POSES, self.closure, &mut rng)?;
        let session: Vec<_> = self.equilibria.iter().chain(&unseen).cloned().collect();
        let sigmas = noise.sigmas(self.truth.platform_weight_n);
        let rows = measure_with_effects(&self.truth, &self.effects, &session, &sigmas, segments, &mut rng)?;
        Ok(rows[self.equilibria.len()..].to_vec())
    }
}

/// Poses of each case's truth held out of its diagnosis, to measure what
/// the final model predicts ([`crate::experiments::HeldOutPrediction`]).
pub const HELD_OUT_POSES: usize = 15;

/// Mixed into a case's seed for its held-out poses' random stream.
const HELD_OUT_STREAM: u64 = 0x6865_6c64_6f75_7421;

/// One case's data: the measurements, the true robot (off the nominal one, its
/// effects set) and the initial guess (the nominal robot); poses closed by `options.closure`.
pub fn simulate_case(
    nominal: &Robot,
    hidden: &[EffectKind],
    seed: u64,
    options: &HiddenEffectOptions,
) -> Result<(Vec<PoseMeasurement>, Robot, Robot)> {
    simulate_truth(nominal, hidden, seed, options)?.measure(options.noise, options.segments)
}

/// The pairs of effects the sweep hides together.
pub const PAIRS: [[EffectKind; 2]; 4] = [
    [EffectKind::Com, EffectKind::Elastic],
    [EffectKind::EncoderScale, EffectKind::LoadCell],
    [EffectKind::Elastic, EffectKind::CommonGain],
    [EffectKind::EncoderDrift, EffectKind::LoadCellFriction],
];

/// `none`, or the names joined by `+` in sorted order.
fn set_name(names: impl Iterator<Item = String>) -> String {
    let mut names: Vec<String> = names.filter(|n| n != "none").collect();
    names.sort();
    if names.is_empty() {
        "none".into()
    } else {
        names.join("+")
    }
}

/// Run one case: simulate `hidden` (empty: none) in a truth drawn off
/// `nominal`, diagnose blind from the nominal robot, score.
pub fn run_case(
    nominal: &Robot,
    hidden: &[EffectKind],
    seed: u64,
    options: &HiddenEffectOptions,
) -> Result<HiddenCase> {
    let simulated = simulate_truth(nominal, hidden, seed, options)?;
    let held_out = simulated.held_out(options.noise, options.segments)?;
    let data = simulated.measure(options.noise, options.segments)?;
    diagnose_case(nominal, (hidden, seed), options, data, &held_out)
}

/// [`run_case`] on the case's simulated data (`measurements, truth, guess`).
fn diagnose_case(
    nominal: &Robot,
    (hidden, seed): (&[EffectKind], u64),
    options: &HiddenEffectOptions,
    (measurements, truth, guess): (Vec<PoseMeasurement>, Robot, Robot),
    held_out: &[PoseMeasurement],
) -> Result<HiddenCase> {
    let mut diagnose_options =
        DiagnoseOptions::new(CalibrationOptions::new(options.noise.sigmas(truth.platform_weight_n)));
    diagnose_options.folds = options.folds;
    let diagnosis = diagnose(
        &guess,
        &measurements,
        Some(&truth),
        &diagnose_options,
        &mut |_, _, _| {},
    )?;
    let left_out = match options.catalogue {
        Catalogue::Full => Vec::new(),
        Catalogue::LeaveOneOut => leave_each_out(
            (&guess, &measurements, &truth),
            (hidden, &diagnosis.verdict),
            &diagnose_options,
        )?,
    };
    let hidden_name = set_name(hidden.iter().map(|k| k.name().to_string()));

    let step_one = |k: EffectKind| {
        diagnosis
            .candidates
            .iter()
            .find(|c| c.step == 1 && c.effect == k.name())
    };
    // Detectable: every hidden effect's first-step test has power >= 0.9 at its true magnitude.
    let powers: Vec<Option<f64>> = hidden
        .iter()
        .map(|k| {
            step_one(*k).and_then(|row| {
                let theta = k.variable_values(&truth.effects);
                let full = power_against(row, &theta, diagnosis.variance_factor)?;
                // An effect that contains a simpler one must also be told from it.
                match EffectKind::ALL.into_iter().find(|inner| inner.nested_in() == Some(*k)) {
                    Some(inner) => Some(full.min(nested_power(row, &theta, inner, diagnosis.variance_factor)?)),
                    None => Some(full),
                }
            })
        })
        .collect();
    let power = powers
        .iter()
        .copied()
        .collect::<Option<Vec<f64>>>()
        .map(|p| p.into_iter().fold(1.0, f64::min));
    let anchor_mae_extended_m = match hidden {
        [k] => step_one(*k).and_then(|c| c.anchor_mae_m),
        _ => None,
    };
    let anchor_mae_known_geometry_m = if hidden.contains(&EffectKind::Pulley) {
        let mut known = guess.clone();
        known.effects = truth.effects;
        let result = calibrate(&known, &measurements, &diagnose_options.calibration)?;
        Some(CalibrationError::between(&result.robot, &truth).anchor_coordinate_mae_m)
    } else {
        None
    };
    Ok(HiddenCase {
        robot: nominal.name.clone(),
        noise: options.noise,
        seed,
        truth: truth.effects.to_string(),
        correct: names_exactly(&diagnosis.verdict, hidden),
        final_model: diagnosis.explanation.final_model.clone(),
        explained: diagnosis.explanation.explained,
        failing_tests: diagnosis
            .explanation
            .final_tests
            .iter()
            .filter(|t| !t.consistent)
            .map(|t| format!("{} {:.1} > {:.1}", t.kind, t.chi_square, t.limit))
            .collect(),
        stand_ins: diagnosis.explanation.stand_ins.iter().map(|s| s.sentence()).collect(),
        left_out,
        verdict: diagnosis.verdict,
        hidden: hidden_name,
        power: if hidden.is_empty() { None } else { power },
        anchor_mae_before_m: diagnosis.gain.anchor_mae_before_m.unwrap_or(f64::NAN),
        anchor_mae_after_m: diagnosis.gain.anchor_mae_after_m.unwrap_or(f64::NAN),
        anchor_mae_extended_m,
        baseline_error_over_sigma: diagnosis.baseline_error_over_sigma.unwrap_or(f64::NAN),
        anchor_mae_known_geometry_m,
        held_out: held_out_prediction(
            &diagnosis.robot_before,
            &diagnosis.robot_after,
            &diagnose_options.calibration.noise,
            held_out,
        ),
    })
}

/// Per hidden effect, the diagnosis of the case with it (and its nested
/// relatives) left out of the catalogue, and whether its verdict is honest
/// (`full_verdict`: the verdict with the whole catalogue).
fn leave_each_out(
    (guess, measurements, truth): (&Robot, &[PoseMeasurement], &Robot),
    (hidden, full_verdict): (&[EffectKind], &str),
    options: &DiagnoseOptions,
) -> Result<Vec<LeftOut>> {
    hidden
        .iter()
        .map(|&k| {
            let out = left_out_with(k);
            let mut blind = options.clone();
            blind.candidates.retain(|c| !out.contains(c));
            let diagnosis = diagnose(guess, measurements, Some(truth), &blind, &mut |_, _, _| {})?;
            Ok(LeftOut {
                left_out: set_name(out.iter().map(|k| k.name().to_string())),
                honest: honest(&diagnosis.verdict, hidden, &out, full_verdict),
                verdict: diagnosis.verdict,
            })
        })
        .collect()
}

/// Whether `verdict` names exactly the `hidden` effects: one term per
/// hidden effect, each term the effect or an ambiguous pair `X|Y` holding it
/// (one of two the data do not tell apart), and nothing left unexplained.
pub fn names_exactly(verdict: &str, hidden: &[EffectKind]) -> bool {
    if verdict == "none" {
        return hidden.is_empty();
    }
    let terms: Vec<Vec<&str>> = verdict.split('+').map(|t| t.split('|').collect()).collect();
    let mut left: Vec<&str> = hidden.iter().map(|k| k.name()).collect();
    terms.len() == hidden.len()
        && terms.iter().all(|term| {
            let holds: Vec<&str> = left.iter().copied().filter(|h| term.contains(h)).collect();
            match holds.as_slice() {
                [one] => {
                    left.retain(|h| h != one);
                    true
                }
                _ => false,
            }
        })
}

/// The power of telling `theta` (variable units, `row`'s effect) from the
/// nested effect `inner` (equal gains: the multiples of `1`): the
/// non-centrality `min_c (theta - c 1)^T Sigma^-1 (theta - c 1) / s^2` on the
/// parameters the nested effect drops, at `row`'s false-alarm level.
fn nested_power(row: &CandidateFit, theta: &[f64], inner: EffectKind, variance_factor: f64) -> Option<f64> {
    let k = theta.len();
    if row.covariance.len() != k {
        return None;
    }
    let covariance = DMatrix::from_fn(k, k, |r, c| row.covariance[r][c] * variance_factor);
    let cholesky = covariance.cholesky()?;
    let theta = DVector::from_column_slice(theta);
    let ones = DVector::from_element(k, 1.0);
    let common = ones.dot(&cholesky.solve(&theta)) / ones.dot(&cholesky.solve(&ones));
    let deviation = &theta - ones * common;
    let lambda = deviation.dot(&cholesky.solve(&deviation));
    let dof = k - inner.parameter_count();
    let critical = chi_square_critical(dof, row.p_threshold);
    lambda
        .is_finite()
        .then(|| noncentral_chi_square_survival(dof, lambda, critical))
}

/// The seed of case `index` of the effects `hidden` on robot number
/// `robot_index`: distinct for every case (and the same as before for a
/// single effect or none).
pub fn case_seed(base_seed: u64, robot_index: usize, hidden: &[EffectKind], index: usize) -> u64 {
    let position = |k: &EffectKind| 1 + EffectKind::ALL.iter().position(|e| e == k).unwrap_or(0);
    let effect_index = hidden.iter().fold(0, |acc, k| acc * 10 + position(k));
    base_seed
        .wrapping_mul(1_000_003)
        .wrapping_add((robot_index as u64) * 100_000 + (effect_index as u64) * 10_000 + index as u64)
}

/// A case whose simulated readings sagcal refuses as input (a load-cell
/// reading at or below zero where the truth's effects leave the reference
/// cable nearly slack): no operator could calibrate from them, so it is
/// reported, not diagnosed.
#[derive(Debug, Clone, Serialize)]
pub struct UnmeasurableCase {
    /// Robot name.
    pub robot: String,
    /// The case's seed.
    pub seed: u64,
    /// The sensor noise of the case.
    pub noise: NoisePreset,
    /// The hidden effects joined by `+` in sorted order, or `none`.
    pub hidden: String,
    /// Which reading sagcal refuses, and why.
    pub reason: String,
}

/// What a sweep found: the diagnosed cases and those whose data could not be measured.
#[derive(Debug, Clone, Default)]
pub struct SweepCases {
    /// The diagnosed cases, in the order robot, noise reading, hidden set, seed.
    pub diagnosed: Vec<HiddenCase>,
    /// The cases whose simulated readings sagcal refuses, in the same order.
    pub unmeasurable: Vec<UnmeasurableCase>,
}

/// One case of a sweep: diagnosed, or its readings refused.
enum SweepCase {
    Diagnosed(Box<HiddenCase>),
    Unmeasurable(UnmeasurableCase),
}

/// Why sagcal refuses `measurements` as input (`validate_measurements`), if
/// it does: the first non-positive load-cell reading, named by pose, or the
/// check's own message.
pub fn refused_readings(measurements: &[PoseMeasurement]) -> Option<String> {
    let refused = validate_measurements(measurements).err()?;
    let refused_tension = |m: &PoseMeasurement| m.reference_tension_n.is_nan() || m.reference_tension_n <= 0.0;
    let reason = match measurements.iter().position(refused_tension) {
        Some(k) => format!(
            "pose {}: load-cell reading {:.3} N (sagcal needs a positive reference tension)",
            k + 1,
            measurements[k].reference_tension_n
        ),
        None => refused.to_string(),
    };
    Some(reason)
}

/// Run `seeds` cases of none, of every effect and of every pair of
/// [`PAIRS`] on every robot under every noise reading of `noises`, in
/// parallel. `progress()` is called after each case. A case whose readings
/// sagcal refuses ([`refused_readings`]) is reported as unmeasurable; any
/// other failure is an error naming the case. Options that cannot give a
/// case (too few poses or seeds, no robot; [`HiddenEffectOptions::validate`])
/// are an error before any case is run.
pub fn run_sweep(
    robots: &[Robot],
    noises: &[NoisePreset],
    seeds: usize,
    base_seed: u64,
    options: &HiddenEffectOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<SweepCases> {
    options.validate()?;
    if seeds == 0 {
        return Err(Error::InvalidInput(
            "seeds (--seeds): at least 1 case per hidden set is needed, got 0".into(),
        ));
    }
    if robots.is_empty() || noises.is_empty() {
        return Err(Error::InvalidInput(
            "the sweep needs at least one robot (--robots) and one noise reading (--noise)".into(),
        ));
    }
    let mut sets: Vec<Vec<EffectKind>> = vec![Vec::new()];
    sets.extend(EffectKind::ALL.map(|k| vec![k]));
    sets.extend(PAIRS.map(|p| p.to_vec()));
    // One job per robot, hidden set and seed: its truth is drawn once and
    // read under every noise reading (the same data as drawing it per case).
    let mut jobs = Vec::new();
    for r in 0..robots.len() {
        for set in &sets {
            jobs.extend((0..seeds).map(|i| (r, set.clone(), i)));
        }
    }
    let name = |r: usize, set: &[EffectKind], noise: String, seed: u64| {
        format!(
            "hidden-effect case robot `{}`, effects {}, {noise} noise, seed {seed}",
            robots[r].name,
            set_name(set.iter().map(|k| k.name().to_string()))
        )
    };
    let done: Vec<Vec<Result<SweepCase>>> = jobs
        .par_iter()
        .map(|(r, set, index)| {
            let seed = case_seed(base_seed, *r, set, *index);
            let simulated = simulate_truth(&robots[*r], set, seed, options);
            noises
                .iter()
                .map(|noise| {
                    let case_options = HiddenEffectOptions {
                        noise: *noise,
                        ..*options
                    };
                    let case = simulated
                        .as_ref()
                        .map_err(|e| input_error("", e))
                        .and_then(|truth| {
                            let held_out = truth.held_out(*noise, options.segments)?;
                            Ok((truth.measure(*noise, options.segments)?, held_out))
                        })
                        .and_then(|(data, held_out)| match refused_readings(&data.0) {
                            Some(reason) => Ok(SweepCase::Unmeasurable(UnmeasurableCase {
                                robot: robots[*r].name.clone(),
                                seed,
                                noise: *noise,
                                hidden: set_name(set.iter().map(|k| k.name().to_string())),
                                reason,
                            })),
                            None => diagnose_case(&robots[*r], (set, seed), &case_options, data, &held_out)
                                .map(|case| SweepCase::Diagnosed(Box::new(case))),
                        })
                        .map_err(|e| input_error(&format!("{}: ", name(*r, set, format!("{noise:?}"), seed)), &e));
                    progress();
                    case
                })
                .collect()
        })
        .collect();
    // Back in the order robot, noise reading, hidden set, seed.
    let mut by_job: Vec<std::vec::IntoIter<Result<SweepCase>>> = done.into_iter().map(Vec::into_iter).collect();
    let mut cases = SweepCases::default();
    for r in 0..robots.len() {
        for _ in noises {
            for (j, job) in jobs.iter().enumerate() {
                if job.0 == r {
                    match by_job[j].next().transpose()? {
                        Some(SweepCase::Diagnosed(case)) => cases.diagnosed.push(*case),
                        Some(SweepCase::Unmeasurable(case)) => cases.unmeasurable.push(case),
                        None => {}
                    }
                }
            }
        }
    }
    Ok(cases)
}

/// `error` as an input error with `context` before its message, without a
/// second `invalid input: ` when it is one already.
fn input_error(context: &str, error: &Error) -> Error {
    match error {
        Error::InvalidInput(why) => Error::InvalidInput(format!("{context}{why}")),
        other => Error::InvalidInput(format!("{context}{other}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_verdict_names_the_hidden_set_alone_or_in_an_ambiguous_pair() {
        let (com, mount, elastic) = (EffectKind::Com, EffectKind::LocaliserMount, EffectKind::Elastic);
        assert!(names_exactly("none", &[]));
        assert!(!names_exactly("unexplained", &[]));
        assert!(names_exactly("com+elastic", &[elastic, com]));
        assert!(names_exactly("localiser-mount|com", &[mount]));
        assert!(names_exactly("localiser-mount|com+elastic", &[com, elastic]));
        assert!(!names_exactly("localiser-mount|com", &[mount, com]));
        assert!(!names_exactly("com+unexplained", &[com]));
        assert!(!names_exactly("com", &[com, elastic]));
        assert!(!names_exactly("elastic|pulley", &[com]));
        assert!(!names_exactly("none", &[com]));
    }
}
