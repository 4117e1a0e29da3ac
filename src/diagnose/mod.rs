//! What the calibration model gets wrong: `sagcal diagnose`.
//!
//! Given measurements, [`diagnose`]
//!
//! 1. calibrates with the baseline model (the paper's closed-form catenary,
//!    with every sensor as evidence: the localiser's orientation is a prior
//!    unless turned off) and tests the normalised residuals against the
//!    stated sensor noise with a chi-square test per factor type ([`FactorTest`]);
//! 2. relates the residuals to physical drivers of each cable and pose
//!    (tension, tension x length, cable length, sag, elevation, pulley wrap
//!    angle, platform position) by correlation, and says which carry structure
//!    ([`DriverTest`], `|t| > 3.29`, two-sided p < 0.001);
//! 3. searches the hypotheses, each effect of the catalogue ([`EffectKind`],
//!    extra parameter variables of the factor graph,
//!    [`crate::calib::effect_factors`]) and "the localiser's orientations are
//!    unreliable" ([`Hypothesis::OrientationFree`], 3 parameters per pose), by
//!    forward selection with likelihood-ratio tests at a stated false-alarm
//!    rate and backward checks (`selection`), so that several effects can be
//!    named at once; each test's power at the effect's smallest physically
//!    plausible magnitude comes from the fit's Fisher information, and a
//!    candidate whose power is below 0.9 is reported as not detectable at
//!    this noise with these poses;
//! 4. keeps only what predicts (`prediction`): each effect the selection
//!    added must lower the held-out residual of the model without it and not
//!    make the anchors worse by their own covariance, else it is taken out;
//! 5. asks whether the final model explains the data (`explanation`): it must
//!    pass every sensor's chi-square test at the false-alarm rate (each
//!    sensor's expectation its redundancy) and hold no stand-in
//!    (`stand_ins`: an estimate beyond what any real robot could have,
//!    [`crate::model::effect_limits`]; an effect whose own sensor stays
//!    inconsistent; freed orientations) and leave no structure: no term
//!    (a reading's residual linear in a driver, the row or the direction of
//!    motion) beyond Rao's score test at the stated rate (`missing_terms`).
//!    The terms missing are proposed by a sparse regression; the causes of
//!    a model that does not explain the data are named only where they are
//!    needed beyond those terms. Hypotheses whose BIC is within 2 of each
//!    other are named together (`X|Y`);
//! 6. reports the verdict (the causes in the order added, joined by `+`;
//!    `none` when nothing is wrong; `unexplained`, or the causes and
//!    `+unexplained`, when the catalogue does not hold what is wrong), the
//!    parameters with 1-sigma, the stand-ins with what they stand in for,
//!    what the final model leaves, and the gain: held-out residual RMS before
//!    and after and, given the truth, anchor and offset errors before and
//!    after.
//!
//! Held-out residual: for each fold the model is re-fitted without the
//! fold's poses; each held-out pose's own variables (pose, reference tension)
//! are then fitted to its measurements with the anchors, offsets and effect
//! parameters held, and its whitened measurement residuals (encoders, load
//! cell, localiser) are collected. `cv_rms` is their root mean square (about 1
//! when the model and the stated noise are right).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::diagnose::{diagnose, DiagnoseOptions};
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! // Encoders that read 0.3 % long: each reading is gain x length (+ offset).
//! let nominal = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
//! let equilibria = sample_equilibria(&nominal, &Workspace::default_for(&nominal), 20, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(nominal.platform_weight_n);
//! let mut data = measure(&nominal, &equilibria, &noise, &mut rng);
//! for (m, e) in data.iter_mut().zip(&equilibria) {
//!     for i in 0..4 {
//!         m.encoder_lengths_m[i] += 0.003 * e.cable_lengths_m[i];
//!     }
//! }
//! let mut options = DiagnoseOptions::new(CalibrationOptions::new(noise));
//! options.candidates = vec![EffectKind::parse("encoder-gain").unwrap()];
//! options.folds = 2;
//! let diagnosis = diagnose(&nominal, &data, None, &options, &mut |_, _, _| {})?;
//! assert_eq!(diagnosis.verdict, "encoder-gain");
//! # Ok::<(), sagcal::Error>(())
//! ```

mod candidates;
mod drivers;
mod equivalent_fits;
mod explanation;
mod missing_terms;
mod prediction;
mod report;
mod residual_tests;
mod selection;
mod settings;
mod stand_ins;
mod term_refit;
mod variance_components;
pub mod verify;

use crate::calib::gross_errors::{calibrate_checked, ExcludedReading, GrossErrorOptions, Verdict};
use crate::calib::mistakes::{Mistake, MistakeKind};
use crate::calib::{
    calibrate, CalibrationGraph, CalibrationOptions, CalibrationResult, OrientationPrior, PreparedCalibration,
};
use crate::error::{Error, Result};
use crate::model::effect_kind::{EffectKind, EffectSet};
use crate::model::measurement::{PoseMeasurement, ReadingSet, Sensor};
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::stats::{self, chi_square_quantile_999};

pub use candidates::{power_against, CandidateFit, Hypothesis, ParameterValue, DETECTION_POWER, WEIGHT_SCALING};
pub use drivers::{DriverSeries, DriverTest, DRIVERS, DRIVER_T_LIMIT};
pub use explanation::{Ambiguity, Explanation, AMBIGUOUS_BIC};
pub use missing_terms::{CausesGivenTerms, MissingTerm, ALIKE_SHARE, MOST_DESCRIBING};
pub use prediction::NotPredictive;
pub use report::{error_over_sigma, Diagnosis, EffectFit, Gain};
pub use residual_tests::{FactorTest, MEASUREMENT_KINDS};
pub use selection::SelectionStep;
pub use settings::DiagnoseSettings;
pub use stand_ins::{StandIn, STAND_IN_SIGMAS};
pub use variance_components::{noise_the_data_show, SMALLEST_NOISE_SCALE};

use candidates::{rebuild, Model};
use drivers::{driver_series, driver_tests, samples};
use explanation::explain;
use prediction::predictive_model;
use residual_tests::{factor_tests, measurement_components, total_chi_square, variance_factor};
use selection::{cross_validate, first_effect, forward_selection, Search, Selection};

/// How to diagnose.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// The baseline calibration's options (their `free_effects` are ignored;
    /// the orientation prior is used unless it is `off`).
    pub calibration: CalibrationOptions,
    /// The candidate effects of the search.
    pub candidates: Vec<EffectKind>,
    /// Whether "the localiser's orientations are unreliable" is a hypothesis too.
    pub orientation_hypothesis: bool,
    /// Folds of the cross-validation over poses (>= 2).
    pub folds: usize,
    /// The false-alarm rate of the whole search: the probability of
    /// declaring an effect on data the baseline describes (module docs).
    pub false_alarm: f64,
    /// Whether the rows are in the order the poses were taken (a sagcal
    /// measurement file): only then are the row (a drift over time) and each
    /// cable's direction of last motion drivers of step 2. A RecurDyn log or
    /// an authors' folder holds poses whose order is not the order a robot
    /// took them in.
    pub rows_in_time_order: bool,
}

impl DiagnoseOptions {
    /// Every candidate of the catalogue and the orientation hypothesis, 5
    /// folds, a false-alarm rate of 0.1 %.
    pub fn new(calibration: CalibrationOptions) -> Self {
        Self {
            calibration,
            candidates: EffectKind::ALL.to_vec(),
            orientation_hypothesis: true,
            folds: 5,
            false_alarm: 1e-3,
            rows_in_time_order: true,
        }
    }
}

/// The progress of a diagnosis: `report(done, total, what)` before each fit.
struct Progress<'a> {
    done: usize,
    total: usize,
    report: &'a mut dyn FnMut(usize, usize, &str),
}

impl<'a> Progress<'a> {
    /// A progress of `total` steps, reported to `report`.
    fn new(total: usize, report: &'a mut dyn FnMut(usize, usize, &str)) -> Self {
        Self { done: 0, total, report }
    }

    /// Report `what` as the next step.
    fn step(&mut self, what: &str) {
        (self.report)(self.done, self.total, what);
        self.done += 1;
    }

    /// Count `steps` steps as done without a report of their own (fits run
    /// in parallel under one report).
    fn advance(&mut self, steps: usize) {
        self.done += steps;
    }

    /// `steps` more steps than planned.
    fn grow(&mut self, steps: usize) {
        self.total += steps;
    }

    /// Report the end.
    fn finish(&mut self) {
        (self.report)(self.total, self.total, "done");
    }
}

/// The baseline model fitted to the data: the calibration, the poses it
/// used, its graph at the fit and the quantities every comparison needs.
struct Baseline {
    /// The baseline calibration.
    result: CalibrationResult,
    /// Its options with the orientation prior resolved.
    options: CalibrationOptions,
    /// The measurements of the poses it used.
    used: Vec<PoseMeasurement>,
    /// Its graph at the fit.
    graph: CalibrationGraph,
    /// Measurement residual components `n`.
    components: usize,
    /// Unknowns of the baseline: 8 per pose and 16 global.
    unknowns: usize,
    /// Chi-square over all factors.
    chi_square: f64,
    /// Degrees of freedom (measurements + statics constraints - unknowns).
    dof: usize,
    /// The a posteriori variance factor (1 unless the data are more precise than stated).
    variance_factor: f64,
    /// The baseline's BIC.
    bic: f64,
    /// Mean load-cell reading over the poses used, newtons.
    mean_reference_tension_n: f64,
    /// The initial guess every calibration starts from, with the cleaned
    /// measurements and the stages of their calibration that the
    /// orientation prior and the free effects do not enter.
    start: PreparedCalibration,
}

impl Baseline {
    /// Calibrate with the baseline model (`options.calibration` without a free effect).
    fn fit(
        robot: &Robot,
        measurements: &[PoseMeasurement],
        options: &DiagnoseOptions,
        progress: &mut Progress<'_>,
    ) -> Result<Self> {
        // Every sensor is evidence: the localiser's orientation is a prior
        // unless the user turned it off; "it is unreliable" is a hypothesis.
        let orientation_prior = match options.calibration.orientation_prior {
            OrientationPrior::Off => OrientationPrior::Off,
            _ => OrientationPrior::On,
        };
        let base_options = CalibrationOptions {
            free_effects: EffectSet::NONE,
            orientation_prior,
            ..options.calibration
        };
        progress.step("baseline calibration");
        let start = PreparedCalibration::new(robot, measurements, &base_options);
        let result = start.calibrate(&base_options)?;
        let resolved = base_options.as_used_by(&result);
        let used: Vec<PoseMeasurement> = (0..measurements.len())
            .filter(|k| !result.excluded_poses.contains(k))
            .map(|k| measurements[k])
            .collect();
        if used.len() < 2 * options.folds {
            return Err(Error::InvalidInput(format!(
                "diagnose: {} usable poses are too few for {}-fold cross-validation (need at least {})",
                used.len(),
                options.folds,
                2 * options.folds
            )));
        }
        let graph = rebuild(&result, &used, &resolved);
        let components = measurement_components(&graph.graph);
        let unknowns = 8 * used.len() + 4 * CABLE_COUNT;
        let constraints = CABLE_COUNT * used.len();
        let chi_square = total_chi_square(&graph.graph);
        let dof = (components + constraints).saturating_sub(unknowns).max(1);
        let mut base = Self {
            result,
            options: resolved,
            used,
            graph,
            components,
            unknowns,
            chi_square,
            dof,
            variance_factor: variance_factor(chi_square, dof),
            bic: f64::NAN,
            mean_reference_tension_n: f64::NAN,
            start,
        };
        base.mean_reference_tension_n =
            base.used.iter().map(|m| m.reference_tension_n).sum::<f64>() / base.used.len() as f64;
        base.bic = base.bic_of(chi_square, 0);
        Ok(base)
    }

    /// [`calibrate`] of `measurements` from the initial guess under
    /// `options`, from the shared stages where the measurements are the
    /// baseline's (the same result, [`PreparedCalibration`]).
    fn calibrate(&self, measurements: &[PoseMeasurement], options: &CalibrationOptions) -> Result<CalibrationResult> {
        if measurements == self.start.measurements() {
            self.start.calibrate(options)
        } else {
            calibrate(self.start.initial(), measurements, options)
        }
    }

    /// The BIC of a fit with chi-square `chi` and `added` parameters more than the baseline.
    fn bic_of(&self, chi: f64, added: usize) -> f64 {
        stats::bic(chi, self.variance_factor, self.unknowns + added, self.components)
    }
}

/// Diagnose `measurements` of `robot` (the initial guess; its `[effects]` are
/// known inputs), optionally against the `truth`. `progress(done, total, what)`
/// is called before each fit.
pub fn diagnose(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    truth: Option<&Robot>,
    options: &DiagnoseOptions,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<Diagnosis> {
    check_options(options)?;
    let options = &time_order_resolved(options, measurements);
    let mut progress = Progress::new(3 + 2 * options.folds, progress);
    // 0. Gross errors: blunders and common mistakes are not model errors.
    let (cleaned, excluded_readings, mistakes) = screen_gross_errors(robot, measurements, options, &mut progress)?;
    let (cleaned, first_row_left_out) = first_motion_unknown(cleaned, options);
    let measurements = cleaned.as_slice();
    // 1. The baseline calibration, its residuals tested against the stated noise.
    let (base, factor_tests, noise_shown, used_options) = fit_baseline(robot, measurements, options, &mut progress)?;
    let options = &used_options;
    // 2. The residuals against the physical drivers.
    let base_samples = samples(&base.result, &base.used, &base.options)?;
    let drivers = driver_tests(&base_samples, options.rows_in_time_order);
    let baseline_cv = cross_validate(&base.result, &base.used, &base.options, options.folds, &mut |what| {
        progress.step(&format!("baseline: {what}"))
    })?;
    // 3-4. Forward selection at the stated false-alarm rate; only what predicts stays.
    let (selection, model, cv_after, not_predictive) =
        select_predictive(&base, measurements, truth, options, baseline_cv, &mut progress)?;
    let model = &model;
    progress.finish();
    // 5-6. The report: what the final model gains, whether it explains the
    // data, and the structure left.
    let gain = report::gain(truth, &base.result.robot, &model.result.robot, baseline_cv, cv_after);
    let (drivers_after, series, after_samples) = if model.hypotheses.is_empty() {
        (Vec::new(), driver_series(&drivers, &base_samples, None), None)
    } else {
        let after_samples = samples(&model.result, &base.used, &model.options)?;
        let shown = first_effect(model).map(|kind| (kind, after_samples.as_slice()));
        let series = driver_series(&drivers, &base_samples, shown);
        let tests = driver_tests(&after_samples, options.rows_in_time_order);
        (tests, series, Some(after_samples))
    };
    let left = match &after_samples {
        None => (drivers.as_slice(), base_samples.as_slice(), base_samples.as_slice()),
        Some(after) => (drivers_after.as_slice(), after.as_slice(), base_samples.as_slice()),
    };
    let explanation = explain(
        &base,
        model,
        left,
        (&selection.steps, &selection.candidates),
        (options.false_alarm, options.rows_in_time_order),
        measurements,
    )?;
    let reason = report::reason(&selection, &base, options, &not_predictive, &explanation);
    let undetectable = report::undetectable(&selection);
    let equivalent_fits = equivalent_fits::equivalent_fits(&model.result.effect_estimates, robot);
    Ok(Diagnosis {
        robot: robot.name.clone(),
        poses_used: base.used.len(),
        measurement_components: base.components,
        baseline_chi_square: base.chi_square,
        baseline_dof: base.dof,
        baseline_consistent: base.chi_square <= chi_square_quantile_999(base.dof),
        variance_factor: base.variance_factor,
        noise_shown,
        orientation_prior: base.options.orientation_prior,
        false_alarm: options.false_alarm,
        factor_tests,
        rows_in_time_order: options.rows_in_time_order,
        first_row_left_out,
        drivers,
        drivers_after,
        baseline_bic: base.bic,
        baseline_cv_rms: baseline_cv,
        verdict: explanation.verdict(),
        selected: selection.model.name(),
        not_predictive,
        explanation,
        effects: report::effect_fits(&model.result.effect_estimates),
        steps: selection.steps,
        undetectable,
        equivalent_fits,
        candidates: selection.candidates,
        reason,
        gain,
        baseline_error_over_sigma: truth.map(|t| error_over_sigma(&base.result.robot, t, &base.result.uncertainty)),
        robot_after: model.result.robot.clone(),
        robot_before: base.result.robot.clone(),
        series,
        excluded_readings,
        mistakes,
    })
}

/// The baseline fit and its chi-square test per sensor. Where the data are
/// more precise than stated, each sensor by its own factor, the baseline is
/// fitted again with the noise the data show ([`noise_the_data_show`]),
/// which the options returned carry into every later test.
fn fit_baseline(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    options: &DiagnoseOptions,
    progress: &mut Progress<'_>,
) -> Result<(Baseline, Vec<FactorTest>, Option<SensorNoise>, DiagnoseOptions)> {
    let base = Baseline::fit(robot, measurements, options, progress)?;
    let tests = factor_tests(&base.graph.graph, base.components, base.dof);
    let shown = (base.variance_factor < 1.0)
        .then(|| noise_the_data_show(&options.calibration.noise, &tests))
        .flatten();
    let Some(noise) = shown else {
        return Ok((base, tests, None, options.clone()));
    };
    let rescaled = DiagnoseOptions {
        calibration: CalibrationOptions {
            noise,
            ..options.calibration
        },
        ..options.clone()
    };
    progress.grow(1);
    let base = Baseline::fit(robot, measurements, &rescaled, progress)?;
    let tests = factor_tests(&base.graph.graph, base.components, base.dof);
    Ok((base, tests, Some(noise), rescaled))
}

/// `options` for `measurements`: the row and the direction of last motion
/// are drivers, and the effects of time and motion
/// ([`EffectKind::needs_time_order`]) candidates, only where the rows are
/// in the order the robot took them and every pose carries that order
/// ([`PoseMeasurement::order`]); elsewhere they are off.
fn time_order_resolved(options: &DiagnoseOptions, measurements: &[PoseMeasurement]) -> DiagnoseOptions {
    let ordered = options.rows_in_time_order && measurements.iter().all(|m| m.order.is_some());
    DiagnoseOptions {
        rows_in_time_order: ordered,
        candidates: options
            .candidates
            .iter()
            .copied()
            .filter(|k| ordered || !k.needs_time_order())
            .collect(),
        ..options.clone()
    }
}

/// How many times the search runs at most (module docs of [`select_predictive`]).
const MOST_SEARCHES: usize = 3;

/// Steps 3-4: forward selection of the hypotheses at the stated false-alarm
/// rate, then only what predicts stays (the held-out residual and the
/// anchors). An effect taken out for not predicting may have taken the
/// place of one that would: the search runs again without it, at most
/// [`MOST_SEARCHES`] times. On data the baseline describes a second search
/// only follows a declared effect, so the stated false-alarm rate holds.
/// Returns the last search, its predictive model with its held-out residual
/// RMS, and everything taken out.
fn select_predictive(
    base: &Baseline,
    measurements: &[PoseMeasurement],
    truth: Option<&Robot>,
    options: &DiagnoseOptions,
    baseline_cv: f64,
    progress: &mut Progress<'_>,
) -> Result<(Selection, Model, f64, Vec<NotPredictive>)> {
    let mut banned: Vec<EffectKind> = Vec::new();
    let mut all_removed = Vec::new();
    for search_index in 1..=MOST_SEARCHES {
        let narrowed = DiagnoseOptions {
            candidates: options
                .candidates
                .iter()
                .copied()
                .filter(|k| !banned.contains(k))
                .collect(),
            ..options.clone()
        };
        let search = Search {
            base,
            measurements,
            truth,
            options: &narrowed,
        };
        let selection = forward_selection(&search, progress);
        let (model, cv, removed) = predictive_model(&search, &selection.model, baseline_cv, progress)?;
        let newly: Vec<EffectKind> = removed
            .iter()
            .flat_map(|r| r.hypothesis.split('+').map(str::to_string).collect::<Vec<_>>())
            .filter_map(|name| EffectKind::parse(&name).ok())
            .filter(|k| !model.effects().contains(*k) && !banned.contains(k))
            .collect();
        all_removed.extend(removed);
        if newly.is_empty() || search_index == MOST_SEARCHES {
            return Ok((selection, model, cv, all_removed));
        }
        banned.extend(newly);
    }
    unreachable!("the loop returns on its last search")
}

/// The direction of the motion that led to the first row is unknown (the
/// robot came from wherever it was homed): where a candidate depends on that
/// direction (backlash, pulley friction), the first row's encoders and load
/// cell take no part in any fit, so that every hypothesis sees the same
/// readings. Returns the measurements and whether that was done.
fn first_motion_unknown(
    mut measurements: Vec<PoseMeasurement>,
    options: &DiagnoseOptions,
) -> (Vec<PoseMeasurement>, bool) {
    let needs_direction = options
        .candidates
        .iter()
        .any(|k| matches!(k, EffectKind::EncoderBacklash | EffectKind::LoadCellFriction));
    if !(options.rows_in_time_order && needs_direction) {
        return (measurements, false);
    }
    let mut left_out = false;
    for m in measurements.iter_mut().filter(|m| m.order.is_some_and(|o| o.row == 1)) {
        m.excluded = (0..CABLE_COUNT)
            .map(Sensor::Encoder)
            .chain([Sensor::LoadCell])
            .fold(m.excluded, ReadingSet::with);
        left_out = true;
    }
    (measurements, left_out)
}

/// The options' own checks: at least 2 folds, a false-alarm rate in (0, 1).
fn check_options(options: &DiagnoseOptions) -> Result<()> {
    if options.folds < 2 {
        return Err(Error::InvalidInput(format!(
            "diagnose: at least 2 cross-validation folds are needed, got {}",
            options.folds
        )));
    }
    if !(options.false_alarm > 0.0 && options.false_alarm < 1.0) {
        return Err(Error::InvalidInput(format!(
            "diagnose: the false-alarm rate must be in (0, 1), got {}",
            options.false_alarm
        )));
    }
    Ok(())
}

/// Step 0: the gross-error tests of `calibrate`
/// ([`crate::calib::gross_errors::calibrate_checked`]) on the baseline. A
/// sensor in the wrong unit is an error (the data must be fixed). Readings
/// are left out when the baseline is then consistent, or when a specific
/// mistake explains them (swapped cables, a re-homed drum); otherwise the
/// failing readings are the model error this diagnosis is for, and every
/// reading stays in (the mistakes found are still reported).
fn screen_gross_errors(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    options: &DiagnoseOptions,
    progress: &mut Progress<'_>,
) -> Result<(Vec<PoseMeasurement>, Vec<ExcludedReading>, Vec<Mistake>)> {
    progress.step("gross errors");
    let check = GrossErrorOptions {
        false_alarm: options.false_alarm,
        ..GrossErrorOptions::default()
    };
    let base_options = CalibrationOptions {
        free_effects: EffectSet::NONE,
        ..options.calibration
    };
    let checked = calibrate_checked(robot, measurements, &base_options, &check)
        .map_err(|e| Error::InvalidInput(format!("diagnose: {e}")))?;
    let consistent = checked.verdict == Verdict::Consistent;
    let specific = |x: &ExcludedReading| {
        checked.mistakes.iter().any(|m| {
            matches!(m.kind, MistakeKind::SwappedCables | MistakeKind::Rehoming)
                && x.explanation.as_deref() == Some(m.message.as_str())
        })
    };
    // An inconsistent baseline's candidates are in `set_aside`.
    let kept: Vec<ExcludedReading> = checked
        .excluded
        .iter()
        .chain(&checked.set_aside)
        .filter(|x| consistent || specific(x))
        .cloned()
        .collect();
    let mut cleaned = measurements.to_vec();
    for m in &mut cleaned {
        m.excluded = ReadingSet::NONE;
    }
    for x in &kept {
        cleaned[x.test.pose].excluded = cleaned[x.test.pose].excluded.with(x.test.sensor);
    }
    // Rows outside the frame go, the rest keep their order.
    let outside: Vec<usize> = checked
        .mistakes
        .iter()
        .filter(|m| m.kind == MistakeKind::OutsideFrame)
        .flat_map(|m| m.rows.iter().copied())
        .collect();
    let cleaned = (0..cleaned.len())
        .filter(|k| !outside.contains(k))
        .map(|k| cleaned[k])
        .collect();
    // The mistakes acted on: rows left out, or readings left out that they explain.
    let mistakes = checked
        .mistakes
        .into_iter()
        .filter(|m| {
            m.kind == MistakeKind::OutsideFrame
                || kept
                    .iter()
                    .any(|x| x.explanation.as_deref() == Some(m.message.as_str()))
        })
        .collect();
    Ok((cleaned, kept, mistakes))
}
