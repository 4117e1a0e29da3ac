//! Step 3a: every candidate effect of the catalogue fitted as an extension of
//! the baseline's factor graph, scored by BIC and held-out residual.

use serde::Serialize;

use super::selection::cross_validate;
use super::{Baseline, DiagnoseOptions, Progress};
use crate::calib::{
    build_graph, refine_with_effect, CableModel, CalibrationError, CalibrationGraph, CalibrationOptions,
    CalibrationResult, EffectEstimate,
};
use crate::graph::VariableValue;
use crate::model::effects::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::Robot;

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

/// One candidate extension, fitted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateFit {
    /// The effect's name.
    pub effect: String,
    /// Estimated parameters (empty when the fit failed).
    pub params: Vec<ParameterValue>,
    /// Parameters added to the baseline.
    pub added_parameters: usize,
    /// Sum of squared normalised residuals at the fit.
    pub chi_square: f64,
    /// `chi_square + k ln n`.
    pub bic: f64,
    /// `bic - baseline bic` (negative: preferred over the baseline).
    pub delta_bic: f64,
    /// Held-out residual RMS (normalised).
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
/// radius, more than 3 sigma below zero), if it is.
pub(super) fn inadmissible(estimate: &EffectEstimate) -> Option<String> {
    if estimate.sigmas.iter().any(|s| !s.is_finite()) {
        return Some("not identifiable from these poses (singular information matrix)".into());
    }
    let (value, sigma) = (estimate.values[0], estimate.sigmas[0]);
    let what = match estimate.effect {
        EffectKind::Elastic => "axial compliance",
        EffectKind::Pulley => "pulley radius",
        _ => return None,
    };
    (value < -3.0 * sigma.max(0.0) || (value < 0.0 && !sigma.is_finite()))
        .then(|| format!("negative {what} ({value:.3e} +- {sigma:.1e})"))
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

/// The graph of a fitted calibration (values at the fit), with the effect's
/// variable set from its estimate (the robot file's effects cannot hold a
/// negative compliance).
pub(super) fn rebuild(
    result: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let mut built = build_graph(
        &result.robot,
        used,
        &result.poses,
        &result.reference_tensions(),
        CableModel::Catenary,
        options,
    );
    if let (Some(vars), Some(estimate)) = (built.effects, &result.effect_estimate) {
        built.graph.values.set(
            vars.of(estimate.effect),
            VariableValue::Vector(nalgebra::DVector::from_vec(estimate.variable_values())),
        );
    }
    built
}

/// Fit every candidate of `options.candidates` from the baseline: the
/// report row of each, and the fits that succeeded.
pub(super) fn fit_candidates(
    base: &Baseline,
    measurements: &[PoseMeasurement],
    truth: Option<&Robot>,
    options: &DiagnoseOptions,
    progress: &mut Progress<'_>,
) -> (Vec<CandidateFit>, Vec<(EffectKind, CalibrationResult)>) {
    let mut candidates = Vec::new();
    let mut fits: Vec<(EffectKind, CalibrationResult)> = Vec::new();
    for &kind in &options.candidates {
        progress.step(&format!("fit {kind}"));
        let candidate_options = CalibrationOptions {
            free_effect: Some(kind),
            ..base.options
        };
        let fitted = refine_with_effect(&base.result, measurements, &candidate_options).and_then(|result| {
            let cv = cross_validate(&result, &base.used, &candidate_options, options.folds, &mut |what| {
                progress.step(&format!("{kind}: {what}"))
            })?;
            Ok((result, cv))
        });
        match fitted {
            Ok((result, cv_rms)) => {
                let graph = rebuild(&result, &base.used, &candidate_options);
                let chi = super::residual_tests::total_chi_square(&graph.graph);
                let estimate = result.effect_estimate.clone().expect("refine_with_effect sets it");
                candidates.push(CandidateFit {
                    effect: kind.name().to_string(),
                    params: parameters(&estimate),
                    added_parameters: kind.parameter_count(),
                    chi_square: chi,
                    bic: base.bic_of(chi, kind.parameter_count()),
                    delta_bic: base.bic_of(chi, kind.parameter_count()) - base.bic,
                    cv_rms,
                    converged: result.converged(),
                    anchor_mae_m: truth.map(|t| CalibrationError::between(&result.robot, t).anchor_coordinate_mae_m),
                    error: None,
                    inadmissible: inadmissible(&estimate),
                });
                fits.push((kind, result));
            }
            Err(e) => {
                progress.skip(options.folds);
                candidates.push(CandidateFit {
                    effect: kind.name().to_string(),
                    params: Vec::new(),
                    added_parameters: kind.parameter_count(),
                    chi_square: f64::NAN,
                    bic: f64::NAN,
                    delta_bic: f64::NAN,
                    cv_rms: f64::NAN,
                    converged: false,
                    anchor_mae_m: None,
                    error: Some(e.to_string()),
                    inadmissible: None,
                })
            }
        }
    }
    (candidates, fits)
}
