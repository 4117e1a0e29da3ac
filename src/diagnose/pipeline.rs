//! The steps of a diagnosis in order (module docs of [`super`]): gross
//! errors, the baseline, the drivers, the search for what predicts, and the
//! report.

use super::baseline::{fit_baseline, Baseline};
use super::candidates::Model;
use super::drivers::{driver_series, driver_tests, samples};
use super::equivalent_fits;
use super::explanation::explain;
use super::options::{check_options, time_order_resolved, DiagnoseOptions};
use super::prediction::predictive_model;
use super::progress::Progress;
use super::report::{self, error_over_sigma, Diagnosis};
use super::search::Search;
use super::selection::{cross_validate, first_effect, forward_selection, Selection};
use super::NotPredictive;
use crate::calib::gross_errors::{calibrate_checked, ExcludedReading, GrossErrorOptions, Verdict};
use crate::calib::mistakes::{Mistake, MistakeKind};
use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::effect_kind::{EffectKind, EffectSet};
use crate::model::measurement::{PoseMeasurement, ReadingSet, Sensor};
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::stats::chi_square_quantile_999;

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
    let checked = calibrate_checked(robot, measurements, &base_options, &check).map_err(|e| match e {
        Error::InvalidInput(why) => Error::InvalidInput(format!("diagnose: {why}")),
        other => other,
    })?;
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
        .flat_map(Mistake::indices)
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
