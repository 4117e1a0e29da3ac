//! Step 3a: the hypotheses of the search (each effect of the catalogue, and
//! the localiser's orientation freed), each fitted as an extension of the
//! current model and tested against it.

use serde::Serialize;

use super::baseline::Baseline;
use super::fitted_graph::rebuild;
use super::residual_tests::total_chi_square;
use super::search::Search;
use crate::calib::{
    refine_with_effects, CalibrationError, CalibrationOptions, CalibrationResult, EffectEstimate, OrientationPrior,
};
use crate::error::Result;
use crate::model::effect_kind::{EffectKind, EffectSet};
use crate::model::effect_ranges::smallest_plausible;
use crate::model::measurement::PoseMeasurement;
use crate::stats::{chi_square_critical, chi_square_survival, noncentral_chi_square_survival, noncentrality_for_power};

/// The power a test must have before its silence counts as evidence of absence.
pub const DETECTION_POWER: f64 = 0.9;

/// Three effects of which any two explain all three: the catenary's shape
/// depends on the tensions only through `f_h / w` (paper eq. 2-3), and the
/// platform's balance (eq. 9) is linear in its weight, so scaling the
/// platform's weight and the cables' weight per metre by one factor `s`
/// scales every tension by `s` and leaves every length and orientation as
/// it was: only the load cell, reading `s |T_ref|`, sees it, exactly as a
/// load-cell gain of `s`. The data cannot tell `(W, w, g)` from
/// `(s W, s w, g / s)`; fitting all three is singular, so at most two enter
/// a model, and a heavier platform is indistinguishable from lighter cables
/// read through a load cell of higher gain (the report says so where it
/// names one of them).
pub const WEIGHT_SCALING: [EffectKind; 3] = [
    EffectKind::PlatformWeight,
    EffectKind::CableWeight,
    EffectKind::LoadCell,
];

/// One hypothesis of the search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hypothesis {
    /// An effect of the catalogue.
    Effect(EffectKind),
    /// The localiser's orientations are unreliable: every pose's orientation
    /// is freed from its prior (3 parameters per pose). It contains the
    /// structured fault [`EffectKind::LocaliserMount`] (one rotation for all
    /// poses), which it replaces.
    OrientationFree,
}

impl Hypothesis {
    /// The name in reports (`com`, ..., `orientation`).
    pub fn name(self) -> &'static str {
        match self {
            Hypothesis::Effect(kind) => kind.name(),
            Hypothesis::OrientationFree => "orientation",
        }
    }
}

/// A fitted model of the search: the baseline plus hypotheses in the order added.
#[derive(Debug, Clone)]
pub(super) struct Model {
    /// The hypotheses, in the order added.
    pub hypotheses: Vec<Hypothesis>,
    /// The fit.
    pub result: CalibrationResult,
    /// Its options (free effects, orientation prior).
    pub options: CalibrationOptions,
    /// Chi-square over all factors at the fit, with the orientation prior's
    /// rows as the model has them.
    pub chi_square: f64,
}

impl Model {
    /// The baseline as a model of the search.
    pub fn baseline(base: &Baseline) -> Self {
        Self {
            hypotheses: Vec::new(),
            result: base.result.clone(),
            options: base.options,
            chi_square: base.chi_square,
        }
    }

    /// `none`, or the hypotheses joined by `+` in the order added.
    pub fn name(&self) -> String {
        if self.hypotheses.is_empty() {
            return "none".into();
        }
        let names: Vec<&str> = self.hypotheses.iter().map(|h| h.name()).collect();
        names.join("+")
    }

    /// The effects the model estimates.
    pub fn effects(&self) -> EffectSet {
        self.hypotheses
            .iter()
            .filter_map(|h| match h {
                Hypothesis::Effect(kind) => Some(*kind),
                Hypothesis::OrientationFree => None,
            })
            .collect()
    }

    /// Whether `hypothesis` may be added: not already in, not nested in an
    /// effect that is (the common gain in the per-drum gains), and not the
    /// third of [`WEIGHT_SCALING`].
    pub fn can_add(&self, hypothesis: Hypothesis) -> bool {
        if self.hypotheses.contains(&hypothesis) {
            return false;
        }
        match hypothesis {
            Hypothesis::Effect(EffectKind::LocaliserMount) => !self.hypotheses.contains(&Hypothesis::OrientationFree),
            Hypothesis::Effect(kind) if WEIGHT_SCALING.contains(&kind) => {
                let effects = self.effects();
                WEIGHT_SCALING.iter().filter(|k| effects.contains(**k)).count() < 2
            }
            Hypothesis::Effect(kind) => kind.nested_in().is_none_or(|outer| !self.effects().contains(outer)),
            Hypothesis::OrientationFree => true,
        }
    }

    /// Parameters `hypothesis` adds to this model: an effect's (less those of
    /// an effect nested in it that it replaces), or 3 per pose (less the
    /// localiser mount's 3 it replaces).
    pub fn added_parameters(&self, hypothesis: Hypothesis, poses: usize) -> usize {
        match hypothesis {
            Hypothesis::Effect(kind) => {
                let replaced: usize = EffectKind::ALL
                    .into_iter()
                    .filter(|inner| inner.nested_in() == Some(kind) && self.effects().contains(*inner))
                    .map(EffectKind::parameter_count)
                    .sum();
                kind.parameter_count() - replaced
            }
            Hypothesis::OrientationFree => {
                let mount = self.effects().contains(EffectKind::LocaliserMount);
                3 * poses
                    - if mount {
                        EffectKind::LocaliserMount.parameter_count()
                    } else {
                        0
                    }
            }
        }
    }

    /// This model fitted with `hypotheses` instead of its own, starting from
    /// its solution (effects dropped go back to the robot file's values; the
    /// localiser mount is dropped where every orientation is free).
    pub fn refit(
        &self,
        mut hypotheses: Vec<Hypothesis>,
        base: &Baseline,
        measurements: &[PoseMeasurement],
    ) -> Result<Self> {
        if hypotheses.contains(&Hypothesis::OrientationFree) {
            hypotheses.retain(|h| *h != Hypothesis::Effect(EffectKind::LocaliserMount));
        }
        let mut effects: EffectSet = hypotheses
            .iter()
            .filter_map(|h| match h {
                Hypothesis::Effect(kind) => Some(*kind),
                Hypothesis::OrientationFree => None,
            })
            .collect();
        for inner in EffectKind::ALL {
            if inner.nested_in().is_some_and(|outer| effects.contains(outer)) {
                effects = effects.without(inner);
            }
        }
        let orientation_prior = if hypotheses.contains(&Hypothesis::OrientationFree) {
            OrientationPrior::Off
        } else {
            base.options.orientation_prior
        };
        let options = CalibrationOptions {
            free_effects: effects,
            orientation_prior,
            ..base.options
        };
        let mut start = self.result.clone();
        start.robot.effects = base.result.robot.effects;
        start.effect_estimates.retain(|e| effects.contains(e.effect));
        let mut result = refine_with_effects(&start, measurements, &options)?;
        let mut chi_square = total_chi_square(&rebuild(&result, &base.used, &options).graph);
        // A second start: the whole staged calibration from the initial guess
        // with this model, so that a baseline caught in a wrong basin does not
        // trap its extensions. The lower chi-square over the same poses wins.
        if !hypotheses.is_empty() {
            // The fit's effects go back to the known inputs before the refinement
            // estimates them (the robot's `[effects]` cannot hold every estimate).
            let fresh = base.calibrate(measurements, &options).and_then(|mut fresh| {
                fresh.robot.effects = base.result.robot.effects;
                refine_with_effects(&fresh, measurements, &options)
            });
            if let Ok(fresh) = fresh {
                if fresh.excluded_poses == base.result.excluded_poses {
                    let fresh_chi_square = total_chi_square(&rebuild(&fresh, &base.used, &options).graph);
                    if fresh_chi_square < chi_square {
                        (result, chi_square) = (fresh, fresh_chi_square);
                    }
                }
            }
        }
        Ok(Self {
            hypotheses,
            result,
            options,
            chi_square,
        })
    }

    /// This model with `hypothesis` added.
    pub fn with(&self, hypothesis: Hypothesis, base: &Baseline, measurements: &[PoseMeasurement]) -> Result<Self> {
        let mut hypotheses = self.hypotheses.clone();
        hypotheses.push(hypothesis);
        self.refit(hypotheses, base, measurements)
    }

    /// This model without `hypothesis`.
    pub fn without(&self, hypothesis: Hypothesis, base: &Baseline, measurements: &[PoseMeasurement]) -> Result<Self> {
        let hypotheses = self.hypotheses.iter().copied().filter(|h| *h != hypothesis).collect();
        self.refit(hypotheses, base, measurements)
    }

    /// The estimate of `kind`, if the model has it.
    pub fn estimate(&self, kind: EffectKind) -> Option<&EffectEstimate> {
        self.result.effect_estimates.iter().find(|e| e.effect == kind)
    }
}

/// One estimated parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterValue {
    /// Name ([`EffectKind::parameter_names`]).
    pub name: String,
    /// Estimate.
    pub value: f64,
    /// 1-sigma (NaN when not observable).
    pub sigma: f64,
}

/// One hypothesis tested against the model of one step of the search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateFit {
    /// The hypothesis' name (an effect, or `orientation`).
    pub effect: String,
    /// The step of the forward selection (1: against the baseline).
    pub step: usize,
    /// The model it extends (`none`: the baseline).
    pub extends: String,
    /// Estimated parameters (empty when the fit failed or for `orientation`).
    pub params: Vec<ParameterValue>,
    /// Parameters added to the model it extends.
    pub added_parameters: usize,
    /// Sum of squared normalised residuals at the fit.
    pub chi_square: f64,
    /// Likelihood-ratio statistic: the chi-square drop over the variance factor.
    pub lr_statistic: f64,
    /// Its p-value under "the hypothesis adds nothing" (chi-square, `added_parameters` dof).
    pub p_value: f64,
    /// The p-value below which it is declared: the false-alarm rate over the step's hypotheses.
    pub p_threshold: f64,
    /// `p_value < p_threshold`, converged and admissible.
    pub significant: bool,
    /// `chi_square / variance_factor + k ln n` minus the extended model's.
    pub delta_bic: f64,
    /// Power of the test at the effect's smallest physically plausible
    /// magnitude for this robot (from the fit's Fisher information); `None`
    /// for `orientation` or a singular information matrix.
    pub power: Option<f64>,
    /// Per parameter, the smallest magnitude the test detects with power
    /// 0.9 (the others estimated too), in the variable's units (gains as errors).
    pub min_detectable: Vec<f64>,
    /// The estimate's covariance (variable units), for the power against other magnitudes.
    #[serde(skip)]
    pub covariance: Vec<Vec<f64>>,
    /// Held-out residual RMS (normalised): computed for the models the search selects, else NaN.
    pub cv_rms: f64,
    /// Whether the solver converged.
    pub converged: bool,
    /// Mean absolute anchor-coordinate error against the truth, metres.
    pub anchor_mae_m: Option<f64>,
    /// Why the fit failed, if it did.
    pub error: Option<String>,
    /// `None` when the estimate is physically possible; else why not (e.g. a
    /// negative pulley radius): such a fit only mimics another effect and is
    /// never declared.
    pub inadmissible: Option<String>,
}

/// Why an estimate is physically impossible (a negative compliance or pulley
/// radius, more than 3 sigma below zero; more than one element for a chain
/// is required too), or unidentifiable, if it is.
pub(super) fn inadmissible(estimate: &EffectEstimate) -> Option<String> {
    if estimate.sigmas.iter().any(|s| !s.is_finite()) {
        return Some("not identifiable from these poses (singular information matrix)".into());
    }
    let (value, sigma) = (estimate.values[0], estimate.sigmas[0]);
    let what = match estimate.effect {
        EffectKind::Elastic => "axial compliance",
        EffectKind::Pulley => "pulley radius",
        EffectKind::Segments => "1/n^2 of the cable's elements",
        _ => return None,
    };
    (value < -3.0 * sigma.max(0.0)).then(|| format!("negative {what} ({value:.3e} +- {sigma:.1e})"))
}

/// The estimate's parameters with their 1-sigma, for the report.
pub(super) fn parameters(estimate: &EffectEstimate) -> Vec<ParameterValue> {
    estimate
        .names
        .iter()
        .zip(&estimate.values)
        .zip(&estimate.sigmas)
        .map(|((name, value), sigma)| ParameterValue {
            name: name.clone(),
            value: *value,
            sigma: *sigma,
        })
        .collect()
}

/// The test of `hypothesis` against `model` at a step where `tested`
/// hypotheses share the false-alarm rate: the fit (if it succeeded) and its row.
pub(super) fn test_hypothesis(
    search: &Search<'_>,
    model: &Model,
    hypothesis: Hypothesis,
    tested: usize,
    step: usize,
) -> (Option<Model>, CandidateFit) {
    let (base, measurements) = (search.base, search.measurements);
    let added = model.added_parameters(hypothesis, base.used.len());
    let p_threshold = search.options.false_alarm / tested as f64;
    let mut row = CandidateFit {
        effect: hypothesis.name().to_string(),
        step,
        extends: model.name(),
        params: Vec::new(),
        added_parameters: added,
        chi_square: f64::NAN,
        lr_statistic: f64::NAN,
        p_value: f64::NAN,
        p_threshold,
        significant: false,
        delta_bic: f64::NAN,
        power: None,
        min_detectable: Vec::new(),
        covariance: Vec::new(),
        cv_rms: f64::NAN,
        converged: false,
        anchor_mae_m: None,
        error: None,
        inadmissible: None,
    };
    let fit = match model.with(hypothesis, base, measurements) {
        Ok(fit) => fit,
        Err(e) => {
            row.error = Some(e.to_string());
            return (None, row);
        }
    };
    let lr = (model.chi_square - fit.chi_square) / base.variance_factor;
    row.chi_square = fit.chi_square;
    row.lr_statistic = lr;
    row.p_value = chi_square_survival(added, lr.max(0.0));
    row.delta_bic = base.bic_of(fit.chi_square, added) - base.bic_of(model.chi_square, 0);
    row.converged = fit.result.converged();
    row.anchor_mae_m = search
        .truth
        .map(|t| CalibrationError::between(&fit.result.robot, t).anchor_coordinate_mae_m);
    if let Hypothesis::Effect(kind) = hypothesis {
        if let Some(estimate) = fit.estimate(kind) {
            row.params = parameters(estimate);
            row.covariance = estimate.covariance.clone();
            row.inadmissible = inadmissible(estimate);
            let critical = chi_square_critical(added, p_threshold);
            let smallest = smallest_plausible(kind, &base.result.robot, base.mean_reference_tension_n);
            row.power = power_at(estimate, &smallest, added, critical, base.variance_factor);
            row.min_detectable = min_detectable(estimate, added, critical, base.variance_factor);
        }
    }
    row.significant = row.converged && row.inadmissible.is_none() && row.p_value < p_threshold;
    (Some(fit), row)
}

/// The power of `row`'s test against the effect at `magnitude` (variable
/// units, [`EffectKind::variable_values`]) with the diagnosis' variance
/// factor; `None` without a full-rank covariance.
pub fn power_against(row: &CandidateFit, magnitude: &[f64], variance_factor: f64) -> Option<f64> {
    if row.covariance.len() != magnitude.len() || row.added_parameters == 0 {
        return None;
    }
    let critical = chi_square_critical(row.added_parameters, row.p_threshold);
    let covariance = nalgebra::DMatrix::from_fn(magnitude.len(), magnitude.len(), |r, c| {
        row.covariance[r][c] * variance_factor
    });
    let theta = nalgebra::DVector::from_column_slice(magnitude);
    let lambda = theta.dot(&covariance.cholesky()?.solve(&theta));
    lambda
        .is_finite()
        .then(|| noncentral_chi_square_survival(row.added_parameters, lambda, critical))
}

/// The power of a chi-square test with `dof` degrees of freedom and critical
/// value `critical` against the effect at `magnitude` (variable units): the
/// non-centrality is `theta^T Sigma^-1 theta / s^2`, `Sigma` the estimate's
/// covariance (the inverse Fisher information) and `s^2` the variance factor.
fn power_at(
    estimate: &EffectEstimate,
    magnitude: &[f64],
    dof: usize,
    critical: f64,
    variance_factor: f64,
) -> Option<f64> {
    let k = magnitude.len();
    let covariance = nalgebra::DMatrix::from_fn(k, k, |r, c| estimate.covariance[r][c] * variance_factor);
    let theta = nalgebra::DVector::from_column_slice(magnitude);
    let solved = covariance.cholesky()?.solve(&theta);
    let lambda = theta.dot(&solved);
    lambda
        .is_finite()
        .then(|| noncentral_chi_square_survival(dof, lambda, critical))
}

/// Per parameter, the magnitude detected with power [`DETECTION_POWER`]
/// when it alone is present: `sigma s sqrt(lambda_0.9)`.
fn min_detectable(estimate: &EffectEstimate, dof: usize, critical: f64, variance_factor: f64) -> Vec<f64> {
    let lambda = noncentrality_for_power(dof, critical, DETECTION_POWER);
    estimate
        .sigmas
        .iter()
        .map(|s| s * (variance_factor * lambda).sqrt())
        .collect()
}
