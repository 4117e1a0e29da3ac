//! Step 4: the report data: the diagnosis, and what the verdict's extension gains.

use serde::Serialize;

use super::baseline::Baseline;
use super::candidates::{parameters, CandidateFit, Hypothesis, ParameterValue, DETECTION_POWER};
use super::drivers::{DriverSeries, DriverTest};
use super::explanation::Explanation;
use super::options::DiagnoseOptions;
use super::prediction::NotPredictive;
use super::residual_tests::FactorTest;
use super::selection::{Selection, SelectionStep};
use crate::calib::gross_errors::ExcludedReading;
use crate::calib::mistakes::Mistake;
use crate::calib::{CalibrationError, EffectEstimate, OrientationPrior, ParameterUncertainty};
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;

/// What the chosen extension gains.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gain {
    /// Held-out normalised residual RMS of the baseline.
    pub residual_rms_before: f64,
    /// Held-out normalised residual RMS of the verdict's model (the baseline's for `none`).
    pub residual_rms_after: f64,
    /// Mean absolute anchor-coordinate error of the baseline against the truth, metres.
    pub anchor_mae_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub anchor_mae_after_m: Option<f64>,
    /// Mean Euclidean anchor error of the baseline, metres (Table II's metric).
    pub anchor_mean_euclidean_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub anchor_mean_euclidean_after_m: Option<f64>,
    /// Mean absolute length-offset error of the baseline, metres.
    pub offset_mae_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub offset_mae_after_m: Option<f64>,
}

/// The diagnosis of one dataset.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Robot name.
    pub robot: String,
    /// Poses used (those with an equilibrium).
    pub poses_used: usize,
    /// Measurement residual components `n` (encoders, load cell, localiser).
    pub measurement_components: usize,
    /// Baseline chi-square over all factors.
    pub baseline_chi_square: f64,
    /// Its degrees of freedom (measurements + statics constraints - unknowns).
    pub baseline_dof: usize,
    /// Whether the baseline's chi-square is within the 99.9 % quantile.
    pub baseline_consistent: bool,
    /// The a posteriori variance factor dividing every chi-square of the
    /// tests (1 unless the data are more precise than the stated noise).
    pub variance_factor: f64,
    /// Where the sensors are more precise than stated by different factors,
    /// the noise each sensor's data show, which every test uses
    /// ([`super::noise_the_data_show`]); `None` (JSON `null`): the stated noise.
    pub noise_shown: Option<SensorNoise>,
    /// The localiser's orientation in the baseline (`on` unless turned off).
    pub orientation_prior: OrientationPrior,
    /// The false-alarm rate of the search.
    pub false_alarm: f64,
    /// Per factor type.
    pub factor_tests: Vec<FactorTest>,
    /// Whether the rows were taken in their order (the row and direction
    /// drivers are tested only then, [`super::DiagnoseOptions::rows_in_time_order`]).
    pub rows_in_time_order: bool,
    /// Whether the first row's encoders and load cell were left out of every
    /// fit: the direction of the motion that led there is unknown, and
    /// backlash and pulley friction depend on it.
    pub first_row_left_out: bool,
    /// Residual-driver correlations of the baseline, strongest first.
    pub drivers: Vec<DriverTest>,
    /// The same with the verdict's model (empty for `none`): the structure left.
    pub drivers_after: Vec<DriverTest>,
    /// Baseline BIC.
    pub baseline_bic: f64,
    /// Baseline held-out residual RMS.
    pub baseline_cv_rms: f64,
    /// The causes named, in the order added, joined by `+`; `none` (nothing
    /// is wrong), `unexplained` (something is wrong that the catalogue does
    /// not hold) or the causes and `+unexplained` (they explain part of it).
    pub verdict: String,
    /// The model the forward selection chose, before the prediction checks.
    pub selected: String,
    /// Effects the selection added that do not predict, taken out.
    pub not_predictive: Vec<NotPredictive>,
    /// Whether the final model explains the data: causes, stand-ins, its
    /// per-sensor tests, what it leaves.
    #[serde(flatten)]
    pub explanation: Explanation,
    /// The final model's effects with their parameters and 1-sigma (stand-ins included).
    pub effects: Vec<EffectFit>,
    /// The steps of the forward selection that added something.
    pub steps: Vec<SelectionStep>,
    /// Candidates not selected whose test has power below 0.9 at their
    /// smallest plausible magnitude: not detectable at this noise with these poses.
    pub undetectable: Vec<String>,
    /// Other values of the weight effects that fit these data exactly as
    /// well as the final model's ([`super::candidates::WEIGHT_SCALING`]), in words.
    pub equivalent_fits: Vec<String>,
    /// Every hypothesis tested, at every step.
    pub candidates: Vec<CandidateFit>,
    /// Why, in one sentence.
    pub reason: String,
    /// What the final model gains.
    pub gain: Gain,
    /// Given the truth: the baseline's anchor error over its stated 1-sigma
    /// ([`error_over_sigma`]); above 1 the model error is visible in the anchors.
    pub baseline_error_over_sigma: Option<f64>,
    /// The final model's calibrated robot (anchors, offsets, effects); the baseline's without hypotheses.
    #[serde(skip)]
    pub robot_after: Robot,
    /// The baseline's calibrated robot.
    #[serde(skip)]
    pub robot_before: Robot,
    /// Residual against the winning driver (or the strongest, for `none`).
    #[serde(skip)]
    pub series: DriverSeries,
    /// Readings left out as gross errors before the diagnosis (step 0).
    pub excluded_readings: Vec<ExcludedReading>,
    /// The common mistakes recognised in the data (step 0).
    pub mistakes: Vec<Mistake>,
}

/// Mean over anchors of `|error| / sqrt(trace Sigma)` (NaN without a full-rank covariance).
pub fn error_over_sigma(estimate: &Robot, truth: &Robot, uncertainty: &ParameterUncertainty) -> f64 {
    match crate::calib::anchor_rms_bound_m(uncertainty) {
        Some(bounds) => {
            (0..CABLE_COUNT)
                .map(|i| (estimate.anchors_m[i] - truth.anchors_m[i]).norm() / bounds[i])
                .sum::<f64>()
                / CABLE_COUNT as f64
        }
        None => f64::NAN,
    }
}

/// The gain of `after` over `before`: held-out residuals, and errors against the truth if given.
pub(super) fn gain(truth: Option<&Robot>, before: &Robot, after: &Robot, cv_before: f64, cv_after: f64) -> Gain {
    let error = |r: &Robot| truth.map(|t| CalibrationError::between(r, t));
    let (before_error, after_error) = (error(before), error(after));
    Gain {
        residual_rms_before: cv_before,
        residual_rms_after: cv_after,
        anchor_mae_before_m: before_error.map(|e| e.anchor_coordinate_mae_m),
        anchor_mae_after_m: after_error.map(|e| e.anchor_coordinate_mae_m),
        anchor_mean_euclidean_before_m: before_error.map(|e| e.anchor_mean_euclidean_m),
        anchor_mean_euclidean_after_m: after_error.map(|e| e.anchor_mean_euclidean_m),
        offset_mae_before_m: before_error.map(|e| e.offset_mae_m),
        offset_mae_after_m: after_error.map(|e| e.offset_mae_m),
    }
}

/// One selected effect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectFit {
    /// The effect's name.
    pub effect: String,
    /// Its parameters with 1-sigma.
    pub params: Vec<ParameterValue>,
}

/// The selected effects with their parameters, for the report.
pub(super) fn effect_fits(estimates: &[EffectEstimate]) -> Vec<EffectFit> {
    estimates
        .iter()
        .map(|e| EffectFit {
            effect: e.effect.name().to_string(),
            params: parameters(e),
        })
        .collect()
}

/// Why the search selected what it did and what the checks after it found, in one paragraph.
pub(super) fn reason(
    selection: &Selection,
    base: &Baseline,
    options: &DiagnoseOptions,
    not_predictive: &[NotPredictive],
    explanation: &Explanation,
) -> String {
    let mut text = selection_reason(selection, base, options);
    for x in not_predictive {
        text.push_str(&format!(
            "; {} taken out of {}: {} (held-out residual RMS {:.3} with it, {:.3} without)",
            x.hypothesis, x.model, x.why, x.cv_rms_with, x.cv_rms_without
        ));
    }
    if !explanation.explained {
        text.push_str(&format!("; {}", explanation.sentence()));
    }
    text
}

/// Why the forward selection added what it did, in one sentence.
fn selection_reason(selection: &Selection, base: &Baseline, options: &DiagnoseOptions) -> String {
    let level = format!("false-alarm rate {:.0e}", options.false_alarm);
    if selection.steps.is_empty() {
        let best = selection
            .candidates
            .iter()
            .filter(|c| c.p_value.is_finite())
            .min_by(|a, b| a.p_value.total_cmp(&b.p_value));
        return match best {
            Some(c) => format!(
                "no hypothesis is significant at {level}: the strongest, {}, has p = {:.2e} (needs < {:.2e}; likelihood ratio {:.1} on {} dof, variance factor {:.3})",
                c.effect, c.p_value, c.p_threshold, c.lr_statistic, c.added_parameters, base.variance_factor
            ),
            None => "no hypothesis could be fitted".into(),
        };
    }
    let steps: Vec<String> = selection
        .steps
        .iter()
        .map(|s| {
            let removed = if s.removed.is_empty() {
                String::new()
            } else {
                format!(", then removed or replaced: {}", s.removed.join(", "))
            };
            format!(
                "step {}: {} (likelihood ratio {:.1} on {} dof, p = {:.2e} < {:.2e}){removed}",
                s.step, s.added, s.lr_statistic, s.added_parameters, s.p_value, s.p_threshold
            )
        })
        .collect();
    let mut text = format!("forward selection at {level}: {}", steps.join("; "));
    if selection.model.hypotheses.contains(&Hypothesis::OrientationFree) {
        text.push_str(
            "; the localiser's orientations stay freed pose by pose: neither one mounting rotation \
             (alone or beside an effect of the catalogue) nor any other effect tested explains their \
             disagreement with the statics",
        );
    }
    text
}

/// The candidates of the last step whose power at their smallest plausible
/// magnitude is below [`DETECTION_POWER`], with that power.
pub(super) fn undetectable(selection: &Selection) -> Vec<String> {
    let last = selection.candidates.iter().map(|c| c.step).max().unwrap_or(0);
    selection
        .candidates
        .iter()
        .filter(|c| c.step == last && !c.significant)
        .filter_map(|c| {
            c.power
                .filter(|p| *p < DETECTION_POWER)
                .map(|p| format!("{} (power {p:.2})", c.effect))
        })
        .collect()
}
